//! Frames per second of the four-patch left ventricle (`examples/anim/ventricle.toml`, §8.1.1)
//! at 64 × 128 per patch: every frame's formulas evaluated, the design re-solved, tessellated
//! and welded into one mesh (what `pdeshape animate` does per frame before writing). One
//! iteration is the whole 48-frame beat; the throughput is in frames. Frames are solved in
//! parallel (one worker per thread of the pool); the second row runs them on one thread; the
//! third also puts every frame into the GLB's binary chunk as `pdeshape animate` does (the
//! file's bytes in memory, not written). The last two rows time what the issue's "solve +
//! tessellate" names, without the weld: the same beat, frames in parallel over the pool (every
//! thread with its own compiled design, re-solved incrementally from its previous frame), then
//! on one thread.
//!
//! `cargo bench -p pdeshape --bench anim` (all rows), or one row by name, e.g.
//! `cargo bench -p pdeshape --bench anim -- ventricle_frames_64x128$`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use pdeshape::anim::{for_each_frame, Animation, GlbFrames, Keyframes};
use pdeshape::design::{compile, Export};
use pdeshape::mesh::MeshInfo;
use pdeshape::spec::time::parse_timed;
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let text = pdeshape_testkit::example("anim/ventricle.toml");
    let anim = Animation::Timed(parse_timed(&text).unwrap());
    let times = anim.times().unwrap();
    let mut group = c.benchmark_group("anim");
    group.throughput(Throughput::Elements(times.len() as u64));
    let beat = || {
        let mut n = 0usize;
        for_each_frame(&anim, &times, 64, 128, &Export::default(), |f| {
            n += f.mesh.positions.len();
            Ok(())
        })
        .unwrap();
        black_box(n)
    };
    // Frames in parallel over the default pool (one worker per core), then on one thread.
    group.bench_function("ventricle_frames_64x128", |b| b.iter(beat));
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    group.bench_function("ventricle_frames_64x128_one_thread", |b| {
        b.iter(|| one.install(beat))
    });
    let with_glb = || {
        let mut glb: Option<GlbFrames> = None;
        let mut keys = Keyframes::new(anim.time());
        for_each_frame(&anim, &times, 64, 128, &Export::default(), |f| {
            keys.push_time(&f);
            let (p, n) = (&f.mesh.positions, &f.mesh.normals);
            match glb.as_mut() {
                Some(g) => g.push(p, n),
                None => {
                    let info = MeshInfo::default();
                    GlbFrames::new(&info, &f.mesh.triangles, p, n, times.len())
                        .map(|g| glb = Some(g))
                }
            }
        })
        .unwrap();
        let mut bytes = Vec::new();
        glb.unwrap()
            .finish(&keys, &MeshInfo::default(), &mut bytes)
            .unwrap();
        black_box(bytes.len())
    };
    group.bench_function("ventricle_frames_64x128_glb_in_memory", |b| {
        b.iter(with_glb)
    });
    // Solve + tessellate only: worker w of W takes frames w, w + W, … (every frame solved).
    let solve_tessellate = || {
        use rayon::prelude::*;
        let workers = rayon::current_num_threads().max(1);
        let n: usize = (0..workers)
            .into_par_iter()
            .map(|w| {
                let mut compiled = None;
                let mut n = 0usize;
                for &t in times.iter().skip(w).step_by(workers) {
                    let spec = anim.spec_at(t).unwrap();
                    match compiled.as_mut() {
                        None => compiled = Some(compile(&spec).unwrap()),
                        Some(c) => c.set_spec(spec).unwrap(),
                    }
                    let c = compiled.as_mut().unwrap();
                    n += c.meshes(64, 128).unwrap().len();
                }
                n
            })
            .sum();
        black_box(n)
    };
    group.bench_function("ventricle_solve_tessellate_64x128", |b| {
        b.iter(solve_tessellate)
    });
    group.bench_function("ventricle_solve_tessellate_64x128_one_thread", |b| {
        b.iter(|| one.install(solve_tessellate))
    });
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10).warm_up_time(std::time::Duration::from_secs(1)).measurement_time(std::time::Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
