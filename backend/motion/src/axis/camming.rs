//! Cam couplings (TwinCAT NC Camming, spec camming-tf5050.md): MC_CamIn (couple, or switch the
//! cam of a coupled slave), MC_CamOut, MC_CamScaling, their activation modes, autooffset, and
//! MC_CamInfo. The law — slave = (f((m + MO)/MS) + strokes)·SS + SO, on the master's set
//! values — is a coupling law like the gears (`CouplingLaw` in `coupling.rs`, which names this
//! file's [`CamSet`]; this file reaches the coupling only through the axis's `cam_set`,
//! `install_coupling`…), so admission, losing the master and the soft limits of a coupled
//! slave are shared with them.
//!
//! A cam never makes the slave jump: where it takes effect (coupling, switch, scaling) the
//! slave's position must match within the target window (#1026) and its velocity within one
//! cycle's acceleration (#1004), else the command ends with 0x7084 and nothing changes.

use super::*;
use crate::cam::{
    Cam, CamActivationMode as Act, CamIn, CamInV2, CamInfo, CamOperationMode, CamScaling,
    CamScalingMode, CamScalingV2, CamTerm, InterpolationType, RampIn, StartMode,
};

/// The cam law in force.
#[derive(Clone, Copy, Debug)]
pub(super) struct CamLaw {
    pub(super) table: u32,
    /// The generation of the table's data this slave runs (an online change makes a new one).
    pub(super) generation: u32,
    pub(super) mo: f64,
    pub(super) so: f64,
    pub(super) ms: f64,
    pub(super) ss: f64,
    /// The coupling's interpolation of a position table (`None`: the table's own).
    interpolation: Option<InterpolationType>,
    /// The table's own interpolation, for MC_CamInfo (evaluation reads it from the cam).
    cam_interpolation: InterpolationType,
    /// The cycle of a periodic cam the coupling counts strokes from (its base cycle).
    k_base: i64,
    master_absolute: bool,
    slave_absolute: bool,
    master_coupling_pos: f64,
    slave_coupling_pos: f64,
    /// Superimposed distance laid onto the slave (MC_MoveSuperImposed), in `so` as well.
    superimposed: f64,
    /// The table's start, period and stroke (MC_CamInfo).
    cam_start: (f64, f64),
    cam_period: f64,
    cam_stroke: f64,
    periodic: bool,
    // Of the latest evaluation (MC_CamInfo):
    x_local: f64,
    y_local: f64,
    strokes: f64,
    master_pos: f64,
    /// The interval of the cam found last: the next cycle's search starts there (O(1) in a
    /// non-equidistant table while the master moves a few rows per cycle). Any value is
    /// correct, only slower.
    hint: usize,
}

impl CamLaw {
    /// Raw cam master coordinate of a master axis position.
    fn raw(&self, m: f64) -> f64 {
        (m + self.mo) / self.ms
    }

    /// The slave's setpoint for the master's motion (chain rule through the scalings).
    pub(super) fn eval(&mut self, cam: &Cam, m: &Kinematics) -> Kinematics {
        let x = self.raw(m.position);
        let (k, xl) = cam.cycle_of(x);
        let interpolation = self.interpolation.unwrap_or(cam.interpolation);
        let f = if cam.periodic {
            cam.eval_in_range_hinted(xl, interpolation, &mut self.hint)
        } else {
            cam.eval_hinted(x, interpolation, &mut self.hint)
        };
        let strokes = if cam.periodic {
            (k - self.k_base) as f64 * cam.stroke()
        } else {
            0.0
        };
        self.x_local = xl;
        self.y_local = f.position;
        self.strokes = strokes;
        self.master_pos = m.position;
        let (ss, ms) = (self.ss, self.ms);
        let (vm, am, jm) = (m.velocity, m.acceleration, m.jerk);
        Kinematics {
            position: (f.position + strokes) * ss + self.so,
            velocity: ss / ms * f.velocity * vm,
            acceleration: ss / (ms * ms) * f.acceleration * vm * vm + ss / ms * f.velocity * am,
            jerk: ss / (ms * ms * ms) * f.jerk * vm * vm * vm
                + 3.0 * ss / (ms * ms) * f.acceleration * vm * am
                + ss / ms * f.velocity * jm,
        }
    }

    pub(super) fn shift_slave(&mut self, d: f64) {
        self.so += d;
        self.superimposed += d;
    }

    fn info(&self, master: AxisSlot, slave_pos: f64) -> CamInfo {
        let ((x0, y0), p, h, periodic) = (
            self.cam_start,
            self.cam_period,
            self.cam_stroke,
            self.periodic,
        );
        CamInfo {
            cam_table_id: self.table,
            periodic,
            master_axis: master,
            master_cam_start_pos: x0,
            slave_cam_start_pos: y0,
            raw_master_period: p,
            raw_slave_stroke: h,
            master_axis_coupling_pos: self.master_coupling_pos,
            slave_axis_coupling_pos: self.slave_coupling_pos,
            master_absolute: self.master_absolute,
            slave_absolute: self.slave_absolute,
            master_offset: self.mo,
            slave_offset: self.so,
            master_scaling: self.ms,
            slave_scaling: self.ss,
            sum_of_slave_strokes: self.strokes * self.ss,
            sum_of_superposition_distance: self.superimposed,
            actual_master_axis_pos: self.master_pos,
            actual_slave_axis_pos: slave_pos,
            actual_master_cam_pos: self.x_local,
            actual_slave_cam_pos: self.y_local,
            ..CamInfo::default()
        }
    }
}

/// The most cams superimposed on one slave (MC_CamIn_V2, MC_CamAdd).
pub(super) const MAX_CAMS: usize = 4;

/// A slave's cams: one (MC_CamIn) or several superimposed (MC_CamIn_V2): the slave position is
/// the sum of their contributions, each with its own offsets and scalings (spec §1.9). Terms
/// are kept packed from index 0 (the base).
#[derive(Clone, Copy, Debug)]
pub(super) struct CamSet {
    pub(super) terms: [Option<CamLaw>; MAX_CAMS],
    /// Coupled by MC_CamIn_V2 (MC_CamIn and MC_CamIn_V2 exclude each other on a slave).
    pub(super) v2: bool,
    /// A ramp-in runs: the axis's planner (idle while coupled) carries the slave's deviation
    /// from the cam down to 0, laid over the cams' setpoint; InSync when it arrives.
    pub(super) ramp: bool,
}

impl CamSet {
    fn single(law: CamLaw, v2: bool) -> Self {
        let mut terms = [None; MAX_CAMS];
        terms[0] = Some(law);
        CamSet {
            terms,
            v2,
            ramp: false,
        }
    }

    fn base(&self) -> CamLaw {
        self.terms[0].expect("a cam set has a base")
    }

    fn count(&self) -> usize {
        self.terms.iter().flatten().count()
    }

    /// The term running table `id`.
    fn find(&self, id: u32) -> Option<usize> {
        self.terms
            .iter()
            .position(|t| t.is_some_and(|t| t.table == id))
    }

    fn remove(&mut self, i: usize) {
        for k in i..MAX_CAMS - 1 {
            self.terms[k] = self.terms[k + 1];
        }
        self.terms[MAX_CAMS - 1] = None;
    }

    /// The sum of the terms' setpoints; `None` if a cam left the store (the slave holds).
    pub(super) fn eval(
        &mut self,
        cams: &crate::cam::CamStore,
        m: &Kinematics,
    ) -> Option<Kinematics> {
        let mut sum = Kinematics::default();
        for t in self.terms.iter_mut().flatten() {
            let k = t.eval(cams.get_gen(t.table, t.generation)?, m);
            sum.position += k.position;
            sum.velocity += k.velocity;
            sum.acceleration += k.acceleration;
            sum.jerk += k.jerk;
        }
        Some(sum)
    }

    pub(super) fn shift_slave(&mut self, d: f64) {
        if let Some(b) = self.terms[0].as_mut() {
            b.shift_slave(d);
        }
    }
}

/// When a queued coupling, switch or scaling takes effect, and the master positions it last
/// saw (to find a crossing between two cycles).
#[derive(Clone, Copy, Debug)]
pub(super) struct Activation {
    mode: Act,
    position: f64,
    prev_axis: f64,
    prev_raw: f64,
}

/// Whether going from `a` to `b` passes `t` (or `t` + n·`period`): `t` in (a, b] or [b, a).
fn crossed(a: f64, b: f64, t: f64, period: Option<f64>) -> bool {
    if a == b {
        return false;
    }
    match period {
        None => (a < t && t <= b) || (b <= t && t < a),
        Some(p) if b > a => t + ((a - t) / p).floor().mul_add(p, p) <= b,
        Some(p) => t + (((a - t) / p).ceil() - 1.0) * p >= b,
    }
}

impl Activation {
    fn new(mode: Act, position: f64, m_axis: f64, raw: f64) -> Self {
        Activation {
            mode,
            position,
            prev_axis: m_axis,
            prev_raw: raw,
        }
    }

    /// Taken effect now? `m_axis` the master axis position, `raw` its raw position in the cam
    /// the mode refers to (`cam`).
    fn reached(&mut self, m_axis: f64, raw: f64, cam: &Cam) -> bool {
        let (a, b) = (self.prev_axis, m_axis);
        let (ra, rb) = (self.prev_raw, raw);
        self.prev_axis = m_axis;
        self.prev_raw = raw;
        let period = cam.periodic.then(|| cam.period());
        match self.mode {
            Act::Instantaneous => true,
            Act::AtMasterAxisPos => crossed(a, b, self.position, None),
            Act::AtMasterAxisPosPositiveDirection => b > a && crossed(a, b, self.position, None),
            Act::AtMasterAxisPosNegativeDirection => b < a && crossed(a, b, self.position, None),
            Act::AtMasterCamPos => crossed(ra, rb, self.position, period),
            Act::NextCycle => {
                let (x0, xn) = cam.master_range();
                match period {
                    Some(p) => crossed(ra, rb, x0, Some(p)),
                    None => crossed(ra, rb, x0, None) || crossed(ra, rb, xn, None),
                }
            }
            _ => false,
        }
    }

    /// Already there when asked: a master standing exactly on the activation position.
    fn at_once(&self, m_axis: f64, raw: f64) -> bool {
        match self.mode {
            Act::Instantaneous => true,
            Act::AtMasterAxisPos
            | Act::AtMasterAxisPosPositiveDirection
            | Act::AtMasterAxisPosNegativeDirection => m_axis == self.position,
            Act::AtMasterCamPos => raw == self.position,
            _ => false,
        }
    }
}

/// A coupling that waits for its activation (MC_CamIn on an uncoupled axis).
#[derive(Clone, Copy, Debug)]
pub(super) struct PendingCamIn {
    pub(super) cmd: Held,
    pub(super) master: AxisSlot,
    ci: CamIn,
    act: Activation,
    /// By MC_CamIn_V2.
    v2: bool,
}

/// A cam switch (MC_CamIn on a cam slave) or a scaling that waits for its activation.
#[derive(Clone, Copy, Debug)]
pub(super) struct PendingChange<T> {
    cmd: Held,
    what: T,
    act: Activation,
}

/// Data written to the coupled table (an online change) that waits to take effect on this
/// slave: the new generation, when, and how the offsets follow.
#[derive(Clone, Copy, Debug)]
pub(super) struct PendingData {
    /// The term of the slave's cams that runs the table.
    term: usize,
    generation: u32,
    act: Activation,
    master_scaling_mode: CamScalingMode,
    slave_scaling_mode: CamScalingMode,
    /// Its activation has been reached; it takes effect in the first cycle without a jump.
    due: bool,
}

/// A cam slave's state besides its cams (those are the coupling's law, [`CamSet`]): what
/// waits for its activation, and what MC_CamInfo keeps.
#[derive(Debug, Default)]
pub(super) struct CamState {
    /// MC_CamIn waiting for its activation (the axis is not coupled yet).
    cam_in: Option<PendingCamIn>,
    /// MC_CamIn on a cam slave waiting for its activation (CamTableQueued).
    switch: Option<PendingChange<CamIn>>,
    /// MC_CamScaling waiting for its activation (CamScalingPending).
    scaling: Option<PendingChange<CamScaling>>,
    /// The cam (term) a queued MC_CamScaling(_V2) scales.
    scaling_term: usize,
    /// Data written to the coupled table waiting to take effect here (CamDataQueued).
    data: Option<PendingData>,
    /// MC_CamIn_V2 / MC_CamAdd / MC_CamExchange / MC_CamRemove waiting for its activation.
    v2_op: Option<PendingChange<CamInV2>>,
    /// The master's set values in the latest cycle (a scaling at once uses them).
    last_master: Kinematics,
    /// MC_CamInfo of the last cam coupling, kept after an error ended it (until MC_CamOut).
    last_info: CamInfo,
    /// The status's cam info is what it stays while no cam couples and nothing is queued
    /// (it is not built again every cycle: it is large).
    pub(super) idle_info: bool,
}

impl CamState {
    /// No scaling, switch, V2 operation or table data waits to take effect.
    pub(super) fn nothing_queued(&self) -> bool {
        self.scaling.is_none()
            && self.switch.is_none()
            && self.v2_op.is_none()
            && self.data.is_none()
    }

    /// A coupling waits for its activation (the axis executes a job, §4.1.1).
    pub(super) fn waits_for_coupling(&self) -> bool {
        self.cam_in.is_some()
    }

    /// MC_CamInfo of the cam coupling `info` reports, or, decoupled otherwise than by
    /// MC_CamOut, the last valid one (no longer active, nothing queued).
    pub(super) fn kept_info(&mut self, mut info: CamInfo) -> CamInfo {
        if info.cam_table_id != 0 {
            info.active = true;
            self.last_info = info;
        } else if self.last_info.cam_table_id != 0 {
            // Decoupled otherwise than by MC_CamOut: the last valid state stays readable.
            info = CamInfo {
                active: false,
                cam_data_queued: false,
                cam_table_queued: false,
                scaling_pending: false,
                ..self.last_info
            };
        }
        info
    }
}

fn finite_scaling(v: f64) -> bool {
    v.is_finite() && v != 0.0
}

impl Axis {
    /// The slave's master while coupled through a cam, or waiting to be.
    pub(super) fn cam_master(&self) -> Option<AxisSlot> {
        if self.idle(Idle::CAM) {
            // Nothing waits for its activation (`idle.rs`).
            return None;
        }
        self.cam.cam_in.as_ref().map(|p| p.master)
    }

    /// Runs generation `generation` of cam table `id` (the kernel retires data no slave runs).
    pub fn runs_cam(&self, id: u32, generation: u32) -> bool {
        self.cam_set().is_some_and(|set| {
            set.terms
                .iter()
                .flatten()
                .any(|l| l.table == id && l.generation == generation)
        })
    }

    /// Data written to table `id` waits to take effect on this slave.
    pub fn cam_data_queued_for(&self, id: u32) -> bool {
        self.cam.data.is_some_and(|d| {
            self.cam_set()
                .and_then(|set| set.terms[d.term])
                .is_some_and(|l| l.table == id)
        })
    }

    /// An online change of table `id` (new data in generation `generation`) is to reach this slave
    /// as `change` says (OFF: it keeps the data it runs).
    pub fn queue_cam_data(&mut self, id: u32, generation: u32, change: crate::cam::OnlineChange) {
        self.wake();
        let Some(set) = self.cam_set() else {
            return;
        };
        let Some(term) = set.find(id) else {
            return;
        };
        if change.activation_mode == Act::Off {
            return;
        }
        let law = set.terms[term].expect("found");
        let m = law.master_pos;
        // Decision 63: ASSOONASPOSSIBLE, like INSTANTANEOUS, is the first cycle where the new
        // data does not move the slave.
        let mode = match change.activation_mode {
            Act::AsSoonAsPossible => Act::Instantaneous,
            other => other,
        };
        self.cam.data = Some(PendingData {
            term,
            generation,
            act: Activation::new(mode, change.activation_position, m, law.raw(m)),
            master_scaling_mode: change.master_scaling_mode,
            slave_scaling_mode: change.slave_scaling_mode,
            due: false,
        });
        self.update_status();
    }

    /// MC_CamActivation DELETEQUEUEDDATA for table `id`: written data not yet in effect on
    /// this slave stays out of it.
    pub fn drop_cam_data(&mut self, id: u32) {
        self.wake();
        if self.cam_set().is_some_and(|set| set.find(id).is_some())
            && self.cam.data.take().is_some()
        {
            self.update_status();
        }
    }

    /// Coupled through cam `id`, or waiting for it.
    pub fn uses_cam(&self, id: u32) -> bool {
        let coupled = self.cam_set().is_some_and(|set| set.find(id).is_some());
        coupled
            || self.cam.cam_in.is_some_and(|p| p.ci.cam_table == id)
            || self.cam.switch.is_some_and(|p| p.what.cam_table == id)
    }

    /// A ramp-in runs: the planner holds the slave's deviation from its cams, which moves
    /// with neither a superposition nor a new coordinate origin (those shift the cams).
    pub(super) fn ramping_in(&self) -> bool {
        self.cam_set().is_some_and(|s| s.ramp)
    }

    /// The base cam of a cam slave (the only one of an MC_CamIn coupling).
    fn cam_law(&self) -> Option<CamLaw> {
        self.cam_set().map(|s| s.base())
    }

    /// Term `i` of the slave's cams.
    fn cam_term(&self, i: usize) -> Option<CamLaw> {
        self.cam_set().and_then(|s| s.terms[i])
    }

    /// The law a CamIn gives with the master at `m` and the slave at `s` (its set position);
    /// `before` is the law in force for a switch (autooffset and OFF refer to it).
    fn law_for(
        &self,
        ci: &CamIn,
        (cam, generation): (&Cam, u32),
        m: f64,
        s: f64,
        before: Option<(CamLaw, &Cam)>,
    ) -> CamLaw {
        let (mut mo, mut ms) = (ci.master_offset, ci.master_scaling);
        let (mut so, mut ss) = (ci.slave_offset, ci.slave_scaling);
        match (ci.master_scaling_mode, before) {
            (CamScalingMode::Off, Some((b, _))) => (mo, ms) = (b.mo, b.ms),
            (CamScalingMode::Off, None) => (mo, ms) = (0.0, 1.0),
            (CamScalingMode::AutoOffset, Some((b, old))) => {
                // Keep the relative position in the cycle (spec §1.8).
                let r = (b.x_local - old.master_range().0) / old.period();
                let x_new = cam.master_range().0 + r * cam.period();
                mo = ms * x_new - m;
            }
            _ if ci.start_mode.master_relative() => mo -= m,
            _ => {}
        }
        if ci.slave_scaling_mode == CamScalingMode::Off {
            (so, ss) = before.map_or((0.0, 1.0), |(b, _)| (b.so, b.ss));
        } else if ci.start_mode.slave_relative() {
            so += s;
        }
        let x = (m + mo) / ms;
        let k_base = if cam.periodic { cam.cycle_of(x).0 } else { 0 };
        let mut law = CamLaw {
            table: ci.cam_table,
            generation,
            mo,
            so,
            ms,
            ss,
            interpolation: ci.interpolation,
            cam_interpolation: cam.interpolation,
            k_base,
            master_absolute: !ci.start_mode.master_relative(),
            slave_absolute: !ci.start_mode.slave_relative(),
            master_coupling_pos: m,
            slave_coupling_pos: s,
            superimposed: before.map_or(0.0, |(b, _)| b.superimposed),
            cam_start: (cam.master_range().0, cam.slave_range().0),
            cam_period: cam.period(),
            cam_stroke: cam.stroke(),
            periodic: cam.periodic,
            x_local: 0.0,
            y_local: 0.0,
            strokes: 0.0,
            master_pos: m,
            hint: 0,
        };
        if ci.slave_scaling_mode == CamScalingMode::AutoOffset {
            // The slave stays where it is (spec §1.8: no jump in position).
            let at = law.eval(
                cam,
                &Kinematics {
                    position: m,
                    ..Kinematics::default()
                },
            );
            law.so += s - at.position;
        }
        law
    }

    /// Where a coupling joins its cam: without a jump (else 0x7084, see [`Axis::check_no_jump`]),
    /// or with a ramp-in start mode by catching up. Then the slave's deviation from the cam
    /// (position, velocity, acceleration) is planned down to 0 on the axis's planner, which
    /// is idle while the axis is coupled; `ramp_in_positive`/`_negative` first take the cam
    /// position modulo AxisEncoderModuloValue so that the catch-up runs that way and is shorter
    /// than one period. `stepped`: the master sample is this cycle's (an activation), the
    /// slave's setpoint still the last cycle's. True when a ramp-in was planned.
    fn join_cam(
        &mut self,
        ci: &CamIn,
        law: &mut CamLaw,
        cam: &Cam,
        m: &Kinematics,
        stepped: bool,
    ) -> Result<bool, ErrorId> {
        if !ci.start_mode.ramp_in() {
            // In the step the master has moved this cycle and the slave not yet: the cam is
            // compared with where the slave's own motion takes it in this cycle (a slave at
            // rest stays where it is; a geared slave goes on with its master), decision 175.
            let from = if stepped { self.carried_on() } else { self.set };
            self.check_no_jump(law, cam, m, from)?;
            return Ok(false);
        }
        let mut probe = *law;
        let mut at = probe.eval(cam, m);
        if stepped {
            // The deviation is planned from the slave's last setpoint: compare it with where
            // the cam was then (one cycle back along its own motion), so that the first
            // sample of the ramp, laid over this cycle's cam, continues the slave's motion.
            let dt = self.cycle_time;
            at = Kinematics {
                position: at.position - at.velocity * dt + 0.5 * at.acceleration * dt * dt,
                velocity: at.velocity - at.acceleration * dt,
                ..at
            };
        }
        let p = self.p();
        let mut deviation = self.set.position - at.position;
        let period = p.axis_encoder_modulo_value;
        let turns = match ci.start_mode {
            StartMode::RampInPositive => (deviation / period).ceil(),
            StartMode::RampInNegative => (deviation / period).floor(),
            _ => 0.0,
        };
        law.so += turns * period;
        deviation -= turns * period;
        let (acc, dec, jerk) = self.dynamics(Dynamics {
            acceleration: ci.ramp_in.acceleration,
            deceleration: ci.ramp_in.deceleration,
            jerk: ci.ramp_in.jerk,
        })?;
        let from = Kinematics {
            position: deviation,
            velocity: self.set.velocity - at.velocity,
            acceleration: self.set.acceleration - at.acceleration,
            jerk: 0.0,
        };
        let limits = Limits {
            velocity: ci.ramp_in.velocity,
            acceleration: acc,
            deceleration: dec,
            jerk,
        };
        self.planner
            .plan_position(from, 0.0, 0.0, &limits)
            .map_err(|_| ErrorId::PARAMETER_NOT_CORRECT)?;
        Ok(true)
    }

    /// 0x7084 when following `law` from now on would step the slave's position or velocity
    /// away from `from` (where the slave is, or where the law in force puts it in this cycle).
    fn check_no_jump(
        &self,
        law: &mut CamLaw,
        cam: &Cam,
        m: &Kinematics,
        from: Kinematics,
    ) -> Result<(), ErrorId> {
        let at = law.eval(cam, m);
        let p = self.p();
        // Written data must not move the slave at all; a coupling, switch or scaling may
        // start within the target window (the slave was pre-positioned to it).
        let runs_other_generation = self.cam_set().is_some_and(|set| {
            set.terms
                .iter()
                .flatten()
                .any(|t| t.table == law.table && t.generation != law.generation)
        });
        let window = if runs_other_generation {
            1e-6
        } else {
            p.axis_target_position_window.max(1e-9)
        };
        let dv = p.axis_acc * self.cycle_time * (1.0 + 1e-9) + 1e-9;
        if (at.position - from.position).abs() > window || (at.velocity - from.velocity).abs() > dv
        {
            // Where the cam wanted the slave: the refusal's answer says so (pre-position there).
            self.refusal_hint.set(Some(crate::RefusalHint::CamSlave {
                position: at.position,
                velocity: at.velocity,
                window,
            }));
            return Err(ErrorId::CAM_SLAVE_WOULD_JUMP);
        }
        Ok(())
    }

    /// MC_CamIn.
    pub(super) fn submit_cam_in(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
        ci: CamIn,
        master: Option<MasterSample>,
    ) -> Result<(), ErrorId> {
        let Some(cam) = cx.cams.get(ci.cam_table) else {
            return Err(ErrorId::CAM_TABLE_ID_INVALID);
        };
        if ci.interpolation == Some(InterpolationType::FourPoint) {
            return Err(ErrorId::CAM_TABLE_TYPE_INVALID);
        }
        let generation = cx.cams.generation(ci.cam_table);
        for v in [ci.master_offset, ci.slave_offset, ci.activation_position] {
            if !v.is_finite() {
                return Err(ErrorId::PARAMETER_NOT_CORRECT);
            }
        }
        if !finite_scaling(ci.master_scaling) || !finite_scaling(ci.slave_scaling) {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        if self.cam_set().is_some_and(|s| s.v2) || self.cam.cam_in.is_some_and(|p| p.v2) {
            return Err(ErrorId::CAM_FAMILY_MIXED);
        }
        let law_now = self.cam_law();
        let switching = law_now.is_some() && self.master_slot() == Some(ci.master);
        if ci.start_mode.ramp_in() {
            // A ramp-in couples; a switch must join the cam in force without a jump.
            if switching {
                return Err(ErrorId::CAM_MODE_INVALID);
            }
            self.check_velocity(ci.ramp_in.velocity)?;
            self.dynamics(Dynamics {
                acceleration: ci.ramp_in.acceleration,
                deceleration: ci.ramp_in.deceleration,
                jerk: ci.ramp_in.jerk,
            })?;
        }
        // Modes the manual allows (spec §1.6–§1.8).
        match ci.activation_mode {
            Act::NextCycleOnce | Act::AsSoonAsPossible | Act::Off => {
                return Err(ErrorId::CAM_MODE_INVALID);
            }
            Act::DeleteQueuedData if !switching => return Err(ErrorId::CAM_MODE_INVALID),
            Act::AtMasterCamPos | Act::NextCycle
                if !switching && ci.start_mode.master_relative() =>
            {
                return Err(ErrorId::CAM_MODE_INVALID);
            }
            _ => {}
        }
        if ci.master_scaling_mode == CamScalingMode::AutoOffset
            && (!switching || ci.start_mode.master_relative())
        {
            return Err(ErrorId::CAM_MODE_INVALID);
        }
        let m = self.admit_coupling(master)?;
        if switching {
            let law = law_now.expect("switching");
            if ci.activation_mode == Act::DeleteQueuedData {
                if let Some(mut q) = self.cam.switch.take() {
                    q.cmd.end(cx, End::Aborted);
                }
                let mut h = Held::start(
                    cx,
                    id,
                    FbOutputs {
                        busy: true,
                        ..FbOutputs::default()
                    },
                );
                h.end(cx, End::Done);
                return Ok(());
            }
            // Coupled tables stay in the store (the kernel refuses to take them out).
            let Some(old) = cx.cams.get_gen(law.table, law.generation) else {
                return Err(ErrorId::CAM_TABLE_ID_INVALID);
            };
            let act = Activation::new(
                ci.activation_mode,
                ci.activation_position,
                m.set.position,
                law.raw(m.set.position),
            );
            if let Some(mut q) = self.cam.switch.take() {
                // A newer switch replaces a queued one.
                q.cmd.end(cx, End::Aborted);
            }
            let cmd = Held::start(
                cx,
                id,
                FbOutputs {
                    busy: true,
                    active: true,
                    ..FbOutputs::default()
                },
            );
            let mut pending = PendingChange { cmd, what: ci, act };
            if act.at_once(m.set.position, law.raw(m.set.position)) {
                let mut probe = law;
                let now = probe.eval(old, &m.set);
                let mut new = self.law_for(
                    &ci,
                    (cam, generation),
                    m.set.position,
                    now.position,
                    Some((probe, old)),
                );
                match self.check_no_jump(&mut new, cam, &m.set, now) {
                    Ok(()) => {
                        self.set_cam_law(new);
                        pending.cmd.emit(
                            cx,
                            FbOutputs {
                                busy: false,
                                active: false,
                                in_sync: true,
                                ..pending.cmd.out
                            },
                        );
                    }
                    Err(e) => {
                        // The switch refused at once: nothing changes, the old cam runs on.
                        pending.cmd.end(cx, End::Error(e));
                    }
                }
            } else {
                self.cam.switch = Some(pending);
            }
            return Ok(());
        }
        // First coupling.
        self.couple_first(cx, id, ci, (cam, generation), &m, false)
    }

    /// A first coupling (MC_CamIn, MC_CamIn_V2 on an uncoupled axis): at once, or queued
    /// until its activation.
    fn couple_first(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
        ci: CamIn,
        (cam, generation): (&Cam, u32),
        m: &MasterSample,
        v2: bool,
    ) -> Result<(), ErrorId> {
        let mut law = self.law_for(
            &ci,
            (cam, generation),
            m.set.position,
            self.set.position,
            None,
        );
        let act = Activation::new(
            ci.activation_mode,
            ci.activation_position,
            m.set.position,
            law.raw(m.set.position),
        );
        if act.at_once(m.set.position, law.raw(m.set.position)) {
            let ramp = self.join_cam(&ci, &mut law, cam, &m.set, false)?;
            self.cancel_cam_in(cx, End::Aborted);
            let cmd = Held::start(
                cx,
                id,
                FbOutputs {
                    busy: true,
                    ..FbOutputs::default()
                },
            );
            self.start_cam_coupling(cx, ci.master, law, cmd, v2, ramp);
        } else {
            // The activation is watched on the master the slave follows now (the kernel steps
            // only its masters before it): a coupling that waits for another is refused, not
            // run from one master's position on another's (decision 174).
            if let Some(c) = self.coupling.as_ref().filter(|c| c.master != ci.master) {
                self.refusal_hint
                    .set(Some(crate::RefusalHint::FollowsMaster { master: c.master }));
                return Err(ErrorId::MASTER_INVALID);
            }
            self.cancel_cam_in(cx, End::Aborted);
            let cmd = Held::start(
                cx,
                id,
                FbOutputs {
                    busy: true,
                    active: true,
                    ..FbOutputs::default()
                },
            );
            self.cam.cam_in = Some(PendingCamIn {
                cmd,
                v2,
                master: ci.master,
                ci,
                act,
            });
        }
        Ok(())
    }

    /// Couples now: aborts what runs, the coupling job takes over, the command ends InSync.
    fn start_cam_coupling(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        master: AxisSlot,
        law: CamLaw,
        mut cmd: Held,
        v2: bool,
        ramp: bool,
    ) {
        self.abort_superposition(cx);
        self.abort_all(cx);
        let mut set = CamSet::single(law, v2);
        set.ramp = ramp;
        self.install_coupling(master, set, 0);
        if ramp {
            // The command keeps the axis (Active) until the slave has caught up (InSync).
            let out = FbOutputs {
                busy: true,
                active: true,
                ..FbOutputs::default()
            };
            cmd.emit(cx, out);
            let mut j = Job::new(cmd.id, JobKind::Gear);
            j.out = out;
            self.job = Some(j);
            return;
        }
        cmd.emit(
            cx,
            FbOutputs {
                busy: false,
                active: false,
                in_sync: true,
                ..cmd.out
            },
        );
        // The coupling goes on without an owning command until CamOut or a new motion.
        let mut j = Job::new(0, JobKind::Gear);
        j.out = FbOutputs {
            busy: true,
            ..FbOutputs::default()
        };
        self.job = Some(j);
    }

    fn set_cam_law(&mut self, law: CamLaw) {
        self.set_cam_term(0, law);
    }

    fn set_cam_term(&mut self, i: usize, law: CamLaw) {
        if let Some(set) = self.cam_set_mut() {
            set.terms[i] = Some(law);
        }
    }

    /// Ends a coupling that waits for its activation (a new command took the axis, an error).
    pub(super) fn cancel_cam_in(&mut self, cx: &mut Ctx<'_, impl EventSink>, end: End) {
        if let Some(mut p) = self.cam.cam_in.take() {
            p.cmd.end(cx, end);
        }
    }

    /// Ends the queued switch and scaling of a coupling that is gone.
    pub(super) fn settle_cam(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        // Marked idle: nothing queued or waiting (`idle.rs`).
        if self.idle(Idle::CAM) || self.cam_law().is_some() {
            return;
        }
        if self.cam.nothing_queued() && !self.cam.waits_for_coupling() {
            // Nothing to settle: an axis that never cams writes none of this every cycle.
            return;
        }
        self.cam.data = None;
        let end = if self.mode == Mode::ErrorStop {
            End::Error(self.error)
        } else {
            End::Aborted
        };
        if let Some(mut q) = self.cam.switch.take() {
            q.cmd.end(cx, end);
        }
        if let Some(mut q) = self.cam.scaling.take() {
            q.cmd.end(cx, end);
        }
        if let Some(mut q) = self.cam.v2_op.take() {
            q.cmd.end(cx, end);
        }
        if self.mode == Mode::ErrorStop || self.mode == Mode::Disabled {
            self.cancel_cam_in(cx, end);
        }
    }

    /// MC_CamOut: decouple; the slave keeps its velocity (as after GearOut). A coupling that
    /// still waits for its activation is dropped.
    pub(super) fn submit_cam_out(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
    ) -> Result<(), ErrorId> {
        if self.cam_law().is_none() {
            if self.cam.cam_in.is_none() {
                return Err(ErrorId::CAM_NOT_COUPLED);
            }
            self.cancel_cam_in(cx, End::Aborted);
        } else {
            self.abort_superposition(cx);
            self.coupling = None;
            if let Some(mut j) = self.job.take() {
                j.finish_aborted(cx);
            }
            self.settle_cam(cx);
            self.continue_at_current_velocity(cx);
        }
        self.cam.last_info = CamInfo::default();
        self.cam.idle_info = false;
        cx.report(id, DONE);
        Ok(())
    }

    /// MC_CamScaling.
    pub(super) fn submit_cam_scaling(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
        sc: CamScaling,
    ) -> Result<(), ErrorId> {
        if self.cam_set().is_some_and(|s| s.v2) {
            return Err(ErrorId::CAM_FAMILY_MIXED);
        }
        self.cam.scaling_term = 0;
        self.queue_cam_scaling(cx, id, sc)
    }

    /// MC_CamScaling(_V2) of the cam `cam_scaling_term`: at once or at its activation.
    fn queue_cam_scaling(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
        sc: CamScaling,
    ) -> Result<(), ErrorId> {
        let Some(law) = self.cam_term(self.cam.scaling_term) else {
            return Err(ErrorId::CAM_NOT_COUPLED);
        };
        for v in [sc.master_offset, sc.slave_offset, sc.activation_position] {
            if !v.is_finite() {
                return Err(ErrorId::PARAMETER_NOT_CORRECT);
            }
        }
        if !finite_scaling(sc.master_scaling) || !finite_scaling(sc.slave_scaling) {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        match sc.activation_mode {
            Act::Instantaneous
            | Act::AtMasterCamPos
            | Act::AtMasterAxisPos
            | Act::AtMasterAxisPosPositiveDirection
            | Act::AtMasterAxisPosNegativeDirection
            | Act::NextCycle => {}
            Act::Off => {
                // No scaling is done (spec §1.7).
                cx.report(id, DONE);
                return Ok(());
            }
            _ => return Err(ErrorId::CAM_MODE_INVALID),
        }
        if let Some(mut q) = self.cam.scaling.take() {
            q.cmd.end(cx, End::Aborted);
        }
        let m = law.master_pos;
        let act = Activation::new(sc.activation_mode, sc.activation_position, m, law.raw(m));
        let cmd = Held::start(
            cx,
            id,
            FbOutputs {
                busy: true,
                active: true,
                ..FbOutputs::default()
            },
        );
        self.cam.scaling = Some(PendingChange { cmd, what: sc, act });
        if act.at_once(m, law.raw(m)) {
            let master = Kinematics {
                position: m,
                velocity: self.cam.last_master.velocity,
                acceleration: self.cam.last_master.acceleration,
                jerk: 0.0,
            };
            self.apply_scaling(cx, &master);
        }
        Ok(())
    }

    /// The scaling's new law from here (autooffset keeps the slave and the master's phase).
    fn scaled(&self, law: CamLaw, sc: &CamScaling, cam: &Cam, m: f64) -> CamLaw {
        let mut new = law;
        match sc.master_scaling_mode {
            CamScalingMode::Off => {}
            CamScalingMode::UserDefined => (new.mo, new.ms) = (sc.master_offset, sc.master_scaling),
            CamScalingMode::AutoOffset => {
                // The same raw position in the cam (and so the same phase) after the change.
                new.ms = sc.master_scaling;
                new.mo = law.raw(m) * new.ms - m;
            }
        }
        match sc.slave_scaling_mode {
            CamScalingMode::Off => {}
            CamScalingMode::UserDefined => {
                (new.so, new.ss) = (sc.slave_offset + law.superimposed, sc.slave_scaling)
            }
            CamScalingMode::AutoOffset => {
                new.ss = sc.slave_scaling;
                let mut probe = new;
                let at = probe.eval(
                    cam,
                    &Kinematics {
                        position: m,
                        ..Kinematics::default()
                    },
                );
                let before = law.clone().eval(
                    cam,
                    &Kinematics {
                        position: m,
                        ..Kinematics::default()
                    },
                );
                new.so += before.position - at.position;
            }
        }
        new
    }

    fn apply_scaling(&mut self, cx: &mut Ctx<'_, impl EventSink>, master: &Kinematics) {
        let term = self.cam.scaling_term;
        let (Some(law), Some(mut q)) = (self.cam_term(term), self.cam.scaling.take()) else {
            return;
        };
        let Some(cam) = cx.cams.get_gen(law.table, law.generation) else {
            q.cmd.end(cx, End::Error(ErrorId::CAM_TABLE_ID_INVALID));
            return;
        };
        let mut new = self.scaled(law, &q.what, cam, master.position);
        let mut probe = law;
        let now = probe.eval(cam, master);
        match self.check_no_jump(&mut new, cam, master, now) {
            Ok(()) => {
                self.set_cam_term(term, new);
                q.cmd.end(cx, End::Done);
            }
            Err(e) => q.cmd.end(cx, End::Error(e)),
        }
    }

    /// The slave's last setpoint carried on by its own motion for one cycle: where it is in
    /// this cycle's step before its job has run (decision 175).
    fn carried_on(&self) -> Kinematics {
        let (s, dt) = (self.set, self.cycle_time);
        Kinematics {
            position: s.position + s.velocity * dt + 0.5 * s.acceleration * dt * dt,
            velocity: s.velocity + s.acceleration * dt,
            ..s
        }
    }

    /// Each cycle before the coupling's setpoint: a queued coupling, switch or scaling takes
    /// effect when its activation is reached.
    pub(super) fn step_cam_activations(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        master: Master,
    ) {
        let Master::Sample(m) = master else {
            // (Asked without copying the pending coupling.)
            if master == Master::Lost && self.cam.cam_in.is_some() {
                self.cancel_cam_in(cx, End::Error(ErrorId::MASTER_LOST));
            }
            return;
        };
        self.cam.last_master = m.set;
        if let Some(mut p) = self.cam.cam_in.take() {
            if m.error {
                p.cmd.end(cx, End::Error(ErrorId::MASTER_INVALID));
            } else if let Some(cam) = cx.cams.get(p.ci.cam_table) {
                let generation = cx.cams.generation(p.ci.cam_table);
                // A relative slave start counts from where the slave is in this cycle (the
                // position the no-jump check compares with); a ramp-in plans from its last
                // setpoint.
                let slave_at = if p.ci.start_mode.ramp_in() {
                    self.set.position
                } else {
                    self.carried_on().position
                };
                let law = self.law_for(&p.ci, (cam, generation), m.set.position, slave_at, None);
                if p.act.reached(m.set.position, law.raw(m.set.position), cam) {
                    // Coupled from the slave's and the master's positions at activation.
                    let mut law =
                        self.law_for(&p.ci, (cam, generation), m.set.position, slave_at, None);
                    match self.join_cam(&p.ci, &mut law, cam, &m.set, true) {
                        Ok(ramp) => self.start_cam_coupling(cx, p.master, law, p.cmd, p.v2, ramp),
                        Err(e) => p.cmd.end(cx, End::Error(e)),
                    }
                } else {
                    self.cam.cam_in = Some(p);
                }
            } else {
                p.cmd.end(cx, End::Error(ErrorId::CAM_TABLE_ID_INVALID));
            }
        }
        let Some(law) = self.cam_law() else {
            return;
        };
        let Some(cam) = cx.cams.get_gen(law.table, law.generation) else {
            return;
        };
        let raw = law.raw(m.set.position);
        if let Some(mut q) = self.cam.switch.take() {
            if q.act.reached(m.set.position, raw, cam) {
                match cx.cams.get(q.what.cam_table) {
                    Some(new_cam) => {
                        // Where the cam in force puts the slave in this cycle: the switch joins it there.
                        let mut probe = law;
                        let now = probe.eval(cam, &m.set);
                        let generation = cx.cams.generation(q.what.cam_table);
                        let mut new = self.law_for(
                            &q.what,
                            (new_cam, generation),
                            m.set.position,
                            now.position,
                            Some((probe, cam)),
                        );
                        match self.check_no_jump(&mut new, new_cam, &m.set, now) {
                            Ok(()) => {
                                self.set_cam_law(new);
                                q.cmd.emit(
                                    cx,
                                    FbOutputs {
                                        busy: false,
                                        active: false,
                                        in_sync: true,
                                        ..q.cmd.out
                                    },
                                );
                            }
                            Err(e) => q.cmd.end(cx, End::Error(e)),
                        }
                    }
                    None => q.cmd.end(cx, End::Error(ErrorId::CAM_TABLE_ID_INVALID)),
                }
            } else {
                self.cam.switch = Some(q);
            }
        }
        self.step_cam_v2(cx, &m.set, raw, cam);
        if let Some(mut d) = self.cam.data {
            match self.cam_term(d.term) {
                Some(term) => {
                    let term_cam = cx.cams.get_gen(term.table, term.generation);
                    let raw_t = term.raw(m.set.position);
                    if let Some(tc) = term_cam {
                        d.due = d.act.reached(m.set.position, raw_t, tc) || d.due;
                    }
                    self.cam.data = Some(d);
                    if let (true, Some(tc), Some(new_cam)) =
                        (d.due, term_cam, cx.cams.get_gen(term.table, d.generation))
                    {
                        self.take_cam_data(d, term, tc, new_cam, &m.set);
                    }
                }
                None => self.cam.data = None,
            }
        }
        if let Some(mut q) = self.cam.scaling {
            if q.act.reached(m.set.position, raw, cam) {
                self.apply_scaling(cx, &m.set);
            } else {
                self.cam.scaling = Some(q);
            }
        }
    }

    /// The same coupling on the new data of an online change; it takes effect only where it
    /// does not move the slave (spec §1.10: "no direct effect on the slave").
    fn take_cam_data(
        &mut self,
        d: PendingData,
        law: CamLaw,
        cam: &Cam,
        new_cam: &Cam,
        m: &Kinematics,
    ) {
        let mut probe = law;
        let now = probe.eval(cam, m);
        let ci = CamIn {
            master: 0,
            cam_table: law.table,
            master_offset: law.mo,
            slave_offset: law.so,
            master_scaling: law.ms,
            slave_scaling: law.ss,
            start_mode: crate::cam::StartMode::Absolute,
            activation_mode: Act::Instantaneous,
            activation_position: 0.0,
            master_scaling_mode: d.master_scaling_mode,
            slave_scaling_mode: d.slave_scaling_mode,
            interpolation: law.interpolation,
            ramp_in: RampIn::default(),
        };
        let mut new = self.law_for(
            &ci,
            (new_cam, d.generation),
            m.position,
            now.position,
            Some((probe, cam)),
        );
        // Offsets as they were unless autooffset: the coupling keeps its base cycle.
        if d.master_scaling_mode != CamScalingMode::AutoOffset {
            new.k_base = law.k_base;
        }
        new.master_absolute = law.master_absolute;
        new.slave_absolute = law.slave_absolute;
        new.master_coupling_pos = law.master_coupling_pos;
        new.slave_coupling_pos = law.slave_coupling_pos;
        if self.check_no_jump(&mut new, new_cam, m, now).is_ok() {
            self.set_cam_term(d.term, new);
            self.cam.data = None;
        }
    }

    /// MC_CamInfo and the camming status flags.
    pub(super) fn cam_status(&self) -> (CamInfo, bool, bool) {
        let mut info = match (self.cam_law(), self.master_slot()) {
            (Some(l), Some(master)) => l.info(master, self.set.position),
            _ => CamInfo::default(),
        };
        if let Some(q) = &self.cam.scaling {
            info.scaling_pending = true;
            info.scaling_activation_mode = q.act.mode;
            info.scaling_activation_pos = q.act.position;
        }
        if let Some(q) = &self.cam.switch {
            info.cam_table_queued = true;
            info.cam_exchange_cam_table_id = q.what.cam_table;
            info.cam_exchange_activation_mode = q.act.mode;
            info.cam_exchange_activation_pos = q.act.position;
        }
        if let Some(q) = &self.cam.v2_op {
            info.cam_table_queued = true;
            info.cam_exchange_cam_table_id = q.what.cam_table;
            info.cam_exchange_activation_mode = q.act.mode;
            info.cam_exchange_activation_pos = q.act.position;
        }
        info.cam_data_queued = self.cam.data.is_some();
        if let Some(set) = self.cam_set() {
            info.multi_cam = set.v2;
            for (k, t) in set.terms.iter().enumerate() {
                if let Some(t) = t {
                    info.cams[k] = CamTerm {
                        cam_table_id: t.table,
                        master_offset: t.mo,
                        slave_offset: t.so,
                        master_scaling: t.ms,
                        slave_scaling: t.ss,
                        actual_master_cam_pos: t.x_local,
                        actual_slave_cam_pos: t.y_local,
                        slave_contribution: (t.y_local + t.strokes) * t.ss + t.so,
                        sum_of_slave_strokes: t.strokes * t.ss,
                        interpolation: t.interpolation.unwrap_or(t.cam_interpolation),
                    };
                }
            }
        }
        let queued = self.cam.switch.is_some() || self.cam.v2_op.is_some();
        (info, queued, self.cam.scaling.is_some())
    }
}

/// A CamIn of the first cam (or a cam to add or exchange) from MC_CamIn_V2's scaling data.
fn as_cam_in(op: &CamInV2) -> CamIn {
    let d = op.scaling;
    CamIn {
        master: op.master,
        cam_table: op.cam_table,
        master_offset: d.master_offset,
        slave_offset: d.slave_offset,
        master_scaling: d.master_scaling,
        slave_scaling: d.slave_scaling,
        start_mode: match (d.master_relative, d.slave_relative) {
            (false, false) => StartMode::Absolute,
            (true, true) => StartMode::Relative,
            (false, true) => StartMode::MasterAbsSlaveRel,
            (true, false) => StartMode::MasterRelSlaveAbs,
        },
        activation_mode: op.activation_mode,
        activation_position: op.activation_position,
        master_scaling_mode: d.master_scaling_mode,
        slave_scaling_mode: d.slave_scaling_mode,
        interpolation: op.interpolation,
        ramp_in: RampIn::default(),
    }
}

impl Axis {
    /// MC_CamIn_V2, MC_CamAdd, MC_CamExchange, MC_CamRemove (spec §1.9, §2.5–§2.8).
    pub(super) fn submit_cam_in_v2(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
        op: CamInV2,
        master: Option<MasterSample>,
    ) -> Result<(), ErrorId> {
        let Some(cam) = cx.cams.get(op.cam_table) else {
            return Err(ErrorId::CAM_TABLE_ID_INVALID);
        };
        if op.interpolation == Some(InterpolationType::FourPoint) {
            return Err(ErrorId::CAM_TABLE_TYPE_INVALID);
        }
        let d = op.scaling;
        for v in [d.master_offset, d.slave_offset, op.activation_position] {
            if !v.is_finite() {
                return Err(ErrorId::PARAMETER_NOT_CORRECT);
            }
        }
        if !finite_scaling(d.master_scaling) || !finite_scaling(d.slave_scaling) {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        if matches!(
            op.activation_mode,
            Act::NextCycleOnce | Act::AsSoonAsPossible | Act::Off
        ) {
            return Err(ErrorId::CAM_MODE_INVALID);
        }
        let ci = as_cam_in(&op);
        let Some(set) = self.cam_set() else {
            if self.cam.cam_in.is_some_and(|p| !p.v2) {
                return Err(ErrorId::CAM_FAMILY_MIXED);
            }
            // Not coupled: the first call couples (additive); nothing to exchange or remove.
            return match op.operation {
                CamOperationMode::Default | CamOperationMode::Additive => {
                    // (cam-position activation or AutoOffset) and (master relative or
                    // AutoOffset), written out: AutoOffset always, a cam-position activation
                    // only on a relative master.
                    let auto_offset = d.master_scaling_mode == CamScalingMode::AutoOffset;
                    let at_cam_pos =
                        matches!(op.activation_mode, Act::AtMasterCamPos | Act::NextCycle);
                    if matches!(op.activation_mode, Act::DeleteQueuedData)
                        || auto_offset
                        || (at_cam_pos && d.master_relative)
                    {
                        return Err(ErrorId::CAM_MODE_INVALID);
                    }
                    let m = self.admit_coupling(master)?;
                    let generation = cx.cams.generation(op.cam_table);
                    self.couple_first(cx, id, ci, (cam, generation), &m, true)
                }
                _ => Err(ErrorId::CAM_NOT_COUPLED),
            };
        };
        if !set.v2 {
            return Err(ErrorId::CAM_FAMILY_MIXED);
        }
        if self.master_slot() != Some(op.master) {
            // A multi-cam slave follows one master.
            return Err(ErrorId::MASTER_INVALID);
        }
        let m = self.admit_coupling(master)?;
        if op.activation_mode == Act::DeleteQueuedData {
            if let Some(mut q) = self.cam.v2_op.take() {
                q.cmd.end(cx, End::Aborted);
            }
            let mut h = Held::start(
                cx,
                id,
                FbOutputs {
                    busy: true,
                    ..FbOutputs::default()
                },
            );
            h.end(cx, End::Done);
            return Ok(());
        }
        // Checked now, so that a queued operation can only fail for a jump at its activation.
        self.v2_term(set, &op)?;
        let base = set.base();
        let act = Activation::new(
            op.activation_mode,
            op.activation_position,
            m.set.position,
            base.raw(m.set.position),
        );
        if act.at_once(m.set.position, base.raw(m.set.position)) {
            // Refused outright when it would make the slave jump: nothing changes.
            let new = self.v2_apply(cx, &op, &m.set)?;
            self.set_cam_set(new);
            let mut h = Held::start(
                cx,
                id,
                FbOutputs {
                    busy: true,
                    ..FbOutputs::default()
                },
            );
            self.v2_end(cx, &mut h, &op, Ok(()));
            return Ok(());
        }
        if let Some(mut q) = self.cam.v2_op.take() {
            q.cmd.end(cx, End::Aborted);
        }
        let cmd = Held::start(
            cx,
            id,
            FbOutputs {
                busy: true,
                active: true,
                ..FbOutputs::default()
            },
        );
        self.cam.v2_op = Some(PendingChange { cmd, what: op, act });
        Ok(())
    }

    /// The term an operation works on (exchange: the reference cam; remove: the cam), or why
    /// it cannot be done.
    fn v2_term(&self, set: &CamSet, op: &CamInV2) -> Result<Option<usize>, ErrorId> {
        match op.operation {
            CamOperationMode::Default | CamOperationMode::Additive => {
                if set.count() == MAX_CAMS {
                    return Err(ErrorId::BUFFER_FULL);
                }
                if set.find(op.cam_table).is_some() {
                    return Err(ErrorId::CAM_MODE_INVALID);
                }
                Ok(None)
            }
            CamOperationMode::Exchange => match op.reference_cam_table {
                0 if set.count() == 1 => Ok(Some(0)),
                0 => Err(ErrorId::CAM_MODE_INVALID), // ambiguous
                r => set.find(r).map(Some).ok_or(ErrorId::CAM_TABLE_ID_INVALID),
            },
            CamOperationMode::Remove => {
                let i = set
                    .find(op.cam_table)
                    .ok_or(ErrorId::CAM_TABLE_ID_INVALID)?;
                if set.count() == 1 {
                    // The last cam: MC_CamOut decouples.
                    return Err(ErrorId::CAM_MODE_INVALID);
                }
                Ok(Some(i))
            }
        }
    }

    /// The slave's cams after `op` with the master at `m`; 0x7084 when it would make the
    /// slave jump.
    fn v2_apply(
        &self,
        cx: &Ctx<'_, impl EventSink>,
        op: &CamInV2,
        m: &Kinematics,
    ) -> Result<CamSet, ErrorId> {
        let mut set = *self.cam_set().ok_or(ErrorId::CAM_NOT_COUPLED)?;
        let term = self.v2_term(&set, op)?;
        let cam = cx
            .cams
            .get(op.cam_table)
            .ok_or(ErrorId::CAM_TABLE_ID_INVALID)?;
        let generation = cx.cams.generation(op.cam_table);
        let ci = as_cam_in(op);
        match (op.operation, term) {
            (CamOperationMode::Exchange, Some(i)) => {
                let old = set.terms[i].expect("found");
                let old_cam = cx
                    .cams
                    .get_gen(old.table, old.generation)
                    .ok_or(ErrorId::CAM_TABLE_ID_INVALID)?;
                let mut probe = old;
                let now = probe.eval(old_cam, m);
                let mut new = self.law_for(
                    &ci,
                    (cam, generation),
                    m.position,
                    now.position,
                    Some((probe, old_cam)),
                );
                self.check_no_jump(&mut new, cam, m, now)?;
                set.terms[i] = Some(new);
            }
            (CamOperationMode::Remove, Some(i)) => {
                let mut old = set.terms[i].expect("found");
                let old_cam = cx
                    .cams
                    .get_gen(old.table, old.generation)
                    .ok_or(ErrorId::CAM_TABLE_ID_INVALID)?;
                let now = old.eval(old_cam, m);
                // Its position stays (folded into the base's offset); its velocity must not step.
                let p = self.p();
                if now.velocity.abs() > p.axis_acc * self.cycle_time * (1.0 + 1e-9) + 1e-9 {
                    return Err(ErrorId::CAM_SLAVE_WOULD_JUMP);
                }
                set.remove(i);
                if let Some(b) = set.terms[0].as_mut() {
                    b.so += now.position;
                }
            }
            _ => {
                // An added cam: with a relative slave (or slave autooffset) its contribution
                // starts from 0 here (its offset shifts it from there: a jump, refused like
                // any other); absolute, its contribution must already be 0 here.
                let start_mode = if ci.start_mode.master_relative() {
                    StartMode::MasterRelSlaveAbs
                } else {
                    StartMode::Absolute
                };
                let ci = CamIn {
                    start_mode,
                    slave_scaling_mode: CamScalingMode::UserDefined,
                    ..ci
                };
                let mut new = self.law_for(&ci, (cam, generation), m.position, 0.0, None);
                if op.scaling.slave_relative
                    || op.scaling.slave_scaling_mode == CamScalingMode::AutoOffset
                {
                    let mut probe = new;
                    let at = probe.eval(
                        cam,
                        &Kinematics {
                            position: m.position,
                            ..Kinematics::default()
                        },
                    );
                    new.so -= at.position - op.scaling.slave_offset;
                }
                self.check_no_jump(&mut new, cam, m, Kinematics::default())?;
                let k = set.count();
                set.terms[k] = Some(new);
            }
        }
        Ok(set)
    }

    fn set_cam_set(&mut self, set: CamSet) {
        if let Some(s) = self.cam_set_mut() {
            *s = set;
        }
    }

    /// How an operation ends: add and exchange with InSync, remove with Done (spec §2.8).
    fn v2_end(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        h: &mut Held,
        op: &CamInV2,
        r: Result<(), ErrorId>,
    ) {
        match r {
            Err(e) => h.end(cx, End::Error(e)),
            Ok(()) if op.operation == CamOperationMode::Remove => h.end(cx, End::Done),
            Ok(()) => h.emit(
                cx,
                FbOutputs {
                    busy: false,
                    active: false,
                    in_sync: true,
                    ..h.out
                },
            ),
        }
    }

    /// A queued multi-cam operation takes effect at its activation.
    fn step_cam_v2(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        m: &Kinematics,
        raw: f64,
        cam: &Cam,
    ) {
        let Some(mut q) = self.cam.v2_op.take() else {
            return;
        };
        if !q.act.reached(m.position, raw, cam) {
            self.cam.v2_op = Some(q);
            return;
        }
        let r = self
            .v2_apply(cx, &q.what, m)
            .map(|set| self.set_cam_set(set));
        let op = q.what;
        self.v2_end(cx, &mut q.cmd, &op, r);
    }

    /// MC_CamScaling_V2: MC_CamScaling for one cam of the slave.
    pub(super) fn submit_cam_scaling_v2(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
        sc: CamScalingV2,
    ) -> Result<(), ErrorId> {
        let set = self.cam_set().ok_or(ErrorId::CAM_NOT_COUPLED)?;
        let term = match sc.cam_table {
            0 if set.count() == 1 => 0,
            0 => return Err(ErrorId::CAM_MODE_INVALID),
            t => set.find(t).ok_or(ErrorId::CAM_TABLE_ID_INVALID)?,
        };
        let d = sc.scaling;
        let law = set.terms[term].expect("found");
        let m = law.master_pos;
        let scaling = CamScaling {
            activation_mode: sc.activation_mode,
            activation_position: sc.activation_position,
            master_scaling_mode: d.master_scaling_mode,
            slave_scaling_mode: d.slave_scaling_mode,
            master_offset: d.master_offset - if d.master_relative { m } else { 0.0 },
            slave_offset: d.slave_offset
                + if d.slave_relative {
                    self.set.position
                } else {
                    0.0
                },
            master_scaling: d.master_scaling,
            slave_scaling: d.slave_scaling,
        };
        if self.cam.scaling.is_some() && self.cam.scaling_term != term {
            // One queued scaling per slave: a new one replaces it.
            if let Some(mut q) = self.cam.scaling.take() {
                q.cmd.end(cx, End::Aborted);
            }
        }
        self.cam.scaling_term = term;
        self.queue_cam_scaling(cx, id, scaling)
    }
}

/// A ramp-in's cycle: its deviation laid over the cams' setpoint `set`; InSync (and the
/// MC_CamIn ends) when it has run down to 0.
pub(super) fn step_ramp_in(
    cx: &mut Ctx<'_, impl EventSink>,
    job: &mut Job,
    cams: &mut CamSet,
    planner: &mut Planner,
    set: &mut Kinematics,
    dt: f64,
) {
    if !cams.ramp {
        return;
    }
    if let Some(e) = planner.step(dt) {
        set.position += e.position;
        set.velocity += e.velocity;
        set.acceleration += e.acceleration;
        set.jerk += e.jerk;
    }
    if planner.finished() {
        cams.ramp = false;
        planner.clear();
        let out = FbOutputs {
            busy: false,
            active: false,
            in_sync: true,
            ..job.out
        };
        job.emit(cx, out);
        // The coupling goes on without an owning command, as after an immediate one.
        job.id = 0;
        job.out = FbOutputs {
            busy: true,
            ..FbOutputs::default()
        };
    }
}

#[cfg(test)]
mod tests {
    use super::crossed;

    #[test]
    fn crossings_are_found_between_two_cycles_in_either_direction() {
        assert!(crossed(499.0, 500.0, 500.0, None));
        assert!(
            !crossed(500.0, 501.0, 500.0, None),
            "from the position itself is not a crossing"
        );
        assert!(crossed(501.0, 499.0, 500.0, None));
        assert!(!crossed(499.0, 499.5, 500.0, None));
        // Periodic: any occurrence t + n·P.
        assert!(crossed(710.0, 730.0, 0.0, Some(360.0)));
        assert!(crossed(-10.0, 10.0, 0.0, Some(360.0)));
        assert!(crossed(370.0, 350.0, 0.0, Some(360.0)));
        assert!(!crossed(10.0, 350.0, 0.0, Some(360.0)));
        assert!(crossed(10.0, 100.0, 90.0, Some(360.0)));
        assert!(crossed(1000.0, 1200.0, 90.0, Some(360.0)));
    }
}
