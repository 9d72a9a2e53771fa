use super::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const OPS1: [Op1; 26] = [
    Op1::Neg,
    Op1::Abs,
    Op1::Signum,
    Op1::Sin,
    Op1::Cos,
    Op1::Tan,
    Op1::Asin,
    Op1::Acos,
    Op1::Atan,
    Op1::Sinh,
    Op1::Cosh,
    Op1::Tanh,
    Op1::Asinh,
    Op1::Acosh,
    Op1::Atanh,
    Op1::Floor,
    Op1::Round,
    Op1::Ceil,
    Op1::Trunc,
    Op1::Fract,
    Op1::Exp,
    Op1::Sqrt,
    Op1::Cbrt,
    Op1::Ln,
    Op1::Log2,
    Op1::Log10,
];

const OPS2: [Op2; 8] = [
    Op2::Add,
    Op2::Sub,
    Op2::Mul,
    Op2::Div,
    Op2::Pow,
    Op2::Atan2,
    Op2::Min,
    Op2::Max,
];

/// A random interval: centres over several scales (small, around the functions' special points,
/// large), widths from 0 to a few units.
fn interval(rng: &mut ChaCha8Rng) -> Iv {
    let c = match rng.gen_range(0..6) {
        0 => rng.gen_range(-1.0..1.0),
        1 => rng.gen_range(-10.0..10.0),
        2 => rng.gen_range(-100.0..100.0),
        // Near the extrema and poles of sin, cos and tan.
        3 => rng.gen_range(-8i32..8) as f64 * FRAC_PI_2 + rng.gen_range(-1e-3..1e-3),
        // Near integers and half-integers (the jumps).
        4 => rng.gen_range(-6i32..6) as f64 * 0.5 + rng.gen_range(-1e-6..1e-6),
        _ => rng.gen_range(0.0..3.0),
    };
    let w = match rng.gen_range(0..4) {
        0 => 0.0,
        1 => rng.gen_range(0.0..1e-6),
        2 => rng.gen_range(0.0..0.3),
        _ => rng.gen_range(0.0..4.0),
    };
    Iv { lo: c, hi: c + w }
}

/// Points of an interval: its ends and random ones inside.
fn points(rng: &mut ChaCha8Rng, a: Iv, k: usize) -> Vec<f64> {
    let mut p = vec![a.lo, a.hi];
    for _ in 0..k {
        p.push(a.lo + (a.hi - a.lo) * rng.gen::<f64>());
    }
    p.into_iter().map(|x| x.clamp(a.lo, a.hi)).collect()
}

fn inside(x: f64, r: Iv) -> bool {
    r.lo <= x && x <= r.hi
}

/// Every function of the language: on thousands of random intervals, the enclosure (where one
/// is given) contains the `f64` value of the function (computed as the programs compute it) at
/// the ends and at random points inside, and is not much wider than the range those points
/// span plus the slope over the interval (so a test of containment could not pass with
/// `[−∞, ∞]`). Refusals are counted: each function must give enclosures on most intervals that
/// are free of its singular points.
#[test]
fn enclosures_contain_the_point_values_of_every_function() {
    let mut rng = ChaCha8Rng::seed_from_u64(20);
    for op in OPS1 {
        let (mut given, mut checked) = (0usize, 0usize);
        for _ in 0..4000 {
            let a = interval(&mut rng);
            let Ok(r) = apply1(op, a) else { continue };
            given += 1;
            assert!(r.lo <= r.hi, "{op:?} {a:?} -> {r:?}");
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for x in points(&mut rng, a, 40) {
                let y = op.apply(x);
                assert!(inside(y, r), "{op:?}({x}) = {y} outside {r:?} of {a:?}");
                lo = lo.min(y);
                hi = hi.max(y);
                checked += 1;
            }
            // Not loose: within the sampled range widened by what 40 samples can miss (the
            // slope bound over a gap, estimated from the samples' spread) and rounding.
            let spread = hi - lo;
            let slack = 0.5 * spread + 1e-12 * (1.0 + r.lo.abs().max(r.hi.abs()));
            assert!(
                r.lo >= lo - slack - (a.hi - a.lo) && r.hi <= hi + slack + (a.hi - a.lo),
                "{op:?} {a:?}: enclosure {r:?} far wider than the values [{lo}, {hi}]"
            );
        }
        assert!(
            given >= 200,
            "{op:?}: enclosures only on {given} of 4000 intervals"
        );
        assert!(checked > 10_000, "{op:?}");
    }
    for op in OPS2 {
        let mut given = 0usize;
        for _ in 0..4000 {
            let (a, b) = (interval(&mut rng), interval(&mut rng));
            let Ok(r) = apply2(op, a, b) else { continue };
            given += 1;
            for x in points(&mut rng, a, 8) {
                for y in points(&mut rng, b, 8) {
                    let z = op.apply(x, y);
                    assert!(inside(z, r), "{op:?}({x}, {y}) = {z} outside {r:?}");
                }
            }
        }
        assert!(
            given >= 200,
            "{op:?}: enclosures only on {given} of 4000 intervals"
        );
    }
    // The integer powers the programs use (x·x, x·x·x, (x·x)·(x·x), 1/x, 1/(x·x)) and powf
    // with integer exponents.
    for _ in 0..4000 {
        let a = interval(&mut rng);
        for n in -3i64..=5 {
            let Ok(r) = powi(a, n) else { continue };
            for x in points(&mut rng, a, 10) {
                let want = [
                    x.powf(n as f64),
                    if n == 3 { x * x * x } else { x.powf(n as f64) },
                ];
                for y in want {
                    assert!(inside(y, r), "{x}^{n} = {y} outside {r:?}");
                }
            }
        }
        if let Ok(r) = square(a) {
            for x in points(&mut rng, a, 10) {
                assert!(inside(x * x, r));
            }
        }
    }
}

/// The refusals: singular points inside an interval are reported, never enclosed.
#[test]
fn singular_points_are_refused() {
    let iv = |a: f64, b: f64| Iv { lo: a, hi: b };
    assert!(div(iv(1.0, 2.0), iv(-1.0, 1.0)).is_err());
    assert!(ln(iv(0.0, 1.0)).is_err());
    assert!(sqrt(iv(0.0, 1.0)).is_err());
    assert!(tan(iv(1.5, 1.6)).is_err());
    assert!(tan(iv(-1.6, -1.5)).is_err());
    assert!(tan(iv(1.0, 1.5)).is_ok());
    assert!(asin(iv(0.5, 1.0)).is_err());
    assert!(acosh(iv(1.0, 2.0)).is_err());
    assert!(pow(iv(0.0, 1.0), iv(0.5, 0.5)).is_err());
    assert!(pow(iv(-1.0, 1.0), iv(2.0, 2.0)).is_ok());
    assert!(pow(iv(-1.0, 1.0), iv(-1.0, -1.0)).is_err());
    assert!(abs(iv(-1.0, 1.0)).is_err());
    assert!(floor(iv(0.5, 1.5)).is_err());
    assert!(apply1(Op1::Round, iv(0.2, 0.7)).is_err());
    assert!(apply1(Op1::Round, iv(0.6, 1.4)).is_ok());
    assert!(min(iv(0.0, 2.0), iv(1.0, 3.0)).is_err());
    assert!(atan2(iv(-1.0, 1.0), iv(-2.0, -1.0)).is_err());
    assert!(atan2(iv(-1.0, 1.0), iv(1.0, 2.0)).is_ok());
    assert!(exp(iv(700.0, 800.0)).is_err(), "overflow is not finite");
    // Extrema inside: sin over [1, 2] reaches 1, cos over [3, 3.5] reaches −1.
    assert_eq!(sin(iv(1.0, 2.0)).unwrap().hi, 1.0);
    assert_eq!(cos(iv(3.0, 3.5)).unwrap().lo, -1.0);
    // Tight on a small interval away from the extrema.
    let s = sin(iv(0.1, 0.2)).unwrap();
    assert!(s.lo <= 0.1f64.sin() && s.hi >= 0.2f64.sin());
    assert!(s.hi - s.lo < 0.2f64.sin() - 0.1f64.sin() + 1e-14);
}

fn floor(a: Iv) -> IvResult {
    apply1(Op1::Floor, a)
}
