//! Virtual-time test rig: a kernel, an ideal/PT1 plant per axis with cam, index pulse and
//! latch, and invariant checks that run in EVERY cycle (FB protocol, state diagram,
//! continuity, velocity/acceleration/jerk bounds of the axis, and of a motion command started
//! from rest and left undisturbed its own dynamics: see [`FromRest`]; a positioning job never
//! moves away from its target: see [`Course`]; the set position never leaves an enabled
//! software limit while the axis is commanded: see `check_soft_limits`).
#![allow(
    dead_code,
    reason = "every test crate includes the rig and uses a part of it"
)]

use std::collections::{HashMap, HashSet};

use motion::planner::sign;
use motion::*;

pub const DT: f64 = 0.001;

/// A simple plant: actual follows the previous setpoint through an optional PT1.
#[derive(Clone, Debug)]
pub struct Plant {
    pub pos: f64,
    pub vel: f64,
    pub tau: f64,
    pub enabled: bool,
    pub enable_delay_cycles: u32,
    pending: u32,
    pub fault: bool,
    pub fault_code: u32,
    /// The bus cannot reach the drive (its feedback is flagged; the drive keeps following).
    pub bus_error: bool,
    pub cam: Option<(f64, f64)>,
    pub index_period: Option<f64>,
    pub limit_positive: bool,
    pub limit_negative: bool,
    /// Extra lag added to the actual position (a load that the drive cannot hold).
    pub load_lag: f64,
    /// A measuring probe's mark: digital input 1 is on at and beyond it.
    pub probe_mark: Option<f64>,
    latch_valid: bool,
    latch_pos: f64,
    prev_pos: f64,
    prev_cam: bool,
    /// Torque mode (the last setpoint asked for it): the load accelerates with
    /// `torque_acceleration` per percent, less `friction` percent against the motion, and the
    /// drive holds the velocity within the setpoint's limits.
    pub torque_mode: bool,
    /// A drive that does not leave torque mode when asked back to position (the manual's
    /// danger note): it stays in it with no torque.
    pub stays_in_torque: bool,
    pub torque_acceleration: f64,
    pub friction: f64,
    torque: f64,
    velocity_limited: bool,
}

impl Default for Plant {
    fn default() -> Self {
        Plant {
            pos: 0.0,
            vel: 0.0,
            tau: 0.0,
            enabled: false,
            enable_delay_cycles: 3,
            pending: 0,
            fault: false,
            fault_code: 0,
            bus_error: false,
            cam: None,
            index_period: None,
            limit_positive: false,
            limit_negative: false,
            load_lag: 0.0,
            probe_mark: None,
            torque_mode: false,
            stays_in_torque: false,
            torque_acceleration: 100.0,
            friction: 1.0,
            torque: 0.0,
            velocity_limited: false,
            latch_valid: false,
            latch_pos: 0.0,
            prev_pos: 0.0,
            prev_cam: false,
        }
    }
}

impl Plant {
    fn cam_at(&self, p: f64) -> bool {
        self.cam.is_some_and(|(a, b)| p >= a && p <= b)
    }

    pub fn feedback(&self) -> DriveFeedback {
        DriveFeedback {
            bus_error: self.bus_error,
            ready: !self.fault,
            enabled: self.enabled,
            fault: self.fault,
            fault_code: self.fault_code,
            actual_position: self.pos - self.load_lag,
            actual_velocity: self.vel,
            reference_cam: self.cam_at(self.pos),
            limit_positive: self.limit_positive,
            limit_negative: self.limit_negative,
            latch_valid: self.latch_valid,
            latch_position: self.latch_pos,
            mode: if self.torque_mode {
                DriveMode::Torque
            } else {
                DriveMode::Configured
            },
            actual_torque: self.torque,
            velocity_limited: self.velocity_limited,
            profile: Default::default(),
        }
    }

    pub fn apply(&mut self, sp: &DriveSetpoint, dt: f64) {
        if sp.fault_reset {
            self.fault = false;
        }
        if sp.enable && !self.fault {
            if !self.enabled {
                self.pending += 1;
                if self.pending >= self.enable_delay_cycles {
                    self.enabled = true;
                }
            }
        } else {
            self.enabled = false;
            self.pending = 0;
        }
        self.prev_pos = self.pos;
        self.torque_mode = (sp.mode == DriveMode::Torque
            || (self.stays_in_torque && self.torque_mode))
            && self.enabled;
        self.velocity_limited = false;
        if self.torque_mode {
            let torque = if sp.mode == DriveMode::Torque {
                sp.torque
            } else {
                0.0
            };
            let drag = if self.vel != 0.0 {
                self.friction * self.vel.signum()
            } else {
                0.0
            };
            let mut v = self.vel + (torque - drag) * self.torque_acceleration * dt;
            if v > sp.velocity_limit_high || v < sp.velocity_limit_low {
                v = v.clamp(sp.velocity_limit_low, sp.velocity_limit_high);
                self.velocity_limited = true;
            }
            self.pos += 0.5 * (self.vel + v) * dt;
            self.vel = v;
            self.torque = torque;
        } else if self.enabled {
            let target = sp.position;
            let new = if self.tau > 0.0 {
                self.pos + (target - self.pos) * (1.0 - (-dt / self.tau).exp())
            } else {
                target
            };
            self.vel = (new - self.pos) / dt;
            self.pos = new;
        } else {
            self.vel = 0.0;
        }
        // Latch.
        if !sp.latch_enable {
            self.latch_valid = false;
        } else if !self.latch_valid {
            let (a, b) = (self.prev_pos, self.pos);
            let hit = match sp.latch_source {
                LatchSource::IndexPulse => self.index_period.and_then(|per| {
                    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
                    let k = (lo / per).ceil() * per;
                    (k <= hi && a != b && k != a).then_some(k)
                }),
                LatchSource::Input1Rising | LatchSource::Input1Falling => {
                    self.probe_mark.and_then(|m| {
                        let up = a < m && m <= b;
                        let down = b < m && m <= a;
                        let rising = sp.latch_source == LatchSource::Input1Rising;
                        ((rising && up) || (!rising && down)).then_some(m)
                    })
                }
                LatchSource::CamRising | LatchSource::CamFalling => {
                    let (ca, cb) = (self.cam_at(a), self.cam_at(b));
                    let want = sp.latch_source == LatchSource::CamRising;
                    if ca != cb && cb == want {
                        let (s, e) = self.cam.unwrap();
                        Some(if (b > a) == want { s } else { e })
                    } else {
                        None
                    }
                }
            };
            if let Some(p) = hit {
                self.latch_valid = true;
                self.latch_pos = p;
            }
        }
        self.prev_cam = self.cam_at(self.pos);
    }
}

/// Bounds checked every cycle for one axis.
#[derive(Clone, Copy, Debug)]
pub struct Bounds {
    pub velocity: f64,
    pub acceleration: f64,
    pub jerk: f64,
}

/// A positioning or velocity command that started from rest (v = 0, a = 0) and has run
/// undisturbed since: no other command on its axis was accepted (nothing aborted, blended,
/// buffered, overrode, stopped or superimposed it). Every cycle its own dynamics bound the
/// setpoint: |v| ≤ velocity × override, |a| ≤ acceleration while |v| rises and ≤ deceleration
/// while it falls, |j| ≤ jerk (axis defaults for 0).
#[derive(Clone, Copy, Debug)]
pub struct FromRest {
    pub command: CommandId,
    pub velocity: f64,
    pub acceleration: f64,
    pub deceleration: f64,
    pub jerk: f64,
}

/// A positioning job (MoveAbsolute/Relative/Additive/Continuous*, inching) as it runs: it
/// may move away from its target only where no profile could avoid it — braking a motion
/// that was heading away when it began, the release of an acceleration away from it, or an
/// overshoot it could not brake for from its start — and after passing its target only when
/// it goes on at an end velocity (MoveContinuous). MoveModulo's path and stops are not
/// positioning towards a target and are not tracked.
#[derive(Clone, Copy, Debug)]
pub struct Course {
    pub command: CommandId,
    pub target: f64,
    /// Direction from the start towards the target (±1).
    dir: f64,
    /// Still braking a motion away from the target that it began with.
    braking_away: bool,
    /// Backwards travel no profile avoids (release of an acceleration away from the target).
    tolerance: f64,
    /// It may pass its target: it goes on beyond it (continuous), or it could not stop in time.
    may_pass: bool,
}

pub struct Rig {
    pub k: Kernel,
    pub plants: Vec<Plant>,
    pub sp: Vec<DriveSetpoint>,
    pub events: Vec<CommandEvent>,
    pub bounds: Vec<Bounds>,
    pub outputs: HashMap<CommandId, FbOutputs>,
    finals: HashSet<CommandId>,
    next_id: CommandId,
    prev: Vec<AxisStatus>,
    /// Position jumps are expected (SetPosition, homing, disable) this cycle.
    shifted: Vec<bool>,
    pub history: Vec<Vec<AxisStatus>>,
    pub checked_cycles: u64,
    /// Per axis: the command started from rest whose own bounds are checked (see [`FromRest`]).
    pub from_rest: Vec<Option<FromRest>>,
    /// Cycles checked against a [`FromRest`] command's own bounds (all axes).
    pub from_rest_cycles: u64,
    /// Every accepted command's kind.
    pub kinds: HashMap<CommandId, CommandKind>,
    /// Per axis: the positioning job whose course is checked (see [`Course`]).
    pub course: Vec<Option<Course>>,
    /// Cycles checked against a positioning job's course (all axes).
    pub course_cycles: u64,
    /// Cycles checked against enabled software limits (all axes).
    pub soft_limit_cycles: u64,
    /// Groups checked every cycle (see `check_groups`) and their last status.
    pub groups: Vec<(GroupId, motion::group::GroupStatus)>,
    /// Per MovePath: the highest path velocity its entries command.
    pub path_velocity: HashMap<CommandId, f64>,
    /// Cycles checked against a group's path invariants.
    pub group_cycles: u64,
}

pub fn params() -> AxisParameters {
    AxisParameters {
        axis_velo_max: 500.0,
        axis_acc: 2000.0,
        axis_dec: 1000.0,
        axis_jerk: 20000.0,
        axis_fast_dec: 5000.0,
        axis_fast_acc: 5000.0,
        axis_fast_jerk: 100000.0,
        axis_maximum_acceleration: 5000.0,
        axis_maximum_deceleration: 5000.0,
        axis_target_position_window: 0.01,
        axis_target_position_monitoring_time: 0.005,
        axis_max_pos_lag_value: 1.0,
        axis_max_pos_lag_filter_time: 0.01,
        ..AxisParameters::default()
    }
}

impl Rig {
    pub fn new(axes: usize) -> Rig {
        Rig::with(vec![(false, params()); axes])
    }

    pub fn with(configs: Vec<(bool, AxisParameters)>) -> Rig {
        Rig::with_configs(
            configs
                .into_iter()
                .map(|(modulo, parameters)| AxisConfig {
                    modulo,
                    parameters,
                    compensation_table: None,
                    drive_executed: false,
                })
                .collect(),
        )
    }

    pub fn with_configs(configs: Vec<AxisConfig>) -> Rig {
        let n = configs.len();
        let mut k = Kernel::new(DT, n);
        let mut bounds = Vec::new();
        for (i, config) in configs.into_iter().enumerate() {
            let p = &config.parameters;
            bounds.push(Bounds {
                velocity: p.axis_velo_max,
                acceleration: p
                    .axis_maximum_acceleration
                    .max(p.axis_maximum_deceleration)
                    .max(p.axis_fast_dec),
                jerk: p.axis_jerk.max(p.axis_fast_jerk),
            });
            k.insert_axis(i as u16, Axis::new(config, DT)).unwrap();
        }
        Rig {
            k,
            plants: vec![Plant::default(); n],
            sp: vec![DriveSetpoint::default(); n],
            events: Vec::new(),
            bounds,
            outputs: HashMap::new(),
            finals: HashSet::new(),
            next_id: 1,
            prev: vec![AxisStatus::default(); n],
            shifted: vec![true; n],
            history: vec![Vec::new(); n],
            checked_cycles: 0,
            from_rest: vec![None; n],
            from_rest_cycles: 0,
            kinds: HashMap::new(),
            course: vec![None; n],
            course_cycles: 0,
            soft_limit_cycles: 0,
            groups: Vec::new(),
            path_velocity: HashMap::new(),
            group_cycles: 0,
        }
    }

    /// Builds a cam table and hands it to the kernel under `id`.
    /// (See [`bent_positions`] for a position table whose interpolations differ.)
    pub fn cam(&mut self, id: u32, table: &motion::cam::CamTableData) {
        let cam = motion::cam::Cam::build(table).expect("a valid cam table");
        assert!(
            self.k.insert_cam(id, std::sync::Arc::new(cam)).is_ok(),
            "cam {id} not taken"
        );
    }

    pub fn cmd(&mut self, axis: u16, kind: CommandKind) -> (CommandId, Verdict) {
        let id = self.next_id;
        self.next_id += 1;
        let n = self.events.len();
        if matches!(
            kind,
            CommandKind::SetPosition { .. }
                | CommandKind::Home { .. }
                | CommandKind::Reset
                // Absolute encoder scaling moves the coordinates (§4.5.9), like SetPosition.
                | CommandKind::SetEncoderScalingFactor {
                    relative: false,
                    ..
                }
                | CommandKind::WriteParameter {
                    number: 1040 | 1055 | 1056,
                    ..
                }
        ) {
            self.shifted[axis as usize] = true;
        }
        let before = self.k.status(axis);
        let v = self.k.submit(
            Command {
                id,
                target: Target::Axis(axis),
                kind,
            },
            &mut self.events,
        );
        if let Verdict::Rejected(_) = v {
            assert_eq!(self.events.len(), n, "a rejected command emitted events");
            assert_eq!(
                self.k.status(axis),
                before,
                "a rejected command changed the axis status"
            );
        }
        // Events of a submit are stamped with the cycle the command takes effect in.
        self.check_events_at(n, self.k.cycle() + 1);
        if v == Verdict::Accepted {
            self.kinds.insert(id, kind);
            // Any accepted command disturbs the one started from rest; a motion command that
            // starts at once from rest is the next one checked against its own bounds.
            let before = before.unwrap();
            self.from_rest[axis as usize] = None;
            let at_rest = before.set_velocity == 0.0
                && before.set_acceleration == 0.0
                && !before.compensating;
            if at_rest && self.out(id).active {
                self.from_rest[axis as usize] = self.own_bounds(axis, id, &kind, &before);
            }
        }
        // The state changes in the cycle the command is accepted: check that transition too.
        let now = self.k.status(axis).unwrap().state;
        let prev = self.prev[axis as usize].state;
        assert!(
            allowed(prev, now),
            "axis {axis}: transition {prev:?} -> {now:?} by {kind:?} not in the diagram"
        );
        self.prev[axis as usize].state = now;
        (id, v)
    }

    /// Submits and expects acceptance.
    pub fn ok(&mut self, axis: u16, kind: CommandKind) -> CommandId {
        let (id, v) = self.cmd(axis, kind);
        assert_eq!(v, Verdict::Accepted, "{kind:?} rejected");
        id
    }

    pub fn rejected(&mut self, axis: u16, kind: CommandKind) -> ErrorId {
        match self.cmd(axis, kind).1 {
            Verdict::Rejected(e) => e,
            Verdict::Accepted => panic!("{kind:?} accepted"),
        }
    }

    pub fn out(&self, id: CommandId) -> FbOutputs {
        self.outputs.get(&id).copied().unwrap_or_default()
    }

    /// Commands whose last outputs are still busy.
    pub fn busy_commands(&self) -> Vec<(CommandId, FbOutputs)> {
        self.outputs
            .iter()
            .filter(|(_, o)| o.busy)
            .map(|(i, o)| (*i, *o))
            .collect()
    }

    pub fn st(&self, axis: u16) -> AxisStatus {
        self.k.status(axis).unwrap()
    }

    pub fn step(&mut self) {
        let fb: Vec<DriveFeedback> = self.plants.iter().map(|p| p.feedback()).collect();
        let n = self.events.len();
        self.k.step(&fb, &mut self.sp, &mut self.events);
        for (i, p) in self.plants.iter_mut().enumerate() {
            p.apply(&self.sp[i], DT);
        }
        self.check_events(n);
        self.check_axes();
        self.check_groups();
    }

    pub fn run(&mut self, seconds: f64) {
        for _ in 0..(seconds / DT).round() as usize {
            self.step();
        }
    }

    /// Steps until `f` holds (at most `seconds`); returns the cycles taken.
    pub fn until(&mut self, seconds: f64, mut f: impl FnMut(&Rig) -> bool) -> usize {
        for i in 0..(seconds / DT).round() as usize {
            if f(self) {
                return i;
            }
            self.step();
        }
        panic!(
            "condition not reached within {seconds} s; status {:?}",
            self.st(0)
        );
    }

    pub fn power_on(&mut self, axis: u16) -> CommandId {
        self.power_on_with_override(axis, 100.0)
    }

    /// MC_Power with both feed enables and the given override; waits for Standstill.
    pub fn power_on_with_override(&mut self, axis: u16, override_percent: f64) -> CommandId {
        let id = self.ok(axis, power_with_override(override_percent));
        self.until(0.1, |r| r.st(axis).state == AxisState::Standstill);
        id
    }

    /// The bounds a motion command sets itself (`None` for other commands).
    fn own_bounds(
        &self,
        axis: u16,
        id: CommandId,
        kind: &CommandKind,
        before: &AxisStatus,
    ) -> Option<FromRest> {
        let p = self.k.parameters(axis).unwrap();
        let axis_dynamics = Dynamics::default();
        let (velocity, dynamics) = match *kind {
            CommandKind::MoveAbsolute(m)
            | CommandKind::MoveRelative(m)
            | CommandKind::MoveAdditive(m)
            | CommandKind::MoveModulo { move_: m, .. } => (m.velocity, m.dynamics),
            CommandKind::MoveContinuousAbsolute {
                move_: m,
                end_velocity,
            }
            | CommandKind::MoveContinuousRelative {
                move_: m,
                end_velocity,
            } => (m.velocity.max(end_velocity), m.dynamics),
            CommandKind::MoveVelocity {
                velocity, dynamics, ..
            } => (velocity, dynamics),
            CommandKind::Jog {
                mode,
                velocity,
                dynamics,
                ..
            } => match mode {
                JogMode::StandardSlow => (p.axis_velo_man_slow, axis_dynamics),
                JogMode::StandardFast => (p.axis_velo_man_fast, axis_dynamics),
                _ => (velocity, dynamics),
            },
            _ => return None,
        };
        let or = |x: f64, default: f64| if x == 0.0 { default } else { x };
        let ovr = (before.override_percent / 100.0).clamp(0.0, 1.0);
        Some(FromRest {
            command: id,
            velocity: velocity * ovr,
            acceleration: or(dynamics.acceleration, p.axis_acc),
            deceleration: or(dynamics.deceleration, p.axis_dec),
            jerk: or(dynamics.jerk, p.axis_jerk),
        })
    }

    /// Checks a cycle of axis `i` against the bounds of its command started from rest.
    fn check_from_rest(&mut self, i: usize, p: &AxisStatus, s: &AxisStatus) {
        let Some(t) = self.from_rest[i] else { return };
        if self.finals.contains(&t.command) {
            // It ended in this cycle (at its target, or with an error whose stop now runs).
            self.from_rest[i] = None;
            return;
        }
        self.from_rest_cycles += 1;
        let tol = 1e-9;
        assert!(
            s.set_velocity.abs() <= t.velocity * (1.0 + tol),
            "axis {i}: |v| {} above the command's velocity × override {} ({t:?})",
            s.set_velocity,
            t.velocity
        );
        let speeding_up = s.set_acceleration * s.set_velocity >= 0.0;
        let a_max = if speeding_up {
            t.acceleration
        } else {
            t.deceleration
        };
        assert!(
            s.set_acceleration.abs() <= a_max * (1.0 + tol) + tol,
            "axis {i}: |a| {} above the command's {} {a_max} (v {}, {t:?})",
            s.set_acceleration,
            if speeding_up {
                "acceleration"
            } else {
                "deceleration"
            },
            s.set_velocity
        );
        assert!(
            s.set_jerk.abs() <= t.jerk * (1.0 + tol)
                && (s.set_acceleration - p.set_acceleration).abs()
                    <= t.jerk * DT * (1.0 + 1e-6) + 1e-6,
            "axis {i}: jerk {} (a {} -> {}) above the command's {} ({t:?})",
            s.set_jerk,
            p.set_acceleration,
            s.set_acceleration,
            t.jerk
        );
    }

    /// The dynamics (deceleration, jerk) a positioning command plans with, if it is one whose
    /// course is checked, and whether it goes on beyond its target.
    fn positioning(&self, axis: usize, id: CommandId) -> Option<(f64, f64, bool)> {
        let p = self.k.parameters(axis as u16).unwrap();
        let or = |x: f64, default: f64| if x == 0.0 { default } else { x };
        let (d, continuous) = match *self.kinds.get(&id)? {
            CommandKind::MoveAbsolute(m)
            | CommandKind::MoveRelative(m)
            | CommandKind::MoveAdditive(m) => (m.dynamics, false),
            CommandKind::MoveContinuousAbsolute { move_: m, .. }
            | CommandKind::MoveContinuousRelative { move_: m, .. } => (m.dynamics, true),
            CommandKind::Jog {
                mode: JogMode::Inching | JogMode::InchingModulo,
                dynamics,
                ..
            } => (dynamics, false),
            _ => return None,
        };
        Some((
            or(d.deceleration, p.axis_dec),
            or(d.jerk, p.axis_jerk),
            continuous,
        ))
    }

    /// Invariant (a): a positioning job never moves away from its target except where no
    /// profile could avoid it (see [`Course`]). Checked in every cycle of every test.
    fn check_course(&mut self, i: usize, p: &AxisStatus, s: &AxisStatus) {
        let tracked = s.has_job
            && matches!(
                s.state,
                AxisState::DiscreteMotion | AxisState::ContinuousMotion
            )
            && !s.compensating
            && !p.compensating
            && !self.shifted[i]
            && !s.coupled;
        let job = if tracked {
            self.positioning(i, s.active_command)
        } else {
            None
        };
        let Some((dec, jerk, continuous)) = job else {
            self.course[i] = None;
            return;
        };
        let same = self.course[i]
            .is_some_and(|c| c.command == s.active_command && c.target == s.target_position);
        if !same {
            // A new job (or one re-based): it begins from the previous cycle's setpoint.
            let dir = sign(s.target_position - p.set_position);
            if dir == 0.0 {
                self.course[i] = None;
                return;
            }
            let a_away = (p.set_acceleration * dir).min(0.0).abs();
            let room = (s.target_position - p.set_position).abs();
            let cannot_stop = p.set_velocity * dir > 0.0
                && motion::planner::stop_distance(p.set_velocity, p.set_acceleration, dec, jerk)
                    > room * (1.0 - 1e-9);
            self.course[i] = Some(Course {
                command: s.active_command,
                target: s.target_position,
                dir,
                braking_away: p.set_velocity * dir < 0.0,
                tolerance: a_away * a_away * a_away / (jerk * jerk),
                may_pass: continuous || cannot_stop,
            });
        }
        let c = self.course[i].unwrap();
        self.course_cycles += 1;
        if c.braking_away && s.set_velocity * c.dir >= 0.0 {
            // Turned towards the target in this cycle: from the next one on, never back.
            self.course[i].as_mut().unwrap().braking_away = false;
        }
        let tol = 1e-9 * (1.0 + s.set_position.abs()) + c.tolerance;
        let step = (s.set_position - p.set_position) * c.dir;
        let before_target = (c.target - p.set_position) * c.dir > 0.0;
        if before_target {
            assert!(
                c.braking_away || step >= -tol,
                "axis {i}: command {} moves away from its target {} before reaching it: \
                 {} -> {} (v {}, {c:?})",
                c.command,
                c.target,
                p.set_position,
                s.set_position,
                s.set_velocity
            );
        } else {
            let beyond = (s.set_position - c.target) * c.dir;
            assert!(
                c.may_pass || beyond <= s.set_velocity.abs() * DT + tol,
                "axis {i}: command {} passes its target {} by {beyond} although it could have \
                 stopped there ({c:?})",
                c.command,
                c.target
            );
        }
    }

    /// Invariant (b): while the axis is commanded (not disabled, not in ErrorStop, not a
    /// homing run, not a coupled slave, whose crossing is an axis error), the set position
    /// never moves beyond an enabled software limit.
    fn check_soft_limits(&mut self, i: usize, p: &AxisStatus, s: &AxisStatus) {
        let par = self.k.parameters(i as u16).unwrap();
        let commanded = !matches!(
            s.state,
            AxisState::Disabled | AxisState::ErrorStop | AxisState::Homing
        ) && !matches!(p.state, AxisState::Disabled | AxisState::Homing)
            && !s.coupled
            && !p.coupled
            && !self.shifted[i];
        if !commanded || !(par.axis_en_max_soft_pos_limit || par.axis_en_min_soft_pos_limit) {
            return;
        }
        self.soft_limit_cycles += 1;
        let tol = 1e-9 * (1.0 + s.set_position.abs());
        let outwards = s.set_position - p.set_position;
        assert!(
            !(par.axis_en_max_soft_pos_limit
                && s.set_position > par.axis_max_soft_pos_limit + tol
                && outwards > tol),
            "axis {i}: set position {} -> {} beyond the positive software limit {} ({:?})",
            p.set_position,
            s.set_position,
            par.axis_max_soft_pos_limit,
            s.state
        );
        assert!(
            !(par.axis_en_min_soft_pos_limit
                && s.set_position < par.axis_min_soft_pos_limit - tol
                && outwards < -tol),
            "axis {i}: set position {} -> {} beyond the negative software limit {} ({:?})",
            p.set_position,
            s.set_position,
            par.axis_min_soft_pos_limit,
            s.state
        );
    }

    fn check_events(&mut self, from: usize) {
        self.check_events_at(from, self.k.cycle());
    }

    fn check_events_at(&mut self, from: usize, cycle: u64) {
        for e in &self.events[from..] {
            let o = e.outputs;
            assert!(
                !self.finals.contains(&e.command),
                "event after the final one: {e:?}"
            );
            // §3.1: Busy/Done/Error/CommandAborted exclusive; Active/Done/Error/CommandAborted
            // exclusive — except MC_Stop's Done while busy and active.
            let stop_locked = o.done && o.busy && o.active && !o.error && !o.command_aborted;
            let a = [o.busy, o.done, o.error, o.command_aborted]
                .iter()
                .filter(|x| **x)
                .count();
            let b = [o.active, o.done, o.error, o.command_aborted]
                .iter()
                .filter(|x| **x)
                .count();
            assert!(
                stop_locked || (a <= 1 && b <= 1),
                "exclusivity violated: {e:?}"
            );
            // A coupling FB ends with InSync instead of Done (Tc2_MC2_Camming §2.0).
            assert!(a >= 1 || o.in_sync, "no output set: {e:?}");
            // MC_TrackConveyorBelt's InSync is the exception: it has no Done and is InSync
            // while Busy and Active (TF5420 §4.1).
            let tracking = matches!(e.target, Target::Group(_)) && !o.done;
            assert!(
                !(o.in_sync && (o.busy || o.active || o.done)) || tracking,
                "InSync is a completion output: {e:?}"
            );
            assert!(
                !(o.error && (o.in_velocity || o.in_gear || o.in_sync || o.in_end_velocity)),
                "success flag with error: {e:?}"
            );
            assert!(
                !(o.command_aborted
                    && (o.in_velocity || o.in_gear || o.in_sync || o.in_end_velocity)),
                "success flag with command_aborted: {e:?}"
            );
            assert_eq!(
                o.error,
                o.error_id != 0,
                "error and error_id disagree: {e:?}"
            );
            if o.active {
                assert!(o.busy, "active without busy: {e:?}");
            }
            if let Some(prev) = self.outputs.get(&e.command) {
                assert_ne!(*prev, o, "event without change: {e:?}");
                assert!(
                    !prev.done || !o.busy || stop_locked || prev.busy,
                    "done then busy again: {e:?}"
                );
            }
            assert_eq!(e.cycle, cycle, "event stamped with a wrong cycle");
            self.outputs.insert(e.command, o);
            if o.is_final() {
                self.finals.insert(e.command);
            }
        }
    }

    /// A group with `config` in slot `id`, with `members` (role, axis) added.
    pub fn group(
        &mut self,
        id: GroupId,
        config: motion::group::GroupConfig,
        members: &[(motion::group::GroupRole, u16)],
    ) {
        assert!(
            self.k
                .insert_group(id, motion::group::Group::new(config, DT))
                .is_ok()
        );
        for &(role, axis) in members {
            self.gok(id, CommandKind::AddAxisToGroup { axis, role });
        }
        let st = self.gst(id);
        self.groups.push((id, st));
    }

    pub fn gst(&self, id: GroupId) -> motion::group::GroupStatus {
        self.k.group_status(id).expect("a group")
    }

    /// Submits a command to a group; a refusal must change nothing and report nothing.
    pub fn gcmd(&mut self, id: GroupId, kind: CommandKind) -> (CommandId, Verdict) {
        let cid = self.next_id;
        self.next_id += 1;
        let n = self.events.len();
        let before = self.k.group_status(id);
        let axes: Vec<_> = (0..self.prev.len())
            .map(|i| self.k.status(i as u16))
            .collect();
        let v = self.k.submit(
            Command {
                id: cid,
                target: Target::Group(id),
                kind,
            },
            &mut self.events,
        );
        if let Verdict::Rejected(_) = v {
            assert_eq!(self.events.len(), n, "a rejected command emitted events");
            assert_eq!(
                self.k.group_status(id),
                before,
                "a rejected command changed the group"
            );
            let after: Vec<_> = (0..self.prev.len())
                .map(|i| self.k.status(i as u16))
                .collect();
            assert_eq!(axes, after, "a rejected group command changed an axis");
        }
        self.check_events_at(n, self.k.cycle() + 1);
        if v == Verdict::Accepted {
            self.kinds.insert(cid, kind);
        }
        (cid, v)
    }

    pub fn gok(&mut self, id: GroupId, kind: CommandKind) -> CommandId {
        let (cid, v) = self.gcmd(id, kind);
        assert_eq!(v, Verdict::Accepted, "{kind:?} rejected");
        cid
    }

    pub fn grejected(&mut self, id: GroupId, kind: CommandKind) -> ErrorId {
        match self.gcmd(id, kind).1 {
            Verdict::Rejected(e) => e,
            Verdict::Accepted => panic!("{kind:?} accepted"),
        }
    }

    /// MC_MovePath with `entries`; a refusal must change nothing.
    pub fn path(
        &mut self,
        id: GroupId,
        entries: Vec<motion::group::PathEntry>,
    ) -> (CommandId, Verdict) {
        let cid = self.next_id;
        self.next_id += 1;
        let n = self.events.len();
        let before = self.k.group_status(id);
        let vmax = entries
            .iter()
            .filter_map(|e| match e {
                motion::group::PathEntry::Linear { motion, .. }
                | motion::group::PathEntry::Circular { motion, .. } => match motion.velocity {
                    motion::group::PathValue::Value(v) => Some(v),
                    _ => Some(f64::INFINITY),
                },
                _ => None,
            })
            .fold(0.0, f64::max);
        let table = motion::group::PathTable { entries };
        let v = self.k.submit_path(cid, id, &table, &mut self.events);
        if let Verdict::Rejected(_) = v {
            assert_eq!(self.events.len(), n, "a rejected MovePath emitted events");
            assert_eq!(
                self.k.group_status(id),
                before,
                "a rejected MovePath changed the group"
            );
        } else {
            self.path_velocity.insert(cid, vmax);
        }
        self.check_events_at(n, self.k.cycle() + 1);
        (cid, v)
    }

    pub fn path_ok(&mut self, id: GroupId, entries: Vec<motion::group::PathEntry>) -> CommandId {
        let (cid, v) = self.path(id, entries);
        assert_eq!(v, Verdict::Accepted, "MovePath rejected");
        cid
    }

    /// Every cycle, every group: the path velocity is ≥ 0 and within what the running
    /// MovePath commands; the path never runs backwards while anything is queued.
    fn check_groups(&mut self) {
        for k in 0..self.groups.len() {
            let (id, prev) = self.groups[k];
            let s = self.gst(id);
            self.group_cycles += 1;
            assert!(
                s.path_velocity >= -1e-9,
                "group {id}: path runs backwards: {s:?}"
            );
            if s.command != 0 {
                if let Some(v) = self.path_velocity.get(&s.command) {
                    assert!(
                        s.path_velocity <= v * (1.0 + 1e-9) + 1e-9,
                        "group {id}: path velocity {} above the commanded {v}",
                        s.path_velocity
                    );
                }
            }
            if prev.queued_entries > 0 && s.queued_entries > 0 {
                assert!(
                    s.path_position >= prev.path_position - 1e-9,
                    "group {id}: s went back {} -> {}",
                    prev.path_position,
                    s.path_position
                );
            }
            self.groups[k].1 = s;
        }
    }

    fn check_axes(&mut self) {
        self.checked_cycles += 1;
        for i in 0..self.prev.len() {
            let s = self.k.status(i as u16).unwrap();
            let p = self.prev[i];
            let b = self.bounds[i];
            assert!(
                allowed(p.state, s.state),
                "axis {i}: transition {:?} -> {:?} not in the diagram",
                p.state,
                s.state
            );
            let tol = 1e-9;
            assert!(
                s.set_velocity.abs() <= b.velocity * (1.0 + tol) + tol,
                "axis {i}: |v| {} > {}",
                s.set_velocity,
                b.velocity
            );
            assert!(
                s.set_acceleration.abs() <= b.acceleration * (1.0 + tol) + tol,
                "axis {i}: |a| {} > {}",
                s.set_acceleration,
                b.acceleration
            );
            // Torque control follows the load the drive moves (the position loop open, its
            // take-over and hand-back are the documented steps).
            let settled = !self.shifted[i]
                && (s.control_loop_closed || !s.operational)
                && (p.control_loop_closed || !p.operational)
                // The external setpoint generator's samples are the client's motion.
                && !s.ext_setpoint_gen_enabled
                && !p.ext_setpoint_gen_enabled
                && !matches!(s.state, AxisState::Disabled | AxisState::ErrorStop)
                && !matches!(p.state, AxisState::Disabled | AxisState::ErrorStop)
                && p.homed == s.homed
                && !s.coupled
                && !p.coupled;
            if settled {
                let j = b.jerk;
                assert!(
                    (s.set_acceleration - p.set_acceleration).abs() <= j * DT * (1.0 + 1e-6) + 1e-6,
                    "axis {i}: jerk {} > {j} (a {} -> {})",
                    (s.set_acceleration - p.set_acceleration) / DT,
                    p.set_acceleration,
                    s.set_acceleration
                );
                let dv = s.set_velocity - p.set_velocity;
                assert!(
                    (dv - (p.set_acceleration + s.set_acceleration) / 2.0 * DT).abs()
                        <= j * DT * DT + 1e-6,
                    "axis {i}: velocity jump {} -> {} (a {})",
                    p.set_velocity,
                    s.set_velocity,
                    p.set_acceleration
                );
                let dp = s.set_position - p.set_position;
                assert!(
                    (dp - (p.set_velocity + s.set_velocity) / 2.0 * DT).abs()
                        <= b.acceleration * DT * DT + 1e-6,
                    "axis {i}: position jump {} -> {} (v {} -> {})",
                    p.set_position,
                    s.set_position,
                    p.set_velocity,
                    s.set_velocity
                );
            }
            self.check_from_rest(i, &p, &s);
            self.check_course(i, &p, &s);
            self.check_soft_limits(i, &p, &s);
            self.shifted[i] = false;
            self.prev[i] = s;
            self.history[i].push(s);
        }
    }
}

/// The PLCopen state diagram (spec §2.4) with its notes; self-transitions are always fine.
pub fn allowed(from: AxisState, to: AxisState) -> bool {
    use AxisState::*;
    if from == to || to == ErrorStop || to == Disabled {
        return true;
    }
    match from {
        Disabled => matches!(to, Standstill),
        ErrorStop => matches!(to, Standstill),
        Standstill => matches!(
            to,
            Homing | DiscreteMotion | ContinuousMotion | SynchronizedMotion | Stopping
        ),
        Homing => matches!(to, Standstill | Stopping),
        DiscreteMotion | ContinuousMotion => matches!(
            to,
            Standstill | DiscreteMotion | ContinuousMotion | SynchronizedMotion | Stopping
        ),
        SynchronizedMotion => matches!(
            to,
            Standstill | DiscreteMotion | ContinuousMotion | Stopping
        ),
        Stopping => matches!(to, Standstill),
    }
}

pub fn mv(position: f64, velocity: f64) -> Positioning {
    Positioning {
        position,
        velocity,
        dynamics: Dynamics::default(),
        buffer_mode: BufferMode::Aborting,
        options: MoveOptions::default(),
    }
}

pub fn mvb(position: f64, velocity: f64, buffer_mode: BufferMode) -> Positioning {
    Positioning {
        buffer_mode,
        ..mv(position, velocity)
    }
}

/// MC_MoveVelocity, Aborting, axis dynamics.
pub fn velocity(velocity: f64, direction: Direction) -> CommandKind {
    CommandKind::MoveVelocity {
        velocity,
        dynamics: Dynamics::default(),
        direction,
        buffer_mode: BufferMode::Aborting,
        options: MoveOptions::default(),
    }
}

/// The rig's parameters with both software limits enabled at `min` and `max`.
pub fn params_with_soft_limits(min: f64, max: f64) -> AxisParameters {
    let mut p = params();
    p.axis_en_min_soft_pos_limit = true;
    p.axis_min_soft_pos_limit = min;
    p.axis_en_max_soft_pos_limit = true;
    p.axis_max_soft_pos_limit = max;
    p
}

/// MC_GearIn of the slave to `master` with ratio numerator / denominator.
pub fn gear_in(master: u16, ratio_numerator: f64, ratio_denominator: u16) -> CommandKind {
    CommandKind::GearIn {
        master,
        ratio_numerator,
        ratio_denominator,
    }
}

/// MC_Power Enable TRUE with both feed enables and the given override.
pub fn power_with_override(override_percent: f64) -> CommandKind {
    CommandKind::Power {
        enable: true,
        enable_positive: true,
        enable_negative: true,
        override_percent,
        buffer_mode: BufferMode::Aborting,
    }
}

/// MC_Power Enable FALSE.
pub fn power_off() -> CommandKind {
    CommandKind::Power {
        enable: false,
        enable_positive: false,
        enable_negative: false,
        override_percent: 100.0,
        buffer_mode: BufferMode::Aborting,
    }
}

/// MC_Halt, Aborting, with the last move's dynamics.
pub fn halt() -> CommandKind {
    CommandKind::Halt {
        deceleration: 0.0,
        jerk: 0.0,
        buffer_mode: BufferMode::Aborting,
        options: MoveOptions::default(),
    }
}

/// The property tests' configuration: `default_cases` cases (`MOTION_PROP_CASES` overrides)
/// from a fixed seed, so that the suite is the same on every run (`MOTION_PROP_SEED=<u64>`
/// explores another part of the space, `MOTION_PROP_SEED=random` a new one each run).
pub fn prop_config(default_cases: u32) -> proptest::test_runner::Config {
    use proptest::test_runner::{Config, RngSeed};
    let cases = std::env::var("MOTION_PROP_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default_cases);
    let rng_seed = match std::env::var("MOTION_PROP_SEED").ok().as_deref() {
        Some("random") => RngSeed::Random,
        Some(v) => RngSeed::Fixed(v.parse().expect("MOTION_PROP_SEED: a u64 or random")),
        None => RngSeed::Fixed(20_261_123),
    };
    Config {
        cases,
        rng_seed,
        ..Config::default()
    }
}

/// A periodic, equidistant, linearly interpolated position table whose rows bend (one stroke of
/// 360 per 360 of master), so that a coupling's own interpolation (spline, sliding spline)
/// differs from the table's.
pub fn bent_positions() -> motion::cam::CamTableData {
    let mut t = motion::cam::CamTableData::positions(
        vec![
            [0.0, 0.0],
            [90.0, 60.0],
            [180.0, 180.0],
            [270.0, 300.0],
            [360.0, 360.0],
        ],
        true,
    );
    t.periodic = true;
    t
}
