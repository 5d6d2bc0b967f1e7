// The path editor's plan from the server: the rows as edited are posted to
// `POST /path-analysis` (debounced, the latest answer counts: cams/analysis.ts's LiveAnalysis),
// which runs them on the group's own planner in virtual time; the answer is the planned trace
// (machine coordinates, corner blends as planned) and the path's and every axis's dynamics over
// time. Here: the body, the answer as path points for the canvas and as columns for the charts,
// and the live run mapped onto the plan's time. No UI code, no global state.
import type { GroupRole, PathAnalysisBody, PathAnalysisResource } from '../api/types';
import { PATH_DIMS, type PathPoint } from './geometry';
import { movePathBody, roleDim, type PathRow } from './rows';

/** The body of an analysis of `rows` for `group` from `start` (a path point; null: where the group is). */
export function analysisBody(group: string, rows: PathRow[], roles: GroupRole[], start: PathPoint | null, maxSamples = 2000): PathAnalysisBody {
  const body: PathAnalysisBody = { group, entries: movePathBody(rows).entries, max_samples: maxSamples };
  if (start) body.start = Object.fromEntries(roles.map((r) => [r, start[roleDim(r)] ?? 0]));
  return body;
}

/** The planned trace as the view draws it: a path point per sample, and its entry and blend flag. */
export interface PlannedTrace {
  points: PathPoint[];
  entry: number[];
  inBlend: boolean[];
  start: PathPoint;
  length: number;
  duration: number;
  truncated: boolean;
}

export function plannedTrace(p: PathAnalysisResource): PlannedTrace {
  const n = p.t.length;
  const points: PathPoint[] = Array.from({ length: n }, () => new Array<number>(PATH_DIMS).fill(0));
  const start = new Array<number>(PATH_DIMS).fill(0);
  for (const a of p.axes) {
    const d = roleDim(a.role);
    if (d < 0) continue;
    for (let i = 0; i < n; i++) points[i][d] = a.position[i];
    start[d] = p.start[a.role] ?? 0;
  }
  // The samples begin one cycle after the start: the start is drawn as the trace's first point.
  return { points: [start, ...points], entry: [p.entry[0] ?? 0, ...p.entry], inBlend: [false, ...p.in_blend], start, length: p.length, duration: p.duration, truncated: p.truncated };
}

/**
 * The pieces of a trace to draw in one style: runs of samples of one entry and blend state, as
 * index ranges [from, to] (to inclusive); each piece begins at the last point of the one before,
 * so the line has no gap.
 */
export function tracePieces(t: Pick<PlannedTrace, 'entry' | 'inBlend'>): { from: number; to: number; entry: number; blend: boolean }[] {
  const out: { from: number; to: number; entry: number; blend: boolean }[] = [];
  for (let i = 0; i < t.entry.length; i++) {
    const last = out[out.length - 1];
    if (last && last.entry === t.entry[i] && last.blend === t.inBlend[i]) last.to = i;
    else out.push({ from: last ? last.to : i, to: i, entry: t.entry[i], blend: t.inBlend[i] });
  }
  return out;
}

/** Times (s) where the running entry changes, with the entry that begins there (for the charts' marks). */
export function entryChanges(p: PathAnalysisResource): { t: number; entry: number }[] {
  const out: { t: number; entry: number }[] = [];
  for (let i = 1; i < p.entry.length; i++) if (p.entry[i] !== p.entry[i - 1]) out.push({ t: p.t[i], entry: p.entry[i] });
  return out;
}

/** The intervals (s) in which a corner blend runs. */
export function blendIntervals(p: PathAnalysisResource): [number, number][] {
  const out: [number, number][] = [];
  let from: number | null = null;
  p.in_blend.forEach((b, i) => {
    if (b && from === null) from = p.t[i];
    if (!b && from !== null) {
      out.push([from, p.t[i]]);
      from = null;
    }
  });
  if (from !== null) out.push([from, p.t[p.t.length - 1]]);
  return out;
}

/** "planned 314.16 in 0.472 s" — the summary under the view. */
export function planText(p: { length: number; duration: number; truncated: boolean }): string {
  const len = p.length.toFixed(2);
  return p.truncated ? `planned ${len} in the first ${p.duration.toFixed(3)} s (not ended: longer than analysed)` : `planned length ${len}, duration ${p.duration.toFixed(3)} s`;
}

/** A live run's samples against the plan: time since the run began (s) and path velocity. */
export class LiveRun {
  private c0: number | null = null;
  private cycleTime = 0.001;
  readonly t: number[] = [];
  readonly v: number[] = [];
  constructor(private readonly max = 20000) {}
  /** Starts a run whose first cycle is after `cycle` (the status when it was sent), cycles of `cycleTime` s. */
  begin(cycle: number, cycleTime: number): void {
    this.c0 = cycle;
    this.cycleTime = cycleTime;
    this.t.length = 0;
    this.v.length = 0;
  }
  get running(): boolean {
    return this.c0 !== null;
  }
  push(cycle: number, pathVelocity: number): void {
    if (this.c0 === null || cycle < this.c0) return;
    const t = (cycle - this.c0) * this.cycleTime;
    if (this.t.length && t <= this.t[this.t.length - 1]) return;
    this.t.push(t);
    this.v.push(pathVelocity);
    if (this.t.length > this.max) {
      this.t.splice(0, this.t.length - this.max);
      this.v.splice(0, this.v.length - this.max);
    }
  }
  clear(): void {
    this.c0 = null;
    this.t.length = 0;
    this.v.length = 0;
  }
}
