//! An emulated CiA-402 servo drive behind an emulated ESC: the object dictionary with PDO
//! mapping and assignment (changeable in PRE-OP), the device state machine driven by the
//! controlword, the cyclic synchronous modes CSP, CSV and CST on a plant with lag, inertia and
//! friction, one setpoint taken per SYNC0 pulse, the profile modes PP, PV and homing in which
//! the drive runs the motion itself ([`profile`]), the touch probe (0x60B8–0x60BB) on probe
//! input 1 or the index pulse, digital inputs (limit switches on the plant or forced from
//! outside), and injected faults (a drive fault with its 0x603F error code).

mod profile;

pub use profile::{HOMING_METHODS, Homing, Ramp};

use super::Application;
use super::coe::{self, Access, Od, WriteRules, abort};
use super::esc::{AL_OP, AL_PRE_OP, AL_SAFE_OP, SmConfig};
use super::sii::{Identity, MBOX_IN_START, MBOX_LEN, MBOX_OUT_START};

/// The plant behind the drive, in increments.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plant {
    /// CSP: time constant of the drive's position loop (s).
    pub position_lag: f64,
    /// CSV: time constant of the velocity loop (s).
    pub velocity_lag: f64,
    /// CST: acceleration per per-mille of rated torque (increments/s²).
    pub torque_gain: f64,
    /// CST: viscous friction (1/s).
    pub damping: f64,
    /// Increments per index pulse (one motor turn).
    pub increments_per_turn: u32,
    /// 0x6080 max motor speed (increments/s): velocity limit in CSV, CST and the profile modes.
    pub max_speed: u32,
    /// Hardware limit switches on the plant (0x60FD bits 0 and 1): active at motor positions
    /// ≤ `limit_negative` / ≥ `limit_positive` (increments, where the motor is before any
    /// homing shifted what the drive reports).
    pub limit_negative: Option<f64>,
    pub limit_positive: Option<f64>,
}

impl Default for Plant {
    fn default() -> Self {
        Plant {
            position_lag: 0.001,
            velocity_lag: 0.002,
            torque_gain: 2_000.0,
            damping: 5.0,
            increments_per_turn: 10_000,
            max_speed: 50_000_000,
            limit_negative: None,
            limit_positive: None,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum State {
    NotReadyToSwitchOn,
    SwitchOnDisabled,
    ReadyToSwitchOn,
    SwitchedOn,
    OperationEnabled,
    QuickStopActive,
    FaultReactionActive,
    Fault,
}

pub struct Cia402Emu {
    pub od: Od,
    pub plant: Plant,
    al_state: u8,
    pub state: State,
    /// Position and velocity in increments (the 32-bit objects wrap; these do not).
    pub position: f64,
    pub velocity: f64,
    last_controlword: u16,
    /// SYNC0 pulses taken (the pulse count at the last step), or the time of the last step
    /// without DC.
    last_pulse: Option<u64>,
    last_time: Option<u64>,
    /// Setpoints taken: one per SYNC0 pulse in OP.
    pub setpoints_taken: u64,
    /// Target position unwrapped (increments).
    target: f64,
    probe_input: bool,
    last_probe_input: bool,
    pending_fault: Option<u16>,
    /// A drive like many not written by motiond's authors: without the optional objects
    /// ([`OPTIONAL_OBJECTS`]); it takes any mapping write and checks the mapping only at
    /// PRE-OP → SAFE-OP (AL status code 0x001D/0x001E for an object it does not have).
    pub strict: bool,
    /// Entries one PDO may map, checked at PRE-OP → SAFE-OP (a drive with fewer mappable
    /// entries than motiond's full mapping that says so only then).
    pub max_entries_at_safe_op: Option<u8>,
    /// The profile modes' state (PP, PV, HM).
    profile: profile::Profile,
    /// What the drive reports minus where the motor is on the plant (increments): set by
    /// homing so that the home position reads as the home offset 0x607C.
    shift: f64,
    /// 0x60FD bits forced from outside (the emulator's door), on top of the plant's switches.
    forced_inputs: u32,
    /// How long the position lag has been beyond 0x6065 (s).
    following_error_time: f64,
}

/// What a [`Cia402Emu::strict`] drive lacks: touch probe function, status and edges,
/// digital inputs.
pub const OPTIONAL_OBJECTS: [u16; 5] = [0x60B8, 0x60B9, 0x60BA, 0x60BB, 0x60FD];

const MAPPABLE_RX: &[(u16, usize)] = &[
    (0x6040, 2),
    (0x6060, 1),
    (0x6071, 2),
    (0x607A, 4),
    (0x6081, 4),
    (0x6083, 4),
    (0x6084, 4),
    (0x60B8, 2),
    (0x60FF, 4),
];
const MAPPABLE_TX: &[(u16, usize)] = &[
    (0x603F, 2),
    (0x6041, 2),
    (0x6061, 1),
    (0x6062, 4),
    (0x6064, 4),
    (0x606C, 4),
    (0x6077, 2),
    (0x60B9, 2),
    (0x60BA, 4),
    (0x60BB, 4),
    (0x60F4, 4),
    (0x60FD, 4),
];

/// Entries a PDO mapping object has (sub 1..=this).
const MAX_ENTRIES: u8 = 16;

/// CiA-402 modes of operation (0x6060).
pub const MODE_PP: i8 = 1;
pub const MODE_PV: i8 = 3;
pub const MODE_HM: i8 = 6;
pub const MODE_CSP: i8 = 8;
pub const MODE_CSV: i8 = 9;
pub const MODE_CST: i8 = 10;

/// An input to the emulated drive from outside its process data (the emulator's own fault
/// door): a drive fault with its 0x603F code, the probe input, a limit switch (0x60FD bits).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Input {
    Fault {
        code: u16,
    },
    ProbeInput {
        active: bool,
    },
    LimitSwitch {
        positive: bool,
        active: bool,
    },
    /// Probe input and limit switches off (a fault is cleared by the drive's fault reset).
    Clear,
}

impl Cia402Emu {
    pub fn new(id: &Identity, plant: Plant) -> Cia402Emu {
        let mut od = Od::default();
        od.add(0x1000, 0, &0x0002_0192u32.to_le_bytes(), Access::Ro, false);
        od.add_string(0x1008, &id.name);
        od.add_string(0x1009, "1.0");
        od.add_string(0x100A, env!("CARGO_PKG_VERSION"));
        od.add(0x1018, 0, &[4], Access::Ro, false);
        for (sub, v) in [
            (1, id.vendor_id),
            (2, id.product_code),
            (3, id.revision),
            (4, id.serial),
        ] {
            od.add(0x1018, sub, &v.to_le_bytes(), Access::Ro, false);
        }
        // Default mappings: what a drive ships with before the MainDevice configures it.
        for (index, default) in [
            (0x1600u16, &[0x6040_0010u32, 0x607A_0020][..]),
            (0x1A00, &[0x6041_0010, 0x6064_0020][..]),
        ] {
            od.add(index, 0, &[default.len() as u8], Access::RwPreOp, false);
            for sub in 1..=MAX_ENTRIES {
                let v = default.get(sub as usize - 1).copied().unwrap_or(0);
                od.add(index, sub, &v.to_le_bytes(), Access::RwPreOp, false);
            }
        }
        od.add(0x1C00, 0, &[4], Access::Ro, false);
        for (sub, t) in [(1u8, 1u8), (2, 2), (3, 3), (4, 4)] {
            od.add(0x1C00, sub, &[t], Access::Ro, false);
        }
        for (index, pdo) in [(0x1C12u16, 0x1600u16), (0x1C13, 0x1A00)] {
            od.add(index, 0, &[1], Access::RwPreOp, false);
            od.add(index, 1, &pdo.to_le_bytes(), Access::RwPreOp, false);
            od.add(index, 2, &0u16.to_le_bytes(), Access::RwPreOp, false);
        }
        for index in [0x1C32u16, 0x1C33] {
            od.add(index, 0, &[4], Access::Ro, false);
            od.add(index, 1, &0u16.to_le_bytes(), Access::RwPreOp, false);
            od.add(index, 2, &0u32.to_le_bytes(), Access::RwPreOp, false);
            od.add(index, 3, &0u32.to_le_bytes(), Access::Ro, false);
            // Supported: free run, SM-synchronous, DC SYNC0.
            od.add(
                index,
                4,
                &0b0000_0000_0000_0111u16.to_le_bytes(),
                Access::Ro,
                false,
            );
        }
        for &(index, len) in MAPPABLE_RX {
            od.add(index, 0, &vec![0; len], Access::Rw, true);
        }
        for &(index, len) in MAPPABLE_TX {
            od.add(index, 0, &vec![0; len], Access::Ro, true);
        }
        od.set(0x6060, 0, &[MODE_CSP as u8]);
        od.add(0x6065, 0, &10_000u32.to_le_bytes(), Access::Rw, false);
        od.add(0x6080, 0, &plant.max_speed.to_le_bytes(), Access::Rw, false);
        od.add(0x6085, 0, &1_000_000u32.to_le_bytes(), Access::Rw, false);
        od.add(0x60C2, 0, &[2], Access::Ro, false);
        od.add(0x60C2, 1, &[1], Access::Rw, false);
        od.add(0x60C2, 2, &[(-3i8) as u8], Access::Rw, false);
        // The profile modes' objects (increments, increments/s, increments/s², ms).
        od.add(0x6066, 0, &0u16.to_le_bytes(), Access::Rw, false);
        od.add(0x6067, 0, &10u32.to_le_bytes(), Access::Rw, false);
        od.add(0x6068, 0, &0u16.to_le_bytes(), Access::Rw, false);
        od.add(0x606D, 0, &1_000u16.to_le_bytes(), Access::Rw, false);
        od.add(0x606E, 0, &0u16.to_le_bytes(), Access::Rw, false);
        od.add(0x606F, 0, &1_000u16.to_le_bytes(), Access::Rw, false);
        od.add(0x6070, 0, &0u16.to_le_bytes(), Access::Rw, false);
        od.add(0x607C, 0, &0i32.to_le_bytes(), Access::Rw, false);
        od.add(0x607F, 0, &plant.max_speed.to_le_bytes(), Access::Rw, false);
        od.set(0x6081, 0, &100_000u32.to_le_bytes());
        od.set(0x6083, 0, &1_000_000u32.to_le_bytes());
        od.set(0x6084, 0, &1_000_000u32.to_le_bytes());
        od.add(0x6086, 0, &0i16.to_le_bytes(), Access::Rw, false);
        od.add(0x6098, 0, &[37], Access::Rw, false);
        od.add(0x6099, 0, &[2], Access::Ro, false);
        od.add(0x6099, 1, &50_000u32.to_le_bytes(), Access::Rw, false);
        od.add(0x6099, 2, &10_000u32.to_le_bytes(), Access::Rw, false);
        od.add(0x609A, 0, &1_000_000u32.to_le_bytes(), Access::Rw, false);
        od.add(0x60F2, 0, &0u16.to_le_bytes(), Access::Rw, false);
        // Supported modes (0x6502 bit = mode − 1): PP, PV, HM, CSP, CSV, CST.
        od.add(
            0x6502,
            0,
            &((1u32 << 0) | (1 << 2) | (1 << 5) | (1 << 7) | (1 << 8) | (1 << 9)).to_le_bytes(),
            Access::Ro,
            false,
        );
        Cia402Emu {
            od,
            plant,
            al_state: 1,
            state: State::NotReadyToSwitchOn,
            position: 0.0,
            velocity: 0.0,
            last_controlword: 0,
            last_pulse: None,
            last_time: None,
            setpoints_taken: 0,
            target: 0.0,
            probe_input: false,
            last_probe_input: false,
            pending_fault: None,
            strict: false,
            max_entries_at_safe_op: None,
            profile: profile::Profile::default(),
            shift: 0.0,
            forced_inputs: 0,
            following_error_time: 0.0,
        }
    }

    /// The drive without [`OPTIONAL_OBJECTS`], checking its mapping at SAFE-OP only.
    pub fn strict(id: &Identity, plant: Plant) -> Cia402Emu {
        let mut d = Cia402Emu::new(id, plant);
        for index in OPTIONAL_OBJECTS {
            d.od.entries.remove(&(index, 0));
        }
        d.strict = true;
        d
    }

    /// The mapped entries of the assigned PDOs that are not mappable objects of this drive:
    /// 0x001D (outputs) or 0x001E (inputs), as a drive that checks at SAFE-OP answers.
    fn check_mapping(&self) -> Result<(), u16> {
        for (assign, rx, code) in [(0x1C12u16, true, 0x001Du16), (0x1C13, false, 0x001E)] {
            for i in 1..=self.od.u8(assign, 0) {
                let pdo = self.od.u16(assign, i);
                if self
                    .max_entries_at_safe_op
                    .is_some_and(|n| self.od.u8(pdo, 0) > n)
                {
                    return Err(code);
                }
                for k in 1..=self.od.u8(pdo, 0) {
                    let e = self.od.u32(pdo, k);
                    let index = (e >> 16) as u16;
                    if !mappable(index, e as u8, rx) || self.od.get(index, 0).is_none() {
                        return Err(code);
                    }
                }
            }
        }
        Ok(())
    }

    /// A drive fault (overcurrent, encoder, …) with its 0x603F error code.
    /// What a test or a demo does to the emulated drive from outside (the emulator's fault
    /// door): its fault, its probe input, its limit switches.
    pub fn apply(&mut self, input: Input) {
        match input {
            Input::Fault { code } => self.inject_fault(code),
            Input::ProbeInput { active } => self.set_probe_input(active),
            Input::LimitSwitch { positive, active } => {
                let bit = if positive { 0b010 } else { 0b001 };
                let now = self.forced_inputs;
                self.set_digital_inputs(if active { now | bit } else { now & !bit });
            }
            Input::Clear => {
                self.set_probe_input(false);
                self.set_digital_inputs(0);
            }
        }
    }

    pub fn inject_fault(&mut self, error_code: u16) {
        self.pending_fault = Some(error_code);
    }

    /// 0x60FD forced from outside: bit 0 negative limit switch, bit 1 positive limit switch,
    /// bit 2 home switch (on top of the plant's switches).
    pub fn set_digital_inputs(&mut self, bits: u32) {
        self.forced_inputs = bits;
        self.update_digital_inputs();
    }

    fn update_digital_inputs(&mut self) {
        let (neg, pos) = self.limit_switches();
        let bits = (self.forced_inputs & !0b11) | u32::from(neg) | (u32::from(pos) << 1);
        if self.od.get(0x60FD, 0).is_some() {
            self.od.set(0x60FD, 0, &bits.to_le_bytes());
        }
    }

    /// Where the motor is on the plant (increments): what the drive reports less the shift a
    /// homing run made.
    pub fn plant_position(&self) -> f64 {
        self.position - self.shift
    }

    /// The homing run's state (mode 6).
    pub fn homing(&self) -> Homing {
        self.profile.homing
    }

    /// One setpoint period without a segment: the outputs written as an RxPDO would write
    /// them, the drive stepped in OP, its inputs read as a TxPDO (for tests of the kernel and
    /// the CiA-402 layer against this drive in virtual time, cycle by cycle).
    pub fn exchange_direct(
        &mut self,
        rx: &drives::cia402::RxPdo,
        dt: f64,
    ) -> drives::cia402::TxPdo {
        self.od.set(0x6040, 0, &rx.controlword.to_le_bytes());
        self.od.set(0x607A, 0, &rx.target_position.to_le_bytes());
        self.od.set(0x60FF, 0, &rx.target_velocity.to_le_bytes());
        self.od.set(0x6071, 0, &rx.target_torque.to_le_bytes());
        if matches!(
            rx.mode,
            MODE_PP | MODE_PV | MODE_HM | MODE_CSP | MODE_CSV | MODE_CST
        ) {
            self.od.set(0x6060, 0, &[rx.mode as u8]);
        }
        if self.od.get(0x60B8, 0).is_some() {
            self.od
                .set(0x60B8, 0, &rx.touch_probe_function.to_le_bytes());
        }
        self.od.set(0x6081, 0, &rx.profile_velocity.to_le_bytes());
        self.od
            .set(0x6083, 0, &rx.profile_acceleration.to_le_bytes());
        self.od
            .set(0x6084, 0, &rx.profile_deceleration.to_le_bytes());
        self.step_drive(dt, true);
        let get = |index: u16| {
            self.od
                .get(index, 0)
                .map(<[u8]>::to_vec)
                .unwrap_or_default()
        };
        let i32_of = |b: Vec<u8>| b.try_into().map(i32::from_le_bytes).unwrap_or(0);
        let u16_of = |b: Vec<u8>| b.try_into().map(u16::from_le_bytes).unwrap_or(0);
        drives::cia402::TxPdo {
            statusword: u16_of(get(0x6041)),
            position_actual: i32_of(get(0x6064)),
            velocity_actual: i32_of(get(0x606C)),
            mode_display: self.od.i8(0x6061, 0),
            torque_actual: u16_of(get(0x6077)) as i16,
            error_code: u16_of(get(0x603F)),
            digital_inputs: i32_of(get(0x60FD)) as u32,
            touch_probe_status: u16_of(get(0x60B9)),
            touch_probe_pos_edge: i32_of(get(0x60BA)),
            touch_probe_neg_edge: i32_of(get(0x60BB)),
        }
    }

    /// The touch probe's input 1 (a mark passing the sensor).
    pub fn set_probe_input(&mut self, on: bool) {
        self.probe_input = on;
    }

    /// The assigned PDOs' mapped objects: (index, sub, bytes), in process image order.
    fn mapping(&self, assign: u16) -> Vec<(u16, u8, usize)> {
        let mut out = Vec::new();
        for i in 1..=self.od.u8(assign, 0) {
            let pdo = self.od.u16(assign, i);
            for k in 1..=self.od.u8(pdo, 0) {
                let e = self.od.u32(pdo, k);
                out.push(((e >> 16) as u16, (e >> 8) as u8, (e & 0xFF) as usize / 8));
            }
        }
        out
    }

    fn statusword(&self) -> u16 {
        let base: u16 = match self.state {
            State::NotReadyToSwitchOn => 0x0000,
            State::SwitchOnDisabled => 0x0040,
            State::ReadyToSwitchOn => 0x0031,
            State::SwitchedOn => 0x0033,
            State::OperationEnabled => 0x0037,
            State::QuickStopActive => 0x0017,
            State::FaultReactionActive => 0x001F,
            State::Fault => 0x0008,
        };
        let mut sw = base | (1 << 9);
        if self.state == State::OperationEnabled {
            let mode = self.od.i8(0x6060, 0);
            if matches!(mode, MODE_PP | MODE_PV | MODE_HM) {
                sw |= self.profile.bits;
                if mode == MODE_PP && self.following_error() {
                    sw |= 1 << 13;
                }
            } else if mode == MODE_CSP {
                // Bit 12: the drive follows the target; bit 10: target reached.
                sw |= 1 << 12;
                if (self.target - self.position).abs() < 10.0 {
                    sw |= 1 << 10;
                }
                if self.following_error() {
                    sw |= 1 << 13;
                }
            } else {
                sw |= 1 << 12;
            }
        }
        sw
    }

    fn command(&mut self, cw: u16) {
        use State::*;
        let reset_edge = cw & 0x80 != 0 && self.last_controlword & 0x80 == 0;
        self.last_controlword = cw;
        let shutdown = cw & 0x87 == 0x06;
        let switch_on = cw & 0x8F == 0x07;
        let enable = cw & 0x8F == 0x0F;
        let disable_voltage = cw & 0x82 == 0x00;
        let quick_stop = cw & 0x86 == 0x02;
        self.state = match self.state {
            NotReadyToSwitchOn => SwitchOnDisabled,
            Fault if reset_edge => {
                self.od.set(0x603F, 0, &0u16.to_le_bytes());
                SwitchOnDisabled
            }
            Fault => Fault,
            FaultReactionActive => Fault,
            SwitchOnDisabled if shutdown => ReadyToSwitchOn,
            SwitchOnDisabled => SwitchOnDisabled,
            ReadyToSwitchOn | SwitchedOn | OperationEnabled if disable_voltage => SwitchOnDisabled,
            OperationEnabled if quick_stop => QuickStopActive,
            ReadyToSwitchOn | SwitchedOn if quick_stop => SwitchOnDisabled,
            ReadyToSwitchOn if switch_on => SwitchedOn,
            ReadyToSwitchOn | SwitchedOn if enable => {
                // Entering operation: hold where the motor is.
                self.target = self.position;
                OperationEnabled
            }
            SwitchedOn | OperationEnabled if shutdown => ReadyToSwitchOn,
            OperationEnabled if switch_on => SwitchedOn,
            QuickStopActive if disable_voltage => SwitchOnDisabled,
            s => s,
        };
    }

    /// Following error: beyond the window 0x6065 for at least the timeout 0x6066 (ms).
    fn following_error(&self) -> bool {
        self.following_error_time > 0.0
            && self.following_error_time + 1e-9 >= f64::from(self.od.u16(0x6066, 0)) * 1e-3
    }

    /// Unwraps a 32-bit target against the current one.
    fn unwrap_target(&self, raw: i32) -> f64 {
        let now = self.target.round() as i64;
        let delta = raw.wrapping_sub(now as i32) as i64;
        (now + delta) as f64
    }

    /// One SYNC0 period (or one free-run step) of `dt` seconds.
    fn step_drive(&mut self, dt: f64, op: bool) {
        if let Some(code) = self.pending_fault.take() {
            self.od.set(0x603F, 0, &code.to_le_bytes());
            self.state = State::FaultReactionActive;
        }
        // Outside OP the outputs are not valid: the drive sees no command (disable voltage).
        let cw = if op { self.od.u16(0x6040, 0) } else { 0 };
        self.command(cw);
        let mode = self.od.i8(0x6060, 0);
        self.od.set(0x6061, 0, &[mode as u8]);
        // Plant coordinates: a homing run may shift the reported ones within the period.
        let before = self.position - self.shift;
        if self.state != State::OperationEnabled || !matches!(mode, MODE_PP | MODE_PV | MODE_HM) {
            self.profile_disabled();
        }
        match self.state {
            State::OperationEnabled => {
                self.setpoints_taken += u64::from(op);
                match mode {
                    MODE_PP | MODE_PV | MODE_HM => self.step_profile(mode, dt, cw),
                    MODE_CSP => {
                        self.target = self.unwrap_target(self.od.i32(0x607A, 0));
                        let k = 1.0 - (-dt / self.plant.position_lag).exp();
                        self.position += (self.target - self.position) * k;
                        self.velocity = (self.position - self.shift - before) / dt;
                    }
                    MODE_CSV => {
                        let v = (self.od.i32(0x60FF, 0) as f64)
                            .clamp(-(self.plant.max_speed as f64), self.plant.max_speed as f64);
                        let k = 1.0 - (-dt / self.plant.velocity_lag).exp();
                        self.velocity += (v - self.velocity) * k;
                        self.position += self.velocity * dt;
                        self.target = self.position;
                    }
                    MODE_CST => {
                        let t = self.od.i16(0x6071, 0) as f64;
                        let a = t * self.plant.torque_gain - self.plant.damping * self.velocity;
                        let max = self.plant.max_speed as f64;
                        self.velocity = (self.velocity + a * dt).clamp(-max, max);
                        self.position += self.velocity * dt;
                        self.target = self.position;
                        self.od.set(0x6077, 0, &(t as i16).to_le_bytes());
                    }
                    _ => {}
                }
            }
            State::QuickStopActive => {
                let dec = self.od.u32(0x6085, 0) as f64;
                let dv = dec * dt;
                self.velocity = if self.velocity.abs() <= dv {
                    0.0
                } else {
                    self.velocity - dv * self.velocity.signum()
                };
                self.position += self.velocity * dt;
                self.target = self.position;
                if self.velocity == 0.0 {
                    self.state = State::SwitchOnDisabled;
                }
            }
            _ => {
                // Power stage off: the motor stands (the brake holds it).
                self.velocity = 0.0;
                self.target = self.position;
            }
        }
        self.probe(before);
        self.update_digital_inputs();
        let lag = (self.target - self.position).abs();
        self.following_error_time = if lag > f64::from(self.od.u32(0x6065, 0)) {
            self.following_error_time + dt
        } else {
            0.0
        };
        let demand = self.target.round() as i64 as i32;
        self.od.set(0x6062, 0, &demand.to_le_bytes());
        let pos = self.position.round() as i64 as i32;
        self.od.set(0x6064, 0, &pos.to_le_bytes());
        self.od
            .set(0x606C, 0, &(self.velocity.round() as i32).to_le_bytes());
        let fe = (self.target - self.position).round() as i32;
        self.od.set(0x60F4, 0, &fe.to_le_bytes());
        let sw = self.statusword();
        self.od.set(0x6041, 0, &sw.to_le_bytes());
    }

    /// 0x60B8 function bit 0 enable, bits 2–3 source (0 input 1, 1 index pulse), bit 4/5 latch
    /// the positive/negative edge; 0x60B9 status bit 0 enabled, bit 1/2 edge stored.
    fn probe(&mut self, before: f64) {
        let f = self.od.u16(0x60B8, 0);
        let mut status = self.od.u16(0x60B9, 0);
        if f & 1 == 0 {
            self.od.set(0x60B9, 0, &0u16.to_le_bytes());
            self.last_probe_input = self.probe_input;
            return;
        }
        status |= 1;
        let index_source = (f >> 2) & 0b11 == 1;
        let (rising, falling, at) = if index_source {
            // The index pulse is where the motor is on the plant.
            let turn = self.plant.increments_per_turn.max(1) as f64;
            let now = self.position - self.shift;
            let crossed = (before / turn).floor() != (now / turn).floor();
            let at = if now > before {
                (now / turn).floor() * turn
            } else {
                (before / turn).floor() * turn
            };
            (crossed, false, at + self.shift)
        } else {
            (
                self.probe_input && !self.last_probe_input,
                !self.probe_input && self.last_probe_input,
                self.position,
            )
        };
        self.last_probe_input = self.probe_input;
        let at = at.round() as i64 as i32;
        if f & (1 << 4) != 0 && rising && status & 0b010 == 0 {
            status |= 0b010;
            self.od.set(0x60BA, 0, &at.to_le_bytes());
        }
        if f & (1 << 5) != 0 && falling && status & 0b100 == 0 {
            status |= 0b100;
            self.od.set(0x60BB, 0, &at.to_le_bytes());
        }
        self.od.set(0x60B9, 0, &status.to_le_bytes());
    }
}

struct Rules {
    al_state: u8,
    /// Mapping entries are taken as written (checked at SAFE-OP).
    lax: bool,
}

fn mappable(index: u16, bits: u8, rx: bool) -> bool {
    let table = if rx { MAPPABLE_RX } else { MAPPABLE_TX };
    table
        .iter()
        .any(|&(i, len)| i == index && len * 8 == bits as usize)
}

impl WriteRules for Rules {
    fn check_write(&self, od: &Od, index: u16, sub: u8, value: &[u8]) -> Result<(), u32> {
        let entry = od
            .entries
            .get(&(index, sub))
            .expect("checked by the caller");
        if entry.access == Access::RwPreOp && self.al_state != AL_PRE_OP {
            return Err(abort::DEVICE_STATE);
        }
        let mut v = [0u8; 4];
        v[..value.len().min(4)].copy_from_slice(&value[..value.len().min(4)]);
        let v = u32::from_le_bytes(v);
        let mapping = (0x1600..0x1800).contains(&index) || (0x1A00..0x1C00).contains(&index);
        let assign = index == 0x1C12 || index == 0x1C13;
        if (mapping || assign) && sub > 0 && od.u8(index, 0) != 0 {
            return Err(abort::SUB0_NOT_ZERO);
        }
        if mapping && sub == 0 {
            if v > u32::from(MAX_ENTRIES) {
                return Err(abort::VALUE_RANGE);
            }
            let rx = index < 0x1800;
            let mut bytes = 0;
            for k in 1..=v as u8 {
                let e = od.u32(index, k);
                if !self.lax && !mappable((e >> 16) as u16, e as u8, rx) {
                    return Err(abort::NOT_MAPPABLE);
                }
                bytes += (e & 0xFF) / 8;
            }
            if bytes > 64 {
                return Err(abort::PDO_TOO_LONG);
            }
        }
        if assign && sub == 0 {
            if v > 2 {
                return Err(abort::VALUE_RANGE);
            }
            let range = if index == 0x1C12 {
                0x1600..0x1800
            } else {
                0x1A00..0x1C00
            };
            for k in 1..=v as u8 {
                let pdo = od.u16(index, k);
                if !range.contains(&pdo) || od.get(pdo, 0).is_none() {
                    return Err(abort::VALUE_RANGE);
                }
            }
        }
        if assign && sub > 0 && v != 0 && od.get(v as u16, 0).is_none() {
            return Err(abort::VALUE_RANGE);
        }
        if index == 0x6060
            && !matches!(
                v as u8 as i8,
                MODE_PP | MODE_PV | MODE_HM | MODE_CSP | MODE_CSV | MODE_CST
            )
        {
            return Err(abort::VALUE_RANGE);
        }
        if index == 0x6098 && !HOMING_METHODS.contains(&(v as u8 as i8)) {
            return Err(abort::VALUE_RANGE);
        }
        if index == 0x6086 && v as u16 != 0 {
            // Only the linear ramp.
            return Err(abort::VALUE_RANGE);
        }
        Ok(())
    }
}

impl Application for Cia402Emu {
    fn mailbox(&mut self, request: &[u8]) -> Option<Vec<u8>> {
        let rules = Rules {
            al_state: self.al_state,
            lax: self.strict,
        };
        coe::serve(&mut self.od, &rules, request, MBOX_LEN as usize)
    }

    fn mailbox_layout(&self) -> ((u16, u16), (u16, u16)) {
        ((MBOX_OUT_START, MBOX_LEN), (MBOX_IN_START, MBOX_LEN))
    }

    fn check_safe_op(&self) -> Result<(), u16> {
        if self.strict || self.max_entries_at_safe_op.is_some() {
            self.check_mapping()
        } else {
            Ok(())
        }
    }

    fn process_data_sizes(&self) -> (usize, usize) {
        (
            self.mapping(0x1C12).iter().map(|m| m.2).sum(),
            self.mapping(0x1C13).iter().map(|m| m.2).sum(),
        )
    }

    fn al_changed(&mut self, state: u8) {
        self.al_state = state;
        if state < AL_SAFE_OP {
            self.last_pulse = None;
            self.last_time = None;
        }
    }

    fn step(
        &mut self,
        mem: &mut [u8],
        sm2: SmConfig,
        sm3: SmConfig,
        al_state: u8,
        system_time: u64,
        sync0: Option<(u64, u64)>,
    ) {
        if al_state < AL_SAFE_OP {
            // The drive runs its state machine without process data (not ready in INIT).
            if self.state == State::NotReadyToSwitchOn {
                self.step_drive(0.001, false);
            }
            return;
        }
        let op = al_state == AL_OP;
        // How many setpoint periods passed: SYNC0 pulses, or the time since the last step.
        let periods: Vec<f64> = match sync0 {
            Some((start, cycle)) => {
                let pulses = if system_time >= start {
                    (system_time - start) / cycle + 1
                } else {
                    0
                };
                let last = self.last_pulse.unwrap_or(pulses);
                self.last_pulse = Some(pulses);
                let n = pulses.saturating_sub(last).min(1000);
                vec![cycle as f64 * 1e-9; n as usize]
            }
            None => {
                let last = self.last_time.unwrap_or(system_time);
                self.last_time = Some(system_time);
                let dt = (system_time.saturating_sub(last) as f64 * 1e-9).min(0.01);
                if dt > 0.0 { vec![dt] } else { vec![] }
            }
        };
        if periods.is_empty() {
            return;
        }
        // Outputs: taken at the pulse from the RxPDO image.
        if op && sm2.enabled {
            let mut p = sm2.start as usize;
            for (index, sub, n) in self.mapping(0x1C12) {
                let bytes = mem[p..p + n].to_vec();
                self.od.set(index, sub, &bytes);
                p += n;
            }
        }
        for dt in periods {
            self.step_drive(dt, op);
        }
        if sm3.enabled {
            let mut p = sm3.start as usize;
            for (index, sub, n) in self.mapping(0x1C13) {
                let v = self
                    .od
                    .get(index, sub)
                    .map(<[u8]>::to_vec)
                    .unwrap_or_else(|| vec![0; n]);
                mem[p..p + n].copy_from_slice(&v[..n]);
                p += n;
            }
        }
    }

    fn as_any(&mut self) -> &mut dyn std::any::Any {
        self
    }
}

/// A drive as the emulated segment holds it: SII image and application.
pub fn servo(id: Identity, plant: Plant) -> (Vec<u8>, Box<dyn Application>) {
    let sii = super::sii::servo_drive(&id);
    (sii, Box::new(Cia402Emu::new(&id, plant)))
}

/// A [`Cia402Emu::strict`] drive as the emulated segment holds it.
pub fn strict_servo(id: Identity, plant: Plant) -> (Vec<u8>, Box<dyn Application>) {
    let sii = super::sii::servo_drive(&id);
    (sii, Box::new(Cia402Emu::strict(&id, plant)))
}
