// The jog buttons' stop paths, at the DOM level (services mocked).
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { render } from 'preact';
import { act } from 'preact/test-utils';

const h = vi.hoisted(() => ({
  press: vi.fn(),
  release: vi.fn(),
  snap: { phase: 'idle', axis: null, direction: null, mode: null, command: null, lastEnd: null, error: null, lastAxis: null } as Record<string, unknown>,
}));

vi.mock('../src/services', async () => {
  const { Store } = await import('../src/store');
  return {
    jog: {
      press: h.press,
      release: h.release,
      snapshot: () => h.snap,
      onChange: () => () => {},
    },
    live: { state: new Store({ kind: 'open', since: 0 }) },
  };
});

import { JogButtons, type JogButtonDef } from '../src/ui/axis/jog-buttons';

const buttons: JogButtonDef[] = [
  { key: 'fast-backward', label: '−−', direction: 'backward', mode: 'standard_fast', velocity: 100 },
  { key: 'slow-backward', label: '−', direction: 'backward', mode: 'standard_slow', velocity: 10 },
  { key: 'slow-forward', label: '+', direction: 'forward', mode: 'standard_slow', velocity: 10 },
  { key: 'fast-forward', label: '++', direction: 'forward', mode: 'standard_fast', velocity: 100 },
];

let root: HTMLElement;
beforeEach(() => {
  h.press.mockClear();
  h.release.mockClear();
  root = document.createElement('div');
  document.body.appendChild(root);
  act(() => render(<JogButtons axis="x" unit="mm" buttons={buttons} disabled={false} />, root));
});
afterEach(() => {
  act(() => render(null, root));
  root.remove();
});

const btn = (k: string) => root.querySelector(`[data-jog="${k}"]`) as HTMLButtonElement;
const pointer = (el: EventTarget, type: string) => el.dispatchEvent(new PointerEvent(type, { bubbles: true, button: 0 }));

describe('JogButtons', () => {
  it("show how the last jog ended only on that jog's axis", () => {
    h.snap = { ...h.snap, lastEnd: 'button released', lastAxis: 'y' };
    const other = document.createElement('div');
    act(() => render(<JogButtons axis="x" unit="mm" buttons={buttons} disabled={false} />, other));
    expect(other.querySelector('.jog-state')!.textContent).toMatch(/hold a button/);
    const mine = document.createElement('div');
    act(() => render(<JogButtons axis="y" unit="mm" buttons={buttons} disabled={false} />, mine));
    expect(mine.querySelector('.jog-state')!.textContent).toBe('released (button released)');
    act(() => render(null, other));
    act(() => render(null, mine));
    h.snap = { ...h.snap, lastEnd: null, lastAxis: null };
  });

  it('show the velocities from the parameters on the buttons', () => {
    expect(btn('fast-forward').textContent).toContain('100 mm/s');
    expect(btn('slow-backward').textContent).toContain('10 mm/s');
  });

  it('pointerdown starts the jog of that button', () => {
    pointer(btn('fast-backward'), 'pointerdown');
    expect(h.press).toHaveBeenCalledWith('x', 'backward', 'standard_fast');
    pointer(btn('slow-forward'), 'pointerdown');
    expect(h.press).toHaveBeenLastCalledWith('x', 'forward', 'standard_slow');
  });

  it.each(['pointerup', 'pointerleave', 'pointercancel'])('%s on the button releases', (type) => {
    pointer(btn('slow-forward'), 'pointerdown');
    pointer(btn('slow-forward'), type);
    expect(h.release).toHaveBeenCalled();
  });

  it('pointerup anywhere in the window releases', () => {
    pointer(btn('slow-forward'), 'pointerdown');
    pointer(window, 'pointerup');
    expect(h.release).toHaveBeenCalledWith('button released');
  });

  it('the window losing focus releases', () => {
    window.dispatchEvent(new Event('blur'));
    expect(h.release).toHaveBeenCalledWith('window lost focus');
  });

  it('the tab being hidden releases', () => {
    Object.defineProperty(document, 'visibilityState', { value: 'hidden', configurable: true });
    document.dispatchEvent(new Event('visibilitychange'));
    expect(h.release).toHaveBeenCalledWith('page hidden');
    Object.defineProperty(document, 'visibilityState', { value: 'visible', configurable: true });
  });

  it('leaving the page releases', () => {
    window.dispatchEvent(new Event('pagehide'));
    expect(h.release).toHaveBeenCalledWith('page closed');
  });

  it('a right click does not jog', () => {
    btn('slow-forward').dispatchEvent(new PointerEvent('pointerdown', { bubbles: true, button: 2 }));
    expect(h.press).not.toHaveBeenCalled();
  });

  it('keyboard: space held jogs, key up releases', () => {
    btn('slow-forward').dispatchEvent(new KeyboardEvent('keydown', { key: ' ', bubbles: true }));
    expect(h.press).toHaveBeenCalledWith('x', 'forward', 'standard_slow');
    btn('slow-forward').dispatchEvent(new KeyboardEvent('keyup', { key: ' ', bubbles: true }));
    expect(h.release).toHaveBeenCalledWith('key released');
  });
});
