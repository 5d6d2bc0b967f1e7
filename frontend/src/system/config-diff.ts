// The configuration document (`GET/PUT /config`): what importing a file would change against
// the configuration now active, axis by axis (by name) and cam table by cam table (by name),
// field by field, and the server's refusals of an import in words of the file's axes.
import type { components } from '../api/schema';
import type { Problem } from '../api/types';

export type ConfigDocument = components['schemas']['ConfigDocument'];

/** A field's change; `old`/`new` undefined: the field is not there. */
export interface FieldChange {
  path: string;
  old: unknown;
  new: unknown;
  /** For lists: how they differ ("3 of 361 rows differ", "361 → 365 rows"). */
  note?: string;
}

export interface ItemDiff {
  name: string;
  kind: 'added' | 'removed' | 'changed' | 'same';
  changes: FieldChange[];
  /** For an added or removed item: a few words about it (unit and drive; table type and size). */
  summary?: string;
}

export interface ConfigDiff {
  axes: ItemDiff[];
  /** null: the file has no `cam_tables`, the stored ones stay as they are. */
  camTables: ItemDiff[] | null;
  /** Changes of the document itself (its version). */
  document: FieldChange[];
  /** Nothing would change. */
  same: boolean;
}

const isObject = (v: unknown): v is Record<string, unknown> => !!v && typeof v === 'object' && !Array.isArray(v);

function equal(a: unknown, b: unknown): boolean {
  if (a === b) return true;
  if (typeof a === 'number' && typeof b === 'number') return Number.isNaN(a) && Number.isNaN(b);
  if (Array.isArray(a) && Array.isArray(b)) return a.length === b.length && a.every((x, i) => equal(x, b[i]));
  if (isObject(a) && isObject(b)) {
    const ka = Object.keys(a).filter((k) => a[k] !== undefined);
    const kb = Object.keys(b).filter((k) => b[k] !== undefined);
    return ka.length === kb.length && ka.every((k) => equal(a[k], b[k]));
  }
  return false;
}

function listNote(a: unknown[], b: unknown[], what: string): string {
  if (a.length !== b.length) return `${a.length} → ${b.length} ${what}`;
  const n = a.filter((x, i) => !equal(x, b[i])).length;
  return `${n} of ${a.length} ${what} differ`;
}

/**
 * The leaf changes from `a` to `b` (objects are walked; lists and other values compared whole),
 * with paths joined by dots under `prefix`.
 */
export function diffValues(a: unknown, b: unknown, prefix = ''): FieldChange[] {
  if (equal(a, b)) return [];
  if (isObject(a) && isObject(b)) {
    const out: FieldChange[] = [];
    const keys = [...new Set([...Object.keys(a), ...Object.keys(b)])];
    for (const k of keys) out.push(...diffValues(a[k], b[k], prefix ? `${prefix}.${k}` : k));
    return out;
  }
  const c: FieldChange = { path: prefix, old: a, new: b };
  if (Array.isArray(a) && Array.isArray(b)) c.note = listNote(a, b, prefix.endsWith('rows') ? 'rows' : prefix.endsWith('points') ? 'points' : 'items');
  return [c];
}

/** An axis of the document as compared: its configuration (without `config.`) and its persistent values. */
function axisView(a: Record<string, unknown>): Record<string, unknown> {
  const { config, ...rest } = a;
  return { ...(isObject(config) ? config : {}), ...rest };
}

const axisName = (a: unknown): string => (isObject(a) && isObject(a.config) && typeof a.config.name === 'string' ? a.config.name : '');
const tableName = (t: unknown): string => (isObject(t) && typeof t.name === 'string' ? t.name : '');

function axisSummary(a: Record<string, unknown>): string {
  const c = isObject(a.config) ? a.config : {};
  const drive = isObject(c.drive) && typeof c.drive.kind === 'string' ? c.drive.kind : 'simulated';
  const modulo = isObject(c.modulo) ? `, modulo ${c.modulo.period}` : '';
  return `${String(c.unit ?? '?')}${modulo}, ${drive} drive`;
}

function tableSummary(t: Record<string, unknown>): string {
  const rows = Array.isArray(t.rows) ? `${t.rows.length} rows` : Array.isArray(t.points) ? `${t.points.length} points` : 'empty';
  return `${String(t.table_type ?? '?')}, ${rows}`;
}

function diffItems(
  current: unknown[],
  incoming: unknown[],
  nameOf: (x: unknown) => string,
  view: (x: Record<string, unknown>) => Record<string, unknown>,
  summary: (x: Record<string, unknown>) => string,
): ItemDiff[] {
  const cur = new Map<string, Record<string, unknown>>();
  for (const x of current) if (isObject(x)) cur.set(nameOf(x), x);
  const out: ItemDiff[] = [];
  const seen = new Set<string>();
  for (const x of incoming) {
    if (!isObject(x)) continue;
    const name = nameOf(x);
    seen.add(name);
    const old = cur.get(name);
    if (!old) {
      out.push({ name, kind: 'added', changes: [], summary: summary(x) });
      continue;
    }
    const changes = diffValues(view(old), view(x));
    out.push({ name, kind: changes.length ? 'changed' : 'same', changes });
  }
  for (const [name, x] of cur) if (!seen.has(name)) out.push({ name, kind: 'removed', changes: [], summary: summary(x) });
  return out;
}

/** What importing `incoming` would change against `current` (both configuration documents). */
export function diffConfig(current: ConfigDocument, incoming: ConfigDocument): ConfigDiff {
  const axes = diffItems(current.axes ?? [], incoming.axes ?? [], axisName, axisView, axisSummary);
  const camTables =
    incoming.cam_tables === undefined || incoming.cam_tables === null
      ? null
      : diffItems(current.cam_tables ?? [], incoming.cam_tables, tableName, (t) => t, tableSummary);
  const document = diffValues(current.version, incoming.version, 'version');
  const same = document.length === 0 && axes.every((a) => a.kind === 'same') && (camTables ?? []).every((t) => t.kind === 'same');
  return { axes, camTables, document, same };
}

/** Counts for a one-line summary: added, removed, changed items and changed fields. */
export function diffCounts(d: ConfigDiff): { added: number; removed: number; changed: number; fields: number } {
  const items = [...d.axes, ...(d.camTables ?? [])];
  return {
    added: items.filter((i) => i.kind === 'added').length,
    removed: items.filter((i) => i.kind === 'removed').length,
    changed: items.filter((i) => i.kind === 'changed').length,
    fields: items.reduce((n, i) => n + i.changes.length, 0) + d.document.length,
  };
}

/** A value of a change as text: absent, a list's length, or JSON. */
export function valueText(v: unknown): string {
  if (v === undefined) return '(none)';
  if (Array.isArray(v) && (v.length > 4 || v.some((x) => typeof x === 'object' && x !== null))) return `[${v.length} items]`;
  const s = JSON.stringify(v);
  return s.length > 60 ? s.slice(0, 59) + '…' : s;
}

/**
 * Whether a parsed file is a configuration document at all (an object with a version and a list
 * of axes): an error text, or null. Everything else is the server's to check.
 */
export function notADocument(x: unknown): string | null {
  if (!isObject(x)) return 'the file is not a JSON object';
  if (!Array.isArray(x.axes)) return 'the file has no "axes" list: not a motiond configuration document';
  if (x.version === undefined) return 'the file has no "version": not a motiond configuration document';
  if (x.cam_tables !== undefined && x.cam_tables !== null && !Array.isArray(x.cam_tables)) return '"cam_tables" is not a list';
  return null;
}

/**
 * A field path of the server (`axes[1].config.dynamics.max_velocity`, `cam_tables[0].rows`) with
 * the name of the axis or table it is in, from the imported document.
 */
export function fieldLabel(field: string, doc: unknown): string {
  const m = /^(axes|cam_tables)\[(\d+)\](?:\.(.*))?$/.exec(field);
  if (!m || !isObject(doc)) return field;
  const list = doc[m[1]];
  const item = Array.isArray(list) ? list[Number(m[2])] : undefined;
  const name = m[1] === 'axes' ? axisName(item) : tableName(item);
  const what = m[1] === 'axes' ? 'axis' : 'cam table';
  const rest = (m[3] ?? '').replace(/^config\./, '');
  return `${what} ${name ? `'${name}'` : `#${Number(m[2]) + 1}`}${rest ? `: ${rest}` : ''}`;
}

/** The server's field errors of a refused import, labelled by axis or table. */
export function importErrors(p: Problem | null, doc: unknown): { field: string; label: string; message: string }[] {
  return (p?.errors ?? []).map((e) => ({ field: e.field, label: fieldLabel(e.field, doc), message: e.message }));
}

/** The file name of an export: `motiond-config-YYYY-MM-DD.json` (local date). */
export function exportName(d = new Date()): string {
  const p = (n: number) => String(n).padStart(2, '0');
  return `motiond-config-${d.getFullYear()}-${p(d.getMonth() + 1)}-${p(d.getDate())}.json`;
}
