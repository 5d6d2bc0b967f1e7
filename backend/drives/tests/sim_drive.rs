//! Behaviour of the simulated servo drive, cycle by cycle in virtual time.

use drives::sim::{
    GENERIC_FAULT_CODE, IndexPulse, LIMIT_SWITCH_FAULT_CODE, LimitSwitches, PlantModel,
    ReferenceCam, SimDrive, SimDriveConfig, SimFault,
};
use motion::{DriveFeedback, DriveSetpoint, LatchSource};
use serde_json::json;

const DT: f64 = 0.001;

fn config(plant: PlantModel, dead_time: f64) -> SimDriveConfig {
    SimDriveConfig {
        plant,
        dead_time,
        enable_delay: 0.0,
        ..SimDriveConfig::default()
    }
}

fn ideal(dead_time: f64) -> SimDriveConfig {
    config(PlantModel::Ideal, dead_time)
}

fn hold(position: f64) -> DriveSetpoint {
    DriveSetpoint {
        enable: true,
        position,
        ..Default::default()
    }
}

/// Enables the drive holding its actual position; returns the number of cycles it took.
fn enable(drive: &mut SimDrive) -> usize {
    for n in 1..=100_000 {
        let p = drive.feedback().actual_position;
        drive.apply(&hold(p));
        if drive.feedback().enabled {
            return n;
        }
    }
    panic!("drive never enabled");
}

/// Runs `cycles` cycles of one setpoint; returns the last feedback.
fn run(drive: &mut SimDrive, sp: &DriveSetpoint, cycles: usize) -> DriveFeedback {
    for _ in 0..cycles {
        drive.apply(sp);
    }
    drive.feedback()
}

/// Positions after each of `cycles` applies of a position step to `target` (enabled first).
fn step_response(cfg: SimDriveConfig, target: f64, cycles: usize) -> Vec<f64> {
    let mut drive = SimDrive::new(cfg, DT);
    enable(&mut drive);
    (0..cycles)
        .map(|_| {
            drive.apply(&hold(target));
            drive.feedback().actual_position
        })
        .collect()
}

/// A trapezoidal move from 0 to `distance` with consistent position, velocity and
/// acceleration setpoints, then `tail` cycles at rest. Yields (setpoint, feedback after it).
fn trapezoid(
    drive: &mut SimDrive,
    distance: f64,
    v_max: f64,
    acc: f64,
    tail: usize,
) -> Vec<(DriveSetpoint, DriveFeedback)> {
    let t_acc = v_max / acc;
    let d_acc = 0.5 * acc * t_acc * t_acc;
    let t_const = (distance - 2.0 * d_acc) / v_max;
    assert!(t_const > 0.0);
    let t_total = 2.0 * t_acc + t_const;
    let cycles = (t_total / DT).ceil() as usize + tail;
    let mut out = Vec::with_capacity(cycles);
    for k in 1..=cycles {
        let t = (k as f64 * DT).min(t_total);
        let (p, v, a) = if t < t_acc {
            (0.5 * acc * t * t, acc * t, acc)
        } else if t < t_acc + t_const {
            (d_acc + v_max * (t - t_acc), v_max, 0.0)
        } else if t < t_total {
            let r = t_total - t;
            (distance - 0.5 * acc * r * r, acc * r, -acc)
        } else {
            (distance, 0.0, 0.0)
        };
        let sp = DriveSetpoint {
            enable: true,
            position: p,
            velocity: v,
            acceleration: a,
            ..Default::default()
        };
        drive.apply(&sp);
        out.push((sp, drive.feedback()));
    }
    out
}

/// Moves at constant `velocity` from the actual position; returns the feedback after each cycle.
fn constant_velocity(
    drive: &mut SimDrive,
    velocity: f64,
    cycles: usize,
    latch: Option<LatchSource>,
) -> Vec<DriveFeedback> {
    let p0 = drive.feedback().actual_position;
    (1..=cycles)
        .map(|k| {
            let sp = DriveSetpoint {
                enable: true,
                position: p0 + velocity * k as f64 * DT,
                velocity,
                latch_enable: latch.is_some(),
                latch_source: latch.unwrap_or_default(),
                ..Default::default()
            };
            drive.apply(&sp);
            drive.feedback()
        })
        .collect()
}

// ---------------------------------------------------------------- defaults, models, timing

#[test]
fn default_is_valid_pt2_with_one_cycle_of_dead_time() {
    let cfg = SimDriveConfig::default();
    assert_eq!(cfg.validate(), Ok(()));
    assert!(matches!(cfg.plant, PlantModel::Pt2 { .. }));
    assert_eq!(cfg.dead_time, 0.001);
    let fb = SimDrive::new(cfg, DT).feedback();
    assert!(fb.ready && !fb.enabled && !fb.fault);
    assert_eq!(fb.actual_position, 0.0);
}

#[test]
fn ideal_follows_the_setpoint_exactly_one_cycle_later() {
    let mut drive = SimDrive::new(ideal(0.0), DT);
    enable(&mut drive);
    let mut last = 0.0;
    for k in 1..=50 {
        let p = 0.37 * (k * k) as f64;
        drive.apply(&hold(p));
        let fb = drive.feedback();
        assert_eq!(fb.actual_position, p);
        assert!((fb.actual_velocity - (p - last) / DT).abs() < 1e-9);
        last = p;
    }
}

#[test]
fn dead_time_shifts_the_response_by_exact_cycles() {
    for plant in [
        PlantModel::Ideal,
        PlantModel::Pt1 {
            time_constant: 0.004,
        },
        PlantModel::default(),
    ] {
        let undelayed = step_response(config(plant, 0.0), 1.0, 100);
        let delayed = step_response(config(plant, 0.003), 1.0, 100);
        assert_eq!(
            &delayed[..3],
            &[0.0; 3],
            "{plant:?}: the load holds during the dead time"
        );
        assert_eq!(
            &delayed[3..],
            &undelayed[..97],
            "{plant:?}: same response, three cycles later"
        );
    }
}

#[test]
fn dead_time_shifts_with_other_cycle_times() {
    let dt = 0.00025;
    let mut drive = SimDrive::new(ideal(0.001), dt);
    enable(&mut drive);
    let positions: Vec<f64> = (1..=20)
        .map(|k| {
            drive.apply(&hold(k as f64));
            drive.feedback().actual_position
        })
        .collect();
    let expected: Vec<f64> = (1..=20)
        .map(|k| if k <= 4 { 0.0 } else { (k - 4) as f64 })
        .collect();
    assert_eq!(positions, expected);
}

#[test]
fn fractional_dead_time_interpolates_between_cycles() {
    let mut cfg = ideal(0.0015);
    cfg.dead_time_compensation = false;
    let mut drive = SimDrive::new(cfg, DT);
    enable(&mut drive);
    let positions: Vec<f64> = (1..=6)
        .map(|k| {
            drive.apply(&hold(10.0 * k as f64));
            drive.feedback().actual_position
        })
        .collect();
    // Ramp of 10 per cycle, 1.5 cycles late; the first cycle and a half still holds 0.
    assert_eq!(positions, vec![0.0, 5.0, 15.0, 25.0, 35.0, 45.0]);
}

#[test]
fn pt1_step_matches_the_analytic_response() {
    let t = 0.01;
    let response = step_response(config(PlantModel::Pt1 { time_constant: t }, 0.0), 1.0, 100);
    // The fine interpolator ramps the reference over the first cycle, then holds it.
    for (k, q) in response.iter().enumerate() {
        let time = (k + 1) as f64 * DT;
        let exact = 1.0 - (t / DT) * ((DT / t).exp() - 1.0) * (-time / t).exp();
        // RK4 in sub-steps of T/20.
        assert!((q - exact).abs() < 1e-7, "cycle {k}: {q} vs {exact}");
    }
    assert!((response[99] - 1.0).abs() < 1e-4);
}

#[test]
fn pt2_step_overshoots_as_its_damping_says_and_settles() {
    let response = step_response(
        SimDriveConfig {
            enable_delay: 0.0,
            ..SimDriveConfig::default()
        },
        1.0,
        500,
    );
    let peak = response.iter().cloned().fold(f64::MIN, f64::max);
    // ζ = 0.8: exp(−πζ/√(1−ζ²)) = 1.5 % for an ideal step; the one-cycle ramp softens it.
    assert!(peak > 1.01 && peak < 1.016, "peak {peak}");
    let last_outside = response
        .iter()
        .rposition(|q| (q - 1.0).abs() > 0.02)
        .unwrap();
    let settle = (last_outside + 1) as f64 * DT;
    assert!(
        settle > 0.005 && settle < 0.04,
        "settled into 2 % after {settle} s"
    );
    assert!((response[499] - 1.0).abs() < 1e-9);

    let critically_damped = step_response(
        config(
            PlantModel::Pt2 {
                natural_frequency_hz: 20.0,
                damping: 1.0,
            },
            0.0,
        ),
        1.0,
        1000,
    );
    assert!(
        critically_damped.windows(2).all(|w| w[1] >= w[0]),
        "no overshoot at ζ = 1"
    );
    assert!(*critically_damped.last().unwrap() <= 1.0 + 1e-12);
}

#[test]
fn default_drive_tracks_a_fast_move_closely_and_settles_in_the_target_window() {
    let mut drive = SimDrive::new(SimDriveConfig::default(), DT);
    enable(&mut drive);
    let trace = trapezoid(&mut drive, 200.0, 500.0, 2500.0, 200);
    let lag = |(sp, fb): &(DriveSetpoint, DriveFeedback)| sp.position - fb.actual_position;
    let max_lag = trace.iter().map(|x| lag(x).abs()).fold(0.0, f64::max);
    // a/ω² = 2500 / (2π·50)² = 25 µm while accelerating, plus the transient of the jump in a.
    assert!(max_lag < 0.05, "max lag {max_lag}");
    assert!(max_lag > 0.01, "the lag is real: {max_lag}");
    let cruising: Vec<f64> = trace
        .iter()
        .filter(|(sp, _)| sp.velocity == 500.0)
        .skip(50)
        .map(|x| lag(x).abs())
        .collect();
    assert!(cruising.len() > 100);
    assert!(
        cruising.iter().all(|l| *l < 0.005),
        "lag at 500 units/s: {:?}",
        cruising.iter().cloned().fold(0.0, f64::max)
    );
    let velocity_error = trace
        .iter()
        .filter(|(sp, _)| sp.velocity == 500.0)
        .skip(50)
        .map(|(_, fb)| (fb.actual_velocity - 500.0).abs())
        .fold(0.0, f64::max);
    assert!(velocity_error < 0.1, "velocity error {velocity_error}");

    let end = trace
        .iter()
        .position(|(sp, _)| sp.position == 200.0 && sp.velocity == 0.0)
        .unwrap();
    let last_outside = trace.iter().rposition(|x| lag(x).abs() > 0.02).unwrap_or(0);
    let settle = last_outside.saturating_sub(end) as f64 * DT;
    assert!(
        settle < 0.03,
        "in the 20 µm window {settle} s after the setpoint stopped"
    );
    assert!(lag(trace.last().unwrap()).abs() < 1e-6);
}

#[test]
fn feed_forward_weights_set_the_velocity_lag() {
    let v = 100.0;
    let zeta = 0.7;
    let f = 25.0;
    let omega = 2.0 * std::f64::consts::PI * f;
    let cases = [
        (
            PlantModel::Pt2 {
                natural_frequency_hz: f,
                damping: zeta,
            },
            0.0,
            2.0 * zeta * v / omega,
        ),
        (
            PlantModel::Pt2 {
                natural_frequency_hz: f,
                damping: zeta,
            },
            1.0,
            0.0,
        ),
        (
            PlantModel::Pt1 {
                time_constant: 0.02,
            },
            0.0,
            v * 0.02,
        ),
        (
            PlantModel::Pt1 {
                time_constant: 0.02,
            },
            0.5,
            0.5 * v * 0.02,
        ),
        (
            PlantModel::Pt1 {
                time_constant: 0.02,
            },
            1.0,
            0.0,
        ),
    ];
    for (plant, kv, expected) in cases {
        let mut cfg = config(plant, 0.0);
        cfg.velocity_feed_forward = kv;
        let mut drive = SimDrive::new(cfg, DT);
        enable(&mut drive);
        let trace = constant_velocity(&mut drive, v, 1000, None);
        let lag = v * 1000.0 * DT - trace.last().unwrap().actual_position;
        assert!(
            (lag - expected).abs() < 1e-6,
            "{plant:?} kv {kv}: lag {lag}, expected {expected}"
        );
    }
}

#[test]
fn acceleration_feed_forward_removes_the_acceleration_lag() {
    let mut lags = Vec::new();
    for ka in [0.0, 1.0] {
        let cfg = SimDriveConfig {
            acceleration_feed_forward: ka,
            ..SimDriveConfig::default()
        };
        let mut drive = SimDrive::new(cfg, DT);
        enable(&mut drive);
        let trace = trapezoid(&mut drive, 200.0, 500.0, 2500.0, 0);
        // Mid-acceleration (0.1 s in): a/ω² without, ~0 with.
        let (sp, fb) = trace[100];
        lags.push(sp.position - fb.actual_position);
    }
    let omega = 2.0 * std::f64::consts::PI * 50.0;
    // Up to a·dt²/8 = 0.3 µm from the linear fine interpolation between cycles.
    assert!(
        (lags[0] - 2500.0 / (omega * omega)).abs() < 3e-4,
        "{lags:?}"
    );
    assert!(lags[1].abs() < 3e-4, "{lags:?}");
}

#[test]
fn uncompensated_dead_time_lags_by_velocity_times_dead_time() {
    for (compensation, expected) in [(false, 0.5), (true, 0.0)] {
        let cfg = SimDriveConfig {
            dead_time_compensation: compensation,
            ..SimDriveConfig::default()
        };
        let mut drive = SimDrive::new(cfg, DT);
        enable(&mut drive);
        let trace = constant_velocity(&mut drive, 500.0, 500, None);
        let lag = 500.0 * 500.0 * DT - trace.last().unwrap().actual_position;
        assert!(
            (lag - expected).abs() < 1e-6,
            "compensation {compensation}: lag {lag}"
        );
    }
}

#[test]
fn drives_are_deterministic() {
    let run_once = || {
        let mut drive = SimDrive::new(SimDriveConfig::default(), DT);
        enable(&mut drive);
        drive.inject(SimFault::Load { force: 12.5 });
        let mut out = trapezoid(&mut drive, 50.0, 100.0, 1000.0, 50);
        drive.set_actual_position(3.0);
        out.extend(trapezoid(&mut drive, 40.0, 80.0, 800.0, 10));
        out.into_iter().map(|(_, fb)| fb).collect::<Vec<_>>()
    };
    let a = run_once();
    let b = run_once();
    assert!(
        a.iter()
            .zip(&b)
            .all(|(x, y)| x.actual_position.to_bits() == y.actual_position.to_bits())
    );
    assert_eq!(a, b);
}

#[test]
fn non_finite_setpoints_are_ignored() {
    let mut drive = SimDrive::new(SimDriveConfig::default(), DT);
    enable(&mut drive);
    run(&mut drive, &hold(2.0), 300);
    let sp = DriveSetpoint {
        enable: true,
        position: f64::NAN,
        velocity: f64::INFINITY,
        ..Default::default()
    };
    let fb = run(&mut drive, &sp, 100);
    assert!((fb.actual_position - 2.0).abs() < 1e-9);
    assert!(fb.actual_velocity.is_finite());
}

// ---------------------------------------------------------------- enable sequencing, faults

#[test]
fn enabled_follows_the_enable_request_after_the_enable_delay() {
    let mut drive = SimDrive::new(SimDriveConfig::default(), DT);
    // 5 ms at 1 ms: the fifth apply with `enable` switches operation on.
    let target = DriveSetpoint {
        enable: true,
        position: 1.0,
        ..Default::default()
    };
    for k in 1..=5 {
        drive.apply(&target);
        let fb = drive.feedback();
        assert_eq!(fb.enabled, k == 5, "after {k} cycles");
        assert_eq!(
            fb.actual_position, 0.0,
            "the load does not follow before it is enabled"
        );
    }
    // Then it follows (one cycle of dead time first).
    let fb = run(&mut drive, &target, 300);
    assert!((fb.actual_position - 1.0).abs() < 1e-6);

    // Dropping enable disables at once.
    drive.apply(&DriveSetpoint {
        enable: false,
        position: 1.0,
        ..Default::default()
    });
    assert!(!drive.feedback().enabled);
    assert!(drive.feedback().ready);

    // Zero delay still takes the cycle that carries the request.
    let mut cfg = SimDriveConfig {
        enable_delay: 0.0,
        ..SimDriveConfig::default()
    };
    assert_eq!(enable(&mut SimDrive::new(cfg.clone(), DT)), 1);
    cfg.enable_delay = 0.0025;
    assert_eq!(enable(&mut SimDrive::new(cfg, DT)), 3);
}

#[test]
fn interrupted_enable_request_starts_the_delay_again() {
    let mut drive = SimDrive::new(SimDriveConfig::default(), DT);
    run(&mut drive, &hold(0.0), 4);
    drive.apply(&DriveSetpoint::default());
    assert!(!run(&mut drive, &hold(0.0), 4).enabled);
    assert!(run(&mut drive, &hold(0.0), 1).enabled);
}

#[test]
fn a_disabled_drive_does_not_follow_and_coasts_to_rest() {
    let mut drive = SimDrive::new(SimDriveConfig::default(), DT);
    let fb = run(
        &mut drive,
        &DriveSetpoint {
            enable: false,
            position: 50.0,
            velocity: 10.0,
            ..Default::default()
        },
        100,
    );
    assert_eq!(fb.actual_position, 0.0);
    assert_eq!(fb.actual_velocity, 0.0);

    enable(&mut drive);
    let trace = constant_velocity(&mut drive, 100.0, 300, None);
    let moving = *trace.last().unwrap();
    assert!((moving.actual_velocity - 100.0).abs() < 1e-6);
    // Power off at 100 units/s: stops after 100/10000 s = 10 ms, 0.5 units further.
    let off = DriveSetpoint {
        enable: false,
        position: 1000.0,
        ..Default::default()
    };
    let mut fb = drive.feedback();
    let mut cycles = 0;
    while fb.actual_velocity != 0.0 {
        drive.apply(&off);
        fb = drive.feedback();
        cycles += 1;
        assert!(!fb.enabled);
    }
    assert_eq!(cycles, 10);
    assert!((fb.actual_position - moving.actual_position - 0.5).abs() < 1e-9);
    assert_eq!(
        run(&mut drive, &off, 10).actual_position,
        fb.actual_position
    );
}

#[test]
fn re_enabling_holds_the_actual_position_then_follows() {
    let mut drive = SimDrive::new(SimDriveConfig::default(), DT);
    drive.set_actual_position(7.0);
    let n = enable(&mut drive);
    assert_eq!(n, 5);
    let fb = run(&mut drive, &hold(7.0), 100);
    assert!((fb.actual_position - 7.0).abs() < 1e-12);
}

#[test]
fn injected_fault_disables_and_needs_the_cause_cleared_before_a_reset() {
    let mut drive = SimDrive::new(SimDriveConfig::default(), DT);
    enable(&mut drive);
    drive.inject(SimFault::DriveFault { code: 0x2310 });
    let fb = drive.feedback();
    assert!(fb.fault && !fb.ready && !fb.enabled);
    assert_eq!(fb.fault_code, 0x2310);

    // Enable requests are refused while faulted.
    assert!(!run(&mut drive, &hold(0.0), 20).enabled);

    // Reset while the cause persists: nothing.
    let reset = DriveSetpoint {
        fault_reset: true,
        ..Default::default()
    };
    drive.apply(&reset);
    assert!(drive.feedback().fault);

    // Cause removed, but the fault is latched until the next rising edge.
    drive.inject(SimFault::Clear);
    assert!(drive.feedback().fault);
    drive.apply(&reset);
    assert!(drive.feedback().fault, "a held reset is no edge");
    drive.apply(&DriveSetpoint::default());
    drive.apply(&reset);
    let fb = drive.feedback();
    assert!(!fb.fault && fb.ready && !fb.enabled);
    assert_eq!(fb.fault_code, 0);

    // Enable still requested after the reset: the drive goes through the enable delay again.
    assert_eq!(enable(&mut drive), 5);
}

#[test]
fn fault_code_zero_reads_as_a_generic_fault() {
    let mut drive = SimDrive::new(SimDriveConfig::default(), DT);
    drive.inject(SimFault::DriveFault { code: 0 });
    let fb = drive.feedback();
    assert!(fb.fault);
    assert_eq!(fb.fault_code, GENERIC_FAULT_CODE);
}

#[test]
fn a_fault_while_moving_lets_the_load_coast() {
    let mut drive = SimDrive::new(SimDriveConfig::default(), DT);
    enable(&mut drive);
    constant_velocity(&mut drive, 50.0, 100, None);
    let at_fault = drive.feedback().actual_position;
    drive.inject(SimFault::DriveFault { code: 7 });
    let fb = run(&mut drive, &hold(1000.0), 100);
    assert_eq!(fb.actual_velocity, 0.0);
    let coasted = fb.actual_position - at_fault;
    assert!(
        (coasted - 50.0 * 50.0 / 20_000.0).abs() < 1e-3,
        "coasted {coasted}"
    );
}

// ---------------------------------------------------------------- cam, index, latch

#[test]
fn reference_cam_is_active_on_its_range_of_the_actual_position() {
    let mut drive = SimDrive::new(SimDriveConfig::default(), DT);
    for (p, cam) in [
        (19.999, false),
        (20.0, true),
        (22.0, true),
        (25.0, true),
        (25.001, false),
        (-22.0, false),
    ] {
        drive.set_actual_position(p);
        assert_eq!(drive.feedback().reference_cam, cam, "at {p}");
    }
    let cfg = SimDriveConfig {
        reference_cam: None,
        ..SimDriveConfig::default()
    };
    let mut drive = SimDrive::new(cfg, DT);
    drive.set_actual_position(22.0);
    assert!(!drive.feedback().reference_cam);
}

#[test]
fn cam_flag_follows_the_moving_load() {
    let mut drive = SimDrive::new(SimDriveConfig::default(), DT);
    enable(&mut drive);
    let trace = constant_velocity(&mut drive, 30.0, 1500, None);
    let on: Vec<usize> = trace
        .iter()
        .enumerate()
        .filter(|(_, fb)| fb.reference_cam)
        .map(|(k, _)| k)
        .collect();
    let first = trace[on[0]].actual_position;
    let last = trace[*on.last().unwrap()].actual_position;
    assert!((20.0..20.03 + 1e-9).contains(&first), "{first}");
    assert!(last <= 25.0 && last > 24.97 - 1e-9, "{last}");
    assert_eq!(
        on.len(),
        on.last().unwrap() - on[0] + 1,
        "one contiguous stretch"
    );
}

fn index_config(plant: PlantModel) -> SimDriveConfig {
    SimDriveConfig {
        index_pulse: Some(IndexPulse {
            period: 10.0,
            offset: 2.5,
        }),
        ..config(plant, 0.0)
    }
}

#[test]
fn latch_on_the_index_pulse_is_exact_for_linear_motion() {
    let mut drive = SimDrive::new(index_config(PlantModel::Ideal), DT);
    drive.set_actual_position(3.1234567);
    enable(&mut drive);
    // 7.3 units/s: passes 12.5 between two cycles, nowhere near a cycle boundary.
    let trace = constant_velocity(&mut drive, 7.3, 2000, Some(LatchSource::IndexPulse));
    let k = trace.iter().position(|fb| fb.latch_valid).expect("latched");
    assert!(trace[k - 1].actual_position < 12.5 && trace[k].actual_position >= 12.5);
    assert!((trace[k].latch_position - 12.5).abs() < 1e-9);
    // Held while latch_enable stays, even across the next pulse (22.5 at ~2.65 s is not
    // reached here, but 12.5 is long passed): the value does not change.
    assert!(
        trace[k..]
            .iter()
            .all(|fb| fb.latch_valid && fb.latch_position == trace[k].latch_position)
    );
}

#[test]
fn latch_on_the_index_pulse_in_the_negative_direction() {
    let mut drive = SimDrive::new(index_config(PlantModel::default()), DT);
    drive.set_actual_position(30.0);
    enable(&mut drive);
    let trace = constant_velocity(&mut drive, -11.0, 1000, Some(LatchSource::IndexPulse));
    let k = trace.iter().position(|fb| fb.latch_valid).expect("latched");
    assert!(trace[k - 1].actual_position > 22.5 && trace[k].actual_position <= 22.5);
    assert!((trace[k].latch_position - 22.5).abs() < 1e-9);
}

#[test]
fn latch_is_exact_through_a_lagging_plant_at_homing_speed() {
    for plant in [
        PlantModel::Pt1 {
            time_constant: 0.003,
        },
        PlantModel::default(),
    ] {
        let mut drive = SimDrive::new(index_config(plant), DT);
        drive.set_actual_position(1.0);
        enable(&mut drive);
        let trace = constant_velocity(&mut drive, 5.0, 1000, Some(LatchSource::IndexPulse));
        let fb = trace.iter().find(|fb| fb.latch_valid).expect("latched");
        assert!((fb.latch_position - 2.5).abs() < 1e-9, "{plant:?}");
    }
}

#[test]
fn latch_rearms_when_latch_enable_drops() {
    let mut drive = SimDrive::new(index_config(PlantModel::Ideal), DT);
    enable(&mut drive);
    let mut latched = Vec::new();
    let mut latch_enable = true;
    let mut was_valid = false;
    for k in 1..=4000 {
        let sp = DriveSetpoint {
            enable: true,
            position: 0.01 * k as f64,
            velocity: 10.0,
            latch_enable,
            ..Default::default()
        };
        drive.apply(&sp);
        let fb = drive.feedback();
        if fb.latch_valid && !was_valid {
            latched.push(fb.latch_position);
        }
        if !latch_enable {
            assert!(!fb.latch_valid, "latch_valid resets with latch_enable");
        }
        was_valid = fb.latch_valid;
        // Hold the latch for a while, drop it for one cycle, arm again.
        latch_enable = !(fb.latch_valid && fb.actual_position > fb.latch_position + 3.0);
    }
    // Pulses at 2.5, 12.5, 22.5, 32.5 (the axis ends at 40).
    assert_eq!(latched, vec![2.5, 12.5, 22.5, 32.5]);
}

#[test]
fn latch_armed_on_a_pulse_waits_for_the_next_one() {
    let mut drive = SimDrive::new(index_config(PlantModel::Ideal), DT);
    drive.set_actual_position(12.5);
    enable(&mut drive);
    let trace = constant_velocity(&mut drive, 10.0, 1100, Some(LatchSource::IndexPulse));
    let fb = trace.iter().find(|fb| fb.latch_valid).expect("latched");
    assert_eq!(fb.latch_position, 22.5);
}

#[test]
fn no_index_pulse_means_no_latch() {
    let mut cfg = ideal(0.0);
    cfg.index_pulse = None;
    let mut drive = SimDrive::new(cfg, DT);
    enable(&mut drive);
    let trace = constant_velocity(&mut drive, 100.0, 1000, Some(LatchSource::IndexPulse));
    assert!(trace.iter().all(|fb| !fb.latch_valid));
}

#[test]
fn latch_on_cam_edges_in_both_directions() {
    // (start, velocity, source, expected)
    let cases = [
        (0.0, 30.0, LatchSource::CamRising, 20.0),
        (0.0, 30.0, LatchSource::CamFalling, 25.0),
        (22.0, 5.0, LatchSource::CamFalling, 25.0),
        (40.0, -30.0, LatchSource::CamRising, 25.0),
        (40.0, -30.0, LatchSource::CamFalling, 20.0),
        (22.0, -5.0, LatchSource::CamFalling, 20.0),
    ];
    for plant in [PlantModel::Ideal, PlantModel::default()] {
        for (start, v, source, expected) in cases {
            let mut drive = SimDrive::new(config(plant, 0.001), DT);
            drive.set_actual_position(start);
            enable(&mut drive);
            let trace = constant_velocity(&mut drive, v, 2000, Some(source));
            let k = trace.iter().position(|fb| fb.latch_valid).expect("latched");
            assert!(
                (trace[k].latch_position - expected).abs() < 1e-9,
                "{plant:?} {start} {v} {source:?}"
            );
            // Latched in the cycle in which the cam signal changed.
            let rising = matches!(source, LatchSource::CamRising);
            assert_eq!(
                trace[k].reference_cam, rising,
                "{plant:?} {start} {v} {source:?}"
            );
            assert_eq!(
                trace[k - 1].reference_cam,
                !rising,
                "{plant:?} {start} {v} {source:?}"
            );
        }
    }
}

#[test]
fn latch_sees_an_overshoot_between_cycles() {
    // A weakly damped plant overshoots through the pulse at 10.0 and comes back within the
    // same cycles; the probe still catches the crossing.
    let mut cfg = config(
        PlantModel::Pt2 {
            natural_frequency_hz: 100.0,
            damping: 0.1,
        },
        0.0,
    );
    cfg.index_pulse = Some(IndexPulse {
        period: 100.0,
        offset: 10.0,
    });
    let mut drive = SimDrive::new(cfg, 0.01);
    enable(&mut drive);
    let mut latched = None;
    let mut max_sample: f64 = 0.0;
    for _ in 0..50 {
        let sp = DriveSetpoint {
            enable: true,
            position: 9.5,
            latch_enable: true,
            ..Default::default()
        };
        drive.apply(&sp);
        let fb = drive.feedback();
        max_sample = max_sample.max(fb.actual_position);
        if fb.latch_valid && latched.is_none() {
            latched = Some(fb.latch_position);
        }
    }
    assert_eq!(latched, Some(10.0));
    assert!(
        max_sample < 10.0,
        "the cycle samples never show the overshoot: {max_sample}"
    );
}

// ---------------------------------------------------------------- limit switches, load

fn limits(fault_on_hit: bool) -> SimDriveConfig {
    SimDriveConfig {
        limit_switches: LimitSwitches {
            negative: Some(-100.0),
            positive: Some(100.0),
            fault_on_hit,
        },
        ..SimDriveConfig::default()
    }
}

#[test]
fn limit_switches_at_their_positions_and_forced() {
    let mut drive = SimDrive::new(limits(false), DT);
    for (p, pos, neg) in [
        (0.0, false, false),
        (100.0, true, false),
        (150.0, true, false),
        (-100.0, false, true),
        (-99.0, false, false),
    ] {
        drive.set_actual_position(p);
        let fb = drive.feedback();
        assert_eq!((fb.limit_positive, fb.limit_negative), (pos, neg), "at {p}");
    }
    drive.set_actual_position(0.0);
    drive.inject(SimFault::LimitSwitch {
        positive: false,
        active: true,
    });
    assert!(drive.feedback().limit_negative && !drive.feedback().limit_positive);
    drive.inject(SimFault::LimitSwitch {
        positive: true,
        active: true,
    });
    assert!(drive.feedback().limit_positive);
    drive.inject(SimFault::LimitSwitch {
        positive: false,
        active: false,
    });
    assert!(!drive.feedback().limit_negative && drive.feedback().limit_positive);
    drive.inject(SimFault::Clear);
    assert!(!drive.feedback().limit_positive);

    let mut none = SimDrive::new(SimDriveConfig::default(), DT);
    none.set_actual_position(1e9);
    assert!(!none.feedback().limit_positive && !none.feedback().limit_negative);
}

#[test]
fn limit_switches_only_report_unless_configured_to_fault() {
    let mut drive = SimDrive::new(limits(false), DT);
    drive.set_actual_position(95.0);
    enable(&mut drive);
    let trace = constant_velocity(&mut drive, 50.0, 200, None);
    assert!(trace.last().unwrap().limit_positive);
    assert!(trace.iter().all(|fb| !fb.fault && fb.enabled));
}

#[test]
fn limit_switch_hit_faults_the_drive_when_configured() {
    let mut drive = SimDrive::new(limits(true), DT);
    drive.set_actual_position(95.0);
    enable(&mut drive);
    let trace = constant_velocity(&mut drive, 50.0, 200, None);
    let k = trace.iter().position(|fb| fb.fault).expect("faulted");
    assert!(trace[k].limit_positive && !trace[k - 1].limit_positive);
    assert_eq!(trace[k].fault_code, LIMIT_SWITCH_FAULT_CODE);
    assert!(!trace[k].enabled && !trace[k].ready);

    // Coasted to rest on the switch; a reset clears the fault although the switch is pressed.
    let fb = run(&mut drive, &DriveSetpoint::default(), 100);
    assert!(fb.limit_positive && fb.fault);
    drive.apply(&DriveSetpoint {
        fault_reset: true,
        ..Default::default()
    });
    assert!(!drive.feedback().fault);
    // And the axis can be moved off it.
    enable(&mut drive);
    let trace = constant_velocity(&mut drive, -20.0, 500, None);
    assert!(trace.iter().all(|fb| !fb.fault));
    assert!(!trace.last().unwrap().limit_positive);

    // A forced switch while enabled faults too; while disabled it does not.
    drive.inject(SimFault::LimitSwitch {
        positive: false,
        active: true,
    });
    drive.apply(&hold(drive.feedback().actual_position));
    assert_eq!(drive.feedback().fault_code, LIMIT_SWITCH_FAULT_CODE);

    let mut disabled = SimDrive::new(limits(true), DT);
    disabled.inject(SimFault::LimitSwitch {
        positive: true,
        active: true,
    });
    let fb = run(&mut disabled, &DriveSetpoint::default(), 3);
    assert!(fb.limit_positive && !fb.fault);
}

#[test]
fn load_force_gives_a_proportional_following_error() {
    for plant in [
        PlantModel::Ideal,
        PlantModel::Pt1 {
            time_constant: 0.005,
        },
        PlantModel::default(),
    ] {
        let mut drive = SimDrive::new(config(plant, 0.001), DT);
        enable(&mut drive);
        drive.inject(SimFault::Load { force: 500.0 });
        assert_eq!(drive.load_force(), 500.0);
        // At rest: following error = F / load_stiffness = 500 / 1000.
        let fb = run(&mut drive, &hold(0.0), 500);
        assert!(
            (0.0 - fb.actual_position - 0.5).abs() < 1e-9,
            "{plant:?}: {}",
            fb.actual_position
        );
        // Moving: the same offset on top of the motion.
        let trace = constant_velocity(&mut drive, 100.0, 500, None);
        let lag = fb.actual_position + 100.0 * 500.0 * DT - trace.last().unwrap().actual_position;
        assert!((lag - 0.5).abs() < 1e-6, "{plant:?}: lag {lag}");
        // Removing it brings the lag back to 0.
        drive.inject(SimFault::Load { force: 0.0 });
        let p = drive.feedback().actual_position + 0.5;
        let fb = run(&mut drive, &hold(p), 500);
        assert!((fb.actual_position - p).abs() < 1e-9, "{plant:?}");
    }
}

#[test]
fn a_large_load_exceeds_the_default_lag_limit() {
    let mut drive = SimDrive::new(SimDriveConfig::default(), DT);
    enable(&mut drive);
    drive.inject(SimFault::Load { force: -6000.0 });
    let fb = run(&mut drive, &hold(0.0), 200);
    // MC_AxisParameter default max position lag is 5 units.
    assert!((fb.actual_position - 6.0).abs() < 1e-6);
    drive.inject(SimFault::Clear);
    assert_eq!(drive.load_force(), 0.0);
}

// ---------------------------------------------------------------- configuration

fn errors_of(cfg: SimDriveConfig) -> Vec<String> {
    cfg.validate()
        .err()
        .unwrap_or_default()
        .into_iter()
        .map(|e| e.field)
        .collect()
}

#[test]
fn validation_names_the_offending_field() {
    let d = SimDriveConfig::default;
    let cases: Vec<(SimDriveConfig, &str)> = vec![
        (
            SimDriveConfig {
                plant: PlantModel::Pt1 { time_constant: 0.0 },
                ..d()
            },
            "plant.time_constant",
        ),
        (
            SimDriveConfig {
                plant: PlantModel::Pt1 {
                    time_constant: f64::NAN,
                },
                ..d()
            },
            "plant.time_constant",
        ),
        (
            SimDriveConfig {
                plant: PlantModel::Pt2 {
                    natural_frequency_hz: -1.0,
                    damping: 0.7,
                },
                ..d()
            },
            "plant.natural_frequency_hz",
        ),
        (
            SimDriveConfig {
                plant: PlantModel::Pt2 {
                    natural_frequency_hz: 50.0,
                    damping: 0.0,
                },
                ..d()
            },
            "plant.damping",
        ),
        (
            SimDriveConfig {
                dead_time: -0.001,
                ..d()
            },
            "dead_time",
        ),
        (
            SimDriveConfig {
                dead_time: 0.2,
                ..d()
            },
            "dead_time",
        ),
        (
            SimDriveConfig {
                velocity_feed_forward: 3.0,
                ..d()
            },
            "velocity_feed_forward",
        ),
        (
            SimDriveConfig {
                acceleration_feed_forward: -0.5,
                ..d()
            },
            "acceleration_feed_forward",
        ),
        (
            SimDriveConfig {
                enable_delay: f64::INFINITY,
                ..d()
            },
            "enable_delay",
        ),
        (
            SimDriveConfig {
                coast_deceleration: 0.0,
                ..d()
            },
            "coast_deceleration",
        ),
        (
            SimDriveConfig {
                load_stiffness: -1.0,
                ..d()
            },
            "load_stiffness",
        ),
        (
            SimDriveConfig {
                reference_cam: Some(ReferenceCam {
                    start: 5.0,
                    end: 5.0,
                }),
                ..d()
            },
            "reference_cam.end",
        ),
        (
            SimDriveConfig {
                reference_cam: Some(ReferenceCam {
                    start: f64::NAN,
                    end: 5.0,
                }),
                ..d()
            },
            "reference_cam.start",
        ),
        (
            SimDriveConfig {
                index_pulse: Some(IndexPulse {
                    period: 0.0,
                    offset: 0.0,
                }),
                ..d()
            },
            "index_pulse.period",
        ),
        (
            SimDriveConfig {
                index_pulse: Some(IndexPulse {
                    period: 1.0,
                    offset: f64::NAN,
                }),
                ..d()
            },
            "index_pulse.offset",
        ),
        (
            SimDriveConfig {
                limit_switches: LimitSwitches {
                    negative: Some(10.0),
                    positive: Some(-10.0),
                    fault_on_hit: false,
                },
                ..d()
            },
            "limit_switches.positive",
        ),
        (
            SimDriveConfig {
                limit_switches: LimitSwitches {
                    negative: Some(f64::NAN),
                    positive: None,
                    fault_on_hit: false,
                },
                ..d()
            },
            "limit_switches.negative",
        ),
    ];
    for (cfg, field) in cases {
        assert_eq!(errors_of(cfg.clone()), vec![field.to_string()], "{cfg:?}");
    }
    let all = SimDriveConfig {
        dead_time: -1.0,
        enable_delay: -1.0,
        load_stiffness: 0.0,
        ..d()
    };
    assert_eq!(
        errors_of(all),
        vec!["dead_time", "enable_delay", "load_stiffness"]
    );
    let err = SimDriveConfig {
        dead_time: 1.0,
        ..d()
    }
    .validate()
    .unwrap_err();
    assert!(!err[0].message.is_empty());
    assert_eq!(
        errors_of(SimDriveConfig {
            plant: PlantModel::Ideal,
            reference_cam: None,
            index_pulse: None,
            ..d()
        }),
        Vec::<String>::new()
    );
}

#[test]
#[should_panic(expected = "invalid SimDriveConfig")]
fn new_refuses_an_invalid_config() {
    SimDrive::new(
        SimDriveConfig {
            dead_time: -1.0,
            ..SimDriveConfig::default()
        },
        DT,
    );
}

#[test]
fn default_config_json_shape() {
    let value = serde_json::to_value(SimDriveConfig::default()).unwrap();
    assert_eq!(
        value,
        json!({
            "plant": { "kind": "pt2", "natural_frequency_hz": 50.0, "damping": 0.8 },
            "dead_time": 0.001,
            "dead_time_compensation": true,
            "velocity_feed_forward": 1.0,
            "acceleration_feed_forward": 0.0,
            "enable_delay": 0.005,
            "coast_deceleration": 10000.0,
            "load_stiffness": 1000.0,
            "reference_cam": { "start": 20.0, "end": 25.0 },
            "index_pulse": { "period": 10.0, "offset": 0.0 },
            "limit_switches": { "negative": null, "positive": null, "fault_on_hit": false },
            "torque": { "acceleration_per_percent": 100.0, "friction": 1.0, "viscous": 0.0 },
            "velocity_mode_position_gain": 100.0
        })
    );
}

#[test]
fn config_round_trips_through_json() {
    let configs = [
        SimDriveConfig::default(),
        SimDriveConfig {
            plant: PlantModel::Pt1 {
                time_constant: 0.0123,
            },
            dead_time: 0.00025,
            dead_time_compensation: false,
            velocity_feed_forward: 0.9,
            acceleration_feed_forward: 0.3,
            enable_delay: 0.1,
            coast_deceleration: 123.0,
            load_stiffness: 42.0,
            reference_cam: None,
            index_pulse: Some(IndexPulse {
                period: 360.0,
                offset: 12.0,
            }),
            limit_switches: LimitSwitches {
                negative: Some(-5.0),
                positive: Some(505.0),
                fault_on_hit: true,
            },
            torque: drives::sim::TorqueModel {
                acceleration_per_percent: 20.0,
                friction: 0.5,
                viscous: 0.01,
            },
            velocity_mode_position_gain: 50.0,
        },
        SimDriveConfig {
            plant: PlantModel::Ideal,
            index_pulse: None,
            ..SimDriveConfig::default()
        },
    ];
    for cfg in configs {
        let text = serde_json::to_string(&cfg).unwrap();
        let back: SimDriveConfig = serde_json::from_str(&text).unwrap();
        assert_eq!(back, cfg, "{text}");
    }
}

#[test]
fn config_parsing_fills_defaults_and_rejects_unknown_fields() {
    let parse = |v: serde_json::Value| serde_json::from_value::<SimDriveConfig>(v);
    assert_eq!(parse(json!({})).unwrap(), SimDriveConfig::default());
    let cfg = parse(json!({ "plant": { "kind": "pt2", "damping": 1.0 }, "reference_cam": null }))
        .unwrap();
    assert_eq!(
        cfg.plant,
        PlantModel::Pt2 {
            natural_frequency_hz: 50.0,
            damping: 1.0
        }
    );
    assert_eq!(cfg.reference_cam, None);
    assert_eq!(
        parse(json!({ "plant": { "kind": "ideal" } }))
            .unwrap()
            .plant,
        PlantModel::Ideal
    );
    assert_eq!(
        parse(json!({ "plant": { "kind": "pt1" } })).unwrap().plant,
        PlantModel::Pt1 {
            time_constant: 0.005
        }
    );
    assert_eq!(
        parse(json!({ "index_pulse": { "period": 5.0 } }))
            .unwrap()
            .index_pulse,
        Some(IndexPulse {
            period: 5.0,
            offset: 0.0
        })
    );
    assert!(parse(json!({ "lag": 1.0 })).is_err());
    assert!(parse(json!({ "plant": { "kind": "pt3" } })).is_err());
    assert!(parse(json!({ "plant": { "kind": "pt1", "damping": 1.0 } })).is_err());
    assert!(parse(json!({ "reference_cam": { "start": 1.0 } })).is_err());
    assert!(parse(json!({ "limit_switches": { "positive": 1.0, "x": 1 } })).is_err());
}

#[test]
fn sim_fault_json_shape() {
    let cases = [
        (
            SimFault::DriveFault { code: 0x2310 },
            json!({ "kind": "drive_fault", "code": 0x2310 }),
        ),
        (
            SimFault::Load { force: 12.5 },
            json!({ "kind": "load", "force": 12.5 }),
        ),
        (
            SimFault::LimitSwitch {
                positive: true,
                active: false,
            },
            json!({ "kind": "limit_switch", "positive": true, "active": false }),
        ),
        (SimFault::Clear, json!({ "kind": "clear" })),
    ];
    for (fault, value) in cases {
        assert_eq!(serde_json::to_value(fault).unwrap(), value);
        assert_eq!(serde_json::from_value::<SimFault>(value).unwrap(), fault);
    }
    assert!(
        serde_json::from_value::<SimFault>(json!({ "kind": "load", "force": 1.0, "x": 2 }))
            .is_err()
    );
}

/// The plant's one-cycle map (used while no probe latch is armed) gives what its substep
/// integration gives (used while one is): two drives fed the same jerky setpoints, one with a
/// latch armed on an input that never switches, stay together to rounding, cycle by cycle.
#[test]
fn the_one_cycle_map_of_the_plant_gives_what_its_substeps_give() {
    for plant in [
        PlantModel::Pt1 {
            time_constant: 0.004,
        },
        PlantModel::Pt2 {
            natural_frequency_hz: 40.0,
            damping: 0.7,
        },
    ] {
        let config = SimDriveConfig {
            plant,
            ..Default::default()
        };
        let (mut mapped, mut stepped) =
            (SimDrive::new(config.clone(), DT), SimDrive::new(config, DT));
        enable(&mut mapped);
        enable(&mut stepped);
        let mut worst: f64 = 0.0;
        for k in 0..3000 {
            let t = k as f64 * DT;
            // A setpoint with velocity and acceleration feed-forward that changes every cycle.
            let sp = DriveSetpoint {
                enable: true,
                position: 100.0 * (3.0 * t).sin() + 20.0 * t,
                velocity: 300.0 * (3.0 * t).cos() + 20.0,
                acceleration: -900.0 * (3.0 * t).sin(),
                ..Default::default()
            };
            mapped.apply(&sp);
            stepped.apply(&DriveSetpoint {
                latch_enable: true,
                latch_source: LatchSource::Input1Rising,
                ..sp
            });
            let (a, b) = (mapped.feedback(), stepped.feedback());
            assert!(!b.latch_valid);
            worst = worst
                .max((a.actual_position - b.actual_position).abs())
                .max((a.actual_velocity - b.actual_velocity).abs() * DT);
        }
        assert!(worst < 1e-9, "{plant:?}: {worst}");
        assert!(mapped.feedback().actual_position != 0.0);
    }
}
