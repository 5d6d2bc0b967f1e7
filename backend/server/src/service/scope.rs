//! Scope recordings: a request checked against the axes and the scope's limits, then handed to
//! the recorder (`crate::scope`, sampled by the cycle thread).

use crate::app::AppState;
use crate::error::FieldError;
use crate::error::{AppError, AppResult};
use crate::model::{ClientInfo, RecordingRequest, ScopeSetup, ScopeSetupResource};
use crate::scope::{
    MAX_SAMPLES, NewRecording, SCOPE_CHANNELS, ScopeChannel, ScopeSignal, ScopeTrigger, TriggerEdge,
};

/// Checks a recording request: every field at fault is named (`channels[2].axis`).
pub fn recording(s: &AppState, body: RecordingRequest) -> AppResult<NewRecording> {
    let mut errors = Vec::new();
    let mut fail = |field: String, message: String| errors.push(FieldError { field, message });
    let n = body.channels.len();
    if n == 0 || n > SCOPE_CHANNELS {
        fail(
            "channels".into(),
            format!("must have 1 to {SCOPE_CHANNELS} channels"),
        );
    }
    let mut channels = Vec::with_capacity(n);
    {
        let reg = s.registry.read().unwrap();
        for (i, c) in body.channels.iter().enumerate() {
            let signal = ScopeSignal::parse(&c.signal);
            if signal.is_none() {
                fail(
                    format!("channels[{i}].signal"),
                    format!(
                        "unknown signal '{}'; one of {}",
                        c.signal,
                        ScopeSignal::ALL.map(ScopeSignal::name).join(", ")
                    ),
                );
            }
            match (&c.axis, &c.group) {
                (Some(key), None) => {
                    let key = key.key();
                    let axis = reg.find(&key);
                    if axis.is_none() {
                        fail(format!("channels[{i}].axis"), format!("no axis '{key}'"));
                    }
                    if signal.is_some_and(ScopeSignal::of_group) {
                        fail(
                            format!("channels[{i}].signal"),
                            "a group's signal: give `group` instead of `axis`".into(),
                        );
                    }
                    if let (Some(a), Some(signal)) = (axis, signal) {
                        channels.push((
                            a.slot,
                            ScopeChannel {
                                axis: Some(a.name.clone()),
                                axis_id: Some(a.id),
                                group: None,
                                group_id: None,
                                signal,
                                unit: signal.unit(&a.config.unit),
                            },
                        ));
                    }
                }
                (None, Some(key)) => {
                    let key = key.key();
                    let group = reg.find_group(&key);
                    if group.is_none() {
                        fail(format!("channels[{i}].group"), format!("no group '{key}'"));
                    }
                    if signal.is_some_and(|s| !s.of_group()) {
                        fail(
                            format!("channels[{i}].signal"),
                            "a group has path_position, path_velocity, path_acceleration and \
                             entry_index"
                                .into(),
                        );
                    }
                    if let (Some(g), Some(signal)) = (group, signal) {
                        // The path's unit: its first member's.
                        let unit = g
                            .members
                            .first()
                            .and_then(|(_, id)| reg.find(&id.to_string()))
                            .map_or_else(String::new, |a| a.config.unit.clone());
                        channels.push((
                            g.slot as motion::AxisSlot,
                            ScopeChannel {
                                axis: None,
                                axis_id: None,
                                group: Some(g.name.clone()),
                                group_id: Some(g.id),
                                signal,
                                unit: signal.unit(&unit),
                            },
                        ));
                    }
                }
                _ => fail(
                    format!("channels[{i}]"),
                    "either `axis` or `group`, not both".into(),
                ),
            }
        }
    }
    let cycle = s.info.cycle_time_s;
    let samples = body.duration_s / cycle;
    let samples = if body.duration_s.is_finite() && body.duration_s > 0.0 {
        samples.round()
    } else {
        0.0
    };
    if !(samples >= 1.0 && samples <= MAX_SAMPLES as f64) {
        fail(
            "duration_s".into(),
            format!(
                "must be > 0 and at most {MAX_SAMPLES} cycles ({} s at the cycle time of {cycle} s)",
                MAX_SAMPLES as f64 * cycle
            ),
        );
    }
    let samples = samples as usize;
    let mut trigger = None;
    let mut pre_trigger_samples = 0;
    if let Some(t) = &body.trigger {
        if t.channel < 0 || t.channel as usize >= n.max(1) {
            fail(
                "trigger.channel".into(),
                format!("must be the index of a channel (0 … {})", n.max(1) - 1),
            );
        }
        if !t.level.is_finite() {
            fail("trigger.level".into(), "must be a finite number".into());
        }
        let edge = match t.edge.as_str() {
            "rising" => Some(TriggerEdge::Rising),
            "falling" => Some(TriggerEdge::Falling),
            "either" => Some(TriggerEdge::Either),
            other => {
                fail(
                    "trigger.edge".into(),
                    format!("unknown edge '{other}'; one of rising, falling, either"),
                );
                None
            }
        };
        if !(t.pre_trigger_s.is_finite()
            && t.pre_trigger_s >= 0.0
            && t.pre_trigger_s <= body.duration_s)
        {
            fail(
                "trigger.pre_trigger_s".into(),
                "must be ≥ 0 and ≤ duration_s".into(),
            );
        }
        if let Some(edge) = edge {
            trigger = Some(ScopeTrigger {
                channel: t.channel.max(0) as usize,
                level: t.level,
                edge,
                pre_trigger_s: t.pre_trigger_s,
            });
            // The trigger sample is always part of the recording.
            pre_trigger_samples =
                ((t.pre_trigger_s / cycle).round() as usize).min(samples.saturating_sub(1));
        }
    }
    if !errors.is_empty() {
        return Err(AppError::invalid(errors));
    }
    Ok(NewRecording {
        channels,
        duration_s: body.duration_s,
        samples,
        trigger,
        pre_trigger_samples,
    })
}

/// The largest `view` of a scope setup, as JSON.
const MAX_VIEW: usize = 64 * 1024;

fn setup_resource(stored: crate::store::scope_setups::StoredSetup) -> Option<ScopeSetupResource> {
    let setup: ScopeSetup = serde_json::from_str(&stored.body).ok()?;
    Some(ScopeSetupResource {
        name: stored.name,
        updated_at: stored.updated_at,
        recording: setup.recording,
        view: setup.view,
    })
}

/// The saved scope setups, by name.
pub async fn setups(s: &AppState) -> AppResult<Vec<ScopeSetupResource>> {
    let rows = crate::store::scope_setups::list(&s.db).await?;
    Ok(rows.into_iter().filter_map(setup_resource).collect())
}

pub async fn setup(s: &AppState, name: &str) -> AppResult<ScopeSetupResource> {
    setups(s)
        .await?
        .into_iter()
        .find(|x| x.name == name)
        .ok_or_else(|| AppError::not_found("scope_setup", name))
}

/// Stores a setup under `name` (checked as a recording request would be, against the axes
/// there are now); `Ok((resource, created))`.
pub async fn put_setup(
    s: &AppState,
    name: &str,
    setup: ScopeSetup,
    client: &ClientInfo,
) -> AppResult<(ScopeSetupResource, bool)> {
    if !crate::model::valid_name(name) {
        return Err(AppError::field(
            "name",
            "must start with a letter or '_' and contain only letters, digits, '_' or '-' (at most 64)",
        ));
    }
    recording(s, setup.recording.clone()).map_err(|e| match e {
        AppError::Invalid(errs) => AppError::Invalid(
            errs.into_iter()
                .map(|f| FieldError {
                    field: format!("recording.{}", f.field),
                    message: f.message,
                })
                .collect(),
        ),
        e => e,
    })?;
    let body = serde_json::to_string(&setup).expect("a setup serialises");
    if serde_json::to_string(&setup.view).map_or(0, |v| v.len()) > MAX_VIEW {
        return Err(AppError::field("view", "at most 64 KiB of JSON"));
    }
    let at = crate::store::now_rfc3339();
    s.audit_barrier().await;
    let mut tx = s.db.begin().await?;
    let replaced = crate::store::scope_setups::put(&mut tx, name, &body, &at).await?;
    crate::store::audit(
        &mut *tx,
        &crate::service::audit_entry(client, "scope_setup.put", name, body),
    )
    .await?;
    tx.commit().await?;
    Ok((
        ScopeSetupResource {
            name: name.to_owned(),
            updated_at: at,
            recording: setup.recording,
            view: setup.view,
        },
        !replaced,
    ))
}

pub async fn delete_setup(s: &AppState, name: &str, client: &ClientInfo) -> AppResult<()> {
    s.audit_barrier().await;
    let mut tx = s.db.begin().await?;
    if !crate::store::scope_setups::delete(&mut tx, name).await? {
        return Err(AppError::not_found("scope_setup", name));
    }
    crate::store::audit(
        &mut *tx,
        &crate::service::audit_entry(client, "scope_setup.delete", name, String::new()),
    )
    .await?;
    tx.commit().await?;
    Ok(())
}
