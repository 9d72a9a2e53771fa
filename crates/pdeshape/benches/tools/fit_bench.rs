//! Times the fitting of the test meshes of `pdeshape_testkit::fit_meshes` (`fit::fit_mesh`, or
//! `fit::fit_template` for the U tube) and measures the fits; prints one markdown table row per
//! mesh (BENCHMARKS.md): the 200 000-triangle vase, a 100 000-triangle vase for the
//! time target, the star-shaped blob, the sphere, the bent tube, the relief sheet and the U tube.
//!
//! Usage: `cargo bench -p pdeshape --bench fit_bench -- [runs]` (on a quiet machine: the
//! fit time is the median of `runs`, 3 by default; the measure time, one run, is beside it).

use pdeshape::design::solve_design;
use pdeshape::fit::{fit_mesh, fit_template, measure, parse_template, FitOptions, InputMesh};
use pdeshape_testkit::fit_meshes;
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let runs: usize = std::env::args()
        .filter(|a| a != "--bench")
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(3)
        .max(1);
    // (name, mesh, tolerance, template)
    let cases: Vec<(&str, InputMesh, f64, Option<&str>)> = vec![
        (
            "vase (noise 1e-4 of the diagonal)",
            fit_meshes::sweep(fit_meshes::vase, 400, 390, 1e-4 * 3.6, 8),
            1e-3,
            None,
        ),
        (
            "vase (noise 1e-4 of the diagonal)",
            fit_meshes::sweep(fit_meshes::vase, 280, 280, 1e-4 * 3.6, 7),
            1e-3,
            None,
        ),
        (
            "star-shaped blob (noise 1e-4)",
            fit_meshes::sweep(fit_meshes::blob, 160, 200, 1e-4 * 3.6, 3),
            5e-3,
            None,
        ),
        (
            "sphere, Fig. 8.10 (no noise)",
            fit_meshes::sweep(fit_meshes::sphere, 120, 160, 0.0, 2),
            2e-3,
            None,
        ),
        (
            "bent tube (noise 1e-4)",
            fit_meshes::sweep(fit_meshes::bent_tube, 160, 120, 1e-4 * 4.0, 4),
            3e-3,
            None,
        ),
        (
            "relief sheet, open (noise 1e-4)",
            fit_meshes::relief_sheet(120, 160, 1e-4 * 3.3, 5),
            2e-3,
            None,
        ),
        (
            "U tube, template (noise 1e-4)",
            fit_meshes::sweep_with(
                fit_meshes::u_tube,
                fit_meshes::u_tube_density,
                300,
                100,
                1e-4 * 4.6,
                6,
            ),
            2e-3,
            Some(fit_meshes::U_TUBE_TEMPLATE),
        ),
    ];
    println!(
        "| mesh | triangles | tolerance | mode | patches | modes | Hausdorff / diag | RMS / diag \
         | ratio (f64 numbers) | ratio (TOML) | fit (median of {runs}) | measure |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (name, mesh, tol, template) in cases {
        let opts = FitOptions {
            target: tol,
            ..FitOptions::default()
        };
        let template = template.map(|t| parse_template(t).expect("template"));
        let mut times = Vec::new();
        let mut fit = None;
        for _ in 0..runs {
            let t = Instant::now();
            let f = match &template {
                Some(t) => fit_template(&mesh, t, &opts),
                None => fit_mesh(&mesh, &opts),
            }
            .expect("fit");
            times.push(t.elapsed().as_secs_f64());
            fit = Some(f);
        }
        let fit = fit.expect("one run");
        let t = Instant::now();
        let solved = solve_design(&fit.spec).expect("solve");
        let (m, _) = measure(&mesh, &fit.spec, &solved, 48, 96).expect("measure");
        let measure_s = t.elapsed().as_secs_f64();
        println!(
            "| {name} | {} | {tol:.0e} | {:?} | {} | {} | {:.2e} | {:.2e} | {:.0} | {:.0} | {:.2} s \
             | {:.2} s |",
            m.mesh_triangles,
            fit.mode,
            fit.patches,
            fit.modes,
            m.hausdorff_relative,
            m.rms_relative,
            m.ratio,
            m.toml_ratio,
            median(times),
            measure_s
        );
    }
}
