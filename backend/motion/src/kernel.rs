//! The kernel: a fixed number of axis slots stepped together, masters before their slaves.
//! It holds what no single axis can see — the slots, the couplings between them and the order
//! they are stepped in; everything else is the axis's (`axis/`).

use crate::axis::{Ahead, Axis, Master, MasterSample, Rest};
use std::sync::Arc;

use crate::cam::{Cam, CamStore};
use crate::command::{AxisSlot, Command, CommandKind, EventSink, Target, Verdict};
use crate::drive::{DriveFeedback, DriveSetpoint};
use crate::error::ErrorId;
use crate::group::{Group, GroupStatus, MAX_GROUPS, PathTable};
use crate::params::AxisParameters;
use crate::status::AxisStatus;

/// All axes of one machine. Capacity is fixed at construction so that the cycle never
/// allocates; axes are built off the cycle thread and handed in as `Box<Axis>`.
pub struct Kernel {
    cycle_time: f64,
    cycle: u64,
    axes: Vec<Option<Box<Axis>>>,
    /// By slot, what an axis at rest repeats (`axis/rest.rs`): side by side, so that the
    /// standing axes of a large machine cost little more each than those of a small one.
    rest: Box<[Rest]>,
    order: StepOrder,
    cams: CamStore,
    /// Coordinated-motion groups, stepped before the axes (they give their members' set
    /// points).
    groups: Vec<Option<Box<Group>>>,
}

/// The order the axes are stepped in: every master before its slaves, so that a slave follows
/// the setpoint its master has in the same cycle. Couplings change only by a command or when
/// an axis leaves one in its step, so the order is computed then (and when an axis is
/// inserted or removed), not every cycle; its arrays are sized once, for every slot.
struct StepOrder {
    /// Occupied slots in stepping order: `slots[..len]`.
    slots: Box<[AxisSlot]>,
    len: usize,
    /// `slots[in_loop..len]` are part of (or behind) a coupling loop: stepped last, without
    /// their master. (Submit refuses couplings that close a loop; this keeps a cycle safe
    /// whatever happens.)
    in_loop: usize,
    /// A coupling or an occupied slot changed: compute the order before the next step.
    stale: bool,
    /// Scratch for `compute`: the slot is in the order already.
    placed: Box<[bool]>,
}

impl StepOrder {
    fn new(capacity: usize) -> Self {
        StepOrder {
            slots: vec![0; capacity].into_boxed_slice(),
            len: 0,
            in_loop: 0,
            stale: true,
            placed: vec![false; capacity].into_boxed_slice(),
        }
    }

    /// Masters first, then slaves whose master is placed (chains resolve in as many passes as
    /// they are long; within a pass by slot), a slave of an empty slot as if uncoupled; what
    /// is left is in a loop, by slot.
    fn compute(&mut self, axes: &[Option<Box<Axis>>]) {
        self.len = 0;
        self.placed.iter_mut().for_each(|p| *p = false);
        for _pass in 0..axes.len().max(1) {
            let mut progressed = false;
            for (i, axis) in axes.iter().enumerate() {
                if self.placed[i] {
                    continue;
                }
                let Some(axis) = axis.as_deref() else {
                    self.placed[i] = true;
                    continue;
                };
                let waits = axis.coupled_masters().iter().flatten().any(|&m| {
                    let master_there = axes.get(m as usize).is_some_and(|a| a.is_some());
                    master_there && !self.placed[m as usize]
                });
                if waits {
                    continue; // wait for the masters
                }
                self.push(i);
                progressed = true;
            }
            if !progressed {
                break;
            }
        }
        self.in_loop = self.len;
        for i in 0..axes.len() {
            if !self.placed[i] {
                self.push(i);
            }
        }
        self.stale = false;
    }

    fn push(&mut self, slot: usize) {
        self.slots[self.len] = slot as AxisSlot;
        self.len += 1;
        self.placed[slot] = true;
    }
}

impl Kernel {
    /// `cycle_time` in seconds; `max_axes` slots.
    pub fn new(cycle_time: f64, max_axes: usize) -> Self {
        assert!(cycle_time > 0.0 && cycle_time.is_finite());
        // The kernel is made on the thread that steps it: its plans then allocate nothing.
        crate::planner::prepare_solver();
        Kernel {
            cycle_time,
            cycle: 0,
            axes: (0..max_axes).map(|_| None).collect(),
            rest: vec![Rest::default(); max_axes].into_boxed_slice(),
            order: StepOrder::new(max_axes),
            cams: CamStore::default(),
            groups: (0..MAX_GROUPS).map(|_| None).collect(),
        }
    }

    pub fn cycle_time(&self) -> f64 {
        self.cycle_time
    }

    /// Number of cycles stepped so far.
    pub fn cycle(&self) -> u64 {
        self.cycle
    }

    pub fn capacity(&self) -> usize {
        self.axes.len()
    }

    /// Puts a ready-built axis into a slot and returns what was there (to be freed off the
    /// cycle thread). The axis reports its commands' events under this slot from now on.
    /// Does not allocate.
    pub fn insert_axis(
        &mut self,
        slot: AxisSlot,
        mut axis: Box<Axis>,
    ) -> Result<Option<Box<Axis>>, Box<Axis>> {
        // An axis put where a group member was takes its place in the group (disabled: the
        // group is not enabled with a member that changes, see `insert_group`).
        let member_of = self.groups.iter().flatten().find_map(|g| {
            g.members()
                .contains(&Some(slot))
                .then(|| (g.status().enable_requested, g.id()))
        });
        match self.axes.get_mut(slot as usize) {
            Some(s) => {
                axis.place(slot, self.cycle);
                if let Some((engaged, g)) = member_of {
                    axis.set_group_link(Some(g), engaged);
                }
                self.order.stale = true;
                Ok(s.replace(axis))
            }
            None => Err(axis),
        }
    }

    /// Takes an axis out of its slot (to be freed off the cycle thread). Slaves coupled to
    /// it lose their master at the next step.
    pub fn remove_axis(&mut self, slot: AxisSlot) -> Option<Box<Axis>> {
        self.order.stale = true;
        // It leaves its group: an axis put into the slot later is not a member by accident.
        for g in self.groups.iter_mut().flatten() {
            g.forget_member(slot);
        }
        self.axes.get_mut(slot as usize).and_then(|s| s.take())
    }

    /// Puts a ready-built cam under its table id (1..255), handing back the one it replaces
    /// (to be freed off the cycle thread). Refused — the cam comes back — while an axis is
    /// coupled through that table or waits to be (a coupled table changes only by the online
    /// change rules, never by a jump), or for an id outside 1..255.
    pub fn insert_cam(&mut self, id: u32, cam: Arc<Cam>) -> Result<Option<Arc<Cam>>, Arc<Cam>> {
        if self.cam_in_use(id) {
            return Err(cam);
        }
        self.cams.insert(id, cam)
    }

    /// Takes a cam out (to be freed off the cycle thread); refused while it is in use.
    pub fn remove_cam(&mut self, id: u32) -> Result<Option<Arc<Cam>>, ErrorId> {
        if self.cam_in_use(id) {
            return Err(ErrorId::CAM_TABLE_IN_USE);
        }
        Ok(self.cams.remove(id))
    }

    /// Online change (MC_WriteMotionFunction on a coupled table): `cam` is the table's data from
    /// now on — new couplings take it at once, coupled slaves when `change` says and never
    /// with a jump. On a table nobody is coupled through it is simply put in place (the old
    /// cam is retired). `Err` gives the cam back while an earlier change is still on its way
    /// to a slave, or for an id that holds no cam.
    pub fn change_cam(
        &mut self,
        id: u32,
        cam: Arc<Cam>,
        change: crate::cam::OnlineChange,
    ) -> Result<(), Arc<Cam>> {
        if self.cams.get(id).is_none() {
            return Err(cam);
        }
        if !self.cam_in_use(id) {
            return match self.cams.insert(id, cam) {
                Ok(old) => {
                    if let Some(old) = old {
                        self.cams.retire(old);
                    }
                    Ok(())
                }
                Err(cam) => Err(cam),
            };
        }
        if self.cam_change_pending(id) {
            return Err(cam);
        }
        let current = self.cams.generation(id);
        let cur_in_use = self.axes.iter().flatten().any(|a| a.runs_cam(id, current));
        let generation = self.cams.stage(id, cam, cur_in_use)?;
        for a in self.axes.iter_mut().flatten() {
            a.queue_cam_data(id, generation, change);
        }
        Ok(())
    }

    /// MC_SetCamOnlineChangeMode DELETEQUEUEDDATA: data written to table `id` that has not
    /// reached its slaves stays out of them (they run the data they have).
    pub fn drop_cam_data(&mut self, id: u32) {
        for a in self.axes.iter_mut().flatten() {
            a.drop_cam_data(id);
        }
    }

    /// An earlier online change of table `id` has not reached all its slaves yet (a slave has
    /// it queued), or slaves run both generations held so that a third cannot be staged. A
    /// slave that keeps older data by choice (DELETEQUEUEDDATA, OFF) does not block a write.
    pub fn cam_change_pending(&self, id: u32) -> bool {
        let queued = self
            .axes
            .iter()
            .flatten()
            .any(|a| a.cam_data_queued_for(id));
        let current = self.cams.generation(id);
        queued
            || (self.cams.has_old(id)
                && self.axes.iter().flatten().any(|a| a.runs_cam(id, current)))
    }

    /// A cam the kernel no longer uses (replaced, or left by its last slave after an online
    /// change), to be freed off the cycle thread.
    pub fn take_retired_cam(&mut self) -> Option<Arc<Cam>> {
        self.cams.take_retired()
    }

    /// An axis is coupled through cam table `id`, or waits to be (a queued coupling or switch).
    pub fn cam_in_use(&self, id: u32) -> bool {
        self.axes.iter().flatten().any(|a| a.uses_cam(id))
    }

    pub fn axis(&self, slot: AxisSlot) -> Option<&Axis> {
        self.axes.get(slot as usize).and_then(|a| a.as_deref())
    }

    pub fn status(&self, slot: AxisSlot) -> Option<AxisStatus> {
        self.axis(slot).map(|a| a.status())
    }

    /// No axis in the slot, or one that is disabled with no enable requested.
    pub fn is_disabled(&self, slot: AxisSlot) -> bool {
        self.axis(slot).is_none_or(|a| a.is_disabled())
    }

    /// Restarts the following-error peak hold of an axis (not a PLCopen command: like the
    /// online tab's reset, it creates no command and changes no motion). False: no axis.
    pub fn reset_following_error_peak(&mut self, slot: AxisSlot) -> bool {
        match self
            .axes
            .get_mut(slot as usize)
            .and_then(|a| a.as_deref_mut())
        {
            Some(a) => {
                a.reset_following_error_peak();
                true
            }
            None => false,
        }
    }

    pub fn parameters(&self, slot: AxisSlot) -> Option<&AxisParameters> {
        self.axis(slot).map(|a| a.parameters())
    }

    /// Puts a ready-built group into a slot (0..MAX_GROUPS) and returns the one it replaces
    /// (to be freed off the cycle thread). Refused — the group comes back — while the group
    /// there is enabled: a configuration changes only on a disabled group. The new group
    /// keeps the old one's members whose roles it still has.
    pub fn insert_group(
        &mut self,
        id: crate::command::GroupId,
        mut group: Box<Group>,
    ) -> Result<Option<Box<Group>>, Box<Group>> {
        let Some(slot) = self.groups.get_mut(id as usize) else {
            return Err(group);
        };
        if slot
            .as_ref()
            .is_some_and(|g| g.status().enable_requested || g.in_error())
        {
            return Err(group);
        }
        group.place(id);
        if let Some(old) = slot.as_deref() {
            group.adopt_members(old, &mut self.axes);
        }
        Ok(slot.replace(group))
    }

    /// Takes a group out (to be freed off the cycle thread): its members leave it; a moving
    /// group's members brake on their own ramps.
    pub fn remove_group(
        &mut self,
        id: crate::command::GroupId,
        events: &mut impl EventSink,
    ) -> Option<Box<Group>> {
        let mut g = self.groups.get_mut(id as usize).and_then(|g| g.take())?;
        let cycle = self.cycle + 1;
        let _ = g.submit(
            0,
            CommandKind::UngroupAllAxes,
            &mut self.axes,
            cycle,
            events,
        );
        Some(g)
    }

    pub fn group(&self, id: crate::command::GroupId) -> Option<&Group> {
        self.groups.get(id as usize).and_then(|g| g.as_deref())
    }

    pub fn group_status(&self, id: crate::command::GroupId) -> Option<GroupStatus> {
        self.group(id).map(|g| *g.status())
    }

    /// MC_MovePath: the table (allocated off the cycle thread; the caller frees it there)
    /// joins the group's queue, or is refused and changes nothing. Its geometry is built
    /// here, in the cycle: see [`Kernel::submit_prepared_path`] to build it off the thread.
    pub fn submit_path(
        &mut self,
        id: crate::command::CommandId,
        group: crate::command::GroupId,
        table: &PathTable,
        events: &mut impl EventSink,
    ) -> Verdict {
        self.submit_prepared_path(id, group, table, None, events)
    }

    /// MC_MovePath with its items built off the cycle thread by
    /// [`crate::group::prepare_path`] from the group's `queue_end` and
    /// [`Kernel::path_context`]: taken as they are when the path still starts there in the
    /// same context, built here otherwise (an aborting path while moving, a queue that
    /// changed meanwhile, a parameter written since).
    pub fn submit_prepared_path(
        &mut self,
        id: crate::command::CommandId,
        group: crate::command::GroupId,
        table: &PathTable,
        prepared: Option<&crate::group::PreparedPath>,
        events: &mut impl EventSink,
    ) -> Verdict {
        let cycle = self.cycle + 1;
        match self
            .groups
            .get_mut(group as usize)
            .and_then(|g| g.as_deref_mut())
        {
            Some(g) => match g.submit_path(id, table, prepared, &mut self.axes, cycle, events) {
                Ok(()) => Verdict::Accepted,
                Err(e) => Verdict::Rejected(e),
            },
            None => Verdict::Rejected(ErrorId::GROUP_NOT_FOUND),
        }
    }

    /// What a MovePath for `group` is built against now (configuration, members' limits).
    pub fn path_context(
        &self,
        group: crate::command::GroupId,
    ) -> Option<crate::group::PathContext> {
        self.group(group).map(|g| g.context(&self.axes))
    }

    /// Offers a command to its axis or group in the current cycle (before [`Kernel::step`]).
    /// The verdict is immediate; an accepted command changes the state at once and its
    /// outputs follow as events (the first one in this call).
    pub fn submit(&mut self, cmd: Command, events: &mut impl EventSink) -> Verdict {
        let slot = match cmd.target {
            Target::Axis(slot) => slot,
            Target::Group(g) => {
                let cycle = self.cycle + 1;
                return match self
                    .groups
                    .get_mut(g as usize)
                    .and_then(|g| g.as_deref_mut())
                {
                    Some(group) => group.submit(cmd.id, cmd.kind, &mut self.axes, cycle, events),
                    None => Verdict::Rejected(ErrorId::GROUP_NOT_FOUND),
                };
            }
        };
        let slot = slot as usize;
        if let CommandKind::GearInMultiMaster(g) = cmd.kind {
            let mut samples = [None; 4];
            for (i, m) in g.masters.iter().enumerate() {
                let Some(m) = *m else { continue };
                let twice = g.masters[..i].contains(&Some(m));
                if m as usize == slot || twice || self.follows(m, slot) {
                    return Verdict::Rejected(ErrorId::MASTER_INVALID);
                }
                match self.axis(m) {
                    Some(a) => samples[i] = Some(MasterSample::of(a)),
                    None => return Verdict::Rejected(ErrorId::MASTER_INVALID),
                }
            }
            if let Some(axis) = self.axes.get_mut(slot).and_then(|a| a.as_deref_mut()) {
                axis.offer_masters(samples);
            }
        }
        let master = match cmd.kind {
            CommandKind::GearIn { master, .. }
            | CommandKind::GearInDyn { master, .. }
            | CommandKind::CamIn(crate::cam::CamIn { master, .. })
            | CommandKind::CamInV2(crate::cam::CamInV2 { master, .. }) => {
                if master as usize == slot {
                    return Verdict::Rejected(ErrorId::MASTER_INVALID);
                }
                // A master that (through its own masters) follows this axis would close a loop.
                if self.follows(master, slot) {
                    return Verdict::Rejected(ErrorId::MASTER_INVALID);
                }
                match self.axis(master) {
                    Some(m) => Some((master, MasterSample::of(m))),
                    None => return Verdict::Rejected(ErrorId::MASTER_INVALID),
                }
            }
            _ => None,
        };
        // Stamped with the cycle the command takes effect in (the next step).
        let cycle = self.cycle + 1;
        match self.axes.get_mut(slot).and_then(|a| a.as_deref_mut()) {
            Some(axis) => {
                // All masters: a further one changing re-orders the step too.
                let coupled_to = axis.coupled_masters();
                let verdict = axis.submit(cmd, master, &self.cams, cycle, events);
                if axis.coupled_masters() != coupled_to {
                    self.order.stale = true;
                }
                verdict
            }
            None => Verdict::Rejected(ErrorId::AXIS_UNKNOWN),
        }
    }

    /// Whether axis `from` follows axis `target` through its masters, theirs and so on (a
    /// coupling of `target` to `from` would close a loop). Without allocating: the set of
    /// axes reached grows in passes (a bitset of up to 1024 slots).
    fn follows(&self, from: AxisSlot, target: usize) -> bool {
        let n = self.axes.len().min(1024);
        let mut reached = [0u64; 16];
        let mark = |r: &mut [u64; 16], i: usize| {
            let new = r[i / 64] & (1 << (i % 64)) == 0;
            r[i / 64] |= 1 << (i % 64);
            new
        };
        if (from as usize) >= n {
            return false;
        }
        mark(&mut reached, from as usize);
        for _ in 0..n {
            let mut grew = false;
            for i in 0..n {
                if reached[i / 64] & (1 << (i % 64)) == 0 {
                    continue;
                }
                let Some(a) = self.axes[i].as_deref() else {
                    continue;
                };
                for m in a.coupled_masters().into_iter().flatten() {
                    if (m as usize) < n {
                        grew |= mark(&mut reached, m as usize);
                    }
                }
            }
            if !grew {
                break;
            }
        }
        target < n && reached[target / 64] & (1 << (target % 64)) != 0
    }

    /// The `k`th axis in the step order, whose lines are asked for ahead of its step (none
    /// beyond the order's end or for an empty slot).
    fn ahead(&self, k: usize) -> Ahead {
        let slot = self.order.slots[..self.order.len].get(k);
        Ahead::of(slot.and_then(|&s| self.axes[s as usize].as_deref()))
    }

    /// One cycle: every axis reads its feedback, advances and writes its setpoint.
    /// `feedback` and `setpoints` are indexed by slot (missing entries are treated as
    /// a drive that is not ready / left untouched).
    pub fn step(
        &mut self,
        feedback: &[DriveFeedback],
        setpoints: &mut [DriveSetpoint],
        events: &mut impl EventSink,
    ) {
        // Stepped on the thread that made the kernel (`Kernel::new`): its plans allocate nothing.
        debug_assert!(crate::planner::solver_prepared());
        self.cycle += 1;
        let cycle = self.cycle;
        let dt = self.cycle_time;
        if self.order.stale {
            self.order.compute(&self.axes);
        }
        for g in self.groups.iter_mut().flatten() {
            g.step(&mut self.axes, cycle, events);
        }
        // The first axis's lines; each axis then asks for the next one's (`prefetch.rs`).
        self.ahead(0).all_from(0);
        // A slot beyond the feedback given reads as a drive that is not ready.
        let no_feedback = DriveFeedback::default();
        // … and a setpoint beyond those given goes nowhere (a step writes all of it).
        let mut spare = DriveSetpoint::default();
        for k in 0..self.order.len {
            let i = self.order.slots[k] as usize;
            let Some(axis) = self.axes[i].as_deref() else {
                continue;
            };
            // The next axis's lines are on their way while this one steps, asked for in parts:
            // the first now, the others from inside the step (`prefetch.rs`).
            let ahead = self.ahead(k + 1);
            ahead.part(0);
            let fb = feedback.get(i).unwrap_or(&no_feedback);
            // An axis at rest follows no master (it would not be at rest): it reads its rest
            // record and its beat, nothing else (`axis/rest.rs`).
            if axis.at_rest(fb, &self.rest[i]) {
                debug_assert!(axis.follows_no_master() && k < self.order.in_loop);
                let axis = self.axes[i].as_deref_mut().expect("checked above");
                let out = setpoints.get_mut(i).unwrap_or(&mut spare);
                let rest = &mut self.rest[i];
                // Debug builds run the full step beside it and compare the two.
                #[cfg(debug_assertions)]
                axis.step_at_rest_checked(dt, fb, &self.cams, cycle, events, rest, out);
                #[cfg(not(debug_assertions))]
                axis.step_at_rest(dt, cycle, rest, out);
                ahead.all_from(1);
                continue;
            }
            // Most axes follow no master: they skip the masters' bookkeeping (issue 27).
            let free = axis.follows_no_master();
            debug_assert_eq!(free, axis.coupled_masters() == [None; 4]);
            let all_masters = if free {
                [None; 4]
            } else {
                axis.coupled_masters()
            };
            // Stepped before this slave in this cycle (the order sees to it).
            let sample = |m: AxisSlot| {
                self.axes
                    .get(m as usize)
                    .and_then(|a| a.as_deref())
                    .map(MasterSample::of)
            };
            let mut samples = None;
            // The first of them is the one a single coupling follows.
            let master = match all_masters[0] {
                _ if k >= self.order.in_loop => Master::Lost,
                None => Master::Uncoupled,
                Some(m) => {
                    let mut all = [None; 4];
                    let mut vanished = false;
                    let mut failed = false;
                    for (j, m) in all_masters.iter().enumerate().skip(1) {
                        if let Some(m) = *m {
                            all[j] = sample(m);
                            vanished |= all[j].is_none();
                            failed |= all[j].is_some_and(|s| s.error);
                        }
                    }
                    all[0] = sample(m);
                    samples = Some(all);
                    match all[0] {
                        // A further master that vanished loses the slave like the first.
                        _ if vanished => Master::Lost,
                        // And one in ErrorStop.
                        Some(s) => Master::Sample(MasterSample {
                            error: s.error || failed,
                            ..s
                        }),
                        None => Master::Lost, // master vanished
                    }
                }
            };
            let axis = self.axes[i].as_deref_mut().expect("checked above");
            if let Some(all) = samples {
                axis.offer_masters(all);
            }
            let out = setpoints.get_mut(i).unwrap_or(&mut spare);
            let rest = &mut self.rest[i];
            axis.step(dt, fb, master, &self.cams, cycle, events, rest, out, ahead);
            let masters_changed = if free {
                debug_assert_eq!(
                    axis.follows_no_master(),
                    axis.coupled_masters() == [None; 4]
                );
                !axis.follows_no_master()
            } else {
                axis.coupled_masters() != all_masters
            };
            if masters_changed {
                // It left its coupling (master lost, an error, a limit), or its masters changed
                // otherwise: next cycle it is stepped where its masters put it.
                self.order.stale = true;
            }
        }
        // Data of an online change no slave runs any more is retired (not freed here).
        let axes = &self.axes;
        self.cams.retire_unused(|id, generation| {
            axes.iter().flatten().any(|a| a.runs_cam(id, generation))
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::command::{
        BufferMode, Direction, DisableMode, Dynamics, MoveOptions, Positioning, Superposition,
    };
    use crate::{AxisConfig, AxisParameters, AxisState, CommandEvent};

    const DT: f64 = 0.001;

    fn kernel(axes: usize) -> Kernel {
        let mut k = Kernel::new(DT, axes);
        for i in 0..axes {
            let config = AxisConfig {
                modulo: false,
                parameters: AxisParameters::default(),
                compensation_table: None,
                drive_executed: false,
            };
            k.insert_axis(i as AxisSlot, Axis::new(config, DT)).unwrap();
        }
        k
    }

    /// Steps with ideal drives (actual = last setpoint).
    fn step(k: &mut Kernel, sp: &mut [DriveSetpoint], events: &mut Vec<CommandEvent>) {
        let fb: Vec<DriveFeedback> = sp
            .iter()
            .map(|s| DriveFeedback {
                ready: true,
                enabled: s.enable,
                actual_position: s.position,
                ..DriveFeedback::default()
            })
            .collect();
        k.step(&fb, sp, events);
    }

    #[test]
    fn a_command_for_a_group_is_refused_while_no_group_exists_and_changes_nothing() {
        let mut k = kernel(1);
        let mut e = Vec::new();
        let before = k.status(0).unwrap();
        let cmd = Command {
            id: 1,
            target: Target::Group(0),
            kind: CommandKind::Reset,
        };
        assert_eq!(
            k.submit(cmd, &mut e),
            Verdict::Rejected(ErrorId::GROUP_NOT_FOUND)
        );
        assert!(e.is_empty(), "{e:?}");
        assert_eq!(k.status(0).unwrap(), before);
    }

    fn accept(
        k: &mut Kernel,
        id: u64,
        axis: AxisSlot,
        kind: CommandKind,
        e: &mut Vec<CommandEvent>,
    ) {
        let cmd = Command {
            id,
            target: Target::Axis(axis),
            kind,
        };
        assert_eq!(k.submit(cmd, e), Verdict::Accepted, "{kind:?}");
    }

    fn gear_in(master: AxisSlot) -> CommandKind {
        CommandKind::GearIn {
            master,
            ratio_numerator: 1.0,
            ratio_denominator: 1,
        }
    }

    /// A reading that overflows in the axis's units (encoder scaling × a huge count), then a
    /// drive that reports no number: the cycle goes on with a number in place of the reading
    /// (the stand-in was the overflowed reading, and the step recursed until the stack ran
    /// out: a stack overflow of the cycle thread, found by a review).
    #[test]
    fn an_overflowed_reading_then_no_number_does_not_recurse() {
        let mut k = kernel(1);
        let mut e = Vec::new();
        let scale = CommandKind::SetEncoderScalingFactor {
            factor: 1e12,
            relative: false,
        };
        accept(&mut k, 1, 0, scale, &mut e);
        let mut sp = vec![DriveSetpoint::default()];
        let mut fb = vec![DriveFeedback {
            ready: true,
            actual_position: 1e300,
            ..DriveFeedback::default()
        }];
        k.step(&fb, &mut sp, &mut e);
        fb[0].actual_position = f64::NAN;
        k.step(&fb, &mut sp, &mut e);
        let st = k.status(0).unwrap();
        // No last good reading to keep: the stand-in is 0, a number.
        assert_eq!(st.actual_position, 0.0, "{st:?}");
        assert!(sp[0].position.is_finite(), "{:?}", sp[0]);
    }

    #[test]
    fn masters_are_stepped_before_their_slaves_whatever_their_slots() {
        let mut k = kernel(4);
        let (mut sp, mut e) = (vec![DriveSetpoint::default(); 4], Vec::new());
        for a in 0..4 {
            accept(&mut k, 1 + a as u64, a, power(), &mut e);
        }
        for _ in 0..10 {
            step(&mut k, &mut sp, &mut e);
        }
        assert!((0..4).all(|a| k.status(a).unwrap().state == AxisState::Standstill));
        // A chain against the slot order: 0 follows 1, which follows 3.
        accept(&mut k, 5, 1, gear_in(3), &mut e);
        accept(&mut k, 6, 0, gear_in(1), &mut e);
        let velocity = velocity(10.0);
        accept(&mut k, 7, 3, velocity, &mut e);
        for _ in 0..50 {
            step(&mut k, &mut sp, &mut e);
            // The whole chain follows in the cycle the master moves.
            let master = k.status(3).unwrap().set_position;
            assert_eq!(k.status(0).unwrap().set_position, master);
        }
        assert_eq!(&k.order.slots[..k.order.len], &[2, 3, 1, 0]);
        assert_eq!(k.order.in_loop, 4);
        assert!(k.status(3).unwrap().set_position > 0.0);
        // The middle axis goes: its slave loses its master and is stepped as an uncoupled
        // axis from the next cycle on.
        drop(k.remove_axis(1));
        step(&mut k, &mut sp, &mut e);
        assert_eq!(k.status(0).unwrap().error_id, ErrorId::MASTER_LOST.0);
        assert_eq!(&k.order.slots[..k.order.len], &[0, 2, 3]);
        step(&mut k, &mut sp, &mut e);
        assert_eq!(&k.order.slots[..k.order.len], &[0, 2, 3]);
    }

    /// Issue 27: a standing axis with the same feedback cycle after cycle is stepped at rest
    /// (`axis/rest.rs`) — its status changes in its cycle counter only, its status count not
    /// at all — and leaves rest in the cycle a command or a new reading arrives. In debug
    /// builds every cycle at rest also runs the full step and asserts it gave the same.
    #[test]
    fn rest_step_is_the_full_step() {
        let mut k = kernel(2);
        let (mut sp, mut e) = (vec![DriveSetpoint::default(); 2], Vec::new());
        accept(&mut k, 1, 0, power(), &mut e);
        let rests = |k: &Kernel, a| k.axis(a).unwrap().is_at_rest();
        // Powering up takes cycles, each different: no rest yet.
        step(&mut k, &mut sp, &mut e);
        assert!(!rests(&k, 0));
        for _ in 0..100 {
            step(&mut k, &mut sp, &mut e);
        }
        // Powered and standing in its window past the dwell; the disabled axis too.
        assert!(rests(&k, 0) && rests(&k, 1));
        let st = k.status(0).unwrap();
        assert!(st.power_status && st.in_target_position && st.state == AxisState::Standstill);
        let seq = k.axis(0).unwrap().status_seq();
        let out = sp[0];
        for _ in 0..10 {
            step(&mut k, &mut sp, &mut e);
            assert_eq!(k.status(0).unwrap().nc_cycle_counter, k.cycle);
            assert_eq!(sp[0], out);
        }
        assert_eq!(k.axis(0).unwrap().status_seq(), seq);
        assert_eq!(
            k.status(0).unwrap(),
            AxisStatus {
                nc_cycle_counter: k.cycle,
                ..st
            }
        );
        // A command wakes it: the axis moves in the next cycle.
        let relative = CommandKind::MoveRelative(Positioning {
            position: 5.0,
            velocity: 50.0,
            dynamics: Dynamics::default(),
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        });
        accept(&mut k, 2, 0, relative, &mut e);
        assert!(!rests(&k, 0));
        assert_ne!(k.axis(0).unwrap().status_seq(), seq);
        step(&mut k, &mut sp, &mut e);
        assert!(k.status(0).unwrap().set_position > 0.0 && !rests(&k, 0));
        while k.status(0).unwrap().state != AxisState::Standstill {
            step(&mut k, &mut sp, &mut e);
        }
        for _ in 0..100 {
            step(&mut k, &mut sp, &mut e);
        }
        assert!(rests(&k, 0));
        assert_eq!(k.status(0).unwrap().set_position, 5.0);
        // A new reading (the drive moved by itself, as a real encoder's count can) is read in
        // its cycle.
        let fb = [
            DriveFeedback {
                ready: true,
                enabled: true,
                actual_position: 5.001,
                ..DriveFeedback::default()
            },
            DriveFeedback::default(),
        ];
        k.step(&fb, &mut sp, &mut e);
        assert!(!rests(&k, 0));
        assert_eq!(k.status(0).unwrap().actual_position, 5.001);
    }

    /// The kernel keeps the rest records by slot (`axis/rest.rs`): an axis put into a slot
    /// starts with full steps, whatever rested there before and wherever it rested itself.
    #[test]
    fn an_axis_put_into_a_slot_does_not_repeat_the_rest_of_the_one_before() {
        let mut k = kernel(2);
        let (mut sp, mut e) = (vec![DriveSetpoint::default(); 2], Vec::new());
        accept(&mut k, 1, 0, power(), &mut e);
        for _ in 0..100 {
            step(&mut k, &mut sp, &mut e);
        }
        let rests = |k: &Kernel, a| k.axis(a).unwrap().is_at_rest();
        assert!(rests(&k, 0) && rests(&k, 1) && sp[0].enable && !sp[1].enable);
        // The powered axis moves into the slot of the disabled one.
        let moved = k.remove_axis(0).unwrap();
        let old = k.insert_axis(1, moved).unwrap();
        assert!(old.is_some_and(|a| a.is_at_rest()));
        assert!(!rests(&k, 1));
        // The reading the disabled axis rested on: the powered axis reads it itself, a
        // drive that is not enabled.
        step(&mut k, &mut sp, &mut e);
        assert!(sp[1].enable, "the disabled axis's setpoint was repeated");
        assert_eq!(k.status(1).unwrap().state, AxisState::ErrorStop);
        assert!(!rests(&k, 1));
    }

    fn velocity(velocity: f64) -> CommandKind {
        CommandKind::MoveVelocity {
            velocity,
            dynamics: Dynamics::default(),
            direction: Direction::Positive,
            buffer_mode: BufferMode::Aborting,
            options: MoveOptions::default(),
        }
    }

    fn power() -> CommandKind {
        CommandKind::Power {
            enable: true,
            enable_positive: true,
            enable_negative: true,
            override_percent: 100.0,
            buffer_mode: BufferMode::Aborting,
        }
    }

    /// Issue 27: a moving axis marks the blocks it does not use as idle and skips their
    /// checks and status parts (`axis/idle.rs`); a command for one of them wakes it, and the
    /// block acts from the next cycle as it did before. In debug builds every status update
    /// with a mark also asserts that the block is idle and its status part what the full
    /// update writes.
    #[test]
    fn idle_blocks_wake_with_their_command() {
        let mut k = kernel(1);
        let (mut sp, mut e) = (vec![DriveSetpoint::default(); 1], Vec::new());
        accept(&mut k, 1, 0, power(), &mut e);
        let allow_correction = CommandKind::WriteParameter {
            number: 1046,
            value: 1.0,
        };
        accept(&mut k, 2, 0, allow_correction, &mut e);
        for _ in 0..5 {
            step(&mut k, &mut sp, &mut e);
        }
        let velocity = velocity(10.0);
        accept(&mut k, 3, 0, velocity, &mut e);
        let marks = |k: &Kernel| k.axis(0).unwrap().idle_marks();
        for _ in 0..200 {
            step(&mut k, &mut sp, &mut e);
        }
        let st = k.status(0).unwrap();
        assert!(st.constant_velocity && st.set_velocity == 10.0);
        assert_eq!(marks(&k), 0x1ff, "every block idle while only moving");
        // Backlash compensation on the right flank while travelling positive: −0.5 on the
        // actual position, +0.5 on the drive's setpoint, ramped at 100 units/s.
        let backlash = CommandKind::BacklashCompensation {
            backlash: Some(0.5),
            compensate_in_positive_direction: true,
            ramp: 100.0,
            disable_mode: DisableMode::default(),
        };
        accept(&mut k, 4, 0, backlash, &mut e);
        assert_eq!(marks(&k), 0, "a command wakes every block");
        step(&mut k, &mut sp, &mut e);
        let st = k.status(0).unwrap();
        assert!(st.position_correction.backlash_enabled);
        assert!((st.position_correction.backlash + 0.1).abs() < 1e-9);
        for _ in 0..10 {
            step(&mut k, &mut sp, &mut e);
        }
        let st = k.status(0).unwrap();
        assert_eq!(st.position_correction.backlash, -0.5);
        assert!((sp[0].position - (st.set_position + 0.5)).abs() < 1e-9);
        assert_eq!(marks(&k) & 1, 0, "a commanded correction is not idle");
        // MC_MoveSuperImposed on the moving axis: under way in the next cycle.
        let before = k.status(0).unwrap().set_position;
        let superimposed = CommandKind::MoveSuperImposed(Superposition {
            distance: 2.0,
            velocity_diff: 5.0,
            velocity_process: 10.0,
            length: 10.0,
            ..Superposition::default()
        });
        accept(&mut k, 5, 0, superimposed, &mut e);
        step(&mut k, &mut sp, &mut e);
        let st = k.status(0).unwrap();
        assert!(st.compensating);
        for _ in 0..2000 {
            step(&mut k, &mut sp, &mut e);
        }
        let st = k.status(0).unwrap();
        assert!(
            !st.compensating && st.superimposed_distance == 0.0,
            "{} {}",
            st.compensating,
            st.superimposed_distance
        );
        // Ten units a second for 2001 cycles, and the two units laid on top.
        let laid_on = st.set_position - before - 10.0 * 2001.0 * DT;
        assert!((laid_on - 2.0).abs() < 1e-6, "{laid_on}");
        assert_eq!(marks(&k) & 0b1000, 0b1000, "idle again once done");
    }

    /// The drive-mode block marked idle on a moving axis is still looked at whenever the
    /// drive reports torque mode (§5.7.1's danger note: nothing asked for it, so after the
    /// timeout the axis goes to ErrorStop, 0x70B4), cycle by cycle.
    #[test]
    fn a_drive_in_torque_mode_is_seen_with_every_block_marked_idle() {
        let mut k = kernel(1);
        let (mut sp, mut e) = (vec![DriveSetpoint::default(); 1], Vec::new());
        accept(&mut k, 1, 0, power(), &mut e);
        for _ in 0..5 {
            step(&mut k, &mut sp, &mut e);
        }
        accept(&mut k, 2, 0, velocity(10.0), &mut e);
        for _ in 0..50 {
            step(&mut k, &mut sp, &mut e);
        }
        assert_eq!(k.axis(0).unwrap().idle_marks(), 0x1ff);
        let feedback = |sp: &[DriveSetpoint], mode| {
            vec![DriveFeedback {
                ready: true,
                enabled: sp[0].enable,
                actual_position: sp[0].position,
                mode,
                ..DriveFeedback::default()
            }]
        };
        // Timed from the first cycle in torque mode: the 500th (a sum of 500 × 1 ms just
        // over the 0.5 s timeout) ends it.
        for i in 0..500 {
            let fb = feedback(&sp, crate::DriveMode::Torque);
            k.step(&fb, &mut sp, &mut e);
            let st = k.status(0).unwrap();
            if i < 499 {
                assert_eq!(st.state, AxisState::ContinuousMotion, "cycle {i}");
            } else {
                assert_eq!(st.state, AxisState::ErrorStop);
                assert_eq!(st.error_id, crate::ErrorId::DRIVE_MODE_NOT_REACHED.0);
            }
        }
    }

    /// An axis put into a kernel that has run for a while counts MC_OverrideFilter's quiet
    /// time from the kernel's cycle, also for a call before its first step (it counted from
    /// cycle 0, so the next value applied at once; found by a review).
    #[test]
    fn an_axis_put_into_a_running_kernel_keeps_the_override_filter_quiet_time() {
        let mut k = Kernel::new(DT, 2);
        let (mut sp, mut e) = (vec![DriveSetpoint::default(); 2], Vec::new());
        for _ in 0..10_000 {
            step(&mut k, &mut sp, &mut e);
        }
        k.insert_axis(1, Axis::new(AxisConfig::default(), DT))
            .unwrap();
        let filter = |raw| CommandKind::OverrideFilter {
            raw,
            lower_threshold: 0.0,
            upper_threshold: 32767.0,
            steps: 200,
            recovery_time: 0.15,
        };
        // The first value applies at once (nothing to wait after), before any step.
        accept(&mut k, 1, 1, filter(16383.5), &mut e);
        assert_eq!(k.status(1).unwrap().power_override_percent, 50.0);
        for _ in 0..50 {
            step(&mut k, &mut sp, &mut e);
        }
        accept(&mut k, 2, 1, filter(8191.75), &mut e);
        // 150 ms after the first: 100 cycles more.
        for i in 1..=100 {
            step(&mut k, &mut sp, &mut e);
            let want = if i < 100 { 50.0 } else { 25.0 };
            assert_eq!(
                k.status(1).unwrap().power_override_percent,
                want,
                "cycle {i}"
            );
        }
    }
}
