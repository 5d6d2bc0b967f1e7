// The scope's recordings as the UI follows them, kept outside the page: leaving the Scope page
// (to jog on the Online tab) does not stop following a recording, and (re)opening the page asks
// the server for its recordings and follows the newest armed or running one (also one started
// by another client or before a reload). No UI code, no global state: services.ts holds the
// instance; tests drive it with a fake API.
import { Store } from '../store';
import type { Recording, RecordingRequest } from './data';

export interface ScopeApi {
  list(): Promise<Recording[]>;
  get(id: number): Promise<Recording>;
  create(r: RecordingRequest): Promise<Recording>;
  cancel(id: number): Promise<unknown>;
}

export interface ScopeState {
  /** The armed or running recording being followed (without data). */
  running: Recording | null;
  /** The finished recording on screen (with data). */
  shown: Recording | null;
  /** The recordings the server keeps, newest first (without data). */
  kept: Recording[];
  /** Why the followed recording did not end in `done`, or a failed request. */
  error: string | null;
}

export interface SessionTiming {
  /** Poll interval of the followed recording while the page is open. */
  pollMs: number;
  /** … and while it is not (the result is ready when the page opens again). */
  backgroundPollMs: number;
  /** Re-reading of the server's list while the page is open. */
  listMs: number;
}

const ACTIVE = new Set(['armed', 'recording']);
const message = (e: unknown) => (e instanceof Error ? e.message : String(e));
/** A request that never reached the server (ApiError status 0): the server may come back. */
const unreachable = (e: unknown) => (e as { status?: number }).status === 0;

export class ScopeSession {
  readonly state = new Store<ScopeState>({ running: null, shown: null, kept: [], error: null });
  private following: number | null = null;
  /** Recordings cancelled here: not followed again while the server still lists them active. */
  private cancelled = new Set<number>();
  private pages = 0;
  private listTimer: ReturnType<typeof setInterval> | null = null;

  constructor(
    private readonly api: ScopeApi,
    private readonly timing: SessionTiming = { pollMs: 200, backgroundPollMs: 1000, listMs: 5000 },
  ) {}

  private patch(p: Partial<ScopeState>): void {
    this.state.set({ ...this.state.get(), ...p });
  }

  /** The Scope page opened: read the server's list now and every `listMs`. Returns the detach. */
  attach(): () => void {
    this.pages++;
    void this.sync();
    if (!this.listTimer) this.listTimer = setInterval(() => void this.sync(), this.timing.listMs);
    let attached = true;
    return () => {
      if (!attached) return;
      attached = false;
      this.pages--;
      if (this.pages === 0 && this.listTimer) {
        clearInterval(this.listTimer);
        this.listTimer = null;
      }
    };
  }

  /** Re-reads the server's recordings; follows the newest active one unless one is followed. */
  async sync(): Promise<void> {
    let kept: Recording[];
    try {
      kept = await this.api.list();
    } catch {
      return; // the connection state shows it
    }
    this.patch({ kept });
    if (this.following === null) {
      const active = kept.find((r) => ACTIVE.has(r.state) && !this.cancelled.has(r.id));
      if (active) void this.follow(active);
    }
  }

  /** Starts a recording and follows it; a refused request is thrown (field errors). */
  async record(request: RecordingRequest): Promise<Recording> {
    this.patch({ error: null });
    const created = await this.api.create(request);
    void this.follow(created);
    return created;
  }

  /** Cancels the followed recording. */
  async cancel(): Promise<void> {
    const r = this.state.get().running;
    if (!r) return;
    this.following = null;
    this.cancelled.add(r.id);
    this.patch({ running: null });
    try {
      await this.api.cancel(r.id);
    } catch (e) {
      this.patch({ error: message(e) });
    }
    void this.sync();
  }

  /** Shows a kept recording (fetched with its data). */
  async show(id: number): Promise<void> {
    try {
      const r = await this.api.get(id);
      this.patch({ shown: r, error: null });
    } catch (e) {
      this.patch({ error: message(e) });
    }
  }

  clearError(): void {
    this.patch({ error: null });
  }

  private async follow(r: Recording): Promise<void> {
    if (this.following === r.id) return;
    this.following = r.id;
    this.patch({ running: r });
    const mine = () => this.following === r.id;
    try {
      for (;;) {
        await new Promise((res) => setTimeout(res, this.pages > 0 ? this.timing.pollMs : this.timing.backgroundPollMs));
        if (!mine()) return;
        let cur: Recording;
        try {
          cur = await this.api.get(r.id);
        } catch (e) {
          if (unreachable(e)) continue; // server gone for now: keep asking
          throw e;
        }
        if (!mine()) return;
        if (cur.state === 'done') {
          this.patch({ running: null, shown: cur });
          return;
        }
        if (!ACTIVE.has(cur.state)) {
          this.patch({ running: null, error: `recording ${cur.id} ${cur.state}${cur.reason ? `: ${cur.reason}` : ''}` });
          return;
        }
        this.patch({ running: cur });
      }
    } catch (e) {
      if (mine()) this.patch({ running: null, error: `recording ${r.id}: ${message(e)}` });
    } finally {
      if (mine()) {
        this.following = null;
        void this.sync();
      }
    }
  }
}
