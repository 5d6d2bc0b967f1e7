//! The audit log: who did what, one row per change or command (written in the same
//! transaction as a configuration change, or in batches for commands).

use sqlx::{Row, SqlitePool};

/// One audit log row.
#[derive(Clone, Debug, Default)]
pub struct AuditEntry {
    pub at: String,
    pub client_addr: Option<String>,
    pub client_id: Option<String>,
    pub action: String,
    pub target: Option<String>,
    pub command_id: Option<u64>,
    pub detail: String,
    pub outcome: Option<String>,
    /// The `Idempotency-Key` a motion command was sent with.
    pub idempotency_key: Option<String>,
    /// `user:NAME` or `token:NAME` (authentication enabled).
    pub principal: Option<String>,
}

pub async fn audit<'e, E: sqlx::SqliteExecutor<'e>>(
    e: E,
    a: &AuditEntry,
) -> Result<(), sqlx::Error> {
    sqlx::query("INSERT INTO audit_log (at, client_addr, client_id, action, target, command_id, detail, outcome, idempotency_key, principal) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?)")
        .bind(&a.at)
        .bind(&a.client_addr)
        .bind(&a.client_id)
        .bind(&a.action)
        .bind(&a.target)
        .bind(a.command_id.map(|c| c as i64))
        .bind(&a.detail)
        .bind(&a.outcome)
        .bind(&a.idempotency_key)
        .bind(&a.principal)
        .execute(e)
        .await
        .map(|_| ())
}

/// The outcome of a command whose submission row was stored as `submitted` (the verdict came
/// after the row was written).
pub async fn audit_outcome<'e, E: sqlx::SqliteExecutor<'e>>(
    e: E,
    command_id: u64,
    outcome: &str,
) -> Result<(), sqlx::Error> {
    sqlx::query("UPDATE audit_log SET outcome = ? WHERE command_id = ? AND outcome = 'submitted'")
        .bind(outcome)
        .bind(command_id as i64)
        .execute(e)
        .await
        .map(|_| ())
}

/// What the batching audit writer does: store a row, or set a command's outcome.
pub enum AuditOp {
    Row(AuditEntry),
    Outcome(u64, String),
    /// Answered once everything queued before it is written (or given up).
    Flush(tokio::sync::oneshot::Sender<()>),
}

/// The newest submission of a motion command sent with `key`: (command id, action, target,
/// body, outcome, when).
pub async fn find_idempotency_key(
    pool: &SqlitePool,
    key: &str,
    principal: Option<&str>,
    client_id: Option<&str>,
) -> Result<Option<(u64, String, Option<String>, String, Option<String>, String)>, sqlx::Error> {
    // A key is the sender's: the same key from another principal or client is another key.
    let row = sqlx::query(
        "SELECT command_id, action, target, detail, outcome, at FROM audit_log \
         WHERE idempotency_key = ? AND principal IS ? AND client_id IS ? ORDER BY id DESC LIMIT 1",
    )
    .bind(key)
    .bind(principal)
    .bind(client_id)
    .fetch_optional(pool)
    .await?;
    Ok(row.map(|r| {
        (
            r.get::<Option<i64>, _>(0).unwrap_or_default() as u64,
            r.get(1),
            r.get(2),
            r.get(3),
            r.get(4),
            r.get(5),
        )
    }))
}

/// One audit log row as stored.
pub struct AuditRow {
    pub id: i64,
    pub entry: AuditEntry,
}

/// The newest rows with an id above `since_id`, newest first.
pub async fn read_audit(
    pool: &SqlitePool,
    limit: u32,
    since_id: i64,
    before_id: i64,
) -> Result<Vec<AuditRow>, sqlx::Error> {
    let rows = sqlx::query(
        "SELECT id, at, client_addr, client_id, action, target, command_id, detail, outcome, principal \
         FROM audit_log WHERE id > ? AND id < ? ORDER BY id DESC LIMIT ?",
    )
    .bind(since_id)
    .bind(before_id)
    .bind(limit as i64)
    .fetch_all(pool)
    .await?;
    Ok(rows
        .into_iter()
        .map(|r| AuditRow {
            id: r.get(0),
            entry: AuditEntry {
                at: r.get(1),
                client_addr: r.get(2),
                client_id: r.get(3),
                action: r.get(4),
                target: r.get(5),
                command_id: r.get::<Option<i64>, _>(6).map(|c| c as u64),
                detail: r.get(7),
                outcome: r.get(8),
                idempotency_key: None,
                principal: r.get(9),
            },
        })
        .collect())
}
