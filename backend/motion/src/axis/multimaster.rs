//! MC_GearInMultiMaster (spec §5.5.4): a slave that follows the sum of up to four masters'
//! travel times their ratios, the ratios changeable while the block is enabled. Without
//! AdvancedSlaveDynamics the slave is the law itself (coupled at rest, ratio changes ramped
//! like MC_GearInDyn's); with it the slave follows the law within its own acceleration,
//! deceleration and jerk, planned every cycle towards where the law is, and SyncMode says
//! what it makes up: VELOSYNC only the velocity, POSSYNC1 also positions lost to limiting once
//! coupled, POSSYNC2 everything (coupling in motion, ratio changes, limiting).

use super::*;
use crate::command::{GearInMultiMaster, MultiMasterSyncMode};

/// The law and how the slave follows it.
#[derive(Clone, Copy, Debug)]
pub(super) struct MultiGear {
    ratio: [f64; 4],
    target: [f64; 4],
    /// Largest ratio change per second (without AdvancedSlaveDynamics).
    rate: [f64; 4],
    /// Where each master was when the law last re-based (NaN: take it next cycle).
    master_start: [f64; 4],
    slave_start: f64,
    advanced: bool,
    sync: MultiMasterSyncMode,
    limits: Limits,
    /// AdvancedSlaveDynamics: the slave has been in sync since coupling (POSSYNC1 makes up
    /// positions from then on).
    synced: bool,
    in_gear: bool,
    /// The law in the previous cycle (position sync plans the slave's offset from it).
    last_ideal: Option<Kinematics>,
}

impl MultiGear {
    pub(super) fn ratio(&self, i: usize) -> f64 {
        self.ratio[i]
    }

    pub(super) fn ratios(&self) -> [f64; 4] {
        self.ratio
    }

    pub(super) fn in_gear(&self) -> bool {
        self.in_gear
    }

    /// Phasing needs dynamic ratios with AdvancedSlaveDynamics and a slave that makes up
    /// positions (§5.6).
    pub(super) fn takes_phasing(&self) -> bool {
        self.advanced && self.sync != MultiMasterSyncMode::Velosync
    }

    pub(super) fn shift_slave(&mut self, d: f64) {
        self.slave_start += d;
        if let Some(k) = self.last_ideal.as_mut() {
            k.position += d;
        }
    }

    pub(super) fn rebase(&mut self, slave_position: f64) {
        self.slave_start = slave_position;
        self.master_start = [f64::NAN; 4];
        self.last_ideal = None;
    }

    /// Enable FALSE: the ratios stay where they are.
    pub(super) fn freeze(&mut self) {
        self.target = self.ratio;
    }

    /// New ratios (a further command while enabled).
    fn retarget(&mut self, ratios: [f64; 4], rate: [f64; 4]) {
        self.target = ratios;
        self.rate = rate;
        if !self.advanced {
            // InGear again once the ratios have ramped there.
            self.in_gear = self.ratio == self.target;
        }
    }

    /// The law's position, velocity and acceleration for the masters' motion in this cycle
    /// (ratio ramps advanced; re-based so that a ratio change moves no position, except in
    /// POSSYNC2, where the slave is to go where the new ratio puts it).
    fn ideal(&mut self, masters: &[Option<Kinematics>; 4], dt: f64) -> Kinematics {
        let mut k = Kinematics::default();
        let rebased = !(self.advanced && self.sync == MultiMasterSyncMode::Possync2);
        for (i, m) in masters.iter().enumerate() {
            let Some(m) = m else { continue };
            if self.master_start[i].is_nan() {
                self.master_start[i] = m.position;
            }
            let mut ratio_change = 0.0;
            if self.ratio[i] != self.target[i] {
                if rebased {
                    self.slave_start += self.ratio[i] * (m.position - self.master_start[i]);
                    self.master_start[i] = m.position;
                }
                let before = self.ratio[i];
                let d = self.target[i] - before;
                let step = self.rate[i] * dt;
                self.ratio[i] = if self.advanced || d.abs() <= step {
                    self.target[i]
                } else {
                    before + step.copysign(d)
                };
                if !self.advanced {
                    ratio_change = (self.ratio[i] - before) / dt;
                }
            }
            let r = self.ratio[i];
            k.position += r * (m.position - self.master_start[i]);
            k.velocity += r * m.velocity;
            k.acceleration += r * m.acceleration + ratio_change * m.velocity;
            k.jerk += r * m.jerk;
        }
        k.position += self.slave_start;
        k
    }
}

impl Axis {
    /// The kernel hands over what it saw of every master before a submit or a step (in the
    /// order of [`Axis::coupled_masters`], or of a GearInMultiMaster's masters).
    pub fn offer_masters(&mut self, masters: [Option<MasterSample>; 4]) {
        self.wake();
        self.offered = masters;
    }

    /// MC_GearInMultiMaster: checks, then couples (or, while enabled on the same masters,
    /// takes the new ratios).
    pub(super) fn submit_gear_in_multi(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
        g: GearInMultiMaster,
    ) -> Result<(), ErrorId> {
        let dynamics_ok = [g.acceleration, g.deceleration, g.jerk]
            .iter()
            .all(|x| x.is_finite() && *x >= 0.0);
        if !dynamics_ok || !g.ratios.iter().all(|r| r.is_finite()) {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        let Some(primary) = g.masters.iter().position(|m| m.is_some()) else {
            return Err(ErrorId::MASTER_INVALID);
        };
        // Ratios of empty masters do not count.
        let mut ratios = g.ratios;
        for (i, m) in g.masters.iter().enumerate() {
            if m.is_none() {
                ratios[i] = 0.0;
            }
        }
        let samples = self.offered;
        let mut rate = [0.0; 4];
        let p = self.p();
        let or = |x: f64, d: f64| if x > 0.0 { x } else { d };
        let acc = or(g.acceleration, p.axis_acc);
        for i in 0..4 {
            match (g.masters[i], samples[i]) {
                (None, _) => {}
                (Some(_), Some(m)) if !m.error => {
                    // The acceleration limit is reached at the master's maximum velocity.
                    rate[i] = acc / m.max_velocity.max(EPS_V);
                }
                _ => return Err(ErrorId::MASTER_INVALID),
            }
        }
        // Enable still TRUE on the same masters: new ratios.
        let order = self.multi_order(&g.masters);
        let same_masters = self.coupled_masters() == order.0;
        if let Some(m) = self.enabled_multi_gear().filter(|_| same_masters) {
            m.retarget(permute(ratios, order.1), permute(rate, order.1));
            self.hand_over_enabled_coupling(cx, id);
            return Ok(());
        }
        self.admit_coupling(samples[primary])?;
        let moving = g.masters.iter().zip(samples).any(|(m, s)| {
            m.is_some() && s.is_some_and(|s| s.moving || s.set.velocity.abs() > EPS_V)
        });
        if !g.advanced_slave_dynamics {
            // Without AdvancedSlaveDynamics the slave is the law: coupled at rest (§5.5.4:
            // synchronising onto moving masters needs the advanced algorithm).
            if moving {
                return Err(ErrorId::MASTER_MOVING);
            }
            if self.set.velocity.abs() > EPS_V {
                return Err(ErrorId::AXIS_CANNOT_BE_STARTED);
            }
        }
        let actual = self.p().axis_couple_slave_to_actual_values;
        let mut master_start = [f64::NAN; 4];
        for i in 0..4 {
            if let (Some(_), Some(s)) = (g.masters[i], samples[i]) {
                master_start[i] = s.followed(actual).position;
            }
        }
        let p = self.p();
        let law = MultiGear {
            ratio: permute(ratios, order.1),
            target: permute(ratios, order.1),
            rate: permute(rate, order.1),
            master_start: permute(master_start, order.1),
            slave_start: self.set.position,
            advanced: g.advanced_slave_dynamics,
            sync: g.sync_mode,
            limits: Limits {
                velocity: p.axis_velo_max,
                acceleration: acc,
                deceleration: or(g.deceleration, p.axis_dec),
                jerk: or(g.jerk, p.axis_jerk),
            },
            synced: false,
            in_gear: !g.advanced_slave_dynamics,
            last_ideal: None,
        };
        let primary_slot = order.0[0].expect("one master at least");
        self.couple(cx, id, primary_slot, law, id);
        self.couple_more_masters([order.0[1], order.0[2], order.0[3]]);
        Ok(())
    }

    /// The masters packed to the front (the coupling's order) and, for each packed place,
    /// the index of the input it came from.
    fn multi_order(&self, masters: &[Option<AxisSlot>; 4]) -> ([Option<AxisSlot>; 4], [usize; 4]) {
        let mut packed = [None; 4];
        let mut from = [usize::MAX; 4];
        let mut n = 0;
        for (i, m) in masters.iter().enumerate() {
            if m.is_some() {
                packed[n] = *m;
                from[n] = i;
                n += 1;
            }
        }
        (packed, from)
    }

    /// A multi-master slave's cycle: the law from every master's motion; the slave is the law,
    /// or (AdvancedSlaveDynamics) follows it within its dynamics as SyncMode says.
    pub(super) fn follow_multi(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        master: Master,
        dt: f64,
    ) {
        // The law alone is copied (a coupling carries a cam set's size).
        let Some(mut law) = self.multi_gear().copied() else {
            return;
        };
        if !matches!(master, Master::Sample(_)) {
            return;
        }
        let actual = self.p().axis_couple_slave_to_actual_values;
        let followed = self.offered.map(|s| s.map(|s| s.followed(actual)));
        let ideal = law.ideal(&followed, dt);
        if !law.advanced {
            self.set = ideal;
            law.in_gear = law.ratio == law.target;
        } else {
            let velocity_only = match law.sync {
                MultiMasterSyncMode::Velosync => true,
                MultiMasterSyncMode::Possync1 => !law.synced,
                MultiMasterSyncMode::Possync2 => false,
            };
            // Position sync plans the slave's offset from the law towards 0 (the law moves on
            // by itself), within what the slave's limits leave beside the law's own
            // acceleration and jerk; where they leave nothing (the masters accelerate harder
            // than the slave may) the slave follows the law's velocity within its limits and
            // the offset that builds up is made up afterwards.
            let mut followed_position = false;
            if let (false, Some(prev)) = (velocity_only, law.last_ideal) {
                let l = law.limits;
                let rel_limits = Limits {
                    velocity: l.velocity,
                    acceleration: l.acceleration - ideal.acceleration.abs(),
                    deceleration: l.deceleration - ideal.acceleration.abs(),
                    jerk: l.jerk - ideal.jerk.abs(),
                };
                let room = rel_limits.acceleration > 1e-3 * l.acceleration
                    && rel_limits.deceleration > 1e-3 * l.deceleration
                    && rel_limits.jerk > 1e-3 * l.jerk;
                let offset = Kinematics {
                    position: self.set.position - prev.position,
                    velocity: self.set.velocity - prev.velocity,
                    acceleration: self.set.acceleration - prev.acceleration,
                    jerk: 0.0,
                };
                if room
                    && self
                        .planner
                        .plan_position(offset, 0.0, 0.0, &rel_limits)
                        .is_ok()
                {
                    if let Some(k) = self.planner.step(dt) {
                        self.set = Kinematics {
                            position: ideal.position + k.position,
                            velocity: ideal.velocity + k.velocity,
                            acceleration: ideal.acceleration + k.acceleration,
                            jerk: ideal.jerk + k.jerk,
                        };
                        followed_position = true;
                    }
                }
            }
            if !followed_position
                && self
                    .planner
                    .plan_velocity(self.set, ideal.velocity, &law.limits)
                    .is_ok()
            {
                if let Some(k) = self.planner.step(dt) {
                    self.set = k;
                }
            }
            law.last_ideal = Some(ideal);
            let v_tol = 1e-6 * (1.0 + ideal.velocity.abs());
            let v_synced = (self.set.velocity - ideal.velocity).abs() <= v_tol;
            let p_synced =
                (self.set.position - ideal.position).abs() <= self.p().axis_target_position_window;
            if law.sync == MultiMasterSyncMode::Possync1 && !law.synced && v_synced {
                // Synchronous from here: what coupling in motion left behind stays behind.
                let d = self.set.position - ideal.position;
                law.slave_start += d;
                if let Some(k) = law.last_ideal.as_mut() {
                    k.position += d;
                }
                law.synced = true;
            }
            law.in_gear = match law.sync {
                MultiMasterSyncMode::Velosync => v_synced,
                MultiMasterSyncMode::Possync1 => law.synced && v_synced && p_synced,
                MultiMasterSyncMode::Possync2 => v_synced && p_synced,
            };
        }
        self.superposition.main_motion_sampled();
        let job = self.job.as_mut().expect("a gear job runs");
        if job.id != 0 && job.out.in_gear != law.in_gear {
            let out = FbOutputs {
                in_gear: law.in_gear,
                ..job.out
            };
            job.emit(cx, out);
        }
        if let Some(m) = self.multi_gear_mut() {
            *m = law;
        }
    }
}

/// `values` rearranged so that place k holds the value of input `from[k]`.
fn permute<T: Copy + Default>(values: [T; 4], from: [usize; 4]) -> [T; 4] {
    let mut out = [T::default(); 4];
    for k in 0..4 {
        if from[k] < 4 {
            out[k] = values[from[k]];
        }
    }
    out
}
