//! The designer's API errors: an HTTP status, a one-line message and the place it is about (a
//! design-file path such as `curves.rim.control[3]`, or a request field such as `nu`).

use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use pdeshape::spec::DesignSpec;

#[derive(Debug, Clone, PartialEq)]
pub(super) struct ApiError {
    pub status: StatusCode,
    pub message: String,
    pub place: String,
}

impl ApiError {
    fn new(status: StatusCode, message: impl Into<String>, place: &str) -> Self {
        ApiError {
            status,
            // One line, whatever a message quotes.
            message: message.into().replace('\r', "\\r").replace('\n', "\\n"),
            place: place.to_string(),
        }
    }
    /// A malformed request (400).
    pub(super) fn bad_request(message: impl Into<String>, place: &str) -> Self {
        Self::new(StatusCode::BAD_REQUEST, message, place)
    }
    /// A missing token, a foreign Host or Origin, a path leading outside (403).
    pub(super) fn forbidden(message: impl Into<String>, place: &str) -> Self {
        Self::new(StatusCode::FORBIDDEN, message, place)
    }
    pub(super) fn not_found(message: impl Into<String>, place: &str) -> Self {
        Self::new(StatusCode::NOT_FOUND, message, place)
    }
    /// A request that collides with another one under way (409).
    pub(super) fn conflict(message: impl Into<String>, place: &str) -> Self {
        Self::new(StatusCode::CONFLICT, message, place)
    }
    /// A save the file system cannot take now (507: a full disk, an I/O error); the message
    /// names the file relative to the start directory.
    pub(super) fn unavailable(message: impl Into<String>, place: &str) -> Self {
        Self::new(StatusCode::INSUFFICIENT_STORAGE, message, place)
    }
    /// A body larger than the limit (413).
    pub(super) fn too_large(message: impl Into<String>) -> Self {
        Self::new(StatusCode::PAYLOAD_TOO_LARGE, message, "")
    }
    /// A body that did not arrive in time (408).
    pub(super) fn timeout(message: impl Into<String>) -> Self {
        Self::new(StatusCode::REQUEST_TIMEOUT, message, "")
    }
    /// A well-formed request the design refuses (422).
    pub(super) fn unprocessable(message: impl Into<String>, place: &str) -> Self {
        Self::new(StatusCode::UNPROCESSABLE_ENTITY, message, place)
    }
    /// A failure of the server itself (500): a bug or the file system.
    pub(super) fn internal(message: impl Into<String>) -> Self {
        Self::new(StatusCode::INTERNAL_SERVER_ERROR, message, "")
    }

    /// An edit that does not apply or a design that does not solve (422), with the place in the
    /// design file.
    pub(super) fn edit(_spec: &DesignSpec, e: &pdeshape::Error) -> Self {
        Self::unprocessable(crate::common::message_of(e), e.place())
    }

    /// A design file that does not load (422), located as `file:line:col: place: message`.
    pub(super) fn design(file: &str, spec: &DesignSpec, e: &pdeshape::Error) -> Self {
        let text = pdeshape::spec::write_design(spec).unwrap_or_default();
        Self::unprocessable(pdeshape::spec::describe_error(file, &text, e), e.place())
    }

    pub(super) fn to_json(&self) -> serde_json::Value {
        Self::json(&self.message, &self.place)
    }

    /// The JSON of every error answer.
    pub(super) fn json(message: &str, place: &str) -> serde_json::Value {
        serde_json::json!({ "error": message, "place": place })
    }
}

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        (self.status, axum::Json(self.to_json())).into_response()
    }
}
