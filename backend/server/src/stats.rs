//! Timing statistics written by the cycle thread and read by the API, without locks.
//!
//! A fixed-bucket log-linear histogram of atomics: the cycle thread does one relaxed
//! `fetch_add` per sample (no allocation, no lock, no syscall); readers sum the buckets.
//! Resolution is 1/16 of the power of two a value falls in (≈6 %), range 64 ns … 1 s.

use std::sync::atomic::{AtomicU64, Ordering::Relaxed};

const SUB_BITS: u32 = 4;
const SUB: usize = 1 << SUB_BITS;
const MIN_EXP: u32 = 6; // values < 64 ns share bucket 0
const MAX_EXP: u32 = 30; // ≈ 1.07 s
const BUCKETS: usize = 1 + (MAX_EXP - MIN_EXP + 1) as usize * SUB;

pub struct Histogram {
    buckets: [AtomicU64; BUCKETS],
    count: AtomicU64,
    sum: AtomicU64,
    max: AtomicU64,
}

fn index(v: u64) -> usize {
    if v < (1 << MIN_EXP) {
        return 0;
    }
    let e = 63 - v.leading_zeros();
    if e > MAX_EXP {
        return BUCKETS - 1;
    }
    let sub = ((v >> (e - SUB_BITS)) as usize) & (SUB - 1);
    1 + (e - MIN_EXP) as usize * SUB + sub
}

/// Upper bound (exclusive) of a bucket in nanoseconds.
fn upper(i: usize) -> u64 {
    if i == 0 {
        return 1 << MIN_EXP;
    }
    let e = MIN_EXP + ((i - 1) / SUB) as u32;
    let sub = ((i - 1) % SUB) as u64;
    (1u64 << e) + (sub + 1) * (1u64 << (e - SUB_BITS))
}

impl Default for Histogram {
    fn default() -> Self {
        Histogram {
            buckets: std::array::from_fn(|_| AtomicU64::new(0)),
            count: AtomicU64::new(0),
            sum: AtomicU64::new(0),
            max: AtomicU64::new(0),
        }
    }
}

/// A reader's copy of a histogram's figures, in microseconds.
#[derive(Clone, Copy, Debug, Default, serde::Serialize, utoipa::ToSchema)]
pub struct Summary {
    pub count: u64,
    pub mean_us: f64,
    pub p50_us: f64,
    pub p90_us: f64,
    pub p99_us: f64,
    pub p999_us: f64,
    pub max_us: f64,
}

impl Histogram {
    /// Records one sample (nanoseconds). Cycle-thread safe.
    pub fn record(&self, ns: u64) {
        self.buckets[index(ns)].fetch_add(1, Relaxed);
        self.count.fetch_add(1, Relaxed);
        self.sum.fetch_add(ns, Relaxed);
        self.max.fetch_max(ns, Relaxed);
    }

    pub fn counts(&self) -> Vec<u64> {
        self.buckets.iter().map(|b| b.load(Relaxed)).collect()
    }

    /// Quantile `q` ∈ [0, 1] in nanoseconds (upper bound of its bucket, capped at the max).
    pub fn quantile(counts: &[u64], q: f64, max: u64) -> u64 {
        let total: u64 = counts.iter().sum();
        if total == 0 {
            return 0;
        }
        let rank = ((q * total as f64).ceil() as u64).clamp(1, total);
        let mut seen = 0;
        for (i, c) in counts.iter().enumerate() {
            seen += c;
            if seen >= rank {
                return upper(i).min(max);
            }
        }
        max
    }

    pub fn summary(&self) -> Summary {
        let counts = self.counts();
        let max = self.max.load(Relaxed);
        let count: u64 = counts.iter().sum();
        let us = |ns: u64| ns as f64 / 1000.0;
        Summary {
            count,
            mean_us: if count > 0 {
                self.sum.load(Relaxed) as f64 / count as f64 / 1000.0
            } else {
                0.0
            },
            p50_us: us(Self::quantile(&counts, 0.5, max)),
            p90_us: us(Self::quantile(&counts, 0.9, max)),
            p99_us: us(Self::quantile(&counts, 0.99, max)),
            p999_us: us(Self::quantile(&counts, 0.999, max)),
            max_us: us(max),
        }
    }

    /// The upper bounds (ns, exclusive) of the buckets, in the order of [`Histogram::counts`].
    pub fn bounds_ns() -> impl Iterator<Item = u64> {
        (0..BUCKETS).map(upper)
    }

    /// The sum of the samples (ns).
    pub fn sum_ns(&self) -> u64 {
        self.sum.load(Relaxed)
    }
}

/// Everything the cycle thread measures about itself.
#[derive(Default)]
pub struct CycleStats {
    /// Wake-up time minus the deadline.
    pub wakeup_latency: Histogram,
    /// From wake-up to the end of the cycle's work.
    pub compute: Histogram,
    /// Between two consecutive wake-ups.
    pub period: Histogram,
    pub cycles: AtomicU64,
    /// Cycles whose work ended after the next deadline (deadlines were skipped).
    pub overruns: AtomicU64,
    pub events_dropped: AtomicU64,
    pub commands_drained: AtomicU64,
    /// Scope frames lost because the scope ring was full (each fails the recordings running).
    pub scope_frames_dropped: AtomicU64,
    /// Requests dropped undone because their requester had stopped waiting (it answered 503).
    pub requests_expired: AtomicU64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn buckets_are_monotonic_and_contain_their_values() {
        for v in [
            0u64,
            1,
            63,
            64,
            65,
            100,
            1000,
            4095,
            4096,
            123_456,
            999_999_999,
        ] {
            let i = index(v);
            assert!(v < upper(i), "{v} in bucket {i} with upper {}", upper(i));
            if i > 0 {
                assert!(v >= upper(i - 1), "{v} below bucket {i}");
            }
        }
        for i in 1..BUCKETS {
            assert!(upper(i) > upper(i - 1));
        }
    }

    #[test]
    fn quantiles() {
        let h = Histogram::default();
        for v in 1..=1000u64 {
            h.record(v * 1000);
        }
        let s = h.summary();
        assert_eq!(s.count, 1000);
        assert!((s.p50_us - 500.0).abs() / 500.0 < 0.07, "{}", s.p50_us);
        assert!((s.p99_us - 990.0).abs() / 990.0 < 0.07, "{}", s.p99_us);
        assert_eq!(s.max_us, 1000.0);
    }
}
