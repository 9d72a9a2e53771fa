//! The binary STL writer.

use super::blocks::{le3, stream};
use super::check::{check_mesh, check_u32};
use super::format::Format;
use super::info::{parts_of, token, Frame, MeshInfo, GENERATOR};
use crate::mesh::TriMesh;
use crate::Result;
use std::io::Write;

/// `(b − a) × (c − a)` normalised, or zero for a triangle without area.
pub(super) fn facet_normal(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> [f32; 3] {
    let x = crate::mesh::weld::facet_cross(&[a, b, c], [0, 1, 2]);
    let len = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
    if len > 0.0 && len.is_finite() {
        x.map(|c| (c / len) as f32)
    } else {
        [0.0; 3]
    }
}

/// Binary STL. The 80-byte header names the generator, units, up axis and parts (cut at 80
/// bytes; it never begins with `solid`); then the triangle count and per triangle the facet
/// normal computed from the facet, `(b − a) × (c − a)` normalised (zero for a triangle without
/// area), the three corners counter-clockwise seen from it, and a zero attribute word.
pub fn write_stl(mesh: &TriMesh, info: &MeshInfo, w: &mut dyn Write) -> Result<()> {
    check_mesh(mesh)?;
    let frame = Frame::new(info, Format::Stl)?;
    let count = check_u32(mesh.triangles.len() as u128, "triangles", "STL")?;
    let parts = parts_of(mesh);
    let names: Vec<String> = parts
        .iter()
        .enumerate()
        .map(|(k, p)| token(&p.name, k))
        .collect();
    let text = format!(
        "{GENERATOR} binary STL; units {}; up {}; parts {}",
        info.units.as_str(),
        info.up.label(),
        names.join(",")
    );
    let mut header = [b' '; 80];
    let n = text.len().min(80);
    header[..n].copy_from_slice(&text.as_bytes()[..n]);
    stream(w, "STL", |out| {
        out.bytes(&header);
        out.u32_le(count);
        out.records(mesh.triangles.len(), |k| {
            let [a, b, c] = mesh.triangles[k].map(|i| frame.point(mesh.positions[i as usize]));
            // One record: facet normal, three corners, a zero attribute word.
            let mut record = [0u8; 50];
            for (k, v) in [facet_normal(a, b, c), a, b, c].into_iter().enumerate() {
                record[12 * k..12 * k + 12].copy_from_slice(&le3(v.map(f32::to_bits)));
            }
            record
        })
    })
}
