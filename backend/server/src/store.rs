//! SQLite store (DESIGN §5): WAL, synchronous=FULL, one writer connection.
//!
//! The database is opened with `locking_mode=EXCLUSIVE`, so a second motiond on the same
//! file fails at start-up with "database is locked" instead of two processes writing.

use std::borrow::Cow;
use std::str::FromStr;
use std::time::Duration;

use sqlx::migrate::{Migration, MigrationType, Migrator};
use sqlx::sqlite::{
    SqliteConnectOptions, SqliteJournalMode, SqliteLockingMode, SqlitePoolOptions,
    SqliteSynchronous,
};
use sqlx::{Row, SqlitePool};

pub fn migrator() -> Migrator {
    Migrator {
        migrations: Cow::Owned(vec![Migration::new(
            1,
            "init".into(),
            MigrationType::Simple,
            include_str!("../../../migrations/0001_init.sql").into(),
            false,
        )]),
        ..Migrator::DEFAULT
    }
}

/// Opens (creating if needed), checks and migrates the database.
pub async fn open(path: &str) -> Result<SqlitePool, String> {
    let memory = path == ":memory:";
    let opts = if memory {
        SqliteConnectOptions::from_str("sqlite::memory:").map_err(|e| e.to_string())?
    } else {
        SqliteConnectOptions::new()
            .filename(path)
            .create_if_missing(true)
    };
    let opts = opts
        .journal_mode(if memory {
            SqliteJournalMode::Memory
        } else {
            SqliteJournalMode::Wal
        })
        .synchronous(SqliteSynchronous::Full)
        .locking_mode(SqliteLockingMode::Exclusive)
        .busy_timeout(Duration::from_secs(2))
        .foreign_keys(true);
    // One connection: SQLite has one writer anyway, `:memory:` is per connection, and the
    // exclusive lock is per connection.
    let pool = SqlitePoolOptions::new()
        .max_connections(1)
        .min_connections(1)
        .idle_timeout(None)
        .max_lifetime(None)
        .acquire_timeout(Duration::from_secs(10))
        .connect_with(opts)
        .await
        .map_err(|e| format!("cannot open database {path}: {e}"))?;
    let check: String = sqlx::query_scalar("PRAGMA quick_check")
        .fetch_one(&pool)
        .await
        .map_err(|e| format!("database {path} is unreadable: {e}"))?;
    if check != "ok" {
        return Err(format!("database {path} is corrupt: {check}"));
    }
    migrator()
        .run(&pool)
        .await
        .map_err(|e| format!("cannot migrate database {path}: {e}"))?;
    // A write takes the exclusive lock and keeps it: a second motiond on this file fails.
    sqlx::query("INSERT INTO meta (key, value) VALUES ('last_start', ?) ON CONFLICT (key) DO UPDATE SET value = excluded.value")
        .bind(now_rfc3339())
        .execute(&pool)
        .await
        .map_err(|e| format!("cannot write database {path} (is another motiond using it?): {e}"))?;
    Ok(pool)
}

pub struct StoredAxis {
    pub id: i64,
    pub name: String,
    pub config: String,
}

pub async fn load_axes(pool: &SqlitePool) -> Result<Vec<StoredAxis>, sqlx::Error> {
    let rows = sqlx::query("SELECT id, name, config FROM axes ORDER BY id")
        .fetch_all(pool)
        .await?;
    Ok(rows
        .into_iter()
        .map(|r| StoredAxis {
            id: r.get(0),
            name: r.get(1),
            config: r.get(2),
        })
        .collect())
}

pub async fn load_persistent(pool: &SqlitePool) -> Result<Vec<(i64, u16, String)>, sqlx::Error> {
    let rows = sqlx::query(
        "SELECT axis_id, number, value FROM persistent_parameters ORDER BY axis_id, number",
    )
    .fetch_all(pool)
    .await?;
    Ok(rows
        .into_iter()
        .map(|r| (r.get::<i64, _>(0), r.get::<i64, _>(1) as u16, r.get(2)))
        .collect())
}

pub async fn meta(pool: &SqlitePool, key: &str) -> Result<Option<String>, sqlx::Error> {
    sqlx::query_scalar("SELECT value FROM meta WHERE key = ?")
        .bind(key)
        .fetch_optional(pool)
        .await
}

pub async fn max_command_id(pool: &SqlitePool) -> Result<u64, sqlx::Error> {
    let v: Option<i64> = sqlx::query_scalar("SELECT max(command_id) FROM audit_log")
        .fetch_one(pool)
        .await?;
    Ok(v.unwrap_or(0) as u64)
}

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
}

pub async fn audit<'e, E: sqlx::SqliteExecutor<'e>>(
    e: E,
    a: &AuditEntry,
) -> Result<(), sqlx::Error> {
    sqlx::query("INSERT INTO audit_log (at, client_addr, client_id, action, target, command_id, detail, outcome) VALUES (?, ?, ?, ?, ?, ?, ?, ?)")
        .bind(&a.at)
        .bind(&a.client_addr)
        .bind(&a.client_id)
        .bind(&a.action)
        .bind(&a.target)
        .bind(a.command_id.map(|c| c as i64))
        .bind(&a.detail)
        .bind(&a.outcome)
        .execute(e)
        .await
        .map(|_| ())
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
) -> Result<Vec<AuditRow>, sqlx::Error> {
    let rows = sqlx::query(
        "SELECT id, at, client_addr, client_id, action, target, command_id, detail, outcome \
         FROM audit_log WHERE id > ? ORDER BY id DESC LIMIT ?",
    )
    .bind(since_id)
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
            },
        })
        .collect())
}

pub fn now_rfc3339() -> String {
    humantime::format_rfc3339_millis(std::time::SystemTime::now()).to_string()
}
