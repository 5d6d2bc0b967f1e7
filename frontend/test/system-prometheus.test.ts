// The Prometheus text of GET /metrics and the cycle timing histograms in it; the System page's
// figures (µs, levels against the cycle time) and its history of polls.
import { describe, expect, it } from 'vitest';
import { bars, cycleHistograms, diffHistogram, histogramOf, maxBound, parsePrometheus, quantile, trimBars, type Histogram } from '../src/system/prometheus';
import { TimingHistory, level, us, uptime } from '../src/system/timing';

const TEXT = `# HELP motiond_build_info The running build.
# TYPE motiond_build_info gauge
motiond_build_info{version="0.1.0"} 1
# HELP motiond_cycle_compute_seconds Work per cycle
# TYPE motiond_cycle_compute_seconds histogram
motiond_cycle_compute_seconds_sum 0.0522
motiond_cycle_compute_seconds_count 10
motiond_cycle_compute_seconds_bucket{le="0.000002"} 0
motiond_cycle_compute_seconds_bucket{le="0.000004"} 6
motiond_cycle_compute_seconds_bucket{le="0.000008"} 9
motiond_cycle_compute_seconds_bucket{le="0.000016"} 9
motiond_cycle_compute_seconds_bucket{le="0.000032"} 10
motiond_cycle_compute_seconds_bucket{le="+Inf"} 10
motiond_commands_total{block="move-absolute",verdict="accepted"} 12 1700000000000
weird{a="x \\"quoted\\" }",b="line\\nbreak"} NaN

process_threads 5.0
`;

describe('the Prometheus text format', () => {
  it('reads names, labels (with escapes), values (+Inf, NaN, a timestamp after them) and skips comments', () => {
    const s = parsePrometheus(TEXT);
    expect(s.find((x) => x.name === 'motiond_build_info')).toEqual({ name: 'motiond_build_info', labels: { version: '0.1.0' }, value: 1 });
    expect(s.find((x) => x.name === 'motiond_commands_total')).toEqual({ name: 'motiond_commands_total', labels: { block: 'move-absolute', verdict: 'accepted' }, value: 12 });
    const w = s.find((x) => x.name === 'weird')!;
    expect(w.labels).toEqual({ a: 'x "quoted" }', b: 'line\nbreak' });
    expect(Number.isNaN(w.value)).toBe(true);
    expect(s.find((x) => x.name === 'process_threads')!.value).toBe(5);
    expect(s.filter((x) => x.name.endsWith('_bucket')).map((x) => x.labels.le)).toEqual(['0.000002', '0.000004', '0.000008', '0.000016', '0.000032', '+Inf']);
  });

  it('refuses a line it cannot read', () => {
    expect(() => parsePrometheus('motiond_x{le="1} 3')).toThrow();
    expect(() => parsePrometheus('just_a_name')).toThrow();
    expect(() => parsePrometheus('m abc')).toThrow();
  });

  it('a histogram: bounds ascending with +Inf last, cumulative counts, count and sum', () => {
    const h = histogramOf(parsePrometheus(TEXT), 'motiond_cycle_compute_seconds')!;
    expect(h.le).toEqual([2e-6, 4e-6, 8e-6, 16e-6, 32e-6, Infinity]);
    expect(h.cumulative).toEqual([0, 6, 9, 9, 10, 10]);
    expect(h.count).toBe(10);
    expect(h.sum).toBeCloseTo(0.0522);
    expect(histogramOf(parsePrometheus(TEXT), 'motiond_nothing')).toBeNull();
    // cycleHistograms: the three of motiond by the names of GET /system's timing
    const c = cycleHistograms(TEXT);
    expect(Object.keys(c)).toEqual(['compute']);
  });

  it('bars per bucket, trimmed to the non-empty ones with one empty either side', () => {
    const h = histogramOf(parsePrometheus(TEXT), 'motiond_cycle_compute_seconds')!;
    expect(bars(h).map((b) => b.count)).toEqual([0, 6, 3, 0, 1, 0]);
    const t = trimBars(bars(h));
    expect(t.map((b) => [b.lo, b.hi, b.count])).toEqual([
      [0, 2e-6, 0],
      [2e-6, 4e-6, 6],
      [4e-6, 8e-6, 3],
      [8e-6, 16e-6, 0],
      [16e-6, 32e-6, 1],
    ]);
    // (the empty +Inf bucket is left out: it has no width; the empty first bucket is the pad)
    expect(trimBars(bars(h), 0)[0].lo).toBe(2e-6);
    expect(trimBars(bars(h), 0).length).toBe(4);
    expect(trimBars(bars({ le: [1, Infinity], cumulative: [0, 0], count: 0, sum: 0 }))).toEqual([]);
  });

  it('quantiles and the largest value to a bucket, as motiond computes them', () => {
    const h = histogramOf(parsePrometheus(TEXT), 'motiond_cycle_compute_seconds')!;
    expect(quantile(h, 0.5)).toBe(4e-6);
    expect(quantile(h, 0.6)).toBe(4e-6);
    expect(quantile(h, 0.61)).toBe(8e-6);
    expect(quantile(h, 0.99)).toBe(32e-6);
    expect(maxBound(h)).toBe(32e-6);
    const empty: Histogram = { le: [1, Infinity], cumulative: [0, 0], count: 0, sum: 0 };
    expect(quantile(empty, 0.5)).toBeNull();
    expect(maxBound(empty)).toBeNull();
  });

  it('the difference of two scrapes is the cycles between them; a restart gives none', () => {
    const a: Histogram = { le: [1, 2, Infinity], cumulative: [5, 8, 8], count: 8, sum: 9 };
    const b: Histogram = { le: [1, 2, Infinity], cumulative: [6, 12, 13], count: 13, sum: 20 };
    expect(diffHistogram(b, a)).toEqual({ le: [1, 2, Infinity], cumulative: [1, 4, 5], count: 5, sum: 11 });
    expect(diffHistogram(a, b)).toBeNull();
    expect(diffHistogram(b, { ...a, le: [1, 3, Infinity] })).toBeNull();
  });
});

describe('timing figures', () => {
  it('µs with a precision that fits', () => {
    expect(us(3.7123)).toBe('3.712');
    expect(us(14.336)).toBe('14.34');
    expect(us(1015.808)).toBe('1015.8');
    expect(us(null)).toBe('—');
    expect(us(NaN)).toBe('—');
  });

  it('levels against the cycle time (1 ms)', () => {
    expect(level('wakeup_latency', 30, 0.001)).toBe('ok');
    expect(level('wakeup_latency', 500, 0.001)).toBe('warn');
    expect(level('wakeup_latency', 1200, 0.001)).toBe('bad');
    expect(level('compute', 999, 0.001)).toBe('warn');
    expect(level('period', 1015.8, 0.001)).toBe('ok');
    expect(level('period', 1600, 0.001)).toBe('warn');
    expect(level('period', 400, 0.001)).toBe('warn');
    expect(level('period', 2100, 0.001)).toBe('bad');
  });

  it('uptime in words', () => {
    expect(uptime(12.5)).toBe('12 s');
    expect(uptime(303)).toBe('5 min 3 s');
    expect(uptime(2 * 3600 + 13 * 60)).toBe('2 h 13 min');
    expect(uptime(3 * 86400 + 4 * 3600)).toBe('3 d 4 h');
  });
});

describe('the history of polls', () => {
  const sys = (cycles: number, overruns: number) => ({ timing: { cycles, overruns } }) as never;
  const wake = (cum: number[]): Histogram => ({ le: [10e-6, 20e-6, 40e-6, Infinity], cumulative: cum, count: cum[cum.length - 1], sum: 0 });

  it('overruns per poll, the wake-up latency of each poll’s cycles; a gap or restart breaks the line', () => {
    const h = new TimingHistory(300);
    expect(h.add(1000, sys(100, 2), { wakeup_latency: wake([90, 100, 100, 100]) }).overrunsDelta).toBeNull();
    const p = h.add(1002, sys(2100, 5), { wakeup_latency: wake([1000, 2090, 2100, 2100]) });
    expect(p.overrunsDelta).toBe(3);
    // the 2000 cycles between: 910 ≤ 10 µs, 1080 ≤ 20 µs, 10 ≤ 40 µs
    expect(p.wakeP99).toBeCloseTo(20);
    expect(p.wakeMax).toBeCloseTo(40);
    // a poll 30 s later (the page was hidden): a gap point, then a fresh start
    const q = h.add(1032, sys(32000, 5), { wakeup_latency: wake([30000, 31990, 32000, 32000]) });
    expect(q.overrunsDelta).toBeNull();
    expect(h.points.map((x) => x.overrunsDelta)).toEqual([null, 3, null, null]);
    // motiond restarted: counters went down
    expect(h.add(1034, sys(50, 0), null).overrunsDelta).toBeNull();
  });

  it('keeps the last few minutes; windows are differences of snapshots', () => {
    const h = new TimingHistory(60);
    for (let i = 0; i <= 60; i++) h.add(i * 2, sys(i * 2000, 0), { wakeup_latency: wake([i * 1000, i * 2000, i * 2000, i * 2000]) });
    expect(h.points[0].t).toBeGreaterThanOrEqual(120 - 60);
    expect(h.points[h.points.length - 1].t).toBe(120);
    const w = h.window(10)!;
    expect(w.spanS).toBe(10);
    expect(w.hist.wakeup_latency!.count).toBe(10000);
    expect(h.window(null)!.hist.wakeup_latency!.count).toBe(120000);
    expect(h.window(600)).toBeNull();
  });
});
