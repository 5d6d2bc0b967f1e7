//! The websocket status feed: an axis's status object, its whole JSON and its delta from what a
//! subscriber was sent before are made once per tick and shared by every socket that sends
//! them, so that the cost of streaming grows with the axes, not with axes × subscribers.
//!
//! Ticks are a grid every [`TICK`] from the feed's epoch; a subscription at a given rate is due
//! on the same ticks in every socket (and a socket sleeps until its next one is due), so
//! subscribers of one axis at one rate share one delta. A delta is keyed by the object it starts from (the
//! `Arc` a subscriber was sent), never by a tick number alone, so a socket that runs late can
//! never be handed another socket's delta.

use std::sync::{Arc, RwLock};
use std::time::Duration;

use serde_json::{Map, Value};
use tokio::time::Instant;

use super::{AppState, StatusJson};
use motion::AxisSlot;

/// The websocket tick: the finest subscription grid (200 Hz; the highest rate is 100 Hz).
pub const TICK: Duration = Duration::from_millis(5);

/// One axis at the newest tick anyone asked for.
#[derive(Default)]
struct Frame {
    tick: u64,
    cycle: u64,
    map: Option<StatusJson>,
    /// The whole object as JSON (for first updates), made when first needed.
    full: Option<Arc<str>>,
    /// Deltas to `map` from the objects subscribers were sent before (`None`: no change).
    deltas: Vec<(StatusJson, Option<Arc<str>>)>,
}

/// What a subscription sends for one axis at a tick.
pub struct Piece {
    pub cycle: u64,
    /// `data` is the whole object (the first update, or after the axis object changed).
    pub full: bool,
    /// The object (or the delta) as JSON; `None`: nothing changed, nothing to send.
    pub data: Option<Arc<str>>,
    /// The object the subscriber has from now on.
    pub map: StatusJson,
}

pub struct Feed {
    epoch: Instant,
    frames: Vec<RwLock<Frame>>,
}

impl Feed {
    pub fn new(slots: usize) -> Self {
        Feed {
            epoch: Instant::now(),
            frames: (0..slots).map(|_| RwLock::default()).collect(),
        }
    }

    /// When tick `tick` is.
    pub fn at(&self, tick: u64) -> Instant {
        self.epoch + Duration::from_nanos(tick.saturating_mul(TICK.as_nanos() as u64))
    }

    /// The tick now (the last one that has begun).
    pub fn tick_now(&self) -> u64 {
        (Instant::now()
            .saturating_duration_since(self.epoch)
            .as_nanos()
            / TICK.as_nanos()) as u64
    }

    /// The update of axis `slot` for a subscriber that was last sent `last` (`None`: nothing
    /// yet); `None` when the axis has no status.
    pub fn piece(
        &self,
        s: &AppState,
        slot: AxisSlot,
        tick: u64,
        last: Option<&StatusJson>,
    ) -> Option<Piece> {
        let frame = self.frames.get(slot as usize)?;
        // Most subscribers find what they need made already: a shared read.
        {
            let f = frame.read().unwrap();
            if f.map.is_some() && tick <= f.tick {
                if let Some(p) = f.answer(last) {
                    return Some(p);
                }
            }
        }
        let mut f = frame.write().unwrap();
        // A late socket uses the newer frame (newer data), never takes the feed back.
        if f.map.is_none() || tick > f.tick {
            let (cycle, map) = s.status_json(slot)?;
            f.tick = tick;
            if !f.map.as_ref().is_some_and(|m| Arc::ptr_eq(m, &map)) {
                *f = Frame {
                    tick,
                    cycle,
                    map: Some(map),
                    ..Frame::default()
                };
            }
        }
        let map = f.map.clone()?;
        match last {
            None => {
                if f.full.is_none() {
                    f.full = Some(serde_json::to_string(&*map).unwrap_or_default().into());
                }
            }
            Some(last) => {
                if !Arc::ptr_eq(last, &map)
                    && !f.deltas.iter().any(|(from, _)| Arc::ptr_eq(from, last))
                {
                    let d = delta(last, &map);
                    let d = (!d.is_empty())
                        .then(|| Arc::<str>::from(serde_json::to_string(&d).unwrap_or_default()));
                    f.deltas.push((last.clone(), d));
                }
            }
        }
        f.answer(last)
    }
}

impl Frame {
    /// The update for a subscriber last sent `last`, if this frame has it made.
    fn answer(&self, last: Option<&StatusJson>) -> Option<Piece> {
        let map = self.map.clone()?;
        let (data, full) = match last {
            None => (Some(self.full.clone()?), true),
            Some(last) if Arc::ptr_eq(last, &map) => (None, false),
            Some(last) => (
                self.deltas
                    .iter()
                    .find(|(from, _)| Arc::ptr_eq(from, last))?
                    .1
                    .clone(),
                false,
            ),
        };
        Some(Piece {
            cycle: self.cycle,
            full,
            data,
            map,
        })
    }
}

/// The members of `now` that differ from `before`.
pub fn delta(before: &Map<String, Value>, now: &Map<String, Value>) -> Map<String, Value> {
    now.iter()
        .filter(|(k, v)| before.get(*k) != Some(v))
        .map(|(k, v)| (k.clone(), v.clone()))
        .collect()
}
