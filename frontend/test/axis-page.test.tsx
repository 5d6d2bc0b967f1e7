// The axis page at the DOM level (services mocked, parameters from a fetch double): going
// from one axis to another — or to another axis under the same name after an import — never
// keeps the previous axis's state (jog labels, inching steps, move form, enables), and the
// parameters shown and sent are always the axis's own. MC_Power keeps the axis's override.
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { render } from 'preact';
import { act } from 'preact/test-utils';
import { mountPoint, unmount, urlOf } from './dom';

const h = vi.hoisted(() => ({ command: vi.fn(async () => ({ id: 1 })), stopAndRelease: vi.fn(async () => ({ stop: { id: 9 }, followed: Promise.resolve('released') })) }));

vi.mock('../src/services', async () => {
  const { Store } = await import('../src/store');
  return {
    axes: new Store<unknown[]>([]),
    axesLoaded: new Store(true),
    statuses: new Store(new Map()),
    system: new Store(null),
    live: { state: new Store({ kind: 'open', since: 0 }), lastMessageAt: null },
    command: h.command,
    stopAndRelease: h.stopAndRelease,
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
// uPlot and the command log are not what is tested here.
vi.mock('../src/ui/axis/trend', () => ({ Trend: () => null }));
vi.mock('../src/ui/shared/command-log', () => ({ CommandLog: () => null }));

import { axes, statuses } from '../src/services';
import { AxisPage } from '../src/ui/axis/axis-page';
import { powerOverride } from '../src/ui/axis/online';
import { useParameters } from '../src/ui/axis/axis-params';
import type { AxisLiveStatus, AxisResource, ParameterResource } from '../src/api/types';

const axis = (id: number, name: string, modulo = false) =>
  ({ id, state: 'standstill', config: { name, unit: 'mm', modulo: modulo ? { period: 360 } : null, soft_limits: null } }) as unknown as AxisResource;
const param = (number: number, value: number) => ({ number, value }) as ParameterResource;
/** #1001 slow, #1002 fast, #1014 step +, #1015 step − */
const paramsOf = (slow: number, fast: number, fwd: number, back: number) => [param(1001, slow), param(1002, fast), param(1014, fwd), param(1015, back)];

/** Parameter requests wait until the test answers them, by URL. */
let waiting: { url: string; answer: (body: unknown) => void }[];
let root: HTMLElement;
beforeEach(() => {
  h.command.mockClear();
  waiting = [];
  vi.stubGlobal(
    'fetch',
    vi.fn(
      (input: RequestInfo | URL) =>
        new Promise<Response>((resolve) => waiting.push({ url: urlOf(input), answer: (b) => resolve(new Response(JSON.stringify(b), { status: 200 })) })),
    ),
  );
  root = mountPoint();
});
afterEach(() => {
  unmount(root);
  vi.unstubAllGlobals();
  statuses.get().clear();
});

async function answer(url: string, body: unknown) {
  const i = waiting.findIndex((w) => w.url === url);
  expect(i, `a request for ${url} (asked: ${waiting.map((w) => w.url)})`).toBeGreaterThanOrEqual(0);
  const [w] = waiting.splice(i, 1);
  await act(async () => {
    w.answer(body);
    await new Promise((r) => setTimeout(r, 0));
  });
}

const q = <T extends Element>(sel: string) => root.querySelector(sel) as T;
const jogLabel = (k: string) => q(`[data-jog="${k}"]`).textContent;
const input = (n: string) => q<HTMLInputElement>(`input[name="${n}"]`);
const button = (n: string) => q<HTMLButtonElement>(`button[name="${n}"]`);
const type = (n: string, v: string) =>
  act(() => {
    input(n).value = v;
    input(n).dispatchEvent(new Event('input', { bubbles: true }));
  });
const show = (name: string) => act(() => render(<AxisPage axis={name} tab="online" />, root));

describe('axis page', () => {
  it('another axis: nothing of the previous one is kept, its parameters are waited for', async () => {
    axes.set([axis(1, 'x', true), axis(2, 'y')]);
    show('x');
    await answer('/api/v1/axes/x/parameters', paramsOf(10, 100, 2.5, 0.5));
    expect(jogLabel('slow-forward')).toContain('10 mm/s');
    expect(input('inch-step-forward').value).toBe('2.5');
    // the user's inputs on x: a modulo move with a target, a step, feed + off
    act(() => q<HTMLButtonElement>('[data-move="move-modulo"]').click());
    type('position', '123');
    type('inch-step-backward', '9');
    act(() => input('feed-positive').click());
    expect(input('feed-positive').checked).toBe(false);

    // e.g. the "coupled to master y" link: the same component, another axis
    show('y');
    // until y's parameters are there: no labels, no steps, no inching of x's velocity
    expect(jogLabel('slow-forward')).toContain('…');
    expect(jogLabel('fast-forward')).toContain('…');
    expect(input('inch-step-forward').value).toBe('');
    expect(input('inch-step-backward').value).toBe('');
    expect(button('inch-forward').disabled).toBe(true);
    expect(root.querySelector('[data-move="move-modulo"]')).toBeNull(); // y is linear
    expect(q('[data-move="move-absolute"]').classList.contains('active')).toBe(true);
    expect(input('position').value).toBe('');
    expect(input('velocity').value).toBe('');
    expect(input('feed-positive').checked).toBe(true);
    await answer('/api/v1/axes/y/parameters', paramsOf(3, 30, 7, 1));
    expect(jogLabel('slow-forward')).toContain('3 mm/s');
    expect(jogLabel('fast-backward')).toContain('30 mm/s');
    expect(input('inch-step-forward').value).toBe('7');
    expect(input('inch-step-backward').value).toBe('1');
    expect(input('velocity').value).toBe('30');
    // a step of y goes at y's #1001
    await act(async () => button('inch-forward').click());
    expect(h.command).toHaveBeenCalledWith('y', 'jog', { direction: 'forward', mode: 'inching', position: 7, velocity: 3 });
  });

  it('another axis under the same name (an import gives new ids): started afresh, parameters read again', async () => {
    axes.set([axis(1, 'x')]);
    show('x');
    await answer('/api/v1/axes/x/parameters', paramsOf(10, 100, 2.5, 0.5));
    type('inch-step-forward', '4');
    expect(input('inch-step-forward').value).toBe('4');
    act(() => axes.set([axis(5, 'x')]));
    expect(jogLabel('slow-forward')).toContain('…');
    expect(input('inch-step-forward').value).toBe('');
    await answer('/api/v1/axes/x/parameters', paramsOf(20, 200, 8, 6));
    expect(jogLabel('slow-forward')).toContain('20 mm/s');
    expect(input('inch-step-forward').value).toBe('8');
  });
});

describe('useParameters', () => {
  it('gives no map of another axis while the new one loads', async () => {
    const seen: (number | null)[] = [];
    function Probe({ name, id }: { name: string; id: number }) {
      const m = useParameters(name, id);
      seen.push((m?.get(1001)?.value as number | undefined) ?? null);
      return null;
    }
    act(() => render(<Probe name="x" id={1} />, root));
    await answer('/api/v1/axes/x/parameters', [param(1001, 10)]);
    expect(seen.at(-1)).toBe(10);
    act(() => render(<Probe name="y" id={2} />, root));
    expect(seen.at(-1)).toBeNull();
    act(() => render(<Probe name="x" id={3} />, root));
    expect(seen.at(-1)).toBeNull();
    // the late answer for y is not taken for the axis now shown
    await answer('/api/v1/axes/y/parameters', [param(1001, 3)]);
    expect(seen.at(-1)).toBeNull();
    await answer('/api/v1/axes/x/parameters', [param(1001, 20)]);
    expect(seen.at(-1)).toBe(20);
  });
});

describe('MC_Power from the Online tab', () => {
  const liveStatus = (over: Record<string, unknown>) =>
    act(() => {
      const status = { state: 'standstill', power_status: true, enable_positive: true, enable_negative: true, error_id: 0, ...over } as unknown as AxisLiveStatus;
      statuses.set(new Map([['x', { status, cycle: 1, stale: false }]]));
    });

  it('Set and Disable keep the axis’s power override (another client’s 50 %)', async () => {
    axes.set([axis(1, 'x')]);
    show('x');
    liveStatus({ power_override_percent: 50, set_override_factor: 1, override_percent: 50 });
    await act(async () => button('power-set').click());
    expect(h.command).toHaveBeenLastCalledWith('x', 'power', { enable: true, enable_positive: true, enable_negative: true, override_percent: 50 });
    await act(async () => button('power-off').click());
    expect(h.command).toHaveBeenLastCalledWith('x', 'power', { enable: false, enable_positive: false, enable_negative: false, override_percent: 50 });
    liveStatus({ power_override_percent: 80, set_override_factor: 1, override_percent: 80 });
    await act(async () => button('power-set').click());
    expect(h.command).toHaveBeenLastCalledWith('x', 'power', expect.objectContaining({ enable: true, override_percent: 80 }));
  });

  it('100 % only while the status is unknown', () => {
    expect(powerOverride(null)).toBe(100);
    expect(powerOverride(undefined)).toBe(100);
    expect(powerOverride({ power_override_percent: 0 })).toBe(0);
    expect(powerOverride({ power_override_percent: 37.5 })).toBe(37.5);
  });
});

describe('Stop (F6) from the Online tab', () => {
  it('is TwinCAT XAE’s: the stop is released at standstill (stopAndRelease), said in its tooltip', async () => {
    h.stopAndRelease.mockClear();
    axes.set([axis(1, 'x')]);
    show('x');
    type('stop-deceleration', '800');
    await act(async () => button('stop').click());
    expect(h.stopAndRelease).toHaveBeenCalledWith('x', { deceleration: 800, jerk: 0 });
    expect(h.command).not.toHaveBeenCalledWith('x', 'stop', expect.anything());
    expect(button('stop').title).toMatch(/standstill; there the UI releases the stop, so the axis is ready again/);
    await act(async () => void window.dispatchEvent(new KeyboardEvent('keydown', { key: 'F6', bubbles: true })));
    expect(h.stopAndRelease).toHaveBeenCalledTimes(2);
  });
});
