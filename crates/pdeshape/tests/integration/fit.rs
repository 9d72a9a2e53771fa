//! Fitting meshes made by an independent construction (`pdeshape_testkit::fit_meshes`: swept rings and rows with
//! random counts, offsets and spacings, a zipper triangulation and noise): the fitted designs
//! must meet the tolerance asked for, two-sided (the Hausdorff distance between the mesh and the
//! solved design, relative to the mesh's bounding-box diagonal), and compress the mesh by at
//! least a stated floor. The floors are the issue's targets where it states one (the blob: 50;
//! the 200 000-triangle vase: 100) and otherwise about half the ratio measured when the test was
//! written, so a fit that grows markedly is noticed.

use pdeshape::curve::FourierSeries;
use pdeshape::design::{solve_design, SolvedDesign};
use pdeshape::fit::{
    fit_general, fit_mesh, fit_template, measure, parse_template, position_weights, weights, Fit,
    FitMode, FitOptions, InputMesh, Measures, MeshSamples,
};
use pdeshape::spec::{describe_error, parse_design, write_design, CurveKind, DesignSpec};
use pdeshape::Vec3;
use pdeshape_testkit::fit_meshes::{
    self, bent_tube, blob, relief_sheet, sphere, sweep, sweep_with, u_tube, vase,
};

fn options(target: f64) -> FitOptions {
    FitOptions {
        target,
        ..FitOptions::default()
    }
}

/// Reads the fit's design back from its file (what is measured is what a user reads back),
/// solves and measures it.
fn measured(mesh: &InputMesh, fit: &Fit) -> (DesignSpec, SolvedDesign, Measures) {
    let text = write_design(&fit.spec).unwrap();
    let spec = parse_design(&text).unwrap();
    assert_eq!(spec, fit.spec);
    let solved = solve_design(&spec).unwrap();
    // The mesh sampled for the default tolerance, as `pdeshape fit` measures.
    let samples = MeshSamples::for_tolerance(mesh, pdeshape::fit::DEFAULT_TOLERANCE);
    let (m, _) = measure(mesh, &spec, &solved, (48, 96), &samples).unwrap();
    (spec, solved, m)
}

/// Fits `mesh` automatically to the relative tolerance `target` and measures the result.
fn fit_and_measure(mesh: &InputMesh, target: f64) -> (Fit, Measures) {
    let fit = fit_mesh(mesh, &options(target)).unwrap();
    let (_, _, m) = measured(mesh, &fit);
    (fit, m)
}

fn report(name: &str, fit: &Fit, m: &Measures) {
    eprintln!(
        "{name}: {} triangles, {:?} mode, {} patches, {} modes, a = {}, Hausdorff {:.2e}, RMS \
         {:.2e} (of the diagonal), ratio {:.0} (toml {:.1})",
        m.mesh_triangles,
        fit.mode,
        fit.patches,
        fit.modes,
        fit.a,
        m.hausdorff_relative,
        m.rms_relative,
        m.ratio,
        m.toml_ratio
    );
}

#[test]
fn vase_meets_the_tolerance_both_ways() {
    let mesh = sweep(vase, 160, 200, 1e-4 * 3.6, 1);
    let (fit, m) = fit_and_measure(&mesh, 2e-3);
    report("vase", &fit, &m);
    assert_eq!(fit.mode, FitMode::Tube);
    assert!(m.hausdorff_relative <= 2e-3, "{m:?}");
    assert!(m.rms_relative <= 1e-3, "{m:?}");
    assert!(m.ratio >= 150.0, "{m:?}");
}

/// The issue's target: a vase of 200 000 triangles with noise of 1e-4 of the diagonal, RMS
/// distance at most 1e-3 of the diagonal at a compression ratio of at least 100.
#[test]
fn vase_of_200k_triangles_meets_the_issue_target() {
    // Diagonal of the vase: 3.6 (about; the noise is 1e-4 of it).
    let mesh = sweep(vase, 400, 390, 1e-4 * 3.6, 8);
    assert!(
        (195_000..=205_000).contains(&mesh.triangles.len()),
        "{}",
        mesh.triangles.len()
    );
    let (fit, m) = fit_and_measure(&mesh, 1e-3);
    report("vase 200k", &fit, &m);
    assert!(m.rms_relative <= 1e-3, "{m:?}");
    assert!(m.hausdorff_relative <= 1e-3, "{m:?}");
    assert!(m.ratio >= 100.0, "{m:?}");
}

#[test]
fn sphere_of_fig_8_10_meets_the_tolerance() {
    let mesh = sweep(sphere, 120, 160, 0.0, 2);
    let (fit, m) = fit_and_measure(&mesh, 2e-3);
    report("sphere", &fit, &m);
    assert!(m.hausdorff_relative <= 2e-3, "{m:?}");
    assert!(m.ratio >= 150.0, "{m:?}");
}

/// The issue's target: a closed star-shaped blob, Hausdorff at most 5e-3 of the diagonal at a
/// compression ratio of at least 50.
#[test]
fn star_shaped_blob_meets_the_issue_target() {
    let mesh = sweep(blob, 160, 200, 1e-4 * 3.6, 3);
    let (fit, m) = fit_and_measure(&mesh, 5e-3);
    report("blob", &fit, &m);
    assert!(m.hausdorff_relative <= 5e-3, "{m:?}");
    assert!(m.ratio >= 50.0, "{m:?}");
}

/// A fit does not depend on the mesh's size: the blob scaled by 10⁶ and by 10⁻⁶ (metres
/// written as micrometres, say) is fitted by the same patches, its distances relative to the
/// diagonal the same to a few parts in a thousand (rounding lands on other digits). The
/// derivative curves used to be rounded to the positions' absolute step, so at 10⁶ their unit
/// directions kept one decimal and the fit was three times farther from the mesh.
#[test]
fn a_fit_is_the_same_at_any_scale() {
    let mesh = sweep(blob, 60, 80, 1e-4 * 3.6, 3);
    let (fit, m) = fit_and_measure(&mesh, 5e-3);
    for scale in [1e6, 1e-6] {
        let big = InputMesh::new(
            mesh.positions.iter().map(|p| p * scale).collect(),
            mesh.triangles.clone(),
        )
        .unwrap();
        let (f, s) = fit_and_measure(&big, 5e-3);
        assert_eq!(
            (f.patches, f.modes, f.mode),
            (fit.patches, fit.modes, fit.mode)
        );
        let rel = |a: f64, b: f64| (a / b - 1.0).abs();
        assert!(
            rel(s.hausdorff_relative, m.hausdorff_relative) < 0.01
                && rel(s.rms_relative, m.rms_relative) < 0.01,
            "{scale}: {} against {}, RMS {} against {}",
            s.hausdorff_relative,
            m.hausdorff_relative,
            s.rms_relative,
            m.rms_relative
        );
    }
}

#[test]
fn bent_tube_meets_the_tolerance() {
    let mesh = sweep(bent_tube, 160, 120, 1e-4 * 4.0, 4);
    let (fit, m) = fit_and_measure(&mesh, 3e-3);
    report("bent tube", &fit, &m);
    assert!(m.hausdorff_relative <= 3e-3, "{m:?}");
    assert!(m.ratio >= 100.0, "{m:?}");
}

/// Neighbouring patches of a tube share their tangent plane at every node: `X_u` of the one at
/// `u = 1` and of the next at `u = 0` are parallel and point the same way (each is the patch's
/// chord length times the node's shared derivative curve).
#[test]
fn tube_patches_meet_with_one_tangent_plane() {
    let mesh = sweep(blob, 120, 160, 1e-4 * 3.6, 9);
    let fit = fit_mesh(&mesh, &options(2e-3)).unwrap();
    let (_, solved, _) = measured(&mesh, &fit);
    assert!(solved.surfaces.len() >= 2);
    for w in solved.surfaces.windows(2) {
        let (a, b) = (w[0].surface(), w[1].surface());
        for k in 0..16 {
            let v = pdeshape::TAU * k as f64 / 16.0;
            assert!((a.point(1.0, v) - b.point(0.0, v)).norm() < 1e-9);
            let (ta, tb) = (a.partials(1.0, v).xu, b.partials(0.0, v).xu);
            let sin = ta.cross(&tb).norm() / (ta.norm() * tb.norm());
            assert!(sin < 1e-9 && ta.dot(&tb) > 0.0, "{sin} at v = {v}");
        }
    }
}

/// The open face-like relief (book §4.6, Figs. 4.6–4.8) is fitted by the sheet mode: profiles
/// closed by an even reflection (cosine series only), patches with four position curves. The
/// fitted surface covers the sheet twice over, `X(u, 2π − v) = X(u, v)`.
#[test]
fn relief_sheet_meets_the_tolerance() {
    // Diagonal about 3.3: the noise is 1e-4 of it.
    let mesh = relief_sheet(120, 160, 1e-4 * 3.3, 5);
    let fit = fit_mesh(&mesh, &options(2e-3)).unwrap();
    assert_eq!(fit.mode, FitMode::Sheet);
    let (spec, solved, m) = measured(&mesh, &fit);
    report("relief sheet", &fit, &m);
    assert!(m.hausdorff_relative <= 2e-3, "{m:?}");
    assert!(m.ratio >= 15.0, "{m:?}");
    for c in spec.curves.values() {
        match &c.kind {
            CurveKind::Fourier { sin, .. } => assert!(sin.is_empty()),
            other => panic!("{other:?}"),
        }
    }
    for s in &solved.surfaces {
        for u in [0.0, 0.2, 0.5, 1.0] {
            for v in [0.3, 1.0, 2.5] {
                let (p, q) = (
                    s.surface().point(u, v),
                    s.surface().point(u, pdeshape::TAU - v),
                );
                assert!((p - q).norm() < 1e-9, "{u} {v}");
            }
        }
    }
}

/// The U-shaped tube: every plane across its main axis cuts both legs, so the automatic mode
/// refuses it; a template of three joined parts (two legs along z, the bend by five planes
/// about its centre) fits it within the tolerance, with G1 continuity across the parts.
#[test]
fn u_tube_needs_a_template() {
    let mesh = sweep_with(u_tube, fit_meshes::u_tube_density, 300, 100, 1e-4 * 4.6, 6);
    let e = fit_mesh(&mesh, &options(2e-3)).unwrap_err().to_string();
    assert!(e.contains("2 separate loops"), "{e}");
    let template = parse_template(fit_meshes::U_TUBE_TEMPLATE).unwrap();
    let fit = fit_template(&mesh, &template, &options(2e-3)).unwrap();
    assert_eq!(fit.mode, FitMode::Template);
    let (spec, solved, m) = measured(&mesh, &fit);
    report("U tube (template)", &fit, &m);
    assert!(m.hausdorff_relative <= 2e-3, "{m:?}");
    assert!(m.ratio >= 100.0, "{m:?}");
    // One chain: consecutive patches meet with G0 and G1, across the parts too.
    let names: Vec<&str> = spec
        .patches
        .as_ref()
        .unwrap()
        .iter()
        .map(|p| p.name.as_str())
        .collect();
    for part in ["left", "bend", "right"] {
        assert!(names.iter().any(|n| n.starts_with(part)), "{names:?}");
    }
    for w in solved.surfaces.windows(2) {
        let (a, b) = (w[0].surface(), w[1].surface());
        for k in 0..8 {
            let v = pdeshape::TAU * k as f64 / 8.0;
            assert!((a.point(1.0, v) - b.point(0.0, v)).norm() < 1e-9);
            let (ta, tb) = (a.partials(1.0, v).xu, b.partials(0.0, v).xu);
            assert!(ta.cross(&tb).norm() < 1e-9 * ta.norm() * tb.norm());
        }
    }
}

/// A bad template is refused with the place of the error, which `describe_error` turns into
/// the line and column of the template.
#[test]
fn bad_templates_name_their_place() {
    let cases: [(&str, &str, &str); 8] = [
        (
            "[[parts]]\nname = \"a\"\naxis = [0, 0, 1]\n",
            "1:1",
            "parts[0]: a part needs planes",
        ),
        (
            "[[parts]]\nname = \"a\"\naxis = [0, 0, 0]\npositions = [0, 1]\n",
            "3:1",
            "parts[0].axis: must not be the zero vector",
        ),
        (
            "[[parts]]\nname = \"a\"\naxis = [0, 0, 1]\npositions = [0, 1, 0.5]\n",
            "4:20",
            "parts[0].positions[2]: 0.5: positions must increase",
        ),
        (
            "[[parts]]\nname = \"a\"\nmode = \"blob\"\nplanes = []\n",
            "3:1",
            "parts[0].mode: 'blob'",
        ),
        (
            "[[parts]]\nname = \"a\"\nplanes = [{ point = [0, 0, 0], normal = [0, 0, 1] }, \
             { point = [0, 0, 1], normal = [0, 0, 1], size = 2 }]\n",
            "3:95",
            "parts[0].planes[1].size: unknown key",
        ),
        (
            "[[parts]]\nname = \"a\"\nstart = \"edge\"\naxis = [0, 0, 1]\npositions = [0, 1]\n",
            "3:1",
            "parts[0].start: \"edge\" ends a sheet part",
        ),
        ("[[parts]]\nname = \"a b\"\n", "2:1", "parts[0].name: 'a b'"),
        ("[[parts]\n", "1:", "1"),
    ];
    for (text, at, needle) in cases {
        let e = parse_template(text).unwrap_err();
        let line = describe_error("t.toml", text, &e);
        assert!(
            line.starts_with(&format!("t.toml:{at}")) && line.contains(needle),
            "{line}"
        );
        assert!(!line.contains('\n'), "{line}");
    }
    // Two parts of one name.
    let text = "[[parts]]\nname = \"a\"\naxis = [0, 0, 1]\npositions = [0, 1]\n\
                [[parts]]\nname = \"a\"\naxis = [0, 0, 1]\npositions = [1, 2]\n";
    let line = describe_error("t.toml", text, &parse_template(text).unwrap_err());
    assert!(line.starts_with("t.toml:6:1: parts[1].name"), "{line}");
}

#[test]
fn a_tighter_tolerance_gives_a_closer_fit_with_more_data() {
    let mesh = sweep(blob, 120, 160, 0.0, 5);
    let (loose_fit, loose) = fit_and_measure(&mesh, 8e-3);
    let (tight_fit, tight) = fit_and_measure(&mesh, 1e-3);
    assert!(tight.hausdorff < loose.hausdorff, "{tight:?} {loose:?}");
    assert!(tight.hausdorff_relative <= 1e-3, "{tight:?}");
    assert!(loose.hausdorff_relative <= 8e-3, "{loose:?}");
    assert!(tight.design_numbers > loose.design_numbers);
    assert!(tight_fit.patches + tight_fit.modes > loose_fit.patches + loose_fit.modes);
}

/// The fitted design's `a` and the patches' chord lengths are numbers of the file: a design
/// read back equals the one written, and the library's own solution of a patch between the
/// fitted curves is what the least squares assumed (the mode weights), for the Hermite patch
/// and for the four-position patch.
#[test]
fn mode_weights_match_the_library_solver() {
    let curves = r#"
[curves.p0]
type = "fourier"
a0 = [0.1, 0.0, 0.0]
cos = [[1.0, 0.2, 0.0], [0.0, 0.0, 0.1]]
sin = [[0.0, 1.0, 0.0], [0.05, 0.0, 0.0]]
[curves.d0]
type = "fourier"
a0 = [0.0, 0.0, 2.0]
cos = [[0.3, 0.0, 0.0], [0.0, 0.2, 0.0], [0.0, 0.0, 0.1]]
[curves.p1]
type = "fourier"
a0 = [0.0, 0.2, 1.5]
cos = [[0.7, 0.0, 0.0]]
sin = [[0.0, 0.8, 0.0], [0.0, 0.0, -0.1], [0.02, 0.0, 0.0]]
[curves.d1]
type = "fourier"
a0 = [0.0, 0.0, 1.0]
sin = [[0.0, -0.4, 0.0]]
"#;
    let hermite = |a: f64| {
        format!(
            "conditions = [\n  {{ u = 0.0, curve = \"p0\" }},\n  {{ u = 0.0, derivative = 1, \
             curve = \"d0\" }},\n  {{ u = 1.0, curve = \"p1\" }},\n  {{ u = 1.0, derivative = \
             1, curve = \"d1\" }},\n]\n[operator]\nkind = \"polyharmonic\"\norder = 2\na = \
             {a}\n{curves}"
        )
    };
    let four = |a: f64| {
        format!(
            "conditions = [\n  {{ u = 0.0, curve = \"p0\" }},\n  {{ u = 0.3333333333333333, \
             curve = \"d0\" }},\n  {{ u = 0.6666666666666666, curve = \"d1\" }},\n  {{ u = \
             1.0, curve = \"p1\" }},\n]\n[operator]\nkind = \"polyharmonic\"\norder = 2\na = \
             {a}\n{curves}"
        )
    };
    for a in [1.3, 0.25, 0.05] {
        for (text, is_four) in [(hermite(a), false), (four(a), true)] {
            let spec = parse_design(&text).unwrap();
            let solved = solve_design(&spec).unwrap();
            let surface = solved.surfaces[0].surface();
            let curve = |name: &str| -> FourierSeries {
                match &spec.curves[name].kind {
                    CurveKind::Fourier { a0, cos, sin } => FourierSeries::new(
                        Vec3::from(*a0),
                        cos.iter().map(|c| Vec3::from(*c)).collect(),
                        sin.iter().map(|c| Vec3::from(*c)).collect(),
                    )
                    .unwrap(),
                    _ => unreachable!(),
                }
            };
            // In the order of the weights: Hermite (P₀, D₀, P₁, D₁), four points (P(0),
            // P(1/3), P(2/3), P(1)).
            let cs = if is_four {
                ["p0", "d0", "d1", "p1"].map(curve)
            } else {
                ["p0", "d0", "p1", "d1"].map(curve)
            };
            let mode = |s: &FourierSeries, n: usize, v: f64| -> Vec3 {
                if n == 0 {
                    return s.a0;
                }
                let (c, d) = (
                    s.cos.get(n - 1).copied().unwrap_or_default(),
                    s.sin.get(n - 1).copied().unwrap_or_default(),
                );
                c * (n as f64 * v).cos() + d * (n as f64 * v).sin()
            };
            let mut worst: f64 = 0.0;
            for u in [0.0, 0.1, 0.37, 0.5, 0.8, 1.0] {
                for k in 0..16 {
                    let v = pdeshape::TAU * k as f64 / 16.0;
                    let mut x = Vec3::zeros();
                    for n in 0..=3 {
                        let w = if is_four {
                            position_weights(n, a, [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0], u)
                        } else {
                            weights(n, a, u)
                        };
                        for (c, wk) in cs.iter().zip(w) {
                            x += mode(c, n, v) * wk;
                        }
                    }
                    worst = worst.max((surface.point(u, v) - x).norm());
                }
            }
            // The mode systems' conditioning grows like 1/(an)³ for small an: about 1e5 at
            // a = 0.05, so agreement to 1e-9 leaves a margin of 1e2 over rounding.
            assert!(worst < 1e-9, "a = {a}, four points: {is_four}: {worst}");
        }
    }
}

/// A washer (flat rings between two coaxial cylinders: outer radius 1, inner 0.5, height 0.4, 48
/// sections, each side of the cross-section in 4 rows), built here as a surface of revolution of
/// its rectangular profile. Its rims are sharp features: the general mode lays its edges along
/// them as creases, and the faces on a ring take the ring's plane at the rims. A face whose
/// corners all lie on a ring is then flat to rounding (flat boundary curves, normals square to
/// the plane along them: the plane is the patch; with one normal per corner the rings' faces
/// leaned into the rims' 45° average normals).
#[test]
fn a_washers_rings_are_flat_and_its_rims_creases() {
    let (outer, inner, h, n, k) = (1.0, 0.5, 0.2, 48usize, 4usize);
    // The profile in (r, z), counterclockwise: outer wall up, top ring in, inner wall down,
    // bottom ring out.
    let mut profile = Vec::new();
    for i in 0..k {
        let t = i as f64 / k as f64;
        profile.push((outer, -h + 2.0 * h * t));
    }
    for i in 0..k {
        let t = i as f64 / k as f64;
        profile.push((outer + (inner - outer) * t, h));
    }
    for i in 0..k {
        let t = i as f64 / k as f64;
        profile.push((inner, h - 2.0 * h * t));
    }
    for i in 0..k {
        let t = i as f64 / k as f64;
        profile.push((inner + (outer - inner) * t, -h));
    }
    let m = profile.len();
    let mut positions = Vec::new();
    for j in 0..n {
        let phi = pdeshape::TAU * j as f64 / n as f64;
        for &(r, z) in &profile {
            positions.push(Vec3::new(r * phi.cos(), r * phi.sin(), z));
        }
    }
    let at = |j: usize, i: usize| ((j % n) * m + i % m) as u32;
    let mut triangles = Vec::new();
    for j in 0..n {
        for i in 0..m {
            let (a, b, c, d) = (at(j, i), at(j, i + 1), at(j + 1, i + 1), at(j + 1, i));
            triangles.push([a, d, c]);
            triangles.push([a, c, b]);
        }
    }
    let mut mesh = InputMesh::new(positions, triangles).unwrap();
    mesh.require_closed().unwrap();
    // Outward: the enclosed volume positive.
    if mesh.signed_volume() < 0.0 {
        for t in &mut mesh.triangles {
            t.swap(1, 2);
        }
    }
    let (fit, miss) = fit_general(&mesh, &options(0.02)).unwrap();
    assert!(miss.is_none(), "{miss:?}");
    let (spec, solved, m) = measured(&mesh, &fit);
    assert!(m.hausdorff_relative <= 0.02, "{m:?}");
    let p = &spec.patchwork[0];
    let point = |c: usize| Vec3::from(p.points[c]);
    let on_rim = |c: usize| {
        let q = point(c);
        let r = q.xy().norm();
        ((r - outer).abs() < 1e-9 || (r - inner).abs() < 1e-9) && (q.z.abs() - h).abs() < 1e-9
    };
    // The creases run from rim to rim, on all four rims.
    let creases: Vec<_> = p.edges.iter().filter(|e| e.crease).collect();
    // (A few more may be folds the layout creases wherever its tangent planes would fold.)
    let along = creases
        .iter()
        .filter(|e| on_rim(e.ends[0]) && on_rim(e.ends[1]))
        .count();
    assert!(
        10 * along >= 9 * creases.len(),
        "{along} of {} creases run along the rims",
        creases.len()
    );
    for (r, z) in [(outer, h), (outer, -h), (inner, h), (inner, -h)] {
        assert!(
            creases.iter().any(|e| e.ends.iter().all(|&c| {
                let q = point(c);
                (q.xy().norm() - r).abs() < 1e-9 && (q.z - z).abs() < 1e-9
            })),
            "no crease on the rim r = {r}, z = {z}"
        );
    }
    // The faces on a ring are flat: the patch reproduces the plane to rounding (10⁻⁹ of a
    // diagonal of 2.06 leaves 8 digits for the solve's conditioning).
    let mut flat_faces = 0;
    let mut off: f64 = 0.0;
    for (f, corners) in p.faces.iter().enumerate() {
        let z0 = point(corners[0]).z;
        if (z0.abs() - h).abs() > 1e-12 || corners.iter().any(|&c| (point(c).z - z0).abs() > 1e-12)
        {
            continue;
        }
        flat_faces += 1;
        let name = format!("fit.{f}");
        for s in solved
            .surfaces
            .iter()
            .filter(|s| s.name == name || s.name.starts_with(&format!("{name}.")))
        {
            for i in 0..=8 {
                for j in 0..=8 {
                    let q = s.surface().point(i as f64 / 8.0, j as f64 / 8.0);
                    off = off.max((q.z - z0).abs());
                }
            }
        }
    }
    assert!(flat_faces >= 8, "{flat_faces} faces on the rings");
    assert!(off < 1e-9, "a ring's face leaves its plane by {off}");
}
