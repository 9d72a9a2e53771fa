//! API tests, in-process: requests through the router as the page sends them.

use super::http::{router, AppState, MAX_BODY, TOKEN_HEADER};
use super::session::{starting_design, Session};
use axum::body::Body;
use axum::http::{Request, StatusCode};
use http_body_util::BodyExt;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use tower::ServiceExt;

const PORT: u16 = 8737;
const TOKEN: &str = "0123456789abcdef0123456789abcdef";
const HOST: &str = "127.0.0.1:8737";

pub(super) fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples")
}

/// A start directory with the examples the tests load in `examples/`.
pub(super) fn root() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("examples/anim")).unwrap();
    for f in [
        "cup.toml",
        "wine_glass.toml",
        "teacup.toml",
        "trimmed_vase.toml",
        "aeroplane.toml",
        "swirl_port_params.toml",
        "anim/fish.toml",
        "anim/ventricle.toml",
        "anim/glass_morph.toml",
        "anim/water_glass.toml",
    ] {
        std::fs::copy(examples().join(f), dir.path().join("examples").join(f)).unwrap();
    }
    dir
}

pub(super) fn app(root: &Path, design: Option<&str>) -> axum::Router {
    let session = Session::open(root.to_path_buf(), design).unwrap();
    router(AppState {
        session: Arc::new(tokio::sync::Mutex::new(session)),
        token: TOKEN.into(),
        port: PORT,
        host_name: None,
    })
}

pub(super) struct Answer {
    pub(super) status: StatusCode,
    pub(super) headers: axum::http::HeaderMap,
    pub(super) body: Vec<u8>,
}

impl Answer {
    pub(super) fn json(&self) -> Value {
        serde_json::from_slice(&self.body)
            .unwrap_or_else(|_| panic!("not JSON: {}", String::from_utf8_lossy(&self.body)))
    }
    pub(super) fn error(&self) -> (String, String) {
        let v = self.json();
        (
            v["error"].as_str().unwrap_or("").to_string(),
            v["place"].as_str().unwrap_or("").to_string(),
        )
    }
}

/// Sends a request; `headers` replace the defaults (Host, token) where named.
pub(super) async fn send(
    app: &axum::Router,
    method: &str,
    uri: &str,
    body: Option<Vec<u8>>,
    headers: &[(&str, &str)],
) -> Answer {
    let mut b = Request::builder().method(method).uri(uri);
    let mut defaults = vec![("host", HOST), (TOKEN_HEADER, TOKEN)];
    defaults.retain(|(k, _)| !headers.iter().any(|(h, _)| h == k));
    for (k, v) in defaults
        .iter()
        .chain(headers)
        .filter(|(_, v)| !v.is_empty())
    {
        b = b.header(*k, *v);
    }
    let request = b
        .body(body.map(Body::from).unwrap_or_else(Body::empty))
        .unwrap();
    let response = app.clone().oneshot(request).await.unwrap();
    let status = response.status();
    let headers = response.headers().clone();
    let body = response
        .into_body()
        .collect()
        .await
        .unwrap()
        .to_bytes()
        .to_vec();
    Answer {
        status,
        headers,
        body,
    }
}

pub(super) async fn post(app: &axum::Router, uri: &str, body: Value) -> Answer {
    send(app, "POST", uri, Some(body.to_string().into_bytes()), &[]).await
}

/// A decoded frame: the scene and, per surface, `(nu, nv, positions)`, and the triangles of
/// the trimmed ones.
pub(super) struct Frame {
    pub(super) scene: Value,
    pub(super) surfaces: Vec<(usize, usize, Vec<f32>)>,
    pub(super) triangles: Vec<Option<Vec<[u32; 3]>>>,
    /// Per surface: colours were sent.
    pub(super) colored: Vec<bool>,
}

fn u32_at(b: &[u8], at: usize) -> usize {
    u32::from_le_bytes(b[at..at + 4].try_into().unwrap()) as usize
}

pub(super) fn decode(a: &Answer) -> Frame {
    assert_eq!(
        a.status,
        StatusCode::OK,
        "{}",
        String::from_utf8_lossy(&a.body)
    );
    let b = &a.body;
    assert_eq!(&b[..4], b"PDSF");
    let len = u32_at(b, 4);
    assert_eq!(len % 4, 0);
    let scene: Value = serde_json::from_slice(&b[8..8 + len]).unwrap();
    let mut at = 8 + len;
    let count = u32_at(b, at);
    at += 4;
    let mut surfaces = Vec::new();
    let mut triangles = Vec::new();
    let mut colored = Vec::new();
    for _ in 0..count {
        let (nu, nv, flags) = (u32_at(b, at), u32_at(b, at + 4), u32_at(b, at + 8));
        at += 12;
        let (n, tris) = if flags & 4 != 0 {
            at += 8;
            (u32_at(b, at - 8), Some(u32_at(b, at - 4)))
        } else {
            (nu * nv, None)
        };
        let positions: Vec<f32> = b[at..at + 12 * n]
            .chunks(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        at += 12 * n;
        // Normals: unit length to the i16 quantisation.
        for k in (0..n).step_by(97) {
            let q: Vec<f64> = (0..3)
                .map(|c| {
                    let o = at + 6 * k + 2 * c;
                    i16::from_le_bytes([b[o], b[o + 1]]) as f64 / 32767.0
                })
                .collect();
            let len = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2]).sqrt();
            assert!((len - 1.0).abs() < 1e-3, "normal length {len}");
        }
        at += (6 * n).div_ceil(4) * 4;
        if flags & 2 != 0 {
            at += (3 * n).div_ceil(4) * 4;
        }
        colored.push(flags & 2 != 0);
        triangles.push(tris.map(|t| {
            let list: Vec<[u32; 3]> = (0..t)
                .map(|k| std::array::from_fn(|c| u32_at(b, at + 12 * k + 4 * c) as u32))
                .collect();
            at += 12 * t;
            assert!(
                list.iter().flatten().all(|&i| (i as usize) < n),
                "index out of range"
            );
            list
        }));
        surfaces.push((nu, nv, positions));
    }
    assert_eq!(at, b.len(), "frame length");
    Frame {
        scene,
        surfaces,
        triangles,
        colored,
    }
}

pub(super) fn curve<'a>(scene: &'a Value, name: &str) -> &'a Value {
    scene["curves"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == name)
        .unwrap_or_else(|| panic!("no curve {name}"))
}

fn move_rim(index: usize, point: [f64; 3], group: Option<u64>) -> Value {
    json!({
        "edit": { "edit": "move_control_point", "name": "rim", "index": index, "point": point },
        "group": group,
    })
}

pub(super) const GRID: &str = "nu=16&nv=32";

#[tokio::test]
async fn starting_design_is_served_with_control_points() {
    assert!(starting_design().is_ok());
    let dir = root();
    let app = app(dir.path(), None);
    let f = decode(&send(&app, "GET", &format!("/api/frame?{GRID}"), None, &[]).await);
    assert_eq!(f.surfaces.len(), 1);
    assert_eq!((f.surfaces[0].0, f.surfaces[0].1), (16, 32));
    let rim = curve(&f.scene, "rim");
    assert_eq!(rim["control"].as_array().unwrap().len(), 8);
    assert_eq!(rim["role"], "position");
    assert_eq!(curve(&f.scene, "rim_tangent")["role"], "derivative");
    assert_eq!(f.scene["vectors"].as_array().unwrap().len(), 2);
    // The v = 0 mark of the rim is on the +x axis (the B-spline was laid out for that).
    let v0 = &rim["v0"]["point"];
    assert!(v0[1].as_f64().unwrap().abs() < 1e-12, "{v0}");
    assert!(v0[0].as_f64().unwrap() > 0.9);
    // The page itself, with the token.
    let page = send(&app, "GET", &format!("/?token={TOKEN}"), None, &[]).await;
    assert_eq!(page.status, StatusCode::OK);
    assert!(String::from_utf8_lossy(&page.body).contains("app.js"));
    let js = send(&app, "GET", "/app.js", None, &[]).await;
    assert_eq!(js.status, StatusCode::OK);
}

#[tokio::test]
async fn drag_edits_undo_and_redo() {
    let dir = root();
    let app = app(dir.path(), None);
    let before = decode(&send(&app, "GET", &format!("/api/frame?{GRID}"), None, &[]).await);
    // A drag: three moves of one control point in one group.
    let mut last = None;
    for (k, x) in [1.2, 1.4, 1.6].iter().enumerate() {
        let a = post(
            &app,
            &format!("/api/edit?{GRID}"),
            move_rim(1, [*x, 0.0, 2.0 + 0.1 * k as f64], Some(7)),
        )
        .await;
        last = Some(decode(&a));
    }
    let after = last.unwrap();
    assert_ne!(
        before.surfaces[0].2, after.surfaces[0].2,
        "the surface moved"
    );
    assert_eq!(after.scene["version"], 3);
    assert_eq!(
        curve(&after.scene, "rim")["control"][1],
        json!([1.6, 0.0, 2.2])
    );
    assert_eq!(after.scene["can_undo"], true);
    // One undo takes the whole drag back, bit for bit.
    let undone = decode(&post(&app, &format!("/api/undo?{GRID}"), json!(null)).await);
    assert_eq!(undone.surfaces[0].2, before.surfaces[0].2);
    assert_eq!(undone.scene["can_undo"], false);
    assert_eq!(undone.scene["can_redo"], true);
    let nothing = post(&app, &format!("/api/undo?{GRID}"), json!(null)).await;
    assert_eq!(nothing.status, StatusCode::UNPROCESSABLE_ENTITY);
    // Redo tessellates the drag's last state; the drag's own frames came from its affine
    // model, which agrees with a tessellation to 2⁻²⁷ of the extent before rounding to single
    // precision: a unit in the last place at most.
    let redone = decode(&post(&app, &format!("/api/redo?{GRID}"), json!(null)).await);
    let (a, b) = (&redone.surfaces[0].2, &after.surfaces[0].2);
    let extent = b.iter().fold(0.0f32, |m, c| m.max(c.abs()));
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(b) {
        let bound = extent / (1u32 << 27) as f32 + y.abs() * f32::EPSILON + f32::MIN_POSITIVE;
        assert!((x - y).abs() <= bound, "{x} against {y}");
    }
    // Edits without a group are separate undo steps.
    for x in [1.0, 0.9] {
        decode(
            &post(
                &app,
                &format!("/api/edit?{GRID}"),
                move_rim(2, [x, x, 2.0], None),
            )
            .await,
        );
    }
    let one = decode(&post(&app, &format!("/api/undo?{GRID}"), json!(null)).await);
    assert_eq!(
        curve(&one.scene, "rim")["control"][2],
        json!([1.0, 1.0, 2.0])
    );
}

#[tokio::test]
async fn bad_edits_answer_422_and_keep_the_last_good_surface() {
    let dir = root();
    let app = app(dir.path(), None);
    let before = decode(&send(&app, "GET", &format!("/api/frame?{GRID}"), None, &[]).await);
    let cases = [
        (move_rim(99, [0.0, 0.0, 0.0], None), "index"),
        (
            json!({ "edit": { "edit": "set_smoothing", "patch": "body", "a": 0.0 } }),
            "operator.a",
        ),
        (
            json!({ "edit": { "edit": "set_curve", "name": "rim", "curve": {
                "type": "circle", "center": [0.0, 0.0, 2.0], "radius": -1.0 } } }),
            "curves.rim.radius",
        ),
        (
            json!({ "edit": { "edit": "set_order", "patch": "body", "order": 3 } }),
            "patches[0].conditions",
        ),
    ];
    for (edit, place) in cases {
        let a = post(&app, &format!("/api/edit?{GRID}"), edit.clone()).await;
        assert_eq!(a.status, StatusCode::UNPROCESSABLE_ENTITY, "{edit}");
        let (message, got) = a.error();
        assert!(!message.is_empty());
        assert!(
            got.starts_with(place),
            "{edit}: place {got}, message {message}"
        );
    }
    let after = decode(&send(&app, "GET", &format!("/api/frame?{GRID}"), None, &[]).await);
    assert_eq!(after.surfaces[0].2, before.surfaces[0].2);
    assert_eq!(after.scene["version"], 0);
    assert_eq!(after.scene["can_undo"], false);
}

#[tokio::test]
async fn malformed_requests_answer_4xx() {
    let dir = root();
    let app = app(dir.path(), None);
    let raw = |s: &str| Some(s.as_bytes().to_vec());
    let cases: Vec<(&str, &str, Option<Vec<u8>>, StatusCode)> = vec![
        (
            "POST",
            "/api/edit",
            raw("{not json"),
            StatusCode::BAD_REQUEST,
        ),
        ("POST", "/api/edit", raw(""), StatusCode::BAD_REQUEST),
        (
            "POST",
            "/api/edit",
            raw(r#"{"edit":{"edit":"fly"}}"#),
            StatusCode::BAD_REQUEST,
        ),
        (
            "POST",
            "/api/edit",
            raw(r#"{"edit":{"edit":"set_modes","modes":4},"x":1}"#),
            StatusCode::BAD_REQUEST,
        ),
        (
            "POST",
            "/api/edit?nu=abc",
            raw("{}"),
            StatusCode::BAD_REQUEST,
        ),
        ("GET", "/api/frame?nu=100000", None, StatusCode::BAD_REQUEST),
        ("GET", "/api/frame?nv=1", None, StatusCode::BAD_REQUEST),
        (
            "GET",
            "/api/frame?color=plaid",
            None,
            StatusCode::BAD_REQUEST,
        ),
        (
            "GET",
            "/api/download?format=exe",
            None,
            StatusCode::BAD_REQUEST,
        ),
        ("GET", "/api/download", None, StatusCode::BAD_REQUEST),
        (
            "GET",
            "/api/download?format=png&size=0x5",
            None,
            StatusCode::BAD_REQUEST,
        ),
        (
            "GET",
            "/api/download?format=png&view=0,0,0",
            None,
            StatusCode::BAD_REQUEST,
        ),
        (
            "POST",
            "/api/save",
            raw(r#"{"path": 3}"#),
            StatusCode::BAD_REQUEST,
        ),
        (
            "POST",
            "/api/convert",
            raw(r#"{"name": "rim"}"#),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        ("GET", "/api/nothing", None, StatusCode::NOT_FOUND),
        ("GET", "/nothing.js", None, StatusCode::NOT_FOUND),
        ("GET", "/api/edit", None, StatusCode::METHOD_NOT_ALLOWED),
        (
            "POST",
            "/api/edit",
            Some(vec![b' '; MAX_BODY + 1]),
            StatusCode::PAYLOAD_TOO_LARGE,
        ),
    ];
    for (method, uri, body, want) in cases {
        let a = send(&app, method, uri, body, &[]).await;
        assert_eq!(
            a.status,
            want,
            "{method} {uri}: {}",
            String::from_utf8_lossy(&a.body)
        );
    }
    // Refused requests changed nothing, and the server still answers.
    let f = decode(&send(&app, "GET", &format!("/api/frame?{GRID}"), None, &[]).await);
    assert_eq!(f.scene["version"], 0);
}

#[tokio::test]
async fn token_host_and_origin_are_checked() {
    let dir = root();
    let app = app(dir.path(), None);
    let uri = format!("/api/frame?{GRID}");
    let forbidden = [
        vec![(TOKEN_HEADER, "")],
        vec![(TOKEN_HEADER, "0123456789abcdef0123456789abcdee")],
        vec![(TOKEN_HEADER, "short")],
        vec![("host", "evil.example:8737")],
        vec![("host", "127.0.0.1:9999")],
        vec![("host", "")],
        vec![("origin", "http://evil.example")],
        vec![("origin", "http://localhost:8737")],
        vec![("origin", "null")],
    ];
    for headers in forbidden {
        let a = send(&app, "GET", &uri, None, &headers).await;
        assert_eq!(a.status, StatusCode::FORBIDDEN, "{headers:?}");
        assert!(!a.error().0.is_empty());
    }
    let a = send(
        &app,
        "POST",
        "/api/edit",
        Some(move_rim(1, [2.0, 0.0, 2.0], None).to_string().into_bytes()),
        &[("origin", "http://evil.example")],
    )
    .await;
    assert_eq!(a.status, StatusCode::FORBIDDEN);
    let allowed = [
        vec![],
        vec![("host", "localhost:8737")],
        vec![("host", "[::1]:8737")],
        vec![("origin", "http://127.0.0.1:8737")],
    ];
    for headers in allowed {
        let a = send(&app, "GET", &uri, None, &headers).await;
        assert_eq!(a.status, StatusCode::OK, "{headers:?}");
    }
    // The page needs the token in its URL.
    for uri in ["/", "/?token=nope"] {
        assert_eq!(
            send(&app, "GET", uri, None, &[]).await.status,
            StatusCode::FORBIDDEN
        );
    }
    // The refused edit did nothing.
    let f = decode(&send(&app, "GET", &uri, None, &[]).await);
    assert_eq!(f.scene["version"], 0);
}

/// Meshes of a design file solved from scratch, as `pdeshape surface` does.
pub(super) fn meshes_of_file(path: &Path, nu: usize, nv: usize) -> Vec<Vec<f32>> {
    let text = std::fs::read_to_string(path).unwrap();
    let spec = pdeshape::spec::parse_design(&text).unwrap();
    let solved = pdeshape::design::solve_design(&spec).unwrap();
    solved
        .meshes(nu, nv)
        .unwrap()
        .iter()
        .map(|m| m.positions.iter().flatten().copied().collect())
        .collect()
}

#[tokio::test]
async fn save_and_load_round_trip() {
    let dir = root();
    let app = app(dir.path(), Some("examples/cup.toml"));
    let f = decode(&send(&app, "GET", &format!("/api/frame?{GRID}"), None, &[]).await);
    assert_eq!(f.surfaces.len(), 2);
    assert_eq!(f.scene["file"], "examples/cup.toml");
    assert_eq!(f.scene["shared_curves"], json!(["belly"]));
    // Make the belly a B-spline and drag one of its points; save; the file solves to the same
    // surfaces.
    let c = decode(
        &post(
            &app,
            &format!("/api/convert?{GRID}"),
            json!({"name": "belly"}),
        )
        .await,
    );
    assert_eq!(
        curve(&c.scene, "belly")["control"]
            .as_array()
            .unwrap()
            .len(),
        8
    );
    let moved = json!({ "edit": { "edit": "move_control_point", "name": "belly", "index": 3,
        "point": [0.2, 1.9, 1.0] }, "group": 1 });
    let e = decode(&post(&app, &format!("/api/edit?{GRID}"), moved).await);
    let saved = post(&app, "/api/save", json!({"path": "mine.toml"})).await;
    assert_eq!(saved.status, StatusCode::OK);
    assert_eq!(saved.json()["saved"], "mine.toml");
    let from_file = meshes_of_file(&dir.path().join("mine.toml"), 16, 32);
    for (k, m) in from_file.iter().enumerate() {
        assert_eq!(m, &e.surfaces[k].2, "surface {k}");
    }
    let text = std::fs::read_to_string(dir.path().join("mine.toml")).unwrap();
    assert!(text.contains("[0.2, 1.9, 1.0]"), "{text}");
    // No temporary file is left beside it.
    let names: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().all(|n| !n.ends_with(".tmp")), "{names:?}");
    // Load another file, then the saved one back: the same surfaces.
    let w = decode(
        &post(
            &app,
            &format!("/api/load?{GRID}"),
            json!({"path": "examples/wine_glass.toml"}),
        )
        .await,
    );
    assert_eq!(w.surfaces.len(), 3);
    assert_eq!(w.scene["can_undo"], false);
    let back = decode(
        &post(
            &app,
            &format!("/api/load?{GRID}"),
            json!({"path": "mine.toml"}),
        )
        .await,
    );
    for (k, m) in from_file.iter().enumerate() {
        assert_eq!(m, &back.surfaces[k].2);
    }
    let list = send(&app, "GET", "/api/files", None, &[]).await.json();
    let files: Vec<&str> = list["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_str().unwrap())
        .collect();
    assert!(files.is_sorted(), "{files:?}");
    assert_eq!(files.len(), 11, "{files:?}");
    for f in ["examples/cup.toml", "examples/anim/fish.toml", "mine.toml"] {
        assert!(files.contains(&f), "{files:?}");
    }
}

#[tokio::test]
async fn paths_stay_inside_the_start_directory() {
    let dir = root();
    let outside = tempfile::tempdir().unwrap();
    std::fs::copy(examples().join("cup.toml"), outside.path().join("cup.toml")).unwrap();
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink(outside.path(), dir.path().join("away")).unwrap();
        std::os::unix::fs::symlink(
            outside.path().join("cup.toml"),
            dir.path().join("link.toml"),
        )
        .unwrap();
        std::os::unix::fs::symlink(
            outside.path().join("new.toml"),
            dir.path().join("dangling.toml"),
        )
        .unwrap();
        std::os::unix::fs::symlink(
            dir.path().join("examples/cup.toml"),
            dir.path().join("inside.toml"),
        )
        .unwrap();
    }
    let app = app(dir.path(), None);
    let refused = [
        ("../x.toml", StatusCode::FORBIDDEN),
        ("examples/../../x.toml", StatusCode::FORBIDDEN),
        ("/etc/x.toml", StatusCode::FORBIDDEN),
        ("./cup.toml", StatusCode::FORBIDDEN),
        ("away/cup.toml", StatusCode::FORBIDDEN),
        ("link.toml", StatusCode::FORBIDDEN),
        ("dangling.toml", StatusCode::FORBIDDEN),
        ("examples/cup.txt", StatusCode::BAD_REQUEST),
        ("", StatusCode::BAD_REQUEST),
    ];
    for (path, want) in refused {
        for verb in ["load", "save"] {
            let a = post(
                &app,
                &format!("/api/{verb}?{GRID}"),
                json!({ "path": path }),
            )
            .await;
            // A dangling link cannot be loaded (nothing is there): 404 or 403 both refuse it.
            let ok = a.status == want
                || (verb == "load" && path == "dangling.toml" && a.status == StatusCode::NOT_FOUND);
            assert!(
                ok,
                "{verb} {path}: {} {}",
                a.status,
                String::from_utf8_lossy(&a.body)
            );
            assert_eq!(a.error().1, "path");
        }
    }
    assert_eq!(
        post(
            &app,
            &format!("/api/load?{GRID}"),
            json!({"path": "missing.toml"})
        )
        .await
        .status,
        StatusCode::NOT_FOUND
    );
    // Nothing was written outside, and the dangling link still dangles.
    assert!(!outside.path().join("new.toml").exists());
    assert!(!outside.path().join("x.toml").exists());
    // A link that stays inside is fine.
    let f = decode(
        &post(
            &app,
            &format!("/api/load?{GRID}"),
            json!({"path": "inside.toml"}),
        )
        .await,
    );
    assert_eq!(f.surfaces.len(), 2);
    // A design file with a mistake: located, 422.
    std::fs::write(
        dir.path().join("bad.toml"),
        "title = \"x\"\n[operator]\nkind = 3\n",
    )
    .unwrap();
    let a = post(
        &app,
        &format!("/api/load?{GRID}"),
        json!({"path": "bad.toml"}),
    )
    .await;
    assert_eq!(a.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(a.error().0.starts_with("bad.toml:3:"), "{}", a.error().0);
}

#[tokio::test]
async fn reports_and_downloads() {
    let dir = root();
    let app = app(dir.path(), Some("examples/cup.toml"));
    let check = send(&app, "GET", "/api/check", None, &[]).await.json();
    let report = check["report"].as_str().unwrap();
    assert!(
        report.contains("condition errors") && report.contains("G0 ="),
        "{report}"
    );
    // The verdict as `pdeshape check` prints it, from the library's diagnostics.
    assert_eq!(check["verdict"], "ok");
    assert_eq!(check["conclusion"], "OK\n");
    assert_eq!(check["edges"], check["diagnostics"]["edges"]);
    assert_eq!(check["edges"].as_array().unwrap().len(), 1);
    let analyze = send(&app, "GET", "/api/analyze", None, &[]).await.json();
    assert!(analyze["total"]["area"].as_f64().unwrap() > 0.0);
    for (format, magic) in [
        ("obj", &b"# "[..]),
        ("stl", &b""[..]),
        ("ply", &b"ply"[..]),
        ("glb", &b"glTF"[..]),
        ("png", &b"\x89PNG"[..]),
    ] {
        let a = send(
            &app,
            "GET",
            &format!("/api/download?format={format}&{GRID}&size=64x48"),
            None,
            &[],
        )
        .await;
        assert_eq!(a.status, StatusCode::OK, "{format}");
        assert!(a.body.len() > 100 && a.body.starts_with(magic), "{format}");
    }
    // Curvature colouring comes with its range.
    let a = send(
        &app,
        "GET",
        &format!("/api/frame?{GRID}&color=gauss"),
        None,
        &[],
    )
    .await;
    let f = decode(&a);
    let range = f.scene["color_range"].as_array().unwrap();
    assert!(range[0].as_f64().unwrap() < range[1].as_f64().unwrap());
}

/// The seam tolerance of `/api/check`: the cup's smooth seam passes any tolerance; a tolerance
/// that is not an angle is a 400 naming `g1_tolerance`.
#[tokio::test]
async fn check_judges_seams_by_the_tolerance() {
    let dir = root();
    let app = app(dir.path(), Some("examples/cup.toml"));
    let check = send(&app, "GET", "/api/check?g1_tolerance=0", None, &[])
        .await
        .json();
    // G1 to rounding (about 1e-16 rad) is above 0: the seam fails at a zero tolerance.
    assert_eq!(check["verdict"], "fail");
    assert_eq!(check["edges"][0]["failed"], true);
    assert!(check["text"]
        .as_str()
        .unwrap()
        .starts_with("FAIL\nfail: shared edge 'base' u = 1 | 'bowl' u = 0 along 'belly'"));
    let check = send(&app, "GET", "/api/check", None, &[]).await.json();
    assert_eq!(check["verdict"], "ok");
    assert_eq!(check["g1_tolerance"], std::f64::consts::PI / 180.0);
    assert!(check["text"]
        .as_str()
        .unwrap()
        .starts_with("OK\n\ndesign: examples/cup.toml"));
    for bad in ["abc", "-1", "NaN", "inf"] {
        let a = send(
            &app,
            "GET",
            &format!("/api/check?g1_tolerance={bad}"),
            None,
            &[],
        )
        .await;
        assert_eq!(a.status, StatusCode::BAD_REQUEST, "{bad}");
        let (message, place) = a.error();
        assert_eq!(place, "g1_tolerance");
        assert!(message.contains(&format!("(got '{bad}')")), "{message}");
    }
}

/// The curvature tolerance of `/api/check`: the cup's belly (G1, with a curvature jump) passes
/// without one and above its G2 figure, fails below it (`g2_failed`, the text leading with
/// FAIL); a tolerance that is not a curvature is a 400 naming `g2_tolerance`.
#[tokio::test]
async fn check_judges_curvature_by_the_g2_tolerance() {
    let dir = root();
    let app = app(dir.path(), Some("examples/cup.toml"));
    let check = send(&app, "GET", "/api/check", None, &[]).await.json();
    assert_eq!(check["verdict"], "ok");
    assert_eq!(check["g2_tolerance"], serde_json::Value::Null);
    let g2 = check["edges"][0]["g2"].as_f64().unwrap();
    assert!(g2 > 1e-3, "{g2}");
    let below = send(
        &app,
        "GET",
        &format!("/api/check?g2_tolerance={}", 0.99 * g2),
        None,
        &[],
    )
    .await
    .json();
    assert_eq!(below["verdict"], "fail");
    assert_eq!(below["edges"][0]["failed"], true);
    assert_eq!(below["edges"][0]["g2_failed"], true);
    assert_eq!(below["edges"][0]["g1_failed"], false);
    assert!(below["text"]
        .as_str()
        .unwrap()
        .starts_with("FAIL\nfail: shared edge 'base' u = 1 | 'bowl' u = 0 along 'belly': G2 = "));
    let above = send(
        &app,
        "GET",
        &format!("/api/check?g2_tolerance={}", 1.01 * g2),
        None,
        &[],
    )
    .await
    .json();
    assert_eq!(above["verdict"], "ok");
    assert_eq!(above["g2_tolerance"], 1.01 * g2);
    for bad in ["abc", "-1", "NaN", "inf"] {
        let a = send(
            &app,
            "GET",
            &format!("/api/check?g2_tolerance={bad}"),
            None,
            &[],
        )
        .await;
        assert_eq!(a.status, StatusCode::BAD_REQUEST, "{bad}");
        let (message, place) = a.error();
        assert_eq!(place, "g2_tolerance");
        assert!(message.contains(&format!("(got '{bad}')")), "{message}");
    }
}

/// Curvature maps: a user range is taken as given, the default one lies within the true range
/// carried beside it; a range that is not `lo,hi` with `lo < hi` is a 400 naming `range`.
#[tokio::test]
async fn curvature_ranges() {
    let dir = root();
    let app = app(dir.path(), Some("examples/teacup.toml"));
    for color in ["gauss", "mean", "abs"] {
        let f = decode(
            &send(
                &app,
                "GET",
                &format!("/api/frame?{GRID}&color={color}"),
                None,
                &[],
            )
            .await,
        );
        let r: Vec<f64> = f.scene["color_range"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        let full: Vec<f64> = f.scene["color_full_range"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        assert!(r[0] < r[1] && full[0] <= full[1], "{color}: {r:?} {full:?}");
        // Within the true range (or its symmetric extension about 0), and narrower for the
        // teacup, whose handle is far more curved than its body.
        let reach = full[0].abs().max(full[1].abs());
        assert!(
            r[1] - r[0] < 0.5 * (full[1] - full[0]),
            "{color}: {r:?} {full:?}"
        );
        assert!(r[0] >= -reach && r[1] <= reach, "{color}: {r:?} {full:?}");
        if color == "abs" {
            assert!(full[0] >= 0.0, "{full:?}");
        }
    }
    let f = decode(
        &send(
            &app,
            "GET",
            &format!("/api/frame?{GRID}&color=mean&range=-0.5,2"),
            None,
            &[],
        )
        .await,
    );
    assert_eq!(f.scene["color_range"], json!([-0.5, 2.0]));
    for bad in ["1", "2,1", "a,b", "1,1", "0,inf"] {
        let a = send(
            &app,
            "GET",
            &format!("/api/frame?{GRID}&color=gauss&range={bad}"),
            None,
            &[],
        )
        .await;
        assert_eq!(a.status, StatusCode::BAD_REQUEST, "{bad}");
        assert_eq!(a.error().1, "range", "{bad}");
    }
    let a = send(
        &app,
        "GET",
        &format!("/api/frame?{GRID}&color=curly"),
        None,
        &[],
    )
    .await;
    assert_eq!(a.status, StatusCode::BAD_REQUEST);
    assert_eq!(
        a.error(),
        (
            "expected none, gauss, mean or abs (got 'curly')".to_string(),
            "color".to_string()
        )
    );
}

/// STEP and IGES downloads: the library's CAD writer, with a summary of the deviation in a
/// header; another format word is a 400.
#[tokio::test]
async fn cad_downloads() {
    let dir = root();
    let app = app(dir.path(), Some("examples/cup.toml"));
    for (format, magic) in [("step", "ISO-10303-21;"), ("igs", ""), ("iges", "")] {
        let a = send(
            &app,
            "GET",
            &format!("/api/download?format={format}"),
            None,
            &[],
        )
        .await;
        assert_eq!(a.status, StatusCode::OK, "{format}");
        assert!(
            a.body.starts_with(magic.as_bytes()) && a.body.len() > 1000,
            "{format}"
        );
        let summary = a
            .headers
            .get("x-pdeshape-cad")
            .unwrap()
            .to_str()
            .unwrap()
            .to_string();
        let fields: std::collections::HashMap<&str, &str> = summary
            .split("; ")
            .filter_map(|kv| kv.split_once('='))
            .collect();
        assert_eq!(fields["surfaces"], "2", "{summary}");
        assert_eq!(fields["certified"], "true", "{summary}");
        let deviation: f64 = fields["deviation"].parse().unwrap();
        let tolerance: f64 = fields["tolerance"].parse().unwrap();
        assert!(deviation > 0.0 && deviation <= tolerance, "{summary}");
        let disposition = a
            .headers
            .get("content-disposition")
            .unwrap()
            .to_str()
            .unwrap();
        assert_eq!(
            disposition,
            format!("attachment; filename=\"cup.{format}\"")
        );
    }
    let a = send(&app, "GET", "/api/download?format=dxf", None, &[]).await;
    assert_eq!(a.status, StatusCode::BAD_REQUEST);
    assert_eq!(a.error().1, "format");
    assert!(
        a.error().0.contains("step or igs (got 'dxf')"),
        "{}",
        a.error().0
    );
}

#[tokio::test]
async fn transforms_sliders_and_library_curves() {
    let dir = root();
    let app = app(dir.path(), None);
    let q = format!("/api/edit?{GRID}");
    let before = decode(&send(&app, "GET", &format!("/api/frame?{GRID}"), None, &[]).await);
    let p1 = curve(&before.scene, "rim")["control"][1].clone();
    // Translate the rim (§6.1): its control points are drawn moved; the spec keeps them.
    let t = decode(
        &post(
            &app,
            &q,
            json!({ "edit": { "edit": "transform", "name": "rim", "step": { "translate": [0.0, 0.0, 0.5] } } }),
        )
        .await,
    );
    let rim = curve(&t.scene, "rim");
    assert_eq!(
        rim["control"][1][2].as_f64().unwrap(),
        p1[2].as_f64().unwrap() + 0.5
    );
    assert_eq!(rim["spec"]["control"][1], p1);
    // A drag in world coordinates on the transformed curve lands where it was dropped.
    let d = decode(
        &post(
            &app,
            &q,
            json!({ "edit": { "edit": "move_control_point", "name": "rim", "index": 1,
                "point": [1.3, 0.0, 2.7] }, "world": true }),
        )
        .await,
    );
    let rim = curve(&d.scene, "rim");
    assert_eq!(rim["control"][1], json!([1.3, 0.0, 2.7]));
    assert_eq!(rim["spec"]["control"][1], json!([1.3, 0.0, 2.2]));
    // A slider gesture of `a` is one undo step; each value re-solves.
    let mut surfaces = Vec::new();
    for a in [1.5, 2.0, 2.5] {
        let f = decode(
            &post(
                &app,
                &q,
                json!({ "edit": { "edit": "set_smoothing", "patch": "body", "a": a }, "group": 42 }),
            )
            .await,
        );
        assert_eq!(f.scene["surfaces"][0]["operator"]["a"], a);
        surfaces.push(f.surfaces[0].2.clone());
    }
    assert_ne!(surfaces[0], surfaces[2]);
    let u = decode(&post(&app, &format!("/api/undo?{GRID}"), json!(null)).await);
    assert_eq!(u.scene["surfaces"][0]["operator"]["a"], 1.0);
    assert_eq!(u.surfaces[0].2, d.surfaces[0].2);
    // The v = 0 point of a circle (§6.4) and the derivative scale s.
    let mut base = curve(&u.scene, "base")["spec"].clone();
    base["v_origin"] = json!(0.5);
    let v = decode(
        &post(
            &app,
            &q,
            json!({ "edit": { "edit": "set_curve", "name": "base", "curve": base } }),
        )
        .await,
    );
    let mark = &curve(&v.scene, "base")["v0"]["point"];
    assert!(
        (mark[0].as_f64().unwrap() - 0.5f64.cos()).abs() < 1e-12,
        "{mark}"
    );
    let mut tangent = curve(&v.scene, "rim_tangent")["spec"].clone();
    assert_eq!(curve(&v.scene, "rim_tangent")["scale"], 1.0);
    tangent["scale"] = json!(2.0);
    let s = decode(
        &post(
            &app,
            &q,
            json!({ "edit": { "edit": "set_curve", "name": "rim_tangent", "curve": tangent } }),
        )
        .await,
    );
    assert_eq!(curve(&s.scene, "rim_tangent")["scale"], 2.0);
    assert_ne!(s.surfaces[0].2, v.surfaces[0].2);
    // A curve from the library made a B-spline, and a patch between two curves; then deleted.
    decode(
        &post(
            &app,
            &q,
            json!({ "edit": { "edit": "set_curve", "name": "top",
        "curve": { "type": "circle", "center": [0.0, 0.0, 3.5], "radius": 0.5 } } }),
        )
        .await,
    );
    let c = decode(
        &post(
            &app,
            &format!("/api/convert?{GRID}"),
            json!({ "name": "top" }),
        )
        .await,
    );
    assert_eq!(curve(&c.scene, "top")["kind"], "bspline");
    let patch = json!({ "name": "lid", "conditions": [
        { "u": 0.0, "curve": "rim" },
        { "u": 0.0, "derivative": 1, "curve": { "type": "derivative", "position": "rim", "direction": "top", "scale": 1.0 } },
        { "u": 1.0, "curve": "top" },
        { "u": 1.0, "derivative": 1, "curve": { "type": "derivative", "position": "rim", "direction": "top", "scale": 1.0 } },
    ]});
    let p = decode(
        &post(
            &app,
            &q,
            json!({ "edit": { "edit": "insert_patch", "index": 1, "patch": patch } }),
        )
        .await,
    );
    assert_eq!(p.surfaces.len(), 2);
    assert_eq!(p.scene["shared_curves"], json!(["rim"]));
    let r = decode(
        &post(
            &app,
            &q,
            json!({ "edit": { "edit": "remove_patch", "name": "lid" } }),
        )
        .await,
    );
    assert_eq!(r.surfaces.len(), 1);
    assert_eq!(r.surfaces[0].2, s.surfaces[0].2);
    // Deleting a curve a patch uses is refused with its place; an unused one goes.
    let a = post(
        &app,
        &q,
        json!({ "edit": { "edit": "set_curve", "name": "rim", "curve": null } }),
    )
    .await;
    assert_eq!(a.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(a.error().0.contains("rim"), "{:?}", a.error());
    let g = decode(
        &post(
            &app,
            &q,
            json!({ "edit": { "edit": "set_curve", "name": "top", "curve": null } }),
        )
        .await,
    );
    assert!(g.scene["curves"]
        .as_array()
        .unwrap()
        .iter()
        .all(|c| c["name"] != "top"));
}

/// Drawn points go to seven significant digits: within half a unit of the seventh digit, and
/// printed (as JSON prints a double) in at most seven digits; zero, tiny and non-finite numbers
/// stay as they are.
#[test]
fn drawn_points_are_sent_to_seven_digits() {
    use super::scene::short;
    for x in [
        1.0 / 3.0,
        -2.0 / 3.0,
        std::f64::consts::PI * 1e-5,
        123456.789123,
        9.999_999_95,
        -0.000_123_456_789,
        1.35 * std::f64::consts::FRAC_1_SQRT_2,
        6.02e23,
    ] {
        let y = short(x);
        let digits: String = serde_json::json!(y)
            .to_string()
            .chars()
            .take_while(|c| *c != 'e')
            .filter(char::is_ascii_digit)
            .collect();
        let significant = digits.trim_start_matches('0').len();
        assert!(significant <= 7, "{x} -> {y}");
        let unit = 10f64.powi(x.abs().log10().floor() as i32 - 6);
        assert!((y - x).abs() <= 0.5 * unit * (1.0 + 1e-9), "{x} -> {y}");
    }
    assert_eq!(short(0.0), 0.0);
    assert_eq!(short(1e-300), 1e-300);
    assert!(short(f64::NAN).is_nan());
    assert_eq!(short(f64::INFINITY), f64::INFINITY);
}
