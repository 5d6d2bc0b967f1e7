//! The websocket status feed: an axis's status object, its whole JSON and its delta from what a
//! subscriber was sent before are made once per tick and shared by every socket that sends
//! them, so that the cost of streaming grows with the axes, not with axes × subscribers.
//!
//! Ticks are a grid every [`TICK`] from the feed's epoch; every socket wakes on that grid and a
//! subscription at a given rate is due on the same ticks in every socket, so subscribers of
//! one axis at one rate share one delta. A delta is keyed by the object it starts from (the
//! `Arc` a subscriber was sent), never by a tick number alone, so a socket that runs late can
//! never be handed another socket's delta.

use std::sync::{Arc, Mutex};
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
    frames: Vec<Mutex<Frame>>,
}

impl Feed {
    pub fn new(slots: usize) -> Self {
        Feed {
            epoch: Instant::now(),
            frames: (0..slots).map(|_| Mutex::default()).collect(),
        }
    }

    /// The first tick instant at or after `now`.
    pub fn next_tick_at(&self, now: Instant) -> Instant {
        let n = (now - self.epoch).as_nanos().div_ceil(TICK.as_nanos());
        self.epoch + TICK * n as u32
    }

    /// The number of the tick scheduled at `at` (an instant of the grid).
    pub fn tick_of(&self, at: Instant) -> u64 {
        let d = at.saturating_duration_since(self.epoch).as_nanos();
        ((d + TICK.as_nanos() / 2) / TICK.as_nanos()) as u64
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
        let mut f = self.frames.get(slot as usize)?.lock().unwrap();
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
        let cycle = f.cycle;
        let Some(last) = last else {
            let data = f
                .full
                .get_or_insert_with(|| serde_json::to_string(&*map).unwrap_or_default().into())
                .clone();
            return Some(Piece {
                cycle,
                full: true,
                data: Some(data),
                map,
            });
        };
        if Arc::ptr_eq(last, &map) {
            return Some(Piece {
                cycle,
                full: false,
                data: None,
                map,
            });
        }
        let data = match f.deltas.iter().find(|(from, _)| Arc::ptr_eq(from, last)) {
            Some((_, d)) => d.clone(),
            None => {
                let d = delta(last, &map);
                let d = (!d.is_empty())
                    .then(|| Arc::<str>::from(serde_json::to_string(&d).unwrap_or_default()));
                f.deltas.push((last.clone(), d.clone()));
                d
            }
        };
        Some(Piece {
            cycle,
            full: false,
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
