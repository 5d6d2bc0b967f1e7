// The cam editor's data: the points of a motion function as edited (texts as typed), their
// conversion to the table the server takes, and the laws offered with what they need.
import type { CamTableResource, MotionFunctionPoint, MotionFunctionType, MotionPointType } from '../api/types';

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

/** The points as the server takes them: indices 1, 2, … in row order (no gaps). */
export function pointsOf(rows: PointRow[]): MotionFunctionPoint[] {
  return rows.map((r, i) => ({
    point_index: i + 1,
    function_type: r.function_type,
    point_type: r.point_type,
    rel_index_next_point: 1,
    master_pos: num(r.master_pos),
    slave_pos: num(r.slave_pos),
    slave_velo: num(r.slave_velo),
    slave_acc: num(r.slave_acc),
    slave_jerk: num(r.slave_jerk),
  }));
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

/** The sampling increment for a plot of about `n` points over the table's range. */
export function increment(t: CamTableResource, n = 720): number {
  const span = Math.abs(t.master_end - t.master_start) || 1;
  return span / n;
}
