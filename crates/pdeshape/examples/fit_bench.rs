//! Times `fit::fit_tube` and the measures on the test meshes of `tests/fit_meshes` at the sizes
//! of the targets; prints one markdown table row per mesh (BENCHMARKS.md).
//!
//! Usage: `cargo run --release -p pdeshape --example fit_bench [runs]`

#[path = "../tests/fit_meshes/mod.rs"]
mod fit_meshes;

use pdeshape::design::solve_design;
use pdeshape::fit::{fit_tube, measure, TubeOptions};
use std::time::Instant;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let runs: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(3);
    type Shape = fn(f64, f64) -> pdeshape::Vec3;
    // (name, shape, rings, around, diagonal (for the noise), noise / diagonal, tolerance)
    let cases: [(&str, Shape, usize, usize, f64, f64, f64); 5] = [
        ("vase", fit_meshes::vase, 320, 320, 3.6, 1e-4, 1e-3),
        ("vase", fit_meshes::vase, 220, 230, 3.6, 1e-4, 1e-3),
        ("star blob", fit_meshes::blob, 320, 320, 4.1, 1e-4, 5e-3),
        ("sphere", fit_meshes::sphere, 220, 230, 3.5, 0.0, 2e-3),
        (
            "bent tube",
            fit_meshes::bent_tube,
            320,
            200,
            4.3,
            1e-4,
            3e-3,
        ),
    ];
    println!("| mesh | triangles | tolerance | patches | modes | Hausdorff / diag | RMS / diag | ratio (f64 numbers) | ratio (TOML) | fit (median of {runs}) | measure |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for (name, shape, rings, around, diag, noise, tol) in cases {
        let mesh = fit_meshes::sweep(shape, rings, around, noise * diag, 7);
        let opts = TubeOptions {
            target: tol,
            ..TubeOptions::default()
        };
        let mut times = Vec::new();
        let mut fit = None;
        for _ in 0..runs {
            let t = Instant::now();
            let f = fit_tube(&mesh, &opts).expect("fit");
            times.push(t.elapsed().as_secs_f64());
            fit = Some(f);
        }
        let fit = fit.expect("one run");
        let t = Instant::now();
        let solved = solve_design(&fit.spec).expect("solve");
        let (m, _) = measure(&mesh, &fit.spec, &solved, 48, 96).expect("measure");
        let measure_s = t.elapsed().as_secs_f64();
        println!(
            "| {name} (noise {noise:.0e} of the diagonal) | {} | {tol:.0e} | {} | {} | {:.2e} | {:.2e} | {:.0} | {:.0} | {:.2} s | {:.2} s |",
            m.mesh_triangles,
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
