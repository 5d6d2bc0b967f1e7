// The path preview's geometry (groups/geometry.ts) against the kernel's reading of the manual:
// lines, the three circle modes, the four path choices (backend/motion/src/path/arc.rs).
import { describe, expect, it } from 'vitest';
import { arcGeometry, lineLength, preview, sampleArc, type PathChoiceName, type Vec3 } from '../src/groups/geometry';

const P = (x: number, y: number, z = 0) => [x, y, z, 0, 0, 0, 0, 0, 0, 0, 0, 0];
const close = (a: number, b: number, eps = 1e-9) => expect(Math.abs(a - b)).toBeLessThan(eps);
const DEG = Math.PI / 180;

describe('lines', () => {
  it('is the Cartesian distance; a move of C only counts its travel', () => {
    close(lineLength(P(0, 0), P(30, 40)), 50);
    close(lineLength(P(1, 2, 3), P(1, 2, 3 + 7)), 7);
    const c = P(5, 5);
    c[3] = 90;
    close(lineLength(P(5, 5), c), 90);
  });
});

describe('arcs: center mode (spec §8.3)', () => {
  it('centre (200,−100) from (200,0) to (300,−100) counter-clockwise is the 90° arc of length 157.08', () => {
    const g = arcGeometry('center', P(200, 0), [200, -100, 0], P(300, -100), 'counter_clockwise', false);
    close(g.sweep, 90 * DEG);
    close(g.length, 157.07963267948966);
    expect(g.normal.map((x) => x + 0)).toEqual([0, 0, -1]);
    // the quarter arc passes the 45° point towards +X, +Y of the centre
    const mid = sampleArc(g, P(200, 0), P(300, -100), 2)[1];
    const h = 100 / Math.SQRT2;
    close(mid[0], 200 + h);
    close(mid[1], -100 + h);
  });
  it('short_segment is the same arc; clockwise and long_segment the 270° arc the other way round', () => {
    const s = arcGeometry('center', P(200, 0), [200, -100, 0], P(300, -100), 'short_segment', false);
    close(s.sweep, 90 * DEG);
    for (const c of ['clockwise', 'long_segment'] as PathChoiceName[]) {
      const g = arcGeometry('center', P(200, 0), [200, -100, 0], P(300, -100), c, false);
      close(g.sweep, 270 * DEG);
      close(g.length, 100 * 270 * DEG);
      const mid = sampleArc(g, P(200, 0), P(300, -100), 2)[1];
      // halfway round the long way: at 135° from the start, i.e. towards −X, −Y of the centre
      close(mid[0], 200 - 100 / Math.SQRT2);
      close(mid[1], -100 - 100 / Math.SQRT2);
    }
  });
  it('refuses a half circle, a full circle and a centre off the bisector', () => {
    expect(() => arcGeometry('center', P(0, 0), [50, 0, 0], P(100, 0), 'counter_clockwise', true)).toThrow(/half circle/);
    expect(() => arcGeometry('center', P(0, 0), [50, 0, 0], P(0, 0), 'counter_clockwise', true)).toThrow(/full circle/);
    expect(() => arcGeometry('center', P(0, 0), [0, 10, 0], P(20, 0), 'counter_clockwise', true)).toThrow(/different distances/);
  });
});

describe('arcs: border mode', () => {
  it('runs start → aux → end on the circumcircle, whatever the path choice', () => {
    // (100,0) → (0,100) → (−100,0): the upper half circle about the origin, 180°
    const g = arcGeometry('border', P(100, 0), [0, 100, 0], P(-100, 0), 'clockwise', true);
    close(g.radius, 100);
    close(g.sweep, 180 * DEG);
    const mid = sampleArc(g, P(100, 0), P(-100, 0), 2)[1];
    close(mid[0], 0, 1e-9);
    close(mid[1], 100);
    // via (0,−100): the lower half
    const h = arcGeometry('border', P(100, 0), [0, -100, 0], P(-100, 0), 'counter_clockwise', true);
    close(sampleArc(h, P(100, 0), P(-100, 0), 2)[1][1], -100);
    // via (−100,0) to (0,−100): three quarters, 270°
    const t = arcGeometry('border', P(100, 0), [-100, 0, 0], P(0, -100), 'counter_clockwise', true);
    close(t.sweep, 270 * DEG);
  });
  it('refuses collinear points', () => {
    expect(() => arcGeometry('border', P(0, 0), [50, 0, 0], P(100, 0), 'counter_clockwise', true)).toThrow(/one line/);
  });
});

describe('arcs: radius mode, the four path choices', () => {
  // From (0,0) to (100,0), radius 100, normal +Z: chord 100, the centres at (50, ±86.6).
  const S = P(0, 0);
  const E = P(100, 0);
  const N: Vec3 = [0, 0, 100];
  const h = Math.sqrt(100 * 100 - 50 * 50);
  const arc = (c: PathChoiceName, n: Vec3 = N) => arcGeometry('radius', S, n, E, c, true);
  it('counter_clockwise and short_segment: the 60° arc positive about the normal (centre above the chord)', () => {
    for (const c of ['counter_clockwise', 'short_segment'] as PathChoiceName[]) {
      const g = arc(c);
      close(g.sweep, 60 * DEG);
      close(g.centre[0], 50);
      close(g.centre[1], h);
      close(g.normal[2], 1);
      // turning positively about +Z from (0,0) with the centre above: the arc dips below the chord
      expect(sampleArc(g, S, E, 2)[1][1]).toBeLessThan(0);
    }
  });
  it('clockwise: the same circle, the other way round (300°, negative about the normal)', () => {
    const g = arc('clockwise');
    close(g.sweep, 300 * DEG);
    close(g.centre[1], h);
    close(g.normal[2], -1);
    close(sampleArc(g, S, E, 2)[1][1], h + 100);
  });
  it('long_segment: positive about the normal round the other centre (300°)', () => {
    const g = arc('long_segment');
    close(g.sweep, 300 * DEG);
    close(g.centre[1], -h);
    close(g.normal[2], 1);
    close(sampleArc(g, S, E, 2)[1][1], -h - 100);
  });
  it('a flipped normal gives the short arc turning the other way; too small a radius is refused', () => {
    const g = arc('counter_clockwise', [0, 0, -100]);
    close(g.sweep, 60 * DEG);
    expect(sampleArc(g, S, E, 2)[1][1]).toBeGreaterThan(0);
    expect(() => arc('counter_clockwise', [0, 0, 40])).toThrow(/less than half/);
    expect(() => arc('counter_clockwise', [0, 100, 0])).toThrow(/XY plane/);
  });
});

describe('the preview of a table', () => {
  it('chains the entries from the start, samples arcs, marks blended corners, skips blockers and dwells', () => {
    const pv = preview(
      [
        { type: 'linear', position: [200, 0] },
        { type: 'circular', circ_mode: 'center', aux_point: [200, -100, 0], end_point: [300, -100], path_choice: 'counter_clockwise' },
        { type: 'dwell' },
        { type: 'linear', position: [300, -300], corner: [5, 5] },
      ],
      P(0, 0),
      [0, 1],
      true,
    );
    expect(pv.segments.map((s) => s.kind)).toEqual(['linear', 'circular', 'linear']);
    expect(pv.segments.map((s) => s.entry)).toEqual([0, 1, 3]);
    close(pv.length, 200 + 157.07963267948966 + 200);
    const arcPts = pv.segments[1].points;
    expect(arcPts.length).toBeGreaterThan(8);
    for (const p of arcPts) close(Math.hypot(p[0] - 200, p[1] + 100), 100, 1e-9);
    expect(pv.corners).toEqual([{ entry: 3, at: P(300, -100), rIn: 5, rOut: 5 }]);
    expect(pv.points.map((p) => p.entry)).toEqual([-1, 0, 1, 3]);
    expect(pv.errors).toEqual([]);
  });
  it('places the axis order by role (XYZ convention: dims 0, 1, 2) and says which row cannot be drawn', () => {
    const pv = preview(
      [
        { type: 'linear', position: [1, 2, 3] },
        { type: 'circular', circ_mode: 'center', aux_point: [1, 2, 3], end_point: [1, 2, 3], path_choice: 'clockwise' },
        { type: 'linear', position: [1, 2] },
      ],
      P(0, 0, 0),
      [0, 1, 2],
      false,
    );
    expect(pv.segments[0].points[1].slice(0, 3)).toEqual([1, 2, 3]);
    expect(pv.errors.map((e) => e.entry)).toEqual([1, 2]);
    expect(pv.errors[0].text).toMatch(/full circle/);
  });
});
