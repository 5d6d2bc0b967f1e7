// ScopeSession: recordings are followed outside the page and found again on the server.
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { ScopeSession, type ScopeApi } from '../src/scope/session';
import type { Recording } from '../src/scope/data';
import { ApiError } from '../src/api/problem';

const rec = (id: number, state: Recording['state'], extra: Partial<Recording> = {}): Recording => ({
  id,
  state,
  cycle_time_s: 0.001,
  samples: 3,
  channels: [{ axis: 'x', signal: 'set_position' }],
  ...extra,
});

/** A server double: recordings by id; `advance(id, state)` changes one. */
function server(initial: Recording[]) {
  const all = new Map(initial.map((r) => [r.id, r]));
  let next = 100;
  const api: ScopeApi & { [k: string]: any } = {
    list: vi.fn(async () => [...all.values()].sort((a, b) => b.id - a.id).map(({ data, t, ...r }) => r as Recording)),
    get: vi.fn(async (id: number) => {
      const r = all.get(id);
      if (!r) throw new ApiError(404, null, 'no such recording');
      return r;
    }),
    create: vi.fn(async () => {
      const r = rec(next++, 'armed');
      all.set(r.id, r);
      return r;
    }),
    cancel: vi.fn(async (id: number) => {
      all.set(id, { ...all.get(id)!, state: 'cancelled' });
    }),
  };
  const advance = (id: number, state: Recording['state'], extra: Partial<Recording> = {}) => all.set(id, { ...all.get(id)!, state, ...extra });
  return { api, advance, all };
}

const TIMING = { pollMs: 200, backgroundPollMs: 1000, listMs: 5000 };

beforeEach(() => vi.useFakeTimers());
afterEach(() => vi.useRealTimers());

describe('ScopeSession', () => {
  it('opening the page lists the server’s recordings and follows an armed one until it is done', async () => {
    const { api, advance } = server([rec(1, 'done'), rec(2, 'armed')]);
    const s = new ScopeSession(api, TIMING);
    const detach = s.attach();
    await vi.advanceTimersByTimeAsync(0);
    expect(s.state.get().kept.map((r) => r.id)).toEqual([2, 1]);
    expect(s.state.get().running?.id).toBe(2);
    advance(2, 'recording', { samples_recorded: 1 });
    await vi.advanceTimersByTimeAsync(200);
    expect(s.state.get().running).toMatchObject({ id: 2, state: 'recording', samples_recorded: 1 });
    advance(2, 'done', { t: [0, 0.001, 0.002], data: [[1, 2, 3]] });
    await vi.advanceTimersByTimeAsync(200);
    expect(s.state.get().running).toBeNull();
    expect(s.state.get().shown).toMatchObject({ id: 2, state: 'done', data: [[1, 2, 3]] });
    await vi.advanceTimersByTimeAsync(0);
    expect(s.state.get().kept.find((r) => r.id === 2)?.state).toBe('done');
    detach();
  });

  it('a recording goes on being followed while the page is away, and is on screen when it comes back', async () => {
    const { api, advance } = server([]);
    const s = new ScopeSession(api, TIMING);
    const detach = s.attach();
    await s.record({ channels: [{ axis: 'x', signal: 'set_position' }], duration_s: 0.003, trigger: null });
    detach(); // to the Online tab, to move the axis
    advance(100, 'done', { t: [0, 1, 2], data: [[0, 1, 2]] });
    await vi.advanceTimersByTimeAsync(1000); // slower polling in the background
    expect(s.state.get().shown?.id).toBe(100);
    expect(s.state.get().running).toBeNull();
    // no list polling while no page is attached
    const lists = vi.mocked(api.list).mock.calls.length;
    await vi.advanceTimersByTimeAsync(20000);
    expect(vi.mocked(api.list).mock.calls.length).toBe(lists);
  });

  it('a fresh session (page reloaded) finds a running recording of the server', async () => {
    const { api } = server([rec(7, 'recording', { samples_recorded: 2 })]);
    const s = new ScopeSession(api, TIMING);
    s.attach();
    await vi.advanceTimersByTimeAsync(0);
    expect(s.state.get().running).toMatchObject({ id: 7, state: 'recording' });
  });

  it('the kept list is re-read while the page is open', async () => {
    const { api, all } = server([rec(1, 'done')]);
    const s = new ScopeSession(api, TIMING);
    const detach = s.attach();
    await vi.advanceTimersByTimeAsync(0);
    all.set(3, rec(3, 'done')); // another client's recording
    await vi.advanceTimersByTimeAsync(5000);
    expect(s.state.get().kept.map((r) => r.id)).toEqual([3, 1]);
    detach();
  });

  it('a failed recording says why; a cancelled one is not followed again', async () => {
    const { api, advance } = server([]);
    const s = new ScopeSession(api, TIMING);
    const detach = s.attach();
    await s.record({ channels: [{ axis: 'x', signal: 'set_position' }], duration_s: 1, trigger: null });
    advance(100, 'failed', { reason: 'samples lost' });
    await vi.advanceTimersByTimeAsync(200);
    expect(s.state.get().error).toBe('recording 100 failed: samples lost');
    expect(s.state.get().running).toBeNull();
    s.clearError();
    await s.record({ channels: [{ axis: 'x', signal: 'set_position' }], duration_s: 1, trigger: null });
    expect(s.state.get().running?.id).toBe(101);
    await s.cancel();
    expect(api.cancel).toHaveBeenCalledWith(101);
    await vi.advanceTimersByTimeAsync(6000);
    expect(s.state.get().running).toBeNull();
    expect(s.state.get().error).toBeNull();
    detach();
  });

  it('keeps asking while the server cannot be reached; a recording the server lost ends with an error', async () => {
    const { api, all } = server([rec(5, 'armed')]);
    const s = new ScopeSession(api, TIMING);
    s.attach();
    await vi.advanceTimersByTimeAsync(0);
    vi.mocked(api.get).mockRejectedValueOnce(new ApiError(0, null, 'server not reachable'));
    await vi.advanceTimersByTimeAsync(200);
    expect(s.state.get().running?.id).toBe(5);
    expect(s.state.get().error).toBeNull();
    all.delete(5); // motiond restarted: recordings are in memory
    await vi.advanceTimersByTimeAsync(200);
    expect(s.state.get().running).toBeNull();
    expect(s.state.get().error).toMatch(/recording 5: no such recording/);
  });

  it('a refused request is thrown for the form', async () => {
    const { api } = server([]);
    vi.mocked(api.create).mockRejectedValueOnce(new ApiError(422, null, 'invalid'));
    const s = new ScopeSession(api, TIMING);
    await expect(s.record({ channels: [], duration_s: 1, trigger: null })).rejects.toThrow('invalid');
    expect(s.state.get().running).toBeNull();
  });

  it('shows a kept recording with its data', async () => {
    const { api } = server([rec(4, 'done', { t: [0], data: [[9]] })]);
    const s = new ScopeSession(api, TIMING);
    await s.show(4);
    expect(s.state.get().shown?.data).toEqual([[9]]);
    await s.show(99);
    expect(s.state.get().error).toBe('no such recording');
  });
});
