// The scope's view (which channel goes to which chart, colours, rolling mode), saved setups
// ({recording, view} as PUT /scope/setups/{name} takes them), the rolling ring with honest gaps
// and the alignment of two recordings for comparison. Pure: no DOM, no requests.
import type { components } from '../api/schema';
import { MAX_CHANNELS, SIGNALS, timeAxis, type Edge, type Recording, type RecordingRequest, type ScopeForm, type Signal } from './data';

export type ScopeSetup = components['schemas']['ScopeSetup'];
export type ScopeSetupResource = components['schemas']['ScopeSetupResource'];

/** At most this many stacked charts. */
export const MAX_CHARTS = 4;

export const DEFAULT_COLORS = ['#1363c6', '#d9480f', '#2b8a3e', '#ae3ec9', '#e67700', '#0b7285', '#c92a2a', '#5c5f66'];

export interface RollingOptions {
  /** Show rolling (continuous) recordings instead of single shots. */
  enabled: boolean;
  /** Length of each recording (s). */
  chunk_s: number;
  /** Seconds shown (the ring keeps this much). */
  window_s: number;
}

/** What the page shows beyond the recording request, per channel index. */
export interface ScopeView {
  /** Chart (0-based) of each channel. */
  chart: number[];
  /** Colour of each channel (#rrggbb). */
  colors: string[];
  rolling: RollingOptions;
}

export const DEFAULT_ROLLING: RollingOptions = { enabled: false, chunk_s: 1, window_s: 10 };

export function defaultView(n: number): ScopeView {
  return {
    chart: Array.from({ length: n }, () => 0),
    colors: Array.from({ length: n }, (_, i) => DEFAULT_COLORS[i % DEFAULT_COLORS.length]),
    rolling: { ...DEFAULT_ROLLING },
  };
}

/** The view fitted to n channels (new channels: chart 1 and their default colour). */
export function fitView(v: ScopeView, n: number): ScopeView {
  const d = defaultView(n);
  return {
    ...v,
    chart: d.chart.map((c, i) => (i < v.chart.length ? v.chart[i] : c)),
    colors: d.colors.map((c, i) => (i < v.colors.length ? v.colors[i] : c)),
  };
}

/** The view without channel i (a channel removed from the form). */
export function removeChannel(v: ScopeView, i: number): ScopeView {
  return { ...v, chart: v.chart.filter((_, j) => j !== i), colors: v.colors.filter((_, j) => j !== i) };
}

/** Channel indices of each chart actually used, in chart order (empty charts left out). */
export function chartGroups(v: ScopeView, n: number): number[][] {
  const groups: number[][] = Array.from({ length: MAX_CHARTS }, () => []);
  for (let i = 0; i < n; i++) {
    const c = v.chart[i];
    groups[Number.isInteger(c) && c >= 0 && c < MAX_CHARTS ? c : 0].push(i);
  }
  return groups.filter((g) => g.length > 0);
}

/** The view as saved on the server (JSON object, well under 64 KiB). */
export function viewToJson(v: ScopeView, n: number): Record<string, unknown> {
  const f = fitView(v, n);
  const charts: number[][] = Array.from({ length: MAX_CHARTS }, () => []);
  f.chart.forEach((c, i) => charts[Math.min(Math.max(0, c), MAX_CHARTS - 1)].push(i));
  while (charts.length > 1 && charts[charts.length - 1].length === 0) charts.pop();
  return { version: 1, charts, colors: f.colors, rolling: { ...f.rolling } };
}

const isColor = (x: unknown): x is string => typeof x === 'string' && /^#[0-9a-fA-F]{6}$/.test(x);
const posNum = (x: unknown, d: number) => (typeof x === 'number' && Number.isFinite(x) && x > 0 ? x : d);

/** A saved view back (tolerant: anything missing or odd falls back to the default). */
export function viewFromJson(j: unknown, n: number): ScopeView {
  const v = defaultView(n);
  if (!j || typeof j !== 'object') return v;
  const o = j as Record<string, unknown>;
  if (Array.isArray(o.charts)) {
    o.charts.slice(0, MAX_CHARTS).forEach((g, ci) => {
      if (!Array.isArray(g)) return;
      for (const i of g) if (Number.isInteger(i) && i >= 0 && i < n) v.chart[i as number] = ci;
    });
  }
  if (Array.isArray(o.colors)) o.colors.slice(0, n).forEach((c, i) => isColor(c) && (v.colors[i] = c));
  if (o.rolling && typeof o.rolling === 'object') {
    const r = o.rolling as Record<string, unknown>;
    v.rolling = {
      enabled: r.enabled === true,
      chunk_s: posNum(r.chunk_s, DEFAULT_ROLLING.chunk_s),
      window_s: posNum(r.window_s, DEFAULT_ROLLING.window_s),
    };
  } else if (typeof o.rolling === 'boolean') {
    v.rolling = { ...DEFAULT_ROLLING, enabled: o.rolling };
  }
  return v;
}

/** The body of PUT /scope/setups/{name}. */
export function toSetup(request: RecordingRequest, v: ScopeView): ScopeSetup {
  return { recording: request, view: viewToJson(v, request.channels.length) as ScopeSetup['view'] };
}

/** A saved setup as the form and view of the page. */
export function fromSetup(s: ScopeSetup): { form: ScopeForm; view: ScopeView } {
  const r = s.recording;
  const channels = (r.channels ?? []).slice(0, MAX_CHANNELS).map((c) =>
    c.group
      ? { axis: '', group: c.group, signal: c.signal as Signal }
      : {
          axis: c.axis ?? '',
          signal: (SIGNALS.includes(c.signal as Signal) ? c.signal : 'actual_position') as Signal,
        },
  );
  const t = r.trigger ?? null;
  const form: ScopeForm = {
    channels,
    duration_s: r.duration_s,
    trigger: t
      ? { enabled: true, channel: t.channel, level: t.level, edge: (t.edge ?? 'rising') as Edge, pre_trigger_s: t.pre_trigger_s ?? 0 }
      : { enabled: false, channel: 0, level: 0, edge: 'rising', pre_trigger_s: 0.2 },
  };
  return { form, view: viewFromJson(s.view, channels.length) };
}

/** Server field errors of a setup (`recording.channels[0].axis`) as the form names them. */
export function setupFieldErrors(fields: Record<string, string>): { form: Record<string, string>; other: Record<string, string> } {
  const form: Record<string, string> = {};
  const other: Record<string, string> = {};
  for (const [k, m] of Object.entries(fields)) {
    if (k.startsWith('recording.')) form[k.slice('recording.'.length)] = m;
    else other[k] = m;
  }
  return { form, other };
}

/** A setup name as the server takes it: a letter or `_`, then letters, digits, `_` or `-` (≤ 64). */
export function setupNameError(name: string): string | null {
  if (!name) return 'give the setup a name';
  if (name.length > 64) return 'at most 64 characters';
  if (!/^[A-Za-z_][A-Za-z0-9_-]*$/.test(name)) return 'a letter or _, then letters, digits, _ or -';
  return null;
}

// ---- the rolling ring ----

/** A ring of consecutive recordings on one time axis (s since the first one's start). */
export interface Ring {
  /** Absolute time (s) of t = 0: the first recording's first sample. */
  origin: number | null;
  cycle: number;
  /** Number of channels. */
  n: number;
  t: number[];
  /** One row per channel; null at gaps (drawn as breaks, never joined). */
  data: (number | null)[][];
  /** End (s) of the last appended recording: a gap follows when the next starts later. */
  end: number | null;
  /** Gaps found between recordings (s), newest last. */
  gaps: number;
  /** Samples lost in gaps (total). */
  lostSamples: number;
}

export function emptyRing(n: number, cycle = 0): Ring {
  return { origin: null, cycle, n, t: [], data: Array.from({ length: n }, () => []), end: null, gaps: 0, lostSamples: 0 };
}

/**
 * Appends a finished recording (its first sample at absolute time `start_s`: start_cycle ×
 * cycle time) to the ring; when it does not follow the previous one within half a cycle, one
 * null point is put into the gap so the charts show a break. Samples older than `window_s`
 * before the newest are dropped.
 */
export function appendRing(ring: Ring, start_s: number, cycle: number, data: (number | null)[][], window_s: number): Ring {
  const origin = ring.origin ?? start_s;
  const n = ring.n;
  const t = ring.t.slice();
  const rows = ring.data.map((r) => r.slice());
  const len = data[0]?.length ?? 0;
  const t0 = start_s - origin;
  let gaps = ring.gaps;
  let lost = ring.lostSamples;
  if (ring.end !== null && t.length) {
    const gap = t0 - ring.end;
    if (gap > cycle * 0.5) {
      gaps++;
      lost += Math.round(gap / cycle);
      t.push(ring.end);
      rows.forEach((r) => r.push(null));
    }
  }
  for (let i = 0; i < len; i++) {
    t.push(t0 + i * cycle);
    for (let k = 0; k < n; k++) rows[k].push(data[k]?.[i] ?? null);
  }
  const end = len ? t0 + len * cycle : (ring.end ?? t0);
  // keep the last window (plus the first point before it, so the line enters from the left edge)
  const from = end - window_s;
  let cut = 0;
  while (cut < t.length - 1 && t[cut + 1] < from) cut++;
  if (cut > 0) {
    t.splice(0, cut);
    rows.forEach((r) => r.splice(0, cut));
    // a leading gap marker is of no use
    while (t.length && rows.every((r) => r[0] === null)) {
      t.shift();
      rows.forEach((r) => r.shift());
    }
  }
  return { origin, cycle, n, t, data: rows, end, gaps, lostSamples: lost };
}

/** Absolute start time (s) of a recording's first sample. */
export function recordingStart(r: Recording): number {
  return (r.start_cycle ?? 0) * r.cycle_time_s;
}

// ---- comparing two recordings ----

export type Align = 'start' | 'trigger';

/** The time axis of a recording aligned at its start (0 = first sample) or its trigger (0 = trigger; the start without one). */
export function alignedTime(r: Recording, align: Align): number[] {
  const t = timeAxis(r);
  if (align === 'trigger' && r.trigger) return t;
  const t0 = t[0] ?? 0;
  return t.map((x) => x - t0);
}

/**
 * Two recordings on one x axis for uPlot: the union of their (aligned) sample times, each
 * recording's rows null where it has no sample (drawn with spanGaps). Rows: a's then b's.
 */
export function mergeAligned(
  ta: ArrayLike<number>,
  da: ArrayLike<number | null>[],
  tb: ArrayLike<number>,
  db: ArrayLike<number | null>[],
  eps = 1e-9,
): { t: number[]; a: (number | null)[][]; b: (number | null)[][] } {
  const t: number[] = [];
  const a: (number | null)[][] = da.map(() => []);
  const b: (number | null)[][] = db.map(() => []);
  let i = 0;
  let j = 0;
  while (i < ta.length || j < tb.length) {
    const x = i < ta.length ? ta[i] : Infinity;
    const y = j < tb.length ? tb[j] : Infinity;
    const takeA = x <= y + eps;
    const takeB = y <= x + eps;
    t.push(takeA ? x : y);
    da.forEach((d, k) => a[k].push(takeA ? (d[i] ?? null) : null));
    db.forEach((d, k) => b[k].push(takeB ? (d[j] ?? null) : null));
    if (takeA) i++;
    if (takeB) j++;
  }
  return { t, a, b };
}
