//! The EtherCAT `DriveBus` against an emulated segment: bring-up to OP with the CoE script and
//! SYNC0, a CiA-402 drive attached to an axis slot enables and follows CSP setpoints, a drive
//! fault reaches the feedback with its 0x603F code, lost frames fault the bus's axes after N
//! in a row and MC_Reset's edge clears it once frames flow.

mod common;

use std::time::Duration;

use common::servos;
use drives::cia402::{Cia402Config, Cia402Mode};
use drives::{DriveBus, DriveConfig};
use ethercat::bus::{BusOptions, EthercatBus, Link};
use ethercat::emu::drive::{self, Cia402Emu};
use motion::{DriveFeedback, DriveSetpoint};

const CYCLE: Duration = Duration::from_millis(1);

/// One cycle of the bus as the tests drive it (exchange, then wait a cycle).
type Exchange = dyn FnMut(&mut EthercatBus, &[DriveSetpoint], &mut [DriveFeedback]);

#[test]
fn an_axis_slot_drives_an_emulated_cia402_drive_through_faults_and_reset() {
    let seg = servos(2, true);
    let mut bus = EthercatBus::start(Link::Emulated(seg.clone()), &BusOptions::new(CYCLE), 4)
        .expect("bring-up");
    let status = bus.status();
    assert_eq!(status.subdevices.len(), 2);
    assert_eq!(status.subdevices[1].name, "motiond servo 1");
    assert_eq!(status.subdevices[0].drive.map(|l| l.name), Some("full"));
    assert_eq!(status.expected_working_counter, 6);

    let cfg = DriveConfig::Cia402(Cia402Config::csp(1, 1000.0));
    assert!(bus.attach(2, cfg.build(0.001)).unwrap().is_none());
    let mut sp = vec![DriveSetpoint::default(); 4];
    let mut fb = vec![DriveFeedback::default(); 4];
    let mut cycle = |bus: &mut EthercatBus, sp: &[DriveSetpoint], fb: &mut [DriveFeedback]| {
        bus.exchange(sp, fb);
        std::thread::sleep(CYCLE);
    };
    let until = |what: &str,
                 bus: &mut EthercatBus,
                 sp: &mut Vec<DriveSetpoint>,
                 fb: &mut Vec<DriveFeedback>,
                 f: &dyn Fn(&DriveFeedback) -> bool,
                 cycle: &mut Exchange| {
        for _ in 0..5000 {
            cycle(bus, sp, fb);
            if f(&fb[2]) {
                return;
            }
        }
        panic!("{what}: {:?}", fb[2]);
    };
    until(
        "ready",
        &mut bus,
        &mut sp,
        &mut fb,
        &|f| f.ready && !f.fault,
        &mut cycle,
    );
    assert!(!fb[0].ready, "an empty slot is never ready");
    sp[2].enable = true;
    until(
        "enabled",
        &mut bus,
        &mut sp,
        &mut fb,
        &|f| f.enabled,
        &mut cycle,
    );
    // A 5 mm move: the drive (subdevice 1) follows in increments.
    for k in 1..=500 {
        sp[2].position = 5.0 * k as f64 / 500.0;
        sp[2].velocity = 5.0;
        cycle(&mut bus, &sp, &mut fb);
    }
    sp[2].velocity = 0.0;
    until(
        "at 5 mm",
        &mut bus,
        &mut sp,
        &mut fb,
        &|f| (f.actual_position - 5.0).abs() < 0.002,
        &mut cycle,
    );
    {
        let mut s = seg.lock().unwrap();
        assert!((s.app::<Cia402Emu>(1).unwrap().position - 5000.0).abs() < 2.0);
        assert_eq!(
            s.app::<Cia402Emu>(0).unwrap().state,
            drive::State::SwitchOnDisabled,
            "subdevice 0 untouched"
        );
    }

    // A drive fault: its code in the feedback; a reset edge clears it.
    seg.lock()
        .unwrap()
        .app::<Cia402Emu>(1)
        .unwrap()
        .inject_fault(0x2310);
    until(
        "drive fault",
        &mut bus,
        &mut sp,
        &mut fb,
        &|f| f.fault,
        &mut cycle,
    );
    assert_eq!(fb[2].fault_code, 0x2310);
    sp[2].enable = false;
    sp[2].fault_reset = true;
    until(
        "fault reset",
        &mut bus,
        &mut sp,
        &mut fb,
        &|f| !f.fault,
        &mut cycle,
    );
    sp[2].fault_reset = false;

    // Lost frames (each sent three times before it counts as lost): fewer than three in a row
    // are counted only; three fault the bus.
    let lost = status
        .lost_frames
        .load(std::sync::atomic::Ordering::Relaxed);
    seg.lock().unwrap().faults.drop_frames = 1;
    cycle(&mut bus, &sp, &mut fb);
    assert_eq!(
        status
            .lost_frames
            .load(std::sync::atomic::Ordering::Relaxed),
        lost,
        "a frame answered on its retry is not lost"
    );
    seg.lock().unwrap().faults.drop_frames = 6;
    for _ in 0..5 {
        cycle(&mut bus, &sp, &mut fb);
    }
    assert!(!fb[2].bus_error, "two lost frames do not fault the bus");
    assert_eq!(
        status
            .lost_frames
            .load(std::sync::atomic::Ordering::Relaxed),
        lost + 2
    );
    seg.lock().unwrap().faults.drop_frames = 9;
    for _ in 0..3 {
        cycle(&mut bus, &sp, &mut fb);
    }
    assert!(fb[2].bus_error && !fb[2].fault, "{:?}", fb[2]);
    assert!(status.faulted.load(std::sync::atomic::Ordering::Relaxed));
    sp[2].fault_reset = true;
    cycle(&mut bus, &sp, &mut fb);
    sp[2].fault_reset = false;
    until(
        "bus fault cleared",
        &mut bus,
        &mut sp,
        &mut fb,
        &|f| !f.bus_error && f.ready,
        &mut cycle,
    );
    assert!(!status.faulted.load(std::sync::atomic::Ordering::Relaxed));

    // SDO from another thread while the cycle runs.
    let sdo = bus.sdo();
    let v = futures_lite::future::block_on(sdo.read(1, 0x1018, 4)).unwrap();
    assert_eq!(v, common::identity(1).serial.to_le_bytes());
    let e = futures_lite::future::block_on(sdo.read(1, 0x2000, 0)).unwrap_err();
    assert_eq!(e, ethercat::bus::SdoError::Abort(0x0602_0000));
}

/// CST (0x6060 = 10): motiond closes position and velocity loops and sends the torque; the
/// emulated drive's plant (inertia and friction) follows a slow move to the target.
#[test]
fn a_cst_axis_closes_its_loops_on_our_side_and_reaches_the_target() {
    let seg = servos(1, true);
    let mut bus = EthercatBus::start(Link::Emulated(seg.clone()), &BusOptions::new(CYCLE), 2)
        .expect("bring-up");
    let cfg = DriveConfig::Cia402(Cia402Config {
        mode: Cia402Mode::Cst,
        position_gain: 20.0,
        velocity_gain: 40.0,
        acceleration_feed_forward: 0.5,
        ..Cia402Config::csp(0, 1000.0)
    });
    assert!(cfg.validate().is_ok());
    assert!(bus.attach(0, cfg.build(0.001)).unwrap().is_none());
    let mut sp = vec![
        DriveSetpoint {
            enable: true,
            ..DriveSetpoint::default()
        },
        DriveSetpoint::default(),
    ];
    let mut fb = vec![DriveFeedback::default(); 2];
    let mut enabled = false;
    for _ in 0..3000 {
        bus.exchange(&sp, &mut fb);
        std::thread::sleep(CYCLE);
        if fb[0].enabled {
            enabled = true;
            break;
        }
    }
    assert!(enabled, "{:?}", fb[0]);
    {
        let mut s = seg.lock().unwrap();
        assert_eq!(
            s.app::<Cia402Emu>(0).unwrap().od.i8(0x6061, 0),
            10,
            "CST displayed"
        );
    }
    // 2 units in 1 s at constant velocity, then hold.
    for k in 1..=1000 {
        sp[0].position = 2.0 * k as f64 / 1000.0;
        sp[0].velocity = 2.0;
        bus.exchange(&sp, &mut fb);
        std::thread::sleep(CYCLE);
    }
    sp[0].velocity = 0.0;
    let mut settled = false;
    for _ in 0..5000 {
        bus.exchange(&sp, &mut fb);
        std::thread::sleep(CYCLE);
        if (fb[0].actual_position - 2.0).abs() < 0.01 && fb[0].actual_velocity.abs() < 0.05 {
            settled = true;
            break;
        }
    }
    assert!(settled, "CST settles at the target: {:?}", fb[0]);
}

/// A segment without distributed clocks (ESCs without a DC unit) runs free: bring-up skips
/// SYNC0, each exchange is a plain `tx_rx`, the cycle has no clock to follow, and a CSP drive
/// still enables and follows.
#[test]
fn a_segment_without_dc_runs_free() {
    let seg = servos(1, false);
    let mut bus = EthercatBus::start(Link::Emulated(seg.clone()), &BusOptions::new(CYCLE), 2)
        .expect("bring-up");
    assert!(!bus.status().subdevices[0].dc);
    let cfg = DriveConfig::Cia402(Cia402Config::csp(0, 1000.0));
    assert!(bus.attach(0, cfg.build(0.001)).unwrap().is_none());
    let mut sp = vec![
        DriveSetpoint {
            enable: true,
            ..DriveSetpoint::default()
        },
        DriveSetpoint::default(),
    ];
    let mut fb = vec![DriveFeedback::default(); 2];
    let mut reached = false;
    for k in 0..5000 {
        bus.exchange(&sp, &mut fb);
        assert_eq!(bus.sync_error_ns(), None, "no bus clock to follow");
        std::thread::sleep(CYCLE);
        if fb[0].enabled {
            sp[0].position = (sp[0].position + 0.01).min(1.0);
        }
        if k > 10 && (fb[0].actual_position - 1.0).abs() < 0.002 {
            reached = true;
            break;
        }
    }
    assert!(reached, "{:?}", fb[0]);
    assert_eq!(
        bus.status()
            .lost_frames
            .load(std::sync::atomic::Ordering::Relaxed),
        0
    );
}

/// A segment of 64 servos (the full mapping, 3584 bytes of process image): ethercrab sends
/// the image in four frames, a drive whose image straddles two frames counts in both
/// working counters, and every drive follows its own set point — with and without DC.
#[test]
fn sixty_four_drives_share_a_process_image_of_four_frames() {
    for dc in [true, false] {
        let seg = servos(64, dc);
        let mut bus = EthercatBus::start(Link::Emulated(seg.clone()), &BusOptions::new(CYCLE), 64)
            .expect("bring-up");
        let status = bus.status();
        assert_eq!(status.subdevices.len(), 64);
        assert!(
            status
                .subdevices
                .iter()
                .all(|s| s.drive.map(|l| l.name) == Some("full"))
        );
        // 64 × 3, and the straddling drives once more (see the unit test of the count).
        assert_eq!(status.expected_working_counter, if dc { 195 } else { 197 });
        for i in 0..64u16 {
            let cfg = DriveConfig::Cia402(Cia402Config::csp(i, 1000.0));
            assert!(bus.attach(i as usize, cfg.build(0.001)).unwrap().is_none());
        }
        let mut sp = vec![
            DriveSetpoint {
                enable: true,
                ..DriveSetpoint::default()
            };
            64
        ];
        let mut fb = vec![DriveFeedback::default(); 64];
        // Drive i goes to i/64 mm, 0.01 mm per cycle once enabled.
        let target = |i: usize| i as f64 / 64.0;
        let mut reached = false;
        for _ in 0..5000 {
            bus.exchange(&sp, &mut fb);
            std::thread::sleep(CYCLE);
            for (i, (s, f)) in sp.iter_mut().zip(&fb).enumerate() {
                if f.enabled {
                    s.position = (s.position + 0.01).min(target(i));
                }
            }
            if fb
                .iter()
                .enumerate()
                .all(|(i, f)| f.enabled && (f.actual_position - target(i)).abs() < 0.002)
            {
                reached = true;
                break;
            }
        }
        assert!(reached, "dc {dc}: {fb:?}");
        let wkc_errors = status
            .working_counter_errors
            .load(std::sync::atomic::Ordering::Relaxed);
        assert_eq!(wkc_errors, 0, "dc {dc}");
        assert_eq!(
            status
                .last_working_counter
                .load(std::sync::atomic::Ordering::Relaxed),
            status.expected_working_counter
        );
        let mut s = seg.lock().unwrap();
        for i in [0, 37, 52, 53, 63] {
            let p = s.app::<Cia402Emu>(i).unwrap().position;
            assert!((p - 1000.0 * target(i)).abs() < 2.0, "drive {i} at {p}");
        }
    }
}
