// The live trend of the Online tab: a fixed-size ring buffer of status samples per axis and
// the series a chart draws from it. No UI, no global state.
//
// Samples come from the status subscription, stamped with the kernel cycle. The server sends
// an axis's status only when a field changed, so a pause between two samples means "nothing
// changed" (a hold), not "no data"; only a lost socket or subscription is a real gap, marked
// with `gap()`. The time axis is the kernel's: cycle × cycle time.

/** Seconds the trend shows. */
export const TREND_WINDOW_S = 10;
/** Samples kept per axis: 10 s at 50 Hz with room to spare. Older ones are overwritten. */
export const TREND_CAPACITY = 640;

export interface TrendPoint {
  cycle: number;
  setVelocity: number;
  actualVelocity: number;
  followingError: number;
  /** No data between the previous sample and this one (socket or subscription lost). */
  gapBefore: boolean;
}

export class TrendBuffer {
  readonly capacity: number;
  private readonly cycles: Float64Array;
  private readonly setV: Float64Array;
  private readonly actV: Float64Array;
  private readonly lag: Float64Array;
  private readonly gaps: Uint8Array;
  private head = 0; // where the next sample goes
  private n = 0;
  private gapPending = false;
  /** `performance.now()`-style time at which the newest sample arrived. */
  lastAt = 0;
  /** Counts every change (push, gap, clear) so a chart redraws only when needed. */
  version = 0;

  constructor(capacity = TREND_CAPACITY) {
    this.capacity = Math.max(2, Math.floor(capacity));
    this.cycles = new Float64Array(this.capacity);
    this.setV = new Float64Array(this.capacity);
    this.actV = new Float64Array(this.capacity);
    this.lag = new Float64Array(this.capacity);
    this.gaps = new Uint8Array(this.capacity);
  }

  get length(): number {
    return this.n;
  }

  /** The newest sample's cycle, or null when empty. */
  get lastCycle(): number | null {
    return this.n ? this.cycles[(this.head - 1 + this.capacity) % this.capacity] : null;
  }

  /**
   * Adds a sample. A cycle older than the newest one means the server was restarted (its
   * counter starts at 0 again): what was recorded before is dropped. The same cycle again
   * replaces the newest sample.
   */
  push(cycle: number, setVelocity: number, actualVelocity: number, followingError: number, at = 0): void {
    const last = this.lastCycle;
    if (last !== null && cycle < last) this.clear();
    let i: number;
    if (last !== null && cycle === last && this.n) {
      i = (this.head - 1 + this.capacity) % this.capacity;
    } else {
      i = this.head;
      this.head = (this.head + 1) % this.capacity;
      if (this.n < this.capacity) this.n++;
      this.gaps[i] = this.gapPending && this.n > 1 ? 1 : 0;
      this.gapPending = false;
    }
    this.cycles[i] = cycle;
    this.setV[i] = setVelocity;
    this.actV[i] = actualVelocity;
    this.lag[i] = followingError;
    this.lastAt = at;
    this.version++;
  }

  /** Nothing is known from now until the next sample (the socket or subscription was lost). */
  gap(): void {
    if (this.gapPending || !this.n) return;
    this.gapPending = true;
    this.version++;
  }

  /** Whether the newest sample is followed by a gap (no hold to "now" may be drawn). */
  get broken(): boolean {
    return this.gapPending;
  }

  clear(): void {
    this.head = 0;
    this.n = 0;
    this.gapPending = false;
    this.version++;
  }

  /** The i-th sample, oldest first. */
  at(i: number): TrendPoint {
    const k = (this.head - this.n + i + this.capacity * 2) % this.capacity;
    return {
      cycle: this.cycles[k],
      setVelocity: this.setV[k],
      actualVelocity: this.actV[k],
      followingError: this.lag[k],
      gapBefore: this.gaps[k] === 1,
    };
  }
}

export interface TrendSeries {
  /** Seconds relative to `nowCycle` (≤ 0). */
  t: number[];
  setVelocity: (number | null)[];
  actualVelocity: (number | null)[];
  followingError: (number | null)[];
  /** Real samples in the window (holds and gap markers not counted). */
  samples: number;
}

export interface SeriesOptions {
  /** Kernel cycle time in seconds. */
  cycleTime: number;
  /** The cycle at the right edge (the present). */
  nowCycle: number;
  /** Seconds shown (default TREND_WINDOW_S). */
  window?: number;
  /** The status update interval in seconds (1 / rate); a longer pause is a hold. */
  step: number;
  /** Draw the newest values on to `nowCycle` (live, nothing changed since). */
  holdToNow: boolean;
}

/**
 * The points to draw for the last `window` seconds: times relative to `nowCycle`, a hold
 * point just before a sample that follows a pause (values stayed as they were), a null
 * between samples separated by a gap (uPlot leaves a gap), and, when live, the newest values
 * held on to the present. One sample before the window is kept so the lines enter from the
 * left edge.
 */
export function trendSeries(buf: TrendBuffer, o: SeriesOptions): TrendSeries {
  const window = o.window ?? TREND_WINDOW_S;
  const out: TrendSeries = { t: [], setVelocity: [], actualVelocity: [], followingError: [], samples: 0 };
  const dt = o.cycleTime > 0 ? o.cycleTime : 0.001;
  const rel = (cycle: number) => (cycle - o.nowCycle) * dt;
  const add = (t: number, p: { setVelocity: number; actualVelocity: number; followingError: number } | null) => {
    out.t.push(t);
    out.setVelocity.push(p ? p.setVelocity : null);
    out.actualVelocity.push(p ? p.actualVelocity : null);
    out.followingError.push(p ? p.followingError : null);
  };
  // The first sample to draw: the newest one at or before the window's start, if any.
  let first = 0;
  for (let i = buf.length - 1; i >= 0; i--) {
    if (rel(buf.at(i).cycle) <= -window) {
      first = i;
      break;
    }
  }
  let prev: TrendPoint | null = null;
  for (let i = first; i < buf.length; i++) {
    const p = buf.at(i);
    const t = rel(p.cycle);
    if (t > 0) break; // newer than the present asked for
    if (prev) {
      const tp = rel(prev.cycle);
      if (p.gapBefore) {
        add((tp + t) / 2, null);
      } else if (t - tp > 1.5 * o.step) {
        add(t - o.step, prev);
      }
    }
    add(t, p);
    if (t > -window) out.samples++;
    prev = p;
  }
  if (prev && o.holdToNow && !buf.broken && rel(prev.cycle) < 0) add(0, prev);
  return out;
}

/** The present in kernel cycles: the newest sample's cycle plus the time since it arrived. */
export function presentCycle(buf: TrendBuffer, now: number, cycleTime: number): number | null {
  const last = buf.lastCycle;
  if (last === null) return null;
  const dt = cycleTime > 0 ? cycleTime : 0.001;
  return last + Math.max(0, (now - buf.lastAt) / 1000 / dt);
}

/** A y range that always holds 0 and never collapses to nothing. */
export function trendRange(min: number | null, max: number | null): [number, number] {
  let lo = Math.min(min ?? 0, 0);
  let hi = Math.max(max ?? 0, 0);
  if (!Number.isFinite(lo) || !Number.isFinite(hi)) return [-1, 1];
  if (hi - lo < 1e-9) return [-1, 1];
  const pad = (hi - lo) * 0.08;
  if (lo < 0) lo -= pad;
  if (hi > 0) hi += pad;
  return [lo, hi];
}
