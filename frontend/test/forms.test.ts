import { describe, expect, it } from 'vitest';
import { fieldErrors } from '../src/api/rest';
import { errorInfo } from '../src/api/errors';
import { diff, parseValue, rangeText } from '../src/ui/parameters';
import { configOf, DEFAULT_FORM, formOf } from '../src/ui/axis-config';
import type { ParameterResource } from '../src/api/types';

describe('problem+json field errors', () => {
  it('by JSON path', () => {
    expect(
      fieldErrors({
        type: 't',
        title: 'Invalid request',
        status: 422,
        detail: '',
        code: 'validation_failed',
        errors: [
          { field: 'dynamics.jerk', message: 'must be a finite number > 0' },
          { field: 'drive.plant.damping', message: 'must be > 0 and ≤ 10' },
        ],
      }),
    ).toEqual({ 'dynamics.jerk': 'must be a finite number > 0', 'drive.plant.damping': 'must be > 0 and ≤ 10' });
  });

  it('maps serde’s missing/unknown field messages of `body` to the field', () => {
    const p = (message: string) => ({ type: '', title: '', status: 422, detail: '', code: 'validation_failed', errors: [{ field: 'body', message }] });
    expect(fieldErrors(p('missing field `velocity` at line 1 column 20'))).toEqual({ velocity: 'missing field `velocity` at line 1 column 20' });
    expect(fieldErrors(p('unknown field `speed`, expected one of …'))).toHaveProperty('speed');
    expect(fieldErrors(p('invalid type: string "a", expected f64'))).toHaveProperty('body');
  });
});

describe('error table (from docs/errors.md)', () => {
  it('knows the TwinCAT and motiond numbers', () => {
    expect(errorInfo(0x4550)).toMatchObject({ hex: '0x4550', code: 'following_error' });
    expect(errorInfo(0x4b01).text).toMatch(/cannot be started/);
    expect(errorInfo(0x7061).code).toBe('deadman_timeout');
    expect(errorInfo(12345).code).toBe('unknown');
  });
});

const param = (p: Partial<ParameterResource>): ParameterResource =>
  ({ number: 1003, name: 'AxisVeloMax', type: 'lreal', unit: 'velocity', group: 'dynamics', read_only: false, storage: 1003, min: 0, max: null, min_exclusive: true, ads_index_offset: '', help: '', unit_text: 'mm/s', value: 500, ...p }) as ParameterResource;

describe('parameters', () => {
  it('range texts', () => {
    expect(rangeText(param({}))).toBe('> 0');
    expect(rangeText(param({ min: 0, max: 100, min_exclusive: false }))).toBe('0 … 100');
    expect(rangeText(param({ min: null as unknown as number, max: null as unknown as number }))).toBe('any');
    expect(rangeText(param({ type: 'bool' }))).toBe('true / false');
  });

  it('parses booleans and numbers by type', () => {
    expect(parseValue(param({}), ' 800 ')).toBe(800);
    expect(parseValue(param({}), '1,5')).toBe(1.5);
    expect(parseValue(param({}), 'x')).toBeNull();
    expect(parseValue(param({ type: 'bool' }), 'true')).toBe(true);
  });

  it('the diff lists only real changes, old → new', () => {
    const list = [param({}), param({ number: 1004, name: 'AxisAcc', value: 2500 }), param({ number: 1018, name: 'AxisEnMaxSoftPosLimit', type: 'bool', value: true })];
    const { changes, invalid } = diff(list, { 1003: '800', 1004: '2500', 1018: 'false' });
    expect(changes.map((c) => [c.param.number, c.old, c.next])).toEqual([
      [1003, 500, 800],
      [1018, true, false],
    ]);
    expect(invalid).toEqual({});
    expect(diff(list, { 1003: 'abc' }).invalid).toEqual({ 1003: 'not a number' });
  });
});

describe('axis configuration form', () => {
  it('round-trips a configuration', () => {
    const cfg = {
      name: 'x',
      unit: 'mm',
      soft_limits: { min: 0, max: 1000 },
      dynamics: { max_velocity: 500, acceleration: 2500, deceleration: 2500, jerk: 25000, jog_velocity_slow: 10, jog_velocity_fast: 100 },
      parameters: { AxisTargetPositionWindow: 0.01 },
      drive: {
        plant: { kind: 'pt2', natural_frequency_hz: 50, damping: 0.8 },
        dead_time: 0.001,
        dead_time_compensation: true,
        velocity_feed_forward: 1,
        acceleration_feed_forward: 0,
        enable_delay: 0.005,
        coast_deceleration: 10000,
        load_stiffness: 1000,
        reference_cam: { start: 20, end: 25 },
        index_pulse: { period: 10, offset: 0 },
        limit_switches: { negative: null, positive: null, fault_on_hit: false },
      },
    };
    const { config, errors } = configOf(formOf(cfg as never));
    expect(errors).toEqual({});
    expect(config).toEqual(cfg);
  });

  it('names fields whose text is not a number by their JSON path', () => {
    const f = { ...DEFAULT_FORM, name: 'z', dyn: { ...DEFAULT_FORM.dyn, jerk: 'fast' }, damping: '' };
    const { config, errors } = configOf(f);
    expect(config).toBeNull();
    expect(errors).toEqual({ 'dynamics.jerk': 'not a number', 'drive.plant.damping': 'required' });
  });

  it('leaves range checks to the server (a negative jerk is sent)', () => {
    const { config } = configOf({ ...DEFAULT_FORM, name: 'z', dyn: { ...DEFAULT_FORM.dyn, jerk: '-1' } });
    expect(config!.dynamics.jerk).toBe(-1);
  });
});
