// The bodies of the single-axis blocks beyond moving (phasing, multi-master gear, torque control,
// the drive's operation mode, position correction, encoder): a valid form, blank inputs left to
// the server's defaults, and mistakes named at their fields (nothing is sent then).
import { describe, expect, it } from 'vitest';
import {
  BACKLASH_DEFAULTS,
  ENCODER_SCALING_DEFAULTS,
  LIMITER_DEFAULTS,
  MULTI_MASTER_DEFAULTS,
  PHASING_DEFAULTS,
  TABLE_COMPENSATION_DEFAULTS,
  TORQUE_DEFAULTS,
  backlashBody,
  correctionRows,
  encoderScalingBody,
  gearInMultiMasterBody,
  haltPhasingBody,
  incPosQuery,
  limiterBody,
  multiMasterFields,
  multiMasterForm,
  multiMasterRows,
  phasingBody,
  posQuery,
  tableCompensationBody,
  torqueControlBody,
  writeDriveModeBody,
} from '../src/axis/bodies';

describe('phasing', () => {
  it('MC_PhasingAbsolute / Relative: master, shift, velocity and dynamics', () => {
    expect(phasingBody({ ...PHASING_DEFAULTS, master: 'x', phase_shift: '5', velocity: '10', acceleration: '100', deceleration: '200', jerk: '1000' })).toEqual({
      body: { master: 'x', phase_shift: 5, velocity: 10, acceleration: 100, deceleration: 200, jerk: 1000 },
      errors: {},
    });
  });
  it('blank acceleration, deceleration and jerk are left out (the axis default)', () => {
    expect(phasingBody({ ...PHASING_DEFAULTS, master: 'x', phase_shift: '-2,5', velocity: '0.01' }).body).toEqual({ master: 'x', phase_shift: -2.5, velocity: 0.01 });
  });
  it('names the mistakes at their fields', () => {
    expect(phasingBody({ ...PHASING_DEFAULTS, phase_shift: '', velocity: '0.001', jerk: '-1' }).errors).toEqual({
      master: 'choose a master axis',
      phase_shift: 'enter a value',
      velocity: 'must be ≥ 0.01',
      jerk: 'must be ≥ 0',
    });
    expect(phasingBody({ ...PHASING_DEFAULTS, master: 'x', phase_shift: 'abc', velocity: '' }).errors).toEqual({ phase_shift: 'enter a number', velocity: 'enter a value' });
  });
  it('MC_HaltPhasing: master, deceleration and jerk only', () => {
    expect(haltPhasingBody({ ...PHASING_DEFAULTS, master: 'x', velocity: '10', deceleration: '500' })).toEqual({ body: { master: 'x', deceleration: 500 }, errors: {} });
    expect(haltPhasingBody({ ...PHASING_DEFAULTS, master: 'x' }).body).toEqual({ master: 'x' });
    expect(haltPhasingBody({ ...PHASING_DEFAULTS, master: '', deceleration: '-5' }).errors).toEqual({ master: 'choose a master axis', deceleration: 'must be ≥ 0' });
  });
});

describe('multi-master gear', () => {
  it('the rows with a master, in order; blank rows are unused', () => {
    const f = { ...MULTI_MASTER_DEFAULTS, master1: 'x', ratio1: '1', master3: 'spindle', ratio3: '0.1', ratio2: '7' };
    expect(multiMasterRows(f)).toEqual([1, 3]);
    expect(gearInMultiMasterBody(f)).toEqual({
      body: {
        masters: [
          { master: 'x', gear_ratio: 1 },
          { master: 'spindle', gear_ratio: 0.1 },
        ],
      },
      errors: {},
    });
  });
  it('deceleration, jerk and the sync mode go with advanced slave dynamics only', () => {
    const f = { ...MULTI_MASTER_DEFAULTS, master1: 'x', acceleration: '1000', deceleration: '900', jerk: '9000', sync_mode: 'possync2' };
    expect(gearInMultiMasterBody(f).body).toEqual({ masters: [{ master: 'x', gear_ratio: 1 }], acceleration: 1000 });
    expect(gearInMultiMasterBody({ ...f, advanced_slave_dynamics: '1' }).body).toEqual({
      masters: [{ master: 'x', gear_ratio: 1 }],
      acceleration: 1000,
      deceleration: 900,
      jerk: 9000,
      advanced_slave_dynamics: true,
      sync_mode: 'possync2',
    });
  });
  it('no master, a master twice, a missing ratio are named at their rows', () => {
    expect(gearInMultiMasterBody(MULTI_MASTER_DEFAULTS).errors).toEqual({ master1: 'choose at least one master' });
    expect(gearInMultiMasterBody({ ...MULTI_MASTER_DEFAULTS, master1: 'x', master2: 'x', master4: 'spindle', ratio4: '', acceleration: '-1' }).errors).toEqual({
      master2: 'names a master twice',
      ratio4: 'enter a value',
      acceleration: 'must be ≥ 0',
    });
  });
  it("the server's errors of masters[j] land at the row j-th used", () => {
    const f = { ...MULTI_MASTER_DEFAULTS, master1: 'x', master3: 'x' };
    expect(multiMasterFields(f, { 'masters[1].master': 'names a master twice', 'masters[0].gear_ratio': 'bad', masters: 'must name 1 to 4 masters', acceleration: 'too big' })).toEqual({
      master3: 'names a master twice',
      ratio1: 'bad',
      master1: 'must name 1 to 4 masters',
      acceleration: 'too big',
    });
    // local errors (already row keys) pass unchanged
    expect(multiMasterFields(f, { master2: 'names a master twice' })).toEqual({ master2: 'names a master twice' });
  });
  it("a running command's masters fill the form", () => {
    expect(multiMasterForm({ masters: [{ master: 'x', gear_ratio: 1.5 }, { master: 'spindle', gear_ratio: 0.2 }] })).toEqual({
      master1: 'x',
      ratio1: '1.5',
      master2: 'spindle',
      ratio2: '0.2',
      master3: '',
      ratio3: '1',
      master4: '',
      ratio4: '1',
    });
    expect(multiMasterForm(null).master1).toBe('');
  });
});

describe('torque control and the drive operation mode', () => {
  const ok = { ...TORQUE_DEFAULTS, torque: '35', torque_ramp: '10', velocity_limit_high: '400', velocity_limit_low: '-500' };
  it('MC_TorqueControl: torque, ramp, limits; blank start torque and relative left out', () => {
    expect(torqueControlBody(ok)).toEqual({ body: { torque: 35, torque_ramp: 10, velocity_limit_high: 400, velocity_limit_low: -500 }, errors: {} });
    expect(torqueControlBody({ ...ok, relative: '1', manual_start_torque: '5' }).body).toEqual({
      torque: 35,
      torque_ramp: 10,
      relative: true,
      velocity_limit_high: 400,
      velocity_limit_low: -500,
      manual_start_torque: 5,
    });
  });
  it('a ramp of 0, low above high, a torque beyond 1000 % are named', () => {
    expect(torqueControlBody({ ...ok, torque_ramp: '0', velocity_limit_low: '500', torque: '1200' }).errors).toEqual({
      torque_ramp: 'must be > 0',
      velocity_limit_low: 'must be ≤ the high limit',
      torque: 'must be ≤ 1000',
    });
    expect(torqueControlBody(TORQUE_DEFAULTS).errors).toEqual({ torque: 'enter a value', velocity_limit_high: 'enter a value', velocity_limit_low: 'enter a value' });
  });
  it('MC_WriteDriveOperationMode: the position-based modes only', () => {
    expect(writeDriveModeBody({ drive_operation_mode: 'velocity' })).toEqual({ body: { drive_operation_mode: 'velocity' }, errors: {} });
    expect(writeDriveModeBody({ drive_operation_mode: 'torque' }).errors).toEqual({ drive_operation_mode: 'choose configured, position or velocity' });
  });
});

describe('position correction', () => {
  it('the limiter: the acceleration with fast, the length with full length', () => {
    expect(limiterBody({ ...LIMITER_DEFAULTS, value: '0.5', acceleration: '100', correction_length: '10' })).toEqual({ body: { value: 0.5, mode: 'unlimited' }, errors: {} });
    expect(limiterBody({ ...LIMITER_DEFAULTS, value: '0.5', mode: 'fast', acceleration: '100' }).body).toEqual({ value: 0.5, mode: 'fast', acceleration: 100 });
    expect(limiterBody({ ...LIMITER_DEFAULTS, value: '0.5', mode: 'fast' }).body).toEqual({ value: 0.5, mode: 'fast' });
    expect(limiterBody({ ...LIMITER_DEFAULTS, value: '-0.1', mode: 'full_length', correction_length: '20' }).body).toEqual({ value: -0.1, mode: 'full_length', correction_length: 20 });
  });
  it('the limiter: a missing value, a length of 0 are named', () => {
    expect(limiterBody({ ...LIMITER_DEFAULTS, mode: 'full_length', correction_length: '0' }).errors).toEqual({ value: 'enter a value', correction_length: 'must be > 0' });
  });
  it('backlash: blank = #1036, the direction only when positive', () => {
    expect(backlashBody({ ...BACKLASH_DEFAULTS, ramp: '1' })).toEqual({ body: { ramp: 1, disable_mode: 'hold' }, errors: {} });
    expect(backlashBody({ ...BACKLASH_DEFAULTS, backlash: '0.02', ramp: '2', compensate_in_positive_direction: '1', disable_mode: 'reset' }).body).toEqual({
      backlash: 0.02,
      compensate_in_positive_direction: true,
      ramp: 2,
      disable_mode: 'reset',
    });
    expect(backlashBody({ ...BACKLASH_DEFAULTS, backlash: 'x', ramp: '0' }).errors).toEqual({ backlash: 'enter a number', ramp: 'must be > 0' });
  });
  it('table compensation: the ramp must be > 0', () => {
    expect(tableCompensationBody({ ...TABLE_COMPENSATION_DEFAULTS, ramp: '1' })).toEqual({ body: { ramp: 1, disable_mode: 'hold' }, errors: {} });
    expect(tableCompensationBody(TABLE_COMPENSATION_DEFAULTS).errors).toEqual({ ramp: 'enter a value' });
    expect(tableCompensationBody({ ramp: '-1', disable_mode: '' })).toEqual({ body: { ramp: -1 }, errors: { ramp: 'must be > 0' } });
  });
  it('the rows of the correction table', () => {
    expect(correctionRows(null)).toEqual([]);
    const rows = correctionRows({ total: 0.7, limiter: 0.5, limiter_enabled: true, limiter_limiting: false, backlash: 0.2, backlash_enabled: true, backlash_limiting: true, table: 0, table_enabled: false, table_limiting: false });
    expect(rows).toEqual([
      ['limiter', 'Limiter', 0.5, true, false],
      ['backlash', 'Backlash', 0.2, true, true],
      ['table', 'Table', 0, false, false],
    ]);
  });
});

describe('encoder', () => {
  it('MC_SetEncoderScalingFactor: > 0, absolute by default', () => {
    expect(encoderScalingBody({ ...ENCODER_SCALING_DEFAULTS, scaling_factor: '0.001' })).toEqual({ body: { scaling_factor: 0.001, mode: 'absolute' }, errors: {} });
    expect(encoderScalingBody({ scaling_factor: '1.001', mode: 'relative' }).body).toEqual({ scaling_factor: 1.001, mode: 'relative' });
    expect(encoderScalingBody({ scaling_factor: '1', mode: '' }).body).toEqual({ scaling_factor: 1 });
    expect(encoderScalingBody({ ...ENCODER_SCALING_DEFAULTS, scaling_factor: '0' }).errors).toEqual({ scaling_factor: 'must be ≥ 1e-12' });
    expect(encoderScalingBody(ENCODER_SCALING_DEFAULTS).errors).toEqual({ scaling_factor: 'enter a value' });
  });
  it('the conversions: a whole count, a position', () => {
    expect(incPosQuery({ inc_pos: '100' })).toEqual({ body: 'inc_pos=100', errors: {} });
    expect(incPosQuery({ inc_pos: '1.5' }).errors).toEqual({ inc_pos: 'must be a whole number' });
    expect(incPosQuery({ inc_pos: '-1' }).errors).toEqual({ inc_pos: 'must be ≥ 0' });
    expect(incPosQuery({ inc_pos: '' }).errors).toEqual({ inc_pos: 'enter a value' });
    expect(posQuery({ position: '12,5' })).toEqual({ body: 'position=12.5', errors: {} });
    expect(posQuery({ position: 'abc' }).errors).toEqual({ position: 'enter a number' });
  });
});
