// The System page's bus panel at the DOM level against a fetch double: the EtherCAT view (state,
// counters, PDU timeout, TX/RX loop, notice, SubDevices with the mapping each drive took and the
// ones it refused, a faulted bus's banner with its reason), read again every second; Reset bus
// (disabled while it runs and on the simulated bus, the server's problem shown when it fails); the SDO tool (a read
// shown as hex/unsigned/signed, an abort with the server's text, a write read back, Write for
// the engineer role only); the simulated bus as its axes.
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { render } from 'preact';
import { act } from 'preact/test-utils';
import { asSent, enter, mountPoint, problem, settle, stubFetch, unmount, type FetchCall } from './dom';
import { emulated, simulated, strictDrive, sub } from './bus-fixture';

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
import { BusPanel } from '../src/ui/system/bus';
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

describe('issue 22: the negotiated process image, the frame counters, the TX/RX loop and Reset bus', () => {
  const stopped = () =>
    emulated({
      state: 'faulted',
      fault_reason: 'the TX/RX loop was stopped (injected fault)',
      lost_frames: 40,
      faults: 1,
      txrx: { running: false, restarts: 0, thread: 'SCHED_FIFO 79, pinned to CPU 0' },
    });

  it('PDU timeout, the TX/RX loop, the late/duplicate/malformed counters, the notice; a drive that refused the full mapping: a row under it with what it lacks and why', async () => {
    bus = emulated({
      late_replies: 12,
      duplicate_replies: 3,
      notice: 'CiA-402 drive 2 (motiond emulated servo 3) is used by no axis: give an axis drive.kind cia402 with drive.subdevice 2.',
      subdevices: [sub(0, 'x', { drive: strictDrive() }), sub(1, 'y')],
    });
    await act(async () => render(<BusPanel />, root));
    await settle();
    expect(text('[data-testid="bus-pdu-timeout"]')).toBe('PDU timeout 10 ms');
    expect($('[data-testid="bus-txrx"]')!.dataset.running).toBe('1');
    expect($('[data-testid="bus-txrx"] [data-led]')!.dataset.led).toBe('running');
    expect(text('[data-testid="bus-txrx-restarts"] b')).toBe('0');
    expect(text('[data-testid="bus-txrx-thread"] b')).toBe('SCHED_FIFO 79, pinned to CPU 0');
    expect($$('[data-testid="bus-counters"] .kpi-label').map((e) => e.textContent)).toEqual([
      'Frames',
      'Lost frames',
      'Late replies',
      'Duplicate replies',
      'Malformed frames',
      'Bus faults',
      'WKC errors',
      'WKC last / expected',
      'Errors in a row / max',
      'DC cycle offset',
    ]);
    expect(text('[data-kpi="late_replies"] .kpi-value')).toBe('12');
    expect($('[data-kpi="late_replies"]')!.className).toMatch(/kpi-warn/);
    expect(text('[data-kpi="duplicate_replies"] .kpi-value')).toBe('3');
    expect(text('[data-kpi="malformed_frames"] .kpi-value')).toBe('0');
    expect(text('[data-testid="bus-notice"]')).toBe(bus.notice!);
    // SubDevice 0: the available mapping in its column and, in a row of its own (shown on a phone too), what it lacks and the refusal
    expect(text('tr[data-subdevice="0"] [data-col="mapping"]')).toBe('available · 13 B out, 17 B in');
    expect($('tr[data-subdevice="0"] [data-col="mapping"]')!.dataset.mapping).toBe('available');
    const detail = $('tr[data-mapping-for="0"]')!;
    expect(detail.querySelector('[data-testid="mapping-taken"]')!.textContent).toBe('Process data available · 13 B out, 17 B in');
    expect(detail.querySelector('[data-testid="mapping-missing"]')!.textContent).toBe('Missing objects 0x60B8, 0x60B9, 0x60BA, 0x60BB, 0x60FD');
    const refused = detail.querySelector('[data-testid="mapping-refused"]') as HTMLElement;
    expect(refused.dataset.alCode).toBe('0x001D');
    expect(refused.textContent).toBe('Refused full at PRE-OP to SAFE-OP — AL status 0x001D Invalid Output Configuration');
    // SubDevice 1 took the full mapping: no row under it
    expect($('tr[data-mapping-for="1"]')).toBeNull();
    expect($('[data-testid="bus-banner"]')).toBeNull();
  });

  it('the TX/RX loop stopped: its reason in the banner; Reset bus posts {} to /bus/reset, is disabled while it runs, and shows the bus it answers (OP, 1 restart)', async () => {
    bus = stopped();
    let release: () => void = () => {};
    const stub = globalThis.fetch;
    asked = [];
    vi.stubGlobal(
      'fetch',
      vi.fn(async (input: RequestInfo | URL, init?: RequestInit) => {
        const { method, url, body } = await asSent(input, init);
        asked.push({ method, url, body: body ? JSON.parse(body) : undefined });
        if (url === '/api/v1/bus/reset') {
          await new Promise<void>((r) => (release = r));
          bus = emulated({ lost_frames: 40, faults: 1, txrx: { running: true, restarts: 1, thread: 'SCHED_FIFO 79, pinned to CPU 0' } });
          return new Response(JSON.stringify(bus), { status: 200, headers: { 'content-type': 'application/json' } });
        }
        return stub(input, init);
      }),
    );
    await act(async () => render(<BusPanel />, root));
    await settle();
    expect($('[data-testid="bus-state"]')!.dataset.state).toBe('faulted');
    expect(text('[data-testid="bus-banner"]')).toMatch(/^Bus faulted\. The TX\/RX loop was stopped \(injected fault\)\. No frame goes out: /);
    expect(text('[data-testid="bus-banner"]')).toMatch(/Reset bus \(or an axis's MC_Reset\) starts the TX\/RX loop again/);
    expect($('[data-testid="bus-txrx"]')!.dataset.running).toBe('0');
    expect($('[data-testid="bus-txrx"] [data-led]')!.dataset.led).toBe('stopped');
    const button = () => $('button[name="bus-reset"]') as HTMLButtonElement;
    expect(button().disabled).toBe(false);
    expect(button().textContent).toBe('Reset bus');
    await click('button[name="bus-reset"]');
    // running: disabled, says so
    expect(button().disabled).toBe(true);
    expect(button().textContent).toBe('Resetting…');
    expect(button().title).toBe('the bus is being reset');
    const posts = asked.filter((a) => a.method === 'POST');
    expect(posts).toEqual([{ method: 'POST', url: '/api/v1/bus/reset', body: {} }]);
    await act(async () => release());
    await settle();
    expect(button().disabled).toBe(false);
    expect($('[data-testid="bus-state"]')!.dataset.state).toBe('op');
    expect($('[data-testid="bus-banner"]')).toBeNull();
    expect(text('[data-testid="bus-txrx-restarts"] b')).toBe('1');
    expect($('[data-testid="bus-reset-result"]')!.dataset.ok).toBe('1');
    expect(text('[data-testid="bus-reset-result"] span')).toBe('Bus reset: every SubDevice in OP again. Axes the fault stopped stay in ErrorStop until their reset (MC_Reset).');
  });

  it("a reset that fails shows the server's problem; the button can be pressed again", async () => {
    bus = stopped();
    const detail = 'SubDevice 1 (motiond emulated servo 2) still in SAFE-OP, AL status code 0x001b (Sync Manager Watchdog)';
    asked = stubFetch((c) => (c.url === '/api/v1/bus' ? [200, bus] : c.url === '/api/v1/bus/reset' ? [503, problem(503, 'bus_reset_failed', 'Service Unavailable', detail)] : [404, null]));
    await act(async () => render(<BusPanel />, root));
    await settle();
    await click('button[name="bus-reset"]');
    expect($('[data-testid="bus-reset-result"]')!.dataset.ok).toBe('0');
    expect($('[data-testid="bus-reset-result"]')!.getAttribute('role')).toBe('alert');
    expect(text('[data-testid="bus-reset-result"] span')).toBe(`Bus reset failed — Service Unavailable: ${detail}`);
    expect(($('button[name="bus-reset"]') as HTMLButtonElement).disabled).toBe(false);
    expect($('[data-testid="bus-state"]')!.dataset.state).toBe('faulted');
    await click('button[name="bus-reset-close"]');
    expect($('[data-testid="bus-reset-result"]')).toBeNull();
  });

  it('Reset bus is disabled on the simulated bus (it has no segment) and for an operator', async () => {
    bus = simulated;
    await act(async () => render(<BusPanel />, root));
    await settle();
    const b = $('button[name="bus-reset"]') as HTMLButtonElement;
    expect(b.disabled).toBe(true);
    expect(b.title).toBe('motiond runs the simulated bus: there is no EtherCAT segment to reset');
    expect($('[data-testid="bus-txrx"]')).toBeNull();
    unmount(root);
    root = mountPoint();
    bus = emulated();
    auth.set({ kind: 'app', session: { auth_enabled: true, principal: 'user:otto', role: 'operator' } as never });
    await act(async () => render(<BusPanel />, root));
    await settle();
    expect(($('button[name="bus-reset"]') as HTMLButtonElement).disabled).toBe(true);
    expect($('button[name="bus-reset"]')!.title).toBe('resetting the bus needs the engineer role');
    expect(asked.some((a) => a.method === 'POST')).toBe(false);
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
