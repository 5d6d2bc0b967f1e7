// The cam editor while a slave is coupled through the table: where it is on the table now
// (MC_CamInfo's master and slave cam positions, multi-cam terms too) and the plot's units
// (the slave axis's per the master axis's).
import { describe, expect, it } from 'vitest';
import { camMarkers, camUnits } from '../src/cams/online';
import { camAxisLabel } from '../src/cams/chart';
import type { AxisLiveStatus } from '../src/api/types';

const term = (id: number, x: number, y: number) => ({ cam_table_id: id, actual_master_cam_pos: x, actual_slave_cam_pos: y });
const coupled = (master: string, cam: Record<string, unknown>) => ({ status: { master, cam: { active: true, cams: [], ...cam } } as unknown as AxisLiveStatus });

describe('camMarkers', () => {
  it('the coupled slaves’ positions on this table, in its own coordinates', () => {
    const m = new Map<string, { status: AxisLiveStatus | null }>([
      ['z', coupled('x', { cam_table_id: 3, actual_master_cam_pos: 190, actual_slave_cam_pos: 95 })],
      ['y', coupled('x', { cam_table_id: 3, multi_cam: true, cams: [term(1, 5, 6), term(3, 40, 20), term(0, 0, 0)] })],
      ['w', coupled('x', { cam_table_id: 4, actual_master_cam_pos: 1, actual_slave_cam_pos: 2 })],
      ['v', coupled('x', { cam_table_id: 3, active: false, actual_master_cam_pos: 1, actual_slave_cam_pos: 2 })],
      ['u', { status: null }],
    ]);
    expect(camMarkers(m, 3)).toEqual([
      { axis: 'y', master: 'x', x: 40, y: 20 },
      { axis: 'z', master: 'x', x: 190, y: 95 },
    ]);
    expect(camMarkers(m, 9)).toEqual([]);
  });
});

describe('the plot’s units', () => {
  const axes = [
    { config: { name: 'x', unit: 'deg' } },
    { config: { name: 'y', unit: 'mm' } },
  ];
  it('a coupled slave’s unit per its master’s', () => {
    const u = camUnits([{ axis: 'y', master: 'x', x: 0, y: 0 }], axes);
    expect(u).toEqual({ master: 'deg', slave: 'mm' });
    expect([camAxisLabel('x', u), camAxisLabel(0, u), camAxisLabel(1, u), camAxisLabel(2, u), camAxisLabel(3, u)]).toEqual([
      'master (deg)',
      'position (mm)',
      'vel (mm/deg)',
      'acc (mm/deg²)',
      'jerk (mm/deg³)',
    ]);
  });
  it('no slave coupled: a table has no units of its own', () => {
    expect(camUnits([], axes)).toBe(null);
    expect([camAxisLabel('x', null), camAxisLabel(1, null)]).toEqual(['master', 'velocity']);
  });
});
