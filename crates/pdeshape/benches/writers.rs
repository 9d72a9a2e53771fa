//! Mesh writing throughput: the cup (two patches) tessellated at 1024 × 1024 per patch, welded
//! into one mesh once, then written as binary glTF (GLB) and binary STL into memory. Reported in
//! bytes of output per second; the weld itself (what `mesh::write` does before writing) is
//! timed apart.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use pdeshape::design::compile;
use pdeshape::mesh::{weld, write_mesh, Format, MeshInfo, WeldOptions};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let spec = pdeshape_testkit::example_spec("cup.toml");
    let mut design = compile(&spec).unwrap();
    let grids = &design.meshes(1024, 1024).unwrap();
    assert_eq!(grids.len(), 2);
    let mesh = weld(grids, &["base", "bowl"], WeldOptions::default());
    let info = MeshInfo::default();
    let mut group = c.benchmark_group("write_1024x1024_two_patches");
    for (name, format) in [("glb", Format::Glb), ("stl", Format::Stl)] {
        let mut out = Vec::new();
        write_mesh(format, &mesh, &info, &mut out).unwrap();
        let size = out.len();
        group.throughput(Throughput::Bytes(size as u64));
        group.bench_function(name, |b| {
            b.iter(|| {
                out.clear();
                write_mesh(format, black_box(&mesh), &info, &mut out).unwrap();
                black_box(out.len())
            })
        });
    }
    group.throughput(Throughput::Elements(
        grids.iter().map(|g| g.positions.len() as u64).sum(),
    ));
    group.bench_function("weld", |b| {
        b.iter(|| {
            black_box(weld(
                black_box(grids),
                &["base", "bowl"],
                WeldOptions::default(),
            ))
            .triangles
            .len()
        })
    });
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10);
    targets = bench
}
criterion_main!(benches);
