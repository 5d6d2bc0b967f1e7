//! Commands: a function block's body checked and turned into a kernel command, submitted to
//! the cycle thread, tracked, waited for, released, renewed. REST and websocket both come here
//! (through the catalogue, `api::blocks`), so a rule holds whatever the transport.

use std::collections::VecDeque;
use std::time::Duration;

use motion::{
    AxisSlot, CommandId, CommandKind, Direction, ErrorId, FbOutputs, JogMode, Positioning,
    Superposition,
};

use crate::app::{AppState, AxisEntry, CommandRecord, HISTORY, Registry};
use crate::error::FieldError;
use crate::error::{AppError, AppResult};
use crate::metrics::Verdict;
use crate::model::*;
use crate::store::{self, AuditEntry};

/// Collects invalid fields of a command body.
#[derive(Default)]
pub struct Check(Vec<FieldError>);

impl Check {
    fn fail(&mut self, field: &str, message: &str) {
        self.0.push(FieldError {
            field: field.into(),
            message: message.into(),
        });
    }
    /// A position, distance, offset or end velocity: within ±1e12 (beyond it an f64 position
    /// has no useful resolution, and sums of such inputs could overflow to infinity).
    fn finite(&mut self, field: &str, v: f64) {
        if !(v.is_finite() && v.abs() <= crate::model::MAX_MAGNITUDE) {
            self.fail(field, "must be a number from -1e12 to 1e12");
        }
    }
    fn scaling(&mut self, field: &str, v: f64) {
        if !crate::model::valid_scaling(v) {
            self.fail(
                field,
                "must be a number other than 0, from 1e-9 to 1e12 in magnitude",
            );
        }
    }
    fn positive(&mut self, field: &str, v: f64) {
        if !(v.is_finite() && v > 0.0) {
            self.fail(field, "must be > 0");
        }
    }
    fn non_negative(&mut self, field: &str, v: f64) {
        if !(v.is_finite() && v >= 0.0) {
            self.fail(field, "must be ≥ 0 (0 = axis default)");
        }
    }
    /// A cam block's offsets and activation position (finite) and scalings (finite, not 0).
    /// A coupling's own interpolation of a position table (4POINT is no longer supported).
    fn interpolation(&mut self, i: Option<motion::cam::InterpolationType>) {
        if i == Some(motion::cam::InterpolationType::FourPoint) {
            self.fail(
                "interpolation",
                "4-point interpolation is no longer supported (as in TwinCAT); use linear, spline or sliding_spline",
            );
        }
    }
    fn cam_coupling(&mut self, [mo, so, position]: [f64; 3], [ms, ss]: [f64; 2]) {
        self.finite("master_offset", mo);
        self.finite("slave_offset", so);
        self.finite("activation_position", position);
        self.scaling("master_scaling", ms);
        self.scaling("slave_scaling", ss);
    }
    fn options(&mut self, o: &motion::MoveOptions) {
        if let Some(b) = o.blending_position {
            self.finite("options.blending_position", b);
        }
    }
    fn done<T>(self, t: T) -> AppResult<T> {
        if self.0.is_empty() {
            Ok(t)
        } else {
            Err(AppError::invalid(self.0))
        }
    }
}

impl PowerBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        if !(self.override_percent.is_finite() && (0.0..=100.0).contains(&self.override_percent)) {
            c.fail("override_percent", "must be between 0 and 100");
        }
        c.done(CommandKind::Power {
            enable: self.enable,
            enable_positive: self.enable_positive,
            enable_negative: self.enable_negative,
            override_percent: self.override_percent,
            buffer_mode: self.buffer_mode.unwrap_or_default(),
        })
    }
}

impl SetPositionBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        c.finite("position", self.position);
        c.done(CommandKind::SetPosition {
            position: self.position,
            relative: self.relative,
            clear_position_lag: self.clear_position_lag,
            clear_position_offset: self.clear_position_offset,
        })
    }
}

impl SetOverrideBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        if !(self.velocity_factor.is_finite() && (0.0..=1.0).contains(&self.velocity_factor)) {
            c.fail("velocity_factor", "must be between 0 and 1");
        }
        for (field, f) in [
            ("acceleration_factor", self.acceleration_factor),
            ("jerk_factor", self.jerk_factor),
        ] {
            if !(f.is_finite() && f > 0.0 && f <= 1.0) {
                c.fail(field, "must be above 0 and at most 1");
            }
        }
        c.done(CommandKind::SetOverride {
            velocity_factor: self.velocity_factor,
            acceleration_factor: self.acceleration_factor,
            jerk_factor: self.jerk_factor,
        })
    }
}

impl OverrideFilterBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        c.finite("raw", self.raw);
        c.finite("lower_threshold", self.lower_threshold);
        c.finite("upper_threshold", self.upper_threshold);
        if self.upper_threshold <= self.lower_threshold {
            c.fail("upper_threshold", "must be above lower_threshold");
        }
        if !(2..=1_000_000).contains(&self.steps) {
            c.fail("steps", "must be from 2 to 1000000");
        }
        if !(self.recovery_time.is_finite() && (0.0..=3600.0).contains(&self.recovery_time)) {
            c.fail("recovery_time", "must be between 0 and 3600 s");
        }
        c.done(CommandKind::OverrideFilter {
            raw: self.raw,
            lower_threshold: self.lower_threshold,
            upper_threshold: self.upper_threshold,
            steps: self.steps,
            recovery_time: self.recovery_time,
        })
    }
}

/// The inputs every positioning block shares, checked, as the kernel's `Positioning`
/// (`field`: the body's name of the target or distance; the kernel calls both `position`).
fn positioning(
    c: &mut Check,
    (field, position): (&str, f64),
    velocity: f64,
    (acceleration, deceleration, jerk): (f64, f64, f64),
    buffer_mode: motion::BufferMode,
    options: motion::MoveOptions,
) -> Positioning {
    c.finite(field, position);
    c.positive("velocity", velocity);
    c.non_negative("acceleration", acceleration);
    c.non_negative("deceleration", deceleration);
    c.non_negative("jerk", jerk);
    c.options(&options);
    Positioning {
        position,
        velocity,
        dynamics: dynamics(acceleration, deceleration, jerk),
        buffer_mode,
        options,
    }
}

/// `positioning` for the bodies of the positioning blocks; `$target` is the body's name of its
/// target or distance.
macro_rules! positioning_inputs {
    ($($body:ty => $target:ident),+ $(,)?) => {$(
        impl $body {
            fn positioning(&self, c: &mut Check) -> Positioning {
                positioning(
                    c,
                    (stringify!($target), self.$target),
                    self.velocity,
                    (self.acceleration, self.deceleration, self.jerk),
                    self.buffer_mode,
                    self.options,
                )
            }
        }
    )+};
}

positioning_inputs! {
    MoveBody => position,
    MoveModuloBody => position,
    MoveRelativeBody => distance,
    MoveContinuousBody => position,
    MoveContinuousRelativeBody => distance,
}

impl MoveBody {
    /// MC_MoveAbsolute.
    pub fn absolute(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let p = self.positioning(&mut c);
        c.done(CommandKind::MoveAbsolute(p))
    }
}

impl MoveModuloBody {
    /// MC_MoveModulo: only on a modulo axis, with a target within one turn's range.
    pub fn modulo(&self, _: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let p = self.positioning(&mut c);
        if axis.config.modulo.is_none() {
            c.fail("axis", "move-modulo needs a modulo axis");
        }
        if self.position < 0.0 {
            c.fail("position", "a modulo target must be ≥ 0");
        }
        c.done(CommandKind::MoveModulo {
            move_: p,
            direction: self.direction.unwrap_or(Direction::Positive),
        })
    }
}

impl MoveRelativeBody {
    /// MC_MoveRelative: `distance` from the set position.
    pub fn relative(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let p = self.positioning(&mut c);
        c.done(CommandKind::MoveRelative(p))
    }

    /// MC_MoveAdditive: `distance` added to the running target.
    pub fn additive(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let p = self.positioning(&mut c);
        c.done(CommandKind::MoveAdditive(p))
    }
}

impl MoveContinuousRelativeBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let move_ = self.positioning(&mut c);
        c.finite("end_velocity", self.end_velocity);
        c.done(CommandKind::MoveContinuousRelative {
            move_,
            end_velocity: self.end_velocity,
        })
    }
}

impl MoveContinuousBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let move_ = self.positioning(&mut c);
        c.finite("end_velocity", self.end_velocity);
        c.done(CommandKind::MoveContinuousAbsolute {
            move_,
            end_velocity: self.end_velocity,
        })
    }
}

impl MoveVelocityBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        c.positive("velocity", self.velocity);
        c.non_negative("acceleration", self.acceleration);
        c.non_negative("deceleration", self.deceleration);
        c.non_negative("jerk", self.jerk);
        c.options(&self.options);
        c.done(CommandKind::MoveVelocity {
            velocity: self.velocity,
            dynamics: dynamics(self.acceleration, self.deceleration, self.jerk),
            direction: self.direction,
            buffer_mode: self.buffer_mode,
            options: self.options,
        })
    }
}

impl HaltBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        c.non_negative("deceleration", self.deceleration);
        c.non_negative("jerk", self.jerk);
        c.options(&self.options);
        c.done(CommandKind::Halt {
            deceleration: self.deceleration,
            jerk: self.jerk,
            buffer_mode: self.buffer_mode,
            options: self.options,
        })
    }
}

impl StopBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        c.non_negative("deceleration", self.deceleration);
        c.non_negative("jerk", self.jerk);
        c.options(&self.options);
        c.done(CommandKind::Stop {
            deceleration: self.deceleration,
            jerk: self.jerk,
            options: self.options,
        })
    }
}

impl JogBody {
    pub fn to_kind(&self, _: &Registry, e: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        // Bounded by the engineer's maximum for this axis: a client that vanishes mid-jog
        // costs at most that long at jog speed.
        let max = e.config.dynamics.jog_deadman_max;
        if !(self.deadman_timeout.is_finite() && (0.05..=max).contains(&self.deadman_timeout)) {
            c.fail(
                "deadman_timeout",
                &format!("must be between 0.05 and {max} s (the axis's dynamics.jog_deadman_max)"),
            );
        }
        c.non_negative("velocity", self.velocity);
        c.non_negative("acceleration", self.acceleration);
        c.non_negative("deceleration", self.deceleration);
        c.non_negative("jerk", self.jerk);
        c.non_negative("position", self.position);
        match self.mode {
            JogMode::Continuous if self.velocity <= 0.0 => {
                c.fail("velocity", "continuous jog needs a velocity > 0")
            }
            JogMode::Inching | JogMode::InchingModulo if self.position <= 0.0 => {
                c.fail("position", "inching needs a distance > 0")
            }
            _ => {}
        }
        c.done(CommandKind::Jog {
            mode: self.mode,
            forward: self.direction == JogDirection::Forward,
            position: self.position,
            velocity: self.velocity,
            dynamics: dynamics(self.acceleration, self.deceleration, self.jerk),
            deadman: self.deadman_timeout,
        })
    }
}

impl HomeBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        if let Some(p) = self.position {
            c.finite("position", p);
        }
        for (f, v) in [
            ("options.search_velocity", self.options.search_velocity),
            ("options.sync_velocity", self.options.sync_velocity),
        ] {
            if let Some(v) = v {
                c.positive(f, v);
            }
        }
        c.done(CommandKind::Home {
            position: self.position,
            mode: self.mode,
            options: self.options,
        })
    }
}

/// The master of a coupling: an axis other than the slave.
fn master_slot(c: &mut Check, reg: &Registry, axis: &AxisEntry, master: &str) -> AxisSlot {
    match reg.find(master) {
        None => {
            c.fail("master", "no such axis");
            0
        }
        Some(m) if m.id == axis.id => {
            c.fail("master", "an axis cannot be its own master");
            0
        }
        Some(m) => m.slot,
    }
}

impl GearInBody {
    pub fn to_kind(&self, reg: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let master = master_slot(&mut c, reg, axis, &self.master);
        c.scaling("ratio_numerator", self.ratio_numerator);
        if self.ratio_denominator == 0 {
            c.fail("ratio_denominator", "must be ≥ 1");
        }
        c.done(CommandKind::GearIn {
            master,
            ratio_numerator: self.ratio_numerator,
            ratio_denominator: self.ratio_denominator,
        })
    }
}

impl ExtSetPointGenEnableBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        if let Some(p) = self.position {
            c.finite("position", p);
        }
        if !(self.feed_timeout.is_finite() && self.feed_timeout > 0.0 && self.feed_timeout <= 10.0)
        {
            c.fail("feed_timeout", "must be above 0 and at most 10 s");
        }
        c.done(CommandKind::ExtSetPointGenEnable {
            target: self.position,
            relative: self.position_type == PositionType::Relative,
            timeout: self.feed_timeout,
        })
    }
}

/// MC_ExtSetPointGenFeed: checked, admitted like a motion command (control), handed to the
/// kernel without a command record (a stream of them at up to the cycle rate); the cycle it
/// takes effect in.
pub async fn ext_feed(
    s: &AppState,
    axis: &str,
    body: &ExtSetPointFeedBody,
    client: &ClientInfo,
) -> AppResult<u64> {
    let (slot, vmax) = {
        let reg = s.registry.read().unwrap();
        let e = reg
            .find(axis)
            .ok_or_else(|| AppError::not_found("axis", axis))?;
        (e.slot, e.params.axis_velo_max)
    };
    let mut c = Check::default();
    c.finite("position", body.position);
    c.finite("acceleration", body.acceleration);
    if !(body.velocity.is_finite() && body.velocity.abs() <= vmax) {
        c.fail("velocity", &format!("must be within ±{vmax} (AxisVeloMax)"));
    }
    let sign = |v: f64| {
        if v > 0.0 {
            1
        } else if v < 0.0 {
            -1
        } else {
            0
        }
    };
    let direction = body.direction.unwrap_or(sign(body.velocity));
    if ![-1, 0, 1].contains(&direction) {
        c.fail("direction", "must be -1, 0 or 1");
    } else if direction != sign(body.velocity) && body.velocity != 0.0 {
        c.fail("direction", "must be the velocity's sign");
    } else if direction == 0 && body.velocity != 0.0 {
        c.fail("direction", "0 means standstill: the velocity must be 0");
    }
    let kind = c.done(CommandKind::ExtSetPointGenFeed {
        position: body.position,
        velocity: body.velocity,
        acceleration: body.acceleration,
        direction,
    })?;
    s.control.admit(client, &kind)?;
    s.kernel_command(slot, kind).await
}

impl TorqueControlBody {
    pub fn to_kind(&self, _: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let bounded = |x: f64, m: f64| x.is_finite() && x.abs() <= m;
        if !bounded(self.torque, 1000.0) {
            c.fail("torque", "must be from -1000 to 1000 %");
        }
        c.positive("torque_ramp", self.torque_ramp);
        let vmax = axis.params.axis_velo_max;
        for (field, v) in [
            ("velocity_limit_high", self.velocity_limit_high),
            ("velocity_limit_low", self.velocity_limit_low),
        ] {
            if !bounded(v, vmax) {
                c.fail(field, &format!("must be within ±{vmax} (AxisVeloMax)"));
            }
        }
        if self.velocity_limit_low > self.velocity_limit_high {
            c.fail("velocity_limit_low", "must not exceed velocity_limit_high");
        }
        if let Some(t) = self.manual_start_torque {
            if !bounded(t, 1000.0) {
                c.fail("manual_start_torque", "must be from -1000 to 1000 %");
            }
        }
        c.done(CommandKind::TorqueControl(motion::TorqueControl {
            torque: self.torque,
            torque_ramp: self.torque_ramp,
            relative: self.relative,
            velocity_limit_high: self.velocity_limit_high,
            velocity_limit_low: self.velocity_limit_low,
            manual_start: self.manual_start_torque,
        }))
    }
}

impl WriteDriveOperationModeBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        Ok(CommandKind::WriteDriveOperationMode {
            mode: self.drive_operation_mode,
        })
    }
}

impl SelectControlLoopBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        if self.encoder_index > 9 {
            c.fail("encoder_index", "must be from 0 to 9");
        }
        c.done(CommandKind::SelectControlLoop {
            index: self.encoder_index,
        })
    }
}

impl SetEncoderScalingFactorBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        if !(self.scaling_factor.is_finite() && (1e-12..=1e12).contains(&self.scaling_factor)) {
            c.fail("scaling_factor", "must be a number from 1e-12 to 1e12");
        }
        c.done(CommandKind::SetEncoderScalingFactor {
            factor: self.scaling_factor,
            relative: self.mode == EncoderScalingMode::Relative,
        })
    }
}

impl PositionCorrectionLimiterBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        if !(self.value.is_finite() && self.value.abs() <= 1e9) {
            c.fail("value", "must be a number from -1e9 to 1e9");
        }
        c.non_negative("acceleration", self.acceleration);
        if self.mode == motion::PositionCorrectionMode::FullLength {
            c.positive("correction_length", self.correction_length);
        } else {
            c.non_negative("correction_length", self.correction_length);
        }
        c.done(CommandKind::PositionCorrectionLimiter {
            value: self.value,
            mode: self.mode,
            acceleration: self.acceleration,
            correction_length: self.correction_length,
        })
    }
}

impl BacklashCompensationBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        if let Some(b) = self.backlash {
            if !(b.is_finite() && b.abs() <= 1e6) {
                c.fail("backlash", "must be a number from -1e6 to 1e6");
            }
        }
        c.positive("ramp", self.ramp);
        c.done(CommandKind::BacklashCompensation {
            backlash: self.backlash,
            compensate_in_positive_direction: self.compensate_in_positive_direction,
            ramp: self.ramp,
            disable_mode: self.disable_mode,
        })
    }
}

impl TableCompensationBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        c.positive("ramp", self.ramp);
        c.done(CommandKind::TableBasedPositionCompensation {
            ramp: self.ramp,
            disable_mode: self.disable_mode,
        })
    }
}

impl PhasingBody {
    fn to_phasing(
        &self,
        reg: &Registry,
        axis: &AxisEntry,
        kind: motion::PhasingKind,
    ) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let master = master_slot(&mut c, reg, axis, &self.master);
        c.finite("phase_shift", self.phase_shift);
        if !(self.velocity.is_finite() && self.velocity >= 0.01) {
            c.fail("velocity", "must be ≥ 0.01");
        }
        c.non_negative("acceleration", self.acceleration);
        c.non_negative("deceleration", self.deceleration);
        c.non_negative("jerk", self.jerk);
        c.done(CommandKind::Phasing {
            master,
            motion: motion::PhasingMotion {
                kind,
                phase_shift: self.phase_shift,
                velocity: self.velocity,
                acceleration: self.acceleration,
                deceleration: self.deceleration,
                jerk: self.jerk,
            },
        })
    }
    pub fn absolute(&self, reg: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        self.to_phasing(reg, axis, motion::PhasingKind::Absolute)
    }
    pub fn relative(&self, reg: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        self.to_phasing(reg, axis, motion::PhasingKind::Relative)
    }
}

impl HaltPhasingBody {
    pub fn to_kind(&self, reg: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let master = master_slot(&mut c, reg, axis, &self.master);
        c.non_negative("deceleration", self.deceleration);
        c.non_negative("jerk", self.jerk);
        c.done(CommandKind::Phasing {
            master,
            motion: motion::PhasingMotion {
                kind: motion::PhasingKind::Halt,
                phase_shift: 0.0,
                velocity: 0.0,
                acceleration: 0.0,
                deceleration: self.deceleration,
                jerk: self.jerk,
            },
        })
    }
}

impl GearInMultiMasterBody {
    pub fn to_kind(&self, reg: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        if self.masters.is_empty() || self.masters.len() > 4 {
            c.fail("masters", "must name 1 to 4 masters");
        }
        let mut masters = [None; 4];
        let mut ratios = [0.0; 4];
        for (i, m) in self.masters.iter().take(4).enumerate() {
            let mut one = Check::default();
            let slot = master_slot(&mut one, reg, axis, &m.master);
            for e in one.0 {
                c.fail(&format!("masters[{i}].{}", e.field), &e.message);
            }
            if masters[..i].contains(&Some(slot)) {
                c.fail(&format!("masters[{i}].master"), "names a master twice");
            }
            masters[i] = Some(slot);
            if !(m.gear_ratio.is_finite() && m.gear_ratio.abs() <= MAX_MAGNITUDE) {
                c.fail(
                    &format!("masters[{i}].gear_ratio"),
                    "must be a number from -1e12 to 1e12",
                );
            }
            ratios[i] = m.gear_ratio;
        }
        c.non_negative("acceleration", self.acceleration);
        c.non_negative("deceleration", self.deceleration);
        c.non_negative("jerk", self.jerk);
        c.done(CommandKind::GearInMultiMaster(motion::GearInMultiMaster {
            masters,
            ratios,
            acceleration: self.acceleration,
            deceleration: self.deceleration,
            jerk: self.jerk,
            advanced_slave_dynamics: self.advanced_slave_dynamics,
            sync_mode: self.sync_mode,
        }))
    }
}

impl GearInDynBody {
    pub fn to_kind(&self, reg: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let master = master_slot(&mut c, reg, axis, &self.master);
        c.finite("gear_ratio", self.gear_ratio);
        c.non_negative("acceleration", self.acceleration);
        c.done(CommandKind::GearInDyn {
            master,
            gear_ratio: self.gear_ratio,
            acceleration: self.acceleration,
        })
    }
}

/// A cam table by id or name, as the kernel knows it (its id).
fn cam_table_id(c: &mut Check, reg: &Registry, key: &str) -> u32 {
    match reg.find_cam(key) {
        Some(t) => t.id,
        None => {
            c.fail("cam_table", "no such cam table");
            0
        }
    }
}

impl CamInBody {
    pub fn to_kind(&self, reg: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let master = master_slot(&mut c, reg, axis, &self.master);
        let cam_table = cam_table_id(&mut c, reg, &self.cam_table);
        c.cam_coupling(
            [
                self.master_offset,
                self.slave_offset,
                self.activation_position,
            ],
            [self.master_scaling, self.slave_scaling],
        );
        c.interpolation(self.interpolation);
        let ramp_in = self.ramp_in.unwrap_or_default();
        if self.start_mode.ramp_in() {
            if !(ramp_in.velocity > 0.0 && ramp_in.velocity.is_finite()) {
                c.fail(
                    "ramp_in.velocity",
                    "a ramp-in start mode needs its velocity (> 0)",
                );
            }
            for (field, v) in [
                ("ramp_in.acceleration", ramp_in.acceleration),
                ("ramp_in.deceleration", ramp_in.deceleration),
                ("ramp_in.jerk", ramp_in.jerk),
            ] {
                if !(v >= 0.0 && v.is_finite()) {
                    c.fail(field, "must be a finite number ≥ 0 (0: the axis default)");
                }
            }
        } else if self.ramp_in.is_some() {
            c.fail("ramp_in", "only with a ramp_in start mode");
        }
        c.done(CommandKind::CamIn(motion::cam::CamIn {
            master,
            cam_table,
            master_offset: self.master_offset,
            slave_offset: self.slave_offset,
            master_scaling: self.master_scaling,
            slave_scaling: self.slave_scaling,
            start_mode: self.start_mode,
            activation_mode: self.activation_mode,
            activation_position: self.activation_position,
            master_scaling_mode: self.master_scaling_mode,
            slave_scaling_mode: self.slave_scaling_mode,
            interpolation: self.interpolation,
            ramp_in,
        }))
    }
}

/// A multi-cam operation (MC_CamIn_V2 and its convenience blocks).
#[allow(clippy::too_many_arguments)]
fn cam_in_v2(
    reg: &Registry,
    axis: &AxisEntry,
    master: &str,
    cam_table: &str,
    reference: Option<&str>,
    activation: (motion::cam::CamActivationMode, f64),
    scaling: motion::cam::CamScalingData,
    operation: motion::cam::CamOperationMode,
    interpolation: Option<motion::cam::InterpolationType>,
) -> AppResult<CommandKind> {
    let mut c = Check::default();
    let master = master_slot(&mut c, reg, axis, master);
    let cam_table = cam_table_id(&mut c, reg, cam_table);
    let reference_cam_table = match reference {
        None => 0,
        Some(r) => match reg.find_cam(r) {
            Some(t) => t.id,
            None => {
                c.fail("reference_cam_table", "no such cam table");
                0
            }
        },
    };
    c.cam_coupling(
        [scaling.master_offset, scaling.slave_offset, activation.1],
        [scaling.master_scaling, scaling.slave_scaling],
    );
    c.interpolation(interpolation);
    c.done(CommandKind::CamInV2(motion::cam::CamInV2 {
        master,
        cam_table,
        activation_mode: activation.0,
        activation_position: activation.1,
        scaling,
        operation,
        reference_cam_table,
        interpolation,
    }))
}

impl CamInV2Body {
    pub fn to_kind(&self, reg: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        cam_in_v2(
            reg,
            axis,
            &self.master,
            &self.cam_table,
            self.reference_cam_table.as_deref(),
            (self.activation_mode, self.activation_position),
            self.scaling,
            self.operation,
            self.interpolation,
        )
    }
}

impl CamAddBody {
    pub fn to_kind(&self, reg: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        cam_in_v2(
            reg,
            axis,
            &self.master,
            &self.cam_table,
            None,
            (self.activation_mode, self.activation_position),
            self.scaling,
            motion::cam::CamOperationMode::Additive,
            self.interpolation,
        )
    }
}

impl CamExchangeBody {
    pub fn to_kind(&self, reg: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        cam_in_v2(
            reg,
            axis,
            &self.master,
            &self.cam_table,
            self.reference_cam_table.as_deref(),
            (self.activation_mode, self.activation_position),
            self.scaling,
            motion::cam::CamOperationMode::Exchange,
            self.interpolation,
        )
    }
}

impl CamRemoveBody {
    pub fn to_kind(&self, reg: &Registry, axis: &AxisEntry) -> AppResult<CommandKind> {
        cam_in_v2(
            reg,
            axis,
            &self.master,
            &self.cam_table,
            None,
            (self.activation_mode, self.activation_position),
            motion::cam::CamScalingData::default(),
            motion::cam::CamOperationMode::Remove,
            None,
        )
    }
}

impl CamScalingV2Body {
    pub fn to_kind(&self, reg: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        let cam_table = match self.cam_table.as_deref() {
            None => 0,
            Some(t) => cam_table_id(&mut c, reg, t),
        };
        let d = self.scaling;
        c.cam_coupling(
            [d.master_offset, d.slave_offset, self.activation_position],
            [d.master_scaling, d.slave_scaling],
        );
        c.done(CommandKind::CamScalingV2(motion::cam::CamScalingV2 {
            cam_table,
            activation_mode: self.activation_mode,
            activation_position: self.activation_position,
            scaling: d,
        }))
    }
}

impl CamScalingBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        c.cam_coupling(
            [
                self.master_offset,
                self.slave_offset,
                self.activation_position,
            ],
            [self.master_scaling, self.slave_scaling],
        );
        c.done(CommandKind::CamScaling(motion::cam::CamScaling {
            activation_mode: self.activation_mode,
            activation_position: self.activation_position,
            master_scaling_mode: self.master_scaling_mode,
            slave_scaling_mode: self.slave_scaling_mode,
            master_offset: self.master_offset,
            slave_offset: self.slave_offset,
            master_scaling: self.master_scaling,
            slave_scaling: self.slave_scaling,
        }))
    }
}

impl TouchProbeBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        use motion::LatchSource as L;
        let mut c = Check::default();
        c.finite("first_position", self.first_position);
        c.finite("last_position", self.last_position);
        if self.window_only && !self.modulo_positions && self.first_position > self.last_position {
            c.fail(
                "last_position",
                "an absolute window needs first_position <= last_position (only a modulo window wraps)",
            );
        }
        let source = match (self.signal, self.edge) {
            (ProbeSignal::Input1, SignalEdge::Rising) => L::Input1Rising,
            (ProbeSignal::Input1, SignalEdge::Falling) => L::Input1Falling,
            (ProbeSignal::ReferenceCam, SignalEdge::Rising) => L::CamRising,
            (ProbeSignal::ReferenceCam, SignalEdge::Falling) => L::CamFalling,
            (ProbeSignal::IndexPulse, SignalEdge::Rising) => L::IndexPulse,
            (ProbeSignal::IndexPulse, SignalEdge::Falling) => {
                c.fail("edge", "the index pulse is latched on its rising edge only");
                L::IndexPulse
            }
        };
        c.done(CommandKind::TouchProbe(motion::TouchProbe {
            source,
            window_only: self.window_only,
            first_position: self.first_position,
            last_position: self.last_position,
            modulo_positions: self.modulo_positions,
        }))
    }
}

impl MoveSuperImposedBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        c.finite("distance", self.distance);
        c.positive("velocity_diff", self.velocity_diff);
        c.non_negative("acceleration", self.acceleration);
        c.non_negative("deceleration", self.deceleration);
        c.positive("velocity_process", self.velocity_process);
        c.positive("length", self.length);
        c.done(CommandKind::MoveSuperImposed(Superposition {
            mode: self.mode,
            distance: self.distance,
            velocity_diff: self.velocity_diff,
            acceleration: self.acceleration,
            deceleration: self.deceleration,
            velocity_process: self.velocity_process,
            length: self.length,
            abort_option: self.abort_option,
        }))
    }
}

/// Validates, submits and (optionally) waits: shared by all command endpoints and the websocket.
/// How a catalogue entry turns its body into a kernel command.
pub type ToKind<B> = fn(&B, &Registry, &AxisEntry) -> AppResult<CommandKind>;

/// A function block as the catalogue hands it over: its name, its milestone and its body's
/// conversion.
pub struct Submission<'a, B> {
    pub name: &'static str,
    pub milestone: Milestone,
    pub to_kind: ToKind<B>,
    pub axis: &'a str,
    pub body: B,
    /// The body as sent, kept with the command and in the audit log.
    pub raw: serde_json::Value,
    pub client: ClientInfo,
    /// The `Idempotency-Key` it was sent with (see `service::idempotency`).
    pub idempotency_key: Option<String>,
}

/// Checks, submits and (with `wait`) waits for a command: what every command endpoint and
/// websocket method does.
pub async fn run<B>(
    s: &AppState,
    sub: Submission<'_, B>,
    wait: Option<Duration>,
) -> AppResult<CommandResource> {
    let Submission {
        name,
        milestone,
        to_kind,
        axis,
        body,
        raw,
        client,
        idempotency_key,
    } = sub;
    let id = submit(
        s,
        axis,
        (name, milestone),
        (raw, idempotency_key),
        client,
        |reg, e| to_kind(&body, reg, e),
    )
    .await?;
    let view = match wait {
        Some(t) => wait_for(s, id, t).await.map(|mut v| {
            v.wait = Some(wait_outcome(s, &v, milestone));
            v
        }),
        None => get(s, id),
    };
    view.ok_or_else(|| {
        AppError::unavailable(
            "command_forgotten",
            "the command left the history before it could be shown",
        )
    })
}

/// `?wait=true&timeout_ms=N` as a duration to wait (`None`: answer at once). A timeout alone
/// is a client that means to wait.
pub fn wait_duration(wait: Option<bool>, timeout_ms: Option<u64>) -> AppResult<Option<Duration>> {
    match (wait, timeout_ms) {
        (_, Some(t)) if t > 600_000 => Err(AppError::field("timeout_ms", "at most 600000")),
        (Some(false), _) => Ok(None),
        (Some(true), t) | (None, t @ Some(_)) => {
            Ok(Some(Duration::from_millis(t.unwrap_or(10_000))))
        }
        (None, None) => Ok(None),
    }
}

/// Submits a tracked command. Returns its id once the cycle thread accepted it; a refusal is
/// audited and forgotten.
async fn submit(
    s: &AppState,
    axis_key: &str,
    (name, milestone): (&'static str, Milestone),
    (parameters, key): (serde_json::Value, Option<String>),
    client: ClientInfo,
    build: impl FnOnce(&Registry, &AxisEntry) -> AppResult<CommandKind>,
) -> AppResult<CommandId> {
    let (slot, axis_id, axis_name, kind) = {
        let reg = s.registry.read().unwrap();
        let invalid = |e| {
            s.metrics.command(name, Verdict::invalid);
            e
        };
        let e = reg
            .find(axis_key)
            .ok_or_else(|| invalid(AppError::not_found("axis", axis_key)))?;
        (
            e.slot,
            e.id,
            e.name.clone(),
            build(&reg, e).map_err(invalid)?,
        )
    };
    if let Some(e) = drive_lacks(s, axis_key, &kind) {
        s.metrics.command(name, Verdict::rejected);
        return Err(e);
    }
    // One holder commands motion at a time (stop, halt and disabling always pass).
    s.control.admit(&client, &kind).inspect_err(|_| {
        s.metrics.command(name, Verdict::rejected);
    })?;
    let id = s.next_id();
    if let Err(e) = s.reserve_id(id).await {
        // A stop is never refused (docs/decisions.md 116): its id comes from memory, unique in
        // this run (after a crash it may be handed out again — its audit row is lost anyway).
        if !crate::service::control::stops_motion(&kind) {
            return Err(e);
        }
        tracing::error!("command {id} ({name}) acts although its id could not be reserved: {e}");
    }
    let submitted_at = store::now_rfc3339();
    let audit = AuditEntry {
        at: submitted_at.clone(),
        client_addr: Some(client.addr.clone()),
        client_id: client.id.clone(),
        principal: client.principal.clone(),
        action: format!("command.{name}"),
        target: Some(axis_name.clone()),
        command_id: Some(id),
        detail: parameters.to_string(),
        outcome: None,
        idempotency_key: key.clone(),
    };
    s.commands.lock().unwrap().insert(CommandRecord {
        id,
        axis_id,
        axis_name,
        slot,
        name,
        milestone,
        parameters,
        client,
        submitted_at,
        accepted: false,
        accepted_cycle: 0,
        outputs: FbOutputs::default(),
        last_cycle: 0,
        finished_at: None,
        events: VecDeque::new(),
        final_audit: None,
        result: None,
    });
    // The submission row is stored while the cycle thread decides (both take about a tenth
    // of a millisecond; docs/decisions.md 71 and 79), so that no acknowledged command misses
    // it after a crash; its outcome (`submitted` until then) follows through the batching
    // writer, before the command's end row.
    let row = AuditEntry {
        outcome: Some("submitted".into()),
        ..audit
    };
    let (stored, reply) =
        tokio::join!(store::audit(&s.db, &row), s.command_request(id, slot, kind));
    let stored = match stored {
        Ok(()) => true,
        Err(e) => {
            tracing::error!("audit row of command {id} not stored: {e}");
            s.audit_dropped
                .fetch_add(1, std::sync::atomic::Ordering::Relaxed);
            false
        }
    };
    // The verdict as the audit log says it: as an update of the stored row, or a whole row.
    let outcome = |outcome: String| {
        if stored {
            s.audit_outcome(id, outcome);
        } else {
            s.audit(AuditEntry {
                outcome: Some(outcome),
                ..row.clone()
            });
        }
    };
    let reply = match reply {
        Ok(r) => r,
        Err(e) => {
            s.commands.lock().unwrap().remove(id);
            outcome(format!("failed:{}", e.problem().code));
            return Err(e);
        }
    };
    s.metrics.command(
        name,
        if reply.result.is_ok() {
            Verdict::accepted
        } else {
            Verdict::rejected
        },
    );
    match reply.result {
        Ok(()) => {
            // Accepted only now, so that the end row (queued by the pump once the command
            // counts as accepted and is final) comes after the outcome.
            outcome("accepted".into());
            if let CommandKind::SetEncoderScalingFactor { factor, .. } = kind {
                // The kernel recorded the factor in #1040; so does the server's mirror.
                if let Some(e) = s.registry_write().axes.get_mut(&axis_id) {
                    let _ = e.params.write(1040, factor);
                }
            }
            let final_audit = s.commands.lock().unwrap().map.get_mut(&id).and_then(|r| {
                r.accepted = true;
                r.accepted_cycle = reply.cycle;
                if r.finished_at.is_none() && r.is_final() {
                    r.finished_at = Some(store::now_rfc3339());
                }
                r.final_audit.take()
            });
            if let Some(e) = final_audit {
                s.audit(e);
            }
            Ok(id)
        }
        Err(e) => {
            s.commands.lock().unwrap().remove(id);
            outcome(format!("rejected:{}", e.code()));
            Err(match refusal_why(s, slot, e, reply.hint) {
                Some(why) => AppError::RejectedBecause { id: e, why },
                None => AppError::rejected(e),
            })
        }
    }
}

/// The CiA-402 objects a block needs in the drive's process image: the touch probe
/// (0x60B8 function, 0x60B9 status, 0x60BA position) for MC_TouchProbe and for homing that
/// latches the reference in the drive, the digital inputs (0x60FD: the reference cam) for
/// homing on the cam, the target torque (0x6071) for MC_TorqueControl.
fn objects_needed(kind: &CommandKind, reference_mode: u32) -> &'static [u16] {
    use motion::{HomingMode, ReferenceMode as R};
    const PROBE: &[u16] = &[0x60B8, 0x60B9, 0x60BA];
    const CAM_AND_PROBE: &[u16] = &[0x60FD, 0x60B8, 0x60B9, 0x60BA];
    match kind {
        CommandKind::TouchProbe(_) => PROBE,
        CommandKind::TorqueControl(_) => &[0x6071],
        CommandKind::Home {
            mode: HomingMode::Default,
            ..
        } => match R::from_number(reference_mode).unwrap_or_default() {
            R::PlcCam | R::SoftwareSync => &[0x60FD],
            R::SoftDriveLatchPos | R::SoftDriveLatchNeg => PROBE,
            R::Default | R::HardwareSync | R::HardwareLatchPos | R::HardwareLatchNeg => {
                CAM_AND_PROBE
            }
        },
        _ => &[],
    }
}

/// 409 `drive_object_missing` when the axis's CiA-402 drive lacks an object the block needs
/// in its process image (the drive's dictionary has no such object, or the mapping it took
/// left it out): never run half-broken (issue 22).
fn drive_lacks(s: &AppState, axis_key: &str, kind: &CommandKind) -> Option<AppError> {
    let (subdevice, reference_mode, axis) = {
        let reg = s.registry.read().unwrap();
        let e = reg.find(axis_key)?;
        let drives::DriveConfig::Cia402(c) = &e.config.drive else {
            return None;
        };
        (
            c.subdevice,
            e.params.axis_encoder_reference_mode,
            e.name.clone(),
        )
    };
    let needed = objects_needed(kind, reference_mode);
    if needed.is_empty() {
        return None;
    }
    let missing = s.info.bus.unmapped(subdevice, needed);
    if missing.is_empty() {
        return None;
    }
    let list = missing
        .iter()
        .map(|i| format!("0x{i:04X}"))
        .collect::<Vec<_>>()
        .join(", ");
    Some(AppError::conflict(
        "drive_object_missing",
        format!(
            "axis {axis}'s drive (SubDevice {subdevice}) has no {list} in its process image \
             (GET /api/v1/bus shows its mapping and missing objects): this block needs it"
        ),
    ))
}

/// What stood in the way of a refused command, and what to do: the axis's state as the latest
/// snapshot shows it (the refused command changed nothing), its error, the stop lock and who
/// holds it, a coupling, or what the kernel's check needed (issue 28, defect 3).
pub fn refusal_why(
    s: &AppState,
    slot: AxisSlot,
    e: ErrorId,
    hint: Option<motion::RefusalHint>,
) -> Option<String> {
    use motion::AxisState as S;
    if let Some(motion::RefusalHint::CamSlave {
        position,
        velocity,
        window,
    }) = hint
    {
        let (_, st) = s.status(slot);
        let at = st.map(|st| st.set_position).unwrap_or(f64::NAN);
        // Six decimals at most, without trailing zeros.
        let n = |v: f64| {
            let t = format!("{v:.6}");
            let t = t.trim_end_matches('0').trim_end_matches('.');
            if t == "-0" {
                "0".to_owned()
            } else {
                t.to_owned()
            }
        };
        return Some(format!(
            "the cam puts the slave at {} (velocity {}) now, the slave is at {}: move it there \
             first (within {}), couple with autooffset, or start with start_mode ramp_in",
            n(position),
            n(velocity),
            n(at),
            n(window)
        ));
    }
    let (_, Some(st)) = s.status(slot) else {
        return Some("the axis is not in the cycle".into());
    };
    // A software limit: where it is (the refused target is in the request).
    if e == ErrorId::TARGET_ABOVE_SOFT_LIMIT || e == ErrorId::TARGET_BELOW_SOFT_LIMIT {
        let reg = s.registry.read().unwrap();
        let p = &reg.by_slot(slot)?.params;
        let (name, at) = if e == ErrorId::TARGET_ABOVE_SOFT_LIMIT {
            ("SWLimitPos (#1019)", p.axis_max_soft_pos_limit)
        } else {
            ("SWLimitNeg (#1017)", p.axis_min_soft_pos_limit)
        };
        return Some(format!("{name} is {at}"));
    }
    // The state explains only refusals for the state (and is always the cause in error_stop
    // or disabled); a refusal of the request's own values says enough by its number.
    let for_state = [
        ErrorId::AXIS_CANNOT_BE_STARTED,
        ErrorId::COMMAND_NOT_PERMITTED,
        ErrorId::AXIS_NOT_MOVING,
        ErrorId::BUFFER_FULL,
    ]
    .contains(&e)
        || matches!(st.state, S::ErrorStop | S::Disabled);
    if !for_state {
        return None;
    }
    let name = |st: S| {
        serde_json::to_value(st)
            .ok()
            .and_then(|v| v.as_str().map(str::to_owned))
            .unwrap_or_default()
    };
    let state = name(st.state);
    Some(match st.state {
        S::ErrorStop => {
            let err = ErrorId(st.error_id);
            format!(
                "the axis is in error_stop with 0x{:04X} {} ({}): remove the cause, then reset \
                 it (POST …/reset)",
                st.error_id,
                err.code(),
                err.text()
            )
        }
        S::Disabled => {
            "the axis is disabled: enable it first (POST …/power with enable true)".into()
        }
        S::Stopping if st.motion_commands_locked => {
            // The lock's holder: the newest MC_Stop of this axis (its job ends at standstill,
            // the lock stays until it is released).
            let stop = {
                let store = s.commands.lock().unwrap();
                store
                    .order
                    .iter()
                    .rev()
                    .filter_map(|id| store.map.get(id))
                    .find(|r| r.slot == slot && r.name == "stop" && r.accepted)
                    .map_or(st.active_command, |r| r.id)
            };
            if st.moving {
                format!("MC_Stop (command {stop}) is stopping the axis and holds it locked")
            } else {
                format!(
                    "the axis stands locked by MC_Stop (command {stop}): release it \
                     (DELETE /api/v1/commands/{stop}) or reset the axis"
                )
            }
        }
        S::Homing => format!(
            "the axis is homing (command {}): wait for it to end or stop it",
            st.active_command
        ),
        S::SynchronizedMotion if e == ErrorId::AXIS_CANNOT_BE_STARTED => {
            "the axis is a coupled slave: decouple it first (gear-out, cam-out) or stop it".into()
        }
        _ if e == ErrorId::BUFFER_FULL => format!(
            "the axis already executes command {} with one buffered after it",
            st.active_command
        ),
        _ => format!("the axis is in {state}"),
    })
}

/// An accepted command as it stands.
pub fn get(s: &AppState, id: CommandId) -> Option<CommandResource> {
    s.commands
        .lock()
        .unwrap()
        .map
        .get(&id)
        .filter(|r| r.accepted)
        .map(|r| r.view())
}

/// An accepted command, or 404.
pub fn find(s: &AppState, id: CommandId) -> AppResult<CommandResource> {
    get(s, id).ok_or_else(|| AppError::not_found("command", &id.to_string()))
}

/// How a wait ended: at the milestone, or why not (the axis's state and error as they are).
fn wait_outcome(s: &AppState, v: &CommandResource, milestone: Milestone) -> WaitOutcome {
    let reached = v.is_final || milestone.reached(&v.outputs);
    let st = s
        .registry
        .read()
        .unwrap()
        .find(&v.axis_id.to_string())
        .map(|e| e.slot)
        .and_then(|slot| s.status(slot).1)
        .unwrap_or_default();
    let reason = match st.state {
        _ if reached => None,
        motion::AxisState::ErrorStop => Some("axis_error_stop"),
        motion::AxisState::Disabled => Some("axis_disabled"),
        _ => Some("timeout"),
    };
    WaitOutcome {
        milestone,
        reached,
        reason,
        axis_state: st.state,
        axis_error_id: st.error_id,
        axis_error_code: (st.error_id != 0).then(|| ErrorId(st.error_id).code()),
    }
}

/// Waits until the command is final or reaches its milestone, or the timeout — or until its
/// axis is in error_stop, where nothing reaches a milestone before a reset (the answer then
/// says so: `wait.reason`).
pub async fn wait_for(s: &AppState, id: CommandId, timeout: Duration) -> Option<CommandResource> {
    let deadline = tokio::time::Instant::now() + timeout;
    let mut rx = s.notices.subscribe();
    // The axis's state changes without an event of this command (a power waiting for Status
    // while the axis stays in error_stop): looked at between notices too.
    let mut look = tokio::time::interval(Duration::from_millis(20));
    look.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    // Set when the axis was first seen in error_stop: the drain count to wait for.
    let mut error_stop_seen: Option<u64> = None;
    loop {
        let (view, milestone, slot) = {
            let store = s.commands.lock().unwrap();
            let r = store.map.get(&id).filter(|r| r.accepted)?;
            (r.view(), r.milestone, r.slot)
        };
        if view.is_final || milestone.reached(&view.outputs) {
            return Some(view);
        }
        let (cycle, st) = s.status(slot);
        // A reset is what leaves error_stop (its drive may take cycles to clear the fault).
        if cycle > view.accepted_cycle
            && view.command != "reset"
            && st.is_some_and(|st| st.state == motion::AxisState::ErrorStop)
        {
            // The snapshot is published before the pump applies that cycle's events: the
            // command's own error (the reason the axis stopped) may still be in the queue. A
            // drain that begins after this snapshot was read has applied it; only then is the
            // command as it stands the answer.
            let drains = s.drains.load(std::sync::atomic::Ordering::Acquire);
            match error_stop_seen {
                Some(after) if drains >= after => return get(s, id),
                Some(_) => {}
                None => error_stop_seen = Some(drains + 2),
            }
        }
        tokio::select! {
            r = tokio::time::timeout_at(deadline, rx.recv()) => match r {
                Err(_) => return get(s, id),
                Ok(Err(tokio::sync::broadcast::error::RecvError::Closed)) => return get(s, id),
                Ok(_) => {}
            },
            _ = look.tick() => {}
        }
    }
}

/// `GET /commands` filters.
pub struct ListFilter<'a> {
    pub axis: Option<&'a str>,
    pub state: Option<CommandState>,
    pub limit: Option<usize>,
}

/// Accepted commands, newest first.
pub fn list(s: &AppState, f: ListFilter<'_>) -> AppResult<Vec<CommandResource>> {
    let axis_id = match f.axis {
        Some(a) => Some(
            s.registry
                .read()
                .unwrap()
                .find(a)
                .map(|e| e.id)
                .ok_or_else(|| AppError::not_found("axis", a))?,
        ),
        None => None,
    };
    let limit = f.limit.unwrap_or(100).min(HISTORY);
    let store = s.commands.lock().unwrap();
    Ok(store
        .order
        .iter()
        .rev()
        .filter_map(|id| store.map.get(id))
        .filter(|r| r.accepted)
        .filter(|r| axis_id.is_none_or(|a| r.axis_id == a))
        .map(|r| r.view())
        .filter(|v| f.state.is_none_or(|st| v.state == st))
        .take(limit)
        .collect())
}

/// The slot of an accepted command (404 for an unknown one).
pub fn slot_of(s: &AppState, id: CommandId) -> AppResult<AxisSlot> {
    let store = s.commands.lock().unwrap();
    store
        .map
        .get(&id)
        .filter(|r| r.accepted)
        .map(|r| r.slot)
        .ok_or_else(|| AppError::not_found("command", &id.to_string()))
}

/// Releases a command (the falling edge of Execute/Enable) and audits it; the cycle it took
/// effect in.
pub async fn release(s: &AppState, id: CommandId, client: &ClientInfo) -> AppResult<u64> {
    let slot = slot_of(s, id)?;
    let result = s
        .kernel_command(slot, CommandKind::Release { target: id })
        .await;
    let outcome = match &result {
        Ok(_) => "accepted".to_owned(),
        Err(AppError::Rejected(e)) => format!("rejected:{}", e.code()),
        // The cycle thread did not answer: nothing was released, nothing to audit.
        Err(_) => return result,
    };
    s.audit(AuditEntry {
        at: store::now_rfc3339(),
        client_addr: (!client.addr.is_empty()).then(|| client.addr.clone()),
        client_id: client.id.clone(),
        principal: client.principal.clone(),
        action: "command.release".into(),
        target: Some(id.to_string()),
        command_id: Some(id),
        detail: serde_json::json!({"via": client.via}).to_string(),
        outcome: Some(outcome),
        idempotency_key: None,
    });
    result
}

/// Renews a jog's dead-man; the cycle it took effect in.
pub async fn keepalive(s: &AppState, id: CommandId) -> AppResult<u64> {
    let slot = slot_of(s, id)?;
    s.kernel_command(slot, CommandKind::Keepalive { target: id })
        .await
}
