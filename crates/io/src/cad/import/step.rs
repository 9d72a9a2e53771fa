//! The STEP reader of `import`: the B-rep of a part's `ADVANCED_FACE`s (ISO 10303-21 syntax
//! through `cad/read.rs`'s parser), its surfaces, curves and length unit.

use super::{
    build_curve, closest_parameter, combo, n, Analytic, Brep, Edge, Face, FaceSurface, Frame,
};
use crate::cad::read::{instance_parts, instances, Parser, Value};
use crate::spec::{CurveKind, DomainSpec, NurbsSpec, Units};
use crate::{Error, Result, Vec3};
use std::collections::HashMap;
use std::f64::consts::PI;

/// Instances by id: simple (`Typed`) or complex (a list of `Typed`).
struct Model {
    items: HashMap<usize, (usize, Value)>,
}

fn num(v: Option<&Value>) -> Option<f64> {
    match v {
        Some(Value::Num(x)) => Some(*x),
        _ => None,
    }
}

impl Model {
    fn parse(text: &str) -> Result<Model> {
        let mut items = HashMap::new();
        for (line, inst) in instances(text)? {
            let at = |m: String| Error::invalid(format!("line {line}: {m}"));
            let (id, body) = instance_parts(line, &inst)?;
            let v = match body.strip_prefix('(').and_then(|b| b.strip_suffix(')')) {
                // A complex instance: typed parts one after another, without commas.
                Some(inner) => {
                    let mut p = Parser {
                        s: inner.as_bytes(),
                        i: 0,
                    };
                    let mut parts = Vec::new();
                    loop {
                        while p.s.get(p.i).is_some_and(u8::is_ascii_whitespace) {
                            p.i += 1;
                        }
                        if p.i >= p.s.len() {
                            break;
                        }
                        parts.push(p.value().map_err(at)?);
                    }
                    Value::List(parts)
                }
                None => Parser {
                    s: body.as_bytes(),
                    i: 0,
                }
                .value()
                .map_err(at)?,
            };
            items.insert(id, (line, v));
        }
        Ok(Model { items })
    }

    fn line(&self, id: usize) -> usize {
        self.items.get(&id).map_or(0, |(l, _)| *l)
    }

    /// The simple entity `id` as `(type, arguments)`.
    fn entity(&self, id: usize) -> Result<(&str, &[Value])> {
        match self.items.get(&id) {
            Some((_, Value::Typed(name, args))) => Ok((name.as_str(), args.as_slice())),
            Some((line, _)) => Err(Error::invalid(format!(
                "line {line}: #{id} is not a simple entity"
            ))),
            None => Err(Error::invalid(format!(
                "#{id} is referenced but not defined"
            ))),
        }
    }

    /// The parts of a complex entity (`( A(..) B(..) )`), or the simple one alone.
    fn parts(&self, id: usize) -> Vec<(&str, &[Value])> {
        match self.items.get(&id) {
            Some((_, Value::Typed(name, args))) => vec![(name.as_str(), args.as_slice())],
            Some((_, Value::List(parts))) => parts
                .iter()
                .filter_map(|p| match p {
                    Value::Typed(n, a) => Some((n.as_str(), a.as_slice())),
                    _ => None,
                })
                .collect(),
            _ => Vec::new(),
        }
    }

    fn bad(&self, id: usize, what: &str) -> Error {
        Error::invalid(format!("line {}: #{id}: {what}", self.line(id)))
    }

    fn reference(&self, id: usize, v: Option<&Value>, what: &str) -> Result<usize> {
        match v {
            Some(Value::Ref(r)) if self.items.contains_key(r) => Ok(*r),
            Some(Value::Ref(r)) => Err(self.bad(id, &format!("#{r} ({what}) is not defined"))),
            _ => Err(self.bad(id, &format!("expected a reference to {what}"))),
        }
    }

    fn point(&self, id: usize) -> Result<Vec3> {
        match self.entity(id)? {
            ("CARTESIAN_POINT", a) => match a.get(1) {
                Some(Value::List(c)) if c.len() == 3 => {
                    let x: Vec<f64> = c.iter().filter_map(|v| num(Some(v))).collect();
                    if x.len() == 3 && x.iter().all(|v| v.is_finite()) {
                        Ok(Vec3::new(x[0], x[1], x[2]))
                    } else {
                        Err(self.bad(id, "a coordinate that is not a finite number"))
                    }
                }
                _ => Err(self.bad(id, "expected a 3D CARTESIAN_POINT")),
            },
            ("VERTEX_POINT", a) => self.point(self.reference(id, a.get(1), "a point")?),
            (t, _) => Err(self.bad(id, &format!("expected a point, found {t}"))),
        }
    }

    fn direction(&self, id: usize) -> Result<Vec3> {
        let (t, a) = self.entity(id)?;
        if t != "DIRECTION" {
            return Err(self.bad(id, &format!("expected a DIRECTION, found {t}")));
        }
        let d = match a.get(1) {
            Some(Value::List(c)) if c.len() == 3 => Vec3::new(
                num(c.first()).unwrap_or(f64::NAN),
                num(c.get(1)).unwrap_or(f64::NAN),
                num(c.get(2)).unwrap_or(f64::NAN),
            ),
            _ => return Err(self.bad(id, "expected a 3D DIRECTION")),
        };
        let l = d.norm();
        if l.is_finite() && l > 0.0 {
            Ok(d / l)
        } else {
            Err(self.bad(id, "a DIRECTION of zero or undefined length"))
        }
    }

    /// `AXIS2_PLACEMENT_3D`: origin and the frame `(x, y, z)`.
    fn placement(&self, id: usize) -> Result<Frame> {
        let (t, a) = self.entity(id)?;
        if t != "AXIS2_PLACEMENT_3D" {
            return Err(self.bad(id, &format!("expected an AXIS2_PLACEMENT_3D, found {t}")));
        }
        let origin = self.point(self.reference(id, a.get(1), "a point")?)?;
        let z = match a.get(2) {
            Some(Value::Ref(r)) => self
                .direction(*r)
                .map_err(|e| self.bad(id, &e.to_string()))?,
            _ => Vec3::z(),
        };
        let hint = match a.get(3) {
            Some(Value::Ref(r)) => self
                .direction(*r)
                .map_err(|e| self.bad(id, &e.to_string()))?,
            _ => {
                if z.x.abs() < 0.9 {
                    Vec3::x()
                } else {
                    Vec3::y()
                }
            }
        };
        let x = hint - z * hint.dot(&z);
        if x.norm() < 1e-12 {
            return Err(self.bad(id, "the reference direction is parallel to the axis"));
        }
        let x = x.normalize();
        Ok(Frame {
            o: origin,
            x,
            y: z.cross(&x),
            z,
        })
    }
}

/// The unit of lengths in the file (`SI_UNIT(.MILLI.,.METRE.)`, `.CENTI.`, none, or inches).
fn units(model: &Model) -> Option<Units> {
    for (_, v) in model.items.values() {
        let Value::List(parts) = v else { continue };
        let mut length = false;
        let mut prefix = None;
        let mut inch = false;
        for p in parts {
            match p {
                Value::Typed(n, _) if n == "LENGTH_UNIT" => length = true,
                Value::Typed(n, a) if n == "SI_UNIT" => {
                    prefix = Some(match a.first() {
                        Some(Value::Enum(e)) => e.clone(),
                        _ => String::new(),
                    })
                }
                Value::Typed(n, a) if n == "CONVERSION_BASED_UNIT" => {
                    inch =
                        matches!(a.first(), Some(Value::Str(s)) if s.eq_ignore_ascii_case("inch"))
                }
                _ => {}
            }
        }
        if length {
            if inch {
                return Some(Units::Inch);
            }
            return match prefix.as_deref() {
                Some("MILLI") => Some(Units::Millimetre),
                Some("CENTI") => Some(Units::Centimetre),
                Some("") => Some(Units::Metre),
                _ => None,
            };
        }
    }
    None
}

fn edge_vertices(model: &Model, ec: usize) -> Result<(usize, usize)> {
    let (_, a) = model.entity(ec)?;
    Ok((
        model.reference(ec, a.get(1), "a vertex")?,
        model.reference(ec, a.get(2), "a vertex")?,
    ))
}

/// The surface of a face, when it is one of the analytic kinds.
fn analytic(model: &Model, id: usize, t: &str, a: &[Value]) -> Result<Option<Analytic>> {
    let frame = || model.placement(model.reference(id, a.get(1), "a placement")?);
    let positive = |v: Option<&Value>, what: &str| -> Result<f64> {
        match num(v) {
            Some(x) if x.is_finite() && x > 0.0 => Ok(x),
            _ => Err(model.bad(id, &format!("{t}: the {what} must be a positive number"))),
        }
    };
    Ok(Some(match t {
        "PLANE" => Analytic::Plane(frame()?),
        "CYLINDRICAL_SURFACE" => Analytic::Cylinder(frame()?, positive(a.get(2), "radius")?),
        "SPHERICAL_SURFACE" => Analytic::Sphere(frame()?, positive(a.get(2), "radius")?),
        "CONICAL_SURFACE" => {
            let r = num(a.get(2)).filter(|x| x.is_finite() && *x >= 0.0);
            let semi = num(a.get(3)).filter(|x| x.is_finite() && x.abs() < PI / 2.0);
            match (r, semi) {
                (Some(r), Some(s)) => Analytic::Cone(frame()?, r, s),
                _ => return Err(model.bad(id, "CONICAL_SURFACE: a bad radius or semi-angle")),
            }
        }
        "TOROIDAL_SURFACE" => Analytic::Torus(
            frame()?,
            positive(a.get(2), "major radius")?,
            positive(a.get(3), "minor radius")?,
        ),
        _ => return Ok(None),
    }))
}

/// The surface of a face as a `[[nurbs]]` table (named by the kernel), when it is a
/// `B_SPLINE_SURFACE_WITH_KNOTS` (simple, or complex with `RATIONAL_B_SPLINE_SURFACE`), with
/// the entity name to report; `None` for other surfaces.
fn bspline_surface(model: &Model, id: usize) -> Result<Option<(NurbsSpec, &'static str)>> {
    let parts = model.parts(id);
    let find = |t: &str| parts.iter().find(|(n, _)| *n == t).map(|(_, a)| *a);
    let Some(a) = find("B_SPLINE_SURFACE_WITH_KNOTS") else {
        return Ok(None);
    };
    // Simple: (name, p, q, points, form, u_closed, v_closed, self, u_mults, v_mults, u_knots,
    // v_knots, spec); complex: B_SPLINE_SURFACE(p, q, points, …) and
    // B_SPLINE_SURFACE_WITH_KNOTS(u_mults, v_mults, u_knots, v_knots, spec).
    let (head, knots_at) = match find("B_SPLINE_SURFACE") {
        Some(b) => (b, 0),
        None => (a.get(1..).unwrap_or(&[]), 8),
    };
    let degree = |v: Option<&Value>, which: &str| -> Result<usize> {
        match num(v) {
            Some(d) if (1.0..=30.0).contains(&d) && d.fract() == 0.0 => Ok(d as usize),
            _ => Err(model.bad(id, &format!("a B-spline surface of a bad {which} degree"))),
        }
    };
    let degree = [degree(head.first(), "u")?, degree(head.get(1), "v")?];
    let rows = |v: Option<&Value>, what: &str| -> Result<Vec<Vec<Value>>> {
        match v {
            Some(Value::List(r)) => r
                .iter()
                .map(|row| match row {
                    Value::List(c) => Ok(c.clone()),
                    _ => Err(model.bad(id, &format!("{what}: expected a list of rows"))),
                })
                .collect(),
            _ => Err(model.bad(id, &format!("{what}: expected a list of rows"))),
        }
    };
    let control = rows(head.get(2), "control points")?
        .iter()
        .map(|row| {
            row.iter()
                .map(|r| match r {
                    Value::Ref(r) => model
                        .point(*r)
                        .map(|p| [p.x, p.y, p.z])
                        .map_err(|e| model.bad(id, &e.to_string())),
                    _ => Err(model.bad(id, "a control point that is not a reference")),
                })
                .collect::<Result<Vec<_>>>()
        })
        .collect::<Result<Vec<_>>>()?;
    let list = |v: Option<&Value>| -> Vec<f64> {
        match v {
            Some(Value::List(l)) => l.iter().filter_map(|x| num(Some(x))).collect(),
            _ => Vec::new(),
        }
    };
    let full = |mults: Vec<f64>, knots: Vec<f64>, which: &str| -> Result<Vec<f64>> {
        if mults.is_empty()
            || mults.len() != knots.len()
            || mults
                .iter()
                .any(|m| !(1.0..=31.0).contains(m) || m.fract() != 0.0)
        {
            return Err(model.bad(id, &format!("bad knot multiplicities in {which}")));
        }
        Ok(mults
            .iter()
            .zip(&knots)
            .flat_map(|(m, k)| std::iter::repeat_n(*k, *m as usize))
            .collect())
    };
    let knots_u = full(list(a.get(knots_at)), list(a.get(knots_at + 2)), "u")?;
    let knots_v = full(list(a.get(knots_at + 1)), list(a.get(knots_at + 3)), "v")?;
    let (weights, kind) = match find("RATIONAL_B_SPLINE_SURFACE") {
        Some(r) => {
            let w = rows(r.first(), "weights")?
                .iter()
                .map(|row| {
                    row.iter()
                        .map(|x| {
                            num(Some(x))
                                .ok_or_else(|| model.bad(id, "a weight that is not a number"))
                        })
                        .collect::<Result<Vec<f64>>>()
                })
                .collect::<Result<Vec<_>>>()?;
            (Some(w), "RATIONAL_B_SPLINE_SURFACE")
        }
        None => (None, "B_SPLINE_SURFACE_WITH_KNOTS"),
    };
    let net = NurbsSpec {
        name: String::new(),
        degree,
        knots_u,
        knots_v,
        control,
        weights,
    };
    // Checked now, so that a bad net is refused with its line.
    crate::design::NurbsSurface::from_spec(&net, "").map_err(|e| {
        let at = e.place().trim_start_matches('.');
        let at = if at.is_empty() {
            String::new()
        } else {
            format!("{at}: ")
        };
        model.bad(id, &format!("{kind}: {at}{}", e.message()))
    })?;
    Ok(Some((net, kind)))
}

/// The geometry of an edge: its curve over the interval between its vertices.
fn read_edge(
    model: &Model,
    id: usize,
    v1: usize,
    v2: usize,
    geom: usize,
    same: bool,
) -> Result<Edge> {
    let (p1, p2) = (model.point(v1)?, model.point(v2)?);
    // Unwrap SURFACE_CURVE / SEAM_CURVE to the 3D curve.
    let mut geom = geom;
    for _ in 0..4 {
        match model.entity(geom) {
            Ok(("SURFACE_CURVE" | "SEAM_CURVE" | "INTERSECTION_CURVE", a)) => {
                geom = model.reference(geom, a.get(1), "a curve")?;
            }
            _ => break,
        }
    }
    let parts = model.parts(geom);
    let find = |t: &str| parts.iter().find(|(n, _)| *n == t).map(|(_, a)| *a);
    // The curve's direction runs v1 → v2 when `same`; the output runs the curve's own way.
    let (start, end) = if same { (v1, v2) } else { (v2, v1) };
    let (ps, pe) = if same { (p1, p2) } else { (p2, p1) };
    if let Some(a) = find("LINE") {
        let p = model.point(model.reference(geom, a.get(1), "a point")?)?;
        let vec = model.reference(geom, a.get(2), "a vector")?;
        let (_, va) = model.entity(vec)?;
        let d = model.direction(model.reference(vec, va.get(1), "a direction")?)?;
        let t0 = (ps - p).dot(&d);
        let t1 = (pe - p).dot(&d);
        if (t1 - t0).abs() <= 1e-12 * (1.0 + p.norm()) {
            return Err(model.bad(id, "an edge of zero length"));
        }
        let [x, y, z] = combo(p, &[("v", d)]);
        let domain = if t1 > t0 { [t0, t1] } else { [t1, t0] };
        let (start, end) = if t1 > t0 { (start, end) } else { (end, start) };
        return Ok(Edge {
            kind: CurveKind::Formula {
                x,
                y,
                z,
                domain: DomainSpec::Interval(domain),
            },
            range: None,
            start,
            end,
        });
    }
    let conic = find("CIRCLE")
        .map(|a| (a, true))
        .or_else(|| find("ELLIPSE").map(|a| (a, false)));
    if let Some((a, circle)) = conic {
        let f = model.placement(model.reference(geom, a.get(1), "a placement")?)?;
        let r1 = num(a.get(2)).filter(|r| r.is_finite() && *r > 0.0);
        let r2 = if circle {
            r1
        } else {
            num(a.get(3)).filter(|r| r.is_finite() && *r > 0.0)
        };
        let (Some(r1), Some(r2)) = (r1, r2) else {
            return Err(model.bad(geom, "a circle or ellipse without positive radii"));
        };
        let angle = |p: Vec3| {
            let q = p - f.o;
            (q.dot(&f.y) / r2).atan2(q.dot(&f.x) / r1)
        };
        let t0 = angle(ps);
        let mut t1 = angle(pe);
        while t1 <= t0 + 1e-12 {
            t1 += 2.0 * PI;
        }
        let [x, y, z] = combo(
            f.o,
            &[
                (&format!("{}*cos(v)", n(r1)), f.x),
                (&format!("{}*sin(v)", n(r2)), f.y),
            ],
        );
        return Ok(Edge {
            kind: CurveKind::Formula {
                x,
                y,
                z,
                domain: DomainSpec::Interval([t0, t1]),
            },
            range: None,
            start,
            end,
        });
    }
    if let Some(a) = find("B_SPLINE_CURVE_WITH_KNOTS") {
        // Simple: (name, degree, points, form, closed, self, mults, knots, spec); complex:
        // B_SPLINE_CURVE(degree, points, …) + B_SPLINE_CURVE_WITH_KNOTS(mults, knots, spec).
        let (head, mults_at) = match find("B_SPLINE_CURVE") {
            Some(b) => (b, 0),
            None => (a.get(1..).unwrap_or(&[]), 6),
        };
        let degree = num(head.first()).filter(|d| *d >= 1.0 && d.fract() == 0.0 && *d <= 30.0);
        let Some(degree) = degree.map(|d| d as usize) else {
            return Err(model.bad(geom, "a B-spline curve of a bad degree"));
        };
        let Some(Value::List(refs)) = head.get(1) else {
            return Err(model.bad(geom, "a B-spline curve without control points"));
        };
        let control = refs
            .iter()
            .map(|r| match r {
                Value::Ref(r) => model
                    .point(*r)
                    .map(|p| [p.x, p.y, p.z])
                    .map_err(|e| model.bad(geom, &e.to_string())),
                _ => Err(model.bad(geom, "a control point that is not a reference")),
            })
            .collect::<Result<Vec<_>>>()?;
        let list = |v: Option<&Value>| -> Vec<f64> {
            match v {
                Some(Value::List(l)) => l.iter().filter_map(|x| num(Some(x))).collect(),
                _ => Vec::new(),
            }
        };
        let (mults, knots) = (list(a.get(mults_at)), list(a.get(mults_at + 1)));
        if mults.len() != knots.len() || mults.iter().any(|m| *m < 1.0 || m.fract() != 0.0) {
            return Err(model.bad(geom, "bad knot multiplicities"));
        }
        let total: f64 = mults.iter().sum();
        if total as usize != control.len() + degree + 1 {
            return Err(model.bad(
                geom,
                &format!(
                    "the knot multiplicities sum to {total}; {} control points of degree {degree} need {}",
                    control.len(),
                    control.len() + degree + 1
                ),
            ));
        }
        let full: Vec<f64> = mults
            .iter()
            .zip(&knots)
            .flat_map(|(m, k)| std::iter::repeat_n(*k, *m as usize))
            .collect();
        let weights = find("RATIONAL_B_SPLINE_CURVE").map(|r| list(r.first()));
        let kind = CurveKind::BSpline {
            degree,
            control,
            knots: Some(full.clone()),
            periodic: false,
            weights,
        };
        // The vertices' parameters, by closest point on the curve.
        let curve = build_curve(&kind).map_err(|e| model.bad(geom, &e.to_string()))?;
        let (lo, hi) = (full[degree], full[full.len() - degree - 1]);
        let t_of = |p: Vec3| closest_parameter(&*curve, lo, hi, p);
        let (t0, t1) = (t_of(ps), t_of(pe));
        let range = if t1 > t0 { [t0, t1] } else { [t1, t0] };
        let (start, end) = if t1 > t0 { (start, end) } else { (end, start) };
        return Ok(Edge {
            kind,
            range: Some(range),
            start,
            end,
        });
    }
    let what = parts.first().map_or("?", |(t, _)| *t);
    Err(model.bad(
        id,
        &format!("an edge on a {what}: not read yet (lines, circles, ellipses and B-splines are)"),
    ))
}

/// The B-rep of a STEP file: its `EDGE_CURVE`s and its `ADVANCED_FACE`s (or `FACE_SURFACE`s).
pub(super) fn read(text: &str) -> Result<Brep> {
    let model = Model::parse(text)?;
    let mut ids: Vec<usize> = model.items.keys().copied().collect();
    ids.sort_unstable();
    // Edges, in the file's order.
    let mut edges: Vec<Edge> = Vec::new();
    let mut edge_index: HashMap<usize, usize> = HashMap::new();
    for &id in &ids {
        let Ok(("EDGE_CURVE", a)) = model.entity(id) else {
            continue;
        };
        let v1 = model.reference(id, a.get(1), "a vertex")?;
        let v2 = model.reference(id, a.get(2), "a vertex")?;
        let geom = model.reference(id, a.get(3), "a curve")?;
        let same = !matches!(a.get(4), Some(Value::Enum(e)) if e == "F");
        let edge = read_edge(&model, id, v1, v2, geom, same)?;
        edge_index.insert(id, edges.len());
        edges.push(edge);
    }
    let mut faces = Vec::new();
    for &id in &ids {
        let Ok((t, a)) = model.entity(id) else {
            continue;
        };
        if t != "ADVANCED_FACE" && t != "FACE_SURFACE" {
            continue;
        }
        let surface_id = model.reference(id, a.get(2), "a surface")?;
        let same_sense = !matches!(a.get(3), Some(Value::Enum(e)) if e == "F");
        let mut face_edges = Vec::new();
        let bounds = match a.get(1) {
            Some(Value::List(b)) => b.clone(),
            _ => return Err(model.bad(id, "expected a list of face bounds")),
        };
        for b in &bounds {
            let Value::Ref(b) = b else {
                return Err(model.bad(id, "a face bound that is not a reference"));
            };
            let (_, ba) = model
                .entity(*b)
                .map_err(|e| model.bad(id, &e.to_string()))?;
            let loop_id = model.reference(*b, ba.get(1), "an edge loop")?;
            let bound_sense = !matches!(ba.get(2), Some(Value::Enum(e)) if e == "F");
            let (lt, la) = model.entity(loop_id)?;
            if lt != "EDGE_LOOP" {
                continue; // a VERTEX_LOOP (a pole) or a POLY_LOOP: no edges
            }
            let Some(Value::List(oes)) = la.get(1) else {
                return Err(model.bad(loop_id, "expected a list of oriented edges"));
            };
            for oe in oes {
                let Value::Ref(oe) = oe else { continue };
                let (_, oa) = model
                    .entity(*oe)
                    .map_err(|e| model.bad(loop_id, &e.to_string()))?;
                let ec = model.reference(*oe, oa.get(3), "an edge")?;
                let sense = !matches!(oa.get(4), Some(Value::Enum(e)) if e == "F");
                let Some(&e) = edge_index.get(&ec) else {
                    return Err(model.bad(*oe, &format!("#{ec} is not an EDGE_CURVE")));
                };
                // The face runs the edge from its first vertex to its second when the two
                // senses agree; the curve's own direction may be the other way.
                let v1_first = sense == bound_sense;
                let (v1, _) = edge_vertices(&model, ec)?;
                let forward = v1_first == (edges[e].start == v1);
                face_edges.push((e, forward));
            }
        }
        let parts = model.parts(surface_id);
        let (kind, analytic) = match parts.first() {
            Some((t, sa)) => (t.to_string(), analytic(&model, surface_id, t, sa)?),
            None => ("?".to_string(), None),
        };
        let (kind, surface) = match bspline_surface(&model, surface_id)? {
            Some((net, kind)) => (kind.to_string(), FaceSurface::Nurbs(net)),
            None => match analytic {
                Some(s) => (kind, FaceSurface::Analytic(s, same_sense)),
                None => (kind, FaceSurface::Skipped),
            },
        };
        faces.push(Face {
            kind,
            place: format!("line {}", model.line(id)),
            label: format!("#{id}"),
            surface,
            edges: face_edges,
        });
    }
    Ok(Brep {
        units: units(&model),
        edges,
        faces,
    })
}
