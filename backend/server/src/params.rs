//! MC_AxisParameter access: the kernel's table (`motion::params`) re-exported, plus the few
//! helpers the service needs.

pub use motion::params::{
    PARAMETERS, ParamIssue, ParamType, ParamValue, ParameterInfo, by_name, by_number, lookup,
};
use motion::{AxisParameters, AxisStatus, ErrorId};

pub fn read(p: &AxisParameters, number: u16, status: &AxisStatus) -> Result<ParamValue, ErrorId> {
    p.read(number, status)
}

pub fn set(p: &mut AxisParameters, number: u16, value: ParamValue) -> Result<(), ErrorId> {
    p.set(number, value)
}

pub fn validate(p: &AxisParameters) -> Result<(), ParamIssue> {
    p.validate()
}

/// Parameters the system assigns (axis id, cycle times).
pub fn assign_system(p: &mut AxisParameters, axis_id: i64, cycle_time: f64) {
    p.set_raw(1000, axis_id as f64);
    for n in [1050, 4000, 4001] {
        p.set_raw(n, cycle_time);
    }
}
