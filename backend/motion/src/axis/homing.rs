//! MC_Home: direct, force/reset calibration, and the referencing sequence of spec §5.3
//! against the drive's reference cam and latch. Apart because the sequence is a state machine
//! of its own (phases, a latch armed and read across cycles) that runs inside one job.

use super::*;

#[derive(Clone, Copy, Debug, Default)]
pub(super) struct HomeSeq {
    pub(super) phase: HomingPhase,
    pub(super) reference: f64,
    pub(super) mode: ReferenceMode,
    pub(super) search_dir: f64,
    pub(super) search_velocity: f64,
    pub(super) sync_dir: f64,
    pub(super) sync_velocity: f64,
    pub(super) latched: Option<f64>,
    pub(super) cam_seen: bool,
    /// The sequence failed: stopping (still Homing), then the command reports this error.
    pub(super) failed: Option<ErrorId>,
}

impl Axis {
    pub(super) fn submit_home(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
        position: Option<f64>,
        mode: HomingMode,
        options: HomingOptions,
    ) -> Result<(), ErrorId> {
        if self.state() != AxisState::Standstill {
            return Err(ErrorId::AXIS_CANNOT_BE_STARTED);
        }
        let reference = position.unwrap_or(self.p().axis_encoder_homing_calib_value);
        if !reference.is_finite() {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        match mode {
            HomingMode::Direct => {
                // Like MC_SetPosition absolute: the actual position becomes `reference`.
                let shift = reference - self.act_pos;
                self.shift_coordinates(shift);
                if options.clear_position_lag {
                    self.set.position = self.act_pos;
                }
                self.set_position_offset = 0.0;
                self.homed = true;
                cx.report(id, DONE);
                Ok(())
            }
            HomingMode::ForceCalibration => {
                self.homed = true;
                cx.report(id, DONE);
                Ok(())
            }
            HomingMode::ResetCalibration => {
                self.homed = false;
                cx.report(id, DONE);
                Ok(())
            }
            HomingMode::DriveBased => {
                self.start_drive_home(cx, id, reference);
                Ok(())
            }
            HomingMode::Default if self.drive_executed() => {
                self.start_drive_home(cx, id, reference);
                Ok(())
            }
            HomingMode::Default => {
                let p = self.p();
                let dir_of =
                    |d: Option<Direction>, inv: bool, default: f64| -> Result<f64, ErrorId> {
                        match d {
                            None => Ok(if inv { -default } else { default }),
                            Some(Direction::Positive) => Ok(1.0),
                            Some(Direction::Negative) => Ok(-1.0),
                            Some(_) => Err(ErrorId::INVALID_MODE),
                        }
                    };
                let search_dir = dir_of(
                    options.search_direction,
                    p.axis_encoder_homing_inv_dir_cam_search,
                    1.0,
                )?;
                // ST_HomingOptions: an undefined SyncDirection searches positive, like an
                // undefined SearchDirection (#1074 inverts it).
                let sync_dir = dir_of(
                    options.sync_direction,
                    p.axis_encoder_homing_inv_dir_sync_search,
                    1.0,
                )?;
                let search_velocity = self.check_velocity(
                    options
                        .search_velocity
                        .unwrap_or(p.axis_calibration_velocity_forward),
                )?;
                let sync_velocity = self.check_velocity(
                    options
                        .sync_velocity
                        .unwrap_or(p.axis_calibration_velocity_backward),
                )?;
                let rm = match options.reference_mode {
                    Some(m) => m,
                    None => ReferenceMode::from_number(p.axis_encoder_reference_mode)
                        .ok_or(ErrorId::INVALID_MODE)?,
                };
                // The drive-latch modes take their reference from the cam edge met while
                // searching; they have no sync phase. Starting on the cam they leave it
                // against the search direction and search it again, so the latched edge is
                // the one a search from outside meets.
                let sync_dir = if is_drive_latch(rm) {
                    -search_dir
                } else {
                    sync_dir
                };
                self.check_feed_enable(search_dir)?;
                // Only a direction the run will travel must be free: the drive-latch modes go
                // against the search direction only when they start on the cam.
                if !is_drive_latch(rm) || self.prev_cam {
                    self.check_feed_enable(sync_dir)?;
                }
                // Spec §5.3.1: with the cam already active at the start, homing begins
                // directly at phase 3 (leave the cam). The cam as the drive reported it last.
                let phase = if self.prev_cam {
                    HomingPhase::LeaveCam
                } else {
                    HomingPhase::SearchCam
                };
                let mut j = Job::new(id, JobKind::Home);
                j.acc = p.axis_acc;
                j.dec = p.axis_dec;
                j.jerk = p.axis_jerk;
                j.home = HomeSeq {
                    phase,
                    reference,
                    mode: rm,
                    search_dir,
                    search_velocity,
                    sync_dir,
                    sync_velocity,
                    latched: None,
                    cam_seen: self.prev_cam,
                    failed: None,
                };
                self.homed = false;
                self.start_job(cx, j);
                Ok(())
            }
        }
    }

    /// The referencing sequence of spec §5.3 against the drive's cam and latch.
    pub(super) fn step_home(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        dt: f64,
        fb: &DriveFeedback,
    ) {
        let Some(mut job) = self.job else { return };
        let mut h = job.home;
        let cam = fb.reference_cam;
        let cam_rise = cam && !self.prev_cam;
        let cam_fall = !cam && self.prev_cam;
        let drive_latch = is_drive_latch(h.mode);
        let mut replan = false;
        let mut fail = None;
        if let Some(k) = self.planner.step(dt) {
            self.set = k;
            self.superposition.main_motion_sampled();
        }
        let stopped = self.planner.finished() && self.set.velocity.abs() <= EPS_V;
        // A limit switch ahead ends the sequence in every phase (no reference without it).
        let v = self.set.velocity;
        let limit_hit = (v > EPS_V && fb.limit_positive) || (v < -EPS_V && fb.limit_negative);
        if let Some(e) = h.failed {
            if stopped {
                job.home = HomeSeq {
                    phase: HomingPhase::Idle,
                    ..h
                };
                job.finish_error(cx, e);
                self.job = None;
                self.planner.clear();
                self.set.velocity = 0.0;
                self.set.acceleration = 0.0;
            }
            return;
        }
        match h.phase {
            HomingPhase::SearchCam => {
                if drive_latch {
                    let source = if matches!(
                        h.mode,
                        ReferenceMode::HardwareLatchPos | ReferenceMode::SoftDriveLatchPos
                    ) {
                        LatchSource::CamRising
                    } else {
                        LatchSource::CamFalling
                    };
                    if let Some(p) = self.poll_latch(source, fb) {
                        h.latched = Some(p);
                        h.phase = HomingPhase::SetPosition;
                        replan = true;
                    }
                } else if cam && (!h.cam_seen || cam_rise) {
                    h.cam_seen = true;
                    // Cam already active at the start: directly to phase 3.
                    h.phase = if self.set.velocity.abs() <= EPS_V {
                        HomingPhase::LeaveCam
                    } else {
                        HomingPhase::StopOnCam
                    };
                    replan = true;
                }
            }
            HomingPhase::StopOnCam => {
                if stopped {
                    if !cam {
                        fail = Some(ErrorId::HOMING_CAM_OVERRUN);
                    } else {
                        h.phase = HomingPhase::LeaveCam;
                        replan = true;
                    }
                }
            }
            HomingPhase::LeaveCam => {
                h.phase = HomingPhase::WaitCamFallingEdge;
            }
            HomingPhase::WaitCamFallingEdge => {
                if cam_fall || !cam {
                    match h.mode {
                        _ if drive_latch => {
                            // Off the cam it started on: search it again, latch armed.
                            h.phase = HomingPhase::SearchCam;
                            replan = true;
                        }
                        ReferenceMode::PlcCam => {
                            h.latched = Some(self.act_pos);
                            h.phase = HomingPhase::SetPosition;
                            replan = true;
                        }
                        _ => {
                            self.poll_latch(LatchSource::IndexPulse, fb);
                            h.phase = HomingPhase::WaitLatch;
                        }
                    }
                }
            }
            HomingPhase::WaitLatch => {
                if let Some(p) = self.poll_latch(LatchSource::IndexPulse, fb) {
                    h.latched = Some(p);
                    h.phase = HomingPhase::SetPosition;
                    replan = true;
                }
            }
            HomingPhase::SetPosition => {
                if stopped {
                    let latched = h.latched.unwrap_or(self.act_pos);
                    // actual = reference + distance travelled since the latch.
                    let shift = h.reference - latched;
                    self.shift_coordinates(shift);
                    self.set_position_offset = 0.0;
                    self.homed = true;
                    h.phase = HomingPhase::Idle;
                    job.home = h;
                    job.finish_done(cx);
                    self.job = None;
                    self.planner.clear();
                    self.set.velocity = 0.0;
                    self.set.acceleration = 0.0;
                    return;
                }
            }
            HomingPhase::Idle => {}
        }
        if limit_hit && h.phase != HomingPhase::SetPosition {
            // The switch is an end of travel: the axis stops on it in ErrorStop, with why
            // the run failed.
            let e = match h.phase {
                HomingPhase::SearchCam => ErrorId::HOMING_FAILED,
                HomingPhase::StopOnCam => ErrorId::HOMING_CAM_OVERRUN,
                _ => ErrorId::HOMING_SYNC_NOT_FOUND,
            };
            self.latch = None;
            job.home = HomeSeq {
                phase: HomingPhase::Idle,
                ..h
            };
            self.job = Some(job);
            self.enter_error(cx, e);
            return;
        }
        if let Some(e) = fail {
            self.latch = None;
            h.failed = Some(e);
            h.phase = HomingPhase::SetPosition;
            job.home = h;
            self.job = Some(job);
            self.plan_job_now();
            return;
        }
        job.home = h;
        self.job = Some(job);
        if replan {
            self.plan_job_now();
        }
    }

    /// Arms the drive's latch for `source` and returns the latched axis position once it
    /// fired. Arms only in a cycle in which the drive shows no latch, so a latch left valid
    /// from an earlier (aborted) run is never taken for this one: the drive drops it when it
    /// sees `latch_enable` false for a cycle.
    fn poll_latch(&mut self, source: LatchSource, fb: &DriveFeedback) -> Option<f64> {
        if self.latch != Some(source) {
            self.latch = if fb.latch_valid { None } else { Some(source) };
            return None;
        }
        if fb.latch_valid {
            self.latch = None;
            return Some(self.enc_k * fb.latch_position + self.offset + self.corrections.read);
        }
        None
    }
}

/// The reference modes whose reference is a cam edge latched by the drive (#1076 = 3, 4, 6, 7).
fn is_drive_latch(mode: ReferenceMode) -> bool {
    matches!(
        mode,
        ReferenceMode::HardwareLatchPos
            | ReferenceMode::HardwareLatchNeg
            | ReferenceMode::SoftDriveLatchPos
            | ReferenceMode::SoftDriveLatchNeg
    )
}
