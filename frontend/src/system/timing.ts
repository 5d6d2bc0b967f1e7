// Cycle timing as the System page shows it: microseconds for people, how alarming a figure is
// against the cycle time, and a client-side history of the polls (overruns over time, the
// wake-up latency of each poll's window) kept for the last few minutes.
import type { components } from '../api/schema';
import { diffHistogram, maxBound, quantile, type CycleHistograms, type Histogram } from './prometheus';

export type Summary = components['schemas']['Summary'];
export type SystemResource = components['schemas']['SystemResource'];

export const POLL_MS = 2000;
/** How much of the polled history is kept (and drawn). */
export const HISTORY_S = 300;
/** A pause between two polls longer than this is drawn as a gap. */
export const GAP_S = 10;

/** A duration in µs with a precision that fits its size: "3.712", "14.34", "1015.8". */
export function us(v: number | null | undefined): string {
  if (v === null || v === undefined || !Number.isFinite(v)) return '—';
  const a = Math.abs(v);
  if (a >= 100) return v.toFixed(1);
  if (a >= 10) return v.toFixed(2);
  return v.toFixed(3);
}

/** A bound in seconds as µs text for an axis or a tooltip (0.000014336 → "14.3"). */
export function usShort(seconds: number): string {
  const v = seconds * 1e6;
  if (!Number.isFinite(v)) return '∞';
  if (v >= 1000) return `${Number((v / 1000).toPrecision(3))} ms`;
  return `${Number(v.toPrecision(3))} µs`;
}

export type Level = 'ok' | 'warn' | 'bad';

/**
 * How alarming a timing figure is against the cycle time (µs vs seconds): wake-up latency and
 * compute time eat the cycle (half of it: warn; all of it: a missed deadline); the period
 * should be the cycle time (off by half a cycle: warn; two cycles: a cycle was skipped).
 */
export function level(kind: 'wakeup_latency' | 'compute' | 'period', valueUs: number, cycleTimeS: number): Level {
  const cycleUs = cycleTimeS * 1e6;
  if (!Number.isFinite(valueUs) || !(cycleUs > 0)) return 'ok';
  if (kind === 'period') {
    const off = Math.abs(valueUs - cycleUs);
    if (valueUs >= 2 * cycleUs) return 'bad';
    return off >= 0.5 * cycleUs ? 'warn' : 'ok';
  }
  if (valueUs >= cycleUs) return 'bad';
  return valueUs >= 0.5 * cycleUs ? 'warn' : 'ok';
}

export const QUANTILES = [
  ['p50_us', 'p50'],
  ['p90_us', 'p90'],
  ['p99_us', 'p99'],
  ['p999_us', 'p99.9'],
  ['max_us', 'max'],
  ['mean_us', 'mean'],
] as const;

/** One poll: the counters, and the wake-up latency of the cycles since the previous poll. */
export interface Point {
  /** Seconds since the epoch (client clock). */
  t: number;
  cycles: number;
  overruns: number;
  /** Overruns since the previous poll; null for the first poll after a gap or a restart. */
  overrunsDelta: number | null;
  /** Wake-up latency p99 and largest of the cycles since the previous poll (µs, to a bucket). */
  wakeP99: number | null;
  wakeMax: number | null;
}

/** Polls of the last few minutes, with the histograms of the last poll to diff against. */
export class TimingHistory {
  points: Point[] = [];
  private lastWake: Histogram | null = null;
  /** Histograms of past polls (for windows: "last 10 s", "last minute"). */
  snapshots: { t: number; hist: CycleHistograms }[] = [];

  constructor(readonly keepS = HISTORY_S) {}

  add(t: number, sys: Pick<SystemResource, 'timing'>, hist: CycleHistograms | null): Point {
    const prev = this.points[this.points.length - 1];
    const fresh = !prev || t - prev.t > GAP_S || sys.timing.cycles < prev.cycles || sys.timing.overruns < prev.overruns;
    let wakeP99: number | null = null;
    let wakeMax: number | null = null;
    const wake = hist?.wakeup_latency ?? null;
    if (!fresh && wake && this.lastWake) {
      const d = diffHistogram(wake, this.lastWake);
      if (d && d.count > 0) {
        const q = quantile(d, 0.99);
        const m = maxBound(d);
        wakeP99 = q === null ? null : q * 1e6;
        wakeMax = m === null ? null : m * 1e6;
      }
    }
    if (wake) this.lastWake = wake;
    if (fresh) this.snapshots = [];
    if (hist) this.snapshots.push({ t, hist });
    const p: Point = {
      t,
      cycles: sys.timing.cycles,
      overruns: sys.timing.overruns,
      overrunsDelta: fresh ? null : sys.timing.overruns - prev.overruns,
      wakeP99,
      wakeMax,
    };
    // After a gap (the page was away, motiond restarted) a point without values breaks the lines.
    if (fresh && prev) this.points.push({ t: (prev.t + t) / 2, cycles: prev.cycles, overruns: prev.overruns, overrunsDelta: null, wakeP99: null, wakeMax: null });
    this.points.push(p);
    const cut = t - this.keepS;
    while (this.points.length && this.points[0].t < cut) this.points.shift();
    while (this.snapshots.length > 1 && this.snapshots[0].t < cut) this.snapshots.shift();
    return p;
  }

  /**
   * The histograms of the cycles in about the last `windowS` seconds (the newest snapshot minus
   * the one nearest `windowS` before it); null for "since start" or when none is old enough.
   */
  window(windowS: number | null): { hist: CycleHistograms; spanS: number } | null {
    const last = this.snapshots[this.snapshots.length - 1];
    if (!last) return null;
    if (windowS === null) return { hist: last.hist, spanS: Infinity };
    let base: { t: number; hist: CycleHistograms } | null = null;
    for (const s of this.snapshots) {
      if (s === last) break;
      if (last.t - s.t >= windowS * 0.9) base = s;
    }
    if (!base) return null;
    const out: CycleHistograms = {};
    for (const k of Object.keys(last.hist) as (keyof CycleHistograms)[]) {
      const a = last.hist[k];
      const b = base.hist[k];
      const d = a && b ? diffHistogram(a, b) : null;
      if (d) out[k] = d;
    }
    return { hist: out, spanS: last.t - base.t };
  }

  clear(): void {
    this.points = [];
    this.snapshots = [];
    this.lastWake = null;
  }
}

/** An uptime as "3 d 4 h", "2 h 13 min", "5 min 3 s", "12 s". */
export function uptime(s: number): string {
  if (!Number.isFinite(s) || s < 0) return '—';
  const d = Math.floor(s / 86400);
  const h = Math.floor((s % 86400) / 3600);
  const m = Math.floor((s % 3600) / 60);
  const sec = Math.floor(s % 60);
  if (d) return `${d} d ${h} h`;
  if (h) return `${h} h ${m} min`;
  if (m) return `${m} min ${sec} s`;
  return `${sec} s`;
}
