//! Fixtures shared by the EtherCAT tests: emulated segments of CiA-402 servos on the segment's
//! own clock.
#![allow(dead_code, reason = "each test binary uses part of the fixtures")]

use std::sync::{Arc, Mutex};
use std::time::Instant;

use ethercat::emu::Segment;
use ethercat::emu::drive::{self, Plant};
use ethercat::emu::sii::Identity;

/// The identity of emulated servo `i` (vendor 0xACE, revision and serial counting with `i`).
pub fn identity(i: u32) -> Identity {
    Identity {
        vendor_id: 0x0000_0ACE,
        product_code: 0x0402_0001,
        revision: 0x0001_0000 + i,
        serial: 1000 + i,
        name: format!("motiond servo {i}"),
    }
}

/// `n` emulated servos; `dc` false: ESCs without a distributed clock unit.
pub fn servos(n: u32, dc: bool) -> Arc<Mutex<Segment>> {
    let start = Instant::now();
    Segment::with_dc(
        (0..n)
            .map(|i| drive::servo(identity(i), Plant::default()))
            .collect(),
        Box::new(move || start.elapsed().as_nanos() as u64),
        dc,
    )
    .shared()
}
