//! The packed size of a fit: how many bytes its numbers need once quantised to what the
//! tolerance allows, beside the TOML text and the plain `f64` count.
//!
//! Only the `[[patchwork]]` tables of the general mode are quantised (the tube and sheet
//! modes write a few hundred numbers, counted at 8 bytes each). A patchwork's numbers are
//! stored without the ones its other numbers determine:
//!
//! - corners: each coordinate an integer multiple of the step `s`, stored as its offset from
//!   the smallest in `⌈log₂(range/s + 1)⌉` bits, one width for the table, the smallest value and
//!   the width in the header;
//! - corner normals (directions only): octahedral coordinates (the unit sphere unfolded onto
//!   the square `|x| + |y| ≤ 1` and its folded corners), two integers of `b` bits;
//! - edge tangents: a fit's lie in their corners' tangent planes, so each is two coordinates in
//!   a frame of the plane of the *decoded* corner normal (`plane_frame`), multiples of `s` in
//!   one table as the corners are (three coordinates each when some tangent leaves its plane);
//! - an edge's inner normal samples: the design makes each normal to the curve
//!   (`design/patchwork.rs`), so each is one angle about the decoded curve's tangent, from the
//!   decoded corner normals blended linearly along the edge and made normal to the curve, in
//!   `b + 2` bits over the full turn;
//! - an edge's own end normals (`end_normals`, at sharp features): a flag bit per edge, and two
//!   octahedral normals of `2b` bits each where it is set; the edge's tangents and samples are
//!   then taken in the planes of those normals;
//! - connectivity: a face's side count in 3 bits and its corners in `⌈log₂ V⌉` bits each; an
//!   edge's sample count in 5 bits and its crease flag in 1; its ends only when some edge is
//!   no face's side (otherwise the edges are stored in the order and direction in which the
//!   faces' sides first appear, a reversed edge's tangents swapped and negated, exactly);
//! - the name, the counts, `order`, `a`, `degree`, `b` and two flags in a header of whole bytes.
//!
//! [`pack`] returns that size with the design as a decoder would restore it (every quantised
//! number replaced by its quantised value), so the cost of quantising is measured, not
//! assumed: [`crate::fit::rate_distortion`] solves and measures it. The step is `s =
//! tolerance · diagonal / 64` ([`STEP_FRACTION`]), or [`GAP_FRACTION`] of the shortest distance
//! between two corners of a face or edge tangent when that is smaller (a corner then moves by at
//! most `√3/16` of that distance, so no two corners of a face become one point and no tangent
//! becomes 0: a layout refined at a spot can have corners far closer than the tolerance). A
//! corner moves by at most `√3 s / 2`; `b = ⌈log₂(diagonal / s)⌉ + 3` keeps a corner normal's
//! angle error (at most `3√2 / (2ᵇ − 1)` rad) times the diagonal below `s`, so a tangent turns
//! with its frame by less than `s` over its length and moves by at most `√2 s / 2` in it; a
//! sample's angle moves by at most `π / 2ᵇ⁺²`. The quantised fit stays within a few steps (a
//! few percent of the tolerance) of the fit. The size is computed, not written: no file
//! format is defined for it.

use super::layout::hermite_tangent;
use crate::spec::{DesignSpec, PatchworkSpec};
use crate::{Error, Result, Vec3};
use pdeshape_geometry::network::{lobatto, normal_to};

/// The step of the lengths as a fraction of `tolerance · diagonal`.
pub const STEP_FRACTION: f64 = 1.0 / 64.0;

/// The largest step as a fraction of the shortest distance between two corners of a face or
/// edge tangent.
pub(super) const GAP_FRACTION: f64 = 1.0 / 8.0;

/// A fit's numbers, quantised.
#[derive(Clone, Debug)]
pub struct Packed {
    /// The size in bytes of the packed numbers (module documentation).
    pub bytes: usize,
    /// The design with every quantised number replaced by its quantised value.
    pub spec: DesignSpec,
    /// The step of the lengths.
    pub step: f64,
    /// The step was shortened below the tolerance's by the shortest corner distance or tangent.
    pub step_by_corners: bool,
    /// Bits per octahedral coordinate of a normal (0 when nothing was quantised).
    pub normal_bits: u32,
}

impl Packed {
    /// The quantisation in words, for reports.
    pub fn describe(&self) -> String {
        if self.normal_bits == 0 {
            "8 bytes per number".to_string()
        } else {
            format!(
                "lengths to a step of {} ({}), normals in 2 × {} bits",
                crate::number::sig(self.step, 3),
                if self.step_by_corners {
                    "1/8 of the shortest corner distance or tangent"
                } else {
                    "1/64 of the tolerance"
                },
                self.normal_bits
            )
        }
    }
}

/// Bits for the integers `0 ..= max`.
pub(super) fn bits_for(max: u64) -> u32 {
    64 - max.leading_zeros()
}

/// Lengths quantised to multiples of `step` in one table: `(bits, header bytes, the values)`.
fn lengths(values: &[f64], step: f64) -> (u64, usize, Vec<f64>) {
    if values.is_empty() {
        return (0, 0, Vec::new());
    }
    let q: Vec<i64> = values.iter().map(|x| (x / step).round() as i64).collect();
    let lo = *q.iter().min().unwrap_or(&0);
    let hi = *q.iter().max().unwrap_or(&0);
    let width = bits_for((hi - lo) as u64) as u64;
    // The smallest multiple as an `i64` and the width as a byte.
    (
        width * q.len() as u64,
        9,
        q.iter().map(|&k| k as f64 * step).collect(),
    )
}

/// The unit vector `n` in octahedral coordinates quantised to `bits` bits each, and back.
fn octahedral(n: [f64; 3], bits: u32) -> [f64; 3] {
    let l1 = n[0].abs() + n[1].abs() + n[2].abs();
    if !(l1 > 0.0 && l1.is_finite()) {
        return n;
    }
    let (mut x, mut y) = (n[0] / l1, n[1] / l1);
    if n[2] < 0.0 {
        (x, y) = ((1.0 - y.abs()) * x.signum(), (1.0 - x.abs()) * y.signum());
    }
    let levels = ((1u64 << bits) - 1) as f64;
    let q = |t: f64| ((t + 1.0) / 2.0 * levels).round() / levels * 2.0 - 1.0;
    let (x, y) = (q(x), q(y));
    let z = 1.0 - x.abs() - y.abs();
    let (x, y) = if z < 0.0 {
        ((1.0 - y.abs()) * x.signum(), (1.0 - x.abs()) * y.signum())
    } else {
        (x, y)
    };
    let l = (x * x + y * y + z * z).sqrt();
    [x / l, y / l, z / l]
}

/// The shortest length the quantisation must keep: the distance between two distinct corners
/// of one face of `p`, or an edge's tangent (infinite for none).
fn shortest_length(p: &PatchworkSpec) -> f64 {
    let norm = |a: &[f64; 3]| (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
    let mut gap = p
        .edges
        .iter()
        .flat_map(|e| e.tangents.iter().map(norm))
        .filter(|&l| l > 0.0)
        .fold(f64::INFINITY, f64::min);
    for face in &p.faces {
        for (k, &i) in face.iter().enumerate() {
            for &j in &face[k + 1..] {
                let (Some(a), Some(b)) = (p.points.get(i), p.points.get(j)) else {
                    continue;
                };
                let d = norm(&[a[0] - b[0], a[1] - b[1], a[2] - b[2]]);
                if d > 0.0 {
                    gap = gap.min(d);
                }
            }
        }
    }
    gap
}

/// An orthonormal pair spanning the plane normal to the unit vector `n`, the same for the same
/// `n` (the encoder's and a decoder's frame of a corner's tangents).
fn plane_frame(n: Vec3) -> (Vec3, Vec3) {
    let e1 = normal_to(
        n,
        if n.x.abs() < 0.9 {
            Vec3::x()
        } else {
            Vec3::y()
        },
    );
    (e1, n.cross(&e1))
}

/// The normal of edge `e` of `p` at its end `k`: the edge's own (`end_normals`) or its corner's.
fn end_normal(p: &PatchworkSpec, e: usize, k: usize) -> Vec3 {
    let edge = &p.edges[e];
    vec3(edge.end_normals.map_or(p.normals[edge.ends[k]], |n| n[k]))
}

/// Whether every edge tangent of `p` lies in its end's tangent plane (to rounding), as a fit's
/// do by construction.
fn tangents_in_planes(p: &PatchworkSpec) -> bool {
    (0..p.edges.len()).all(|e| {
        (0..2).all(|k| {
            let (n, t) = (end_normal(p, e, k), vec3(p.edges[e].tangents[k]));
            n.dot(&t).abs() <= 1e-9 * n.norm() * t.norm()
        })
    })
}

/// Whether every edge of `p` is a side of some face (its ends and direction then follow from
/// the faces' corner loops: the order and direction in which the sides first appear).
fn edges_from_faces(p: &PatchworkSpec) -> bool {
    let mut sides = std::collections::HashSet::new();
    for f in &p.faces {
        for (k, &a) in f.iter().enumerate() {
            let b = f[(k + 1) % f.len()];
            sides.insert((a.min(b), a.max(b)));
        }
    }
    p.edges
        .iter()
        .all(|e| sides.contains(&(e.ends[0].min(e.ends[1]), e.ends[0].max(e.ends[1]))))
}

fn vec3(a: [f64; 3]) -> Vec3 {
    Vec3::new(a[0], a[1], a[2])
}

/// One patchwork quantised (module documentation): `(bits, header bytes)`, the table changed
/// in place to what a decoder restores.
fn pack_patchwork(p: &mut PatchworkSpec, step: f64, normal_bits: u32) -> (u64, usize) {
    let in_planes = tangents_in_planes(p);
    let implied = edges_from_faces(p);
    let flat: Vec<f64> = p.points.iter().flatten().copied().collect();
    let (mut bits, mut header, q) = lengths(&flat, step);
    for (k, x) in q.into_iter().enumerate() {
        p.points[k / 3][k % 3] = x;
    }
    for n in p.normals.iter_mut() {
        *n = octahedral(*n, normal_bits);
        bits += 2 * normal_bits as u64;
    }
    // An edge's own end normals (at sharp features): a flag, and two normals when set.
    for e in p.edges.iter_mut() {
        bits += 1;
        if let Some(ns) = e.end_normals.as_mut() {
            for n in ns.iter_mut() {
                *n = octahedral(*n, normal_bits);
                bits += 2 * normal_bits as u64;
            }
        }
    }
    // Tangents: two coordinates in the plane of the decoded end normal, or three.
    let ends: Vec<(usize, usize)> = (0..p.edges.len())
        .flat_map(|e| (0..2).map(move |k| (e, k)))
        .collect();
    if in_planes {
        let mut flat = Vec::with_capacity(2 * ends.len());
        for &(e, k) in &ends {
            let (e1, e2) = plane_frame(end_normal(p, e, k));
            let t = vec3(p.edges[e].tangents[k]);
            flat.extend([t.dot(&e1), t.dot(&e2)]);
        }
        let (b, h, q) = lengths(&flat, step);
        bits += b;
        header += h;
        for (i, &(e, k)) in ends.iter().enumerate() {
            let (e1, e2) = plane_frame(end_normal(p, e, k));
            let t = e1 * q[2 * i] + e2 * q[2 * i + 1];
            p.edges[e].tangents[k] = [t.x, t.y, t.z];
        }
    } else {
        let flat: Vec<f64> = p
            .edges
            .iter()
            .flat_map(|e| e.tangents.iter().flatten().copied())
            .collect();
        let (b, h, q) = lengths(&flat, step);
        bits += b;
        header += h;
        for (k, x) in q.into_iter().enumerate() {
            p.edges[k / 6].tangents[(k / 3) % 2][k % 3] = x;
        }
    }
    // An edge's inner normals: one angle each about the decoded curve's tangent, from the
    // end normals blended linearly and made normal to the curve.
    let angle_bits = normal_bits + 2;
    let levels = (1u64 << angle_bits) as f64;
    for i in 0..p.edges.len() {
        let (na, nb) = (end_normal(p, i, 0), end_normal(p, i, 1));
        let e = &mut p.edges[i];
        let [a, b] = e.ends;
        let (p0, p1) = (vec3(p.points[a]), vec3(p.points[b]));
        let (d0, d1) = (vec3(e.tangents[0]), vec3(e.tangents[1]));
        let m = e.normals.len() + 1;
        for (j, n) in e.normals.iter_mut().enumerate() {
            let s = lobatto(j + 1, m);
            let t = hermite_tangent(p0, p1, d0, d1, s);
            let t = if t.norm() > 0.0 {
                t.normalize()
            } else {
                (p1 - p0).normalize()
            };
            let f1 = normal_to(t, na * (1.0 - s) + nb * s);
            let f2 = t.cross(&f1);
            let v = vec3(*n);
            let turn = v.dot(&f2).atan2(v.dot(&f1));
            let k = (turn / std::f64::consts::TAU * levels).round();
            let turn = k / levels * std::f64::consts::TAU;
            let q = f1 * turn.cos() + f2 * turn.sin();
            *n = [q.x, q.y, q.z];
            bits += angle_bits as u64;
        }
    }
    let index = bits_for(p.points.len().saturating_sub(1) as u64).max(1) as u64;
    // Per edge its sample count (5 bits) and crease flag; its ends when the faces do not give
    // them.
    bits += p.edges.len() as u64 * (5 + 1 + if implied { 0 } else { 2 * index });
    for f in &p.faces {
        bits += 3 + index * f.len() as u64;
    }
    // Name, three counts, order, a, degree, the normals' width and the two flags.
    header += p.name.len() + 1 + 3 * 4 + 1 + 8 + 1 + 1 + 1;
    (bits, header)
}

/// The numbers of `spec` (a fit of a mesh whose bounding box has the diagonal `diagonal`)
/// packed for `tolerance` (module documentation).
pub fn pack(spec: &DesignSpec, diagonal: f64, tolerance: f64) -> Result<Packed> {
    let by_tolerance = tolerance * diagonal * STEP_FRACTION;
    let by_corners = GAP_FRACTION
        * spec
            .patchwork
            .iter()
            .map(shortest_length)
            .fold(f64::INFINITY, f64::min);
    let step = by_tolerance.min(by_corners);
    if !(step > 0.0 && step.is_finite()) {
        return Err(Error::invalid(format!(
            "no quantisation step for the tolerance {tolerance} and the diagonal {diagonal}"
        )));
    }
    let mut out = spec.clone();
    let mut patchworks = std::mem::take(&mut out.patchwork);
    let rest = super::measure::count_numbers(&out);
    let normal_bits = if patchworks.is_empty() {
        0
    } else {
        ((diagonal / step).log2().ceil() as u32 + 3).clamp(4, 30)
    };
    let (mut bits, mut header) = (0u64, 0usize);
    for p in patchworks.iter_mut() {
        let (b, h) = pack_patchwork(p, step, normal_bits);
        bits += b;
        header += h;
    }
    out.patchwork = patchworks;
    Ok(Packed {
        bytes: 8 * rest + header + bits.div_ceil(8) as usize,
        spec: out,
        step,
        step_by_corners: by_corners < by_tolerance,
        normal_bits,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::spec::PatchworkEdgeSpec;

    /// One flat quadrilateral face (normal +z) on `points`, each edge a straight Hermite curve
    /// (chord tangents) with normal samples turned about it by `turns`.
    fn quad(points: &[[f64; 3]; 4], turns: &[f64]) -> DesignSpec {
        let edge = |a: usize, b: usize| {
            let c: [f64; 3] = std::array::from_fn(|k| points[b][k] - points[a][k]);
            let side = Vec3::new(-c[1], c[0], 0.0).normalize();
            let normals = turns
                .iter()
                .map(|&w| {
                    let n = Vec3::z() * w.cos() + side * w.sin();
                    [n.x, n.y, n.z]
                })
                .collect();
            PatchworkEdgeSpec {
                ends: [a, b],
                tangents: [c, c],
                normals,
                crease: false,
                end_normals: None,
            }
        };
        DesignSpec {
            patchwork: vec![PatchworkSpec {
                name: "quad".to_string(),
                order: 2,
                a: 1.0,
                degree: 6,
                points: points.to_vec(),
                normals: vec![[0.0, 0.0, 1.0]; 4],
                edges: vec![edge(0, 1), edge(1, 2), edge(2, 3), edge(3, 0)],
                faces: vec![vec![0, 1, 2, 3]],
            }],
            ..DesignSpec::default()
        }
    }

    #[test]
    fn octahedral_coordinates_keep_directions_to_their_resolution() {
        // Directions on every octant, near the poles and the folds.
        let mut worst: f64 = 0.0;
        for i in 0..40 {
            for j in 0..80 {
                let th = std::f64::consts::PI * (i as f64 + 0.5) / 40.0;
                let ph = std::f64::consts::TAU * j as f64 / 80.0;
                let n = [th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()];
                let m = octahedral(n, 12);
                let l = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
                assert!((l - 1.0).abs() < 1e-15);
                let dot = n[0] * m[0] + n[1] * m[1] + n[2] * m[2];
                worst = worst.max(dot.min(1.0).acos());
            }
        }
        // The bound of the module documentation: 3√2 / (2¹² − 1) rad.
        assert!(
            worst > 0.0 && worst <= 3.0 * 2f64.sqrt() / 4095.0,
            "{worst}"
        );
    }

    #[test]
    fn lengths_are_multiples_of_the_step_within_half_a_step() {
        let v = [0.123456, -3.5, 7.25, 2.0];
        let (bits, _, q) = lengths(&v, 0.01);
        for (a, b) in v.iter().zip(&q) {
            assert!((a - b).abs() <= 0.005 + 1e-15);
            assert!(((b / 0.01).round() * 0.01 - b).abs() < 1e-12);
        }
        // Range 1075 steps: 11 bits each.
        assert_eq!(bits, 4 * 11);
    }

    /// One flat quadrilateral whose first two corners are 10⁻³ apart, packed for a tolerance
    /// whose step (1/64 of 0.5 of the diagonal 1.5: 0.0117) would round both to the origin:
    /// the step is shortened to 1/8 of that distance, the corners stay apart, every number
    /// moves by at most half a step per coordinate, and the packed design solves.
    #[test]
    fn corners_closer_than_the_tolerance_step_stay_apart() {
        let points = [
            [0.0, 0.0, 0.0],
            [1e-3, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let spec = quad(&points, &[]);
        let packed = pack(&spec, 1.5, 0.5).unwrap();
        assert!(packed.step_by_corners);
        assert!((packed.step - 1e-3 / 8.0).abs() < 1e-15, "{}", packed.step);
        assert!(packed.describe().contains("shortest corner distance"));
        let q = &packed.spec.patchwork[0];
        for (a, b) in points.iter().zip(&q.points) {
            for k in 0..3 {
                assert!((a[k] - b[k]).abs() <= packed.step / 2.0 + 1e-15);
            }
        }
        assert!(q.points[0] != q.points[1]);
        crate::design::solve_design(&packed.spec).unwrap();
        // With the tolerance's step the two corners would be one point.
        let coarse = 0.5 * 1.5 * STEP_FRACTION;
        assert_eq!((1e-3 / coarse).round(), 0.0);
    }

    /// A flat square whose edges carry the tilted normal samples a fit gives them (normal to
    /// the edge, turned about it): packed, every tangent stays in its decoded corner's plane
    /// within its half step, every sample within half an angle step of its turn about the
    /// edge, and the size is the module documentation's count, bit by bit. A tangent out of its
    /// plane makes the tangents three coordinates again.
    #[test]
    fn tangents_are_two_coordinates_in_their_planes_and_samples_one_angle() {
        let points = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let spec = quad(&points, &[0.3, -0.2, 0.1]);
        let (diagonal, tolerance) = (2f64.sqrt(), 0.01);
        let packed = pack(&spec, diagonal, tolerance).unwrap();
        let (s, b) = (packed.step, packed.normal_bits as u64);
        assert!(!packed.step_by_corners);
        let q = &packed.spec.patchwork[0];
        let angle_step = std::f64::consts::TAU / (1u64 << (b + 2)) as f64;
        for (e, (orig, got)) in spec.patchwork[0].edges.iter().zip(&q.edges).enumerate() {
            for k in 0..2 {
                let n = vec3(q.normals[got.ends[k]]);
                let t = vec3(got.tangents[k]);
                assert!(n.dot(&t).abs() <= 1e-12 * t.norm(), "edge {e}");
                assert!((t - vec3(orig.tangents[k])).norm() <= s, "edge {e}");
            }
            // The curve's tangent at a sample, before and after: the sample is normal to it,
            // so it turns with it besides its own half step.
            let curve = |p: &PatchworkSpec, e: &PatchworkEdgeSpec, x: f64| {
                let [a, b] = e.ends;
                let (p0, p1) = (vec3(p.points[a]), vec3(p.points[b]));
                hermite_tangent(p0, p1, vec3(e.tangents[0]), vec3(e.tangents[1]), x).normalize()
            };
            for (j, (a, m)) in orig.normals.iter().zip(&got.normals).enumerate() {
                let (a, m) = (vec3(*a), vec3(*m));
                assert!((m.norm() - 1.0).abs() < 1e-12);
                let x = lobatto(j + 1, orig.normals.len() + 1);
                let before = curve(&spec.patchwork[0], orig, x);
                let turned = before.dot(&curve(q, got, x)).clamp(-1.0, 1.0).acos();
                assert!(turned < 1e-3, "edge {e} sample {j}: {turned}");
                let angle = a.dot(&m).clamp(-1.0, 1.0).acos();
                assert!(
                    angle <= angle_step / 2.0 + turned + 1e-12,
                    "edge {e} sample {j}: {angle}"
                );
            }
        }
        // The count: corners (12 coordinates, range 1 in steps of s), 4 normals, 8 tangents of
        // two coordinates (range from −1 to 1), 12 samples, 4 edges of 7 bits (no ends: the
        // face gives them), one face of 3 + 4 · 2 bits.
        let width = |range: f64| bits_for((range / s).round() as u64) as u64;
        let bits = 12 * width(1.0) + 4 * 2 * b + 16 * width(2.0) + 12 * (b + 2) + 4 * 7 + 11;
        let header = 9 + 9 + "quad".len() + 1 + 12 + 1 + 8 + 3;
        assert_eq!(packed.bytes, header + bits.div_ceil(8) as usize);
        // An edge's own end normals (here its corners' own, so its tangents stay in their
        // planes): two more normals of 2 · b bits.
        let mut own = spec.clone();
        let e0 = own.patchwork[0].edges[0].clone();
        let ends = e0.ends.map(|c| own.patchwork[0].normals[c]);
        own.patchwork[0].edges[0].end_normals = Some(ends);
        let more = pack(&own, diagonal, tolerance).unwrap();
        let extra = more.bytes as i64 - packed.bytes as i64;
        assert!((extra * 8 - 4 * b as i64).abs() <= 8, "{extra}");
        // A tangent out of its plane: three coordinates for every tangent (8 more widths).
        let mut tilted = spec.clone();
        tilted.patchwork[0].edges[0].tangents[0][2] = 0.1;
        let more = pack(&tilted, diagonal, tolerance).unwrap();
        let extra = more.bytes as i64 - packed.bytes as i64;
        assert!((extra * 8 - 8 * width(2.0) as i64).abs() <= 8, "{extra}");
        crate::design::solve_design(&packed.spec).unwrap();
    }
}
