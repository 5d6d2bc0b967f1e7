// The cam editor's live analysis: every edit posts the table as edited to
// `POST /cam-analysis` (debounced), only the answer to the latest request counts; a 422 names
// the rows at fault. Also the texts of what the analysis finds (discontinuities, row errors).
import type { CamAnalysisResource, CamDiscontinuity, CamTableBody } from '../api/types';
import { ApiError } from '../api/problem';
import { sig } from '../format';

/** What the latest answered request says about the table as edited. */
export type Analysis<R = CamAnalysisResource> =
  | { kind: 'ok'; seq: number; result: R }
  /** The server's validation refused it (422): messages by field (`points[1].point_type`). */
  | { kind: 'invalid'; seq: number; fields: Record<string, string>; text: string }
  /** No answer (server gone, another refusal). */
  | { kind: 'error'; seq: number; text: string };

export interface LiveAnalysisOptions {
  /** Quiet time after the last edit before it is sent (ms). */
  delay?: number;
  /** Longest an edit waits while edits go on (a drag): sent at least this often (ms). */
  maxWait?: number;
}

/**
 * Debounces edits into requests and drops stale answers: each request has a sequence number,
 * and an answer is passed on only if no later request was sent meanwhile. `pending` is true
 * from an edit until the answer to it (or to a later one) is in. The body and answer are a cam
 * table's by default (the path editor's are a path table's: groups/plan.ts).
 */
export class LiveAnalysis<B = CamTableBody, R = CamAnalysisResource> {
  private seq = 0;
  private body: B | null = null;
  private timer: ReturnType<typeof setTimeout> | null = null;
  private firstWait = 0;
  private waiting = false;
  private inFlight = 0;
  private readonly delay: number;
  private readonly maxWait: number;

  constructor(
    private readonly send: (body: B) => Promise<R>,
    private readonly onAnalysis: (a: Analysis<R>) => void,
    private readonly onPending: (pending: boolean) => void = () => {},
    opts: LiveAnalysisOptions = {},
    private readonly now: () => number = () => Date.now(),
  ) {
    this.delay = opts.delay ?? 250;
    this.maxWait = opts.maxWait ?? 600;
  }

  get pending(): boolean {
    return this.waiting || this.inFlight > 0;
  }

  /** The table changed: analyse it once the edits pause (or maxWait has passed). */
  schedule(body: B): void {
    this.body = body;
    const t = this.now();
    if (!this.waiting) this.firstWait = t;
    this.setWaiting(true);
    if (this.timer !== null) clearTimeout(this.timer);
    const wait = Math.max(0, Math.min(this.delay, this.firstWait + this.maxWait - t));
    this.timer = setTimeout(() => void this.flush(), wait);
  }

  /** Sends the scheduled table now. */
  async flush(): Promise<void> {
    if (this.timer !== null) clearTimeout(this.timer);
    this.timer = null;
    const body = this.body;
    if (!body) return;
    this.body = null;
    const seq = ++this.seq;
    this.inFlight = seq;
    this.setWaiting(false);
    let a: Analysis<R>;
    try {
      a = { kind: 'ok', seq, result: await this.send(body) };
    } catch (e) {
      a =
        e instanceof ApiError && e.status === 422
          ? { kind: 'invalid', seq, fields: e.fields, text: e.message }
          : { kind: 'error', seq, text: e instanceof Error ? e.message : String(e) };
    }
    if (seq !== this.seq || this.disposed) return; // a later request was sent: this answer is stale
    this.inFlight = 0;
    this.onAnalysis(a);
    this.onPending(this.pending);
  }

  private disposed = false;

  /** Drops the scheduled body and any answer still to come (nothing to analyse now). */
  cancel(): void {
    const before = this.pending;
    if (this.timer !== null) clearTimeout(this.timer);
    this.timer = null;
    this.body = null;
    this.seq++;
    this.inFlight = 0;
    this.waiting = false;
    if (this.pending !== before) this.onPending(this.pending);
  }

  dispose(): void {
    this.disposed = true;
    if (this.timer !== null) clearTimeout(this.timer);
    this.timer = null;
  }

  private setWaiting(w: boolean): void {
    const before = this.pending;
    this.waiting = w;
    if (this.pending !== before) this.onPending(this.pending);
  }
}

/** The samples asked for: 721 (every half unit of 360°), more for a long position table. */
export function samplesFor(body: CamTableBody): number {
  return Math.min(20001, Math.max(721, 4 * (body.rows?.length ?? 0) + 1));
}

/** A value of a jump: 4 significant digits, rounding noise (below 1e-9 of the other side) is 0. */
function jumpValue(v: number, other: number): string {
  return Math.abs(v) <= 1e-9 * Math.max(1, Math.abs(other)) ? '0' : sig(v, 4);
}

/** "velocity jumps from 0 to 0.5 at point 2, master 100" (points counted from 1, as the table shows them). */
export function discontinuityText(d: CamDiscontinuity, what: 'point' | 'row' = 'point'): string {
  const where = d.wrap ? `at the periodic wrap after ${what} ${d.index + 1} (master ${sig(d.master)})` : `at ${what} ${d.index + 1}, master ${sig(d.master)}`;
  return `${d.quantity} jumps from ${jumpValue(d.before, d.after)} to ${jumpValue(d.after, d.before)} ${where}`;
}

/** The discontinuities by row (0-based), for the row markers. */
export function warningsByRow(ds: readonly CamDiscontinuity[]): Map<number, CamDiscontinuity[]> {
  const m = new Map<number, CamDiscontinuity[]>();
  for (const d of ds) m.set(d.index, [...(m.get(d.index) ?? []), d]);
  return m;
}

/**
 * The server's field errors split by row: `points[2].point_type` → row 2, "point_type: …";
 * `rows[3][0]` → row 3, "master: …"; anything else (`points`, `rows`, `name`) is the table's.
 */
export function errorsByRow(fields: Record<string, string>): { rows: Map<number, string[]>; table: string[] } {
  const rows = new Map<number, string[]>();
  const table: string[] = [];
  for (const [f, msg] of Object.entries(fields)) {
    const m = /^(?:points|rows)\[(\d+)\](?:\.(\w+)|\[(\d)\])?$/.exec(f);
    if (!m) {
      table.push(`${f}: ${msg}`);
      continue;
    }
    const i = Number(m[1]);
    const field = m[2] ?? (m[3] === '0' ? 'master' : m[3] === '1' ? 'slave' : '');
    rows.set(i, [...(rows.get(i) ?? []), field ? `${field}: ${msg}` : msg]);
  }
  return { rows, table };
}
