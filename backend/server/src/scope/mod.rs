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

mod frame;
mod recording;

pub use frame::{ScopeConfig, ScopeFrame, ScopeSignal};
pub use recording::{
    NewRecording, RecordingState, ScopeBusy, ScopeChannel, ScopeRecording, ScopeTrigger,
    TriggerEdge,
};

use std::collections::{BTreeMap, VecDeque};

use motion::AxisSlot;
use recording::Recording;

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
        self.removed(slot, false)
    }

    /// A group left its slot: likewise for the recordings of its signals.
    pub fn group_removed(&mut self, slot: AxisSlot) -> bool {
        self.removed(slot, true)
    }

    fn removed(&mut self, slot: AxisSlot, group: bool) -> bool {
        let layout = self.layout;
        let mut ended = Vec::new();
        for r in self.recordings.values_mut() {
            if !r.state.is_active() {
                continue;
            }
            let hit = r.index.iter().zip(&r.channels).find(|(i, _)| {
                layout[**i].is_some_and(|(s, g, _)| s == slot && g.of_group() == group)
            });
            if let Some((_, c)) = hit {
                let reason = match (&c.axis, &c.group) {
                    (Some(a), _) => format!("axis '{a}' was removed during the recording"),
                    (None, g) => format!(
                        "group '{}' was removed during the recording",
                        g.as_deref().unwrap_or_default()
                    ),
                };
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
    use motion::AxisStatus;

    const DT_NS: u64 = 1_000_000;

    fn channel(signal: ScopeSignal) -> (AxisSlot, ScopeChannel) {
        (
            0,
            ScopeChannel {
                axis: Some("x".into()),
                axis_id: Some(1),
                group: None,
                group_id: None,
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
        ScopeFrame::sample(cycle, config, &axes, &[])
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
