//! MC_MoveSuperImposed / MC_AbortSuperposition (spec §5.2, §6.13): a distance laid over the
//! running motion as a function of its travel. Apart from the jobs because it outlives them
//! (ResumeAfterMotionStop) and lays its increment on whatever setpoint the job gave.

use super::*;

/// MC_MoveSuperImposed on this axis: the one running, and whether `set` carries it yet.
#[derive(Debug, Default)]
pub(super) struct SuperpositionState {
    pub(super) running: Option<Superimposed>,
    /// `set` includes what the superposition added (true between its step and the next
    /// sample of the main motion).
    in_set: bool,
}

impl SuperpositionState {
    /// The main motion (or a master) wrote `set` anew: what the superposition added is no
    /// longer in it.
    pub(super) fn main_motion_sampled(&mut self) {
        self.in_set = false;
    }
}

/// A running MC_MoveSuperImposed: `distance` is laid over the main motion as a quintic
/// (C² smooth) function of the main motion's travel `u` over `length` (spec §5.2.1, §6.13).
#[derive(Clone, Copy, Debug)]
pub(super) struct Superimposed {
    pub(super) cmd: Held,
    /// Effective distance (signed, axis coordinates); reduced when infeasible (warning).
    pub(super) distance: f64,
    /// Main-motion travel over which it is spread.
    pub(super) length: f64,
    /// Main-motion travel so far.
    pub(super) travelled: f64,
    pub(super) applied: f64,
    pub(super) option: SuperpositionAbortOption,
    pub(super) last_position: f64,
    pub(super) last_direction: f64,
    /// Largest velocity the superposition may add (the main motion may run faster than
    /// `velocity_process`; progress is then rate-limited instead of exceeding it).
    pub(super) velocity_diff: f64,
    /// Acceleration limit of the superimposed motion.
    pub(super) acc_limit: f64,
    /// Velocity and acceleration it added in the last cycle.
    pub(super) added: (f64, f64),
}

/// The superposition shape and its first two derivatives on [0, 1].
pub(super) fn smoothstep5(x: f64) -> (f64, f64, f64) {
    let x = x.clamp(0.0, 1.0);
    let (x2, x3) = (x * x, x * x * x);
    (
        10.0 * x3 - 15.0 * x3 * x + 6.0 * x3 * x2,
        30.0 * x2 - 60.0 * x3 + 30.0 * x2 * x2,
        60.0 * x - 180.0 * x2 + 120.0 * x3,
    )
}
/// max s' and max |s''| of [`smoothstep5`].
const SMOOTHSTEP5_MAX_SLOPE: f64 = 1.875;
const SMOOTHSTEP5_MAX_CURVATURE: f64 = 5.773_502_691_896_258;

impl Axis {
    pub(super) fn submit_superposition(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
        sp: Superposition,
    ) -> Result<(), ErrorId> {
        let p = self.p();
        let finite = [
            sp.distance,
            sp.velocity_diff,
            sp.acceleration,
            sp.deceleration,
            sp.velocity_process,
            sp.length,
        ]
        .iter()
        .all(|x| x.is_finite());
        if !finite
            || sp.velocity_diff <= 0.0
            || sp.velocity_process <= 0.0
            || sp.length <= 0.0
            || sp.acceleration < 0.0
            || sp.deceleration < 0.0
        {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        match self.state() {
            // Not over a torque or a client's samples: neither is a planned motion to lay a
            // distance on.
            _ if self
                .job
                .is_some_and(|j| matches!(j.kind, JobKind::Torque | JobKind::External)) =>
            {
                return Err(ErrorId::AXIS_CANNOT_BE_STARTED);
            }
            AxisState::DiscreteMotion
            | AxisState::ContinuousMotion
            | AxisState::SynchronizedMotion => {}
            AxisState::Standstill => return Err(ErrorId::AXIS_NOT_MOVING),
            _ => return Err(ErrorId::AXIS_CANNOT_BE_STARTED),
        }
        let dir = if self.set.velocity.abs() > EPS_V {
            self.set.velocity.signum()
        } else {
            return Err(ErrorId::AXIS_NOT_MOVING);
        };
        let acc = if sp.acceleration > 0.0 {
            sp.acceleration
        } else {
            p.axis_acc
        };
        let dec = if sp.deceleration > 0.0 {
            sp.deceleration
        } else {
            p.axis_dec
        };
        let a_lim = acc.min(dec);
        // The limits hold for the velocity the main motion really has, if that is higher.
        let vp = sp.velocity_process.max(self.set.velocity.abs());
        let d = sp.distance.abs();
        // Without reversal a slow-down can take at most the process velocity; a speed-up at
        // most what is left up to the maximum velocity.
        let vdiff = if sp.distance < 0.0 {
            sp.velocity_diff.min(vp)
        } else {
            sp.velocity_diff.min((p.axis_velo_max - vp).max(0.0))
        };
        let limited = matches!(
            sp.mode,
            SuperpositionMode::VeloReductionLimitedMotion
                | SuperpositionMode::LengthReductionLimitedMotion
                | SuperpositionMode::AccReductionLimitedMotion
        );
        // Main-motion travel available: "limited" lengths count this axis's own travel.
        let l_max = if limited {
            sp.length - sp.distance
        } else {
            sp.length
        };
        if l_max <= 0.0 {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        let need = |len: f64| {
            (
                vp * d * SMOOTHSTEP5_MAX_SLOPE / len,
                vp * vp * d * SMOOTHSTEP5_MAX_CURVATURE / (len * len),
            )
        };
        let length = match sp.mode {
            SuperpositionMode::LengthReductionAdditiveMotion
            | SuperpositionMode::LengthReductionLimitedMotion => {
                let by_v = vp * d * SMOOTHSTEP5_MAX_SLOPE / vdiff.max(EPS_V);
                let by_a = (vp * vp * d * SMOOTHSTEP5_MAX_CURVATURE / a_lim).sqrt();
                by_v.max(by_a).min(l_max).max(EPS_V)
            }
            _ => l_max,
        };
        let (nv, na) = need(length);
        let scale = (vdiff / nv.max(EPS_V)).min(a_lim / na.max(EPS_V)).min(1.0);
        let wanted = dir * sp.distance.signum() * d * if d > 0.0 { scale } else { 1.0 };
        // Never beyond an enabled soft limit: the target of the running move moves with the
        // superposition, so only what keeps it within the limits is done (as far as possible,
        // with the warning, like any superposition the parameters do not allow in full).
        let distance = self.superposition_room(wanted);
        let warning = d > 0.0 && (scale < 1.0 - 1e-12 || distance != wanted);
        // A new superposition replaces the running one (what it applied so far stays).
        self.abort_superposition(cx);
        let out = FbOutputs {
            busy: true,
            active: true,
            warning,
            warning_id: if warning {
                ErrorId::SUPERPOSITION_INCOMPLETE.0
            } else {
                0
            },
            ..FbOutputs::default()
        };
        let cmd = Held::start(cx, id, out);
        self.superposition.running = Some(Superimposed {
            cmd,
            distance,
            length,
            travelled: 0.0,
            applied: 0.0,
            option: sp.abort_option,
            last_position: self.set.position,
            last_direction: dir,
            velocity_diff: vdiff.max(EPS_V),
            acc_limit: a_lim,
            added: (0.0, 0.0),
        });
        Ok(())
    }

    /// The part of a superimposed `distance` still to come that keeps the target of the
    /// running positioning (which moves with it) within the enabled soft limits. Endless
    /// motion has no target: it brakes for the limit itself (and a coupled slave crossing
    /// one is an axis error), so there the distance is not limited.
    pub(super) fn superposition_room(&self, distance: f64) -> f64 {
        let p = self.p();
        let Some(target) = self
            .job
            .as_ref()
            .filter(|j| j.is_positioning())
            .map(|j| j.target)
        else {
            return distance;
        };
        if distance > 0.0 && p.axis_en_max_soft_pos_limit {
            distance.min((p.axis_max_soft_pos_limit - target).max(0.0))
        } else if distance < 0.0 && p.axis_en_min_soft_pos_limit {
            distance.max((p.axis_min_soft_pos_limit - target).min(0.0))
        } else {
            distance
        }
    }

    /// Ends a superposition with CommandAborted; what it applied stays.
    pub(super) fn abort_superposition(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        self.end_superposition(cx, End::Aborted);
    }

    /// Ends a superposition that cannot go on within the soft limits: Done as far as it got,
    /// with Warning 0x4243 (as a superposition the parameters do not allow in full).
    pub(super) fn end_superposition_incomplete(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        if let Some(sp) = self.superposition.running.as_mut() {
            warn_incomplete(cx, sp);
        }
        self.end_superposition(cx, End::Done);
    }

    /// Ends a superposition; what it applied stays. The velocity it was adding is handed to
    /// the main motion's planner, which takes it away smoothly.
    fn end_superposition(&mut self, cx: &mut Ctx<'_, impl EventSink>, end: End) {
        if let Some(mut sp) = self.superposition.running.take() {
            sp.cmd.end(cx, end);
            if sp.added != (0.0, 0.0)
                && self.mode != Mode::Disabled
                && self
                    .job
                    .as_ref()
                    .is_some_and(|j| j.kind != JobKind::Gear && j.kind != JobKind::Home)
            {
                self.plan_job_now();
            }
        }
    }

    /// The state plans start from: the setpoint without what a running superposition adds
    /// (it keeps adding it on top of the new plan).
    pub(super) fn plan_origin(&self) -> Kinematics {
        match self
            .superposition
            .running
            .filter(|_| self.superposition.in_set)
        {
            Some(sp) => Kinematics {
                velocity: self.set.velocity - sp.added.0,
                acceleration: self.set.acceleration - sp.added.1,
                ..self.set
            },
            None => self.set,
        }
    }

    /// Lays the superposition over the setpoint the job produced this cycle: the increment is
    /// folded into the running plan (and target, and coupling), so the main motion carries it
    /// from now on and its target moves by the distance (spec §5.2.1).
    pub(super) fn step_superposition(&mut self, cx: &mut Ctx<'_, impl EventSink>, dt: f64) {
        let Some(mut sp) = self.superposition.running else {
            return;
        };
        let base = self.set;
        let mut moved = base.position - sp.last_position;
        if moved.abs() < 1e-12 {
            moved = 0.0; // float noise of a standing main motion is no reversal
        }
        let travelling = self.job.as_ref().is_some_and(|j| j.kind != JobKind::Halt)
            && self.mode == Mode::Enabled;
        let stopped_by_override = self.override_ratio() <= 0.0;
        let abort = match sp.option {
            SuperpositionAbortOption::AbortAtStandstill => {
                !travelling
                    || (moved == 0.0 && !stopped_by_override)
                    || (moved != 0.0 && moved.signum() != sp.last_direction)
            }
            SuperpositionAbortOption::ResumeAfterStandstill => !travelling,
            SuperpositionAbortOption::ResumeAfterMotionStop => false,
        };
        // The main motion may have changed since the start (a new move under
        // ResumeAfterMotionStop, a stop at the soft limit): what is still to come must keep
        // its target within the soft limits too. Less is done, with the warning: by braking
        // within the room left where the superposition can, else it ends here.
        let to_come = sp.distance - sp.applied;
        let room = self.superposition_room(to_come);
        let prev = sp.added.0.abs();
        let cut_short =
            room != to_come && (room == 0.0 || prev * prev > 2.0 * sp.acc_limit * room.abs());
        if abort || cut_short {
            // This cycle's sample is the bare main motion: keep last cycle's contribution in
            // it so that the planner takes over from a continuous state (ending re-plans the
            // main motion from there; without it the velocity would step back by what the
            // superposition added).
            self.set.position += sp.added.0 * dt;
            self.set.velocity += sp.added.0;
            self.set.acceleration += sp.added.1;
            if self.planner.is_planned() && !self.ramping_in() {
                self.planner.shift(sp.added.0 * dt);
            }
            if let Some(c) = self.coupling.as_mut() {
                c.law.shift_slave(sp.added.0 * dt);
            }
            self.superposition.in_set = false;
            self.superposition.running = Some(sp);
            if abort {
                self.abort_superposition(cx);
            } else {
                self.end_superposition_incomplete(cx);
            }
            return;
        }
        if room != to_come {
            sp.distance = sp.applied + room;
            warn_incomplete(cx, &mut sp);
        }
        if moved != 0.0 {
            sp.last_direction = moved.signum();
        }
        // Where the profile wants the superposition to be, as a function of the main travel.
        sp.travelled += moved.abs();
        let x = (sp.travelled / sp.length).min(1.0);
        let desired = sp.distance * smoothstep5(x).0;
        // Follow it within the limits of the superimposed motion: never against the distance,
        // at most velocity_diff (and never beyond AxisVeloMax or a reversal of the main
        // motion), acceleration within its limit, braking in time for the full distance.
        // When the main motion runs faster than velocity_process the superposition lags the
        // profile and catches up; it is acceleration-limited, not jerk-limited (TwinCAT:
        // "Jerk not implemented").
        let dir = sign(sp.distance);
        let v_base = base.velocity.abs();
        let adds_speed = sp.distance * sp.last_direction > 0.0;
        let room = if adds_speed {
            (self.p().axis_velo_max - v_base).max(0.0)
        } else {
            v_base
        };
        let v_max = sp.velocity_diff.min(room);
        let prev = sp.added.0 * dir; // ≥ 0 in the direction of the distance
        let to_desired = (desired - sp.applied) * dir;
        let to_end = (sp.distance - sp.applied) * dir;
        let a = sp.acc_limit;
        let mut v = (to_desired / dt).min(v_max);
        v = v.clamp(prev - a * dt, prev + a * dt);
        v = v
            .min((2.0 * a * to_end.max(0.0)).sqrt())
            .min(to_end.max(0.0) / dt)
            .max(0.0);
        let delta = dir * v * dt;
        sp.applied += delta;
        if delta != 0.0 {
            if self.planner.is_planned() && !self.ramping_in() {
                self.planner.shift(delta);
            }
            if let Some(j) = self.job.as_mut() {
                j.target += delta;
            }
            if let Some(t) = self.last_target.as_mut() {
                *t += delta;
            }
            if let Some(c) = self.coupling.as_mut() {
                c.law.shift_slave(delta);
            }
            self.set.position += delta;
        }
        let complete =
            x >= 1.0 && (sp.distance - sp.applied).abs() <= 1e-9 * (1.0 + sp.distance.abs());
        if !complete {
            // Velocity the superposition adds (its increment per cycle, consistent with the
            // position by construction) and its acceleration (the change of that velocity).
            let v_add = delta / dt;
            let a_add = (v_add - sp.added.0) / dt;
            self.set.velocity += v_add;
            self.set.acceleration += a_add;
            self.superposition.in_set = true;
            sp.added = (v_add, a_add);
            sp.last_position = self.set.position;
            self.superposition.running = Some(sp);
        } else {
            sp.cmd.end(cx, End::Done);
            self.superposition.running = None;
        }
    }
}

/// Warning 0x4243 on a running superposition: it does less than asked.
fn warn_incomplete(cx: &mut Ctx<'_, impl EventSink>, sp: &mut Superimposed) {
    let out = FbOutputs {
        warning: true,
        warning_id: ErrorId::SUPERPOSITION_INCOMPLETE.0,
        ..sp.cmd.out
    };
    sp.cmd.emit(cx, out);
}
