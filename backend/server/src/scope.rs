//! Scope recordings: the cycle thread samples up to [`SCOPE_CHANNELS`] signals every cycle into
//! a bounded ring ([`ScopeFrame`]); the pump drains the ring into the [`Recordings`] kept here,
//! where trigger detection and the pre-trigger history live.
//!
//! What the cycle thread samples is the union of what the active recordings need, handed to it
//! as a [`ScopeConfig`] through the request queue. A channel keeps its index in the frame while
//! any active recording uses it, so a recording reads the same index for its whole life; each
//! configuration carries a generation, and a recording only reads frames whose generation is at
//! least the one that added its channels.
//!
//! A recording is never gappy: it expects the frames of consecutive cycles, and a missing cycle
//! (the ring overflowed because the pump fell behind) fails it with the number of cycles lost.

use std::collections::{BTreeMap, VecDeque};
use std::sync::Arc;

use motion::{AxisSlot, AxisStatus};
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

/// Signals sampled at once (the frame's width).
pub const SCOPE_CHANNELS: usize = 8;
/// Frames the ring holds: 4 s at 250 µs, 16 s at 1 ms, far more than the pump's 1 ms period.
pub const SCOPE_RING: usize = 1 << 14;
/// Longest recording in samples (cycles).
pub const MAX_SAMPLES: usize = 600_000;
/// Recordings kept in memory (active and finished); the oldest finished ones go first.
pub const MAX_RECORDINGS: usize = 8;
/// Values (samples × channels) kept over all recordings: 9.6 M f64 ≈ 77 MB.
pub const MAX_VALUES: usize = 9_600_000;

/// What the scope can sample of an axis (the axis's status after the cycle's kernel step).
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize, ToSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum ScopeSignal {
    SetPosition,
    ActualPosition,
    SetVelocity,
    ActualVelocity,
    SetAcceleration,
    ActualAcceleration,
    FollowingError,
}

impl ScopeSignal {
    pub const ALL: [ScopeSignal; 7] = [
        ScopeSignal::SetPosition,
        ScopeSignal::ActualPosition,
        ScopeSignal::SetVelocity,
        ScopeSignal::ActualVelocity,
        ScopeSignal::SetAcceleration,
        ScopeSignal::ActualAcceleration,
        ScopeSignal::FollowingError,
    ];

    pub fn name(self) -> &'static str {
        match self {
            ScopeSignal::SetPosition => "set_position",
            ScopeSignal::ActualPosition => "actual_position",
            ScopeSignal::SetVelocity => "set_velocity",
            ScopeSignal::ActualVelocity => "actual_velocity",
            ScopeSignal::SetAcceleration => "set_acceleration",
            ScopeSignal::ActualAcceleration => "actual_acceleration",
            ScopeSignal::FollowingError => "following_error",
        }
    }

    pub fn parse(s: &str) -> Option<ScopeSignal> {
        Self::ALL.into_iter().find(|x| x.name() == s)
    }

    #[inline]
    pub fn sample(self, s: &AxisStatus) -> f64 {
        match self {
            ScopeSignal::SetPosition => s.set_position,
            ScopeSignal::ActualPosition => s.actual_position,
            ScopeSignal::SetVelocity => s.set_velocity,
            ScopeSignal::ActualVelocity => s.actual_velocity,
            ScopeSignal::SetAcceleration => s.set_acceleration,
            ScopeSignal::ActualAcceleration => s.actual_acceleration,
            ScopeSignal::FollowingError => s.following_error,
        }
    }

    /// The unit of the signal for an axis whose positions are in `unit`.
    pub fn unit(self, unit: &str) -> String {
        match self {
            ScopeSignal::SetVelocity | ScopeSignal::ActualVelocity => format!("{unit}/s"),
            ScopeSignal::SetAcceleration | ScopeSignal::ActualAcceleration => format!("{unit}/s²"),
            _ => unit.to_string(),
        }
    }
}

/// What the cycle thread samples: `Copy`, handed over through the request queue.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ScopeConfig {
    pub generation: u64,
    pub channels: [Option<(AxisSlot, ScopeSignal)>; SCOPE_CHANNELS],
}

impl ScopeConfig {
    pub fn is_active(&self) -> bool {
        self.channels.iter().any(Option::is_some)
    }
}

/// One cycle's samples. Unused channels and axes missing from their slot read NaN.
#[derive(Clone, Copy, Debug)]
pub struct ScopeFrame {
    pub cycle: u64,
    pub generation: u64,
    pub values: [f64; SCOPE_CHANNELS],
}

impl ScopeFrame {
    /// Samples `config` from the statuses of one cycle (no allocation: runs on the cycle thread).
    #[inline]
    pub fn sample(cycle: u64, config: &ScopeConfig, axes: &[Option<AxisStatus>]) -> ScopeFrame {
        let mut values = [f64::NAN; SCOPE_CHANNELS];
        for (v, c) in values.iter_mut().zip(&config.channels) {
            if let Some((slot, signal)) = c {
                if let Some(Some(s)) = axes.get(*slot as usize) {
                    *v = signal.sample(s);
                }
            }
        }
        ScopeFrame {
            cycle,
            generation: config.generation,
            values,
        }
    }
}

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
    /// The axis's name (also when it was given by id).
    #[schema(example = "x")]
    pub axis: String,
    pub axis_id: i64,
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

struct Recording {
    id: u64,
    created_at: String,
    finished_at: Option<String>,
    channels: Vec<ScopeChannel>,
    /// Index of each channel in the frame.
    index: Vec<usize>,
    duration_s: f64,
    samples: usize,
    trigger: Option<ScopeTrigger>,
    pre: usize,
    state: RecordingState,
    reason: Option<String>,
    /// Frames of older generations do not carry this recording's channels yet.
    generation: u64,
    start_cycle: u64,
    trigger_cycle: Option<u64>,
    /// The cycle of the frame it expects next (after its first).
    next_cycle: Option<u64>,
    /// Pre-trigger history per channel (at most `pre` samples) while armed.
    history: Vec<VecDeque<f64>>,
    /// The trigger channel's previous sample.
    prev: Option<f64>,
    data: Vec<Vec<f64>>,
    done: Option<Arc<Vec<Vec<f64>>>>,
}

impl Recording {
    fn values(&self) -> usize {
        self.samples * self.channels.len()
    }

    fn recorded(&self) -> usize {
        self.data.first().map_or(0, Vec::len)
    }

    fn fail(&mut self, reason: String) {
        self.state = RecordingState::Failed;
        self.reason = Some(reason);
        self.finish();
    }

    fn finish(&mut self) {
        self.finished_at = Some(crate::store::now_rfc3339());
        self.history = Vec::new();
        if self.state == RecordingState::Done {
            self.done = Some(Arc::new(std::mem::take(&mut self.data)));
        } else {
            self.data = Vec::new();
        }
    }

    /// Takes one frame; true when the recording became final.
    fn feed(&mut self, f: &ScopeFrame) -> bool {
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

    fn view(&self, cycle_time_s: f64, period_ns: u64, with_data: bool) -> ScopeRecording {
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

/// The recordings and the channel layout the cycle thread samples.
pub struct Recordings {
    cycle_time_s: f64,
    period_ns: u64,
    next_id: u64,
    generation: u64,
    /// Per frame index: the signal and how many active recordings use it.
    layout: [Option<(AxisSlot, ScopeSignal, usize)>; SCOPE_CHANNELS],
    /// The layout changed and the cycle thread has not been handed it yet.
    dirty: bool,
    recordings: BTreeMap<u64, Recording>,
}

impl Recordings {
    pub fn new(cycle_time_s: f64, period_ns: u64) -> Self {
        Recordings {
            cycle_time_s,
            period_ns,
            next_id: 1,
            generation: 0,
            layout: [None; SCOPE_CHANNELS],
            dirty: false,
            recordings: BTreeMap::new(),
        }
    }

    /// The configuration the cycle thread should sample now.
    pub fn config(&self) -> ScopeConfig {
        let mut c = ScopeConfig {
            generation: self.generation,
            ..Default::default()
        };
        for (o, l) in c.channels.iter_mut().zip(&self.layout) {
            *o = l.map(|(slot, signal, _)| (slot, signal));
        }
        c
    }

    /// The layout changed since the cycle thread was last handed it: returns the config to
    /// hand over (and forgets the change; call [`Recordings::handover_failed`] if that fails).
    pub fn take_dirty(&mut self) -> Option<ScopeConfig> {
        std::mem::take(&mut self.dirty).then(|| self.config())
    }

    pub fn handover_failed(&mut self) {
        self.dirty = true;
    }

    /// Adds a recording, allocating its channels in the frame. Returns its id and the config
    /// to hand to the cycle thread (whose generation the recording waits for).
    pub fn create(&mut self, r: NewRecording) -> Result<(u64, ScopeConfig), ScopeBusy> {
        // Channels: those already sampled are shared, new ones need free indices.
        let mut wanted: Vec<(AxisSlot, ScopeSignal)> = Vec::new();
        for (slot, c) in &r.channels {
            if !wanted.contains(&(*slot, c.signal)) {
                wanted.push((*slot, c.signal));
            }
        }
        let find = |layout: &[Option<(AxisSlot, ScopeSignal, usize)>],
                    w: (AxisSlot, ScopeSignal)| {
            layout
                .iter()
                .position(|l| l.is_some_and(|(s, g, _)| (s, g) == w))
        };
        let new = wanted
            .iter()
            .filter(|w| find(&self.layout, **w).is_none())
            .count();
        let in_use = self.layout.iter().filter(|l| l.is_some()).count();
        if in_use + new > SCOPE_CHANNELS {
            return Err(ScopeBusy::Channels {
                in_use,
                needed: new,
            });
        }
        self.make_room(r.samples * r.channels.len())?;

        for w in &wanted {
            match find(&self.layout, *w) {
                Some(i) => {
                    if let Some(l) = &mut self.layout[i] {
                        l.2 += 1;
                    }
                }
                None => {
                    let i = self.layout.iter().position(Option::is_none).unwrap();
                    self.layout[i] = Some((w.0, w.1, 1));
                }
            }
        }
        let index = r
            .channels
            .iter()
            .map(|(slot, c)| find(&self.layout, (*slot, c.signal)).unwrap())
            .collect();
        self.generation += 1;
        self.dirty = false;
        let id = self.next_id;
        self.next_id += 1;
        let n = r.channels.len();
        let pre = if r.trigger.is_some() {
            r.pre_trigger_samples
        } else {
            0
        };
        let armed = r.trigger.is_some();
        self.recordings.insert(
            id,
            Recording {
                id,
                created_at: crate::store::now_rfc3339(),
                finished_at: None,
                channels: r.channels.into_iter().map(|(_, c)| c).collect(),
                index,
                duration_s: r.duration_s,
                samples: r.samples,
                trigger: r.trigger,
                pre,
                state: if armed {
                    RecordingState::Armed
                } else {
                    RecordingState::Recording
                },
                reason: None,
                generation: self.generation,
                start_cycle: 0,
                trigger_cycle: None,
                next_cycle: None,
                history: if armed {
                    (0..n).map(|_| VecDeque::with_capacity(pre)).collect()
                } else {
                    Vec::new()
                },
                prev: None,
                data: (0..n)
                    .map(|_| Vec::with_capacity(if armed { 0 } else { r.samples }))
                    .collect(),
                done: None,
            },
        );
        Ok((id, self.config()))
    }

    /// Evicts the oldest finished recordings until one more of `values` fits.
    fn make_room(&mut self, values: usize) -> Result<(), ScopeBusy> {
        let active: usize = self
            .recordings
            .values()
            .filter(|r| r.state.is_active())
            .map(Recording::values)
            .sum();
        let active_n = self
            .recordings
            .values()
            .filter(|r| r.state.is_active())
            .count();
        if active_n >= MAX_RECORDINGS || active + values > MAX_VALUES {
            return Err(ScopeBusy::Recordings);
        }
        loop {
            let kept: usize = self
                .recordings
                .values()
                .filter(|r| r.state.is_active() || r.done.is_some())
                .map(Recording::values)
                .sum();
            if self.recordings.len() < MAX_RECORDINGS && kept + values <= MAX_VALUES {
                return Ok(());
            }
            let oldest = self
                .recordings
                .values()
                .find(|r| !r.state.is_active())
                .map(|r| r.id);
            match oldest {
                Some(id) => {
                    self.recordings.remove(&id);
                }
                None => return Err(ScopeBusy::Recordings),
            }
        }
    }

    /// The cycle a new configuration took effect in (the cycle thread's reply): the recordings
    /// of that generation start there (unless a frame told them already).
    pub fn started(&mut self, id: u64, cycle: u64) {
        if let Some(r) = self.recordings.get_mut(&id) {
            if r.state.is_active() && r.next_cycle.is_none() {
                r.start_cycle = cycle;
            }
        }
    }

    /// Releases the frame indices of a recording that is no longer active.
    fn release(&mut self, id: u64) {
        let Some(r) = self.recordings.get(&id) else {
            return;
        };
        let mut seen = Vec::new();
        for &i in &r.index {
            if seen.contains(&i) {
                continue;
            }
            seen.push(i);
            if let Some(l) = &mut self.layout[i] {
                l.2 -= 1;
                if l.2 == 0 {
                    self.layout[i] = None;
                }
            }
        }
        self.generation += 1;
        self.dirty = true;
    }

    /// Takes the frames the cycle thread produced. Returns true when the layout changed
    /// (recordings ended), so that a new configuration should be handed over.
    pub fn feed(&mut self, frames: impl IntoIterator<Item = ScopeFrame>) -> bool {
        let mut ended = Vec::new();
        for f in frames {
            for r in self.recordings.values_mut() {
                if r.feed(&f) {
                    ended.push(r.id);
                }
            }
        }
        let changed = !ended.is_empty();
        for id in ended {
            self.release(id);
        }
        changed
    }

    /// An axis left its slot: the active recordings of it fail (the slot may get another
    /// axis). Returns true when the layout changed.
    pub fn axis_removed(&mut self, slot: AxisSlot) -> bool {
        let layout = self.layout;
        let mut ended = Vec::new();
        for r in self.recordings.values_mut() {
            if !r.state.is_active() {
                continue;
            }
            let hit = r
                .index
                .iter()
                .zip(&r.channels)
                .find(|(i, _)| layout[**i].is_some_and(|(s, _, _)| s == slot));
            if let Some((_, c)) = hit {
                let reason = format!("axis '{}' was removed during the recording", c.axis);
                r.fail(reason);
                ended.push(r.id);
            }
        }
        let changed = !ended.is_empty();
        for id in ended {
            self.release(id);
        }
        changed
    }

    /// Removes a recording that failed to start (its configuration never reached the cycle).
    pub fn abandon(&mut self, id: u64) {
        if self
            .recordings
            .get(&id)
            .is_some_and(|r| r.state.is_active())
        {
            self.release(id);
        }
        self.recordings.remove(&id);
    }

    /// `DELETE`: cancels an active recording (kept as `cancelled`) or removes a final one.
    /// None when there is no such recording; Some(view) when it was cancelled.
    pub fn delete(&mut self, id: u64) -> Option<Option<ScopeRecording>> {
        let r = self.recordings.get_mut(&id)?;
        if r.state.is_active() {
            r.state = RecordingState::Cancelled;
            r.reason = Some("cancelled by a client".into());
            r.finish();
            self.release(id);
            Some(self.get(id, false))
        } else {
            self.recordings.remove(&id);
            Some(None)
        }
    }

    pub fn get(&self, id: u64, with_data: bool) -> Option<ScopeRecording> {
        self.recordings
            .get(&id)
            .map(|r| r.view(self.cycle_time_s, self.period_ns, with_data))
    }

    pub fn list(&self) -> Vec<ScopeRecording> {
        self.recordings
            .values()
            .map(|r| r.view(self.cycle_time_s, self.period_ns, false))
            .collect()
    }

    /// Number of signals the cycle thread samples now.
    pub fn channels_in_use(&self) -> usize {
        self.layout.iter().filter(|l| l.is_some()).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DT_NS: u64 = 1_000_000;

    fn channel(signal: ScopeSignal) -> (AxisSlot, ScopeChannel) {
        (
            0,
            ScopeChannel {
                axis: "x".into(),
                axis_id: 1,
                signal,
                unit: "mm".into(),
            },
        )
    }

    fn new(samples: usize, trigger: Option<ScopeTrigger>, pre: usize) -> NewRecording {
        NewRecording {
            channels: vec![
                channel(ScopeSignal::SetPosition),
                channel(ScopeSignal::SetVelocity),
            ],
            duration_s: samples as f64 * 1e-3,
            samples,
            trigger,
            pre_trigger_samples: pre,
        }
    }

    /// A frame as the cycle thread makes it for `config`: position = cycle, velocity = -cycle.
    fn frame(cycle: u64, config: &ScopeConfig) -> ScopeFrame {
        let mut axes = [None; 1];
        axes[0] = Some(AxisStatus {
            set_position: cycle as f64,
            set_velocity: -(cycle as f64),
            ..Default::default()
        });
        ScopeFrame::sample(cycle, config, &axes)
    }

    #[test]
    fn untriggered_records_consecutive_cycles_from_its_generation_on() {
        let mut rs = Recordings::new(1e-3, DT_NS);
        let old = rs.config();
        let (id, config) = rs.create(new(5, None, 0)).unwrap();
        assert_eq!(config.generation, old.generation + 1);
        // Frames of the old generation are ignored.
        assert!(!rs.feed([frame(9, &old)]));
        rs.started(id, 10);
        assert!(rs.feed((10..20).map(|c| frame(c, &config))));
        let r = rs.get(id, true).unwrap();
        assert_eq!(r.state, RecordingState::Done);
        assert_eq!(r.start_cycle, 10);
        assert_eq!(r.t.unwrap(), vec![0.0, 0.001, 0.002, 0.003, 0.004]);
        let data = r.data.unwrap();
        assert_eq!(data[0], vec![10.0, 11.0, 12.0, 13.0, 14.0]);
        assert_eq!(data[1], vec![-10.0, -11.0, -12.0, -13.0, -14.0]);
        // Its channels are released.
        assert_eq!(rs.channels_in_use(), 0);
        assert!(!rs.take_dirty().unwrap().is_active());
    }

    #[test]
    fn a_trigger_keeps_the_pre_trigger_history_and_puts_the_crossing_at_t_zero() {
        let mut rs = Recordings::new(1e-3, DT_NS);
        let trigger = ScopeTrigger {
            channel: 0,
            level: 20.0,
            edge: TriggerEdge::Rising,
            pre_trigger_s: 0.003,
        };
        let (id, config) = rs.create(new(6, Some(trigger), 3)).unwrap();
        rs.started(id, 10);
        rs.feed((10..20).map(|c| frame(c, &config)));
        assert_eq!(rs.get(id, false).unwrap().state, RecordingState::Armed);
        rs.feed((20..30).map(|c| frame(c, &config)));
        let r = rs.get(id, true).unwrap();
        assert_eq!(r.state, RecordingState::Done);
        assert_eq!(r.trigger_cycle, Some(20));
        assert_eq!(r.start_cycle, 17);
        assert_eq!(
            r.t.unwrap(),
            vec![-0.003, -0.002, -0.001, 0.0, 0.001, 0.002]
        );
        assert_eq!(r.data.unwrap()[0], vec![17.0, 18.0, 19.0, 20.0, 21.0, 22.0]);
    }

    #[test]
    fn the_trigger_waits_for_a_full_history_and_follows_its_edge() {
        let mut rs = Recordings::new(1e-3, DT_NS);
        let falling = ScopeTrigger {
            channel: 1,
            level: -12.0,
            edge: TriggerEdge::Falling,
            pre_trigger_s: 0.005,
        };
        let (id, config) = rs.create(new(8, Some(falling), 5)).unwrap();
        // velocity = -cycle crosses -12 downwards at cycle 12, before 5 samples of history
        // are there (from cycle 10): ignored, so it never fires.
        rs.feed((10..40).map(|c| frame(c, &config)));
        let r = rs.get(id, false).unwrap();
        assert_eq!(r.state, RecordingState::Armed);
        assert_eq!(r.start_cycle, 35, "history = the last 5 cycles");
        let either = ScopeTrigger {
            channel: 0,
            level: 42.5,
            edge: TriggerEdge::Either,
            pre_trigger_s: 0.0,
        };
        let (id2, config) = rs.create(new(2, Some(either), 0)).unwrap();
        rs.feed((40..50).map(|c| frame(c, &config)));
        let r = rs.get(id2, true).unwrap();
        assert_eq!(r.trigger_cycle, Some(43));
        assert_eq!(r.t.unwrap(), vec![0.0, 0.001]);
        assert_eq!(r.data.unwrap()[0], vec![43.0, 44.0]);
    }

    #[test]
    fn a_lost_cycle_fails_the_recording_instead_of_leaving_a_gap() {
        let mut rs = Recordings::new(1e-3, DT_NS);
        let (id, config) = rs.create(new(100, None, 0)).unwrap();
        rs.feed((10..20).map(|c| frame(c, &config)));
        assert!(rs.feed((23..30).map(|c| frame(c, &config))));
        let r = rs.get(id, true).unwrap();
        assert_eq!(r.state, RecordingState::Failed);
        assert!(r.reason.unwrap().starts_with("3 cycles"));
        assert!(r.data.is_none() && r.t.is_none());
    }

    #[test]
    fn channels_are_shared_and_at_most_eight_are_sampled() {
        let mut rs = Recordings::new(1e-3, DT_NS);
        let many = |signals: &[ScopeSignal], slot: AxisSlot| NewRecording {
            channels: signals
                .iter()
                .map(|s| {
                    let (_, c) = channel(*s);
                    (slot, c)
                })
                .collect(),
            duration_s: 1.0,
            samples: 1000,
            trigger: None,
            pre_trigger_samples: 0,
        };
        let (a, _) = rs
            .create(many(&ScopeSignal::ALL[..4], 0))
            .expect("4 channels");
        // The same signals again share the indices.
        let (b, _) = rs.create(many(&ScopeSignal::ALL[..4], 0)).unwrap();
        assert_eq!(rs.channels_in_use(), 4);
        let (third, _) = rs.create(many(&ScopeSignal::ALL[..4], 1)).unwrap();
        assert_eq!(rs.channels_in_use(), 8);
        assert_eq!(
            rs.create(many(&ScopeSignal::ALL[4..5], 1)).unwrap_err(),
            ScopeBusy::Channels {
                in_use: 8,
                needed: 1
            }
        );
        // Cancelling `a` keeps the indices `b` uses.
        assert_eq!(
            rs.delete(a).unwrap().unwrap().state,
            RecordingState::Cancelled
        );
        assert_eq!(rs.channels_in_use(), 8);
        rs.delete(b);
        assert_eq!(rs.channels_in_use(), 4);
        assert_eq!(rs.config().channels[..4], [None; 4]);
        // The cancelled one is kept; deleting it again removes it.
        assert!(matches!(rs.delete(a), Some(None)));
        assert!(rs.get(a, false).is_none());
        assert!(rs.get(third, false).is_some());
    }

    #[test]
    fn removing_an_axis_fails_its_active_recordings() {
        let mut rs = Recordings::new(1e-3, DT_NS);
        let (id, config) = rs.create(new(100, None, 0)).unwrap();
        rs.feed((10..20).map(|c| frame(c, &config)));
        assert!(!rs.axis_removed(3));
        assert!(rs.axis_removed(0));
        let r = rs.get(id, false).unwrap();
        assert_eq!(r.state, RecordingState::Failed);
        assert_eq!(
            r.reason.as_deref(),
            Some("axis 'x' was removed during the recording")
        );
        assert_eq!(rs.channels_in_use(), 0);
    }

    #[test]
    fn finished_recordings_are_evicted_oldest_first() {
        let mut rs = Recordings::new(1e-3, DT_NS);
        let mut ids = Vec::new();
        for _ in 0..MAX_RECORDINGS {
            let (id, config) = rs.create(new(2, None, 0)).unwrap();
            rs.feed((0..2).map(|c| frame(c, &config)));
            ids.push(id);
        }
        let (id, _) = rs.create(new(2, None, 0)).unwrap();
        assert!(rs.get(ids[0], false).is_none());
        assert!(rs.get(ids[1], false).is_some());
        assert_eq!(rs.list().len(), MAX_RECORDINGS);
        // Active recordings are never evicted: with 8 active a ninth is refused.
        let mut rs = Recordings::new(1e-3, DT_NS);
        for _ in 0..MAX_RECORDINGS {
            rs.create(new(2, None, 0)).unwrap();
        }
        assert!(matches!(
            rs.create(new(2, None, 0)),
            Err(ScopeBusy::Recordings)
        ));
        let _ = id;
    }
}
