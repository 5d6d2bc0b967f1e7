import { describe, expect, it } from 'vitest';
import {
  alignedTime,
  appendRing,
  chartGroups,
  defaultView,
  emptyRing,
  fitView,
  fromSetup,
  mergeAligned,
  recordingStart,
  removeChannel,
  setupFieldErrors,
  setupNameError,
  toSetup,
  viewFromJson,
  viewToJson,
} from '../src/scope/view';
import { buildRequest, type Recording, type ScopeForm } from '../src/scope/data';

const form: ScopeForm = {
  channels: [
    { axis: 'x', signal: 'set_velocity' },
    { axis: 'x', signal: 'actual_velocity' },
    { axis: 'y', signal: 'following_error' },
  ],
  duration_s: 2,
  trigger: { enabled: true, channel: 0, level: 10, edge: 'falling', pre_trigger_s: 0.2 },
};

describe('scope view and setups', () => {
  it('round-trips a setup: request and view (charts, colours, rolling)', () => {
    const req = buildRequest(form).request!;
    const v = { chart: [0, 0, 1], colors: ['#111111', '#222222', '#333333'], rolling: { enabled: true, chunk_s: 0.5, window_s: 20 } };
    const s = toSetup(req, v);
    expect(s.recording).toEqual(req);
    expect(s.view).toEqual({ version: 1, charts: [[0, 1], [2]], colors: v.colors, rolling: v.rolling });
    expect(JSON.stringify(s).length).toBeLessThan(64 * 1024);
    const back = fromSetup(JSON.parse(JSON.stringify(s)));
    expect(back.form).toEqual(form);
    expect(back.view).toEqual(v);
  });

  it('a setup without trigger or view loads with defaults', () => {
    const back = fromSetup({ recording: { channels: [{ axis: 'x', signal: 'set_position' }], duration_s: 1 } });
    expect(back.form.trigger.enabled).toBe(false);
    expect(back.form.duration_s).toBe(1);
    expect(back.view).toEqual(defaultView(1));
  });

  it('reads the server example view and ignores what does not fit', () => {
    expect(viewFromJson({ charts: [[0], [1]], rolling: false }, 2).chart).toEqual([0, 1]);
    const odd = viewFromJson({ charts: [[5, 'a', 1], 7, [0]], colors: ['red', '#00ff00'], rolling: { enabled: 'yes', chunk_s: -1, window_s: 30 } }, 2);
    expect(odd.chart).toEqual([2, 0]);
    expect(odd.colors[0]).toBe(defaultView(2).colors[0]);
    expect(odd.colors[1]).toBe('#00ff00');
    expect(odd.rolling).toEqual({ enabled: false, chunk_s: 1, window_s: 30 });
    expect(viewFromJson(null, 1)).toEqual(defaultView(1));
  });

  it('keeps the view in step with added and removed channels', () => {
    const v = { ...defaultView(2), chart: [1, 2] };
    expect(fitView(v, 3).chart).toEqual([1, 2, 0]);
    expect(removeChannel(fitView(v, 3), 0).chart).toEqual([2, 0]);
    expect(chartGroups({ ...v, chart: [3, 1, 1] }, 3)).toEqual([[1, 2], [0]]);
    expect(viewToJson({ ...v, chart: [0, 0] }, 2).charts).toEqual([[0, 1]]);
  });

  it('maps server field errors of a setup onto the form', () => {
    expect(setupFieldErrors({ 'recording.channels[0].axis': 'unknown axis', name: 'bad name' })).toEqual({
      form: { 'channels[0].axis': 'unknown axis' },
      other: { name: 'bad name' },
    });
    expect(setupNameError('')).toBeTruthy();
    expect(setupNameError('9a')).toBeTruthy();
    expect(setupNameError('a b')).toBeTruthy();
    expect(setupNameError('x'.repeat(65))).toBeTruthy();
    expect(setupNameError('_x-loop_2')).toBeNull();
  });
});

describe('rolling ring', () => {
  const cyc = 0.01;
  it('appends consecutive recordings without a gap', () => {
    let r = emptyRing(1);
    r = appendRing(r, 100, cyc, [[1, 2, 3]], 10);
    r = appendRing(r, 100.03, cyc, [[4, 5]], 10);
    expect(r.t.map((x) => +x.toFixed(6))).toEqual([0, 0.01, 0.02, 0.03, 0.04]);
    expect(r.data[0]).toEqual([1, 2, 3, 4, 5]);
    expect(r.gaps).toBe(0);
    expect(r.end).toBeCloseTo(0.05);
  });

  it('puts a null between recordings that do not follow each other (a break, not a joined line)', () => {
    let r = emptyRing(2);
    r = appendRing(r, 100, cyc, [[1, 2], [10, 20]], 10);
    r = appendRing(r, 100.07, cyc, [[3, 4], [30, 40]], 10);
    expect(r.data[0]).toEqual([1, 2, null, 3, 4]);
    expect(r.data[1]).toEqual([10, 20, null, 30, 40]);
    expect(r.t[2]).toBeGreaterThan(r.t[1]);
    expect(r.t[2]).toBeLessThan(r.t[3]);
    expect(r.gaps).toBe(1);
    expect(r.lostSamples).toBe(5);
  });

  it('keeps only the last window', () => {
    let r = emptyRing(1);
    for (let k = 0; k < 5; k++) r = appendRing(r, k * 1.5, 0.5, [[k, k]], 2);
    // recordings at 0, 1.5, 3, 4.5, 6 s of 1 s each, gaps of 0.5 s; end 7 s: keeps from 5 s on (+ one before)
    expect(r.end).toBeCloseTo(7);
    expect(r.t[0]).toBeLessThanOrEqual(5);
    expect(r.t[1]).toBeGreaterThan(5 - 1e-9);
    expect(r.data[0].at(-1)).toBe(4);
    expect(r.data[0][0]).not.toBeNull();
    expect(r.t.length).toBeLessThan(8);
  });

  it('absolute start from the start cycle', () => {
    expect(recordingStart({ id: 1, state: 'done', cycle_time_s: 0.002, samples: 1, channels: [], start_cycle: 500 })).toBeCloseTo(1);
  });
});

describe('compare: alignment', () => {
  const rec = (id: number, t: number[], d: number[], trigger = true): Recording => ({
    id,
    state: 'done',
    cycle_time_s: 0.1,
    samples: t.length,
    channels: [{ axis: 'x', signal: 'set_position' }],
    trigger: trigger ? { channel: 0, level: 1, edge: 'rising', pre_trigger_s: -t[0] } : null,
    t,
    data: [d],
  });

  it('aligns at the trigger (server t) or at the start', () => {
    const a = rec(1, [-0.2, -0.1, 0, 0.1], [0, 0, 1, 2]);
    expect(alignedTime(a, 'trigger')).toEqual([-0.2, -0.1, 0, 0.1]);
    expect(alignedTime(a, 'start').map((x) => +x.toFixed(9))).toEqual([0, 0.1, 0.2, 0.3]);
    const b = rec(2, [0, 0.1], [5, 6], false);
    expect(alignedTime(b, 'trigger')).toEqual([0, 0.1]);
  });

  it('merges two time axes; each recording null where it has no sample', () => {
    const m = mergeAligned([0, 0.1, 0.2], [[1, 2, 3]], [0.05, 0.1, 0.3], [[7, 8, 9]]);
    expect(m.t).toEqual([0, 0.05, 0.1, 0.2, 0.3]);
    expect(m.a).toEqual([[1, null, 2, 3, null]]);
    expect(m.b).toEqual([[null, 7, 8, null, 9]]);
  });

  it('identical sample times stay one point', () => {
    const m = mergeAligned([0, 1], [[1, 2]], [0, 1 + 1e-12], [[3, 4]]);
    expect(m.t).toHaveLength(2);
    expect(m.b[0]).toEqual([3, 4]);
  });
});
