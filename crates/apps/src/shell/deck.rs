//! The CalculiX input deck of a shell model.

use super::mesh::{segment_weights, ShellMesh, Side};
use super::Material;
use std::fmt::Write;

/// A line load along a patch's edge: `force_per_length` newtons per metre in `direction` (a unit
/// vector).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LineLoad {
    /// Index of the patch whose edge is loaded.
    pub patch: usize,
    /// The loaded edge.
    pub side: Side,
    /// Force per length of edge (N/m).
    pub force_per_length: f64,
    /// Unit direction of the force.
    pub direction: [f64; 3],
}

/// A shell model: mesh, thickness, material, clamped edges and loads.
#[derive(Clone, Debug, PartialEq)]
pub struct ShellModel {
    /// The shell mesh of the design's surfaces, in metres.
    pub mesh: ShellMesh,
    /// Wall thickness (m).
    pub thickness: f64,
    /// The shell's material.
    pub material: Material,
    /// Edges with every displacement and rotation fixed.
    pub clamped: Vec<(usize, Side)>,
    /// Loads along patch edges.
    pub line_loads: Vec<LineLoad>,
    /// Uniform pressure (Pa) on the side the normals point away from: positive pushes along the
    /// normals (inflates a closed, outward-oriented surface).
    pub pressure: f64,
}

impl ShellModel {
    /// Nodal forces of the line loads (consistent with the quadratic edges), by node.
    pub fn nodal_forces(&self) -> Vec<(u32, [f64; 3])> {
        let mut f: std::collections::BTreeMap<u32, [f64; 3]> = Default::default();
        for l in &self.line_loads {
            for seg in self.mesh.edge_segments(l.patch, l.side) {
                let w = segment_weights(&self.mesh.nodes, seg);
                for (n, wi) in seg.iter().zip(w) {
                    let e = f.entry(*n).or_default();
                    for (ec, dc) in e.iter_mut().zip(l.direction) {
                        *ec += wi * l.force_per_length * dc;
                    }
                }
            }
        }
        f.into_iter().collect()
    }

    /// The input deck: nodes, `S8R` and `S6` elements, material, shell section, the clamped node set,
    /// one linear static step with the loads, nodal displacements and stresses to the `.frd`
    /// file. Node and element numbers are the mesh's indices plus one.
    pub fn deck(&self) -> String {
        let m = &self.mesh;
        let mut s = String::with_capacity(64 * (m.nodes.len() + m.elements.len()) + 1024);
        s.push_str("*HEADING\npdeshape shell model\n*NODE, NSET=NALL\n");
        for (i, p) in m.nodes.iter().enumerate() {
            let _ = writeln!(s, "{}, {}, {}, {}", i + 1, num(p[0]), num(p[1]), num(p[2]));
        }
        for (kind, want) in [("S8R", 8), ("S6", 6)] {
            let mut first = true;
            for (i, e) in m.elements.iter().enumerate() {
                if e.nodes().len() != want {
                    continue;
                }
                if first {
                    let _ = writeln!(s, "*ELEMENT, TYPE={kind}, ELSET=EALL");
                    first = false;
                }
                let _ = write!(s, "{}", i + 1);
                for n in e.nodes() {
                    let _ = write!(s, ", {}", n + 1);
                }
                s.push('\n');
            }
        }
        let mut fixed: Vec<u32> = self
            .clamped
            .iter()
            .flat_map(|&(p, side)| m.edge_nodes(p, side))
            .collect();
        fixed.sort_unstable();
        fixed.dedup();
        if !fixed.is_empty() {
            s.push_str("*NSET, NSET=FIXED\n");
            write_ids(&mut s, &fixed);
        }
        let mat = &self.material;
        let _ = write!(
            s,
            "*MATERIAL, NAME=WALL\n*ELASTIC\n{}, {}\n*DENSITY\n{}\n\
             *SHELL SECTION, ELSET=EALL, MATERIAL=WALL\n{}\n*STEP\n*STATIC\n",
            num(mat.youngs_modulus),
            num(mat.poisson_ratio),
            num(mat.density),
            num(self.thickness)
        );
        if !fixed.is_empty() {
            s.push_str("*BOUNDARY\nFIXED, 1, 6\n");
        }
        let forces = self.nodal_forces();
        if !forces.is_empty() {
            s.push_str("*CLOAD\n");
            for (n, f) in forces {
                for (c, fc) in f.iter().enumerate() {
                    if *fc != 0.0 {
                        let _ = writeln!(s, "{}, {}, {}", n + 1, c + 1, num(*fc));
                    }
                }
            }
        }
        if self.pressure != 0.0 {
            // CalculiX: a positive shell pressure pushes along the element normal (the side
            // its corners turn counter-clockwise around), which the closed-form tests confirm.
            let _ = writeln!(s, "*DLOAD\nEALL, P, {}", num(self.pressure));
        }
        s.push_str("*NODE FILE\nU\n*EL FILE\nS\n*END STEP\n");
        s
    }
}

/// A number as CalculiX reads it: mantissa with a decimal point, exponent with `E`, at most 20 characters (its field width).
fn num(x: f64) -> String {
    format!("{x:.12E}")
}

/// Node numbers (0-based indices plus one), sixteen to a line as CalculiX reads them.
fn write_ids(s: &mut String, ids: &[u32]) {
    for chunk in ids.chunks(16) {
        let line: Vec<String> = chunk.iter().map(|i| (i + 1).to_string()).collect();
        s.push_str(&line.join(", "));
        s.push_str(",\n");
    }
}
