//! Shell meshes, input decks and the result reader, without the solver (the reader runs on a
//! small `.frd` file CalculiX 2.20 wrote for `small_model()`'s deck).

use pdeshape::shell::*;
use pdeshape::surface::{Partials, Surface, VDomain};
use pdeshape::Vec3;
use std::f64::consts::PI;

use crate::shell_common::Cylinder;

/// A disc `((1 − u) R cos v, (1 − u) R sin v, 0)` closing the cylinder's base: its rim `u = 0`
/// is the cylinder's `u = 0`, its centre the pole `u = 1`.
struct Disc {
    r: f64,
}

impl Surface for Disc {
    fn v_domain(&self) -> VDomain {
        VDomain::Periodic
    }
    fn partials(&self, u: f64, v: f64) -> Partials {
        let (s, c) = v.sin_cos();
        let rho = (1.0 - u) * self.r;
        Partials {
            x: Vec3::new(rho * c, rho * s, 0.0),
            xu: Vec3::new(-self.r * c, -self.r * s, 0.0),
            xv: Vec3::new(-rho * s, rho * c, 0.0),
            xuv: Vec3::new(self.r * s, -self.r * c, 0.0),
            xvv: Vec3::new(-rho * c, -rho * s, 0.0),
            ..Default::default()
        }
    }
}

fn corners(mesh: &ShellMesh, e: &Element) -> Vec<[f64; 3]> {
    e.nodes()[..e.corners()]
        .iter()
        .map(|&n| mesh.nodes[n as usize])
        .collect()
}

/// Every element turns counter-clockwise around the node normals at its corners.
fn assert_oriented(mesh: &ShellMesh) {
    for e in &mesh.elements {
        let c = corners(mesh, e);
        let (a, b, d) = (c[0], c[1], c[c.len() - 1]);
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let w = [d[0] - a[0], d[1] - a[1], d[2] - a[2]];
        let f = [
            u[1] * w[2] - u[2] * w[1],
            u[2] * w[0] - u[0] * w[2],
            u[0] * w[1] - u[1] * w[0],
        ];
        // The mean of the corners' normals (a pole's normal alone may be anything).
        let mut n = [0.0; 3];
        for &k in &e.nodes()[..e.corners()] {
            for (nc, kc) in n.iter_mut().zip(mesh.normals[k as usize]) {
                *nc += kc;
            }
        }
        assert!(f[0] * n[0] + f[1] * n[1] + f[2] * n[2] > 0.0, "{e:?}");
    }
}

#[test]
fn a_cylinder_is_a_grid_of_eight_node_quadrilaterals() {
    let cyl = Cylinder {
        r: 0.05,
        z0: 0.0,
        h: 0.1,
    };
    let mesh = ShellMesh::new(&[&cyl], &["wall"], 4, 8).unwrap();
    // (2·4 + 1) rows of 2·8 nodes but the 4 × 8 cell centres (S8R has none); 4 × 8 quads.
    assert_eq!(mesh.nodes.len(), 9 * 16 - 32);
    assert_eq!(mesh.elements.len(), 32);
    assert!(mesh.elements.iter().all(|e| matches!(e, Element::Quad(_))));
    assert_eq!(mesh.edge_nodes(0, Side::U0).len(), 16);
    assert_eq!(mesh.edge_segments(0, Side::U1).len(), 8);
    // Every node on the surface; the mid-side nodes halfway in the parameters.
    for (p, &(_, u, v)) in mesh.nodes.iter().zip(&mesh.params) {
        let q = cyl.point(u, v);
        assert!((0..3).all(|c| (p[c] - q[c]).abs() < 1e-15));
    }
    assert_oriented(&mesh);
    // The quadratic edges' length of the circle: relative error O(θ⁴), θ = 2π/8.
    let theta = 2.0 * PI / 8.0;
    let len = mesh.edge_length(0, Side::U1);
    assert!(
        (len - 2.0 * PI * 0.05).abs() < theta.powi(4) / 100.0 * len,
        "{len}"
    );
    assert!((len - 2.0 * PI * 0.05).abs() > 0.0);
}

#[test]
fn patches_share_their_common_edge_and_poles_get_triangles() {
    let disc = Disc { r: 0.05 };
    let cyl = Cylinder {
        r: 0.05,
        z0: 0.0,
        h: 0.1,
    };
    let mesh = ShellMesh::new(&[&disc, &cyl], &["base", "wall"], 3, 8).unwrap();
    // Disc: the pole is one node, its ring of cells are triangles; the disc's rim is the
    // cylinder's base row, merged. No cell centres.
    let disc_nodes = 1 + (2 * 3) * 16 - 3 * 8;
    let wall_nodes = (2 * 3 + 1) * 16 - 16 - 3 * 8;
    assert_eq!(mesh.nodes.len(), disc_nodes + wall_nodes);
    let tris = mesh
        .elements
        .iter()
        .filter(|e| matches!(e, Element::Tri(_)))
        .count();
    assert_eq!(tris, 8);
    assert_eq!(mesh.elements.len(), 2 * 3 * 8);
    assert_eq!(mesh.edge_nodes(0, Side::U1).len(), 1);
    assert!(mesh.edge_segments(0, Side::U1).is_empty());
    assert_eq!(mesh.edge_nodes(0, Side::U0), mesh.edge_nodes(1, Side::U0));
    assert_oriented(&mesh);
    // The cup is turned outward: the wall's normals point away from the axis, the base's down.
    for (k, n) in mesh.normals.iter().enumerate() {
        let (patch, u, _) = mesh.params[k];
        let x = mesh.nodes[k];
        if patch == 1 && u > 0.1 {
            assert!(x[0] * n[0] + x[1] * n[1] > 0.0);
        }
        if patch == 0 && u < 0.9 {
            assert!(n[2] < 0.0);
        }
    }
}

#[test]
fn refused_meshes() {
    let cyl = Cylinder {
        r: 0.05,
        z0: 0.0,
        h: 0.1,
    };
    let e = ShellMesh::new(&[&cyl], &["wall"], 0, 8).unwrap_err();
    assert!(e.to_string().contains("at least"), "{e}");
    let e = ShellMesh::new(&[&cyl], &["wall"], 1000, 1000).unwrap_err();
    assert!(e.to_string().contains("above the limit"), "{e}");
}

fn small_model() -> ShellModel {
    let cyl = Cylinder {
        r: 0.05,
        z0: 0.0,
        h: 0.1,
    };
    let mesh = ShellMesh::new(&[&cyl], &["wall"], 2, 4).unwrap();
    ShellModel {
        mesh,
        thickness: 0.5e-3,
        material: Material::POLYSTYRENE,
        clamped: vec![(0, Side::U0)],
        line_loads: vec![LineLoad {
            patch: 0,
            side: Side::U1,
            force_per_length: 15.0,
            direction: [0.0, 0.0, -1.0],
        }],
        pressure: 0.0,
    }
}

#[test]
fn the_deck_lists_nodes_elements_supports_and_loads() {
    let model = small_model();
    let deck = model.deck();
    if let Ok(path) = std::env::var("PDESHAPE_WRITE_DECK") {
        std::fs::write(path, &deck).unwrap();
    }
    let section = |name: &str| -> Vec<&str> {
        let start = deck.find(name).unwrap_or_else(|| panic!("no {name}"));
        deck[start..]
            .lines()
            .skip(1)
            .take_while(|l| !l.starts_with('*'))
            .collect()
    };
    assert_eq!(section("*NODE").len(), model.mesh.nodes.len());
    assert_eq!(section("*ELEMENT, TYPE=S8R").len(), 8);
    // Every number fits CalculiX's 20-character fields and reads back.
    for line in section("*NODE") {
        for f in line.split(',') {
            assert!(f.trim().len() <= 20, "{line}");
            f.trim().parse::<f64>().unwrap();
        }
    }
    let fixed: Vec<u32> = section("*NSET, NSET=FIXED")
        .iter()
        .flat_map(|l| l.split(',').filter_map(|f| f.trim().parse().ok()))
        .collect();
    assert_eq!(fixed.len(), 8);
    assert!(deck.contains("*BOUNDARY\nFIXED, 1, 6\n"));
    // The nodal forces sum to the load times the rim's length, all along −z.
    let forces = section("*CLOAD");
    let total: f64 = forces
        .iter()
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            assert_eq!(f[1].trim(), "3");
            f[2].trim().parse::<f64>().unwrap()
        })
        .sum();
    let want = -15.0 * model.mesh.edge_length(0, Side::U1);
    assert!((total - want).abs() < 1e-12, "{total} {want}");
    assert!(deck.contains("*SHELL SECTION, ELSET=EALL, MATERIAL=WALL\n5.000000000000E-4\n"));
}

#[test]
fn results_read_back_onto_the_shell_nodes() {
    let model = small_model();
    let text = include_str!("../data/shell_cylinder_2x4.frd");
    let frd = read_frd(text).unwrap();
    // Corner nodes expand to three nodes through the thickness, mid-side nodes to two.
    let corners = 3 * 4;
    let mids = model.mesh.nodes.len() - corners;
    assert_eq!(frd.nodes.len(), 3 * corners + 2 * mids);
    assert_eq!(frd.stresses.len(), frd.nodes.len());
    let report = map_to_shell(&model, &frd).unwrap();
    // The rim load's membrane stress q/t = 30 kPa, compressive and axial, on the middle row
    // (a coarse mesh: within 10 %); the peak is the largest nodal value.
    for (k, &(_, u, _)) in model.mesh.params.iter().enumerate() {
        if (u - 0.5).abs() < 1e-12 {
            let szz = report.mid_stress[k][2];
            assert!((szz + 30e3).abs() < 3e3, "{szz}");
        }
    }
    let top = report.max_shear.iter().cloned().fold(f64::MIN, f64::max);
    assert_eq!(report.peak.value, top);
    assert!(report.peak.value >= 15e3 * 0.9);
    // Displacements point down (the load), nothing moves at the clamped base.
    for (k, &(_, u, _)) in model.mesh.params.iter().enumerate() {
        if u == 0.0 {
            assert!(report.displacement[k].iter().all(|x| x.abs() < 1e-12));
        } else {
            assert!(report.displacement[k][2] < 0.0);
        }
    }
}

#[test]
fn malformed_result_files_are_refused() {
    let e = read_frd("    2C\n -1         1 garbage\n").unwrap_err();
    assert!(e.to_string().contains("line 2"), "{e}");
    let e = read_frd("    1C\n").unwrap_err();
    assert!(e.to_string().contains("no nodal stresses"), "{e}");
}
