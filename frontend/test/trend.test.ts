// The Online tab's live trend: the fixed-size ring buffer and the series drawn from it.
import { describe, expect, it } from 'vitest';
import { TREND_CAPACITY, TREND_WINDOW_S, TrendBuffer, presentCycle, trendRange, trendSeries } from '../src/live/trend';

/** Cycle time 1 ms, updates at 50 Hz (every 20 cycles). */
const CT = 0.001;
const STEP = 0.02;
const series = (b: TrendBuffer, nowCycle: number, holdToNow = false) => trendSeries(b, { cycleTime: CT, nowCycle, step: STEP, holdToNow });

describe('ring buffer', () => {
  it('keeps at most its capacity, oldest first, overwriting the oldest', () => {
    const b = new TrendBuffer(4);
    for (let i = 1; i <= 6; i++) b.push(i * 20, i, i + 0.5, i / 100);
    expect(b.length).toBe(4);
    expect([0, 1, 2, 3].map((i) => b.at(i).cycle)).toEqual([60, 80, 100, 120]);
    expect(b.at(3)).toEqual({ cycle: 120, setVelocity: 6, actualVelocity: 6.5, followingError: 0.06, gapBefore: false });
    expect(b.lastCycle).toBe(120);
  });

  it('never grows beyond the default capacity (10 s at 50 Hz and more)', () => {
    const b = new TrendBuffer();
    for (let i = 0; i < 10 * TREND_CAPACITY; i++) b.push(i * 20, 1, 1, 0);
    expect(b.length).toBe(TREND_CAPACITY);
    expect(TREND_CAPACITY * STEP).toBeGreaterThan(TREND_WINDOW_S);
    expect(b.at(0).cycle).toBe((10 * TREND_CAPACITY - TREND_CAPACITY) * 20);
  });

  it('the same cycle replaces the newest sample; an older one (server restarted) starts afresh', () => {
    const b = new TrendBuffer(8);
    b.push(100, 1, 1, 0);
    b.push(100, 2, 2, 0);
    expect(b.length).toBe(1);
    expect(b.at(0).setVelocity).toBe(2);
    b.push(120, 3, 3, 0);
    b.push(5, 9, 9, 0);
    expect(b.length).toBe(1);
    expect(b.at(0).cycle).toBe(5);
  });

  it('a gap marks the next sample; clear empties it; version counts changes', () => {
    const b = new TrendBuffer(8);
    const v0 = b.version;
    b.gap(); // nothing recorded yet: no gap to mark
    expect(b.broken).toBe(false);
    b.push(20, 1, 1, 0);
    b.gap();
    expect(b.broken).toBe(true);
    b.push(5000, 2, 2, 0);
    expect(b.broken).toBe(false);
    expect(b.at(1).gapBefore).toBe(true);
    expect(b.version).toBeGreaterThan(v0);
    b.clear();
    expect(b.length).toBe(0);
    expect(b.lastCycle).toBeNull();
  });
});

describe('series', () => {
  it('times are seconds before the present; one sample before the window enters from the left', () => {
    const b = new TrendBuffer(1000);
    for (let c = 0; c <= 20000; c += 20) b.push(c, c / 1000, c / 1000, 0);
    const s = series(b, 20000);
    expect(s.t[s.t.length - 1]).toBe(0);
    expect(s.t[0]).toBeCloseTo(-10, 9); // cycle 10000 is exactly at the window's start
    expect(s.t[1]).toBeCloseTo(-9.98, 9);
    expect(s.samples).toBe(500); // 10 s at 50 Hz, the start not counted
    expect(s.setVelocity.length).toBe(s.t.length);
    expect(s.followingError.length).toBe(s.t.length);
    expect(s.t.every((t, i) => i === 0 || t > s.t[i - 1])).toBe(true);
  });

  it('a pause between samples is a hold (the server sends only changes), not a ramp', () => {
    const b = new TrendBuffer(8);
    b.push(1000, 0, 0, 0); // at rest …
    b.push(3000, 50, 40, 0.1); // … starts moving 2 s later
    const s = series(b, 3000);
    expect(s.t).toEqual([-2, -STEP, 0]);
    expect(s.setVelocity).toEqual([0, 0, 50]);
    expect(s.followingError).toEqual([0, 0, 0.1]);
    // consecutive 50 Hz samples: no hold point between them
    b.push(3020, 51, 41, 0.1);
    expect(series(b, 3020).t.length).toBe(4);
  });

  it('a gap (socket lost) is a break in the lines, never bridged', () => {
    const b = new TrendBuffer(8);
    b.push(1000, 5, 5, 0);
    b.gap();
    b.push(4000, 7, 7, 0);
    const s = series(b, 4000);
    expect(s.t).toEqual([-3, -1.5, 0]);
    expect(s.setVelocity).toEqual([5, null, 7]);
    expect(s.actualVelocity).toEqual([5, null, 7]);
  });

  it('while live the newest values are held on to the present; not after a gap', () => {
    const b = new TrendBuffer(8);
    b.push(1000, 3, 2, 0.01);
    let s = series(b, 6000, true);
    expect(s.t).toEqual([-5, 0]);
    expect(s.setVelocity).toEqual([3, 3]);
    expect(s.samples).toBe(1);
    b.gap();
    s = series(b, 6000, true);
    expect(s.t).toEqual([-5]);
    expect(series(b, 6000, false).t).toEqual([-5]);
  });

  it('nothing newer than the present is drawn; an empty buffer gives empty series', () => {
    const b = new TrendBuffer(8);
    expect(series(b, 100)).toEqual({ t: [], setVelocity: [], actualVelocity: [], followingError: [], samples: 0 });
    b.push(100, 1, 1, 0);
    b.push(200, 2, 2, 0);
    expect(series(b, 150).t).toEqual([-0.05]);
  });

  it('the present: the newest sample’s cycle plus the time since it arrived', () => {
    const b = new TrendBuffer(8);
    expect(presentCycle(b, 1000, CT)).toBeNull();
    b.push(5000, 0, 0, 0, 200);
    expect(presentCycle(b, 200, CT)).toBe(5000);
    expect(presentCycle(b, 450, CT)).toBe(5250);
    expect(presentCycle(b, 100, CT)).toBe(5000); // never before the sample
  });

  it('y ranges hold 0 and never collapse', () => {
    expect(trendRange(0, 0)).toEqual([-1, 1]);
    expect(trendRange(null, null)).toEqual([-1, 1]);
    const [lo, hi] = trendRange(20, 100);
    expect(lo).toBe(0);
    expect(hi).toBeGreaterThan(100);
    const [lo2, hi2] = trendRange(-0.02, 0.01);
    expect(lo2).toBeLessThan(-0.02);
    expect(hi2).toBeGreaterThan(0.01);
  });
});
