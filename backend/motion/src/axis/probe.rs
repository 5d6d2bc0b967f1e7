//! MC_TouchProbe / MC_AbortTrigger (spec §4.3): the drive's latch armed for one edge, a
//! window that discards edges outside it and re-arms, the recorded position into the status.
//! Apart because a probe cycle runs beside whatever the axis does (it moves nothing).

use super::*;

/// A running probe cycle.
#[derive(Debug)]
pub(super) struct Probe {
    held: Held,
    input: TouchProbe,
    /// The latch was asked for in the setpoint of an earlier cycle (a `latch_valid` read now
    /// answers this cycle's arming, never an older one).
    sent: bool,
    /// Drop the latch enable for one cycle: the drive re-arms on its next rising edge.
    rearm: bool,
}

impl Probe {
    pub(super) fn source(&self) -> LatchSource {
        self.input.source
    }
}

impl Axis {
    /// MC_TouchProbe: a new probe cycle, unless one runs or homing holds the latch.
    pub(super) fn submit_touch_probe(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        id: CommandId,
        t: TouchProbe,
    ) -> Result<(), ErrorId> {
        if !(t.first_position.is_finite() && t.last_position.is_finite()) {
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        if t.window_only && !t.modulo_positions && t.first_position > t.last_position {
            // An absolute window must not be empty (only a modulo window wraps).
            return Err(ErrorId::PARAMETER_NOT_CORRECT);
        }
        if self.probe.is_some() || self.latch.is_some() {
            return Err(ErrorId::TOUCH_PROBE_BUSY);
        }
        let held = Held::start(
            cx,
            id,
            FbOutputs {
                busy: true,
                ..Default::default()
            },
        );
        self.probe = Some(Probe {
            held,
            input: t,
            sent: false,
            rearm: false,
        });
        self.status.probe.armed = true;
        self.status.external_latch_valid = false;
        Ok(())
    }

    /// MC_AbortTrigger: the running probe cycle ends with CommandAborted; Done at once either
    /// way (nothing to cancel is not an error).
    pub(super) fn abort_trigger(&mut self, cx: &mut Ctx<'_, impl EventSink>) {
        if let Some(mut p) = self.probe.take() {
            p.held.end(cx, End::Aborted);
            self.status.external_latch_valid = false;
        }
        self.status.probe.armed = false;
    }

    /// One cycle of the probe: read what the drive latched for the arming sent earlier,
    /// check the window, and say whether the latch is to be armed in this cycle's setpoint.
    pub(super) fn step_probe(
        &mut self,
        cx: &mut Ctx<'_, impl EventSink>,
        fb: &DriveFeedback,
    ) -> bool {
        if self.latch.is_none() && self.idle(Idle::PROBE) {
            // No probe armed (`idle.rs`): what the lines below find.
            return false;
        }
        // Homing takes the drive's one latch: a probe cycle gives way.
        if self.latch.is_some() {
            self.abort_trigger(cx);
            return false;
        }
        let period = self.p().axis_encoder_modulo_value;
        let Some(p) = self.probe.as_mut() else {
            return false;
        };
        if p.rearm {
            p.rearm = false;
            p.sent = false;
            return false;
        }
        if p.sent && fb.latch_valid {
            let absolute = self.enc_k * fb.latch_position + self.offset + self.corrections.read;
            let modulo = if period > 0.0 {
                absolute.rem_euclid(period)
            } else {
                absolute
            };
            let t = p.input;
            let x = if t.modulo_positions { modulo } else { absolute };
            let inside = if t.first_position <= t.last_position {
                (t.first_position..=t.last_position).contains(&x)
            } else {
                x >= t.first_position || x <= t.last_position
            };
            if t.window_only && !inside {
                // Discarded; the latch is armed again after one cycle without it.
                p.rearm = true;
                return false;
            }
            let mut p = self.probe.take().expect("a probe cycle runs");
            let s = &mut self.status.probe;
            s.armed = false;
            s.command = p.held.id;
            s.counter += 1;
            s.recorded_position = x;
            s.absolute_position = absolute;
            s.modulo_position = modulo;
            self.status.external_latch_valid = true;
            p.held.done_with(cx, BlockResult::Probe(*s));
            return false;
        }
        p.sent = true;
        true
    }
}
