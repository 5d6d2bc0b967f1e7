//! MC_AxisParameter (spec §6.11.8). SEED VERSION: only the storage fields the kernel reads;
//! the full table, aliases, types, units, ranges and validation are being added.

/// Storage of one axis's parameters. Field names are the snake_case of the canonical
/// (1000-series) Beckhoff name; aliases share a field.
#[derive(Clone, Debug, PartialEq)]
pub struct AxisParameters {
    pub axis_id: f64,
    pub axis_velo_man_slow: f64,
    pub axis_velo_man_fast: f64,
    pub axis_velo_max: f64,
    pub axis_acc: f64,
    pub axis_dec: f64,
    pub axis_jerk: f64,
    pub axis_calibration_velocity_forward: f64,
    pub axis_calibration_velocity_backward: f64,
    pub axis_jog_increment_forward: f64,
    pub axis_jog_increment_backward: f64,
    pub axis_en_min_soft_pos_limit: bool,
    pub axis_min_soft_pos_limit: f64,
    pub axis_en_max_soft_pos_limit: bool,
    pub axis_max_soft_pos_limit: f64,
    pub axis_en_position_lag_monitoring: bool,
    pub axis_max_pos_lag_value: f64,
    pub axis_max_pos_lag_filter_time: f64,
    pub axis_en_position_range_monitoring: bool,
    pub axis_position_range_window: f64,
    pub axis_en_target_position_monitoring: bool,
    pub axis_target_position_window: f64,
    pub axis_target_position_monitoring_time: f64,
    pub axis_en_in_target_timeout: bool,
    pub axis_in_target_timeout: f64,
    pub axis_encoder_modulo_value: f64,
    pub axis_modulo_tolerance_window: f64,
    pub axis_fast_acc: f64,
    pub axis_fast_dec: f64,
    pub axis_fast_jerk: f64,
    pub axis_maximum_acceleration: f64,
    pub axis_maximum_deceleration: f64,
    pub axis_couple_slave_to_actual_values: bool,
    pub axis_allow_motion_cmd_to_slave_axis: bool,
    pub axis_encoder_homing_inv_dir_cam_search: bool,
    pub axis_encoder_homing_inv_dir_sync_search: bool,
    pub axis_encoder_homing_calib_value: f64,
    pub axis_encoder_reference_mode: u32,
    pub axis_cycle_time: f64,
}

impl Default for AxisParameters {
    fn default() -> Self {
        AxisParameters {
            axis_id: 0.0,
            axis_velo_man_slow: 10.0,
            axis_velo_man_fast: 50.0,
            axis_velo_max: 500.0,
            axis_acc: 2500.0,
            axis_dec: 2500.0,
            axis_jerk: 25000.0,
            axis_calibration_velocity_forward: 30.0,
            axis_calibration_velocity_backward: 5.0,
            axis_jog_increment_forward: 1.0,
            axis_jog_increment_backward: 1.0,
            axis_en_min_soft_pos_limit: false,
            axis_min_soft_pos_limit: 0.0,
            axis_en_max_soft_pos_limit: false,
            axis_max_soft_pos_limit: 0.0,
            axis_en_position_lag_monitoring: true,
            axis_max_pos_lag_value: 5.0,
            axis_max_pos_lag_filter_time: 0.02,
            axis_en_position_range_monitoring: true,
            axis_position_range_window: 5.0,
            axis_en_target_position_monitoring: true,
            axis_target_position_window: 0.02,
            axis_target_position_monitoring_time: 0.02,
            axis_en_in_target_timeout: true,
            axis_in_target_timeout: 5.0,
            axis_encoder_modulo_value: 360.0,
            axis_modulo_tolerance_window: 1.0,
            axis_fast_acc: 10000.0,
            axis_fast_dec: 10000.0,
            axis_fast_jerk: 100000.0,
            axis_maximum_acceleration: 10000.0,
            axis_maximum_deceleration: 10000.0,
            axis_couple_slave_to_actual_values: false,
            axis_allow_motion_cmd_to_slave_axis: false,
            axis_encoder_homing_inv_dir_cam_search: false,
            axis_encoder_homing_inv_dir_sync_search: false,
            axis_encoder_homing_calib_value: 0.0,
            axis_encoder_reference_mode: 0,
            axis_cycle_time: 0.001,
        }
    }
}

impl AxisParameters {
    /// TEMPORARY (kernel worktree): replaced by the full table's set_raw.
    pub fn set_raw(&mut self, _number: u16, _value: f64) {}
}
