import { describe, expect, it } from 'vitest';
import { fieldErrors } from '../src/api/problem';
import { errorInfo } from '../src/api/errors';
import { diff, parseValue, rangeText } from '../src/ui/config/parameters';
import { configOf, DEFAULT_FORM, formOf, shownFields } from '../src/ui/config/axis-config';
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
    expect(diff(list, { 1003: 'abc' }).invalid).toEqual({ 1003: 'enter a number' });
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
        kind: 'simulated',
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
        torque: { acceleration_per_percent: 250, friction: 2, viscous: 0.01 },
        velocity_mode_position_gain: 80,
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
    expect(errors).toEqual({ 'dynamics.jerk': 'enter a number', 'drive.plant.damping': 'required' });
  });

  it('leaves range checks to the server (a negative jerk is sent)', () => {
    const { config } = configOf({ ...DEFAULT_FORM, name: 'z', dyn: { ...DEFAULT_FORM.dyn, jerk: '-1' } });
    expect(config!.dynamics.jerk).toBe(-1);
  });

  const dynamics = { max_velocity: 500, acceleration: 2500, deceleration: 2500, jerk: 25000, jog_velocity_slow: 10, jog_velocity_fast: 100, jog_deadman_max: 1 };

  it('round-trips a CiA-402 drive as the server sends it (blank velocity increments: null)', () => {
    const cfg = {
      name: 'x',
      unit: 'mm',
      dynamics,
      parameters: { AxisTargetPositionWindow: 0.01 },
      drive: { kind: 'cia402', subdevice: 0, increments_per_unit: 1000, velocity_increments_per_unit: null, mode: 'csp', position_gain: 50, velocity_gain: 0, acceleration_feed_forward: 0, max_torque: 1000, profile: 'host', homing_method: null },
    };
    const f = formOf(cfg as never);
    expect(f.driveKind).toBe('cia402');
    expect(f.cia).toEqual({ subdevice: '0', increments_per_unit: '1000', velocity_increments_per_unit: '', position_gain: '50', velocity_gain: '0', acceleration_feed_forward: '0', max_torque: '1000' });
    expect(f.ciaMode).toBe('csp');
    const { config, errors } = configOf(f);
    expect(errors).toEqual({});
    expect(config).toEqual(cfg);
    // CSV with its own velocity scaling and gain
    const csv = configOf({ ...f, ciaMode: 'csv', cia: { ...f.cia, subdevice: '2', increments_per_unit: '131072', velocity_increments_per_unit: '10', position_gain: '80' } });
    expect(csv.config!.drive).toEqual({ kind: 'cia402', subdevice: 2, increments_per_unit: 131072, velocity_increments_per_unit: 10, mode: 'csv', position_gain: 80, velocity_gain: 0, acceleration_feed_forward: 0, max_torque: 1000, profile: 'host', homing_method: null });
  });

  it('round-trips a CST drive with its torque loop; a drive read without the CST fields gets the server defaults; a save keeps the gains of the other modes', () => {
    const cst = { kind: 'cia402', subdevice: 1, increments_per_unit: 131072, velocity_increments_per_unit: 10, mode: 'cst', position_gain: 40, velocity_gain: 2.5, acceleration_feed_forward: 0.1, max_torque: 1500, profile: 'host', homing_method: null };
    const cfg = { name: 'y', unit: 'mm', dynamics, parameters: {}, drive: cst };
    const f = formOf(cfg as never);
    expect(f.ciaMode).toBe('cst');
    expect(f.cia).toEqual({ subdevice: '1', increments_per_unit: '131072', velocity_increments_per_unit: '10', position_gain: '40', velocity_gain: '2.5', acceleration_feed_forward: '0.1', max_torque: '1500' });
    expect(configOf(f)).toEqual({ config: cfg, errors: {} });
    // switched to CSP: the CST gains (hidden) go along unchanged
    expect(configOf({ ...f, ciaMode: 'csp' }).config!.drive).toEqual({ ...cst, mode: 'csp' });
    // an older configuration without them
    const old = formOf({ ...cfg, drive: { kind: 'cia402', subdevice: 1, increments_per_unit: 1000, mode: 'csv' } } as never);
    expect(old.cia).toMatchObject({ position_gain: '50', velocity_gain: '0', acceleration_feed_forward: '0', max_torque: '1000' });
    // typed text that is no number: named by its JSON path
    expect(configOf({ ...f, cia: { ...f.cia, velocity_gain: 'fast', max_torque: '' } }).errors).toEqual({ 'drive.velocity_gain': 'enter a number', 'drive.max_torque': 'required' });
  });

  it('a CiA-402 drive: no simulated field is sent; the simulated one keeps what was typed while the kind is switched', () => {
    const typed = { ...DEFAULT_FORM, name: 'z', plant: 'pt1' as const, time_constant: '0.02', cia: { ...DEFAULT_FORM.cia, subdevice: '1' } };
    const cia = configOf({ ...typed, driveKind: 'cia402' }).config!;
    expect(cia.drive).toEqual({ kind: 'cia402', subdevice: 1, increments_per_unit: 1000, velocity_increments_per_unit: null, mode: 'csp', position_gain: 50, velocity_gain: 0, acceleration_feed_forward: 0, max_torque: 1000, profile: 'host', homing_method: null });
    const sim = configOf({ ...typed, driveKind: 'simulated' }).config!;
    expect(sim.drive).toMatchObject({ kind: 'simulated', plant: { kind: 'pt1', time_constant: 0.02 }, dead_time: 0.001 });
    // a simulated drive read from a configuration starts the CiA-402 fields at their defaults
    expect(formOf(sim).cia).toEqual(DEFAULT_FORM.cia);
    expect(formOf(sim).driveKind).toBe('simulated');
    // a configuration without a kind is a simulated drive
    expect(formOf({ ...sim, drive: undefined }).driveKind).toBe('simulated');
  });

  it('the profile side and the homing method: read, sent in `drive`; blank method = null (the drive\'s own); an older configuration is host-side', () => {
    const feeder = { kind: 'cia402', subdevice: 3, increments_per_unit: 1000, velocity_increments_per_unit: null, mode: 'csp', position_gain: 50, velocity_gain: 0, acceleration_feed_forward: 0, max_torque: 1000, profile: 'drive', homing_method: 1 };
    const cfg = { name: 'feeder', unit: 'mm', dynamics, parameters: {}, drive: feeder };
    const f = formOf(cfg as never);
    expect([f.ciaProfile, f.homingMethod]).toEqual(['drive', '1']);
    expect(configOf(f)).toEqual({ config: cfg, errors: {} });
    expect(configOf({ ...f, ciaProfile: 'host', homingMethod: '' }).config!.drive).toEqual({ ...feeder, profile: 'host', homing_method: null });
    expect(configOf({ ...f, homingMethod: '34' }).config!.drive).toMatchObject({ profile: 'drive', homing_method: 34 });
    // range checks are the server's (1..37); a fraction is no method number
    expect(configOf({ ...f, homingMethod: '40' }).config!.drive).toMatchObject({ homing_method: 40 });
    expect(configOf({ ...f, homingMethod: '1.5' }).errors).toEqual({ 'drive.homing_method': 'a whole number' });
    const old = formOf({ ...cfg, drive: { kind: 'cia402', subdevice: 1, increments_per_unit: 1000, mode: 'csp' } } as never);
    expect([old.ciaProfile, old.homingMethod]).toEqual(['host', '']);
    // the fields the form shows for a CiA-402 drive (a 422 there lands at the field)
    expect(shownFields(f).has('drive.profile')).toBe(true);
    expect(shownFields(f).has('drive.homing_method')).toBe(true);
  });

  it('CiA-402 fields that are not numbers are named by their JSON path; the position must be whole', () => {
    const f = { ...DEFAULT_FORM, name: 'z', driveKind: 'cia402' as const, damping: 'not checked', cia: { ...DEFAULT_FORM.cia, subdevice: '1.5', increments_per_unit: '', velocity_increments_per_unit: 'x' } };
    const { config, errors } = configOf(f);
    expect(config).toBeNull();
    expect(errors).toEqual({ 'drive.subdevice': 'a whole number', 'drive.increments_per_unit': 'required', 'drive.velocity_increments_per_unit': 'enter a number' });
    expect(configOf({ ...f, cia: { ...f.cia, subdevice: '' , increments_per_unit: '1', velocity_increments_per_unit: '' } }).errors).toEqual({ 'drive.subdevice': 'required' });
  });

  it("the fields shown depend on the drive's kind (other paths go to the banner)", () => {
    const cia = shownFields({ ...DEFAULT_FORM, driveKind: 'cia402' });
    for (const p of ['drive.kind', 'drive.subdevice', 'drive.increments_per_unit', 'drive.velocity_increments_per_unit', 'drive.mode']) expect(cia.has(p)).toBe(true);
    // the gains by mode: none in CSP, the position gain in CSV, all in CST
    const gains = ['drive.position_gain', 'drive.velocity_gain', 'drive.acceleration_feed_forward', 'drive.max_torque'];
    expect(gains.filter((p) => cia.has(p))).toEqual([]);
    expect(gains.filter((p) => shownFields({ ...DEFAULT_FORM, driveKind: 'cia402', ciaMode: 'csv' }).has(p))).toEqual(['drive.position_gain']);
    expect(gains.filter((p) => shownFields({ ...DEFAULT_FORM, driveKind: 'cia402', ciaMode: 'cst' }).has(p))).toEqual(gains);
    expect(cia.has('drive.plant.damping')).toBe(false);
    const sim = shownFields(DEFAULT_FORM);
    expect(sim.has('drive.kind')).toBe(true);
    expect(sim.has('drive.plant.damping')).toBe(true);
    expect(sim.has('drive.subdevice')).toBe(false);
  });
});
