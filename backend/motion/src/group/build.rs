//! From a path table to the items a group runs: geometry from the start point, each
//! entry's dynamics within every member's limits, the corner blends between entries, the
//! software limits. Pure, so that the server prepares a MovePath off the cycle thread
//! ([`prepare_path`]); the group commits a prepared path only when the context it was
//! prepared in still holds (same start point, configuration and members' limits) and builds
//! it itself otherwise. Only the blend from the queue's last item into a new path ([`join`])
//! is made when the path joins, because it depends on what is queued then.

use super::motion::{Item, ItemKind};
use super::*;
use crate::params::AxisParameters;

/// Per-member dynamics the path respects.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisLimits {
    pub velocity: f64,
    pub acceleration: f64,
    pub jerk: f64,
    pub soft_min: Option<f64>,
    pub soft_max: Option<f64>,
}

impl AxisLimits {
    /// The axis's maximum velocity, the lower of its maximum acceleration and deceleration
    /// (a path may brake an axis that it accelerates), its jerk, its enabled software limits.
    pub fn of(p: &AxisParameters) -> AxisLimits {
        AxisLimits {
            velocity: p.axis_velo_max,
            acceleration: p.axis_maximum_acceleration.min(p.axis_maximum_deceleration),
            jerk: p.axis_jerk,
            soft_min: p
                .axis_en_min_soft_pos_limit
                .then_some(p.axis_min_soft_pos_limit),
            soft_max: p
                .axis_en_max_soft_pos_limit
                .then_some(p.axis_max_soft_pos_limit),
        }
    }
}

/// What a MovePath is built against.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PathContext {
    pub config: GroupConfig,
    /// The coordinate frame in effect for the table's first entry.
    pub frame: CoordTransform,
    /// Per role dimension: the member's limits (None: no member).
    pub limits: [Option<AxisLimits>; MAX_PATH_DIMS],
    pub cycle_time: f64,
}

/// A MovePath built off the cycle thread: its items from `start`, in `context`.
#[derive(Clone, Debug)]
pub struct PreparedPath {
    pub(super) start: PathPoint,
    pub(super) context: PathContext,
    pub(super) items: Vec<Item>,
    /// The frame after the table (its last frame switch).
    pub(super) frame: CoordTransform,
}

impl PreparedPath {
    /// Items (entries and blends) it holds.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }
}

/// Builds a MovePath off the cycle thread as if it started at `start` (the group's queue end
/// point, `GroupStatus::queue_end`). The failing entry's index, field and error.
pub fn prepare_path(
    ctx: &PathContext,
    table: &PathTable,
    start: PathPoint,
) -> Result<PreparedPath, (usize, &'static str, ErrorId)> {
    table.check(ctx.config.axis_count(), ctx.config.convention.planar())?;
    let mut items = Vec::with_capacity(2 * table.entries.len() + 1);
    let frame = build(ctx, 0, &table.entries, start, 0.0, &mut items)
        .map_err(|(i, e)| (i, field_of(e), e))?;
    Ok(PreparedPath {
        start,
        context: *ctx,
        items,
        frame,
    })
}

/// The request field an error of building names.
fn field_of(e: ErrorId) -> &'static str {
    match e {
        ErrorId::CIRCLE_INVALID => "aux_point",
        _ => "position",
    }
}

/// Turns the table into items in `out`: geometry from `start`, dynamics within
/// the members' limits, blends, soft limits. Returns how the queue's last item is to be
/// trimmed for a blend into the first entry (applied only once everything passed).
pub(super) fn build(
    ctx: &PathContext,
    id: CommandId,
    entries: &[PathEntry],
    start: PathPoint,
    s0: f64,
    out: &mut Vec<Item>,
) -> Result<CoordTransform, (usize, ErrorId)> {
    out.clear();
    let mut frame = ctx.frame;
    let limits = &ctx.limits;
    let roles: [Option<GroupRole>; MAX_PATH_DIMS] = {
        let mut r = [None; MAX_PATH_DIMS];
        for (i, role) in ctx.config.roles().enumerate() {
            r[i] = Some(role);
        }
        r
    };
    let planar = ctx.config.convention.planar();
    let mut at = start;
    let mut s = s0;
    let mut prev: Option<Item> = None;
    for (i, e) in entries.iter().enumerate() {
        let base = standing_item(id, s, i as u16, e.invoke_id());
        let (seg, motion) = match *e {
            PathEntry::CoordinateTransform { transform } => {
                frame = transform;
                continue;
            }
            PathEntry::Blocker { blocker_id, .. } => {
                out.push(Item {
                    kind: ItemKind::Blocker {
                        id: blocker_id,
                        released: false,
                    },
                    ..base
                });
                prev = None;
                continue;
            }
            PathEntry::Dwell { time, .. } => {
                out.push(Item {
                    kind: ItemKind::Dwell(time),
                    ..base
                });
                prev = None;
                continue;
            }
            PathEntry::Linear {
                position, motion, ..
            } => {
                let target = placed(&roles, &position, at, &frame, ctx.config.convention);
                let line =
                    path::Line::new(at, target).map_err(|_| (i, ErrorId::PARAMETER_NOT_CORRECT))?;
                (Segment::Line(line), motion)
            }
            PathEntry::Circular {
                mode,
                aux,
                end_point,
                path_choice,
                motion,
                ..
            } => {
                let target = placed(&roles, &end_point, at, &frame, ctx.config.convention);
                // A point of the circle is a point; a radius-mode normal is a direction.
                let aux = match mode {
                    path::CircMode::Radius => frame.rotate(aux),
                    _ => frame.apply(aux),
                };
                let arc = path::Arc::new(mode, at, aux, target, path_choice, planar)
                    .map_err(|_| (i, ErrorId::CIRCLE_INVALID))?;
                (Segment::Arc(arc), motion)
            }
        };
        let lim = entry_limits(ctx, &motion, &seg);
        check_soft_limits(&seg, limits).map_err(|e| (i, e))?;
        let mut item = Item {
            kind: ItemKind::Motion(seg),
            len: seg.length(),
            limits: lim,
            ..base
        };
        // A blend into this entry from the one before (its transition parameters govern
        // the corner at its start, §5.5).
        if let (Some((r_in, r_out)), Some(p)) = (e.corner_distance(), prev) {
            let ItemKind::Motion(pseg) = p.kind else {
                unreachable!("prev is a motion item")
            };
            let blended = path::blend_corner(&pseg, &seg, r_in, r_out).and_then(|b| {
                let bseg = Segment::Blend(b.1);
                let blim = blend_limits(&p.limits, &lim, &bseg, limits);
                worth_blending(&blim, &p.limits, &lim).then_some((b, bseg, blim))
            });
            if let Some(((cut_prev, _, cut_next), bseg, blim)) = blended {
                {
                    check_soft_limits(&bseg, limits).map_err(|e| (i, e))?;
                    let prev_seg = pseg.trimmed(0.0, cut_prev);
                    let prev_corner = p.limits.velocity.min(blim.velocity);
                    let last_ix = out.len() - 1;
                    let q = &mut out[last_ix];
                    q.kind = ItemKind::Motion(prev_seg);
                    q.len = cut_prev;
                    q.corner = prev_corner;
                    s = q.s0 + cut_prev;
                    let blen = bseg.length();
                    out.push(Item {
                        kind: ItemKind::Motion(bseg),
                        s0: s,
                        len: blen,
                        limits: blim,
                        corner: blim.velocity.min(lim.velocity),
                        blend: true,
                        last: false,
                        ..base
                    });
                    s += blen;
                    let rest = seg.trimmed(cut_next, seg.length());
                    item.kind = ItemKind::Motion(rest);
                    item.len = rest.length();
                }
            } else if tangent_continuous(&pseg, &seg) {
                let corner = p
                    .limits
                    .velocity
                    .min(lim.velocity)
                    .min(curvature_jump_velocity(&pseg, &seg, limits, ctx.cycle_time));
                let last_ix = out.len() - 1;
                out[last_ix].corner = corner;
            }
        }
        // Motion, blocker, motion without a corner: passed in motion if the blocker is
        // released before the path reaches it (§4.3).
        let n_scratch = out.len();
        if n_scratch >= 2 {
            if let (ItemKind::Blocker { .. }, ItemKind::Motion(pseg)) =
                (out[n_scratch - 1].kind, out[n_scratch - 2].kind)
            {
                if tangent_continuous(&pseg, &seg) {
                    let jump = curvature_jump_velocity(&pseg, &seg, limits, ctx.cycle_time);
                    let q = &mut out[n_scratch - 2];
                    q.through = q.limits.velocity.min(lim.velocity).min(jump);
                }
            }
        }
        item.s0 = s;
        s += item.len;
        at = seg.end();
        out.push(item);
        prev = Some(item);
    }
    // The MovePath is Done when its last item is passed; a table of frame switches only is
    // Done at once (a dwell of 0).
    match out.last_mut() {
        Some(l) => l.last = true,
        None => out.push(Item {
            last: true,
            ..standing_item(id, s, 0, 0)
        }),
    }
    Ok(frame)
}

/// An item that stands (a dwell of 0) at `s`: the base every entry's item is made from.
fn standing_item(command: CommandId, s: f64, entry: u16, invoke_id: u32) -> Item {
    Item {
        kind: ItemKind::Dwell(0.0),
        s0: s,
        len: 0.0,
        limits: Limits {
            velocity: 1.0,
            acceleration: 1.0,
            deceleration: 1.0,
            jerk: 100.0,
        },
        corner: 0.0,
        through: 0.0,
        v_end: 0.0,
        command,
        entry,
        invoke_id,
        blend: false,
        last: false,
    }
}

/// The entry's path dynamics, each lowered to what every member axis allows on `seg`
/// (decision 124): velocity by |dp_i/ds|, the centripetal part within half an axis's
/// acceleration, the tangential part within what is left.
fn entry_limits(ctx: &PathContext, m: &EntryMotion, seg: &Segment) -> Limits {
    let (d, mx) = (ctx.config.default_dynamics, ctx.config.maximum_dynamics);
    let pick = |v: PathValue, default: f64, max: f64| match v {
        PathValue::Value(x) => x.min(max),
        PathValue::Maximum => max,
        PathValue::Default | PathValue::Ignore => default,
    };
    let commanded = Limits {
        velocity: pick(m.velocity, d.velocity, mx.velocity),
        acceleration: pick(m.acceleration, d.acceleration, mx.acceleration),
        deceleration: pick(m.deceleration, d.deceleration, mx.deceleration),
        jerk: pick(m.jerk, d.jerk, mx.jerk),
    };
    axis_bounded(commanded, seg, &ctx.limits)
}

fn blend_limits(
    a: &Limits,
    b: &Limits,
    seg: &Segment,
    limits: &[Option<AxisLimits>; MAX_PATH_DIMS],
) -> Limits {
    let commanded = Limits {
        velocity: a.velocity.min(b.velocity),
        acceleration: a.acceleration.min(b.acceleration),
        deceleration: a.deceleration.min(b.deceleration),
        jerk: a.jerk.min(b.jerk),
    };
    axis_bounded(commanded, seg, limits)
}

/// How the queue's last item changes when a new path joins it with a blend (or a
/// tangent-continuous corner): its trimmed segment, length and corner velocity.
pub(super) type BackTrim = Option<(Segment, f64, f64)>;

/// The corner between the queue's last item `back` and the first new item `items[0]` (entry
/// 0 of a BlendingPrevious MovePath with CornerDistance `radii`): a blend item is inserted
/// and the first item trimmed when `reachable(cut)` says the path can still get there; the
/// new items' s0 are set from `back`. Returns how `back` changes.
pub(super) fn join(
    ctx: &PathContext,
    back: &Item,
    radii: (f64, f64),
    items: &mut Vec<Item>,
    mut reachable: impl FnMut(f64, f64) -> bool,
) -> Result<BackTrim, ErrorId> {
    let (ItemKind::Motion(pseg), Some(first)) = (back.kind, items.first().copied()) else {
        return Ok(None);
    };
    let ItemKind::Motion(seg) = first.kind else {
        return Ok(None);
    };
    let limits = &ctx.limits;
    let mut trim = None;
    let mut s = back.end_s();
    let blended = path::blend_corner(&pseg, &seg, radii.0, radii.1).and_then(|b| {
        let bseg = Segment::Blend(b.1);
        let blim = blend_limits(&back.limits, &first.limits, &bseg, limits);
        worth_blending(&blim, &back.limits, &first.limits).then_some((b, bseg, blim))
    });
    if let Some(((cut_prev, _, cut_next), bseg, blim)) = blended {
        if reachable(cut_prev, blim.velocity.min(first.limits.velocity)) {
            check_soft_limits(&bseg, limits)?;
            trim = Some((
                pseg.trimmed(0.0, cut_prev),
                cut_prev,
                back.limits.velocity.min(blim.velocity),
            ));
            s = back.s0 + cut_prev;
            let rest = seg.trimmed(cut_next, seg.length());
            items[0].kind = ItemKind::Motion(rest);
            items[0].len = rest.length();
            items.insert(
                0,
                Item {
                    kind: ItemKind::Motion(bseg),
                    s0: s,
                    len: bseg.length(),
                    limits: blim,
                    corner: blim.velocity.min(first.limits.velocity),
                    blend: true,
                    last: false,
                    entry: 0,
                    ..first
                },
            );
        }
    } else if tangent_continuous(&pseg, &seg) {
        let corner = back
            .limits
            .velocity
            .min(first.limits.velocity)
            .min(curvature_jump_velocity(&pseg, &seg, limits, ctx.cycle_time));
        trim = Some((pseg, back.len, corner));
    }
    for it in items.iter_mut() {
        it.s0 = s;
        s += it.len;
    }
    Ok(trim)
}

/// The table's vector read in `frame`: its X, Y, Z (those the convention has) are
/// transformed into machine coordinates, C and the ADDAX axes are not.
fn placed(
    roles: &[Option<GroupRole>; MAX_PATH_DIMS],
    v: &PathPoint,
    at: PathPoint,
    frame: &CoordTransform,
    convention: AxesConvention,
) -> PathPoint {
    let mut p = place(roles, v, at);
    if !frame.is_identity() {
        let spatial = if convention.planar() { 2 } else { 3 };
        let m = frame.apply([p[0], p[1], if spatial == 3 { p[2] } else { 0.0 }]);
        p[..spatial].copy_from_slice(&m[..spatial]);
    }
    p
}

/// The table's vector (convention axes, then ADDAX1..n) placed into a path point; roles the
/// group does not have keep their value from `at`.
fn place(roles: &[Option<GroupRole>; MAX_PATH_DIMS], v: &PathPoint, at: PathPoint) -> PathPoint {
    let mut p = at;
    for (i, r) in roles.iter().enumerate() {
        if let Some(r) = r {
            p[r.dim()] = v[i];
        }
    }
    p
}

fn tangent_continuous(a: &Segment, b: &Segment) -> bool {
    let ta = a.sample(a.length()).d1;
    let tb = b.sample(0.0).d1;
    let dot: f64 = ta.iter().zip(tb.iter()).map(|(x, y)| x * y).sum();
    let na: f64 = ta.iter().map(|x| x * x).sum::<f64>().sqrt();
    let nb: f64 = tb.iter().map(|x| x * x).sum::<f64>().sqrt();
    na > 0.0 && nb > 0.0 && dot / (na * nb) > 1.0 - 1e-9
}

/// A blend is made only where it is faster than stopping at the corner: a near-reversal's
/// blend curls so tightly that the members' jerk holds it to a crawl; below a twentieth of
/// its neighbours' velocity the corner is an exact stop instead (decision 124).
fn worth_blending(blend: &Limits, prev: &Limits, next: &Limits) -> bool {
    blend.velocity >= 0.05 * prev.velocity.min(next.velocity)
}

/// Commanded path dynamics lowered to what every member axis allows on `seg`: the axis's
/// velocity over |dp/ds|; its acceleration shared between the centripetal part (d²p/ds²·v²,
/// at most half) and the tangential part; its jerk between the change of curvature
/// (d³p/ds³·v³, at most half), the curvature with the tangential acceleration
/// (3·d²p/ds²·v·a, a quarter) and the path jerk (a quarter) (decision 124).
fn axis_bounded(
    mut l: Limits,
    seg: &Segment,
    limits: &[Option<AxisLimits>; MAX_PATH_DIMS],
) -> Limits {
    let b = seg.bounds();
    let d3 = b.d3_max;
    for (d, lim) in limits.iter().enumerate() {
        let Some(lim) = lim else { continue };
        if b.d1_max[d] > 0.0 {
            l.velocity = l.velocity.min(lim.velocity / b.d1_max[d]);
        }
        if b.d2_max[d] > 0.0 {
            l.velocity = l
                .velocity
                .min((0.5 * lim.acceleration / b.d2_max[d]).sqrt());
        }
        if d3[d] > 0.0 {
            l.velocity = l.velocity.min((0.5 * lim.jerk / d3[d]).cbrt());
        }
    }
    for (d, lim) in limits.iter().enumerate() {
        let Some(lim) = lim else { continue };
        if b.d1_max[d] > 0.0 {
            let left = lim.acceleration - b.d2_max[d] * l.velocity * l.velocity;
            let mut a = left.max(0.5 * lim.acceleration) / b.d1_max[d];
            if b.d2_max[d] > 0.0 {
                a = a.min(0.25 * lim.jerk / (3.0 * b.d2_max[d] * l.velocity));
            }
            l.acceleration = l.acceleration.min(a);
            l.deceleration = l.deceleration.min(a);
            l.jerk = l.jerk.min(0.25 * lim.jerk / b.d1_max[d]);
        }
    }
    l
}

/// A corner without a blend where the tangent is continuous but the curvature jumps (a line
/// into an arc): the axes' acceleration jumps by v²·Δ(d²p/ds²); keep that within one cycle of
/// each axis's jerk (decision 124).
fn curvature_jump_velocity(
    a: &Segment,
    b: &Segment,
    limits: &[Option<AxisLimits>; MAX_PATH_DIMS],
    cycle_time: f64,
) -> f64 {
    let ka = a.sample(a.length()).d2;
    let kb = b.sample(0.0).d2;
    let mut v = f64::INFINITY;
    for (d, lim) in limits.iter().enumerate() {
        let Some(lim) = lim else { continue };
        let jump = (ka[d] - kb[d]).abs();
        if jump > 1e-12 {
            v = v.min((lim.jerk * cycle_time / jump).sqrt());
        }
    }
    v
}

fn check_soft_limits(
    seg: &Segment,
    limits: &[Option<AxisLimits>; MAX_PATH_DIMS],
) -> Result<(), ErrorId> {
    let b = seg.bounds();
    for (d, lim) in limits.iter().enumerate() {
        let Some(lim) = lim else { continue };
        if lim.soft_min.is_some_and(|m| b.lo[d] < m) || lim.soft_max.is_some_and(|m| b.hi[d] > m) {
            return Err(ErrorId::PATH_BEYOND_SOFT_LIMIT);
        }
    }
    Ok(())
}
