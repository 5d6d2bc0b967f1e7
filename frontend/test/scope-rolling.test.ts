import { describe, expect, it } from 'vitest';
import { Rolling, doneVia, donePolling } from '../src/scope/rolling';
import { Store } from '../src/store';
import type { Recording, RecordingRequest } from '../src/scope/data';

const req: RecordingRequest = { channels: [{ axis: 'x', signal: 'set_position' }], duration_s: 0.03 };
const cycle = 0.01;

function fake(starts: number[]) {
  let id = 0;
  const done = new Map<number, Recording>();
  let cancelled = 0;
  return {
    deps: {
      record: async () => {
        const k = id++;
        const start = starts[k] ?? starts.at(-1)! + k;
        const r: Recording = { id: k, state: 'done', cycle_time_s: cycle, samples: 3, channels: req.channels, start_cycle: start, data: [[k, k, k]] };
        done.set(k, r);
        return { ...r, state: 'recording' as const, data: null };
      },
      done: async (rid: number) => done.get(rid)!,
      cancel: async () => {
        cancelled++;
      },
    },
    cancelled: () => cancelled,
  };
}

describe('Rolling', () => {
  it('appends recordings until stop, with gaps where cycles were not recorded', async () => {
    const f = fake([100, 103, 110]);
    const r = new Rolling(f.deps);
    const run = r.start(req, 10);
    await new Promise<void>((res) => {
      const off = r.state.subscribe(() => {
        if (r.state.get().chunks >= 3) {
          off();
          res();
        }
      });
    });
    await r.stop();
    await run;
    const s = r.state.get();
    expect(s.active).toBe(false);
    expect(f.cancelled()).toBe(1);
    const ring = s.ring!;
    // 100..102, 103..105 back to back; 110..: after a gap of 4 cycles
    expect(ring.data[0].slice(0, 8)).toEqual([0, 0, 0, 1, 1, 1, null, 2]);
    expect(ring.gaps).toBeGreaterThanOrEqual(1);
  });

  it('a refused first request is thrown (field errors at the form)', async () => {
    const r = new Rolling({
      record: async () => {
        throw new Error('422');
      },
      done: async () => {
        throw new Error('never');
      },
      cancel: async () => {},
    });
    await expect(r.start(req, 10)).rejects.toThrow('422');
    expect(r.state.get().active).toBe(false);
  });

  it('doneVia resolves when the session shows the recording and rejects on its error', async () => {
    const st = new Store<{ running: Recording | null; shown: Recording | null; error: string | null }>({ running: null, shown: null, error: null });
    const done = doneVia(st);
    const a = new AbortController();
    const p = done(7, a.signal);
    const rec: Recording = { id: 7, state: 'done', cycle_time_s: cycle, samples: 0, channels: [] };
    st.set({ running: null, shown: rec, error: null });
    await expect(p).resolves.toBe(rec);
    const q = done(8, a.signal);
    st.set({ running: null, shown: rec, error: 'recording 8 failed' });
    await expect(q).rejects.toThrow('failed');
    st.set({ running: null, shown: rec, error: null });
    const b = new AbortController();
    const w = done(9, b.signal);
    b.abort();
    await expect(w).rejects.toThrow('stopped');
  });
});

describe('donePolling', () => {
  it('asks until the recording is done; a failed one rejects', async () => {
    const states = ['recording', 'recording', 'done'];
    let asked = 0;
    const get = async (id: number): Promise<Recording> => ({ id, state: states[Math.min(asked++, 2)] as Recording['state'], cycle_time_s: cycle, samples: 0, channels: [] });
    const r = await donePolling(get, () => 0, 1)(3, new AbortController().signal);
    expect(r.state).toBe('done');
    expect(asked).toBe(3);
    const failed = async (id: number): Promise<Recording> => ({ id, state: 'failed', reason: 'lost samples', cycle_time_s: cycle, samples: 0, channels: [] });
    await expect(donePolling(failed, () => 0, 1)(4, new AbortController().signal)).rejects.toThrow('lost samples');
  });
});
