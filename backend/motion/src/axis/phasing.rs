//! Phasing (spec §5.6): MC_PhasingAbsolute, MC_PhasingRelative and MC_HaltPhasing — a phase
//! shift between a coupled slave and its master, made by a jerk-limited motion of the phase
//! itself laid over what the coupling gives. Apart from the coupling because it is a motion
//! with its own profile (planned like a job, on its own planner) while the coupling law only
//! moves by what the phase adds.

use super::coupling::CouplingLaw;
use super::*;
use crate::planner::Limits;

/// The running phasing command.
#[derive(Clone, Copy, Debug)]
pub(super) struct PhasingJob {
    pub(super) cmd: Held,
    /// The absolute phase shift it brings the slave to (MC_HaltPhasing: where it stops).
    target: f64,
    /// The phase shift when it started (CoveredPhaseShift counts from here).
    start: f64,
    halting: bool,
}

/// A slave's phase shift against its master and the phasing that moves it.
#[derive(Debug)]
pub(super) struct PhasingState {
    /// The phase shift against the master (AbsPhasingPos) and its motion (§5.6).
    shift: Kinematics,
    /// Boxed: a planner is large, and the axis's hot fields stay close together without it.
    planner: Box<Planner>,
    /// A new phasing is planned here first and swapped in when it succeeds.
    scratch: Box<Planner>,
    job: Option<PhasingJob>,
    /// `planner` may hold a plan (set where one is swapped in): an axis that never phases
    /// does not reach into the boxed planner every cycle (a cache miss per axis, issue 27).
    engaged: bool,
}

impl PhasingState {
    /// No phasing runs or holds a plan.
    pub(super) fn settled(&self) -> bool {
        self.job.is_none() && !self.engaged
    }

    /// Settled, and no phase shift left (what an uncoupled axis's step leaves).
    pub(super) fn unused(&self) -> bool {
        let s = self.shift;
        self.settled()
            && [s.position, s.velocity, s.acceleration, s.jerk]
                .iter()
                .all(|v| v.to_bits() == 0)
    }

    /// Built with the axis (the only allocation: the two planners).
    pub(super) fn new(cycle_time: f64) -> Self {
        PhasingState {
            shift: Kinematics::default(),
            planner: Box::new(Planner::new(cycle_time)),
            scratch: Box::new(Planner::new(cycle_time)),
            job: None,
            engaged: false,
        }
    }

    /// The phase belongs to the coupling: a new one starts without a shift.
    pub(super) fn clear_shift(&mut self) {
        self.shift = Kinematics::default();
    }
}

impl Axis {
    /// MC_PhasingAbsolute / MC_PhasingRelative / MC_HaltPhasing: admission (a slave coupled
    /// to `master` by a gear or a cam — not MC_GearInDyn, §5.6), the plan from where the
    /// phase is now (an earlier phasing is aborted, its velocity carried on).
    pub(super) fn submit_phasing(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
        master: AxisSlot,
        ph: PhasingMotion,
    ) -> Result<(), ErrorId> {
        let p = self.p();
        let dynamics = [ph.acceleration, ph.deceleration, ph.jerk];
        if !(ph.phase_shift.is_finite()
            && ph.velocity.is_finite()
            && dynamics.iter().all(|x| x.is_finite() && *x >= 0.0))
        {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        // §5.6.2: Velocity ≥ 0.01 (not used by MC_HaltPhasing).
        if ph.kind != PhasingKind::Halt && ph.velocity < 0.01 {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        // §5.6: a gear or a cam; dynamic ratios only with MC_GearInMultiMaster's
        // AdvancedSlaveDynamics, and only where the slave makes up positions (POSSYNC): a
        // velocity-synchronous slave would never establish a shift.
        let coupled = match self.coupling.as_ref() {
            Some(c) if c.master == master => match &c.law {
                CouplingLaw::GearDyn { .. } => false,
                CouplingLaw::Multi(m) => m.takes_phasing(),
                _ => true,
            },
            _ => false,
        };
        if !coupled || self.mode != Mode::Enabled {
            return Err(ErrorId::PHASING_NOT_COUPLED);
        }
        let or = |x: f64, d: f64| if x > 0.0 { x } else { d };
        let acc = or(ph.acceleration, p.axis_acc);
        let dec = or(ph.deceleration, p.axis_dec);
        let jerk = or(ph.jerk, p.axis_jerk);
        let from = self.phasing.shift;
        let limits = Limits {
            velocity: ph.velocity.max(from.velocity.abs()).max(EPS_V),
            acceleration: acc,
            deceleration: dec,
            jerk,
        };
        let (planned, target) = match ph.kind {
            PhasingKind::Halt => {
                let r = self.phasing.scratch.plan_velocity(from, 0.0, &limits);
                (r, self.phasing.scratch.end_state().position)
            }
            kind => {
                let target = if kind == PhasingKind::Absolute {
                    ph.phase_shift
                } else {
                    from.position + ph.phase_shift
                };
                let limits = Limits {
                    velocity: ph.velocity,
                    ..limits
                };
                (
                    self.phasing
                        .scratch
                        .plan_position(from, target, 0.0, &limits),
                    target,
                )
            }
        };
        // Planned on the spare planner: a refusal leaves the running phase as it was.
        if planned.is_err() {
            return Err(ErrorId::PLANNING_FAILED);
        }
        core::mem::swap(&mut self.phasing.planner, &mut self.phasing.scratch);
        self.phasing.engaged = true;
        if let Some(mut old) = self.phasing.job.take() {
            old.cmd.end(cx, End::Aborted);
        }
        let cmd = Held::start_active(cx, id);
        self.phasing.job = Some(PhasingJob {
            cmd,
            target: if ph.kind == PhasingKind::Halt {
                self.phasing.planner.end_state().position
            } else {
                target
            },
            start: from.position,
            halting: ph.kind == PhasingKind::Halt,
        });
        Ok(())
    }

    /// One cycle of the phase: its profile's increment moves the slave (and the coupling
    /// with it); Done once the phase stands at its target (§5.6.2) or, halting, at rest
    /// (§5.6.1). Ends aborted when the coupling it shifts is gone.
    pub(super) fn step_phasing(&mut self, cx: &mut Ctx<'_, impl EventSink>, dt: f64) {
        if self.coupling.is_none() || self.mode != Mode::Enabled {
            if self.phasing.job.is_some()
                || (self.phasing.engaged && self.phasing.planner.is_planned())
            {
                self.end_phasing(cx, End::Aborted);
            }
            // No plan is left on the planner now. Written only when it changes: an axis that
            // never phases dirties none of this every cycle (issue 27).
            if self.phasing.engaged {
                self.phasing.engaged = false;
            }
            let s = self.phasing.shift;
            let zero = [s.position, s.velocity, s.acceleration, s.jerk]
                .iter()
                .all(|v| v.to_bits() == 0);
            if self.coupling.is_none() && !zero {
                self.phasing.shift = Kinematics::default();
            }
            return;
        }
        if !self.phasing.engaged {
            return;
        }
        let Some(k) = self.phasing.planner.step(dt) else {
            return;
        };
        let d = k.position - self.phasing.shift.position;
        // A multi-master slave with advanced dynamics follows its law within its own limits:
        // the phase moves the law, and the slave catches up as it makes up any offset.
        let law_only = self
            .coupling
            .as_ref()
            .is_some_and(|c| matches!(c.law, CouplingLaw::Multi(_)));
        if let Some(c) = self.coupling.as_mut() {
            c.law.shift_slave(d);
        }
        if !law_only {
            self.set.position += d;
            self.set.velocity += k.velocity;
            self.set.acceleration += k.acceleration;
            self.set.jerk += k.jerk;
        }
        self.phasing.shift = k;
        if self.phasing.planner.finished() {
            let ph = self.phasing.job.take();
            let at = match ph {
                Some(p) if !p.halting => p.target,
                _ => k.position,
            };
            // Exactly at the target: the last sample's residue goes into the slave too.
            let rest = at - k.position;
            if let Some(c) = self.coupling.as_mut() {
                c.law.shift_slave(rest);
            }
            if !law_only {
                self.set.position += rest;
            }
            self.phasing.shift = Kinematics {
                position: at,
                ..Kinematics::default()
            };
            if let Some(mut p) = ph {
                p.cmd.end(cx, End::Done);
            }
            self.phasing.planner.clear();
            self.phasing.engaged = false;
        }
    }

    /// Ends the running phasing command (`end`); the phase stays where it is.
    pub(super) fn end_phasing(&mut self, cx: &mut Ctx<'_, impl EventSink>, end: End) {
        if let Some(mut ph) = self.phasing.job.take() {
            ph.cmd.end(cx, end);
        }
        self.phasing.planner.clear();
        self.phasing.engaged = false;
        self.phasing.shift.velocity = 0.0;
        self.phasing.shift.acceleration = 0.0;
        self.phasing.shift.jerk = 0.0;
    }

    /// The phasing part of the status (PhasingActive, AbsPhasingPos, CoveredPhaseShift).
    pub(super) fn phasing_status(&self) -> (bool, f64, f64) {
        (
            self.phasing.job.is_some(),
            self.phasing.shift.position,
            self.phasing
                .job
                .map(|p| self.phasing.shift.position - p.start)
                .unwrap_or(0.0),
        )
    }
}
