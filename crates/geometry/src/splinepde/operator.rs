//! Linear constant-coefficient PDE operators and their quadratic functionals.

use crate::{Error, Result, Vec3};

/// A linear constant-coefficient operator of one of the two families of seed 003.
#[derive(Clone, Debug, PartialEq)]
pub enum Operator {
    /// `a x_uu + b x_uv + c x_vv + d x_u + e x_v + f x = g` (seed 003 §1), `g` a constant vector.
    Second {
        /// Coefficient of `x_uu`.
        a: f64,
        /// Coefficient of `x_uv`.
        b: f64,
        /// Coefficient of `x_vv`.
        c: f64,
        /// Coefficient of `x_u`.
        d: f64,
        /// Coefficient of `x_v`.
        e: f64,
        /// Coefficient of `x`.
        f: f64,
        /// The constant right-hand side `g`.
        g: Vec3,
    },
    /// `a x_uuuu + b x_uuuv + c x_uuvv + d x_uvvv + e x_vvvv = 0` (seed 003 Eq. 4).
    Fourth {
        /// Coefficient of `x_uuuu`.
        a: f64,
        /// Coefficient of `x_uuuv`.
        b: f64,
        /// Coefficient of `x_uuvv`.
        c: f64,
        /// Coefficient of `x_uvvv`.
        d: f64,
        /// Coefficient of `x_vvvv`.
        e: f64,
    },
}

/// One term `w · <∂u^a1 ∂v^b1 x, ∂u^a2 ∂v^b2 x>` of a quadratic functional `∫ Σ terms du dv`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InnerTerm {
    /// Weight `w`.
    pub w: f64,
    /// Derivative orders `[a1, b1]` (in `u`, `v`) of the left factor.
    pub left: [usize; 2],
    /// Derivative orders `[a2, b2]` (in `u`, `v`) of the right factor.
    pub right: [usize; 2],
}

impl Operator {
    /// The Laplace operator `x_uu + x_vv` (harmonic surfaces).
    pub fn laplace() -> Self {
        Operator::second(1.0, 0.0, 1.0)
    }

    /// The homogeneous second-order operator `a x_uu + b x_uv + c x_vv` (seed 003 Eq. 2).
    pub fn second(a: f64, b: f64, c: f64) -> Self {
        Operator::Second {
            a,
            b,
            c,
            d: 0.0,
            e: 0.0,
            f: 0.0,
            g: Vec3::zeros(),
        }
    }

    /// `L_{a,b,c,d,e}` of seed 003 §2/§5: `a x_uuuu + b x_uuuv + c x_uuvv + d x_uvvv + e x_vvvv`.
    pub fn fourth(a: f64, b: f64, c: f64, d: f64, e: f64) -> Self {
        Operator::Fourth { a, b, c, d, e }
    }

    /// The biharmonic operator `F_bihar = L_{1,0,2,0,1}` (seed 003 §5).
    pub fn biharmonic() -> Self {
        Operator::fourth(1.0, 0.0, 2.0, 0.0, 1.0)
    }

    /// The Coons functional's operator `F_Coons = L_{0,0,1,0,0}`: `x_uuvv = 0` (seed 003 §5).
    pub fn coons() -> Self {
        Operator::fourth(0.0, 0.0, 1.0, 0.0, 0.0)
    }

    /// The modified biharmonic operator `F_a = L_{1,0,2a²,0,a⁴}` (seed 003 §5).
    pub fn modified_biharmonic(a: f64) -> Self {
        Operator::fourth(1.0, 0.0, 2.0 * a * a, 0.0, a.powi(4))
    }

    /// The terms `(coefficient, [order in u, order in v])` of the operator.
    pub fn terms(&self) -> Vec<(f64, [usize; 2])> {
        let all = match *self {
            Operator::Second {
                a, b, c, d, e, f, ..
            } => vec![
                (a, [2, 0]),
                (b, [1, 1]),
                (c, [0, 2]),
                (d, [1, 0]),
                (e, [0, 1]),
                (f, [0, 0]),
            ],
            Operator::Fourth { a, b, c, d, e } => vec![
                (a, [4, 0]),
                (b, [3, 1]),
                (c, [2, 2]),
                (d, [1, 3]),
                (e, [0, 4]),
            ],
        };
        all.into_iter().filter(|(w, _)| *w != 0.0).collect()
    }

    /// The right-hand side `g` (zero for the fourth-order family).
    pub fn rhs(&self) -> Vec3 {
        match self {
            Operator::Second { g, .. } => *g,
            Operator::Fourth { .. } => Vec3::zeros(),
        }
    }

    /// The quadratic functional whose Euler–Lagrange equation is the operator's principal part:
    /// `∫ a|x_u|² + b<x_u,x_v> + c|x_v|²` (seed 003 Eq. 1) for the second-order family and
    /// `∫ a|x_uu|² + b<x_uu,x_uv> + c|x_uv|² + d<x_uv,x_vv> + e|x_vv|²` (`L_{a,b,c,d,e}`, seed 003
    /// §2) for the fourth-order one. The first-order and zeroth-order terms `d, e, f` of the
    /// second-order family do not enter.
    pub fn functional(&self) -> Vec<InnerTerm> {
        let t = |w: f64, left: [usize; 2], right: [usize; 2]| InnerTerm { w, left, right };
        let all = match *self {
            Operator::Second { a, b, c, .. } => vec![
                t(a, [1, 0], [1, 0]),
                t(b, [1, 0], [0, 1]),
                t(c, [0, 1], [0, 1]),
            ],
            Operator::Fourth { a, b, c, d, e } => vec![
                t(a, [2, 0], [2, 0]),
                t(b, [2, 0], [1, 1]),
                t(c, [1, 1], [1, 1]),
                t(d, [1, 1], [0, 2]),
                t(e, [0, 2], [0, 2]),
            ],
        };
        all.into_iter().filter(|x| x.w != 0.0).collect()
    }

    /// The Dirichlet energy `∫ |x_u|² + |x_v|²`, used to pick among nets the functional above
    /// leaves undetermined.
    pub fn dirichlet() -> Vec<InnerTerm> {
        vec![
            InnerTerm {
                w: 1.0,
                left: [1, 0],
                right: [1, 0],
            },
            InnerTerm {
                w: 1.0,
                left: [0, 1],
                right: [0, 1],
            },
        ]
    }

    /// Highest derivative order in u and in v.
    pub fn max_orders(&self) -> [usize; 2] {
        self.terms()
            .iter()
            .fold([0, 0], |m, (_, o)| [m[0].max(o[0]), m[1].max(o[1])])
    }

    /// Checks that every coefficient is finite and that the operator is not zero.
    pub fn check(&self) -> Result<()> {
        let named: Vec<(&str, f64)> = match *self {
            Operator::Second {
                a,
                b,
                c,
                d,
                e,
                f,
                g,
            } => vec![
                ("a", a),
                ("b", b),
                ("c", c),
                ("d", d),
                ("e", e),
                ("f", f),
                ("g[0]", g.x),
                ("g[1]", g.y),
                ("g[2]", g.z),
            ],
            Operator::Fourth { a, b, c, d, e } => {
                vec![("a", a), ("b", b), ("c", c), ("d", d), ("e", e)]
            }
        };
        for (name, x) in named {
            if !x.is_finite() {
                return Err(Error::invalid(format!("must be finite (got {x})")).at(name));
            }
        }
        if self.terms().is_empty() {
            return Err(Error::invalid(
                "every coefficient is zero: the PDE says nothing",
            ));
        }
        Ok(())
    }

    /// A one-line description, e.g. `1 x_uuuu + 2 x_uuvv + 1 x_vvvv = 0`.
    pub fn describe(&self) -> String {
        let name = |o: [usize; 2]| {
            if o == [0, 0] {
                "x".to_string()
            } else {
                format!("x_{}{}", "u".repeat(o[0]), "v".repeat(o[1]))
            }
        };
        let lhs: Vec<String> = self
            .terms()
            .iter()
            .map(|(w, o)| format!("{w} {}", name(*o)))
            .collect();
        let g = self.rhs();
        let rhs = if g == Vec3::zeros() {
            "0".to_string()
        } else {
            format!("[{}, {}, {}]", g.x, g.y, g.z)
        };
        format!("{} = {rhs}", lhs.join(" + "))
    }
}
