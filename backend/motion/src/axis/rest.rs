//! An axis at rest (issue 27): powered and standing, or disabled, with nothing running,
//! buffered, coupled, queued or settling, and the same feedback as in the cycle before. Its
//! full step would give the same status and setpoint again, and change nothing but the cycle
//! counter and a timer that only counts (InTargetPosition's dwell; MC_OverrideFilter's quiet
//! time counts from a cycle, decision 180). [`Axis::step`] then does only that: a standing
//! axis pays for reading its feedback, not for the blocks it does not use.
//!
//! Entered after two full steps in a row that ended at rest with the same feedback and the
//! same setpoint; left at the first cycle whose feedback differs, whose master is not
//! "uncoupled", or after any call that changes the axis from outside its step (every
//! `pub` `&mut self` method calls [`Axis::wake`]).
//!
//! Debug builds hold the claim: every cycle at rest runs the full step too and asserts that
//! it gave what the rest step gives — the setpoint, the status, no event, and in the first
//! cycles at rest and every 64th the whole axis (its `Debug` form, hashed)
//! (`rest_step_is_the_full_step` in `kernel.rs`' tests, and every other test that lets an
//! axis stand).

use super::*;

/// What an axis at rest repeats, and since when it may.
#[derive(Clone, Copy, Debug)]
pub(super) struct Rest {
    /// The feedback of the cycle that ended at rest.
    fb: DriveFeedback,
    /// The setpoint it gave.
    out: DriveSetpoint,
    /// InTargetPosition's dwell counts (the axis stands inside its target window).
    in_window: bool,
    /// A second full step with the same feedback ended at rest with the same setpoint.
    confirmed: bool,
    /// Debug builds: cycles checked against the full step (`step_at_rest_checked`).
    #[cfg(debug_assertions)]
    checks: u32,
}

impl Axis {
    /// The axis was changed from outside its step: the next step is a full one.
    pub(super) fn wake(&mut self) {
        self.rest = None;
        self.resting = false;
        self.forget_idle();
    }

    /// Nothing in the axis moves, waits or counts towards anything: the state its next full
    /// step would leave unchanged, given the same feedback.
    fn quiet(&self) -> bool {
        let p = &self.config.parameters;
        let powered = match self.mode {
            // A disabled axis waiting for its drive counts towards the power-on timeout.
            Mode::Disabled => !self.enable,
            Mode::Enabled => self.enable && self.status.power_status,
            Mode::Stopping | Mode::ErrorStop => return false,
        };
        powered
            && self.job.is_none()
            && self.next.is_none()
            && self.stop.is_none()
            && self.pending_reset.is_none()
            && !self.disable_when_idle
            && !self.fault_reset
            && self.reset_grace == 0
            && self.lag_timer == 0.0
            && self.coupling.is_none()
            && self.superposition.running.is_none()
            && self.latch.is_none()
            && self.probe.is_none()
            && self.cam.nothing_queued()
            && !self.cam.waits_for_coupling()
            && self.cam.idle_info
            && self.phasing.settled()
            && self.corrections.settled()
            && self.override_filter.settled()
            && self.torque.settled()
            && self.group.group.is_none()
            && !self.group_reset
            && !self.drive_executed()
            && self.drive.cmd.mode == crate::drive::ProfileMode::Off
            && self.act_acc == 0.0
            // The dwell either counts past its time already or does not count at all.
            && (self.in_window_timer == 0.0
                || self.in_window_timer + 1e-12 >= p.axis_target_position_monitoring_time)
    }

    /// At rest: the next step with the same feedback repeats the last one.
    pub fn is_at_rest(&self) -> bool {
        self.rest.is_some_and(|r| r.confirmed)
    }

    /// The rest step applies to this cycle.
    pub(super) fn at_rest(&self, fb: &DriveFeedback, master: &Master) -> bool {
        // The flag first: it shares its line with the flags every step reads, the rest
        // record does not.
        self.resting
            && self.rest.as_ref().is_some_and(|r| {
                r.confirmed && same_reading(&r.fb, fb) && *master == Master::Uncoupled
            })
    }

    /// After a full step: at rest from the next cycle on, or a step closer to it.
    pub(super) fn settle_rest(&mut self, fb: &DriveFeedback, out: &DriveSetpoint) {
        if !self.quiet() {
            // Written only when it changes: a moving axis dirties nothing here.
            if self.rest.is_some() {
                self.rest = None;
            }
            self.resting = false;
            return;
        }
        let confirmed = self
            .rest
            .is_some_and(|r| same_reading(&r.fb, fb) && r.out == *out);
        self.resting = confirmed;
        self.rest = Some(Rest {
            fb: *fb,
            out: *out,
            in_window: self.in_window_timer > 0.0,
            confirmed,
            #[cfg(debug_assertions)]
            checks: 0,
        });
    }

    /// One cycle at rest: what the full step would change, and nothing else.
    pub(super) fn step_at_rest(&mut self, dt: f64, cycle: u64, out: &mut DriveSetpoint) {
        let Some(r) = self.rest.as_ref() else {
            return;
        };
        *out = r.out;
        if r.in_window {
            self.in_window_timer += dt;
        }
        self.cycle = cycle;
        self.status.nc_cycle_counter = cycle;
    }

    /// Debug builds: the rest step and the full step side by side (module doc).
    #[cfg(debug_assertions)]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn step_at_rest_checked(
        &mut self,
        dt: f64,
        fb: &DriveFeedback,
        master: Master,
        cams: &crate::cam::CamStore,
        cycle: u64,
        events: &mut impl EventSink,
        out: &mut DriveSetpoint,
    ) {
        struct Counting<'a, E>(&'a mut E, usize);
        impl<E: EventSink> EventSink for Counting<'_, E> {
            fn push(&mut self, event: CommandEvent) {
                self.1 += 1;
                self.0.push(event);
            }
        }
        let mut rest = self.rest.take();
        // The whole axis is compared in the first cycles at rest and every 64th after (its
        // `Debug` form is long); its status and setpoint every cycle.
        let checks = rest.as_mut().map_or(0, |r| {
            r.checks = r.checks.wrapping_add(1);
            r.checks - 1
        });
        let deep = checks < 4 || checks % 64 == 0;
        let kept = (
            self.cycle,
            self.status.nc_cycle_counter,
            self.in_window_timer,
        );
        self.rest = rest;
        self.step_at_rest(dt, cycle, out);
        let rest_out = *out;
        let rest_status = self.status;
        self.rest = None;
        let rest_axis = if deep { self.digest() } else { 0 };
        (
            self.cycle,
            self.status.nc_cycle_counter,
            self.in_window_timer,
        ) = kept;
        let mut counting = Counting(events, 0);
        let seq = self.status_seq;
        self.step_full(dt, fb, master, cams, cycle, &mut counting, out);
        // The full step counts a status change; the rest step does not (it changes none).
        self.status_seq = seq;
        self.rest = None;
        let full_axis = if deep { self.digest() } else { 0 };
        assert_eq!(counting.1, 0, "an axis at rest reported an event");
        assert_eq!(*out, rest_out, "an axis at rest changed its setpoint");
        assert_eq!(
            self.status, rest_status,
            "an axis at rest changed its status"
        );
        assert_eq!(
            rest_axis, full_axis,
            "the full step of an axis at rest changed it; after the full step: {self:?}"
        );
        self.rest = rest;
    }

    /// A hash of the whole axis as `Debug` writes it, made without allocating (the
    /// allocation-free tests step axes at rest in debug builds too).
    #[cfg(debug_assertions)]
    fn digest(&self) -> u64 {
        struct Fnv(u64);
        impl core::fmt::Write for Fnv {
            fn write_str(&mut self, s: &str) -> core::fmt::Result {
                for b in s.bytes() {
                    self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x100_0000_01b3);
                }
                Ok(())
            }
        }
        let mut h = Fnv(0xcbf2_9ce4_8422_2325);
        let _ = core::fmt::Write::write_fmt(&mut h, format_args!("{self:?}"));
        h.0
    }
}

/// The same feedback, down to the sign of a zero in the readings the status shows (`==` takes
/// −0.0 for 0.0, the status would not).
fn same_reading(a: &DriveFeedback, b: &DriveFeedback) -> bool {
    a == b
        && a.actual_position.to_bits() == b.actual_position.to_bits()
        && a.actual_velocity.to_bits() == b.actual_velocity.to_bits()
        && a.actual_torque.to_bits() == b.actual_torque.to_bits()
}
