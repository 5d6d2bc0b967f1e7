//! motiond's own TX/RX loop on the emulated segment: late and duplicate replies are counted
//! and dropped while an axis keeps moving; a stopped loop faults the bus (every axis on it
//! sees bus_error) and a reset brings the segment back to OP without a new bring-up.

mod common;

use std::time::{Duration, Instant};

use common::servos;
use drives::cia402::Cia402Config;
use drives::{DriveBus, DriveConfig};
use ethercat::bus::{BusOptions, EthercatBus, Link};
use motion::{DriveFeedback, DriveSetpoint};
use std::sync::atomic::Ordering::Relaxed;

const CYCLE: Duration = Duration::from_millis(1);

struct Rig {
    bus: EthercatBus,
    sp: Vec<DriveSetpoint>,
    fb: Vec<DriveFeedback>,
}

impl Rig {
    fn cycle(&mut self) {
        self.bus.exchange(&self.sp, &mut self.fb);
        std::thread::sleep(CYCLE);
    }
    /// Cycles until `f` holds (a generous deadline: this is about behaviour, not timing).
    fn until(&mut self, what: &str, f: impl Fn(&Rig) -> bool) {
        let deadline = Instant::now() + Duration::from_secs(20);
        while !f(self) {
            assert!(Instant::now() < deadline, "{what}: {:?}", self.fb[0]);
            self.cycle();
        }
    }
    /// Moves by `mm` in `cycles` steps, as the kernel's setpoints would.
    fn move_by(&mut self, mm: f64, cycles: u32) {
        let from = self.sp[0].position;
        for k in 1..=cycles {
            self.sp[0].position = from + mm * f64::from(k) / f64::from(cycles);
            self.sp[0].velocity = 1.0;
            self.cycle();
        }
        self.sp[0].velocity = 0.0;
    }
}

fn enabled_rig() -> (
    Rig,
    std::sync::Arc<std::sync::Mutex<ethercat::emu::Segment>>,
) {
    let seg = servos(1, true);
    let mut bus = EthercatBus::start(Link::Emulated(seg.clone()), &BusOptions::new(CYCLE), 1)
        .expect("bring-up");
    let cfg = DriveConfig::Cia402(Cia402Config::csp(0, 1000.0));
    assert!(bus.attach(0, cfg.build(0.001)).unwrap().is_none());
    let mut rig = Rig {
        bus,
        sp: vec![DriveSetpoint::default()],
        fb: vec![DriveFeedback::default()],
    };
    rig.until("ready", |r| r.fb[0].ready && !r.fb[0].fault);
    rig.sp[0].enable = true;
    rig.until("enabled", |r| r.fb[0].enabled);
    (rig, seg)
}

#[test]
fn late_and_duplicate_replies_are_counted_and_dropped_while_the_axis_moves() {
    let (mut rig, seg) = enabled_rig();
    let status = rig.bus.status();
    let timeout = BusOptions::new(CYCLE).pdu_timeout;
    {
        let mut s = seg.lock().unwrap();
        // Half again the PDU timeout: each such frame is sent again and answered twice,
        // the second answer long after the timeout.
        s.faults.late_replies = 40;
        s.faults.reply_delay = timeout * 3 / 2;
        s.faults.duplicate_replies = 400;
    }
    rig.move_by(2.0, 1000);
    rig.until("the burst is over", |_| {
        let s = seg.lock().unwrap();
        s.faults.late_replies == 0 && s.faults.duplicate_replies == 0
    });
    rig.move_by(1.0, 300);
    rig.until("at 3 mm", |r| (r.fb[0].actual_position - 3.0).abs() < 0.002);
    let link = &status.link;
    let (late, dup) = (link.late.load(Relaxed), link.duplicate.load(Relaxed));
    println!(
        "late {late}, duplicate {dup}, malformed {}, lost frames {}, frames {}",
        link.malformed.load(Relaxed),
        status.lost_frames.load(Relaxed),
        status.frames.load(Relaxed)
    );
    assert!(late >= 10, "late replies counted: {late}");
    assert!(dup >= 300, "duplicate replies counted: {dup}");
    assert!(link.alive(), "the loop survived: {:?}", link.fault());
    assert!(!rig.fb[0].bus_error && rig.fb[0].enabled, "{:?}", rig.fb[0]);
    assert_eq!(status.faults.load(Relaxed), 0, "the bus never faulted");
}

#[test]
fn a_stopped_loop_faults_the_bus_and_a_reset_brings_it_back_to_op() {
    let (mut rig, _seg) = enabled_rig();
    let status = rig.bus.status();
    let control = rig.bus.control();
    rig.move_by(1.0, 200);
    control.kill_loop();
    rig.until("bus_error", |r| r.fb[0].bus_error);
    assert!(status.faulted.load(Relaxed));
    let why = status.link.fault().expect("a reason");
    assert!(why.contains("stopped"), "{why}");
    assert!(
        status.al_states.iter().all(|a| a.load(Relaxed) == 0),
        "no stale AL state"
    );
    // The reset runs off the cycle thread while the cycle goes on.
    let reset = std::thread::spawn(move || control.reset(Duration::from_secs(10)));
    rig.until("reset done", |_| reset.is_finished());
    let took = reset.join().unwrap().expect("back to OP");
    println!("reset: back in OP after {took:?}");
    rig.until("bus clear", |r| !r.fb[0].bus_error);
    assert!(status.link.alive() && status.link.fault().is_none());
    assert_eq!(status.link.restarts.load(Relaxed), 1);
    // The axis powers on again and moves.
    rig.sp[0].enable = false;
    rig.cycle();
    rig.sp[0].position = rig.fb[0].actual_position;
    rig.sp[0].enable = true;
    rig.until("enabled again", |r| r.fb[0].enabled);
    rig.move_by(1.0, 300);
    let target = rig.sp[0].position;
    rig.until("moved after the reset", |r| {
        (r.fb[0].actual_position - target).abs() < 0.002
    });
}

#[test]
fn an_axis_reset_edge_starts_a_stopped_loop_again() {
    let (mut rig, _seg) = enabled_rig();
    let status = rig.bus.status();
    rig.bus.control().kill_loop();
    rig.until("bus_error", |r| r.fb[0].bus_error);
    rig.sp[0].fault_reset = true;
    rig.cycle();
    rig.sp[0].fault_reset = false;
    rig.until("bus clear", |r| !r.fb[0].bus_error);
    assert!(status.link.alive());
    assert!(status.al_states.iter().all(|a| a.load(Relaxed) == 8));
}
