//! `Idempotency-Key` on motion commands (REST): a retry of a command with the key it was first
//! sent with — an MES that timed out waiting for the answer — gets that command's answer and
//! nothing is done again, for 24 h. The key is kept in memory with the answer, and stored with
//! the command's submission row (committed before the command is acknowledged), so that a retry
//! after a restart is recognised too: then the command cannot be shown any more, and the
//! answer is a 409 naming it. A key belongs to its sender (principal and `X-Client-Id`): the
//! same key from another client is another key (decision 117).

use std::time::{Duration, SystemTime};

use tokio::time::Instant;

use super::commands::{self, Submission};
use crate::app::AppState;
use crate::app::idempotency::{Answer, Keys, Remembered};
use crate::error::{AppError, AppResult};
use crate::model::CommandResource;
use crate::store;

/// How long a key is remembered.
pub const TTL: Duration = Duration::from_secs(24 * 3600);
/// Keys kept in memory (older ones are still found in the database).
pub const MAX_REMEMBERED: usize = 10_000;
/// The longest key.
pub const MAX_KEY: usize = 255;

enum Begin {
    New,
    Replay(Answer),
    InFlight,
    Reused,
}

impl Keys {
    fn begin(&self, key: &str, fingerprint: &str) -> Begin {
        let now = Instant::now();
        let mut g = self.inner.lock().unwrap();
        let (map, order) = &mut *g;
        // Forget what is too old or beyond the memory's size.
        while let Some((at, k)) = order.front() {
            if now.duration_since(*at) < TTL && map.len() <= MAX_REMEMBERED {
                break;
            }
            if map.get(k).is_some_and(|r| r.at == *at) {
                map.remove(k);
            }
            order.pop_front();
        }
        match map.get(key) {
            Some(r) if r.fingerprint != fingerprint => Begin::Reused,
            Some(Remembered { answer: None, .. }) => Begin::InFlight,
            Some(Remembered {
                answer: Some(a), ..
            }) => Begin::Replay(a.clone()),
            None => {
                map.insert(
                    key.to_owned(),
                    Remembered {
                        fingerprint: fingerprint.to_owned(),
                        at: now,
                        answer: None,
                    },
                );
                order.push_back((now, key.to_owned()));
                Begin::New
            }
        }
    }

    fn finish(&self, key: &str, answer: Option<Answer>) {
        let mut g = self.inner.lock().unwrap();
        match answer {
            Some(a) => {
                if let Some(r) = g.0.get_mut(key) {
                    r.answer = Some(a);
                }
            }
            // Nothing was done (invalid, unknown axis, not taken): a retry is a new request.
            None => {
                g.0.remove(key);
            }
        }
    }
}

/// The `Idempotency-Key` header: 1–255 visible ASCII characters; absent is `None`.
pub fn key(headers: &axum::http::HeaderMap) -> AppResult<Option<String>> {
    let Some(v) = headers.get("idempotency-key") else {
        return Ok(None);
    };
    match v.to_str() {
        Ok(k) if !k.is_empty() && k.len() <= MAX_KEY && k.bytes().all(|b| b.is_ascii_graphic()) => {
            Ok(Some(k.to_owned()))
        }
        _ => Err(AppError::field(
            "Idempotency-Key",
            "must be 1 to 255 visible ASCII characters",
        )),
    }
}

/// [`commands::run`] once per `Idempotency-Key`: the answer, and whether it is a replay.
pub async fn run_once<B>(
    s: &AppState,
    sub: Submission<'_, B>,
    wait: Option<Duration>,
) -> AppResult<(CommandResource, bool)> {
    let Some(key) = sub.idempotency_key.clone() else {
        return commands::run(s, sub, wait).await.map(|v| (v, false));
    };
    // The block's path, not its name: an axis's and a group's block may share a name.
    let fingerprint = format!("{}\n{}\n{}", sub.block.path, sub.target, sub.raw);
    let (principal, client_id) = (sub.client.principal.clone(), sub.client.id.clone());
    // Remembered per sender: principal and client id before the key (neither contains a newline).
    let scoped = format!(
        "{}\n{}\n{key}",
        principal.as_deref().unwrap_or(""),
        client_id.as_deref().unwrap_or("")
    );
    let reused = || {
        AppError::conflict(
            "idempotency_key_reused",
            format!("the Idempotency-Key {key:?} was sent with another request"),
        )
    };
    match s.idempotency.begin(&scoped, &fingerprint) {
        Begin::New => {}
        Begin::Replay(Answer::Accepted(first)) => {
            // The command as it stands now (as it was answered, once it left the history).
            return Ok((commands::get(s, first.id).unwrap_or(*first), true));
        }
        Begin::Replay(Answer::Rejected(id, why)) => {
            return Err(match why {
                Some(why) => AppError::RejectedBecause { id, why },
                None => AppError::rejected(id),
            });
        }
        Begin::InFlight => {
            return Err(AppError::conflict(
                "idempotency_key_in_flight",
                format!("a request with the Idempotency-Key {key:?} is being answered"),
            ));
        }
        Begin::Reused => return Err(reused()),
    }
    // Not in memory: sent before a restart (or so long ago that memory let it go)?
    let stored =
        match store::find_idempotency_key(&s.db, &key, principal.as_deref(), client_id.as_deref())
            .await
        {
            Ok(r) => r,
            Err(e) => {
                s.idempotency.finish(&scoped, None);
                return Err(AppError::storage(e));
            }
        };
    let cutoff = humantime::format_rfc3339_millis(
        crate::store::wall_now()
            .checked_sub(TTL)
            .unwrap_or(SystemTime::UNIX_EPOCH),
    )
    .to_string();
    if let Some((id, action, target, detail, outcome, at)) = stored.filter(|r| r.5 >= cutoff) {
        s.idempotency.finish(&scoped, None);
        let axis = s
            .registry
            .read()
            .unwrap()
            .find(sub.target)
            .map(|e| e.name.clone());
        let same = action == format!("command.{}", sub.block.name)
            && target == axis
            && serde_json::from_str::<serde_json::Value>(&detail)
                .ok()
                .as_ref()
                == Some(&sub.raw);
        if !same {
            return Err(reused());
        }
        return Err(AppError::conflict(
            "idempotency_key_replayed",
            format!(
                "command {id} was sent with this Idempotency-Key at {at} (outcome: {}); it can no \
                 longer be shown (motiond restarted since, or many commands came after it) and is \
                 not carried out again",
                outcome.as_deref().unwrap_or("unknown")
            ),
        ));
    }
    let r = commands::run(s, sub, wait).await;
    s.idempotency.finish(
        &scoped,
        match &r {
            Ok(v) => Some(Answer::Accepted(Box::new(v.clone()))),
            Err(AppError::Rejected(id)) => Some(Answer::Rejected(*id, None)),
            Err(AppError::RejectedBecause { id, why }) => {
                Some(Answer::Rejected(*id, Some(why.clone())))
            }
            Err(_) => None,
        },
    );
    r.map(|v| (v, false))
}
