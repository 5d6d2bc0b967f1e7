//! Move, halt and jog (spec §5.1, §5.4): from a command to a job — admission (state, lock,
//! slave rule), dynamics and velocity, targets (relative, additive, modulo, inching), feed
//! enables and soft limits — and starting a job. When a job runs behind another is the
//! buffer's (`blending.rs`); how it is planned, `planning.rs`'s.

use super::*;

impl Axis {
    /// Checks shared by every motion command: state, lock, slave rule. Returns whether the
    /// axis is a slave that the command will decouple.
    pub(super) fn admit_motion(&self, buffer_mode: BufferMode) -> Result<(), ErrorId> {
        self.admit_to_group()?;
        match self.state() {
            AxisState::Standstill | AxisState::DiscreteMotion | AxisState::ContinuousMotion => {
                Ok(())
            }
            AxisState::SynchronizedMotion => {
                if !self.p().axis_allow_motion_cmd_to_slave_axis {
                    Err(ErrorId::SLAVE_COMMAND_NOT_ALLOWED)
                } else if buffer_mode != BufferMode::Aborting {
                    Err(ErrorId::INVALID_MODE)
                } else {
                    Ok(())
                }
            }
            _ => Err(ErrorId::AXIS_CANNOT_BE_STARTED),
        }
    }

    /// Resolves 0 → axis default and checks the dynamics of a move.
    pub(super) fn dynamics(&self, d: Dynamics) -> Result<(f64, f64, f64), ErrorId> {
        let p = self.p();
        let pick = |v: f64, default: f64| {
            if v == 0.0 {
                Ok(default)
            } else if v > 0.0 && v.is_finite() {
                Ok(v)
            } else {
                Err(ErrorId::PARAMETER_NOT_CORRECT)
            }
        };
        let acc = pick(d.acceleration, p.axis_acc)?;
        let dec = pick(d.deceleration, p.axis_dec)?;
        let jerk = pick(d.jerk, p.axis_jerk)?;
        if acc > p.axis_maximum_acceleration * (1.0 + 1e-12)
            || dec > p.axis_maximum_deceleration * (1.0 + 1e-12)
        {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        Ok(self.scaled_dynamics(acc, dec, jerk))
    }

    /// MC_SetOverride's AccFactor and JerkFactor on the dynamics of a motion command (not on
    /// MC_Halt, MC_Stop or an error stop: a stop keeps its full deceleration).
    pub(super) fn scaled_dynamics(&self, acc: f64, dec: f64, jerk: f64) -> (f64, f64, f64) {
        (
            acc * self.acc_factor,
            dec * self.acc_factor,
            jerk * self.jerk_factor,
        )
    }

    pub(super) fn check_velocity(&self, v: f64) -> Result<f64, ErrorId> {
        if v <= 0.0 || !v.is_finite() || v > self.p().axis_velo_max * (1.0 + 1e-12) {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        Ok(v)
    }

    pub(super) fn check_soft_limits(&self, target: f64) -> Result<(), ErrorId> {
        let p = self.p();
        if p.axis_en_max_soft_pos_limit && target > p.axis_max_soft_pos_limit {
            return Err(ErrorId::TARGET_ABOVE_SOFT_LIMIT);
        }
        if p.axis_en_min_soft_pos_limit && target < p.axis_min_soft_pos_limit {
            return Err(ErrorId::TARGET_BELOW_SOFT_LIMIT);
        }
        Ok(())
    }

    /// Feed enable and hardware limit switch of the direction of travel.
    pub(super) fn check_feed_enable(&self, direction: f64) -> Result<(), ErrorId> {
        if (direction > 0.0 && !self.enable_positive) || (direction < 0.0 && !self.enable_negative)
        {
            return Err(ErrorId::FEED_ENABLE_MISSING);
        }
        if (direction > 0.0 && self.limit_positive) || (direction < 0.0 && self.limit_negative) {
            return Err(ErrorId::LIMIT_SWITCH);
        }
        Ok(())
    }

    /// A move, halt or jog command: checks it, resolves its target and dynamics and hands
    /// the job to the buffer, which decides when it runs.
    pub(super) fn submit_motion(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        cmd: Command,
    ) -> Result<(), ErrorId> {
        if !matches!(cmd.kind, CommandKind::Halt { .. }) {
            self.admit_to_external()?;
        }
        let mut job;
        let continuous_update = match cmd.kind {
            CommandKind::MoveAbsolute(m)
            | CommandKind::MoveRelative(m)
            | CommandKind::MoveAdditive(m)
            | CommandKind::MoveModulo { move_: m, .. }
            | CommandKind::MoveContinuousAbsolute { move_: m, .. }
            | CommandKind::MoveContinuousRelative { move_: m, .. } => m.options.continuous_update,
            CommandKind::Halt { options, .. } => options.continuous_update,
            _ => false,
        };
        if continuous_update {
            // ContinuousUpdate is MoveVelocity's input only.
            return Err(ErrorId::COMMAND_NOT_PERMITTED);
        }
        match cmd.kind {
            CommandKind::MoveAbsolute(m)
            | CommandKind::MoveRelative(m)
            | CommandKind::MoveAdditive(m)
            | CommandKind::MoveModulo { move_: m, .. }
            | CommandKind::MoveContinuousAbsolute { move_: m, .. }
            | CommandKind::MoveContinuousRelative { move_: m, .. } => {
                self.admit_motion(m.buffer_mode)?;
                let v = self.check_velocity(m.velocity)?;
                let (acc, dec, jerk) = self.dynamics(m.dynamics)?;
                if !m.position.is_finite() {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                let start = self.start_position(m.buffer_mode);
                let mut continuous = false;
                let mut end_v = 0.0;
                let mut modulo = None;
                let target = match cmd.kind {
                    CommandKind::MoveAbsolute(_) => m.position,
                    CommandKind::MoveRelative(_) => start + m.position,
                    CommandKind::MoveAdditive(_) => {
                        let base = match self.predecessor() {
                            Some(p) if p.is_endless() => self.set.position,
                            _ => self.last_target.unwrap_or(self.set.position),
                        };
                        base + m.position
                    }
                    CommandKind::MoveModulo { direction, .. } => {
                        let period = self.period();
                        let tf = self.p().axis_modulo_tolerance_window;
                        // The rules follow from where the move will start, not from the
                        // buffer mode asked for: acting at once (Aborting, or Buffered/
                        // blending behind endless motion, §3.8) it starts from the present
                        // state — at rest (also while a finished move still settles) from
                        // standstill, else from motion; queued Buffered behind a discrete
                        // move from that move's standstill; blending, or taking over at a
                        // blending position, from motion. An invalid blending position is
                        // rejected below; until then take the mode as asked.
                        let (mode, blend_at) = self
                            .buffering(m.buffer_mode, &m.options)
                            .unwrap_or((m.buffer_mode, None));
                        let at_rest = self.set.velocity.abs() <= EPS_V
                            && self.set.acceleration.abs() <= EPS_V;
                        let from_standstill = blend_at.is_none()
                            && match mode {
                                BufferMode::Aborting => {
                                    at_rest || self.state() == AxisState::Standstill
                                }
                                BufferMode::Buffered => true,
                                _ => false,
                            };
                        // Validate now (errors are the command's verdict); moves from motion
                        // are resolved against the state at their start.
                        let end = modulo_end_position(
                            start,
                            m.position,
                            period,
                            tf,
                            direction,
                            from_standstill,
                        )?;
                        if !from_standstill {
                            // From motion the direction must not be reversed (spec §5.1.4);
                            // shortest way keeps the direction of travel.
                            let travel = sign(self.set.velocity);
                            let reversed = match direction {
                                Direction::Positive => travel < 0.0,
                                Direction::Negative => travel > 0.0,
                                _ => false,
                            };
                            if reversed {
                                return Err(ErrorId::INVALID_MODE);
                            }
                            modulo = Some((m.position, direction));
                        }
                        end
                    }
                    CommandKind::MoveContinuousAbsolute { end_velocity, .. }
                    | CommandKind::MoveContinuousRelative { end_velocity, .. } => {
                        if end_velocity < 0.0
                            || !end_velocity.is_finite()
                            || end_velocity > self.p().axis_velo_max
                        {
                            return Err(ErrorId::PARAMETER_NOT_CORRECT);
                        }
                        continuous = true;
                        let t = if matches!(cmd.kind, CommandKind::MoveContinuousAbsolute { .. }) {
                            m.position
                        } else {
                            start + m.position
                        };
                        let dir = if t >= start { 1.0 } else { -1.0 };
                        end_v = dir * end_velocity;
                        t
                    }
                    _ => unreachable!(),
                };
                self.check_soft_limits(target)?;
                let dir = (target - start).signum();
                if target != start {
                    self.check_feed_enable(dir)?;
                }
                job = Job::new(cmd.id, JobKind::Positioning { continuous });
                job.velocity = v;
                job.acc = acc;
                job.dec = dec;
                job.jerk = jerk;
                job.target = target;
                job.end_velocity = end_v;
                job.continuous_velocity = end_v.abs();
                job.buffer_mode = m.buffer_mode;
                job.options = m.options;
                job.modulo = modulo;
            }
            CommandKind::MoveVelocity {
                velocity,
                dynamics,
                direction,
                buffer_mode,
                options,
            } => {
                self.admit_motion(buffer_mode)?;
                let v = self.check_velocity(velocity)?;
                let (acc, dec, jerk) = self.dynamics(dynamics)?;
                let dir = match direction {
                    Direction::Positive => 1.0,
                    Direction::Negative => -1.0,
                    _ => return Err(ErrorId::COMMAND_NOT_PERMITTED),
                };
                self.check_feed_enable(dir)?;
                job = Job::new(cmd.id, JobKind::Velocity);
                job.velocity = v;
                job.direction = dir;
                job.acc = acc;
                job.dec = dec;
                job.jerk = jerk;
                job.buffer_mode = buffer_mode;
                job.options = options;
            }
            CommandKind::Halt {
                deceleration,
                jerk,
                buffer_mode,
                options,
            } => {
                self.admit_motion(buffer_mode)?;
                if !deceleration.is_finite() || !jerk.is_finite() {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                let (dec, jk) = self.stop_dynamics(deceleration, jerk);
                job = Job::new(cmd.id, JobKind::Halt);
                job.dec = dec;
                job.acc = dec.max(self.p().axis_acc);
                job.jerk = jk;
                job.velocity = self.p().axis_velo_max;
                job.buffer_mode = buffer_mode;
                job.options = options;
            }
            CommandKind::Jog {
                mode,
                forward,
                position,
                velocity,
                dynamics,
                deadman,
            } => {
                self.admit_motion(BufferMode::Aborting)?;
                if !deadman.is_finite() || deadman < 0.0 {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                let dir = if forward { 1.0 } else { -1.0 };
                let p = self.p();
                let scaled = |v: f64| {
                    let (a, d, j) = self.scaled_dynamics(p.axis_acc, p.axis_dec, p.axis_jerk);
                    (v, a, d, j)
                };
                let (v, acc, dec, jerk) = match mode {
                    JogMode::StandardSlow => scaled(p.axis_velo_man_slow),
                    JogMode::StandardFast => scaled(p.axis_velo_man_fast),
                    _ => {
                        let v = self.check_velocity(velocity)?;
                        let (a, d, j) = self.dynamics(dynamics)?;
                        (v, a, d, j)
                    }
                };
                let v = self.check_velocity(v)?;
                self.check_feed_enable(dir)?;
                match mode {
                    JogMode::Inching | JogMode::InchingModulo => {
                        if position <= 0.0 || !position.is_finite() {
                            return Err(ErrorId::PARAMETER_NOT_CORRECT);
                        }
                        let s = self.set.position;
                        let target = if mode == JogMode::Inching {
                            s + dir * position
                        } else {
                            self.inching_modulo_target(s, position, forward)
                        };
                        self.check_soft_limits(target)?;
                        job = Job::new(cmd.id, JobKind::Positioning { continuous: false });
                        job.target = target;
                    }
                    _ => {
                        job = Job::new(cmd.id, JobKind::JogHeld { released: false });
                        // Counted in whole cycles so that it fires exactly `deadman` after
                        // the last keepalive (a float sum would drift by a cycle).
                        job.deadman_cycles = if deadman > 0.0 {
                            ((deadman / self.cycle_time) - 1e-9).ceil().max(1.0) as u32
                        } else {
                            0
                        };
                    }
                }
                job.velocity = v;
                job.direction = dir;
                job.acc = acc;
                job.dec = dec;
                job.jerk = jerk;
            }
            _ => return Err(ErrorId::COMMAND_NOT_PERMITTED),
        }
        self.enqueue(cx, job)
    }

    /// ContinuousUpdate: a running MoveVelocity started with it takes new inputs (checked as
    /// at its start) as quickly as possible — re-planned here, sent to the drive there.
    pub(super) fn update_inputs(
        &mut self,
        target: CommandId,
        velocity: f64,
        dynamics: Dynamics,
    ) -> Result<(), ErrorId> {
        let job = self
            .job
            .filter(|j| j.id == target && target != 0)
            .ok_or(ErrorId::COMMAND_UNKNOWN)?;
        if job.kind != JobKind::Velocity || !job.options.continuous_update {
            return Err(ErrorId::COMMAND_NOT_PERMITTED);
        }
        let v = self.check_velocity(velocity)?;
        let (acc, dec, jerk) = self.dynamics(dynamics)?;
        if self.drive_executed() && dynamics.jerk != 0.0 {
            return Err(ErrorId::INPUT_NOT_ON_DRIVE_EXECUTED_AXIS);
        }
        let j = self.job.as_mut().expect("checked");
        j.velocity = v;
        j.acc = acc;
        j.dec = dec;
        j.jerk = jerk;
        j.phase = Phase::Moving;
        self.last_dec = dec;
        self.last_jerk = jerk;
        self.plan_job_now();
        Ok(())
    }

    /// MC_Jog INCHING_MODULO: the next multiple of `step` after `s` in the direction of
    /// travel. On a modulo axis the multiples count from 0 of each turn (modulo coordinates),
    /// so the stops repeat every turn even when the period is no multiple of the step: the
    /// last stop of a turn is followed by 0 of the next one.
    pub(super) fn inching_modulo_target(&self, s: f64, step: f64, forward: bool) -> f64 {
        let period = self.period();
        let (base, m) = if self.config.modulo && period > 0.0 {
            let base = (s / period).floor() * period;
            let m = (s - base).clamp(0.0, period);
            // Standing on the end of a turn (within float noise) is standing on 0 of the next.
            if period - m <= 1e-9 * step {
                (base + period, 0.0)
            } else {
                (base, m)
            }
        } else {
            (0.0, s)
        };
        let n = m / step;
        let mut t = if forward {
            ((n + 1e-9).floor() + 1.0) * step
        } else {
            ((n - 1e-9).ceil() - 1.0) * step
        };
        if self.config.modulo && period > 0.0 {
            if t >= period * (1.0 - 1e-12) {
                t = period;
            } else if t < 0.0 {
                // The last stop of the turn before: the highest multiple below the period.
                t = ((period / step - 1e-9).ceil() - 1.0) * step - period;
            }
        }
        base + t
    }

    /// MC_Halt/MC_Stop dynamics: ≤ 0 means the last move's; never weaker than the running job.
    pub(super) fn stop_dynamics(&self, dec: f64, jerk: f64) -> (f64, f64) {
        let mut d = if dec > 0.0 { dec } else { self.last_dec };
        let mut j = if jerk > 0.0 { jerk } else { self.last_jerk };
        if let Some(job) = &self.job {
            if job.dec > 0.0 {
                d = d.max(job.dec);
            }
            if job.jerk > 0.0 {
                j = j.max(job.jerk);
            }
        }
        (d, j)
    }

    pub(super) fn start_job(&mut self, cx: &mut Ctx<'_, impl EventSink>, mut job: Job) {
        job.activate(cx);
        if self.drive_executed() || job.kind == JobKind::DriveHome {
            self.drive_job_started();
        }
        if job.kind != JobKind::Halt && job.id != 0 {
            // A motion command clears it; an internal job (a monitoring stop's) does not.
            self.has_been_stopped = false;
        }
        self.new_target = job.is_positioning() && self.set.velocity.abs() > EPS_V;
        job.since_keepalive = 0;
        if job.kind == (JobKind::Positioning { continuous: true }) && !job.past_target {
            // The end velocity keeps the direction from where the move really starts (a
            // queued move's start was only a guess when it was accepted).
            let d = sign(job.target - self.set.position);
            if d != 0.0 {
                job.end_velocity = d * job.continuous_velocity;
            }
        }
        if job.kind != (JobKind::Positioning { continuous: false }) {
            // MoveAdditive after an endless motion, a halt or a stop starts from the set
            // position (spec §5.1.3).
            self.last_target = None;
        }
        self.job = Some(job);
        if job.modulo.is_some() {
            self.resolve_modulo_from_motion();
            let target = self
                .job
                .as_ref()
                .map(|j| j.target)
                .unwrap_or(self.set.position);
            if let Err(e) = self.check_soft_limits(target) {
                // The oriented stop would cross a software limit: stop safely, with the
                // error, not at the position (spec §5.1.4).
                self.stop_internally(cx, e, false);
                return;
            }
            self.last_target = Some(target);
        }
        self.plan_job_now();
        self.prepare_blend();
    }

    /// A modulo move started from motion takes the shortest path in the direction of travel
    /// that it can still brake for (extra turns are ignored, no reversal).
    pub(super) fn resolve_modulo_from_motion(&mut self) {
        let period = self.period();
        let tf = self.p().axis_modulo_tolerance_window;
        let set = self.set;
        if let Some(j) = self.job.as_mut() {
            if let Some((t, dir)) = j.modulo.take() {
                let travel_dir = if set.velocity.abs() > EPS_V {
                    set.velocity.signum()
                } else {
                    match dir {
                        Direction::Negative => -1.0,
                        _ => 1.0,
                    }
                };
                let d = if travel_dir > 0.0 {
                    Direction::Positive
                } else {
                    Direction::Negative
                };
                let sd = stop_distance(set.velocity, set.acceleration, j.dec, j.jerk);
                let brake_point = set.position + travel_dir * sd;
                if let Ok(mut end) = modulo_end_position(
                    brake_point,
                    t.rem_euclid(period),
                    period,
                    tf.min(0.0),
                    d,
                    false,
                ) {
                    // Past the brake point in the travel direction.
                    while (end - brake_point) * travel_dir < 0.0 {
                        end += travel_dir * period;
                    }
                    j.target = end;
                }
            }
        }
    }

    /// After GearOut (or when a slave loses its master while moving): keep the current
    /// velocity as an endless motion that no command owns.
    pub(super) fn continue_at_current_velocity(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        if self.set.velocity.abs() <= EPS_V && self.set.acceleration == 0.0 {
            self.set.velocity = 0.0;
            return;
        }
        let p = self.p();
        let mut j = Job::new(0, JobKind::Velocity);
        j.velocity = self.set.velocity.abs().min(p.axis_velo_max).max(EPS_V);
        j.direction = self.set.velocity.signum();
        j.acc = p.axis_acc;
        j.dec = p.axis_dec;
        j.jerk = p.axis_jerk;
        // Not scaled by the override: it continues the master's speed.
        j.planned_override = 1.0;
        self.start_job(cx, j);
        let ovr = self.override_ratio();
        if let Some(j) = self.job.as_mut() {
            let _ = self
                .planner
                .plan_velocity(self.set, j.direction * j.velocity, &j.limits(1.0));
            j.planned_override = ovr;
        }
    }
}
