//! A spine edit (§5.3) of the bent tube (`examples/spine_bend.toml`) and the re-tessellation
//! of the edited patch at 64 × 128: the patch itself is reused, only the spine, the frames and
//! the mesh are recomputed. Both ways of carrying the sections.

use criterion::{criterion_group, criterion_main, Criterion};
use pdeshape::design::{compile, Edit};
use pdeshape::spec::{SpineCarry, SpineMove, SpineSpec};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let spec = pdeshape_testkit::example_spec("spine_bend.toml");
    let (nu, nv) = (64, 128);
    let mut group = c.benchmark_group("spine");
    for carry in [SpineCarry::Frame, SpineCarry::Translate] {
        // A drag of one control point between two positions.
        let edits = [2.5, 2.6].map(|x| Edit::SetSpine {
            patch: None,
            spine: Some(SpineSpec {
                patch: None,
                carry,
                control: None,
                moves: vec![SpineMove {
                    index: 2,
                    by: [x, 0.0, 0.0],
                }],
                hermite: None,
                wave: None,
            }),
        });
        let mut d = compile(&spec).unwrap();
        d.meshes(nu, nv).unwrap();
        let mut k = 0;
        let label = format!("{carry:?}").to_lowercase();
        group.bench_function(format!("{label}/edit_retessellate_64x128"), |b| {
            b.iter(|| {
                k ^= 1;
                d.apply(&edits[k]).unwrap();
                black_box(d.meshes(nu, nv).unwrap().len())
            })
        });
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).warm_up_time(std::time::Duration::from_secs(1)).measurement_time(std::time::Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
