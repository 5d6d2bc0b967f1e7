//! Modulo positioning (MC_MoveModulo, spec §5.1.5): where a modulo target ends in absolute
//! coordinates, including the tolerance window and full turns.

use crate::command::Direction;
use crate::error::ErrorId;

/// Absolute end position of a modulo move of target `t` (≥ 0) from set position `s` on an axis
/// with period `period` and tolerance window half width `tf`. `from_standstill`: targets
/// ≥ period add full turns; in motion the extra turns are ignored (the shortest path in the
/// given direction is taken).
pub fn modulo_end_position(
    s: f64,
    t: f64,
    period: f64,
    tf: f64,
    direction: Direction,
    from_standstill: bool,
) -> Result<f64, ErrorId> {
    if period <= 0.0 || !period.is_finite() {
        return Err(ErrorId::PARAMETER_NOT_CORRECT);
    }
    if t < 0.0 || !t.is_finite() {
        return Err(ErrorId::PARAMETER_NOT_CORRECT);
    }
    let base_turn = (s / period).floor() * period;
    let t0 = t.rem_euclid(period);
    let extra_turns = if from_standstill {
        (t / period).floor()
    } else {
        0.0
    };
    let mut c = base_turn + t0;
    match direction {
        Direction::Positive => {
            if c < s - tf {
                c += period;
            }
            Ok(c + extra_turns * period)
        }
        Direction::Negative => {
            if c > s + tf {
                c -= period;
            }
            Ok(c - extra_turns * period)
        }
        Direction::ShortestWay => {
            if t >= period {
                return Err(ErrorId::INVALID_MODE);
            }
            // Candidates one period either side; the nearest wins (ties: positive).
            let mut best = c;
            for cand in [c - period, c + period] {
                if (cand - s).abs() < (best - s).abs() {
                    best = cand;
                }
            }
            Ok(best)
        }
        Direction::CurrentDirection => Err(ErrorId::INVALID_MODE),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use Direction::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }

    /// Spec §5.1.5 Table 1: start 90, period 360 (tolerance window irrelevant here).
    #[test]
    fn table_1_positioning_by_less_than_one_turn() {
        let rows = [
            (Positive, 90.0, 0.0, 270.0, 360.0, 0.0),
            (Positive, 90.0, 360.0, 630.0, 720.0, 0.0),
            (Positive, 90.0, 720.0, 990.0, 1080.0, 0.0),
            (Negative, 90.0, 0.0, -90.0, 0.0, 0.0),
            (Negative, 90.0, 360.0, -450.0, -360.0, 0.0),
            (Negative, 90.0, 720.0, -810.0, -720.0, 0.0),
            (ShortestWay, 90.0, 0.0, -90.0, 0.0, 0.0),
        ];
        for (dir, start, target, travel, end, mend) in rows {
            let e = modulo_end_position(start, target, 360.0, 1.0, dir, true).unwrap();
            assert!(close(e, end), "{dir:?} {start} {target}: {e} != {end}");
            assert!(close(e - start, travel));
            assert!(close(e.rem_euclid(360.0), mend));
        }
    }

    /// Spec §5.1.5 Table 2: start ≈ 90, tolerance window 1°, every row.
    #[test]
    fn table_2_positioning_by_full_turns_with_tolerance_window() {
        let rows = [
            (Positive, 90.00, 90.0, 0.00, 90.0),
            (Positive, 90.90, 90.0, -0.90, 90.0),
            (Positive, 91.10, 90.0, 358.90, 450.0),
            (Positive, 89.10, 90.0, 0.90, 90.0),
            (Positive, 88.90, 90.0, 1.10, 90.0),
            (Positive, 90.00, 450.0, 360.00, 450.0),
            (Positive, 90.90, 450.0, 359.10, 450.0),
            (Positive, 91.10, 450.0, 718.90, 810.0),
            (Positive, 89.10, 450.0, 360.90, 450.0),
            (Positive, 88.90, 450.0, 361.10, 450.0),
            (Positive, 90.00, 810.0, 720.00, 810.0),
            (Positive, 90.90, 810.0, 719.10, 810.0),
            (Positive, 91.10, 810.0, 1078.90, 1170.0),
            (Positive, 89.10, 810.0, 720.90, 810.0),
            (Positive, 88.90, 810.0, 721.10, 810.0),
            (Negative, 90.00, 90.0, 0.00, 90.0),
            (Negative, 90.90, 90.0, -0.90, 90.0),
            (Negative, 91.10, 90.0, -1.10, 90.0),
            (Negative, 89.10, 90.0, 0.90, 90.0),
            (Negative, 88.90, 90.0, -358.90, -270.0),
            (Negative, 90.00, 450.0, -360.00, -270.0),
            (Negative, 90.90, 450.0, -360.90, -270.0),
            (Negative, 91.10, 450.0, -361.10, -270.0),
            (Negative, 89.10, 450.0, -359.10, -270.0),
            (Negative, 88.90, 450.0, -718.90, -630.0),
            (Negative, 90.00, 810.0, -720.00, -630.0),
            (Negative, 90.90, 810.0, -720.90, -630.0),
            (Negative, 91.10, 810.0, -721.10, -630.0),
            (Negative, 89.10, 810.0, -719.10, -630.0),
            (Negative, 88.90, 810.0, -1078.90, -990.0),
        ];
        for (dir, start, target, travel, end) in rows {
            let e = modulo_end_position(start, target, 360.0, 1.0, dir, true).unwrap();
            assert!(close(e, end), "{dir:?} {start} {target}: {e} != {end}");
            assert!(
                close(e - start, travel),
                "{dir:?} {start} {target}: travel {}",
                e - start
            );
            assert!(close(e.rem_euclid(360.0), 90.0));
        }
    }

    #[test]
    fn shortest_way_rejects_targets_beyond_one_period_and_negative_targets() {
        assert_eq!(
            modulo_end_position(90.0, 360.0, 360.0, 1.0, ShortestWay, true),
            Err(ErrorId::INVALID_MODE)
        );
        assert_eq!(
            modulo_end_position(90.0, -1.0, 360.0, 1.0, Positive, true),
            Err(ErrorId::PARAMETER_NOT_CORRECT)
        );
        assert!(close(
            modulo_end_position(350.0, 10.0, 360.0, 1.0, ShortestWay, true).unwrap(),
            370.0
        ));
    }

    #[test]
    fn from_motion_extra_turns_are_ignored() {
        assert!(close(
            modulo_end_position(90.0, 450.0, 360.0, 1.0, Positive, false).unwrap(),
            90.0
        ));
        assert!(close(
            modulo_end_position(100.0, 450.0, 360.0, 1.0, Positive, false).unwrap(),
            450.0
        ));
    }
}
