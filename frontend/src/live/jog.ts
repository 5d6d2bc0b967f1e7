// Press-and-hold jogging over the websocket. While a button is held the client renews the
// jog's dead-man (keepalive every KEEPALIVE_MS); every way of letting go ends in release().
// Should the browser die instead, the server stops the axis: it releases a socket's jogs
// when the socket closes, and the dead-man (DEADMAN_S) fires when keepalives stop.
import type { JogDirection, JogMode, CommandResource, Problem } from '../api/types';
import { hexId } from '../api/errors';

export const KEEPALIVE_MS = 150;
export const DEADMAN_S = 0.5;

export interface JogTransport {
  call<R = unknown>(method: string, params: Record<string, unknown>): Promise<R>;
}

/** Where the controller reports jogs for the command log. */
export interface JogLog {
  started?(r: CommandResource): void;
  rejected?(axis: string, params: Record<string, unknown>, e: unknown): void;
}

/** An error's text with the PLCopen error number when the server gave one. */
function describe(e: unknown): string {
  const p = (e as { problem?: Problem | null }).problem;
  const msg = e instanceof Error ? e.message : String(e);
  return p?.error_id ? `${msg} (${hexId(p.error_id)})` : msg;
}

export type JogPhase = 'idle' | 'starting' | 'held';

export interface JogSnapshot {
  phase: JogPhase;
  axis: string | null;
  direction: JogDirection | null;
  mode: JogMode | null;
  command: number | null;
  /** Why the last jog ended (release reason or error text). */
  lastEnd: string | null;
  error: string | null;
  /** The axis the last jog was on: `lastEnd` and `error` are that axis's. */
  lastAxis: string | null;
}

interface Hold {
  token: number;
  axis: string;
  direction: JogDirection;
  mode: JogMode;
  command: number | null;
  released: boolean;
  timer: ReturnType<typeof setInterval>;
}

export class JogController {
  private hold: Hold | null = null;
  private token = 0;
  private listeners = new Set<(s: JogSnapshot) => void>();
  private lastEnd: string | null = null;
  private error: string | null = null;
  private lastAxis: string | null = null;

  constructor(
    private readonly t: JogTransport,
    private readonly log: JogLog = {},
  ) {}

  snapshot(): JogSnapshot {
    const h = this.hold;
    return {
      phase: h ? (h.command === null ? 'starting' : 'held') : 'idle',
      axis: h?.axis ?? null,
      direction: h?.direction ?? null,
      mode: h?.mode ?? null,
      command: h?.command ?? null,
      lastEnd: this.lastEnd,
      error: this.error,
      lastAxis: this.lastAxis,
    };
  }

  onChange(l: (s: JogSnapshot) => void): () => void {
    this.listeners.add(l);
    return () => this.listeners.delete(l);
  }

  private changed(): void {
    const s = this.snapshot();
    this.listeners.forEach((l) => l(s));
  }

  /** Button pressed: start a jog (standard_slow / standard_fast / continuous). */
  press(axis: string, direction: JogDirection, mode: JogMode, extra: Record<string, unknown> = {}): void {
    if (this.hold) this.release('another jog button pressed');
    const token = ++this.token;
    const h: Hold = {
      token,
      axis,
      direction,
      mode,
      command: null,
      released: false,
      timer: setInterval(() => this.renew(h), KEEPALIVE_MS),
    };
    this.hold = h;
    this.error = null;
    this.lastEnd = null;
    this.lastAxis = axis;
    this.changed();
    const params = { direction, mode, deadman_timeout: DEADMAN_S, ...extra };
    this.t
      .call<CommandResource>('jog', { axis, ...params })
      .then((r) => {
        this.log.started?.(r);
        if (h.released) {
          // Let go before the server answered: release at once.
          this.t.call('release', { command: r.id }).catch(() => {});
          return;
        }
        if (this.hold !== h) return;
        h.command = r.id;
        if (r.final) this.end(h, `jog ended at once (${r.state})`);
        else this.changed();
      })
      .catch((e: Error) => {
        clearInterval(h.timer);
        this.log.rejected?.(axis, params, e);
        if (this.hold === h) {
          this.hold = null;
          this.error = describe(e);
          this.lastEnd = 'rejected';
          this.changed();
        }
      });
  }

  private renew(h: Hold): void {
    if (this.hold !== h || h.command === null) return;
    this.t.call('keepalive', { command: h.command }).catch((e: Error) => {
      // The command is gone or final (dead-man fired, aborted, axis error): stop renewing.
      if (this.hold === h) this.end(h, `keepalive refused: ${e.message}`);
    });
  }

  /** Button let go (or any other stop path): release the running jog, if any. */
  release(reason: string): void {
    const h = this.hold;
    if (!h) return;
    h.released = true;
    clearInterval(h.timer);
    this.hold = null;
    this.lastEnd = reason;
    if (h.command !== null) this.t.call('release', { command: h.command }).catch(() => {});
    this.changed();
  }

  /** The socket closed: the server releases the socket's jogs itself; stop renewing. */
  connectionLost(): void {
    const h = this.hold;
    if (!h) return;
    h.released = true;
    clearInterval(h.timer);
    this.hold = null;
    this.lastEnd = 'connection lost (the server stops the jog)';
    this.changed();
  }

  /** A command reached a final state (from the `commands` topic). */
  commandFinal(id: number, state: string): void {
    const h = this.hold;
    if (h && h.command === id) this.end(h, `jog ${state}`);
  }

  private end(h: Hold, why: string): void {
    clearInterval(h.timer);
    // Belt and braces: releasing a final command is harmless.
    if (!h.released && h.command !== null) this.t.call('release', { command: h.command }).catch(() => {});
    h.released = true;
    if (this.hold === h) this.hold = null;
    this.lastEnd = why;
    this.changed();
  }

  get held(): boolean {
    return this.hold !== null;
  }
}
