use super::*;
use crate::curve::{Bezier, Ellipse};
use std::f64::consts::FRAC_PI_2;
use std::f64::consts::PI;
use std::sync::Arc;

fn line(a: [f64; 3], b: [f64; 3]) -> NetworkCurve {
    NetworkCurve {
        curve: Arc::new(Bezier::new(vec![Vec3::from(a), Vec3::from(b)]).unwrap()),
        t0: 0.0,
        t1: 1.0,
    }
}

/// A grid of `nx + 1` vertical and `ny + 1` horizontal lines in the plane `z = 0`, each
/// overshooting the grid by `over`.
fn grid(nx: usize, ny: usize, over: f64) -> Vec<NetworkCurve> {
    let mut c = Vec::new();
    for j in 0..=ny {
        let y = j as f64;
        c.push(line([-over, y, 0.0], [nx as f64 + over, y, 0.0]));
    }
    for i in 0..=nx {
        let x = i as f64;
        c.push(line([x, -over, 0.0], [x, ny as f64 + over, 0.0]));
    }
    c
}

#[test]
fn a_grid_has_its_cells_as_faces_and_its_outline_open() {
    for over in [0.0, 0.4] {
        let net = Network::find(&grid(3, 2, over), &NetworkOptions::default()).unwrap();
        assert_eq!(net.nodes.len(), 12, "over {over}");
        assert_eq!(net.edges.len(), 17, "over {over}");
        assert_eq!(net.faces.len(), 6, "over {over}");
        assert_eq!(net.open.len(), 1);
        assert_eq!(
            net.open[0].sides.len(),
            4,
            "the outline's straight joints are merged"
        );
        for f in &net.faces {
            assert_eq!(f.sides.len(), 4);
            assert!((f.angle_sum - 2.0 * PI).abs() < 1e-12, "{}", f.angle_sum);
        }
        let n0 = net.nodes[0].normal;
        for node in &net.nodes {
            assert!((node.normal - n0).norm() < 1e-12, "one orientation");
            assert!(node.normal.z.abs() > 1.0 - 1e-15);
            assert_eq!(node.residual, 0.0);
        }
        // Inner pieces: 17 − the 10 of the outline.
        assert_eq!(net.inner_edges().len(), 7);
    }
}

#[test]
fn a_t_junction_is_inside_a_side_not_a_corner() {
    // The square [0, 2]² split by x = 1, its right half split by y = 1 (ending on x = 1).
    let curves = vec![
        line([0.0, 0.0, 0.0], [2.0, 0.0, 0.0]),
        line([2.0, 0.0, 0.0], [2.0, 2.0, 0.0]),
        line([2.0, 2.0, 0.0], [0.0, 2.0, 0.0]),
        line([0.0, 2.0, 0.0], [0.0, 0.0, 0.0]),
        line([1.0, 0.0, 0.0], [1.0, 2.0, 0.0]),
        line([1.0, 1.0, 0.0], [2.0, 1.0, 0.0]),
    ];
    let net = Network::find(&curves, &NetworkOptions::default()).unwrap();
    assert_eq!(net.faces.len(), 3);
    let sides: Vec<usize> = net.faces.iter().map(|f| f.sides.len()).collect();
    assert_eq!(sides, vec![4, 4, 4]);
    let merged: Vec<&Vec<Run>> = net
        .faces
        .iter()
        .flat_map(|f| f.sides.iter())
        .filter(|s| s.len() == 2)
        .collect();
    assert_eq!(
        merged.len(),
        1,
        "the left face's side x = 1 passes the T-junction"
    );
    assert!(merged[0].iter().all(|r| net.edges[r.edge].curve == 4));
}

#[test]
fn great_circles_on_a_sphere_give_radial_normal_fields() {
    // The octant x, y, z ≥ 0 of the unit sphere cut by the arc from (1,0,0) to (0,1,0) at
    // its middle meridian: the quarter circles in the three coordinate planes and the arc
    // from the pole (0,0,1) down to (1,1,0)/√2.
    let circle = |a: Vec3, b: Vec3, t1: f64| NetworkCurve {
        curve: Arc::new(Ellipse::new(Vec3::zeros(), a, b).unwrap()),
        t0: 0.0,
        t1,
    };
    let (x, y, z) = (Vec3::x(), Vec3::y(), Vec3::z());
    let d = (x + y) / 2f64.sqrt();
    let curves = vec![
        circle(x, y, FRAC_PI_2),
        circle(y, z, FRAC_PI_2),
        circle(z, x, FRAC_PI_2),
        circle(z, d, FRAC_PI_2),
    ];
    let net = Network::find(&curves, &NetworkOptions::default()).unwrap();
    assert_eq!(net.faces.len(), 2, "two triangles of the octant");
    for f in &net.faces {
        assert_eq!(f.sides.len(), 3);
    }
    for node in &net.nodes {
        let radial = node.point.normalize();
        assert!(node.normal.cross(&radial).norm() < 1e-12, "{node:?}");
    }
    // Along a great circle the rotation-minimising frame keeps the radial normal; the fields
    // are normal to the curve and radial to the accuracy of the marching (fourth order in
    // 1024 steps).
    for e in 0..net.edges.len() {
        let edge = &net.edges[e];
        let c = &net.curves[edge.curve];
        let field = net.normal_samples(e, 128);
        for (j, n) in field.iter().enumerate() {
            let s = normals::lobatto(j, 128);
            let p = c.curve.point(edge.t0 + s * (edge.t1 - edge.t0));
            assert!((n.norm() - 1.0).abs() < 1e-14);
            assert!(n.cross(&p).norm() < 1e-10, "edge {e} at {s}: {n:?} {p:?}");
        }
    }
}

#[test]
fn curves_that_do_not_enclose_anything_are_refused() {
    let apart = vec![
        line([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
        line([0.0, 1.0, 0.0], [1.0, 1.0, 0.0]),
    ];
    let err = Network::find(&apart, &NetworkOptions::default()).unwrap_err();
    assert!(err.to_string().contains("do not enclose"), "{err}");
    // Two curves crossing once: a plus sign, every piece with a free end.
    let plus = vec![
        line([-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
        line([0.0, -1.0, 0.0], [0.0, 1.0, 0.0]),
    ];
    assert!(Network::find(&plus, &NetworkOptions::default()).is_err());
    let one = vec![line([0.0, 0.0, 0.0], [1.0, 0.0, 0.0])];
    assert!(Network::find(&one, &NetworkOptions::default()).is_err());
}

#[test]
fn curves_that_miss_by_more_than_the_tolerance_do_not_meet() {
    // A triangle whose third side stops 1e-6 short of the first corner.
    let tri = |gap: f64| {
        vec![
            line([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]),
            line([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
            line([0.0, 1.0, 0.0], [0.0, gap, 0.0]),
        ]
    };
    let net = Network::find(&tri(0.0), &NetworkOptions::default()).unwrap();
    assert_eq!(net.faces.len(), 1);
    assert!(Network::find(&tri(1e-6), &NetworkOptions::default()).is_err());
    let loose = NetworkOptions { tolerance: 1e-5 };
    assert_eq!(Network::find(&tri(1e-6), &loose).unwrap().faces.len(), 1);
}
