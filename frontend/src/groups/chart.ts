// uPlot charts of a planned path over time, stacked on one time axis (as cams/chart.ts stacks
// a cam's): the path velocity, every member axis's velocity, every member axis's acceleration —
// the server's plan (`POST /path-analysis`). Corner blends are shaded, the start of each entry
// marked by a dashed line with its row number; while the path runs, its live path velocity is
// drawn over the planned one. The element carries `data-samples`, `data-series` and `data-live`
// for the tests.
import uPlot from 'uplot';
import type { GroupRole, PathAnalysisResource } from '../api/types';
import { followWidth, narrowPanes, paneWidth } from '../cams/chart';
import { blendIntervals, entryChanges } from './plan';

export const ROLE_COLORS: Record<string, string> = { x: '#1363c6', y: '#2b8a3e', z: '#d9480f', c: '#ae3ec9' };
const ADDAX_COLORS = ['#495057', '#868e96', '#0c8599', '#e67700', '#5f3dc4', '#a61e4d', '#364fc7', '#2f9e44'];
export const roleColor = (r: string, i: number) => ROLE_COLORS[r] ?? ADDAX_COLORS[i % ADDAX_COLORS.length];
const LIVE = '#e8590c';
const BLEND = 'rgba(174, 62, 201, 0.10)';

interface Pane {
  name: string;
  label: string;
  series: { label: string; stroke: string }[];
  column: (p: PathAnalysisResource) => number[][];
}

let charts = 0;

export class PlanChart {
  private panes: uPlot[] = [];
  private readout: HTMLElement;
  private plan: PathAnalysisResource | null = null;
  private live: { t: number[]; v: number[] } = { t: [], v: [] };
  private blends: [number, number][] = [];
  private entries: { t: number; entry: number }[] = [];
  private ro: ResizeObserver | null = null;
  private readonly defs: Pane[];

  constructor(
    private readonly el: HTMLElement,
    roles: GroupRole[],
    unit = '',
  ) {
    const key = `plan-${++charts}`;
    const u = unit ? ` (${unit}/s)` : ' (/s)';
    const u2 = unit ? ` (${unit}/s²)` : ' (/s²)';
    this.defs = [
      { name: 'path-velocity', label: `path v${u}`, series: [{ label: 'path velocity', stroke: '#1363c6' }], column: (p) => [p.path_velocity] },
      { name: 'axis-velocity', label: `axis v${u}`, series: roles.map((r, i) => ({ label: `${r} velocity`, stroke: roleColor(r, i) })), column: (p) => roles.map((r) => p.axes.find((a) => a.role === r)?.velocity ?? []) },
      { name: 'axis-acceleration', label: `axis a${u2}`, series: roles.map((r, i) => ({ label: `${r} acceleration`, stroke: roleColor(r, i) })), column: (p) => roles.map((r) => p.axes.find((a) => a.role === r)?.acceleration ?? []) },
    ];
    el.replaceChildren();
    // which line is which: the path, each axis by its role's colour, the live run
    const legend = document.createElement('div');
    legend.className = 'plan-legend small';
    const addKey = (text: string, color: string) => {
      const k = document.createElement('span');
      k.className = 'plan-key';
      k.style.setProperty('--key', color);
      k.textContent = text;
      legend.appendChild(k);
    };
    addKey('path', '#1363c6');
    roles.forEach((r, i) => addKey(r.toUpperCase(), roleColor(r, i)));
    addKey('live', LIVE);
    el.appendChild(legend);
    this.readout = document.createElement('div');
    this.readout.className = 'plan-readout mono small';
    el.appendChild(this.readout);
    this.showReadout(null);
    this.defs.forEach((d, i) => {
      const box = document.createElement('div');
      box.className = `plan-pane plan-pane-${d.name}`;
      box.dataset.pane = d.name;
      el.appendChild(box);
      const last = i === this.defs.length - 1;
      const opts: uPlot.Options = {
        width: paneWidth(el),
        height: this.height(i),
        legend: { show: false },
        cursor: { sync: { key }, drag: { x: false, y: false } },
        scales: { x: { time: false }, y: { range: (_u, min, max) => range(min, max) } },
        axes: [
          last
            ? { label: 'time (s)', labelSize: 14, size: 30, stroke: '#4a5563', grid: { stroke: '#e6e9ee' }, ticks: { stroke: '#c9cfd6' } }
            : { stroke: '#4a5563', grid: { stroke: '#e6e9ee' }, ticks: { stroke: '#c9cfd6', size: 4 }, size: 6, values: (_u, splits) => splits.map(() => '') },
          { label: d.label, labelSize: 16, labelFont: '11px system-ui, sans-serif', stroke: '#4a5563', grid: { stroke: '#eef0f3' }, ticks: { stroke: '#c9cfd6' }, size: 64, space: 18 },
        ],
        series: [{ label: 't' }, ...d.series.map((s) => ({ label: s.label, stroke: s.stroke, width: 1.5 }))],
        hooks: {
          drawClear: [(u) => this.drawUnder(u)],
          draw: [(u) => this.drawOver(u, i)],
          setCursor: i === 0 ? [(u) => this.showReadout(u.cursor.idx ?? null)] : [],
        },
      };
      this.panes.push(new uPlot(opts, [[], ...d.series.map(() => [])], box));
    });
    el.dataset.series = this.defs.flatMap((d) => d.series.map((s) => s.label)).join(',');
    el.dataset.samples = '0';
    el.dataset.live = '0';
    this.ro = followWidth(el, () => this.panes, (i) => this.height(i));
  }

  private height(i: number): number {
    return (narrowPanes(this.el) ? 90 : 120) + (i === this.defs.length - 1 ? 30 : 0);
  }

  /** The plan to draw (null: none; the panes are emptied). */
  setPlan(p: PathAnalysisResource | null): void {
    this.plan = p;
    this.blends = p ? blendIntervals(p) : [];
    this.entries = p ? entryChanges(p) : [];
    this.panes.forEach((u, i) => u.setData([p ? p.t : [], ...(p ? this.defs[i].column(p) : this.defs[i].series.map(() => []))], true));
    this.el.dataset.samples = String(p?.t.length ?? 0);
    this.showReadout(null);
  }

  /** The live run's path velocity over its time (drawn over the plan's). */
  setLive(t: number[], v: number[]): void {
    this.live = { t, v };
    this.el.dataset.live = String(t.length);
    this.panes[0]?.redraw(false, false);
  }

  /** Blends shaded and entry starts marked, under the lines. */
  private drawUnder(u: uPlot): void {
    const ctx = u.ctx;
    const { left, top, width, height } = u.bbox;
    ctx.save();
    ctx.fillStyle = BLEND;
    for (const [a, b] of this.blends) {
      const x0 = Math.max(left, u.valToPos(a, 'x', true));
      const x1 = Math.min(left + width, u.valToPos(b, 'x', true));
      if (x1 > x0) ctx.fillRect(x0, top, Math.max(1, x1 - x0), height);
    }
    ctx.strokeStyle = '#adb5bd';
    ctx.lineWidth = uPlot.pxRatio;
    ctx.setLineDash([3 * uPlot.pxRatio, 3 * uPlot.pxRatio]);
    for (const e of this.entries) {
      const x = Math.round(u.valToPos(e.t, 'x', true));
      ctx.beginPath();
      ctx.moveTo(x, top);
      ctx.lineTo(x, top + height);
      ctx.stroke();
    }
    ctx.restore();
  }

  /** Row numbers at the entry starts (top pane), and the live path velocity over the plan. */
  private drawOver(u: uPlot, i: number): void {
    if (i !== 0) return;
    const ctx = u.ctx;
    const { left, top, width, height } = u.bbox;
    ctx.save();
    ctx.font = `${10 * uPlot.pxRatio}px system-ui, sans-serif`;
    ctx.fillStyle = '#6c757d';
    ctx.textBaseline = 'top';
    const first = this.plan?.entry[0];
    const marks = first === undefined ? this.entries : [{ t: this.plan!.t[0], entry: first }, ...this.entries];
    for (const e of marks) ctx.fillText(String(e.entry + 1), Math.round(u.valToPos(e.t, 'x', true)) + 3 * uPlot.pxRatio, top + 2 * uPlot.pxRatio);
    const { t, v } = this.live;
    if (t.length > 1) {
      ctx.beginPath();
      ctx.rect(left, top, width, height);
      ctx.clip();
      ctx.strokeStyle = LIVE;
      ctx.lineWidth = 2 * uPlot.pxRatio;
      ctx.beginPath();
      t.forEach((x, k) => {
        const px = u.valToPos(x, 'x', true);
        const py = u.valToPos(v[k], 'y', true);
        if (k) ctx.lineTo(px, py);
        else ctx.moveTo(px, py);
      });
      ctx.stroke();
    }
    ctx.restore();
  }

  private showReadout(idx: number | null): void {
    const p = this.plan;
    if (idx === null || !p || p.t[idx] === undefined) {
      this.readout.textContent = p ? 'Move the pointer over a chart to read the plan.' : '\u00a0';
      return;
    }
    const parts = [`t ${fmt(p.t[idx])} s`, `row ${p.entry[idx] + 1}${p.in_blend[idx] ? ' (blend)' : ''}`, `path v ${fmt(p.path_velocity[idx])}`, ...p.axes.map((a) => `${a.role} v ${fmt(a.velocity[idx])} a ${fmt(a.acceleration[idx])}`)];
    this.readout.textContent = parts.join(' · ');
  }

  destroy(): void {
    this.ro?.disconnect();
    this.panes.forEach((u) => u.destroy());
    this.panes = [];
    this.el.replaceChildren();
  }
}

function range(min: number, max: number): [number, number] {
  if (!Number.isFinite(min) || !Number.isFinite(max)) return [-1, 1];
  if (max - min < 1e-9) return [min - 1, max + 1];
  const r = uPlot.rangeNum(min, max, 0.1, true);
  return [r[0] ?? min, r[1] ?? max];
}

const fmt = (v: number | null | undefined) => (v === null || v === undefined || !Number.isFinite(v) ? '—' : String(Number(v.toPrecision(5))));
