//! The face example's expressions and the re-targeting of its motion onto the scan
//! (`examples/anim/face.toml`, `examples/anim/face_scan.obj`).

use super::*;
use crate::design::compile;
use crate::spec::time::{parse_timed, TimedDesign};
use crate::spec::DesignSpec;
use std::f64::consts::PI;

const FACE: &str = include_str!("../../../../../examples/anim/face.toml");
const SCAN: &[u8] = include_bytes!("../../../../../examples/anim/face_scan.obj");

fn face() -> TimedDesign {
    parse_timed(FACE).unwrap()
}

/// The face with its expression curves replaced by the profiles they edit: the neutral face,
/// written without any expression.
fn neutral(d: &TimedDesign) -> DesignSpec {
    let mut s = d.at(0.0).unwrap();
    for (edited, base) in [("mouth_expr", "mouth"), ("brow_expr", "brow")] {
        let c = s.curves[base].clone();
        s.curves.insert(edited.to_string(), c);
    }
    s
}

/// Points of every surface on a 13 × 97 grid.
fn grid_points(s: &SolvedDesign) -> Vec<Vec<Vec3>> {
    s.surfaces
        .iter()
        .map(|f| {
            (0..13)
                .flat_map(|i| (0..97).map(move |j| (i as f64 / 12.0, 2.0 * PI * j as f64 / 96.0)))
                .map(|(u, v)| f.surface().point(u, v))
                .collect()
        })
        .collect()
}

fn weights(d: &TimedDesign, t: f64) -> [f64; 3] {
    let values = d.values(t).unwrap();
    let names = ["w_smile", "w_frown", "w_raise"];
    let k = |n: &str| {
        let mut keys: Vec<&String> = d.time.params.keys().collect();
        keys.sort();
        1 + keys.iter().position(|k| k.as_str() == n).unwrap()
    };
    names.map(|n| values[k(n)])
}

#[test]
fn zero_weights_give_the_neutral_face_exactly() {
    let d = face();
    let reference = grid_points(compile(&neutral(&d)).unwrap().solved());
    for t in [0.0, 2.0, 4.0] {
        assert_eq!(weights(&d, t), [0.0; 3], "t = {t}");
        let at = grid_points(compile(&d.at(t).unwrap()).unwrap().solved());
        assert!(at == reference, "t = {t}: differs from the neutral face");
    }
    // And an expression at full weight does differ.
    assert_eq!(weights(&d, 1.0), [1.0, 0.0, 0.0]);
    let smile = grid_points(compile(&d.at(1.0).unwrap()).unwrap().solved());
    assert!(smile != reference);
}

/// Displacements of every grid point between the neutral face and the face at `t`: per
/// surface, (u, v, |ΔX|, ΔX).
fn moves(d: &TimedDesign, t: f64) -> Vec<Vec<(f64, f64, Vec3)>> {
    let n = compile(&neutral(d)).unwrap();
    let e = compile(&d.at(t).unwrap()).unwrap();
    n.solved()
        .surfaces
        .iter()
        .zip(&e.solved().surfaces)
        .map(|(a, b)| {
            (0..=24)
                .flat_map(|i| {
                    (0..=360).map(move |j| (i as f64 / 24.0, 2.0 * PI * j as f64 / 360.0))
                })
                .map(|(u, v)| (u, v, b.surface().point(u, v) - a.surface().point(u, v)))
                .collect()
        })
        .collect()
}

/// The largest displacement over the points of `m` whose v lies outside `[lo, hi]`, and over
/// all points.
fn outside_and_peak(m: &[Vec<(f64, f64, Vec3)>], lo: f64, hi: f64) -> (f64, f64) {
    let mut out: f64 = 0.0;
    let mut peak: f64 = 0.0;
    for &(_, v, dx) in m.iter().flatten() {
        peak = peak.max(dx.norm());
        if v < lo || v > hi {
            out = out.max(dx.norm());
        }
    }
    (out, peak)
}

/// Each expression moves its own curves by the amounts of the design file, leaves the patches
/// that do not use them unchanged bit for bit, and moves the rest of the face little away from
/// the edited parts of the profiles: beyond 0.35 rad (about 2.3 cm on the mouth) outside the
/// interval of the edit, less than a tenth of the largest displacement. With a = 0.1 the
/// patches couple the values of v weakly (∂uu dominates the operator), so a profile's local
/// edit stays local on the surface; a tenth is a bound on that, not the measured value.
#[test]
fn each_expression_moves_only_its_neighbourhood() {
    let d = face();
    let (jaw, nose, brow) = (0, 1, 2);
    // The smile: the left mouth corner (jaw at u = 1, v = 2.7301) up by 0.9, back by 0.3.
    let m = moves(&d, 1.0);
    assert!(m[brow].iter().all(|p| p.2 == Vec3::zeros()));
    let n = compile(&neutral(&d)).unwrap();
    let e = compile(&d.at(1.0).unwrap()).unwrap();
    let dx = e.solved().surfaces[jaw].surface().point(1.0, 2.7301)
        - n.solved().surfaces[jaw].surface().point(1.0, 2.7301);
    // Up by 0.9; back by 0.3 across the chord of the edit (horizontal, mostly +y).
    assert!((dx.z - 0.9).abs() < 1e-9, "{dx:?}");
    assert!(
        (dx.x.hypot(dx.y) - 0.3).abs() < 1e-9 && dx.y > 0.25,
        "{dx:?}"
    );
    // The right corner (v = 3.5531, outside the edit) stays where it was.
    let dr = e.solved().surfaces[jaw].surface().point(1.0, 3.5531)
        - n.solved().surfaces[jaw].surface().point(1.0, 3.5531);
    assert!(dr.norm() < 1e-9, "{dr:?}");
    let (out, peak) = outside_and_peak(&m, 2.30 - 0.35, 3.15 + 0.35);
    eprintln!("smile: {out:.4} outside, peak {peak:.4}");
    assert!(out < 0.1 * peak, "smile: {out} outside, peak {peak}");
    // The frown: mouth corners down by 0.6, inner brows down by 0.5.
    let m = moves(&d, 3.0);
    let (out, peak) = outside_and_peak(&m, 2.30 - 0.35, 3.98 + 0.35);
    eprintln!("frown: {out:.4} outside, peak {peak:.4}");
    assert!(out < 0.1 * peak, "frown: {out} outside, peak {peak}");
    let e = compile(&d.at(3.0).unwrap()).unwrap();
    for (s, u, v, dz) in [
        (jaw, 1.0, 2.7301, -0.6),
        (nose, 0.0, 3.5531, -0.6),
        (brow, 0.6667, PI, -0.5),
    ] {
        let dx = e.solved().surfaces[s].surface().point(u, v)
            - n.solved().surfaces[s].surface().point(u, v);
        assert!((dx.z - dz).abs() < 1e-9, "frown at {s} {u} {v}: {dx:?}");
    }
    // The eyebrow raise: only the brow patch moves; the right brow up by 0.9, the left not.
    let m = moves(&d, 5.0);
    assert!(m[jaw].iter().chain(&m[nose]).all(|p| p.2 == Vec3::zeros()));
    let (out, peak) = outside_and_peak(&m, 3.10 - 0.35, 4.05 + 0.35);
    eprintln!("raise: {out:.4} outside, peak {peak:.4}");
    assert!(out < 0.1 * peak, "raise: {out} outside, peak {peak}");
    let e = compile(&d.at(5.0).unwrap()).unwrap();
    let up = e.solved().surfaces[brow].surface().point(0.6667, 3.5738)
        - n.solved().surfaces[brow].surface().point(0.6667, 3.5738);
    assert!((up.z - 0.9).abs() < 1e-9, "{up:?}");
    let left = e.solved().surfaces[brow].surface().point(0.6667, 2.7093)
        - n.solved().surfaces[brow].surface().point(0.6667, 2.7093);
    assert!(left.norm() < 1e-9, "{left:?}");
}

/// Points at a known distance along the normal of a surface are anchored at that distance to
/// the point they were pushed from.
#[test]
fn anchors_find_the_foot_points_of_offset_points() {
    let d = face();
    let c = compile(&d.at(0.0).unwrap()).unwrap();
    let s = c.solved();
    let mut points = Vec::new();
    let mut feet = Vec::new();
    for (k, (u, v)) in [(0.3, 2.9), (0.5, 3.3), (0.7, 3.0), (0.45, 3.6)]
        .into_iter()
        .enumerate()
    {
        let p = s.surfaces[1].surface().partials(u, v);
        let h = 0.01 * (k as f64 + 1.0);
        points.push(p.x + p.normal() * h);
        feet.push((p.x, h));
    }
    let c = Correspondence::new(s, &points).unwrap();
    for (a, (x, h)) in c.anchors.iter().zip(feet) {
        assert_eq!(a.surface, 1);
        assert!((a.distance - h).abs() < 1e-9, "{} vs {h}", a.distance);
        assert!((a.foot - x).norm() < 1e-7, "{:?}", a.foot - x);
    }
}

fn scan() -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let m = crate::fit::InputMesh::read(SCAN, crate::fit::MeshFormat::Obj).unwrap();
    (m.positions, m.triangles)
}

/// The two checks: at every frame the moved scan lies within the correspondence's
/// distance of the animated face (each vertex's distance to the frame's surfaces, by closest
/// point, is at most its anchor's distance; the margin 10⁻⁹ cm is rounding), and a frame whose
/// weights are all zero gives the scan back bit for bit.
#[test]
fn retargeted_scan_follows_the_face() {
    let d = face();
    let (points, triangles) = scan();
    assert!(points.len() > 4000, "{} vertices", points.len());
    let c0 = compile(&d.at(0.0).unwrap()).unwrap();
    let mut r = Retarget::new(c0.solved(), &points, triangles, &d.time).unwrap();
    // The scan is the face with noise of 0.02 cm: the anchors say so.
    let worst = r.correspondence.max_distance();
    assert!(worst <= 0.0201 && worst > 0.01, "{worst}");
    let times = d.time.times().unwrap();
    let opts = ClosestOptions::default();
    let mut moved_some = false;
    for (k, &t) in times.iter().enumerate() {
        let c = compile(&d.at(t).unwrap()).unwrap();
        let p = r.push(t, c.solved()).unwrap();
        if weights(&d, t) == [0.0; 3] {
            assert!(
                p.iter().zip(&points).all(|(a, b)| a == b),
                "t = {t}: not the scan bit for bit"
            );
            continue;
        }
        if k % 6 != 3 {
            continue;
        }
        let indices: Vec<_> = c
            .solved()
            .surfaces
            .iter()
            .map(|s| ClosestPointIndex::new(s.surface(), &opts))
            .collect();
        for (q, a) in p.iter().zip(&r.correspondence.anchors).step_by(5) {
            let dist = indices
                .iter()
                .filter_map(|i| i.closest(*q))
                .map(|c| c.distance)
                .fold(f64::INFINITY, f64::min);
            assert!(
                dist <= a.distance + 1e-9,
                "t = {t}: {dist} from the face, anchored at {}",
                a.distance
            );
        }
        moved_some |= p.iter().zip(&points).any(|(a, b)| (a - b).norm() > 0.1);
    }
    assert!(moved_some, "the expressions move the scan");
    assert_eq!(r.keys.positions.len(), times.len());
    assert!(!r.keys.closed);
    // The GLB writer takes the re-targeted frames.
    let mut glb = Vec::new();
    crate::anim::write_glb(&r.keys, &crate::mesh_write::MeshInfo::default(), &mut glb).unwrap();
    assert!(glb.len() > 12 * points.len());
}

#[test]
fn vertex_normals_point_out_of_counter_clockwise_triangles() {
    let p = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        Vec3::new(5.0, 5.0, 5.0),
    ];
    let n = vertex_normals(&p, &[[0, 1, 2]], Vec3::x());
    assert_eq!(n[..3], [Vec3::z(); 3]);
    assert_eq!(n[3], Vec3::x());
}
