//! Cam tables: one row per table, position-table rows as a blob of little-endian f64 pairs
//! (16 bytes a row: a million rows load in milliseconds), motion-function points as JSON.

use motion::cam::{CamTableData, InterpolationType, TableType};
use sqlx::{Row, SqliteConnection, SqlitePool};

pub struct StoredCamTable {
    pub id: u32,
    pub name: String,
    pub version: i64,
    pub data: CamTableData,
    pub updated_at: String,
}

fn enum_text<T: serde::Serialize>(v: &T) -> String {
    serde_json::to_value(v)
        .ok()
        .and_then(|v| v.as_str().map(str::to_string))
        .expect("a unit enum serialises as a string")
}

fn enum_from<T: serde::de::DeserializeOwned>(s: &str) -> Result<T, sqlx::Error> {
    serde_json::from_value(serde_json::Value::String(s.into()))
        .map_err(|e| sqlx::Error::Decode(Box::new(e)))
}

fn rows_blob(rows: &[[f64; 2]]) -> Vec<u8> {
    let mut b = Vec::with_capacity(rows.len() * 16);
    for [m, s] in rows {
        b.extend_from_slice(&m.to_le_bytes());
        b.extend_from_slice(&s.to_le_bytes());
    }
    b
}

fn rows_from(blob: &[u8]) -> Vec<[f64; 2]> {
    blob.chunks_exact(16)
        .map(|c| {
            let f = |i: usize| f64::from_le_bytes(c[i..i + 8].try_into().expect("8 bytes"));
            [f(0), f(8)]
        })
        .collect()
}

pub async fn load_cam_tables(pool: &SqlitePool) -> Result<Vec<StoredCamTable>, sqlx::Error> {
    let rows = sqlx::query(
        "SELECT id, name, version, table_type, periodic, interpolation, rows, points, updated_at \
         FROM cam_tables ORDER BY id",
    )
    .fetch_all(pool)
    .await?;
    rows.into_iter()
        .map(|r| {
            let points: Option<String> = r.get(7);
            Ok(StoredCamTable {
                id: r.get::<i64, _>(0) as u32,
                name: r.get(1),
                version: r.get(2),
                data: CamTableData {
                    table_type: enum_from::<TableType>(r.get(3))?,
                    periodic: r.get::<i64, _>(4) != 0,
                    interpolation: enum_from::<InterpolationType>(r.get(5))?,
                    rows: r
                        .get::<Option<Vec<u8>>, _>(6)
                        .map(|b| rows_from(&b))
                        .unwrap_or_default(),
                    points: match points {
                        Some(p) => serde_json::from_str(&p)
                            .map_err(|e| sqlx::Error::Decode(Box::new(e)))?,
                        None => Vec::new(),
                    },
                },
                updated_at: r.get(8),
            })
        })
        .collect()
}

/// Inserts a table, or replaces the one with its id (version given by the caller).
pub async fn upsert_cam_table(
    c: &mut SqliteConnection,
    id: u32,
    name: &str,
    version: i64,
    data: &CamTableData,
    now: &str,
) -> Result<(), sqlx::Error> {
    let rows = (!data.rows.is_empty()).then(|| rows_blob(&data.rows));
    let points = (!data.points.is_empty())
        .then(|| serde_json::to_string(&data.points).expect("points serialise"));
    sqlx::query(
        "INSERT INTO cam_tables (id, name, version, table_type, periodic, interpolation, row_count, rows, points, created_at, updated_at) \
         VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?) \
         ON CONFLICT (id) DO UPDATE SET name = excluded.name, version = excluded.version, \
         table_type = excluded.table_type, periodic = excluded.periodic, interpolation = excluded.interpolation, \
         row_count = excluded.row_count, rows = excluded.rows, points = excluded.points, updated_at = excluded.updated_at",
    )
    .bind(id as i64)
    .bind(name)
    .bind(version)
    .bind(enum_text(&data.table_type))
    .bind(data.periodic as i64)
    .bind(enum_text(&data.interpolation))
    .bind(data.len() as i64)
    .bind(rows)
    .bind(points)
    .bind(now)
    .bind(now)
    .execute(c)
    .await
    .map(|_| ())
}

pub async fn delete_cam_table(c: &mut SqliteConnection, id: u32) -> Result<(), sqlx::Error> {
    sqlx::query("DELETE FROM cam_tables WHERE id = ?")
        .bind(id as i64)
        .execute(c)
        .await
        .map(|_| ())
}

/// Deletes every table (an import with cam tables replaces them all).
pub async fn delete_all_cam_tables(c: &mut SqliteConnection) -> Result<(), sqlx::Error> {
    sqlx::query("DELETE FROM cam_tables")
        .execute(c)
        .await
        .map(|_| ())
}
