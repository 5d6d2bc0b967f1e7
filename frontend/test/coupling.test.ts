// The bodies of the Coupling tab's blocks, built from the forms' text inputs.
import { describe, expect, it } from 'vitest';
import { CAM_IN_DEFAULTS, CAM_SCALING_DEFAULTS, SUPERIMPOSED_DEFAULTS, camInBody, camInfoRows, camScalingBody, gearInBody, gearInDynBody, superimposedBody } from '../src/axis/bodies';
import { parseRoute, href } from '../src/router';
import { nonFiniteFields } from '../src/api/problem';
import { couplingInForce } from '../src/axis/coupling-kind';

describe('gear bodies', () => {
  it('MC_GearIn: master and ratio', () => {
    expect(gearInBody({ master: 'x', ratio_numerator: '1', ratio_denominator: '2' })).toEqual({ body: { master: 'x', ratio_numerator: 1, ratio_denominator: 2 }, errors: {} });
  });
  it('MC_GearIn: a missing master or ratio is named at its field', () => {
    expect(gearInBody({ master: '', ratio_numerator: '', ratio_denominator: '1' }).errors).toEqual({ master: 'choose a master axis', ratio_numerator: 'enter a value' });
  });
  it('text that is no number is NaN in the body, which the REST client never sends (NotSentError: "enter a number" at its field)', () => {
    expect(gearInBody({ master: 'x', ratio_numerator: 'abc', ratio_denominator: '1' }).body).toEqual({ master: 'x', ratio_numerator: NaN, ratio_denominator: 1 });
    expect(nonFiniteFields(gearInBody({ master: 'x', ratio_numerator: 'abc', ratio_denominator: '1' }).body)).toEqual(['ratio_numerator']);
  });
  it('MC_GearInDyn: blank acceleration is left out', () => {
    expect(gearInDynBody({ master: 'x', gear_ratio: '1.5', acceleration: '' }).body).toEqual({ master: 'x', gear_ratio: 1.5 });
    expect(gearInDynBody({ master: 'x', gear_ratio: '-2', acceleration: '500' }).body).toEqual({ master: 'x', gear_ratio: -2, acceleration: 500 });
  });
});

describe('cam bodies', () => {
  it('MC_CamIn with the documented defaults', () => {
    expect(camInBody({ ...CAM_IN_DEFAULTS, master: 'x', cam_table: 'knife' }).body).toEqual({
      master: 'x',
      cam_table: 'knife',
      master_offset: 0,
      slave_offset: 0,
      master_scaling: 1,
      slave_scaling: 1,
      start_mode: 'absolute',
      activation_mode: 'instantaneous',
      master_scaling_mode: 'user_defined',
      slave_scaling_mode: 'user_defined',
    });
  });
  it('an activation at a position sends it; a ramp-in needs its velocity', () => {
    const b = camInBody({ ...CAM_IN_DEFAULTS, master: 'x', cam_table: '1', activation_mode: 'at_master_axis_pos', activation_position: '120', start_mode: 'ramp_in', ramp_velocity: '50' }).body;
    expect(b.activation_position).toBe(120);
    expect(b.ramp_in).toEqual({ velocity: 50 });
    expect(camInBody({ ...CAM_IN_DEFAULTS, master: 'x', cam_table: '1', start_mode: 'ramp_in' }).errors).toEqual({ 'ramp_in.velocity': 'a ramp-in needs a velocity' });
    expect(camInBody({ ...CAM_IN_DEFAULTS }).errors).toEqual({ master: 'choose a master axis', cam_table: 'choose a cam table' });
  });
  it('MC_CamScaling', () => {
    expect(camScalingBody({ ...CAM_SCALING_DEFAULTS, slave_scaling: '2', slave_scaling_mode: 'auto_offset' }).body).toEqual({
      master_offset: 0,
      slave_offset: 0,
      master_scaling: 1,
      slave_scaling: 2,
      activation_mode: 'instantaneous',
      master_scaling_mode: 'user_defined',
      slave_scaling_mode: 'auto_offset',
    });
  });
  it('the CamInfo table rows', () => {
    expect(camInfoRows(null)).toEqual([]);
    const rows = camInfoRows({ cam_table_id: 3, active: true, master_scaling: 1 / 3, periodic: false } as never);
    expect(rows[0]).toEqual(['cam_table_id', 'Cam table', '3']);
    expect(rows.find((r) => r[0] === 'master_scaling')?.[2]).toBe('0.3333');
  });
});

describe('superposition body', () => {
  it('requires distance, velocity diff, process velocity and length', () => {
    expect(superimposedBody(SUPERIMPOSED_DEFAULTS).errors).toEqual({ distance: 'enter a value', velocity_diff: 'enter a value', velocity_process: 'enter a value', length: 'enter a value' });
    expect(superimposedBody({ ...SUPERIMPOSED_DEFAULTS, distance: '10', velocity_diff: '50', velocity_process: '200', length: '200' }).body).toEqual({
      mode: 'velo_reduction_additive_motion',
      distance: 10,
      velocity_diff: 50,
      acceleration: 0,
      deceleration: 0,
      velocity_process: 200,
      length: 200,
      abort_option: 'abort_at_standstill',
    });
  });
});

describe('routes of the new tabs', () => {
  it('coupling and functions', () => {
    expect(parseRoute('#/axes/y/coupling')).toEqual({ page: 'axis', axis: 'y', tab: 'coupling' });
    expect(parseRoute('#/axes/y/functions')).toEqual({ page: 'axis', axis: 'y', tab: 'functions' });
    expect(href({ page: 'axis', axis: 'x', tab: 'coupling' })).toBe('#/axes/x/coupling');
  });
});

describe('the coupling in force', () => {
  const cam = (id: number, active = true) => ({ cam_table_id: id, active }) as never;
  const st = (o: Record<string, unknown>) => ({ coupled: true, master: 'x', gear_ratio: 0, gear_ratios: [0, 0, 0, 0], cam: cam(0, false), ...o }) as never;
  it('a cam slave is a cam coupling — its ratios of 0 are no multi-master gear', () => {
    expect(couplingInForce(st({ cam: cam(3) }), { command: 'cam-in', state: 'active' })).toEqual({ kind: 'cam', master: 'x', text: 'cam table 3 (MC_CamIn)' });
    expect(couplingInForce(st({ cam: cam(3) }), null)).toEqual({ kind: 'cam', master: 'x', text: 'cam table 3' });
    // coupled by MC_CamIn, the cam not yet active (waiting for its activation)
    expect(couplingInForce(st({}), { command: 'cam-in', state: 'active' }).kind).toBe('cam');
  });
  it('a multi-master coupling: by its command, or (no command known) by a second master’s ratio', () => {
    expect(couplingInForce(st({ gear_ratio: 2, gear_ratios: [2, 0, 0, 0] }), { command: 'gear-in-multi-master', state: 'done' }).kind).toBe('multi-master');
    expect(couplingInForce(st({ gear_ratio: 1, gear_ratios: [1, 0.5, 0, 0] }), null).kind).toBe('multi-master');
    expect(couplingInForce(st({ gear_ratio: 1, gear_ratios: [1, 0, 0, 0] }), null).kind).toBe('gear');
  });
  it('a gear: its ratio and the block', () => {
    expect(couplingInForce(st({ gear_ratio: 0.5, gear_ratios: [0.5, 0, 0, 0] }), { command: 'gear-in', state: 'done' })).toEqual({ kind: 'gear', master: 'x', text: 'gear ratio 0.5 (MC_GearIn)' });
    expect(couplingInForce(st({ gear_ratio: 1.5 }), { command: 'gear-in-dyn', state: 'active' }).text).toBe('gear ratio 1.5 (MC_GearInDyn)');
    // a coupling command that failed coupled nothing: what coupled the axis is not known
    expect(couplingInForce(st({ gear_ratio: 0.5, gear_ratios: [0.5, 0, 0, 0] }), { command: 'gear-in-multi-master', state: 'error' }).kind).toBe('gear');
  });
  it('not coupled', () => {
    expect(couplingInForce(st({ coupled: false, master: null }), { command: 'gear-in-multi-master', state: 'done' })).toEqual({ kind: 'none', master: null, text: 'not coupled' });
    expect(couplingInForce(null, null).kind).toBe('none');
  });
});
