// Parts of the Online tab at the DOM level (services mocked): the override slider follows the
// axis's MC_SetOverride factor, inching waits for the parameters and takes each direction's step.
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { render } from 'preact';
import { act } from 'preact/test-utils';
import { mountPoint, unmount } from './dom';

const h = vi.hoisted(() => ({ command: vi.fn(async () => ({ id: 1 })), fetch: vi.fn() }));

vi.mock('../src/services', async () => {
  const { Store } = await import('../src/store');
  return {
    command: h.command,
    live: { state: new Store({ kind: 'open', since: 0 }) },
  };
});

import { OverrideControl, factorPercent, HOLD_MS, type OverrideStatus } from '../src/ui/axis/override';
import { Inching } from '../src/ui/axis/inching';
import type { ParameterResource } from '../src/api/types';

let root: HTMLElement;
beforeEach(() => {
  h.command.mockClear();
  h.fetch.mockClear();
  // Nothing is asked of the server to show the override (no command history search).
  vi.stubGlobal('fetch', h.fetch);
  root = mountPoint();
});
afterEach(() => {
  unmount(root);
  vi.useRealTimers();
  expect(h.fetch).not.toHaveBeenCalled();
  vi.unstubAllGlobals();
});

describe('override', () => {
  it('the slider is the MC_SetOverride factor in percent', () => {
    expect(factorPercent(0.5)).toBe(50);
    expect(factorPercent(0.333)).toBe(33);
    expect(factorPercent(1)).toBe(100);
    expect(factorPercent(0)).toBe(0);
    expect(factorPercent(1.2)).toBe(100);
    expect(factorPercent(undefined)).toBeNull();
    expect(factorPercent(NaN)).toBeNull();
  });

  const slider = () => root.querySelector('input[name="override"]') as HTMLInputElement;
  const powerNote = () => root.querySelector('[data-testid="override-power"]');
  /** The status as the server reports it: effective = power override × factor. */
  const st = (factor: number, power = 100): OverrideStatus => ({ set_override_factor: factor, power_override_percent: power, override_percent: factor * power });
  const show = (status: OverrideStatus | null) => act(() => render(<OverrideControl axis="x" status={status} online={true} onError={() => {}} />, root));

  it('follows the axis when the override is changed elsewhere', () => {
    show(null);
    expect(root.querySelector('[data-testid="override-value"]')!.textContent).toBe('— %');
    show(st(1));
    expect(slider().value).toBe('100');
    show(st(0.3));
    expect(slider().value).toBe('30');
    expect(h.command).not.toHaveBeenCalled();
  });

  it('with a power override of 50 % the slider shows the factor, not the effective value', () => {
    show(st(0.5, 50));
    expect(slider().value).toBe('50');
    expect(powerNote()!.textContent).toBe('× MC_Power override 50 % = 25.0 % effective');
    // another client's power command changes only the power part: the slider stays
    show(st(0.5, 80));
    expect(slider().value).toBe('50');
    expect(powerNote()!.textContent).toMatch(/80 % = 40\.0 % effective/);
    show(st(0.5, 100));
    expect(powerNote()).toBeNull();
  });

  it('is not moved under the user’s finger; sends the factor; follows again after letting go', async () => {
    vi.useFakeTimers();
    show(st(1));
    act(() => {
      slider().dispatchEvent(new PointerEvent('pointerdown', { bubbles: true }));
      slider().value = '40';
      slider().dispatchEvent(new Event('input', { bubbles: true }));
    });
    await act(async () => {
      await vi.advanceTimersByTimeAsync(150);
    });
    expect(h.command).toHaveBeenCalledWith('x', 'set-override', { velocity_factor: 0.4 });
    show(st(0.7)); // someone else's value arrives while dragging
    expect(slider().value).toBe('40');
    act(() => {
      window.dispatchEvent(new PointerEvent('pointerup'));
    });
    await act(async () => {
      await vi.advanceTimersByTimeAsync(HOLD_MS + 50);
    });
    expect(slider().value).toBe('70');
  });
});

describe('inching', () => {
  const param = (number: number, value: number) => ({ number, value }) as ParameterResource;
  const params = new Map([
    [1001, param(1001, 10)],
    [1014, param(1014, 2.5)],
    [1015, param(1015, 0.5)],
  ]);
  const btn = (n: string) => root.querySelector(`button[name="${n}"]`) as HTMLButtonElement;
  const input = (n: string) => root.querySelector(`input[name="${n}"]`) as HTMLInputElement;

  it('is disabled until the parameters are known (no velocity 0 is ever sent)', () => {
    act(() => render(<Inching axis="x" unit="mm" params={null} online={true} onError={() => {}} />, root));
    expect(btn('inch-forward').disabled).toBe(true);
    expect(btn('inch-backward').disabled).toBe(true);
    act(() => render(<Inching axis="x" unit="mm" params={params} online={true} onError={() => {}} />, root));
    expect(btn('inch-forward').disabled).toBe(false);
  });

  it('steps start as #1015 backward and #1014 forward, at #1001', async () => {
    act(() => render(<Inching axis="x" unit="mm" params={params} online={true} onError={() => {}} />, root));
    expect(input('inch-step-backward').value).toBe('0.5');
    expect(input('inch-step-forward').value).toBe('2.5');
    await act(async () => {
      btn('inch-backward').click();
    });
    expect(h.command).toHaveBeenLastCalledWith('x', 'jog', { direction: 'backward', mode: 'inching', position: 0.5, velocity: 10 });
    await act(async () => {
      btn('inch-forward').click();
    });
    expect(h.command).toHaveBeenLastCalledWith('x', 'jog', { direction: 'forward', mode: 'inching', position: 2.5, velocity: 10 });
  });

  it('is disabled while offline', () => {
    act(() => render(<Inching axis="x" unit="mm" params={params} online={false} onError={() => {}} />, root));
    expect(btn('inch-forward').disabled).toBe(true);
  });
});
