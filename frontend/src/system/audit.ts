// The audit log as the System page keeps it: pages of `GET /audit` (newest first) merged by id,
// filters over what is loaded, and the texts of a row.
import type { components } from '../api/schema';

export type AuditRecord = components['schemas']['AuditRecord'];

export const PAGE = 100;
export const REFRESH_MS = 5000;

/** Entries of both lists, each id once (the newer copy wins), newest first. */
export function mergeEntries(have: AuditRecord[], got: AuditRecord[]): AuditRecord[] {
  const byId = new Map<number, AuditRecord>();
  for (const e of have) byId.set(e.id, e);
  for (const e of got) byId.set(e.id, e);
  return [...byId.values()].sort((a, b) => b.id - a.id);
}

export const newestId = (l: AuditRecord[]): number | null => (l.length ? Math.max(...l.map((e) => e.id)) : null);
export const oldestId = (l: AuditRecord[]): number | null => (l.length ? Math.min(...l.map((e) => e.id)) : null);

type PageAsked = { limit?: number; since?: number | null; before?: number | null };

/** The query parameters of a page: the newest, those after `since`, or those before `before`. */
export function auditParams(q: PageAsked): { limit: number; since_id?: number; before_id?: number } {
  const p: { limit: number; since_id?: number; before_id?: number } = { limit: q.limit ?? PAGE };
  if (q.since !== undefined && q.since !== null) p.since_id = q.since;
  if (q.before !== undefined && q.before !== null) p.before_id = q.before;
  return p;
}

/** The page's query as the path it reads: `/audit?limit=100&since_id=9`. */
export function auditQuery(q: PageAsked): string {
  return `/audit?${new URLSearchParams(Object.entries(auditParams(q)).map(([k, v]) => [k, String(v)]))}`;
}

/** Outcome filter values besides a literal outcome. */
export const ANY = '';
export const FAILURES = '!failures';

export interface AuditFilter {
  /** Actions starting with this (`command.`, `config.import`, `parameter.`); '' for all. */
  action: string;
  /** Exactly this target (an axis name, a command id, `config`); '' for all. */
  target: string;
  /** '' (any), FAILURES (rejected, error, aborted) or one outcome exactly. */
  outcome: string;
}

export const NO_FILTER: AuditFilter = { action: '', target: '', outcome: ANY };

export type OutcomeKind = 'ok' | 'fail' | 'aborted' | 'none';

/** What an outcome says: `rejected:<code>` and `error:<code>` failed, `aborted` did not finish. */
export function outcomeKind(o: string | null | undefined): OutcomeKind {
  if (!o) return 'none';
  if (o.startsWith('rejected') || o.startsWith('error')) return 'fail';
  if (o === 'aborted') return 'aborted';
  return 'ok';
}

export function matches(e: AuditRecord, f: AuditFilter): boolean {
  const action = f.action.trim().toLowerCase();
  if (action && !e.action.toLowerCase().startsWith(action)) return false;
  const target = f.target.trim();
  if (target && (e.target ?? '') !== target && String(e.command_id ?? '') !== target) return false;
  if (f.outcome === FAILURES) {
    const k = outcomeKind(e.outcome);
    if (k !== 'fail' && k !== 'aborted') return false;
  } else if (f.outcome && (e.outcome ?? '') !== f.outcome) return false;
  return true;
}

export const filterEntries = (l: AuditRecord[], f: AuditFilter) => l.filter((e) => matches(e, f));

export const isFiltered = (f: AuditFilter) => !!(f.action.trim() || f.target.trim() || f.outcome);

/** The distinct values seen (for the filters' suggestions), sorted. */
export function distinct(l: AuditRecord[], key: 'action' | 'target' | 'outcome'): string[] {
  const s = new Set<string>();
  for (const e of l) {
    const v = e[key];
    if (v) s.add(v);
  }
  return [...s].sort();
}

/** Action prefixes to offer: each action's family (`command.`) and the actions themselves. */
export function actionSuggestions(l: AuditRecord[]): string[] {
  const s = new Set<string>();
  for (const a of distinct(l, 'action')) {
    const dot = a.indexOf('.');
    if (dot > 0) s.add(a.slice(0, dot + 1));
    s.add(a);
  }
  return [...s].sort();
}

/** Who: the principal (`user:anna`, `token:mes`) if any, the client id and the address. */
export function who(e: AuditRecord): { principal: string | null; client: string | null; addr: string | null } {
  return { principal: e.principal ?? null, client: e.client_id ?? null, addr: e.client_addr ?? null };
}

/** The detail on one line, cut to `max` characters ('' for none). */
export function detailLine(d: unknown, max = 80): string {
  if (d === null || d === undefined) return '';
  const s = JSON.stringify(d);
  if (s === '{}') return '';
  return s.length > max ? s.slice(0, max - 1) + '…' : s;
}

/** A moment as `YYYY-MM-DD HH:MM:SS.mmm` in local time. */
export function stamp(iso: string): string {
  const d = new Date(iso);
  if (Number.isNaN(d.getTime())) return iso;
  const p = (n: number, w = 2) => String(n).padStart(w, '0');
  return `${d.getFullYear()}-${p(d.getMonth() + 1)}-${p(d.getDate())} ${p(d.getHours())}:${p(d.getMinutes())}:${p(d.getSeconds())}.${p(d.getMilliseconds(), 3)}`;
}
