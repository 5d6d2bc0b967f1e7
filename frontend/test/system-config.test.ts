// What importing a configuration file would change (the diff shown before any import), and the
// server's refusals in words of the file's axes.
import { describe, expect, it } from 'vitest';
import { diffConfig, diffCounts, diffValues, exportName, fieldLabel, importErrors, notADocument, valueText, type ConfigDocument } from '../src/system/config-diff';

const axis = (id: number, name: string, extra: Record<string, unknown> = {}, persistent: Record<string, unknown> = {}) => ({
  id,
  config: {
    name,
    unit: 'mm',
    dynamics: { max_velocity: 500, acceleration: 2500, deceleration: 2500, jerk: 25000, jog_velocity_slow: 10, jog_velocity_fast: 100 },
    parameters: { AxisTargetPositionWindow: 0.01 },
    drive: { kind: 'simulated', dead_time: 0.001, plant: { kind: 'pt2', natural_frequency_hz: 50, damping: 0.8 } },
    ...extra,
  },
  persistent_parameters: persistent,
});

const table = (name: string, rows: number[][]) => ({ id: 1, name, table_type: 'position' as const, periodic: false, interpolation: 'linear' as const, rows });

const current = {
  version: 1,
  axes: [axis(1, 'x', {}, { AxisVeloMax: 400 }), axis(2, 'y'), axis(3, 'spindle', { unit: 'deg', modulo: { period: 360 } })],
  cam_tables: [table('knife', [[0, 0], [10, 5], [20, 10]]), table('old', [[0, 0], [1, 1]])],
} as unknown as ConfigDocument;

const clone = <T>(x: T): T => JSON.parse(JSON.stringify(x));

describe('the configuration diff', () => {
  it('the same document: nothing changes', () => {
    const d = diffConfig(current, clone(current));
    expect(d.same).toBe(true);
    expect(d.axes.map((a) => a.kind)).toEqual(['same', 'same', 'same']);
    expect(diffCounts(d)).toEqual({ added: 0, removed: 0, changed: 0, fields: 0 });
  });

  it('per axis (by name): changed fields with old → new, added and removed axes', () => {
    const file = clone(current) as any;
    file.axes[0].config.dynamics.max_velocity = 400;
    file.axes[0].config.drive.plant.natural_frequency_hz = 80;
    delete file.axes[0].persistent_parameters.AxisVeloMax;
    file.axes[0].persistent_parameters.AxisAccMax = 1000;
    file.axes.splice(1, 1); // y removed
    file.axes.push(axis(4, 'z', { unit: 'm' }));
    const d = diffConfig(current, file);
    expect(d.same).toBe(false);
    const x = d.axes.find((a) => a.name === 'x')!;
    expect(x.kind).toBe('changed');
    expect(x.changes).toEqual([
      { path: 'dynamics.max_velocity', old: 500, new: 400 },
      { path: 'drive.plant.natural_frequency_hz', old: 50, new: 80 },
      { path: 'persistent_parameters.AxisVeloMax', old: 400, new: undefined },
      { path: 'persistent_parameters.AxisAccMax', old: undefined, new: 1000 },
    ]);
    expect(d.axes.find((a) => a.name === 'spindle')!.kind).toBe('same');
    expect(d.axes.find((a) => a.name === 'z')).toMatchObject({ kind: 'added', summary: 'm, simulated drive' });
    expect(d.axes.find((a) => a.name === 'y')).toMatchObject({ kind: 'removed', summary: 'mm, simulated drive' });
    expect(diffCounts(d)).toEqual({ added: 1, removed: 1, changed: 1, fields: 4 });
  });

  it('an axis id and a modulo are fields too; null is not the same as absent', () => {
    const file = clone(current) as any;
    file.axes[2].id = 7;
    file.axes[2].config.modulo = null;
    file.axes[1].config.drive.reference_cam = null;
    const d = diffConfig(current, file);
    expect(d.axes.find((a) => a.name === 'spindle')!.changes).toEqual([
      { path: 'modulo', old: { period: 360 }, new: null },
      { path: 'id', old: 3, new: 7 },
    ]);
    expect(d.axes.find((a) => a.name === 'y')!.changes).toEqual([{ path: 'drive.reference_cam', old: undefined, new: null }]);
  });

  it('cam tables: added, removed, changed (rows counted, not listed); none in the file: kept', () => {
    const file = clone(current) as any;
    file.cam_tables[0].rows[1] = [10, 6];
    file.cam_tables[0].periodic = true;
    file.cam_tables.splice(1, 1);
    file.cam_tables.push(table('new', [[0, 0], [5, 5]]));
    const d = diffConfig(current, file);
    const knife = d.camTables!.find((t) => t.name === 'knife')!;
    expect(knife.kind).toBe('changed');
    expect(knife.changes.map((c) => [c.path, c.note])).toEqual([
      ['periodic', undefined],
      ['rows', '1 of 3 rows differ'],
    ]);
    expect(d.camTables!.find((t) => t.name === 'old')).toMatchObject({ kind: 'removed', summary: 'position, 2 rows' });
    expect(d.camTables!.find((t) => t.name === 'new')).toMatchObject({ kind: 'added', summary: 'position, 2 rows' });
    const longer = clone(file);
    longer.cam_tables[0].rows.push([30, 12]);
    expect(diffConfig(current, longer).camTables!.find((t) => t.name === 'knife')!.changes.find((c) => c.path === 'rows')!.note).toBe('3 → 4 rows');

    const without = clone(current) as any;
    delete without.cam_tables;
    const k = diffConfig(current, without);
    expect(k.camTables).toBeNull();
    expect(k.same).toBe(true);
    // an empty list empties them
    const empty = { ...clone(current), cam_tables: [] };
    expect(diffConfig(current, empty).camTables!.map((t) => t.kind)).toEqual(['removed', 'removed']);
  });

  it('leaf changes of nested values; lists compared whole', () => {
    expect(diffValues({ a: { b: 1, c: [1, 2] } }, { a: { b: 2, c: [1, 2] } })).toEqual([{ path: 'a.b', old: 1, new: 2 }]);
    expect(diffValues({ a: [1, 2] }, { a: [1, 3] })).toEqual([{ path: 'a', old: [1, 2], new: [1, 3], note: '1 of 2 items differ' }]);
    expect(diffValues(1, 1)).toEqual([]);
    expect(diffValues({ a: 1, b: undefined }, { a: 1 })).toEqual([]);
  });

  it('values as text', () => {
    expect(valueText(undefined)).toBe('(none)');
    expect(valueText(null)).toBe('null');
    expect(valueText(400)).toBe('400');
    expect(valueText({ period: 360 })).toBe('{"period":360}');
    expect(valueText([[0, 0], [1, 1]])).toBe('[2 items]');
    expect(valueText('x'.repeat(100)).length).toBe(60);
  });
});

describe('reading and refusing a file', () => {
  it('only a configuration document gets to the diff', () => {
    expect(notADocument([])).toMatch(/not a JSON object/);
    expect(notADocument({ version: 1 })).toMatch(/no "axes"/);
    expect(notADocument({ axes: [] })).toMatch(/no "version"/);
    expect(notADocument({ version: 1, axes: [], cam_tables: {} })).toMatch(/cam_tables/);
    expect(notADocument({ version: 1, axes: [] })).toBeNull();
  });

  it('the server’s field paths named by axis or table', () => {
    expect(fieldLabel('axes[0].config.dynamics.max_velocity', current)).toBe("axis 'x': dynamics.max_velocity");
    expect(fieldLabel('axes[1].config.name', current)).toBe("axis 'y': name");
    expect(fieldLabel('axes[9].id', current)).toBe('axis #10: id');
    expect(fieldLabel('cam_tables[0].rows', current)).toBe("cam table 'knife': rows");
    expect(fieldLabel('version', current)).toBe('version');
    const p = {
      type: 'urn:motiond:problem:validation_failed',
      title: 'Invalid request',
      status: 422,
      detail: '…',
      code: 'validation_failed',
      errors: [{ field: 'axes[1].config.name', message: 'duplicate name' }],
    };
    expect(importErrors(p, current)).toEqual([{ field: 'axes[1].config.name', label: "axis 'y': name", message: 'duplicate name' }]);
    expect(importErrors(null, current)).toEqual([]);
  });

  it('the export is named by the local date', () => {
    expect(exportName(new Date(2026, 0, 5, 23, 59))).toBe('motiond-config-2026-01-05.json');
  });
});
