//! The scenario folder (`scenarios/*.json`, issue 26): a data-driven PLCopen acceptance set run
//! by `motiond scenario run` in virtual time.

mod common;

use common::bin;

fn scenario_files() -> Vec<std::path::PathBuf> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.extension().is_some_and(|e| e == "json")
                && !p.file_name().unwrap().to_string_lossy().contains("schema")
        })
        .collect();
    files.sort();
    files
}

#[test]
fn every_scenario_of_the_folder_passes() {
    let files = scenario_files();
    assert!(files.len() >= 8, "{files:?}");
    let out = bin()
        .arg("scenario")
        .arg("run")
        .args(&files)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(text.matches("PASS ").count(), files.len(), "{text}");
}

#[test]
fn a_scenario_run_twice_writes_the_same_scope_csv_byte_for_byte() {
    let dir = common::temp_dir();
    let file =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenarios/fault-and-reset.json");
    let mut csv = Vec::new();
    for n in 0..2 {
        let out_file = dir.join(format!("run{n}.csv"));
        let mut sc: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
        // The fault scenario with the scope on x's set and actual position and following error.
        sc["scope"] = serde_json::json!({"channels": [
            {"axis": "x", "signal": "set_position"}, {"axis": "x", "signal": "actual_position"},
            {"axis": "x", "signal": "following_error"}], "duration_s": 2.5});
        let f = dir.join("fault.json");
        std::fs::write(&f, sc.to_string()).unwrap();
        let out = bin()
            .args(["scenario", "run"])
            .arg(&f)
            .arg("--csv")
            .arg(&out_file)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        csv.push(std::fs::read(&out_file).unwrap());
    }
    assert!(csv[0].len() > 50_000, "{}", csv[0].len());
    assert!(csv[0] == csv[1], "the two runs' CSV differ");
}

#[test]
fn a_failed_expectation_ends_the_run_with_what_where_expected_and_got() {
    let dir = common::temp_dir();
    let f = dir.join("wrong.json");
    std::fs::write(
        &f,
        r#"{"name": "a wrong expectation", "steps": [
            {"request": "POST /axes/x/power", "body": {}, "as": "power"},
            {"when": {"command": "power"}},
            {"request": "POST /axes/x/move-absolute", "body": {"position": 10, "velocity": 10}, "as": "m"},
            {"when": {"command": "m"}, "note": "where it ends",
             "expect": [{"axis": "x", "field": "set_position", "value": 11, "tolerance": 0.001}]},
            {"after_cycles": 10, "expect": [{"axis": "x", "field": "state", "equals": "nowhere"}]}]}"#,
    )
    .unwrap();
    let out = bin().args(["scenario", "run"]).arg(&f).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("FAIL") && err.contains("a wrong expectation"),
        "{err}"
    );
    assert!(err.contains("step 4 (where it ends) at cycle"), "{err}");
    assert!(
        err.contains("axis x.set_position: expected 11 ± 0.001, got 10"),
        "{err}"
    );
    // An unknown field in the file is refused before anything runs.
    std::fs::write(
        &f,
        r#"{"name": "x", "steps": [{"at": 1, "requets": "GET /axes"}]}"#,
    )
    .unwrap();
    let out = bin().args(["scenario", "run"]).arg(&f).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("unknown field `requets`"), "{err}");
}

#[test]
fn the_committed_scenario_schema_is_current() {
    let out = bin().args(["scenario", "schema"]).output().unwrap();
    let committed = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("scenarios/schema/scenario.schema.json"),
    )
    .unwrap();
    assert_eq!(
        String::from_utf8_lossy(&out.stdout),
        committed,
        "regenerate: motiond scenario schema > scenarios/schema/scenario.schema.json"
    );
    let schema: serde_json::Value = serde_json::from_str(&committed).unwrap();
    assert_eq!(schema["$ref"], "#/$defs/Scenario");
    assert!(schema["$defs"]["Step"]["properties"]["when"].is_object());
}
