//! The path in motion: the queue of segments a group runs, the look-ahead that keeps it able
//! to stop at the end of what is queued, and the path parameter `s` (arc length) stepped
//! cycle by cycle by the jerk-limited planner.
//!
//! * **Items.** Each accepted entry becomes one item (a line, an arc, a dwell, a blocker);
//!   a CornerDistance transition adds a blend item between two motion items and trims them.
//!   `s` is measured from the start of the first item queued since the group last stood.
//! * **Dynamics per item.** The entry's path velocity, acceleration, deceleration and jerk,
//!   each lowered so that no member axis exceeds its own limits anywhere on the segment:
//!   velocity by |dp_i/ds|, the centripetal part d²p_i/ds²·v² kept within half an axis's
//!   acceleration, the tangential part within the rest (decision 124).
//! * **Look-ahead.** `v_end[k]`, the velocity the path may have at the end of item k, is the
//!   lower of the corner's limit (0 at an exact stop, a dwell, a blocker and the end of the
//!   queue) and the highest velocity from which item k+1 can still brake to `v_end[k+1]`
//!   within its length (jerk-limited, from and to zero acceleration). Each item is planned to
//!   its end with that velocity, so the group can always stop at the end of what is queued.
//! * **Override** scales time: `s` follows the plan at `k·dt` per cycle, so the path stays
//!   the same and velocity, acceleration scale with k and k² (≤ 1). k ramps towards the
//!   requested factor no faster than the override ramp time and than the acceleration
//!   headroom allows (`dk/dt · v` is an acceleration too).
//! * **Braking** (halt, stop, an error, an aborting MovePath): one stop profile on `s`,
//!   across item ends, on the path; never past the end of what is queued.
//!
//! Nothing here allocates: the queue's capacity is reserved when the group is built.

use std::collections::VecDeque;

use crate::command::CommandId;
use crate::path::{MAX_PATH_DIMS, PathPoint, Segment};
use crate::planner::{Kinematics, Limits, Planner};

/// What an item is.
#[allow(
    clippy::large_enum_variant,
    reason = "items live in a ring reserved when the group is built; boxing a segment would allocate in the cycle"
)]
#[derive(Clone, Copy, Debug)]
pub(super) enum ItemKind {
    Motion(Segment),
    /// Stand for this many seconds (0: an exact stop).
    Dwell(f64),
    /// Wait until released (`released`: an early MC_ReleaseBlocker).
    Blocker {
        id: u32,
        released: bool,
    },
}

/// One queued piece of path.
#[derive(Clone, Copy, Debug)]
pub(super) struct Item {
    pub(super) kind: ItemKind,
    /// Global path parameter at the item's start.
    pub(super) s0: f64,
    pub(super) len: f64,
    pub(super) limits: Limits,
    /// Velocity allowed at the item's end by its corner alone (before look-ahead).
    pub(super) corner: f64,
    /// The corner's velocity when the blocker after this item is released before the path
    /// reaches it (0 unless the items around the blocker join without a corner).
    pub(super) through: f64,
    /// Look-ahead result: the velocity the plan may have at the item's end.
    pub(super) v_end: f64,
    /// The MovePath it belongs to, the entry's index in its table and InvokeId.
    pub(super) command: CommandId,
    pub(super) entry: u16,
    pub(super) invoke_id: u32,
    /// A blend segment (IsInBlendingSegment).
    pub(super) blend: bool,
    /// The last item of its MovePath (its Done).
    pub(super) last: bool,
}

impl Item {
    pub(super) fn end_s(&self) -> f64 {
        self.s0 + self.len
    }

    fn waits(&self) -> bool {
        matches!(
            self.kind,
            ItemKind::Dwell(_)
                | ItemKind::Blocker {
                    released: false,
                    ..
                }
        )
    }
}

/// What the path does this cycle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Exec {
    /// Nothing queued (or everything passed): standing where `point` is.
    Idle,
    /// Following the queue item by item; `planned` = the front item has its plan.
    Follow { planned: bool },
    /// Standing at a dwell for `left` more seconds.
    Dwell { left: f64 },
    /// Standing at a blocker until it is released.
    Blocked { id: u32 },
}

/// What a cycle of the path reports to the group. Room for every MovePath a group keeps in
/// flight: short entries can finish many in one cycle, and none may lose its Done.
#[derive(Clone, Copy, Debug)]
pub(super) struct StepReport {
    /// Items finished this cycle: the MovePaths whose last item it was are Done.
    pub(super) done: [CommandId; super::MAX_PATH_COMMANDS],
    pub(super) done_len: usize,
    /// A MovePath whose first item started this cycle (Active).
    pub(super) started: [CommandId; super::MAX_PATH_COMMANDS],
    pub(super) started_len: usize,
    /// A stop ([`PathRun::brake`]) reached standstill this cycle.
    pub(super) braked: bool,
}

impl Default for StepReport {
    fn default() -> Self {
        StepReport {
            done: [0; super::MAX_PATH_COMMANDS],
            done_len: 0,
            started: [0; super::MAX_PATH_COMMANDS],
            started_len: 0,
            braked: false,
        }
    }
}

impl StepReport {
    fn push_done(&mut self, id: CommandId) {
        if id != 0 && self.done_len < self.done.len() && !self.done[..self.done_len].contains(&id) {
            self.done[self.done_len] = id;
            self.done_len += 1;
        }
    }
    fn push_started(&mut self, id: CommandId) {
        if id != 0
            && self.started_len < self.started.len()
            && !self.started[..self.started_len].contains(&id)
        {
            self.started[self.started_len] = id;
            self.started_len += 1;
        }
    }
}

/// The path parameter's own state and the queue.
#[derive(Debug)]
pub(super) struct PathRun {
    pub(super) items: VecDeque<Item>,
    capacity: usize,
    /// Path kinematics in plan time (before override scaling).
    pub(super) s: Kinematics,
    planner: Planner,
    pub(super) exec: Exec,
    /// The override factor in effect (ramped) and the one asked for.
    pub(super) k: f64,
    pub(super) k_target: f64,
    /// dk/dt: the override's own rate of change (its part of the path acceleration).
    k_rate: f64,
    /// The set point of every dimension (members and not).
    pub(super) point: PathPoint,
    pub(super) velocity: PathPoint,
    pub(super) acceleration: PathPoint,
    /// The last command id whose item became active (Active reported).
    last_started: CommandId,
    /// Entries queued (items that are not blends), kept as items come and go.
    pub(super) entries: u32,
    /// A stop in progress (halt, stop, error, an aborting MovePath): its deceleration and
    /// jerk. The path is followed as planned, but each item is planned to stop as early as
    /// its dynamics allow.
    braking: Option<(f64, f64)>,
    cycle_time: f64,
}

/// Velocity below which the path counts as standing.
const EPS_V: f64 = 1e-9;

impl PathRun {
    pub(super) fn new(cycle_time: f64, capacity: usize) -> Self {
        PathRun {
            items: VecDeque::with_capacity(capacity),
            capacity,
            s: Kinematics::default(),
            planner: Planner::new(cycle_time),
            exec: Exec::Idle,
            k: 1.0,
            k_target: 1.0,
            k_rate: 0.0,
            point: [0.0; MAX_PATH_DIMS],
            velocity: [0.0; MAX_PATH_DIMS],
            acceleration: [0.0; MAX_PATH_DIMS],
            last_started: 0,
            braking: None,
            entries: 0,
            cycle_time,
        }
    }

    fn pop_item(&mut self) -> Option<Item> {
        let it = self.items.pop_front();
        if it.is_some_and(|i| !i.blend) {
            self.entries -= 1;
        }
        it
    }

    fn clear_items(&mut self) {
        self.items.clear();
        self.entries = 0;
    }

    pub(super) fn free(&self) -> usize {
        self.capacity - self.items.len()
    }

    pub(super) fn is_idle(&self) -> bool {
        self.exec == Exec::Idle
    }

    /// The path velocity as the axes see it (after override).
    pub(super) fn path_velocity(&self) -> f64 {
        self.s.velocity * self.k
    }

    pub(super) fn path_acceleration(&self) -> f64 {
        self.s.acceleration * self.k * self.k + self.k_rate * self.s.velocity
    }

    /// Where a path appended behind the queue starts.
    pub(super) fn end_point(&self) -> PathPoint {
        for it in self.items.iter().rev() {
            if let ItemKind::Motion(seg) = it.kind {
                return seg.end();
            }
        }
        self.point
    }

    /// Global s where the queue ends.
    pub(super) fn end_s(&self) -> f64 {
        self.items.back().map_or(self.s.position, |i| i.end_s())
    }

    /// The front item (the one `s` is in).
    pub(super) fn front(&self) -> Option<&Item> {
        self.items.front()
    }

    /// Puts the group's set point where the members stand (while idle).
    pub(super) fn take_point(&mut self, point: PathPoint) {
        self.point = point;
        self.velocity = [0.0; MAX_PATH_DIMS];
        self.acceleration = [0.0; MAX_PATH_DIMS];
        self.s = Kinematics::default();
    }

    /// Where (global s) the path would come to rest if it braked now with `dec`/`jerk` (§7.3:
    /// the virtual corner of an aborting MovePath that blends). None when it is not moving
    /// along motion items (it stands, waits or already brakes).
    pub(super) fn rest_s(&self, dec: f64, jerk: f64) -> Option<f64> {
        if !matches!(self.exec, Exec::Follow { .. }) || self.braking.is_some() {
            return None;
        }
        // In plan time, as the items are planned (the override scales time, not distance).
        let reach = crate::planner::stop_distance(self.s.velocity, self.s.acceleration, dec, jerk);
        Some(self.s.position + reach)
    }

    /// The motion item global `s` lies in (the last one when `s` is beyond the queue) and
    /// that item cut there. None when a dwell or a blocker comes first.
    pub(super) fn cut_point(&self, s: f64) -> Option<(usize, Item)> {
        let mut found = None;
        for (i, it) in self.items.iter().enumerate() {
            if !matches!(it.kind, ItemKind::Motion(_)) {
                return None;
            }
            found = Some(i);
            if s <= it.end_s() {
                break;
            }
        }
        let i = found?;
        let mut it = self.items[i];
        let ItemKind::Motion(seg) = it.kind else {
            return None;
        };
        let local = (s - it.s0).clamp(0.0, it.len);
        if local < it.len {
            let cut = seg.trimmed(0.0, local);
            it.kind = ItemKind::Motion(cut);
            it.len = cut.length();
        }
        Some((i, it))
    }

    /// Cuts the queue after item `i`, which becomes `cut` (from [`PathRun::cut_point`]);
    /// what is left belongs to no command (the caller ends them) and is planned again.
    pub(super) fn cut_at(&mut self, i: usize, cut: Item) {
        self.items.truncate(i + 1);
        if let Some(it) = self.items.get_mut(i) {
            *it = cut;
        }
        for it in self.items.iter_mut() {
            it.command = 0;
            it.last = false;
        }
        self.last_started = 0;
        self.entries = self.items.iter().filter(|i| !i.blend).count() as u32;
        self.look_ahead();
        self.exec = Exec::Follow { planned: false };
    }

    /// Whether the path, from where it is now, can pass global `s` no faster than
    /// `velocity` within `limits` (a trial plan on `planner`).
    pub(super) fn can_pass(
        &self,
        planner: &mut Planner,
        s: f64,
        velocity: f64,
        limits: &Limits,
    ) -> bool {
        // In plan time, as the item will be planned again.
        let from = self.s;
        if s <= from.position + 1e-9 {
            return false;
        }
        let lim = Limits {
            velocity: limits.velocity.max(from.velocity),
            ..*limits
        };
        matches!(
            planner.plan_position_towards(from, s, velocity, &lim),
            Ok(v) if v <= velocity * (1.0 + 1e-9) + 1e-9
        )
    }

    /// Appends items (already built and checked) and runs the look-ahead.
    pub(super) fn append(&mut self, new: impl Iterator<Item = Item>) {
        for it in new {
            debug_assert!(self.items.len() < self.capacity);
            if !it.blend {
                self.entries += 1;
            }
            self.items.push_back(it);
        }
        self.look_ahead();
        if self.exec == Exec::Idle && !self.items.is_empty() {
            self.exec = Exec::Follow { planned: false };
        } else if let Exec::Follow { .. } = self.exec {
            // The end velocity of the running item may have risen.
            self.exec = Exec::Follow { planned: false };
        }
    }

    /// `v_end` of every item from the back: the corner's limit, and what the next item can
    /// brake from within its length.
    pub(super) fn look_ahead(&mut self) {
        let mut next_v_end = 0.0;
        let mut next: Option<(f64, Limits, bool)> = None;
        // A blocker released before it is reached is passed as if it were not there.
        let mut released_after = false;
        for it in self.items.iter_mut().rev() {
            if let ItemKind::Blocker { released: true, .. } = it.kind {
                it.v_end = next_v_end;
                released_after = true;
                continue;
            }
            let mut v = if released_after {
                it.through
            } else {
                it.corner
            };
            released_after = false;
            match next {
                None => v = 0.0,
                Some((len, lim, waits)) => {
                    if waits {
                        v = 0.0;
                    } else {
                        // The cycle that passes an item's end travels on into the next
                        // one: up to a cycle's travel of it is gone before it is planned, so
                        // it must stop within what is left.
                        let reach = brake_reach(len, next_v_end, lim.deceleration, lim.jerk);
                        let left = (len - reach * self.cycle_time).max(0.0);
                        v = v.min(brake_reach(left, next_v_end, lim.deceleration, lim.jerk));
                    }
                }
            }
            if it.waits() {
                v = 0.0;
            }
            it.v_end = v.min(it.limits.velocity);
            next_v_end = it.v_end;
            next = Some((it.len, it.limits, it.waits()));
        }
    }

    /// The set point: the front item sampled at `s`.
    fn sample(&mut self) {
        let Some(it) = self.items.front() else {
            return;
        };
        let ItemKind::Motion(seg) = it.kind else {
            // Standing at a dwell or a blocker (the point is the last item's end).
            self.velocity = [0.0; MAX_PATH_DIMS];
            self.acceleration = [0.0; MAX_PATH_DIMS];
            return;
        };
        {
            let local = (self.s.position - it.s0).clamp(0.0, it.len);
            let p = seg.sample(local);
            let v = self.path_velocity();
            let a = self.path_acceleration();
            for d in 0..MAX_PATH_DIMS {
                self.point[d] = p.position[d];
                self.velocity[d] = p.d1[d] * v;
                self.acceleration[d] = p.d2[d] * v * v + p.d1[d] * a;
            }
        }
    }

    /// Ramps the override towards its target: its rate no faster than the ramp time allows
    /// and than the acceleration left to the front item (dk/dt · v is a path acceleration),
    /// the rate itself changed no faster than the item's jerk allows (dk²/dt² · v).
    fn step_override(&mut self, dt: f64, ramp_time: f64) {
        // A stop runs in real time with its own deceleration (`brake`): the override waits.
        if self.braking.is_some() {
            return;
        }
        let target = self.k_target;
        let diff = target - self.k;
        if diff == 0.0 && self.k_rate == 0.0 {
            return;
        }
        // dk/dt multiplies the plan's velocity v (s'' = k²·a + k'·v): both the rate and its
        // change are bounded through v.
        let v = self.s.velocity.abs();
        let (a_lim, j_lim, v_lim) =
            self.items
                .front()
                .map_or((f64::INFINITY, f64::INFINITY, 0.0), |i| {
                    (
                        i.limits.acceleration.min(i.limits.deceleration),
                        i.limits.jerk,
                        i.limits.velocity,
                    )
                });
        let mut r_max = if ramp_time > 0.0 {
            1.0 / ramp_time
        } else {
            1.0 / dt
        };
        let mut q = f64::INFINITY;
        if v > EPS_V {
            let used = self.k * self.k * self.s.acceleration.abs();
            r_max = r_max.min((a_lim - used).max(0.0) / v);
            q = 0.5 * j_lim / v;
        }
        // The rate is kept low enough to be braked to 0 by the target at the rate change the
        // item's highest velocity allows (v may grow meanwhile).
        let v_up = v.max(v_lim);
        let q_safe = if v_up > EPS_V { 0.5 * j_lim / v_up } else { q };
        let desired = diff.signum() * r_max.min((2.0 * q_safe * diff.abs()).sqrt());
        let step = if q.is_finite() { q * dt } else { f64::INFINITY };
        self.k_rate += (desired - self.k_rate).clamp(-step, step);
        let next = self.k + self.k_rate * dt;
        // Arriving: the rate ends there only when one step of its change can end it (a
        // target changed in the middle of a ramp may be passed and come back to: a step of
        // the rate is a step of the path acceleration, k'·v).
        if (target - next) * diff <= 0.0 && self.k_rate.abs() <= step {
            self.k = target;
            self.k_rate = 0.0;
        } else {
            self.k = next.clamp(0.0, 1.0);
            if self.k != next {
                self.k_rate = 0.0;
            }
        }
    }

    /// Starts a stop on the path (halt, stop, error reaction, an aborting MovePath) with
    /// `dec`/`jerk` (path units). The path stays on its geometry and every corner is passed
    /// no faster than planned: each item is planned to stop as early as the lower of the
    /// stop's and the item's own dynamics allow (the item's keep every member within its
    /// limits), and where that would pass the item's end faster than the look-ahead planned,
    /// with the item's own (decision 125). At standstill the rest of the queue is dropped.
    /// What is queued belongs to no command from now on (the callers end them).
    pub(super) fn brake(&mut self, dec: f64, jerk: f64) {
        for it in self.items.iter_mut() {
            it.command = 0;
            it.last = false;
        }
        self.last_started = 0;
        match self.exec {
            Exec::Idle => {}
            Exec::Dwell { .. } | Exec::Blocked { .. } => {
                // Standing already: the stop is here.
                self.clear_items();
                self.exec = Exec::Idle;
                self.hold();
            }
            Exec::Follow { .. } if self.k == 0.0 && self.k_rate == 0.0 => {
                // The override holds the path: it stands, and the stop is here.
                self.clear_items();
                self.exec = Exec::Idle;
                self.hold();
            }
            Exec::Follow { .. } => {
                // A stop brakes with its own deceleration in real time, not stretched by a
                // low override: the time scaling is folded into the path's state (the
                // velocity and acceleration stay what they are) and is 1 while the stop
                // runs; at standstill the override asked for is in effect again (decision 151).
                if self.k != 1.0 || self.k_rate != 0.0 {
                    let k = self.k;
                    self.s.acceleration =
                        k * k * self.s.acceleration + self.k_rate * self.s.velocity;
                    self.s.velocity *= k;
                    self.k = 1.0;
                    self.k_rate = 0.0;
                }
                self.braking = Some((dec, jerk));
                self.exec = Exec::Follow { planned: false };
            }
        }
    }

    /// The stop is at standstill: the override asked for applies to what comes next.
    fn end_brake(&mut self) {
        self.braking = None;
        self.k = self.k_target;
        self.k_rate = 0.0;
    }

    /// A stop is running.
    pub(super) fn is_braking(&self) -> bool {
        self.braking.is_some()
    }

    /// Drops every item: the group stands where it is.
    pub(super) fn flush(&mut self) {
        self.exec = Exec::Idle;
        self.end_brake();
        self.s = Kinematics::default();
        self.last_started = 0;
        self.clear_items();
    }

    /// One cycle. `dt` the cycle time; `ramp_time` the override ramp time.
    pub(super) fn step(&mut self, dt: f64, ramp_time: f64, report: &mut StepReport) {
        self.step_override(dt, ramp_time);
        match self.exec {
            Exec::Idle => {
                self.velocity = [0.0; MAX_PATH_DIMS];
                self.acceleration = [0.0; MAX_PATH_DIMS];
            }
            Exec::Dwell { left } => {
                // A dwell is time, not path: the override does not stretch it.
                let left = left - dt;
                if left <= 1e-12 {
                    self.pass_front(report);
                } else {
                    self.exec = Exec::Dwell { left };
                }
                self.hold();
            }
            Exec::Blocked { id } => {
                let released = matches!(
                    self.items.front().map(|i| i.kind),
                    Some(ItemKind::Blocker { released: true, .. })
                );
                if released || self.items.front().is_none() {
                    self.pass_front(report);
                } else {
                    self.exec = Exec::Blocked { id };
                }
                self.hold();
            }
            Exec::Follow { .. } => self.follow(dt, report),
        }
    }

    fn hold(&mut self) {
        self.s.velocity = 0.0;
        self.s.acceleration = 0.0;
        self.velocity = [0.0; MAX_PATH_DIMS];
        self.acceleration = [0.0; MAX_PATH_DIMS];
    }

    /// Plans the front motion item from the present state to its end with its `v_end`.
    fn plan_front(&mut self) {
        let Some(it) = self.items.front().copied() else {
            return;
        };
        let mut from = self.s;
        if from.velocity > it.limits.velocity {
            // Entering a slower item at the look-ahead's velocity (a hair above by rounding).
            from.velocity = from.velocity.min(it.limits.velocity.max(from.velocity));
        }
        let target = it.end_s();
        if let Some((dec, jerk)) = self.braking {
            // Braking into an item whose jerk cannot take the deceleration back to 0 before
            // the velocity reaches 0 would end the stop with a step in acceleration (or run
            // backwards): use at least the jerk that can (as the axis planner does, decision 125).
            let unwind = if from.acceleration < 0.0 && from.velocity > EPS_V {
                1.05 * from.acceleration * from.acceleration / (2.0 * from.velocity)
            } else {
                0.0
            };
            let lim = Limits {
                velocity: it.limits.velocity.max(from.velocity),
                acceleration: it.limits.acceleration.min(dec),
                deceleration: it.limits.deceleration.min(dec).max(-from.acceleration),
                jerk: it.limits.jerk.min(jerk).max(unwind),
            };
            let reach = crate::planner::stop_distance(
                from.velocity,
                from.acceleration,
                lim.deceleration,
                lim.jerk,
            );
            let planned = if from.position + reach <= target {
                // The stop ends within this item.
                self.planner.plan_velocity(from, 0.0, &lim).map(|_| 0.0)
            } else {
                // Braking through the item; never faster at its end than planned before.
                match self.planner.plan_position_towards(from, target, 0.0, &lim) {
                    Ok(v) if v <= it.v_end + 1e-9 => Ok(v),
                    _ => {
                        let own = Limits {
                            velocity: lim.velocity,
                            ..it.limits
                        };
                        self.planner.plan_position_towards(from, target, 0.0, &own)
                    }
                }
            };
            if planned.is_err() {
                self.planner
                    .plan_fallback_stop(from, it.limits.deceleration, it.limits.jerk);
            }
            return;
        }
        if target - from.position <= 1e-12 && it.v_end >= from.velocity - 1e-9 {
            // A zero-length item: passed at once.
            self.planner.clear();
            return;
        }
        if self
            .planner
            .plan_position_towards(from, target, it.v_end, &it.limits)
            .is_err()
        {
            self.planner
                .plan_fallback_stop(from, it.limits.deceleration, it.limits.jerk);
        }
    }

    fn follow(&mut self, dt: f64, report: &mut StepReport) {
        // Waiting items at the front are handled before any motion.
        if self.enter_waiting(report) {
            self.hold();
            return;
        }
        if let Exec::Follow { planned: false } = self.exec {
            self.plan_front();
            self.exec = Exec::Follow { planned: true };
        }
        if let Some(it) = self.items.front() {
            if it.command != self.last_started {
                self.last_started = it.command;
                report.push_started(it.command);
            }
        }
        let k = self.planner.step(dt * self.k).unwrap_or(self.s);
        self.s = Kinematics {
            position: k.position.max(self.s.position),
            velocity: k.velocity.max(0.0),
            ..k
        };
        self.advance_while_passed(report);
        self.sample();
        if self.braking.is_some() && self.planner.finished() && self.s.velocity <= EPS_V {
            // Standstill: the stop ends here; the rest of the queue is dropped.
            self.clear_items();
            self.end_brake();
            report.braked = true;
        }
        if self.items.is_empty() {
            self.exec = Exec::Idle;
            self.hold();
        }
    }

    /// A dwell or an unreleased blocker at the front: stand there.
    fn enter_waiting(&mut self, report: &mut StepReport) -> bool {
        loop {
            let Some(it) = self.items.front().copied() else {
                return false;
            };
            if self.braking.is_some() && !matches!(it.kind, ItemKind::Motion(_)) {
                // A stop that reaches a dwell or a blocker ends there.
                self.clear_items();
                self.end_brake();
                self.exec = Exec::Idle;
                report.braked = true;
                return true;
            }
            match it.kind {
                ItemKind::Dwell(t) => {
                    if it.command != self.last_started {
                        self.last_started = it.command;
                        report.push_started(it.command);
                    }
                    if t <= 0.0 {
                        self.pass_front(report);
                        continue;
                    }
                    self.exec = Exec::Dwell { left: t };
                    return true;
                }
                ItemKind::Blocker { id, released } => {
                    if it.command != self.last_started {
                        self.last_started = it.command;
                        report.push_started(it.command);
                    }
                    if released {
                        self.pass_front(report);
                        continue;
                    }
                    self.exec = Exec::Blocked { id };
                    return true;
                }
                ItemKind::Motion(_) => return false,
            }
        }
    }

    /// Pops the front item as finished and goes on following.
    fn pass_front(&mut self, report: &mut StepReport) {
        if let Some(it) = self.pop_item() {
            if it.last {
                report.push_done(it.command);
            }
        }
        self.exec = if self.items.is_empty() {
            Exec::Idle
        } else {
            Exec::Follow { planned: false }
        };
    }

    /// Pops every motion item `s` has passed (or whose plan has ended) and plans the next one
    /// from the present state. The point of a passed item is its exact end until the next
    /// item is sampled.
    fn advance_while_passed(&mut self, report: &mut StepReport) {
        while let Some(it) = self.items.front().copied() {
            let ItemKind::Motion(seg) = it.kind else {
                break;
            };
            // A stop that ends at standstill inside the item has not passed it.
            let standing_stop = self.braking.is_some() && self.s.velocity <= EPS_V;
            let finished = self.planner.finished() && !standing_stop;
            if self.s.position < it.end_s() - 1e-12 && !finished {
                break;
            }
            if finished || self.items.len() == 1 {
                // Never short of the item's end because of the solver's rounding.
                self.s.position = self.s.position.max(it.end_s());
            }
            self.pop_item();
            self.point = seg.end();
            if it.last {
                report.push_done(it.command);
            }
            // Released blockers are passed in motion.
            while let Some(b) = self.items.front().copied() {
                if !matches!(b.kind, ItemKind::Blocker { released: true, .. }) {
                    break;
                }
                self.pop_item();
                if b.last {
                    report.push_done(b.command);
                }
            }
            let Some(next) = self.items.front().copied() else {
                break;
            };
            if next.command != self.last_started && !next.waits() {
                self.last_started = next.command;
                report.push_started(next.command);
            }
            if next.waits() {
                self.s.velocity = 0.0;
                self.s.acceleration = 0.0;
                break;
            }
            self.plan_front();
        }
    }

    /// Marks a queued blocker released (early, or the one the path waits at). False: no
    /// queued blocker has this id.
    pub(super) fn release_blocker(&mut self, id: u32) -> bool {
        let mut found = false;
        for it in self.items.iter_mut() {
            if let ItemKind::Blocker { id: b, released } = &mut it.kind {
                if *b == id && !*released {
                    *released = true;
                    found = true;
                    break;
                }
            }
        }
        if found {
            self.look_ahead();
            if let Exec::Follow { .. } = self.exec {
                self.exec = Exec::Follow { planned: false };
            }
        }
        found
    }

    /// The blocker the path waits at.
    pub(super) fn blocked(&self) -> Option<u32> {
        match self.exec {
            Exec::Blocked { id } => Some(id),
            _ => None,
        }
    }

    /// Distance and time left in the front item (RemainingCartesianDistanceActiveJob,
    /// RemainingTimeActiveJob).
    pub(super) fn remaining(&self) -> (f64, f64) {
        match (self.exec, self.items.front()) {
            (Exec::Follow { .. }, Some(it)) => {
                let d = (it.end_s() - self.s.position).max(0.0);
                // At the override in effect; with the path held (0) as at 100 %.
                let t = if self.k > 0.0 {
                    self.planner.remaining_time() / self.k
                } else {
                    self.planner.remaining_time()
                };
                (d, t)
            }
            (Exec::Dwell { left }, _) => (0.0, left),
            _ => (0.0, 0.0),
        }
    }
}

/// The highest velocity from which a jerk-limited stop (zero acceleration at both ends) with
/// deceleration `d` and jerk `j` reaches `v_end` within `len`.
pub(super) fn brake_reach(len: f64, v_end: f64, d: f64, j: f64) -> f64 {
    if len <= 0.0 {
        return v_end;
    }
    // Distance to go from v_end + x down to v_end.
    let dist = |x: f64| {
        if x >= d * d / j {
            (2.0 * v_end + x) / 2.0 * (x / d + d / j)
        } else {
            (2.0 * v_end + x) * (x / j).sqrt()
        }
    };
    // Trapezoidal case, closed form: x²/d + x(2v/d + d/j) + 2v·d/j − 2L = 0.
    let (a, b, c) = (
        1.0 / d,
        2.0 * v_end / d + d / j,
        2.0 * v_end * d / j - 2.0 * len,
    );
    let disc = b * b - 4.0 * a * c;
    if disc >= 0.0 {
        let x = (-b + disc.sqrt()) / (2.0 * a);
        if x >= d * d / j {
            return v_end + x * (1.0 - 1e-12);
        }
    }
    // Triangular case: bisection on [0, d²/j].
    let (mut lo, mut hi) = (0.0, d * d / j);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if dist(mid) <= len {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    v_end + lo
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn brake_reach_inverts_the_jerk_limited_braking_distance() {
        for &(v_end, d, j) in &[(0.0, 1000.0, 1e4), (50.0, 500.0, 1e5), (0.0, 10.0, 1e6)] {
            for &len in &[1e-3, 0.5, 10.0, 1000.0] {
                let v = brake_reach(len, v_end, d, j);
                let s = crate::planner::stop_distance(v - v_end, 0.0, d, j);
                // The braking distance from v to v_end (shifted frame: v − v_end to 0 plus
                // v_end for the whole time) fits in len.
                let t = if v - v_end >= d * d / j {
                    (v - v_end) / d + d / j
                } else {
                    2.0 * ((v - v_end) / j).sqrt()
                };
                let dist = s + v_end * t;
                assert!(dist <= len * (1.0 + 1e-9), "{v} {dist} > {len}");
                assert!(dist >= len * (1.0 - 1e-6), "{v} {dist} ≪ {len}");
            }
        }
    }
}
