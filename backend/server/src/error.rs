//! The one error type of the server, [`AppError`]: what went wrong, as the service layer knows
//! it. It becomes RFC 9457 problem+json only at the edge ([`AppError::problem`], used by the
//! REST responses and by the websocket's JSON-RPC errors), so no layer reads a problem back.

use std::fmt;

use axum::http::{HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};
use motion::ErrorId;
use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

/// One invalid field of a configuration.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize, ToSchema)]
pub struct FieldError {
    /// JSON path of the field, e.g. `plant.time_constant`.
    pub field: String,
    pub message: String,
}

impl std::fmt::Display for FieldError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.field, self.message)
    }
}

impl std::error::Error for FieldError {}

/// `application/problem+json` body.
#[derive(Clone, Debug, Serialize, ToSchema)]
#[schema(example = json!({
    "type": "urn:motiond:problem:axis_cannot_be_started", "title": "Command rejected by the axis",
    "status": 409, "detail": "axis cannot be started in its current state", "code": "axis_cannot_be_started",
    "error_id": 19201
}))]
pub struct Problem {
    #[serde(rename = "type")]
    pub type_: String,
    pub title: String,
    pub status: u16,
    pub detail: String,
    /// Stable snake_case code.
    pub code: String,
    /// The kernel's error number (PLCopen ErrorID), when there is one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error_id: Option<u32>,
    /// Invalid fields (422).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub errors: Vec<FieldError>,
}

/// Everything a request can fail with.
#[derive(Debug)]
pub enum AppError {
    /// 404 `{what}_not_found`: no such axis, command, recording, parameter …
    NotFound { what: &'static str, key: String },
    /// 422 `validation_failed`: the fields at fault.
    Invalid(Vec<FieldError>),
    /// 422 `validation_failed` for one field whose value the kernel's parameter table refuses,
    /// with the kernel's error number.
    Refused {
        field: std::borrow::Cow<'static, str>,
        message: String,
        id: ErrorId,
    },
    /// 422 `validation_failed`: the fields at fault, one of them a condition with a number of
    /// its own (a cam table id out of 1..255 is 0x4B32) given as `error_id`.
    InvalidNumbered {
        errors: Vec<FieldError>,
        id: ErrorId,
    },
    /// 422 with the error's own code (`transition_mode_invalid` …): a value the kernel's rules
    /// refuse before anything is submitted (a path entry), the field at fault named.
    InvalidCoded {
        errors: Vec<FieldError>,
        id: ErrorId,
    },
    /// 409: the axis refused the command (its PLCopen ErrorID is the code).
    Rejected(ErrorId),
    /// 409: the axis refused the command, with what was in the way (the axis state, its error,
    /// the stop lock …) and what to do, after the error's own text.
    RejectedBecause { id: ErrorId, why: String },
    /// A kernel error number under another status or title (an axis the cycle thread did not
    /// take …).
    Kernel {
        status: StatusCode,
        title: &'static str,
        id: ErrorId,
    },
    /// 409: a rule of the service (name taken, no free slot, scope busy, axis not disabled …).
    Conflict { code: &'static str, detail: String },
    /// 503: the cycle thread, the queue, the history or the scope cannot serve it now.
    Unavailable { code: &'static str, detail: String },
    /// 503 `storage_unavailable`: the database did not take the write; nothing was changed.
    Storage(String),
    /// 400 `malformed_json`.
    BadJson(String),
    /// 413 `payload_too_large`.
    TooLarge { limit: usize },
    /// 405 `method_not_allowed` (the `Allow` header is axum's).
    MethodNotAllowed { method: String, path: String },
    /// 403 `cross_origin_forbidden`: a state-changing request from another web origin.
    CrossOrigin(String),
    /// 415 `unsupported_media_type`: a state-changing request not declared JSON.
    UnsupportedMediaType(String),
    /// 421 `misdirected_request`: a Host motiond does not serve (DNS rebinding).
    Misdirected(String),
    /// Any other HTTP-level problem (route not found, websocket handshake, axum's own answers).
    Http {
        status: StatusCode,
        code: String,
        title: String,
        detail: String,
    },
}

impl AppError {
    pub fn new(status: StatusCode, code: &str, title: &str, detail: impl Into<String>) -> Self {
        AppError::Http {
            status,
            code: code.into(),
            title: title.into(),
            detail: detail.into(),
        }
    }
    pub fn not_found(what: &'static str, key: &str) -> Self {
        AppError::NotFound {
            what,
            key: key.into(),
        }
    }
    pub fn bad_json(detail: impl Into<String>) -> Self {
        AppError::BadJson(detail.into())
    }
    /// A body over the limit (axum's rejection would be plain text).
    pub fn too_large(limit: usize) -> Self {
        AppError::TooLarge { limit }
    }
    pub fn method_not_allowed(method: &str, path: &str) -> Self {
        AppError::MethodNotAllowed {
            method: method.into(),
            path: path.into(),
        }
    }
    pub fn cross_origin(detail: impl Into<String>) -> Self {
        AppError::CrossOrigin(detail.into())
    }
    pub fn unsupported_media_type(detail: impl Into<String>) -> Self {
        AppError::UnsupportedMediaType(detail.into())
    }
    pub fn misdirected(detail: impl Into<String>) -> Self {
        AppError::Misdirected(detail.into())
    }
    pub fn invalid(errors: Vec<FieldError>) -> Self {
        AppError::Invalid(errors)
    }
    pub fn field(field: &str, message: &str) -> Self {
        AppError::Invalid(vec![FieldError {
            field: field.into(),
            message: message.into(),
        }])
    }
    /// A kernel error number with its HTTP status.
    pub fn kernel(status: StatusCode, title: &'static str, id: ErrorId) -> Self {
        AppError::Kernel { status, title, id }
    }
    pub fn rejected(id: ErrorId) -> Self {
        AppError::Rejected(id)
    }
    /// A value the kernel's parameter table refuses: a 422 on `field` with the error number.
    pub fn refused(
        field: impl Into<std::borrow::Cow<'static, str>>,
        id: ErrorId,
        message: impl Into<String>,
    ) -> Self {
        AppError::Refused {
            field: field.into(),
            message: message.into(),
            id,
        }
    }
    pub fn conflict(code: &'static str, detail: impl Into<String>) -> Self {
        AppError::Conflict {
            code,
            detail: detail.into(),
        }
    }
    pub fn unavailable(code: &'static str, detail: impl Into<String>) -> Self {
        AppError::Unavailable {
            code,
            detail: detail.into(),
        }
    }
    /// The database did not take a write (logged here, once, where it happens).
    pub fn storage(e: sqlx::Error) -> Self {
        tracing::error!("database: {e}");
        AppError::Storage(format!("the database did not accept the write: {e}"))
    }

    /// The kernel's refusal, when this is one (a rolled-back step tells it apart from a
    /// failure of the transport).
    pub fn kernel_error(&self) -> Option<ErrorId> {
        match self {
            AppError::Rejected(id)
            | AppError::RejectedBecause { id, .. }
            | AppError::InvalidNumbered { id, .. }
            | AppError::InvalidCoded { id, .. }
            | AppError::Kernel { id, .. }
            | AppError::Refused { id, .. } => Some(*id),
            _ => None,
        }
    }

    pub fn status(&self) -> StatusCode {
        use AppError::*;
        match self {
            NotFound { .. } => StatusCode::NOT_FOUND,
            Invalid(_) | InvalidNumbered { .. } | InvalidCoded { .. } | Refused { .. } => {
                StatusCode::UNPROCESSABLE_ENTITY
            }
            Rejected(_) | RejectedBecause { .. } | Conflict { .. } => StatusCode::CONFLICT,
            Kernel { status, .. } | Http { status, .. } => *status,
            Unavailable { .. } | Storage(_) => StatusCode::SERVICE_UNAVAILABLE,
            BadJson(_) => StatusCode::BAD_REQUEST,
            TooLarge { .. } => StatusCode::PAYLOAD_TOO_LARGE,
            MethodNotAllowed { .. } => StatusCode::METHOD_NOT_ALLOWED,
            CrossOrigin(_) => StatusCode::FORBIDDEN,
            UnsupportedMediaType(_) => StatusCode::UNSUPPORTED_MEDIA_TYPE,
            Misdirected(_) => StatusCode::MISDIRECTED_REQUEST,
        }
    }

    /// The problem+json body this error is answered with.
    pub fn problem(&self) -> Problem {
        use AppError::*;
        let (code, title): (String, &str) = match self {
            NotFound { what, .. } => (format!("{what}_not_found"), "Not found"),
            Invalid(_) | InvalidNumbered { .. } | Refused { .. } => {
                ("validation_failed".into(), "Invalid request")
            }
            InvalidCoded { id, .. } => (id.code().into(), "Invalid request"),
            Rejected(id) | RejectedBecause { id, .. } => {
                (id.code().into(), "Command rejected by the axis")
            }
            Kernel { title, id, .. } => (id.code().into(), title),
            Conflict { code, .. } => ((*code).into(), "Conflict"),
            Unavailable { code, .. } => ((*code).into(), "Service unavailable"),
            Storage(_) => ("storage_unavailable".into(), "Service unavailable"),
            BadJson(_) => ("malformed_json".into(), "Malformed JSON"),
            TooLarge { .. } => ("payload_too_large".into(), "Payload too large"),
            MethodNotAllowed { .. } => ("method_not_allowed".into(), "Method not allowed"),
            CrossOrigin(_) => (
                "cross_origin_forbidden".into(),
                "Cross-origin request refused",
            ),
            UnsupportedMediaType(_) => ("unsupported_media_type".into(), "Unsupported media type"),
            Misdirected(_) => ("misdirected_request".into(), "Misdirected request"),
            Http { code, title, .. } => (code.clone(), title),
        };
        let errors = match self {
            Invalid(errors) | InvalidNumbered { errors, .. } | InvalidCoded { errors, .. } => {
                errors.clone()
            }
            Refused { field, message, .. } => vec![FieldError {
                field: field.to_string(),
                message: message.clone(),
            }],
            _ => Vec::new(),
        };
        Problem {
            type_: format!("urn:motiond:problem:{code}"),
            title: title.into(),
            status: self.status().as_u16(),
            detail: self.to_string(),
            code,
            error_id: self.kernel_error().map(|id| id.0),
            errors,
        }
    }
}

/// The problem's `detail`.
impl fmt::Display for AppError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use AppError::*;
        match self {
            NotFound { what, key } => write!(f, "no {what} '{key}'"),
            Invalid(errors) | InvalidNumbered { errors, .. } | InvalidCoded { errors, .. } => {
                for (i, e) in errors.iter().enumerate() {
                    if i > 0 {
                        f.write_str("; ")?;
                    }
                    write!(f, "{}: {}", e.field, e.message)?;
                }
                Ok(())
            }
            Refused { field, message, .. } => write!(f, "{field}: {message}"),
            Rejected(id) | Kernel { id, .. } => f.write_str(id.text()),
            RejectedBecause { id, why } => write!(f, "{}: {why}", id.text()),
            TooLarge { limit } => write!(f, "the body is larger than {limit} bytes"),
            MethodNotAllowed { method, path } => write!(
                f,
                "{path} does not take {method}; the Allow header lists the methods it takes"
            ),
            Conflict { detail, .. }
            | Unavailable { detail, .. }
            | Http { detail, .. }
            | Storage(detail)
            | BadJson(detail)
            | CrossOrigin(detail)
            | UnsupportedMediaType(detail)
            | Misdirected(detail) => f.write_str(detail),
        }
    }
}

impl std::error::Error for AppError {}

impl From<sqlx::Error> for AppError {
    fn from(e: sqlx::Error) -> Self {
        AppError::storage(e)
    }
}

impl IntoResponse for AppError {
    fn into_response(self) -> Response {
        let body = serde_json::to_vec(&self.problem()).unwrap_or_default();
        let mut r = (self.status(), body).into_response();
        r.headers_mut().insert(
            header::CONTENT_TYPE,
            HeaderValue::from_static("application/problem+json"),
        );
        r
    }
}

pub type AppResult<T> = Result<T, AppError>;
