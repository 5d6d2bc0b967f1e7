//! A job's plan: the one place where a job's kind, the override and its end velocity become a
//! planner call (position or velocity interface), so that every (re)plan — a start, an
//! override change, blending, a superposition ending, a homing phase — plans alike. A planner
//! failure stops the axis on the closed-form ramp and the job ends with PLANNING_FAILED.

use super::*;

impl Axis {
    /// (Re)plans the active job from the current set state. On a planner failure the axis
    /// stops on the closed-form ramp and the job reports PLANNING_FAILED.
    pub(super) fn plan_job_now(&mut self) -> bool {
        let ovr = self.override_ratio();
        let from = self.plan_origin();
        let velo_max = self.config.parameters.axis_velo_max;
        let Some(j) = self.job.as_mut() else {
            return true;
        };
        if self.config.drive_executed
            || j.kind == JobKind::DriveHome
            || self.drive.cmd.mode != crate::drive::ProfileMode::Off
        {
            // The drive plans it (a host-side axis's drive still in its homing mode: the job
            // is planned once it is back in the cyclic mode).
            return true;
        }
        j.planned_override = ovr;
        // Taking over an accelerating axis with a weak jerk would let the velocity run on
        // past the axis maximum while the acceleration is ramped down: use at least the jerk
        // that keeps it within AxisVeloMax.
        if from.acceleration * from.velocity > 0.0 {
            let room = (velo_max - from.velocity.abs()).max(velo_max * 1e-6);
            let needed = from.acceleration * from.acceleration / (2.0 * room);
            if needed > j.jerk {
                j.jerk = needed;
            }
        }
        let res = match j.kind {
            JobKind::Positioning { continuous } => {
                // End velocity (continuous moves, blending) is kept before override.
                let end = j.end_velocity * ovr;
                if ovr <= 0.0 {
                    self.planner.plan_velocity(from, 0.0, &j.limits(1.0))
                } else if continuous && j.past_target {
                    // Past the target (passed slower than the end velocity): run up to it.
                    self.planner
                        .plan_velocity(from, end, &j.limits_passing(1.0, end))
                } else {
                    let lim = j.limits_passing(ovr, end);
                    // Never away from the target to reach an end velocity: the best
                    // reachable one instead, with a warning.
                    let planned = self
                        .planner
                        .plan_position_towards(from, j.target, end, &lim)
                        .map(|reached| {
                            j.planned_end = reached / ovr;
                            if (reached - end).abs() > 1e-9 * (1.0 + end.abs()) {
                                j.warn = Some(ErrorId::END_VELOCITY_ADJUSTED);
                            }
                            0.0
                        });
                    let toward = sign(j.target - from.position);
                    if continuous && end != 0.0 && self.planner.overshoots(j.target, toward) {
                        // Too fast to pass the target at any end velocity without running
                        // past it and back: it passes the target in its motion and goes on
                        // to the end velocity from there (never back to run at it again).
                        j.past_target = true;
                        j.planned_end = j.end_velocity;
                        j.warn = Some(ErrorId::END_VELOCITY_ADJUSTED);
                        self.planner
                            .plan_velocity(from, end, &j.limits_passing(1.0, end))
                    } else {
                        planned
                    }
                }
            }
            JobKind::Velocity | JobKind::JogHeld { released: false } => {
                self.planner
                    .plan_velocity(from, j.direction * j.velocity * ovr, &j.limits(1.0))
            }
            JobKind::JogHeld { released: true } | JobKind::Halt => {
                self.planner.plan_velocity(from, 0.0, &j.limits(1.0))
            }
            JobKind::Home => {
                let h = j.home;
                let v = match h.phase {
                    HomingPhase::SearchCam => h.search_dir * h.search_velocity * ovr,
                    HomingPhase::LeaveCam | HomingPhase::WaitCamFallingEdge => {
                        h.sync_dir * h.sync_velocity * ovr
                    }
                    _ => 0.0,
                };
                self.planner.plan_velocity(
                    from,
                    v,
                    &Limits {
                        velocity: h.search_velocity.max(h.sync_velocity),
                        acceleration: j.acc,
                        deceleration: j.dec,
                        jerk: j.jerk,
                    },
                )
            }
            JobKind::Gear
            | JobKind::Torque
            | JobKind::External
            | JobKind::Group
            | JobKind::DriveHome => return true,
        };
        match res {
            Ok(_) => {
                let a = self.job.expect("planned above");
                let dir = sign(a.target - from.position);
                let blending =
                    a.kind == (JobKind::Positioning { continuous: false }) && a.end_velocity != 0.0;
                if blending && dir != 0.0 && self.planner.overshoots(a.target, dir) {
                    self.pass_target_to_successor(a.target, dir);
                }
                true
            }
            Err(_) => {
                let (dec, jerk) = (
                    j.dec.max(self.config.parameters.axis_dec),
                    j.jerk.max(self.config.parameters.axis_jerk),
                );
                self.planner.plan_fallback_stop(from, dec, jerk);
                j.kind = JobKind::Halt;
                j.options.ignore_position_monitoring = true;
                j.pending_error = Some(ErrorId::PLANNING_FAILED);
                false
            }
        }
    }
}
