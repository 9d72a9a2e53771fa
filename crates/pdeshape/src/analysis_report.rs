//! What `pdeshape analyze` reports of a solved design (its table and JSON, also the designer's
//! analysis panel), and the curvature colours of `pdeshape render --color` and the designer.
//! Above `analysis` and `render`.

use crate::analysis::{curvature_grid, integrate_design, DesignIntegrals, Integrals, Quadrature};
use crate::design::SolvedDesign;
use crate::mesh::GridMesh;
use crate::surface::Surface;
use crate::Result;
use std::fmt::Write;

/// A number for JSON: finite numbers as they are, others as null.
pub fn num(x: f64) -> serde_json::Value {
    serde_json::Number::from_f64(x).map_or(serde_json::Value::Null, serde_json::Value::Number)
}

fn integrals_map(i: &Integrals) -> serde_json::Map<String, serde_json::Value> {
    let mut m = serde_json::Map::new();
    for (k, v) in [
        ("area", i.area),
        ("volume", i.volume),
        ("mean_integral", i.mean),
        ("mean_sq_integral", i.mean_sq),
        ("gauss_integral", i.gauss),
        ("bending_energy", i.bending_energy()),
        ("willmore", i.willmore()),
    ] {
        m.insert(k.to_string(), num(v));
    }
    m
}

/// The design's integrals as `pdeshape analyze --json` prints them (without trims), as
/// pretty-printed JSON ending in a newline: the title, whether the design is closed, each patch's
/// integrals, curvature ranges and quadrature figures, the total (with the reduced volume and
/// equivalent radius), the caps and the estimated quadrature error.
pub fn integrals_json(title: &Option<String>, d: &DesignIntegrals) -> String {
    let patches: Vec<serde_json::Value> = d
        .patches
        .iter()
        .enumerate()
        .map(|(k, i)| {
            let a = &d.analyses[k];
            let mut m = integrals_map(i);
            m.insert("name".into(), d.names[k].clone().into());
            m.insert("orientation".into(), num(d.orientation[k]));
            // K does not depend on the orientation; H follows it.
            let s = d.orientation[k];
            let (h0, h1) = (a.mean_range.0 * s, a.mean_range.1 * s);
            m.insert("gauss_min".into(), num(a.gauss_range.0));
            m.insert("gauss_max".into(), num(a.gauss_range.1));
            m.insert("mean_min".into(), num(h0.min(h1)));
            m.insert("mean_max".into(), num(h0.max(h1)));
            m.insert("quadrature_error".into(), num(a.error));
            m.insert("converged".into(), a.converged.into());
            m.insert("nodes".into(), serde_json::json!([a.u_nodes, a.v_nodes]));
            serde_json::Value::Object(m)
        })
        .collect();
    let mut total = integrals_map(&d.total);
    total.insert("reduced_volume".into(), num(d.total.reduced_volume()));
    total.insert("equivalent_radius".into(), num(d.total.equivalent_radius()));
    let caps: Vec<serde_json::Value> = d
        .caps
        .iter()
        .map(|c| {
            serde_json::json!({
                "patch": d.names[c.patch], "u": c.u, "volume": num(c.volume),
                "area": num(c.area), "planarity": num(c.planarity)
            })
        })
        .collect();
    let v = serde_json::json!({
        "title": title,
        "closed": d.closed,
        "patches": patches,
        "total": total,
        "caps": caps,
        "quadrature_error": num(d.error),
    });
    let mut s = serde_json::to_string_pretty(&v).unwrap_or_default();
    s.push('\n');
    s
}

/// The design's integrals as `pdeshape analyze` prints them (without trims), as a text table
/// with [`crate::number::DIGITS`] significant digits and, when the design declares `units`, the
/// unit of each column: first the total's area and volume, whether the design is closed and the
/// quadrature's estimated error (the summary), then the title, each patch's and the total's
/// integrals, each patch's curvature ranges, the caps and the reduced volume.
pub fn integrals_table(
    title: &Option<String>,
    units: Option<crate::spec::Units>,
    d: &DesignIntegrals,
) -> String {
    use crate::number::{length_power, quantity, sig, DIGITS};
    let l = units.map(|u| u.as_str());
    let unit = |p: i32| length_power(l, p);
    let head = |name: &str, p: i32| match unit(p) {
        u if u.is_empty() => name.to_string(),
        u => format!("{name} ({u})"),
    };
    let v = |x: f64| sig(x, DIGITS);
    let mut s = String::new();
    let converged = d.analyses.iter().all(|a| a.converged);
    let _ = writeln!(
        s,
        "total: area {}, volume {}; {}; quadrature error {}{}",
        quantity(d.total.area, &unit(2)),
        quantity(d.total.volume, &unit(3)),
        if d.closed {
            "closed"
        } else if d.caps.is_empty() {
            "open"
        } else {
            "closed by caps"
        },
        sig(d.error, 2),
        if converged {
            ""
        } else {
            " (NOT converged within the node budget)"
        }
    );
    if let Some(t) = title {
        let _ = writeln!(s, "design: {t}");
    }
    let _ = writeln!(s);
    let w = 16;
    let _ = writeln!(
        s,
        "{:<14}{:>w$}{:>w$}{:>w$}{:>w$}{:>w$}{:>w$}",
        "patch",
        head("area", 2),
        head("volume", 3),
        "bending",
        "willmore",
        "∫K dA",
        head("∫H dA", 1)
    );
    let row = |s: &mut String, name: &str, i: &Integrals| {
        let _ = writeln!(
            s,
            "{:<14}{:>w$}{:>w$}{:>w$}{:>w$}{:>w$}{:>w$}",
            name,
            v(i.area),
            v(i.volume),
            v(i.bending_energy()),
            v(i.willmore()),
            v(i.gauss),
            v(i.mean)
        );
    };
    for (k, i) in d.patches.iter().enumerate() {
        row(&mut s, &d.names[k], i);
    }
    row(&mut s, "total", &d.total);
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "{:<14}{:>w$}{:>w$}{:>w$}{:>w$}",
        "patch",
        head("K min", -2),
        head("K max", -2),
        head("H min", -1),
        head("H max", -1)
    );
    for (k, a) in d.analyses.iter().enumerate() {
        let sgn = d.orientation[k];
        let (h0, h1) = (a.mean_range.0 * sgn, a.mean_range.1 * sgn);
        let _ = writeln!(
            s,
            "{:<14}{:>w$}{:>w$}{:>w$}{:>w$}",
            d.names[k],
            v(a.gauss_range.0),
            v(a.gauss_range.1),
            v(h0.min(h1)),
            v(h0.max(h1))
        );
    }
    let _ = writeln!(s);
    let _ = writeln!(
        s,
        "closed: {}",
        if d.closed {
            "yes".to_string()
        } else if d.caps.is_empty() {
            "no (open in v: volume is the patches' (1/3)∫X·n dA only)".to_string()
        } else {
            let caps: Vec<String> = d
                .caps
                .iter()
                .map(|c| {
                    format!(
                        "'{}' u = {} (planarity {})",
                        d.names[c.patch],
                        c.u,
                        sig(c.planarity, 2)
                    )
                })
                .collect();
            format!("no; volume closed by caps over {}", caps.join(", "))
        }
    );
    let _ = writeln!(
        s,
        "reduced volume ν = {}   (R0 = √(A/4π) = {})",
        v(d.total.reduced_volume()),
        quantity(d.total.equivalent_radius(), &unit(1))
    );
    s
}

/// The JSON of `pdeshape analyze --json` without trims (the designer's analysis panel): the
/// design's integrals with the default quadrature.
pub fn design_json(built: &SolvedDesign) -> Result<String> {
    let di = integrate_design(built, &Quadrature::default())?;
    Ok(integrals_json(&built.title, &di))
}

/// sRGB colours per vertex, one list per mesh.
pub type MeshColors = Vec<Vec<[u8; 3]>>;

/// The curvature a picture is coloured by.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Curvature {
    /// Gaussian curvature K.
    Gauss,
    /// Mean curvature H (outward normal).
    Mean,
}

/// Per-vertex colours of every mesh (PDE patches, then parametric surfaces, in the order of
/// the design's surfaces) by `K` or `H`, and the range used: `range`, or
/// [`crate::render::robust_range`] of the values on the grids (1st to 99th percentile,
/// symmetric about 0 when it spans 0; `±1` if no value is finite). `H` is taken with the
/// design's outward orientation.
pub fn curvature_colors(
    built: &SolvedDesign,
    meshes: &[GridMesh],
    by: Curvature,
    range: Option<(f64, f64)>,
) -> Result<(MeshColors, f64, f64)> {
    let surfaces: Vec<&dyn Surface> = built.surfaces.iter().map(|s| s.surface()).collect();
    let orientation = match by {
        Curvature::Gauss => vec![1.0; surfaces.len()],
        Curvature::Mean => integrate_design(built, &Quadrature::default())?.orientation,
    };
    let values: Vec<Vec<f64>> = surfaces
        .iter()
        .zip(meshes)
        .zip(&orientation)
        .map(|((s, m), sign)| {
            let (k, h) = curvature_grid(*s, &m.u, &m.v);
            match by {
                Curvature::Gauss => k,
                Curvature::Mean => h.into_iter().map(|x| x * sign).collect(),
            }
        })
        .collect();
    let (lo, hi) = match range {
        Some(r) => r,
        None => crate::render::robust_range(values.iter().flatten()).unwrap_or((-1.0, 1.0)),
    };
    let colors = values
        .iter()
        .map(|v| crate::render::diverging_colors(v, lo, hi))
        .collect();
    Ok((colors, lo, hi))
}
