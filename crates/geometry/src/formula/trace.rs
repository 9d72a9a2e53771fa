//! The expression tree of a parsed formula, read off exmex by evaluating the formula once on
//! symbols: [`Sym`] is a number type whose operators build the tree instead of computing, and
//! [`SymOps`] gives it exactly the operators of exmex's `FloatOpsFactory` (same names,
//! priorities, commutativity, unary and binary forms; a test compares the two lists). exmex
//! therefore parses the text as it parses it for `f64`, and the tree records the operations in
//! the order exmex applies them. Operations on two numbers are carried out at once with the same
//! `f64` functions exmex uses (so exmex's own constant folding at parse time, and the
//! simplifications of its symbolic derivatives, see the same numbers as in `f64`).

use exmex::{BinOp, MakeOperators, Operator};
use std::rc::Rc;
use std::str::FromStr;

/// A function of one argument, as exmex's `FloatOpsFactory` defines it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Op1 {
    Neg,
    Abs,
    Signum,
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Sinh,
    Cosh,
    Tanh,
    Asinh,
    Acosh,
    Atanh,
    Floor,
    Round,
    Ceil,
    Trunc,
    Fract,
    Exp,
    Sqrt,
    Cbrt,
    Ln,
    Log2,
    Log10,
}

impl Op1 {
    /// The value, computed exactly as exmex computes it for `f64`.
    pub(crate) fn apply(self, a: f64) -> f64 {
        match self {
            Op1::Neg => -a,
            Op1::Abs => a.abs(),
            Op1::Signum => a.signum(),
            Op1::Sin => a.sin(),
            Op1::Cos => a.cos(),
            Op1::Tan => a.tan(),
            Op1::Asin => a.asin(),
            Op1::Acos => a.acos(),
            Op1::Atan => a.atan(),
            Op1::Sinh => a.sinh(),
            Op1::Cosh => a.cosh(),
            Op1::Tanh => a.tanh(),
            Op1::Asinh => a.asinh(),
            Op1::Acosh => a.acosh(),
            Op1::Atanh => a.atanh(),
            Op1::Floor => a.floor(),
            Op1::Round => a.round(),
            Op1::Ceil => a.ceil(),
            Op1::Trunc => a.trunc(),
            Op1::Fract => a.fract(),
            Op1::Exp => a.exp(),
            Op1::Sqrt => a.sqrt(),
            Op1::Cbrt => a.cbrt(),
            Op1::Ln => a.ln(),
            Op1::Log2 => a.log2(),
            Op1::Log10 => a.log10(),
        }
    }
}

/// A function of two arguments (the operators `+ - * / ^` and `atan2`, `min`, `max`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Op2 {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
    Atan2,
    Min,
    Max,
}

impl Op2 {
    /// The value, computed exactly as exmex computes it for `f64`.
    pub(crate) fn apply(self, a: f64, b: f64) -> f64 {
        match self {
            Op2::Add => a + b,
            Op2::Sub => a - b,
            Op2::Mul => a * b,
            Op2::Div => a / b,
            Op2::Pow => a.powf(b),
            Op2::Atan2 => a.atan2(b),
            Op2::Min => a.min(b),
            Op2::Max => a.max(b),
        }
    }
}

/// A node of the expression tree: a number, the variable with a given slot (its position in the
/// formula's [`super::Variables`]), or an operation. Subtrees are shared, so a subexpression
/// exmex reuses appears once.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Sym {
    Num(f64),
    Var(usize),
    Un(Op1, Rc<Sym>),
    Bin(Op2, Rc<Sym>, Rc<Sym>),
}

impl Default for Sym {
    fn default() -> Self {
        Sym::Num(0.0)
    }
}

impl FromStr for Sym {
    type Err = std::num::ParseFloatError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        s.parse::<f64>().map(Sym::Num)
    }
}

/// For exmex's symbolic derivatives (their constants).
impl From<f32> for Sym {
    fn from(x: f32) -> Self {
        Sym::Num(f64::from(x))
    }
}

/// For exmex's symbolic derivatives (zero and one).
impl From<u8> for Sym {
    fn from(x: u8) -> Self {
        Sym::Num(f64::from(x))
    }
}

fn un(op: Op1, a: Sym) -> Sym {
    match a {
        Sym::Num(x) => Sym::Num(op.apply(x)),
        a => Sym::Un(op, Rc::new(a)),
    }
}

fn bin(op: Op2, a: Sym, b: Sym) -> Sym {
    match (a, b) {
        (Sym::Num(x), Sym::Num(y)) => Sym::Num(op.apply(x, y)),
        (a, b) => Sym::Bin(op, Rc::new(a), Rc::new(b)),
    }
}

/// exmex's `FloatOpsFactory` over [`Sym`]: the same operators, names, priorities and flags.
#[derive(Clone, Debug)]
pub(crate) struct SymOps;

macro_rules! unary {
    ($repr:literal, $op:expr) => {
        Operator::make_unary($repr, |a| un($op, a))
    };
}

impl MakeOperators<Sym> for SymOps {
    fn make<'a>() -> Vec<Operator<'a, Sym>> {
        let binop = |apply: fn(Sym, Sym) -> Sym, prio: i64, is_commutative: bool| BinOp {
            apply,
            prio,
            is_commutative,
        };
        vec![
            Operator::make_bin("^", binop(|a, b| bin(Op2::Pow, a, b), 4, false)),
            Operator::make_bin("*", binop(|a, b| bin(Op2::Mul, a, b), 2, true)),
            Operator::make_bin("/", binop(|a, b| bin(Op2::Div, a, b), 3, false)),
            Operator::make_bin_unary("+", binop(|a, b| bin(Op2::Add, a, b), 0, true), |a| a),
            Operator::make_bin_unary("-", binop(|a, b| bin(Op2::Sub, a, b), 1, false), |a| {
                un(Op1::Neg, a)
            }),
            Operator::make_bin("atan2", binop(|a, b| bin(Op2::Atan2, a, b), 0, false)),
            Operator::make_bin("min", binop(|a, b| bin(Op2::Min, a, b), 0, false)),
            Operator::make_bin("max", binop(|a, b| bin(Op2::Max, a, b), 0, false)),
            unary!("abs", Op1::Abs),
            unary!("signum", Op1::Signum),
            unary!("sin", Op1::Sin),
            unary!("cos", Op1::Cos),
            unary!("tan", Op1::Tan),
            unary!("asin", Op1::Asin),
            unary!("acos", Op1::Acos),
            unary!("atan", Op1::Atan),
            unary!("sinh", Op1::Sinh),
            unary!("cosh", Op1::Cosh),
            unary!("tanh", Op1::Tanh),
            unary!("asinh", Op1::Asinh),
            unary!("acosh", Op1::Acosh),
            unary!("atanh", Op1::Atanh),
            unary!("floor", Op1::Floor),
            unary!("round", Op1::Round),
            unary!("ceil", Op1::Ceil),
            unary!("trunc", Op1::Trunc),
            unary!("fract", Op1::Fract),
            unary!("exp", Op1::Exp),
            unary!("sqrt", Op1::Sqrt),
            unary!("cbrt", Op1::Cbrt),
            unary!("ln", Op1::Ln),
            unary!("log2", Op1::Log2),
            unary!("log10", Op1::Log10),
            unary!("log", Op1::Ln),
            Operator::make_constant("PI", Sym::Num(std::f64::consts::PI)),
            Operator::make_constant("π", Sym::Num(std::f64::consts::PI)),
            Operator::make_constant("E", Sym::Num(std::f64::consts::E)),
            Operator::make_constant("e", Sym::Num(std::f64::consts::E)),
            Operator::make_constant("TAU", Sym::Num(std::f64::consts::TAU)),
            Operator::make_constant("τ", Sym::Num(std::f64::consts::TAU)),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use exmex::FloatOpsFactory;

    /// Values that exercise every branch of the functions: signed zeros, infinities, NaN,
    /// subnormals, integers and halves (rounding), the edges of the inverse functions' domains.
    fn probes() -> Vec<f64> {
        let mut v = vec![
            0.0,
            -0.0,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::MIN_POSITIVE,
            5e-324,
            -5e-324,
            f64::MAX,
            f64::MIN,
            1.0,
            -1.0,
            0.5,
            -0.5,
            1.5,
            -2.5,
            2.0,
            3.0,
            -3.0,
            1e-8,
            710.0,
            -745.0,
            1e300,
        ];
        let mut s = 0.123456789f64;
        for _ in 0..200 {
            s = (s * 997.0 + 0.271).fract();
            v.push((s - 0.5) * 20.0);
            v.push((s - 0.5) * 1e6);
        }
        v
    }

    fn same(a: f64, b: f64) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    /// The operator list is exmex's `FloatOpsFactory` list: same names in the same order, same
    /// priorities, commutativity, unary/binary forms and constants, and every function gives
    /// bit-identical values on the probes. So exmex parses a text into the same structure for
    /// `Sym` as for `f64`, and a program built from the tree computes the same numbers.
    #[test]
    fn the_operators_are_exmexs_float_operators() {
        let ours = SymOps::make();
        let theirs = <FloatOpsFactory<f64> as MakeOperators<f64>>::make();
        assert_eq!(ours.len(), theirs.len());
        let probes = probes();
        for (o, t) in ours.iter().zip(&theirs) {
            let name = t.repr();
            assert_eq!(o.repr(), name);
            assert_eq!(o.has_bin(), t.has_bin(), "{name}");
            assert_eq!(o.has_unary(), t.has_unary(), "{name}");
            match (o.constant(), t.constant()) {
                (Some(Sym::Num(a)), Some(b)) => assert!(same(a, b), "{name}"),
                (None, None) => {}
                (a, b) => panic!("{name}: constant {a:?} against {b:?}"),
            }
            if let (Ok(ob), Ok(tb)) = (o.bin(), t.bin()) {
                assert_eq!(ob.prio, tb.prio, "{name}");
                assert_eq!(ob.is_commutative, tb.is_commutative, "{name}");
                for &a in &probes {
                    for &b in probes.iter().step_by(7) {
                        let Sym::Num(x) = (ob.apply)(Sym::Num(a), Sym::Num(b)) else {
                            panic!("{name} does not fold numbers");
                        };
                        assert!(same(x, (tb.apply)(a, b)), "{name}({a}, {b})");
                    }
                }
                // On a symbol it builds a node.
                let node = (ob.apply)(Sym::Var(0), Sym::Num(2.0));
                assert!(matches!(node, Sym::Bin(..)), "{name}");
            }
            if let (Ok(ou), Ok(tu)) = (o.unary(), t.unary()) {
                for &a in &probes {
                    let Sym::Num(x) = ou(Sym::Num(a)) else {
                        panic!("{name} does not fold numbers");
                    };
                    assert!(same(x, tu(a)), "{name}({a})");
                }
            }
        }
    }
}
