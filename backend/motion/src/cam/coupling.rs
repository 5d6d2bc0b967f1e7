//! What the cam coupling blocks take (MC_CamIn, MC_CamScaling) and report (MC_CamInfo), and
//! the kernel's store of built cams. The coupling law itself is `axis/camming.rs`.

use std::sync::Arc;

use super::Cam;
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
}

impl StartMode {
    pub fn master_relative(self) -> bool {
        matches!(self, StartMode::Relative | StartMode::MasterRelSlaveAbs)
    }
    pub fn slave_relative(self) -> bool {
        matches!(self, StartMode::Relative | StartMode::MasterAbsSlaveRel)
    }
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

/// MC_CamInfoData of a cam slave (spec §3.5): the coupling as it is in this cycle. Cam
/// positions are raw (unscaled); axis positions are set positions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
pub struct CamInfo {
    /// The active cam table (0: not coupled through a cam).
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
}

/// The built cams the kernel couples through, by cam table id (1..255), shared with whoever
/// built them (the server's analysis reads the same cam). Put in and taken out by requests
/// between cycles and handed back, so the cycle never frees one.
pub struct CamStore {
    slots: Vec<Option<Arc<Cam>>>,
}

/// The highest cam table id (MC_CAM_ID).
pub const MAX_CAM_TABLE_ID: u32 = 255;

impl Default for CamStore {
    fn default() -> Self {
        CamStore {
            slots: (0..=MAX_CAM_TABLE_ID).map(|_| None).collect(),
        }
    }
}

impl CamStore {
    pub fn get(&self, id: u32) -> Option<&Cam> {
        self.slots.get(id as usize).and_then(|c| c.as_deref())
    }

    /// Puts a cam under `id`, handing back the one it replaces; `Err` gives it back for an
    /// id outside 1..255.
    pub fn insert(&mut self, id: u32, cam: Arc<Cam>) -> Result<Option<Arc<Cam>>, Arc<Cam>> {
        match self.slots.get_mut(id as usize) {
            Some(s) if id >= 1 => Ok(s.replace(cam)),
            _ => Err(cam),
        }
    }

    pub fn remove(&mut self, id: u32) -> Option<Arc<Cam>> {
        self.slots.get_mut(id as usize).and_then(|s| s.take())
    }
}
