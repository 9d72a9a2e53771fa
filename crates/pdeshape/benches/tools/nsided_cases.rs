//! pdeshape's side of the n-sided peer comparison (`bench/peers/network_cases.py` writes the
//! cases, `bench/peers/occ_fill.py` runs OpenCascade on them): for every case file given, the
//! sides become natural cubic splines through the case's points (chord-length parameters, like
//! an interpolating B-spline), each side with normals becomes a tangent-plane ribbon (the
//! normals interpolated by the same spline and normalised), and the patch is solved at degree
//! 12 (order 2). Printed per case, as one JSON line: the boundary deviation (largest distance
//! from the case's points to the patch at their parameters), the G1 angle (largest angle
//! between the patch's normal there and the case's normal, corners excluded), the distance to
//! the truth surface over a 25 × 25 grid of every piece (max and RMS), and the solve time
//! (median and minimum of `--repeat` runs; `first` includes building the cached Galerkin
//! operator, `again` is an edit's re-solve).
//!
//! usage: `cargo bench -p pdeshape --bench nsided_cases -- CASE.json… [--repeat K]`

use pdeshape::curve::{Curve, Domain, SharedCurve};
use pdeshape::nsided::{NSidedOptions, NSidedPatch, Ribbon, Side};
use pdeshape::surface::Surface;
use pdeshape::Vec3;
use serde_json::Value;
use std::sync::Arc;
use std::time::Instant;

/// A cubic spline through `points` at chord-length parameters on `[0, 1]`, clamped at each end
/// to the slope of the cubic through the four nearest points (so tangents are `O(h³)`
/// accurate up to the ends, where a natural spline's would be `O(h)` off).
#[derive(Debug)]
struct Clamped {
    t: Vec<f64>,
    p: Vec<Vec3>,
    /// Second derivatives at the knots.
    m: Vec<Vec3>,
}

impl Clamped {
    fn new(p: Vec<Vec3>, t: Vec<f64>) -> Clamped {
        let n = p.len();
        // Tridiagonal system for the second derivatives with clamped ends.
        let mut a = vec![0.0; n];
        let mut b = vec![1.0; n];
        let mut c = vec![0.0; n];
        let mut r = vec![Vec3::zeros(); n];
        let lagrange_slope = |idx: [usize; 4], at: usize| {
            let mut d = Vec3::zeros();
            for &j in &idx {
                let mut w = 0.0;
                for &k in idx.iter().filter(|&&k| k != j) {
                    let mut prod = 1.0 / (t[j] - t[k]);
                    for &l in idx.iter().filter(|&&l| l != j && l != k) {
                        prod *= (t[at] - t[l]) / (t[j] - t[l]);
                    }
                    w += prod;
                }
                d += p[j] * w;
            }
            d
        };
        let (d0, d1) = (
            lagrange_slope([0, 1, 2, 3], 0),
            lagrange_slope([n - 4, n - 3, n - 2, n - 1], n - 1),
        );
        let (h0, hn) = (t[1] - t[0], t[n - 1] - t[n - 2]);
        b[0] = 2.0 * h0;
        c[0] = h0;
        r[0] = ((p[1] - p[0]) / h0 - d0) * 6.0;
        a[n - 1] = hn;
        b[n - 1] = 2.0 * hn;
        r[n - 1] = (d1 - (p[n - 1] - p[n - 2]) / hn) * 6.0;
        for i in 1..n - 1 {
            let (h0, h1) = (t[i] - t[i - 1], t[i + 1] - t[i]);
            a[i] = h0;
            b[i] = 2.0 * (h0 + h1);
            c[i] = h1;
            r[i] = ((p[i + 1] - p[i]) / h1 - (p[i] - p[i - 1]) / h0) * 6.0;
        }
        for i in 1..n {
            let w = a[i] / b[i - 1];
            b[i] -= w * c[i - 1];
            r[i] = r[i] - r[i - 1] * w;
        }
        let mut m = vec![Vec3::zeros(); n];
        m[n - 1] = r[n - 1] / b[n - 1];
        for i in (0..n - 1).rev() {
            m[i] = (r[i] - m[i + 1] * c[i]) / b[i];
        }
        Clamped { t, p, m }
    }
}

impl Curve for Clamped {
    fn domain(&self) -> Domain {
        Domain::Interval(0.0, 1.0)
    }
    fn jet(&self, s: f64, out: &mut [Vec3]) {
        let n = self.t.len();
        let i = self.t.partition_point(|&x| x <= s).clamp(1, n - 1) - 1;
        let h = self.t[i + 1] - self.t[i];
        let x = s - self.t[i];
        let (p0, p1, m0, m1) = (self.p[i], self.p[i + 1], self.m[i], self.m[i + 1]);
        let slope = (p1 - p0) / h - (m0 * 2.0 + m1) * (h / 6.0);
        for (k, o) in out.iter_mut().enumerate() {
            *o = match k {
                0 => p0 + slope * x + m0 * (x * x / 2.0) + (m1 - m0) * (x * x * x / (6.0 * h)),
                1 => slope + m0 * x + (m1 - m0) * (x * x / (2.0 * h)),
                2 => m0 + (m1 - m0) * (x / h),
                3 => (m1 - m0) / h,
                _ => Vec3::zeros(),
            };
        }
    }
}

fn vec3(v: &Value) -> Vec3 {
    let a: Vec<f64> = v
        .as_array()
        .expect("a point")
        .iter()
        .map(|x| x.as_f64().expect("a number"))
        .collect();
    Vec3::new(a[0], a[1], a[2])
}

fn chord_params(p: &[Vec3]) -> Vec<f64> {
    let mut t = vec![0.0];
    for w in p.windows(2) {
        t.push(t.last().unwrap() + (w[1] - w[0]).norm());
    }
    let total = *t.last().unwrap();
    t.iter().map(|x| x / total).collect()
}

/// Distance from `x` to the truth surface.
fn truth_distance(truth: &Value, x: Vec3) -> f64 {
    match truth["type"].as_str() {
        Some("sphere") => {
            ((x - vec3(&truth["center"])).norm() - truth["radius"].as_f64().unwrap()).abs()
        }
        Some("plane") => (x - vec3(&truth["point"]))
            .dot(&vec3(&truth["normal"]).normalize())
            .abs(),
        Some("cylinder") => {
            let (c, d) = (
                vec3(&truth["axis_point"]),
                vec3(&truth["axis_dir"]).normalize(),
            );
            let r = x - c;
            ((r - d * r.dot(&d)).norm() - truth["radius"].as_f64().unwrap()).abs()
        }
        _ => f64::NAN,
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| a != "--bench")
        .collect();
    let mut repeat = 5;
    let mut files = Vec::new();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        if a == "--repeat" {
            repeat = it.next().and_then(|k| k.parse().ok()).expect("--repeat K");
        } else {
            files.push(a.clone());
        }
    }
    for file in files {
        let case: Value = serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
        let mut sides = Vec::new();
        let mut data = Vec::new();
        for side in case["sides"].as_array().unwrap() {
            let pts: Vec<Vec3> = side["points"]
                .as_array()
                .unwrap()
                .iter()
                .map(vec3)
                .collect();
            let t = chord_params(&pts);
            let curve: SharedCurve = Arc::new(Clamped::new(pts.clone(), t.clone()));
            let normals: Option<Vec<Vec3>> = side["normals"]
                .as_array()
                .map(|ns| ns.iter().map(vec3).collect());
            let ribbon = match &normals {
                Some(ns) => {
                    let spline = Clamped::new(ns.clone(), t.clone());
                    Ribbon::TangentPlane(Arc::new(move |s| spline.point(s).normalize()))
                }
                None => Ribbon::Position,
            };
            sides.push(Side {
                curve,
                t0: 0.0,
                t1: 1.0,
                ribbon,
            });
            data.push((pts, t, normals));
        }
        let opts = NSidedOptions::default();
        let mut first = Vec::new();
        let mut again = Vec::new();
        let mut patch = None;
        for r in 0..repeat {
            // A different degree on every first run forces a fresh operator.
            let o = NSidedOptions {
                degree: 13 + r % 12,
                ..opts.clone()
            };
            let start = Instant::now();
            let p = NSidedPatch::solve(sides.clone(), &o).unwrap();
            first.push(start.elapsed().as_secs_f64());
            std::hint::black_box(p);
            let start = Instant::now();
            let p = NSidedPatch::solve(sides.clone(), &opts).unwrap();
            again.push(start.elapsed().as_secs_f64());
            patch = Some(p);
        }
        let patch = Arc::new(patch.unwrap());
        let (mut boundary, mut g1) = (0.0f64, 0.0f64);
        for (i, (pts, t, normals)) in data.iter().enumerate() {
            for (j, (p, s)) in pts.iter().zip(t).enumerate() {
                if j == 0 || j + 1 == pts.len() {
                    continue;
                }
                let (x, n) = patch.boundary_normal(i, *s);
                boundary = boundary.max((x - p).norm());
                if let Some(ns) = normals {
                    let m = ns[j];
                    g1 = g1.max(n.cross(&m).norm().atan2(n.dot(&m).abs()));
                }
            }
        }
        let (mut worst, mut sum, mut count) = (0.0f64, 0.0, 0usize);
        for s in patch.surfaces() {
            for i in 0..=24 {
                for j in 0..=24 {
                    let d =
                        truth_distance(&case["truth"], s.point(i as f64 / 24.0, j as f64 / 24.0));
                    worst = worst.max(d);
                    sum += d * d;
                    count += 1;
                }
            }
        }
        println!(
            "{}",
            serde_json::json!({
                "case": case["name"],
                "boundary": boundary,
                "g1": g1,
                "truth_max": worst,
                "truth_rms": (sum / count as f64).sqrt(),
                "first_median_s": median(first.clone()),
                "again_median_s": median(again.clone()),
                "again_min_s": again.iter().cloned().fold(f64::INFINITY, f64::min),
            })
        );
    }
}
