// The drive on the Configuration and New axis pages at the DOM level (services mocked, the
// server a fetch double): the kind select (CiA-402 offered disabled with the hint on the
// simulated bus), the SubDevice chosen from GET /bus with the axis that uses it, the request
// body of each kind, and the server's 422 at `drive.subdevice` / `drive.kind` shown at the field.
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { render } from 'preact';
import { act } from 'preact/test-utils';
import { enter, mountPoint, problem, settle, stubFetch, unmount, type FetchCall } from './dom';
import { emulated, simulated } from './bus-fixture';

vi.mock('../src/services', async () => {
  const { Store } = await import('../src/store');
  return {
    axes: new Store<unknown[]>([]),
    statuses: new Store(new Map()),
    live: { state: new Store({ kind: 'open', since: 0 }) },
    command: vi.fn(async () => ({ id: 1 })),
    refreshAxes: vi.fn(async () => {}),
  };
});
vi.mock('../src/router', async (orig) => ({ ...(await orig<typeof import('../src/router')>()), navigate: vi.fn() }));

import { AxisConfigPage } from '../src/ui/config/axis-config';
import type { AxisConfig, AxisResource, BusResource } from '../src/api/types';

let calls: FetchCall[];
let bus: BusResource;
/** The answer to a POST /axes or PUT /axes/x(?dry_run=true): status and body (null: echo the request). */
let answer: [number, unknown];

const dynamics = { max_velocity: 500, acceleration: 2500, deceleration: 2500, jerk: 25000, jog_velocity_slow: 10, jog_velocity_fast: 100, jog_deadman_max: 1 };
const xConfig: AxisConfig = {
  name: 'x',
  unit: 'mm',
  dynamics,
  parameters: { AxisTargetPositionWindow: 0.01 } as unknown as AxisConfig['parameters'],
  drive: { kind: 'cia402', subdevice: 0, increments_per_unit: 1000, velocity_increments_per_unit: null, mode: 'csp', position_gain: 50, velocity_gain: 0, acceleration_feed_forward: 0, max_torque: 1000, profile: 'host', homing_method: null },
};
/** The CiA-402 fields a CSP drive is sent with besides subdevice and scaling (the server's defaults). */
const gains = { position_gain: 50, velocity_gain: 0, acceleration_feed_forward: 0, max_torque: 1000, profile: 'host', homing_method: null };
const x = { id: 1, slot: 0, state: 'disabled', config: xConfig } as AxisResource;
const invalid = (field: string, message: string) => problem(422, 'validation_failed', 'Invalid request', `${field}: ${message}`, [{ field, message }]);

let root: HTMLElement;
beforeEach(() => {
  bus = emulated();
  answer = [200, null];
  calls = stubFetch(({ method, url, body }) => {
    if (url === '/api/v1/bus') return [200, bus];
    if (method === 'GET') return [200, []];
    const change = { dry_run: url.endsWith('dry_run=true'), rebuild: false, rebuild_reasons: [], parameters: [], persistent_discarded: [] };
    return answer[1] === null ? [method === 'POST' ? 201 : 200, { ...x, config: body, change }] : answer;
  });
  root = mountPoint();
});
afterEach(() => {
  unmount(root);
  vi.unstubAllGlobals();
});

const q = <T extends Element = HTMLElement>(sel: string) => root.querySelector(sel) as T | null;
const text = (sel: string) => q(sel)?.textContent?.trim() ?? null;
const choose = (sel: string, value: string) => enter(q(sel), value);
const options = (sel: string) => [...root.querySelectorAll(`${sel} option`)].map((o) => [(o as HTMLOptionElement).value, o.textContent, (o as HTMLOptionElement).disabled]);
/** The New axis page with axis z on a CiA-402 drive. */
const newCiaAxis = async () => {
  await act(async () => render(<AxisConfigPage axis={null} />, root));
  await settle();
  enter(q('input[name="name"]'), 'z');
  choose('select[name="drive.kind"]', 'cia402');
};
const save = async () => {
  await act(async () => q<HTMLButtonElement>('button[name="save"]')!.click());
  await settle();
};

describe('the drive kind', () => {
  it('on the simulated bus CiA-402 is offered disabled, with how to start motiond for it', async () => {
    bus = simulated;
    await act(async () => render(<AxisConfigPage axis={null} />, root));
    await settle();
    expect(options('select[name="drive.kind"]')).toEqual([
      ['simulated', 'Simulated', false],
      ['cia402', 'CiA-402 on EtherCAT', true],
    ]);
    expect(text('[data-testid="cia402-unavailable"]')).toBe(
      'CiA-402 is not offered: motiond runs the simulated bus; start motiond with --bus ethercat --interface IFACE, or --bus emulated.',
    );
    // the simulated drive's fields as before
    expect(q('select[name="drive.plant.kind"]')).not.toBeNull();
    expect(q('input[name="drive.reference_cam.start"]')).not.toBeNull();
    expect(q('select[name="drive.subdevice"]')).toBeNull();
  });

  it('on EtherCAT a new axis gets the first free drive; the others show whose they are; the body is a cia402 drive', async () => {
    await newCiaAxis();
    expect(q('[data-testid="cia402-unavailable"]')).toBeNull();
    expect(q<HTMLSelectElement>('select[name="drive.subdevice"]')!.value).toBe('2');
    expect(options('select[name="drive.subdevice"]').map((o) => o[1])).toEqual([
      '0 · motiond emulated servo 1 — used by x',
      '1 · motiond emulated servo 2 — used by y',
      '2 · motiond emulated servo 3 — free',
    ]);
    // no simulated drive's fields (plant, homing cam, switches)
    expect(q('select[name="drive.plant.kind"]')).toBeNull();
    expect(q('input[name="drive.reference_cam.start"]')).toBeNull();
    expect(q<HTMLSelectElement>('select[name="drive.mode"]')!.value).toBe('csp');
    await save();
    const post = calls.find((c) => c.method === 'POST')!;
    expect(post.url).toBe('/api/v1/axes');
    expect((post.body as AxisConfig).drive).toEqual({ kind: 'cia402', subdevice: 2, increments_per_unit: 1000, velocity_increments_per_unit: null, mode: 'csp', ...gains });
  });

  it('the mode: CSP has no gain to set; CSV the position gain; CST also the velocity gain, feed-forward and max torque, sent in the body', async () => {
    const shown = () => ['position_gain', 'velocity_gain', 'acceleration_feed_forward', 'max_torque'].filter((k) => q(`input[name="drive.${k}"]`));
    await newCiaAxis();
    expect(options('select[name="drive.mode"]').map((o) => o[0])).toEqual(['csp', 'csv', 'cst']);
    expect(shown()).toEqual([]);
    choose('select[name="drive.mode"]', 'csv');
    expect(shown()).toEqual(['position_gain']);
    choose('select[name="drive.mode"]', 'cst');
    expect(shown()).toEqual(['position_gain', 'velocity_gain', 'acceleration_feed_forward', 'max_torque']);
    expect(text('[data-field="drive.velocity_gain"] .field-label')).toMatch(/Velocity gain \(‰ per mm\/s\)/);
    enter(q('input[name="drive.position_gain"]'), '40');
    enter(q('input[name="drive.velocity_gain"]'), '2.5');
    enter(q('input[name="drive.acceleration_feed_forward"]'), '0,1');
    enter(q('input[name="drive.max_torque"]'), '1500');
    await save();
    const post = calls.find((c) => c.method === 'POST')!;
    expect((post.body as AxisConfig).drive).toEqual({
      kind: 'cia402',
      subdevice: 2,
      increments_per_unit: 1000,
      velocity_increments_per_unit: null,
      mode: 'cst',
      position_gain: 40,
      velocity_gain: 2.5,
      acceleration_feed_forward: 0.1,
      max_torque: 1500,
      profile: 'host',
      homing_method: null,
    });
  });

  it("CST without a velocity gain: the server's 422 at drive.velocity_gain is shown at the field", async () => {
    answer = [422, invalid('drive.velocity_gain', 'must be a finite number > 0')];
    await newCiaAxis();
    choose('select[name="drive.mode"]', 'cst');
    expect(q<HTMLInputElement>('input[name="drive.velocity_gain"]')!.value).toBe('0');
    await save();
    expect(text('[data-field="drive.velocity_gain"] .field-error')).toBe('must be a finite number > 0');
    expect(text('.banner-error > span')).toBe('The server refused the configuration: see the fields marked red.');
  });

  it("a taken drive is refused by the server at drive.subdevice: shown at the field, the banner points there", async () => {
    answer = [422, invalid('drive.subdevice', "the drive at position 1 is axis y's")];
    await newCiaAxis();
    choose('select[name="drive.subdevice"]', '1');
    await save();
    expect(text('[data-field="drive.subdevice"] .field-error')).toBe("the drive at position 1 is axis y's");
    expect(q('[data-field="drive.subdevice"]')!.className).toMatch(/has-error/);
    expect(text('.banner-error > span')).toBe('The server refused the configuration: see the fields marked red.');
  });

  it('an axis with a CiA-402 drive: its drive shown and saved unchanged (the dry run asked with the same drive)', async () => {
    await act(async () => render(<AxisConfigPage axis={x} />, root));
    await settle();
    expect(q<HTMLSelectElement>('select[name="drive.kind"]')!.value).toBe('cia402');
    expect(q<HTMLSelectElement>('select[name="drive.subdevice"]')!.value).toBe('0');
    expect(q<HTMLInputElement>('input[name="drive.increments_per_unit"]')!.value).toBe('1000');
    expect(q<HTMLInputElement>('input[name="drive.velocity_increments_per_unit"]')!.value).toBe('');
    // CSP: the position loop is the drive's (the gains are kept, not shown)
    expect(q('input[name="drive.position_gain"]')).toBeNull();
    expect(q('input[name="drive.velocity_gain"]')).toBeNull();
    await save();
    const dry = calls.find((c) => c.method === 'PUT')!;
    expect(dry.url).toBe('/api/v1/axes/x?dry_run=true');
    expect(dry.body).toEqual(xConfig);
    expect(q('[data-testid="save-panel"]')).not.toBeNull();
  });

  it('the profile side (host or drive) and the homing method (the named common ones, the others by number, blank = the drive\'s own): shown as configured, sent in `drive`', async () => {
    const feeder = { ...x, id: 4, config: { ...xConfig, name: 'feeder', drive: { ...xConfig.drive, subdevice: 2, profile: 'drive', homing_method: 1 } } } as AxisResource;
    await act(async () => render(<AxisConfigPage axis={feeder} />, root));
    await settle();
    expect(q<HTMLSelectElement>('select[name="drive.profile"]')!.value).toBe('drive');
    expect(options('select[name="drive.profile"]').map((o) => o[0])).toEqual(['host', 'drive']);
    expect(text('[data-field="drive.profile"] .field-hint')).toMatch(/^the drive runs profile position, velocity and homing/);
    expect(q<HTMLSelectElement>('select[name="drive.homing_method"]')!.value).toBe('1');
    const methods = options('select[name="drive.homing_method"]');
    expect(methods.slice(0, 9).map((o) => o[1])).toEqual([
      'the drive’s own (not written)',
      '1 · negative limit switch + index pulse',
      '2 · positive limit switch + index pulse',
      '17 · negative limit switch',
      '18 · positive limit switch',
      '33 · index pulse, negative',
      '34 · index pulse, positive',
      '35 · current position',
      '37 · current position',
    ]);
    // every CiA-402 method 1..37 can be chosen, each once
    expect(methods.slice(1).map((o) => Number(o[0])).sort((a, b) => a - b)).toEqual(Array.from({ length: 37 }, (_, i) => i + 1));
    choose('select[name="drive.profile"]', 'host');
    expect(text('[data-field="drive.profile"] .field-hint')).toMatch(/^motiond plans the motion/);
    choose('select[name="drive.homing_method"]', '34');
    await save();
    expect((calls.find((c) => c.method === 'PUT')!.body as AxisConfig).drive).toEqual({ ...xConfig.drive, subdevice: 2, profile: 'host', homing_method: 34 });
    choose('select[name="drive.homing_method"]', '');
    choose('select[name="drive.profile"]', 'drive');
    await act(async () => q<HTMLButtonElement>('[data-testid="save-panel"] button[name="cancel-save"]')!.click());
    calls.length = 0;
    await save();
    expect((calls.find((c) => c.method === 'PUT')!.body as AxisConfig).drive).toMatchObject({ profile: 'drive', homing_method: null });
  });

  it("the server's 422 at drive.profile (a drive that cannot run the profile) is shown at the profile select", async () => {
    answer = [422, invalid('drive.profile', 'the drive at position 2 cannot run the profile: its process image lacks 0x607A; use profile host')];
    await newCiaAxis();
    choose('select[name="drive.profile"]', 'drive');
    await save();
    expect(text('[data-field="drive.profile"] .field-error')).toBe('the drive at position 2 cannot run the profile: its process image lacks 0x607A; use profile host');
    expect(text('.banner-error > span')).toBe('The server refused the configuration: see the fields marked red.');
  });

  it("the server's 422 at drive.kind (no EtherCAT bus) is shown at the kind select", async () => {
    bus = simulated;
    answer = [422, invalid('drive.kind', 'a CiA-402 drive needs an EtherCAT bus (--bus ethercat or --bus emulated)')];
    await act(async () => render(<AxisConfigPage axis={x} />, root));
    await settle();
    // the axis's own kind stays selectable
    expect(options('select[name="drive.kind"]')[1]).toEqual(['cia402', 'CiA-402 on EtherCAT', false]);
    expect(text('select[name="drive.subdevice"] option')).toBe('0 · no CiA-402 drive there on the bus');
    await save();
    expect(text('[data-field="drive.kind"] .field-error')).toBe('a CiA-402 drive needs an EtherCAT bus (--bus ethercat or --bus emulated)');
    expect(q('[data-testid="save-panel"]')).toBeNull();
  });
});
