// An axis whose CiA-402 drive runs the motion profile itself (TwinCAT Drive Motion Control:
// `drive.profile = "drive"`, `status.drive_executed`; decisions 167–168): the blocks it offers,
// the inputs it lacks, and the drive's homing methods (0x6098). Pure: tested without a DOM.
// The UI offers only these blocks there and never sends another; the server refuses the rest
// with 409 `not_on_drive_executed_axis` / `input_not_on_drive_executed_axis` all the same.
import type { BlockName } from '../api/blocks';
import type { AxisConfig, AxisStatus, HomingMode } from '../api/types';

/** The blocks an axis whose drive runs the profile takes (DMC's set; parameter reads and writes besides). */
export const DRIVE_EXECUTED_BLOCKS = [
  'power',
  'reset',
  'set-position',
  'home',
  'jog',
  'halt',
  'move-absolute',
  'move-relative',
  'move-modulo',
  'move-velocity',
  'stop',
  'touch-probe',
  'abort-trigger',
] as const satisfies readonly BlockName[];

/** Why a block is not offered on such an axis (a panel's note, a button's title). */
export const NOT_OFFERED = 'not offered when the drive runs the profile (Drive Motion Control)';

/** What the axis page says about such an axis. */
export const DRIVE_EXECUTED_TEXT = 'the drive executes the profile (Drive Motion Control)';

/** Whether the configuration says the drive runs the profile (a CiA-402 drive with `profile: "drive"`). */
export function configuredDriveExecuted(c: Pick<AxisConfig, 'drive'> | null | undefined): boolean {
  return c?.drive?.kind === 'cia402' && c.drive.profile === 'drive';
}

/**
 * Whether the drive runs the axis's profile: the live status says so (`drive_executed`); until
 * a status has come, the configuration does — so no block is offered for a moment that the axis
 * then refuses.
 */
export function isDriveExecuted(c: Pick<AxisConfig, 'drive'> | null | undefined, s: Pick<AxisStatus, 'drive_executed'> | null | undefined): boolean {
  return typeof s?.drive_executed === 'boolean' ? s.drive_executed : configuredDriveExecuted(c);
}

const OFFERED: ReadonlySet<string> = new Set(DRIVE_EXECUTED_BLOCKS);

/** Whether block `name` is offered on an axis whose drive runs the profile. */
export function offeredOnDrive(name: string): boolean {
  return OFFERED.has(name);
}

/** The reason block `name` is not offered on this axis, or null (offered). */
export function notOffered(name: BlockName, driveExecuted: boolean): string | null {
  return driveExecuted && !offeredOnDrive(name) ? NOT_OFFERED : null;
}

/** What a drive-executed axis refuses of a command: the block, or inputs by their field path. */
export interface DriveRefusal {
  code: 'not_on_drive_executed_axis' | 'input_not_on_drive_executed_axis';
  detail: string;
  /** Field path → message (the inputs the drive lacks). */
  fields: Record<string, string>;
}

const num = (v: unknown): number | null => (typeof v === 'number' && !Number.isNaN(v) ? v : null);

/**
 * What an axis whose drive runs the profile would refuse of block `name` with `body` (as the
 * kernel's admission does: not a DMC block, inching, jerk ≠ 0, a buffer mode other than
 * aborting, a power override other than 100 %), or null: it takes it.
 */
export function driveRefusal(name: string, body: unknown): DriveRefusal | null {
  if (!offeredOnDrive(name)) return { code: 'not_on_drive_executed_axis', detail: `${name} is ${NOT_OFFERED}`, fields: {} };
  const b = (body && typeof body === 'object' ? body : {}) as Record<string, unknown>;
  if (name === 'jog' && (b.mode === 'inching' || b.mode === 'inching_modulo')) {
    return { code: 'not_on_drive_executed_axis', detail: `inching is ${NOT_OFFERED}: hold a jog button`, fields: {} };
  }
  const fields: Record<string, string> = {};
  const jerk = num(b.jerk);
  if (jerk !== null && jerk !== 0 && ['move-absolute', 'move-relative', 'move-modulo', 'move-velocity', 'halt', 'stop', 'jog'].includes(name)) {
    fields.jerk = 'no jerk when the drive runs the profile (leave it 0)';
  }
  if (b.buffer_mode !== undefined && b.buffer_mode !== null && b.buffer_mode !== 'aborting') {
    fields.buffer_mode = 'only aborting when the drive runs the profile';
  }
  const override = num(b.override_percent);
  if (name === 'power' && override !== null && override !== 100) {
    fields.override_percent = 'only 100 % when the drive runs the profile';
  }
  if (!Object.keys(fields).length) return null;
  return { code: 'input_not_on_drive_executed_axis', detail: `the drive runs this axis's profile: ${Object.values(fields).join('; ')}`, fields };
}

// ---- homing in the drive --------------------------------------------------------------------

/** The CiA-402 homing methods (0x6098) most drives have, by number; the emulated drive has these. */
export const HOMING_METHODS: [number, string][] = [
  [1, 'negative limit switch + index pulse'],
  [2, 'positive limit switch + index pulse'],
  [17, 'negative limit switch'],
  [18, 'positive limit switch'],
  [33, 'index pulse, negative'],
  [34, 'index pulse, positive'],
  [35, 'current position'],
  [37, 'current position'],
];

/** The other method numbers of CiA-402 (1..37). */
export const OTHER_HOMING_METHODS: number[] = Array.from({ length: 37 }, (_, i) => i + 1).filter((n) => !HOMING_METHODS.some(([m]) => m === n));

/** `1` → "1 · negative limit switch + index pulse"; a number without a name → "method 5"; null → the drive's own. */
export function homingMethodText(m: number | null | undefined): string {
  if (m === null || m === undefined) return "the drive's own method";
  const named = HOMING_METHODS.find(([n]) => n === m);
  return named ? `${m} · ${named[1]}` : `method ${m}`;
}

/** Whether MC_Home in `mode` homes in the drive (drive-based; `default` too where the drive runs the profile). */
export function homesInDrive(mode: HomingMode | string, driveExecuted: boolean): boolean {
  return mode === 'drive_based' || (mode === 'default' && driveExecuted);
}

/** An option of a homing-mode select: the mode, its label, and why it cannot be chosen (or null). */
export type HomeModeOption = [HomingMode, string, string | null];

/**
 * MC_Home's modes for this axis: `default` says where it homes (the referencing sequence of
 * #1076, or in the drive with its method), `drive_based` needs a CiA-402 drive (a simulated
 * drive has no homing mode: the server answers 409 `drive_based_homing_unavailable`).
 * `short`: the labels of a narrow select (the Functions tab's).
 */
export function homeModeOptions(c: Pick<AxisConfig, 'drive'> | null | undefined, driveExecuted: boolean, short = false): HomeModeOption[] {
  const cia = c?.drive?.kind === 'cia402' ? c.drive : null;
  const method = !short && typeof cia?.homing_method === 'number' ? ` (method ${cia.homing_method})` : '';
  const noDriveHoming = cia ? null : 'needs a CiA-402 drive: a simulated drive has no homing mode';
  return [
    ['default', driveExecuted ? `default: in the drive${method}` : 'default: referencing', null],
    ['drive_based', short ? 'drive-based' : 'in the drive (drive-based)', noDriveHoming],
    ['direct', short ? 'direct' : 'direct: set the position here', null],
    ['force_calibration', short ? 'force calibration' : 'force calibration: mark as homed', null],
    ['reset_calibration', short ? 'reset calibration' : 'reset calibration: mark as not homed', null],
  ];
}

/** What homing in the drive does on this axis (the select's title, a note): its method (0x6098). */
export function driveHomingText(c: Pick<AxisConfig, 'drive'> | null | undefined): string {
  const cia = c?.drive?.kind === 'cia402' ? c.drive : null;
  if (!cia) return 'homing in the drive needs a CiA-402 drive';
  return `the drive homes in its homing mode with ${typeof cia.homing_method === 'number' ? `method ${homingMethodText(cia.homing_method)}` : "its own method (none configured)"}; the axis then reads the home position there`;
}
