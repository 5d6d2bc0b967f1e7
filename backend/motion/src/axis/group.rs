//! The axis as a member of a coordinated-motion group (TF5420 §1.5): which group it is in,
//! whether that group is enabled (then single-axis motion is refused), and the group's
//! motion as the axis's setpoint source. The group (`crate::group`) is stepped before its
//! axes and hands each member its set point; the axis keeps every monitor of its own.

use super::*;

/// What the axis knows of its group.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct GroupLink {
    pub(super) group: Option<GroupId>,
    /// The group's enable is requested: single-axis motion commands are refused.
    pub(super) engaged: bool,
    /// The set point the group gave for this cycle.
    pub(super) set: Option<Kinematics>,
    /// The group stopped commanding in motion (MC_GroupDisable): brake on the axis's own
    /// fast-stop ramp in this cycle's step.
    pub(super) abandon: bool,
}

impl Axis {
    /// The group the axis belongs to and whether it is enabled.
    pub fn group_link(&self) -> (Option<GroupId>, bool) {
        (self.group.group, self.group.engaged)
    }

    pub(crate) fn set_group_link(&mut self, group: Option<GroupId>, engaged: bool) {
        self.wake();
        self.group.group = group;
        self.group.engaged = engaged && group.is_some();
    }

    /// In ErrorStop (the group's note 7).
    pub(crate) fn group_axis_error(&self) -> bool {
        self.mode == Mode::ErrorStop
    }

    /// Closed loop and standing, or already following the group (note 8).
    pub(crate) fn group_axis_ready(&self) -> bool {
        // An axis whose drive runs the profile cannot follow a path's set points.
        !self.config.drive_executed
            && self.mode == Mode::Enabled
            && (self.job.is_none() || self.group_axis_following())
            && self.status.power_status
    }

    pub(crate) fn group_axis_following(&self) -> bool {
        self.runs(JobKind::Group)
    }

    /// The group starts moving: the axis takes the path as its setpoint source. False when
    /// it cannot (not standing in Enabled).
    pub(crate) fn group_start(&mut self) -> bool {
        self.wake();
        if self.group_axis_following() {
            return true;
        }
        if self.mode != Mode::Enabled || self.job.is_some() || self.config.drive_executed {
            return false;
        }
        let mut job = Job::new(0, JobKind::Group);
        job.phase = Phase::Moving;
        self.job = Some(job);
        true
    }

    pub(crate) fn group_follow(&mut self, k: Kinematics) {
        self.wake();
        if self.group_axis_following() {
            self.group.set = Some(k);
        }
    }

    /// The path stands with nothing left: the axis stands, without a job.
    pub(crate) fn group_finish(&mut self) {
        self.wake();
        if self.group_axis_following() {
            self.job = None;
            // The path's last point, given this cycle, is where the axis stands.
            if let Some(k) = self.group.set.take() {
                self.set.position = k.position;
            }
            self.set.velocity = 0.0;
            self.set.acceleration = 0.0;
            self.set.jerk = 0.0;
        }
    }

    pub(crate) fn group_abandon(&mut self) {
        self.wake();
        if self.group_axis_following() {
            self.group.abandon = true;
        }
    }

    pub(crate) fn group_reset_axis(&mut self) {
        self.wake();
        self.group_reset = true;
    }

    /// MC_GroupReset has asked this axis to reset and its step has not run yet.
    pub(crate) fn group_reset_pending(&self) -> bool {
        self.group_reset
    }

    /// One cycle of the group's motion: the set point the group gave. Without one (the
    /// group gone, or disabled in motion) the axis brakes on its own fast-stop ramp.
    pub(super) fn step_group(&mut self, cx: &mut Ctx<'_, impl EventSink>, dt: f64) {
        match self.group.set.take() {
            Some(k) if !self.group.abandon => self.set = k,
            _ => {
                self.group.abandon = false;
                self.job = None;
                if self.set.velocity.abs() > EPS_V || self.set.acceleration.abs() > 0.0 {
                    let p = self.p();
                    let mut h = Job::new(0, JobKind::Halt);
                    h.dec = p.axis_fast_dec.max(p.axis_dec);
                    h.acc = h.dec;
                    h.jerk = p.axis_fast_jerk.max(p.axis_jerk);
                    h.velocity = self.set.velocity.abs().max(EPS_V);
                    self.start_job(cx, h);
                    // The ramp starts in this cycle (no cycle standing at speed).
                    if let Some(k) = self.planner.step(dt) {
                        self.set = k;
                    }
                }
            }
        }
    }

    /// MC_GroupReset's part on the axis: an axis in ErrorStop at rest is reset.
    pub(super) fn step_group_reset(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        if core::mem::take(&mut self.group_reset)
            && self.mode == Mode::ErrorStop
            && self.job.is_none()
        {
            self.reset(cx);
        }
    }

    /// A single-axis motion command while the group is enabled (§1.5, §10 item 25).
    pub(super) fn admit_to_group(&self) -> Result<(), ErrorId> {
        if self.group.engaged {
            return Err(ErrorId::AXIS_IN_GROUP);
        }
        Ok(())
    }
}
