//! Meshes during a drag: the affine model of [`super::preview`] gives the meshes a fresh
//! tessellation of the design solved from scratch gives, to the single precision they are
//! stored in, on every frame; surfaces the model does not cover are tessellated as before.

use super::*;
use crate::mesh::GridMesh;
use crate::spec::{parse_design, DesignSpec};
use crate::Vec3;

fn example(name: &str) -> String {
    let path = format!("{}/../../examples/{name}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// The largest difference between two meshes' positions, each coordinate measured against
/// its bound: the model's agreement (of the surface's extent, checked on every frame at its
/// probes and exact up to rounding elsewhere for an affine surface) plus one unit in the last
/// place of single precision (each side rounded once to `f32`). Normals against the same
/// rounding amplified by the grid's worst `1 / sin θ`: 1e-6 bounds both on these grids.
fn worst(a: &[GridMesh], b: &[GridMesh]) -> f64 {
    let mut worst = 0.0f64;
    for (ma, mb) in a.iter().zip(b) {
        assert_eq!((ma.nu, ma.nv), (mb.nu, mb.nv));
        let extent = mb
            .positions
            .iter()
            .flatten()
            .fold(0.0f64, |m, &c| m.max(f64::from(c).abs()));
        for (pa, pb) in ma.positions.iter().zip(&mb.positions) {
            for c in 0..3 {
                let bound = preview::AGREEMENT * extent
                    + f64::from(pb[c]).abs() * f64::from(f32::EPSILON)
                    + f64::from(f32::MIN_POSITIVE);
                worst = worst.max(f64::from(pa[c] - pb[c]).abs() / bound);
            }
        }
        for (na, nb) in ma.normals.iter().zip(&mb.normals) {
            for c in 0..3 {
                worst = worst.max(f64::from(na[c] - nb[c]).abs() / 1e-6);
            }
        }
    }
    worst
}

/// Drags control point `index` of `curve` round a circle of `radius` (in `frames` edits, as
/// the designer sends them) and compares every frame's meshes with the design solved afresh.
/// Returns the number of meshes the model gave.
fn drag(spec: &DesignSpec, curve: &str, index: usize, grid: (usize, usize), radius: f64) -> usize {
    let mut d = compile(spec).unwrap();
    d.meshes(grid.0, grid.1).unwrap();
    let start = preview::control_point(
        d.spec(),
        &preview::DragKey {
            curve: curve.to_string(),
            index,
        },
    )
    .unwrap();
    for f in 1..=8 {
        let a = f as f64 * 0.7;
        let p = start + Vec3::new(a.cos() - 1.0, a.sin(), 0.3 * a.sin()) * radius;
        let edit = Edit::MoveControlPoint {
            name: curve.to_string(),
            index,
            point: [p.x, p.y, p.z],
        };
        d.apply_dragging(&edit).unwrap();
        let got = d.meshes(grid.0, grid.1).unwrap().to_vec();
        let want = solve_design(d.spec())
            .unwrap()
            .meshes(grid.0, grid.1)
            .unwrap();
        let w = worst(&got, &want);
        assert!(w <= 1.0, "{curve}[{index}], frame {f}: {w} of the bound");
    }
    let predicted = d.predicted_meshes();
    // The same point moved back with meshes on another grid (an undo after a drag's coarse
    // frames, shown on the full grid): no model is made for one frame, and the meshes are the
    // design's.
    let full = (grid.0 * 2, grid.1 * 2);
    let p = [start.x, start.y, start.z];
    d.apply_dragging(&Edit::MoveControlPoint {
        name: curve.to_string(),
        index,
        point: p,
    })
    .unwrap();
    let got = d.meshes(full.0, full.1).unwrap().to_vec();
    let want = solve_design(d.spec())
        .unwrap()
        .meshes(full.0, full.1)
        .unwrap();
    assert!(
        worst(&got, &want) <= 1.0,
        "{curve}[{index}] on the full grid"
    );
    assert_eq!(d.predicted_meshes(), predicted);
    predicted
}

#[test]
fn a_dragged_side_of_the_pentagon_is_predicted_to_single_precision() {
    let spec = parse_design(&example("nsided_pentagon.toml")).unwrap();
    let predicted = drag(&spec, "side0", 1, (32, 64), 0.1);
    // The model is made on the second frame of the drag: frames 2 to 8, five pieces each.
    assert_eq!(predicted, 7 * 5);
}

/// The cup with its widest section a closed B-spline: both patches depend on it (position of
/// both, and through the derivative curve of both) and both are predicted.
#[test]
fn a_dragged_section_of_the_cup_is_predicted_on_both_patches() {
    let text = example("cup.toml").replace(
        "[curves.belly]\ntype = \"circle\"\ncenter = [0.0, 0.0, 0.9]\nradius = 1.5",
        "[curves.belly]\ntype = \"bspline\"\ndegree = 3\nperiodic = true\ncontrol = [\
         [1.5, 0.0, 0.9], [1.06, 1.06, 0.9], [0.0, 1.5, 0.9], [-1.06, 1.06, 0.9], \
         [-1.5, 0.0, 0.9], [-1.06, -1.06, 0.9], [0.0, -1.5, 0.9], [1.06, -1.06, 0.9]]",
    );
    assert!(text.contains("periodic = true"), "the cup's belly changed");
    let spec = parse_design(&text).unwrap();
    assert_eq!(drag(&spec, "belly", 2, (32, 64), 0.2), 7 * 2);
}

/// Edits of another point, or edits applied outside a drag, make no model: the meshes are
/// the design's, bit for bit.
#[test]
fn single_edits_are_tessellated() {
    let spec = parse_design(&example("nsided_pentagon.toml")).unwrap();
    let mut d = compile(&spec).unwrap();
    let mut e = compile(&spec).unwrap();
    let moves = [("side0", 1), ("side1", 1), ("side0", 2), ("side2", 1)];
    for (f, (curve, index)) in moves.into_iter().chain(moves).enumerate() {
        let key = preview::DragKey {
            curve: curve.to_string(),
            index,
        };
        let p = preview::control_point(d.spec(), &key).unwrap() + Vec3::new(0.0, 0.0, 0.05);
        let edit = Edit::MoveControlPoint {
            name: curve.to_string(),
            index,
            point: [p.x, p.y, p.z],
        };
        // Alternating points in a drag, and one point again and again outside one.
        d.apply_dragging(&edit).unwrap();
        let got = d.meshes(16, 16).unwrap().to_vec();
        let want = solve_design(d.spec()).unwrap().meshes(16, 16).unwrap();
        assert_eq!(got, want, "edit {f}");
        let again = Edit::MoveControlPoint {
            name: "side3".to_string(),
            index: 1,
            point: [0.8, -0.47, 0.15 + 0.01 * f as f64],
        };
        e.apply(&again).unwrap();
        let got = e.meshes(16, 16).unwrap().to_vec();
        let want = solve_design(e.spec()).unwrap().meshes(16, 16).unwrap();
        assert_eq!(got, want, "edit {f} outside a drag");
    }
    assert_eq!(d.predicted_meshes() + e.predicted_meshes(), 0);
}

/// The teacup with its rim a closed B-spline: the bowl depends on it affinely; the handle is
/// attached to the bowl by curves on it (closest points, tangent fields), so whether it is
/// affine in the rim is for the model's checks to find. Either way every frame's meshes are the
/// design's, and at least the bowl is predicted.
#[test]
fn a_dragged_rim_of_the_teacup_gives_the_designs_meshes() {
    let text = example("teacup.toml").replace(
        "[curves.rim]\ntype = \"circle\"\ncenter = [0.0, 0.0, 2.4]\nradius = 1.35",
        "[curves.rim]\ntype = \"bspline\"\ndegree = 3\nperiodic = true\ncontrol = [\
         [1.35, 0.0, 2.4], [0.955, 0.955, 2.4], [0.0, 1.35, 2.4], [-0.955, 0.955, 2.4], \
         [-1.35, 0.0, 2.4], [-0.955, -0.955, 2.4], [0.0, -1.35, 2.4], [0.955, -0.955, 2.4]]",
    );
    assert!(text.contains("periodic = true"), "the teacup's rim changed");
    let spec = parse_design(&text).unwrap();
    assert!(drag(&spec, "rim", 3, (32, 64), 0.1) >= 7);
}
