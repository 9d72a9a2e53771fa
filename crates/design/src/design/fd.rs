//! Designs solved by finite differences (`solver = "fd"` or `[solver] method = "fd"`): the
//! design file's periodic patches, each `(∂uu + a²∂vv)^N X = 0` with `N ≤ 3` and its conditions
//! at `u = 0` and `u = 1` (orders `0 … N−1` at each end), solved on the grid `solver.grid`.

use super::solved::ConditionInfo;
use super::validate::patch_specs;
use crate::fd::{solve_periodic, EdgeFn, FdSurface, PeriodicProblem, MAX_ORDER, MAX_UNKNOWNS};
use crate::spec::{DesignSpec, OperatorSpec, SolverMethod};
use crate::{Error, Result, Vec3};

/// Default finite-difference grid: intervals in `u`, nodes around `v`.
pub const DEFAULT_GRID: [usize; 2] = [64, 128];

/// The smallest grid `(nu, nv)` the scheme takes for half order `n`.
fn min_grid(n: usize) -> (usize, usize) {
    ((2 * n).max(4), (2 * n + 1).max(4))
}

/// Checks what the finite-difference solver needs beyond a valid design: polyharmonic operators
/// with `N ≤ 3`, conditions only at `u = 0` and `u = 1` with u-derivative orders below `N`, and
/// the grid `solver.grid`. Also refuses `solver.grid` without `method = "fd"`.
pub(crate) fn check(spec: &DesignSpec) -> Result<()> {
    let s = &spec.solver;
    if s.method != SolverMethod::Fd {
        if s.grid.is_some() {
            return Err(Error::invalid(
                "the grid is for the finite-difference solver: set method = \"fd\" or remove it",
            )
            .at("solver.grid"));
        }
        return Ok(());
    }
    let [nu, nv] = s.grid.unwrap_or(DEFAULT_GRID);
    for (place, op_place, op, conds) in patch_specs(spec)? {
        let n = match op {
            OperatorSpec::Polyharmonic { order, .. } => order,
            _ => return Err(Error::invalid(
                "the finite-difference solver takes only the polyharmonic operator (∂uu + a²∂vv)^N",
            )
            .at(&format!("{op_place}.kind"))),
        };
        if n > MAX_ORDER {
            return Err(Error::invalid(format!(
                "the finite-difference solver takes N = 1 to {MAX_ORDER} (got {n})"
            ))
            .at(&format!("{op_place}.order")));
        }
        for (i, c) in conds.iter().enumerate() {
            if c.u != 0.0 && c.u != 1.0 {
                return Err(Error::invalid(format!(
                    "the finite-difference solver takes conditions at u = 0 and u = 1 only (got {})",
                    c.u
                ))
                .at(&format!("{place}[{i}].u")));
            }
            if c.derivative >= n {
                return Err(Error::invalid(format!(
                    "the finite-difference solver takes u-derivatives of orders 0 to {} at each end (got {})",
                    n - 1,
                    c.derivative
                ))
                .at(&format!("{place}[{i}].derivative")));
            }
        }
        let (mu, mv) = min_grid(n);
        if nu < mu {
            return Err(
                Error::invalid(format!("must be at least {mu} for N = {n} (got {nu})"))
                    .at("solver.grid[0]"),
            );
        }
        if nv < mv {
            return Err(
                Error::invalid(format!("must be at least {mv} for N = {n} (got {nv})"))
                    .at("solver.grid[1]"),
            );
        }
        let unknowns = (nu + 2 * n - 1).checked_mul(nv);
        if unknowns.is_none_or(|k| k > MAX_UNKNOWNS) {
            return Err(Error::invalid(format!(
                "a {nu} × {nv} grid has more than {MAX_UNKNOWNS} unknowns; refusing to allocate it"
            ))
            .at("solver.grid"));
        }
    }
    Ok(())
}

/// Solves one patch by [`solve_periodic`] on the grid `[nu, nv]`: `(∂uu + a²∂vv)^N X = 0` with the
/// patch's conditions (checked by [`check`]: orders `0 … N−1` at `u = 0` and at `u = 1`).
/// `place` is where the patch's conditions are (`conditions`, `patches[2].conditions`); errors
/// name the condition curve or the grid.
pub(crate) fn solve_patch(
    order: usize,
    a: f64,
    [nu, nv]: [usize; 2],
    conditions: &[ConditionInfo],
    place: &str,
) -> Result<FdSurface> {
    let n = order;
    // Condition index of (end, derivative order).
    let index = |u: f64, d: usize| {
        conditions
            .iter()
            .position(|c| c.u == u && c.derivative == d)
            .expect("checked by validate_design")
    };
    let fns: Vec<Box<dyn Fn(f64) -> Vec3 + Sync>> = conditions
        .iter()
        .map(|c| {
            let curve = c.curve.clone();
            Box::new(move |v: f64| curve.point(v)) as Box<dyn Fn(f64) -> Vec3 + Sync>
        })
        .collect();
    let pick = |u: f64| -> Vec<EdgeFn<'_>> { (0..n).map(|d| &*fns[index(u, d)]).collect() };
    solve_periodic(&PeriodicProblem {
        order: n,
        a,
        nu,
        nv,
        start: pick(0.0),
        end: pick(1.0),
        source: None,
    })
    .map_err(|e| {
        let inner = e.place().to_string();
        let at = |u: f64, rest: &str| {
            rest.trim_start_matches('[')
                .trim_end_matches(']')
                .parse::<usize>()
                .map(|d| format!("{place}[{}].curve", index(u, d)))
                .unwrap_or_else(|_| place.to_string())
        };
        let outer = if let Some(rest) = inner.strip_prefix("start") {
            at(0.0, rest)
        } else if let Some(rest) = inner.strip_prefix("end") {
            at(1.0, rest)
        } else {
            match inner.as_str() {
                "nu" => "solver.grid[0]".to_string(),
                "nv" => "solver.grid[1]".to_string(),
                "nu × nv" => "solver.grid".to_string(),
                _ => place.to_string(),
            }
        };
        if e.kind() == crate::ErrorKind::Invalid {
            Error::invalid(e.detail()).at(&outer)
        } else {
            e
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::{compile, validate_design, SurfaceKind};
    use crate::spec::parse_design;

    /// The finite-difference surface `k` of a compiled design.
    fn fd_surface(d: &crate::design::CompiledDesign, k: usize) -> &crate::fd::FdSurface {
        match &d.solved().surfaces[k].kind {
            SurfaceKind::Fd(s) => s,
            _ => panic!("surface {k} is not a finite-difference surface"),
        }
    }

    const CURVES: &str = r#"
[curves.base]
type = "ellipse"
center = [0, 0, 0]
rx = 1.0
ry = 0.7
[curves.rim]
type = "fourier"
a0 = [0.1, 0, 1]
cos = [[1.5, 0, 0], [0, 0, 0.1]]
sin = [[0, 1.2, 0], [0.2, 0, 0]]
[curves.t0]
type = "fourier"
a0 = [0, 0, 1]
cos = [[0.5, 0, 0]]
sin = [[0, 0.5, 0], [0, 0, 0.2]]
[curves.t1]
type = "fourier"
a0 = [0, 0, 0.5]
cos = [[0.8, 0, 0.1]]
sin = [[0, 0.6, 0]]
[curves.s0]
type = "fourier"
a0 = [0, 0, -0.3]
cos = [[0.2, 0, 0]]
[curves.s1]
type = "fourier"
a0 = [0, 0, 0.2]
sin = [[0, -0.3, 0], [0.1, 0, 0]]
"#;

    /// A periodic design of half order `n` (conditions of orders `< n` at both ends).
    fn text(n: usize, a: f64, solver: &str) -> String {
        let names = [("base", "t0", "s0"), ("rim", "t1", "s1")];
        let mut conds = Vec::new();
        for (u, (p, t, s)) in [0.0, 1.0].iter().zip(names) {
            for (d, c) in [p, t, s].iter().enumerate().take(n) {
                conds.push(format!(
                    "{{ u = {u:.1}, derivative = {d}, curve = \"{c}\" }}"
                ));
            }
        }
        format!(
            "{solver}\nconditions = [{}]\n[operator]\nkind = \"polyharmonic\"\norder = {n}\na = {a}\n{CURVES}",
            conds.join(", ")
        )
    }

    /// On a periodic design the finite-difference surface converges at second order to the
    /// analytic solver's surface (exact here: the curves are finite Fourier series).
    #[test]
    fn converges_to_the_analytic_surface_at_second_order() {
        for (n, a) in [(1, 1.0), (2, 1.2), (3, 0.8)] {
            let exact = compile(&parse_design(&text(n, a, "")).unwrap()).unwrap();
            let exact = exact.solved().surfaces[0].surface();
            let errors: Vec<f64> = [16, 32, 64]
                .iter()
                .map(|&k| {
                    let solver = format!("solver = {{ method = \"fd\", grid = [{k}, {}] }}", 2 * k);
                    let fd = compile(&parse_design(&text(n, a, &solver)).unwrap()).unwrap();
                    let s = fd_surface(&fd, 0);
                    let mut e: f64 = 0.0;
                    for i in 0..=s.nu() {
                        for j in 0..s.nodes_v() {
                            let (u, v) = (s.u_node(i), s.v_node(j));
                            e = e.max((s.node(i, j) - exact.point(u, v)).norm());
                        }
                    }
                    e
                })
                .collect();
            let orders: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
            eprintln!("N = {n}: errors {errors:?}, orders {orders:?}");
            assert!(
                orders.iter().all(|&o| o >= 1.8),
                "N = {n}: errors {errors:?}, orders {orders:?}"
            );
        }
    }

    #[test]
    fn solver_may_be_a_name_or_a_table() {
        let s = parse_design(&text(2, 1.0, "solver = \"fd\"")).unwrap();
        assert_eq!(s.solver.method, SolverMethod::Fd);
        assert_eq!(s.solver.modes, 12);
        let d = compile(&s).unwrap();
        assert_eq!(d.solved().fd_grid, Some(DEFAULT_GRID));
        assert_eq!(fd_surface(&d, 0).nu(), 64);
        let s = parse_design(&text(2, 1.0, "solver = \"analytic\"")).unwrap();
        assert_eq!(s.solver.method, SolverMethod::Analytic);
        let e = parse_design(&text(2, 1.0, "solver = \"fem\"")).unwrap_err();
        assert!(e.to_string().contains("fem"), "{e}");
        let e =
            parse_design(&text(2, 1.0, "solver = { method = \"fd\", grd = [8, 8] }")).unwrap_err();
        assert!(e.to_string().contains("grd"), "{e}");
    }

    fn place(text: &str) -> String {
        let spec = parse_design(text).unwrap();
        let e = validate_design(&spec).unwrap_err();
        // The same error from the builder.
        assert_eq!(compile(&spec).unwrap_err().place(), e.place());
        e.place().to_string()
    }

    #[test]
    fn designs_the_scheme_cannot_take_are_refused_with_their_place() {
        let fd = "solver = \"fd\"";
        assert_eq!(
            place(&text(
                2,
                1.0,
                "solver = { method = \"fd\", grid = [3, 16] }"
            )),
            "solver.grid[0]"
        );
        assert_eq!(
            place(&text(
                3,
                1.0,
                "solver = { method = \"fd\", grid = [16, 6] }"
            )),
            "solver.grid[1]"
        );
        assert_eq!(
            place(&text(
                2,
                1.0,
                "solver = { method = \"fd\", grid = [100000, 100000] }"
            )),
            "solver.grid"
        );
        // A grid without the finite-difference method.
        let spec = parse_design(&text(2, 1.0, "solver = { grid = [16, 16] }")).unwrap();
        assert_eq!(validate_design(&spec).unwrap_err().place(), "solver.grid");
        // An intermediate condition.
        let t = text(2, 1.0, fd).replace(
            "{ u = 1.0, derivative = 1, curve = \"t1\" }",
            "{ u = 0.5, derivative = 0, curve = \"t1\" }",
        );
        assert_eq!(place(&t), "conditions[3].u");
        // A second derivative with N = 2 (valid for the analytic solver).
        let t = text(2, 1.0, fd).replace(
            "{ u = 1.0, derivative = 1, curve = \"t1\" }",
            "{ u = 0.0, derivative = 2, curve = \"t1\" }",
        );
        assert_eq!(place(&t), "conditions[3].derivative");
        // Operators the scheme does not take.
        let t = text(2, 1.0, fd).replace(
            "kind = \"polyharmonic\"\norder = 2\na = 1",
            "kind = \"general\"\ncoefficients = [1, 3, 1]",
        );
        assert_eq!(place(&t), "operator.kind");
        let t = text(3, 1.0, fd);
        let conds_of_4 = t.replace("order = 3", "order = 4").replace(
            "conditions = [",
            "conditions = [{ u = 0.0, derivative = 3, curve = \"s0\" }, { u = 1.0, derivative = 3, curve = \"s1\" }, ",
        );
        assert_eq!(place(&conds_of_4), "operator.order");
        // Without the finite-difference method, the same design is solved analytically.
        let spec = parse_design(&text(2, 1.0, "")).unwrap();
        let d = compile(&spec).unwrap();
        assert!(matches!(d.solved().surfaces[0].kind, SurfaceKind::Pde(_)));
    }

    /// A curve that is not finite somewhere is refused, at the curve (where the curve's own
    /// checks find it) or at the condition using it (where only the grid's nodes do).
    #[test]
    fn non_finite_curves_are_named() {
        let t = text(2, 1.0, "solver = { method = \"fd\", grid = [8, 16] }").replace(
            "[curves.t1]\ntype = \"fourier\"\na0 = [0, 0, 0.5]\ncos = [[0.8, 0, 0.1]]\nsin = [[0, 0.6, 0]]",
            "[curves.t1]\ntype = \"formula\"\nx = \"1/(v - 0.7853981633974483)\"\ny = \"0\"\nz = \"0\"",
        );
        let spec = parse_design(&t).unwrap();
        let e = compile(&spec)
            .and_then(|d| d.solved().meshes(8, 16).map(|_| ()))
            .unwrap_err();
        assert!(
            e.place().starts_with("conditions[3]") || e.place().starts_with("curves.t1"),
            "{e}"
        );
        assert!(
            e.to_string().contains("inf") || e.to_string().contains("finite"),
            "{e}"
        );
    }
}
