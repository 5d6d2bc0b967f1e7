//! A path as programmed (TF5420 §4.3): the entries of an `MC_PATH_DATA_REF` table, with
//! their inputs as the Preparation blocks take them. Built off the cycle thread (the table's
//! `Vec`), checked there and again by the group when MC_MovePath hands it over; the group
//! turns entries into geometry only when it accepts them, because the first entry starts
//! where the group is (or will be) at that moment.

use crate::command::BufferMode;
pub use crate::command::{CoordTransform, PathValue};
use crate::error::ErrorId;
use crate::path::{CircMode, CircPathChoice, PathPoint};

/// Entries a MovePath takes at most. TwinCAT's table holds 30; a program that cuts a contour
/// into many short lines needs more, and the group's look-ahead is linear in the number of
/// queued entries (decision 123). The group's queue holds [`QUEUE_ENTRIES`].
pub const MAX_PATH_ENTRIES: usize = 256;
/// Entries a group keeps queued at most (running and buffered MovePaths together).
pub const QUEUE_ENTRIES: usize = 512;

/// `MC_TRANSITION_MODE`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TransitionMode {
    /// mcTransModeNone: no blending; the path stops at the corner.
    #[default]
    None,
    /// mcTransModeCornerDistance (1 parameter): a tolerance sphere of that radius.
    CornerDistance,
    /// mcTransModeCornerDistanceAdvanced (2 parameters): r_in on the previous segment,
    /// r_out on this one.
    CornerDistanceAdvanced,
    /// Named by the type, not supported by the CM group (§5.5): refused.
    StartVelocity,
    ConstantVelocity,
    MaxCornerDeviation,
}

/// The motion inputs shared by the linear and the circular Preparation blocks.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EntryMotion {
    /// Maximum path velocity of the segment (> 0, mandatory: `MC_INVALID` by default).
    pub velocity: PathValue,
    pub acceleration: PathValue,
    pub deceleration: PathValue,
    pub jerk: PathValue,
    pub buffer_mode: BufferMode,
    pub transition_mode: TransitionMode,
    /// TransitionParameter[1..count].
    pub transition_parameters: [f64; 2],
    pub transition_parameter_count: u8,
}

/// One row of a path table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PathEntry {
    /// MC_MoveLinearAbsolutePreparation: `position[..count]` in the group's axis order
    /// (convention axes, then ADDAX1..n).
    Linear {
        position: PathPoint,
        count: u8,
        motion: EntryMotion,
        invoke_id: u32,
    },
    /// MC_MoveCircularAbsolutePreparation: `aux` is X, Y, Z of the AuxPoint (a point on the
    /// arc, its centre, or the normal whose length is the radius: `mode`).
    Circular {
        mode: CircMode,
        aux: [f64; 3],
        end_point: PathPoint,
        count: u8,
        path_choice: CircPathChoice,
        motion: EntryMotion,
        invoke_id: u32,
    },
    /// MC_BlockerPreparation: the path waits here until MC_ReleaseBlocker(`blocker_id`).
    Blocker {
        blocker_id: u32,
        buffer_mode: BufferMode,
        invoke_id: u32,
    },
    /// MC_DwellTimePreparation: the path stands for `time` seconds (0: an exact stop).
    Dwell {
        time: f64,
        buffer_mode: BufferMode,
        invoke_id: u32,
    },
    /// MC_SetCoordinateTransformPreparation: the entries after it are read in `transform`
    /// (it neither stops the path nor breaks a blend: the geometry is in machine coordinates).
    CoordinateTransform { transform: CoordTransform },
}

impl PathEntry {
    pub fn invoke_id(&self) -> u32 {
        match *self {
            PathEntry::Linear { invoke_id, .. }
            | PathEntry::Circular { invoke_id, .. }
            | PathEntry::Blocker { invoke_id, .. }
            | PathEntry::Dwell { invoke_id, .. } => invoke_id,
            PathEntry::CoordinateTransform { .. } => 0,
        }
    }

    pub fn buffer_mode(&self) -> BufferMode {
        match *self {
            PathEntry::Linear { motion, .. } | PathEntry::Circular { motion, .. } => {
                motion.buffer_mode
            }
            PathEntry::Blocker { buffer_mode, .. } | PathEntry::Dwell { buffer_mode, .. } => {
                buffer_mode
            }
            // Joins as the entry after it does: a frame switch is not a job of its own.
            PathEntry::CoordinateTransform { .. } => BufferMode::Buffered,
        }
    }

    fn motion(&self) -> Option<&EntryMotion> {
        match self {
            PathEntry::Linear { motion, .. } | PathEntry::Circular { motion, .. } => Some(motion),
            _ => None,
        }
    }

    /// The corner radii (r_in, r_out) this entry asks for at its start; None: an exact stop.
    pub fn corner_distance(&self) -> Option<(f64, f64)> {
        let m = self.motion()?;
        let p = m.transition_parameters;
        match m.transition_mode {
            TransitionMode::CornerDistance => Some((p[0], p[0])),
            TransitionMode::CornerDistanceAdvanced => Some((p[0], p[1])),
            _ => None,
        }
    }

    /// Checks what does not depend on where the path starts (§7.3, §11 items 10–13):
    /// `first` = the first entry of its table; `axes` = the group's axis count.
    /// The field that fails and the error.
    pub fn check(
        &self,
        first: bool,
        axes: usize,
        planar: bool,
    ) -> Result<(), (&'static str, ErrorId)> {
        match *self {
            PathEntry::CoordinateTransform { transform } => transform
                .check(planar)
                .map_err(|f| (f, ErrorId::PARAMETER_NOT_CORRECT)),
            PathEntry::Linear {
                count,
                motion,
                position,
                ..
            } => {
                if count as usize != axes {
                    return Err(("position", ErrorId::POSITION_COUNT_INVALID));
                }
                if position[..axes].iter().any(|x| !x.is_finite()) {
                    return Err(("position", ErrorId::PARAMETER_NOT_CORRECT));
                }
                check_motion(&motion, first)
            }
            PathEntry::Circular {
                count,
                motion,
                end_point,
                aux,
                ..
            } => {
                if count as usize != axes {
                    return Err(("end_point", ErrorId::POSITION_COUNT_INVALID));
                }
                if end_point[..axes].iter().any(|x| !x.is_finite()) {
                    return Err(("end_point", ErrorId::PARAMETER_NOT_CORRECT));
                }
                if aux.iter().any(|x| !x.is_finite()) {
                    return Err(("aux_point", ErrorId::PARAMETER_NOT_CORRECT));
                }
                check_motion(&motion, first)
            }
            PathEntry::Blocker {
                blocker_id,
                buffer_mode,
                ..
            } => {
                if blocker_id == 0 {
                    return Err(("blocker_id", ErrorId::BLOCKER_ID_INVALID));
                }
                check_stop_buffer(buffer_mode, first)
            }
            PathEntry::Dwell {
                time, buffer_mode, ..
            } => {
                if !(time.is_finite() && time >= 0.0) {
                    return Err(("time", ErrorId::DWELL_TIME_INVALID));
                }
                check_stop_buffer(buffer_mode, first)
            }
        }
    }
}

/// Blocker and Dwell take Buffered, or Aborting as the first entry of a table.
fn check_stop_buffer(mode: BufferMode, first: bool) -> Result<(), (&'static str, ErrorId)> {
    match mode {
        BufferMode::Buffered => Ok(()),
        BufferMode::Aborting if first => Ok(()),
        _ => Err(("buffer_mode", ErrorId::BUFFER_MODE_INVALID)),
    }
}

fn check_value(v: PathValue, min: f64, strict: bool) -> bool {
    match v {
        PathValue::Value(x) => x.is_finite() && if strict { x > min } else { x >= min },
        PathValue::Default | PathValue::Maximum => true,
        PathValue::Ignore => false,
    }
}

/// §2.4 bounds and the §7.3 matrix.
fn check_motion(m: &EntryMotion, first: bool) -> Result<(), (&'static str, ErrorId)> {
    // The velocity is mandatory (MC_INVALID by default): a number, or "maximum".
    let velocity_ok = match m.velocity {
        PathValue::Value(v) => v.is_finite() && v > 0.0,
        PathValue::Maximum => true,
        PathValue::Default | PathValue::Ignore => false,
    };
    if !velocity_ok {
        return Err(("velocity", ErrorId::PATH_DYNAMICS_INVALID));
    }
    if !check_value(m.acceleration, 1.0, false) {
        return Err(("acceleration", ErrorId::PATH_DYNAMICS_INVALID));
    }
    if !check_value(m.deceleration, 1.0, false) {
        return Err(("deceleration", ErrorId::PATH_DYNAMICS_INVALID));
    }
    if !check_value(m.jerk, 100.0, false) {
        return Err(("jerk", ErrorId::PATH_DYNAMICS_INVALID));
    }
    use BufferMode as B;
    use TransitionMode as T;
    let needs = match m.transition_mode {
        T::None => 0,
        T::CornerDistance => 1,
        T::CornerDistanceAdvanced => 2,
        T::StartVelocity | T::ConstantVelocity | T::MaxCornerDeviation => {
            return Err(("transition_mode", ErrorId::TRANSITION_MODE_INVALID));
        }
    };
    match (m.transition_mode, m.buffer_mode) {
        (_, B::Aborting) if !first => {
            return Err(("buffer_mode", ErrorId::BUFFER_MODE_INVALID));
        }
        (T::None, B::Aborting | B::Buffered) => {}
        (T::None, B::BlendingPrevious) => {
            return Err(("transition_mode", ErrorId::TRANSITION_MODE_INVALID));
        }
        (T::CornerDistance | T::CornerDistanceAdvanced, B::Aborting | B::BlendingPrevious) => {}
        (T::CornerDistance | T::CornerDistanceAdvanced, B::Buffered) => {
            return Err(("transition_mode", ErrorId::TRANSITION_MODE_INVALID));
        }
        (_, _) => return Err(("buffer_mode", ErrorId::BUFFER_MODE_INVALID)),
    }
    // None ignores its parameters ("no effect"); the corner modes need theirs, ≥ 0.
    if needs > 0 {
        if m.transition_parameter_count as usize != needs {
            return Err(("transition_parameters", ErrorId::TRANSITION_MODE_INVALID));
        }
        if m.transition_parameters[..needs]
            .iter()
            .any(|p| !(p.is_finite() && *p >= 0.0))
        {
            return Err(("transition_parameters", ErrorId::TRANSITION_MODE_INVALID));
        }
    }
    Ok(())
}

/// A whole table as MC_MovePath hands it over.
#[derive(Clone, Debug, PartialEq)]
pub struct PathTable {
    pub entries: Vec<PathEntry>,
}

impl PathTable {
    /// Every entry checked (the first one as the first); the entry index, field and error.
    pub fn check(&self, axes: usize, planar: bool) -> Result<(), (usize, &'static str, ErrorId)> {
        if self.entries.is_empty() {
            return Err((0, "entries", ErrorId::PARAMETER_NOT_CORRECT));
        }
        if self.entries.len() > MAX_PATH_ENTRIES {
            return Err((0, "entries", ErrorId::PATH_TOO_LONG));
        }
        // The first entry that is a job decides how the table joins (§7.3); frame switches
        // before it do not count.
        let first_job = self
            .entries
            .iter()
            .position(|e| !matches!(e, PathEntry::CoordinateTransform { .. }))
            .unwrap_or(0);
        for (i, e) in self.entries.iter().enumerate() {
            e.check(i == first_job, axes, planar)
                .map_err(|(f, id)| (i, f, id))?;
        }
        Ok(())
    }

    /// The BufferMode the table joins the queue with: its first job's.
    pub fn joins_with(&self) -> BufferMode {
        self.entries
            .iter()
            .find(|e| !matches!(e, PathEntry::CoordinateTransform { .. }))
            .map_or(BufferMode::Buffered, PathEntry::buffer_mode)
    }

    /// The first job (its corner radii decide a blend from the queue).
    pub fn first_job(&self) -> Option<&PathEntry> {
        self.entries
            .iter()
            .find(|e| !matches!(e, PathEntry::CoordinateTransform { .. }))
    }
}
