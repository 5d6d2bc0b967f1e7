//! MC_TouchProbe and MC_AbortTrigger: a position latched at an edge of a signal, Done with the
//! recorded data as its result.

use motion::CommandKind;
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::*;
use crate::app::{AxisEntry, Registry};
use crate::error::AppResult;

/// The family's catalogue entries (the form: `crate::blocks`).
macro_rules! entries {
    ($catalogue:ident) => {
        $catalogue! {
            touch_probe: "touch-probe" at axes, TouchProbeBody, TouchProbeBody::to_kind, Operator, Done, [has_result, lease_free],
                "MC_TouchProbe: latch the position at one edge of a signal (window optional); Done with `result`";
            abort_trigger: "abort-trigger" at axes, EmptyBody, |_, _, _| Ok(CommandKind::AbortTrigger), Operator, Done, [lease_free],
                "MC_AbortTrigger: end the running probe cycle (CommandAborted) without a capture";
        }
    };
}
pub(crate) use entries;

/// The signal a touch probe latches on (`TRIGGER_REF.SignalSource`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum ProbeSignal {
    /// The drive's probe input 1 (a measuring probe; simulated: `probe_mark`/`probe_input`
    /// faults).
    #[default]
    Input1,
    /// The encoder's zero pulse (rising edge only).
    IndexPulse,
    /// The reference cam input.
    ReferenceCam,
}

/// `E_SignalEdge`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum SignalEdge {
    #[default]
    Rising,
    Falling,
}

/// MC_TouchProbe (§4.3.1): the trigger (signal, edge, modulo positions) and the window.
#[derive(Clone, Debug, Default, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"signal": "input1", "edge": "rising", "window_only": true,
    "first_position": 100.0, "last_position": 120.0}))]
pub struct TouchProbeBody {
    /// Default `input1`.
    #[serde(default)]
    pub signal: ProbeSignal,
    /// Default `rising`.
    #[serde(default)]
    pub edge: SignalEdge,
    /// Only a position within [first_position, last_position] completes the cycle; an edge
    /// outside is discarded and the latch re-armed.
    #[serde(default)]
    pub window_only: bool,
    #[serde(default)]
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub first_position: f64,
    #[serde(default)]
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub last_position: f64,
    /// Positions (window and recorded) modulo the axis's period (AxisEncoderModuloValue);
    /// the window repeats every period and wraps when first > last.
    #[serde(default)]
    pub modulo_positions: bool,
}

impl TouchProbeBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        use motion::LatchSource as L;
        let mut c = Check::default();
        c.finite("first_position", self.first_position);
        c.finite("last_position", self.last_position);
        if self.window_only && !self.modulo_positions && self.first_position > self.last_position {
            c.fail(
                "last_position",
                "an absolute window needs first_position <= last_position (only a modulo window wraps)",
            );
        }
        let source = match (self.signal, self.edge) {
            (ProbeSignal::Input1, SignalEdge::Rising) => L::Input1Rising,
            (ProbeSignal::Input1, SignalEdge::Falling) => L::Input1Falling,
            (ProbeSignal::ReferenceCam, SignalEdge::Rising) => L::CamRising,
            (ProbeSignal::ReferenceCam, SignalEdge::Falling) => L::CamFalling,
            (ProbeSignal::IndexPulse, SignalEdge::Rising) => L::IndexPulse,
            (ProbeSignal::IndexPulse, SignalEdge::Falling) => {
                c.fail("edge", "the index pulse is latched on its rising edge only");
                L::IndexPulse
            }
        };
        c.done(CommandKind::TouchProbe(motion::TouchProbe {
            source,
            window_only: self.window_only,
            first_position: self.first_position,
            last_position: self.last_position,
            modulo_positions: self.modulo_positions,
        }))
    }
}
