//! Error responses for the OpenAPI document.

use utoipa::IntoResponses;

use crate::error::Problem;

#[allow(dead_code)]
#[derive(IntoResponses)]
pub enum CommandErrors {
    /// The body is not JSON.
    #[response(status = 400, content_type = "application/problem+json",
        example = json!({"type": "urn:motiond:problem:malformed_json", "title": "Malformed JSON", "status": 400,
                         "detail": "expected value at line 1 column 2", "code": "malformed_json"}))]
    BadJson(Problem),
    /// No such axis.
    #[response(status = 404, content_type = "application/problem+json",
        example = json!({"type": "urn:motiond:problem:axis_not_found", "title": "Not found", "status": 404,
                         "detail": "no axis 'z'", "code": "axis_not_found"}))]
    NotFound(Problem),
    /// Rejected by the axis (wrong state, buffer full …); `error_id` is the PLCopen ErrorID.
    #[response(status = 409, content_type = "application/problem+json",
        example = json!({"type": "urn:motiond:problem:axis_cannot_be_started", "title": "Command rejected by the axis",
                         "status": 409, "detail": "axis cannot be started in its current state",
                         "code": "axis_cannot_be_started", "error_id": 19201}))]
    Rejected(Problem),
    /// Invalid parameters (wrong type, unknown field, out of range); no command is kept.
    #[response(status = 422, content_type = "application/problem+json",
        example = json!({"type": "urn:motiond:problem:validation_failed", "title": "Invalid request", "status": 422,
                         "detail": "velocity: must be > 0", "code": "validation_failed",
                         "errors": [{"field": "velocity", "message": "must be > 0"}]}))]
    Invalid(Problem),
    /// The cycle thread or the database is not available.
    #[response(status = 503, content_type = "application/problem+json",
        example = json!({"type": "urn:motiond:problem:command_queue_full", "title": "Service unavailable", "status": 503,
                         "detail": "the command queue to the cycle thread is full; try again", "code": "command_queue_full"}))]
    Unavailable(Problem),
}

#[allow(dead_code)]
#[derive(IntoResponses)]
pub enum ConfigErrors {
    /// The body is not JSON.
    #[response(status = 400, content_type = "application/problem+json")]
    BadJson(Problem),
    /// No such axis or parameter.
    #[response(status = 404, content_type = "application/problem+json",
        example = json!({"type": "urn:motiond:problem:axis_not_found", "title": "Not found", "status": 404,
                         "detail": "no axis 'z'", "code": "axis_not_found"}))]
    NotFound(Problem),
    /// The axis is not disabled, or the name is taken.
    #[response(status = 409, content_type = "application/problem+json",
        example = json!({"type": "urn:motiond:problem:axis_not_disabled", "title": "Conflict", "status": 409,
                         "detail": "axis 'x' is not disabled: switch it off (DELETE its power command) first",
                         "code": "axis_not_disabled"}))]
    Conflict(Problem),
    /// The configuration is invalid; `errors` lists every invalid field.
    #[response(status = 422, content_type = "application/problem+json",
        example = json!({"type": "urn:motiond:problem:validation_failed", "title": "Invalid request", "status": 422,
                         "detail": "dynamics.jerk: must be a finite number > 0", "code": "validation_failed",
                         "errors": [{"field": "dynamics.jerk", "message": "must be a finite number > 0"}]}))]
    Invalid(Problem),
    /// The database did not accept the write (locked, full, I/O error); nothing was changed.
    #[response(status = 503, content_type = "application/problem+json",
        example = json!({"type": "urn:motiond:problem:storage_unavailable", "title": "Service unavailable", "status": 503,
                         "detail": "the database did not accept the write: database is locked", "code": "storage_unavailable"}))]
    Unavailable(Problem),
}

#[allow(dead_code)]
#[derive(IntoResponses)]
pub enum ReadErrors {
    /// No such resource.
    #[response(status = 404, content_type = "application/problem+json",
        example = json!({"type": "urn:motiond:problem:axis_not_found", "title": "Not found", "status": 404,
                         "detail": "no axis 'z'", "code": "axis_not_found"}))]
    NotFound(Problem),
}

#[allow(dead_code)]
#[derive(IntoResponses)]
pub enum FaultErrors {
    /// The body is not JSON.
    #[response(status = 400, content_type = "application/problem+json")]
    BadJson(Problem),
    /// No such axis.
    #[response(status = 404, content_type = "application/problem+json",
        example = json!({"type": "urn:motiond:problem:axis_not_found", "title": "Not found", "status": 404,
                         "detail": "no axis 'z'", "code": "axis_not_found"}))]
    NotFound(Problem),
    /// Not a fault: unknown `kind`, missing or wrong fields.
    #[response(status = 422, content_type = "application/problem+json",
        example = json!({"type": "urn:motiond:problem:validation_failed", "title": "Invalid request", "status": 422,
                         "detail": "body: unknown variant `meltdown`, expected one of `drive_fault`, `load`, `limit_switch`, `clear`",
                         "code": "validation_failed",
                         "errors": [{"field": "body", "message": "unknown variant `meltdown`, expected one of `drive_fault`, `load`, `limit_switch`, `clear`"}]}))]
    Invalid(Problem),
    /// The cycle thread is not available.
    #[response(status = 503, content_type = "application/problem+json")]
    Unavailable(Problem),
}
