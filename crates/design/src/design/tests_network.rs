//! `[[network]]`s in the design file: planar networks give the plane, faces meet G1 across
//! every inner curve, a network on a sphere converges to it, the file round-trips, and bad
//! networks are refused with their place.

use super::*;
use crate::spec::{parse_design, write_design};
use crate::Vec3;
use std::fmt::Write;

fn example(name: &str) -> String {
    let path = format!("{}/../../examples/{name}", env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// A `[curves.name]` table: the segment from `a` to `b` in the plane `(x, y)`, lifted by the
/// formula `z` of `x` and `y`.
fn lifted(name: &str, a: [f64; 2], b: [f64; 2], z: &str) -> String {
    let x = format!("({:?} + {:?}*v)", a[0], b[0] - a[0]);
    let y = format!("({:?} + {:?}*v)", a[1], b[1] - a[1]);
    let z = z.replace('x', &x).replace('y', &y);
    format!(
        "[curves.{name}]\ntype = \"formula\"\nx = \"{x}\"\ny = \"{y}\"\nz = \"{z}\"\n\
         domain = [0.0, 1.0]\n\n"
    )
}

/// The dome example's layout (a pentagon, a hexagon and three triangles) lifted by `z`.
fn layout(z: &str, order: usize) -> String {
    let lines: [(&str, [f64; 2], [f64; 2]); 8] = [
        ("bottom", [-2.0, -1.0], [2.0, -1.0]),
        ("top", [-2.0, 1.0], [2.0, 1.0]),
        ("left", [-2.0, -1.0], [-2.0, 1.0]),
        ("right", [2.0, -1.0], [2.0, 1.0]),
        ("middle", [0.0, -1.0], [0.0, 1.0]),
        ("cut_a", [-2.0, 0.4], [-1.4, 1.0]),
        ("cut_b", [1.4, 1.0], [2.0, 0.4]),
        ("cut_c", [2.0, -0.4], [1.4, -1.0]),
    ];
    let mut t = format!("[[network]]\nname = \"net\"\norder = {order}\ncurves = [\n");
    for (n, _, _) in &lines {
        let _ = writeln!(t, "  {{ curve = \"{n}\" }},");
    }
    t.push_str("]\n\n");
    for (n, a, b) in &lines {
        t.push_str(&lifted(n, *a, *b, z));
    }
    t
}

fn faces(d: &SolvedDesign) -> Vec<&DesignSurface> {
    d.surfaces
        .iter()
        .filter(|s| matches!(s.kind, SurfaceKind::NSided(_)))
        .collect()
}

#[test]
fn a_planar_network_gives_the_plane() {
    for order in [1, 2] {
        let spec = parse_design(&layout("1 + 0.3*x - 0.2*y", order)).unwrap();
        let d = solve_design(&spec).unwrap();
        let net = &d.networks[0];
        let sides: Vec<usize> = net.network.faces.iter().map(|f| f.sides.len()).collect();
        assert_eq!(sides, [5, 6, 3, 3, 3]);
        assert_eq!(faces(&d).len(), 5 + 6 + 3 * 3);
        // Data in a plane and an operator acting on each coordinate: the plane solves it, so
        // the patches are the plane to rounding: 1e-12 of the network's size (√20), the
        // machine epsilon times the growth of the dense Galerkin solve (condition ~1e3–1e4).
        for s in faces(&d) {
            for i in 0..=8 {
                for j in 0..=8 {
                    let p = s.surface().partials(i as f64 / 8.0, j as f64 / 8.0).x;
                    let off = p.z - (1.0 + 0.3 * p.x - 0.2 * p.y);
                    assert!(
                        off.abs() < 1e-12 * 20f64.sqrt(),
                        "order {order}, {}: {off:e}",
                        s.name
                    );
                }
            }
        }
        let g1 = net.joints.iter().filter(|j| **j == Joint::Shared).count();
        assert_eq!(g1, if order == 2 { 4 } else { 0 });
    }
}

#[test]
fn the_dome_faces_meet_exactly_and_g1_along_every_inner_curve() {
    let spec = parse_design(&example("network_dome.toml")).unwrap();
    let d = solve_design(&spec).unwrap();
    let net = &d.networks[0];
    assert_eq!(net.faces.len(), 5);
    for patch in &net.faces {
        let r = patch.report(64);
        for b in &r.boundary {
            assert!(*b < 1e-13 * r.size, "{r:?}");
        }
    }
    // Along an inner curve both faces take their tangent plane from the same samples of one
    // normal field, through the same interpolant: G1 to rounding.
    let mut shared = 0;
    for (e, joint) in net.joints.iter().enumerate() {
        if *joint != Joint::Shared {
            continue;
        }
        shared += 1;
        let along = net.network.faces_of(e);
        assert_eq!(along.len(), 2);
        for q in 0..32 {
            let f = (q as f64 + 0.5) / 32.0;
            let mut pts = Vec::new();
            for (face, _) in &along {
                let (side, a, b) = net.place_on_face(e, *face).unwrap();
                pts.push(net.faces[*face].boundary_normal(side, a + (b - a) * f));
            }
            let ((pa, na), (pb, nb)) = (pts[0], pts[1]);
            assert!((pa - pb).norm() < 1e-13, "edge {e}");
            let angle = na.cross(&nb).norm().atan2(na.dot(&nb).abs());
            assert!(angle < 1e-10, "edge {e}: {angle:e}");
        }
    }
    assert_eq!(shared, 4, "middle and the three cuts");
}

/// Unit vectors `a, b, c` of a spherical triangle of size `h` about (1, 0, 0), and the arc
/// `[[network]]` of its three sides (tangent to the sphere) and of the arc from `a` to the
/// middle of `bc`, which splits it in two.
fn sphere_network(h: f64) -> String {
    let a = Vec3::new(1.0, 0.0, h).normalize();
    let b = Vec3::new(1.0, -0.87 * h, -0.5 * h).normalize();
    let c = Vec3::new(1.0, 0.87 * h, -0.5 * h).normalize();
    let m = (b + c).normalize();
    let arc = |name: &str, p: Vec3, q: Vec3| {
        let angle = p.cross(&q).norm().atan2(p.dot(&q));
        let w = (q - p * p.dot(&q)).normalize();
        let coord = |k: usize| format!("{:?}*cos(v) + {:?}*sin(v)", p[k], w[k]);
        format!(
            "[curves.{name}]\ntype = \"formula\"\nx = \"{}\"\ny = \"{}\"\nz = \"{}\"\n\
             domain = [0.0, {angle:?}]\n\n",
            coord(0),
            coord(1),
            coord(2)
        )
    };
    let mut t = String::from(
        "[[parametric]]\nname = \"sphere\"\nx = \"cos(1.2*(u - 0.5))*cos(v)\"\n\
         y = \"cos(1.2*(u - 0.5))*sin(v)\"\nz = \"sin(1.2*(u - 0.5))\"\ndomain = [-0.6, 0.6]\n\n\
         [[network]]\nname = \"cap\"\ndegree = 16\ncurves = [\n\
         { curve = \"ab\", tangent_to = \"sphere\" },\n\
         { curve = \"bc\", tangent_to = \"sphere\" },\n\
         { curve = \"ca\", tangent_to = \"sphere\" },\n\
         { curve = \"am\" },\n]\n\n",
    );
    t.push_str(&arc("ab", a, b));
    t.push_str(&arc("bc", b, c));
    t.push_str(&arc("ca", c, a));
    t.push_str(&arc("am", a, m));
    t
}

#[test]
fn a_network_on_a_sphere_converges_to_it() {
    // Positions and tangent planes of the sphere on every curve; the faces' distance to the
    // sphere falls with the size h of the network at the n-sided patches' order (about 4, from
    // the corners' C² interpolant), relative to h at order ≥ 3.
    let mut errors = Vec::new();
    for h in [0.4, 0.2, 0.1] {
        let spec = parse_design(&sphere_network(h)).unwrap();
        let d = solve_design(&spec).unwrap();
        let net = &d.networks[0];
        assert_eq!(net.faces.len(), 2);
        assert!(net.joints.contains(&Joint::Shared));
        let mut worst: f64 = 0.0;
        for s in faces(&d) {
            for i in 0..=12 {
                for j in 0..=12 {
                    let p = s.surface().partials(i as f64 / 12.0, j as f64 / 12.0).x;
                    worst = worst.max((p.norm() - 1.0).abs());
                }
            }
        }
        errors.push(worst);
    }
    for w in errors.windows(2) {
        assert!(w[1] < w[0] / 8.0, "{errors:?}");
    }
    assert!(errors[2] < 1e-5, "{errors:?}");
}

#[test]
fn a_network_round_trips_through_the_file() {
    let spec = parse_design(&example("network_dome.toml")).unwrap();
    let again = parse_design(&write_design(&spec).unwrap()).unwrap();
    assert_eq!(spec, again);
    let spec = parse_design(&sphere_network(0.3)).unwrap();
    assert_eq!(parse_design(&write_design(&spec).unwrap()).unwrap(), spec);
}

fn refused(text: &str) -> crate::Error {
    let spec = parse_design(text).unwrap();
    solve_design(&spec).unwrap_err()
}

#[test]
fn bad_networks_are_refused_with_their_place() {
    // A nine-sided face: a regular nonagon of lines.
    let mut t = String::from("[[network]]\nname = \"n\"\ncurves = [\n");
    for k in 0..9 {
        let _ = writeln!(t, "  {{ curve = \"s{k}\" }},");
    }
    t.push_str("]\n\n");
    for k in 0..9 {
        let p = |k: usize| {
            let a = std::f64::consts::TAU * k as f64 / 9.0;
            [a.cos(), a.sin()]
        };
        t.push_str(&lifted(&format!("s{k}"), p(k), p((k + 1) % 9), "0"));
    }
    let e = refused(&t);
    assert_eq!(e.place(), "network[0]");
    assert!(e.to_string().contains("9 sides"), "{e}");

    // Order 3, a curve that is not on the outline asked to be tangent, an unknown neighbour.
    let base = layout("0", 2);
    let e = refused(&base.replace("order = 2", "order = 3"));
    assert_eq!(e.place(), "network[0].order", "{e}");
    let e = refused(&base.replace(
        "{ curve = \"middle\" }",
        "{ curve = \"middle\", tangent_to = \"net.0\" }",
    ));
    assert_eq!(e.place(), "network[0].curves[4].tangent_to", "{e}");
    assert!(e.to_string().contains("outline"), "{e}");
    let e = refused(&base.replace(
        "{ curve = \"top\" }",
        "{ curve = \"top\", tangent_to = \"nothing\" }",
    ));
    assert_eq!(e.place(), "network[0].curves[1].tangent_to", "{e}");
    assert!(e.to_string().contains("no surface 'nothing'"), "{e}");

    // A periodic curve without a range; curves that enclose nothing.
    let e = refused(
        "[[network]]\nname = \"n\"\ncurves = [{ curve = \"c\" }, { curve = \"d\" }]\n\
         [curves.c]\ntype = \"circle\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0\n\
         [curves.d]\ntype = \"circle\"\ncenter = [0.0, 0.0, 0.0]\nradius = 2.0\n",
    );
    assert_eq!(e.place(), "network[0].curves[0]", "{e}");
    let mut apart = String::from(
        "[[network]]\nname = \"n\"\ncurves = [{ curve = \"p\" }, { curve = \"q\" }]\n",
    );
    apart.push_str(&lifted("p", [0.0, 0.0], [1.0, 0.0], "0"));
    apart.push_str(&lifted("q", [0.0, 1.0], [1.0, 1.0], "0"));
    let e = refused(&apart);
    assert_eq!(e.place(), "network[0]");
    assert!(e.to_string().contains("do not enclose"), "{e}");
}

#[test]
fn the_faces_weld_into_one_mesh_open_only_along_the_outline() {
    let spec = parse_design(&example("network_dome.toml")).unwrap();
    let d = solve_design(&spec).unwrap();
    let (nu, nv) = grid(&spec, Some(12), Some(20)).unwrap();
    assert_eq!((nu, nv), (20, 20), "square grids for n-sided pieces");
    let grids = d.meshes(nu, nv).unwrap();
    let names = d.names();
    let mesh = crate::mesh::weld(&grids, &names, Default::default());
    let mut count = std::collections::HashMap::new();
    for t in &mesh.triangles {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    let mut open = 0;
    for ((a, b), n) in count {
        assert!(n <= 2, "an edge of {n} triangles");
        if n == 1 {
            open += 1;
            // The outline is the rectangle |x| = 2, |y| = 1 (lifted); the midpoint of a
            // boundary edge lies on it (f32 positions).
            let (p, q) = (mesh.positions[a as usize], mesh.positions[b as usize]);
            let (x, y) = (0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1]));
            let off = (x.abs() - 2.0).abs().min((y.abs() - 1.0).abs());
            assert!(off < 1e-5, "an open edge inside the network at ({x}, {y})");
        }
    }
    // 24 half-sides on the outline (every face has 3, 5 or 6 sides, so all are in pieces),
    // each of nu − 1 segments.
    assert_eq!(open, 24 * (nu - 1));
}

#[test]
fn a_t_junction_inside_the_network_keeps_g1_on_both_sides() {
    // A spur from the middle of `middle` to the outline splits the hexagon: the pentagon on
    // the left keeps `middle` as one side, which now borders two faces on the right.
    let text = example("network_dome.toml").replace(
        "  { curve = \"cut_c\" },\n",
        "  { curve = \"cut_c\" },\n  { curve = \"spur\" },\n",
    ) + &lifted("spur", [0.0, 0.0], [2.0, 0.0], "0.6 - 0.12*(x^2 + y^2)");
    let spec = parse_design(&text).unwrap();
    let d = solve_design(&spec).unwrap();
    let net = &d.networks[0];
    let sides: Vec<usize> = net.network.faces.iter().map(|f| f.sides.len()).collect();
    assert_eq!(sides, [5, 5, 3, 3, 5, 3]);
    let merged = net.network.faces[0]
        .sides
        .iter()
        .filter(|s| s.len() == 2)
        .count();
    assert_eq!(
        merged, 1,
        "the pentagon's side along `middle` passes the T-junction"
    );
    let mut checked = 0;
    for (e, joint) in net.joints.iter().enumerate() {
        if *joint != Joint::Shared {
            continue;
        }
        let along = net.network.faces_of(e);
        for q in 0..32 {
            let f = (q as f64 + 0.5) / 32.0;
            let pts: Vec<(Vec3, Vec3)> = along
                .iter()
                .map(|(face, _)| {
                    let (side, a, b) = net.place_on_face(e, *face).unwrap();
                    net.faces[*face].boundary_normal(side, a + (b - a) * f)
                })
                .collect();
            let ((pa, na), (pb, nb)) = (pts[0], pts[1]);
            assert!((pa - pb).norm() < 1e-13, "edge {e}");
            let angle = na.cross(&nb).norm().atan2(na.dot(&nb).abs());
            assert!(angle < 1e-10, "edge {e}: {angle:e}");
        }
        checked += 1;
    }
    assert_eq!(checked, 6, "two pieces of middle, the cuts and the spur");
}
