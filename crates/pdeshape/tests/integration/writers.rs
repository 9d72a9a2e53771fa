//! Writers read back with independent parsers (tobj, stl_io, ply-rs, gltf, csv).

use pdeshape::mesh::{
    report, weld, write, write_csv, write_glb, write_obj, write_ply, write_stl, Format, Grid,
    GridMesh, MeshInfo, Samples, TriMesh, Units, Up, WeldOptions,
};
use pdeshape::{ErrorKind, TAU};
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
        assert_eq!(e.kind(), ErrorKind::Invalid, "{e:?}");
        let msg = e.to_string();
        assert!(msg.contains(&format!("'{ext}'")), "{msg}");
        assert!(msg.contains(".obj, .stl, .ply, .glb or .csv"), "{msg}");
        assert!(!msg.contains('\n'));
    }
    for p in ["noext", "dir.d/noext", ""] {
        let e = Format::from_path(Path::new(p)).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::Invalid, "{e:?}");
        assert!(e.to_string().contains("no extension"), "{e}");
    }
    assert!(Format::Obj.is_mesh() && !Format::Csv.is_mesh());
}

// ------------------------------------------------------------------------------------------
// Meshes to write
// ------------------------------------------------------------------------------------------

/// Each case welded (parts named with spaces, which formats without spaces turn into `_`), and
/// each case's grids as they are, with texture coordinates (the awkward numbers only here: a
/// weld tolerance scaled to 1e30 would join them all).
fn meshes() -> Vec<(String, TriMesh)> {
    let mut out = Vec::new();
    for (name, grids) in cases() {
        let g: Vec<GridMesh> = grids.iter().map(to_f32).collect();
        let names: Vec<String> = (0..g.len()).map(|k| format!("{name} part {k}")).collect();
        let refs: Vec<&str> = names.iter().map(|s| s.as_str()).collect();
        if !name.contains("awkward") {
            out.push((name.to_string(), weld(&g, &refs, WeldOptions::default())));
        }
        let mut m = TriMesh::default();
        for (k, gg) in g.iter().enumerate() {
            m.append(&TriMesh::from_grid(gg, &format!("p{k}")));
        }
        out.push((format!("{name} (grid, uv)"), m));
    }
    out
}

fn info() -> MeshInfo {
    MeshInfo {
        title: Some("A test\nwith two lines".to_string()),
        ..MeshInfo::default()
    }
}

fn token(s: &str) -> String {
    s.replace(' ', "_")
}

/// The facet normal computed here, independently of the writer, in f64.
fn facet(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> [f64; 3] {
    let [a, b, c] = [a, b, c].map(|p| p.map(f64::from));
    let e = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let f = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let x = [
        e[1] * f[2] - e[2] * f[1],
        e[2] * f[0] - e[0] * f[2],
        e[0] * f[1] - e[1] * f[0],
    ];
    let n = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
    x.map(|c| c / n)
}

// ------------------------------------------------------------------------------------------
// OBJ via tobj
// ------------------------------------------------------------------------------------------

#[test]
fn obj_reads_back_exactly() {
    for (name, m) in meshes() {
        let mut bytes = Vec::new();
        write_obj(&m, &info(), &mut bytes).unwrap();
        let text = String::from_utf8(bytes.clone()).unwrap();
        assert!(text.starts_with("# pdeshape "), "{name}");
        assert!(text.contains("# title: A test with two lines\n"), "{name}");
        assert!(
            text.contains("# units: mm (1 unit = 0.001 m); up: +Z\n"),
            "{name}"
        );
        let opts = tobj::LoadOptions {
            single_index: false,
            triangulate: false,
            ..Default::default()
        };
        let (models, _) =
            tobj::load_obj_buf(&mut Cursor::new(&bytes), &opts, |_| unreachable!()).unwrap();
        assert_eq!(models.len(), m.parts.len(), "{name}");
        for (model, part) in models.iter().zip(&m.parts) {
            assert_eq!(model.name, token(&part.name), "{name}");
            let t = &model.mesh;
            assert_eq!(t.indices.len(), 3 * part.triangles.len(), "{name}");
            assert_eq!(t.texcoord_indices.is_empty(), m.uv.is_empty(), "{name}");
            for (k, tri) in m.triangles[part.triangles.clone()].iter().enumerate() {
                for (c, &i) in tri.iter().enumerate() {
                    let i = i as usize;
                    let pi = t.indices[3 * k + c] as usize;
                    let ni = t.normal_indices[3 * k + c] as usize;
                    // tobj parses in double precision; the file holds single-precision values.
                    let p = [0, 1, 2].map(|a| t.positions[3 * pi + a] as f32);
                    let n = [0, 1, 2].map(|a| t.normals[3 * ni + a] as f32);
                    assert_eq!(bits3(p), bits3(m.positions[i]), "{name}");
                    assert_eq!(bits3(n), bits3(m.normals[i]), "{name}");
                    if !m.uv.is_empty() {
                        let ti = t.texcoord_indices[3 * k + c] as usize;
                        assert_eq!(t.texcoords[2 * ti] as f32, m.uv[i][0], "{name}");
                    }
                }
            }
        }
    }
}

// ------------------------------------------------------------------------------------------
// STL via stl_io
// ------------------------------------------------------------------------------------------

#[test]
fn stl_reads_back_with_facet_normals() {
    for (name, m) in meshes() {
        let mut bytes = Vec::new();
        write_stl(&m, &info(), &mut bytes).unwrap();
        let header = String::from_utf8_lossy(&bytes[..80]).to_string();
        assert!(!header.starts_with("solid"), "{name}");
        assert!(header.contains("units mm; up +Z; parts"), "{header}");
        assert!(header.contains(&token(&m.parts[0].name)), "{header}");
        let stl = stl_io::read_stl(&mut Cursor::new(&bytes)).unwrap();
        assert_eq!(stl.faces.len(), m.triangles.len(), "{name}");
        for (f, t) in stl.faces.iter().zip(&m.triangles) {
            let [a, b, c] = t.map(|i| m.positions[i as usize]);
            for (k, p) in [a, b, c].iter().enumerate() {
                let v = stl.vertices[f.vertices[k]];
                assert_eq!(bits3([v[0], v[1], v[2]]), bits3(*p), "{name}");
            }
            // The facet's own normal (to f32 rounding), not the smooth vertex normals; zero for a
            // triangle without area (an unwelded pole).
            let want = facet(a, b, c);
            let want = if want.iter().all(|x| x.is_finite()) {
                want
            } else {
                [0.0; 3]
            };
            for (got, want) in [f.normal[0], f.normal[1], f.normal[2]].iter().zip(want) {
                assert!((*got as f64 - want).abs() < 1e-6, "{name}: {f:?}");
            }
        }
    }
}

// ------------------------------------------------------------------------------------------
// PLY via ply-rs
// ------------------------------------------------------------------------------------------

#[test]
fn ply_reads_back_exactly() {
    use ply_rs::ply::Property;
    let float = |p: &Property| match p {
        Property::Float(x) => *x,
        other => panic!("{other:?}"),
    };
    for (name, m) in meshes() {
        let mut bytes = Vec::new();
        write_ply(&m, &info(), &mut bytes).unwrap();
        let parser = ply_rs::parser::Parser::<ply_rs::ply::DefaultElement>::new();
        let ply = parser.read_ply(&mut Cursor::new(&bytes)).unwrap();
        let comments = ply.header.comments.join("\n");
        assert!(comments.contains("units: mm"), "{comments}");
        for p in &m.parts {
            let line = format!(
                "part {} faces {} {}",
                token(&p.name),
                p.triangles.start,
                p.triangles.len()
            );
            assert!(comments.contains(&line), "{name}: {comments}");
        }
        let vs = &ply.payload["vertex"];
        assert_eq!(vs.len(), m.positions.len(), "{name}");
        for (k, v) in vs.iter().enumerate() {
            let p = [float(&v["x"]), float(&v["y"]), float(&v["z"])];
            let n = [float(&v["nx"]), float(&v["ny"]), float(&v["nz"])];
            assert_eq!(bits3(p), bits3(m.positions[k]), "{name}");
            assert_eq!(bits3(n), bits3(m.normals[k]), "{name}");
            assert_eq!(v.contains_key("u"), !m.uv.is_empty(), "{name}");
        }
        let fs = &ply.payload["face"];
        assert_eq!(fs.len(), m.triangles.len(), "{name}");
        for (f, t) in fs.iter().zip(&m.triangles) {
            match &f["vertex_indices"] {
                Property::ListUInt(ix) => assert_eq!(ix[..], t[..], "{name}"),
                other => panic!("{other:?}"),
            }
        }
    }
}

// ------------------------------------------------------------------------------------------
// GLB via gltf
// ------------------------------------------------------------------------------------------

/// A sphere of radius 1.3 (poles at rows 0 and nu − 1), wound inward: closed once welded.
fn sphere(nu: usize, nv: usize) -> Samples {
    let us = (0..nu).map(|i| i as f64 / (nu - 1) as f64).collect();
    build(nu, nv, true, us, periodic_vs(nv), |u, v| {
        let th = std::f64::consts::PI * u;
        let n = [th.sin() * v.cos(), th.sin() * v.sin(), th.cos()];
        (n.map(|c| 1.3 * c), n.map(|c| -c))
    })
}

#[test]
fn glb_is_y_up_in_metres_with_named_meshes_and_a_fitting_material() {
    let closed = weld(&[to_f32(&sphere(9, 12))], &["ball"], WeldOptions::default());
    let mut cases = meshes();
    cases.push(("sphere".to_string(), closed));
    for (name, m) in cases {
        let is_closed = report(&m).boundary_edges == 0;
        for (units, metres) in [(Units::Millimetre, 1e-3), (Units::Inch, 0.0254)] {
            let info = MeshInfo {
                units,
                scale: 2.0,
                ..info()
            };
            let mut bytes = Vec::new();
            write_glb(&m, &info, &mut bytes).unwrap();
            let (doc, buffers, _) = gltf::import_slice(&bytes).unwrap();
            let asset = doc.as_json().asset.clone();
            assert_eq!(
                asset.generator.as_deref(),
                Some(concat!("pdeshape ", env!("CARGO_PKG_VERSION")))
            );
            let json_len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
            let json: serde_json::Value =
                serde_json::from_slice(&bytes[20..20 + json_len]).unwrap();
            let extras = &json["asset"]["extras"];
            assert_eq!(extras["title"], "A test\nwith two lines");
            assert_eq!(extras["design_units"], units.as_str());
            assert_eq!(extras["scale"], 2.0);
            let scene = doc.default_scene().unwrap();
            let root = scene.nodes().next().unwrap();
            assert_eq!(root.name(), Some("A test\nwith two lines"));
            // No node transform: the data themselves are +Y up.
            assert_eq!(
                root.transform().matrix(),
                gltf::scene::Transform::Decomposed {
                    translation: [0.0; 3],
                    rotation: [0.0, 0.0, 0.0, 1.0],
                    scale: [1.0; 3],
                }
                .matrix()
            );
            let children: Vec<_> = root.children().collect();
            assert_eq!(children.len(), m.parts.len(), "{name}");
            for (node, part) in children.iter().zip(&m.parts) {
                assert_eq!(node.name(), Some(part.name.as_str()));
                let mesh = node.mesh().unwrap();
                assert_eq!(mesh.name(), Some(part.name.as_str()));
                let prim = mesh.primitives().next().unwrap();
                assert_eq!(prim.material().double_sided(), !is_closed, "{name}");
                assert_eq!(
                    prim.get(&gltf::Semantic::TexCoords(0)).is_some(),
                    !m.uv.is_empty()
                );
                let reader = prim.reader(|b| Some(&buffers[b.index()]));
                let pos: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
                let nrm: Vec<[f32; 3]> = reader.read_normals().unwrap().collect();
                let idx: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
                assert_eq!(idx.len(), 3 * part.triangles.len());
                for (k, t) in m.triangles[part.triangles.clone()].iter().enumerate() {
                    for c in 0..3 {
                        let [x, y, z] = m.positions[t[c] as usize].map(f64::from);
                        let k2 = 2.0 * metres;
                        let want = [x * k2, z * k2, -y * k2].map(|c| c as f32);
                        let got = pos[idx[3 * k + c] as usize];
                        assert_eq!(bits3(got), bits3(want), "{name}");
                        let [nx, ny, nz] = m.normals[t[c] as usize];
                        assert_eq!(nrm[idx[3 * k + c] as usize], [nx, nz, -ny]);
                    }
                }
            }
        }
    }
}

#[test]
fn scale_and_up_turn_and_scale_the_text_formats() {
    let m = weld(&[to_f32(&torus(5, 8))], &["t"], WeldOptions::default());
    let plain = MeshInfo::default();
    let turned = MeshInfo {
        scale: 3.0,
        up: Up::Y,
        ..MeshInfo::default()
    };
    let mut a = Vec::new();
    let mut b = Vec::new();
    write_ply(&m, &plain, &mut a).unwrap();
    write_ply(&m, &turned, &mut b).unwrap();
    let parser = ply_rs::parser::Parser::<ply_rs::ply::DefaultElement>::new();
    let pa = parser.read_ply(&mut Cursor::new(&a)).unwrap();
    let pb = parser.read_ply(&mut Cursor::new(&b)).unwrap();
    assert!(pb.header.comments.iter().any(|c| c.contains("up: +Y")));
    let f = |p: &ply_rs::ply::Property| match p {
        ply_rs::ply::Property::Float(x) => *x as f64,
        _ => panic!(),
    };
    for (va, vb) in pa.payload["vertex"].iter().zip(&pb.payload["vertex"]) {
        assert_eq!(f(&vb["x"]), (3.0 * f(&va["x"])) as f32 as f64);
        assert_eq!(f(&vb["y"]), (3.0 * f(&va["z"])) as f32 as f64);
        assert_eq!(f(&vb["z"]), (-3.0 * f(&va["y"])) as f32 as f64);
    }
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let info = MeshInfo {
            scale: bad,
            ..MeshInfo::default()
        };
        let mut bytes = Vec::new();
        let e = write_stl(&m, &info, &mut bytes).unwrap_err();
        assert_eq!(e.place(), "scale");
        assert!(bytes.is_empty());
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

type MeshWriter = Box<dyn Fn(&[GridMesh], &mut dyn std::io::Write) -> pdeshape::Result<()>>;

fn mesh_writers() -> Vec<(&'static str, MeshWriter)> {
    [Format::Obj, Format::Stl, Format::Ply, Format::Glb]
        .into_iter()
        .map(|f| {
            let w: MeshWriter = Box::new(move |g, out| write(f, g, out));
            (f.extension(), w)
        })
        .collect()
}

#[test]
fn empty_input_is_refused() {
    for (name, wr) in mesh_writers() {
        let mut bytes = Vec::new();
        let e = wr(&[], &mut bytes).unwrap_err();
        assert_eq!(e.kind(), ErrorKind::Invalid, "{name}: {e:?}");
        assert!(bytes.is_empty(), "{name}");
    }
    let mut bytes = Vec::new();
    let e = write_csv(&[], &mut bytes).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Invalid, "{e:?}");
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
            assert_eq!(e.kind(), ErrorKind::Invalid, "{name}: {e:?}");
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
            assert_eq!(e.kind(), ErrorKind::Invalid, "{name}: {e:?}");
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
        assert_eq!(e.kind(), ErrorKind::Io, "{name}: {e:?}");
        assert!(e.to_string().contains("disk full"), "{e}");
    }
    let e = write_csv(&[torus(3, 4)], &mut Broken).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::Io, "{e:?}");
}
