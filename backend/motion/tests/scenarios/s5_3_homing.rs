//! §5.3 Homing: MC_Home direct, force and reset calibration, and the referencing sequence
//! against the cam, the index pulse and the drive latch (§11a item 25).

use super::*;

/// MC_SetPosition relative +5: the MC_SetPosition offset (#2003) is 5.
fn set_position_offset_5(r: &mut Rig) {
    r.ok(
        0,
        CommandKind::SetPosition {
            position: 5.0,
            relative: true,
            clear_position_lag: false,
            clear_position_offset: false,
        },
    );
    assert_eq!(r.st(0).set_position_offset, 5.0);
}

#[test]
fn s11a_25_home_direct_force_reset_calibration() {
    let mut r = Rig::new(1);
    power(&mut r);
    set_position_offset_5(&mut r);
    r.ok(
        0,
        CommandKind::Home {
            position: Some(42.0),
            mode: HomingMode::Direct,
            options: HomingOptions::default(),
        },
    );
    assert!(r.st(0).homed);
    assert!((r.st(0).set_position - 42.0).abs() < 1e-9);
    assert_eq!(r.st(0).set_position_offset, 0.0);
    r.run(0.01);
    assert_eq!(r.plants[0].pos, 0.0, "direct homing moved the axis");
    r.ok(
        0,
        CommandKind::Home {
            position: None,
            mode: HomingMode::ResetCalibration,
            options: HomingOptions::default(),
        },
    );
    assert!(!r.st(0).homed);
    r.ok(
        0,
        CommandKind::Home {
            position: None,
            mode: HomingMode::ForceCalibration,
            options: HomingOptions::default(),
        },
    );
    assert!(r.st(0).homed);
    assert!((r.st(0).set_position - 42.0).abs() < 1e-9);
}

/// MC_Home with the referencing sequence (#1076) to `position`; returns when it has ended.
fn home_by_sequence(r: &mut Rig, position: f64) -> CommandId {
    let h = r.ok(
        0,
        CommandKind::Home {
            position: Some(position),
            mode: HomingMode::Default,
            options: HomingOptions::default(),
        },
    );
    r.until(20.0, |r| !r.out(h).busy);
    h
}

/// §11a #25 for the referencing sequence (not only MC_Direct): homing clears the
/// MC_SetPosition offset.
#[test]
fn s11a_25_a_homing_sequence_clears_the_set_position_offset() {
    let mut r = Rig::new(1);
    r.plants[0].cam = Some((50.0, 55.0));
    r.plants[0].index_period = Some(8.0);
    power(&mut r);
    set_position_offset_5(&mut r);
    let h = home_by_sequence(&mut r, 100.0);
    assert!(r.out(h).done && r.st(0).homed);
    assert_eq!(r.st(0).set_position_offset, 0.0);
}

#[test]
fn homing_sequence_cam_then_index_pulse_references_exactly() {
    let mut r = Rig::new(1);
    r.plants[0].cam = Some((50.0, 55.0));
    r.plants[0].index_period = Some(8.0); // pulses at …, 40, 48, 56 …
    power(&mut r);
    let h = r.ok(
        0,
        CommandKind::Home {
            position: Some(100.0),
            mode: HomingMode::Default,
            options: HomingOptions::default(),
        },
    );
    assert_eq!(r.st(0).state, AxisState::Homing);
    let mut phases = vec![];
    r.until(20.0, |r| {
        let p = r.st(0).homing_phase;
        if phases.last() != Some(&p) {
            phases.push(p);
        }
        !r.out(h).busy
    });
    assert!(r.out(h).done, "{:?}", r.out(h));
    r.run(0.01); // the drive follows the last setpoint
    use HomingPhase::*;
    assert_eq!(
        phases,
        vec![
            SearchCam,
            StopOnCam,
            LeaveCam,
            WaitCamFallingEdge,
            WaitLatch,
            SetPosition,
            Idle
        ]
    );
    // ST_HomingOptions: an undefined SyncDirection is positive, so the cam is left forwards
    // (falling edge at 55) and the first index pulse is at 56: the drive position 56 is now
    // the reference 100.
    let s = r.st(0);
    assert!(s.homed && s.state == AxisState::Standstill);
    assert!(
        (s.actual_position - (100.0 + (r.plants[0].pos - 56.0))).abs() < 1e-9,
        "{s:?} plant {}",
        r.plants[0].pos
    );
}

/// A homing run that reaches a limit switch before the cam says so (0x7030, cam not found)
/// and stops on the switch in ErrorStop: an axis on an end of travel is never a silent
/// Standstill.
#[test]
fn homing_fails_cleanly_when_the_cam_is_never_found() {
    let mut r = Rig::new(1);
    power(&mut r);
    let h = r.ok(
        0,
        CommandKind::Home {
            position: None,
            mode: HomingMode::Default,
            options: HomingOptions::default(),
        },
    );
    r.run(0.5);
    r.plants[0].limit_positive = true;
    r.until(2.0, |r| !r.out(h).busy);
    assert_eq!(r.out(h).error_id, ErrorId::HOMING_FAILED.0);
    assert_eq!(r.st(0).state, AxisState::ErrorStop);
    assert_eq!(r.st(0).error_id, ErrorId::HOMING_FAILED.0);
    assert!(!r.st(0).homed);
    r.until(1.0, |r| !r.st(0).moving);
    r.plants[0].limit_positive = false;
    r.ok(0, CommandKind::Reset);
    r.until(0.1, |r| r.st(0).state == AxisState::Standstill);
}

#[test]
fn homing_reference_modes_plc_cam_and_drive_latch_on_the_cam_edge() {
    // PLC cam (#1076 = 1): the reference is the falling edge of the cam seen by the kernel.
    let mut p = params();
    p.axis_encoder_reference_mode = 1;
    let mut r = Rig::with(vec![(false, p)]);
    r.plants[0].cam = Some((50.0, 55.0));
    r.power_on(0);
    let h = home_by_sequence(&mut r, 0.0);
    assert!(r.out(h).done);
    r.run(0.01);
    // Leaving the cam forwards (the default sync direction), its falling edge is at 55
    // (within one cycle of travel at the sync velocity 5 mm/s, the resolution of a PLC cam).
    let zero_at_drive = r.plants[0].pos - r.st(0).actual_position;
    assert!(
        (zero_at_drive - 55.0).abs() <= 5.0 * DT + 1e-9,
        "{zero_at_drive}"
    );

    // Hardware latch on the rising cam edge (#1076 = 3), found while searching: exact.
    let mut p = params();
    p.axis_encoder_reference_mode = 3;
    let mut r = Rig::with(vec![(false, p)]);
    r.plants[0].cam = Some((50.0, 55.0));
    r.power_on(0);
    let h = home_by_sequence(&mut r, 7.0);
    assert!(r.out(h).done);
    r.run(0.01);
    let at = r.plants[0].pos - (r.st(0).actual_position - 7.0);
    assert!((at - 50.0).abs() < 1e-9, "{at}");
}

/// Spec §5.3.1: with the cam already active at the start, homing begins at phase 3 (leave
/// the cam) — also in the drive-latch modes (#1076 = 3, 4, 6, 7), which leave the cam against
/// the search direction and search it again: they latch the same cam edge as a search from
/// outside (rising: the cam's start 50, falling: its end 55, searching positive).
#[test]
fn homing_with_the_cam_active_at_the_start_begins_by_leaving_the_cam_in_every_mode() {
    use ReferenceMode::*;
    for (mode, edge) in [
        (HardwareLatchPos, Some(50.0)),
        (HardwareLatchNeg, Some(55.0)),
        (SoftDriveLatchPos, Some(50.0)),
        (SoftDriveLatchNeg, Some(55.0)),
        (PlcCam, None),
        (HardwareSync, None),
    ] {
        let mut references = vec![];
        for start in [0.0, 52.0] {
            let mut r = Rig::new(1);
            r.plants[0].cam = Some((50.0, 55.0));
            r.plants[0].index_period = Some(8.0);
            r.plants[0].pos = start;
            r.power_on(0);
            let h = r.ok(
                0,
                CommandKind::Home {
                    position: Some(7.0),
                    mode: HomingMode::Default,
                    options: HomingOptions {
                        reference_mode: Some(mode),
                        ..HomingOptions::default()
                    },
                },
            );
            let mut phases = vec![r.st(0).homing_phase];
            r.until(20.0, |r| {
                let p = r.st(0).homing_phase;
                if phases.last() != Some(&p) {
                    phases.push(p);
                }
                !r.out(h).busy
            });
            assert!(r.out(h).done, "{mode:?} from {start}: {:?}", r.out(h));
            if start == 52.0 {
                assert_eq!(phases[0], HomingPhase::LeaveCam, "{mode:?}: {phases:?}");
            } else {
                assert_eq!(phases[0], HomingPhase::SearchCam, "{mode:?}: {phases:?}");
            }
            r.run(0.01);
            // Where the drive position that became 7 lies.
            references.push(r.plants[0].pos - (r.st(0).actual_position - 7.0));
        }
        if let Some(edge) = edge {
            for at in &references {
                assert!((at - edge).abs() < 1e-9, "{mode:?}: {references:?}");
            }
        } else {
            // The same reference (cam left backwards; PLC cam to within one cycle of travel).
            assert!(
                (references[0] - references[1]).abs() <= 5.0 * DT + 1e-9,
                "{mode:?}: {references:?}"
            );
        }
    }
}

#[test]
fn a_second_homing_run_never_uses_a_latch_left_from_an_aborted_one() {
    let mut r = Rig::new(1);
    r.plants[0].cam = Some((50.0, 55.0));
    r.plants[0].index_period = Some(8.0);
    r.power_on(0);
    let h = r.ok(
        0,
        CommandKind::Home {
            position: Some(100.0),
            mode: HomingMode::Default,
            options: HomingOptions::default(),
        },
    );
    r.until(20.0, |r| r.st(0).homing_phase == HomingPhase::WaitLatch);
    r.run(0.1); // latch armed; the next pulse (56) is not reached yet
    let s = r.ok(
        0,
        CommandKind::Stop {
            deceleration: 0.0,
            jerk: 0.0,
            options: MoveOptions::default(),
        },
    );
    assert!(r.out(h).command_aborted);
    r.until(2.0, |r| r.out(s).done);
    r.ok(0, CommandKind::Release { target: s });
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(200.0, 300.0)));
    r.until(5.0, |r| r.out(m).done);
    r.plants[0].cam = Some((250.0, 255.0));
    let h2 = r.ok(
        0,
        CommandKind::Home {
            position: Some(100.0),
            mode: HomingMode::Default,
            options: HomingOptions::default(),
        },
    );
    r.until(30.0, |r| !r.out(h2).busy);
    assert!(r.out(h2).done);
    r.run(0.01);
    // Referenced to the pulse at 256 (above the new cam), not the stale one at 56.
    let zero = r.plants[0].pos - (r.st(0).actual_position - 100.0);
    assert!((zero - 256.0).abs() < 1e-9, "{zero}");
}

#[test]
fn homing_stops_at_a_limit_switch_in_any_phase() {
    let mut r = Rig::new(1);
    r.plants[0].cam = Some((10.0, 15.0)); // a cam, but no index pulse ever comes
    r.power_on(0);
    let h = r.ok(
        0,
        CommandKind::Home {
            position: None,
            mode: HomingMode::Default,
            options: HomingOptions::default(),
        },
    );
    r.until(20.0, |r| r.st(0).homing_phase == HomingPhase::WaitLatch);
    r.run(0.5);
    r.plants[0].limit_positive = true;
    r.until(3.0, |r| !r.out(h).busy);
    // The cam was found, the sync pulse was not: the error says which.
    assert_eq!(r.out(h).error_id, ErrorId::HOMING_SYNC_NOT_FOUND.0);
    assert_eq!(r.st(0).state, AxisState::ErrorStop);
}

/// A drive-latch homing run (#1076 = 3, 4, 6, 7) started off the cam never travels against
/// the search direction, so a blocked direction there (negative limit switch) does not refuse
/// it; a mode with a sync phase does travel it and is refused, and so is a drive-latch run that
/// starts on the cam (it leaves the cam backwards first).
#[test]
fn homing_is_refused_only_for_a_direction_the_run_will_travel() {
    use ReferenceMode::*;
    let home = |r: &mut Rig, mode: ReferenceMode, sync_direction: Option<Direction>| {
        r.cmd(
            0,
            CommandKind::Home {
                position: Some(0.0),
                mode: HomingMode::Default,
                options: HomingOptions {
                    reference_mode: Some(mode),
                    sync_direction,
                    ..HomingOptions::default()
                },
            },
        )
    };
    let neg = Some(Direction::Negative);
    for (mode, start, sync, accepted) in [
        (HardwareLatchPos, 0.0, None, true),
        (SoftDriveLatchNeg, 0.0, None, true),
        (HardwareLatchPos, 52.0, None, false),
        (HardwareSync, 0.0, neg, false),
        // The default sync direction is positive (ST_HomingOptions): never travels negative.
        (HardwareSync, 0.0, None, true),
    ] {
        let mut r = Rig::new(1);
        r.plants[0].cam = Some((50.0, 55.0));
        r.plants[0].index_period = Some(8.0);
        r.plants[0].pos = start;
        r.power_on(0);
        r.plants[0].limit_negative = true;
        r.run(0.01);
        let (id, verdict) = home(&mut r, mode, sync);
        assert_eq!(
            verdict == Verdict::Accepted,
            accepted,
            "{mode:?} from {start}: {verdict:?}"
        );
        if accepted {
            r.until(20.0, |r| !r.out(id).busy);
            assert!(r.out(id).done, "{mode:?}: {:?}", r.out(id));
        }
    }
}

/// A cam narrower than the search velocity's braking distance: the axis stops beyond it, and
/// the run ends with why (0x7032, could not stop on the cam).
#[test]
fn homing_that_cannot_stop_on_the_cam_says_so() {
    let mut r = Rig::new(1);
    r.plants[0].cam = Some((50.0, 50.5));
    r.plants[0].index_period = Some(8.0);
    r.power_on(0);
    let h = r.ok(
        0,
        CommandKind::Home {
            position: Some(0.0),
            mode: HomingMode::Default,
            options: HomingOptions {
                search_velocity: Some(300.0),
                ..HomingOptions::default()
            },
        },
    );
    r.until(5.0, |r| !r.out(h).busy);
    assert_eq!(r.out(h).error_id, ErrorId::HOMING_CAM_OVERRUN.0);
    assert!(!r.out(h).done && !r.st(0).homed);
    assert!(r.plants[0].pos > 50.5, "{}", r.plants[0].pos);
    // An FB error, not an axis error: the axis stands where it stopped, ready for a new run.
    r.until(1.0, |r| !r.st(0).moving);
    assert_eq!(r.st(0).state, AxisState::Standstill);
}
