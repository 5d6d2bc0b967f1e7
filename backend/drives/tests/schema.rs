//! OpenAPI schemas of the drive configuration and fault injection (feature `schema`).
#![cfg(feature = "schema")]

use drives::sim::{SimDriveConfig, SimFault};
use utoipa::PartialSchema;

#[test]
fn schemas_name_the_json_fields_and_tags() {
    let config = serde_json::to_string(&SimDriveConfig::schema()).unwrap();
    for field in [
        "plant",
        "dead_time",
        "velocity_feed_forward",
        "reference_cam",
        "index_pulse",
        "limit_switches",
        "pt2",
        "natural_frequency_hz",
    ] {
        assert!(config.contains(field), "{field} missing in {config}");
    }
    let fault = serde_json::to_string(&SimFault::schema()).unwrap();
    for field in ["drive_fault", "load", "limit_switch", "clear", "kind"] {
        assert!(fault.contains(field), "{field} missing in {fault}");
    }
}
