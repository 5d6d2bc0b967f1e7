// The live XY (XZ, YZ) view of a group's path on a canvas: the path as the server plans it
// (plan.ts: the sampled trace, corner blends in their own colour), the programmed geometry
// faintly beneath it (points, lines, arcs, corner tolerance circles: geometry.ts), and the live
// trace of the members' actual positions drawn over the plan while it runs, on one scale for both
// axes (a circle stays round, which uPlot's independent scales would not keep), with a grid of
// round numbers. Drawing only: the data come from geometry.ts, plan.ts and the trace buffer
// below. No UI framework, no global state.
import type { Preview } from './geometry';
import { tracePieces, type PlannedTrace } from './plan';

/** Which plane: the path-point dims on the horizontal and the vertical axis. */
export interface Plane {
  name: string;
  h: number;
  v: number;
  hLabel: string;
  vLabel: string;
}
export const XY: Plane = { name: 'xy', h: 0, v: 1, hLabel: 'X', vLabel: 'Y' };
export const XZ: Plane = { name: 'xz', h: 0, v: 2, hLabel: 'X', vLabel: 'Z' };
export const YZ: Plane = { name: 'yz', h: 1, v: 2, hLabel: 'Y', vLabel: 'Z' };

/** A bounded buffer of path points (the live trace), cleared when a new run starts. */
export class TraceBuffer {
  private pts: number[][] = [];
  constructor(private readonly max = 20000) {}
  push(p: number[]): void {
    const last = this.pts[this.pts.length - 1];
    if (last && last.every((x, i) => x === p[i])) return;
    this.pts.push(p);
    if (this.pts.length > this.max) this.pts.splice(0, this.pts.length - this.max);
  }
  clear(): void {
    this.pts = [];
  }
  get points(): readonly number[][] {
    return this.pts;
  }
}

export interface ViewData {
  preview: Preview | null;
  /** The server's plan of the rows (null: none yet, or refused). */
  plan?: PlannedTrace | null;
  trace: readonly number[][];
  /** The group's position now (path point), drawn as a dot. */
  now: number[] | null;
  /** The entry running (highlighted), −1 none. */
  activeEntry: number;
  /** The row selected in the editor (its points emphasised), −1 none. */
  selectedEntry: number;
  /** Dimmed: the preview is of rows the server has not seen (or the status is stale). */
  dim?: boolean;
}

export const VIEW_COLORS = { path: '#1363c6', active: '#2b8a3e', arc: '#1363c6', point: '#1b2a3a', corner: '#ae3ec9', blend: '#ae3ec9', programmed: '#9aa5b1', trace: '#e8590c', now: '#d9480f', grid: '#e3e8ee', axis: '#8a96a3', error: '#c92a2a' };

/** A round step (1, 2, 5 × 10ⁿ) that gives about `n` grid lines over `span`. */
export function niceStep(span: number, n: number): number {
  if (!(span > 0)) return 1;
  const raw = span / n;
  const p = 10 ** Math.floor(Math.log10(raw));
  const m = raw / p;
  return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p;
}

/** The bounds of what is drawn in a plane, widened to a non-empty box. */
export function bounds(d: ViewData, plane: Plane): [number, number, number, number] {
  let [x0, y0, x1, y1] = [Infinity, Infinity, -Infinity, -Infinity];
  const see = (p: number[], r = 0) => {
    const x = p[plane.h] ?? 0;
    const y = p[plane.v] ?? 0;
    if (!Number.isFinite(x) || !Number.isFinite(y)) return;
    x0 = Math.min(x0, x - r);
    x1 = Math.max(x1, x + r);
    y0 = Math.min(y0, y - r);
    y1 = Math.max(y1, y + r);
  };
  if (d.preview) {
    see(d.preview.start);
    for (const s of d.preview.segments) for (const p of s.points) see(p);
    for (const c of d.preview.corners) see(c.at, Math.max(Number.isFinite(c.rIn) ? c.rIn : 0, Number.isFinite(c.rOut) ? c.rOut : 0));
  }
  for (const p of d.plan?.points ?? []) see(p);
  for (const p of d.trace) see(p);
  if (d.now) see(d.now);
  if (!Number.isFinite(x0)) return [-10, -10, 10, 10];
  const span = Math.max(x1 - x0, y1 - y0, 1e-6);
  const pad = span * 0.08 + 1e-9;
  return [x0 - pad, y0 - pad, x1 + pad, y1 + pad];
}

/** Draws the view into `ctx` of CSS size w × h (device pixels already scaled by the caller). */
export function drawView(ctx: CanvasRenderingContext2D, w: number, h: number, d: ViewData, plane: Plane): void {
  ctx.clearRect(0, 0, w, h);
  const m = { l: 48, r: 10, t: 10, b: 28 };
  const pw = Math.max(10, w - m.l - m.r);
  const ph = Math.max(10, h - m.t - m.b);
  let [x0, y0, x1, y1] = bounds(d, plane);
  // One scale for both axes: the box widened along the shorter way.
  const k = Math.min(pw / (x1 - x0), ph / (y1 - y0));
  const cx = (x0 + x1) / 2;
  const cy = (y0 + y1) / 2;
  x0 = cx - pw / k / 2;
  x1 = cx + pw / k / 2;
  y0 = cy - ph / k / 2;
  y1 = cy + ph / k / 2;
  const X = (x: number) => m.l + (x - x0) * k;
  const Y = (y: number) => m.t + ph - (y - y0) * k;

  // grid and labels
  ctx.font = '11px system-ui, sans-serif';
  ctx.lineWidth = 1;
  const step = niceStep(Math.max(x1 - x0, y1 - y0), 8);
  ctx.strokeStyle = VIEW_COLORS.grid;
  ctx.fillStyle = VIEW_COLORS.axis;
  const label = (v: number) => String(Number(v.toPrecision(6)));
  ctx.textAlign = 'center';
  ctx.textBaseline = 'top';
  for (let x = Math.ceil(x0 / step) * step; x <= x1; x += step) {
    ctx.beginPath();
    ctx.moveTo(X(x), m.t);
    ctx.lineTo(X(x), m.t + ph);
    ctx.stroke();
    ctx.fillText(label(x), X(x), m.t + ph + 4);
  }
  ctx.textAlign = 'right';
  ctx.textBaseline = 'middle';
  for (let y = Math.ceil(y0 / step) * step; y <= y1; y += step) {
    ctx.beginPath();
    ctx.moveTo(m.l, Y(y));
    ctx.lineTo(m.l + pw, Y(y));
    ctx.stroke();
    ctx.fillText(label(y), m.l - 4, Y(y));
  }
  ctx.textAlign = 'left';
  ctx.textBaseline = 'bottom';
  ctx.fillText(`${plane.hLabel} →`, m.l + pw - 30, m.t + ph - 2);
  ctx.textBaseline = 'top';
  ctx.fillText(`↑ ${plane.vLabel}`, m.l + 4, m.t + 2);
  ctx.strokeStyle = VIEW_COLORS.axis;
  ctx.strokeRect(m.l + 0.5, m.t + 0.5, pw, ph);

  ctx.save();
  ctx.beginPath();
  ctx.rect(m.l, m.t, pw, ph);
  ctx.clip();
  ctx.globalAlpha = d.dim ? 0.45 : 1;
  const p = d.preview;
  const plan = d.plan ?? null;
  const line = (pts: readonly number[][], from = 0, to = pts.length - 1) => {
    ctx.beginPath();
    for (let i = from; i <= to; i++) {
      const q = pts[i];
      if (i === from) ctx.moveTo(X(q[plane.h]), Y(q[plane.v]));
      else ctx.lineTo(X(q[plane.h]), Y(q[plane.v]));
    }
    ctx.stroke();
  };
  if (p) {
    // corner tolerance circles
    ctx.setLineDash([4, 3]);
    ctx.strokeStyle = VIEW_COLORS.corner;
    ctx.lineWidth = 1;
    for (const c of p.corners) {
      for (const r of c.rIn === c.rOut ? [c.rIn] : [c.rIn, c.rOut]) {
        if (!(r > 0)) continue;
        ctx.beginPath();
        ctx.arc(X(c.at[plane.h]), Y(c.at[plane.v]), r * k, 0, 2 * Math.PI);
        ctx.stroke();
      }
    }
    ctx.setLineDash([]);
    // programmed segments: the path itself when there is no plan, faint beneath the plan
    for (const s of p.segments) {
      if (plan) {
        ctx.strokeStyle = VIEW_COLORS.programmed;
        ctx.lineWidth = 1;
        ctx.setLineDash([3, 3]);
      } else {
        ctx.strokeStyle = s.entry === d.activeEntry ? VIEW_COLORS.active : VIEW_COLORS.path;
        ctx.lineWidth = s.entry === d.selectedEntry || s.entry === d.activeEntry ? 3 : 1.75;
      }
      line(s.points);
      ctx.setLineDash([]);
      if (s.centre) {
        ctx.fillStyle = plan ? VIEW_COLORS.programmed : VIEW_COLORS.path;
        const [a, b] = [X(s.centre[plane.h] ?? 0), Y(s.centre[plane.v] ?? 0)];
        ctx.fillRect(a - 1.5, b - 1.5, 3, 3);
      }
    }
  }
  if (plan && plan.points.length > 1) {
    // the server's plan: pieces of one entry and blend state, blends in their own colour, the
    // running or selected entry emphasised
    ctx.lineJoin = 'round';
    ctx.lineCap = 'round';
    for (const piece of tracePieces(plan)) {
      const e = piece.entry;
      ctx.strokeStyle = piece.blend ? VIEW_COLORS.blend : e === d.activeEntry ? VIEW_COLORS.active : VIEW_COLORS.path;
      ctx.lineWidth = piece.blend || e === d.selectedEntry || e === d.activeEntry ? 3.5 : 2.25;
      line(plan.points, piece.from, piece.to);
    }
  }
  if (p) {
    // programmed points with their row number
    ctx.lineWidth = 1;
    ctx.font = '11px system-ui, sans-serif';
    ctx.textAlign = 'left';
    ctx.textBaseline = 'bottom';
    const labelled = new Map<string, string[]>();
    for (const q of p.points) {
      const key = `${Math.round(X(q.at[plane.h]))},${Math.round(Y(q.at[plane.v]))}`;
      const text = q.entry < 0 ? 'start' : String(q.entry + 1);
      labelled.set(key, [...(labelled.get(key) ?? []), text]);
      ctx.fillStyle = q.entry === d.selectedEntry ? VIEW_COLORS.now : VIEW_COLORS.point;
      ctx.beginPath();
      ctx.arc(X(q.at[plane.h]), Y(q.at[plane.v]), q.entry < 0 ? 4 : 3, 0, 2 * Math.PI);
      ctx.fill();
    }
    ctx.fillStyle = VIEW_COLORS.point;
    for (const [key, texts] of labelled) {
      const [a, b] = key.split(',').map(Number);
      ctx.fillText(texts.join(', '), a + 5, b - 3);
    }
  }
  // the live trace, over the plan
  if (d.trace.length > 1) {
    ctx.save();
    ctx.globalAlpha = 0.9;
    ctx.strokeStyle = VIEW_COLORS.trace;
    ctx.lineWidth = 2;
    ctx.lineJoin = 'round';
    ctx.lineCap = 'round';
    line(d.trace);
    ctx.restore();
  }
  if (d.now && Number.isFinite(d.now[plane.h]) && Number.isFinite(d.now[plane.v])) {
    ctx.globalAlpha = 1;
    ctx.fillStyle = VIEW_COLORS.now;
    ctx.strokeStyle = '#fff';
    ctx.lineWidth = 1.5;
    ctx.beginPath();
    ctx.arc(X(d.now[plane.h]), Y(d.now[plane.v]), 5, 0, 2 * Math.PI);
    ctx.fill();
    ctx.stroke();
  }
  ctx.restore();
}
