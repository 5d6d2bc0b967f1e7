//! Axis configurations, status, parameters and the whole-configuration document.

use std::collections::BTreeMap;
use std::sync::Arc;

use axum::Json;
use axum::extract::{Path, State};
use axum::http::{HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};
use motion::{AxisState, AxisStatus, CommandKind};
use serde::Serialize;
use utoipa::ToSchema;

use super::errors::{ConfigErrors, ReadErrors};
use super::{Client, JsonBody};
use crate::app::{AppState, AxisEntry};
use crate::error::{ApiError, ApiResult};
use crate::model::{
    AxisConfigDto, AxisResource, ConfigAxis, ConfigDocument, LiveStatus, ParameterResource,
    ParameterWrite,
};
use crate::params::{self, ParamValue};
use crate::sim::FieldError;
use crate::store::{self, AuditEntry};

fn resource(s: &AppState, e: &AxisEntry) -> AxisResource {
    let state = s.status(e.slot).1.map(|st| st.state).unwrap_or_default();
    AxisResource {
        id: e.id,
        slot: e.slot,
        state,
        config: e.config.clone(),
    }
}

fn audit_entry(client: &Client, action: &str, target: &str, detail: String) -> AuditEntry {
    AuditEntry {
        at: store::now_rfc3339(),
        client_addr: Some(client.0.addr.clone()),
        client_id: client.0.id.clone(),
        action: action.into(),
        target: Some(target.into()),
        detail,
        outcome: Some("committed".into()),
        ..Default::default()
    }
}

fn not_disabled(name: &str) -> ApiError {
    ApiError::conflict(
        "axis_not_disabled",
        format!("axis '{name}' is not disabled: switch it off (DELETE its power command) first"),
    )
}

#[utoipa::path(get, path = "/api/v1/axes", tag = "axes", summary = "List the axes",
    responses((status = 200, description = "All axes, by id", body = Vec<AxisResource>)))]
pub async fn list_axes(State(s): State<Arc<AppState>>) -> Json<Vec<AxisResource>> {
    let reg = s.registry.read().unwrap();
    Json(reg.axes.values().map(|e| resource(&s, e)).collect())
}

#[utoipa::path(get, path = "/api/v1/axes/{axis}", tag = "axes", summary = "One axis",
    params(("axis" = String, Path, description = "axis id or name", example = "x")),
    responses((status = 200, description = "The axis", body = AxisResource), ReadErrors))]
pub async fn get_axis(
    State(s): State<Arc<AppState>>,
    Path(axis): Path<String>,
) -> ApiResult<Json<AxisResource>> {
    let reg = s.registry.read().unwrap();
    let e = reg
        .find(&axis)
        .ok_or_else(|| ApiError::not_found("axis", &axis))?;
    Ok(Json(resource(&s, e)))
}

fn check_name_free(s: &AppState, name: &str, except: Option<i64>) -> ApiResult<()> {
    let reg = s.registry.read().unwrap();
    if reg
        .axes
        .values()
        .any(|a| a.name == name && Some(a.id) != except)
    {
        return Err(ApiError::conflict(
            "axis_name_taken",
            format!("an axis named '{name}' exists"),
        ));
    }
    Ok(())
}

/// Creates an axis (used by the API and the demo). Nothing is changed unless all of it commits.
pub async fn create(
    s: &AppState,
    config: AxisConfigDto,
    id: Option<i64>,
    audit: AuditEntry,
) -> ApiResult<AxisResource> {
    config
        .to_parameters(0, s.info.cycle_time_s)
        .map_err(ApiError::invalid)?;
    check_name_free(s, &config.name, None)?;
    let slot = s
        .registry
        .read()
        .unwrap()
        .free_slot()
        .ok_or_else(|| ApiError::conflict("no_free_slot", "all axis slots are used"))?;
    let json = serde_json::to_string(&config).expect("config serialises");
    let mut tx = s.db.begin().await?;
    let now = store::now_rfc3339();
    let id = store::axes::insert_axis(&mut tx, id, &config.name, &json, &now).await?;
    store::audit(
        &mut *tx,
        &AuditEntry {
            detail: json,
            ..audit
        },
    )
    .await?;
    let (p, axis, drive) = s
        .build_axis(id, &config, &BTreeMap::new())
        .map_err(ApiError::invalid)?;
    if let Err(e) = s.install_axis(slot, axis, drive, false).await? {
        return Err(ApiError::kernel(
            StatusCode::CONFLICT,
            "Axis not installed",
            e,
        ));
    }
    if let Err(e) = tx.commit().await {
        let _ = s.uninstall_axis(slot, false).await;
        return Err(e.into());
    }
    let entry = AxisEntry {
        id,
        name: config.name.clone(),
        slot,
        config,
        params: p,
        persistent: BTreeMap::new(),
    };
    let r = resource(s, &entry);
    s.registry.write().unwrap().axes.insert(id, entry);
    Ok(r)
}

#[utoipa::path(post, path = "/api/v1/axes", tag = "axes", summary = "Create an axis",
    request_body = AxisConfigDto,
    responses((status = 201, description = "Created", body = AxisResource,
        headers(("Location" = String, description = "/api/v1/axes/{id}"))), super::errors::AxisCreateErrors))]
pub async fn create_axis(
    State(s): State<Arc<AppState>>,
    client: Client,
    JsonBody(config, _): JsonBody<AxisConfigDto>,
) -> ApiResult<Response> {
    let _guard = s.config_lock.lock().await;
    let name = config.name.clone();
    let r = create(
        &s,
        config,
        None,
        audit_entry(&client, "axis.create", &name, String::new()),
    )
    .await?;
    let loc = format!("/api/v1/axes/{}", r.id);
    let mut resp = (StatusCode::CREATED, Json(r)).into_response();
    resp.headers_mut().insert(
        header::LOCATION,
        HeaderValue::from_str(&loc).expect("ascii"),
    );
    Ok(resp)
}

#[utoipa::path(put, path = "/api/v1/axes/{axis}", tag = "axes",
    summary = "Replace an axis's configuration (the axis must be disabled; drops its persistent parameters)",
    params(("axis" = String, Path, description = "axis id or name", example = "x")),
    request_body = AxisConfigDto,
    responses((status = 200, description = "Replaced", body = AxisResource), ConfigErrors))]
pub async fn replace_axis(
    State(s): State<Arc<AppState>>,
    Path(axis): Path<String>,
    client: Client,
    JsonBody(config, _): JsonBody<AxisConfigDto>,
) -> ApiResult<Json<AxisResource>> {
    let _guard = s.config_lock.lock().await;
    let (id, slot, old_name, old_config) = {
        let reg = s.registry.read().unwrap();
        let e = reg
            .find(&axis)
            .ok_or_else(|| ApiError::not_found("axis", &axis))?;
        (e.id, e.slot, e.name.clone(), e.config.clone())
    };
    let (p, new_axis, drive) = s
        .build_axis(id, &config, &BTreeMap::new())
        .map_err(ApiError::invalid)?;
    check_name_free(&s, &config.name, Some(id))?;
    let json = serde_json::to_string(&config).expect("config serialises");
    let mut tx = s.db.begin().await?;
    store::axes::update_axis(&mut tx, id, &config.name, &json, &store::now_rfc3339()).await?;
    store::axes::clear_persistent(&mut tx, id).await?;
    store::audit(
        &mut *tx,
        &audit_entry(&client, "axis.replace", &old_name, json),
    )
    .await?;
    if s.install_axis(slot, new_axis, drive, true).await?.is_err() {
        return Err(not_disabled(&old_name));
    }
    if let Err(e) = tx.commit().await {
        // Put the old axis back (it is disabled: the new one was just installed).
        let old_persistent = s
            .registry
            .read()
            .unwrap()
            .axes
            .get(&id)
            .map(|e| e.persistent.clone())
            .unwrap_or_default();
        if let Ok((_, a, d)) = s.build_axis(id, &old_config, &old_persistent) {
            let _ = s.install_axis(slot, a, d, false).await;
        }
        return Err(e.into());
    }
    let mut reg = s.registry.write().unwrap();
    let e = reg.axes.get_mut(&id).expect("locked by config_lock");
    e.name = config.name.clone();
    e.config = config;
    e.params = p;
    e.persistent.clear();
    Ok(Json(resource(&s, e)))
}

#[utoipa::path(delete, path = "/api/v1/axes/{axis}", tag = "axes", summary = "Delete an axis (it must be disabled)",
    params(("axis" = String, Path, description = "axis id or name", example = "x")),
    request_body(content = crate::model::EmptyBody, description = "`{}`: the operation takes no parameters (a body is not read). Send it, or an empty body, as `application/json`."),
    responses((status = 204, description = "Deleted"), super::errors::AxisDeleteErrors))]
pub async fn delete_axis(
    State(s): State<Arc<AppState>>,
    Path(axis): Path<String>,
    client: Client,
) -> ApiResult<StatusCode> {
    let _guard = s.config_lock.lock().await;
    let (id, slot, name, config, persistent) = {
        let reg = s.registry.read().unwrap();
        let e = reg
            .find(&axis)
            .ok_or_else(|| ApiError::not_found("axis", &axis))?;
        (
            e.id,
            e.slot,
            e.name.clone(),
            e.config.clone(),
            e.persistent.clone(),
        )
    };
    let mut tx = s.db.begin().await?;
    store::axes::delete_axis(&mut tx, id).await?;
    store::audit(
        &mut *tx,
        &audit_entry(&client, "axis.delete", &name, String::new()),
    )
    .await?;
    if s.uninstall_axis(slot, true).await?.is_err() {
        return Err(not_disabled(&name));
    }
    if let Err(e) = tx.commit().await {
        if let Ok((_, a, d)) = s.build_axis(id, &config, &persistent) {
            let _ = s.install_axis(slot, a, d, false).await;
        }
        return Err(e.into());
    }
    s.registry.write().unwrap().axes.remove(&id);
    Ok(StatusCode::NO_CONTENT)
}

/// Live status of an axis.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"axis": "x", "axis_id": 1, "cycle": 2009, "unit": "mm",
                          "status": crate::model::examples::live_status()}))]
pub struct StatusResource {
    pub axis: String,
    pub axis_id: i64,
    /// The cycle the snapshot was taken in.
    pub cycle: u64,
    pub unit: String,
    pub status: LiveStatus,
}

#[utoipa::path(get, path = "/api/v1/axes/{axis}/status", tag = "axes", summary = "Live status (PLCopen state, positions, flags)",
    params(("axis" = String, Path, description = "axis id or name", example = "x")),
    responses((status = 200, description = "The status at the latest cycle", body = StatusResource), ReadErrors))]
pub async fn axis_status(
    State(s): State<Arc<AppState>>,
    Path(axis): Path<String>,
) -> ApiResult<Json<StatusResource>> {
    let (slot, id, name, unit) = {
        let reg = s.registry.read().unwrap();
        let e = reg
            .find(&axis)
            .ok_or_else(|| ApiError::not_found("axis", &axis))?;
        (e.slot, e.id, e.name.clone(), e.config.unit.clone())
    };
    let (cycle, status) = s.status(slot);
    Ok(Json(StatusResource {
        axis: name,
        axis_id: id,
        cycle,
        unit,
        status: s.status_view(status.unwrap_or_default()),
    }))
}

/// When the following-error peak hold counts from.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"axis": "x", "cycle": 120345}))]
pub struct PeakResetResource {
    pub axis: String,
    /// The first cycle of the new peak hold.
    pub cycle: u64,
}

#[utoipa::path(post, path = "/api/v1/axes/{axis}/status/following-error-peak/reset", tag = "axes",
    summary = "Restart the following-error peak hold",
    description = "`following_error_min` / `following_error_max` of the status hold the lowest and highest \
following error of every cycle since the last reset (TwinCAT's online \"lag distance min/max\"). This restarts \
them from the present following error; it changes no motion and creates no command.",
    params(("axis" = String, Path, description = "axis id or name", example = "x")),
    request_body(content = crate::model::EmptyBody, description = "`{}`: the operation takes no parameters (a body is not read). Send it, or an empty body, as `application/json`."),
    responses((status = 200, description = "Reset; the peak hold counts from `cycle`", body = PeakResetResource), super::errors::PeakResetErrors))]
pub async fn reset_following_error_peak(
    State(s): State<Arc<AppState>>,
    Path(axis): Path<String>,
    client: Client,
) -> ApiResult<Json<PeakResetResource>> {
    let (slot, name) = s.axis_slot(&axis)?;
    let result = s.reset_following_error_peak(slot).await?;
    s.audit(AuditEntry {
        at: store::now_rfc3339(),
        client_addr: Some(client.0.addr.clone()),
        client_id: client.0.id.clone(),
        action: "axis.following_error_peak.reset".into(),
        target: Some(name.clone()),
        command_id: None,
        detail: String::new(),
        outcome: Some(
            if result.is_ok() {
                "applied"
            } else {
                "rejected:axis_unknown"
            }
            .into(),
        ),
    });
    match result {
        Ok(cycle) => Ok(Json(PeakResetResource { axis: name, cycle })),
        // The axis was removed between the look-up and the cycle thread.
        Err(_) => Err(ApiError::not_found("axis", &axis)),
    }
}

fn parameter_resource(
    e: &AxisEntry,
    info: &'static params::ParameterInfo,
    status: &AxisStatus,
) -> ParameterResource {
    ParameterResource {
        info: *info,
        unit_text: info.unit.text(&e.config.unit),
        value: params::read(&e.params, info.number, status).unwrap_or(ParamValue::Number(f64::NAN)),
        persistent_value: e.persistent.get(&info.storage).copied(),
    }
}

#[utoipa::path(get, path = "/api/v1/axes/{axis}/parameters", tag = "parameters", summary = "All MC_AxisParameter entries with values",
    params(("axis" = String, Path, description = "axis id or name", example = "x")),
    responses((status = 200, description = "Descriptors and values", body = Vec<ParameterResource>), ReadErrors))]
pub async fn list_parameters(
    State(s): State<Arc<AppState>>,
    Path(axis): Path<String>,
) -> ApiResult<Json<Vec<ParameterResource>>> {
    let reg = s.registry.read().unwrap();
    let e = reg
        .find(&axis)
        .ok_or_else(|| ApiError::not_found("axis", &axis))?;
    let status = s.status(e.slot).1.unwrap_or_default();
    Ok(Json(
        params::PARAMETERS
            .iter()
            .map(|i| parameter_resource(e, i, &status))
            .collect(),
    ))
}

#[utoipa::path(get, path = "/api/v1/axes/{axis}/parameters/{parameter}", tag = "parameters", summary = "One parameter (MC_ReadParameter)",
    params(("axis" = String, Path, description = "axis id or name", example = "x"),
           ("parameter" = String, Path, description = "number or name", example = "AxisVeloMax")),
    responses((status = 200, description = "Descriptor and value", body = ParameterResource), super::errors::ParameterReadErrors))]
pub async fn get_parameter(
    State(s): State<Arc<AppState>>,
    Path((axis, parameter)): Path<(String, String)>,
) -> ApiResult<Json<ParameterResource>> {
    let reg = s.registry.read().unwrap();
    let e = reg
        .find(&axis)
        .ok_or_else(|| ApiError::not_found("axis", &axis))?;
    let info =
        params::lookup(&parameter).ok_or_else(|| ApiError::not_found("parameter", &parameter))?;
    let status = s.status(e.slot).1.unwrap_or_default();
    Ok(Json(parameter_resource(e, info, &status)))
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
) -> ApiResult<Json<ParameterResource>> {
    let _guard = s.config_lock.lock().await;
    let (id, slot, name, mut p) = {
        let reg = s.registry.read().unwrap();
        let e = reg
            .find(&axis)
            .ok_or_else(|| ApiError::not_found("axis", &axis))?;
        (e.id, e.slot, e.name.clone(), e.params.clone())
    };
    let info =
        params::lookup(&parameter).ok_or_else(|| ApiError::not_found("parameter", &parameter))?;
    let invalid = |id: motion::ErrorId, msg: String| {
        let mut e = ApiError::invalid(vec![FieldError {
            field: "value".into(),
            message: msg,
        }]);
        e.0.error_id = Some(id.0);
        e
    };
    params::set(&mut p, info.number, w.value).map_err(|e| invalid(e, e.text().into()))?;
    params::validate(&p).map_err(|i| invalid(i.error, i.message))?;
    let kind = CommandKind::WriteParameter {
        number: info.number,
        value: w.value.as_f64(),
    };
    let audit = AuditEntry {
        command_id: None,
        ..audit_entry(
            &client,
            if w.persistent {
                "parameter.write_persistent"
            } else {
                "parameter.write"
            },
            &name,
            {
                let mut d = raw.clone();
                d["parameter"] = info.number.into();
                d.to_string()
            },
        )
    };
    if w.persistent {
        let mut tx = s.db.begin().await?;
        let value = serde_json::to_string(&w.value).expect("value");
        store::axes::upsert_persistent(&mut tx, id, info.storage, &value, &store::now_rfc3339())
            .await?;
        store::audit(&mut *tx, &audit).await?;
        // The kernel checks the value with the same table (it should agree with the checks
        // above): its refusal is the same 422 with the error number.
        if let Err(e) = s.kernel_command(slot, kind).await? {
            return Err(invalid(e, e.text().into()));
        }
        tx.commit().await.map_err(|e| {
            tracing::error!(
                "axis {name}: parameter {} applied but not persisted: {e}",
                info.number
            );
            ApiError::unavailable(
                "storage_unavailable",
                format!("the value is active but was NOT persisted: {e}"),
            )
        })?;
    } else {
        // The kernel checks the value with the same table (it should agree with the checks
        // above): its refusal is the same 422 with the error number.
        if let Err(e) = s.kernel_command(slot, kind).await? {
            return Err(invalid(e, e.text().into()));
        }
        s.audit(audit);
    }
    let mut reg = s.registry.write().unwrap();
    let e = reg.axes.get_mut(&id).expect("locked by config_lock");
    e.params = p;
    if w.persistent {
        e.persistent.insert(info.storage, w.value);
    }
    let status = s.status(slot).1.unwrap_or_default();
    Ok(Json(parameter_resource(e, info, &status)))
}

fn export(s: &AppState) -> ConfigDocument {
    let reg = s.registry.read().unwrap();
    ConfigDocument {
        version: 1,
        axes: reg
            .axes
            .values()
            .map(|e| ConfigAxis {
                id: e.id,
                config: e.config.clone(),
                persistent_parameters: e
                    .persistent
                    .iter()
                    .map(|(n, v)| {
                        (
                            params::by_number(*n)
                                .map_or_else(|| n.to_string(), |i| i.name.to_string()),
                            *v,
                        )
                    })
                    .collect(),
            })
            .collect(),
    }
}

#[utoipa::path(get, path = "/api/v1/config", tag = "system", summary = "Export the whole configuration",
    responses((status = 200, description = "Axes with their persistent parameters", body = ConfigDocument)))]
pub async fn export_config(State(s): State<Arc<AppState>>) -> Json<ConfigDocument> {
    Json(export(&s))
}

/// An axis as installed before an import: id, slot, name, configuration, persistent overlay.
type InstalledAxis = (i64, u16, String, AxisConfigDto, BTreeMap<u16, ParamValue>);

#[utoipa::path(put, path = "/api/v1/config", tag = "system",
    summary = "Import a whole configuration (replaces every axis; all axes must be disabled)",
    request_body = ConfigDocument,
    responses((status = 200, description = "Imported; the configuration as now active", body = ConfigDocument), super::errors::ImportErrors))]
pub async fn import_config(
    State(s): State<Arc<AppState>>,
    client: Client,
    JsonBody(doc, raw): JsonBody<ConfigDocument>,
) -> ApiResult<Json<ConfigDocument>> {
    let _guard = s.config_lock.lock().await;
    // Validate everything first.
    let mut errs = Vec::new();
    if doc.version != 1 {
        errs.push(FieldError {
            field: "version".into(),
            message: "must be 1".into(),
        });
    }
    if doc.axes.len() > crate::cycle::MAX_AXES {
        errs.push(FieldError {
            field: "axes".into(),
            message: format!("at most {} axes", crate::cycle::MAX_AXES),
        });
    }
    let mut built = Vec::new();
    for (i, a) in doc.axes.iter().enumerate() {
        if a.id <= 0 {
            errs.push(FieldError {
                field: format!("axes[{i}].id"),
                message: "must be > 0".into(),
            });
        }
        if doc.axes[..i].iter().any(|b| b.id == a.id) {
            errs.push(FieldError {
                field: format!("axes[{i}].id"),
                message: "duplicate id".into(),
            });
        }
        if doc.axes[..i].iter().any(|b| b.config.name == a.config.name) {
            errs.push(FieldError {
                field: format!("axes[{i}].config.name"),
                message: "duplicate name".into(),
            });
        }
        let mut persistent = BTreeMap::new();
        for (k, v) in &a.persistent_parameters {
            match params::lookup(k) {
                Some(info) if !info.read_only && !info.is_status() => {
                    persistent.insert(info.storage, *v);
                }
                _ => errs.push(FieldError {
                    field: format!("axes[{i}].persistent_parameters.{k}"),
                    message: "unknown or read-only parameter".into(),
                }),
            }
        }
        match a.config.to_parameters(a.id, s.info.cycle_time_s) {
            Err(fe) => errs.extend(fe.into_iter().map(|e| FieldError {
                field: format!("axes[{i}].config.{}", e.field),
                message: e.message,
            })),
            Ok(mut p) => {
                for (n, v) in &persistent {
                    if let Err(e) = params::set(&mut p, *n, *v) {
                        errs.push(FieldError {
                            field: format!("axes[{i}].persistent_parameters.{n}"),
                            message: e.text().into(),
                        });
                    }
                }
                if let Err(issue) = params::validate(&p) {
                    errs.push(FieldError {
                        field: format!("axes[{i}].persistent_parameters"),
                        message: issue.message,
                    });
                }
            }
        }
        built.push(persistent);
    }
    if !errs.is_empty() {
        return Err(ApiError::invalid(errs));
    }
    let old: Vec<InstalledAxis> = {
        let reg = s.registry.read().unwrap();
        reg.axes
            .values()
            .map(|e| {
                (
                    e.id,
                    e.slot,
                    e.name.clone(),
                    e.config.clone(),
                    e.persistent.clone(),
                )
            })
            .collect()
    };
    for (_, slot, name, _, _) in &old {
        if s.status(*slot)
            .1
            .is_some_and(|st| st.state != AxisState::Disabled || st.power_status)
        {
            return Err(not_disabled(name));
        }
    }
    let mut tx = s.db.begin().await?;
    store::axes::delete_all_axes(&mut tx).await?;
    let now = store::now_rfc3339();
    for (a, persistent) in doc.axes.iter().zip(&built) {
        let json = serde_json::to_string(&a.config).expect("config");
        store::axes::insert_axis(&mut tx, Some(a.id), &a.config.name, &json, &now).await?;
        for (n, v) in persistent {
            let value = serde_json::to_string(v).expect("value");
            store::axes::upsert_persistent(&mut tx, a.id, *n, &value, &now).await?;
        }
    }
    store::audit(
        &mut *tx,
        &audit_entry(&client, "config.import", "config", raw.to_string()),
    )
    .await?;
    // Swap the kernel's axes: take the old ones out (refused if one was enabled meanwhile).
    let mut removed = Vec::new();
    let mut refused = None;
    for (id, slot, name, _, _) in &old {
        match s.uninstall_axis(*slot, true).await {
            Ok(Ok(())) => removed.push(*id),
            _ => {
                refused = Some(name.clone());
                break;
            }
        }
    }
    let restore = |ids: Vec<i64>| {
        let s = s.clone();
        let old = old.clone();
        async move {
            for (id, slot, _, config, persistent) in &old {
                if ids.contains(id) {
                    if let Ok((_, a, d)) = s.build_axis(*id, config, persistent) {
                        let _ = s.install_axis(*slot, a, d, false).await;
                    }
                }
            }
        }
    };
    if let Some(name) = refused {
        restore(removed).await;
        return Err(not_disabled(&name));
    }
    // Install the new axes, then commit; if anything fails on the way (the cycle thread
    // unavailable, a slot refused, the commit) the kernel goes back to the old axes and the
    // transaction rolls back, so registry, kernel and database always agree.
    let mut entries = Vec::new();
    let mut failed: Option<ApiError> = None;
    for (slot, (a, persistent)) in doc.axes.iter().zip(built).enumerate() {
        let (p, axis, drive) = match s.build_axis(a.id, &a.config, &persistent) {
            Ok(x) => x,
            Err(fe) => {
                failed = Some(ApiError::invalid(fe));
                break;
            }
        };
        match s.install_axis(slot as u16, axis, drive, false).await {
            Ok(Ok(())) => {}
            Ok(Err(e)) => {
                failed = Some(ApiError::rejected(e));
                break;
            }
            Err(e) => {
                failed = Some(e);
                break;
            }
        }
        entries.push(AxisEntry {
            id: a.id,
            name: a.config.name.clone(),
            slot: slot as u16,
            config: a.config.clone(),
            params: p,
            persistent,
        });
    }
    if failed.is_none() {
        if let Err(e) = tx.commit().await {
            failed = Some(e.into());
        }
    }
    if let Some(e) = failed {
        // The old axes are out; a slot whose insert failed or never came holds nothing, and
        // removing nothing is harmless.
        for slot in 0..doc.axes.len() {
            let _ = s.uninstall_axis(slot as u16, false).await;
        }
        restore(removed).await;
        return Err(e);
    }
    {
        let mut reg = s.registry.write().unwrap();
        reg.axes = entries.into_iter().map(|e| (e.id, e)).collect();
    }
    Ok(Json(export(&s)))
}
