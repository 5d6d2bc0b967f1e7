// Scope recordings: the request, the time axis, channel mapping, cursor readouts and CSV.
// The server records every cycle into a ring (POST /api/v1/scope/recordings) and returns
// `t` (seconds relative to the trigger, or to the start without one) and `data` per channel.

import type { components } from '../api/schema';

type S = components['schemas'];

/** The signals the server can record (generated from the OpenAPI document). */
export type Signal = S['ScopeSignal'];

export const SIGNAL_LABEL: Record<Signal, string> = {
  set_position: 'set position',
  actual_position: 'actual position',
  set_velocity: 'set velocity',
  actual_velocity: 'actual velocity',
  set_acceleration: 'set acceleration',
  actual_acceleration: 'actual acceleration',
  following_error: 'following error',
  path_position: 'path position',
  path_velocity: 'path velocity',
  path_acceleration: 'path acceleration',
  entry_index: 'entry index',
};

/** A group's signals (a channel with `group` instead of `axis`). */
export const GROUP_SIGNALS: Signal[] = ['path_position', 'path_velocity', 'path_acceleration', 'entry_index'];

/** An axis's signals (what the form offers). */
export const SIGNALS = (Object.keys(SIGNAL_LABEL) as Signal[]).filter((s) => !GROUP_SIGNALS.includes(s));

export const MAX_CHANNELS = 8;

export type Edge = S['TriggerEdge'];
export type RecordingRequest = S['RecordingRequest'];
export type TriggerSpec = S['TriggerRequest'];
export type RecordingState = S['RecordingState'];

export interface ChannelSpec {
  /** The axis — or, for a group's signal, the group. */
  axis?: string | null;
  group?: string | null;
  signal: Signal;
  /** The signal's unit (the server names it in a recording). */
  unit?: string;
}

type Rec = S['ScopeRecording'];

/**
 * What this module needs of a recording: the server's `ScopeRecording` (fixtures in tests
 * may leave out the bookkeeping fields). `data` holds null where an axis was missing.
 */
export type Recording = Pick<Rec, 'id' | 'state' | 'cycle_time_s' | 'samples'> &
  Partial<Pick<Rec, 'duration_s' | 'pre_trigger_samples' | 'samples_recorded' | 'reason' | 'start_cycle' | 'trigger_cycle'>> & {
    channels: ChannelSpec[];
    trigger?: TriggerSpec | null;
    t?: number[] | null;
    data?: (number | null)[][] | null;
  };

/** Number of samples of a recording: one per cycle, duration / cycle time exactly. */
export function expectedSamples(duration_s: number, cycle_time_s: number): number {
  return Math.round(duration_s / cycle_time_s);
}

/** Samples before the trigger. */
export function preTriggerSamples(trigger: TriggerSpec | null | undefined, cycle_time_s: number): number {
  return trigger ? Math.round((trigger.pre_trigger_s ?? 0) / cycle_time_s) : 0;
}

export interface FormChannel {
  axis: string;
  /** A group's signal (from a setup stored over the API): kept as it is. */
  group?: string;
  signal: Signal;
}

export interface ScopeForm {
  channels: FormChannel[];
  duration_s: number;
  trigger: { enabled: boolean; channel: number; level: number; edge: Edge; pre_trigger_s: number };
}

/** Builds the request body from the form; errors by field path (as the server names them). */
export function buildRequest(f: ScopeForm): { request: RecordingRequest | null; errors: Record<string, string> } {
  const errors: Record<string, string> = {};
  const channels = f.channels.filter((c) => c.axis || c.group);
  if (channels.length === 0) errors.channels = 'pick at least one signal';
  if (channels.length > MAX_CHANNELS) errors.channels = `at most ${MAX_CHANNELS} channels`;
  channels.forEach((c, i) => {
    const known = c.group ? GROUP_SIGNALS : SIGNALS;
    if (!known.includes(c.signal)) errors[`channels[${i}].signal`] = 'unknown signal';
  });
  if (!(Number.isFinite(f.duration_s) && f.duration_s > 0)) errors.duration_s = 'must be > 0';
  let trigger: TriggerSpec | null = null;
  if (f.trigger.enabled) {
    const t = f.trigger;
    if (!(Number.isInteger(t.channel) && t.channel >= 0 && t.channel < channels.length)) {
      errors['trigger.channel'] = 'pick one of the recorded channels';
    }
    if (!Number.isFinite(t.level)) errors['trigger.level'] = 'must be a number';
    if (!(Number.isFinite(t.pre_trigger_s) && t.pre_trigger_s >= 0)) errors['trigger.pre_trigger_s'] = 'must be ≥ 0';
    else if (t.pre_trigger_s > f.duration_s) errors['trigger.pre_trigger_s'] = 'must not exceed the duration';
    trigger = { channel: t.channel, level: t.level, edge: t.edge, pre_trigger_s: t.pre_trigger_s };
  }
  if (Object.keys(errors).length) return { request: null, errors };
  return {
    request: {
      channels: channels.map((c) => (c.group ? { group: c.group, signal: c.signal } : { axis: c.axis, signal: c.signal })),
      duration_s: f.duration_s,
      trigger,
    },
    errors,
  };
}

export function channelLabel(c: ChannelSpec): string {
  return `${c.axis ?? c.group ?? ''}.${c.signal}`;
}

/** The unit of a signal given the axis's position unit. */
export function signalUnit(signal: Signal, unit: string): string {
  switch (signal) {
    case 'set_velocity':
    case 'actual_velocity':
      return `${unit}/s`;
    case 'set_acceleration':
    case 'actual_acceleration':
      return `${unit}/s²`;
    default:
      return unit;
  }
}

/** Channels of one unit share a y scale. */
export function scaleKey(signal: Signal, unit: string): string {
  return signal === 'following_error' ? `lag:${unit}` : signalUnit(signal, unit);
}

/**
 * The time axis: the server's `t` when present; otherwise one sample per cycle, 0 at the
 * trigger (after `pre_trigger_s` of samples) or at the start.
 */
export function timeAxis(rec: Recording): number[] {
  if (rec.t && rec.t.length) return rec.t;
  const n = rec.data?.[0]?.length ?? rec.samples;
  const pre = rec.pre_trigger_samples ?? preTriggerSamples(rec.trigger, rec.cycle_time_s);
  const t = new Array<number>(n);
  for (let i = 0; i < n; i++) t[i] = (i - pre) * rec.cycle_time_s;
  return t;
}

/** Consistency problems of a finished recording (shown, not thrown). */
export function checkRecording(rec: Recording): string[] {
  const out: string[] = [];
  const data = rec.data ?? [];
  if (data.length !== rec.channels.length) out.push(`${data.length} data rows for ${rec.channels.length} channels`);
  const n = rec.samples;
  if (rec.t && rec.t.length !== n) out.push(`t has ${rec.t.length} samples, expected ${n}`);
  data.forEach((d, i) => {
    if (d.length !== n) out.push(`channel ${i} has ${d.length} samples, expected ${n}`);
  });
  if (rec.duration_s !== undefined && rec.cycle_time_s > 0) {
    const e = expectedSamples(rec.duration_s, rec.cycle_time_s);
    if (e !== n) out.push(`${n} samples, but ${rec.duration_s} s / ${rec.cycle_time_s} s = ${e}`);
  }
  return out;
}

/** Index of the sample nearest to time x (t ascending). */
export function indexAt(t: ArrayLike<number>, x: number): number {
  const n = t.length;
  if (n === 0) return -1;
  if (x <= t[0]) return 0;
  if (x >= t[n - 1]) return n - 1;
  let lo = 0;
  let hi = n - 1;
  while (hi - lo > 1) {
    const mid = (lo + hi) >> 1;
    if (t[mid] <= x) lo = mid;
    else hi = mid;
  }
  return x - t[lo] <= t[hi] - x ? lo : hi;
}

export interface CursorRow {
  label: string;
  v1: number | null;
  v2: number | null;
  dv: number | null;
}

export interface CursorReadout {
  i1: number | null;
  i2: number | null;
  t1: number | null;
  t2: number | null;
  dt: number | null;
  rows: CursorRow[];
}

/** Readouts of two cursors (each snapped to the nearest sample): t, values, Δt, Δvalue. */
export function cursorReadout(
  t: ArrayLike<number>,
  data: ArrayLike<number | null>[],
  labels: string[],
  x1: number | null,
  x2: number | null,
): CursorReadout {
  const i1 = x1 === null ? null : indexAt(t, x1);
  const i2 = x2 === null ? null : indexAt(t, x2);
  const at = (i: number | null) => (i === null || i < 0 ? null : t[i]);
  const t1 = at(i1);
  const t2 = at(i2);
  return {
    i1,
    i2,
    t1,
    t2,
    dt: t1 !== null && t2 !== null ? t2 - t1 : null,
    rows: data.map((d, k) => {
      const v1 = i1 === null || i1 < 0 ? null : (d[i1] ?? null);
      const v2 = i2 === null || i2 < 0 ? null : (d[i2] ?? null);
      return { label: labels[k], v1, v2, dv: v1 !== null && v2 !== null ? v2 - v1 : null };
    }),
  };
}

/** CSV as the server writes it: header `t,x.set_position,…`, one row per sample. */
export function toCsv(
  t: ArrayLike<number>,
  channels: ChannelSpec[],
  data: ArrayLike<number | null>[],
  range?: { from: number; to: number },
): string {
  const lo = range ? Math.max(0, indexAt(t, range.from)) : 0;
  const hi = range ? indexAt(t, range.to) : t.length - 1;
  const lines = [['t', ...channels.map(channelLabel)].join(',')];
  for (let i = lo; i <= hi; i++) {
    const row = [String(t[i])];
    for (const d of data) row.push(d[i] === null || d[i] === undefined ? '' : String(d[i]));
    lines.push(row.join(','));
  }
  return lines.join('\n') + '\n';
}

/** Zoom the x range by `factor` around `x` (factor < 1 zooms in), kept inside [min, max]. */
export function zoomRange(
  range: { min: number; max: number },
  x: number,
  factor: number,
  limits: { min: number; max: number },
): { min: number; max: number } {
  const full = limits.max - limits.min;
  let w = (range.max - range.min) * factor;
  w = Math.min(full, Math.max(w, full * 1e-6));
  const f = (x - range.min) / (range.max - range.min || 1);
  let min = x - f * w;
  let max = min + w;
  if (min < limits.min) {
    min = limits.min;
    max = min + w;
  }
  if (max > limits.max) {
    max = limits.max;
    min = max - w;
  }
  return { min, max };
}

/** Pan the x range by `dx` (seconds), kept inside [min, max]. */
export function panRange(
  range: { min: number; max: number },
  dx: number,
  limits: { min: number; max: number },
): { min: number; max: number } {
  const w = range.max - range.min;
  let min = range.min + dx;
  min = Math.max(limits.min, Math.min(min, limits.max - w));
  return { min, max: min + w };
}
