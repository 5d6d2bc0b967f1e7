//! The lines of an axis that its next step will touch, asked for while the axis before it
//! steps (issue 27). An axis is ≈ 6 KB (95 cache lines) and a moving step touches ≈ 31–33 of
//! them, spread over it; with 256 axes they live in L2 instead of L1, and the step waited for
//! them (a positioning axis 1.6 × as long per axis at 256 axes as at 16). They are asked for
//! in [`PARTS`] parts spread over the step before ([`Ahead`]), not all at once. A prefetch is
//! only a hint: a span that no longer holds what a step touches costs a little time, never a
//! result.

// Elsewhere than on x86-64 the prefetch is a no-op and the lines are not used.
#![cfg_attr(not(target_arch = "x86_64"), allow(dead_code))]

use super::*;
use core::mem::{offset_of, size_of};

/// A part of an axis: its offset and length in bytes.
type Span = (usize, usize);

/// `len` bytes from `at` into the field at `offset` of size `size`; `at` < 0 counts from
/// the field's end. A span that leaves its field stops the build.
const fn span(offset: usize, size: usize, at: isize, len: usize) -> Span {
    let from = if at < 0 {
        assert!(at.unsigned_abs() <= size, "a span starts before its field");
        size - at.unsigned_abs()
    } else {
        at as usize
    };
    assert!(len > 0 && from + len <= size, "a span leaves its field");
    (offset + from, len)
}

macro_rules! part {
    ($field:ident) => {
        span(
            offset_of!(Axis, $field),
            size_of_field!($field),
            0,
            size_of_field!($field),
        )
    };
    ($field:ident, $at:expr, $len:expr) => {
        span(offset_of!(Axis, $field), size_of_field!($field), $at, $len)
    };
}

/// The size of a field of `Axis` (without a value to take it from).
macro_rules! size_of_field {
    ($field:ident) => {{
        const fn size<T>(_: fn(&Axis) -> &T) -> usize {
            size_of::<T>()
        }
        size(|a: &Axis| &a.$field)
    }};
}

/// The parts a moving step reads or writes — a velocity or positioning job with nothing
/// coupled and no other block in use — as a trace of the step's memory accesses found them
/// (valgrind's lackey over 16 moving axes, `scripts/bench/axis_lines.py`); named by field and
/// measured from a field's start or end, so that they follow each field's place in `Axis`
/// when fields are added (the offsets inside a field follow that type's own layout: the trace
/// is what tells them). The step's scalar fields (actual values, flags, the idle marks) lie
/// together at the end of the struct in rustc's present layout, which puts the small fields
/// last; the set values (32 bytes, as aligned as the beat's 32) and the beat come earlier and
/// are named on their own. The test bounds the set should the layout change.
const MOVING: [Span; 20] = [
    // The plan being sampled: its trajectory's head and the sampling state at its end.
    part!(planner, 48, 80),
    part!(planner, -72, 72),
    part!(ext),
    part!(job),
    part!(next, 0, 8),
    // The parameters a step reads (windows, limits, following error) and the config's flags.
    part!(config, 144, 48),
    part!(config, 280, 8),
    part!(config, -72, 72),
    // The status: its numbers at the head, its flags at the end.
    part!(status, 0, 264),
    part!(status, -72, 72),
    part!(coupling, -16, 16),
    part!(drive, 40, 8),
    part!(superposition, -8, 8),
    part!(corrections, 0, 40),
    part!(power),
    part!(stop),
    part!(torque, 0, 32),
    part!(beat),
    part!(set),
    (SCALARS, size_of::<Axis>() - SCALARS),
];

/// Where the step's scalar fields begin (the lowest of their offsets).
const SCALARS: usize = {
    let offsets = [
        offset_of!(Axis, cycle_time),
        offset_of!(Axis, power_override),
        offset_of!(Axis, act_pos),
        offset_of!(Axis, enc_k),
        offset_of!(Axis, error),
        offset_of!(Axis, idle),
        offset_of!(Axis, mode),
    ];
    let mut low = usize::MAX;
    let mut i = 0;
    while i < offsets.len() {
        if offsets[i] < low {
            low = offsets[i];
        }
        i += 1;
    }
    low
};

/// The cache lines of `spans` (64 bytes, from the start of an axis: `Axis` is aligned to
/// them), as a bit set.
const fn lines(spans: &[Span]) -> u128 {
    let mut set = 0u128;
    let mut i = 0;
    while i < spans.len() {
        let (start, len) = spans[i];
        assert!(
            len > 0 && start + len <= size_of::<Axis>(),
            "a span leaves the axis"
        );
        let mut line = start / 64;
        while line <= (start + len - 1) / 64 {
            set |= 1 << line;
            line += 1;
        }
        i += 1;
    }
    set
}

const MOVING_LINES: u128 = lines(&MOVING);
const COUNT: usize = MOVING_LINES.count_ones() as usize;

/// The lines' offsets in bytes, lowest first.
const OFFSETS: [usize; COUNT] = {
    let mut out = [0; COUNT];
    let mut set = MOVING_LINES;
    let mut i = 0;
    while set != 0 {
        out[i] = set.trailing_zeros() as usize * 64;
        set &= set - 1;
        i += 1;
    }
    out
};

// The set holds every line of an axis.
const _: () = assert!(size_of::<Axis>() <= 128 * 64);
const _: () = assert!(core::mem::align_of::<Axis>() == 64);

/// In how many parts the next axis's lines are asked for: the first before this axis steps,
/// the second after its MC_Power part, the third after its job (a disabled axis: once its set
/// values follow the actual position; `cycle.rs`). The parts go by offset, not by when the
/// next step reads them: all of them are asked for before it begins. All ≈ 33 at once, as
/// before, waited for the core's line-fill buffers (about a dozen misses in flight) before the
/// step went on: at 256 axes, where the lines come from L2, a moving step cost 1.13–1.27 × per
/// axis what it cost at 16, and 1.10–1.18 × with the requests in three parts
/// (docs/benchmarks.md, "Kernel cycle").
pub(crate) const PARTS: usize = 3;
const PART: usize = COUNT.div_ceil(PARTS);
// The parts cover every line, and none is empty.
const _: () = assert!(PART * PARTS >= COUNT && PART * (PARTS - 1) < COUNT);

/// The axis the kernel steps next, whose lines are asked for while this one steps. Only its
/// address is kept: a prefetch reads nothing into the program, so the next axis is never
/// read through it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Ahead(*const Axis);

impl Ahead {
    /// No axis follows, or it rests: nothing to ask for.
    pub(crate) const NONE: Ahead = Ahead(core::ptr::null());

    /// `next`'s step is ahead. An axis at rest reads only its beat, which this reads to know.
    #[inline]
    pub(crate) fn of(next: Option<&Axis>) -> Ahead {
        match next {
            Some(a) if !a.beat.resting => Ahead(a),
            _ => Ahead::NONE,
        }
    }

    /// Asks for the `n`th part of the lines (`n` < [`PARTS`]).
    #[inline]
    pub(crate) fn part(self, n: usize) {
        debug_assert!(n < PARTS);
        self.parts(n, n + 1);
    }

    /// Asks for the parts from the `n`th on, at once: for the first axis, which no step
    /// precedes, and after a step at rest, which is too short to spread them over.
    #[inline]
    pub(crate) fn all_from(self, n: usize) {
        self.parts(n, PARTS);
    }

    #[inline]
    #[cfg_attr(not(target_arch = "x86_64"), allow(unused_variables))]
    fn parts(self, from: usize, to: usize) {
        if self.0.is_null() {
            return;
        }
        #[cfg(target_arch = "x86_64")]
        {
            let base = self.0.cast::<i8>();
            let lines = &OFFSETS[(from * PART).min(COUNT)..(to * PART).min(COUNT)];
            for &offset in lines {
                // SAFETY: SSE, which `_mm_prefetch` needs, is part of every x86-64 CPU; the
                // address is made with `wrapping_add` and a prefetch never faults (it reads
                // nothing into the program).
                unsafe {
                    core::arch::x86_64::_mm_prefetch::<{ core::arch::x86_64::_MM_HINT_T0 }>(
                        base.wrapping_add(offset),
                    )
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every span lies inside the axis (checked while the constants are evaluated), and the
    /// set is the few lines a step touches, not the whole axis (the trace found 31–33 of its
    /// 95).
    #[test]
    fn the_prefetched_lines_are_inside_the_axis_and_few() {
        let all = size_of::<Axis>().div_ceil(64);
        assert!(COUNT >= 25 && COUNT <= all / 2, "{COUNT} of {all} lines");
        assert!(OFFSETS.windows(2).all(|w| w[0] < w[1]));
    }
}
