// The System page's panels at the DOM level against a fetch double: the audit log (filters, the
// engineer role's 403 shown as such), the configuration import (a diff before anything is sent;
// the server's 409 and 422 shown at the diff), the bus.
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { render } from 'preact';
import { act } from 'preact/test-utils';
import { asSent, mountPoint, problem, unmount } from './dom';

vi.mock('../src/services', async () => {
  const { Store } = await import('../src/store');
  return {
    axes: new Store<unknown[]>([]),
    statuses: new Store(new Map()),
    refreshAxes: vi.fn(async () => {}),
  };
});

import { AuditPanel, ConfigPanel, clockText } from '../src/ui/system/system';
import { parseRoute, href } from '../src/router';
import { ms, plantText, simulatedAxes } from '../src/system/bus';

type Answer = [number, unknown];
let asked: { method: string; url: string; body: unknown }[];
let answer: (method: string, url: string, body: unknown) => Answer;

let root: HTMLElement;
beforeEach(() => {
  asked = [];
  vi.stubGlobal(
    'fetch',
    vi.fn(async (input: RequestInfo | URL, init?: RequestInit) => {
      const sent = await asSent(input, init);
      const { method, url } = sent;
      const body = sent.body ? JSON.parse(sent.body) : undefined;
      asked.push({ method, url, body });
      const [status, json] = answer(method, url, body);
      return new Response(json === null ? null : JSON.stringify(json), { status });
    }),
  );
  root = mountPoint();
});
afterEach(() => {
  unmount(root);
  vi.unstubAllGlobals();
});

/** Lets the fetch double's answers and the renders they cause happen. */
async function settle(n = 5) {
  for (let i = 0; i < n; i++) await act(async () => await new Promise((r) => setTimeout(r, 0)));
}

const $ = (sel: string) => root.querySelector(sel) as HTMLElement | null;
const $$ = (sel: string) => [...root.querySelectorAll(sel)] as HTMLElement[];

function input(sel: string, value: string) {
  const el = $(sel) as HTMLInputElement | HTMLSelectElement;
  el.value = value;
  el.dispatchEvent(new Event(el.tagName === 'SELECT' ? 'change' : 'input', { bubbles: true }));
}

const entry = (id: number, action: string, target: string, outcome: string) => ({
  id,
  at: '2026-11-25T12:00:00.000Z',
  action,
  target,
  outcome,
  client_id: 'e2e',
  client_addr: '127.0.0.1:1',
  principal: null,
  command_id: null,
  detail: { velocity: 10 },
});

describe('the audit log', () => {
  it('lists the newest page; the filters narrow it', async () => {
    answer = (_m, url) => {
      if (url.includes('before_id=')) return [200, [entry(1, 'axis.create', 'x', 'committed')]];
      return [200, [entry(3, 'command.power', 'x', 'accepted'), entry(2, 'command.move-absolute', 'y', 'rejected:control_held')]];
    };
    await act(async () => render(<AuditPanel />, root));
    await settle();
    expect(asked[0].url).toBe('/api/v1/audit?limit=100');
    expect($$('[data-testid="audit"] tbody tr[data-audit-id]').map((r) => r.dataset.auditId)).toEqual(['3', '2']);
    input('input[name="audit-action"]', 'command.power');
    await settle(1);
    expect($$('tr[data-audit-id]').map((r) => r.dataset.auditId)).toEqual(['3']);
    expect($('[data-testid="audit-count"]')!.textContent).toBe('1 of 2 loaded');
    input('input[name="audit-action"]', '');
    input('select[name="audit-outcome"]', '!failures');
    await settle(1);
    expect($$('tr[data-audit-id]').map((r) => r.dataset.auditId)).toEqual(['2']);
    ($('button[name="audit-clear"]') as HTMLButtonElement).click();
    await settle(1);
    expect($$('tr[data-audit-id]').length).toBe(2);
    // the first page was short: it is the whole log
    expect($('[data-testid="audit-end"]')).not.toBeNull();
  });

  it('a full page offers Load older, which asks before the oldest id', async () => {
    const page = Array.from({ length: 100 }, (_, i) => entry(200 - i, 'command.power', 'x', 'accepted'));
    answer = (_m, url) => (url.includes('before_id=') ? [200, [entry(50, 'axis.create', 'x', 'committed')]] : url.includes('since_id=') ? [200, []] : [200, page]);
    await act(async () => render(<AuditPanel />, root));
    await settle();
    expect($$('tr[data-audit-id]').length).toBe(100);
    ($('button[name="audit-older"]') as HTMLButtonElement).click();
    await settle();
    expect(asked.some((a) => a.url === '/api/v1/audit?limit=100&before_id=101')).toBe(true);
    expect($$('tr[data-audit-id]').length).toBe(101);
    expect($('[data-testid="audit-end"]')).not.toBeNull();
  });

  it('403 (the engineer role): the server’s message, shown as what it is', async () => {
    answer = () => [403, problem(403, 'role_insufficient', 'Forbidden', 'this needs the role engineer or higher; user:otto has the role operator')];
    await act(async () => render(<AuditPanel />, root));
    await settle();
    const b = $('[data-testid="audit-forbidden"]')!;
    expect(b.textContent).toContain('The audit log needs the engineer role.');
    expect(b.textContent).toContain('user:otto has the role operator');
    expect($('[data-testid="audit"]')).toBeNull();
  });
});

const doc = (maxV: number) => ({
  version: 1,
  axes: [
    {
      id: 1,
      config: { name: 'x', unit: 'mm', dynamics: { max_velocity: maxV, acceleration: 1, deceleration: 1, jerk: 1, jog_velocity_slow: 1, jog_velocity_fast: 1 }, drive: { kind: 'simulated' } },
      persistent_parameters: {},
    },
  ],
  cam_tables: [],
});

async function chooseFile(name: string, text: string) {
  const el = $('input[name="config-file"]') as HTMLInputElement;
  const file = new File([text], name, { type: 'application/json' });
  Object.defineProperty(el, 'files', { value: [file], configurable: true });
  await act(async () => {
    el.dispatchEvent(new Event('change', { bubbles: true }));
  });
  await settle();
}

describe('configuration import', () => {
  it('shows the diff first; only Import sends PUT /config with the file', async () => {
    let active = doc(500);
    answer = (m, url, body) => {
      if (m === 'GET' && url === '/api/v1/config') return [200, active];
      if (m === 'PUT' && url === '/api/v1/config') {
        active = body as ReturnType<typeof doc>;
        return [200, active];
      }
      return [404, null];
    };
    await act(async () => render(<ConfigPanel />, root));
    await chooseFile('cfg.json', JSON.stringify(doc(400)));
    expect(asked.filter((a) => a.method === 'PUT')).toEqual([]);
    const d = $('[data-testid="import-diff"]')!;
    expect(d.querySelector('[data-diff-item="x"]')!.getAttribute('data-diff-kind')).toBe('changed');
    const row = d.querySelector('tr[data-path="dynamics.max_velocity"]')!;
    expect(row.textContent).toContain('500 → 400');
    expect($('[data-testid="diff-summary"]')!.textContent).toBe('1 changed (1 field), 0 added, 0 removed');
    ($('button[name="import-confirm"]') as HTMLButtonElement).click();
    await settle();
    const puts = asked.filter((a) => a.method === 'PUT');
    expect(puts.length).toBe(1);
    expect(puts[0].body).toEqual(doc(400));
    expect($('[data-testid="import-done"]')!.textContent).toContain('Imported cfg.json: 1 axis, 0 cam tables');
    expect($('[data-testid="import-diff"]')).toBeNull();
  });

  it('409 (an axis enabled) and 422 (field errors by axis) are shown at the diff, which stays', async () => {
    let put = 0;
    answer = (m) => {
      if (m === 'GET') return [200, doc(500)];
      put++;
      if (put === 1) return [409, problem(409, 'axis_not_disabled', 'Conflict', "axis 'x' is not disabled: switch it off (DELETE its power command) first")];
      return [
        422,
        problem(422, 'validation_failed', 'Invalid request', 'axes[0].config.dynamics.max_velocity: must be a finite number > 0', [
          { field: 'axes[0].config.dynamics.max_velocity', message: 'must be a finite number > 0' },
        ]),
      ];
    };
    await act(async () => render(<ConfigPanel />, root));
    await chooseFile('bad.json', JSON.stringify(doc(-1)));
    ($('button[name="import-confirm"]') as HTMLButtonElement).click();
    await settle();
    let p = $('[data-testid="import-problem"]')!;
    expect(p.dataset.status).toBe('409');
    expect(p.textContent).toContain('All axes must be disabled before an import.');
    expect(p.textContent).toContain("axis 'x' is not disabled");
    ($('button[name="import-confirm"]') as HTMLButtonElement).click();
    await settle();
    p = $('[data-testid="import-problem"]')!;
    expect(p.dataset.status).toBe('422');
    expect($('[data-testid="import-errors"] li')!.textContent).toBe("axis 'x': dynamics.max_velocity: must be a finite number > 0");
    expect($('[data-testid="import-diff"]')).not.toBeNull();
  });

  it('a file that is not JSON, or not a configuration, never gets to a diff', async () => {
    answer = () => [200, doc(500)];
    await act(async () => render(<ConfigPanel />, root));
    await chooseFile('notes.txt', 'hello');
    expect($('[data-testid="config-error"]')!.textContent).toMatch(/^notes\.txt is not JSON/);
    await chooseFile('other.json', '{"foo": 1}');
    expect($('[data-testid="config-error"]')!.textContent).toMatch(/no "axes" list/);
    expect($('[data-testid="import-diff"]')).toBeNull();
    expect(asked.filter((a) => a.url === '/api/v1/config').length).toBe(0);
  });

  it('the configuration changed after the diff was made: the new diff is shown, nothing is sent', async () => {
    let active = doc(500);
    answer = (m) => (m === 'GET' ? [200, active] : [200, active]);
    await act(async () => render(<ConfigPanel />, root));
    await chooseFile('cfg.json', JSON.stringify(doc(400)));
    active = doc(450);
    ($('button[name="import-confirm"]') as HTMLButtonElement).click();
    await settle();
    expect(asked.filter((a) => a.method === 'PUT')).toEqual([]);
    expect($('[data-testid="diff-stale"]')).not.toBeNull();
    expect($('tr[data-path="dynamics.max_velocity"]')!.textContent).toContain('450 → 400');
  });
});

describe('the route and the bus', () => {
  it('#/system is the System page', () => {
    expect(parseRoute('#/system')).toEqual({ page: 'system' });
    expect(href({ page: 'system' })).toBe('#/system');
  });

  it('the simulated bus: the axes with simulated drives, by id', () => {
    const a = (id: number, name: string, kind?: string) => ({ id, slot: id, state: 'disabled', config: { name, unit: 'mm', dynamics: {}, drive: kind ? { kind } : undefined } }) as never;
    expect(simulatedAxes([])).toEqual([]);
    expect(simulatedAxes([a(2, 'y', 'simulated'), a(1, 'x'), a(3, 'z', 'cia402')]).map((x: { config: { name: string } }) => x.config.name)).toEqual(['x', 'y']);
    expect(plantText({ kind: 'pt2', natural_frequency_hz: 50, damping: 0.8 })).toBe('PT2 50 Hz, ζ 0.8');
    expect(plantText({ kind: 'pt1', time_constant: 0.01 })).toBe('PT1 T 0.01 s');
    expect(ms(0.001)).toBe('1 ms');
    expect(ms(0.005)).toBe('5 ms');
    expect(ms(undefined)).toBe('—');
  });
});

describe('the clock KPI', () => {
  it('says real time plainly and names what is not', () => {
    const c = { cycle: 1500, cycle_time_s: 0.001, time_s: 1.5, advancing: false };
    expect(clockText({ ...c, mode: 'real' })).toBe('real');
    expect(clockText({ ...c, mode: 'virtual' })).toBe('virtual');
    expect(clockText({ ...c, mode: 'fast', factor: 10 })).toBe('fast ×10');
    expect(clockText({ ...c, mode: 'fast', factor: null })).toBe('fast (max)');
  });
});
