//! What the cam coupling blocks take (MC_CamIn, MC_CamScaling) and report (MC_CamInfo), and
//! the kernel's store of built cams. The coupling law itself is `axis/camming.rs`.

use std::sync::Arc;

use super::{Cam, InterpolationType};
use serde::{Deserialize, Serialize};

/// `MC_StartMode`: absolute or relative, for master and slave (spec §1.6). Relative places the
/// origin of the cam's coordinates (raw 0) at the axis's position when the cam takes effect.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum StartMode {
    /// 1: master and slave absolute.
    #[default]
    Absolute,
    /// 2: master and slave relative.
    Relative,
    /// 3: master absolute, slave relative.
    MasterAbsSlaveRel,
    /// 4: master relative, slave absolute.
    MasterRelSlaveAbs,
    /// PLCopen `ramp_in` (not in TwinCAT's MC_StartMode): master and slave absolute; a slave
    /// that is not where the cam puts it catches up with the `ramp_in` dynamics instead of
    /// being refused (decision 75).
    RampIn,
    /// PLCopen `ramp_in_pos`: as `ramp_in`, catching up forwards only (the cam position taken
    /// modulo AxisEncoderModuloValue ahead of the slave).
    RampInPositive,
    /// PLCopen `ramp_in_neg`: as `ramp_in`, catching up backwards only.
    RampInNegative,
}

impl StartMode {
    pub fn master_relative(self) -> bool {
        matches!(self, StartMode::Relative | StartMode::MasterRelSlaveAbs)
    }
    pub fn slave_relative(self) -> bool {
        matches!(self, StartMode::Relative | StartMode::MasterAbsSlaveRel)
    }
    /// The slave ramps in to the cam (PLCopen ramp-in start modes).
    pub fn ramp_in(self) -> bool {
        matches!(
            self,
            StartMode::RampIn | StartMode::RampInPositive | StartMode::RampInNegative
        )
    }
}

/// How a ramp-in start mode catches the slave up with its cam: limits of the slave's deviation
/// from the cam position (relative to the cam's own motion). `velocity` must be given for a
/// ramp-in; acceleration, deceleration and jerk 0 mean the axis defaults (#1004–#1006).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[cfg_attr(feature = "schema", schema(example = json!({"velocity": 50.0, "acceleration": 500.0})))]
#[serde(default, deny_unknown_fields)]
pub struct RampIn {
    pub velocity: f64,
    pub acceleration: f64,
    pub deceleration: f64,
    pub jerk: f64,
}

/// `MC_CamActivationMode` (spec §1.7): when a coupling, a cam switch or a scaling takes effect.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum CamActivationMode {
    /// 0: at once.
    #[default]
    Instantaneous,
    /// 1: when the master passes `activation_position` in raw cam coordinates (periodic cams:
    /// at its next occurrence in any cycle).
    AtMasterCamPos,
    /// 2: when the master axis passes `activation_position` (either direction).
    AtMasterAxisPos,
    /// 3: at the next cycle border of a periodic cam (linear cams: at an end of its range).
    NextCycle,
    /// 4: not implemented in TwinCAT either (refused).
    NextCycleOnce,
    /// 5: for online changes of motion-function data (refused for couplings and scalings).
    AsSoonAsPossible,
    /// 6: MC_CamScaling: no scaling is done.
    Off,
    /// 7: MC_CamIn while coupled: drops a queued cam switch.
    DeleteQueuedData,
    /// 8: when the master axis passes `activation_position` moving positive.
    AtMasterAxisPosPositiveDirection,
    /// 9: when the master axis passes `activation_position` moving negative.
    AtMasterAxisPosNegativeDirection,
}

/// `MC_CamScalingMode` (spec §1.8), per axis.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum CamScalingMode {
    /// 0: offset and scaling as given.
    #[default]
    UserDefined,
    /// 1: scaling as given, the offset computed so that the position does not jump (master:
    /// the relative position in the cycle is kept).
    AutoOffset,
    /// 2: this axis's scaling and offset stay as they are.
    Off,
}

/// MC_CamIn: couple the axis to `master` through cam table `cam_table`, or switch the cam of
/// a coupled slave.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CamIn {
    pub master: crate::AxisSlot,
    pub cam_table: u32,
    pub master_offset: f64,
    pub slave_offset: f64,
    pub master_scaling: f64,
    pub slave_scaling: f64,
    pub start_mode: StartMode,
    pub activation_mode: CamActivationMode,
    pub activation_position: f64,
    pub master_scaling_mode: CamScalingMode,
    pub slave_scaling_mode: CamScalingMode,
    /// `ST_CamInOptions.InterpolationType`: how this coupling interpolates a position table
    /// (`None`: the table's own; motion functions ignore it).
    pub interpolation: Option<InterpolationType>,
    /// The catch-up of a ramp-in start mode (ignored by the others).
    pub ramp_in: RampIn,
}

/// MC_CamScaling: new offsets and scalings of the coupling.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CamScaling {
    pub activation_mode: CamActivationMode,
    pub activation_position: f64,
    pub master_scaling_mode: CamScalingMode,
    pub slave_scaling_mode: CamScalingMode,
    pub master_offset: f64,
    pub slave_offset: f64,
    pub master_scaling: f64,
    pub slave_scaling: f64,
}

/// `MC_CamOperationMode` (spec §1.9): what MC_CamIn_V2 does on a multi-cam slave.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(rename_all = "snake_case")]
pub enum CamOperationMode {
    /// 0: as `additive`.
    #[default]
    Default,
    /// 1: couples (the first call) or adds a cam.
    Additive,
    /// 2: replaces the reference cam.
    Exchange,
    /// 3: removes the cam.
    Remove,
}

/// `ST_CamScalingData` (spec §3.19): one cam's offsets and scalings in a multi-cam coupling.
/// Relative: from the axis position at activation (for the slave of an added cam: its
/// contribution starts at 0 there); absolute: from axis position 0.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct CamScalingData {
    #[serde(default)]
    pub master_scaling_mode: CamScalingMode,
    #[serde(default)]
    pub master_relative: bool,
    #[serde(default)]
    #[cfg_attr(feature = "schema", schema(minimum = -1e12, maximum = 1e12))]
    pub master_offset: f64,
    #[serde(default = "unit")]
    #[cfg_attr(feature = "schema", schema(minimum = -1e12, maximum = 1e12))]
    pub master_scaling: f64,
    #[serde(default)]
    pub slave_scaling_mode: CamScalingMode,
    #[serde(default)]
    pub slave_relative: bool,
    #[serde(default)]
    #[cfg_attr(feature = "schema", schema(minimum = -1e12, maximum = 1e12))]
    pub slave_offset: f64,
    #[serde(default = "unit")]
    #[cfg_attr(feature = "schema", schema(minimum = -1e12, maximum = 1e12))]
    pub slave_scaling: f64,
}

fn unit() -> f64 {
    1.0
}

impl Default for CamScalingData {
    fn default() -> Self {
        CamScalingData {
            master_scaling_mode: CamScalingMode::UserDefined,
            master_relative: false,
            master_offset: 0.0,
            master_scaling: 1.0,
            slave_scaling_mode: CamScalingMode::UserDefined,
            slave_relative: false,
            slave_offset: 0.0,
            slave_scaling: 1.0,
        }
    }
}

/// MC_CamIn_V2 (and MC_CamAdd, MC_CamExchange, MC_CamRemove): couple with one cam, then add,
/// exchange or remove cams superimposed on the slave.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CamInV2 {
    pub master: crate::AxisSlot,
    pub cam_table: u32,
    pub activation_mode: CamActivationMode,
    pub activation_position: f64,
    pub scaling: CamScalingData,
    pub operation: CamOperationMode,
    /// The cam an exchange replaces (0: the only one).
    pub reference_cam_table: u32,
    /// `ST_CamInOptions_V2.InterpolationType` (`None`: the table's own).
    pub interpolation: Option<InterpolationType>,
}

/// MC_CamScaling_V2: new offsets and scalings of one cam of the slave (0: the only one).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CamScalingV2 {
    pub cam_table: u32,
    pub activation_mode: CamActivationMode,
    pub activation_position: f64,
    pub scaling: CamScalingData,
}

/// One cam of a multi-cam slave (MC_CamInfo_V2's per-cam values).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct CamTerm {
    /// 0: no cam in this place.
    pub cam_table_id: u32,
    pub master_offset: f64,
    pub slave_offset: f64,
    pub master_scaling: f64,
    pub slave_scaling: f64,
    pub actual_master_cam_pos: f64,
    pub actual_slave_cam_pos: f64,
    /// This cam's share of the slave position (axis units).
    pub slave_contribution: f64,
    /// Strokes this cam added since its base cycle, in slave axis units.
    pub sum_of_slave_strokes: f64,
    /// How this coupling interpolates its position table (its own choice or the table's;
    /// `linear` for a motion function, whose laws decide).
    pub interpolation: InterpolationType,
}

/// MC_CamInfoData of a cam slave (spec §3.5): the coupling as it is in this cycle. Cam
/// positions are raw (unscaled); axis positions are set positions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct CamInfo {
    /// The coupling is in force. False with a `cam_table_id`: the last valid state of a
    /// coupling that an error (or another command than MC_CamOut) ended — MC_CamInfo's data
    /// to restore it.
    pub active: bool,
    /// The cam table (0: never coupled through a cam, or decoupled by MC_CamOut).
    pub cam_table_id: u32,
    pub periodic: bool,
    /// Kernel slot of the master (the server names the axis instead).
    #[serde(skip)]
    pub master_axis: u16,
    pub master_cam_start_pos: f64,
    pub slave_cam_start_pos: f64,
    pub raw_master_period: f64,
    pub raw_slave_stroke: f64,
    pub master_axis_coupling_pos: f64,
    pub slave_axis_coupling_pos: f64,
    pub master_absolute: bool,
    pub slave_absolute: bool,
    /// Total offsets and scalings (relative start modes included).
    pub master_offset: f64,
    pub slave_offset: f64,
    pub master_scaling: f64,
    pub slave_scaling: f64,
    /// Strokes added since the coupling's base cycle, in slave axis units.
    pub sum_of_slave_strokes: f64,
    pub sum_of_superposition_distance: f64,
    pub actual_master_axis_pos: f64,
    pub actual_slave_axis_pos: f64,
    pub actual_master_cam_pos: f64,
    pub actual_slave_cam_pos: f64,
    pub scaling_pending: bool,
    pub scaling_activation_mode: CamActivationMode,
    pub scaling_activation_pos: f64,
    pub cam_data_queued: bool,
    pub cam_table_queued: bool,
    pub cam_exchange_cam_table_id: u32,
    pub cam_exchange_activation_mode: CamActivationMode,
    pub cam_exchange_activation_pos: f64,
    /// Coupled by MC_CamIn_V2 (multi-cam).
    pub multi_cam: bool,
    /// The cams superimposed on the slave, the base first (MC_CamIn: one).
    pub cams: [CamTerm; 4],
}

/// The activation modes an online change takes (the document's view of
/// [`CamActivationMode`]: `next_cycle_once` is refused, as TwinCAT does not implement it).
#[cfg(feature = "schema")]
#[derive(Serialize, utoipa::ToSchema)]
#[serde(rename_all = "snake_case")]
#[allow(
    dead_code,
    reason = "only its schema is used: the OpenAPI document's enum of the modes"
)]
pub enum OnlineActivationMode {
    Instantaneous,
    AtMasterCamPos,
    AtMasterAxisPos,
    NextCycle,
    AsSoonAsPossible,
    Off,
    DeleteQueuedData,
    AtMasterAxisPosPositiveDirection,
    AtMasterAxisPosNegativeDirection,
}

/// MC_SetCamOnlineChangeMode (spec §1.10, §2.14): when data written to a coupled table takes
/// effect on its slaves, and how their offsets follow.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[serde(deny_unknown_fields)]
pub struct OnlineChange {
    /// `instantaneous` and `as_soon_as_possible`: in the first cycle the new data does not
    /// move the slave; `at_master_cam_pos`, `at_master_axis_pos…`, `next_cycle`: from there
    /// (and still only without a jump); `off`: coupled slaves keep the data they run with.
    #[serde(default)]
    #[cfg_attr(feature = "schema", schema(value_type = OnlineActivationMode))]
    pub activation_mode: CamActivationMode,
    #[serde(default)]
    pub activation_position: f64,
    #[serde(default)]
    pub master_scaling_mode: CamScalingMode,
    #[serde(default)]
    pub slave_scaling_mode: CamScalingMode,
}

/// One table id's cams: the one in force (`cur`) and, after an online change, the one its
/// slaves still run until the change takes effect on them (`old`). Each has a generation.
#[derive(Default)]
struct Slot {
    cur: Option<(u32, Arc<Cam>)>,
    old: Option<(u32, Arc<Cam>)>,
    next_gen: u32,
}

/// The built cams the kernel couples through, by cam table id (1..255), shared with whoever
/// built them (the server's analysis reads the same cam). Put in and taken out by requests
/// between cycles and handed back, so the cycle never frees one: a cam its last slave left is
/// kept in `retired` until the owner of the kernel takes it.
pub struct CamStore {
    slots: Vec<Slot>,
    retired: Vec<Arc<Cam>>,
    /// Some slot holds an `old` cam (worth looking for slaves that left it).
    has_old: bool,
}

/// The highest cam table id (MC_CAM_ID).
pub const MAX_CAM_TABLE_ID: u32 = 255;

impl Default for CamStore {
    fn default() -> Self {
        CamStore {
            slots: (0..=MAX_CAM_TABLE_ID).map(|_| Slot::default()).collect(),
            // One old cam per id at most: retiring never reallocates.
            retired: Vec::with_capacity(MAX_CAM_TABLE_ID as usize + 1),
            has_old: false,
        }
    }
}

impl CamStore {
    /// The cam in force under `id`.
    pub fn get(&self, id: u32) -> Option<&Cam> {
        self.slots
            .get(id as usize)
            .and_then(|s| s.cur.as_ref())
            .map(|(_, c)| &**c)
    }

    /// The generation of the cam in force (what a new coupling runs).
    pub fn generation(&self, id: u32) -> u32 {
        self.slots
            .get(id as usize)
            .and_then(|s| s.cur.as_ref())
            .map_or(0, |(g, _)| *g)
    }

    /// The cam of `id` in generation `generation` (in force, or the one before an online change).
    pub fn get_gen(&self, id: u32, generation: u32) -> Option<&Cam> {
        let s = self.slots.get(id as usize)?;
        [&s.cur, &s.old]
            .into_iter()
            .flatten()
            .find(|(g, _)| *g == generation)
            .map(|(_, c)| &**c)
    }

    /// Puts a cam under `id` in place of the one in force, handing that back; `Err` gives it
    /// back for an id outside 1..255.
    pub fn insert(&mut self, id: u32, cam: Arc<Cam>) -> Result<Option<Arc<Cam>>, Arc<Cam>> {
        match self.slots.get_mut(id as usize) {
            Some(s) if id >= 1 => {
                s.next_gen += 1;
                Ok(s.cur.replace((s.next_gen, cam)).map(|(_, c)| c))
            }
            _ => Err(cam),
        }
    }

    /// Makes `cam` the one in force while the slaves of the present one keep it until the
    /// change reaches them. When slaves still run an older generation by choice (the change
    /// was dropped with DELETEQUEUEDDATA, or the mode was OFF) and nobody runs the present one
    /// (`cur_in_use` false), the present one is retired and the older stays for its slaves.
    /// `Err` when both generations held are in use (a third cannot be held). Returns the
    /// generation of the new cam.
    pub fn stage(&mut self, id: u32, cam: Arc<Cam>, cur_in_use: bool) -> Result<u32, Arc<Cam>> {
        match self.slots.get_mut(id as usize) {
            Some(s) if id >= 1 && s.old.is_none() && s.cur.is_some() => {
                s.next_gen += 1;
                s.old = s.cur.replace((s.next_gen, cam));
                self.has_old = true;
                Ok(s.next_gen)
            }
            Some(s) if id >= 1 && s.old.is_some() && !cur_in_use => {
                s.next_gen += 1;
                let unused = s.cur.replace((s.next_gen, cam));
                let generation = s.next_gen;
                if let Some((_, c)) = unused {
                    self.retire(c);
                }
                Ok(generation)
            }
            _ => Err(cam),
        }
    }

    /// Slaves run an older generation of `id` than the one in force.
    pub fn has_old(&self, id: u32) -> bool {
        self.slots.get(id as usize).is_some_and(|s| s.old.is_some())
    }

    pub fn remove(&mut self, id: u32) -> Option<Arc<Cam>> {
        let s = self.slots.get_mut(id as usize)?;
        let old = s.old.take();
        let cur = s.cur.take().map(|(_, c)| c);
        if let Some((_, old)) = old {
            self.retire(old);
        }
        cur
    }

    /// Retires old cams no slave runs any more (`in_use(id, generation)`); allocation-free.
    pub fn retire_unused(&mut self, in_use: impl Fn(u32, u32) -> bool) {
        if !self.has_old {
            return;
        }
        let mut any = false;
        for (id, s) in self.slots.iter_mut().enumerate() {
            if let Some((generation, _)) = s.old {
                if in_use(id as u32, generation) {
                    any = true;
                } else if let Some((_, c)) = s.old.take() {
                    if self.retired.len() < self.retired.capacity() {
                        self.retired.push(c);
                    } else {
                        core::mem::forget(c);
                    }
                }
            }
        }
        self.has_old = any;
    }

    /// Keeps a cam the kernel replaced until its owner takes it.
    pub fn retire(&mut self, cam: Arc<Cam>) {
        if self.retired.len() < self.retired.capacity() {
            self.retired.push(cam);
        } else {
            // Never free (or grow) in the cycle: the owner has not collected for a long time.
            core::mem::forget(cam);
        }
    }

    /// A cam the kernel no longer uses, to be freed off the cycle thread.
    pub fn take_retired(&mut self) -> Option<Arc<Cam>> {
        self.retired.pop()
    }
}
