//! Writers of an indexed triangle mesh ([`TriMesh`]: trimmed designs) in the mesh formats.
//! The grid writers of [`super::writers`] stay the path for untrimmed designs.

use super::{Format, TriMesh};
use crate::{Error, Result};
use std::io::Write;

/// Writes `m` in a mesh format (obj, stl, ply, glb). Refuses a mesh without triangles, one that
/// fails [`TriMesh::check`], non-finite values, and CSV (which stores grids of samples).
pub fn write_trimesh(format: Format, m: &TriMesh, w: &mut dyn Write) -> Result<()> {
    m.check().map_err(|e| Error::invalid(e).at("mesh"))?;
    if m.triangles.is_empty() {
        return Err(Error::invalid("no triangles to write").at("mesh"));
    }
    if let Some(k) = m
        .positions
        .iter()
        .chain(&m.normals)
        .position(|p| p.iter().any(|x| !x.is_finite()))
    {
        return Err(
            Error::invalid(format!("vertex {} is not finite", k % m.positions.len())).at("mesh"),
        );
    }
    let mut buf = Vec::with_capacity(64 * m.positions.len() + 16 * m.triangles.len());
    match format {
        Format::Obj => obj(m, &mut buf),
        Format::Stl => stl(m, &mut buf),
        Format::Ply => ply(m, &mut buf),
        Format::Glb => glb(m, &mut buf)?,
        Format::Csv => {
            return Err(Error::invalid(
                "csv stores full grids of samples; write a trimmed mesh as obj, stl, ply or glb",
            ))
        }
    }
    w.write_all(&buf)
        .map_err(|e| Error::io(format!("writing {}: {e}", format.extension())))
}

fn f32_text(buf: &mut Vec<u8>, x: f32) {
    let mut b = ryu::Buffer::new();
    buf.extend_from_slice(b.format_finite(x).as_bytes());
}

/// OBJ: one object `o <part>` per part; `v`, `vt` (the `(u, v)` parameters, when present), `vn`,
/// triangles `f a/a/a b/b/b c/c/c` (1-based).
fn obj(m: &TriMesh, buf: &mut Vec<u8>) {
    let uv = m.uv.len() == m.positions.len();
    buf.extend_from_slice(b"# pdeshape OBJ: triangles, trimmed\n");
    for (tag, data) in [(&b"v "[..], &m.positions), (&b"vn "[..], &m.normals)] {
        for p in data {
            buf.extend_from_slice(tag);
            for (k, c) in p.iter().enumerate() {
                if k > 0 {
                    buf.push(b' ');
                }
                f32_text(buf, *c);
            }
            buf.push(b'\n');
        }
    }
    if uv {
        for p in &m.uv {
            buf.extend_from_slice(b"vt ");
            f32_text(buf, p[0]);
            buf.push(b' ');
            f32_text(buf, p[1]);
            buf.push(b'\n');
        }
    }
    let parts: Vec<(String, std::ops::Range<usize>)> = if m.parts.is_empty() {
        vec![("mesh".to_string(), 0..m.triangles.len())]
    } else {
        m.parts
            .iter()
            .map(|p| (p.name.clone(), p.triangles.clone()))
            .collect()
    };
    for (name, range) in parts {
        buf.extend_from_slice(b"o ");
        let name: String = name
            .chars()
            .map(|c| if c.is_whitespace() { '_' } else { c })
            .collect();
        buf.extend_from_slice(if name.is_empty() { "part" } else { &name }.as_bytes());
        buf.push(b'\n');
        for t in &m.triangles[range] {
            buf.push(b'f');
            for i in t {
                let i = (i + 1).to_string();
                buf.push(b' ');
                buf.extend_from_slice(i.as_bytes());
                buf.push(b'/');
                if uv {
                    buf.extend_from_slice(i.as_bytes());
                }
                buf.push(b'/');
                buf.extend_from_slice(i.as_bytes());
            }
            buf.push(b'\n');
        }
    }
}

/// Binary STL; facet normal: the mean of the vertex normals, normalised.
fn stl(m: &TriMesh, buf: &mut Vec<u8>) {
    let mut header = [b' '; 80];
    header[..28].copy_from_slice(b"pdeshape binary STL, trimmed");
    buf.extend_from_slice(&header);
    buf.extend_from_slice(&(m.triangles.len() as u32).to_le_bytes());
    for t in &m.triangles {
        let mut n = [0f32; 3];
        for &i in t {
            for c in 0..3 {
                n[c] += m.normals[i as usize][c];
            }
        }
        let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        for c in n {
            buf.extend_from_slice(&(if l > 0.0 { c / l } else { 0.0 }).to_le_bytes());
        }
        for &i in t {
            for c in m.positions[i as usize] {
                buf.extend_from_slice(&c.to_le_bytes());
            }
        }
        buf.extend_from_slice(&[0, 0]);
    }
}

/// Binary little-endian PLY: `x y z nx ny nz u v` per vertex, triangles as
/// `list uchar uint vertex_indices`.
fn ply(m: &TriMesh, buf: &mut Vec<u8>) {
    let uv = m.uv.len() == m.positions.len();
    buf.extend_from_slice(
        format!(
            "ply\nformat binary_little_endian 1.0\ncomment pdeshape: trimmed\nelement vertex {}\n\
             property float x\nproperty float y\nproperty float z\n\
             property float nx\nproperty float ny\nproperty float nz\n\
             property float u\nproperty float v\nelement face {}\n\
             property list uchar uint vertex_indices\nend_header\n",
            m.positions.len(),
            m.triangles.len()
        )
        .as_bytes(),
    );
    for k in 0..m.positions.len() {
        let t = if uv { m.uv[k] } else { [0.0; 2] };
        for c in m.positions[k].iter().chain(&m.normals[k]).chain(&t) {
            buf.extend_from_slice(&c.to_le_bytes());
        }
    }
    for t in &m.triangles {
        buf.push(3);
        for i in t {
            buf.extend_from_slice(&i.to_le_bytes());
        }
    }
}

/// glTF 2.0 binary: one primitive per part over shared vertex arrays (`POSITION` with min/max,
/// `NORMAL`, `TEXCOORD_0`) and `u32` indices.
fn glb(m: &TriMesh, buf: &mut Vec<u8>) -> Result<()> {
    use serde_json::json;
    let n = m.positions.len();
    let uv: Vec<[f32; 2]> = if m.uv.len() == n {
        m.uv.clone()
    } else {
        vec![[0.0; 2]; n]
    };
    let mut bin: Vec<u8> = Vec::new();
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in &m.positions {
        for c in 0..3 {
            lo[c] = lo[c].min(p[c]);
            hi[c] = hi[c].max(p[c]);
        }
        for c in p {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    for p in &m.normals {
        for c in p {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    for p in &uv {
        for c in p {
            bin.extend_from_slice(&c.to_le_bytes());
        }
    }
    let mut views = vec![
        json!({"buffer": 0, "byteOffset": 0, "byteLength": 12 * n, "byteStride": 12, "target": 34962}),
        json!({"buffer": 0, "byteOffset": 12 * n, "byteLength": 12 * n, "byteStride": 12, "target": 34962}),
        json!({"buffer": 0, "byteOffset": 24 * n, "byteLength": 8 * n, "byteStride": 8, "target": 34962}),
    ];
    let mut accessors = vec![
        json!({"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3", "min": lo, "max": hi}),
        json!({"bufferView": 1, "componentType": 5126, "count": n, "type": "VEC3"}),
        json!({"bufferView": 2, "componentType": 5126, "count": n, "type": "VEC2"}),
    ];
    let ranges: Vec<std::ops::Range<usize>> = if m.parts.is_empty() {
        vec![0..m.triangles.len()]
    } else {
        m.parts
            .iter()
            .filter(|p| !p.triangles.is_empty())
            .map(|p| p.triangles.clone())
            .collect()
    };
    let mut primitives = Vec::new();
    for r in ranges {
        let offset = bin.len();
        for t in &m.triangles[r.clone()] {
            for i in t {
                bin.extend_from_slice(&i.to_le_bytes());
            }
        }
        views.push(json!({"buffer": 0, "byteOffset": offset, "byteLength": bin.len() - offset, "target": 34963}));
        accessors.push(json!({"bufferView": views.len() - 1, "componentType": 5125, "count": 3 * r.len(), "type": "SCALAR"}));
        primitives.push(json!({
            "attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2},
            "indices": accessors.len() - 1,
            "mode": 4,
        }));
    }
    let doc = json!({
        "asset": {"version": "2.0", "generator": "pdeshape"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "pdeshape"}],
        "meshes": [{"name": "pdeshape", "primitives": primitives}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len()}],
    });
    let mut js = serde_json::to_vec(&doc).map_err(|e| Error::io(format!("glTF JSON: {e}")))?;
    while js.len() % 4 != 0 {
        js.push(b' ');
    }
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let total = 12 + 8 + js.len() + 8 + bin.len();
    if total > u32::MAX as usize {
        return Err(Error::invalid("the mesh is too large for GLB (4 GiB)").at("mesh"));
    }
    for x in [
        0x4654_6C67u32,
        2,
        total as u32,
        js.len() as u32,
        0x4E4F_534A,
    ] {
        buf.extend_from_slice(&x.to_le_bytes());
    }
    buf.extend_from_slice(&js);
    for x in [bin.len() as u32, 0x004E_4942] {
        buf.extend_from_slice(&x.to_le_bytes());
    }
    buf.extend_from_slice(&bin);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::surface::{ParametricSurface, VDomain};
    use crate::trim::{trimmed_mesh, TrimCurve, TrimMethod};

    fn trimmed() -> TriMesh {
        let s = ParametricSurface::new("cos(v)", "sin(v)", "u", VDomain::Periodic).unwrap();
        let (mut m, _) = trimmed_mesh(
            &s,
            17,
            32,
            &[TrimCurve::circle([0.5, 1.0], 0.2)],
            TrimMethod::Cdt,
            "tube",
        )
        .unwrap();
        let plain = crate::mesh::tessellate(&s, 3, 8).unwrap();
        m.append(&TriMesh::from_grid(&plain, "other"));
        m
    }

    fn bytes(f: Format, m: &TriMesh) -> Vec<u8> {
        let mut out = Vec::new();
        write_trimesh(f, m, &mut out).unwrap();
        out
    }

    #[test]
    fn every_format_reads_back_with_a_peer_reader() {
        let m = trimmed();
        // OBJ through tobj.
        let obj = bytes(Format::Obj, &m);
        let (models, _) = tobj::load_obj_buf(
            &mut std::io::Cursor::new(&obj),
            &tobj::LoadOptions {
                single_index: true,
                triangulate: false,
                ..Default::default()
            },
            |_| Ok(Default::default()),
        )
        .unwrap();
        assert_eq!(models.len(), 2);
        assert_eq!(models[0].name, "tube");
        let tris: usize = models.iter().map(|x| x.mesh.indices.len() / 3).sum();
        assert_eq!(tris, m.triangles.len());
        // STL through stl_io.
        let stl = bytes(Format::Stl, &m);
        let read = stl_io::read_stl(&mut std::io::Cursor::new(&stl)).unwrap();
        assert_eq!(read.faces.len(), m.triangles.len());
        // PLY through ply-rs.
        let ply = bytes(Format::Ply, &m);
        let p = ply_rs::parser::Parser::<ply_rs::ply::DefaultElement>::new()
            .read_ply(&mut std::io::Cursor::new(&ply))
            .unwrap();
        assert_eq!(p.payload["vertex"].len(), m.positions.len());
        assert_eq!(p.payload["face"].len(), m.triangles.len());
        // GLB through gltf.
        let glb = bytes(Format::Glb, &m);
        let g = gltf::Gltf::from_slice(&glb).unwrap();
        let prims: Vec<_> = g.meshes().next().unwrap().primitives().collect();
        assert_eq!(prims.len(), 2);
        let idx: usize = prims.iter().map(|p| p.indices().unwrap().count()).sum();
        assert_eq!(idx, 3 * m.triangles.len());
    }

    #[test]
    fn broken_meshes_and_csv_are_refused() {
        let mut m = trimmed();
        m.positions[3][1] = f32::NAN;
        let e = write_trimesh(Format::Obj, &m, &mut Vec::new()).unwrap_err();
        assert!(e.to_string().contains("vertex 3 is not finite"), "{e}");
        let e = write_trimesh(Format::Csv, &trimmed(), &mut Vec::new()).unwrap_err();
        assert!(e.to_string().contains("csv"));
    }
}
