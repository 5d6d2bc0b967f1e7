//! Function FBs of Tc2_MC2 that compute values and touch no axis (spec §4.5).

use serde::Serialize;

use crate::ErrorId;

/// MC_CalcDynamicsByRampTime's outputs.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[cfg_attr(feature = "schema", schema(example = json!({"acceleration": 666.6666666666666,
    "deceleration": 666.6666666666666, "jerk": 6666.666666666666, "jerk_time": 0.1, "constant_acceleration_time": 0.1})))]
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct RampDynamics {
    pub acceleration: f64,
    /// Equal to the acceleration (the manual: the ramp is computed once and used both ways).
    pub deceleration: f64,
    pub jerk: f64,
    /// t1: each jerk phase of the ramp.
    pub jerk_time: f64,
    /// t2: the constant-acceleration phase (ramp time = 2·t1 + t2).
    pub constant_acceleration_time: f64,
}

/// MC_CalcDynamicsByRampTime (§4.5.3): the acceleration (= deceleration) and jerk that reach
/// `velocity` from rest in `ramp_time`, with `stiffness` in [0, 1) setting how much of the
/// ramp is constant acceleration: t2/t1 = s/(1−s), so 0 is a pure S-curve (t1 = t/2, t2 = 0),
/// 0.5 gives t1 = t2 = t/3 and near 1 a trapezoid (the manual's three examples). Stiffness 1
/// would need an infinite jerk and is refused, as are a velocity or ramp time not > 0.
pub fn calc_dynamics_by_ramp_time(
    velocity: f64,
    ramp_time: f64,
    stiffness: f64,
) -> Result<RampDynamics, ErrorId> {
    let finite_positive = |x: f64| x.is_finite() && x > 0.0;
    if !(finite_positive(velocity) && finite_positive(ramp_time) && (0.0..1.0).contains(&stiffness))
    {
        return Err(ErrorId::PARAMETER_NOT_CORRECT);
    }
    let t1 = ramp_time * (1.0 - stiffness) / (2.0 - stiffness);
    let t2 = ramp_time * stiffness / (2.0 - stiffness);
    let acceleration = velocity / (t1 + t2);
    Ok(RampDynamics {
        acceleration,
        deceleration: acceleration,
        jerk: acceleration / t1,
        jerk_time: t1,
        constant_acceleration_time: t2,
    })
}

/// MC_OverrideFilter's filtering (§4.5.4) without its quiet time: `raw` clamped to
/// [lower, upper] and quantised down into `steps` equal steps of 100 % (200 steps = 0.5 %),
/// so that the upper threshold gives 100 % and anything below the first step 0 %. Refused
/// (0x4B06) when steps ≤ 1 or lower ≥ upper, as the manual says, or for numbers that are not
/// finite. Returns the override in percent.
pub fn override_filter(raw: f64, lower: f64, upper: f64, steps: u32) -> Result<f64, ErrorId> {
    if steps <= 1 || !(raw.is_finite() && lower.is_finite() && upper.is_finite()) || lower >= upper
    {
        return Err(ErrorId::PARAMETER_NOT_CORRECT);
    }
    let share = (raw.clamp(lower, upper) - lower) / (upper - lower);
    // The tiny allowance keeps a raw value that is exactly on a step on it despite rounding.
    let step = (share * steps as f64 + 1e-9).floor().min(steps as f64);
    Ok(step * 100.0 / steps as f64)
}

/// MC_ConvertIncPosToPos (§4.5.13): the axis position of encoder count `inc_pos`, from the
/// axis's latest status — its raw count and actual position — counting the difference on the
/// counter of `mask` (#1043) the short way round (past and future overflows are not
/// considered, as the manual says) and scaling it with the encoder scaling now.
pub fn convert_inc_pos_to_pos(status: &crate::AxisStatus, inc_pos: u32, mask: u32) -> f64 {
    status.actual_position
        + count_difference(inc_pos, status.encoder_count, mask) as f64
            * status.encoder_scaling_factor
}

/// MC_ConvertPosToIncPos (§4.5.14): the encoder count of axis position `position`; refused
/// (0x70B3) when the position is so far from the actual one that the counter of `mask` would
/// overflow on the way (half its range or more), or is not a number.
pub fn convert_pos_to_inc_pos(
    status: &crate::AxisStatus,
    position: f64,
    mask: u32,
) -> Result<u32, ErrorId> {
    let period = mask as f64 + 1.0;
    let delta = ((position - status.actual_position) / status.encoder_scaling_factor).round();
    if !delta.is_finite() || delta.abs() >= period / 2.0 {
        return Err(ErrorId::POSITION_OUT_OF_COUNTER_RANGE);
    }
    let count = (status.encoder_count as f64 + delta).rem_euclid(period);
    Ok(count as u32 & mask)
}

/// `to − from` on a counter of `mask + 1` values, in [−range/2, range/2).
fn count_difference(to: u32, from: u32, mask: u32) -> i64 {
    let period = mask as i64 + 1;
    let d = ((to & mask) as i64 - (from & mask) as i64).rem_euclid(period);
    if d >= period / 2 { d - period } else { d }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The manual's examples: stiffness 0 → t1 = t/2, t2 = 0; 0.5 → t1 = t2 = t/3; 0.99 →
    /// t1 ≈ 0, t2 ≈ t. Integrating the profile reaches the velocity at the ramp time.
    #[test]
    fn the_manuals_three_stiffnesses() {
        for (s, t1, t2) in [
            (0.0, 0.5, 0.0),
            (0.5, 1.0 / 3.0, 1.0 / 3.0),
            (0.99, 0.0099, 0.9802),
        ] {
            let d = calc_dynamics_by_ramp_time(300.0, 1.0, s).unwrap();
            assert!((d.jerk_time - t1).abs() < 1e-4, "{s}: {d:?}");
            assert!(
                (d.constant_acceleration_time - t2).abs() < 1e-4,
                "{s}: {d:?}"
            );
            assert_eq!(d.deceleration, d.acceleration);
            // v(t) = jerk·t1² (both jerk phases) + a·t2.
            let v =
                d.jerk * d.jerk_time * d.jerk_time + d.acceleration * d.constant_acceleration_time;
            assert!((v - 300.0).abs() < 1e-9, "{s}: reaches {v}");
            assert!((2.0 * d.jerk_time + d.constant_acceleration_time - 1.0).abs() < 1e-12);
        }
        assert_eq!(
            calc_dynamics_by_ramp_time(300.0, 1.0, 1.0),
            Err(ErrorId::PARAMETER_NOT_CORRECT)
        );
        assert!(calc_dynamics_by_ramp_time(0.0, 1.0, 0.5).is_err());
        assert!(calc_dynamics_by_ramp_time(10.0, 0.0, 0.5).is_err());
    }

    /// §4.5.4: the defaults (0…32767 digits, 200 steps) give 0.5 % steps; the raw value is
    /// clamped to the thresholds; steps ≤ 1 and lower ≥ upper are refused.
    #[test]
    fn override_filter_clamps_and_quantises() {
        assert_eq!(override_filter(32767.0, 0.0, 32767.0, 200), Ok(100.0));
        assert_eq!(override_filter(40000.0, 0.0, 32767.0, 200), Ok(100.0));
        assert_eq!(override_filter(-5.0, 0.0, 32767.0, 200), Ok(0.0));
        // One step is 163.835 digits: just below it is 0 %, on it 0.5 %.
        assert_eq!(override_filter(163.0, 0.0, 32767.0, 200), Ok(0.0));
        assert_eq!(override_filter(163.835, 0.0, 32767.0, 200), Ok(0.5));
        assert_eq!(override_filter(16383.5, 0.0, 32767.0, 200), Ok(50.0));
        assert_eq!(override_filter(7.5, 5.0, 10.0, 4), Ok(50.0));
        for (steps, lower, upper) in [
            (1, 0.0, 10.0),
            (0, 0.0, 10.0),
            (200, 10.0, 10.0),
            (200, 11.0, 10.0),
        ] {
            assert_eq!(
                override_filter(5.0, lower, upper, steps),
                Err(ErrorId::PARAMETER_NOT_CORRECT)
            );
        }
        assert!(override_filter(f64::NAN, 0.0, 10.0, 200).is_err());
    }

    /// §4.5.13/14: positions from counts and back, relative to the present count, across the
    /// counter's wrap; a position half the counter away or more is refused.
    #[test]
    fn inc_pos_conversions_count_from_the_present_count_the_short_way() {
        let st = crate::AxisStatus {
            actual_position: 100.0,
            encoder_count: 4_294_967_290,
            encoder_scaling_factor: 0.001,
            ..Default::default()
        };
        let mask = u32::MAX;
        assert_eq!(convert_inc_pos_to_pos(&st, 4_294_967_290, mask), 100.0);
        // 10 counts further, across the wrap: +0.01.
        assert!((convert_inc_pos_to_pos(&st, 4, mask) - 100.01).abs() < 1e-9);
        assert!((convert_inc_pos_to_pos(&st, 4_294_967_280, mask) - 99.99).abs() < 1e-9);
        assert_eq!(convert_pos_to_inc_pos(&st, 100.01, mask), Ok(4));
        assert_eq!(convert_pos_to_inc_pos(&st, 99.99, mask), Ok(4_294_967_280));
        for inc in [0u32, 17, 4_294_967_295, 2_000_000_000] {
            let p = convert_inc_pos_to_pos(&st, inc, mask);
            assert_eq!(convert_pos_to_inc_pos(&st, p, mask), Ok(inc), "{inc}");
        }
        // 16-bit counter: 40000 counts away is more than half of it.
        let st16 = crate::AxisStatus {
            encoder_count: 100,
            ..st
        };
        assert_eq!(
            convert_pos_to_inc_pos(&st16, 100.0 + 40.0, 0xFFFF),
            Err(ErrorId::POSITION_OUT_OF_COUNTER_RANGE)
        );
        assert_eq!(
            convert_pos_to_inc_pos(&st16, 100.0 + 30.0, 0xFFFF),
            Ok(30_100)
        );
        assert!((convert_inc_pos_to_pos(&st16, 65_535, 0xFFFF) - 99.899).abs() < 1e-9);
        assert!(convert_pos_to_inc_pos(&st, f64::NAN, mask).is_err());
    }
}
