//! API tests of the design operations, in-process: trimmed and attached designs drawn with their
//! holes, trim curves and attachments moved in `(u, v)`, spine handles, local edits, design
//! parameters and time.

use super::gestures::SpineRequest;
use super::session::Session;
use super::tests::{app as open, curve, decode, meshes_of_file, post, root, send, Frame, GRID};
use axum::http::StatusCode;
use serde_json::{json, Value};

const Q: &str = "/api/edit?nu=16&nv=32";

async fn frame(app: &axum::Router) -> Frame {
    decode(&send(app, "GET", &format!("/api/frame?{GRID}"), None, &[]).await)
}

async fn edit(app: &axum::Router, e: Value, group: Option<u64>) -> Frame {
    decode(&post(app, Q, json!({ "edit": e, "group": group })).await)
}

/// An edit that must be refused: its status and the place of its message.
async fn refused(app: &axum::Router, uri: &str, body: Value, status: StatusCode) -> String {
    let a = post(app, uri, body.clone()).await;
    assert_eq!(
        a.status,
        status,
        "{body}: {}",
        String::from_utf8_lossy(&a.body)
    );
    let (message, place) = a.error();
    assert!(!message.is_empty() && !message.contains('\n'), "{message}");
    place
}

fn surface(f: &Frame, scene_name: &str) -> usize {
    f.scene["surfaces"]
        .as_array()
        .unwrap()
        .iter()
        .position(|s| s["name"] == scene_name)
        .unwrap_or_else(|| panic!("no surface {scene_name}"))
}

/// The trimmed surface's triangles and positions are the library's trimmed mesh of a fresh
/// solve of the same design (the page draws the holes), and untrimmed surfaces keep the grid.
#[tokio::test]
async fn trimmed_surfaces_are_sent_as_triangle_meshes_with_their_holes() {
    let dir = root();
    for (file, trimmed) in [
        ("examples/trimmed_vase.toml", vec!["wall"]),
        ("examples/teacup.toml", vec!["bowl"]),
        ("examples/aeroplane.toml", vec!["fuselage"]),
        ("examples/cup.toml", vec![]),
    ] {
        let app = open(dir.path(), Some(file));
        let f = frame(&app).await;
        let spec =
            pdeshape::spec::parse_design(&std::fs::read_to_string(dir.path().join(file)).unwrap())
                .unwrap();
        let solved = pdeshape::design::solve_design(&spec).unwrap();
        for (k, s) in solved.surfaces.iter().enumerate() {
            let drawn = &f.triangles[k];
            assert_eq!(f.scene["surfaces"][k]["trimmed"], drawn.is_some());
            let Some(t) = solved.trim_of(k) else {
                assert!(drawn.is_none(), "{file}: {} has no holes", s.name);
                continue;
            };
            assert!(trimmed.contains(&s.name.as_str()), "{file}: {}", s.name);
            let (mesh, param) =
                pdeshape::trim::trimmed_mesh(s.surface(), 16, 32, &t.curves, t.method, &s.name)
                    .unwrap();
            assert_eq!(
                drawn.as_ref().unwrap(),
                &mesh.triangles,
                "{file}: {}",
                s.name
            );
            assert!(!param.remeshed().is_empty());
            let positions = &f.surfaces[k].2;
            assert_eq!(positions.len(), 3 * mesh.positions.len());
            for (p, q) in positions.chunks(3).zip(&mesh.positions) {
                for c in 0..3 {
                    assert!(
                        (p[c] - q[c]).abs() <= 1e-5 * (1.0 + q[c].abs()),
                        "{p:?} {q:?}"
                    );
                }
            }
        }
        let lines = f.scene["trim_lines"].as_array().unwrap().len();
        let curves: usize = solved.trims.iter().map(|t| t.curves.len()).sum();
        assert_eq!(lines, curves, "{file}");
    }
    // Curvature colours follow a trimmed mesh's vertices; pictures and mesh files have the holes.
    let app = open(dir.path(), Some("examples/teacup.toml"));
    let a = send(
        &app,
        "GET",
        &format!("/api/frame?{GRID}&color=mean"),
        None,
        &[],
    )
    .await;
    let coloured = decode(&a);
    assert!(coloured.scene["color_range"].is_array());
    assert!(coloured.triangles.iter().any(Option::is_some));
    assert!(
        coloured.colored.iter().all(|&c| c),
        "every surface, trimmed or not, is coloured"
    );
    for format in ["png", "obj"] {
        let a = send(
            &app,
            "GET",
            &format!("/api/download?format={format}&{GRID}&size=64x48"),
            None,
            &[],
        )
        .await;
        assert_eq!(a.status, StatusCode::OK, "{format}");
        assert!(a.body.len() > 100, "{format}");
    }
    // The (u, v) curves: three in the vase's one [[trims]] entry, sampled by the library.
    let app = open(dir.path(), Some("examples/trimmed_vase.toml"));
    let f = frame(&app).await;
    let trims = &f.scene["trims"];
    assert_eq!(trims[0]["surface"], "wall");
    assert_eq!(trims[0]["uv"].as_array().unwrap().len(), 3);
    let circle = &trims[0]["uv"][0];
    let p = circle[0].as_array().unwrap();
    assert!((p[0].as_f64().unwrap() - 0.66).abs() < 1e-12, "{p:?}");
    assert!((p[1].as_f64().unwrap() - 5.2).abs() < 1e-12, "{p:?}");
    assert_eq!(f.scene["surfaces"][0]["domain"]["periodic"], true);
    assert_eq!(f.scene["surfaces"][0]["domain"]["u"], json!([0.0, 1.0]));
}

/// A drag of a trim curve in (u, v) moves the hole (the triangles change with it) and undoes
/// in one step; holes are added, re-meshed by another method and removed; refused trims say
/// where.
#[tokio::test]
async fn trim_curves_are_dragged_added_and_removed() {
    let dir = root();
    let app = open(dir.path(), Some("examples/trimmed_vase.toml"));
    let before = frame(&app).await;
    let spec = before.scene["trims"][0]["spec"].clone();
    let mut last = None;
    for (k, u) in [0.52, 0.55, 0.58].iter().enumerate() {
        let mut moved = spec.clone();
        moved["curves"][0]["center"] = json!([u, 5.2 - 0.05 * k as f64]);
        let f = edit(
            &app,
            json!({ "edit": "set_trim", "index": 0, "trim": moved }),
            Some(11),
        )
        .await;
        assert_ne!(f.triangles[0], before.triangles[0]);
        last = Some(f);
    }
    let last = last.unwrap();
    assert_eq!(
        last.scene["trims"][0]["spec"]["curves"][0]["center"],
        json!([0.58, 5.2 - 0.05 * 2.0])
    );
    // Dragging the whole curve by offsets (the library's MoveTrimCurve) joins the same step.
    let m = edit(
        &app,
        json!({ "edit": "move_trim_curve", "index": 0, "curve": 0, "offset": [0.02, 0.0] }),
        Some(11),
    )
    .await;
    let c = m.scene["trims"][0]["spec"]["curves"][0]["center"].clone();
    assert!((c[0].as_f64().unwrap() - 0.60).abs() < 1e-12, "{c}");
    let undone = decode(&post(&app, &format!("/api/undo?{GRID}"), json!(null)).await);
    assert_eq!(undone.triangles, before.triangles);
    assert_eq!(undone.surfaces[0].2, before.surfaces[0].2);
    assert_eq!(undone.scene["trims"][0]["spec"], spec);
    assert_eq!(undone.scene["can_undo"], false);

    // A hole cut into the cup's bowl by the book's Laplace method, then removed.
    let app = open(dir.path(), Some("examples/cup.toml"));
    let cup = frame(&app).await;
    let bowl = surface(&cup, "bowl");
    assert!(cup.triangles[bowl].is_none());
    let hole = json!({ "surface": "bowl", "method": "laplace",
        "curves": [{ "type": "circle", "center": [0.5, 1.0], "radius": 0.15 }] });
    let cut = edit(
        &app,
        json!({ "edit": "insert_trim", "index": 0, "trim": hole }),
        None,
    )
    .await;
    assert!(cut.triangles[bowl].is_some());
    assert!(cut.triangles[1 - bowl].is_none());
    assert_eq!(cut.scene["trims"][0]["spec"]["method"], "laplace");
    let mut cdt = hole.clone();
    cdt["method"] = json!("cdt");
    let other = edit(
        &app,
        json!({ "edit": "set_trim", "index": 0, "trim": cdt }),
        None,
    )
    .await;
    assert_ne!(other.triangles[bowl], cut.triangles[bowl]);
    let gone = edit(&app, json!({ "edit": "remove_trim", "index": 0 }), None).await;
    assert!(gone.triangles[bowl].is_none());
    assert_eq!(gone.surfaces[bowl].2, cup.surfaces[bowl].2);

    // Refused: a hole across the domain's edge, a missing entry or curve; nothing changes.
    let version = gone.scene["version"].clone();
    let mut edge = hole.clone();
    edge["curves"][0]["center"] = json!([0.95, 1.0]);
    let place = refused(
        &app,
        Q,
        json!({ "edit": { "edit": "insert_trim", "index": 0, "trim": edge } }),
        StatusCode::UNPROCESSABLE_ENTITY,
    )
    .await;
    assert!(place.starts_with("trims[0]"), "{place}");
    let place = refused(
        &app,
        Q,
        json!({ "edit": { "edit": "remove_trim", "index": 9 } }),
        StatusCode::UNPROCESSABLE_ENTITY,
    )
    .await;
    assert_eq!(place, "trims[9]");
    refused(
        &app,
        Q,
        json!({ "edit": { "edit": "set_trim", "index": 0, "trim": { "curves": [{ "type": "blob" }] } } }),
        StatusCode::BAD_REQUEST,
    )
    .await;
    assert_eq!(frame(&app).await.scene["version"], version);
}

/// Moving an attachment's (u, v) curve moves the attached patch's end and the host's hole
/// (Fig. 5.11); one drag is one undo step.
#[tokio::test]
async fn attachments_slide_over_their_host() {
    let dir = root();
    let app = open(dir.path(), Some("examples/teacup.toml"));
    let before = frame(&app).await;
    let list = before.scene["attachments"].as_array().unwrap();
    let top = list.iter().find(|a| a["name"] == "top_root").unwrap();
    assert_eq!(top["host"], "bowl");
    assert_eq!(top["trim"], true);
    let v0 = top["uv"][0][1].as_f64().unwrap();
    let (bowl, handle) = (surface(&before, "bowl"), surface(&before, "handle_top"));
    let base = surface(&before, "base");
    let mut f = None;
    for _ in 0..2 {
        f = Some(
            edit(
                &app,
                json!({ "edit": "move_attachment", "name": "top_root", "offset": [0.0, 0.1] }),
                Some(21),
            )
            .await,
        );
    }
    let f = f.unwrap();
    let moved = f.scene["attachments"]
        .as_array()
        .unwrap()
        .iter()
        .find(|a| a["name"] == "top_root")
        .unwrap();
    assert!((moved["uv"][0][1].as_f64().unwrap() - v0 - 0.2).abs() < 1e-9);
    assert_ne!(f.surfaces[handle].2, before.surfaces[handle].2);
    assert_ne!(f.triangles[bowl], before.triangles[bowl]);
    // The bowl itself and the base are not re-solved.
    assert_eq!(f.surfaces[base].2, before.surfaces[base].2);
    let undone = decode(&post(&app, &format!("/api/undo?{GRID}"), json!(null)).await);
    assert_eq!(undone.surfaces[handle].2, before.surfaces[handle].2);
    assert_eq!(undone.triangles[bowl], before.triangles[bowl]);
    assert_eq!(undone.scene["can_undo"], false);
    let place = refused(
        &app,
        Q,
        json!({ "edit": { "edit": "move_attachment", "name": "rim", "offset": [0.0, 0.1] } }),
        StatusCode::UNPROCESSABLE_ENTITY,
    )
    .await;
    assert_eq!(place, "name");
}

fn spine_point(f: &Frame, k: usize, i: usize) -> [f64; 3] {
    let p = &f.scene["surfaces"][k]["spine_control"][i];
    std::array::from_fn(|c| p[c].as_f64().unwrap())
}

/// A spine handle dragged (§5.3): one undo step, the other patch untouched, saved as a
/// `[[spine]]` table that solves to the same surfaces.
#[tokio::test]
async fn spine_handles_are_dragged_saved_and_undone() {
    let dir = root();
    let app = open(dir.path(), Some("examples/cup.toml"));
    let before = frame(&app).await;
    let (bowl, base) = (surface(&before, "bowl"), surface(&before, "base"));
    assert_eq!(
        before.scene["surfaces"][bowl]["spine_control"]
            .as_array()
            .unwrap()
            .len(),
        4
    );
    assert_eq!(before.scene["surfaces"][bowl]["spine_carry"], Value::Null);
    let p = spine_point(&before, bowl, 2);
    let uri = format!("/api/spine?{GRID}");
    let mut last = None;
    for k in 1..=3 {
        let to = [p[0] + 0.1 * k as f64, p[1], p[2]];
        let f = decode(
            &post(
                &app,
                &uri,
                json!({ "patch": "bowl", "index": 2, "point": to, "group": 5 }),
            )
            .await,
        );
        assert_eq!(spine_point(&f, bowl, 2), to);
        last = Some(f);
    }
    let f = last.unwrap();
    assert_eq!(f.scene["surfaces"][bowl]["spine_carry"], "frame");
    assert_ne!(f.surfaces[bowl].2, before.surfaces[bowl].2);
    assert_eq!(f.surfaces[base].2, before.surfaces[base].2);
    // Saved: a [[spine]] table with the control points; the file solves to the same surfaces.
    let saved = post(&app, "/api/save", json!({ "path": "spined.toml" })).await;
    assert_eq!(saved.status, StatusCode::OK);
    let text = std::fs::read_to_string(dir.path().join("spined.toml")).unwrap();
    assert!(
        text.contains("[[spine]]") && text.contains("control"),
        "{text}"
    );
    for (k, m) in meshes_of_file(&dir.path().join("spined.toml"), 16, 32)
        .iter()
        .enumerate()
    {
        assert_eq!(m, &f.surfaces[k].2, "surface {k}");
    }
    // The sections only translated (the book's method): another surface, same spine.
    let t = decode(&post(&app, &uri, json!({ "patch": "bowl", "carry": "translate" })).await);
    assert_eq!(t.scene["surfaces"][bowl]["spine_carry"], "translate");
    assert_eq!(spine_point(&t, bowl, 2), spine_point(&f, bowl, 2));
    assert_ne!(t.surfaces[bowl].2, f.surfaces[bowl].2);
    decode(&post(&app, &format!("/api/undo?{GRID}"), json!(null)).await);
    let undone = decode(&post(&app, &format!("/api/undo?{GRID}"), json!(null)).await);
    assert_eq!(undone.surfaces[bowl].2, before.surfaces[bowl].2);
    assert_eq!(spine_point(&undone, bowl, 2), p);
    assert_eq!(undone.scene["can_undo"], false);
    // Refused requests.
    let cases = [
        (
            json!({ "patch": "bowl", "index": 4, "point": [0, 0, 0] }),
            StatusCode::UNPROCESSABLE_ENTITY,
            "index",
        ),
        (
            json!({ "patch": "lid", "index": 0, "point": [0, 0, 0] }),
            StatusCode::UNPROCESSABLE_ENTITY,
            "patch",
        ),
        (
            json!({ "index": 0, "point": [0, 0, 0] }),
            StatusCode::UNPROCESSABLE_ENTITY,
            "patch",
        ),
        (json!({ "patch": "bowl" }), StatusCode::BAD_REQUEST, "index"),
        (
            json!({ "patch": "bowl", "index": 1 }),
            StatusCode::BAD_REQUEST,
            "point",
        ),
        (
            json!({ "patch": "bowl", "point": [0, 0, 0] }),
            StatusCode::BAD_REQUEST,
            "index",
        ),
        (
            json!({ "patch": "bowl", "carry": "bend" }),
            StatusCode::BAD_REQUEST,
            "body:1:",
        ),
        (
            json!({ "patch": "bowl", "index": 1, "point": [0, 0] }),
            StatusCode::BAD_REQUEST,
            "body:1:",
        ),
    ];
    for (body, status, place) in cases {
        let got = refused(&app, &uri, body.clone(), status).await;
        assert!(got.starts_with(place), "{body}: {got}");
    }
    assert_eq!(frame(&app).await.scene["can_undo"], false);
}

/// A spine drag of a trimmed patch re-uses its re-meshed parameter domain (only the positions
/// are gathered again); moving a hole re-meshes it. (A host of attachments keeps its spine:
/// the library refuses curves on spine-edited patches, and says so.)
#[tokio::test]
async fn a_spine_drag_of_a_trimmed_patch_keeps_its_parameter_mesh() {
    let dir = root();
    let mut s =
        Session::open(dir.path().to_path_buf(), Some("examples/trimmed_vase.toml")).unwrap();
    let grid = (16, 32);
    s.meshes(grid).unwrap();
    let first = s.remeshed();
    assert_eq!(first, 1);
    let before = s.drawn(grid).unwrap().1.get(0).unwrap().mesh.clone();
    for (k, x) in [0.1, 0.2].iter().enumerate() {
        let request: SpineRequest = serde_json::from_value(json!({
            "patch": "wall", "index": 1, "point": [x, 0.0, 1.0], "group": 1 }))
        .unwrap();
        s.spine(&request, grid).unwrap();
        assert_eq!(s.version(), k as u64 + 1);
    }
    let after = s.drawn(grid).unwrap().1.get(0).unwrap().mesh.clone();
    assert_eq!(s.remeshed(), first, "the parameter mesh was made again");
    assert_eq!(after.triangles, before.triangles);
    assert_ne!(after.positions, before.positions);
    let moved = pdeshape::design::Edit::MoveTrimCurve {
        index: 0,
        curve: 0,
        offset: [0.0, 0.05],
    };
    s.apply(&moved, None, grid).unwrap();
    s.meshes(grid).unwrap();
    assert_eq!(s.remeshed(), first + 1);
    // The teacup's bowl hosts the handle: its spine stays, with the library's reason.
    let mut cup = Session::open(dir.path().to_path_buf(), Some("examples/teacup.toml")).unwrap();
    let request: SpineRequest = serde_json::from_value(json!({
        "patch": "bowl", "index": 1, "point": [0.2, 0.1, 1.3] }))
    .unwrap();
    let e = cup.spine(&request, grid).unwrap_err();
    assert_eq!(e.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert!(e.message.contains("spine"), "{}", e.message);
}

fn point(v: &Value) -> [f64; 3] {
    std::array::from_fn(|c| v[c].as_f64().unwrap())
}

/// A local edit (§6.2): the frame comes from the library, a drag is one local edit around the
/// curve as it was (not a local edit of a local edit) and one undo step.
#[tokio::test]
async fn local_edits_are_one_edit_per_drag() {
    let dir = root();
    let app = open(dir.path(), Some("examples/cup.toml"));
    let before = frame(&app).await;
    let lf = send(&app, "GET", "/api/local?name=rim&from=0.5&to=2", None, &[])
        .await
        .json();
    // The cup's rim: centre (0, 0, 2.4), radius 1.35; the handle at the midpoint 1.25.
    let x3 = point(&lf["x3"]);
    let want = [1.35 * 1.25f64.cos(), 1.35 * 1.25f64.sin(), 2.4];
    for c in 0..3 {
        assert!((x3[c] - want[c]).abs() < 1e-12, "{x3:?}");
    }
    assert_eq!(lf["at"], 1.25);
    let e2 = point(&lf["e2"]);
    let uri = format!("/api/local?{GRID}");
    let mut last = None;
    for across in [0.1, 0.2, 0.3] {
        last = Some(decode(
            &post(
                &app,
                &uri,
                json!({ "name": "rim", "from": 0.5, "to": 2.0, "across": across, "group": 8 }),
            )
            .await,
        ));
    }
    let f = last.unwrap();
    let rim = curve(&f.scene, "rim");
    assert_eq!(rim["spec"]["type"], "local");
    assert_eq!(rim["spec"]["curve"]["type"], "circle", "{}", rim["spec"]);
    assert_eq!(rim["spec"]["across"], 0.3);
    assert_ne!(f.surfaces, before.surfaces);
    // The handle moved by 0.3 e2.
    let moved = send(&app, "GET", "/api/local?name=rim&from=0.5&to=2", None, &[])
        .await
        .json();
    let x3m = point(&moved["x3"]);
    for c in 0..3 {
        assert!((x3m[c] - x3[c] - 0.3 * e2[c]).abs() < 1e-9, "{x3m:?}");
    }
    let saved = post(&app, "/api/save", json!({ "path": "lip.toml" })).await;
    assert_eq!(saved.status, StatusCode::OK);
    let text = std::fs::read_to_string(dir.path().join("lip.toml")).unwrap();
    assert!(text.contains("\"local\""), "{text}");
    let undone = decode(&post(&app, &format!("/api/undo?{GRID}"), json!(null)).await);
    assert_eq!(curve(&undone.scene, "rim")["spec"]["type"], "circle");
    assert_eq!(undone.surfaces, before.surfaces);
    assert_eq!(undone.scene["can_undo"], false);
    // Refused.
    let place = refused(
        &app,
        &uri,
        json!({ "name": "rim", "from": 1.0, "to": 1.0, "across": 0.1 }),
        StatusCode::UNPROCESSABLE_ENTITY,
    )
    .await;
    assert!(place.ends_with("to"), "{place}");
    refused(
        &app,
        &uri,
        json!({ "name": "lid", "from": 0.5, "to": 2.0 }),
        StatusCode::UNPROCESSABLE_ENTITY,
    )
    .await;
    refused(
        &app,
        &uri,
        json!({ "name": "rim", "to": 2.0 }),
        StatusCode::BAD_REQUEST,
    )
    .await;
    for q in [
        "name=rim&to=2",
        "name=rim&from=x&to=2",
        "from=0&to=1",
        "name=rim&from=0&to=1&at=inf",
    ] {
        let a = send(&app, "GET", &format!("/api/local?{q}"), None, &[]).await;
        assert_eq!(a.status, StatusCode::BAD_REQUEST, "{q}");
    }
    let a = send(
        &app,
        "GET",
        "/api/local?name=rim&from=0.5&to=2&at=3",
        None,
        &[],
    )
    .await;
    assert_eq!(a.status, StatusCode::UNPROCESSABLE_ENTITY);
    assert_eq!(a.error().1, "at");
    assert_eq!(frame(&app).await.scene["can_undo"], false);
}

/// `[[parameters]]` are listed with their bounds; a slider gesture is one undo step; a value
/// outside the bounds is refused with its place.
#[tokio::test]
async fn design_parameters_are_listed_and_set() {
    let dir = root();
    let app = open(dir.path(), Some("examples/swirl_port_params.toml"));
    let before = frame(&app).await;
    let list = before.scene["parameters"].as_array().unwrap();
    let names: Vec<&str> = list.iter().map(|p| p["name"].as_str().unwrap()).collect();
    assert_eq!(names, ["x1", "y1", "z1", "theta", "s", "twist"]);
    let theta = &list[3];
    assert_eq!(theta["kind"], "angle");
    let (lo, hi) = (
        theta["min"].as_f64().unwrap(),
        theta["max"].as_f64().unwrap(),
    );
    assert!(lo < hi);
    let mut last = None;
    for k in 1..=3 {
        let v = lo + (hi - lo) * k as f64 / 4.0;
        let f = edit(
            &app,
            json!({ "edit": "set_parameter", "name": "theta", "value": v }),
            Some(3),
        )
        .await;
        assert_eq!(f.scene["parameters"][3]["value"], v);
        last = Some(f);
    }
    assert_ne!(last.unwrap().surfaces, before.surfaces);
    let undone = decode(&post(&app, &format!("/api/undo?{GRID}"), json!(null)).await);
    assert_eq!(undone.surfaces, before.surfaces);
    assert_eq!(undone.scene["can_undo"], false);
    let place = refused(
        &app,
        Q,
        json!({ "edit": { "edit": "set_parameter", "name": "theta", "value": hi + 1.0 } }),
        StatusCode::UNPROCESSABLE_ENTITY,
    )
    .await;
    assert_eq!(place, "parameters[3].value");
    refused(
        &app,
        Q,
        json!({ "edit": { "edit": "set_parameter", "name": "phi", "value": 0.0 } }),
        StatusCode::UNPROCESSABLE_ENTITY,
    )
    .await;
}

/// The design of a timed file at `t`, solved from scratch.
fn timed_meshes(path: &std::path::Path, t: f64) -> Vec<Vec<f32>> {
    let text = std::fs::read_to_string(path).unwrap();
    let spec = pdeshape::spec::time::parse_timed(&text)
        .unwrap()
        .at(t)
        .unwrap();
    let solved = pdeshape::design::solve_design(&spec).unwrap();
    solved
        .meshes(16, 32)
        .unwrap()
        .iter()
        .map(|m| m.positions.iter().flatten().copied().collect())
        .collect()
}

/// A time-dependent design shows its timeline; the design at `t` is the library's, solved
/// incrementally (equal to a fresh solve); an edit makes it a still design.
#[tokio::test]
async fn time_dependent_designs_are_shown_at_any_time() {
    let dir = root();
    let app = open(dir.path(), Some("examples/anim/ventricle.toml"));
    let start = frame(&app).await;
    let time = &start.scene["time"];
    assert_eq!(time["kind"], "timed");
    assert_eq!(time["start"], 0.0);
    assert_eq!(time["end"], 0.8);
    assert_eq!(time["loop"], true);
    assert_eq!(time["frames"], 48);
    assert_eq!(time["t"], 0.0);
    let uri = format!("/api/time?{GRID}");
    let f = decode(&post(&app, &uri, json!({ "t": 0.4 })).await);
    assert_eq!(f.scene["time"]["t"], 0.4);
    assert_eq!(f.scene["can_undo"], false);
    assert_ne!(f.surfaces, start.surfaces);
    let path = dir.path().join("examples/anim/ventricle.toml");
    let fresh = timed_meshes(&path, 0.4);
    for (k, m) in fresh.iter().enumerate() {
        assert_eq!(m, &f.surfaces[k].2, "surface {k}");
    }
    let back = decode(&post(&app, &uri, json!({ "t": 0.0 })).await);
    assert_eq!(back.surfaces, start.surfaces);
    // Refused: outside [start, end], not a number, an unknown key.
    for (body, status) in [
        (json!({ "t": 0.9 }), StatusCode::BAD_REQUEST),
        (json!({ "t": -1.0 }), StatusCode::BAD_REQUEST),
        (json!({ "t": "0.1" }), StatusCode::BAD_REQUEST),
        (json!({}), StatusCode::BAD_REQUEST),
        (json!({ "t": 0.1, "speed": 2 }), StatusCode::BAD_REQUEST),
    ] {
        refused(&app, &uri, body, status).await;
    }
    // Saving over the animated file would lose its formulas: refused; another name is fine.
    let a = post(
        &app,
        "/api/save",
        json!({ "path": "examples/anim/ventricle.toml" }),
    )
    .await;
    assert_eq!(a.status, StatusCode::UNPROCESSABLE_ENTITY);
    let a = post(&app, "/api/save", json!({ "path": "beat.toml" })).await;
    assert_eq!(a.status, StatusCode::OK);
    // An edit makes it the still design at the time shown.
    decode(&post(&app, &uri, json!({ "t": 0.2 })).await);
    let e = edit(&app, json!({ "edit": "set_modes", "modes": 6 }), None).await;
    assert_eq!(e.scene["time"], Value::Null);
    assert_eq!(e.scene["frozen_at"], 0.2);
    let place = refused(
        &app,
        &uri,
        json!({ "t": 0.3 }),
        StatusCode::UNPROCESSABLE_ENTITY,
    )
    .await;
    assert_eq!(place, "t");

    // The fish swims: its spine wave follows t.
    let app = open(dir.path(), Some("examples/anim/fish.toml"));
    let f0 = frame(&app).await;
    assert_eq!(f0.scene["time"]["loop"], true);
    assert_eq!(f0.scene["surfaces"][0]["spine_wave"], true);
    let f1 = decode(&post(&app, &uri, json!({ "t": 0.25 })).await);
    assert_ne!(f1.surfaces, f0.surfaces);
    let fresh = timed_meshes(&dir.path().join("examples/anim/fish.toml"), 0.25);
    assert_eq!(fresh[0], f1.surfaces[0].2);

    // A morph between two designs inside the start directory.
    let app = open(dir.path(), Some("examples/anim/glass_morph.toml"));
    let m0 = frame(&app).await;
    assert_eq!(m0.scene["time"]["kind"], "morph");
    assert_eq!(m0.scene["time"]["epsilon"], 0.0);
    let m1 = decode(&post(&app, &uri, json!({ "t": 2.0 })).await);
    assert_eq!(m1.scene["time"]["epsilon"], 1.0);
    assert_ne!(m1.surfaces, m0.surfaces);

    // A design that does not depend on time has no timeline.
    let app = open(dir.path(), Some("examples/cup.toml"));
    assert_eq!(frame(&app).await.scene["time"], Value::Null);
    let place = refused(
        &app,
        &uri,
        json!({ "t": 0.0 }),
        StatusCode::UNPROCESSABLE_ENTITY,
    )
    .await;
    assert_eq!(place, "t");
}

/// A morph whose source lies outside the start directory is not read.
#[tokio::test]
async fn a_morph_reads_only_inside_the_start_directory() {
    let dir = root();
    let outside = tempfile::tempdir().unwrap();
    let away = outside.path().join("away.toml");
    std::fs::copy(super::tests::examples().join("cup.toml"), &away).unwrap();
    let text = format!(
        "[time]\nend = 1.0\nframes = 3\n[morph]\nsource = \"{}\"\ntarget = \"examples/cup.toml\"\n",
        away.display()
    );
    std::fs::write(dir.path().join("sneaky.toml"), text).unwrap();
    std::fs::write(
        dir.path().join("missing.toml"),
        "[time]\nend = 1.0\nframes = 3\n[morph]\nsource = \"nowhere.toml\"\ntarget = \"examples/cup.toml\"\n",
    )
    .unwrap();
    let app = open(dir.path(), None);
    let load = format!("/api/load?{GRID}");
    let a = post(&app, &load, json!({ "path": "sneaky.toml" })).await;
    assert_eq!(
        a.status,
        StatusCode::FORBIDDEN,
        "{}",
        String::from_utf8_lossy(&a.body)
    );
    assert_eq!(a.error().1, "morph.source");
    let a = post(&app, &load, json!({ "path": "missing.toml" })).await;
    assert_eq!(a.status, StatusCode::NOT_FOUND);
    assert_eq!(frame(&app).await.scene["version"], 0);
}

/// Curves and trim lines are sampled at the grid's resolution (a gesture's half grid samples
/// them half as finely), between 32 and 128 points a curve; a derivative curve, not drawn, at 32
/// for its centroid; every frame says how many points each curve was asked for.
#[tokio::test]
async fn curves_are_sampled_at_the_grids_resolution() {
    let dir = root();
    let app = open(dir.path(), Some("examples/teacup.toml"));
    for (grid, per_curve) in [
        ("nu=64&nv=128", 128),
        ("nu=32&nv=64", 64),
        ("nu=8&nv=16", 32),
    ] {
        let f = decode(&send(&app, "GET", &format!("/api/frame?{grid}"), None, &[]).await);
        for name in ["rim", "top_root"] {
            let c = curve(&f.scene, name);
            assert_eq!(c["samples"], json!(per_curve), "{grid} {name}");
            assert_eq!(
                c["points"].as_array().unwrap().len(),
                per_curve,
                "{grid} {name}"
            );
        }
        let field = curve(&f.scene, "top_arrive");
        assert_eq!(field["role"], json!("derivative"));
        assert_eq!(field["samples"], json!(32), "{grid}");
        assert!(field["points"].as_array().unwrap().is_empty());
        assert!(field["centroid"].is_array());
        let lines = f.scene["trim_lines"].as_array().unwrap();
        assert_eq!(lines.len(), 2);
        for l in lines {
            assert_eq!(l.as_array().unwrap().len(), 2 * per_curve, "{grid}");
        }
    }
}
