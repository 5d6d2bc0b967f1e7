//! Axis groups (TwinCAT TF5420 CM group): create, replace, delete, load at start-up, export,
//! and their live status. A group is validated field by field (`GroupConfig::validate` for the
//! kernel's part), stored with its audit row in one transaction, built off the cycle thread and
//! put into its kernel slot (id − 1) before the commit, then given its configured axes with
//! MC_AddAxisToGroup; if anything fails on the way, kernel and database stay as they were.

use motion::group::{Group, GroupConfig, GroupRole, GroupStatus, MAX_GROUPS};
use motion::{CommandKind, ErrorId, Target};
use serde::{Deserialize, Serialize};

use super::audit_entry;
use crate::app::{AppState, GroupEntry, Registry};
use crate::error::{AppError, AppResult, FieldError};
use crate::model::{
    ClientInfo, GroupBlockerRead, GroupBody, GroupErrorRead, GroupMemberBody, GroupMemberResource,
    GroupResource, GroupStatusDto, role_name, valid_name,
};
use crate::store;

/// The stored form of a group (`axis_groups.config`): members by axis id, so that an axis keeps
/// its place when renamed.
#[derive(Serialize, Deserialize)]
struct Stored {
    config: GroupConfig,
    members: Vec<(GroupRole, i64)>,
}

/// Every configured group (a copy: the registry is not held across awaits).
fn all(s: &AppState) -> Vec<GroupEntry> {
    s.registry
        .read()
        .unwrap()
        .groups
        .values()
        .cloned()
        .collect()
}

fn entry(s: &AppState, key: &str) -> AppResult<GroupEntry> {
    s.registry
        .read()
        .unwrap()
        .find_group(key)
        .cloned()
        .ok_or_else(|| AppError::not_found("group", key))
}

/// A kernel status as the API shows it: members and positions by role, axes by name.
pub fn status_dto(
    reg: &Registry,
    cycle: u64,
    config: &GroupConfig,
    st: &GroupStatus,
    actual: &[f64; motion::path::MAX_PATH_DIMS],
) -> GroupStatusDto {
    let members = GroupRole::ALL
        .iter()
        .zip(st.members.iter())
        .filter_map(|(r, m)| {
            let slot = (*m)?;
            Some((role_name(*r), reg.by_slot(slot)?.name.clone()))
        })
        .collect();
    GroupStatusDto {
        cycle,
        state: st.state,
        enable_requested: st.enable_requested,
        error_id: st.error_id,
        error_code: (st.error_id != 0).then(|| ErrorId(st.error_id).code()),
        members,
        axes_count: st.axes_count,
        all_axes_standing: st.all_axes_standing,
        override_factor: st.override_factor,
        actual_override: st.actual_override,
        path_velocity: st.path_velocity,
        path_acceleration: st.path_acceleration,
        path_position: st.path_position,
        command: (st.command != 0).then_some(st.command),
        entry_index: st.entry_index,
        invoke_id: st.invoke_id,
        in_blending_segment: st.in_blending_segment,
        remaining_distance: st.remaining_distance,
        remaining_time: st.remaining_time,
        blocked: st.blocked,
        blocker_id: st.blocker_id,
        queued_entries: st.queued_entries,
        position: config
            .roles()
            .map(|r| (role_name(r), st.position[r.dim()]))
            .collect(),
        actual_position: config
            .roles()
            .filter(|r| actual[r.dim()].is_finite())
            .map(|r| (role_name(r), actual[r.dim()]))
            .collect(),
        frame: crate::model::FrameDto {
            translation: st.frame.translation,
            rotation: st.frame.rotation,
        },
        prepared_paths: st.prepared_paths,
        tracking: st.conveyor.map(|slot| crate::model::TrackingStatusDto {
            conveyor: reg
                .by_slot(slot)
                .map(|a| a.name.clone())
                .unwrap_or_default(),
            command: st.tracking_command,
            in_sync: st.in_sync,
            conveyor_error: st.conveyor_error,
            remaining_distance_to_sync: st.remaining_distance_to_sync,
            remaining_time_to_sync: st.remaining_time_to_sync,
        }),
        tracking_velocity: st.tracking_velocity,
    }
}

fn resource(s: &AppState, e: &GroupEntry) -> GroupResource {
    let (cycle, st, actual) = s.group_status_and_actuals(e.slot);
    let reg = s.registry.read().unwrap();
    GroupResource {
        id: e.id,
        name: e.name.clone(),
        convention: e.config.convention,
        additional_axes: e.config.additional_axes,
        axes: e
            .members
            .iter()
            .map(|(role, axis)| GroupMemberResource {
                role: *role,
                axis: reg
                    .axes
                    .get(axis)
                    .map(|a| a.name.clone())
                    .unwrap_or_default(),
                axis_id: *axis,
            })
            .collect(),
        default_dynamics: e.config.default_dynamics,
        maximum_dynamics: e.config.maximum_dynamics,
        override_ramp_time: e.config.override_ramp_time,
        updated_at: e.updated_at.clone(),
        status: st.map(|st| status_dto(&reg, cycle, &e.config, &st, &actual)),
    }
}

pub fn list(s: &AppState) -> Vec<GroupResource> {
    let entries = all(s);
    entries.iter().map(|e| resource(s, e)).collect()
}

pub fn get(s: &AppState, key: &str) -> AppResult<GroupResource> {
    Ok(resource(s, &entry(s, key)?))
}

/// The live status (MC_GroupReadStatus); 503 while the group is not in the cycle.
pub fn status(s: &AppState, key: &str) -> AppResult<GroupStatusDto> {
    let e = entry(s, key)?;
    let (cycle, st, actual) = s.group_status_and_actuals(e.slot);
    let st = st.ok_or_else(|| {
        AppError::unavailable("group_not_in_cycle", "the group is not in the cycle yet")
    })?;
    let reg = s.registry.read().unwrap();
    Ok(status_dto(&reg, cycle, &e.config, &st, &actual))
}

/// MC_GroupReadError.
pub fn read_error(s: &AppState, key: &str) -> AppResult<GroupErrorRead> {
    let e = entry(s, key)?;
    let (cycle, st) = s.group_status(e.slot);
    let error_id = st.map_or(0, |st| st.error_id);
    Ok(GroupErrorRead {
        group: e.name,
        cycle,
        valid: st.is_some(),
        error: error_id != 0,
        error_id,
        error_code: (error_id != 0).then(|| ErrorId(error_id).code()),
    })
}

/// MC_GroupReadBlockerStatus.
pub fn read_blocker(s: &AppState, key: &str) -> AppResult<GroupBlockerRead> {
    let e = entry(s, key)?;
    let (cycle, st) = s.group_status(e.slot);
    Ok(GroupBlockerRead {
        group: e.name,
        cycle,
        valid: st.is_some(),
        blocked: st.is_some_and(|st| st.blocked),
        blocker_id: st.map_or(0, |st| st.blocker_id),
    })
}

/// The members of a body resolved against `find` (an axis by id or name → its id, name):
/// each role of the configuration at most once, each axis once and in no other group
/// (`taken`: the group an axis is configured in, other than this one). Errors name
/// `{prefix}axes[i].…`.
pub fn resolve_members(
    body: &GroupBody,
    prefix: &str,
    find: impl Fn(&str) -> Option<(i64, String)>,
    taken: impl Fn(i64) -> Option<String>,
    errs: &mut Vec<FieldError>,
) -> Vec<(GroupRole, i64)> {
    let config = body.config();
    let mut members: Vec<(GroupRole, i64)> = Vec::new();
    let mut fail = |field: String, message: String| errs.push(FieldError { field, message });
    if body.axes.len() > config.axis_count() {
        fail(
            format!("{prefix}axes"),
            format!("the group takes {} axes at most", config.axis_count()),
        );
    }
    for (i, GroupMemberBody { role, axis }) in body.axes.iter().enumerate() {
        let f = |name: &str| format!("{prefix}axes[{i}].{name}");
        if !config.has_role(*role) {
            fail(
                f("role"),
                format!(
                    "not a role of this group: {} (the convention's axes, then addax1..{})",
                    config.roles().map(role_name).collect::<Vec<_>>().join(", "),
                    config.additional_axes
                ),
            );
            continue;
        }
        if members.iter().any(|(r, _)| r == role) {
            fail(f("role"), "this role is given twice".into());
            continue;
        }
        let Some((id, name)) = find(axis) else {
            fail(f("axis"), format!("no axis '{axis}'"));
            continue;
        };
        if members.iter().any(|(_, a)| *a == id) {
            fail(f("axis"), format!("axis {name} is given twice"));
            continue;
        }
        if let Some(other) = taken(id) {
            fail(
                f("axis"),
                format!("axis {name} belongs to group {other} (an axis is in one group at most)"),
            );
            continue;
        }
        members.push((*role, id));
    }
    members
}

/// A body's own checks (name, id, the kernel's configuration rules, members), with the JSON
/// path prefix where it was sent. The members on success.
fn check(s: &AppState, body: &GroupBody, except: Option<i64>) -> AppResult<Vec<(GroupRole, i64)>> {
    let mut errs = Vec::new();
    if !valid_name(&body.name) {
        errs.push(FieldError {
            field: "name".into(),
            message: "must start with a letter or '_' and contain only letters, digits, '_' or '-' (at most 64)".into(),
        });
    }
    if let Some(id) = body.id {
        if !(1..=MAX_GROUPS as i64).contains(&id) {
            errs.push(FieldError {
                field: "id".into(),
                message: format!("a group id is 1..{MAX_GROUPS}"),
            });
        }
    }
    let numbered = body.config().validate().err();
    if let Some((field, id)) = numbered {
        errs.push(FieldError {
            field: field.into(),
            message: id.text().into(),
        });
    }
    let members = if numbered.is_none() {
        let reg = s.registry.read().unwrap();
        resolve_members(
            body,
            "",
            |k| reg.find(k).map(|a| (a.id, a.name.clone())),
            |a| {
                reg.group_of_axis(a)
                    .filter(|g| Some(g.id) != except)
                    .map(|g| g.name.clone())
            },
            &mut errs,
        )
    } else {
        Vec::new()
    };
    match (errs.is_empty(), numbered) {
        (true, _) => Ok(members),
        (false, Some((_, id))) => Err(AppError::InvalidNumbered { errors: errs, id }),
        (false, None) => Err(AppError::invalid(errs)),
    }
}

fn name_taken(s: &AppState, name: &str, except: Option<i64>) -> AppResult<()> {
    if s.registry
        .read()
        .unwrap()
        .groups
        .values()
        .any(|g| g.name == name && Some(g.id) != except)
    {
        return Err(AppError::conflict(
            "group_name_taken",
            format!("a group named '{name}' exists"),
        ));
    }
    Ok(())
}

/// Builds the group off the cycle thread, puts it into its slot (refused while the group there
/// is enabled or in error: 409 `group_state_invalid`) and adds its configured axes.
async fn put_in_force(
    s: &AppState,
    slot: motion::group::GroupId,
    config: GroupConfig,
    members: &[(GroupRole, i64)],
) -> AppResult<()> {
    let group = Group::new(config, s.info.cycle_time_s);
    s.install_group(slot, group).await?;
    // A replaced group keeps the old one's members whose roles it still has: the configured
    // ones are what it gets.
    s.kernel_command(Target::Group(slot), CommandKind::UngroupAllAxes)
        .await?;
    for (role, axis) in members {
        let axis_slot = s.registry.read().unwrap().axes.get(axis).map(|a| a.slot);
        let Some(axis_slot) = axis_slot else {
            tracing::warn!("group slot {slot}: axis {axis} no longer exists; {role:?} left empty");
            continue;
        };
        s.kernel_command(
            Target::Group(slot),
            CommandKind::AddAxisToGroup {
                axis: axis_slot,
                role: *role,
            },
        )
        .await?;
    }
    Ok(())
}

fn stored_json(config: &GroupConfig, members: &[(GroupRole, i64)]) -> String {
    serde_json::to_string(&Stored {
        config: *config,
        members: members.to_vec(),
    })
    .expect("a group serialises")
}

/// Stores a new group (`POST /groups`). Nothing is changed unless all of it commits.
pub async fn create(
    s: &AppState,
    body: GroupBody,
    client: &ClientInfo,
) -> AppResult<GroupResource> {
    let _guard = s.config_lock.lock().await;
    let members = check(s, &body, None)?;
    name_taken(s, &body.name, None)?;
    let id = {
        let reg = s.registry.read().unwrap();
        match body.id {
            Some(id) if reg.groups.contains_key(&id) => {
                return Err(AppError::conflict(
                    "group_id_taken",
                    format!("group {id} exists: PUT /api/v1/groups/{id} replaces it"),
                ));
            }
            Some(id) => id,
            None => (1..=MAX_GROUPS as i64)
                .find(|id| !reg.groups.contains_key(id))
                .ok_or_else(|| {
                    AppError::conflict(
                        "no_free_group_slot",
                        format!("all {MAX_GROUPS} group slots are used (delete a group first)"),
                    )
                })?,
        }
    };
    let e = GroupEntry {
        id,
        name: body.name.clone(),
        slot: (id - 1) as motion::group::GroupId,
        config: body.config(),
        members,
        updated_at: store::now_rfc3339(),
    };
    store_and_register(s, e, &body, client, None).await
}

/// Stores a group with its audit row and puts it in force before the commit; if either fails,
/// the kernel gets back what it had (`replacing`: the old group; `None`: nothing in the slot).
async fn store_and_register(
    s: &AppState,
    e: GroupEntry,
    body: &GroupBody,
    client: &ClientInfo,
    replacing: Option<&GroupEntry>,
) -> AppResult<GroupResource> {
    let restore = || async {
        match replacing {
            Some(old) => drop(put_in_force(s, old.slot, old.config, &old.members).await),
            None => drop(s.uninstall_group(e.slot, false).await),
        }
    };
    s.audit_barrier().await;
    let mut tx = s.db.begin().await?;
    let stored = stored_json(&e.config, &e.members);
    store::groups::upsert_group(&mut tx, e.id, &e.name, &stored, &e.updated_at).await?;
    let action = if replacing.is_some() {
        "group.replace"
    } else {
        "group.create"
    };
    let detail = serde_json::to_string(body).unwrap_or_default();
    store::audit(&mut *tx, &audit_entry(client, action, &e.name, detail)).await?;
    if let Err(err) = put_in_force(s, e.slot, e.config, &e.members).await {
        // Refused because the group there is enabled: nothing was swapped.
        if err.kernel_error() != Some(ErrorId::GROUP_STATE_INVALID) || replacing.is_none() {
            restore().await;
        }
        return Err(state_conflict(err, &e.name));
    }
    if let Err(err) = tx.commit().await {
        restore().await;
        return Err(err.into());
    }
    s.registry_write().groups.insert(e.id, e.clone());
    Ok(resource(s, &e))
}

/// Replaces a group's configuration (`PUT /groups/{group}`): only while it is disabled.
pub async fn replace(
    s: &AppState,
    key: &str,
    body: GroupBody,
    client: &ClientInfo,
) -> AppResult<GroupResource> {
    let _guard = s.config_lock.lock().await;
    let old = entry(s, key)?;
    if body.id.is_some_and(|id| id != old.id) {
        return Err(AppError::field(
            "id",
            &format!("the group's id is {}; a group keeps its id", old.id),
        ));
    }
    let members = check(s, &body, Some(old.id))?;
    name_taken(s, &body.name, Some(old.id))?;
    refuse_unless_disabled(s, &old)?;
    let e = GroupEntry {
        id: old.id,
        name: body.name.clone(),
        slot: old.slot,
        config: body.config(),
        members,
        updated_at: store::now_rfc3339(),
    };
    store_and_register(s, e, &body, client, Some(&old)).await
}

/// 409 `group_state_invalid` while the group is enabled or in error (as the snapshot shows it;
/// the cycle thread checks again when the group is swapped).
fn refuse_unless_disabled(s: &AppState, e: &GroupEntry) -> AppResult<()> {
    let (_, st) = s.group_status(e.slot);
    if st.is_some_and(|st| st.enable_requested || st.state == motion::group::GroupState::ErrorStop)
    {
        return Err(state_conflict(
            AppError::rejected(ErrorId::GROUP_STATE_INVALID),
            &e.name,
        ));
    }
    Ok(())
}

fn state_conflict(e: AppError, name: &str) -> AppError {
    match e.kernel_error() {
        Some(ErrorId::GROUP_STATE_INVALID) => AppError::RejectedBecause {
            id: ErrorId::GROUP_STATE_INVALID,
            why: format!(
                "group {name} is enabled or in error: disable it first (POST /api/v1/groups/{name}/disable)"
            ),
        },
        _ => e,
    }
}

/// Deletes a group (`DELETE /groups/{group}`): only while it is disabled.
pub async fn delete(s: &AppState, key: &str, client: &ClientInfo) -> AppResult<()> {
    let _guard = s.config_lock.lock().await;
    let e = entry(s, key)?;
    refuse_unless_disabled(s, &e)?;
    s.audit_barrier().await;
    let mut tx = s.db.begin().await?;
    store::groups::delete_group(&mut tx, e.id).await?;
    store::audit(
        &mut *tx,
        &audit_entry(client, "group.delete", &e.name, String::new()),
    )
    .await?;
    s.uninstall_group(e.slot, true)
        .await
        .map_err(|err| state_conflict(err, &e.name))?;
    if let Err(err) = tx.commit().await {
        let _ = put_in_force(s, e.slot, e.config, &e.members).await;
        return Err(err.into());
    }
    s.registry_write().groups.remove(&e.id);
    Ok(())
}

/// Loads the stored groups at start-up (after the axes): each one disabled with its configured
/// axes. A group that no longer fits is reported and skipped rather than stopping motiond.
pub async fn load(s: &AppState) -> Result<usize, String> {
    let stored = store::groups::load_groups(&s.db)
        .await
        .map_err(|e| format!("cannot read axis groups: {e}"))?;
    let mut n = 0;
    for g in stored {
        let parsed: Stored = match serde_json::from_str(&g.config) {
            Ok(p) => p,
            Err(e) => {
                tracing::error!("group {} '{}' is stored unreadable: {e}", g.id, g.name);
                continue;
            }
        };
        if let Err((field, id)) = parsed.config.validate() {
            tracing::error!("group {} '{}': {field}: {}", g.id, g.name, id.text());
            continue;
        }
        let slot = (g.id - 1) as motion::group::GroupId;
        put_in_force(s, slot, parsed.config, &parsed.members)
            .await
            .map_err(|e| format!("group {} '{}': {e}", g.id, g.name))?;
        s.registry_write().groups.insert(
            g.id,
            GroupEntry {
                id: g.id,
                name: g.name,
                slot,
                config: parsed.config,
                members: parsed.members,
                updated_at: g.updated_at,
            },
        );
        n += 1;
    }
    Ok(n)
}

/// The groups for the configuration document, with their ids (members by axis name).
pub fn export(s: &AppState) -> Vec<GroupBody> {
    let reg = s.registry.read().unwrap();
    reg.groups
        .values()
        .map(|e| GroupBody {
            id: Some(e.id),
            name: e.name.clone(),
            convention: e.config.convention,
            additional_axes: e.config.additional_axes,
            axes: e
                .members
                .iter()
                .map(|(role, a)| GroupMemberBody {
                    role: *role,
                    axis: reg
                        .axes
                        .get(a)
                        .map_or_else(|| a.to_string(), |x| x.name.clone()),
                })
                .collect(),
            default_dynamics: e.config.default_dynamics,
            maximum_dynamics: e.config.maximum_dynamics,
            override_ramp_time: e.config.override_ramp_time,
        })
        .collect()
}

/// Creates the demo machine's group `xy` (axes `x` and `y`), disabled.
pub async fn create_demo(s: &AppState) -> AppResult<()> {
    let body = crate::model::demo::group();
    let client = ClientInfo {
        id: Some("demo".into()),
        ..Default::default()
    };
    create(s, body, &client).await.map(drop)
}

/// The groups of an import, validated against the imported axes (`axes`: id and name) before
/// anything is changed; errors name `groups[i].…`. `None` (no `groups` in the document): the
/// stored groups stay, and their members must be among the imported axes.
pub fn prepare_import(
    s: &AppState,
    groups: Option<&[GroupBody]>,
    axes: &[(i64, String)],
) -> Result<Option<Vec<GroupEntry>>, Vec<FieldError>> {
    let mut errs = Vec::new();
    let Some(groups) = groups else {
        let reg = s.registry.read().unwrap();
        for g in reg.groups.values() {
            for (role, a) in &g.members {
                if !axes.iter().any(|(id, _)| id == a) {
                    errs.push(FieldError {
                        field: "groups".into(),
                        message: format!(
                            "the stored group {} has axis {a} as {}, which the document does not have: \
                             give the groups too",
                            g.name,
                            role_name(*role)
                        ),
                    });
                }
            }
        }
        return if errs.is_empty() { Ok(None) } else { Err(errs) };
    };
    if groups.len() > MAX_GROUPS {
        errs.push(FieldError {
            field: "groups".into(),
            message: format!("at most {MAX_GROUPS} groups"),
        });
    }
    let now = store::now_rfc3339();
    let mut entries: Vec<GroupEntry> = Vec::new();
    for (i, g) in groups.iter().enumerate() {
        let prefix = format!("groups[{i}].");
        let mut fail = |f: &str, m: String| {
            errs.push(FieldError {
                field: format!("{prefix}{f}"),
                message: m,
            })
        };
        if !valid_name(&g.name) {
            fail("name", "must start with a letter or '_' and contain only letters, digits, '_' or '-' (at most 64)".into());
        }
        if groups[..i].iter().any(|o| o.name == g.name) {
            fail("name", "duplicate name".into());
        }
        match g.id {
            None => fail("id", "required in a configuration document".into()),
            Some(id) if !(1..=MAX_GROUPS as i64).contains(&id) => {
                fail("id", format!("a group id is 1..{MAX_GROUPS}"))
            }
            Some(id) if groups[..i].iter().any(|o| o.id == Some(id)) => {
                fail("id", "duplicate id".into())
            }
            _ => {}
        }
        if let Err((field, id)) = g.config().validate() {
            fail(field, format!("{} ({})", id.text(), id.code()));
            continue;
        }
        let members = resolve_members(
            g,
            &prefix,
            |k| {
                axes.iter()
                    .find(|(id, name)| id.to_string() == k || name == k)
                    .cloned()
            },
            |a| {
                entries
                    .iter()
                    .find(|e| e.members.iter().any(|(_, m)| *m == a))
                    .map(|e| e.name.clone())
            },
            &mut errs,
        );
        let id = g.id.unwrap_or(1).clamp(1, MAX_GROUPS as i64);
        entries.push(GroupEntry {
            id,
            name: g.name.clone(),
            slot: (id - 1) as motion::group::GroupId,
            config: g.config(),
            members,
            updated_at: now.clone(),
        });
    }
    if errs.is_empty() {
        Ok(Some(entries))
    } else {
        Err(errs)
    }
}

/// 409 `group_state_invalid` while a group is enabled or in error (an import replaces the
/// axes under every group).
pub fn refuse_unless_all_disabled(s: &AppState) -> AppResult<()> {
    let groups = all(s);
    groups.iter().try_for_each(|g| refuse_unless_disabled(s, g))
}

/// Replaces the stored groups within an import's transaction.
pub async fn store_import(
    tx: &mut sqlx::SqliteConnection,
    entries: &[GroupEntry],
) -> Result<(), sqlx::Error> {
    store::groups::delete_all_groups(tx).await?;
    for e in entries {
        store::groups::upsert_group(
            tx,
            e.id,
            &e.name,
            &stored_json(&e.config, &e.members),
            &e.updated_at,
        )
        .await?;
    }
    Ok(())
}

/// After an import has committed: the groups (the new ones, or the stored ones kept) put in
/// force again with the imported axes, the others taken out of the kernel. A group the cycle
/// thread does not take is reported; it is in force after the next start.
pub async fn install_import(s: &AppState, new: Option<Vec<GroupEntry>>) {
    let old = all(s);
    let entries = new.unwrap_or_else(|| old.clone());
    for g in &old {
        if !entries.iter().any(|e| e.slot == g.slot) {
            if let Err(e) = s.uninstall_group(g.slot, false).await {
                tracing::error!("group {} not taken out after the import: {e}", g.name);
            }
        }
    }
    for g in &entries {
        if let Err(e) = put_in_force(s, g.slot, g.config, &g.members).await {
            tracing::error!(
                "group {} imported but not in force until the next start: {e}",
                g.name
            );
        }
    }
    s.registry_write().groups = entries.into_iter().map(|e| (e.id, e)).collect();
}

/// Before axis `axis_id` (in kernel slot `slot`) is deleted: it leaves every group it is in —
/// the kernel's membership (MC_RemoveAxisFromGroup, so that no later axis in that slot finds
/// itself in the group) and the stored configuration (in `tx`, the axis's deletion). Refused
/// with 409 `group_state_invalid` while such a group is enabled or in error. The changed
/// groups, to be registered once `tx` has committed.
pub async fn axis_leaves(
    s: &AppState,
    tx: &mut sqlx::SqliteConnection,
    axis_id: i64,
    slot: motion::AxisSlot,
) -> AppResult<Vec<GroupEntry>> {
    let groups = all(s);
    let mut changed = Vec::new();
    for g in groups {
        let live: Vec<GroupRole> = s
            .group_status(g.slot)
            .1
            .map(|st| {
                GroupRole::ALL
                    .iter()
                    .zip(st.members.iter())
                    .filter(|(_, m)| **m == Some(slot))
                    .map(|(r, _)| *r)
                    .collect()
            })
            .unwrap_or_default();
        let configured = g.members.iter().any(|(_, a)| *a == axis_id);
        if live.is_empty() && !configured {
            continue;
        }
        refuse_unless_disabled(s, &g)?;
        for role in live {
            s.kernel_command(
                Target::Group(g.slot),
                CommandKind::RemoveAxisFromGroup { role },
            )
            .await
            .map_err(|e| state_conflict(e, &g.name))?;
        }
        if configured {
            let mut e = g.clone();
            e.members.retain(|(_, a)| *a != axis_id);
            e.updated_at = store::now_rfc3339();
            store::groups::upsert_group(
                tx,
                e.id,
                &e.name,
                &stored_json(&e.config, &e.members),
                &e.updated_at,
            )
            .await?;
            changed.push(e);
        }
    }
    Ok(changed)
}

/// Registers groups changed by [`axis_leaves`] after their transaction committed.
pub fn register(s: &AppState, changed: Vec<GroupEntry>) {
    let mut reg = s.registry_write();
    for e in changed {
        reg.groups.insert(e.id, e);
    }
}

/// The samples a path analysis keeps by default, and at most.
pub const ANALYSIS_SAMPLES: usize = 2000;
pub const MAX_ANALYSIS_SAMPLES: usize = 20_000;
/// The run a path analysis plans by default, and at most (s).
pub const ANALYSIS_SECONDS: f64 = 60.0;
pub const MAX_ANALYSIS_SECONDS: f64 = 600.0;

/// The configuration of a group named in a body (422 at `field` when there is none).
pub fn config_of(s: &AppState, key: &str, field: &str) -> AppResult<GroupConfig> {
    s.registry
        .read()
        .unwrap()
        .find_group(key)
        .map(|e| e.config)
        .ok_or_else(|| AppError::field(field, &format!("no group '{key}'")))
}

/// A path table's run planned for a group without running it (`POST /path-analysis`): the
/// group's configuration and frame, its configured members' parameters as mirrored, from
/// `start` (per role; a role left out from its axis's set point now), in virtual time on a
/// private kernel off the async runtime. Nothing is stored, nothing reaches the cycle thread.
/// A table the group would refuse is a 422 naming the entry and field, with the rule's code.
pub async fn analyse_path(
    s: &AppState,
    key: &str,
    table: motion::group::PathTable,
    start: Option<std::collections::BTreeMap<String, f64>>,
    max_samples: usize,
    max_seconds: f64,
) -> AppResult<crate::model::PathAnalysisResource> {
    let e = s
        .registry
        .read()
        .unwrap()
        .find_group(key)
        .cloned()
        .ok_or_else(|| AppError::field("group", &format!("no group '{key}'")))?;
    let roles: Vec<GroupRole> = e.config.roles().collect();
    let mut errors = Vec::new();
    for (name, v) in start.iter().flatten() {
        let field = format!("start.{name}");
        if !roles.iter().any(|r| role_name(*r) == *name) {
            let names: Vec<String> = roles.iter().map(|r| role_name(*r)).collect();
            errors.push(FieldError {
                field,
                message: format!("not a role of this group: {}", names.join(", ")),
            });
        } else if !(v.is_finite() && v.abs() <= crate::model::MAX_MAGNITUDE) {
            errors.push(FieldError {
                field,
                message: "must be a number from -1e12 to 1e12".into(),
            });
        }
    }
    if !errors.is_empty() {
        return Err(AppError::Invalid(errors));
    }
    let (_, st) = s.group_status(e.slot);
    let frame = st.map(|st| st.frame).unwrap_or_default();
    let mut axes = Vec::with_capacity(roles.len());
    let mut names = Vec::with_capacity(roles.len());
    let mut at = [0.0; motion::path::MAX_PATH_DIMS];
    {
        let reg = s.registry.read().unwrap();
        for r in &roles {
            let member = e.members.iter().find(|(role, _)| role == r);
            let Some(a) = member.and_then(|(_, id)| reg.axes.get(id)) else {
                return Err(AppError::field(
                    "group",
                    &format!(
                        "group {} has no axis for role {}: a path needs every role's axis",
                        e.name,
                        role_name(*r)
                    ),
                ));
            };
            axes.push((*r, a.params.clone()));
            names.push(a.name.clone());
            // Where the group's set point is now (the axis's when the group is not in the cycle).
            at[r.dim()] = match st {
                Some(st) => st.position[r.dim()],
                None => s.status(a.slot).1.map_or(0.0, |a| a.set_position),
            };
        }
    }
    for (name, v) in start.iter().flatten() {
        if let Some(r) = roles.iter().find(|r| role_name(**r) == *name) {
            at[r.dim()] = *v;
        }
    }
    let config = e.config;
    let cycle_time = s.info.cycle_time_s;
    let analysis = tokio::task::spawn_blocking(move || {
        motion::group::analyse_path(
            &config,
            &axes,
            at,
            frame,
            &table,
            cycle_time,
            max_seconds,
            max_samples,
        )
    })
    .await
    .map_err(|e| AppError::unavailable("internal", format!("the analysis failed: {e}")))?;
    let a = analysis.map_err(|(i, field, id)| {
        let field = match field {
            "group" | "frame" | "entries" => field.to_string(),
            f => format!("entries[{i}].{f}"),
        };
        AppError::InvalidCoded {
            errors: vec![FieldError {
                message: format!("{} (0x{:04X}): {}", id.code(), id.0, id.text()),
                field,
            }],
            id,
        }
    })?;
    let column = |f: &dyn Fn(&motion::group::PlannedSample) -> f64| -> Vec<f64> {
        a.samples.iter().map(f).collect()
    };
    Ok(crate::model::PathAnalysisResource {
        group: e.name.clone(),
        cycle_time,
        start: roles.iter().map(|r| (role_name(*r), at[r.dim()])).collect(),
        duration: a.duration,
        length: a.length,
        truncated: a.truncated,
        t: column(&|p| p.t),
        path_position: column(&|p| p.path_position),
        path_velocity: column(&|p| p.path_velocity),
        path_acceleration: column(&|p| p.path_acceleration),
        entry: a.samples.iter().map(|p| p.entry).collect(),
        in_blend: a.samples.iter().map(|p| p.in_blend).collect(),
        axes: roles
            .iter()
            .zip(names)
            .map(|(r, axis)| {
                let d = r.dim();
                crate::model::PlannedAxisDto {
                    role: *r,
                    axis,
                    position: column(&|p| p.position[d]),
                    velocity: column(&|p| p.velocity[d]),
                    acceleration: column(&|p| p.acceleration[d]),
                    max_velocity: a.max_velocity[d],
                    max_acceleration: a.max_acceleration[d],
                }
            })
            .collect(),
    })
}
