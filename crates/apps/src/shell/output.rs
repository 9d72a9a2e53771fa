//! The stress field of an analysis as files: VTU (VTK's XML unstructured grid, for ParaView) and
//! CSV (`patch,u,v,x,y,z,max_shear` per node).

use super::{Element, ShellModel, ShellReport};
use std::fmt::Write;

/// VTK cell types of the quadratic elements (VTK's numbering; node order corners, then mid-side
/// nodes of edges 1–2, 2–3, …: CalculiX's order).
const VTK_QUADRATIC_TRIANGLE: u8 = 22;
const VTK_QUADRATIC_QUAD: u8 = 23;

/// The model and its results as an ASCII VTU file: points in metres, quadratic cells, point data
/// `max_shear` (Pa), `displacement` (m), `patch`, `u`, `v`, cell data `patch`.
pub fn vtu(model: &ShellModel, report: &ShellReport, names: &[&str]) -> String {
    let m = &model.mesh;
    let mut s = String::with_capacity(160 * m.nodes.len() + 64 * m.elements.len() + 2048);
    let _ = write!(
        s,
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" \
         byte_order=\"LittleEndian\" header_type=\"UInt64\">\n<UnstructuredGrid>\n\
         <Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">\n",
        m.nodes.len(),
        m.elements.len()
    );
    let _ = writeln!(
        s,
        "<!-- patches: {} -->",
        names.join(", ").replace("--", "- -")
    );
    s.push_str("<PointData Scalars=\"max_shear\" Vectors=\"displacement\">\n");
    data(
        &mut s,
        "Float64",
        "max_shear",
        1,
        report.max_shear.iter().map(|x| num(*x)),
    );
    data(
        &mut s,
        "Float64",
        "displacement",
        3,
        report
            .displacement
            .iter()
            .flat_map(|d| d.iter().map(|x| num(*x)).collect::<Vec<_>>()),
    );
    data(
        &mut s,
        "Int32",
        "patch",
        1,
        m.params.iter().map(|p| p.0.to_string()),
    );
    data(&mut s, "Float64", "u", 1, m.params.iter().map(|p| num(p.1)));
    data(&mut s, "Float64", "v", 1, m.params.iter().map(|p| num(p.2)));
    s.push_str("</PointData>\n<CellData Scalars=\"patch\">\n");
    data(
        &mut s,
        "Int32",
        "patch",
        1,
        m.element_patch.iter().map(|p| p.to_string()),
    );
    s.push_str("</CellData>\n<Points>\n");
    data(
        &mut s,
        "Float64",
        "Points",
        3,
        m.nodes
            .iter()
            .flat_map(|p| p.iter().map(|x| num(*x)).collect::<Vec<_>>()),
    );
    s.push_str("</Points>\n<Cells>\n");
    data(
        &mut s,
        "Int64",
        "connectivity",
        1,
        m.elements
            .iter()
            .flat_map(|e| e.nodes().iter().map(|n| n.to_string()).collect::<Vec<_>>()),
    );
    let mut offset = 0usize;
    data(
        &mut s,
        "Int64",
        "offsets",
        1,
        m.elements.iter().map(|e| {
            offset += e.nodes().len();
            offset.to_string()
        }),
    );
    data(
        &mut s,
        "UInt8",
        "types",
        1,
        m.elements.iter().map(|e| {
            match e {
                Element::Tri(_) => VTK_QUADRATIC_TRIANGLE,
                Element::Quad(_) => VTK_QUADRATIC_QUAD,
            }
            .to_string()
        }),
    );
    s.push_str("</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    s
}

/// One `DataArray`, values separated by spaces, twelve to a line.
fn data(
    s: &mut String,
    kind: &str,
    name: &str,
    components: usize,
    values: impl Iterator<Item = String>,
) {
    let _ = writeln!(
        s,
        "<DataArray type=\"{kind}\" Name=\"{name}\" NumberOfComponents=\"{components}\" \
         format=\"ascii\">"
    );
    for (i, v) in values.enumerate() {
        if i > 0 {
            s.push(if i % 12 == 0 { '\n' } else { ' ' });
        }
        s.push_str(&v);
    }
    s.push_str("\n</DataArray>\n");
}

/// A number that round-trips (Rust's shortest form); non-finite values (not expected) as 0.
fn num(x: f64) -> String {
    if x.is_finite() {
        format!("{x:e}")
    } else {
        "0".to_string()
    }
}

/// The stress field as CSV: `patch,u,v,x,y,z,max_shear` per node (patch by name, coordinates
/// in metres, stress in pascals).
pub fn csv(model: &ShellModel, report: &ShellReport, names: &[&str]) -> String {
    let m = &model.mesh;
    let mut s = String::with_capacity(96 * m.nodes.len() + 64);
    s.push_str("patch,u,v,x,y,z,max_shear\n");
    for (k, p) in m.nodes.iter().enumerate() {
        let (patch, u, v) = m.params[k];
        let name = names.get(patch).copied().unwrap_or("?");
        let name = if name.contains([',', '"', '\n']) {
            format!("\"{}\"", name.replace('"', "\"\""))
        } else {
            name.to_string()
        };
        let _ = writeln!(
            s,
            "{name},{u},{v},{},{},{},{}",
            p[0], p[1], p[2], report.max_shear[k]
        );
    }
    s
}
