#![allow(clippy::excessive_precision)]
use super::*;
use crate::surface::Surface;
use crate::Vec3;

/// Gauss–Legendre with 5 points on [0, 1] (exact for degree ≤ 9): error integrals.
const GAUSS5: [(f64, f64); 5] = [
    (0.046_910_077_030_668_0, 0.118_463_442_528_094_5),
    (0.230_765_344_947_158_5, 0.239_314_335_249_683_2),
    (0.5, 0.284_444_444_444_444_4),
    (0.769_234_655_052_841_5, 0.239_314_335_249_683_2),
    (0.953_089_922_969_332_0, 0.118_463_442_528_094_5),
];

/// A separable function `X(x) Y(y)` given by its derivatives `X⁽ⁿ⁾`, `Y⁽ⁿ⁾`.
#[derive(Clone, Copy)]
struct Sep {
    fx: fn(f64, usize) -> f64,
    fy: fn(f64, usize) -> f64,
}

impl Sep {
    fn d(&self, x: f64, y: f64, i: usize, j: usize) -> f64 {
        (self.fx)(x, i) * (self.fy)(y, j)
    }
}

/// A vector function with three separable components.
struct Exact([Sep; 3]);

impl Exact {
    fn d(&self, x: f64, y: f64, i: usize, j: usize) -> Vec3 {
        Vec3::new(
            self.0[0].d(x, y, i, j),
            self.0[1].d(x, y, i, j),
            self.0[2].d(x, y, i, j),
        )
    }
    /// `L u` for the fourth-order part of `energy` (`c = [∂x⁴, ∂x³∂y, ∂x²∂y², ∂x∂y³, ∂y⁴]`).
    fn load(&self, energy: &Energy, x: f64, y: f64) -> Vec3 {
        let c = energy.operator_coefficients();
        (0..5).map(|k| self.d(x, y, 4 - k, k) * c[k]).sum()
    }
    /// Every degree of freedom of the nodes on ∂Ω fixed from `self`.
    fn clamped(&self, p: &Partition) -> (Vec<bool>, Vec<Vec3>) {
        let mut fixed = vec![false; p.dofs()];
        let mut vals = vec![Vec3::zeros(); p.dofs()];
        for j in 0..=p.ny() {
            for i in 0..=p.nx() {
                if i == 0 || j == 0 || i == p.nx() || j == p.ny() {
                    let (x, y) = (p.xs()[i], p.ys()[j]);
                    for (k, (a, b)) in [(0, 0), (1, 0), (0, 1), (1, 1)].into_iter().enumerate() {
                        fixed[p.dof(i, j, k)] = true;
                        vals[p.dof(i, j, k)] = self.d(x, y, a, b);
                    }
                }
            }
        }
        (fixed, vals)
    }
}

fn sin_pi(x: f64, n: usize) -> f64 {
    let k = std::f64::consts::PI;
    k.powi(n as i32) * (k * x + n as f64 * std::f64::consts::FRAC_PI_2).sin()
}
fn sin2(x: f64, n: usize) -> f64 {
    2f64.powi(n as i32) * (2.0 * x + 0.3 + n as f64 * std::f64::consts::FRAC_PI_2).sin()
}
fn exp1(x: f64, _n: usize) -> f64 {
    x.exp()
}
fn cos3(x: f64, n: usize) -> f64 {
    3f64.powi(n as i32) * (3.0 * x + n as f64 * std::f64::consts::FRAC_PI_2).cos()
}
/// `x³ − x²`
fn cubic_a(x: f64, n: usize) -> f64 {
    match n {
        0 => x * x * x - x * x,
        1 => 3.0 * x * x - 2.0 * x,
        2 => 6.0 * x - 2.0,
        3 => 6.0,
        _ => 0.0,
    }
}
/// `2 + x − x³`
fn cubic_b(x: f64, n: usize) -> f64 {
    match n {
        0 => 2.0 + x - x * x * x,
        1 => 1.0 - 3.0 * x * x,
        2 => -6.0 * x,
        3 => -6.0,
        _ => 0.0,
    }
}

fn smooth_exact() -> Exact {
    Exact([
        Sep { fx: sin2, fy: exp1 },
        Sep { fx: exp1, fy: cos3 },
        Sep {
            fx: sin_pi,
            fy: sin_pi,
        },
    ])
}

/// `(L², H² seminorm)` errors of `s` against `u` by the 5 × 5 Gauss rule per element.
fn errors(s: &BfsSurface, u: &Exact) -> (f64, f64) {
    let p = s.partition();
    let (mut l2, mut h2) = (0.0, 0.0);
    for j in 0..p.ny() {
        for i in 0..p.nx() {
            let (x0, hx) = (p.xs()[i], p.xs()[i + 1] - p.xs()[i]);
            let (y0, hy) = (p.ys()[j], p.ys()[j + 1] - p.ys()[j]);
            for &(t, wt) in &GAUSS5 {
                for &(r, wr) in &GAUSS5 {
                    let (x, y) = (x0 + r * hx, y0 + t * hy);
                    let w = wr * wt * hx * hy;
                    // Evaluate inside the element (away from its edges).
                    let q = s.evaluate(x, y);
                    l2 += w * (q.x - u.d(x, y, 0, 0)).norm_squared();
                    h2 += w
                        * ((q.xuu - u.d(x, y, 2, 0)).norm_squared()
                            + 2.0 * (q.xuv - u.d(x, y, 1, 1)).norm_squared()
                            + (q.xvv - u.d(x, y, 0, 2)).norm_squared());
                }
            }
        }
    }
    (l2.sqrt(), h2.sqrt())
}

fn solve_clamped(n: usize, energy: &Energy, u: &Exact) -> BfsSurface {
    let p = Partition::uniform(n, n, false).unwrap();
    let (fixed, vals) = u.clamped(&p);
    let sys = SplineSystem::new(p, &fixed).unwrap();
    let f = sys.factor(energy, 1.0, &[]).unwrap();
    let load = |x: f64, y: f64| u.load(energy, x, y);
    f.solve(&[], &vals, Some(&load)).unwrap()
}

#[test]
fn hermite_basis_interpolates_its_nodal_data() {
    let h = 0.37;
    let g0 = hermite_1d(0.0, h);
    let g1 = hermite_1d(1.0, h);
    // value at 0, derivative at 0, value at 1, derivative at 1
    assert_eq!(
        [g0[0][0], g0[1][1], g1[0][2], g1[1][3]],
        [1.0, 1.0, 1.0, 1.0]
    );
    for k in [1, 2, 3] {
        assert_eq!(g0[0][k], 0.0);
    }
    for k in [0, 2, 3] {
        assert!(g0[1][k].abs() < 1e-15);
    }
    // Second derivative by central differences of the first.
    let s = 0.3;
    let e = 1e-5;
    let (a, b, c) = (hermite_1d(s - e, h), hermite_1d(s + e, h), hermite_1d(s, h));
    for k in 0..4 {
        let fd1 = (b[0][k] - a[0][k]) / (2.0 * e * h);
        let fd2 = (b[1][k] - a[1][k]) / (2.0 * e * h);
        assert!((fd1 - c[1][k]).abs() < 1e-8, "{k}");
        assert!((fd2 - c[2][k]).abs() < 1e-6, "{k}");
    }
}

#[test]
fn element_energy_of_a_monomial_is_exact() {
    // u = x²y² on [0, hx] × [0, hy]: (u, u)_L = ∫ (2y²)² + 2a (4xy)² + a² (2x²)².
    let (hx, hy, a) = (0.5, 2.0, 3.0);
    let e = Energy::section6(a).unwrap();
    let k = element_matrix(&e, hx, hy);
    // Nodal data of x²y²: u, u_x = 2xy², u_y = 2x²y, u_xy = 4xy.
    let mut c = [0.0; 16];
    for b in 0..2 {
        for aa in 0..2 {
            let (x, y) = (aa as f64 * hx, b as f64 * hy);
            let l = 4 * (aa + 2 * b);
            c[l..l + 4].copy_from_slice(&[
                x * x * y * y,
                2.0 * x * y * y,
                2.0 * x * x * y,
                4.0 * x * y,
            ]);
        }
    }
    let mut energy = 0.0;
    for i in 0..16 {
        for j in 0..16 {
            energy += c[i] * k[i][j] * c[j];
        }
    }
    let exact = 4.0 * hx * hy.powi(5) / 5.0
        + 2.0 * a * 16.0 * hx.powi(3) * hy.powi(3) / 9.0
        + a * a * 4.0 * hx.powi(5) * hy / 5.0;
    assert!(
        (energy - exact).abs() < 1e-13 * exact,
        "{energy} vs {exact}"
    );
    // Affine functions are in the kernel: u = 1 + 2x − 3y.
    let mut c = [0.0; 16];
    for b in 0..2 {
        for aa in 0..2 {
            let (x, y) = (aa as f64 * hx, b as f64 * hy);
            let l = 4 * (aa + 2 * b);
            c[l..l + 4].copy_from_slice(&[1.0 + 2.0 * x - 3.0 * y, 2.0, -3.0, 0.0]);
        }
    }
    for row in &k {
        let r: f64 = row.iter().zip(&c).map(|(a, b)| a * b).sum();
        assert!(r.abs() < 1e-12, "{r}");
    }
}

#[test]
fn energies_outside_the_accepted_family_are_refused() {
    // The paper's tempting alternative a(u_xx v_yy + u_yy v_xx): M₂ = [[1,0,a],[0,0,0],[a,0,a²]].
    let a = 10.0;
    let e = Energy::quadratic(
        [[1.0, 0.0, a], [0.0, 0.0, 0.0], [a, 0.0, a * a]],
        [[0.0; 2]; 2],
        0.0,
    )
    .unwrap_err();
    assert!(e.to_string().contains("not positive definite"), "{e}");
    assert!(Energy::section6(0.0).is_err());
    assert!(Energy::section6(f64::NAN).is_err());
    assert!(Energy::general(1.0, 3.0, 1.0, 0.0, 1.0).is_err()); // b² > 4ac: indefinite
    assert!(Energy::quadratic(
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
        [[-1.0, 0.0], [0.0, 0.0]],
        0.0
    )
    .is_err());
    let ok = Energy::section6(2.0).unwrap();
    assert_eq!(ok.operator_coefficients(), [1.0, 0.0, 4.0, 0.0, 4.0]);
}

#[test]
fn bicubic_solutions_are_reproduced_to_rounding() {
    // u ∈ Q₃ with its own load: the Galerkin solution is u itself, interior dofs included.
    let u = Exact([
        Sep {
            fx: cubic_a,
            fy: cubic_b,
        },
        Sep {
            fx: cubic_b,
            fy: cubic_b,
        },
        Sep {
            fx: cubic_a,
            fy: cubic_a,
        },
    ]);
    let e = Energy::general(1.0, 0.4, 2.5, -0.3, 1.5).unwrap();
    let s = solve_clamped(5, &e, &u);
    let mut worst = 0.0f64;
    for k in 0..200 {
        let (x, y) = ((k as f64 * 0.618_034) % 1.0, (k as f64 * 0.414_214) % 1.0);
        let q = s.evaluate(x, y);
        worst = worst.max((q.x - u.d(x, y, 0, 0)).norm());
        worst = worst.max((q.xuv - u.d(x, y, 1, 1)).norm());
    }
    assert!(worst < 1e-12, "{worst}");
}

#[test]
fn manufactured_fourth_order_problem_converges_at_orders_4_and_2() {
    // Clamped problem L u = f with a non-diagonal energy; expected orders for bicubic Hermite
    // elements: L² h⁴, H² seminorm h².
    let u = smooth_exact();
    let e = Energy::general(1.0, 0.4, 2.5, -0.3, 1.5).unwrap();
    let mut prev: Option<(f64, f64)> = None;
    let mut orders = Vec::new();
    for n in [4, 8, 16, 32] {
        let s = solve_clamped(n, &e, &u);
        let (l2, h2) = errors(&s, &u);
        if let Some((pl2, ph2)) = prev {
            orders.push(((pl2 / l2).log2(), (ph2 / h2).log2()));
        }
        eprintln!("n = {n}: L² error {l2:.3e}, H² error {h2:.3e}");
        prev = Some((l2, h2));
    }
    eprintln!("observed orders (L², H²): {orders:?}");
    let (ol2, oh2) = *orders.last().unwrap();
    assert!(ol2 >= 3.7, "L² order {ol2}");
    assert!(oh2 >= 1.7, "H² order {oh2}");
}

#[test]
fn the_spline_minimises_j_against_independent_quadrature() {
    // J(σ + δv) is symmetric in δ for every v ∈ H_h⁰ (Theorem 5), with J from Eq. 6 evaluated by
    // independent quadrature of the evaluator's derivatives.
    let p = Partition::uniform(3, 2, false).unwrap();
    let energy = Energy::general(1.0, 0.2, 3.0, 0.1, 2.0).unwrap();
    let eps = 0.05;
    // Fix the paper's τ on y = 0 (value, normal derivative) and nothing else.
    let mut fixed = vec![false; p.dofs()];
    let mut vals = vec![Vec3::zeros(); p.dofs()];
    for i in 0..=p.nx() {
        fixed[p.dof(i, 0, 0)] = true;
        fixed[p.dof(i, 0, 2)] = true;
        vals[p.dof(i, 0, 0)] = Vec3::new(i as f64, 0.5, -1.0);
        vals[p.dof(i, 0, 2)] = Vec3::new(0.2, 1.0, 0.3 * i as f64);
    }
    let sites = vec![[0.2, 0.7], [0.5, 0.9], [0.9, 0.4], [0.33, 0.5]];
    let beta = vec![
        Vec3::new(0.0, 1.0, 2.0),
        Vec3::new(1.0, -1.0, 0.5),
        Vec3::new(2.0, 0.3, 0.0),
        Vec3::new(-1.0, 0.0, 1.0),
    ];
    let load = |x: f64, y: f64| Vec3::new(x * y, (3.0 * x).sin(), 1.0);
    let sys = SplineSystem::new(p.clone(), &fixed).unwrap();
    let sigma = sys
        .factor(&energy, eps, &sites)
        .unwrap()
        .solve(&beta, &vals, Some(&load))
        .unwrap();
    let m = *energy.matrix();
    let j_of = |s: &BfsSurface| {
        let mut data = 0.0;
        for (a, b) in sites.iter().zip(&beta) {
            data += (s.evaluate(a[0], a[1]).x - b).norm_squared();
        }
        let (mut el, mut fl) = (0.0, 0.0);
        for jj in 0..p.ny() {
            for ii in 0..p.nx() {
                let (x0, hx) = (p.xs()[ii], p.xs()[ii + 1] - p.xs()[ii]);
                let (y0, hy) = (p.ys()[jj], p.ys()[jj + 1] - p.ys()[jj]);
                for &(t, wt) in &GAUSS5 {
                    for &(r, wr) in &GAUSS5 {
                        let (x, y) = (x0 + r * hx, y0 + t * hy);
                        let w = wr * wt * hx * hy;
                        let q = s.evaluate(x, y);
                        let ws = [q.x, q.xu, q.xv, q.xuu, q.xuv, q.xvv];
                        for a in 0..6 {
                            for b in 0..6 {
                                el += w * m[a][b] * ws[a].dot(&ws[b]);
                            }
                        }
                        fl += w * load(x, y).dot(&q.x);
                    }
                }
            }
        }
        data + eps * (el - 2.0 * fl)
    };
    let j0 = j_of(&sigma);
    for trial in 0..3 {
        // A direction in H_h⁰: free dofs only.
        let dir: Vec<Vec3> = (0..p.dofs())
            .map(|d| {
                if fixed[d] {
                    Vec3::zeros()
                } else {
                    let t = (d * 7 + trial * 13) as f64;
                    Vec3::new(t.sin(), (1.3 * t).cos(), (0.7 * t).sin())
                }
            })
            .collect();
        let shifted = |delta: f64| {
            let c: Vec<Vec3> = sigma
                .coefficients()
                .iter()
                .zip(&dir)
                .map(|(a, b)| a + b * delta)
                .collect();
            j_of(&BfsSurface::new(p.clone(), c))
        };
        let delta = 1e-3;
        let (jp, jm) = (shifted(delta), shifted(-delta));
        let slope = (jp - jm) / (2.0 * delta);
        let curvature = (jp + jm - 2.0 * j0) / (delta * delta);
        assert!(curvature > 0.0);
        // The first variation vanishes: |slope| at rounding level next to J's size.
        assert!(
            slope.abs() < 1e-9 * (1.0 + j0.abs()) / delta,
            "slope {slope}, J {j0}"
        );
    }
}

#[test]
fn theorem_3_denser_data_and_smaller_epsilon_approach_the_surface() {
    // g ∈ H (τ g from g itself), data ρ g on an r × r grid, ε = r⁻⁴, h = 1/r: the spline
    // approaches g in L² and H². Only the paper's τ is fixed (value and normal derivative at the
    // boundary nodes), so the boundary trace between nodes is free and the H² error falls like
    // h (observed ratios 2.7, 2.2, 2.0), the L² error like h⁴ or faster.
    let g = smooth_exact();
    let energy = Energy::section6(1.0).unwrap();
    let mut prev = (f64::INFINITY, f64::INFINITY);
    for r in [4usize, 8, 16, 32] {
        let p = Partition::uniform(r, r, false).unwrap();
        // The paper's τ: value and normal derivative(s) at the boundary nodes.
        let mut fixed = vec![false; p.dofs()];
        let mut vals = vec![Vec3::zeros(); p.dofs()];
        for j in 0..=r {
            for i in 0..=r {
                let (x, y) = (p.xs()[i], p.ys()[j]);
                let mut set = |k: usize, a: usize, b: usize| {
                    fixed[p.dof(i, j, k)] = true;
                    vals[p.dof(i, j, k)] = g.d(x, y, a, b);
                };
                if i == 0 || i == r || j == 0 || j == r {
                    set(0, 0, 0);
                }
                if i == 0 || i == r {
                    set(1, 1, 0);
                }
                if j == 0 || j == r {
                    set(2, 0, 1);
                }
            }
        }
        let sites: Vec<[f64; 2]> = (0..r * r)
            .map(|k| {
                [
                    ((k % r) as f64 + 0.5) / r as f64,
                    ((k / r) as f64 + 0.5) / r as f64,
                ]
            })
            .collect();
        let beta: Vec<Vec3> = sites.iter().map(|a| g.d(a[0], a[1], 0, 0)).collect();
        let eps = (r as f64).powi(-4);
        let sys = SplineSystem::new(p, &fixed).unwrap();
        let s = sys
            .factor(&energy, eps, &sites)
            .unwrap()
            .solve(&beta, &vals, None)
            .unwrap();
        let (l2, h2) = errors(&s, &g);
        eprintln!("r = {r}: ε = {eps:.1e}, L² error {l2:.3e}, H² error {h2:.3e}");
        assert!(
            l2 < prev.0 / 7.0 && h2 < prev.1 / 1.8,
            "r = {r}: {l2} {h2} after {prev:?}"
        );
        prev = (l2, h2);
    }
    assert!(prev.0 < 1e-5, "{prev:?}");
}

#[test]
fn partials_are_exact_and_the_spline_is_c1() {
    let u = smooth_exact();
    let e = Energy::section6(2.0).unwrap();
    let s = solve_clamped(4, &e, &u);
    let h = 1e-5;
    for &(x, y) in &[(0.1, 0.2), (0.6, 0.35), (0.9, 0.8)] {
        let q = s.partials(x, y);
        let fx = (s.point(x + h, y) - s.point(x - h, y)) / (2.0 * h);
        let fy = (s.point(x, y + h) - s.point(x, y - h)) / (2.0 * h);
        let fxx = (s.partials(x + h, y).xu - s.partials(x - h, y).xu) / (2.0 * h);
        let fxy = (s.partials(x, y + h).xu - s.partials(x, y - h).xu) / (2.0 * h);
        let fyy = (s.partials(x, y + h).xv - s.partials(x, y - h).xv) / (2.0 * h);
        assert!((fx - q.xu).norm() < 1e-8 && (fy - q.xv).norm() < 1e-8);
        assert!((fxx - q.xuu).norm() < 1e-6 && (fxy - q.xuv).norm() < 1e-6);
        assert!((fyy - q.xvv).norm() < 1e-6);
    }
    // C¹ across the interior edge x = 0.5: both elements' Bézier forms agree on value and x-slope.
    let (l, r) = (s.bezier_patch(1, 1), s.bezier_patch(2, 1));
    for j in 0..4 {
        assert!((l.control[3][j] - r.control[0][j]).norm() < 1e-14);
        let dl = (l.control[3][j] - l.control[2][j]) / (l.x[1] - l.x[0]);
        let dr = (r.control[1][j] - r.control[0][j]) / (r.x[1] - r.x[0]);
        assert!((dl - dr).norm() < 1e-12, "{dl:?} {dr:?}");
    }
}

fn bernstein(t: f64) -> [f64; 4] {
    let s = 1.0 - t;
    [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t]
}

/// Cox–de Boor: the cubic B-spline basis functions of `knots` at `t`.
fn bspline_basis(knots: &[f64], t: f64) -> Vec<f64> {
    let n = knots.len() - 4;
    let last = knots[knots.len() - 1];
    let mut b: Vec<f64> = (0..knots.len() - 1)
        .map(|i| {
            let inside = knots[i] <= t && t < knots[i + 1];
            let at_end = t == last && knots[i] < knots[i + 1] && knots[i + 1] == last;
            if inside || at_end {
                1.0
            } else {
                0.0
            }
        })
        .collect();
    for d in 1..=3 {
        for i in 0..knots.len() - 1 - d {
            let a = if knots[i + d] > knots[i] {
                (t - knots[i]) / (knots[i + d] - knots[i]) * b[i]
            } else {
                0.0
            };
            let c = if knots[i + d + 1] > knots[i + 1] {
                (knots[i + d + 1] - t) / (knots[i + d + 1] - knots[i + 1]) * b[i + 1]
            } else {
                0.0
            };
            b[i] = a + c;
        }
    }
    b.truncate(n);
    b
}

#[test]
fn bezier_and_bspline_nets_reproduce_the_spline() {
    let u = smooth_exact();
    let p = Partition::new(vec![0.0, 0.3, 0.45, 1.0], vec![0.0, 0.6, 1.0], false).unwrap();
    let (fixed, vals) = u.clamped(&p);
    let e = Energy::section6(1.0).unwrap();
    let sys = SplineSystem::new(p, &fixed).unwrap();
    let load = |x: f64, y: f64| u.load(&e, x, y);
    let s = sys
        .factor(&e, 1.0, &[])
        .unwrap()
        .solve(&[], &vals, Some(&load))
        .unwrap();
    let net = s.bspline();
    assert_eq!(net.control.len(), 8);
    assert_eq!(net.control[0].len(), 6);
    for k in 0..50 {
        let (x, y) = (
            (k as f64 * 0.618_034) % 1.0,
            (k as f64 * 0.414_214 + 0.01) % 1.0,
        );
        let want = s.point(x, y);
        let (i, j) = s.partition().locate(x, y);
        let b = s.bezier_patch(i, j);
        let (bs, bt) = (
            bernstein((x - b.x[0]) / (b.x[1] - b.x[0])),
            bernstein((y - b.y[0]) / (b.y[1] - b.y[0])),
        );
        let mut got = Vec3::zeros();
        for a in 0..4 {
            for c in 0..4 {
                got += b.control[a][c] * (bs[a] * bt[c]);
            }
        }
        assert!((got - want).norm() < 1e-13, "Bézier at ({x}, {y})");
        let (nx, ny) = (
            bspline_basis(&net.knots_x, x),
            bspline_basis(&net.knots_y, y),
        );
        let mut got = Vec3::zeros();
        for a in 0..nx.len() {
            for c in 0..ny.len() {
                got += net.control[a][c] * (nx[a] * ny[c]);
            }
        }
        assert!(
            (got - want).norm() < 1e-13,
            "B-spline at ({x}, {y}): {got:?} vs {want:?}"
        );
    }
    let json: serde_json::Value = serde_json::from_str(&s.control_net_json()).unwrap();
    assert_eq!(json["bezier"].as_array().unwrap().len(), 6);
    assert_eq!(json["bspline"]["knots_x"].as_array().unwrap().len(), 12);
}

#[test]
fn symbolic_analysis_is_reused_and_bad_input_is_refused() {
    let p = Partition::uniform(4, 3, false).unwrap();
    let mut fixed = vec![false; p.dofs()];
    let mut vals = vec![Vec3::zeros(); p.dofs()];
    for i in 0..=4 {
        for k in 0..4 {
            fixed[p.dof(i, 0, k)] = true;
            vals[p.dof(i, 0, k)] = Vec3::new(i as f64, k as f64, 1.0);
        }
    }
    let e = Energy::section6(1.0).unwrap();
    let sys = SplineSystem::new(p.clone(), &fixed).unwrap();
    let sites = [[0.5, 0.5], [0.2, 0.9]];
    let beta = [Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.0, 0.0, 1.0)];
    let a = sys
        .factor(&e, 0.1, &sites)
        .unwrap()
        .solve(&beta, &vals, None)
        .unwrap();
    let _ = sys
        .factor(&Energy::section6(5.0).unwrap(), 3.0, &[[0.1, 0.1]])
        .unwrap();
    let again = sys
        .factor(&e, 0.1, &sites)
        .unwrap()
        .solve(&beta, &vals, None)
        .unwrap();
    let fresh = SplineSystem::new(p.clone(), &fixed)
        .unwrap()
        .factor(&e, 0.1, &sites)
        .unwrap()
        .solve(&beta, &vals, None)
        .unwrap();
    assert_eq!(a, again);
    assert_eq!(a, fresh);
    // Nothing fixed and no data: the affine functions are free.
    let none = SplineSystem::new(p.clone(), &vec![false; p.dofs()]).unwrap();
    let err = none.factor(&e, 1.0, &[]).err().unwrap();
    assert_eq!(err.kind(), crate::ErrorKind::NotUnique, "{err}");
    // Collinear data do not help either.
    assert!(none
        .factor(&e, 1.0, &[[0.1, 0.1], [0.5, 0.5], [0.9, 0.9]])
        .is_err());
    assert!(none
        .factor(&e, 1.0, &[[0.1, 0.1], [0.5, 0.5], [0.9, 0.2]])
        .is_ok());
    // A site outside Ω, a bad ε.
    let err = sys.factor(&e, 1.0, &[[0.5, 1.5]]).err().unwrap();
    assert_eq!(err.place(), "points[0]");
    assert!(sys.factor(&e, 0.0, &[]).is_err());
    assert!(sys.factor(&e, f64::INFINITY, &[]).is_err());
    assert!(Partition::uniform(0, 3, false).is_err());
    assert!(Partition::new(vec![0.0, 0.5, 0.5, 1.0], vec![0.0, 1.0], false).is_err());
}

/// Seed 004 §6: `f` and `g`, the circle `h(x, 0.5)`, an 8 × 4 partition.
fn section6(a: f64, eps: f64, points: bool, nx: usize, periodic: bool) -> Blend {
    let f = Cylinder::new(Vec3::new(-1.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 0.0), 2.0).unwrap();
    let g = Cylinder::new(Vec3::new(1.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 0.0), 1.0).unwrap();
    let (sites, values) = if points {
        (0..9)
            .map(|i| {
                let x = i as f64 / 9.0;
                let t = crate::TAU * x;
                ([x, 0.5], Vec3::new(0.0, 0.5 * t.cos(), 0.5 * t.sin()))
            })
            .unzip()
    } else {
        (Vec::new(), Vec::new())
    };
    blend(&BlendProblem {
        start: Join {
            surface: &f,
            from: [0.0, 1.0],
            to: [1.0, 1.0],
            cross: [0.0, 1.0],
        },
        end: Join {
            surface: &g,
            from: [0.0, 0.0],
            to: [1.0, 0.0],
            cross: [0.0, 1.0],
        },
        nx,
        ny: nx / 2,
        periodic,
        energy: Energy::section6(a).unwrap(),
        epsilon: eps,
        sites,
        values,
    })
    .unwrap()
}

#[test]
fn section_6_blends_join_to_the_order_the_hermite_edges_allow() {
    // The edge trace is the cubic Hermite interpolant of the primary's boundary circle (radius
    // r, parameter speed 2πr): |e| ≤ h⁴/384 · max|c⁗| and |e'| ≤ √3/216 · h³ · max|c⁗|, with
    // |c⁗| ≤ √2 r (2π)⁴ for the vector. The cross derivative (the constant axis) is
    // interpolated exactly.
    let tau4 = crate::TAU.powi(4);
    let cases = [
        ("A = ∅, ε = 1, a = 1", 1.0, 1.0, false),
        ("A = ∅, ε = 1, a = 10", 10.0, 1.0, false),
        ("9 points, ε = 1e-3, a = 10", 10.0, 1e-3, true),
        ("9 points, ε = 1e-5, a = 10", 10.0, 1e-5, true),
    ];
    let mut max_dist = Vec::new();
    for periodic in [false, true] {
        for &(name, a, eps, points) in &cases {
            let b = section6(a, eps, points, 8, periodic);
            let r = &b.report;
            let h: f64 = 1.0 / 8.0;
            for (join, radius) in [(&r.start, 2.0), (&r.end, 1.0)] {
                let c4 = 2f64.sqrt() * radius * tau4;
                let g0_bound = h.powi(4) / 384.0 * c4;
                let d1 = 3f64.sqrt() / 216.0 * h.powi(3) * c4;
                let g1_bound = (d1 / (crate::TAU * radius - d1)).asin();
                assert!(join.g0 <= g0_bound, "{name}: G0 {} > {g0_bound}", join.g0);
                assert!(join.g1 <= g1_bound, "{name}: G1 {} > {g1_bound}", join.g1);
                assert!(join.cross < 1e-13, "{name}: C¹ {}", join.cross);
            }
            let d = r.point_distances.iter().cloned().fold(0.0, f64::max);
            eprintln!(
                "{name} (periodic {periodic}): G0 {:.2e} / {:.2e}, G1 {:.2e} / {:.2e} rad, \
                 max distance to the 9 points {d:.3e}, seam {:?}",
                r.start.g0, r.end.g0, r.start.g1, r.end.g1, r.seam_gap
            );
            if points {
                max_dist.push(d);
            }
            assert_eq!(r.seam_gap.is_some(), !periodic);
        }
    }
    // Smaller ε: closer to the points.
    assert!(
        max_dist[1] < max_dist[0] / 10.0 && max_dist[3] < max_dist[2] / 10.0,
        "{max_dist:?}"
    );
    // Refinement along the joins: G0 falls like h⁴, G1 like h³.
    let (c, f) = (
        section6(10.0, 1e-3, true, 8, true),
        section6(10.0, 1e-3, true, 16, true),
    );
    let g0_order = (c.report.start.g0 / f.report.start.g0).log2();
    let g1_order = (c.report.start.g1 / f.report.start.g1).log2();
    eprintln!("join orders: G0 {g0_order:.2}, G1 {g1_order:.2}");
    assert!(g0_order >= 3.7 && g1_order >= 2.7, "{g0_order} {g1_order}");
}

#[test]
fn periodic_blends_need_closed_joins() {
    let plane = Plane::new(Vec3::zeros(), Vec3::x(), Vec3::y()).unwrap();
    let up = Plane::new(Vec3::new(0.0, 0.0, 1.0), Vec3::x(), Vec3::y()).unwrap();
    let problem = |periodic| BlendProblem {
        start: Join {
            surface: &plane,
            from: [0.0, 1.0],
            to: [1.0, 1.0],
            cross: [0.0, 1.0],
        },
        end: Join {
            surface: &up,
            from: [0.0, 0.0],
            to: [1.0, 0.0],
            cross: [0.0, 1.0],
        },
        nx: 4,
        ny: 2,
        periodic,
        energy: Energy::section6(1.0).unwrap(),
        epsilon: 1.0,
        sites: vec![],
        values: vec![],
    };
    let err = blend(&problem(true)).err().unwrap();
    assert_eq!(err.place(), "periodic");
    let ok = blend(&problem(false)).unwrap();
    assert_eq!(ok.report.seam_gap, None);
    assert!(ok.report.start.g0 < 1e-14 && ok.report.end.g1 < 1e-14);
    let mut bad = problem(false);
    bad.start.cross = [1.0, 0.0];
    assert_eq!(blend(&bad).err().unwrap().place(), "start.cross");
}
