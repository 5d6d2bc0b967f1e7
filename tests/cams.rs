//! Cam tables over HTTP against the real binary: upload, read back, analysis, validation
//! errors, restart, export/import (spec camming-tf5050.md; issue "Electronic cams").

mod common;

use common::*;
use serde_json::{Value, json};

fn polynom5() -> Value {
    json!({"name": "p5", "table_type": "motion_function", "points": [
        {"point_index": 1, "function_type": "polynom5", "point_type": "rest", "master_pos": 0.0, "slave_pos": 0.0},
        {"point_index": 2, "function_type": "polynom5", "point_type": "rest", "master_pos": 200.0, "slave_pos": 100.0}
    ]})
}

/// The inverse-lookup table of the spec (§5.3).
fn symmetric(periodic: bool) -> Value {
    json!({"name": if periodic { "sym_periodic" } else { "sym" }, "table_type": "non_equidistant", "periodic": periodic,
        "rows": [[0.0, 0.0], [135.0, 80.0], [180.0, 100.0], [225.0, 80.0], [360.0, 0.0]]})
}

fn close(v: &Value, want: f64) -> bool {
    (v.as_f64().unwrap_or(f64::NAN) - want).abs() < 1e-6 * (1.0 + want.abs())
}

#[tokio::test(flavor = "multi_thread")]
async fn cam_tables_are_stored_read_back_and_analysed() {
    let s = Server::start();
    let r = post(&s, "/api/v1/cam-tables", polynom5()).await;
    assert_eq!(r.status, 201, "{}", r.text);
    assert_eq!(r.location.as_deref(), Some("/api/v1/cam-tables/1"));
    assert_eq!(r.json["version"], 1);
    assert_eq!(r.json["master_period"], 200.0);
    assert!(r.json.get("points").is_none(), "the answer is the summary");

    let one = get(&s, "/api/v1/cam-tables/p5").await;
    assert_eq!(one.status, 200);
    assert_eq!(one.json["points"].as_array().unwrap().len(), 2);
    assert_eq!(
        one.json["points"][0]["rel_index_next_point"], 1,
        "defaults are filled in"
    );
    assert_eq!(
        get(&s, "/api/v1/cam-tables/1").await.json,
        one.json,
        "by id or name"
    );

    let c = get(&s, "/api/v1/cam-tables/p5/characteristics").await;
    assert_eq!(c.status, 200);
    assert!(close(&c.json["slave_velo_max"], 0.9375), "{}", c.text);
    assert!(close(&c.json["m_pos_at_s_acc_max"], 42.26497), "{}", c.text);
    assert!(close(&c.json["slave_jerk_start"], 0.00075));

    let v = get(
        &s,
        "/api/v1/cam-tables/p5/values?start=0&end=200&increment=50&values=position,velocity",
    )
    .await;
    assert_eq!(v.status, 200, "{}", v.text);
    assert_eq!(v.json["columns"], json!(["master", "position", "velocity"]));
    assert_eq!(v.json["rows"][1], json!([50.0, 10.3515625, 0.52734375]));
    assert_eq!(v.json["rows"].as_array().unwrap().len(), 5);

    // MC_ReadCamTableSlaveDynamics: what each table type gives (§2.16).
    let d = get(
        &s,
        "/api/v1/cam-tables/p5/slave-dynamics?master_position=50",
    )
    .await;
    assert_eq!(
        d.json,
        json!({"master_position": 50.0, "slave_position": 10.3515625,
        "slave_velocity": 0.52734375, "slave_acceleration": 0.0140625})
    );
    assert_eq!(
        post(&s, "/api/v1/cam-tables", symmetric(false))
            .await
            .status,
        201
    );
    let d = get(
        &s,
        "/api/v1/cam-tables/sym/slave-dynamics?master_position=90",
    )
    .await;
    assert_eq!(
        (
            d.json["slave_velocity"].as_f64(),
            d.json["slave_acceleration"].as_f64()
        ),
        (Some(0.0), Some(0.0))
    );
    assert!(close(&d.json["slave_position"], 80.0 * 90.0 / 135.0));
    let eq = json!({"name": "eq", "table_type": "equidistant", "rows": [[0.0, 0.0], [10.0, 5.0], [20.0, 5.0]]});
    assert_eq!(post(&s, "/api/v1/cam-tables", eq).await.status, 201);
    let d = get(&s, "/api/v1/cam-tables/eq/slave-dynamics?master_position=5").await;
    assert_eq!(
        (
            d.json["slave_velocity"].as_f64(),
            d.json["slave_acceleration"].as_f64()
        ),
        (Some(0.5), Some(0.0))
    );

    // MC_ReadCamTableMasterPosition with the manual's numbers.
    let m = get(
        &s,
        "/api/v1/cam-tables/sym/master-position?slave_position=80&master_start_position=180",
    )
    .await;
    assert_eq!(m.status, 200, "{}", m.text);
    assert!(
        close(&m.json["master_low"]["master_axis_position"], 135.0),
        "{}",
        m.text
    );
    assert!(
        close(&m.json["master_high"]["master_axis_position"], 225.0),
        "{}",
        m.text
    );
    assert_eq!(
        post(&s, "/api/v1/cam-tables", symmetric(true)).await.status,
        201
    );
    let m = get(&s, "/api/v1/cam-tables/sym_periodic/master-position?slave_position=80&master_start_position=90").await;
    assert!(
        close(&m.json["master_low"]["master_axis_position"], -135.0),
        "{}",
        m.text
    );
    assert!(
        close(&m.json["master_high"]["master_axis_position"], 135.0),
        "{}",
        m.text
    );
    let m = get(
        &s,
        "/api/v1/cam-tables/sym/master-position?slave_position=80&master_start_position=90",
    )
    .await;
    assert_eq!(m.json["master_low"]["valid"], false);
    assert_eq!(m.json["master_high"]["valid"], true);

    let list = get(&s, "/api/v1/cam-tables").await;
    let names: Vec<&str> = list
        .json
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["p5", "sym", "eq", "sym_periodic"]);
    assert!(list.json[0].get("points").is_none());
}

#[tokio::test(flavor = "multi_thread")]
async fn bad_tables_and_queries_are_refused_and_change_nothing() {
    let s = Server::start();
    let refused = |body: Value| {
        let s = &s;
        async move {
            let r = post(s, "/api/v1/cam-tables", body).await;
            assert_eq!(r.status, 422, "{}", r.text);
            assert_eq!(r.content_type, "application/problem+json");
            (
                r.json["error_id"].as_u64(),
                r.json["errors"][0]["field"]
                    .as_str()
                    .unwrap_or("")
                    .to_string(),
            )
        }
    };
    let rows = |rows: Value| json!({"name": "t", "table_type": "non_equidistant", "rows": rows});
    assert_eq!(
        refused(rows(json!([[0, 0], [100, 1], [90, 2]]))).await,
        (Some(0x7080), "rows[2][0]".into())
    );
    assert_eq!(
        refused(rows(json!([[0, 0], [100, 1, 3]]))).await,
        (None, "rows[1]".into())
    );
    assert_eq!(
        refused(rows(json!([[0, 0]]))).await,
        (Some(0x4B34), "rows".into())
    );
    let mut p = polynom5();
    p["points"][1]["point_type"] = json!("ignore");
    assert_eq!(
        refused(p).await,
        (Some(0x7081), "points[1].point_type".into())
    );
    let mut p = polynom5();
    p["points"][1]["point_index"] = json!(3);
    assert_eq!(
        refused(p).await,
        (Some(0x4B33), "points[1].point_index".into())
    );
    let mut p = polynom5();
    p["points"][0]["function_type"] = json!("polynom1");
    assert_eq!(
        refused(p).await,
        (Some(0x7082), "points[0].point_type".into())
    );
    let mut p = polynom5();
    p["points"][0]["function_type"] = json!("no_such_law");
    assert_eq!(refused(p).await.1, "points[0].function_type");
    let mut p = polynom5();
    p["name"] = json!("123");
    assert_eq!(refused(p).await, (None, "name".into()));
    let mut p = polynom5();
    p["id"] = json!(256);
    // The id out of 1..255 carries its number (docs/errors.md, issue 28 defect 9).
    assert_eq!(refused(p).await, (Some(0x4B32), "id".into()));
    let mut t = rows(json!([[0, 0], [1, 1]]));
    t["interpolation"] = json!("4point");
    assert_eq!(refused(t).await, (Some(0x4B35), "interpolation".into()));
    assert_eq!(
        get(&s, "/api/v1/cam-tables").await.json,
        json!([]),
        "nothing was stored"
    );

    assert_eq!(post(&s, "/api/v1/cam-tables", polynom5()).await.status, 201);
    let r = post(&s, "/api/v1/cam-tables", polynom5()).await;
    assert_eq!(
        (r.status, r.json["code"].as_str()),
        (409, Some("cam_table_name_taken"))
    );
    let mut other = polynom5();
    other["name"] = json!("other");
    other["id"] = json!(1);
    let r = post(&s, "/api/v1/cam-tables", other).await;
    assert_eq!(
        (r.status, r.json["code"].as_str()),
        (409, Some("cam_table_id_taken"))
    );
    for q in [
        "values?start=0&end=200&increment=0",
        "values?start=0&end=200&increment=0.0001",
        "values?start=0&end=1",
    ] {
        let r = get(&s, &format!("/api/v1/cam-tables/p5/{q}")).await;
        assert_eq!(r.status, 422, "{q}: {}", r.text);
    }
    let r = get(
        &s,
        "/api/v1/cam-tables/p5/values?start=0&end=1&increment=1&values=speed",
    )
    .await;
    assert_eq!(
        (r.status, r.json["errors"][0]["field"].as_str()),
        (422, Some("values"))
    );
    let r = get(&s, "/api/v1/cam-tables/nope").await;
    assert_eq!(
        (r.status, r.json["code"].as_str()),
        (404, Some("cam_table_not_found"))
    );
    let r = req(reqwest::Method::POST, &s.url("/api/v1/cam-tables"), None).await;
    assert_eq!(r.status, 422, "an empty body: {}", r.text);
    // Replacing keeps the id and counts versions; a body naming another id is refused.
    let mut p = polynom5();
    p["points"][1]["slave_pos"] = json!(120.0);
    let r = put(&s, "/api/v1/cam-tables/p5", p.clone()).await;
    assert_eq!(
        (
            r.status,
            r.json["version"].as_i64(),
            r.json["slave_end"].as_f64()
        ),
        (200, Some(2), Some(120.0)),
        "{}",
        r.text
    );
    p["id"] = json!(7);
    assert_eq!(put(&s, "/api/v1/cam-tables/p5", p).await.status, 422);
    assert_eq!(delete(&s, "/api/v1/cam-tables/p5").await.status, 204);
    assert_eq!(get(&s, "/api/v1/cam-tables/p5").await.status, 404);
    let audit = get(&s, "/api/v1/audit?limit=10").await;
    let actions: Vec<&str> = audit
        .json
        .as_array()
        .unwrap()
        .iter()
        .map(|a| a["action"].as_str().unwrap())
        .collect();
    for a in ["cam_table.create", "cam_table.replace", "cam_table.delete"] {
        assert!(actions.contains(&a), "{a} in {actions:?}");
    }
}

/// Tables live in the database: a restart finds them (and only them); the configuration
/// document carries them to another machine, and an import without `cam_tables` keeps them.
#[tokio::test(flavor = "multi_thread")]
async fn cam_tables_survive_a_restart_and_travel_with_the_configuration() {
    let dir = temp_dir();
    let db = dir.join("cams.db");
    let db = db.to_str().unwrap();
    let a = Server::start_with(db, &[]);
    assert_eq!(post(&a, "/api/v1/cam-tables", polynom5()).await.status, 201);
    // A million rows (spec: uploads as JSON, built off the cycle thread).
    let rows: Vec<Value> = (0..1_000_000)
        .map(|i| json!([i as f64 * 0.00036, (i as f64 * 0.00036).to_radians().sin()]))
        .collect();
    let big = json!({"name": "big", "table_type": "equidistant", "periodic": true, "interpolation": "spline", "rows": rows});
    let r = post(&a, "/api/v1/cam-tables", big).await;
    assert_eq!(
        (r.status, r.json["row_count"].as_u64()),
        (201, Some(1_000_000)),
        "{}",
        r.text
    );
    let before = get(&a, "/api/v1/cam-tables").await;
    let exported = get(&a, "/api/v1/config").await;
    assert_eq!(exported.json["cam_tables"].as_array().unwrap().len(), 2);
    a.stop();

    let a = Server::start_with(db, &[]);
    assert_eq!(get(&a, "/api/v1/cam-tables").await.json, before.json);
    let d = get(
        &a,
        "/api/v1/cam-tables/big/slave-dynamics?master_position=90",
    )
    .await;
    assert!(close(&d.json["slave_position"], 1.0), "{}", d.text);
    a.stop();

    let dir = temp_dir();
    let db2 = dir.join("fresh.db");
    let b = Server::start_with(db2.to_str().unwrap(), &[]);
    let r = put(&b, "/api/v1/config", exported.json.clone()).await;
    assert_eq!(r.status, 200, "{}", &r.text[..r.text.len().min(500)]);
    let names: Vec<String> = get(&b, "/api/v1/cam-tables")
        .await
        .json
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t["name"].as_str().unwrap().to_string())
        .collect();
    assert_eq!(names, ["p5", "big"]);
    let mut without = exported.json.clone();
    without.as_object_mut().unwrap().remove("cam_tables");
    assert_eq!(put(&b, "/api/v1/config", without).await.status, 200);
    assert_eq!(
        get(&b, "/api/v1/cam-tables")
            .await
            .json
            .as_array()
            .unwrap()
            .len(),
        2,
        "kept"
    );
    let mut bad = exported.json.clone();
    bad["cam_tables"][0]["points"][0]["point_type"] = json!("ignore");
    let r = put(&b, "/api/v1/config", bad).await;
    assert_eq!(
        (r.status, r.json["errors"][0]["field"].as_str()),
        (422, Some("cam_tables[0].points[0].point_type")),
        "{}",
        r.text
    );
    let mut none = exported.json.clone();
    none["cam_tables"] = json!([]);
    assert_eq!(put(&b, "/api/v1/config", none).await.status, 200);
    assert_eq!(get(&b, "/api/v1/cam-tables").await.json, json!([]));
}

/// The README's cam tour: upload, couple `y` to `x`, move `x`, read the slave (MC_CamInfo in
/// its status); a coupled table cannot be replaced or deleted; after a restart the table is
/// there and the coupling is not (couplings end with the process).
#[tokio::test(flavor = "multi_thread")]
async fn a_cam_couples_y_to_x_over_http_and_only_the_table_survives_a_restart() {
    let dir = temp_dir();
    let db = dir.join("couple.db");
    let db = db.to_str().unwrap();
    let s = Server::start_with(db, &[]);
    assert_eq!(post(&s, "/api/v1/cam-tables", polynom5()).await.status, 201);
    power_on(&s, "x").await;
    power_on(&s, "y").await;
    // Not at the cam's position: refused, nothing coupled.
    let r = post(
        &s,
        "/api/v1/axes/x/move-absolute?wait=true",
        json!({"position": 100.0, "velocity": 200.0}),
    )
    .await;
    assert_eq!(r.status, 202, "{}", r.text);
    let r = post(
        &s,
        "/api/v1/axes/y/cam-in",
        json!({"master": "x", "cam_table": "p5"}),
    )
    .await;
    assert_eq!(
        (r.status, r.json["code"].as_str()),
        (409, Some("cam_slave_would_jump")),
        "{}",
        r.text
    );
    let r = post(
        &s,
        "/api/v1/axes/x/move-absolute?wait=true",
        json!({"position": 0.0, "velocity": 200.0}),
    )
    .await;
    assert_eq!(r.status, 202);
    let r = post(
        &s,
        "/api/v1/axes/y/cam-in?wait=true",
        json!({"master": "x", "cam_table": "p5"}),
    )
    .await;
    assert_eq!(r.status, 202, "{}", r.text);
    assert_eq!(r.json["outputs"]["in_sync"], true, "{}", r.text);
    assert_eq!(r.json["final"], true);
    let r = post(
        &s,
        "/api/v1/axes/x/move-absolute?wait=true",
        json!({"position": 150.0, "velocity": 200.0}),
    )
    .await;
    assert_eq!(r.json["outputs"]["done"], true, "{}", r.text);
    let y = status(&s, "y").await;
    assert!(close(&y["status"]["set_position"], 89.6484375), "{y}");
    assert_eq!(y["status"]["state"], "synchronized_motion");
    let cam = &y["status"]["cam"];
    assert_eq!(cam["cam_table_id"], 1);
    assert!(
        close(&cam["actual_master_cam_pos"], 150.0)
            && close(&cam["actual_slave_cam_pos"], 89.6484375),
        "{cam}"
    );
    // MC_CamInfo now and as it would be with x at 50.
    let info = get(&s, "/api/v1/axes/y/cam-info").await;
    assert_eq!(
        (info.status, info.json["active"].as_bool()),
        (200, Some(true)),
        "{}",
        info.text
    );
    let at = get(&s, "/api/v1/axes/y/cam-info?master_position=50").await;
    assert!(
        close(&at.json["actual_slave_axis_pos"], 10.3515625),
        "{}",
        at.text
    );
    assert!(close(&at.json["actual_master_cam_pos"], 50.0));
    let r = get(&s, "/api/v1/axes/x/cam-info").await;
    assert_eq!(
        (r.status, r.json["code"].as_str()),
        (409, Some("cam_not_coupled"))
    );
    // New data for the coupled table: an online change (here the same data: it takes effect
    // at once, nothing moves); one point written changes the slave only where it may.
    let r = put(&s, "/api/v1/cam-tables/p5", polynom5()).await;
    assert_eq!(
        (r.status, r.json["version"].as_i64()),
        (200, Some(2)),
        "{}",
        r.text
    );
    let mode = json!({"activation_mode": "next_cycle", "master_scaling_mode": "user_defined",
        "slave_scaling_mode": "user_defined", "activation_position": 0.0});
    let r = put(&s, "/api/v1/cam-tables/p5/online-change-mode", mode.clone()).await;
    assert_eq!((r.status, &r.json), (200, &mode), "{}", r.text);
    let mut point = polynom5()["points"][1].clone();
    point["slave_pos"] = json!(120.0);
    let r = put(&s, "/api/v1/cam-tables/p5/points/2", point.clone()).await;
    assert_eq!(
        (r.status, r.json["slave_end"].as_f64()),
        (200, Some(120.0)),
        "{}",
        r.text
    );
    assert_eq!(
        get(&s, "/api/v1/cam-tables/p5/points/2").await.json["slave_pos"],
        120.0
    );
    // A linear cam has no next cycle at x = 150: the data waits (cam_data_queued), the slave
    // stays where it is; a second write while it waits is refused.
    let y = status(&s, "y").await;
    assert_eq!(y["status"]["cam_data_queued"], true, "{y}");
    assert!(close(&y["status"]["set_position"], 89.6484375));
    let r = put(
        &s,
        "/api/v1/cam-tables/p5/points",
        json!({"points": [point]}),
    )
    .await;
    assert_eq!(
        (r.status, r.json["code"].as_str()),
        (409, Some("cam_change_pending")),
        "{}",
        r.text
    );
    let r = put(
        &s,
        "/api/v1/cam-tables/p5/online-change-mode",
        json!({"activation_mode": "delete_queued_data"}),
    )
    .await;
    assert_eq!(r.json["activation_mode"], "next_cycle", "{}", r.text);
    assert_eq!(status(&s, "y").await["status"]["cam_data_queued"], false);
    assert_eq!(get(&s, "/api/v1/cam-tables/p5/points/9").await.status, 404);
    let r = delete(&s, "/api/v1/cam-tables/p5").await;
    assert_eq!(
        (r.status, r.json["code"].as_str()),
        (409, Some("cam_table_in_use"))
    );
    // A scaling with autooffset keeps the slave where it is.
    let r = post(&s, "/api/v1/axes/y/cam-scaling?wait=true", json!({"slave_scaling": 2.0, "slave_scaling_mode": "auto_offset", "master_scaling_mode": "off"})).await;
    assert_eq!(r.json["outputs"]["done"], true, "{}", r.text);
    assert!(close(
        &status(&s, "y").await["status"]["set_position"],
        89.6484375
    ));
    assert_eq!(
        post(&s, "/api/v1/axes/y/cam-out", json!({})).await.status,
        202
    );
    assert_eq!(status(&s, "y").await["status"]["cam"]["cam_table_id"], 0);
    assert_eq!(
        put(&s, "/api/v1/cam-tables/p5", polynom5()).await.status,
        200,
        "free again"
    );
    s.stop();

    let s = Server::start_with(db, &[]);
    assert_eq!(get(&s, "/api/v1/cam-tables/p5").await.json["version"], 4);
    let y = status(&s, "y").await;
    assert_eq!(y["status"]["coupled"], false);
    assert_eq!(y["status"]["cam"]["cam_table_id"], 0);
}

/// Multi-cam over HTTP: cam-in-v2 couples, cam-add superimposes a second cam (relative
/// slave), the status lists both, cam-remove takes it off (Done), cam-in does not mix in.
#[tokio::test(flavor = "multi_thread")]
async fn multi_cam_over_http() {
    let s = Server::start();
    let line = json!({"name": "line", "table_type": "equidistant", "periodic": true, "rows": [[0.0, 0.0], [360.0, 360.0]]});
    let wave = json!({"name": "wave", "table_type": "motion_function", "periodic": true, "points": [
        {"point_index": 1, "function_type": "polynom5", "point_type": "rest", "master_pos": 0.0, "slave_pos": 0.0},
        {"point_index": 2, "function_type": "polynom5", "point_type": "rest", "master_pos": 180.0, "slave_pos": 5.0},
        {"point_index": 3, "function_type": "polynom5", "point_type": "rest", "master_pos": 360.0, "slave_pos": 0.0}]});
    assert_eq!(post(&s, "/api/v1/cam-tables", line).await.status, 201);
    assert_eq!(post(&s, "/api/v1/cam-tables", wave).await.status, 201);
    power_on(&s, "x").await;
    power_on(&s, "y").await;
    let r = post(
        &s,
        "/api/v1/axes/y/cam-in-v2?wait=true",
        json!({"master": "x", "cam_table": "line"}),
    )
    .await;
    assert_eq!(r.json["outputs"]["in_sync"], true, "{}", r.text);
    let r = post(
        &s,
        "/api/v1/axes/y/cam-add?wait=true",
        json!({"master": "x", "cam_table": "wave", "scaling": {"slave_relative": true}}),
    )
    .await;
    assert_eq!(
        (
            r.status,
            r.json["command"].as_str(),
            r.json["outputs"]["in_sync"].as_bool()
        ),
        (202, Some("cam-add"), Some(true)),
        "{}",
        r.text
    );
    let r = post(
        &s,
        "/api/v1/axes/y/cam-in",
        json!({"master": "x", "cam_table": "line"}),
    )
    .await;
    assert_eq!(
        (r.status, r.json["code"].as_str()),
        (409, Some("cam_family_mixed")),
        "{}",
        r.text
    );
    let r = post(
        &s,
        "/api/v1/axes/x/move-absolute?wait=true",
        json!({"position": 180.0, "velocity": 300.0}),
    )
    .await;
    assert_eq!(r.json["outputs"]["done"], true);
    let y = status(&s, "y").await;
    assert!(close(&y["status"]["set_position"], 185.0), "{y}");
    assert_eq!(y["status"]["cam"]["multi_cam"], true);
    assert_eq!(y["status"]["cam"]["cams"][1]["cam_table_id"], 2);
    assert!(close(
        &y["status"]["cam"]["cams"][1]["slave_contribution"],
        5.0
    ));
    let r = post(
        &s,
        "/api/v1/axes/y/cam-remove?wait=true",
        json!({"master": "x", "cam_table": "wave"}),
    )
    .await;
    assert_eq!(r.json["outputs"]["done"], true, "{}", r.text);
    assert!(
        close(&status(&s, "y").await["status"]["set_position"], 185.0),
        "the position stays"
    );
    let r = post(
        &s,
        "/api/v1/axes/y/cam-remove",
        json!({"master": "x", "cam_table": "line"}),
    )
    .await;
    assert_eq!(
        (r.status, r.json["code"].as_str()),
        (409, Some("cam_mode_invalid")),
        "the last cam goes with cam-out"
    );
}

/// `ST_CamInOptions.InterpolationType` over HTTP: a coupling may interpolate a stored linear
/// table with a spline of its own; MC_CamInfo says which and predicts with it; 4POINT is a
/// 422 at `interpolation` and couples nothing.
#[tokio::test(flavor = "multi_thread")]
async fn a_coupling_chooses_its_own_interpolation() {
    let s = Server::start();
    let table = json!({"name": "bent", "table_type": "equidistant", "periodic": true,
        "rows": [[0.0, 0.0], [90.0, 60.0], [180.0, 180.0], [270.0, 300.0], [360.0, 360.0]]});
    let r = post(&s, "/api/v1/cam-tables", table).await;
    assert_eq!(r.status, 201, "{}", r.text);
    assert_eq!(r.json["interpolation"], "linear", "{}", r.text);
    power_on(&s, "x").await;
    power_on(&s, "y").await;
    let r = post(
        &s,
        "/api/v1/axes/y/cam-in",
        json!({"master": "x", "cam_table": "bent", "interpolation": "4point"}),
    )
    .await;
    assert_eq!(r.field_error(), (422, Some("interpolation")), "{}", r.text);
    assert_eq!(status(&s, "y").await["status"]["state"], "standstill");
    let r = post(
        &s,
        "/api/v1/axes/y/cam-in?wait=true",
        json!({"master": "x", "cam_table": "bent", "interpolation": "spline"}),
    )
    .await;
    assert_eq!(r.status, 202, "{}", r.text);
    assert_eq!(r.json["outputs"]["in_sync"], true, "{}", r.text);
    let r = post(
        &s,
        "/api/v1/axes/x/move-absolute?wait=true",
        json!({"position": 45.0, "velocity": 200.0}),
    )
    .await;
    assert_eq!(r.json["outputs"]["done"], true, "{}", r.text);
    let y = status(&s, "y").await;
    let at = y["status"]["set_position"].as_f64().unwrap();
    // The table's own (linear) interpolation would put y at 30 here.
    assert!((at - 30.0).abs() > 0.5, "y at {at}: linear, not the spline");
    assert_eq!(
        y["status"]["cam"]["cams"][0]["interpolation"], "spline",
        "{y}"
    );
    let info = get(&s, "/api/v1/axes/y/cam-info?master_position=45").await;
    assert!(
        close(&info.json["actual_slave_axis_pos"], at),
        "{}",
        info.text
    );
}

/// PLCopen ramp-in over HTTP: a slave away from its cam is refused with `absolute` and caught
/// up with `ramp_in`; `?wait=true` answers at InSync, with the slave on the cam. A ramp-in
/// without its velocity is a 422 at `ramp_in.velocity`.
#[tokio::test(flavor = "multi_thread")]
async fn a_ramp_in_couples_a_slave_away_from_its_cam() {
    let s = Server::start();
    assert_eq!(post(&s, "/api/v1/cam-tables", polynom5()).await.status, 201);
    power_on(&s, "x").await;
    power_on(&s, "y").await;
    let r = post(
        &s,
        "/api/v1/axes/y/move-absolute?wait=true",
        json!({"position": 30.0, "velocity": 200.0}),
    )
    .await;
    assert_eq!(r.json["outputs"]["done"], true, "{}", r.text);
    let r = post(
        &s,
        "/api/v1/axes/y/cam-in",
        json!({"master": "x", "cam_table": "p5", "start_mode": "ramp_in"}),
    )
    .await;
    assert_eq!(
        r.field_error(),
        (422, Some("ramp_in.velocity")),
        "{}",
        r.text
    );
    let r = post(
        &s,
        "/api/v1/axes/y/cam-in",
        json!({"master": "x", "cam_table": "p5", "ramp_in": {"velocity": 50.0}}),
    )
    .await;
    assert_eq!(r.field_error(), (422, Some("ramp_in")), "{}", r.text);
    assert_eq!(status(&s, "y").await["status"]["state"], "standstill");
    let r = post(
        &s,
        "/api/v1/axes/y/cam-in?wait=true",
        json!({"master": "x", "cam_table": "p5", "start_mode": "ramp_in",
               "ramp_in": {"velocity": 50.0, "acceleration": 500.0}}),
    )
    .await;
    assert_eq!(r.status, 202, "{}", r.text);
    assert_eq!(r.json["outputs"]["in_sync"], true, "{}", r.text);
    let y = status(&s, "y").await;
    assert!(close(&y["status"]["set_position"], 0.0), "{y}");
    assert_eq!(y["status"]["state"], "synchronized_motion");
}

/// `POST /cam-analysis` (issue 12, the cam editor's live plots): an unsaved table is analysed
/// by the server's cam math — range, samples with both ends, characteristics equal to a stored
/// table's, the jumps where a law meets a MOTION point — with the errors a store would give at
/// the same fields, and nothing is stored.
#[tokio::test(flavor = "multi_thread")]
async fn an_unsaved_table_is_analysed_and_nothing_is_stored() {
    let s = Server::start();
    let a = post(&s, "/api/v1/cam-analysis?samples=5", polynom5()).await;
    assert_eq!(a.status, 200, "{}", a.text);
    assert_eq!(
        (
            a.json["master_start"].as_f64(),
            a.json["master_end"].as_f64()
        ),
        (Some(0.0), Some(200.0))
    );
    let rows = a.json["values"]["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 5);
    assert_eq!(
        rows[1],
        json!([50.0, 10.3515625, 0.52734375, 0.0140625, -0.00009375])
    );
    assert_eq!(rows[4][0], 200.0, "the last sample at the end");
    assert!(
        close(&a.json["characteristics"]["slave_velo_max"], 0.9375),
        "{}",
        a.text
    );
    assert_eq!(a.json["discontinuities"], json!([]));
    assert_eq!(
        get(&s, "/api/v1/cam-tables").await.json,
        json!([]),
        "nothing stored"
    );

    let jumpy = json!({"name": "jumpy", "table_type": "motion_function", "points": [
        {"point_index": 1, "function_type": "polynom5", "point_type": "rest", "master_pos": 0.0, "slave_pos": 0.0},
        {"point_index": 2, "function_type": "polynom1", "point_type": "motion", "master_pos": 100.0, "slave_pos": 50.0},
        {"point_index": 3, "function_type": "polynom5", "point_type": "motion", "master_pos": 200.0, "slave_pos": 150.0},
        {"point_index": 4, "function_type": "polynom5", "point_type": "rest", "master_pos": 360.0, "slave_pos": 0.0}]});
    let a = post(&s, "/api/v1/cam-analysis", jumpy.clone()).await;
    assert_eq!(a.status, 200, "{}", a.text);
    assert_eq!(
        a.json["values"]["rows"].as_array().unwrap().len(),
        721,
        "the default"
    );
    let d = a.json["discontinuities"].as_array().unwrap();
    assert!(
        d.iter()
            .any(|j| j["index"] == 1 && j["quantity"] == "velocity" && close(&j["after"], 1.0)),
        "{}",
        a.text
    );

    // The errors of a store, at the same field; a bad sample count at `samples`.
    let mut bad = jumpy.clone();
    bad["points"][1]["point_type"] = json!("rest");
    let r = post(&s, "/api/v1/cam-analysis", bad.clone()).await;
    let put = post(&s, "/api/v1/cam-tables", bad).await;
    assert_eq!((r.status, put.status), (422, 422), "{}", r.text);
    assert_eq!(r.json["errors"], put.json["errors"], "{}", r.text);
    assert_eq!(
        r.json["errors"][0]["field"], "points[1].point_type",
        "{}",
        r.text
    );
    let r = post(&s, "/api/v1/cam-analysis?samples=1", jumpy).await;
    assert_eq!(r.status, 422, "{}", r.text);
    assert_eq!(r.json["errors"][0]["field"], "samples", "{}", r.text);
    assert_eq!(
        get(&s, "/api/v1/cam-tables").await.json,
        json!([]),
        "nothing stored"
    );
}

/// Decision 174 over HTTP: a cam-in to another master that would wait for its activation, on
/// a slave coupled to x, is refused (409 master_invalid) with what to do, and the slave goes
/// on following x.
#[tokio::test(flavor = "multi_thread")]
async fn a_coupled_slave_refuses_to_wait_on_another_master() {
    let s = Server::start();
    assert_eq!(post(&s, "/api/v1/cam-tables", polynom5()).await.status, 201);
    for a in ["x", "y", "spindle"] {
        power_on(&s, a).await;
    }
    let r = post(
        &s,
        "/api/v1/axes/y/cam-in?wait=true",
        json!({"master": "x", "cam_table": "p5"}),
    )
    .await;
    assert_eq!(r.json["outputs"]["in_sync"], true, "{}", r.text);
    let r = post(
        &s,
        "/api/v1/axes/y/cam-in",
        json!({"master": "spindle", "cam_table": "p5",
               "activation_mode": "at_master_axis_pos", "activation_position": 100.0}),
    )
    .await;
    assert_eq!(
        (r.status, r.json["code"].as_str()),
        (409, Some("master_invalid")),
        "{}",
        r.text
    );
    let detail = r.json["detail"].as_str().unwrap_or_default();
    assert!(
        detail.contains("the slave follows x") && detail.contains("instantaneous"),
        "{detail}"
    );
    let y = status(&s, "y").await;
    assert_eq!(y["status"]["state"], "synchronized_motion", "{y}");
    assert_eq!(y["status"]["master"], "x", "{y}");
    assert_eq!(y["status"]["cam"]["cam_table_id"], 1, "{y}");
}
