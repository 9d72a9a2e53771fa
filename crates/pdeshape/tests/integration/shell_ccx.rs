//! The CalculiX pipeline against closed forms of thin shells. These run the solver (`ccx`):
//! `.ci/shell.sh` runs them with `--ignored` and they fail when it is missing.

use pdeshape::shell::*;
use pdeshape::surface::{Partials, Surface, VDomain};
use pdeshape::Vec3;
use std::f64::consts::PI;

use crate::shell_common::Cylinder;

/// The sphere of radius `R` from the pole `u = 0` to the pole `u = 1`.
struct Sphere {
    r: f64,
}

impl Surface for Sphere {
    fn v_domain(&self) -> VDomain {
        VDomain::Periodic
    }
    fn partials(&self, u: f64, v: f64) -> Partials {
        let (sv, cv) = v.sin_cos();
        let th = PI * u;
        let (st, ct) = th.sin_cos();
        let r = self.r;
        Partials {
            x: Vec3::new(r * st * cv, r * st * sv, -r * ct),
            xu: Vec3::new(r * PI * ct * cv, r * PI * ct * sv, r * PI * st),
            xv: Vec3::new(-r * st * sv, r * st * cv, 0.0),
            xuu: Vec3::new(
                -r * PI * PI * st * cv,
                -r * PI * PI * st * sv,
                r * PI * PI * ct,
            ),
            xuv: Vec3::new(-r * PI * ct * sv, r * PI * ct * cv, 0.0),
            xvv: Vec3::new(-r * st * cv, -r * st * sv, 0.0),
        }
    }
}

const T: f64 = 0.5e-3;

fn run(model: &ShellModel) -> ShellReport {
    analyse(model, &RunOptions::default()).expect("CalculiX run (is ccx installed?)")
}

/// Largest relative deviation from `want` of `f(node)` over the nodes with `u` in `band`.
fn deviation(
    model: &ShellModel,
    band: (f64, f64),
    want: f64,
    f: impl Fn(usize) -> f64,
) -> (f64, usize) {
    let mut worst = 0.0f64;
    let mut count = 0;
    for (k, &(_, u, _)) in model.mesh.params.iter().enumerate() {
        if u >= band.0 && u <= band.1 {
            worst = worst.max((f(k) - want).abs() / want.abs());
            count += 1;
        }
    }
    (worst, count)
}

/// Stress component `a · S · b` of `[sxx, syy, szz, sxy, syz, szx]`.
fn component(s: [f64; 6], a: [f64; 3], b: [f64; 3]) -> f64 {
    let m = [[s[0], s[3], s[5]], [s[3], s[1], s[4]], [s[5], s[4], s[2]]];
    (0..3)
        .map(|i| (0..3).map(|j| a[i] * m[i][j] * b[j]).sum::<f64>())
        .sum()
}

fn cylinder_rim_load(nu: usize, nv: usize) -> (ShellModel, ShellReport) {
    let cyl = Cylinder {
        r: 0.05,
        z0: 0.0,
        h: 0.1,
    };
    let mesh = ShellMesh::new(&[&cyl], &["wall"], nu, nv).unwrap();
    let model = ShellModel {
        mesh,
        thickness: T,
        material: Material::POLYSTYRENE,
        clamped: vec![(0, Side::U0)],
        line_loads: vec![LineLoad {
            patch: 0,
            side: Side::U1,
            force_per_length: 15.0,
            direction: [0.0, 0.0, -1.0],
        }],
        pressure: 0.0,
    };
    let report = run(&model);
    (model, report)
}

#[test]
#[ignore = "needs CalculiX; run by .ci/shell.sh"]
fn clamped_cylinder_under_a_rim_line_load() {
    // Membrane stress q/t (compressive, axial), largest shear q/(2t), away from the clamped
    // base (the bending boundary layer decays over a few √(Rt) ≈ 5 mm) and the loaded rim.
    let q = 15.0;
    let mut errors = Vec::new();
    for (nu, nv) in [(6, 12), (12, 24)] {
        let (model, report) = cylinder_rim_load(nu, nv);
        let band = (0.3, 0.7);
        let (axial, count) = deviation(&model, band, -q / T, |k| report.mid_stress[k][2]);
        let (shear, _) = deviation(&model, band, q / (2.0 * T), |k| report.max_shear[k]);
        assert!(count > 0);
        eprintln!(
            "{nu}×{nv}: axial {axial:.2e}, shear {shear:.2e}, peak {:.4e}",
            report.peak.value
        );
        assert!(axial < 0.02 && shear < 0.02, "{nu}×{nv}: {axial} {shear}");
        // The rim's nodal forces sum to q times the length of its quadratic edges, which
        // differs from 2πR by O(θ⁴) relatively (θ = 2π/nv: 1e-4 at nv = 12).
        let total: f64 = model.nodal_forces().iter().map(|(_, f)| f[2]).sum();
        let theta = 2.0 * PI / nv as f64;
        let want = -q * 2.0 * PI * 0.05;
        assert!((total - want).abs() < theta.powi(4) * want.abs(), "{total}");
        errors.push(shear.max(axial));
    }
    assert!(errors[1] <= errors[0], "not converging: {errors:?}");
}

#[test]
#[ignore = "needs CalculiX; run by .ci/shell.sh"]
fn cylinder_under_internal_pressure() {
    // Hoop stress pR/t, axial ≈ 0 (open ends), away from the base. The largest shear is on the
    // inner surface, where the radial stress is −p: (pR/t + p)/2 (the solver's expanded shell
    // resolves the stress through the thickness).
    let (r, p) = (0.05, 1000.0);
    let mut errors = Vec::new();
    for (nu, nv) in [(8, 32), (16, 64)] {
        let cyl = Cylinder { r, z0: 0.0, h: 0.1 };
        let mesh = ShellMesh::new(&[&cyl], &["wall"], nu, nv).unwrap();
        let model = ShellModel {
            mesh,
            thickness: T,
            material: Material::POLYSTYRENE,
            clamped: vec![(0, Side::U0)],
            line_loads: vec![],
            pressure: p,
        };
        // Outward normals: the pressure pushes the wall out.
        for (x, n) in model.mesh.nodes.iter().zip(&model.mesh.normals) {
            assert!(x[0] * n[0] + x[1] * n[1] > 0.0);
        }
        let report = run(&model);
        let hoop = |k: usize| {
            let x = model.mesh.nodes[k];
            let rr = (x[0] * x[0] + x[1] * x[1]).sqrt();
            let e = [-x[1] / rr, x[0] / rr, 0.0];
            component(report.mid_stress[k], e, e)
        };
        let (h, count) = deviation(&model, (0.4, 0.8), p * r / T, hoop);
        let tau = (p * r / T + p) / 2.0;
        let (s, _) = deviation(&model, (0.4, 0.8), tau, |k| report.max_shear[k]);
        assert!(count > 0);
        eprintln!("{nu}×{nv}: hoop {h:.2e}, shear {s:.2e}");
        assert!(h < 0.02 && s < 0.02, "{nu}×{nv}: {h} {s}");
        errors.push(h.max(s));
    }
    assert!(errors[1] <= errors[0], "not converging: {errors:?}");
}

#[test]
#[ignore = "needs CalculiX; run by .ci/shell.sh"]
fn sphere_under_internal_pressure() {
    // Membrane stress pR/(2t) in every direction; held at one pole (a self-equilibrated load:
    // the support only removes rigid motion). Checked away from both poles.
    let (r, p) = (0.05, 1000.0);
    let mut errors = Vec::new();
    for (nu, nv) in [(12, 24), (24, 48)] {
        let mesh = ShellMesh::new(&[&Sphere { r }], &["sphere"], nu, nv).unwrap();
        let model = ShellModel {
            mesh,
            thickness: T,
            material: Material::POLYSTYRENE,
            clamped: vec![(0, Side::U0)],
            line_loads: vec![],
            pressure: p,
        };
        let report = run(&model);
        let want = p * r / (2.0 * T);
        let merid = |k: usize| {
            let x = model.mesh.nodes[k];
            let rho = (x[0] * x[0] + x[1] * x[1]).sqrt();
            let e = [-x[1] / rho, x[0] / rho, 0.0];
            component(report.mid_stress[k], e, e)
        };
        let (h, count) = deviation(&model, (0.25, 0.75), want, merid);
        assert!(count > 0);
        eprintln!("{nu}×{nv}: hoop {h:.2e}");
        assert!(h < 0.02, "{nu}×{nv}: {h}");
        errors.push(h);
    }
    assert!(errors[1] <= errors[0], "not converging: {errors:?}");
}

/// The gradient of a strength problem: `max_shear`'s forward differences (one analysis per
/// parameter at [`SHEAR_STEP`] of its scale) against central differences at four times the
/// step, from the problem's own evaluations. They agree within the two differences' error
/// bounds: the forward difference's truncation `h/2 |τ''|` (`τ''` from the central stencil),
/// the central one's `H²/6 |τ'''|` (taken as `H/3 |τ''|`, `τ'''` of the size of `τ''/H`), and
/// the rounding of the stresses, `2 ε τ / h` and `ε τ / H`. The constraint's gradient is the
/// derivative over the yield stress.
#[test]
#[ignore = "needs CalculiX; run by .ci/shell.sh"]
fn the_shell_stress_gradient_matches_central_differences() {
    use pdeshape::optimize::{Problem, SHEAR_ROUNDING, SHEAR_STEP, VARIABLES};
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../examples/yoghurt_optimize.toml"),
    )
    .unwrap()
    .replace("thickness = 0.0005", "thickness = 0.00015")
    .replace("elements = [4, 32]", "elements = [2, 16]");
    let p = Problem::new(&pdeshape::parse_design(&text).unwrap()).unwrap();
    let shear = VARIABLES.iter().position(|&v| v == "max_shear").unwrap();
    let x = p.parameters.initial();
    let g = p.gradient(&x).unwrap();
    let s = &g.sensitivities;
    let tau = s.values[shear];
    assert!(tau.is_finite() && tau > 0.0);
    let constraint = g
        .constraints
        .iter()
        .find(|c| c.text.contains("max_shear"))
        .unwrap();
    let tau_at = |k: usize, d: f64| {
        let mut y = x.clone();
        y[k] += d;
        p.evaluate(&y).unwrap().variables[shear]
    };
    let mut checked = 0;
    for k in 0..x.len() {
        let d = s.d_values[k][shear];
        let h = SHEAR_STEP * s.scales[k];
        let big = 4.0 * h;
        let (plus, minus) = (tau_at(k, big), tau_at(k, -big));
        let central = (plus - minus) / (2.0 * big);
        let second = (plus - 2.0 * tau + minus) / (big * big);
        let eps = SHEAR_ROUNDING * tau;
        let bound = (h / 2.0 + big / 3.0) * second.abs() + 2.0 * eps / h + eps / big;
        eprintln!(
            "{}: forward {d:.6e}, central {central:.6e}, bound {bound:.3e}",
            p.parameters.list[k].name
        );
        assert!(
            (d - central).abs() <= bound,
            "{}",
            p.parameters.list[k].name
        );
        let yield_stress = s.values[VARIABLES.iter().position(|&v| v == "yield").unwrap()];
        let want = d / yield_stress;
        assert!((constraint.gradient[k] - want).abs() <= 1e-12 * want.abs());
        checked += usize::from(d != 0.0);
    }
    assert!(
        checked >= x.len() / 2,
        "the stress moves with most parameters"
    );
}
