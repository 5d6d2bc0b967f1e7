//! Axis configurations, status, parameters and the whole-configuration document: the HTTP
//! side (the rules are `service::axes`).

use std::sync::Arc;

use axum::Json;
use axum::extract::{Path, State};
use axum::http::{HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};

use super::errors::{ConfigErrors, ReadErrors};
use super::{Client, JsonBody, Q};
use crate::app::AppState;
use crate::error::AppResult;
use crate::model::ReplaceQuery;
use crate::model::{
    AxisConfigDto, AxisResource, ConfigDocument, ParameterResource, ParameterWrite,
    PeakResetResource, StatusResource,
};
use crate::service::axes;
use crate::store::{self, AuditEntry};

#[utoipa::path(get, path = "/api/v1/axes", tag = "axes", summary = "List the axes",
    responses((status = 200, description = "All axes, by id", body = Vec<AxisResource>)))]
pub async fn list_axes(State(s): State<Arc<AppState>>) -> Json<Vec<AxisResource>> {
    Json(axes::list(&s))
}

#[utoipa::path(get, path = "/api/v1/axes/{axis}", tag = "axes", summary = "One axis",
    params(("axis" = String, Path, description = "axis id or name", example = "x")),
    responses((status = 200, description = "The axis", body = AxisResource), ReadErrors))]
pub async fn get_axis(
    State(s): State<Arc<AppState>>,
    Path(axis): Path<String>,
) -> AppResult<Json<AxisResource>> {
    Ok(Json(axes::get(&s, &axis)?))
}

#[utoipa::path(post, path = "/api/v1/axes", tag = "axes", summary = "Create an axis",
    request_body = AxisConfigDto,
    responses((status = 201, description = "Created", body = AxisResource,
        headers(("Location" = String, description = "/api/v1/axes/{id}"))), super::errors::AxisCreateErrors))]
pub async fn create_axis(
    State(s): State<Arc<AppState>>,
    client: Client,
    JsonBody(config, _): JsonBody<AxisConfigDto>,
) -> AppResult<Response> {
    let audit = AuditEntry {
        at: store::now_rfc3339(),
        client_addr: Some(client.0.addr.clone()),
        client_id: client.0.id.clone(),
        principal: client.0.principal.clone(),
        action: "axis.create".into(),
        target: Some(config.name.clone()),
        outcome: Some("committed".into()),
        ..Default::default()
    };
    let r = axes::create(&s, config, None, audit).await?;
    let loc = format!("/api/v1/axes/{}", r.id);
    let mut resp = (StatusCode::CREATED, Json(r)).into_response();
    resp.headers_mut().insert(
        header::LOCATION,
        HeaderValue::from_str(&loc).expect("ascii"),
    );
    Ok(resp)
}

#[utoipa::path(put, path = "/api/v1/axes/{axis}", tag = "axes",
    summary = "Replace an axis's configuration; `change` says what it did (`?dry_run=true`: what it would do)",
    description = "When only parameters that can be written online change (dynamics, software limits, \
`parameters`, the name), they are written online: the axis keeps running, homed, where it is. A change of unit, \
modulo or drive (or values that cannot be written online) re-creates the axis: it must be disabled (409 \
`axis_not_disabled`), and its position, homed state and online values are lost. Either way persistent values of \
the parameters the save sets anew are discarded (listed in `change.persistent_discarded`), the others kept.",
    params(("axis" = String, Path, description = "axis id or name", example = "x"), ReplaceQuery),
    request_body = AxisConfigDto,
    responses((status = 200, description = "Replaced (or, with dry_run, the axis as it would be)", body = AxisResource), ConfigErrors))]
pub async fn replace_axis(
    State(s): State<Arc<AppState>>,
    Path(axis): Path<String>,
    client: Client,
    Q(q): Q<ReplaceQuery>,
    JsonBody(config, _): JsonBody<AxisConfigDto>,
) -> AppResult<Json<AxisResource>> {
    Ok(Json(
        axes::replace(&s, &axis, config, &client.0, q.dry_run).await?,
    ))
}

#[utoipa::path(delete, path = "/api/v1/axes/{axis}", tag = "axes", summary = "Delete an axis (it must be disabled)",
    params(("axis" = String, Path, description = "axis id or name", example = "x")),
    request_body(content = crate::model::EmptyBody, description = "`{}` or an empty body, sent as `application/json` (the operation takes no parameters; anything else is a 422)."),
    responses((status = 204, description = "Deleted"), super::errors::AxisDeleteErrors))]
pub async fn delete_axis(
    State(s): State<Arc<AppState>>,
    Path(axis): Path<String>,
    client: Client,
    _: super::JsonBody<crate::model::EmptyBody>,
) -> AppResult<StatusCode> {
    axes::delete(&s, &axis, &client.0).await?;
    Ok(StatusCode::NO_CONTENT)
}

#[utoipa::path(get, path = "/api/v1/axes/{axis}/status", tag = "axes", summary = "Live status (PLCopen state, positions, flags)",
    params(("axis" = String, Path, description = "axis id or name", example = "x")),
    responses((status = 200, description = "The status at the latest cycle", body = StatusResource), ReadErrors))]
pub async fn axis_status(
    State(s): State<Arc<AppState>>,
    Path(axis): Path<String>,
) -> AppResult<Json<StatusResource>> {
    Ok(Json(axes::status(&s, &axis)?))
}

#[utoipa::path(post, path = "/api/v1/axes/{axis}/status/following-error-peak/reset", tag = "axes",
    summary = "Restart the following-error peak hold",
    description = "`following_error_min` / `following_error_max` of the status hold the lowest and highest \
following error of every cycle since the last reset (TwinCAT's online \"lag distance min/max\"). This restarts \
them from the present following error; it changes no motion and creates no command.",
    params(("axis" = String, Path, description = "axis id or name", example = "x")),
    request_body(content = crate::model::EmptyBody, description = "`{}` or an empty body, sent as `application/json` (the operation takes no parameters; anything else is a 422)."),
    responses((status = 200, description = "Reset; the peak hold counts from `cycle`", body = PeakResetResource), super::errors::PeakResetErrors))]
pub async fn reset_following_error_peak(
    State(s): State<Arc<AppState>>,
    Path(axis): Path<String>,
    client: Client,
    _: super::JsonBody<crate::model::EmptyBody>,
) -> AppResult<Json<PeakResetResource>> {
    Ok(Json(
        axes::reset_following_error_peak(&s, &axis, &client.0).await?,
    ))
}

#[utoipa::path(get, path = "/api/v1/axes/{axis}/parameters", tag = "parameters", summary = "All MC_AxisParameter entries with values",
    params(("axis" = String, Path, description = "axis id or name", example = "x")),
    responses((status = 200, description = "Descriptors and values", body = Vec<ParameterResource>), ReadErrors))]
pub async fn list_parameters(
    State(s): State<Arc<AppState>>,
    Path(axis): Path<String>,
) -> AppResult<Json<Vec<ParameterResource>>> {
    Ok(Json(axes::parameters(&s, &axis)?))
}

#[utoipa::path(get, path = "/api/v1/axes/{axis}/parameters/{parameter}", tag = "parameters", summary = "One parameter (MC_ReadParameter)",
    params(("axis" = String, Path, description = "axis id or name", example = "x"),
           ("parameter" = String, Path, description = "number or name", example = "AxisVeloMax")),
    responses((status = 200, description = "Descriptor and value", body = ParameterResource), super::errors::ParameterReadErrors))]
pub async fn get_parameter(
    State(s): State<Arc<AppState>>,
    Path((axis, parameter)): Path<(String, String)>,
) -> AppResult<Json<ParameterResource>> {
    Ok(Json(axes::parameter(&s, &axis, &parameter)?))
}

#[utoipa::path(put, path = "/api/v1/axes/{axis}/parameters/{parameter}", tag = "parameters",
    summary = "Write a parameter (MC_WriteParameter, or MC_WriteParameterPersistent with persistent=true)",
    params(("axis" = String, Path, description = "axis id or name", example = "x"),
           ("parameter" = String, Path, description = "number or name", example = "AxisVeloMax")),
    request_body = ParameterWrite,
    responses((status = 200, description = "Written (and committed when persistent)", body = ParameterResource), super::errors::ParameterWriteErrors))]
pub async fn write_parameter(
    State(s): State<Arc<AppState>>,
    Path((axis, parameter)): Path<(String, String)>,
    client: Client,
    JsonBody(w, raw): JsonBody<ParameterWrite>,
) -> AppResult<Json<ParameterResource>> {
    let r = axes::write_parameter(&s, (&axis, &parameter), w, &raw, &client.0).await?;
    Ok(Json(r))
}

#[utoipa::path(get, path = "/api/v1/config", tag = "system", summary = "Export the whole configuration",
    responses((status = 200, description = "Axes with their persistent parameters", body = ConfigDocument)))]
pub async fn export_config(State(s): State<Arc<AppState>>) -> Json<ConfigDocument> {
    Json(axes::export(&s))
}

#[utoipa::path(put, path = "/api/v1/config", tag = "system",
    summary = "Import a whole configuration (replaces every axis, and the cam tables if the document has them; all axes must be disabled)",
    description = "Bodies up to 64 MiB (cam tables of a million rows). The audit row records the document with each cam \
table's rows and points counted, not copied.",
    request_body = ConfigDocument,
    responses((status = 200, description = "Imported; the configuration as now active", body = ConfigDocument), super::errors::ImportErrors))]
pub async fn import_config(
    State(s): State<Arc<AppState>>,
    client: Client,
    super::cams::LargeJsonBody(doc): super::cams::LargeJsonBody<ConfigDocument>,
) -> AppResult<Json<ConfigDocument>> {
    let raw = audit_view(&doc);
    Ok(Json(axes::import(&s, doc, &raw, &client.0).await?))
}

/// The document as the audit log keeps it: cam tables with their rows and points counted.
fn audit_view(doc: &ConfigDocument) -> serde_json::Value {
    let mut v = serde_json::json!({ "version": doc.version, "axes": doc.axes });
    if let Some(tables) = &doc.cam_tables {
        v["cam_tables"] = tables
            .iter()
            .map(|t| {
                serde_json::json!({
                    "id": t.id, "name": t.name, "table_type": t.table_type, "periodic": t.periodic,
                    "interpolation": t.interpolation, "row_count": t.rows.len() + t.points.len(),
                })
            })
            .collect();
    }
    v
}
