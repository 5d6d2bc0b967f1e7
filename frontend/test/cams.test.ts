import { describe, expect, it } from 'vitest';
import { bodyOf, csvToRows, dragDraft, dragTarget, draftOf, handlesOf, nextRow, pointsOf, rowsOf, rowsToCsv, stepOf, type TableMeta } from '../src/cams/data';
import type { CamTableResource } from '../src/api/types';

const resource = (patch: Partial<CamTableResource>): CamTableResource => ({
  id: 3,
  name: 'lift',
  version: 1,
  table_type: 'motion_function',
  periodic: false,
  interpolation: 'linear',
  row_count: 0,
  master_start: 0,
  master_end: 360,
  slave_start: 0,
  slave_end: 0,
  master_period: 360,
  slave_stroke: 0,
  updated_at: '',
  ...patch,
});

describe('cam editor data', () => {
  it('numbers points 1, 2, … in row order, texts as numbers', () => {
    const rows = rowsOf([
      { point_index: 5, function_type: 'polynom5', point_type: 'rest', master_pos: 0, slave_pos: 0 },
      { point_index: 6, function_type: 'polynom1', point_type: 'velocity', master_pos: 90, slave_pos: 10, slave_velo: 0.5 },
    ]);
    rows[1].slave_pos = '12,5';
    const p = pointsOf(rows);
    expect(p.map((x) => x.point_index)).toEqual([1, 2]);
    expect(p[1]).toMatchObject({ function_type: 'polynom1', point_type: 'velocity', master_pos: 90, slave_pos: 12.5, slave_velo: 0.5 });
  });
  it('each point links to the next one that is not IGNORE', () => {
    const rows = rowsOf([
      { point_index: 1, function_type: 'polynom5', point_type: 'rest', master_pos: 0, slave_pos: 0 },
      { point_index: 2, function_type: 'polynom5', point_type: 'ignore', master_pos: 50, slave_pos: 7 },
      { point_index: 3, function_type: 'polynom5', point_type: 'ignore', master_pos: 60, slave_pos: 7 },
      { point_index: 4, function_type: 'polynom5', point_type: 'rest', master_pos: 100, slave_pos: 10 },
    ]);
    expect(pointsOf(rows).map((p) => p.rel_index_next_point)).toEqual([3, 2, 1, 1]);
  });
  it('a new point continues with the last step and law', () => {
    const rows = rowsOf([
      { point_index: 1, function_type: 'polynom5', point_type: 'rest', master_pos: 0, slave_pos: 0 },
      { point_index: 2, function_type: 'polynom7', point_type: 'rest', master_pos: 120, slave_pos: 10 },
    ]);
    expect(nextRow(rows)).toMatchObject({ master_pos: '240', function_type: 'polynom7' });
  });
  it('position tables go to CSV and back; a header and blank lines are skipped', () => {
    const csv = rowsToCsv([
      [0, 0],
      [10, 2.5],
    ]);
    expect(csv).toBe('master,slave\n0,0\n10,2.5\n');
    expect(csvToRows(csv + '\n20;5\n')).toEqual([
      [0, 0],
      [10, 2.5],
      [20, 5],
    ]);
  });
  it('the body of a motion function has its points, of a position table its rows and interpolation', () => {
    const mf = resource({ points: [{ point_index: 1, function_type: 'polynom5', point_type: 'rest', master_pos: 0, slave_pos: 0 }] });
    expect(bodyOf(mf, { ...draftOf(mf), periodic: true })).toMatchObject({ id: 3, name: 'lift', table_type: 'motion_function', periodic: true, points: [{ point_index: 1 }] });
    const pt = resource({ table_type: 'non_equidistant', interpolation: 'spline', rows: [[0, 0], [10, 5]] });
    const d = draftOf(pt);
    expect(d.csv).toBe('master,slave\n0,0\n10,5\n');
    expect(bodyOf(pt, { ...d, csv: d.csv + '20,1\n' })).toEqual({ id: 3, name: 'lift', table_type: 'non_equidistant', periodic: false, interpolation: 'spline', rows: [[0, 0], [10, 5], [20, 1]] });
  });
});

describe('dragging a point', () => {
  const mf: TableMeta = { id: 1, name: 'c', table_type: 'motion_function', interpolation: 'linear' };
  const draft = draftOf(
    resource({
      points: [
        { point_index: 1, function_type: 'polynom5', point_type: 'rest', master_pos: 0, slave_pos: 0 },
        { point_index: 2, function_type: 'polynom5', point_type: 'rest', master_pos: 180, slave_pos: 100 },
        { point_index: 3, function_type: 'polynom5', point_type: 'rest', master_pos: 360, slave_pos: 0 },
      ],
    }),
  );

  it('moves in steps of about a thousandth of the range', () => {
    expect(stepOf(360)).toBeCloseTo(0.1);
    expect(stepOf(1)).toBeCloseTo(0.001);
    expect(stepOf(0)).toBe(0.001);
  });
  it('master and slave follow, rounded to their steps', () => {
    const d = dragDraft(mf, draft, 1, 200.04, 73.456, 0.1, 0.01);
    expect(d.points[1]).toMatchObject({ master_pos: '200', slave_pos: '73.46' });
    expect(d.points[0]).toBe(draft.points[0]);
  });
  it('the master stays strictly between its neighbours', () => {
    expect(dragDraft(mf, draft, 1, 400, 0, 0.1, 0.1).points[1].master_pos).toBe('359.9');
    expect(dragDraft(mf, draft, 1, -5, 0, 0.1, 0.1).points[1].master_pos).toBe('0.1');
    // the first point has no left neighbour
    expect(dragDraft(mf, draft, 0, -20, 0, 0.1, 0.1).points[0].master_pos).toBe('-20');
    // neighbours one step apart leave no room: the master stays
    expect(dragTarget([0, 0.05, 0.1], 1, 3, 1, 0.1, 0.1)).toEqual({ master: 0.05, slave: 1 });
  });
  it('a position table row is dragged in its CSV; an equidistant one keeps its master', () => {
    const pt: TableMeta = { id: 2, name: 'p', table_type: 'non_equidistant', interpolation: 'linear' };
    const d = { periodic: false, points: [], csv: 'master,slave\n0,0\n10,5\n20,0\n' };
    expect(dragDraft(pt, d, 1, 12.34, 6.78, 0.01, 0.01).csv).toBe('master,slave\n0,0\n12.34,6.78\n20,0\n');
    expect(dragDraft({ ...pt, table_type: 'equidistant' }, d, 1, 12.34, 6.78, 0.01, 0.01).csv).toBe('master,slave\n0,0\n10,6.78\n20,0\n');
    expect(handlesOf(pt, d)).toEqual([
      { index: 0, master: 0, slave: 0 },
      { index: 1, master: 10, slave: 5 },
      { index: 2, master: 20, slave: 0 },
    ]);
  });
  it('handles are the points with numbers (a text that is no number has none)', () => {
    const d = { ...draft, points: draft.points.map((r, i) => (i === 1 ? { ...r, slave_pos: 'x' } : r)) };
    expect(handlesOf(mf, d).map((h) => h.index)).toEqual([0, 2]);
  });
});
