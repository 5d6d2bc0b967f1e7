// The websocket client: JSON-RPC 2.0 over /api/v1/ws with reconnect and backoff,
// subscriptions that are re-sent on every (re)connection, and merged topic values.
import { Store } from '../store';
import type { Problem, SubscriptionEnded } from '../api/types';
import { fieldErrors } from '../api/problem';
import { DeltaMerger, type Update } from './merge';

export type ConnState =
  | { kind: 'connecting'; attempt: number }
  | { kind: 'open'; since: number }
  | { kind: 'closed'; attempt: number; retryAt: number; reason: string };

export class RpcError extends Error {
  readonly code: number;
  readonly problem: Problem | null;
  readonly fields: Record<string, string>;
  constructor(code: number, message: string, problem: Problem | null) {
    super(message);
    this.code = code;
    this.problem = problem;
    this.fields = fieldErrors(problem);
  }
}

/** Delays between reconnection attempts (ms), then the last one repeated; ±20 % jitter. */
export const BACKOFF_MS = [500, 1000, 2000, 4000, 8000];

export function backoffDelay(attempt: number, rnd: () => number = Math.random): number {
  const base = BACKOFF_MS[Math.min(attempt, BACKOFF_MS.length - 1)];
  return Math.round(base * (0.8 + 0.4 * rnd()));
}

interface Pending {
  resolve: (v: unknown) => void;
  reject: (e: Error) => void;
  timer: ReturnType<typeof setTimeout>;
}

export interface Subscription<T extends object> {
  readonly topic: string;
  readonly merger: DeltaMerger<T>;
  rateHz: number;
  onChange: (value: T | null, stale: boolean, cycle: number) => void;
  /** The server ended the subscription (`subscription_ended`); the client has dropped it. */
  onEnded?: (reason: string) => void;
}

type WsLike = Pick<WebSocket, 'send' | 'close' | 'readyState'> & {
  onopen: ((ev: Event) => void) | null;
  onclose: ((ev: CloseEvent) => void) | null;
  onerror: ((ev: Event) => void) | null;
  onmessage: ((ev: MessageEvent) => void) | null;
};

export interface LiveClientOptions {
  url: string;
  createSocket?: (url: string) => WsLike;
  callTimeoutMs?: number;
  random?: () => number;
  /** The wall clock (ms) that stamps each message received; `Date.now` by default. */
  now?: () => number;
}

export class LiveClient {
  readonly state = new Store<ConnState>({ kind: 'connecting', attempt: 0 });
  private ws: WsLike | null = null;
  private nextId = 1;
  private pending = new Map<number, Pending>();
  private subs = new Map<string, Subscription<object>>();
  private notificationHandlers = new Map<string, Set<(params: any) => void>>();
  private openHandlers = new Set<() => void>();
  private closeHandlers = new Set<() => void>();
  private errorHandlers = new Set<(e: RpcError) => void>();
  private retryTimer: ReturnType<typeof setTimeout> | null = null;
  private attempt = 0;
  private stopped = false;
  private lastMessage: number | null = null;
  private readonly createSocket: (url: string) => WsLike;

  constructor(private readonly opts: LiveClientOptions) {
    this.createSocket = opts.createSocket ?? ((u) => new WebSocket(u) as WsLike);
  }

  get connected(): boolean {
    return this.state.get().kind === 'open';
  }

  /**
   * When the last message of any kind (update, batch, answer) arrived, by `now`; null before
   * the first. The server streams only changes, so an open socket can be silent: the age of
   * this shows whether it still speaks (the `system` topic changes every update).
   */
  get lastMessageAt(): number | null {
    return this.lastMessage;
  }

  start(): void {
    this.stopped = false;
    this.connect();
  }

  stop(): void {
    this.stopped = true;
    if (this.retryTimer) clearTimeout(this.retryTimer);
    this.retryTimer = null;
    const ws = this.ws;
    this.ws = null;
    ws?.close();
    this.lost('stopped');
  }

  /** Skip the backoff wait. */
  retryNow(): void {
    if (this.state.get().kind !== 'closed') return;
    if (this.retryTimer) clearTimeout(this.retryTimer);
    this.retryTimer = null;
    this.connect();
  }

  private connect(): void {
    this.state.set({ kind: 'connecting', attempt: this.attempt });
    let ws: WsLike;
    try {
      ws = this.createSocket(this.opts.url);
    } catch (e) {
      this.scheduleRetry(String(e));
      return;
    }
    this.ws = ws;
    ws.onopen = () => {
      if (this.ws !== ws) return;
      this.attempt = 0;
      this.state.set({ kind: 'open', since: Date.now() });
      for (const s of this.subs.values()) this.sendSubscribe(s, true);
      this.openHandlers.forEach((h) => h());
    };
    ws.onmessage = (ev) => {
      if (this.ws !== ws) return;
      this.lastMessage = (this.opts.now ?? Date.now)();
      this.onMessage(String(ev.data));
    };
    ws.onerror = () => {
      /* onclose follows */
    };
    ws.onclose = (ev) => {
      if (this.ws !== ws) return;
      this.ws = null;
      this.lost(ev.reason || `connection closed (${ev.code})`);
      if (!this.stopped) this.scheduleRetry(ev.reason || 'server gone');
    };
  }

  private lost(reason: string): void {
    for (const [id, p] of this.pending) {
      clearTimeout(p.timer);
      p.reject(new RpcError(-32099, `connection lost: ${reason}`, null));
      this.pending.delete(id);
    }
    for (const s of this.subs.values()) {
      s.merger.reset(true);
      s.onChange(s.merger.value, true, s.merger.cycle);
    }
    this.closeHandlers.forEach((h) => h());
  }

  private scheduleRetry(reason: string): void {
    const delay = backoffDelay(this.attempt, this.opts.random);
    this.attempt++;
    this.state.set({ kind: 'closed', attempt: this.attempt, retryAt: Date.now() + delay, reason });
    this.retryTimer = setTimeout(() => {
      this.retryTimer = null;
      if (!this.stopped) this.connect();
    }, delay);
  }

  private onMessage(text: string): void {
    let msg: any;
    try {
      msg = JSON.parse(text);
    } catch {
      return;
    }
    // The server sends the updates due in one tick as a JSON-RPC batch (an array).
    if (Array.isArray(msg)) {
      for (const m of msg) this.onRpc(m);
    } else {
      this.onRpc(msg);
    }
  }

  private onRpc(msg: any): void {
    if (msg && msg.id !== undefined && msg.id !== null && ('result' in msg || 'error' in msg)) {
      const p = this.pending.get(msg.id);
      if (!p) return;
      this.pending.delete(msg.id);
      clearTimeout(p.timer);
      if ('error' in msg) {
        const e = msg.error ?? {};
        const err = new RpcError(e.code ?? -32000, e.message ?? 'error', e.data ?? null);
        this.errorHandlers.forEach((h) => h(err));
        p.reject(err);
      } else {
        p.resolve(msg.result);
      }
      return;
    }
    if (msg && typeof msg.method === 'string') {
      if (msg.method === 'update') {
        const u = msg.params as Update<object> & { topic: string };
        const s = this.subs.get(u.topic);
        if (s && s.merger.apply(u)) s.onChange(s.merger.value, false, s.merger.cycle);
      } else if (msg.method === 'subscription_ended') {
        this.ended(msg.params as SubscriptionEnded);
      }
      this.notificationHandlers.get(msg.method)?.forEach((h) => h(msg.params));
    }
  }

  /**
   * The server ended a subscription (its axis was deleted or replaced): the last value stays,
   * marked stale, and the topic is no longer re-sent on reconnection; `onEnded` decides
   * whether to subscribe again.
   */
  private ended(p: SubscriptionEnded): void {
    const s = p && typeof p.topic === 'string' ? this.subs.get(p.topic) : undefined;
    if (!s) return;
    this.subs.delete(p.topic);
    s.merger.reset();
    s.onChange(s.merger.value, true, s.merger.cycle);
    s.onEnded?.(p.reason);
  }

  /** A JSON-RPC call; rejects with RpcError (the problem+json in `problem`). */
  call<R = unknown>(method: string, params: Record<string, unknown> = {}): Promise<R> {
    const ws = this.ws;
    if (!ws || this.state.get().kind !== 'open') {
      return Promise.reject(new RpcError(-32099, 'not connected to the server', null));
    }
    const id = this.nextId++;
    return new Promise<R>((resolve, reject) => {
      const timer = setTimeout(() => {
        this.pending.delete(id);
        reject(new RpcError(-32098, `no answer to ${method} within ${this.opts.callTimeoutMs ?? 10000} ms`, null));
      }, this.opts.callTimeoutMs ?? 10000);
      this.pending.set(id, { resolve: resolve as (v: unknown) => void, reject, timer });
      try {
        ws.send(JSON.stringify({ jsonrpc: '2.0', id, method, params }));
      } catch (e) {
        clearTimeout(timer);
        this.pending.delete(id);
        reject(new RpcError(-32099, `send failed: ${e}`, null));
      }
    });
  }

  /**
   * Subscribes to a topic (kept across reconnections until unsubscribed or ended by the
   * server, then `onEnded` is called); returns the unsubscribe function.
   */
  subscribe<T extends object>(
    topic: string,
    rateHz: number,
    onChange: (value: T | null, stale: boolean, cycle: number) => void,
    onEnded?: (reason: string) => void,
  ): () => void {
    const existing = this.subs.get(topic);
    const s: Subscription<T> = existing
      ? Object.assign(existing as unknown as Subscription<T>, { rateHz, onChange, onEnded })
      : { topic, rateHz, onChange, onEnded, merger: new DeltaMerger<T>() };
    this.subs.set(topic, s as unknown as Subscription<object>);
    if (this.connected) this.sendSubscribe(s as unknown as Subscription<object>, false);
    return () => {
      if (this.subs.get(topic) !== (s as unknown)) return;
      this.subs.delete(topic);
      if (this.connected) this.call('unsubscribe', { topic }).catch(() => {});
    };
  }

  private sendSubscribe(s: Subscription<object>, newConnection: boolean): void {
    // Everything until the next full object belongs to the old subscription.
    s.merger.reset(newConnection);
    this.call('subscribe', { topic: s.topic, rate_hz: s.rateHz }).catch(() => {});
  }

  on(method: string, handler: (params: any) => void): () => void {
    let set = this.notificationHandlers.get(method);
    if (!set) this.notificationHandlers.set(method, (set = new Set()));
    set.add(handler);
    return () => set!.delete(handler);
  }

  onOpen(h: () => void): () => void {
    this.openHandlers.add(h);
    return () => this.openHandlers.delete(h);
  }

  /** Every error answer to a call (e.g. a 401 problem: the socket's session has ended). */
  onCallError(h: (e: RpcError) => void): () => void {
    this.errorHandlers.add(h);
    return () => this.errorHandlers.delete(h);
  }

  onClose(h: () => void): () => void {
    this.closeHandlers.add(h);
    return () => this.closeHandlers.delete(h);
  }
}
