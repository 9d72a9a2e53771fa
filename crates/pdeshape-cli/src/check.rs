//! `pdeshape check DESIGN`: validate, solve and report.

use crate::common::{self, CliError, Loaded};
use pdeshape::design::{ConditionInfo, SolvedDesign, SurfaceKind};
use pdeshape::spec::OperatorSpec;
use std::fmt::Write;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The design file (TOML).
    pub design: PathBuf,
    /// Set a design parameter (a `[[parameters]]` entry) to a value within its bounds;
    /// repeatable, e.g. `--set theta=0.3 --set s=1.2`.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// Print the report as one JSON object (`"ok": false` and the error when the design is
    /// refused; the error line still goes to stderr with exit status 2).
    #[arg(long)]
    pub json: bool,
}

/// Samples of v for the condition errors.
const ERROR_SAMPLES: usize = 512;
/// Relative errors above this are flagged in the report.
const WARN_RELATIVE: f64 = 1e-6;
/// A surface reaching farther than this many times the extent of its position curves (from
/// their centre) is flagged: the interpolation oscillates between the conditions.
const WARN_EXCURSION: f64 = 10.0;

/// `(surface extent, curve extent)`: the largest distance from the centre of the position
/// curves' bounding box, over a 257 × 64 sample of the patch and over its position curves.
fn excursion(
    surface: &dyn pdeshape::surface::Surface,
    conds: &[pdeshape::design::ConditionInfo],
) -> (f64, f64) {
    use pdeshape::Vec3;
    let mut pts = Vec::new();
    for c in conds.iter().filter(|c| c.derivative == 0) {
        for k in 0..256 {
            pts.push(c.curve.point(pdeshape::TAU * k as f64 / 256.0));
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
    let surface = match pdeshape::mesh::sample(surface, 257, 64) {
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

fn describe_operator(op: &OperatorSpec) -> String {
    match op {
        OperatorSpec::Polyharmonic { order, a } => format!(
            "polyharmonic (∂²/∂u² + a²∂²/∂v²)^{order}, order {} PDE, a = {a}",
            2 * order
        ),
        OperatorSpec::SixthOrder { a, b, c, d } => {
            format!("sixth-order a∂u⁶ + b∂u⁴∂v² + c∂u²∂v⁴ + d∂v⁶ with a = {a}, b = {b}, c = {c}, d = {d}")
        }
        OperatorSpec::General { coefficients } => format!(
            "general Σ c_k ∂u^(2N−2k) ∂v^(2k), order {} PDE, c = {coefficients:?}",
            2 * coefficients.len().saturating_sub(1)
        ),
    }
}

fn derivative_name(d: usize) -> String {
    match d {
        0 => "position".to_string(),
        1 => "X_u".to_string(),
        2 => "X_uu".to_string(),
        _ => format!("∂^{d}X/∂u^{d}"),
    }
}

/// `max_v |X(u, v) − C(v)|` of a position condition on a surface, absolute and relative to the
/// curve's size (for solvers without their own condition report).
fn position_error(s: &dyn pdeshape::surface::Surface, c: &ConditionInfo) -> (f64, f64) {
    let (mut err, mut size) = (0.0f64, 0.0f64);
    for k in 0..ERROR_SAMPLES {
        let v = pdeshape::TAU * k as f64 / ERROR_SAMPLES as f64;
        let p = c.curve.point(v);
        let d = (s.point(c.u, v) - p).norm();
        if d.is_nan() || d > err {
            err = d;
        }
        size = size.max(p.norm());
    }
    (err, err / size.max(f64::MIN_POSITIVE))
}

/// The report for a solved design; the second value lists what deserves a warning.
pub fn report(design: &Loaded, built: &SolvedDesign) -> (String, Vec<String>) {
    let mut s = String::new();
    let mut warnings = Vec::new();
    let _ = writeln!(
        s,
        "design: {}{}",
        design.file,
        built
            .title
            .as_ref()
            .map(|t| format!(" ({t})"))
            .unwrap_or_default()
    );
    let o = &built.options;
    match built.fd_grid {
        Some([gu, gv]) => {
            let _ = writeln!(
                s,
                "solver: finite differences on a {gu} × {gv} grid (second order)"
            );
        }
        None => {
            let _ = writeln!(
                s,
                "solver: {} Fourier modes, spectral remainder {}, {} samples per curve",
                o.modes,
                if o.remainder { "on" } else { "off" },
                if o.samples == 0 {
                    "automatic".to_string()
                } else {
                    o.samples.to_string()
                }
            );
        }
    }
    let _ = writeln!(s, "curves: {}", built.curves.len());
    for c in &built.curves {
        let _ = writeln!(s, "  {} ({})", c.name, c.kind);
    }
    for (i, patch) in built.surfaces.iter().enumerate() {
        match &patch.kind {
            SurfaceKind::Blend(b) => {
                s.push_str(&crate::blend::report(design, b));
                continue;
            }
            SurfaceKind::Spline(net, _) => {
                s.push_str(&crate::spline::report_text(net));
                continue;
            }
            SurfaceKind::Parametric(_) => {
                let _ = writeln!(s, "surface {i} '{}': {}", patch.name, patch.kind.word());
                continue;
            }
            SurfaceKind::Pde(_) | SurfaceKind::Fd(_) | SurfaceKind::SpineEdited(_) => {}
        }
        let conds = &patch.conditions;
        let _ = writeln!(s, "patch {i} '{}':", patch.name);
        if let Some(op) = &patch.operator {
            let _ = writeln!(s, "  operator: {}", describe_operator(op));
        }
        let _ = writeln!(s, "  conditions:");
        for (k, c) in conds.iter().enumerate() {
            let name = c
                .curve_name
                .as_ref()
                .map(|n| format!("'{n}'"))
                .unwrap_or_else(|| "inline".to_string());
            let _ = writeln!(
                s,
                "    [{k}] u = {:<6} {:<9} curve {name} ({})",
                c.u,
                derivative_name(c.derivative),
                c.kind
            );
        }
        spine_lines(&mut s, patch);
        let errors: Vec<(f64, usize, f64, f64)> = match patch.pde() {
            Some(pde) => {
                let _ = writeln!(s, "  modes:");
                let _ = writeln!(s, "    {:>4}  {:>12}  basis", "n", "condition");
                for m in pde.mode_reports() {
                    let _ = writeln!(
                        s,
                        "    {:>4}  {:>12.3e}  {}",
                        m.n, m.condition_number, m.basis
                    );
                }
                pde.condition_errors(ERROR_SAMPLES)
                    .iter()
                    .map(|e| (e.u, e.derivative, e.absolute, e.relative))
                    .collect()
            }
            None => conds
                .iter()
                .filter(|c| c.derivative == 0)
                .map(|c| {
                    let (a, r) = position_error(patch.surface(), c);
                    (c.u, 0, a, r)
                })
                .collect(),
        };
        let _ = writeln!(
            s,
            "  condition errors (max over {ERROR_SAMPLES} values of v):"
        );
        let _ = writeln!(
            s,
            "    {:<8} {:<9} {:>12}  {:>12}",
            "u", "condition", "absolute", "relative"
        );
        // Finite differences meet their conditions only to the grid's accuracy.
        let warn_at = if patch.pde().is_some() {
            WARN_RELATIVE
        } else {
            f64::INFINITY
        };
        for (u, d, absolute, relative) in errors {
            let _ = writeln!(
                s,
                "    {:<8} {:<9} {:>12.3e}  {:>12.3e}",
                u,
                derivative_name(d),
                absolute,
                relative
            );
            if relative > warn_at || relative.is_nan() {
                warnings.push(format!(
                    "patch '{}': the {} condition at u = {} is met only to {:.3e} (relative)",
                    patch.name,
                    derivative_name(d),
                    u,
                    relative
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
    if built.multi_patch {
        let _ = writeln!(s, "shared edges:");
        if built.edges().is_empty() {
            let _ = writeln!(s, "  none (no named position curve is used by two patches)");
        }
        for e in built.edges() {
            let r = &e.report;
            let _ = writeln!(
                s,
                "  '{}' u = {} | '{}' u = {}  along '{}':  G0 = {:.3e}  G1 = {:.3e} rad",
                built.surfaces[r.a].name, r.ua, built.surfaces[r.b].name, r.ub, e.curve, r.g0, r.g1
            );
        }
    }
    if !built.attachments.is_empty() {
        let _ = writeln!(
            s,
            "attachments (G0/G1 by closest points on the host, {ATTACH_SAMPLES} samples):"
        );
        for r in built.attachment_reports(ATTACH_SAMPLES) {
            let a = &r.attachment;
            let host = &built.surfaces[a.host];
            let size = attach_size(host.surface());
            let _ = writeln!(
                s,
                "  '{}' u = {} on '{}' along '{}'{}:  G0 = {:.3e}  G1 = {:.3e} rad",
                built.surfaces[a.patch].name,
                a.u,
                host.name,
                a.curve.as_deref().unwrap_or("(inline curve)"),
                if a.tangent { " (tangent field)" } else { "" },
                r.g0,
                r.g1
            );
            let place = format!(
                "attachment of '{}' to '{}'",
                built.surfaces[a.patch].name, host.name
            );
            if r.g0.is_nan() || r.g0 > ATTACH_G0 * size.max(1.0) {
                warnings.push(format!("{place}: G0 = {:.3e} (positions apart)", r.g0));
            }
            if a.tangent && (r.g1.is_nan() || r.g1 > ATTACH_G1) {
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
        }
    }
    if !built.trims.is_empty() {
        let _ = writeln!(s, "trims:");
        // The design's output grid (its [output] table, or the default).
        let (nu, nv) = design
            .grid(None, None)
            .unwrap_or((pdeshape::design::DEFAULT_NU, pdeshape::design::DEFAULT_NV));
        let params = built.param_meshes(nu, nv);
        for (k, t) in built.trims.iter().enumerate() {
            let name = &built.surfaces[t.surface].name;
            let _ = writeln!(
                s,
                "  {}: surface '{name}', {} curve(s), method {}",
                t.place,
                t.curves.len(),
                t.method.word()
            );
            for c in &t.curves {
                let _ = writeln!(s, "    {} enclosing {:.6e} of (u, v)", c.kind(), c.area());
            }
            if let Ok(p) = &params {
                if let Some(pm) = &p[t.surface] {
                    let du =
                        built.surfaces[t.surface].surface().u_range().length() / (nu - 1) as f64;
                    let dv = match built.surfaces[t.surface].surface().v_domain() {
                        pdeshape::surface::VDomain::Periodic => pdeshape::TAU / nv as f64,
                        pdeshape::surface::VDomain::Interval(a, b) => (b - a) / (nv - 1) as f64,
                    };
                    let periodic = built.surfaces[t.surface].surface().v_domain().is_periodic();
                    let pts: Vec<[f64; 3]> = (pm.grid_triangles..pm.triangles.len())
                        .flat_map(|k| pm.triangle_uv(k, periodic))
                        .map(|p| [p[0] / du, p[1] / dv, 0.0])
                        .collect();
                    let tris: Vec<[u32; 3]> = (0..(pts.len() / 3) as u32)
                        .map(|k| [3 * k, 3 * k + 1, 3 * k + 2])
                        .collect();
                    let q = pdeshape::trim::quality(&pts, &tris, None);
                    let _ = writeln!(
                        s,
                        "    re-meshed on {nu} × {nv}: {} triangles, smallest angle {:.1}°, \
                         largest aspect ratio {:.2} (in grid cells), {} inverted",
                        q.triangles, q.min_angle_deg, q.max_aspect, q.inverted
                    );
                    if q.inverted > 0 {
                        warnings.push(format!("{}: {} inverted triangles", t.place, q.inverted));
                    }
                }
            }
            let _ = k;
        }
    }
    parameter_lines(&mut s, design);
    (s, warnings)
}

/// The design's `[[parameters]]`: value, bounds, neutral value and what each drives.
fn parameter_lines(s: &mut String, design: &Loaded) {
    let Ok(list) = pdeshape::design::design_parameters(&design.spec) else {
        return;
    };
    if list.is_empty() {
        return;
    }
    let _ = writeln!(s, "parameters:");
    for p in &list {
        let with = if p.with.is_empty() {
            String::new()
        } else {
            format!(" (with {})", p.with.join(", "))
        };
        let _ = writeln!(
            s,
            "  {} = {} in [{}, {}] (neutral {}): {}{with}",
            p.name,
            p.value,
            p.min,
            p.max,
            p.neutral,
            p.kind.describe()
        );
    }
}

/// The parameters as JSON (empty without `[[parameters]]`).
fn parameters_json(design: &Loaded) -> serde_json::Value {
    let list = pdeshape::design::design_parameters(&design.spec).unwrap_or_default();
    list.iter()
        .zip(&design.spec.parameters)
        .map(|(p, spec)| {
            serde_json::json!({
                "name": p.name, "kind": spec.kind.word(), "curve": p.kind.curve(),
                "with": p.with, "value": jnum(p.value), "min": jnum(p.min), "max": jnum(p.max),
                "neutral": jnum(p.neutral), "drives": p.kind.describe(),
            })
        })
        .collect()
}

/// Samples along each attachment for its G0/G1 report.
const ATTACH_SAMPLES: usize = 512;
/// G0 above this (times the host's size, at least 1) is warned about (the 1e-10).
const ATTACH_G0: f64 = 1e-10;
/// G1 above this (radians) along an attachment with a tangent field is warned about.
const ATTACH_G1: f64 = 1e-8;

/// The diagonal of a surface's bounding box on a coarse grid (the scale of its G0).
fn attach_size(s: &dyn pdeshape::surface::Surface) -> f64 {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    let r = s.u_range();
    for i in 0..=16 {
        for j in 0..32 {
            let u = r.start + (r.end - r.start) * i as f64 / 16.0;
            let p = s.point(u, pdeshape::TAU * j as f64 / 32.0);
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    }
    (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt()
}

/// A number for JSON: non-finite values as null.
fn jnum(x: f64) -> serde_json::Value {
    if x.is_finite() {
        serde_json::json!(x)
    } else {
        serde_json::Value::Null
    }
}

/// The report as JSON: per surface its kind, operator, modes and condition errors; shared edges;
/// warnings; and the text report.
pub fn report_json(design: &Loaded, built: &SolvedDesign) -> serde_json::Value {
    use serde_json::json;
    let (text, warnings) = report(design, built);
    let surfaces: Vec<serde_json::Value> = built
        .surfaces
        .iter()
        .map(|patch| {
            let mut o = json!({ "name": patch.name, "kind": patch.kind.word() });
            if let Some(op) = &patch.operator {
                o["operator"] = json!(describe_operator(op));
            }
            if !matches!(patch.kind, SurfaceKind::Pde(_) | SurfaceKind::Fd(_)) {
                return o;
            }
            if let Some(pde) = patch.pde() {
                o["modes"] = pde
                    .mode_reports()
                    .iter()
                    .map(|m| json!({ "n": m.n, "condition_number": jnum(m.condition_number), "basis": m.basis }))
                    .collect();
                o["condition_errors"] = pde
                    .condition_errors(ERROR_SAMPLES)
                    .iter()
                    .map(|e| json!({ "u": e.u, "derivative": e.derivative, "absolute": jnum(e.absolute), "relative": jnum(e.relative) }))
                    .collect();
            } else {
                o["condition_errors"] = patch
                    .conditions
                    .iter()
                    .filter(|c| c.derivative == 0)
                    .map(|c| {
                        let (a, r) = position_error(patch.surface(), c);
                        json!({ "u": c.u, "derivative": 0, "absolute": jnum(a), "relative": jnum(r) })
                    })
                    .collect();
            }
            o
        })
        .collect();
    let edges: Vec<serde_json::Value> = if built.multi_patch {
        built
            .edges()
            .iter()
            .map(|e| {
                let r = &e.report;
                json!({
                    "a": built.surfaces[r.a].name, "ua": r.ua,
                    "b": built.surfaces[r.b].name, "ub": r.ub,
                    "curve": e.curve, "g0": jnum(r.g0), "g1": jnum(r.g1),
                })
            })
            .collect()
    } else {
        Vec::new()
    };
    let attachments: Vec<serde_json::Value> = built
        .attachment_reports(ATTACH_SAMPLES)
        .iter()
        .map(|r| {
            let a = &r.attachment;
            json!({
                "patch": built.surfaces[a.patch].name, "u": a.u,
                "host": built.surfaces[a.host].name, "curve": a.curve,
                "tangent": a.tangent, "samples": r.samples,
                "g0": jnum(r.g0), "g1": jnum(r.g1),
            })
        })
        .collect();
    json!({
        "ok": true,
        "design": design.file,
        "title": built.title,
        "surfaces": surfaces,
        "edges": edges,
        "attachments": attachments,
        "parameters": parameters_json(design),
        "warnings": warnings,
        "report": text,
    })
}

/// The sections other commands act on, checked as those commands would read them, so that
/// `check` refuses what they refuse: `[shell]` (thickness, material, elements, edges, loads).
fn check_sections(design: &Loaded, built: &SolvedDesign) -> Result<(), CliError> {
    if design.spec.shell.is_some() {
        pdeshape::shell::ShellSetup::new(&design.spec, &built.names())
            .map_err(|e| design.error(&e))?;
    }
    Ok(())
}

pub fn run(args: &Args) -> Result<(), CliError> {
    if args.json {
        let result = common::load(&args.design).and_then(|mut design| {
            common::apply_sets(&mut design, &args.set)?;
            let built = design.build()?;
            check_sections(&design, &built)?;
            Ok(report_json(&design, &built))
        });
        return match result {
            Ok(v) => {
                common::print_stdout(&format!("{v}\n"));
                Ok(())
            }
            Err(e) => {
                let v = serde_json::json!({ "ok": false, "error": e.message });
                common::print_stdout(&format!("{v}\n"));
                Err(e)
            }
        };
    }
    let mut design = common::load(&args.design)?;
    common::apply_sets(&mut design, &args.set)?;
    let built = design.build()?;
    check_sections(&design, &built)?;
    let (text, warnings) = report(&design, &built);
    let mut text = text;
    for w in &warnings {
        let _ = writeln!(text, "warning: {w}");
    }
    text.push_str("OK\n");
    common::print_stdout(&text);
    Ok(())
}

/// The spine of a PDE patch (§5.3): its Bézier control points, the Hermite form of a cubic
/// spine, and the `[[spine]]` edit if there is one.
fn spine_lines(s: &mut String, patch: &pdeshape::design::DesignSurface) {
    let Some(r) = patch.spine_report() else {
        return;
    };
    let pt = |p: &pdeshape::Vec3| format!("({:.6}, {:.6}, {:.6})", p.x, p.y, p.z);
    let list = |ps: &[pdeshape::Vec3]| ps.iter().map(pt).collect::<Vec<_>>().join(" ");
    let degree = r.solved.len().saturating_sub(1);
    let _ = writeln!(
        s,
        "  spine A0 (Bézier, degree {degree}): {}",
        list(&r.solved)
    );
    if degree == 3 {
        let [p0, p1, p2, p3] = [r.solved[0], r.solved[1], r.solved[2], r.solved[3]];
        let _ = writeln!(
            s,
            "    Hermite form: p0 = {}  p1 = {}  d0 = {}  d1 = {}",
            pt(&p0),
            pt(&p3),
            pt(&((p1 - p0) * 3.0)),
            pt(&((p3 - p2) * 3.0))
        );
    }
    if let Some((carry, control)) = &r.edited {
        let _ = writeln!(
            s,
            "  spine edit ({}): {}",
            match carry {
                pdeshape::spec::SpineCarry::Frame => "sections turn with the spine's frame",
                pdeshape::spec::SpineCarry::Translate => "sections translated",
            },
            list(control)
        );
    }
}
