//! MC_TrackConveyorBelt (TF5420 §4.1, §2.5): the group follows a conveyor axis.
//!
//! The conveyor's motion is a displacement `d` along the conveying direction `u` (the frame's
//! X in machine coordinates), superimposed on the path: a member's set point is
//! `path + shift + Σ u·d`. The path itself is planned and run as ever, in coordinates that
//! move with the conveyor, so blends, look-ahead and braking on the path stay what they are.
//!
//! `d` chases the conveyor's travel since the tracking became active (a position target that
//! moves): the chase is planned relative to the conveyor, as a jerk-limited move of the
//! difference to zero within the tracking's dynamics (the velocity limit is what the tracking
//! velocity leaves above the conveyor's). It is replanned only when the conveyor does not
//! move as predicted (a ramp, a jolt), so a steady conveyor costs one plan. InSync: within
//! the tolerance distance and able to match the velocity without leaving it (decision 146).
//!
//! A tracking that ends (another frame, a halt, a stop, an error) leaves: its displacement
//! brakes to rest along `u` and is then folded into `shift` (decision 147).

use super::*;
use crate::command::{ConveyorTracking, TrackingBehavior};
use crate::planner::{Planner, stop_distance};

/// Tracking components braking to rest at most at once (each a conveyor left while its
/// displacement still moved).
pub(super) const MAX_LEAVING: usize = 4;

/// The active tracking.
#[derive(Debug)]
pub(super) struct Tracking {
    pub(super) id: CommandId,
    pub(super) out: FbOutputs,
    pub(super) conveyor: AxisSlot,
    /// The conveying direction in machine coordinates (unit, role dims X, Y, Z).
    pub(super) dir: [f64; 3],
    /// The conveyor's position when the tracking became active.
    c0: f64,
    /// The displacement along `dir` given last cycle.
    pub(super) d: Kinematics,
    limits: Limits,
    behavior: TrackingBehavior,
    tolerance: f64,
    /// The chase relative to the conveyor (its plan's last sample in `e`).
    pub(super) planner: Planner,
    e: Kinematics,
    planned: bool,
    /// The conveyor as last seen (a conveyor that is gone stands where it was).
    last: Kinematics,
    pub(super) conveyor_error: bool,
    pub(super) distance_to_sync: f64,
    pub(super) time_to_sync: f64,
}

/// A tracking that ended while its displacement moved: it brakes to rest.
#[derive(Debug)]
pub(super) struct Leaving {
    pub(super) dir: [f64; 3],
    pub(super) d: Kinematics,
    pub(super) planner: Planner,
}

impl Tracking {
    /// A tracking of the conveyor `seen` as it stands now, within `limits` (from
    /// [`Tracking::check`]), chasing with `planner`.
    pub(super) fn new(
        id: CommandId,
        t: &ConveyorTracking,
        (seen, limits): (Kinematics, Limits),
        planner: Planner,
    ) -> Tracking {
        Tracking {
            id,
            out: FbOutputs {
                busy: true,
                ..FbOutputs::default()
            },
            conveyor: t.conveyor,
            dir: t.transform.rotate([1.0, 0.0, 0.0]),
            c0: seen.position,
            d: Kinematics::default(),
            limits,
            behavior: t.behavior,
            tolerance: t.sync_tolerance,
            planner,
            e: Kinematics::default(),
            planned: false,
            last: seen,
            conveyor_error: false,
            distance_to_sync: 0.0,
            time_to_sync: 0.0,
        }
    }

    /// Checks MC_TrackConveyorBelt's inputs against the group and the conveyor as it is:
    /// the conveyor now and the tracking's dynamics.
    pub(super) fn check(
        t: &ConveyorTracking,
        config: &GroupConfig,
        members: &[Option<AxisSlot>; MAX_PATH_DIMS],
        axes: &[Option<Box<Axis>>],
    ) -> Result<(Kinematics, Limits), ErrorId> {
        if members.contains(&Some(t.conveyor)) {
            return Err(ErrorId::CONVEYOR_INVALID);
        }
        let Some(conveyor) = axes.get(t.conveyor as usize).and_then(|a| a.as_deref()) else {
            return Err(ErrorId::CONVEYOR_INVALID);
        };
        t.transform
            .check(config.convention.planar())
            .map_err(|_| ErrorId::PARAMETER_NOT_CORRECT)?;
        if t.initial_object_position.iter().any(|x| !x.is_finite())
            || !t.master_ref_position.is_finite()
            || !(t.sync_tolerance.is_finite() && t.sync_tolerance > 0.0)
        {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        let (d, m) = (config.default_dynamics, config.maximum_dynamics);
        let pick = |v: PathValue, def: f64, max: f64, min: f64| match v {
            PathValue::Default => Ok(def),
            PathValue::Maximum => Ok(max),
            // Not capped by the axes' maxima (§4.1), but bounded as path dynamics are.
            PathValue::Value(x) if x.is_finite() && x >= min && x <= 100.0 * max => Ok(x),
            _ => Err(ErrorId::TRACKING_DYNAMICS_INVALID),
        };
        let limits = Limits {
            velocity: pick(t.velocity, d.velocity, m.velocity, f64::MIN_POSITIVE)?,
            acceleration: pick(t.acceleration, d.acceleration, m.acceleration, 1.0)?,
            deceleration: pick(t.deceleration, d.deceleration, m.deceleration, 1.0)?,
            jerk: pick(t.jerk, d.jerk, m.jerk, 100.0)?,
        };
        // Its travel counts from where its last step left it (the tracking's first step
        // follows the conveyor's next).
        let c = conveyor_seen(conveyor);
        // §11: the tracking velocity must exceed the conveyor's.
        if limits.velocity <= c.velocity.abs() {
            return Err(ErrorId::TRACKING_DYNAMICS_INVALID);
        }
        Ok((c, limits))
    }

    /// The frame later MovePaths are read in: the conveyor frame shifted to the object as it
    /// lies in the moving frame — its detected position plus the conveyor's travel from the
    /// latch to the activation (the travel after it is the frame's own motion).
    pub(super) fn object_frame(&self, t: &ConveyorTracking) -> CoordTransform {
        let mut o = t.initial_object_position;
        o[0] += self.c0 - t.master_ref_position;
        CoordTransform {
            translation: t.transform.apply(o),
            rotation: t.transform.rotation,
        }
    }

    /// Takes over the motion of the tracking it replaces when both convey the same way (a
    /// second MC_TrackConveyorBelt switches directly, §4.1): the displacement's velocity and
    /// acceleration carry on, its position goes into `shift`. Returns the position folded.
    pub(super) fn take_over(&mut self, old: &Tracking) -> Option<f64> {
        let parallel = crate::path::vector::dot(&self.dir, &old.dir) > 1.0 - 1e-12;
        parallel.then(|| {
            self.d = Kinematics {
                position: 0.0,
                ..old.d
            };
            old.d.position
        })
    }

    /// One cycle: the displacement for this cycle and whether InSync changed.
    pub(super) fn step(&mut self, axes: &[Option<Box<Axis>>], dt: f64) -> Result<bool, ErrorId> {
        let conveyor = axes.get(self.conveyor as usize).and_then(|a| a.as_deref());
        // The conveyor as it stood after its last step, and as it will stand after this one
        // (the group steps before the axes: predicted at constant acceleration, so a steady
        // conveyor is followed without a cycle's lag).
        let (seen, now) = match conveyor {
            Some(a) => {
                self.conveyor_error = a.status().error_id != 0;
                (conveyor_seen(a), conveyor_now(a, dt))
            }
            None => {
                // Gone: it stands where it was last seen.
                self.conveyor_error = true;
                let k = Kinematics {
                    position: self.last.position,
                    ..Kinematics::default()
                };
                (k, k)
            }
        };
        self.last = now;
        let in_sync_before = self.out.in_sync;
        // StayInSync: once the chase has arrived, the conveyor is followed whatever it does.
        if self.behavior == TrackingBehavior::StayInSync
            && in_sync_before
            && self.e == Kinematics::default()
        {
            self.d = Kinematics {
                position: now.position - self.c0,
                ..now
            };
            self.distance_to_sync = 0.0;
            self.time_to_sync = 0.0;
            return Ok(false);
        }
        // The chase is planned relative to a frame that moves with the conveyor at its
        // acceleration — as far as the tracking may follow it (a conveyor that speeds up
        // harder is not followed harder: the group lags, InSync falls, decision 146).
        let l = self.limits;
        let sgn = if seen.velocity < 0.0 { -1.0 } else { 1.0 };
        let (up, down) = (sgn * l.acceleration, -sgn * l.deceleration);
        let (hi, lo) = (up.max(down), up.min(down));
        let a_frame = seen.acceleration.clamp(0.9 * lo, 0.9 * hi);
        let was = Kinematics {
            position: seen.position - self.c0,
            velocity: seen.velocity,
            acceleration: a_frame,
            jerk: 0.0,
        };
        let goal = Kinematics {
            position: was.position + seen.velocity * dt + 0.5 * a_frame * dt * dt,
            velocity: seen.velocity + a_frame * dt,
            acceleration: a_frame,
            jerk: 0.0,
        };
        // Where the displacement stood relative to that frame; a difference from the plan
        // means the conveyor did not move as predicted: plan again from there.
        let e = Kinematics {
            position: self.d.position - was.position,
            velocity: self.d.velocity - was.velocity,
            acceleration: self.d.acceleration - was.acceleration,
            jerk: 0.0,
        };
        let scale = 1.0 + self.d.position.abs();
        let off = (e.position - self.e.position).abs() > 1e-9 * scale
            || (e.velocity - self.e.velocity).abs() > 1e-9 * (1.0 + self.d.velocity.abs())
            || (e.acceleration - self.e.acceleration).abs() > 1e-6 * (1.0 + l.acceleration);
        if off || !self.planned {
            let at_rest = e.position.abs() <= 1e-12 * scale
                && e.velocity.abs() <= 1e-12
                && e.acceleration.abs() <= 1e-9;
            if at_rest {
                self.planner.clear();
            } else {
                // Within the group's motion's limits: what the tracking velocity leaves
                // above the conveyor's, and its acceleration (deceleration) less the
                // frame's.
                self.planner
                    .plan_signed(
                        false,
                        e,
                        0.0,
                        0.0,
                        (l.velocity - goal.velocity.abs()).max(1e-6 * l.velocity),
                        hi - a_frame,
                        lo - a_frame,
                        l.jerk,
                    )
                    .map_err(|_| ErrorId::TRACKING_DYNAMICS_INVALID)?;
            }
            self.planned = true;
        }
        self.e = self.planner.step(dt).unwrap_or_default();
        self.d = Kinematics {
            position: goal.position + self.e.position,
            velocity: goal.velocity + self.e.velocity,
            acceleration: goal.acceleration + self.e.acceleration,
            jerk: 0.0,
        };
        // InSync: within the tolerance and able to match the conveyor's velocity without
        // leaving it.
        let reach = stop_distance(
            self.e.velocity,
            self.e.acceleration,
            self.limits.deceleration,
            self.limits.jerk,
        );
        let drift = if self.e.velocity * self.e.position > 0.0 {
            self.e.position.abs() + reach
        } else {
            self.e.position.abs().max(reach - self.e.position.abs())
        };
        let in_sync = drift <= self.tolerance
            || (self.behavior == TrackingBehavior::StayInSync && in_sync_before);
        self.distance_to_sync = self.e.position.abs();
        self.time_to_sync = if in_sync {
            0.0
        } else {
            self.planner.remaining_time()
        };
        self.out.in_sync = in_sync;
        Ok(in_sync != in_sync_before)
    }

    /// The tracking ends: its displacement brakes to rest with `dec` and `jerk` (its
    /// planner goes with it).
    pub(super) fn leave(self, dec: f64, jerk: f64) -> Leaving {
        let mut planner = self.planner;
        let lim = Limits {
            velocity: self.d.velocity.abs().max(1e-9),
            acceleration: dec,
            deceleration: dec,
            jerk,
        };
        if planner.plan_velocity(self.d, 0.0, &lim).is_err() {
            planner.plan_fallback_stop(self.d, dec, jerk);
        }
        Leaving {
            dir: self.dir,
            d: self.d,
            planner,
        }
    }

    /// Deceleration and jerk the tracking brakes with.
    pub(super) fn braking(&self) -> (f64, f64) {
        (self.limits.deceleration, self.limits.jerk)
    }
}

impl Leaving {
    /// One cycle of the braking; true when at rest.
    pub(super) fn step(&mut self, dt: f64) -> bool {
        if let Some(k) = self.planner.step(dt) {
            self.d = k;
        }
        if self.planner.finished() {
            self.d.velocity = 0.0;
            self.d.acceleration = 0.0;
            return true;
        }
        false
    }
}

/// The conveyor as its last step left it.
fn conveyor_seen(a: &Axis) -> Kinematics {
    let s = a.status();
    Kinematics {
        position: s.set_position,
        velocity: s.set_velocity,
        acceleration: s.set_acceleration,
        jerk: 0.0,
    }
}

/// The conveyor after this cycle's step, predicted at constant acceleration.
fn conveyor_now(a: &Axis, dt: f64) -> Kinematics {
    let k = conveyor_seen(a);
    Kinematics {
        position: k.position + k.velocity * dt + 0.5 * k.acceleration * dt * dt,
        velocity: k.velocity + k.acceleration * dt,
        ..k
    }
}
