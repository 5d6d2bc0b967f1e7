// The System page's charts: a timing distribution as SVG bars (log-spaced buckets, count on a
// log scale so that the rare slow cycles show), and overruns over time (uPlot).
import uPlot from 'uplot';
import { useEffect, useRef, useState } from 'preact/hooks';
import { bars, quantile, trimBars, type Histogram } from '../../system/prometheus';
import { usShort, type Point } from '../../system/timing';

/** The width of an element, followed as it changes. */
function useWidth(initial: number) {
  const ref = useRef<HTMLDivElement>(null);
  const [w, setW] = useState(initial);
  useEffect(() => {
    const el = ref.current;
    if (!el) return;
    const measure = () => {
      const cw = Math.floor(el.clientWidth);
      if (cw > 0) setW((old) => (Math.abs(old - cw) > 1 ? cw : old));
    };
    measure();
    if (typeof ResizeObserver === 'undefined') return;
    const ro = new ResizeObserver(measure);
    ro.observe(el);
    return () => ro.disconnect();
  }, []);
  return [ref, w] as const;
}

/** 1-2-5 steps in seconds between lo and hi (for the x axis). */
function niceTicks(lo: number, hi: number): number[] {
  const out: number[] = [];
  if (!(hi > 0)) return out;
  let dec = Math.pow(10, Math.floor(Math.log10(Math.max(lo, hi / 1e6))));
  for (let i = 0; i < 40 && dec <= hi; i++, dec *= 10) for (const m of [1, 2, 5]) if (dec * m >= lo && dec * m <= hi) out.push(dec * m);
  return out;
}

const fmtCount = (n: number) => (n >= 1e6 ? `${Number((n / 1e6).toPrecision(3))}M` : n >= 1e3 ? `${Number((n / 1e3).toPrecision(3))}k` : String(n));

const MARKS = [
  [0.5, 'p50', '#2b8a3e'],
  [0.99, 'p99', '#e0950f'],
  [0.999, 'p99.9', '#d32f2f'],
] as const;

/**
 * A timing distribution: one bar per bucket (equal widths: the buckets are log-spaced), the
 * cycle count on a log scale, p50/p99/p99.9 marked. `name` names it for the tests.
 */
export function HistogramChart({ name, hist, height = 170 }: { name: string; hist: Histogram | null | undefined; height?: number }) {
  const [ref, width] = useWidth(480);
  const b = hist ? trimBars(bars(hist)) : [];
  const total = hist ? hist.cumulative[hist.cumulative.length - 1] ?? 0 : 0;
  const W = Math.max(200, width);
  const H = height;
  const m = { l: 38, r: 8, t: 16, b: 22 };
  const pw = W - m.l - m.r;
  const ph = H - m.t - m.b;
  const maxCount = b.reduce((x, y) => Math.max(x, y.count), 0);
  const yOf = (c: number) => m.t + ph - (maxCount > 0 ? (Math.log10(c + 1) / Math.log10(maxCount + 1)) * ph : 0);
  const bw = b.length ? pw / b.length : 0;
  /** x of a value in seconds: inside its bucket, log-interpolated. */
  const xOf = (v: number): number | null => {
    for (let i = 0; i < b.length; i++) {
      const { lo, hi } = b[i];
      if (v > lo && v <= hi) {
        const f = lo > 0 && Number.isFinite(hi) ? Math.log(v / lo) / Math.log(hi / lo) : 1;
        return m.l + (i + f) * bw;
      }
    }
    return null;
  };
  const lo = b.length ? b[0].lo || b[0].hi / 1.06 : 0;
  const hi = b.length ? b[b.length - 1].hi : 0;
  const xt = b.length ? niceTicks(lo, Number.isFinite(hi) ? hi : b[b.length - 1].lo) : [];
  // No more x labels than fit (about 48 px each).
  const step = Math.max(1, Math.ceil((xt.length * 48) / pw));
  const yt: number[] = [];
  for (let v = 1; v <= maxCount; v *= 10) yt.push(v);
  return (
    <div class="hist" ref={ref} data-testid={`hist-${name}`} data-bars={b.length} data-count={total}>
      {b.length === 0 ? (
        <div class="hist-empty muted" style={{ height: `${H}px` }}>
          {hist ? 'no cycles in this window' : 'no histogram (GET /metrics?buckets=fine)'}
        </div>
      ) : (
        <svg width={W} height={H} viewBox={`0 0 ${W} ${H}`} role="img" aria-label={`distribution of ${name}`}>
          {yt.map((v) => (
            <g key={`y${v}`}>
              <line x1={m.l} x2={W - m.r} y1={yOf(v)} y2={yOf(v)} class="hist-grid" />
              <text x={m.l - 4} y={yOf(v) + 3} class="hist-label" text-anchor="end">
                {fmtCount(v)}
              </text>
            </g>
          ))}
          {b.map((x, i) =>
            x.count > 0 ? (
              <rect key={i} x={m.l + i * bw + (bw > 3 ? 0.5 : 0)} width={Math.max(1, bw - (bw > 3 ? 1 : 0))} y={yOf(x.count)} height={m.t + ph - yOf(x.count)} class="hist-bar">
                <title>{`${usShort(x.lo)} – ${usShort(x.hi)}: ${x.count} cycles`}</title>
              </rect>
            ) : null,
          )}
          <line x1={m.l} x2={W - m.r} y1={m.t + ph} y2={m.t + ph} class="hist-axis" />
          {xt.map((v, i) => {
            const x = xOf(v);
            if (x === null || i % step) return null;
            return (
              <g key={`x${v}`}>
                <line x1={x} x2={x} y1={m.t + ph} y2={m.t + ph + 3} class="hist-axis" />
                <text x={x} y={H - 6} class="hist-label" text-anchor="middle">
                  {usShort(v)}
                </text>
              </g>
            );
          })}
          {hist &&
            MARKS.map(([q, label, color], k) => {
              const v = quantile(hist, q);
              const x = v === null ? null : xOf(v);
              if (x === null) return null;
              return (
                <g key={label} data-mark={label}>
                  <line x1={x} x2={x} y1={m.t - 2} y2={m.t + ph} stroke={color} stroke-dasharray="3 2" stroke-width="1.2" />
                  <text x={x > W - m.r - 40 ? x - 3 : x + 3} y={m.t + 7 + k * 10} fill={color} class="hist-label hist-mark" text-anchor={x > W - m.r - 40 ? 'end' : 'start'}>
                    {label}
                  </text>
                </g>
              );
            })}
        </svg>
      )}
    </div>
  );
}

const OVERRUN = '#d32f2f';
const p2 = (n: number) => String(n).padStart(2, '0');
/** A time of day (seconds since the epoch) as HH:MM:SS. */
const clock = (t: number) => {
  const d = new Date(t * 1000);
  return `${p2(d.getHours())}:${p2(d.getMinutes())}:${p2(d.getSeconds())}`;
};
const P99 = '#1363c6';
const MAX = '#8aa4c8';

/**
 * Overruns per poll (bars, left scale) and the wake-up latency p99 and largest of each poll's
 * cycles (lines, µs, right scale) over the last few minutes.
 */
export function OverrunChart({ points, windowS, version }: { points: Point[]; windowS: number; version: number }) {
  const el = useRef<HTMLDivElement>(null);
  const chart = useRef<uPlot | null>(null);
  const HEIGHT = 160;
  const data = (): uPlot.AlignedData => [
    points.map((p) => p.t),
    points.map((p) => p.overrunsDelta),
    points.map((p) => p.wakeP99),
    points.map((p) => p.wakeMax),
  ];
  useEffect(() => {
    const host = el.current!;
    const axisFont = '10px system-ui, sans-serif';
    const opts: uPlot.Options = {
      width: Math.max(200, host.clientWidth),
      height: HEIGHT,
      padding: [8, 4, 0, 2],
      legend: { show: false },
      cursor: { drag: { x: false, y: false, setScale: false }, y: false },
      select: { show: false, left: 0, top: 0, width: 0, height: 0 },
      scales: {
        x: {
          time: true,
          auto: false,
          // The last `windowS` seconds; while there are fewer, what there is (a minute at least).
          range: (u) => {
            const t = u.data[0];
            const end = t.length ? (t[t.length - 1] as number) : Date.now() / 1000;
            const first = t.length ? (t[0] as number) : end;
            return [Math.max(end - windowS, Math.min(first, end - 60)), end];
          },
        },
        n: { auto: true, range: (_u, _min, max) => [0, Math.max(1, Math.ceil((max ?? 0) * 1.15))] },
        us: { auto: true, range: (_u, _min, max) => [0, Math.max(10, (max ?? 0) * 1.15)] },
      },
      axes: [
        { stroke: '#4a5563', size: 24, space: 70, font: axisFont, grid: { stroke: '#eef0f3' }, ticks: { size: 3, stroke: '#c9cfd6' }, values: (_u, vs) => vs.map(clock) },
        { scale: 'n', stroke: OVERRUN, size: 34, font: axisFont, grid: { stroke: '#eef0f3' }, ticks: { size: 3, stroke: '#c9cfd6' }, values: (_u, vs) => vs.map((v) => (Number.isInteger(v) ? String(v) : '')) },
        { scale: 'us', side: 1, stroke: P99, size: 44, font: axisFont, grid: { show: false }, ticks: { size: 3, stroke: '#c9cfd6' }, values: (_u, vs) => vs.map((v) => `${Number(v.toPrecision(3))}`) },
      ],
      series: [
        {},
        { label: 'overruns', scale: 'n', stroke: OVERRUN, fill: 'rgba(211,47,47,0.55)', width: 1, paths: uPlot.paths.bars!({ size: [0.8, 14] }), points: { show: false } },
        { label: 'wake-up p99', scale: 'us', stroke: P99, width: 1.5, points: { show: false } },
        { label: 'wake-up max', scale: 'us', stroke: MAX, width: 1, dash: [4, 3], points: { show: false } },
      ],
    };
    const c = new uPlot(opts, data(), host);
    chart.current = c;
    const ro =
      typeof ResizeObserver !== 'undefined'
        ? new ResizeObserver(() => {
            const w = Math.max(200, host.clientWidth);
            if (Math.abs(w - c.width) > 2) c.setSize({ width: w, height: HEIGHT });
          })
        : null;
    ro?.observe(host);
    return () => {
      ro?.disconnect();
      c.destroy();
      chart.current = null;
    };
  }, []);
  useEffect(() => {
    chart.current?.setData(data());
  }, [version]);
  const total = points.reduce((n, p) => n + (p.overrunsDelta ?? 0), 0);
  return (
    <div>
      <div class="overrun-chart" ref={el} data-testid="overrun-chart" data-points={points.length} data-overruns={total} />
      <div class="trend-legend small">
        <span class="trend-key">
          <i style={{ background: OVERRUN }} />
          overruns per poll <span class="muted">(left)</span>
        </span>
        <span class="trend-key">
          <i style={{ background: P99 }} />
          wake-up p99 <span class="muted">µs (right)</span>
        </span>
        <span class="trend-key">
          <i style={{ background: MAX }} />
          wake-up max <span class="muted">µs</span>
        </span>
      </div>
    </div>
  );
}
