//! The general mode's layout: half-edge collapses of a marching-tetrahedra double torus (genus
//! 2, irregular triangles with slivers, as scans and iso-surfaces have them) down to a layout of
//! 6000 vertices, the decimation every fit of a large mesh runs first (on its proxy) and again
//! each round. The mesh is made once, outside the timing; with `PDESHAPE_BENCH_MESH=FILE.obj`
//! it is also written there, for a peer's decimation of the same triangles.

use criterion::{criterion_group, criterion_main, Criterion};
use pdeshape::fit::{decimate, vertex_normals};
use pdeshape_testkit::implicit;
use std::time::Duration;

fn bench(c: &mut Criterion) {
    let mesh = implicit::double_torus(160);
    let normals = vertex_normals(&mesh);
    let weight = vec![1.0; mesh.positions.len()];
    if let Ok(path) = std::env::var("PDESHAPE_BENCH_MESH") {
        let mut obj = String::new();
        for p in &mesh.positions {
            obj += &format!("v {:?} {:?} {:?}\n", p.x, p.y, p.z);
        }
        for t in &mesh.triangles {
            obj += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
        }
        std::fs::write(&path, obj).expect("the mesh is written");
    }
    let mut group = c.benchmark_group("decimate");
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(30));
    group.warm_up_time(Duration::from_secs(1));
    let name = format!("double_torus_{}_to_6000", mesh.triangles.len());
    let mut faces = Vec::new();
    group.bench_function(name, |b| {
        b.iter(|| {
            let layout = decimate(&mesh, &normals, &weight, 6000, f64::INFINITY);
            faces.push(layout.faces.len());
        })
    });
    group.finish();
    // The same layout every run.
    assert!(faces.windows(2).all(|w| w[0] == w[1]), "{faces:?}");
}

criterion_group!(benches, bench);
criterion_main!(benches);
