//! The Wavefront OBJ writer.

use super::blocks::{stream, Text, LINES};
use super::check::check_mesh;
use super::format::Format;
use super::info::{one_line, parts_of, token, units_text, Frame, MeshInfo, GENERATOR};
use crate::mesh::TriMesh;
use crate::Result;
use std::io::Write;

/// One OBJ record `prefix x y z`.
fn obj_vec3(out: &mut Text, prefix: &[u8], v: &[f32; 3]) {
    out.bytes(prefix);
    out.f32_text(v[0]);
    out.bytes(b" ");
    out.f32_text(v[1]);
    out.bytes(b" ");
    out.f32_text(v[2]);
    out.bytes(b"\n");
}

/// Wavefront OBJ: comments with the generator, title, units and up axis; every vertex `v` and
/// normal `vn` (and `vt` when the mesh has texture coordinates), numbered alike; then each part
/// as an object `o <name>` with its triangles `f a//a b//b c//c` (or `a/a/a`), counter-clockwise
/// seen from the normals. Numbers are the shortest text that reads back to the identical `f32`.
pub fn write_obj(mesh: &TriMesh, info: &MeshInfo, w: &mut dyn Write) -> Result<()> {
    check_mesh(mesh)?;
    let frame = Frame::new(info, Format::Obj)?;
    let parts = parts_of(mesh);
    stream(w, "OBJ", |out| {
        out.bytes(format!("# {GENERATOR} OBJ\n").as_bytes());
        if let Some(t) = &info.title {
            out.bytes(format!("# title: {}\n", one_line(t)).as_bytes());
        }
        out.bytes(format!("# {}\n", units_text(info)).as_bytes());
        let names: Vec<String> = parts
            .iter()
            .enumerate()
            .map(|(k, p)| token(&p.name, k))
            .collect();
        out.bytes(format!("# parts: {}\n", names.join(" ")).as_bytes());
        let (positions, normals) = (&mesh.positions, &mesh.normals);
        out.blocks(positions.len(), LINES, |range, text| {
            for k in range {
                obj_vec3(text, b"v ", &frame.point(positions[k]));
            }
        })?;
        out.blocks(normals.len(), LINES, |range, text| {
            for k in range {
                obj_vec3(text, b"vn ", &frame.normal(normals[k]));
            }
        })?;
        let with_uv = !mesh.uv.is_empty();
        out.blocks(mesh.uv.len(), LINES, |range, text| {
            for t in &mesh.uv[range] {
                text.bytes(b"vt ");
                text.f32_text(t[0]);
                text.bytes(b" ");
                text.f32_text(t[1]);
                text.bytes(b"\n");
            }
        })?;
        for (part, name) in parts.iter().zip(&names) {
            out.bytes(b"o ");
            out.bytes(name.as_bytes());
            out.bytes(b"\n");
            let ts = &mesh.triangles[part.triangles.clone()];
            out.blocks(ts.len(), LINES, |range, text| {
                for t in &ts[range] {
                    text.bytes(b"f");
                    for &i in t {
                        let i = u64::from(i) + 1;
                        text.bytes(b" ");
                        text.uint_text(i);
                        text.bytes(if with_uv { b"/" } else { b"//" });
                        if with_uv {
                            text.uint_text(i);
                            text.bytes(b"/");
                        }
                        text.uint_text(i);
                    }
                    text.bytes(b"\n");
                }
            })?;
        }
        Ok(())
    })
}
