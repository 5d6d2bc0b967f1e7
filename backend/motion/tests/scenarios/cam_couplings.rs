//! Cam couplings (spec camming-tf5050.md §1.4–§1.8, §2.2–§2.4, §5): MC_CamIn, MC_CamOut,
//! MC_CamScaling cycle by cycle, with the rig's FB-protocol checks in every cycle.

use super::*;
use motion::cam::*;

const T_LINE: u32 = 1;
const T_HALF: u32 = 2;

/// (0, 0) – (360, 360), linear interpolation: one stroke of 360 per period when periodic.
fn line(periodic: bool) -> CamTableData {
    let mut t = CamTableData::positions(vec![[0.0, 0.0], [360.0, 360.0]], true);
    t.periodic = periodic;
    t
}

fn cam_in(master: u16, table: u32) -> CamIn {
    CamIn {
        master,
        cam_table: table,
        master_offset: 0.0,
        slave_offset: 0.0,
        master_scaling: 1.0,
        slave_scaling: 1.0,
        start_mode: StartMode::Absolute,
        activation_mode: CamActivationMode::Instantaneous,
        activation_position: 0.0,
        master_scaling_mode: CamScalingMode::UserDefined,
        slave_scaling_mode: CamScalingMode::UserDefined,
        interpolation: None,
        ramp_in: RampIn::default(),
    }
}

/// Two axes powered, the master (0) and the slave (1) moved to their positions; the slave's
/// dynamics bounds opened (it follows its master through the cam).
fn rig_at(master: f64, slave: f64) -> Rig {
    let mut p = params();
    p.axis_velo_max = 2000.0;
    let mut r = Rig::with(vec![(false, p.clone()), (false, p)]);
    r.bounds[1].velocity = 1e9;
    r.bounds[1].acceleration = 1e9;
    r.bounds[1].jerk = 1e12;
    r.power_on(0);
    r.power_on(1);
    for (axis, to) in [(0, master), (1, slave)] {
        if to != 0.0 {
            let m = r.ok(axis, CommandKind::MoveAbsolute(mv(to, 1000.0)));
            r.until(10.0, |r| r.out(m).done);
        }
    }
    r
}

fn move_master(r: &mut Rig, to: f64, v: f64, mut each: impl FnMut(&Rig)) {
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(to, v)));
    r.until(30.0, |r| {
        each(r);
        r.out(m).done
    });
}

/// Spec §5.3 / §1.4: a periodic cam with stroke couples in its base cycle (master at 1000 →
/// slave at 280, not 1000), adds a stroke per cycle forwards and takes it back backwards.
#[test]
fn a_periodic_cam_couples_in_the_base_cycle_and_counts_strokes() {
    let mut r = rig_at(1000.0, 280.0);
    r.cam(T_LINE, &line(true));
    let c = r.ok(1, CommandKind::CamIn(cam_in(0, T_LINE)));
    // Coupled in the cycle it is accepted: InSync ends the command.
    assert!(r.out(c).in_sync && !r.out(c).busy && !r.out(c).error);
    assert_eq!(r.st(1).state, AxisState::SynchronizedMotion);
    assert_eq!(r.st(1).cam.cam_table_id, T_LINE);
    let follows = |r: &Rig| {
        let m = r.st(0).set_position;
        let want = m - 720.0; // the base cycle is the master's third: strokes count from it
        assert!(
            (r.st(1).set_position - want).abs() < 1e-9,
            "master {m}: slave {} ≠ {want}",
            r.st(1).set_position
        );
        assert!((r.st(1).set_velocity - r.st(0).set_velocity).abs() < 1e-9);
    };
    move_master(&mut r, 1100.0, 200.0, follows);
    assert!((r.st(1).set_position - 380.0).abs() < 1e-9);
    assert!(
        (r.st(1).cam.sum_of_slave_strokes - 360.0).abs() < 1e-9,
        "{:?}",
        r.st(1).cam
    );
    move_master(&mut r, 1000.0, 200.0, follows);
    assert!((r.st(1).set_position - 280.0).abs() < 1e-9);
    move_master(&mut r, 700.0, 300.0, follows);
    assert!((r.st(1).set_position + 20.0).abs() < 1e-9);
    assert!((r.st(1).cam.sum_of_slave_strokes + 360.0).abs() < 1e-9);
    assert!((r.st(1).cam.actual_master_cam_pos - 340.0).abs() < 1e-9);
}

/// A cam that would make the slave jump is refused (0x7084) and changes nothing; the same
/// cam with the slave pre-positioned couples, also relatively.
#[test]
fn coupling_never_makes_the_slave_jump() {
    let mut r = rig_at(90.0, 0.0);
    r.cam(T_LINE, &line(false));
    assert_eq!(
        r.rejected(1, CommandKind::CamIn(cam_in(0, T_LINE))),
        ErrorId::CAM_SLAVE_WOULD_JUMP
    );
    assert_eq!(r.st(1).state, AxisState::Standstill);
    // Slave relative: the cam's origin is where the slave stands; master relative too.
    let rel = CamIn {
        start_mode: StartMode::Relative,
        ..cam_in(0, T_LINE)
    };
    let c = r.ok(1, CommandKind::CamIn(rel));
    assert!(r.out(c).in_sync);
    let info = r.st(1).cam;
    assert!(!info.master_absolute && !info.slave_absolute);
    assert_eq!(
        (info.master_axis_coupling_pos, info.slave_axis_coupling_pos),
        (90.0, 0.0)
    );
    move_master(&mut r, 150.0, 100.0, |_| {});
    assert!((r.st(1).set_position - 60.0).abs() < 1e-9);
    // A table in use cannot leave the kernel.
    assert!(r.k.remove_cam(T_LINE).is_err());
    assert!(r.k.cam_in_use(T_LINE));
}

/// Spec §5.3 "activation at an axis position": pending (Busy, Active) until the master
/// passes 500, InSync in that cycle; with _POSITVEDIRECTION a master dithering around 500
/// does not trigger until it crosses upwards.
#[test]
fn coupling_at_a_master_axis_position_waits_for_the_crossing() {
    let mut r = rig_at(400.0, 0.0);
    // A cam at rest up to 550: the slave can couple while the master moves.
    let mut t = CamTableData::positions(vec![[0.0, 0.0], [550.0, 0.0], [600.0, 50.0]], false);
    t.periodic = false;
    r.cam(T_HALF, &t);
    let ci = CamIn {
        activation_mode: CamActivationMode::AtMasterAxisPosPositiveDirection,
        activation_position: 500.0,
        ..cam_in(0, T_HALF)
    };
    let c = r.ok(1, CommandKind::CamIn(ci));
    assert!(r.out(c).busy && r.out(c).active && !r.out(c).in_sync);
    assert_eq!(r.st(1).state, AxisState::Standstill);
    // The master goes to 499.999 and back a little: nothing.
    move_master(&mut r, 499.999, 100.0, |_| {});
    move_master(&mut r, 499.5, 100.0, |_| {});
    assert!(r.out(c).busy && r.out(c).active);
    // Upwards across 500: InSync in the cycle the master passes it.
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(560.0, 100.0)));
    r.until(5.0, |r| {
        let p = r.st(0).set_position;
        if p < 500.0 {
            assert!(r.out(c).busy, "coupled before the master reached 500 ({p})");
        } else {
            assert!(r.out(c).in_sync && !r.out(c).busy, "not coupled at {p}");
        }
        r.out(m).done
    });
    assert!((r.st(1).set_position - 10.0).abs() < 1e-9);
}

/// A periodic motion function with stroke 240 that runs synchronously (slope 1) at both ends
/// of its cycle: it joins the 1:1 line at a cycle border without a velocity step.
fn slower_in_the_middle() -> CamTableData {
    use MotionFunctionType::*;
    let point = |i: u32, law, x: f64, y: f64| MotionFunctionPoint {
        point_index: i,
        function_type: law,
        point_type: MotionPointType::Velocity,
        rel_index_next_point: 1,
        master_pos: x,
        slave_pos: y,
        slave_velo: 1.0,
        slave_acc: 0.0,
        slave_jerk: 0.0,
    };
    let mut t = CamTableData::motion_function(vec![
        point(1, Polynom1, 0.0, 0.0),
        point(2, Polynom5Mm, 60.0, 60.0),
        point(3, Polynom1, 300.0, 180.0),
        point(4, Polynom1, 360.0, 240.0),
    ]);
    t.periodic = true;
    t
}

/// Spec §5.1 step 3: switching cams at the next cycle with slave autooffset: CamTableQueued
/// and Active until the master crosses the period border, then InSync, no jump in position
/// or velocity. DELETEQUEUEDDATA drops a queued switch.
#[test]
fn a_cam_switch_at_the_next_cycle_is_queued_and_seamless() {
    let mut r = rig_at(100.0, 100.0);
    r.cam(T_LINE, &line(true));
    r.cam(T_HALF, &slower_in_the_middle());
    r.ok(1, CommandKind::CamIn(cam_in(0, T_LINE)));
    let switch = CamIn {
        activation_mode: CamActivationMode::NextCycle,
        slave_scaling_mode: CamScalingMode::AutoOffset,
        ..cam_in(0, T_HALF)
    };
    let s = r.ok(1, CommandKind::CamIn(switch));
    assert!(r.out(s).active && r.st(1).cam_table_queued);
    assert_eq!(r.st(1).cam.cam_exchange_cam_table_id, T_HALF);
    // DELETEQUEUEDDATA drops it; a new one queues again.
    let d = r.ok(
        1,
        CommandKind::CamIn(CamIn {
            activation_mode: CamActivationMode::DeleteQueuedData,
            ..switch
        }),
    );
    assert!(r.out(s).command_aborted && r.out(d).done && !r.st(1).cam_table_queued);
    let s = r.ok(1, CommandKind::CamIn(switch));
    let (mut prev, mut prev_v) = (r.st(1).set_position, r.st(1).set_velocity);
    move_master(&mut r, 700.0, 200.0, |r| {
        let p = r.st(0).set_position;
        let (slave, v) = (r.st(1).set_position, r.st(1).set_velocity);
        assert!(
            (slave - prev).abs() <= 200.0 * DT + 1e-9,
            "slave jumped {prev} → {slave}"
        );
        assert!(
            (v - prev_v).abs() <= 2500.0 * DT + 1e-6,
            "velocity stepped {prev_v} → {v} at {p}"
        );
        assert!(!r.out(s).error, "{:?}", r.out(s));
        if p < 360.0 {
            assert!(
                r.st(1).cam_table_queued && r.out(s).active,
                "switched early at {p}"
            );
            assert_eq!(r.st(1).cam.cam_table_id, T_LINE);
        } else {
            assert!(
                !r.st(1).cam_table_queued && r.out(s).in_sync,
                "not switched at {p}"
            );
            assert_eq!(r.st(1).cam.cam_table_id, T_HALF);
        }
        (prev, prev_v) = (slave, v);
    });
    // 340 into the new cam's cycle: 240 − 20 of its stroke, counted from the switch.
    let want = 360.0 + 220.0;
    assert!(
        (r.st(1).set_position - want).abs() < 0.05,
        "{} ≠ {want}",
        r.st(1).set_position
    );
}

/// Spec §5.1 step 5: scaling the slave ×2 with AUTOOFFSET at rest keeps its position; the
/// next travel is doubled. A USERDEFINED scaling that would jump ends with 0x7084, so does
/// one that would step the velocity of a moving slave (the manual: scale at rest); at a
/// master position the scaling waits (CamScalingPending, Active).
#[test]
fn scaling_with_autooffset_keeps_the_slave_where_it_is() {
    let mut r = rig_at(50.0, 50.0);
    // 1:1 up to 100, at rest from 100 to 200.
    let t = CamTableData::positions(vec![[0.0, 0.0], [100.0, 100.0], [200.0, 100.0]], false);
    r.cam(T_LINE, &t);
    r.ok(1, CommandKind::CamIn(cam_in(0, T_LINE)));
    let scaling = CamScaling {
        activation_mode: CamActivationMode::Instantaneous,
        activation_position: 0.0,
        master_scaling_mode: CamScalingMode::Off,
        slave_scaling_mode: CamScalingMode::AutoOffset,
        master_offset: 0.0,
        slave_offset: 0.0,
        master_scaling: 1.0,
        slave_scaling: 2.0,
    };
    let s = r.ok(1, CommandKind::CamScaling(scaling));
    assert!(r.out(s).done && !r.st(1).cam_scaling_pending);
    assert_eq!(r.st(1).set_position, 50.0);
    assert_eq!(
        (r.st(1).cam.slave_scaling, r.st(1).cam.slave_offset),
        (2.0, -50.0)
    );
    move_master(&mut r, 60.0, 100.0, |_| {});
    assert!((r.st(1).set_position - 70.0).abs() < 1e-9);
    let jump = CamScaling {
        slave_scaling_mode: CamScalingMode::UserDefined,
        slave_scaling: 3.0,
        ..scaling
    };
    let j = r.ok(1, CommandKind::CamScaling(jump));
    assert_eq!(r.out(j).error_id, ErrorId::CAM_SLAVE_WOULD_JUMP.0);
    assert_eq!(r.st(1).cam.slave_scaling, 2.0, "unchanged");
    // Back to 1 when the master passes 80: the slave moves there (velocity step): refused.
    let at = |position: f64| CamScaling {
        activation_mode: CamActivationMode::AtMasterAxisPos,
        activation_position: position,
        slave_scaling: 1.0,
        ..scaling
    };
    let l = r.ok(1, CommandKind::CamScaling(at(80.0)));
    assert!(r.out(l).active && r.st(1).cam_scaling_pending);
    move_master(&mut r, 90.0, 100.0, |_| {});
    assert_eq!(r.out(l).error_id, ErrorId::CAM_SLAVE_WOULD_JUMP.0);
    assert_eq!(r.st(1).cam.slave_scaling, 2.0);
    // At 150 the slave rests (the cam's flat part): scaled there, no jump.
    let l = r.ok(1, CommandKind::CamScaling(at(150.0)));
    let mut prev = r.st(1).set_position;
    move_master(&mut r, 180.0, 100.0, |r| {
        let p = r.st(0).set_position;
        assert_eq!(r.out(l).active, p < 150.0, "at {p}");
        assert!((r.st(1).set_position - prev).abs() <= 2.0 * 100.0 * DT + 1e-9);
        prev = r.st(1).set_position;
    });
    assert!(r.out(l).done && !r.st(1).cam_scaling_pending);
    assert_eq!(r.st(1).cam.slave_scaling, 1.0);
    assert!(
        (r.st(1).set_position - 150.0).abs() < 1e-9,
        "{}",
        r.st(1).set_position
    );
}

/// Spec §2.2: after MC_CamOut in motion the slave keeps its velocity with no acceleration.
/// MC_GearOut does not decouple a cam slave; another motion command does.
#[test]
fn cam_out_in_motion_keeps_the_velocity() {
    let mut r = rig_at(0.0, 0.0);
    r.cam(T_LINE, &line(true));
    r.ok(1, CommandKind::CamIn(cam_in(0, T_LINE)));
    assert_eq!(
        r.rejected(1, CommandKind::GearOut),
        ErrorId::COMMAND_NOT_PERMITTED
    );
    let v = r.ok(0, velocity(100.0, Direction::Positive));
    r.until(2.0, |r| r.out(v).in_velocity);
    r.run(0.1);
    let o = r.ok(1, CommandKind::CamOut);
    assert!(r.out(o).done);
    assert_eq!(r.st(1).state, AxisState::ContinuousMotion);
    assert_eq!(r.st(1).cam.cam_table_id, 0);
    r.run(0.5);
    assert!((r.st(1).set_velocity - 100.0).abs() < 1e-9);
    assert_eq!(r.st(1).set_acceleration, 0.0);
    assert_eq!(r.rejected(1, CommandKind::CamOut), ErrorId::CAM_NOT_COUPLED);
}

/// Linear cams hold the first or last slave value outside their range (spec §1.4).
#[test]
fn a_linear_cam_holds_its_end_values_outside_its_range() {
    let mut r = rig_at(0.0, 0.0);
    let t = CamTableData::positions(vec![[0.0, 0.0], [100.0, 50.0], [200.0, 50.0]], false);
    r.cam(T_HALF, &t);
    r.ok(1, CommandKind::CamIn(cam_in(0, T_HALF)));
    move_master(&mut r, 300.0, 200.0, |_| {});
    assert_eq!(r.st(1).set_position, 50.0);
    assert_eq!(r.st(1).set_velocity, 0.0);
}

/// The rotary knife (spec §5.2): synchronous at the cut (30° either side), one stroke of
/// 360 per product; after N products SumOfSlaveStrokes = N·360.
#[test]
fn rotary_knife_one_stroke_per_product() {
    use MotionFunctionType::*;
    let point = |i: u32, law, x: f64, y: f64| MotionFunctionPoint {
        point_index: i,
        function_type: law,
        point_type: MotionPointType::Velocity,
        rel_index_next_point: 1,
        master_pos: x,
        slave_pos: y,
        slave_velo: 1.0,
        slave_acc: 0.0,
        slave_jerk: 0.0,
    };
    // A knife that waits between the cuts: slower in the middle, synchronous at the cut.
    let mut knife = CamTableData::motion_function(vec![
        point(1, Polynom1, 0.0, 0.0),
        point(2, Polynom5Mm, 30.0, 30.0),
        point(3, Polynom1, 330.0, 330.0),
        point(4, Polynom1, 360.0, 360.0),
    ]);
    knife.periodic = true;
    let mut r = rig_at(0.0, 0.0);
    r.cam(T_LINE, &knife);
    r.ok(1, CommandKind::CamIn(cam_in(0, T_LINE)));
    let v = r.ok(0, velocity(360.0, Direction::Positive));
    r.until(2.0, |r| r.out(v).in_velocity);
    let mut cuts = 0;
    let mut prev = r.st(1).cam.actual_master_cam_pos;
    r.until(20.0, |r| {
        let info = r.st(1).cam;
        if info.actual_master_cam_pos < prev {
            cuts += 1;
        }
        prev = info.actual_master_cam_pos;
        let xl = info.actual_master_cam_pos;
        if !(30.0..=330.0).contains(&xl) {
            // In the synchronous window the knife runs with the web.
            assert!(
                (r.st(1).set_velocity - r.st(0).set_velocity).abs() < 1e-6,
                "at {xl}"
            );
        }
        cuts == 5
    });
    let info = r.st(1).cam;
    let k = ((r.st(0).set_position) / 360.0).floor();
    assert!(
        (info.sum_of_slave_strokes - k * 360.0).abs() < 1e-9,
        "{info:?}"
    );
}

/// Modes the manual does not allow are refused (spec §1.6–§1.8): relative master with an
/// activation in cam coordinates or at the next cycle, NEXTCYCLEONCE, master autooffset at
/// the first coupling, a table that is not there.
#[test]
fn cam_modes_the_manual_forbids_are_refused() {
    let mut r = rig_at(0.0, 0.0);
    r.cam(T_LINE, &line(true));
    for ci in [
        CamIn {
            start_mode: StartMode::Relative,
            activation_mode: CamActivationMode::AtMasterCamPos,
            ..cam_in(0, T_LINE)
        },
        CamIn {
            start_mode: StartMode::MasterRelSlaveAbs,
            activation_mode: CamActivationMode::NextCycle,
            ..cam_in(0, T_LINE)
        },
        CamIn {
            activation_mode: CamActivationMode::NextCycleOnce,
            ..cam_in(0, T_LINE)
        },
        CamIn {
            activation_mode: CamActivationMode::DeleteQueuedData,
            ..cam_in(0, T_LINE)
        },
        CamIn {
            master_scaling_mode: CamScalingMode::AutoOffset,
            ..cam_in(0, T_LINE)
        },
    ] {
        assert_eq!(
            r.rejected(1, CommandKind::CamIn(ci)),
            ErrorId::CAM_MODE_INVALID,
            "{ci:?}"
        );
    }
    assert_eq!(
        r.rejected(1, CommandKind::CamIn(cam_in(0, 9))),
        ErrorId::CAM_TABLE_ID_INVALID
    );
    assert_eq!(
        r.rejected(
            1,
            CommandKind::CamIn(CamIn {
                slave_scaling: 0.0,
                ..cam_in(0, T_LINE)
            })
        ),
        ErrorId::PARAMETER_NOT_CORRECT
    );
    assert_eq!(
        r.rejected(1, CommandKind::CamIn(cam_in(1, T_LINE))),
        ErrorId::MASTER_INVALID
    );
}

/// `ST_CamInOptions.InterpolationType`: each coupling may interpolate a position table its own
/// way (decision 74). Two slaves on one linear table, one with the table's own interpolation
/// and one with a spline of its own, follow the library's values for their choice in every
/// cycle; 4POINT is refused.
#[test]
fn a_coupling_interpolates_a_position_table_its_own_way() {
    let mut p = params();
    p.axis_velo_max = 2000.0;
    let mut r = Rig::with(vec![(false, p.clone()), (false, p.clone()), (false, p)]);
    for s in [1, 2] {
        r.bounds[s].velocity = 1e9;
        r.bounds[s].acceleration = 1e9;
        r.bounds[s].jerk = 1e12;
    }
    for a in 0..3 {
        r.power_on(a);
    }
    let bent = rig::bent_positions();
    r.cam(T_LINE, &bent);
    let cam = Cam::build(&bent).unwrap();
    assert_eq!(cam.interpolation, InterpolationType::Linear);
    assert_eq!(
        r.rejected(
            2,
            CommandKind::CamIn(CamIn {
                interpolation: Some(InterpolationType::FourPoint),
                ..cam_in(0, T_LINE)
            })
        ),
        ErrorId::CAM_TABLE_TYPE_INVALID
    );
    let own = r.ok(1, CommandKind::CamIn(cam_in(0, T_LINE)));
    let spline = r.ok(
        2,
        CommandKind::CamIn(CamIn {
            interpolation: Some(InterpolationType::Spline),
            ..cam_in(0, T_LINE)
        }),
    );
    assert!(r.out(own).in_sync && r.out(spline).in_sync);
    let mut apart: f64 = 0.0;
    move_master(&mut r, 450.0, 300.0, |r| {
        let m = r.st(0).set_position;
        for (slave, how) in [
            (1, InterpolationType::Linear),
            (2, InterpolationType::Spline),
        ] {
            let want = cam.eval_with(m, how).position;
            let got = r.st(slave).set_position;
            assert!(
                (got - want).abs() < 1e-9,
                "{how:?} at master {m}: {got} ≠ {want}"
            );
        }
        apart = apart.max((r.st(1).set_position - r.st(2).set_position).abs());
    });
    // Between the rows the two interpolations differ; the spline's slave passes every row.
    assert!(
        apart > 1.0,
        "the spline coupling followed the linear one ({apart})"
    );
    assert!((r.st(2).set_position - (360.0 + 60.0)).abs() < 1e-6);
}

/// PLCopen ramp-in start modes (decision 75): a slave that is not where the cam puts it is
/// not refused but catches up — its deviation from the cam run down to 0 within the ramp-in
/// velocity, acceleration and jerk, continuous from its own motion — the MC_CamIn Busy and
/// Active until InSync, the slave exactly on the cam from then on. `ramp_in_positive` takes
/// the cam position modulo 360 ahead of the slave and never moves it backwards.
#[test]
fn a_ramp_in_catches_the_slave_up_with_its_cam() {
    for mode in [StartMode::RampIn, StartMode::RampInPositive] {
        let mut r = rig_at(0.0, 50.0);
        r.cam(T_LINE, &line(true));
        assert_eq!(
            r.rejected(1, CommandKind::CamIn(cam_in(0, T_LINE))),
            ErrorId::CAM_SLAVE_WOULD_JUMP
        );
        let ramp = CamIn {
            start_mode: mode,
            ramp_in: RampIn {
                velocity: 200.0,
                acceleration: 1000.0,
                deceleration: 1000.0,
                jerk: 10000.0,
            },
            ..cam_in(0, T_LINE)
        };
        // A ramp-in needs its velocity.
        let mut slow = ramp;
        slow.ramp_in.velocity = 0.0;
        assert_eq!(
            r.rejected(1, CommandKind::CamIn(slow)),
            ErrorId::PARAMETER_NOT_CORRECT
        );
        // The master runs at 100 mm/s; the slave stands at 50.
        r.ok(0, velocity(100.0, Direction::Positive));
        r.until(1.0, |r| r.st(0).set_velocity >= 100.0);
        r.run(0.1);
        let c = r.ok(1, CommandKind::CamIn(ramp));
        assert!(r.out(c).busy && r.out(c).active && !r.out(c).in_sync);
        assert_eq!(r.st(1).state, AxisState::SynchronizedMotion);
        let (mut p0, mut v0) = (r.st(1).set_position, r.st(1).set_velocity);
        let target = |m: f64| {
            if mode == StartMode::RampInPositive {
                m + 360.0
            } else {
                m
            }
        };
        let cycles = r.until(5.0, |r| {
            let s = r.st(1);
            // Continuous: no velocity step beyond the ramp's and the cam's acceleration.
            assert!(
                (s.set_velocity - v0).abs() <= 1000.0 * DT + 1e-6,
                "{} after {v0}",
                s.set_velocity
            );
            assert!((s.set_position - p0 - s.set_velocity * DT).abs() < 1e-3);
            // The deviation's rate stays within the ramp-in velocity.
            assert!((s.set_velocity - r.st(0).set_velocity).abs() <= 200.0 + 1e-6);
            if mode == StartMode::RampInPositive {
                assert!(s.set_velocity >= -1e-9, "backwards at {}", s.set_velocity);
            }
            (p0, v0) = (s.set_position, s.set_velocity);
            r.out(c).in_sync
        });
        assert!(cycles > 10, "{mode:?}: in sync after {cycles} cycles");
        let o = r.out(c);
        assert!(!o.busy && !o.active && !o.error, "{o:?}");
        r.run(0.2);
        let (m, s) = (r.st(0).set_position, r.st(1).set_position);
        assert!(
            (s - target(m)).abs() < 1e-9,
            "{mode:?}: slave {s}, master {m}"
        );
        assert_eq!(r.st(1).state, AxisState::SynchronizedMotion);
    }
}

/// MC_CamOut during the ramp-in aborts the MC_CamIn and lets the slave go on at the velocity
/// the ramp gave it, without a jump; a ramp-in while coupled (a switch) is refused.
#[test]
fn a_ramp_in_is_aborted_like_any_coupling() {
    let mut r = rig_at(0.0, 50.0);
    r.cam(T_LINE, &line(true));
    let ramp = CamIn {
        start_mode: StartMode::RampIn,
        ramp_in: RampIn {
            velocity: 20.0,
            ..RampIn::default()
        },
        ..cam_in(0, T_LINE)
    };
    let c = r.ok(1, CommandKind::CamIn(ramp));
    r.run(0.5);
    assert!(r.out(c).busy);
    assert_eq!(
        r.rejected(1, CommandKind::CamIn(ramp)),
        ErrorId::CAM_MODE_INVALID
    );
    let (p, v) = (r.st(1).set_position, r.st(1).set_velocity);
    assert!(p < 50.0 - 5.0 && p > 0.0, "ramping down from 50: {p}");
    assert!(v < -1.0, "{v}");
    // MC_CamOut: the slave keeps the velocity the ramp gave it; the MC_CamIn is aborted.
    let o = r.ok(1, CommandKind::CamOut);
    assert!(r.out(c).command_aborted && !r.out(c).busy, "{:?}", r.out(c));
    assert!(r.out(o).done);
    r.step();
    assert_eq!(r.st(1).state, AxisState::ContinuousMotion);
    assert!(
        (r.st(1).set_velocity - v).abs() < 1e-6,
        "{} after {v}",
        r.st(1).set_velocity
    );
    assert!((r.st(1).set_position - (p + v * DT)).abs() < 1e-6);
}

/// A superposition during the ramp-in shifts the cam once: the deviation the ramp runs down is
/// not moved with it (it would land the slave the distance twice off its cam).
#[test]
fn a_superposition_during_the_ramp_in_counts_once() {
    let mut r = rig_at(0.0, 50.0);
    r.cam(T_LINE, &line(true));
    let ramp = CamIn {
        start_mode: StartMode::RampIn,
        ramp_in: RampIn {
            velocity: 20.0,
            ..RampIn::default()
        },
        ..cam_in(0, T_LINE)
    };
    let c = r.ok(1, CommandKind::CamIn(ramp));
    r.run(0.3);
    assert!(r.out(c).busy && r.st(1).set_velocity < -1.0);
    let sp = r.ok(
        1,
        CommandKind::MoveSuperImposed(Superposition {
            mode: SuperpositionMode::VeloReductionAdditiveMotion,
            distance: 5.0,
            velocity_diff: 10.0,
            velocity_process: 20.0,
            length: 20.0,
            ..Default::default()
        }),
    );
    r.until(10.0, |r| r.out(c).in_sync && r.out(sp).done);
    r.run(0.1);
    // The slave was moving negative: 5 more travel that way, once.
    let (m, s) = (r.st(0).set_position, r.st(1).set_position);
    assert!(
        (s - (m - 5.0)).abs() < 1e-6,
        "slave {s}, master {m}: not the cam − 5"
    );
}

/// A cam slave is a coupled slave: one that crosses its soft limit is decoupled and stopped
/// in ErrorStop (0x7003), a queued switch ends with the error; a pending coupling ends when a
/// motion command takes the axis.
#[test]
fn a_cam_slave_at_its_soft_limit_stops_and_queued_changes_end() {
    let mut p = params_with_soft_limits(-1000.0, 300.0);
    p.axis_velo_max = 2000.0;
    let mut r = Rig::with(vec![(false, params()), (false, p)]);
    r.bounds[1].acceleration = 1e9;
    r.bounds[1].jerk = 1e12;
    r.power_on(0);
    r.power_on(1);
    r.cam(T_LINE, &line(true));
    r.ok(1, CommandKind::CamIn(cam_in(0, T_LINE)));
    let queued = r.ok(
        1,
        CommandKind::CamIn(CamIn {
            activation_mode: CamActivationMode::AtMasterAxisPos,
            activation_position: 900.0,
            ..cam_in(0, T_LINE)
        }),
    );
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(500.0, 200.0)));
    r.until(10.0, |r| r.st(1).state == AxisState::ErrorStop);
    assert_eq!(r.st(1).error_id, ErrorId::SOFT_LIMIT_REACHED.0);
    assert_eq!(r.out(queued).error_id, ErrorId::SOFT_LIMIT_REACHED.0);
    assert!(!r.st(1).coupled);
    r.until(10.0, |r| r.out(m).done);
    // A pending coupling ends when another command takes the axis.
    let mut r = rig_at(0.0, 0.0);
    r.cam(T_LINE, &line(true));
    let pending = r.ok(
        1,
        CommandKind::CamIn(CamIn {
            activation_mode: CamActivationMode::AtMasterAxisPos,
            activation_position: 100.0,
            ..cam_in(0, T_LINE)
        }),
    );
    r.ok(1, CommandKind::MoveAbsolute(mv(10.0, 100.0)));
    assert!(r.out(pending).command_aborted);
    assert!(!r.k.cam_in_use(T_LINE));
}

/// Online change (spec §1.10, §2.12–§2.14; §5.1 step 4): new data for a coupled table reaches
/// its slave when the online-change mode says — NEXTCYCLE at the period border with
/// CamDataQueued until then — and only where it does not move the slave; INSTANTANEOUS data
/// that differs where the master is now waits until the master is where old and new agree.
/// The old data is retired once no slave runs it.
#[test]
fn written_data_reaches_a_coupled_slave_by_the_online_change_rules() {
    use std::sync::Arc;
    let table = |middle: f64| {
        let mut t = slower_in_the_middle();
        t.points[2].slave_pos = middle;
        t
    };
    let mut r = rig_at(0.0, 0.0);
    r.cam(T_HALF, &table(180.0));
    r.ok(1, CommandKind::CamIn(cam_in(0, T_HALF)));
    let v = r.ok(0, velocity(200.0, Direction::Positive));
    r.until(2.0, |r| r.out(v).in_velocity);
    // Master in the first cycle's middle: new data (the middle point lower) at the next cycle.
    r.until(2.0, |r| r.st(0).set_position > 100.0);
    let next_cycle = OnlineChange {
        activation_mode: CamActivationMode::NextCycle,
        ..OnlineChange::default()
    };
    let new = Arc::new(Cam::build(&table(150.0)).unwrap());
    assert!(r.k.change_cam(T_HALF, new.clone(), next_cycle).is_ok());
    assert!(r.k.cam_change_pending(T_HALF));
    assert!(r.st(1).cam_data_queued);
    let mut prev = r.st(1).set_position;
    r.until(5.0, |r| {
        let p = r.st(0).set_position;
        let slave = r.st(1).set_position;
        assert!(
            (slave - prev).abs() <= 2.5 * 200.0 * DT + 1e-9,
            "slave jumped {prev} → {slave} at {p}"
        );
        prev = slave;
        assert_eq!(r.st(1).cam_data_queued, p < 360.0, "at {p}");
        p > 500.0
    });
    // In the second cycle the slave runs the new data: 240 stroke, middle point at 150.
    let p = r.st(0).set_position;
    let want = 240.0 + new.eval(p - 360.0).position;
    assert!(
        (r.st(1).set_position - want).abs() < 1e-6,
        "{} ≠ {want}",
        r.st(1).set_position
    );
    r.step();
    assert!(!r.k.cam_change_pending(T_HALF), "the old data retired");
    assert!(r.k.take_retired_cam().is_some());

    // INSTANTANEOUS data that differs where the master is: waits until old and new agree
    // (the last segment, 300..360, is the same in both).
    r.until(5.0, |r| {
        let xl = r.st(1).cam.actual_master_cam_pos;
        (100.0..120.0).contains(&xl)
    });
    let newer = Arc::new(Cam::build(&table(120.0)).unwrap());
    assert!(
        r.k.change_cam(T_HALF, newer, OnlineChange::default())
            .is_ok()
    );
    let mut prev = r.st(1).set_position;
    r.until(5.0, |r| {
        let xl = r.st(1).cam.actual_master_cam_pos;
        let slave = r.st(1).set_position;
        // The steepest segment of these tables has slope 2.5.
        assert!(
            (slave - prev).abs() <= 2.5 * 200.0 * DT + 1e-9,
            "slave jumped {prev} → {slave} at {xl}"
        );
        prev = slave;
        if (120.0..290.0).contains(&xl) {
            assert!(
                r.st(1).cam_data_queued,
                "took effect where it moves the slave ({xl})"
            );
        }
        !r.st(1).cam_data_queued
    });
    let xl = r.st(1).cam.actual_master_cam_pos;
    assert!(!(60.0..300.0).contains(&xl), "took effect at {xl}");
    // A change while the previous one is on its way is refused; DELETEQUEUEDDATA drops it.
    assert!(
        r.k.change_cam(
            T_HALF,
            Arc::new(Cam::build(&table(100.0)).unwrap()),
            next_cycle
        )
        .is_ok()
    );
    assert!(
        r.k.change_cam(
            T_HALF,
            Arc::new(Cam::build(&table(90.0)).unwrap()),
            next_cycle
        )
        .is_err()
    );
    r.k.drop_cam_data(T_HALF);
    assert!(!r.st(1).cam_data_queued);
    // The slave keeps its data by choice: that blocks no further write. The next one, with
    // ASSOONASPOSSIBLE, reaches it in the first cycle where it does not move the slave.
    assert!(!r.k.cam_change_pending(T_HALF));
    let asap = OnlineChange {
        activation_mode: CamActivationMode::AsSoonAsPossible,
        ..OnlineChange::default()
    };
    let again = Arc::new(Cam::build(&table(110.0)).unwrap());
    assert!(r.k.change_cam(T_HALF, again.clone(), asap).is_ok());
    assert!(r.st(1).cam_data_queued);
    assert!(r.k.cam_change_pending(T_HALF), "on its way");
    r.until(5.0, |r| !r.st(1).cam_data_queued);
    r.run(0.01);
    let xl = r.st(1).cam.actual_master_cam_pos;
    let k = ((r.st(0).set_position - xl) / 360.0).round();
    let want = k * 240.0 + again.eval(xl).position;
    assert!(
        (r.st(1).set_position - want).abs() < 1e-6,
        "runs the newest data: {} ≠ {want}",
        r.st(1).set_position
    );
    // OFF: the slave keeps its data, and a later write is taken again.
    let off = OnlineChange {
        activation_mode: CamActivationMode::Off,
        ..OnlineChange::default()
    };
    assert!(
        r.k.change_cam(T_HALF, Arc::new(Cam::build(&table(130.0)).unwrap()), off)
            .is_ok()
    );
    assert!(!r.st(1).cam_data_queued);
    assert!(!r.k.cam_change_pending(T_HALF));
    assert!(
        r.k.change_cam(T_HALF, Arc::new(Cam::build(&table(140.0)).unwrap()), asap)
            .is_ok()
    );
    r.until(5.0, |r| !r.st(1).cam_data_queued);
}

fn v2(master: u16, table: u32, operation: CamOperationMode) -> CamInV2 {
    CamInV2 {
        master,
        cam_table: table,
        activation_mode: CamActivationMode::Instantaneous,
        activation_position: 0.0,
        scaling: CamScalingData::default(),
        operation,
        reference_cam_table: 0,
        interpolation: None,
    }
}

/// Multi-cam (spec §1.9, §2.5–§2.9): MC_CamIn_V2 couples, MC_CamAdd superimposes a second cam
/// (its contribution starting from 0 with a relative slave), queued at a master position with
/// CamTableQueued; MC_CamExchange replaces it without a jump (slave autooffset);
/// MC_CamScaling_V2 scales one cam; MC_CamRemove ends with Done and keeps the position; the
/// V1 and V2 blocks do not mix, and the last cam is removed by MC_CamOut only.
#[test]
fn multi_cam_adds_exchanges_scales_and_removes_superimposed_cams() {
    const T_WAVE: u32 = 3;
    const T_WAVE2: u32 = 4;
    let mut r = rig_at(0.0, 0.0);
    r.cam(T_LINE, &line(true));
    // A small periodic correction: 0 → 5 → 0 over 360 (rest at both ends).
    let wave = |h: f64| {
        let point = |i: u32, x: f64, y: f64| MotionFunctionPoint {
            point_index: i,
            function_type: MotionFunctionType::Polynom5,
            point_type: MotionPointType::Rest,
            rel_index_next_point: 1,
            master_pos: x,
            slave_pos: y,
            slave_velo: 0.0,
            slave_acc: 0.0,
            slave_jerk: 0.0,
        };
        let mut t = CamTableData::motion_function(vec![
            point(1, 0.0, 0.0),
            point(2, 180.0, h),
            point(3, 360.0, 0.0),
        ]);
        t.periodic = true;
        t
    };
    r.cam(T_WAVE, &wave(5.0));
    r.cam(T_WAVE2, &wave(8.0));
    let c = r.ok(
        1,
        CommandKind::CamInV2(v2(0, T_LINE, CamOperationMode::Default)),
    );
    assert!(r.out(c).in_sync);
    assert!(r.st(1).cam.multi_cam);
    assert_eq!(
        r.rejected(1, CommandKind::CamIn(cam_in(0, T_LINE))),
        ErrorId::CAM_FAMILY_MIXED
    );
    assert_eq!(
        r.rejected(
            1,
            CommandKind::CamInV2(v2(0, T_LINE, CamOperationMode::Remove))
        ),
        ErrorId::CAM_MODE_INVALID
    );
    // Add the wave when the master passes 360 (a cycle border: the wave is at rest there).
    let add = CamInV2 {
        activation_mode: CamActivationMode::AtMasterAxisPos,
        activation_position: 360.0,
        scaling: CamScalingData {
            slave_relative: true,
            ..CamScalingData::default()
        },
        ..v2(0, T_WAVE, CamOperationMode::Additive)
    };
    let a = r.ok(1, CommandKind::CamInV2(add));
    assert!(r.out(a).active && r.st(1).cam_table_queued);
    let mut prev = r.st(1).set_position;
    move_master(&mut r, 540.0, 200.0, |r| {
        let p = r.st(0).set_position;
        let s = r.st(1).set_position;
        assert!(
            (s - prev).abs() <= 1.2 * 200.0 * DT + 1e-9,
            "jump {prev} → {s} at {p}"
        );
        prev = s;
        assert_eq!(r.st(1).cam_table_queued, p < 360.0, "at {p}");
    });
    assert!(r.out(a).in_sync && !r.out(a).busy);
    assert_eq!(r.st(1).cam.cams[1].cam_table_id, T_WAVE);
    // Base 540 (base cycle 0: strokes count), wave at its peak 5.
    assert!(
        (r.st(1).set_position - 545.0).abs() < 1e-6,
        "{}",
        r.st(1).set_position
    );
    // Exchange the wave for the bigger one at rest at the next border, slave autooffset.
    let ex = CamInV2 {
        activation_mode: CamActivationMode::AtMasterAxisPos,
        activation_position: 720.0,
        scaling: CamScalingData {
            slave_scaling_mode: CamScalingMode::AutoOffset,
            ..CamScalingData::default()
        },
        reference_cam_table: T_WAVE,
        ..v2(0, T_WAVE2, CamOperationMode::Exchange)
    };
    let e = r.ok(1, CommandKind::CamInV2(ex));
    move_master(&mut r, 900.0, 200.0, |_| {});
    assert!(r.out(e).in_sync, "{:?}", r.out(e));
    assert_eq!(r.st(1).cam.cams[1].cam_table_id, T_WAVE2);
    assert!(
        (r.st(1).set_position - 908.0).abs() < 1e-6,
        "{}",
        r.st(1).set_position
    );
    // Scale the wave ×0.5 (slave scaling of that cam only, at rest at the border).
    let sc = CamScalingV2 {
        cam_table: T_WAVE2,
        activation_mode: CamActivationMode::AtMasterAxisPos,
        activation_position: 1080.0,
        scaling: CamScalingData {
            slave_scaling: 0.5,
            master_scaling_mode: CamScalingMode::Off,
            ..CamScalingData::default()
        },
    };
    let s = r.ok(1, CommandKind::CamScalingV2(sc));
    assert!(r.st(1).cam_scaling_pending);
    move_master(&mut r, 1260.0, 200.0, |_| {});
    assert!(r.out(s).done, "{:?}", r.out(s));
    assert!(
        (r.st(1).set_position - 1264.0).abs() < 1e-6,
        "{}",
        r.st(1).set_position
    );
    // Remove the wave at a border (at rest, contribution 0): Done, nothing moves.
    move_master(&mut r, 1440.0, 200.0, |_| {});
    let before = r.st(1).set_position;
    let rm = r.ok(
        1,
        CommandKind::CamInV2(v2(0, T_WAVE2, CamOperationMode::Remove)),
    );
    assert!(r.out(rm).done && !r.out(rm).in_sync);
    assert_eq!(r.st(1).set_position, before);
    assert_eq!(r.st(1).cam.cams[1].cam_table_id, 0);
    move_master(&mut r, 1500.0, 200.0, |_| {});
    assert!((r.st(1).set_position - 1500.0).abs() < 1e-6);
    // Adding a cam whose contribution is not 0 here, absolutely: a jump, refused.
    let mut r2 = rig_at(90.0, 90.0);
    r2.cam(T_LINE, &line(true));
    r2.cam(T_WAVE, &wave(5.0));
    r2.ok(
        1,
        CommandKind::CamInV2(v2(0, T_LINE, CamOperationMode::Default)),
    );
    assert_eq!(
        r2.rejected(
            1,
            CommandKind::CamInV2(v2(0, T_WAVE, CamOperationMode::Additive))
        ),
        ErrorId::CAM_SLAVE_WOULD_JUMP
    );
}

/// Spec §2.18 / §5.3 "emergency-stop recovery": MC_CamInfo keeps the last valid coupling
/// state after an error ended it; re-coupling with its total offsets and stroke sum puts the
/// slave back on the cam without a jump. MC_CamOut clears it.
#[test]
fn cam_info_survives_an_error_and_restores_the_coupling() {
    let mut r = rig_at(0.0, 0.0);
    r.cam(T_LINE, &line(true));
    r.ok(
        1,
        CommandKind::CamIn(CamIn {
            slave_offset: 0.0,
            ..cam_in(0, T_LINE)
        }),
    );
    move_master(&mut r, 800.0, 400.0, |_| {});
    let info = r.st(1).cam;
    assert!(
        info.active && (info.sum_of_slave_strokes - 720.0).abs() < 1e-9,
        "{info:?}"
    );
    // A drive fault on the slave: ErrorStop, decoupled; the last state stays readable.
    r.plants[1].fault = true;
    r.until(1.0, |r| r.st(1).state == AxisState::ErrorStop);
    assert!(!r.st(1).coupled);
    let kept = r.st(1).cam;
    assert!(!kept.active && kept.cam_table_id == T_LINE, "{kept:?}");
    assert!((kept.sum_of_slave_strokes - 720.0).abs() < 1e-9);
    r.plants[1].fault = false;
    r.ok(1, CommandKind::Reset);
    r.until(1.0, |r| r.st(1).state == AxisState::Standstill);
    assert_eq!(r.st(1).cam.cam_table_id, T_LINE, "kept through the reset");
    // Re-couple from the kept data: the strokes go into the offset (the base cycle is now).
    let again = CamIn {
        master_offset: kept.master_offset,
        slave_offset: kept.slave_offset + kept.sum_of_slave_strokes,
        master_scaling: kept.master_scaling,
        slave_scaling: kept.slave_scaling,
        ..cam_in(0, T_LINE)
    };
    let c = r.ok(1, CommandKind::CamIn(again));
    assert!(r.out(c).in_sync && r.st(1).cam.active);
    assert!((r.st(1).set_position - 800.0).abs() < 1e-9);
    move_master(&mut r, 900.0, 400.0, |_| {});
    assert!((r.st(1).set_position - 900.0).abs() < 1e-9);
    r.ok(1, CommandKind::CamOut);
    assert_eq!(r.st(1).cam.cam_table_id, 0, "MC_CamOut clears it");
}

/// Spec §5.1, the "Elektronische Kurvenscheiben" sample as a scenario: two motion functions
/// and a position table; couple, run the master; switch at the next cycle, write one point
/// with the online-change mode NEXTCYCLE, switch at a master axis position with slave
/// autooffset, scale the slave ×2 with autooffset at a rest — flags, InSync and position
/// continuity checked in every cycle.
#[test]
fn the_electronic_cams_sample_runs_without_a_jump() {
    use std::sync::Arc;
    const A: u32 = 11;
    const B: u32 = 12;
    const C: u32 = 13;
    let point = |i: u32, law, x: f64, y: f64| MotionFunctionPoint {
        point_index: i,
        function_type: law,
        point_type: MotionPointType::Rest,
        rel_index_next_point: 1,
        master_pos: x,
        slave_pos: y,
        slave_velo: 0.0,
        slave_acc: 0.0,
        slave_jerk: 0.0,
    };
    use MotionFunctionType::*;
    let mut a = CamTableData::motion_function(vec![
        point(1, Polynom5, 0.0, 0.0),
        point(2, Polynom5, 180.0, 100.0),
        point(3, Polynom5, 360.0, 0.0),
    ]);
    a.periodic = true;
    let b_table = |level: f64| {
        let mut b = CamTableData::motion_function(vec![
            point(1, ModSinuslinie, 0.0, 0.0),
            point(2, Polynom1, 120.0, level),
            point(3, ModSinuslinie, 240.0, level),
            point(4, Polynom1, 360.0, 0.0),
        ]);
        b.periodic = true;
        b
    };
    let rows: Vec<[f64; 2]> = (0..=36)
        .map(|i| {
            let x = i as f64 * 10.0;
            [x, 20.0 * (1.0 - (x.to_radians()).cos())]
        })
        .collect();
    let mut c = CamTableData::positions(rows, true);
    c.periodic = true;
    c.interpolation = InterpolationType::Spline;
    let mut r = rig_at(0.0, 0.0);
    r.cam(A, &a);
    r.cam(B, &b_table(60.0));
    r.cam(C, &c);
    let coupled = r.ok(1, CommandKind::CamIn(cam_in(0, A)));
    assert!(r.out(coupled).in_sync);
    let v = r.ok(0, velocity(100.0, Direction::Positive));
    r.until(1.0, |r| r.out(v).in_velocity);
    let mut prev = r.st(1).set_position;
    let mut check = |r: &Rig| {
        let s = r.st(1).set_position;
        assert!(
            (s - prev).abs() < 0.15,
            "slave jumped {prev} → {s} at master {}",
            r.st(0).set_position
        );
        prev = s;
    };
    // 1. Switch to B at the next cycle.
    let to_b = r.ok(
        1,
        CommandKind::CamIn(CamIn {
            activation_mode: CamActivationMode::NextCycle,
            ..cam_in(0, B)
        }),
    );
    r.until(10.0, |r| {
        check(r);
        let m = r.st(0).set_position;
        assert_eq!(r.st(1).cam_table_queued, m < 360.0, "at {m}");
        m > 400.0
    });
    assert!(r.out(to_b).in_sync);
    assert_eq!(r.st(1).cam.cam_table_id, B);
    // 2. One point of B written (the rest level 60 → 50), online change at the next cycle.
    r.k.change_cam(
        B,
        Arc::new(Cam::build(&b_table(50.0)).unwrap()),
        OnlineChange {
            activation_mode: CamActivationMode::NextCycle,
            ..OnlineChange::default()
        },
    )
    .unwrap();
    r.until(10.0, |r| {
        check(r);
        let m = r.st(0).set_position;
        assert_eq!(r.st(1).cam_data_queued, m < 720.0, "at {m}");
        m > 900.0 - 100.0 * DT * 50.0
    });
    // In the third cycle's rest: the new level.
    r.until(1.0, |r| r.st(0).set_position > 860.0);
    assert!(
        (r.st(1).set_position - 50.0).abs() < 1e-9,
        "{}",
        r.st(1).set_position
    );
    // 3. Switch to the position table at master 900 (B at rest there), slave autooffset.
    let to_c = r.ok(
        1,
        CommandKind::CamIn(CamIn {
            activation_mode: CamActivationMode::AtMasterAxisPos,
            activation_position: 900.0,
            slave_scaling_mode: CamScalingMode::AutoOffset,
            ..cam_in(0, C)
        }),
    );
    r.until(10.0, |r| {
        check(r);
        let m = r.st(0).set_position;
        assert_eq!(r.out(to_c).active, m < 900.0, "at {m}");
        m > 1000.0
    });
    assert!(r.out(to_c).in_sync && r.st(1).cam.cam_table_id == C);
    // 4. Scale the slave ×2 at master 1260 (x = 180 in C: at rest), autooffset.
    let scale = r.ok(
        1,
        CommandKind::CamScaling(CamScaling {
            activation_mode: CamActivationMode::AtMasterAxisPos,
            activation_position: 1260.0,
            master_scaling_mode: CamScalingMode::Off,
            slave_scaling_mode: CamScalingMode::AutoOffset,
            master_offset: 0.0,
            slave_offset: 0.0,
            master_scaling: 1.0,
            slave_scaling: 2.0,
        }),
    );
    r.until(10.0, |r| {
        check(r);
        let m = r.st(0).set_position;
        assert_eq!(r.st(1).cam_scaling_pending, m < 1260.0, "at {m}");
        m > 1300.0
    });
    assert!(
        r.out(scale).done && r.st(1).cam.slave_scaling == 2.0,
        "{:?}",
        r.out(scale)
    );
}

/// A coupled slave waits for an activation only on the master it follows: a CamIn to another
/// master that would couple later (at that master's position) is refused with 0x7040 and
/// changes nothing, whether the slave follows its master through a cam or a gear; the same
/// CamIn at once recouples without a jump (decision 174). Before, the activation was watched
/// on the old master and the cam built from the old master's position ran on the new one.
#[test]
fn a_coupled_slave_waits_for_no_other_master() {
    let mut r = rig3();
    let m = r.ok(2, CommandKind::MoveAbsolute(mv(400.0, 1000.0)));
    r.until(10.0, |r| r.out(m).done);
    r.cam(T_LINE, &line(false));
    // A cam at rest up to 550 on master 2.
    let t = CamTableData::positions(vec![[0.0, 0.0], [550.0, 0.0], [600.0, 50.0]], false);
    r.cam(T_HALF, &t);
    let later = CamIn {
        activation_mode: CamActivationMode::AtMasterAxisPos,
        activation_position: 500.0,
        ..cam_in(2, T_HALF)
    };
    let followed: [(&str, CommandKind, CommandKind); 2] = [
        (
            "cam",
            CommandKind::CamIn(cam_in(0, T_LINE)),
            CommandKind::CamOut,
        ),
        ("gear", gear_in(0, 1.0, 1), CommandKind::GearOut),
    ];
    for (how, couple, decouple) in followed {
        let c = r.ok(1, couple);
        assert!(r.out(c).in_sync || r.out(c).in_gear, "{how}: not coupled");
        assert_eq!(r.st(1).state, AxisState::SynchronizedMotion, "{how}");
        assert_eq!(
            r.rejected(1, CommandKind::CamIn(later)),
            ErrorId::MASTER_INVALID,
            "{how}: a CamIn waiting on master 2"
        );
        // Nothing changed: the slave still follows master 0, nothing waits.
        assert!(!r.out(c).error && !r.out(c).command_aborted, "{how}");
        assert_eq!(r.k.axis(1).expect("slave").master_slot(), Some(0), "{how}");
        let (m0, s0) = (r.st(0).set_position, r.st(1).set_position);
        move_master(&mut r, m0 + 300.0, 500.0, |r| {
            let (dm, ds) = (r.st(0).set_position - m0, r.st(1).set_position - s0);
            assert!(
                (ds - dm).abs() < 1e-9,
                "{how}: slave moved {ds}, master 0 {dm}"
            );
        });
        // Master 2 across 500 (the refused activation) moves nothing.
        let before = r.st(1).set_position;
        move_master_axis(&mut r, 2, 560.0);
        assert_eq!(r.st(1).set_position, before, "{how}");
        move_master_axis(&mut r, 2, 400.0);
        // Decoupled and back to where master 0 is, for the next round.
        r.ok(1, decouple);
        let out = r.ok(1, CommandKind::MoveAbsolute(mv(0.0, 1000.0)));
        r.until(10.0, |r| r.out(out).done);
        let back = r.ok(0, CommandKind::MoveAbsolute(mv(0.0, 1000.0)));
        r.until(10.0, |r| r.out(back).done);
    }
    // At once, to master 2 at 400 where the cam puts the slave at 0: recoupled there.
    let c = r.ok(1, CommandKind::CamIn(cam_in(0, T_LINE)));
    assert!(r.out(c).in_sync);
    let now = r.ok(1, CommandKind::CamIn(cam_in(2, T_HALF)));
    assert!(r.out(now).in_sync && !r.out(now).error);
    assert_eq!(r.k.axis(1).expect("slave").master_slot(), Some(2));
    move_master_axis(&mut r, 2, 600.0);
    assert!((r.st(1).set_position - 50.0).abs() < 1e-9);
}

/// Decision 174, the other side: a deferred CamIn to the master the slave follows still waits
/// — from a gear to a cam at a master position, without a jump — and on a multi-master slave
/// it may wait on Master1 (whose sample the slave is given), not on a further master. The
/// gear to cam change on a moving master was refused with 0x7084 at the activation before
/// decision 175 (the slave's last setpoint was compared with this cycle's cam).
#[test]
fn a_coupled_slave_waits_for_a_cam_on_the_master_it_follows() {
    let mut r = rig3();
    r.cam(T_LINE, &line(false));
    let g = r.ok(1, gear_in(0, 1.0, 1));
    assert!(r.out(g).in_gear);
    let later = |master| CamIn {
        activation_mode: CamActivationMode::AtMasterAxisPos,
        activation_position: 300.0,
        ..cam_in(master, T_LINE)
    };
    let c = r.ok(1, CommandKind::CamIn(later(0)));
    assert!(r.out(c).busy && r.out(c).active && !r.out(c).in_sync);
    move_master(&mut r, 350.0, 200.0, |r| {
        let (m, s) = (r.st(0).set_position, r.st(1).set_position);
        assert!((s - m).abs() < 1e-9, "slave {s} left master {m}");
        assert_eq!(r.out(c).in_sync, m >= 300.0, "at {m}: {:?}", r.out(c));
        assert!(!r.out(c).error, "at {m}: {:?}", r.out(c));
    });
    assert_eq!(r.st(1).cam.cam_table_id, T_LINE);
    // The same relative (the cam's origin is where master and slave are in the cycle of the
    // activation): geared down to 100, then the cam from 200 upwards.
    r.ok(1, CommandKind::CamOut);
    let g = r.ok(1, gear_in(0, 1.0, 1));
    assert!(r.out(g).in_gear);
    move_master(&mut r, 100.0, 200.0, |_| {});
    let c = r.ok(
        1,
        CommandKind::CamIn(CamIn {
            start_mode: StartMode::Relative,
            activation_position: 200.0,
            ..later(0)
        }),
    );
    move_master(&mut r, 300.0, 200.0, |r| {
        let (m, s) = (r.st(0).set_position, r.st(1).set_position);
        assert!((s - m).abs() < 1e-9, "slave {s} left master {m}");
        assert_eq!(r.out(c).in_sync, m >= 200.0, "at {m}: {:?}", r.out(c));
        assert!(!r.out(c).error, "at {m}: {:?}", r.out(c));
    });
    // A multi-master slave: Master1 is 0, a further master 2.
    r.ok(1, CommandKind::CamOut);
    let mm = r.ok(
        1,
        CommandKind::GearInMultiMaster(GearInMultiMaster {
            masters: [Some(0), Some(2), None, None],
            ratios: [1.0, 1.0, 0.0, 0.0],
            acceleration: 0.0,
            deceleration: 0.0,
            jerk: 0.0,
            advanced_slave_dynamics: false,
            sync_mode: MultiMasterSyncMode::Velosync,
        }),
    );
    assert!(r.out(mm).in_gear);
    assert_eq!(
        r.rejected(1, CommandKind::CamIn(later(2))),
        ErrorId::MASTER_INVALID
    );
    // (The master stands at 300 now: an activation further on.)
    let c = r.ok(
        1,
        CommandKind::CamIn(CamIn {
            activation_position: 500.0,
            ..later(0)
        }),
    );
    assert!(r.out(c).busy && r.out(c).active && !r.out(mm).command_aborted);
}

/// Three axes powered: masters 0 and 2, the slave 1 with its dynamics bounds opened.
fn rig3() -> Rig {
    let mut p = params();
    p.axis_velo_max = 2000.0;
    let mut r = Rig::with(vec![(false, p.clone()), (false, p.clone()), (false, p)]);
    r.bounds[1].velocity = 1e9;
    r.bounds[1].acceleration = 1e9;
    r.bounds[1].jerk = 1e12;
    for a in 0..3 {
        r.power_on(a);
    }
    r
}

fn move_master_axis(r: &mut Rig, axis: u16, to: f64) {
    let m = r.ok(axis, CommandKind::MoveAbsolute(mv(to, 500.0)));
    r.until(30.0, |r| r.out(m).done);
}

/// An axis error ends a coupling that waits for its activation (with the error), also in the
/// cycle its master reaches the position: it never takes the stopping axis over (the
/// activation was looked at after the error in the same step, and a coupled cam survived the
/// ErrorStop's clean-up).
#[test]
fn a_waiting_coupling_ends_with_an_axis_error() {
    let mut r = rig_at(400.0, 0.0);
    let t = CamTableData::positions(vec![[0.0, 0.0], [550.0, 0.0], [600.0, 50.0]], false);
    r.cam(T_HALF, &t);
    let c = r.ok(
        1,
        CommandKind::CamIn(CamIn {
            activation_mode: CamActivationMode::AtMasterAxisPos,
            activation_position: 500.0,
            ..cam_in(0, T_HALF)
        }),
    );
    assert!(r.out(c).busy && r.out(c).active);
    let m = r.ok(0, CommandKind::MoveAbsolute(mv(560.0, 200.0)));
    // The slave's drive faults in the cycle the master passes 500 (its feedback is read in
    // the next step: the fault is set one cycle before).
    r.until(5.0, |r| r.st(0).set_position >= 499.7);
    r.plants[1].fault = true;
    r.until(5.0, |r| {
        let st = r.st(1);
        assert!(
            !st.coupled && st.state != AxisState::SynchronizedMotion && !st.cam.active,
            "coupled in error at master {}",
            r.st(0).set_position
        );
        r.out(m).done
    });
    assert_eq!(r.st(1).state, AxisState::ErrorStop);
    assert!(
        r.out(c).error && !r.out(c).busy && r.out(c).error_id == ErrorId::DRIVE_FAULT.0,
        "{:?}",
        r.out(c)
    );
}
