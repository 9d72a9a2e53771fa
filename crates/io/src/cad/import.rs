//! A CAD part's faces and edges read from a STEP B-rep (AP203/AP214/AP242 `ADVANCED_FACE`s)
//! into design tables, so that n-sided patches can be tangent to them: every face whose surface
//! is a plane, cylinder, cone, sphere or torus becomes a `[[parametric]]` surface over the box
//! its edges span in the surface's own parameters (exact formulas, full precision); every edge
//! on a line, circle, ellipse or (rational) B-spline curve becomes a named curve; and, when
//! asked, every loop of 3 to 8 free edges (edges with a face on one side only: a gap in the
//! part) becomes an `[[nsided]]` patch tangent to the faces around it.
//!
//! Faces on (rational) B-spline surfaces (`B_SPLINE_SURFACE_WITH_KNOTS`, alone or in a
//! complex instance with `RATIONAL_B_SPLINE_SURFACE`) become `[[nurbs]]` reference surfaces:
//! the file's net, knots and weights as they are, so the design evaluates the face exactly as
//! the file defines it.
//!
//! Faces on other surfaces (offset, swept, …) are listed as skipped: their edges are still
//! read, but a gap next to them is filled without a ribbon on that side.

use super::read::{instance_parts, instances, Parser, Value};
use crate::spec::{
    CurveKind, CurveRef, CurveSpec, DesignSpec, DomainSpec, LoopSideSpec, NSidedSpec, NurbsSpec,
    ParametricSpec, Units,
};
use crate::{Error, Result, Vec3};
use std::collections::{BTreeMap, HashMap};
use std::f64::consts::PI;

/// What was read.
#[derive(Clone, Debug)]
pub struct Imported {
    /// The design: the faces as `[[parametric]]` (analytic) or `[[nurbs]]` (B-spline)
    /// reference surfaces, the edges as curves, and the gaps as `[[nsided]]` patches (when
    /// asked).
    pub spec: DesignSpec,
    /// Per face of the file, in its order.
    pub faces: Vec<ImportedFace>,
    /// Per free-edge loop: its edges, and whether it became an `[[nsided]]` patch.
    pub gaps: Vec<Gap>,
}

/// One face of the file.
#[derive(Clone, Debug)]
pub struct ImportedFace {
    /// The `[[parametric]]` name (`face1`, … in the file's order), or the name it would have.
    pub name: String,
    /// The surface's STEP entity (`CYLINDRICAL_SURFACE`, …).
    pub kind: String,
    /// The line of the `ADVANCED_FACE` in the file.
    pub line: usize,
    /// The names of its edges' curves, in loop order (every loop of the face).
    pub edges: Vec<String>,
    /// False when its surface is not one pdeshape reads yet (it is then not in the design).
    pub imported: bool,
}

/// A loop of free edges.
#[derive(Clone, Debug)]
pub struct Gap {
    /// The edges' curve names in loop order.
    pub edges: Vec<String>,
    /// The `[[nsided]]` name, when the loop became a patch.
    pub patch: Option<String>,
    /// Why it did not (more than 8 or fewer than 3 sides, an open chain).
    pub note: Option<String>,
}

impl Imported {
    /// Comment lines for the top of the design file: where it came from, and per face its
    /// surface and edges, so that the edges can be found by the faces they bound.
    pub fn header(&self, source: &str) -> String {
        let mut out = format!(
            "# Imported from {source} by `pdeshape import`: the part's faces are reference\n\
             # surfaces (neighbours for `tangent_to`, not output), its edges are curves.\n"
        );
        for f in &self.faces {
            let read = if f.imported { "" } else { ", not read" };
            out.push_str(&format!(
                "#   {} ({}{read}): {}\n",
                f.name,
                f.kind,
                f.edges.join(", ")
            ));
        }
        for g in &self.gaps {
            let filled = g
                .patch
                .as_deref()
                .map_or(String::new(), |p| format!(" → {p}"));
            out.push_str(&format!("#   gap: {}{filled}\n", g.edges.join(", ")));
        }
        out.push('\n');
        out
    }
}

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

#[derive(Clone, Copy, Debug)]
struct Frame {
    o: Vec3,
    x: Vec3,
    y: Vec3,
    z: Vec3,
}

/// A number written so that reading it back gives the same `f64`.
fn n(x: f64) -> String {
    let s = format!("{x:?}");
    if s.starts_with('-') {
        format!("({s})")
    } else {
        s
    }
}

/// `o + a·p + b·q` per coordinate, as formulas (`p`, `q` direction vectors, `a`, `b` formulas).
fn combo(o: Vec3, terms: &[(&str, Vec3)]) -> [String; 3] {
    [0, 1, 2].map(|k| {
        let mut s = n(o[k]);
        for (f, d) in terms {
            if d[k] != 0.0 {
                s.push_str(&format!(" + {}*({f})", n(d[k])));
            }
        }
        s
    })
}

/// An edge's geometry: a curve of the design over `[lo, hi]`, with the vertex at `lo` first.
struct Edge {
    name: String,
    kind: CurveKind,
    /// The side's parameter interval (a B-spline edge may run over part of its curve).
    range: Option<[f64; 2]>,
    /// The vertex ids at the start and the end of the curve's own direction.
    start: usize,
    end: usize,
}

/// The analytic surfaces read: `S(a, b)` and its inverse.
#[derive(Clone, Copy, Debug)]
enum Analytic {
    Plane(Frame),
    Cylinder(Frame, f64),
    Cone(Frame, f64, f64),
    Sphere(Frame, f64),
    Torus(Frame, f64, f64),
}

impl Analytic {
    /// The first parameter is an angle (periodic) for all but the plane.
    fn periodic(&self) -> bool {
        !matches!(self, Analytic::Plane(_))
    }

    fn inverse(&self, p: Vec3) -> [f64; 2] {
        let f = match self {
            Analytic::Plane(f)
            | Analytic::Cylinder(f, _)
            | Analytic::Cone(f, ..)
            | Analytic::Sphere(f, _)
            | Analytic::Torus(f, ..) => *f,
        };
        let q = p - f.o;
        let (x, y, z) = (q.dot(&f.x), q.dot(&f.y), q.dot(&f.z));
        match self {
            Analytic::Plane(_) => [x, y],
            Analytic::Cylinder(..) | Analytic::Cone(..) => [y.atan2(x), z],
            Analytic::Sphere(..) => [y.atan2(x), z.atan2(x.hypot(y))],
            Analytic::Torus(_, major, _) => [y.atan2(x), z.atan2(x.hypot(y) - major)],
        }
    }

    /// Formulas of `S(a, b)` with `a`, `b` the formula texts.
    fn formulas(&self, a: &str, b: &str) -> [String; 3] {
        let (c, s) = (format!("cos({a})"), format!("sin({a})"));
        match *self {
            Analytic::Plane(f) => combo(f.o, &[(a, f.x), (b, f.y)]),
            Analytic::Cylinder(f, r) => combo(
                f.o,
                &[
                    (&format!("{}*{c}", n(r)), f.x),
                    (&format!("{}*{s}", n(r)), f.y),
                    (b, f.z),
                ],
            ),
            Analytic::Cone(f, r, semi) => {
                let rad = format!("{} + ({b})*{}", n(r), n(semi.tan()));
                combo(
                    f.o,
                    &[
                        (&format!("({rad})*{c}"), f.x),
                        (&format!("({rad})*{s}"), f.y),
                        (b, f.z),
                    ],
                )
            }
            Analytic::Sphere(f, r) => {
                let rad = format!("{}*cos({b})", n(r));
                combo(
                    f.o,
                    &[
                        (&format!("{rad}*{c}"), f.x),
                        (&format!("{rad}*{s}"), f.y),
                        (&format!("{}*sin({b})", n(r)), f.z),
                    ],
                )
            }
            Analytic::Torus(f, major, minor) => {
                let rad = format!("{} + {}*cos({b})", n(major), n(minor));
                combo(
                    f.o,
                    &[
                        (&format!("({rad})*{c}"), f.x),
                        (&format!("({rad})*{s}"), f.y),
                        (&format!("{}*sin({b})", n(minor)), f.z),
                    ],
                )
            }
        }
    }
}

/// The smallest interval holding the angles `t` (radians), cut at the largest gap between them.
fn angle_span(t: &[f64]) -> [f64; 2] {
    let mut s: Vec<f64> = t.iter().map(|x| x.rem_euclid(2.0 * PI)).collect();
    s.sort_by(f64::total_cmp);
    let mut best = (2.0 * PI - s[s.len() - 1] + s[0], 0);
    for k in 1..s.len() {
        if s[k] - s[k - 1] > best.0 {
            best = (s[k] - s[k - 1], k);
        }
    }
    let lo = s[best.1];
    let hi = if best.1 == 0 {
        s[s.len() - 1]
    } else {
        s[best.1 - 1] + 2.0 * PI
    };
    [lo, hi]
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

/// Whether and how `import_step` fills the gaps of a part.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fill {
    /// Faces and edges only.
    None,
    /// Every loop of 3 to 8 free edges an `[[nsided]]` patch (order 2) tangent (G1) to the
    /// faces beside it.
    G1,
    /// The same patches of order 3, curvature-continuous (G2, `g2 = true`) to the faces beside
    /// them: their normal curvature across each side is the face's.
    G2,
}

/// Reads the faces and edges of a STEP file; with `fill`, also makes every loop of 3 to 8 free
/// edges an `[[nsided]]` patch tangent (G1) or curvature-continuous (G2) to the faces around
/// it. A side whose face was not read has no ribbon (and no `g2`).
pub fn import_step(text: &str, fill: Fill) -> Result<Imported> {
    let model = Model::parse(text)?;
    let mut ids: Vec<usize> = model.items.keys().copied().collect();
    ids.sort_unstable();
    let mut spec = DesignSpec {
        units: units(&model),
        ..DesignSpec::default()
    };
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
        let name = format!("edge{}", edges.len() + 1);
        let edge = read_edge(&model, id, name, v1, v2, geom, same)?;
        edge_index.insert(id, edges.len());
        edges.push(edge);
    }
    // Faces.
    let mut faces = Vec::new();
    // Per edge: the faces using it and the direction each runs it (true: start → end).
    let mut uses: Vec<Vec<(usize, bool)>> = vec![Vec::new(); edges.len()];
    for &id in &ids {
        let Ok((t, a)) = model.entity(id) else {
            continue;
        };
        if t != "ADVANCED_FACE" && t != "FACE_SURFACE" {
            continue;
        }
        let k = faces.len();
        let name = format!("face{}", k + 1);
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
                uses[e].push((k, forward));
                face_edges.push(edges[e].name.clone());
            }
        }
        let parts = model.parts(surface_id);
        let (kind, analytic) = match parts.first() {
            Some((t, sa)) => (t.to_string(), analytic(&model, surface_id, t, sa)?),
            None => ("?".to_string(), None),
        };
        let (kind, imported) = match bspline_surface(&model, surface_id, &name)? {
            Some((net, kind)) => {
                spec.nurbs.push(net);
                (kind.to_string(), true)
            }
            None => (kind, analytic.is_some()),
        };
        if let Some(surf) = analytic {
            let mut pts = Vec::new();
            for e in face_edges
                .iter()
                .filter_map(|n| edges.iter().find(|x| &x.name == n))
            {
                pts.extend(sample_edge(e)?);
            }
            if pts.is_empty() {
                return Err(model.bad(id, "a face without edges"));
            }
            let params: Vec<[f64; 2]> = pts.iter().map(|p| surf.inverse(*p)).collect();
            let a_span = if surf.periodic() {
                angle_span(&params.iter().map(|p| p[0]).collect::<Vec<_>>())
            } else {
                span(params.iter().map(|p| p[0]))
            };
            let b_span = span(params.iter().map(|p| p[1]));
            if !(a_span[1] > a_span[0] && b_span[1] > b_span[0]) {
                return Err(model.bad(id, "the face's edges span no area of its surface"));
            }
            // u runs over the first parameter, v over the second; a face against its surface's
            // normal swaps their roles so that X_u × X_v is the face's normal.
            let a_of = |u: &str| format!("{} + {}*{u}", n(a_span[0]), n(a_span[1] - a_span[0]));
            let (x, y, z, domain) = if same_sense {
                let [x, y, z] = surf.formulas(&a_of("u"), "v");
                (x, y, z, b_span)
            } else {
                let b_of = format!("{} + {}*u", n(b_span[0]), n(b_span[1] - b_span[0]));
                let [x, y, z] = surf.formulas(&format!("{} + {}*v", n(a_span[0]), 1.0), &b_of);
                (x, y, z, [0.0, a_span[1] - a_span[0]])
            };
            spec.parametric.push(ParametricSpec {
                name: name.clone(),
                x,
                y,
                z,
                domain: DomainSpec::Interval(domain),
                reference: true,
            });
        }
        faces.push(ImportedFace {
            name,
            kind,
            line: model.line(id),
            edges: face_edges,
            imported,
        });
    }
    let mut curves = BTreeMap::new();
    for e in &edges {
        curves.insert(
            e.name.clone(),
            CurveSpec {
                kind: e.kind.clone(),
                transform: Vec::new(),
                v_origin: 0.0,
                arc_length: false,
            },
        );
    }
    spec.curves = curves;
    // Free edges: used by one face only.
    let free: Vec<usize> = (0..edges.len()).filter(|&e| uses[e].len() == 1).collect();
    let mut gaps = Vec::new();
    let mut taken = vec![false; edges.len()];
    for &first in &free {
        if taken[first] {
            continue;
        }
        // The gap runs each edge against the face beside it.
        let mut chain = vec![(first, !uses[first][0].1)];
        taken[first] = true;
        let closed = loop {
            let &(e, fwd) = chain.last().unwrap_or(&(first, true));
            let tip = if fwd { edges[e].end } else { edges[e].start };
            let start = if chain[0].1 {
                edges[first].start
            } else {
                edges[first].end
            };
            if tip == start {
                break true;
            }
            let next = free
                .iter()
                .copied()
                .find(|&f| !taken[f] && (edges[f].start == tip || edges[f].end == tip));
            match next {
                Some(f) => {
                    taken[f] = true;
                    chain.push((f, edges[f].start == tip));
                }
                None => break false,
            }
        };
        let names: Vec<String> = chain.iter().map(|(e, _)| edges[*e].name.clone()).collect();
        let note = if !closed {
            Some("the free edges do not close into a loop".to_string())
        } else if !(3..=8).contains(&chain.len()) {
            Some(format!(
                "{} sides (an n-sided patch takes 3 to 8)",
                chain.len()
            ))
        } else {
            None
        };
        let patch =
            (fill != Fill::None && note.is_none()).then(|| format!("fill{}", gaps.len() + 1));
        if let Some(p) = &patch {
            let sides = chain
                .iter()
                .map(|&(e, fwd)| {
                    let face = &faces[uses[e][0].0];
                    LoopSideSpec {
                        curve: CurveRef::Name(edges[e].name.clone()),
                        range: edges[e].range,
                        reverse: !fwd,
                        tangent_to: face.imported.then(|| face.name.clone()),
                        derivative: None,
                        g2: fill == Fill::G2 && face.imported,
                        second_derivative: None,
                    }
                })
                .collect();
            let mut patch = NSidedSpec::new(p.clone(), sides);
            if fill == Fill::G2 {
                patch.order = 3;
            }
            spec.nsided.push(patch);
        }
        gaps.push(Gap {
            edges: names,
            patch,
            note,
        });
    }
    Ok(Imported { spec, faces, gaps })
}

fn span(it: impl Iterator<Item = f64>) -> [f64; 2] {
    it.fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], x| {
        [lo.min(x), hi.max(x)]
    })
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

/// The surface of a face as a `[[nurbs]]` table named `name`, when it is a
/// `B_SPLINE_SURFACE_WITH_KNOTS` (simple, or complex with `RATIONAL_B_SPLINE_SURFACE`), with
/// the entity name to report; `None` for other surfaces.
fn bspline_surface(
    model: &Model,
    id: usize,
    name: &str,
) -> Result<Option<(NurbsSpec, &'static str)>> {
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
        name: name.to_string(),
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
    name: String,
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
            name,
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
            name,
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
            name,
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

/// The parameter in `[lo, hi]` of the point of `curve` closest to `p` (a scan, then Newton).
fn closest_parameter(curve: &dyn crate::curve::Curve, lo: f64, hi: f64, p: Vec3) -> f64 {
    let m = 256;
    let mut best = (f64::INFINITY, lo);
    for k in 0..=m {
        let t = lo + (hi - lo) * k as f64 / m as f64;
        let d = (curve.point(t) - p).norm_squared();
        if d < best.0 {
            best = (d, t);
        }
    }
    let mut t = best.1;
    for _ in 0..30 {
        let mut j = [Vec3::zeros(); 3];
        curve.jet(t, &mut j);
        let r = j[0] - p;
        let g = r.dot(&j[1]);
        let h = j[1].norm_squared() + r.dot(&j[2]);
        if h <= 0.0 {
            break;
        }
        let next = (t - g / h).clamp(lo, hi);
        if (next - t).abs() <= 1e-15 * (hi - lo) {
            t = next;
            break;
        }
        t = next;
    }
    t
}

/// The design's curve of `kind`, built by the design layer.
fn build_curve(kind: &CurveKind) -> Result<crate::curve::SharedCurve> {
    crate::design::build_curve(&CurveSpec {
        kind: kind.clone(),
        transform: Vec::new(),
        v_origin: 0.0,
        arc_length: false,
    })
}

/// Points along an edge (for the parameter box of the faces beside it).
fn sample_edge(e: &Edge) -> Result<Vec<Vec3>> {
    let curve = build_curve(&e.kind)?;
    let [lo, hi] = match (&e.range, curve.domain()) {
        (Some(r), _) => *r,
        (None, crate::curve::Domain::Interval(a, b)) => [a, b],
        (None, _) => [0.0, 2.0 * PI],
    };
    Ok((0..=32)
        .map(|k| curve.point(lo + (hi - lo) * k as f64 / 32.0))
        .collect())
}
