//! Axes: configurations (create, replace, delete, import, export), parameters
//! (MC_ReadParameter, MC_WriteParameter[Persistent]) and status. Each change is one transaction
//! with its audit row; the kernel takes the new axis before the commit and gets the old one
//! back if the commit fails, so registry, kernel and database always agree.

use std::collections::BTreeMap;

use axum::http::StatusCode;
use motion::{AxisState, AxisStatus, CommandKind, Target};

use super::audit_entry;
use crate::app::{AppState, AxisEntry};
use crate::error::FieldError;
use crate::error::{AppError, AppResult};
use crate::model::{
    AxisConfigDto, AxisResource, ClientInfo, ConfigAxis, ConfigChange, ConfigDocument,
    ParameterChange, ParameterResource, ParameterWrite, PeakResetResource, StatusResource,
};
use crate::params::{self, ParamValue};
use crate::store::{self, AuditEntry};

fn resource(s: &AppState, e: &AxisEntry) -> AxisResource {
    let state = s.status(e.slot).1.map(|st| st.state).unwrap_or_default();
    AxisResource {
        id: e.id,
        slot: e.slot,
        state,
        config: e.config.clone(),
        change: None,
    }
}

/// The cycle thread's refusal to swap an axis that is not disabled, as the 409 that says so.
fn refused_unless_disabled(e: AppError, name: &str) -> AppError {
    match e {
        AppError::Rejected(_) => not_disabled(name),
        e => e,
    }
}

fn not_disabled(name: &str) -> AppError {
    AppError::conflict(
        "axis_not_disabled",
        format!("axis '{name}' is not disabled: switch it off (DELETE its power command) first"),
    )
}

/// All axes, by id.
pub fn list(s: &AppState) -> Vec<AxisResource> {
    let reg = s.registry.read().unwrap();
    reg.axes.values().map(|e| resource(s, e)).collect()
}

/// One axis by id or name.
pub fn get(s: &AppState, axis: &str) -> AppResult<AxisResource> {
    let reg = s.registry.read().unwrap();
    let e = reg
        .find(axis)
        .ok_or_else(|| AppError::not_found("axis", axis))?;
    Ok(resource(s, e))
}

fn check_name_free(s: &AppState, name: &str, except: Option<i64>) -> AppResult<()> {
    let reg = s.registry.read().unwrap();
    if reg
        .axes
        .values()
        .any(|a| a.name == name && Some(a.id) != except)
    {
        return Err(AppError::conflict(
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
) -> AppResult<AxisResource> {
    let _guard = s.config_lock.lock().await;
    config
        .to_parameters(0, s.info.cycle_time_s)
        .map_err(AppError::invalid)?;
    check_name_free(s, &config.name, None)?;
    let slot = s
        .registry
        .read()
        .unwrap()
        .free_slot()
        .ok_or_else(|| AppError::conflict("no_free_slot", "all axis slots are used"))?;
    let json = serde_json::to_string(&config).expect("config serialises");
    s.audit_barrier().await;
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
        .map_err(AppError::invalid)?;
    s.install_axis(slot, axis, drive, false)
        .await
        .map_err(|e| match e {
            AppError::Rejected(id) => {
                AppError::kernel(StatusCode::CONFLICT, "Axis not installed", id)
            }
            e => e,
        })?;
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
    s.registry_write().axes.insert(id, entry);
    Ok(r)
}

/// What a new configuration changes for an axis: the parameters whose configured value
/// changes, the persistent values that give way to them, and whether the axis must be
/// re-created (unit, modulo or drive changed, or the new values cannot be written online one
/// by one, each leaving a consistent set) — decided here, shown by `?dry_run=true`.
struct Plan {
    change: ConfigChange,
    /// Online writes (number, value), in an order that keeps the set consistent.
    writes: Vec<(u16, f64)>,
    /// The persistent values kept (storage number → value).
    kept: BTreeMap<u16, ParamValue>,
}

fn plan(s: &AppState, e: &AxisEntry, new: &AxisConfigDto) -> AppResult<Plan> {
    let ct = s.info.cycle_time_s;
    let new_p = new.to_parameters(e.id, ct).map_err(AppError::invalid)?;
    let old_p = e.config.to_parameters(e.id, ct).ok();
    let mut change = ConfigChange::default();
    let mut reasons = Vec::new();
    if new.unit != e.config.unit {
        reasons.push("unit changed".to_owned());
    }
    if new.modulo != e.config.modulo {
        reasons.push("modulo changed".to_owned());
    }
    if new.drive != e.config.drive {
        reasons.push("drive changed".to_owned());
    }
    if new.position_compensation_table != e.config.position_compensation_table {
        reasons.push("position compensation table changed".to_owned());
    }
    let Some(old_p) = old_p else {
        reasons.push("the stored configuration is not valid any more".to_owned());
        change.rebuild_reasons = reasons;
        change.rebuild = true;
        return Ok(Plan {
            change,
            writes: Vec::new(),
            kept: BTreeMap::new(),
        });
    };
    let mut changed = Vec::new();
    for ((info, old), (_, new_v)) in old_p.entries().zip(new_p.entries()) {
        if old == new_v {
            continue;
        }
        let online = e.params.get(info.number).unwrap_or(old);
        change.parameters.push(ParameterChange {
            name: info.name,
            number: info.number,
            configured: old,
            online,
            new: new_v,
        });
        if let Some(v) = e.persistent.get(&info.number) {
            change.persistent_discarded.push(ParameterChange {
                name: info.name,
                number: info.number,
                configured: old,
                online,
                new: *v,
            });
        }
        if info.read_only {
            reasons.push(format!("{} cannot be written online", info.name));
        } else if online != new_v {
            changed.push((info.number, new_v.as_f64()));
        }
    }
    let kept: BTreeMap<u16, ParamValue> = e
        .persistent
        .iter()
        .filter(|(n, _)| !change.parameters.iter().any(|c| c.number == **n))
        .map(|(n, v)| (*n, *v))
        .collect();
    // The online writes in an order in which each leaves a consistent set (raising a maximum
    // before what it bounds …), found by trying them against a copy as the kernel would.
    let mut writes = Vec::new();
    if reasons.is_empty() {
        let mut p = e.params.clone();
        let mut left = changed;
        while !left.is_empty() {
            let Some(i) = left
                .iter()
                .position(|(n, v)| p.clone().write(*n, *v).is_ok())
            else {
                reasons.push(format!(
                    "the new values of {} cannot be written online one by one",
                    left.iter()
                        .filter_map(|(n, _)| params::by_number(*n).map(|i| i.name))
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
                break;
            };
            let (n, v) = left.remove(i);
            p.write(n, v).expect("tried above");
            writes.push((n, v));
        }
    }
    change.rebuild = !reasons.is_empty();
    change.rebuild_reasons = reasons;
    Ok(Plan {
        change,
        writes,
        kept,
    })
}

/// Replaces an axis's configuration. Without a rebuild (see [`plan`]) the changed parameters
/// are written online and the axis keeps running, homed, where it is; with one, the axis must
/// be disabled and is re-created. Persistent values of parameters the save does not change
/// are kept either way. `dry_run`: only the plan.
pub async fn replace(
    s: &AppState,
    axis: &str,
    config: AxisConfigDto,
    client: &ClientInfo,
    dry_run: bool,
) -> AppResult<AxisResource> {
    let _guard = s.config_lock.lock().await;
    let (entry, plan) = {
        let reg = s.registry.read().unwrap();
        let e = reg
            .find(axis)
            .ok_or_else(|| AppError::not_found("axis", axis))?;
        let planned = plan(s, e, &config)?;
        let old = (e.config.clone(), e.params.clone(), e.persistent.clone());
        ((e.id, e.slot, e.name.clone(), old), planned)
    };
    let (id, slot, old_name, (old_config, old_params, old_persistent)) = entry;
    check_name_free(s, &config.name, Some(id))?;
    let Plan {
        mut change,
        writes,
        kept,
    } = plan;
    if dry_run {
        // What the save would answer: a drive the bus does not have is a 422 here too (the
        // save itself checks it where the axis is built).
        s.check_drive_on_bus(id, &config.drive)
            .map_err(AppError::Invalid)?;
        change.dry_run = true;
        return Ok(AxisResource {
            id,
            slot,
            state: s.status(slot).1.map(|st| st.state).unwrap_or_default(),
            config,
            change: Some(change),
        });
    }
    let json = serde_json::to_string(&config).expect("config serialises");
    s.audit_barrier().await;
    let mut tx = s.db.begin().await?;
    store::axes::update_axis(&mut tx, id, &config.name, &json, &store::now_rfc3339()).await?;
    for c in &change.persistent_discarded {
        store::axes::delete_persistent(&mut tx, id, c.number).await?;
    }
    store::audit(
        &mut *tx,
        &audit_entry(client, "axis.replace", &old_name, json),
    )
    .await?;
    let params = if change.rebuild {
        let (p, new_axis, drive) = s
            .build_axis(id, &config, &kept)
            .map_err(AppError::invalid)?;
        s.install_axis(slot, new_axis, drive, true)
            .await
            .map_err(|e| refused_unless_disabled(e, &old_name))?;
        if let Err(e) = tx.commit().await {
            // Put the old axis back (it is disabled: the new one was just installed).
            if let Ok((_, a, d)) = s.build_axis(id, &old_config, &old_persistent) {
                let _ = s.install_axis(slot, a, d, false).await;
            }
            return Err(e.into());
        }
        p
    } else {
        let mut p = old_params;
        let mut done = Vec::new();
        let mut failed = None;
        for &(number, value) in &writes {
            let before = p.get(number).map(|v| v.as_f64()).unwrap_or(value);
            match s
                .kernel_command(
                    Target::Axis(slot),
                    CommandKind::WriteParameter { number, value },
                )
                .await
            {
                Ok(_) => {
                    p.write(number, value).expect("planned");
                    done.push((number, before));
                }
                Err(e) => {
                    failed = Some(e);
                    break;
                }
            }
        }
        let failed = match failed {
            Some(e) => Some(e),
            None => tx.commit().await.err().map(AppError::from),
        };
        if let Some(e) = failed {
            // Nothing stored, so nothing left in force: the old values go back, last first.
            for (number, value) in done.into_iter().rev() {
                let _ = s
                    .kernel_command(
                        Target::Axis(slot),
                        CommandKind::WriteParameter { number, value },
                    )
                    .await;
            }
            return Err(match e {
                AppError::Rejected(id) => AppError::refused("parameters", id, id.text()),
                e => e,
            });
        }
        p
    };
    let mut reg = s.registry_write();
    let e = reg.axes.get_mut(&id).expect("locked by config_lock");
    e.name = config.name.clone();
    e.config = config;
    e.params = params;
    e.persistent = kept;
    let mut r = resource(s, e);
    r.change = Some(change);
    Ok(r)
}

/// Deletes an axis (it must be disabled).
pub async fn delete(s: &AppState, axis: &str, client: &ClientInfo) -> AppResult<()> {
    let _guard = s.config_lock.lock().await;
    let (id, slot, name, config, persistent) = {
        let reg = s.registry.read().unwrap();
        let e = reg
            .find(axis)
            .ok_or_else(|| AppError::not_found("axis", axis))?;
        (
            e.id,
            e.slot,
            e.name.clone(),
            e.config.clone(),
            e.persistent.clone(),
        )
    };
    s.audit_barrier().await;
    let mut tx = s.db.begin().await?;
    // The axis leaves its group (only while the group is disabled), in the same transaction.
    let groups = super::groups::axis_leaves(s, &mut tx, id, slot).await?;
    store::axes::delete_axis(&mut tx, id).await?;
    store::audit(
        &mut *tx,
        &audit_entry(client, "axis.delete", &name, String::new()),
    )
    .await?;
    s.uninstall_axis(slot, true)
        .await
        .map_err(|e| refused_unless_disabled(e, &name))?;
    if let Err(e) = tx.commit().await {
        if let Ok((_, a, d)) = s.build_axis(id, &config, &persistent) {
            let _ = s.install_axis(slot, a, d, false).await;
        }
        return Err(e.into());
    }
    s.registry_write().axes.remove(&id);
    super::groups::register(s, groups);
    Ok(())
}

/// The live status of an axis.
pub fn status(s: &AppState, axis: &str) -> AppResult<StatusResource> {
    let (slot, id, name, unit) = {
        let reg = s.registry.read().unwrap();
        let e = reg
            .find(axis)
            .ok_or_else(|| AppError::not_found("axis", axis))?;
        (e.slot, e.id, e.name.clone(), e.config.unit.clone())
    };
    let (cycle, status) = s.status(slot);
    Ok(StatusResource {
        axis: name,
        axis_id: id,
        cycle,
        unit,
        status: s.status_view(status.unwrap_or_default()),
    })
}

/// Restarts the following-error peak hold (audited; no motion, no command).
pub async fn reset_following_error_peak(
    s: &AppState,
    axis: &str,
    client: &ClientInfo,
) -> AppResult<PeakResetResource> {
    let (slot, name) = s.axis_slot(axis)?;
    let result = s.reset_following_error_peak(slot).await;
    let outcome = match &result {
        Ok(_) => "applied",
        Err(AppError::Rejected(_)) => "rejected:axis_unknown",
        // The cycle thread did not answer: nothing happened, nothing to audit.
        Err(_) => return result.map(|cycle| PeakResetResource { axis: name, cycle }),
    };
    s.audit(AuditEntry {
        at: store::now_rfc3339(),
        client_addr: Some(client.addr.clone()),
        client_id: client.id.clone(),
        principal: client.principal.clone(),
        action: "axis.following_error_peak.reset".into(),
        target: Some(name.clone()),
        command_id: None,
        detail: String::new(),
        outcome: Some(outcome.into()),
        idempotency_key: None,
    });
    match result {
        Ok(cycle) => Ok(PeakResetResource { axis: name, cycle }),
        // The axis was removed between the look-up and the cycle thread.
        Err(_) => Err(AppError::not_found("axis", axis)),
    }
}

fn parameter_resource(
    e: &AxisEntry,
    info: &'static params::ParameterInfo,
    status: &AxisStatus,
    configured: Option<&motion::AxisParameters>,
) -> ParameterResource {
    ParameterResource {
        info: *info,
        unit_text: info.unit.text(&e.config.unit),
        value: params::read(&e.params, info.number, status).unwrap_or(ParamValue::Number(f64::NAN)),
        persistent_value: e.persistent.get(&info.storage).copied(),
        configured_value: configured.and_then(|c| c.get(info.number).ok()),
    }
}

/// The parameter set of an axis's configuration alone.
fn configured(s: &AppState, e: &AxisEntry) -> Option<motion::AxisParameters> {
    e.config.to_parameters(e.id, s.info.cycle_time_s).ok()
}

/// Every MC_AxisParameter of an axis with its values.
pub fn parameters(s: &AppState, axis: &str) -> AppResult<Vec<ParameterResource>> {
    let reg = s.registry.read().unwrap();
    let e = reg
        .find(axis)
        .ok_or_else(|| AppError::not_found("axis", axis))?;
    let status = s.status(e.slot).1.unwrap_or_default();
    let c = configured(s, e);
    Ok(params::PARAMETERS
        .iter()
        .map(|i| parameter_resource(e, i, &status, c.as_ref()))
        .collect())
}

/// One parameter (MC_ReadParameter).
pub fn parameter(s: &AppState, axis: &str, parameter: &str) -> AppResult<ParameterResource> {
    let reg = s.registry.read().unwrap();
    let e = reg
        .find(axis)
        .ok_or_else(|| AppError::not_found("axis", axis))?;
    let info =
        params::lookup(parameter).ok_or_else(|| AppError::not_found("parameter", parameter))?;
    let status = s.status(e.slot).1.unwrap_or_default();
    Ok(parameter_resource(
        e,
        info,
        &status,
        configured(s, e).as_ref(),
    ))
}

/// Writes a parameter: MC_WriteParameter, or MC_WriteParameterPersistent with `persistent`
/// (committed before it is acknowledged). `raw` is the body as sent, for the audit log.
pub async fn write_parameter(
    s: &AppState,
    (axis, parameter): (&str, &str),
    w: ParameterWrite,
    raw: &serde_json::Value,
    client: &ClientInfo,
) -> AppResult<ParameterResource> {
    let _guard = s.config_lock.lock().await;
    let (id, slot, name, mut p) = {
        let reg = s.registry.read().unwrap();
        let e = reg
            .find(axis)
            .ok_or_else(|| AppError::not_found("axis", axis))?;
        (e.id, e.slot, e.name.clone(), e.params.clone())
    };
    let before = p.clone();
    let info =
        params::lookup(parameter).ok_or_else(|| AppError::not_found("parameter", parameter))?;
    let invalid = |id: motion::ErrorId, msg: String| AppError::refused("value", id, msg);
    params::set(&mut p, info.number, w.value).map_err(|e| invalid(e, e.text().into()))?;
    params::validate(&p).map_err(|i| invalid(i.error, i.message))?;
    let kind = CommandKind::WriteParameter {
        number: info.number,
        value: w.value.as_f64(),
    };
    let audit = AuditEntry {
        command_id: None,
        ..audit_entry(
            client,
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
        s.audit_barrier().await;
        let mut tx = s.db.begin().await?;
        let value = serde_json::to_string(&w.value).expect("value");
        store::axes::upsert_persistent(&mut tx, id, info.storage, &value, &store::now_rfc3339())
            .await?;
        store::audit(&mut *tx, &audit).await?;
        // The kernel checks the value with the same table (it should agree with the checks
        // above): its refusal is the same 422 with the error number.
        s.kernel_command(Target::Axis(slot), kind)
            .await
            .map_err(|e| match e {
                AppError::Rejected(id) => invalid(id, id.text().into()),
                e => e,
            })?;
        if let Err(e) = tx.commit().await {
            // Not stored, so not acknowledged and not left active: the kernel gets the value
            // it had back, and API, kernel and database agree.
            let status = s.status(slot).1.unwrap_or_default();
            let restored = match params::read(&before, info.number, &status) {
                Ok(old) => s
                    .kernel_command(
                        Target::Axis(slot),
                        CommandKind::WriteParameter {
                            number: info.number,
                            value: old.as_f64(),
                        },
                    )
                    .await
                    .is_ok(),
                Err(_) => false,
            };
            tracing::error!(
                "axis {name}: parameter {} not persisted ({e}); old value {}",
                info.number,
                if restored { "restored" } else { "NOT restored" }
            );
            return Err(AppError::unavailable(
                "storage_unavailable",
                if restored {
                    format!(
                        "the value was not written: the database did not take it ({e}); the old value is in force"
                    )
                } else {
                    format!(
                        "the value is active but was NOT persisted, and the old value could not be restored: {e}"
                    )
                },
            ));
        }
    } else {
        // The kernel checks the value with the same table (it should agree with the checks
        // above): its refusal is the same 422 with the error number.
        s.kernel_command(Target::Axis(slot), kind)
            .await
            .map_err(|e| match e {
                AppError::Rejected(id) => invalid(id, id.text().into()),
                e => e,
            })?;
        s.audit(audit);
    }
    let mut reg = s.registry_write();
    let e = reg.axes.get_mut(&id).expect("locked by config_lock");
    e.params = p;
    if w.persistent {
        e.persistent.insert(info.storage, w.value);
    }
    let status = s.status(slot).1.unwrap_or_default();
    Ok(parameter_resource(
        e,
        info,
        &status,
        configured(s, e).as_ref(),
    ))
}

/// The whole configuration: axes with their persistent parameters.
pub fn export(s: &AppState) -> ConfigDocument {
    let cam_tables = Some(super::cams::export(s));
    let bus = &s.info.bus;
    let bus = Some(crate::model::BusSettings {
        kind: bus.kind,
        interface: bus
            .ethercat
            .as_ref()
            .filter(|_| bus.kind == crate::bus::BusKind::Ethercat)
            .map(|(st, _)| st.interface.clone()),
        max_errors_in_row: bus.ethercat.as_ref().map(|(st, _)| st.max_errors_in_row),
    });
    let reg = s.registry.read().unwrap();
    let groups = Some(super::groups::export(s));
    ConfigDocument {
        version: 1,
        cam_tables,
        groups,
        bus,
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

/// An axis as installed before an import: id, slot, name, configuration, persistent overlay.
type InstalledAxis = (i64, u16, String, AxisConfigDto, BTreeMap<u16, ParamValue>);

/// Imports a whole configuration: every axis replaced (all must be disabled); registry, kernel
/// and database agree whatever fails on the way. `raw` is the document as sent, for the audit.
pub async fn import(
    s: &AppState,
    doc: ConfigDocument,
    raw: &serde_json::Value,
    client: &ClientInfo,
) -> AppResult<ConfigDocument> {
    let _guard = s.config_lock.lock().await;
    // Validate everything first.
    let mut errs = Vec::new();
    if doc.version != 1 {
        errs.push(FieldError {
            field: "version".into(),
            message: "must be 1".into(),
        });
    }
    if let Some(b) = &doc.bus {
        let running = s.info.bus.kind;
        if b.kind != running {
            errs.push(FieldError {
                field: "bus.kind".into(),
                message: format!(
                    "this machine runs on the {} bus; motiond runs the {} bus: start it with --bus {}{} first",
                    b.kind.name(),
                    running.name(),
                    b.kind.name(),
                    b.interface
                        .as_deref()
                        .map_or(String::new(), |i| format!(" --interface {i}"))
                ),
            });
        }
    }
    if doc.axes.len() > crate::cycle::MAX_AXES {
        errs.push(FieldError {
            field: "axes".into(),
            message: format!("at most {} axes", crate::cycle::MAX_AXES),
        });
    }
    let cams = match &doc.cam_tables {
        None => None,
        Some(tables) => match super::cams::prepare_import(tables).await {
            Ok(entries) => Some(entries),
            Err(e) => {
                errs.extend(e);
                None
            }
        },
    };
    let doc_axes: Vec<(i64, String)> = doc
        .axes
        .iter()
        .map(|a| (a.id, a.config.name.clone()))
        .collect();
    let groups = match super::groups::prepare_import(s, doc.groups.as_deref(), &doc_axes) {
        Ok(g) => g,
        Err(e) => {
            errs.extend(e);
            None
        }
    };
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
        return Err(AppError::invalid(errs));
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
    // The axes under every group are replaced: no group may be enabled.
    super::groups::refuse_unless_all_disabled(s)?;
    for (_, slot, name, _, _) in &old {
        if s.status(*slot)
            .1
            .is_some_and(|st| st.state != AxisState::Disabled || st.power_status)
        {
            return Err(not_disabled(name));
        }
    }
    s.audit_barrier().await;
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
    if let Some(entries) = &cams {
        super::cams::store_import(&mut tx, entries).await?;
    }
    if let Some(entries) = &groups {
        super::groups::store_import(&mut tx, entries).await?;
    }
    store::audit(
        &mut *tx,
        &audit_entry(client, "config.import", "config", raw.to_string()),
    )
    .await?;
    // Swap the kernel's axes: take the old ones out (refused if one was enabled meanwhile).
    let mut removed = Vec::new();
    let mut refused = None;
    for (id, slot, name, _, _) in &old {
        match s.uninstall_axis(*slot, true).await {
            Ok(()) => removed.push(*id),
            _ => {
                refused = Some(name.clone());
                break;
            }
        }
    }
    let restore = |ids: Vec<i64>| {
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
    let mut failed: Option<AppError> = None;
    for (slot, (a, persistent)) in doc.axes.iter().zip(built).enumerate() {
        let (p, axis, drive) = match s.build_axis(a.id, &a.config, &persistent) {
            Ok(x) => x,
            Err(fe) => {
                failed = Some(AppError::invalid(fe));
                break;
            }
        };
        match s.install_axis(slot as u16, axis, drive, false).await {
            Ok(()) => {}
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
    let old_cams = super::cams::installed(s);
    if failed.is_none() {
        if let Some(entries) = &cams {
            if let Err(e) = super::cams::install_import(s, entries).await {
                failed = Some(e);
            }
        }
    }
    if failed.is_none() {
        if let Err(e) = tx.commit().await {
            if let Some(entries) = &cams {
                super::cams::restore_cams(s, &old_cams, entries).await;
            }
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
        let mut reg = s.registry_write();
        reg.axes = entries.into_iter().map(|e| (e.id, e)).collect();
        if let Some(cams) = cams {
            reg.cams = cams.into_iter().map(|e| (e.id, e)).collect();
        }
    }
    super::groups::install_import(s, groups).await;
    Ok(export(s))
}
