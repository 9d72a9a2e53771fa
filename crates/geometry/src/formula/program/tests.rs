use super::*;
use crate::formula::parse;
use exmex::FloatOpsFactory;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

type F64 = Parsed<f64, FloatOpsFactory<f64>>;

const UTX: Variables = Variables::this(&["u", "t", "x"]);

const UNARY: [&str; 27] = [
    "abs", "signum", "sin", "cos", "tan", "asin", "acos", "atan", "sinh", "cosh", "tanh", "asinh",
    "acosh", "atanh", "floor", "round", "ceil", "trunc", "fract", "exp", "sqrt", "cbrt", "ln",
    "log2", "log10", "log", "",
];

/// A random formula of the language: literals in every form, the constants, the variables, the
/// five operators in unparenthesised chains (so precedence and associativity matter), unary
/// minus and plus, every function, `atan2`, `min`, `max`, random spaces. Some texts are refused
/// (the ambiguous minus); the tests check that both sides refuse them.
fn formula(rng: &mut ChaCha8Rng, depth: u32) -> String {
    let sp = |rng: &mut ChaCha8Rng| if rng.gen_bool(0.2) { " " } else { "" };
    if depth == 0 || rng.gen_bool(0.25) {
        return match rng.gen_range(0..10) {
            0 => ["2", "0.5", ".5", "2.", "1e-3", "2.5E+1", "3", "4", "1", "0"]
                [rng.gen_range(0..10)]
            .to_string(),
            1 => ["pi", "e", "TAU", "π", "E", "PI", "τ"][rng.gen_range(0..7)].to_string(),
            2 => format!("{:.3}", rng.gen_range(-2.0..2.0f64).abs()),
            _ => ["u", "t", "x"][rng.gen_range(0..3)].to_string(),
        };
    }
    match rng.gen_range(0..10) {
        0..=3 => {
            let n = rng.gen_range(2..5);
            let mut s = formula(rng, depth - 1);
            for _ in 1..n {
                let op = ["+", "-", "*", "/", "^"][rng.gen_range(0..5)];
                let rhs = if op == "^" && rng.gen_bool(0.6) {
                    ["2", "3", "4", "-1", "(-2)", "0", "1", "0.5", "2.0", "-3"]
                        [rng.gen_range(0..10)]
                    .to_string()
                } else {
                    formula(rng, depth - 1)
                };
                s = format!("{s}{}{op}{}{rhs}", sp(rng), sp(rng));
            }
            s
        }
        4 | 5 => {
            let f = UNARY[rng.gen_range(0..UNARY.len())];
            format!("{f}({})", formula(rng, depth - 1))
        }
        6 => {
            let f = ["atan2", "min", "max"][rng.gen_range(0..3)];
            format!(
                "{f}({},{}{})",
                formula(rng, depth - 1),
                sp(rng),
                formula(rng, depth - 1)
            )
        }
        7 => format!("-{}", formula(rng, depth - 1)),
        8 => format!("+({})", formula(rng, depth - 1)),
        _ => format!("({})", formula(rng, depth - 1)),
    }
}

fn point(rng: &mut ChaCha8Rng) -> f64 {
    match rng.gen_range(0..20) {
        0 => 0.0,
        1 => -0.0,
        2 => 1.0,
        3 => -1.0,
        4 => f64::NAN,
        5 => 1e300,
        6 => rng.gen_range(-1e-3..1e-3),
        _ => rng.gen_range(-3.0..3.0),
    }
}

fn same(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
}

/// Equivalence with exmex: 4000 random formulas at 16 random points each (NaN, signed zeros,
/// huge values included). Without the integer-power rewrite every value is bit-identical to
/// exmex's (NaN where exmex gives NaN), point by point and over arrays; the same texts are
/// refused by both.
#[test]
fn programs_compute_exactly_what_exmex_computes() {
    let mut rng = ChaCha8Rng::seed_from_u64(19);
    let (mut compared, mut refused, mut nan) = (0, 0, 0);
    for _ in 0..4000 {
        let depth = rng.gen_range(1..5);
        let text = formula(&mut rng, depth);
        let theirs = parse::<f64, FloatOpsFactory<f64>>(&text, &UTX);
        let ours = parse::<Sym, SymOps>(&text, &UTX);
        let (theirs, ours): (F64, _) = match (theirs, ours) {
            (Ok(t), Ok(o)) => (t, o),
            (Err(t), Err(o)) => {
                assert_eq!(t.to_string(), o.to_string(), "{text}");
                refused += 1;
                continue;
            }
            (t, o) => panic!("{text}: exmex {t:?}, ours {o:?}"),
        };
        let tree = tree(&ours, &UTX).unwrap();
        let exact = Program::with_powers(&tree, 3, &[1], false);
        let fast = Program::new(&tree, 3, &[1]);
        let t = point(&mut rng);
        let us: Vec<f64> = (0..16).map(|_| point(&mut rng)).collect();
        let xs: Vec<f64> = (0..16).map(|_| point(&mut rng)).collect();
        let mut out = vec![0.0; 16];
        exact.eval(
            &[Input::Slice(&us), Input::Scalar(t), Input::Slice(&xs)],
            &mut out,
        );
        let mut out_fast = vec![0.0; 16];
        fast.eval(
            &[Input::Slice(&us), Input::Scalar(t), Input::Slice(&xs)],
            &mut out_fast,
        );
        for k in 0..16 {
            let want = theirs.eval(&[us[k], t, xs[k]]).unwrap();
            let one = exact.eval_one(&[us[k], t, xs[k]]);
            assert!(
                same(one, want),
                "{text} at u = {}, t = {t}, x = {}: {one} against exmex {want}",
                us[k],
                xs[k]
            );
            assert!(
                same(out[k], want),
                "{text}: array {} against {want}",
                out[k]
            );
            // With integer powers: arrays equal single points bit for bit (the powers' own
            // bound against powf is the next test).
            assert!(
                same(out_fast[k], fast.eval_one(&[us[k], t, xs[k]])),
                "{text}"
            );
            nan += want.is_nan() as usize;
            compared += 1;
        }
    }
    // The generator reaches every case.
    assert!(
        compared > 40_000 && refused > 50 && nan > 2_000,
        "{compared} {refused} {nan}"
    );
}

fn ulps(a: f64, b: f64) -> u64 {
    let key = |x: f64| {
        let i = x.to_bits() as i64;
        if i < 0 {
            i64::MIN - i
        } else {
            i
        }
    };
    key(a).abs_diff(key(b))
}

/// The integer powers against `powf`: at most 3 ulps where the result is normal, and the same
/// special values (signed zeros, infinities, NaN, and 0 for `x^0`).
#[test]
fn integer_powers_agree_with_powf_to_three_ulps() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let vars = Variables::this(&["x"]);
    let specials = [
        0.0,
        -0.0,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
        1.0,
        -1.0,
        f64::MIN_POSITIVE,
        -5e-324,
    ];
    let mut worst = 0;
    for n in ["0", "1", "2", "3", "4", "(-1)", "(-2)"] {
        let text = format!("x^{n}");
        let exmex: F64 = parse(&text, &vars).unwrap();
        let p = Program::compile(&text, &vars, &[]).unwrap();
        if n != "0" && n != "1" {
            assert!(p.code.iter().all(|i| i.op != Op::Bin(Op2::Pow)), "{text}");
        }
        for &x in &specials {
            let (want, got) = (exmex.eval(&[x]).unwrap(), p.eval_one(&[x]));
            let subnormal = want != 0.0 && want.abs() < f64::MIN_POSITIVE;
            assert!(subnormal || same(got, want), "{text} at {x}: {got} {want}");
        }
        let xs: Vec<f64> = (0..100_000)
            .map(|_| {
                let m: f64 = rng.gen_range(-1.0..1.0);
                m * 10f64.powi(rng.gen_range(-70..70))
            })
            .collect();
        let mut out = vec![0.0; xs.len()];
        p.eval(&[Input::Slice(&xs)], &mut out);
        for (&x, &got) in xs.iter().zip(&out) {
            let want = exmex.eval(&[x]).unwrap();
            if want.is_normal() {
                let d = ulps(got, want);
                worst = worst.max(d);
                assert!(d <= 3, "{text} at {x}: {got} against {want} ({d} ulps)");
            }
        }
    }
    // Not trivially exact: the rewrite is observable.
    assert!(worst >= 1, "{worst}");
}

/// Arrays: chunk boundaries, the parallel path, ramps, scalars for varying variables, a
/// uniform result, and the register reuse of a long program; every value equals the
/// point-wise one bit for bit.
#[test]
fn arrays_equal_points_across_chunks_threads_and_input_kinds() {
    let text = "(1 + exp(-t))^2 * (sin(pi*u)^2 - cos(pi*u)^2) * (2*pi^4 + 0.5*pi^2) + \
                x/(1 + x^2) - atan2(x, u + 1)*max(u, x)^3 + sqrt(abs(x*u)) - ln(u)";
    let p = Program::compile(text, &UTX, &[1]).unwrap();
    // Common subexpressions: `pi*u` once, so one sine and one cosine per point.
    let sines = p
        .code
        .iter()
        .filter(|i| matches!(i.op, Op::Un(Op1::Sin | Op1::Cos)))
        .count();
    assert_eq!(sines, 2);
    // `(1 + exp(-t))^2` and `2*pi^4 + …` are uniform: no exp per point.
    assert!(p.code.iter().all(|i| i.op != Op::Un(Op1::Exp)));
    for n in [
        0,
        1,
        CHUNK - 1,
        CHUNK,
        CHUNK + 1,
        3 * CHUNK + 7,
        PARALLEL_FROM + 3 * CHUNK + 5,
    ] {
        let xs: Vec<f64> = (0..n).map(|k| (k as f64 * 0.37).sin() * 2.0).collect();
        let (offset, step) = (0.5, 1.0 / (n.max(1) as f64));
        let t = 0.7;
        let mut out = vec![f64::NAN; n];
        p.eval(
            &[
                Input::Ramp { offset, step },
                Input::Scalar(t),
                Input::Slice(&xs),
            ],
            &mut out,
        );
        for k in 0..n {
            let u = (k as f64 + offset) * step;
            let want = p.eval_one(&[u, t, xs[k]]);
            assert!(same(out[k], want), "n = {n}, k = {k}: {} {want}", out[k]);
        }
        // A scalar for a varying variable is broadcast.
        let mut out2 = vec![0.0; n];
        p.eval(
            &[Input::Slice(&xs), Input::Scalar(t), Input::Scalar(0.25)],
            &mut out2,
        );
        for k in 0..n {
            assert!(same(out2[k], p.eval_one(&[xs[k], t, 0.25])));
        }
    }
    // A result that depends only on the uniform variable fills the output.
    let q = Program::compile("t^2 + 1", &UTX, &[1]).unwrap();
    let mut out = vec![0.0; 5];
    q.eval(
        &[
            Input::Slice(&[0.0; 5]),
            Input::Scalar(3.0),
            Input::Scalar(0.0),
        ],
        &mut out,
    );
    assert_eq!(out, vec![10.0; 5]);
    assert_eq!(
        Program::compile("2*pi - TAU + 1", &UTX, &[])
            .unwrap()
            .constant(),
        Some(1.0)
    );
    // The result is a variable itself.
    let r = Program::compile("x", &UTX, &[1]).unwrap();
    let mut out = vec![0.0; 3];
    r.eval(
        &[
            Input::Scalar(0.0),
            Input::Scalar(0.0),
            Input::Slice(&[1.0, 2.0, 3.0]),
        ],
        &mut out,
    );
    assert_eq!(out, vec![1.0, 2.0, 3.0]);
}

/// Parse errors are those of [`parse`].
#[test]
fn compile_reports_the_parse_errors() {
    let e = Program::compile("x*y", &UTX, &[]).unwrap_err().to_string();
    assert_eq!(
        e,
        "'x*y': unknown variable 'y'; this formula may use u, t, x"
    );
    let e = Program::compile("-u^2", &UTX, &[]).unwrap_err().to_string();
    assert!(e.contains("minus"), "{e}");
    assert!(Program::compile("sin(", &UTX, &[]).is_err());
}

/// Interval evaluation of whole programs: 3000 random formulas (every function, nested), each
/// on random boxes of its three variables; where an enclosure is given it contains the value
/// `eval_one` computes (with and without the integer-power rewrite) at the box's corners and at
/// random points inside. Enough formulas must give enclosures for the test to mean something.
#[test]
fn interval_programs_enclose_their_point_values() {
    use crate::formula::interval::Iv;
    let mut rng = ChaCha8Rng::seed_from_u64(2020);
    let (mut boxes, mut points) = (0usize, 0usize);
    for _ in 0..3000 {
        let depth = rng.gen_range(1..4);
        let text = formula(&mut rng, depth);
        let Ok(ours) = parse::<Sym, SymOps>(&text, &UTX) else {
            continue;
        };
        let tree = tree(&ours, &UTX).unwrap();
        let programs = [
            Program::with_powers(&tree, 3, &[], false),
            Program::new(&tree, 3, &[]),
        ];
        for _ in 0..4 {
            let b: Vec<Iv> = (0..3)
                .map(|_| {
                    let c = rng.gen_range(-3.0..3.0);
                    let w = [0.0, 1e-6, 0.1, 1.0][rng.gen_range(0..4)];
                    Iv { lo: c, hi: c + w }
                })
                .collect();
            for p in &programs {
                let Ok(r) = p.eval_interval(&b) else { continue };
                boxes += 1;
                for k in 0..20 {
                    let x: Vec<f64> = b
                        .iter()
                        .enumerate()
                        .map(|(s, iv)| match k {
                            // The eight corners, then random points.
                            0..=7 => {
                                if (k >> s) & 1 == 1 {
                                    iv.hi
                                } else {
                                    iv.lo
                                }
                            }
                            _ => iv.lo + (iv.hi - iv.lo) * rng.gen::<f64>(),
                        })
                        .collect();
                    let y = p.eval_one(&x);
                    assert!(
                        r.lo <= y && y <= r.hi,
                        "{text} at {x:?}: {y} outside [{}, {}] on {b:?}",
                        r.lo,
                        r.hi
                    );
                    points += 1;
                }
            }
        }
    }
    assert!(boxes > 3000, "only {boxes} boxes with an enclosure");
    assert!(points > 60_000);
}
