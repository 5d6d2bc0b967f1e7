//! The demo machine that a new motiond (empty database, no `--no-demo`) configures, and the
//! examples of the OpenAPI document show.

use std::collections::BTreeMap;

use drives::DriveConfig;

use super::{AxisConfigDto, AxisDynamics, ModuloConfig, SoftLimits};
use crate::params::ParamValue;
use crate::sim::{LimitSwitches, SimDriveConfig};

/// The demo machine: two linear axes with limit switches just outside their travel (so that a
/// homing search that misses the cam ends with homing_failed at a switch instead of running
/// forever; the switches only report, they do not fault the drive) and a rotary spindle.
pub fn axes() -> Vec<AxisConfigDto> {
    let linear = |name: &str, limits: Option<SoftLimits>, switches: (f64, f64)| AxisConfigDto {
        name: name.into(),
        unit: "mm".into(),
        modulo: None,
        soft_limits: limits,
        dynamics: AxisDynamics {
            max_velocity: 500.0,
            acceleration: 2500.0,
            deceleration: 2500.0,
            jerk: 25000.0,
            jog_velocity_slow: 10.0,
            jog_velocity_fast: 100.0,
            jog_deadman_max: 1.0,
        },
        parameters: BTreeMap::from([(
            "AxisTargetPositionWindow".to_string(),
            ParamValue::Number(0.01),
        )]),
        drive: DriveConfig::Simulated(SimDriveConfig {
            limit_switches: LimitSwitches {
                negative: Some(switches.0),
                positive: Some(switches.1),
                fault_on_hit: false,
            },
            ..SimDriveConfig::default()
        }),
        position_compensation_table: None,
    };
    vec![
        // Travel 0–1000 mm (software limits), switches 5 mm beyond.
        linear(
            "x",
            Some(SoftLimits {
                min: 0.0,
                max: 1000.0,
            }),
            (-5.0, 1005.0),
        ),
        // No software limits; travel ±1000 mm between the switches.
        linear("y", None, (-1005.0, 1005.0)),
        AxisConfigDto {
            name: "spindle".into(),
            unit: "deg".into(),
            modulo: Some(ModuloConfig { period: 360.0 }),
            soft_limits: None,
            dynamics: AxisDynamics {
                max_velocity: 3600.0,
                acceleration: 18000.0,
                deceleration: 18000.0,
                jerk: 180000.0,
                jog_velocity_slow: 90.0,
                jog_velocity_fast: 720.0,
                jog_deadman_max: 1.0,
            },
            parameters: BTreeMap::new(),
            drive: DriveConfig::default(),
            position_compensation_table: None,
        },
    ]
}

/// The demo machine on the emulated EtherCAT segment: each axis's drive is the emulated
/// CiA-402 servo at its position (1 µm per increment on the linear axes, 0.01° on the spindle),
/// motiond running the profile (CSP); and a fourth axis, `feeder` (0–500 mm), whose drive runs
/// the profile itself (profile position, profile velocity, homing method 1 on its negative
/// limit switch and index pulse).
pub fn on_emulated_drives(axes: &mut Vec<AxisConfigDto>) {
    for (i, a) in axes.iter_mut().enumerate() {
        a.drive = DriveConfig::Cia402(drives::cia402::Cia402Config::csp(
            i as u16,
            if a.modulo.is_some() { 100.0 } else { 1000.0 },
        ));
    }
    let mut feeder = axes[0].clone();
    feeder.name = "feeder".into();
    feeder.soft_limits = Some(SoftLimits {
        min: 0.0,
        max: 500.0,
    });
    feeder.dynamics = AxisDynamics {
        max_velocity: 200.0,
        acceleration: 1000.0,
        deceleration: 1000.0,
        jerk: 10_000.0,
        jog_velocity_slow: 10.0,
        jog_velocity_fast: 50.0,
        // Room for a client on a slow link to renew a jog (its own deadman_timeout decides).
        jog_deadman_max: 5.0,
    };
    feeder.drive = DriveConfig::Cia402(drives::cia402::Cia402Config {
        profile: drives::cia402::ProfileSide::Drive,
        homing_method: Some(1),
        ..drives::cia402::Cia402Config::csp(3, 1000.0)
    });
    axes.push(feeder);
}

/// The demo machine's group `xy`: axes `x` (role x) and `y` (role y) in the XY convention,
/// disabled, with the default dynamics (within what both axes can do: 500 mm/s, 2500 mm/s²).
pub fn group() -> super::GroupBody {
    let member = |role, axis: &str| super::GroupMemberBody {
        role,
        axis: axis.into(),
    };
    let config = motion::group::GroupConfig::default();
    super::GroupBody {
        id: None,
        name: "xy".into(),
        convention: motion::group::AxesConvention::Xy,
        additional_axes: 0,
        axes: vec![
            member(motion::group::GroupRole::X, "x"),
            member(motion::group::GroupRole::Y, "y"),
        ],
        default_dynamics: config.default_dynamics,
        maximum_dynamics: motion::group::PathDynamics {
            velocity: 500.0,
            acceleration: 2500.0,
            deceleration: 2500.0,
            jerk: 25_000.0,
        },
        override_ramp_time: config.override_ramp_time,
    }
}
