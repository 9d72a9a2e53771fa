//! What the page draws, sent after every change: a JSON scene (curves, control points,
//! derivative vectors, spines with their Bézier control points, `v = 0` marks, shared edges,
//! patches with their operators and parameter domains, the `(u, v)` curves of trims and
//! attachments ([`super::uv`]) with their images on the surfaces, design parameters) and the
//! meshes in a compact binary frame. The G0/G1 of shared edges is measured on request
//! (`GET /api/check`, the library's diagnostics), not in every frame of a drag.
//!
//! Frame layout (little-endian): `b"PDSF"`, `u32` JSON length, the JSON (UTF-8) padded with
//! spaces to a multiple of 4, `u32` surface count; then per surface `u32 nu, u32 nv, u32 flags`
//! (bit 0: periodic in v, bit 1: colours follow, bit 2: triangles follow), and with bit 2
//! `u32 vertices, u32 triangles`; then positions `f32 × 3 × n`, normals `i16 × 3 × n` (unit
//! vectors scaled by 32767), colours `u8 × 3 × n` if present, and with bit 2 the triangles
//! `u32 × 3 × triangles`, each block padded to a multiple of 4 bytes. `n` is `nu·nv` for a
//! grid, whose faces are implied (quads `(i,j) (i+1,j) (i+1,j+1) (i,j+1)`, wrapping in v when
//! periodic), or the vertex count of a trimmed surface's triangle mesh (holes cut out).
//!
//! Points that are only drawn (curves' polylines, derivative vectors, spines, trim lines) go
//! to seven significant digits ([`short`]); control points, spine handles, the other points a
//! user types, snaps to or rotates about, and the curvature combs (sent only while shown, and
//! read as exact curvatures) are sent exact.

use pdeshape::curve::{Curve, Domain};
use pdeshape::design::SolvedDesign;
use pdeshape::mesh::{GridMesh, TriMesh};
use pdeshape::spec::{CurveKind, DesignSpec, OperatorSpec, SpineCarry};
use serde_json::{json, Value};
use std::collections::BTreeSet;

/// Points per drawn curve on the default grid (and at most).
const CURVE_POINTS: usize = 128;
/// Points per drawn curve at least, on the coarsest grids.
const MIN_CURVE_POINTS: usize = 32;
/// Samples of a curve that is not drawn (a derivative condition's vectors) for its centroid.
const CENTROID_POINTS: usize = 32;

/// Points per drawn curve for a frame on `grid`: as many as the grid has columns, between
/// [`MIN_CURVE_POINTS`] and [`CURVE_POINTS`], so the coarse frames of a gesture (a grid half as
/// fine) also sample their curves half as finely; trim lines take twice as many.
pub(super) fn curve_points(grid: (usize, usize)) -> usize {
    grid.1.clamp(MIN_CURVE_POINTS, CURVE_POINTS)
}
/// Teeth of the curvature combs across a shared edge (per side).
const SEAM_COMB_TEETH: usize = 64;
/// Derivative vectors drawn per derivative condition (a power of two: on an attachment their
/// `v` are the solve's samples, whose host jets are kept).
const VECTORS: usize = 32;

fn p3(p: &pdeshape::Vec3) -> [f64; 3] {
    [p.x, p.y, p.z]
}

/// `x` to seven significant digits, as the double nearest that decimal (so that its shortest
/// form, which JSON carries, is at most seven digits long); zero, tiny (below 1e-16) and
/// non-finite numbers as they are.
pub(super) fn short(x: f64) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return x;
    }
    let e = 6 - x.abs().log10().floor() as i32;
    if e > 22 {
        return x;
    }
    let p = 10f64.powi(e.abs());
    let y = if e >= 0 {
        (x * p).round() / p
    } else {
        (x / p).round() * p
    };
    if y.is_finite() {
        y
    } else {
        x
    }
}

/// A point that is only drawn (polylines, vectors, spines, trim lines), to seven
/// significant digits ([`short`]: WebGL draws in single precision anyway), in about half the
/// JSON of a double's shortest form; `None` where it is not finite. Points a user types or
/// snaps to (control points, spine handles, the `v = 0` marks, centroids) stay exact ([`p3`]).
pub(super) fn d3(p: &pdeshape::Vec3) -> Option<[f64; 3]> {
    finite(p).then(|| [short(p.x), short(p.y), short(p.z)])
}

/// Finite points only (JSON has no NaN).
fn finite(p: &pdeshape::Vec3) -> bool {
    p.iter().all(|x| x.is_finite())
}

/// `count` points along a curve: over `[0, 2π)` (closed) or its interval (finite ones only).
fn samples(c: &dyn Curve, count: usize) -> (Vec<pdeshape::Vec3>, bool) {
    let (a, b, closed, n) = match c.domain() {
        Domain::Periodic => (0.0, pdeshape::TAU, true, count as f64),
        Domain::Interval(a, b) => (a, b, false, (count - 1) as f64),
    };
    let points = (0..count)
        .map(|k| c.point(a + (b - a) * k as f64 / n))
        .filter(finite)
        .collect();
    (points, closed)
}

/// The curvature comb of a curve: at the parameters of [`samples`], the point and the
/// curvature vector `κ N = ((C' × C'') × C') / |C'|⁴` from the curve's exact derivatives (points
/// where either is not finite, or `C' = 0`, are left out).
fn comb(c: &dyn Curve, count: usize) -> Vec<[[f64; 3]; 2]> {
    let (a, b, n) = match c.domain() {
        Domain::Periodic => (0.0, pdeshape::TAU, count as f64),
        Domain::Interval(a, b) => (a, b, (count - 1) as f64),
    };
    let mut jet = [pdeshape::Vec3::zeros(); 3];
    (0..count)
        .filter_map(|k| {
            c.jet(a + (b - a) * k as f64 / n, &mut jet);
            let [p, d1, d2] = jet;
            let speed2 = d1.norm_squared();
            if speed2 == 0.0 {
                return None;
            }
            let kappa = d1.cross(&d2).cross(&d1) / (speed2 * speed2);
            (finite(&p) && finite(&kappa)).then(|| [p3(&p), p3(&kappa)])
        })
        .collect()
}

fn operator_json(op: &Option<OperatorSpec>) -> Value {
    match op {
        Some(OperatorSpec::Polyharmonic { order, a }) => {
            json!({ "kind": "polyharmonic", "order": order, "a": a })
        }
        Some(other) => json!({ "kind": "other", "text": format!("{other:?}") }),
        None => Value::Null,
    }
}

/// The scene of a solved design; `combs`: with the curvature comb of every curve that is not a
/// derivative curve (the page asks for them only while it shows them).
/// The scene of a frame: curves sampled at `per_curve` points each ([`curve_points`]), trim
/// lines at twice that.
pub(super) fn scene(
    spec: &DesignSpec,
    solved: &SolvedDesign,
    combs: bool,
    per_curve: usize,
) -> Value {
    // Curves used as derivative conditions hold vectors, not points: they are drawn as vectors
    // from the position curve of the same patch at the same u.
    let derivative_curves: BTreeSet<&str> = solved
        .surfaces
        .iter()
        .flat_map(|s| &s.conditions)
        .filter(|c| c.derivative > 0)
        .filter_map(|c| c.curve_name.as_deref())
        .collect();
    let position_curves: BTreeSet<&str> = solved
        .surfaces
        .iter()
        .flat_map(|s| &s.conditions)
        .filter(|c| c.derivative == 0)
        .filter_map(|c| c.curve_name.as_deref())
        .collect();
    let curves: Vec<Value> = solved
        .curves
        .iter()
        .map(|c| {
            let cs = spec.curves.get(&c.name);
            let is_vector = derivative_curves.contains(c.name.as_str());
            // Sampled once: the drawn points (seven digits) and the centroid (exact). A
            // derivative curve is not drawn: fewer samples serve its centroid.
            let count = if is_vector {
                CENTROID_POINTS
            } else {
                per_curve
            };
            let (sampled, closed) = samples(&*c.curve, count);
            let centre = centroid(&sampled);
            let (points, closed): (Vec<[f64; 3]>, bool) = if is_vector {
                (Vec::new(), false)
            } else {
                (sampled.iter().filter_map(d3).collect(), closed)
            };
            let comb = if is_vector || !combs {
                Vec::new()
            } else {
                comb(&*c.curve, per_curve)
            };
            let v0 = (!is_vector && c.curve.domain() == Domain::Periodic)
                .then(|| (c.curve.point(0.0), c.curve.derivative(0.0, 1)))
                .filter(|(p, d)| finite(p) && finite(d))
                .map(|(p, d)| json!({ "point": p3(&p), "tangent": p3(&d) }));
            let control = cs.and_then(pdeshape::design::world_control_points);
            let role = if position_curves.contains(c.name.as_str()) {
                "position"
            } else if is_vector {
                "derivative"
            } else {
                "other"
            };
            let scale = cs.and_then(|s| match &s.kind {
                CurveKind::Derivative { scale, .. } => Some(*scale),
                _ => None,
            });
            json!({
                "name": c.name,
                "kind": c.kind,
                "role": role,
                "spec": cs,
                "points": points,
                "closed": closed,
                "comb": comb,
                // How many points were asked for (`points` leaves out those not finite).
                "samples": count,
                "control": control,
                "v0": v0,
                "scale": scale,
                "v_origin": cs.map(|s| s.v_origin),
                "centroid": centre.map(|p| p3(&p)),
                // The parameter interval the drawn points span evenly (closed: without its end).
                "range": match c.curve.domain() {
                    Domain::Periodic => [0.0, pdeshape::TAU],
                    Domain::Interval(a, b) => [a, b],
                },
            })
        })
        .collect();
    let mut vectors = Vec::new();
    let mut surfaces = Vec::new();
    for (k, s) in solved.surfaces.iter().enumerate() {
        for c in s.conditions.iter().filter(|c| c.derivative == 1) {
            let base = s
                .conditions
                .iter()
                .find(|p| p.derivative == 0 && p.u == c.u)
                .map(|p| p.curve.clone());
            let segments: Vec<[[f64; 3]; 2]> = (0..VECTORS)
                .filter_map(|k| {
                    let v = pdeshape::TAU * k as f64 / VECTORS as f64;
                    let from = base.as_ref().map(|b| b.point(v))?;
                    let d = c.curve.point(v);
                    // Fig. 5.2 draws X_u at a third of its length to keep the picture legible.
                    let to = from + d / 3.0;
                    Some([d3(&from)?, d3(&to)?])
                })
                .collect();
            vectors.push(json!({
                "patch": s.name, "u": c.u, "curve": c.curve_name, "segments": segments,
            }));
        }
        let spine: Vec<[f64; 3]> = (0..per_curve)
            .filter_map(|k| s.spine(k as f64 / (per_curve - 1) as f64, 0))
            .filter_map(|p| d3(&p))
            .collect();
        // The spine's Bézier control points (§5.3): the edited ones, else the solved spine's.
        let report = s.spine_report();
        let spine_control = report.as_ref().map(|r| {
            let points = match &r.edited {
                Some((_, c)) => c,
                None => &r.solved,
            };
            points
                .iter()
                .filter(|p| finite(p))
                .map(p3)
                .collect::<Vec<_>>()
        });
        let carry = report
            .as_ref()
            .and_then(|r| r.edited.as_ref())
            .map(|(c, _)| match c {
                SpineCarry::Frame => "frame",
                SpineCarry::Translate => "translate",
            });
        let domain = s.surface().parameter_domain();
        let v = domain.v_interval();
        surfaces.push(json!({
            "name": s.name,
            "kind": s.kind.word(),
            "place": s.place,
            "operator": operator_json(&s.operator),
            "own_operator": spec.patches.iter().flatten().any(|p| p.name == s.name && p.operator.is_some()),
            "conditions": s.conditions.iter().map(|c| json!({
                "u": c.u, "derivative": c.derivative, "curve": c.curve_name, "kind": c.kind,
            })).collect::<Vec<_>>(),
            "spine": spine,
            "spine_control": spine_control,
            "spine_carry": carry,
            // A host of attached patches keeps its spine (curves on spine-edited patches are
            // not supported by the library).
            "hosts": spec.curves.values().any(|c| matches!(&c.kind, CurveKind::OnPatch { patch, .. } if *patch == s.name)),
            "spine_wave": spec.spine.iter().any(|t| t.wave.is_some() && t.patch.as_deref().unwrap_or(&s.name) == s.name),
            "domain": { "u": [domain.u.start, domain.u.end], "v": [v.start, v.end], "periodic": domain.v_periodic() },
            "trimmed": solved.trim_of(k).is_some(),
        }));
    }
    // Curves shared as positions by two patches (their G0/G1 is measured on request:
    // `/api/check`).
    let mut shared: Vec<&str> = Vec::new();
    for name in &position_curves {
        let users = solved
            .surfaces
            .iter()
            .filter(|s| {
                s.conditions
                    .iter()
                    .any(|c| c.derivative == 0 && c.curve_name.as_deref() == Some(*name))
            })
            .count();
        if users > 1 {
            shared.push(name);
        }
    }
    // With the combs: the two surfaces' normal curvatures across every shared edge (a comb per
    // side), from their exact derivatives.
    let mut seam_combs = Vec::new();
    if combs {
        for (ia, a) in solved.surfaces.iter().enumerate() {
            for b in &solved.surfaces[ia + 1..] {
                for ca in a.conditions.iter().filter(|c| c.derivative == 0) {
                    let Some(name) = &ca.curve_name else { continue };
                    for cb in b.conditions.iter().filter(|c| {
                        c.derivative == 0 && c.curve_name.as_deref() == Some(name.as_str())
                    }) {
                        let teeth: Vec<Value> = pdeshape::diagnostics::seam_curvatures(
                            a.surface(),
                            ca.u,
                            b.surface(),
                            cb.u,
                            SEAM_COMB_TEETH,
                        )
                        .into_iter()
                        .filter(|c| finite(&c.point) && c.a.is_finite() && c.b.is_finite())
                        .map(|c| json!([p3(&c.point), p3(&c.normal), c.a, c.b]))
                        .collect();
                        seam_combs.push(
                            json!({ "curve": name, "a": a.name, "b": b.name, "teeth": teeth }),
                        );
                    }
                }
            }
        }
    }
    json!({
        "seam_combs": seam_combs,
        "title": solved.title,
        "modes": spec.solver.modes,
        "method": format!("{:?}", spec.solver.method).to_lowercase(),
        "operator": operator_json(&spec.operator),
        "has_patches": spec.patches.is_some(),
        "curves": curves,
        "vectors": vectors,
        "surfaces": surfaces,
        "shared_curves": shared,
        "trims": super::uv::trims(spec, solved),
        "attachments": super::uv::attachments(spec),
        "trim_lines": super::uv::images(solved, 2 * per_curve),
        "parameters": parameters(spec),
    })
}

/// The `[[parameters]]` of the design with their bounds and values (§6.1, §6.4, §7.5).
fn parameters(spec: &DesignSpec) -> Value {
    if spec.parameters.is_empty() {
        return json!([]);
    }
    let Ok(list) = pdeshape::design::design_parameters(spec) else {
        return json!([]);
    };
    list.iter()
        .map(|p| {
            let kind = spec
                .parameters
                .iter()
                .find(|s| s.name == p.name)
                .map(|s| s.kind);
            json!({
                "name": p.name, "place": p.place, "kind": kind, "curve": p.kind.curve(),
                "min": p.min, "max": p.max, "neutral": num(p.neutral), "value": num(p.value),
            })
        })
        .collect()
}

/// A number for JSON: non-finite values as null.
fn num(x: f64) -> Value {
    serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)
}

/// The mean of a curve's drawn points ([`samples`]): the default centre of rotations and
/// scalings.
fn centroid(points: &[pdeshape::Vec3]) -> Option<pdeshape::Vec3> {
    if points.is_empty() {
        return None;
    }
    let n = points.len() as f64;
    Some(
        points
            .iter()
            .fold(pdeshape::Vec3::zeros(), |acc, p| acc + p)
            / n,
    )
}

fn pad4(out: &mut Vec<u8>, fill: u8) {
    while !out.len().is_multiple_of(4) {
        out.push(fill);
    }
}

/// One surface of a frame: its grid, or (with holes) its trimmed triangle mesh.
pub(super) enum Drawn<'a> {
    Grid(&'a GridMesh),
    Trimmed(&'a GridMesh, &'a TriMesh),
}

fn put_u32(out: &mut Vec<u8>, x: usize) {
    out.extend_from_slice(&(x as u32).to_le_bytes());
}

/// The binary frame of `json` and the surfaces `drawn`, with optional per-vertex colours (one
/// list per surface, of its vertex count).
pub(super) fn frame(json: &Value, drawn: &[Drawn], colors: Option<&[Vec<[u8; 3]>]>) -> Vec<u8> {
    let text = json.to_string();
    let vertices: usize = drawn
        .iter()
        .map(|d| match d {
            Drawn::Grid(m) => m.len(),
            Drawn::Trimmed(_, t) => t.positions.len() + 2 * t.triangles.len(),
        })
        .sum();
    let mut out = Vec::with_capacity(16 + text.len() + drawn.len() * 20 + vertices * 24);
    out.extend_from_slice(b"PDSF");
    let mut json_bytes = text.into_bytes();
    while !json_bytes.len().is_multiple_of(4) {
        json_bytes.push(b' ');
    }
    put_u32(&mut out, json_bytes.len());
    out.extend_from_slice(&json_bytes);
    put_u32(&mut out, drawn.len());
    for (k, d) in drawn.iter().enumerate() {
        let (grid, positions, normals, triangles) = match d {
            Drawn::Grid(m) => (*m, &m.positions, &m.normals, None),
            Drawn::Trimmed(g, t) => (*g, &t.positions, &t.normals, Some(&t.triangles)),
        };
        let col = colors
            .and_then(|c| c.get(k))
            .filter(|c| c.len() == positions.len());
        let flags = u32::from(grid.periodic_v)
            | (u32::from(col.is_some()) << 1)
            | (u32::from(triangles.is_some()) << 2);
        put_u32(&mut out, grid.nu);
        put_u32(&mut out, grid.nv);
        out.extend_from_slice(&flags.to_le_bytes());
        if let Some(t) = triangles {
            put_u32(&mut out, positions.len());
            put_u32(&mut out, t.len());
        }
        for p in positions {
            for x in p {
                out.extend_from_slice(&x.to_le_bytes());
            }
        }
        for n in normals {
            for x in n {
                let q = (x.clamp(-1.0, 1.0) * 32767.0).round() as i16;
                out.extend_from_slice(&q.to_le_bytes());
            }
        }
        pad4(&mut out, 0);
        if let Some(c) = col {
            for rgb in c {
                out.extend_from_slice(rgb);
            }
            pad4(&mut out, 0);
        }
        if let Some(t) = triangles {
            for tri in t.iter() {
                for i in tri {
                    out.extend_from_slice(&i.to_le_bytes());
                }
            }
        }
    }
    out
}
