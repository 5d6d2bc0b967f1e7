//! The simulated bus exchanges exactly what a drive stepped by hand would: setpoint applied,
//! then its answer read back, slot by slot; empty slots read "not ready"; attach and detach
//! hand back what a slot held; fault injection reaches only its slot.

use drives::{BusError, Drive, DriveBus, DriveConfig, SimBus, SimDrive, SimDriveConfig, SimFault};
use motion::{DriveFeedback, DriveSetpoint};

const DT: f64 = 0.001;

fn setpoint(k: usize) -> DriveSetpoint {
    DriveSetpoint {
        enable: true,
        position: (k as f64 * 0.05).min(20.0),
        velocity: if k < 400 { 50.0 } else { 0.0 },
        ..DriveSetpoint::default()
    }
}

#[test]
fn the_exchange_is_the_drive_stepped_by_hand() {
    let mut bus = SimBus::new(3);
    assert!(
        bus.attach(1, DriveConfig::default().build(DT))
            .unwrap()
            .is_none()
    );
    let mut by_hand = SimDrive::new(SimDriveConfig::default(), DT);
    let mut fb = vec![DriveFeedback::default(); 3];
    for k in 0..600 {
        let sp = [
            DriveSetpoint::default(),
            setpoint(k),
            DriveSetpoint::default(),
        ];
        bus.exchange(&sp, &mut fb);
        by_hand.apply(&sp[1]);
        assert_eq!(fb[1], by_hand.feedback(), "cycle {k}");
        assert_eq!(fb[0], DriveFeedback::default());
        assert_eq!(fb[2], DriveFeedback::default());
    }
    assert!(fb[1].enabled && fb[1].actual_position > 19.0, "{:?}", fb[1]);
}

#[test]
fn attach_detach_and_fault_injection_act_on_their_slot_only() {
    let mut bus = SimBus::new(2);
    assert_eq!(bus.slots(), 2);
    // A slot that does not exist gives the drive back.
    assert!(bus.attach(2, DriveConfig::default().build(DT)).is_err());
    assert_eq!(bus.inject(0, SimFault::Clear), Err(BusError::NoDrive));
    assert!(
        bus.attach(0, DriveConfig::default().build(DT))
            .unwrap()
            .is_none()
    );
    assert!(
        bus.attach(1, DriveConfig::default().build(DT))
            .unwrap()
            .is_none()
    );
    // Replacing hands the old drive back (to be freed off the cycle thread).
    let old = bus.attach(1, DriveConfig::default().build(DT)).unwrap();
    assert!(matches!(old, Some(Drive::Simulated(_))));
    let mut fb = vec![DriveFeedback::default(); 2];
    let on = DriveSetpoint {
        enable: true,
        ..DriveSetpoint::default()
    };
    for _ in 0..50 {
        bus.exchange(&[on, on], &mut fb);
    }
    assert!(fb[0].enabled && fb[1].enabled);
    assert_eq!(bus.inject(1, SimFault::DriveFault { code: 0x2310 }), Ok(()));
    bus.exchange(&[on, on], &mut fb);
    assert!(fb[1].fault && !fb[0].fault, "{fb:?}");
    assert_eq!(fb[1].fault_code, 0x2310);
    assert!(matches!(bus.detach(1), Some(Drive::Simulated(_))));
    assert!(bus.detach(1).is_none());
    bus.exchange(&[on, on], &mut fb);
    assert_eq!(fb[1], DriveFeedback::default());
    assert!(fb[0].enabled);
}
