//! Cam tables (TwinCAT NC Camming, spec camming-tf5050.md): motion laws against their closed
//! forms (VDI 2143) at segment start, middle and end, continuity at borders as far as each law
//! promises, position-table interpolation, validation with the manual's error codes, and the
//! analysis FBs with the spec's worked examples.

use motion::ErrorId;
use motion::cam::*;

fn pt(
    i: u32,
    law: MotionFunctionType,
    kind: MotionPointType,
    x: f64,
    y: f64,
) -> MotionFunctionPoint {
    MotionFunctionPoint {
        point_index: i,
        function_type: law,
        point_type: kind,
        rel_index_next_point: 1,
        master_pos: x,
        slave_pos: y,
        slave_velo: 0.0,
        slave_acc: 0.0,
        slave_jerk: 0.0,
    }
}

/// One segment of `law` from (0, 0) to (dx, h) between rest points.
fn one_segment(law: MotionFunctionType, dx: f64, h: f64) -> Cam {
    use MotionPointType::Rest;
    Cam::build(&CamTableData::motion_function(vec![
        pt(1, law, Rest, 0.0, 0.0),
        pt(2, MotionFunctionType::Polynom1, Rest, dx, h),
    ]))
    .unwrap_or_else(|e| panic!("{law:?}: {e}"))
}

fn close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * (1.0 + b.abs())
}

#[track_caller]
fn assert_close(have: f64, want: f64, tol: f64, what: &str) {
    assert!(close(have, want, tol), "{what}: have {have}, want {want}");
}

/// The spec's golden values (§5.3): POLYNOM5 from (0, 0) to (200, 100).
#[test]
fn polynom5_golden_values_and_characteristics() {
    let cam = one_segment(MotionFunctionType::Polynom5, 200.0, 100.0);
    for (x, p, v, a) in [
        (50.0, 10.3515625, 0.52734375, 0.0140625),
        (100.0, 50.0, 0.9375, 0.0),
        (150.0, 89.6484375, 0.52734375, -0.0140625),
    ] {
        let c = cam.eval(x);
        assert_close(c.position, p, 1e-12, "position");
        assert_close(c.velocity, v, 1e-12, "velocity");
        assert!(
            (c.acceleration - a).abs() < 1e-12,
            "acceleration at {x}: {}",
            c.acceleration
        );
    }
    let ch = characteristics(&cam);
    assert_close(ch.slave_velo_max, 0.9375, 1e-9, "velo max");
    assert_close(ch.m_pos_at_s_velo_max, 100.0, 1e-6, "at");
    assert_close(ch.slave_acc_max, 0.0144338, 1e-5, "acc max");
    assert_close(ch.m_pos_at_s_acc_max, 42.265, 1e-4, "at");
    assert_close(ch.slave_acc_min, -0.0144338, 1e-5, "acc min");
    assert_close(ch.m_pos_at_s_acc_min, 157.735, 1e-4, "at");
    assert_close(ch.slave_jerk_max, 0.00075, 1e-9, "jerk max");
    assert_close(
        ch.slave_jerk_min,
        -0.0003750,
        1e-9,
        "jerk min (mid-segment)",
    );
    assert_eq!((ch.slave_pos_start, ch.slave_pos_end), (0.0, 100.0));
    assert_eq!((ch.slave_pos_min, ch.slave_pos_max), (0.0, 100.0));
    assert_eq!(ch.master_velo_nom, 1.0);
}

/// Every rest-to-rest law: starts and ends at rest with the stroke, and its peak factors
/// Cv = max f', Ca = max f'' on the unit segment are VDI 2143's.
#[test]
fn rest_to_rest_laws_have_their_peak_factors() {
    use MotionFunctionType::*;
    use core::f64::consts::PI;
    for (law, cv, ca) in [
        (Polynom3, 1.5, 6.0),
        (Polynom5, 1.875, 10.0 / 3f64.sqrt()),
        (Polynom7, 2.1875, 7.5132),
        (Polynom9, 2.4609, 9.3720),
        (Polynom11, 2.7070, 11.2666),
        (Sinuslinie, PI / 2.0, PI * PI / 2.0),
        (Bestehorn, 2.0, 2.0 * PI),
        (ModSinuslinie, 1.7596, 5.5280),
        (BeschlTrapez, 2.0, 16.0 / 3.0),
    ] {
        let cam = one_segment(law, 1.0, 1.0);
        for x in [0.0, 1.0] {
            assert!(cam.eval(x).velocity.abs() < 1e-12, "{law:?} v at {x}");
        }
        assert_close(cam.eval(1.0).position, 1.0, 1e-12, "stroke");
        let ch = characteristics(&cam);
        assert_close(ch.slave_velo_max, cv, 1e-4, &format!("{law:?} Cv"));
        assert_close(ch.slave_acc_max, ca, 1e-4, &format!("{law:?} Ca"));
        // Rest to rest laws are antisymmetric around the middle (except POLYNOM8).
        assert_close(
            cam.eval(0.5).position,
            0.5,
            1e-12,
            &format!("{law:?} middle"),
        );
    }
}

/// POLYNOM8 (no unique standard form; motiond's is f' = 280·z⁴(1−z)³): rest to rest, the 3rd
/// and 4th derivative 0 at the start, the 3rd at the end.
#[test]
fn polynom8_is_the_asymmetric_order_8_law() {
    let cam = one_segment(MotionFunctionType::Polynom8, 1.0, 1.0);
    for z in [0.1f64, 0.3, 0.5, 0.8] {
        let want_v = 280.0 * z.powi(4) * (1.0 - z).powi(3);
        assert_close(cam.eval(z).velocity, want_v, 1e-12, "f'");
    }
    let (s, e) = (cam.eval(0.0), cam.eval_piece(0, 1.0));
    assert_eq!(
        (s.position, s.velocity, s.acceleration, s.jerk),
        (0.0, 0.0, 0.0, 0.0)
    );
    assert_close(e.position, 1.0, 1e-12, "end");
    assert!(e.velocity.abs() < 1e-9 && e.acceleration.abs() < 1e-9 && e.jerk.abs() < 1e-9);
}

/// The modified sine line against the spec's piecewise closed form (C² at 1/8 and 7/8).
#[test]
fn modified_sine_matches_its_closed_form() {
    use core::f64::consts::PI;
    let k = 1.0 / (4.0 + PI);
    let f = |z: f64| {
        if z <= 0.125 {
            k * (PI * z - 0.25 * (4.0 * PI * z).sin())
        } else if z <= 0.875 {
            k * (2.0 + PI * z - 2.25 * (PI / 3.0 + 4.0 * PI * z / 3.0).sin())
        } else {
            k * (4.0 + PI * z - 0.25 * (4.0 * PI * z).sin())
        }
    };
    let cam = one_segment(MotionFunctionType::ModSinuslinie, 2.0, 3.0);
    for i in 0..=40 {
        let z = i as f64 / 40.0;
        assert_close(
            cam.eval(2.0 * z).position,
            3.0 * f(z),
            1e-12,
            &format!("z = {z}"),
        );
    }
    for z in [0.125, 0.875] {
        let (l, r) = (cam.eval(2.0 * z - 1e-9), cam.eval(2.0 * z + 1e-9));
        assert!(
            (l.acceleration - r.acceleration).abs() < 1e-6,
            "a continuous at {z}"
        );
    }
}

/// The boundary-value laws meet their points' velocity, acceleration (and jerk) exactly; with
/// all of them 0 they are the rest-to-rest polynomials.
#[test]
fn boundary_value_laws_meet_their_points() {
    use MotionFunctionType::*;
    use MotionPointType::Motion;
    for law in [Polynom3Vv, Polynom5Mm, Polynom7Mm] {
        let mut a = pt(1, law, Motion, 10.0, 5.0);
        let mut b = pt(2, Polynom1, Motion, 40.0, 35.0);
        (a.slave_velo, a.slave_acc, a.slave_jerk) = (0.5, 0.02, -0.001);
        (b.slave_velo, b.slave_acc, b.slave_jerk) = (1.5, -0.01, 0.002);
        let cam = Cam::build(&CamTableData::motion_function(vec![a, b])).unwrap();
        let (s, e) = (cam.eval_piece(0, 10.0), cam.eval_piece(0, 40.0));
        assert_close(s.position, 5.0, 1e-12, "p0");
        assert_close(e.position, 35.0, 1e-12, "p1");
        assert_close(s.velocity, 0.5, 1e-12, "v0");
        assert_close(e.velocity, 1.5, 1e-12, "v1");
        if law != Polynom3Vv {
            assert_close(s.acceleration, 0.02, 1e-12, "a0");
            assert_close(e.acceleration, -0.01, 1e-12, "a1");
        }
        if law == Polynom7Mm {
            assert_close(s.jerk, -0.001, 1e-10, "j0");
            assert_close(e.jerk, 0.002, 1e-10, "j1");
        }
    }
    for (mm, rr) in [(Polynom5Mm, Polynom5), (Polynom7Mm, Polynom7)] {
        let (a, b) = (one_segment(mm, 3.0, 2.0), one_segment(rr, 3.0, 2.0));
        for x in [0.3, 1.5, 2.7] {
            assert_close(a.eval(x).position, b.eval(x).position, 1e-12, "reduces");
        }
    }
}

/// The transition laws (no formula in the manual; motiond's definitions in docs/decisions.md):
/// each starts and ends with the kind of point its name says, with the points' velocities.
#[test]
fn transition_laws_start_and_end_as_their_names_say() {
    use MotionFunctionType::*;
    use MotionPointType::*;
    // (law, start kind, start v, end kind, end v)
    for (law, k0, v0, k1, v1) in [
        (HarmonicKombiRt, Rest, 0.0, Turn, 0.0),
        (HarmonicKombiTr, Turn, 0.0, Rest, 0.0),
        (HarmonicKombiVt, Velocity, 0.5, Turn, 0.0),
        (HarmonicKombiTv, Turn, 0.0, Velocity, 0.5),
        (BeschlTrapezRt, Rest, 0.0, Turn, 0.0),
        (BeschlTrapezTr, Turn, 0.0, Rest, 0.0),
        (BeschlTrapezRv, Rest, 0.0, Velocity, 2.0),
        (BeschlTrapezVr, Velocity, 2.0, Rest, 0.0),
        (ModSinuslinieVv, Velocity, 0.5, Velocity, 2.0),
    ] {
        let mut a = pt(1, law, k0, 0.0, 0.0);
        let mut b = pt(2, Polynom1, k1, 10.0, 10.0);
        a.slave_velo = v0;
        b.slave_velo = v1;
        if k1 == Velocity {
            // The next segment is a straight line with that velocity.
            let c = pt(3, Polynom1, Velocity, 20.0, 10.0 + 10.0 * v1);
            let cam = Cam::build(&CamTableData::motion_function(vec![a, b, c]))
                .unwrap_or_else(|e| panic!("{law:?}: {e}"));
            check_transition(&cam, law, k0, v0, k1, v1);
        } else {
            let cam = Cam::build(&CamTableData::motion_function(vec![a, b]))
                .unwrap_or_else(|e| panic!("{law:?}: {e}"));
            check_transition(&cam, law, k0, v0, k1, v1);
        }
    }
}

fn check_transition(
    cam: &Cam,
    law: MotionFunctionType,
    k0: MotionPointType,
    v0: f64,
    k1: MotionPointType,
    v1: f64,
) {
    use MotionPointType::*;
    let (s, e) = (cam.eval_piece(0, 0.0), cam.eval_piece(0, 10.0));
    assert!(
        s.position.abs() < 1e-12 && close(e.position, 10.0, 1e-12),
        "{law:?} stroke"
    );
    assert_close(s.velocity, v0, 1e-9, &format!("{law:?} v0"));
    assert_close(e.velocity, v1, 1e-9, &format!("{law:?} v1"));
    for (kind, v) in [(k0, s), (k1, e)] {
        match kind {
            Rest | Velocity => assert!(
                v.acceleration.abs() < 1e-9,
                "{law:?}: a = {} at a {kind:?} point",
                v.acceleration
            ),
            Turn => assert!(
                v.acceleration.abs() > 1e-3,
                "{law:?}: a turn point has a ≠ 0"
            ),
            _ => {}
        }
    }
    // C¹ inside: no velocity step between neighbouring samples.
    let mut prev = cam.eval_piece(0, 0.0).velocity;
    for i in 1..=1000 {
        let v = cam.eval_piece(0, i as f64 * 0.01).velocity;
        assert!(
            (v - prev).abs() < 0.05,
            "{law:?}: velocity step at {}",
            i as f64 * 0.01
        );
        prev = v;
    }
}

/// The harmonic combination rest→turn moves forward only (v ≥ 0) and turns at its end.
#[test]
fn harmonic_combination_rest_to_turn_never_reverses_before_the_turn() {
    let cam = one_turn(MotionFunctionType::HarmonicKombiRt);
    for i in 0..=100 {
        assert!(cam.eval(i as f64).velocity >= -1e-12);
    }
    assert!(cam.eval_piece(0, 100.0).acceleration < 0.0);
}

fn one_turn(law: MotionFunctionType) -> Cam {
    use MotionPointType::*;
    Cam::build(&CamTableData::motion_function(vec![
        pt(1, law, Rest, 0.0, 0.0),
        pt(2, MotionFunctionType::Polynom1, Turn, 100.0, 50.0),
    ]))
    .unwrap()
}

/// The rotary knife of spec §5.2: synchronous (POLYNOM1) around the cut, POLYNOM5_MM between,
/// periodic with stroke 360: position and velocity continuous everywhere, one stroke per cycle.
#[test]
fn rotary_knife_is_c1_and_adds_one_stroke_per_cycle() {
    use MotionFunctionType::*;
    use MotionPointType::*;
    let mut p = vec![
        pt(1, Polynom1, Velocity, 0.0, 0.0),
        pt(2, Polynom5Mm, Velocity, 30.0, 30.0),
        pt(3, Polynom1, Velocity, 330.0, 330.0),
        pt(4, Polynom1, Velocity, 360.0, 360.0),
    ];
    for q in &mut p {
        q.slave_velo = 1.0;
    }
    // A knife whose circumference is 80 % of the product: slower between the cuts.
    p[1].slave_velo = 1.0;
    p[2].slave_pos = 330.0;
    let mut table = CamTableData::motion_function(p);
    table.periodic = true;
    let cam = Cam::build(&table).unwrap();
    assert_eq!(cam.stroke(), 360.0);
    for k in -2..3 {
        let base = k as f64 * 360.0;
        assert_close(
            cam.eval(base + 15.0).position,
            base + 15.0,
            1e-12,
            "sync window",
        );
        assert_close(cam.eval(base + 15.0).velocity, 1.0, 1e-12, "sync velocity");
    }
    let mut prev = cam.eval(-720.0);
    let mut x = -720.0;
    while x < 720.0 {
        x += 0.25;
        let v = cam.eval(x);
        assert!(
            (v.position - prev.position).abs() < 0.26 * 1.2,
            "jump at {x}"
        );
        assert!(
            (v.velocity - prev.velocity).abs() < 0.01,
            "velocity step at {x}"
        );
        prev = v;
    }
}

#[test]
fn validation_follows_the_manuals_rules() {
    use MotionFunctionType::*;
    use MotionPointType::*;
    let ok = || {
        vec![
            pt(1, Polynom5, Rest, 0.0, 0.0),
            pt(2, Polynom5, Rest, 10.0, 5.0),
            pt(3, Polynom5, Rest, 20.0, 0.0),
        ]
    };
    let refused =
        |p: Vec<MotionFunctionPoint>| Cam::build(&CamTableData::motion_function(p)).unwrap_err();
    assert!(Cam::build(&CamTableData::motion_function(ok())).is_ok());

    let e = refused(ok()[..1].to_vec());
    assert_eq!(e.id, ErrorId::CAM_NUMPOINTS_INVALID);
    let mut p = ok();
    p[2].point_index = 4;
    let e = refused(p);
    assert_eq!(
        (e.id, e.field.as_str()),
        (ErrorId::CAM_POINT_ID_INVALID, "points[2].point_index")
    );
    let mut p = ok();
    p[0].point_index = 0;
    assert_eq!(refused(p).id, ErrorId::CAM_POINT_ID_INVALID);
    for i in [0, 2] {
        let mut p = ok();
        p[i].point_type = Ignore;
        let e = refused(p);
        assert_eq!(
            (e.id, e.field.clone()),
            (
                ErrorId::CAM_IGNORE_AT_END,
                format!("points[{i}].point_type")
            )
        );
    }
    let mut p = ok();
    p[1].master_pos = 25.0;
    let e = refused(p);
    assert_eq!(
        (e.id, e.field.as_str()),
        (ErrorId::CAM_MASTER_NOT_MONOTONE, "points[2].master_pos")
    );
    // Skipping a point that is not IGNORE, linking beyond the end, landing on an IGNORE point.
    let mut p = ok();
    p[0].rel_index_next_point = 2;
    assert_eq!(refused(p).field, "points[0].rel_index_next_point");
    let mut p = ok();
    p[1].rel_index_next_point = 5;
    assert_eq!(refused(p).id, ErrorId::CAM_POINT_ID_INVALID);
    let mut p = ok();
    p[1].point_type = Ignore;
    assert_eq!(refused(p).id, ErrorId::CAM_POINT_ID_INVALID);
    // Not offered: NOTDEF and PEISEKAH11.
    for law in [Notdef, Peisekah11] {
        let mut p = ok();
        p[1].function_type = law;
        let e = refused(p);
        assert_eq!(
            (e.id, e.field.as_str()),
            (ErrorId::CAM_TABLE_TYPE_INVALID, "points[1].function_type")
        );
    }
    // A straight line between rest points: its velocity does not match them.
    let mut p = ok();
    p[0].function_type = Polynom1;
    let e = refused(p);
    assert_eq!(e.id, ErrorId::CAM_BOUNDARY_MISMATCH);
    assert_eq!(e.field, "points[0].point_type");
    // A VELOCITY point after a law whose acceleration is not 0 there.
    let mut p = ok();
    p[0].function_type = Polynom3;
    p[1].point_type = Velocity;
    assert_eq!(refused(p).id, ErrorId::CAM_BOUNDARY_MISMATCH);
    let mut p = ok();
    p[1].slave_pos = f64::NAN;
    assert_eq!(refused(p).id, ErrorId::CAM_VALUE_INVALID);
}

/// RelIndexNextPoint jumps over IGNORE points: the law runs from the point to the next valid one.
#[test]
fn ignored_points_are_skipped_by_the_next_point_link() {
    use MotionFunctionType::*;
    use MotionPointType::*;
    let mut p = vec![
        pt(1, Polynom5, Rest, 0.0, 0.0),
        pt(2, Polynom5, Ignore, 5.0, 999.0),
        pt(3, Polynom5, Rest, 10.0, 10.0),
    ];
    p[0].rel_index_next_point = 2;
    let cam = Cam::build(&CamTableData::motion_function(p)).unwrap();
    assert_eq!(cam.pieces(), 1);
    assert_close(
        cam.eval(5.0).position,
        5.0,
        1e-12,
        "middle of the one segment",
    );
}

/// Spec §5.3: pre-positioning a linear cam with offsets and scaling.
#[test]
fn linear_position_table_with_offsets_and_scaling() {
    let cam = Cam::build(&CamTableData::positions(
        vec![[0.0, 0.0], [100.0, 50.0], [200.0, 50.0]],
        false,
    ))
    .unwrap();
    let (mo, ms, so, ss) = (10.0, 2.0, 5.0, 3.0);
    let slave = |m: f64| cam.eval((m + mo) / ms).position * ss + so;
    assert_close(slave(90.0), 80.0, 1e-12, "master 90");
    assert_close(slave(500.0), 155.0, 1e-12, "beyond the end: held");
    assert_close(slave(-50.0), 5.0, 1e-12, "before the start: held");
    // Chain rule: v_s = SS/MS · f' · v_m.
    assert_close(
        ss / ms * cam.eval((90.0 + mo) / ms).velocity * 10.0,
        7.5,
        1e-12,
        "velocity",
    );
    assert_eq!(cam.eval(-1.0).velocity, 0.0);
}

/// Spec §5.3: a periodic cam with stroke repeats with one stroke per cycle, also backwards.
#[test]
fn periodic_cam_with_stroke_adds_one_stroke_per_cycle() {
    let mut t = CamTableData::positions(vec![[0.0, 0.0], [360.0, 360.0]], true);
    t.periodic = true;
    let cam = Cam::build(&t).unwrap();
    assert_eq!(cam.cycle_of(1000.0), (2, 280.0));
    assert_close(cam.eval(1000.0).position, 1000.0, 1e-12, "cycle 2");
    assert_close(cam.eval(700.0).position, 700.0, 1e-12, "cycle 1");
    assert_close(cam.eval(-20.0).position, -20.0, 1e-12, "cycle −1");
    assert_eq!(cam.cycle_of(720.0), (2, 0.0));
}

#[test]
fn equidistant_tables_are_checked_and_found_by_division() {
    let rows: Vec<[f64; 2]> = (0..=100)
        .map(|i| [i as f64 * 0.1, (i as f64 * 0.1).sin()])
        .collect();
    let eq = Cam::build(&CamTableData::positions(rows.clone(), true)).unwrap();
    let ne = Cam::build(&CamTableData::positions(rows.clone(), false)).unwrap();
    for i in 0..1000 {
        let x = i as f64 * 0.01;
        assert_eq!(eq.eval(x), ne.eval(x), "at {x}");
    }
    let mut bad = rows;
    bad[50][0] += 0.01;
    let e = Cam::build(&CamTableData::positions(bad, true)).unwrap_err();
    assert_eq!(
        (e.id, e.field.as_str()),
        (ErrorId::CAM_MASTER_NOT_MONOTONE, "rows[50][0]")
    );
    let e = Cam::build(&CamTableData::positions(
        vec![[0.0, 0.0], [0.0, 1.0]],
        false,
    ))
    .unwrap_err();
    assert_eq!(e.id, ErrorId::CAM_MASTER_NOT_MONOTONE);
    let mut t = CamTableData::positions(vec![[0.0, 0.0], [1.0, 1.0]], false);
    t.interpolation = InterpolationType::FourPoint;
    assert_eq!(
        Cam::build(&t).unwrap_err().id,
        ErrorId::CAM_TABLE_TYPE_INVALID
    );
}

/// SPLINE through a position table: through every row, C² inside; periodic tables close with
/// equal velocity and acceleration; SLIDINGSPLINE is C¹ and through every row.
#[test]
fn spline_interpolations_pass_the_rows_and_are_smooth() {
    use core::f64::consts::PI;
    let rows: Vec<[f64; 2]> = (0..=12)
        .map(|i| {
            let x = i as f64 * 30.0;
            [x, 10.0 * (x * PI / 180.0).sin() + x / 36.0]
        })
        .collect();
    for (interpolation, periodic, c2) in [
        (InterpolationType::Spline, false, true),
        (InterpolationType::Spline, true, true),
        (InterpolationType::SlidingSpline, false, false),
        (InterpolationType::SlidingSpline, true, false),
    ] {
        let mut t = CamTableData::positions(rows.clone(), true);
        t.interpolation = interpolation;
        t.periodic = periodic;
        let cam = Cam::build(&t).unwrap();
        for r in &rows {
            assert_close(
                cam.eval_in_range(r[0]).position,
                r[1],
                1e-12,
                "through the row",
            );
        }
        for i in 1..12 {
            let x = i as f64 * 30.0;
            let (l, r) = (cam.eval_piece(i - 1, x), cam.eval_piece(i, x));
            assert_close(
                l.velocity,
                r.velocity,
                1e-9,
                &format!("{interpolation:?} C¹ at {x}"),
            );
            if c2 {
                assert_close(
                    l.acceleration,
                    r.acceleration,
                    1e-9,
                    &format!("{interpolation:?} C² at {x}"),
                );
            }
        }
        if periodic {
            let (s, e) = (cam.eval_piece(0, 0.0), cam.eval_piece(11, 360.0));
            assert_close(s.velocity, e.velocity, 1e-9, "velocity across the wrap");
            if c2 {
                assert_close(
                    s.acceleration,
                    e.acceleration,
                    1e-9,
                    "acceleration across the wrap",
                );
            }
        }
    }
}

/// A spline run inside a motion function: natural ends, C² at its inner points, then a straight
/// line joined with SPLINE_LINEAR's slope.
#[test]
fn spline_runs_in_a_motion_function() {
    use MotionFunctionType::*;
    use MotionPointType::*;
    let p = vec![
        pt(1, SplineNatural, Motion, 0.0, 0.0),
        pt(2, Spline, Motion, 10.0, 4.0),
        pt(3, Spline, Motion, 20.0, 5.0),
        pt(4, SplineLinear, Motion, 30.0, 9.0),
        pt(5, Polynom1, Motion, 40.0, 13.0),
        pt(6, Polynom1, Motion, 50.0, 17.0),
    ];
    let cam = Cam::build(&CamTableData::motion_function(p)).unwrap();
    assert!(
        cam.eval_piece(0, 0.0).acceleration.abs() < 1e-12,
        "natural start"
    );
    for (i, x) in [(1, 10.0), (2, 20.0), (3, 30.0)] {
        let (l, r) = (cam.eval_piece(i - 1, x), cam.eval_piece(i, x));
        assert_close(l.velocity, r.velocity, 1e-9, "C¹");
        assert_close(l.acceleration, r.acceleration, 1e-9, "C²");
    }
    // The run's last segment (SPLINE_LINEAR, 30 → 40) ends with the next line's slope.
    let (l, r) = (cam.eval_piece(3, 40.0), cam.eval_piece(4, 40.0));
    assert_close(l.velocity, r.velocity, 1e-9, "joined to the line's slope");
    assert_close(r.velocity, 0.4, 1e-12, "the line");
}

/// Spec §2.17 / §5.3: the manual's inverse-lookup numbers.
#[test]
fn master_position_finds_the_manuals_solutions() {
    let rows = vec![
        [0.0, 0.0],
        [135.0, 80.0],
        [180.0, 100.0],
        [225.0, 80.0],
        [360.0, 0.0],
    ];
    let linear = Cam::build(&CamTableData::positions(rows.clone(), false)).unwrap();
    let mut t = CamTableData::positions(rows, false);
    t.periodic = true;
    let periodic = Cam::build(&t).unwrap();
    let q = |start: f64| MasterSearch {
        slave_position: 80.0,
        master_offset: 0.0,
        slave_offset: 0.0,
        master_scaling: 1.0,
        slave_scaling: 1.0,
        master_start_position: start,
        master_accuracy: 1e-9,
    };
    let (low, high) = master_position(&linear, &q(180.0)).unwrap();
    assert!(low.valid && high.valid);
    assert_close(low.master_axis_position, 135.0, 1e-9, "low");
    assert_close(high.master_axis_position, 225.0, 1e-9, "high");
    let (low, high) = master_position(&periodic, &q(90.0)).unwrap();
    assert_close(high.master_axis_position, 135.0, 1e-9, "periodic high");
    assert_close(
        low.master_axis_position,
        -135.0,
        1e-9,
        "periodic low: the previous cycle's 225",
    );
    assert_close(low.master_cam_position, 225.0, 1e-9, "in its cycle");
    let (low, high) = master_position(&linear, &q(90.0)).unwrap();
    assert!(high.valid && !low.valid);
    assert_close(high.master_axis_position, 135.0, 1e-9, "linear high");
}

/// With stroke the solution can be cycles away; offsets and scalings are the coupling's.
#[test]
fn master_position_with_stroke_offsets_and_scaling() {
    let mut t = CamTableData::positions(vec![[0.0, 0.0], [100.0, 50.0]], false);
    t.periodic = true;
    let cam = Cam::build(&t).unwrap();
    let q = MasterSearch {
        slave_position: 3.0 * 275.0 + 7.0, // raw 275: cycle 5, 25 into it
        master_offset: 20.0,
        slave_offset: 7.0,
        master_scaling: 2.0,
        slave_scaling: 3.0,
        master_start_position: 0.0,
        master_accuracy: 1e-9,
    };
    let (low, high) = master_position(&cam, &q).unwrap();
    assert!(!low.valid || low.master_axis_position <= 0.0);
    assert!(high.valid);
    // raw x = 550 → axis m = 550·2 − 20.
    assert_close(high.master_axis_position, 1080.0, 1e-9, "axis position");
    assert_close(high.master_cam_position, 50.0, 1e-9, "cam position");
    assert_close(
        high.slave_offset,
        7.0 + 5.0 * 50.0 * 3.0,
        1e-9,
        "offset with 5 strokes",
    );
}

/// MC_ReadMotionFunctionValues: rows from start by increment; bad increments are 0x4B38.
#[test]
fn sampled_values_and_their_limits() {
    let cam = one_segment(MotionFunctionType::Polynom5, 200.0, 100.0);
    let rows = sample(&cam, 0.0, 200.0, 50.0, 1000).unwrap();
    assert_eq!(rows.len(), 5);
    assert_eq!(rows[2].0, 100.0);
    assert_close(rows[1].1.position, 10.3515625, 1e-12, "row 1");
    assert_eq!(
        sample(&cam, 0.0, 200.0, 0.0, 1000).unwrap_err().id,
        ErrorId::CAM_INCREMENT_INVALID
    );
    assert_eq!(
        sample(&cam, 0.0, 200.0, 0.001, 1000).unwrap_err().id,
        ErrorId::CAM_INCREMENT_INVALID
    );
    assert_eq!(
        sample(&cam, 10.0, 0.0, 1.0, 1000).unwrap_err().id,
        ErrorId::CAM_VALUE_INVALID
    );
}

/// A large position table builds (off the cycle) and evaluates by division or binary search.
#[test]
fn a_million_row_table_builds_and_evaluates() {
    let rows: Vec<[f64; 2]> = (0..1_000_000)
        .map(|i| [i as f64 * 0.001, (i as f64 * 0.001).sin()])
        .collect();
    for equidistant in [true, false] {
        let mut t = CamTableData::positions(rows.clone(), equidistant);
        t.interpolation = InterpolationType::Spline;
        let cam = Cam::build(&t).unwrap();
        for x in [0.5, 1.2345, 500.0, 998.0] {
            assert!((cam.eval(x).position - x.sin()).abs() < 1e-9, "{x}");
            assert!((cam.eval(x).velocity - x.cos()).abs() < 1e-6, "{x}");
        }
    }
}

/// Golden values of every rest-to-rest law (VDI 2143 closed forms, written out here
/// independently of the library): f, f', f'', f''' at the start, the middle and the end of a
/// unit segment, and whether the acceleration is 0 at the ends (C² with rest neighbours) —
/// POLYNOM3 and the sine line have acceleration steps there, the others do not.
#[test]
fn every_rest_to_rest_law_matches_its_closed_form_at_start_middle_and_end() {
    use MotionFunctionType::*;
    use core::f64::consts::PI;
    fn poly(c: &[f64], z: f64) -> [f64; 4] {
        let mut out = [0.0; 4];
        for (i, ci) in c.iter().enumerate() {
            let i = i as i32;
            out[0] += ci * z.powi(i);
            if i >= 1 {
                out[1] += ci * i as f64 * z.powi(i - 1);
            }
            if i >= 2 {
                out[2] += ci * (i * (i - 1)) as f64 * z.powi(i - 2);
            }
            if i >= 3 {
                out[3] += ci * (i * (i - 1) * (i - 2)) as f64 * z.powi(i - 3);
            }
        }
        out
    }
    let k = 1.0 / (4.0 + PI);
    let a_trap = 16.0 / 3.0;
    type Law = (MotionFunctionType, Box<dyn Fn(f64) -> [f64; 4]>, bool);
    let laws: Vec<Law> = vec![
        (
            Polynom3,
            Box::new(|z| poly(&[0.0, 0.0, 3.0, -2.0], z)),
            false,
        ),
        (
            Polynom5,
            Box::new(|z| poly(&[0.0, 0.0, 0.0, 10.0, -15.0, 6.0], z)),
            true,
        ),
        (
            Polynom7,
            Box::new(|z| poly(&[0.0, 0.0, 0.0, 0.0, 35.0, -84.0, 70.0, -20.0], z)),
            true,
        ),
        (
            Polynom8,
            Box::new(|z| poly(&[0.0, 0.0, 0.0, 0.0, 0.0, 56.0, -140.0, 120.0, -35.0], z)),
            true,
        ),
        (
            Polynom9,
            Box::new(|z| {
                poly(
                    &[0.0, 0.0, 0.0, 0.0, 0.0, 126.0, -420.0, 540.0, -315.0, 70.0],
                    z,
                )
            }),
            true,
        ),
        (
            Polynom11,
            Box::new(|z| {
                poly(
                    &[
                        0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 462.0, -1980.0, 3465.0, -3080.0, 1386.0,
                        -252.0,
                    ],
                    z,
                )
            }),
            true,
        ),
        (
            Sinuslinie,
            Box::new(|z| {
                [
                    (1.0 - (PI * z).cos()) / 2.0,
                    PI / 2.0 * (PI * z).sin(),
                    PI * PI / 2.0 * (PI * z).cos(),
                    -PI.powi(3) / 2.0 * (PI * z).sin(),
                ]
            }),
            false,
        ),
        (
            Bestehorn,
            Box::new(|z| {
                [
                    z - (2.0 * PI * z).sin() / (2.0 * PI),
                    1.0 - (2.0 * PI * z).cos(),
                    2.0 * PI * (2.0 * PI * z).sin(),
                    4.0 * PI * PI * (2.0 * PI * z).cos(),
                ]
            }),
            true,
        ),
        // At 0, 1/2 and 1 the modified sine is in its outer, middle and outer part.
        (
            ModSinuslinie,
            Box::new(move |z| {
                if z <= 0.125 || z >= 0.875 {
                    let c = if z <= 0.125 { 0.0 } else { 4.0 };
                    [
                        k * (c + PI * z - 0.25 * (4.0 * PI * z).sin()),
                        k * (PI - PI * (4.0 * PI * z).cos()),
                        k * 4.0 * PI * PI * (4.0 * PI * z).sin(),
                        k * 16.0 * PI.powi(3) * (4.0 * PI * z).cos(),
                    ]
                } else {
                    let t = PI / 3.0 + 4.0 * PI * z / 3.0;
                    [
                        k * (2.0 + PI * z - 2.25 * t.sin()),
                        k * (PI - 3.0 * PI * t.cos()),
                        k * 4.0 * PI * PI * t.sin(),
                        k * 16.0 * PI.powi(3) / 3.0 * t.cos(),
                    ]
                }
            }),
            true,
        ),
        // Linear ramps of 1/8: jerk +8A at the start, −8A through the middle, +8A at the end.
        (
            BeschlTrapez,
            Box::new(move |z| match z {
                0.0 => [0.0, 0.0, 0.0, 8.0 * a_trap],
                1.0 => [1.0, 0.0, 0.0, 8.0 * a_trap],
                _ => [0.5, 3.0 / 8.0 * a_trap, 0.0, -8.0 * a_trap],
            }),
            true,
        ),
    ];
    for (law, f, c2) in &laws {
        let cam = one_segment(*law, 1.0, 1.0);
        for z in [0.0, 0.5, 1.0] {
            let v = cam.eval_piece(0, z);
            let want = f(z);
            for (i, (have, want)) in [v.position, v.velocity, v.acceleration, v.jerk]
                .into_iter()
                .zip(want)
                .enumerate()
            {
                assert!(
                    (have - want).abs() < 1e-9 * (1.0 + want.abs()),
                    "{law:?} derivative {i} at z = {z}: {have} ≠ {want}"
                );
            }
        }
        let ends = [
            cam.eval_piece(0, 0.0).acceleration,
            cam.eval_piece(0, 1.0).acceleration,
        ];
        assert_eq!(
            ends.iter().all(|a| a.abs() < 1e-9),
            *c2,
            "{law:?}: acceleration at the ends {ends:?}"
        );
    }
}

/// The cam editor's warnings (issue 12): where two laws meet with different velocities or
/// accelerations, the boundary condition of one of them is not met. A rest-in-rest chain is
/// continuous; a linear (POLYNOM1) segment after a rest point starts with a velocity the rest
/// point denies; a periodic table whose end velocity differs from its start jumps at the wrap.
#[test]
fn discontinuities_name_the_point_and_the_quantity() {
    use MotionFunctionType::*;
    use MotionPointType::*;
    let smooth = Cam::build(&CamTableData::motion_function(vec![
        pt(1, Polynom5, Rest, 0.0, 0.0),
        pt(2, Polynom5, Rest, 180.0, 100.0),
        pt(3, Polynom5, Rest, 360.0, 0.0),
    ]))
    .unwrap();
    assert_eq!(discontinuities(&smooth), vec![]);

    // MOTION points constrain nothing, so the build accepts what the laws make of them.
    let mut table = CamTableData::motion_function(vec![
        pt(1, Polynom5, Rest, 0.0, 0.0),
        pt(2, Polynom1, Motion, 100.0, 50.0),
        pt(3, Polynom5, Motion, 200.0, 150.0),
        pt(4, Polynom5, Rest, 360.0, 0.0),
    ]);
    table.periodic = true;
    let jumpy = Cam::build(&table).unwrap();
    let d = discontinuities(&jumpy);
    let at = |d: &[Discontinuity], i: usize| {
        d.iter()
            .filter(|j| j.index == i)
            .copied()
            .collect::<Vec<_>>()
    };
    // POLYNOM1 from (100, 50) to (200, 150) runs at 1 per master unit; POLYNOM5 before it
    // ends at rest (its end values are point 2's v = 0), the one after starts at rest.
    let one = at(&d, 1);
    assert_eq!(one.len(), 1, "{d:?}");
    assert_eq!(one[0].quantity, Quantity::Velocity);
    assert!(!one[0].wrap);
    assert_close(one[0].master, 100.0, 1e-12, "where");
    assert_close(one[0].before, 0.0, 1e-9, "rest before");
    assert_close(one[0].after, 1.0, 1e-9, "linear after");
    let two = at(&d, 2);
    assert_eq!(
        two.iter()
            .filter(|j| j.quantity == Quantity::Velocity)
            .count(),
        1,
        "{d:?}"
    );
    // The wrap of a table that ends at rest where it starts at rest is continuous.
    assert!(at(&d, 3).is_empty(), "{d:?}");

    // A periodic table that ends moving and starts at rest: the velocity jumps at the wrap,
    // reported at the last point; the position, which continues by the stroke, is not.
    let mut ends_moving = CamTableData::motion_function(vec![
        pt(1, Polynom5, Rest, 0.0, 0.0),
        pt(2, Polynom1, Motion, 100.0, 50.0),
        pt(3, Polynom1, Motion, 200.0, 150.0),
    ]);
    ends_moving.periodic = true;
    let d = discontinuities(&Cam::build(&ends_moving).unwrap());
    let wrap: Vec<_> = d.iter().filter(|j| j.wrap).collect();
    assert_eq!(wrap.len(), 1, "{d:?}");
    assert_eq!((wrap[0].index, wrap[0].quantity), (2, Quantity::Velocity));
    assert_close(wrap[0].before, 1.0, 1e-9, "end velocity");
    assert_close(wrap[0].after, 0.0, 1e-9, "start velocity");
    // A linear position table: its velocity is a staircase by definition, nothing is reported.
    let table = Cam::build(&CamTableData::positions(
        vec![[0.0, 0.0], [10.0, 5.0], [20.0, 0.0]],
        false,
    ))
    .unwrap();
    assert_eq!(discontinuities(&table), vec![]);
}

proptest::proptest! {
    /// The slave's interval hint (issue 27: O(1) lookups in large tables) changes nothing but
    /// the time: from any hint, at any master position, the values are bit for bit those of
    /// the plain search — rows with uneven spacing, inside and outside the range, and a
    /// motion function's segments.
    #[test]
    fn a_hinted_lookup_is_the_plain_lookup(
        gaps in proptest::collection::vec(1u8..5, 2..60),
        xs in proptest::collection::vec(-20.0f64..200.0, 1..40),
        hint in 0usize..100,
        periodic: bool,
        spline: bool,
    ) {
        let mut x = 0.0;
        let rows: Vec<[f64; 2]> = gaps
            .iter()
            .enumerate()
            .map(|(i, &g)| {
                if i > 0 {
                    x += f64::from(g) * 0.75;
                }
                [x, (i as f64 * 0.7).sin() * 10.0]
            })
            .collect();
        let mut t = CamTableData::positions(rows, false);
        t.periodic = periodic;
        t.interpolation = if spline { InterpolationType::Spline } else { InterpolationType::Linear };
        let mut function = CamTableData::motion_function(
            (0..8)
                .map(|i| pt(i + 1, MotionFunctionType::Polynom5, MotionPointType::Rest, i as f64 * 20.0, (i % 2) as f64 * 5.0))
                .collect(),
        );
        function.periodic = periodic;
        for cam in [Cam::build(&t).unwrap(), Cam::build(&function).unwrap()] {
            let mut h = hint;
            for &x in &xs {
                let plain = cam.eval_with(x, cam.interpolation);
                let hinted = cam.eval_hinted(x, cam.interpolation, &mut h);
                proptest::prop_assert_eq!(format!("{plain:?}"), format!("{hinted:?}"), "x = {}", x);
                let (_, xl) = cam.cycle_of(x);
                let plain = cam.eval_in_range(xl);
                let hinted = cam.eval_in_range_hinted(xl, cam.interpolation, &mut h);
                proptest::prop_assert_eq!(format!("{plain:?}"), format!("{hinted:?}"), "xl = {}", xl);
            }
        }
    }
}
