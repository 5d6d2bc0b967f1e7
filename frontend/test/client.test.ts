import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { LiveClient, RpcError, backoffDelay, BACKOFF_MS } from '../src/live/client';

/** A websocket double: records what is sent, lets the test open/close/answer. */
class FakeSocket {
  static all: FakeSocket[] = [];
  sent: any[] = [];
  readyState = 0;
  onopen: ((ev: Event) => void) | null = null;
  onclose: ((ev: CloseEvent) => void) | null = null;
  onerror: ((ev: Event) => void) | null = null;
  onmessage: ((ev: MessageEvent) => void) | null = null;
  constructor(public url: string) {
    FakeSocket.all.push(this);
  }
  send(s: string) {
    this.sent.push(JSON.parse(s));
  }
  close() {
    this.readyState = 3;
  }
  open() {
    this.readyState = 1;
    this.onopen?.(new Event('open'));
  }
  serverClose(code = 1006, reason = '') {
    this.readyState = 3;
    this.onclose?.({ code, reason } as CloseEvent);
  }
  push(msg: unknown) {
    this.onmessage?.({ data: JSON.stringify(msg) } as MessageEvent);
  }
  reply(req: any, result: unknown) {
    this.push({ jsonrpc: '2.0', id: req.id, result });
  }
  methods() {
    return this.sent.map((m) => m.method);
  }
}

function client() {
  return new LiveClient({ url: 'ws://test/api/v1/ws', createSocket: (u) => new FakeSocket(u) as any, random: () => 0.5 });
}

beforeEach(() => {
  FakeSocket.all = [];
  vi.useFakeTimers();
});
afterEach(() => vi.useRealTimers());

describe('LiveClient', () => {
  it('subscribes when the socket opens and merges full then delta updates', () => {
    const c = client();
    const seen: any[] = [];
    c.subscribe<any>('axes/x/status', 25, (v, stale, cycle) => seen.push({ v, stale, cycle }));
    c.start();
    const ws = FakeSocket.all[0];
    expect(c.state.get().kind).toBe('connecting');
    ws.open();
    expect(c.state.get().kind).toBe('open');
    expect(ws.sent[0]).toMatchObject({ jsonrpc: '2.0', method: 'subscribe', params: { topic: 'axes/x/status', rate_hz: 25 } });
    ws.push({ jsonrpc: '2.0', method: 'update', params: { topic: 'axes/x/status', cycle: 7, full: true, data: { state: 'standstill', set_position: 1 } } });
    ws.push({ jsonrpc: '2.0', method: 'update', params: { topic: 'axes/x/status', cycle: 9, full: false, data: { set_position: 2 } } });
    ws.push({ jsonrpc: '2.0', method: 'update', params: { topic: 'axes/y/status', cycle: 9, full: true, data: { set_position: 99 } } });
    expect(seen.at(-1)).toEqual({ v: { state: 'standstill', set_position: 2 }, stale: false, cycle: 9 });
    expect(seen.length).toBe(2);
  });

  it('stamps every message it receives, a batch or an answer alike; none from a replaced socket', () => {
    let now = 1000;
    const c = new LiveClient({ url: 'ws://test/api/v1/ws', createSocket: (u) => new FakeSocket(u) as any, random: () => 0.5, now: () => now });
    c.subscribe<any>('system', 1, () => {});
    c.start();
    const ws = FakeSocket.all[0];
    ws.open();
    expect(c.lastMessageAt).toBeNull();
    now = 2000;
    ws.push([{ jsonrpc: '2.0', method: 'update', params: { topic: 'system', cycle: 5, full: true, data: { cycle: 5 } } }]);
    expect(c.lastMessageAt).toBe(2000);
    now = 3000;
    ws.reply(ws.sent[0], { topic: 'system' });
    expect(c.lastMessageAt).toBe(3000);
    // the socket is lost; a late message of it is not the new socket speaking
    ws.serverClose();
    now = 4000;
    ws.push({ jsonrpc: '2.0', method: 'update', params: { topic: 'system', cycle: 6, full: false, data: { cycle: 6 } } });
    expect(c.lastMessageAt).toBe(3000);
  });

  it('answers calls, and rejects with the problem+json of an error', async () => {
    const c = client();
    c.start();
    const ws = FakeSocket.all[0];
    ws.open();
    const ok = c.call('power', { axis: 'x' });
    ws.reply(ws.sent.at(-1), { id: 5, state: 'active' });
    await expect(ok).resolves.toEqual({ id: 5, state: 'active' });
    const bad = c.call('move-absolute', { axis: 'x', position: 1, velocity: 0 });
    const req = ws.sent.at(-1);
    ws.push({
      jsonrpc: '2.0',
      id: req.id,
      error: {
        code: -32602,
        message: 'velocity: must be > 0',
        data: { type: 'urn:motiond:problem:validation_failed', title: 'Invalid request', status: 422, detail: 'velocity: must be > 0', code: 'validation_failed', errors: [{ field: 'velocity', message: 'must be > 0' }] },
      },
    });
    const e = (await bad.catch((x: unknown) => x)) as RpcError;
    expect(e).toBeInstanceOf(RpcError);
    expect(e.fields).toEqual({ velocity: 'must be > 0' });
  });

  it('rejects calls while not connected', async () => {
    const c = client();
    c.start();
    await expect(c.call('power', {})).rejects.toThrow(/not connected/);
  });

  it('on socket loss: rejects pending calls, marks values stale, reconnects with backoff and resubscribes', async () => {
    const c = client();
    const seen: any[] = [];
    let closes = 0;
    c.onClose(() => closes++);
    c.subscribe<any>('axes/x/status', 25, (v, stale) => seen.push({ v, stale }));
    c.start();
    const ws1 = FakeSocket.all[0];
    ws1.open();
    ws1.push({ jsonrpc: '2.0', method: 'update', params: { topic: 'axes/x/status', cycle: 500, full: true, data: { p: 1 } } });
    const pending = c.call('jog', { axis: 'x' });
    ws1.serverClose();
    await expect(pending).rejects.toThrow(/connection lost/);
    expect(closes).toBe(1);
    expect(seen.at(-1)).toEqual({ v: { p: 1 }, stale: true });
    const st = c.state.get();
    expect(st.kind).toBe('closed');
    // first retry after BACKOFF_MS[0] (jitter 0 with random 0.5)
    vi.advanceTimersByTime(BACKOFF_MS[0] - 1);
    expect(FakeSocket.all.length).toBe(1);
    vi.advanceTimersByTime(1);
    expect(FakeSocket.all.length).toBe(2);
    const ws2 = FakeSocket.all[1];
    // this attempt fails too: the next delay is longer
    ws2.serverClose();
    vi.advanceTimersByTime(BACKOFF_MS[1] - 1);
    expect(FakeSocket.all.length).toBe(2);
    vi.advanceTimersByTime(1);
    const ws3 = FakeSocket.all[2];
    ws3.open();
    expect(ws3.sent.filter((m) => m.method === 'subscribe').map((m) => m.params.topic)).toEqual(['axes/x/status']);
    // deltas before the new full object are not applied; a restarted server counts from 0
    ws3.push({ jsonrpc: '2.0', method: 'update', params: { topic: 'axes/x/status', cycle: 3, full: false, data: { p: 7 } } });
    expect(seen.at(-1)).toEqual({ v: { p: 1 }, stale: true });
    ws3.push({ jsonrpc: '2.0', method: 'update', params: { topic: 'axes/x/status', cycle: 4, full: true, data: { p: 2 } } });
    expect(seen.at(-1)).toEqual({ v: { p: 2 }, stale: false });
  });

  it('resubscribing (a new rate) waits for the new full object', () => {
    const c = client();
    const seen: any[] = [];
    c.subscribe<any>('axes/x/status', 25, (v) => seen.push(v));
    c.start();
    const ws = FakeSocket.all[0];
    ws.open();
    ws.push({ jsonrpc: '2.0', method: 'update', params: { topic: 'axes/x/status', cycle: 10, full: true, data: { p: 1, q: 1 } } });
    c.subscribe<any>('axes/x/status', 50, (v) => seen.push(v));
    expect(ws.sent.at(-1)).toMatchObject({ method: 'subscribe', params: { topic: 'axes/x/status', rate_hz: 50 } });
    ws.push({ jsonrpc: '2.0', method: 'update', params: { topic: 'axes/x/status', cycle: 11, full: false, data: { p: 5 } } });
    expect(seen.at(-1)).toEqual({ p: 1, q: 1 });
    ws.push({ jsonrpc: '2.0', method: 'update', params: { topic: 'axes/x/status', cycle: 12, full: true, data: { p: 6, q: 2 } } });
    expect(seen.at(-1)).toEqual({ p: 6, q: 2 });
  });

  it('unsubscribe sends unsubscribe and forgets the topic', () => {
    const c = client();
    c.start();
    const ws = FakeSocket.all[0];
    ws.open();
    const off = c.subscribe('axes/x/status', 25, () => {});
    off();
    expect(ws.methods()).toEqual(['subscribe', 'unsubscribe']);
    ws.serverClose();
    vi.advanceTimersByTime(10000);
    FakeSocket.all.at(-1)!.open();
    expect(FakeSocket.all.at(-1)!.methods()).toEqual([]);
  });

  it('subscription_ended: the values turn stale, the topic is dropped (not re-sent) and onEnded is told', () => {
    const c = client();
    const seen: any[] = [];
    const ended: string[] = [];
    const others: any[] = [];
    c.on('subscription_ended', (p) => others.push(p));
    const offX = c.subscribe<any>('axes/x/status', 25, (v, stale, cycle) => seen.push({ v, stale, cycle }), (reason) => ended.push(reason));
    c.subscribe<any>('axes/y/status', 25, () => {}, () => ended.push('y'));
    c.start();
    const ws = FakeSocket.all[0];
    ws.open();
    ws.push({ jsonrpc: '2.0', method: 'update', params: { topic: 'axes/x/status', cycle: 7, full: true, data: { p: 1 } } });
    ws.push({ jsonrpc: '2.0', method: 'subscription_ended', params: { topic: 'axes/x/status', reason: 'axis_removed' } });
    expect(seen.at(-1)).toEqual({ v: { p: 1 }, stale: true, cycle: 7 });
    expect(ended).toEqual(['axis_removed']);
    expect(others).toEqual([{ topic: 'axes/x/status', reason: 'axis_removed' }]);
    // nothing of the ended subscription is applied any more, not even a full object
    ws.push({ jsonrpc: '2.0', method: 'update', params: { topic: 'axes/x/status', cycle: 8, full: true, data: { p: 2 } } });
    expect(seen.length).toBe(2);
    // an unknown topic or a repeated notification changes nothing
    ws.push({ jsonrpc: '2.0', method: 'subscription_ended', params: { topic: 'axes/x/status', reason: 'axis_removed' } });
    ws.push({ jsonrpc: '2.0', method: 'subscription_ended', params: { topic: 'axes/z/status', reason: 'axis_removed' } });
    expect(ended).toEqual(['axis_removed']);
    // the old unsubscribe function is now a no-op (the server has forgotten the topic)
    offX();
    expect(ws.methods()).not.toContain('unsubscribe');
    // on reconnection only the topics still subscribed are sent
    ws.serverClose();
    vi.advanceTimersByTime(10000);
    const ws2 = FakeSocket.all.at(-1)!;
    ws2.open();
    expect(ws2.sent.filter((m) => m.method === 'subscribe').map((m) => m.params.topic)).toEqual(['axes/y/status']);
  });

  it('after subscription_ended the same name can be subscribed again; its first full object is taken', () => {
    const c = client();
    const seen: any[] = [];
    const onChange = (v: any, stale: boolean, cycle: number) => seen.push({ v, stale, cycle });
    let off = c.subscribe<any>('axes/x/status', 25, onChange, () => {
      off = c.subscribe<any>('axes/x/status', 25, onChange);
    });
    c.start();
    const ws = FakeSocket.all[0];
    ws.open();
    ws.push({ jsonrpc: '2.0', method: 'update', params: { topic: 'axes/x/status', cycle: 50, full: true, data: { p: 1, q: 1 } } });
    ws.push({ jsonrpc: '2.0', method: 'subscription_ended', params: { topic: 'axes/x/status', reason: 'axis_removed' } });
    expect(ws.sent.filter((m) => m.method === 'subscribe').length).toBe(2);
    // a delta before the new full object has no base
    ws.push({ jsonrpc: '2.0', method: 'update', params: { topic: 'axes/x/status', cycle: 51, full: false, data: { p: 9 } } });
    expect(seen.at(-1)).toEqual({ v: { p: 1, q: 1 }, stale: true, cycle: 50 });
    ws.push({ jsonrpc: '2.0', method: 'update', params: { topic: 'axes/x/status', cycle: 52, full: true, data: { p: 3, q: 4 } } });
    expect(seen.at(-1)).toEqual({ v: { p: 3, q: 4 }, stale: false, cycle: 52 });
    off();
    expect(ws.methods().at(-1)).toBe('unsubscribe');
  });

  it('passes notifications to handlers', () => {
    const c = client();
    const events: any[] = [];
    c.on('command_event', (p) => events.push(p));
    c.start();
    const ws = FakeSocket.all[0];
    ws.open();
    ws.push({ jsonrpc: '2.0', method: 'command_event', params: { command: 3, final: true } });
    expect(events).toEqual([{ command: 3, final: true }]);
  });

  it('retry now skips the wait', () => {
    const c = client();
    c.start();
    FakeSocket.all[0].serverClose();
    expect(FakeSocket.all.length).toBe(1);
    c.retryNow();
    expect(FakeSocket.all.length).toBe(2);
  });

  it('backoff grows to its cap with ±20 % jitter', () => {
    expect(backoffDelay(0, () => 0)).toBe(400);
    expect(backoffDelay(0, () => 1)).toBe(600);
    expect(backoffDelay(2, () => 0.5)).toBe(2000);
    expect(backoffDelay(99, () => 0.5)).toBe(BACKOFF_MS.at(-1));
  });
});
