// The control of the machine from this tab: the header's text, when the lease is renewed, and
// the lease's life — taken, renewed every 1.5 s, released; lost when another takes over or the
// server cannot be reached for as long as the lease; not renewed while the page is hidden;
// released with a keepalive request when the page goes away.
import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import {
  ControlLease,
  LEASE_MS,
  POLL_MS,
  RETRY_MS,
  controlKind,
  controlText,
  nextRenewal,
  renewEvery,
  type ControlDeps,
  type ControlState,
} from '../src/auth/control';
import { ApiError } from '../src/api/problem';

const holder = (over: Partial<NonNullable<ControlState['holder']>> = {}) => ({
  client_id: 'ui-aaaaaaaa',
  principal: 'user:anna',
  client_addr: '127.0.0.1:5000',
  since: '2026-11-25T08:00:00.000Z',
  lease_ms: 5000,
  expires_in_ms: 5000,
  ...over,
});
const free: ControlState = { lease_enabled: true, holder: null, yours: false };
const mine: ControlState = { lease_enabled: true, holder: holder(), yours: true };
const theirs = (over = {}): ControlState => ({ lease_enabled: true, holder: holder({ client_id: 'mes-1', principal: 'token:mes', ...over }), yours: false });

describe('the header text', () => {
  it('free, you, or who holds it; nothing without leases', () => {
    expect(controlText(free)).toBe('Control: free');
    expect(controlText(mine)).toBe('Control: you');
    expect(controlText(theirs())).toBe('Control: token:mes');
    // no user (authentication off): the client id, else the address
    expect(controlText(theirs({ principal: null }))).toBe('Control: mes-1');
    expect(controlText(theirs({ principal: null, client_id: null }))).toBe('Control: 127.0.0.1:5000');
    // the same user in another tab
    expect(controlText(theirs({ principal: 'user:anna', client_id: 'ui-bbbbbbbb' }), 'user:anna')).toBe('Control: user:anna (other tab)');
    expect(controlText({ lease_enabled: false, holder: null, yours: false })).toBeNull();
    expect(controlText(null)).toBeNull();
    expect([free, mine, theirs(), null].map(controlKind)).toEqual(['free', 'you', 'other', null]);
  });
});

describe('renewal schedule', () => {
  it('every 1.5 s for the 5 s lease (a third or less of a short one)', () => {
    expect(renewEvery(5000)).toBe(1500);
    expect(renewEvery(1000)).toBe(300);
    expect(nextRenewal(5000, 10_000, 10_000, false)).toBe(1500);
    expect(nextRenewal(5000, 10_000, 10_400, false)).toBe(1100);
    // late (a slow answer): at once
    expect(nextRenewal(5000, 10_000, 12_000, false)).toBe(0);
  });

  it('after a failure soon again, never past the end of the lease; then it is lost', () => {
    expect(nextRenewal(5000, 10_000, 11_500, true)).toBe(RETRY_MS);
    expect(nextRenewal(5000, 10_000, 14_800, true)).toBe(200);
    expect(nextRenewal(5000, 10_000, 15_000, true)).toBeNull();
    expect(nextRenewal(5000, 10_000, 15_001, false)).toBeNull();
  });
});

describe('ControlLease', () => {
  let server: { holder: string | null; takes: { lease_ms: number; take_over?: boolean }[]; gets: number; releases: number; unloads: number; down: boolean };
  let lease: ControlLease;
  const state = (): ControlState => (server.holder ? (server.holder === 'me' ? mine : theirs()) : free);
  const held409 = () => new ApiError(409, { type: 't', title: 'Conflict', status: 409, detail: 'control of the machine is held by token:mes', code: 'control_held' });
  const deps = (): ControlDeps => ({
    get: async () => {
      server.gets++;
      if (server.down) throw new ApiError(0, null, 'server not reachable');
      return state();
    },
    take: async (body) => {
      server.takes.push(body);
      if (server.down) throw new ApiError(0, null, 'server not reachable');
      if (server.holder && server.holder !== 'me' && !body.take_over) throw held409();
      server.holder = 'me';
      return state();
    },
    release: async () => {
      server.releases++;
      server.holder = null;
      return state();
    },
    releaseOnUnload: () => void server.unloads++,
    now: () => Date.now(),
    setTimeout: (f, ms) => setTimeout(f, ms),
    clearTimeout: (t) => clearTimeout(t as ReturnType<typeof setTimeout>),
  });
  const renewals = () => server.takes.length - 1;

  beforeEach(() => {
    vi.useFakeTimers();
    vi.setSystemTime(1_000_000);
    server = { holder: null, takes: [], gets: 0, releases: 0, unloads: 0, down: false };
    lease = new ControlLease(deps());
  });
  afterEach(() => {
    lease.stop();
    vi.useRealTimers();
  });

  it('reads the control now and every POLL_MS', async () => {
    lease.start();
    await vi.advanceTimersByTimeAsync(0);
    expect(lease.view.get().state).toEqual(free);
    expect(server.gets).toBe(1);
    await vi.advanceTimersByTimeAsync(POLL_MS * 3);
    expect(server.gets).toBe(4);
  });

  it('take: held with the 5 s lease, renewed every 1.5 s; release: no more renewals', async () => {
    lease.start();
    await lease.take();
    expect(server.takes[0]).toEqual({ lease_ms: LEASE_MS });
    expect(lease.view.get()).toMatchObject({ holding: true, state: mine });
    await vi.advanceTimersByTimeAsync(1499);
    expect(renewals()).toBe(0);
    await vi.advanceTimersByTimeAsync(1);
    expect(renewals()).toBe(1);
    await vi.advanceTimersByTimeAsync(1500 * 4);
    expect(renewals()).toBe(5);
    expect(server.takes.every((b) => b.lease_ms === LEASE_MS && !b.take_over)).toBe(true);
    await lease.release();
    expect(server.releases).toBe(1);
    expect(lease.view.get()).toMatchObject({ holding: false, state: free });
    await vi.advanceTimersByTimeAsync(10_000);
    expect(renewals()).toBe(5);
  });

  it('taken over by another: the next reading shows it lost, and renewing stops', async () => {
    lease.start();
    await vi.advanceTimersByTimeAsync(1000);
    await lease.take(); // the next renewal is due after the next reading
    server.holder = 'mes';
    await vi.advanceTimersByTimeAsync(POLL_MS - 1000);
    expect(renewals()).toBe(0);
    const v = lease.view.get();
    expect(v.holding).toBe(false);
    expect(v.lost).toBe('Control was taken over by token:mes.');
    expect(controlText(v.state)).toBe('Control: token:mes');
    const n = server.takes.length;
    await vi.advanceTimersByTimeAsync(10_000);
    expect(server.takes.length).toBe(n);
  });

  it('a renewal refused (409 control_held) loses control too, and tells by whom', async () => {
    await lease.take();
    server.holder = 'mes';
    await vi.advanceTimersByTimeAsync(1500);
    expect(renewals()).toBe(1);
    expect(lease.view.get()).toMatchObject({ holding: false, lost: 'Control was taken over by token:mes.', state: theirs() });
    await vi.advanceTimersByTimeAsync(10_000);
    expect(renewals()).toBe(1);
  });

  it('a server that cannot be reached: tried again every 500 ms until the lease has run out', async () => {
    await lease.take();
    server.down = true;
    await vi.advanceTimersByTimeAsync(1500); // first renewal fails
    expect(renewals()).toBe(1);
    expect(lease.view.get().holding).toBe(true);
    await vi.advanceTimersByTimeAsync(RETRY_MS);
    expect(renewals()).toBe(2);
    // back before the lease ends: held on
    server.down = false;
    await vi.advanceTimersByTimeAsync(RETRY_MS);
    expect(renewals()).toBe(3);
    expect(lease.view.get().holding).toBe(true);
    // down for longer than the lease: lost
    server.down = true;
    await vi.advanceTimersByTimeAsync(LEASE_MS + 1);
    expect(lease.view.get().holding).toBe(false);
    expect(lease.view.get().lost).toMatch(/ran out/);
    const n = server.takes.length;
    await vi.advanceTimersByTimeAsync(10_000);
    expect(server.takes.length).toBe(n);
  });

  it('a hidden page renews nothing (the lease runs out); back in time it renews at once', async () => {
    lease.start();
    await lease.take();
    lease.setHidden(true);
    const gets = server.gets;
    await vi.advanceTimersByTimeAsync(3000);
    expect(renewals()).toBe(0);
    expect(server.gets).toBe(gets);
    lease.setHidden(false);
    await vi.advanceTimersByTimeAsync(0);
    expect(renewals()).toBe(1);
    expect(lease.view.get().holding).toBe(true);
  });

  it('back after the lease ran out: lost, not taken again by itself', async () => {
    lease.start();
    await lease.take();
    lease.setHidden(true);
    await vi.advanceTimersByTimeAsync(LEASE_MS + 100);
    server.holder = null; // the server let it run out
    lease.setHidden(false);
    await vi.advanceTimersByTimeAsync(0);
    expect(lease.view.get()).toMatchObject({ holding: false, state: free });
    expect(lease.view.get().lost).toMatch(/background/);
    expect(renewals()).toBe(0);
  });

  it('take over: sent with take_over', async () => {
    server.holder = 'mes';
    await expect(lease.take()).rejects.toMatchObject({ code: 'control_held' });
    expect(lease.view.get().holding).toBe(false);
    await lease.take(true);
    expect(server.takes.at(-1)).toEqual({ lease_ms: LEASE_MS, take_over: true });
    expect(lease.view.get()).toMatchObject({ holding: true, state: mine });
  });

  it('the page going away releases a held control with a keepalive request, once', async () => {
    lease.start();
    lease.unload();
    expect(server.unloads).toBe(0); // nothing held, nothing sent
    lease.start();
    await lease.take();
    lease.unload();
    expect(server.unloads).toBe(1);
    await vi.advanceTimersByTimeAsync(10_000);
    expect(renewals()).toBe(0);
  });

  it('a page that goes while its take is on the way releases too', async () => {
    let answer: (s: ControlState) => void = () => {};
    const d = deps();
    const slow = new ControlLease({ ...d, take: () => new Promise((r) => (answer = r)) });
    const taking = slow.take();
    slow.unload();
    expect(server.unloads).toBe(1);
    answer(mine);
    await taking;
    await vi.advanceTimersByTimeAsync(10_000);
    expect(slow.view.get().holding).toBe(false); // the answer came after the page went
  });

  it('an answer to a reading sent before a take does not undo it', async () => {
    let answer: (s: ControlState) => void = () => {};
    const d = deps();
    const slow = new ControlLease({ ...d, get: () => new Promise((r) => (answer = r)) });
    slow.start(); // reading in flight: it will say free
    await slow.take();
    answer(free);
    await vi.advanceTimersByTimeAsync(0);
    expect(slow.view.get()).toMatchObject({ holding: true, lost: null });
    slow.stop();
  });
});
