//! CAD export of formula surfaces (`bench/designs/formula_{ball,ring}.toml`): the net and its
//! STEP text at tolerances 10⁻³ and 10⁻⁶ of the design size, certified by interval bounds
//! (`approximate_formula`) against the sampled refinement (`approximate_sampled`). The control
//! point counts, deviations and file sizes are printed once before the timings.

use criterion::{criterion_group, criterion_main, Criterion};
use pdeshape::cad::certify::{approximate_formula, approximate_sampled, Approximation};
use pdeshape::cad::step::{to_step, LengthUnit, StepOptions};
use pdeshape::cad::{design_size, CadModel, CadSurface};
use pdeshape::design::{solve_design, SurfaceKind};
use pdeshape::spec::parse_design;
use pdeshape::Result;
use std::hint::black_box;
use std::time::Duration;

fn step_text(name: &str, approx: Approximation, tolerance: f64) -> String {
    let model = CadModel {
        name: name.to_string(),
        surfaces: vec![CadSurface {
            name: name.to_string(),
            approx,
            holes: Vec::new(),
        }],
        tolerance,
    };
    to_step(
        &model,
        &StepOptions {
            unit: LengthUnit::Millimetre,
            file_name: format!("{name}.step"),
            timestamp: "2026-01-01T00:00:00".into(),
        },
    )
    .unwrap()
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("cad_formula");
    g.sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    for name in ["ball", "ring"] {
        let path = format!(
            "{}/../../bench/designs/formula_{name}.toml",
            env!("CARGO_MANIFEST_DIR")
        );
        let design =
            solve_design(&parse_design(&std::fs::read_to_string(path).unwrap()).unwrap()).unwrap();
        let size = design_size(&design);
        let SurfaceKind::Parametric(p) = &design.surfaces[0].kind else {
            panic!("{name}: not a formula surface")
        };
        for rel in [1e-3, 1e-6] {
            let t = rel * size;
            type Fit<'a> = Box<dyn Fn() -> Result<Approximation> + 'a>;
            let fits: [(&str, Fit); 2] = [
                ("certified", Box::new(|| approximate_formula(p, t))),
                ("sampled", Box::new(|| approximate_sampled(&**p, t, 8))),
            ];
            for (how, fit) in fits {
                let a = fit().unwrap();
                let [nu, nv] = a.net.counts();
                let dev = a.deviation;
                let bytes = step_text(name, a, t).len();
                eprintln!(
                    "{name} T = {rel:e}·size ({t:.3e}), {how}: {nu} × {nv} control points, \
                     deviation {dev:.3e}, STEP {bytes} bytes"
                );
                g.bench_function(format!("{name}/{rel:e}/{how}"), |b| {
                    b.iter(|| black_box(step_text(name, fit().unwrap(), t).len()))
                });
            }
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
