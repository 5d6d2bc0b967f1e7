// uPlot wrapper for scope recordings: one y scale per unit, drag-select zoom, wheel zoom,
// pan (shift-drag or middle-drag, or a sideways swipe on a touch screen), two cursors placed
// by clicking or tapping (alternating C1/C2). The element carries what is drawn as data
// attributes (`data-samples`, `data-series`, `data-view` = "min,max" of t) for the tests.
import uPlot from 'uplot';
import { panRange, zoomRange } from './data';

export const COLORS = ['#1363c6', '#d9480f', '#2b8a3e', '#ae3ec9', '#e67700', '#0b7285', '#c92a2a', '#5c5f66'];

export interface ChartSeries {
  label: string;
  unit: string;
  scale: string;
  values: ArrayLike<number | null>;
  /** Colour (default: by index). */
  color?: string;
  /** Dashed (the second recording of a comparison). */
  dash?: boolean;
  /** Join across nulls (a comparison's union of sample times); default: nulls are breaks (gaps). */
  spanGaps?: boolean;
}

/** How one chart of a stack is drawn. */
export interface PaneOptions {
  /** uPlot cursor sync key: the hover cursor moves in every chart of the stack. */
  syncKey?: string;
  /** Draw the time axis' labels (only the bottom chart of a stack). */
  showX?: boolean;
  height?: number;
  /** The x range (full view); default: the first and last t. */
  limits?: { min: number; max: number };
  /** Extra space (px) left and right so the plots of a stack line up. */
  padLeft?: number;
  padRight?: number;
}

/** Width of a y axis with its unit label (size + label). */
export const Y_AXIS_WIDTH = 94;

export interface ChartCallbacks {
  onCursors: (c1: number | null, c2: number | null) => void;
  onRange: (min: number, max: number) => void;
}

export class ScopeChart {
  private u: uPlot;
  private c1: number | null = null;
  private c2: number | null = null;
  private next: 1 | 2 = 1;
  private limits: { min: number; max: number };
  private ro: ResizeObserver | null = null;
  private onMove: (e: MouseEvent) => void = () => {};
  private onUp: (e: MouseEvent) => void = () => {};

  constructor(
    private readonly el: HTMLElement,
    t: ArrayLike<number>,
    series: ChartSeries[],
    private readonly cb: ChartCallbacks,
    /** Draw the trigger: a line at t = 0 and the level on the trigger channel's scale. */
    private readonly trigger: { scale: string; level: number } | null = null,
    pane: PaneOptions = {},
  ) {
    const n = t.length;
    this.limits = pane.limits ? { ...pane.limits } : { min: n ? t[0] : 0, max: n ? t[n - 1] : 1 };
    if (this.limits.max <= this.limits.min) this.limits.max = this.limits.min + 1e-3;
    const scales: uPlot.Scales = { x: { time: false, min: this.limits.min, max: this.limits.max } };
    const showX = pane.showX ?? true;
    const axes: uPlot.Axis[] = [
      showX
        ? { label: 't (s)', stroke: '#4a5563', grid: { stroke: '#e6e9ee' }, ticks: { stroke: '#c9cfd6' } }
        : { stroke: '#4a5563', grid: { stroke: '#e6e9ee' }, ticks: { stroke: '#c9cfd6', size: 4 }, size: 6, values: (_u, splits) => splits.map(() => '') },
    ];
    const seen: string[] = [];
    series.forEach((s) => {
      if (seen.includes(s.scale)) return;
      seen.push(s.scale);
      scales[s.scale] = { auto: true };
      axes.push({
        scale: s.scale,
        label: s.unit,
        side: seen.length % 2 === 1 ? 3 : 1,
        stroke: '#4a5563',
        grid: { show: seen.length === 1, stroke: '#eef0f3' },
        ticks: { stroke: '#c9cfd6' },
        size: 64,
      });
    });
    const opts: uPlot.Options = {
      width: Math.max(300, el.clientWidth),
      height: pane.height ?? Math.max(220, el.clientHeight || 420),
      padding: [null, pane.padRight ? pane.padRight + 8 : null, null, pane.padLeft ? pane.padLeft + 8 : null],
      scales,
      axes,
      legend: { show: true, live: true },
      cursor: {
        drag: { x: true, y: false, setScale: true },
        points: { show: false },
        ...(pane.syncKey ? { sync: { key: pane.syncKey, setSeries: false, scales: ['x', null] as [string, null] } } : {}),
      },
      series: [
        { label: 't (s)', value: (_u, v) => (v === null || v === undefined ? '—' : v.toFixed(4)) },
        ...series.map((s, i) => ({
          label: `${s.label} (${s.unit})`,
          scale: s.scale,
          stroke: s.color ?? COLORS[i % COLORS.length],
          width: 1.5,
          dash: s.dash ? [6, 4] : undefined,
          spanGaps: s.spanGaps ?? false,
          value: (_u: uPlot, v: number | null) => (v === null || v === undefined ? '—' : String(Number(v.toPrecision(6)))),
        })),
      ],
      hooks: {
        draw: [(u) => this.drawCursors(u)],
        setScale: [
          (u, key) => {
            if (key !== 'x') return;
            const min = u.scales.x.min ?? 0;
            const max = u.scales.x.max ?? 0;
            this.el.dataset.view = `${min},${max}`;
            this.cb.onRange(min, max);
          },
        ],
      },
    };
    const data = [Array.from(t), ...series.map((s) => Array.from(s.values))] as uPlot.AlignedData;
    this.u = new uPlot(opts, data, el);
    el.dataset.samples = String(n);
    el.dataset.series = String(series.length);
    this.installInteractions();
    if (typeof ResizeObserver !== 'undefined') {
      this.ro = new ResizeObserver(() => this.resize());
      this.ro.observe(el);
    }
  }

  /** New values for the same series (a live trace growing); the view stays where it is. */
  setData(t: ArrayLike<number>, values: ArrayLike<number | null>[]): void {
    const r = this.range();
    this.u.setData([Array.from(t), ...values.map((v) => Array.from(v))] as uPlot.AlignedData, true);
    this.u.setScale('x', r);
    this.el.dataset.samples = String(t.length);
  }

  private resize(): void {
    const w = Math.max(300, this.el.clientWidth);
    if (Math.abs(w - this.u.width) > 2) this.u.setSize({ width: w, height: this.u.height });
  }

  private range(): { min: number; max: number } {
    return { min: this.u.scales.x.min ?? this.limits.min, max: this.u.scales.x.max ?? this.limits.max };
  }

  private setRange(r: { min: number; max: number }): void {
    this.u.setScale('x', r);
  }

  zoom(factor: number, at?: number): void {
    const r = this.range();
    this.setRange(zoomRange(r, at ?? (r.min + r.max) / 2, factor, this.limits));
  }

  pan(fraction: number): void {
    const r = this.range();
    this.setRange(panRange(r, (r.max - r.min) * fraction, this.limits));
  }

  reset(): void {
    this.setRange({ ...this.limits });
  }

  /** Cursors placed in another chart of the stack (no callback). */
  syncCursors(c1: number | null, c2: number | null, next: 1 | 2): void {
    this.c1 = c1;
    this.c2 = c2;
    this.next = next;
    this.u.redraw(false, false);
  }

  get nextCursor(): 1 | 2 {
    return this.next;
  }

  /** The x range from another chart of the stack. */
  syncRange(r: { min: number; max: number }): void {
    const cur = this.range();
    if (Math.abs(cur.min - r.min) < 1e-12 && Math.abs(cur.max - r.max) < 1e-12) return;
    this.u.setScale('x', r);
  }

  get cursors(): [number | null, number | null] {
    return [this.c1, this.c2];
  }

  setCursor(which: 1 | 2, x: number | null): void {
    if (which === 1) this.c1 = x;
    else this.c2 = x;
    this.u.redraw(false, false);
    this.cb.onCursors(this.c1, this.c2);
  }

  clearCursors(): void {
    this.c1 = this.c2 = null;
    this.next = 1;
    this.u.redraw(false, false);
    this.cb.onCursors(null, null);
  }

  private installInteractions(): void {
    const over = this.u.over;
    over.addEventListener(
      'wheel',
      (e) => {
        e.preventDefault();
        const x = this.u.posToVal(e.offsetX, 'x');
        this.zoom(e.deltaY < 0 ? 0.8 : 1.25, x);
      },
      { passive: false },
    );
    let down: { x: number; y: number; pan: boolean; min: number; max: number } | null = null;
    over.addEventListener(
      'mousedown',
      (e) => {
        const pan = e.shiftKey || e.button === 1;
        const r = this.range();
        down = { x: e.clientX, y: e.clientY, pan, ...r };
        if (pan) {
          e.preventDefault();
          e.stopPropagation(); // no drag-select while panning
        }
      },
      true,
    );
    this.onMove = (e: MouseEvent) => {
      if (!down || !down.pan) return;
      const pxPerS = this.u.bbox.width / devicePixelRatio / (down.max - down.min);
      const dx = -(e.clientX - down.x) / pxPerS;
      this.setRange(panRange({ min: down.min, max: down.max }, dx, this.limits));
    };
    this.onUp = (e: MouseEvent) => {
      const d = down;
      down = null;
      if (!d || d.pan) return;
      if (Math.abs(e.clientX - d.x) < 4 && Math.abs(e.clientY - d.y) < 4) {
        const rect = over.getBoundingClientRect();
        const x = this.u.posToVal(e.clientX - rect.left, 'x');
        const which = this.next;
        this.next = this.next === 1 ? 2 : 1;
        this.setCursor(which, x);
      }
    };
    window.addEventListener('mousemove', this.onMove);
    window.addEventListener('mouseup', this.onUp);
    over.addEventListener('dblclick', () => this.reset());
    // Touch: a sideways swipe pans (vertical ones still scroll the page: touch-action pan-y);
    // a tap arrives as a click and places a cursor; zoom with the toolbar's buttons.
    let swipe: { id: number; x: number; min: number; max: number } | null = null;
    over.addEventListener('pointerdown', (e) => {
      if (e.pointerType === 'touch') swipe = { id: e.pointerId, x: e.clientX, ...this.range() };
    });
    over.addEventListener('pointermove', (e) => {
      if (!swipe || e.pointerId !== swipe.id) return;
      const pxPerS = this.u.bbox.width / devicePixelRatio / (swipe.max - swipe.min);
      this.setRange(panRange({ min: swipe.min, max: swipe.max }, -(e.clientX - swipe.x) / pxPerS, this.limits));
    });
    const endSwipe = () => {
      swipe = null;
    };
    over.addEventListener('pointerup', endSwipe);
    over.addEventListener('pointercancel', endSwipe);
  }

  private drawCursors(u: uPlot): void {
    const ctx = u.ctx;
    const { top, height } = u.bbox;
    const draw = (x: number | null, label: string, color: string) => {
      if (x === null) return;
      const px = u.valToPos(x, 'x', true);
      if (px < u.bbox.left || px > u.bbox.left + u.bbox.width) return;
      ctx.save();
      ctx.strokeStyle = color;
      ctx.lineWidth = 1.5 * devicePixelRatio;
      ctx.setLineDash([6 * devicePixelRatio, 4 * devicePixelRatio]);
      ctx.beginPath();
      ctx.moveTo(px, top);
      ctx.lineTo(px, top + height);
      ctx.stroke();
      ctx.setLineDash([]);
      ctx.fillStyle = color;
      ctx.font = `${11 * devicePixelRatio}px system-ui, sans-serif`;
      ctx.fillText(label, px + 4 * devicePixelRatio, top + 12 * devicePixelRatio);
      ctx.restore();
    };
    if (this.trigger) {
      const px = u.valToPos(0, 'x', true);
      const py = u.valToPos(this.trigger.level, this.trigger.scale, true);
      ctx.save();
      ctx.strokeStyle = '#2b8a3e';
      ctx.fillStyle = '#2b8a3e';
      ctx.lineWidth = 1 * devicePixelRatio;
      ctx.setLineDash([2 * devicePixelRatio, 3 * devicePixelRatio]);
      if (px >= u.bbox.left && px <= u.bbox.left + u.bbox.width) {
        ctx.beginPath();
        ctx.moveTo(px, top);
        ctx.lineTo(px, top + height);
        ctx.stroke();
        ctx.font = `${11 * devicePixelRatio}px system-ui, sans-serif`;
        ctx.fillText('T', px + 3 * devicePixelRatio, top + height - 4 * devicePixelRatio);
      }
      if (Number.isFinite(py) && py >= top && py <= top + height) {
        ctx.beginPath();
        ctx.moveTo(u.bbox.left, py);
        ctx.lineTo(u.bbox.left + u.bbox.width, py);
        ctx.stroke();
      }
      ctx.restore();
    }
    draw(this.c1, 'C1', '#111827');
    draw(this.c2, 'C2', '#b91c1c');
  }

  destroy(): void {
    this.ro?.disconnect();
    delete this.el.dataset.samples;
    delete this.el.dataset.series;
    delete this.el.dataset.view;
    window.removeEventListener('mousemove', this.onMove);
    window.removeEventListener('mouseup', this.onUp);
    this.u.destroy();
  }
}

/** One pane of a stack: its series and (optionally) the trigger to draw. */
export interface StackPane {
  series: ChartSeries[];
  trigger?: { scale: string; level: number } | null;
}

/**
 * Charts stacked vertically with one shared time axis (labelled under the bottom one): the
 * hover cursor (uPlot's cursor sync), zoom/pan and the two cursors C1/C2 are the same in all.
 * The container carries `data-samples`, `data-series` (all panes), `data-charts` and
 * `data-view` for the tests.
 */
let stackNo = 0;
export class ScopeStack {
  readonly charts: ScopeChart[] = [];
  private syncing = false;

  constructor(
    private readonly el: HTMLElement,
    t: ArrayLike<number>,
    panes: StackPane[],
    cb: ChartCallbacks,
    opts: { limits?: { min: number; max: number }; height?: number } = {},
  ) {
    const key = `scope-stack-${++stackNo}`;
    const sides = panes.map((p) => {
      const scales = [...new Set(p.series.map((s) => s.scale))];
      return { left: Math.ceil(scales.length / 2), right: Math.floor(scales.length / 2) };
    });
    const maxLeft = Math.max(0, ...sides.map((s) => s.left));
    const maxRight = Math.max(0, ...sides.map((s) => s.right));
    const total = opts.height ?? 420;
    const each = panes.length <= 1 ? total : Math.max(150, Math.round(total / panes.length));
    panes.forEach((p, i) => {
      const div = document.createElement('div');
      div.className = 'chart-pane';
      div.dataset.chart = String(i);
      el.appendChild(div);
      const last = i === panes.length - 1;
      const chart: ScopeChart = new ScopeChart(
        div,
        t,
        p.series,
        {
          onCursors: (c1, c2) => {
            if (!this.syncing) {
              this.syncing = true;
              for (const o of this.charts) if (o !== chart) o.syncCursors(c1, c2, chart.nextCursor);
              this.syncing = false;
            }
            cb.onCursors(c1, c2);
          },
          onRange: (min, max) => {
            this.el.dataset.view = `${min},${max}`;
            if (!this.syncing) {
              this.syncing = true;
              for (const o of this.charts) if (o !== chart) o.syncRange({ min, max });
              this.syncing = false;
            }
            cb.onRange(min, max);
          },
        },
        p.trigger ?? null,
        {
          syncKey: key,
          showX: last,
          height: last && panes.length > 1 ? each + 40 : each,
          limits: opts.limits,
          padLeft: (maxLeft - sides[i].left) * Y_AXIS_WIDTH,
          padRight: (maxRight - sides[i].right) * Y_AXIS_WIDTH,
        },
      );
      this.charts.push(chart);
    });
    el.dataset.samples = String(t.length);
    el.dataset.series = String(panes.reduce((a, p) => a + p.series.length, 0));
    el.dataset.charts = String(panes.length);
    const first = this.charts[0];
    if (first) {
      const r = opts.limits ?? { min: t.length ? t[0] : 0, max: t.length ? t[t.length - 1] : 1 };
      el.dataset.view = `${r.min},${r.max}`;
    }
  }

  /** New values for the panes' series, pane by pane in their order (a live trace growing). */
  setData(t: ArrayLike<number>, panes: ArrayLike<number | null>[][]): void {
    this.charts.forEach((c, i) => c.setData(t, panes[i] ?? []));
    this.el.dataset.samples = String(t.length);
  }

  zoom(factor: number): void {
    this.charts[0]?.zoom(factor);
  }
  pan(fraction: number): void {
    this.charts[0]?.pan(fraction);
  }
  reset(): void {
    this.charts[0]?.reset();
  }
  clearCursors(): void {
    this.syncing = true;
    for (const c of this.charts.slice(1)) c.syncCursors(null, null, 1);
    this.syncing = false;
    this.charts[0]?.clearCursors();
  }

  destroy(): void {
    for (const c of this.charts) c.destroy();
    this.charts.length = 0;
    this.el.replaceChildren();
    delete this.el.dataset.samples;
    delete this.el.dataset.series;
    delete this.el.dataset.charts;
    delete this.el.dataset.view;
  }
}
