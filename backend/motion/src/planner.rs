//! The jerk-limited planner: time-optimal profiles from any state, behind our own interface.
//!
//! `rsruckig` (pinned) solves the 1-DoF state-to-state problem; this module maps PLCopen
//! dynamics onto it (acceleration vs deceleration by direction of travel) and samples the
//! trajectory cycle by cycle. When Ruckig cannot solve a problem (it never should for valid
//! limits) the caller falls back to [`StopRamp`], a closed-form jerk-limited stop.

use std::cell::RefCell;

use rsruckig::prelude::*;

/// A kinematic state of the setpoint.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Kinematics {
    pub position: f64,
    pub velocity: f64,
    pub acceleration: f64,
    pub jerk: f64,
}

/// PLCopen dynamics of one job, all > 0. `acceleration` applies while |v| rises,
/// `deceleration` while it falls.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limits {
    pub velocity: f64,
    pub acceleration: f64,
    pub deceleration: f64,
    pub jerk: f64,
}

impl Limits {
    pub fn is_valid(&self) -> bool {
        [
            self.velocity,
            self.acceleration,
            self.deceleration,
            self.jerk,
        ]
        .iter()
        .all(|x| x.is_finite() && *x > 0.0)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlanError {
    /// A limit is not finite and positive, or the state is not finite.
    InvalidInput,
    /// The solver found no trajectory.
    Infeasible,
}

/// Error handler that turns every Ruckig complaint into an `Err` without building a message
/// string of its own (never `IgnoreErrorHandler`: it lets invalid input through).
#[derive(Debug, Default, Clone, Copy)]
pub struct RejectErrors;

impl RuckigErrorHandler for RejectErrors {
    fn handle_validation_error(_message: &str) -> Result<(), RuckigError> {
        Err(RuckigError::ValidationError(String::new()))
    }
    fn handle_calculator_error(_message: &str) -> Result<(), RuckigError> {
        Err(RuckigError::CalculatorError(String::new()))
    }
}

/// How a planned position profile runs relative to its target.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Course {
    /// Only towards the target (up to what cannot be avoided).
    Towards,
    /// Moves away behind its start first (to gain a run-up).
    BacksUp,
    /// Passes beyond the target and returns.
    Overshoots,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Plan {
    None,
    Ruckig,
    Fallback,
}

/// Ruckig's working memory and its input: 13.5 KB, used only while a plan is solved.
struct Solver {
    otg: Ruckig<1, RejectErrors>,
    input: InputParameter<1>,
}

thread_local! {
    /// One solver per thread, shared by every planner on it: planning runs one problem at a
    /// time, and nothing of a solve is kept in the solver (the plan is the planner's
    /// trajectory; Ruckig's calculator only holds scratch). Three solvers per axis (its job's
    /// planner and phasing's two), as before, put each axis's few hundred hot bytes 51.5 KB
    /// apart, on pages of their own (issue 27, decision 182).
    static SOLVER: RefCell<Option<Box<Solver>>> = const { RefCell::new(None) };
}

/// Makes this thread's solver, so that no plan on it allocates (the cycle thread's
/// `Kernel::new` calls it). A thread that plans without it makes its solver at the first plan.
pub fn prepare_solver() {
    SOLVER.with(|s| {
        s.borrow_mut().get_or_insert_with(Solver::new);
    });
}

/// This thread's solver is made: its plans allocate nothing.
pub fn solver_prepared() -> bool {
    SOLVER.with(|s| s.borrow().is_some())
}

impl Solver {
    fn new() -> Box<Solver> {
        Box::new(Solver {
            // The cycle time is set by each solve (it counts only for discrete durations,
            // which no plan asks for).
            otg: Ruckig::new(None, 0.001),
            input: InputParameter::new(None),
        })
    }
}

/// What a plan aims at: Ruckig's control interface and target (the rest of its input is the
/// start state and the limits, given to each solve).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Goal {
    interface: ControlInterface,
    position: f64,
    velocity: f64,
}

/// One axis's setpoint generator. Allocation-free after construction (with the thread's
/// solver prepared, [`prepare_solver`]).
pub struct Planner {
    cycle_time: f64,
    goal: Goal,
    traj: Trajectory<1>,
    /// A braking segment sampled before `traj` for `split` seconds (0 = none): a position
    /// plan that starts above its velocity limit first brakes to it on the velocity
    /// interface (see [`Planner::plan_position`]).
    brake: Trajectory<1>,
    split: f64,
    plan: Plan,
    time: f64,
    duration: f64,
    end: Kinematics,
    fallback: StopRamp,
    /// Coordinate shift applied after planning (MC_SetPosition during motion).
    shift: f64,
}

impl core::fmt::Debug for Planner {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Planner")
            .field("plan", &self.plan)
            .field("time", &self.time)
            .field("duration", &self.duration)
            .finish()
    }
}

impl Planner {
    pub fn new(cycle_time: f64) -> Self {
        Planner {
            cycle_time,
            goal: Goal {
                interface: ControlInterface::Position,
                position: 0.0,
                velocity: 0.0,
            },
            traj: Trajectory::new(None),
            brake: Trajectory::new(None),
            split: 0.0,
            plan: Plan::None,
            time: 0.0,
            duration: 0.0,
            end: Kinematics::default(),
            fallback: StopRamp::default(),
            shift: 0.0,
        }
    }

    /// Plans from `from` to `target` arriving with `target_velocity` (0 for a stop at the
    /// target, ≠ 0 for blending and continuous moves). Returns the duration.
    pub fn plan_position(
        &mut self,
        from: Kinematics,
        target: f64,
        target_velocity: f64,
        limits: &Limits,
    ) -> Result<f64, PlanError> {
        check_target(from, limits, target, target_velocity)?;
        let d = self.plan_position_direct(from, target, target_velocity, limits)?;
        if self.straight(from, target, limits.jerk) {
            return Ok(d);
        }
        // Above the velocity limit (an override, a slower successor, the run-up of a turn):
        // Ruckig's own brake hands over with the braking acceleration still applied, so the
        // velocity undershoots by up to a²/2j — backwards when the limit is low. Brake (or
        // turn) to the limit on the velocity interface instead, which ends with a = 0, and
        // position from there; when that is too long to stop at the target and the axis is
        // braking for it already, brake on from the present velocity, which only falls.
        let toward = from.velocity * (target - from.position) > 0.0;
        let braking_first = toward && from.velocity.abs() > limits.velocity;
        if !self.exceeds_velocity(limits.velocity) && !braking_first {
            return Ok(d); // not Ruckig's brake at work: its profile stands
        }
        if let Ok(d) = self.plan_braked(from, target, target_velocity, limits) {
            if self.straight(from, target, limits.jerk) {
                return Ok(d);
            }
        }
        if braking_first {
            let braking = Limits {
                velocity: from.velocity.abs(),
                ..*limits
            };
            if let Ok(d) = self.plan_position_direct(from, target, target_velocity, &braking) {
                if self.straight(from, target, limits.jerk) {
                    return Ok(d);
                }
            }
        }
        self.plan_position_direct(from, target, target_velocity, limits)
    }

    /// The planned velocity's magnitude goes above `limit` somewhere (it started above it,
    /// or a turn's run-up carries it there): Ruckig's brake is at work.
    fn exceeds_velocity(&self, limit: f64) -> bool {
        let bound = limit * (1.0 + 1e-9) + 1e-12;
        let mut above = false;
        self.phases(|_, v, a, j, t| {
            let mut at = |x: f64| above |= x.abs() > bound;
            at(v);
            at(v + a * t + 0.5 * j * t * t);
            if j != 0.0 {
                let ts = -a / j;
                if ts > 0.0 && ts < t {
                    at(v - a * a / (2.0 * j));
                }
            }
        });
        above
    }

    /// The plan goes beyond `target` in direction `dir`.
    fn passes(&self, target: f64, dir: f64) -> bool {
        let (min, max) = self.extrema();
        let tol = 1e-9 * (1.0 + target.abs());
        if dir > 0.0 {
            max > target + tol
        } else {
            min < target - tol
        }
    }

    /// The plan runs to `target` without passing it and without turning back on the way.
    fn straight(&self, from: Kinematics, target: f64, jerk: f64) -> bool {
        let dir = sign(target - from.position);
        !self.passes(target, dir) && !self.backs_up_on_the_way(from, target, jerk)
    }

    /// Whether the plan turns back on its way to `target` more than releasing the present
    /// acceleration forces it to.
    fn backs_up_on_the_way(&self, from: Kinematics, target: f64, jerk: f64) -> bool {
        let dir = sign(target - from.position);
        let a_away = (from.acceleration * dir).min(0.0).abs();
        let dip = (a_away * a_away / (2.0 * jerk) - (from.velocity * dir).max(0.0)).max(0.0);
        let floor = -dip - 1e-9 * (1.0 + from.velocity.abs());
        dir != 0.0 && self.reverses_after_turning(dir, from.velocity * dir, floor)
    }

    /// The braking segment to the velocity limit, then the position profile from its end.
    fn plan_braked(
        &mut self,
        from: Kinematics,
        target: f64,
        target_velocity: f64,
        limits: &Limits,
    ) -> Result<f64, PlanError> {
        let dir = sign(target - from.position);
        if dir == 0.0 {
            return Err(PlanError::Infeasible);
        }
        self.plan_velocity(from, dir * limits.velocity, limits)?;
        let mid = self.end;
        let braking = self.duration;
        if (target - mid.position) * dir <= 0.0 {
            return Err(PlanError::Infeasible); // it cannot brake before the target
        }
        core::mem::swap(&mut self.traj, &mut self.brake);
        match self.plan_position_direct(mid, target, target_velocity, limits) {
            Ok(d) => {
                self.split = braking;
                self.duration = braking + d;
                Ok(self.duration)
            }
            Err(e) => {
                core::mem::swap(&mut self.traj, &mut self.brake);
                Err(e)
            }
        }
    }

    fn plan_position_direct(
        &mut self,
        from: Kinematics,
        target: f64,
        target_velocity: f64,
        limits: &Limits,
    ) -> Result<f64, PlanError> {
        let dist = target - from.position;
        let dir = if dist != 0.0 {
            dist.signum()
        } else {
            from.velocity.signum()
        };
        // Will the profile have to turn around (moving away, or too fast to stop in time)?
        let away = from.velocity * dir < 0.0;
        let overshoot = from.velocity * dir > 0.0
            && stop_distance(
                from.velocity,
                from.acceleration,
                limits.deceleration,
                limits.jerk,
            ) > dist.abs();
        let (max_acc, min_acc) = if away || overshoot {
            let a = limits.acceleration.min(limits.deceleration);
            (a, -a)
        } else {
            direction_limits(dir, limits)
        };
        self.goal = Goal {
            interface: ControlInterface::Position,
            position: target,
            velocity: target_velocity,
        };
        if overshoot && !away {
            // The closed-form braking distance is a hair above the distance left when the
            // axis is braking exactly for the target (a re-plan on the way): braking with the
            // deceleration then still stops there, the lower symmetric limit would not.
            let (max_dir, min_dir) = direction_limits(dir, limits);
            if let Ok(d) = self.solve(from, limits, max_dir, min_dir) {
                if !self.passes(target, dir) {
                    return Ok(d);
                }
            }
        }
        self.solve(from, limits, max_acc, min_acc)
    }

    /// Plans from `from` to `target`, passing it with an end velocity as close to
    /// `end_velocity` as the axis can reach while it only ever moves towards the target: it
    /// never backs up to gain a run-up for an end velocity it cannot reach within the
    /// distance (the velocity is lowered to the best reachable one), and never overshoots
    /// and returns to pass at an end velocity it cannot brake down to in time (the velocity is
    /// raised to the lowest it can brake to). Motion away from the target that no profile
    /// can avoid (the axis was moving away when the plan began) stays. A stop at the target
    /// (`end_velocity` 0) and an end velocity pointing away from the target are planned as
    /// asked. Returns the planned end velocity (signed).
    ///
    /// Cost: one solve when `end_velocity` is reachable, else a 16-step bisection (about 18
    /// solves, ≈ 25 µs, docs/benchmarks.md), only when a blending or continuous move is
    /// (re)planned.
    pub fn plan_position_towards(
        &mut self,
        from: Kinematics,
        target: f64,
        end_velocity: f64,
        limits: &Limits,
    ) -> Result<f64, PlanError> {
        check_target(from, limits, target, end_velocity)?;
        let dir = sign(target - from.position);
        if end_velocity == 0.0 || end_velocity * dir < 0.0 {
            self.plan_position(from, target, end_velocity, limits)?;
            return Ok(end_velocity);
        }
        if dir == 0.0 {
            // At the target already: it can only be passed now, at the present velocity.
            let now = if from.velocity * end_velocity > 0.0 && from.acceleration == 0.0 {
                from.velocity
            } else {
                0.0
            };
            self.plan_position(from, target, now, limits)?;
            return Ok(now);
        }
        // Where the axis may get to behind its start: it cannot avoid braking a motion away
        // from the target, nor (within a jerk-limited release) an acceleration away from it.
        let a_away = (from.acceleration * dir).min(0.0).abs();
        let mut back = from.position;
        if from.velocity * dir < 0.0 {
            let a = limits.acceleration.min(limits.deceleration);
            back -= dir * stop_distance(from.velocity, from.acceleration, a, limits.jerk);
        }
        let scale = 1.0 + from.position.abs().max(target.abs());
        let tol_back = 1e-9 * scale + a_away * a_away * a_away / (limits.jerk * limits.jerk);
        let tol = 1e-9 * scale;
        // Releasing an acceleration away from the target costs a²/2j of velocity: the dip
        // below zero that no profile avoids.
        let dip = (a_away * a_away / (2.0 * limits.jerk) - (from.velocity * dir).max(0.0)).max(0.0);
        let floor = -dip - 1e-9 * (1.0 + end_velocity.abs());
        let want = end_velocity.abs();
        let course = |me: &mut Self, u: f64| -> Result<Course, PlanError> {
            // Passing faster than the velocity limit is allowed (blending velocities are).
            let lim = Limits {
                velocity: limits.velocity.max(u),
                ..*limits
            };
            me.plan_position(from, target, dir * u, &lim)?;
            let (lo, hi) = me.extrema();
            let (behind, beyond) = if dir > 0.0 {
                (lo < back - tol_back, hi > target + tol)
            } else {
                (hi > back + tol_back, lo < target - tol)
            };
            // A way back in the middle (braking below zero, then on again) is a back-up too;
            // turning back after passing the target is the overshoot.
            let r = if beyond {
                // Passing the target and turning back (also to run at it again from behind).
                Course::Overshoots
            } else if behind || me.reverses_after_turning(dir, from.velocity * dir, floor) {
                Course::BacksUp
            } else {
                Course::Towards
            };
            Ok(r)
        };
        // The velocity the axis passes through anyway (releasing its acceleration) divides
        // the end velocities it must speed up to (unreachable: too high) from those it must
        // brake down to (unreachable: too low); the reachable ones lie around it.
        let (vd, ad) = (from.velocity * dir, from.acceleration * dir);
        let v_free = vd + ad * ad.abs() / (2.0 * limits.jerk);
        if course(self, want)? == Course::Towards {
            return Ok(end_velocity);
        }
        let towards = |me: &mut Self, u: f64| course(me, u).ok() == Some(Course::Towards);
        // Below: the highest reachable in [0, want]; above: the lowest in [want, v_free].
        // The side the physics points to is searched first; Ruckig's time-optimal profile
        // decides what is "reachable" (a monotonic profile to a velocity may exist where the
        // time-optimal one dips), so the other side is searched when the first has nothing.
        let below = |me: &mut Self| towards(me, 0.0).then(|| edge(me, 0.0, want, &towards));
        let above = |me: &mut Self| {
            (want < v_free && towards(me, v_free)).then(|| edge(me, v_free, want, &towards))
        };
        let found = if want < v_free {
            above(self).or_else(|| below(self))
        } else {
            below(self)
        };
        // Nothing: it cannot avoid passing the target; at the velocity it passes through
        // anyway (the caller hands the target over to a successor, or a continuous move goes
        // on from there).
        let best = found.unwrap_or(v_free.max(0.0));
        let lim = Limits {
            velocity: limits.velocity.max(best),
            ..*limits
        };
        self.plan_position(from, target, dir * best, &lim)?;
        Ok(dir * best)
    }

    /// Plans a change to `target_velocity` (velocity interface): MoveVelocity, Halt, Stop,
    /// jog, gear-out. Returns the duration.
    pub fn plan_velocity(
        &mut self,
        from: Kinematics,
        target_velocity: f64,
        limits: &Limits,
    ) -> Result<f64, PlanError> {
        check(from, limits)?;
        if !target_velocity.is_finite() {
            return Err(PlanError::InvalidInput);
        }
        let reversing = from.velocity * target_velocity < 0.0;
        let (max_acc, min_acc) = if reversing {
            let a = limits.acceleration.min(limits.deceleration);
            (a, -a)
        } else {
            let dir = if target_velocity != 0.0 {
                target_velocity.signum()
            } else {
                from.velocity.signum()
            };
            direction_limits(dir, limits)
        };
        self.goal = Goal {
            interface: ControlInterface::Velocity,
            position: from.position,
            velocity: target_velocity,
        };
        // The velocity interface ignores the velocity limit, but Ruckig validates it.
        let limits = Limits {
            velocity: limits
                .velocity
                .max(target_velocity.abs())
                .max(from.velocity.abs()),
            ..*limits
        };
        self.solve(from, &limits, max_acc, min_acc)
    }

    /// Ruckig's own problem, without the PLCopen mapping: signed acceleration limits
    /// `max_acc` > 0 > `min_acc`. Used by the golden-file comparison with upstream Ruckig.
    #[allow(
        clippy::too_many_arguments,
        reason = "Ruckig's input fields one to one, as the golden-file comparison reads them"
    )]
    pub fn plan_signed(
        &mut self,
        velocity_interface: bool,
        from: Kinematics,
        target_position: f64,
        target_velocity: f64,
        max_velocity: f64,
        max_acc: f64,
        min_acc: f64,
        jerk: f64,
    ) -> Result<f64, PlanError> {
        let limits = Limits {
            velocity: max_velocity,
            acceleration: max_acc,
            deceleration: -min_acc,
            jerk,
        };
        check(from, &limits)?;
        self.goal = Goal {
            interface: if velocity_interface {
                ControlInterface::Velocity
            } else {
                ControlInterface::Position
            },
            position: target_position,
            velocity: target_velocity,
        };
        self.solve_signed(from, &limits, max_acc, min_acc)
    }

    fn solve(
        &mut self,
        from: Kinematics,
        limits: &Limits,
        max_acc: f64,
        min_acc: f64,
    ) -> Result<f64, PlanError> {
        let duration = self.solve_signed(from, limits, max_acc, min_acc)?;
        // The signed limits map PLCopen acceleration/deceleration onto one direction of
        // travel. A profile that turns round on the way (e.g. it must back up to pass its
        // target at the end velocity) also speeds up in the other direction, where they would
        // be swapped: plan it with the lower of both throughout.
        if max_acc != -min_acc && !self.is_monotonic(from.position) {
            let a = max_acc.min(-min_acc);
            return self.solve_signed(from, limits, a, -a);
        }
        Ok(duration)
    }

    /// The planned position never turns round (no extremum inside the profile).
    fn is_monotonic(&mut self, start: f64) -> bool {
        let end = self.end.position;
        let (min, max) = self.extrema();
        let tol = 1e-9 * (1.0 + start.abs().max(end.abs()));
        min >= start.min(end) - tol && max <= start.max(end) + tol
    }

    /// Whether the planned velocity, once it points in `dir` (or from the start when
    /// `v0_dir` ≥ 0), falls below `floor` (in `dir`) again: the profile backs up on the way.
    /// Exact: the velocity is piecewise quadratic in Ruckig's constant-jerk phases.
    fn reverses_after_turning(&self, dir: f64, v0_dir: f64, floor: f64) -> bool {
        let mut toward = v0_dir >= 0.0;
        let mut reversed = false;
        let mut point = |x: f64| {
            if toward && x < floor {
                reversed = true;
            }
            if x >= 0.0 {
                toward = true;
            }
        };
        let mut phase = |v: f64, a: f64, j: f64, t: f64| {
            // A NaN duration adds no phase either.
            if t <= 0.0 || t.is_nan() {
                return;
            }
            let (v, a, j) = (v * dir, a * dir, j * dir);
            point(v);
            if j != 0.0 {
                let ts = -a / j;
                if ts > 0.0 && ts < t {
                    point(v - a * a / (2.0 * j));
                }
            }
            point(v + a * t + 0.5 * j * t * t);
        };
        self.phases(|_, v, a, j, t| phase(v, a, j, t));
        reversed
    }

    /// Every constant-jerk phase of the plan in time order, both segments, Ruckig's brake
    /// pre-phases included: (position, velocity, acceleration, jerk, duration) at its start.
    fn phases(&self, mut f: impl FnMut(f64, f64, f64, f64, f64)) {
        let segments: [Option<&Trajectory<1>>; 2] = [
            if self.split > 0.0 {
                Some(&self.brake)
            } else {
                None
            },
            Some(&self.traj),
        ];
        for traj in segments.into_iter().flatten() {
            for prof in traj.get_profiles() {
                let p = &prof[0];
                for pre in [&p.brake, &p.accel] {
                    if pre.duration > 0.0 {
                        for k in 0..2 {
                            if pre.t[k] > 0.0 {
                                f(pre.p[k], pre.v[k], pre.a[k], pre.j[k], pre.t[k]);
                            }
                        }
                    }
                }
                for k in 0..7 {
                    if p.t[k] > 0.0 {
                        f(p.p[k], p.v[k], p.a[k], p.j[k], p.t[k]);
                    }
                }
            }
        }
    }

    /// Lowest and highest planned position (before any coordinate shift), both segments.
    /// Our own scan of the phases: rsruckig's `get_position_extrema` counts the profile's
    /// final position `pf`, which its velocity interface leaves stale from an earlier plan.
    fn extrema(&self) -> (f64, f64) {
        let (mut min, mut max) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut at = |x: f64| {
            min = min.min(x);
            max = max.max(x);
        };
        self.phases(|p, v, a, j, t| {
            let pos = |s: f64| p + s * (v + s * (a / 2.0 + s * j / 6.0));
            at(p);
            at(pos(t));
            // Turning points inside the phase: v + a s + j s²/2 = 0.
            if j != 0.0 {
                let disc = a * a - 2.0 * j * v;
                if disc >= 0.0 {
                    let r = disc.sqrt();
                    for s in [(-a + r) / j, (-a - r) / j] {
                        if s > 0.0 && s < t {
                            at(pos(s));
                        }
                    }
                }
            } else if a != 0.0 {
                let s = -v / a;
                if s > 0.0 && s < t {
                    at(pos(s));
                }
            }
        });
        if min > max {
            // No phase at all (a zero-length plan): it stands at its end.
            let e = self.end.position - self.shift;
            return (e, e);
        }
        (min, max)
    }

    fn solve_signed(
        &mut self,
        from: Kinematics,
        limits: &Limits,
        max_acc: f64,
        min_acc: f64,
    ) -> Result<f64, PlanError> {
        let solved = SOLVER.with(|solver| {
            let mut solver = solver.borrow_mut();
            let Solver { otg, input: inp } = &mut **solver.get_or_insert_with(Solver::new);
            otg.delta_time = self.cycle_time;
            inp.control_interface = self.goal.interface;
            inp.target_position[0] = self.goal.position;
            inp.target_velocity[0] = self.goal.velocity;
            inp.current_position[0] = from.position;
            inp.current_velocity[0] = from.velocity;
            inp.current_acceleration[0] = from.acceleration;
            inp.target_acceleration[0] = 0.0;
            // The limits as given first (× 1.0 is exact). rsruckig 3.0.1 fails on about 0.2 %
            // of valid position problems in narrow numerical bands that upstream Ruckig solves
            // (backend/motion/tests/ruckig_golden.rs): the same problem with limits a hair
            // tighter lies outside the band. Tighter limits never violate the commanded ones;
            // the duration grows by about the same fraction.
            [0.0, 1e-12, 1e-11, 1e-10, 1e-9, 1e-8, 1e-7, 1e-6]
                .into_iter()
                .any(|shrink| {
                    let k = 1.0 - shrink;
                    inp.max_velocity[0] = limits.velocity * k;
                    inp.max_acceleration[0] = max_acc * k;
                    inp.min_acceleration = Some(rsruckig::daov_stack![min_acc * k]);
                    inp.max_jerk[0] = limits.jerk * k;
                    matches!(
                        otg.calculate(inp, &mut self.traj),
                        Ok(RuckigResult::Working | RuckigResult::Finished)
                    )
                })
        });
        match solved {
            true => {
                self.plan = Plan::Ruckig;
                self.split = 0.0;
                self.shift = 0.0;
                self.time = 0.0;
                self.duration = self.traj.get_duration();
                // The end state is the target itself, not a float-noisy sample of it.
                let mut end = self.sample_raw(self.duration);
                end.velocity = self.goal.velocity;
                end.acceleration = 0.0;
                end.jerk = 0.0;
                if self.goal.interface == ControlInterface::Position {
                    end.position = self.goal.position;
                }
                self.end = end;
                Ok(self.duration)
            }
            false => Err(PlanError::Infeasible),
        }
    }

    /// Last resort: closed-form jerk-limited stop from `from`.
    pub fn plan_fallback_stop(&mut self, from: Kinematics, deceleration: f64, jerk: f64) {
        self.fallback = StopRamp::new(from, deceleration.max(1e-9), jerk.max(1e-9));
        self.plan = Plan::Fallback;
        self.time = 0.0;
        self.duration = f64::INFINITY;
    }

    /// Moves the planned trajectory by `delta` (the coordinate system changed, the motion
    /// did not).
    pub fn shift(&mut self, delta: f64) {
        self.shift += delta;
        self.end.position += delta;
        self.fallback.k.position += delta;
    }

    /// Whether the current position profile passes beyond `target` in direction `dir`
    /// (a blend or limit stop that cannot brake in time).
    pub fn overshoots(&mut self, target: f64, dir: f64) -> bool {
        if self.plan != Plan::Ruckig {
            return false;
        }
        let (min, max) = self.extrema();
        let tol = 1e-9 * (1.0 + target.abs());
        if dir > 0.0 {
            max + self.shift > target + tol
        } else {
            min + self.shift < target - tol
        }
    }

    /// Forgets the plan (the setpoint then holds still).
    pub fn clear(&mut self) {
        self.plan = Plan::None;
    }

    pub fn is_planned(&self) -> bool {
        self.plan != Plan::None
    }

    /// Advances the plan by `dt` and returns the new setpoint. After the end of a profile
    /// the setpoint continues with the end velocity (zero for a stop).
    pub fn step(&mut self, dt: f64) -> Option<Kinematics> {
        match self.plan {
            Plan::None => None,
            Plan::Ruckig => {
                self.time += dt;
                Some(self.sample_at(self.time))
            }
            Plan::Fallback => {
                let k = self.fallback.step(dt);
                if self.fallback.finished() {
                    self.duration = self.time + dt;
                }
                self.time += dt;
                Some(k)
            }
        }
    }

    fn sample_at(&self, t: f64) -> Kinematics {
        if self.plan == Plan::Ruckig && t >= self.duration {
            // At and beyond the end: the exact end state, then constant end velocity.
            let e = self.end;
            return Kinematics {
                position: e.position + e.velocity * (t - self.duration),
                velocity: e.velocity,
                acceleration: 0.0,
                jerk: 0.0,
            };
        }
        self.sample_raw(t)
    }

    fn sample_raw(&self, t: f64) -> Kinematics {
        let mut p = rsruckig::daov_stack![0.0];
        let mut v = rsruckig::daov_stack![0.0];
        let mut a = rsruckig::daov_stack![0.0];
        let mut j = rsruckig::daov_stack![0.0];
        let mut section = None;
        let (traj, t) = if self.split > 0.0 && t < self.split {
            (&self.brake, t)
        } else {
            (&self.traj, t - self.split)
        };
        traj.at_time(
            t.min(traj.get_duration()),
            &mut Some(&mut p),
            &mut Some(&mut v),
            &mut Some(&mut a),
            &mut Some(&mut j),
            &mut section,
        );
        Kinematics {
            position: p[0] + self.shift,
            velocity: v[0],
            acceleration: a[0],
            jerk: j[0],
        }
    }

    /// The profile has reached its end state.
    pub fn finished(&self) -> bool {
        match self.plan {
            Plan::None => true,
            Plan::Ruckig => self.time >= self.duration,
            Plan::Fallback => self.fallback.finished(),
        }
    }

    pub fn duration(&self) -> f64 {
        self.duration
    }

    pub fn elapsed(&self) -> f64 {
        self.time
    }

    pub fn remaining_time(&self) -> f64 {
        (self.duration - self.time).max(0.0)
    }

    /// The end state of the current profile.
    pub fn end_state(&self) -> Kinematics {
        self.end
    }
}

/// The last point from `ok` (where `pred` holds) towards `other` (where it does not) at which
/// `pred` still holds, by bisection (16 steps: 1.5e-5 of the interval).
fn edge<P>(me: &mut P, mut ok: f64, mut other: f64, pred: &impl Fn(&mut P, f64) -> bool) -> f64 {
    for _ in 0..16 {
        let mid = 0.5 * (ok + other);
        if pred(me, mid) {
            ok = mid;
        } else {
            other = mid;
        }
    }
    ok
}

/// -1, 0 or 1 (unlike `f64::signum`, which gives ±1 for ±0).
pub fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// `check`, and a finite target position and velocity.
fn check_target(
    from: Kinematics,
    limits: &Limits,
    target: f64,
    velocity: f64,
) -> Result<(), PlanError> {
    check(from, limits)?;
    if !target.is_finite() || !velocity.is_finite() {
        return Err(PlanError::InvalidInput);
    }
    Ok(())
}

fn check(from: Kinematics, limits: &Limits) -> Result<(), PlanError> {
    if !limits.is_valid()
        || !from.position.is_finite()
        || !from.velocity.is_finite()
        || !from.acceleration.is_finite()
    {
        return Err(PlanError::InvalidInput);
    }
    Ok(())
}

/// Ruckig's signed acceleration limits for travel in direction `dir` (PLCopen: acceleration
/// raises |v|, deceleration lowers it).
fn direction_limits(dir: f64, limits: &Limits) -> (f64, f64) {
    if dir < 0.0 {
        (limits.deceleration, -limits.acceleration)
    } else {
        (limits.acceleration, -limits.deceleration)
    }
}

/// Distance needed to stop from (v, a) with deceleration `dec` and jerk `jerk`, in the
/// direction of v (closed form of the jerk-limited stop; ≥ 0).
pub fn stop_distance(v: f64, a: f64, dec: f64, jerk: f64) -> f64 {
    if v == 0.0 && a == 0.0 {
        return 0.0;
    }
    let mut r = StopRamp::new(
        Kinematics {
            position: 0.0,
            velocity: v,
            acceleration: a,
            jerk: 0.0,
        },
        dec,
        jerk,
    );
    r.distance_to_stop().abs()
}

/// Closed-form jerk-limited stop: |a| ramps at `jerk` towards −sign(v)·`dec` and back to 0
/// so that v and a reach zero together. Used as the fallback and to predict braking distance.
#[derive(Clone, Copy, Debug, Default)]
pub struct StopRamp {
    k: Kinematics,
    dec: f64,
    jerk: f64,
    done: bool,
}

impl StopRamp {
    pub fn new(from: Kinematics, dec: f64, jerk: f64) -> Self {
        StopRamp {
            k: from,
            dec,
            jerk,
            done: from.velocity == 0.0 && from.acceleration == 0.0,
        }
    }

    pub fn finished(&self) -> bool {
        self.done
    }

    /// Integrates the ramp analytically to the end and returns the travelled distance.
    fn distance_to_stop(&mut self) -> f64 {
        // Work in the frame where v ≥ 0.
        let s = if self.k.velocity != 0.0 {
            self.k.velocity.signum()
        } else {
            -self.k.acceleration.signum()
        };
        let (mut v, mut a) = (self.k.velocity * s, self.k.acceleration * s);
        let (d, j) = (self.dec, self.jerk);
        let mut x = 0.0;
        // Phase 0: positive acceleration is first ramped down to 0.
        if a > 0.0 {
            let t = a / j;
            x += v * t + a * t * t / 2.0 - j * t * t * t / 6.0;
            v += a * t - j * t * t / 2.0;
            a = 0.0;
        }
        // Now a ≤ 0. Velocity lost while ramping a back to 0 from a: a²/(2j).
        let a_neg = -a;
        if a_neg * a_neg / (2.0 * j) >= v {
            // Already decelerating hard enough: releasing the braking still reaches v = 0
            // (where the ramp stops, clamping a) at the first root of v(t) = 0.
            let t = (a_neg - (a_neg * a_neg - 2.0 * j * v).max(0.0).sqrt()) / j;
            x += v * t - a_neg * t * t / 2.0 + j * t * t * t / 6.0;
            return x * s;
        }
        // Raise |a| to a_peak ≤ d, hold, then ramp back to 0.
        let a_peak_unlimited = ((v * j) + a_neg * a_neg / 2.0).sqrt();
        let a_peak = a_peak_unlimited.min(d.max(a_neg));
        // ramp up from a_neg to a_peak
        let t1 = (a_peak - a_neg) / j;
        x += v * t1 - a_neg * t1 * t1 / 2.0 - j * t1 * t1 * t1 / 6.0;
        v -= a_neg * t1 + j * t1 * t1 / 2.0;
        // ramp down from a_peak to 0 loses a_peak²/(2j)
        let v_ramp = a_peak * a_peak / (2.0 * j);
        let v_hold = (v - v_ramp).max(0.0);
        let t2 = v_hold / a_peak;
        x += v * t2 - a_peak * t2 * t2 / 2.0;
        v -= a_peak * t2;
        let t3 = a_peak / j;
        x += v * t3 - a_peak * t3 * t3 / 2.0 + j * t3 * t3 * t3 / 6.0;
        x * s
    }

    /// One cycle of the stop, choosing the jerk so that a and v reach 0 together.
    pub fn step(&mut self, dt: f64) -> Kinematics {
        if self.done {
            self.k.velocity = 0.0;
            self.k.acceleration = 0.0;
            self.k.jerk = 0.0;
            return self.k;
        }
        let s = if self.k.velocity != 0.0 {
            self.k.velocity.signum()
        } else {
            -self.k.acceleration.signum()
        };
        let (v, a) = (self.k.velocity * s, self.k.acceleration * s);
        let j = self.jerk;
        // Jerk choice in the v ≥ 0 frame: braking acceleration is negative.
        let jj = if a > -self.dec && (-a) * (-a) / (2.0 * j) < v - (-a).max(0.0) * dt {
            -j // build up braking
        } else if a <= 0.0 && a * a / (2.0 * j) >= v {
            j // release braking so that a reaches 0 when v does
        } else if a > 0.0 {
            -j
        } else {
            0.0
        };
        let (mut nv, mut na) = (v + a * dt + jj * dt * dt / 2.0, a + jj * dt);
        let mut np = self.k.position + s * (v * dt + a * dt * dt / 2.0 + jj * dt * dt * dt / 6.0);
        if nv <= 0.0 || (na >= 0.0 && jj > 0.0 && nv <= 1e-12) {
            // Stopped: clamp exactly at rest.
            if nv < 0.0 {
                // Undo the overshoot of the last partial cycle.
                np -= s * nv * dt / 2.0;
            }
            nv = 0.0;
            na = 0.0;
            self.done = true;
        }
        self.k = Kinematics {
            position: np,
            velocity: s * nv,
            acceleration: s * na,
            jerk: s * jj,
        };
        self.k
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const LIM: Limits = Limits {
        velocity: 100.0,
        acceleration: 1000.0,
        deceleration: 500.0,
        jerk: 10000.0,
    };

    fn run(p: &mut Planner, dt: f64) -> Vec<Kinematics> {
        let mut out = Vec::new();
        while !p.finished() {
            out.push(p.step(dt).unwrap());
            assert!(out.len() < 1_000_000);
        }
        out
    }

    /// Decision 182: every planner on a thread solves with the thread's one solver. A plan
    /// must not depend on what the solver solved before: planner `a`'s plans, made between
    /// another planner's, equal bit for bit those of a planner alone on a fresh thread.
    #[test]
    fn a_plan_does_not_depend_on_what_the_shared_solver_solved_before() {
        // (start, target, target velocity, limits): position and velocity plans, some that
        // turn round, one started above its velocity limit.
        let problems: Vec<(Kinematics, f64, f64, Limits)> = (0..40)
            .map(|i| {
                let f = i as f64;
                let from = Kinematics {
                    position: (f * 7.3) % 50.0 - 25.0,
                    velocity: (f * 13.7) % 160.0 - 80.0,
                    acceleration: (f * 31.1) % 400.0 - 200.0,
                    jerk: 0.0,
                };
                let lim = Limits {
                    velocity: 40.0 + (f * 3.1) % 60.0,
                    acceleration: 300.0 + (f * 17.0) % 900.0,
                    deceleration: 200.0 + (f * 23.0) % 900.0,
                    jerk: 5000.0 + (f * 997.0) % 20000.0,
                };
                let target = if i % 3 == 0 {
                    f64::NAN
                } else {
                    (f * 11.9) % 80.0 - 40.0
                };
                let v = if i % 4 == 1 {
                    (f * 5.5) % 30.0 - 15.0
                } else {
                    0.0
                };
                (from, target, v, lim)
            })
            .collect();
        // A plan's duration and its setpoints, bit for bit.
        fn plan(
            p: &mut Planner,
            (from, target, v, lim): &(Kinematics, f64, f64, Limits),
        ) -> Vec<u64> {
            let d = if target.is_nan() {
                p.plan_velocity(*from, *v + 20.0, lim)
            } else {
                p.plan_position(*from, *target, *v, lim)
            };
            let mut bits = vec![d.map_or(u64::MAX, f64::to_bits)];
            if d.is_ok() {
                for _ in 0..2000 {
                    let k = p.step(0.001).unwrap();
                    bits.extend([k.position, k.velocity, k.acceleration].map(f64::to_bits));
                    if p.finished() {
                        break;
                    }
                }
            }
            bits
        }
        let alone: Vec<Vec<u64>> = std::thread::spawn({
            let problems = problems.clone();
            move || {
                let mut a = Planner::new(0.001);
                problems.iter().map(|x| plan(&mut a, x)).collect()
            }
        })
        .join()
        .unwrap();
        let (mut a, mut b) = (Planner::new(0.001), Planner::new(0.002));
        let mut solved = 0;
        for (i, x) in problems.iter().enumerate() {
            // Another planner's problem (the one after) in between.
            plan(&mut b, &problems[(i + 1) % problems.len()]);
            let bits = plan(&mut a, x);
            solved += usize::from(bits[0] != u64::MAX);
            assert_eq!(bits, alone[i], "problem {i}");
        }
        assert!(solved >= 30, "only {solved} of the problems were solved");
    }

    #[test]
    fn position_plan_reaches_target_and_uses_dec_for_braking() {
        let mut p = Planner::new(0.001);
        let d = p
            .plan_position(Kinematics::default(), 50.0, 0.0, &LIM)
            .unwrap();
        assert!(d > 0.5 && d < 1.0, "duration {d}");
        let ks = run(&mut p, 0.001);
        let last = ks.last().unwrap();
        assert!((last.position - 50.0).abs() < 1e-9);
        assert!(last.velocity.abs() < 1e-9);
        let amax = ks.iter().map(|k| k.acceleration).fold(f64::MIN, f64::max);
        let amin = ks.iter().map(|k| k.acceleration).fold(f64::MAX, f64::min);
        assert!(amax <= 1000.0 + 1e-6 && amax > 900.0, "amax {amax}");
        assert!((-500.0 - 1e-6..-450.0).contains(&amin), "amin {amin}");
    }

    #[test]
    fn negative_direction_swaps_signed_limits() {
        let mut p = Planner::new(0.001);
        p.plan_position(Kinematics::default(), -50.0, 0.0, &LIM)
            .unwrap();
        let ks = run(&mut p, 0.001);
        let amin = ks.iter().map(|k| k.acceleration).fold(f64::MAX, f64::min);
        let amax = ks.iter().map(|k| k.acceleration).fold(f64::MIN, f64::max);
        assert!((-1000.0 - 1e-6..-900.0).contains(&amin));
        assert!(amax <= 500.0 + 1e-6 && amax > 450.0);
    }

    /// Whenever |v| rises the acceleration is within `acceleration`, whenever it falls within
    /// `deceleration` — also in a profile that turns round on the way.
    fn assert_plcopen_dynamics(ks: &[Kinematics], lim: &Limits) {
        for k in ks {
            let a_max = if k.acceleration * k.velocity >= 0.0 {
                lim.acceleration
            } else {
                lim.deceleration
            };
            assert!(k.acceleration.abs() <= a_max + 1e-6, "{k:?} above {a_max}");
        }
    }

    #[test]
    fn a_profile_that_turns_round_keeps_acceleration_and_deceleration_apart() {
        let lim = Limits {
            velocity: 500.0,
            acceleration: 100.0,
            deceleration: 1000.0,
            jerk: 20000.0,
        };
        let mut p = Planner::new(0.001);
        // Through the start position at 40 u/s: it has to back up first.
        p.plan_position(Kinematics::default(), 0.0, 40.0, &lim)
            .unwrap();
        let ks = run(&mut p, 0.001);
        assert!(ks.iter().any(|k| k.velocity < -1.0), "backs up");
        assert_plcopen_dynamics(&ks, &lim);
    }

    #[test]
    fn velocity_plan_to_zero_stops() {
        let mut p = Planner::new(0.001);
        let from = Kinematics {
            position: 0.0,
            velocity: 80.0,
            acceleration: 300.0,
            jerk: 0.0,
        };
        p.plan_velocity(from, 0.0, &LIM).unwrap();
        let ks = run(&mut p, 0.001);
        let last = ks.last().unwrap();
        assert!(last.velocity.abs() < 1e-9 && last.acceleration.abs() < 1e-9);
        // The prediction of the closed form stop agrees roughly (it assumes the same limits).
        let sd = stop_distance(80.0, 300.0, 500.0, 10000.0);
        assert!(
            (sd - last.position).abs() / last.position < 0.05,
            "{sd} vs {}",
            last.position
        );
    }

    #[test]
    fn invalid_limits_are_rejected() {
        let mut p = Planner::new(0.001);
        let bad = Limits {
            jerk: f64::NAN,
            ..LIM
        };
        assert_eq!(
            p.plan_position(Kinematics::default(), 1.0, 0.0, &bad),
            Err(PlanError::InvalidInput)
        );
        let bad = Limits {
            velocity: 0.0,
            ..LIM
        };
        assert_eq!(
            p.plan_position(Kinematics::default(), 1.0, 0.0, &bad),
            Err(PlanError::InvalidInput)
        );
    }

    #[test]
    fn fallback_stop_respects_limits_and_stops() {
        for &(v, a) in &[
            (80.0, 0.0),
            (80.0, 400.0),
            (-60.0, -200.0),
            (5.0, -450.0),
            (-3.0, 100.0),
        ] {
            let mut r = StopRamp::new(
                Kinematics {
                    position: 0.0,
                    velocity: v,
                    acceleration: a,
                    jerk: 0.0,
                },
                500.0,
                10000.0,
            );
            let mut prev = Kinematics {
                position: 0.0,
                velocity: v,
                acceleration: a,
                jerk: 0.0,
            };
            let mut n = 0;
            while !r.finished() {
                let k = r.step(0.001);
                assert!(k.acceleration.abs() <= 500.0f64.max(a.abs()) + 1e-9);
                assert!(
                    (k.acceleration - prev.acceleration).abs() <= 10000.0 * 0.001 + 1e-9
                        || r.finished()
                );
                // never reverses
                assert!(k.velocity * v >= -1e-12, "reversed: {k:?}");
                prev = k;
                n += 1;
                assert!(n < 100_000);
            }
            let predicted = stop_distance(v, a, 500.0, 10000.0);
            assert!(
                (predicted.abs() - prev.position.abs()).abs()
                    < 0.02 * predicted.abs().max(0.01) + 0.01,
                "v {v} a {a}: {predicted} vs {}",
                prev.position
            );
        }
    }
}
