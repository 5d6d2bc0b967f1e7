//! The emulated drive's profile modes period by period: the PP set-point handshake (single,
//! set of set points, change immediately, relative, halt and resume), PV with its windows,
//! and every homing method with its status bits, its failure on a limit switch and its
//! interruption.

use super::super::{Cia402Emu, MODE_CSP, MODE_HM, MODE_PP, MODE_PV, Plant, State};
use super::Homing;
use crate::emu::sii::Identity;

const DT: f64 = 0.001;
const ENABLED: u16 = 0x0F;
const NEW: u16 = 1 << 4;
const IMMEDIATE: u16 = 1 << 5;
const RELATIVE: u16 = 1 << 6;
const HALT: u16 = 1 << 8;
const REACHED: u16 = 1 << 10;
const B12: u16 = 1 << 12;
const B13: u16 = 1 << 13;

fn drive() -> Cia402Emu {
    let id = Identity {
        vendor_id: 1,
        product_code: 2,
        revision: 3,
        serial: 4,
        name: "test".into(),
    };
    Cia402Emu::new(
        &id,
        Plant {
            limit_negative: Some(-45_000.0),
            limit_positive: Some(45_000.0),
            ..Plant::default()
        },
    )
}

/// One setpoint period with controlword `cw`: the statusword.
fn cycle(d: &mut Cia402Emu, cw: u16) -> u16 {
    d.od.set(0x6040, 0, &cw.to_le_bytes());
    d.step_drive(DT, true);
    d.od.u16(0x6041, 0)
}

/// A drive standing at `at`, enabled in `mode`.
fn enabled(mode: i8, at: f64) -> Cia402Emu {
    let mut d = drive();
    d.position = at;
    d.target = at;
    d.od.set(0x6060, 0, &[mode as u8]);
    // Not ready → switch on disabled on its own, then shutdown, switch on, enable.
    for cw in [0, 0x06, 0x07, ENABLED] {
        cycle(&mut d, cw);
    }
    assert_eq!(d.state, State::OperationEnabled);
    assert_eq!(d.od.i8(0x6061, 0), mode);
    d
}

fn target(d: &mut Cia402Emu, t: i32) {
    d.od.set(0x607A, 0, &t.to_le_bytes());
}

fn demand(d: &Cia402Emu) -> f64 {
    f64::from(d.od.i32(0x6062, 0))
}

#[test]
fn pp_a_single_set_point_is_acknowledged_ramped_and_reached() {
    let mut d = enabled(MODE_PP, 0.0);
    assert_ne!(d.od.u16(0x6041, 0) & REACHED, 0, "at rest on its position");
    target(&mut d, 100_000);
    let sw = cycle(&mut d, ENABLED | NEW);
    assert_ne!(sw & B12, 0, "set-point acknowledge with the set point");
    assert_eq!(sw & REACHED, 0, "a new target is not reached");
    // The acknowledge stays while bit 4 does, and falls once it does.
    assert_ne!(cycle(&mut d, ENABLED | NEW) & B12, 0);
    assert_eq!(cycle(&mut d, ENABLED) & B12, 0);
    let (v, a) = (100_000.0, 1_000_000.0);
    let mut last_v = d.profile.ramp.vel;
    let mut periods = 3;
    loop {
        let sw = cycle(&mut d, ENABLED);
        periods += 1;
        let ramp = d.profile.ramp;
        assert!(ramp.vel <= v + 1e-6, "profile velocity {}", ramp.vel);
        assert!(
            (ramp.vel - last_v).abs() <= a * DT * 1.13,
            "ramp: {last_v} → {} at {}",
            ramp.vel,
            ramp.pos
        );
        assert!(ramp.pos <= 100_000.0, "never past the target");
        assert_eq!(sw & B13, 0, "no following error");
        last_v = ramp.vel;
        if sw & REACHED != 0 {
            break;
        }
        assert!(periods < 5_000);
    }
    // 1 s at 100 000/s plus 0.1 s of ramps, and the position loop settling within 10.
    assert!((1_095..1_130).contains(&periods), "{periods} periods");
    assert_eq!(demand(&d), 100_000.0);
    assert!((f64::from(d.od.i32(0x6064, 0)) - 100_000.0).abs() <= 10.0);
}

#[test]
fn pp_a_set_of_set_points_runs_one_after_the_other() {
    let mut d = enabled(MODE_PP, 0.0);
    target(&mut d, 20_000);
    cycle(&mut d, ENABLED | NEW);
    for _ in 0..50 {
        cycle(&mut d, ENABLED);
    }
    // The second while the first runs: buffered, the acknowledge held (buffer full).
    target(&mut d, 40_000);
    assert_ne!(cycle(&mut d, ENABLED | NEW) & B12, 0);
    assert_ne!(cycle(&mut d, ENABLED) & B12, 0, "buffer full");
    // A third while the buffer is full is not taken.
    target(&mut d, -10_000);
    assert_ne!(cycle(&mut d, ENABLED | NEW) & B12, 0);
    cycle(&mut d, ENABLED);
    // The first ends at rest on its target, then the buffered one starts.
    let mut stood_at_first = false;
    let mut sw = 0;
    for _ in 0..3_000 {
        sw = cycle(&mut d, ENABLED);
        if d.profile.ramp.vel == 0.0 && demand(&d) == 20_000.0 {
            stood_at_first = true;
        }
        if stood_at_first && demand(&d) > 20_000.0 {
            assert_eq!(sw & B12, 0, "buffer free once the second started");
        }
        if sw & REACHED != 0 && demand(&d) == 40_000.0 {
            break;
        }
    }
    assert!(stood_at_first);
    assert_ne!(sw & REACHED, 0);
    assert_eq!(demand(&d), 40_000.0, "the third was never taken");
}

#[test]
fn pp_change_set_immediately_replaces_the_running_set_point() {
    let mut d = enabled(MODE_PP, 0.0);
    target(&mut d, 100_000);
    cycle(&mut d, ENABLED | NEW);
    for _ in 0..300 {
        cycle(&mut d, ENABLED);
    }
    let turned_at = demand(&d);
    target(&mut d, -20_000);
    assert_ne!(cycle(&mut d, ENABLED | NEW | IMMEDIATE) & B12, 0);
    let mut highest = turned_at;
    for _ in 0..5_000 {
        let sw = cycle(&mut d, ENABLED | IMMEDIATE);
        highest = highest.max(demand(&d));
        if sw & REACHED != 0 {
            break;
        }
    }
    assert_eq!(demand(&d), -20_000.0);
    // Braked at the deceleration from ≈ 100 000/s: ≈ 5 000 beyond where it turned.
    assert!(highest < turned_at + 6_000.0, "{highest} vs {turned_at}");
    assert!(highest < 100_000.0);
}

#[test]
fn pp_relative_set_points_add_to_the_preceding_target() {
    let mut d = enabled(MODE_PP, 1_000.0);
    target(&mut d, 5_000);
    for _ in 0..2 {
        cycle(&mut d, ENABLED | NEW | RELATIVE);
        for _ in 0..2_000 {
            if cycle(&mut d, ENABLED) & REACHED != 0 {
                break;
            }
        }
    }
    assert_eq!(demand(&d), 11_000.0);
}

#[test]
fn pp_halt_stops_on_the_deceleration_and_release_resumes() {
    let mut d = enabled(MODE_PP, 0.0);
    target(&mut d, 100_000);
    cycle(&mut d, ENABLED | NEW);
    for _ in 0..400 {
        cycle(&mut d, ENABLED);
    }
    let v0 = d.profile.ramp.vel;
    assert!((v0 - 100_000.0).abs() < 1.0);
    let mut periods = 0;
    loop {
        let sw = cycle(&mut d, ENABLED | HALT);
        periods += 1;
        if sw & REACHED != 0 {
            break;
        }
        assert!(periods < 1_000);
    }
    // 0.1 s at 1 000 000/s².
    assert!((99..=102).contains(&periods), "{periods}");
    assert_eq!(d.profile.ramp.vel, 0.0);
    let held = demand(&d);
    for _ in 0..50 {
        assert_ne!(cycle(&mut d, ENABLED | HALT) & REACHED, 0);
    }
    assert_eq!(demand(&d), held, "halted stays");
    assert_eq!(
        cycle(&mut d, ENABLED) & REACHED,
        0,
        "released: on its way again"
    );
    for _ in 0..2_000 {
        if cycle(&mut d, ENABLED) & REACHED != 0 {
            break;
        }
    }
    assert_eq!(demand(&d), 100_000.0);
}

#[test]
fn pv_ramps_to_the_target_velocity_with_its_windows() {
    let mut d = enabled(MODE_PV, 0.0);
    assert_ne!(cycle(&mut d, ENABLED) & B12, 0, "speed zero");
    d.od.set(0x60FF, 0, &50_000i32.to_le_bytes());
    let mut periods = 0;
    loop {
        let sw = cycle(&mut d, ENABLED);
        periods += 1;
        if periods == 20 {
            assert_eq!(sw & B12, 0, "moving");
            assert_eq!(sw & REACHED, 0);
        }
        if sw & REACHED != 0 {
            break;
        }
        assert!(periods < 1_000);
    }
    // 50 ms of ramp, then the velocity loop within 1 000/s.
    assert!((50..70).contains(&periods), "{periods}");
    assert!((f64::from(d.od.i32(0x606C, 0)) - 50_000.0).abs() <= 1_000.0);
    let moved = d.position;
    for _ in 0..100 {
        cycle(&mut d, ENABLED);
    }
    assert!(
        (d.position - moved - 5_000.0).abs() < 100.0,
        "0.1 s at 50 000/s"
    );
    // Halt: down to 0 at the deceleration, bit 10 once standing.
    let mut periods = 0;
    loop {
        let sw = cycle(&mut d, ENABLED | HALT);
        periods += 1;
        if sw & REACHED != 0 && sw & B12 != 0 {
            break;
        }
        assert!(periods < 1_000);
    }
    assert!(periods >= 50, "{periods}");
    assert!(d.velocity.abs() <= 1_000.0);
}

/// Runs homing `method` from `at` until it ends: the statusword, the periods taken and
/// whether bits 10/12/13 ever read anything but "in progress" before the end.
fn home(method: i8, at: f64, offset: i32) -> (Cia402Emu, u16) {
    let mut d = enabled(MODE_HM, at);
    d.od.set(0x6098, 0, &[method as u8]);
    d.od.set(0x607C, 0, &offset.to_le_bytes());
    let before = cycle(&mut d, ENABLED);
    assert_eq!(before & (REACHED | B12 | B13), REACHED, "not started");
    let mut sw = cycle(&mut d, ENABLED | NEW);
    for _ in 0..20_000 {
        if sw & (REACHED | B12 | B13) != 0 {
            break;
        }
        sw = cycle(&mut d, ENABLED | NEW);
    }
    // Let it come to rest.
    for _ in 0..500 {
        sw = cycle(&mut d, ENABLED | NEW);
    }
    (d, sw)
}

fn assert_homed(method: i8, at: f64, home_on_plant: f64) {
    let (d, sw) = home(method, at, 1_234);
    assert_eq!(sw & (REACHED | B12 | B13), REACHED | B12, "method {method}");
    assert_eq!(d.homing(), Homing::Attained);
    // Standing on the home position, which now reads as the home offset.
    assert!(
        (d.plant_position() - home_on_plant).abs() <= 1.0,
        "method {method}: at {} on the plant, home {home_on_plant}",
        d.plant_position()
    );
    assert!((f64::from(d.od.i32(0x6064, 0)) - 1_234.0).abs() <= 1.0);
}

#[test]
fn homing_on_a_limit_switch_and_the_index_pulse() {
    // 1: towards the negative switch (at −45 000), off it, to the next index pulse (every
    // 10 000) beyond: −40 000. 2 mirrors it.
    assert_homed(1, 0.0, -40_000.0);
    assert_homed(2, 0.0, 40_000.0);
    // Started on the switch: straight off it.
    assert_homed(1, -47_000.0, -40_000.0);
}

#[test]
fn homing_on_a_limit_switch_edge() {
    assert_homed(17, 0.0, -45_000.0);
    assert_homed(18, 3_000.0, 45_000.0);
}

#[test]
fn homing_on_the_index_pulse_and_on_the_current_position() {
    assert_homed(33, 5_000.0, 0.0);
    assert_homed(34, 5_000.0, 10_000.0);
    for method in [35, 37] {
        let mut d = enabled(MODE_HM, 7_777.0);
        d.od.set(0x6098, 0, &[method as u8]);
        d.od.set(0x607C, 0, &(-5i32).to_le_bytes());
        let sw = cycle(&mut d, ENABLED | NEW);
        assert_eq!(sw & (REACHED | B12 | B13), REACHED | B12);
        assert_eq!(d.od.i32(0x6064, 0), -5);
        assert_eq!(d.plant_position(), 7_777.0, "no motion");
    }
}

#[test]
fn homing_fails_on_a_limit_switch_it_does_not_look_for() {
    // 34 from 44 000: the next index pulse (50 000) lies beyond the positive switch.
    let (d, sw) = home(34, 44_000.0, 0);
    assert_eq!(sw & (REACHED | B12 | B13), REACHED | B13, "error, standing");
    assert_eq!(d.homing(), Homing::Failed);
    assert!(d.plant_position() < 46_000.0, "{}", d.plant_position());
    // 2 leaving the positive switch runs into the negative one before an index pulse.
    let mut d = enabled(MODE_HM, 20_000.0);
    d.plant.increments_per_turn = 100_000;
    d.plant.limit_negative = Some(5_000.0);
    d.od.set(0x6098, 0, &[2]);
    let mut failed_moving = false;
    for _ in 0..20_000 {
        let sw = cycle(&mut d, ENABLED | NEW);
        if sw & B13 != 0 && sw & REACHED == 0 {
            failed_moving = true;
        }
        if sw & (B13 | REACHED) == B13 | REACHED {
            break;
        }
    }
    assert!(failed_moving, "13 without 10 while braking");
    assert_eq!(d.homing(), Homing::Failed);
    assert!(d.plant_position() < 5_000.0 && d.plant_position() > 4_000.0);
}

#[test]
fn homing_interrupted_by_bit_4_or_halt_stops_and_says_so() {
    for stop in [ENABLED, ENABLED | NEW | HALT] {
        let mut d = enabled(MODE_HM, 0.0);
        d.od.set(0x6098, 0, &[1]);
        cycle(&mut d, ENABLED | NEW);
        for _ in 0..200 {
            assert_eq!(cycle(&mut d, ENABLED | NEW) & (REACHED | B12 | B13), 0);
        }
        let mut sw = 0;
        for _ in 0..500 {
            sw = cycle(&mut d, stop);
        }
        assert_eq!(sw & (REACHED | B12 | B13), REACHED, "interrupted, standing");
        assert_eq!(d.homing(), Homing::Idle);
        assert_eq!(d.profile.ramp.vel, 0.0);
    }
}

#[test]
fn leaving_a_profile_mode_drops_its_set_points_and_csp_holds_where_the_motor_is() {
    let mut d = enabled(MODE_PP, 0.0);
    target(&mut d, 100_000);
    cycle(&mut d, ENABLED | NEW);
    for _ in 0..200 {
        cycle(&mut d, ENABLED);
    }
    let moving = demand(&d);
    assert!(moving > 0.0);
    // Power off and on again: the set point is gone.
    cycle(&mut d, 0x06);
    cycle(&mut d, 0x07);
    cycle(&mut d, ENABLED);
    let here = d.position;
    for _ in 0..100 {
        cycle(&mut d, ENABLED);
    }
    assert!((d.position - here).abs() < 1.0, "no set point left");
    // CSP after homing: the target sent in the reported coordinates.
    d.od.set(0x6060, 0, &[MODE_CSP as u8]);
    let at = d.od.i32(0x6064, 0);
    target(&mut d, at);
    cycle(&mut d, ENABLED);
    assert_eq!(d.od.i8(0x6061, 0), MODE_CSP);
    assert!((f64::from(d.od.i32(0x6064, 0)) - f64::from(at)).abs() <= 1.0);
}
