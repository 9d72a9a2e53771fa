//! The page and its modules, embedded in the binary (plain ES modules and WebGL2: no build step,
//! nothing fetched from elsewhere).

use axum::http::{header, HeaderValue};
use axum::response::{IntoResponse, Response};

/// `(name, content type, text)` of every file of the page.
const FILES: &[(&str, &str, &str)] = &[
    (
        "index.html",
        "text/html; charset=utf-8",
        include_str!("../../web/index.html"),
    ),
    (
        "style.css",
        "text/css; charset=utf-8",
        include_str!("../../web/style.css"),
    ),
    (
        "app.js",
        "text/javascript; charset=utf-8",
        include_str!("../../web/app.js"),
    ),
    (
        "api.js",
        "text/javascript; charset=utf-8",
        include_str!("../../web/api.js"),
    ),
    (
        "view.js",
        "text/javascript; charset=utf-8",
        include_str!("../../web/view.js"),
    ),
    (
        "math.js",
        "text/javascript; charset=utf-8",
        include_str!("../../web/math.js"),
    ),
    (
        "panels.js",
        "text/javascript; charset=utf-8",
        include_str!("../../web/panels.js"),
    ),
    (
        "channel.js",
        "text/javascript; charset=utf-8",
        include_str!("../../web/channel.js"),
    ),
    (
        "uv.js",
        "text/javascript; charset=utf-8",
        include_str!("../../web/uv.js"),
    ),
    (
        "timeline.js",
        "text/javascript; charset=utf-8",
        include_str!("../../web/timeline.js"),
    ),
    (
        "local.js",
        "text/javascript; charset=utf-8",
        include_str!("../../web/local.js"),
    ),
    (
        "params.js",
        "text/javascript; charset=utf-8",
        include_str!("../../web/params.js"),
    ),
];

fn respond(mime: &'static str, text: &'static str) -> Response {
    (
        [
            (header::CONTENT_TYPE, HeaderValue::from_static(mime)),
            (header::CACHE_CONTROL, HeaderValue::from_static("no-store")),
            (
                header::CONTENT_SECURITY_POLICY,
                HeaderValue::from_static(
                    "default-src 'self'; img-src 'self' blob: data:; style-src 'self'; frame-ancestors 'none'",
                ),
            ),
        ],
        text,
    )
        .into_response()
}

/// The page.
pub(super) fn page() -> Response {
    file("index.html").unwrap_or_else(|| respond("text/plain", "missing page"))
}

/// One of the page's files by name.
pub(super) fn file(name: &str) -> Option<Response> {
    FILES
        .iter()
        .find(|(n, _, _)| *n == name)
        .map(|(_, mime, text)| respond(mime, text))
}
