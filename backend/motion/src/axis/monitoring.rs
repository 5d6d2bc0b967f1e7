//! Power, errors and monitoring: MC_Power/notes 1–5, MC_Reset, ErrorStop, feed enables,
//! software limits for endless motion and following-error monitoring. Together because each
//! ends what runs when the axis may not go on, or lets it go on again: the way into ErrorStop
//! (`enter_error`) and out of it (`reset`) are here.

use super::*;

/// MC_OverrideFilter between calls (§4.5.4): after every change of the filtered override a
/// new value waits until `recovery_time` has passed since it (0 % and 100 % never wait).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct OverrideFilterState {
    recovery_time: f64,
    /// The cycle (`Axis::cycle`) at which the filtered override last changed: the quiet time
    /// is counted from it when a new value waits, not by a timer stepped every cycle (a
    /// cache line written in every cycle of every axis, issue 27).
    changed_at: u64,
    /// The latest filtered value (percent) not yet applied.
    pending: Option<f64>,
    /// The last value applied (percent).
    applied: Option<f64>,
}

impl OverrideFilterState {
    /// A new filtered value (MC_OverrideFilter called) and the quiet time it keeps.
    pub(super) fn queue(&mut self, recovery_time: f64, percent: f64) {
        self.recovery_time = recovery_time;
        self.pending = Some(percent);
    }

    /// Nothing waits to be applied.
    pub(super) fn settled(&self) -> bool {
        self.pending.is_none()
    }

    /// At cycle `cycle` (cycles of `dt`): the value to apply as MC_Power's override, once the
    /// quiet time after the last change has passed (0 % and 100 % at once).
    fn step(&mut self, cycle: u64, dt: f64) -> Option<f64> {
        let v = self.pending?;
        // An axis never counts back; saturating, a count from another kernel's cycles (an axis
        // moved) waits the whole quiet time rather than none.
        let since_change = cycle.saturating_sub(self.changed_at) as f64 * dt;
        if self.applied == Some(v) {
            self.pending = None;
        } else if v == 0.0
            || v == 100.0
            || self.applied.is_none()
            || since_change >= self.recovery_time - 1e-9
        {
            self.pending = None;
            self.applied = Some(v);
            self.changed_at = cycle;
            return Some(v);
        }
        None
    }
}

impl Axis {
    /// Note 2: Enable FALSE → Disabled (ErrorStop stays ErrorStop).
    pub(super) fn disable(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        self.enable = false;
        self.disable_when_idle = false;
        self.end_corrections(cx);
        self.last_target = None;
        self.abort_superposition(cx);
        self.abort_all(cx);
        if let Some(mut s) = self.stop.take() {
            s.end(cx, End::Aborted);
        }
        if let Some(mut p) = self.power.take() {
            p.end(cx, End::Done);
        }
        self.planner.clear();
        if self.mode != Mode::ErrorStop {
            self.mode = Mode::Disabled;
        }
        self.set = Kinematics {
            position: self.act_pos,
            ..Kinematics::default()
        };
    }

    /// MC_OverrideFilter (§4.5.4): a filtered value waiting for the quiet time after the last
    /// change is applied as MC_Power's override once it has passed; 0 % and 100 % at once.
    /// Asked in a step and right after the call (between two steps: the quiet time counts
    /// from the latest step's cycle).
    pub(super) fn step_override_filter(&mut self) {
        if let Some(v) = self.override_filter.step(self.beat.cycle, self.cycle_time) {
            self.power_override = v;
        }
    }

    /// The axis executes a job (§4.1.1's test for a buffered disable): a motion, a coupling,
    /// a superposition or a coupling waiting for its activation, running or buffered.
    pub(super) fn executes_job(&self) -> bool {
        self.job.is_some()
            || self.next.is_some()
            || self.coupling.is_some()
            || self.superposition.running.is_some()
            || self.cam.waits_for_coupling()
    }

    /// A buffered disable takes effect once the axis no longer executes a job.
    pub(super) fn step_buffered_disable(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        if self.disable_when_idle && !self.executes_job() {
            self.disable(cx);
        }
    }

    /// MC_Reset: clears ErrorStop (notes 3/4) and the MC_Stop lock; takes actual as set.
    pub(super) fn reset(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        self.abort_superposition(cx);
        if let Some(mut s) = self.stop.take() {
            s.end(cx, End::Aborted);
            if self.mode == Mode::Stopping && self.job.is_none() {
                self.mode = Mode::Enabled;
            }
            // Otherwise the ramp ends in Standstill without the lock (see step_job).
        }
        if self.mode == Mode::ErrorStop {
            self.last_target = None;
            self.power_on_timer = 0.0;
            self.fault_reset = true;
            self.reset_grace = 3;
            self.error = ErrorId(0);
            self.lag_timer = 0.0;
            self.abort_all(cx);
            self.planner.clear();
            self.set = Kinematics {
                position: self.act_pos,
                ..Kinematics::default()
            };
            self.mode = if self.enable && self.status.power_status {
                Mode::Enabled
            } else {
                Mode::Disabled
            };
        }
    }

    /// Note 1: axis error → ErrorStop; every command reports the error; the setpoint stops
    /// on a fast ramp (or follows the actual position when the drive is off).
    pub(super) fn enter_error(&mut self, cx: &mut Ctx<'_, impl EventSink>, e: ErrorId) {
        if self.mode == Mode::ErrorStop {
            return;
        }
        self.error = e;
        self.has_been_stopped = true;
        self.end_phasing(cx, End::Error(e));
        if let Some(mut sp) = self.superposition.running.take() {
            sp.cmd.end(cx, End::Error(e));
        }
        // A member of a moving group keeps the group's job: the group sees the error in its
        // next step and stops every member on the path (this one too, while its drive follows).
        let group_job = if self.group_axis_following() {
            self.job.take()
        } else {
            None
        };
        for j in [self.next.take(), self.job.take()].into_iter().flatten() {
            let mut j = j;
            j.finish_error(cx, e);
        }
        if let Some(mut s) = self.stop.take() {
            s.end(cx, End::Error(e));
        }
        // A coupling that waits for its activation would take the stopping axis over.
        self.cancel_cam_in(cx, End::Error(e));
        self.coupling = None;
        self.mode = Mode::ErrorStop;
        if group_job.is_some() {
            self.job = group_job;
            return;
        }
        let p = self.p();
        let (dec, jerk) = (
            p.axis_fast_dec.max(p.axis_dec),
            p.axis_fast_jerk.max(p.axis_jerk),
        );
        let mut j = Job::new(0, JobKind::Halt);
        j.dec = dec;
        j.acc = dec;
        j.jerk = jerk;
        j.velocity = self.set.velocity.abs().max(EPS_V);
        self.job = Some(j);
        self.plan_job_now();
        if let Some(j) = self.job.as_mut() {
            j.phase = Phase::Moving;
        }
    }

    pub(super) fn step_power(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        dt: f64,
        fb: &DriveFeedback,
    ) {
        self.reset_grace = self.reset_grace.saturating_sub(1);
        if fb.fault
            && self.reset_grace == 0
            && self.mode != Mode::ErrorStop
            && (self.enable || self.mode != Mode::Disabled)
        {
            self.drive_error_code = fb.fault_code;
            self.enter_error(cx, ErrorId::DRIVE_FAULT);
        }
        // A powered axis that loses its drive stops; one still waiting for its power-on waits
        // for the bus too (the drive-not-ready timeout bounds the wait).
        if fb.bus_error
            && self.reset_grace == 0
            && !matches!(self.mode, Mode::ErrorStop | Mode::Disabled)
        {
            self.enter_error(cx, ErrorId::BUS_ERROR);
        }
        let status = self.enable && fb.enabled && fb.ready && !fb.fault && !fb.bus_error;
        if self.enable && !status && self.mode == Mode::Disabled {
            self.power_on_timer += dt;
            if self.power_on_timer > POWER_ON_TIMEOUT {
                if let Some(mut p) = self.power.take() {
                    p.end(cx, End::Error(ErrorId::DRIVE_NOT_READY));
                }
                self.enable = false;
            }
        }
        if self.enable && status && self.mode == Mode::Disabled {
            // Note 5: the axis takes the actual position as set position.
            self.set = Kinematics {
                position: self.act_pos,
                ..Kinematics::default()
            };
            self.mode = Mode::Enabled;
            self.lag_timer = 0.0;
            self.power_on_timer = 0.0;
            self.last_target = None;
        }
        if self.enable
            && !fb.enabled
            && self.status.power_status
            && !fb.fault
            && matches!(self.mode, Mode::Enabled | Mode::Stopping)
        {
            // The drive dropped out by itself.
            self.enter_error(cx, ErrorId::DRIVE_NOT_READY);
        }
        self.status.power_status = status;
        // In place: a copy out and back every cycle stalled on its own stores (issue 27).
        if let Some(p) = self.power.as_mut() {
            p.emit(
                cx,
                FbOutputs {
                    busy: true,
                    active: true,
                    status,
                    ..FbOutputs::default()
                },
            );
        }
    }

    /// A feed enable dropping while moving in its direction stops the axis (controlled).
    pub(super) fn step_feed_enables(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        if self.mode != Mode::Enabled {
            return;
        }
        let v = self.set.velocity;
        // A stop of our own is already under way; homing handles limit switches itself.
        let stoppable = self.job.as_ref().is_some_and(|j| {
            (j.id != 0 || j.kind != JobKind::Halt)
                && !matches!(j.kind, JobKind::Home | JobKind::DriveHome)
        });
        if !stoppable {
            return;
        }
        if (v > EPS_V && self.limit_positive) || (v < -EPS_V && self.limit_negative) {
            // A hardware limit switch in the direction of travel is an end of travel: an
            // axis error, stopped with the fast-stop dynamics (#1053/#1054) in ErrorStop.
            self.enter_error(cx, ErrorId::LIMIT_SWITCH);
        } else if (v > EPS_V && !self.enable_positive) || (v < -EPS_V && !self.enable_negative) {
            self.stop_internally(cx, ErrorId::FEED_ENABLE_MISSING, false);
        }
    }

    /// Ends the running command with `e` and stops the axis on an internal halt (not an
    /// axis error: the axis ends in Standstill).
    pub(super) fn stop_internally(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        e: ErrorId,
        fast: bool,
    ) {
        let p = self.p();
        let (mut dec, mut jerk) = if fast {
            (
                p.axis_fast_dec.max(p.axis_dec),
                p.axis_fast_jerk.max(p.axis_jerk),
            )
        } else {
            (p.axis_dec, p.axis_jerk)
        };
        self.has_been_stopped = true;
        if let Some(mut n) = self.next.take() {
            n.finish_error(cx, e);
        }
        if let Some(mut j) = self.job.take() {
            dec = dec.max(j.dec);
            jerk = jerk.max(j.jerk);
            j.finish_error(cx, e);
        }
        self.cancel_cam_in(cx, End::Error(e));
        self.coupling = None;
        let mut h = Job::new(0, JobKind::Halt);
        h.dec = dec;
        h.acc = dec;
        h.jerk = jerk;
        h.velocity = self.set.velocity.abs().max(EPS_V);
        h.options.ignore_position_monitoring = true;
        self.start_job(cx, h);
    }

    /// Endless motion stops at an enabled software limit with its deceleration; a coupled
    /// slave that crosses one is an axis error.
    pub(super) fn step_soft_limits(&mut self, cx: &mut Ctx<'_, impl EventSink>, dt: f64) {
        let p = self.p();
        // The job's fields by value, not the job (a copy of it every cycle was an eighth of a
        // 64-axis cycle).
        let Some(job) = self.job.as_ref() else {
            return;
        };
        let (kind, id, endless, positioning) =
            (job.kind, job.id, job.is_endless(), job.is_positioning());
        let (acc, dec, jerk) = (job.acc, job.dec.max(1e-9), job.jerk.max(1e-9));
        let v = self.set.velocity;
        if kind == JobKind::External {
            // Checked against the samples themselves (`step_external`).
            return;
        }
        if kind == JobKind::Gear || kind == JobKind::Group {
            // A slave follows its master and cannot brake for a limit of its own while
            // coupled. Crossing one (moving outwards beyond it) decouples it and stops it on
            // the fast-stop ramp in ErrorStop (TwinCAT raises an axis error for a slave
            // outside its software limits); a GearInDyn still enabled and a superposition
            // end with the error.
            let out_max = p.axis_en_max_soft_pos_limit
                && self.set.position > p.axis_max_soft_pos_limit
                && v > EPS_V;
            let out_min = p.axis_en_min_soft_pos_limit
                && self.set.position < p.axis_min_soft_pos_limit
                && v < -EPS_V;
            if out_max || out_min {
                self.enter_error(cx, ErrorId::SOFT_LIMIT_REACHED);
            }
            return;
        }
        let endless = endless || (id == 0 && kind == JobKind::Velocity);
        if v.abs() <= EPS_V || kind == JobKind::Home {
            // A homing run searches for the reference of the coordinates the limits are
            // given in; the limit switches end it.
            return;
        }
        let limit = if v > 0.0 && p.axis_en_max_soft_pos_limit {
            p.axis_max_soft_pos_limit
        } else if v < 0.0 && p.axis_en_min_soft_pos_limit {
            p.axis_min_soft_pos_limit
        } else {
            return;
        };
        let sd = stop_distance(v, self.set.acceleration, dec, jerk);
        let margin = 2.0 * v.abs() * dt;
        if (limit - self.set.position) * v.signum() > sd + margin {
            return;
        }
        // A planned profile (positioning, a halt) ends where it ends: it is stopped only if
        // it would carry the set position beyond the limit (an overshoot, braking a motion
        // that was heading outwards).
        if !endless && !self.planner.overshoots(limit, v.signum()) {
            return;
        }
        if !endless && !positioning {
            // A stop whose own ramp would cross the limit: stop harder, as an axis error.
            self.enter_error(cx, ErrorId::SOFT_LIMIT_REACHED);
            return;
        }
        let mut j = self.job.expect("a job runs");
        j.finish_error(cx, ErrorId::SOFT_LIMIT_REACHED);
        if let Some(mut n) = self.next.take() {
            n.finish_aborted(cx);
        }
        let mut h = Job::new(0, JobKind::Positioning { continuous: false });
        h.velocity = v.abs();
        h.acc = acc;
        h.dec = dec;
        h.jerk = jerk;
        h.target = limit;
        h.options.ignore_position_monitoring = true;
        self.job = None;
        self.start_job(cx, h);
        // The main motion is being stopped (superposition abort table row 4): a superposition
        // ends unless it is to resume after a motion stop, and then too if what it still has
        // to do would carry the stop past the limit; its velocity goes into the stop.
        if let Some(sp) = self.superposition.running {
            let to_come = sp.distance - sp.applied;
            if sp.option != SuperpositionAbortOption::ResumeAfterMotionStop {
                self.abort_superposition(cx);
            } else if self.superposition_room(to_come) != to_come {
                self.end_superposition_incomplete(cx);
            }
        }
        // If the limit cannot be reached without overshoot, the axis would end beyond it:
        // stop as hard as allowed, as an axis error (never a silent standstill outside).
        if self.planner.overshoots(limit, v.signum()) {
            self.enter_error(cx, ErrorId::SOFT_LIMIT_REACHED);
        }
    }

    pub(super) fn step_following_error(&mut self, cx: &mut Ctx<'_, impl EventSink>, dt: f64) {
        let p = self.p();
        let (enabled, max_lag, filter) = (
            p.axis_en_position_lag_monitoring,
            p.axis_max_pos_lag_value,
            p.axis_max_pos_lag_filter_time,
        );
        if !enabled || self.mode == Mode::ErrorStop || self.mode == Mode::Disabled {
            self.lag_timer = 0.0;
            return;
        }
        let lag = (self.sent_position - self.act_pos).abs();
        if lag > max_lag {
            self.lag_timer += dt;
            if self.lag_timer > filter + 1e-12 {
                self.enter_error(cx, ErrorId::FOLLOWING_ERROR);
            }
        } else {
            self.lag_timer = 0.0;
        }
    }
}
