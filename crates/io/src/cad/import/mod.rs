//! A CAD part's faces and edges read from a B-rep (STEP `ADVANCED_FACE`s, IGES trimmed
//! surfaces or B-rep faces) into design tables, so that n-sided patches can be tangent to them:
//! every face whose surface is a plane, cylinder, cone, sphere or torus becomes a
//! `[[parametric]]` surface over the box its edges span in the surface's own parameters (exact
//! formulas, full precision); every edge on a line, circle, ellipse or (rational) B-spline curve
//! becomes a named curve; and, when asked, every loop of 3 to 8 free edges (edges with a face on
//! one side only: a gap in the part) becomes an `[[nsided]]` patch tangent to the faces around
//! it.
//!
//! Faces on (rational) B-spline surfaces become `[[nurbs]]` reference surfaces: the file's net,
//! knots and weights as they are, so the design evaluates the face exactly as the file defines
//! it. Faces on other surfaces (offset, swept, …) are listed as skipped: their edges are still
//! read, but a gap next to them is filled without a ribbon on that side.
//!
//! Two readers, one kernel: `step.rs` and `iges.rs` turn their file into a [`Brep`] (faces with
//! their surfaces and oriented edges, edges with their curves and end vertices), and [`build`]
//! turns any `Brep` into the design: names, parameter boxes, curves, free edges and gap loops.

mod iges;
mod step;

use crate::spec::{
    CurveKind, CurveRef, CurveSpec, DesignSpec, DomainSpec, LoopSideSpec, NSidedSpec, NurbsSpec,
    ParametricSpec, Units,
};
use crate::{Error, Result, Vec3};
use std::collections::BTreeMap;
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
    /// The surface's entity (STEP: `CYLINDRICAL_SURFACE`, …; IGES: `192 (cylinder)`, …).
    pub kind: String,
    /// Where the face is in the file: `line 12` (STEP's `ADVANCED_FACE`), `D 37` (IGES's
    /// directory entry of the trimmed surface or B-rep face).
    pub place: String,
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

/// Whether and how `import_step` and `import_iges` fill the gaps of a part.
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

/// A face of a B-rep as a reader hands it to [`build`].
struct Face {
    /// The surface's entity, for reports.
    kind: String,
    /// `line 12`, `D 37`: where the face is (reports and errors).
    place: String,
    /// What errors add after the place (`#45`, `entity 144`).
    label: String,
    surface: FaceSurface,
    /// The face's edges (indices into [`Brep::edges`]) in loop order, each with the direction the
    /// face runs it (true: from its `start` to its `end`).
    edges: Vec<(usize, bool)>,
}

enum FaceSurface {
    /// An analytic surface, and whether the face's normal is the surface's (`same_sense`).
    Analytic(Analytic, bool),
    /// A (rational) B-spline surface (its `name` is set by [`build`]).
    Nurbs(NurbsSpec),
    /// A surface not read (the face is listed, its edges kept).
    Skipped,
}

/// A part's topology and geometry, whatever file it came from.
struct Brep {
    units: Option<Units>,
    edges: Vec<Edge>,
    faces: Vec<Face>,
}

impl Face {
    fn bad(&self, what: &str) -> Error {
        Error::invalid(format!("{}: {}: {what}", self.place, self.label))
    }
}

/// Reads the faces and edges of a STEP file; with `fill`, also makes every loop of 3 to 8 free
/// edges an `[[nsided]]` patch tangent (G1) or curvature-continuous (G2) to the faces around
/// it. A side whose face was not read has no ribbon (and no `g2`).
pub fn import_step(text: &str, fill: Fill) -> Result<Imported> {
    build(step::read(text)?, fill)
}

/// Reads the faces and edges of an IGES file (the B-rep of entities 186/514/510 when it has
/// one, else its trimmed surfaces 144 with their shared edges found by position); with `fill`,
/// fills its gaps as [`import_step`] does.
pub fn import_iges(text: &str, fill: Fill) -> Result<Imported> {
    build(iges::read(text)?, fill)
}

/// The design of a B-rep: its faces as reference surfaces, its edges as curves `edgeK`, and
/// (with `fill`) its loops of 3 to 8 free edges as `[[nsided]]` patches `fillK`.
fn build(brep: Brep, fill: Fill) -> Result<Imported> {
    let Brep {
        units,
        edges,
        faces: read,
    } = brep;
    let mut spec = DesignSpec {
        units,
        ..DesignSpec::default()
    };
    let name_of = |e: usize| format!("edge{}", e + 1);
    // Per edge: the faces using it and the direction each runs it (true: start → end).
    let mut uses: Vec<Vec<(usize, bool)>> = vec![Vec::new(); edges.len()];
    let mut faces = Vec::with_capacity(read.len());
    for (k, face) in read.into_iter().enumerate() {
        let name = format!("face{}", k + 1);
        for &(e, forward) in &face.edges {
            uses[e].push((k, forward));
        }
        let imported = !matches!(face.surface, FaceSurface::Skipped);
        match &face.surface {
            FaceSurface::Nurbs(net) => spec.nurbs.push(NurbsSpec {
                name: name.clone(),
                ..net.clone()
            }),
            FaceSurface::Analytic(surf, same_sense) => {
                let mut pts = Vec::new();
                for &(e, _) in &face.edges {
                    pts.extend(sample_edge(&edges[e]).map_err(|err| face.bad(&err.to_string()))?);
                }
                if pts.is_empty() {
                    return Err(face.bad("a face without edges"));
                }
                spec.parametric.push(
                    analytic_face(surf, *same_sense, &pts, &name)
                        .ok_or_else(|| face.bad("the face's edges span no area of its surface"))?,
                );
            }
            FaceSurface::Skipped => {}
        }
        faces.push(ImportedFace {
            name,
            kind: face.kind,
            place: face.place,
            edges: face.edges.iter().map(|&(e, _)| name_of(e)).collect(),
            imported,
        });
    }
    spec.curves = edges
        .iter()
        .enumerate()
        .map(|(k, e)| {
            (
                name_of(k),
                CurveSpec {
                    kind: e.kind.clone(),
                    transform: Vec::new(),
                    v_origin: 0.0,
                    arc_length: false,
                },
            )
        })
        .collect::<BTreeMap<_, _>>();
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
        let names: Vec<String> = chain.iter().map(|(e, _)| name_of(*e)).collect();
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
                        curve: CurveRef::Name(name_of(e)),
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

/// The `[[parametric]]` table of an analytic face over the box its edges' points `pts` span in
/// the surface's parameters; `None` when they span no area.
fn analytic_face(
    surf: &Analytic,
    same_sense: bool,
    pts: &[Vec3],
    name: &str,
) -> Option<ParametricSpec> {
    let params: Vec<[f64; 2]> = pts.iter().map(|p| surf.inverse(*p)).collect();
    let a_span = if surf.periodic() {
        angle_span(&params.iter().map(|p| p[0]).collect::<Vec<_>>())
    } else {
        span(params.iter().map(|p| p[0]))
    };
    let b_span = span(params.iter().map(|p| p[1]));
    if !(a_span[1] > a_span[0] && b_span[1] > b_span[0]) {
        return None;
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
    Some(ParametricSpec {
        name: name.to_string(),
        x,
        y,
        z,
        domain: DomainSpec::Interval(domain),
        reference: true,
    })
}
fn span(it: impl Iterator<Item = f64>) -> [f64; 2] {
    it.fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], x| {
        [lo.min(x), hi.max(x)]
    })
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
