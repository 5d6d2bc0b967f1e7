// The live trend of the Online tab (TwinCAT's online chart): the last 10 s of set velocity,
// actual velocity (left scale) and following error (right scale) from the axis's status
// stream (50 Hz while on screen), kept in the axis's fixed-size ring buffer by services.ts.
// Redrawn at most 25 times a second while live; frozen and greyed while the socket is down,
// frozen while paused (recording goes on). The element carries what is drawn as data
// attributes for the tests: `data-points` (samples in the window), `data-vmax` (largest
// |set velocity| in it).
import uPlot from 'uplot';
import { useEffect, useRef, useState } from 'preact/hooks';
import { FOCUS_RATE_HZ, statuses, system, trendOf } from '../../services';
import { Panel } from '../shared/common';
import { num } from '../../format';
import { TREND_WINDOW_S, presentCycle, trendRange, trendSeries } from '../../live/trend';

const SERIES = [
  { key: 'set', label: 'Set velocity', short: 'set v', color: '#1363c6', width: 1.5, scale: 'v' },
  { key: 'act', label: 'Actual velocity', short: 'act v', color: '#2b8a3e', width: 1, scale: 'v' },
  { key: 'lag', label: 'Following error', short: 'lag', color: '#d9480f', width: 1.25, scale: 'e' },
] as const;

const REDRAW_MS = 40;
const HEIGHT = 150;

const tick = (v: number) => String(Number(v.toPrecision(3)));

export function Trend({ axis, unit, online }: { axis: string; unit: string; online: boolean }) {
  const el = useRef<HTMLDivElement>(null);
  const legend = useRef<HTMLSpanElement[]>([]);
  const [paused, setPaused] = useState(false);
  const pausedRef = useRef(paused);
  pausedRef.current = paused;
  const onlineRef = useRef(online);
  onlineRef.current = online;
  const redraw = useRef<() => void>(() => {});

  useEffect(() => {
    const host = el.current!;
    const buf = trendOf(axis);
    const opts: uPlot.Options = {
      width: Math.max(200, host.clientWidth),
      height: HEIGHT,
      padding: [8, 2, 0, 2],
      legend: { show: false },
      cursor: { drag: { x: false, y: false, setScale: false }, points: { show: false }, y: false },
      select: { show: false, left: 0, top: 0, width: 0, height: 0 },
      scales: {
        x: { time: false, auto: false, range: () => [-TREND_WINDOW_S, 0] },
        v: { auto: true, range: (_u, min, max) => trendRange(min, max) },
        e: { auto: true, range: (_u, min, max) => trendRange(min, max) },
      },
      axes: [
        { stroke: '#4a5563', size: 22, font: '10px system-ui, sans-serif', grid: { stroke: '#eef0f3' }, ticks: { size: 3, stroke: '#c9cfd6' }, values: (_u, vs) => vs.map((v) => `${v} s`) },
        { scale: 'v', stroke: SERIES[0].color, size: 46, font: '10px system-ui, sans-serif', grid: { stroke: '#eef0f3' }, ticks: { size: 3, stroke: '#c9cfd6' }, values: (_u, vs) => vs.map(tick) },
        { scale: 'e', side: 1, stroke: SERIES[2].color, size: 50, font: '10px system-ui, sans-serif', grid: { show: false }, ticks: { size: 3, stroke: '#c9cfd6' }, values: (_u, vs) => vs.map(tick) },
      ],
      series: [{}, ...SERIES.map((s) => ({ label: s.label, scale: s.scale, stroke: s.color, width: s.width, points: { show: false } }))],
      hooks: {
        setCursor: [
          (u) => {
            const i = u.cursor.idx;
            SERIES.forEach((s, k) => {
              const span = legend.current[k];
              if (!span) return;
              const v = i === null || i === undefined ? undefined : (u.data[k + 1][i] as number | null);
              span.textContent = v === undefined ? '' : num(v, s.scale === 'e' ? 4 : 2);
            });
          },
        ],
      },
    };
    const chart = new uPlot(opts, [[], [], [], []], host);

    const draw = () => {
      const cycleTime = system.get()?.cycle_time ?? 0.001;
      const now = presentCycle(buf, performance.now(), cycleTime);
      const live = statuses.get().get(axis);
      const s =
        now === null
          ? null
          : trendSeries(buf, {
              cycleTime,
              nowCycle: now,
              step: 1 / FOCUS_RATE_HZ,
              holdToNow: onlineRef.current && !!live && !live.stale,
            });
      chart.setData(s ? [s.t, s.setVelocity, s.actualVelocity, s.followingError] : [[], [], [], []]);
      host.dataset.points = String(s ? s.samples : 0);
      let vmax = 0;
      for (const v of s?.setVelocity ?? []) if (v !== null) vmax = Math.max(vmax, Math.abs(v));
      host.dataset.vmax = String(vmax);
    };
    redraw.current = draw;
    draw();

    let raf = 0;
    let last = 0;
    const frame = (t: number) => {
      raf = requestAnimationFrame(frame);
      if (pausedRef.current || !onlineRef.current || t - last < REDRAW_MS) return;
      last = t;
      draw();
    };
    raf = requestAnimationFrame(frame);

    const ro =
      typeof ResizeObserver !== 'undefined'
        ? new ResizeObserver(() => {
            const w = Math.max(200, host.clientWidth);
            if (Math.abs(w - chart.width) > 2) chart.setSize({ width: w, height: HEIGHT });
          })
        : null;
    ro?.observe(host);
    return () => {
      cancelAnimationFrame(raf);
      ro?.disconnect();
      chart.destroy();
      redraw.current = () => {};
    };
  }, [axis]);

  const clear = () => {
    trendOf(axis).clear();
    redraw.current();
  };
  const state = !online ? 'not live' : paused ? 'paused' : `${TREND_WINDOW_S} s`;
  return (
    <Panel
      title="Trend"
      class={`trend ${online ? '' : 'trend-off'} ${paused ? 'trend-paused' : ''}`}
      actions={
        <>
          <span class="muted small" data-testid="trend-state">
            {state}
          </span>
          <button type="button" class="btn btn-small" name="trend-pause" onClick={() => setPaused(!paused)} title={paused ? 'draw the live values again' : 'freeze the chart (recording goes on)'}>
            {paused ? 'Resume' : 'Pause'}
          </button>
          <button type="button" class="btn btn-small" name="trend-clear" onClick={clear} title="forget the recorded values">
            Clear
          </button>
        </>
      }
    >
      <div class="trend-chart" ref={el} data-testid="trend" data-paused={paused ? '1' : '0'} />
      <div class="trend-legend small">
        {SERIES.map((s, k) => (
          <span class="trend-key" data-series={s.key} title={`${s.label} (${s.scale === 'v' ? `${unit}/s, left scale` : `${unit}, right scale`})`}>
            <i style={{ background: s.color }} />
            {s.short} <span class="muted">{s.scale === 'v' ? `${unit}/s` : unit}</span>{' '}
            <span class="mono" ref={(x) => {
                if (x) legend.current[k] = x;
              }} />
          </span>
        ))}
      </div>
    </Panel>
  );
}
