// The audit log of the System page: pages merged by id, queries, client-side filters.
import { describe, expect, it } from 'vitest';
import {
  FAILURES,
  NO_FILTER,
  actionSuggestions,
  auditQuery,
  detailLine,
  distinct,
  filterEntries,
  isFiltered,
  mergeEntries,
  newestId,
  oldestId,
  outcomeKind,
  stamp,
  who,
  type AuditRecord,
} from '../src/system/audit';

const rec = (id: number, action: string, target: string | null, outcome: string | null, extra: Partial<AuditRecord> = {}): AuditRecord => ({
  id,
  at: `2026-11-25T12:00:${String(id % 60).padStart(2, '0')}.000Z`,
  action,
  target,
  outcome,
  client_id: 'ui-abc',
  client_addr: '127.0.0.1:5000',
  principal: null,
  command_id: null,
  detail: null,
  ...extra,
});

const log = [
  rec(9, 'command.final', 'x', 'done', { command_id: 4 }),
  rec(8, 'command.move-absolute', 'x', 'rejected:control_held'),
  rec(7, 'config.import', 'config', 'committed'),
  rec(6, 'command.power', 'y', 'accepted', { command_id: 3 }),
  rec(5, 'parameter.write', 'x', 'committed'),
  rec(4, 'command.final', 'y', 'aborted', { command_id: 3 }),
  rec(3, 'command.move-velocity', 'spindle', 'error:drive_fault'),
  rec(2, 'axis.create', 'spindle', null),
];

describe('pages of the audit log', () => {
  it('merges by id, newest first, each id once', () => {
    const a = log.slice(0, 3);
    const b = [rec(10, 'axis.delete', 'z', 'committed'), ...log.slice(2, 5)];
    const m = mergeEntries(a, b);
    expect(m.map((e) => e.id)).toEqual([10, 9, 8, 7, 6, 5]);
    expect(newestId(m)).toBe(10);
    expect(oldestId(m)).toBe(5);
    expect(newestId([])).toBeNull();
    expect(oldestId([])).toBeNull();
  });

  it('queries: the newest, newer than, older than', () => {
    expect(auditQuery({})).toBe('/audit?limit=100');
    expect(auditQuery({ limit: 50, since: 9 })).toBe('/audit?limit=50&since_id=9');
    expect(auditQuery({ before: 5 })).toBe('/audit?limit=100&before_id=5');
    expect(auditQuery({ since: null, before: null })).toBe('/audit?limit=100');
  });
});

describe('filters over what is loaded', () => {
  const ids = (f: Partial<typeof NO_FILTER>) => filterEntries(log, { ...NO_FILTER, ...f }).map((e) => e.id);

  it('none: everything', () => {
    expect(ids({})).toEqual([9, 8, 7, 6, 5, 4, 3, 2]);
    expect(isFiltered(NO_FILTER)).toBe(false);
    expect(isFiltered({ ...NO_FILTER, target: ' x ' })).toBe(true);
  });

  it('action by prefix (case-insensitive)', () => {
    expect(ids({ action: 'command.' })).toEqual([9, 8, 6, 4, 3]);
    expect(ids({ action: 'command.move' })).toEqual([8, 3]);
    expect(ids({ action: 'CONFIG' })).toEqual([7]);
    expect(ids({ action: '  ' })).toEqual([9, 8, 7, 6, 5, 4, 3, 2]);
  });

  it('target exactly (an axis, or a command id)', () => {
    expect(ids({ target: 'x' })).toEqual([9, 8, 5]);
    expect(ids({ target: 'spin' })).toEqual([]);
    expect(ids({ target: '3' })).toEqual([6, 4]);
  });

  it('outcome: one exactly, or the failures (rejected, error, aborted)', () => {
    expect(ids({ outcome: 'committed' })).toEqual([7, 5]);
    expect(ids({ outcome: FAILURES })).toEqual([8, 4, 3]);
    expect(outcomeKind('rejected:control_held')).toBe('fail');
    expect(outcomeKind('error:drive_fault')).toBe('fail');
    expect(outcomeKind('aborted')).toBe('aborted');
    expect(outcomeKind('done')).toBe('ok');
    expect(outcomeKind(null)).toBe('none');
  });

  it('filters combine', () => {
    expect(ids({ action: 'command.', target: 'y' })).toEqual([6, 4]);
    expect(ids({ action: 'command.', target: 'y', outcome: FAILURES })).toEqual([4]);
  });

  it('suggestions: action families and actions, targets, outcomes', () => {
    expect(actionSuggestions(log)).toEqual([
      'axis.',
      'axis.create',
      'command.',
      'command.final',
      'command.move-absolute',
      'command.move-velocity',
      'command.power',
      'config.',
      'config.import',
      'parameter.',
      'parameter.write',
    ]);
    expect(distinct(log, 'target')).toEqual(['config', 'spindle', 'x', 'y']);
    expect(distinct(log, 'outcome')).toEqual(['aborted', 'accepted', 'committed', 'done', 'error:drive_fault', 'rejected:control_held']);
  });
});

describe('a row', () => {
  it('who, the detail on one line, the time', () => {
    expect(who(rec(1, 'a', null, null, { principal: 'user:anna' }))).toEqual({ principal: 'user:anna', client: 'ui-abc', addr: '127.0.0.1:5000' });
    expect(detailLine(null)).toBe('');
    expect(detailLine({})).toBe('');
    expect(detailLine({ position: 100, velocity: 200 })).toBe('{"position":100,"velocity":200}');
    const long = detailLine({ text: 'x'.repeat(200) }, 40);
    expect(long.length).toBe(40);
    expect(long.endsWith('…')).toBe(true);
    expect(stamp('2026-11-25T12:00:09.042Z')).toMatch(/^2026-11-2\d \d\d:\d\d:09\.042$/);
    expect(stamp('nonsense')).toBe('nonsense');
  });
});
