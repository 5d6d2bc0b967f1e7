//! Scenario tests in virtual time, one module per section of the Tc2_MC2 digest
//! (`spec/axis-motion-tc2-mc2.md`): `s3_8_buffer_modes` holds §3.8, and so on. Test names
//! carry the spec §11a item they cover (`s11a_NN_…`); every cycle of every test also runs the
//! rig's invariant checks. Item 32 (parameters by number, aliases) is in `tests/params.rs`;
//! item 33 (persistent writes survive a restart) has no kernel meaning — persistence is the
//! server's.

#[path = "../rig/mod.rs"]
mod rig;

mod cam_couplings;
mod groups_tf5420;
mod rig_checks;
mod s2_state_diagram;
mod s3_10_slave_axes;
mod s3_11_done_criterion;
mod s3_8_buffer_modes;
mod s3_fb_protocol;
mod s4_3_touch_probe;
mod s4_4_external_setpoints;
mod s4_5_compensation;
mod s4_organisation;
mod s5_1_point_to_point;
mod s5_2_superposition;
mod s5_3_homing;
mod s5_4_jog;
mod s5_5_4_multi_master;
mod s5_5_coupling;
mod s5_6_phasing;
mod s5_7_torque_control;
mod s8_3_fault_behaviour;

use motion::*;
use rig::*;

fn power(r: &mut Rig) -> CommandId {
    r.power_on(0)
}
