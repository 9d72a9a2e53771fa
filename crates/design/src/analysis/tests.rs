use super::*;
use crate::design::solve_design as build_design;
use crate::spec::parse_design;
use crate::surface::{Partials, Surface, VDomain};
use crate::Vec3;
use std::f64::consts::PI;

/// Relative difference.
fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(f64::MIN_POSITIVE)
}

/// Sphere of radius `r` about `c`: `c + r(sin θ cos v, sin θ sin v, cos θ)` with
/// `θ = π(u₀ + (u₁ − u₀)u)`; outward normal `X_u × X_v` when `u₁ > u₀`.
struct Sphere {
    r: f64,
    c: Vec3,
    /// `u` range `[u0, u1]` of the polar angle `θ = π(u0 + (u1 − u0)u)`.
    u0: f64,
    u1: f64,
}

impl Sphere {
    fn new(r: f64, c: Vec3) -> Self {
        Sphere {
            r,
            c,
            u0: 0.0,
            u1: 1.0,
        }
    }
}

impl Surface for Sphere {
    fn v_domain(&self) -> VDomain {
        VDomain::Periodic
    }
    fn partials(&self, u: f64, v: f64) -> Partials {
        let k = PI * (self.u1 - self.u0);
        let t = PI * self.u0 + k * u;
        let (st, ct) = t.sin_cos();
        let (sv, cv) = v.sin_cos();
        let r = self.r;
        Partials {
            x: self.c + Vec3::new(st * cv, st * sv, ct) * r,
            xu: Vec3::new(ct * cv, ct * sv, -st) * (r * k),
            xv: Vec3::new(-st * sv, st * cv, 0.0) * r,
            xuu: Vec3::new(-st * cv, -st * sv, -ct) * (r * k * k),
            xuv: Vec3::new(-ct * sv, ct * cv, 0.0) * (r * k),
            xvv: Vec3::new(-st * cv, -st * sv, 0.0) * r,
        }
    }
}

/// Torus `((R + r cos φ) cos v, (R + r cos φ) sin v, r sin φ)`, `φ = 2πu` (inward normal).
struct Torus {
    big: f64,
    small: f64,
}

impl Surface for Torus {
    fn v_domain(&self) -> VDomain {
        VDomain::Periodic
    }
    fn partials(&self, u: f64, v: f64) -> Partials {
        let k = 2.0 * PI;
        let (sp, cp) = (k * u).sin_cos();
        let (sv, cv) = v.sin_cos();
        let (rr, r) = (self.big, self.small);
        let w = rr + r * cp;
        Partials {
            x: Vec3::new(w * cv, w * sv, r * sp),
            xu: Vec3::new(-r * sp * cv, -r * sp * sv, r * cp) * k,
            xv: Vec3::new(-w * sv, w * cv, 0.0),
            xuu: Vec3::new(-r * cp * cv, -r * cp * sv, -r * sp) * (k * k),
            xuv: Vec3::new(r * sp * sv, -r * sp * cv, 0.0) * k,
            xvv: Vec3::new(-w * cv, -w * sv, 0.0),
        }
    }
}

/// Open cylinder `(r cos v, r sin v, h u)` (inward normal).
struct Cylinder {
    r: f64,
    h: f64,
}

impl Surface for Cylinder {
    fn v_domain(&self) -> VDomain {
        VDomain::Periodic
    }
    fn partials(&self, _u: f64, v: f64) -> Partials {
        let (sv, cv) = v.sin_cos();
        let r = self.r;
        Partials {
            x: Vec3::new(r * cv, r * sv, self.h * _u),
            xu: Vec3::new(0.0, 0.0, self.h),
            xv: Vec3::new(-r * sv, r * cv, 0.0),
            xuu: Vec3::zeros(),
            xuv: Vec3::zeros(),
            xvv: Vec3::new(-r * cv, -r * sv, 0.0),
        }
    }
}

#[test]
fn sphere_curvature_and_principal_frame() {
    let s = Sphere::new(2.0, Vec3::new(1.0, -2.0, 0.5));
    for (u, v) in [(0.3, 0.1), (0.5, 2.0), (0.9, 5.5)] {
        let c = curvature(&s.partials(u, v)).unwrap();
        assert!(rel(c.gauss, 0.25) < 1e-14, "{c:?}");
        assert!(rel(c.mean, -0.5) < 1e-14);
        assert!(rel(c.k1, -0.5) < 1e-7 && rel(c.k2, -0.5) < 1e-7);
        // Outward normal: along X − c.
        let radial = (s.point(u, v) - s.c) / 2.0;
        assert!((c.normal - radial).norm() < 1e-15);
        assert!((c.d1.norm() - 1.0).abs() < 1e-15 && c.d1.dot(&c.normal).abs() < 1e-15);
        assert!((c.d1.cross(&c.d2) - c.normal).norm() < 1e-15);
    }
    // At the poles the parametrisation degenerates: no pointwise value, a limit from inside.
    for u in [0.0, 1.0] {
        assert!(curvature(&s.partials(u, 0.7)).is_none());
        let c = curvature_at(&s, u, 0.7).unwrap();
        assert!(rel(c.gauss, 0.25) < 1e-8, "{c:?}");
        assert!(rel(c.mean, -0.5) < 1e-8, "{c:?}");
        assert_eq!(c.jacobian, 0.0);
        assert!(c.normal.iter().all(|x| x.is_finite()));
    }
}

#[test]
fn torus_principal_curvatures_and_directions() {
    // Inward normal: the tube's curvature 1/r, the parallel's cos φ/(R + r cos φ).
    let t = Torus {
        big: 3.0,
        small: 1.0,
    };
    for u in [0.1, 0.25, 0.6] {
        let c = curvature(&t.partials(u, 0.4)).unwrap();
        let phi = 2.0 * PI * u;
        let (a, b) = (1.0f64, phi.cos() / (3.0 + phi.cos()));
        let (k1, k2) = (a.max(b), a.min(b));
        assert!((c.k1 - k1).abs() < 1e-13, "{c:?}");
        assert!((c.k2 - k2).abs() < 1e-13, "{c:?}");
        assert!(rel(c.gauss, a * b) < 1e-13);
        // d1 (κ = 1/r) runs along the tube's meridian, that is along X_u.
        let xu = t.partials(u, 0.4).xu.normalize();
        assert!(c.d1.cross(&xu).norm() < 1e-12, "{c:?}");
    }
}

#[test]
fn sphere_integrals_match_closed_forms_and_willmore_is_scale_invariant() {
    for (r, c) in [
        (1.0, Vec3::zeros()),
        (0.01, Vec3::new(3.0, 0.0, 0.0)),
        (250.0, Vec3::new(-1e3, 2e3, 5.0)),
    ] {
        let a = analyze_surface(&Sphere::new(r, c), &Quadrature::default()).unwrap();
        let i = a.integrals;
        assert!(a.converged && a.error < 1e-10, "{a:?}");
        assert!(rel(i.area, 4.0 * PI * r * r) < 1e-12, "{i:?}");
        assert!(rel(i.volume, 4.0 / 3.0 * PI * r.powi(3)) < 1e-10, "{i:?}");
        assert!(rel(i.mean, -4.0 * PI * r) < 1e-12, "{i:?}");
        assert!(rel(i.gauss, 4.0 * PI) < 1e-12, "{i:?}");
        assert!(rel(i.willmore(), 16.0 * PI) < 1e-12, "{i:?}");
        assert!(rel(i.bending_energy(), 8.0 * PI) < 1e-12);
        assert!(rel(i.reduced_volume(), 1.0) < 1e-10);
        // C₀ = 2/R: the sphere is the spontaneous shape.
        assert!(i.helfrich(2.0 / r).abs() < 1e-9, "{}", i.helfrich(2.0 / r));
        assert!(rel(i.vesicle_energy(0.0, 1.0), 20.0 * PI) < 1e-12);
        assert!(rel(i.reduced_spontaneous_curvature(3.0 / r), 3.0) < 1e-12);
        assert!((a.gauss_range.0 * r * r - 1.0).abs() < 1e-12);
        assert!((a.mean_range.1 * r + 1.0).abs() < 1e-12);
    }
}

#[test]
fn torus_and_cylinder_integrals_match_closed_forms() {
    let (rr, r) = (2.5, 0.7);
    let i = integrate_surface(&Torus { big: rr, small: r }, &Quadrature::default()).unwrap();
    // Inward normal: negative volume, positive ∫H.
    assert!(rel(i.area, 4.0 * PI * PI * rr * r) < 1e-12, "{i:?}");
    assert!(rel(i.volume, -2.0 * PI * PI * rr * r * r) < 1e-12, "{i:?}");
    assert!(rel(i.mean, 2.0 * PI * PI * rr) < 1e-12, "{i:?}");
    assert!(i.gauss.abs() < 1e-10 * i.bending_energy(), "{i:?}");
    // Willmore energy of a torus of revolution: π² R² / (r √(R² − r²)).
    let w = PI * PI * rr * rr / (r * (rr * rr - r * r).sqrt());
    assert!(rel(i.mean_sq, w) < 1e-10, "{} {w}", i.mean_sq);
    // As a one-patch design it is closed (u = 0 and u = 1 meet) and turned outward.
    let t = Torus { big: rr, small: r };
    let d = integrate_surfaces(&[("torus", &t)], &[], &Quadrature::default()).unwrap();
    assert!(d.closed && d.caps.is_empty());
    assert_eq!(d.orientation, vec![-1.0]);
    assert!(rel(d.total.volume, 2.0 * PI * PI * rr * r * r) < 1e-12);
    assert!(rel(d.total.mean, -2.0 * PI * PI * rr) < 1e-12);

    let (r, h) = (1.3, 2.0);
    let c = Cylinder { r, h };
    let i = integrate_surface(&c, &Quadrature::default()).unwrap();
    assert!(rel(i.area, 2.0 * PI * r * h) < 1e-13, "{i:?}");
    assert!(rel(i.mean, PI * h) < 1e-13, "{i:?}");
    assert!(rel(i.mean_sq, PI * h / (2.0 * r)) < 1e-13, "{i:?}");
    assert!(i.gauss.abs() < 1e-14, "{i:?}");
    // Closed by two planar caps: V = πr²h, outward.
    let d = integrate_surfaces(&[("tube", &c)], &[], &Quadrature::default()).unwrap();
    assert!(!d.closed);
    assert_eq!(d.caps.len(), 2);
    assert!(rel(d.total.volume, PI * r * r * h) < 1e-13, "{d:?}");
    assert!(d.caps.iter().all(|c| c.planarity < 1e-15));
    assert!(rel(d.caps[0].area, PI * r * r) < 1e-13);
    assert!(rel(d.total.mean, -PI * h) < 1e-13);
}

#[test]
fn hemispheres_are_oriented_consistently_across_the_shared_equator() {
    // Both hemispheres run from a pole (u = 0) to the equator (u = 1): ends 1–1, so one of
    // them is reversed; the design is closed and the volume is the ball's.
    let south = Sphere {
        r: 1.5,
        c: Vec3::zeros(),
        u0: 0.0,
        u1: 0.5,
    };
    let north = Sphere {
        r: 1.5,
        c: Vec3::zeros(),
        u0: 1.0,
        u1: 0.5,
    };
    let d = integrate_surfaces(
        &[("south", &south), ("north", &north)],
        &[],
        &Quadrature::default(),
    )
    .unwrap();
    assert!(d.closed, "{d:?}");
    assert_eq!(d.orientation, vec![1.0, -1.0]);
    let r = 1.5f64;
    assert!(
        rel(d.total.volume, 4.0 / 3.0 * PI * r.powi(3)) < 1e-12,
        "{d:?}"
    );
    assert!(rel(d.total.mean, -4.0 * PI * r) < 1e-12);
    assert!(rel(d.total.willmore(), 16.0 * PI) < 1e-12);
    assert!(rel(d.patches[0].volume, d.patches[1].volume) < 1e-12);
    // The southern half alone gets a planar cap over the equator.
    let d = integrate_surfaces(&[("south", &south)], &[], &Quadrature::default()).unwrap();
    assert!(!d.closed && d.caps.len() == 1);
    assert!(
        rel(d.total.volume, 2.0 / 3.0 * PI * r.powi(3)) < 1e-12,
        "{d:?}"
    );
}

fn cup() -> crate::design::SolvedDesign {
    let text = include_str!("../../../../examples/cup.toml");
    build_design(&parse_design(text).unwrap()).unwrap()
}

/// `K` and `H` from central differences of positions only, against the exact-partials path.
#[test]
fn pde_patch_curvature_matches_finite_differences() {
    let d = cup();
    let s = d.surfaces[1].pde().unwrap();
    let h = 1e-4;
    for (u, v) in [(0.2, 0.3), (0.5, 1.7), (0.8, 4.0)] {
        let x = |du: f64, dv: f64| s.point(u + du * h, v + dv * h);
        let p = Partials {
            x: x(0.0, 0.0),
            xu: (x(1.0, 0.0) - x(-1.0, 0.0)) / (2.0 * h),
            xv: (x(0.0, 1.0) - x(0.0, -1.0)) / (2.0 * h),
            xuu: (x(1.0, 0.0) - x(0.0, 0.0) * 2.0 + x(-1.0, 0.0)) / (h * h),
            xvv: (x(0.0, 1.0) - x(0.0, 0.0) * 2.0 + x(0.0, -1.0)) / (h * h),
            xuv: (x(1.0, 1.0) - x(1.0, -1.0) - x(-1.0, 1.0) + x(-1.0, -1.0)) / (4.0 * h * h),
        };
        let fd = curvature(&p).unwrap();
        let exact = curvature(&s.partials(u, v)).unwrap();
        // O(h²) truncation (~1e-8) plus rounding of the second differences (~1e-16/h² = 1e-8).
        let scale = exact.k1.abs().max(exact.k2.abs());
        assert!(
            (fd.mean - exact.mean).abs() < 1e-6 * scale,
            "{fd:?} {exact:?}"
        );
        assert!((fd.gauss - exact.gauss).abs() < 1e-6 * scale * scale);
    }
}

#[test]
fn quadrature_converges_fast_on_a_pde_patch() {
    let d = cup();
    let s = d.surfaces[1].pde().unwrap();
    let reference = analyze_surface(s, &Quadrature::default()).unwrap();
    assert!(
        reference.converged && reference.error < 1e-10,
        "{reference:?}"
    );
    let err = |nu: usize, nv: usize| {
        let i = integrate_surface(s, &Quadrature::fixed(nu, nv)).unwrap();
        let r = reference.integrals;
        rel(i.area, r.area)
            .max(rel(i.mean_sq, r.mean_sq))
            .max(rel(i.volume, r.volume))
    };
    let errors: Vec<f64> = [(8, 8), (16, 16), (32, 32)]
        .iter()
        .map(|&(a, b)| err(a, b))
        .collect();
    // Each doubling gains at least two orders of magnitude (spectral in v, order 16 in u).
    assert!(errors[0] > 1e-9, "{errors:?}");
    assert!(errors[1] < 1e-2 * errors[0], "{errors:?}");
    assert!(errors[2] < 1e-9, "{errors:?}");
}

#[test]
fn cup_totals_orientation_and_volume() {
    let d = cup();
    let di = integrate_design(&d, &Quadrature::default()).unwrap();
    // The base closes at a point (a pole), the belly is shared, the rim is open.
    assert!(!di.closed);
    assert_eq!(di.caps.len(), 1, "{:?}", di.caps);
    assert_eq!((di.caps[0].patch, di.caps[0].u), (1, 1.0));
    assert!(di.caps[0].planarity < 1e-12);
    // Ends 1–0 at the belly: the same orientation on both.
    assert_eq!(di.orientation[0], di.orientation[1]);
    let sum: f64 = di.patches.iter().map(|p| p.area).sum();
    assert_eq!(sum, di.total.area);
    // Independent volume: the cup is a body of revolution, V = ∫ π ρ² dz along both
    // profiles (ρ(u) = |X(u, 0)_xy|), up to the rim's plane.
    let gl = quadrature::composite_gauss(0.0, 1.0, 32, 8);
    let mut v = 0.0;
    for p in &d.surfaces {
        for (u, w) in gl.nodes.iter().zip(&gl.weights) {
            let q = p.surface().partials(*u, 0.0);
            let rho2 = q.x.x * q.x.x + q.x.y * q.x.y;
            v += w * PI * rho2 * q.xu.z;
        }
    }
    assert!(rel(di.total.volume, v) < 1e-10, "{} {v}", di.total.volume);
    // The rim's cap: a disc of radius 1.35 at height 2.4.
    assert!(rel(di.caps[0].area, PI * 1.35 * 1.35) < 1e-10);
    assert!(rel(di.caps[0].volume, PI * 1.35 * 1.35 * 2.4 / 3.0) < 1e-10);
}

#[test]
fn volume_and_energies_do_not_depend_on_placement() {
    let text = include_str!("../../../../examples/cup.toml");
    let a = integrate_design(&cup(), &Quadrature::default()).unwrap();
    // Move every curve: circles' and the point's centres.
    let moved = text
        .replace("center = [0.0, 0.0,", "center = [3.0, -7.0,")
        .replace("at = [0.0, 0.0, 0.0]", "at = [3.0, -7.0, 0.0]");
    assert_ne!(moved, text);
    let b = integrate_design(
        &build_design(&parse_design(&moved).unwrap()).unwrap(),
        &Quadrature::default(),
    )
    .unwrap();
    for (x, y) in [
        (a.total.volume, b.total.volume),
        (a.total.area, b.total.area),
        (a.total.mean, b.total.mean),
        (a.total.bending_energy(), b.total.bending_energy()),
    ] {
        assert!(rel(x, y) < 1e-10, "{x} {y}");
    }
}

#[test]
fn bad_quadrature_settings_are_errors() {
    let s = Sphere::new(1.0, Vec3::zeros());
    let q = Quadrature {
        order: 0,
        ..Default::default()
    };
    assert_eq!(
        integrate_surface(&s, &q).unwrap_err().to_string(),
        "quadrature.order: must be between 1 and 64 (got 0)"
    );
    let q = Quadrature {
        tolerance: f64::NAN,
        ..Default::default()
    };
    assert!(integrate_surface(&s, &q)
        .unwrap_err()
        .to_string()
        .starts_with("quadrature.tolerance"));
    struct Bad;
    impl Surface for Bad {
        fn v_domain(&self) -> VDomain {
            VDomain::Periodic
        }
        fn partials(&self, u: f64, _v: f64) -> Partials {
            Partials {
                x: Vec3::new(1.0 / (u - u), 0.0, 0.0),
                ..Default::default()
            }
        }
    }
    assert!(integrate_surface(&Bad, &Quadrature::default())
        .unwrap_err()
        .to_string()
        .contains("not finite"));
}

/// A design of `[[parametric]]` surfaces.
fn parametric_design(body: &str) -> crate::design::SolvedDesign {
    build_design(&parse_design(body).unwrap()).unwrap()
}

#[test]
fn sphere_cylinder_torus_as_design_surfaces_match_closed_forms() {
    // Sphere of radius 1.7 about (1, 2, 3), outward as written.
    let r = 1.7f64;
    let d = parametric_design(
        r#"
[[parametric]]
name = "ball"
x = "1 + 1.7*sin(pi*u)*cos(v)"
y = "2 + 1.7*sin(pi*u)*sin(v)"
z = "3 + 1.7*cos(pi*u)"
"#,
    );
    let di = integrate_design(&d, &Quadrature::default()).unwrap();
    assert!(di.closed && di.caps.is_empty(), "{di:?}");
    assert_eq!(di.orientation, vec![1.0]);
    let t = di.total;
    assert!(rel(t.area, 4.0 * PI * r * r) < 1e-12, "{t:?}");
    assert!(rel(t.volume, 4.0 / 3.0 * PI * r.powi(3)) < 1e-12, "{t:?}");
    assert!(rel(t.mean, -4.0 * PI * r) < 1e-12, "{t:?}");
    assert!(rel(t.gauss, 4.0 * PI) < 1e-12, "{t:?}");
    assert!(rel(t.willmore(), 16.0 * PI) < 1e-12, "{t:?}");
    let a = &di.analyses[0];
    assert!(
        rel(a.gauss_range.0, 1.0 / (r * r)) < 1e-12 && rel(a.gauss_range.1, 1.0 / (r * r)) < 1e-12
    );
    assert!(rel(a.mean_range.0, -1.0 / r) < 1e-12 && rel(a.mean_range.1, -1.0 / r) < 1e-12);

    // Cylinder of radius 0.8 and height 3 (inward as written: turned outward), open: two caps;
    // and a torus R = 2, r = 0.5, written with v along the tube (inward normal again).
    let d = parametric_design(
        r#"
[[parametric]]
name = "tube"
x = "0.8*cos(v)"
y = "0.8*sin(v)"
z = "3*u"

[[parametric]]
name = "ring"
x = "(2 + 0.5*cos(2*pi*u))*cos(v) + 10"
y = "(2 + 0.5*cos(2*pi*u))*sin(v)"
z = "0.5*sin(2*pi*u)"
"#,
    );
    let di = integrate_design(&d, &Quadrature::default()).unwrap();
    assert!(!di.closed);
    assert_eq!(di.orientation, vec![-1.0, -1.0]);
    let (c, t) = (di.patches[0], di.patches[1]);
    let (rc, h) = (0.8f64, 3.0);
    assert!(rel(c.area, 2.0 * PI * rc * h) < 1e-12, "{c:?}");
    assert!(rel(c.mean, -PI * h) < 1e-12, "{c:?}");
    assert!(rel(c.mean_sq, PI * h / (2.0 * rc)) < 1e-12, "{c:?}");
    assert!(c.gauss.abs() < 1e-12, "{c:?}");
    let (big, small) = (2.0f64, 0.5f64);
    assert!(rel(t.area, 4.0 * PI * PI * big * small) < 1e-12, "{t:?}");
    assert!(
        rel(t.volume, 2.0 * PI * PI * big * small * small) < 1e-12,
        "{t:?}"
    );
    assert!(rel(t.mean, -2.0 * PI * PI * big) < 1e-12, "{t:?}");
    let w = PI * PI * big * big / (small * (big * big - small * small).sqrt());
    assert!(rel(t.mean_sq, w) < 1e-10, "{t:?}");
    assert!(t.gauss.abs() < 1e-10, "{t:?}");
    // The enclosed volumes: the capped cylinder plus the torus.
    assert_eq!(di.caps.len(), 2);
    assert!(
        rel(
            di.total.volume,
            PI * rc * rc * h + 2.0 * PI * PI * big * small * small
        ) < 1e-12,
        "{di:?}"
    );
    // Pointwise curvature of the torus on its outer equator (u = 0, v = 0), inward normal:
    // κ = 1/r along the tube and 1/(R + r) along the parallel.
    let c = curvature(&d.surfaces[1].surface().partials(0.0, 0.0)).unwrap();
    assert!(rel(c.k1, 1.0 / small) < 1e-13 && rel(c.k2, 1.0 / (big + small)) < 1e-13);
}

#[test]
fn parametric_errors_are_located() {
    let text =
        "title = \"t\"\n[[parametric]]\nname = \"s\"\nx = \"cos(v)\"\ny = \"w\"\nz = \"0\"\n";
    let e = build_design(&parse_design(text).unwrap()).unwrap_err();
    assert_eq!(
        crate::spec::describe_error("d.toml", text, &e),
        "d.toml:5:1: parametric[0].y: unknown variable 'w'; formulas use u and v"
    );
    let text = "[[parametric]]\nname = \"s\"\nx = \"u\"\ny = \"v\"\nz = \"0\"\ndomain = [1, 0]\n";
    let e = crate::design::validate_design(&parse_design(text).unwrap()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "parametric[0].domain: must be an interval [v0, v1] with v0 < v1 (got [1, 0])"
    );
    let text = "[[parametric]]\nname = \"s\"\nx = \"u\"\ny = \"v\"\nz = \"0\"\ncolour = 1\n";
    assert!(parse_design(text)
        .unwrap_err()
        .to_string()
        .contains("unknown field `colour`"));
    let text = "[[parametric]]\nname = \"s\"\nx = \"u\"\ny = \"v\"\nz = \"0\"\ndomain = [0, 1]\n\
                [[parametric]]\nname = \"s\"\nx = \"u\"\ny = \"v\"\nz = \"1\"\ndomain = [0, 1]\n";
    let e = crate::design::validate_design(&parse_design(text).unwrap()).unwrap_err();
    assert_eq!(
        e.to_string(),
        "parametric[1].name: 's' is already the name of parametric[0]"
    );
    // An open sheet: area only, no volume meaning, not closed.
    let text = "[[parametric]]\nname = \"s\"\nx = \"u\"\ny = \"v\"\nz = \"0\"\ndomain = [0, 2]\n";
    let d = build_design(&parse_design(text).unwrap()).unwrap();
    let di = integrate_design(&d, &Quadrature::default()).unwrap();
    assert!(!di.closed && di.caps.is_empty());
    assert!(rel(di.total.area, 2.0) < 1e-14 && di.total.mean_sq == 0.0);
}

#[test]
fn pde_pole_has_a_finite_curvature_limit() {
    // The cup's base closes at a point at u = 0: the pointwise formulas are 0/0 there.
    let d = cup();
    let s = d.surfaces[0].pde().unwrap();
    assert!(curvature(&s.partials(0.0, 0.4)).is_none());
    let pole = curvature_at(s, 0.0, 0.4).unwrap();
    assert!(pole.gauss.is_finite() && pole.mean.is_finite(), "{pole:?}");
    // The limit continues the values just inside (which change by O(u) there).
    let near = curvature(&s.partials(1e-5, 0.4)).unwrap();
    assert!(
        (pole.gauss - near.gauss).abs() < 1e-3 * near.gauss.abs(),
        "{pole:?} {near:?}"
    );
    assert!(
        (pole.mean - near.mean).abs() < 1e-3 * near.mean.abs(),
        "{pole:?} {near:?}"
    );
    // Axisymmetric: the same limit from every direction v.
    let other = curvature_at(s, 0.0, 2.9).unwrap();
    assert!((other.gauss - pole.gauss).abs() < 1e-6 * pole.gauss.abs());
}

/// A B-spline surface of 3 × 3 bicubic spans is C² at its knots: panels that straddle a knot see
/// an integrand with a jump in its third derivative and converge only algebraically (the
/// analysis of this example once refined to the 4-million-node budget, about 45 s, without
/// converging). With panels ending at the knots ([`Surface::breaks`]) it converges in a few
/// levels, to the value of a fine fixed rule.
#[test]
fn spline_surfaces_are_integrated_piece_by_piece_between_their_knots() {
    let spec = parse_design(include_str!(
        "../../../../examples/spline/coons_bspline.toml"
    ))
    .unwrap();
    let d = build_design(&spec).unwrap();
    let s = d.surfaces[0].surface();
    let (bu, bv) = s.breaks();
    assert_eq!(bu.len(), 2, "{bu:?}");
    assert_eq!(bv.len(), 2, "{bv:?}");
    let a = analyze_surface(s, &Quadrature::default()).unwrap();
    assert!(a.converged, "error {}", a.error);
    assert!(
        a.u_nodes * a.v_nodes <= 1 << 14,
        "{} × {}",
        a.u_nodes,
        a.v_nodes
    );
    // A fixed rule of 16 panels of 8 nodes on each of the 3 pieces in each direction.
    let fine = analyze_surface(s, &Quadrature::fixed(8 * 48, 8 * 48)).unwrap();
    assert_eq!(fine.u_nodes, 8 * 48);
    for (x, y) in [
        (a.integrals.area, fine.integrals.area),
        (a.integrals.mean_sq, fine.integrals.mean_sq),
        (a.integrals.gauss, fine.integrals.gauss),
    ] {
        assert!(rel(x, y) < 1e-10, "{x} vs {y}");
    }
}

/// A spline surface degenerate to a curve (seed 003's example 1: `x(u, v) = f(u + v)`) has no
/// area at any node; its analysis stops after two levels instead of refining rounding residue
/// to the node budget.
#[test]
fn a_surface_degenerate_at_every_node_converges_at_once() {
    let spec = parse_design(include_str!("../../../../examples/spline/example1.toml")).unwrap();
    let d = build_design(&spec).unwrap();
    let a = analyze_surface(d.surfaces[0].surface(), &Quadrature::default()).unwrap();
    assert!(a.converged);
    assert_eq!(a.integrals.area, 0.0);
    assert_eq!(a.degenerate_nodes, a.u_nodes * a.v_nodes);
    assert!(a.u_nodes <= 32, "{}", a.u_nodes);
}
