//! The interactive loop of the design layer: a one-curve edit, re-solve and re-tessellation into
//! the previous meshes (64 × 128 per patch), beside compiling and tessellating from scratch, for
//! the cup (2 patches), the wine glass and the 39-patch Klein bottle; and for the five-sided
//! panel, a control point dragged and the n-sided patch re-solved, with and without its meshes.

use criterion::{criterion_group, criterion_main, Criterion};
use pdeshape::design::{compile, Edit};
use pdeshape::spec::{CurveKind, TransformStep};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let (nu, nv) = (64, 128);
    let mut group = c.benchmark_group("design");
    for (file, curve) in [
        ("cup.toml", "rim"),
        ("wine_glass.toml", "rim"),
        ("klein_bottle_patches.toml", "s05"),
    ] {
        let spec = pdeshape_testkit::example_spec(file);
        assert!(spec.curves.contains_key(curve), "{file}: {curve}");
        let label = file.trim_end_matches(".toml");
        group.bench_function(format!("{label}/compile_from_scratch"), |b| {
            b.iter(|| {
                let mut d = compile(black_box(&spec)).unwrap();
                black_box(d.meshes(nu, nv).unwrap().len())
            })
        });
        // A drag: the curve moves up and back down, each step one edit re-solved and
        // re-tessellated into the meshes of the previous step.
        let low = spec.curves[curve].clone();
        let mut high = low.clone();
        high.transform
            .push(TransformStep::Translate([0.0, 0.0, 0.01]));
        let edits = [low, high].map(|c| Edit::SetCurve {
            name: curve.to_string(),
            curve: Some(c),
        });
        let mut d = compile(&spec).unwrap();
        d.meshes(nu, nv).unwrap();
        let mut k = 0;
        group.bench_function(format!("{label}/edit_resolve_retessellate"), |b| {
            b.iter(|| {
                k ^= 1;
                d.apply(&edits[k]).unwrap();
                black_box(d.meshes(nu, nv).unwrap().len())
            })
        });
    }
    // A control point of one side of the five-sided panel moved up and back: each step one
    // edit, the patch re-solved (its Galerkin matrix cached, the interpolant and the right-hand
    // side recomputed), then also re-tessellated; `drag_control_point` moves it frame after
    // frame as a drag (`apply_dragging`), as the designer does, where the meshes come from the
    // drag's affine model (made before the timing starts).
    let spec = pdeshape_testkit::example_spec("nsided_pentagon.toml");
    let CurveKind::BSpline { control, .. } = &spec.curves["side0"].kind else {
        panic!("nsided_pentagon.toml: side0 is a B-spline")
    };
    let low = control[1];
    let high = [low[0], low[1], low[2] + 0.01];
    let one = [low, high].map(|point| Edit::MoveControlPoint {
        name: "side0".to_string(),
        index: 1,
        point,
    });
    let mut d = compile(&spec).unwrap();
    d.meshes(nu, nv).unwrap();
    let mut k = 0;
    group.bench_function("nsided_pentagon/move_control_point_resolve", |b| {
        b.iter(|| {
            k ^= 1;
            d.apply(&one[k]).unwrap();
            black_box(d.solved().surfaces.len())
        })
    });
    group.bench_function(
        "nsided_pentagon/move_control_point_resolve_retessellate",
        |b| {
            b.iter(|| {
                k ^= 1;
                d.apply(&one[k]).unwrap();
                black_box(d.meshes(nu, nv).unwrap().len())
            })
        },
    );
    let predicted = d.predicted_meshes();
    assert_eq!(predicted, 0, "edits outside a drag were predicted");
    let mut k = 0;
    for _ in 0..2 {
        k ^= 1;
        d.apply_dragging(&one[k]).unwrap();
        d.meshes(nu, nv).unwrap();
    }
    group.bench_function("nsided_pentagon/drag_control_point", |b| {
        b.iter(|| {
            k ^= 1;
            d.apply_dragging(&one[k]).unwrap();
            black_box(d.meshes(nu, nv).unwrap().len())
        })
    });
    assert!(d.predicted_meshes() > predicted, "the drag had no model");
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20).measurement_time(std::time::Duration::from_secs(3));
    targets = bench
}
criterion_main!(benches);
