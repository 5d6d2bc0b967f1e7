// The trace of a recording while it is armed or recording (TwinCAT Scope draws as samples come
// in). The server hands out a recording's samples only once it is done, so until then the trace
// is drawn from the status stream of the channels' axes (25–50 Hz, each stamped with its kernel
// cycle); when the recording is done its every-cycle samples replace it. No UI, no global state:
// services.ts feeds it, the Scope page draws it.
import type { Recording } from './data';

/** What of a recording the live trace needs (the server's recording while armed/recording). */
export type LiveRecording = Pick<Recording, 'id' | 'state' | 'cycle_time_s' | 'channels' | 'trigger' | 'start_cycle' | 'trigger_cycle' | 'samples'> & {
  duration_s?: number | null;
};

/** A status of an axis: the recorded signals are among its number fields. */
export type StatusValues = Partial<Record<string, unknown>>;

export interface LiveSeries {
  /** Seconds: relative to the trigger (negative before it), or to the start without one. */
  t: number[];
  /** Per channel, one value per t (null before a channel's axis has said anything). */
  data: (number | null)[][];
  /** The x range of the whole recording: −pre-trigger … duration − pre-trigger. */
  limits: { min: number; max: number };
  /** Status samples drawn (holds to the present not counted). */
  points: number;
  /** Armed: the trigger has not come yet (the pre-trigger history scrolls up to t = 0). */
  armed: boolean;
}

/** The status stream's interval (25 Hz): a longer pause between two statuses is a hold. */
export const HOLD_STEP_S = 0.04;

/** Rows kept at most (a long recording at 50 Hz of several axes): the oldest go first. */
export const LIVE_CAPACITY = 20000;

export class LiveTrace {
  readonly id: Recording['id'];
  private rec: LiveRecording;
  private readonly cycles: number[] = [];
  private readonly rows: (number | null)[][];
  private readonly last: (number | null)[];
  /** The present: the newest cycle heard of and when (ms, performance.now()). */
  private nowCycle: number | null = null;
  private nowAt = 0;
  /** Counts every change, so the page redraws only when needed. */
  version = 0;

  constructor(rec: LiveRecording) {
    this.id = rec.id;
    this.rec = rec;
    this.rows = rec.channels.map(() => []);
    this.last = rec.channels.map(() => null);
  }

  get channels(): LiveRecording['channels'] {
    return this.rec.channels;
  }

  /** The recording as the server has it now (its state, its trigger cycle once triggered). */
  update(rec: LiveRecording): void {
    if (rec.id !== this.id) return;
    this.rec = rec;
    this.version++;
  }

  private get dt(): number {
    return this.rec.cycle_time_s > 0 ? this.rec.cycle_time_s : 0.001;
  }

  private get pre(): number {
    return this.rec.trigger ? (this.rec.trigger.pre_trigger_s ?? 0) : 0;
  }

  private get duration(): number {
    return this.rec.duration_s ?? this.rec.samples * this.dt;
  }

  /** The cycle of t = 0: the trigger's, or the start's without a trigger; null while armed. */
  private get origin(): number | null {
    if (this.rec.trigger) return this.rec.trigger_cycle ?? null;
    return this.rec.start_cycle ?? null;
  }

  /** The present moved on (another axis's status, the system topic): holds reach up to it. */
  tick(cycle: number, at: number): void {
    if (this.nowCycle === null || cycle >= this.nowCycle) {
      this.nowCycle = cycle;
      this.nowAt = at;
      this.version++;
    }
  }

  /**
   * A status of `axis` at `cycle`: a row with its channels' values, the other channels held
   * at their last value. An older cycle than the newest row is dropped (a server restart ends
   * the recording anyway); the same cycle again replaces the row.
   */
  push(axis: string, status: StatusValues, cycle: number, at: number): void {
    const mine = this.rec.channels.map((c) => c.axis === axis);
    if (!mine.some(Boolean)) return;
    const n = this.cycles.length;
    const newest = n ? this.cycles[n - 1] : null;
    if (newest !== null && cycle < newest) return;
    this.rec.channels.forEach((c, i) => {
      if (!mine[i]) return;
      const v = status[c.signal];
      this.last[i] = typeof v === 'number' && Number.isFinite(v) ? v : null;
    });
    if (newest !== null && cycle === newest) {
      this.rows.forEach((r, i) => (r[n - 1] = this.last[i]));
    } else {
      this.cycles.push(cycle);
      this.rows.forEach((r, i) => r.push(this.last[i]));
      if (this.cycles.length > LIVE_CAPACITY) {
        const drop = this.cycles.length - LIVE_CAPACITY;
        this.cycles.splice(0, drop);
        this.rows.forEach((r) => r.splice(0, drop));
      }
    }
    this.tick(cycle, at);
    this.version++;
  }

  /** The present in kernel cycles at `at` (ms): the newest cycle heard of plus the time since. */
  present(at: number): number | null {
    if (this.nowCycle === null) return null;
    return this.nowCycle + Math.max(0, (at - this.nowAt) / 1000 / this.dt);
  }

  /**
   * What to draw at `at` (ms): once triggered (or without a trigger) the samples from
   * −pre-trigger on, growing towards the recording's end; while armed the last pre-trigger
   * seconds, scrolling up to t = 0. The newest values are held on to the present.
   */
  series(at: number): LiveSeries {
    const dt = this.dt;
    const pre = this.pre;
    const end = this.duration - pre;
    const limits = { min: pre ? -pre : 0, max: end > -pre ? end : -pre + dt };
    const origin = this.origin;
    const now = this.present(at);
    const armed = origin === null;
    const zero = armed ? now : origin;
    const out: LiveSeries = { t: [], data: this.rec.channels.map(() => []), limits, points: 0, armed };
    if (zero === null) return out;
    const rel = (cycle: number) => (cycle - zero) * dt;
    let lastIn = -1;
    for (let k = 0; k < this.cycles.length; k++) {
      const t = rel(this.cycles[k]);
      if (t > limits.max) break;
      if (t < limits.min) {
        lastIn = k; // the newest row before the window: the lines enter from its left edge
        continue;
      }
      if (out.t.length === 0 && lastIn >= 0) this.add(out, limits.min, lastIn);
      // A pause between two statuses means nothing changed (the server sends changes): a hold,
      // not a slow ramp from the older values.
      const prevT = out.t.at(-1);
      if (lastIn >= 0 && prevT !== undefined && t - prevT > 1.5 * HOLD_STEP_S) this.add(out, t - HOLD_STEP_S, lastIn);
      this.add(out, t, k);
      out.points++;
      lastIn = k;
    }
    if (out.t.length === 0 && lastIn >= 0) this.add(out, limits.min, lastIn);
    // Nothing changed since the newest row: the values held on to the present.
    if (now !== null && lastIn >= 0) {
      const tn = Math.min(rel(now), limits.max);
      if (tn > (out.t.at(-1) ?? -Infinity)) this.add(out, tn, lastIn);
    }
    return out;
  }

  private add(out: LiveSeries, t: number, k: number): void {
    out.t.push(t);
    this.rows.forEach((r, i) => out.data[i].push(r[k]));
  }
}
