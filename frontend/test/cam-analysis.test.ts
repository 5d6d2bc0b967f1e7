import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { LiveAnalysis, discontinuityText, errorsByRow, samplesFor, warningsByRow, type Analysis } from '../src/cams/analysis';
import { ONLINE_MODES, onlineChangeText, slavesOf } from '../src/cams/online';
import { ApiError } from '../src/api/problem';
import type { AxisLiveStatus, CamAnalysisResource, CamTableBody } from '../src/api/types';

const body = (slave: number): CamTableBody => ({ name: 'c', table_type: 'motion_function', points: [{ point_index: 1, function_type: 'polynom5', master_pos: 0, slave_pos: slave }] });
const answer = (slave: number) => ({ slave_end: slave }) as unknown as CamAnalysisResource;

/** A server whose answers the test releases, in any order. */
function server() {
  const calls: { body: CamTableBody; resolve: (r: CamAnalysisResource) => void; reject: (e: unknown) => void }[] = [];
  const send = (b: CamTableBody) => new Promise<CamAnalysisResource>((resolve, reject) => calls.push({ body: b, resolve, reject }));
  return { calls, send };
}
const flushPromises = () => new Promise((r) => setImmediate(r));

describe('live analysis', () => {
  beforeEach(() => vi.useFakeTimers({ toFake: ['setTimeout', 'clearTimeout', 'Date'] }));
  afterEach(() => vi.useRealTimers());

  it('edits are debounced into one request', async () => {
    const s = server();
    const seen: Analysis[] = [];
    const a = new LiveAnalysis(s.send, (x) => seen.push(x), undefined, { delay: 250, maxWait: 600 });
    a.schedule(body(1));
    vi.advanceTimersByTime(100);
    a.schedule(body(2));
    vi.advanceTimersByTime(100);
    a.schedule(body(3));
    expect(s.calls).toHaveLength(0);
    vi.advanceTimersByTime(250);
    expect(s.calls.map((c) => c.body.points![0].slave_pos)).toEqual([3]);
    s.calls[0].resolve(answer(3));
    await flushPromises();
    expect(seen).toEqual([{ kind: 'ok', seq: 1, result: answer(3) }]);
  });

  it('a stream of edits (a drag) is still sent every maxWait', () => {
    const s = server();
    const a = new LiveAnalysis(s.send, () => {}, undefined, { delay: 250, maxWait: 600 });
    for (let t = 0; t < 1300; t += 50) {
      a.schedule(body(t));
      vi.advanceTimersByTime(50);
    }
    expect(s.calls.length).toBeGreaterThanOrEqual(2);
  });

  it('a stale answer is dropped: only the answer to the latest request counts, whatever the order', async () => {
    const s = server();
    const seen: Analysis[] = [];
    const pend: boolean[] = [];
    const a = new LiveAnalysis(s.send, (x) => seen.push(x), (p) => pend.push(p), { delay: 10 });
    a.schedule(body(1));
    vi.advanceTimersByTime(10);
    a.schedule(body(2));
    vi.advanceTimersByTime(10);
    expect(s.calls).toHaveLength(2);
    s.calls[1].resolve(answer(2));
    await flushPromises();
    s.calls[0].resolve(answer(1));
    await flushPromises();
    expect(seen.map((x) => (x.kind === 'ok' ? x.result.slave_end : x.kind))).toEqual([2]);
    expect(a.pending).toBe(false);
    expect(pend[pend.length - 1]).toBe(false);
  });

  it('an answer that arrives while a newer edit waits (not sent yet) is shown, and pending stays until the newest is in', async () => {
    const s = server();
    const seen: Analysis[] = [];
    const a = new LiveAnalysis(s.send, (x) => seen.push(x), undefined, { delay: 10 });
    a.schedule(body(1));
    vi.advanceTimersByTime(10);
    a.schedule(body(2)); // waiting
    s.calls[0].resolve(answer(1));
    await flushPromises();
    // the first answer is the latest *sent*: it is shown, but the page still waits for the edit
    expect(seen).toHaveLength(1);
    expect(a.pending).toBe(true);
    vi.advanceTimersByTime(10);
    s.calls[1].resolve(answer(2));
    await flushPromises();
    expect(seen).toHaveLength(2);
    expect(a.pending).toBe(false);
  });

  it('a 422 is the rows at fault; another failure is an error', async () => {
    const s = server();
    const seen: Analysis[] = [];
    const a = new LiveAnalysis(s.send, (x) => seen.push(x), undefined, { delay: 0 });
    a.schedule(body(1));
    vi.advanceTimersByTime(0);
    s.calls[0].reject(new ApiError(422, { type: 't', title: 'Invalid request', status: 422, detail: 'points[1].point_type: bad', code: 'validation_failed', errors: [{ field: 'points[1].point_type', message: 'bad' }] }));
    await flushPromises();
    a.schedule(body(2));
    vi.advanceTimersByTime(0);
    s.calls[1].reject(new ApiError(0, null, 'server not reachable'));
    await flushPromises();
    expect(seen[0]).toMatchObject({ kind: 'invalid', fields: { 'points[1].point_type': 'bad' } });
    expect(seen[1]).toMatchObject({ kind: 'error', text: 'server not reachable' });
  });

  it('nothing is passed on after dispose', async () => {
    const s = server();
    const seen: Analysis[] = [];
    const a = new LiveAnalysis(s.send, (x) => seen.push(x), undefined, { delay: 0 });
    a.schedule(body(1));
    vi.advanceTimersByTime(0);
    a.dispose();
    s.calls[0].resolve(answer(1));
    await flushPromises();
    expect(seen).toEqual([]);
  });
});

describe('what the analysis says', () => {
  it('a jump names the quantity, both values, the point (from 1) and the master', () => {
    expect(discontinuityText({ index: 1, master: 100, quantity: 'velocity', before: 0, after: 1, wrap: false })).toBe('velocity jumps from 0 to 1 at point 2, master 100');
    expect(discontinuityText({ index: 2, master: 360, quantity: 'velocity', before: -0.192307692, after: 0.5, wrap: true })).toBe('velocity jumps from -0.1923 to 0.5 at the periodic wrap after point 3 (master 360)');
    // rounding noise of the server's math is 0
    expect(discontinuityText({ index: 1, master: 112.2, quantity: 'acceleration', before: 3.5e-15, after: 0.61, wrap: false }, 'row')).toBe('acceleration jumps from 0 to 0.61 at row 2, master 112.2');
  });
  it('warnings and errors by row', () => {
    const w = warningsByRow([
      { index: 1, master: 100, quantity: 'velocity', before: 0, after: 1, wrap: false },
      { index: 1, master: 100, quantity: 'acceleration', before: 0, after: 1, wrap: false },
    ]);
    expect(w.get(1)?.map((d) => d.quantity)).toEqual(['velocity', 'acceleration']);
    const e = errorsByRow({ 'points[0].point_type': 'not IGNORE', 'rows[2][0]': 'must rise', points: 'at least 2', name: 'bad' });
    expect(e.rows.get(0)).toEqual(['point_type: not IGNORE']);
    expect(e.rows.get(2)).toEqual(['master: must rise']);
    expect(e.table).toEqual(['points: at least 2', 'name: bad']);
  });
  it('samples: 721, more for a long position table', () => {
    expect(samplesFor(body(1))).toBe(721);
    expect(samplesFor({ name: 'p', table_type: 'non_equidistant', rows: Array.from({ length: 1000 }, (_, i) => [i, 0]) })).toBe(4001);
  });
});

describe('online change', () => {
  const status = (cam: Partial<AxisLiveStatus['cam']>, extra: Partial<AxisLiveStatus> = {}) =>
    ({ status: { master: 'x', cam_data_queued: false, cam: { active: true, cam_table_id: 0, cams: [], ...cam }, ...extra } as unknown as AxisLiveStatus | null });
  it('the slaves of a table are the axes whose active coupling runs on it (multi-cam too)', () => {
    const m = new Map([
      ['y', status({ cam_table_id: 3 }, { cam_data_queued: true })],
      ['z', status({ cam_table_id: 1, cams: [{ cam_table_id: 1 }, { cam_table_id: 3 }] as never })],
      ['w', status({ cam_table_id: 3, active: false })],
      ['v', status({ cam_table_id: 4 })],
      ['u', { status: null }],
    ]);
    expect(slavesOf(m, 3)).toEqual([
      { axis: 'y', master: 'x', queued: true },
      { axis: 'z', master: 'x', queued: false },
    ]);
  });
  it('says before a save whom it reaches and by which mode', () => {
    const text = onlineChangeText([{ axis: 'y', master: 'x', queued: false }], { activation_mode: 'at_master_axis_pos', activation_position: 50, master_scaling_mode: 'user_defined', slave_scaling_mode: 'auto_offset' });
    expect(text).toBe(
      'This table is coupled: saving is an online change. It reaches y (master x) by the mode at_master_axis_pos (activation position 50): from the master axis at the activation position, in the first cycle where the new data does not move it; the slave offset follows (auto_offset).',
    );
    expect(onlineChangeText([{ axis: 'y', master: 'x', queued: false }, { axis: 'z', master: 'x', queued: false }], { activation_mode: 'off' })).toMatch(/reaches y \(master x\) and z \(master x\) by the mode off: never/);
    expect(ONLINE_MODES).not.toContain('delete_queued_data');
  });
});
