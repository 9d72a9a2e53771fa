//! Makes `examples/anim/face_scan.obj`: a triangle mesh of the front of the neutral face of
//! `examples/anim/face.toml`, built independently of the PDE face's grid, as a stand-in for a
//! scan to re-target the face's expressions onto.
//!
//! The face at its first time (every expression weight zero) is sampled at scattered points: a
//! Halton sequence (bases 2 and 3) over the front of each patch (`|v − π| < 1`), as many per
//! patch as its share of the face's height. Each point is pushed along the surface normal by a
//! pseudo-random amount in `[−0.02, 0.02]` cm (scanner noise), and the points are triangulated
//! by a Delaunay triangulation of their projection on the `x, z` plane (`spade`); triangles with
//! an edge longer than 0.8 cm (the hull's slivers around the border) are dropped.
//!
//! Usage: `cargo bench -p pdeshape --bench face_scan -- ../../examples/anim/face.toml OUT.obj`

use pdeshape::spec::time::parse_timed;
use pdeshape::Vec3;
use spade::{DelaunayTriangulation, Point2, Triangulation};
use std::fmt::Write as _;

const POINTS: usize = 5000;
const NOISE: f64 = 0.02;
const LONGEST_EDGE: f64 = 0.8;

fn halton(mut i: usize, base: usize) -> f64 {
    let (mut f, mut r) = (1.0, 0.0);
    while i > 0 {
        f /= base as f64;
        r += f * (i % base) as f64;
        i /= base;
    }
    r
}

fn main() -> Result<(), String> {
    let args: Vec<String> = std::env::args().filter(|a| a != "--bench").collect();
    if args.len() != 3 {
        return Err("usage: face_scan FACE.toml OUT.obj".into());
    }
    let text = std::fs::read_to_string(&args[1]).map_err(|e| e.to_string())?;
    let timed = parse_timed(&text).map_err(|e| e.to_string())?;
    let spec = timed.at(timed.time.start).map_err(|e| e.to_string())?;
    let compiled = pdeshape::design::compile(&spec).map_err(|e| e.to_string())?;
    let solved = compiled.solved();
    // Each patch's share of the height (z at its u = 0 and u = 1 on the front).
    let pi = std::f64::consts::PI;
    let heights: Vec<f64> = solved
        .surfaces
        .iter()
        .map(|s| (s.surface().point(1.0, pi).z - s.surface().point(0.0, pi).z).abs())
        .collect();
    let total: f64 = heights.iter().sum();
    let mut points: Vec<Vec3> = Vec::new();
    let mut seed: u64 = 0x2545_F491_4F6C_DD1D;
    let mut noise = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    for (s, h) in solved.surfaces.iter().zip(&heights) {
        let n = (POINTS as f64 * h / total).round() as usize;
        for i in 1..=n {
            let (u, v) = (halton(i, 2), pi + 2.0 * (halton(i, 3) - 0.5));
            let p = s.surface().partials(u, v);
            let Some(normal) = p.normal_or_none() else {
                continue;
            };
            points.push(p.x + normal * (NOISE * noise()));
        }
    }
    let mut dt: DelaunayTriangulation<Point2<f64>> = DelaunayTriangulation::new();
    let mut index_of = std::collections::HashMap::new();
    let mut kept: Vec<Vec3> = Vec::new();
    for p in &points {
        let h = dt
            .insert(Point2::new(p.x, p.z))
            .map_err(|e| format!("{e:?}"))?;
        if let std::collections::hash_map::Entry::Vacant(e) = index_of.entry(h.index()) {
            e.insert(kept.len());
            kept.push(*p);
        }
    }
    let mut used = vec![usize::MAX; kept.len()];
    let mut vertices: Vec<Vec3> = Vec::new();
    let mut triangles: Vec<[usize; 3]> = Vec::new();
    for f in dt.inner_faces() {
        let ids = f.vertices().map(|v| index_of[&v.fix().index()]);
        let [a, b, c] = ids.map(|i| kept[i]);
        if (b - a).norm().max((c - b).norm()).max((a - c).norm()) > LONGEST_EDGE {
            continue;
        }
        // Orient towards the viewer (−y), the face's outside.
        let mut t = ids;
        if (b - a).cross(&(c - a)).y > 0.0 {
            t.swap(1, 2);
        }
        let t = t.map(|i| {
            if used[i] == usize::MAX {
                used[i] = vertices.len();
                vertices.push(kept[i]);
            }
            used[i]
        });
        triangles.push(t);
    }
    let mut out = String::new();
    let _ = writeln!(
        out,
        "# The front of the neutral face of face.toml, sampled at {} scattered points with \
         noise of at most {NOISE} cm along the normal and triangulated by Delaunay in the x-z \
         plane (crates/pdeshape/benches/tools/face_scan.rs). Units: cm.",
        vertices.len()
    );
    for v in &vertices {
        let _ = writeln!(out, "v {:.6} {:.6} {:.6}", v.x, v.y, v.z);
    }
    for t in &triangles {
        let _ = writeln!(out, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    std::fs::write(&args[2], out).map_err(|e| e.to_string())?;
    eprintln!(
        "wrote {}: {} vertices, {} triangles",
        args[2],
        vertices.len(),
        triangles.len()
    );
    Ok(())
}
