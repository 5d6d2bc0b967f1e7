//! Position correction (spec §7.2) and the blocks built on it: MC_PositionCorrectionLimiter
//! (§4.5.5), MC_BacklashCompensation (§4.5.2, appendix §7) and
//! MC_TableBasedPositionCompensation (§4.5.12). The sum of their corrections is taken off
//! the setpoint sent to the drive and added to the actual position read back, so the axis's
//! own coordinates (set, actual, limits, targets) stay the ideal ones while the drive travels
//! through the backlash or the table's error. Apart from the motion because it acts below
//! it: no job sees a correction, and a correction never moves the set position.
//!
//! Every source changes at a bounded rate (its ramp, the FAST bound, the FULLLENGTH travel)
//! except where the block asks for a jump (UNLIMITED, DisableMode Reset).

use super::*;
use crate::command::{DisableMode, PositionCorrectionMode};
use crate::compensation::WorkDirection;

/// One source of correction and the Enable-type command that drives it.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Source {
    pub(super) cmd: Option<Held>,
    /// The correction this source applies now.
    pub(super) value: f64,
    /// Where it is going.
    target: f64,
    /// Largest change per second (0: at once).
    ramp: f64,
    disable_mode: DisableMode,
}

impl Source {
    /// Moves `value` towards `target` by at most `max_step` (None: at once).
    fn approach(&mut self, max_step: Option<f64>) {
        let d = self.target - self.value;
        self.value = match max_step {
            Some(m) if d.abs() > m => self.value + m.copysign(d),
            _ => self.target,
        };
    }

    fn limiting(&self) -> bool {
        self.cmd.is_some() && self.value != self.target
    }

    /// Ends the command with `end`; the value holds or returns to 0 as its DisableMode says.
    fn end(&mut self, cx: &mut Ctx<'_, impl EventSink>, end: End) {
        if let Some(mut c) = self.cmd.take() {
            c.end(cx, end);
        }
        if self.disable_mode == DisableMode::Reset {
            self.value = 0.0;
        }
        self.target = self.value;
    }
}

/// The position correction of an axis. In declaration order: what every cycle reads, together
/// (33 bytes), then the sources (read only while one is commanded, `idle.rs`).
#[derive(Clone, Copy, Debug, Default)]
#[repr(C)]
pub(super) struct Corrections {
    /// The total sent with the last setpoint: the actual position read now answers it.
    pub(super) sent: f64,
    /// The total the latest actual position was read with (`sent` before this cycle's step):
    /// what turns the reading back into the drive's position.
    pub(super) read: f64,
    /// The set position's last travel direction (+1, −1; 0 before the first travel), kept
    /// at standstill: backlash and directional tables depend on it.
    direction: f64,
    pub(super) last_set: f64,
    /// `last_set` holds a set position (false before the first cycle: no travel yet).
    started: bool,
    pub(super) limiter: Source,
    limiter_mode: PositionCorrectionMode,
    limiter_acceleration: f64,
    /// FULLLENGTH: correction change per unit of the axis's travel.
    limiter_per_travel: f64,
    pub(super) backlash: Source,
    backlash_value: f64,
    backlash_positive: bool,
    pub(super) table: Source,
}

impl Corrections {
    /// No source is commanded: nothing approaches a target.
    pub(super) fn settled(&self) -> bool {
        self.limiter.cmd.is_none() && self.backlash.cmd.is_none() && self.table.cmd.is_none()
    }

    pub(super) fn total(&self) -> f64 {
        self.limiter.value + self.backlash.value + self.table.value
    }
}

impl Axis {
    /// MC_PositionCorrectionLimiter, MC_BacklashCompensation, MC_TableBasedPositionCompensation:
    /// admission (position correction #1046 enabled — else 0x4B04, as TwinCAT — and valid
    /// inputs); a further command of the same block takes over from where its correction is.
    pub(super) fn submit_correction(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
        kind: CommandKind,
    ) -> Result<(), ErrorId> {
        let p = self.p();
        let ok = |x: f64| x.is_finite() && x >= 0.0;
        match kind {
            CommandKind::PositionCorrectionLimiter {
                value,
                mode,
                acceleration,
                correction_length,
            } => {
                let length_ok = mode != PositionCorrectionMode::FullLength
                    || (correction_length.is_finite() && correction_length > 0.0);
                if !(value.is_finite() && value.abs() <= 1e9 && ok(acceleration) && length_ok) {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
            }
            CommandKind::BacklashCompensation { backlash, ramp, .. } => {
                let b = backlash.unwrap_or(p.axis_backlash);
                if !(b.is_finite() && b.abs() <= 1e6 && ramp.is_finite() && ramp > 0.0) {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
            }
            CommandKind::TableBasedPositionCompensation { ramp, .. } => {
                if !(ramp.is_finite() && ramp > 0.0) {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                if self.config.compensation_table.is_none() {
                    return Err(ErrorId::COMPENSATION_TABLE_MISSING);
                }
            }
            _ => unreachable!("not a correction block"),
        }
        if !p.axis_enable_pos_correction {
            return Err(ErrorId::INVALID_MODE);
        }
        // "Should only be used on enabled axes" (§4.5.5), and MC_Power off ends them.
        if !self.enable {
            return Err(ErrorId::AXIS_CANNOT_BE_STARTED);
        }
        let axis_backlash = p.axis_backlash;
        let c = &mut self.corrections;
        let source = match kind {
            CommandKind::PositionCorrectionLimiter {
                value,
                mode,
                acceleration,
                correction_length,
            } => {
                c.limiter_mode = mode;
                c.limiter_acceleration = acceleration;
                c.limiter_per_travel = if mode == PositionCorrectionMode::FullLength {
                    (value - c.limiter.value).abs() / correction_length
                } else {
                    0.0
                };
                c.limiter.target = value;
                &mut c.limiter
            }
            CommandKind::BacklashCompensation {
                backlash,
                compensate_in_positive_direction,
                ramp,
                disable_mode,
            } => {
                c.backlash_value = backlash.unwrap_or(axis_backlash);
                c.backlash_positive = compensate_in_positive_direction;
                c.backlash.ramp = ramp;
                c.backlash.disable_mode = disable_mode;
                &mut c.backlash
            }
            CommandKind::TableBasedPositionCompensation { ramp, disable_mode } => {
                c.table.ramp = ramp;
                c.table.disable_mode = disable_mode;
                &mut c.table
            }
            _ => unreachable!(),
        };
        if let Some(mut old) = source.cmd.take() {
            old.end(cx, End::Aborted);
        }
        source.cmd = Some(Held::start_active(cx, id));
        self.correction_targets();
        Ok(())
    }

    /// The falling Enable of a correction block: the limiter's correction freezes where it
    /// is; backlash and table hold or return to 0 as their DisableMode says. Whether `target`
    /// was one of them.
    pub(super) fn release_correction(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        target: CommandId,
    ) -> bool {
        let c = &mut self.corrections;
        let mine = |s: &Source| s.cmd.is_some_and(|h| h.id == target);
        if mine(&c.limiter) {
            // (The limiter's DisableMode is never set: it holds.)
            c.limiter.end(cx, End::Done);
        } else if mine(&c.backlash) {
            c.backlash.end(cx, End::Done);
        } else if mine(&c.table) {
            c.table.end(cx, End::Done);
        } else {
            return false;
        }
        true
    }

    /// Where backlash and table compensation are going: from the travel direction and the
    /// set position (also at once when one is enabled, so Limiting shows from the start).
    fn correction_targets(&mut self) {
        let set = self.set.position;
        let table_at = self
            .config
            .compensation_table
            .as_ref()
            .map(|t| (t.at(set), t.direction));
        let c = &mut self.corrections;
        if c.backlash.cmd.is_some() {
            // Appendix §7.3: reference on the left flank → compensated while travelling
            // negative (+backlash on the actual, −backlash on the drive's setpoint); on the
            // right flank → while travelling positive (the opposite signs).
            c.backlash.target = match (c.backlash_positive, c.direction) {
                (false, d) if d < 0.0 => c.backlash_value,
                (true, d) if d > 0.0 => -c.backlash_value,
                _ => 0.0,
            };
        }
        if let (true, Some((at, direction))) = (c.table.cmd.is_some(), table_at) {
            let applies = match direction {
                WorkDirection::Both => true,
                WorkDirection::Positive => c.direction > 0.0,
                WorkDirection::Negative => c.direction < 0.0,
            };
            c.table.target = if applies { at } else { 0.0 };
        }
    }

    /// MC_Power off ends the correction blocks (CommandAborted), each leaving its correction
    /// as its DisableMode says: an enable that is gone cannot keep a block active.
    pub(super) fn end_corrections(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        let c = &mut self.corrections;
        for s in [&mut c.limiter, &mut c.backlash, &mut c.table] {
            if s.cmd.is_some() {
                s.end(cx, End::Aborted);
            }
        }
    }

    /// One cycle of the corrections, after the motion: the travel direction, each source one
    /// step towards its target. Returns the total for this cycle's setpoint.
    pub(super) fn step_corrections(&mut self) -> f64 {
        let dt = self.cycle_time;
        let set = self.set.position;
        // While the set position follows the actual one (disabled, torque control) the
        // reading moves with the correction itself: no travel of the axis's own.
        let follows_actual = self.mode == Mode::Disabled || self.runs(JobKind::Torque);
        let c = &mut self.corrections;
        let travel = if c.started && !follows_actual {
            set - c.last_set
        } else {
            0.0
        };
        c.started = true;
        c.last_set = set;
        if travel.abs() > 1e-12 {
            c.direction = travel.signum();
        }
        if self.idle(Idle::CORRECTIONS) {
            // No source commanded (`idle.rs`): the total stays what was sent.
            return self.corrections.sent;
        }
        self.correction_targets();
        let c = &mut self.corrections;
        if c.limiter.cmd.is_some() {
            let step = match c.limiter_mode {
                PositionCorrectionMode::Unlimited => None,
                PositionCorrectionMode::Fast if c.limiter_acceleration == 0.0 => None,
                PositionCorrectionMode::Fast => Some(c.limiter_acceleration * dt * dt),
                PositionCorrectionMode::FullLength => Some(travel.abs() * c.limiter_per_travel),
            };
            c.limiter.approach(step);
        }
        if c.backlash.cmd.is_some() {
            c.backlash.approach(Some(c.backlash.ramp * dt));
        }
        if c.table.cmd.is_some() {
            c.table.approach(Some(c.table.ramp * dt));
        }
        c.total()
    }

    /// The correction part of the status.
    pub(super) fn correction_status(&self) -> crate::status::PositionCorrectionStatus {
        let c = &self.corrections;
        crate::status::PositionCorrectionStatus {
            total: c.sent,
            limiter: c.limiter.value,
            limiter_enabled: c.limiter.cmd.is_some(),
            limiter_limiting: c.limiter.limiting(),
            backlash: c.backlash.value,
            backlash_enabled: c.backlash.cmd.is_some(),
            backlash_limiting: c.backlash.limiting(),
            table: c.table.value,
            table_enabled: c.table.cmd.is_some(),
            table_limiting: c.table.limiting(),
        }
    }
}
