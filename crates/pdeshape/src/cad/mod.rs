//! CAD exchange: every surface of a design as a tensor B-spline with a known deviation
//! ([`certify`]: proven for analytic PDE patches, exact for piecewise polynomial surfaces,
//! sampled for formula surfaces), written as STEP (ISO 10303-21, AP214: a shell of
//! `ADVANCED_FACE`s over `B_SPLINE_SURFACE_WITH_KNOTS` with shared edges and vertices,
//! [`step`]) and IGES 5.3 (entity 128, through the one IGES writer of `splinepde::export`), and
//! read back ([`read`]) to measure the round trip.

pub mod certify;
mod hermite;
pub mod read;
pub mod step;
#[cfg(test)]
mod tests;

pub use certify::{approximate, Approximation, Certificate};
pub use hermite::hermite_interpolant;

use crate::design::{SolvedDesign, SurfaceKind};
use crate::spline::BSplineSurface;
use crate::surface::{Surface, VDomain};
use crate::{Error, Result, Vec3, TAU};

/// One surface of a design in CAD form.
#[derive(Clone, Debug)]
pub struct CadSurface {
    pub name: String,
    pub approx: Approximation,
}

/// A design in CAD form.
#[derive(Clone, Debug)]
pub struct CadModel {
    /// The design's title (or `design`).
    pub name: String,
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

/// Every surface of the design approximated within `tolerance` (absolute). Periodic analytic
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
    let mut surfaces: Vec<CadSurface> = Vec::with_capacity(design.surfaces.len());
    for s in &design.surfaces {
        let approx = approximate(&s.kind, tolerance, min_v).map_err(|e| located(e, &s.place))?;
        surfaces.push(CadSurface {
            name: s.name.clone(),
            approx,
        });
    }
    share_edges(&mut surfaces, 1e-9 * size)?;
    Ok(CadModel {
        name: design.title.clone().unwrap_or_else(|| "design".to_string()),
        surfaces,
        tolerance,
    })
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
/// unit declared in the Global section, labels from the surface names.
pub fn to_iges(
    model: &CadModel,
    unit: step::LengthUnit,
    file_name: &str,
    unix_seconds: u64,
) -> Result<String> {
    use crate::splinepde::export::{
        iges_surfaces, iges_timestamp, IgesOptions, IgesSurface, IgesUnit,
    };
    if model.surfaces.is_empty() {
        return Err(Error::invalid("the design has no surface to write"));
    }
    let surfaces: Vec<IgesSurface> = model
        .surfaces
        .iter()
        .map(|s| {
            let net = &s.approx.net;
            IgesSurface {
                degree: net.degree(),
                knots_u: net.knots_u().to_vec(),
                knots_v: net.knots_v().to_vec(),
                control: net.control().iter().map(|p| [p.x, p.y, p.z]).collect(),
                closed: s.approx.closed,
                label: s.name.to_ascii_uppercase(),
            }
        })
        .collect();
    let unit = match unit {
        step::LengthUnit::Millimetre => IgesUnit::MILLIMETRE,
        step::LengthUnit::Centimetre => IgesUnit::CENTIMETRE,
        step::LengthUnit::Metre => IgesUnit::METRE,
        step::LengthUnit::Inch => IgesUnit::INCH,
    };
    let name: String = model
        .name
        .chars()
        .map(|c| {
            if c.is_ascii() && !c.is_ascii_control() {
                c
            } else {
                '_'
            }
        })
        .collect();
    let file_name: String = file_name
        .chars()
        .map(|c| {
            if c.is_ascii() && !c.is_ascii_control() {
                c
            } else {
                '_'
            }
        })
        .collect();
    iges_surfaces(
        &surfaces,
        &IgesOptions {
            file_name,
            timestamp: iges_timestamp(unix_seconds),
        },
        unit,
        &format!("pdeshape: {} as B-spline surfaces (entity 128)", name)
            .chars()
            .take(72)
            .collect::<String>(),
    )
}
