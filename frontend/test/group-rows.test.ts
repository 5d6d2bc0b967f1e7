// The path editor's rows ↔ MC_MovePath's JSON entries (groups/rows.ts), the group form's body
// (groups/config.ts), and where the server's field errors land.
import { describe, expect, it } from 'vitest';
import { blendCorners, entryToRow, exactStops, groupRoles, moveRow, movePathBody, newRow, previewEntry, rowErrors, rowToEntry, type PathRow } from '../src/groups/rows';
import { bodyOf, memberError, memberField, newDraft } from '../src/groups/config';
import { nonFiniteFields } from '../src/api/problem';

const row = (p: Partial<PathRow>, before?: PathRow): PathRow => ({ ...newRow(2, before), ...p });

describe('rows → entries', () => {
  it('a first row takes the manual defaults (aborting / none); a row after it buffered / none, copying velocity and target', () => {
    const a = newRow(2);
    expect([a.bufferMode, a.transitionMode]).toEqual(['aborting', 'none']);
    a.position = ['100', '0'];
    a.velocity = '250';
    const b = newRow(2, a);
    expect([b.bufferMode, b.transitionMode, b.velocity, b.position]).toEqual(['buffered', 'none', '250', ['100', '0']]);
  });

  it('a linear row: numbers as typed, blank dynamics left out (the group default), "maximum" kept', () => {
    const r = row({ position: ['100', '-2,5'], velocity: '200', acceleration: '', deceleration: 'maximum', jerk: '5000', invokeId: '10' });
    expect(rowToEntry(r)).toEqual({
      type: 'linear',
      position: [100, -2.5],
      velocity: 200,
      deceleration: 'maximum',
      jerk: 5000,
      buffer_mode: 'aborting',
      transition_mode: 'none',
      invoke_id: 10,
    });
  });

  it('a circular row: circ mode, aux point, end point, path choice; corner distance with its parameter', () => {
    const r = row({ type: 'circular', circMode: 'center', aux: ['100', '50', '0'], position: ['150', '50'], pathChoice: 'clockwise', velocity: 'maximum', bufferMode: 'blending_previous', transitionMode: 'corner_distance', rIn: '5' });
    expect(rowToEntry(r)).toEqual({
      type: 'circular',
      circ_mode: 'center',
      aux_point: [100, 50, 0],
      end_point: [150, 50],
      path_choice: 'clockwise',
      velocity: 'maximum',
      buffer_mode: 'blending_previous',
      transition_mode: 'corner_distance',
      transition_parameters: [5],
    });
    expect(rowToEntry({ ...r, transitionMode: 'corner_distance_advanced', rIn: '4', rOut: '8' })).toMatchObject({ transition_parameters: [4, 8] });
  });

  it('blocker and dwell rows send only their own fields', () => {
    expect(rowToEntry(row({ type: 'blocker', blockerId: '7', bufferMode: 'buffered', invokeId: '3' }))).toEqual({ type: 'blocker', blocker_id: 7, buffer_mode: 'buffered', invoke_id: 3 });
    expect(rowToEntry(row({ type: 'dwell', time: '0.25', bufferMode: 'buffered' }))).toEqual({ type: 'dwell', time: 0.25, buffer_mode: 'buffered' });
  });

  it('text that is not a number is never sent: the client names its JSON path (entries[i].field)', () => {
    const body = movePathBody([row({ position: ['1', '2'] }), row({ position: ['x', '2'], velocity: '' })]);
    expect(nonFiniteFields(body)).toEqual(['entries[1].position[0]', 'entries[1].velocity']);
  });

  it('entries → rows → entries is the same JSON', () => {
    const entries = [
      { type: 'linear', position: [100, 0], velocity: 200, buffer_mode: 'aborting', transition_mode: 'none', invoke_id: 1 },
      { type: 'circular', circ_mode: 'radius', aux_point: [0, 0, 60], end_point: [150, 50], path_choice: 'long_segment', velocity: 150, buffer_mode: 'buffered', transition_mode: 'none' },
      { type: 'linear', position: [150, 150], velocity: 'maximum', acceleration: 500, buffer_mode: 'blending_previous', transition_mode: 'corner_distance_advanced', transition_parameters: [3, 6] },
      { type: 'blocker', blocker_id: 4, buffer_mode: 'buffered' },
      { type: 'dwell', time: 1.5, buffer_mode: 'buffered', invoke_id: 9 },
    ] as const;
    const back = entries.map((e) => rowToEntry(entryToRow(e as never, 2)));
    expect(back).toEqual(entries);
  });
});

describe('editing the table', () => {
  it('"blend corners" sets blending_previous + corner_distance with the radius on every moving row after the first', () => {
    const rows = [row({}), row({ type: 'circular' }), row({ type: 'dwell', bufferMode: 'buffered' }), row({ bufferMode: 'buffered' })];
    const b = blendCorners(rows, '5');
    expect(b.map((r) => [r.bufferMode, r.transitionMode, r.rIn])).toEqual([
      ['aborting', 'none', ''],
      ['blending_previous', 'corner_distance', '5'],
      ['buffered', 'none', ''],
      ['blending_previous', 'corner_distance', '5'],
    ]);
    expect(previewEntry(b[3])).toMatchObject({ corner: [5, 5] });
    expect(exactStops(b).map((r) => [r.bufferMode, r.transitionMode])).toEqual([
      ['aborting', 'none'],
      ['buffered', 'none'],
      ['buffered', 'none'],
      ['buffered', 'none'],
    ]);
  });

  it('rows move up and down, not beyond the ends', () => {
    const rows = [row({ invokeId: '1' }), row({ invokeId: '2' }), row({ invokeId: '3' })];
    expect(moveRow(rows, 2, -1).map((r) => r.invokeId)).toEqual(['1', '3', '2']);
    expect(moveRow(rows, 0, -1)).toBe(rows);
  });

  it("the server's field errors of a row, by the field's name within it", () => {
    const fields = { 'entries[2].velocity': 'must be > 0', 'entries[2].position': 'wrong count', 'entries[12].velocity': 'x', entries: 'too long' };
    expect(rowErrors(fields, 2)).toEqual({ velocity: 'must be > 0', position: 'wrong count' });
    expect(rowErrors(fields, 1)).toEqual({});
  });
});

describe('the group form', () => {
  it('roles are the convention’s, then ADDAX1..n', () => {
    expect(groupRoles('xy', 0)).toEqual(['x', 'y']);
    expect(groupRoles('xyzc', 2)).toEqual(['x', 'y', 'z', 'c', 'addax1', 'addax2']);
  });
  it('sends the roles that have an axis; their selects are named by the index sent, where the 422 points', () => {
    const d = newDraft(['x', 'y']);
    d.name = 'g';
    d.convention = 'xyz';
    d.axes = { x: 'x', y: '', z: 'y' };
    const body = bodyOf(d);
    expect(body.axes).toEqual([
      { role: 'x', axis: 'x' },
      { role: 'z', axis: 'y' },
    ]);
    expect(body.default_dynamics).toEqual({ velocity: 100, acceleration: 1000, deceleration: 1000, jerk: 10000 });
    expect(memberField(d, 'z')).toBe('axes[1].axis');
    expect(memberError(d, 'z', { 'axes[1].axis': 'axis y belongs to group xy' })).toBe('axis y belongs to group xy');
    expect(memberError(d, 'x', { 'axes[1].axis': 'axis y belongs to group xy' })).toBeUndefined();
    expect(body.id).toBeUndefined();
  });
});
