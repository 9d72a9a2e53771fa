//! The designer's HTTP API (axum): every `/api/` request carries the per-launch token in the
//! `x-pdeshape-token` header; every request's Host must name this server by an IP literal or
//! `localhost` (or the `--host` name) with its port, and an Origin, when sent, must be this
//! server's own. Bodies are limited; design work runs on a blocking thread behind one lock.
//!
//! | request | answer |
//! |---|---|
//! | `GET /?token=T` | the page |
//! | `GET /socket?token=T` | a WebSocket carrying the `/api/` requests below ([`super::socket`]) |
//! | `GET /app.js`, `/view.js`, … | the page's modules |
//! | `GET /api/frame?nu&nv&color&range&comb` | a frame (scene JSON + meshes, [`super::scene`]); `color` none, gauss, mean or abs (absolute curvature), `range=lo,hi` its colour range (default: the 2nd–98th percentile by area, the true range in `color_full_range`); `comb=1` adds each curve's curvature comb |
//! | `POST /api/edit?nu&nv&color` `{"edit": Edit, "group": n?, "world": bool?}` | a frame |
//! | `POST /api/convert` `{"name": curve}` | a frame (the circle or ellipse as a B-spline) |
//! | `POST /api/spine?nu&nv&color` `{"patch", "index"?, "point"?, "carry"?, "group"?}` | a frame (a spine control point moved, §5.3) |
//! | `GET /api/local?name&from&to&at` | the frame of a local edit: `X₁ X₂ X₃`, `e₁ e₂ e₃` (§6.2) |
//! | `POST /api/local?nu&nv&color` `{"name", "from", "to", "at"?, "along", "across", "normal", "group"?}` | a frame |
//! | `POST /api/time?nu&nv&color` `{"t": t}` | a frame: the time-dependent design at `t` |
//! | `POST /api/undo`, `/api/redo` | a frame |
//! | `POST /api/load` `{"path": p}`, `POST /api/save` `{"path": p}` | a frame / `{"saved": p}` |
//! | `POST /api/new` | a frame (the starting design) |
//! | `GET /api/files` | `{"files": [...]}` |
//! | `GET /api/check?g1_tolerance&g2_tolerance`, `GET /api/analyze` | the `check` report, its `text` as `pdeshape check` prints it (the verdict first), its conclusion (failing seams, warnings, gaps, creases, `OK`, `ATTENTION` or `FAIL`), the `verdict` word, the G0/G1/G2 of shared edges (`failed` above the seam tolerance, radians, one degree by default, or above the curvature tolerance, 1/length, not judged unless given; `g1_failed`, `g2_failed` say which) and the diagnostics; the `analyze --json` numbers |
//! | `GET /api/download?format=obj\|stl\|ply\|glb\|png\|step\|igs&nu&nv&view&size` | the file; STEP and IGES with `x-pdeshape-cad: surfaces=N; deviation=D; certified=B; tolerance=T` |

use super::assets;
use super::error::ApiError;
use super::gestures::{self, LocalRequest, SpineRequest};
use super::library;
use super::scene::{self, Drawn};
use super::session::{Coloring, Session};
use super::socket;
use super::trimmed;
use axum::body::{Body, Bytes};
use axum::extract::{DefaultBodyLimit, Query, Request, State};
use axum::http::{header, HeaderMap, HeaderValue, StatusCode};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::Router;
use pdeshape::design::Edit;
use pdeshape::format::OutputFormat;
use serde::Deserialize;
use std::collections::HashMap;
use std::sync::Arc;
use std::time::Instant;
use tokio::sync::Mutex;

/// Largest request body.
pub(super) const MAX_BODY: usize = 256 * 1024;
/// Largest picture side for downloads.
const MAX_PICTURE: u32 = 4096;
pub(super) const TOKEN_HEADER: &str = "x-pdeshape-token";

/// What every handler shares.
#[derive(Clone)]
pub(super) struct AppState {
    pub session: Arc<Mutex<Session>>,
    pub token: Arc<str>,
    /// The port the server listens on (Host and Origin must name it).
    pub port: u16,
    /// A host name given with `--host` (accepted in Host besides IP literals and localhost).
    pub host_name: Option<String>,
}

/// The router of the designer.
pub(super) fn router(state: AppState) -> Router {
    let api = Router::new()
        .route("/frame", get(frame))
        .route("/edit", post(edit))
        .route("/convert", post(convert))
        .route("/spine", post(spine))
        .route("/local", get(local_frame).post(local))
        .route("/time", post(time))
        .route("/undo", post(undo))
        .route("/redo", post(redo))
        .route("/load", post(load))
        .route("/save", post(save))
        .route("/new", post(new_design))
        .route("/files", get(files))
        .route("/check", get(check))
        .route("/analyze", get(analyze))
        .route("/download", get(download))
        .fallback(|| async { ApiError::not_found("no such API request", "") })
        .layer(middleware::from_fn_with_state(state.clone(), api_guard));
    let pages = Router::new()
        .route("/", get(page))
        .route("/{file}", get(asset))
        .nest("/api", api);
    // The socket's requests run through the same routes and guards as HTTP's.
    let inner = guarded(pages.clone(), &state);
    let with_socket = pages.route(
        "/socket",
        get(move |st, q, headers, upgrade| socket::open(st, q, headers, inner.clone(), upgrade)),
    );
    guarded(with_socket, &state)
}

/// `routes` behind the checks of every request: Host and Origin, the body's size and time.
fn guarded(routes: Router<AppState>, state: &AppState) -> Router {
    routes
        .layer(middleware::from_fn_with_state(state.clone(), host_guard))
        .layer(DefaultBodyLimit::max(MAX_BODY))
        .layer(middleware::from_fn(edge))
        .with_state(state.clone())
}

/// A request's body must arrive within this time once its headers have; slower ones get 408.
pub(super) const BODY_TIMEOUT: std::time::Duration = std::time::Duration::from_secs(5);

/// The first and last step of every request. The body is read whole before anything answers
/// (a request answered with its body unread would have its connection reset by the kernel,
/// losing the answer): at most [`MAX_BODY`] bytes (413 after that) within [`BODY_TIMEOUT`]
/// (408). Both close the connection. And every error answer carries a JSON message: those
/// made below without one (405 for a wrong method, …) get one here.
async fn edge(request: Request, next: Next) -> Response {
    let (parts, body) = request.into_parts();
    let method = parts.method.clone();
    let read = tokio::time::timeout(BODY_TIMEOUT, axum::body::to_bytes(body, MAX_BODY)).await;
    let bytes = match read {
        Ok(Ok(b)) => b,
        Ok(Err(_)) => {
            return closing(ApiError::too_large(format!(
                "the request body is larger than {} KiB",
                MAX_BODY / 1024
            )))
        }
        Err(_) => {
            return closing(ApiError::timeout(format!(
                "the request body did not arrive within {} s",
                BODY_TIMEOUT.as_secs()
            )))
        }
    };
    let response = next
        .run(Request::from_parts(parts, Body::from(bytes)))
        .await;
    let status = response.status();
    let is_json = response
        .headers()
        .get(header::CONTENT_TYPE)
        .is_some_and(|v| v.as_bytes().starts_with(b"application/json"));
    if !(status.is_client_error() || status.is_server_error()) || is_json {
        return response;
    }
    let message = if status == StatusCode::METHOD_NOT_ALLOWED {
        let allowed = response
            .headers()
            .get(header::ALLOW)
            .and_then(|v| v.to_str().ok())
            .unwrap_or("another method")
            .to_string();
        format!("{method} is not allowed here; use {allowed}")
    } else {
        status
            .canonical_reason()
            .unwrap_or("the request failed")
            .to_lowercase()
    };
    let mut fixed = (status, axum::Json(ApiError::json(&message, ""))).into_response();
    for (name, value) in response.headers() {
        if name != header::CONTENT_TYPE && name != header::CONTENT_LENGTH {
            fixed.headers_mut().insert(name.clone(), value.clone());
        }
    }
    fixed
}

/// `e` as an answer that closes the connection.
fn closing(e: ApiError) -> Response {
    let mut r = e.into_response();
    r.headers_mut()
        .insert(header::CONNECTION, HeaderValue::from_static("close"));
    r
}

/// `a == b` in time independent of where they differ.
pub(super) fn same_secret(a: &[u8], b: &[u8]) -> bool {
    a.len() == b.len() && a.iter().zip(b).fold(0u8, |acc, (x, y)| acc | (x ^ y)) == 0
}

/// True for a Host (or an Origin's host part) naming this server: an IP literal or `localhost`
/// (or the `--host` name) with our port. A DNS name that resolves here (DNS rebinding) fails.
fn host_ok(state: &AppState, host: &str) -> bool {
    let Some((name, port)) = host.rsplit_once(':') else {
        return false;
    };
    if port.parse::<u16>().ok() != Some(state.port) {
        return false;
    }
    let bare = name
        .strip_prefix('[')
        .and_then(|n| n.strip_suffix(']'))
        .unwrap_or(name);
    bare.eq_ignore_ascii_case("localhost")
        || bare.parse::<std::net::IpAddr>().is_ok()
        || state
            .host_name
            .as_deref()
            .is_some_and(|h| h.eq_ignore_ascii_case(bare))
}

/// Host and Origin checks for every request.
async fn host_guard(State(state): State<AppState>, request: Request, next: Next) -> Response {
    let headers = request.headers();
    let host = headers.get(header::HOST).and_then(|h| h.to_str().ok());
    match host {
        Some(h) if host_ok(&state, h) => {}
        _ => return ApiError::forbidden(
            "the Host header does not name this server (open the URL printed by pdeshape serve)",
            "Host",
        )
        .into_response(),
    }
    if let Some(origin) = headers.get(header::ORIGIN) {
        let ok = origin
            .to_str()
            .ok()
            .and_then(|o| o.strip_prefix("http://"))
            .is_some_and(|o| Some(o) == host);
        if !ok {
            return ApiError::forbidden("requests from another origin are refused", "Origin")
                .into_response();
        }
    }
    next.run(request).await
}

/// The token check of every API request.
async fn api_guard(State(state): State<AppState>, request: Request, next: Next) -> Response {
    let given = request
        .headers()
        .get(TOKEN_HEADER)
        .map(|h| h.as_bytes().to_vec());
    match given {
        Some(t) if same_secret(&t, state.token.as_bytes()) => next.run(request).await,
        Some(_) => ApiError::forbidden("wrong token", TOKEN_HEADER).into_response(),
        None => ApiError::forbidden(
            "missing token (open the URL printed by pdeshape serve)",
            TOKEN_HEADER,
        )
        .into_response(),
    }
}

async fn page(State(state): State<AppState>, Query(q): Query<HashMap<String, String>>) -> Response {
    match q.get("token") {
        Some(t) if same_secret(t.as_bytes(), state.token.as_bytes()) => assets::page(),
        _ => ApiError::forbidden(
            "missing or wrong token: open the URL printed by pdeshape serve",
            "token",
        )
        .into_response(),
    }
}

async fn asset(axum::extract::Path(file): axum::extract::Path<String>) -> Response {
    assets::file(&file)
        .unwrap_or_else(|| ApiError::not_found(format!("no file '{file}'"), "").into_response())
}

/// Runs `f` on the session on a blocking thread; a panic becomes a 500 with its message.
async fn with_session<T: Send + 'static>(
    state: &AppState,
    f: impl FnOnce(&mut Session) -> Result<T, ApiError> + Send + 'static,
) -> Result<T, ApiError> {
    let mut guard = state.session.clone().lock_owned().await;
    let joined = tokio::task::spawn_blocking(move || {
        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| f(&mut guard)))
    })
    .await;
    match joined {
        Ok(Ok(result)) => result,
        Ok(Err(payload)) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".to_string());
            Err(ApiError::internal(format!("internal error: {what}")))
        }
        Err(e) => Err(ApiError::internal(format!("internal error: {e}"))),
    }
}

/// Grid and colouring of a frame.
#[derive(Clone, Copy)]
struct View {
    grid: (usize, usize),
    color: Coloring,
    /// The colour range of a curvature map (`range=lo,hi`), else a robust one.
    range: Option<(f64, f64)>,
    /// Curvature combs of the curves in the scene (`comb=1`).
    combs: bool,
}

fn parse_usize(q: &HashMap<String, String>, key: &str, default: usize) -> Result<usize, ApiError> {
    match q.get(key) {
        None => Ok(default),
        Some(s) => s.parse().map_err(|_| {
            ApiError::bad_request(format!("expected a whole number (got '{s}')"), key)
        }),
    }
}

fn view_of(q: &HashMap<String, String>) -> Result<View, ApiError> {
    let grid = (parse_usize(q, "nu", 64)?, parse_usize(q, "nv", 128)?);
    let color = match q.get("color").map(String::as_str) {
        None | Some("") | Some("none") => Coloring::Shaded,
        Some("gauss") => Coloring::Gauss,
        Some("mean") => Coloring::Mean,
        Some("abs") => Coloring::Absolute,
        Some(other) => {
            return Err(ApiError::bad_request(
                format!("expected none, gauss, mean or abs (got '{other}')"),
                "color",
            ))
        }
    };
    let range = match q.get("range").map(String::as_str) {
        None | Some("") => None,
        Some(r) => {
            let bad = || {
                ApiError::bad_request(
                    format!("expected two numbers lo,hi with lo < hi (got '{r}')"),
                    "range",
                )
            };
            let v: Vec<f64> = r
                .split(',')
                .map(|x| x.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .map_err(|_| bad())?;
            match v[..] {
                [lo, hi] if lo.is_finite() && hi.is_finite() && lo < hi => Some((lo, hi)),
                _ => return Err(bad()),
            }
        }
    };
    let combs = match q.get("comb").map(String::as_str) {
        None | Some("") | Some("0") => false,
        Some("1") => true,
        Some(other) => {
            return Err(ApiError::bad_request(
                format!("expected 0 or 1 (got '{other}')"),
                "comb",
            ))
        }
    };
    Ok(View {
        grid,
        color,
        range,
        combs,
    })
}

/// The frame of the session as it stands.
fn make_frame(s: &mut Session, view: View, started: Instant) -> Result<Vec<u8>, ApiError> {
    // The server's time in its phases (ms): the request and its edit with the re-solve, the
    // meshes (grids and trimmed triangles), the colours and the scene's curves.
    let ms = |t: Instant| t.elapsed().as_secs_f64() * 1e3;
    let edit_ms = ms(started);
    let t = Instant::now();
    s.meshes(view.grid)?;
    let meshes_ms = ms(t);
    let t = Instant::now();
    let colors = s.colors(view.grid, view.color, view.range)?;
    let colors_ms = ms(t);
    let t = Instant::now();
    let points = scene::curve_points(view.grid);
    let mut json = scene::scene(s.spec(), s.design().solved(), view.combs, points);
    json["server_split"] = serde_json::json!({
        "edit": edit_ms,
        "meshes": meshes_ms,
        "colors": colors_ms,
        "scene": ms(t),
    });
    json["version"] = s.version().into();
    json["file"] = s.file().into();
    json["can_undo"] = s.can_undo().into();
    json["can_redo"] = s.can_redo().into();
    json["grid"] = serde_json::json!([view.grid.0, view.grid.1]);
    json["time"] = s.timeline().map_or(serde_json::Value::Null, |t| t.json());
    json["frozen_at"] = s.frozen_at().into();
    if let Some(c) = &colors {
        json["color_range"] = serde_json::json!([c.range.0, c.range.1]);
        json["color_full_range"] = serde_json::json!([c.full.0, c.full.1]);
    }
    json["server_ms"] = (started.elapsed().as_secs_f64() * 1e3).into();
    let (meshes, trimmed) = s.drawn(view.grid)?;
    let drawn: Vec<Drawn> = meshes
        .iter()
        .enumerate()
        .map(|(k, m)| match trimmed.get(k) {
            Some(t) => Drawn::Trimmed(m, &t.mesh),
            None => Drawn::Grid(m),
        })
        .collect();
    // Colours of a trimmed surface follow its triangle mesh's vertices.
    let colors: Option<Vec<Vec<[u8; 3]>>> = colors.map(|c| {
        c.colors
            .into_iter()
            .enumerate()
            .map(|(k, c)| match trimmed.get(k) {
                Some(t) if c.len() == meshes[k].len() => trimmed::colors(t, &meshes[k], &c),
                _ => c,
            })
            .collect()
    });
    Ok(scene::frame(&json, &drawn, colors.as_deref()))
}

fn binary(bytes: Vec<u8>) -> Response {
    (
        [(
            header::CONTENT_TYPE,
            HeaderValue::from_static("application/octet-stream"),
        )],
        bytes,
    )
        .into_response()
}

/// A JSON body of type `T`, or a 400 naming what is wrong (line:col in the body).
fn parse_body<T: for<'de> Deserialize<'de>>(body: &Bytes) -> Result<T, ApiError> {
    serde_json::from_slice(body).map_err(|e| {
        ApiError::bad_request(
            // serde's words for the JSON types, in a designer's words.
            format!(
                "malformed request body: {}",
                pdeshape::spec::plain_message(&e.to_string())
            ),
            &format!("body:{}:{}", e.line(), e.column()),
        )
    })
}

async fn frame(
    State(state): State<AppState>,
    Query(q): Query<HashMap<String, String>>,
) -> Result<Response, ApiError> {
    let started = Instant::now();
    let view = view_of(&q)?;
    let bytes = with_session(&state, move |s| make_frame(s, view, started)).await?;
    Ok(binary(bytes))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EditRequest {
    edit: Edit,
    #[serde(default)]
    group: Option<u64>,
    /// A moved control point is given where it is drawn (through the curve's transform).
    #[serde(default)]
    world: bool,
}

async fn edit(
    State(state): State<AppState>,
    Query(q): Query<HashMap<String, String>>,
    body: Bytes,
) -> Result<Response, ApiError> {
    let started = Instant::now();
    let view = view_of(&q)?;
    let request: EditRequest = parse_body(&body)?;
    let bytes = with_session(&state, move |s| {
        let mut edit = request.edit;
        if request.world {
            if let Edit::MoveControlPoint { name, point, .. } = &mut edit {
                let cs = s.spec().curves.get(name).ok_or_else(|| {
                    ApiError::unprocessable(
                        format!("the design has no curve named '{name}'"),
                        "name",
                    )
                })?;
                *point = pdeshape::design::spec_point(cs, *point).ok_or_else(|| {
                    ApiError::unprocessable("the curve's transform cannot be inverted", "point")
                })?;
            }
        }
        s.apply(&edit, request.group, view.grid)?;
        make_frame(s, view, started)
    })
    .await?;
    Ok(binary(bytes))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct NameRequest {
    name: String,
}

async fn convert(
    State(state): State<AppState>,
    Query(q): Query<HashMap<String, String>>,
    body: Bytes,
) -> Result<Response, ApiError> {
    let started = Instant::now();
    let view = view_of(&q)?;
    let request: NameRequest = parse_body(&body)?;
    let bytes = with_session(&state, move |s| {
        let name = request.name;
        let kind = s.spec().curves.get(&name).map(|c| &c.kind);
        let is_ellipse = matches!(
            kind,
            Some(pdeshape::spec::CurveKind::Circle { .. })
                | Some(pdeshape::spec::CurveKind::Ellipse { .. })
        );
        if !is_ellipse {
            return Err(ApiError::unprocessable(
                format!("only a circle or an ellipse can be made a B-spline ('{name}' is not one)"),
                "name",
            ));
        }
        let curve = s
            .design()
            .solved()
            .curves
            .iter()
            .find(|c| c.name == name)
            .map(|c| c.curve.clone())
            .ok_or_else(|| ApiError::unprocessable(format!("no curve '{name}'"), "name"))?;
        let spec = library::bspline_from_ellipse(&*curve)
            .ok_or_else(|| ApiError::unprocessable("the curve is not a closed ellipse", "name"))?;
        s.apply(
            &Edit::SetCurve {
                name,
                curve: Some(spec),
            },
            None,
            view.grid,
        )?;
        make_frame(s, view, started)
    })
    .await?;
    Ok(binary(bytes))
}

async fn spine(
    State(state): State<AppState>,
    Query(q): Query<HashMap<String, String>>,
    body: Bytes,
) -> Result<Response, ApiError> {
    let started = Instant::now();
    let view = view_of(&q)?;
    let request: SpineRequest = parse_body(&body)?;
    let bytes = with_session(&state, move |s| {
        s.spine(&request, view.grid)?;
        make_frame(s, view, started)
    })
    .await?;
    Ok(binary(bytes))
}

fn parse_f64(q: &HashMap<String, String>, key: &str) -> Result<Option<f64>, ApiError> {
    match q.get(key).map(String::as_str) {
        None | Some("") => Ok(None),
        Some(s) => match s.parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(Some(x)),
            _ => Err(ApiError::bad_request(
                format!("expected a finite number (got '{s}')"),
                key,
            )),
        },
    }
}

async fn local_frame(
    State(state): State<AppState>,
    Query(q): Query<HashMap<String, String>>,
) -> Result<Response, ApiError> {
    let name = q
        .get("name")
        .cloned()
        .ok_or_else(|| ApiError::bad_request("missing (the curve's name)", "name"))?;
    let need = |key: &str| parse_f64(&q, key)?.ok_or_else(|| ApiError::bad_request("missing", key));
    let (from, to, at) = (need("from")?, need("to")?, parse_f64(&q, "at")?);
    let frame = with_session(&state, move |s| {
        gestures::local_frame(s.design().solved(), &name, from, to, at)
            .map(|f| gestures::frame_json(&f))
    })
    .await?;
    Ok(axum::Json(frame).into_response())
}

async fn local(
    State(state): State<AppState>,
    Query(q): Query<HashMap<String, String>>,
    body: Bytes,
) -> Result<Response, ApiError> {
    let started = Instant::now();
    let view = view_of(&q)?;
    let request: LocalRequest = parse_body(&body)?;
    let bytes = with_session(&state, move |s| {
        s.local(&request, view.grid)?;
        make_frame(s, view, started)
    })
    .await?;
    Ok(binary(bytes))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TimeRequest {
    t: f64,
}

async fn time(
    State(state): State<AppState>,
    Query(q): Query<HashMap<String, String>>,
    body: Bytes,
) -> Result<Response, ApiError> {
    let started = Instant::now();
    let view = view_of(&q)?;
    let request: TimeRequest = parse_body(&body)?;
    let bytes = with_session(&state, move |s| {
        s.set_time(request.t, view.grid)?;
        make_frame(s, view, started)
    })
    .await?;
    Ok(binary(bytes))
}

async fn undo(
    State(state): State<AppState>,
    Query(q): Query<HashMap<String, String>>,
) -> Result<Response, ApiError> {
    let started = Instant::now();
    let view = view_of(&q)?;
    let bytes = with_session(&state, move |s| {
        if !s.undo(view.grid)? {
            return Err(ApiError::unprocessable("nothing to undo", "undo"));
        }
        make_frame(s, view, started)
    })
    .await?;
    Ok(binary(bytes))
}

async fn redo(
    State(state): State<AppState>,
    Query(q): Query<HashMap<String, String>>,
) -> Result<Response, ApiError> {
    let started = Instant::now();
    let view = view_of(&q)?;
    let bytes = with_session(&state, move |s| {
        if !s.redo(view.grid)? {
            return Err(ApiError::unprocessable("nothing to redo", "redo"));
        }
        make_frame(s, view, started)
    })
    .await?;
    Ok(binary(bytes))
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PathRequest {
    path: String,
}

async fn load(
    State(state): State<AppState>,
    Query(q): Query<HashMap<String, String>>,
    body: Bytes,
) -> Result<Response, ApiError> {
    let started = Instant::now();
    let view = view_of(&q)?;
    let request: PathRequest = parse_body(&body)?;
    let bytes = with_session(&state, move |s| {
        s.load(&request.path)?;
        make_frame(s, view, started)
    })
    .await?;
    Ok(binary(bytes))
}

async fn new_design(
    State(state): State<AppState>,
    Query(q): Query<HashMap<String, String>>,
) -> Result<Response, ApiError> {
    let started = Instant::now();
    let view = view_of(&q)?;
    let bytes = with_session(&state, move |s| {
        s.reset()?;
        make_frame(s, view, started)
    })
    .await?;
    Ok(binary(bytes))
}

async fn save(State(state): State<AppState>, body: Bytes) -> Result<Response, ApiError> {
    let request: PathRequest = parse_body(&body)?;
    let saved = with_session(&state, move |s| s.save(&request.path)).await?;
    Ok(axum::Json(serde_json::json!({ "saved": saved })).into_response())
}

async fn files(State(state): State<AppState>) -> Result<Response, ApiError> {
    let list = with_session(&state, |s| Ok(super::files::list(s.root()))).await?;
    Ok(axum::Json(serde_json::json!({ "files": list })).into_response())
}

async fn check(
    State(state): State<AppState>,
    Query(q): Query<HashMap<String, String>>,
) -> Result<Response, ApiError> {
    let tolerance = match q.get("g1_tolerance") {
        None => pdeshape::diagnostics::SEAM_G1_TOLERANCE,
        Some(t) => match t.parse::<f64>() {
            Ok(x) if x.is_finite() && x >= 0.0 => x,
            _ => {
                return Err(ApiError::bad_request(
                    format!("expected an angle in radians, at least 0 (got '{t}')"),
                    "g1_tolerance",
                ))
            }
        },
    };
    // The curvature tolerance (1/length): not judged unless given (or given empty).
    let g2_tolerance = match q.get("g2_tolerance").map(String::as_str) {
        None | Some("") => None,
        Some(t) => match t.parse::<f64>() {
            Ok(x) if x.is_finite() && x >= 0.0 => Some(x),
            _ => {
                return Err(ApiError::bad_request(
                    format!("expected a curvature (1/length), at least 0 (got '{t}')"),
                    "g2_tolerance",
                ))
            }
        },
    };
    let (report, text, d) =
        with_session(&state, move |s| Ok(s.check(tolerance, g2_tolerance))).await?;
    let diagnostics = d.to_json();
    Ok(axum::Json(serde_json::json!({
        "report": report, "text": text, "conclusion": d.conclusion(), "warnings": d.warnings,
        "edges": diagnostics["edges"], "verdict": d.verdict.word(), "g1_tolerance": tolerance,
        "g2_tolerance": g2_tolerance, "diagnostics": diagnostics,
    }))
    .into_response())
}

async fn analyze(State(state): State<AppState>) -> Result<Response, ApiError> {
    let text = with_session(&state, |s| s.analyze()).await?;
    Ok((
        [(
            header::CONTENT_TYPE,
            HeaderValue::from_static("application/json"),
        )],
        text,
    )
        .into_response())
}

fn parse_triple(s: &str, key: &str) -> Result<pdeshape::Vec3, ApiError> {
    let bad = || ApiError::bad_request(format!("expected x,y,z (got '{s}')"), key);
    let parts: Vec<f64> = s
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad())?;
    if parts.len() != 3 || parts.iter().any(|x| !x.is_finite()) {
        return Err(bad());
    }
    let v = pdeshape::Vec3::new(parts[0], parts[1], parts[2]);
    let m = v.amax();
    if m == 0.0 {
        return Err(ApiError::bad_request("must not be the zero vector", key));
    }
    Ok(v / m)
}

/// A picture's size ([`pdeshape::format::parse_size`]), at most [`MAX_PICTURE`] a side for a
/// download.
fn parse_size(s: &str) -> Result<(u32, u32), ApiError> {
    let (w, h) = pdeshape::format::parse_size(s)
        .map_err(|e| ApiError::bad_request(crate::common::message_of(&e), "size"))?;
    if w > MAX_PICTURE || h > MAX_PICTURE {
        return Err(ApiError::bad_request(
            format!("expected WIDTHxHEIGHT, each 1 to {MAX_PICTURE} (got '{s}')"),
            "size",
        ));
    }
    Ok((w, h))
}

async fn download(
    State(state): State<AppState>,
    Query(q): Query<HashMap<String, String>>,
) -> Result<Response, ApiError> {
    let view = view_of(&q)?;
    let word = q
        .get("format")
        .ok_or_else(|| {
            ApiError::bad_request("missing (obj, stl, ply, glb, png, step or igs)", "format")
        })?
        .clone();
    let mut summary = None;
    let (bytes, mime) = if word == "png" {
        let size = parse_size(q.get("size").map(String::as_str).unwrap_or("800x600"))?;
        let dir = q.get("view").map(|v| parse_triple(v, "view")).transpose()?;
        let png = with_session(&state, move |s| s.picture(view.grid, size, dir)).await?;
        (png, "image/png")
    } else if let Some(f) = OutputFormat::from_name(&word).filter(|f| f.is_cad()) {
        let (bytes, text) = with_session(&state, move |s| s.cad(f)).await?;
        summary = Some(text);
        (bytes, "application/octet-stream")
    } else {
        let format = match OutputFormat::from_name(&word)
            .filter(|f| f.name() == word)
            .map(|f| (f, f.mesh()))
        {
            Some((
                OutputFormat::Obj | OutputFormat::Stl | OutputFormat::Ply | OutputFormat::Glb,
                Ok(f),
            )) => f,
            _ => {
                return Err(ApiError::bad_request(
                    format!("expected obj, stl, ply, glb, png, step or igs (got '{word}')"),
                    "format",
                ))
            }
        };
        let bytes = with_session(&state, move |s| s.download(format, view.grid)).await?;
        (bytes, "application/octet-stream")
    };
    let name = with_session(&state, |s| {
        Ok(std::path::Path::new(s.file())
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "design".to_string()))
    })
    .await?;
    let disposition = format!(
        "attachment; filename=\"{}.{word}\"",
        name.replace(
            |c: char| !c.is_ascii_alphanumeric() && c != '_' && c != '-',
            "_"
        )
    );
    let mut headers = HeaderMap::new();
    headers.insert(header::CONTENT_TYPE, HeaderValue::from_static(mime));
    if let Ok(v) = HeaderValue::from_str(&disposition) {
        headers.insert(header::CONTENT_DISPOSITION, v);
    }
    if let Some(v) = summary.and_then(|t| HeaderValue::from_str(&t).ok()) {
        headers.insert("x-pdeshape-cad", v);
    }
    Ok((StatusCode::OK, headers, Body::from(bytes)).into_response())
}
