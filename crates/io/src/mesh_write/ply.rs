//! The binary little-endian PLY writer.

use super::blocks::{join_bytes, le3, stream};
use super::check::{check_mesh, check_u32};
use super::format::Format;
use super::info::{one_line, parts_of, token, units_text, Frame, MeshInfo, GENERATOR};
use crate::mesh::TriMesh;
use crate::Result;
use std::io::Write;

/// Binary little-endian PLY. Comments name the generator, title, units, up axis and each part
/// with its range of faces (`comment part <name> faces <first> <count>`); element `vertex` holds
/// `x y z nx ny nz` as floats (and `u v` when the mesh has texture coordinates); element `face`
/// holds the triangles as `list uchar uint vertex_indices`, parts one after another.
pub fn write_ply(mesh: &TriMesh, info: &MeshInfo, w: &mut dyn Write) -> Result<()> {
    check_mesh(mesh)?;
    let frame = Frame::new(info, Format::Ply)?;
    let vertices = check_u32(mesh.positions.len() as u128, "vertices", "PLY")?;
    let faces = check_u32(mesh.triangles.len() as u128, "faces", "PLY")?;
    let with_uv = !mesh.uv.is_empty();
    let mut head = String::from("ply\nformat binary_little_endian 1.0\n");
    head += &format!("comment {GENERATOR}\n");
    if let Some(t) = &info.title {
        head += &format!("comment title {}\n", one_line(t));
    }
    head += &format!("comment {}\n", units_text(info));
    for (k, p) in parts_of(mesh).iter().enumerate() {
        head += &format!(
            "comment part {} faces {} {}\n",
            token(&p.name, k),
            p.triangles.start,
            p.triangles.len()
        );
    }
    head += &format!("element vertex {vertices}\n");
    head += "property float x\nproperty float y\nproperty float z\n\
             property float nx\nproperty float ny\nproperty float nz\n";
    if with_uv {
        head += "property float u\nproperty float v\n";
    }
    head += &format!("element face {faces}\nproperty list uchar uint vertex_indices\nend_header\n");
    stream(w, "PLY", |out| {
        out.bytes(head.as_bytes());
        let (positions, normals) = (&mesh.positions, &mesh.normals);
        let vertex = |k: usize| -> [u8; 24] {
            join_bytes(
                le3(frame.point(positions[k]).map(f32::to_bits)),
                le3(frame.normal(normals[k]).map(f32::to_bits)),
            )
        };
        if with_uv {
            out.records(positions.len(), |k| {
                let [u, v] = mesh.uv[k];
                join_bytes::<24, 8, 32>(
                    vertex(k),
                    join_bytes::<4, 4, 8>(u.to_le_bytes(), v.to_le_bytes()),
                )
            })?;
        } else {
            out.records(positions.len(), vertex)?;
        }
        // One record per face: the count 3, then the three indices.
        out.records(mesh.triangles.len(), |k| {
            join_bytes::<1, 12, 13>([3], le3(mesh.triangles[k]))
        })
    })
}
