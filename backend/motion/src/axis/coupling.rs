//! Couplings: a slave follows its master through a coupling law. MC_GearIn (fixed ratio,
//! coupled at rest), MC_GearInDyn (ratio changeable every cycle, rate-limited, can couple onto
//! a moving master) and MC_GearOut (the slave keeps its velocity).
//!
//! The laws are kept apart from the command protocol: a law only maps the master's motion to
//! the slave's setpoint, so a new one (an electronic cam) is one more [`CouplingLaw`] variant
//! and its `submit_*`, while what every coupling shares — admission, aborting what runs,
//! InGear, losing the master, soft limits — stays as it is.

use super::camming::{CamSet, step_ramp_in};
use super::multimaster::MultiGear;
use super::*;

/// A slave's coupling to its master.
#[derive(Clone, Copy, Debug)]
pub(super) struct Coupling {
    pub(super) master: AxisSlot,
    /// MC_GearInMultiMaster's Master2…Master4 (`master` is Master1 or the first given).
    pub(super) more_masters: [Option<AxisSlot>; 3],
    pub(super) law: CouplingLaw,
    /// The GearInDyn command that still has Enable TRUE (0 when none): a further GearInDyn to
    /// the same master changes this coupling's ratio instead of coupling anew.
    pub(super) dyn_command: CommandId,
}

/// How the slave's setpoint follows the master's motion.
#[allow(
    clippy::large_enum_variant,
    reason = "a Box would allocate on the cycle thread; an axis holds one coupling, inline"
)]
#[derive(Clone, Copy, Debug)]
pub(super) enum CouplingLaw {
    /// MC_GearIn: a fixed ratio.
    Gear(Gear),
    /// MC_GearInDyn: the ratio ramps towards `target_ratio` by at most `ratio_rate` per second.
    GearDyn {
        gear: Gear,
        target_ratio: f64,
        ratio_rate: f64,
    },
    /// MC_CamIn, MC_CamIn_V2: through one or (multi-cam) several superimposed cam tables
    /// (`axis/camming.rs`).
    Cam(CamSet),
    /// MC_GearInMultiMaster: the sum of up to four masters (`axis/multimaster.rs`).
    Multi(MultiGear),
}

/// slave = slave_start + ratio · (master − master_start): the slave follows the master's
/// travel from where both stood when they were coupled (or the ratio last changed).
#[derive(Clone, Copy, Debug)]
pub(super) struct Gear {
    pub(super) ratio: f64,
    /// NaN: taken from the master in the next cycle (re-based after a GearOut that recoupled).
    master_start: f64,
    slave_start: f64,
}

impl Gear {
    /// The slave's setpoint; `ratio_change` is the ratio's rate of change in this cycle (its
    /// share of the slave's acceleration).
    fn follow(&self, master: &Kinematics, ratio_change: f64) -> Kinematics {
        Kinematics {
            position: self.slave_start + self.ratio * (master.position - self.master_start),
            velocity: self.ratio * master.velocity,
            acceleration: self.ratio * master.acceleration + ratio_change * master.velocity,
            jerk: self.ratio * master.jerk,
        }
    }
}

impl CouplingLaw {
    fn gear_mut(&mut self) -> Option<&mut Gear> {
        match self {
            CouplingLaw::Gear(g) | CouplingLaw::GearDyn { gear: g, .. } => Some(g),
            CouplingLaw::Cam(_) | CouplingLaw::Multi(_) => None,
        }
    }

    /// The slave's setpoint for the master's motion in this cycle (advances a ratio ramp).
    /// `None` only for a cam that left the store (the slave holds).
    pub(super) fn slave_setpoint(
        &mut self,
        master: &Kinematics,
        dt: f64,
        cams: &crate::cam::CamStore,
    ) -> Option<Kinematics> {
        if let Some(g) = self.gear_mut() {
            if g.master_start.is_nan() {
                g.master_start = master.position;
            }
        }
        Some(match self {
            CouplingLaw::Cam(set) => set.eval(cams, master)?,
            // Followed in `follow_master` (it needs every master).
            CouplingLaw::Multi(_) => return None,
            CouplingLaw::Gear(g) => g.follow(master, 0.0),
            CouplingLaw::GearDyn {
                gear: g,
                target_ratio,
                ratio_rate,
            } => {
                let mut ratio_change = 0.0;
                if g.ratio != *target_ratio {
                    // Rate-limited, re-based so that the position stays continuous.
                    let step = (*target_ratio - g.ratio).clamp(-*ratio_rate * dt, *ratio_rate * dt);
                    g.slave_start += g.ratio * (master.position - g.master_start);
                    g.master_start = master.position;
                    let before = g.ratio;
                    // The last step lands exactly on the target (no float residue).
                    g.ratio = if (*target_ratio - g.ratio).abs() <= *ratio_rate * dt {
                        *target_ratio
                    } else {
                        g.ratio + step
                    };
                    ratio_change = (g.ratio - before) / dt;
                }
                g.follow(master, ratio_change)
            }
        })
    }

    /// The ratio in force (AxisStatus::gear_ratio).
    pub(super) fn ratio(&self) -> f64 {
        match self {
            CouplingLaw::Gear(g) | CouplingLaw::GearDyn { gear: g, .. } => g.ratio,
            CouplingLaw::Multi(m) => m.ratio(0),
            CouplingLaw::Cam(_) => 0.0,
        }
    }

    /// Still changing towards what it was asked for (a GearInDyn ratio ramp).
    fn ramping(&self) -> bool {
        match self {
            CouplingLaw::Gear(_) | CouplingLaw::Cam(_) | CouplingLaw::Multi(_) => false,
            CouplingLaw::GearDyn {
                gear, target_ratio, ..
            } => gear.ratio != *target_ratio,
        }
    }

    /// What InGear reports when a command takes this coupling over.
    pub(super) fn in_gear(&self) -> bool {
        match self {
            CouplingLaw::Gear(_) | CouplingLaw::Cam(_) => true,
            CouplingLaw::Multi(m) => m.in_gear(),
            CouplingLaw::GearDyn {
                gear, target_ratio, ..
            } => (gear.ratio - target_ratio).abs() < 1e-12,
        }
    }

    /// A new ratio to ramp to (GearInDyn while enabled).
    fn retarget(&mut self, ratio: f64, rate: f64) {
        let Some(&mut gear) = self.gear_mut() else {
            return;
        };
        *self = CouplingLaw::GearDyn {
            gear,
            target_ratio: ratio,
            ratio_rate: rate,
        };
    }

    /// GearInDyn's Enable fell: the ratio stays where the ramp has brought it.
    pub(super) fn freeze(&mut self) {
        if let CouplingLaw::Multi(m) = self {
            m.freeze();
        }
        if let CouplingLaw::GearDyn {
            gear, target_ratio, ..
        } = self
        {
            *target_ratio = gear.ratio;
        }
    }

    /// The slave's setpoint moves by `d` relative to the master (a superposition, a cleared
    /// position lag).
    pub(super) fn shift_slave(&mut self, d: f64) {
        match self {
            CouplingLaw::Cam(set) => set.shift_slave(d),
            CouplingLaw::Multi(m) => m.shift_slave(d),
            _ => {
                if let Some(g) = self.gear_mut() {
                    g.slave_start += d;
                }
            }
        }
    }

    /// Couples anew from here: the slave at `slave_position`, the master where it is in the
    /// next cycle.
    fn rebase(&mut self, slave_position: f64) {
        if let Some(g) = self.gear_mut() {
            g.slave_start = slave_position;
            g.master_start = f64::NAN;
        }
        if let CouplingLaw::Multi(m) = self {
            m.rebase(slave_position);
        }
    }
}

impl From<CamSet> for CouplingLaw {
    fn from(set: CamSet) -> Self {
        CouplingLaw::Cam(set)
    }
}

impl From<MultiGear> for CouplingLaw {
    fn from(law: MultiGear) -> Self {
        CouplingLaw::Multi(law)
    }
}

/// The coupling as the laws' own files see it: `camming.rs` and `multimaster.rs` reach their
/// law in the coupling through these, so that only this file names the coupling (the
/// dependency points one way: the coupling knows its laws, a law does not know the coupling).
impl Axis {
    /// The cams of a cam slave.
    /// By reference: a cam set is 616 bytes, and this is asked several times per cycle of a
    /// cam slave (issue 27).
    pub(super) fn cam_set(&self) -> Option<&CamSet> {
        match &self.coupling {
            Some(Coupling {
                law: CouplingLaw::Cam(set),
                ..
            }) => Some(set),
            _ => None,
        }
    }

    pub(super) fn cam_set_mut(&mut self) -> Option<&mut CamSet> {
        match self.coupling.as_mut() {
            Some(Coupling {
                law: CouplingLaw::Cam(set),
                ..
            }) => Some(set),
            _ => None,
        }
    }

    pub(super) fn multi_gear(&self) -> Option<&MultiGear> {
        match self.coupling.as_ref().map(|c| &c.law) {
            Some(CouplingLaw::Multi(m)) => Some(m),
            _ => None,
        }
    }

    pub(super) fn multi_gear_mut(&mut self) -> Option<&mut MultiGear> {
        match self.coupling.as_mut().map(|c| &mut c.law) {
            Some(CouplingLaw::Multi(m)) => Some(m),
            _ => None,
        }
    }

    /// The multi-master law of a coupling that an Enable-type command still holds.
    pub(super) fn enabled_multi_gear(&mut self) -> Option<&mut MultiGear> {
        match self.coupling.as_mut().filter(|c| c.dyn_command != 0) {
            Some(Coupling {
                law: CouplingLaw::Multi(m),
                ..
            }) => Some(m),
            _ => None,
        }
    }

    /// The masters this axis follows (Master1…Master4 of a multi-master coupling; the one
    /// master of any other coupling first).
    pub fn coupled_masters(&self) -> [Option<AxisSlot>; 4] {
        match self.coupling.as_ref() {
            Some(c) => [
                Some(c.master),
                c.more_masters[0],
                c.more_masters[1],
                c.more_masters[2],
            ],
            None => [self.master_slot(), None, None, None],
        }
    }

    /// [`Axis::coupled_masters`] are all `None` (asked without building them).
    pub fn follows_no_master(&self) -> bool {
        self.coupling.is_none() && self.cam_master().is_none()
    }

    /// MC_GearInMultiMaster's Master2…Master4 of the coupling just made.
    pub(super) fn couple_more_masters(&mut self, more: [Option<AxisSlot>; 3]) {
        if let Some(c) = self.coupling.as_mut() {
            c.more_masters = more;
        }
    }

    /// The axis follows `master` through `law` from now on (what runs is the caller's).
    pub(super) fn install_coupling(
        &mut self,
        master: AxisSlot,
        law: impl Into<CouplingLaw>,
        dyn_command: CommandId,
    ) {
        self.coupling = Some(Coupling {
            master,
            more_masters: [None; 3],
            law: law.into(),
            dyn_command,
        });
    }
}

impl Axis {
    pub(super) fn submit_gear_out(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
    ) -> Result<(), ErrorId> {
        if self.state() != AxisState::SynchronizedMotion {
            return Err(ErrorId::AXIS_CANNOT_BE_STARTED);
        }
        if matches!(
            self.coupling,
            Some(Coupling {
                law: CouplingLaw::Cam(_),
                ..
            })
        ) {
            // A cam slave is decoupled by MC_CamOut.
            return Err(ErrorId::COMMAND_NOT_PERMITTED);
        }
        if let Some(c) = self.coupling.as_mut().filter(|c| c.dyn_command != 0) {
            // GearInDyn still enabled: the slave is decoupled only for an instant and
            // recoupled at once with the ratio it has (spec §5.5.2).
            c.law.rebase(self.set.position);
            cx.report(id, DONE);
            return Ok(());
        }
        self.abort_superposition(cx);
        self.end_phasing(cx, End::Aborted);
        self.coupling = None;
        if let Some(mut j) = self.job.take() {
            j.finish_aborted(cx);
        }
        self.continue_at_current_velocity(cx);
        cx.report(id, DONE);
        Ok(())
    }

    pub(super) fn submit_gear_in(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
        master_slot: AxisSlot,
        master: Option<MasterSample>,
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
        let gear = self.gear_from_here(&m, numerator / denominator as f64);
        self.couple(cx, id, master_slot, CouplingLaw::Gear(gear), 0);
        Ok(())
    }

    pub(super) fn submit_gear_in_dyn(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
        master_slot: AxisSlot,
        master: Option<MasterSample>,
        gear_ratio: f64,
        acceleration: f64,
    ) -> Result<(), ErrorId> {
        if !gear_ratio.is_finite() || !acceleration.is_finite() || acceleration < 0.0 {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        let Some(m) = master else {
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
            c.law.retarget(gear_ratio, rate);
            self.hand_over_enabled_coupling(cx, id);
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
        let law = CouplingLaw::GearDyn {
            gear: self.gear_from_here(&m, start_ratio),
            target_ratio: gear_ratio,
            ratio_rate: rate,
        };
        self.couple(cx, id, master_slot, law, id);
        Ok(())
    }

    /// A further Enable-type coupling command (MC_GearInDyn, MC_GearInMultiMaster) on the
    /// coupling an earlier one still enables: the earlier instance hands over to `id` (Done),
    /// which reports the coupling from now on.
    pub(super) fn hand_over_enabled_coupling(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
    ) {
        let Some(c) = self.coupling.as_mut() else {
            return;
        };
        let old = c.dyn_command;
        c.dyn_command = id;
        let in_gear = c.law.in_gear();
        if let Some(j) = self.job.as_mut().filter(|j| j.kind == JobKind::Gear) {
            let mut prev = Job { id: old, ..*j };
            prev.finish_done(cx);
            j.id = id;
            j.out = FbOutputs::default();
            j.activate(cx);
            let out = FbOutputs { in_gear, ..j.out };
            j.emit(cx, out);
        }
    }

    /// State and master checks shared by both couplings.
    pub(super) fn admit_coupling(
        &self,
        master: Option<MasterSample>,
    ) -> Result<MasterSample, ErrorId> {
        let Some(m) = master else {
            return Err(ErrorId::MASTER_INVALID);
        };
        self.admit_to_external()?;
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

    /// A gear with `ratio` that takes the slave from where it stands and the master from
    /// where the slave follows it (its setpoint, or its actual position with #1064).
    fn gear_from_here(&self, m: &MasterSample, ratio: f64) -> Gear {
        let followed = m.followed(self.p().axis_couple_slave_to_actual_values);
        Gear {
            ratio,
            master_start: followed.position,
            slave_start: self.set.position,
        }
    }

    /// Aborts what runs and couples this axis to `master_slot` from here on.
    pub(super) fn couple(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
        master_slot: AxisSlot,
        law: impl Into<CouplingLaw>,
        dyn_command: CommandId,
    ) {
        let law = law.into();
        self.abort_superposition(cx);
        self.abort_all(cx);
        self.install_coupling(master_slot, law, dyn_command);
        let mut j = Job::new(id, JobKind::Gear);
        j.activate(cx);
        let out = FbOutputs {
            in_gear: law.in_gear(),
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

    /// A coupled slave's cycle: its setpoint from the master's motion through the law; InGear
    /// when a ratio ramp arrives. Without a master sample (lost: see `Axis::step`) it holds.
    pub(super) fn follow_master(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        master: Master,
        dt: f64,
    ) {
        if self
            .coupling
            .as_ref()
            .is_some_and(|c| matches!(c.law, CouplingLaw::Multi(_)))
        {
            self.follow_multi(cx, master, dt);
            return;
        }
        // In place, field by field: a coupling carries a cam set's size, and copying it out
        // and back every cycle cost more than the gear's arithmetic (issue 27).
        let (Some(c), Master::Sample(m)) = (self.coupling.as_mut(), master) else {
            return;
        };
        // Gears and cams follow the master's set values, or its actual ones with #1064.
        let followed = m.followed(self.config.parameters.axis_couple_slave_to_actual_values);
        let ramping = c.law.ramping();
        if let Some(set) = c.law.slave_setpoint(&followed, dt, cx.cams) {
            self.set = set;
        }
        if let CouplingLaw::Cam(cams) = &mut c.law {
            let job = self.job.as_mut().expect("a gear job runs");
            step_ramp_in(cx, job, cams, &mut self.planner, &mut self.set, dt);
        }
        self.superposition.main_motion_sampled();
        let job = self.job.as_mut().expect("a gear job runs");
        if ramping && !c.law.ramping() && job.id != 0 && !job.out.in_gear {
            let out = FbOutputs {
                in_gear: true,
                ..job.out
            };
            job.emit(cx, out);
        }
    }
}
