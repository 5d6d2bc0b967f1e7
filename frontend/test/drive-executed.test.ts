// An axis whose drive runs the profile (Drive Motion Control, issue 25): which blocks it is
// offered, which inputs it lacks (as the kernel's admission, decision 167), the homing modes
// and methods, and that services.command never sends what such an axis refuses.
import { afterEach, describe, expect, it, vi } from 'vitest';
import {
  DRIVE_EXECUTED_BLOCKS,
  HOMING_METHODS,
  NOT_OFFERED,
  OTHER_HOMING_METHODS,
  configuredDriveExecuted,
  driveHomingText,
  driveRefusal,
  homeModeOptions,
  homesInDrive,
  homingMethodText,
  isDriveExecuted,
  notOffered,
  offeredOnDrive,
} from '../src/axis/drive-executed';
import { homeBody, HOME_DEFAULTS } from '../src/axis/bodies';
import { NotOfferedError } from '../src/api/problem';
import { axes, command, commandLog, driveExecutedAxis, statuses } from '../src/services';
import type { AxisConfig, AxisLiveStatus, AxisResource } from '../src/api/types';
import { asSent } from './dom';

const cia = (profile: 'host' | 'drive' | undefined, homing_method: number | null = null) =>
  ({ drive: { kind: 'cia402', subdevice: 3, increments_per_unit: 1000, mode: 'csp', ...(profile ? { profile } : {}), homing_method } }) as Pick<AxisConfig, 'drive'>;
const sim = { drive: { kind: 'simulated' } } as Pick<AxisConfig, 'drive'>;

describe('the blocks of an axis whose drive runs the profile', () => {
  it('are DMC’s: power, reset, set position, home, jog, halt, the four moves, stop, touch probe, abort trigger', () => {
    expect([...DRIVE_EXECUTED_BLOCKS].sort()).toEqual(
      ['abort-trigger', 'halt', 'home', 'jog', 'move-absolute', 'move-modulo', 'move-relative', 'move-velocity', 'power', 'reset', 'set-position', 'stop', 'touch-probe'],
    );
    for (const b of DRIVE_EXECUTED_BLOCKS) expect(offeredOnDrive(b), b).toBe(true);
  });

  it('no other block: coupling, cams, superposition, phasing, torque, the override, corrections, the encoder, the drive mode …', () => {
    const refused = [
      'move-additive',
      'move-continuous-absolute',
      'move-continuous-relative',
      'gear-in',
      'gear-in-dyn',
      'gear-in-multi-master',
      'gear-out',
      'cam-in',
      'cam-out',
      'cam-scaling',
      'move-superimposed',
      'abort-superposition',
      'phasing-absolute',
      'phasing-relative',
      'halt-phasing',
      'torque-control',
      'ext-setpoint-gen-enable',
      'set-override',
      'override-filter',
      'position-correction-limiter',
      'backlash-compensation',
      'table-based-position-compensation',
      'write-drive-operation-mode',
      'set-encoder-scaling-factor',
    ] as const;
    for (const b of refused) {
      expect(offeredOnDrive(b), b).toBe(false);
      expect(notOffered(b, true), b).toBe(NOT_OFFERED);
      // a host-side axis offers every block
      expect(notOffered(b, false), b).toBeNull();
    }
    expect(notOffered('move-absolute', true)).toBeNull();
  });

  it('the live status says whether the drive runs the profile; until it has come, the configuration', () => {
    expect(configuredDriveExecuted(cia('drive'))).toBe(true);
    expect(configuredDriveExecuted(cia('host'))).toBe(false);
    // a configuration from before the profile side: host
    expect(configuredDriveExecuted(cia(undefined))).toBe(false);
    expect(configuredDriveExecuted(sim)).toBe(false);
    expect(configuredDriveExecuted(null)).toBe(false);
    expect(isDriveExecuted(cia('drive'), null)).toBe(true);
    expect(isDriveExecuted(cia('drive'), { drive_executed: false })).toBe(false);
    expect(isDriveExecuted(cia('host'), { drive_executed: true })).toBe(true);
    expect(isDriveExecuted(cia('drive'), {})).toBe(true);
    expect(isDriveExecuted(sim, { drive_executed: false })).toBe(false);
  });
});

describe('what such an axis refuses of a command (decision 167)', () => {
  it('a block it does not have', () => {
    expect(driveRefusal('gear-in', { master: 'x', ratio_numerator: 1, ratio_denominator: 1 })).toEqual({
      code: 'not_on_drive_executed_axis',
      detail: `gear-in is ${NOT_OFFERED}`,
      fields: {},
    });
  });

  it('inching (DMC jogs while held only); a held jog is taken', () => {
    expect(driveRefusal('jog', { direction: 'forward', mode: 'inching', position: 1, velocity: 2 })?.code).toBe('not_on_drive_executed_axis');
    expect(driveRefusal('jog', { direction: 'forward', mode: 'inching_modulo', position: 1, velocity: 2 })?.code).toBe('not_on_drive_executed_axis');
    expect(driveRefusal('jog', { direction: 'forward', mode: 'standard_slow' })).toBeNull();
  });

  it('jerk ≠ 0 and a buffer mode other than aborting, at their fields; 0 and aborting are taken', () => {
    expect(driveRefusal('move-absolute', { position: 10, velocity: 5, acceleration: 0, deceleration: 0, jerk: 0 })).toBeNull();
    expect(driveRefusal('move-absolute', { position: 10, velocity: 5, buffer_mode: 'aborting' })).toBeNull();
    const r = driveRefusal('move-relative', { distance: 10, velocity: 5, jerk: 100, buffer_mode: 'buffered' });
    expect(r?.code).toBe('input_not_on_drive_executed_axis');
    expect(Object.keys(r!.fields).sort()).toEqual(['buffer_mode', 'jerk']);
    expect(driveRefusal('halt', { deceleration: 0, jerk: 5 })?.fields).toEqual({ jerk: 'no jerk when the drive runs the profile (leave it 0)' });
    expect(driveRefusal('stop', { deceleration: 100, jerk: 0 })).toBeNull();
    expect(driveRefusal('move-velocity', { velocity: 5, direction: 'positive', jerk: -1 })?.code).toBe('input_not_on_drive_executed_axis');
    // text that is no number is the REST client's to refuse (NotSentError at the field)
    expect(driveRefusal('move-absolute', { position: 1, velocity: 1, jerk: NaN })).toBeNull();
  });

  it('a power override other than 100 %', () => {
    expect(driveRefusal('power', { enable: true, override_percent: 100 })).toBeNull();
    expect(driveRefusal('power', { enable: true })).toBeNull();
    expect(driveRefusal('power', { enable: true, override_percent: 50 })?.fields).toEqual({ override_percent: 'only 100 % when the drive runs the profile' });
  });

  it('every homing mode is taken', () => {
    for (const mode of ['default', 'drive_based', 'direct', 'force_calibration', 'reset_calibration']) expect(driveRefusal('home', { mode })).toBeNull();
  });
});

describe('homing in the drive', () => {
  it('MC_Home homes in the drive with drive_based, and with default where the drive runs the profile', () => {
    expect(homesInDrive('drive_based', false)).toBe(true);
    expect(homesInDrive('drive_based', true)).toBe(true);
    expect(homesInDrive('default', true)).toBe(true);
    expect(homesInDrive('default', false)).toBe(false);
    expect(homesInDrive('direct', true)).toBe(false);
  });

  it('the modes offered: default says where it homes; drive-based needs a CiA-402 drive', () => {
    expect(homeModeOptions(cia('drive', 1), true)).toEqual([
      ['default', 'default: in the drive (method 1)', null],
      ['drive_based', 'in the drive (drive-based)', null],
      ['direct', 'direct: set the position here', null],
      ['force_calibration', 'force calibration: mark as homed', null],
      ['reset_calibration', 'reset calibration: mark as not homed', null],
    ]);
    expect(homeModeOptions(cia('drive', null), true)[0]).toEqual(['default', 'default: in the drive', null]);
    expect(homeModeOptions(cia('host', 17), false).slice(0, 2)).toEqual([
      ['default', 'default: referencing', null],
      ['drive_based', 'in the drive (drive-based)', null],
    ]);
    expect(homeModeOptions(sim, false)[1]).toEqual(['drive_based', 'in the drive (drive-based)', 'needs a CiA-402 drive: a simulated drive has no homing mode']);
    // the narrow select of the Functions tab
    expect(homeModeOptions(cia('drive', 1), true, true).map(([m, l]) => [m, l])).toEqual([
      ['default', 'default: in the drive'],
      ['drive_based', 'drive-based'],
      ['direct', 'direct'],
      ['force_calibration', 'force calibration'],
      ['reset_calibration', 'reset calibration'],
    ]);
  });

  it('the methods: the common ones by name, every other of 1..37 by number', () => {
    expect(HOMING_METHODS.map(([n]) => n)).toEqual([1, 2, 17, 18, 33, 34, 35, 37]);
    expect([...HOMING_METHODS.map(([n]) => n), ...OTHER_HOMING_METHODS].sort((a, b) => a - b)).toEqual(Array.from({ length: 37 }, (_, i) => i + 1));
    expect(homingMethodText(1)).toBe('1 · negative limit switch + index pulse');
    expect(homingMethodText(34)).toBe('34 · index pulse, positive');
    expect(homingMethodText(5)).toBe('method 5');
    expect(homingMethodText(null)).toBe("the drive's own method");
    expect(driveHomingText(cia('drive', 18))).toBe('the drive homes in its homing mode with method 18 · positive limit switch; the axis then reads the home position there');
    expect(driveHomingText(cia('drive', null))).toMatch(/its own method \(none configured\)/);
    expect(driveHomingText(sim)).toBe('homing in the drive needs a CiA-402 drive');
  });

  it('the MC_Home body: in the drive, motiond’s referencing options are not sent', () => {
    const f = { ...HOME_DEFAULTS, mode: 'drive_based', position: '5', reference_mode: 'plc_cam', search_velocity: '20' };
    expect(homeBody(f, true).body).toEqual({ mode: 'drive_based', position: 5 });
    expect(homeBody({ ...f, mode: 'default' }).body).toEqual({ mode: 'default', position: 5, options: { reference_mode: 'plc_cam', search_velocity: 20 } });
  });
});

describe('services.command on an axis whose drive runs the profile', () => {
  const feeder = { id: 4, slot: 3, state: 'standstill', config: { name: 'feeder', unit: 'mm', ...cia('drive', 1) } } as unknown as AxisResource;
  const x = { id: 1, slot: 0, state: 'standstill', config: { name: 'x', unit: 'mm', ...sim } } as unknown as AxisResource;
  let sent: string[];
  const serve = () => {
    sent = [];
    vi.stubGlobal(
      'fetch',
      vi.fn(async (input: RequestInfo | URL, init?: RequestInit) => {
        const { method, url } = await asSent(input, init);
        sent.push(`${method} ${url}`);
        const r = { id: sent.length, axis: url.split('/')[4], command: url.split('/')[5]?.split('?')[0], state: 'busy', final: false, parameters: {}, outputs: { error_id: 0 }, last_cycle: 1, submitted_at: '' };
        return new Response(JSON.stringify(r), { status: 202, headers: { 'content-type': 'application/json' } });
      }),
    );
  };
  afterEach(() => {
    vi.unstubAllGlobals();
    axes.set([]);
    statuses.set(new Map());
  });

  it('never sends a block or an input it refuses (nothing logged: nothing was refused by the server); sends what it takes', async () => {
    serve();
    axes.set([feeder, x]);
    const logged = commandLog.get().length;
    expect(driveExecutedAxis('feeder')).toBe(true);
    const gear = command('feeder', 'gear-in', { master: 'x', ratio_numerator: 1, ratio_denominator: 1 });
    await expect(gear).rejects.toBeInstanceOf(NotOfferedError);
    await expect(gear).rejects.toMatchObject({ status: 409, code: 'not_on_drive_executed_axis' });
    const jerk = command('feeder', 'move-absolute', { position: 10, velocity: 5, jerk: 100 });
    await expect(jerk).rejects.toMatchObject({ code: 'input_not_on_drive_executed_axis', fields: { jerk: 'no jerk when the drive runs the profile (leave it 0)' } });
    await expect(command('feeder', 'set-override', { velocity_factor: 0.5 })).rejects.toBeInstanceOf(NotOfferedError);
    expect(sent).toEqual([]);
    expect(commandLog.get().length).toBe(logged);
    await command('feeder', 'move-absolute', { position: 10, velocity: 5, jerk: 0 });
    expect(sent).toEqual(['POST /api/v1/axes/feeder/move-absolute']);
    // a host-side axis: every block is sent (the server judges)
    await command('x', 'gear-in', { master: 'feeder', ratio_numerator: 1, ratio_denominator: 1 });
    expect(sent.at(-1)).toBe('POST /api/v1/axes/x/gear-in');
  });

  it('the live status decides: an axis the server reports host-side is sent every block', async () => {
    serve();
    axes.set([feeder]);
    statuses.set(new Map([['feeder', { status: { drive_executed: false } as AxisLiveStatus, cycle: 1, stale: false }]]));
    expect(driveExecutedAxis('feeder')).toBe(false);
    await command('feeder', 'gear-in', { master: 'x', ratio_numerator: 1, ratio_denominator: 1 });
    expect(sent).toEqual(['POST /api/v1/axes/feeder/gear-in']);
  });
});
