//! CAD exchange: every surface of a design as a tensor B-spline with a known deviation
//! ([`certify`]: proven for analytic PDE patches and, by interval arithmetic, for formula
//! surfaces, exact for piecewise polynomial surfaces, sampled otherwise), written as STEP (ISO 10303-21, AP214: a shell of
//! `ADVANCED_FACE`s over `B_SPLINE_SURFACE_WITH_KNOTS` with shared edges and vertices,
//! [`step`]) and IGES 5.3 (entity 128, through the one IGES writer of `splinepde::export`), and
//! read back ([`read`]) to measure the round trip.

pub mod certify;
pub mod curve;
mod export;
mod hermite;
pub mod iges_read;
pub mod import;
pub mod read;
pub mod step;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_edges;
#[cfg(test)]
mod tests_remainder;
pub mod trimmed;

pub use certify::{approximate, Approximation, Certificate};
pub use export::{default_tolerance, export_design, CadExport, CadExportError};
pub use hermite::hermite_interpolant;

use crate::design::{SolvedDesign, SurfaceKind};
use crate::spline::BSplineSurface;
use crate::surface::{Surface, VDomain};
use crate::{Error, Result, Vec3, TAU};

/// One surface of a design in CAD form.
#[derive(Clone, Debug)]
pub struct CadSurface {
    /// The surface's name in the design.
    pub name: String,
    /// Its B-spline approximation (with the holes' trimming applied to `approx.net`).
    pub approx: Approximation,
    /// The holes of a trimmed surface (`[[trims]]`), on `approx.net` (whose `v` window a hole
    /// across a periodic seam moves: see [`trimmed`]).
    pub holes: Vec<trimmed::Hole>,
}

/// A design in CAD form.
#[derive(Clone, Debug)]
pub struct CadModel {
    /// The design's title (or `design`).
    pub name: String,
    /// The design's surfaces, in the design's order.
    pub surfaces: Vec<CadSurface>,
    /// The tolerance asked for (absolute, design units).
    pub tolerance: f64,
}

/// The diagonal of the bounding box of a 17 × 17 sample of every surface: the design's size.
pub fn design_size(design: &SolvedDesign) -> f64 {
    let (mut lo, mut hi) = (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
    for s in &design.surfaces {
        let surface = s.kind.surface();
        let u = surface.u_range();
        let (v0, v1) = match surface.v_domain() {
            VDomain::Periodic => (0.0, TAU),
            VDomain::Interval(a, b) => (a, b),
        };
        for i in 0..=16 {
            for j in 0..=16 {
                let p = surface.point(
                    u.start + (u.end - u.start) * i as f64 / 16.0,
                    v0 + (v1 - v0) * j as f64 / 16.0,
                );
                if p.iter().all(|x| x.is_finite()) {
                    lo = lo.inf(&p);
                    hi = hi.sup(&p);
                }
            }
        }
    }
    let d = (hi - lo).norm();
    if d.is_finite() && d > 0.0 {
        d
    } else {
        1.0
    }
}

/// Every surface of the design approximated within `tolerance` (absolute), with the holes of
/// trimmed surfaces as edges ([`trimmed::holes`]). Periodic analytic
/// PDE patches share one `v` grid, and where the first or last row of one net lies within
/// `10⁻⁹ ×` the design's size of a row of an earlier net on the same `v` knots (an edge the two
/// patches share), the later row is made the earlier one, its distance added to the deviation:
/// neighbouring faces get identical boundary curves.
pub fn approximate_design(design: &SolvedDesign, tolerance: f64) -> Result<CadModel> {
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(Error::invalid(format!(
            "tolerance must be a positive number (got {tolerance})"
        ))
        .at("tolerance"));
    }
    let size = design_size(design);
    // One v grid for the analytic patches.
    let mut min_v = 1;
    for s in &design.surfaces {
        if let SurfaceKind::Pde(p) = &s.kind {
            if let Some(grid) = certify::pde_grid(p, tolerance, 1) {
                let (_, n) = grid.map_err(|e| located(e, &s.place))?;
                min_v = min_v.max(n);
            }
        }
    }
    // With a spectral remainder somewhere, the periodic patches whose bounds are known share
    // one non-uniform `v` grid: every break of their condition curves, cut until each meets
    // its budget ([`certify::shared_v_nodes`]).
    let plans: Vec<Option<certify::PdePlan>> = design
        .surfaces
        .iter()
        .map(|s| match &s.kind {
            SurfaceKind::Pde(p) => certify::PdePlan::new(p).ok(),
            _ => None,
        })
        .collect();
    let shared = if plans.iter().flatten().any(certify::PdePlan::has_remainder) {
        let known: Vec<&certify::PdePlan> = plans.iter().flatten().collect();
        Some(certify::shared_v_nodes(&known, tolerance, min_v.max(8))?)
    } else {
        None
    };
    let mut surfaces: Vec<CadSurface> = Vec::with_capacity(design.surfaces.len());
    for (s, plan) in design.surfaces.iter().zip(&plans) {
        let approx = match (&s.kind, plan, &shared) {
            (SurfaceKind::Pde(p), Some(plan), Some(vs)) => {
                certify::approximate_pde_on(p, plan, vs, tolerance)
            }
            _ => approximate(&s.kind, tolerance, min_v),
        }
        .map_err(|e| located(e, &s.place))?;
        surfaces.push(CadSurface {
            name: s.name.clone(),
            approx,
            holes: Vec::new(),
        });
    }
    share_edges(&mut surfaces, 1e-9 * size)?;
    let before: Vec<BSplineSurface> = if design.trims.is_empty() {
        Vec::new()
    } else {
        surfaces.iter().map(|s| s.approx.net.clone()).collect()
    };
    for t in &design.trims {
        let periodic = matches!(
            design.surfaces[t.surface].kind.surface().v_domain(),
            VDomain::Periodic
        );
        let s = &mut surfaces[t.surface];
        let (net, holes) = trimmed::holes(
            t,
            &s.approx.net,
            periodic && s.approx.closed[1],
            s.approx.deviation,
            s.approx.certificate.is_certified(),
            tolerance,
        )
        .map_err(|e| e.at(&t.place))?;
        s.approx.net = net;
        s.holes = holes;
    }
    follow_moved_seams(&mut surfaces, &before)?;
    Ok(CadModel {
        name: design.title.clone().unwrap_or_else(|| "design".to_string()),
        surfaces,
        tolerance,
    })
}

/// A trimmed face whose periodic `v` now starts elsewhere (a hole across `v = 0`, see
/// [`trimmed`]) has new `v` knots, so a neighbour that shared an edge with it (the same `v`
/// knots and an identical end row, from [`share_edges`]) would no longer: such a neighbour
/// without holes of its own is re-expressed from the same `v` (the same surface, see
/// [`trimmed::rotate_v`]). Knot insertion works row by row, so the shared rows stay identical
/// and the edge stays shared. (A neighbour with holes of its own keeps its own window: the two
/// faces then meet along two coincident edges.)
fn follow_moved_seams(surfaces: &mut [CadSurface], before: &[BSplineSurface]) -> Result<()> {
    let moved = |s: &CadSurface, old: &BSplineSurface| s.approx.net.knots_v() != old.knots_v();
    // Moved faces, and the neighbours moved with them (whose own neighbours follow in turn).
    let mut work: Vec<usize> = (0..before.len())
        .filter(|&b| moved(&surfaces[b], &before[b]))
        .collect();
    while let Some(b) = work.pop() {
        let old = &before[b];
        let start = surfaces[b].approx.net.domain()[1][0];
        let old_rows = end_rows(old);
        for a in 0..surfaces.len() {
            let s = &surfaces[a];
            if a == b || !s.holes.is_empty() || !s.approx.closed[1] || moved(s, &before[a]) {
                continue;
            }
            if s.approx.net.knots_v() != old.knots_v() {
                continue;
            }
            let shares = end_rows(&s.approx.net)
                .iter()
                .any(|r| old_rows.iter().any(|o| o == r));
            if shares {
                surfaces[a].approx.net = trimmed::rotate_v(&surfaces[a].approx.net, start)?;
                work.push(a);
            }
        }
    }
    Ok(())
}

/// A surface's error at its place in the design file; tolerance errors keep their place.
fn located(e: Error, place: &str) -> Error {
    if e.place() == "tolerance" {
        e
    } else {
        e.at(place)
    }
}

/// The control rows `i = 0` and `i = n_u − 1` of a net.
fn end_rows(net: &BSplineSurface) -> [Vec<Vec3>; 2] {
    let [nu, nv] = net.counts();
    let c = net.control();
    [c[..nv].to_vec(), c[(nu - 1) * nv..].to_vec()]
}

fn share_edges(surfaces: &mut [CadSurface], snap: f64) -> Result<()> {
    for b in 1..surfaces.len() {
        for side in 0..2 {
            let row = end_rows(&surfaces[b].approx.net)[side].clone();
            let found = (0..b).find_map(|a| {
                let net = &surfaces[a].approx.net;
                if net.knots_v() != surfaces[b].approx.net.knots_v() {
                    return None;
                }
                end_rows(net).into_iter().find_map(|r| {
                    let d = certify::row_distance(&r, &row);
                    (d <= snap).then_some((r, d))
                })
            });
            if let Some((target, d)) = found {
                let ap = &mut surfaces[b].approx;
                let [nu, nv] = ap.net.counts();
                let mut control = ap.net.control().to_vec();
                let start = if side == 0 { 0 } else { (nu - 1) * nv };
                control[start..start + nv].copy_from_slice(&target);
                ap.net = BSplineSurface::new(
                    ap.net.degree(),
                    ap.net.knots_u().to_vec(),
                    ap.net.knots_v().to_vec(),
                    control,
                )?;
                ap.deviation += d;
            }
        }
    }
    Ok(())
}

/// The largest distance between a surface and its approximation on a `k × k` lattice in every
/// cell of the net's knot grid.
pub fn sampled_deviation(surface: &dyn Surface, net: &BSplineSurface, k: usize) -> f64 {
    certify::sampled_deviation(surface, net, k)
}

/// The model as IGES 5.3: one entity 128 per surface (the writer of `splinepde::export`), the
/// unit declared in the Global section, labels from the surface names. A surface with holes is
/// an entity 144 (trimmed parametric surface) over its 128, the outer boundary the domain's,
/// one entity 142 (curve on a parametric surface) per hole with its parameter-space curve and
/// its model-space curve (entities 126), each running clockwise in `(u, v)`.
pub fn to_iges(
    model: &CadModel,
    unit: step::LengthUnit,
    file_name: &str,
    unix_seconds: u64,
) -> Result<String> {
    use crate::splinepde::export::{
        check_iges_surface, iges_entities, iges_surface_params, iges_timestamp, IgesEntity,
        IgesOptions, IgesSurface, IgesUnit, IGES_DEPENDENT, IGES_INDEPENDENT, IGES_PARAMETRIC,
    };
    if model.surfaces.is_empty() {
        return Err(Error::no_surface());
    }
    let unit = IgesUnit::from(unit);
    let ascii = |s: &str| -> String {
        s.chars()
            .map(|c| {
                if c.is_ascii() && !c.is_ascii_control() {
                    c
                } else {
                    '_'
                }
            })
            .collect()
    };
    let (name, file_name) = (ascii(&model.name), ascii(file_name));
    let many = model.surfaces.len() > 1;
    let mut entities: Vec<IgesEntity> = Vec::new();
    let mut maxc = 0.0f64;
    let de = |k: usize| (2 * k + 1).to_string();
    for (e, s) in model.surfaces.iter().enumerate() {
        let net = &s.approx.net;
        let surface = IgesSurface {
            degree: net.degree(),
            knots_u: net.knots_u().to_vec(),
            knots_v: net.knots_v().to_vec(),
            control: net.control().iter().map(|p| [p.x, p.y, p.z]).collect(),
            closed: s.approx.closed,
            label: s.name.to_ascii_uppercase(),
        };
        check_iges_surface(&surface)?;
        maxc = surface
            .control
            .iter()
            .flatten()
            .fold(maxc, |m, x| m.max(x.abs()));
        let subscript = if many { e + 1 } else { 0 };
        let trimmed = !s.holes.is_empty();
        let surface_de = entities.len();
        entities.push(IgesEntity {
            number: 128,
            form: 0,
            params: iges_surface_params(&surface),
            status: if trimmed {
                IGES_DEPENDENT
            } else {
                IGES_INDEPENDENT
            },
            label: surface.label.clone(),
            subscript,
        });
        if !trimmed {
            continue;
        }
        let mut bounds = Vec::new();
        for h in &s.holes {
            let (pc, edge) = if h.counter_clockwise {
                (h.pcurve.reversed(), h.edge.reversed())
            } else {
                (h.pcurve.clone(), h.edge.clone())
            };
            let b = entities.len();
            entities.push(IgesEntity {
                number: 126,
                form: 0,
                params: iges_curve_params(&pc, true),
                status: IGES_PARAMETRIC,
                label: "PCURVE".into(),
                subscript: h.curve + 1,
            });
            let c = entities.len();
            entities.push(IgesEntity {
                number: 126,
                form: 0,
                params: iges_curve_params(&edge, false),
                status: IGES_DEPENDENT,
                label: "HOLE".into(),
                subscript: h.curve + 1,
            });
            bounds.push(entities.len());
            entities.push(IgesEntity {
                number: 142,
                form: 0,
                // Created by projection, on the surface, its parameter-space curve, its
                // model-space curve, the parameter-space curve preferred.
                params: vec!["1".into(), de(surface_de), de(b), de(c), "1".into()],
                status: IGES_DEPENDENT,
                label: "BOUNDARY".into(),
                subscript: h.curve + 1,
            });
        }
        let mut params = vec![
            de(surface_de),
            "0".into(),
            bounds.len().to_string(),
            "0".into(),
        ];
        params.extend(bounds.iter().map(|&k| de(k)));
        entities.push(IgesEntity {
            number: 144,
            form: 0,
            params,
            status: IGES_INDEPENDENT,
            label: surface.label.clone(),
            subscript,
        });
    }
    let trimmed = model.surfaces.iter().any(|s| !s.holes.is_empty());
    let what = if trimmed {
        "B-spline surfaces (entity 128), trimmed (144)"
    } else {
        "B-spline surfaces (entity 128)"
    };
    iges_entities(
        &entities,
        &IgesOptions {
            file_name,
            timestamp: iges_timestamp(unix_seconds),
        },
        unit,
        &format!("pdeshape: {name} as {what}")
            .chars()
            .take(72)
            .collect::<String>(),
        maxc,
    )
}

/// The parameters of an entity 126 (after the type number) for a closed polynomial B-spline
/// curve; `planar` for a curve in a surface's parameter space (`z = 0`, normal `+z`).
fn iges_curve_params(c: &curve::BCurve, planar: bool) -> Vec<String> {
    use crate::splinepde::export::iges_real as real;
    let n = c.points.len();
    let [a, b] = c.domain();
    let mut params = vec![
        (n - 1).to_string(),
        c.degree.to_string(),
        if planar { "1" } else { "0" }.into(), // PROP1: planar
        "1".into(),                            // PROP2: closed
        "1".into(),                            // PROP3: polynomial
        "0".into(),                            // PROP4: not periodic
    ];
    params.extend(c.knots.iter().map(|&x| real(x)));
    params.extend((0..n).map(|_| real(1.0)));
    for p in &c.points {
        params.extend([real(p.x), real(p.y), real(if planar { 0.0 } else { p.z })]);
    }
    params.extend([real(a), real(b)]);
    if planar {
        params.extend([real(0.0), real(0.0), real(1.0)]);
    }
    params
}
