// The Online tab's Stop (F6) as TwinCAT XAE's: the UI releases its MC_Stop once the axis stands
// (the stop done), so the axis takes the next command; nothing is released before, nor a stop
// that ended otherwise.
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { releaseWhenDone, type StopFollowApi, type StopState } from '../src/axis/stop';

function fakeApi(first: StopState) {
  let server = first;
  let on: ((s: StopState) => void) | null = null;
  const released: number[] = [];
  const api: StopFollowApi = {
    read: vi.fn(async () => server),
    watch: (_id, cb) => {
      on = cb;
      return () => (on = null);
    },
    release: vi.fn(async (id: number) => void released.push(id)),
  };
  return {
    api,
    released,
    /** An event of the command log (and the server's state from now on). */
    event: (s: StopState) => {
      server = s;
      on?.(s);
    },
    watching: () => on !== null,
  };
}

beforeEach(() => vi.useFakeTimers());
afterEach(() => vi.useRealTimers());

describe('releaseWhenDone', () => {
  it('releases the stop once it is done (at standstill), not while it decelerates', async () => {
    const f = fakeApi({ state: 'active', final: false });
    const p = releaseWhenDone(7, f.api, 1000);
    await vi.advanceTimersByTimeAsync(2500);
    expect(f.released).toEqual([]);
    f.event({ state: 'done', final: false });
    await expect(p).resolves.toBe('released');
    expect(f.released).toEqual([7]);
    expect(f.watching()).toBe(false);
    await vi.advanceTimersByTimeAsync(5000);
    expect(f.api.release).toHaveBeenCalledTimes(1);
  });

  it('a missed event: the server is asked again and tells', async () => {
    const f = fakeApi({ state: 'active', final: false });
    const p = releaseWhenDone(3, f.api, 1000);
    await vi.advanceTimersByTimeAsync(10);
    f.api.read = vi.fn(async () => ({ state: 'done', final: false }));
    await vi.advanceTimersByTimeAsync(1000);
    await expect(p).resolves.toBe('released');
    expect(f.released).toEqual([3]);
  });

  it('a stop already done when sent (the axis stood) is released at once', async () => {
    const f = fakeApi({ state: 'done', final: false });
    await expect(releaseWhenDone(4, f.api)).resolves.toBe('released');
    expect(f.released).toEqual([4]);
  });

  it('a stop that ended otherwise (aborted by an error, released elsewhere) is left alone', async () => {
    const f = fakeApi({ state: 'active', final: false });
    const p = releaseWhenDone(5, f.api);
    f.event({ state: 'error', final: true });
    await expect(p).resolves.toBe('ended');
    expect(f.released).toEqual([]);
  });

  it('a refused release is the caller’s to show', async () => {
    const f = fakeApi({ state: 'done', final: false });
    f.api.release = vi.fn(async () => {
      throw new Error('409');
    });
    await expect(releaseWhenDone(6, f.api)).rejects.toThrow('409');
  });
});
