// Rolling (continuous) mode: records short recordings one after another (each followed by the
// ScopeSession like any other) and appends them to a ring of the last N seconds. The server
// records nothing between two recordings: those cycles show as gaps, never as joined lines.
import { Store } from '../store';
import type { Recording, RecordingRequest } from './data';
import { appendRing, emptyRing, recordingStart, type Ring } from './view';

export interface RollingDeps {
  /** Starts a recording (and follows it). */
  record(r: RecordingRequest): Promise<Recording>;
  /** The recording once done (with data); rejects when it failed. */
  done(id: Recording['id'], signal: AbortSignal): Promise<Recording>;
  /** Cancels the followed recording (Stop). */
  cancel(): Promise<void>;
}

export interface RollingState {
  active: boolean;
  ring: Ring | null;
  /** Recordings appended. */
  chunks: number;
  /** The request being repeated (its channels name the ring's rows). */
  request: RecordingRequest | null;
  window_s: number;
  error: string | null;
}

export class Rolling {
  readonly state = new Store<RollingState>({ active: false, ring: null, chunks: 0, request: null, window_s: 10, error: null });
  private abort: AbortController | null = null;

  constructor(private readonly deps: RollingDeps) {}

  private patch(p: Partial<RollingState>): void {
    this.state.set({ ...this.state.get(), ...p });
  }

  /** Repeats `request` (its duration: the chunk) until stop(); a refused first request is thrown. */
  async start(request: RecordingRequest, window_s: number): Promise<void> {
    if (this.abort) return;
    const abort = new AbortController();
    this.abort = abort;
    this.patch({ active: true, ring: emptyRing(request.channels.length), chunks: 0, request, window_s, error: null });
    let first = true;
    try {
      while (!abort.signal.aborted) {
        let created: Recording;
        try {
          created = await this.deps.record(request);
        } catch (e) {
          if (first) throw e;
          this.patch({ error: e instanceof Error ? e.message : String(e) });
          break;
        }
        first = false;
        let rec: Recording;
        try {
          rec = await this.deps.done(created.id, abort.signal);
        } catch (e) {
          if (!abort.signal.aborted) this.patch({ error: e instanceof Error ? e.message : String(e) });
          break;
        }
        if (abort.signal.aborted) break;
        const s = this.state.get();
        const ring = appendRing(s.ring ?? emptyRing(request.channels.length), recordingStart(rec), rec.cycle_time_s, rec.data ?? [], s.window_s);
        this.patch({ ring, chunks: s.chunks + 1 });
      }
    } finally {
      if (this.abort === abort) this.abort = null;
      this.patch({ active: false });
    }
  }

  /** Stops after cancelling the recording under way (what was appended stays on screen). */
  async stop(): Promise<void> {
    const a = this.abort;
    if (!a) return;
    a.abort();
    this.abort = null;
    this.patch({ active: false });
    await this.deps.cancel();
  }

  setWindow(window_s: number): void {
    this.patch({ window_s });
  }
}

/**
 * `done` by asking the server directly: the first question after about the recording's length,
 * then every `ms` (the gap to the next recording is this short, not the session's 200 ms poll).
 */
export function donePolling(
  get: (id: Recording['id']) => Promise<Recording>,
  duration_s: () => number,
  ms = 25,
): (id: Recording['id'], signal: AbortSignal) => Promise<Recording> {
  return async (id, signal) => {
    const wait = (t: number) => new Promise((r) => setTimeout(r, t));
    await wait(Math.max(0, duration_s() * 1000 - 2 * ms));
    for (;;) {
      if (signal.aborted) throw new Error('stopped');
      const r = await get(id);
      if (r.state === 'done') return r;
      if (r.state !== 'armed' && r.state !== 'recording') throw new Error(`recording ${r.id} ${r.state}${r.reason ? `: ${r.reason}` : ''}`);
      await wait(ms);
    }
  };
}

/** `done` for a Store of the ScopeSession's state: resolves when the recording is shown. */
export function doneVia(
  state: Store<{ running: Recording | null; shown: Recording | null; error: string | null }>,
): (id: Recording['id'], signal: AbortSignal) => Promise<Recording> {
  return (id, signal) =>
    new Promise<Recording>((resolve, reject) => {
      let off = () => {};
      const check = () => {
        const s = state.get();
        if (s.shown && s.shown.id === id) {
          off();
          resolve(s.shown);
        } else if (s.running?.id !== id && s.error) {
          off();
          reject(new Error(s.error));
        } else if (signal.aborted) {
          off();
          reject(new Error('stopped'));
        }
      };
      off = state.subscribe(check);
      signal.addEventListener('abort', check);
      check();
    });
}
