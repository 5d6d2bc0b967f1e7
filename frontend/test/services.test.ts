// services.ts against a fetch double: the held MC_Stop is asked of the server at click time;
// the following-error peak hold is the server's (reset by its endpoint); the status stream
// feeds each axis's trend buffer; a subscription the server ends (axis deleted or replaced by
// an import) turns stale and is taken up again by name when an axis still has it.
import { afterEach, describe, expect, it, vi } from 'vitest';
import { axes, findHeldStop, live, refreshAxes, resetFollowingErrorPeak, statuses, trendOf } from '../src/services';
import type { CommandResource } from '../src/api/types';
import { asSent } from './dom';

const cmd = (id: number, command: string, state: CommandResource['state'], final: boolean, parameters: object = {}, axis = 'x') =>
  ({ id, axis, command, state, final, parameters, outputs: { error_id: 0 }, last_cycle: id, submitted_at: '' }) as unknown as CommandResource;

let asked: string[];
function serve(byQuery: (url: string) => unknown) {
  asked = [];
  vi.stubGlobal(
    'fetch',
    vi.fn(async (input: RequestInfo | URL, init?: RequestInit) => {
      const { method, url } = await asSent(input, init);
      asked.push(`${method} ${url}`);
      return new Response(JSON.stringify(byQuery(url)), { status: 200 });
    }),
  );
}
afterEach(() => vi.unstubAllGlobals());

describe('release of a stop', () => {
  it('asks the server for the axis’s stop that still holds the lock (ramping: active)', async () => {
    serve((u) => (u.includes('state=active') ? [cmd(9, 'move-velocity', 'active', false), cmd(8, 'stop', 'active', false)] : []));
    expect(await findHeldStop('x')).toBe(8);
    expect(asked[0]).toBe('GET /api/v1/commands?axis=x&state=active&limit=500');
  });

  it('at standstill the held stop is done but not final; a released (final) one is not taken', async () => {
    serve((u) => (u.includes('state=done') ? [cmd(12, 'stop', 'done', true), cmd(11, 'stop', 'done', false), cmd(10, 'reset', 'done', true)] : []));
    expect(await findHeldStop('x')).toBe(11);
  });

  it('null when the server knows none', async () => {
    serve(() => [cmd(3, 'stop', 'done', true)]);
    expect(await findHeldStop('x')).toBeNull();
  });
});

describe('following-error peak hold', () => {
  it('is reset on the server (no command, no body)', async () => {
    serve(() => ({ axis: 'x', cycle: 1234 }));
    expect(await resetFollowingErrorPeak('x y')).toEqual({ axis: 'x', cycle: 1234 });
    expect(asked).toEqual(['POST /api/v1/axes/x%20y/status/following-error-peak/reset']);
  });
});

describe('status stream', () => {
  const status = (v: number, lag: number) => ({
    set_velocity: v,
    actual_velocity: v - 1,
    following_error: lag,
    following_error_min: -0.5,
    following_error_max: 0.75,
  });
  // What the socket delivers, without a socket: the client's message handler.
  const deliver = (msg: object) => (live as unknown as { onMessage(t: string): void }).onMessage(JSON.stringify({ jsonrpc: '2.0', method: 'update', params: msg }));

  it('feeds the axis’s trend; min/max of the following error are the server’s fields', async () => {
    serve((u) => (u.endsWith('/axes') ? [{ id: 1, state: 'standstill', config: { name: 'tx', unit: 'mm' } }] : []));
    await refreshAxes();
    const topic = 'axes/tx/status';
    deliver({ topic, cycle: 100, full: true, data: status(10, 0.25) });
    deliver({ topic, cycle: 120, full: false, data: { set_velocity: 20, following_error: 0.5 } });
    const t = trendOf('tx');
    expect(t.length).toBe(2);
    expect(t.at(1)).toMatchObject({ cycle: 120, setVelocity: 20, actualVelocity: 9, followingError: 0.5 });
    const s = statuses.get().get('tx')!.status!;
    // not a peak hold of the streamed values (0.25, 0.5): what the server kept
    expect([s.following_error_min, s.following_error_max]).toEqual([-0.5, 0.75]);
    // the socket lost: a gap, not a hold
    (live as unknown as { lost(r: string): void }).lost('test');
    expect(t.broken).toBe(true);
    expect(statuses.get().get('tx')!.stale).toBe(true);
  });

  it('takes a batch (the updates of one tick as a JSON-RPC array) update by update', async () => {
    serve((u) =>
      u.endsWith('/axes')
        ? [
            { id: 1, state: 'standstill', config: { name: 'bx', unit: 'mm' } },
            { id: 2, state: 'standstill', config: { name: 'by', unit: 'mm' } },
          ]
        : [],
    );
    await refreshAxes();
    const update = (topic: string, cycle: number, full: boolean, data: object) => ({ jsonrpc: '2.0', method: 'update', params: { topic, cycle, full, data } });
    const batch = (...m: object[]) => (live as unknown as { onMessage(t: string): void }).onMessage(JSON.stringify(m));
    batch(update('axes/bx/status', 200, true, status(1, 0)), update('axes/by/status', 200, true, status(2, 0)));
    batch(update('axes/bx/status', 210, false, { set_velocity: 3 }), update('axes/by/status', 210, false, { set_velocity: 4 }));
    expect(statuses.get().get('bx')).toMatchObject({ cycle: 210, status: { set_velocity: 3, actual_velocity: 0 } });
    expect(statuses.get().get('by')).toMatchObject({ cycle: 210, status: { set_velocity: 4, actual_velocity: 1 } });
  });
});

describe('a subscription the server ends', () => {
  const topic = 'axes/rx/status';
  const notify = (method: string, params: object) => (live as unknown as { onMessage(t: string): void }).onMessage(JSON.stringify({ jsonrpc: '2.0', method, params }));
  const subscribedTopics = () => [...(live as unknown as { subs: Map<string, unknown> }).subs.keys()].filter((t) => t.startsWith('axes/'));
  const axis = (id: number, name = 'rx') => ({ id, state: 'standstill', config: { name, unit: 'mm' } });
  const status = (v: number) => ({ set_velocity: v, actual_velocity: v, following_error: 0, set_position: v });

  it('replaced by an import: stale at once, the axes read again, subscribed anew by name, live on the new full object', async () => {
    serve((u) => (u.endsWith('/axes') ? [axis(1)] : []));
    await refreshAxes();
    expect(subscribedTopics()).toEqual([topic]);
    notify('update', { topic, cycle: 100, full: true, data: status(5) });
    expect(statuses.get().get('rx')).toMatchObject({ stale: false, status: { set_velocity: 5 } });

    // PUT /config: the same name, a new id
    serve((u) => (u.endsWith('/axes') ? [axis(9)] : []));
    notify('subscription_ended', { topic, reason: 'axis_removed' });
    // the frozen values are not shown as live
    expect(statuses.get().get('rx')).toMatchObject({ stale: true, status: { set_velocity: 5 } });
    await vi.waitFor(() => expect(asked).toEqual(['GET /api/v1/axes']));
    await vi.waitFor(() => expect(axes.get().map((a) => a.id)).toEqual([9]));
    expect(subscribedTopics()).toEqual([topic]);
    // the new subscription's changes need its full object first
    notify('update', { topic, cycle: 130, full: false, data: { set_velocity: 7 } });
    expect(statuses.get().get('rx')).toMatchObject({ stale: true, status: { set_velocity: 5 } });
    notify('update', { topic, cycle: 131, full: true, data: status(0) });
    expect(statuses.get().get('rx')).toMatchObject({ stale: false, cycle: 131, status: { set_velocity: 0 } });
  });

  it('deleted: its values and subscription go once the axes say so', async () => {
    serve((u) => (u.endsWith('/axes') ? [axis(9)] : []));
    await refreshAxes();
    notify('update', { topic, cycle: 200, full: true, data: status(1) });
    serve((u) => (u.endsWith('/axes') ? [] : []));
    notify('subscription_ended', { topic, reason: 'axis_removed' });
    expect(statuses.get().get('rx')?.stale).toBe(true);
    await vi.waitFor(() => expect(statuses.get().has('rx')).toBe(false));
    expect(asked).toEqual(['GET /api/v1/axes']);
    expect(subscribedTopics()).toEqual([]);
  });
});
