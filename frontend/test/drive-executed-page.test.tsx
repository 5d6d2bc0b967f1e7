// The axis page of an axis whose drive runs the profile (Drive Motion Control) at the DOM level
// (services mocked, the server a fetch double): the notice beside the axis state; the Online tab
// without inching, override and jerk, its moves sent without jerk, MC_Home with drive-based;
// the Coupling tab's blocks disabled with the reason; the Functions tab's torque, correction and
// encoder blocks disabled, homing in the drive without motiond's referencing options. A
// host-side axis is offered everything as before.
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { render } from 'preact';
import { act } from 'preact/test-utils';
import { enter, mountPoint, settle, stubFetch, unmount } from './dom';

const h = vi.hoisted(() => ({ command: vi.fn(async () => ({ id: 1 })) }));

vi.mock('../src/services', async () => {
  const { Store } = await import('../src/store');
  return {
    axes: new Store<unknown[]>([]),
    axesLoaded: new Store(true),
    statuses: new Store(new Map()),
    system: new Store(null),
    commandLog: new Store([]),
    live: { state: new Store({ kind: 'open', since: 0 }), lastMessageAt: null },
    command: h.command,
    stopAndRelease: vi.fn(),
    findHeldStop: vi.fn(),
    releaseCommand: vi.fn(),
    resetFollowingErrorPeak: vi.fn(),
    refreshAxes: vi.fn(),
    jog: {
      press: vi.fn(),
      release: vi.fn(),
      snapshot: () => ({ phase: 'idle', axis: null, direction: null, mode: null, command: null, lastEnd: null, error: null }),
      onChange: () => () => {},
    },
  };
});
vi.mock('../src/ui/axis/trend', () => ({ Trend: () => null }));
vi.mock('../src/ui/shared/command-log', () => ({ CommandLog: () => null }));

import { axes, statuses } from '../src/services';
import { AxisPage } from '../src/ui/axis/axis-page';
import type { AxisTab } from '../src/router';
import type { AxisLiveStatus, AxisResource } from '../src/api/types';
import { NOT_OFFERED } from '../src/axis/drive-executed';

const drive = (profile: 'host' | 'drive') => ({ kind: 'cia402', subdevice: 3, increments_per_unit: 1000, velocity_increments_per_unit: null, mode: 'csp', position_gain: 50, velocity_gain: 0, acceleration_feed_forward: 0, max_torque: 1000, profile, homing_method: 1 });
const axis = (id: number, name: string, d: unknown) =>
  ({ id, slot: id - 1, state: 'standstill', config: { name, unit: 'mm', modulo: null, soft_limits: { min: 0, max: 500 }, dynamics: { jog_velocity_fast: 50 }, drive: d } }) as unknown as AxisResource;
const feeder = axis(4, 'feeder', drive('drive'));
const x = axis(1, 'x', { kind: 'simulated' });
const live = (name: string, drive_executed: boolean) => {
  const status = { state: 'standstill', power_status: true, enable_positive: true, enable_negative: true, error_id: 0, homing_phase: 'idle', power_override_percent: 100, set_override_factor: 1, override_percent: 100, drive_executed } as unknown as AxisLiveStatus;
  statuses.get().set(name, { status, cycle: 1, stale: false });
  statuses.emit();
};

let root: HTMLElement;
beforeEach(() => {
  h.command.mockClear();
  stubFetch(({ url }) => {
    if (url.endsWith('/read-drive-operation-mode')) return [200, { drive_operation_mode: 'position', code: 8, cycle: 1 }];
    if (url.includes('/parameters/')) return [200, { number: 1046, name: 'AxisEnablePosCorrection', value: false }];
    return [200, []];
  });
  root = mountPoint();
  axes.set([x, feeder]);
});
afterEach(() => {
  unmount(root);
  vi.unstubAllGlobals();
  statuses.set(new Map());
});

const q = <T extends Element = HTMLElement>(sel: string) => root.querySelector(sel) as T | null;
const text = (sel: string) => q(sel)?.textContent?.trim() ?? null;
const show = async (name: string, tab: AxisTab) => {
  await act(async () => render(<AxisPage axis={name} tab={tab} />, root));
  await settle();
};
/** Whether a control cannot be used: disabled itself or inside a disabled fieldset. */
const off = (sel: string) => {
  const el = q<HTMLButtonElement>(sel);
  expect(el, sel).not.toBeNull();
  return el!.disabled || !!el!.closest('fieldset[disabled]');
};
const options = (sel: string) => [...root.querySelectorAll(`${sel} option`)].map((o) => [(o as HTMLOptionElement).value, o.textContent, (o as HTMLOptionElement).disabled]);

describe('the axis page of an axis whose drive runs the profile', () => {
  it('says so beside its state; a host-side axis does not', async () => {
    live('feeder', true);
    await show('feeder', 'online');
    expect(text('[data-testid="drive-executed"]')).toBe('the drive executes the profile (Drive Motion Control)');
    live('x', false);
    await show('x', 'online');
    expect(q('[data-testid="drive-executed"]')).toBeNull();
  });

  it('before its status has come, the configuration says it', async () => {
    await show('feeder', 'online');
    expect(q('[data-testid="drive-executed"]')).not.toBeNull();
  });

  it('Online: no inching, no override, no jerk; a move is sent without jerk; MC_Home offers drive-based and says default homes in the drive', async () => {
    live('feeder', true);
    await show('feeder', 'online');
    expect(q('button[name="inch-forward"]')).toBeNull();
    expect(text('[data-testid="inching-not-offered"]')).toBe(`Inching (one step per click) is ${NOT_OFFERED}: hold a jog button.`);
    expect(off('input[name="override"]')).toBe(true);
    expect(off('button[name="override-50"]')).toBe(true);
    expect(text('[data-testid="override-not-offered"]')).toBe(`The override is ${NOT_OFFERED}.`);
    expect(off('input[name="jerk"]')).toBe(true);
    expect(off('input[name="stop-jerk"]')).toBe(true);
    // the jog buttons, moves, halt and stop stay
    expect(off('button[data-jog="slow-forward"]')).toBe(false);
    expect([...root.querySelectorAll('[data-move]')].map((b) => b.getAttribute('data-move'))).toEqual(['move-absolute', 'move-relative', 'move-velocity']);
    expect(off('button[name="halt"]')).toBe(false);
    enter(q('input[name="position"]'), '120');
    enter(q('input[name="velocity"]'), '40');
    await act(async () => q<HTMLFormElement>('form.move-form')!.requestSubmit());
    expect(h.command).toHaveBeenLastCalledWith('feeder', 'move-absolute', { position: 120, velocity: 40, acceleration: 0, deceleration: 0, jerk: 0 });
    await act(async () => q<HTMLButtonElement>('button[name="halt"]')!.click());
    expect(h.command).toHaveBeenLastCalledWith('feeder', 'halt', { deceleration: 0, jerk: 0 });
    expect(options('select[name="home-mode"]').slice(0, 2)).toEqual([
      ['default', 'default: in the drive (method 1)', false],
      ['drive_based', 'in the drive (drive-based)', false],
    ]);
    enter(q('select[name="home-mode"]'), 'drive_based');
    await act(async () => q<HTMLButtonElement>('button[name="home-btn"]')!.closest('form')!.requestSubmit());
    expect(h.command).toHaveBeenLastCalledWith('feeder', 'home', { mode: 'drive_based' });
  });

  it('Online of a host-side axis: inching, override and jerk as before; drive-based homing needs a CiA-402 drive', async () => {
    live('x', false);
    await show('x', 'online');
    expect(q('button[name="inch-forward"]')).not.toBeNull();
    expect(q('[data-testid="inching-not-offered"]')).toBeNull();
    expect(off('input[name="override"]')).toBe(false);
    expect(off('input[name="jerk"]')).toBe(false);
    expect(options('select[name="home-mode"]').slice(0, 2)).toEqual([
      ['default', 'default: referencing', false],
      ['drive_based', 'in the drive (drive-based)', true],
    ]);
  });

  it('Coupling: every block disabled, the reason said; a host-side axis has them', async () => {
    live('feeder', true);
    await show('feeder', 'coupling');
    expect(text('[data-testid="coupling-not-offered"]')!.startsWith(`Gear, cam, multi-master gear, phasing and superposition are ${NOT_OFFERED}:`)).toBe(true);
    for (const b of ['gear-in', 'gear-out', 'gear-in-dyn', 'cam-in', 'cam-out', 'cam-scaling', 'move-superimposed', 'abort-superposition', 'phasing-absolute', 'phasing-relative', 'halt-phasing', 'mm-couple']) {
      expect(off(`button[name="${b}"]`), b).toBe(true);
    }
    expect(off('input[name="ratio-numerator"]')).toBe(true);
    live('x', false);
    await show('x', 'coupling');
    expect(q('[data-testid="coupling-not-offered"]')).toBeNull();
    expect(off('button[name="gear-in"]')).toBe(false);
  });

  it('Functions: torque control, the drive mode write, the corrections and the encoder scaling disabled with the reason; homing in the drive sends no referencing options', async () => {
    live('feeder', true);
    await show('feeder', 'functions');
    const notes = [...root.querySelectorAll('[data-testid="not-offered"]')].map((n) => n.textContent);
    expect(notes).toEqual([
      `MC_TorqueControl and MC_WriteDriveOperationMode: ${NOT_OFFERED}.`,
      `MC_SetEncoderScalingFactor: ${NOT_OFFERED}.`,
      `The limiter, backlash and table compensation: ${NOT_OFFERED}.`,
    ]);
    for (const b of ['torque-start', 'torque-halt', 'drive-mode-write', 'encoder-scaling-set', 'limiter-start', 'backlash-start', 'table-start']) expect(off(`button[name="${b}"]`), b).toBe(true);
    // reads stay: the drive's mode, the conversions; the reversing sequence (MC_MoveAbsolute, MC_Halt)
    for (const b of ['drive-mode-read', 'convert-inc', 'convert-pos', 'rev-start', 'home-start']) expect(off(`button[name="${b}"]`), b).toBe(false);
    // default homes in the drive: motiond's referencing options are off and not sent
    expect(q<HTMLSelectElement>('select[name="home-mode"]')!.value).toBe('default');
    expect(off('select[name="home-reference-mode"]')).toBe(true);
    expect(off('input[name="home-search-velocity"]')).toBe(true);
    expect(text('[data-testid="drive-homing"]')).toMatch(/^Homing in the drive: the drive homes in its homing mode with method 1 · negative limit switch \+ index pulse/);
    await act(async () => q<HTMLFormElement>('form.homing-form')!.requestSubmit());
    expect(h.command).toHaveBeenLastCalledWith('feeder', 'home', { mode: 'default' }, undefined);
    // direct: MC_Home's own options again
    enter(q('select[name="home-mode"]'), 'direct');
    expect(off('select[name="home-reference-mode"]')).toBe(false);
    expect(q('[data-testid="drive-homing"]')).toBeNull();
  });

  it('Functions of a host-side axis: every block as before', async () => {
    live('x', false);
    await show('x', 'functions');
    expect(q('[data-testid="not-offered"]')).toBeNull();
    for (const b of ['torque-start', 'drive-mode-write', 'encoder-scaling-set', 'limiter-start']) expect(off(`button[name="${b}"]`), b).toBe(false);
    expect(off('select[name="home-reference-mode"]')).toBe(false);
  });
});
