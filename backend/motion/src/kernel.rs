//! The kernel: a fixed number of axis slots stepped together, masters before their slaves.

use crate::axis::{Axis, Master, MasterSample};
use crate::command::{AxisSlot, Command, CommandKind, EventSink, Verdict};
use crate::drive::{DriveFeedback, DriveSetpoint};
use crate::error::ErrorId;
use crate::params::AxisParameters;
use crate::status::AxisStatus;

/// All axes of one machine. Capacity is fixed at construction so that the cycle never
/// allocates; axes are built off the cycle thread and handed in as `Box<Axis>`.
pub struct Kernel {
    cycle_time: f64,
    cycle: u64,
    axes: Vec<Option<Box<Axis>>>,
    stepped: Vec<bool>,
}

impl Kernel {
    /// `cycle_time` in seconds; `max_axes` slots.
    pub fn new(cycle_time: f64, max_axes: usize) -> Self {
        assert!(cycle_time > 0.0 && cycle_time.is_finite());
        Kernel {
            cycle_time,
            cycle: 0,
            axes: (0..max_axes).map(|_| None).collect(),
            stepped: vec![false; max_axes],
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
        match self.axes.get_mut(slot as usize) {
            Some(s) => {
                axis.place(slot);
                Ok(s.replace(axis))
            }
            None => Err(axis),
        }
    }

    /// Takes an axis out of its slot (to be freed off the cycle thread). Slaves coupled to
    /// it lose their master at the next step.
    pub fn remove_axis(&mut self, slot: AxisSlot) -> Option<Box<Axis>> {
        self.axes.get_mut(slot as usize).and_then(|s| s.take())
    }

    pub fn axis(&self, slot: AxisSlot) -> Option<&Axis> {
        self.axes.get(slot as usize).and_then(|a| a.as_deref())
    }

    pub fn status(&self, slot: AxisSlot) -> Option<AxisStatus> {
        self.axis(slot).map(|a| *a.status())
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

    /// Offers a command to its axis in the current cycle (before [`Kernel::step`]). The
    /// verdict is immediate; an accepted command changes the axis state at once and its
    /// outputs follow as events (the first one in this call).
    pub fn submit(&mut self, cmd: Command, events: &mut impl EventSink) -> Verdict {
        let slot = cmd.axis as usize;
        let master = match cmd.kind {
            CommandKind::GearIn { master, .. } | CommandKind::GearInDyn { master, .. } => {
                if master as usize == slot {
                    return Verdict::Rejected(ErrorId::MASTER_INVALID);
                }
                // A master that (through its own masters) follows this axis would close a loop.
                let mut m = Some(master);
                for _ in 0..self.axes.len() {
                    match m {
                        Some(x) if x as usize == slot => {
                            return Verdict::Rejected(ErrorId::MASTER_INVALID);
                        }
                        Some(x) => m = self.axis(x).and_then(|a| a.master_slot()),
                        None => break,
                    }
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
            Some(axis) => axis.submit(cmd, master, cycle, events),
            None => Verdict::Rejected(ErrorId::AXIS_UNKNOWN),
        }
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
        self.cycle += 1;
        let cycle = self.cycle;
        let dt = self.cycle_time;
        self.stepped.iter_mut().for_each(|s| *s = false);
        // Masters first, then slaves whose master has been stepped (chains resolve in as
        // many passes as they are long; submit rejects couplings that would close a loop).
        for _pass in 0..self.axes.len().max(1) {
            let mut progressed = false;
            for i in 0..self.axes.len() {
                if self.stepped[i] {
                    continue;
                }
                let Some(axis) = self.axes[i].as_deref() else {
                    self.stepped[i] = true;
                    continue;
                };
                let master = match axis.master_slot() {
                    None => Master::Uncoupled,
                    Some(m) => match self.axes.get(m as usize).and_then(|a| a.as_deref()) {
                        None => Master::Lost, // master vanished
                        Some(ma) if self.stepped[m as usize] => {
                            Master::Sample(MasterSample::of(ma))
                        }
                        Some(_) => continue, // wait for the master
                    },
                };
                let fb = feedback.get(i).copied().unwrap_or_default();
                let axis = self.axes[i].as_deref_mut().expect("checked above");
                let sp = axis.step(dt, &fb, master, cycle, events);
                if let Some(out) = setpoints.get_mut(i) {
                    *out = sp;
                }
                self.stepped[i] = true;
                progressed = true;
            }
            if !progressed {
                break;
            }
        }
        // Anything left is part of a coupling cycle: step it without its master.
        for i in 0..self.axes.len() {
            if !self.stepped[i] {
                let fb = feedback.get(i).copied().unwrap_or_default();
                if let Some(axis) = self.axes[i].as_deref_mut() {
                    let sp = axis.step(dt, &fb, Master::Lost, cycle, events);
                    if let Some(out) = setpoints.get_mut(i) {
                        *out = sp;
                    }
                }
            }
        }
    }
}
