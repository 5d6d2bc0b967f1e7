//! Control of the machine (DESIGN §6): one holder commands motion at a time.
//!
//! A client takes control with a lease that it renews (`POST /api/v1/control`), as a jog's
//! dead-man is renewed; a lease not renewed in time ends by itself, so a client that vanishes
//! does not keep the machine. While one client holds control, the motion commands of every
//! other client are refused with 409 `control_held` naming the holder — except MC_Stop, MC_Halt
//! and MC_Power with `enable: false`, which are accepted from anyone allowed to move axes (a
//! stop is never refused). Nobody holding control: everyone may command, as without leases. An
//! admin (anyone, while authentication is off) may take control over from its holder.
//! `--control-lease false` switches it off (decision 87).
//!
//! A client is known by its principal (`user:NAME`, `token:NAME`) and its `X-Client-Id`
//! ([`ClientInfo::control_key`]): two browser tabs of one user send different client ids.

use std::time::Duration;

use motion::CommandKind;
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use crate::app::control::{Control, Holder};
use crate::auth::Role;
use crate::error::{AppError, AppResult};
use crate::model::ClientInfo;

/// Shortest and longest lease a client may ask for.
pub const MIN_LEASE_MS: u64 = 500;
pub const MAX_LEASE_MS: u64 = 60_000;
pub const DEFAULT_LEASE_MS: u64 = 5_000;

/// `POST /api/v1/control`.
#[derive(Debug, Default, Deserialize, ToSchema)]
#[schema(example = json!({"lease_ms": 5000}))]
#[serde(deny_unknown_fields)]
pub struct TakeControl {
    /// How long the control lasts unless renewed (by this request again), in ms (500–60000,
    /// default 5000). Renew well before it runs out, e.g. every third of it.
    #[schema(minimum = 500, maximum = 60000, example = 5000)]
    pub lease_ms: Option<u64>,
    /// Take control from another holder (admin only; anyone while authentication is off).
    #[serde(default)]
    pub take_over: bool,
}

/// Who holds the control.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"client_id": "line-3-mes", "principal": "token:line-3-mes", "client_addr": "10.0.3.17:50312",
    "since": "2026-11-25T08:00:00.000Z", "lease_ms": 5000, "expires_in_ms": 3170}))]
pub struct ControlHolder {
    pub client_id: Option<String>,
    pub principal: Option<String>,
    pub client_addr: String,
    /// When it took control.
    pub since: String,
    pub lease_ms: u64,
    /// Left of the lease when this was answered.
    pub expires_in_ms: u64,
}

/// The control of the machine as a client sees it.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({"lease_enabled": true, "holder": {"client_id": "line-3-mes", "principal": null,
    "client_addr": "10.0.3.17:50312", "since": "2026-11-25T08:00:00.000Z", "lease_ms": 5000, "expires_in_ms": 3170}, "yours": false}))]
pub struct ControlState {
    /// False when motiond runs with `--control-lease false`: nobody can hold control.
    pub lease_enabled: bool,
    /// Null: nobody holds it, every operator may command motion.
    pub holder: Option<ControlHolder>,
    /// The asking client holds it.
    pub yours: bool,
}

fn holder_view(h: &Holder, now: Duration) -> ControlHolder {
    ControlHolder {
        client_id: h.client_id.clone(),
        principal: h.principal.clone(),
        client_addr: h.addr.clone(),
        since: humantime::format_rfc3339_millis(h.since).to_string(),
        lease_ms: h.lease.as_millis() as u64,
        expires_in_ms: h.until.saturating_sub(now).as_millis() as u64,
    }
}

fn describe(h: &Holder) -> String {
    let who = match (&h.principal, &h.client_id) {
        (Some(p), Some(c)) => format!("{p} (client {c})"),
        (Some(p), None) => p.clone(),
        (None, Some(c)) => format!("client {c}"),
        (None, None) => "an unnamed client".into(),
    };
    format!("{who} at {}", h.addr)
}

/// 409: someone else holds control.
fn held(h: &Holder, now: Duration) -> AppError {
    AppError::conflict(
        "control_held",
        format!(
            "control of the machine is held by {}: motion commands from other clients are refused \
             (stop, halt and disabling are always accepted); its lease ends in {} ms unless renewed",
            describe(h),
            h.until.saturating_sub(now).as_millis()
        ),
    )
}

/// A command that only ends motion (MC_Stop, MC_Halt, MC_Power off, switching the external
/// generator off, MC_HaltPhasing): never refused for who holds control, nor because the store
/// is down (safety first: a stop is never refused).
pub fn stops_motion(kind: &CommandKind) -> bool {
    matches!(
        kind,
        CommandKind::Stop { .. }
            | CommandKind::Halt { .. }
            | CommandKind::GroupStop { .. }
            | CommandKind::GroupHalt { .. }
            | CommandKind::GroupDisable
            | CommandKind::UngroupAllAxes
            | CommandKind::Power { enable: false, .. }
            // Switching the external generator off stops what it moves.
            | CommandKind::ExtSetPointGenDisable
            // Halting a phase motion is a stop.
            | CommandKind::Phasing {
                motion: motion::PhasingMotion {
                    kind: motion::PhasingKind::Halt,
                    ..
                },
                ..
            }
    )
}

impl Control {
    /// The live holder (an expired lease is dropped here).
    fn live(&self) -> std::sync::MutexGuard<'_, Option<Holder>> {
        let mut h = self.holder.lock().unwrap();
        if h.as_ref().is_some_and(|h| h.until <= self.clock.now()) {
            *h = None;
        }
        h
    }

    pub fn state(&self, client: &ClientInfo) -> ControlState {
        let h = self.live();
        let key = client.control_key();
        ControlState {
            lease_enabled: self.enabled,
            holder: h.as_ref().map(|h| holder_view(h, self.clock.now())),
            yours: h.as_ref().is_some_and(|h| Some(&h.key) == key.as_ref()),
        }
    }

    /// Takes or renews control. `Ok((state, changed))`: `changed` when the holder is new (for
    /// the audit log; a renewal is not audited).
    pub fn take(&self, client: &ClientInfo, req: &TakeControl) -> AppResult<(ControlState, bool)> {
        if !self.enabled {
            return Err(AppError::conflict(
                "control_lease_disabled",
                "motiond runs with --control-lease false: there is no control to take",
            ));
        }
        let lease_ms = req.lease_ms.unwrap_or(DEFAULT_LEASE_MS);
        if !(MIN_LEASE_MS..=MAX_LEASE_MS).contains(&lease_ms) {
            return Err(AppError::field(
                "lease_ms",
                &format!("must be {MIN_LEASE_MS} to {MAX_LEASE_MS}"),
            ));
        }
        let Some(key) = client.control_key() else {
            return Err(AppError::field(
                "X-Client-Id",
                "name the client with an X-Client-Id header to take control (authentication is off, so nothing else names it)",
            ));
        };
        let mut h = self.live();
        let changed = match h.as_ref() {
            Some(cur) if cur.key == key => false,
            Some(cur) => {
                let may_take_over = client
                    .identity
                    .as_ref()
                    .is_none_or(|p| p.role >= Role::Admin);
                if !req.take_over {
                    return Err(held(cur, self.clock.now()));
                }
                if !may_take_over {
                    return Err(AppError::new(
                        axum::http::StatusCode::FORBIDDEN,
                        "role_insufficient",
                        "Forbidden",
                        format!("only an admin may take control over from {}", describe(cur)),
                    ));
                }
                true
            }
            None => true,
        };
        let lease = Duration::from_millis(lease_ms);
        let since = match h.as_ref() {
            Some(cur) if !changed => cur.since,
            _ => crate::store::wall_now(),
        };
        *h = Some(Holder {
            key,
            client_id: client.id.clone(),
            principal: client.principal.clone(),
            addr: client.addr.clone(),
            since,
            until: self.clock.now() + lease,
            lease,
        });
        let state = ControlState {
            lease_enabled: true,
            holder: h.as_ref().map(|h| holder_view(h, self.clock.now())),
            yours: true,
        };
        Ok((state, changed))
    }

    /// Gives control back. Only its holder may (an admin too, or anyone while authentication is
    /// off). `Ok(true)` when something was released.
    pub fn release(&self, client: &ClientInfo) -> AppResult<bool> {
        let mut h = self.live();
        let Some(cur) = h.as_ref() else {
            return Ok(false);
        };
        let mine = client.control_key().as_ref() == Some(&cur.key);
        let admin = client
            .identity
            .as_ref()
            .is_none_or(|p| p.role >= Role::Admin);
        if !mine && !admin {
            return Err(held(cur, self.clock.now()));
        }
        *h = None;
        Ok(true)
    }

    /// Whether `client` may send `kind` now: a motion command of a client that does not hold
    /// control while another does is refused; stop, halt and disabling never are. (A block
    /// whose catalogue entry is `lease_free` — it ends motion or moves nothing — is not asked.)
    pub fn admit(&self, client: &ClientInfo, kind: &CommandKind) -> AppResult<()> {
        if !self.enabled {
            return Ok(());
        }
        if stops_motion(kind) {
            return Ok(());
        }
        self.admit_motion(client)
    }

    /// Whether `client` may command motion now (a path for a group): refused while another
    /// client holds control.
    pub fn admit_motion(&self, client: &ClientInfo) -> AppResult<()> {
        if !self.enabled {
            return Ok(());
        }
        let h = self.live();
        match h.as_ref() {
            Some(cur) if client.control_key().as_ref() != Some(&cur.key) => {
                Err(held(cur, self.clock.now()))
            }
            _ => Ok(()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn client(id: &str) -> ClientInfo {
        ClientInfo {
            addr: "127.0.0.1:1".into(),
            id: Some(id.into()),
            via: "rest",
            ..Default::default()
        }
    }

    #[test]
    fn a_holder_refuses_others_motion_but_never_their_stop() {
        let c = Control::new(
            true,
            crate::clock::Clock::new(
                crate::clock::Mode::Real,
                std::sync::Arc::new(crate::cycle::Shared::new(1_000_000)),
            ),
        );
        let (a, b) = (client("a"), client("b"));
        let go = CommandKind::Reset;
        c.admit(&b, &go).unwrap();
        c.take(&a, &TakeControl::default()).unwrap();
        c.admit(&a, &go).unwrap();
        let e = c.admit(&b, &go).unwrap_err();
        assert_eq!(e.problem().code, "control_held");
        assert!(e.problem().detail.contains("client a"));
        let stop = CommandKind::Stop {
            deceleration: 0.0,
            jerk: 0.0,
            options: Default::default(),
        };
        c.admit(&b, &stop).unwrap();
        // b cannot take it without taking over; without authentication it may take over.
        assert_eq!(
            c.take(&b, &TakeControl::default())
                .unwrap_err()
                .problem()
                .code,
            "control_held"
        );
        let (s, changed) = c
            .take(
                &b,
                &TakeControl {
                    lease_ms: None,
                    take_over: true,
                },
            )
            .unwrap();
        assert!(changed && s.yours);
        assert_eq!(c.admit(&a, &go).unwrap_err().problem().code, "control_held");
    }

    #[test]
    fn a_lease_not_renewed_ends() {
        let c = Control::new(
            true,
            crate::clock::Clock::new(
                crate::clock::Mode::Real,
                std::sync::Arc::new(crate::cycle::Shared::new(1_000_000)),
            ),
        );
        c.take(
            &client("a"),
            &TakeControl {
                lease_ms: Some(500),
                take_over: false,
            },
        )
        .unwrap();
        // Forced into the past instead of sleeping.
        c.holder.lock().unwrap().as_mut().unwrap().until = c.clock.now();
        assert!(c.state(&client("b")).holder.is_none());
        c.admit(&client("b"), &CommandKind::Reset).unwrap();
    }
}
