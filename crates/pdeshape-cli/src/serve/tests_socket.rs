//! The socket through a real TCP connection: its answers are HTTP's, its refusals keep it open,
//! and its upgrade keeps the token, Host and Origin checks.

use super::http::{router, AppState};
use super::session::Session;
use super::tests::{app, post, root, send};
use futures_util::{SinkExt, StreamExt};
use serde_json::{json, Value};
use std::sync::Arc;
use tokio_tungstenite::tungstenite::client::IntoClientRequest;
use tokio_tungstenite::tungstenite::{Error as WsError, Message};

const TOKEN: &str = "fedcba9876543210fedcba9876543210";

/// A server on a free port serving `design`; its address.
async fn start(root: &std::path::Path, design: &str) -> std::net::SocketAddr {
    let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await.unwrap();
    let addr = listener.local_addr().unwrap();
    let session = Session::open(root.to_path_buf(), Some(design)).unwrap();
    let state = AppState {
        session: Arc::new(tokio::sync::Mutex::new(session)),
        token: TOKEN.into(),
        port: addr.port(),
        host_name: None,
    };
    tokio::spawn(super::serve_bounded(listener, router(state)));
    addr
}

type Ws = tokio_tungstenite::WebSocketStream<tokio::net::TcpStream>;

/// Opens the socket with `token` and, when given, an Origin.
async fn open(
    addr: std::net::SocketAddr,
    token: &str,
    origin: Option<&str>,
) -> Result<Ws, WsError> {
    let mut request = format!("ws://{addr}/socket?token={token}")
        .into_client_request()
        .unwrap();
    if let Some(o) = origin {
        request.headers_mut().insert("origin", o.parse().unwrap());
    }
    let stream = tokio::net::TcpStream::connect(addr).await.unwrap();
    tokio_tungstenite::client_async(request, stream)
        .await
        .map(|(ws, _)| ws)
}

/// One request and its answer: id, status, kind and bytes.
async fn ask(ws: &mut Ws, message: Value) -> (u32, u16, u16, Vec<u8>) {
    ask_text(ws, &message.to_string()).await
}

async fn ask_text(ws: &mut Ws, text: &str) -> (u32, u16, u16, Vec<u8>) {
    ws.send(Message::Text(text.into())).await.unwrap();
    answer(ws).await
}

/// The next answer: id, status, kind and bytes.
async fn answer(ws: &mut Ws) -> (u32, u16, u16, Vec<u8>) {
    loop {
        match ws.next().await.unwrap().unwrap() {
            Message::Binary(b) => {
                let id = u32::from_le_bytes(b[0..4].try_into().unwrap());
                let status = u16::from_le_bytes(b[4..6].try_into().unwrap());
                let kind = u16::from_le_bytes(b[6..8].try_into().unwrap());
                return (id, status, kind, b[8..].to_vec());
            }
            Message::Ping(_) | Message::Pong(_) => continue,
            other => panic!("unexpected message {other:?}"),
        }
    }
}

/// A frame's scene JSON without the server's own timings, and its meshes' bytes.
fn frame_parts(bytes: &[u8]) -> (Value, Vec<u8>) {
    assert_eq!(&bytes[0..4], b"PDSF");
    let n = u32::from_le_bytes(bytes[4..8].try_into().unwrap()) as usize;
    let mut scene: Value = serde_json::from_slice(&bytes[8..8 + n]).unwrap();
    let o = scene.as_object_mut().unwrap();
    o.remove("server_ms");
    o.remove("server_split");
    (scene, bytes[8 + n..].to_vec())
}

fn rim(radius: f64) -> Value {
    json!({ "edit": "set_curve", "name": "rim", "curve": {
        "type": "circle", "center": [0.0, 0.0, 2.4], "radius": radius } })
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn socket_answers_are_the_http_answers() {
    let dir = root();
    let addr = start(dir.path(), "examples/cup.toml").await;
    let twin = app(dir.path(), Some("examples/cup.toml"));
    let mut ws = open(addr, TOKEN, Some(&format!("http://{addr}")))
        .await
        .unwrap();
    let q = "edit?nu=12&nv=16&color=gauss";
    for (k, x) in [1.4, 1.5, 1.2].into_iter().enumerate() {
        let id = 40 + k as u32;
        let body = json!({ "edit": rim(x), "group": 7 });
        let (got, status, kind, bytes) = ask(
            &mut ws,
            json!({ "id": id, "method": "POST", "path": q, "body": body }),
        )
        .await;
        assert_eq!((got, status, kind), (id, 200, 0));
        let http = post(&twin, &format!("/api/{q}"), body).await;
        assert_eq!(http.status, 200);
        assert_eq!(frame_parts(&bytes), frame_parts(&http.body), "edit {k}");
    }
    // GET without a body, and undo as the page sends it.
    let (_, status, kind, bytes) = ask(
        &mut ws,
        json!({ "id": 1, "method": "POST", "path": "undo?nu=12&nv=16" }),
    )
    .await;
    assert_eq!((status, kind), (200, 0));
    let http = send(&twin, "POST", "/api/undo?nu=12&nv=16", None, &[]).await;
    assert_eq!(
        frame_parts(&bytes).0["version"],
        frame_parts(&http.body).0["version"]
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn socket_refusals_name_the_place_and_keep_it_open() {
    let dir = root();
    let addr = start(dir.path(), "examples/cup.toml").await;
    let mut ws = open(addr, TOKEN, None).await.unwrap();
    let error = |bytes: &[u8]| -> (String, String) {
        let v: Value = serde_json::from_slice(bytes).unwrap();
        (
            v["error"].as_str().unwrap().into(),
            v["place"].as_str().unwrap().into(),
        )
    };
    // Not JSON: id 0, the place in the message.
    let (id, status, kind, bytes) = ask_text(&mut ws, "{\"id\": 3, \"method\": ").await;
    assert_eq!((id, status, kind), (0, 400, 1));
    let (message, place) = error(&bytes);
    assert!(message.starts_with("malformed socket request"), "{message}");
    assert!(place.starts_with("message:1:"), "{place}");
    // A readable id is kept; an unknown field is named.
    let (id, status, _, bytes) = ask(
        &mut ws,
        json!({ "id": 9, "method": "GET", "path": "files", "extra": 1 }),
    )
    .await;
    assert_eq!((id, status), (9, 400));
    assert!(error(&bytes).0.contains("extra"), "{:?}", error(&bytes));
    let (_, status, _, bytes) =
        ask(&mut ws, json!({ "id": 4, "method": "PUT", "path": "edit" })).await;
    assert_eq!((status, error(&bytes).1.as_str()), (400, "method"));
    let (_, status, _, bytes) = ask(
        &mut ws,
        json!({ "id": 5, "method": "GET", "path": "/api/files" }),
    )
    .await;
    assert_eq!((status, error(&bytes).1.as_str()), (400, "path"));
    let (_, status, _, _) = ask(
        &mut ws,
        json!({ "id": 6, "method": "GET", "path": "nothing" }),
    )
    .await;
    assert_eq!(status, 404);
    // The router's own refusals, as HTTP gives them: a bad query value, an edit refused.
    let (_, status, _, bytes) = ask(
        &mut ws,
        json!({ "id": 7, "method": "GET", "path": "frame?nu=abc" }),
    )
    .await;
    assert_eq!((status, error(&bytes).1.as_str()), (400, "nu"));
    let (_, status, _, bytes) = ask(
        &mut ws,
        json!({ "id": 8, "method": "POST", "path": "edit",
        "body": { "edit": rim(-1.0) } }),
    )
    .await;
    assert_eq!(
        (status, error(&bytes).1.as_str()),
        (422, "curves.rim.radius")
    );
    // Binary messages are not requests.
    ws.send(Message::Binary(vec![1, 2, 3].into()))
        .await
        .unwrap();
    let (id, status, kind, _) = answer(&mut ws).await;
    assert_eq!((id, status, kind), (0, 400, 1));
    // Still serving.
    let (id, status, kind, bytes) = ask(
        &mut ws,
        json!({ "id": 10, "method": "GET", "path": "frame?nu=8&nv=8" }),
    )
    .await;
    assert_eq!((id, status, kind, &bytes[0..4]), (10, 200, 0, &b"PDSF"[..]));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn socket_upgrade_keeps_the_checks() {
    let dir = root();
    let addr = start(dir.path(), "examples/cup.toml").await;
    let status = |r: Result<Ws, WsError>| match r {
        Err(WsError::Http(response)) => response.status().as_u16(),
        Err(e) => panic!("unexpected error {e}"),
        Ok(_) => 101,
    };
    assert_eq!(status(open(addr, "wrong", None).await), 403);
    assert_eq!(status(open(addr, "", None).await), 403);
    assert_eq!(
        status(open(addr, TOKEN, Some("http://evil.example:80")).await),
        403
    );
    assert_eq!(
        status(open(addr, TOKEN, Some(&format!("http://{addr}"))).await),
        101
    );
}
