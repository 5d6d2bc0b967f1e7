// TwinCAT's "Reversing Sequence" (Functions tab): move to position 1, dwell, move to position 2,
// dwell, … a number of cycles or endless. Run by the client as MC_MoveAbsolute calls that wait
// for their end; the step logic is a small state machine with the sending and the waiting
// injected, so that it is tested without a server or a clock.

export interface ReversingConfig {
  position1: number;
  position2: number;
  velocity: number;
  /** Dwell after each move, in ms. */
  dwellMs: number;
  /** Cycles to run (one cycle = to position 1 and to position 2); null = endless. */
  repeats: number | null;
}

/** What the sequence does next. */
export type ReversingStep =
  | { kind: 'move'; position: number; leg: 1 | 2 }
  | { kind: 'dwell'; ms: number }
  | { kind: 'finished' };

export interface ReversingState {
  /** Completed cycles. */
  cycles: number;
  /** Where in the cycle: 0 move to 1, 1 dwell, 2 move to 2, 3 dwell. */
  phase: 0 | 1 | 2 | 3;
}

export const initialReversing = (): ReversingState => ({ cycles: 0, phase: 0 });

/**
 * The step at `s` and the state after it: move 1 → dwell → move 2 → (cycle counted) dwell →
 * move 1 …; no dwell after the last cycle's second move.
 */
export function nextStep(s: ReversingState, c: ReversingConfig): { step: ReversingStep; state: ReversingState } {
  if (c.repeats !== null && s.cycles >= c.repeats) return { step: { kind: 'finished' }, state: s };
  switch (s.phase) {
    case 0:
      return { step: { kind: 'move', position: c.position1, leg: 1 }, state: { cycles: s.cycles, phase: 1 } };
    case 1:
      return { step: { kind: 'dwell', ms: c.dwellMs }, state: { cycles: s.cycles, phase: 2 } };
    case 2: {
      const cycles = s.cycles + 1;
      const last = c.repeats !== null && cycles >= c.repeats;
      return { step: { kind: 'move', position: c.position2, leg: 2 }, state: { cycles, phase: last ? 0 : 3 } };
    }
    default:
      return { step: { kind: 'dwell', ms: c.dwellMs }, state: { cycles: s.cycles, phase: 0 } };
  }
}

/** Why a sequence ended. */
export type ReversingEnd = { kind: 'finished'; cycles: number } | { kind: 'stopped'; cycles: number } | { kind: 'failed'; cycles: number; error: unknown };

export interface ReversingDeps {
  /** Moves to `position` and resolves when the move has ended: true if it reached it (done). */
  move: (position: number, velocity: number) => Promise<boolean>;
  /** Waits `ms`; resolves early (or rejects) when the signal aborts. */
  sleep: (ms: number, signal: AbortSignal) => Promise<void>;
  onCycle?: (cycles: number) => void;
  onStep?: (step: ReversingStep) => void;
}

/** Runs the sequence until it has finished, is stopped (signal) or a move fails. */
export async function runReversing(c: ReversingConfig, deps: ReversingDeps, signal: AbortSignal): Promise<ReversingEnd> {
  let s = initialReversing();
  for (;;) {
    if (signal.aborted) return { kind: 'stopped', cycles: s.cycles };
    const n = nextStep(s, c);
    if (n.step.kind === 'finished') return { kind: 'finished', cycles: s.cycles };
    deps.onStep?.(n.step);
    if (n.step.kind === 'dwell') {
      await deps.sleep(n.step.ms, signal).catch(() => {});
      s = n.state;
      continue;
    }
    let ok: boolean;
    try {
      ok = await deps.move(n.step.position, c.velocity);
    } catch (error) {
      if (signal.aborted) return { kind: 'stopped', cycles: s.cycles };
      return { kind: 'failed', cycles: s.cycles, error };
    }
    if (signal.aborted) return { kind: 'stopped', cycles: s.cycles };
    if (!ok) return { kind: 'failed', cycles: s.cycles, error: new Error(`the move to ${n.step.position} did not reach its target`) };
    // A cycle counts once its second move has arrived.
    if (n.state.cycles !== s.cycles) deps.onCycle?.(n.state.cycles);
    s = n.state;
  }
}

/** A sleep that ends early when the signal aborts. */
export function abortableSleep(ms: number, signal: AbortSignal): Promise<void> {
  return new Promise((resolve) => {
    if (signal.aborted || ms <= 0) return resolve();
    const t = setTimeout(done, ms);
    function done() {
      clearTimeout(t);
      signal.removeEventListener('abort', done);
      resolve();
    }
    signal.addEventListener('abort', done);
  });
}

/** The form's inputs → a configuration, or the errors by field. */
export function reversingConfig(f: { position1: string; position2: string; velocity: string; dwell: string; repeats: string; endless: boolean }): { config: ReversingConfig | null; errors: Record<string, string> } {
  const errors: Record<string, string> = {};
  const n = (v: string) => (v.trim() === '' ? NaN : Number(v.trim().replace(',', '.')));
  const p1 = n(f.position1);
  const p2 = n(f.position2);
  const v = n(f.velocity);
  const d = f.dwell.trim() === '' ? 0 : n(f.dwell);
  const r = f.endless ? null : n(f.repeats);
  if (!Number.isFinite(p1)) errors.position1 = 'enter a position';
  if (!Number.isFinite(p2)) errors.position2 = 'enter a position';
  if (!(v > 0)) errors.velocity = 'enter a velocity > 0';
  if (!(d >= 0)) errors.dwell = 'enter a time ≥ 0';
  if (r !== null && !(Number.isInteger(r) && r >= 1)) errors.repeats = 'enter a whole number ≥ 1';
  if (Object.keys(errors).length) return { config: null, errors };
  return { config: { position1: p1, position2: p2, velocity: v, dwellMs: Math.round(d * 1000), repeats: r }, errors };
}
