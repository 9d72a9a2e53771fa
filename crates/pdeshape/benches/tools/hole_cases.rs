//! pdeshape's side of the hole-filling peer comparison (`bench/peers/hole_cases.py` writes the
//! cases, `igl_hole_fill.py` and `cgal_hole_fill.py` run libigl and CGAL on them): every mesh
//! given (OBJ of the unit sphere with holes) is filled at G1 and G2, and printed per case and
//! continuity as one JSON line with the peers' fields: the fill's wall time (median and minimum
//! of `--repeat` runs of `fill_holes`, reading excluded), the new vertices' distance from the
//! unit sphere (max and RMS), the normal jump at the boundary vertices (max and RMS: the angle
//! between the area-weighted normals of the fill's and the mesh's triangles there), the G1
//! angle of the continuous patch, the counts, and whether the result is watertight.
//!
//! usage: `cargo bench -p pdeshape --bench hole_cases -- MESH.obj… [--repeat K]`

use pdeshape::fill::{fill_holes, Continuity, FillOptions};
use pdeshape::fit::{InputMesh, MeshFormat};
use std::time::Instant;

fn main() {
    let mut files = Vec::new();
    let mut repeat = 5usize;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--repeat" => repeat = args.next().and_then(|v| v.parse().ok()).unwrap_or(5),
            "--bench" => {}
            _ => files.push(a),
        }
    }
    for path in files {
        let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
        let mesh =
            InputMesh::read(&bytes, MeshFormat::Obj).unwrap_or_else(|e| panic!("{path}: {e}"));
        let case = std::path::Path::new(&path)
            .file_stem()
            .map(|s| s.to_string_lossy().to_string())
            .unwrap_or_default();
        for (name, continuity) in [("G1", Continuity::G1), ("G2", Continuity::G2)] {
            let options = FillOptions {
                continuity,
                ..FillOptions::default()
            };
            let mut times = Vec::with_capacity(repeat);
            let mut filled = None;
            for _ in 0..repeat.max(1) {
                let t = Instant::now();
                let f = fill_holes(&mesh, &options).unwrap_or_else(|e| panic!("{path}: {e}"));
                times.push(t.elapsed().as_secs_f64());
                filled = Some(f);
            }
            let filled = filled.expect("one run");
            times.sort_by(f64::total_cmp);
            let new = &filled.positions[mesh.positions.len()..];
            let dev: Vec<f64> = new.iter().map(|p| (p.norm() - 1.0).abs()).collect();
            let dev_max = dev.iter().copied().fold(0.0, f64::max);
            let dev_rms = (dev.iter().map(|d| d * d).sum::<f64>() / dev.len().max(1) as f64).sqrt();
            let h = &filled.holes[0];
            println!(
                "{{\"case\": \"{case}\", \"peer\": \"pdeshape fill\", \"setting\": \"{name}\", \
                 \"boundary_vertices\": {}, \"new_vertices\": {}, \"new_faces\": {}, \
                 \"fill_median_s\": {:e}, \"fill_min_s\": {:e}, \"truth_dev_max\": {dev_max:e}, \
                 \"truth_dev_rms\": {dev_rms:e}, \"normal_jump_max\": {:e}, \
                 \"normal_jump_rms\": {:e}, \"g1_angle\": {:e}, \"open_edges\": {}}}",
                h.boundary_vertices,
                h.vertices_added,
                h.triangles_added,
                times[times.len() / 2],
                times[0],
                h.normal_jump.0,
                h.normal_jump.1,
                h.g1_angle,
                filled.open_edges
            );
        }
    }
}
