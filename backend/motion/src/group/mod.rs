//! Coordinated-motion groups (TwinCAT TF5420 "CM group", spec `groups-tf5420.md`): several
//! axes moved together along a path of lines, arcs and corner blends.
//!
//! A group is a kernel object stepped in the same cycle as its axes, before them. It keeps
//! the group state machine (§1), the MovePath commands in flight and the path in motion
//! (`motion.rs`); each cycle it gives every member axis its set point, which the axis takes
//! as its setpoint source (as a cam slave takes its cam), so that every per-axis monitor
//! stays where it is. What the manual leaves open is decided in docs/decisions.md (123–).
//!
//! States (§1.1): Disabled, NotReady, Standby, Moving, Stopping, ErrorStop — the last with
//! the enable request telling GroupErrorEnabled from GroupErrorDisabled (§10 item 2).

pub mod analysis;
mod build;
pub mod config;
pub mod entry;
mod motion;
mod tracking;

pub use analysis::{PathAnalysis, PlannedSample, analyse_path};
pub use build::{AxisLimits, PathContext, PreparedPath, prepare_path};
pub use config::*;
pub use entry::*;

use serde::{Deserialize, Serialize};

use crate::axis::Axis;
use crate::command::{AxisSlot, BufferMode, CommandEvent, CommandId, CommandKind, EventSink};
use crate::command::{FbOutputs, Target, Verdict};
use crate::error::ErrorId;
use crate::path::{self, MAX_PATH_DIMS, PathPoint, Segment};
use crate::planner::{Kinematics, Limits, Planner};
use motion::{Item, ItemKind, PathRun, StepReport};
use tracking::{Leaving, MAX_LEAVING, Tracking};

/// `MC_GROUP_STATE` as motiond reports it.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GroupState {
    #[default]
    Disabled,
    NotReady,
    Standby,
    Moving,
    Stopping,
    ErrorStop,
}

/// What a group reports every cycle (`NcToPlc` of the group, MC_GroupReadStatus,
/// MC_GroupReadBlockerStatus, MC_GroupReadError).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GroupStatus {
    pub state: GroupState,
    /// `Flags.IsEnableRequested`.
    pub enable_requested: bool,
    /// `GroupErrorId` (0: none).
    pub error_id: u32,
    /// The member axis of each role ([X, Y, Z, C, ADDAX1..8]).
    pub members: [Option<AxisSlot>; MAX_PATH_DIMS],
    /// `GroupAxesCount`.
    pub axes_count: u8,
    /// `AllAxesStanding`: every member at v = 0 and a = 0.
    pub all_axes_standing: bool,
    /// Override asked for and in effect (`ActOverrideFactor`), 0…1.
    pub override_factor: f64,
    pub actual_override: f64,
    /// `PathVelo` and the path acceleration (after override).
    pub path_velocity: f64,
    pub path_acceleration: f64,
    /// Path length travelled since the group last stood idle.
    pub path_position: f64,
    /// The MovePath running and its entry (index in its table) and `InvokeId`.
    pub command: CommandId,
    pub entry_index: u32,
    pub invoke_id: u32,
    /// `IsInBlendingSegment`.
    pub in_blending_segment: bool,
    /// `RemainingCartesianDistanceActiveJob`, `RemainingTimeActiveJob`.
    pub remaining_distance: f64,
    pub remaining_time: f64,
    /// MC_GroupReadBlockerStatus: `Blocked`, `BlockerId`.
    pub blocked: bool,
    pub blocker_id: u32,
    /// Entries queued (running included).
    pub queued_entries: u32,
    /// The group's set point of every role (members' set positions).
    pub position: PathPoint,
    /// Where a MovePath appended now would start: the end of what is queued (the set point
    /// when nothing is). A path is prepared from it off the cycle thread.
    pub queue_end: PathPoint,
    /// The coordinate frame later MovePaths are read in.
    pub frame: CoordTransform,
    /// MovePaths committed as prepared off the cycle thread (the others were built in it).
    pub prepared_paths: u64,
    /// MC_TrackConveyorBelt: the conveyor followed and the command following it.
    pub conveyor: Option<AxisSlot>,
    pub tracking_command: CommandId,
    /// `InSync` of the tracking.
    pub in_sync: bool,
    /// The conveyor is in error or gone (the path goes on: the caller reacts, §4.1).
    pub conveyor_error: bool,
    /// `RemainingCartesianTimeToSync` (a distance) and `RemainingTimeToSync` (s).
    pub remaining_distance_to_sync: f64,
    pub remaining_time_to_sync: f64,
    /// The set point's motion along the conveyor (trackings still braking included).
    pub tracking_velocity: f64,
}

/// A MovePath in flight.
#[derive(Clone, Copy, Debug)]
struct PathCommand {
    id: CommandId,
    out: FbOutputs,
}

/// A halt or stop in progress.
#[derive(Clone, Copy, Debug)]
struct StopCommand {
    id: CommandId,
    out: FbOutputs,
    /// MC_GroupStop (locks until released) rather than MC_GroupHalt.
    locks: bool,
    /// At standstill (the stop's Done has been reported).
    standing: bool,
    /// Execute went FALSE (`Release`).
    released: bool,
}

/// Virtual corners an aborting blend tries (§7.3, decision 154).
const ABORT_CORNER_TRIES: usize = 8;

/// MovePaths a group keeps in flight at most.
const MAX_PATH_COMMANDS: usize = 64;

/// One CM group.
#[derive(Debug)]
pub struct Group {
    config: GroupConfig,
    id: crate::command::GroupId,
    cycle_time: f64,
    members: [Option<AxisSlot>; MAX_PATH_DIMS],
    enable_requested: bool,
    state: GroupState,
    error: ErrorId,
    run: PathRun,
    paths: [Option<PathCommand>; MAX_PATH_COMMANDS],
    stop: Option<StopCommand>,
    /// A MC_GroupReset asked while the error stop still moves: done at standstill.
    pending_reset: Option<CommandId>,
    /// Scratch for a MovePath's items before they are committed (capacity reserved).
    scratch: Vec<Item>,
    /// MovePaths committed as prepared off the cycle thread (the rest were built in it).
    prepared_taken: u64,
    /// An aborting MovePath accepted while the group moved: its entries, built from where
    /// the running path stops (capacity reserved).
    pending: Option<CommandId>,
    pending_entries: Vec<PathEntry>,
    pending_frame: CoordTransform,
    /// MC_SetCoordinateTransform: the frame later MovePaths are read in (cleared by a halt
    /// or a stop, §4.2).
    frame: CoordTransform,
    /// MC_TrackConveyorBelt: the tracking active, those braking to rest since they ended,
    /// the planners for them (made off the cycle thread), and what the displacements of
    /// those that ended left between the path's coordinates and the machine's (X, Y, Z;
    /// zero again once the group rests).
    track: Option<Tracking>,
    leaving: [Option<Leaving>; MAX_LEAVING],
    spare: Vec<Planner>,
    shift: [f64; 3],
    /// This cycle's conveyor offset of the set point (position, velocity, acceleration).
    offset: [[f64; 3]; 3],
    /// A MC_SetCoordinateTransform that detached a tracking: Done once it stands.
    frame_command: Option<CommandId>,
    status: GroupStatus,
}

impl Group {
    /// Built off the cycle thread (the queue's capacity is reserved here).
    pub fn new(config: GroupConfig, cycle_time: f64) -> Box<Group> {
        Box::new(Group {
            config,
            id: 0,
            cycle_time,
            members: [None; MAX_PATH_DIMS],
            enable_requested: false,
            state: GroupState::Disabled,
            error: ErrorId(0),
            run: PathRun::new(cycle_time, 2 * QUEUE_ENTRIES),
            paths: [None; MAX_PATH_COMMANDS],
            stop: None,
            pending_reset: None,
            scratch: Vec::with_capacity(2 * MAX_PATH_ENTRIES + 2),
            prepared_taken: 0,
            pending: None,
            pending_entries: Vec::with_capacity(MAX_PATH_ENTRIES),
            pending_frame: CoordTransform::default(),
            frame: CoordTransform::default(),
            track: None,
            leaving: Default::default(),
            spare: (0..=MAX_LEAVING)
                .map(|_| Planner::new(cycle_time))
                .collect(),
            shift: [0.0; 3],
            offset: [[0.0; 3]; 3],
            frame_command: None,
            status: GroupStatus {
                override_factor: 1.0,
                actual_override: 1.0,
                ..GroupStatus::default()
            },
        })
    }

    pub fn config(&self) -> &GroupConfig {
        &self.config
    }

    pub fn status(&self) -> &GroupStatus {
        &self.status
    }

    pub fn state(&self) -> GroupState {
        self.state
    }

    /// MovePaths whose items were taken as prepared off the cycle thread.
    pub fn prepared_paths_taken(&self) -> u64 {
        self.prepared_taken
    }

    /// The member axes (by role dimension).
    pub fn members(&self) -> &[Option<AxisSlot>; MAX_PATH_DIMS] {
        &self.members
    }

    pub fn id(&self) -> crate::command::GroupId {
        self.id
    }

    /// The axis in `slot` is gone: it is no member any more (a moving group stops with
    /// 0x8147 in its next step, an enabled one is NotReady).
    pub(crate) fn forget_member(&mut self, slot: AxisSlot) {
        for m in self.members.iter_mut() {
            if *m == Some(slot) {
                *m = None;
            }
        }
    }

    pub(crate) fn place(&mut self, id: crate::command::GroupId) {
        self.id = id;
    }

    /// Takes over the members of the group this one replaces (a configuration change of a
    /// disabled group keeps its axes where the new convention still has their roles).
    pub(crate) fn adopt_members(&mut self, old: &Group, axes: &mut [Option<Box<Axis>>]) {
        for role in GroupRole::ALL {
            let d = role.dim();
            if let Some(slot) = old.members[d] {
                if self.config.has_role(role) {
                    self.members[d] = Some(slot);
                } else if let Some(a) = axes.get_mut(slot as usize).and_then(|a| a.as_deref_mut()) {
                    a.set_group_link(None, false);
                }
            }
        }
    }

    fn event(
        &self,
        events: &mut impl EventSink,
        cycle: u64,
        command: CommandId,
        outputs: FbOutputs,
    ) {
        if command == 0 {
            return;
        }
        events.push(CommandEvent {
            cycle,
            command,
            target: Target::Group(self.id),
            outputs,
            result: None,
        });
    }

    /// An Execute-type administrative block that is done in the cycle it is accepted.
    fn done_at_once(&self, events: &mut impl EventSink, cycle: u64, id: CommandId) {
        self.event(events, cycle, id, busy());
        self.event(
            events,
            cycle,
            id,
            FbOutputs {
                done: true,
                ..FbOutputs::default()
            },
        );
    }

    /// The group's error reaction is running or over; new motion is refused until reset.
    pub fn in_error(&self) -> bool {
        self.state == GroupState::ErrorStop
    }

    /// Offers a command (not MovePath: [`Group::submit_path`]).
    pub(crate) fn submit(
        &mut self,
        id: CommandId,
        kind: CommandKind,
        axes: &mut [Option<Box<Axis>>],
        cycle: u64,
        events: &mut impl EventSink,
    ) -> Verdict {
        match self.try_submit(id, kind, axes, cycle, events) {
            Ok(()) => {
                self.update_status(axes);
                Verdict::Accepted
            }
            Err(e) => Verdict::Rejected(e),
        }
    }

    fn try_submit(
        &mut self,
        id: CommandId,
        kind: CommandKind,
        axes: &mut [Option<Box<Axis>>],
        cycle: u64,
        events: &mut impl EventSink,
    ) -> Result<(), ErrorId> {
        let disabled_flavour = matches!(self.state, GroupState::Disabled)
            || (self.state == GroupState::ErrorStop && !self.enable_requested);
        match kind {
            CommandKind::AddAxisToGroup { axis, role } => {
                if !disabled_flavour {
                    return Err(ErrorId::GROUP_STATE_INVALID);
                }
                if !self.config.has_role(role) {
                    return Err(ErrorId::GROUP_CONFIG_INVALID);
                }
                let d = role.dim();
                let Some(a) = axes.get(axis as usize).and_then(|a| a.as_deref()) else {
                    return Err(ErrorId::AXIS_UNKNOWN);
                };
                if a.config().drive_executed {
                    // Its drive runs the profile: it cannot follow a path's set points.
                    return Err(ErrorId::NOT_ON_DRIVE_EXECUTED_AXIS);
                }
                match a.group_link().0 {
                    Some(g) if g == self.id && self.members[d] == Some(axis) => {}
                    Some(_) => return Err(ErrorId::GROUP_CONFIG_INVALID),
                    None => {}
                }
                if self.members[d].is_some_and(|s| s != axis) {
                    return Err(ErrorId::GROUP_CONFIG_INVALID);
                }
                self.members[d] = Some(axis);
                if let Some(a) = axes.get_mut(axis as usize).and_then(|a| a.as_deref_mut()) {
                    a.set_group_link(Some(self.id), false);
                }
                self.done_at_once(events, cycle, id);
            }
            CommandKind::RemoveAxisFromGroup { role } => {
                if self.enable_requested {
                    return Err(ErrorId::GROUP_STATE_INVALID);
                }
                self.release_member(role.dim(), axes);
                self.done_at_once(events, cycle, id);
            }
            CommandKind::UngroupAllAxes => {
                self.disable(axes, cycle, events);
                for d in 0..MAX_PATH_DIMS {
                    self.release_member(d, axes);
                }
                self.done_at_once(events, cycle, id);
            }
            CommandKind::GroupEnable => {
                if self.state == GroupState::ErrorStop {
                    return Err(ErrorId::GROUP_STATE_INVALID);
                }
                if self.state == GroupState::Disabled {
                    let complete = self.config.roles().all(|r| self.members[r.dim()].is_some());
                    if !complete {
                        return Err(ErrorId::GROUP_CONFIG_INVALID);
                    }
                    self.enable_requested = true;
                    self.state = GroupState::NotReady;
                    self.for_members(axes, |a| {
                        let g = a.group_link().0;
                        a.set_group_link(g, true);
                    });
                    self.take_point(axes);
                }
                self.done_at_once(events, cycle, id);
            }
            CommandKind::GroupDisable => {
                self.disable(axes, cycle, events);
                self.done_at_once(events, cycle, id);
            }
            CommandKind::GroupReset => {
                if self.state == GroupState::ErrorStop {
                    if self.run.is_idle() {
                        self.reset(axes);
                    } else {
                        // The error stop still moves: reset at standstill.
                        if let Some(old) = self.pending_reset.replace(id) {
                            self.event(events, cycle, old, aborted());
                        }
                        self.event(events, cycle, id, busy());
                        return Ok(());
                    }
                }
                self.done_at_once(events, cycle, id);
            }
            CommandKind::GroupSetOverride { factor } => {
                if !factor.is_finite() {
                    return Err(ErrorId::PARAMETER_NOT_CORRECT);
                }
                self.run.k_target = factor.clamp(0.0, 1.0);
                self.done_at_once(events, cycle, id);
            }
            CommandKind::GroupHalt { deceleration, jerk }
            | CommandKind::GroupStop { deceleration, jerk } => {
                let locks = matches!(kind, CommandKind::GroupStop { .. });
                let (dec, jerk) = self.stop_dynamics(deceleration, jerk)?;
                self.start_stop(id, locks, dec, jerk, axes, cycle, events)?;
            }
            CommandKind::SetCoordinateTransform { transform } => {
                transform
                    .check(self.config.convention.planar())
                    .map_err(|_| ErrorId::PARAMETER_NOT_CORRECT)?;
                // For the MovePaths that follow (those already accepted keep theirs).
                self.frame = transform;
                if self.track.is_some() {
                    // A static frame detaches from the conveyor: Active while the tracking
                    // brakes to rest, Done when it stands (§4.1, decision 147).
                    self.detach(None, aborted(), cycle, events);
                    if let Some(old) = self.frame_command.replace(id) {
                        self.event(events, cycle, old, aborted());
                    }
                    self.event(
                        events,
                        cycle,
                        id,
                        FbOutputs {
                            busy: true,
                            active: true,
                            ..FbOutputs::default()
                        },
                    );
                } else {
                    self.done_at_once(events, cycle, id);
                }
            }
            CommandKind::TrackConveyorBelt(t) => {
                if !matches!(self.state, GroupState::Standby | GroupState::Moving) {
                    return Err(ErrorId::GROUP_STATE_INVALID);
                }
                // Room for this tracking to brake to rest one day, and for the one it
                // replaces to do so now.
                let free = self.leaving.iter().filter(|l| l.is_none()).count();
                let needed = 1 + usize::from(self.track.is_some());
                if free < needed {
                    return Err(ErrorId::GROUP_STATE_INVALID);
                }
                let checked = Tracking::check(&t, &self.config, &self.members, axes)?;
                let planner = self.spare.pop().ok_or(ErrorId::GROUP_STATE_INVALID)?;
                let mut new = Tracking::new(id, &t, checked, planner);
                // Accepted. A second tracking switches over directly (§4.1).
                if let Some(old) = self.track.take() {
                    self.event(events, cycle, old.id, aborted());
                    match new.take_over(&old) {
                        Some(folded) => {
                            for (i, s) in self.shift.iter_mut().enumerate() {
                                *s += old.dir[i] * folded;
                            }
                            self.spare.push(old.planner);
                        }
                        None => {
                            let (dec, jerk) = old.braking();
                            self.park(old.leave(dec, jerk));
                        }
                    }
                }
                self.frame = new.object_frame(&t);
                self.event(events, cycle, id, new.out);
                self.track = Some(new);
            }
            CommandKind::ReleaseBlocker { blocker_id } => {
                if blocker_id == 0 {
                    return Err(ErrorId::BLOCKER_ID_INVALID);
                }
                if !matches!(self.state, GroupState::Standby | GroupState::Moving) {
                    return Err(ErrorId::GROUP_STATE_INVALID);
                }
                // An unknown id is remembered nowhere: releasing a blocker that is not queued
                // is Done and changes nothing (decision 127).
                self.run.release_blocker(blocker_id);
                self.done_at_once(events, cycle, id);
            }
            CommandKind::Release { target } => {
                let Some(s) = self.stop.as_mut().filter(|s| s.id == target) else {
                    // Releasing a command that no longer holds anything is harmless.
                    return Ok(());
                };
                s.released = true;
                self.try_unlock(cycle, events);
            }
            _ => return Err(ErrorId::INVALID_MODE),
        }
        Ok(())
    }

    /// The frame moves: a conveyor is tracked, or a tracking that ended still brakes.
    fn frame_moves(&self) -> bool {
        self.track.is_some() || self.leaving.iter().any(Option::is_some)
    }

    /// `frame` as the path's coordinates read it (the displacements of trackings that
    /// ended lie between them and the machine's).
    fn build_frame(&self, frame: CoordTransform) -> CoordTransform {
        let mut f = frame;
        for (t, s) in f.translation.iter_mut().zip(self.shift) {
            *t -= s;
        }
        f
    }

    /// The frame a table left in effect becomes the group's. With trackings' displacements
    /// between the path and the machine the table had no frame entry (they are refused
    /// then): what it returns is the build frame, and the group's frame stays.
    fn take_frame(&mut self, frame: CoordTransform) {
        if self.shift == [0.0; 3] {
            self.frame = frame;
        }
    }

    /// The active tracking ends with `out` and brakes to rest (with `braking`, else its own
    /// deceleration and jerk).
    fn detach(
        &mut self,
        braking: Option<(f64, f64)>,
        out: FbOutputs,
        cycle: u64,
        events: &mut impl EventSink,
    ) {
        if let Some(t) = self.track.take() {
            self.event(events, cycle, t.id, out);
            let (dec, jerk) = braking.unwrap_or(t.braking());
            self.park(t.leave(dec, jerk));
        }
    }

    fn park(&mut self, l: Leaving) {
        // Room was checked when the tracking was accepted.
        if let Some(slot) = self.leaving.iter_mut().find(|s| s.is_none()) {
            *slot = Some(l);
        }
    }

    /// Trackings are gone at once (the group is disabled): the members stop on their own.
    fn drop_trackings(&mut self, cycle: u64, events: &mut impl EventSink) {
        if let Some(t) = self.track.take() {
            self.event(events, cycle, t.id, aborted());
            self.spare.push(t.planner);
        }
        for slot in self.leaving.iter_mut() {
            if let Some(l) = slot.take() {
                self.spare.push(l.planner);
            }
        }
        if let Some(c) = self.frame_command.take() {
            self.event(events, cycle, c, aborted());
        }
    }

    /// One cycle of the conveyor tracking and of those braking to rest: the offset of the
    /// members' set points (X, Y, Z), and the look-ahead that stops the group before the
    /// tracking carries a member beyond an enabled software limit.
    fn step_frame(&mut self, axes: &[Option<Box<Axis>>], cycle: u64, events: &mut impl EventSink) {
        let dt = self.cycle_time;
        let mut off = [self.shift, [0.0; 3], [0.0; 3]];
        let add = |off: &mut [[f64; 3]; 3], dir: [f64; 3], k: Kinematics| {
            for i in 0..3 {
                off[0][i] += dir[i] * k.position;
                off[1][i] += dir[i] * k.velocity;
                off[2][i] += dir[i] * k.acceleration;
            }
        };
        let mut report = None;
        let mut failed_with = None;
        if let Some(t) = self.track.as_mut() {
            let first = !t.out.active;
            t.out.active = true;
            match t.step(axes, dt) {
                Ok(changed) => {
                    if first || changed {
                        report = Some((t.id, t.out));
                    }
                    add(&mut off, t.dir, t.d);
                }
                Err(e) => failed_with = Some(e),
            }
        }
        if let Some((id, out)) = report {
            self.event(events, cycle, id, out);
        }
        if let Some(e) = failed_with {
            // It brakes from where it was (its displacement is added below, once).
            self.detach(None, failed(e), cycle, events);
        }
        for slot in self.leaving.iter_mut() {
            let Some(l) = slot.as_mut() else { continue };
            let at_rest = l.step(dt);
            add(&mut off, l.dir, l.d);
            if at_rest {
                for i in 0..3 {
                    self.shift[i] += l.dir[i] * l.d.position;
                }
                if let Some(l) = slot.take() {
                    self.spare.push(l.planner);
                }
            }
        }
        if self.leaving.iter().all(Option::is_none) {
            if let Some(c) = self.frame_command.take() {
                self.event(
                    events,
                    cycle,
                    c,
                    FbOutputs {
                        done: true,
                        ..FbOutputs::default()
                    },
                );
            }
        }
        self.offset = off;
        if self.state != GroupState::ErrorStop && self.tracking_beyond_limit(axes) {
            self.enter_error(ErrorId::PATH_BEYOND_SOFT_LIMIT, cycle, events);
        }
    }

    /// A tracked member could no longer stop short of an enabled software limit it heads
    /// for, braking both the path and the tracking (decision 148).
    fn tracking_beyond_limit(&self, axes: &[Option<Box<Axis>>]) -> bool {
        let Some(t) = self.track.as_ref() else {
            return false;
        };
        let (tdec, tjerk) = t.braking();
        let (pdec, pjerk) = self.front_dynamics();
        let dt = self.cycle_time;
        for d in 0..3 {
            let Some(a) = self.members[d]
                .and_then(|s| axes.get(s as usize))
                .and_then(|a| a.as_deref())
            else {
                continue;
            };
            let p = a.parameters();
            let pos = self.run.point[d] + self.offset[0][d];
            let v_track = t.dir[d] * t.d.velocity;
            let v = self.run.velocity[d] + self.offset[1][d];
            let limit = if v > 0.0 && p.axis_en_max_soft_pos_limit {
                p.axis_max_soft_pos_limit
            } else if v < 0.0 && p.axis_en_min_soft_pos_limit {
                p.axis_min_soft_pos_limit
            } else {
                continue;
            };
            let reach = crate::planner::stop_distance(v_track.abs(), 0.0, tdec, tjerk)
                + crate::planner::stop_distance(self.run.velocity[d].abs(), 0.0, pdec, pjerk)
                + 2.0 * v.abs() * dt;
            if (limit - pos) * v.signum() <= reach {
                return true;
            }
        }
        false
    }

    fn for_members(&self, axes: &mut [Option<Box<Axis>>], mut f: impl FnMut(&mut Axis)) {
        for slot in self.members.iter().flatten() {
            if let Some(a) = axes.get_mut(*slot as usize).and_then(|a| a.as_deref_mut()) {
                f(a);
            }
        }
    }

    fn release_member(&mut self, d: usize, axes: &mut [Option<Box<Axis>>]) {
        if let Some(slot) = self.members[d].take() {
            if let Some(a) = axes.get_mut(slot as usize).and_then(|a| a.as_deref_mut()) {
                a.set_group_link(None, false);
            }
        }
    }

    /// MC_GroupDisable (and the first half of MC_UngroupAllAxes): from any state; a moving
    /// group stops at once — each axis on its own fast-stop ramp, off the path (decision 126).
    fn disable(&mut self, axes: &mut [Option<Box<Axis>>], cycle: u64, events: &mut impl EventSink) {
        if !self.run.is_idle() || self.state == GroupState::Moving {
            self.for_members(axes, |a| a.group_abandon());
        }
        self.pending = None;
        self.abort_all(cycle, events);
        self.drop_trackings(cycle, events);
        if let Some(s) = self.stop.take() {
            self.event(events, cycle, s.id, aborted());
        }
        if let Some(r) = self.pending_reset.take() {
            self.event(events, cycle, r, aborted());
        }
        self.enable_requested = false;
        self.for_members(axes, |a| {
            let g = a.group_link().0;
            a.set_group_link(g, false);
        });
        if self.state != GroupState::ErrorStop {
            self.state = GroupState::Disabled;
        }
    }

    /// The queue is flushed and every MovePath ends CommandAborted.
    fn abort_all(&mut self, cycle: u64, events: &mut impl EventSink) {
        self.run.flush();
        self.end_all_paths(cycle, events, aborted());
    }

    /// Every MovePath in flight ends with `out` (CommandAborted or Error).
    fn end_all_paths(&mut self, cycle: u64, events: &mut impl EventSink, out: FbOutputs) {
        for p in self.paths.iter_mut() {
            if let Some(c) = p.take() {
                events.push(CommandEvent {
                    cycle,
                    command: c.id,
                    target: Target::Group(self.id),
                    outputs: out,
                    result: None,
                });
            }
        }
    }

    fn end_path(&mut self, id: CommandId, cycle: u64, events: &mut impl EventSink, out: FbOutputs) {
        if let Some(slot) = self
            .paths
            .iter_mut()
            .find(|p| p.is_some_and(|p| p.id == id))
        {
            *slot = None;
            self.event(events, cycle, id, out);
        }
    }

    /// MC_GroupReset in ErrorStop: the group's and the members' errors are cleared (§4.1).
    fn reset(&mut self, axes: &mut [Option<Box<Axis>>]) {
        self.error = ErrorId(0);
        self.for_members(axes, |a| a.group_reset_axis());
        self.state = if self.enable_requested {
            GroupState::NotReady
        } else {
            GroupState::Disabled
        };
    }

    /// Deceleration and jerk of a halt or stop: defaults and maxima from the configuration;
    /// a value above the maximum is capped; `Ignore` on the jerk = no jerk limit.
    fn stop_dynamics(&self, dec: PathValue, jerk: PathValue) -> Result<(f64, f64), ErrorId> {
        let (d, m) = (self.config.default_dynamics, self.config.maximum_dynamics);
        let dec = match dec {
            PathValue::Default => d.deceleration,
            PathValue::Maximum => m.deceleration,
            PathValue::Value(x) if x.is_finite() && x >= 1.0 => x.min(m.deceleration),
            _ => return Err(ErrorId::PATH_DYNAMICS_INVALID),
        };
        let jerk = match jerk {
            PathValue::Default => d.jerk,
            PathValue::Maximum => m.jerk,
            PathValue::Ignore => 1e12,
            PathValue::Value(x) if x.is_finite() && x >= 100.0 => x.min(m.jerk),
            PathValue::Value(_) => return Err(ErrorId::PATH_DYNAMICS_INVALID),
        };
        Ok((dec, jerk))
    }

    #[allow(
        clippy::too_many_arguments,
        reason = "one call site; the cycle's context"
    )]
    fn start_stop(
        &mut self,
        id: CommandId,
        locks: bool,
        dec: f64,
        jerk: f64,
        axes: &mut [Option<Box<Axis>>],
        cycle: u64,
        events: &mut impl EventSink,
    ) -> Result<(), ErrorId> {
        match self.state {
            GroupState::Standby | GroupState::Moving => {}
            GroupState::Stopping if locks => {}
            GroupState::Stopping => return Err(ErrorId::GROUP_STATE_INVALID),
            // A stop is never refused: where nothing moves it is done at once (decision 128).
            _ if locks => {
                self.done_at_once(events, cycle, id);
                return Ok(());
            }
            _ => return Err(ErrorId::GROUP_STATE_INVALID),
        }
        if let Some(old) = self.stop.take() {
            self.event(events, cycle, old.id, aborted());
        }
        // The queue is flushed: every MovePath is aborted; the stop runs over what is left.
        self.end_all_paths(cycle, events, aborted());
        self.pending = None;
        // MC_GroupHalt and MC_GroupStop clear the coordinate transformation (§4.2); a
        // tracked conveyor is left with the stop's deceleration.
        self.frame = CoordTransform::default();
        self.detach(Some((dec, jerk)), aborted(), cycle, events);
        self.run.brake(dec, jerk);
        self.stop = Some(StopCommand {
            id,
            out: FbOutputs {
                busy: true,
                active: true,
                ..FbOutputs::default()
            },
            locks,
            standing: false,
            released: false,
        });
        self.event(events, cycle, id, self.stop.expect("set").out);
        if locks {
            self.state = GroupState::Stopping;
        }
        if self.run.is_idle() && !self.frame_moves() {
            self.stop_at_standstill(cycle, events);
            if self.state == GroupState::Moving {
                self.stand_still(axes, cycle, events);
            }
        }
        self.update_status(axes);
        Ok(())
    }

    fn stop_at_standstill(&mut self, cycle: u64, events: &mut impl EventSink) {
        let Some(mut s) = self.stop else { return };
        if s.standing {
            return;
        }
        s.standing = true;
        if s.locks {
            // MC_GroupStop: Done at standstill, Busy and Active until Execute falls (§4.2).
            s.out.done = true;
            self.event(events, cycle, s.id, s.out);
            self.stop = Some(s);
            self.try_unlock(cycle, events);
        } else {
            self.stop = None;
            self.event(
                events,
                cycle,
                s.id,
                FbOutputs {
                    done: true,
                    ..FbOutputs::default()
                },
            );
        }
    }

    /// Stopping → Standby once the stop stands and is released (note 3).
    fn try_unlock(&mut self, cycle: u64, events: &mut impl EventSink) {
        let Some(s) = self.stop else { return };
        if s.locks && s.standing && s.released {
            self.stop = None;
            self.event(
                events,
                cycle,
                s.id,
                FbOutputs {
                    done: true,
                    ..FbOutputs::default()
                },
            );
            if self.state == GroupState::Stopping {
                self.state = GroupState::Standby;
            }
        }
    }

    /// What a MovePath is built against now (the members' limits as their parameters are).
    pub(crate) fn context(&self, axes: &[Option<Box<Axis>>]) -> PathContext {
        let mut limits = [None; MAX_PATH_DIMS];
        for (d, m) in self.members.iter().enumerate() {
            if let Some(a) = m
                .and_then(|s| axes.get(s as usize))
                .and_then(|a| a.as_deref())
            {
                limits[d] = Some(AxisLimits::of(a.parameters()));
            }
        }
        PathContext {
            config: self.config,
            frame: self.build_frame(self.frame),
            limits,
            cycle_time: self.cycle_time,
        }
    }

    /// MC_MovePath: the table's entries join the queue as their first entry's BufferMode
    /// says (§7.3). Everything is checked before anything changes. With `prepared` (built
    /// off the cycle thread by [`prepare_path`]) the items are taken as they are when the
    /// path starts where they were built from, in the same context; otherwise (an aborting
    /// path while moving, or the group changed meanwhile) they are built here.
    #[allow(
        clippy::too_many_arguments,
        reason = "the cycle's context, one call site"
    )]
    pub(crate) fn submit_path(
        &mut self,
        id: CommandId,
        table: &PathTable,
        prepared: Option<&PreparedPath>,
        axes: &mut [Option<Box<Axis>>],
        cycle: u64,
        events: &mut impl EventSink,
    ) -> Result<(), ErrorId> {
        if !matches!(self.state, GroupState::Standby | GroupState::Moving) {
            return Err(ErrorId::GROUP_STATE_INVALID);
        }
        let axis_count = self.config.axis_count();
        table
            .check(axis_count, self.config.convention.planar())
            .map_err(|(_, _, e)| e)?;
        if self.paths.iter().all(|p| p.is_some()) || self.run.free() < 2 * table.entries.len() + 2 {
            return Err(ErrorId::PATH_TOO_LONG);
        }
        let frame_entry = table
            .entries
            .iter()
            .any(|e| matches!(e, PathEntry::CoordinateTransform { .. }));
        if frame_entry && (self.frame_moves() || self.shift != [0.0; 3]) {
            // A frame entry would detach from the conveyor in the middle of a path:
            // detach first with MC_SetCoordinateTransform (decision 147).
            return Err(ErrorId::GROUP_STATE_INVALID);
        }
        let ctx = self.context(axes);
        let first = table.joins_with();
        // A path during a stop's ramp starts where the stop ends, whatever its BufferMode.
        let aborting =
            (first == BufferMode::Aborting && !self.run.is_idle()) || self.run.is_braking();
        if aborting && first == BufferMode::Aborting {
            if let Some(radii) = table.first_job().and_then(PathEntry::corner_distance) {
                if self.abort_blending(id, table, radii, axes, cycle, events)? {
                    return Ok(());
                }
            }
        }
        if aborting {
            // Velocity 0 at the transition (§7.3): the running path stops on itself first,
            // and the new one is built from where it stands (decision 129).
            let (dec, jerk) = self.front_dynamics();
            self.run.brake(dec, jerk);
            self.end_all_paths(cycle, events, aborted());
            if let Some(s) = self.stop.take() {
                self.event(events, cycle, s.id, aborted());
            }
            self.pending_entries.clear();
            self.pending_entries.extend_from_slice(&table.entries);
            self.pending_frame = self.frame;
            self.pending = Some(id);
            self.paths[0] = Some(PathCommand { id, out: busy() });
            self.event(events, cycle, id, busy());
            self.update_status(axes);
            return Ok(());
        }
        let (start, s0) = (self.run.end_point(), self.run.end_s());
        let mut scratch = core::mem::take(&mut self.scratch);
        let built = match prepared {
            Some(p) if p.start == start && p.context == ctx => {
                self.prepared_taken += 1;
                scratch.clear();
                scratch.extend(p.items.iter().map(|it| Item {
                    command: id,
                    s0: it.s0 + s0,
                    ..*it
                }));
                Ok(p.frame)
            }
            _ => {
                build::build(&ctx, id, &table.entries, start, s0, &mut scratch).map_err(|(_, e)| e)
            }
        };
        // The blend from what is queued into the first entry.
        let joined = built.and_then(|frame| match (first, self.run.items.back().copied()) {
            (BufferMode::BlendingPrevious, Some(back)) => {
                let radii = table
                    .first_job()
                    .and_then(PathEntry::corner_distance)
                    .unwrap_or((0.0, 0.0));
                build::join(&ctx, &back, radii, &mut scratch, |cut, _| {
                    self.blend_reachable(&back, cut)
                })
                .map(|t| (t, frame))
            }
            _ => Ok((None, frame)),
        });
        let (back_trim, frame_after) = match joined {
            Ok(t) => t,
            Err(e) => {
                self.scratch = scratch;
                return Err(e);
            }
        };
        // Accepted: nothing below fails.
        self.take_frame(frame_after);
        if let Some(s) = self.stop.take() {
            // A MovePath during a halt's ramp takes over (§4.2: CommandAborted).
            self.event(events, cycle, s.id, aborted());
        }
        if let Some((seg, len, corner)) = back_trim {
            if let Some(b) = self.run.items.back_mut() {
                b.kind = ItemKind::Motion(seg);
                b.len = len;
                b.corner = corner;
            }
        }
        let slot = self
            .paths
            .iter_mut()
            .find(|p| p.is_none())
            .expect("checked above");
        *slot = Some(PathCommand { id, out: busy() });
        self.event(events, cycle, id, busy());
        self.run.append(scratch.drain(..));
        self.scratch = scratch;
        self.update_status(axes);
        Ok(())
    }

    /// §7.3 Aborting × CornerDistance: the new path blends from the running one at the
    /// virtual corner — where the running path would come to rest if it stopped now — and
    /// what is queued behind that point is dropped. A jerk-limited path cannot enter a blend
    /// that starts just before its rest point at the blend's velocity, so when it cannot, the
    /// corner moves on along the running path (by the corner distance, a few times) to the
    /// first point from which it can (decision 154). False (nothing changed) when there is no
    /// such corner on the motion items ahead: the caller stops first, as for None.
    #[allow(
        clippy::too_many_arguments,
        reason = "the cycle's context, one call site"
    )]
    fn abort_blending(
        &mut self,
        id: CommandId,
        table: &PathTable,
        radii: (f64, f64),
        axes: &mut [Option<Box<Axis>>],
        cycle: u64,
        events: &mut impl EventSink,
    ) -> Result<bool, ErrorId> {
        let (dec, jerk) = self.front_dynamics();
        let Some(rest) = self.run.rest_s(dec, jerk) else {
            return Ok(false);
        };
        let ctx = self.context(axes);
        // The entries up to the first job decide the blend: tried first on their own.
        let first = table
            .entries
            .iter()
            .position(|e| !matches!(e, PathEntry::CoordinateTransform { .. }))
            .unwrap_or(0);
        let mut scratch = core::mem::take(&mut self.scratch);
        let mut planner = self.spare.pop();
        let step = radii.0.max(radii.1).max(1e-3);
        let mut found = None;
        let mut rest_item = None;
        for k in 0..ABORT_CORNER_TRIES {
            let Some((i, back)) = self.run.cut_point(rest + k as f64 * step) else {
                break;
            };
            // The corner stays in the item the rest point lies in, and no corner blend lies
            // between the path and it (the items up to it keep the plan they were
            // checked with).
            if *rest_item.get_or_insert(i) != i
                || self.run.items.iter().take(i + 1).any(|it| it.blend)
            {
                break;
            }
            let ItemKind::Motion(back_seg) = back.kind else {
                break;
            };
            scratch.clear();
            let head = &table.entries[..=first];
            if build::build(&ctx, id, head, back_seg.end(), back.end_s(), &mut scratch).is_err() {
                break;
            }
            let run = &self.run;
            let joined = build::join(&ctx, &back, radii, &mut scratch, |cut, v| {
                planner
                    .as_mut()
                    .is_some_and(|p| run.can_pass(p, back.s0 + cut, v, &back.limits))
            });
            if let Ok(Some(t)) = joined {
                found = Some((i, back, back_seg, t));
                break;
            }
            if i + 1 == self.run.items.len() && back.end_s() <= rest + k as f64 * step {
                break;
            }
        }
        if let Some(p) = planner {
            self.spare.push(p);
        }
        let Some((i, back, back_seg, _)) = found else {
            self.scratch = scratch;
            return Ok(false);
        };
        // The whole table from that corner, and its blend.
        scratch.clear();
        let built = build::build(
            &ctx,
            id,
            &table.entries,
            back_seg.end(),
            back.end_s(),
            &mut scratch,
        )
        .map_err(|(_, e)| e)
        .and_then(|frame| {
            build::join(&ctx, &back, radii, &mut scratch, |_, _| true).map(|t| (t, frame))
        });
        let (back_trim, frame_after) = match built {
            Ok((Some(t), frame)) => (t, frame),
            Ok((None, _)) => {
                self.scratch = scratch;
                return Ok(false);
            }
            Err(e) => {
                self.scratch = scratch;
                return Err(e);
            }
        };
        // Accepted: the running path is cut at the corner, the new one blends on from there.
        self.end_all_paths(cycle, events, aborted());
        if let Some(s) = self.stop.take() {
            self.event(events, cycle, s.id, aborted());
        }
        let (seg, len, corner) = back_trim;
        let mut cut = back;
        cut.kind = ItemKind::Motion(seg);
        cut.len = len;
        cut.corner = corner;
        self.run.cut_at(i, cut);
        self.take_frame(frame_after);
        self.paths[0] = Some(PathCommand { id, out: busy() });
        self.event(events, cycle, id, busy());
        self.run.append(scratch.drain(..));
        self.scratch = scratch;
        self.update_status(axes);
        Ok(true)
    }

    /// The deceleration and jerk the running item plans with (an aborting path's stop).
    fn front_dynamics(&self) -> (f64, f64) {
        self.run.front().map_or(
            (
                self.config.default_dynamics.deceleration,
                self.config.default_dynamics.jerk,
            ),
            |i| (i.limits.deceleration, i.limits.jerk),
        )
    }

    /// A blend from the queue's last item can still be reached: the cut lies ahead of where
    /// the path could stop if it braked now.
    fn blend_reachable(&self, back: &Item, cut: f64) -> bool {
        if self.run.is_idle() {
            return true;
        }
        let front_is_back = self.run.items.len() == 1;
        if !front_is_back {
            return true;
        }
        let s = self.run.s;
        let reach = crate::planner::stop_distance(
            s.velocity,
            s.acceleration,
            back.limits.deceleration,
            back.limits.jerk,
        );
        back.s0 + cut > s.position + reach + 1e-9
    }

    /// The members' set positions as the group's point (while nothing runs).
    fn take_point(&mut self, axes: &[Option<Box<Axis>>]) {
        // The members' set points are the machine's: nothing lies between any more.
        self.shift = [0.0; 3];
        self.offset = [[0.0; 3]; 3];
        let mut p = self.run.point;
        for (d, m) in self.members.iter().enumerate() {
            if let Some(a) = m
                .and_then(|s| axes.get(s as usize))
                .and_then(|a| a.as_deref())
            {
                p[d] = a.status().set_position;
            }
        }
        self.run.take_point(p);
    }

    /// Enters ErrorStop: MovePaths end with the error; a moving path brakes on itself.
    fn enter_error(&mut self, e: ErrorId, cycle: u64, events: &mut impl EventSink) {
        if self.state == GroupState::ErrorStop {
            return;
        }
        self.state = GroupState::ErrorStop;
        self.error = e;
        self.end_all_paths(cycle, events, failed(e));
        if let Some(s) = self.stop.take() {
            self.event(events, cycle, s.id, failed(e));
        }
        self.pending = None;
        // A tracked conveyor is left with the tracking's own deceleration.
        self.detach(None, failed(e), cycle, events);
        if !self.run.is_idle() && !self.run.is_braking() {
            let (dec, jerk) = self.front_dynamics();
            self.run.brake(dec, jerk);
        }
    }

    /// One cycle, before the axes: the state machine, the path, the members' set points.
    pub(crate) fn step(
        &mut self,
        axes: &mut [Option<Box<Axis>>],
        cycle: u64,
        events: &mut impl EventSink,
    ) {
        let dt = self.cycle_time;
        // What the members are.
        let (mut any_error, mut all_ready, mut all_following) = (false, true, true);
        let mut present = 0;
        for slot in self.members.iter().flatten() {
            match axes.get(*slot as usize).and_then(|a| a.as_deref()) {
                Some(a) => {
                    present += 1;
                    // An axis MC_GroupReset is resetting counts from its next step on.
                    any_error |= a.group_axis_error() && !a.group_reset_pending();
                    all_ready &= a.group_axis_ready();
                    all_following &= a.group_axis_following();
                }
                None => {
                    any_error = true;
                    all_ready = false;
                    all_following = false;
                }
            }
        }
        let complete = present == self.config.axis_count();
        match self.state {
            GroupState::Disabled => self.take_point(axes),
            GroupState::NotReady => {
                if any_error {
                    self.enter_error(ErrorId::GROUP_AXIS_ERROR, cycle, events);
                } else if all_ready && complete {
                    self.state = GroupState::Standby;
                    self.take_point(axes);
                } else {
                    self.take_point(axes);
                }
            }
            GroupState::Standby => {
                if any_error {
                    self.enter_error(ErrorId::GROUP_AXIS_ERROR, cycle, events);
                } else if !all_ready || !complete {
                    // T2b: an axis without its control loop makes the group NotReady.
                    self.state = GroupState::NotReady;
                    self.take_point(axes);
                } else if !self.run.is_idle() || self.frame_moves() {
                    self.start_moving(axes, cycle, events);
                } else if self.stop.is_none() {
                    self.take_point(axes);
                }
            }
            GroupState::Moving | GroupState::Stopping => {
                if any_error {
                    self.enter_error(ErrorId::GROUP_AXIS_ERROR, cycle, events);
                } else if (!all_following || !complete)
                    && (!self.run.is_idle() || self.frame_moves())
                {
                    self.enter_error(ErrorId::GROUP_AXIS_LEFT, cycle, events);
                }
            }
            GroupState::ErrorStop => {}
        }
        if self.run.is_idle() && !self.frame_moves() {
            self.run.step(
                dt,
                self.config.override_ramp_time,
                &mut StepReport::default(),
            );
        } else if matches!(
            self.state,
            GroupState::Moving | GroupState::Stopping | GroupState::ErrorStop
        ) {
            let mut report = StepReport::default();
            self.run
                .step(dt, self.config.override_ramp_time, &mut report);
            if self.frame_moves() || self.shift != [0.0; 3] {
                self.step_frame(axes, cycle, events);
            }
            // Members that still follow take the path's set point (moved with the conveyor).
            let (point, vel, acc) = (self.run.point, self.run.velocity, self.run.acceleration);
            for (d, m) in self.members.iter().enumerate() {
                if let Some(a) = m
                    .and_then(|s| axes.get_mut(s as usize))
                    .and_then(|a| a.as_deref_mut())
                {
                    let o = |i: usize| if d < 3 { self.offset[i][d] } else { 0.0 };
                    a.group_follow(Kinematics {
                        position: point[d] + o(0),
                        velocity: vel[d] + o(1),
                        acceleration: acc[d] + o(2),
                        jerk: 0.0,
                    });
                }
            }
            for c in &report.started[..report.started_len] {
                if let Some(p) = self.paths.iter_mut().flatten().find(|p| p.id == *c) {
                    if !p.out.active {
                        p.out.active = true;
                        let out = p.out;
                        self.event(events, cycle, *c, out);
                    }
                }
            }
            for c in &report.done[..report.done_len] {
                self.end_path(
                    *c,
                    cycle,
                    events,
                    FbOutputs {
                        done: true,
                        ..FbOutputs::default()
                    },
                );
            }
            if report.braked || self.run.is_idle() {
                if !self.frame_moves() {
                    self.stop_at_standstill(cycle, events);
                }
                if let Some(id) = self.pending.take() {
                    self.build_pending(id, axes, cycle, events);
                }
            }
        }
        if self.run.is_idle()
            && !self.frame_moves()
            && matches!(self.state, GroupState::Moving | GroupState::ErrorStop)
        {
            self.stand_still(axes, cycle, events);
        }
        self.update_status(axes);
    }

    /// The aborting MovePath, from where the path stopped for it. Its geometry from there
    /// is checked only now: a circle that is not defined from that point ends it with the
    /// error (decision 129).
    fn build_pending(
        &mut self,
        id: CommandId,
        axes: &mut [Option<Box<Axis>>],
        cycle: u64,
        events: &mut impl EventSink,
    ) {
        let ctx = PathContext {
            frame: self.build_frame(self.pending_frame),
            ..self.context(axes)
        };
        let mut scratch = core::mem::take(&mut self.scratch);
        let (start, s0) = (self.run.point, self.run.s.position);
        match build::build(&ctx, id, &self.pending_entries, start, s0, &mut scratch) {
            Ok(frame) => {
                self.take_frame(frame);
                self.run.append(scratch.drain(..));
            }
            Err((_, e)) => self.end_path(id, cycle, events, failed(e)),
        }
        self.scratch = scratch;
    }

    /// Standby → Moving: every member takes the path as its setpoint source.
    fn start_moving(
        &mut self,
        axes: &mut [Option<Box<Axis>>],
        cycle: u64,
        events: &mut impl EventSink,
    ) {
        let mut all = true;
        self.for_members(axes, |a| all &= a.group_start());
        if all {
            self.state = GroupState::Moving;
        } else {
            self.enter_error(ErrorId::GROUP_AXIS_LEFT, cycle, events);
        }
    }

    /// The path stands with nothing left to run: the members are released to standstill.
    fn stand_still(
        &mut self,
        axes: &mut [Option<Box<Axis>>],
        cycle: u64,
        events: &mut impl EventSink,
    ) {
        self.for_members(axes, |a| a.group_finish());
        match self.state {
            GroupState::Moving => self.state = GroupState::Standby,
            GroupState::ErrorStop => {
                if let Some(r) = self.pending_reset.take() {
                    self.reset(axes);
                    self.event(
                        events,
                        cycle,
                        r,
                        FbOutputs {
                            done: true,
                            ..FbOutputs::default()
                        },
                    );
                }
            }
            _ => {}
        }
    }

    fn update_status(&mut self, axes: &[Option<Box<Axis>>]) {
        // The set point the group gives its members this cycle (their own statuses show it
        // after their step).
        let mut position = self.run.point;
        for (p, o) in position.iter_mut().zip(self.offset[0]) {
            *p += o;
        }
        let mut standing = true;
        for m in self.members.iter() {
            if let Some(a) = m
                .and_then(|s| axes.get(s as usize))
                .and_then(|a| a.as_deref())
            {
                let st = a.status();
                standing &= st.set_velocity == 0.0 && st.set_acceleration == 0.0;
            }
        }
        let front = self.run.front().copied();
        let (remaining_distance, remaining_time) = self.run.remaining();
        let blocker = self.run.blocked();
        self.status = GroupStatus {
            state: self.state,
            enable_requested: self.enable_requested,
            error_id: self.error.0,
            members: self.members,
            axes_count: self.members.iter().flatten().count() as u8,
            all_axes_standing: standing,
            override_factor: self.run.k_target,
            actual_override: self.run.k,
            path_velocity: self.run.path_velocity(),
            path_acceleration: self.run.path_acceleration(),
            path_position: self.run.s.position,
            command: front.map_or(0, |f| f.command),
            entry_index: front.map_or(0, |f| f.entry as u32),
            invoke_id: front.map_or(0, |f| f.invoke_id),
            in_blending_segment: front.is_some_and(|f| f.blend) && !self.run.is_idle(),
            remaining_distance,
            remaining_time,
            blocked: blocker.is_some(),
            blocker_id: blocker.unwrap_or(0),
            queued_entries: self.run.entries,
            position,
            queue_end: self.run.end_point(),
            frame: self.frame,
            prepared_paths: self.prepared_taken,
            conveyor: self.track.as_ref().map(|t| t.conveyor),
            tracking_command: self.track.as_ref().map_or(0, |t| t.id),
            in_sync: self.track.as_ref().is_some_and(|t| t.out.in_sync),
            conveyor_error: self.track.as_ref().is_some_and(|t| t.conveyor_error),
            remaining_distance_to_sync: self.track.as_ref().map_or(0.0, |t| t.distance_to_sync),
            remaining_time_to_sync: self.track.as_ref().map_or(0.0, |t| t.time_to_sync),
            tracking_velocity: {
                let v = self.offset[1];
                (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
            },
        };
    }
}

fn busy() -> FbOutputs {
    FbOutputs {
        busy: true,
        ..FbOutputs::default()
    }
}

fn aborted() -> FbOutputs {
    FbOutputs {
        command_aborted: true,
        ..FbOutputs::default()
    }
}

fn failed(e: ErrorId) -> FbOutputs {
    FbOutputs {
        error: true,
        error_id: e.0,
        ..FbOutputs::default()
    }
}
