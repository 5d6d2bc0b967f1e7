//! Users, sessions and API tokens (migration 0004). Only hashes are stored (see `crate::auth`).

use sqlx::{Row, SqlitePool};

pub struct StoredUser {
    pub id: i64,
    pub name: String,
    pub role: String,
    pub password_hash: String,
    pub created_at: String,
}

pub struct StoredSession {
    pub secret_sha256: Vec<u8>,
    pub user_id: i64,
    pub expires_at: String,
}

pub struct StoredToken {
    pub id: i64,
    pub name: String,
    pub role: String,
    pub secret_sha256: Vec<u8>,
    pub created_by: String,
    pub created_at: String,
    pub expires_at: Option<String>,
    pub last_used_at: Option<String>,
    pub revoked_at: Option<String>,
}

pub async fn users(pool: &SqlitePool) -> Result<Vec<StoredUser>, sqlx::Error> {
    let rows =
        sqlx::query("SELECT id, name, role, password_hash, created_at FROM users ORDER BY name")
            .fetch_all(pool)
            .await?;
    Ok(rows
        .into_iter()
        .map(|r| StoredUser {
            id: r.get(0),
            name: r.get(1),
            role: r.get(2),
            password_hash: r.get(3),
            created_at: r.get(4),
        })
        .collect())
}

pub async fn sessions(pool: &SqlitePool) -> Result<Vec<StoredSession>, sqlx::Error> {
    let rows = sqlx::query("SELECT secret_sha256, user_id, expires_at FROM sessions")
        .fetch_all(pool)
        .await?;
    Ok(rows
        .into_iter()
        .map(|r| StoredSession {
            secret_sha256: r.get(0),
            user_id: r.get(1),
            expires_at: r.get(2),
        })
        .collect())
}

pub async fn tokens(pool: &SqlitePool) -> Result<Vec<StoredToken>, sqlx::Error> {
    let rows = sqlx::query(
        "SELECT id, name, role, secret_sha256, created_by, created_at, expires_at, last_used_at, revoked_at \
         FROM api_tokens ORDER BY id",
    )
    .fetch_all(pool)
    .await?;
    Ok(rows
        .into_iter()
        .map(|r| StoredToken {
            id: r.get(0),
            name: r.get(1),
            role: r.get(2),
            secret_sha256: r.get(3),
            created_by: r.get(4),
            created_at: r.get(5),
            expires_at: r.get(6),
            last_used_at: r.get(7),
            revoked_at: r.get(8),
        })
        .collect())
}

pub async fn insert_user<'e, E: sqlx::SqliteExecutor<'e>>(
    e: E,
    name: &str,
    role: &str,
    password_hash: &str,
    created_at: &str,
) -> Result<i64, sqlx::Error> {
    let r = sqlx::query(
        "INSERT INTO users (name, role, password_hash, created_at) VALUES (?, ?, ?, ?)",
    )
    .bind(name)
    .bind(role)
    .bind(password_hash)
    .bind(created_at)
    .execute(e)
    .await?;
    Ok(r.last_insert_rowid())
}

pub async fn update_user<'e, E: sqlx::SqliteExecutor<'e>>(
    e: E,
    id: i64,
    role: &str,
    password_hash: &str,
) -> Result<(), sqlx::Error> {
    sqlx::query("UPDATE users SET role = ?, password_hash = ? WHERE id = ?")
        .bind(role)
        .bind(password_hash)
        .bind(id)
        .execute(e)
        .await
        .map(|_| ())
}

pub async fn delete_user<'e, E: sqlx::SqliteExecutor<'e>>(
    e: E,
    id: i64,
) -> Result<(), sqlx::Error> {
    sqlx::query("DELETE FROM users WHERE id = ?")
        .bind(id)
        .execute(e)
        .await
        .map(|_| ())
}

pub async fn delete_sessions_of<'e, E: sqlx::SqliteExecutor<'e>>(
    e: E,
    user_id: i64,
) -> Result<(), sqlx::Error> {
    sqlx::query("DELETE FROM sessions WHERE user_id = ?")
        .bind(user_id)
        .execute(e)
        .await
        .map(|_| ())
}

pub async fn insert_session<'e, E: sqlx::SqliteExecutor<'e>>(
    e: E,
    secret_sha256: &[u8],
    user_id: i64,
    created_at: &str,
    expires_at: &str,
) -> Result<(), sqlx::Error> {
    sqlx::query(
        "INSERT INTO sessions (secret_sha256, user_id, created_at, expires_at) VALUES (?, ?, ?, ?)",
    )
    .bind(secret_sha256)
    .bind(user_id)
    .bind(created_at)
    .bind(expires_at)
    .execute(e)
    .await
    .map(|_| ())
}

pub async fn delete_session<'e, E: sqlx::SqliteExecutor<'e>>(
    e: E,
    secret_sha256: &[u8],
) -> Result<(), sqlx::Error> {
    sqlx::query("DELETE FROM sessions WHERE secret_sha256 = ?")
        .bind(secret_sha256)
        .execute(e)
        .await
        .map(|_| ())
}

pub async fn delete_expired_sessions(pool: &SqlitePool, now: &str) -> Result<(), sqlx::Error> {
    sqlx::query("DELETE FROM sessions WHERE expires_at <= ?")
        .bind(now)
        .execute(pool)
        .await
        .map(|_| ())
}

#[allow(clippy::too_many_arguments, reason = "one column each")]
pub async fn insert_token<'e, E: sqlx::SqliteExecutor<'e>>(
    e: E,
    name: &str,
    role: &str,
    secret_sha256: &[u8],
    created_by: &str,
    created_at: &str,
    expires_at: Option<&str>,
) -> Result<i64, sqlx::Error> {
    let r = sqlx::query(
        "INSERT INTO api_tokens (name, role, secret_sha256, created_by, created_at, expires_at) VALUES (?, ?, ?, ?, ?, ?)",
    )
    .bind(name)
    .bind(role)
    .bind(secret_sha256)
    .bind(created_by)
    .bind(created_at)
    .bind(expires_at)
    .execute(e)
    .await?;
    Ok(r.last_insert_rowid())
}

/// Revokes every token not revoked yet; their names.
pub async fn revoke_all_tokens<'e, E: sqlx::SqliteExecutor<'e>>(
    e: E,
    at: &str,
) -> Result<Vec<String>, sqlx::Error> {
    let rows =
        sqlx::query("UPDATE api_tokens SET revoked_at = ? WHERE revoked_at IS NULL RETURNING name")
            .bind(at)
            .fetch_all(e)
            .await?;
    Ok(rows.iter().map(|r| r.get::<String, _>(0)).collect())
}

pub async fn revoke_token<'e, E: sqlx::SqliteExecutor<'e>>(
    e: E,
    id: i64,
    at: &str,
) -> Result<(), sqlx::Error> {
    sqlx::query("UPDATE api_tokens SET revoked_at = ? WHERE id = ? AND revoked_at IS NULL")
        .bind(at)
        .bind(id)
        .execute(e)
        .await
        .map(|_| ())
}

pub async fn token_used(pool: &SqlitePool, id: i64, at: &str) -> Result<(), sqlx::Error> {
    sqlx::query("UPDATE api_tokens SET last_used_at = ? WHERE id = ?")
        .bind(at)
        .bind(id)
        .execute(pool)
        .await
        .map(|_| ())
}
