// The request bodies of the Coupling and Functions tabs, built from the forms' text inputs
// (pure: tested without a DOM). An empty optional input is left out, so that the server's
// default applies; a text that is no number is sent as NaN → null for the server to refuse
// at its field.
import type { components } from '../api/schema';
import { NOT_A_NUMBER } from '../api/problem';

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
export type PhasingBody = S['PhasingBody'];
export type HaltPhasingBody = S['HaltPhasingBody'];
export type GearInMultiMasterBody = S['GearInMultiMasterBody'];
export type MultiMasterSyncMode = S['MultiMasterSyncMode'];
export type TorqueControlBody = S['TorqueControlBody'];
export type WriteDriveOperationModeBody = S['WriteDriveOperationModeBody'];
export type DriveMode = S['DriveMode'];
export type DriveOperationModeResource = S['DriveOperationModeResource'];
export type PositionCorrectionLimiterBody = S['PositionCorrectionLimiterBody'];
export type PositionCorrectionMode = S['PositionCorrectionMode'];
export type PositionCorrectionStatus = S['PositionCorrectionStatus'];
export type BacklashCompensationBody = S['BacklashCompensationBody'];
export type TableCompensationBody = S['TableCompensationBody'];
export type DisableMode = S['DisableMode'];
export type SetEncoderScalingFactorBody = S['SetEncoderScalingFactorBody'];
export type EncoderScalingMode = S['EncoderScalingMode'];
export type PositionConversion = S['PositionConversion'];

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

/**
 * MC_Home: blank options are left out (the axis's parameters #1073/#1074/#1012/#1013/#1076 apply).
 * `inDrive`: the drive homes with its own method (axis/drive-executed.ts), so motiond's
 * referencing options are not sent.
 */
export function homeBody(f: Form, inDrive = false): Built<HomeBody> {
  const options = inDrive ? {} : clean({
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

// ---- the single-axis blocks beyond moving (docs/single-axis-blocks.md) --------------------
// Their numbers are checked here as the schema states them (required, ≥ / > a bound, whole
// numbers), so that a form with a mistake is never sent; a blank optional input is left out
// (the server's default: the axis's dynamics, #1036 …). The server's own refusals are shown
// at the same fields.

interface NumRule {
  required?: boolean;
  /** Lower bound; `above`: exclusive. */
  min?: number;
  above?: boolean;
  max?: number;
  integer?: boolean;
}

/** The number of `f[key]` by `rule`: undefined when blank (and optional), NaN with an error. */
function checkNum(f: Form, key: string, errors: Record<string, string>, rule: NumRule = {}): number | undefined {
  const v = optNum(f[key]);
  if (v === undefined) {
    if (rule.required) errors[key] = 'enter a value';
    return rule.required ? NaN : undefined;
  }
  if (!Number.isFinite(v)) errors[key] = NOT_A_NUMBER;
  else if (rule.integer && !Number.isInteger(v)) errors[key] = 'must be a whole number';
  else if (rule.min !== undefined && (rule.above ? v <= rule.min : v < rule.min)) errors[key] = `must be ${rule.above ? '>' : '≥'} ${rule.min}`;
  else if (rule.max !== undefined && v > rule.max) errors[key] = `must be ≤ ${rule.max}`;
  return v;
}

/** MC_PhasingAbsolute / MC_PhasingRelative and MC_HaltPhasing share one form. */
export const PHASING_DEFAULTS: Form = { master: '', phase_shift: '0', velocity: '', acceleration: '', deceleration: '', jerk: '' };

/** MC_PhasingAbsolute / Relative: velocity ≥ 0.01; blank acceleration, deceleration, jerk = the axis's. */
export function phasingBody(f: Form): Built<PhasingBody> {
  const errors: Record<string, string> = {};
  if (!f.master) errors.master = 'choose a master axis';
  const body = clean({
    master: f.master ?? '',
    phase_shift: checkNum(f, 'phase_shift', errors, { required: true }) as number,
    velocity: checkNum(f, 'velocity', errors, { required: true, min: 0.01 }) as number,
    acceleration: checkNum(f, 'acceleration', errors, { min: 0 }),
    deceleration: checkNum(f, 'deceleration', errors, { min: 0 }),
    jerk: checkNum(f, 'jerk', errors, { min: 0 }),
  });
  return { body, errors };
}

/** MC_HaltPhasing: the master, and the deceleration and jerk (blank = the axis's). */
export function haltPhasingBody(f: Form): Built<HaltPhasingBody> {
  const errors: Record<string, string> = {};
  if (!f.master) errors.master = 'choose a master axis';
  const body = clean({ master: f.master ?? '', deceleration: checkNum(f, 'deceleration', errors, { min: 0 }), jerk: checkNum(f, 'jerk', errors, { min: 0 }) });
  return { body, errors };
}

/** MC_GearInMultiMaster: Master1…Master4 (form keys master1…4, ratio1…4). */
export const MULTI_MASTER_ROWS = [1, 2, 3, 4] as const;
export const SYNC_MODES: MultiMasterSyncMode[] = ['velosync', 'possync1', 'possync2'];
export const MULTI_MASTER_DEFAULTS: Form = {
  master1: '',
  ratio1: '1',
  master2: '',
  ratio2: '1',
  master3: '',
  ratio3: '1',
  master4: '',
  ratio4: '1',
  acceleration: '',
  deceleration: '',
  jerk: '',
  advanced_slave_dynamics: '',
  sync_mode: 'velosync',
};

/** The form rows that name a master (a blank master = an unused row), in order. */
export function multiMasterRows(f: Form): number[] {
  return MULTI_MASTER_ROWS.filter((i) => !!f[`master${i}`]);
}

/**
 * MC_GearInMultiMaster: the rows with a master, in order (each with its ratio); deceleration,
 * jerk and the sync mode only with advanced slave dynamics (they mean nothing without).
 */
export function gearInMultiMasterBody(f: Form): Built<GearInMultiMasterBody> {
  const errors: Record<string, string> = {};
  const rows = multiMasterRows(f);
  if (!rows.length) errors.master1 = 'choose at least one master';
  const seen = new Set<string>();
  for (const i of rows) {
    const m = f[`master${i}`];
    if (seen.has(m)) errors[`master${i}`] = 'names a master twice';
    seen.add(m);
  }
  const masters = rows.map((i) => ({ master: f[`master${i}`], gear_ratio: checkNum(f, `ratio${i}`, errors, { required: true }) as number }));
  const adv = f.advanced_slave_dynamics === '1';
  const body = clean({
    masters,
    acceleration: checkNum(f, 'acceleration', errors, { min: 0 }),
    deceleration: adv ? checkNum(f, 'deceleration', errors, { min: 0 }) : undefined,
    jerk: adv ? checkNum(f, 'jerk', errors, { min: 0 }) : undefined,
    advanced_slave_dynamics: adv ? true : undefined,
    sync_mode: adv && f.sync_mode ? (f.sync_mode as MultiMasterSyncMode) : undefined,
  });
  return { body, errors };
}

/**
 * The server's field errors of a multi-master body at the form's fields: `masters[j].master`
 * and `masters[j].gear_ratio` count the masters sent, which skip the blank rows.
 */
export function multiMasterFields(f: Form, fields: Record<string, string>): Record<string, string> {
  const rows = multiMasterRows(f);
  const out: Record<string, string> = {};
  for (const [k, v] of Object.entries(fields)) {
    const m = /^masters\[(\d+)\](?:\.(master|gear_ratio))?$/.exec(k);
    const row = m ? rows[Number(m[1])] : undefined;
    const key = !m ? (k === 'masters' ? 'master1' : k) : row === undefined ? 'master1' : m[2] === 'gear_ratio' ? `ratio${row}` : `master${row}`;
    out[key] = out[key] ? `${out[key]}; ${v}` : v;
  }
  return out;
}

/** The form rows of a multi-master command's masters (`parameters.masters`), for a page that finds one running. */
export function multiMasterForm(parameters: unknown): Form {
  const ms = (parameters as { masters?: { master?: unknown; gear_ratio?: unknown }[] } | null)?.masters;
  const out: Form = {};
  for (const i of MULTI_MASTER_ROWS) {
    const m = Array.isArray(ms) ? ms[i - 1] : undefined;
    out[`master${i}`] = typeof m?.master === 'string' ? m.master : '';
    out[`ratio${i}`] = typeof m?.gear_ratio === 'number' ? String(m.gear_ratio) : '1';
  }
  return out;
}

/** MC_TorqueControl. */
export const TORQUE_DEFAULTS: Form = { torque: '', torque_ramp: '10', velocity_limit_high: '', velocity_limit_low: '', relative: '', manual_start_torque: '' };

/** MC_TorqueControl: torque (%) and ramp (%/s, > 0), the velocity limits (low ≤ high); blank start torque = the drive's. */
export function torqueControlBody(f: Form): Built<TorqueControlBody> {
  const errors: Record<string, string> = {};
  const high = checkNum(f, 'velocity_limit_high', errors, { required: true }) as number;
  const low = checkNum(f, 'velocity_limit_low', errors, { required: true }) as number;
  if (!errors.velocity_limit_high && !errors.velocity_limit_low && low > high) errors.velocity_limit_low = 'must be ≤ the high limit';
  const body = clean({
    torque: checkNum(f, 'torque', errors, { required: true, min: -1000, max: 1000 }) as number,
    torque_ramp: checkNum(f, 'torque_ramp', errors, { required: true, min: 0, above: true }) as number,
    relative: f.relative === '1' ? true : undefined,
    velocity_limit_high: high,
    velocity_limit_low: low,
    manual_start_torque: checkNum(f, 'manual_start_torque', errors, { min: -1000, max: 1000 }),
  });
  return { body, errors };
}

/** MC_WriteDriveOperationMode takes the position-based modes (torque is MC_TorqueControl's). */
export const WRITABLE_DRIVE_MODES: DriveMode[] = ['configured', 'position', 'velocity'];

export function writeDriveModeBody(f: Form): Built<WriteDriveOperationModeBody> {
  const errors: Record<string, string> = {};
  const m = f.drive_operation_mode as DriveMode;
  if (!WRITABLE_DRIVE_MODES.includes(m)) errors.drive_operation_mode = 'choose configured, position or velocity';
  return { body: { drive_operation_mode: m }, errors };
}

/** MC_PositionCorrectionLimiter. */
export const CORRECTION_MODES: PositionCorrectionMode[] = ['unlimited', 'fast', 'full_length'];
export const DISABLE_MODES: DisableMode[] = ['hold', 'reset'];
export const LIMITER_DEFAULTS: Form = { value: '', mode: 'unlimited', acceleration: '', correction_length: '' };

/** The acceleration goes with `fast` (blank = no limitation), the correction length (> 0) with `full_length`. */
export function limiterBody(f: Form): Built<PositionCorrectionLimiterBody> {
  const errors: Record<string, string> = {};
  const mode = (f.mode || undefined) as PositionCorrectionMode | undefined;
  const body = clean({
    value: checkNum(f, 'value', errors, { required: true }) as number,
    mode,
    acceleration: mode === 'fast' ? checkNum(f, 'acceleration', errors, { min: 0 }) : undefined,
    correction_length: mode === 'full_length' ? checkNum(f, 'correction_length', errors, { required: true, min: 0, above: true }) : undefined,
  });
  return { body, errors };
}

/** MC_BacklashCompensation. */
export const BACKLASH_DEFAULTS: Form = { backlash: '', compensate_in_positive_direction: '', ramp: '', disable_mode: 'hold' };

/** Blank backlash = AxisBacklash (#1036); the ramp (units/s) must be > 0. */
export function backlashBody(f: Form): Built<BacklashCompensationBody> {
  const errors: Record<string, string> = {};
  const body = clean({
    backlash: checkNum(f, 'backlash', errors),
    compensate_in_positive_direction: f.compensate_in_positive_direction === '1' ? true : undefined,
    ramp: checkNum(f, 'ramp', errors, { required: true, min: 0, above: true }) as number,
    disable_mode: (f.disable_mode || undefined) as DisableMode | undefined,
  });
  return { body, errors };
}

/** MC_TableBasedPositionCompensation (the table: `position_compensation_table` of the axis configuration). */
export const TABLE_COMPENSATION_DEFAULTS: Form = { ramp: '', disable_mode: 'hold' };

export function tableCompensationBody(f: Form): Built<TableCompensationBody> {
  const errors: Record<string, string> = {};
  const body = clean({
    ramp: checkNum(f, 'ramp', errors, { required: true, min: 0, above: true }) as number,
    disable_mode: (f.disable_mode || undefined) as DisableMode | undefined,
  });
  return { body, errors };
}

/** The sources of the position correction: key, label, value, enabled, limiting (the sum last). */
export function correctionRows(c: PositionCorrectionStatus | null | undefined): [string, string, number, boolean, boolean][] {
  if (!c) return [];
  return [
    ['limiter', 'Limiter', c.limiter, c.limiter_enabled, c.limiter_limiting],
    ['backlash', 'Backlash', c.backlash, c.backlash_enabled, c.backlash_limiting],
    ['table', 'Table', c.table, c.table_enabled, c.table_limiting],
  ];
}

/** MC_SetEncoderScalingFactor (mode absolute: the server's default). */
export const ENCODER_SCALING_MODES: EncoderScalingMode[] = ['absolute', 'relative'];
export const ENCODER_SCALING_DEFAULTS: Form = { scaling_factor: '', mode: 'absolute' };

export function encoderScalingBody(f: Form): Built<SetEncoderScalingFactorBody> {
  const errors: Record<string, string> = {};
  const body = clean({
    scaling_factor: checkNum(f, 'scaling_factor', errors, { required: true, min: 1e-12, max: 1e12 }) as number,
    mode: (f.mode || undefined) as EncoderScalingMode | undefined,
  });
  return { body, errors };
}

/** MC_ConvertIncPosToPos's query parameters: an encoder count (UDINT). */
export function incPosParams(f: Form): Built<{ inc_pos: number }> {
  const errors: Record<string, string> = {};
  const v = checkNum(f, 'inc_pos', errors, { required: true, integer: true, min: 0, max: 4294967295 }) as number;
  return { body: { inc_pos: v }, errors };
}

/** MC_ConvertPosToIncPos's query parameters: an axis position. */
export function posParams(f: Form): Built<{ position: number }> {
  const errors: Record<string, string> = {};
  const v = checkNum(f, 'position', errors, { required: true, min: -1e12, max: 1e12 }) as number;
  return { body: { position: v }, errors };
}

/** A query's parameters as its text: `{ inc_pos: 100 }` → `inc_pos=100`. */
const queryText = <T extends object>(b: Built<T>): Built<string> => ({ body: new URLSearchParams(Object.entries(b.body).map(([k, v]) => [k, String(v)])).toString(), errors: b.errors });

/** MC_ConvertIncPosToPos's query as sent: `inc_pos=100`. */
export const incPosQuery = (f: Form): Built<string> => queryText(incPosParams(f));

/** MC_ConvertPosToIncPos's query as sent: `position=12.5`. */
export const posQuery = (f: Form): Built<string> => queryText(posParams(f));
