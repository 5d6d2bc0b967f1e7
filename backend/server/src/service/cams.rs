//! Cam tables (TwinCAT NC Camming): create, replace, delete, export and import with the
//! configuration, and the analysis FBs. A table is validated and built on a blocking thread
//! (a million-row spline takes tens of milliseconds), stored in one transaction with its audit
//! row, and only then put in the registry.

use std::sync::Arc;

use motion::cam::{
    self, Cam, CamActivationMode, CamError, CamTableData, MasterSearch, MotionFunctionPoint,
    OnlineChange, TableType, ValueSelect,
};

use super::audit_entry;
use crate::app::{AppState, CamEntry};
use crate::error::FieldError;
use crate::error::{AppError, AppResult};
use crate::model::{
    CamAnalysisResource, CamTableBody, CamTableResource, CamValuesResource, ClientInfo,
    MasterPositionResource, SlaveDynamicsResource, valid_name,
};
use crate::store::{self, AuditEntry};

/// MC_CAM_ID: 1..255.
pub const MAX_CAM_ID: u32 = 255;
/// The most rows MC_ReadMotionFunctionValues answers with in one response.
pub const MAX_VALUE_ROWS: usize = 100_000;

/// The table's own checks failed: 422 with the fields, numbered 0x4B32 when the id is one of
/// them (docs/errors.md).
fn invalid(errs: Vec<FieldError>) -> AppError {
    if errs.iter().any(|e| e.field.ends_with("id")) {
        AppError::InvalidNumbered {
            errors: errs,
            id: motion::ErrorId::CAM_TABLE_ID_INVALID,
        }
    } else {
        AppError::Invalid(errs)
    }
}

fn refused(e: CamError) -> AppError {
    AppError::refused(e.field, e.id, e.message)
}

fn resource(e: &CamEntry, with_data: bool) -> CamTableResource {
    let (master_start, master_end) = e.cam.master_range();
    let (slave_start, slave_end) = e.cam.slave_range();
    CamTableResource {
        id: e.id,
        name: e.name.clone(),
        version: e.version,
        table_type: e.data.table_type,
        periodic: e.data.periodic,
        interpolation: e.data.interpolation,
        row_count: e.data.len(),
        master_start,
        master_end,
        slave_start,
        slave_end,
        master_period: e.cam.period(),
        slave_stroke: e.cam.stroke(),
        updated_at: e.updated_at.clone(),
        rows: (with_data && !e.data.rows.is_empty()).then(|| e.data.rows.clone()),
        points: (with_data && !e.data.points.is_empty()).then(|| e.data.points.clone()),
    }
}

fn entry(s: &AppState, key: &str) -> AppResult<CamEntry> {
    s.registry
        .read()
        .unwrap()
        .find_cam(key)
        .cloned()
        .ok_or_else(|| AppError::not_found("cam_table", key))
}

pub fn list(s: &AppState) -> Vec<CamTableResource> {
    s.registry
        .read()
        .unwrap()
        .cams
        .values()
        .map(|e| resource(e, false))
        .collect()
}

pub fn get(s: &AppState, key: &str) -> AppResult<CamTableResource> {
    Ok(resource(&entry(s, key)?, true))
}

/// The table's own checks (name, id range), with the JSON path prefix of where it was sent.
fn check(body: &CamTableBody, prefix: &str) -> Vec<FieldError> {
    let mut errs = Vec::new();
    if !valid_name(&body.name) {
        errs.push(FieldError {
            field: format!("{prefix}name"),
            message: "must start with a letter or '_' and contain only letters, digits, '_' or '-' (at most 64)".into(),
        });
    }
    if let Some(id) = body.id {
        if !(1..=MAX_CAM_ID).contains(&id) {
            errs.push(FieldError {
                field: format!("{prefix}id"),
                message: format!("a cam table id (MC_CAM_ID) is 1..{MAX_CAM_ID}"),
            });
        }
    }
    errs
}

/// Validates and builds the cam off the async workers.
async fn build(data: CamTableData) -> AppResult<(CamTableData, Cam)> {
    tokio::task::spawn_blocking(move || Cam::build(&data).map(|cam| (data, cam)))
        .await
        .map_err(|e| AppError::unavailable("internal", format!("building the cam failed: {e}")))?
        .map_err(refused)
}

fn audit_detail(id: u32, name: &str, version: i64, data: &CamTableData) -> String {
    serde_json::json!({
        "id": id, "name": name, "version": version, "table_type": data.table_type,
        "periodic": data.periodic, "interpolation": data.interpolation, "row_count": data.len(),
    })
    .to_string()
}

fn name_taken(s: &AppState, name: &str, except: Option<u32>) -> AppResult<()> {
    if s.registry
        .read()
        .unwrap()
        .cams
        .values()
        .any(|c| c.name == name && Some(c.id) != except)
    {
        return Err(AppError::conflict(
            "cam_table_name_taken",
            format!("a cam table named '{name}' exists"),
        ));
    }
    Ok(())
}

/// Stores a new table (`POST /cam-tables`). Nothing is changed unless all of it commits.
pub async fn create(
    s: &AppState,
    body: CamTableBody,
    client: &ClientInfo,
) -> AppResult<CamTableResource> {
    let errs = check(&body, "");
    if !errs.is_empty() {
        return Err(invalid(errs));
    }
    let (data, cam) = build(body.data()).await?;
    let _guard = s.config_lock.lock().await;
    name_taken(s, &body.name, None)?;
    let id = {
        let reg = s.registry.read().unwrap();
        match body.id {
            Some(id) if reg.cams.contains_key(&id) => {
                return Err(AppError::conflict(
                    "cam_table_id_taken",
                    format!("cam table {id} exists: PUT /api/v1/cam-tables/{id} replaces it"),
                ));
            }
            Some(id) => id,
            None => (1..=MAX_CAM_ID)
                .find(|id| !reg.cams.contains_key(id))
                .ok_or_else(|| {
                    AppError::conflict("no_free_cam_table_id", "all 255 cam table ids are used")
                })?,
        }
    };
    store_and_register(s, id, &body.name, 1, data, cam, client, None).await
}

/// Replaces a table (`PUT /cam-tables/{table}`): same id, version + 1.
pub async fn replace(
    s: &AppState,
    key: &str,
    body: CamTableBody,
    client: &ClientInfo,
) -> AppResult<CamTableResource> {
    let _guard = s.config_lock.lock().await;
    replace_locked(s, key, body, client).await
}

/// `replace` under the configuration lock.
async fn replace_locked(
    s: &AppState,
    key: &str,
    body: CamTableBody,
    client: &ClientInfo,
) -> AppResult<CamTableResource> {
    let errs = check(&body, "");
    if !errs.is_empty() {
        return Err(invalid(errs));
    }
    let old = entry(s, key)?;
    if body.id.is_some_and(|id| id != old.id) {
        return Err(AppError::field(
            "id",
            &format!(
                "the table's id is {}; a table keeps its id (create a new one with POST)",
                old.id
            ),
        ));
    }
    name_taken(s, &body.name, Some(old.id))?;
    let (data, cam) = build(body.data()).await?;
    store_and_register(
        s,
        old.id,
        &body.name,
        old.version + 1,
        data,
        cam,
        client,
        Some(old.online),
    )
    .await
}

/// Stores a table and puts it in force. A new one (`replacing` None) goes to the kernel before
/// the commit and out again if the commit fails. New data for an existing one goes to the kernel
/// after the commit — checked first so that it will be taken: on a coupled table it is an
/// online change that reaches the slaves by `replacing`'s rules, never with a jump.
#[allow(
    clippy::too_many_arguments,
    reason = "a cam table's parts as the two callers hold them"
)]
async fn store_and_register(
    s: &AppState,
    id: u32,
    name: &str,
    version: i64,
    data: CamTableData,
    cam: Cam,
    client: &ClientInfo,
    replacing: Option<OnlineChange>,
) -> AppResult<CamTableResource> {
    let cam = Arc::new(cam);
    if replacing.is_some() {
        s.probe_cam_change(id).await?;
    }
    let now = store::now_rfc3339();
    let action = if replacing.is_some() {
        "cam_table.replace"
    } else {
        "cam_table.create"
    };
    s.audit_barrier().await;
    let mut tx = s.db.begin().await?;
    store::cams::upsert_cam_table(&mut tx, id, name, version, &data, &now).await?;
    store::audit(
        &mut *tx,
        &audit_entry(client, action, name, audit_detail(id, name, version, &data)),
    )
    .await?;
    match replacing {
        None => {
            s.install_cam(id, cam.clone()).await?;
            if let Err(e) = tx.commit().await {
                let _ = s.uninstall_cam(id).await;
                return Err(e.into());
            }
        }
        Some(change) => {
            tx.commit().await?;
            if let Err(e) = s.change_cam(id, cam.clone(), change).await {
                // Stored, not in force: the registry follows the database (the analysis shows
                // the new data); the cycle thread takes it at the next start.
                tracing::error!(
                    "cam table {id} '{name}' stored but not taken by the cycle thread: {e}"
                );
                register(s, id, name, version, data, cam, now, change);
                return Err(AppError::unavailable(
                    "cam_table_not_active",
                    format!(
                        "cam table '{name}' version {version} is stored, but the cycle thread did not take it ({e}); it is in force after the next start"
                    ),
                ));
            }
        }
    }
    Ok(register(
        s,
        id,
        name,
        version,
        data,
        cam,
        now,
        replacing.unwrap_or_default(),
    ))
}

#[allow(
    clippy::too_many_arguments,
    reason = "a cam table's parts as the two callers hold them"
)]
fn register(
    s: &AppState,
    id: u32,
    name: &str,
    version: i64,
    data: CamTableData,
    cam: Arc<Cam>,
    updated_at: String,
    online: OnlineChange,
) -> CamTableResource {
    let e = CamEntry {
        id,
        name: name.to_string(),
        version,
        data: Arc::new(data),
        cam,
        updated_at,
        online,
    };
    let r = resource(&e, false);
    s.registry_write().cams.insert(id, e);
    r
}

/// MC_SetCamOnlineChangeMode: how later writes to the table reach coupled slaves.
/// DELETEQUEUEDDATA drops written data that has not reached them and keeps the mode.
pub async fn set_online_change(
    s: &AppState,
    key: &str,
    change: OnlineChange,
    client: &ClientInfo,
) -> AppResult<OnlineChange> {
    let _guard = s.config_lock.lock().await;
    let e = entry(s, key)?;
    match change.activation_mode {
        CamActivationMode::NextCycleOnce => {
            return Err(AppError::refused(
                "activation_mode",
                motion::ErrorId::CAM_MODE_INVALID,
                "next_cycle_once is not implemented (as in TwinCAT)",
            ));
        }
        CamActivationMode::DeleteQueuedData => {
            s.drop_cam_data(e.id).await?;
        }
        _ => {
            if let Some(c) = s.registry_write().cams.get_mut(&e.id) {
                c.online = change;
            }
        }
    }
    s.audit(AuditEntry {
        detail: serde_json::to_string(&change).unwrap_or_default(),
        ..audit_entry(
            client,
            "cam_table.online_change_mode",
            &e.name,
            String::new(),
        )
    });
    Ok(entry(s, key)?.online)
}

pub fn online_change(s: &AppState, key: &str) -> AppResult<OnlineChange> {
    Ok(entry(s, key)?.online)
}

/// MC_ReadMotionFunctionPoint.
pub fn point(s: &AppState, key: &str, index: u32) -> AppResult<MotionFunctionPoint> {
    let e = entry(s, key)?;
    e.data
        .points
        .iter()
        .find(|p| p.point_index == index)
        .copied()
        .ok_or_else(|| AppError::not_found("point", &index.to_string()))
}

/// MC_WriteMotionFunction(Point): the points with these indices replaced (the whole table is
/// validated again); on a coupled table an online change.
pub async fn write_points(
    s: &AppState,
    key: &str,
    points: Vec<MotionFunctionPoint>,
    client: &ClientInfo,
) -> AppResult<CamTableResource> {
    let _guard = s.config_lock.lock().await;
    let e = entry(s, key)?;
    if e.data.table_type != TableType::MotionFunction {
        return Err(AppError::refused(
            "points",
            motion::ErrorId::CAM_TABLE_TYPE_INVALID,
            "only a motion function has points (replace a position table with PUT /cam-tables/{table})",
        ));
    }
    let mut data = (*e.data).clone();
    for (i, p) in points.iter().enumerate() {
        match data
            .points
            .iter_mut()
            .find(|q| q.point_index == p.point_index)
        {
            Some(q) => *q = *p,
            None => {
                return Err(AppError::refused(
                    format!("points[{i}].point_index"),
                    motion::ErrorId::CAM_POINT_ID_INVALID,
                    format!("the table has no point {}", p.point_index),
                ));
            }
        }
    }
    let body = CamTableBody {
        id: Some(e.id),
        name: e.name.clone(),
        table_type: data.table_type,
        periodic: data.periodic,
        interpolation: data.interpolation,
        rows: Vec::new(),
        points: data.points,
    };
    replace_locked(s, &e.id.to_string(), body, client).await
}

/// Deletes a table (`DELETE /cam-tables/{table}`).
pub async fn delete(s: &AppState, key: &str, client: &ClientInfo) -> AppResult<()> {
    let _guard = s.config_lock.lock().await;
    let e = entry(s, key)?;
    s.audit_barrier().await;
    let mut tx = s.db.begin().await?;
    store::cams::delete_cam_table(&mut tx, e.id).await?;
    store::audit(
        &mut *tx,
        &audit_entry(
            client,
            "cam_table.delete",
            &e.name,
            audit_detail(e.id, &e.name, e.version, &e.data),
        ),
    )
    .await?;
    s.uninstall_cam(e.id).await?;
    if let Err(err) = tx.commit().await {
        let _ = s.install_cam(e.id, e.cam.clone()).await;
        return Err(err.into());
    }
    s.registry_write().cams.remove(&e.id);
    Ok(())
}

/// Loads the stored tables at start-up (building each; a table that no longer builds is
/// reported and skipped rather than stopping motiond).
pub async fn load(s: &AppState) -> Result<usize, String> {
    let stored = store::cams::load_cam_tables(&s.db)
        .await
        .map_err(|e| format!("cannot read cam tables: {e}"))?;
    let mut n = 0;
    for t in stored {
        match build(t.data).await {
            Ok((data, cam)) => {
                let cam = Arc::new(cam);
                s.install_cam(t.id, cam.clone())
                    .await
                    .map_err(|e| format!("cam table {}: {e}", t.id))?;
                s.registry_write().cams.insert(
                    t.id,
                    CamEntry {
                        id: t.id,
                        name: t.name,
                        version: t.version,
                        data: Arc::new(data),
                        cam,
                        updated_at: t.updated_at,
                        online: OnlineChange::default(),
                    },
                );
                n += 1;
            }
            Err(e) => tracing::error!(
                "cam table {} '{}' is stored but does not build: {e}",
                t.id,
                t.name
            ),
        }
    }
    Ok(n)
}

/// The tables for the configuration document, with their ids.
pub fn export(s: &AppState) -> Vec<CamTableBody> {
    s.registry
        .read()
        .unwrap()
        .cams
        .values()
        .map(|e| CamTableBody {
            id: Some(e.id),
            name: e.name.clone(),
            table_type: e.data.table_type,
            periodic: e.data.periodic,
            interpolation: e.data.interpolation,
            rows: e.data.rows.clone(),
            points: e.data.points.clone(),
        })
        .collect()
}

/// The cam tables of an import, validated and built (before anything is changed); errors name
/// `cam_tables[i].…`.
pub async fn prepare_import(tables: &[CamTableBody]) -> Result<Vec<CamEntry>, Vec<FieldError>> {
    let mut errs = Vec::new();
    let mut entries = Vec::new();
    let now = store::now_rfc3339();
    for (i, t) in tables.iter().enumerate() {
        let prefix = format!("cam_tables[{i}].");
        errs.extend(check(t, &prefix));
        match t.id {
            None => errs.push(FieldError {
                field: format!("{prefix}id"),
                message: "required in a configuration document".into(),
            }),
            Some(id) if tables[..i].iter().any(|o| o.id == Some(id)) => errs.push(FieldError {
                field: format!("{prefix}id"),
                message: "duplicate id".into(),
            }),
            _ => {}
        }
        if tables[..i].iter().any(|o| o.name == t.name) {
            errs.push(FieldError {
                field: format!("{prefix}name"),
                message: "duplicate name".into(),
            });
        }
        match build(t.data()).await {
            Ok((data, cam)) => entries.push(CamEntry {
                id: t.id.unwrap_or(0),
                name: t.name.clone(),
                version: 1,
                data: Arc::new(data),
                cam: Arc::new(cam),
                updated_at: now.clone(),
                online: OnlineChange::default(),
            }),
            Err(AppError::Refused { field, message, id }) => errs.push(FieldError {
                field: format!("{prefix}{field}"),
                message: format!("{message} ({id})"),
            }),
            Err(e) => errs.push(FieldError {
                field: format!("{prefix}table_type"),
                message: e.to_string(),
            }),
        }
    }
    if errs.is_empty() {
        Ok(entries)
    } else {
        Err(errs)
    }
}

/// Swaps the kernel's cams for an import's (its axes are new: nothing is coupled); on `Err`
/// the old cams are back.
pub async fn install_import(s: &AppState, entries: &[CamEntry]) -> AppResult<()> {
    let old = installed(s);
    let mut result = Ok(());
    for (id, _) in &old {
        if let Err(e) = s.uninstall_cam(*id).await {
            result = Err(e);
            break;
        }
    }
    if result.is_ok() {
        for e in entries {
            if let Err(err) = s.install_cam(e.id, e.cam.clone()).await {
                result = Err(err);
                break;
            }
        }
    }
    if result.is_err() {
        restore_cams(s, &old, entries).await;
    }
    result
}

/// Puts the cams of `old` back after a failed swap (and takes `new` out).
pub async fn restore_cams(s: &AppState, old: &[(u32, Arc<Cam>)], new: &[CamEntry]) {
    for e in new {
        let _ = s.uninstall_cam(e.id).await;
    }
    for (id, cam) in old {
        let _ = s.install_cam(*id, cam.clone()).await;
    }
}

/// The kernel's cams as the registry has them (to restore after a failed import).
pub fn installed(s: &AppState) -> Vec<(u32, Arc<Cam>)> {
    s.registry
        .read()
        .unwrap()
        .cams
        .values()
        .map(|e| (e.id, e.cam.clone()))
        .collect()
}

/// Replaces the stored tables within an import's transaction.
pub async fn store_import(
    tx: &mut sqlx::SqliteConnection,
    entries: &[CamEntry],
) -> Result<(), sqlx::Error> {
    store::cams::delete_all_cam_tables(tx).await?;
    for e in entries {
        store::cams::upsert_cam_table(tx, e.id, &e.name, e.version, &e.data, &e.updated_at).await?;
    }
    Ok(())
}

/// MC_ReadCamTableCharacteristics.
pub async fn characteristics(s: &AppState, key: &str) -> AppResult<cam::Characteristics> {
    let e = entry(s, key)?;
    tokio::task::spawn_blocking(move || cam::characteristics(&e.cam))
        .await
        .map_err(|e| AppError::unavailable("internal", format!("the analysis failed: {e}")))
}

/// MC_ReadCamTableSlaveDynamics at a raw master position (the table's own coordinates).
pub fn slave_dynamics(
    s: &AppState,
    key: &str,
    master_position: f64,
) -> AppResult<SlaveDynamicsResource> {
    let e = entry(s, key)?;
    if !master_position.is_finite() {
        return Err(AppError::field(
            "master_position",
            "must be a finite number",
        ));
    }
    let v = e.cam.eval(master_position);
    let (velocity, acceleration) = match e.data.table_type {
        TableType::MotionFunction => (v.velocity, v.acceleration),
        TableType::Equidistant => (v.velocity, 0.0),
        TableType::NonEquidistant => (0.0, 0.0),
    };
    Ok(SlaveDynamicsResource {
        master_position,
        slave_position: v.position,
        slave_velocity: velocity,
        slave_acceleration: acceleration,
    })
}

/// MC_ReadCamTableMasterPosition.
pub async fn master_position(
    s: &AppState,
    key: &str,
    q: MasterSearch,
) -> AppResult<MasterPositionResource> {
    let e = entry(s, key)?;
    let (low, high) = tokio::task::spawn_blocking(move || cam::master_position(&e.cam, &q))
        .await
        .map_err(|e| AppError::unavailable("internal", format!("the search failed: {e}")))?
        .map_err(refused)?;
    Ok(MasterPositionResource {
        master_low: low,
        master_high: high,
    })
}

/// The cam editor's view of a table that is not stored (or not yet): validated exactly as a
/// `POST`/`PUT` would (the same errors at the same fields), then sampled over one cycle with
/// its characteristics and its discontinuities. Off the async workers; nothing is stored.
pub async fn analyse(body: CamTableBody, samples: usize) -> AppResult<CamAnalysisResource> {
    let errs = check(&body, "");
    if !errs.is_empty() {
        return Err(invalid(errs));
    }
    let (_, cam) = build(body.data()).await?;
    tokio::task::spawn_blocking(move || {
        let (x0, xn) = cam.master_range();
        let (y0, yn) = cam.slave_range();
        let step = (xn - x0) / (samples - 1) as f64;
        let rows = (0..samples)
            .map(|i| {
                // The last sample exactly at the end (no rounding past the table).
                let x = if i + 1 == samples {
                    xn
                } else {
                    x0 + step * i as f64
                };
                let v = cam.eval_in_range(x);
                vec![x, v.position, v.velocity, v.acceleration, v.jerk]
            })
            .collect();
        CamAnalysisResource {
            master_start: x0,
            master_end: xn,
            slave_start: y0,
            slave_end: yn,
            values: CamValuesResource {
                columns: vec!["master", "position", "velocity", "acceleration", "jerk"],
                rows,
            },
            characteristics: cam::characteristics(&cam),
            discontinuities: cam::discontinuities(&cam),
        }
    })
    .await
    .map_err(|e| AppError::unavailable("internal", format!("the analysis failed: {e}")))
}

/// MC_ReadMotionFunctionValues (also for position tables: the cam editor plots both).
pub fn values(
    s: &AppState,
    key: &str,
    start: f64,
    end: f64,
    increment: f64,
    select: &[ValueSelect],
) -> AppResult<CamValuesResource> {
    let e = entry(s, key)?;
    let rows = cam::sample(&e.cam, start, end, increment, MAX_VALUE_ROWS).map_err(refused)?;
    let order = [
        ValueSelect::Position,
        ValueSelect::Velocity,
        ValueSelect::Acceleration,
        ValueSelect::Jerk,
    ];
    let chosen: Vec<ValueSelect> = order
        .into_iter()
        .filter(|v| select.is_empty() || select.contains(v))
        .collect();
    let mut columns = vec!["master"];
    columns.extend(chosen.iter().map(|v| match v {
        ValueSelect::Position => "position",
        ValueSelect::Velocity => "velocity",
        ValueSelect::Acceleration => "acceleration",
        ValueSelect::Jerk => "jerk",
    }));
    Ok(CamValuesResource {
        columns,
        rows: rows
            .into_iter()
            .map(|(x, v)| {
                let mut row = Vec::with_capacity(chosen.len() + 1);
                row.push(x);
                row.extend(chosen.iter().map(|c| match c {
                    ValueSelect::Position => v.position,
                    ValueSelect::Velocity => v.velocity,
                    ValueSelect::Acceleration => v.acceleration,
                    ValueSelect::Jerk => v.jerk,
                }));
                row
            })
            .collect(),
    })
}

/// MC_CamInfo(_V2) of a cam slave: the coupling as it is, or (`master_position`) as it would be
/// with the master there — each cam's share from its table, offsets, scalings and the strokes
/// counted from its base cycle. After an error ended the coupling: its last valid state.
pub fn cam_info(s: &AppState, axis: &str, master_position: Option<f64>) -> AppResult<cam::CamInfo> {
    let slot = {
        let reg = s.registry.read().unwrap();
        reg.find(axis)
            .ok_or_else(|| AppError::not_found("axis", axis))?
            .slot
    };
    let mut info = s.status(slot).1.unwrap_or_default().cam;
    if info.cam_table_id == 0 {
        return Err(AppError::rejected(motion::ErrorId::CAM_NOT_COUPLED));
    }
    let Some(m) = master_position else {
        return Ok(info);
    };
    if !m.is_finite() {
        return Err(AppError::field(
            "master_position",
            "must be a finite number",
        ));
    }
    let reg = s.registry.read().unwrap();
    let mut slave = 0.0;
    for (k, t) in info.cams.iter_mut().enumerate() {
        if t.cam_table_id == 0 {
            continue;
        }
        let c = reg
            .cams
            .get(&t.cam_table_id)
            .ok_or_else(|| AppError::not_found("cam_table", &t.cam_table_id.to_string()))?
            .cam
            .clone();
        let stroke = c.stroke() * t.slave_scaling;
        // The base cycle from where the master is now and the strokes counted so far.
        let k_now = c
            .cycle_of((info.actual_master_axis_pos + t.master_offset) / t.master_scaling)
            .0;
        let k_base = if c.periodic && stroke != 0.0 {
            k_now - (t.sum_of_slave_strokes / stroke).round() as i64
        } else {
            k_now
        };
        let x = (m + t.master_offset) / t.master_scaling;
        let (kx, xl) = c.cycle_of(x);
        let f = if c.periodic {
            c.eval_in_range_with(xl, t.interpolation)
        } else {
            c.eval_with(x, t.interpolation)
        };
        let strokes = if c.periodic {
            (kx - k_base) as f64 * stroke
        } else {
            0.0
        };
        t.actual_master_cam_pos = if c.periodic { xl } else { x };
        t.actual_slave_cam_pos = f.position;
        t.sum_of_slave_strokes = strokes;
        t.slave_contribution = f.position * t.slave_scaling + t.slave_offset + strokes;
        slave += t.slave_contribution;
        if k == 0 {
            info.actual_master_cam_pos = t.actual_master_cam_pos;
            info.actual_slave_cam_pos = f.position;
            info.sum_of_slave_strokes = strokes;
        }
    }
    info.actual_master_axis_pos = m;
    info.actual_slave_axis_pos = slave;
    Ok(info)
}
