//! The process image negotiated with drives motiond did not write: a drive whose dictionary
//! lacks the optional objects and that checks its mapping only at SAFE-OP reaches OP with
//! what it has; a drive that refuses SAFE-OP (AL status code 0x001E) gets the next smaller
//! mapping, and the bus says which was refused and why.

mod common;

use std::time::{Duration, Instant};

use ethercat::bus::{BusOptions, EthercatBus, Link};
use ethercat::emu::Segment;
use ethercat::emu::drive::{Cia402Emu, Plant};
use ethercat::emu::sii;

/// Brings up a segment of one strict drive (at most `max_entries` per PDO at SAFE-OP).
fn start_strict(max_entries: Option<u8>) -> Result<EthercatBus, String> {
    EthercatBus::start(
        Link::Emulated(strict_segment(max_entries)),
        &BusOptions::new(Duration::from_millis(1)),
        1,
    )
}

fn strict_segment(max_entries: Option<u8>) -> std::sync::Arc<std::sync::Mutex<Segment>> {
    let id = common::identity(0);
    let mut d = Cia402Emu::strict(&id, Plant::default());
    d.max_entries_at_safe_op = max_entries;
    let start = Instant::now();
    Segment::new(
        vec![(sii::servo_drive(&id), Box::new(d))],
        Box::new(move || start.elapsed().as_nanos() as u64),
    )
    .shared()
}

#[test]
fn a_drive_without_the_optional_objects_reaches_op_with_what_it_has() {
    let bus = start_strict(None).expect("bring-up");
    let st = bus.status();
    let sd = &st.subdevices[0];
    let layout = sd.drive.expect("a drive");
    assert_eq!(layout.name, "available");
    assert_eq!(sd.missing_objects, [0x60B8, 0x60B9, 0x60BA, 0x60BB, 0x60FD]);
    assert!(!layout.maps(0x60B8) && !layout.maps(0x60FD) && layout.maps(0x6071));
    assert!(sd.refused.is_empty(), "{:?}", sd.refused);
}

#[test]
fn a_drive_refusing_safe_op_gets_the_next_smaller_mapping() {
    let bus = start_strict(Some(5)).expect("bring-up");
    let st = bus.status();
    let sd = &st.subdevices[0];
    assert_eq!(sd.drive.map(|l| l.name), Some("minimal"));
    assert_eq!(sd.refused.len(), 2, "{:?}", sd.refused);
    // Its outputs with the profile modes' dynamics (8 entries), then its inputs (6).
    let r = &sd.refused[0];
    assert_eq!((r.mapping, r.at), ("available", "PRE-OP to SAFE-OP"));
    assert_eq!(r.al_status_code, Some(0x001D));
    let r = &sd.refused[1];
    assert_eq!((r.mapping, r.at), ("available_cyclic", "PRE-OP to SAFE-OP"));
    assert_eq!(r.al_status_code, Some(0x001E));
    assert!(
        r.reason.contains("Invalid Input Configuration"),
        "{}",
        r.reason
    );
}

#[test]
fn a_drive_refusing_every_mapping_names_itself_the_transition_and_the_code() {
    let err = start_strict(Some(1)).err().expect("no mapping fits");
    assert!(err.contains("SubDevice 0"), "{err}");
    assert!(err.contains("PRE-OP to SAFE-OP"), "{err}");
    assert!(err.contains("0x001"), "{err}");
}
