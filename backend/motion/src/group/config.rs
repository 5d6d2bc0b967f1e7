//! What a coordinated-motion group is configured with (TF5420 §2.2–§2.4): its spatial axes
//! convention, how many auxiliary axes it takes, and the path dynamics that stand for
//! `MC_DEFAULT` and cap `MC_MAXIMUM`. Which axis holds which role is runtime membership
//! (MC_AddAxisToGroup), kept by the group itself.

use serde::{Deserialize, Serialize};

use crate::error::ErrorId;

/// Index of a group slot in the kernel (0-based).
pub use crate::command::{GroupId, GroupRole};

/// Groups a kernel holds at most (fixed so that the cycle never allocates).
pub const MAX_GROUPS: usize = 16;

/// `MC_AXES_CONVENTION`: which Cartesian axes form the path.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AxesConvention {
    /// mcAxesConv2DCartesianXY: X, Y.
    #[default]
    Xy,
    /// mcAxesConv3DCartesianXYZ: X, Y, Z.
    Xyz,
    /// mcAxesConv4DCartesianXYZC: X, Y, Z and a rotation C about Z.
    Xyzc,
}

impl AxesConvention {
    /// Roles the convention needs, in the order of a position vector.
    pub fn roles(self) -> &'static [GroupRole] {
        match self {
            AxesConvention::Xy => &[GroupRole::X, GroupRole::Y],
            AxesConvention::Xyz => &[GroupRole::X, GroupRole::Y, GroupRole::Z],
            AxesConvention::Xyzc => &[GroupRole::X, GroupRole::Y, GroupRole::Z, GroupRole::C],
        }
    }

    /// The path lies in the XY plane (arcs too).
    pub fn planar(self) -> bool {
        self == AxesConvention::Xy
    }
}

/// Path dynamics of a group (path units: mm, mm/s … along the Cartesian path).
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PathDynamics {
    #[cfg_attr(feature = "schema", schema(exclusive_minimum = 0.0, maximum = 1e9))]
    pub velocity: f64,
    /// ≥ 1 (TF5420 §2.4).
    #[cfg_attr(feature = "schema", schema(minimum = 1.0, maximum = 1e12))]
    pub acceleration: f64,
    /// ≥ 1.
    #[cfg_attr(feature = "schema", schema(minimum = 1.0, maximum = 1e12))]
    pub deceleration: f64,
    /// ≥ 100.
    #[cfg_attr(feature = "schema", schema(minimum = 100.0, maximum = 1e15))]
    pub jerk: f64,
}

impl PathDynamics {
    /// Checked as TF5420 bounds path inputs: velocity > 0, acceleration and deceleration ≥ 1,
    /// jerk ≥ 100, all finite. Names the first field that fails.
    pub fn check(&self) -> Result<(), &'static str> {
        let ok = |x: f64, min: f64, strict: bool| {
            x.is_finite() && if strict { x > min } else { x >= min }
        };
        // The upper bounds are the schema's: beyond them no machine moves and the planner's
        // arithmetic loses its resolution.
        if !ok(self.velocity, 0.0, true) || self.velocity > 1e9 {
            return Err("velocity");
        }
        if !ok(self.acceleration, 1.0, false) || self.acceleration > 1e12 {
            return Err("acceleration");
        }
        if !ok(self.deceleration, 1.0, false) || self.deceleration > 1e12 {
            return Err("deceleration");
        }
        if !ok(self.jerk, 100.0, false) || self.jerk > 1e15 {
            return Err("jerk");
        }
        Ok(())
    }
}

/// The configuration of one CM group.
#[cfg_attr(feature = "schema", derive(utoipa::ToSchema))]
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GroupConfig {
    /// Spatial Axes Convention.
    pub convention: AxesConvention,
    /// Additional Axes Count (0…8): auxiliary axes without geometric meaning, ADDAX1..n.
    #[cfg_attr(feature = "schema", schema(minimum = 0, maximum = 8))]
    pub additional_axes: u8,
    /// What `"default"` stands for in a path entry or a halt/stop (velocity: the path
    /// velocity a jog-like UI offers; entries must give their own velocity).
    pub default_dynamics: PathDynamics,
    /// What `"maximum"` stands for, and the cap of every commanded path value.
    pub maximum_dynamics: PathDynamics,
    /// Time Override Ramp Time (s): how fast a new override takes effect (0…10 s).
    #[cfg_attr(feature = "schema", schema(minimum = 0.0, maximum = 10.0))]
    pub override_ramp_time: f64,
}

impl Default for GroupConfig {
    fn default() -> Self {
        GroupConfig {
            convention: AxesConvention::Xy,
            additional_axes: 0,
            default_dynamics: PathDynamics {
                velocity: 100.0,
                acceleration: 1000.0,
                deceleration: 1000.0,
                jerk: 10_000.0,
            },
            maximum_dynamics: PathDynamics {
                velocity: 1000.0,
                acceleration: 10_000.0,
                deceleration: 10_000.0,
                jerk: 1_000_000.0,
            },
            override_ramp_time: 0.1,
        }
    }
}

impl GroupConfig {
    /// Roles the group needs before it can be enabled: the convention's, then ADDAX1..n.
    pub fn roles(&self) -> impl Iterator<Item = GroupRole> + '_ {
        let spatial = self.convention.roles();
        spatial.iter().copied().chain(
            GroupRole::ALL[4..4 + self.additional_axes.min(8) as usize]
                .iter()
                .copied(),
        )
    }

    /// Whether `role` belongs to this group's configuration.
    pub fn has_role(&self, role: GroupRole) -> bool {
        self.roles().any(|r| r == role)
    }

    /// Number of axes the group needs (note 4).
    pub fn axis_count(&self) -> usize {
        self.convention.roles().len() + self.additional_axes.min(8) as usize
    }

    /// Field by field; the first field that fails and why.
    pub fn validate(&self) -> Result<(), (&'static str, ErrorId)> {
        if self.additional_axes > 8 {
            return Err(("additional_axes", ErrorId::GROUP_CONFIG_INVALID));
        }
        if let Err(f) = self.default_dynamics.check() {
            return Err((
                match f {
                    "velocity" => "default_dynamics.velocity",
                    "acceleration" => "default_dynamics.acceleration",
                    "deceleration" => "default_dynamics.deceleration",
                    _ => "default_dynamics.jerk",
                },
                ErrorId::PATH_DYNAMICS_INVALID,
            ));
        }
        if let Err(f) = self.maximum_dynamics.check() {
            return Err((
                match f {
                    "velocity" => "maximum_dynamics.velocity",
                    "acceleration" => "maximum_dynamics.acceleration",
                    "deceleration" => "maximum_dynamics.deceleration",
                    _ => "maximum_dynamics.jerk",
                },
                ErrorId::PATH_DYNAMICS_INVALID,
            ));
        }
        let (d, m) = (self.default_dynamics, self.maximum_dynamics);
        for (name, dv, mv) in [
            ("default_dynamics.velocity", d.velocity, m.velocity),
            (
                "default_dynamics.acceleration",
                d.acceleration,
                m.acceleration,
            ),
            (
                "default_dynamics.deceleration",
                d.deceleration,
                m.deceleration,
            ),
            ("default_dynamics.jerk", d.jerk, m.jerk),
        ] {
            if dv > mv {
                return Err((name, ErrorId::PATH_DYNAMICS_INVALID));
            }
        }
        if !(self.override_ramp_time.is_finite() && (0.0..=10.0).contains(&self.override_ramp_time))
        {
            return Err(("override_ramp_time", ErrorId::GROUP_CONFIG_INVALID));
        }
        Ok(())
    }
}
