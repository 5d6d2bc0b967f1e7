//! Errors as RFC 9457 problem+json.

use axum::http::{HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Response};
use motion::ErrorId;
use serde::Serialize;
use utoipa::ToSchema;

use crate::sim::FieldError;

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

#[derive(Debug)]
pub struct ApiError(pub Box<Problem>);

impl ApiError {
    pub fn new(status: StatusCode, code: &str, title: &str, detail: impl Into<String>) -> Self {
        ApiError(Box::new(Problem {
            type_: format!("urn:motiond:problem:{code}"),
            title: title.into(),
            status: status.as_u16(),
            detail: detail.into(),
            code: code.into(),
            error_id: None,
            errors: Vec::new(),
        }))
    }
    pub fn not_found(what: &str, key: &str) -> Self {
        Self::new(
            StatusCode::NOT_FOUND,
            &format!("{what}_not_found"),
            "Not found",
            format!("no {what} '{key}'"),
        )
    }
    pub fn bad_json(detail: impl Into<String>) -> Self {
        Self::new(
            StatusCode::BAD_REQUEST,
            "malformed_json",
            "Malformed JSON",
            detail,
        )
    }
    /// A body over the limit (axum's rejection would be plain text).
    pub fn too_large(limit: usize) -> Self {
        Self::new(
            StatusCode::PAYLOAD_TOO_LARGE,
            "payload_too_large",
            "Payload too large",
            format!("the body is larger than {limit} bytes"),
        )
    }
    /// A method the route does not have; the response's `Allow` header lists those it has.
    pub fn method_not_allowed(method: &str, path: &str) -> Self {
        Self::new(
            StatusCode::METHOD_NOT_ALLOWED,
            "method_not_allowed",
            "Method not allowed",
            format!("{path} does not take {method}; the Allow header lists the methods it takes"),
        )
    }
    /// A state-changing request from another web origin (`Origin`, `Sec-Fetch-Site`).
    pub fn cross_origin(detail: impl Into<String>) -> Self {
        Self::new(
            StatusCode::FORBIDDEN,
            "cross_origin_forbidden",
            "Cross-origin request refused",
            detail,
        )
    }
    /// A state-changing request whose body is not declared `application/json`.
    pub fn unsupported_media_type(detail: impl Into<String>) -> Self {
        Self::new(
            StatusCode::UNSUPPORTED_MEDIA_TYPE,
            "unsupported_media_type",
            "Unsupported media type",
            detail,
        )
    }
    /// A request for a host name motiond does not serve (DNS rebinding).
    pub fn misdirected(detail: impl Into<String>) -> Self {
        Self::new(
            StatusCode::MISDIRECTED_REQUEST,
            "misdirected_request",
            "Misdirected request",
            detail,
        )
    }
    pub fn invalid(errors: Vec<FieldError>) -> Self {
        let detail = errors
            .iter()
            .map(|e| format!("{}: {}", e.field, e.message))
            .collect::<Vec<_>>()
            .join("; ");
        let mut e = Self::new(
            StatusCode::UNPROCESSABLE_ENTITY,
            "validation_failed",
            "Invalid request",
            detail,
        );
        e.0.errors = errors;
        e
    }
    pub fn field(field: &str, message: &str) -> Self {
        Self::invalid(vec![FieldError {
            field: field.into(),
            message: message.into(),
        }])
    }
    /// A kernel error number with its HTTP status.
    pub fn kernel(status: StatusCode, title: &str, id: ErrorId) -> Self {
        let mut e = Self::new(status, id.code(), title, id.text());
        e.0.error_id = Some(id.0);
        e
    }
    pub fn rejected(id: ErrorId) -> Self {
        Self::kernel(StatusCode::CONFLICT, "Command rejected by the axis", id)
    }
    pub fn conflict(code: &str, detail: impl Into<String>) -> Self {
        Self::new(StatusCode::CONFLICT, code, "Conflict", detail)
    }
    pub fn unavailable(code: &str, detail: impl Into<String>) -> Self {
        Self::new(
            StatusCode::SERVICE_UNAVAILABLE,
            code,
            "Service unavailable",
            detail,
        )
    }
    pub fn storage(e: sqlx::Error) -> Self {
        tracing::error!("database: {e}");
        Self::unavailable(
            "storage_unavailable",
            format!("the database did not accept the write: {e}"),
        )
    }
}

impl From<sqlx::Error> for ApiError {
    fn from(e: sqlx::Error) -> Self {
        ApiError::storage(e)
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        let status =
            StatusCode::from_u16(self.0.status).unwrap_or(StatusCode::INTERNAL_SERVER_ERROR);
        let body = serde_json::to_vec(&*self.0).unwrap_or_default();
        let mut r = (status, body).into_response();
        r.headers_mut().insert(
            header::CONTENT_TYPE,
            HeaderValue::from_static("application/problem+json"),
        );
        r
    }
}

pub type ApiResult<T> = Result<T, ApiError>;
