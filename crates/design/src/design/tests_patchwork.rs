//! `[[patchwork]]`s in the design file: an octahedron's layout on the unit sphere (corners on
//! the sphere, its normals, quarter-circle Hermite edges) is one G1 surface near the sphere,
//! and bad layouts are refused with their place.

use super::*;
use crate::spec::parse_design;
use crate::Vec3;
use std::fmt::Write;

const CORNERS: [[f64; 3]; 6] = [
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [-1.0, 0.0, 0.0],
    [0.0, -1.0, 0.0],
    [0.0, 0.0, 1.0],
    [0.0, 0.0, -1.0],
];

/// The eight faces, counterclockwise seen from outside.
const FACES: [[usize; 3]; 8] = [
    [0, 1, 4],
    [1, 2, 4],
    [2, 3, 4],
    [3, 0, 4],
    [1, 0, 5],
    [2, 1, 5],
    [3, 2, 5],
    [0, 3, 5],
];

/// The octahedron's patchwork, `faces` replaced by `faces` when given.
fn octahedron(faces: Option<&str>) -> String {
    let v = |i: usize| Vec3::from(CORNERS[i]);
    let mut t = String::from("[[patchwork]]\nname = \"ball\"\npoints = [");
    for c in CORNERS {
        let _ = write!(t, "[{:?}, {:?}, {:?}], ", c[0], c[1], c[2]);
    }
    t += "]\nnormals = [";
    for c in CORNERS {
        let _ = write!(t, "[{:?}, {:?}, {:?}], ", c[0], c[1], c[2]);
    }
    t += "]\nedges = [\n";
    let mut pairs = Vec::new();
    for f in FACES {
        for k in 0..3 {
            let (a, b) = (f[k].min(f[(k + 1) % 3]), f[k].max(f[(k + 1) % 3]));
            if !pairs.contains(&(a, b)) {
                pairs.push((a, b));
            }
        }
    }
    for (a, b) in pairs {
        // A quarter circle from a to b: the derivatives are π/2 times the unit tangents.
        let q = std::f64::consts::FRAC_PI_2;
        let (d0, d1) = (v(b) * q, -v(a) * q);
        let mid = (v(a) + v(b)).normalize();
        let _ = writeln!(
            t,
            "  {{ ends = [{a}, {b}], tangents = [[{:?}, {:?}, {:?}], [{:?}, {:?}, {:?}]], \
             normals = [[{:?}, {:?}, {:?}]] }},",
            d0.x, d0.y, d0.z, d1.x, d1.y, d1.z, mid.x, mid.y, mid.z
        );
    }
    t += "]\n";
    match faces {
        Some(f) => t += &format!("faces = {f}\n"),
        None => {
            t += "faces = [";
            for f in FACES {
                let _ = write!(t, "[{}, {}, {}], ", f[0], f[1], f[2]);
            }
            t += "]\n";
        }
    }
    t
}

#[test]
fn an_octahedron_layout_is_one_g1_surface_near_the_sphere() {
    let spec = parse_design(&octahedron(None)).unwrap();
    let d = solve_design(&spec).unwrap();
    let net = &d.networks[0];
    assert_eq!(net.faces.len(), 8);
    assert!(net.joints.iter().all(|j| *j == Joint::Shared));
    let mut g1: f64 = 0.0;
    for e in 0..net.network.edges.len() {
        let along = net.network.faces_of(e);
        assert_eq!(along.len(), 2);
        for j in 1..16 {
            let s = j as f64 / 16.0;
            let mut n = Vec::new();
            for &(f, side) in &along {
                let forward = net.network.faces[f].sides[side][0].forward;
                n.push(net.faces[f].boundary_normal(side, if forward { s } else { 1.0 - s }));
            }
            assert!(
                (n[0].0 - n[1].0).norm() < 1e-12,
                "the faces part along edge {e}"
            );
            g1 = g1.max(n[0].1.cross(&n[1].1).norm());
        }
    }
    assert!(g1 < 1e-9, "G1 {g1}");
    // Near the sphere: eight faces over a sphere stay within 4 % of it (3.1 % measured).
    for s in &d.surfaces {
        for i in 0..=8 {
            for j in 0..=8 {
                let p = s.surface().point(i as f64 / 8.0, j as f64 / 8.0);
                let r = p.norm();
                assert!((r - 1.0).abs() < 0.04, "{}: radius {r}", s.name);
            }
        }
    }
}

#[test]
fn bad_layouts_are_refused_with_their_place() {
    let bad = |faces: &str, place: &str, needle: &str| {
        let spec = parse_design(&octahedron(Some(faces))).unwrap();
        let e = solve_design(&spec).unwrap_err();
        assert_eq!(e.place(), place, "{e}");
        assert!(e.to_string().contains(needle), "{e}");
    };
    bad(
        "[[0, 1, 2]]",
        "patchwork[0].faces[0]",
        "no edge joins corners 2 and 0",
    );
    bad("[[0, 1]]", "patchwork[0].faces[0]", "a face of 2 corners");
    bad(
        "[[0, 1, 4], [0, 1, 4]]",
        "patchwork[0].faces[1]",
        "opposite directions",
    );
    bad(
        "[[0, 1, 9]]",
        "patchwork[0].faces[0]",
        "corner 9 does not exist",
    );
    let mut text = octahedron(None);
    text = text.replacen("ends = [0, 1]", "ends = [0, 0]", 1);
    let e = solve_design(&parse_design(&text).unwrap()).unwrap_err();
    assert!(e.place().starts_with("patchwork[0].edges["), "{e}");
    assert!(e.to_string().contains("joins a corner to itself"), "{e}");
}

/// Two patchworks of one name would give their faces' pieces the same names: the second is
/// refused at its name, after the first's pieces (`ball.0.0` …) were taken.
#[test]
fn a_patchwork_whose_pieces_take_names_already_taken_is_refused() {
    let one = octahedron(None);
    let spec = parse_design(&format!("{one}\n{one}")).unwrap();
    let e = solve_design(&spec).unwrap_err();
    assert_eq!(e.place(), "patchwork[1].name", "{e}");
    assert!(e.to_string().contains("'ball.0.0' is used twice"), "{e}");
    // Renamed, both are built: 8 faces of 3 pieces each.
    let spec = parse_design(&format!("{one}\n{}", one.replace("\"ball\"", "\"ball2\""))).unwrap();
    assert_eq!(solve_design(&spec).unwrap().surfaces.len(), 2 * 8 * 3);
}

/// A fold at a right angle along the x axis: two flat quads in `z = 0` (facing `−z`) and two
/// upright in `y = 0` (facing `+y`), meeting along the ridge `A M B`, which is a crease. The
/// edges leaving the ridge's middle corner `M` into each side (`M D`, `M G`) are shared by the
/// two quads of that side; `end_normals` (when `own`) gives them their side's plane at `M`,
/// whose corner normal is the ridge's average. Edge `M D`'s normal at `M` is `md` when given.
fn fold(own: bool, md: Option<[f64; 3]>) -> String {
    let s = std::f64::consts::FRAC_1_SQRT_2;
    // A, M, B on the ridge; C, D, E on the flat side; F, G, H on the upright side.
    let points = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [0.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [2.0, -1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [2.0, 0.0, 1.0],
    ];
    let ridge = [0.0, s, -s];
    let normals = [
        ridge,
        ridge,
        ridge,
        [0.0, 0.0, -1.0],
        [0.0, 0.0, -1.0],
        [0.0, 0.0, -1.0],
        [0.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let (a, m, b, c, d, e, f, g, h) = (0, 1, 2, 3, 4, 5, 6, 7, 8);
    let mut t = String::from("[[patchwork]]\nname = \"fold\"\npoints = [");
    for p in points {
        let _ = write!(t, "[{:?}, {:?}, {:?}], ", p[0], p[1], p[2]);
    }
    t += "]\nnormals = [";
    for n in normals {
        let _ = write!(t, "[{:?}, {:?}, {:?}], ", n[0], n[1], n[2]);
    }
    t += "]\nedges = [\n";
    let edges: [(usize, usize, &str); 12] = [
        (a, m, "crease = true"),
        (m, b, "crease = true"),
        (m, d, "md"),
        (m, g, "end_normals = [[0.0, 1.0, 0.0], [0.0, 1.0, 0.0]]"),
        (c, d, ""),
        (a, c, ""),
        (d, e, ""),
        (b, e, ""),
        (a, f, ""),
        (f, g, ""),
        (g, h, ""),
        (b, h, ""),
    ];
    for (p, q, extra) in edges {
        let x = [0, 1, 2].map(|k| points[q][k] - points[p][k]);
        let extra = match extra {
            "md" => {
                let n = md.unwrap_or([0.0, 0.0, -1.0]);
                format!(
                    "end_normals = [[{:?}, {:?}, {:?}], [0.0, 0.0, -1.0]]",
                    n[0], n[1], n[2]
                )
            }
            x => x.to_string(),
        };
        let extra = if !own && extra.starts_with("end_normals") {
            String::new()
        } else {
            extra
        };
        let _ = writeln!(
            t,
            "  {{ ends = [{p}, {q}], tangents = [[{:?}, {:?}, {:?}], [{:?}, {:?}, {:?}]]{}{extra} }},",
            x[0],
            x[1],
            x[2],
            x[0],
            x[1],
            x[2],
            if extra.is_empty() { "" } else { ", " }
        );
    }
    let _ = writeln!(
        t,
        "]\nfaces = [[{a}, {m}, {d}, {c}], [{m}, {b}, {e}, {d}], [{m}, {a}, {f}, {g}], [{b}, {m}, {g}, {h}]]"
    );
    t
}

/// The edge of `net` between corners `p` and `q`.
fn edge_between(net: &SolvedNetwork, p: usize, q: usize) -> usize {
    (0..net.network.edges.len())
        .find(|&e| {
            let x = &net.network.edges[e];
            (x.start, x.end) == (p, q) || (x.start, x.end) == (q, p)
        })
        .unwrap()
}

#[test]
fn edges_leaving_a_fold_in_their_sides_planes_keep_g1_and_the_sides_stay_flat() {
    let spec = parse_design(&fold(true, None)).unwrap();
    let d = solve_design(&spec).unwrap();
    let net = &d.networks[0];
    // The edges into each side share their side's plane at the ridge.
    for (p, q) in [(1, 4), (1, 7)] {
        assert_eq!(
            net.joints[edge_between(net, p, q)],
            Joint::Shared,
            "{p}-{q}"
        );
    }
    for (p, q) in [(0, 1), (1, 2)] {
        assert_eq!(
            net.joints[edge_between(net, p, q)],
            Joint::Crease,
            "{p}-{q}"
        );
    }
    // Planar sides: flat boundary data and normals in the plane give the plane (to rounding).
    let mut off: f64 = 0.0;
    for s in &d.surfaces {
        let upright = s.surface().point(0.5, 0.5).z > 1e-3;
        for i in 0..=16 {
            for j in 0..=16 {
                let p = s.surface().point(i as f64 / 16.0, j as f64 / 16.0);
                off = off.max(if upright { p.y.abs() } else { p.z.abs() });
            }
        }
    }
    assert!(off < 1e-12, "a side leaves its plane by {off}");
}

#[test]
fn a_corner_whose_edges_leave_its_normals_plane_or_disagree_is_creased() {
    // Without their own normals the edges into the sides leave the ridge's average plane by
    // 45°: the corner's edges are creases.
    let spec = parse_design(&fold(false, None)).unwrap();
    let net = &solve_design(&spec).unwrap().networks[0];
    for (p, q) in [(1, 4), (1, 7)] {
        assert_eq!(
            net.joints[edge_between(net, p, q)],
            Joint::Crease,
            "{p}-{q}"
        );
    }
    // Edge M D given a plane at M that holds its own tangent but not the ridge: the flat
    // side's corners at M between M D and the ridge (a crease whose tangent leaves that plane)
    // make M D a crease, while M G keeps its side's plane.
    let spec = parse_design(&fold(true, Some([0.6, 0.0, -0.8]))).unwrap();
    let net = &solve_design(&spec).unwrap().networks[0];
    assert_eq!(net.joints[edge_between(net, 1, 4)], Joint::Crease);
    assert_eq!(net.joints[edge_between(net, 1, 7)], Joint::Shared);
    // A normal of length 0 is refused with its place.
    let spec = parse_design(&fold(true, Some([0.0, 0.0, 0.0]))).unwrap();
    let e = solve_design(&spec).unwrap_err();
    assert!(e.place().ends_with("edges[2].end_normals[0]"), "{e}");
}
