//! Design parameters (`[[parameters]]`, §6.1, §6.4): neutral values, the position, angling and
//! scaling parameters measured independently, the `v = 0` point, `Edit::SetParameter` against a
//! fresh compile, and bad input with its place.

use super::{compile, design_parameters, CompiledDesign, Edit};
use crate::spec::{parse_design, DesignSpec};
use crate::{Vec3, TAU};

/// Two patches: a duct from a circle to a B-spline section (the driven one) and a second,
/// separate duct that no parameter touches.
const BASE: &str = r#"
operator = { kind = "polyharmonic", order = 2, a = 1.2 }

[[patches]]
name = "duct"
conditions = [
  { u = 0.0, curve = "port" },
  { u = 0.0, derivative = 1, curve = "port_d" },
  { u = 1.0, curve = "outlet" },
  { u = 1.0, derivative = 1, curve = "outlet_d" },
]

[[patches]]
name = "other"
conditions = [
  { u = 0.0, curve = "o0" },
  { u = 0.0, derivative = 1, curve = "od" },
  { u = 1.0, curve = "o1" },
  { u = 1.0, derivative = 1, curve = "od" },
]

[curves.port]
type = "circle"
center = [0.0, 0.0, 0.0]
radius = 1.0

[curves.port_d]
type = "point"
at = [0.0, 0.0, 2.0]

[curves.outlet]
type = "bspline"
degree = 3
control = [
  [1.3, 0.1, 3.0], [1.2, 0.8, 3.1], [0.0, 0.7, 3.0], [-1.4, 0.6, 2.9],
  [-1.3, 0.0, 3.0], [-1.2, -0.7, 3.1], [0.1, -0.8, 3.0], [1.3, -0.7, 2.9],
]

[curves.outlet_ahead]
type = "bspline"
degree = 3
control = [
  [1.3, 0.1, 4.0], [1.2, 0.8, 4.1], [0.0, 0.7, 4.0], [-1.4, 0.6, 3.9],
  [-1.3, 0.0, 4.0], [-1.2, -0.7, 4.1], [0.1, -0.8, 4.0], [1.3, -0.7, 3.9],
]

[curves.outlet_d]
type = "derivative"
position = "outlet"
direction = "outlet_ahead"
scale = 2.0

[curves.o0]
type = "circle"
center = [5.0, 0.0, 0.0]
radius = 0.5

[curves.o1]
type = "circle"
center = [5.0, 0.0, 2.0]
radius = 0.7

[curves.od]
type = "point"
at = [0.0, 0.0, 1.0]
"#;

fn with(params: &str) -> DesignSpec {
    parse_design(&format!("{BASE}\n{params}")).unwrap()
}

fn curve(d: &CompiledDesign, name: &str) -> crate::curve::SharedCurve {
    d.solved()
        .curves
        .iter()
        .find(|c| c.name == name)
        .unwrap()
        .curve
        .clone()
}

/// Every surface of the design evaluated (in f64) on a 17 × 32 grid of (u, v).
fn positions(d: &mut CompiledDesign) -> Vec<[f64; 3]> {
    let mut out = Vec::new();
    for s in &d.solved().surfaces {
        for i in 0..17 {
            for k in 0..32 {
                let p = s.surface().point(i as f64 / 16.0, TAU * k as f64 / 32.0);
                out.push([p.x, p.y, p.z]);
            }
        }
    }
    out
}

fn bits(p: &[[f64; 3]]) -> Vec<[u64; 3]> {
    p.iter()
        .map(|q| [q[0].to_bits(), q[1].to_bits(), q[2].to_bits()])
        .collect()
}

/// Every kind at its neutral value (no `value`, or the neutral value written) leaves the
/// design as written, bit for bit.
#[test]
fn neutral_values_give_the_original_surface_bit_for_bit() {
    let mut plain = compile(&parse_design(BASE).unwrap()).unwrap();
    let reference = bits(&positions(&mut plain));
    let params = r#"
[[parameters]]
name = "x1"
kind = "position"
curve = "outlet"
with = ["outlet_ahead"]
v1 = 0.4
axis = "x"
min = -5.0
max = 5.0

[[parameters]]
name = "theta"
kind = "angle"
curve = "outlet"
with = ["outlet_ahead"]
v1 = 0.4
plane = "yz"
min = -1.0
max = 1.0

[[parameters]]
name = "s"
kind = "scale"
curve = "outlet"
with = ["outlet_ahead"]
v1 = 0.4
v2 = 3.5
min = 0.1
max = 9.0

[[parameters]]
name = "twist"
kind = "v_origin"
curve = "outlet"
with = ["outlet_ahead"]
min = -3.0
max = 3.0

[[parameters]]
name = "tx"
kind = "translate"
curve = "o1"
axis = "y"
min = -1.0
max = 1.0

[[parameters]]
name = "ry"
kind = "rotate"
curve = "o1"
axis = "y"
min = -1.0
max = 1.0

[[parameters]]
name = "dz"
kind = "dilate"
curve = "o1"
axis = "z"
min = 0.5
max = 2.0

[[parameters]]
name = "a"
kind = "smoothing"
min = 0.5
max = 2.0

[[parameters]]
name = "ct"
kind = "control_offset"
curve = "outlet"
min = -1.0
max = 1.0
"#;
    let spec = with(params);
    let mut d = compile(&spec).unwrap();
    assert_eq!(bits(&positions(&mut d)), reference);
    // The same with every neutral value written as `value`.
    let list = design_parameters(&spec).unwrap();
    assert_eq!(list.len(), 9);
    assert_eq!(list[3].neutral, 0.0);
    assert_eq!(list[6].neutral, 1.0);
    assert_eq!(list[7].neutral, 1.2);
    let mut written = spec.clone();
    for (p, e) in written.parameters.iter_mut().zip(&list) {
        p.value = Some(e.neutral);
    }
    let mut w = compile(&written).unwrap();
    assert_eq!(bits(&positions(&mut w)), reference);
    // The neutral X1 and |X1X2| are the curve's own.
    let outlet = curve(&plain, "outlet");
    assert_eq!(list[0].neutral, outlet.point(0.4).x);
    assert_eq!(
        list[2].neutral,
        (outlet.point(3.5) - outlet.point(0.4)).norm()
    );
}

fn one(params: &str) -> (CompiledDesign, CompiledDesign) {
    (
        compile(&parse_design(BASE).unwrap()).unwrap(),
        compile(&with(params)).unwrap(),
    )
}

/// The position parameters move the curve's point at v1 exactly to the values, translating
/// the curve (and the curve given `with` it) rigidly.
#[test]
fn position_moves_x1_to_the_value() {
    let mut text = String::new();
    for (axis, value) in [("x", 0.3), ("y", -0.25), ("z", 2.6)] {
        text.push_str(&format!(
            "[[parameters]]\nname = \"p{axis}\"\nkind = \"position\"\ncurve = \"outlet\"\n\
             with = [\"outlet_ahead\"]\nv1 = 1.1\naxis = \"{axis}\"\nvalue = {value}\n\
             min = -4.0\nmax = 4.0\n"
        ));
    }
    let (plain, moved) = one(&text);
    let (a, b) = (curve(&plain, "outlet"), curve(&moved, "outlet"));
    let x1 = b.point(1.1);
    assert!((x1 - Vec3::new(0.3, -0.25, 2.6)).norm() < 1e-12, "{x1}");
    let shift = x1 - a.point(1.1);
    for k in 0..16 {
        let v = TAU * k as f64 / 16.0;
        assert!((b.point(v) - a.point(v) - shift).norm() < 1e-12);
        let (c, e) = (curve(&plain, "outlet_ahead"), curve(&moved, "outlet_ahead"));
        assert!((e.point(v) - c.point(v) - shift).norm() < 1e-12);
    }
    // The surface follows: its edge at u = 1 is the moved curve.
    let duct = &moved.solved().surfaces[0];
    assert!((duct.surface().point(1.0, 1.1) - x1).norm() < 1e-9);
}

/// The angle between the projections of `a` and `b` on the plane normal to `axis`, signed by
/// the right-hand rule, measured with atan2.
fn turned(a: Vec3, b: Vec3, axis: Vec3) -> f64 {
    let pa = a - axis * axis.dot(&a);
    let pb = b - axis * axis.dot(&b);
    axis.dot(&pa.cross(&pb)).atan2(pa.dot(&pb))
}

/// The angling parameter keeps X1 and turns every chord from X1 and the tangent at X1 by θ
/// about the axis (measured independently by atan2 of the projected vectors).
#[test]
fn angle_keeps_x1_and_turns_the_curve_by_theta() {
    for (how, axis) in [
        ("plane = \"xy\"", Vec3::z()),
        ("axis = \"x\"", Vec3::x()),
        (
            "axis = [1.0, 2.0, -0.5]",
            Vec3::new(1.0, 2.0, -0.5).normalize(),
        ),
    ] {
        let (plain, moved) = one(&format!(
            "[[parameters]]\nname = \"theta\"\nkind = \"angle\"\ncurve = \"outlet\"\n\
             v1 = 0.9\n{how}\nvalue = 0.7\nmin = -1.0\nmax = 1.0\n"
        ));
        let (a, b) = (curve(&plain, "outlet"), curve(&moved, "outlet"));
        let x1 = a.point(0.9);
        assert!((b.point(0.9) - x1).norm() < 1e-12, "{how}");
        for v in [0.0, 2.0, 3.3, 5.0] {
            let (ca, cb) = (a.point(v) - x1, b.point(v) - x1);
            assert!((turned(ca, cb, axis) - 0.7).abs() < 1e-12, "{how} v = {v}");
            // The component along the axis and the length are kept.
            assert!((ca.dot(&axis) - cb.dot(&axis)).abs() < 1e-12);
            assert!((ca.norm() - cb.norm()).abs() < 1e-12);
        }
        let (ta, tb) = (a.derivative(0.9, 1), b.derivative(0.9, 1));
        assert!((turned(ta, tb, axis) - 0.7).abs() < 1e-12, "{how}");
    }
}

/// The scaling parameter gives |X1X2| = s and keeps X1; the scaling is uniform about X1.
#[test]
fn scale_sets_the_distance_and_keeps_x1() {
    let (plain, moved) = one(
        "[[parameters]]\nname = \"s\"\nkind = \"scale\"\ncurve = \"outlet\"\nv1 = 0.3\n\
         v2 = 2.5\nvalue = 1.7\nmin = 0.5\nmax = 3.0\n",
    );
    let (a, b) = (curve(&plain, "outlet"), curve(&moved, "outlet"));
    let (x1, x2) = (b.point(0.3), b.point(2.5));
    assert!((x1 - a.point(0.3)).norm() < 1e-12);
    assert!(((x2 - x1).norm() - 1.7).abs() < 1e-12);
    let f = 1.7 / (a.point(2.5) - a.point(0.3)).norm();
    for v in [0.0, 1.0, 4.0, 6.0] {
        let want = x1 + (a.point(v) - x1) * f;
        assert!((b.point(v) - want).norm() < 1e-12, "v = {v}");
    }
}

/// The v = 0 point: C̃(v) = C(v + v0) for the curve and the curves `with` it.
#[test]
fn v_origin_shifts_the_parameter() {
    let (plain, moved) = one(
        "[[parameters]]\nname = \"twist\"\nkind = \"v_origin\"\ncurve = \"outlet\"\n\
         with = [\"outlet_ahead\"]\nvalue = 0.9\nmin = -3.0\nmax = 3.0\n",
    );
    for name in ["outlet", "outlet_ahead"] {
        let (a, b) = (curve(&plain, name), curve(&moved, name));
        for k in 0..32 {
            let v = TAU * k as f64 / 32.0;
            assert!(
                (b.point(v) - a.point(v + 0.9)).norm() < 1e-14,
                "{name} v = {v}"
            );
        }
    }
    // A twist, not a move: the point set is the same, so the u = 1 edge is the same curve but
    // v = 0 sits elsewhere.
    assert!((curve(&moved, "outlet").point(0.0) - curve(&plain, "outlet").point(0.0)).norm() > 0.1);
}

/// `Edit::SetParameter` equals a fresh compile of the file with the value written, bit for
/// bit; it re-solves only the patch the parameter touches; its undo restores the design.
#[test]
fn set_parameter_equals_a_fresh_compile() {
    let params = |value: &str| {
        format!(
            "[[parameters]]\nname = \"theta\"\nkind = \"angle\"\ncurve = \"outlet\"\n\
             with = [\"outlet_ahead\"]\nv1 = 0.0\nplane = \"xz\"\n{value}min = -1.0\nmax = 1.0\n\n\
             [[parameters]]\nname = \"s\"\nkind = \"scale\"\ncurve = \"outlet\"\n\
             with = [\"outlet_ahead\"]\nv1 = 0.0\nv2 = 3.14\nmin = 0.5\nmax = 5.0\n"
        )
    };
    let mut d = compile(&with(&params(""))).unwrap();
    let before = bits(&positions(&mut d));
    let other = d.solved().surfaces[1].kind.id();
    let duct = d.solved().surfaces[0].kind.id();
    let undo = d
        .apply(&Edit::SetParameter {
            name: "theta".into(),
            value: Some(0.35),
        })
        .unwrap();
    let mut fresh = compile(&with(&params("value = 0.35\n"))).unwrap();
    let after = bits(&positions(&mut d));
    assert_eq!(after, bits(&positions(&mut fresh)));
    assert_ne!(after, before);
    assert_eq!(
        d.solved().surfaces[1].kind.id(),
        other,
        "untouched patch re-solved"
    );
    assert_ne!(d.solved().surfaces[0].kind.id(), duct);
    assert_eq!(d.spec().parameters[0].value, Some(0.35));
    d.apply(&undo).unwrap();
    assert_eq!(d.spec().parameters[0].value, None);
    assert_eq!(bits(&positions(&mut d)), before);
    // Out of bounds and unknown names change nothing.
    let e = d
        .apply(&Edit::SetParameter {
            name: "theta".into(),
            value: Some(1.5),
        })
        .unwrap_err();
    assert_eq!(e.place(), "parameters[0].value");
    assert!(e.to_string().contains("'theta'"), "{e}");
    let e = d
        .apply(&Edit::SetParameter {
            name: "phi".into(),
            value: Some(0.0),
        })
        .unwrap_err();
    assert!(e.to_string().contains("no parameter named 'phi'"), "{e}");
    assert_eq!(bits(&positions(&mut d)), before);
    // The edit serialises as the server's edits do.
    let json = serde_json::to_string(&Edit::SetParameter {
        name: "s".into(),
        value: Some(2.0),
    })
    .unwrap();
    assert_eq!(json, r#"{"edit":"set_parameter","name":"s","value":2.0}"#);
}

/// Parameters act in the order written: the angle turns about X1 as the position parameter
/// left it, so X1 stays where the position parameter put it.
#[test]
fn parameters_act_in_the_order_written() {
    let (_, moved) = one(
        "[[parameters]]\nname = \"px\"\nkind = \"position\"\ncurve = \"outlet\"\nv1 = 2.0\n\
         axis = \"x\"\nvalue = 0.5\nmin = -4.0\nmax = 4.0\n\n\
         [[parameters]]\nname = \"theta\"\nkind = \"angle\"\ncurve = \"outlet\"\nv1 = 2.0\n\
         plane = \"xy\"\nvalue = 0.4\nmin = -1.0\nmax = 1.0\n\n\
         [[parameters]]\nname = \"s\"\nkind = \"scale\"\ncurve = \"outlet\"\nv1 = 2.0\n\
         v2 = 5.0\nvalue = 2.0\nmin = 0.5\nmax = 4.0\n",
    );
    let b = curve(&moved, "outlet");
    assert!((b.point(2.0).x - 0.5).abs() < 1e-12);
    assert!(((b.point(5.0) - b.point(2.0)).norm() - 2.0).abs() < 1e-12);
}

fn error(params: &str) -> crate::Error {
    compile(&with(params)).unwrap_err()
}

#[test]
fn bad_parameters_are_refused_with_their_place() {
    let p = |body: &str| format!("[[parameters]]\nname = \"p\"\n{body}\n");
    let cases = [
        (
            p("kind = \"position\"\ncurve = \"nope\"\nv1 = 0.0\naxis = \"x\"\nmin = 0\nmax = 1"),
            "parameters[0].curve",
            "'nope'",
        ),
        (
            p("kind = \"scale\"\ncurve = \"outlet\"\nv1 = 1.0\nv2 = 1.0\nmin = 0.1\nmax = 9"),
            "parameters[0].v2",
            "differ",
        ),
        (
            p("kind = \"angle\"\ncurve = \"outlet\"\nv1 = 1.0\nplane = \"xy\"\nvalue = 2\nmin = -1\nmax = 1"),
            "parameters[0].value",
            "outside",
        ),
        (
            p("kind = \"scale\"\ncurve = \"port_d\"\nv1 = 0.0\nv2 = 1.0\nmin = 0.1\nmax = 9"),
            "parameters[0].v2",
            "coincide",
        ),
        (
            p("kind = \"scale\"\ncurve = \"port\"\nv1 = 0.0\nv2 = 6.283185307179586\nmin = 0.1\nmax = 9"),
            "parameters[0].v2",
            "coincide",
        ),
        (
            format!(
                "{}{}",
                p("kind = \"v_origin\"\ncurve = \"outlet\"\nmin = -1\nmax = 1"),
                p("kind = \"v_origin\"\ncurve = \"port\"\nmin = -1\nmax = 1")
            ),
            "parameters[1].name",
            "twice",
        ),
        (
            p("kind = \"v_origin\"\ncurve = \"outlet\"\nmin = 1\nmax = 1"),
            "parameters[0].max",
            "greater",
        ),
        (
            p("kind = \"angle\"\ncurve = \"outlet\"\nv1 = 1.0\nmin = -1\nmax = 1"),
            "parameters[0]",
            "plane",
        ),
        (
            p("kind = \"angle\"\ncurve = \"outlet\"\nv1 = 1.0\nplane = \"xy\"\naxis = \"z\"\nmin = -1\nmax = 1"),
            "parameters[0].plane",
            "not both",
        ),
        (
            p("kind = \"angle\"\ncurve = \"outlet\"\nv1 = 1.0\naxis = [0.0, 0.0, 0.0]\nmin = -1\nmax = 1"),
            "parameters[0].axis",
            "non-zero",
        ),
        (
            p("kind = \"scale\"\ncurve = \"outlet\"\nv1 = 1.0\nv2 = 2.0\nmin = 0\nmax = 1"),
            "parameters[0].min",
            "positive",
        ),
        (
            p("kind = \"position\"\ncurve = \"outlet\"\naxis = \"x\"\nmin = 0\nmax = 1"),
            "parameters[0]",
            "needs `v1`",
        ),
        (
            p("kind = \"smoothing\"\ncurve = \"outlet\"\nmin = 0.5\nmax = 1"),
            "parameters[0].curve",
            "takes no",
        ),
        (
            p("kind = \"position\"\ncurve = \"outlet\"\nv1 = 0.0\naxis = \"x\"\nmin = 5\nmax = 6"),
            "parameters[0].min",
            "neutral",
        ),
        (
            p("kind = \"position\"\ncurve = \"outlet\"\nwith = [\"gone\"]\nv1 = 0.0\naxis = \"x\"\nmin = 0\nmax = 6"),
            "parameters[0].with[0]",
            "'gone'",
        ),
        (
            p("kind = \"control_offset\"\ncurve = \"port\"\nmin = -1\nmax = 1"),
            "parameters[0].curve",
            "bspline",
        ),
    ];
    for (params, place, words) in cases {
        let e = error(&params);
        assert_eq!(e.place(), place, "{params}: {e}");
        assert!(e.to_string().contains(words), "{params}: {e}");
    }
}
