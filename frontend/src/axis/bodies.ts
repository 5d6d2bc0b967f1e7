// The request bodies of the Coupling and Functions tabs, built from the forms' text inputs
// (pure: tested without a DOM). An empty optional input is left out, so that the server's
// default applies; a text that is no number is sent as NaN → null for the server to refuse
// at its field.
import type { components } from '../api/schema';

type S = components['schemas'];
export type GearInBody = S['GearInBody'];
export type GearInDynBody = S['GearInDynBody'];
export type CamInBody = S['CamInBody'];
export type CamScalingBody = S['CamScalingBody'];
export type MoveSuperImposedBody = S['MoveSuperImposedBody'];
export type HomeBody = S['HomeBody'];
export type StartMode = S['StartMode'];
export type CamActivationMode = S['CamActivationMode'];
export type CamScalingMode = S['CamScalingMode'];
export type SuperpositionMode = S['SuperpositionMode'];
export type SuperpositionAbortOption = S['SuperpositionAbortOption'];
export type ReferenceMode = S['ReferenceMode'];
export type Direction = S['Direction'];
export type CamInfo = S['CamInfo'];

export type Form = Record<string, string>;

export interface Built<T> {
  body: T;
  errors: Record<string, string>;
}

/** '' → undefined; else the number (NaN for text that is none). */
export function optNum(s: string | undefined): number | undefined {
  const t = (s ?? '').trim().replace(',', '.');
  return t === '' ? undefined : Number(t);
}

function required(f: Form, key: string, errors: Record<string, string>, what = 'enter a value'): number {
  const v = optNum(f[key]);
  if (v === undefined) {
    errors[key] = what;
    return NaN;
  }
  return v;
}

/** Drops the undefined members (JSON would too, but tests compare objects). */
function clean<T extends object>(o: T): T {
  return Object.fromEntries(Object.entries(o).filter(([, v]) => v !== undefined)) as T;
}

export function gearInBody(f: Form): Built<GearInBody> {
  const errors: Record<string, string> = {};
  if (!f.master) errors.master = 'choose a master axis';
  const body = {
    master: f.master ?? '',
    ratio_numerator: required(f, 'ratio_numerator', errors),
    ratio_denominator: required(f, 'ratio_denominator', errors),
  };
  return { body, errors };
}

export function gearInDynBody(f: Form): Built<GearInDynBody> {
  const errors: Record<string, string> = {};
  if (!f.master) errors.master = 'choose a master axis';
  const body = clean({ master: f.master ?? '', gear_ratio: required(f, 'gear_ratio', errors), acceleration: optNum(f.acceleration) });
  return { body, errors };
}

export const START_MODES: StartMode[] = ['absolute', 'relative', 'master_abs_slave_rel', 'master_rel_slave_abs', 'ramp_in', 'ramp_in_positive', 'ramp_in_negative'];
export const ACTIVATION_MODES: CamActivationMode[] = [
  'instantaneous',
  'at_master_cam_pos',
  'at_master_axis_pos',
  'at_master_axis_pos_positive_direction',
  'at_master_axis_pos_negative_direction',
  'next_cycle',
  'next_cycle_once',
  'as_soon_as_possible',
  'off',
  'delete_queued_data',
];
export const SCALING_MODES: CamScalingMode[] = ['user_defined', 'auto_offset', 'off'];
export const SUPERPOSITION_MODES: SuperpositionMode[] = [
  'velo_reduction_additive_motion',
  'velo_reduction_limited_motion',
  'length_reduction_additive_motion',
  'length_reduction_limited_motion',
  'acc_reduction_additive_motion',
  'acc_reduction_limited_motion',
];
export const ABORT_OPTIONS: SuperpositionAbortOption[] = ['abort_at_standstill', 'resume_after_standstill', 'resume_after_motion_stop'];
export const REFERENCE_MODES: ReferenceMode[] = ['default', 'plc_cam', 'hardware_sync', 'hardware_latch_pos', 'hardware_latch_neg', 'software_sync', 'soft_drive_latch_pos', 'soft_drive_latch_neg'];

/** The defaults of a CamIn form (CamInBody's documented defaults). */
export const CAM_IN_DEFAULTS: Form = {
  master: '',
  cam_table: '',
  master_offset: '0',
  slave_offset: '0',
  master_scaling: '1',
  slave_scaling: '1',
  start_mode: 'absolute',
  activation_mode: 'instantaneous',
  activation_position: '0',
  master_scaling_mode: 'user_defined',
  slave_scaling_mode: 'user_defined',
  interpolation: '',
  ramp_velocity: '',
  ramp_acceleration: '',
};

export const CAM_SCALING_DEFAULTS: Form = {
  master_offset: '0',
  slave_offset: '0',
  master_scaling: '1',
  slave_scaling: '1',
  activation_mode: 'instantaneous',
  activation_position: '0',
  master_scaling_mode: 'user_defined',
  slave_scaling_mode: 'user_defined',
};

/** Whether the activation mode takes a position. */
export const takesPosition = (m: string) => m.startsWith('at_master');

export function camInBody(f: Form): Built<CamInBody> {
  const errors: Record<string, string> = {};
  if (!f.master) errors.master = 'choose a master axis';
  if (!f.cam_table) errors.cam_table = 'choose a cam table';
  const ramp = (f.start_mode ?? '').startsWith('ramp_in');
  if (ramp && optNum(f.ramp_velocity) === undefined) errors['ramp_in.velocity'] = 'a ramp-in needs a velocity';
  const body = clean({
    master: f.master ?? '',
    cam_table: f.cam_table ?? '',
    master_offset: optNum(f.master_offset),
    slave_offset: optNum(f.slave_offset),
    master_scaling: optNum(f.master_scaling),
    slave_scaling: optNum(f.slave_scaling),
    start_mode: (f.start_mode || undefined) as StartMode | undefined,
    activation_mode: (f.activation_mode || undefined) as CamActivationMode | undefined,
    activation_position: takesPosition(f.activation_mode ?? '') ? optNum(f.activation_position) : undefined,
    master_scaling_mode: (f.master_scaling_mode || undefined) as CamScalingMode | undefined,
    slave_scaling_mode: (f.slave_scaling_mode || undefined) as CamScalingMode | undefined,
    interpolation: (f.interpolation || undefined) as CamInBody['interpolation'],
    ramp_in: ramp ? clean({ velocity: optNum(f.ramp_velocity), acceleration: optNum(f.ramp_acceleration) }) : undefined,
  }) as CamInBody;
  return { body, errors };
}

export function camScalingBody(f: Form): Built<CamScalingBody> {
  const body = clean({
    master_offset: optNum(f.master_offset),
    slave_offset: optNum(f.slave_offset),
    master_scaling: optNum(f.master_scaling),
    slave_scaling: optNum(f.slave_scaling),
    activation_mode: (f.activation_mode || undefined) as CamActivationMode | undefined,
    activation_position: takesPosition(f.activation_mode ?? '') ? optNum(f.activation_position) : undefined,
    master_scaling_mode: (f.master_scaling_mode || undefined) as CamScalingMode | undefined,
    slave_scaling_mode: (f.slave_scaling_mode || undefined) as CamScalingMode | undefined,
  }) as CamScalingBody;
  return { body, errors: {} };
}

export const SUPERIMPOSED_DEFAULTS: Form = {
  mode: 'velo_reduction_additive_motion',
  distance: '',
  velocity_diff: '',
  acceleration: '0',
  deceleration: '0',
  velocity_process: '',
  length: '',
  abort_option: 'abort_at_standstill',
};

export function superimposedBody(f: Form): Built<MoveSuperImposedBody> {
  const errors: Record<string, string> = {};
  const body = clean({
    mode: (f.mode || undefined) as SuperpositionMode | undefined,
    distance: required(f, 'distance', errors),
    velocity_diff: required(f, 'velocity_diff', errors),
    acceleration: optNum(f.acceleration),
    deceleration: optNum(f.deceleration),
    velocity_process: required(f, 'velocity_process', errors),
    length: required(f, 'length', errors),
    abort_option: (f.abort_option || undefined) as SuperpositionAbortOption | undefined,
  }) as MoveSuperImposedBody;
  return { body, errors };
}

export const HOME_DEFAULTS: Form = {
  mode: 'default',
  position: '',
  reference_mode: '',
  search_direction: '',
  search_velocity: '',
  sync_direction: '',
  sync_velocity: '',
  clear_position_lag: '',
};

/** MC_Home: blank options are left out (the axis's parameters #1073/#1074/#1012/#1013/#1076 apply). */
export function homeBody(f: Form): Built<HomeBody> {
  const options = clean({
    reference_mode: (f.reference_mode || undefined) as ReferenceMode | undefined,
    search_direction: (f.search_direction || undefined) as Direction | undefined,
    search_velocity: optNum(f.search_velocity),
    sync_direction: (f.sync_direction || undefined) as Direction | undefined,
    sync_velocity: optNum(f.sync_velocity),
    clear_position_lag: f.clear_position_lag === '1' ? true : undefined,
  });
  const body = clean({
    mode: (f.mode || undefined) as HomeBody['mode'],
    position: optNum(f.position),
    options: Object.keys(options).length ? options : undefined,
  }) as HomeBody;
  return { body, errors: {} };
}

/** The rows of the CamInfo table: label, value. */
export function camInfoRows(c: CamInfo | null | undefined): [string, string, string][] {
  if (!c) return [];
  const n = (v: number) => (Number.isFinite(v) ? String(Math.round(v * 10000) / 10000) : '—');
  const b = (v: boolean) => (v ? 'yes' : 'no');
  return [
    ['cam_table_id', 'Cam table', c.cam_table_id ? String(c.cam_table_id) : '—'],
    ['active', 'Active', b(c.active)],
    ['periodic', 'Periodic', b(c.periodic)],
    ['master_offset', 'Master offset', n(c.master_offset)],
    ['slave_offset', 'Slave offset', n(c.slave_offset)],
    ['master_scaling', 'Master scaling', n(c.master_scaling)],
    ['slave_scaling', 'Slave scaling', n(c.slave_scaling)],
    ['actual_master_cam_pos', 'Master cam pos', n(c.actual_master_cam_pos)],
    ['actual_slave_cam_pos', 'Slave cam pos', n(c.actual_slave_cam_pos)],
    ['raw_master_period', 'Master period', n(c.raw_master_period)],
    ['raw_slave_stroke', 'Slave stroke', n(c.raw_slave_stroke)],
    ['sum_of_slave_strokes', 'Sum of strokes', n(c.sum_of_slave_strokes)],
    ['scaling_pending', 'Scaling pending', b(c.scaling_pending)],
  ];
}

/** Labels of enum values for the selects: `at_master_axis_pos` → `at master axis pos`. */
export const label = (v: string) => v.replace(/_/g, ' ');
