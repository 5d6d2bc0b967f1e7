// The cam editor's data: the table as edited (points of a motion function as typed, the rows
// of a position table as CSV), its conversion to the body the server takes, the laws offered,
// and what dragging a point on the plot does to it.
import type { CamTableBody, CamTableResource, MotionFunctionPoint, MotionFunctionType, MotionPointType } from '../api/types';

/** The laws in TwinCAT's order, with the names a TwinCAT engineer knows them by. */
export const LAWS: { type: MotionFunctionType; label: string }[] = [
  { type: 'polynom1', label: 'Polynom 1 (synchronous)' },
  { type: 'polynom3', label: 'Polynom 3' },
  { type: 'polynom5', label: 'Polynom 5' },
  { type: 'polynom7', label: 'Polynom 7' },
  { type: 'polynom8', label: 'Polynom 8' },
  { type: 'polynom9', label: 'Polynom 9' },
  { type: 'polynom11', label: 'Polynom 11' },
  { type: 'sinuslinie', label: 'Sine line' },
  { type: 'mod_sinuslinie', label: 'Modified sine' },
  { type: 'bestehorn', label: 'Bestehorn (cycloid)' },
  { type: 'beschl_trapez', label: 'Acceleration trapezoid' },
  { type: 'polynom5_mm', label: 'Polynom 5 motion↔motion (automatic)' },
  { type: 'polynom7_mm', label: 'Polynom 7 motion↔motion' },
  { type: 'polynom3_vv', label: 'Polynom 3 velocity↔velocity' },
  { type: 'harmonic_kombi_rt', label: 'Harmonic combination rest→turn' },
  { type: 'harmonic_kombi_tr', label: 'Harmonic combination turn→rest' },
  { type: 'harmonic_kombi_vt', label: 'Harmonic combination velocity→turn' },
  { type: 'harmonic_kombi_tv', label: 'Harmonic combination turn→velocity' },
  { type: 'beschl_trapez_rt', label: 'Acc. trapezoid rest→turn' },
  { type: 'beschl_trapez_tr', label: 'Acc. trapezoid turn→rest' },
  { type: 'beschl_trapez_rv', label: 'Acc. trapezoid rest→velocity' },
  { type: 'beschl_trapez_vr', label: 'Acc. trapezoid velocity→rest' },
  { type: 'mod_sinuslinie_vv', label: 'Modified sine velocity↔velocity' },
  { type: 'spline', label: 'Spline (inner point)' },
  { type: 'spline_natural', label: 'Spline, natural end' },
  { type: 'spline_tangential', label: 'Spline, tangential end' },
  { type: 'spline_periodic', label: 'Spline, periodic end' },
  { type: 'spline_linear', label: 'Spline, linear end' },
];

export const POINT_TYPES: MotionPointType[] = ['rest', 'velocity', 'turn', 'motion', 'ignore'];

/** One point as edited: numbers as typed. */
export interface PointRow {
  function_type: MotionFunctionType;
  point_type: MotionPointType;
  master_pos: string;
  slave_pos: string;
  slave_velo: string;
  slave_acc: string;
  slave_jerk: string;
}

const text = (v: number | undefined) => (v === undefined ? '0' : String(v));

export function rowsOf(points: MotionFunctionPoint[]): PointRow[] {
  return points.map((p) => ({
    function_type: p.function_type,
    point_type: p.point_type ?? 'rest',
    master_pos: text(p.master_pos),
    slave_pos: text(p.slave_pos),
    slave_velo: text(p.slave_velo),
    slave_acc: text(p.slave_acc),
    slave_jerk: text(p.slave_jerk),
  }));
}

const num = (s: string) => {
  const t = s.trim().replace(',', '.');
  return t === '' ? 0 : Number(t);
};

/**
 * The points as the server takes them: indices 1, 2, … in row order (no gaps), each linked to
 * the next point that is not IGNORE (`rel_index_next_point`, 1 when none follows).
 */
export function pointsOf(rows: PointRow[]): MotionFunctionPoint[] {
  return rows.map((r, i) => {
    let next = rows.findIndex((q, k) => k > i && q.point_type !== 'ignore');
    if (next < 0) next = i + 1;
    return {
      point_index: i + 1,
      function_type: r.function_type,
      point_type: r.point_type,
      rel_index_next_point: next - i,
      master_pos: num(r.master_pos),
      slave_pos: num(r.slave_pos),
      slave_velo: num(r.slave_velo),
      slave_acc: num(r.slave_acc),
      slave_jerk: num(r.slave_jerk),
    };
  });
}

/** A new row after the last: one more segment of the same law, 10 % of the range further. */
export function nextRow(rows: PointRow[]): PointRow {
  const last = rows[rows.length - 1];
  if (!last) return { function_type: 'polynom5', point_type: 'rest', master_pos: '0', slave_pos: '0', slave_velo: '0', slave_acc: '0', slave_jerk: '0' };
  const prev = rows[rows.length - 2];
  const step = prev ? num(last.master_pos) - num(prev.master_pos) : 90;
  return { ...last, master_pos: String(num(last.master_pos) + (step > 0 ? step : 90)) };
}

/** CSV of a position table's rows (`master,slave` per line) and back. */
export function rowsToCsv(rows: number[][]): string {
  return ['master,slave', ...rows.map((r) => `${r[0]},${r[1]}`)].join('\n') + '\n';
}

export function csvToRows(csv: string): number[][] {
  const out: number[][] = [];
  for (const line of csv.split(/\r?\n/)) {
    const cells = line.split(/[,;\t]/).map((c) => c.trim());
    if (cells.length < 2 || cells[0] === '' || Number.isNaN(Number(cells[0]))) continue;
    out.push([Number(cells[0]), Number(cells[1])]);
  }
  return out;
}

/** The table as edited: what undo and redo go through. */
export interface Draft {
  periodic: boolean;
  /** The points of a motion function (empty for a position table). */
  points: PointRow[];
  /** The rows of a position table as CSV text (empty for a motion function). */
  csv: string;
}

/** What a table is, beside what is edited. */
export type TableMeta = Pick<CamTableResource, 'id' | 'name' | 'table_type' | 'interpolation'>;

export function draftOf(t: CamTableResource): Draft {
  return { periodic: t.periodic, points: rowsOf(t.points ?? []), csv: t.rows ? rowsToCsv(t.rows) : '' };
}

/** The body of `PUT /cam-tables/{id}` and `POST /cam-analysis` for the table as edited. */
export function bodyOf(t: TableMeta, d: Draft): CamTableBody {
  return t.table_type === 'motion_function'
    ? { id: t.id, name: t.name, table_type: t.table_type, periodic: d.periodic, points: pointsOf(d.points) }
    : { id: t.id, name: t.name, table_type: t.table_type, periodic: d.periodic, interpolation: t.interpolation, rows: csvToRows(d.csv) };
}

/** A point of the plot that can be dragged: a motion function's point or a position table's row. */
export interface Handle {
  index: number;
  master: number;
  slave: number;
}

/** Position tables with more rows than this get no handles (they would hide the curve). */
export const MAX_ROW_HANDLES = 100;

export function handlesOf(t: TableMeta, d: Draft): Handle[] {
  const pts: [number, number][] =
    t.table_type === 'motion_function' ? d.points.map((r) => [num(r.master_pos), num(r.slave_pos)]) : (csvToRows(d.csv) as [number, number][]);
  if (t.table_type !== 'motion_function' && pts.length > MAX_ROW_HANDLES) return [];
  return pts.map(([master, slave], index) => ({ index, master, slave })).filter((h) => Number.isFinite(h.master) && Number.isFinite(h.slave));
}

/** The resolution a drag moves in over a range: about a thousandth of it, a power of ten. */
export function stepOf(span: number): number {
  const s = Math.abs(span);
  return s > 0 && Number.isFinite(s) ? 10 ** (Math.floor(Math.log10(s)) - 3) : 0.001;
}

function snap(v: number, step: number): number {
  const digits = Math.max(0, -Math.floor(Math.log10(step)));
  return Number((Math.round(v / step) * step).toFixed(digits));
}

/**
 * Where a dragged point goes: master and slave rounded to their steps, the master strictly
 * between its neighbours' masters (at least one step from each); a point whose neighbours
 * leave no room keeps its master. `masters` are the present masters of all points.
 */
export function dragTarget(masters: number[], i: number, master: number, slave: number, mStep: number, sStep: number): { master: number; slave: number } {
  let m = snap(master, mStep);
  const lo = i > 0 && Number.isFinite(masters[i - 1]) ? snap(masters[i - 1] + mStep, mStep) : -Infinity;
  const hi = i < masters.length - 1 && Number.isFinite(masters[i + 1]) ? snap(masters[i + 1] - mStep, mStep) : Infinity;
  if (lo > hi) m = masters[i];
  else m = Math.min(hi, Math.max(lo, m));
  return { master: m, slave: snap(slave, sStep) };
}

/** The draft with handle `i` dragged to (master, slave); an equidistant table keeps its masters. */
export function dragDraft(t: TableMeta, d: Draft, i: number, master: number, slave: number, mStep: number, sStep: number): Draft {
  if (t.table_type === 'motion_function') {
    const to = dragTarget(d.points.map((r) => num(r.master_pos)), i, master, slave, mStep, sStep);
    return { ...d, points: d.points.map((r, k) => (k === i ? { ...r, master_pos: String(to.master), slave_pos: String(to.slave) } : r)) };
  }
  const rows = csvToRows(d.csv);
  if (!rows[i]) return d;
  const to = dragTarget(rows.map((r) => r[0]), i, t.table_type === 'equidistant' ? rows[i][0] : master, slave, mStep, sStep);
  return { ...d, csv: rowsToCsv(rows.map((r, k) => (k === i ? [t.table_type === 'equidistant' ? r[0] : to.master, to.slave] : r))) };
}
