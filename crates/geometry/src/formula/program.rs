//! A formula compiled once and evaluated over whole arrays of points.
//!
//! The expression tree ([`super::trace`]) becomes a straight-line program in static single
//! assignment form: equal subexpressions are computed once (hash-consing), operations on numbers
//! are folded, and a power with an integer exponent `n ∈ {−2, −1, 2, 3, 4}` becomes
//! multiplications (`x^0 = 1` and `x^1 = x`, as `powf` gives for every `x`, NaN included). The
//! variables are either *uniform* (one value per call, e.g. the time `t` of a level) or *varying*
//! (one value per point); everything that depends only on uniform variables is computed once
//! per call. The varying part runs over the points in chunks of [`CHUNK`], each instruction a
//! tight loop over one chunk in registers of `CHUNK` values (registers are reused after a
//! value's last use, so a program's working set stays in the L1/L2 cache); arrays of
//! [`PARALLEL_FROM`] points or more are split across rayon's threads.
//!
//! Values: without integer powers the program performs exactly exmex's operations on `f64`, so
//! it agrees with exmex bit for bit (NaN where exmex gives NaN). An integer power differs from
//! `powf` by at most 3 ulps where the result is a normal number (`x·x` is correctly rounded,
//! `x·x·x` and `(x·x)·(x·x)` carry two roundings, and glibc's `pow` is within 0.52 ulp), with the
//! same special values (signed zeros, infinities, NaN); tests check both statements.

use super::interval::{self, Iv, IvResult};
use super::trace::{Op1, Op2, Sym, SymOps};
use super::{Parsed, Variables};
use crate::{Error, Result};
use rayon::prelude::*;
use std::cell::RefCell;
use std::collections::HashMap;
use std::rc::Rc;

/// Points per chunk: the registers of a program of ~20 instructions fit in L2.
pub(crate) const CHUNK: usize = 512;

/// Arrays of at least this many points are evaluated in parallel.
pub(crate) const PARALLEL_FROM: usize = 1 << 14;

/// Points per parallel task.
const BLOCK: usize = 16 * CHUNK;

/// An operation of a program.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Op {
    Un(Op1),
    Bin(Op2),
    /// `x·x`
    Square,
    /// `x·x·x`
    Cube,
    /// `(x·x)·(x·x)`
    Fourth,
    /// `1/x`
    Recip,
    /// `1/(x·x)`
    RecipSquare,
}

impl Op {
    fn apply(self, a: f64, b: f64) -> f64 {
        match self {
            Op::Un(f) => f.apply(a),
            Op::Bin(f) => f.apply(a, b),
            Op::Square => a * a,
            Op::Cube => a * a * a,
            Op::Fourth => {
                let s = a * a;
                s * s
            }
            Op::Recip => 1.0 / a,
            Op::RecipSquare => 1.0 / (a * a),
        }
    }
}

/// A value of the program (SSA): a variable, a number, or an operation on earlier values (the
/// second operand of a one-argument operation is unused).
#[derive(Clone, Copy, Debug)]
enum Value {
    Input(usize),
    Const(f64),
    Op(Op, u32, u32),
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Key {
    Input(usize),
    Const(u64),
    Op(Op, u32, u32),
}

/// One instruction of the varying part: `reg[d] = op(reg[a], reg[b])` over a chunk.
#[derive(Clone, Copy, Debug)]
struct Instr {
    op: Op,
    a: u32,
    b: u32,
    d: u32,
}

/// The values of a formula's variables for [`Program::eval`].
#[derive(Clone, Copy, Debug)]
pub(crate) enum Input<'a> {
    /// The same value at every point.
    Scalar(f64),
    /// One value per point.
    Slice(&'a [f64]),
    /// `(k + offset)·step` at point `k` (grid parameters, computed as `(k as f64 + offset) * step`).
    Ramp { offset: f64, step: f64 },
}

/// A compiled formula. See the [module documentation](self).
#[derive(Clone, Debug)]
pub(crate) struct Program {
    values: Vec<Value>,
    result: u32,
    /// Number of variables (the length of the inputs).
    slots: usize,
    /// Whether each value depends on a varying variable.
    varying: Vec<bool>,
    /// The varying variables loaded per chunk, and their registers.
    loads: Vec<(usize, u32)>,
    /// Uniform values used by varying instructions, and the registers they are broadcast to.
    broadcast: Vec<(u32, u32)>,
    code: Vec<Instr>,
    registers: usize,
    /// The register of the result, if it is varying.
    result_reg: Option<u32>,
}

/// The tree of a formula parsed over [`Sym`]: each variable slot `s` stands for itself.
pub(crate) fn tree(parsed: &Parsed<Sym, SymOps>, vars: &Variables) -> Result<Sym> {
    let args: Vec<Sym> = (0..vars.names.len()).map(Sym::Var).collect();
    parsed
        .eval(&args)
        .map_err(|e| Error::invalid(format!("cannot evaluate: {e}")))
}

struct Builder {
    values: Vec<Value>,
    keys: HashMap<Key, u32>,
    /// Values already built for shared subtrees (by address).
    seen: HashMap<*const Sym, u32>,
    /// Whether `^` with a small integer exponent becomes multiplications.
    integer_powers: bool,
}

impl Builder {
    fn push(&mut self, v: Value) -> u32 {
        let key = match v {
            Value::Input(s) => Key::Input(s),
            Value::Const(c) => Key::Const(c.to_bits()),
            Value::Op(op, a, b) => Key::Op(op, a, b),
        };
        if let Some(&id) = self.keys.get(&key) {
            return id;
        }
        let id = self.values.len() as u32;
        self.values.push(v);
        self.keys.insert(key, id);
        id
    }

    fn node(&mut self, s: &Rc<Sym>) -> u32 {
        let ptr = Rc::as_ptr(s);
        if let Some(&id) = self.seen.get(&ptr) {
            return id;
        }
        let id = self.build(s);
        self.seen.insert(ptr, id);
        id
    }

    fn build(&mut self, s: &Sym) -> u32 {
        match s {
            Sym::Num(c) => self.push(Value::Const(*c)),
            Sym::Var(slot) => self.push(Value::Input(*slot)),
            Sym::Un(f, a) => {
                let a = self.node(a);
                self.op(Op::Un(*f), a, a)
            }
            Sym::Bin(Op2::Pow, a, b) if self.integer_powers && matches!(**b, Sym::Num(_)) => {
                let Sym::Num(n) = **b else { unreachable!() };
                let a = self.node(a);
                let op = match n {
                    0.0 => return self.push(Value::Const(1.0)),
                    1.0 => return a,
                    2.0 => Op::Square,
                    3.0 => Op::Cube,
                    4.0 => Op::Fourth,
                    -1.0 => Op::Recip,
                    -2.0 => Op::RecipSquare,
                    _ => {
                        let b = self.push(Value::Const(n));
                        return self.op(Op::Bin(Op2::Pow), a, b);
                    }
                };
                self.op(op, a, a)
            }
            Sym::Bin(f, a, b) => {
                let a = self.node(a);
                let b = self.node(b);
                self.op(Op::Bin(*f), a, b)
            }
        }
    }

    /// An operation, folded when its operands are numbers.
    fn op(&mut self, op: Op, a: u32, b: u32) -> u32 {
        if let (Value::Const(x), Value::Const(y)) =
            (self.values[a as usize], self.values[b as usize])
        {
            return self.push(Value::Const(op.apply(x, y)));
        }
        self.push(Value::Op(op, a, b))
    }
}

impl Program {
    /// Compiles a formula's tree. `slots` is the number of variables; those in `uniform` are
    /// given one value per call ([`Input::Scalar`]).
    pub(crate) fn new(tree: &Sym, slots: usize, uniform: &[usize]) -> Program {
        Program::with_powers(tree, slots, uniform, true)
    }

    /// [`Program::new`]; without `integer_powers`, every `^` stays `powf` (the program then
    /// performs exactly exmex's operations).
    fn with_powers(tree: &Sym, slots: usize, uniform: &[usize], integer_powers: bool) -> Program {
        let mut b = Builder {
            values: Vec::new(),
            keys: HashMap::new(),
            seen: HashMap::new(),
            integer_powers,
        };
        let result = b.build(tree);
        let values = b.values;
        let mut varying = vec![false; values.len()];
        for (i, v) in values.iter().enumerate() {
            varying[i] = match *v {
                Value::Input(s) => !uniform.contains(&s),
                Value::Const(_) => false,
                Value::Op(_, a, b2) => varying[a as usize] || varying[b2 as usize],
            };
        }
        let mut p = Program {
            values,
            result,
            slots,
            varying,
            loads: Vec::new(),
            broadcast: Vec::new(),
            code: Vec::new(),
            registers: 0,
            result_reg: None,
        };
        p.plan();
        p
    }

    /// Parses and compiles `text` (as [`super::parse`], with its errors) for evaluation over
    /// arrays; the variables in `uniform` (slots of `vars`) take one value per call.
    pub(crate) fn compile(text: &str, vars: &Variables, uniform: &[usize]) -> Result<Program> {
        let parsed: Parsed<Sym, SymOps> = super::parse(text, vars)?;
        let t = tree(&parsed, vars)?;
        Ok(Program::new(&t, vars.names.len(), uniform))
    }

    /// Only the values the result needs (the tree may hold none other, but folding can leave
    /// constants behind), registers for the varying ones, reused after their last use.
    fn plan(&mut self) {
        let n = self.values.len();
        let mut needed = vec![false; n];
        needed[self.result as usize] = true;
        for i in (0..n).rev() {
            if needed[i] {
                if let Value::Op(_, a, b) = self.values[i] {
                    needed[a as usize] = true;
                    needed[b as usize] = true;
                }
            }
        }
        if !self.varying[self.result as usize] {
            return;
        }
        // The last instruction reading each value.
        let mut last = vec![0usize; n];
        for (i, (&v, (&need, &vary))) in self
            .values
            .iter()
            .zip(needed.iter().zip(&self.varying))
            .enumerate()
        {
            if let (true, true, Value::Op(_, a, b)) = (need, vary, v) {
                last[a as usize] = i;
                last[b as usize] = i;
            }
        }
        last[self.result as usize] = usize::MAX;
        let mut reg: Vec<Option<u32>> = vec![None; n];
        let mut free: Vec<u32> = Vec::new();
        let mut count = 0u32;
        let fresh = |count: &mut u32| {
            *count += 1;
            *count - 1
        };
        for i in 0..n {
            if !needed[i] || !self.varying[i] {
                continue;
            }
            match self.values[i] {
                Value::Input(s) => {
                    let r = fresh(&mut count);
                    reg[i] = Some(r);
                    self.loads.push((s, r));
                }
                Value::Const(_) => unreachable!("constants are uniform"),
                Value::Op(op, a, b) => {
                    let mut operand = |v: u32, reg: &mut Vec<Option<u32>>, count: &mut u32| {
                        if let Some(r) = reg[v as usize] {
                            return r;
                        }
                        // A uniform operand: broadcast once per call into its own register.
                        let r = fresh(count);
                        reg[v as usize] = Some(r);
                        self.broadcast.push((v, r));
                        r
                    };
                    let ra = operand(a, &mut reg, &mut count);
                    let rb = operand(b, &mut reg, &mut count);
                    let d = free.pop().unwrap_or_else(|| fresh(&mut count));
                    reg[i] = Some(d);
                    self.code.push(Instr {
                        op,
                        a: ra,
                        b: rb,
                        d,
                    });
                    // Registers of computed values (not inputs or broadcasts) read for the
                    // last time here are free for later instructions.
                    for v in [a, b] {
                        let vi = v as usize;
                        if last[vi] == i
                            && self.varying[vi]
                            && matches!(self.values[vi], Value::Op(..))
                            && !free.contains(&reg[vi].unwrap())
                        {
                            free.push(reg[vi].unwrap());
                        }
                    }
                }
            }
        }
        self.registers = count as usize;
        self.result_reg = reg[self.result as usize];
    }

    /// The value, if it does not depend on any variable.
    #[cfg(test)]
    fn constant(&self) -> Option<f64> {
        match self.values[self.result as usize] {
            Value::Const(c) => Some(c),
            _ => None,
        }
    }

    /// The value at one point: `values[s]` for the variable with slot `s`.
    pub(crate) fn eval_one(&self, values: &[f64]) -> f64 {
        let mut stack = [0.0f64; 32];
        let mut heap;
        let vals: &mut [f64] = if self.values.len() <= stack.len() {
            &mut stack[..self.values.len()]
        } else {
            heap = vec![0.0; self.values.len()];
            &mut heap
        };
        for (i, v) in self.values.iter().enumerate() {
            vals[i] = match *v {
                Value::Input(s) => values[s],
                Value::Const(c) => c,
                Value::Op(op, a, b) => op.apply(vals[a as usize], vals[b as usize]),
            };
        }
        vals[self.result as usize]
    }

    /// An enclosure of the value over the box `boxes[s]` of the variables (one interval per
    /// slot), or why the formula is not analytic somewhere on it ([`interval`]). The enclosure
    /// contains the exact value of every operation and the value [`Program::eval_one`]
    /// computes at any point of the box.
    pub(crate) fn eval_interval(&self, boxes: &[Iv]) -> IvResult {
        let mut vals: Vec<Iv> = Vec::with_capacity(self.values.len());
        for v in &self.values {
            let r = match *v {
                Value::Input(s) => boxes[s],
                Value::Const(c) => Iv::point(c)?,
                Value::Op(op, a, b) => {
                    let (x, y) = (vals[a as usize], vals[b as usize]);
                    match op {
                        Op::Un(f) => interval::apply1(f, x)?,
                        Op::Bin(f) => interval::apply2(f, x, y)?,
                        Op::Square => interval::square(x)?,
                        Op::Cube => interval::powi(x, 3)?,
                        Op::Fourth => interval::powi(x, 4)?,
                        Op::Recip => interval::div(Iv::point(1.0)?, x)?,
                        Op::RecipSquare => interval::div(Iv::point(1.0)?, interval::square(x)?)?,
                    }
                }
            };
            vals.push(r);
        }
        Ok(vals[self.result as usize])
    }

    /// `out[k]` = the value at point `k`, the variables given by `inputs` (one per slot; the
    /// uniform ones as [`Input::Scalar`], slices at least as long as `out`).
    pub(crate) fn eval(&self, inputs: &[Input], out: &mut [f64]) {
        assert_eq!(inputs.len(), self.slots, "one input per variable");
        // The uniform values, once.
        let mut uniform = vec![0.0f64; self.values.len()];
        for (i, v) in self.values.iter().enumerate() {
            if self.varying[i] {
                continue;
            }
            uniform[i] = match *v {
                Value::Input(s) => match inputs[s] {
                    Input::Scalar(x) => x,
                    _ => panic!("the uniform variable {s} needs a scalar"),
                },
                Value::Const(c) => c,
                Value::Op(op, a, b) => op.apply(uniform[a as usize], uniform[b as usize]),
            };
        }
        let Some(result) = self.result_reg else {
            out.fill(uniform[self.result as usize]);
            return;
        };
        for input in inputs {
            if let Input::Slice(s) = input {
                assert!(
                    s.len() >= out.len(),
                    "an input slice is shorter than the output"
                );
            }
        }
        let block = |start: usize, out: &mut [f64], regs: &mut Vec<f64>| {
            self.run(inputs, &uniform, start, out, regs, result)
        };
        if out.len() >= PARALLEL_FROM {
            out.par_chunks_mut(BLOCK)
                .enumerate()
                .for_each(|(i, o)| with_registers(|regs| block(i * BLOCK, o, regs)));
        } else {
            with_registers(|regs| block(0, out, regs));
        }
    }

    /// Evaluates the points `start .. start + out.len()` chunk by chunk.
    fn run(
        &self,
        inputs: &[Input],
        uniform: &[f64],
        start: usize,
        out: &mut [f64],
        regs: &mut Vec<f64>,
        result: u32,
    ) {
        regs.clear();
        regs.resize(self.registers * CHUNK, 0.0);
        for &(v, r) in &self.broadcast {
            reg_mut(regs, r).fill(uniform[v as usize]);
        }
        for (c, o) in out.chunks_mut(CHUNK).enumerate() {
            let k0 = start + c * CHUNK;
            let len = o.len();
            for &(s, r) in &self.loads {
                let dst = &mut reg_mut(regs, r)[..len];
                match inputs[s] {
                    Input::Scalar(x) => dst.fill(x),
                    Input::Slice(src) => dst.copy_from_slice(&src[k0..k0 + len]),
                    Input::Ramp { offset, step } => {
                        for (k, d) in dst.iter_mut().enumerate() {
                            *d = ((k0 + k) as f64 + offset) * step;
                        }
                    }
                }
            }
            for ins in &self.code {
                exec(ins, regs, len);
            }
            o.copy_from_slice(&reg_mut(regs, result)[..len]);
        }
    }
}

thread_local! {
    static REGISTERS: RefCell<Vec<f64>> = const { RefCell::new(Vec::new()) };
}

/// Runs `f` with this thread's register file (a fresh one if it is in use).
fn with_registers<R>(f: impl FnOnce(&mut Vec<f64>) -> R) -> R {
    REGISTERS.with(|cell| match cell.try_borrow_mut() {
        Ok(mut regs) => f(&mut regs),
        Err(_) => f(&mut Vec::new()),
    })
}

fn reg_mut(regs: &mut [f64], r: u32) -> &mut [f64] {
    let at = r as usize * CHUNK;
    &mut regs[at..at + CHUNK]
}

/// The destination register and the two operand registers (both distinct from it) of a chunk
/// of `len` points.
fn operands(regs: &mut [f64], d: u32, a: u32, b: u32, len: usize) -> (&mut [f64], &[f64], &[f64]) {
    assert!(d != a && d != b, "an instruction overwrites its operand");
    let (lo, rest) = regs.split_at_mut(d as usize * CHUNK);
    let (dst, hi) = rest.split_at_mut(CHUNK);
    let (lo, hi): (&[f64], &[f64]) = (lo, hi);
    let get = |r: u32| -> &[f64] {
        let r = r as usize;
        let d = d as usize;
        if r < d {
            &lo[r * CHUNK..r * CHUNK + len]
        } else {
            &hi[(r - d - 1) * CHUNK..(r - d - 1) * CHUNK + len]
        }
    };
    (&mut dst[..len], get(a), get(b))
}

#[inline(always)]
fn map1(d: &mut [f64], a: &[f64], f: impl Fn(f64) -> f64) {
    for (d, &a) in d.iter_mut().zip(a) {
        *d = f(a);
    }
}

#[inline(always)]
fn map2(d: &mut [f64], a: &[f64], b: &[f64], f: impl Fn(f64, f64) -> f64) {
    for ((d, &a), &b) in d.iter_mut().zip(a).zip(b) {
        *d = f(a, b);
    }
}

/// One instruction over a chunk; each arm is its own loop (the simple ones vectorise).
fn exec(ins: &Instr, regs: &mut [f64], len: usize) {
    let (d, a, b) = operands(regs, ins.d, ins.a, ins.b, len);
    macro_rules! un {
        ($($op:ident),*) => {
            match ins.op {
                $(Op::Un(Op1::$op) => map1(d, a, |x| Op1::$op.apply(x)),)*
                Op::Square => map1(d, a, |x| x * x),
                Op::Cube => map1(d, a, |x| x * x * x),
                Op::Fourth => map1(d, a, |x| {
                    let s = x * x;
                    s * s
                }),
                Op::Recip => map1(d, a, |x| 1.0 / x),
                Op::RecipSquare => map1(d, a, |x| 1.0 / (x * x)),
                Op::Bin(Op2::Add) => map2(d, a, b, |x, y| x + y),
                Op::Bin(Op2::Sub) => map2(d, a, b, |x, y| x - y),
                Op::Bin(Op2::Mul) => map2(d, a, b, |x, y| x * y),
                Op::Bin(Op2::Div) => map2(d, a, b, |x, y| x / y),
                Op::Bin(Op2::Pow) => map2(d, a, b, f64::powf),
                Op::Bin(Op2::Atan2) => map2(d, a, b, f64::atan2),
                Op::Bin(Op2::Min) => map2(d, a, b, f64::min),
                Op::Bin(Op2::Max) => map2(d, a, b, f64::max),
            }
        };
    }
    un!(
        Neg, Abs, Signum, Sin, Cos, Tan, Asin, Acos, Atan, Sinh, Cosh, Tanh, Asinh, Acosh, Atanh,
        Floor, Round, Ceil, Trunc, Fract, Exp, Sqrt, Cbrt, Ln, Log2, Log10
    );
}

#[cfg(test)]
mod tests;
