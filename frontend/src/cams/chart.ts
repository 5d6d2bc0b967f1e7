// uPlot charts of a cam over its master, stacked on one master axis: position (with the points
// as handles to drag), velocity, acceleration, jerk — the server's sampled values, the one source
// of the cam's math. Discontinuities are marked by a dashed line at their master position.
// The element carries `data-samples` and `data-series`; each handle is an element
// `[data-handle=i]` placed with uPlot's valToPos, so tests can grab it.
import uPlot from 'uplot';
import type { Handle } from './data';

export const CAM_COLORS = ['#1363c6', '#2b8a3e', '#d9480f', '#ae3ec9'];
const NAMES = ['position', 'velocity', 'acceleration', 'jerk'];
/** The axis labels with units (slave unit per master unit, its derivatives), short enough for a pane. */
const SHORT = ['position', 'vel', 'acc', 'jerk'];
const POWER = ['', '', '²', '³'];

/** The units of the plot: a coupled slave's and its master's. */
export interface CamUnits {
  master: string;
  slave: string;
}

/** Where a coupled slave is on the table now (drawn as a marker on the position plot). */
export interface CamChartMarker {
  axis: string;
  x: number;
  y: number;
}

/** The label of pane `i`'s y axis (and the master axis as `x`) in these units. */
export function camAxisLabel(i: number | 'x', units: CamUnits | null): string {
  if (i === 'x') return units ? `master (${units.master})` : 'master';
  if (!units) return NAMES[i];
  return i === 0 ? `${SHORT[0]} (${units.slave})` : `${SHORT[i]} (${units.slave}/${units.master}${POWER[i]})`;
}

export type DragPhase = 'start' | 'move' | 'end';

export interface CamChartCallbacks {
  /**
   * A handle is grabbed ('start'), dragged to (master, slave) in the values of the plot, not yet
   * clamped ('move'), let go ('end': where the last move took it).
   */
  onDrag?: (index: number, master: number, slave: number, phase: DragPhase) => void;
}

let charts = 0;

/** The width of a stacked pane in `el`, and whether `el` is narrow (a phone's width). */
export const paneWidth = (el: HTMLElement) => Math.max(200, el.clientWidth || 600);
export const narrowPanes = (el: HTMLElement) => (el.clientWidth || 600) < 560;

/** Keeps stacked panes as wide as `el`, each `height(i)` high (null without ResizeObserver). */
export function followWidth(el: HTMLElement, panes: () => uPlot[], height: (i: number) => number): ResizeObserver | null {
  if (typeof ResizeObserver === 'undefined') return null;
  const ro = new ResizeObserver(() => panes().forEach((u, i) => u.setSize({ width: paneWidth(el), height: height(i) })));
  ro.observe(el);
  return ro;
}

export class CamChart {
  private panes: uPlot[] = [];
  private readout: HTMLElement;
  private handleBox: HTMLElement | null = null;
  private handles: Handle[] = [];
  private warn = new Set<number>();
  private marks: number[] = [];
  private markers: CamChartMarker[] = [];
  private units: CamUnits | null = null;
  private range: [number, number] = [0, 1];
  /** While a handle is dragged, the scales stay where they were when it was grabbed. */
  private frozen: { x: [number, number]; y: [number, number] } | null = null;
  private dragging: number | null = null;
  private ro: ResizeObserver | null = null;

  constructor(
    private readonly el: HTMLElement,
    private readonly cb: CamChartCallbacks = {},
  ) {
    const key = `cam-${++charts}`;
    el.replaceChildren();
    this.readout = document.createElement('div');
    this.readout.className = 'cam-readout mono';
    el.appendChild(this.readout);
    this.showReadout(null);
    NAMES.forEach((name, i) => {
      const box = document.createElement('div');
      box.className = `cam-pane cam-pane-${name}`;
      box.dataset.pane = name;
      el.appendChild(box);
      const last = i === NAMES.length - 1;
      const opts: uPlot.Options = {
        width: this.width(),
        height: this.height(i),
        legend: { show: false },
        cursor: { sync: { key }, drag: { x: false, y: false } },
        scales: {
          x: { time: false, range: () => this.frozen?.x ?? this.range },
          y: { range: (_u, min, max) => this.yRange(i, min, max) },
        },
        axes: [
          last
            ? { label: camAxisLabel('x', null), labelSize: 14, size: 30, stroke: '#4a5563', grid: { stroke: '#e6e9ee' }, ticks: { stroke: '#c9cfd6' } }
            : { stroke: '#4a5563', grid: { stroke: '#e6e9ee' }, ticks: { stroke: '#c9cfd6', size: 4 }, size: 6, values: (_u, splits) => splits.map(() => '') },
          { label: camAxisLabel(i, null), labelSize: 16, labelFont: '11px system-ui, sans-serif', stroke: CAM_COLORS[i], grid: { stroke: '#eef0f3' }, ticks: { stroke: '#c9cfd6' }, size: 56, space: i === 0 ? 30 : 18 },
        ],
        series: [{ label: 'master' }, { label: name, stroke: CAM_COLORS[i], width: 1.5 }],
        hooks: {
          draw: [(u) => this.drawMarks(u, i)],
          setCursor: i === 0 ? [(u) => this.showReadout(u.cursor.idx ?? null)] : [],
        },
      };
      this.panes.push(new uPlot(opts, [[], []], box));
    });
    el.dataset.series = NAMES.join(',');
    el.dataset.samples = '0';
    this.handleBox = this.panes[0].over;
    this.ro = followWidth(el, () => this.panes, (i) => this.height(i));
  }

  private width(): number {
    return paneWidth(this.el);
  }

  private height(i: number): number {
    const small = narrowPanes(this.el);
    return i === 0 ? (small ? 200 : 250) : small ? 96 : 120;
  }

  /** Auto range of a pane; the position pane also holds the handles, and stays put while dragging. */
  private yRange(i: number, min: number, max: number): [number, number] {
    if (i === 0 && this.frozen) return this.frozen.y;
    if (i === 0)
      for (const h of this.handles) {
        min = Math.min(min, h.slave);
        max = Math.max(max, h.slave);
      }
    if (!Number.isFinite(min) || !Number.isFinite(max)) return [0, 1];
    const r = uPlot.rangeNum(min, max, 0.1, true);
    return [r[0] ?? min, r[1] ?? max];
  }

  /** New values (`columns`: master, position, velocity, acceleration, jerk) over [start, end]. */
  setData(rows: number[][], start: number, end: number, discontinuities: number[] = []): void {
    this.range = end > start ? [start, end] : [start, start + 1];
    this.marks = discontinuities;
    const x = rows.map((r) => r[0]);
    this.panes.forEach((u, i) => u.setData([x, rows.map((r) => r[i + 1])], !this.frozen));
    this.el.dataset.samples = String(x.length);
    this.place();
  }

  /**
   * The units of the axes: a coupled slave's (position) per its master's (the master axis); null
   * while no axis is coupled through the table. `data-units` says them for the tests.
   */
  setUnits(units: CamUnits | null): void {
    if (this.units?.master === units?.master && this.units?.slave === units?.slave) return;
    this.units = units;
    this.panes.forEach((u, i) => {
      u.axes[1].label = camAxisLabel(i, units);
      if (i === this.panes.length - 1) u.axes[0].label = camAxisLabel('x', units);
      u.redraw(false, true);
    });
    this.el.dataset.units = units ? `${units.master}|${units.slave}` : '';
  }

  /** Where the slaves coupled through the table are on it now (live, MC_CamInfo). */
  setMarkers(markers: CamChartMarker[]): void {
    this.markers = markers;
    this.placeMarkers();
    // the master position on the other plots: a line, drawn with the marks
    this.panes.slice(1).forEach((u) => u.redraw(false, false));
  }

  /** Puts the marker elements (a dot and the slave's name) where the slaves are. */
  private placeMarkers(): void {
    const make = () => {
      const m = document.createElement('div');
      m.className = 'cam-marker';
      m.appendChild(document.createElement('span'));
      return m;
    };
    this.placeAll('cam-marker', this.markers, make, (m, p) => {
      this.putAt(m, p.x, p.y);
      m.dataset.axis = p.axis;
      m.title = `${p.axis} now: master ${fmt(p.x)}, slave ${fmt(p.y)} (table coordinates)`;
      m.firstElementChild!.textContent = p.axis;
    });
  }

  /** One element of class `cls` per item in the position pane, made by `make`, set by `set`. */
  private placeAll<T>(cls: string, items: T[], make: () => HTMLElement, set: (el: HTMLElement, item: T) => void): void {
    const box = this.handleBox;
    if (!box) return;
    const els = [...box.querySelectorAll<HTMLElement>(`.${cls}`)];
    while (els.length > items.length) els.pop()!.remove();
    while (els.length < items.length) {
      const el = make();
      box.appendChild(el);
      els.push(el);
    }
    items.forEach((item, k) => set(els[k], item));
  }

  /** An element of the position pane at (master, slave), hidden outside the plot; both values as data attributes. */
  private putAt(el: HTMLElement, master: number, slave: number): void {
    const u = this.panes[0];
    const box = this.handleBox!;
    const left = u.valToPos(master, 'x');
    const top = u.valToPos(slave, 'y');
    const inside = Number.isFinite(left) && Number.isFinite(top) && left >= -0.5 && left <= box.clientWidth + 0.5 && top >= -0.5 && top <= box.clientHeight + 0.5;
    el.dataset.master = String(master);
    el.dataset.slave = String(slave);
    el.style.left = `${left}px`;
    el.style.top = `${top}px`;
    el.style.display = inside ? '' : 'none';
  }

  /** The points to drag (and the ones with a warning). */
  setHandles(handles: Handle[], warn: Set<number> = new Set()): void {
    this.handles = handles;
    this.warn = warn;
    // the position scale holds the handles too: ranged again unless a drag holds it
    if (!this.frozen) this.panes[0].setData(this.panes[0].data, true);
    this.place();
    if (this.panes[0].cursor.idx == null) this.showReadout(null);
  }

  /** Canvas position → values of the position pane (for a drag). */
  private valuesAt(clientX: number, clientY: number): { master: number; slave: number } {
    const u = this.panes[0];
    const r = u.over.getBoundingClientRect();
    const x = Math.min(r.width, Math.max(0, clientX - r.left));
    const y = Math.min(r.height, Math.max(0, clientY - r.top));
    return { master: u.posToVal(x, 'x'), slave: u.posToVal(y, 'y') };
  }

  /** Puts the handle elements where their points are. */
  private place(): void {
    const make = () => {
      const h = document.createElement('div');
      h.className = 'cam-handle';
      h.tabIndex = -1;
      this.grab(h);
      return h;
    };
    this.placeAll('cam-handle', this.handles, make, (h, p) => {
      this.putAt(h, p.master, p.slave);
      h.dataset.handle = String(p.index);
      h.title = `point ${p.index + 1}: master ${p.master}, slave ${p.slave} — drag to move it`;
      h.classList.toggle('warn', this.warn.has(p.index));
      h.classList.toggle('dragging', this.dragging === p.index);
    });
  }

  /** Pointer handling of a handle: one drag from pointerdown to pointerup (captured). */
  private grab(h: HTMLElement): void {
    const index = () => Number(h.dataset.handle);
    h.addEventListener('pointerdown', (e) => {
      if (e.button !== 0) return;
      e.preventDefault();
      e.stopPropagation();
      h.setPointerCapture?.(e.pointerId);
      const u = this.panes[0];
      this.frozen = { x: [u.scales.x.min!, u.scales.x.max!], y: [u.scales.y.min!, u.scales.y.max!] };
      this.dragging = index();
      const p = this.handles.find((q) => q.index === this.dragging);
      if (p) this.cb.onDrag?.(this.dragging, p.master, p.slave, 'start');
      this.place();
    });
    h.addEventListener('pointermove', (e) => {
      if (this.dragging === null || this.dragging !== index()) return;
      e.preventDefault();
      const v = this.valuesAt(e.clientX, e.clientY);
      this.cb.onDrag?.(this.dragging, v.master, v.slave, 'move');
    });
    const end = () => {
      if (this.dragging === null) return;
      const i = this.dragging;
      this.dragging = null;
      this.frozen = null;
      // the drag ends where its last move took it (a click without a move changes nothing)
      const p = this.handles.find((q) => q.index === i);
      this.cb.onDrag?.(i, p?.master ?? NaN, p?.slave ?? NaN, 'end');
      this.panes.forEach((u) => u.setData(u.data, true));
      this.place();
    };
    h.addEventListener('pointerup', end);
    h.addEventListener('pointercancel', end);
  }

  private drawMarks(u: uPlot, i: number): void {
    if (i === 0) {
      this.place();
      this.placeMarkers();
    }
    const ctx = u.ctx;
    if (i > 0 && this.markers.length) {
      // where the coupled slaves' master is on the table: a line through the other plots
      ctx.save();
      ctx.strokeStyle = '#e03131';
      ctx.lineWidth = uPlot.pxRatio;
      for (const m of this.markers) {
        const x = Math.round(u.valToPos(m.x, 'x', true));
        if (x < u.bbox.left || x > u.bbox.left + u.bbox.width) continue;
        ctx.beginPath();
        ctx.moveTo(x, u.bbox.top);
        ctx.lineTo(x, u.bbox.top + u.bbox.height);
        ctx.stroke();
      }
      ctx.restore();
    }
    if (!this.marks.length) return;
    ctx.save();
    ctx.strokeStyle = '#d32f2f';
    ctx.lineWidth = uPlot.pxRatio;
    ctx.setLineDash([4 * uPlot.pxRatio, 3 * uPlot.pxRatio]);
    for (const m of this.marks) {
      const x = Math.round(u.valToPos(m, 'x', true));
      ctx.beginPath();
      ctx.moveTo(x, u.bbox.top);
      ctx.lineTo(x, u.bbox.top + u.bbox.height);
      ctx.stroke();
    }
    ctx.restore();
  }

  private showReadout(idx: number | null): void {
    const d = this.panes[0]?.data;
    if (idx === null || !d || d[0][idx] === undefined) {
      this.readout.textContent = this.handles.length ? 'Drag a point of the position plot to move it.' : '\u00a0';
      return;
    }
    const parts = [`master ${fmt(d[0][idx])}`, ...this.panes.map((u, i) => `${NAMES[i]} ${fmt(u.data[1]?.[idx] as number)}`)];
    this.readout.textContent = parts.join(' · ');
  }

  destroy(): void {
    this.ro?.disconnect();
    this.panes.forEach((u) => u.destroy());
    this.panes = [];
    this.el.replaceChildren();
  }
}

const fmt = (v: number | null | undefined) => (v === null || v === undefined || !Number.isFinite(v) ? '—' : String(Number(v.toPrecision(5))));
