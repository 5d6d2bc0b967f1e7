//! The modes in which the emulated drive runs the motion itself (CiA-402 §6.2): profile
//! position (PP, 1), profile velocity (PV, 3) and homing (HM, 6). The drive's own profile
//! generator is a linear ramp (0x6086 = 0, the one every CiA-402 drive has), stepped once per
//! setpoint period; its position demand goes through the same position loop as CSP, its
//! velocity demand in PV through the velocity loop of CSV.
//!
//! PP takes a set point on the rising edge of controlword bit 4 (target 0x607A, profile
//! velocity 0x6081, acceleration 0x6083, deceleration 0x6084, bit 6 relative as 0x60F2 says):
//! with bit 5 (change set immediately) it replaces the running one at once, without it the
//! drive keeps one set point in a buffer and starts it when the running one stands on its
//! target. Statusword bit 12 (set-point acknowledge) rises with the accepted set point and
//! falls once bit 4 is low and the buffer is free again; bit 10 (target reached) is set when
//! no set point is left and the actual position stayed within 0x6067 for 0x6068 ms, or, while
//! halted (bit 8, braking at 0x6084 as it is then), when the drive stands. Releasing the halt
//! resumes the set point.
//!
//! HM runs the homing method of 0x6098 on the plant's limit switches and index pulse (methods
//! 1, 2, 17, 18, 33, 34, 35 and 37), at 0x6099:1 while searching a switch and 0x6099:2 while
//! searching the zero, with 0x609A as acceleration; at the end the drive stands on the home
//! position and reports 0x607C there (decision 165).

use super::{Cia402Emu, MODE_HM, MODE_PP, MODE_PV};

/// The drive's position demand: a linear-ramp profile generator.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Ramp {
    /// Position demand (increments, the drive's reported coordinates).
    pub pos: f64,
    /// Velocity demand (increments/s).
    pub vel: f64,
}

fn approach(v: f64, goal: f64, step: f64) -> f64 {
    if v < goal {
        (v + step).min(goal)
    } else {
        (v - step).max(goal)
    }
}

impl Ramp {
    /// One period towards `target`, at most `vmax`, accelerating at `acc` and braking at `dec`
    /// so that it comes to rest exactly on the target (the braking velocity is the one from
    /// which whole periods of `dec` end there). True once it stands on the target.
    pub fn to_position(&mut self, target: f64, vmax: f64, acc: f64, dec: f64, dt: f64) -> bool {
        let d = target - self.pos;
        if d == 0.0 && self.vel == 0.0 {
            return true;
        }
        let dir = if d >= 0.0 { 1.0 } else { -1.0 };
        let dec = dec.max(1.0);
        let acc = acc.max(1.0);
        // k whole periods of braking from k·dec·dt travel dec·dt²·k(k+1)/2.
        let k = (0.25 + 2.0 * d.abs() / (dec * dt * dt)).sqrt() - 0.5;
        let v_brake = dec * dt * k;
        let v_goal = dir * vmax.max(0.0).min(v_brake);
        let rate = if self.vel * v_goal >= 0.0 && v_goal.abs() > self.vel.abs() {
            acc
        } else {
            dec
        };
        let v = approach(self.vel, v_goal, rate * dt);
        if v * dir >= 0.0 && (v * dt).abs() >= d.abs() && self.vel.abs() <= 2.0 * dec * dt {
            // The last period lands on the target (at the velocity that does), the next one
            // stands there.
            self.pos = target;
            self.vel = d / dt;
            return d == 0.0;
        }
        self.pos += v * dt;
        self.vel = v;
        false
    }

    /// One period towards the velocity `goal` (accelerating at `acc`, braking at `dec`).
    pub fn to_velocity(&mut self, goal: f64, acc: f64, dec: f64, dt: f64) {
        let speeding_up = self.vel * goal >= 0.0 && goal.abs() > self.vel.abs();
        let rate = if speeding_up { acc } else { dec };
        self.vel = approach(self.vel, goal, rate.max(1.0) * dt);
        self.pos += self.vel * dt;
    }
}

/// One PP set point as the drive took it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SetPoint {
    /// Absolute target (increments).
    pub target: f64,
    pub velocity: f64,
    pub acceleration: f64,
    pub deceleration: f64,
}

/// What homing is doing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Homing {
    /// Not started, or interrupted (bit 4 dropped, halt, mode or power left).
    Idle,
    /// Searching: moving in `dir` at `speed` until `seek` happens.
    Seek { seek: Seek, dir: f64, speed: f64 },
    /// The home position was found at `home` (plant coordinates): back onto it.
    Return { home: f64 },
    /// Homing attained: the drive stands on the home position.
    Attained,
    /// Homing failed (a limit switch the method does not look for, or no such method).
    Failed,
}

/// The event a homing search waits for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Seek {
    /// The limit switch on the side of travel becomes active.
    SwitchOn,
    /// The limit switch behind the travel becomes inactive; then the index pulse (`index`)
    /// or home right there.
    SwitchOff { index: bool },
    /// The next index pulse.
    Index,
}

/// The homing methods the emulated drive has (0x6098).
pub const HOMING_METHODS: [i8; 8] = [1, 2, 17, 18, 33, 34, 35, 37];

/// The profile modes' state (what survives from one period to the next).
#[derive(Clone, Copy, Debug)]
pub struct Profile {
    pub ramp: Ramp,
    /// The mode the state belongs to, and whether the drive was in Operation enabled: a
    /// change of either starts again from where the motor is.
    pub mode: i8,
    pub enabled: bool,
    pub last_cw: u16,
    pub active: Option<SetPoint>,
    pub buffered: Option<SetPoint>,
    pub ack: bool,
    /// The target of the last set point taken (PP), what bit 10 compares with.
    pub goal: f64,
    /// Time within the position window (PP) or velocity window (PV), and speed zero (PV).
    pub in_window: f64,
    pub at_zero: f64,
    pub homing: Homing,
    /// Statusword bits 10, 12 and 13 of the profile mode.
    pub bits: u16,
}

impl Default for Profile {
    fn default() -> Self {
        Profile {
            ramp: Ramp::default(),
            mode: 0,
            enabled: false,
            last_cw: 0,
            active: None,
            buffered: None,
            ack: false,
            goal: 0.0,
            in_window: 0.0,
            at_zero: 0.0,
            homing: Homing::Idle,
            bits: 0,
        }
    }
}

const BIT_TARGET_REACHED: u16 = 1 << 10;
const BIT_12: u16 = 1 << 12;
const BIT_13: u16 = 1 << 13;
const CW_NEW_SET_POINT: u16 = 1 << 4;
const CW_IMMEDIATE: u16 = 1 << 5;
const CW_RELATIVE: u16 = 1 << 6;
const CW_HALT: u16 = 1 << 8;

impl Cia402Emu {
    /// Leaving Operation enabled (or the profile modes): set points dropped, a homing run
    /// interrupted.
    pub(super) fn profile_disabled(&mut self) {
        let p = &mut self.profile;
        p.enabled = false;
        p.active = None;
        p.buffered = None;
        p.ack = false;
        if matches!(p.homing, Homing::Seek { .. } | Homing::Return { .. }) {
            p.homing = Homing::Idle;
        }
    }

    /// One period of a profile mode in Operation enabled.
    pub(super) fn step_profile(&mut self, mode: i8, dt: f64, cw: u16) {
        if !self.profile.enabled || self.profile.mode != mode {
            self.profile_disabled();
            self.profile = Profile {
                ramp: Ramp {
                    pos: self.target,
                    vel: if mode == MODE_PV { self.velocity } else { 0.0 },
                },
                mode,
                enabled: true,
                last_cw: cw,
                goal: self.target,
                homing: if self.profile.homing == Homing::Attained && mode == MODE_HM {
                    Homing::Attained
                } else {
                    Homing::Idle
                },
                ..Profile::default()
            };
        }
        // Plant coordinates: homing may move the reported ones within the period.
        let before = self.position - self.shift;
        match mode {
            MODE_PP => self.step_pp(dt, cw),
            MODE_PV => self.step_pv(dt, cw),
            MODE_HM => self.step_homing(dt, cw),
            _ => {}
        }
        self.profile.last_cw = cw;
        if mode != MODE_PV {
            // The drive's position loop follows its own demand.
            self.target = self.profile.ramp.pos;
            let k = 1.0 - (-dt / self.plant.position_lag).exp();
            self.position += (self.target - self.position) * k;
            self.velocity = (self.position - self.shift - before) / dt;
        }
        if mode == MODE_HM {
            self.check_homing_events(before);
            self.profile.bits = self.homing_bits();
        }
    }

    fn step_pp(&mut self, dt: f64, cw: u16) {
        let edge = cw & CW_NEW_SET_POINT != 0 && self.profile.last_cw & CW_NEW_SET_POINT == 0;
        let immediate = cw & CW_IMMEDIATE != 0;
        if edge && (immediate || self.profile.buffered.is_none()) {
            let raw = self.od.i32(0x607A, 0);
            let target = if cw & CW_RELATIVE != 0 {
                // 0x60F2 bits 0–1: relative to the preceding target, the position demand or
                // the actual position.
                let base = match self.od.u16(0x60F2, 0) & 0b11 {
                    0 => self
                        .profile
                        .buffered
                        .or(self.profile.active)
                        .map_or(self.profile.goal, |s| s.target),
                    1 => self.profile.ramp.pos,
                    _ => self.position,
                };
                base + f64::from(raw)
            } else {
                let now = self.profile.ramp.pos.round() as i64;
                (now + i64::from(raw.wrapping_sub(now as i32))) as f64
            };
            let max = f64::from(self.od.u32(0x607F, 0).min(self.plant.max_speed));
            let sp = SetPoint {
                target,
                velocity: f64::from(self.od.u32(0x6081, 0)).min(max),
                acceleration: f64::from(self.od.u32(0x6083, 0)),
                deceleration: f64::from(self.od.u32(0x6084, 0)),
            };
            let p = &mut self.profile;
            if immediate || p.active.is_none() {
                p.active = Some(sp);
                p.buffered = None;
                p.goal = sp.target;
            } else {
                p.buffered = Some(sp);
            }
            p.ack = true;
        }
        let halt = cw & CW_HALT != 0;
        let p = &mut self.profile;
        if halt {
            // The profile deceleration as it is now (a controller brakes harder by writing
            // it with the halt).
            let dec = f64::from(self.od.u32(0x6084, 0));
            p.ramp.to_velocity(0.0, dec, dec, dt);
        } else if let Some(sp) = p.active {
            if p.ramp
                .to_position(sp.target, sp.velocity, sp.acceleration, sp.deceleration, dt)
            {
                p.active = p.buffered.take();
                if let Some(next) = p.active {
                    p.goal = next.target;
                }
            }
        } else {
            p.ramp.vel = 0.0;
        }
        if cw & CW_NEW_SET_POINT == 0 && p.buffered.is_none() {
            p.ack = false;
        }
        let window = f64::from(self.od.u32(0x6067, 0));
        let within = p.active.is_none() && (self.position - p.goal).abs() <= window;
        p.in_window = if within { p.in_window + dt } else { 0.0 };
        let reached = if halt {
            p.ramp.vel == 0.0
        } else {
            within && p.in_window + 1e-9 >= f64::from(self.od.u16(0x6068, 0)) * 1e-3
        };
        p.bits = if reached { BIT_TARGET_REACHED } else { 0 } | if p.ack { BIT_12 } else { 0 };
    }

    fn step_pv(&mut self, dt: f64, cw: u16) {
        let max = f64::from(self.plant.max_speed);
        let halt = cw & CW_HALT != 0;
        let goal = if halt {
            0.0
        } else {
            f64::from(self.od.i32(0x60FF, 0)).clamp(-max, max)
        };
        let acc = f64::from(self.od.u32(0x6083, 0));
        let dec = f64::from(self.od.u32(0x6084, 0));
        self.profile.ramp.to_velocity(goal, acc, dec, dt);
        let k = 1.0 - (-dt / self.plant.velocity_lag).exp();
        self.velocity += (self.profile.ramp.vel - self.velocity) * k;
        self.position += self.velocity * dt;
        self.target = self.position;
        self.profile.ramp.pos = self.position;
        let window = f64::from(self.od.u16(0x606D, 0));
        let threshold = f64::from(self.od.u16(0x606F, 0));
        let p = &mut self.profile;
        p.in_window = if (goal - self.velocity).abs() <= window {
            p.in_window + dt
        } else {
            0.0
        };
        p.at_zero = if self.velocity.abs() <= threshold {
            p.at_zero + dt
        } else {
            0.0
        };
        let reached =
            p.in_window + 1e-9 >= f64::from(self.od.u16(0x606E, 0)) * 1e-3 && p.in_window > 0.0;
        let zero = p.at_zero > 0.0 && p.at_zero + 1e-9 >= f64::from(self.od.u16(0x6070, 0)) * 1e-3;
        p.bits = if reached { BIT_TARGET_REACHED } else { 0 } | if zero { BIT_12 } else { 0 };
    }

    /// The plant's limit switches where the motor is (plant coordinates), with the inputs
    /// forced from outside: (negative, positive).
    pub(super) fn limit_switches(&self) -> (bool, bool) {
        let at = self.position - self.shift;
        let forced = self.forced_inputs;
        (
            forced & 0b01 != 0 || self.plant.limit_negative.is_some_and(|n| at <= n),
            forced & 0b10 != 0 || self.plant.limit_positive.is_some_and(|p| at >= p),
        )
    }

    fn start_homing(&mut self) {
        let method = self.od.i8(0x6098, 0);
        let switch = f64::from(self.od.u32(0x6099, 1));
        let zero = f64::from(self.od.u32(0x6099, 2));
        let (neg, pos) = self.limit_switches();
        // The side of the reference switch: −1 negative (methods 1, 17), +1 positive (2, 18).
        let side = match method {
            1 | 17 => -1.0,
            2 | 18 => 1.0,
            _ => 0.0,
        };
        let index = matches!(method, 1 | 2);
        self.profile.homing = match method {
            1 | 2 | 17 | 18 => {
                let on = if side < 0.0 { neg } else { pos };
                if on {
                    Homing::Seek {
                        seek: Seek::SwitchOff { index },
                        dir: -side,
                        speed: zero,
                    }
                } else {
                    Homing::Seek {
                        seek: Seek::SwitchOn,
                        dir: side,
                        speed: switch,
                    }
                }
            }
            33 | 34 => Homing::Seek {
                seek: Seek::Index,
                dir: if method == 33 { -1.0 } else { 1.0 },
                speed: zero,
            },
            35 | 37 => {
                let here = self.position - self.shift;
                self.set_home(here);
                Homing::Attained
            }
            _ => Homing::Failed,
        };
    }

    /// The home position is `home` (plant coordinates): from now on the drive reports the
    /// home offset 0x607C there.
    fn set_home(&mut self, home: f64) {
        let shift = f64::from(self.od.i32(0x607C, 0)) - home;
        let by = shift - self.shift;
        self.shift = shift;
        self.position += by;
        self.target += by;
        self.profile.ramp.pos += by;
        self.profile.goal += by;
    }

    fn step_homing(&mut self, dt: f64, cw: u16) {
        let start = cw & CW_NEW_SET_POINT != 0 && self.profile.last_cw & CW_NEW_SET_POINT == 0;
        let halt = cw & CW_HALT != 0;
        let running = matches!(
            self.profile.homing,
            Homing::Seek { .. } | Homing::Return { .. }
        );
        if running && (halt || cw & CW_NEW_SET_POINT == 0) {
            // Interrupted: bit 4 dropped or halt.
            self.profile.homing = Homing::Idle;
        } else if start && !halt && !running {
            self.start_homing();
        }
        let acc = f64::from(self.od.u32(0x609A, 0));
        let zero = f64::from(self.od.u32(0x6099, 2));
        match self.profile.homing {
            Homing::Idle | Homing::Attained => {
                self.profile.ramp.to_velocity(0.0, acc, acc, dt);
            }
            Homing::Failed => {
                let quick = f64::from(self.od.u32(0x6085, 0));
                self.profile.ramp.to_velocity(0.0, quick, quick, dt);
            }
            Homing::Seek { dir, speed, .. } => {
                self.profile.ramp.to_velocity(dir * speed, acc, acc, dt);
            }
            Homing::Return { home } => {
                let home_here = home + self.shift;
                if self.profile.ramp.to_position(home_here, zero, acc, acc, dt) {
                    self.set_home(home);
                    self.profile.homing = Homing::Attained;
                }
            }
        }
    }

    /// Looks at the motor's travel since `before` (plant coordinates) for what the search
    /// waits for, and at the limit switches for a failure.
    fn check_homing_events(&mut self, before: f64) {
        let Homing::Seek { seek, dir, .. } = self.profile.homing else {
            return;
        };
        let now = self.position - self.shift;
        let (neg, pos) = self.limit_switches();
        let ahead = if dir < 0.0 { neg } else { pos };
        let behind = if dir < 0.0 { pos } else { neg };
        let zero = f64::from(self.od.u32(0x6099, 2));
        match seek {
            Seek::SwitchOn if ahead => {
                let method = self.od.i8(0x6098, 0);
                self.profile.homing = Homing::Seek {
                    seek: Seek::SwitchOff {
                        index: matches!(method, 1 | 2),
                    },
                    dir: -dir,
                    speed: zero,
                };
            }
            Seek::SwitchOn => {}
            _ if ahead => self.profile.homing = Homing::Failed,
            Seek::SwitchOff { index } if !behind && (now - before) * dir > 0.0 => {
                // The edge: where the plant's switch ends, or where the motor is when the
                // switch was forced from outside.
                let edge = if dir > 0.0 {
                    self.plant
                        .limit_negative
                        .filter(|&n| n >= before && n <= now)
                } else {
                    self.plant
                        .limit_positive
                        .filter(|&p| p <= before && p >= now)
                }
                .unwrap_or(now);
                self.profile.homing = if index {
                    Homing::Seek {
                        seek: Seek::Index,
                        dir,
                        speed: zero,
                    }
                } else {
                    Homing::Return { home: edge }
                };
            }
            Seek::SwitchOff { .. } => {}
            Seek::Index => {
                let turn = f64::from(self.plant.increments_per_turn.max(1));
                let (a, b) = (before / turn, now / turn);
                if a.floor() != b.floor() {
                    let pulse = if now > before { b.floor() } else { a.floor() } * turn;
                    self.profile.homing = Homing::Return { home: pulse };
                }
            }
        }
    }

    /// Statusword bits 10, 12, 13 in homing mode (CiA-402 table of the homing status).
    fn homing_bits(&self) -> u16 {
        let standing = self.profile.ramp.vel == 0.0;
        match self.profile.homing {
            Homing::Idle if standing => BIT_TARGET_REACHED,
            Homing::Idle | Homing::Seek { .. } | Homing::Return { .. } => 0,
            Homing::Attained => BIT_12 | if standing { BIT_TARGET_REACHED } else { 0 },
            Homing::Failed => BIT_13 | if standing { BIT_TARGET_REACHED } else { 0 },
        }
    }
}

#[cfg(test)]
mod tests;
