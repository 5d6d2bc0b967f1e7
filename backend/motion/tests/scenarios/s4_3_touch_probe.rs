//! §4.3 MC_TouchProbe / MC_AbortTrigger, cycle by cycle against the rig's plant with a probe
//! mark on digital input 1 (the rig checks the FB protocol in every cycle).

use super::*;

fn probe(source: LatchSource, window: Option<(f64, f64)>, modulo: bool) -> CommandKind {
    CommandKind::TouchProbe(TouchProbe {
        source,
        window_only: window.is_some(),
        first_position: window.map_or(0.0, |w| w.0),
        last_position: window.map_or(0.0, |w| w.1),
        modulo_positions: modulo,
    })
}

fn power(r: &mut Rig) {
    r.power_on(0);
    r.until(1.0, |r| r.st(0).power_status);
}

/// §4.3.1: "captures the axis position at the moment of a digital signal": Busy from the
/// submit, Done in the cycle after the one in which the load passed the mark, the recorded
/// position exactly the mark's (not the cycle's sample).
#[test]
fn s4_3_a_probe_records_the_exact_position_of_the_mark() {
    let mut r = Rig::new(1);
    r.plants[0].probe_mark = Some(42.123);
    power(&mut r);
    let p = r.ok(0, probe(LatchSource::Input1Rising, None, false));
    assert!(r.out(p).busy && !r.out(p).done);
    assert!(r.st(0).probe.armed);
    r.ok(0, CommandKind::MoveAbsolute(mv(100.0, 50.0)));
    let mut cycle = 0u64;
    let mut passed_at = None;
    while !r.out(p).done {
        r.step();
        cycle += 1;
        if passed_at.is_none() && r.plants[0].pos >= 42.123 {
            passed_at = Some(cycle);
            assert!(!r.out(p).done, "not before the drive has answered");
        }
        assert!(cycle < 10_000, "never latched");
    }
    let passed = passed_at.expect("the mark was passed");
    // The latch answers in the next feedback: Done one cycle after the pass.
    assert_eq!(cycle, passed + 1, "Done the cycle after the pass");
    let s = r.st(0).probe;
    assert!(!s.armed);
    assert_eq!(s.recorded_position, 42.123);
    assert_eq!(s.absolute_position, 42.123);
    assert_eq!(s.command, p);
    assert_eq!(s.counter, 1);
    let out = r.out(p);
    assert!(out.done && !out.busy && !out.error && !out.command_aborted);
}

/// The recorded data travels on the event that ends the probe cycle Done (whoever tracks the
/// command completes it from that event), and on no other event.
#[test]
fn s4_3_the_done_event_carries_the_recorded_data() {
    let mut r = Rig::new(1);
    r.plants[0].probe_mark = Some(42.123);
    power(&mut r);
    let p = r.ok(0, probe(LatchSource::Input1Rising, None, false));
    r.ok(0, CommandKind::MoveAbsolute(mv(100.0, 50.0)));
    r.until(3.0, |r| r.out(p).done);
    let with: Vec<_> = r.events.iter().filter(|e| e.result.is_some()).collect();
    assert_eq!(with.len(), 1, "one event carries a result");
    assert_eq!(with[0].command, p);
    assert!(with[0].outputs.done && !with[0].outputs.busy);
    assert_eq!(
        with[0].result,
        Some(motion::BlockResult::Probe(motion::ProbeStatus {
            armed: false,
            command: p,
            recorded_position: 42.123,
            absolute_position: 42.123,
            modulo_position: 42.123,
            counter: 1,
        }))
    );
}

/// §4.3.1 WindowOnly: an edge outside [First, Last] is discarded and the latch re-armed
/// automatically; Done only for an in-window capture.
#[test]
fn s4_3_window_only_discards_edges_outside_and_rearms() {
    let mut r = Rig::new(1);
    r.plants[0].probe_mark = Some(10.0);
    power(&mut r);
    let p = r.ok(
        0,
        probe(LatchSource::Input1Rising, Some((30.0, 60.0)), false),
    );
    r.ok(0, CommandKind::MoveAbsolute(mv(20.0, 50.0)));
    r.until(3.0, |r| r.st(0).state == AxisState::Standstill);
    assert!(r.out(p).busy, "the edge at 10 is outside the window");
    assert_eq!(r.st(0).probe.counter, 0);
    // The mark moves into the window (a second part): the next pass completes the cycle.
    r.plants[0].probe_mark = Some(45.0);
    r.ok(0, CommandKind::MoveAbsolute(mv(80.0, 50.0)));
    r.until(3.0, |r| r.out(p).done);
    assert_eq!(r.st(0).probe.recorded_position, 45.0);
}

/// TRIGGER_REF.ModuloPositions: the recorded position and the window are modulo the axis's
/// period; a window with First > Last wraps through 0.
#[test]
fn s4_3_modulo_positions_and_a_wrapping_window() {
    let mut p = params();
    p.axis_encoder_modulo_value = 360.0;
    let mut r = Rig::with(vec![(true, p)]);
    r.plants[0].probe_mark = Some(365.0);
    power(&mut r);
    let id = r.ok(
        0,
        probe(LatchSource::Input1Rising, Some((350.0, 10.0)), true),
    );
    r.ok(0, CommandKind::MoveAbsolute(mv(400.0, 100.0)));
    r.until(6.0, |r| r.out(id).done);
    let s = r.st(0).probe;
    assert!((s.recorded_position - 5.0).abs() < 1e-9, "{s:?}");
    assert!((s.modulo_position - 5.0).abs() < 1e-9);
    assert_eq!(s.absolute_position, 365.0);
}

/// §4.3.2: MC_AbortTrigger ends the probe cycle with CommandAborted before the trigger fired
/// and is Done at once; a second MC_TouchProbe while one runs is refused; homing takes the
/// latch from a running probe cycle when it arms it (decision 97).
#[test]
fn s4_3_abort_trigger_ends_the_cycle_and_only_one_runs_at_a_time() {
    let mut r = Rig::new(1);
    power(&mut r);
    let p = r.ok(0, probe(LatchSource::Input1Rising, None, false));
    assert_eq!(
        r.rejected(0, probe(LatchSource::Input1Falling, None, false)),
        ErrorId::TOUCH_PROBE_BUSY
    );
    r.run(0.01);
    let a = r.ok(0, CommandKind::AbortTrigger);
    assert!(r.out(a).done);
    let out = r.out(p);
    assert!(out.command_aborted && !out.busy && !out.done);
    assert!(!r.st(0).probe.armed);
    // Nothing to abort is not an error.
    let a = r.ok(0, CommandKind::AbortTrigger);
    assert!(r.out(a).done);
    // An absolute window must not be empty.
    assert_eq!(
        r.rejected(0, probe(LatchSource::Input1Rising, Some((5.0, 1.0)), false)),
        ErrorId::PARAMETER_NOT_CORRECT
    );
    // Homing needs the drive's one latch: the probe cycle is aborted.
    r.plants[0].cam = Some((20.0, 25.0));
    r.plants[0].index_period = Some(10.0);
    let p = r.ok(0, probe(LatchSource::Input1Rising, None, false));
    r.ok(
        0,
        CommandKind::Home {
            position: None,
            mode: HomingMode::Default,
            options: Default::default(),
        },
    );
    // (when its sequence arms the drive latch for the index pulse)
    r.until(20.0, |r| !r.out(p).busy);
    assert!(r.out(p).command_aborted);
    assert!(!r.st(0).probe.armed);
}
