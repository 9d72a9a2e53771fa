//! The `(u, v)` part of a scene (§5.2, §5.2.1, Figs. 5.5–5.7 and 5.11): the `[[trims]]` entries
//! with their curves sampled in the parameter plane, the `on_patch` curves of attachments on
//! their hosts' planes, and the images of all trim curves on their surfaces (as `render` draws
//! them). The curves are sampled by the library's `TrimCurve`, so the page draws exactly what
//! cuts the holes; the page edits the tables it is sent (`trims[i]`, an `on_patch` curve's
//! `path`) and sends them back as the library's edits.

use pdeshape::design::{trim_curve, SolvedDesign};
use pdeshape::spec::{CurveKind, DesignSpec, TrimCurveSpec};
use serde_json::{json, Value};

/// Points per drawn `(u, v)` curve.
const UV_POINTS: usize = 96;

/// A closed `(u, v)` curve's points at `t = k / UV_POINTS` (finite ones only).
fn samples(c: &TrimCurveSpec) -> Vec<[f64; 2]> {
    let curve = trim_curve(c);
    (0..UV_POINTS)
        .map(|k| curve.point(k as f64 / UV_POINTS as f64))
        .filter(|p| p.iter().all(|x| x.is_finite()))
        .collect()
}

/// Every `[[trims]]` entry: its index, the surface it cuts (by name, the single surface when it
/// names none), its table as the design file states it and its curves' `(u, v)` points.
pub(super) fn trims(spec: &DesignSpec, solved: &SolvedDesign) -> Value {
    spec.trims
        .iter()
        .enumerate()
        .map(|(index, t)| {
            let surface = t
                .surface
                .clone()
                .or_else(|| (solved.surfaces.len() == 1).then(|| solved.surfaces[0].name.clone()));
            json!({
                "index": index,
                "surface": surface,
                "spec": t,
                "uv": t.curves.iter().map(samples).collect::<Vec<_>>(),
            })
        })
        .collect()
}

/// Every `on_patch` curve: its name, its host, whether it trims the host, and its `(u, v)`
/// points (its table is the curve's `spec` in the scene's curves).
pub(super) fn attachments(spec: &DesignSpec) -> Value {
    spec.curves
        .iter()
        .filter_map(|(name, c)| match &c.kind {
            CurveKind::OnPatch { patch, path, trim } => Some(json!({
                "name": name,
                "host": patch,
                "trim": trim,
                "uv": samples(path),
            })),
            _ => None,
        })
        .collect()
}

/// The images of every trim curve on its surface (the library's overlays of `render`), `points`
/// points each.
pub(super) fn images(solved: &SolvedDesign, points: usize) -> Value {
    solved
        .trim_overlays(points)
        .iter()
        .map(|line| {
            line.points
                .iter()
                .filter_map(super::scene::d3)
                .collect::<Vec<_>>()
        })
        .collect()
}
