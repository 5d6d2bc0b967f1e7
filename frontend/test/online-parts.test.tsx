// Parts of the Online tab at the DOM level (services mocked): the override slider follows the
// axis, inching waits for the parameters and takes each direction's step.
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { render } from 'preact';
import { act } from 'preact/test-utils';

const h = vi.hoisted(() => ({ command: vi.fn(async () => ({ id: 1 })), loadPowerCommand: vi.fn(async () => {}) }));

vi.mock('../src/services', async () => {
  const { Store } = await import('../src/store');
  return {
    command: h.command,
    loadPowerCommand: h.loadPowerCommand,
    powerOverrides: new Store(new Map()),
    live: { state: new Store({ kind: 'open', since: 0 }) },
  };
});

import { OverrideControl, overrideFactorPercent, HOLD_MS } from '../src/ui/override';
import { Inching } from '../src/ui/inching';
import { powerOverrides } from '../src/services';
import type { ParameterResource } from '../src/api/types';

let root: HTMLElement;
beforeEach(() => {
  h.command.mockClear();
  powerOverrides.set(new Map());
  root = document.createElement('div');
  document.body.appendChild(root);
});
afterEach(() => {
  act(() => render(null, root));
  root.remove();
  vi.useRealTimers();
});

describe('override', () => {
  it('the slider is the MC_SetOverride factor: effective ÷ power override', () => {
    expect(overrideFactorPercent(50, 100)).toBe(50);
    expect(overrideFactorPercent(25, 50)).toBe(50);
    expect(overrideFactorPercent(40, 40)).toBe(100);
    expect(overrideFactorPercent(0, 0)).toBeNull(); // factor unknowable
    expect(overrideFactorPercent(30, null)).toBeNull(); // power override not known yet
    expect(overrideFactorPercent(undefined, 100)).toBeNull();
  });

  const slider = () => root.querySelector('input[name="override"]') as HTMLInputElement;
  const show = (effective: number | undefined) =>
    act(() => render(<OverrideControl axis="x" effective={effective} online={true} onError={() => {}} />, root));

  it('follows the axis when the override is changed elsewhere', () => {
    show(100);
    expect(slider().value).toBe('100');
    show(30);
    expect(slider().value).toBe('30');
    expect(h.command).not.toHaveBeenCalled();
  });

  it('with a power override of 50 % the slider shows the factor, not the effective value', () => {
    act(() => powerOverrides.set(new Map([['x', { id: 3, percent: 50 }]])));
    show(25);
    expect(slider().value).toBe('50');
    expect(root.querySelector('[data-testid="override-power"]')!.textContent).toMatch(/50 % = 25\.0 % effective/);
  });

  it('is not moved under the user’s finger; sends the factor; follows again after letting go', async () => {
    vi.useFakeTimers();
    show(100);
    act(() => {
      slider().dispatchEvent(new PointerEvent('pointerdown', { bubbles: true }));
      slider().value = '40';
      slider().dispatchEvent(new Event('input', { bubbles: true }));
    });
    await act(async () => {
      await vi.advanceTimersByTimeAsync(150);
    });
    expect(h.command).toHaveBeenCalledWith('x', 'set-override', { velocity_factor: 0.4 });
    show(70); // someone else's value arrives while dragging
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
