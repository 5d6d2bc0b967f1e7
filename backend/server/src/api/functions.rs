//! Function FBs that compute values and touch no axis (`/api/v1/functions/…`).

use axum::Json;
use serde::Deserialize;
use utoipa::IntoParams;

use super::Q;
use crate::error::{AppError, AppResult};
use motion::functions::{RampDynamics, calc_dynamics_by_ramp_time};

/// MC_CalcDynamicsByRampTime's inputs.
#[derive(Debug, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
#[serde(deny_unknown_fields)]
pub struct RampQuery {
    /// Velocity to reach (> 0), units/s.
    #[param(minimum = 1e-9, maximum = 1e12)]
    pub velocity: f64,
    /// Time to reach it from rest (> 0), s.
    #[param(minimum = 1e-6, maximum = 1e6)]
    pub ramp_time: f64,
    /// 0 (pure S-curve) to below 1 (nearly a trapezoid); default 0.5 (t1 = t2 = t/3).
    #[param(minimum = 0, exclusive_maximum = 1)]
    pub stiffness: Option<f64>,
}

#[utoipa::path(get, path = "/api/v1/functions/calc-dynamics-by-ramp-time", tag = "commands",
    summary = "MC_CalcDynamicsByRampTime: acceleration (= deceleration) and jerk that reach a velocity in a ramp time",
    description = "Ramp time t = 2·t1 + t2 (t1 each jerk phase, t2 constant acceleration) with t2/t1 = s/(1−s) for \
stiffness s: 0 gives a pure S-curve (t1 = t/2), 0.5 gives t1 = t2 = t/3, near 1 a trapezoid. Assumes the velocity is \
reached (on a short distance it is not). The results go into any move's `acceleration`, `deceleration` and `jerk`.",
    params(RampQuery),
    responses((status = 200, body = RampDynamics), super::errors::FunctionErrors))]
pub async fn calc_dynamics_by_ramp_time_fb(Q(q): Q<RampQuery>) -> AppResult<Json<RampDynamics>> {
    let stiffness = q.stiffness.unwrap_or(0.5);
    let bad = |field: &'static str, message: &str| {
        AppError::refused(
            field,
            motion::ErrorId::PARAMETER_NOT_CORRECT,
            message.to_owned(),
        )
    };
    if !(q.velocity.is_finite() && (1e-9..=1e12).contains(&q.velocity)) {
        return Err(bad("velocity", "must be from 1e-9 to 1e12"));
    }
    if !(q.ramp_time.is_finite() && (1e-6..=1e6).contains(&q.ramp_time)) {
        return Err(bad("ramp_time", "must be from 1e-6 to 1e6 s"));
    }
    if !(0.0..1.0).contains(&stiffness) {
        return Err(bad(
            "stiffness",
            "must be from 0 to below 1 (1 would need an infinite jerk)",
        ));
    }
    calc_dynamics_by_ramp_time(q.velocity, q.ramp_time, stiffness)
        .map(Json)
        .map_err(|id| bad("velocity", id.text()))
}
