//! A drive that executes the profile itself, through the EtherCAT bus and the CiA-402 drive
//! layer: the kernel's profile command becomes the PP/PV/HM process data (mode, targets,
//! 0x6081/0x6083/0x6084, controlword bits 4, 5, 8) and the statusword's bits 10, 12, 13 come
//! back as the profile feedback; a switch back to CSP takes over the position without a jump.

mod common;

use std::time::Duration;

use common::servos;
use drives::cia402::{Cia402Config, ProfileSide};
use drives::{DriveBus, DriveConfig};
use ethercat::bus::{BusOptions, EthercatBus, Link};
use ethercat::emu::drive::Cia402Emu;
use motion::{DriveFeedback, DriveSetpoint, ProfileCommand, ProfileMode};

const CYCLE: Duration = Duration::from_millis(1);

struct Rig {
    bus: EthercatBus,
    seg: std::sync::Arc<std::sync::Mutex<ethercat::emu::Segment>>,
    sp: Vec<DriveSetpoint>,
    fb: Vec<DriveFeedback>,
}

impl Rig {
    fn cycle(&mut self) {
        self.bus.exchange(&self.sp, &mut self.fb);
        // The emulated segment runs on its own clock: let a setpoint period pass.
        std::thread::sleep(CYCLE);
    }
    /// Cycles until `f` holds (at most 20 000).
    fn until(&mut self, what: &str, f: impl Fn(&DriveFeedback) -> bool) {
        for _ in 0..20_000 {
            self.cycle();
            if f(&self.fb[0]) {
                return;
            }
        }
        panic!("{what}: {:?}", self.fb[0]);
    }
    fn emu<T>(&self, f: impl FnOnce(&mut Cia402Emu) -> T) -> T {
        let mut s = self.seg.lock().unwrap();
        f(s.app::<Cia402Emu>(0).unwrap())
    }
}

#[test]
fn profile_position_velocity_and_homing_run_in_the_drive() {
    let seg = servos(1, true);
    let bus = EthercatBus::start(Link::Emulated(seg.clone()), &BusOptions::new(CYCLE), 1)
        .expect("bring-up");
    let layout = bus.status().subdevices[0].drive.expect("a drive");
    assert!(layout.runs_profiles(), "{layout:?}");
    let mut rig = Rig {
        bus,
        seg,
        sp: vec![DriveSetpoint::default()],
        fb: vec![DriveFeedback::default()],
    };
    let cfg = DriveConfig::Cia402(Cia402Config {
        profile: ProfileSide::Drive,
        ..Cia402Config::csp(0, 1000.0)
    });
    assert!(rig.bus.attach(0, cfg.build(0.001)).unwrap().is_none());
    rig.sp[0].enable = true;
    rig.until("enabled", |f| f.enabled);
    // In CSP the mapped profile dynamics carry the drive's own values (read at bring-up): its
    // halt and quick-stop ramps stay as commissioned.
    for _ in 0..5 {
        rig.cycle();
    }
    assert_eq!(rig.emu(|d| d.od.u32(0x6081, 0)), 100_000);
    assert_eq!(rig.emu(|d| d.od.u32(0x6084, 0)), 1_000_000);

    // Profile position: 20 mm at 50 mm/s, 500 mm/s².
    rig.sp[0].profile = ProfileCommand {
        mode: ProfileMode::Position,
        target: 20.0,
        velocity: 50.0,
        acceleration: 500.0,
        deceleration: 500.0,
        start: true,
        immediate: true,
        halt: false,
    };
    rig.until("in profile position, acknowledged", |f| {
        f.profile.mode == ProfileMode::Position && f.profile.acknowledge
    });
    assert!(!rig.fb[0].profile.target_reached, "a new target");
    assert_eq!(rig.emu(|d| d.od.u32(0x6081, 0)), 50_000, "profile velocity");
    assert_eq!(rig.emu(|d| d.od.u32(0x6083, 0)), 500_000);
    rig.sp[0].profile.start = false;
    rig.until("acknowledge dropped", |f| !f.profile.acknowledge);
    let mut fastest: f64 = 0.0;
    for _ in 0..20_000 {
        rig.cycle();
        fastest = fastest.max(rig.fb[0].actual_velocity.abs());
        if rig.fb[0].profile.target_reached {
            break;
        }
    }
    assert!(rig.fb[0].profile.target_reached);
    assert!(
        (rig.fb[0].actual_position - 20.0).abs() <= 0.01,
        "{:?}",
        rig.fb[0]
    );
    assert!(fastest <= 50.5, "the drive's profile velocity: {fastest}");

    // Halt on the way back: standing short of the target, bit 10 while halted.
    rig.sp[0].profile.target = 0.0;
    rig.sp[0].profile.start = true;
    rig.until("acknowledged", |f| f.profile.acknowledge);
    rig.sp[0].profile.start = false;
    rig.until("moving", |f| f.actual_position < 15.0);
    rig.sp[0].profile.halt = true;
    rig.until("halted", |f| {
        f.profile.target_reached && f.actual_velocity.abs() < 0.01
    });
    let held = rig.fb[0].actual_position;
    assert!(held > 1.0 && held < 15.0, "{held}");

    // Profile velocity: −10 mm/s.
    rig.sp[0].profile = ProfileCommand {
        mode: ProfileMode::Velocity,
        target: -10.0,
        acceleration: 200.0,
        deceleration: 200.0,
        ..ProfileCommand::default()
    };
    // Bit 10 of the cycles that still showed the halt (the mode switch holds) says nothing
    // about the new target: under way first.
    rig.until("under way", |f| {
        f.profile.mode == ProfileMode::Velocity && f.actual_velocity < -1.0
    });
    rig.until("at velocity", |f| f.profile.target_reached);
    assert!(
        (rig.fb[0].actual_velocity + 10.0).abs() <= 1.0,
        "{:?}",
        rig.fb[0]
    );
    rig.sp[0].profile.halt = true;
    rig.until("standing", |f| {
        f.profile.acknowledge && f.profile.target_reached
    });

    // Homing on the current position (method 37, the emulated drive's default) with a home
    // offset of 5 mm.
    rig.emu(|d| d.od.set(0x607C, 0, &5_000i32.to_le_bytes()));
    rig.sp[0].profile = ProfileCommand {
        mode: ProfileMode::Homing,
        velocity: 10.0,
        acceleration: 100.0,
        start: true,
        ..ProfileCommand::default()
    };
    rig.until("homed", |f| {
        f.profile.mode == ProfileMode::Homing && f.profile.acknowledge && f.profile.target_reached
    });
    assert!(
        (rig.fb[0].actual_position - 5.0).abs() < 0.002,
        "{:?}",
        rig.fb[0]
    );

    // Back to CSP, holding where the drive is: no jump while the mode changes.
    let here = rig.fb[0].actual_position;
    rig.sp[0].profile = ProfileCommand::default();
    rig.sp[0].position = here;
    for _ in 0..200 {
        rig.cycle();
        assert!(
            (rig.fb[0].actual_position - here).abs() < 0.002,
            "{:?}",
            rig.fb[0]
        );
    }
    assert_eq!(rig.emu(|d| d.od.i8(0x6061, 0)), 8, "CSP again");
    assert!(rig.fb[0].enabled);
}
