//! Trimmed tessellation: the wall of `examples/trimmed_vase.toml` (one biharmonic patch) on a
//! 256 × 512 grid with its three holes (circle, ellipse across the seam, concave B-spline),
//! re-meshed by the general method; the two convex holes by the book's two methods; and the
//! untrimmed tessellation of the same grid for scale. `mesh` builds a fresh mesh; `mesh_into`
//! re-meshes a trim edit (the circle moved) into the previous mesh's buffers.

use criterion::{criterion_group, criterion_main, Criterion};
use pdeshape::design::{compile, trim_curve, trim_method};
use pdeshape::mesh::tessellate;
use pdeshape::trim::{
    to_trimesh, trim_domain, trimmed_mesh, trimmed_mesh_into, TrimCurve, TrimMethod, TrimmedMesh,
};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let spec = pdeshape_testkit::example_spec("trimmed_vase.toml");
    let d = compile(&spec).unwrap();
    let solved = d.solved();
    let s = solved.surfaces[0].surface();
    let t = &spec.trims[0];
    let curves: Vec<_> = t.curves.iter().map(trim_curve).collect();
    assert_eq!(trim_method(t.method), TrimMethod::Cdt);
    let (nu, nv) = (256, 512);
    let mut g = c.benchmark_group("trim");
    g.bench_function("untrimmed_tessellation_256x512", |b| {
        b.iter(|| black_box(tessellate(s, nu, nv).unwrap().len()))
    });
    g.bench_function("cdt_3_holes_256x512/domain", |b| {
        b.iter(|| {
            black_box(
                trim_domain(s.parameter_domain(), nu, nv, &curves, TrimMethod::Cdt)
                    .unwrap()
                    .triangles
                    .len(),
            )
        })
    });
    g.bench_function("cdt_3_holes_256x512/mesh", |b| {
        b.iter(|| {
            black_box(
                trimmed_mesh(s, nu, nv, &curves, TrimMethod::Cdt, "wall")
                    .unwrap()
                    .0
                    .triangles
                    .len(),
            )
        })
    });
    // A trim edit: the circle moved between two positions, re-meshed into the previous mesh.
    let moved: [Vec<TrimCurve>; 2] = [0.0, 0.01].map(|dv| {
        let mut c = curves.clone();
        let TrimCurve::Ellipse { center, .. } = &mut c[0] else {
            panic!("the vase's first hole is a circle");
        };
        center[1] += dv;
        c
    });
    let mut out = TrimmedMesh::default();
    let mut k = 0;
    g.bench_function("cdt_3_holes_256x512/mesh_into", |b| {
        b.iter(|| {
            k ^= 1;
            trimmed_mesh_into(s, nu, nv, &moved[k], TrimMethod::Cdt, "wall", &mut out).unwrap();
            black_box(out.mesh.triangles.len())
        })
    });
    let grid = tessellate(s, nu, nv).unwrap();
    for method in [TrimMethod::Cdt, TrimMethod::Bilinear, TrimMethod::Laplace] {
        g.bench_function(
            format!("{}_2_convex_holes_256x512/remesh", method.word()),
            |b| {
                b.iter(|| {
                    let pm =
                        trim_domain(s.parameter_domain(), nu, nv, &curves[..2], method).unwrap();
                    black_box(to_trimesh(s, &grid, &pm, "wall").triangles.len())
                })
            },
        );
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
