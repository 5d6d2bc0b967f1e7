import { describe, expect, it } from 'vitest';
import { DeltaMerger } from '../src/live/merge';

interface S {
  a: number;
  b: number;
  c?: string;
}

describe('DeltaMerger', () => {
  it('takes the full object, then merges only the changed fields', () => {
    const m = new DeltaMerger<S>();
    expect(m.apply({ cycle: 10, full: true, data: { a: 1, b: 2 } })).toBe(true);
    expect(m.value).toEqual({ a: 1, b: 2 });
    expect(m.stale).toBe(false);
    expect(m.apply({ cycle: 12, full: false, data: { b: 3 } })).toBe(true);
    expect(m.value).toEqual({ a: 1, b: 3 });
    expect(m.cycle).toBe(12);
  });

  it('ignores deltas until the first full object', () => {
    const m = new DeltaMerger<S>();
    expect(m.apply({ cycle: 5, full: false, data: { a: 9 } })).toBe(false);
    expect(m.value).toBeNull();
    expect(m.stale).toBe(true);
    m.apply({ cycle: 6, full: true, data: { a: 1, b: 1 } });
    expect(m.value).toEqual({ a: 1, b: 1 });
  });

  it('drops an update older than the one shown (cycle ordering)', () => {
    const m = new DeltaMerger<S>();
    m.apply({ cycle: 100, full: true, data: { a: 1, b: 1 } });
    m.apply({ cycle: 120, full: false, data: { a: 2 } });
    expect(m.apply({ cycle: 110, full: false, data: { a: 7 } })).toBe(false);
    expect(m.value).toEqual({ a: 2, b: 1 });
    // the same cycle again is fine (two topics may stamp the same cycle)
    expect(m.apply({ cycle: 120, full: false, data: { b: 5 } })).toBe(true);
    expect(m.value).toEqual({ a: 2, b: 5 });
  });

  it('does not mutate the object it handed out', () => {
    const m = new DeltaMerger<S>();
    m.apply({ cycle: 1, full: true, data: { a: 1, b: 1 } });
    const before = m.value;
    m.apply({ cycle: 2, full: false, data: { a: 2 } });
    expect(before).toEqual({ a: 1, b: 1 });
    expect(m.value).not.toBe(before);
  });

  it('on resubscribe keeps the last value (stale) and waits for the next full object', () => {
    const m = new DeltaMerger<S>();
    m.apply({ cycle: 50, full: true, data: { a: 1, b: 1 } });
    m.apply({ cycle: 60, full: false, data: { a: 2 } });
    m.reset();
    expect(m.stale).toBe(true);
    expect(m.value).toEqual({ a: 2, b: 1 });
    // a delta of the old subscription still in flight is not applied
    expect(m.apply({ cycle: 61, full: false, data: { a: 3 } })).toBe(false);
    expect(m.value).toEqual({ a: 2, b: 1 });
    // a full object older than what we have is a leftover only when not awaiting one …
    expect(m.apply({ cycle: 70, full: true, data: { a: 4, b: 4, c: 'x' } })).toBe(true);
    expect(m.value).toEqual({ a: 4, b: 4, c: 'x' });
    expect(m.apply({ cycle: 65, full: true, data: { a: 0, b: 0 } })).toBe(false);
  });

  it('the full object replaces the value entirely (fields that vanished are gone)', () => {
    const m = new DeltaMerger<S>();
    m.apply({ cycle: 1, full: true, data: { a: 1, b: 1, c: 'old' } });
    m.reset();
    m.apply({ cycle: 2, full: true, data: { a: 1, b: 1 } });
    expect(m.value).toEqual({ a: 1, b: 1 });
  });

  it('after a reconnection accepts a full object with a lower cycle (server restarted)', () => {
    const m = new DeltaMerger<S>();
    m.apply({ cycle: 90000, full: true, data: { a: 1, b: 1 } });
    m.reset(true);
    expect(m.apply({ cycle: 12, full: true, data: { a: 0, b: 0 } })).toBe(true);
    expect(m.cycle).toBe(12);
    expect(m.apply({ cycle: 13, full: false, data: { a: 5 } })).toBe(true);
    expect(m.value).toEqual({ a: 5, b: 0 });
  });
});
