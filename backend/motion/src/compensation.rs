//! A position compensation table (MC_TableBasedPositionCompensation, spec §4.5.12 and
//! `ST_PositionCompensationTableParameter`, §6.9): equidistant compensation values from
//! `min_position` to `max_position`, interpolated linearly, stored with the axis and built
//! off the cycle thread (the lookup does not allocate).

use serde::{Deserialize, Serialize};

/// `E_WorkDirection` (§6.11.7): in which travel direction a compensation applies.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum WorkDirection {
    #[default]
    Both,
    Positive,
    Negative,
}

/// The table: `compensation[i]` at `min_position + i · (max − min) / (n − 1)`.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[cfg_attr(feature = "schema", schema(example = json!({"min_position": -10.0, "max_position": 10.0,
    "compensation": [1.0, 0.9, 0.8, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2, 0.1, 0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.4, 0.3, 0.2, 0.1, 0.0]})))]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CompensationTable {
    /// Where the table starts (uncorrected set position).
    pub min_position: f64,
    /// Where it ends (> min_position).
    pub max_position: f64,
    /// The compensation values (axis units), equidistant from min to max; 2 to 100 000.
    pub compensation: Vec<f64>,
    /// The travel direction the compensation applies in (the other: none).
    #[serde(default)]
    pub direction: WorkDirection,
    /// The table repeats every max − min (a modulo axis's period); otherwise positions
    /// outside [min, max] take the nearer end's value.
    #[serde(default)]
    pub modulo: bool,
}

/// The largest table and the largest compensation value a table may hold.
pub const MAX_TABLE_ELEMENTS: usize = 100_000;
pub const MAX_COMPENSATION: f64 = 1e6;

impl CompensationTable {
    /// The first invalid field (its name and why), or Ok.
    pub fn validate(&self) -> Result<(), (&'static str, &'static str)> {
        let finite = |x: f64| x.is_finite() && x.abs() <= 1e12;
        if !finite(self.min_position) {
            return Err(("min_position", "must be a number from -1e12 to 1e12"));
        }
        if !(finite(self.max_position) && self.max_position > self.min_position) {
            return Err(("max_position", "must be a number above min_position"));
        }
        if !(2..=MAX_TABLE_ELEMENTS).contains(&self.compensation.len()) {
            return Err(("compensation", "must hold 2 to 100000 values"));
        }
        if !self
            .compensation
            .iter()
            .all(|c| c.is_finite() && c.abs() <= MAX_COMPENSATION)
        {
            return Err((
                "compensation",
                "every value must be a number from -1e6 to 1e6",
            ));
        }
        Ok(())
    }

    /// The compensation at `position` (linear between the points).
    pub fn at(&self, position: f64) -> f64 {
        let n = self.compensation.len();
        let span = self.max_position - self.min_position;
        if n < 2 || span <= 0.0 {
            return 0.0;
        }
        let mut x = position - self.min_position;
        if self.modulo {
            x = x.rem_euclid(span);
        }
        let step = span / (n - 1) as f64;
        let u = (x / step).clamp(0.0, (n - 1) as f64);
        let i = (u.floor() as usize).min(n - 2);
        let f = u - i as f64;
        self.compensation[i] + f * (self.compensation[i + 1] - self.compensation[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The manual's example (§4.5.12): 21 values from −10 to 10.
    fn manual() -> CompensationTable {
        CompensationTable {
            min_position: -10.0,
            max_position: 10.0,
            compensation: vec![
                1.0, 0.9, 0.8, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2, 0.1, 0.0, 0.1, 0.2, 0.3, 0.4, 0.5,
                0.4, 0.3, 0.2, 0.1, 0.0,
            ],
            direction: WorkDirection::Both,
            modulo: false,
        }
    }

    #[test]
    fn the_manuals_table_gives_its_points_and_interpolates_between_them() {
        let t = manual();
        t.validate().unwrap();
        for (i, c) in t.compensation.iter().enumerate() {
            assert!((t.at(-10.0 + i as f64) - c).abs() < 1e-12, "point {i}");
        }
        assert!((t.at(4.5) - 0.45).abs() < 1e-12);
        assert!((t.at(-0.25) - 0.025).abs() < 1e-12);
        // Outside: the nearer end's value.
        assert_eq!(t.at(-50.0), 1.0);
        assert_eq!(t.at(50.0), 0.0);
        let m = CompensationTable {
            modulo: true,
            ..manual()
        };
        assert!((m.at(25.0) - m.at(5.0)).abs() < 1e-12);
        assert!((m.at(-14.5) - m.at(5.5)).abs() < 1e-12);
    }

    #[test]
    fn invalid_tables_name_their_field() {
        let mut t = manual();
        t.max_position = -10.0;
        assert_eq!(t.validate().unwrap_err().0, "max_position");
        let mut t = manual();
        t.compensation = vec![1.0];
        assert_eq!(t.validate().unwrap_err().0, "compensation");
        let mut t = manual();
        t.compensation[3] = f64::NAN;
        assert_eq!(t.validate().unwrap_err().0, "compensation");
        let mut t = manual();
        t.min_position = f64::INFINITY;
        assert_eq!(t.validate().unwrap_err().0, "min_position");
    }
}
