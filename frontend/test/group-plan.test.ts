// The path editor's plan (groups/plan.ts): the analysis body from the rows, the server's answer
// as path points, pieces to draw, blend intervals and entry starts for the charts, the live run
// on the plan's time; and LiveAnalysis.cancel (an emptied editor drops answers still to come).
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { LiveAnalysis } from '../src/cams/analysis';
import type { PathAnalysisResource } from '../src/api/types';
import { LiveRun, analysisBody, blendIntervals, entryChanges, planText, plannedTrace, tracePieces } from '../src/groups/plan';
import { newRow } from '../src/groups/rows';

const plan = (): PathAnalysisResource => ({
  group: 'xy',
  cycle_time: 0.001,
  start: { x: 0, y: 5 },
  duration: 0.004,
  length: 12.5,
  truncated: false,
  t: [0.001, 0.002, 0.003, 0.004],
  path_position: [1, 2, 3, 4],
  path_velocity: [1, 2, 2, 0],
  path_acceleration: [0, 0, 0, 0],
  entry: [0, 0, 1, 1],
  in_blend: [false, true, true, false],
  axes: [
    { role: 'x', axis: 'x', position: [1, 2, 3, 4], velocity: [1, 1, 1, 0], acceleration: [0, 0, 0, 0], max_velocity: 1, max_acceleration: 0 },
    { role: 'y', axis: 'y', position: [5, 6, 7, 8], velocity: [1, 1, 1, 0], acceleration: [0, 0, 0, 0], max_velocity: 1, max_acceleration: 0 },
  ],
});

describe('the plan of the rows', () => {
  it('is asked for with the rows as move-path entries, from a start per role', () => {
    const r = newRow(2);
    r.position = ['10', '20'];
    r.velocity = '100';
    const start = [1, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0];
    const b = analysisBody('xy', [r], ['x', 'y'], start, 500);
    expect(b).toMatchObject({ group: 'xy', start: { x: 1, y: 2 }, max_samples: 500 });
    expect(b.entries[0]).toMatchObject({ type: 'linear', position: [10, 20], velocity: 100 });
    expect(analysisBody('xy', [r], ['x', 'y'], null).start).toBeUndefined();
  });

  it('is drawn from its start through every sample, in the kernel layout', () => {
    const t = plannedTrace(plan());
    expect(t.points).toHaveLength(5);
    expect(t.points[0].slice(0, 3)).toEqual([0, 5, 0]);
    expect(t.points[4].slice(0, 2)).toEqual([4, 8]);
    expect(t.entry).toEqual([0, 0, 0, 1, 1]);
    expect(t.inBlend).toEqual([false, false, true, true, false]);
    expect(t.length).toBe(12.5);
  });

  it('in pieces of one entry and blend state that join without gaps', () => {
    expect(tracePieces(plannedTrace(plan()))).toEqual([
      { from: 0, to: 1, entry: 0, blend: false },
      { from: 1, to: 2, entry: 0, blend: true },
      { from: 2, to: 3, entry: 1, blend: true },
      { from: 3, to: 4, entry: 1, blend: false },
    ]);
  });

  it('marks its blends and the start of each entry on the time axis', () => {
    expect(blendIntervals(plan())).toEqual([[0.002, 0.004]]);
    expect(entryChanges(plan())).toEqual([{ t: 0.003, entry: 1 }]);
    expect(planText(plan())).toBe('planned length 12.50, duration 0.004 s');
    expect(planText({ ...plan(), truncated: true })).toMatch(/not ended/);
  });
});

describe('the live run', () => {
  it('is timed from the cycle it was sent in; nothing before it or out of order counts', () => {
    const r = new LiveRun();
    r.push(10, 1);
    expect(r.t).toEqual([]);
    r.begin(100, 0.002);
    r.push(99, 5);
    r.push(110, 50);
    r.push(105, 7);
    r.push(120, 100);
    expect(r.t).toEqual([0.02, 0.04]);
    expect(r.v).toEqual([50, 100]);
    r.clear();
    expect(r.running).toBe(false);
    expect(r.t).toEqual([]);
  });
});

describe('LiveAnalysis.cancel', () => {
  beforeEach(() => vi.useFakeTimers({ toFake: ['setTimeout', 'clearTimeout', 'Date'] }));
  afterEach(() => vi.useRealTimers());

  it('drops the scheduled body and the answer still to come', async () => {
    const calls: ((r: number) => void)[] = [];
    const seen: unknown[] = [];
    const pending: boolean[] = [];
    const a = new LiveAnalysis<number, number>(
      () => new Promise<number>((resolve) => calls.push(resolve)),
      (x) => seen.push(x),
      (p) => pending.push(p),
      { delay: 100, maxWait: 100 },
    );
    a.schedule(1);
    vi.advanceTimersByTime(100);
    expect(calls).toHaveLength(1);
    a.schedule(2);
    a.cancel();
    expect(a.pending).toBe(false);
    vi.advanceTimersByTime(500);
    expect(calls).toHaveLength(1);
    calls[0](1);
    await new Promise((r) => setImmediate(r));
    expect(seen).toEqual([]);
    expect(pending[pending.length - 1]).toBe(false);
  });
});
