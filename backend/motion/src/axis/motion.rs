//! Motion jobs: admission and resolution of move/halt/jog commands, the buffer and blending
//! (spec §3.8), planning from the current state, the per-cycle job step and the done criterion
//! (§3.11).

use super::*;

impl Axis {
    /// Checks shared by every motion command: state, lock, slave rule. Returns whether the
    /// axis is a slave that the command will decouple.
    pub(super) fn admit_motion(&self, buffer_mode: BufferMode) -> Result<(), ErrorId> {
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
        Ok((acc, dec, jerk))
    }

    pub(super) fn check_velocity(&self, v: f64) -> Result<f64, ErrorId> {
        if !(v > 0.0) || !v.is_finite() || v > self.p().axis_velo_max * (1.0 + 1e-12) {
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

    /// The job that a new buffered command would follow (the buffered one if any, else the
    /// running one), if it is a job that can be followed.
    pub(super) fn predecessor(&self) -> Option<&Job> {
        self.next.as_ref().or(self.job.as_ref())
    }

    /// Where a command issued now starts from: the previous target when it is buffered
    /// behind a positioning job, else the current set position.
    pub(super) fn start_position(&self, buffer_mode: BufferMode) -> f64 {
        if buffer_mode != BufferMode::Aborting {
            if let Some(p) = self.predecessor() {
                if p.is_positioning() && !p.is_endless() {
                    return p.target;
                }
            }
        }
        self.set.position
    }

    /// How a command with `buffer_mode` and `options` runs (§3.8): the buffer mode in effect
    /// and, when it is to take over at its own blending position, that position with the
    /// direction of travel there.
    ///
    /// The blending position must lie before the previous target (0x4296); already passed,
    /// the command acts at once (Aborting). An endless job takes no successor except at a
    /// blending position, so behind one (and behind no job) every buffer mode acts at once.
    pub(super) fn buffering(
        &self,
        buffer_mode: BufferMode,
        options: &MoveOptions,
    ) -> Result<(BufferMode, Option<(f64, f64)>), ErrorId> {
        let mut mode = buffer_mode;
        let mut blend_at = None;
        if let Some(bp) = options.blending_position {
            if mode != BufferMode::Aborting {
                if !bp.is_finite() {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                if let Some(prev) = self.predecessor() {
                    let dir = if prev.is_positioning() && !prev.is_endless() {
                        let dir = sign(prev.target - self.set.position);
                        if (bp - prev.target) * dir > 0.0 || (dir == 0.0 && bp != prev.target) {
                            return Err(ErrorId::BLENDING_POSITION_INVALID);
                        }
                        dir
                    } else if self.set.velocity.abs() > EPS_V {
                        sign(self.set.velocity)
                    } else {
                        prev.direction
                    };
                    if (self.set.position - bp) * dir >= 0.0 {
                        mode = BufferMode::Aborting;
                    } else {
                        blend_at = Some((bp, dir));
                    }
                }
            }
        }
        let running_endless = self.job.as_ref().is_some_and(|j| j.is_endless())
            || self
                .job
                .as_ref()
                .is_some_and(|j| j.kind == JobKind::Halt && j.id == 0);
        if mode != BufferMode::Aborting
            && (self.job.is_none() || (running_endless && blend_at.is_none()))
        {
            mode = BufferMode::Aborting;
        }
        Ok((mode, blend_at))
    }

    pub(super) fn submit_motion(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        cmd: Command,
    ) -> Result<(), ErrorId> {
        let mut job;
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
                        if !(end_velocity >= 0.0)
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
                let (v, acc, dec, jerk) = match mode {
                    JogMode::StandardSlow => {
                        (p.axis_velo_man_slow, p.axis_acc, p.axis_dec, p.axis_jerk)
                    }
                    JogMode::StandardFast => {
                        (p.axis_velo_man_fast, p.axis_acc, p.axis_dec, p.axis_jerk)
                    }
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
                        if !(position > 0.0) || !position.is_finite() {
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

        let (mode, blend_at) = self.buffering(job.buffer_mode, &job.options)?;
        job.blend_at = blend_at;
        if mode != BufferMode::Aborting && self.next.is_some() {
            return Err(ErrorId::BUFFER_FULL);
        }

        // Accepted from here on. A motion command decouples a slave (and with it ends a
        // superposition on it, abort table row 6).
        if self.coupling.is_some() {
            self.abort_superposition(cx);
            self.coupling = None;
        }
        if job.is_positioning() {
            self.last_target = Some(job.target);
        }
        if job.kind != JobKind::Halt {
            self.last_dec = job.dec;
            self.last_jerk = job.jerk;
        }
        job.buffer_mode = mode;
        if mode == BufferMode::Aborting {
            if let Some(mut n) = self.next.take() {
                n.finish_aborted(cx);
            }
            if let Some(mut j) = self.job.take() {
                if j.kind == JobKind::Halt && job.kind == JobKind::Halt {
                    // A halt on a halting axis keeps the stronger ramp.
                    job.dec = job.dec.max(j.dec);
                    job.jerk = job.jerk.max(j.jerk);
                }
                j.finish_aborted(cx);
            }
            self.start_job(cx, job);
        } else {
            // Queued: busy, not active.
            let out = job.out;
            if job.id != 0 {
                cx.report(job.id, out);
            }
            job.phase = Phase::Queued;
            self.next = Some(job);
            self.prepare_blend();
        }
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
            let target = self.job.map(|j| j.target).unwrap_or(self.set.position);
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

    /// (Re)plans the active job from the current set state. On a planner failure the axis
    /// stops on the closed-form ramp and the job reports PLANNING_FAILED.
    pub(super) fn plan_job_now(&mut self) -> bool {
        let ovr = self.override_ratio();
        let from = self.plan_origin();
        let velo_max = self.config.parameters.axis_velo_max;
        let Some(j) = self.job.as_mut() else {
            return true;
        };
        j.planned_override = ovr;
        // Taking over an accelerating axis with a weak jerk would let the velocity run on
        // past the axis maximum while the acceleration is ramped down: use at least the jerk
        // that keeps it within AxisVeloMax.
        if from.acceleration * from.velocity > 0.0 {
            let room = (velo_max - from.velocity.abs()).max(velo_max * 1e-6);
            let needed = from.acceleration * from.acceleration / (2.0 * room);
            if needed > j.jerk {
                j.jerk = needed;
            }
        }
        let res = match j.kind {
            JobKind::Positioning { continuous } => {
                // End velocity (continuous moves, blending) is kept before override.
                let end = j.end_velocity * ovr;
                if ovr <= 0.0 {
                    self.planner.plan_velocity(from, 0.0, &j.limits(1.0))
                } else if continuous && j.past_target {
                    // Past the target (passed slower than the end velocity): run up to it.
                    self.planner
                        .plan_velocity(from, end, &j.limits_passing(1.0, end))
                } else {
                    let lim = j.limits_passing(ovr, end);
                    // Never away from the target to reach an end velocity: the best
                    // reachable one instead, with a warning.
                    let planned = self
                        .planner
                        .plan_position_towards(from, j.target, end, &lim)
                        .map(|reached| {
                            j.planned_end = reached / ovr;
                            if (reached - end).abs() > 1e-9 * (1.0 + end.abs()) {
                                j.warn = Some(ErrorId::END_VELOCITY_ADJUSTED);
                            }
                            0.0
                        });
                    let toward = sign(j.target - from.position);
                    if continuous && end != 0.0 && self.planner.overshoots(j.target, toward) {
                        // Too fast to pass the target at any end velocity without running
                        // past it and back: it passes the target in its motion and goes on
                        // to the end velocity from there (never back to run at it again).
                        j.past_target = true;
                        j.planned_end = j.end_velocity;
                        j.warn = Some(ErrorId::END_VELOCITY_ADJUSTED);
                        self.planner
                            .plan_velocity(from, end, &j.limits_passing(1.0, end))
                    } else {
                        planned
                    }
                }
            }
            JobKind::Velocity | JobKind::JogHeld { released: false } => {
                self.planner
                    .plan_velocity(from, j.direction * j.velocity * ovr, &j.limits(1.0))
            }
            JobKind::JogHeld { released: true } | JobKind::Halt => {
                self.planner.plan_velocity(from, 0.0, &j.limits(1.0))
            }
            JobKind::Home => {
                let h = j.home;
                let v = match h.phase {
                    HomingPhase::SearchCam => h.search_dir * h.search_velocity * ovr,
                    HomingPhase::LeaveCam | HomingPhase::WaitCamFallingEdge => {
                        h.sync_dir * h.sync_velocity * ovr
                    }
                    _ => 0.0,
                };
                self.planner.plan_velocity(
                    from,
                    v,
                    &Limits {
                        velocity: h.search_velocity.max(h.sync_velocity),
                        acceleration: j.acc,
                        deceleration: j.dec,
                        jerk: j.jerk,
                    },
                )
            }
            JobKind::Gear => return true,
        };
        match res {
            Ok(_) => {
                let a = self.job.expect("planned above");
                let dir = sign(a.target - from.position);
                let blending =
                    a.kind == (JobKind::Positioning { continuous: false }) && a.end_velocity != 0.0;
                if blending && dir != 0.0 && self.planner.overshoots(a.target, dir) {
                    self.pass_target_to_successor(a.target, dir);
                }
                true
            }
            Err(_) => {
                let (dec, jerk) = (
                    j.dec.max(self.config.parameters.axis_dec),
                    j.jerk.max(self.config.parameters.axis_jerk),
                );
                self.planner.plan_fallback_stop(from, dec, jerk);
                j.kind = JobKind::Halt;
                j.options.ignore_position_monitoring = true;
                j.pending_error = Some(ErrorId::PLANNING_FAILED);
                false
            }
        }
    }

    /// No end velocity lets the running positioning pass its target without overshooting it
    /// (it is too fast to brake down to any in time): its blending successor takes over where
    /// the axis passes the target, from the motion it has then, and the running job is done
    /// there (with the warning that the blending velocity was not met).
    fn pass_target_to_successor(&mut self, target: f64, dir: f64) {
        let Some(b) = self.next.as_mut() else { return };
        if !b.buffer_mode.is_blending() || (b.blend_at.is_some() && !b.blend_done) {
            return;
        }
        b.blend_at = Some((target, dir));
        b.blend_done = true;
        if let Some(a) = self.job.as_mut() {
            a.warn = Some(ErrorId::END_VELOCITY_ADJUSTED);
        }
    }

    /// When a blending successor is queued behind a positioning job, the running job is
    /// re-planned to pass its target at the blending velocity (§3.8), as well as possible.
    pub(super) fn prepare_blend(&mut self) {
        let ovr = self.override_ratio();
        let (Some(a), Some(b)) = (self.job.as_ref(), self.next.as_ref()) else {
            return;
        };
        if !a.is_positioning() || a.is_endless() || a.phase != Phase::Moving {
            return;
        }
        if b.blend_at.is_some() {
            return; // takes over at its own blending position (see step_job)
        }
        let a_dir = sign(a.target - self.set.position);
        let (v1, v2) = (a.velocity, b.velocity);
        // Blending velocity at A's target, before override (A keeps it unscaled so that an
        // override change re-plans it too).
        let vb = if b.kind == JobKind::Halt {
            match b.buffer_mode {
                // Halt: travel on to the original target and start the stop ramp only there.
                BufferMode::BlendingPrevious | BufferMode::BlendingHigh => v1,
                // Halt: the target stays, only the stop ramp may get stronger.
                BufferMode::BlendingNext | BufferMode::BlendingLow => {
                    if b.dec > a.dec {
                        let dec = b.dec;
                        if let Some(a) = self.job.as_mut() {
                            a.dec = dec;
                        }
                        self.plan_job_now();
                    }
                    return;
                }
                _ => return,
            }
        } else {
            if !b.buffer_mode.is_blending() {
                return;
            }
            // Direction of the successor's travel from A's target.
            let b_dir = match b.kind {
                JobKind::Positioning { .. } => sign(b.target - a.target),
                JobKind::Velocity | JobKind::JogHeld { .. } => b.direction,
                _ => 0.0,
            };
            if b_dir == 0.0 || a_dir == 0.0 || b_dir != a_dir {
                return; // a reversal blends at rest, as Buffered
            }
            match b.buffer_mode {
                BufferMode::BlendingLow => v1.min(v2),
                BufferMode::BlendingPrevious => v1,
                BufferMode::BlendingNext => v2,
                BufferMode::BlendingHigh => v1.max(v2),
                _ => 0.0,
            }
        };
        if a_dir == 0.0 {
            return;
        }
        // A successor that stops at its target must be able to stop there from the blending
        // velocity: faster would overshoot its target and come back.
        let (vb_asked, mut vb) = (vb, vb);
        if b.kind == (JobKind::Positioning { continuous: false }) && ovr > 0.0 {
            let room = (b.target - a.target).abs();
            let (dec, jerk) = (b.dec.max(1e-9), b.jerk.max(1e-9));
            // The successor takes over in the cycle after the target: up to a cycle later.
            let dt = self.cycle_time;
            let needs = |v: f64| stop_distance(v, 0.0, dec, jerk) + v * dt;
            if needs(vb * ovr) > room {
                let (mut lo, mut hi) = (0.0, vb * ovr);
                for _ in 0..48 {
                    let mid = 0.5 * (lo + hi);
                    if needs(mid) > room {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                vb = lo / ovr;
            }
        }
        let capped = vb < vb_asked;
        let from = self.plan_origin();
        let target = a.target;
        let lim = a.limits_passing(ovr, vb * ovr);
        // Pass the target at the blending velocity, or at the best one reachable moving only
        // towards it (never backing up for a run-up, never overshooting and returning).
        let planned = if ovr > 0.0 {
            self.planner
                .plan_position_towards(from, target, a_dir * vb * ovr, &lim)
                .ok()
        } else {
            None
        };
        match planned {
            Some(_) if self.planner.overshoots(target, a_dir) => {
                self.pass_target_to_successor(target, a_dir);
            }
            Some(reached) => {
                if let Some(a) = self.job.as_mut() {
                    a.end_velocity = reached / ovr;
                    a.planned_end = a.end_velocity;
                    a.planned_override = ovr;
                    let adjusted = (reached - a_dir * vb * ovr).abs() > 1e-9 * (1.0 + vb * ovr);
                    if adjusted || capped {
                        a.warn = Some(ErrorId::END_VELOCITY_ADJUSTED);
                    }
                }
            }
            None => {
                if let Some(a) = self.job.as_mut() {
                    a.end_velocity = 0.0;
                }
                self.plan_job_now();
            }
        }
    }

    pub(super) fn step_job(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        dt: f64,
        fb: &DriveFeedback,
        master: Master,
    ) {
        let ovr = self.override_ratio();
        let Some(mut job) = self.job else {
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
                self.job = Some(job);
                self.plan_job_now();
                job = self.job.expect("set above");
            }
        }

        if job.kind == JobKind::Gear {
            self.follow_master(cx, &mut job, master, dt);
            self.job = Some(job);
            return;
        }

        // Override changes re-plan (never a velocity jump).
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
            self.job = Some(job);
            if endless_holding {
                // Continue at end velocity × override.
                let j = self.job.as_mut().expect("set");
                j.planned_override = ovr;
                let v = j.end_velocity * ovr;
                let _ = self
                    .planner
                    .plan_velocity(self.set, v, &j.limits_passing(1.0, v));
            } else {
                self.plan_job_now();
                // Re-planning restarts the milestone.
                let j = self.job.as_mut().expect("set");
                if j.phase == Phase::Holding {
                    j.phase = Phase::Moving;
                }
            }
            job = self.job.expect("set above");
            if job.out.in_velocity {
                let out = FbOutputs {
                    in_velocity: false,
                    ..job.out
                };
                job.emit(cx, out);
            }
        }

        if job.kind == JobKind::Home {
            self.job = Some(job);
            self.step_home(cx, dt, fb);
            return;
        }

        if let Some(k) = self.planner.step(dt) {
            self.set = k;
            self.set_has_superposition = false;
        }
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
                if reached != job.out.in_velocity {
                    let out = FbOutputs {
                        in_velocity: reached,
                        ..job.out
                    };
                    job.emit(cx, out);
                }
                job.phase = if reached {
                    Phase::Holding
                } else {
                    Phase::Moving
                };
                self.job = Some(job);
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
                    self.job = Some(job);
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
                self.job = Some(job);
            }
            JobKind::Positioning { continuous: false }
            | JobKind::Halt
            | JobKind::JogHeld { released: true } => {
                if !finished
                    || (job.kind == JobKind::Positioning { continuous: false }
                        && job.planned_override <= 0.0)
                {
                    self.job = Some(job);
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
                let done = self.done_criterion(&mut job, dt);
                match done {
                    None => {
                        self.job = Some(job);
                    }
                    Some(Ok(())) => {
                        if let Some(e) = job.pending_error {
                            job.finish_error(cx, e);
                        } else {
                            job.finish_done(cx);
                        }
                        self.job = None;
                        self.planner.clear();
                        self.set.velocity = 0.0;
                        self.set.acceleration = 0.0;
                        self.set.jerk = 0.0;
                        if self.mode == Mode::Stopping {
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
                                // The lock was removed by MC_Reset during the ramp.
                                self.mode = Mode::Enabled;
                            }
                        }
                        self.start_next(cx);
                    }
                    Some(Err(e)) => {
                        job.finish_error(cx, e);
                        self.job = None;
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
            JobKind::Home | JobKind::Gear => unreachable!(),
        }
    }

    /// §3.11: None = still waiting; Some(Ok) = done; Some(Err) = in-target timeout.
    pub(super) fn done_criterion(&mut self, job: &mut Job, dt: f64) -> Option<Result<(), ErrorId>> {
        let p = self.p();
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

    /// Activates the buffered job when the running one has ended.
    pub(super) fn start_next(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        if self.job.is_some() || self.mode != Mode::Enabled {
            return;
        }
        if let Some(mut n) = self.next.take() {
            if n.kind == JobKind::Halt {
                // Buffered halt at standstill: nothing to stop.
                n.activate(cx);
                if self.set.velocity.abs() <= EPS_V {
                    n.finish_done(cx);
                    return;
                }
            }
            n.since_keepalive = 0;
            self.start_job(cx, n);
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
