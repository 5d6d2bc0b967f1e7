//! Read-type blocks of one axis (`GET /api/v1/axes/{axis}/<name>`), which are also websocket
//! methods of the same name with params = the query plus `axis`: MC_ConvertIncPosToPos,
//! MC_ConvertPosToIncPos, MC_ReadAxisComponents. They answer from the axis's latest status
//! and configuration; no command is made.

use std::sync::Arc;

use axum::Json;
use axum::extract::{Path, State};
use serde_json::Value;

use super::Q;
use crate::app::AppState;
use crate::error::{AppError, AppResult};
use crate::model::*;
use crate::service::reads;

/// A read block: its method name, the schema of its params (besides `axis`) and of its result.
pub struct Read {
    pub name: &'static str,
    pub params: Option<&'static str>,
    pub result: &'static str,
    pub summary: &'static str,
}

pub const READS: &[Read] = &[
    Read {
        name: "convert-inc-pos-to-pos",
        params: Some("IncPosQuery"),
        result: "PositionConversion",
        summary: "MC_ConvertIncPosToPos: the axis position of an encoder count",
    },
    Read {
        name: "convert-pos-to-inc-pos",
        params: Some("PositionQuery"),
        result: "PositionConversion",
        summary: "MC_ConvertPosToIncPos: the encoder count of an axis position",
    },
    Read {
        name: "read-axis-components",
        params: None,
        result: "AxisComponents",
        summary: "MC_ReadAxisComponents: the encoder, controller and drive of the axis",
    },
    Read {
        name: "read-drive-operation-mode",
        params: None,
        result: "DriveOperationModeResource",
        summary: "MC_ReadDriveOperationMode: the operation mode the drive reports",
    },
];

#[utoipa::path(get, path = "/api/v1/axes/{axis}/read-drive-operation-mode", tag = "axes",
    summary = "MC_ReadDriveOperationMode: the operation mode the drive reports",
    description = "From the drive's feedback of the latest cycle (CiA-402 0x6061; the simulated drive says which \
mode it runs in). Check it after MC_TorqueControl before enabling again (the manual's warning about drives left in \
torque mode). Also the websocket method `read-drive-operation-mode` {axis}.",
    params(("axis" = String, Path, description = "axis id or name", example = "x")),
    responses((status = 200, body = DriveOperationModeResource), super::errors::ReadErrors))]
pub async fn read_drive_operation_mode(
    State(s): State<Arc<AppState>>,
    Path(axis): Path<String>,
) -> AppResult<Json<DriveOperationModeResource>> {
    Ok(Json(reads::read_drive_operation_mode(&s, &axis)?))
}

#[utoipa::path(get, path = "/api/v1/axes/{axis}/convert-inc-pos-to-pos", tag = "axes",
    summary = "MC_ConvertIncPosToPos: the axis position of an encoder count",
    description = "Scaled with the encoder scaling now and counted from the encoder count of the latest cycle \
(the status's `encoder_count`, `actual_position`) the short way round the counter (AxisEncoderMask #1043): past \
and future overflows are not considered. Also the websocket method `convert-inc-pos-to-pos` {axis, inc_pos}.",
    params(("axis" = String, Path, description = "axis id or name", example = "x"), IncPosQuery),
    responses((status = 200, body = PositionConversion), super::errors::AxisFunctionErrors))]
pub async fn convert_inc_pos_to_pos(
    State(s): State<Arc<AppState>>,
    Path(axis): Path<String>,
    Q(q): Q<IncPosQuery>,
) -> AppResult<Json<PositionConversion>> {
    Ok(Json(reads::convert_inc_pos_to_pos(&s, &axis, &q)?))
}

#[utoipa::path(get, path = "/api/v1/axes/{axis}/convert-pos-to-inc-pos", tag = "axes",
    summary = "MC_ConvertPosToIncPos: the encoder count of an axis position",
    description = "Counted from the encoder count of the latest cycle; a position half the counter's range or more \
away from the actual one is a 422 at `position` with `error_id` 0x70B3 position_out_of_counter_range (the counter \
would overflow on the way). Also the \
websocket method `convert-pos-to-inc-pos` {axis, position}.",
    params(("axis" = String, Path, description = "axis id or name", example = "x"), PositionQuery),
    responses((status = 200, body = PositionConversion), super::errors::AxisFunctionErrors))]
pub async fn convert_pos_to_inc_pos(
    State(s): State<Arc<AppState>>,
    Path(axis): Path<String>,
    Q(q): Q<PositionQuery>,
) -> AppResult<Json<PositionConversion>> {
    Ok(Json(reads::convert_pos_to_inc_pos(&s, &axis, &q)?))
}

#[utoipa::path(get, path = "/api/v1/axes/{axis}/read-axis-components", tag = "axes",
    summary = "MC_ReadAxisComponents: the encoder, controller and drive of the axis",
    description = "Also the websocket method `read-axis-components` {axis}.",
    params(("axis" = String, Path, description = "axis id or name", example = "x")),
    responses((status = 200, body = AxisComponents), super::errors::ReadErrors))]
pub async fn read_axis_components(
    State(s): State<Arc<AppState>>,
    Path(axis): Path<String>,
) -> AppResult<Json<AxisComponents>> {
    Ok(Json(reads::read_axis_components(&s, &axis)?))
}

/// A read sent over the websocket: `params` without `axis` read as its query; `None` for a
/// method that is not a read.
pub fn dispatch(s: &AppState, method: &str, axis: &str, params: Value) -> Option<AppResult<Value>> {
    // As a REST body is read: the same field errors.
    fn query<T: serde::de::DeserializeOwned + utoipa::ToSchema>(params: Value) -> AppResult<T> {
        super::from_value::<T>(params).map(|(t, _)| t)
    }
    fn no_params(params: &Value) -> AppResult<()> {
        match params.as_object() {
            Some(m) if m.is_empty() => Ok(()),
            _ => Err(AppError::field("params", "takes only `axis`")),
        }
    }
    fn json<T: serde::Serialize>(v: AppResult<T>) -> AppResult<Value> {
        v.map(|r| serde_json::to_value(r).unwrap_or(Value::Null))
    }
    Some(match method {
        "convert-inc-pos-to-pos" => json(
            query::<IncPosQuery>(params).and_then(|q| reads::convert_inc_pos_to_pos(s, axis, &q)),
        ),
        "convert-pos-to-inc-pos" => json(
            query::<PositionQuery>(params).and_then(|q| reads::convert_pos_to_inc_pos(s, axis, &q)),
        ),
        "read-axis-components" => {
            json(no_params(&params).and_then(|()| reads::read_axis_components(s, axis)))
        }
        "read-drive-operation-mode" => {
            json(no_params(&params).and_then(|()| reads::read_drive_operation_mode(s, axis)))
        }
        _ => return None,
    })
}
