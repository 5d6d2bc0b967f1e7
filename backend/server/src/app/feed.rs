//! The websocket status feed. Each axis's status is written as JSON once per cycle that anyone
//! asks for (straight from the status, no `serde_json::Value`; the members that did not change
//! since the version before are copied from it, `members.rs`), marked member by member, and
//! kept with the last [`KEPT`] versions; the delta from an older version to the newest is made
//! once and shared by every subscriber that has that older version. So the cost
//! of streaming grows with axes × versions in flight (at most [`KEPT`]), never with axes ×
//! subscribers — also when sockets fall out of step with each other. A subscriber whose
//! version is older than what is kept gets the newest state whole (coalesced).
//!
//! Ticks are a grid every [`TICK`] from the feed's epoch; a subscription at a given rate is due
//! on the same ticks in every socket (and a socket sleeps until its next one is due). A
//! subscriber is known here only by the version (the status's cycle) it was last sent.

use std::collections::VecDeque;
use std::sync::atomic::{AtomicU64, Ordering::Relaxed};
use std::sync::{Arc, Mutex, RwLock};
use std::time::Duration;

use serde_json::{Map, Value};

use super::AppState;
use super::members;
use crate::clock::{Clock, Hold};
use motion::AxisSlot;

/// The websocket tick: the finest subscription grid (200 Hz; the highest rate is 100 Hz).
pub const TICK: Duration = Duration::from_millis(5);

/// Versions of an axis's status kept for deltas (a subscriber further behind gets it whole).
pub const KEPT: usize = 8;

/// Different messages shared per tick (sockets asking for something else make their own).
const SHARED_PER_TICK: usize = 16;

/// A JSON text shared by the subscribers that send it.
pub type Text = Arc<String>;

/// One axis's status at one cycle, as JSON (its text kept as written, not copied into an
/// `Arc<str>`: 4 KB per axis per tick). `since`: the cycle at which each member last changed.
type Version = members::Written<Text>;

/// The status at `cycle`, its members that did not change since `before` (the newest version,
/// whose prints are `prints`) copied from it; its own prints go to `spare`.
fn write_version(
    cycle: u64,
    status: &impl serde::Serialize,
    before: Option<&Version>,
    prints: &members::Prints,
    spare: &mut members::Prints,
) -> Option<Version> {
    let before = before.map(|b| b.before(prints));
    members::write(cycle, status, before, spare).map(members::Written::shared)
}

/// The members of `now` whose value differs from `before` (or that `before` lacks), as a JSON
/// object; `None` when nothing changed. (From a version in `now`'s chain of the same members:
/// every member changed since, which may include one that changed back, decision 177.)
fn delta_json(before: &Version, now: &Version) -> Option<Text> {
    // A version since which every version has had the same members: each member of `now`
    // says when it last changed, nothing is compared (a member that changed and changed back
    // is sent again, which a client merging the changes does not see).
    let chained = before.cycle < now.cycle && before.cycle >= now.shape_since;
    let same_shape = chained
        || before.members.len() == now.members.len()
            && (0..now.members.len()).all(|i| before.key(i) == now.key(i));
    let mut out = String::with_capacity(256);
    for i in 0..now.members.len() {
        let changed = if chained {
            now.since[i] > before.cycle
        } else if same_shape {
            before.value(i) != now.value(i)
        } else {
            let key = now.key(i);
            (0..before.members.len())
                .find(|&j| before.key(j) == key)
                .is_none_or(|j| before.value(j) != now.value(i))
        };
        if changed {
            out.push(if out.is_empty() { '{' } else { ',' });
            out.push_str(now.member(i));
        }
    }
    if out.is_empty() {
        return None;
    }
    out.push('}');
    Some(Arc::new(out))
}

/// One axis: its recent versions and the deltas made to the newest.
#[derive(Default)]
struct AxisFeed {
    /// The newest tick anyone asked for.
    tick: u64,
    /// Oldest first.
    versions: VecDeque<Arc<Version>>,
    /// The newest version's prints, and the buffer the next one's are made in.
    prints: members::Prints,
    spare: members::Prints,
    /// Deltas to the newest version from the older ones asked for (`None`: no change).
    deltas: Vec<(u64, Option<Text>)>,
}

/// What a subscription sends for one axis at a tick.
pub struct Piece {
    pub cycle: u64,
    /// `data` is the whole object (the first update, or a subscriber too far behind).
    pub full: bool,
    /// The object (or the delta) as JSON; `None`: nothing changed, nothing to send.
    pub data: Option<Text>,
    /// The version the subscriber has from now on.
    pub version: u64,
}

/// One due axis subscription of a socket: its slot, the version it was last sent, its topic
/// as JSON (shared, [`Feed::topic`]).
pub type Asked = (AxisSlot, Option<u64>, Arc<str>);

/// One socket's axis updates at a tick, as sent: shared with every socket that asks for the
/// same at that tick — the same axes under the same topic names, each last sent the same
/// version (issue 27). Sockets that subscribe alike and keep up ask alike, so a tick's
/// message is made once, not once per socket.
pub struct SharedBatch {
    /// Each due axis subscription, in the socket's order.
    pub asked: Vec<Asked>,
    /// The version each of them has after this message (in `asked`'s order).
    pub seen: Vec<Option<u64>>,
    /// The message (`None`: nothing changed, nothing to send).
    /// (Text as made: a socket that takes it sends it without validating it again.)
    pub message: Option<axum::extract::ws::Utf8Bytes>,
}

#[derive(Default)]
struct SharedTick {
    tick: u64,
    batches: Vec<Arc<SharedBatch>>,
}

impl SharedTick {
    fn find(&self, tick: u64, same: impl Fn(&[Asked]) -> bool) -> Option<Arc<SharedBatch>> {
        if self.tick != tick {
            return None;
        }
        self.batches.iter().find(|b| same(&b.asked)).cloned()
    }

    fn keep(&mut self, tick: u64, batch: SharedBatch) {
        if tick > self.tick {
            self.tick = tick;
            self.batches.clear();
        }
        // Two sockets that asked alike at once both made it: one copy is enough.
        let known = self.batches.iter().any(|b| b.asked == batch.asked);
        if tick == self.tick && !known && self.batches.len() < SHARED_PER_TICK {
            self.batches.push(Arc::new(batch));
        }
    }
}

/// Topics as shared text: sockets that ask alike are found alike by comparing pointers, not
/// 64 topic names per socket and tick (issue 27: those comparisons were 6 % of motiond's
/// samples at 100 clients × 64 axes, 1.4 % after). Topics no socket holds are forgotten.
/// (Swept when it has doubled since the last sweep: subscribing stays O(1) on average.)
#[derive(Default)]
struct Topics(Mutex<TopicSet>);

#[derive(Default)]
struct TopicSet {
    set: std::collections::HashSet<Arc<str>>,
    /// The set's size after the last sweep.
    swept: usize,
}

impl Topics {
    fn get(&self, topic_json: &str) -> Arc<str> {
        let mut topics = self.0.lock().unwrap();
        if let Some(t) = topics.set.get(topic_json) {
            return t.clone();
        }
        if topics.set.len() >= 2 * topics.swept.max(8) {
            topics.set.retain(|t| Arc::strong_count(t) > 1);
            topics.swept = topics.set.len();
        }
        let t: Arc<str> = topic_json.into();
        topics.set.insert(t.clone());
        t
    }
}

pub struct Feed {
    /// Ticks are clock time (virtual time in virtual time: a 50 Hz subscription is sent once
    /// per 20 ms of it).
    clock: Arc<Clock>,
    axes: Vec<RwLock<AxisFeed>>,
    /// The newest tick's messages, for the sockets that ask the same.
    shared: Mutex<SharedTick>,
    /// Ticks whose axis updates a socket made itself, and took from another socket's (`/metrics`;
    /// a tick with nothing to send counts too).
    made: AtomicU64,
    reused: AtomicU64,
    /// Every topic's text once, shared by the sockets that subscribe to it.
    topics: Topics,
    /// The tick and how many sockets began to make their own message at it.
    makers: Mutex<(u64, u32)>,
}

impl Feed {
    pub fn new(slots: usize, clock: Arc<Clock>) -> Self {
        Feed {
            clock,
            axes: (0..slots).map(|_| RwLock::default()).collect(),
            shared: Mutex::default(),
            made: AtomicU64::new(0),
            reused: AtomicU64::new(0),
            topics: Topics::default(),
            makers: Mutex::default(),
        }
    }

    /// `topic_json` as the text every socket subscribed to it shares (see [`Topics`]).
    pub fn topic(&self, topic_json: &str) -> Arc<str> {
        self.topics.get(topic_json)
    }

    /// Ticks whose axis updates a socket made itself, and took from another socket's.
    pub fn messages(&self) -> (u64, u64) {
        (self.made.load(Relaxed), self.reused.load(Relaxed))
    }

    /// A socket made its tick's axis updates itself.
    pub fn made_one(&self) {
        self.made.fetch_add(1, Relaxed);
    }

    /// The message another socket made at `tick` for what `same` accepts (its `asked`), if
    /// any. Only the newest tick's messages are kept: a socket behind makes its own.
    pub fn shared(&self, tick: u64, same: impl Fn(&[Asked]) -> bool) -> Option<Arc<SharedBatch>> {
        let found = self.shared.lock().unwrap().find(tick, same);
        if found.is_some() {
            self.reused.fetch_add(1, Relaxed);
        }
        found
    }

    /// Keeps what a socket made at `tick` for the sockets after it.
    pub fn share(&self, tick: u64, batch: SharedBatch) {
        self.shared.lock().unwrap().keep(tick, batch);
    }

    /// Tick `tick`, held (in virtual time the clock stops there until the hold is dropped, so
    /// that the tick sends the machine as it was at that time) …
    /// `hold`: the clock waits there (else this only wakes its holder then).
    pub fn at(&self, tick: u64, hold: bool) -> Hold {
        let t = Duration::from_nanos(tick.saturating_mul(TICK.as_nanos() as u64));
        if hold {
            self.clock.hold_until(t)
        } else {
            self.clock.wake_at(t)
        }
    }

    /// The tick now (the last one that has begun).
    pub fn tick_now(&self) -> u64 {
        (self.clock.now().as_nanos() / TICK.as_nanos()) as u64
    }

    /// Makes axis `slot`'s version for `tick` unless it is made or being made (another socket
    /// holds the axis). Sockets that make a tick's message at the same time make its versions
    /// from both ends ([`Feed::maker`]) instead of waiting on each other axis by axis.
    pub fn prepare(&self, s: &AppState, slot: AxisSlot, tick: u64) {
        let Some(axis) = self.axes.get(slot as usize) else {
            return;
        };
        match axis.try_read() {
            Ok(f) if !f.versions.is_empty() && tick <= f.tick => return,
            Err(std::sync::TryLockError::WouldBlock) => return,
            _ => {}
        }
        let mut _retired = None;
        if let Ok(mut f) = axis.try_write() {
            f.make_now(s, slot, tick, &mut _retired);
        }
    }

    /// How many sockets began to make their own message at `tick` before this one.
    pub fn maker(&self, tick: u64) -> u32 {
        let mut m = self.makers.lock().unwrap();
        if m.0 != tick {
            *m = (tick, 0);
        }
        m.1 += 1;
        m.1 - 1
    }

    /// The update of axis `slot` at `tick` for a subscriber that was last sent version `seen`
    /// (`None`: nothing yet); `None` when the axis has no status.
    pub fn piece(
        &self,
        s: &AppState,
        slot: AxisSlot,
        tick: u64,
        seen: Option<u64>,
    ) -> Option<Piece> {
        let axis = self.axes.get(slot as usize)?;
        // Most subscribers find what they need made already: a shared read.
        {
            let f = axis.read().unwrap();
            if !f.versions.is_empty() && tick <= f.tick {
                if let Some(p) = f.answer(seen) {
                    return Some(p);
                }
            }
        }
        // The oldest version, freed after the lock is let go (not while others wait on it).
        let mut _retired = None;
        let mut guard = axis.write().unwrap();
        let f = &mut *guard;
        f.make_now(s, slot, tick, &mut _retired)?;
        f.update(seen)
    }
}

impl AxisFeed {
    /// The update for a subscriber last sent version `seen`, its delta made if it is not yet.
    fn update(&mut self, seen: Option<u64>) -> Option<Piece> {
        if let Some(from) = seen {
            let newest = self.versions.back()?.clone();
            let made = from == newest.cycle || self.deltas.iter().any(|(c, _)| *c == from);
            if !made {
                if let Some(old) = self.versions.iter().find(|v| v.cycle == from).cloned() {
                    let d = delta_json(&old, &newest);
                    self.deltas.push((from, d));
                }
            }
        }
        self.answer(seen)
    }

    /// [`AxisFeed::make`] from axis `slot`'s status now, as the API shows it.
    fn make_now(
        &mut self,
        s: &AppState,
        slot: AxisSlot,
        tick: u64,
        retired: &mut Option<Arc<Version>>,
    ) -> Option<()> {
        self.make(tick, || s.status(slot), |st| s.status_view(st), retired)
    }

    /// The version for `tick`, unless one as new is there. A late socket uses the newer
    /// version (newer data), never takes the feed back. `None` when the axis has no status.
    /// (`status`: the axis's cycle and status now; `view`: the status as the API shows it.)
    fn make<S, V: serde::Serialize>(
        &mut self,
        tick: u64,
        status: impl FnOnce() -> (u64, Option<S>),
        view: impl FnOnce(S) -> V,
        retired: &mut Option<Arc<Version>>,
    ) -> Option<()> {
        if self.versions.is_empty() || tick > self.tick {
            self.tick = self.tick.max(tick);
            let (cycle, status) = status();
            let status = status?;
            // Versions are a chain of rising cycles (what the deltas rely on, `delta_json`);
            // a cycle that went back (never, with one kernel) starts the chain again.
            if self.versions.back().is_some_and(|v| cycle < v.cycle) {
                self.versions.clear();
                self.deltas.clear();
            }
            if self.versions.back().is_none_or(|v| v.cycle != cycle) {
                let before = self.versions.back().map(|v| &**v);
                let view = view(status);
                let v = write_version(cycle, &view, before, &self.prints, &mut self.spare)?;
                std::mem::swap(&mut self.prints, &mut self.spare);
                if self.versions.len() == KEPT {
                    *retired = self.versions.pop_front();
                }
                self.versions.push_back(Arc::new(v));
                self.deltas.clear();
            }
        }
        Some(())
    }

    /// The update for a subscriber last sent version `seen`, if it is made (`None`: a delta
    /// still to make).
    fn answer(&self, seen: Option<u64>) -> Option<Piece> {
        let newest = self.versions.back()?;
        let piece = |full: bool, data: Option<Text>| Piece {
            cycle: newest.cycle,
            full,
            data,
            version: newest.cycle,
        };
        match seen {
            None => Some(piece(true, Some(newest.json.clone()))),
            Some(c) if c == newest.cycle => Some(piece(false, None)),
            Some(c) => match self.deltas.iter().find(|(from, _)| *from == c) {
                Some((_, d)) => Some(piece(false, d.clone())),
                None if self.versions.iter().any(|v| v.cycle == c) => None,
                // Further behind than what is kept: the newest state, whole.
                None => Some(piece(true, Some(newest.json.clone()))),
            },
        }
    }
}

/// The members of `now` that differ from `before` (the system topic's delta).
pub fn delta(before: &Map<String, Value>, now: &Map<String, Value>) -> Map<String, Value> {
    let mut d: Map<String, Value> = now
        .iter()
        .filter(|(k, v)| before.get(*k) != Some(v))
        .map(|(k, v)| (k.clone(), v.clone()))
        .collect();
    // A field that is no longer there (an optional one left out) is sent as null, as a JSON
    // merge patch says "removed": a client merging the changes would keep it otherwise.
    for k in before.keys() {
        if !now.contains_key(k) {
            d.insert(k.clone(), Value::Null);
        }
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn version(cycle: u64, v: Value) -> Version {
        let none = members::Prints::default();
        write_version(cycle, &v, None, &none, &mut members::Prints::default()).unwrap()
    }

    /// Versions made one after the other, as the feed makes them.
    fn versions(values: &[(u64, Value)]) -> Vec<Version> {
        let (mut prints, mut spare) = <(members::Prints, members::Prints)>::default();
        let mut out: Vec<Version> = Vec::new();
        for (cycle, v) in values {
            let made = write_version(*cycle, v, out.last(), &prints, &mut spare).unwrap();
            std::mem::swap(&mut prints, &mut spare);
            out.push(made);
        }
        out
    }

    #[test]
    fn a_field_that_is_gone_is_a_null_in_the_delta() {
        let before = json!({"a": 1, "gone": {"x": 1}, "same": 2});
        let now = json!({"a": 3, "same": 2, "new": true});
        let d = delta(before.as_object().unwrap(), now.as_object().unwrap());
        assert_eq!(Value::Object(d), json!({"a": 3, "gone": null, "new": true}));
    }

    #[test]
    fn members_split_at_top_level_only() {
        let v = version(
            1,
            json!({"a": 1, "b": {"c": [1, 2, {"d": "x,}]\"y"}]}, "e": "q\\\"", "f": null}),
        );
        let keys: Vec<&str> = (0..v.members.len()).map(|i| v.key(i)).collect();
        assert_eq!(keys, [r#""a":"#, r#""b":"#, r#""e":"#, r#""f":"#]);
        assert_eq!(v.value(1), r#"{"c":[1,2,{"d":"x,}]\"y"}]}"#);
        assert_eq!(v.value(2), r#""q\\\"""#);
        assert_eq!(v.value(3), "null");
        let none = members::Prints::default();
        let mut spare = members::Prints::default();
        assert!(write_version(1, &json!([1, {"a": 2}]), None, &none, &mut spare).is_none());
        assert_eq!(version(1, json!({})).members.len(), 0);
        // Written as `serde_json::to_string` writes it.
        let status = json!({"s": "standstill", "p": [1.5, {"q": null}], "e": {}});
        assert_eq!(*version(1, status.clone()).json, status.to_string());
    }

    #[test]
    fn a_topic_is_one_text_while_sockets_hold_it() {
        let topics = Topics::default();
        let a = topics.get(r#""axes/x/status""#);
        let b = topics.get(r#""axes/x/status""#);
        assert!(Arc::ptr_eq(&a, &b));
        assert!(!Arc::ptr_eq(&a, &topics.get(r#""axes/y/status""#)));
        // Topics no socket holds are forgotten once the set has doubled: it stays within
        // twice what sockets hold (and at least 16).
        let held: Vec<Arc<str>> = (0..20)
            .map(|i| topics.get(&format!(r#""axes/h{i}/status""#)))
            .collect();
        for i in 0..500 {
            topics.get(&format!(r#""axes/gone{i}/status""#));
            let n = topics.0.lock().unwrap().set.len();
            assert!(n <= 2 * (held.len() + 1) + 1, "{n} kept after {i}");
        }
        let set = &topics.0.lock().unwrap().set;
        assert!(held.iter().all(|t| set.contains(&**t)) && set.contains(&*a));
    }

    #[test]
    fn a_delta_has_the_changed_members_and_parses_as_their_values() {
        let a = version(
            1,
            json!({"p": 1.5, "s": "standstill", "n": {"x": 1}, "k": true}),
        );
        let b = version(
            2,
            json!({"p": 2.5, "s": "standstill", "n": {"x": 2}, "k": true}),
        );
        let d: Value = serde_json::from_str(&delta_json(&a, &b).unwrap()).unwrap();
        assert_eq!(d, json!({"p": 2.5, "n": {"x": 2}}));
        assert!(delta_json(&a, &a).is_none());
        // Another shape (a member skipped in one of them): compared by key.
        let c = version(3, json!({"s": "standstill", "p": 2.5, "m": "x"}));
        let d: Value = serde_json::from_str(&delta_json(&a, &c).unwrap()).unwrap();
        assert_eq!(d, json!({"p": 2.5, "m": "x"}));
    }

    /// Versions made one after the other know when each member last changed: a delta over
    /// several of them has every member changed in any of them; one from a version of other
    /// members is compared by key and value.
    #[test]
    fn a_delta_over_several_versions_has_what_changed_in_any() {
        let v = versions(&[
            (10, json!({"p": 1.0, "s": "a", "n": {"x": 1}})),
            (20, json!({"p": 2.0, "s": "a", "n": {"x": 1}})),
            (30, json!({"p": 3.0, "s": "a", "n": {"x": 2}})),
            (40, json!({"p": 3.0, "s": "a", "n": {"x": 2}})),
            (50, json!({"p": 3.0, "s": "b"})),
            (60, json!({"p": 4.0, "s": "b"})),
        ]);
        let delta = |from: usize, to: usize| -> Option<Value> {
            delta_json(&v[from], &v[to]).map(|d| serde_json::from_str(&d).unwrap())
        };
        assert_eq!(v[3].shape_since, 10);
        assert_eq!(delta(0, 3), Some(json!({"p": 3.0, "n": {"x": 2}})));
        assert_eq!(delta(1, 3), Some(json!({"p": 3.0, "n": {"x": 2}})));
        assert_eq!(delta(2, 3), None);
        assert_eq!(delta(3, 3), None);
        // Other members since 50: compared by value (a member gone is not in the delta).
        assert_eq!(v[5].shape_since, 50);
        assert_eq!(delta(3, 5), Some(json!({"p": 4.0, "s": "b"})));
        assert_eq!(delta(4, 5), Some(json!({"p": 4.0})));
        assert_eq!(delta(0, 4), Some(json!({"p": 3.0, "s": "b"})));
        // A member that changed and changed back between two versions is in their delta
        // (decision 177): the same value again.
        let v = versions(&[
            (10, json!({"p": 1.0, "n": 1})),
            (20, json!({"p": 1.0, "n": 2})),
            (30, json!({"p": 1.0, "n": 1})),
        ]);
        let d: Value = serde_json::from_str(&delta_json(&v[0], &v[2]).unwrap()).unwrap();
        assert_eq!(d, json!({"n": 1}));
    }

    /// Versions are a chain of rising cycles: a cycle that goes back starts it again, and a
    /// subscriber of a version from before is sent the newest whole (a delta by the members'
    /// cycles across the break would have missed the change of `p`).
    #[test]
    fn a_cycle_that_goes_back_starts_the_versions_again() {
        let mut f = AxisFeed::default();
        let mut retired = None;
        let mut at = |f: &mut AxisFeed, tick: u64, cycle: u64, p: f64| {
            let status = json!({"p": p, "k": 1});
            f.make(tick, || (cycle, Some(status)), |v| v, &mut retired)
                .unwrap();
        };
        at(&mut f, 1, 100, 1.0);
        at(&mut f, 2, 50, 2.0);
        at(&mut f, 3, 120, 2.0);
        let cycles: Vec<u64> = f.versions.iter().map(|v| v.cycle).collect();
        assert_eq!(cycles, [50, 120]);
        let p = f.update(Some(100)).unwrap();
        let data: Value = serde_json::from_str(p.data.as_deref().unwrap()).unwrap();
        assert!(p.full && data["p"] == 2.0, "{data}");
        // Within the new chain, deltas as usual.
        let p = f.update(Some(50)).unwrap();
        assert!(!p.full && p.data.is_none(), "nothing changed since 50");
    }

    #[test]
    fn answers_come_from_kept_versions_and_a_subscriber_too_far_behind_gets_the_whole() {
        let mut f = AxisFeed::default();
        for c in 1..=(KEPT as u64 + 2) {
            f.versions
                .push_back(Arc::new(version(c, json!({"c": c, "k": 0}))));
            if f.versions.len() > KEPT {
                f.versions.pop_front();
            }
        }
        let newest = KEPT as u64 + 2;
        let p = f.answer(None).unwrap();
        assert!(p.full && p.version == newest);
        assert!(f.answer(Some(newest)).unwrap().data.is_none());
        // A kept version: its delta is to be made first.
        assert!(f.answer(Some(newest - 1)).is_none());
        // Older than what is kept: the newest, whole.
        let p = f.answer(Some(1)).unwrap();
        assert!(p.full);
        assert_eq!(&*p.data.unwrap(), &*f.versions.back().unwrap().json);
    }

    /// Issue 27: a tick's message is kept for the sockets that ask the same at that tick; a
    /// newer tick drops the older ones, a socket still at an older tick makes its own, and
    /// only so many different ones are kept per tick.
    #[test]
    fn a_tick_s_message_is_kept_for_the_sockets_that_ask_the_same() {
        let batch = |slot: AxisSlot, seen: Option<u64>, text: &'static str| SharedBatch {
            asked: vec![(slot, seen, r#""axes/x/status""#.into())],
            seen: vec![Some(7)],
            message: Some(axum::extract::ws::Utf8Bytes::from_static(text)),
        };
        let asks = |slot: AxisSlot, seen: Option<u64>| {
            move |a: &[Asked]| a.len() == 1 && a[0].0 == slot && a[0].1 == seen
        };
        let mut t = SharedTick::default();
        t.keep(5, batch(0, Some(3), "five"));
        let got = t.find(5, asks(0, Some(3))).expect("the same asked");
        assert_eq!(got.message.as_deref(), Some("five"));
        assert_eq!(got.seen, [Some(7)]);
        assert!(
            t.find(5, asks(0, Some(2))).is_none(),
            "another version last sent"
        );
        assert!(t.find(5, asks(1, Some(3))).is_none(), "another axis");
        assert!(t.find(4, asks(0, Some(3))).is_none(), "an older tick");
        // An older tick's message is not kept over the newer one's.
        t.keep(4, batch(0, Some(3), "four"));
        assert!(t.find(4, asks(0, Some(3))).is_none());
        t.keep(6, batch(0, Some(3), "six"));
        assert!(t.find(5, asks(0, Some(3))).is_none(), "tick 5 is gone");
        assert_eq!(t.batches.len(), 1);
        for slot in 1..=(2 * SHARED_PER_TICK as AxisSlot) {
            t.keep(6, batch(slot, None, "more"));
        }
        assert_eq!(t.batches.len(), SHARED_PER_TICK);
    }
}
