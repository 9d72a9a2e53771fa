//! The text of `pdeshape check` (also the designer's check panel).

use super::{derivative_name, Diagnostics, ATTACH_SAMPLES, ERROR_SAMPLES};
use crate::bfs::Blend;
use crate::design::{DesignSurface, SolvedDesign, SolvedSpline, SurfaceKind};
use crate::spec::{DesignSpec, OperatorSpec, SpineCarry};
use std::fmt::Write;

/// The operator in words, e.g. `polyharmonic (∂²/∂u² + a²∂²/∂v²)^2, order 4 PDE, a = 1`.
pub fn describe_operator(op: &OperatorSpec) -> String {
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

/// The report of a solved `[blend]` (`spec` its design): elements, the joins' G0/G1/C1, the
/// distances to the data points, the seam gap.
pub fn blend_report(spec: &DesignSpec, b: &Blend) -> String {
    let mut t = String::new();
    let Some(spec) = &spec.blend else {
        return t;
    };
    let [nx, ny] = spec.elements;
    let _ = writeln!(
        t,
        "blend: {nx} × {ny} BFS elements{}, ε = {}, L = {}",
        if spec.periodic { ", periodic in x" } else { "" },
        spec.epsilon,
        spec.energy.describe()
    );
    let r = &b.report;
    let _ = writeln!(
        t,
        "condition errors along the joins ({} samples each): G0 = max |blend − primary|, \
         G1 = max angle between normals, C1 = max |∂y blend − cross derivative|",
        r.start.samples
    );
    for (name, j) in [("start (y = 0)", &r.start), ("end (y = 1)", &r.end)] {
        let _ = writeln!(
            t,
            "  {name}: G0 {:.3e}, G1 {:.3e} rad, C1 {:.3e}",
            j.g0, j.g1, j.cross
        );
    }
    if !r.point_distances.is_empty() {
        let _ = writeln!(t, "distance to the data points:");
        for (p, d) in spec.points.iter().zip(&r.point_distances) {
            let _ = writeln!(t, "  at [{}, {}]: {d:.3e}", p.at[0], p.at[1]);
        }
        let max = r.point_distances.iter().cloned().fold(0.0, f64::max);
        let rms = (r.point_distances.iter().map(|d| d * d).sum::<f64>()
            / r.point_distances.len() as f64)
            .sqrt();
        let _ = writeln!(t, "  max {max:.3e}, rms {rms:.3e}");
    }
    if let Some(g) = r.seam_gap {
        let _ = writeln!(
            t,
            "seam gap between x = 0 and x = 1: {g:.3e} (the joins are closed; periodic = true closes the blend)"
        );
    }
    t
}

/// The report of a solved `[spline]`: the PDE, the net, the rank and the free points.
pub fn spline_report(s: &SolvedSpline) -> String {
    let net = s.to_f64();
    let r = s.report();
    let list = |v: &[[usize; 2]]| {
        if v.is_empty() {
            "none".to_string()
        } else {
            v.iter()
                .map(|[i, j]| format!("[{i},{j}]"))
                .collect::<Vec<_>>()
                .join(" ")
        }
    };
    let mut out = format!(
        "PDE: {}\nnet: {} × {} control points, degree [{}, {}], {} arithmetic\n",
        net.operator.describe(),
        r.counts[0],
        r.counts[1],
        net.u.degree,
        net.v.degree,
        if matches!(s, SolvedSpline::Exact(_)) {
            "exact rational"
        } else {
            "f64"
        }
    );
    out += &format!(
        "equations: {} residual coefficients, rank {} (PDE alone: rank {} in {} control points)\n",
        r.equations,
        r.rank,
        r.pde_rank,
        r.counts[0] * r.counts[1]
    );
    out += &format!(
        "fixed: {}, unknown: {}, determined: {}, free: {} (solution set of dimension {})\n",
        r.fixed.len(),
        r.unknowns,
        r.determined.len(),
        r.free.len(),
        r.freedom
    );
    out += &format!("determined points: {}\n", list(&r.determined));
    out += &format!("free points: {}\n", list(&r.free));
    if !r.chosen_by.is_empty() {
        out += &format!(
            "free points chosen by minimising: {}\n",
            r.chosen_by.join("; then ")
        );
    }
    out
}

/// A number of `pdeshape check`'s text: [`crate::number::DIGITS`] significant digits.
fn n(x: f64) -> String {
    crate::number::sig(x, crate::number::DIGITS)
}

/// The whole text of `pdeshape check`: the verdict first ([`super::Verdict::label`] alone on
/// the first line), then a line per reason for it (`warning: …`, `attention: …`), then a blank
/// line and the details of [`check_report`].
pub fn check_text(file: &str, spec: &DesignSpec, built: &SolvedDesign, d: &Diagnostics) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "{}", d.verdict.label());
    s.push_str(&d.reasons());
    s.push('\n');
    s.push_str(&check_report(file, spec, built, d));
    s
}

/// The text of `pdeshape check` for the design file `file` (as shown), solved from `spec` into
/// `built`, with its diagnostics `d` (from [`super::diagnose`]): the solver, the curves, per
/// surface its operator, conditions, spine, modes and condition errors, the shared edges,
/// attachments, trims and parameters. The warnings are not in it (they are `d.warnings`).
pub fn check_report(
    file: &str,
    spec: &DesignSpec,
    built: &SolvedDesign,
    d: &Diagnostics,
) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "design: {file}{}",
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
    for (i, (patch, diag)) in built.surfaces.iter().zip(&d.surfaces).enumerate() {
        match &patch.kind {
            SurfaceKind::Blend(b) => {
                s.push_str(&blend_report(spec, b));
                continue;
            }
            SurfaceKind::Spline(net, _) => {
                s.push_str(&spline_report(net));
                continue;
            }
            SurfaceKind::Parametric(_)
            | SurfaceKind::Nurbs(_)
            | SurfaceKind::NSided(_)
            | SurfaceKind::Disk(_) => {
                let _ = writeln!(s, "surface {i} '{}': {}", patch.name, patch.kind.word());
                continue;
            }
            SurfaceKind::Pde(_) | SurfaceKind::Fd(_) | SurfaceKind::SpineEdited(_) => {}
        }
        let _ = writeln!(s, "patch {i} '{}':", patch.name);
        if let Some(op) = &diag.operator {
            let _ = writeln!(s, "  operator: {op}");
        }
        let _ = writeln!(s, "  conditions:");
        for (k, c) in patch.conditions.iter().enumerate() {
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
        if let Some(modes) = &diag.modes {
            let _ = writeln!(s, "  modes:");
            let _ = writeln!(s, "    {:>4}  {:>12}  basis", "n", "condition");
            for m in modes {
                let _ = writeln!(
                    s,
                    "    {:>4}  {:>12}  {}",
                    m.n,
                    n(m.condition_number),
                    m.basis
                );
            }
        }
        let _ = writeln!(
            s,
            "  condition errors (max over {ERROR_SAMPLES} values of v):"
        );
        let _ = writeln!(
            s,
            "    {:<8} {:<9} {:>12}  {:>12}",
            "u", "condition", "absolute", "relative"
        );
        for e in &diag.condition_errors {
            let _ = writeln!(
                s,
                "    {:<8} {:<9} {:>12}  {:>12}",
                e.u,
                derivative_name(e.derivative),
                n(e.absolute),
                n(e.relative)
            );
        }
    }
    if let Some(edges) = &d.edges {
        let _ = writeln!(s, "shared edges:");
        if edges.is_empty() {
            let _ = writeln!(s, "  none (no named position curve is used by two patches)");
        }
        for e in edges {
            let _ = writeln!(
                s,
                "  '{}' u = {} | '{}' u = {}  along '{}':  G0 = {}  G1 = {} rad  G2 = {}{}",
                e.a,
                e.ua,
                e.b,
                e.ub,
                e.curve,
                n(e.g0),
                n(e.g1),
                n(e.g2),
                if e.declared_crease {
                    "  (a crease the design declares)"
                } else {
                    ""
                }
            );
        }
    }
    if !built.attachments.is_empty() {
        let _ = writeln!(
            s,
            "attachments (G0/G1 by closest points on the host, {ATTACH_SAMPLES} samples):"
        );
        for a in &d.attachments {
            let _ = writeln!(
                s,
                "  '{}' u = {} on '{}' along '{}'{}:  G0 = {}  G1 = {} rad",
                a.patch,
                a.u,
                a.host,
                a.curve.as_deref().unwrap_or("(inline curve)"),
                if a.tangent { " (tangent field)" } else { "" },
                n(a.g0),
                n(a.g1)
            );
        }
    }
    if !d.trims.is_empty() {
        let _ = writeln!(s, "trims:");
        for t in &d.trims {
            let _ = writeln!(
                s,
                "  {}: surface '{}', {} curve(s), method {}",
                t.place,
                t.surface,
                t.curves.len(),
                t.method
            );
            for (kind, area) in &t.curves {
                let _ = writeln!(s, "    {kind} enclosing {area:.6e} of (u, v)");
            }
            if let Some(q) = &t.quality {
                let (nu, nv) = t.grid;
                let _ = writeln!(
                    s,
                    "    re-meshed on {nu} × {nv}: {} triangles, smallest angle {:.1}°, \
                     largest aspect ratio {:.2} (in grid cells), {} inverted",
                    q.triangles, q.min_angle_deg, q.max_aspect, q.inverted
                );
            }
        }
    }
    for n in &d.nsided {
        let _ = writeln!(
            s,
            "n-sided patch '{}' ({} sides): sides met to {:.1e} (relative)",
            n.name, n.sides, n.boundary
        );
        for (i, g) in n.g1.iter().enumerate() {
            let (t, w) = n.corners[i];
            let g1 = match g {
                Some(g) => format!("G1 to {g:.1e} rad"),
                None => "position only".to_string(),
            };
            let g2 = match n.g2.get(i).copied().flatten() {
                Some(g) => format!(", G2 to {g:.1e} (normal curvature × size)"),
                None => String::new(),
            };
            let c = match n.corner_curvature.get(i).copied().flatten() {
                Some(c) => format!(", curvature mismatch {c:.1e}"),
                None => String::new(),
            };
            let _ = writeln!(
                s,
                "  side {i}: {g1}{g2}; corner {i}: tangent mismatch {t:.1e} rad, twist mismatch \
                 {w:.1e}{c}"
            );
        }
    }
    for n in &d.networks {
        n.report(&mut s);
    }
    if !d.parameters.is_empty() {
        let _ = writeln!(s, "parameters:");
        for p in &d.parameters {
            let with = if p.with.is_empty() {
                String::new()
            } else {
                format!(" (with {})", p.with.join(", "))
            };
            let _ = writeln!(
                s,
                "  {} = {} in [{}, {}] (neutral {}): {}{with}",
                p.name, p.value, p.min, p.max, p.neutral, p.drives
            );
        }
    }
    s
}

/// The spine of a PDE patch (§5.3): its Bézier control points, the Hermite form of a cubic
/// spine, and the `[[spine]]` edit if there is one.
fn spine_lines(s: &mut String, patch: &DesignSurface) {
    let Some(r) = patch.spine_report() else {
        return;
    };
    let pt = |p: &crate::Vec3| format!("({:.6}, {:.6}, {:.6})", p.x, p.y, p.z);
    let list = |ps: &[crate::Vec3]| ps.iter().map(pt).collect::<Vec<_>>().join(" ");
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
                SpineCarry::Frame => "sections turn with the spine's frame",
                SpineCarry::Translate => "sections translated",
            },
            list(control)
        );
    }
}
