// The Prometheus text format (0.0.4) as `GET /metrics` sends it, and the cycle timing
// histograms in it (`motiond_cycle_*_seconds_bucket`, cumulative, `le` in seconds). With
// `?buckets=fine` every bucket (≈6 % steps) is there: the distribution can be drawn, and the
// difference of two scrapes is the distribution of the cycles between them.

export interface Sample {
  name: string;
  labels: Record<string, string>;
  value: number;
}

/** A histogram: upper bounds (seconds, ascending, the last +Inf) with cumulative counts. */
export interface Histogram {
  le: number[];
  cumulative: number[];
  count: number;
  sum: number;
}

/** One bucket of a histogram as a bar: the cycles whose value lies in (lo, hi]. */
export interface Bar {
  lo: number;
  hi: number;
  count: number;
}

function parseValue(s: string): number {
  switch (s) {
    case '+Inf':
    case 'Inf':
      return Infinity;
    case '-Inf':
      return -Infinity;
    case 'NaN':
      return NaN;
    default:
      return s.trim() === '' ? NaN : Number(s);
  }
}

/** The labels between `{` and `}`: `a="x",b="y \"q\""` (escapes \\, \" and \n). */
function parseLabels(s: string, line: string): Record<string, string> {
  const out: Record<string, string> = {};
  let i = 0;
  for (;;) {
    while (i < s.length && (s[i] === ' ' || s[i] === ',')) i++;
    if (i >= s.length) return out;
    const eq = s.indexOf('=', i);
    if (eq < 0 || s[eq + 1] !== '"') throw new Error(`bad labels in: ${line}`);
    const name = s.slice(i, eq).trim();
    let v = '';
    let j = eq + 2;
    for (; j < s.length && s[j] !== '"'; j++) {
      if (s[j] === '\\' && j + 1 < s.length) {
        j++;
        v += s[j] === 'n' ? '\n' : s[j];
      } else v += s[j];
    }
    if (j >= s.length) throw new Error(`unterminated label value in: ${line}`);
    out[name] = v;
    i = j + 1;
  }
}

/**
 * Every sample of a Prometheus text exposition. Comments (`# HELP`, `# TYPE`) and blank lines
 * are skipped; a timestamp after the value is ignored; a line that cannot be read throws.
 */
export function parsePrometheus(text: string): Sample[] {
  const out: Sample[] = [];
  for (const raw of text.split('\n')) {
    const line = raw.trim();
    if (!line || line.startsWith('#')) continue;
    let name: string;
    let labels: Record<string, string> = {};
    let rest: string;
    const brace = line.indexOf('{');
    const space = line.search(/\s/);
    if (brace >= 0 && (space < 0 || brace < space)) {
      name = line.slice(0, brace);
      // The closing brace: the last `}` (label values may hold one, quoted).
      const close = line.lastIndexOf('}');
      if (close < brace) throw new Error(`bad sample: ${line}`);
      labels = parseLabels(line.slice(brace + 1, close), line);
      rest = line.slice(close + 1).trim();
    } else {
      if (space < 0) throw new Error(`bad sample: ${line}`);
      name = line.slice(0, space);
      rest = line.slice(space).trim();
    }
    const value = parseValue(rest.split(/\s+/)[0] ?? '');
    if (!/^[a-zA-Z_:][a-zA-Z0-9_:]*$/.test(name) || (Number.isNaN(value) && rest.split(/\s+/)[0] !== 'NaN')) {
      throw new Error(`bad sample: ${line}`);
    }
    out.push({ name, labels, value });
  }
  return out;
}

/**
 * The histogram `base` (e.g. `motiond_cycle_compute_seconds`) of the samples whose labels
 * (other than `le`) equal `match`; null when it is not there.
 */
export function histogramOf(samples: Sample[], base: string, match: Record<string, string> = {}): Histogram | null {
  const fits = (s: Sample) => Object.entries(match).every(([k, v]) => s.labels[k] === v);
  const buckets: [number, number][] = [];
  let count: number | null = null;
  let sum = 0;
  for (const s of samples) {
    if (!fits(s)) continue;
    if (s.name === `${base}_bucket` && s.labels.le !== undefined) buckets.push([parseValue(s.labels.le), s.value]);
    else if (s.name === `${base}_count`) count = s.value;
    else if (s.name === `${base}_sum`) sum = s.value;
  }
  if (!buckets.length) return null;
  buckets.sort((a, b) => a[0] - b[0]);
  const le = buckets.map((b) => b[0]);
  const cumulative = buckets.map((b) => b[1]);
  return { le, cumulative, count: count ?? cumulative[cumulative.length - 1], sum };
}

/** The cycle timing histograms of motiond, by the names of `GET /system`'s timing. */
export const CYCLE_HISTOGRAMS = {
  wakeup_latency: 'motiond_cycle_wakeup_latency_seconds',
  compute: 'motiond_cycle_compute_seconds',
  period: 'motiond_cycle_period_seconds',
} as const;
export type CycleHistogram = keyof typeof CYCLE_HISTOGRAMS;

export type CycleHistograms = Partial<Record<CycleHistogram, Histogram>>;

export function cycleHistograms(text: string): CycleHistograms {
  const samples = parsePrometheus(text);
  const out: CycleHistograms = {};
  for (const [k, base] of Object.entries(CYCLE_HISTOGRAMS) as [CycleHistogram, string][]) {
    const h = histogramOf(samples, base);
    if (h) out[k] = h;
  }
  return out;
}

/**
 * The cycles between two scrapes: `now` minus `before` bucket by bucket. Null when they do not
 * fit (other buckets, or counts that went down: motiond was restarted in between).
 */
export function diffHistogram(now: Histogram, before: Histogram): Histogram | null {
  if (now.le.length !== before.le.length || now.le.some((v, i) => v !== before.le[i])) return null;
  const cumulative = now.cumulative.map((c, i) => c - before.cumulative[i]);
  if (cumulative.some((c) => c < 0) || now.count < before.count) return null;
  return { le: now.le, cumulative, count: now.count - before.count, sum: now.sum - before.sum };
}

/** The buckets as bars (counts per bucket, not cumulative), from 0 to the last bound. */
export function bars(h: Histogram): Bar[] {
  const out: Bar[] = [];
  let prevLe = 0;
  let prevCum = 0;
  for (let i = 0; i < h.le.length; i++) {
    out.push({ lo: prevLe, hi: h.le[i], count: Math.max(0, h.cumulative[i] - prevCum) });
    prevLe = h.le[i];
    prevCum = h.cumulative[i];
  }
  return out;
}

/**
 * The bars from the first to the last non-empty one, with `pad` empty ones either side where
 * there are (an empty list for an empty histogram).
 */
export function trimBars(b: Bar[], pad = 1): Bar[] {
  let first = b.findIndex((x) => x.count > 0);
  if (first < 0) return [];
  let last = b.length - 1;
  while (last > first && b[last].count === 0) last--;
  first = Math.max(0, first - pad);
  last = Math.min(b.length - 1, last + pad);
  // An open-ended last bucket (+Inf) cannot be drawn as a bar of finite width.
  while (last > first && !Number.isFinite(b[last].hi) && b[last].count === 0) last--;
  return b.slice(first, last + 1);
}

/**
 * The q-quantile (0…1) as the upper bound of the bucket where the cumulative count reaches
 * q × count (as motiond's own p50 … p99.9 are); null for an empty histogram.
 */
export function quantile(h: Histogram, q: number): number | null {
  const total = h.cumulative[h.cumulative.length - 1] ?? 0;
  if (total <= 0) return null;
  const rank = Math.max(1, Math.ceil(q * total));
  for (let i = 0; i < h.le.length; i++) if (h.cumulative[i] >= rank) return h.le[i];
  return h.le[h.le.length - 1];
}

/** The upper bound of the highest non-empty bucket (the largest value, to a bucket); null if empty. */
export function maxBound(h: Histogram): number | null {
  let prev = 0;
  let best: number | null = null;
  for (let i = 0; i < h.le.length; i++) {
    if (h.cumulative[i] > prev) best = h.le[i];
    prev = h.cumulative[i];
  }
  return best;
}
