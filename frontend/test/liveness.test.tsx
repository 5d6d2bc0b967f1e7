// Liveness of the live values: the socket streams only changes, so silence must be told apart
// from a still machine (the `system` topic speaks every second), and the LIVE panel shows it.
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { render } from 'preact';
import { act } from 'preact/test-utils';
import { mountPoint, unmount } from './dom';

vi.mock('../src/services', async () => {
  const { Store } = await import('../src/store');
  return {
    system: new Store<unknown>(null),
    live: { state: new Store({ kind: 'open', since: 0 }), lastMessageAt: null as number | null },
  };
});

import { live, system } from '../src/services';
import { STALE_AFTER_MS, ageText, latestCycle, liveness } from '../src/live/liveness';
import { LiveIndicator } from '../src/ui/shared/liveness';

describe('liveness', () => {
  it('is live until no message came for longer than STALE_AFTER_MS, offline while closed', () => {
    expect(liveness(false, 1000, 1500)).toEqual({ kind: 'offline' });
    expect(liveness(true, null, 1500)).toEqual({ kind: 'stale', ageMs: null });
    expect(liveness(true, 1000, 1000 + STALE_AFTER_MS)).toEqual({ kind: 'live', ageMs: STALE_AFTER_MS });
    expect(liveness(true, 1000, 1001 + STALE_AFTER_MS)).toEqual({ kind: 'stale', ageMs: STALE_AFTER_MS + 1 });
    // a clock that went back a little is no negative age
    expect(liveness(true, 1000, 900)).toEqual({ kind: 'live', ageMs: 0 });
  });

  it('the latest cycle is the highest of any topic; none known is null', () => {
    expect(latestCycle(120, 5000)).toBe(5000);
    expect(latestCycle(7000, 5000)).toBe(7000);
    expect(latestCycle(undefined, null, -1)).toBeNull();
    expect(latestCycle(0)).toBe(0);
  });

  it('ages in seconds, then minutes', () => {
    expect(ageText(999)).toBe('0 s');
    expect(ageText(4200)).toBe('4 s');
    expect(ageText(180_000)).toBe('3 min');
  });
});

describe('LiveIndicator', () => {
  let root: HTMLElement;
  const l = live as unknown as { state: { set(v: unknown): void }; lastMessageAt: number | null };
  const q = () => root.querySelector('.live-ind') as HTMLElement;
  beforeEach(() => {
    vi.useFakeTimers();
    vi.setSystemTime(100_000);
    root = mountPoint();
  });
  afterEach(() => {
    unmount(root);
    vi.useRealTimers();
  });

  it('shows the system cycle advancing while the axis is still, and turns stale when the socket goes silent', () => {
    l.state.set({ kind: 'open', since: 0 });
    l.lastMessageAt = Date.now();
    act(() => system.set({ cycle: 5000 } as never));
    act(() => render(<LiveIndicator cycle={1200} />, root));
    expect(q().dataset.live).toBe('live');
    expect(q().textContent).toContain('cycle 5000');
    // a second later: the next system update
    act(() => {
      vi.advanceTimersByTime(1000);
      l.lastMessageAt = Date.now();
      system.set({ cycle: 6000 } as never);
    });
    expect(q().textContent).toContain('cycle 6000');
    // then nothing: stale after STALE_AFTER_MS, found by the indicator's own timer
    act(() => {
      vi.advanceTimersByTime(STALE_AFTER_MS + 1000);
    });
    expect(q().dataset.live).toBe('stale');
    expect(q().textContent).toContain('no message for 4 s');
    expect(q().textContent).toContain('cycle 6000');
    // a message again: live
    act(() => {
      l.lastMessageAt = Date.now();
      vi.advanceTimersByTime(1000);
    });
    expect(q().dataset.live).toBe('live');
  });

  it('says "not live" while disconnected or while its subscription is stale', () => {
    l.lastMessageAt = Date.now();
    l.state.set({ kind: 'open', since: 0 });
    act(() => render(<LiveIndicator cycle={10} stale />, root));
    expect(q().dataset.live).toBe('off');
    act(() => l.state.set({ kind: 'closed', attempt: 1, retryAt: 0, reason: 'gone' }));
    act(() => render(<LiveIndicator cycle={10} />, root));
    expect(q().textContent).toBe('not live');
  });
});
