//! SQLite store (DESIGN §5): WAL, synchronous=FULL, one writer connection. All SQL lives in
//! this module, one submodule per table group ([`axes`]: axes and their persistent
//! parameters; [`cams`]: cam tables; [`groups`]: axis groups; [`audit`]: the audit log); the service decides what goes into a transaction.
//!
//! The database is opened with `locking_mode=EXCLUSIVE`, so a second motiond on the same
//! file fails at start-up with "database is locked" instead of two processes writing.

pub mod audit;
pub mod auth;
pub mod axes;
pub mod cams;
pub mod groups;
pub mod scope_setups;

pub use audit::{
    AuditEntry, AuditOp, AuditRow, audit, audit_outcome, find_idempotency_key, read_audit,
};
pub use axes::{StoredAxis, load_axes, load_persistent};

use std::str::FromStr;
use std::time::Duration;

use sqlx::SqlitePool;
use sqlx::migrate::Migrator;
use sqlx::sqlite::{
    SqliteConnectOptions, SqliteJournalMode, SqliteLockingMode, SqlitePoolOptions,
    SqliteSynchronous,
};

/// The schema migrations of `migrations/`, embedded at build time.
pub fn migrator() -> Migrator {
    sqlx::migrate!("../../migrations")
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
        // A write that failed (disk full, I/O error) can leave the connection inside a
        // transaction — SQLite's, or sqlx's bookkeeping of one — and every later "commit" on it
        // would only release a savepoint of that transaction: acknowledged and never stored.
        // Such a connection is closed when it comes back and before it is handed out; the
        // pool opens a fresh one.
        // (Not for `:memory:`: a new connection would be a new, empty database.)
        .after_release(move |conn, _| {
            Box::pin(async move { if memory { Ok(true) } else { clean(conn).await } })
        })
        .before_acquire(move |conn, _| {
            Box::pin(async move { if memory { Ok(true) } else { clean(conn).await } })
        })
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

/// Whether a pooled connection holds no transaction, in sqlx's books and SQLite's. A
/// transaction dropped without commit has its rollback queued on the connection's worker:
/// taking the handle lets it run first (the worker works in order), then both are asked.
async fn clean(conn: &mut sqlx::SqliteConnection) -> Result<bool, sqlx::Error> {
    use sqlx::TransactionManager;
    let autocommit = {
        let mut handle = conn.lock_handle().await?;
        // SAFETY: the handle is locked for us (the worker makes no calls meanwhile) and valid.
        unsafe { libsqlite3_sys::sqlite3_get_autocommit(handle.as_raw_handle().as_ptr()) }
    };
    let depth = sqlx::sqlite::SqliteTransactionManager::get_transaction_depth(conn);
    if depth != 0 || autocommit == 0 {
        tracing::warn!(
            "database connection left inside a transaction after a failed write (depth {depth}, SQLite {}): reopened",
            if autocommit == 0 {
                "in a transaction"
            } else {
                "not"
            }
        );
        return Ok(false);
    }
    Ok(true)
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

/// The highest command id handed out or reserved (persisted before an id above the previous
/// mark is acknowledged, so that ids never repeat after a crash).
pub async fn command_ids_reserved(pool: &SqlitePool) -> Result<u64, sqlx::Error> {
    Ok(meta(pool, "command_ids_reserved")
        .await?
        .and_then(|v| v.parse().ok())
        .unwrap_or(0))
}

pub async fn reserve_command_ids(pool: &SqlitePool, up_to: u64) -> Result<(), sqlx::Error> {
    sqlx::query(
        "INSERT INTO meta (key, value) VALUES ('command_ids_reserved', ?) \
         ON CONFLICT (key) DO UPDATE SET value = excluded.value",
    )
    .bind(up_to.to_string())
    .execute(pool)
    .await
    .map(|_| ())
}

/// Records the first start of a database (the demo machine is created only then).
pub async fn mark_initialised(pool: &SqlitePool) -> Result<(), sqlx::Error> {
    sqlx::query("INSERT INTO meta (key, value) VALUES ('initialised', ?)")
        .bind(now_rfc3339())
        .execute(pool)
        .await
        .map(|_| ())
}

/// The cycle count and the cycle time of a virtual clock (`crate::clock`), once one runs.
type VirtualTime = (Box<dyn Fn() -> u64 + Send + Sync>, u64);
/// Replaced by each machine started in this process (`motiond scenario run` runs one after
/// the other).
static VIRTUAL_TIME: std::sync::RwLock<Option<VirtualTime>> = std::sync::RwLock::new(None);

/// Stamps follow a virtual clock from now on: `cycle` reads its cycle count.
pub fn use_virtual_time(cycle: Box<dyn Fn() -> u64 + Send + Sync>, period_ns: u64) {
    *VIRTUAL_TIME.write().unwrap() = Some((cycle, period_ns));
}

/// The time to stamp things with: the wall clock, or in virtual time the Unix epoch plus the
/// virtual time (two runs stamp alike; decision 158).
pub fn wall_now() -> std::time::SystemTime {
    let cycle = VIRTUAL_TIME.read().unwrap().as_ref().map(|(c, _)| c());
    match cycle {
        Some(c) => wall_at_cycle(c),
        None => std::time::SystemTime::now(),
    }
}

/// The time of something that happened in `cycle` (a command's end): in virtual time that
/// cycle's time (not when the async side got to it), in real time now.
pub fn wall_at_cycle(cycle: u64) -> std::time::SystemTime {
    match VIRTUAL_TIME.read().unwrap().as_ref() {
        Some((_, period)) => {
            std::time::UNIX_EPOCH + std::time::Duration::from_nanos(cycle * period)
        }
        None => std::time::SystemTime::now(),
    }
}

/// The time of something that happened in `cycle`, as RFC 3339 (see [`wall_at_cycle`]).
pub fn cycle_rfc3339(cycle: u64) -> String {
    humantime::format_rfc3339_millis(wall_at_cycle(cycle)).to_string()
}

pub fn now_rfc3339() -> String {
    humantime::format_rfc3339_millis(wall_now()).to_string()
}
