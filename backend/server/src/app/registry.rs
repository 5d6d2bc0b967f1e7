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
    pub fn by_slot(&self, slot: AxisSlot) -> Option<&AxisEntry> {
        self.axes.values().find(|a| a.slot == slot)
    }
    pub fn free_slot(&self) -> Option<AxisSlot> {
        (0..MAX_AXES as AxisSlot).find(|s| self.axes.values().all(|a| a.slot != *s))
    }
}
