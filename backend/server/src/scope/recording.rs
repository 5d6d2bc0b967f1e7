//! One recording: its channels, trigger and state, fed frame by frame by the pump (trigger
//! detection and pre-trigger history live here, off the cycle thread), and the API's view of
//! it.

use std::collections::VecDeque;
use std::sync::Arc;

use motion::AxisSlot;
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::{ScopeFrame, ScopeSignal};

/// Direction of a trigger crossing.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum TriggerEdge {
    /// previous < level ≤ sample.
    #[default]
    Rising,
    /// previous > level ≥ sample.
    Falling,
    /// Rising or falling.
    Either,
}

impl TriggerEdge {
    pub fn crossed(self, prev: f64, v: f64, level: f64) -> bool {
        let rising = prev < level && v >= level;
        let falling = prev > level && v <= level;
        match self {
            TriggerEdge::Rising => rising,
            TriggerEdge::Falling => falling,
            TriggerEdge::Either => rising || falling,
        }
    }
}

/// A trigger on one of the recording's channels.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"channel": 0, "level": 100.0, "edge": "rising", "pre_trigger_s": 0.002}))]
pub struct ScopeTrigger {
    /// Index into `channels`.
    pub channel: usize,
    /// Threshold in the channel's unit.
    pub level: f64,
    /// Default `rising`.
    #[serde(default)]
    pub edge: TriggerEdge,
    /// History kept before the trigger sample (s, 0 … duration_s; default 0).
    #[serde(default)]
    pub pre_trigger_s: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum RecordingState {
    /// Waiting for the trigger (keeping the pre-trigger history).
    Armed,
    /// Collecting samples.
    Recording,
    /// All samples recorded: `t` and `data` are there.
    Done,
    /// Cancelled by `DELETE` before it was done.
    Cancelled,
    /// Samples were lost (see `reason`); a recording never has gaps.
    Failed,
}

impl RecordingState {
    pub fn is_active(self) -> bool {
        matches!(self, RecordingState::Armed | RecordingState::Recording)
    }
}

/// One channel of a recording, as resolved by the server.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
#[schema(example = json!({"axis": "x", "axis_id": 1, "signal": "set_velocity", "unit": "mm/s"}))]
pub struct ScopeChannel {
    /// The axis's name (also when it was given by id); absent for a group's signal.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(example = "x")]
    pub axis: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis_id: Option<i64>,
    /// The group's name for a group's signal (`path_position`, `path_velocity`,
    /// `path_acceleration`, `entry_index`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub group: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub group_id: Option<i64>,
    pub signal: ScopeSignal,
    /// Unit of the values (axis unit, unit/s, unit/s²).
    #[schema(example = "mm")]
    pub unit: String,
}

/// A scope recording. `t` and `data` are only present in `GET /scope/recordings/{id}` of a
/// recording that is `done`.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({
    "id": 3, "state": "done", "cycle_time_s": 0.001,
    "channels": [{"axis": "x", "axis_id": 1, "signal": "set_position", "unit": "mm"},
                 {"axis": "x", "axis_id": 1, "signal": "set_velocity", "unit": "mm/s"}],
    "duration_s": 0.005, "trigger": {"channel": 0, "level": 100.0, "edge": "rising", "pre_trigger_s": 0.002},
    "samples": 5, "pre_trigger_samples": 2, "samples_recorded": 5, "start_cycle": 120343, "trigger_cycle": 120345,
    "created_at": "2025-01-01T12:00:00.000Z", "finished_at": "2025-01-01T12:00:01.204Z",
    "t": [-0.002, -0.001, 0.0, 0.001, 0.002],
    "data": [[99.6, 99.8, 100.0, 100.2, 100.4], [200.0, 200.0, 200.0, 200.0, 200.0]]
}))]
pub struct ScopeRecording {
    pub id: u64,
    pub state: RecordingState,
    /// Why it failed or was cancelled.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// One sample per cycle of this length (s).
    #[schema(example = 0.001)]
    pub cycle_time_s: f64,
    pub channels: Vec<ScopeChannel>,
    /// As requested.
    pub duration_s: f64,
    pub trigger: Option<ScopeTrigger>,
    /// Samples per channel when done: round(duration_s / cycle_time_s).
    pub samples: usize,
    /// Samples before the trigger sample: min(round(pre_trigger_s / cycle_time_s), samples − 1);
    /// 0 without a trigger.
    pub pre_trigger_samples: usize,
    /// Samples per channel recorded so far (the pre-trigger history counts once triggered).
    pub samples_recorded: usize,
    /// Cycle of the first sample. While armed: the cycle the pre-trigger history began in.
    pub start_cycle: u64,
    /// Cycle of the trigger sample (`t` = 0).
    pub trigger_cycle: Option<u64>,
    pub created_at: String,
    pub finished_at: Option<String>,
    /// Seconds, one per sample: relative to the trigger sample (negative before it), or to the
    /// first sample without a trigger.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub t: Option<Vec<f64>>,
    /// Per channel, exactly `samples` values (null where the axis was missing from its slot).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(value_type = Option<Vec<Vec<f64>>>)]
    pub data: Option<Arc<Vec<Vec<f64>>>>,
}

/// A validated request for a recording (the API resolves axes and checks the ranges).
#[derive(Clone, Debug)]
pub struct NewRecording {
    pub channels: Vec<(AxisSlot, ScopeChannel)>,
    pub duration_s: f64,
    pub samples: usize,
    pub trigger: Option<ScopeTrigger>,
    pub pre_trigger_samples: usize,
}

/// Why a recording cannot be created now.
#[derive(Debug, PartialEq)]
pub enum ScopeBusy {
    /// The active recordings and this one would need more than 8 distinct signals.
    Channels { in_use: usize, needed: usize },
    /// Every kept recording is active, or the active ones leave too little memory.
    Recordings,
}

pub(super) struct Recording {
    pub(super) id: u64,
    pub(super) created_at: String,
    pub(super) finished_at: Option<String>,
    pub(super) channels: Vec<ScopeChannel>,
    /// Index of each channel in the frame.
    pub(super) index: Vec<usize>,
    pub(super) duration_s: f64,
    pub(super) samples: usize,
    pub(super) trigger: Option<ScopeTrigger>,
    pub(super) pre: usize,
    pub(super) state: RecordingState,
    pub(super) reason: Option<String>,
    /// Frames of older generations do not carry this recording's channels yet.
    pub(super) generation: u64,
    pub(super) start_cycle: u64,
    pub(super) trigger_cycle: Option<u64>,
    /// The cycle of the frame it expects next (after its first).
    pub(super) next_cycle: Option<u64>,
    /// Pre-trigger history per channel (at most `pre` samples) while armed.
    pub(super) history: Vec<VecDeque<f64>>,
    /// The trigger channel's previous sample.
    pub(super) prev: Option<f64>,
    pub(super) data: Vec<Vec<f64>>,
    pub(super) done: Option<Arc<Vec<Vec<f64>>>>,
}

impl Recording {
    pub(super) fn values(&self) -> usize {
        self.samples * self.channels.len()
    }

    pub(super) fn recorded(&self) -> usize {
        self.data.first().map_or(0, Vec::len)
    }

    pub(super) fn fail(&mut self, reason: String) {
        self.state = RecordingState::Failed;
        self.reason = Some(reason);
        self.finish();
    }

    pub(super) fn finish(&mut self) {
        self.finished_at = Some(crate::store::now_rfc3339());
        self.history = Vec::new();
        if self.state == RecordingState::Done {
            self.done = Some(Arc::new(std::mem::take(&mut self.data)));
        } else {
            self.data = Vec::new();
        }
    }

    /// Takes one frame; true when the recording became final.
    pub(super) fn feed(&mut self, f: &ScopeFrame) -> bool {
        if !self.state.is_active() || f.generation < self.generation || f.cycle < self.start_cycle {
            return false;
        }
        if let Some(expected) = self.next_cycle {
            if f.cycle != expected {
                let lost = f.cycle.saturating_sub(expected);
                self.fail(format!(
                    "{lost} cycles of samples lost from cycle {expected} on: the scope ring \
                     overflowed (the server fell behind the cycle thread)"
                ));
                return true;
            }
        }
        self.next_cycle = Some(f.cycle + 1);
        if self.state == RecordingState::Armed {
            let Some(trigger) = self.trigger else {
                return false;
            };
            let v = f.values[self.index[trigger.channel]];
            let full = self.history.first().map_or(0, VecDeque::len) >= self.pre;
            let fired = full
                && self
                    .prev
                    .is_some_and(|p| trigger.edge.crossed(p, v, trigger.level));
            self.prev = Some(v);
            if !fired {
                if self.pre > 0 {
                    for (h, &i) in self.history.iter_mut().zip(&self.index) {
                        if h.len() == self.pre {
                            h.pop_front();
                        }
                        h.push_back(f.values[i]);
                    }
                }
                self.start_cycle = f.cycle + 1 - self.history[0].len() as u64;
                return false;
            }
            self.state = RecordingState::Recording;
            self.trigger_cycle = Some(f.cycle);
            self.start_cycle = f.cycle - self.pre as u64;
            for (d, h) in self.data.iter_mut().zip(&mut self.history) {
                d.extend(h.drain(..));
            }
            self.history = Vec::new();
        } else if self.recorded() == 0 {
            self.start_cycle = f.cycle;
        }
        for (d, &i) in self.data.iter_mut().zip(&self.index) {
            d.push(f.values[i]);
        }
        if self.recorded() == self.samples {
            self.state = RecordingState::Done;
            self.finish();
            return true;
        }
        false
    }

    pub(super) fn view(
        &self,
        cycle_time_s: f64,
        period_ns: u64,
        with_data: bool,
    ) -> ScopeRecording {
        let data = if with_data { self.done.clone() } else { None };
        let t = data.as_ref().map(|_| {
            let pre = if self.trigger.is_some() { self.pre } else { 0 } as i64;
            // From integers so that t is the nearest double to (i − pre)·cycle (no drift).
            (0..self.samples as i64)
                .map(|i| ((i - pre) * period_ns as i64) as f64 / 1e9)
                .collect()
        });
        ScopeRecording {
            id: self.id,
            state: self.state,
            reason: self.reason.clone(),
            cycle_time_s,
            channels: self.channels.clone(),
            duration_s: self.duration_s,
            trigger: self.trigger,
            samples: self.samples,
            pre_trigger_samples: self.pre,
            samples_recorded: self
                .done
                .as_ref()
                .map_or_else(|| self.recorded(), |d| d.first().map_or(0, Vec::len)),
            start_cycle: self.start_cycle,
            trigger_cycle: self.trigger_cycle,
            created_at: self.created_at.clone(),
            finished_at: self.finished_at.clone(),
            t,
            data,
        }
    }
}
