//! §4.5.2 MC_BacklashCompensation, §4.5.5 MC_PositionCorrectionLimiter, §4.5.12
//! MC_TableBasedPositionCompensation, on the position correction of appendix §7.2: the drive's
//! setpoint is reduced by the correction and the actual position increased by it, so the
//! axis's own positions stay the ideal ones. Checked cycle by cycle against the rig's plant.

use super::*;

fn enable_position_correction(r: &mut Rig, axis: u16) {
    r.ok(
        axis,
        CommandKind::WriteParameter {
            number: 1046,
            value: 1.0,
        },
    );
}

fn limiter(
    value: f64,
    mode: PositionCorrectionMode,
    acceleration: f64,
    length: f64,
) -> CommandKind {
    CommandKind::PositionCorrectionLimiter {
        value,
        mode,
        acceleration,
        correction_length: length,
    }
}

fn backlash(b: f64, positive: bool, ramp: f64, disable_mode: DisableMode) -> CommandKind {
    CommandKind::BacklashCompensation {
        backlash: Some(b),
        compensate_in_positive_direction: positive,
        ramp,
        disable_mode,
    }
}

/// The drive's setpoint = set − correction, and the actual position the drive answers with
/// plus the correction gives the set position back (an ideal plant): checked every cycle.
fn check_correction_is_below_the_axis(r: &Rig, axis: u16) {
    let st = r.st(axis);
    let c = st.position_correction;
    assert!(
        (r.sp[axis as usize].position - (st.set_position - c.total)).abs() < 1e-9,
        "drive setpoint {} ≠ set {} − correction {}",
        r.sp[axis as usize].position,
        st.set_position,
        c.total
    );
    assert!((c.total - (c.limiter + c.backlash + c.table)).abs() < 1e-12);
}

/// §4.5.2/§4.5.5: position correction must be enabled (#1046) — else 0x4B04 invalid mode;
/// FAST needs no more than acceleration × cycle time² per cycle, FULLLENGTH a positive
/// length; Limiting while the correction is still on its way.
#[test]
fn s4_5_5_limiter_needs_position_correction_and_valid_inputs() {
    let mut r = Rig::new(1);
    power(&mut r);
    assert_eq!(
        r.rejected(0, limiter(0.5, PositionCorrectionMode::Unlimited, 0.0, 0.0)),
        ErrorId::INVALID_MODE
    );
    assert_eq!(
        r.rejected(0, backlash(0.1, false, 1.0, DisableMode::Hold)),
        ErrorId::INVALID_MODE
    );
    enable_position_correction(&mut r, 0);
    assert_eq!(
        r.rejected(
            0,
            limiter(0.5, PositionCorrectionMode::FullLength, 0.0, 0.0)
        ),
        ErrorId::PARAMETER_NOT_CORRECT
    );
    assert_eq!(
        r.rejected(0, limiter(f64::NAN, PositionCorrectionMode::Fast, 0.0, 0.0)),
        ErrorId::PARAMETER_NOT_CORRECT
    );
    assert_eq!(
        r.rejected(0, backlash(0.1, false, 0.0, DisableMode::Hold)),
        ErrorId::PARAMETER_NOT_CORRECT,
        "a ramp > 0 is needed"
    );
    assert_eq!(
        r.rejected(
            0,
            CommandKind::TableBasedPositionCompensation {
                ramp: 1.0,
                disable_mode: DisableMode::Hold
            }
        ),
        ErrorId::COMPENSATION_TABLE_MISSING
    );
}

/// §4.5.5 / §6.9: UNLIMITED applies the correction at once; FAST at most Acceleration × (cycle
/// time)² per cycle until reached (Limiting meanwhile); FULLLENGTH spreads a change over
/// CorrectionLength of travel and does nothing at standstill. The set position never moves;
/// the drive takes the correction off its setpoint and the actual comes back ideal.
#[test]
fn s4_5_5_limiter_modes_cycle_by_cycle() {
    let mut r = Rig::new(1);
    power(&mut r);
    enable_position_correction(&mut r, 0);
    let set = r.st(0).set_position;
    let u = r.ok(0, limiter(0.5, PositionCorrectionMode::Unlimited, 0.0, 0.0));
    r.step();
    assert_eq!(r.st(0).position_correction.limiter, 0.5);
    assert!(!r.st(0).position_correction.limiter_limiting);
    assert!(r.out(u).busy && r.out(u).active);
    check_correction_is_below_the_axis(&r, 0);
    r.step();
    assert!(
        (r.st(0).actual_position - set).abs() < 1e-9,
        "actual stays ideal"
    );
    assert_eq!(r.st(0).set_position, set);

    // FAST back to 0.3 with 1000 u/s²: 1000 × 0.001² = 0.001 per cycle → 200 cycles.
    let f = r.ok(0, limiter(0.3, PositionCorrectionMode::Fast, 1000.0, 0.0));
    assert!(r.out(u).command_aborted, "the new command takes over");
    let mut cycles = 0;
    let mut last = 0.5;
    loop {
        r.step();
        cycles += 1;
        let c = r.st(0).position_correction;
        assert!((last - c.limiter) <= 0.001 + 1e-12 && c.limiter <= last);
        check_correction_is_below_the_axis(&r, 0);
        last = c.limiter;
        if !c.limiter_limiting {
            break;
        }
        assert!(cycles < 1000);
    }
    assert!((199..=201).contains(&cycles), "{cycles} cycles");
    assert!((last - 0.3).abs() < 1e-12);
    assert!(r.out(f).busy);

    // FULLLENGTH: +1 over 10 units of travel; nothing while the axis stands.
    let fl = r.ok(
        0,
        limiter(1.3, PositionCorrectionMode::FullLength, 0.0, 10.0),
    );
    r.run(0.1);
    assert!((r.st(0).position_correction.limiter - 0.3).abs() < 1e-12);
    let m = r.ok(0, CommandKind::MoveRelative(mv(20.0, 100.0)));
    let start = r.st(0).set_position;
    r.until(2.0, |r| {
        let st = r.st(0);
        let travelled = st.set_position - start;
        let expected = (0.3 + travelled / 10.0).min(1.3);
        assert!(
            (st.position_correction.limiter - expected).abs() < 1e-9,
            "{} after {travelled}",
            st.position_correction.limiter
        );
        check_correction_is_below_the_axis(r, 0);
        r.out(m).done
    });
    // Enable FALSE: the limiter's correction stays as it is.
    r.ok(0, CommandKind::Release { target: fl });
    r.step();
    assert!(!r.st(0).position_correction.limiter_enabled);
    assert!((r.st(0).position_correction.limiter - 1.3).abs() < 1e-9);
}

/// §4.5.2 and appendix §7.3: with the reference on the left flank (default) the backlash is
/// compensated while travelling negative (actual + backlash, setpoint − backlash) and not
/// while travelling positive; it changes at most Ramp per second (Limiting meanwhile);
/// CurrentBacklash in the status. On the right flank the signs and direction turn round.
/// DisableMode Reset returns it to 0 at once; Hold keeps it.
#[test]
fn s4_5_2_backlash_follows_the_travel_direction_within_its_ramp() {
    let mut r = Rig::new(1);
    power(&mut r);
    enable_position_correction(&mut r, 0);
    let b = r.ok(0, backlash(0.2, false, 10.0, DisableMode::Reset));
    r.step();
    assert_eq!(r.st(0).position_correction.backlash, 0.0, "no travel yet");
    let m = r.ok(0, CommandKind::MoveRelative(mv(-5.0, 50.0)));
    let mut last = 0.0;
    r.until(1.0, |r| {
        let c = r.st(0).position_correction;
        assert!(c.backlash - last <= 10.0 * DT + 1e-12, "ramp exceeded");
        assert!((0.0..=0.2 + 1e-12).contains(&c.backlash));
        check_correction_is_below_the_axis(r, 0);
        last = c.backlash;
        r.out(m).done
    });
    assert!((last - 0.2).abs() < 1e-12 && !r.st(0).position_correction.backlash_limiting);
    // Positive travel: back to 0 on the ramp.
    let m = r.ok(0, CommandKind::MoveRelative(mv(5.0, 50.0)));
    r.until(1.0, |r| {
        check_correction_is_below_the_axis(r, 0);
        r.out(m).done
    });
    assert_eq!(r.st(0).position_correction.backlash, 0.0);
    r.ok(0, CommandKind::MoveRelative(mv(-5.0, 50.0)));
    r.run(0.2);
    assert!(r.st(0).position_correction.backlash > 0.0);
    // Reset: 0 at once.
    r.ok(0, CommandKind::Release { target: b });
    r.step();
    assert_eq!(r.st(0).position_correction.backlash, 0.0);
    assert!(!r.st(0).position_correction.backlash_enabled);
    r.run(0.5);

    // Right flank: −backlash while travelling positive; Hold keeps it after the release.
    let b = r.ok(0, backlash(0.2, true, 10.0, DisableMode::Hold));
    let m = r.ok(0, CommandKind::MoveRelative(mv(5.0, 50.0)));
    r.until(1.0, |r| r.out(m).done);
    assert!((r.st(0).position_correction.backlash + 0.2).abs() < 1e-12);
    r.ok(0, CommandKind::Release { target: b });
    r.run(0.1);
    assert!((r.st(0).position_correction.backlash + 0.2).abs() < 1e-12);
    check_correction_is_below_the_axis(&r, 0);
}

/// §4.5.12: the compensation of the axis's table at the set position (the manual's 21-point
/// example), reached at most at Ramp per second, following the table as the axis travels;
/// a table for the positive direction only gives nothing while travelling negative.
#[test]
fn s4_5_12_table_compensation_follows_the_table_along_the_travel() {
    let table = CompensationTable {
        min_position: -10.0,
        max_position: 10.0,
        compensation: vec![
            1.0, 0.9, 0.8, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2, 0.1, 0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.4,
            0.3, 0.2, 0.1, 0.0,
        ],
        direction: WorkDirection::Both,
        modulo: false,
    };
    let config = |t: CompensationTable| AxisConfig {
        modulo: false,
        parameters: params(),
        compensation_table: Some(t),
        drive_executed: false,
    };
    let mut r = Rig::with_configs(vec![config(table.clone())]);
    power(&mut r);
    enable_position_correction(&mut r, 0);
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(4.5, 100.0)));
    r.until(1.0, |r| r.out(m).done);
    let t = r.ok(
        0,
        CommandKind::TableBasedPositionCompensation {
            ramp: 1.0,
            disable_mode: DisableMode::Hold,
        },
    );
    let mut cycles = 0;
    r.until(1.0, |r| {
        cycles += 1;
        let c = r.st(0).position_correction;
        assert!(c.table <= cycles as f64 * DT + 1e-12, "ramp 1 u/s exceeded");
        check_correction_is_below_the_axis(r, 0);
        !c.table_limiting
    });
    let c = r.st(0).position_correction.table;
    assert!((c - 0.45).abs() < 1e-9, "{c}");
    assert!(r.out(t).busy && r.out(t).active);
    // Travel slowly (the ramp keeps up at 1 u/s with slopes of 0.1 per unit at 5 u/s).
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(-7.0, 5.0)));
    r.until(5.0, |r| {
        let st = r.st(0);
        assert!(
            (st.position_correction.table - table.at(st.set_position)).abs() < 0.01,
            "{} at {}",
            st.position_correction.table,
            st.set_position
        );
        check_correction_is_below_the_axis(r, 0);
        r.out(m).done
    });
    assert!((r.st(0).position_correction.table - 0.7).abs() < 1e-9);

    // Positive direction only: travelling negative gives 0.
    let mut r = Rig::with_configs(vec![config(CompensationTable {
        direction: WorkDirection::Positive,
        ..table
    })]);
    power(&mut r);
    enable_position_correction(&mut r, 0);
    r.ok(
        0,
        CommandKind::TableBasedPositionCompensation {
            ramp: 10.0,
            disable_mode: DisableMode::Hold,
        },
    );
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(-5.0, 5.0)));
    r.until(3.0, |r| r.out(m).done);
    assert_eq!(r.st(0).position_correction.table, 0.0);
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(-4.0, 5.0)));
    r.until(3.0, |r| r.out(m).done);
    r.run(0.2);
    assert!((r.st(0).position_correction.table - 0.4).abs() < 1e-9);
}
