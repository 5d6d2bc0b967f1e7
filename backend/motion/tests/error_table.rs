//! docs/errors.md is the one documented table of error numbers; it must list exactly what
//! the kernel reports. Regenerate with `MOTION_WRITE_DOCS=1 cargo test -p motion --test error_table`.

use motion::ErrorId;

fn table() -> String {
    let mut s = String::from(
        "# Error numbers\n\n\
         Every error a command or an axis can report, with its number (`error_id`, as in an FB's\n\
         `ErrorID` output) and its stable `code` (problem+json). Numbers below 0x7000 are\n\
         TwinCAT's own for the same condition; 0x7000 and up are motiond's. Generated from\n\
         `backend/motion/src/error.rs` by `backend/motion/tests/error_table.rs`.\n\n\
         | error_id | hex | code | meaning |\n|---:|---|---|---|\n",
    );
    for e in ErrorId::ALL {
        s.push_str(&format!(
            "| {} | 0x{:04X} | `{}` | {} |\n",
            e.0,
            e.0,
            e.code(),
            e.text()
        ));
    }
    s
}

#[test]
fn docs_errors_md_lists_every_error_number() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/errors.md");
    let want = table();
    if std::env::var_os("MOTION_WRITE_DOCS").is_some() {
        std::fs::write(path, &want).unwrap();
    }
    let have = std::fs::read_to_string(path).unwrap_or_default();
    assert!(
        have == want,
        "docs/errors.md is stale: run MOTION_WRITE_DOCS=1 cargo test -p motion --test error_table"
    );
}
