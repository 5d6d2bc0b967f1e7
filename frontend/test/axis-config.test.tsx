// The Configuration page's Delete while the axis cannot be swapped: disabled with the reason
// next to it (and a way to switch the axis off), enabled as soon as the live status says the
// axis is disabled; Save is not blocked by the status (the dry run decides: config-save.test.tsx);
// the server stays the judge (its 409 is shown).
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { render } from 'preact';
import { act } from 'preact/test-utils';
import { mountPoint, unmount } from './dom';

const h = vi.hoisted(() => ({ command: vi.fn(async () => ({ id: 1 })) }));

vi.mock('../src/services', async () => {
  const { Store } = await import('../src/store');
  return {
    statuses: new Store(new Map()),
    live: { state: new Store({ kind: 'open', since: 0 }) },
    command: h.command,
    refreshAxes: vi.fn(async () => {}),
  };
});

import { statuses } from '../src/services';
import { AxisConfigPage, DEFAULT_FORM, configOf, reconfigureBlocked } from '../src/ui/config/axis-config';
import type { AxisLiveStatus, AxisResource } from '../src/api/types';

const config = configOf({ ...DEFAULT_FORM, name: 'x' }).config!;
const axis = { id: 1, state: 'disabled', config } as unknown as AxisResource;
const live = (state: AxisLiveStatus['state'], power_status: boolean, stale = false) => {
  act(() => {
    statuses.get().set('x', { status: { state, power_status } as AxisLiveStatus, cycle: 1, stale });
    statuses.emit();
  });
};

let root: HTMLElement;
beforeEach(() => {
  h.command.mockClear();
  // the page reads the axis's parameters (values beside the fields): none here
  vi.stubGlobal('fetch', vi.fn(async () => new Response('[]', { status: 200 })));
  root = mountPoint();
});
afterEach(() => {
  unmount(root);
  vi.unstubAllGlobals();
  statuses.get().clear();
});

const button = (n: string) => root.querySelector(`button[name="${n}"]`) as HTMLButtonElement | null;
const hint = () => root.querySelector('[data-testid="delete-blocked"]');

describe('reconfigureBlocked', () => {
  it('blocks an enabled axis and one not Disabled; an unknown status is the server’s to judge', () => {
    expect(reconfigureBlocked({ state: 'standstill', power_status: true })).toMatch(/enabled: switch it off to re-create or delete it/);
    expect(reconfigureBlocked({ state: 'disabled', power_status: true })).toMatch(/enabled/);
    expect(reconfigureBlocked({ state: 'error_stop', power_status: false })).toMatch(/ErrorStop.*must be Disabled/);
    expect(reconfigureBlocked({ state: 'disabled', power_status: false })).toBeNull();
    expect(reconfigureBlocked(null)).toBeNull();
  });
});

describe('configuration page', () => {
  it('Delete is off with the reason while the axis is enabled, on once it is disabled; Save stays on', async () => {
    live('standstill', true);
    act(() => render(<AxisConfigPage axis={axis} />, root));
    expect(button('save')!.disabled).toBe(false);
    expect(button('delete')!.disabled).toBe(true);
    expect(hint()!.textContent).toMatch(/enabled: switch it off to re-create or delete it/);
    expect(button('delete')!.getAttribute('aria-describedby')).toBe('delete-blocked');
    // the hint offers to switch the axis off
    await act(async () => button('disable-axis')!.click());
    expect(h.command).toHaveBeenCalledWith('x', 'power', expect.objectContaining({ enable: false }));
    live('disabled', false);
    expect(button('save')!.disabled).toBe(false);
    expect(button('delete')!.disabled).toBe(false);
    expect(hint()).toBeNull();
    expect(button('disable-axis')).toBeNull();
  });

  it('a stale status blocks nothing: the server judges, and its refusal is shown', async () => {
    live('standstill', true, true);
    const problem = { type: 'about:blank', title: 'Conflict', status: 409, code: 'axis_not_disabled', detail: "axis 'x' is not disabled" };
    vi.stubGlobal('fetch', vi.fn(async () => new Response(JSON.stringify(problem), { status: 409, headers: { 'content-type': 'application/problem+json' } })));
    act(() => render(<AxisConfigPage axis={axis} />, root));
    expect(button('save')!.disabled).toBe(false);
    expect(hint()).toBeNull();
    await act(async () => {
      button('save')!.click();
      await new Promise((r) => setTimeout(r, 0));
    });
    expect(root.querySelector('[data-testid="not-disabled"]')!.textContent).toMatch(/refused: the axis must be disabled first/);
    expect(button('disable-axis')).not.toBeNull();
  });
});
