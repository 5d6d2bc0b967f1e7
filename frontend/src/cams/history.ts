// Undo/redo of the cam editor: a history of whole table states (pure, immutable values, so a
// page keeps it in its state). Changes that carry the same gesture key one after the other are
// one step: the keystrokes typed into one field, the moves of one drag. A change that leaves
// the state as it was is no step.

export interface History<T> {
  /** Older states, the oldest first. */
  readonly past: readonly T[];
  readonly present: T;
  /** States undone, the next to redo first. */
  readonly future: readonly T[];
  /** The gesture of the last change (null after undo, redo or a change without a key). */
  readonly key: string | null;
}

/** Steps kept at most (the oldest are dropped). */
export const HISTORY_LIMIT = 200;

export function historyOf<T>(present: T): History<T> {
  return { past: [], present, future: [], key: null };
}

const same = <T,>(a: T, b: T) => a === b || JSON.stringify(a) === JSON.stringify(b);

/**
 * The history after a change to `next`. With the `key` of the change before it (the same
 * field typed into, the same drag), it replaces that step instead of adding one; a change
 * after an undo drops what could be redone.
 */
export function record<T>(h: History<T>, next: T, key: string | null = null, limit = HISTORY_LIMIT): History<T> {
  if (key !== null && key === h.key) {
    // The same gesture goes on: back where it started means no step at all.
    const start = h.past[h.past.length - 1];
    if (start !== undefined && same(start, next)) return { past: h.past.slice(0, -1), present: start, future: [], key: null };
    return { past: h.past, present: next, future: [], key };
  }
  if (same(h.present, next)) return h;
  const past = [...h.past, h.present];
  return { past: past.length > limit ? past.slice(past.length - limit) : past, present: next, future: [], key };
}

/** Ends the gesture in course: the next change is a step of its own even with the same key. */
export function settle<T>(h: History<T>): History<T> {
  return h.key === null ? h : { ...h, key: null };
}

export const canUndo = <T,>(h: History<T>) => h.past.length > 0;
export const canRedo = <T,>(h: History<T>) => h.future.length > 0;

export function undo<T>(h: History<T>): History<T> {
  if (!canUndo(h)) return h;
  return { past: h.past.slice(0, -1), present: h.past[h.past.length - 1], future: [h.present, ...h.future], key: null };
}

export function redo<T>(h: History<T>): History<T> {
  if (!canRedo(h)) return h;
  return { past: [...h.past, h.present], present: h.future[0], future: h.future.slice(1), key: null };
}

/** The keyboard's undo and redo: Ctrl+Z, Ctrl+Shift+Z and Ctrl+Y (⌘ on a Mac). */
export function historyKey(e: { key: string; ctrlKey: boolean; metaKey: boolean; shiftKey: boolean; altKey: boolean }): 'undo' | 'redo' | null {
  if (!(e.ctrlKey || e.metaKey) || e.altKey) return null;
  const k = e.key.toLowerCase();
  if (k === 'z') return e.shiftKey ? 'redo' : 'undo';
  if (k === 'y' && !e.shiftKey) return 'redo';
  return null;
}
