//! An axis at rest (issue 27): powered and standing, or disabled, with nothing running,
//! buffered, coupled, queued or settling, and the same feedback as in the cycle before. Its
//! full step would give the same status and setpoint again, and change nothing but the cycle
//! counter and a timer that only counts (InTargetPosition's dwell; MC_OverrideFilter's quiet
//! time counts from a cycle, decision 180). The kernel then steps it with
//! [`Axis::step_at_rest`], which does only that: a standing axis pays for comparing its
//! feedback, not for the blocks it does not use.
//!
//! What it repeats (the feedback and the setpoint) the kernel keeps in a [`Rest`] record per
//! slot, side by side; what the step changes in the axis (the cycle, the dwell) and the flags
//! it reads lie in the axis's [`Beat`], one cache line. The status's NcCycleCounter is the
//! beat's cycle, put in when the status is read ([`Axis::status`]), so the step does not
//! write the status's line either. With 256 axes a standing axis then costs 1.15–1.19 × what
//! it costs with 16, where it read 8 lines spread over its 6 KB and cost 1.3–1.4 × (docs/
//! benchmarks.md, "Kernel cycle").
//!
//! Entered after two full steps in a row that ended at rest with the same feedback and the
//! same setpoint; left at the first cycle whose feedback differs in any bit, or after any
//! call that changes the axis from outside its step (every `pub` `&mut self` method calls
//! [`Axis::wake`], and so does putting the axis into a slot: the record there is another's).
//!
//! Debug builds hold the claim: every cycle at rest runs the full step too and asserts that
//! it gave what the rest step gives — the setpoint, the status, no event, and in the first
//! cycles at rest and every 64th the whole axis (its `Debug` form, hashed)
//! (`rest_step_is_the_full_step` in `kernel.rs`' tests, and every other test that lets an
//! axis stand).

use super::*;

/// What an axis at rest repeats. Kept by the kernel, one per slot side by side (not in the
/// axis): a step at rest reads it and the axis's [`Beat`], and no other line of the axis.
/// It is this axis's only while the axis's `beat.kept` says so.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Rest {
    /// The feedback of the cycle that ended at rest.
    fb: DriveFeedback,
    /// The setpoint it gave.
    out: DriveSetpoint,
    /// Debug builds: cycles checked against the full step (`step_at_rest_checked`).
    #[cfg(debug_assertions)]
    checks: u32,
}

/// All that a step at rest reads and writes of the axis itself, on one line: with 256 axes
/// a standing step touched 8 lines of its axis, spread over 6 KB, and cost 1.3–1.5 × per
/// axis what it cost with 16.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub(super) struct Beat {
    /// The cycle of the latest step (the status's NcCycleCounter); before the first one, the
    /// kernel's cycle when the axis was put into its slot.
    pub(super) cycle: u64,
    /// InTargetPosition's dwell: how long the axis has stood inside its target window.
    pub(super) in_window_timer: f64,
    /// Counts the status's changes (every full step and every accepted submit): a reader
    /// that copied the status at one count need not copy it again at the same count, except
    /// its cycle counter.
    pub(super) status_seq: u64,
    /// The kernel's [`Rest`] holds this axis's latest full step, which ended quiet, and
    /// nothing changed the axis since.
    pub(super) kept: bool,
    /// … and the full step before it ended the same way: the next step with that feedback
    /// repeats it.
    pub(super) resting: bool,
}

impl Axis {
    /// The axis was changed from outside its step: the next step is a full one.
    pub(super) fn wake(&mut self) {
        self.beat.kept = false;
        self.beat.resting = false;
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
            && (self.beat.in_window_timer == 0.0
                || self.beat.in_window_timer + 1e-12 >= p.axis_target_position_monitoring_time)
    }

    /// At rest: the next step with the same feedback repeats the last one.
    pub fn is_at_rest(&self) -> bool {
        self.beat.resting
    }

    /// The rest step applies to this cycle (`rest`: the kernel's record for this axis). An
    /// axis at rest follows no master.
    #[inline]
    pub(crate) fn at_rest(&self, fb: &DriveFeedback, rest: &Rest) -> bool {
        self.beat.resting && same_reading(&rest.fb, fb)
    }

    /// After a full step: at rest from the next cycle on, or a step closer to it.
    pub(super) fn settle_rest(&mut self, fb: &DriveFeedback, out: &DriveSetpoint, rest: &mut Rest) {
        if !self.quiet() {
            // A moving axis writes nothing but its beat (which its step writes anyway).
            self.beat.kept = false;
            self.beat.resting = false;
            return;
        }
        self.beat.resting = self.beat.kept && same_reading(&rest.fb, fb) && rest.out == *out;
        self.beat.kept = true;
        *rest = Rest {
            fb: *fb,
            out: *out,
            #[cfg(debug_assertions)]
            checks: 0,
        };
    }

    /// One cycle at rest: what the full step would change, and nothing else.
    #[inline]
    pub(crate) fn step_at_rest(
        &mut self,
        dt: f64,
        cycle: u64,
        rest: &Rest,
        out: &mut DriveSetpoint,
    ) {
        *out = rest.out;
        // The dwell counts while the axis stands in its window: then it is past 0 (`quiet`
        // takes it at 0 or past its time), and a step at rest keeps it so.
        if self.beat.in_window_timer > 0.0 {
            self.beat.in_window_timer += dt;
        }
        self.beat.cycle = cycle;
    }

    /// Debug builds: the rest step and the full step side by side (module doc).
    #[cfg(debug_assertions)]
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn step_at_rest_checked(
        &mut self,
        dt: f64,
        fb: &DriveFeedback,
        cams: &crate::cam::CamStore,
        cycle: u64,
        events: &mut impl EventSink,
        rest: &mut Rest,
        out: &mut DriveSetpoint,
    ) {
        struct Counting<'a, E>(&'a mut E, usize);
        impl<E: EventSink> EventSink for Counting<'_, E> {
            fn push(&mut self, event: CommandEvent) {
                self.1 += 1;
                self.0.push(event);
            }
        }
        // The whole axis is compared in the first cycles at rest and every 64th after (its
        // `Debug` form is long); its status and setpoint every cycle.
        let checks = rest.checks;
        rest.checks = checks.wrapping_add(1);
        let deep = checks < 4 || checks % 64 == 0;
        let kept = (self.beat.cycle, self.beat.in_window_timer);
        self.step_at_rest(dt, cycle, rest, out);
        let rest_out = *out;
        let rest_status = self.status();
        let rest_axis = if deep { self.digest() } else { 0 };
        (self.beat.cycle, self.beat.in_window_timer) = kept;
        let mut counting = Counting(events, 0);
        let seq = self.beat.status_seq;
        self.step_full(
            dt,
            fb,
            Master::Uncoupled,
            cams,
            cycle,
            &mut counting,
            out,
            Ahead::NONE,
        );
        // The full step counts a status change; the rest step does not (it changes none).
        self.beat.status_seq = seq;
        let full_axis = if deep { self.digest() } else { 0 };
        assert_eq!(counting.1, 0, "an axis at rest reported an event");
        assert_eq!(*out, rest_out, "an axis at rest changed its setpoint");
        assert_eq!(
            self.status(),
            rest_status,
            "an axis at rest changed its status"
        );
        assert_eq!(
            rest_axis, full_axis,
            "the full step of an axis at rest changed it; after the full step: {self:?}"
        );
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

/// The same feedback, bit for bit (`==` takes −0.0 for 0.0, the status would not), and no
/// NaN in it (a status that shows one never equals itself, and the check would fail). Every
/// field by name, so that a field added to the feedback stops the build here until it is
/// compared; without branches, since a standing machine compares all of them every cycle.
#[inline]
fn same_reading(a: &DriveFeedback, b: &DriveFeedback) -> bool {
    let DriveFeedback {
        ready,
        enabled,
        fault,
        fault_code,
        bus_error,
        actual_position,
        actual_velocity,
        reference_cam,
        limit_positive,
        limit_negative,
        latch_valid,
        latch_position,
        mode,
        actual_torque,
        velocity_limited,
        profile,
    } = *a;
    // A NaN is never the same reading: the status would show it, and NaN ≠ NaN in the status.
    let bits = |x: f64, y: f64| (x.to_bits() ^ y.to_bits()) | u64::from(x.is_nan());
    let numbers = bits(actual_position, b.actual_position)
        | bits(actual_velocity, b.actual_velocity)
        | bits(latch_position, b.latch_position)
        | bits(actual_torque, b.actual_torque)
        | u64::from(fault_code ^ b.fault_code);
    let flags = (ready != b.ready)
        | (enabled != b.enabled)
        | (fault != b.fault)
        | (bus_error != b.bus_error)
        | (reference_cam != b.reference_cam)
        | (limit_positive != b.limit_positive)
        | (limit_negative != b.limit_negative)
        | (latch_valid != b.latch_valid)
        | (velocity_limited != b.velocity_limited)
        | (mode != b.mode)
        | (profile != b.profile);
    numbers == 0 && !flags
}

// A step at rest touches one line of its axis: the beat fits in one.
const _: () = assert!(core::mem::size_of::<Beat>() <= 32 && core::mem::align_of::<Beat>() == 32);

#[cfg(test)]
mod tests {
    use super::*;

    /// Any field that differs, down to a zero's sign, is a new reading; so is a NaN, even
    /// the same one again.
    #[test]
    fn the_same_reading_is_every_field_bit_for_bit() {
        let a = DriveFeedback {
            ready: true,
            enabled: true,
            actual_position: 0.0,
            ..DriveFeedback::default()
        };
        assert!(same_reading(&a, &a));
        let nan = DriveFeedback {
            actual_position: f64::NAN,
            ..a
        };
        assert!(!same_reading(&nan, &nan));
        let nan_torque = DriveFeedback {
            actual_torque: f64::NAN,
            ..a
        };
        assert!(!same_reading(&nan_torque, &nan_torque));
        let changed = [
            DriveFeedback {
                actual_position: -0.0,
                ..a
            },
            DriveFeedback {
                actual_torque: 1e-300,
                ..a
            },
            DriveFeedback {
                latch_position: 1.0,
                ..a
            },
            DriveFeedback { fault_code: 7, ..a },
            DriveFeedback {
                latch_valid: true,
                ..a
            },
            DriveFeedback {
                velocity_limited: true,
                ..a
            },
            DriveFeedback {
                mode: crate::DriveMode::Velocity,
                ..a
            },
            DriveFeedback {
                profile: crate::ProfileFeedback {
                    acknowledge: true,
                    ..a.profile
                },
                ..a
            },
        ];
        for b in changed {
            assert!(!same_reading(&a, &b), "{b:?}");
            assert!(!same_reading(&b, &a), "{b:?}");
        }
    }
}
