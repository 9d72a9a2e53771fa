//! Writers read back with independent parsers (tobj, stl_io, ply-rs, gltf, csv).

use pdeshape::mesh::{
    write_csv, write_glb, write_obj, write_ply, write_stl, Format, Grid, GridMesh, Samples,
};
use pdeshape::{Error, TAU};
use std::io::Cursor;
use std::path::Path;

// ------------------------------------------------------------------------------------------
// Test grids, evaluated analytically
// ------------------------------------------------------------------------------------------

fn to_f32(g: &Samples) -> GridMesh {
    let c = |a: &[f64; 3]| a.map(|x| x as f32);
    Grid {
        nu: g.nu,
        nv: g.nv,
        periodic_v: g.periodic_v,
        u: g.u.clone(),
        v: g.v.clone(),
        positions: g.positions.iter().map(c).collect(),
        normals: g.normals.iter().map(c).collect(),
    }
}

fn build(
    nu: usize,
    nv: usize,
    periodic: bool,
    us: Vec<f64>,
    vs: Vec<f64>,
    f: impl Fn(f64, f64) -> ([f64; 3], [f64; 3]),
) -> Samples {
    assert_eq!(us.len(), nu);
    assert_eq!(vs.len(), nv);
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    for &u in &us {
        for &v in &vs {
            let (p, n) = f(u, v);
            positions.push(p);
            normals.push(n);
        }
    }
    Grid {
        nu,
        nv,
        periodic_v: periodic,
        u: us,
        v: vs,
        positions,
        normals,
    }
}

fn periodic_vs(nv: usize) -> Vec<f64> {
    (0..nv).map(|j| TAU * j as f64 / nv as f64).collect()
}

/// Three quarters of a torus (R = 1.7, r = 0.45), periodic in v; normal X_u × X_v (outward).
fn torus(nu: usize, nv: usize) -> Samples {
    let us = (0..nu).map(|i| i as f64 / (nu - 1) as f64).collect();
    build(nu, nv, true, us, periodic_vs(nv), |u, v| {
        let th = 1.5 * std::f64::consts::PI * u;
        let (big_r, r) = (1.7, 0.45);
        let rho = big_r + r * v.cos();
        (
            [rho * th.cos(), rho * th.sin(), r * v.sin()],
            [v.cos() * th.cos(), v.cos() * th.sin(), v.sin()],
        )
    })
}

/// Spherical cap of radius 1.3 from the pole (u = 0, all of row 0 at one point) to the equator,
/// periodic in v; normal X_u × X_v (outward).
fn cap(nu: usize, nv: usize) -> Samples {
    let us = (0..nu).map(|i| i as f64 / (nu - 1) as f64).collect();
    build(nu, nv, true, us, periodic_vs(nv), |u, v| {
        let th = std::f64::consts::FRAC_PI_2 * u;
        let n = [th.sin() * v.cos(), th.sin() * v.sin(), th.cos()];
        (n.map(|c| 1.3 * c), n)
    })
}

/// Part of a cylinder over v ∈ [0.3, 2.1] (not periodic), with non-uniform u; normal
/// X_u × X_v (inward).
fn cylinder(nu: usize, nv: usize) -> Samples {
    let us = (0..nu)
        .map(|i| (i as f64 / (nu - 1) as f64).powi(2))
        .collect();
    let vs = (0..nv)
        .map(|j| 0.3 + 1.8 * j as f64 / (nv - 1) as f64)
        .collect();
    build(nu, nv, false, us, vs, |u, v| {
        (
            [0.8 * v.cos(), 0.8 * v.sin(), 2.0 * u - 0.5],
            [-v.cos(), -v.sin(), 0.0],
        )
    })
}

/// A flat grid with awkward numbers (tiny, huge, subnormal, negative zero) in its positions.
fn awkward() -> Samples {
    let mut g = cylinder(3, 4);
    let odd = [
        1e-8,
        -3.4e38,
        1.0e-40,
        -0.0,
        0.1,
        1.0 / 3.0,
        16777217.0,
        -2.5e-12,
        7.0e30,
        123.456,
        -1e-45,
        0.2,
    ];
    for (k, p) in g.positions.iter_mut().enumerate() {
        p[k % 3] = odd[k];
    }
    g
}

fn cases() -> Vec<(&'static str, Vec<Samples>)> {
    vec![
        ("torus", vec![torus(5, 8)]),
        ("cylinder", vec![cylinder(4, 6)]),
        ("cap+cylinder", vec![cap(4, 7), cylinder(3, 5)]),
        (
            "cylinder+torus+awkward",
            vec![cylinder(3, 3), torus(3, 3), awkward()],
        ),
    ]
}

fn bits3(a: [f32; 3]) -> [u32; 3] {
    a.map(f32::to_bits)
}

/// Expected texture coordinate t of column `j` (`j == nv` only for the periodic seam copy).
fn expected_t(g: &GridMesh, j: usize) -> f32 {
    if g.periodic_v {
        if j == g.nv {
            1.0
        } else {
            (g.v[j] / TAU) as f32
        }
    } else {
        ((g.v[j] - g.v[0]) / (g.v[g.nv - 1] - g.v[0])) as f32
    }
}

/// The quads of a grid as `(i, j)` corners, with the seam column written as `nv` (unwrapped).
fn quad_corners(g: &GridMesh) -> Vec<[(usize, usize); 4]> {
    let cols = if g.periodic_v { g.nv } else { g.nv - 1 };
    let mut out = Vec::new();
    for i in 0..g.nu - 1 {
        for j in 0..cols {
            out.push([(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]);
        }
    }
    // Same connectivity as the grid's own iterator, once wrapped.
    let wrapped: Vec<[u32; 4]> = out
        .iter()
        .map(|q| q.map(|(i, j)| (i * g.nv + j % g.nv) as u32))
        .collect();
    assert_eq!(wrapped, g.quads().collect::<Vec<_>>());
    out
}

// ------------------------------------------------------------------------------------------
// Format::from_path
// ------------------------------------------------------------------------------------------

#[test]
fn format_from_path_by_extension() {
    let cases = [
        ("a.obj", Format::Obj),
        ("dir.x/b.stl", Format::Stl),
        ("c.ply", Format::Ply),
        ("d.glb", Format::Glb),
        ("e.csv", Format::Csv),
        ("A.OBJ", Format::Obj),
        ("B.Stl", Format::Stl),
        ("C.PLY", Format::Ply),
        ("out/D.GlB", Format::Glb),
        ("E.CSV", Format::Csv),
    ];
    for (p, f) in cases {
        assert_eq!(Format::from_path(Path::new(p)).unwrap(), f, "{p}");
        assert_eq!(
            Format::from_path(Path::new(&format!("x.{}", f.extension()))).unwrap(),
            f
        );
    }
    for (p, ext) in [("a.xyz", ".xyz"), ("b.tar.gz", ".gz"), ("c.gltf", ".gltf")] {
        let e = Format::from_path(Path::new(p)).unwrap_err();
        assert!(matches!(e, Error::Invalid { .. }), "{e:?}");
        let msg = e.to_string();
        assert!(msg.contains(&format!("'{ext}'")), "{msg}");
        assert!(msg.contains(".obj, .stl, .ply, .glb or .csv"), "{msg}");
        assert!(!msg.contains('\n'));
    }
    for p in ["noext", "dir.d/noext", ""] {
        let e = Format::from_path(Path::new(p)).unwrap_err();
        assert!(matches!(e, Error::Invalid { .. }), "{e:?}");
        assert!(e.to_string().contains("no extension"), "{e}");
    }
    assert!(Format::Obj.is_mesh() && !Format::Csv.is_mesh());
}

// ------------------------------------------------------------------------------------------
// OBJ via tobj
// ------------------------------------------------------------------------------------------

#[test]
fn obj_reads_back_exactly() {
    for (name, samples) in cases() {
        let meshes: Vec<GridMesh> = samples.iter().map(to_f32).collect();
        let mut bytes = Vec::new();
        write_obj(&meshes, &mut bytes).unwrap();
        let opts = tobj::LoadOptions {
            single_index: false,
            triangulate: false,
            ignore_points: true,
            ignore_lines: true,
        };
        let (models, _) =
            tobj::load_obj_buf(&mut Cursor::new(&bytes), &opts, |_| Ok(Default::default()))
                .unwrap();
        assert_eq!(models.len(), meshes.len(), "{name}");
        for (k, (model, g)) in models.iter().zip(&meshes).enumerate() {
            assert_eq!(model.name, format!("patch{k}"));
            let m = &model.mesh;
            let quads = quad_corners(g);
            assert_eq!(m.face_arities, vec![4; quads.len()], "{name} patch {k}");
            assert_eq!(m.indices.len(), 4 * quads.len());
            // Every grid vertex is used, every texture column (with the seam copy) too.
            assert_eq!(m.positions.len(), 3 * g.nu * g.nv);
            assert_eq!(m.normals.len(), 3 * g.nu * g.nv);
            let tw = g.nv + usize::from(g.periodic_v);
            assert_eq!(m.texcoords.len(), 2 * g.nu * tw);
            // Shared vertices stay shared: grid vertex -> one reader index, and back.
            let mut seen = std::collections::HashMap::new();
            let mut seen_back = std::collections::HashMap::new();
            for (f, q) in quads.iter().enumerate() {
                for (c, &(i, j)) in q.iter().enumerate() {
                    let at = 4 * f + c;
                    let gi = i * g.nv + j % g.nv;
                    let (pi, ni, ti) = (
                        m.indices[at] as usize,
                        m.normal_indices[at] as usize,
                        m.texcoord_indices[at] as usize,
                    );
                    assert_eq!(*seen.entry(gi).or_insert(pi), pi);
                    assert_eq!(*seen_back.entry(pi).or_insert(gi), gi);
                    let p = [0, 1, 2].map(|d| m.positions[3 * pi + d]);
                    let n = [0, 1, 2].map(|d| m.normals[3 * ni + d]);
                    let t = [m.texcoords[2 * ti], m.texcoords[2 * ti + 1]];
                    assert_eq!(bits3(p), bits3(g.positions[gi]), "{name} {k} ({i},{j})");
                    assert_eq!(bits3(n), bits3(g.normals[gi]), "{name} {k} ({i},{j})");
                    assert_eq!(
                        t.map(f32::to_bits),
                        [g.u[i] as f32, expected_t(g, j)].map(f32::to_bits),
                        "{name} {k} ({i},{j})"
                    );
                }
            }
        }
    }
}

#[test]
fn obj_text_is_well_formed() {
    let g = to_f32(&torus(3, 3));
    let mut bytes = Vec::new();
    write_obj(&[g], &mut bytes).unwrap();
    let text = String::from_utf8(bytes).unwrap();
    let count = |p: &str| text.lines().filter(|l| l.starts_with(p)).count();
    assert_eq!(count("v "), 9);
    assert_eq!(count("vt "), 12);
    assert_eq!(count("vn "), 9);
    assert_eq!(count("f "), 6);
    assert_eq!(count("o "), 1);
    // First seam face: corners (0,2),(1,2),(1,0),(0,0); texture column 3 = the seam copy.
    assert!(
        text.lines().any(|l| l == "f 3/3/3 6/7/6 4/8/4 1/4/1"),
        "{text}"
    );
    assert!(text.lines().any(|l| l == "vt 0.0 1.0"));
}

// ------------------------------------------------------------------------------------------
// STL via stl_io
// ------------------------------------------------------------------------------------------

#[test]
fn stl_reads_back_exactly() {
    for (name, samples) in cases() {
        let meshes: Vec<GridMesh> = samples.iter().map(to_f32).collect();
        let mut bytes = Vec::new();
        write_stl(&meshes, &mut bytes).unwrap();
        assert!(!bytes.starts_with(b"solid"));
        let tris: Vec<stl_io::Triangle> = stl_io::create_stl_reader(&mut Cursor::new(&bytes))
            .unwrap()
            .collect::<std::io::Result<_>>()
            .unwrap();
        let header_count = u32::from_le_bytes(bytes[80..84].try_into().unwrap()) as usize;
        assert_eq!(bytes.len(), 84 + 50 * header_count);
        assert_eq!(tris.len(), header_count);
        let mut expected = Vec::new();
        let mut skipped = 0;
        for g in &meshes {
            for t in g.triangles() {
                let p = t.map(|i| g.positions[i as usize]);
                if p[0] == p[1] || p[1] == p[2] || p[0] == p[2] {
                    skipped += 1;
                    continue;
                }
                expected.push((g, t));
            }
        }
        // Only the cap has coincident corners: one triangle per quad touching the pole.
        let cap_skips = if name.starts_with("cap") { 7 } else { 0 };
        assert_eq!(skipped, cap_skips, "{name}");
        assert_eq!(tris.len(), expected.len(), "{name}");
        for (tri, (g, t)) in tris.iter().zip(&expected) {
            for (vertex, &i) in tri.vertices.iter().zip(t) {
                assert_eq!(bits3(vertex.0), bits3(g.positions[i as usize]), "{name}");
            }
            let n = tri.normal.0.map(f64::from);
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            assert!((len - 1.0).abs() < 2e-7, "{name}: |n| = {len}");
            // The normalised mean of the vertex normals, to f32 rounding.
            let mut mean = [0.0f64; 3];
            for &i in t {
                for (m, c) in mean.iter_mut().zip(g.normals[i as usize]) {
                    *m += c as f64;
                }
            }
            let ml = (mean[0] * mean[0] + mean[1] * mean[1] + mean[2] * mean[2]).sqrt();
            for d in 0..3 {
                assert!((n[d] - mean[d] / ml).abs() < 1e-7, "{name}");
            }
            // Counter-clockwise seen from the normal side.
            let p = t.map(|i| g.positions[i as usize].map(f64::from));
            let e1 = [0, 1, 2].map(|d| p[1][d] - p[0][d]);
            let e2 = [0, 1, 2].map(|d| p[2][d] - p[0][d]);
            let x = [
                e1[1] * e2[2] - e1[2] * e2[1],
                e1[2] * e2[0] - e1[0] * e2[2],
                e1[0] * e2[1] - e1[1] * e2[0],
            ];
            if !name.contains("awkward") {
                assert!(x[0] * n[0] + x[1] * n[1] + x[2] * n[2] > 0.0, "{name}");
            }
        }
    }
}

#[test]
fn stl_falls_back_to_geometric_normal() {
    // Zero vertex normals: the facet normal comes from the corners instead.
    let mut g = to_f32(&cylinder(2, 2));
    // (0,0) = (0,0,0), (0,1) = (1,0,0), (1,0) = (0,1,0), (1,1) = (1,1,0): the quad runs
    // clockwise seen from +z, so both triangles face -z.
    g.positions = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
    ];
    g.normals = vec![[0.0, 0.0, 0.0]; 4];
    let mut bytes = Vec::new();
    write_stl(&[g], &mut bytes).unwrap();
    let tris: Vec<stl_io::Triangle> = stl_io::create_stl_reader(&mut Cursor::new(&bytes))
        .unwrap()
        .collect::<std::io::Result<_>>()
        .unwrap();
    assert_eq!(tris.len(), 2);
    for t in tris {
        assert_eq!(t.normal.0, [0.0, 0.0, -1.0]);
    }
}

// ------------------------------------------------------------------------------------------
// PLY via ply-rs
// ------------------------------------------------------------------------------------------

#[test]
fn ply_reads_back_exactly() {
    use ply_rs::ply::Property;
    for (name, samples) in cases() {
        let meshes: Vec<GridMesh> = samples.iter().map(to_f32).collect();
        let mut bytes = Vec::new();
        write_ply(&meshes, &mut bytes).unwrap();
        let parser = ply_rs::parser::Parser::<ply_rs::ply::DefaultElement>::new();
        let ply = parser.read_ply(&mut Cursor::new(&bytes)).unwrap();
        assert_eq!(
            ply.header.encoding,
            ply_rs::ply::Encoding::BinaryLittleEndian
        );
        let verts = &ply.payload["vertex"];
        let faces = &ply.payload["face"];
        let f = |e: &ply_rs::ply::DefaultElement, key: &str| match e[key] {
            Property::Float(x) => x,
            ref other => panic!("{key}: {other:?}"),
        };
        let total: usize = meshes.iter().map(|g| g.nu * g.nv).sum();
        assert_eq!(verts.len(), total, "{name}");
        let mut base = 0;
        let mut face_at = 0;
        for g in &meshes {
            for i in 0..g.nu {
                for j in 0..g.nv {
                    let e = &verts[base + i * g.nv + j];
                    let gi = i * g.nv + j;
                    let p = [f(e, "x"), f(e, "y"), f(e, "z")];
                    let n = [f(e, "nx"), f(e, "ny"), f(e, "nz")];
                    assert_eq!(bits3(p), bits3(g.positions[gi]), "{name}");
                    assert_eq!(bits3(n), bits3(g.normals[gi]), "{name}");
                    assert_eq!(f(e, "u").to_bits(), (g.u[i] as f32).to_bits());
                    assert_eq!(f(e, "v").to_bits(), expected_t(g, j).to_bits());
                }
            }
            for q in quad_corners(g) {
                let want: Vec<u32> = q
                    .iter()
                    .map(|&(i, j)| (base + i * g.nv + j % g.nv) as u32)
                    .collect();
                match &faces[face_at]["vertex_indices"] {
                    Property::ListUInt(ix) => assert_eq!(ix, &want, "{name}"),
                    other => panic!("{other:?}"),
                }
                face_at += 1;
            }
            base += g.nu * g.nv;
        }
        assert_eq!(faces.len(), face_at, "{name}");
    }
}

// ------------------------------------------------------------------------------------------
// GLB via gltf
// ------------------------------------------------------------------------------------------

#[test]
fn glb_reads_back_exactly() {
    for (name, samples) in cases() {
        let meshes: Vec<GridMesh> = samples.iter().map(to_f32).collect();
        let mut bytes = Vec::new();
        write_glb(&meshes, &mut bytes).unwrap();
        check_glb_layout(&bytes, &meshes);
        let (doc, buffers, _) = gltf::import_slice(&bytes).unwrap();
        assert_eq!(doc.meshes().count(), 1);
        assert_eq!(doc.nodes().count(), 1);
        let mesh = doc.meshes().next().unwrap();
        assert_eq!(mesh.primitives().count(), meshes.len(), "{name}");
        for (prim, g) in mesh.primitives().zip(&meshes) {
            assert_eq!(prim.mode(), gltf::mesh::Mode::Triangles);
            let reader = prim.reader(|b| Some(&buffers[b.index()].0[..]));
            let pos: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
            let nrm: Vec<[f32; 3]> = reader.read_normals().unwrap().collect();
            let uv: Vec<[f32; 2]> = reader.read_tex_coords(0).unwrap().into_f32().collect();
            let idx: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
            let w = g.nv + usize::from(g.periodic_v);
            assert_eq!(pos.len(), g.nu * w, "{name}");
            assert_eq!(nrm.len(), pos.len());
            assert_eq!(uv.len(), pos.len());
            for i in 0..g.nu {
                for j in 0..w {
                    let gi = i * g.nv + j % g.nv;
                    let k = i * w + j;
                    assert_eq!(bits3(pos[k]), bits3(g.positions[gi]), "{name}");
                    assert_eq!(bits3(nrm[k]), bits3(g.normals[gi]), "{name}");
                    assert_eq!(
                        uv[k].map(f32::to_bits),
                        [g.u[i] as f32, expected_t(g, j)].map(f32::to_bits)
                    );
                }
            }
            // The grid's triangles, with the seam corners moved to the copied column.
            let mut want = Vec::new();
            for q in quad_corners(g) {
                let q = q.map(|(i, j)| (i * w + j) as u32);
                want.extend([q[0], q[1], q[2], q[0], q[2], q[3]]);
            }
            assert_eq!(idx, want, "{name}");
            assert_eq!(idx.len(), 3 * g.triangles().count());
            // Continuous uvs: no triangle spans more than one column step in t.
            for t in idx.chunks(3) {
                let ts = [0, 1, 2].map(|c| uv[t[c] as usize][1]);
                let spread = ts.iter().cloned().fold(f32::MIN, f32::max)
                    - ts.iter().cloned().fold(f32::MAX, f32::min);
                assert!(spread <= 1.0 / (g.nv - 1) as f32 + 1e-6, "{name}: {spread}");
            }
            let b = prim.bounding_box();
            let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
            for p in &g.positions {
                for d in 0..3 {
                    lo[d] = lo[d].min(p[d]);
                    hi[d] = hi[d].max(p[d]);
                }
            }
            assert_eq!(b.min, lo);
            assert_eq!(b.max, hi);
        }
    }
}

/// Container and JSON checks of the glTF 2.0 binary layout.
fn check_glb_layout(bytes: &[u8], meshes: &[GridMesh]) {
    let u32_at = |o: usize| u32::from_le_bytes(bytes[o..o + 4].try_into().unwrap()) as usize;
    assert_eq!(&bytes[0..4], b"glTF");
    assert_eq!(u32_at(4), 2);
    assert_eq!(u32_at(8), bytes.len());
    let json_len = u32_at(12);
    assert_eq!(&bytes[16..20], b"JSON");
    assert_eq!(json_len % 4, 0);
    let json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
    let bin_at = 20 + json_len;
    let bin_len = u32_at(bin_at);
    assert_eq!(&bytes[bin_at + 4..bin_at + 8], b"BIN\0");
    assert_eq!(bin_len % 4, 0);
    assert_eq!(bin_at + 8 + bin_len, bytes.len());
    assert_eq!(json["asset"]["version"], "2.0");
    let buffer_len = json["buffers"][0]["byteLength"].as_u64().unwrap() as usize;
    assert!(buffer_len <= bin_len && bin_len - buffer_len < 4);
    let views = json["bufferViews"].as_array().unwrap();
    assert_eq!(views.len(), 4 * meshes.len());
    let mut end = 0;
    for (k, v) in views.iter().enumerate() {
        let off = v["byteOffset"].as_u64().unwrap() as usize;
        let len = v["byteLength"].as_u64().unwrap() as usize;
        assert_eq!(off % 4, 0);
        assert_eq!(off, end, "views are packed in order");
        end = off + len;
        let target = v["target"].as_u64().unwrap();
        if k % 4 == 3 {
            assert_eq!(target, 34963);
            assert!(v.get("byteStride").is_none());
        } else {
            assert_eq!(target, 34962);
            let stride = v["byteStride"].as_u64().unwrap();
            assert_eq!(stride, if k % 4 == 2 { 8 } else { 12 });
        }
    }
    assert_eq!(end, buffer_len);
    for (k, a) in json["accessors"].as_array().unwrap().iter().enumerate() {
        let (ct, ty) = match k % 4 {
            0 | 1 => (5126, "VEC3"),
            2 => (5126, "VEC2"),
            _ => (5125, "SCALAR"),
        };
        assert_eq!(a["componentType"], ct);
        assert_eq!(a["type"], ty);
        assert_eq!(a["bufferView"], k);
        assert_eq!(a.get("min").is_some(), k % 4 == 0);
    }
}

// ------------------------------------------------------------------------------------------
// CSV via csv
// ------------------------------------------------------------------------------------------

#[test]
fn csv_reads_back_exactly() {
    for (name, samples) in cases() {
        let mut bytes = Vec::new();
        write_csv(&samples, &mut bytes).unwrap();
        let mut rd = csv::Reader::from_reader(Cursor::new(&bytes));
        let several = samples.len() > 1;
        let header: Vec<String> = rd.headers().unwrap().iter().map(String::from).collect();
        let mut want_header = "u,v,x,y,z,nx,ny,nz".to_string();
        if several {
            want_header.push_str(",patch");
        }
        assert_eq!(header.join(","), want_header, "{name}");
        let rows: Vec<csv::StringRecord> = rd.records().collect::<Result<_, _>>().unwrap();
        let mut at = 0;
        for (k, g) in samples.iter().enumerate() {
            for i in 0..g.nu {
                for j in 0..g.nv {
                    let r = &rows[at];
                    at += 1;
                    let gi = i * g.nv + j;
                    let mut want = vec![g.u[i], g.v[j]];
                    want.extend(g.positions[gi]);
                    want.extend(g.normals[gi]);
                    let got: Vec<f64> = (0..8).map(|c| r[c].parse::<f64>().unwrap()).collect();
                    assert_eq!(
                        got.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                        want.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
                        "{name} row {at}"
                    );
                    if several {
                        assert_eq!(r.len(), 9);
                        assert_eq!(r[8].parse::<usize>().unwrap(), k);
                    } else {
                        assert_eq!(r.len(), 8);
                    }
                }
            }
        }
        assert_eq!(rows.len(), at, "{name}");
    }
}

#[test]
fn csv_keeps_every_digit() {
    let mut g = cylinder(2, 2);
    g.positions[0] = [0.1 + 0.2, 1.0 / 3.0, -1e-300];
    let mut bytes = Vec::new();
    write_csv(&[g], &mut bytes).unwrap();
    let text = String::from_utf8(bytes).unwrap();
    let row = text.lines().nth(1).unwrap();
    assert!(
        row.contains("0.30000000000000004,0.3333333333333333,-1e-300"),
        "{row}"
    );
}

// ------------------------------------------------------------------------------------------
// Refused input and failing destinations
// ------------------------------------------------------------------------------------------

type MeshWriter = fn(&[GridMesh], &mut dyn std::io::Write) -> pdeshape::Result<()>;

fn mesh_writers() -> [(&'static str, MeshWriter); 4] {
    [
        ("obj", write_obj),
        ("stl", write_stl),
        ("ply", write_ply),
        ("glb", write_glb),
    ]
}

#[test]
fn empty_input_is_refused() {
    for (name, wr) in mesh_writers() {
        let mut bytes = Vec::new();
        let e = wr(&[], &mut bytes).unwrap_err();
        assert!(matches!(e, Error::Invalid { .. }), "{name}: {e:?}");
        assert!(bytes.is_empty(), "{name}");
    }
    let mut bytes = Vec::new();
    let e = write_csv(&[], &mut bytes).unwrap_err();
    assert!(matches!(e, Error::Invalid { .. }), "{e:?}");
    assert!(bytes.is_empty());
}

#[test]
fn non_finite_values_are_refused_before_writing() {
    let good = to_f32(&torus(4, 5));
    for (what, bad) in [
        ("position", {
            let mut g = good.clone();
            g.positions[7][1] = f32::NAN;
            g
        }),
        ("normal", {
            let mut g = good.clone();
            g.normals[7][2] = f32::INFINITY;
            g
        }),
    ] {
        for (name, wr) in mesh_writers() {
            let mut bytes = Vec::new();
            let e = wr(&[good.clone(), bad.clone()], &mut bytes).unwrap_err();
            assert!(matches!(e, Error::Invalid { .. }), "{name}: {e:?}");
            assert_eq!(e.place(), "patches[1]", "{name}");
            let msg = e.to_string();
            assert!(msg.contains(what), "{msg}");
            assert!(msg.contains("vertex 7 (i = 1, j = 2)"), "{msg}");
            assert!(bytes.is_empty(), "{name}");
        }
    }
    let mut s = torus(3, 4);
    s.positions[5][0] = f64::NEG_INFINITY;
    let mut bytes = Vec::new();
    let e = write_csv(&[s], &mut bytes).unwrap_err();
    assert_eq!(e.place(), "patches[0]");
    assert!(e.to_string().contains("-inf"), "{e}");
    assert!(bytes.is_empty());
    let mut s = torus(3, 4);
    s.v[2] = f64::NAN;
    let e = write_csv(&[s], &mut Vec::new()).unwrap_err();
    assert!(e.to_string().contains("v[2]"), "{e}");
}

#[test]
fn inconsistent_grids_are_refused() {
    let good = to_f32(&cylinder(3, 4));
    let mut short = good.clone();
    short.normals.pop();
    let mut one_row = good.clone();
    one_row.nu = 1;
    one_row.u.truncate(1);
    one_row.positions.truncate(4);
    one_row.normals.truncate(4);
    let mut bad_u = good.clone();
    bad_u.u.push(2.0);
    for (what, g) in [
        ("normals has 11", short),
        ("no faces", one_row.clone()),
        ("u has 4", bad_u),
    ] {
        for (name, wr) in mesh_writers() {
            let mut bytes = Vec::new();
            let e = wr(std::slice::from_ref(&g), &mut bytes).unwrap_err();
            assert!(matches!(e, Error::Invalid { .. }), "{name}: {e:?}");
            assert!(e.to_string().contains(what), "{name}: {e}");
            assert!(bytes.is_empty());
        }
    }
    // A single row of samples is still a valid CSV.
    let s = Grid {
        nu: 1,
        nv: one_row.nv,
        periodic_v: false,
        u: one_row.u.clone(),
        v: one_row.v.clone(),
        positions: one_row.positions.iter().map(|p| p.map(f64::from)).collect(),
        normals: one_row.normals.iter().map(|p| p.map(f64::from)).collect(),
    };
    let mut bytes = Vec::new();
    write_csv(&[s], &mut bytes).unwrap();
    assert_eq!(String::from_utf8(bytes).unwrap().lines().count(), 5);
}

struct Broken;
impl std::io::Write for Broken {
    fn write(&mut self, _: &[u8]) -> std::io::Result<usize> {
        Err(std::io::Error::other("disk full"))
    }
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

#[test]
fn io_errors_are_reported() {
    let g = to_f32(&torus(3, 4));
    for (name, wr) in mesh_writers() {
        let e = wr(std::slice::from_ref(&g), &mut Broken).unwrap_err();
        assert!(matches!(e, Error::Io { .. }), "{name}: {e:?}");
        assert!(e.to_string().contains("disk full"), "{e}");
    }
    let e = write_csv(&[torus(3, 4)], &mut Broken).unwrap_err();
    assert!(matches!(e, Error::Io { .. }), "{e:?}");
}

// ------------------------------------------------------------------------------------------
// Speed (run with `cargo test --release -p pdeshape --test writers -- --ignored --nocapture`)
// ------------------------------------------------------------------------------------------

#[test]
#[ignore]
fn write_speed_1024() {
    let s = torus(1024, 1024);
    let m = to_f32(&s);
    let time = |name: &str, f: &dyn Fn(&mut Vec<u8>)| {
        let mut bytes = Vec::with_capacity(1 << 28);
        let t0 = std::time::Instant::now();
        f(&mut bytes);
        let dt = t0.elapsed().as_secs_f64();
        println!(
            "{name}: {:.1} MB in {:.3} s ({:.0} MB/s)",
            bytes.len() as f64 / 1e6,
            dt,
            bytes.len() as f64 / 1e6 / dt
        );
    };
    time("obj", &|b| write_obj(std::slice::from_ref(&m), b).unwrap());
    time("stl", &|b| write_stl(std::slice::from_ref(&m), b).unwrap());
    time("ply", &|b| write_ply(std::slice::from_ref(&m), b).unwrap());
    time("glb", &|b| write_glb(std::slice::from_ref(&m), b).unwrap());
    time("csv", &|b| write_csv(std::slice::from_ref(&s), b).unwrap());
}
