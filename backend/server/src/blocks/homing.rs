//! MC_Home: the homing modes and their options.

use motion::{CommandKind, HomingMode, HomingOptions};
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::*;
use crate::app::{AxisEntry, Registry};
use crate::error::AppResult;

/// The family's catalogue entries (the form: `crate::blocks`).
macro_rules! entries {
    ($catalogue:ident) => {
        $catalogue! {
            home: "home" at axes, HomeBody, HomeBody::to_kind, Operator, Done, [],
                "MC_Home";
        }
    };
}
pub(crate) use entries;

/// MC_Home.
#[derive(Clone, Debug, Default, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"mode": "direct", "position": 0.0}))]
pub struct HomeBody {
    /// None = the calibration value (#1075).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    #[schema(minimum = -1e12, maximum = 1e12)]
    pub position: Option<f64>,
    /// Default `default` (the referencing sequence configured by #1076).
    #[serde(default)]
    pub mode: HomingMode,
    /// Default: none set.
    #[serde(default)]
    pub options: HomingOptions,
}

impl HomeBody {
    pub fn to_kind(&self, _: &Registry, _: &AxisEntry) -> AppResult<CommandKind> {
        let mut c = Check::default();
        if let Some(p) = self.position {
            c.finite("position", p);
        }
        for (f, v) in [
            ("options.search_velocity", self.options.search_velocity),
            ("options.sync_velocity", self.options.sync_velocity),
        ] {
            if let Some(v) = v {
                c.positive(f, v);
            }
        }
        c.done(CommandKind::Home {
            position: self.position,
            mode: self.mode,
            options: self.options,
        })
    }
}
