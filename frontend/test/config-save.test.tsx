// The Configuration page's save at the DOM level (services mocked, the server a fetch double):
// Save asks for a dry run and shows what it says; an enabled axis is saved when no rebuild is
// needed; a rebuild is blocked until the axis is disabled; the fields show online and
// persistent values that differ from the configured ones.
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { render } from 'preact';
import { act } from 'preact/test-utils';
import { asSent, mountPoint, unmount } from './dom';

const h = vi.hoisted(() => ({ command: vi.fn(async () => ({ id: 1 })), refreshAxes: vi.fn(async () => {}) }));

vi.mock('../src/services', async () => {
  const { Store } = await import('../src/store');
  return {
    statuses: new Store(new Map()),
    live: { state: new Store({ kind: 'open', since: 0 }) },
    command: h.command,
    refreshAxes: h.refreshAxes,
  };
});

import { statuses } from '../src/services';
import { AxisConfigPage, DEFAULT_FORM, configOf } from '../src/ui/config/axis-config';
import type { AxisLiveStatus, AxisResource, ParameterResource } from '../src/api/types';
import type { ConfigChange } from '../src/config/change';

const config = configOf({ ...DEFAULT_FORM, name: 'x', softLimits: true }).config!;
const axis = { id: 1, slot: 0, state: 'standstill', config } as AxisResource;
const live = (state: AxisLiveStatus['state'], power_status: boolean, actual_position = 200) => {
  act(() => {
    statuses.get().set('x', { status: { state, power_status, actual_position } as AxisLiveStatus, cycle: 1, stale: false });
    statuses.emit();
  });
};
const param = (number: number, name: string, value: number, configured: number, persistent?: number) =>
  ({ number, name, storage: number, read_only: false, group: 'dynamics', value, configured_value: configured, persistent_value: persistent }) as ParameterResource;
const PARAMS = [param(1003, 'AxisVeloMax', 650, 500, 800), param(1001, 'AxisVeloManSlow', 10, 10), param(1015, 'AxisJogIncrementBackward', 3, 1)];

type Call = { method: string; url: string; body: unknown };
let calls: Call[];
/** What the server answers to the dry run and to the save. */
let dry: ConfigChange | { status: number; problem: unknown };
let real: ConfigChange;

const change = (c: Partial<ConfigChange>): ConfigChange => ({ dry_run: true, rebuild: false, rebuild_reasons: [], parameters: [], persistent_discarded: [], ...c });
const json = (b: unknown, status = 200) => new Response(JSON.stringify(b), { status, headers: { 'content-type': status < 300 ? 'application/json' : 'application/problem+json' } });

let root: HTMLElement;
beforeEach(() => {
  h.command.mockClear();
  calls = [];
  vi.stubGlobal(
    'fetch',
    vi.fn(async (input: RequestInfo | URL, init?: RequestInit) => {
      const sent = await asSent(input, init);
      const { method, url } = sent;
      const body = sent.body ? JSON.parse(sent.body) : undefined;
      calls.push({ method, url, body });
      if (method === 'GET' && url === '/api/v1/axes/x/parameters') return json(PARAMS);
      if (method === 'PUT' && url === '/api/v1/axes/x?dry_run=true') {
        if ('problem' in dry) return json(dry.problem, dry.status);
        return json({ ...axis, config: body, change: dry });
      }
      if (method === 'PUT' && url === '/api/v1/axes/x') return json({ ...axis, config: body, change: real });
      return json({}, 404);
    }),
  );
  root = mountPoint();
});
afterEach(() => {
  unmount(root);
  vi.unstubAllGlobals();
  statuses.get().clear();
});

const q = <T extends Element>(sel: string) => root.querySelector(sel) as T | null;
const button = (n: string) => q<HTMLButtonElement>(`button[name="${n}"]`);
const text = (sel: string) => q(sel)?.textContent?.trim() ?? null;
const settle = () => act(async () => {
  for (let i = 0; i < 5; i++) await new Promise((r) => setTimeout(r, 0));
});
const type = (name: string, v: string) =>
  act(() => {
    const i = q<HTMLInputElement>(`input[name="${name}"]`)!;
    i.value = v;
    i.dispatchEvent(new Event('input', { bubbles: true }));
  });
async function show() {
  act(() => render(<AxisConfigPage axis={axis} />, root));
  await settle();
}
async function clickSave() {
  await act(async () => {
    q<HTMLFormElement>('form')!.dispatchEvent(new Event('submit', { bubbles: true, cancelable: true }));
  });
  await settle();
}

describe('saving the configuration', () => {
  it('an enabled axis: Save asks for a dry run, the panel says nothing is reset, confirming saves that configuration', async () => {
    live('standstill', true);
    dry = change({ parameters: [{ name: 'AxisVeloManSlow', number: 1001, configured: 10, online: 10, new: 20 }] });
    real = { ...dry, dry_run: false } as ConfigChange;
    await show();
    expect(button('save')!.disabled).toBe(false);
    // Delete stays blocked while the axis is enabled, the reason beside it
    expect(button('delete')!.disabled).toBe(true);
    expect(text('[data-testid="delete-blocked"]')).toMatch(/enabled: switch it off to re-create or delete it/);
    type('dynamics.jog_velocity_slow', '20');
    await clickSave();
    const asked = calls.find((c) => c.url.endsWith('?dry_run=true'))!;
    expect(asked.method).toBe('PUT');
    expect((asked.body as typeof config).dynamics.jog_velocity_slow).toBe(20);
    expect(calls.some((c) => c.url === '/api/v1/axes/x')).toBe(false);
    expect(q('[data-testid="save-panel"]')!.getAttribute('data-rebuild')).toBe('0');
    expect(text('[data-testid="save-headline"]')).toBe('This save changes 1 parameter online; nothing is reset.');
    expect(text('[data-testid="save-changes"] tr[data-param="AxisVeloManSlow"] .new')).toBe('20');
    expect(q('[data-testid="save-blocked"]')).toBeNull();
    expect(button('confirm-save')!.disabled).toBe(false);
    await act(async () => button('confirm-save')!.click());
    await settle();
    const saved = calls.find((c) => c.method === 'PUT' && c.url === '/api/v1/axes/x')!;
    expect(saved.body).toEqual(asked.body);
    expect(q('[data-testid="save-panel"]')).toBeNull();
    expect(text('[data-testid="save-result"]')).toMatch(/^Saved\. 1 parameter changed online; nothing was reset\. AxisVeloManSlow 10 → 20\./);
    expect(h.refreshAxes).toHaveBeenCalled();
  });

  it('a rebuild of an enabled axis is blocked, with the reason and Disable now; once disabled it can be saved', async () => {
    live('standstill', true, 123.4567);
    dry = change({
      rebuild: true,
      rebuild_reasons: ['unit changed'],
      parameters: [{ name: 'AxisVeloMax', number: 1003, configured: 500, online: 650, new: 700 }],
      persistent_discarded: [{ name: 'AxisVeloMax', number: 1003, configured: 500, online: 650, new: 800 }],
    });
    real = { ...dry, dry_run: false } as ConfigChange;
    await show();
    await act(async () => {
      const s = q<HTMLSelectElement>('select[name="unit"]')!;
      s.value = 'm';
      s.dispatchEvent(new Event('change', { bubbles: true }));
    });
    await clickSave();
    expect(q('[data-testid="save-panel"]')!.getAttribute('data-rebuild')).toBe('1');
    expect(text('[data-testid="save-headline"]')).toBe(
      'Warning: The axis will be re-created (unit changed): its position (now 123.457 mm), homed state and online values are lost.',
    );
    expect(text('[data-testid="save-changes"] tr[data-param="AxisVeloMax"] .online')).toBe('650');
    expect(text('[data-testid="save-discarded"] li[data-param="AxisVeloMax"]')).toMatch(/persistent 800 is given up; the configured 700 applies/);
    expect(text('[data-testid="save-lost"] li[data-param="AxisJogIncrementBackward"]')).toBe('AxisJogIncrementBackward (#1015): online 3 → 1 (configured)');
    expect(button('confirm-save')!.disabled).toBe(true);
    expect(text('[data-testid="save-blocked"]')).toMatch(/^Save is blocked: re-creating the axis needs it disabled, and it is enabled\./);
    // one Disable button (the one beside Delete waits while the panel is open)
    expect(root.querySelectorAll('button[name="disable-axis"]').length).toBe(1);
    await act(async () => button('disable-axis')!.click());
    expect(h.command).toHaveBeenCalledWith('x', 'power', expect.objectContaining({ enable: false }));
    live('disabled', false, 123.4567);
    expect(q('[data-testid="save-blocked"]')).toBeNull();
    expect(button('confirm-save')!.disabled).toBe(false);
    await act(async () => button('confirm-save')!.click());
    await settle();
    expect(q('[data-testid="save-result"]')!.getAttribute('data-rebuild')).toBe('1');
    expect(text('[data-testid="save-result"]')).toMatch(/re-created \(unit changed\).*1 persistent value discarded \(AxisVeloMax 800\)/);
  });

  it('Cancel (or Escape) saves nothing', async () => {
    live('standstill', true);
    dry = change({});
    await show();
    await clickSave();
    expect(q('[data-testid="save-panel"]')).not.toBeNull();
    await act(async () => button('cancel-save')!.click());
    expect(q('[data-testid="save-panel"]')).toBeNull();
    await clickSave();
    await act(async () => {
      document.dispatchEvent(new KeyboardEvent('keydown', { key: 'Escape' }));
    });
    expect(q('[data-testid="save-panel"]')).toBeNull();
    expect(calls.some((c) => c.url === '/api/v1/axes/x')).toBe(false);
  });

  it('the dry run’s field errors are shown at their field, and no panel', async () => {
    live('disabled', false);
    dry = {
      status: 422,
      problem: { type: 't', title: 'Invalid request', status: 422, detail: '', code: 'validation_failed', errors: [{ field: 'dynamics.jog_deadman_max', message: 'must be between 0.05 and 10 s' }] },
    };
    await show();
    type('dynamics.jog_deadman_max', '20');
    await clickSave();
    expect((calls.find((c) => c.url.endsWith('?dry_run=true'))!.body as typeof config).dynamics.jog_deadman_max).toBe(20);
    expect(text('[data-field="dynamics.jog_deadman_max"] .field-error')).toBe('must be between 0.05 and 10 s');
    expect(q('[data-testid="save-panel"]')).toBeNull();
  });

  it('the fields show the online and persistent values that differ from the configured one', async () => {
    live('standstill', true);
    await show();
    expect(text('[data-side="dynamics.max_velocity"]')).toBe('online 650 · persistent 800');
    expect(q('[data-side="dynamics.jog_velocity_slow"]')).toBeNull();
  });
});
