//! The designer's socket: the same API requests as HTTP, over one WebSocket the page keeps open.
//!
//! A browser's `fetch` costs a few milliseconds of its own per request (measured 4–5 ms on a
//! two-core machine for an empty answer, against under 1 ms for a message on an open socket),
//! which is a large part of a drag's frame. So the page sends its frames' requests here:
//!
//! - `GET /socket?token=T` opens it (the Host and Origin checks of every request apply; the token
//!   is in the query because a browser cannot set headers on a WebSocket).
//! - Each text message is one request, `{"id": n, "method": "POST", "path": "edit?nu=32&nv=64",
//!   "body": {...}}` (`path` as after `/api/`; `body` omitted for none). It is answered, in order,
//!   by one binary message: the id (u32), the HTTP status (u16) and the answer's kind (u16: 0 a
//!   frame, 1 JSON), little-endian, then the answer's bytes exactly as HTTP gives them.
//! - The request runs through the HTTP router itself (every route, limit, guard and error
//!   message is the same one); a message that is not such a request is answered with a 400
//!   naming the place (`message:line:col`, or the field) under id 0 when its id is unknown, and
//!   the socket stays open. Messages over the body limit close the socket.

use super::error::ApiError;
use super::http::{AppState, MAX_BODY, TOKEN_HEADER};
use axum::body::Body;
use axum::extract::ws::{Message, WebSocket, WebSocketUpgrade};
use axum::extract::{Query, Request, State};
use axum::http::{header, HeaderMap, HeaderValue, Method, StatusCode};
use axum::response::{IntoResponse, Response};
use axum::Router;
use serde::Deserialize;
use std::collections::HashMap;
use tower::ServiceExt;

/// The kinds of answer a socket message carries after its header.
const KIND_FRAME: u16 = 0;
const KIND_JSON: u16 = 1;

/// One request on the socket.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SocketRequest {
    id: u32,
    method: String,
    path: String,
    #[serde(default)]
    body: Option<serde_json::Value>,
}

/// `GET /socket?token=T`: the upgrade, once the token is right. `api` answers the requests.
pub(super) async fn open(
    State(state): State<AppState>,
    Query(q): Query<HashMap<String, String>>,
    headers: HeaderMap,
    api: Router,
    upgrade: WebSocketUpgrade,
) -> Response {
    match q.get("token") {
        Some(t) if super::http::same_secret(t.as_bytes(), state.token.as_bytes()) => {}
        Some(_) => return ApiError::forbidden("wrong token", "token").into_response(),
        None => {
            return ApiError::forbidden(
                "missing token (open the URL printed by pdeshape serve)",
                "token",
            )
            .into_response()
        }
    }
    let host = headers.get(header::HOST).cloned();
    let token = state.token.clone();
    upgrade
        .max_message_size(MAX_BODY)
        .on_upgrade(move |socket| serve(socket, api, host, token))
}

/// Answers the socket's requests one after another until it closes.
async fn serve(
    mut socket: WebSocket,
    api: Router,
    host: Option<HeaderValue>,
    token: std::sync::Arc<str>,
) {
    while let Some(Ok(message)) = socket.recv().await {
        let answer = match message {
            Message::Text(text) => answer(text.as_bytes(), &api, host.as_ref(), &token).await,
            Message::Binary(_) => refusal(
                0,
                ApiError::bad_request("a socket request is a JSON text message", "message"),
            ),
            Message::Ping(_) | Message::Pong(_) => continue,
            Message::Close(_) => break,
        };
        if socket.send(Message::Binary(answer.into())).await.is_err() {
            break;
        }
    }
}

/// The answer to one text message.
async fn answer(text: &[u8], api: &Router, host: Option<&HeaderValue>, token: &str) -> Vec<u8> {
    let request: SocketRequest = match serde_json::from_slice(text) {
        Ok(r) => r,
        Err(e) => {
            // The id, when the message has a readable one, so the page can say which failed.
            let id = serde_json::from_slice::<serde_json::Value>(text)
                .ok()
                .and_then(|v| v.get("id").and_then(|i| i.as_u64()))
                .and_then(|i| u32::try_from(i).ok())
                .unwrap_or(0);
            return refusal(
                id,
                ApiError::bad_request(
                    format!(
                        "malformed socket request: {}",
                        pdeshape::spec::plain_message(&e.to_string())
                    ),
                    &format!("message:{}:{}", e.line(), e.column()),
                ),
            );
        }
    };
    let id = request.id;
    match to_http(request, host, token) {
        Ok(http) => match api.clone().oneshot(http).await {
            Ok(response) => encode(id, response).await,
            Err(never) => match never {},
        },
        Err(e) => refusal(id, e),
    }
}

/// The HTTP request a socket request stands for.
fn to_http(r: SocketRequest, host: Option<&HeaderValue>, token: &str) -> Result<Request, ApiError> {
    let method = match r.method.as_str() {
        "GET" => Method::GET,
        "POST" => Method::POST,
        other => {
            return Err(ApiError::bad_request(
                format!("method '{other}' is not GET or POST"),
                "method",
            ))
        }
    };
    if r.path.starts_with('/') || r.path.contains("://") {
        return Err(ApiError::bad_request(
            format!(
                "path '{}' is not an API request (write it as after /api/)",
                r.path
            ),
            "path",
        ));
    }
    let body = match &r.body {
        Some(b) => serde_json::to_vec(b).map_err(|e| ApiError::internal(e.to_string()))?,
        None => Vec::new(),
    };
    let mut builder = Request::builder()
        .method(method)
        .uri(format!("/api/{}", r.path))
        .header(TOKEN_HEADER, token);
    if let Some(h) = host {
        builder = builder.header(header::HOST, h.clone());
    }
    if r.body.is_some() {
        builder = builder.header(header::CONTENT_TYPE, "application/json");
    }
    builder
        .body(Body::from(body))
        .map_err(|e| ApiError::bad_request(format!("path '{}': {e}", r.path), "path"))
}

/// `response` as a socket answer.
async fn encode(id: u32, response: Response) -> Vec<u8> {
    let status = response.status();
    let json = response
        .headers()
        .get(header::CONTENT_TYPE)
        .is_some_and(|v| v.as_bytes().starts_with(b"application/json"));
    // The router's answers are made in memory: reading them whole does not wait.
    let bytes = axum::body::to_bytes(response.into_body(), usize::MAX)
        .await
        .unwrap_or_default();
    framed(
        id,
        status,
        if json { KIND_JSON } else { KIND_FRAME },
        &bytes,
    )
}

fn refusal(id: u32, e: ApiError) -> Vec<u8> {
    let body = serde_json::to_vec(&e.to_json()).unwrap_or_default();
    framed(id, e.status, KIND_JSON, &body)
}

fn framed(id: u32, status: StatusCode, kind: u16, body: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(8 + body.len());
    out.extend_from_slice(&id.to_le_bytes());
    out.extend_from_slice(&status.as_u16().to_le_bytes());
    out.extend_from_slice(&kind.to_le_bytes());
    out.extend_from_slice(body);
    out
}
