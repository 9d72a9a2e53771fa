use super::export::{iges_timestamp, to_iges, to_json, IgesOptions};
use super::*;
use crate::spline::knots::cox_de_boor;
use crate::Vec3;
use num_traits::Zero;
use rand::{rngs::StdRng, Rng, SeedableRng};

type Q = BigRational;

fn q(n: i64, d: i64) -> Q {
    Q::new(n.into(), d.into())
}

fn zero_q(x: &Q) -> bool {
    Zero::is_zero(x)
}

/// Unclamped uniform knots `0, 1, …` (seed 003 Examples 1 and 2, h = 1).
fn uniform<T: Scalar>(p: usize, count: usize) -> Direction<T> {
    Direction {
        degree: p,
        knots: (0..count + p + 1).map(|k| T::int(k as i64)).collect(),
    }
}

/// A random knot vector of degree `p` with `spans` spans: clamped or not, uneven dyadic knots,
/// sometimes a repeated interior knot (exact in f64 and in rationals).
fn random_direction<T: Scalar>(rng: &mut StdRng, p: usize, spans: usize) -> Direction<T> {
    let clamped = rng.gen_bool(0.5);
    let mut knots = Vec::new();
    let mut t = 0i64;
    let push = |knots: &mut Vec<T>, t: i64| knots.push(T::int(t) / T::int(8));
    if clamped {
        for _ in 0..p {
            push(&mut knots, 0);
        }
    } else {
        for _ in 0..p {
            push(&mut knots, t);
            t += rng.gen_range(1..6);
        }
    }
    push(&mut knots, t);
    for s in 0..spans {
        t += rng.gen_range(1..9);
        push(&mut knots, t);
        if s + 1 < spans && p >= 2 && rng.gen_bool(0.2) {
            push(&mut knots, t); // a double interior knot
        }
    }
    for _ in 0..p {
        if !clamped {
            t += rng.gen_range(1..6);
        }
        push(&mut knots, t);
    }
    Direction { degree: p, knots }
}

fn random_operator(rng: &mut StdRng, fourth: bool) -> Operator {
    let mut c = || rng.gen_range(-4i32..=4) as f64 / 2.0;
    if fourth {
        Operator::fourth(c(), c(), c(), c(), c())
    } else {
        Operator::Second {
            a: c(),
            b: c(),
            c: c(),
            d: c(),
            e: c(),
            f: c(),
            g: crate::Vec3::new(c(), c(), c()),
        }
    }
}

/// A random net solving the PDE: a random point `x0 + N y` of the solution set of the residual
/// equations, with `y` of small dyadic integers (exact in rational mode): `None` when the PDE has
/// no solution in the space.
fn random_solution<T: Solve>(
    rng: &mut StdRng,
    u: &Direction<T>,
    v: &Direction<T>,
    op: &Operator,
) -> Option<Vec<Point<T>>> {
    let (a, b, _) = assemble(u, v, op);
    let aff = T::affine(&a, &b).unwrap();
    if !aff.inconsistent.is_empty() {
        return None;
    }
    let n = a.cols;
    let mut net = Vec::with_capacity(n);
    let ys: Vec<[T; 3]> = (0..aff.null.cols)
        .map(|_| [(); 3].map(|_| T::int(rng.gen_range(-16..=16)) / T::int(2)))
        .collect();
    for c in 0..n {
        let mut p = [
            aff.x0.at(c, 0).clone(),
            aff.x0.at(c, 1).clone(),
            aff.x0.at(c, 2).clone(),
        ];
        for (k, y) in ys.iter().enumerate() {
            for d in 0..3 {
                p[d] = p[d].clone() + aff.null.at(c, k).clone() * y[d].clone();
            }
        }
        net.push(p);
    }
    Some(net)
}

/// `|L x − g|` at `(u, v)` relative to the natural size of the terms:
/// `Σ_k |c_k| · max|P| · (p/h_min,u)^{α_k} (q/h_min,v)^{β_k} + |g|`, which bounds every
/// `|c_k D_k x|` (derivatives of a B-spline are differences of control points over knot gaps);
/// rounding in the evaluation is a modest multiple of ε times it.
fn relative_residual(net: &SplineNet<f64>, u: f64, v: f64) -> f64 {
    let r = net.residual(&u, &v);
    let mut scale = net.operator.rhs().amax();
    for (w, o) in net.operator.terms() {
        scale += w.abs() * natural_scale(net, o);
    }
    r.iter().fold(0.0f64, |m, x| m.max(x.abs())) / scale.max(f64::MIN_POSITIVE)
}

/// `max|P| · (p/h_min,u)^α (q/h_min,v)^β`: a bound on the size of `∂u^α ∂v^β x`.
fn natural_scale(net: &SplineNet<f64>, o: [usize; 2]) -> f64 {
    let hmin = |d: &Direction<f64>| {
        d.knots
            .windows(2)
            .map(|w| w[1] - w[0])
            .filter(|&h| h > 0.0)
            .fold(f64::INFINITY, f64::min)
    };
    let (hu, hv) = (hmin(&net.u), hmin(&net.v));
    let pmax = net
        .control
        .iter()
        .flatten()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    pmax * (net.u.degree as f64 / hu).powi(o[0] as i32)
        * (net.v.degree as f64 / hv).powi(o[1] as i32)
}

#[test]
fn span_polynomials_agree_with_the_pointwise_recursion_exactly() {
    let mut rng = StdRng::seed_from_u64(1);
    for case in 0..40 {
        let p = 1 + case % 5;
        let dir: Direction<Q> = random_direction(&mut rng, p, 1 + case % 4);
        dir.check("u").unwrap();
        for span in dir.spans() {
            for _ in 0..3 {
                let s = q(rng.gen_range(0..=64), 64);
                let u = dir.knots[span.k].clone() + s.clone() * span.h.clone();
                let (k, ders) = dir.basis_derivatives_at(&u, p + 1);
                // At a knot the pointwise evaluator may pick the next span; compare values only
                // where both describe the same span.
                if k != span.k {
                    continue;
                }
                let mut sum = q(0, 1);
                for d in 0..=p + 1 {
                    for (r, poly) in span.polys.iter().enumerate() {
                        let mut scale = q(1, 1);
                        for _ in 0..d {
                            scale /= span.h.clone();
                        }
                        let dp = basis_poly_derivative(poly, d);
                        let val = poly_at(&dp, &s) * scale;
                        assert_eq!(val, ders[d][r], "case {case}: D^{d} N_{}", span.k - p + r);
                        if d == 0 {
                            sum += val;
                        }
                    }
                }
                assert_eq!(sum, q(1, 1), "partition of unity, case {case}");
            }
        }
    }
}

fn basis_poly_derivative(p: &[Q], d: usize) -> Vec<Q> {
    let mut out = p.to_vec();
    for _ in 0..d {
        out = (1..out.len())
            .map(|n| out[n].clone() * q(n as i64, 1))
            .collect();
    }
    out
}

fn poly_at(p: &[Q], s: &Q) -> Q {
    let mut acc = q(0, 1);
    for c in p.iter().rev() {
        acc = acc * s.clone() + c.clone();
    }
    acc
}

/// Random spaces, operators and fixed rings taken from a random exact solution: the solve keeps
/// the fixed points, and the residual of the returned net vanishes to rounding at random points.
#[test]
fn residual_of_every_solution_vanishes_in_f64() {
    let mut rng = StdRng::seed_from_u64(2);
    let mut solved = 0;
    for case in 0..60 {
        let fourth = case % 2 == 1;
        let (p, qd) = if fourth {
            (rng.gen_range(3..=6), rng.gen_range(3..=6))
        } else {
            (rng.gen_range(2..=4), rng.gen_range(2..=4))
        };
        let (su, sv) = (rng.gen_range(1..=3), rng.gen_range(1..=3));
        let u: Direction<f64> = random_direction(&mut rng, p, su);
        let v: Direction<f64> = random_direction(&mut rng, qd, sv);
        let op = random_operator(&mut rng, fourth);
        let Some(truth) = random_solution(&mut rng, &u, &v, &op) else {
            continue;
        };
        let nv = v.count();
        let rings = if fourth { 2 } else { 1 };
        let fixed: Vec<([usize; 2], Point<f64>)> = ring_indices([u.count() - 1, nv - 1], rings)
            .into_iter()
            .map(|[i, j]| ([i, j], truth[i * nv + j]))
            .collect();
        let net = solve(&SplineProblem {
            u: u.clone(),
            v: v.clone(),
            operator: op.clone(),
            fixed: fixed.clone(),
        })
        .unwrap_or_else(|e| panic!("case {case}: {e}"));
        for ([i, j], x) in &fixed {
            assert_eq!(
                net.control_point(*i, *j),
                x,
                "case {case}: fixed point kept"
            );
        }
        let (u0, u1) = u.domain();
        let (v0, v1) = v.domain();
        for _ in 0..20 {
            let (s, t) = (rng.gen_range(u0..=u1), rng.gen_range(v0..=v1));
            let r = relative_residual(&net, s, t);
            assert!(
                r <= 1e-10,
                "case {case} {}: residual {r:e} at ({s}, {t})",
                op.describe()
            );
        }
        solved += 1;
    }
    assert!(solved >= 50, "only {solved} cases had solutions");
}

/// The same in exact arithmetic: the residual at random rational points is exactly zero, and the
/// f64 solve of the same problem agrees with the exact one (rank, determined points, values).
#[test]
fn residual_of_exact_solutions_is_exactly_zero() {
    let mut rng = StdRng::seed_from_u64(3);
    for case in 0..6 {
        let fourth = case % 2 == 1;
        let (p, qd) = if fourth { (4, 3) } else { (3, 2) };
        let u: Direction<Q> = random_direction(&mut rng, p, 1 + case % 2);
        let v: Direction<Q> = random_direction(&mut rng, qd, 1 + (case / 2) % 2);
        let op = random_operator(&mut rng, fourth);
        let nv = v.count();
        let Some(truth) = random_solution(&mut rng, &u, &v, &op) else {
            continue;
        };
        let rings = if fourth { 2 } else { 1 };
        let fixed: Vec<([usize; 2], Point<Q>)> = ring_indices([u.count() - 1, nv - 1], rings)
            .into_iter()
            .map(|[i, j]| ([i, j], truth[i * nv + j].clone()))
            .collect();
        let problem = SplineProblem {
            u: u.clone(),
            v: v.clone(),
            operator: op.clone(),
            fixed,
        };
        let net = solve(&problem).unwrap();
        let (u0, u1) = u.domain();
        let (v0, v1) = v.domain();
        for _ in 0..6 {
            let s = u0.clone() + (u1.clone() - u0.clone()) * q(rng.gen_range(0..=97), 97);
            let t = v0.clone() + (v1.clone() - v0.clone()) * q(rng.gen_range(0..=89), 89);
            let r = net.residual(&s, &t);
            assert!(r.iter().all(zero_q), "case {case}: residual {:?}", r);
        }
        let to_f = |d: &Direction<Q>| Direction {
            degree: d.degree,
            knots: d.knots.iter().map(|x| x.to_f64()).collect(),
        };
        let fproblem = SplineProblem {
            u: to_f(&u),
            v: to_f(&v),
            operator: op,
            fixed: problem
                .fixed
                .iter()
                .map(|(ij, x)| (*ij, [x[0].to_f64(), x[1].to_f64(), x[2].to_f64()]))
                .collect(),
        };
        let fnet = solve(&fproblem).unwrap();
        assert_eq!(fnet.report.rank, net.report.rank, "case {case}");
        assert_eq!(fnet.report.freedom, net.report.freedom, "case {case}");
        assert_eq!(fnet.report.determined, net.report.determined, "case {case}");
        let scale = net
            .control
            .iter()
            .flatten()
            .fold(1.0f64, |m, x| m.max(x.to_f64().abs()));
        for (a, b) in fnet.control.iter().zip(&net.control) {
            for d in 0..3 {
                assert!(
                    (a[d] - b[d].to_f64()).abs() <= 1e-9 * scale,
                    "case {case}: {} vs {}",
                    a[d],
                    b[d].to_text()
                );
            }
        }
    }
}

/// Seed 003 Example 1: the printed control net, `P_ij = [i+1, j+1, z_ij]`.
fn example1_net() -> Vec<Point<Q>> {
    let z = [
        [q(1, 1), q(-8, 1), q(8, 1), q(1, 1)],
        [q(8, 1), q(-5, 9), q(119, 9), q(4, 3)],
        [q(-8, 1), q(-121, 9), q(7, 9), q(-40, 3)],
        [q(1, 1), q(4, 3), q(56, 3), q(5, 1)],
    ];
    let mut net = Vec::new();
    for (i, row) in z.iter().enumerate() {
        for (j, zz) in row.iter().enumerate() {
            net.push([q(i as i64 + 1, 1), q(j as i64 + 1, 1), zz.clone()]);
        }
    }
    net
}

/// Residual coefficients `A x` of one coordinate of a net.
fn residual_coefficients(a: &Mat<Q>, net: &[Point<Q>], d: usize) -> Vec<Q> {
    let x = Mat {
        rows: net.len(),
        cols: 1,
        data: net.iter().map(|p| p[d].clone()).collect(),
    };
    a.mul(&x).data
}

/// Seed 003 Example 1 (x_uu − 2x_uv + x_vv = 0, one bicubic span, uniform knots h = 1): 13
/// residual coefficients as printed, but of rank 9, not 12; the printed net violates three of
/// them in z; and the four printed boundary points leave a 3-dimensional family of solutions.
#[test]
fn seed003_example1_as_checked() {
    let u = uniform::<Q>(3, 4);
    let op = Operator::second(1.0, -2.0, 1.0);
    let (a, _, labels) = assemble(&u, &u, &op);
    assert_eq!(a.rows, 13);
    assert_eq!(Q::affine(&a, &Mat::zeros(13, 0)).unwrap().rank, 9);
    let net = example1_net();
    for d in 0..2 {
        assert!(
            residual_coefficients(&a, &net, d).iter().all(zero_q),
            "x, y are linear"
        );
    }
    let rz = residual_coefficients(&a, &net, 2);
    let bad: Vec<([usize; 2], Q)> = rz
        .iter()
        .zip(&labels)
        .filter(|(x, _)| !zero_q(x))
        .map(|(x, l)| (l.monomial, x.clone()))
        .collect();
    assert_eq!(
        bad,
        vec![([0, 0], q(10, 9)), ([0, 1], q(-40, 1)), ([1, 0], q(40, 1))],
        "residual coefficients of z in s = u − 3, t = v − 3"
    );
    // From the four printed points P_{0,j}: rank 9 in 12 unknowns, nothing determined.
    let fixed = (0..4).map(|j| ([0, j], net[j].clone())).collect();
    let sol = solve(&SplineProblem {
        u: u.clone(),
        v: u,
        operator: op,
        fixed,
    })
    .unwrap();
    assert_eq!((sol.report.rank, sol.report.freedom), (9, 3));
    assert!(sol.report.determined.is_empty());
    // The functional ∫|x_u − x_v|² picks x = F(u + v): P_ij = P_{0,i+j} continued.
    assert_eq!(sol.control_point(1, 0), sol.control_point(0, 1));
    assert_eq!(sol.control_point(2, 1), sol.control_point(0, 3));
}

/// Seed 003 Example 2: printed z of `P_ij = [i+1, j+1, z_ij]`; `None` for `P_{1,1}`, which the
/// paper does not print.
fn example2_z() -> Vec<Vec<Option<Q>>> {
    let i = |n: i64| Some(q(n, 1));
    let t = |n: i64| Some(q(n, 3));
    vec![
        vec![i(0), i(10), i(10), i(-10), i(-10), i(0)],
        vec![i(-10), None, i(-1), i(-27), t(-106), t(-80)],
        vec![i(-10), i(1), i(0), i(-33), t(-164), t(-175)],
        vec![i(10), i(27), i(33), i(0), i(-30), i(-45)],
        vec![i(10), t(106), t(164), i(30), i(0), i(-20)],
        vec![i(0), t(80), t(175), i(45), i(20), i(0)],
    ]
}

/// Seed 003 Example 2 (one biquintic span, uniform knots): no value of the unprinted `P_{1,1}`
/// makes the printed net a solution, neither of the biharmonic equation (2 coefficients fail)
/// nor of the literal `x_uuuu + 2x_uuuv + x_uuvv = 0` (20 fail); the residual has 24 non-zero
/// coefficients of rank 16 (not 26), and the 11 printed boundary points leave 9 free directions.
#[test]
fn seed003_example2_as_checked() {
    let u = uniform::<Q>(5, 6);
    let z = example2_z();
    let printed = || {
        let mut fixed = Vec::new();
        for i in 0..6 {
            for j in 0..6 {
                if let Some(zz) = &z[i][j] {
                    fixed.push(([i, j], [q(i as i64 + 1, 1), q(j as i64 + 1, 1), zz.clone()]));
                }
            }
        }
        fixed
    };
    for (op, rows, failing) in [
        (Operator::biharmonic(), 24, 2),
        (Operator::fourth(1.0, 2.0, 1.0, 0.0, 0.0), 21, 20),
    ] {
        let (a, _, _) = assemble(&u, &u, &op);
        assert_eq!(a.rows, rows);
        assert_eq!(Q::affine(&a, &Mat::zeros(rows, 0)).unwrap().rank, 16);
        let err = solve(&SplineProblem {
            u: u.clone(),
            v: u.clone(),
            operator: op,
            fixed: printed(),
        })
        .unwrap_err()
        .to_string();
        assert!(
            err.contains(&format!("{failing} equation(s) cannot hold")),
            "{err}"
        );
    }
    // The 11 given boundary points: rank 16 in 25 unknowns.
    let fixed: Vec<_> = printed()
        .into_iter()
        .filter(|([i, j], _)| *i == 0 || *j == 0)
        .collect();
    assert_eq!(fixed.len(), 11);
    let sol = solve(&SplineProblem {
        u: u.clone(),
        v: u,
        operator: Operator::biharmonic(),
        fixed,
    })
    .unwrap();
    assert_eq!((sol.report.rank, sol.report.freedom), (16, 9));
}

fn random_points_q(rng: &mut StdRng, n: usize) -> Vec<Point<Q>> {
    (0..n)
        .map(|_| {
            [
                q(rng.gen_range(-20..=20), 4),
                q(rng.gen_range(-20..=20), 4),
                q(rng.gen_range(-20..=20), 4),
            ]
        })
        .collect()
}

/// A control-point mask of book §8.3.
type MaskFn = fn([usize; 2], &[Point<Q>], usize, usize) -> Point<Q>;

/// Mask equations `mask(net) = 0` over the index set, as a matrix in the `(n+1)(m+1)` control
/// points (one coordinate), built by applying the mask to unit nets.
fn mask_matrix(degree: [usize; 2], mask: MaskFn, from: usize) -> Mat<Q> {
    let [n, m] = degree;
    let count = (n + 1) * (m + 1);
    let idx: Vec<(usize, usize)> = (from..=n)
        .flat_map(|i| (from..=m).map(move |j| (i, j)))
        .collect();
    let mut a = Mat::zeros(idx.len(), count);
    for c in 0..count {
        let mut net = vec![[q(0, 1), q(0, 1), q(0, 1)]; count];
        net[c][0] = q(1, 1);
        for (r, &(i, j)) in idx.iter().enumerate() {
            *a.at_mut(r, c) = mask(degree, &net, i, j)[0].clone();
        }
    }
    a
}

/// Book §8.3: the first and last rows determine a harmonic Bézier surface (any rows for odd
/// degree; rows meeting one linear condition for even degree); the mask of Eq. (8.10) (stray `b` removed) vanishes on it
/// at every `(i, j) ∈ {0..n}²`, and its equations span the same space as the engine's. Over the
/// printed range `{1..n}²` they do not.
#[test]
fn harmonic_bezier_surfaces_and_the_mask_of_eq_8_10() {
    let mut rng = StdRng::seed_from_u64(4);
    for n in 2..=5 {
        let dir = bezier_direction::<Q>(n);
        let truth = random_solution(&mut rng, &dir, &dir, &Operator::laplace()).unwrap();
        let first = truth[..=n].to_vec();
        let last = truth[n * (n + 1)..].to_vec();
        let net = harmonic_bezier([n, n], &first, &last).unwrap();
        // Arbitrary rows: for even n one linear condition ties the two rows (for n = 2: equal
        // v² coefficients); for odd n any two rows give exactly one harmonic net.
        let mut other = last.clone();
        other[n][2] = other[n][2].clone() + q(1, 1);
        let r = harmonic_bezier([n, n], &first, &other);
        // Found: even n needs compatible rows, odd n takes any rows.
        if n % 2 == 0 {
            assert!(r
                .unwrap_err()
                .to_string()
                .contains("1 equation(s) cannot hold"));
        } else {
            assert_eq!(r.unwrap().report.freedom, 0);
        }
        for i in 0..=n {
            for j in 0..=n {
                let m = harmonic_mask([n, n], &net.control, i, j);
                assert!(m.iter().all(zero_q), "n = {n}: mask at ({i}, {j})");
            }
        }
        let r = net.residual(&q(1, 3), &q(2, 7));
        assert!(r.iter().all(zero_q));
        let (a, _, _) = assemble(&dir, &dir, &Operator::laplace());
        let engine_rank = Q::affine(&a, &Mat::zeros(a.rows, 0)).unwrap().rank;
        let full = mask_matrix([n, n], harmonic_mask, 0);
        let printed = mask_matrix([n, n], harmonic_mask, 1);
        let rank = |m: &Mat<Q>| Q::affine(m, &Mat::zeros(m.rows, 0)).unwrap().rank;
        assert_eq!(rank(&full), engine_rank, "n = {n}");
        // Same row space: stacking adds nothing.
        let mut both = a.clone();
        both.data.extend(full.data.clone());
        both.rows += full.rows;
        assert_eq!(rank(&both), engine_rank);
        assert!(
            rank(&printed) < engine_rank,
            "n = {n}: i, j ∈ 1..n misses equations"
        );
    }
}

/// Biharmonic Bézier surfaces: the boundary ring alone determines them; two rings taken from a
/// biharmonic net reproduce it, two arbitrary rings contradict the PDE. Eq. (8.11)'s mask
/// vanishes on the solutions for all `(i, j) ∈ {0..n} × {0..m}` and spans the engine's equations.
#[test]
fn biharmonic_bezier_from_two_rings_and_the_mask_of_eq_8_11() {
    let mut rng = StdRng::seed_from_u64(5);
    for (n, m) in [(4, 4), (5, 4), (5, 6)] {
        let (du, dv) = (bezier_direction::<Q>(n), bezier_direction::<Q>(m));
        let ring = random_solution(&mut rng, &du, &dv, &Operator::biharmonic()).unwrap();
        let net = bezier_from_rings([n, m], Operator::biharmonic(), 2, &ring).unwrap();
        // Arbitrary rings are not: a random ring contradicts the PDE.
        let arbitrary = random_points_q(&mut rng, (n + 1) * (m + 1));
        assert!(bezier_from_rings([n, m], Operator::biharmonic(), 2, &arbitrary).is_err());
        assert_eq!(net.report.freedom, 0, "{n} × {m}");
        for i in 0..=n {
            for j in 0..=m {
                let mk = biharmonic_mask([n, m], &net.control, i, j);
                assert!(mk.iter().all(zero_q), "{n} × {m}: mask at ({i}, {j})");
            }
        }
        let (a, _, _) = assemble(&du, &dv, &Operator::biharmonic());
        let rank = |mm: &Mat<Q>| Q::affine(mm, &Mat::zeros(mm.rows, 0)).unwrap().rank;
        assert_eq!(rank(&mask_matrix([n, m], biharmonic_mask, 0)), rank(&a));
        // One ring (the boundary) alone already determines the net, for any boundary (book
        // §8.3: "the knowledge of the boundary … fully determines the entire surface").
        let one = bezier_from_rings([n, m], Operator::biharmonic(), 1, &arbitrary).unwrap();
        assert_eq!(one.report.freedom, 0);
        assert_eq!(one.report.determined.len(), (n - 1) * (m - 1));
        assert!(one.residual(&q(1, 5), &q(3, 4)).iter().all(zero_q));
    }
}

/// The named special cases of seed 003 §5 are the operators they claim, and their solutions from
/// boundary rings have zero residual.
#[test]
fn coons_biharmonic_and_modified_biharmonic() {
    assert_eq!(Operator::coons().terms(), vec![(1.0, [2, 2])]);
    assert_eq!(
        Operator::biharmonic().terms(),
        vec![(1.0, [4, 0]), (2.0, [2, 2]), (1.0, [0, 4])]
    );
    assert_eq!(
        Operator::modified_biharmonic(0.5).terms(),
        vec![(1.0, [4, 0]), (0.5, [2, 2]), (0.0625, [0, 4])]
    );
    let mut rng = StdRng::seed_from_u64(6);
    let dir = clamped_uniform::<Q>(3, 2);
    for (op, rings) in [
        (Operator::coons(), 1),
        (Operator::biharmonic(), 2),
        (Operator::modified_biharmonic(0.5), 2),
    ] {
        let ring = random_points_q(&mut rng, 25);
        let nv = 5;
        let fixed = ring_indices([4, 4], rings)
            .into_iter()
            .map(|[i, j]| ([i, j], ring[i * nv + j].clone()))
            .collect();
        let net = solve(&SplineProblem {
            u: dir.clone(),
            v: dir.clone(),
            operator: op.clone(),
            fixed,
        });
        // Bicubic: x_uuuu = x_vvvv = 0, so a full ring of the biharmonic family over-determines
        // the tangents unless consistent; report which.
        match net {
            Ok(net) => {
                for k in 0..5 {
                    let r = net.residual(&q(k, 4), &q(4 - k, 5));
                    assert!(r.iter().all(zero_q), "{}", op.describe());
                }
            }
            Err(e) => assert!(e.to_string().contains("cannot hold"), "{e}"),
        }
    }
    // Coons (x_uuvv = 0) from the boundary ring of a bicubic: consistent for any ring, since
    // x = f(u) + g(v) + bilinear terms spans it; the twist points are chosen by ∫|x_uv|².
    let ring = random_points_q(&mut rng, 16);
    let fixed = ring_indices([3, 3], 1)
        .into_iter()
        .map(|[i, j]| ([i, j], ring[i * 4 + j].clone()))
        .collect();
    let dir = bezier_direction::<Q>(3);
    let net = solve(&SplineProblem {
        u: dir.clone(),
        v: dir,
        operator: Operator::coons(),
        fixed,
    })
    .unwrap();
    assert!(net.residual(&q(1, 3), &q(1, 2)).iter().all(zero_q));
}

#[test]
fn inconsistent_and_bad_input_is_reported_with_its_place() {
    let dir = bezier_direction::<f64>(3);
    // Laplace on a bicubic with the whole boundary fixed at random: contradicts the PDE.
    let mut rng = StdRng::seed_from_u64(7);
    let fixed: Vec<_> = ring_indices([3, 3], 1)
        .into_iter()
        .map(|ij| {
            (
                ij,
                [
                    rng.gen_range(-1.0..1.0),
                    rng.gen_range(-1.0..1.0),
                    rng.gen_range(-1.0..1.0),
                ],
            )
        })
        .collect();
    let e = solve(&SplineProblem {
        u: dir.clone(),
        v: dir.clone(),
        operator: Operator::laplace(),
        fixed: fixed.clone(),
    })
    .unwrap_err();
    assert_eq!(e.place(), "spline.fixed");
    assert!(e.to_string().contains("the coefficient of s^"), "{e}");
    let mut dup = fixed.clone();
    dup.push(fixed[0]);
    let e = solve(&SplineProblem {
        u: dir.clone(),
        v: dir.clone(),
        operator: Operator::laplace(),
        fixed: dup,
    })
    .unwrap_err();
    assert_eq!(e.place(), format!("spline.fixed[{}].index", fixed.len()));
    let e = solve(&SplineProblem {
        u: dir.clone(),
        v: dir.clone(),
        operator: Operator::laplace(),
        fixed: vec![([4, 0], [0.0; 3])],
    })
    .unwrap_err();
    assert!(e.to_string().contains("does not exist"), "{e}");
    let bad = Direction {
        degree: 2,
        knots: vec![0.0, 0.0, 0.0, 1.0, 0.5, 1.0, 1.0],
    };
    let e = solve(&SplineProblem {
        u: bad,
        v: dir.clone(),
        operator: Operator::laplace(),
        fixed: vec![],
    })
    .unwrap_err();
    assert!(e.to_string().contains("knots must not decrease"), "{e}");
    let e = solve(&SplineProblem {
        u: dir.clone(),
        v: dir.clone(),
        operator: Operator::fourth(0.0, 0.0, f64::NAN, 0.0, 0.0),
        fixed: vec![],
    })
    .unwrap_err();
    assert_eq!(e.place(), "spline.operator.c");
    let e = solve(&SplineProblem {
        u: dir.clone(),
        v: dir,
        operator: Operator::fourth(0.0, 0.0, 0.0, 0.0, 0.0),
        fixed: vec![],
    })
    .unwrap_err();
    assert!(e.to_string().contains("every coefficient is zero"), "{e}");
}

/// Reads an IGES file with fixed columns and returns the entity-128 parameters.
fn parse_iges(text: &str) -> Vec<String> {
    let lines: Vec<&str> = text.lines().collect();
    let mut counts = std::collections::BTreeMap::new();
    for (k, l) in lines.iter().enumerate() {
        assert_eq!(l.len(), 80, "line {} is not 80 columns: {l:?}", k + 1);
        let letter = l.as_bytes()[72] as char;
        let seq: usize = l[73..80].trim().parse().unwrap();
        let c = counts.entry(letter).or_insert(0usize);
        *c += 1;
        assert_eq!(seq, *c, "sequence numbers of section {letter}");
    }
    let t = lines.last().unwrap();
    assert_eq!(&t[72..73], "T");
    let field = |s: &str| -> usize { s[1..8].trim().parse().unwrap() };
    assert_eq!(field(&t[0..8]), counts[&'S']);
    assert_eq!(field(&t[8..16]), counts[&'G']);
    assert_eq!(field(&t[16..24]), counts[&'D']);
    assert_eq!(field(&t[24..32]), counts[&'P']);
    let sect = |c: char| lines.iter().filter(move |l| l.as_bytes()[72] as char == c);
    // Global: delimiters as declared.
    let global: String = sect('G').map(|l| &l[..72]).collect::<String>();
    assert!(global.starts_with("1H,,1H;,"), "{global}");
    assert!(global.trim_end().ends_with(';'));
    let d: Vec<&&str> = sect('D').collect();
    assert_eq!(d.len(), 2);
    let de = |l: &str, k: usize| l[8 * k..8 * k + 8].trim().to_string();
    assert_eq!(de(d[0], 0), "128");
    assert_eq!(de(d[1], 0), "128");
    let start: usize = de(d[0], 1).parse().unwrap();
    let count: usize = de(d[1], 3).parse().unwrap();
    let p: Vec<&&str> = sect('P').collect();
    assert_eq!(start, 1);
    assert_eq!(count, p.len());
    let mut data = String::new();
    for l in &p {
        assert_eq!(l[64..72].trim(), "1", "PD back pointer to the DE line");
        data.push_str(&l[..64]);
    }
    let data = data.trim_end();
    assert!(data.ends_with(';'));
    data[..data.len() - 1]
        .split(',')
        .map(|s| s.trim().to_string())
        .collect()
}

/// IGES entity 128 read back by an independent column parser and evaluated by the textbook
/// recursion: points agree with the net's evaluator.
#[test]
fn iges_round_trip_by_an_independent_reader() {
    let mut rng = StdRng::seed_from_u64(8);
    let u: Direction<f64> = random_direction(&mut rng, 3, 3);
    let v: Direction<f64> = random_direction(&mut rng, 2, 2);
    let op = Operator::laplace();
    let truth = random_solution(&mut rng, &u, &v, &op).unwrap();
    let nv = v.count();
    let fixed = ring_indices([u.count() - 1, nv - 1], 1)
        .into_iter()
        .filter(|[i, _]| *i == 0 || *i == u.count() - 1)
        .map(|[i, j]| ([i, j], truth[i * nv + j]))
        .collect();
    let net = solve(&SplineProblem {
        u,
        v,
        operator: op,
        fixed,
    })
    .unwrap();
    let text = to_iges(
        &net,
        &IgesOptions {
            file_name: "t.igs".into(),
            timestamp: iges_timestamp(0),
        },
    )
    .unwrap();
    assert_eq!(iges_timestamp(0), "19700101.000000");
    assert_eq!(iges_timestamp(1_795_340_000), "20261122.093320");
    let f = parse_iges(&text);
    let int = |k: usize| f[k].parse::<usize>().unwrap();
    let real = |k: usize| f[k].replace('D', "E").parse::<f64>().unwrap();
    assert_eq!(f[0], "128");
    let (k1, k2, m1, m2) = (int(1), int(2), int(3), int(4));
    assert_eq!([k1 + 1, k2 + 1], net.report.counts);
    assert_eq!([m1, m2], [net.u.degree, net.v.degree]);
    assert_eq!(
        (int(5), int(6), int(7), int(8), int(9)),
        (0, 0, 1, 0, 0),
        "PROP1..5: open, polynomial, not periodic"
    );
    let mut at = 10;
    let ks: Vec<f64> = (0..k1 + m1 + 2).map(|k| real(at + k)).collect();
    at += ks.len();
    let kt: Vec<f64> = (0..k2 + m2 + 2).map(|k| real(at + k)).collect();
    at += kt.len();
    let w: Vec<f64> = (0..(k1 + 1) * (k2 + 1)).map(|k| real(at + k)).collect();
    assert!(w.iter().all(|&x| x == 1.0));
    at += w.len();
    let pts: Vec<[f64; 3]> = (0..(k1 + 1) * (k2 + 1))
        .map(|k| [real(at + 3 * k), real(at + 3 * k + 1), real(at + 3 * k + 2)])
        .collect();
    at += 3 * pts.len();
    let (u0, u1, v0, v1) = (real(at), real(at + 1), real(at + 2), real(at + 3));
    assert_eq!(f.len(), at + 4);
    assert_eq!((u0, u1), net.u.domain());
    assert_eq!((v0, v1), net.v.domain());
    for _ in 0..25 {
        let (s, t) = (rng.gen_range(u0..=u1), rng.gen_range(v0..=v1));
        let mut x = [0.0; 3];
        for i in 0..=k1 {
            let bi = cox_de_boor(&ks, i, m1, s, u1);
            for j in 0..=k2 {
                let b = bi * cox_de_boor(&kt, j, m2, t, v1);
                // IGES lists control points with the first index fastest.
                let c = pts[j * (k1 + 1) + i];
                for d in 0..3 {
                    x[d] += b * c[d];
                }
            }
        }
        let ours = net.derivative(&s, &t, 0, 0);
        for d in 0..3 {
            assert!(
                (x[d] - ours[d]).abs() <= 1e-12 * (1.0 + ours[d].abs()),
                "{x:?} vs {ours:?}"
            );
        }
    }
}

#[test]
fn json_has_net_report_and_exact_fractions() {
    let dir = bezier_direction::<Q>(2);
    // z = (u² − v²)/2 on [0, 1]²: Bézier ordinates of u²/2 are 0, 0, 1/2 (degree 2).
    let first = vec![
        [q(0, 1), q(0, 1), q(0, 1)],
        [q(0, 1), q(1, 2), q(0, 1)],
        [q(0, 1), q(1, 1), q(-1, 2)],
    ];
    let last = vec![
        [q(1, 1), q(0, 1), q(1, 2)],
        [q(1, 1), q(1, 2), q(1, 2)],
        [q(1, 1), q(1, 1), q(0, 1)],
    ];
    let net = harmonic_bezier([2, 2], &first, &last).unwrap();
    let j = to_json(&net);
    assert_eq!(j["degree"], serde_json::json!([2, 2]));
    assert_eq!(
        j["knots_u"],
        serde_json::json!([0.0, 0.0, 0.0, 1.0, 1.0, 1.0])
    );
    assert_eq!(j["report"]["freedom"], 0);
    assert_eq!(j["control"].as_array().unwrap().len(), 3);
    // x_uu + x_vv = 0 on the 3×3 net: the middle row is the mean of the outer rows minus the
    // second difference across, all in thirds.
    // Middle row: x = 1/2, z = 1/4·(0 + 0) + … : the exact Bézier net of (u² − v²)/2.
    assert_eq!(
        j["control_exact"][1][0],
        serde_json::json!(["1/2", "0", "0"])
    );
    assert_eq!(
        j["control_exact"][1][2],
        serde_json::json!(["1/2", "1", "-1/2"])
    );
    let dir_ok = dir == net.u;
    assert!(dir_ok);
}

/// The net is a `Surface`: positions and partials (mapped to u ∈ [0, 1]) agree with finite
/// differences (its tessellation: `pdeshape-design`'s `lower_layers` tests).
#[test]
fn surface_partials_and_tessellation() {
    let mut rng = StdRng::seed_from_u64(9);
    let u: Direction<f64> = random_direction(&mut rng, 3, 2);
    let v: Direction<f64> = random_direction(&mut rng, 3, 2);
    let op = Operator::biharmonic();
    let truth = random_solution(&mut rng, &u, &v, &op).unwrap();
    let fixed = ring_indices([u.count() - 1, v.count() - 1], 2)
        .into_iter()
        .map(|[i, j]| ([i, j], truth[i * v.count() + j]))
        .collect();
    let net = solve(&SplineProblem {
        u,
        v,
        operator: op,
        fixed,
    })
    .unwrap();
    use crate::surface::{Surface, VDomain};
    let VDomain::Interval(v0, v1) = net.v_domain() else {
        panic!()
    };
    let (s, t) = (0.37, v0 + 0.61 * (v1 - v0));
    let p = net.partials(s, t);
    let h = 1e-5;
    let fd_u = (Surface::point(&net, s + h, t) - Surface::point(&net, s - h, t)) / (2.0 * h);
    let fd_v = (Surface::point(&net, s, t + h) - Surface::point(&net, s, t - h)) / (2.0 * h);
    // Central differences: error O(h²)·|X'''| ~ 1e-10 · scale.
    let scale = p.x.amax().max(1.0);
    assert!((fd_u - p.xu).amax() < 1e-6 * scale, "{fd_u} {}", p.xu);
    assert!((fd_v - p.xv).amax() < 1e-6 * scale);
    let fd_uv = (net.partials(s, t + h).xu - net.partials(s, t - h).xu) / (2.0 * h);
    assert!((fd_uv - p.xuv).amax() < 1e-6 * scale);
}

/// Knot insertion and degree elevation (of `spline::BSplineSurface`) leave solutions solutions:
/// the refined surface has the same residual (zero) at random points, evaluated by the B-spline
/// surface's own derivatives, which also agree with the net's evaluator before refinement.
#[test]
fn knot_insertion_and_degree_elevation_keep_solutions() {
    let mut rng = StdRng::seed_from_u64(10);
    for case in 0..8 {
        let fourth = case % 2 == 1;
        let (p, qd) = if fourth { (4, 3) } else { (3, 2) };
        let u: Direction<f64> = random_direction(&mut rng, p, 1 + case % 3);
        let v: Direction<f64> = random_direction(&mut rng, qd, 1 + (case / 3) % 2);
        let op = random_operator(&mut rng, fourth);
        let Some(truth) = random_solution(&mut rng, &u, &v, &op) else {
            continue;
        };
        let nv = v.count();
        let fixed = ring_indices([u.count() - 1, nv - 1], if fourth { 2 } else { 1 })
            .into_iter()
            .map(|[i, j]| ([i, j], truth[i * nv + j]))
            .collect();
        let net = solve(&SplineProblem {
            u: u.clone(),
            v: v.clone(),
            operator: op.clone(),
            fixed,
        })
        .unwrap();
        let bs = net.to_bspline().unwrap();
        let (u0, u1) = u.domain();
        let (v0, v1) = v.domain();
        let tu = u0 + (u1 - u0) * rng.gen_range(0.1..0.9);
        let tv = v0 + (v1 - v0) * rng.gen_range(0.1..0.9);
        let refined = bs
            .insert_knot_u(tu)
            .and_then(|s| s.insert_knot_v(tv))
            .and_then(|s| s.elevate_degree_u())
            .and_then(|s| s.elevate_degree_v())
            .unwrap();
        assert_eq!(refined.degree(), [p + 1, qd + 1]);
        // The refined net as a net of the refined space: its residual, by our evaluator.
        let rnet = SplineNet {
            u: Direction {
                degree: p + 1,
                knots: refined.knots_u().to_vec(),
            },
            v: Direction {
                degree: qd + 1,
                knots: refined.knots_v().to_vec(),
            },
            operator: op.clone(),
            control: refined.control().iter().map(|x| [x.x, x.y, x.z]).collect(),
            report: net.report.clone(),
        };
        for _ in 0..10 {
            let (s, t) = (rng.gen_range(u0..=u1), rng.gen_range(v0..=v1));
            for (_, o) in op.terms() {
                let a = bs.derivative(s, t, o[0], o[1]);
                let b = net.derivative(&s, &t, o[0], o[1]);
                let c = refined.derivative(s, t, o[0], o[1]);
                // Natural size of this derivative (see `relative_residual`).
                let scale = natural_scale(&net, o);
                assert!(
                    (a - Vec3::new(b[0], b[1], b[2])).amax() <= 1e-12 * scale,
                    "case {case}: evaluators differ"
                );
                assert!(
                    (a - c).amax() <= 1e-12 * scale,
                    "case {case}: refinement changed the surface: {a} {c} {scale}"
                );
            }
            let r = relative_residual(&rnet, s, t);
            assert!(r <= 1e-10, "case {case}: refined residual {r:e}");
        }
    }
}

/// Which degrees let an arbitrary boundary ring determine a biharmonic Bézier patch (existence and
/// uniqueness), and the f64 solve agrees with the exact one on such a patch (5 × 5).
#[test]
fn biharmonic_bezier_from_an_arbitrary_boundary() {
    let mut rng = StdRng::seed_from_u64(11);
    for n in 3..=7usize {
        for m in 3..=7usize {
            let ring = random_points_q(&mut rng, (n + 1) * (m + 1));
            let r = bezier_from_rings([n, m], Operator::biharmonic(), 1, &ring);
            let bad = (n.min(m) <= 4) && (n.max(m) >= 6);
            match r {
                Ok(net) => {
                    assert!(!bad, "{n} × {m}");
                    assert_eq!(net.report.freedom, 0);
                }
                Err(e) => assert!(bad, "{n} × {m}: {e}"),
            }
        }
    }
    let ring: Vec<Point<f64>> = (0..36)
        .map(|_| [(); 3].map(|_| rng.gen_range(-1.0..1.0)))
        .collect();
    let ringq: Vec<Point<Q>> = ring
        .iter()
        .map(|p| p.map(|x| Q::from_float(x).unwrap()))
        .collect();
    let exact = bezier_from_rings([5, 5], Operator::biharmonic(), 1, &ringq)
        .unwrap()
        .to_f64();
    let float = bezier_from_rings([5, 5], Operator::biharmonic(), 1, &ring).unwrap();
    for (a, b) in float.control.iter().zip(&exact.control) {
        for d in 0..3 {
            // κ ≈ 2·10⁴ for this system: agreement to 1e-10 leaves a margin of 100.
            assert!((a[d] - b[d]).abs() < 1e-10, "{} vs {}", a[d], b[d]);
        }
    }
}

/// A system the capped SVD cannot decompose (here: a non-finite entry) is an error that says
/// so; there is no fallback to an SVD without an iteration cap.
#[test]
fn a_system_the_capped_svd_cannot_decompose_is_an_error() {
    let mut a: Mat<f64> = Mat::zeros(3, 2);
    *a.at_mut(0, 0) = 1.0;
    *a.at_mut(1, 1) = f64::NAN;
    *a.at_mut(2, 0) = 2.0;
    let e = f64::affine(&a, &Mat::zeros(3, 1)).unwrap_err().to_string();
    assert!(e.contains("3 × 2 linear system"), "{e}");
    assert!(e.contains("did not converge within 1000 sweeps"), "{e}");
    // A finite system of the same shape is solved.
    *a.at_mut(1, 1) = 1.0;
    assert_eq!(f64::affine(&a, &Mat::zeros(3, 1)).unwrap().rank, 2);
}

/// A finite system whose SVD needs more sweeps than the cap is the same error, naming the
/// system's size and the cap (a lowered cap stands for a system that does not converge).
#[test]
fn a_system_past_the_svd_iteration_cap_is_an_error_naming_it() {
    let mut a: Mat<f64> = Mat::zeros(7, 6);
    for i in 0..7 {
        for j in 0..6 {
            *a.at_mut(i, j) =
                1.0 / (1.0 + i as f64 + 2.0 * j as f64) + if i == j { 1.0 } else { 0.0 };
        }
    }
    let e = crate::linalg::decomp::with_cap(1, || f64::affine(&a, &Mat::zeros(7, 1)).unwrap_err())
        .to_string();
    assert!(e.contains("7 × 6 linear system"), "{e}");
    assert!(e.contains("did not converge within 1 sweeps"), "{e}");
    assert_eq!(f64::affine(&a, &Mat::zeros(7, 1)).unwrap().rank, 6);
}
