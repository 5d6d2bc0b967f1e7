// Control of the machine (GET/POST/DELETE /api/v1/control): one client commands motion at a
// time. This tab takes control with a short lease and renews it while it wants it and is on
// screen; a tab that is hidden stops renewing, so its lease simply runs out, and a tab that
// closes gives control back at once (fetch keepalive). Other clients' motion commands are
// refused with 409 `control_held` while this tab holds it; stop, halt and power off never are.
import { Store } from '../store';
import { ApiError } from '../api/problem';
import { api } from '../api/client';
import type { components } from '../api/schema';

export type ControlState = components['schemas']['ControlState'];
export type ControlHolder = components['schemas']['ControlHolder'];

/** The lease asked for (ms): a tab that stops renewing loses control this long after. */
export const LEASE_MS = 5000;
/** How often the control is read while nothing else changes it (ms). */
export const POLL_MS = 2000;
/** The pause before renewing again after a renewal failed (ms), while the lease lasts. */
export const RETRY_MS = 500;

/** How often a lease is renewed: well before it ends, every 1.5 s for the 5 s lease. */
export function renewEvery(leaseMs: number): number {
  return Math.min(1500, Math.floor(leaseMs * 0.3));
}

/**
 * When to renew next, in ms from `now`; null when the lease has run out (control is lost).
 * `renewedAt` is when the last renewal that succeeded was sent (the server's lease started no
 * earlier); after a failure it is tried again soon, but never past the lease's end.
 */
export function nextRenewal(leaseMs: number, renewedAt: number, now: number, failed: boolean): number | null {
  const left = renewedAt + leaseMs - now;
  if (left <= 0) return null;
  if (failed) return Math.min(RETRY_MS, left);
  return Math.max(0, renewedAt + renewEvery(leaseMs) - now);
}

/** Who holds control, for the header: the principal (`user:bob`), else its client id or address. */
export function holderName(h: ControlHolder): string {
  return h.principal ?? h.client_id ?? h.client_addr;
}

/**
 * The header's text: "Control: free" / "Control: you" / "Control: user:bob"; null when the
 * server runs without control leases (nothing to show). `me` is this page's principal: the
 * same user in another tab (or program) is said so; its client id is in the tooltip.
 */
export function controlText(s: ControlState | null, me: string | null = null): string | null {
  if (!s || !s.lease_enabled) return null;
  if (!s.holder) return 'Control: free';
  if (s.yours) return 'Control: you';
  const h = s.holder;
  if (me && h.principal === me) return `Control: ${h.principal} (other tab)`;
  return `Control: ${holderName(h)}`;
}

/** Whose the control is, for styling and tests: `free`, `you` or `other`; null: no leases. */
export function controlKind(s: ControlState | null): 'free' | 'you' | 'other' | null {
  if (!s || !s.lease_enabled) return null;
  return !s.holder ? 'free' : s.yours ? 'you' : 'other';
}

export interface ControlView {
  /** The control as last read (null before the first answer). */
  state: ControlState | null;
  /** This tab holds control and renews it. */
  holding: boolean;
  /** Why control was lost without a release (taken over, ran out): shown until dismissed. */
  lost: string | null;
}

export interface ControlDeps {
  get(): Promise<ControlState>;
  take(body: { lease_ms: number; take_over?: boolean }): Promise<ControlState>;
  release(): Promise<ControlState>;
  /** Releases while the page goes away (fetch keepalive: it outlives the page). */
  releaseOnUnload(): void;
  now(): number;
  setTimeout(f: () => void, ms: number): unknown;
  clearTimeout(t: unknown): void;
}

export class ControlLease {
  readonly view = new Store<ControlView>({ state: null, holding: false, lost: null });
  private pollTimer: unknown = null;
  private renewTimer: unknown = null;
  private running = false;
  private hidden = false;
  private renewedAt = 0;
  /** A take is on its way (the page may go before its answer). */
  private taking = false;
  /** Changes with every take and release: an answer to an older request is stale. */
  private epoch = 0;

  constructor(private readonly deps: ControlDeps, readonly leaseMs = LEASE_MS) {}

  private patch(p: Partial<ControlView>): void {
    this.view.set({ ...this.view.get(), ...p });
  }

  /** Starts reading the control (now, then every POLL_MS). */
  start(): void {
    if (this.running) return;
    this.running = true;
    void this.poll();
  }

  /** Stops everything without a release (the session ended; the lease runs out by itself). */
  stop(): void {
    this.running = false;
    this.epoch++;
    this.clearPoll();
    this.clearRenew();
    this.view.set({ state: null, holding: false, lost: null });
  }

  private clearPoll(): void {
    if (this.pollTimer !== null) this.deps.clearTimeout(this.pollTimer);
    this.pollTimer = null;
  }

  private clearRenew(): void {
    if (this.renewTimer !== null) this.deps.clearTimeout(this.renewTimer);
    this.renewTimer = null;
  }

  private schedulePoll(): void {
    this.clearPoll();
    if (!this.running || this.hidden) return;
    this.pollTimer = this.deps.setTimeout(() => {
      this.pollTimer = null;
      void this.poll();
    }, POLL_MS);
  }

  /** Reads the control now. */
  async poll(): Promise<void> {
    const epoch = this.epoch;
    try {
      const s = await this.deps.get();
      if (epoch === this.epoch && this.running) this.seen(s);
    } catch {
      /* the connection state shows an unreachable server; a 401 ends the session */
    } finally {
      this.schedulePoll();
    }
  }

  /** A control state from the server: if this tab held control and no longer does, it was lost. */
  private seen(s: ControlState): void {
    const v = this.view.get();
    if (v.holding && !s.yours) {
      this.lose(s.holder ? `Control was taken over by ${holderName(s.holder)}.` : 'Control ran out.', s);
      return;
    }
    this.patch({ state: s });
  }

  private lose(why: string, s: ControlState | null = this.view.get().state): void {
    this.epoch++;
    this.clearRenew();
    this.view.set({ state: s, holding: false, lost: why });
  }

  /** Takes control (from another holder with `takeOver`); the server's refusal is thrown. */
  async take(takeOver = false): Promise<void> {
    const epoch = ++this.epoch;
    const sent = this.deps.now();
    let s: ControlState;
    this.taking = true;
    try {
      s = await this.deps.take(takeOver ? { lease_ms: this.leaseMs, take_over: true } : { lease_ms: this.leaseMs });
    } finally {
      this.taking = false;
    }
    if (epoch !== this.epoch) return;
    this.renewedAt = sent;
    this.view.set({ state: s, holding: true, lost: null });
    this.scheduleRenew(false);
  }

  /** Gives control back (stops renewing first). */
  async release(): Promise<void> {
    const was = this.view.get().holding;
    this.epoch++;
    this.clearRenew();
    this.patch({ holding: false, lost: null });
    if (!was && !this.view.get().state?.yours) return;
    const s = await this.deps.release();
    this.patch({ state: s });
  }

  dismissLost(): void {
    this.patch({ lost: null });
  }

  private scheduleRenew(failed: boolean): void {
    this.clearRenew();
    if (!this.view.get().holding || this.hidden) return;
    const delay = nextRenewal(this.leaseMs, this.renewedAt, this.deps.now(), failed);
    if (delay === null) {
      this.lose('Control ran out: the server could not be reached to renew it.');
      return;
    }
    this.renewTimer = this.deps.setTimeout(() => {
      this.renewTimer = null;
      void this.renew();
    }, delay);
  }

  private async renew(): Promise<void> {
    const epoch = this.epoch;
    const sent = this.deps.now();
    try {
      const s = await this.deps.take({ lease_ms: this.leaseMs });
      if (epoch !== this.epoch) return;
      this.renewedAt = sent;
      this.patch({ state: s });
      this.scheduleRenew(false);
    } catch (e) {
      if (epoch !== this.epoch) return;
      if (e instanceof ApiError && e.status !== 0 && e.status < 500) {
        // Refused: taken over by another (409), no longer allowed (401/403).
        this.lose(`Control was lost: ${e.problem?.detail ?? e.message}`);
        if (e.code === 'control_held') await this.tellTakenOver();
      } else {
        this.scheduleRenew(true);
      }
    }
  }

  /** After a renewal refused with `control_held`: says by whom. */
  private async tellTakenOver(): Promise<void> {
    const epoch = this.epoch;
    try {
      const s = await this.deps.get();
      if (epoch !== this.epoch) return;
      this.patch(s.holder && !s.yours ? { state: s, lost: `Control was taken over by ${holderName(s.holder)}.` } : { state: s });
    } catch {
      /* the message of the refusal stays */
    }
  }

  /**
   * The page went to the background (or came back). Hidden: no renewal and no reading, the lease
   * runs out. Visible again: reading resumes; control still held (back within the lease) is
   * renewed at once, otherwise it is lost and must be taken again.
   */
  setHidden(hidden: boolean): void {
    if (this.hidden === hidden) return;
    this.hidden = hidden;
    if (hidden) {
      this.clearPoll();
      this.clearRenew();
      return;
    }
    if (!this.running) return;
    const v = this.view.get();
    if (v.holding) {
      const left = this.renewedAt + this.leaseMs - this.deps.now();
      if (left <= 0) {
        this.lose('Control ran out while this page was in the background.');
      } else {
        this.clearRenew();
        this.renewTimer = this.deps.setTimeout(() => {
          this.renewTimer = null;
          void this.renew();
        }, 0);
      }
    }
    void this.poll();
  }

  /** The page goes away: a held control is released at once rather than left to run out. */
  unload(): void {
    const held = this.view.get().holding || this.taking;
    this.epoch++;
    this.clearRenew();
    this.clearPoll();
    this.running = false;
    if (held) this.deps.releaseOnUnload();
  }
}

export const control = new ControlLease({
  get: () => api.GET('/api/v1/control'),
  take: (body) => api.POST('/api/v1/control', { body }),
  release: () => api.DELETE('/api/v1/control'),
  releaseOnUnload: () => {
    try {
      void api.DELETE('/api/v1/control', { keepalive: true }).catch(() => {});
    } catch {
      /* the lease runs out instead */
    }
  },
  now: () => Date.now(),
  setTimeout: (f, ms) => setTimeout(f, ms),
  clearTimeout: (t) => clearTimeout(t as ReturnType<typeof setTimeout>),
});
