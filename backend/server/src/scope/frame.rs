//! What the cycle thread samples: the signals of an axis's status, the configuration that says
//! which ones go into which index of the frame, and the frame itself (`Copy`, fixed width: the
//! cycle thread writes one per cycle into the ring without allocating).

use motion::group::GroupStatus;
use motion::{AxisSlot, AxisStatus};
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::SCOPE_CHANNELS;

/// What the scope can sample of an axis (the axis's status after the cycle's kernel step), and
/// of a group (its status after the step: path position, velocity, acceleration, the entry).
#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize, ToSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum ScopeSignal {
    SetPosition,
    ActualPosition,
    SetVelocity,
    ActualVelocity,
    SetAcceleration,
    ActualAcceleration,
    FollowingError,
    /// A group's path length travelled since it last stood idle.
    PathPosition,
    /// A group's path velocity (`PathVelo`, after override).
    PathVelocity,
    PathAcceleration,
    /// The index of the running entry in its table.
    EntryIndex,
}

impl ScopeSignal {
    pub const ALL: [ScopeSignal; 11] = [
        ScopeSignal::SetPosition,
        ScopeSignal::ActualPosition,
        ScopeSignal::SetVelocity,
        ScopeSignal::ActualVelocity,
        ScopeSignal::SetAcceleration,
        ScopeSignal::ActualAcceleration,
        ScopeSignal::FollowingError,
        ScopeSignal::PathPosition,
        ScopeSignal::PathVelocity,
        ScopeSignal::PathAcceleration,
        ScopeSignal::EntryIndex,
    ];

    /// A signal of a group (else of an axis).
    pub fn of_group(self) -> bool {
        matches!(
            self,
            ScopeSignal::PathPosition
                | ScopeSignal::PathVelocity
                | ScopeSignal::PathAcceleration
                | ScopeSignal::EntryIndex
        )
    }

    pub fn name(self) -> &'static str {
        match self {
            ScopeSignal::SetPosition => "set_position",
            ScopeSignal::ActualPosition => "actual_position",
            ScopeSignal::SetVelocity => "set_velocity",
            ScopeSignal::ActualVelocity => "actual_velocity",
            ScopeSignal::SetAcceleration => "set_acceleration",
            ScopeSignal::ActualAcceleration => "actual_acceleration",
            ScopeSignal::FollowingError => "following_error",
            ScopeSignal::PathPosition => "path_position",
            ScopeSignal::PathVelocity => "path_velocity",
            ScopeSignal::PathAcceleration => "path_acceleration",
            ScopeSignal::EntryIndex => "entry_index",
        }
    }

    pub fn parse(s: &str) -> Option<ScopeSignal> {
        Self::ALL.into_iter().find(|x| x.name() == s)
    }

    #[inline]
    pub fn sample(self, s: &AxisStatus) -> f64 {
        match self {
            ScopeSignal::SetPosition => s.set_position,
            ScopeSignal::ActualPosition => s.actual_position,
            ScopeSignal::SetVelocity => s.set_velocity,
            ScopeSignal::ActualVelocity => s.actual_velocity,
            ScopeSignal::SetAcceleration => s.set_acceleration,
            ScopeSignal::ActualAcceleration => s.actual_acceleration,
            ScopeSignal::FollowingError => s.following_error,
            _ => f64::NAN,
        }
    }

    #[inline]
    pub fn sample_group(self, s: &GroupStatus) -> f64 {
        match self {
            ScopeSignal::PathPosition => s.path_position,
            ScopeSignal::PathVelocity => s.path_velocity,
            ScopeSignal::PathAcceleration => s.path_acceleration,
            ScopeSignal::EntryIndex => f64::from(s.entry_index),
            _ => f64::NAN,
        }
    }

    /// The unit of the signal for an axis whose positions are in `unit`.
    pub fn unit(self, unit: &str) -> String {
        match self {
            ScopeSignal::SetVelocity | ScopeSignal::ActualVelocity | ScopeSignal::PathVelocity => {
                format!("{unit}/s")
            }
            ScopeSignal::SetAcceleration
            | ScopeSignal::ActualAcceleration
            | ScopeSignal::PathAcceleration => format!("{unit}/s²"),
            ScopeSignal::EntryIndex => String::new(),
            _ => unit.to_string(),
        }
    }
}

/// What the cycle thread samples: `Copy`, handed over through the request queue.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ScopeConfig {
    pub generation: u64,
    pub channels: [Option<(AxisSlot, ScopeSignal)>; SCOPE_CHANNELS],
}

impl ScopeConfig {
    pub fn is_active(&self) -> bool {
        self.channels.iter().any(Option::is_some)
    }
}

/// One cycle's samples. Unused channels and axes missing from their slot read NaN.
#[derive(Clone, Copy, Debug)]
pub struct ScopeFrame {
    pub cycle: u64,
    pub generation: u64,
    pub values: [f64; SCOPE_CHANNELS],
}

impl ScopeFrame {
    /// Samples `config` from the statuses of one cycle (no allocation: runs on the cycle thread).
    #[inline]
    pub fn sample(
        cycle: u64,
        config: &ScopeConfig,
        axes: &[Option<AxisStatus>],
        groups: &[Option<GroupStatus>],
    ) -> ScopeFrame {
        let mut values = [f64::NAN; SCOPE_CHANNELS];
        for (v, c) in values.iter_mut().zip(&config.channels) {
            match c {
                // A group signal's slot is the group's.
                Some((slot, signal)) if signal.of_group() => {
                    if let Some(Some(s)) = groups.get(*slot as usize) {
                        *v = signal.sample_group(s);
                    }
                }
                Some((slot, signal)) => {
                    if let Some(Some(s)) = axes.get(*slot as usize) {
                        *v = signal.sample(s);
                    }
                }
                None => {}
            }
        }
        ScopeFrame {
            cycle,
            generation: config.generation,
            values,
        }
    }
}
