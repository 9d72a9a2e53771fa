use super::*;

/// Ackley's function: global minimum f(0) = 0; a local minimum near every integer point, each
/// at least ≈ 2.6 above it (the nearest, (±1, 0), is at f ≈ 3.57).
fn ackley(x: &[f64]) -> f64 {
    let n = x.len() as f64;
    let r2 = x.iter().map(|xi| xi * xi).sum::<f64>() / n;
    let c = x.iter().map(|xi| (crate::TAU * xi).cos()).sum::<f64>() / n;
    -20.0 * (-0.2 * r2.sqrt()).exp() - c.exp() + std::f64::consts::E + 20.0
}

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

fn opts(seed: u64, evaluations: usize, chains: usize, polish: usize) -> SearchOptions {
    SearchOptions {
        seed,
        evaluations,
        chains,
        polish,
        ..SearchOptions::default()
    }
}

#[test]
fn ackley_global_minimum_found_and_repeatable_across_thread_counts() {
    // Ackley's function has ~10ⁿ local minima on the box; the global one is f(0) = 0. Starting
    // far away near the local minimum (4, −3, 2), annealing must cross the barriers.
    let bounds = [(-5.0, 5.0); 3];
    let start = [4.0, -3.0, 2.0];
    let o = opts(7, 6000, 4, 300);
    let one = in_pool(1, || {
        minimize(&ackley, &bounds, &start, &o, &|_, _| {}).unwrap()
    });
    let two = in_pool(2, || {
        minimize(&ackley, &bounds, &start, &o, &|_, _| {}).unwrap()
    });
    assert_eq!(one.x, two.x, "result depends on the thread count");
    assert_eq!(one.value.to_bits(), two.value.to_bits());
    assert_eq!(one.log, two.log);
    assert!(one.start_value > 9.0, "start {}", one.start_value);
    // Near the minimum f ≈ 4/√3 |x| (a cone), so f < 1e-6 means |x| < 5e-7.
    assert!(one.value < 1e-6, "f = {} at {:?}", one.value, one.x);
    for xi in &one.x {
        assert!(xi.abs() < 1e-6, "x = {:?}", one.x);
    }
    assert!(one.evaluations <= 6000 + 300);
    // Another seed is another search (and finds the minimum too).
    let other = minimize(&ackley, &bounds, &start, &opts(8, 6000, 4, 300), &|_, _| {}).unwrap();
    assert_ne!(other.log, one.log);
    assert!(other.value < 1e-6, "f = {}", other.value);
}

#[test]
fn rosenbrock_polished_to_the_valley_floor() {
    // The curved valley defeats annealing's coarse steps; Nelder–Mead finishes at (1, 1).
    let f = |x: &[f64]| (1.0 - x[0]).powi(2) + 100.0 * (x[1] - x[0] * x[0]).powi(2);
    let r = minimize(
        &f,
        &[(-2.0, 2.0), (-1.0, 3.0)],
        &[-1.5, 2.5],
        &opts(3, 1500, 2, 600),
        &|_, _| {},
    )
    .unwrap();
    assert!(r.value < 1e-12, "f = {} at {:?}", r.value, r.x);
    assert!(
        (r.x[0] - 1.0).abs() < 1e-5 && (r.x[1] - 1.0).abs() < 1e-5,
        "{:?}",
        r.x
    );
    assert!(r.log.iter().any(|l| l.phase == "polish"));
}

#[test]
fn minimum_on_a_bound_and_bounds_never_evaluated() {
    // min (x − 3)² + (y + 1)² over [0, 2] × [0, 1]: at (2, 0), value 2.
    let outside = std::sync::atomic::AtomicUsize::new(0);
    let f = |x: &[f64]| {
        if !(0.0..=2.0).contains(&x[0]) || !(0.0..=1.0).contains(&x[1]) {
            outside.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        }
        (x[0] - 3.0).powi(2) + (x[1] + 1.0).powi(2)
    };
    let r = minimize(
        &f,
        &[(0.0, 2.0), (0.0, 1.0)],
        &[1.0, 0.5],
        &opts(1, 800, 2, 200),
        &|_, _| {},
    )
    .unwrap();
    assert_eq!(outside.load(std::sync::atomic::Ordering::Relaxed), 0);
    assert!((r.value - 2.0).abs() < 1e-7, "f = {} at {:?}", r.value, r.x);
    assert!(
        (r.x[0] - 2.0).abs() < 1e-7 && r.x[1].abs() < 1e-7,
        "{:?}",
        r.x
    );
}

#[test]
fn failed_evaluations_are_infeasible_not_fatal() {
    // The objective "fails" (NaN) on half the box, including the unconstrained minimum's side.
    let f = |x: &[f64]| {
        if x[0] < 0.0 {
            f64::NAN
        } else {
            (x[0] + 1.0).powi(2) + x[1] * x[1]
        }
    };
    let r = minimize(
        &f,
        &[(-2.0, 2.0), (-2.0, 2.0)],
        &[1.5, 1.5],
        &opts(5, 1000, 3, 200),
        &|_, _| {},
    )
    .unwrap();
    assert!(r.value.is_finite());
    assert!(
        r.x[0] >= 0.0 && r.x[0] < 1e-6 && r.x[1].abs() < 1e-6,
        "{:?}",
        r.x
    );
    assert!(r.log.iter().any(|l| l.value.is_infinite()));
}

#[test]
fn progress_reports_every_evaluation_and_the_best_so_far() {
    let calls = std::sync::Mutex::new(Vec::new());
    let f = |x: &[f64]| x[0] * x[0];
    let r = minimize(
        &f,
        &[(-1.0, 1.0)],
        &[0.9],
        &opts(2, 100, 2, 20),
        &|n, best| {
            calls.lock().unwrap().push((n, best));
        },
    )
    .unwrap();
    let calls = calls.into_inner().unwrap();
    assert_eq!(calls.len(), r.evaluations);
    assert_eq!(calls.iter().map(|c| c.0).max(), Some(r.evaluations));
    assert_eq!(calls.last().map(|c| c.1 <= 0.81), Some(true));
    assert!(calls.iter().all(|c| c.1 >= r.value));
}

#[test]
fn nelder_mead_quadratic_and_budget() {
    let g = |x: &[f64]| (x[0] - 0.3).powi(2) + 4.0 * (x[1] + 0.2).powi(2) + x[0] * x[1];
    // Minimum: ∇ = (2(x−0.3) + y, 8(y+0.2) + x) = 0 → x = (4.8+1.6)/15·…; solve exactly.
    let (a, b, c, d) = (2.0, 1.0, 1.0, 8.0);
    let (r0, r1) = (0.6, -1.6);
    let det = a * d - b * c;
    let (xs, ys) = ((r0 * d - b * r1) / det, (a * r1 - c * r0) / det);
    let mut used = 0;
    let (x, v, log) = nelder_mead(&g, &[1.0, 1.0], g(&[1.0, 1.0]), &[0.1, 0.1], 500, &mut used);
    assert!(used <= 500 && log.len() == used);
    assert!(
        (x[0] - xs).abs() < 1e-6 && (x[1] - ys).abs() < 1e-6,
        "{x:?} vs ({xs}, {ys})"
    );
    assert!((v - g(&[xs, ys])).abs() < 1e-12);
    let mut used = 0;
    let _ = nelder_mead(&g, &[1.0, 1.0], g(&[1.0, 1.0]), &[0.1, 0.1], 7, &mut used);
    assert!(used <= 7);
}

#[test]
fn options_are_checked() {
    let f = |x: &[f64]| x[0];
    let e = minimize(&f, &[(0.0, 1.0)], &[0.5], &opts(1, 10, 0, 0), &|_, _| {}).unwrap_err();
    assert_eq!(e.place(), "optimize.chains");
    let mut o = opts(1, 10, 1, 0);
    o.cooling = Some(1.0);
    let e = minimize(&f, &[(0.0, 1.0)], &[0.5], &o, &|_, _| {}).unwrap_err();
    assert_eq!(e.place(), "optimize.cooling");
    let e = minimize(&f, &[(0.0, 1.0)], &[2.0], &opts(1, 10, 1, 0), &|_, _| {}).unwrap_err();
    assert!(e.to_string().contains("outside"), "{e}");
}

// ---- design parameters ----

use crate::design::build_curves;
use crate::spec::parse_design;
use crate::Vec3;

const CURVATURE: &str = include_str!("../../../../examples/optimize_curvature.toml");
const VESICLE: &str = include_str!("../../../../examples/vesicle.toml");

fn curve_points(spec: &DesignSpec, name: &str) -> Vec<Vec3> {
    let curves = build_curves(spec).unwrap();
    let c = &curves.iter().find(|c| c.name == name).unwrap().curve;
    (0..16)
        .map(|k| c.point(crate::TAU * k as f64 / 16.0))
        .collect()
}

fn problem_of(text: &str) -> Problem {
    Problem::new(&parse_design(text).unwrap()).unwrap()
}

#[test]
fn parameters_read_in_the_books_notation() {
    let p = problem_of(CURVATURE);
    assert_eq!(p.parameters.len(), 19);
    assert_eq!(
        p.parameters.list[0].kind,
        ParamKind::Translate {
            curve: "d1".into(),
            axis: 0
        }
    );
    assert_eq!(
        p.parameters.list[17].kind,
        ParamKind::Dilate {
            curve: "d2".into(),
            axis: 2
        }
    );
    assert_eq!(p.parameters.list[18].kind, ParamKind::Smoothing);
    // Neutral initial values: 0 for T and R, 1 for D, the design's a = 0.5 (Table 7.2).
    let x0 = p.parameters.initial();
    assert_eq!(&x0[..12], &[0.0; 12]);
    assert_eq!(&x0[12..18], &[1.0; 6]);
    assert_eq!(x0[18], 0.5);
    // At the initial values the design is the file's design.
    let applied = p.design(&x0);
    for name in ["d1", "d2", "p1"] {
        let (a, b) = (curve_points(&applied, name), curve_points(&p.base, name));
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).norm() < 1e-14, "{name}: {x} vs {y}");
        }
    }
}

#[test]
fn parameters_move_curves_as_stated() {
    let p = problem_of(CURVATURE);
    let base = curve_points(&p.base, "d1");
    // d1 is the circle of radius 1.6 about (0, 0.6, 0) in the plane y = 0.6.
    let centre = Vec3::new(0.0, 0.6, 0.0);
    let mut x = p.parameters.initial();
    x[0] = 0.3; // d1Tx
    x[4] = 0.2; // d1Ty
    x[7] = 0.5; // d1Ry (radians)
    x[12] = 2.0; // d1Dx
    x[14] = 0.5; // d1Dz
    let moved = curve_points(&p.design(&x), "d1");
    let (s, c) = 0.5f64.sin_cos();
    for (b, m) in base.iter().zip(&moved) {
        let r = b - centre;
        let d = Vec3::new(2.0 * r.x, r.y, 0.5 * r.z);
        // Rotation about +y: (x, z) ↦ (x cos + z sin, −x sin + z cos).
        let rot = Vec3::new(c * d.x + s * d.z, d.y, -s * d.x + c * d.z);
        let want = centre + rot + Vec3::new(0.3, 0.2, 0.0);
        assert!((m - want).norm() < 1e-13, "{m} vs {want}");
    }
    // d2 is untouched; a is set.
    assert_eq!(
        curve_points(&p.design(&x), "d2"),
        curve_points(&p.base, "d2")
    );
    x[18] = 2.5;
    assert_eq!(
        p.design(&x).operator,
        Some(crate::spec::OperatorSpec::Polyharmonic { order: 2, a: 2.5 })
    );
}

#[test]
fn edited_text_builds_the_same_design_and_keeps_the_layout() {
    let p = problem_of(CURVATURE);
    let mut x = p.parameters.initial();
    for (i, xi) in x.iter_mut().enumerate() {
        let (lo, hi) = (p.parameters.list[i].min, p.parameters.list[i].max);
        *xi = lo + (hi - lo) * (0.3 + 0.03 * i as f64);
    }
    let text = p.parameters.apply_to_text(CURVATURE, &p.base, &x).unwrap();
    assert!(text.contains("# A biharmonic patch between two fixed position curves"));
    assert!(text.contains("dilate = {"), "{text}");
    let reread = parse_design(&text).unwrap();
    let direct = p.design(&x);
    for name in ["d1", "d2", "p1", "p2", "t1", "t2"] {
        let (a, b) = (curve_points(&reread, name), curve_points(&direct, name));
        for (u, w) in a.iter().zip(&b) {
            assert!((u - w).norm() < 1e-13, "{name}: {u} vs {w}");
        }
    }
    assert_eq!(reread.operator, direct.operator);
    // The rewritten file still carries the [optimize] section and re-reads as a problem whose
    // parameters now act on top of the applied design.
    assert!(Problem::new(&reread).is_ok());
}

#[test]
fn control_offsets_alternate_along_the_polygon_normal() {
    let text = r#"
conditions = [{ u = 0, curve = "ring" }, { u = 1, curve = "top" }]
[curves.ring]
type = "bspline"
degree = 3
control = [[1, 0, 0], [0, 1, 0], [-1, 0, 0], [0, -1, 0]]
[curves.top]
type = "circle"
center = [0, 0, 1]
radius = 1.0
[operator]
kind = "polyharmonic"
order = 1
[optimize]
objective = "area"
parameters = [{ name = "ringcT", min = -0.3, max = 0.3 }]
"#;
    let p = problem_of(text);
    let spec = p.design(&[0.2]);
    let Some(crate::spec::CurveSpec {
        kind: crate::spec::CurveKind::BSpline { control, .. },
        ..
    }) = spec.curves.get("ring")
    else {
        panic!("not a bspline")
    };
    // Outward normals of this square polygon are the radial directions.
    assert_eq!(control[0], [1.2, 0.0, 0.0]);
    assert!((control[1][1] - 0.8).abs() < 1e-15 && control[1][0].abs() < 1e-15);
    assert!((control[2][0] + 1.2).abs() < 1e-15);
    assert!((control[3][1] + 0.8).abs() < 1e-15);
    let edited = p.parameters.apply_to_text(text, &p.base, &[0.2]).unwrap();
    let reread = parse_design(&edited).unwrap();
    assert_eq!(
        curve_points(&reread, "ring"),
        curve_points(&spec, "ring"),
        "{edited}"
    );
}

/// The error of a design: from the reader (limits such as `chains`) or from `Problem::new`.
fn error_of(text: &str) -> crate::Error {
    match parse_design(text) {
        Err(e) => e,
        Ok(spec) => Problem::new(&spec).expect_err("an error"),
    }
}

#[test]
fn bad_parameters_are_refused_with_their_place() {
    let with = |params: &str| {
        CURVATURE.replace(
            r#"  { name = "a", min = 0.01, max = 9.0 },"#,
            &format!("  {params},"),
        )
    };
    let cases = [
        (
            r#"{ name = "d3Dx", min = 0.5, max = 2 }"#,
            "optimize.parameters[18].name",
            "'d3'",
        ),
        (
            r#"{ name = "d1Qx", min = 0.5, max = 2 }"#,
            "optimize.parameters[18].name",
            "unknown parameter",
        ),
        (
            r#"{ name = "d1cT", min = -1, max = 1 }"#,
            "optimize.parameters[18].name",
            "bspline",
        ),
        (
            r#"{ name = "d1Dz", min = 0.5, max = 2 }"#,
            "optimize.parameters[18].name",
            "twice",
        ),
        (
            r#"{ name = "a", min = 2, max = 1 }"#,
            "optimize.parameters[18].max",
            "greater",
        ),
        (
            r#"{ name = "a", min = 0, max = 1 }"#,
            "optimize.parameters[18].min",
            "positive",
        ),
        (
            r#"{ name = "d1Rx", min = 0.1, max = 1 }"#,
            "optimize.parameters[18].min",
            "outside",
        ),
        (
            r#"{ name = "d1Rx", min = -1, max = 1, initial = 3 }"#,
            "optimize.parameters[18].initial",
            "outside",
        ),
    ];
    for (param, place, words) in cases {
        let e = error_of(&with(param));
        assert_eq!(e.place(), place, "{param}: {e}");
        assert!(e.to_string().contains(words), "{param}: {e}");
    }
    let e = error_of(&CURVATURE.replace("d1Dx", "d1Dy").replace(
        r#"{ name = "d1Dy", min = 0.01"#,
        r#"{ name = "d1Dy", min = -0.01"#,
    ));
    assert!(e.to_string().contains("must not contain 0"), "{e}");
    let e = error_of(&CURVATURE.replace(r#"objective = "bending""#, r#"objective = "bend + 1""#));
    assert_eq!(e.place(), "optimize.objective");
    assert!(e.to_string().contains("unknown variable 'bend'"), "{e}");
    let e = error_of(&VESICLE.replace("equal = 0.8", "equal = 0.8, max = 2"));
    assert_eq!(e.place(), "optimize.constraints[0]");
    let e = error_of(&VESICLE.replace("weight = 1e6", "weight = -1"));
    assert_eq!(e.place(), "optimize.constraints[0].weight");
    let e = error_of(&VESICLE.replace("chains = 4", "chains = 0"));
    assert_eq!(e.place(), "optimize.chains");
    let e = error_of(&VESICLE.replace("quadrature_v = 16", "quadrature_v = 1"));
    assert_eq!(e.place(), "optimize.quadrature_v");
    let e = Problem::new(
        &parse_design("[curves.c]\ntype = \"circle\"\ncenter = [0,0,0]\nradius = 1\n").unwrap(),
    )
    .unwrap_err();
    assert_eq!(e.place(), "optimize");
}

#[test]
fn formulas_and_penalties() {
    let p = problem_of(&VESICLE.replace(
        r#"objective = "helfrich""#,
        r#"objective = "helfrich / (16*pi) + 0*area""#,
    ));
    // A unit sphere's integrals: A = 4π, V = 4π/3, ∫H = −4π (H = −1 for the outward normal),
    // ∫H² = 4π, ∫K = 4π.
    let pi = std::f64::consts::PI;
    let t = crate::analysis::Integrals {
        area: 4.0 * pi,
        volume: 4.0 * pi / 3.0,
        mean: -4.0 * pi,
        mean_sq: 4.0 * pi,
        gauss: 4.0 * pi,
    };
    let e = p.evaluate_totals(&t);
    assert!((e.objective - 1.0).abs() < 1e-15, "{}", e.objective);
    let v = |name: &str| e.variables[VARIABLES.iter().position(|n| *n == name).unwrap()];
    assert!((v("bending") - 8.0 * pi).abs() < 1e-13);
    assert!((v("nu") - 1.0).abs() < 1e-15);
    assert!((v("helfrich") - 16.0 * pi).abs() < 1e-13);
    assert!((v("willmore") - 16.0 * pi).abs() < 1e-13);
    // ν = 1 against the target 0.8 with weight 1e6: penalty 1e6 · 0.2².
    assert!((e.penalty - 1e6 * 0.04).abs() < 1e-7, "{}", e.penalty);
    // Helfrich with C0: ∫(C1 + C2 − C0)² dA on the unit sphere = (2 − C0)² 4π.
    let mut q = p.clone();
    q.spontaneous_curvature = 0.5;
    let e = q.evaluate_totals(&t);
    assert!((v("C0") - 0.0).abs() == 0.0);
    let h = e.variables[7];
    assert!((h - 1.5f64.powi(2) * 4.0 * pi).abs() < 1e-13, "{h}");
    // `-nu^2` is ambiguous (exmex reads (−ν)²): refused with its place, as curve formulas are.
    let e = error_of(&VESICLE.replace(r#"objective = "helfrich""#, r#"objective = "-nu^2""#));
    assert_eq!(e.place(), "optimize.objective");
    assert!(e.to_string().contains("before the power"), "{e}");
}

// ---- integrals ----

#[test]
fn gauss_legendre_rule_is_exact_to_degree_2n_minus_1() {
    let (x, w) = measure::gauss_legendre01(6);
    for k in 0..12 {
        let q: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(k)).sum();
        assert!((q - 1.0 / (k + 1) as f64).abs() < 1e-15, "k = {k}: {q}");
    }
}

/// A torus with radii (R, r) or, with R = 0 and the u-range [0, π], a sphere of radius r:
/// X = ((R + r sin θ) cos v, (R + r sin θ) sin v, r cos θ), θ = span·u.
struct Torus {
    big: f64,
    r: f64,
    span: f64,
}

impl crate::surface::Surface for Torus {
    fn v_domain(&self) -> crate::surface::VDomain {
        crate::surface::VDomain::Periodic
    }
    fn partials(&self, u: f64, v: f64) -> crate::surface::Partials {
        let (k, r, big) = (self.span, self.r, self.big);
        let (st, ct) = (k * u).sin_cos();
        let (sv, cv) = v.sin_cos();
        let rho = big + r * st;
        crate::surface::Partials {
            x: Vec3::new(rho * cv, rho * sv, r * ct),
            xu: Vec3::new(r * k * ct * cv, r * k * ct * sv, -r * k * st),
            xv: Vec3::new(-rho * sv, rho * cv, 0.0),
            xuu: Vec3::new(-r * k * k * st * cv, -r * k * k * st * sv, -r * k * k * ct),
            xuv: Vec3::new(-r * k * ct * sv, r * k * ct * cv, 0.0),
            xvv: Vec3::new(-rho * cv, -rho * sv, 0.0),
        }
    }
}

#[test]
fn sphere_and_torus_integrals_match_closed_forms() {
    let pi = std::f64::consts::PI;
    // Sphere of radius 2 (u from the north pole to the south pole).
    let r = 2.0;
    let t = measure::totals(
        &[&Torus {
            big: 0.0,
            r,
            span: pi,
        }],
        24,
        8,
    )
    .unwrap();
    let close = |a: f64, b: f64| (a - b).abs() < 1e-12 * b.abs().max(1.0);
    assert!(close(t.area, 4.0 * pi * r * r), "{t:?}");
    assert!(close(t.volume, 4.0 / 3.0 * pi * r.powi(3)), "{t:?}");
    assert!(close(t.mean, 4.0 * pi * r), "{t:?}");
    assert!(close(t.mean_sq, 4.0 * pi), "{t:?}");
    assert!(close(t.gauss, 4.0 * pi), "{t:?}");
    let v = variables(&t, 0.0);
    assert!(close(v[7], 16.0 * pi) && close(v[8], 1.0), "{v:?}");
    // Torus R = 3, r = 1 (u once around the tube): A = 4π²Rr, V = 2π²Rr², ∫H dA = 2π²R, ∫K = 0.
    let (big, r) = (3.0, 1.0);
    let t = measure::totals(
        &[&Torus {
            big,
            r,
            span: crate::TAU,
        }],
        48,
        16,
    )
    .unwrap();
    assert!(close(t.area, 4.0 * pi * pi * big * r), "{t:?}");
    assert!(close(t.volume, 2.0 * pi * pi * big * r * r), "{t:?}");
    assert!(t.gauss.abs() < 1e-12, "{t:?}");
    assert!(close(t.mean, 2.0 * pi * pi * big), "{t:?}");
    // The Willmore energy of this torus is π² c² / √(c² − 1), c = R/r (2π² for the Clifford
    // torus c = √2).
    let c = big / r;
    assert!(
        close(t.mean_sq, pi * pi * c * c / (c * c - 1.0).sqrt()),
        "{t:?}"
    );
}

#[test]
fn vesicle_start_is_closed_smooth_and_converged() {
    let p = problem_of(VESICLE);
    let built = crate::design::solve_design(&p.design(&p.parameters.initial())).unwrap();
    let fine = measure::measure(&built, 64, 64).unwrap();
    let coarse = measure(&built, p.quadrature.0, p.quadrature.1).unwrap();
    // Gauss–Bonnet for a closed smooth genus-0 surface: ∫K dA = 4π (an independent check of
    // the smoothness at the poles and the tangent continuity at the equator).
    let pi = std::f64::consts::PI;
    assert!((fine.gauss - 4.0 * pi).abs() < 1e-9, "{fine:?}");
    // The search's coarse rule (the library's integrals) agrees with a fine independent one.
    for (a, b) in [
        (coarse.area, fine.area),
        (coarse.volume, fine.volume),
        (coarse.mean_sq, fine.mean_sq),
    ] {
        assert!((a - b).abs() < 1e-8 * b.abs(), "{a} vs {b}");
    }
    assert!((coarse.mean.abs() - fine.mean).abs() < 1e-8 * fine.mean);
    let v = variables(&coarse, 0.0);
    // Isoperimetric and Willmore inequalities.
    assert!(v[8] < 1.0 && v[8] > 0.5, "nu = {}", v[8]);
    assert!(v[7] > 16.0 * pi, "helfrich = {}", v[7]);
}

// ---- the examples of §7.5 ----

#[test]
fn curvature_example_lowers_the_bending_energy_repeatably() {
    let mut p = problem_of(CURVATURE);
    p.options.evaluations = 400;
    p.options.polish = 60;
    p.options.chains = 2;
    let one = in_pool(1, || p.run(&|_, _| {}).unwrap());
    let two = in_pool(2, || p.run(&|_, _| {}).unwrap());
    assert_eq!(one.best.0, two.best.0, "result depends on the thread count");
    assert_eq!(one.search.log, two.search.log);
    let start = one.start.1.as_ref().unwrap().total();
    let best = one.best.1.total();
    // The start (Table 7.2's initial values) has ∫(κ1² + κ2²) dA ≈ 42.1; the search must cut it
    // by a fifth at least.
    assert!(best < 0.8 * start, "start {start}, best {best}");
    for (x, q) in one.best.0.iter().zip(&p.parameters.list) {
        assert!((q.min..=q.max).contains(x), "{} = {x}", q.name);
    }
    // The optimised file, re-read and rebuilt, has the energy reported.
    let text = p
        .parameters
        .apply_to_text(CURVATURE, &p.base, &one.best.0)
        .unwrap();
    let built = crate::design::solve_design(&parse_design(&text).unwrap()).unwrap();
    let again = measure(&built, p.quadrature.0, p.quadrature.1).unwrap();
    assert!((again.bending_energy() - best).abs() < 1e-9 * best);
    // The search's coarse quadrature (24 × 48 nodes) is accurate enough for the optimum: a fine
    // independent rule agrees to 10⁻⁴ (3·10⁻⁵ observed), far below the differences the search
    // resolves.
    let fine = measure::measure(&built, 96, 128).unwrap();
    let b = 4.0 * fine.mean_sq - 2.0 * fine.gauss;
    assert!((b - best).abs() < 1e-4 * best, "{b} vs {best}");
}

/// `F/8π = helfrich/16π` of the axisymmetric minimum (prolate branch) at reduced volume `nu`,
/// interpolated linearly in the table of bench/peers/vesicle_reference.py (Ritz minima over 14
/// Legendre modes of a star-shaped profile; the 8-mode values differ by ≤ 1e-3 for ν ≥ 0.8).
fn prolate_reference(nu: f64) -> f64 {
    const T: [(f64, f64); 5] = [
        (0.75, 1.50229),
        (0.80, 1.38752),
        (0.85, 1.28568),
        (0.90, 1.18964),
        (0.95, 1.09556),
    ];
    interpolate(&T, nu)
}

/// The same for the oblate branch (same source).
fn oblate_reference(nu: f64) -> f64 {
    const T: [(f64, f64); 5] = [
        (0.75, 1.57565),
        (0.80, 1.45269),
        (0.85, 1.33356),
        (0.90, 1.21786),
        (0.95, 1.10611),
    ];
    interpolate(&T, nu)
}

fn interpolate(table: &[(f64, f64)], nu: f64) -> f64 {
    // Linear in each interval; the end intervals also serve 0.005 beyond the table (the penalty
    // leaves ν that close to its target).
    let (first, last) = (table[0].0, table[table.len() - 1].0);
    if !(first - 0.005..=last + 0.005).contains(&nu) {
        return f64::NAN;
    }
    let k = table
        .windows(2)
        .position(|w| nu <= w[1].0)
        .unwrap_or(table.len() - 2);
    let ((x0, y0), (x1, y1)) = (table[k], table[k + 1]);
    y0 + (y1 - y0) * (nu - x0) / (x1 - x0)
}

/// Extent of a design along z and its largest distance from the z axis ([`profile_extremes`]).
fn extents(spec: &DesignSpec) -> (f64, f64) {
    let [_, _, zmax, zmin, rmax, _] = profile_extremes(spec);
    (zmax - zmin, rmax)
}

#[test]
fn vesicle_at_reduced_volume_0_8_is_prolate_and_not_below_the_minimum() {
    // The prolate branch: the equator radius at most the half-distance of the poles. (Unbounded,
    // this short search may settle on the oblate branch, a local minimum ≈ 5 % higher.)
    let text = VESICLE.replace(
        "min = 0.3, max = 3.0, initial = 0.6",
        "min = 0.3, max = 1.0, initial = 0.6",
    );
    let p = problem_of(&text);
    let out = p.run(&|_, _| {}).unwrap();
    let v = &out.best.1.variables;
    let (nu, f) = (v[8], v[7] / (16.0 * std::f64::consts::PI));
    assert!((nu - 0.8).abs() < 2e-3, "nu = {nu}");
    // Closed and smooth: Gauss–Bonnet, with a fine independent rule; the search's coarse rule
    // (24 × 16 nodes) agrees with it to 10⁻⁴ on the energy.
    let built = crate::design::solve_design(&p.design(&out.best.0)).unwrap();
    let fine = measure::measure(&built, 64, 128).unwrap();
    assert!(
        (fine.gauss - 4.0 * std::f64::consts::PI).abs() < 1e-9,
        "∫K = {}",
        fine.gauss
    );
    assert!(
        (4.0 * fine.mean_sq - v[7]).abs() < 1e-4 * v[7],
        "{} vs {}",
        4.0 * fine.mean_sq,
        v[7]
    );
    // At or above the axisymmetric minimum (less the reference's own uncertainty), and not far
    // from it: the two-patch family and the example's search (2000 + 300 evaluations) come
    // within 20 % (16 % observed).
    let reference = prolate_reference(nu);
    assert!(
        f >= reference - 2e-3,
        "F/8π = {f} below the minimum {reference} at ν = {nu}"
    );
    assert!(
        f <= 1.20 * reference,
        "F/8π = {f}, minimum {reference} at ν = {nu}"
    );
    // Prolate: longer along the axis than across.
    let (height, radius) = extents(&p.design(&out.best.0));
    assert!(
        height > 2.0 * radius * 1.2,
        "height {height}, radius {radius}"
    );
}

/// The table of §7.5.2 for c0 = 0: reduced volumes 0.95 down to 0.6 by continuation (each search
/// starts at the previous optimum, as the book does), with the reference minima. About a minute
/// in release mode: `cargo test --release -p pdeshape --lib vesicle_table -- --ignored --nocapture`.
#[test]
#[ignore]
fn vesicle_table() {
    let mut p = problem_of(VESICLE);
    p.options.evaluations = 2000;
    p.options.polish = 400;
    println!("| target ν | ν found | F/8π found | prolate minimum | oblate minimum | shape (height / diameter) | evaluations |");
    println!("|---|---|---|---|---|---|---|");
    for target in [0.95, 0.9, 0.85, 0.8, 0.75, 0.7, 0.65, 0.6] {
        let text = VESICLE.replace("equal = 0.8", &format!("equal = {target}"));
        let mut q = problem_of(&text);
        q.options = p.options.clone();
        for (dst, src) in q.parameters.list.iter_mut().zip(&p.parameters.list) {
            dst.initial = src.initial;
        }
        let out = q.run(&|_, _| {}).unwrap();
        let v = &out.best.1.variables;
        let (nu, f) = (v[8], v[7] / (16.0 * std::f64::consts::PI));
        let (height, radius) = extents(&q.design(&out.best.0));
        let reference = prolate_reference(nu);
        let show = |r: f64| {
            if r.is_nan() {
                "—".to_string()
            } else {
                format!("{r:.4}")
            }
        };
        let kind = if height > 2.0 * radius {
            "prolate"
        } else {
            "oblate"
        };
        println!(
            "| {target} | {nu:.4} | {f:.4} | {} | {} | {:.3} ({kind}) | {} |",
            show(reference),
            show(oblate_reference(nu)),
            height / (2.0 * radius),
            out.search.evaluations
        );
        assert!(reference.is_nan() || f >= reference - 2e-3);
        assert!(f >= 1.0);
        for (dst, x) in p.parameters.list.iter_mut().zip(&out.best.0) {
            dst.initial = *x;
        }
    }
}

/// The start of examples/vesicle_disc.toml on the discocyte branch (bench/vesicle_branches.py,
/// `STARTS["discocyte"]`): the poles at ±0.2 below rings at ±0.4 of radius 0.6 whose tangent
/// rises outwards, so both poles are dimpled.
const DISCOCYTE_START: [(&str, f64); 22] = [
    ("north_z", 0.2),
    ("south_z", -0.2),
    ("north_spreadDx", 0.763942),
    ("north_spreadDy", 0.763942),
    ("south_spreadDx", 0.763942),
    ("south_spreadDy", 0.763942),
    ("nringDx", 0.848536),
    ("nringDy", 0.848536),
    ("nringTz", -0.3071),
    ("nring_aheadDx", 0.950495),
    ("nring_aheadDy", 0.950495),
    ("nring_aheadTz", 0.4483),
    ("equator_aheadDx", 1.0),
    ("equator_aheadDy", 1.0),
    ("equator_aheadTz", 0.1854),
    ("sringDx", 0.848536),
    ("sringDy", 0.848536),
    ("sringTz", 0.3071),
    ("sring_aheadDx", 0.659196),
    ("sring_aheadDy", 0.659196),
    ("sring_aheadTz", 1.0625),
    ("a", 1.0),
];

/// The profile of a design of patches along the z axis: (z of the north pole, z of the south
/// pole, largest z, smallest z, largest distance from the axis, z where it is reached), from a
/// 64 × 64 grid of every patch.
fn profile_extremes(spec: &DesignSpec) -> [f64; 6] {
    let built = crate::design::solve_design(spec).unwrap();
    let (mut zn, mut zs) = (f64::MIN, f64::MAX);
    let (mut zmax, mut zmin, mut rmax, mut zeq) = (f64::MIN, f64::MAX, 0.0f64, 0.0);
    for p in built.surfaces.iter().filter(|s| s.is_patch()) {
        for i in 0..=64 {
            for j in 0..64 {
                let x = crate::surface::Surface::point(
                    p.surface(),
                    i as f64 / 64.0,
                    crate::TAU * j as f64 / 64.0,
                );
                let r = x.x.hypot(x.y);
                if r < 1e-9 {
                    zn = zn.max(x.z);
                    zs = zs.min(x.z);
                }
                zmax = zmax.max(x.z);
                zmin = zmin.min(x.z);
                if r > rmax {
                    rmax = r;
                    zeq = x.z;
                }
            }
        }
    }
    [zn, zs, zmax, zmin, rmax, zeq]
}

/// §7.5.2's discocyte: the gradient search on examples/vesicle_disc.toml from its discocyte
/// start at ν = 0.65 (c0 = 0) ends on the discocyte branch (both poles dimpled, neither folded
/// past the widest circle, flat) at the axisymmetric minimum of that branch.
///
/// The reference is bench/peers/vesicle_shapes.py (a Ritz family in the tangent angle ψ(s) of
/// the profile, all branches): F/8π = 1.8275167, 1.8262334, 1.8249505 at ν = 0.6495, 0.65,
/// 0.6505, the same to 7 digits with 12 and 20 modes; linear interpolation over the band
/// errs by F''·Δν²/8 ≈ 10⁻⁶ (a little more just outside it, where ν may lie to SLSQP's
/// constraint accuracy, ~10⁻⁶). The margin: the search's 24 × 16-node rule against a fine rule
/// (checked here to 10⁻⁴ relative), plus the reference's convergence (10⁻⁷), plus 10⁻³ relative
/// allowed to the four-patch family above the axisymmetric minimum (a requirement on the
/// representation, not a measurement); below the reference by more than the rule's and the
/// reference's errors would be a wrong energy, since the reference converges from above.
#[test]
fn vesicle_disc_reaches_the_discocyte_minimum_at_reduced_volume_0_65() {
    let text = include_str!("../../../../examples/vesicle_disc.toml")
        .replace("equal = 0.8,", "equal = 0.65,");
    let mut p = problem_of(&text);
    for (name, x) in DISCOCYTE_START {
        let q = p
            .parameters
            .list
            .iter_mut()
            .find(|q| q.name == name)
            .unwrap();
        q.initial = x;
    }
    let o = p
        .run_gradient(&GradientOptions::default(), &|_, _| {})
        .unwrap();
    let r = o.gradient.as_ref().unwrap();
    assert!(r.converged, "{:?}", r.starts);
    let v = &o.best.1.variables;
    let (nu, f) = (v[8], v[7] / (16.0 * std::f64::consts::PI));
    // Feasible: the search keeps ν in its band of half the feasibility tolerance, to SLSQP's
    // constraint accuracy.
    assert!(
        o.best.1.feasible && (nu - 0.65).abs() <= EQUALITY_TOLERANCE * 0.65,
        "nu = {nu}"
    );
    let reference = interpolate(
        &[(0.6495, 1.8275167), (0.65, 1.8262334), (0.6505, 1.8249505)],
        nu,
    );
    // Closed and smooth (Gauss–Bonnet), and the search's rule against a fine one.
    let spec = p.design(&o.best.0);
    let built = crate::design::solve_design(&spec).unwrap();
    let fine = measure::measure(&built, 96, 128).unwrap();
    assert!(
        (fine.gauss - 4.0 * std::f64::consts::PI).abs() < 1e-8,
        "∫K = {}",
        fine.gauss
    );
    let quadrature = 1e-4 * f;
    assert!(
        (4.0 * fine.mean_sq / (16.0 * std::f64::consts::PI) - f).abs() <= quadrature,
        "{} vs {f}",
        4.0 * fine.mean_sq / (16.0 * std::f64::consts::PI)
    );
    assert!(
        f >= reference - quadrature - 1e-7,
        "F/8π = {f} below the minimum {reference} at ν = {nu}"
    );
    assert!(
        f <= reference * (1.0 + 1e-3) + quadrature + 1e-7,
        "F/8π = {f}, minimum {reference} at ν = {nu}"
    );
    // The branch, from the profile: both poles below the top (above the bottom) by more than
    // 1 % of the height, on the same side of the widest circle as their own half (no fold),
    // and flat.
    let [zn, zs, zmax, zmin, rmax, zeq] = profile_extremes(&spec);
    let height = zmax - zmin;
    assert!(
        zn < zmax - 0.01 * height && zn > zeq,
        "north pole {zn}, top {zmax}, rim {zeq}"
    );
    assert!(
        zs > zmin + 0.01 * height && zs < zeq,
        "south pole {zs}, bottom {zmin}, rim {zeq}"
    );
    assert!(
        height < 0.5 * 2.0 * rmax,
        "height {height}, diameter {}",
        2.0 * rmax
    );
}

// ---- shell measures ----

const YOGHURT: &str = include_str!("../../../../examples/yoghurt_optimize.toml");

#[test]
fn mass_is_density_times_thickness_times_area_without_the_solver() {
    // Objective and constraints without `max_shear`: no shell analysis runs.
    let text = YOGHURT
        .replace(
            r#"{ expr = "max_shear / yield", max = 0.3, weight = 10000.0 },"#,
            r#"{ expr = "mass / yield", max = 1.0, weight = 1.0 },"#,
        )
        .replace("thickness = 0.0005", "thickness = 0.0004");
    let p = problem_of(&text);
    assert!(p.shell_setup().is_some());
    assert!(!p.runs_solver());
    let e = p.evaluate(&p.parameters.initial()).unwrap();
    let v = |name: &str| e.variables[VARIABLES.iter().position(|n| *n == name).unwrap()];
    // cm² → m²: 1e-4; 1050 kg/m³ × 0.4 mm = 0.42 kg/m² = 4.2e-5 kg/cm².
    let per_cm2 = 1050.0 * 0.0004 * 1e-4;
    assert!(
        (v("mass") - per_cm2 * v("area")).abs() <= 1e-15 * v("mass"),
        "{} {}",
        v("mass"),
        v("area")
    );
    assert_eq!(v("yield"), 40e6);
    assert!(v("max_shear").is_nan());
    assert!((e.objective - 1000.0 * v("mass")).abs() <= 1e-12 * e.objective);
    // Table 7.4's start is the straight frustum r = 2.5 → 3.5 over 5.3 cm with ridges: about
    // π h (r₀² + r₀r₁ + r₁²)/3 = 151.2 ml.
    assert!((v("volume") - 151.2).abs() < 3.0, "{}", v("volume"));
    // Geometry-only problems have no shell measures at all.
    let q = problem_of(VESICLE);
    assert!(q.shell_setup().is_none() && !q.runs_solver());
    // The stress limit of the example asks for the solver.
    let r = problem_of(YOGHURT);
    assert!(r.runs_solver());
}

#[test]
fn feasibility_is_exact_for_inequalities_and_relative_for_equalities() {
    let p = problem_of(&YOGHURT.replace(
        r#"{ expr = "max_shear / yield", max = 0.3, weight = 10000.0 },"#,
        r#"{ expr = "mass", max = 0.005, weight = 1.0 },"#,
    ));
    let t = |volume: f64| crate::analysis::Integrals {
        area: 100.0,
        volume,
        mean: 1.0,
        mean_sq: 1.0,
        gauss: 1.0,
    };
    let shell = |mass: f64| Some([mass, f64::NAN, 40e6]);
    // Equality 150 within 1e-3 · 150 = 0.15.
    assert!(p.evaluate_with(&t(150.149), shell(0.005)).feasible);
    assert!(!p.evaluate_with(&t(150.151), shell(0.005)).feasible);
    assert!(p.evaluate_with(&t(149.851), shell(0.001)).feasible);
    // The inequality exactly.
    assert!(
        !p.evaluate_with(&t(150.0), shell(0.005 * (1.0 + 1e-15)))
            .feasible
    );
    assert!(!p.evaluate_with(&t(150.0), shell(f64::NAN)).feasible);
    // Penalties: 1 · 0.5² for the volume.
    let e = p.evaluate_with(&t(150.5), shell(0.001));
    assert!((e.penalty - 0.25).abs() < 1e-12, "{}", e.penalty);
}

#[test]
fn max_shear_is_a_variable_despite_the_parsers_max() {
    assert_eq!(
        rename_for_parser("max_shear/yield + max(max_shear, 1e3) + 2.max_shear"),
        "shear_max/yield + max(shear_max, 1e3) + 2.max_shear"
    );
    let f = Formula::parse("max_shear / yield", "x").unwrap();
    let mut vars = [0.0; NVARS];
    vars[MAX_SHEAR] = 12e6;
    vars[YIELD] = 40e6;
    assert_eq!(f.eval(&vars), 0.3);
    // Messages speak of the names as written.
    let e = Formula::parse("max_shear * shear", "x").unwrap_err();
    assert!(
        e.to_string()
            .contains("'max_shear * shear': unknown variable 'shear'")
            && e.to_string().contains("mass, max_shear, yield"),
        "{e}"
    );
}

// ---- `[[parameters]]` named by `[optimize]` ----

/// A sheared tube: the Laplace patch (order 1) between a circle and the same circle moved by
/// `px` along x and up by 2. By the mirror symmetry x ↦ −x the area is even in `px`, and it
/// grows with the shear, so the minimum of the area over `px` is at 0.
const SHEARED: &str = r#"
operator = { kind = "polyharmonic", order = 1, a = 1.0 }
conditions = [
  { u = 0.0, curve = "bottom" },
  { u = 1.0, curve = "top" },
]

[curves.bottom]
type = "circle"
center = [0.0, 0.0, 0.0]
radius = 1.0

[curves.top]
type = "circle"
center = [0.0, 0.0, 2.0]
radius = 1.0

[[parameters]]
name = "px"
kind = "position"
curve = "top"
v1 = 1.0
axis = "x"
value = 0.6
min = -1.0
max = 1.0

[optimize]
objective = "area"
parameters = [{ name = "px" }]
evaluations = 150
chains = 2
polish = 80
"#;

#[test]
fn optimiser_recovers_the_optimum_of_a_named_parameter() {
    let p = problem_of(SHEARED);
    let q = &p.parameters.list[0];
    assert_eq!(q.entry, Some(0));
    // Bounds and start come from the entry.
    assert_eq!((q.min, q.max, q.initial), (-1.0, 1.0, 0.6));
    // The point at v1 = 1 of the top circle is (cos 1, sin 1, 2): px = 0.6 shifts the circle by
    // 0.6 − cos 1 along x.
    let shift = 0.6 - 1f64.cos();
    let out = p.run(&|_, _| {}).unwrap();
    let best = out.best.0[0];
    let centred = 1f64.cos();
    assert!(
        (best - centred).abs() < 1e-3,
        "best px = {best}, want {centred}"
    );
    assert!(shift.abs() > 0.05);
    // The design of the best point sets the entry's value; the file written back carries it.
    assert_eq!(p.design(&out.best.0).parameters[0].value, Some(best));
    let text = p
        .parameters
        .apply_to_text(SHEARED, &p.base, &out.best.0)
        .unwrap();
    let reread = parse_design(&text).unwrap();
    assert_eq!(reread.parameters[0].value, Some(best));
    assert!(text.contains("kind = \"position\""), "{text}");
}

#[test]
fn named_parameters_keep_within_the_entry_bounds() {
    let case = |opt: &str| error_of(&SHEARED.replace(r#"parameters = [{ name = "px" }]"#, opt));
    let e = case(r#"parameters = [{ name = "px", min = -2.0 }]"#);
    assert_eq!(e.place(), "optimize.parameters[0].min", "{e}");
    assert!(e.to_string().contains("parameters[0]"), "{e}");
    let e = case(r#"parameters = [{ name = "px", max = 1.5 }]"#);
    assert_eq!(e.place(), "optimize.parameters[0].max", "{e}");
    let e = case(r#"parameters = [{ name = "px", min = 0.7 }]"#);
    assert_eq!(e.place(), "optimize.parameters[0].min", "{e}");
    assert!(e.to_string().contains("outside"), "{e}");
    let e = case(r#"parameters = [{ name = "topTx" }]"#);
    assert_eq!(e.place(), "optimize.parameters[0]", "{e}");
    assert!(e.to_string().contains("needs `min` and `max`"), "{e}");
    // A book-notation name and a named entry in one search.
    let p = problem_of(&SHEARED.replace(
        r#"parameters = [{ name = "px" }]"#,
        r#"parameters = [{ name = "px" }, { name = "topTz", min = -0.5, max = 0.5 }]"#,
    ));
    let spec = p.design(&[0.2, 0.3]);
    assert_eq!(spec.parameters[0].value, Some(0.2));
    let top = curve_points(&spec, "top");
    // X1 at v1 = 1 lands on x = 0.2 after the book's translation by 0.3 along z.
    let c = build_curves(&spec).unwrap();
    let t = &c.iter().find(|c| c.name == "top").unwrap().curve;
    assert!((t.point(1.0) - Vec3::new(0.2, 1f64.sin(), 2.3)).norm() < 1e-12);
    assert_eq!(top.len(), 16);
}
