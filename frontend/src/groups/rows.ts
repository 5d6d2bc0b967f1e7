// The path editor's rows and what MC_MovePath is sent (`POST /groups/{group}/move-path`): a row
// holds its fields as typed (text), one row is one entry of `entries[]`, and every input of a
// row is named by the JSON path of its field (`entries[2].velocity`, `entries[0].position[1]`),
// so a 422 of the server lands at the row and field it names. The UI sends what was typed: a
// number field whose text is no number is never sent (the REST client's NotSentError at that
// field), everything else is the server's to judge.
//
// Defaults: the manual's, except that a row added after the first one defaults to `buffered` /
// `none` (an exact stop; TwinCAT's `aborting` is legal on the first entry only), and "blend
// corners" sets `blending_previous` + `corner_distance` with one radius on every row after the
// first (TF5420 §7.3). No UI code, no global state.
import type { AxesConvention, BufferMode, CircMode, CircPathChoice, GroupRole, MovePathBody, PathEntry, PathValue, TransitionMode } from '../api/types';
import type { PathChoiceName, PreviewEntry, Vec3 } from './geometry';

/** The entry types the editor has rows for (a frame switch, `coordinate_transform`, is not
 * edited here yet: MC_SetCoordinateTransform is the group's own block). */
export type EntryType = Exclude<PathEntry['type'], 'coordinate_transform'>;
export const ENTRY_TYPES: EntryType[] = ['linear', 'circular', 'blocker', 'dwell'];
export const CIRC_MODES: CircMode[] = ['border', 'center', 'radius'];
export const PATH_CHOICES: CircPathChoice[] = ['counter_clockwise', 'clockwise', 'short_segment', 'long_segment'];
/** The buffer modes a path entry may have (§7.3: the others are refused). */
export const BUFFER_MODES: BufferMode[] = ['aborting', 'buffered', 'blending_previous'];
/** The transition modes the CM group supports (the others are refused with transition_mode_invalid). */
export const TRANSITION_MODES: TransitionMode[] = ['none', 'corner_distance', 'corner_distance_advanced'];

/** One row of the editor: its fields as typed. */
export interface PathRow {
  /** Stable key of the row (for the list), not sent. */
  key: number;
  type: EntryType;
  /** Linear `position` / circular `end_point`, in the group's axis order (one text per role). */
  position: string[];
  circMode: CircMode;
  aux: [string, string, string];
  pathChoice: CircPathChoice;
  /** A number, or `maximum` (velocity); blank = `default` for acceleration, deceleration, jerk. */
  velocity: string;
  acceleration: string;
  deceleration: string;
  jerk: string;
  bufferMode: BufferMode;
  transitionMode: TransitionMode;
  /** TransitionParameter[1] (corner distance, r_in) and [2] (r_out, advanced only). */
  rIn: string;
  rOut: string;
  blockerId: string;
  time: string;
  invokeId: string;
}

let keys = 0;
const nextKey = () => ++keys;

/** The roles of a group's axis order: the convention's, then ADDAX1..n (GroupConfig::roles). */
export function groupRoles(convention: AxesConvention, additional: number): GroupRole[] {
  const spatial: GroupRole[] = convention === 'xy' ? ['x', 'y'] : convention === 'xyz' ? ['x', 'y', 'z'] : ['x', 'y', 'z', 'c'];
  const add: GroupRole[] = ['addax1', 'addax2', 'addax3', 'addax4', 'addax5', 'addax6', 'addax7', 'addax8'];
  return [...spatial, ...add.slice(0, Math.max(0, Math.min(8, additional)))];
}

/** The dim of a role in a path point ([X, Y, Z, C, ADDAX1..8]: GroupRole::dim). */
export function roleDim(r: GroupRole): number {
  return ['x', 'y', 'z', 'c', 'addax1', 'addax2', 'addax3', 'addax4', 'addax5', 'addax6', 'addax7', 'addax8'].indexOf(r);
}

/**
 * A new row. The first row of a table takes the manual's defaults (`aborting`, `none`); a row
 * after it `buffered` / `none`, its velocity and position those of the row before (so that it
 * starts as a copy to edit, not as a row of blanks).
 */
export function newRow(axes: number, before?: PathRow, type: EntryType = 'linear'): PathRow {
  return {
    key: nextKey(),
    type,
    position: before?.position.slice(0, axes) ?? Array.from({ length: axes }, () => '0'),
    circMode: 'center',
    aux: ['0', '0', '0'],
    pathChoice: 'counter_clockwise',
    velocity: before?.velocity || '100',
    acceleration: '',
    deceleration: '',
    jerk: '',
    bufferMode: before ? 'buffered' : 'aborting',
    transitionMode: 'none',
    rIn: '',
    rOut: '',
    blockerId: '1',
    time: '0.5',
    invokeId: '',
  };
}

/** A row with `position` fitted to `axes` values (a group of another axis count). */
export function fitRow(r: PathRow, axes: number): PathRow {
  if (r.position.length === axes) return r;
  return { ...r, position: Array.from({ length: axes }, (_, i) => r.position[i] ?? '0') };
}

/**
 * "Blend corners": every row after the first that moves (linear, circular) is set to
 * `blending_previous` + `corner_distance` with radius `radius` (text as typed); the first row
 * and blockers and dwells are left as they are.
 */
export function blendCorners(rows: PathRow[], radius: string): PathRow[] {
  return rows.map((r, i) =>
    i > 0 && (r.type === 'linear' || r.type === 'circular')
      ? { ...r, bufferMode: 'blending_previous', transitionMode: 'corner_distance', rIn: radius, rOut: '' }
      : r,
  );
}

/** Every row after the first back to an exact stop (`buffered` / `none`). */
export function exactStops(rows: PathRow[]): PathRow[] {
  return rows.map((r, i) => (i > 0 && r.bufferMode === 'blending_previous' ? { ...r, bufferMode: 'buffered', transitionMode: 'none', rIn: '', rOut: '' } : r));
}

/** Moves row `i` by `by` (−1 up, +1 down); the same list if it cannot move. */
export function moveRow(rows: PathRow[], i: number, by: number): PathRow[] {
  const j = i + by;
  if (i < 0 || i >= rows.length || j < 0 || j >= rows.length) return rows;
  const out = rows.slice();
  [out[i], out[j]] = [out[j], out[i]];
  return out;
}

const numText = (s: string) => Number(s.trim().replace(',', '.'));
/** A number as typed: '' and text that is not a number are NaN (never sent: NotSentError). */
const number = (s: string) => (s.trim() === '' ? NaN : numText(s));

/** A dynamics input: blank → absent (the group's default), `default` / `maximum`, else the number. */
function dynamics(s: string): PathValue | undefined {
  const t = s.trim().toLowerCase();
  if (t === '') return undefined;
  if (t === 'default' || t === 'maximum') return t;
  return numText(t);
}

/** The velocity (mandatory): `maximum`, or the number (blank: NaN, not sent). */
function velocity(s: string): PathValue {
  const t = s.trim().toLowerCase();
  return t === 'maximum' || t === 'default' ? t : number(t);
}

function invoke(s: string): number | undefined {
  return s.trim() === '' ? undefined : number(s);
}

function transition(r: PathRow): { transition_mode: TransitionMode; transition_parameters?: number[] } {
  switch (r.transitionMode) {
    case 'corner_distance':
      return { transition_mode: r.transitionMode, transition_parameters: [number(r.rIn)] };
    case 'corner_distance_advanced':
      return { transition_mode: r.transitionMode, transition_parameters: [number(r.rIn), number(r.rOut)] };
    default:
      return { transition_mode: r.transitionMode };
  }
}

/** Drops the keys whose value is undefined (JSON would leave them out anyway; tests compare). */
function defined<T extends object>(o: T): T {
  return Object.fromEntries(Object.entries(o).filter(([, v]) => v !== undefined)) as T;
}

/** The JSON entry of a row. */
export function rowToEntry(r: PathRow): PathEntry {
  switch (r.type) {
    case 'linear':
      return defined({
        type: 'linear',
        position: r.position.map(number),
        velocity: velocity(r.velocity),
        acceleration: dynamics(r.acceleration),
        deceleration: dynamics(r.deceleration),
        jerk: dynamics(r.jerk),
        buffer_mode: r.bufferMode,
        ...transition(r),
        invoke_id: invoke(r.invokeId),
      }) as PathEntry;
    case 'circular':
      return defined({
        type: 'circular',
        circ_mode: r.circMode,
        aux_point: r.aux.map(number),
        end_point: r.position.map(number),
        path_choice: r.pathChoice,
        velocity: velocity(r.velocity),
        acceleration: dynamics(r.acceleration),
        deceleration: dynamics(r.deceleration),
        jerk: dynamics(r.jerk),
        buffer_mode: r.bufferMode,
        ...transition(r),
        invoke_id: invoke(r.invokeId),
      }) as PathEntry;
    case 'blocker':
      return defined({ type: 'blocker', blocker_id: number(r.blockerId), buffer_mode: r.bufferMode, invoke_id: invoke(r.invokeId) }) as PathEntry;
    case 'dwell':
      return defined({ type: 'dwell', time: number(r.time), buffer_mode: r.bufferMode, invoke_id: invoke(r.invokeId) }) as PathEntry;
  }
}

/** MC_MovePath's body of the rows. */
export function movePathBody(rows: PathRow[]): MovePathBody {
  return { entries: rows.map(rowToEntry) };
}

const text = (v: number | string | undefined | null) => (v === undefined || v === null ? '' : typeof v === 'number' ? String(v) : v);

/** A row of a JSON entry (a path loaded back, a table pasted): absent fields as the server reads them. */
export function entryToRow(e: PathEntry, axes: number): PathRow {
  const r = newRow(axes);
  if (e.type === 'coordinate_transform') {
    throw new Error('a coordinate_transform entry has no row in the editor');
  }
  r.type = e.type;
  r.velocity = '';
  switch (e.type) {
    case 'linear':
    case 'circular': {
      r.position = (e.type === 'linear' ? e.position : e.end_point).map((x) => text(x));
      if (e.type === 'circular') {
        r.circMode = e.circ_mode;
        r.aux = [text(e.aux_point[0]), text(e.aux_point[1]), text(e.aux_point[2])];
        r.pathChoice = e.path_choice ?? 'counter_clockwise';
      }
      r.velocity = text(e.velocity);
      r.acceleration = e.acceleration === 'default' ? '' : text(e.acceleration);
      r.deceleration = e.deceleration === 'default' ? '' : text(e.deceleration);
      r.jerk = e.jerk === 'default' ? '' : text(e.jerk);
      // The server's default is `aborting` whatever the row (the manual's).
      r.bufferMode = e.buffer_mode ?? 'aborting';
      r.transitionMode = e.transition_mode ?? 'none';
      r.rIn = text(e.transition_parameters?.[0]);
      r.rOut = text(e.transition_parameters?.[1]);
      break;
    }
    case 'blocker':
      r.blockerId = text(e.blocker_id);
      r.bufferMode = e.buffer_mode ?? 'buffered';
      break;
    case 'dwell':
      r.time = text(e.time);
      r.bufferMode = e.buffer_mode ?? 'buffered';
      break;
  }
  r.invokeId = e.invoke_id ? String(e.invoke_id) : '';
  return r;
}

/** What the preview draws of a row (null: a row it cannot read; the server will say why). */
export function previewEntry(r: PathRow): PreviewEntry | null {
  const corner = (): [number, number] | undefined => {
    if (r.bufferMode === 'buffered') return undefined;
    if (r.transitionMode === 'corner_distance') return [number(r.rIn), number(r.rIn)];
    if (r.transitionMode === 'corner_distance_advanced') return [number(r.rIn), number(r.rOut)];
    return undefined;
  };
  switch (r.type) {
    case 'linear':
      return { type: 'linear', position: r.position.map(number), corner: corner() };
    case 'circular':
      return {
        type: 'circular',
        circ_mode: r.circMode,
        aux_point: r.aux.map(number) as Vec3,
        end_point: r.position.map(number),
        path_choice: r.pathChoice as PathChoiceName,
        corner: corner(),
      };
    default:
      return { type: r.type };
  }
}

/**
 * The server's field errors of row `i` (`entries[i].…`), by the field's name within the row
 * (`velocity`, `position`, `position[1]`, `transition_parameters` …); `entries` itself (the
 * whole table) is not a row's.
 */
export function rowErrors(fields: Record<string, string>, i: number): Record<string, string> {
  const prefix = `entries[${i}].`;
  const out: Record<string, string> = {};
  for (const [k, v] of Object.entries(fields)) if (k.startsWith(prefix)) out[k.slice(prefix.length)] = v;
  return out;
}

/** The message of `field` in a row's errors, also one given for an element of it (`position[1]`) or for all of it. */
export function fieldError(errs: Record<string, string>, field: string): string | undefined {
  if (errs[field]) return errs[field];
  const base = field.replace(/\[\d+\]$/, '');
  if (base !== field && errs[base]) return undefined; // shown once, at the vector
  const parts = Object.entries(errs).filter(([k]) => k.startsWith(field + '['));
  return parts.length ? parts.map(([, v]) => v).join('; ') : undefined;
}
