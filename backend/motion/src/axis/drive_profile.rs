//! Motion the drive executes (TwinCAT Drive Motion Control on the CiA-402 profile modes):
//! the axis keeps the PLCopen state machine and the FB output protocol, the drive runs the
//! ramp. A drive-executed axis (`AxisConfig::drive_executed`) takes the DMC blocks only —
//! Power, Reset, SetPosition, Home, Jog, Halt, MoveAbsolute, MoveRelative, MoveModulo,
//! MoveVelocity, Stop, TouchProbe, AbortTrigger — with DMC's inputs (no jerk, no buffer mode
//! but Aborting, no override); every other block is refused, never run host-side. A host-side
//! axis runs MC_Home with `HomingMode::DriveBased` here too (homing in the drive, then back to
//! its cyclic mode with the set position taken over).
//!
//! Each cycle the running job becomes a [`ProfileCommand`]: profile position for moves,
//! profile velocity for MoveVelocity and jog, homing for MC_Home; MC_Halt, MC_Stop and an
//! error stop set the drive's halt bit in the mode it runs in. The drive's mode changes only
//! at rest (a move of another mode first brakes the running one) and is taken as changed once
//! the drive reports it (0x6061). Done comes from the drive: a move after the set-point
//! handshake (acknowledge, then target reached), a velocity when the drive reports it,
//! homing when attained; the drive's following error and homing error are axis errors.

use super::*;
use crate::drive::{ProfileCommand, ProfileFeedback, ProfileMode};

/// How long a drive may take to show the profile mode asked for (0x6061) before the axis
/// stops with DRIVE_MODE_NOT_REACHED (a drive that does not have the mode never shows it).
const MODE_TIMEOUT: f64 = 1.0;

/// Cycles a drive needs to answer a changed command in its statusword: the setpoint leaves at
/// the end of cycle k, the drive takes it at its next SYNC0 and its status arrives one or two
/// exchanges later. Until then the status still answers the command before.
const ANSWER_CYCLES: u32 = 3;

/// The set-point handshake of a profile-position move (statusword bit 12, controlword bit 4).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) enum Handshake {
    /// Waiting until the drive takes a new set point (bit 12 low).
    #[default]
    WaitFree,
    /// New set point sent (bit 4 high) until the drive acknowledges it.
    Sent,
    /// Acknowledged: bit 4 low again; the drive runs the set point.
    Acked,
}

/// What is sent to a drive that runs the profile, and the handshake of the running job.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct DriveProfile {
    pub(super) cmd: ProfileCommand,
    /// Cycles since the command last changed in what the drive answers (mode, target,
    /// halt, start).
    pub(super) since_change: u32,
    pub(super) handshake: Handshake,
    /// Homing: the drive reported "in progress" (or an error) since the start, so an
    /// "attained" read now is this run's.
    pub(super) homing_seen_running: bool,
    /// How long the drive has not shown the mode asked for (s).
    pub(super) mode_wait: f64,
    /// Cycles bit 4 has been sent low, and cycles a set point has waited for its acknowledge.
    pub(super) start_low: u32,
    pub(super) sent_for: u32,
}

impl DriveProfile {
    fn set(&mut self, cmd: ProfileCommand) {
        let changed = cmd.mode != self.cmd.mode
            || cmd.target != self.cmd.target
            || cmd.halt != self.cmd.halt
            || cmd.start != self.cmd.start
            || cmd.velocity != self.cmd.velocity;
        self.cmd = cmd;
        if changed {
            self.since_change = 0;
        }
    }
}

impl Axis {
    /// The axis's drive runs the profile.
    pub(super) fn drive_executed(&self) -> bool {
        self.config.drive_executed
    }

    /// The blocks and inputs a drive-executed axis takes (DMC's set, §9 of its manual): a
    /// block Drive Motion Control does not have is refused with
    /// [`ErrorId::NOT_ON_DRIVE_EXECUTED_AXIS`], an input it does not have (jerk, a buffer mode
    /// other than Aborting, an override) with [`ErrorId::INPUT_NOT_ON_DRIVE_EXECUTED_AXIS`].
    pub(super) fn admit_on_drive(&self, kind: &CommandKind) -> Result<(), ErrorId> {
        if !self.drive_executed() {
            return Ok(());
        }
        let no_input = Err(ErrorId::INPUT_NOT_ON_DRIVE_EXECUTED_AXIS);
        let plain = |d: &Dynamics, b: BufferMode| d.jerk == 0.0 && b == BufferMode::Aborting;
        match kind {
            CommandKind::Power {
                override_percent, ..
            } if *override_percent != 100.0 => no_input,
            CommandKind::Power { .. }
            | CommandKind::Reset
            | CommandKind::SetPosition { .. }
            | CommandKind::WriteParameter { .. }
            | CommandKind::TouchProbe(_)
            | CommandKind::AbortTrigger
            | CommandKind::Release { .. }
            | CommandKind::Keepalive { .. }
            | CommandKind::UpdateInputs { .. } => Ok(()),
            CommandKind::MoveAbsolute(m)
            | CommandKind::MoveRelative(m)
            | CommandKind::MoveModulo { move_: m, .. } => {
                if plain(&m.dynamics, m.buffer_mode) {
                    Ok(())
                } else {
                    no_input
                }
            }
            CommandKind::MoveVelocity {
                dynamics,
                buffer_mode,
                ..
            } => {
                if plain(dynamics, *buffer_mode) {
                    Ok(())
                } else {
                    no_input
                }
            }
            CommandKind::Halt {
                jerk, buffer_mode, ..
            } => {
                if *jerk == 0.0 && *buffer_mode == BufferMode::Aborting {
                    Ok(())
                } else {
                    no_input
                }
            }
            CommandKind::Stop { jerk, .. } => {
                if *jerk == 0.0 {
                    Ok(())
                } else {
                    no_input
                }
            }
            // DMC's jog runs while the key is held; inching is MC2's.
            CommandKind::Jog { mode, dynamics, .. } => match mode {
                JogMode::Inching | JogMode::InchingModulo => {
                    Err(ErrorId::NOT_ON_DRIVE_EXECUTED_AXIS)
                }
                _ if dynamics.jerk != 0.0 => no_input,
                _ => Ok(()),
            },
            CommandKind::Home { mode, .. } => match mode {
                HomingMode::Default
                | HomingMode::DriveBased
                | HomingMode::Direct
                | HomingMode::ForceCalibration
                | HomingMode::ResetCalibration => Ok(()),
            },
            _ => Err(ErrorId::NOT_ON_DRIVE_EXECUTED_AXIS),
        }
    }

    /// MC_Home in the drive: a job that switches the drive to homing, starts its method and
    /// ends when the drive reports homing attained; the axis then reads `reference` there.
    pub(super) fn start_drive_home(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
        reference: f64,
    ) {
        let p = self.p();
        let mut j = Job::new(id, JobKind::DriveHome);
        j.acc = p.axis_acc;
        j.dec = p.axis_dec;
        j.velocity = p.axis_calibration_velocity_forward;
        j.target = reference;
        self.homed = false;
        self.start_job(cx, j);
    }

    /// A job starts on a drive that runs the profile: its handshake starts over.
    pub(super) fn drive_job_started(&mut self) {
        self.drive.handshake = Handshake::WaitFree;
        self.drive.homing_seen_running = false;
        self.drive.since_change = 0;
    }

    /// The profile mode a job runs in (`None`: it keeps the drive's, e.g. a halt).
    fn job_profile_mode(kind: JobKind) -> Option<ProfileMode> {
        match kind {
            JobKind::Positioning { .. } => Some(ProfileMode::Position),
            JobKind::Velocity | JobKind::JogHeld { released: false } => Some(ProfileMode::Velocity),
            JobKind::DriveHome => Some(ProfileMode::Homing),
            _ => None,
        }
    }

    /// The drive stands: it says so under a halt (bit 10: velocity 0) or at the end of a
    /// profile-position or homing run, or its reported velocity is below a ten-thousandth of
    /// the axis's maximum.
    fn drive_at_rest(&self, pf: ProfileFeedback, answered: bool) -> bool {
        let says = answered
            && pf.target_reached
            && (self.drive.cmd.halt || pf.mode != ProfileMode::Velocity);
        says || self.act_vel.abs() <= self.p().axis_velo_max * 1e-4
    }

    /// While the drive runs the profile the set values are its actual ones, and the lag is the
    /// drive's own (it reports it, bit 13): what the drive answers is its own position, also
    /// where homing moved it. Counts the cycles since the last profile command changed.
    fn follow_the_drive(&mut self) {
        self.set = Kinematics {
            position: self.act_pos,
            velocity: self.act_vel,
            acceleration: self.act_acc,
            jerk: 0.0,
        };
        self.sent_position = self.act_pos;
        self.drive.since_change = self.drive.since_change.saturating_add(1);
    }

    /// A host-side axis whose drive still runs its homing mode (the homing ended by a stop,
    /// an error or a homing error): the drive brakes by itself with the halt bit, and the
    /// axis goes back to its cyclic mode once it stands, the set position taken over there.
    /// True while it is still returning.
    pub(super) fn step_drive_return(&mut self, fb: &DriveFeedback) -> bool {
        self.follow_the_drive();
        let pf = fb.profile;
        let answered = pf.mode == self.drive.cmd.mode && self.drive.since_change >= ANSWER_CYCLES;
        if !self.drive_at_rest(pf, answered) && fb.enabled {
            self.drive.set(ProfileCommand {
                halt: true,
                start: false,
                ..self.drive.cmd
            });
            return true;
        }
        self.drive.set(ProfileCommand::default());
        self.set = Kinematics {
            position: self.act_pos,
            ..Kinematics::default()
        };
        self.sent_position = self.act_pos;
        false
    }

    /// One cycle of a job the drive runs (instead of the planner), and of a drive-executed
    /// axis without a job. The set values are the drive's actual ones.
    pub(super) fn step_drive_job(&mut self, cx: &mut Ctx<'_, impl EventSink>, fb: &DriveFeedback) {
        self.follow_the_drive();
        // How long the drive has seen bit 4 low: a new set point needs a rising edge it sees.
        self.drive.start_low = if self.drive.cmd.start {
            0
        } else {
            self.drive.start_low.saturating_add(1)
        };
        let pf = fb.profile;
        let in_mode = pf.mode == self.drive.cmd.mode;
        let answered = in_mode && self.drive.since_change >= ANSWER_CYCLES;
        let commanding = matches!(self.mode, Mode::Enabled | Mode::Stopping);
        if fb.enabled && self.drive.cmd.mode != ProfileMode::Off && !in_mode && commanding {
            self.drive.mode_wait += self.cycle_time;
            if self.drive.mode_wait > MODE_TIMEOUT {
                // Ask for the mode the drive is in (or profile position), so that a reset
                // does not run into the same timeout at once.
                self.drive.mode_wait = 0.0;
                self.drive.cmd.mode = match pf.mode {
                    ProfileMode::Off if self.drive_executed() => ProfileMode::Position,
                    m => m,
                };
                self.enter_error(cx, ErrorId::DRIVE_MODE_NOT_REACHED);
                return;
            }
        } else {
            self.drive.mode_wait = 0.0;
        }
        // The drive's following error (bit 13 in profile position), whenever it shows.
        if pf.error && pf.mode == ProfileMode::Position && in_mode && commanding {
            self.enter_error(cx, ErrorId::FOLLOWING_ERROR);
            return;
        }
        if self.drive_executed() && commanding && self.drive_soft_limit(cx) {
            return;
        }
        let at_rest = self.drive_at_rest(pf, answered);
        let Some(mut job) = self.job else {
            // At rest in the mode it is in (profile position by default; homing once it
            // stands): nothing started. A halt stays set until the next job: releasing it
            // would resume the set point the drive was halted on (CiA-402 profile position
            // resumes after a halt).
            let mode = match self.drive.cmd.mode {
                ProfileMode::Off => ProfileMode::Position,
                ProfileMode::Homing if at_rest => ProfileMode::Position,
                m => m,
            };
            self.drive.set(ProfileCommand {
                mode,
                target: if mode == ProfileMode::Position {
                    self.drive.cmd.target
                } else {
                    0.0
                },
                start: false,
                halt: mode != ProfileMode::Position || self.drive.cmd.halt,
                ..self.drive.cmd
            });
            return;
        };
        let dec = job.dec.max(1e-9);
        let wanted = Self::job_profile_mode(job.kind);
        let current = self.drive.cmd.mode;
        if let Some(mode) = wanted.filter(|&m| m != current) {
            // Modes change at rest only: brake in the mode the drive runs in (never weaker
            // than the motion it brakes), then switch.
            if at_rest || current == ProfileMode::Off {
                self.drive.set(ProfileCommand {
                    mode,
                    target: if mode == ProfileMode::Position {
                        self.act_pos
                    } else {
                        0.0
                    },
                    velocity: job.velocity,
                    acceleration: job.acc,
                    deceleration: dec,
                    start: false,
                    immediate: true,
                    halt: true,
                });
                self.drive.handshake = Handshake::WaitFree;
            } else {
                self.drive.set(ProfileCommand {
                    halt: true,
                    deceleration: dec.max(self.drive.cmd.deceleration),
                    start: false,
                    ..self.drive.cmd
                });
            }
            return;
        }
        match job.kind {
            JobKind::Positioning { .. } => {
                let hs = self.drive.handshake;
                let start = match hs {
                    Handshake::WaitFree => {
                        // The drive saw bit 4 low long enough, and its bit 12 (read after
                        // that) says it takes a new set point.
                        if in_mode && !pf.acknowledge && self.drive.start_low >= ANSWER_CYCLES {
                            self.drive.handshake = Handshake::Sent;
                            self.drive.sent_for = 0;
                            true
                        } else {
                            false
                        }
                    }
                    Handshake::Sent => {
                        self.drive.sent_for = self.drive.sent_for.saturating_add(1);
                        if in_mode && pf.acknowledge {
                            self.drive.handshake = Handshake::Acked;
                            false
                        } else if f64::from(self.drive.sent_for) * self.cycle_time > MODE_TIMEOUT {
                            self.enter_error(cx, ErrorId::DRIVE_SET_POINT_NOT_ACKNOWLEDGED);
                            return;
                        } else {
                            true
                        }
                    }
                    Handshake::Acked => false,
                };
                // Halted before (a stop, an error stop, a mode switch): the halt is released
                // with the new set point, not before (the drive would resume the old one).
                let halt = hs == Handshake::WaitFree && !start && self.drive.cmd.halt;
                self.drive.set(ProfileCommand {
                    mode: ProfileMode::Position,
                    target: job.target,
                    velocity: job.velocity,
                    acceleration: job.acc,
                    deceleration: dec,
                    start,
                    immediate: true,
                    halt,
                });
                if hs == Handshake::Acked && in_mode && pf.target_reached {
                    self.end_drive_job(cx, job, Ok(()));
                }
            }
            JobKind::Velocity | JobKind::JogHeld { released: false } => {
                let target = job.direction * job.velocity;
                self.drive.set(ProfileCommand {
                    mode: ProfileMode::Velocity,
                    target,
                    velocity: job.velocity,
                    acceleration: job.acc,
                    deceleration: dec,
                    start: false,
                    immediate: true,
                    halt: false,
                });
                // The drive's bit 10, and its velocity there (a status from before the new
                // target could still say reached).
                let reached = answered
                    && pf.target_reached
                    && (self.act_vel - target).abs() <= 0.01 * job.velocity.max(EPS_V);
                job.hold_velocity(cx, reached);
                self.job = Some(job);
            }
            JobKind::Halt | JobKind::JogHeld { released: true } => {
                let mode = match current {
                    ProfileMode::Off => ProfileMode::Position,
                    m => m,
                };
                self.drive.set(ProfileCommand {
                    mode,
                    halt: true,
                    start: false,
                    deceleration: dec,
                    ..self.drive.cmd
                });
                // A drive that does not run the mode asked for (it never switched) ends the
                // halt once it stands.
                let stood = if in_mode {
                    answered && pf.target_reached
                } else {
                    self.drive.since_change >= ANSWER_CYCLES
                        && self.act_vel.abs() <= self.p().axis_velo_max * 1e-4
                };
                if stood {
                    // What the drive stands on is the target now (PP holds there after the
                    // halt is released).
                    self.drive.cmd.target = self.act_pos;
                    self.end_drive_job(cx, job, Ok(()));
                }
            }
            JobKind::DriveHome => {
                self.drive.set(ProfileCommand {
                    mode: ProfileMode::Homing,
                    target: 0.0,
                    velocity: job.velocity,
                    acceleration: job.acc,
                    deceleration: dec,
                    start: in_mode,
                    immediate: false,
                    halt: false,
                });
                if !in_mode {
                    return;
                }
                let attained = pf.acknowledge && pf.target_reached && !pf.error;
                if !attained && self.drive.since_change >= 1 {
                    self.drive.homing_seen_running = true;
                }
                if pf.error && answered {
                    self.end_drive_job(cx, job, Err(ErrorId::DRIVE_HOMING_ERROR));
                } else if attained && (self.drive.homing_seen_running || answered) {
                    // The drive stands on its home position: the axis reads the reference
                    // there (the drive's home offset 0x607C is left at 0, decision 168).
                    let shift = job.target - self.act_pos;
                    self.shift_coordinates(shift);
                    self.set_position_offset = 0.0;
                    self.homed = true;
                    self.set.position = self.act_pos;
                    self.drive.cmd.target = self.act_pos;
                    self.end_drive_job(cx, job, Ok(()));
                }
            }
            _ => {
                // Kinds a drive-executed axis is never given (refused at submit, and groups
                // do not take it).
                self.job = Some(job);
            }
        }
    }

    /// The software limits of an axis whose drive runs the profile (its set position is the
    /// drive's actual one, so motiond's own monitor cannot see what the drive plans): where
    /// the drive would stand if it braked now — at the deceleration it was given, after the
    /// cycles it takes to answer — lies beyond an enabled limit in the direction of travel.
    /// Endless motion (velocity, a held jog) stops there with its deceleration, ending with
    /// `soft_limit_reached`; anything else heading out (a move reversing a faster one, a
    /// weak halt) is an axis error, stopped with the fast ramp. True when it stopped.
    fn drive_soft_limit(&mut self, cx: &mut Ctx<'_, impl EventSink>) -> bool {
        let p = self.p();
        let v = self.act_vel;
        if v.abs() <= EPS_V {
            return false;
        }
        let limit = if v > 0.0 && p.axis_en_max_soft_pos_limit {
            p.axis_max_soft_pos_limit
        } else if v < 0.0 && p.axis_en_min_soft_pos_limit {
            p.axis_min_soft_pos_limit
        } else {
            return false;
        };
        let Some(job) = self.job else {
            return false;
        };
        let endless = matches!(
            job.kind,
            JobKind::Velocity | JobKind::JogHeld { released: false }
        );
        // A drive within its standstill band (as `drive_at_rest` takes it) under a job that
        // ends by itself heads nowhere: the creep a drive reports while it settles after
        // homing onto a limit is no motion out of the limits (a move off that limit was an
        // axis error at random, decision 172). Endless motion may be commanded that slowly:
        // it is watched at any speed.
        if !endless && v.abs() <= p.axis_velo_max * 1e-4 {
            return false;
        }
        let dec = self.drive.cmd.deceleration.max(job.dec).max(1e-9);
        let reach = v * v / (2.0 * dec) + v.abs() * self.cycle_time * f64::from(ANSWER_CYCLES + 1);
        if (limit - self.act_pos) * v.signum() > reach {
            return false;
        }
        match job.kind {
            _ if endless => {
                self.stop_internally(cx, ErrorId::SOFT_LIMIT_REACHED, false);
                true
            }
            // A move towards a target inside the limits brakes to it by itself.
            JobKind::Positioning { .. } if (job.target - self.act_pos) * v > 0.0 => false,
            JobKind::DriveHome => false,
            _ => {
                self.enter_error(cx, ErrorId::SOFT_LIMIT_REACHED);
                true
            }
        }
    }

    /// A drive job ends: Done (a halt's end also reports MC_Stop's Done) or an error. A
    /// host-side axis goes back to its cyclic mode once its drive stands
    /// (`step_drive_return`).
    fn end_drive_job(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        mut job: Job,
        result: Result<(), ErrorId>,
    ) {
        self.job = None;
        match result {
            Ok(()) => {
                if let Some(e) = job.pending_error {
                    job.finish_error(cx, e);
                } else {
                    job.finish_done(cx);
                }
                self.stop_ramp_ended(cx);
            }
            Err(e) => job.finish_error(cx, e),
        }
    }

    /// What the drive is sent this cycle for the profile it runs, in the drive's coordinates
    /// (without the axis's offset, through the encoder scaling) as the cyclic setpoint is.
    pub(super) fn profile_command(&self) -> ProfileCommand {
        if !self.drive_executed() && self.drive.cmd.mode == ProfileMode::Off {
            return ProfileCommand::default();
        }
        let c = self.drive.cmd;
        let k = self.enc_k;
        ProfileCommand {
            target: match c.mode {
                ProfileMode::Position => (c.target - self.offset) / k,
                ProfileMode::Velocity => c.target / k,
                _ => 0.0,
            },
            velocity: (c.velocity / k).abs(),
            acceleration: (c.acceleration / k).abs(),
            deceleration: (c.deceleration / k).abs(),
            ..c
        }
    }
}
