//! Gearing: MC_GearIn (fixed ratio, coupled at rest), MC_GearInDyn (ratio changeable every
//! cycle, rate-limited, can couple onto a moving master) and MC_GearOut (the slave keeps its
//! velocity). The slave's setpoint itself is computed in `step_job`.

use super::*;

impl Axis {
    pub(super) fn submit_gear_out(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
    ) -> Result<(), ErrorId> {
        if self.state() != AxisState::SynchronizedMotion {
            return Err(ErrorId::AXIS_CANNOT_BE_STARTED);
        }
        if let Some(c) = self.coupling.as_mut().filter(|c| c.dyn_command != 0) {
            // GearInDyn still enabled: the slave is decoupled only for an instant and
            // recoupled at once with the ratio it has (spec §5.5.2).
            c.slave_start = self.set.position;
            c.master_start = f64::NAN; // re-based on the next step
            cx.report(id, DONE);
            return Ok(());
        }
        self.abort_superposition(cx);
        self.coupling = None;
        if let Some(mut j) = self.job.take() {
            j.finish_aborted(cx);
        }
        self.continue_at_current_velocity(cx);
        cx.report(id, DONE);
        Ok(())
    }

    #[allow(clippy::too_many_arguments)]
    pub(super) fn submit_gear_in(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
        master_slot: AxisSlot,
        master: Option<(AxisSlot, MasterSample)>,
        numerator: f64,
        denominator: u16,
    ) -> Result<(), ErrorId> {
        if denominator == 0 || !numerator.is_finite() {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        let m = self.admit_coupling(master)?;
        if m.moving || m.set.velocity.abs() > EPS_V {
            return Err(ErrorId::MASTER_MOVING);
        }
        if self.set.velocity.abs() > EPS_V {
            return Err(ErrorId::AXIS_CANNOT_BE_STARTED);
        }
        let ratio = numerator / denominator as f64;
        self.couple(cx, id, master_slot, &m, ratio, ratio, f64::INFINITY, 0);
        Ok(())
    }

    #[allow(clippy::too_many_arguments)]
    pub(super) fn submit_gear_in_dyn(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
        master_slot: AxisSlot,
        master: Option<(AxisSlot, MasterSample)>,
        gear_ratio: f64,
        acceleration: f64,
    ) -> Result<(), ErrorId> {
        if !gear_ratio.is_finite() || !acceleration.is_finite() || acceleration < 0.0 {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        let Some((_, m)) = master else {
            return Err(ErrorId::MASTER_INVALID);
        };
        if m.error {
            return Err(ErrorId::MASTER_INVALID);
        }
        let acc = if acceleration > 0.0 {
            acceleration
        } else {
            self.p().axis_acc
        };
        // The acceleration limit is reached at the master's maximum velocity (spec §5.5.2).
        let rate = acc / m.max_velocity.max(EPS_V);
        // Enable still TRUE on the same coupling: a new ratio.
        if let Some(c) = self
            .coupling
            .as_mut()
            .filter(|c| c.master == master_slot && c.dyn_command != 0)
        {
            c.target_ratio = gear_ratio;
            c.ratio_rate = rate;
            let old = c.dyn_command;
            c.dyn_command = id;
            if let Some(j) = self.job.as_mut().filter(|j| j.kind == JobKind::Gear) {
                // The earlier instance hands over to this one.
                let mut prev = Job { id: old, ..*j };
                prev.finish_done(cx);
                j.id = id;
                j.out = FbOutputs::default();
                j.activate(cx);
                let out = FbOutputs {
                    in_gear: (c.ratio - c.target_ratio).abs() < 1e-12,
                    ..j.out
                };
                j.emit(cx, out);
            }
            return Ok(());
        }
        let m = self.admit_coupling(master)?;
        let mv = if self.p().axis_couple_slave_to_actual_values {
            m.actual_velocity
        } else {
            m.set.velocity
        };
        // Start from the ratio the slave already has (at rest: the target) and ramp from
        // there, so that coupling onto a moving master is acceleration-limited.
        let start_ratio = if mv.abs() > EPS_V {
            self.set.velocity / mv
        } else if self.set.velocity.abs() <= EPS_V {
            gear_ratio
        } else {
            return Err(ErrorId::AXIS_CANNOT_BE_STARTED);
        };
        self.couple(cx, id, master_slot, &m, start_ratio, gear_ratio, rate, id);
        Ok(())
    }

    /// State and master checks shared by both couplings.
    fn admit_coupling(
        &self,
        master: Option<(AxisSlot, MasterSample)>,
    ) -> Result<MasterSample, ErrorId> {
        let Some((_, m)) = master else {
            return Err(ErrorId::MASTER_INVALID);
        };
        match self.state() {
            AxisState::Standstill
            | AxisState::DiscreteMotion
            | AxisState::ContinuousMotion
            | AxisState::SynchronizedMotion => {}
            _ => return Err(ErrorId::AXIS_CANNOT_BE_STARTED),
        }
        if m.error {
            return Err(ErrorId::MASTER_INVALID);
        }
        Ok(m)
    }

    /// Aborts what runs and couples this axis to `master_slot` from here on.
    #[allow(clippy::too_many_arguments)]
    fn couple(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
        master_slot: AxisSlot,
        m: &MasterSample,
        ratio: f64,
        target_ratio: f64,
        ratio_rate: f64,
        dyn_command: CommandId,
    ) {
        let use_actual = self.p().axis_couple_slave_to_actual_values;
        self.abort_superposition(cx);
        self.abort_all(cx);
        self.coupling = Some(Coupling {
            master: master_slot,
            ratio,
            target_ratio,
            ratio_rate,
            dyn_command,
            master_start: if use_actual {
                m.actual_position
            } else {
                m.set.position
            },
            slave_start: self.set.position,
        });
        let mut j = Job::new(id, JobKind::Gear);
        j.activate(cx);
        let out = FbOutputs {
            in_gear: (ratio - target_ratio).abs() < 1e-12,
            ..j.out
        };
        j.emit(cx, out);
        if dyn_command == 0 {
            // MC_GearIn ends once coupled (Busy falls with InGear, manual §6.5.1); the
            // coupling goes on without an owning command until GearOut or a new motion.
            let out = FbOutputs {
                busy: false,
                active: false,
                done: true,
                ..j.out
            };
            j.emit(cx, out);
            j.id = 0;
        }
        self.job = Some(j);
    }
}
