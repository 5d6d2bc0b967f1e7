//! The simulated servo drive: a position-controlled axis in CSP mode, as the kernel sees a
//! real CiA-402 drive over the bus, without hardware.
//!
//! # Exchange and timing
//!
//! Each cycle the runtime calls [`SimDrive::feedback`], steps the kernel, then
//! [`SimDrive::apply`]. `apply(sp_k)` advances the plant by one cycle `dt`, during which the
//! drive's fine interpolator moves its position reference linearly from the previous
//! (delayed) setpoint to `sp_k` (delayed). So with no dead time the feedback read at the start
//! of cycle k+1 is the plant's response to `sp_k`: the one-cycle bus lag of
//! [`motion::drive`], and nothing more. The kernel's following error is therefore
//! `sp_k.position − feedback_{k+1}.actual_position` (the setpoint it wrote last cycle).
//!
//! # Plant
//!
//! The setpoint stream `s = (p, v, a)` (position, feed-forward velocity and acceleration) is
//! delayed by `dead_time` `D` (a ring of setpoints sized at construction, linear interpolation
//! between cycles for fractional dead times). With `dead_time_compensation` the drive
//! extrapolates the delayed setpoint over the dead time with its own feed-forward, as a
//! "lagless" CSP drive does: reference `r = p + v·D + a·D²/2`, `v_ff = v + a·D`,
//! `a_ff = a`. Steps (no feed-forward) still arrive exactly `D` later; consistent
//! trajectories show no steady lag from `D`.
//!
//! With `F` the injected load force and `k = load_stiffness`, the load settles at
//! `r − F/k` (a positive force pushes towards negative positions, so at rest the following
//! error is `+F/k`). With `K_v = velocity_feed_forward`, `K_a = acceleration_feed_forward`:
//!
//! * `ideal`: `q = r − F/k`;
//! * `pt1 { time_constant: T }`: `q' = (r − F/k − q)/T + K_v·v_ff`;
//! * `pt2 { natural_frequency_hz: f, damping: ζ }`, `ω = 2πf`:
//!   `q'' = ω²(r − F/k − q) + 2ζω(K_v·v_ff − q') + K_a·a_ff`.
//!
//! Following error of PT2 with full velocity feed-forward: 0 at constant velocity,
//! `(1 − K_a)·a/ω²` while accelerating at `a` (25 µm at 2.5 m/s² with the default 50 Hz),
//! `F/k` under a load. PT1 at constant velocity: `(1 − K_v)·v·T`. Without feed-forward PT2
//! lags `2ζ·v/ω`. The models are integrated with RK4 in sub-steps of at most `0.05/ω`
//! (resp. `T/20`); actual velocity is the model's velocity state (ideal: the reference's
//! slope over the cycle).
//!
//! While the power stage is off the load coasts to rest at `coast_deceleration` (a load
//! force does not move it).
//!
//! # Sequencing (CiA-402 in short)
//!
//! `ready` unless faulted. `enabled` rises `enable_delay` (rounded up to whole cycles, at
//! least one) after `enable` is requested with no fault; the load holds its place for the
//! first `D` after enabling (the dead-time ring restarts at the actual position), then
//! follows. Dropping `enable` or a fault clears `enabled` at once. A fault sets `fault`,
//! `fault_code`, clears `ready` and `enabled`. A rising edge of `fault_reset` clears the fault
//! when its cause is gone: an injected [`SimFault::DriveFault`] stays until
//! [`SimFault::Clear`]; a limit-switch fault is latched by the switch's rising edge and is
//! cleared by a reset even while the switch is still pressed (so the axis can be moved off).
//!
//! # Inputs and latch
//!
//! `reference_cam` is true while `start ≤ actual ≤ end`; the encoder index pulse sits at
//! `offset + n·period`; hardware limit switches are active at `actual ≥ positive` /
//! `actual ≤ negative` (or forced by [`SimFault::LimitSwitch`]). The touch probe, armed by
//! `latch_enable`, checks every plant sub-step's path for the first event of `latch_source`
//! (index crossing, cam rising, cam falling: a cam edge is at `start` or `end` depending on
//! the direction of travel) and latches the event's exact position. `latch_valid` stays until
//! `latch_enable` drops, which re-arms the probe.
//!
//! Everything is deterministic and `feedback`/`apply` do not allocate.

use std::f64::consts::PI;

use motion::{DriveFeedback, DriveMode, DriveSetpoint, LatchSource};
use serde::{Deserialize, Serialize};

use crate::error::ConfigError;

/// Fault code reported for an injected [`SimFault::DriveFault`] with code 0 (CiA 301
/// "generic error"): a fault must never read as code 0.
pub const GENERIC_FAULT_CODE: u32 = 0x1000;
/// Fault code of a hardware limit switch hit with `limit_switches.fault_on_hit` (CiA 402
/// "reference limit").
pub const LIMIT_SWITCH_FAULT_CODE: u32 = 0x8612;

/// Longest accepted dead time (s); the setpoint ring is sized from it and the cycle time.
pub const MAX_DEAD_TIME: f64 = 0.1;

/// Model of the simulated servo drive. Times in seconds, positions in the axis's units.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SimDriveConfig {
    /// Closed-loop response of the position-controlled load.
    pub plant: PlantModel,
    /// Delay between a setpoint and its effect on the load (s, 0…0.1).
    #[cfg_attr(feature = "schema", schema(minimum = 0, maximum = 0.1))]
    pub dead_time: f64,
    /// Extrapolate the delayed setpoint over the dead time with its feed-forward velocity and
    /// acceleration, as a "lagless" CSP drive does.
    pub dead_time_compensation: bool,
    /// Weight of the setpoint's velocity feed-forward (0…2; 1 = full).
    #[cfg_attr(feature = "schema", schema(minimum = 0, maximum = 2))]
    pub velocity_feed_forward: f64,
    /// Weight of the setpoint's acceleration feed-forward (0…2; PT2 only).
    #[cfg_attr(feature = "schema", schema(minimum = 0, maximum = 2))]
    pub acceleration_feed_forward: f64,
    /// Time from the enable request to "operation enabled" (s, 0…10).
    #[cfg_attr(feature = "schema", schema(minimum = 0, maximum = 10))]
    pub enable_delay: f64,
    /// Deceleration of the load while the power stage is off (units/s², > 0).
    #[cfg_attr(feature = "schema", schema(exclusive_minimum = 0))]
    pub coast_deceleration: f64,
    /// Static stiffness of the position loop against a load force (force units per position
    /// unit, > 0): a force F gives a following error F / load_stiffness.
    #[cfg_attr(feature = "schema", schema(exclusive_minimum = 0))]
    pub load_stiffness: f64,
    /// Reference cam (homing switch); `null` for none.
    pub reference_cam: Option<ReferenceCam>,
    /// Encoder index (zero) pulse; `null` for none.
    pub index_pulse: Option<IndexPulse>,
    /// Hardware limit switches.
    pub limit_switches: LimitSwitches,
    /// The load in torque mode (MC_TorqueControl).
    pub torque: TorqueModel,
    /// Velocity mode (MC_WriteDriveOperationMode Velo1, CSV): the gain (1/s, > 0) of the
    /// position loop closed on motiond's side — velocity = feed-forward + gain × (set − actual).
    pub velocity_mode_position_gain: f64,
}

/// The load as torque moves it (torque mode): what 1 % of rated torque accelerates it by,
/// and the friction it has to overcome. An injected load force counts as that many percent
/// of torque against the motion's positive direction.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[cfg_attr(feature = "schema", schema(example = json!({"acceleration_per_percent": 100.0, "friction": 1.0, "viscous": 0.0})))]
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TorqueModel {
    /// Acceleration per percent of rated torque (units/s² per %, > 0): rated torque over the
    /// load's inertia.
    pub acceleration_per_percent: f64,
    /// Coulomb friction, percent of rated torque (≥ 0): the load stays at rest until the
    /// torque overcomes it.
    pub friction: f64,
    /// Viscous friction, percent of rated torque per unit/s (≥ 0).
    pub viscous: f64,
}

impl Default for TorqueModel {
    fn default() -> Self {
        TorqueModel {
            acceleration_per_percent: 100.0,
            friction: 1.0,
            viscous: 0.0,
        }
    }
}

impl Default for SimDriveConfig {
    fn default() -> Self {
        SimDriveConfig {
            plant: PlantModel::default(),
            dead_time: 0.001,
            dead_time_compensation: true,
            velocity_feed_forward: 1.0,
            acceleration_feed_forward: 0.0,
            enable_delay: 0.005,
            coast_deceleration: 10_000.0,
            load_stiffness: 1_000.0,
            reference_cam: Some(ReferenceCam {
                start: 20.0,
                end: 25.0,
            }),
            index_pulse: Some(IndexPulse {
                period: 10.0,
                offset: 0.0,
            }),
            limit_switches: LimitSwitches::default(),
            torque: TorqueModel::default(),
            velocity_mode_position_gain: 100.0,
        }
    }
}

/// Closed-loop response of the load to the position reference.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum PlantModel {
    /// The load is exactly at the reference.
    Ideal,
    /// First-order lag.
    Pt1 {
        /// Time constant (s, > 0 and ≤ 10).
        #[serde(default = "default_time_constant")]
        #[cfg_attr(feature = "schema", schema(exclusive_minimum = 0, maximum = 10))]
        time_constant: f64,
    },
    /// Second-order lag (a tuned position loop).
    Pt2 {
        /// Natural frequency (Hz, > 0 and ≤ 1000).
        #[serde(default = "default_natural_frequency_hz")]
        #[cfg_attr(feature = "schema", schema(exclusive_minimum = 0, maximum = 1000))]
        natural_frequency_hz: f64,
        /// Damping ratio (> 0 and ≤ 10; 1 = critically damped).
        #[serde(default = "default_damping")]
        #[cfg_attr(feature = "schema", schema(exclusive_minimum = 0, maximum = 10))]
        damping: f64,
    },
}

fn default_time_constant() -> f64 {
    0.005
}
fn default_natural_frequency_hz() -> f64 {
    50.0
}
fn default_damping() -> f64 {
    0.8
}

impl Default for PlantModel {
    fn default() -> Self {
        PlantModel::Pt2 {
            natural_frequency_hz: default_natural_frequency_hz(),
            damping: default_damping(),
        }
    }
}

/// Reference cam: active while `start ≤ actual position ≤ end`.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceCam {
    pub start: f64,
    pub end: f64,
}

/// Encoder index pulse at `offset + n·period` (e.g. once per motor revolution).
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IndexPulse {
    /// Distance between pulses (> 0).
    #[cfg_attr(feature = "schema", schema(exclusive_minimum = 0))]
    pub period: f64,
    /// Position of one pulse.
    #[serde(default)]
    pub offset: f64,
}

/// Hardware limit switches (each optional).
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LimitSwitches {
    /// Active at actual positions ≤ this.
    pub negative: Option<f64>,
    /// Active at actual positions ≥ this.
    pub positive: Option<f64>,
    /// A switch reached while enabled faults the drive (code 0x8612); otherwise the switches
    /// are only reported.
    pub fault_on_hit: bool,
}

impl SimDriveConfig {
    /// Checks every field; the errors name fields by JSON path (`plant.damping`).
    pub fn validate(&self) -> Result<(), Vec<ConfigError>> {
        let mut errors = Vec::new();
        let mut check = |ok: bool, field: &str, message: &str| {
            if !ok {
                errors.push(ConfigError {
                    field: field.into(),
                    message: message.into(),
                });
            }
        };
        let within = |x: f64, lo: f64, hi: f64| x.is_finite() && x >= lo && x <= hi;
        let positive_up_to = |x: f64, hi: f64| x.is_finite() && x > 0.0 && x <= hi;

        match self.plant {
            PlantModel::Ideal => {}
            PlantModel::Pt1 { time_constant } => {
                check(
                    positive_up_to(time_constant, 10.0),
                    "plant.time_constant",
                    "must be > 0 and ≤ 10 s",
                );
            }
            PlantModel::Pt2 {
                natural_frequency_hz,
                damping,
            } => {
                check(
                    positive_up_to(natural_frequency_hz, 1000.0),
                    "plant.natural_frequency_hz",
                    "must be > 0 and ≤ 1000 Hz",
                );
                check(
                    positive_up_to(damping, 10.0),
                    "plant.damping",
                    "must be > 0 and ≤ 10",
                );
            }
        }
        check(
            within(self.dead_time, 0.0, MAX_DEAD_TIME),
            "dead_time",
            "must be between 0 and 0.1 s",
        );
        check(
            within(self.velocity_feed_forward, 0.0, 2.0),
            "velocity_feed_forward",
            "must be between 0 and 2",
        );
        check(
            within(self.acceleration_feed_forward, 0.0, 2.0),
            "acceleration_feed_forward",
            "must be between 0 and 2",
        );
        check(
            within(self.enable_delay, 0.0, 10.0),
            "enable_delay",
            "must be between 0 and 10 s",
        );
        check(
            self.coast_deceleration.is_finite() && self.coast_deceleration > 0.0,
            "coast_deceleration",
            "must be a finite number > 0",
        );
        check(
            self.load_stiffness.is_finite() && self.load_stiffness > 0.0,
            "load_stiffness",
            "must be a finite number > 0",
        );
        if let Some(cam) = self.reference_cam {
            check(
                cam.start.is_finite(),
                "reference_cam.start",
                "must be a finite number",
            );
            check(
                cam.end.is_finite(),
                "reference_cam.end",
                "must be a finite number",
            );
            if cam.start.is_finite() && cam.end.is_finite() {
                check(
                    cam.end > cam.start,
                    "reference_cam.end",
                    "must be greater than reference_cam.start",
                );
            }
        }
        if let Some(index) = self.index_pulse {
            check(
                index.period.is_finite() && index.period > 0.0,
                "index_pulse.period",
                "must be a finite number > 0",
            );
            check(
                index.offset.is_finite(),
                "index_pulse.offset",
                "must be a finite number",
            );
        }
        let ls = self.limit_switches;
        if let Some(n) = ls.negative {
            check(
                n.is_finite(),
                "limit_switches.negative",
                "must be a finite number",
            );
        }
        if let Some(p) = ls.positive {
            check(
                p.is_finite(),
                "limit_switches.positive",
                "must be a finite number",
            );
        }
        if let (Some(n), Some(p)) = (ls.negative, ls.positive) {
            if n.is_finite() && p.is_finite() {
                check(
                    p > n,
                    "limit_switches.positive",
                    "must be greater than limit_switches.negative",
                );
            }
        }
        let t = self.torque;
        check(
            positive_up_to(t.acceleration_per_percent, 1e9),
            "torque.acceleration_per_percent",
            "must be > 0 and ≤ 1e9",
        );
        check(
            within(t.friction, 0.0, 1000.0),
            "torque.friction",
            "must be between 0 and 1000 %",
        );
        check(
            within(t.viscous, 0.0, 1e6),
            "torque.viscous",
            "must be between 0 and 1e6 % per unit/s",
        );
        check(
            positive_up_to(self.velocity_mode_position_gain, 1e6),
            "velocity_mode_position_gain",
            "must be > 0 and ≤ 1e6 1/s",
        );
        if errors.is_empty() {
            Ok(())
        } else {
            Err(errors)
        }
    }
}

/// A fault or disturbance injected into the simulation (tests, demos, commissioning).
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum SimFault {
    /// The drive faults at once with `code` (0 reads as 0x1000). The cause stays until
    /// `clear`, so a fault reset before that does not clear it.
    DriveFault {
        #[cfg_attr(feature = "schema", schema(value_type = i64, minimum = 0, maximum = 4294967295_i64))]
        code: u32,
    },
    /// Constant load force; a positive force pushes towards negative positions and gives a
    /// following error of force / `load_stiffness`. 0 removes it.
    Load { force: f64 },
    /// Force a limit switch input on or off (in addition to the configured positions).
    LimitSwitch { positive: bool, active: bool },
    /// A mark on the load for the measuring probe at digital input 1: the input is on while
    /// the actual position is at or beyond `position` (`null` removes the mark), so passing
    /// the mark is an edge a touch probe latches exactly.
    ProbeMark { position: Option<f64> },
    /// Force digital input 1 on or off (besides the mark): the edge happens now, at the
    /// position the load is at.
    ProbeInput { active: bool },
    /// Remove every injected cause (drive fault, load, forced switches and input, the probe
    /// mark). A latched fault still needs a fault reset.
    Clear,
}

/// One setpoint in the dead-time ring, or the drive's reference derived from it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Sample {
    position: f64,
    velocity: f64,
    acceleration: f64,
}

impl Sample {
    fn hold(position: f64) -> Sample {
        Sample {
            position,
            velocity: 0.0,
            acceleration: 0.0,
        }
    }
    fn lerp(self, other: Sample, t: f64) -> Sample {
        Sample {
            position: self.position + (other.position - self.position) * t,
            velocity: self.velocity + (other.velocity - self.velocity) * t,
            acceleration: self.acceleration + (other.acceleration - self.acceleration) * t,
        }
    }
}

/// The plant model with its constants resolved.
#[derive(Clone, Copy, Debug)]
enum Dynamics {
    Ideal,
    Pt1 { inv_t: f64 },
    Pt2 { omega2: f64, two_zeta_omega: f64 },
}

/// Simulated servo drive. See the module documentation for the model.
pub struct SimDrive {
    config: SimDriveConfig,
    cycle_time: f64,

    // Constants derived at construction.
    dynamics: Dynamics,
    substeps: u32,
    /// One cycle of the plant in position mode as the linear map it is (the plant is linear
    /// and moves with its reference, its inputs linear over the cycle): the position relative
    /// to the cycle's starting reference and the velocity at the cycle's end from
    /// [q − r0, v, r1 − r0, w0, w1, a0, a1] at its start (reference r, velocity and
    /// acceleration feed-forward w and a, at the cycle's start and end). Made once from the
    /// substep integration itself, so it gives what the substeps give (to rounding, in
    /// coordinates relative to the reference so that rounding stays at the lag's scale) at a
    /// fraction of their cost; the substeps still run while a probe latch is armed (it needs
    /// the load's path within the cycle).
    cycle_map: [[f64; 7]; 2],
    /// Dead time in cycles = `delay_cycles + delay_frac`.
    delay_cycles: usize,
    delay_frac: f64,
    /// Dead time used for the extrapolation (0 without compensation).
    compensation_time: f64,
    enable_cycles: u32,

    /// Setpoints of the last `delay_cycles + 2` cycles; `head` is the newest.
    ring: Box<[Sample]>,
    head: usize,
    /// The drive's reference at the end of the last cycle (start of the next).
    reference: Sample,

    // Load state.
    position: f64,
    velocity: f64,

    // Sequencing.
    enabled: bool,
    enable_count: u32,
    /// Latched fault (0 = none).
    fault_code: u32,
    /// Cause of an injected fault, until `SimFault::Clear`.
    injected_fault: Option<u32>,
    last_fault_reset: bool,

    // Inputs.
    load_force: f64,
    forced_limit_positive: bool,
    forced_limit_negative: bool,
    /// Digital input 1 forced on (`SimFault::ProbeInput`).
    forced_input1: bool,
    /// The probe mark (`SimFault::ProbeMark`).
    probe_mark: Option<f64>,
    /// An edge of input 1 made by `ProbeInput` (true: rising), for the next cycle's latch.
    input1_edge: Option<bool>,
    /// Switch levels at the end of the last cycle, for edges.
    last_limit_positive: bool,
    last_limit_negative: bool,

    latch_valid: bool,
    latch_position: f64,

    /// The operation mode the drive runs in (`Configured`: position, the default).
    mode: DriveMode,
    /// Torque mode: the torque applied (percent), and whether a velocity limit reduced it.
    torque: f64,
    velocity_limited: bool,
}

impl SimDrive {
    /// A drive at rest at position 0, ready, disabled.
    ///
    /// # Panics
    /// If `config` does not pass [`SimDriveConfig::validate`] or `cycle_time` is not a finite
    /// number > 0 (validate both before).
    pub fn new(config: SimDriveConfig, cycle_time: f64) -> SimDrive {
        if let Err(errors) = config.validate() {
            panic!("invalid SimDriveConfig: {errors:?}");
        }
        assert!(
            cycle_time.is_finite() && cycle_time > 0.0,
            "cycle time must be > 0, got {cycle_time}"
        );

        // Sub-steps fine enough for RK4 to be accurate and for the latch to see overshoots.
        let (dynamics, rate) = match config.plant {
            PlantModel::Ideal => (Dynamics::Ideal, 0.0),
            PlantModel::Pt1 { time_constant } => (
                Dynamics::Pt1 {
                    inv_t: 1.0 / time_constant,
                },
                1.0 / time_constant,
            ),
            PlantModel::Pt2 {
                natural_frequency_hz,
                damping,
            } => {
                let omega = 2.0 * PI * natural_frequency_hz;
                (
                    Dynamics::Pt2 {
                        omega2: omega * omega,
                        two_zeta_omega: 2.0 * damping * omega,
                    },
                    omega,
                )
            }
        };
        let substeps = ((rate * cycle_time / 0.05).ceil() as u32).clamp(1, 10_000);

        let delay = config.dead_time / cycle_time;
        // Dead times that are whole cycles up to rounding must be exact shifts.
        let rounded = delay.round();
        let delay = if (delay - rounded).abs() < 1e-9 {
            rounded
        } else {
            delay
        };
        let delay_cycles = delay.floor() as usize;
        let delay_frac = delay - delay_cycles as f64;

        let enable_cycles = ((config.enable_delay / cycle_time - 1e-9).ceil().max(1.0)) as u32;
        let compensation_time = if config.dead_time_compensation {
            config.dead_time
        } else {
            0.0
        };

        let mut cycle_map = [[0.0; 7]; 2];
        for j in 0..7 {
            let mut e = [0.0; 7];
            e[j] = 1.0;
            // r0 = 0: positions relative to the starting reference.
            let inputs = [0.0, e[2], e[3], e[4], e[5], e[6]];
            let (q, v) = integrate(
                dynamics,
                substeps,
                cycle_time,
                e[0],
                e[1],
                inputs,
                |_, _| {},
            );
            cycle_map[0][j] = q;
            cycle_map[1][j] = v;
        }
        let mut drive = SimDrive {
            cycle_time,
            dynamics,
            substeps,
            cycle_map,
            delay_cycles,
            delay_frac,
            compensation_time,
            enable_cycles,
            ring: vec![Sample::default(); delay_cycles + 2].into_boxed_slice(),
            head: 0,
            reference: Sample::default(),
            position: 0.0,
            velocity: 0.0,
            enabled: false,
            enable_count: 0,
            fault_code: 0,
            injected_fault: None,
            last_fault_reset: false,
            load_force: 0.0,
            forced_limit_positive: false,
            forced_limit_negative: false,
            forced_input1: false,
            probe_mark: None,
            input1_edge: None,
            last_limit_positive: false,
            last_limit_negative: false,
            latch_valid: false,
            latch_position: 0.0,
            mode: DriveMode::Position,
            torque: 0.0,
            velocity_limited: false,
            config,
        };
        drive.set_actual_position(0.0);
        drive
    }

    pub fn config(&self) -> &SimDriveConfig {
        &self.config
    }

    pub fn cycle_time(&self) -> f64 {
        self.cycle_time
    }

    /// The drive's inputs as the kernel reads them at the start of a cycle.
    pub fn feedback(&self) -> DriveFeedback {
        let (limit_positive, limit_negative) = self.limit_levels();
        DriveFeedback {
            ready: self.fault_code == 0,
            enabled: self.enabled,
            fault: self.fault_code != 0,
            bus_error: false,
            fault_code: self.fault_code,
            actual_position: self.position,
            actual_velocity: self.velocity,
            reference_cam: self.cam_level(self.position),
            limit_positive,
            limit_negative,
            latch_valid: self.latch_valid,
            latch_position: self.latch_position,
            mode: self.mode,
            actual_torque: self.torque,
            velocity_limited: self.velocity_limited,
            // The simulated drive runs no profile of its own (a drive-executed axis needs a
            // CiA-402 drive).
            profile: motion::ProfileFeedback::default(),
        }
    }

    /// Takes the kernel's setpoint and advances the plant one cycle.
    pub fn apply(&mut self, setpoint: &DriveSetpoint) {
        let reset_edge = setpoint.fault_reset && !self.last_fault_reset;
        self.last_fault_reset = setpoint.fault_reset;
        if reset_edge && self.fault_code != 0 && self.injected_fault.is_none() {
            self.fault_code = 0;
        }

        if self.fault_code != 0 || !setpoint.enable {
            self.enabled = false;
            self.enable_count = 0;
        }

        if !setpoint.latch_enable {
            self.latch_valid = false;
        }
        let mut latch = if setpoint.latch_enable && !self.latch_valid {
            Some(setpoint.latch_source)
        } else {
            None
        };
        // An edge forced on input 1 since the last cycle happened where the load was.
        if let Some(rising) = self.input1_edge.take() {
            let wanted = match latch {
                Some(LatchSource::Input1Rising) => rising,
                Some(LatchSource::Input1Falling) => !rising,
                _ => false,
            };
            if wanted {
                self.latch_valid = true;
                self.latch_position = self.position;
                latch = None;
            }
        }

        // The mode switches at once (on the fly, as drives that support MC_TorqueControl
        // do); back in a position mode the reference starts where the load is.
        let mode = match setpoint.mode {
            DriveMode::Configured => DriveMode::Position,
            m => m,
        };
        if mode != self.mode {
            if self.mode == DriveMode::Torque || mode == DriveMode::Torque {
                self.restart_reference();
            }
            self.mode = mode;
        }
        self.velocity_limited = false;
        // The power stage is on for this whole cycle only if it was on at its start.
        let powered = self.enabled;
        if !powered {
            self.torque = 0.0;
            self.coast(latch);
        } else {
            match self.mode {
                DriveMode::Torque => self.torque_control(setpoint, latch),
                DriveMode::Velocity => self.velocity_control(setpoint, latch),
                _ => {
                    self.follow(setpoint, latch);
                    // What holding the load against its force takes.
                    self.torque = self.load_force;
                }
            }
        }

        let (limit_positive, limit_negative) = self.limit_levels();
        let hit = (limit_positive && !self.last_limit_positive)
            || (limit_negative && !self.last_limit_negative);
        self.last_limit_positive = limit_positive;
        self.last_limit_negative = limit_negative;
        if hit && powered && self.config.limit_switches.fault_on_hit && self.fault_code == 0 {
            self.fault_code = LIMIT_SWITCH_FAULT_CODE;
            self.enabled = false;
            self.enable_count = 0;
        }

        if !self.enabled && setpoint.enable && self.fault_code == 0 {
            self.enable_count += 1;
            if self.enable_count >= self.enable_cycles {
                self.enabled = true;
                self.restart_reference();
            }
        }
    }

    /// Injects a fault or disturbance; it shows in the next feedback (faults) or acts from
    /// the next cycle (load, switches).
    pub fn inject(&mut self, fault: SimFault) {
        match fault {
            SimFault::DriveFault { code } => {
                let code = if code == 0 { GENERIC_FAULT_CODE } else { code };
                self.injected_fault = Some(code);
                self.fault_code = code;
                self.enabled = false;
                self.enable_count = 0;
            }
            SimFault::Load { force } => {
                self.load_force = if force.is_finite() { force } else { 0.0 }
            }
            SimFault::LimitSwitch {
                positive: true,
                active,
            } => self.forced_limit_positive = active,
            SimFault::LimitSwitch {
                positive: false,
                active,
            } => self.forced_limit_negative = active,
            SimFault::ProbeMark { position } => self.probe_mark = position,
            SimFault::ProbeInput { active } => {
                let before = self.input1(self.position);
                self.forced_input1 = active;
                let after = self.input1(self.position);
                if before != after {
                    self.input1_edge = Some(after);
                }
            }
            SimFault::Clear => {
                self.injected_fault = None;
                self.load_force = 0.0;
                self.forced_limit_positive = false;
                self.forced_limit_negative = false;
                self.forced_input1 = false;
                self.probe_mark = None;
            }
        }
    }

    /// Places the load at `p`, at rest (initial position, tests). No latch or switch edge is
    /// seen for the jump; an enabled drive holds the new place until new setpoints arrive.
    pub fn set_actual_position(&mut self, p: f64) {
        self.position = p;
        self.velocity = 0.0;
        self.restart_reference();
        let (positive, negative) = self.limit_levels();
        self.last_limit_positive = positive;
        self.last_limit_negative = negative;
    }

    /// The load force currently injected.
    pub fn load_force(&self) -> f64 {
        self.load_force
    }

    fn restart_reference(&mut self) {
        let hold = Sample::hold(self.position);
        self.ring.fill(hold);
        self.reference = hold;
    }

    fn cam_level(&self, x: f64) -> bool {
        self.config
            .reference_cam
            .is_some_and(|cam| cam.start <= x && x <= cam.end)
    }

    /// Digital input 1 at a position: forced on, or at or beyond the probe mark.
    fn input1(&self, x: f64) -> bool {
        self.forced_input1 || self.probe_mark.is_some_and(|m| x >= m)
    }

    fn limit_levels(&self) -> (bool, bool) {
        let ls = &self.config.limit_switches;
        let positive =
            self.forced_limit_positive || ls.positive.is_some_and(|x| self.position >= x);
        let negative =
            self.forced_limit_negative || ls.negative.is_some_and(|x| self.position <= x);
        (positive, negative)
    }

    /// Closed loop: push the setpoint, derive the reference at the end of the cycle, integrate.
    fn follow(&mut self, setpoint: &DriveSetpoint, mut latch: Option<LatchSource>) {
        let len = self.ring.len();
        let newest = self.ring[self.head];
        let sample = Sample {
            position: if setpoint.position.is_finite() {
                setpoint.position
            } else {
                newest.position
            },
            velocity: if setpoint.velocity.is_finite() {
                setpoint.velocity
            } else {
                0.0
            },
            acceleration: if setpoint.acceleration.is_finite() {
                setpoint.acceleration
            } else {
                0.0
            },
        };
        self.head = (self.head + 1) % len;
        self.ring[self.head] = sample;

        let delayed_at = |back: usize| self.ring[(self.head + len - back) % len];
        let mut delayed = delayed_at(self.delay_cycles);
        if self.delay_frac > 0.0 {
            delayed = delayed.lerp(delayed_at(self.delay_cycles + 1), self.delay_frac);
        }
        let d = self.compensation_time;
        let end = Sample {
            position: delayed.position + delayed.velocity * d + 0.5 * delayed.acceleration * d * d,
            velocity: delayed.velocity + delayed.acceleration * d,
            acceleration: delayed.acceleration,
        };
        let start = self.reference;
        self.reference = end;

        let offset = self.load_force / self.config.load_stiffness;
        let kv = self.config.velocity_feed_forward;
        let ka = self.config.acceleration_feed_forward;
        let inputs = [
            start.position - offset,
            end.position - offset,
            kv * start.velocity,
            kv * end.velocity,
            ka * start.acceleration,
            ka * end.acceleration,
        ];
        let (q, v) = (self.position, self.velocity);
        if latch.is_none() && !matches!(self.dynamics, Dynamics::Ideal) {
            let r0 = inputs[0];
            let x = [
                q - r0,
                v,
                inputs[1] - r0,
                inputs[2],
                inputs[3],
                inputs[4],
                inputs[5],
            ];
            let row = |r: &[f64; 7]| r.iter().zip(&x).map(|(m, x)| m * x).sum::<f64>();
            self.position = r0 + row(&self.cycle_map[0]);
            self.velocity = row(&self.cycle_map[1]);
        } else {
            let (dynamics, n, t) = (self.dynamics, self.substeps, self.cycle_time);
            let mut path = |a: f64, b: f64| self.probe(&mut latch, a, b);
            let (q1, v1) = integrate(dynamics, n, t, q, v, inputs, &mut path);
            self.position = q1;
            self.velocity = v1;
        }
    }

    /// Torque mode: the load accelerates with the torque (less friction and the load force),
    /// its velocity held within the setpoint's limits by reducing the torque.
    fn torque_control(&mut self, setpoint: &DriveSetpoint, mut latch: Option<LatchSource>) {
        let m = self.config.torque;
        let finite = |x: f64, d: f64| if x.is_finite() { x } else { d };
        let asked = finite(setpoint.torque, 0.0);
        let high = finite(setpoint.velocity_limit_high, 0.0);
        let low = finite(setpoint.velocity_limit_low, 0.0).min(high);
        let n = self.substeps.max(10);
        let h = self.cycle_time / n as f64;
        let mut applied = asked;
        for _ in 0..n {
            let before = self.position;
            let v0 = self.velocity;
            let drive = asked - self.load_force - m.viscous * v0;
            let net = if v0 != 0.0 {
                drive - m.friction * v0.signum()
            } else if drive.abs() <= m.friction {
                0.0 // static friction holds the load
            } else {
                drive - m.friction * drive.signum()
            };
            let mut v1 = v0 + net * m.acceleration_per_percent * h;
            if v0 != 0.0 && v1.signum() != v0.signum() && (drive.abs() <= m.friction) {
                v1 = 0.0; // friction stops the load, it does not reverse it
            }
            if v1 > high || v1 < low {
                let limit = v1.clamp(low, high);
                // The torque that keeps the limit instead of the one asked for.
                applied = asked - (v1 - limit) / (m.acceleration_per_percent * h);
                v1 = limit;
                self.velocity_limited = true;
            }
            self.position += 0.5 * (v0 + v1) * h;
            self.velocity = v1;
            self.probe(&mut latch, before, self.position);
        }
        self.torque = if self.velocity_limited {
            applied
        } else {
            asked
        };
    }

    /// Velocity mode (CSV): the load follows the velocity setpoint with the position loop
    /// closed on the controller's side (its gain in the configuration).
    fn velocity_control(&mut self, setpoint: &DriveSetpoint, mut latch: Option<LatchSource>) {
        let finite = |x: f64, d: f64| if x.is_finite() { x } else { d };
        let target = finite(setpoint.position, self.position);
        let vff = finite(setpoint.velocity, 0.0);
        let n = self.substeps;
        let h = self.cycle_time / n as f64;
        let k = self.config.velocity_mode_position_gain;
        // The set position moves from the last cycle's to this one's over the cycle.
        let start = self.reference.position;
        for i in 0..n {
            let before = self.position;
            let s = (i + 1) as f64 / n as f64;
            let v = vff + k * (start + (target - start) * s - self.position);
            self.velocity = v;
            self.position += v * h;
            self.probe(&mut latch, before, self.position);
        }
        self.torque = self.load_force;
        // A switch back to position mode starts from here.
        self.restart_reference();
        self.reference = Sample::hold(target);
    }

    /// Power stage off: the load slows down at the coast deceleration.
    fn coast(&mut self, mut latch: Option<LatchSource>) {
        let n = self.substeps;
        let h = self.cycle_time / n as f64;
        let dv = self.config.coast_deceleration * h;
        for _ in 0..n {
            let before = self.position;
            let v0 = self.velocity;
            if v0.abs() <= dv {
                // Comes to rest inside this sub-step.
                self.position += 0.5 * v0 * (v0.abs() / self.config.coast_deceleration);
                self.velocity = 0.0;
            } else {
                let v1 = v0 - dv.copysign(v0);
                self.position += 0.5 * (v0 + v1) * h;
                self.velocity = v1;
            }
            self.probe(&mut latch, before, self.position);
        }
    }

    /// Touch probe: the first event of `source` on the path `a → b` latches its position.
    fn probe(&mut self, latch: &mut Option<LatchSource>, a: f64, b: f64) {
        let Some(source) = *latch else { return };
        let event = match source {
            LatchSource::IndexPulse => self
                .config
                .index_pulse
                .and_then(|ip| index_crossing(a, b, ip)),
            LatchSource::CamRising => self
                .config
                .reference_cam
                .and_then(|cam| cam_edge(a, b, cam, true)),
            LatchSource::CamFalling => self
                .config
                .reference_cam
                .and_then(|cam| cam_edge(a, b, cam, false)),
            // The mark's edge, unless the input is forced on (then it has no edges).
            LatchSource::Input1Rising | LatchSource::Input1Falling if self.forced_input1 => None,
            LatchSource::Input1Rising => self.probe_mark.and_then(|m| mark_edge(a, b, m, true)),
            LatchSource::Input1Falling => self.probe_mark.and_then(|m| mark_edge(a, b, m, false)),
        };
        if let Some(x) = event {
            self.latch_valid = true;
            self.latch_position = x;
            *latch = None;
        }
    }
}

/// One cycle of the plant in position mode from (`q`, `v`), integrated in `n` RK4 substeps;
/// `inputs` are the reference, the velocity and the acceleration feed-forward at the cycle's
/// start and end (`[r0, r1, w0, w1, a0, a1]`, linear in between). `on_substep(before, after)`
/// sees the load's path. Returns the position and velocity at the cycle's end.
fn integrate(
    dynamics: Dynamics,
    n: u32,
    cycle_time: f64,
    q: f64,
    v: f64,
    inputs: [f64; 6],
    mut on_substep: impl FnMut(f64, f64),
) -> (f64, f64) {
    let [r0, r1, w0, w1, a0, a1] = inputs;
    let h = cycle_time / n as f64;
    let input = |s: f64| (r0 + (r1 - r0) * s, w0 + (w1 - w0) * s, a0 + (a1 - a0) * s);
    let (mut position, mut velocity) = (q, v);
    for i in 0..n {
        let s0 = i as f64 / n as f64;
        let s1 = (i + 1) as f64 / n as f64;
        let sm = 0.5 * (s0 + s1);
        let before = position;
        match dynamics {
            Dynamics::Ideal => {
                position = input(s1).0;
                velocity = (r1 - r0) / cycle_time;
            }
            Dynamics::Pt1 { inv_t } => {
                let f = |s: f64, q: f64| {
                    let (r, vff, _) = input(s);
                    (r - q) * inv_t + vff
                };
                let q = position;
                let k1 = f(s0, q);
                let k2 = f(sm, q + 0.5 * h * k1);
                let k3 = f(sm, q + 0.5 * h * k2);
                let k4 = f(s1, q + h * k3);
                position = q + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
                velocity = f(s1, position);
            }
            Dynamics::Pt2 {
                omega2,
                two_zeta_omega,
            } => {
                let f = |s: f64, q: f64, v: f64| {
                    let (r, vff, aff) = input(s);
                    omega2 * (r - q) + two_zeta_omega * (vff - v) + aff
                };
                let (q, v) = (position, velocity);
                let (q1, v1) = (v, f(s0, q, v));
                let (q2, v2) = (v + 0.5 * h * v1, f(sm, q + 0.5 * h * q1, v + 0.5 * h * v1));
                let (q3, v3) = (v + 0.5 * h * v2, f(sm, q + 0.5 * h * q2, v + 0.5 * h * v2));
                let (q4, v4) = (v + h * v3, f(s1, q + h * q3, v + h * v3));
                position = q + h / 6.0 * (q1 + 2.0 * q2 + 2.0 * q3 + q4);
                velocity = v + h / 6.0 * (v1 + 2.0 * v2 + 2.0 * v3 + v4);
            }
        }
        on_substep(before, position);
    }
    (position, velocity)
}

/// The first index pulse passed on the way from `a` to `b` (reaching it counts; leaving it
/// does not).
fn index_crossing(a: f64, b: f64, ip: IndexPulse) -> Option<f64> {
    let IndexPulse { period, offset } = ip;
    // Pulse n is always computed the same way, so a latched pulse reads the same every time.
    let pulse = |n: f64| offset + n * period;
    if b > a {
        let mut n = ((a - offset) / period).floor() + 1.0;
        // Rounding in the division may skip a pulse just ahead of `a`.
        if pulse(n - 1.0) > a {
            n -= 1.0;
        }
        (pulse(n) <= b).then(|| pulse(n))
    } else if b < a {
        let mut n = ((a - offset) / period).ceil() - 1.0;
        if pulse(n + 1.0) < a {
            n += 1.0;
        }
        (pulse(n) >= b).then(|| pulse(n))
    } else {
        None
    }
}

/// Where the cam signal rises (`rising`) or falls on the way from `a` to `b`. The signal is
/// true on `[start, end]`: moving positive it rises at `start` and falls after `end`, moving
/// negative it rises at `end` and falls after `start`.
/// The edge of an input that is on at and beyond `mark`, on the way from `a` to `b`: rising
/// when reaching it from below, falling when leaving it downwards.
fn mark_edge(a: f64, b: f64, mark: f64, rising: bool) -> Option<f64> {
    let up = a < mark && mark <= b;
    let down = b < mark && mark <= a;
    ((rising && up) || (!rising && down)).then_some(mark)
}

fn cam_edge(a: f64, b: f64, cam: ReferenceCam, rising: bool) -> Option<f64> {
    let ReferenceCam { start, end } = cam;
    if b > a {
        if rising {
            (a < start && start <= b).then_some(start)
        } else {
            (a <= end && end < b).then_some(end)
        }
    } else if b < a {
        if rising {
            (b <= end && end < a).then_some(end)
        } else {
            (b < start && start <= a).then_some(start)
        }
    } else {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const IP: IndexPulse = IndexPulse {
        period: 10.0,
        offset: 2.5,
    };

    fn enabled_drive() -> SimDrive {
        let mut d = SimDrive::new(
            SimDriveConfig {
                reference_cam: None,
                index_pulse: None,
                ..SimDriveConfig::default()
            },
            0.001,
        );
        let sp = DriveSetpoint {
            enable: true,
            ..DriveSetpoint::default()
        };
        while !d.feedback().enabled {
            d.apply(&sp);
        }
        d
    }

    fn torque_setpoint(torque: f64, high: f64, low: f64) -> DriveSetpoint {
        DriveSetpoint {
            enable: true,
            mode: DriveMode::Torque,
            torque,
            velocity_limit_high: high,
            velocity_limit_low: low,
            ..DriveSetpoint::default()
        }
    }

    /// Torque mode (MC_TorqueControl): 10 % against 1 % friction at 100 u/s² per % gives
    /// 900 u/s²; the velocity is held at the high limit with a smaller torque applied; a
    /// torque below the friction leaves the load at rest; back in position mode the load
    /// is held where it is (no jump).
    #[test]
    fn torque_mode_accelerates_against_friction_within_the_velocity_limits() {
        let mut d = enabled_drive();
        for _ in 0..100 {
            d.apply(&torque_setpoint(10.0, 500.0, -500.0));
        }
        let fb = d.feedback();
        assert_eq!(fb.mode, DriveMode::Torque);
        assert!(
            (fb.actual_velocity - 90.0).abs() < 0.5,
            "{}",
            fb.actual_velocity
        );
        assert_eq!(fb.actual_torque, 10.0);
        assert!(!fb.velocity_limited);
        for _ in 0..200 {
            d.apply(&torque_setpoint(10.0, 100.0, -500.0));
        }
        let fb = d.feedback();
        assert_eq!(fb.actual_velocity, 100.0);
        assert!(fb.velocity_limited);
        assert!(fb.actual_torque < 10.0, "{}", fb.actual_torque);
        // Held at rest by limits of 0, then back to position mode where the load is.
        d.apply(&torque_setpoint(10.0, 0.0, 0.0));
        assert_eq!(d.feedback().actual_velocity, 0.0);
        let at = d.feedback().actual_position;
        d.apply(&DriveSetpoint {
            enable: true,
            position: at,
            ..DriveSetpoint::default()
        });
        assert_eq!(d.feedback().mode, DriveMode::Position);
        assert!(
            (d.feedback().actual_position - at).abs() < 1e-9,
            "{} vs {at}",
            d.feedback().actual_position
        );

        let mut d = enabled_drive();
        for _ in 0..100 {
            d.apply(&torque_setpoint(0.5, 500.0, -500.0));
        }
        assert_eq!(d.feedback().actual_velocity, 0.0, "static friction holds");
        assert_eq!(d.feedback().actual_position, 0.0);
    }

    /// Velocity mode (CSV, MC_WriteDriveOperationMode Velo1): the load follows the setpoint's
    /// velocity with the position loop's correction and reports the mode.
    #[test]
    fn velocity_mode_follows_the_setpoint() {
        let mut d = enabled_drive();
        for k in 1..=500 {
            d.apply(&DriveSetpoint {
                enable: true,
                mode: DriveMode::Velocity,
                position: 20.0 * k as f64 * 0.001,
                velocity: 20.0,
                ..DriveSetpoint::default()
            });
        }
        let fb = d.feedback();
        assert_eq!(fb.mode, DriveMode::Velocity);
        assert!(
            (fb.actual_velocity - 20.0).abs() < 0.5,
            "{} at {}",
            fb.actual_velocity,
            fb.actual_position
        );
        assert!(
            (fb.actual_position - 10.0).abs() < 0.3,
            "{}",
            fb.actual_position
        );
    }

    #[test]
    fn index_crossing_in_both_directions() {
        assert_eq!(index_crossing(0.0, 3.0, IP), Some(2.5));
        assert_eq!(index_crossing(0.0, 2.5, IP), Some(2.5));
        assert_eq!(
            index_crossing(2.5, 3.0, IP),
            None,
            "leaving a pulse is no crossing"
        );
        assert_eq!(index_crossing(3.0, 12.0, IP), None);
        assert_eq!(index_crossing(3.0, 13.0, IP), Some(12.5));
        assert_eq!(index_crossing(3.0, -20.0, IP), Some(2.5));
        assert_eq!(index_crossing(2.5, -7.0, IP), None);
        assert_eq!(index_crossing(2.5, -7.5, IP), Some(-7.5));
        assert_eq!(index_crossing(-13.0, -7.0, IP), Some(-7.5));
        assert_eq!(index_crossing(5.0, 5.0, IP), None);
        // 3.4999999999999996 / 0.7 rounds to 5.0: the pulse at 5·0.7 is still ahead.
        let ip = IndexPulse {
            period: 0.7,
            offset: 0.0,
        };
        let a = 3.4999999999999996;
        assert_eq!(a / 0.7, 5.0);
        assert!(a < 5.0 * 0.7);
        assert_eq!(index_crossing(a, 3.6, ip), Some(5.0 * 0.7));
        assert_eq!(index_crossing(5.0 * 0.7 + 1e-12, a, ip), Some(5.0 * 0.7));
    }

    #[test]
    fn a_probe_mark_has_a_rising_edge_upwards_and_a_falling_one_downwards() {
        assert_eq!(mark_edge(4.0, 6.0, 5.0, true), Some(5.0));
        assert_eq!(mark_edge(4.0, 6.0, 5.0, false), None);
        assert_eq!(mark_edge(6.0, 4.0, 5.0, false), Some(5.0));
        assert_eq!(mark_edge(5.0, 6.0, 5.0, true), None, "already on");
    }

    #[test]
    fn cam_edges_by_direction() {
        let cam = ReferenceCam {
            start: 20.0,
            end: 25.0,
        };
        assert_eq!(cam_edge(19.0, 21.0, cam, true), Some(20.0));
        assert_eq!(cam_edge(19.0, 21.0, cam, false), None);
        assert_eq!(cam_edge(24.0, 26.0, cam, false), Some(25.0));
        assert_eq!(cam_edge(19.0, 26.0, cam, true), Some(20.0));
        assert_eq!(cam_edge(19.0, 26.0, cam, false), Some(25.0));
        assert_eq!(cam_edge(26.0, 24.0, cam, true), Some(25.0));
        assert_eq!(cam_edge(21.0, 19.0, cam, false), Some(20.0));
        assert_eq!(cam_edge(20.0, 21.0, cam, true), None, "already on the cam");
        assert_eq!(cam_edge(25.0, 24.0, cam, true), None, "already on the cam");
    }
}
