// The reversing sequence's step logic (injected moves and sleeps) and the MC_Home body.
import { describe, expect, it } from 'vitest';
import { abortableSleep, initialReversing, nextStep, reversingConfig, runReversing, type ReversingConfig, type ReversingStep } from '../src/axis/reversing';
import { homeBody, HOME_DEFAULTS } from '../src/axis/bodies';

const cfg = (over: Partial<ReversingConfig> = {}): ReversingConfig => ({ position1: 10, position2: 30, velocity: 50, dwellMs: 200, repeats: 2, ...over });

function steps(c: ReversingConfig, max = 20): ReversingStep[] {
  let s = initialReversing();
  const out: ReversingStep[] = [];
  for (let i = 0; i < max; i++) {
    const n = nextStep(s, c);
    out.push(n.step);
    if (n.step.kind === 'finished') break;
    s = n.state;
  }
  return out;
}

describe('reversing sequence steps', () => {
  it('2 repeats: 1, dwell, 2, dwell, 1, dwell, 2 and finished (no dwell after the last move)', () => {
    expect(steps(cfg())).toEqual([
      { kind: 'move', position: 10, leg: 1 },
      { kind: 'dwell', ms: 200 },
      { kind: 'move', position: 30, leg: 2 },
      { kind: 'dwell', ms: 200 },
      { kind: 'move', position: 10, leg: 1 },
      { kind: 'dwell', ms: 200 },
      { kind: 'move', position: 30, leg: 2 },
      { kind: 'finished' },
    ]);
  });

  it('endless never finishes', () => {
    const s = steps(cfg({ repeats: null }), 50);
    expect(s).toHaveLength(50);
    expect(s.some((x) => x.kind === 'finished')).toBe(false);
  });

  it('counts a cycle after its second move', () => {
    let s = initialReversing();
    const counts: number[] = [];
    for (let i = 0; i < 4; i++) {
      s = nextStep(s, cfg()).state;
      counts.push(s.cycles);
    }
    expect(counts).toEqual([0, 0, 1, 1]);
  });
});

describe('runReversing', () => {
  it('runs the moves and dwells and ends with the count', async () => {
    const moves: number[] = [];
    const sleeps: number[] = [];
    const cycles: number[] = [];
    const end = await runReversing(
      cfg(),
      {
        move: async (p, v) => {
          expect(v).toBe(50);
          moves.push(p);
          return true;
        },
        sleep: async (ms) => {
          sleeps.push(ms);
        },
        onCycle: (n) => cycles.push(n),
      },
      new AbortController().signal,
    );
    expect(end).toEqual({ kind: 'finished', cycles: 2 });
    expect(moves).toEqual([10, 30, 10, 30]);
    expect(sleeps).toEqual([200, 200, 200]);
    expect(cycles).toEqual([1, 2]);
  });

  it('Stop during a move: stopped, no further move', async () => {
    const c = new AbortController();
    const moves: number[] = [];
    const end = await runReversing(
      cfg({ repeats: null }),
      {
        move: async (p) => {
          moves.push(p);
          if (moves.length === 3) {
            c.abort();
            return false; // the halt aborted the move
          }
          return true;
        },
        sleep: async () => {},
      },
      c.signal,
    );
    expect(end).toEqual({ kind: 'stopped', cycles: 1 });
    expect(moves).toEqual([10, 30, 10]);
  });

  it('Stop during a dwell ends the dwell at once', async () => {
    const c = new AbortController();
    const moves: number[] = [];
    const p = runReversing(cfg({ dwellMs: 60000 }), { move: async (x) => (moves.push(x), true), sleep: abortableSleep }, c.signal);
    await new Promise((r) => setTimeout(r, 5));
    c.abort();
    expect(await p).toEqual({ kind: 'stopped', cycles: 0 });
    expect(moves).toEqual([10]);
  });

  it('a refused or failed move ends it as failed', async () => {
    const err = new Error('refused');
    expect(await runReversing(cfg(), { move: async () => Promise.reject(err), sleep: async () => {} }, new AbortController().signal)).toEqual({ kind: 'failed', cycles: 0, error: err });
    const end = await runReversing(cfg(), { move: async (p) => p === 10, sleep: async () => {} }, new AbortController().signal);
    expect(end.kind).toBe('failed');
    expect(end.cycles).toBe(0);
  });
});

describe('reversing form', () => {
  const f = { position1: '10', position2: '30', velocity: '50', dwell: '0.5', repeats: '2', endless: false };
  it('converts seconds to ms and takes endless', () => {
    expect(reversingConfig(f).config).toEqual(cfg({ dwellMs: 500 }));
    expect(reversingConfig({ ...f, repeats: '', endless: true }).config?.repeats).toBeNull();
  });
  it('names the bad fields', () => {
    expect(reversingConfig({ ...f, position1: '', velocity: '0', dwell: '-1', repeats: '1.5' }).errors).toEqual({
      position1: 'enter a position',
      velocity: 'enter a velocity > 0',
      dwell: 'enter a time ≥ 0',
      repeats: 'enter a whole number ≥ 1',
    });
  });
});

describe('MC_Home body', () => {
  it('defaults: only the mode (the axis parameters apply)', () => {
    expect(homeBody(HOME_DEFAULTS).body).toEqual({ mode: 'default' });
  });
  it('options given are sent as HomingOptions', () => {
    const b = homeBody({ ...HOME_DEFAULTS, mode: 'direct', position: '5', search_direction: 'negative', search_velocity: '20', sync_velocity: '2', reference_mode: 'plc_cam', clear_position_lag: '1' }).body;
    expect(b).toEqual({
      mode: 'direct',
      position: 5,
      options: { reference_mode: 'plc_cam', search_direction: 'negative', search_velocity: 20, sync_velocity: 2, clear_position_lag: true },
    });
  });
});
