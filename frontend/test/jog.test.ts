import { afterEach, beforeEach, describe, expect, it, vi } from 'vitest';
import { DEADMAN_S, JogController, KEEPALIVE_MS } from '../src/live/jog';

/** Transport double: records calls; the test resolves or rejects them. */
class FakeTransport {
  calls: { method: string; params: any; resolve: (v: any) => void; reject: (e: Error) => void }[] = [];
  call<R>(method: string, params: Record<string, unknown>): Promise<R> {
    return new Promise<R>((resolve, reject) => this.calls.push({ method, params, resolve, reject }));
  }
  of(method: string) {
    return this.calls.filter((c) => c.method === method);
  }
}

const flush = () => vi.advanceTimersByTimeAsync(0);

beforeEach(() => vi.useFakeTimers());
afterEach(() => vi.useRealTimers());

async function held(t: FakeTransport, j: JogController, id = 41) {
  j.press('x', 'forward', 'standard_slow');
  t.of('jog')[0].resolve({ id, final: false, state: 'active' });
  await flush();
}

describe('JogController', () => {
  it('press sends a jog with the dead-man timeout over the transport', () => {
    const t = new FakeTransport();
    const j = new JogController(t);
    j.press('x', 'backward', 'standard_fast');
    expect(t.calls[0]).toMatchObject({ method: 'jog', params: { axis: 'x', direction: 'backward', mode: 'standard_fast', deadman_timeout: DEADMAN_S } });
    expect(j.snapshot().phase).toBe('starting');
  });

  it('renews the dead-man every KEEPALIVE_MS while held', async () => {
    const t = new FakeTransport();
    const j = new JogController(t);
    await held(t, j);
    expect(j.snapshot()).toMatchObject({ phase: 'held', command: 41 });
    expect(t.of('keepalive').length).toBe(0);
    await vi.advanceTimersByTimeAsync(KEEPALIVE_MS * 4);
    expect(t.of('keepalive').length).toBe(4);
    expect(t.of('keepalive')[0].params).toEqual({ command: 41 });
    // renewal is well inside the dead-man
    expect(KEEPALIVE_MS * 3).toBeLessThan(DEADMAN_S * 1000);
  });

  it('no keepalive is sent before the server named the command', async () => {
    const t = new FakeTransport();
    const j = new JogController(t);
    j.press('x', 'forward', 'standard_slow');
    await vi.advanceTimersByTimeAsync(KEEPALIVE_MS * 3);
    expect(t.of('keepalive').length).toBe(0);
  });

  it('release sends release and stops renewing', async () => {
    const t = new FakeTransport();
    const j = new JogController(t);
    await held(t, j);
    await vi.advanceTimersByTimeAsync(KEEPALIVE_MS);
    j.release('button released');
    expect(t.of('release').map((c) => c.params)).toEqual([{ command: 41 }]);
    const n = t.of('keepalive').length;
    await vi.advanceTimersByTimeAsync(KEEPALIVE_MS * 10);
    expect(t.of('keepalive').length).toBe(n);
    expect(j.snapshot()).toMatchObject({ phase: 'idle', lastEnd: 'button released' });
  });

  it('a release before the jog was answered releases it as soon as the answer arrives', async () => {
    const t = new FakeTransport();
    const j = new JogController(t);
    j.press('x', 'forward', 'standard_slow');
    j.release('pointer left the button');
    expect(j.snapshot().phase).toBe('idle');
    expect(t.of('release').length).toBe(0);
    t.of('jog')[0].resolve({ id: 77, final: false });
    await flush();
    expect(t.of('release').map((c) => c.params)).toEqual([{ command: 77 }]);
    await vi.advanceTimersByTimeAsync(KEEPALIVE_MS * 5);
    expect(t.of('keepalive').length).toBe(0);
  });

  it('every stop path ends the hold exactly once', async () => {
    for (const path of ['button released', 'pointer left the button', 'pointer cancelled', 'window lost focus', 'page hidden']) {
      const t = new FakeTransport();
      const j = new JogController(t);
      await held(t, j);
      j.release(path);
      j.release(path); // a second event of the same gesture changes nothing
      expect(t.of('release').length).toBe(1);
      expect(j.snapshot().lastEnd).toBe(path);
    }
  });

  it('socket loss stops renewing without a release (the server releases the socket’s jogs)', async () => {
    const t = new FakeTransport();
    const j = new JogController(t);
    await held(t, j);
    j.connectionLost();
    await vi.advanceTimersByTimeAsync(KEEPALIVE_MS * 5);
    expect(t.of('keepalive').length).toBe(0);
    expect(t.of('release').length).toBe(0);
    expect(j.snapshot()).toMatchObject({ phase: 'idle' });
    expect(j.snapshot().lastEnd).toMatch(/connection lost/);
  });

  it('a refused keepalive (dead-man fired, command final) ends the hold', async () => {
    const t = new FakeTransport();
    const j = new JogController(t);
    await held(t, j);
    await vi.advanceTimersByTimeAsync(KEEPALIVE_MS);
    t.of('keepalive')[0].reject(new Error('unknown or finished command'));
    await flush();
    expect(j.snapshot().phase).toBe('idle');
    const n = t.of('keepalive').length;
    await vi.advanceTimersByTimeAsync(KEEPALIVE_MS * 5);
    expect(t.of('keepalive').length).toBe(n);
  });

  it('the command turning final (commands topic) ends the hold', async () => {
    const t = new FakeTransport();
    const j = new JogController(t);
    await held(t, j, 9);
    j.commandFinal(8, 'done'); // someone else's command: nothing happens
    expect(j.snapshot().phase).toBe('held');
    j.commandFinal(9, 'aborted');
    expect(j.snapshot()).toMatchObject({ phase: 'idle', lastEnd: 'jog aborted' });
    await vi.advanceTimersByTimeAsync(KEEPALIVE_MS * 3);
    expect(t.of('keepalive').length).toBe(0);
  });

  it('a rejected jog shows the error and keeps nothing running', async () => {
    const t = new FakeTransport();
    const j = new JogController(t);
    j.press('x', 'forward', 'standard_slow');
    t.of('jog')[0].reject(new Error('axis cannot be started in its current state'));
    await flush();
    expect(j.snapshot()).toMatchObject({ phase: 'idle', error: 'axis cannot be started in its current state' });
    await vi.advanceTimersByTimeAsync(KEEPALIVE_MS * 3);
    expect(t.of('keepalive').length).toBe(0);
  });

  it('reports started and refused jogs for the command log, with the error number', async () => {
    const t = new FakeTransport();
    const started: unknown[] = [];
    const rejected: unknown[][] = [];
    const j = new JogController(t, { started: (r) => started.push(r), rejected: (...a) => rejected.push(a) });
    j.press('x', 'forward', 'standard_slow');
    t.of('jog')[0].resolve({ id: 5, final: false });
    await flush();
    expect(started).toEqual([{ id: 5, final: false }]);
    j.release('button released');
    j.press('x', 'forward', 'standard_fast');
    const e = Object.assign(new Error('feed enable for this direction missing'), { problem: { error_id: 0x7020 } });
    t.of('jog')[1].reject(e);
    await flush();
    expect(rejected).toEqual([['x', { direction: 'forward', mode: 'standard_fast', deadman_timeout: DEADMAN_S }, e]]);
    expect(j.snapshot().error).toBe('feed enable for this direction missing (0x7020)');
  });

  it('pressing another button releases the first jog', async () => {
    const t = new FakeTransport();
    const j = new JogController(t);
    await held(t, j, 1);
    j.press('x', 'backward', 'standard_fast');
    expect(t.of('release').map((c) => c.params)).toEqual([{ command: 1 }]);
    expect(j.snapshot()).toMatchObject({ phase: 'starting', direction: 'backward' });
  });
});
