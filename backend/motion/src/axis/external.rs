//! The external setpoint generator (spec §4.4): MC_ExtSetPointGenEnable / Disable and the
//! samples a client feeds (MC_ExtSetPointGenFeed: position, velocity, acceleration,
//! direction). While it runs, the axis's set position is the latest sample extrapolated with
//! its velocity and acceleration to the present cycle — a client may feed more slowly than
//! the cycle — checked every cycle: within the axis's maximum velocity, no jump (a step whose
//! velocity exceeds it), inside enabled software limits. A stream that stalls longer than its
//! timeout stops the axis on its ramp with an error, as does a sample that fails the checks.
//! Apart from the jobs because the client, not a planner, makes the motion.

use super::*;

/// What the generator holds between cycles.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct ExtGen {
    /// MC_ExtSetPointGenEnable's state (`Enabled`, StateDWord bit 14).
    pub(super) enabled: bool,
    /// The position monitored for InTargetPosition (None: no target monitoring).
    pub(super) target: Option<f64>,
    /// The latest sample, and how long ago it arrived (s).
    sample: Kinematics,
    age: f64,
    /// A sample arrived since the last cycle.
    fresh: bool,
    /// The stream stalls after this long without a sample (s).
    timeout: f64,
}

impl Axis {
    /// MC_ExtSetPointGenEnable: at standstill (or already enabled: new target and timeout).
    pub(super) fn submit_ext_enable(
        &mut self,
        target: Option<f64>,
        relative: bool,
        timeout: f64,
    ) -> Result<(), ErrorId> {
        if !(timeout.is_finite() && timeout > 0.0 && timeout <= 10.0)
            || target.is_some_and(|t| !t.is_finite())
        {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        if !self.ext.enabled && self.state() != AxisState::Standstill {
            return Err(ErrorId::AXIS_CANNOT_BE_STARTED);
        }
        self.ext.enabled = true;
        self.ext.timeout = timeout;
        self.ext.target = target.map(|t| if relative { self.set.position + t } else { t });
        Ok(())
    }

    /// MC_ExtSetPointGenDisable: the axis no longer takes samples; one that is moving by them
    /// stops on its ramp (the client's motion ends with it).
    pub(super) fn submit_ext_disable(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        if self.runs(JobKind::External) {
            self.stop_external(cx, None);
        }
        self.ext = ExtGen::default();
    }

    /// MC_ExtSetPointGenFeed: a sample for the present cycle. The first one starts the
    /// generator's motion (from standstill, where the axis is: a first sample elsewhere is a
    /// jump and refused).
    pub(super) fn submit_ext_feed(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
        sample: Kinematics,
        direction: i8,
    ) -> Result<(), ErrorId> {
        if !self.ext.enabled {
            return Err(ErrorId::EXT_SETPOINT_GEN_NOT_ENABLED);
        }
        let p = self.p();
        let vmax = p.axis_velo_max * (1.0 + 1e-9);
        let consistent = match direction {
            1 => sample.velocity >= 0.0,
            -1 => sample.velocity <= 0.0,
            0 => sample.velocity == 0.0,
            _ => false,
        };
        if ![sample.position, sample.velocity, sample.acceleration]
            .iter()
            .all(|x| x.is_finite())
            || sample.velocity.abs() > vmax
            || sample.acceleration.abs()
                > p.axis_maximum_acceleration.max(p.axis_maximum_deceleration) * (1.0 + 1e-9)
            || !consistent
        {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        let running = self.runs(JobKind::External);
        if !running {
            // The first sample: from standstill, continuing the set position without a jump.
            if self.state() != AxisState::Standstill {
                return Err(ErrorId::AXIS_CANNOT_BE_STARTED);
            }
            if (sample.position - self.set.position).abs() > vmax * self.cycle_time {
                return Err(ErrorId::EXT_SETPOINT_INVALID);
            }
            if sample.velocity != 0.0 {
                self.check_feed_enable(sample.velocity.signum())?;
            }
            let mut job = Job::new(id, JobKind::External);
            job.buffer_mode = BufferMode::Aborting;
            job.velocity = p.axis_velo_max;
            job.acc = p.axis_acc;
            job.dec = p.axis_dec;
            job.jerk = p.axis_jerk;
            // Reported as the generator's own motion (no FB output: the feed is a function).
            job.id = 0;
            self.enqueue(cx, job)?;
        }
        self.ext.sample = Kinematics {
            jerk: 0.0,
            ..sample
        };
        self.ext.age = 0.0;
        self.ext.fresh = true;
        Ok(())
    }

    /// One cycle of the generator's motion: the sample extrapolated to now, checked; a stalled
    /// stream or a bad sample stops the axis on its ramp with the error.
    pub(super) fn step_external(&mut self, cx: &mut Ctx<'_, impl EventSink>, dt: f64) {
        let g = &mut self.ext;
        if g.fresh {
            g.fresh = false;
        } else {
            g.age += dt;
        }
        let moving = g.sample.velocity != 0.0 || g.sample.acceleration != 0.0;
        if g.age > g.timeout && moving {
            // A client gone while it moved the axis; one that left it standing holds it.
            self.stop_external(cx, Some(ErrorId::EXT_SETPOINT_STALLED));
            return;
        }
        let (s, t) = (g.sample, g.age);
        let next = Kinematics {
            position: s.position + s.velocity * t + 0.5 * s.acceleration * t * t,
            velocity: s.velocity + s.acceleration * t,
            acceleration: s.acceleration,
            jerk: 0.0,
        };
        let p = self.p();
        let step = (next.position - self.set.position) / dt;
        if step.abs() > p.axis_velo_max * (1.0 + 1e-6) + 1e-9
            || next.velocity.abs() > p.axis_velo_max * (1.0 + 1e-9)
        {
            self.stop_external(cx, Some(ErrorId::EXT_SETPOINT_INVALID));
            return;
        }
        // An enabled software limit within the fast-stop distance of where the samples go:
        // stop now, so that the stop ends inside it.
        let (dec, jerk) = (
            p.axis_fast_dec.max(p.axis_dec),
            p.axis_fast_jerk.max(p.axis_jerk),
        );
        // The velocity the samples really move at, whatever they declare.
        let v = if step.abs() > next.velocity.abs() {
            step
        } else {
            next.velocity
        };
        let reach = stop_distance(v, next.acceleration, dec, jerk) + 2.0 * v.abs() * dt;
        let ahead_max = if v > 0.0 { reach } else { 0.0 };
        let ahead_min = if v < 0.0 { reach } else { 0.0 };
        let beyond = (p.axis_en_max_soft_pos_limit
            && next.position + ahead_max > p.axis_max_soft_pos_limit)
            || (p.axis_en_min_soft_pos_limit
                && next.position - ahead_min < p.axis_min_soft_pos_limit);
        if beyond {
            self.stop_external(cx, Some(ErrorId::SOFT_LIMIT_REACHED));
            return;
        }
        self.set = next;
    }

    /// Ends the generator's motion: the axis brakes on its ramp from where the stream left it;
    /// with `error` it is an axis error (ErrorStop, MC_Reset to go on) — a stalled stream is a
    /// client gone, and the feed has no FB of its own to report it.
    fn stop_external(&mut self, cx: &mut Ctx<'_, impl EventSink>, error: Option<ErrorId>) {
        match error {
            Some(e) => {
                self.enter_error(cx, e);
                self.ext = ExtGen::default();
            }
            None => {
                if let Some(mut j) = self.job.take() {
                    j.finish_done(cx);
                }
                let p = self.p();
                let mut h = Job::new(0, JobKind::Halt);
                h.dec = p.axis_dec;
                h.acc = p.axis_acc;
                h.jerk = p.axis_jerk;
                h.velocity = self.set.velocity.abs().max(EPS_V);
                self.start_job(cx, h);
            }
        }
    }

    /// A motion command to an axis the generator moves needs #1066 (§4.4.1); a halt or a stop
    /// never does.
    pub(super) fn admit_to_external(&self) -> Result<(), ErrorId> {
        if self.runs(JobKind::External) && !self.p().axis_allow_motion_cmd_to_ext_set_axis {
            return Err(ErrorId::EXT_SETPOINT_AXIS_COMMAND_NOT_ALLOWED);
        }
        Ok(())
    }
}
