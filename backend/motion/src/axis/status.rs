//! The status snapshot (`AxisStatus`): everything a reader may ask, derived after every cycle
//! and every accepted submit, so that reading never computes and never disagrees with the
//! axis. The following-error peak hold counts cycles only (see `Axis::step`).

use super::*;

impl Axis {
    /// Starts a new following-error peak hold from the present following error.
    pub fn reset_following_error_peak(&mut self) {
        self.wake();
        self.beat.status_seq = self.beat.status_seq.wrapping_add(1);
        let s = &mut self.status;
        s.following_error_min = s.following_error;
        s.following_error_max = s.following_error;
    }

    pub(super) fn update_status(&mut self) {
        self.beat.status_seq = self.beat.status_seq.wrapping_add(1);
        let p = &self.config.parameters;
        let state = self.state();
        let s = &mut self.status;
        let set = self.set;
        s.state = state;
        s.set_position = set.position;
        s.set_velocity = set.velocity;
        s.set_acceleration = set.acceleration;
        s.set_jerk = set.jerk;
        s.actual_position = self.act_pos;
        s.actual_velocity = self.act_vel;
        s.actual_acceleration = self.act_acc;
        s.following_error = self.sent_position - self.act_pos;
        let period = p.axis_encoder_modulo_value;
        if self.config.modulo && period > 0.0 {
            s.modulo_set_position = set.position.rem_euclid(period);
            s.modulo_actual_position = self.act_pos.rem_euclid(period);
            s.modulo_set_turns = (set.position / period).floor() as i64;
        } else {
            s.modulo_set_position = set.position;
            s.modulo_actual_position = self.act_pos;
            s.modulo_set_turns = 0;
        }
        let job = self.job.as_ref();
        s.target_position = match job {
            Some(j) if j.is_positioning() => j.target,
            _ => set.position,
        };
        s.remaining_distance = (s.target_position - set.position).abs();
        s.remaining_time = if job.is_some() {
            self.planner.remaining_time()
        } else {
            0.0
        };
        s.override_percent = self.power_override * self.override_factor;
        s.power_override_percent = self.power_override;
        s.set_override_factor = self.override_factor;
        s.enable_positive = self.enable_positive;
        s.enable_negative = self.enable_negative;
        s.homed = self.homed;
        s.homing_phase = job
            .filter(|j| j.kind == JobKind::Home)
            .map(|j| j.home.phase)
            .unwrap_or_default();
        s.has_job = job.is_some();
        s.command_buffered = self.next.is_some();
        s.motion_commands_locked = self.stop.is_some();
        s.moving = set.velocity.abs() > EPS_V;
        s.moving_forward = set.velocity > EPS_V;
        s.moving_backward = set.velocity < -EPS_V;
        s.accelerating = s.moving && set.acceleration * set.velocity > 0.0;
        s.decelerating = s.moving && set.acceleration * set.velocity < 0.0;
        s.constant_velocity = s.moving && set.acceleration == 0.0;
        s.in_target_position = !s.moving
            && self.beat.in_window_timer + 1e-12 >= p.axis_target_position_monitoring_time
            && state != AxisState::Disabled;
        s.in_position_area =
            (self.act_pos - s.target_position).abs() <= p.axis_position_range_window;
        s.soft_limit_max_exceeded =
            p.axis_en_max_soft_pos_limit && set.position > p.axis_max_soft_pos_limit;
        s.soft_limit_min_exceeded =
            p.axis_en_min_soft_pos_limit && set.position < p.axis_min_soft_pos_limit;
        s.coupled = self.coupling.is_some();
        s.master = self.coupling.as_ref().map(|c| c.master);
        s.gear_ratio = self.coupling.as_ref().map(|c| c.law.ratio()).unwrap_or(0.0);
        // By reference: a coupling (a cam set) is large to copy every cycle.
        s.gear_ratios = match self.coupling.as_ref().map(|c| &c.law) {
            Some(coupling::CouplingLaw::Multi(m)) => m.ratios(),
            _ => [s.gear_ratio, 0.0, 0.0, 0.0],
        };
        s.error_id = if self.mode == Mode::ErrorStop {
            self.error.0
        } else {
            0
        };
        s.drive_fault = self.error == ErrorId::DRIVE_FAULT && self.mode == Mode::ErrorStop;
        s.drive_error_code = if s.drive_fault {
            self.drive_error_code
        } else {
            0
        };
        s.set_position_offset = self.set_position_offset;
        s.active_command = job.map(|j| j.id).unwrap_or(0);
        // The cam info changes only while a cam couples or something is queued; idle, it is
        // what it was when it became idle (the kept info or none).
        // Blocks marked idle (`idle.rs`) keep their part of the status as it is.
        let cam_idle = self.cam_set().is_none()
            && (self.idle(Idle::CAM) || (self.cam.nothing_queued() && self.cam.idle_info));
        let cam = if cam_idle {
            None
        } else {
            let idle_now = self.cam_set().is_none() && self.cam.nothing_queued();
            let (cam, queued, scaling) = self.cam_status();
            self.cam.idle_info = idle_now;
            // The kept info may change from now on: looked at again after the step.
            self.idle.forget(Idle::CAM);
            Some((self.cam.kept_info(cam), queued, scaling))
        };
        let phasing = (!self.idle(Idle::PHASING)).then(|| self.phasing_status());
        let position_correction = (!self.idle(Idle::CORRECTIONS)).then(|| self.correction_status());
        let op_modes = (!self.idle(Idle::CONFIG)).then(|| self.op_modes());
        let encoder_count = self.encoder_count();
        let (drive_mode, actual_torque, set_torque, velocity_limited) = self.torque_status();
        let torque_job = self.runs(JobKind::Torque);
        // Not `then_some`: an idle generator's line is not to be read at all.
        let ext = if self.idle(Idle::EXT) {
            None
        } else {
            Some(self.ext.enabled)
        };
        let ext_target = self.ext.target.filter(|_| ext == Some(true));
        let superposition = (!self.idle(Idle::SUPERPOSITION))
            .then(|| self.superposition.running.map(|x| x.applied));
        let s = &mut self.status;
        if let Some((active, absolute, covered)) = phasing {
            s.phasing_active = active;
            s.absolute_phase_shift = absolute;
            s.covered_phase_shift = covered;
        }
        if let Some(c) = position_correction {
            s.position_correction = c;
        }
        if let Some(running) = superposition {
            s.compensating = running.is_some();
            s.superimposed_distance = running.unwrap_or(0.0);
        }
        s.encoder_count = encoder_count;
        s.drive_operation_mode = drive_mode;
        s.actual_torque = actual_torque;
        s.set_torque = set_torque;
        s.torque_velocity_limited = velocity_limited;
        if let Some(enabled) = ext {
            s.ext_setpoint_gen_enabled = enabled;
        }
        if let Some(t) = ext_target {
            // §4.4.1: the position given to the enable is monitored, the axis does not go
            // there by itself.
            s.target_position = t;
            s.remaining_distance = (t - s.set_position).abs();
            s.in_target_position =
                s.in_target_position && s.remaining_distance <= p.axis_target_position_window;
        }
        if let Some(op_modes) = op_modes {
            s.encoder_scaling_factor = p.axis_encoder_scaling_factor;
            s.op_modes = op_modes;
        }
        s.operational = s.power_status && matches!(self.mode, Mode::Enabled | Mode::Stopping);
        // Torque control leaves the position loop open.
        s.control_loop_closed = s.operational && !torque_job;
        s.not_moving = !s.moving;
        s.has_been_stopped = self.has_been_stopped;
        s.homing_busy = state == AxisState::Homing;
        s.new_target_position =
            self.new_target && self.job.as_ref().is_some_and(|j| j.is_positioning());
        s.ptp_mode = !s.coupled;
        s.io_data_invalid = self.io_data_invalid;
        if let Some((cam, queued, scaling)) = cam {
            s.cam = cam;
            s.cam_table_queued = queued;
            s.cam_scaling_pending = scaling;
            s.cam_data_queued = cam.cam_data_queued;
        }
        #[cfg(debug_assertions)]
        self.check_idle();
    }

    /// The status's OpModes: the parameters that switch monitoring and modes on.
    pub(super) fn op_modes(&self) -> crate::status::AxisOpModes {
        let p = &self.config.parameters;
        crate::status::AxisOpModes {
            position_area_monitoring: p.axis_en_position_range_monitoring,
            target_position_monitoring: p.axis_en_target_position_monitoring,
            loop_mode: p.axis_en_looping_distance,
            motion_monitoring: p.axis_en_motion_monitoring,
            peh_time_monitoring: p.axis_en_in_target_timeout,
            modulo: self.config.modulo,
            position_lag_monitoring: p.axis_en_position_lag_monitoring,
            soft_limit_min_monitoring: p.axis_en_min_soft_pos_limit,
            soft_limit_max_monitoring: p.axis_en_max_soft_pos_limit,
            position_correction: p.axis_enable_pos_correction,
            allow_slave_commands: p.axis_allow_motion_cmd_to_slave_axis,
            allow_ext_set_axis_commands: p.axis_allow_motion_cmd_to_ext_set_axis,
        }
    }
}
