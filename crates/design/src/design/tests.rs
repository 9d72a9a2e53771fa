//! Parsing, validation and building of design files.

use super::*;
use crate::spec::*;

const CUP_LIKE: &str = r#"
title = "test"
[operator]
kind = "polyharmonic"
order = 2
a = 1.5
[curves.base]
type = "circle"
center = [0, 0, 0]
radius = 1.0
[curves.rim]
type = "circle"
center = [0, 0, 1]
radius = 2
[curves.out]
type = "circle"
center = [0, 0, 2]
radius = 2
[curves.tan]
type = "derivative"
position = "rim"
direction = "out"
scale = 2.0
"#;

fn with_conditions(conds: &str) -> String {
    format!("{CUP_LIKE}\nconditions = [{conds}]\n").replace(
        "\ntitle", "title", // keep the top-level keys before the tables
    )
}

/// Puts `conditions` at the top level (before the first table).
fn design(conds: &str, extra_top: &str) -> String {
    let body = CUP_LIKE.trim_start();
    let split = body.find("[operator]").unwrap();
    format!(
        "{}conditions = [{conds}]\n{extra_top}\n{}",
        &body[..split],
        &body[split..]
    )
}

const FOUR: &str = r#"{ u = 0.0, curve = "base" }, { u = 0.0, derivative = 1, curve = "tan" },
  { u = 1.0, curve = "rim" }, { u = 1.0, derivative = 1, curve = "tan" }"#;

fn err_of(text: &str) -> String {
    match parse_design(text) {
        Err(e) => e.to_string(),
        Ok(spec) => match validate_design(&spec) {
            Err(e) => e.to_string(),
            Ok(()) => panic!("expected an error for\n{text}"),
        },
    }
}

#[test]
fn a_valid_design_parses_and_validates() {
    let _ = with_conditions;
    let spec = parse_design(&design(FOUR, "")).unwrap();
    assert_eq!(spec.title.as_deref(), Some("test"));
    assert_eq!(
        spec.operator,
        Some(OperatorSpec::Polyharmonic { order: 2, a: 1.5 })
    );
    assert_eq!(spec.curves.len(), 4);
    let conds = spec.conditions.as_ref().unwrap();
    assert_eq!(conds.len(), 4);
    assert_eq!(conds[1].derivative, 1);
    assert!(matches!(&conds[2].curve, CurveRef::Name(n) if n == "rim"));
    match &spec.curves["rim"].kind {
        CurveKind::Circle {
            center,
            radius,
            normal,
        } => {
            assert_eq!(*center, [0.0, 0.0, 1.0]);
            assert_eq!(*radius, 2.0);
            assert_eq!(*normal, [0.0, 0.0, 1.0]);
        }
        other => panic!("{other:?}"),
    }
    validate_design(&spec).unwrap();
}

#[test]
fn inline_curves_transforms_and_modifiers_parse() {
    let text = r#"
conditions = [
  { u = 0.0, curve = { type = "ellipse", center = [0, 0, 0], rx = 2, ry = 1, v_origin = 0.5 } },
  { u = 1.0, curve = { type = "circle", center = [0, 0, 0], radius = 1, transform = [ { translate = [0, 0, 1] }, { rotate = { axis = [1, 0, 0], angle = 30 } }, { scale = { factor = 2.0, about = [0, 0, 1] } } ], arc_length = true } },
]
[operator]
kind = "polyharmonic"
order = 1
"#;
    let spec = parse_design(text).unwrap();
    validate_design(&spec).unwrap();
    let conds = spec.conditions.unwrap();
    let CurveRef::Inline(c) = &conds[1].curve else {
        panic!()
    };
    assert!(c.arc_length);
    assert_eq!(
        c.transform,
        vec![
            TransformStep::Translate([0.0, 0.0, 1.0]),
            TransformStep::Rotate {
                axis: [1.0, 0.0, 0.0],
                angle: 30.0,
                about: [0.0, 0.0, 0.0]
            },
            TransformStep::Scale {
                factor: 2.0,
                about: [0.0, 0.0, 1.0]
            },
        ]
    );
    let CurveRef::Inline(c) = &conds[0].curve else {
        panic!()
    };
    assert_eq!(c.v_origin, 0.5);
}

#[test]
fn syntax_and_schema_errors_name_the_place() {
    let e = err_of("title = \n");
    assert!(!e.is_empty());
    let e = err_of("[curves.rim]\ntype = \"circle\"\ncenter = [0,0,0]\nradiuss = 1\n");
    assert!(
        e.starts_with("curves.rim.radiuss: unknown field `radiuss`"),
        "{e}"
    );
    assert!(e.ends_with("did you mean `radius`?"), "{e}");
    // A key every curve accepts is suggested too, and a type name.
    let e = err_of("[curves.rim]\ntype = \"circle\"\nradius = 1\nv_orign = 1\n");
    assert!(e.ends_with("did you mean `v_origin`?"), "{e}");
    let e = err_of("[curves.rim]\ntype = \"circel\"\nradius = 1\n");
    assert!(e.ends_with("did you mean `circle`?"), "{e}");
    let e = err_of("[curves.rim]\ntype = \"circle\"\nradius = 1\nzzzzzzzz = 1\n");
    assert!(!e.contains("did you mean"), "{e}");
    let e = err_of("colour = 1\n");
    assert!(e.starts_with("colour: unknown field `colour`"), "{e}");
    let e = err_of("[solver]\nmodes = \"many\"\n");
    assert!(e.starts_with("solver.modes: invalid type"), "{e}");
    let e = err_of("[operator]\nkind = \"cubic\"\n");
    assert!(
        e.starts_with("operator.kind: unknown variant `cubic`"),
        "{e}"
    );
}

#[test]
fn non_finite_numbers_are_refused_with_their_path() {
    let text = design(FOUR, "").replace("center = [0, 0, 1]", "center = [0, nan, 1]");
    assert_eq!(
        err_of(&text),
        "curves.rim.center[1]: must be finite (got NaN)"
    );
    let text = design(FOUR, "").replace("a = 1.5", "a = inf");
    assert_eq!(err_of(&text), "operator.a: must be finite (got inf)");
    let text = design(FOUR, "").replace("u = 1.0, curve = \"rim\"", "u = -inf, curve = \"rim\"");
    assert_eq!(err_of(&text), "conditions[2].u: must be finite (got -inf)");
}

#[test]
fn semantic_errors_name_the_place() {
    let cases: Vec<(String, &str)> = vec![
        (
            design(FOUR, "").replace("1]\nradius = 2\n", "1]\nradius = -1\n"),
            "curves.rim.radius: must be positive (got -1)",
        ),
        (
            design(FOUR, "").replace("a = 1.5", "a = 0"),
            "operator.a: must be positive (got 0)",
        ),
        (
            design(FOUR, "").replace("order = 2", "order = 21"),
            "operator.order: must be between 1 and 20 (got 21); the PDE has order 2·order",
        ),
        (
            design(&FOUR.replace("\"rim\" },", "\"rimm\" },"), ""),
            "conditions[2].curve: unknown curve 'rimm' (did you mean 'rim'? known: base, out, rim, tan)",
        ),
        (
            design(
                r#"{ u = 0.0, curve = "base" }, { u = 1.0, curve = "rim" }, { u = 1.0, derivative = 1, curve = "tan" }"#,
                "",
            ),
            "conditions: a polyharmonic operator of order 2 needs 4 conditions, got 3",
        ),
        (
            design(&format!("{FOUR}, {{ u = 0.5, curve = \"rim\" }}"), ""),
            "conditions: a polyharmonic operator of order 2 needs 4 conditions, got 5",
        ),
        (
            design(&FOUR.replace("u = 1.0, derivative = 1", "u = 1.0"), ""),
            "conditions[3]: prescribes the position at u = 1 like conditions[2]",
        ),
        (
            design(&FOUR.replace("u = 1.0, curve", "u = 1.5, curve"), ""),
            "conditions[2].u: must lie in [0, 1] (got 1.5)",
        ),
        (
            design(
                &FOUR.replace(
                    "derivative = 1, curve = \"tan\" }\"",
                    "derivative = 4, curve = \"tan\" }",
                ),
                "",
            )
            .replace("u = 1.0, derivative = 1", "u = 1.0, derivative = 4"),
            "conditions[3].derivative: must be below the PDE's order 4 (got 4)",
        ),
        (
            design(FOUR, "[solver]\nmodes = 0\n"),
            "solver.modes: must be between 1 and 256 (got 0)",
        ),
        (
            design(FOUR, "[solver]\nmodes = 10\nsamples = 5\n"),
            "solver.samples: must be 0 (automatic) or between 2·modes + 1 = 21 and 65536 (got 5)",
        ),
        (
            design(FOUR, "[output]\nnu = 1\n"),
            "output.nu: must be at least 2 (got 1)",
        ),
        (
            design(FOUR, "").replace("position = \"rim\"", "position = \"tan\""),
            "curves.tan: curves refer to each other in a cycle: tan → tan",
        ),
    ];
    for (text, want) in cases {
        assert_eq!(err_of(&text), want, "\n{text}");
    }
}

#[test]
fn curve_kind_errors() {
    let top = |curve: &str| {
        format!(
            "conditions = [ {{ u = 0.0, curve = \"c\" }}, {{ u = 1.0, curve = \"c\" }} ]\n\
             [operator]\nkind = \"polyharmonic\"\norder = 1\n[curves.c]\n{curve}\n"
        )
    };
    let cases = [
        (
            "type = \"circle\"\ncenter = [0,0,0]\nradius = 0",
            "curves.c.radius: must be positive (got 0)",
        ),
        (
            "type = \"ellipse\"\ncenter = [0,0,0]\naxis1 = [1,0,0]\naxis2 = [2,0,0]",
            "curves.c.axis2: axis1 and axis2 are parallel: the ellipse is degenerate",
        ),
        (
            "type = \"ellipse\"\ncenter = [0,0,0]\nrx = 1",
            "curves.c: give either axis1 and axis2, or rx and ry (with an optional normal)",
        ),
        (
            "type = \"bspline\"\ndegree = 3\ncontrol = [[1,0,0],[0,1,0],[-1,0,0],[0,-1,0]]\nknots = [0, 1, 1, 2, 3]",
            "curves.c.knots[2]: must be increasing (got 1 after 1)",
        ),
        (
            "type = \"bspline\"\ndegree = 3\ncontrol = [[1,0,0],[0,1,0],[-1,0,0],[0,-1,0]]\nknots = [0, 1, 2]",
            "curves.c.knots: needs 5 increasing breakpoints for 4 control points of degree 3 (got 3)",
        ),
        (
            "type = \"bezier\"\ncontrol = [[1,0,0],[0,1,0]]",
            "conditions[0].curve: a condition curve must be periodic (closed, v in [0, 2π)); this bezier curve is open",
        ),
        (
            "type = \"circle\"\ncenter = [0,0,0]\nradius = 1\ntransform = [ { scale = { factor = 0 } } ]",
            "curves.c.transform[0].scale.factor: must not be 0",
        ),
        (
            "type = \"formula\"\nx = \"cos(v)\"\ny = \"\"\nz = \"0\"",
            "curves.c.y: is empty",
        ),
    ];
    for (curve, want) in cases {
        assert_eq!(err_of(&top(curve)), want, "\n{curve}");
    }
}

#[test]
fn multi_patch_rules() {
    let base = r#"
[curves.a]
type = "circle"
center = [0, 0, 0]
radius = 1
[curves.b]
type = "circle"
center = [0, 0, 1]
radius = 1
[[patches]]
name = "one"
operator = { kind = "polyharmonic", order = 1 }
conditions = [ { u = 0.0, curve = "a" }, { u = 1.0, curve = "b" } ]
[[patches]]
name = "two"
operator = { kind = "polyharmonic", order = 1 }
conditions = [ { u = 0.0, curve = "b" }, { u = 1.0, curve = "zz" } ]
"#;
    assert_eq!(
        err_of(base),
        "patches[1].conditions[1].curve: unknown curve 'zz' (known: a, b)"
    );
    let dup = base
        .replace("\"two\"", "\"one\"")
        .replace("\"zz\"", "\"a\"");
    assert_eq!(
        err_of(&dup),
        "patches[1].name: 'one' is already the name of patches[0]"
    );
    let ok = base.replace("\"zz\"", "\"a\"");
    validate_design(&parse_design(&ok).unwrap()).unwrap();
    let both = format!("conditions = []\n{ok}");
    assert!(err_of(&both).starts_with("conditions: a design has either"));
    assert_eq!(
        err_of("title = \"x\"\n"),
        "the design has no conditions: give `conditions = [...]` or [[patches]]"
    );
}

#[test]
fn errors_are_located_in_the_file() {
    let text = design(FOUR, "").replace("1]\nradius = 2\n", "1]\nradius = -1\n");
    let spec = parse_design(&text).unwrap();
    let e = validate_design(&spec).unwrap_err();
    let line = text
        .lines()
        .position(|l| l.starts_with("radius = -1"))
        .unwrap()
        + 1;
    assert_eq!(
        describe_error("d.toml", &text, &e),
        format!("d.toml:{line}:1: curves.rim.radius: must be positive (got -1)")
    );
    let bad = "title = \"x\"\n[curves\n";
    let e = parse_design(bad).unwrap_err();
    let d = describe_error("d.toml", bad, &e);
    assert!(d.starts_with("d.toml:2:"), "{d}");
    assert!(!d.contains('\n'));
}

#[test]
fn the_schema_is_json_and_lists_the_curve_kinds() {
    let s = json_schema();
    let v: serde_json::Value = serde_json::from_str(&s).unwrap();
    assert!(v["definitions"]["CurveSpec"].is_object(), "{s}");
    for kind in [
        "circle",
        "ellipse",
        "bspline",
        "formula",
        "derivative",
        "samples",
        "local",
        "on_patch",
        "tangent_field",
    ] {
        assert!(s.contains(&format!("\"{kind}\"")), "{kind}");
    }
    // The common modifiers are part of every curve kind.
    let variants = crate::spec::schema::curve_variants(&v);
    assert_eq!(variants.len(), 13);
    for variant in variants {
        assert!(variant["properties"]["transform"].is_object());
        assert!(variant["properties"]["v_origin"].is_object());
    }
}

#[test]
fn the_documented_example_is_valid() {
    let doc = include_str!("../../../../docs/design-file.md");
    let start = doc.find("```toml\n").unwrap() + "```toml\n".len();
    let end = start + doc[start..].find("```").unwrap();
    let spec = parse_design(&doc[start..end]).unwrap();
    validate_design(&spec).unwrap();
    assert_eq!(spec.conditions.as_ref().unwrap().len(), 4);
}

#[test]
fn every_example_file_is_valid() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    let mut seen = 0;
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        if p.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let text = std::fs::read_to_string(&p).unwrap();
        let spec = parse_design(&text).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        validate_design(&spec).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        seen += 1;
    }
    assert!(seen >= 7, "{seen}");
}

fn curve_named<'a>(curves: &'a [NamedCurve], name: &str) -> &'a NamedCurve {
    curves.iter().find(|c| c.name == name).unwrap()
}

#[test]
fn derivative_curves_point_from_position_to_direction() {
    let spec = parse_design(&design(FOUR, "")).unwrap();
    let curves = build_curves(&spec).unwrap();
    let tan = curve_named(&curves, "tan");
    assert_eq!(tan.kind, "derivative");
    // tan = 2 (out − rim): both circles have radius 2, out is one higher: (0, 0, 2) for all v.
    for k in 0..16 {
        let v = crate::TAU * k as f64 / 16.0;
        let t = tan.curve.point(v);
        assert!(
            (t - crate::Vec3::new(0.0, 0.0, 2.0)).norm() < 1e-14,
            "{v}: {t}"
        );
    }
}

#[test]
fn transforms_apply_in_order_with_angles_in_degrees() {
    let text = r#"
conditions = [ { u = 0.0, curve = "c" }, { u = 1.0, curve = "d" } ]
[operator]
kind = "polyharmonic"
order = 1
[curves.c]
type = "circle"
center = [0, 0, 0]
radius = 1
transform = [ { rotate = { axis = [1, 0, 0], angle = 90 } }, { translate = [0, 0, 5] }, { scale = { factor = 2, about = [0, 0, 5] } } ]
[curves.d]
type = "circle"
center = [0, 0, 0]
radius = 1
v_origin = 1.5707963267948966
"#;
    let curves = build_curves(&parse_design(text).unwrap()).unwrap();
    let c = &curve_named(&curves, "c").curve;
    // v = 0: (1, 0, 0) → rotation about x keeps it → (1, 0, 5) → scaled about (0, 0, 5): (2, 0, 5).
    let p = c.point(0.0);
    assert!((p - crate::Vec3::new(2.0, 0.0, 5.0)).norm() < 1e-14, "{p}");
    // v = π/2: (0, 1, 0) → rotated by +90° about x: (0, 0, 1) → (0, 0, 6) → (0, 0, 7).
    let p = c.point(std::f64::consts::FRAC_PI_2);
    assert!((p - crate::Vec3::new(0.0, 0.0, 7.0)).norm() < 1e-14, "{p}");
    // v_origin = π/2 starts the circle at (0, 1, 0).
    let d = &curve_named(&curves, "d").curve;
    let p = d.point(0.0);
    assert!((p - crate::Vec3::new(0.0, 1.0, 0.0)).norm() < 1e-15, "{p}");
}

#[test]
fn the_curves_of_every_example_build_and_are_finite() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples");
    for entry in std::fs::read_dir(dir).unwrap() {
        let p = entry.unwrap().path();
        if p.extension().and_then(|e| e.to_str()) != Some("toml") {
            continue;
        }
        let spec = parse_design(&std::fs::read_to_string(&p).unwrap()).unwrap();
        let curves = build_curves(&spec).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        for c in &curves {
            for k in 0..64 {
                let x = c.curve.point(crate::TAU * k as f64 / 64.0);
                assert!(
                    x.iter().all(|t| t.is_finite()),
                    "{}: {}",
                    p.display(),
                    c.name
                );
            }
        }
    }
}

#[test]
fn construction_errors_carry_the_curve_path() {
    let text = r#"
conditions = [ { u = 0.0, curve = "f" }, { u = 1.0, curve = { type = "formula", x = "cos(v)", y = "sin(v)", z = "ln(cos(v))" } } ]
[operator]
kind = "polyharmonic"
order = 1
[curves.f]
type = "formula"
x = "cos(v)"
y = "sin(v)"
z = "1"
"#;
    let e = build_curves(&parse_design(text).unwrap());
    // Named curves build; the inline one is only built with the conditions.
    assert!(e.is_ok());
    let bad = text.replace("z = \"1\"", "z = \"1 +\"");
    let e = build_curves(&parse_design(&bad).unwrap()).unwrap_err();
    assert!(e.to_string().starts_with("curves.f.z: "), "{e}");
}

#[test]
fn check_grid_agrees_with_grid_parameters() {
    use crate::mesh::{grid_parameters, MAX_VERTICES};
    use crate::surface::VDomain;
    let cases = [
        (0, 10),
        (1, 10),
        (2, 10),
        (10, 0),
        (10, 2),
        (10, 3),
        (2, MAX_VERTICES / 2),
        (2, MAX_VERTICES / 2 + 1),
        (1_000_000_000, 128),
        (usize::MAX, usize::MAX),
    ];
    for (nu, nv) in cases {
        // grid_parameters allocates nu + nv values on success: only call it for small grids.
        let mine = check_grid(nu, nv);
        if nu.saturating_add(nv) <= 1_000 || mine.is_err() {
            let theirs = grid_parameters(VDomain::Periodic, nu, nv).map(|_| ());
            assert_eq!(mine, theirs, "{nu} × {nv}");
        }
    }
    assert!(check_grid(2, MAX_VERTICES / 2).is_ok());
    assert!(check_grid(2, MAX_VERTICES / 2 + 1).is_err());
}

#[test]
fn schema_errors_inside_tagged_tables_keep_their_path() {
    let e = err_of("[operator]\nkind = \"polyharmonic\"\norder = 0.5\n");
    assert!(
        e.starts_with("operator.order: invalid type: number `0.5`, expected a whole number"),
        "{e}"
    );
    let e = err_of("[operator]\nkind = \"general\"\ncoefficients = [1, \"x\"]\n");
    assert!(
        e.starts_with("operator.coefficients[1]: invalid type: string"),
        "{e}"
    );
    let e = err_of("[curves.r]\ntype = \"bspline\"\ndegree = 2\ncontrol = [[0, 0, 0], [1, 0]]\n");
    assert!(
        e.starts_with("curves.r.control[1]: invalid length 2"),
        "{e}"
    );
    let e = err_of(
        "[curves.r]\ntype = \"derivative\"\ndirection = \"a\"\n\
         position = { type = \"circle\", center = [0, 0, 0], radius = 1, transform = [ { rotate = { axis = [0, 0, 1], angel = 3 } } ] }\n",
    );
    assert!(
        e.starts_with("curves.r.position.transform[0].rotate.angel: unknown field `angel`"),
        "{e}"
    );
    let e = err_of("[curves.r]\ntype = 3\n");
    assert!(
        e.starts_with("curves.r.type: expected a string, found integer"),
        "{e}"
    );
}

#[test]
fn huge_numbers_are_written_compactly() {
    let text = design(&FOUR.replace("u = 1.0, curve", "u = 1e300, curve"), "");
    assert_eq!(
        err_of(&text),
        "conditions[2].u: must lie in [0, 1] (got 1e300)"
    );
    assert_eq!(validate::num(0.25), "0.25");
    assert_eq!(validate::num(-3.0), "-3");
    assert_eq!(validate::num(1e-7), "1e-7");
}

/// Edits applied to a compiled design, one after another.
mod edits {
    use crate::design::{compile, CompiledDesign, Edit};
    use crate::mesh::sample;
    use crate::spec::{parse_design, write_design, CurveKind, DesignSpec, TransformStep};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn example(name: &str) -> DesignSpec {
        let path = format!("{}/../../examples/{name}", env!("CARGO_MANIFEST_DIR"));
        parse_design(&std::fs::read_to_string(path).unwrap()).unwrap()
    }

    /// Every surface of both designs, sampled at full precision on a grid that is not the
    /// tessellation grid, compared bit for bit; and the meshes of `a` (made incrementally into
    /// reused buffers) equal to fresh meshes of `b`.
    fn assert_same(a: &mut CompiledDesign, b: &CompiledDesign, what: &str) {
        let (sa, sb) = (a.solved(), b.solved());
        assert_eq!(sa.surfaces.len(), sb.surfaces.len(), "{what}");
        for (x, y) in sa.surfaces.iter().zip(&sb.surfaces) {
            assert_eq!(x.name, y.name, "{what}");
            let (gx, gy) = (
                sample(x.surface(), 7, 11).unwrap(),
                sample(y.surface(), 7, 11).unwrap(),
            );
            let bits = |g: &crate::mesh::Samples| {
                g.positions
                    .iter()
                    .chain(&g.normals)
                    .flatten()
                    .map(|v| v.to_bits())
                    .collect::<Vec<_>>()
            };
            assert_eq!(bits(&gx), bits(&gy), "{what}: surface '{}'", x.name);
        }
        let fresh = sb.meshes(9, 16).unwrap();
        assert_eq!(a.meshes(9, 16).unwrap(), &fresh[..], "{what}: meshes");
    }

    /// A random edit of one of the design's curves, its smoothing parameter or its modes
    /// (sometimes one that leaves the design unsolvable, such as a zero radius).
    fn random_edit(rng: &mut ChaCha8Rng, spec: &DesignSpec) -> Edit {
        let names: Vec<&String> = spec.curves.keys().collect();
        let name = names[rng.gen_range(0..names.len())].clone();
        let patch = spec
            .patches
            .as_ref()
            .map(|p| p[rng.gen_range(0..p.len())].name.clone());
        match rng.gen_range(0..6) {
            0 => Edit::Transform {
                name,
                step: TransformStep::Translate([
                    rng.gen_range(-0.1..0.1),
                    rng.gen_range(-0.1..0.1),
                    rng.gen_range(-0.1..0.1),
                ]),
            },
            1 => Edit::Transform {
                name,
                step: TransformStep::Scale {
                    factor: rng.gen_range(0.8..1.2),
                    about: [0.0, 0.0, rng.gen_range(0.0..1.0)],
                },
            },
            2 => Edit::SetSmoothing {
                patch,
                a: rng.gen_range(0.5..2.0),
            },
            3 => Edit::SetModes {
                modes: rng.gen_range(4..16),
            },
            4 => {
                let mut curve = spec.curves[&name].clone();
                if let CurveKind::Circle { radius, .. } = &mut curve.kind {
                    // Now and then an invalid radius: the edit is refused, nothing changes.
                    *radius = if rng.gen_bool(0.2) {
                        0.0
                    } else {
                        *radius * rng.gen_range(0.8..1.2)
                    };
                }
                Edit::SetCurve {
                    name,
                    curve: Some(curve),
                }
            }
            _ => Edit::Transform {
                name,
                step: TransformStep::Rotate {
                    axis: [0.0, 0.0, 1.0],
                    angle: rng.gen_range(-20.0..20.0),
                    about: [0.0, 0.0, 0.0],
                },
            },
        }
    }

    /// Random sequences of edits applied incrementally give the same surfaces, bit for bit,
    /// and the same design as compiling the final design from scratch; undoing every edit in
    /// reverse returns the original design and surfaces.
    #[test]
    fn incremental_edits_match_compiling_from_scratch_and_undo() {
        for (file, steps, seed) in [
            ("cup.toml", 24, 1),
            ("wine_glass.toml", 16, 2),
            ("klein_bottle_patches.toml", 6, 3),
        ] {
            let original = example(file);
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let mut d = compile(&original).unwrap();
            let mut undo = Vec::new();
            let mut refused = 0;
            for step in 0..steps {
                let edit = random_edit(&mut rng, d.spec());
                let before = d.spec().clone();
                match d.apply(&edit) {
                    Ok(u) => undo.push(u),
                    Err(_) => {
                        refused += 1;
                        assert_eq!(d.spec(), &before, "{file} step {step}: refused edit");
                    }
                }
                let scratch = compile(d.spec()).unwrap();
                assert_eq!(d.spec(), scratch.spec());
                assert_same(&mut d, &scratch, &format!("{file} step {step} {edit:?}"));
            }
            assert!(undo.len() > refused, "{file}: {} edits applied", undo.len());
            // The edited design writes out as a design file that reads in to the same design
            // and solves to the same surfaces.
            let text = write_design(d.spec()).unwrap();
            let reread = parse_design(&text).unwrap();
            assert_eq!(&reread, d.spec(), "{file}: written and read back");
            assert_same(
                &mut d,
                &compile(&reread).unwrap(),
                &format!("{file}: reread"),
            );
            // Every undo edit travels as JSON and comes back equal.
            for u in &undo {
                let json = serde_json::to_string(u).unwrap();
                let back: Edit = serde_json::from_str(&json).unwrap();
                assert_eq!(&back, u, "{json}");
            }
            for u in undo.iter().rev() {
                d.apply(u).unwrap();
            }
            assert_eq!(d.spec(), &original, "{file}: undo");
            assert_same(
                &mut d,
                &compile(&original).unwrap(),
                &format!("{file}: undo"),
            );
        }
    }

    /// An edit re-solves only the patches that depend on what it changed: the others are the
    /// very objects of the previous solve.
    #[test]
    fn an_edit_re_solves_only_dependent_patches() {
        let mut d = compile(&example("cup.toml")).unwrap();
        let ids = |d: &CompiledDesign| -> Vec<usize> {
            d.solved().surfaces.iter().map(|s| s.kind.id()).collect()
        };
        let before = ids(&d);
        // The rim is a condition of the bowl only.
        d.apply(&Edit::Transform {
            name: "rim".into(),
            step: TransformStep::Translate([0.0, 0.0, 0.1]),
        })
        .unwrap();
        let after = ids(&d);
        let names: Vec<&str> = d.solved().names();
        assert_eq!(names, ["base", "bowl"]);
        assert_eq!(after[0], before[0], "the base does not use the rim");
        assert_ne!(after[1], before[1], "the bowl does");
        // The belly is shared: both re-solve.
        d.apply(&Edit::Transform {
            name: "belly".into(),
            step: TransformStep::Translate([0.0, 0.0, 0.1]),
        })
        .unwrap();
        let again = ids(&d);
        assert!(again[0] != after[0] && again[1] != after[1]);
    }
}

/// A `[blend]` whose start surface is a surface of the design (`type = "patch"`) is the blend of
/// that surface: here a `[[parametric]]` copy of the example's first cylinder gives the same
/// blend as the built-in cylinder, to rounding (the formula's symbolic partials differ from the
/// cylinder's in the last bits only).
#[test]
fn blends_join_surfaces_of_their_design() {
    use crate::design::{solve_design, SurfaceKind};
    let path = format!(
        "{}/../../examples/blend_cylinders.toml",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(path).unwrap();
    let builtin = solve_design(&parse_design(&text).unwrap()).unwrap();
    let own = text.replace(
        "surface = { type = \"cylinder\", base = [-1.0, 0.0, 0.0], axis = [2.0, 0.0, 0.0], radius = 2.0 }",
        "surface = { type = \"patch\", name = \"tube\" }",
    ) + "\n[[parametric]]\nname = \"tube\"\nx = \"-1 + 2*v\"\ny = \"2*cos(2*pi*u)\"\nz = \"2*sin(2*pi*u)\"\ndomain = [0.0, 1.0]\n";
    assert_ne!(own, text);
    let joined = solve_design(&parse_design(&own).unwrap()).unwrap();
    assert_eq!(joined.names(), ["tube", "blend"]);
    let blend = |d: &crate::design::SolvedDesign| match &d.surfaces.last().unwrap().kind {
        SurfaceKind::Blend(b) => b.clone(),
        _ => panic!("no blend"),
    };
    let (a, b) = (blend(&builtin), blend(&joined));
    for i in 0..=8 {
        for j in 0..=8 {
            let (x, y) = (i as f64 / 8.0, j as f64 / 8.0);
            let d = (a.surface.evaluate(x, y).x - b.surface.evaluate(x, y).x).norm();
            assert!(d < 1e-11, "at ({x}, {y}): {d}");
        }
    }
    // An unknown name is refused at its place.
    let bad = own.replace("name = \"tube\" }", "name = \"tub\" }");
    let e = solve_design(&parse_design(&bad).unwrap()).unwrap_err();
    assert_eq!(e.place(), "blend.start.surface.name", "{e}");
    assert!(e.to_string().contains("'tub'"), "{e}");
}

/// Edits that do not apply are refused with their place, and leave the design as it was.
#[test]
fn edits_that_do_not_apply_are_refused() {
    use crate::design::{compile, Edit};
    let spec = parse_design(&design(FOUR, "")).unwrap();
    let mut d = compile(&spec).unwrap();
    let general = Edit::SetOperator {
        patch: None,
        operator: Some(OperatorSpec::General {
            coefficients: vec![1.0, 2.0, 1.0],
        }),
    };
    let undo = d.apply(&general).unwrap();
    let cases = [
        (
            Edit::SetSmoothing {
                patch: None,
                a: 2.0,
            },
            "a",
        ),
        (
            Edit::SetOrder {
                patch: None,
                order: 3,
            },
            "order",
        ),
        (
            Edit::MoveControlPoint {
                name: "rim".into(),
                index: 0,
                point: [0.0; 3],
            },
            "name",
        ),
        (
            Edit::RemoveCondition {
                patch: None,
                index: 9,
            },
            "index",
        ),
        (
            Edit::RemovePatch {
                name: "nothing".into(),
            },
            "patch",
        ),
        (
            Edit::Transform {
                name: "nothing".into(),
                step: TransformStep::Translate([0.0; 3]),
            },
            "name",
        ),
    ];
    for (edit, place) in cases {
        let before = d.spec().clone();
        let e = d.apply(&edit).unwrap_err();
        assert_eq!(e.place(), place, "{edit:?}: {e}");
        assert_eq!(d.spec(), &before, "{edit:?}");
    }
    d.apply(&undo).unwrap();
    assert_eq!(d.spec(), &spec);
}

/// The default grid of a design of many pieces is coarser, so that all pieces together stay
/// within the default's vertex budget; a design of few pieces, an `[output]` grid and the
/// caller's grid are kept; a caller's grid too large for all the pieces is refused by their
/// count (every face of a patchwork is one piece for four sides, else one per side).
#[test]
fn the_default_grid_of_many_pieces_is_coarser() {
    let patchwork = |triangles: usize, quads: usize| DesignSpec {
        patchwork: vec![PatchworkSpec {
            name: "p".into(),
            order: 2,
            a: 1.0,
            degree: 10,
            points: Vec::new(),
            normals: Vec::new(),
            edges: Vec::new(),
            faces: [
                vec![vec![0, 1, 2]; triangles],
                vec![vec![0, 1, 2, 3]; quads],
            ]
            .concat(),
        }],
        ..DesignSpec::default()
    };
    // 100 triangles and 56 quadrilaterals: 356 pieces of 128 × 128 would be 5.8 million
    // vertices; 4 194 304 / 356 = 11 781.7, whose square root is 108.5.
    let many = patchwork(100, 56);
    assert_eq!(grid(&many, None, None).unwrap(), (108, 108));
    // 256 pieces of 128 × 128 are exactly the budget.
    assert_eq!(grid(&patchwork(0, 256), None, None).unwrap(), (128, 128));
    assert_eq!(grid(&patchwork(0, 257), None, None).unwrap(), (127, 127));
    // The floor: more than (1 << 22) / 9² = 51 781 pieces get 9 × 9.
    assert_eq!(grid(&patchwork(0, 60_000), None, None).unwrap(), (9, 9));
    assert_eq!(grid(&many, Some(40), None).unwrap(), (128, 128));
    assert_eq!(grid(&many, Some(20), Some(30)).unwrap(), (30, 30));
    let mut given = many.clone();
    given.output.nu = Some(100);
    assert_eq!(grid(&given, None, None).unwrap(), (128, 128));
    // 200 000 triangles are 600 000 pieces: 128 × 128 each is past every vertex limit.
    let e = grid(&patchwork(200_000, 0), Some(128), Some(128)).unwrap_err();
    assert!(e.to_string().contains("600000 patches"), "{e}");
}
