//! The trimmed mesh of `examples/trimmed_vase.toml` (256 × 512, three holes, the general
//! method) `ITER` times, printing the median and the fastest time:
//! `cargo bench -p pdeshape --bench trim_timing -- mesh 200` (`mesh`: fresh buffers,
//! as `trimmed_mesh`; `into`: reused buffers, as `trimmed_mesh_into`; `domain`: the parameter
//! domain alone). The figures in BENCHMARKS.md come from `cargo bench --bench trim`; this is
//! for profiling (`perf record`, `valgrind --tool=callgrind`) and quick A/B runs.

use pdeshape::design::{compile, trim_curve};
use pdeshape::trim::{trim_domain, trimmed_mesh, trimmed_mesh_into, TrimMethod, TrimmedMesh};
use std::hint::black_box;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().filter(|a| a != "--bench").collect();
    let what = args.get(1).map(|s| s.as_str()).unwrap_or("mesh");
    let iters: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(50);
    let spec = pdeshape_testkit::example_spec("trimmed_vase.toml");
    let d = compile(&spec).unwrap();
    let solved = d.solved();
    let s = solved.surfaces[0].surface();
    let curves: Vec<_> = spec.trims[0].curves.iter().map(trim_curve).collect();
    let (nu, nv) = (256, 512);
    let mut times = Vec::with_capacity(iters);
    let mut out = TrimmedMesh::default();
    for _ in 0..iters.max(1) {
        let t = Instant::now();
        let n = match what {
            "mesh" => trimmed_mesh(s, nu, nv, &curves, TrimMethod::Cdt, "wall")
                .unwrap()
                .0
                .triangles
                .len(),
            "domain" => trim_domain(s.parameter_domain(), nu, nv, &curves, TrimMethod::Cdt)
                .unwrap()
                .triangles
                .len(),
            "into" => {
                trimmed_mesh_into(s, nu, nv, &curves, TrimMethod::Cdt, "wall", &mut out).unwrap();
                out.mesh.triangles.len()
            }
            _ => panic!("mesh, into or domain"),
        };
        black_box(n);
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    println!(
        "{what}: median {:.3} ms, fastest {:.3} ms ({} runs)",
        times[times.len() / 2],
        times[0],
        times.len()
    );
}
