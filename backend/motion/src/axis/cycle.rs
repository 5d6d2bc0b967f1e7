//! One cycle of an axis: [`Axis::step`] in this order — read the feedback (actual = drive
//! position + coordinate offset + the position correction sent last cycle) → power and drive
//! readiness (notes 1, 2, 5) → feed enables → the job (planner sample, or the master through
//! the coupling) → phasing → superposition laid on top → soft limits (endless motion, gear
//! slaves) → following error (against the setpoint the drive is answering) → MC_Stop's unlock
//! (note 6) → touch probe → position correction → status → setpoint (set − offset −
//! correction); the running job's step (dead-man, a coupled slave, override
//! re-plan, the planner sample, a blending hand-over, milestones and its end); the done
//! criterion (§3.11). Kept in one place so that a cycle can be read top to bottom.

use super::*;

impl Axis {
    /// One cycle, from the drive's feedback to its setpoint. `master`: what the kernel saw of
    /// this axis's master after stepping it in this cycle. The setpoint is written into `out`
    /// in place (a 56-byte setpoint returned through the stack and copied again cost more
    /// than building it). `rest`: the kernel's rest record for this slot, kept up to date
    /// here; an axis at rest the kernel steps with [`Axis::step_at_rest`] (`rest.rs`).
    /// `ahead`: the axis stepped next, whose lines this step asks for in parts as it goes
    /// (`prefetch.rs`; the kernel asked for the first part).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn step(
        &mut self,
        dt: f64,
        fb: &DriveFeedback,
        master: Master,
        cams: &crate::cam::CamStore,
        cycle: u64,
        events: &mut impl EventSink,
        rest: &mut rest::Rest,
        out: &mut DriveSetpoint,
        ahead: Ahead,
    ) {
        // The kernel steps an axis at rest without coming here (`rest.rs`).
        debug_assert!(!self.at_rest(fb, rest));
        self.step_full(dt, fb, master, cams, cycle, events, out, ahead);
        self.settle_rest(fb, out, rest);
    }

    /// [`Axis::step`] with everything in it.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn step_full(
        &mut self,
        dt: f64,
        fb: &DriveFeedback,
        master: Master,
        cams: &crate::cam::CamStore,
        cycle: u64,
        events: &mut impl EventSink,
        out: &mut DriveSetpoint,
        ahead: Ahead,
    ) {
        if !(fb.actual_position.is_finite() && fb.actual_velocity.is_finite()) {
            // A drive that reports no number is a faulty drive; keep the last good values.
            // Where there is none (a reading that overflowed in the axis's units), 0: the
            // stand-in must be a number, or this would recurse without end.
            let kept = (self.act_pos - self.offset - self.corrections.read) / self.enc_k;
            let fb = DriveFeedback {
                fault: true,
                actual_position: if kept.is_finite() { kept } else { 0.0 },
                actual_velocity: 0.0,
                ..*fb
            };
            return self.step_full(dt, &fb, master, cams, cycle, events, out, ahead);
        }
        let cx = &mut Ctx {
            slot: self.slot,
            cycle,
            events,
            cams,
        };
        self.beat.cycle = cycle;
        self.io_data_invalid = fb.bus_error;
        self.reported_mode = fb.mode;
        self.actual_torque = fb.actual_torque;
        self.velocity_limited = fb.velocity_limited;
        // The drive answers the setpoint sent last cycle, which carried that cycle's correction.
        // Read through the encoder scaling (1 unless MC_SetEncoderScalingFactor changed it).
        self.corrections.read = self.corrections.sent;
        self.act_pos = self.enc_k * fb.actual_position + self.offset + self.corrections.read;
        self.limit_positive = fb.limit_positive;
        self.limit_negative = fb.limit_negative;
        if self.latch.is_some() && !self.runs(JobKind::Home) {
            // Whatever ended a homing run (stop, power off, error, reset) disarms its latch.
            self.latch = None;
        }
        self.act_acc = if self.fed {
            (self.enc_k * fb.actual_velocity - self.act_vel) / dt
        } else {
            0.0
        };
        self.fed = true;
        self.act_vel = self.enc_k * fb.actual_velocity;
        let fault_reset = core::mem::take(&mut self.fault_reset);

        if !self.idle(Idle::OVERRIDE_FILTER) {
            self.step_override_filter();
        }
        self.step_group_reset(cx);
        // A drive that reports torque mode is looked at in every cycle, marked or not (it is
        // timed from now on: the mark no longer holds).
        if !self.idle(Idle::DRIVE_MODE) || self.reported_mode == crate::DriveMode::Torque {
            self.idle.forget(Idle::DRIVE_MODE);
            self.step_drive_mode(cx, dt);
        }
        // Power and drive readiness (notes 1, 2, 5).
        self.step_power(cx, dt, fb);
        ahead.part(1);

        // Disabled: the setpoint follows the actual position.
        if self.mode == Mode::Disabled || (self.mode == Mode::ErrorStop && !fb.enabled) {
            self.set = Kinematics {
                position: self.act_pos,
                ..Kinematics::default()
            };
            if self.mode == Mode::ErrorStop && self.job.is_some() {
                self.job = None;
                self.planner.clear();
            }
            ahead.part(2);
        } else {
            // A coupled slave whose master is gone or in ErrorStop.
            let lost = match master {
                Master::Uncoupled => false,
                Master::Lost => true,
                Master::Sample(m) => m.error,
            };
            if lost && self.coupling.is_some() {
                self.enter_error(cx, ErrorId::MASTER_LOST);
            }
            // Nothing waits for a master that is not there (and an uncoupled axis has none).
            if !matches!(master, Master::Uncoupled) {
                self.step_cam_activations(cx, master);
            }
            self.step_feed_enables(cx);
            self.step_job(cx, dt, fb, master);
            // The next axis's last part: the monitors and the status, still to come, cover its
            // way (`prefetch.rs`).
            ahead.part(2);
            // Blocks marked idle are skipped (`idle.rs`).
            if !self.idle(Idle::PHASING) {
                self.step_phasing(cx, dt);
            }
            if !self.idle(Idle::SUPERPOSITION) {
                self.step_superposition(cx, dt);
            }
            if !self.drive_executed() {
                // A drive that runs the profile watches its own lag (statusword bit 13) and
                // the soft limits are its jobs' (`drive_profile.rs`).
                self.step_soft_limits(cx, dt);
                self.step_following_error(cx, dt);
            }
        }
        if self.mode == Mode::ErrorStop && self.job.is_none() {
            if let Some(mut r) = self.pending_reset.take() {
                self.reset(cx);
                r.end(cx, End::Done);
            }
        }
        self.try_unlock(cx);
        self.settle_cam(cx);
        self.step_buffered_disable(cx);
        // InTargetPosition's dwell counts cycles (not status updates: submits update too).
        let lag = (self.act_pos - self.set.position).abs();
        if self.set.velocity.abs() <= EPS_V && lag <= self.p().axis_target_position_window {
            self.beat.in_window_timer += dt;
        } else {
            self.beat.in_window_timer = 0.0;
        }
        let probe_armed = self.step_probe(cx, fb);
        let correction = self.step_corrections();
        let correction_rate = (correction - self.corrections.sent) / dt;
        self.corrections.sent = correction;
        self.update_status();
        self.settle_idle();
        // The peak hold counts cycles only: a submit's status update sees the setpoint the
        // drive has not answered yet. NaN feedback cannot stick (f64::min/max skip NaN).
        let s = &mut self.status;
        s.following_error_min = s.following_error_min.min(s.following_error);
        s.following_error_max = s.following_error_max.max(s.following_error);
        self.sent_position = self.set.position;
        self.prev_cam = fb.reference_cam;
        *out = DriveSetpoint {
            enable: self.enable
                && !(self.mode == Mode::ErrorStop && self.error == ErrorId::DRIVE_FAULT),
            fault_reset,
            position: (self.set.position - self.offset - correction) / self.enc_k,
            velocity: (self.set.velocity - correction_rate) / self.enc_k,
            acceleration: self.set.acceleration / self.enc_k,
            mode: self.drive_mode(self.runs(JobKind::Torque)),
            torque: self.torque.set,
            velocity_limit_high: self.torque.limit_high,
            velocity_limit_low: self.torque.limit_low,
            latch_enable: self.latch.is_some() || probe_armed,
            // The probe only when armed: an axis without one does not read it.
            latch_source: match self.latch {
                Some(l) => l,
                None if probe_armed => self.probe.as_ref().map(|p| p.source()).unwrap_or_default(),
                None => LatchSource::default(),
            },
            profile: self.profile_command(),
        };
    }

    /// The running job's step: the setpoint it gives in this cycle, its milestones, and its
    /// end (the buffered job starts in the same cycle).
    pub(super) fn step_job(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        dt: f64,
        fb: &DriveFeedback,
        master: Master,
    ) {
        let ovr = self.override_ratio();
        let returning = !self.drive_executed()
            && self.drive.cmd.mode != crate::drive::ProfileMode::Off
            && !self.runs(JobKind::DriveHome);
        if returning {
            // A host-side axis whose drive still runs its homing mode: the drive stops by
            // itself first; the job (if any) takes over in the cyclic mode from rest.
            if self.step_drive_return(fb) {
                return;
            }
            self.plan_job_now();
        }
        // The job is worked on in place (`self.job`), borrowed anew after each call that needs
        // the whole axis: a copy of the 300-byte job out and back every cycle was a sixth of a
        // moving axis's step (issue 27).
        let Some(job) = self.job.as_mut() else {
            if self.drive_executed() {
                self.step_drive_job(cx, fb);
                return;
            }
            self.set.velocity = 0.0;
            self.set.acceleration = 0.0;
            self.set.jerk = 0.0;
            return;
        };

        // Jog dead-man.
        if let JobKind::JogHeld { released: false } = job.kind {
            job.since_keepalive = job.since_keepalive.saturating_add(1);
            if job.deadman_cycles > 0 && job.since_keepalive >= job.deadman_cycles {
                job.kind = JobKind::JogHeld { released: true };
                job.pending_error = Some(ErrorId::DEADMAN_TIMEOUT);
                // Reported in the cycle it fires (the command ends with the error at rest).
                let out = FbOutputs {
                    in_velocity: false,
                    warning: true,
                    warning_id: ErrorId::DEADMAN_TIMEOUT.0,
                    ..job.out
                };
                job.emit(cx, out);
                self.plan_job_now();
            }
        }

        let kind = self.running().kind;
        if self.drive_executed() || kind == JobKind::DriveHome {
            // The drive runs the profile: no planner, no override re-plan.
            self.step_drive_job(cx, fb);
            return;
        }
        match kind {
            JobKind::Gear => return self.follow_master(cx, master, dt),
            JobKind::Torque => return self.step_torque(cx, dt, fb),
            JobKind::External => return self.step_external(cx, dt),
            JobKind::Group => return self.step_group(cx, dt),
            _ => {}
        }

        // Override changes re-plan (never a velocity jump).
        let job = self.running();
        let endless_holding =
            job.phase == Phase::Holding && job.kind == JobKind::Positioning { continuous: true };
        if job.planned_override != ovr
            && job.phase != Phase::Queued
            && !matches!(
                job.kind,
                JobKind::Halt | JobKind::JogHeld { released: true }
            )
            && !matches!(job.phase, Phase::Settling { .. })
        {
            if endless_holding {
                // Continue at end velocity × override.
                let j = self.job.as_mut().expect("running");
                j.planned_override = ovr;
                let v = j.end_velocity * ovr;
                let _ = self
                    .planner
                    .plan_velocity(self.set, v, &j.limits_passing(1.0, v));
            } else {
                self.plan_job_now();
                // Re-planning restarts the milestone.
                let j = self.job.as_mut().expect("running");
                if j.phase == Phase::Holding {
                    j.phase = Phase::Moving;
                }
            }
            let job = self.job.as_mut().expect("running");
            if job.out.in_velocity {
                let out = FbOutputs {
                    in_velocity: false,
                    ..job.out
                };
                job.emit(cx, out);
            }
        }

        // Read again: a re-plan that failed above made the homing run a stop (`Halt`).
        if self.running().kind == JobKind::Home {
            self.step_home(cx, dt, fb);
            return;
        }

        if let Some(k) = self.planner.step(dt) {
            self.set = k;
            self.superposition.main_motion_sampled();
        }
        let job = self.job.as_mut().expect("running");
        // An end or blending velocity that could not be reached moving only towards the
        // target was adjusted to the best reachable one: say so.
        if let Some(w) = job.warn.take() {
            let out = FbOutputs {
                warning: true,
                warning_id: w.0,
                ..job.out
            };
            job.emit(cx, out);
        }
        // A successor with its own blending position takes over where the axis passes it.
        if let Some((bp, dir)) = self.next.as_ref().and_then(|n| n.blend_at) {
            if (self.set.position - bp) * dir >= 0.0 {
                if self.next.as_ref().is_some_and(|n| n.blend_done) {
                    job.finish_done(cx);
                } else {
                    job.finish_aborted(cx);
                }
                self.job = None;
                if let Some(n) = self.next.take() {
                    self.start_job(cx, n);
                }
                return;
            }
        }
        let finished = self.planner.finished();

        match job.kind {
            JobKind::Velocity | JobKind::JogHeld { released: false } => {
                let reached = finished && ovr > 0.0 && job.planned_override == ovr;
                job.hold_velocity(cx, reached);
            }
            JobKind::Positioning { continuous: true } => {
                let short = (job.planned_end - job.end_velocity).abs()
                    > 1e-9 * (1.0 + job.end_velocity.abs());
                if finished
                    && job.phase == Phase::Moving
                    && job.planned_override > 0.0
                    && !job.past_target
                    && short
                {
                    // Passed the target slower than the end velocity: now run up to it.
                    job.past_target = true;
                    self.plan_job_now();
                    return;
                }
                if finished && job.phase == Phase::Moving && job.planned_override > 0.0 {
                    job.past_target = true;
                    job.phase = Phase::Holding;
                    let out = FbOutputs {
                        in_end_velocity: true,
                        ..job.out
                    };
                    job.emit(cx, out);
                }
            }
            JobKind::Positioning { continuous: false }
            | JobKind::Halt
            | JobKind::JogHeld { released: true } => {
                if !finished
                    || (job.kind == JobKind::Positioning { continuous: false }
                        && job.planned_override <= 0.0)
                {
                    return;
                }
                // Logical end of positioning: the setpoint stands exactly on the target.
                if job.kind == (JobKind::Positioning { continuous: false })
                    && job.end_velocity == 0.0
                {
                    self.set.position = job.target;
                }
                let blending_successor = self
                    .next
                    .as_ref()
                    .is_some_and(|n| n.buffer_mode.is_blending())
                    && job.end_velocity != 0.0;
                if blending_successor {
                    job.finish_done(cx);
                    self.job = None;
                    self.start_next(cx);
                    return;
                }
                let Some(done) = self.done_criterion(dt) else {
                    return;
                };
                // The job ends: taken out of the axis (this happens once).
                let mut job = self.job.take().expect("running");
                match done {
                    Ok(()) => {
                        if let Some(e) = job.pending_error {
                            job.finish_error(cx, e);
                        } else {
                            job.finish_done(cx);
                        }
                        self.planner.clear();
                        self.set.velocity = 0.0;
                        self.set.acceleration = 0.0;
                        self.set.jerk = 0.0;
                        self.stop_ramp_ended(cx);
                        self.start_next(cx);
                    }
                    Err(e) => {
                        job.finish_error(cx, e);
                        self.planner.clear();
                        if let Some(mut n) = self.next.take() {
                            n.finish_aborted(cx);
                        }
                        if self.mode == Mode::Stopping {
                            // MC_Stop's own ramp missed its position window: the stop ends
                            // with the error, and with it the lock.
                            if let Some(mut s) = self.stop.take() {
                                s.end(cx, End::Error(e));
                            }
                            self.mode = Mode::Enabled;
                        }
                    }
                }
            }
            JobKind::Home
            | JobKind::Gear
            | JobKind::Torque
            | JobKind::External
            | JobKind::Group
            | JobKind::DriveHome => unreachable!(),
        }
    }

    /// The running job (callers have checked that there is one).
    fn running(&self) -> &Job {
        self.job.as_ref().expect("a job runs")
    }

    /// A stop's ramp came to rest: MC_Stop reports Done and keeps the lock (note 6), or the
    /// axis is enabled again when MC_Reset removed the lock during the ramp.
    pub(super) fn stop_ramp_ended(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        if self.mode != Mode::Stopping {
            return;
        }
        if let Some(mut s) = self.stop {
            s.emit(
                cx,
                FbOutputs {
                    busy: true,
                    active: true,
                    done: true,
                    ..FbOutputs::default()
                },
            );
            self.stop = Some(s);
        } else {
            self.mode = Mode::Enabled;
        }
    }

    /// §3.11: None = still waiting; Some(Ok) = done; Some(Err) = in-target timeout.
    pub(super) fn done_criterion(&mut self, dt: f64) -> Option<Result<(), ErrorId>> {
        let p = &self.config.parameters;
        let job = self.job.as_mut().expect("a job runs");
        let stop_like = job.kind != (JobKind::Positioning { continuous: false });
        let monitor = if stop_like {
            job.options.enable_stop_position_monitoring
        } else {
            !job.options.ignore_position_monitoring
        };
        if !monitor || self.mode == Mode::ErrorStop {
            return Some(Ok(()));
        }
        let target = if stop_like {
            self.set.position
        } else {
            job.target
        };
        let dev = (self.act_pos - target).abs();
        let (mut in_window, mut total) = match job.phase {
            Phase::Settling { in_window, total } => (in_window, total),
            _ => (0.0, 0.0),
        };
        total += dt;
        let reached = if p.axis_en_target_position_monitoring {
            if dev <= p.axis_target_position_window {
                in_window += dt;
            } else {
                in_window = 0.0;
            }
            in_window + 1e-12 >= p.axis_target_position_monitoring_time
        } else if p.axis_en_position_range_monitoring {
            dev <= p.axis_position_range_window
        } else {
            true
        };
        job.phase = Phase::Settling { in_window, total };
        if reached {
            return Some(Ok(()));
        }
        if p.axis_en_in_target_timeout && total > p.axis_in_target_timeout {
            return Some(Err(ErrorId::IN_TARGET_TIMEOUT));
        }
        None
    }
}
