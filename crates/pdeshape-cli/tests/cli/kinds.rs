//! Every command treats every design kind alike: `check`, `analyze`, `render` and `surface` honour
//! `solver = "fd"`, and work on blend and spline designs, all through the library's one design
//! layer (the pictures and numbers are those the library computes for the same design).

use crate::common::*;
use pdeshape::design::WriteDesign as _;
use pdeshape::design::{solve_design, SurfaceKind};
use pdeshape::render::{render_png, RenderOptions};

/// The cup solved by finite differences on a coarse grid (far from the analytic surface, so a
/// command that solved analytically could not produce the same output).
fn fd_cup() -> String {
    let cup = std::fs::read_to_string(examples_dir().join("cup.toml")).unwrap();
    format!("solver = {{ method = \"fd\", grid = [8, 16] }}\n{cup}")
}

/// The quadrature of `analyze --tolerance 1e-6` (finite-difference surfaces are only C²
/// between their nodes, so the default 1e-11 takes many refinements).
fn quadrature() -> pdeshape::analysis::Quadrature {
    pdeshape::analysis::Quadrature {
        tolerance: 1e-6,
        ..Default::default()
    }
}

fn json_area(stdout: &[u8]) -> f64 {
    let v: serde_json::Value = serde_json::from_slice(stdout).unwrap();
    v["total"]["area"].as_f64().unwrap()
}

#[test]
fn every_command_honours_the_finite_difference_solver() {
    let dir = tempfile::tempdir().unwrap();
    let fd = write(dir.path(), "fd.toml", &fd_cup());
    let analytic = examples_dir().join("cup.toml");
    let spec = pdeshape::spec::parse_design(&fd_cup()).unwrap();
    let solved = solve_design(&spec).unwrap();
    assert!(solved
        .surfaces
        .iter()
        .all(|s| matches!(s.kind, SurfaceKind::Fd(_))));

    // check: reports the finite-difference solver and each patch's position errors. On this
    // coarse 8 × 16 grid the seam along 'belly' is G1 only to about 0.019 rad, above the
    // default seam tolerance of one degree: FAIL with status 1; a tolerance of 0.05 rad passes.
    let out = pdeshape(&["check", s(&fd)]);
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    assert!(
        String::from_utf8_lossy(&out.stdout)
            .starts_with("FAIL\nfail: shared edge 'base' u = 1 | 'bowl' u = 0 along 'belly'"),
        "{out:?}"
    );
    let out = pdeshape(&["check", "--g1-tolerance", "0.05", s(&fd)]);
    assert!(out.status.success(), "{out:?}");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("solver: finite differences on a 8 × 16 grid"),
        "{text}"
    );
    assert!(!text.contains("Fourier modes"), "{text}");

    // analyze: the finite-difference surfaces' area, not the analytic one.
    let out = pdeshape(&["analyze", s(&fd), "--json", "--tolerance", "1e-6"]);
    assert!(out.status.success(), "{out:?}");
    let fd_area = json_area(&out.stdout);
    let out = pdeshape(&["analyze", s(&analytic), "--json", "--tolerance", "1e-6"]);
    let analytic_area = json_area(&out.stdout);
    let lib = pdeshape::analysis::integrate_design(&solved, &quadrature()).unwrap();
    assert_eq!(fd_area, lib.total.area);
    // The 8 × 16 grid is coarse: the areas differ well beyond the quadrature's 1e-6.
    assert!(
        (fd_area - analytic_area).abs() > 1e-6 * analytic_area,
        "{fd_area} vs {analytic_area}"
    );

    // render: exactly the picture of the finite-difference meshes.
    let png = dir.path().join("fd.png");
    let out = pdeshape(&["render", s(&fd), "-o", s(&png), "--size", "200x150"]);
    assert!(out.status.success(), "{out:?}");
    let meshes = solved.meshes(64, 128).unwrap();
    let options = RenderOptions {
        width: 200,
        height: 150,
        ..RenderOptions::default()
    };
    let expected = render_png(
        &meshes,
        &pdeshape::render::overlay_lines(&solved.overlays()),
        &options,
    )
    .unwrap();
    assert_eq!(std::fs::read(&png).unwrap(), expected);

    // surface: says so, and writes the finite-difference meshes.
    let obj = dir.path().join("fd.obj");
    let out = pdeshape(&["surface", s(&fd), "-o", s(&obj)]);
    assert!(out.status.success(), "{out:?}");
    assert!(String::from_utf8_lossy(&out.stdout).contains("finite differences on 8 × 16"));
    let mut expected = Vec::new();
    solved
        .write(
            pdeshape::mesh::Format::Obj,
            meshes[0].nu,
            meshes[0].nv,
            &mut expected,
        )
        .unwrap();
    assert_eq!(std::fs::read(&obj).unwrap(), expected);
}

/// `render`, `analyze`, `check` and `surface` on the blend and spline examples.
#[test]
fn blend_and_spline_designs_render_and_analyze() {
    let dir = tempfile::tempdir().unwrap();
    for (file, kind) in [
        ("blend_cylinders.toml", "blend"),
        ("spline/biharmonic_bezier.toml", "spline"),
    ] {
        let path = examples_dir().join(file);
        let spec = pdeshape::spec::parse_design(&std::fs::read_to_string(&path).unwrap()).unwrap();
        let solved = solve_design(&spec).unwrap();
        assert_eq!(solved.surfaces.last().unwrap().name, kind, "{file}");

        let png = dir.path().join(format!("{kind}.png"));
        let out = pdeshape(&["render", s(&path), "-o", s(&png), "--size", "160x120"]);
        assert!(out.status.success(), "{file}: {out:?}");
        let (nu, nv) = pdeshape::design::grid(&spec, None, None).unwrap();
        let meshes = solved.meshes(nu, nv).unwrap();
        let options = RenderOptions {
            width: 160,
            height: 120,
            ..RenderOptions::default()
        };
        let expected = render_png(
            &meshes,
            &pdeshape::render::overlay_lines(&solved.overlays()),
            &options,
        )
        .unwrap();
        assert_eq!(std::fs::read(&png).unwrap(), expected, "{file}");

        let out = pdeshape(&["analyze", s(&path), "--json", "--tolerance", "1e-6"]);
        assert!(out.status.success(), "{file}: {out:?}");
        let area = json_area(&out.stdout);
        let lib = pdeshape::analysis::integrate_design(&solved, &quadrature()).unwrap();
        assert!(area.is_finite() && area > 0.0, "{file}: {area}");
        assert_eq!(area, lib.total.area, "{file}");

        let out = pdeshape(&["check", s(&path)]);
        assert!(out.status.success(), "{file}: {out:?}");
        assert!(String::from_utf8_lossy(&out.stdout).starts_with("OK\n"));

        let obj = dir.path().join(format!("{kind}.obj"));
        let out = pdeshape(&["surface", s(&path), "-o", s(&obj)]);
        assert!(out.status.success(), "{file}: {out:?}");
        let mut expected = Vec::new();
        solved
            .write(
                pdeshape::mesh::Format::Obj,
                meshes[0].nu,
                meshes[0].nv,
                &mut expected,
            )
            .unwrap();
        assert_eq!(std::fs::read(&obj).unwrap(), expected, "{file}");
    }
}

/// An order 3 n-sided patch: `check` prints and writes (JSON) its G2 per side and the corners'
/// curvature mismatch; G2 asked where it cannot be met is one line, status 2, no output.
#[test]
fn check_reports_g2_sides_and_refuses_bad_g2_input() {
    let octant = std::fs::read_to_string(examples_dir().join("nsided_g2_octant.toml")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), "octant.toml", &octant);
    let out = pdeshape(&["check", s(&f), "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let ns = &v["nsided"][0];
    for k in 0..3 {
        let g2 = ns["g2"][k].as_f64().unwrap();
        assert!(g2 < 1e-9, "{ns}");
        let c = ns["corners"][k]["curvature_mismatch"].as_f64().unwrap();
        assert!(c < 1e-9, "{ns}");
    }
    assert_eq!(v["verdict"], "ok", "{v}");
    let report = v["report"].as_str().unwrap();
    assert!(report.contains("G2 to "), "{report}");
    // G2 at order 2, on a side without a neighbour, and a fourth order.
    bad_design(
        &edit(&octant, "order = 3\n", "order = 2\n"),
        &[
            "nsided[0].sides[0]",
            "a curvature ribbon (G2) needs order 3, not 2",
        ],
    );
    bad_design(
        &edit(
            &octant,
            "{ curve = \"equator\", tangent_to = \"sphere\", g2 = true }",
            "{ curve = \"equator\", g2 = true }",
        ),
        &["nsided[0].sides[0].g2", "`g2` needs `tangent_to`"],
    );
    bad_design(
        &edit(&octant, "order = 3\n", "order = 4\n"),
        &["nsided[0]", "order 1, 2 or 3, not 4"],
    );
}
