//! Tests of Theorem 1 and the dual bases of seed 001, exactly in rationals and to rounding in
//! `f64`. The independent truth is the power (monomial) form of each patch, expanded from the
//! Bernstein polynomials in the test: `∂^σ P(0) = σ! c_σ` for the power coefficients `c`.

use super::scalar::{binomial, IndexSet, Scalar};
use super::*;
use crate::Vec3;
use num_rational::BigRational;
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};

type Q = BigRational;

fn rand_q(rng: &mut StdRng) -> Q {
    Q::ratio(rng.gen_range(-50..=50), rng.gen_range(1..=12))
}

fn rand_values<T: Scalar>(rng: &mut StdRng, count: usize, f: impl Fn(&mut StdRng) -> T) -> Vec<T> {
    (0..count).map(|_| f(rng)).collect()
}

fn fact<T: Scalar>(n: usize) -> T {
    (1..=n).fold(T::one(), |a, k| a * T::int(k as i64))
}

fn pow<T: Scalar>(x: &T, k: usize) -> T {
    (0..k).fold(T::one(), |a, _| a * x.clone())
}

fn sign<T: Scalar>(k: usize) -> T {
    if k.is_multiple_of(2) {
        T::one()
    } else {
        -T::one()
    }
}

/// Every `σ ≤ α` (componentwise).
fn below(alpha: &[usize]) -> Vec<Vec<usize>> {
    IndexSet::boxed(alpha).unwrap().indices().to_vec()
}

/// Power coefficients `c_γ` (γ in the box order) of the tensor Bézier patch:
/// `B_k^n(x) = Σ_{j≥k} C(n,k) C(n−k, j−k) (−1)^{j−k} x^j`.
fn box_power<T: Scalar>(z: &TensorBezier<T>) -> Vec<T> {
    let (set, d, dim) = (z.index_set(), z.degree(), z.dim());
    let mut c = vec![T::zero(); set.len() * dim];
    for (g, gamma) in set.indices().iter().enumerate() {
        for alpha in below(gamma) {
            let mut w = T::one();
            for i in 0..d.len() {
                w = w
                    * binomial::<T>(d[i], alpha[i])
                    * binomial::<T>(d[i] - alpha[i], gamma[i] - alpha[i])
                    * sign::<T>(gamma[i] - alpha[i]);
            }
            let p = z.control_point(&alpha).unwrap();
            for k in 0..dim {
                c[g * dim + k] = c[g * dim + k].clone() + w.clone() * p[k].clone();
            }
        }
    }
    c
}

/// `∂^σ` of the power form at `x`: `Σ_{γ≥σ} c_γ γ!/(γ−σ)! x^{γ−σ}`.
fn power_derivative<T: Scalar>(
    set: &IndexSet,
    dim: usize,
    c: &[T],
    x: &[T],
    sigma: &[usize],
) -> Vec<T> {
    let mut out = vec![T::zero(); dim];
    for (g, gamma) in set.indices().iter().enumerate() {
        if gamma.iter().zip(sigma).any(|(g, s)| g < s) {
            continue;
        }
        let mut w = T::one();
        for i in 0..sigma.len() {
            w = w * fact::<T>(gamma[i]) / fact::<T>(gamma[i] - sigma[i])
                * pow(&x[i], gamma[i] - sigma[i]);
        }
        for k in 0..dim {
            out[k] = out[k].clone() + w.clone() * c[g * dim + k].clone();
        }
    }
    out
}

fn rand_box_degree(rng: &mut StdRng, m: usize) -> Vec<usize> {
    (0..m).map(|_| rng.gen_range(0..=4)).collect()
}

/// Theorem 1 in rationals on boxes and simplices: both directions against the printed sums,
/// and each other's inverse, exactly.
#[test]
fn theorem_1_directions_match_the_sums_and_invert_exactly() {
    let mut rng = StdRng::seed_from_u64(11);
    for trial in 0..24 {
        let m = 1 + trial % 4;
        let set = if trial % 2 == 0 {
            IndexSet::boxed(&rand_box_degree(&mut rng, m)).unwrap()
        } else {
            IndexSet::simplex(m, rng.gen_range(0..=5)).unwrap()
        };
        let dim = 2;
        let b: Vec<Q> = rand_values(&mut rng, set.len() * dim, rand_q);
        let a = forward_differences(&set, dim, &b).unwrap();
        for (pos, alpha) in set.indices().iter().enumerate() {
            for k in 0..dim {
                // (E − I)^α b_0 = Σ_{σ≤α} (−1)^{|α−σ|} C(α, σ) b_σ.
                let mut want = Q::int(0);
                for sigma in below(alpha) {
                    let q = set.position(&sigma).unwrap();
                    let mut w = Q::int(1);
                    for i in 0..m {
                        w *= binomial::<Q>(alpha[i], sigma[i]) * sign::<Q>(alpha[i] - sigma[i]);
                    }
                    want += w * b[q * dim + k].clone();
                }
                assert_eq!(a[pos * dim + k], want, "Eq. (1) at {alpha:?}");
            }
        }
        let back = binomial_sums(&set, dim, &a).unwrap();
        assert_eq!(back, b, "(2) ∘ (1) = id");
        // The other direction: (E + I)^α a_0 against its sum, then (1) ∘ (2) = id.
        let a2: Vec<Q> = rand_values(&mut rng, set.len() * dim, rand_q);
        let b2 = binomial_sums(&set, dim, &a2).unwrap();
        for (pos, alpha) in set.indices().iter().enumerate() {
            for k in 0..dim {
                let mut want = Q::int(0);
                for sigma in below(alpha) {
                    let q = set.position(&sigma).unwrap();
                    let mut w = Q::int(1);
                    for i in 0..m {
                        w *= binomial::<Q>(alpha[i], sigma[i]);
                    }
                    want += w * a2[q * dim + k].clone();
                }
                assert_eq!(b2[pos * dim + k], want, "Eq. (2) at {alpha:?}");
            }
        }
        assert_eq!(
            forward_differences(&set, dim, &b2).unwrap(),
            a2,
            "(1) ∘ (2) = id"
        );
    }
}

/// In `f64` the round trip holds to rounding: each difference at most doubles magnitudes, so
/// `|Δ^α b| ≤ 2^{|α|} max|b|` and the error of `|α|` subtractions then `|α|` additions is at
/// most `2|α| ε 4^{|α|} max|b|`.
#[test]
fn theorem_1_round_trip_in_f64() {
    let mut rng = StdRng::seed_from_u64(12);
    for _ in 0..10 {
        let d = rand_box_degree(&mut rng, 3);
        let set = IndexSet::boxed(&d).unwrap();
        let b: Vec<f64> = rand_values(&mut rng, set.len() * 3, |r| r.gen_range(-1.0..1.0));
        let back = binomial_sums(&set, 3, &forward_differences(&set, 3, &b).unwrap()).unwrap();
        let n: usize = d.iter().sum();
        let tol = 2.0 * n as f64 * f64::EPSILON * 4f64.powi(n as i32);
        for (x, y) in back.iter().zip(&b) {
            assert!((x - y).abs() <= tol, "{x} vs {y}, tol {tol}");
        }
    }
}

/// Theorem 2 / Corollary 2.1: `Λ_α` applied to a random rational tensor patch (derivatives at
/// the origin from the independent power form) returns `P_α` exactly; the patch's own
/// evaluator and derivatives agree exactly with the power form at random rational points.
#[test]
fn box_dual_basis_recovers_control_points_exactly() {
    let mut rng = StdRng::seed_from_u64(13);
    for trial in 0..16 {
        let m = 1 + trial % 3;
        let d = rand_box_degree(&mut rng, m);
        let dim = 2;
        let count = IndexSet::boxed(&d).unwrap().len();
        let z =
            TensorBezier::new(d.clone(), dim, rand_values(&mut rng, count * dim, rand_q)).unwrap();
        let c = box_power(&z);
        let set = z.index_set().clone();
        let zero = vec![Q::int(0); m];
        for alpha in set.indices() {
            let got = box_dual(&d, alpha, |sigma| {
                power_derivative(&set, dim, &c, &zero, sigma)
            })
            .unwrap();
            assert_eq!(got, z.control_point(alpha).unwrap(), "Λ_{alpha:?}");
        }
        // Corner derivatives (Theorem 1 scaled) and the inverse of Theorem 2 at once.
        let cd = z.corner_derivatives();
        for (pos, sigma) in set.indices().iter().enumerate() {
            assert_eq!(
                &cd[pos * dim..(pos + 1) * dim],
                &power_derivative(&set, dim, &c, &zero, sigma)[..]
            );
        }
        let back = TensorBezier::from_corner_derivatives(d.clone(), dim, &cd).unwrap();
        assert_eq!(back, z);
        // de Casteljau and the difference-net derivatives against the power form.
        for _ in 0..3 {
            let x: Vec<Q> = (0..m).map(|_| rand_q(&mut rng) / Q::int(10)).collect();
            assert_eq!(
                z.eval(&x).unwrap(),
                power_derivative(&set, dim, &c, &x, &vec![0; m])
            );
            for sigma in IndexSet::boxed(&d.iter().map(|k| k + 1).collect::<Vec<_>>())
                .unwrap()
                .indices()
            {
                assert_eq!(
                    z.derivative(&x, sigma).unwrap(),
                    if sigma.iter().zip(&d).any(|(s, k)| s > k) {
                        vec![Q::int(0); dim]
                    } else {
                        power_derivative(&set, dim, &c, &x, sigma)
                    },
                    "∂^{sigma:?}"
                );
            }
        }
    }
}

/// Multinomial `n!/(k_1! ⋯ k_r!)` with `Σ k = n`.
fn multinomial<T: Scalar>(parts: &[usize]) -> T {
    let n: usize = parts.iter().sum();
    parts
        .iter()
        .fold(fact::<T>(n), |acc, &k| acc / fact::<T>(k))
}

/// Power coefficients of a simplex patch:
/// `B_α^n = n!/(α!(n−|α|)!) λ^α (1 − |λ|)^{n−|α|}`, `(1 − |λ|)^k = Σ_{|μ|≤k} k!/(μ!(k−|μ|)!) (−λ)^μ`.
fn simplex_power<T: Scalar>(z: &SimplexBezier<T>) -> Vec<T> {
    let (set, n, dim) = (z.index_set(), z.degree(), z.dim());
    let mut c = vec![T::zero(); set.len() * dim];
    for (g, gamma) in set.indices().iter().enumerate() {
        for alpha in below(gamma) {
            let na: usize = alpha.iter().sum();
            let mut parts = alpha.clone();
            parts.push(n - na);
            let mu: Vec<usize> = gamma.iter().zip(&alpha).map(|(g, a)| g - a).collect();
            let nm: usize = mu.iter().sum();
            if nm > n - na {
                continue;
            }
            let mut parts2 = mu.clone();
            parts2.push(n - na - nm);
            let w = multinomial::<T>(&parts) * multinomial::<T>(&parts2) * sign::<T>(nm);
            let p = z.control_point(&alpha).unwrap();
            for k in 0..dim {
                c[g * dim + k] = c[g * dim + k].clone() + w.clone() * p[k].clone();
            }
        }
    }
    c
}

/// Theorem 3 / Corollary 3.1 (triangles, m = 2) and tetrahedra (m = 3): `Λ_α` returns `C_α`
/// exactly; evaluation, partial and directional derivatives agree exactly with the power form.
#[test]
fn simplex_dual_basis_recovers_control_points_exactly() {
    let mut rng = StdRng::seed_from_u64(14);
    for trial in 0..12 {
        let m = [2, 3, 1][trial % 3];
        let n = rng.gen_range(0..=5);
        let dim = 3;
        let count = IndexSet::simplex(m, n).unwrap().len();
        let z = SimplexBezier::new(m, n, dim, rand_values(&mut rng, count * dim, rand_q)).unwrap();
        let c = simplex_power(&z);
        let set = z.index_set().clone();
        let zero = vec![Q::int(0); m];
        for alpha in set.indices() {
            let got = simplex_dual(n, alpha, |sigma| {
                power_derivative(&set, dim, &c, &zero, sigma)
            })
            .unwrap();
            assert_eq!(got, z.control_point(alpha).unwrap(), "Λ_{alpha:?}");
        }
        let cd = z.corner_derivatives();
        let back = SimplexBezier::from_corner_derivatives(m, n, dim, &cd).unwrap();
        assert_eq!(back, z);
        for _ in 0..3 {
            let lambda: Vec<Q> = (0..m).map(|_| rand_q(&mut rng) / Q::int(50)).collect();
            assert_eq!(
                z.eval(&lambda).unwrap(),
                power_derivative(&set, dim, &c, &lambda, &vec![0; m])
            );
            for sigma in IndexSet::simplex(m, n + 1).unwrap().indices() {
                let want = if sigma.iter().sum::<usize>() > n {
                    vec![Q::int(0); dim]
                } else {
                    power_derivative(&set, dim, &c, &lambda, sigma)
                };
                assert_eq!(z.derivative(&lambda, sigma).unwrap(), want, "∂^{sigma:?}");
            }
            // D_u D_w = Σ_ij u_i w_j ∂_i ∂_j.
            let u: Vec<Q> = (0..m).map(|_| rand_q(&mut rng)).collect();
            let w: Vec<Q> = (0..m).map(|_| rand_q(&mut rng)).collect();
            let mut want = vec![Q::int(0); dim];
            for i in 0..m {
                for j in 0..m {
                    let mut s = vec![0; m];
                    s[i] += 1;
                    s[j] += 1;
                    let d = z.derivative(&lambda, &s).unwrap();
                    for k in 0..dim {
                        want[k] = want[k].clone() + u[i].clone() * w[j].clone() * d[k].clone();
                    }
                }
            }
            assert_eq!(
                z.directional(&lambda, &[u.clone(), w.clone()]).unwrap(),
                want
            );
        }
    }
}

/// Seed 001's functionals in `f64` on a [`BezierSurface`]: `Λ_{ij}` of Corollary 2.1 from the
/// surface's exact corner derivatives returns `P_{ij}` to rounding (the sum has at most
/// `(i+1)(j+1)` terms of size ≤ `2^{i+j} max|P|`), and the m = 2, dim = 3 tensor patch is
/// the same surface.
#[test]
fn corollary_2_1_on_a_bezier_surface_in_f64() {
    let mut rng = StdRng::seed_from_u64(15);
    let (n, m) = (4, 3);
    let ctrl: Vec<Vec3> = (0..(n + 1) * (m + 1))
        .map(|_| {
            Vec3::new(
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.0),
            )
        })
        .collect();
    let s = BezierSurface::new([n, m], ctrl.clone()).unwrap();
    let flat: Vec<f64> = ctrl.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
    let t = TensorBezier::new(vec![n, m], 3, flat).unwrap();
    for i in 0..=n {
        for j in 0..=m {
            let got = box_dual(&[n, m], &[i, j], |sg| {
                let d = s.derivative(0.0, 0.0, sg[0], sg[1]);
                vec![d.x, d.y, d.z]
            })
            .unwrap();
            let p = s.control_point(i, j);
            let tol = ((i + 1) * (j + 1)) as f64 * 2f64.powi((i + j) as i32) * 4.0 * f64::EPSILON;
            for k in 0..3 {
                assert!(
                    (got[k] - p[k]).abs() <= tol,
                    "Λ_{i}{j}: {} vs {}",
                    got[k],
                    p[k]
                );
            }
        }
    }
    for _ in 0..5 {
        let (u, v) = (rng.gen_range(0.0..1.0), rng.gen_range(0.0..1.0));
        for (ku, kv) in [(0, 0), (1, 0), (0, 2), (2, 1), (4, 3), (5, 0)] {
            let a = s.derivative(u, v, ku, kv);
            let b = t.derivative(&[u, v], &[ku, kv]).unwrap();
            let tol = 1e-13 * 2f64.powi((ku + kv) as i32) * 100.0;
            assert!(
                (a - Vec3::new(b[0], b[1], b[2])).amax() <= tol,
                "({ku}, {kv})"
            );
        }
    }
}

#[test]
fn dual_bases_reject_bad_input() {
    let e = box_dual::<f64>(&[2, 3], &[3, 0], |_| vec![0.0])
        .unwrap_err()
        .to_string();
    assert!(e.contains("alpha[0] = 3"), "{e}");
    let e = box_dual::<f64>(&[2, 3], &[1], |_| vec![0.0])
        .unwrap_err()
        .to_string();
    assert!(e.contains("2 components"), "{e}");
    let e = simplex_dual::<f64>(3, &[2, 2], |_| vec![0.0])
        .unwrap_err()
        .to_string();
    assert!(e.contains("|alpha| = 4"), "{e}");
    let set = IndexSet::simplex(2, 2).unwrap();
    assert_eq!(set.len(), 6);
    let e = forward_differences(&set, 2, &[0.0; 11])
        .unwrap_err()
        .to_string();
    assert!(e.contains("got 11"), "{e}");
    assert!(TensorBezier::new(vec![], 1, vec![0.0]).is_err());
    assert!(TensorBezier::new(vec![1], 0, Vec::<f64>::new()).is_err());
    assert!(SimplexBezier::new(2, 2, 1, vec![0.0; 5]).is_err());
    assert!(IndexSet::boxed(&[usize::MAX]).is_err());
    assert!(IndexSet::simplex(40, 3).is_err());
    let z = SimplexBezier::new(2, 2, 1, vec![0.0; 6]).unwrap();
    assert!(z.eval(&[0.0]).is_err());
    assert!(z.directional(&[0.0, 0.0], &[vec![1.0]]).is_err());
}

/// Simplex coordinates in a random non-degenerate simplex: exact in rationals; the geometric
/// directional derivative through `simplex_direction` against a finite difference of the
/// patch along a straight line in the domain (the patch is a polynomial of degree `n` along
/// the line, so the central difference's error is `Σ_{odd j≥3} h^{j−1}/j! |f⁽ʲ⁾|`, bounded
/// here with the exact third derivative (doubled for the tail), plus rounding).
#[test]
fn simplex_coordinates_and_geometric_directions() {
    let mut rng = StdRng::seed_from_u64(16);
    for m in 1..=3 {
        let verts: Vec<Vec<Q>> = (0..=m)
            .map(|_| (0..m).map(|_| rand_q(&mut rng)).collect())
            .collect();
        let lambda: Vec<Q> = (0..m).map(|_| rand_q(&mut rng) / Q::int(50)).collect();
        let last = lambda.iter().fold(Q::int(1), |a, l| a - l);
        let x: Vec<Q> = (0..m)
            .map(|r| {
                (0..m).fold(last.clone() * verts[m][r].clone(), |a, i| {
                    a + lambda[i].clone() * verts[i][r].clone()
                })
            })
            .collect();
        match simplex_coordinates(&verts, &x) {
            Ok(l) => assert_eq!(l, lambda),
            Err(e) => panic!("random simplex degenerate? {e}"),
        }
    }
    // Degenerate: three collinear vertices in the plane.
    let flat = vec![vec![0.0, 0.0], vec![1.0, 1.0], vec![2.0, 2.0]];
    let e = simplex_coordinates(&flat, &[0.5, 0.5])
        .unwrap_err()
        .to_string();
    assert!(e.contains("degenerate"), "{e}");
    let flat_q: Vec<Vec<Q>> = flat
        .iter()
        .map(|v| v.iter().map(|&c| rational_from_f64(c).unwrap()).collect())
        .collect();
    assert!(simplex_direction(&flat_q, &[Q::int(1), Q::int(0)]).is_err());
    // A triangle in f64: D_w b = lim (b(λ(x + h w)) − b(λ(x − h w)))/2h.
    let tri = vec![vec![0.3, 0.1], vec![2.0, 0.4], vec![0.7, 1.9]];
    let n = 4;
    let count = IndexSet::simplex(2, n).unwrap().len();
    let z = SimplexBezier::new(
        2,
        n,
        3,
        rand_values(&mut rng, count * 3, |r| r.gen_range(-1.0..1.0)),
    )
    .unwrap();
    let x = [0.9, 0.7];
    let w = [0.6, -0.8];
    let d = simplex_direction(&tri, &w).unwrap();
    let lam = simplex_coordinates(&tri, &x).unwrap();
    let exact = z.directional(&lam, std::slice::from_ref(&d)).unwrap();
    let h = 1e-3;
    let at = |t: f64| {
        let p = [x[0] + t * w[0], x[1] + t * w[1]];
        z.eval(&simplex_coordinates(&tri, &p).unwrap()).unwrap()
    };
    let (fp, fm) = (at(h), at(-h));
    let third = z
        .directional(&lam, &[d.clone(), d.clone(), d.clone()])
        .unwrap();
    for k in 0..3 {
        let fd = (fp[k] - fm[k]) / (2.0 * h);
        let tol = 2.0 * h * h / 6.0 * third[k].abs() + 64.0 * f64::EPSILON / h;
        assert!(
            (fd - exact[k]).abs() <= tol,
            "{fd} vs {}, tol {tol}",
            exact[k]
        );
    }
}
