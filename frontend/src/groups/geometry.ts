// The path preview's geometry, computed in the browser from the editor's rows: straight lines and
// arcs by the three MC_CIRC_MODEs and the four MC_CIRC_PATHCHOICEs, exactly as the kernel reads
// them (backend/motion/src/path/arc.rs and the `path` module's documentation: Border = the
// circumcircle run S → A → E; Center = n = (S−C)×(E−C), CounterClockwise / ShortSegment the short
// arc positive about n, Clockwise / LongSegment the long arc positive about −n; Radius = A is the
// normal, |A| the radius, CounterClockwise / ShortSegment the short arc positive about A,
// Clockwise the long arc of the same circle negative about A, LongSegment the long arc positive
// about A round the other centre). Blends are not drawn: a corner with a transition is marked by
// its tolerance circle. A preview only — the server checks and plans the real path.
//
// Points are path points in the kernel's layout: [X, Y, Z, C, ADDAX1..8] (12 numbers). No UI
// code, no global state.

export type Vec3 = [number, number, number];
export type CircModeName = 'border' | 'center' | 'radius';
export type PathChoiceName = 'clockwise' | 'counter_clockwise' | 'short_segment' | 'long_segment';

/** Dimensions of a path point: X, Y, Z, C, ADDAX1..8. */
export const PATH_DIMS = 12;
export type PathPoint = number[];

const sub = (a: Vec3, b: Vec3): Vec3 => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const add = (a: Vec3, b: Vec3): Vec3 => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const scale = (a: Vec3, k: number): Vec3 => [a[0] * k, a[1] * k, a[2] * k];
const dot = (a: Vec3, b: Vec3) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a: Vec3, b: Vec3): Vec3 => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const norm = (a: Vec3) => Math.hypot(a[0], a[1], a[2]);
const unit = (a: Vec3): Vec3 => scale(a, 1 / norm(a));
const cart = (p: PathPoint): Vec3 => [p[0] ?? 0, p[1] ?? 0, p[2] ?? 0];

/** The kernel's geometric tolerance for a figure of size `s` (path/mod.rs: 1e-6 relative + 1e-9). */
export const tolerance = (s: number) => 1e-6 * Math.abs(s) + 1e-9;

/** Why an arc cannot be drawn (the kernel's GeometryError, in its words). */
export class GeometryError extends Error {}

export interface ArcGeometry {
  centre: Vec3;
  radius: number;
  /** Unit vector centre → start. */
  u: Vec3;
  /** normal × u: the direction of travel at the start. */
  v: Vec3;
  /** The arc turns positively (right-hand) about this unit vector. */
  normal: Vec3;
  /** Swept angle, (0, 2π). */
  sweep: number;
  length: number;
}

function borderCircle(s: Vec3, a: Vec3, e: Vec3): [Vec3, Vec3] {
  const sa = sub(a, s);
  const se = sub(e, s);
  const ae = sub(e, a);
  const longest = Math.max(norm(sa), norm(se), norm(ae));
  const tol = tolerance(longest);
  if (norm(se) <= tol) throw new GeometryError('CircMode Border: start and end coincide; a full circle cannot be programmed');
  const n = cross(sa, se);
  if (norm(sa) <= tol || norm(ae) <= tol || norm(n) / longest <= tol) {
    throw new GeometryError('CircMode Border: start, AuxPoint and end lie on one line or two of them coincide');
  }
  const nn = dot(n, n);
  const toCentre = scale(cross(sub(scale(se, dot(sa, sa)), scale(sa, dot(se, se))), n), 0.5 / nn);
  return [add(s, toCentre), unit(n)];
}

function centerCircle(s: Vec3, c: Vec3, e: Vec3, choice: PathChoiceName): [Vec3, Vec3] {
  const tol = tolerance(Math.max(norm(sub(s, c)), norm(sub(e, c))));
  const se = sub(e, s);
  const chord = norm(se);
  if (chord <= tol) throw new GeometryError('CircMode Center: start and end coincide; a full circle cannot be programmed');
  const along = scale(se, 1 / chord);
  const middle = scale(add(s, e), 0.5);
  const off = dot(sub(c, middle), along);
  if (Math.abs(off) > tol) throw new GeometryError('CircMode Center: start and end are at different distances from the centre');
  const centre = sub(c, scale(along, off));
  const n = cross(sub(s, centre), sub(e, centre));
  if (norm(n) / chord <= tol) throw new GeometryError('CircMode Center: start, centre and end lie on one line; a half circle has no defined plane');
  const nu = unit(n);
  return [centre, choice === 'counter_clockwise' || choice === 'short_segment' ? nu : scale(nu, -1)];
}

function radiusCircle(s: Vec3, aux: Vec3, e0: Vec3, choice: PathChoiceName): [Vec3, Vec3] {
  const r = norm(aux);
  const n = scale(aux, 1 / r);
  const tol = tolerance(r);
  const offPlane = dot(sub(e0, s), n);
  if (Math.abs(offPlane) > tol) throw new GeometryError("CircMode Radius: the end point is not in the circle's plane (no helix)");
  const e = sub(e0, scale(n, offPlane));
  const se = sub(e, s);
  const chord = norm(se);
  if (chord <= tol) throw new GeometryError('CircMode Radius: start and end coincide; a full circle cannot be programmed');
  if (r < chord / 2 - tol) throw new GeometryError('CircMode Radius: the radius is less than half the distance from start to end');
  const half = Math.sqrt(Math.max(0, r * r - (chord * chord) / 4));
  const middle = scale(add(s, e), 0.5);
  const side = cross(n, scale(se, 1 / chord));
  const shortSide = add(middle, scale(side, half));
  switch (choice) {
    case 'counter_clockwise':
    case 'short_segment':
      return [shortSide, n];
    case 'clockwise':
      return [shortSide, scale(n, -1)];
    case 'long_segment':
      return [sub(middle, scale(side, half)), n];
  }
}

/**
 * The arc from `start` to `end` (path points) with the AuxPoint `aux` (X, Y, Z). `planar`: the
 * group is XY, so the arc must lie in the XY plane at the start's height (as the kernel checks).
 * Throws GeometryError with the kernel's reason.
 */
export function arcGeometry(mode: CircModeName, start: PathPoint, aux: Vec3, end: PathPoint, choice: PathChoiceName, planar: boolean): ArcGeometry {
  const s = cart(start);
  const e = cart(end);
  let a: Vec3 = [...aux];
  if (![...s, ...e, ...a].every(Number.isFinite)) throw new GeometryError('a position or AuxPoint coordinate is not a finite number');
  if (mode === 'radius' && norm(a) <= 0) throw new GeometryError('CircMode Radius: the normal vector is zero, so radius and plane are undefined');
  if (planar) {
    const size = mode === 'radius' ? norm(a) : Math.max(norm(sub(a, s)), norm(sub(e, s)));
    const tol = tolerance(size);
    const outside = 'the group is planar (XY) but the arc is not in the XY plane';
    if (Math.abs(e[2] - s[2]) > tol) throw new GeometryError(outside);
    e[2] = s[2];
    if (mode === 'radius') {
      if (Math.hypot(a[0], a[1]) > tol) throw new GeometryError(outside);
      a = [0, 0, Math.sign(a[2] || 1) * norm(a)];
    } else {
      if (Math.abs(a[2] - s[2]) > tol) throw new GeometryError(outside);
      a[2] = s[2];
    }
  }
  const [centre, n0] = mode === 'border' ? borderCircle(s, a, e) : mode === 'center' ? centerCircle(s, a, e, choice) : radiusCircle(s, a, e, choice);
  const rel = sub(s, centre);
  const radius = norm(rel);
  const u = scale(rel, 1 / radius);
  const normal = unit(sub(n0, scale(u, dot(n0, u))));
  const v = cross(normal, u);
  const toEnd = sub(e, centre);
  let sweep = Math.atan2(dot(toEnd, v), dot(toEnd, u));
  if (sweep <= 0) sweep += 2 * Math.PI;
  return { centre, radius, u, v, normal, sweep, length: radius * sweep };
}

/**
 * `n` + 1 points of the arc from `start` to `end` (both exactly), X, Y, Z on the circle, C and
 * the additional axes in proportion to the path length (as the kernel moves them).
 */
export function sampleArc(g: ArcGeometry, start: PathPoint, end: PathPoint, n: number): PathPoint[] {
  const out: PathPoint[] = [];
  for (let k = 0; k <= n; k++) {
    const t = k / n;
    if (k === 0) out.push([...start]);
    else if (k === n) out.push([...end]);
    else {
      const th = t * g.sweep;
      const c = Math.cos(th);
      const sn = Math.sin(th);
      const p = start.map((x, i) => x + ((end[i] ?? x) - x) * t);
      for (let i = 0; i < 3; i++) p[i] = g.centre[i] + g.radius * (c * g.u[i] + sn * g.v[i]);
      out.push(p);
    }
  }
  return out;
}

/** Cartesian length of a line; a C / additional-axis only move counts its largest extra travel (path/mod.rs). */
export function lineLength(start: PathPoint, end: PathPoint): number {
  const l = norm(sub(cart(end), cart(start)));
  if (l >= 1e-9) return l;
  let m = 0;
  for (let i = 3; i < Math.max(start.length, end.length); i++) m = Math.max(m, Math.abs((end[i] ?? 0) - (start[i] ?? 0)));
  return m;
}

// ---- a table of entries → what the preview draws ------------------------------------------

/** One entry of a path as the preview needs it (the JSON of the row, parsed). */
export type PreviewEntry =
  | { type: 'linear'; position: number[]; corner?: [number, number] }
  | { type: 'circular'; circ_mode: CircModeName; aux_point: Vec3; end_point: number[]; path_choice: PathChoiceName; corner?: [number, number] }
  | { type: 'blocker' }
  | { type: 'dwell' };

export interface PreviewSegment {
  /** The row (entry index) it is drawn for. */
  entry: number;
  kind: 'linear' | 'circular';
  points: PathPoint[];
  length: number;
  /** An arc's centre (X, Y, Z), for a marker. */
  centre?: Vec3;
}

export interface PreviewCorner {
  /** The entry whose start the corner is (its transition governs it). */
  entry: number;
  at: PathPoint;
  /** The tolerance radius (corner distance; r_in and r_out for the advanced mode). */
  rIn: number;
  rOut: number;
}

export interface Preview {
  start: PathPoint;
  segments: PreviewSegment[];
  /** Programmed points: the start, then each motion entry's end, with the entry it ends. */
  points: { entry: number; at: PathPoint }[];
  corners: PreviewCorner[];
  /** Entries that cannot be drawn, and why (the server will say the same or more). */
  errors: { entry: number; text: string }[];
  /** The sum of the segments' lengths. */
  length: number;
}

/**
 * The preview of a table run from `start`: `roles` are the path-point dims of the group's
 * axis order (the convention's, then ADDAX1..n), as `GroupRole.dim()` numbers them; each
 * entry's vector is placed there, the other dims keep their value (as the kernel's `place`).
 * An arc is sampled every `arcStepDeg` degrees (at least 8 points).
 */
export function preview(entries: (PreviewEntry | null)[], start: PathPoint, dims: number[], planar: boolean, arcStepDeg = 3): Preview {
  const out: Preview = { start: [...start], segments: [], points: [{ entry: -1, at: [...start] }], corners: [], errors: [], length: 0 };
  let at = [...start];
  const place = (v: number[]) => {
    const p = [...at];
    dims.forEach((d, i) => (p[d] = v[i] ?? NaN));
    return p;
  };
  entries.forEach((e, entry) => {
    if (!e || e.type === 'blocker' || e.type === 'dwell') return;
    const end = place(e.type === 'linear' ? e.position : e.end_point);
    if (!end.every(Number.isFinite) || (e.type === 'linear' ? e.position : e.end_point).length !== dims.length) {
      out.errors.push({ entry, text: `${dims.length} numbers needed` });
      return;
    }
    if (e.corner && out.segments.length > 0) out.corners.push({ entry, at: [...at], rIn: e.corner[0], rOut: e.corner[1] });
    if (e.type === 'linear') {
      const length = lineLength(at, end);
      out.segments.push({ entry, kind: 'linear', points: [[...at], end], length });
      out.length += length;
    } else {
      try {
        const g = arcGeometry(e.circ_mode, at, e.aux_point, end, e.path_choice, planar);
        const n = Math.max(8, Math.ceil((g.sweep * 180) / Math.PI / arcStepDeg));
        out.segments.push({ entry, kind: 'circular', points: sampleArc(g, at, end, n), length: g.length, centre: g.centre });
        out.length += g.length;
      } catch (x) {
        out.errors.push({ entry, text: (x as Error).message });
        // Drawn as a straight dashed jump? No: the path goes on from the programmed end point.
      }
    }
    out.points.push({ entry, at: end });
    at = end;
  });
  return out;
}
