//! `pdeshape fit`: a mesh in, a design out that `pdeshape surface` reads like any other; closed
//! meshes by the tube mode, open ones by the sheet mode, anything by a template; bad meshes and
//! bad templates get one line and no output file.

use crate::common::*;

/// An ellipsoid of revolution (semi-axes 1, 1, 1.5) as an OBJ text: `rings` latitude rings of
/// `around` vertices, every other ring turned by half a step, and two poles.
fn ellipsoid_obj(rings: usize, around: usize) -> String {
    let mut out = String::from("# ellipsoid\nv 0 0 -1.5\n");
    for i in 1..rings {
        let t = std::f64::consts::PI * i as f64 / rings as f64;
        for j in 0..around {
            let phi = std::f64::consts::TAU * (j as f64 + 0.5 * (i % 2) as f64) / around as f64;
            out += &format!(
                "v {} {} {}\n",
                t.sin() * phi.cos(),
                t.sin() * phi.sin(),
                -1.5 * t.cos()
            );
        }
    }
    out += "v 0 0 1.5\n";
    let top = 1 + (rings - 1) * around + 1;
    let at = |i: usize, j: usize| 2 + (i - 1) * around + j % around;
    for j in 0..around {
        out += &format!("f 1 {} {}\n", at(1, j + 1), at(1, j));
        out += &format!("f {top} {} {}\n", at(rings - 1, j), at(rings - 1, j + 1));
    }
    for i in 1..rings - 1 {
        for j in 0..around {
            out += &format!("f {} {} {}\n", at(i, j), at(i, j + 1), at(i + 1, j + 1));
            out += &format!("f {} {} {}\n", at(i, j), at(i + 1, j + 1), at(i + 1, j));
        }
    }
    out
}

/// The pixels of an RGB or RGBA PNG file as RGB: `(width, height, 3 · width · height bytes)`.
fn read_png(path: &std::path::Path) -> (usize, usize, Vec<u8>) {
    let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).unwrap();
    let channels = info.color_type.samples();
    let rgb = buf[..info.buffer_size()]
        .chunks(channels)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    (info.width as usize, info.height as usize, rgb)
}

#[test]
fn fit_writes_a_design_that_surface_reads() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "egg.obj", &ellipsoid_obj(60, 80));
    let design = dir.path().join("egg.toml");
    let json = dir.path().join("egg.json");
    let pic = dir.path().join("egg.png");
    let out = pdeshape(&[
        "fit",
        s(&mesh),
        "-o",
        s(&design),
        "--tolerance",
        "2e-3",
        "--json",
        s(&json),
        "--picture",
        s(&pic),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout} {}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The verdict first, numbers with four significant digits.
    assert!(
        stdout.contains("egg.obj: Hausdorff ")
            && stdout.contains("% of the diagonal (within the tolerance 0.2000%), RMS "),
        "{stdout}"
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let m = &report["measures"];
    let h = m["hausdorff_relative"].as_f64().unwrap();
    assert!(h > 0.0 && h <= 2e-3, "{report}");
    assert!(m["ratio"].as_f64().unwrap() >= 20.0, "{report}");
    // The TOML's size is the file's as written (its title line included), and its ratio the
    // mesh's bytes over it.
    let written = std::fs::metadata(&design).unwrap().len();
    assert_eq!(m["toml_bytes"].as_u64(), Some(written), "{report}");
    let ratio = m["mesh_bytes"].as_f64().unwrap() / written as f64;
    assert_eq!(m["toml_ratio"].as_f64(), Some(ratio), "{report}");
    // The picture: the bar on the right runs from red at the tolerance (top) to blue at zero
    // (bottom), in the layout the library states; "mesh" and "fit" are written in ink over the
    // two halves of the rest, nowhere else in that band.
    let (w, h, rgb) = read_png(&pic);
    let layout = pdeshape::render::BarLayout::new(w as u32, h as u32);
    let (bx, by, bw, bh) = layout.bar;
    let at = |x: usize, y: usize| {
        let i = 3 * (y * w + x);
        (rgb[i] as i32, rgb[i + 1] as i32, rgb[i + 2] as i32)
    };
    let (r, g, b) = at(bx + bw / 2, by + 1);
    assert!(r > 2 * g && r > 2 * b, "top of the bar {:?}", (r, g, b));
    let (r, g, b) = at(bx + bw / 2, by + bh - 2);
    assert!(b > 2 * r && b > g + 40, "bottom of the bar {:?}", (r, g, b));
    let ink_in = |x0: usize, x1: usize| {
        (0..8 * layout.scale + 4 * layout.scale)
            .flat_map(|y| (x0..x1).map(move |x| (x, y)))
            .filter(|&(x, y)| {
                let (r, g, b) = at(x, y);
                r < 80 && g < 80 && b < 80
            })
            .count()
    };
    let half = layout.panel_x / 2;
    let band = 40 * layout.scale;
    assert!(ink_in(half / 2 - band / 2, half / 2 + band / 2) > 20);
    assert!(ink_in(half + half / 2 - band / 2, half + half / 2 + band / 2) > 20);
    assert_eq!(ink_in(half / 2 + band, half - band / 2), 0);
    // The design is an ordinary design file.
    let obj = dir.path().join("egg_fit.obj");
    let out = pdeshape(&[
        "surface",
        s(&design),
        "-o",
        s(&obj),
        "--nu",
        "16",
        "--nv",
        "32",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = pdeshape(&["check", s(&design)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `obj` (vertices and triangles only) as an OFF text, with a colour after every vertex and a
/// comment, as CGAL's data files are written.
fn off_of(obj: &str) -> String {
    let v: Vec<&str> = obj.lines().filter_map(|l| l.strip_prefix("v ")).collect();
    let f: Vec<Vec<usize>> = obj
        .lines()
        .filter_map(|l| l.strip_prefix("f "))
        .map(|l| {
            l.split(' ')
                .map(|i| i.parse::<usize>().unwrap() - 1)
                .collect()
        })
        .collect();
    let mut out = format!("COFF\n# converted\n{} {} 0\n", v.len(), f.len());
    for p in v {
        out += &format!("{p} 128 128 128 255\n");
    }
    for t in f {
        out += &format!("3 {} {} {}\n", t[0], t[1], t[2]);
    }
    out
}

/// An OFF file is read as the same mesh as the OBJ it was made from: the designs differ only in
/// their titles. A damaged one gets one line naming its line, exit 2 and no file.
#[test]
fn off_meshes_fit_like_the_same_obj() {
    let dir = tempfile::tempdir().unwrap();
    let text = ellipsoid_obj(24, 32);
    let obj = write(dir.path(), "egg.obj", &text);
    let off = write(dir.path(), "egg.off", &off_of(&text));
    let (a, b) = (dir.path().join("a.toml"), dir.path().join("b.toml"));
    // The tube mode, whose design depends on the surface only: the general mode's layout
    // breaks ties between equal collapses by vertex number, and the OBJ parser numbers
    // vertices in the order the faces first use them.
    for (mesh, design) in [(&obj, &a), (&off, &b)] {
        let out = pdeshape(&["fit", s(mesh), "-o", s(design), "-q", "--mode", "tube"]);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let body = |p: &std::path::Path| {
        let t = std::fs::read_to_string(p).unwrap();
        t.split_once('\n').unwrap().1.to_string()
    };
    assert!(
        body(&a) == body(&b),
        "the OFF file's design differs from the OBJ's"
    );
    let broken = off_of(&text).replacen("\n3 0 ", "\n3 0 x", 1);
    bad_mesh(
        "broken.off",
        broken.as_bytes(),
        &[
            "broken.off",
            "not a readable OFF file: line",
            "is not a vertex index",
        ],
    );
}

#[test]
fn quiet_fit_prints_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "egg.obj", &ellipsoid_obj(24, 32));
    let design = dir.path().join("egg.toml");
    let out = pdeshape(&["fit", "--quiet", s(&mesh), "-o", s(&design)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.stdout.is_empty() && out.stderr.is_empty());
    assert!(design.exists());
}

/// Runs `fit` on a bad mesh file; checks the one-line error and that nothing was written.
fn bad_mesh(name: &str, bytes: &[u8], needles: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join(name);
    std::fs::write(&mesh, bytes).unwrap();
    let design = dir.path().join("out.toml");
    let json = dir.path().join("out.json");
    let out = pdeshape(&["fit", s(&mesh), "-o", s(&design), "--json", s(&json)]);
    assert_bad(&out, needles);
    assert_eq!(files(dir.path()), vec![name.to_string()]);
}

#[test]
fn bad_meshes_get_one_line_and_no_output() {
    let good = ellipsoid_obj(12, 16);
    bad_mesh("empty.obj", b"", &["empty.obj", "no triangles"]);
    // A point cloud (a PLY of vertices and no faces, as scanners write them).
    bad_mesh(
        "cloud.ply",
        b"ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
          property float z\nelement face 0\nproperty list uchar int vertex_indices\n\
          end_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n",
        &[
            "cloud.ply",
            "4 vertices and no triangles",
            "point cloud",
            "reconstruct",
        ],
    );
    bad_mesh(
        "nan.obj",
        good.replacen("v 0 0 -1.5", "v nan 0 -1.5", 1).as_bytes(),
        &["nan.obj", "vertex 1 is not finite"],
    );
    // The file's second vertex, which the faces first use third: named by its line and its
    // number in the file, not the parser's.
    let mut k = 0;
    let late: String = good
        .lines()
        .map(|l| {
            k += usize::from(l.starts_with("v "));
            if l.starts_with("v ") && k == 2 {
                "v 0 nan 0\n".to_string()
            } else {
                format!("{l}\n")
            }
        })
        .collect();
    bad_mesh(
        "late.obj",
        late.as_bytes(),
        &["late.obj", "line 3: vertex 2 is not finite: (0, NaN, 0)"],
    );
    // Coordinates whose squares overflow, and a mesh too small for its areas.
    let scaled = |k: f64| {
        let mut out = String::new();
        for l in good.lines() {
            match l.strip_prefix("v ") {
                Some(rest) => {
                    let c: Vec<f64> = rest.split(' ').map(|x| x.parse().unwrap()).collect();
                    out += &format!("v {:e} {:e} {:e}\n", c[0] * k, c[1] * k, c[2] * k);
                }
                None => out += &format!("{l}\n"),
            }
        }
        out
    };
    bad_mesh(
        "huge.obj",
        scaled(1e200).as_bytes(),
        &["huge.obj", "vertex 1 lies at", "scale the mesh down"],
    );
    bad_mesh(
        "tiny.obj",
        scaled(1e-200).as_bytes(),
        &["tiny.obj", "spans only", "scale the mesh up"],
    );
    // A binary STL whose count runs past its end is truncated, whatever the count says.
    let mut stl = vec![0u8; 80];
    stl.extend_from_slice(&u32::MAX.to_le_bytes());
    stl.extend_from_slice(&[0; 150]);
    bad_mesh(
        "short.stl",
        &stl,
        &["short.stl", "truncated", "announces 4294967295 triangles"],
    );
    // A volume mesh's cells (a 3 × 3 × 3 grid of cubes, each writing its six faces as quads):
    // not a surface, refused with a point instead of repaired away.
    let mut cells = String::new();
    let v = |i: u32, j: u32, k: u32| 1 + i + 4 * (j + 4 * k);
    for k in 0..4 {
        for j in 0..4 {
            for i in 0..4 {
                cells += &format!("v {i} {j} {k}\n");
            }
        }
    }
    for k in 0..3 {
        for j in 0..3 {
            for i in 0..3 {
                let c = |a: u32, b: u32, d: u32| v(i + a, j + b, k + d);
                let quads = [
                    [c(0, 0, 0), c(0, 1, 0), c(1, 1, 0), c(1, 0, 0)],
                    [c(0, 0, 1), c(1, 0, 1), c(1, 1, 1), c(0, 1, 1)],
                    [c(0, 0, 0), c(1, 0, 0), c(1, 0, 1), c(0, 0, 1)],
                    [c(0, 1, 0), c(0, 1, 1), c(1, 1, 1), c(1, 1, 0)],
                    [c(0, 0, 0), c(0, 0, 1), c(0, 1, 1), c(0, 1, 0)],
                    [c(1, 0, 0), c(1, 1, 0), c(1, 1, 1), c(1, 0, 1)],
                ];
                for q in quads {
                    // Each cell's own diagonal: a face between two cells is not written twice
                    // alike.
                    let q = if (i + j + k) % 2 == 1 {
                        [q[1], q[2], q[3], q[0]]
                    } else {
                        q
                    };
                    cells += &format!(
                        "f {} {} {}\nf {} {} {}\n",
                        q[0], q[1], q[2], q[0], q[2], q[3]
                    );
                }
            }
        }
    }
    bad_mesh(
        "cells.obj",
        cells.as_bytes(),
        &[
            "cells.obj",
            "not one surface",
            "export the object's outer surface alone",
        ],
    );
    // Two components: the ellipsoid twice, the second shifted.
    let n = 2 + 11 * 16;
    let mut two = good.clone();
    for l in good.lines() {
        if let Some(rest) = l.strip_prefix("v ") {
            let c: Vec<f64> = rest.split(' ').map(|x| x.parse().unwrap()).collect();
            two += &format!("v {} {} {}\n", c[0] + 5.0, c[1], c[2]);
        }
    }
    for l in good.lines() {
        if let Some(rest) = l.strip_prefix("f ") {
            let c: Vec<usize> = rest.split(' ').map(|x| x.parse().unwrap()).collect();
            two += &format!("f {} {} {}\n", c[0] + n, c[1] + n, c[2] + n);
        }
    }
    // Neither a tube nor a sheet: each component is fitted by the general mode, one
    // patchwork each, and the whole measured within the default tolerance.
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "two.obj", &two);
    let design = dir.path().join("two.toml");
    let json = dir.path().join("two.json");
    let out = pdeshape(&["fit", s(&mesh), "-o", s(&design), "--json", s(&json)]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("2 separate components") && err.contains("general mode"),
        "{err}"
    );
    let text = std::fs::read_to_string(&design).unwrap();
    assert_eq!(text.matches("[[patchwork]]").count(), 2, "{text}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let h = report["measures"]["hausdorff_relative"].as_f64().unwrap();
    assert!(h <= 0.02, "Hausdorff {h}");
    // Non-manifold: a fin on an edge of the first ring is dropped with a note, and the rest
    // fitted.
    let fin = format!("{good}v 3 3 3\nf 2 3 {}\n", n + 1);
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "fin.obj", &fin);
    let out = pdeshape(&["fit", s(&mesh), "-o", s(&dir.path().join("fin.toml"))]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("fin.obj: repaired: 1 edge made manifold by dropping 1 triangle"),
        "{stderr}"
    );
    // Binary STL announcing ten million triangles.
    let mut huge = vec![0u8; 84];
    huge[80..84].copy_from_slice(&10_000_000u32.to_le_bytes());
    bad_mesh("huge.stl", &huge, &["huge.stl", "10000000 triangles"]);
    // Truncated binary STL: two triangles announced, one and a half present.
    let mut cut = vec![0u8; 84 + 75];
    cut[80..84].copy_from_slice(&2u32.to_le_bytes());
    bad_mesh("cut.stl", &cut, &["cut.stl", "truncated"]);
    bad_mesh(
        "cut.ply",
        b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n",
        &["cut.ply", "PLY"],
    );
    // Bad flags.
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "m.obj", &good);
    let design = dir.path().join("out.toml");
    let out = pdeshape(&["fit", s(&mesh), "-o", s(&design), "--tolerance", "0"]);
    assert_bad(&out, &["--tolerance 0"]);
    let out = pdeshape(&["fit", s(&mesh), "-o", s(&design), "--template", "t.toml"]);
    assert_bad(&out, &["--template t.toml", "cannot read"]);
    let out = pdeshape(&[
        "fit",
        s(&mesh),
        "-o",
        s(&design),
        "--template",
        "t.toml",
        "--sections",
        "3",
    ]);
    assert_bad(&out, &["--template", "--sections"]);
    let out = pdeshape(&["fit", s(&mesh), "-o", s(&dir.path().join("x.obj"))]);
    assert_bad(&out, &["-o", ".toml"]);
    assert_eq!(files(dir.path()), vec!["m.obj".to_string()]);
}

/// A sheet over `[−1, 1] × [−1.5, 1.5]` with heights `0.2 sin 2x cos y`, as an OBJ: rows of
/// `across` vertices (every other row shifted by half a step, its ends kept on the outline),
/// triangles alternating in direction.
fn sheet_obj(rows: usize, across: usize) -> String {
    let mut out = String::from("# sheet\n");
    for i in 0..=rows {
        let y = -1.5 + 3.0 * i as f64 / rows as f64;
        for j in 0..across {
            let shift = if i % 2 == 1 && j > 0 && j + 1 < across {
                0.5
            } else {
                0.0
            };
            let x = -1.0 + 2.0 * (j as f64 + shift) / (across - 1) as f64;
            out += &format!("v {x} {y} {}\n", 0.2 * (2.0 * x).sin() * y.cos());
        }
    }
    let at = |i: usize, j: usize| 1 + i * across + j;
    for i in 0..rows {
        for j in 0..across - 1 {
            out += &format!("f {} {} {}\n", at(i, j), at(i, j + 1), at(i + 1, j + 1));
            out += &format!("f {} {} {}\n", at(i, j), at(i + 1, j + 1), at(i + 1, j));
        }
    }
    out
}

#[test]
fn open_meshes_are_fitted_as_sheets() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "sheet.obj", &sheet_obj(60, 41));
    let design = dir.path().join("sheet.toml");
    let json = dir.path().join("sheet.json");
    let out = pdeshape(&[
        "fit",
        s(&mesh),
        "-o",
        s(&design),
        "--tolerance",
        "2e-3",
        "--json",
        s(&json),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout} {}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("sheet mode"), "{stdout}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(report["mode"], "sheet", "{report}");
    let h = report["measures"]["hausdorff_relative"].as_f64().unwrap();
    assert!(h > 0.0 && h <= 2e-3, "{report}");
    // The fitted sheet's patches meet within about 1.1° (0.019 rad): above the default seam
    // tolerance of one degree, within 0.05 rad.
    let out = pdeshape(&["check", "--g1-tolerance", "0.05", s(&design)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The ellipsoid by a template of one part along z, closed by poles at both ends; a bad
/// template is reported at its line and column, before the mesh is read, and nothing is
/// written.
#[test]
fn templates_fit_and_bad_ones_are_located() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "egg.obj", &ellipsoid_obj(60, 80));
    let template = write(
        dir.path(),
        "egg_template.toml",
        "# the egg from end to end\n[[parts]]\nname = \"egg\"\naxis = [0, 0, 1]\n\
         positions = [-1.2, 1.2]\nstart = \"pole\"\nend = \"pole\"\n",
    );
    let design = dir.path().join("egg.toml");
    let json = dir.path().join("egg.json");
    let out = pdeshape(&[
        "fit",
        s(&mesh),
        "-o",
        s(&design),
        "--template",
        s(&template),
        "--json",
        s(&json),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(report["mode"], "template", "{report}");
    let h = report["measures"]["hausdorff_relative"].as_f64().unwrap();
    assert!(h > 0.0 && h <= 2e-3, "{report}");
    let text = std::fs::read_to_string(&design).unwrap();
    assert!(text.contains("[curves.egg_p00]"), "{text}");

    // Sixteen joined parts of 4096 sections: one chain of 65 000 sections, whose node choice
    // would run for hours; priced and refused before the first section is cut.
    let many: String = (0..16)
        .map(|i| {
            format!(
                "[[parts]]\nname = \"p{i}\"\naxis = [0, 0, 1]\npositions = [{}, {}]\n\
                 sections = 4096\n",
                -1.2 + 0.15 * i as f64,
                -1.2 + 0.15 * (i + 1) as f64
            )
        })
        .collect();
    let cases: [(&str, &[&str]); 5] = [
        (
            &many,
            &[
                ":5:",
                "parts[0].sections",
                "sections over",
                "s of work",
                "fewer sections",
            ],
        ),
        (
            "[[parts]]\nname = \"egg\"\naxis = [0, 0, 1]\npositions = [1.0, -1.0]\n",
            &[":4:", "parts[0].positions[1]", "positions must increase"],
        ),
        (
            "[[parts]]\nname = \"egg\"\nplanes = [{ point = [0, 0, 0] }, \
             { point = [0, 0, 1], normal = [0, 0, 1] }]\n",
            &[":3:", "parts[0].planes[0].normal", "missing"],
        ),
        ("[[parts]\n", &[":1:", "invalid table header"]),
        // The planes are fine but the second misses the mesh: the error names the plane.
        (
            "[[parts]]\nname = \"egg\"\naxis = [0, 0, 1]\npositions = [0.0, 5.0]\n",
            &[":4:", "parts[0].positions[1]", "misses the mesh", "fitting"],
        ),
    ];
    for (text, needles) in cases {
        let dir = tempfile::tempdir().unwrap();
        let mesh = write(dir.path(), "egg.obj", &ellipsoid_obj(20, 24));
        let t = write(dir.path(), "t.toml", text);
        let design = dir.path().join("out.toml");
        let start = std::time::Instant::now();
        let out = pdeshape(&["fit", s(&mesh), "-o", s(&design), "--template", s(&t)]);
        assert!(start.elapsed() < std::time::Duration::from_secs(10));
        let line = assert_bad(&out, needles);
        assert!(line.contains("t.toml:"), "{line}");
        assert_eq!(
            files(dir.path()),
            vec!["egg.obj".to_string(), "t.toml".to_string()]
        );
    }
}

/// A sheet part of a template: planes across y from −1.4 to 1.4, both ends at the mesh's edge
/// (the arcs of its boundary beyond the first and the last plane): the fit covers the whole
/// sheet within the tolerance, and its curves are cosine series (profiles closed evenly).
#[test]
fn sheet_templates_reach_the_edge() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "sheet.obj", &sheet_obj(60, 41));
    let template = write(
        dir.path(),
        "sheet_template.toml",
        "[[parts]]\nname = \"face\"\nmode = \"sheet\"\naxis = [0, 1, 0]\n\
         positions = [-1.4, 0.0, 1.4]\nstart = \"edge\"\nend = \"edge\"\n",
    );
    let design = dir.path().join("sheet.toml");
    let json = dir.path().join("sheet.json");
    let out = pdeshape(&[
        "fit",
        s(&mesh),
        "-o",
        s(&design),
        "--template",
        s(&template),
        "--tolerance",
        "2e-3",
        "--json",
        s(&json),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(report["mode"], "template", "{report}");
    let h = report["measures"]["hausdorff_relative"].as_f64().unwrap();
    assert!(h > 0.0 && h <= 2e-3, "{report}");
    let text = std::fs::read_to_string(&design).unwrap();
    let value: toml::Value = toml::from_str(&text).unwrap();
    let curves = value["curves"].as_table().unwrap();
    assert!(!curves.is_empty());
    for (name, c) in curves {
        assert!(
            c.get("sin")
                .is_none_or(|s| s.as_array().unwrap().is_empty()),
            "{name}: {c}"
        );
    }
    // A pole closes tube parts only.
    let bad = write(
        dir.path(),
        "bad.toml",
        "[[parts]]\nname = \"face\"\nmode = \"sheet\"\naxis = [0, 1, 0]\n\
         positions = [-1.4, 1.4]\nstart = \"pole\"\n",
    );
    let out = pdeshape(&[
        "fit",
        s(&mesh),
        "-o",
        s(&dir.path().join("bad_fit.toml")),
        "--template",
        s(&bad),
    ]);
    assert_bad(&out, &["bad.toml:6:1", "parts[0].start", "tube part"]);
    assert!(!dir.path().join("bad_fit.toml").exists());
}

/// The ellipsoid of [`ellipsoid_obj`] as two OBJ objects (its lower and upper halves of
/// triangles, each with its own copies of the vertices it uses, as Blender writes separate
/// objects), or as two groups of one vertex list.
fn ellipsoid_two_objects(rings: usize, around: usize, groups: bool) -> String {
    let text = ellipsoid_obj(rings, around);
    let vertices: Vec<&str> = text.lines().filter(|l| l.starts_with("v ")).collect();
    let faces: Vec<Vec<usize>> = text
        .lines()
        .filter(|l| l.starts_with("f "))
        .map(|l| l[2..].split(' ').map(|w| w.parse().unwrap()).collect())
        .collect();
    let (lower, upper) = faces.split_at(faces.len() / 2);
    let mut out = String::new();
    if groups {
        for v in &vertices {
            out += &format!("{v}\n");
        }
    }
    let mut base = 0;
    for (name, part) in [("lower", lower), ("upper", upper)] {
        out += &format!("{} {name}\n", if groups { "g" } else { "o" });
        for f in part {
            if groups {
                out += &format!("f {} {} {}\n", f[0], f[1], f[2]);
            } else {
                for &i in f {
                    out += &format!("{}\n", vertices[i - 1]);
                }
                out += &format!("f {} {} {}\n", base + 1, base + 2, base + 3);
                base += 3;
            }
        }
    }
    out
}

/// An OBJ of several objects or groups is one mesh welded by position: it fits as the same mesh
/// in one object does (the same measures to the last digit), with a note that says so.
#[test]
fn a_multi_object_obj_fits() {
    let dir = tempfile::tempdir().unwrap();
    let fit = |name: &str, text: &str| {
        let mesh = write(dir.path(), name, text);
        let design = dir.path().join(format!("{name}.toml"));
        let json = dir.path().join(format!("{name}.json"));
        // The tube mode (see `off_meshes_fit_like_the_same_obj`).
        let out = pdeshape(&[
            "fit",
            s(&mesh),
            "-o",
            s(&design),
            "--json",
            s(&json),
            "--mode",
            "tube",
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr).to_string();
        assert!(out.status.success(), "{stderr}");
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        (stderr, report)
    };
    let (quiet, one) = fit("one.obj", &ellipsoid_obj(24, 32));
    // No note about objects (the only note is the plain one that the design file is larger
    // than this small mesh).
    assert!(!quiet.contains("objects or groups"), "{quiet}");
    assert!(
        quiet
            .lines()
            .all(|l| !l.starts_with("note:") || l.contains("larger than the mesh")),
        "{quiet}"
    );
    assert_eq!(one["mode"], "tube", "{one}");
    for groups in [false, true] {
        let name = if groups { "groups.obj" } else { "objects.obj" };
        let (stderr, two) = fit(name, &ellipsoid_two_objects(24, 32, groups));
        assert!(
            stderr.contains("2 objects or groups, read as one mesh"),
            "{stderr}"
        );
        for key in ["mode", "patches", "modes", "a"] {
            assert_eq!(two[key], one[key], "{key}: {two} against {one}");
        }
        for key in ["hausdorff", "rms", "mesh_triangles"] {
            assert_eq!(two["measures"][key], one["measures"][key], "{key}");
        }
    }
}

/// Whatever `pdeshape surface` writes (OBJ, the OBJ of separate patches, STL, PLY) of every
/// bundled example reads back as the same mesh: the same triangles and the same connected
/// components; `fit` on the OBJ succeeds or gives its reason, which is about separate
/// components only when the written mesh itself has several.
#[test]
fn the_tools_own_meshes_of_every_example_read_back_and_fit() {
    use pdeshape::fit::{InputMesh, MeshFormat};
    let dir = tempfile::tempdir().unwrap();
    let mut checked = 0;
    for (name, _) in pdeshape_testkit::example_designs() {
        let path = if examples_dir().join(&name).exists() {
            examples_dir().join(&name)
        } else {
            examples_dir().join("spline").join(&name)
        };
        let stem = name.trim_end_matches(".toml");
        let mut read = Vec::new();
        for (file, extra) in [
            ("obj", None),
            ("sep.obj", Some("--separate-patches")),
            ("stl", None),
            ("ply", None),
        ] {
            let out_path = dir.path().join(format!("{stem}.{file}"));
            let mut args = vec!["surface", s(&path), "-o", s(&out_path), "-q"];
            args.extend(extra);
            let out = pdeshape(&args);
            let stderr = String::from_utf8_lossy(&out.stderr).to_string();
            if !out.status.success() {
                // Only designs without a surface (a [dynamic] curve) write no mesh.
                assert!(
                    stderr.contains("the design has no surface"),
                    "{name}: {stderr}"
                );
                break;
            }
            let format = MeshFormat::from_extension(file.rsplit('.').next().unwrap()).unwrap();
            let mesh = InputMesh::read(&std::fs::read(&out_path).unwrap(), format)
                .unwrap_or_else(|e| panic!("{name} {file}: {e}"));
            let t = mesh.topology();
            read.push((file, mesh.triangles.len(), t.components, t.boundary_edges));
        }
        if read.is_empty() {
            continue;
        }
        // The same triangles in every format. The two OBJs (objects welded by position on
        // reading) are the same mesh; the STL (corners merged where bit-equal) has the same
        // components, and may keep apart a few corners the OBJ reader's tolerance joins (the
        // teacup's handle); the PLY keeps the design's own vertices, so patches that only
        // touch (an attached wing) stay apart there.
        let (welded, ply) = (read[0], read[3]);
        for r in &read {
            assert_eq!(r.1, welded.1, "{name}: {r:?} against {welded:?}");
        }
        assert_eq!(
            (read[1].2, read[1].3),
            (welded.2, welded.3),
            "{name}: {read:?}"
        );
        assert_eq!(read[2].2, welded.2, "{name}: {read:?}");
        assert!(ply.2 >= welded.2, "{name}: {ply:?} against {welded:?}");
        let obj = dir.path().join(format!("{stem}.obj"));
        let design = dir.path().join(format!("{stem}.fit.toml"));
        let out = pdeshape(&["fit", s(&obj), "-o", s(&design)]);
        let stderr = String::from_utf8_lossy(&out.stderr).to_string();
        if !out.status.success() {
            // Refused (2), or fitted but beyond the tolerance and not written (1).
            match out.status.code() {
                Some(1) => assert!(stderr.contains("misses the tolerance"), "{name}: {stderr}"),
                code => assert_eq!(code, Some(2), "{name}: {stderr}"),
            }
            assert!(!design.exists(), "{name}: {stderr}");
            assert_eq!(stderr.lines().count(), 1, "{name}: {stderr}");
            // Separate components only when the parts do not touch even after welding.
            if stderr.contains("separate components") {
                assert!(welded.2 > 1, "{name}: {stderr}");
            }
        }
        checked += 1;
    }
    assert!(checked >= 20, "{checked} examples checked");
}

/// A vase of revolution open at both ends, `r(z) = 1 + 0.3 sin 1.5z + 0.1z` for `z ∈ [0, 3]`,
/// as an OBJ written the way modelling tools leave seams: 40 vertices around below `z = 1.5`,
/// 80 above, the seam's ring twice (40 vertices for the band below, 80 for the band above,
/// the odd ones at the middles of the lower ring's edges: T-junctions), with a stray triangle
/// far away and a fin on an inner edge.
fn vase_with_seams_obj() -> String {
    let r = |z: f64| 1.0 + 0.3 * (1.5 * z).sin() + 0.1 * z;
    let mut v: Vec<[f64; 3]> = Vec::new();
    let mut f: Vec<[usize; 3]> = Vec::new();
    let ring = |v: &mut Vec<[f64; 3]>, z: f64, n: usize, middles: bool| {
        let start = v.len();
        for j in 0..n {
            let at = |k: usize| {
                let a = std::f64::consts::TAU * k as f64 / n as f64;
                [r(z) * a.cos(), r(z) * a.sin()]
            };
            let p = if middles && j % 2 == 1 {
                let (a, b) = (at(j - 1), at(j + 1));
                [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0]
            } else {
                at(j)
            };
            v.push([p[0], p[1], z]);
        }
        (start, n)
    };
    let rings: Vec<(usize, usize)> = (0..=30)
        .map(|k| {
            let z = k as f64 * 0.1;
            ring(&mut v, z, if k < 15 { 40 } else { 80 }, k == 15)
        })
        .collect();
    let seam_below = ring(&mut v, 1.5, 40, false);
    for k in 0..30 {
        let ((s0, n0), (s1, n1)) = (rings[k], if k == 14 { seam_below } else { rings[k + 1] });
        let (mut i, mut j) = (0, 0);
        while i < n0 || j < n1 {
            if j < n1 && (i >= n0 || (j + 1) * n0 <= (i + 1) * n1) {
                f.push([s0 + i % n0, s1 + (j + 1) % n1, s1 + j % n1]);
                j += 1;
            } else {
                f.push([s0 + i % n0, s0 + (i + 1) % n0, s1 + j % n1]);
                i += 1;
            }
        }
    }
    // A fin on an inner edge of the bottom band (vertex 0 of the first ring to vertex 1 of the
    // second), and a speck.
    v.push([3.0, 0.0, 0.05]);
    f.push([0, 41, v.len() - 1]);
    let s = v.len();
    v.extend([[9.0, 9.0, 9.0], [9.01, 9.0, 9.0], [9.0, 9.01, 9.0]]);
    f.push([s, s + 1, s + 2]);
    let mut out = String::from("# vase with seams\n");
    for p in &v {
        out += &format!("v {} {} {}\n", p[0], p[1], p[2]);
    }
    for t in &f {
        out += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    out
}

/// The vase is repaired (the seam's duplicate vertices welded, its T-junctions split, the fin
/// and the speck dropped, each said in one note) and fitted as a tube open at both ends, within
/// the tolerance of the mesh it was read as.
#[test]
fn an_open_vase_with_t_junctions_fins_and_specks_is_repaired_and_fitted() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(dir.path(), "vase.obj", &vase_with_seams_obj());
    let design = dir.path().join("vase.toml");
    let json = dir.path().join("vase.json");
    let out = pdeshape(&["fit", s(&mesh), "-o", s(&design), "--json", s(&json)]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    for needle in [
        "40 vertices welded across cracks",
        "40 T-junctions split",
        "1 edge made manifold by dropping 1 triangle",
        "1 stray piece of 1 triangle dropped",
    ] {
        assert!(stderr.contains(needle), "{needle}: {stderr}");
    }
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(report["mode"], "tube", "{report}");
    assert!(report["notes"][0]
        .as_str()
        .unwrap()
        .contains("T-junctions split"));
    let h = report["measures"]["hausdorff_relative"].as_f64().unwrap();
    assert!(h > 0.0 && h <= 2e-3, "{report}");
    // The design's surface reaches both rims: z from 0 to 3.
    let out = pdeshape(&["check", s(&design)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// An OBJ of a mesh.
fn obj(mesh: &pdeshape::fit::InputMesh) -> String {
    let mut out = String::new();
    for p in &mesh.positions {
        out += &format!("v {} {} {}\n", p.x, p.y, p.z);
    }
    for t in &mesh.triangles {
        out += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    out
}

#[test]
fn a_torus_is_fitted_by_the_general_mode_and_a_miss_is_not_written() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(
        dir.path(),
        "torus.obj",
        &obj(&pdeshape_testkit::implicit::torus(24)),
    );
    let design = dir.path().join("torus.toml");
    let json = dir.path().join("torus.json");
    let out = pdeshape(&["fit", s(&mesh), "-o", s(&design), "--json", s(&json)]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("general mode"), "{err}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(report["mode"], "general");
    let h = report["measures"]["hausdorff_relative"].as_f64().unwrap();
    assert!(h <= 0.02, "Hausdorff {h}");
    // The design reads back: check finds every layout edge G1.
    let out = pdeshape(&["check", s(&design)]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{text}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(text.contains("network 'fit'"), "{text}");
    // A tolerance it cannot meet (from a first layout of 8 vertices, so the five rounds stay
    // small): exit 1, a point and the distance, nothing written.
    let tight = dir.path().join("tight.toml");
    let out = pdeshape(&[
        "fit",
        s(&mesh),
        "-o",
        s(&tight),
        "--mode",
        "general",
        "--sections",
        "8",
        "--tolerance",
        "1e-6",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains("misses the tolerance") && err.contains(" at ("),
        "{err}"
    );
    assert!(!tight.exists());
    // --best-effort writes it and says so.
    let out = pdeshape(&[
        "fit",
        s(&mesh),
        "-o",
        s(&tight),
        "--mode",
        "general",
        "--sections",
        "8",
        "--tolerance",
        "1e-6",
        "--best-effort",
    ]);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--best-effort"));
    assert!(tight.exists());
}

#[test]
fn a_flipped_triangle_is_turned_back_with_a_note_and_the_mesh_fitted() {
    // The repairs orient every piece: the one triangle running its edges the same way as its
    // neighbours is flipped, said in a note, and the general mode fits the torus.
    let dir = tempfile::tempdir().unwrap();
    let mut m = pdeshape_testkit::implicit::torus(12);
    m.triangles[3].swap(1, 2);
    let mesh = write(dir.path(), "flip.obj", &obj(&m));
    let design = dir.path().join("out.toml");
    let out = pdeshape(&["fit", s(&mesh), "-o", s(&design), "--mode", "general"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("repaired: 1 triangle flipped to agree with their neighbours"),
        "{err}"
    );
    assert!(design.exists());
}

/// A closed "pillow" of two coincident discs of `n` rim vertices sharing their rim, centred at
/// `x` on the x axis: each rim vertex's triangles face up and down in equal measure, so it has
/// no normal, which the general mode cannot lay out.
fn pillow(x: f64, n: usize) -> pdeshape::fit::InputMesh {
    let mut p = vec![pdeshape::Vec3::new(x, 0.0, 0.0); 2];
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        p.push(pdeshape::Vec3::new(x + a.cos(), a.sin(), 0.0));
    }
    let mut t = Vec::new();
    for k in 0..n {
        let (a, b) = ((2 + k) as u32, (2 + (k + 1) % n) as u32);
        t.push([0, a, b]);
        t.push([1, b, a]);
    }
    pdeshape::fit::InputMesh::new(p, t).unwrap()
}

#[test]
fn a_sweep_writes_bytes_against_distances_beside_decimation() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = write(
        dir.path(),
        "torus.obj",
        &obj(&pdeshape_testkit::implicit::torus(16)),
    );
    let csv = dir.path().join("rd.csv");
    let svg = dir.path().join("rd.svg");
    let out = pdeshape(&[
        "fit",
        s(&mesh),
        "--sweep",
        "0.02,0.04",
        "-o",
        s(&csv),
        "--plot",
        s(&svg),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (mut fits, mut levels) = (0, 0);
    for line in lines {
        let r: Vec<&str> = line.split(',').collect();
        assert_eq!(r.len(), header.len(), "{text}");
        let num = |name: &str| r[col(name)].parse::<f64>().unwrap();
        match r[col("kind")] {
            "fit" => {
                fits += 1;
                let t = num("tolerance_percent");
                assert!(num("hausdorff_percent") <= t, "{text}");
                // The packed design's numbers move by a few steps of 1/64 of the tolerance
                // (pack.rs): allow four.
                let moved = (num("packed_hausdorff_percent") - num("hausdorff_percent")).abs();
                assert!(moved <= t / 16.0, "{text}");
                let moved = (num("packed_rms_percent") - num("rms_percent")).abs();
                assert!(moved <= t / 16.0, "{text}");
                assert!(num("packed_bytes") < num("f64_bytes"), "{text}");
                assert!(num("toml_gz_bytes") < num("toml_bytes"), "{text}");
            }
            "decimation" => {
                levels += 1;
                assert!(num("hausdorff_percent") > 0.0, "{text}");
            }
            k => panic!("kind {k}"),
        }
    }
    assert_eq!(fits, 2, "{text}");
    assert!(levels >= 5, "{text}");
    let plot = std::fs::read_to_string(&svg).unwrap();
    assert!(plot.starts_with("<svg") && plot.trim_end().ends_with("</svg>"));
    assert!(plot.contains("decimation, packed") && plot.contains("PDE patches, packed"));
    // Two panels: bytes against the Hausdorff and against the RMS distance.
    assert!(plot.contains("Hausdorff distance, %") && plot.contains("RMS distance, %"));
    assert_eq!(plot.matches("PDE patches, packed").count(), 2);
    // A tolerance outside (0, 1): one line naming it, exit 2, nothing written.
    let bad = dir.path().join("bad.csv");
    let out = pdeshape(&["fit", s(&mesh), "--sweep", "0.02,1.5", "-o", s(&bad)]);
    assert_bad(&out, &["--sweep 1.5", "between 0 and 1"]);
    assert!(!bad.exists());
    // The table must be CSV, and --plot needs --sweep.
    let out = pdeshape(&[
        "fit",
        s(&mesh),
        "--sweep",
        "0.02",
        "-o",
        s(&dir.path().join("x.toml")),
    ]);
    assert_bad(&out, &[".csv"]);
    let out = pdeshape(&[
        "fit",
        s(&mesh),
        "-o",
        s(&dir.path().join("y.toml")),
        "--plot",
        s(&svg),
    ]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn a_missed_tube_fit_is_kept_when_the_general_mode_does_no_better() {
    // An ellipsoid with one triangle turned the other way (turned back by the repairs, with a
    // note): the tube mode fits it but, at a tolerance below its facets' depth, misses; the
    // general mode misses by more. The tube fit is the one returned: a miss (exit 1, nothing
    // written), or with --best-effort written with a note saying why.
    let dir = tempfile::tempdir().unwrap();
    let text = ellipsoid_obj(24, 32);
    let first = text
        .lines()
        .find(|l| l.starts_with("f "))
        .unwrap()
        .to_string();
    let p: Vec<&str> = first.split_whitespace().collect();
    let flipped = text.replacen(&first, &format!("f {} {} {}", p[1], p[3], p[2]), 1);
    let mesh = write(dir.path(), "flip.obj", &flipped);
    let design = dir.path().join("out.toml");
    let json = dir.path().join("out.json");
    let args = ["fit", s(&mesh), "-o", s(&design), "--tolerance", "1e-4"];
    let out = pdeshape(&args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains("the tube mode's fit is kept: the general mode did no better"),
        "{err}"
    );
    assert!(!design.exists());
    let mut more = args.to_vec();
    more.extend(["--best-effort", "--json", s(&json)]);
    let out = pdeshape(&more);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("the tube mode's fit misses the tolerance and the general mode did no better")
            && err.contains("1 triangle flipped to agree with their neighbours")
            && err.contains("that fit is kept"),
        "{err}"
    );
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(report["mode"], "tube");
    assert_eq!(report["missed"], true);
    assert!(report["general_declined"]
        .as_str()
        .unwrap()
        .contains("did no better"));
}

#[test]
fn a_component_the_general_mode_cannot_lay_out_is_left_out_and_named() {
    // A torus and, beside it, a pillow whose rim vertices have no normal: the torus is
    // fitted, the pillow left out with a point near it; the fit misses (the pillow's vertices
    // are far from it), so it is written only with --best-effort.
    let dir = tempfile::tempdir().unwrap();
    let a = pdeshape_testkit::implicit::torus(12);
    // (36 rim vertices: 72 triangles, not a speck of the torus, and fewer vertices than a
    // first layout keeps, so every rim vertex is a layout vertex.)
    let b = pillow(10.0, 36);
    let offset = a.positions.len() as u32;
    let both = pdeshape::fit::InputMesh::new(
        a.positions.iter().chain(&b.positions).copied().collect(),
        a.triangles
            .iter()
            .copied()
            .chain(b.triangles.iter().map(|t| t.map(|i| i + offset)))
            .collect(),
    )
    .unwrap();
    let mesh = write(dir.path(), "two.obj", &obj(&both));
    let design = dir.path().join("two.toml");
    let args = ["fit", s(&mesh), "-o", s(&design), "--mode", "general"];
    let out = pdeshape(&args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(
        err.contains("component 2 of 2 (about (") && err.contains("is left out"),
        "{err}"
    );
    assert!(!design.exists());
    let mut more = args.to_vec();
    more.push("--best-effort");
    let out = pdeshape(&more);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("has no normal at ("), "{err}");
    let text = std::fs::read_to_string(&design).unwrap();
    let spec = pdeshape::spec::parse_design(&text).unwrap();
    assert_eq!(spec.patchwork.len(), 1);
    // The one fitted lies about the first torus (x near 0), not the second (x near 10).
    assert!(spec.patchwork[0].points.iter().all(|p| p[0] < 5.0));
}

/// The point `(x, y, z)` that follows the first `marker` in `text`.
fn point_after(text: &str, marker: &str) -> [f64; 3] {
    let rest = &text[text
        .find(marker)
        .unwrap_or_else(|| panic!("{marker}: {text}"))
        + marker.len()..];
    let inside = &rest[..rest.find(')').unwrap()];
    let c: Vec<f64> = inside.split(", ").map(|x| x.parse().unwrap()).collect();
    [c[0], c[1], c[2]]
}

#[test]
fn points_in_messages_are_where_the_file_has_them() {
    // The torus and the pillow of the test above, raised 20 along the design's +Z, written to
    // a file that states +Y up: the file's (x, y, z) is the design's (x, −z, y), so both lie
    // about y = 20 in the file (the pillow in that plane, the torus within its tube's radius
    // 0.35 of it), about z = 20 in the design. Every point a message names must be the file's.
    let dir = tempfile::tempdir().unwrap();
    let a = pdeshape_testkit::implicit::torus(12);
    let b = pillow(10.0, 36);
    let up = pdeshape::Vec3::new(0.0, 0.0, 20.0);
    let mut text = String::from("# units: mm; up: +Y\n");
    for d in a.positions.iter().chain(&b.positions).map(|p| p + up) {
        text += &format!("v {} {} {}\n", d.x, d.z, -d.y);
    }
    let offset = a.positions.len() as u32;
    for t in a
        .triangles
        .iter()
        .copied()
        .chain(b.triangles.iter().map(|t| t.map(|i| i + offset)))
    {
        text += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    let mesh = write(dir.path(), "up.obj", &text);
    let design = dir.path().join("up.toml");
    let json = dir.path().join("up.json");
    let args = ["fit", s(&mesh), "-o", s(&design), "--mode", "general"];
    let out = pdeshape(&args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    // The pillow's box is centred at the file's (10, 20, 0).
    assert!(
        err.contains("component 2 of 2 (about (10, 20, 0)) is left out"),
        "{err}"
    );
    let at = point_after(&err[err.find("misses the tolerance").unwrap()..], " at (");
    assert!((at[1] - 20.0).abs() <= 0.36, "{at:?}: {err}");
    let mut more = args.to_vec();
    more.extend(["--best-effort", "--json", s(&json)]);
    let out = pdeshape(&more);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    // A rim vertex of the pillow, to the six digits shown.
    let rim = point_after(&err, "has no normal at (");
    assert_eq!(rim[1], 20.0, "{err}");
    assert!(
        ((rim[0] - 10.0).powi(2) + rim[2].powi(2) - 1.0).abs() < 1e-3,
        "{err}"
    );
    let at = point_after(&err[err.find("--best-effort").unwrap()..], " at (");
    assert!((at[1] - 20.0).abs() <= 0.36, "{at:?}: {err}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let worst: Vec<f64> = report["worst"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert!((worst[1] - 20.0).abs() <= 0.36, "{worst:?}");
}
