// TwinCAT's function keys of the Online tab (installFunctionKeys), on a happy-dom window.
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { installFunctionKeys, keyOf, type FunctionKeyHandlers } from '../src/ui/axis/fkeys';

let h: FunctionKeyHandlers & { on: boolean };
let off: () => void;
beforeEach(() => {
  h = { on: true, enabled: () => h.on, jog: vi.fn(), release: vi.fn(), action: vi.fn() };
  off = installFunctionKeys(window, () => h);
});
afterEach(() => off());

function key(type: 'keydown' | 'keyup', k: string, init: KeyboardEventInit = {}, target: EventTarget = window): KeyboardEvent {
  const e = new KeyboardEvent(type, { key: k, bubbles: true, cancelable: true, ...init });
  target.dispatchEvent(e);
  return e;
}

describe('function keys', () => {
  it('F1 … F4 hold the jogs −−, −, +, ++ and key up releases', () => {
    const e = key('keydown', 'F3');
    expect(h.jog).toHaveBeenCalledWith('slow-forward');
    expect(e.defaultPrevented).toBe(true);
    key('keyup', 'F3');
    expect(h.release).toHaveBeenCalledWith('key released');
    key('keydown', 'F1');
    key('keydown', 'F2');
    key('keydown', 'F4');
    expect(vi.mocked(h.jog).mock.calls.map((c) => c[0])).toEqual(['slow-forward', 'fast-backward', 'slow-backward', 'fast-forward']);
  });

  it('auto-repeat does not start the jog again, but is kept from the browser', () => {
    key('keydown', 'F4');
    const r = key('keydown', 'F4', { repeat: true });
    expect(r.defaultPrevented).toBe(true);
    expect(h.jog).toHaveBeenCalledTimes(1);
  });

  it('only the key that started the jog releases it', () => {
    key('keydown', 'F3');
    key('keyup', 'F5');
    expect(h.release).not.toHaveBeenCalled();
    key('keyup', 'F3');
    expect(h.release).toHaveBeenCalledTimes(1);
    key('keyup', 'F3');
    expect(h.release).toHaveBeenCalledTimes(1);
  });

  it('F5 start, F6 stop, F8 reset, F9 home', () => {
    for (const k of ['F5', 'F6', 'F8', 'F9']) expect(key('keydown', k).defaultPrevented).toBe(true);
    expect(vi.mocked(h.action).mock.calls.map((c) => c[0])).toEqual(['start', 'stop', 'reset', 'home']);
    expect(h.jog).not.toHaveBeenCalled();
  });

  it('work with the focus in a text field (they type nothing there)', () => {
    const input = document.createElement('input');
    document.body.appendChild(input);
    input.focus();
    expect(key('keydown', 'F6', {}, input).defaultPrevented).toBe(true);
    expect(h.action).toHaveBeenCalledWith('stop');
    input.remove();
  });

  it('leave other keys and modified F-keys to the browser', () => {
    for (const [k, init] of [['F7', {}], ['F10', {}], ['a', {}], ['Enter', {}], ['F5', { ctrlKey: true }], ['F4', { altKey: true }], ['F3', { shiftKey: true }]] as const) {
      expect(key('keydown', k, init).defaultPrevented).toBe(false);
    }
    expect(h.jog).not.toHaveBeenCalled();
    expect(h.action).not.toHaveBeenCalled();
  });

  it('do nothing while offline (but still keep F5 from reloading the page)', () => {
    h.on = false;
    expect(key('keydown', 'F5').defaultPrevented).toBe(true);
    key('keydown', 'F3');
    expect(h.action).not.toHaveBeenCalled();
    expect(h.jog).not.toHaveBeenCalled();
  });

  it('leaving the tab (uninstall) releases a held jog and stops listening', () => {
    key('keydown', 'F2');
    off();
    expect(h.release).toHaveBeenCalledWith('left the Online tab');
    expect(key('keydown', 'F5').defaultPrevented).toBe(false);
    expect(h.action).not.toHaveBeenCalled();
  });

  it('names the key of each button for its title', () => {
    expect([keyOf('fast-backward'), keyOf('slow-backward'), keyOf('slow-forward'), keyOf('fast-forward')]).toEqual(['F1', 'F2', 'F3', 'F4']);
    expect([keyOf('start'), keyOf('stop'), keyOf('reset'), keyOf('home')]).toEqual(['F5', 'F6', 'F8', 'F9']);
  });
});
