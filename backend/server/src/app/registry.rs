//! The axes the async side knows: id, name, slot, configuration and parameter mirrors.

use std::collections::BTreeMap;

use motion::{AxisParameters, AxisSlot};

use crate::cycle::MAX_AXES;
use crate::model::AxisConfigDto;
use crate::params::ParamValue;

pub struct AxisEntry {
    pub id: i64,
    pub name: String,
    pub slot: AxisSlot,
    pub config: AxisConfigDto,
    /// Mirror of the parameters active in the kernel (base + persistent + runtime writes).
    pub params: AxisParameters,
    /// The persistent overlay.
    pub persistent: BTreeMap<u16, ParamValue>,
}

#[derive(Default)]
pub struct Registry {
    pub axes: BTreeMap<i64, AxisEntry>,
    /// Cam tables by id (MC_CAM_ID).
    pub cams: BTreeMap<u32, CamEntry>,
    /// Axis groups by id (1..16; the kernel's group slot is id − 1).
    pub groups: BTreeMap<i64, GroupEntry>,
}

/// A configured axis group (TF5420 CM group).
#[derive(Clone, Debug)]
pub struct GroupEntry {
    pub id: i64,
    pub name: String,
    /// The kernel's group slot (`id − 1`).
    pub slot: motion::group::GroupId,
    pub config: motion::group::GroupConfig,
    /// The configured members: role and axis id, added with MC_AddAxisToGroup whenever the
    /// group is put into the kernel.
    pub members: Vec<(motion::group::GroupRole, i64)>,
    pub updated_at: String,
}

/// A stored cam table: its definition and the cam built from it (shared with couplings).
#[derive(Clone, Debug)]
pub struct CamEntry {
    pub id: u32,
    pub name: String,
    pub version: i64,
    pub data: std::sync::Arc<motion::cam::CamTableData>,
    pub cam: std::sync::Arc<motion::cam::Cam>,
    pub updated_at: String,
    /// MC_SetCamOnlineChangeMode: how later writes reach coupled slaves (runtime, like the
    /// couplings; INSTANTANEOUS after a start).
    pub online: motion::cam::OnlineChange,
}

impl Registry {
    /// By id (all digits) or by name.
    pub fn find(&self, key: &str) -> Option<&AxisEntry> {
        match key.parse::<i64>() {
            Ok(id) => self.axes.get(&id),
            Err(_) => self.axes.values().find(|a| a.name == key),
        }
    }
    pub fn find_mut(&mut self, key: &str) -> Option<&mut AxisEntry> {
        match key.parse::<i64>() {
            Ok(id) => self.axes.get_mut(&id),
            Err(_) => self.axes.values_mut().find(|a| a.name == key),
        }
    }
    /// A cam table by id (all digits) or by name.
    pub fn find_cam(&self, key: &str) -> Option<&CamEntry> {
        match key.parse::<u32>() {
            Ok(id) => self.cams.get(&id),
            Err(_) => self.cams.values().find(|c| c.name == key),
        }
    }
    /// A group by id (all digits) or by name.
    pub fn find_group(&self, key: &str) -> Option<&GroupEntry> {
        match key.parse::<i64>() {
            Ok(id) => self.groups.get(&id),
            Err(_) => self.groups.values().find(|g| g.name == key),
        }
    }
    /// The group that has `axis` (an axis id) among its configured members.
    pub fn group_of_axis(&self, axis: i64) -> Option<&GroupEntry> {
        self.groups
            .values()
            .find(|g| g.members.iter().any(|(_, a)| *a == axis))
    }
    pub fn by_slot(&self, slot: AxisSlot) -> Option<&AxisEntry> {
        self.axes.values().find(|a| a.slot == slot)
    }
    pub fn free_slot(&self) -> Option<AxisSlot> {
        (0..MAX_AXES as AxisSlot).find(|s| self.axes.values().all(|a| a.slot != *s))
    }
}
