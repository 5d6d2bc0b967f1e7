//! Cam tables and the cam analysis FBs: the HTTP side (the rules are `service::cams`).

use std::sync::Arc;

use axum::Json;
use axum::extract::{FromRequest, Path, Request, State};
use axum::http::{HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};
use motion::cam::{Characteristics, MasterSearch, MotionFunctionPoint, OnlineChange, ValueSelect};
use serde::Deserialize;
use serde::de::DeserializeOwned;
use utoipa::IntoParams;

use super::{Client, JsonBody, Q};
use crate::app::AppState;
use crate::error::{AppError, AppResult};
use crate::model::{
    CamAnalysisResource, CamTableBody, CamTableResource, CamValuesResource, MasterPositionResource,
    SlaveDynamicsResource,
};
use crate::service::cams;

/// The largest cam table body: a million rows of JSON numbers is about 40 MB.
pub const CAM_BODY_LIMIT: usize = 64 * 1024 * 1024;

/// A large JSON object body read straight into `T` (no `serde_json::Value` tree: a million
/// rows would cost hundreds of megabytes), with the same problem+json answers as `JsonBody`.
pub struct LargeJsonBody<T>(pub T);

impl<T: DeserializeOwned + utoipa::ToSchema, S: Send + Sync> FromRequest<S> for LargeJsonBody<T> {
    type Rejection = AppError;

    async fn from_request(req: Request, state: &S) -> Result<Self, AppError> {
        let bytes = axum::body::Bytes::from_request(req, state)
            .await
            .map_err(|e| super::body_error(e, CAM_BODY_LIMIT))?;
        match bytes.iter().find(|b| !b.is_ascii_whitespace()) {
            Some(b'{') => {}
            None => return Err(AppError::field("body", "a cam table is required")),
            Some(_) => {
                // Not an object: malformed JSON is a 400, any other JSON value a 422.
                let v: serde_json::Value = serde_json::from_slice(&bytes)
                    .map_err(|e| AppError::bad_json(e.to_string()))?;
                return Err(super::not_an_object(&v));
            }
        }
        // A body of ordinary size is checked against its schema as `JsonBody`s are (no array
        // for an object, `2.0` read as an integer); a large one (a table of many rows) is read
        // straight from the bytes, without a value tree.
        if bytes.len() <= super::BODY_LIMIT {
            let value: serde_json::Value =
                serde_json::from_slice(&bytes).map_err(|e| AppError::bad_json(e.to_string()))?;
            return super::from_value(value).map(|(t, _)| LargeJsonBody(t));
        }
        let mut de = serde_json::Deserializer::from_slice(&bytes);
        let t = serde_path_to_error::deserialize(&mut de).map_err(|e| {
            let inner = e.inner();
            if inner.is_syntax() || inner.is_eof() {
                return AppError::bad_json(inner.to_string());
            }
            let mut path = e.path().to_string();
            let message = inner.to_string();
            if let Some(name) = message
                .strip_prefix("missing field `")
                .and_then(|m| m.split('`').next())
            {
                path = if path == "." {
                    name.to_string()
                } else {
                    format!("{path}.{name}")
                };
            }
            if path == "." {
                path = "body".into();
            }
            AppError::field(&path, &message)
        })?;
        de.end().map_err(|e| AppError::bad_json(e.to_string()))?;
        Ok(LargeJsonBody(t))
    }
}

#[utoipa::path(get, path = "/api/v1/cam-tables", tag = "cams", summary = "List the cam tables (without their rows or points)",
    responses((status = 200, description = "All cam tables, by id", body = Vec<CamTableResource>)))]
pub async fn list_cam_tables(State(s): State<Arc<AppState>>) -> Json<Vec<CamTableResource>> {
    Json(cams::list(&s))
}

#[utoipa::path(post, path = "/api/v1/cam-tables", tag = "cams",
    summary = "Store a cam table (MC_CamTableSelect): a position table or a motion function",
    description = "Validated with MC_TableErrorCodes (`error_id` 0x4B31…0x4B38) and motiond's cam errors \
(0x7080…0x7083): `errors[].field` names the row or point at fault. Bodies up to 64 MiB (a million rows).",
    request_body = CamTableBody,
    responses((status = 201, description = "Stored", body = CamTableResource,
        headers(("Location" = String, description = "/api/v1/cam-tables/{id}"))), super::errors::CamTableCreateErrors))]
pub async fn create_cam_table(
    State(s): State<Arc<AppState>>,
    client: Client,
    LargeJsonBody(body): LargeJsonBody<CamTableBody>,
) -> AppResult<Response> {
    let r = cams::create(&s, body, &client.0).await?;
    let loc = format!("/api/v1/cam-tables/{}", r.id);
    let mut resp = (StatusCode::CREATED, Json(r)).into_response();
    resp.headers_mut().insert(
        header::LOCATION,
        HeaderValue::from_str(&loc).expect("ascii"),
    );
    Ok(resp)
}

#[utoipa::path(get, path = "/api/v1/cam-tables/{table}", tag = "cams", summary = "One cam table with its rows or points",
    params(("table" = String, Path, description = "cam table id (1..255) or name", example = "knife")),
    responses((status = 200, description = "The table", body = CamTableResource), super::errors::CamTableReadErrors))]
pub async fn get_cam_table(
    State(s): State<Arc<AppState>>,
    Path(table): Path<String>,
) -> AppResult<Json<CamTableResource>> {
    Ok(Json(cams::get(&s, &table)?))
}

#[utoipa::path(put, path = "/api/v1/cam-tables/{table}", tag = "cams", summary = "Replace a cam table (same id, version + 1)",
    params(("table" = String, Path, description = "cam table id (1..255) or name", example = "knife")),
    request_body = CamTableBody,
    responses((status = 200, description = "Replaced", body = CamTableResource), super::errors::CamTableReplaceErrors))]
pub async fn replace_cam_table(
    State(s): State<Arc<AppState>>,
    Path(table): Path<String>,
    client: Client,
    LargeJsonBody(body): LargeJsonBody<CamTableBody>,
) -> AppResult<Json<CamTableResource>> {
    Ok(Json(cams::replace(&s, &table, body, &client.0).await?))
}

#[utoipa::path(delete, path = "/api/v1/cam-tables/{table}", tag = "cams", summary = "Delete a cam table",
    params(("table" = String, Path, description = "cam table id (1..255) or name", example = "knife")),
    request_body(content = crate::model::EmptyBody, description = "`{}` or an empty body, sent as `application/json` (the operation takes no parameters; anything else is a 422)."),
    responses((status = 204, description = "Deleted"), super::errors::CamTableDeleteErrors))]
pub async fn delete_cam_table(
    State(s): State<Arc<AppState>>,
    Path(table): Path<String>,
    client: Client,
    _: super::JsonBody<crate::model::EmptyBody>,
) -> AppResult<StatusCode> {
    cams::delete(&s, &table, &client.0).await?;
    Ok(StatusCode::NO_CONTENT)
}

#[utoipa::path(get, path = "/api/v1/cam-tables/{table}/characteristics", tag = "cams",
    summary = "MC_ReadCamTableCharacteristics: start and end values and the extremes of one cycle",
    params(("table" = String, Path, description = "cam table id (1..255) or name", example = "knife")),
    responses((status = 200, description = "Per raw master unit (master velocity normed to 1)", body = Characteristics), super::errors::CamTableReadErrors))]
pub async fn characteristics(
    State(s): State<Arc<AppState>>,
    Path(table): Path<String>,
) -> AppResult<Json<Characteristics>> {
    Ok(Json(cams::characteristics(&s, &table).await?))
}

#[derive(Debug, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
#[serde(deny_unknown_fields)]
pub struct SlaveDynamicsQuery {
    /// Raw master position in the table's coordinates (no coupling offset or scaling).
    #[param(minimum = -1e12, maximum = 1e12)]
    pub master_position: f64,
}

/// A position query parameter within ±[`crate::model::MAX_MAGNITUDE`], the bound of every
/// position a request gives (beyond it cycle counts of the cam search would overflow).
fn position(field: &str, x: f64) -> AppResult<f64> {
    if x.is_finite() && x.abs() <= crate::model::MAX_MAGNITUDE {
        Ok(x)
    } else {
        Err(AppError::field(
            field,
            "must be a number from -1e12 to 1e12",
        ))
    }
}

#[utoipa::path(get, path = "/api/v1/cam-tables/{table}/slave-dynamics", tag = "cams",
    summary = "MC_ReadCamTableSlaveDynamics: raw slave position, velocity and acceleration at a master position",
    params(("table" = String, Path, description = "cam table id (1..255) or name", example = "knife"), SlaveDynamicsQuery),
    responses((status = 200, description = "Raw table values", body = SlaveDynamicsResource), super::errors::CamTableQueryErrors))]
pub async fn slave_dynamics(
    State(s): State<Arc<AppState>>,
    Path(table): Path<String>,
    Q(q): Q<SlaveDynamicsQuery>,
) -> AppResult<Json<SlaveDynamicsResource>> {
    let x = position("master_position", q.master_position)?;
    Ok(Json(cams::slave_dynamics(&s, &table, x)?))
}

/// MC_ReadCamTableMasterPosition's inputs (axis coordinates and the coupling's offsets and
/// scalings).
#[derive(Debug, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
#[serde(deny_unknown_fields)]
pub struct MasterPositionQuery {
    /// The slave axis position to find master positions for.
    #[param(minimum = -1e12, maximum = 1e12)]
    pub slave_position: f64,
    /// Master offset of the coupling (default 0).
    #[param(minimum = -1e12, maximum = 1e12)]
    pub master_offset: Option<f64>,
    /// Slave offset of the coupling (default 0).
    #[param(minimum = -1e12, maximum = 1e12)]
    pub slave_offset: Option<f64>,
    /// Master scaling of the coupling (default 1; not 0).
    #[param(schema_with = nonzero_scaling)]
    pub master_scaling: Option<f64>,
    /// Slave scaling of the coupling (default 1; not 0).
    #[param(schema_with = nonzero_scaling)]
    pub slave_scaling: Option<f64>,
    /// Master axis position the search starts from (default 0).
    #[param(minimum = -1e12, maximum = 1e12)]
    pub master_start_position: Option<f64>,
    /// Accuracy of the master positions found, axis units (default (0): 1e-9 of the period).
    #[param(minimum = 0)]
    pub master_accuracy: Option<f64>,
}

/// A scaling: a number other than 0, within ±1e12.
pub(crate) fn nonzero_scaling() -> utoipa::openapi::schema::Schema {
    crate::model::nonzero_number()
}

#[utoipa::path(get, path = "/api/v1/cam-tables/{table}/master-position", tag = "cams",
    summary = "MC_ReadCamTableMasterPosition: the nearest master positions below and above a start for a slave position",
    params(("table" = String, Path, description = "cam table id (1..255) or name", example = "knife"), MasterPositionQuery),
    responses((status = 200, description = "`valid` is false where there is no solution", body = MasterPositionResource), super::errors::CamTableQueryErrors))]
pub async fn master_position(
    State(s): State<Arc<AppState>>,
    Path(table): Path<String>,
    Q(q): Q<MasterPositionQuery>,
) -> AppResult<Json<MasterPositionResource>> {
    position("slave_position", q.slave_position)?;
    for (f, v) in [
        ("master_scaling", q.master_scaling),
        ("slave_scaling", q.slave_scaling),
    ] {
        if !crate::model::valid_scaling(v.unwrap_or(1.0)) {
            return Err(AppError::field(
                f,
                "must be a number other than 0, from 1e-9 to 1e12 in magnitude",
            ));
        }
    }
    for (f, v) in [
        ("master_offset", q.master_offset),
        ("slave_offset", q.slave_offset),
        ("master_start_position", q.master_start_position),
    ] {
        position(f, v.unwrap_or(0.0))?;
    }
    let search = MasterSearch {
        slave_position: q.slave_position,
        master_offset: q.master_offset.unwrap_or(0.0),
        slave_offset: q.slave_offset.unwrap_or(0.0),
        master_scaling: q.master_scaling.unwrap_or(1.0),
        slave_scaling: q.slave_scaling.unwrap_or(1.0),
        master_start_position: q.master_start_position.unwrap_or(0.0),
        master_accuracy: q.master_accuracy.unwrap_or(0.0),
    };
    Ok(Json(cams::master_position(&s, &table, search).await?))
}

#[derive(Debug, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
#[serde(deny_unknown_fields)]
pub struct ValuesQuery {
    /// Raw master position of the first sample.
    #[param(minimum = -1e12, maximum = 1e12)]
    pub start: f64,
    /// Raw master position of the last sample (at most; not before `start`).
    #[param(minimum = -1e12, maximum = 1e12)]
    pub end: f64,
    /// Master step (> 0; at most 100 000 rows).
    #[param(exclusive_minimum = 0)]
    pub increment: f64,
    /// Comma-separated: `position`, `velocity`, `acceleration`, `jerk` (default all four).
    #[param(value_type = Option<Vec<ValueSelect>>, style = Form, explode = false)]
    pub values: Option<String>,
}

#[utoipa::path(get, path = "/api/v1/cam-tables/{table}/values", tag = "cams",
    summary = "MC_ReadMotionFunctionValues: position, velocity, acceleration, jerk sampled over a master range",
    params(("table" = String, Path, description = "cam table id (1..255) or name", example = "knife"), ValuesQuery),
    responses((status = 200, description = "Rows from `start` by `increment`", body = CamValuesResource), super::errors::CamTableQueryErrors))]
pub async fn values(
    State(s): State<Arc<AppState>>,
    Path(table): Path<String>,
    Q(q): Q<ValuesQuery>,
) -> AppResult<Json<CamValuesResource>> {
    position("start", q.start)?;
    position("end", q.end)?;
    let mut select = Vec::new();
    // Absent: all four; given, every item must name one (`values=` is an empty name).
    for v in q
        .values
        .as_deref()
        .into_iter()
        .flat_map(|v| v.split(','))
        .map(str::trim)
    {
        select.push(
            serde_json::from_value::<ValueSelect>(serde_json::Value::String(v.into())).map_err(
                |_| {
                    AppError::field(
                        "values",
                        &format!(
                            "unknown value `{v}`: expected position, velocity, acceleration or jerk"
                        ),
                    )
                },
            )?,
        );
    }
    Ok(Json(cams::values(
        &s,
        &table,
        q.start,
        q.end,
        q.increment,
        &select,
    )?))
}

#[derive(Debug, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
#[serde(deny_unknown_fields)]
pub struct AnalysisQuery {
    /// Samples over the table's range, both ends included (default 721: every half unit of a
    /// 360° cycle).
    #[param(minimum = 2, maximum = 100000)]
    pub samples: Option<u32>,
}

#[utoipa::path(post, path = "/api/v1/cam-analysis", tag = "cams",
    summary = "Analyse a cam table without storing it: values over one cycle, characteristic values, jumps where laws meet",
    description = "What the cam editor plots while a table is edited; the server is the one source of the cam \
math. The body is a cam table as for `POST /cam-tables`, validated the same way (the same errors at the same \
fields); nothing is stored and no coupled slave sees it.",
    params(AnalysisQuery),
    request_body = CamTableBody,
    responses((status = 200, description = "The table's range, values, characteristics and discontinuities", body = CamAnalysisResource),
        super::errors::CamAnalysisErrors))]
pub async fn analyse(
    Q(q): Q<AnalysisQuery>,
    LargeJsonBody(body): LargeJsonBody<CamTableBody>,
) -> AppResult<Json<CamAnalysisResource>> {
    let samples = q.samples.unwrap_or(721) as usize;
    if !(2..=cams::MAX_VALUE_ROWS).contains(&samples) {
        return Err(AppError::field(
            "samples",
            &format!("2..{} samples", cams::MAX_VALUE_ROWS),
        ));
    }
    Ok(Json(cams::analyse(body, samples).await?))
}

#[utoipa::path(get, path = "/api/v1/cam-tables/{table}/online-change-mode", tag = "cams",
    summary = "How data written to this table reaches coupled slaves (MC_SetCamOnlineChangeMode as set)",
    params(("table" = String, Path, description = "cam table id (1..255) or name", example = "knife")),
    responses((status = 200, description = "The mode in force (instantaneous after a start)", body = OnlineChange), super::errors::CamTableReadErrors))]
pub async fn get_online_change_mode(
    State(s): State<Arc<AppState>>,
    Path(table): Path<String>,
) -> AppResult<Json<OnlineChange>> {
    Ok(Json(cams::online_change(&s, &table)?))
}

#[utoipa::path(put, path = "/api/v1/cam-tables/{table}/online-change-mode", tag = "cams",
    summary = "MC_SetCamOnlineChangeMode: when later writes to this table reach coupled slaves",
    description = "Applies to every later write (PUT of the table, of its points). Written data reaches a coupled \
slave at its activation and only where it does not move the slave (`instantaneous`, `as_soon_as_possible`: the first \
such cycle); until then the slave's status shows `cam_data_queued`. `off`: coupled slaves keep the data they run. \
`delete_queued_data` drops written data that has not reached its slaves (the mode stays). Not stored: \
`instantaneous` after a start.",
    params(("table" = String, Path, description = "cam table id (1..255) or name", example = "knife")),
    request_body = OnlineChange,
    responses((status = 200, description = "The mode now in force", body = OnlineChange), super::errors::CamOnlineModeErrors))]
pub async fn set_online_change_mode(
    State(s): State<Arc<AppState>>,
    Path(table): Path<String>,
    client: Client,
    JsonBody(change, _): JsonBody<OnlineChange>,
) -> AppResult<Json<OnlineChange>> {
    Ok(Json(
        cams::set_online_change(&s, &table, change, &client.0).await?,
    ))
}

#[utoipa::path(get, path = "/api/v1/cam-tables/{table}/points/{point}", tag = "cams",
    summary = "MC_ReadMotionFunctionPoint",
    params(("table" = String, Path, description = "cam table id (1..255) or name", example = "knife"),
        ("point" = u32, Path, description = "point_index", example = 2)),
    responses((status = 200, description = "The point", body = MotionFunctionPoint), super::errors::CamPointReadErrors))]
pub async fn get_point(
    State(s): State<Arc<AppState>>,
    Path((table, point)): Path<(String, String)>,
) -> AppResult<Json<MotionFunctionPoint>> {
    let index = point
        .parse::<u32>()
        .map_err(|_| AppError::not_found("point", &point))?;
    Ok(Json(cams::point(&s, &table, index)?))
}

#[utoipa::path(put, path = "/api/v1/cam-tables/{table}/points/{point}", tag = "cams",
    summary = "MC_WriteMotionFunctionPoint: replace one point (an online change on a coupled table)",
    params(("table" = String, Path, description = "cam table id (1..255) or name", example = "knife"),
        ("point" = u32, Path, description = "point_index", example = 2)),
    request_body = MotionFunctionPoint,
    responses((status = 200, description = "Stored (version + 1); coupled slaves take it by the online-change mode", body = CamTableResource),
        super::errors::CamTableReplaceErrors))]
pub async fn write_point(
    State(s): State<Arc<AppState>>,
    Path((table, point)): Path<(String, String)>,
    client: Client,
    JsonBody(p, _): JsonBody<MotionFunctionPoint>,
) -> AppResult<Json<CamTableResource>> {
    if point.parse::<u32>().ok() != Some(p.point_index) {
        return Err(AppError::field(
            "point_index",
            &format!("must be the point of the path ({point})"),
        ));
    }
    Ok(Json(
        cams::write_points(&s, &table, vec![p], &client.0).await?,
    ))
}

/// MC_WriteMotionFunction: points to replace, by their `point_index`.
#[derive(Debug, Deserialize, serde::Serialize, utoipa::ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"points": [{"point_index": 2, "function_type": "polynom5", "point_type": "rest", "master_pos": 200.0, "slave_pos": 120.0}]}))]
pub struct WritePointsBody {
    pub points: Vec<MotionFunctionPoint>,
}

#[utoipa::path(put, path = "/api/v1/cam-tables/{table}/points", tag = "cams",
    summary = "MC_WriteMotionFunction: replace points (an online change on a coupled table)",
    params(("table" = String, Path, description = "cam table id (1..255) or name", example = "knife")),
    request_body = WritePointsBody,
    responses((status = 200, description = "Stored (version + 1); coupled slaves take it by the online-change mode", body = CamTableResource),
        super::errors::CamTableReplaceErrors))]
pub async fn write_points(
    State(s): State<Arc<AppState>>,
    Path(table): Path<String>,
    client: Client,
    LargeJsonBody(body): LargeJsonBody<WritePointsBody>,
) -> AppResult<Json<CamTableResource>> {
    Ok(Json(
        cams::write_points(&s, &table, body.points, &client.0).await?,
    ))
}

#[derive(Debug, Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
#[serde(deny_unknown_fields)]
pub struct CamInfoQuery {
    /// Report the coupling as it would be with the master axis here (MC_CamInfo's
    /// AtMasterPosition); left out: as it is.
    pub master_position: Option<f64>,
}

#[utoipa::path(get, path = "/api/v1/axes/{axis}/cam-info", tag = "cams",
    summary = "MC_CamInfo(_V2): a cam slave's coupling, now or at a master position",
    description = "Offsets, scalings and cam positions of the coupling (each cam of a multi-cam slave in `cams`). \
After an error ended the coupling it is the last valid state (`active` false) — the data to couple again at the \
same positions; MC_CamOut clears it. 409 `cam_not_coupled` when there is none.",
    params(("axis" = String, Path, description = "axis id or name", example = "y"), CamInfoQuery),
    responses((status = 200, description = "MC_CamInfoData", body = motion::cam::CamInfo), super::errors::CamInfoErrors))]
pub async fn cam_info(
    State(s): State<Arc<AppState>>,
    Path(axis): Path<String>,
    Q(q): Q<CamInfoQuery>,
) -> AppResult<Json<motion::cam::CamInfo>> {
    Ok(Json(cams::cam_info(&s, &axis, q.master_position)?))
}
