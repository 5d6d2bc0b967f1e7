//! The buffer and blending (spec §3.8): where a buffered command starts, which buffer mode is
//! in effect (a blending position; nothing to wait for behind endless motion), the one
//! buffered job and its turn, and blending — the running job re-planned to pass its target
//! at the blending velocity, or its target handed over to the successor where no velocity
//! lets it pass. Kept together because every rule here depends on the pair (running job,
//! buffered job) and nothing else does.

use super::*;

impl Axis {
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

    /// Takes an admitted job into the buffer (§3.8): at once (Aborting, or nothing to wait
    /// for), or as the one buffered job; refused only when the buffer is full or its blending
    /// position is invalid. From here on the command is accepted.
    pub(super) fn enqueue(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        mut job: Job,
    ) -> Result<(), ErrorId> {
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
        self.cancel_cam_in(cx, End::Aborted);
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

    /// No end velocity lets the running positioning pass its target without overshooting it
    /// (it is too fast to brake down to any in time): its blending successor takes over where
    /// the axis passes the target, from the motion it has then, and the running job is done
    /// there (with the warning that the blending velocity was not met).
    pub(super) fn pass_target_to_successor(&mut self, target: f64, dir: f64) {
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
}
