//! Saved scope setups: one row per name, the setup as JSON.

use sqlx::{Row, SqliteConnection, SqlitePool};

pub struct StoredSetup {
    pub name: String,
    pub body: String,
    pub updated_at: String,
}

pub async fn list(pool: &SqlitePool) -> Result<Vec<StoredSetup>, sqlx::Error> {
    let rows = sqlx::query("SELECT name, body, updated_at FROM scope_setups ORDER BY name")
        .fetch_all(pool)
        .await?;
    Ok(rows
        .into_iter()
        .map(|r| StoredSetup {
            name: r.get(0),
            body: r.get(1),
            updated_at: r.get(2),
        })
        .collect())
}

/// Stores a setup; true when it replaced one of the same name.
pub async fn put(
    c: &mut SqliteConnection,
    name: &str,
    body: &str,
    at: &str,
) -> Result<bool, sqlx::Error> {
    let existed: Option<String> =
        sqlx::query_scalar("SELECT name FROM scope_setups WHERE name = ?")
            .bind(name)
            .fetch_optional(&mut *c)
            .await?;
    sqlx::query(
        "INSERT INTO scope_setups (name, body, updated_at) VALUES (?, ?, ?) \
         ON CONFLICT (name) DO UPDATE SET body = excluded.body, updated_at = excluded.updated_at",
    )
    .bind(name)
    .bind(body)
    .bind(at)
    .execute(c)
    .await?;
    Ok(existed.is_some())
}

/// Deletes a setup; false when there was none.
pub async fn delete(c: &mut SqliteConnection, name: &str) -> Result<bool, sqlx::Error> {
    let r = sqlx::query("DELETE FROM scope_setups WHERE name = ?")
        .bind(name)
        .execute(c)
        .await?;
    Ok(r.rows_affected() > 0)
}
