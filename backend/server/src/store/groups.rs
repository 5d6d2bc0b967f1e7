//! Axis groups: one row per group, its configuration as JSON (members by axis id, so that an
//! axis keeps its place when renamed).

use sqlx::{Row, SqliteConnection, SqlitePool};

pub struct StoredGroup {
    pub id: i64,
    pub name: String,
    pub config: String,
    pub updated_at: String,
}

pub async fn load_groups(pool: &SqlitePool) -> Result<Vec<StoredGroup>, sqlx::Error> {
    let rows = sqlx::query("SELECT id, name, config, updated_at FROM axis_groups ORDER BY id")
        .fetch_all(pool)
        .await?;
    Ok(rows
        .into_iter()
        .map(|r| StoredGroup {
            id: r.get(0),
            name: r.get(1),
            config: r.get(2),
            updated_at: r.get(3),
        })
        .collect())
}

pub async fn upsert_group(
    c: &mut SqliteConnection,
    id: i64,
    name: &str,
    config: &str,
    now: &str,
) -> Result<(), sqlx::Error> {
    sqlx::query(
        "INSERT INTO axis_groups (id, name, config, created_at, updated_at) VALUES (?, ?, ?, ?, ?) \
         ON CONFLICT(id) DO UPDATE SET name = excluded.name, config = excluded.config, \
         updated_at = excluded.updated_at",
    )
    .bind(id)
    .bind(name)
    .bind(config)
    .bind(now)
    .bind(now)
    .execute(c)
    .await?;
    Ok(())
}

pub async fn delete_group(c: &mut SqliteConnection, id: i64) -> Result<(), sqlx::Error> {
    sqlx::query("DELETE FROM axis_groups WHERE id = ?")
        .bind(id)
        .execute(c)
        .await?;
    Ok(())
}

pub async fn delete_all_groups(c: &mut SqliteConnection) -> Result<(), sqlx::Error> {
    sqlx::query("DELETE FROM axis_groups").execute(c).await?;
    Ok(())
}
