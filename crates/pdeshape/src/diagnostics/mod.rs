//! What `pdeshape check` reports about a solved design, computed once for every shell (the CLI,
//! the designer, Python): the condition errors of every patch, G0/G1 along shared edges and
//! attachments, the quality of trimmed re-meshings, the design's parameters, the warnings and a
//! verdict. [`diagnose`] computes a [`Diagnostics`]; [`Diagnostics::to_json`] is `check
//! --json`'s data and [`check_report`] its text.

mod network;
mod report;
#[cfg(test)]
mod tests;

pub use network::{NetworkDiagnostics, NetworkFace, NetworkJoint};
pub use report::{blend_report, check_report, check_text, describe_operator, spline_report};

use crate::design::{self, ConditionInfo, SolvedDesign, SurfaceKind};
use crate::elliptic::{ConditionError, ModeReport};
use crate::spec::DesignSpec;
use crate::surface::{ClosestOptions, ClosestPointIndex, Surface};
use crate::trim::MeshQuality;
use crate::Vec3;
use serde_json::{json, Value};
use std::fmt::Write;

/// Samples of `v` for the condition errors.
pub const ERROR_SAMPLES: usize = 512;
/// Relative condition errors of analytic patches above this are warned about.
pub const WARN_RELATIVE: f64 = 1e-6;
/// A surface reaching farther than this many times the extent of its position curves (from
/// their centre) is warned about: the interpolation oscillates between the conditions.
pub const WARN_EXCURSION: f64 = 10.0;
/// Samples along each attachment for its G0/G1.
pub const ATTACH_SAMPLES: usize = 512;
/// G0 above this (times the host's size, at least 1) along an attachment or a shared edge is a
/// gap.
pub const G0_TOLERANCE: f64 = 1e-10;
/// G1 above this (radians) along an attachment with a tangent field or a shared edge is a crease.
pub const G1_TOLERANCE: f64 = 1e-8;
/// A G2 side of an n-sided patch whose normal curvature across it differs from its
/// neighbour's by more than this, times the boundary's size, asks for attention; so does a
/// corner where G2 data disagree by more.
pub const G2_TOLERANCE: f64 = 1e-6;
/// The default of `pdeshape check --g1-tolerance` and of the designer's seam tolerance: one
/// degree (in radians). A shared edge creased by more than this fails the check
/// ([`Diagnostics::judge_seams`]); below it, a crease only asks for attention.
pub const SEAM_G1_TOLERANCE: f64 = std::f64::consts::PI / 180.0;

/// The overall judgement of a solved design.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Verdict {
    /// Every condition met, no warning, every shared edge G0 and G1.
    Ok,
    /// The design solved, but something deserves a look: a warning, or a shared edge that is
    /// not G0 (a gap) or not G1 (a crease; often intended, as at a lid or a flange).
    Attention,
    /// A shared edge is creased by more than the seam tolerance given to
    /// [`Diagnostics::judge_seams`], or its curvature jumps by more than the tolerance given
    /// to [`Diagnostics::judge_curvature`] (never the verdict of [`diagnose`] alone).
    Fail,
}

impl Verdict {
    /// `"ok"`, `"attention"` or `"fail"`.
    pub fn word(self) -> &'static str {
        match self {
            Verdict::Ok => "ok",
            Verdict::Attention => "attention",
            Verdict::Fail => "fail",
        }
    }

    /// The first line of `pdeshape check`'s text: `OK`, `ATTENTION` or `FAIL`.
    pub fn label(self) -> &'static str {
        match self {
            Verdict::Ok => "OK",
            Verdict::Attention => "ATTENTION",
            Verdict::Fail => "FAIL",
        }
    }
}

/// One surface's kind, operator, modes and condition errors.
#[derive(Clone, Debug)]
pub struct SurfaceDiagnostics {
    /// The surface's name.
    pub name: String,
    /// [`SurfaceKind::word`].
    pub kind: &'static str,
    /// A PDE patch (analytic, finite differences or with an edited spine).
    pub patch: bool,
    /// A PDE patch with an edited spine (its conditions are the unedited patch's).
    pub spine_edited: bool,
    /// The operator in words ([`describe_operator`]).
    pub operator: Option<String>,
    /// The analytic solver's report per Fourier mode.
    pub modes: Option<Vec<ModeReport>>,
    /// `max_v` errors of the conditions (every condition of an analytic patch, the position
    /// conditions of the others), on [`ERROR_SAMPLES`] values of `v`; empty unless `patch`.
    pub condition_errors: Vec<ConditionError>,
}

/// G0/G1 along an edge shared by two patches.
#[derive(Clone, Debug)]
pub struct EdgeDiagnostics {
    /// The shared position curve.
    pub curve: String,
    /// The first patch's name.
    pub a: String,
    /// The edge's `u` on the first patch.
    pub ua: f64,
    /// The second patch's name.
    pub b: String,
    /// The edge's `u` on the second patch.
    pub ub: f64,
    /// G0 error: `max_v |X_a(ua, v) − X_b(ub, v)|`.
    pub g0: f64,
    /// Radians.
    pub g1: f64,
    /// `g0` within [`G0_TOLERANCE`] times the first surface's size (at least 1).
    pub g0_met: bool,
    /// `g1` within [`G1_TOLERANCE`]: no crease.
    pub g1_met: bool,
    /// `g1` above the seam tolerance of [`Diagnostics::judge_seams`] (or NaN); false until
    /// judged.
    pub g1_failed: bool,
    /// `g2` above the curvature tolerance of [`Diagnostics::judge_curvature`] (or NaN); false
    /// until judged (and never for a declared crease).
    pub g2_failed: bool,
    /// The edge runs along a curve the design lists in `creases`: a crease there is meant, and
    /// neither fails the seams nor turns the verdict.
    pub declared_crease: bool,
    /// G2 figure: the largest difference (1/length) between the two surfaces' normal curvatures
    /// across the edge ([`seam_g2`]); 0 to rounding where the edge is curvature-continuous.
    pub g2: f64,
}

/// Samples of `v` for [`seam_g2`] in the diagnostics.
pub const G2_SAMPLES: usize = 256;

/// The normal curvature of a surface at `p` in the tangent direction `d` (with the unit normal
/// `n`): `II(d, d) / I(d, d)` with `d` written in the basis `X_u, X_v`; `None` where that basis
/// degenerates.
fn normal_curvature(p: &crate::surface::Partials, n: &Vec3, d: &Vec3) -> Option<f64> {
    let (e, f, g) = (p.xu.dot(&p.xu), p.xu.dot(&p.xv), p.xv.dot(&p.xv));
    let det = e * g - f * f;
    // NaN refuses too.
    if det.is_nan() || det <= 1e-24 * (e + g) * (e + g) {
        return None;
    }
    let (du, dv) = (p.xu.dot(d), p.xv.dot(d));
    let alpha = (g * du - f * dv) / det;
    let beta = (e * dv - f * du) / det;
    let second = alpha * alpha * p.xuu.dot(n)
        + 2.0 * alpha * beta * p.xuv.dot(n)
        + beta * beta * p.xvv.dot(n);
    let first = alpha * alpha * e + 2.0 * alpha * beta * f + beta * beta * g;
    (first > 0.0).then(|| second / first)
}

/// The normal curvatures of two surfaces across an edge they share, at one `v`: the point on
/// the first surface, its unit normal, and the normal curvature of each surface in the direction
/// across the edge ([`seam_curvatures`]).
#[derive(Clone, Copy, Debug)]
pub struct SeamCurvature {
    /// `X_a(ua, v)`.
    pub point: Vec3,
    /// The first surface's unit normal there (the second's is turned to agree with it).
    pub normal: Vec3,
    /// The first surface's normal curvature across the edge (positive: curving towards
    /// `normal`).
    pub a: f64,
    /// The second surface's.
    pub b: f64,
}

/// The normal curvatures of two surfaces across the edge along `u = ua` on `a` and `u = ub` on
/// `b`, at `samples` equally spaced `v`: in each surface's tangent plane, the direction
/// perpendicular to the edge's tangent `X_v`, with `b`'s normal turned to agree with `a`'s.
/// Samples where a normal or the edge's tangent degenerates (a pole) are left out.
pub fn seam_curvatures(
    a: &dyn Surface,
    ua: f64,
    b: &dyn Surface,
    ub: f64,
    samples: usize,
) -> Vec<SeamCurvature> {
    let mut out = Vec::with_capacity(samples.max(1));
    for j in 0..samples.max(1) {
        let v = crate::TAU * j as f64 / samples.max(1) as f64;
        let (pa, pb) = (a.partials(ua, v), b.partials(ub, v));
        let (Some(na), Some(nb)) = (pa.normal_or_none(), pb.normal_or_none()) else {
            continue;
        };
        let nb = if na.dot(&nb) < 0.0 { -nb } else { nb };
        let t = pa.xv;
        if t.norm().is_nan() || t.norm() == 0.0 {
            continue;
        }
        let t = t / t.norm();
        let (da, db) = (na.cross(&t), nb.cross(&t));
        if let (Some(ka), Some(kb)) = (
            normal_curvature(&pa, &na, &da),
            normal_curvature(&pb, &nb, &db),
        ) {
            out.push(SeamCurvature {
                point: pa.x,
                normal: na,
                a: ka,
                b: kb,
            });
        }
    }
    out
}

/// The G2 figure of an edge shared by two surfaces along `u = ua` on `a` and `u = ub` on `b`:
/// over `samples` equally spaced `v`, the largest difference between the two surfaces' normal
/// curvatures across the edge ([`seam_curvatures`]); NaN shows.
pub fn seam_g2(a: &dyn Surface, ua: f64, b: &dyn Surface, ub: f64, samples: usize) -> f64 {
    let mut worst = 0.0f64;
    for c in seam_curvatures(a, ua, b, ub, samples) {
        let d = (c.a - c.b).abs();
        if d.is_nan() || d > worst {
            worst = d;
        }
    }
    worst
}

/// G0/G1 along an attachment (a patch whose condition lies on a host patch).
#[derive(Clone, Debug)]
pub struct AttachmentDiagnostics {
    /// The attached patch's name.
    pub patch: String,
    /// The `u` of the attached patch's condition on the host (its end, or an intermediate curve).
    pub u: f64,
    /// The host patch's name.
    pub host: String,
    /// The attaching curve's name (`None`: an inline curve).
    pub curve: Option<String>,
    /// Attached with a tangent field (G1 expected).
    pub tangent: bool,
    /// Points sampled along the attached patch at `u`.
    pub samples: usize,
    /// Largest distance from a sample to the host.
    pub g0: f64,
    /// Largest angle (radians) between the two surfaces' normals at the samples, as lines.
    pub g1: f64,
    /// Samples whose closest-point search did not converge.
    pub unconverged: usize,
}

/// A `[[trims]]` entry and the quality of its re-meshing on the design's output grid.
#[derive(Clone, Debug)]
pub struct TrimDiagnostics {
    /// `trims[i]`.
    pub place: String,
    /// The trimmed surface's name.
    pub surface: String,
    /// The re-meshing method, as the design file names it.
    pub method: &'static str,
    /// Each curve's kind and the area of `(u, v)` it encloses.
    pub curves: Vec<(&'static str, f64)>,
    /// The grid `(nu, nv)` of the re-meshing.
    pub grid: (usize, usize),
    /// The re-meshed band's triangles measured in grid cells (`None` if it could not be made).
    pub quality: Option<MeshQuality>,
}

/// A `[[parameters]]` entry: its value, bounds and what it drives.
#[derive(Clone, Debug)]
pub struct ParameterDiagnostics {
    /// The entry's name.
    pub name: String,
    /// The file's word for its kind.
    pub kind: &'static str,
    /// The curve it drives (`None` for the smoothing parameter `a`).
    pub curve: Option<String>,
    /// Further curves that follow the same map.
    pub with: Vec<String>,
    /// Its value: the given one, else the neutral one.
    pub value: f64,
    /// Lower bound.
    pub min: f64,
    /// Upper bound.
    pub max: f64,
    /// The value that leaves the design as written.
    pub neutral: f64,
    /// What it drives, in words.
    pub drives: String,
}

/// An `[[nsided]]` patch: how exactly it meets its sides and its neighbours.
#[derive(Clone, Debug)]
pub struct NSidedDiagnostics {
    /// The `[[nsided]]` entry's `name` (a patch of `n ≠ 4` sides is the surfaces `name.0`,
    /// `name.1`, …).
    pub name: String,
    /// The number of sides.
    pub sides: usize,
    /// The largest distance between the patch and a side's curve, relative to the boundary's
    /// size.
    pub boundary: f64,
    /// Per side: `None` for a position-only side, else the largest angle (radians) between the
    /// patch's normal and the neighbour's (`tangent_to`, measured against the neighbour
    /// surface itself) or the ribbon's plane (`derivative`).
    pub g1: Vec<Option<f64>>,
    /// Per corner: the tangent mismatch and the twist mismatch (see
    /// `pdeshape_geometry::nsided::Corner`).
    pub corners: Vec<(f64, f64)>,
    /// Per side: `None` unless the side is G2 (order 3), else the largest difference between
    /// the patch's normal curvature across the side and the neighbour's (`tangent_to` with
    /// `g2`, measured against the neighbour surface itself) or the ribbon surface's
    /// (`second_derivative`), times the boundary's size.
    pub g2: Vec<Option<f64>>,
    /// Per corner: `None` unless a G2 side meets it, else how far the two sides' curvature
    /// data disagree there (a normal curvature times the boundary's size; see
    /// `pdeshape_geometry::nsided::Corner::curvature_mismatch`).
    pub corner_curvature: Vec<Option<f64>>,
}

/// Everything `pdeshape check` finds in a solved design.
#[derive(Clone, Debug)]
pub struct Diagnostics {
    /// The design's title.
    pub title: Option<String>,
    /// Every surface, in the design's order.
    pub surfaces: Vec<SurfaceDiagnostics>,
    /// The shared edges of a multi-patch design (`None` for a single surface).
    pub edges: Option<Vec<EdgeDiagnostics>>,
    /// Every attachment of a patch to a host patch.
    pub attachments: Vec<AttachmentDiagnostics>,
    /// Every `[[trims]]` entry, in order.
    pub trims: Vec<TrimDiagnostics>,
    /// Every `[[parameters]]` entry, in order.
    pub parameters: Vec<ParameterDiagnostics>,
    /// The `[[nsided]]` patches.
    pub nsided: Vec<NSidedDiagnostics>,
    /// The `[[network]]`s.
    pub networks: Vec<NetworkDiagnostics>,
    /// What deserves a warning, in words (without a `warning: ` prefix).
    pub warnings: Vec<String>,
    /// The overall judgement ([`diagnose`] says how it is reached).
    pub verdict: Verdict,
    /// The seam tolerance (radians) the shared edges were judged by
    /// ([`Diagnostics::judge_seams`]), if they were.
    pub g1_tolerance: Option<f64>,
    /// The curvature tolerance (1/length) the shared edges' G2 figures were judged by
    /// ([`Diagnostics::judge_curvature`]), if they were.
    pub g2_tolerance: Option<f64>,
}

/// The name of the `d`-th u-derivative in reports: `position`, `X_u`, `X_uu`, `∂^dX/∂u^d`.
pub(crate) fn derivative_name(d: usize) -> String {
    match d {
        0 => "position".to_string(),
        1 => "X_u".to_string(),
        2 => "X_uu".to_string(),
        _ => format!("∂^{d}X/∂u^{d}"),
    }
}

/// `max_v |X(u, v) − C(v)|` of a position condition on a surface, absolute and relative to the
/// curve's size (for solvers without their own condition report).
fn position_error(s: &dyn Surface, c: &ConditionInfo) -> (f64, f64) {
    let (mut err, mut size) = (0.0f64, 0.0f64);
    for k in 0..ERROR_SAMPLES {
        let v = crate::TAU * k as f64 / ERROR_SAMPLES as f64;
        let p = c.curve.point(v);
        let d = (s.point(c.u, v) - p).norm();
        if d.is_nan() || d > err {
            err = d;
        }
        size = size.max(p.norm());
    }
    (err, err / size.max(f64::MIN_POSITIVE))
}

/// `(surface extent, curve extent)`: the largest distance from the centre of the position
/// curves' bounding box, over a 257 × 64 sample of the patch and over its position curves.
fn excursion(surface: &dyn Surface, conds: &[ConditionInfo]) -> (f64, f64) {
    let mut pts = Vec::new();
    for c in conds.iter().filter(|c| c.derivative == 0) {
        for k in 0..256 {
            pts.push(c.curve.point(crate::TAU * k as f64 / 256.0));
        }
    }
    if pts.is_empty() {
        return (0.0, 0.0);
    }
    let mut lo = pts[0];
    let mut hi = pts[0];
    for p in &pts {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let centre: Vec3 = (lo + hi) / 2.0;
    let curves = pts.iter().map(|p| (p - centre).norm()).fold(0.0, f64::max);
    let surface = match crate::mesh::sample(surface, 257, 64) {
        Ok(grid) => grid
            .positions
            .iter()
            .map(|p| (Vec3::new(p[0], p[1], p[2]) - centre).norm())
            .fold(
                0.0,
                |m: f64, d| if d.is_nan() { f64::INFINITY } else { m.max(d) },
            ),
        Err(_) => 0.0,
    };
    (surface, curves)
}

/// The diagonal of a surface's bounding box on a coarse grid (the scale of its G0).
fn size_of(s: &dyn Surface) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    let r = s.u_range();
    for i in 0..=16 {
        for j in 0..32 {
            let u = r.start + (r.end - r.start) * i as f64 / 16.0;
            let p = s.point(u, crate::TAU * j as f64 / 32.0);
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    }
    (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt()
}

fn surface_diagnostics(patch: &design::DesignSurface) -> SurfaceDiagnostics {
    let is_patch = patch.is_patch();
    let (modes, condition_errors) = match patch.pde() {
        Some(pde) => (
            Some(pde.mode_reports().to_vec()),
            pde.condition_errors(ERROR_SAMPLES),
        ),
        None if is_patch => (
            None,
            patch
                .conditions
                .iter()
                .filter(|c| c.derivative == 0)
                .map(|c| {
                    let (absolute, relative) = position_error(patch.surface(), c);
                    ConditionError {
                        u: c.u,
                        derivative: 0,
                        absolute,
                        relative,
                    }
                })
                .collect(),
        ),
        None => (None, Vec::new()),
    };
    SurfaceDiagnostics {
        name: patch.name.clone(),
        kind: patch.kind.word(),
        patch: is_patch,
        spine_edited: matches!(patch.kind, SurfaceKind::SpineEdited(_)),
        operator: patch.operator.as_ref().map(describe_operator),
        modes,
        condition_errors,
    }
}

fn trim_diagnostics(spec: &DesignSpec, built: &SolvedDesign) -> Vec<TrimDiagnostics> {
    if built.trims.is_empty() {
        return Vec::new();
    }
    // The design's output grid (its [output] table, or the default).
    let (nu, nv) =
        design::grid(spec, None, None).unwrap_or((design::DEFAULT_NU, design::DEFAULT_NV));
    let params = built.param_meshes(nu, nv);
    built
        .trims
        .iter()
        .map(|t| {
            let target = &built.surfaces[t.surface];
            let quality = match &params {
                Ok(p) => p[t.surface].as_ref().map(|pm| {
                    let surface = target.surface();
                    let du = surface.u_range().length() / (nu - 1) as f64;
                    let dv = match surface.v_domain() {
                        crate::surface::VDomain::Periodic => crate::TAU / nv as f64,
                        crate::surface::VDomain::Interval(a, b) => (b - a) / (nv - 1) as f64,
                    };
                    let periodic = surface.v_domain().is_periodic();
                    let pts: Vec<[f64; 3]> = (pm.grid_triangles..pm.triangles.len())
                        .flat_map(|k| pm.triangle_uv(k, periodic))
                        .map(|p| [p[0] / du, p[1] / dv, 0.0])
                        .collect();
                    let tris: Vec<[u32; 3]> = (0..(pts.len() / 3) as u32)
                        .map(|k| [3 * k, 3 * k + 1, 3 * k + 2])
                        .collect();
                    crate::trim::quality(&pts, &tris, None)
                }),
                Err(_) => None,
            };
            TrimDiagnostics {
                place: t.place.clone(),
                surface: target.name.clone(),
                method: t.method.word(),
                curves: t.curves.iter().map(|c| (c.kind(), c.area())).collect(),
                grid: (nu, nv),
                quality,
            }
        })
        .collect()
}

fn parameter_diagnostics(spec: &DesignSpec) -> Vec<ParameterDiagnostics> {
    let list = design::design_parameters(spec).unwrap_or_default();
    list.into_iter()
        .zip(&spec.parameters)
        .map(|(p, entry)| ParameterDiagnostics {
            kind: entry.kind.word(),
            curve: p.kind.curve().map(str::to_string),
            drives: p.kind.describe(),
            name: p.name,
            with: p.with,
            value: p.value,
            min: p.min,
            max: p.max,
            neutral: p.neutral,
        })
        .collect()
}

/// The diagnostics of a design solved from `spec` (the design as solved: parameters applied).
///
/// Warnings, in this order: conditions of analytic patches met only to a relative error above
/// [`WARN_RELATIVE`] (or NaN); patches reaching beyond [`WARN_EXCURSION`] times the extent of
/// their position curves; attachments apart by more than [`G0_TOLERANCE`] times the host's size
/// (at least 1), with a tangent field by more than [`G1_TOLERANCE`] radians, or whose
/// closest-point search did not converge; trimmed re-meshings with inverted triangles. The
/// verdict is [`Verdict::Ok`] when there is no warning and every shared edge is G0 and G1 within
/// the same tolerances.
pub fn diagnose(spec: &DesignSpec, built: &SolvedDesign) -> Diagnostics {
    let surfaces: Vec<SurfaceDiagnostics> =
        built.surfaces.iter().map(surface_diagnostics).collect();
    let mut warnings = Vec::new();
    for s in surfaces.iter().filter(|s| s.patch) {
        // Finite differences meet their conditions only to the grid's accuracy.
        let warn_at = if s.modes.is_some() {
            WARN_RELATIVE
        } else {
            f64::INFINITY
        };
        for e in &s.condition_errors {
            if e.relative > warn_at || e.relative.is_nan() {
                warnings.push(format!(
                    "patch '{}': the {} condition at u = {} is met only to {:.3e} (relative)",
                    s.name,
                    derivative_name(e.derivative),
                    e.u,
                    e.relative
                ));
            }
        }
    }
    for patch in built.surfaces.iter().filter(|p| p.is_patch()) {
        let (surface, curves) = excursion(patch.surface(), &patch.conditions);
        if curves > 0.0 && surface > WARN_EXCURSION * curves {
            warnings.push(format!(
                "patch '{}': the surface reaches {surface:.3e} from the centre of its position \
                 curves, which lie within {curves:.3e}: it oscillates between the conditions \
                 (fewer or smoother conditions, or other u values, help)",
                patch.name
            ));
        }
    }
    let edges = built.multi_patch.then(|| {
        built
            .edges()
            .iter()
            .map(|e| {
                let r = &e.report;
                let size = size_of(built.surfaces[r.a].surface());
                EdgeDiagnostics {
                    curve: e.curve.clone(),
                    a: built.surfaces[r.a].name.clone(),
                    ua: r.ua,
                    b: built.surfaces[r.b].name.clone(),
                    ub: r.ub,
                    g0: r.g0,
                    g1: r.g1,
                    g0_met: r.g0 <= G0_TOLERANCE * size.max(1.0),
                    g1_met: r.g1 <= G1_TOLERANCE,
                    g1_failed: false,
                    g2_failed: false,
                    declared_crease: spec.creases.contains(&e.curve),
                    g2: seam_g2(
                        built.surfaces[r.a].surface(),
                        r.ua,
                        built.surfaces[r.b].surface(),
                        r.ub,
                        G2_SAMPLES,
                    ),
                }
            })
            .collect::<Vec<_>>()
    });
    let mut attachments = Vec::new();
    if !built.attachments.is_empty() {
        for r in built.attachment_reports(ATTACH_SAMPLES) {
            let a = &r.attachment;
            let host = &built.surfaces[a.host];
            let patch = &built.surfaces[a.patch].name;
            let size = size_of(host.surface());
            let place = format!("attachment of '{patch}' to '{}'", host.name);
            if r.g0.is_nan() || r.g0 > G0_TOLERANCE * size.max(1.0) {
                warnings.push(format!("{place}: G0 = {:.3e} (positions apart)", r.g0));
            }
            if a.tangent && (r.g1.is_nan() || r.g1 > G1_TOLERANCE) {
                warnings.push(format!(
                    "{place}: G1 = {:.3e} rad (tangent planes apart)",
                    r.g1
                ));
            }
            if r.unconverged > 0 {
                warnings.push(format!(
                    "{place}: the closest-point search did not converge at {} of {} samples",
                    r.unconverged, r.samples
                ));
            }
            attachments.push(AttachmentDiagnostics {
                patch: patch.clone(),
                u: a.u,
                host: host.name.clone(),
                curve: a.curve.clone(),
                tangent: a.tangent,
                samples: r.samples,
                g0: r.g0,
                g1: r.g1,
                unconverged: r.unconverged,
            });
        }
    }
    let trims = trim_diagnostics(spec, built);
    for t in &trims {
        if let Some(q) = &t.quality {
            if q.inverted > 0 {
                warnings.push(format!("{}: {} inverted triangles", t.place, q.inverted));
            }
        }
    }
    let nsided = nsided_diagnostics(spec, built);
    for d in &nsided {
        if d.boundary.is_nan() || d.boundary > 1e-10 {
            warnings.push(format!(
                "n-sided patch '{}': its sides are met only to {:.3e} (relative)",
                d.name, d.boundary
            ));
        }
        for (i, g) in d.g1.iter().enumerate() {
            if let Some(g) = g.filter(|g| g.is_nan() || *g > G1_TOLERANCE) {
                warnings.push(format!(
                    "n-sided patch '{}': side {i} is G1 only to {g:.3e} rad",
                    d.name
                ));
            }
        }
        for (k, (t, _)) in d.corners.iter().enumerate() {
            if t.is_nan() || *t > G1_TOLERANCE {
                warnings.push(format!(
                    "n-sided patch '{}': at corner {k} the adjacent side leaves the neighbour's \
                     tangent plane by {t:.3e} rad (no surface is G1 to both there)",
                    d.name
                ));
            }
        }
        for (i, g) in d.g2.iter().enumerate() {
            if let Some(g) = g.filter(|g| g.is_nan() || *g > G2_TOLERANCE) {
                warnings.push(format!(
                    "n-sided patch '{}': side {i} is G2 only to {g:.3e} (normal curvature × \
                     size)",
                    d.name
                ));
            }
        }
        for (k, c) in d.corner_curvature.iter().enumerate() {
            if let Some(c) = c.filter(|c| c.is_nan() || *c > G2_TOLERANCE) {
                warnings.push(format!(
                    "n-sided patch '{}': at corner {k} the sides' curvature data disagree by \
                     {c:.3e} (normal curvature × size): no surface is G2 to both there",
                    d.name
                ));
            }
        }
    }
    let networks = network::network_diagnostics(built);
    for n in &networks {
        warnings.extend(n.warnings());
    }
    let edges_met = edges
        .iter()
        .flatten()
        .all(|e| e.g0_met && (e.g1_met || e.declared_crease));
    let verdict = if warnings.is_empty() && edges_met {
        Verdict::Ok
    } else {
        Verdict::Attention
    };
    Diagnostics {
        title: built.title.clone(),
        surfaces,
        edges,
        attachments,
        trims,
        parameters: parameter_diagnostics(spec),
        nsided,
        networks,
        warnings,
        verdict,
        g1_tolerance: None,
        g2_tolerance: None,
    }
}

/// `pdeshape check --json`'s object (also Python's `Design.check()`): [`Diagnostics::to_json`]
/// with `ok` (true: the design solved), `design` (`file` as given) and `report` (the text of
/// [`check_report`]).
pub fn check_json(file: &str, spec: &DesignSpec, built: &SolvedDesign, d: &Diagnostics) -> Value {
    let mut v = d.to_json();
    v["ok"] = json!(true);
    v["design"] = json!(file);
    v["report"] = json!(check_report(file, spec, built, d));
    v
}

/// Samples per side for the n-sided checks (between the corners).
const NSIDED_SAMPLES: usize = 48;

fn nsided_diagnostics(spec: &DesignSpec, built: &SolvedDesign) -> Vec<NSidedDiagnostics> {
    let mut out = Vec::new();
    for (i, ns) in spec.nsided.iter().enumerate() {
        let place = format!("nsided[{i}]");
        let Some(patch) = built.surfaces.iter().find_map(|s| match &s.kind {
            SurfaceKind::NSided(p) if s.place == place => Some(p.patch().clone()),
            _ => None,
        }) else {
            continue;
        };
        let report = patch.report(NSIDED_SAMPLES);
        let boundary = report.boundary.iter().fold(0.0f64, |a, b| a.max(*b)) / report.size;
        let mut g1 = report.g1.clone();
        let mut g2 = report.g2.clone();
        for (j, side) in ns.sides.iter().enumerate() {
            let Some(name) = &side.tangent_to else {
                continue;
            };
            let Some(target) = built.surface_named(name) else {
                continue;
            };
            let points: Vec<(Vec3, Vec3)> = (0..NSIDED_SAMPLES)
                .map(|m| patch.boundary_normal(j, (m as f64 + 0.5) / NSIDED_SAMPLES as f64))
                .collect();
            let worst = network::g1_to_surface(&points, target.surface());
            g1[j] = Some(worst);
            if side.g2 && report.g2.get(j).is_some_and(Option::is_some) {
                let along: Vec<(Vec3, Vec3, Vec3, f64)> = (0..NSIDED_SAMPLES)
                    .map(|m| patch.boundary_curvature(j, (m as f64 + 0.5) / NSIDED_SAMPLES as f64))
                    .collect();
                g2[j] = Some(g2_to_surface(&along, target.surface()) * report.size);
            }
        }
        let g2_sides = patch.g2_sides();
        let n = g2_sides.len();
        let corner_curvature = report
            .corners
            .iter()
            .enumerate()
            .map(|(k, c)| {
                (g2_sides[k] || g2_sides[(k + n - 1) % n]).then_some(c.curvature_mismatch)
            })
            .collect();
        out.push(NSidedDiagnostics {
            name: ns.name.clone(),
            sides: patch.n(),
            boundary,
            g1,
            corners: report
                .corners
                .iter()
                .map(|c| (c.tangent_mismatch, c.twist_mismatch))
                .collect(),
            g2,
            corner_curvature,
        });
    }
    out
}

/// The largest difference between the normal curvatures `κ` of a patch along the directions
/// `u` at its points `(p, n, u, κ)` and those of `surface` at its closest points in the same
/// directions (`uᵀ S u / |u|²`, `S` the surface's second fundamental form against the patch's
/// normal `n`); NaN where a closest point or the curvature is missing.
fn g2_to_surface(points: &[(Vec3, Vec3, Vec3, f64)], surface: &dyn Surface) -> f64 {
    let index = ClosestPointIndex::new(surface, &ClosestOptions::default());
    let mut worst: f64 = 0.0;
    for (p, n, u, k) in points {
        let diff = index
            .closest(*p)
            .and_then(|c| crate::nsided::shape_tensor(&surface.partials(c.u, c.v)))
            .map_or(f64::NAN, |(m, s)| {
                let sign = if m.dot(n) < 0.0 { -1.0 } else { 1.0 };
                (sign * u.dot(&(s * u)) / u.norm_squared() - k).abs()
            });
        worst = if worst.is_nan() || diff.is_nan() {
            f64::NAN
        } else {
            worst.max(diff)
        };
    }
    worst
}

/// A number for JSON: non-finite values as null.
pub(crate) fn jnum(x: f64) -> Value {
    serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)
}

impl Diagnostics {
    /// The shared edges that are not G1 within [`G1_TOLERANCE`] (creases).
    pub fn creases(&self) -> impl Iterator<Item = &EdgeDiagnostics> {
        self.edges.iter().flatten().filter(|e| !e.g1_met)
    }

    /// Judges the shared edges (seams) by a G1 tolerance in radians (`pdeshape check
    /// --g1-tolerance`, the designer's seam tolerance; [`SEAM_G1_TOLERANCE`] by default): a
    /// seam whose G1 angle exceeds it (or is NaN) fails, and so does the verdict
    /// ([`Verdict::Fail`]). Seams within it keep the verdict of [`diagnose`].
    pub fn judge_seams(&mut self, g1_tolerance: f64) {
        self.g1_tolerance = Some(g1_tolerance);
        let mut failed = false;
        for e in self.edges.iter_mut().flatten() {
            e.g1_failed = !e.declared_crease && (e.g1.is_nan() || e.g1 > g1_tolerance);
            failed |= e.g1_failed;
        }
        if failed {
            self.verdict = Verdict::Fail;
        }
    }

    /// Judges the shared edges' G2 figures ([`seam_g2`], the largest jump of the normal
    /// curvature across the seam, 1/length) by `g2_tolerance` (`pdeshape check
    /// --g2-tolerance`, the designer's curvature tolerance; not judged unless asked, since the
    /// library's patches meet G1, not G2, where they share a derivative curve): a seam whose
    /// figure exceeds it (or is NaN) fails, and so does the verdict ([`Verdict::Fail`]). A
    /// declared crease is not judged.
    pub fn judge_curvature(&mut self, g2_tolerance: f64) {
        self.g2_tolerance = Some(g2_tolerance);
        let mut failed = false;
        for e in self.edges.iter_mut().flatten() {
            e.g2_failed = !e.declared_crease && (e.g2.is_nan() || e.g2 > g2_tolerance);
            failed |= e.g2_failed;
        }
        if failed {
            self.verdict = Verdict::Fail;
        }
    }

    /// The shared edges that failed [`Diagnostics::judge_seams`] or
    /// [`Diagnostics::judge_curvature`].
    pub fn failed_seams(&self) -> impl Iterator<Item = &EdgeDiagnostics> {
        self.edges
            .iter()
            .flatten()
            .filter(|e| e.g1_failed || e.g2_failed)
    }

    /// The reasons ([`Diagnostics::reasons`]) and the verdict's [label](Verdict::label) as the
    /// last line (the designer's summary under the report).
    pub fn conclusion(&self) -> String {
        let mut t = self.reasons();
        let _ = writeln!(t, "{}", self.verdict.label());
        t
    }

    /// The reasons for the verdict, a line each: `fail: …` per shared edge creased beyond the
    /// seam tolerance ([`Diagnostics::judge_seams`]), `warning: …` per warning, `attention: …`
    /// per other shared edge that is not G0 (a gap) or not G1 (a crease); empty for `OK`.
    pub fn reasons(&self) -> String {
        let mut t = String::new();
        let n = |x: f64| crate::number::sig(x, crate::number::DIGITS);
        for e in self.failed_seams().filter(|e| e.g1_failed) {
            let _ = writeln!(
                t,
                "fail: shared edge '{}' u = {} | '{}' u = {} along '{}': G1 = {} rad, above the \
                 tolerance {} rad (a crease)",
                e.a,
                e.ua,
                e.b,
                e.ub,
                e.curve,
                n(e.g1),
                n(self.g1_tolerance.unwrap_or(SEAM_G1_TOLERANCE))
            );
        }
        for e in self.failed_seams().filter(|e| e.g2_failed) {
            let _ = writeln!(
                t,
                "fail: shared edge '{}' u = {} | '{}' u = {} along '{}': G2 = {} 1/length, above \
                 the tolerance {} (a curvature jump)",
                e.a,
                e.ua,
                e.b,
                e.ub,
                e.curve,
                n(e.g2),
                n(self.g2_tolerance.unwrap_or(f64::NAN))
            );
        }
        for w in &self.warnings {
            let _ = writeln!(t, "warning: {w}");
        }
        for e in self.edges.iter().flatten() {
            let place = format!(
                "attention: shared edge '{}' u = {} | '{}' u = {} along '{}'",
                e.a, e.ua, e.b, e.ub, e.curve
            );
            if !e.g0_met {
                let _ = writeln!(t, "{place}: G0 = {} (a gap)", n(e.g0));
            }
            if !e.g1_met && !e.g1_failed && !e.declared_crease {
                let _ = writeln!(t, "{place}: G1 = {} rad (a crease)", n(e.g1));
            }
        }
        t
    }

    /// The data of `pdeshape check --json` (without its `ok`, `design` and `report`): `title`,
    /// per surface its `name`, `kind`, `operator`, and for analytic and finite-difference
    /// patches their `modes` and `condition_errors`; the shared `edges` with `g0`, `g1`, `g2`
    /// ([`seam_g2`]), `failed` (either judgement) and `g1_failed`, `g2_failed`
    /// ([`Diagnostics::judge_seams`], [`Diagnostics::judge_curvature`]); `attachments`;
    /// `parameters`; `warnings`; the `verdict`'s [word](Verdict::word) and the `g1_tolerance`
    /// and `g2_tolerance` it was judged by (null if not).
    /// Non-finite numbers are null.
    pub fn to_json(&self) -> Value {
        let surfaces: Vec<Value> = self
            .surfaces
            .iter()
            .map(|s| {
                let mut o = json!({ "name": s.name, "kind": s.kind });
                if let Some(op) = &s.operator {
                    o["operator"] = json!(op);
                }
                if !s.patch || s.spine_edited {
                    return o;
                }
                if let Some(modes) = &s.modes {
                    o["modes"] = modes
                        .iter()
                        .map(|m| json!({ "n": m.n, "condition_number": jnum(m.condition_number), "basis": m.basis }))
                        .collect();
                }
                o["condition_errors"] = s
                    .condition_errors
                    .iter()
                    .map(|e| json!({ "u": e.u, "derivative": e.derivative, "absolute": jnum(e.absolute), "relative": jnum(e.relative) }))
                    .collect();
                o
            })
            .collect();
        let edges: Vec<Value> = self
            .edges
            .iter()
            .flatten()
            .map(|e| {
                json!({
                    "a": e.a, "ua": e.ua, "b": e.b, "ub": e.ub,
                    "curve": e.curve, "g0": jnum(e.g0), "g1": jnum(e.g1),
                    "g2": jnum(e.g2), "failed": e.g1_failed || e.g2_failed,
                    "g1_failed": e.g1_failed, "g2_failed": e.g2_failed,
                    "declared_crease": e.declared_crease,
                })
            })
            .collect();
        let attachments: Vec<Value> = self
            .attachments
            .iter()
            .map(|a| {
                json!({
                    "patch": a.patch, "u": a.u, "host": a.host, "curve": a.curve,
                    "tangent": a.tangent, "samples": a.samples,
                    "g0": jnum(a.g0), "g1": jnum(a.g1),
                })
            })
            .collect();
        let parameters: Vec<Value> = self
            .parameters
            .iter()
            .map(|p| {
                json!({
                    "name": p.name, "kind": p.kind, "curve": p.curve,
                    "with": p.with, "value": jnum(p.value), "min": jnum(p.min), "max": jnum(p.max),
                    "neutral": jnum(p.neutral), "drives": p.drives,
                })
            })
            .collect();
        json!({
            "title": self.title,
            "surfaces": surfaces,
            "edges": edges,
            "attachments": attachments,
            "parameters": parameters,
            "nsided": self.nsided.iter().map(|n| json!({
                "name": n.name,
                "sides": n.sides,
                "boundary": jnum(n.boundary),
                "g1": n.g1.iter().map(|g| g.map(jnum)).collect::<Vec<_>>(),
                "g2": n.g2.iter().map(|g| g.map(jnum)).collect::<Vec<_>>(),
                "corners": n.corners.iter().zip(&n.corner_curvature).map(|((t, w), c)| json!({
                    "tangent_mismatch": jnum(*t),
                    "twist_mismatch": jnum(*w),
                    "curvature_mismatch": c.map(jnum),
                })).collect::<Vec<_>>(),
            })).collect::<Vec<_>>(),
            "networks": self.networks.iter().map(NetworkDiagnostics::to_json).collect::<Vec<_>>(),
            "warnings": self.warnings,
            "verdict": self.verdict.word(),
            "g1_tolerance": self.g1_tolerance.map(jnum),
            "g2_tolerance": self.g2_tolerance.map(jnum),
        })
    }
}
