//! MC_TorqueControl (spec §5.7.1) and the drive's operation mode (§4.5.1, §4.5.7): the drive
//! runs in torque mode with a ramped torque setpoint while the load's velocity is kept within
//! limits by the drive; the set position follows the actual one, so any motion command (MC_Halt,
//! MC_Stop, a move) takes the axis back to position control from where it is and how fast it
//! goes. Apart from the planned motion because nothing is planned here: the drive's torque
//! moves the axis.

use super::*;
use crate::DriveMode;

/// How long a drive may take to report the operation mode asked for.
const MODE_SWITCH_TIMEOUT: f64 = 0.5;

/// The torque and mode side of an axis.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct TorqueState {
    /// The torque setpoint now (percent), ramping towards `target`.
    pub(super) set: f64,
    target: f64,
    ramp: f64,
    pub(super) limit_high: f64,
    pub(super) limit_low: f64,
    /// Seconds the running torque job has waited for the drive to report torque mode.
    waiting: f64,
    /// Seconds the drive has kept reporting torque mode with no torque control running.
    leaving: f64,
    /// MC_WriteDriveOperationMode waiting for the drive to report its mode.
    pending: Option<(Held, DriveMode, f64)>,
}

/// Whether a drive reporting `reported` runs `mode` (a drive that does not say is taken as
/// running the position-based mode it was configured for).
fn reports(reported: DriveMode, mode: DriveMode) -> bool {
    match mode {
        DriveMode::Configured => reported != DriveMode::Torque,
        m => reported == m || (reported == DriveMode::Configured && m == DriveMode::Position),
    }
}

impl TorqueState {
    /// No mode change is awaited or timed.
    pub(super) fn settled(&self) -> bool {
        self.pending.is_none() && self.leaving == 0.0
    }
}

impl Axis {
    /// The mode to ask the drive for.
    pub(super) fn drive_mode(&self, torque_job: bool) -> DriveMode {
        if torque_job {
            DriveMode::Torque
        } else {
            self.position_mode
        }
    }

    /// MC_TorqueControl: admission as a motion command (Aborting), the ramp from the torque
    /// the drive applies now (or the manual start value, or the running setpoint).
    pub(super) fn submit_torque_control(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
        tc: TorqueControl,
    ) -> Result<(), ErrorId> {
        let p = self.p();
        let bounded = |x: f64, m: f64| x.is_finite() && x.abs() <= m;
        if !(bounded(tc.torque, 1000.0)
            && tc.torque_ramp.is_finite()
            && tc.torque_ramp > 0.0
            && bounded(tc.velocity_limit_high, p.axis_velo_max)
            && bounded(tc.velocity_limit_low, p.axis_velo_max)
            && tc.velocity_limit_low <= tc.velocity_limit_high
            && tc.manual_start.is_none_or(|t| bounded(t, 1000.0)))
        {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        self.admit_motion(BufferMode::Aborting)?;
        let running = self.runs(JobKind::Torque);
        let start = match (running, tc.manual_start) {
            (true, _) => self.torque.set,
            (false, Some(t)) => t,
            (false, None) => self.actual_torque,
        };
        let base = if running { self.torque.target } else { start };
        let target = if tc.relative {
            base + tc.torque
        } else {
            tc.torque
        };
        if !bounded(target, 1000.0) {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        let mut job = Job::new(id, JobKind::Torque);
        job.buffer_mode = BufferMode::Aborting;
        job.velocity = tc
            .velocity_limit_high
            .abs()
            .max(tc.velocity_limit_low.abs());
        // A stop from torque control (a soft limit ahead) brakes with the axis's dynamics.
        job.acc = p.axis_acc;
        job.dec = p.axis_dec;
        job.jerk = p.axis_jerk;
        self.enqueue(cx, job)?;
        // Position control ends here: the set position is the actual one from now on.
        self.set = Kinematics {
            position: self.act_pos,
            velocity: self.act_vel,
            ..Kinematics::default()
        };
        self.planner.clear();
        let t = &mut self.torque;
        t.set = start;
        t.target = target;
        t.ramp = tc.torque_ramp;
        t.limit_high = tc.velocity_limit_high;
        t.limit_low = tc.velocity_limit_low;
        if !running {
            t.waiting = 0.0;
        }
        Ok(())
    }

    /// One cycle of torque control: the set position follows the actual one, the torque
    /// ramps, InTorque while the torque stands at its setpoint and the drive limits nothing;
    /// a drive that does not take torque mode ends the command (0x70B4).
    pub(super) fn step_torque(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        dt: f64,
        fb: &DriveFeedback,
    ) {
        // With the load's acceleration: a software limit's braking distance needs it.
        self.set = Kinematics {
            position: self.act_pos,
            velocity: self.act_vel,
            acceleration: self.act_acc,
            jerk: 0.0,
        };
        let t = &mut self.torque;
        if fb.mode == DriveMode::Torque {
            t.waiting = 0.0;
        } else {
            t.waiting += dt;
            if t.waiting > MODE_SWITCH_TIMEOUT {
                self.stop_internally(cx, ErrorId::DRIVE_MODE_NOT_REACHED, false);
                return;
            }
        }
        let step = t.ramp * dt;
        let d = t.target - t.set;
        t.set = if d.abs() <= step {
            t.target
        } else {
            t.set + step.copysign(d)
        };
        let in_torque = t.set == t.target && fb.mode == DriveMode::Torque && !fb.velocity_limited;
        if let Some(job) = self.job.as_mut().filter(|j| in_torque != j.out.in_torque) {
            let out = FbOutputs {
                in_torque,
                ..job.out
            };
            job.emit(cx, out);
        }
    }

    /// MC_WriteDriveOperationMode: a position-based mode (torque is MC_TorqueControl's, so a
    /// drive is never left in torque mode without a torque under control), at rest; Done once
    /// the drive reports it.
    pub(super) fn submit_drive_mode(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
        mode: DriveMode,
    ) -> Result<(), ErrorId> {
        if mode == DriveMode::Torque {
            return Err(ErrorId::INVALID_MODE);
        }
        let at_rest =
            self.job.is_none() && self.coupling.is_none() && self.set.velocity.abs() <= EPS_V;
        if !at_rest {
            return Err(ErrorId::AXIS_CANNOT_BE_STARTED);
        }
        if let Some((mut old, _, _)) = self.torque.pending.take() {
            old.end(cx, End::Aborted);
        }
        self.position_mode = mode;
        let held = Held::start_active(cx, id);
        self.torque.pending = Some((held, mode, 0.0));
        Ok(())
    }

    /// MC_WriteDriveOperationMode's end: the drive reports the mode (Done) or does not within
    /// the timeout (0x70B4).
    pub(super) fn step_drive_mode(&mut self, cx: &mut Ctx<'_, impl EventSink>, dt: f64) {
        // The manual's danger note (§5.7.1): a drive left in torque mode after torque control
        // moves unplanned. Asked back to its position mode, it must show it within the
        // timeout, or the axis goes to ErrorStop.
        let torque_job = self.runs(JobKind::Torque);
        if !torque_job
            && self.reported_mode == DriveMode::Torque
            && matches!(self.mode, Mode::Enabled | Mode::Stopping)
        {
            self.torque.leaving += dt;
            if self.torque.leaving > MODE_SWITCH_TIMEOUT {
                self.torque.leaving = 0.0;
                self.enter_error(cx, ErrorId::DRIVE_MODE_NOT_REACHED);
            }
        } else {
            self.torque.leaving = 0.0;
        }
        let Some((mut held, mode, waited)) = self.torque.pending.take() else {
            return;
        };
        if reports(self.reported_mode, mode) {
            held.end(cx, End::Done);
        } else if waited + dt > MODE_SWITCH_TIMEOUT {
            held.end(cx, End::Error(ErrorId::DRIVE_MODE_NOT_REACHED));
        } else {
            self.torque.pending = Some((held, mode, waited + dt));
        }
    }

    /// The torque part of the status: the mode the drive reports, its torque, the setpoint.
    pub(super) fn torque_status(&self) -> (DriveMode, f64, f64, bool) {
        let torque_job = self.runs(JobKind::Torque);
        (
            self.reported_mode,
            self.actual_torque,
            if torque_job { self.torque.set } else { 0.0 },
            torque_job && self.velocity_limited,
        )
    }
}
