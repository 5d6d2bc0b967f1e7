//! Submitting a command (the rising edge of a fresh FB instance): the immediate verdict; the
//! commands that act on the axis itself at once — MC_Power, MC_Reset, MC_SetOverride,
//! MC_SetPosition, MC_WriteParameter, MC_Stop and its lock (note 6), the falling edge of
//! Execute/Enable, a jog's keepalive; and the dispatch of the others to their modules.
//!
//! Apart from the cycle because a submit acts at once (the state changes in the cycle the
//! command is accepted) and a rejected command must leave no trace: every check comes before
//! the first change.

use super::*;

/// The largest coordinate MC_SetPosition may make (1e15 units: an f64 still resolves 0.1 there).
pub const MAX_COORDINATE: f64 = 1e15;

impl Axis {
    /// Offers a command; the verdict is immediate and a rejected command changes nothing.
    pub fn submit(
        &mut self,
        cmd: Command,
        master: Option<(AxisSlot, MasterSample)>,
        cams: &crate::cam::CamStore,
        cycle: u64,
        events: &mut impl EventSink,
    ) -> Verdict {
        self.wake();
        let cx = &mut Ctx {
            slot: self.slot,
            cycle,
            events,
            cams,
        };
        match self.try_submit(cx, cmd, master.map(|(_, m)| m)) {
            Ok(()) => {
                self.settle_cam(cx);
                self.update_status();
                Verdict::Accepted
            }
            Err(e) => Verdict::Rejected(e),
        }
    }

    fn try_submit(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        cmd: Command,
        master: Option<MasterSample>,
    ) -> Result<(), ErrorId> {
        self.admit_on_drive(&cmd.kind)?;
        match cmd.kind {
            CommandKind::Power {
                enable,
                enable_positive,
                enable_negative,
                override_percent,
                buffer_mode,
            } => {
                if !(0.0..=100.0).contains(&override_percent) {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                self.power_override = override_percent;
                self.enable_positive = enable_positive;
                self.enable_negative = enable_negative;
                if let Some(mut old) = self.power.take() {
                    old.end(cx, End::Aborted);
                }
                let holds = Held::start(
                    cx,
                    cmd.id,
                    FbOutputs {
                        busy: true,
                        active: true,
                        status: self.status.power_status,
                        ..FbOutputs::default()
                    },
                );
                self.disable_when_idle = false;
                if enable {
                    if !self.enable {
                        self.power_on_timer = 0.0;
                    }
                    self.enable = true;
                    self.power_buffer_mode = buffer_mode;
                    self.power = Some(holds);
                } else if buffer_mode != BufferMode::Aborting && self.enable && self.executes_job()
                {
                    // §4.1.1: the enable is removed once the axis no longer executes a job;
                    // until then this command reports the enabled axis.
                    self.power = Some(holds);
                    self.disable_when_idle = true;
                } else {
                    self.power = Some(holds);
                    self.disable(cx);
                }
                Ok(())
            }
            CommandKind::Reset => {
                if self.mode == Mode::ErrorStop && self.job.is_some() {
                    // The axis is still on its error-stop ramp: the reset waits for standstill
                    // (no velocity step with the drive enabled); a newer reset replaces it.
                    if let Some(mut old) = self.pending_reset.take() {
                        old.end(cx, End::Aborted);
                    }
                    let held = Held::start(
                        cx,
                        cmd.id,
                        FbOutputs {
                            busy: true,
                            ..FbOutputs::default()
                        },
                    );
                    self.pending_reset = Some(held);
                    return Ok(());
                }
                self.reset(cx);
                cx.report(cmd.id, DONE);
                Ok(())
            }
            CommandKind::SetOverride {
                velocity_factor,
                acceleration_factor,
                jerk_factor,
            } => {
                let dyn_factor = |f: f64| f > 0.0 && f <= 1.0;
                if !(0.0..=1.0).contains(&velocity_factor)
                    || !dyn_factor(acceleration_factor)
                    || !dyn_factor(jerk_factor)
                {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                self.override_factor = velocity_factor;
                self.acc_factor = acceleration_factor;
                self.jerk_factor = jerk_factor;
                cx.report(cmd.id, DONE);
                Ok(())
            }
            CommandKind::OverrideFilter {
                raw,
                lower_threshold,
                upper_threshold,
                steps,
                recovery_time,
            } => {
                let percent = crate::functions::override_filter(
                    raw,
                    lower_threshold,
                    upper_threshold,
                    steps,
                )?;
                if !(recovery_time.is_finite() && recovery_time >= 0.0) {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                self.override_filter.queue(recovery_time, percent);
                self.step_override_filter();
                cx.report(cmd.id, DONE);
                Ok(())
            }
            CommandKind::SetPosition {
                position,
                relative,
                clear_position_lag,
                clear_position_offset,
            } => {
                // Undoing the accumulated offset is a relative shift by its opposite.
                let (position, relative) = if clear_position_offset {
                    (-self.set_position_offset, true)
                } else {
                    (position, relative)
                };
                if !position.is_finite() {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                let client_motion = self
                    .job
                    .is_some_and(|j| matches!(j.kind, JobKind::External | JobKind::Torque));
                match self.state() {
                    AxisState::Disabled | AxisState::Standstill | AxisState::ErrorStop => {}
                    // Not under samples a client feeds or a torque: their positions are the
                    // client's and the drive's, not ours to shift.
                    AxisState::DiscreteMotion | AxisState::ContinuousMotion
                        if relative && !client_motion => {}
                    _ => return Err(ErrorId::AXIS_CANNOT_BE_STARTED),
                }
                let shift = if relative {
                    position
                } else {
                    position - self.act_pos
                };
                // The new coordinates must stay where an f64 position still resolves the
                // motion (and finite): relative shifts could otherwise add up to infinity.
                let lands = |p: f64| (p + shift).abs() <= MAX_COORDINATE;
                if !(shift.is_finite() && lands(self.act_pos) && lands(self.set.position)) {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                self.shift_coordinates(shift);
                self.set_position_offset += shift;
                if clear_position_lag {
                    // set = actual; a running motion continues from there (re-planned, or
                    // the coupling re-based) so the next sample does not bring the lag back.
                    let d = self.act_pos - self.set.position;
                    self.set.position = self.act_pos;
                    self.sent_position = self.act_pos;
                    if let Some(c) = self.coupling.as_mut() {
                        c.law.shift_slave(d);
                    } else if self.job.is_some() {
                        self.plan_job_now();
                    }
                }
                cx.report(cmd.id, DONE);
                Ok(())
            }
            CommandKind::WriteParameter { number, value } => {
                // Checked here as well: a bad value must never reach an axis, whoever submits
                // it. #3000 AxisGearRatio is read-only like in the table: a ratio written
                // directly would step the slave's velocity; MC_GearInDyn changes it with a
                // limited acceleration.
                if let Some(factor) = self.encoder_scaling_written(number, value) {
                    // A new encoder scaling changes the reading (§4.5.9, absolute mode).
                    self.set_encoder_scaling(factor, false, (number, value))?;
                } else {
                    self.config.parameters.write(number, value)?;
                }
                cx.report(cmd.id, DONE);
                Ok(())
            }
            CommandKind::TorqueControl(tc) => {
                self.admit_to_external()?;
                self.submit_torque_control(cx, cmd.id, tc)
            }
            CommandKind::ExtSetPointGenEnable {
                target,
                relative,
                timeout,
            } => {
                self.submit_ext_enable(target, relative, timeout)?;
                cx.report(cmd.id, DONE);
                Ok(())
            }
            CommandKind::ExtSetPointGenDisable => {
                self.submit_ext_disable(cx);
                cx.report(cmd.id, DONE);
                Ok(())
            }
            CommandKind::ExtSetPointGenFeed {
                position,
                velocity,
                acceleration,
                direction,
            } => self.submit_ext_feed(
                cx,
                cmd.id,
                Kinematics {
                    position,
                    velocity,
                    acceleration,
                    jerk: 0.0,
                },
                direction,
            ),
            CommandKind::WriteDriveOperationMode { mode } => {
                self.submit_drive_mode(cx, cmd.id, mode)
            }
            CommandKind::SelectControlLoop { index } => {
                // The drive is the axis's one encoder, controller and drive: loop 0.
                if index != 0 {
                    return Err(ErrorId::CONTROL_LOOP_UNKNOWN);
                }
                cx.report(cmd.id, DONE);
                Ok(())
            }
            CommandKind::SetEncoderScalingFactor { factor, relative } => {
                self.set_encoder_scaling(factor, relative, (1040, factor))?;
                cx.report(cmd.id, DONE);
                Ok(())
            }
            CommandKind::Release { target } => self.release(cx, target),
            CommandKind::UpdateInputs {
                target,
                velocity,
                dynamics,
            } => {
                self.update_inputs(target, velocity, dynamics)?;
                cx.report(cmd.id, DONE);
                Ok(())
            }
            CommandKind::Keepalive { target } => {
                for j in [self.job.as_mut(), self.next.as_mut()]
                    .into_iter()
                    .flatten()
                {
                    if j.id == target {
                        j.since_keepalive = 0;
                        return Ok(());
                    }
                }
                Err(ErrorId::COMMAND_UNKNOWN)
            }
            CommandKind::Stop {
                deceleration,
                jerk,
                options,
            } => {
                if !deceleration.is_finite() || !jerk.is_finite() {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                match self.mode {
                    Mode::Disabled | Mode::ErrorStop => {
                        return Err(ErrorId::AXIS_CANNOT_BE_STARTED);
                    }
                    _ => {}
                }
                let (dec, jk) = self.stop_dynamics(deceleration, jerk);
                self.abort_all(cx);
                self.has_been_stopped = true;
                if let Some(mut old) = self.stop.take() {
                    old.end(cx, End::Aborted);
                }
                self.coupling = None;
                self.mode = Mode::Stopping;
                let held = Held::start(
                    cx,
                    cmd.id,
                    FbOutputs {
                        busy: true,
                        active: true,
                        ..FbOutputs::default()
                    },
                );
                self.stop = Some(held);
                let mut j = Job::new(0, JobKind::Halt);
                j.options = options;
                j.dec = dec;
                j.acc = dec.max(self.p().axis_acc);
                j.jerk = jk;
                j.velocity = self.set.velocity.abs().max(EPS_V);
                self.start_job(cx, j);
                Ok(())
            }
            CommandKind::GearOut => self.submit_gear_out(cx, cmd.id),
            CommandKind::GearInMultiMaster(g) => self.submit_gear_in_multi(cx, cmd.id, g),
            CommandKind::GearIn {
                master: master_slot,
                ratio_numerator,
                ratio_denominator,
            } => self.submit_gear_in(
                cx,
                cmd.id,
                master_slot,
                master,
                ratio_numerator,
                ratio_denominator,
            ),
            CommandKind::GearInDyn {
                master: master_slot,
                gear_ratio,
                acceleration,
            } => self.submit_gear_in_dyn(cx, cmd.id, master_slot, master, gear_ratio, acceleration),
            CommandKind::CamIn(ci) => self.submit_cam_in(cx, cmd.id, ci, master),
            CommandKind::CamOut => self.submit_cam_out(cx, cmd.id),
            CommandKind::CamScaling(sc) => self.submit_cam_scaling(cx, cmd.id, sc),
            CommandKind::CamInV2(op) => self.submit_cam_in_v2(cx, cmd.id, op, master),
            CommandKind::CamScalingV2(sc) => self.submit_cam_scaling_v2(cx, cmd.id, sc),
            CommandKind::MoveSuperImposed(sp) => self.submit_superposition(cx, cmd.id, sp),
            CommandKind::AbortSuperposition => {
                self.abort_superposition(cx);
                cx.report(cmd.id, DONE);
                Ok(())
            }
            CommandKind::TouchProbe(t) => self.submit_touch_probe(cx, cmd.id, t),
            kind @ (CommandKind::PositionCorrectionLimiter { .. }
            | CommandKind::BacklashCompensation { .. }
            | CommandKind::TableBasedPositionCompensation { .. }) => {
                self.submit_correction(cx, cmd.id, kind)
            }
            CommandKind::Phasing { master, motion } => {
                self.submit_phasing(cx, cmd.id, master, motion)
            }
            CommandKind::AbortTrigger => {
                self.abort_trigger(cx);
                cx.report(cmd.id, DONE);
                Ok(())
            }
            CommandKind::Home {
                position,
                mode,
                options,
            } => self.submit_home(cx, cmd.id, position, mode, options),
            _ => self.submit_motion(cx, cmd),
        }
    }

    /// Falling edge of Execute/Enable.
    pub(super) fn release(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        target: CommandId,
    ) -> Result<(), ErrorId> {
        if let Some(s) = self.stop.as_mut().filter(|s| s.id == target) {
            s.released = true;
            self.try_unlock(cx);
            return Ok(());
        }
        if self.release_correction(cx, target) {
            return Ok(());
        }
        if self.power.as_ref().is_some_and(|p| p.id == target) {
            if self.disable_when_idle {
                // The command is a disable already waiting for the job: its Enable is FALSE.
                return Ok(());
            }
            if self.power_buffer_mode != BufferMode::Aborting && self.executes_job() {
                self.disable_when_idle = true;
            } else {
                self.disable(cx);
            }
            return Ok(());
        }
        if let Some(c) = self
            .coupling
            .as_mut()
            .filter(|c| c.dyn_command == target && target != 0)
        {
            // Enable FALSE after coupling: the ratio freezes where it is, the slave stays coupled.
            c.dyn_command = 0;
            c.law.freeze();
            if let Some(j) = self.job.as_mut().filter(|j| j.id == target) {
                let out = FbOutputs {
                    busy: false,
                    active: false,
                    done: true,
                    in_gear: true,
                    ..j.out
                };
                j.emit(cx, out);
                j.id = 0;
            }
            return Ok(());
        }
        if let Some(j) = self.job.as_mut().filter(|j| j.id == target) {
            if let JobKind::JogHeld { released: false } = j.kind {
                // Button released: ramp down now.
                j.kind = JobKind::JogHeld { released: true };
                let out = FbOutputs {
                    in_velocity: false,
                    ..j.out
                };
                j.emit(cx, out);
                self.plan_job_now();
            }
            // Other Execute-type commands run on (§3.2).
            return Ok(());
        }
        if let Some(j) = self.next.as_mut().filter(|j| j.id == target) {
            if let JobKind::JogHeld { released } = &mut j.kind {
                *released = true;
            }
            return Ok(());
        }
        Err(ErrorId::COMMAND_UNKNOWN)
    }

    /// Note 6: MC_Stop done and released → Standstill.
    pub(super) fn try_unlock(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        if let Some(mut s) = self.stop {
            if s.released && s.out.done && self.job.is_none() {
                s.end(cx, End::Done);
                self.stop = None;
                if self.mode == Mode::Stopping {
                    self.mode = Mode::Enabled;
                }
            } else {
                self.stop = Some(s);
            }
        }
    }

    /// Aborts the running and the buffered job (CommandAborted).
    pub(super) fn abort_all(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        if let Some(mut n) = self.next.take() {
            n.finish_aborted(cx);
        }
        if let Some(mut j) = self.job.take() {
            j.finish_aborted(cx);
        }
        self.coupling = None;
        // The phase belongs to the coupling: a new one starts without a shift.
        self.end_phasing(cx, End::Aborted);
        self.phasing.clear_shift();
        self.cancel_cam_in(cx, End::Aborted);
        self.settle_cam(cx);
    }
}
