//! Builds the `[[disk]]` patches: one exact polyharmonic solve each (see
//! `pdeshape_geometry::disk`).

use super::solved::{DesignSurface, SurfaceKind};
use crate::disk::{polyline, DiskData, DiskPatch, MAX_SAMPLES};
use crate::spec::{DiskSpec, OperatorSpec};
use crate::{Error, Result, Vec3};
use std::sync::Arc;

/// The most samples per edge of a `[[disk]]` polyline.
pub(super) const MAX_PER_EDGE: usize = 64;

/// Builds every `[[disk]]` patch and appends it to `surfaces` (a name already taken is
/// refused at `disk[i].name`).
pub(crate) fn build_disks(specs: &[DiskSpec], surfaces: &mut Vec<DesignSurface>) -> Result<()> {
    for (i, spec) in specs.iter().enumerate() {
        let place = format!("disk[{i}]");
        if surfaces.iter().any(|s| s.name == spec.name) {
            return Err(Error::not_unique(format!(
                "the surface name '{}' is used twice",
                spec.name
            ))
            .at(&format!("{place}.name")));
        }
        let patch = build_one(spec).map_err(|e| e.at(&place))?;
        surfaces.push(DesignSurface {
            name: spec.name.clone(),
            place,
            kind: SurfaceKind::Disk(Arc::new(patch)),
            operator: Some(OperatorSpec::Polyharmonic {
                order: spec.order,
                a: 1.0,
            }),
            conditions: Vec::new(),
        });
    }
    Ok(())
}

/// One patch; errors are placed relative to its table.
pub(super) fn build_one(spec: &DiskSpec) -> Result<DiskPatch> {
    let k = spec.samples_per_edge;
    if !(1..=MAX_PER_EDGE).contains(&k) {
        return Err(
            Error::invalid(format!("is 1 to {MAX_PER_EDGE}, not {k}")).at("samples_per_edge")
        );
    }
    let n = spec.points.len();
    if n < 3 || n.saturating_mul(k) > MAX_SAMPLES {
        return Err(Error::invalid(format!(
            "needs 3 to {} points at {k} samples per edge, not {n}",
            MAX_SAMPLES / k
        ))
        .at("points"));
    }
    let samples = |v: &[[f64; 3]], name: &str| -> Result<Vec<Vec3>> {
        if v.len() != n {
            return Err(Error::invalid(format!(
                "has {} entries, not {n} like the points",
                v.len()
            ))
            .at(name));
        }
        let p: Vec<Vec3> = v.iter().map(|a| Vec3::new(a[0], a[1], a[2])).collect();
        Ok(if k == 1 { p } else { polyline(&p, k) })
    };
    let p = samples(&spec.points, "points")?;
    let d = spec
        .derivatives
        .as_deref()
        .map(|v| samples(v, "derivatives"))
        .transpose()?;
    let e = spec
        .second
        .as_deref()
        .map(|v| samples(v, "second"))
        .transpose()?;
    DiskPatch::solve(
        spec.order,
        &DiskData {
            positions: &p,
            derivatives: if spec.order >= 2 { d.as_deref() } else { None },
            second: if spec.order >= 3 { e.as_deref() } else { None },
        },
    )
    .map_err(|e| {
        // The solver names `positions`; the file calls them `points`.
        match e.place().strip_prefix("positions") {
            Some(rest) => Error::invalid(e.detail().to_string()).at(&format!("points{rest}")),
            None => e,
        }
    })
}

#[cfg(test)]
mod tests {
    use crate::design::solve_design;
    use crate::spec::parse_design;

    const CIRCLE: &str = "points = [[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]]\n";

    fn error(text: &str) -> String {
        let spec = parse_design(text).unwrap();
        let Err(e) = solve_design(&spec) else {
            panic!("not refused: {text}");
        };
        format!("{}: {}", e.place(), e.message())
    }

    #[test]
    fn a_circle_with_radial_ribbons_is_the_flat_disc() {
        let text = format!(
            "[[disk]]\nname = \"d\"\n{CIRCLE}derivatives = [[1, 0, 0], [0, 1, 0], [-1, 0, 0], \
             [0, -1, 0]]\n"
        );
        let solved = solve_design(&parse_design(&text).unwrap()).unwrap();
        let s = solved.surfaces[0].kind.surface();
        for (r, t) in [(0.0, 0.0), (0.5, 1.0), (0.9, 4.0), (1.0, 2.5)] {
            let x = s.partials(r, t).x;
            assert!(x.z.abs() < 1e-15, "{x}");
            // Four samples carry modes 0 to 2: the disc's map is exact for mode 1.
            assert!((x.x - r * f64::cos(t)).abs() < 1e-15, "{x}");
            assert!((x.y - r * f64::sin(t)).abs() < 1e-15, "{x}");
        }
    }

    #[test]
    fn bad_disk_tables_are_refused_naming_the_place() {
        let e = error(&format!("[[disk]]\nname = \"d\"\n{CIRCLE}"));
        assert!(e.starts_with("disk[0].derivatives:"), "{e}");
        let e = error(&format!(
            "[[disk]]\nname = \"d\"\norder = 1\n{CIRCLE}samples_per_edge = 65\n"
        ));
        assert!(e.starts_with("disk[0].samples_per_edge:"), "{e}");
        let e = error("[[disk]]\nname = \"d\"\norder = 1\npoints = [[0, 0, 0], [1, 0, 0]]\n");
        assert!(e.starts_with("disk[0].points:"), "{e}");
        let e = error(&format!(
            "[[disk]]\nname = \"d\"\n{CIRCLE}derivatives = [[1, 0, 0]]\n"
        ));
        assert!(e.starts_with("disk[0].derivatives:"), "{e}");
        let e = error(&format!(
            "[[disk]]\nname = \"d\"\norder = 1\n{CIRCLE}[[disk]]\nname = \"d\"\norder = 1\n{CIRCLE}"
        ));
        assert!(e.starts_with("disk[1].name:"), "{e}");
        let e = error(&format!("[[disk]]\nname = \"d\"\norder = 4\n{CIRCLE}"));
        assert!(e.starts_with("disk[0].order:"), "{e}");
    }
}
