import { describe, expect, it } from 'vitest';
import {
  buildRequest,
  channelLabel,
  checkRecording,
  cursorReadout,
  expectedSamples,
  indexAt,
  panRange,
  preTriggerSamples,
  scaleKey,
  signalUnit,
  timeAxis,
  toCsv,
  zoomRange,
  type Recording,
  type ScopeForm,
} from '../src/scope/data';

const form = (patch: Partial<ScopeForm> = {}): ScopeForm => ({
  channels: [
    { axis: 'x', signal: 'set_position' },
    { axis: 'y', signal: 'actual_velocity' },
  ],
  duration_s: 2,
  trigger: { enabled: false, channel: 0, level: 0, edge: 'rising', pre_trigger_s: 0.2 },
  ...patch,
});

/** A finished recording as the server returns it (fixture). */
function recording(n: number, cycle = 0.001, pre = 0): Recording {
  const t = Array.from({ length: n }, (_, i) => (i - pre) * cycle);
  return {
    id: 7,
    state: 'done',
    cycle_time_s: cycle,
    duration_s: n * cycle,
    channels: [
      { axis: 'x', signal: 'set_position' },
      { axis: 'x', signal: 'set_velocity' },
    ],
    samples: n,
    trigger: pre ? { channel: 0, level: 0.5, edge: 'rising', pre_trigger_s: pre * cycle } : null,
    t,
    data: [t.map((x) => 100 * x), t.map(() => 100)],
  };
}

describe('recording request', () => {
  it('maps the channels in order and passes the duration', () => {
    const { request, errors } = buildRequest(form());
    expect(errors).toEqual({});
    expect(request).toEqual({
      channels: [
        { axis: 'x', signal: 'set_position' },
        { axis: 'y', signal: 'actual_velocity' },
      ],
      duration_s: 2,
      trigger: null,
    });
  });

  it('a trigger names the channel by index and carries edge, level and pre-trigger', () => {
    const { request } = buildRequest(form({ trigger: { enabled: true, channel: 1, level: 50, edge: 'falling', pre_trigger_s: 0.25 } }));
    expect(request!.trigger).toEqual({ channel: 1, level: 50, edge: 'falling', pre_trigger_s: 0.25 });
  });

  it('refuses what the server would refuse, at the field', () => {
    expect(buildRequest(form({ channels: [] })).errors.channels).toBeTruthy();
    const nine = Array.from({ length: 9 }, () => ({ axis: 'x', signal: 'set_position' as const }));
    expect(buildRequest(form({ channels: nine })).errors.channels).toMatch(/at most 8/);
    expect(buildRequest(form({ duration_s: 0 })).errors.duration_s).toBeTruthy();
    expect(buildRequest(form({ duration_s: NaN })).errors.duration_s).toBeTruthy();
    const trig = (t: Partial<ScopeForm['trigger']>) => buildRequest(form({ trigger: { enabled: true, channel: 0, level: 1, edge: 'rising', pre_trigger_s: 0.1, ...t } })).errors;
    expect(trig({ channel: 2 })['trigger.channel']).toBeTruthy();
    expect(trig({ pre_trigger_s: -1 })['trigger.pre_trigger_s']).toBeTruthy();
    expect(trig({ pre_trigger_s: 3 })['trigger.pre_trigger_s']).toMatch(/exceed/);
    expect(trig({ pre_trigger_s: 2 })['trigger.pre_trigger_s']).toBeUndefined();
    expect(trig({ level: NaN })['trigger.level']).toBeTruthy();
  });
});

describe('samples and the time axis', () => {
  it('sample count is duration / cycle time exactly', () => {
    expect(expectedSamples(2, 0.001)).toBe(2000);
    expect(expectedSamples(0.3, 0.001)).toBe(300); // 0.3/0.001 = 299.99999999999994
    expect(expectedSamples(1, 0.00025)).toBe(4000);
    expect(expectedSamples(0.5, 0.002)).toBe(250);
  });

  it('without a trigger t starts at 0, one sample per cycle', () => {
    const r = recording(5);
    delete r.t;
    expect(timeAxis(r)).toEqual([0, 0.001, 0.002, 0.003, 0.004]);
  });

  it('with a pre-trigger t is 0 at the trigger and negative before it', () => {
    const r = recording(10, 0.001, 3);
    delete r.t;
    expect(preTriggerSamples(r.trigger, r.cycle_time_s)).toBe(3);
    const t = timeAxis(r);
    expect(t[0]).toBeCloseTo(-0.003, 12);
    expect(t[3]).toBe(0);
    expect(t[9]).toBeCloseTo(0.006, 12);
  });

  it("takes the server's pre_trigger_samples when t is missing", () => {
    const r = recording(6, 0.002);
    delete r.t;
    r.pre_trigger_samples = 2;
    expect(timeAxis(r)).toEqual([-0.004, -0.002, 0, 0.002, 0.004, 0.006]);
  });

  it("uses the server's t when present", () => {
    const r = recording(4);
    r.t = [10, 11, 12, 13];
    expect(timeAxis(r)).toEqual([10, 11, 12, 13]);
  });

  it('checks a recording for consistency', () => {
    expect(checkRecording(recording(100))).toEqual([]);
    const r = recording(100);
    r.data![1] = r.data![1].slice(0, 99);
    expect(checkRecording(r)).toEqual(['channel 1 has 99 samples, expected 100']);
    const s = recording(100);
    s.duration_s = 0.2;
    expect(checkRecording(s)[0]).toMatch(/0.2 s/);
  });
});

describe('channel mapping', () => {
  it('labels as the CSV header does and units per signal', () => {
    expect(channelLabel({ axis: 'x', signal: 'set_position' })).toBe('x.set_position');
    expect(signalUnit('set_position', 'mm')).toBe('mm');
    expect(signalUnit('actual_velocity', 'deg')).toBe('deg/s');
    expect(signalUnit('set_acceleration', 'mm')).toBe('mm/s²');
    expect(signalUnit('actual_acceleration', 'mm')).toBe('mm/s²');
    expect(signalUnit('following_error', 'mm')).toBe('mm');
  });

  it('signals of one unit share a scale; the following error gets its own', () => {
    expect(scaleKey('set_position', 'mm')).toBe(scaleKey('actual_position', 'mm'));
    expect(scaleKey('set_velocity', 'mm')).toBe(scaleKey('actual_velocity', 'mm'));
    expect(scaleKey('set_velocity', 'mm')).not.toBe(scaleKey('set_velocity', 'deg'));
    expect(scaleKey('following_error', 'mm')).not.toBe(scaleKey('set_position', 'mm'));
  });
});

describe('cursors', () => {
  it('finds the nearest sample', () => {
    const t = [0, 0.001, 0.002, 0.003];
    expect(indexAt(t, -5)).toBe(0);
    expect(indexAt(t, 0.0014)).toBe(1);
    expect(indexAt(t, 0.0016)).toBe(2);
    expect(indexAt(t, 9)).toBe(3);
    expect(indexAt([], 1)).toBe(-1);
  });

  it('reads t, values, Δt and Δvalue at both cursors', () => {
    const r = recording(1001);
    const o = cursorReadout(r.t!, r.data!, r.channels.map(channelLabel), 0.1002, 0.5999);
    expect(o.i1).toBe(100);
    expect(o.i2).toBe(600);
    expect(o.t1).toBeCloseTo(0.1, 12);
    expect(o.dt).toBeCloseTo(0.5, 12);
    expect(o.rows[0].label).toBe('x.set_position');
    expect(o.rows[0].v1).toBeCloseTo(10, 9);
    expect(o.rows[0].dv).toBeCloseTo(50, 9);
    expect(o.rows[1].dv).toBe(0);
  });

  it('a missing value (null) reads as no value', () => {
    const o = cursorReadout([0, 1, 2], [[5, null, 7]], ['a'], 0, 1);
    expect(o.rows[0]).toEqual({ label: 'a', v1: 5, v2: null, dv: null });
  });

  it('one cursor alone has no differences', () => {
    const r = recording(10);
    const o = cursorReadout(r.t!, r.data!, ['a', 'b'], 0.004, null);
    expect(o.t2).toBeNull();
    expect(o.dt).toBeNull();
    expect(o.rows[0]).toMatchObject({ v2: null, dv: null });
  });
});

describe('CSV', () => {
  it('writes the header t,axis.signal,… and one row per sample', () => {
    const r = recording(3);
    const csv = toCsv(r.t!, r.channels, r.data!);
    expect(csv).toBe('t,x.set_position,x.set_velocity\n0,0,100\n0.001,0.1,100\n0.002,0.2,100\n');
  });

  it('leaves a value empty where the axis was missing (null)', () => {
    const csv = toCsv([0, 0.001], [{ axis: 'x', signal: 'set_position' }], [[1, null]]);
    expect(csv).toBe('t,x.set_position\n0,1\n0.001,\n');
  });

  it('writes only the visible range when asked', () => {
    const r = recording(10);
    const lines = toCsv(r.t!, r.channels, r.data!, { from: 0.002, to: 0.004 }).trim().split('\n');
    expect(lines.length).toBe(4);
    expect(lines[1].startsWith('0.002,')).toBe(true);
  });
});

describe('zoom and pan', () => {
  const lim = { min: 0, max: 10 };
  it('zooms around the pointer', () => {
    expect(zoomRange({ min: 0, max: 10 }, 5, 0.5, lim)).toEqual({ min: 2.5, max: 7.5 });
    expect(zoomRange({ min: 0, max: 10 }, 0, 0.5, lim)).toEqual({ min: 0, max: 5 });
  });
  it('never zooms out beyond the recording', () => {
    expect(zoomRange({ min: 2, max: 8 }, 5, 4, lim)).toEqual({ min: 0, max: 10 });
  });
  it('pans within the recording', () => {
    expect(panRange({ min: 2, max: 4 }, 1, lim)).toEqual({ min: 3, max: 5 });
    expect(panRange({ min: 2, max: 4 }, -5, lim)).toEqual({ min: 0, max: 2 });
    expect(panRange({ min: 2, max: 4 }, 50, lim)).toEqual({ min: 8, max: 10 });
  });
});
