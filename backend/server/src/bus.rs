//! Which drive bus motiond runs (`--bus`): the simulated bus (the default), an EtherCAT segment
//! on a network interface, or an emulated EtherCAT segment of CiA-402 drives in this process
//! (`--bus emulated`: the same EtherCAT code path as real hardware, without hardware). Built
//! before the cycle thread starts; what the API may see of it lives in [`BusHandle`].

use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use drives::DriveBus;
use ethercat::bus::{BusControl, BusOptions, BusStatus, EthercatBus, Link, SdoAccess};
use ethercat::emu::Segment;
use ethercat::emu::drive::{self, Plant};
use ethercat::emu::sii::Identity;
use motion::ErrorId;
use serde::Serialize;
use utoipa::ToSchema;

#[derive(
    Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, Serialize, serde::Deserialize, ToSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum BusKind {
    /// Simulated drives only (no EtherCAT).
    Simulated,
    /// An emulated EtherCAT segment of CiA-402 servo drives in this process.
    Emulated,
    /// EtherCAT on `--interface` (needs `CAP_NET_RAW`).
    Ethercat,
}

impl BusKind {
    pub fn name(self) -> &'static str {
        match self {
            BusKind::Simulated => "simulated",
            BusKind::Emulated => "emulated",
            BusKind::Ethercat => "ethercat",
        }
    }
}

/// The drives of the emulated segment: one per demo axis (x, y, spindle, and the feeder
/// whose drive runs the profile).
pub const EMULATED_DRIVES: u32 = 4;

/// The plant of emulated drive `i`: the fourth (the demo's feeder) has limit switches 5 mm
/// outside its 0–500 mm travel at 1 µm per increment, for homing in the drive.
pub fn emulated_plant(i: u32) -> Plant {
    if i == 3 {
        Plant {
            limit_negative: Some(-5_000.0),
            limit_positive: Some(505_000.0),
            ..Plant::default()
        }
    } else {
        Plant::default()
    }
}

/// What the API sees of the bus.
#[derive(Clone)]
pub struct BusHandle {
    pub kind: BusKind,
    /// EtherCAT (real or emulated): the bus's shared status and SDO access.
    pub ethercat: Option<(Arc<BusStatus>, SdoAccess)>,
    /// The emulated segment (fault injection: lost frames).
    pub segment: Option<Arc<Mutex<Segment>>>,
    /// EtherCAT: reset after a fault, stopping the TX/RX loop (a test's fault).
    pub control: Option<BusControl>,
}

impl BusHandle {
    /// A fault for the emulated CiA-402 drive at `position` of the emulated segment, through
    /// the emulator's own door (`emu::drive::Input`): the drive's fault (its 0x603F code), its
    /// probe input, its limit switches. The simulated load's disturbances (load, probe mark)
    /// are the simulated drive's only; a real bus takes none.
    pub fn inject_emulated(&self, position: u16, fault: drives::SimFault) -> Result<(), ErrorId> {
        use drives::SimFault as F;
        let input = match fault {
            F::DriveFault { code } => drive::Input::Fault {
                code: code.min(0xFFFF) as u16,
            },
            F::ProbeInput { active } => drive::Input::ProbeInput { active },
            F::LimitSwitch { positive, active } => drive::Input::LimitSwitch { positive, active },
            F::Clear => drive::Input::Clear,
            F::Load { .. } | F::ProbeMark { .. } => return Err(ErrorId::COMMAND_NOT_PERMITTED),
        };
        let Some(segment) = &self.segment else {
            return Err(ErrorId::COMMAND_NOT_PERMITTED);
        };
        let mut seg = segment.lock().unwrap_or_else(|e| e.into_inner());
        let Some(d) = seg.app::<drive::Cia402Emu>(position as usize) else {
            return Err(ErrorId::COMMAND_NOT_PERMITTED);
        };
        d.apply(input);
        Ok(())
    }

    pub fn simulated() -> BusHandle {
        BusHandle {
            kind: BusKind::Simulated,
            ethercat: None,
            segment: None,
            control: None,
        }
    }

    /// The objects of `needed` that the drive at `position` does not have in its process
    /// image (missing from its dictionary, or left out of the mapping it took). Empty for a
    /// drive that is not on the bus (the axis's own check says so).
    pub fn unmapped(&self, position: u16, needed: &[u16]) -> Vec<u16> {
        let Some((st, _)) = &self.ethercat else {
            return Vec::new();
        };
        let Some(layout) = st
            .subdevices
            .iter()
            .find(|s| s.position == position)
            .and_then(|s| s.drive.as_ref())
        else {
            return Vec::new();
        };
        needed
            .iter()
            .copied()
            .filter(|&i| !layout.maps(i))
            .collect()
    }

    /// Positions of the SubDevices that are CiA-402 drives.
    pub fn drive_positions(&self) -> Vec<u16> {
        self.ethercat.as_ref().map_or_else(Vec::new, |(st, _)| {
            st.subdevices
                .iter()
                .filter(|s| s.drive.is_some())
                .map(|s| s.position)
                .collect()
        })
    }
}

/// The identity of emulated drive `i` (a vendor id from the range no EtherCAT vendor has).
pub fn emulated_identity(i: u32) -> Identity {
    Identity {
        vendor_id: 0x00FF_0ACE,
        product_code: 0x0402_0001,
        revision: 0x0001_0000,
        serial: 0x2026_0000 + i,
        name: format!("motiond emulated servo {}", i + 1),
    }
}

/// The emulated segment of `drives` CiA-402 servos, on the segment's own clock (`strict`:
/// drives without the optional objects that check their mapping at SAFE-OP).
fn emulated_segment(drives: u32, strict: bool) -> Arc<Mutex<Segment>> {
    let start = Instant::now();
    let make = if strict {
        drive::strict_servo
    } else {
        drive::servo
    };
    Segment::new(
        (0..drives)
            .map(|i| make(emulated_identity(i), emulated_plant(i)))
            .collect(),
        Box::new(move || start.elapsed().as_nanos() as u64),
    )
    .shared()
}

/// `motiond emulate-segment`: the emulated segment on a raw socket until the process ends.
/// `late_reply_ms`: one answer in 100 comes that late (a link slow now and then: motiond
/// sends the frame again and counts the answer it no longer waits for as late).
pub fn serve_emulated_segment(
    interface: &str,
    drives: u32,
    strict: bool,
    late_reply_ms: Option<u32>,
) -> Result<(), String> {
    let stop = Arc::new(std::sync::atomic::AtomicBool::new(false));
    let segment = emulated_segment(drives, strict);
    if let Some(ms) = late_reply_ms {
        let mut seg = segment.lock().unwrap_or_else(|e| e.into_inner());
        seg.faults.late_every = 100;
        seg.faults.reply_delay = Duration::from_millis(u64::from(ms));
    }
    let server = ethercat::emu::transport::serve_raw_socket(interface, segment, stop)
        .map_err(|e| format!("cannot serve on {interface} (CAP_NET_RAW needed): {e}"))?;
    println!(
        "emulated EtherCAT segment of {drives} {}CiA-402 drives on {interface}{}",
        if strict { "strict " } else { "" },
        late_reply_ms.map_or(String::new(), |ms| format!(
            ", one answer in 100 {ms} ms late"
        ))
    );
    server
        .join()
        .map_err(|_| "the emulated segment stopped".to_string())
}

/// What `--bus emulated` puts on its segment.
#[derive(Clone, Copy, Debug)]
pub struct Emulation {
    /// Emulated drives (the demo's axes use the first [`EMULATED_DRIVES`]).
    pub drives: u32,
    /// Drives like many not written by motiond's authors (`--emulated-strict-drives`).
    pub strict: bool,
}

/// Builds the bus (blocking: an EtherCAT segment is brought up to OP here).
pub fn start(
    kind: BusKind,
    interface: Option<&str>,
    emulation: Emulation,
    cycle: Duration,
    max_errors_in_row: u32,
    timeout: Option<Duration>,
    slots: usize,
) -> Result<(Box<dyn DriveBus>, BusHandle), String> {
    let link = match kind {
        BusKind::Simulated => {
            return Ok((Box::new(drives::SimBus::new(slots)), BusHandle::simulated()));
        }
        BusKind::Ethercat => Link::Interface(
            interface
                .ok_or("--bus ethercat needs --interface (the network interface of the segment)")?
                .to_string(),
        ),
        BusKind::Emulated => Link::Emulated(emulated_segment(emulation.drives, emulation.strict)),
    };
    let segment = match &link {
        Link::Emulated(s) => Some(s.clone()),
        Link::Interface(_) => None,
    };
    let mut opts = BusOptions::new(cycle);
    opts.max_errors_in_row = max_errors_in_row;
    if let Some(t) = timeout {
        opts.pdu_timeout = t;
    }

    let bus = EthercatBus::start(link, &opts, slots)?;
    let status = bus.status();
    for s in &status.subdevices {
        tracing::info!(
            "EtherCAT SubDevice {} {:#06x} '{}' vendor {:#010x} product {:#010x} rev {:#010x} serial {}{}",
            s.position,
            s.configured_address,
            s.name,
            s.vendor_id,
            s.product_code,
            s.revision,
            s.serial,
            s.drive.map_or(String::new(), |l| format!(
                ", CiA-402 drive ({} mapping{}{})",
                l.name,
                if s.missing_objects.is_empty() {
                    String::new()
                } else {
                    format!(
                        "; it has no {}",
                        s.missing_objects
                            .iter()
                            .map(|i| format!("{i:#06x}"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    )
                },
                s.refused
                    .iter()
                    .map(|r| format!("; refused {} at {}: {}", r.mapping, r.at, r.reason))
                    .collect::<String>()
            ))
        );
    }
    tracing::info!(
        "EtherCAT on {}: {} SubDevices in OP, DC SYNC0 every {} µs; PDU timeout {} ms; TX/RX thread: {}",
        status.interface,
        status.subdevices.len(),
        cycle.as_micros(),
        status.pdu_timeout.as_millis(),
        status.link.realtime()
    );
    let handle = BusHandle {
        kind,
        ethercat: Some((status, bus.sdo())),
        segment,
        control: Some(bus.control()),
    };
    Ok((Box::new(bus), handle))
}
