import { describe, expect, it } from 'vitest';
import { csvToRows, nextRow, pointsOf, rowsOf, rowsToCsv } from '../src/cams/data';

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
});
