// The System page's bus panel at the DOM level against a fetch double: the EtherCAT view (state,
// counters, SubDevices, a faulted bus's banner), read again every second; the SDO tool (a read
// shown as hex/unsigned/signed, an abort with the server's text, a write read back, Write for
// the engineer role only); the simulated bus as its axes.
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
  };
});

import { axes } from '../src/services';
import { auth } from '../src/auth/session';
import { BusPanel } from '../src/ui/bus';
import type { AxisResource, BusResource } from '../src/api/types';

let asked: FetchCall[];
let bus: BusResource;
let sdo: (c: FetchCall) => [number, unknown];

let root: HTMLElement;
beforeEach(() => {
  bus = emulated();
  sdo = () => [404, null];
  auth.set({ kind: 'app', session: null });
  asked = stubFetch((c) => (c.url === '/api/v1/bus' ? [200, bus] : sdo(c)));
  root = mountPoint();
});
afterEach(() => {
  unmount(root);
  vi.useRealTimers();
  vi.unstubAllGlobals();
  (axes as unknown as { set: (v: unknown[]) => void }).set([]);
});

const $ = (sel: string) => root.querySelector(sel) as HTMLElement | null;
const $$ = (sel: string) => [...root.querySelectorAll(sel)] as HTMLElement[];
const text = (sel: string) => $(sel)?.textContent?.trim() ?? null;
const input = (sel: string, value: string) => enter($(sel), value);
const click = async (sel: string) => {
  ($(sel) as HTMLButtonElement).click();
  await settle();
};

describe('the EtherCAT bus', () => {
  it('kind, interface, state, counters and the SubDevices with their axes', async () => {
    await act(async () => render(<BusPanel />, root));
    await settle();
    expect(asked[0].url).toBe('/api/v1/bus');
    expect(text('[data-testid="bus-title"]')).toBe('EtherCAT (emulated segment)');
    expect($('[data-testid="bus-state"]')!.dataset.state).toBe('op');
    expect($('[data-testid="bus-state"] [data-led]')!.dataset.led).toBe('OP');
    expect($('[data-testid="bus-banner"]')).toBeNull();
    expect(text('[data-kpi="frames"] .kpi-value')).toBe('120,345');
    expect(text('[data-kpi="working_counter"] .kpi-value')).toBe('9 / 9');
    expect(text('[data-kpi="dc_cycle_offset"] .kpi-value')).toBe('12.3 µs');
    const rows = $$('[data-testid="subdevices"] tr[data-subdevice]');
    expect(rows.map((r) => r.dataset.subdevice)).toEqual(['0', '1', '2']);
    const cell = (r: HTMLElement, c: string) => r.querySelector(`[data-col="${c}"]`)!.textContent!.trim();
    expect(['address', 'name', 'vendor', 'product', 'revision', 'serial', 'al', 'mapping', 'dc', 'axis'].map((c) => cell(rows[0], c))).toEqual([
      '0x1000',
      'motiond emulated servo 1',
      '0x00FF0ACE',
      '0x04020001',
      '0x00010000',
      '539361280',
      'OP',
      'full · 15 B out, 29 B in',
      'SYNC0',
      'x',
    ]);
    expect(rows[0].querySelector('[data-col="axis"] a')!.getAttribute('href')).toBe('#/axes/x');
    expect(cell(rows[2], 'axis')).toBe('—');
    // no simulated drive: no simulated section
    expect($('[data-bus="simulated"]')).toBeNull();
  });

  it('read again every second: a faulted bus shows its banner, the lost frames and the fault; back in OP the banner goes, the count stays', async () => {
    vi.useFakeTimers({ toFake: ['setTimeout', 'clearTimeout'] });
    await act(async () => render(<BusPanel />, root));
    await act(async () => void (await vi.advanceTimersByTimeAsync(0)));
    expect(asked.length).toBe(1);
    bus = emulated({ state: 'faulted', lost_frames: 6, faults: 1, errors_in_row: 3 });
    await act(async () => void (await vi.advanceTimersByTimeAsync(1000)));
    expect(asked.length).toBe(2);
    expect($('[data-testid="bus-state"]')!.dataset.state).toBe('faulted');
    expect($('[data-testid="bus-banner"]')!.dataset.tone).toBe('error');
    expect(text('[data-testid="bus-banner"]')).toMatch(/^Bus faulted\. 3 lost frames or wrong working counters in a row: the enabled EtherCAT axes were stopped/);
    expect(text('[data-testid="bus-banner"]')).toMatch(/The bus clears by itself after 3 good frames in a row\.$/);
    expect(text('[data-kpi="lost_frames"] .kpi-value')).toBe('6');
    expect($('[data-kpi="lost_frames"]')!.className).toMatch(/kpi-warn/);
    expect(text('[data-kpi="faults"] .kpi-label')).toBe('Bus faults');
    expect(text('[data-kpi="faults"] .kpi-value')).toBe('1');
    expect($('[data-kpi="faults"]')!.className).toMatch(/kpi-warn/);
    // frames flow again: the bus clears by itself — OP, no banner, nothing red; the count stays amber
    bus = emulated({ state: 'op', lost_frames: 6, faults: 1, errors_in_row: 0 });
    await act(async () => void (await vi.advanceTimersByTimeAsync(1000)));
    expect(asked.length).toBe(3);
    expect($('[data-testid="bus-state"]')!.dataset.state).toBe('op');
    expect($('[data-testid="bus-banner"]')).toBeNull();
    expect(text('[data-kpi="faults"] .kpi-value')).toBe('1');
    expect($('[data-kpi="faults"]')!.className).toMatch(/kpi-warn/);
    expect($$('[data-testid="bus-counters"] .kpi-bad')).toEqual([]);
  });

  it('unmounted: no more requests', async () => {
    vi.useFakeTimers({ toFake: ['setTimeout', 'clearTimeout'] });
    await act(async () => render(<BusPanel />, root));
    await act(async () => void (await vi.advanceTimersByTimeAsync(0)));
    act(() => render(null, root));
    await act(async () => void (await vi.advanceTimersByTimeAsync(5000)));
    expect(asked.length).toBe(1);
  });

  it('the simulated bus: its axes with simulated drives, no SubDevices and no SDO tool', async () => {
    bus = simulated;
    const a = { id: 1, slot: 0, state: 'disabled', config: { name: 'x', unit: 'mm', dynamics: {}, drive: { kind: 'simulated', dead_time: 0.001, enable_delay: 0.005 } } } as unknown as AxisResource;
    (axes as unknown as { set: (v: unknown[]) => void }).set([a]);
    await act(async () => render(<BusPanel />, root));
    await settle();
    expect(text('[data-testid="bus-title"]')).toBe('Simulated bus: 1 axis');
    expect($$('[data-bus="simulated"] tr[data-axis]').map((r) => r.dataset.axis)).toEqual(['x']);
    expect($('[data-testid="subdevices"]')).toBeNull();
    expect($('button[name="sdo-open"]')).toBeNull();
  });
});

describe('the SDO tool', () => {
  const open = async (position: number) => {
    await act(async () => render(<BusPanel />, root));
    await settle();
    await click(`tr[data-subdevice="${position}"] button[name="sdo-open"]`);
    expect($(`tr[data-sdo-for="${position}"] [data-testid="sdo-tool"]`)).not.toBeNull();
  };

  it('a read shows the value in hex, unsigned and signed', async () => {
    sdo = ({ method, url }) => (method === 'GET' && url === '/api/v1/bus/subdevices/1/sdo/0x1018/1' ? [200, { position: 1, index: '0x1018', sub: 1, bytes: [206, 10, 255, 0], hex: 'ce0aff00', unsigned: 16714446, signed: 16714446, text: null }] : [404, null]);
    await open(1);
    await click('button[name="sdo-read"]');
    expect($('[data-testid="sdo-result"]')!.dataset.kind).toBe('read');
    expect(text('[data-sdo="address"]')).toBe('0x1018:01');
    expect(text('[data-sdo="value"]')).toBe('0x00FF0ACE');
    expect(text('[data-sdo="unsigned"]')).toBe('16714446');
    expect(text('[data-sdo="bytes"]')).toBe('ce 0a ff 00');
    expect($('[data-sdo="text"]')).toBeNull();
  });

  it('an abort shows the server’s text with the CiA-301 code; a bad index is refused at its field before asking', async () => {
    const detail = 'SubDevice 0 aborted the SDO transfer of 0x2000:0 with 0x06020000 (the object does not exist in the object dictionary)';
    sdo = () => [409, problem(409, 'sdo_aborted', 'Conflict', detail)];
    await open(0);
    input('input[name="sdo-index"]', '0x2000');
    input('input[name="sdo-sub"]', '0');
    await click('button[name="sdo-read"]');
    expect(text('[data-testid="sdo-error"]')).toBe(detail);
    expect($('[data-testid="sdo-result"]')).toBeNull();
    const before = asked.length;
    input('input[name="sdo-index"]', 'x');
    await click('button[name="sdo-read"]');
    expect(asked.length).toBe(before);
    expect(text('[data-field="index"] .field-error')).toBe('hex like 0x1018, or decimal');
    expect($('[data-testid="sdo-error"]')).toBeNull();
  });

  it('a write sends value and size and shows the value read back; the server’s 422 lands at the field', async () => {
    sdo = ({ method, url, body }) => {
      if (method !== 'PUT' || url !== '/api/v1/bus/subdevices/0/sdo/0x6065/0') return [404, null];
      const b = body as { value: number; size: number };
      if (b.size === 1) return [422, problem(422, 'validation_failed', 'Invalid request', 'value: does not fit 1 bytes (-128..255)', [{ field: 'value', message: 'does not fit 1 bytes (-128..255)' }])];
      return [200, { position: 0, index: '0x6065', sub: 0, bytes: [0x20, 0x4e, 0, 0], hex: '204e0000', unsigned: 20000, signed: 20000, text: null }];
    };
    await open(0);
    input('input[name="sdo-index"]', '0x6065');
    input('input[name="sdo-sub"]', '0');
    input('input[name="sdo-value"]', '0x4E20');
    input('select[name="sdo-size"]', '1');
    await click('button[name="sdo-write"]');
    expect(text('[data-field="value"] .field-error')).toBe('does not fit 1 bytes (-128..255)');
    expect($('[data-testid="sdo-error"]')).toBeNull();
    input('select[name="sdo-size"]', '4');
    await click('button[name="sdo-write"]');
    const puts = asked.filter((a) => a.method === 'PUT');
    expect(puts.map((p) => p.body)).toEqual([
      { value: 20000, size: 1 },
      { value: 20000, size: 4 },
    ]);
    expect($('[data-testid="sdo-result"]')!.dataset.kind).toBe('written');
    expect(text('[data-sdo="unsigned"]')).toBe('20000');
    expect($('[data-field="value"] .field-error')).toBeNull();
  });

  it('Write needs the engineer role (an operator may read)', async () => {
    auth.set({ kind: 'app', session: { auth_enabled: true, principal: 'user:otto', role: 'operator' } as never });
    await open(0);
    expect(($('button[name="sdo-write"]') as HTMLButtonElement).disabled).toBe(true);
    expect($('button[name="sdo-write"]')!.title).toBe('writing needs the engineer role');
    expect(($('button[name="sdo-read"]') as HTMLButtonElement).disabled).toBe(false);
  });
});
