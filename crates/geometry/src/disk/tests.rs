use super::*;

/// A closed-form solution `X(r, θ)` with its first two radial derivatives.
type Exact = fn(f64, f64) -> [Vec3; 3];

fn data(s: usize, exact: Exact) -> [Vec<Vec3>; 3] {
    let rows: Vec<[Vec3; 3]> = (0..s)
        .map(|k| exact(1.0, TAU * k as f64 / s as f64))
        .collect();
    std::array::from_fn(|j| rows.iter().map(|r| r[j]).collect())
}

fn worst(patch: &DiskPatch, exact: Exact) -> f64 {
    let mut err: f64 = 0.0;
    for i in 0..=20 {
        for j in 0..37 {
            let (r, t) = (i as f64 / 20.0, 0.3 + TAU * j as f64 / 37.0);
            err = err.max((patch.point(r, t) - exact(r, t)[0]).amax());
        }
    }
    err
}

/// `Δ(r^k e^{imθ}) = (k² − m²) r^{k−2} e^{imθ}`: harmonic `r cos θ, r³ sin 3θ`, biharmonic
/// `r² · r cos θ`, `r⁴ cos 2θ`, `r²`, triharmonic `r⁴ · r sin θ`.
fn harmonic(r: f64, t: f64) -> [Vec3; 3] {
    [
        Vec3::new(r * t.cos(), r.powi(3) * (3.0 * t).sin(), 0.5),
        Vec3::new(t.cos(), 3.0 * r * r * (3.0 * t).sin(), 0.0),
        Vec3::new(0.0, 6.0 * r * (3.0 * t).sin(), 0.0),
    ]
}

fn biharmonic(r: f64, t: f64) -> [Vec3; 3] {
    [
        Vec3::new(
            r * t.cos() + 0.3 * r.powi(3) * t.cos(),
            r.powi(4) * (2.0 * t).cos() - r.powi(3) * (3.0 * t).sin(),
            r * r + r * t.sin(),
        ),
        Vec3::new(
            t.cos() + 0.9 * r * r * t.cos(),
            4.0 * r.powi(3) * (2.0 * t).cos() - 3.0 * r * r * (3.0 * t).sin(),
            2.0 * r + t.sin(),
        ),
        Vec3::new(
            1.8 * r * t.cos(),
            12.0 * r * r * (2.0 * t).cos() - 6.0 * r * (3.0 * t).sin(),
            2.0,
        ),
    ]
}

fn triharmonic(r: f64, t: f64) -> [Vec3; 3] {
    let [x, xr, xrr] = biharmonic(r, t);
    let k = Vec3::new(0.0, 0.0, 0.7 * t.sin());
    [
        x + k * r.powi(5),
        xr + k * (5.0 * r.powi(4)),
        xrr + k * (20.0 * r.powi(3)),
    ]
}

#[test]
fn closed_form_polyharmonic_solutions_are_reproduced_to_rounding() {
    for (order, exact) in [
        (1, harmonic as Exact),
        (2, biharmonic as Exact),
        (3, triharmonic as Exact),
    ] {
        for s in [16usize, 17, 64] {
            let [p, d, e] = data(s, exact);
            let patch = DiskPatch::solve(
                order,
                &DiskData {
                    positions: &p,
                    derivatives: Some(&d),
                    second: Some(&e),
                },
            )
            .unwrap();
            // Largest coordinate about 2: rounding is a few 1e-16 per mode.
            let err = worst(&patch, exact);
            assert!(err < 1e-14, "order {order}, S = {s}: {err:e}");
        }
    }
}

#[test]
fn the_samples_are_met_exactly_and_the_ring_agrees_with_the_partials() {
    // Boundary data with every mode present (random points), order 3.
    let s = 40;
    let mut x = 0.37f64;
    let mut next = || {
        x = (x * 9301.0 + 0.49297).fract();
        x - 0.5
    };
    let mut v = || -> Vec<Vec3> { (0..s).map(|_| Vec3::new(next(), next(), next())).collect() };
    let (p, d, e) = (v(), v(), v());
    let patch = DiskPatch::solve(
        3,
        &DiskData {
            positions: &p,
            derivatives: Some(&d),
            second: Some(&e),
        },
    )
    .unwrap();
    for k in 0..s {
        let q = patch.partials(1.0, patch.sample_angle(k));
        assert!((q.x - p[k]).amax() < 1e-14, "{k}");
        assert!((q.xu - d[k]).amax() < 1e-13, "{k}");
        assert!((q.xuu - e[k]).amax() < 1e-12, "{k}");
    }
    for (r, count, phase) in [
        (1.0, 40, 0.0),
        (0.63, 17, 0.5),
        (0.2, 5, 0.25),
        (0.0, 3, 0.0),
    ] {
        let ring = patch.ring(r, count, phase);
        for (l, pt) in ring.iter().enumerate() {
            let q = patch.partials(r, TAU * (l as f64 + phase) / count as f64);
            assert!((pt.x - q.x).amax() < 1e-13, "{r} {l}");
            assert!((pt.xr - q.xu).amax() < 1e-12, "{r} {l}");
            assert!((pt.xt - q.xv).amax() < 1e-12, "{r} {l}");
        }
    }
}

#[test]
fn partials_match_difference_quotients() {
    let [p, d, _] = data(24, biharmonic);
    let patch = DiskPatch::solve(
        2,
        &DiskData {
            positions: &p,
            derivatives: Some(&d),
            second: None,
        },
    )
    .unwrap();
    let h = 1e-5;
    for (r, t) in [(0.5, 0.3), (0.9, 2.0), (0.1, 4.0)] {
        let q = patch.partials(r, t);
        let du = (patch.point(r + h, t) - patch.point(r - h, t)) / (2.0 * h);
        let dv = (patch.point(r, t + h) - patch.point(r, t - h)) / (2.0 * h);
        let duu = (patch.point(r + h, t) - 2.0 * q.x + patch.point(r - h, t)) / (h * h);
        let dvv = (patch.point(r, t + h) - 2.0 * q.x + patch.point(r, t - h)) / (h * h);
        let p = |a, b| patch.point(a, b);
        let duv =
            (p(r + h, t + h) - p(r + h, t - h) - p(r - h, t + h) + p(r - h, t - h)) / (4.0 * h * h);
        // Central differences: O(h²) for the first, rounding/h² ≈ 1e-6 for the second.
        assert!((q.xu - du).amax() < 1e-8 && (q.xv - dv).amax() < 1e-8);
        assert!((q.xuu - duu).amax() < 1e-4 && (q.xvv - dvv).amax() < 1e-4);
        assert!((q.xuv - duv).amax() < 1e-4);
    }
}

#[test]
fn a_planar_circle_with_in_plane_ribbons_gives_the_flat_disc() {
    // D = P_θ × N with N = +z: the conformal ribbon of the circle of radius 2.
    let s = 32;
    let p: Vec<Vec3> = (0..s)
        .map(|k| {
            let t = TAU * k as f64 / s as f64;
            Vec3::new(2.0 * t.cos() + 1.0, 2.0 * t.sin(), 3.0)
        })
        .collect();
    let d: Vec<Vec3> = p.iter().map(|q| Vec3::new(q.x - 1.0, q.y, 0.0)).collect();
    let patch = DiskPatch::solve(
        2,
        &DiskData {
            positions: &p,
            derivatives: Some(&d),
            second: None,
        },
    )
    .unwrap();
    for (r, t) in [(0.0, 0.0), (0.5, 1.0), (0.99, 4.0)] {
        let q = patch.partials(r, t);
        let exact = Vec3::new(1.0 + 2.0 * r * t.cos(), 2.0 * r * t.sin(), 3.0);
        assert!((q.x - exact).amax() < 1e-14, "{r} {t}");
        // The normal X_r × X_θ (its pole limit at r = 0) is +z.
        assert!((q.normal() - Vec3::z()).amax() < 1e-14, "{r} {t}");
    }
}

#[test]
fn bad_data_are_refused_naming_the_place() {
    let p = vec![Vec3::zeros(); 8];
    let mut q = p.clone();
    q[5].y = f64::NAN;
    let cases: Vec<(usize, DiskData, &str)> = vec![
        (
            4,
            DiskData {
                positions: &p,
                derivatives: None,
                second: None,
            },
            "order",
        ),
        (
            2,
            DiskData {
                positions: &p,
                derivatives: None,
                second: None,
            },
            "derivatives",
        ),
        (
            1,
            DiskData {
                positions: &p[..2],
                derivatives: None,
                second: None,
            },
            "positions",
        ),
        (
            1,
            DiskData {
                positions: &q,
                derivatives: None,
                second: None,
            },
            "positions[5]",
        ),
        (
            2,
            DiskData {
                positions: &p,
                derivatives: Some(&p[..7]),
                second: None,
            },
            "derivatives",
        ),
        (
            3,
            DiskData {
                positions: &p,
                derivatives: Some(&p),
                second: None,
            },
            "second",
        ),
    ];
    for (order, data, place) in cases {
        let e = DiskPatch::solve(order, &data).unwrap_err();
        assert_eq!(e.place(), place, "{e}");
    }
}

/// The unit sphere's conformal chart of the geodesic disc of radius `alpha` about the north
/// pole, `X = (2Rz, 1 − R²|z|²)/(1 + R²|z|²)`, `R = tan(alpha/2)`, with `∂X/∂r`, `∂²X/∂r²`.
fn cap(alpha: f64, r: f64, t: f64) -> [Vec3; 3] {
    let big = (alpha / 2.0).tan();
    let (c, s) = (t.cos(), t.sin());
    // With ρ = R r: X = (2ρ c, 2ρ s, 1 − ρ²)/(1 + ρ²).
    let rho = big * r;
    let q = 1.0 + rho * rho;
    let a = 2.0 * rho / q;
    let a1 = 2.0 * (1.0 - rho * rho) / (q * q);
    let a2 = 4.0 * rho * (rho * rho - 3.0) / (q * q * q);
    let h = (1.0 - rho * rho) / q;
    let h1 = -4.0 * rho / (q * q);
    let h2 = 4.0 * (3.0 * rho * rho - 1.0) / (q * q * q);
    let b2 = big * big;
    [
        Vec3::new(a * c, a * s, h),
        Vec3::new(a1 * c, a1 * s, h1) * big,
        Vec3::new(a2 * c, a2 * s, h2) * b2,
    ]
}

/// Largest distance of the patch from the unit sphere.
fn sphere_distance(patch: &DiskPatch) -> f64 {
    let mut worst: f64 = 0.0;
    for i in 0..=16 {
        for j in 0..16 {
            let x = patch.point(i as f64 / 16.0, TAU * j as f64 / 16.0);
            worst = worst.max((x.norm() - 1.0).abs());
        }
    }
    worst
}

#[test]
fn a_spherical_cap_is_approached_at_the_predicted_orders() {
    // Boundary, ribbon (and curvature ribbon) of the sphere's conformal chart. Its first term
    // that is not biharmonic is 2R⁴|z|⁴ in the height, which leaves e = −2R⁴(1 − r²)² (order 2:
    // distance 2R⁴ at the centre, O(R⁴) = O(α⁴)); the first that is not triharmonic is
    // −2R⁶|z|⁶ (order 3: O(α⁶)).
    let mut previous: [f64; 2] = [0.0; 2];
    for (step, alpha) in [0.8, 0.4, 0.2, 0.1].into_iter().enumerate() {
        let s = 64;
        let rows: Vec<[Vec3; 3]> = (0..s)
            .map(|k| cap(alpha, 1.0, TAU * k as f64 / s as f64))
            .collect();
        let [p, d, e]: [Vec<Vec3>; 3] =
            std::array::from_fn(|j| rows.iter().map(|r| r[j]).collect());
        let data = DiskData {
            positions: &p,
            derivatives: Some(&d),
            second: Some(&e),
        };
        let two = sphere_distance(&DiskPatch::solve(2, &data).unwrap());
        let three = sphere_distance(&DiskPatch::solve(3, &data).unwrap());
        let big = (alpha / 2.0).tan();
        // The leading term, within its O(R⁶) correction.
        let lead = 2.0 * big.powi(4);
        assert!(
            (two - lead).abs() < 8.0 * big.powi(6),
            "α {alpha}: {two:e} vs {lead:e}"
        );
        if step > 0 {
            let (o2, o3) = ((previous[0] / two).log2(), (previous[1] / three).log2());
            assert!((o2 - 4.0).abs() < 0.15, "α {alpha}: order {o2}");
            assert!((o3 - 6.0).abs() < 0.3, "α {alpha}: order {o3}");
        }
        previous = [two, three];
    }
}
