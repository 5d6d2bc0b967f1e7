//! Axes (their configuration as JSON) and their persistent parameters. Writes take a
//! connection (a transaction's): the service layer decides what commits together.

use sqlx::{Row, SqliteConnection, SqlitePool};

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

/// Inserts an axis row; `id` None lets SQLite choose. Returns the id.
pub async fn insert_axis(
    c: &mut SqliteConnection,
    id: Option<i64>,
    name: &str,
    config_json: &str,
    now: &str,
) -> Result<i64, sqlx::Error> {
    sqlx::query_scalar(
        "INSERT INTO axes (id, name, config, created_at, updated_at) VALUES (?, ?, ?, ?, ?) RETURNING id",
    )
    .bind(id)
    .bind(name)
    .bind(config_json)
    .bind(now)
    .bind(now)
    .fetch_one(c)
    .await
}

/// Replaces an axis's name and configuration.
pub async fn update_axis(
    c: &mut SqliteConnection,
    id: i64,
    name: &str,
    config_json: &str,
    now: &str,
) -> Result<(), sqlx::Error> {
    sqlx::query("UPDATE axes SET name = ?, config = ?, updated_at = ? WHERE id = ?")
        .bind(name)
        .bind(config_json)
        .bind(now)
        .bind(id)
        .execute(c)
        .await
        .map(|_| ())
}

/// Deletes an axis (its persistent parameters go with it: foreign key cascade).
pub async fn delete_axis(c: &mut SqliteConnection, id: i64) -> Result<(), sqlx::Error> {
    sqlx::query("DELETE FROM axes WHERE id = ?")
        .bind(id)
        .execute(c)
        .await
        .map(|_| ())
}

/// Deletes every axis (a configuration import replaces them all).
pub async fn delete_all_axes(c: &mut SqliteConnection) -> Result<(), sqlx::Error> {
    sqlx::query("DELETE FROM axes").execute(c).await.map(|_| ())
}

/// Forgets an axis's persistent parameters (its configuration was replaced).
pub async fn clear_persistent(c: &mut SqliteConnection, axis_id: i64) -> Result<(), sqlx::Error> {
    sqlx::query("DELETE FROM persistent_parameters WHERE axis_id = ?")
        .bind(axis_id)
        .execute(c)
        .await
        .map(|_| ())
}

/// Drops one persistent parameter value (by its storage number).
pub async fn delete_persistent(
    c: &mut SqliteConnection,
    axis_id: i64,
    number: u16,
) -> Result<(), sqlx::Error> {
    sqlx::query("DELETE FROM persistent_parameters WHERE axis_id = ? AND number = ?")
        .bind(axis_id)
        .bind(number as i64)
        .execute(c)
        .await
        .map(|_| ())
}

/// Stores a persistent parameter value (JSON), replacing the one stored before.
pub async fn upsert_persistent(
    c: &mut SqliteConnection,
    axis_id: i64,
    number: u16,
    value_json: &str,
    now: &str,
) -> Result<(), sqlx::Error> {
    sqlx::query(
        "INSERT INTO persistent_parameters (axis_id, number, value, updated_at) VALUES (?, ?, ?, ?) \
         ON CONFLICT (axis_id, number) DO UPDATE SET value = excluded.value, updated_at = excluded.updated_at",
    )
    .bind(axis_id)
    .bind(number as i64)
    .bind(value_json)
    .bind(now)
    .execute(c)
    .await
    .map(|_| ())
}
