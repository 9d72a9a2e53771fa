use super::*;
use serde_json::json;
use std::collections::HashMap;

/// A grid of `nu × nv` vertices with awkward numbers (tiny, huge, negative zero, many
/// digits) in its positions and normals that are not all unit.
fn odd_grid(nu: usize, nv: usize, shift: f64) -> GridMesh {
    let odd = [
        1e-8,
        1e-40,
        -0.0,
        0.1,
        1.0 / 3.0,
        1.0000001,
        -2.5e-12,
        2.9999998,
    ];
    let mut positions = Vec::with_capacity(nu * nv);
    let mut normals = Vec::with_capacity(nu * nv);
    for i in 0..nu {
        for j in 0..nv {
            let (u, v) = (i as f64 / nu as f64, j as f64 / nv as f64);
            let x = u + shift;
            let mut p = [x, v * 1.7, (x * 7.0 + v * 3.0).sin()];
            if (i * 31 + j * 17) % 97 == 0 {
                p[(i + j) % 3] = odd[(i * 7 + j) % odd.len()];
            }
            positions.push(p.map(|x| x as f32));
            normals.push([(u * 5.0).cos(), (v * 3.0).sin(), 0.3 + u].map(|x| x as f32));
        }
    }
    Grid {
        nu,
        nv,
        periodic_v: false,
        u: (0..nu).map(|i| i as f64 / (nu - 1) as f64).collect(),
        v: (0..nv).map(|j| 0.25 + j as f64 / (nv - 1) as f64).collect(),
        positions,
        normals,
    }
}

/// Meshes large enough that every array is encoded in many blocks, several batches of
/// them: two grids side by side welded (the second part shares the first's vertices along
/// the seam), the same grids appended with texture coordinates, one part, and a mesh
/// without parts.
fn large_meshes() -> Vec<(&'static str, TriMesh)> {
    let a = odd_grid(420, 260, 0.0);
    let b = odd_grid(300, 260, 1.0 - 1.0 / 420.0);
    let welded = weld(
        &[a.clone(), b.clone()],
        &["left part", ""],
        WeldOptions::default(),
    );
    let mut grids = TriMesh::from_grid(&a, "a");
    grids.append(&TriMesh::from_grid(&b, "b b"));
    let mut single = TriMesh::from_grid(&a, "single");
    single.uv.clear();
    let mut unnamed = single.clone();
    unnamed.parts.clear();
    vec![
        ("welded", welded),
        ("grids with uv", grids),
        ("single", single),
        ("unnamed", unnamed),
    ]
}

fn infos() -> Vec<MeshInfo> {
    vec![
        MeshInfo {
            title: Some("A title".to_string()),
            ..MeshInfo::default()
        },
        MeshInfo {
            scale: 2.5,
            up: Up::Y,
            units: Units::Centimetre,
            ..MeshInfo::default()
        },
    ]
}

/// What follows the header of a text file: everything from the first line starting with
/// `v `.
fn text_body(bytes: &[u8]) -> &[u8] {
    let at = bytes
        .windows(3)
        .position(|w| w == b"\nv ")
        .expect("a vertex line");
    &bytes[at + 1..]
}

/// The OBJ records, one at a time in file order, as a single serial pass writes them.
fn obj_reference(mesh: &TriMesh, info: &MeshInfo) -> Vec<u8> {
    let frame = Frame::new(info, Format::Obj).unwrap();
    let mut t = Text::new(Vec::new());
    let vec3 = |t: &mut Text, prefix: &[u8], v: [f32; 3]| {
        t.bytes(prefix);
        for (c, x) in v.into_iter().enumerate() {
            if c > 0 {
                t.bytes(b" ");
            }
            t.f32_text(x);
        }
        t.bytes(b"\n");
    };
    for &p in &mesh.positions {
        vec3(&mut t, b"v ", frame.point(p));
    }
    for &n in &mesh.normals {
        vec3(&mut t, b"vn ", frame.normal(n));
    }
    for uv in &mesh.uv {
        t.bytes(b"vt ");
        t.f32_text(uv[0]);
        t.bytes(b" ");
        t.f32_text(uv[1]);
        t.bytes(b"\n");
    }
    for (k, part) in parts_of(mesh).iter().enumerate() {
        t.bytes(format!("o {}\n", token(&part.name, k)).as_bytes());
        for tri in &mesh.triangles[part.triangles.clone()] {
            t.bytes(b"f");
            for &i in tri {
                let i = i + 1;
                if mesh.uv.is_empty() {
                    t.bytes(format!(" {i}//{i}").as_bytes());
                } else {
                    t.bytes(format!(" {i}/{i}/{i}").as_bytes());
                }
            }
            t.bytes(b"\n");
        }
    }
    t.buf
}

fn f32s(out: &mut Vec<u8>, v: &[f32]) {
    for x in v {
        out.extend_from_slice(&x.to_le_bytes());
    }
}

/// The STL triangle records.
fn stl_reference(mesh: &TriMesh, info: &MeshInfo) -> Vec<u8> {
    let frame = Frame::new(info, Format::Stl).unwrap();
    let mut out = Vec::new();
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| frame.point(mesh.positions[i as usize]));
        for v in [facet_normal(a, b, c), a, b, c] {
            f32s(&mut out, &v);
        }
        out.extend_from_slice(&[0, 0]);
    }
    out
}

/// The PLY vertex and face records.
fn ply_reference(mesh: &TriMesh, info: &MeshInfo) -> Vec<u8> {
    let frame = Frame::new(info, Format::Ply).unwrap();
    let mut out = Vec::new();
    for (k, (&p, &n)) in mesh.positions.iter().zip(&mesh.normals).enumerate() {
        f32s(&mut out, &frame.point(p));
        f32s(&mut out, &frame.normal(n));
        if !mesh.uv.is_empty() {
            f32s(&mut out, &mesh.uv[k]);
        }
    }
    for t in &mesh.triangles {
        out.push(3);
        for i in t {
            out.extend_from_slice(&i.to_le_bytes());
        }
    }
    out
}

/// The GLB binary chunk (each part's vertices in the order its triangles first use them:
/// positions, normals, texture coordinates, then its triangles in that numbering), and each
/// part's vertex count, triangle count and position bounds.
#[allow(clippy::type_complexity)]
fn glb_reference(
    mesh: &TriMesh,
    info: &MeshInfo,
) -> (Vec<u8>, Vec<(usize, usize, [f32; 3], [f32; 3])>) {
    let frame = Frame::new(info, Format::Glb).unwrap();
    let mut out = Vec::new();
    let mut parts = Vec::new();
    for part in parts_of(mesh) {
        // The vertices the part uses, in increasing order.
        let tris = &mesh.triangles[part.triangles.clone()];
        let mut order: Vec<u32> = tris.iter().flatten().copied().collect();
        order.sort_unstable();
        order.dedup();
        let number: HashMap<u32, u32> = order
            .iter()
            .enumerate()
            .map(|(k, &i)| (i, k as u32))
            .collect();
        let local: Vec<u32> = tris.iter().flatten().map(|i| number[i]).collect();
        if order.is_empty() {
            continue;
        }
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for &i in &order {
            let q = frame.point(mesh.positions[i as usize]);
            f32s(&mut out, &q);
            for c in 0..3 {
                lo[c] = lo[c].min(q[c]);
                hi[c] = hi[c].max(q[c]);
            }
        }
        // A zero bound is written `0`, whichever sign the minimum kept.
        let (lo, hi) = (lo.map(|x| x + 0.0), hi.map(|x| x + 0.0));
        for &i in &order {
            f32s(&mut out, &frame.normal(mesh.normals[i as usize]));
        }
        if !mesh.uv.is_empty() {
            for &i in &order {
                f32s(&mut out, &mesh.uv[i as usize]);
            }
        }
        for k in local {
            out.extend_from_slice(&k.to_le_bytes());
        }
        parts.push((order.len(), part.triangles.len(), lo, hi));
    }
    while out.len() % 4 != 0 {
        out.push(0);
    }
    (out, parts)
}

/// Every edge used by exactly two triangles, counted.
fn closed_reference(mesh: &TriMesh) -> bool {
    let mut uses: HashMap<(u32, u32), usize> = HashMap::new();
    for t in &mesh.triangles {
        for e in 0..3 {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            *uses.entry((a.min(b), a.max(b))).or_default() += 1;
        }
    }
    uses.values().all(|&n| n == 2)
}

fn u32_at(bytes: &[u8], at: usize) -> usize {
    u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize
}

#[test]
fn large_meshes_are_written_as_one_serial_pass_writes_them() {
    for (name, mesh) in large_meshes() {
        for info in infos() {
            let case = format!("{name}, scale {}, up {}", info.scale, info.up.label());
            let mut obj = Vec::new();
            write_obj(&mesh, &info, &mut obj).unwrap();
            assert!(text_body(&obj) == obj_reference(&mesh, &info), "OBJ {case}");

            let mut stl = Vec::new();
            write_stl(&mesh, &info, &mut stl).unwrap();
            assert_eq!(u32_at(&stl, 80), mesh.triangles.len(), "STL {case}");
            assert!(stl[84..] == stl_reference(&mesh, &info), "STL {case}");

            let mut ply = Vec::new();
            write_ply(&mesh, &info, &mut ply).unwrap();
            let end = b"end_header\n";
            let at = ply.windows(end.len()).position(|w| w == end).unwrap() + end.len();
            assert!(ply[at..] == ply_reference(&mesh, &info), "PLY {case}");

            let mut glb = Vec::new();
            write_glb(&mesh, &info, &mut glb).unwrap();
            assert_eq!(u32_at(&glb, 8), glb.len(), "GLB {case}");
            let json_len = u32_at(&glb, 12);
            let doc: serde_json::Value = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
            let bin = &glb[20 + json_len + 8..];
            assert_eq!(u32_at(&glb, 20 + json_len), bin.len(), "GLB {case}");
            let (expected, parts) = glb_reference(&mesh, &info);
            assert!(bin == expected, "GLB binary chunk, {case}");
            assert_eq!(
                doc["materials"][0]["doubleSided"],
                json!(!closed_reference(&mesh)),
                "{case}"
            );
            let meshes = doc["meshes"].as_array().unwrap();
            assert_eq!(meshes.len(), parts.len(), "{case}");
            for (m, (vertices, triangles, lo, hi)) in meshes.iter().zip(parts) {
                let prim = &m["primitives"][0];
                let position =
                    &doc["accessors"][prim["attributes"]["POSITION"].as_u64().unwrap() as usize];
                assert_eq!(position["count"], json!(vertices), "{case}");
                assert_eq!(position["min"], json!(lo), "{case}");
                assert_eq!(position["max"], json!(hi), "{case}");
                let indices = &doc["accessors"][prim["indices"].as_u64().unwrap() as usize];
                assert_eq!(indices["count"], json!(3 * triangles), "{case}");
            }
        }
    }
}

#[test]
fn integer_and_float_text() {
    let mut dest = Vec::new();
    stream(&mut dest, "test", |out| {
        for x in [0, 7, 10, 99, 100, 4_294_967_295, u64::MAX] {
            out.uint_text(x);
            out.bytes(b" ");
        }
        out.f32_text(0.1);
        out.bytes(b" ");
        out.f32_text(-0.0);
        out.bytes(b" ");
        out.f64_text(0.1 + 0.2);
        Ok(())
    })
    .unwrap();
    assert_eq!(
        String::from_utf8(dest).unwrap(),
        "0 7 10 99 100 4294967295 18446744073709551615 0.1 -0.0 0.30000000000000004"
    );
}
