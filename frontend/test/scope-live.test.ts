// The trace of a recording while it is armed or running, drawn from the status stream (the
// server gives out samples only when done): rows stamped with kernel cycles, other channels
// held, holds to the present, the pre-trigger history scrolling while armed, the trace growing
// from −pre-trigger once triggered.
import { describe, expect, it } from 'vitest';
import { HOLD_STEP_S, LiveTrace, type LiveRecording } from '../src/scope/live';

const rec = (over: Partial<LiveRecording> = {}): LiveRecording => ({
  id: 7,
  state: 'recording',
  cycle_time_s: 0.001,
  samples: 2000,
  duration_s: 2,
  start_cycle: 1000,
  trigger_cycle: null,
  trigger: null,
  channels: [
    { axis: 'x', signal: 'set_position' },
    { axis: 'y', signal: 'set_velocity' },
  ],
  ...over,
});

describe('LiveTrace', () => {
  it('without a trigger: t from the start, each axis’s channels from its statuses, the others held', () => {
    const tr = new LiveTrace(rec());
    tr.push('x', { set_position: 1 }, 1000, 0);
    tr.push('y', { set_velocity: 5 }, 1020, 20);
    tr.push('x', { set_position: 2, set_velocity: 99 }, 1040, 40);
    tr.push('spindle', { set_position: 3 }, 1050, 50); // no channel of it
    const s = tr.series(40);
    expect(s.limits).toEqual({ min: 0, max: 2 });
    expect(s.armed).toBe(false);
    expect(s.points).toBe(3);
    expect(s.t.map((x) => +x.toFixed(3))).toEqual([0, 0.02, 0.04]);
    expect(s.data).toEqual([
      [1, 1, 2],
      [null, 5, 5],
    ]);
  });

  it('grows: the newest values are held on to the present (nothing changed since), never beyond the end', () => {
    const tr = new LiveTrace(rec());
    tr.push('x', { set_position: 1 }, 1000, 0);
    let s = tr.series(500); // 0.5 s later, no status since
    expect(s.t.map((x) => +x.toFixed(3))).toEqual([0, 0.5]);
    expect(s.data[0]).toEqual([1, 1]);
    expect(s.points).toBe(1);
    s = tr.series(5000);
    expect(s.t.at(-1)).toBe(2);
  });

  it('a pause between two statuses is a hold, not a slow ramp', () => {
    const tr = new LiveTrace(rec());
    tr.push('x', { set_position: 0 }, 1000, 0);
    tr.push('x', { set_position: 10 }, 1500, 500);
    const s = tr.series(500);
    expect(s.t.map((x) => +x.toFixed(3))).toEqual([0, +(0.5 - HOLD_STEP_S).toFixed(3), 0.5]);
    expect(s.data[0]).toEqual([0, 0, 10]);
  });

  it('armed: the last pre-trigger seconds scroll up to t = 0; triggered: t from the trigger, −pre … duration − pre', () => {
    const trig = { channel: 0, level: 5, edge: 'rising' as const, pre_trigger_s: 0.1 };
    const tr = new LiveTrace(rec({ state: 'armed', trigger: trig }));
    for (let c = 1000; c <= 1400; c += 20) tr.push('x', { set_position: (c - 1000) / 100 }, c, c - 1000);
    let s = tr.series(400);
    expect(s.armed).toBe(true);
    expect(s.limits).toEqual({ min: -0.1, max: 1.9 });
    expect(s.t[0]).toBeCloseTo(-0.1);
    expect(s.t.at(-1)).toBeCloseTo(0);
    expect(s.data[0].at(-1)).toBe(4);
    // the server says where the trigger was: the trace is drawn from it, the history before
    tr.update(rec({ state: 'recording', trigger: trig, trigger_cycle: 1300 }));
    s = tr.series(400);
    expect(s.armed).toBe(false);
    expect(s.t[0]).toBeCloseTo(-0.1);
    expect(s.t.at(-1)).toBeCloseTo(0.1);
    expect(s.data[0][s.t.findIndex((t) => Math.abs(t) < 1e-9)]).toBe(3);
  });

  it('an older cycle (another subscription’s late status) is not drawn back in time; the same cycle replaces its row', () => {
    const tr = new LiveTrace(rec());
    tr.push('x', { set_position: 1 }, 1100, 0);
    tr.push('x', { set_position: 9 }, 1050, 0);
    tr.push('y', { set_velocity: 3 }, 1100, 0);
    const s = tr.series(0);
    expect(s.t).toEqual([0.1]);
    expect(s.data).toEqual([[1], [3]]);
  });

  it('another recording’s update is not taken', () => {
    const tr = new LiveTrace(rec());
    tr.update(rec({ id: 8, start_cycle: 5000 }));
    tr.push('x', { set_position: 1 }, 1000, 0);
    expect(tr.series(0).t).toEqual([0]);
  });
});
