import { describe, expect, it } from 'vitest';
import { HISTORY_LIMIT, canRedo, canUndo, historyKey, historyOf, record, redo, settle, undo } from '../src/cams/history';

describe('cam editor history', () => {
  it('undo and redo walk through whole states; a change after an undo drops the redo', () => {
    let h = historyOf({ v: 1 });
    h = record(h, { v: 2 });
    h = record(h, { v: 3 });
    expect(canUndo(h)).toBe(true);
    expect(canRedo(h)).toBe(false);
    h = undo(h);
    expect(h.present).toEqual({ v: 2 });
    h = undo(h);
    expect(h.present).toEqual({ v: 1 });
    expect(canUndo(h)).toBe(false);
    expect(undo(h)).toBe(h);
    h = redo(h);
    expect(h.present).toEqual({ v: 2 });
    h = record(h, { v: 9 });
    expect(canRedo(h)).toBe(false);
    expect(undo(h).present).toEqual({ v: 2 });
  });

  it('a change that leaves the state as it was is no step', () => {
    const h = record(historyOf({ v: 1 }), { v: 2 });
    expect(record(h, { v: 2 })).toBe(h);
  });

  it('one drag (one key) is one step, however many moves; the next drag is another', () => {
    let h = historyOf({ x: 0 });
    for (let i = 1; i <= 50; i++) h = record(h, { x: i }, 'drag-1');
    h = settle(h);
    h = record(h, { x: 70 }, 'drag-2');
    h = record(h, { x: 80 }, 'drag-2');
    expect(h.past).toHaveLength(2);
    h = undo(h);
    expect(h.present).toEqual({ x: 50 });
    h = undo(h);
    expect(h.present).toEqual({ x: 0 });
    expect(redo(redo(h)).present).toEqual({ x: 80 });
  });

  it('typing into one field is one step until the field is left (settle)', () => {
    let h = historyOf({ s: '' });
    h = record(h, { s: '1' }, 'slave_pos-1');
    h = record(h, { s: '12' }, 'slave_pos-1');
    h = record(h, { s: '120' }, 'slave_pos-1');
    expect(h.past).toHaveLength(1);
    h = settle(h);
    h = record(h, { s: '1200' }, 'slave_pos-1');
    expect(h.past).toHaveLength(2);
    expect(undo(h).present).toEqual({ s: '120' });
  });

  it('a gesture that ends where it started leaves no step', () => {
    let h = record(historyOf({ x: 0 }), { x: 5 });
    h = record(h, { x: 6 }, 'drag-1');
    h = record(h, { x: 5 }, 'drag-1');
    expect(h.present).toEqual({ x: 5 });
    expect(h.past).toHaveLength(1);
    expect(undo(h).present).toEqual({ x: 0 });
  });

  it('keeps at most the limit of steps, dropping the oldest', () => {
    let h = historyOf(0);
    for (let i = 1; i <= HISTORY_LIMIT + 5; i++) h = record(h, i);
    expect(h.past).toHaveLength(HISTORY_LIMIT);
    expect(h.past[0]).toBe(5);
  });

  it('Ctrl+Z undoes, Ctrl+Shift+Z and Ctrl+Y redo (⌘ too); Alt or no modifier is nothing', () => {
    const k = (key: string, m: Partial<{ ctrlKey: boolean; metaKey: boolean; shiftKey: boolean; altKey: boolean }>) => historyKey({ key, ctrlKey: false, metaKey: false, shiftKey: false, altKey: false, ...m });
    expect(k('z', { ctrlKey: true })).toBe('undo');
    expect(k('Z', { ctrlKey: true, shiftKey: true })).toBe('redo');
    expect(k('y', { ctrlKey: true })).toBe('redo');
    expect(k('z', { metaKey: true })).toBe('undo');
    expect(k('z', {})).toBeNull();
    expect(k('z', { ctrlKey: true, altKey: true })).toBeNull();
    expect(k('x', { ctrlKey: true })).toBeNull();
  });
});
