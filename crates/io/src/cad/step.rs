//! STEP (ISO 10303-21) in the AP214 schema `AUTOMOTIVE_DESIGN`: one product named after the
//! design whose shape is a shell of `ADVANCED_FACE`s, each over a `B_SPLINE_SURFACE_WITH_KNOTS`
//! and bounded by one loop of its boundary curves (`B_SPLINE_CURVE_WITH_KNOTS`, the boundary
//! control rows of the net, so each edge lies exactly on its face).
//!
//! A trimmed surface's face has one `FACE_BOUND` per hole besides its outer bound: a closed
//! edge over a `SURFACE_CURVE` whose 3D B-spline and `PCURVE` (a 2D B-spline in the face's
//! `(u, v)`) are those of [`super::trimmed`].
//!
//! Topology: vertices are the nets' corners, edges their boundary rows; a boundary that is one
//! point (a pole) is left out of the loop; equal rows (the seam of a closed direction, an edge
//! two faces share) are one `EDGE_CURVE` used with both orientations. When every edge is used
//! exactly twice the shell is a `CLOSED_SHELL` of a `MANIFOLD_SOLID_BREP` (the faces oriented
//! consistently), otherwise an `OPEN_SHELL` of a `SHELL_BASED_SURFACE_MODEL`.

use super::curve::BCurve;
use super::CadModel;
use crate::spline::BSplineSurface;
use crate::{Error, Result, Vec3};
use std::fmt::Write as _;

/// The length unit a file declares (coordinates are written as they are): the design's
/// [`Units`](crate::spec::Units), under the name this module has always used.
pub use crate::spec::Units as LengthUnit;

/// Options of a STEP file.
#[derive(Clone, Debug)]
pub struct StepOptions {
    /// The length unit the file declares (coordinates are written as they are).
    pub unit: LengthUnit,
    /// The file name recorded in the header.
    pub file_name: String,
    /// `YYYY-MM-DDTHH:MM:SS` recorded in the header.
    pub timestamp: String,
}

/// A STEP real: shortest round-trip digits with a decimal point and `E` exponent.
pub(crate) fn real(x: f64) -> String {
    let s = format!("{x:?}");
    let (mant, exp) = match s.find(['e', 'E']) {
        Some(k) => (&s[..k], Some(&s[k + 1..])),
        None => (s.as_str(), None),
    };
    let mant = if mant.contains('.') {
        mant.to_string()
    } else {
        format!("{mant}.")
    };
    match exp {
        Some(e) => format!("{mant}E{e}"),
        None => mant,
    }
}

/// A STEP string literal (ISO 10303-21): printable ASCII as is with `'` and `\` doubled; every
/// other character of the basic plane in a `\X2\…\X0\` run of four hex digits each, one
/// beyond it in a `\X4\…\X0\` run of eight, so `§` is `\X2\00A7\X0\`.
fn string(s: &str) -> String {
    let mut out = String::from("'");
    // The open run: 0 none, else its digits per character (4 or 8).
    let mut run = 0;
    for c in s.chars() {
        let width = if c.is_ascii() && !c.is_ascii_control() {
            0
        } else if (c as u32) <= 0xFFFF {
            4
        } else {
            8
        };
        if width != run && run != 0 {
            out.push_str("\\X0\\");
        }
        if width != run && width != 0 {
            out.push_str(if width == 4 { "\\X2\\" } else { "\\X4\\" });
        }
        run = width;
        match (c, width) {
            ('\'', _) => out.push_str("''"),
            ('\\', _) => out.push_str("\\\\"),
            (c, 0) => out.push(c),
            (c, w) => out.push_str(&format!("{:0w$X}", c as u32)),
        }
    }
    if run != 0 {
        out.push_str("\\X0\\");
    }
    out.push('\'');
    out
}

/// Knot values and multiplicities of a full knot vector.
pub(crate) fn knot_runs(knots: &[f64]) -> (Vec<f64>, Vec<usize>) {
    let (mut values, mut mults) = (Vec::new(), Vec::new());
    for &k in knots {
        if values.last() == Some(&k) {
            *mults.last_mut().unwrap() += 1;
        } else {
            values.push(k);
            mults.push(1);
        }
    }
    (values, mults)
}

fn list<T: ToString>(items: impl IntoIterator<Item = T>) -> String {
    let v: Vec<String> = items.into_iter().map(|x| x.to_string()).collect();
    format!("({})", v.join(","))
}

/// A boundary curve: knots, degree and control points.
#[derive(Clone, Debug)]
struct Curve {
    degree: usize,
    knots: Vec<f64>,
    points: Vec<Vec3>,
}

impl Curve {
    fn reversed(&self) -> Curve {
        let (a, b) = (self.knots[0], *self.knots.last().unwrap());
        Curve {
            degree: self.degree,
            knots: self.knots.iter().rev().map(|k| a + b - k).collect(),
            points: self.points.iter().rev().copied().collect(),
        }
    }
    fn close_to(&self, other: &Curve, tol: f64) -> bool {
        self.degree == other.degree
            && self.knots.len() == other.knots.len()
            && self
                .knots
                .iter()
                .zip(&other.knots)
                .all(|(a, b)| (a - b).abs() <= 1e-12 * (1.0 + a.abs()))
            && self.points.len() == other.points.len()
            && self
                .points
                .iter()
                .zip(&other.points)
                .all(|(p, q)| (p - q).norm() <= tol)
    }
    fn degenerate(&self, tol: f64) -> bool {
        self.points
            .iter()
            .all(|p| (p - self.points[0]).norm() <= tol)
    }
}

struct Edge {
    curve: Curve,
    start: usize,
    end: usize,
    uses: Vec<(usize, bool)>,
}

/// Faces, their loops (edge, orientation) and the shared edges and vertices.
pub(crate) struct Topology {
    vertices: Vec<Vec3>,
    edges: Vec<Edge>,
    loops: Vec<Vec<(usize, bool)>>,
    /// Face orientation agrees with the surface normal.
    same_sense: Vec<bool>,
    pub(crate) closed: bool,
}

fn rows(net: &BSplineSurface) -> [Curve; 4] {
    let [p, q] = net.degree();
    let [nu, nv] = net.counts();
    let c = net.control();
    let row = |i: usize| Curve {
        degree: q,
        knots: net.knots_v().to_vec(),
        points: c[i * nv..(i + 1) * nv].to_vec(),
    };
    let col = |j: usize| Curve {
        degree: p,
        knots: net.knots_u().to_vec(),
        points: (0..nu).map(|i| c[i * nv + j]).collect(),
    };
    // Counter-clockwise in (u, v): v = v0 forwards, u = u1 forwards, v = v1 back, u = u0 back.
    [
        col(0),
        row(nu - 1),
        col(nv - 1).reversed(),
        row(0).reversed(),
    ]
}

impl Topology {
    /// Edges used by two different faces.
    #[cfg(test)]
    pub(crate) fn shared_edges(&self) -> usize {
        self.edges
            .iter()
            .filter(|e| e.uses.len() == 2 && e.uses[0].0 != e.uses[1].0)
            .count()
    }

    pub(crate) fn build(nets: &[&BSplineSurface], tol: f64) -> Topology {
        let mut t = Topology {
            vertices: Vec::new(),
            edges: Vec::new(),
            loops: Vec::new(),
            same_sense: vec![true; nets.len()],
            closed: false,
        };
        for (f, net) in nets.iter().enumerate() {
            let mut lp = Vec::new();
            for curve in rows(net) {
                if curve.degenerate(tol) {
                    continue;
                }
                let (e, forward) = t.edge(curve, tol);
                t.edges[e].uses.push((f, forward));
                lp.push((e, forward));
            }
            t.loops.push(lp);
        }
        t.closed = !t.edges.is_empty() && t.edges.iter().all(|e| e.uses.len() == 2);
        if t.closed {
            t.orient();
        }
        t
    }

    fn vertex(&mut self, p: Vec3, tol: f64) -> usize {
        if let Some(k) = self.vertices.iter().position(|q| (p - q).norm() <= tol) {
            return k;
        }
        self.vertices.push(p);
        self.vertices.len() - 1
    }

    fn edge(&mut self, curve: Curve, tol: f64) -> (usize, bool) {
        for (k, e) in self.edges.iter().enumerate() {
            if e.curve.close_to(&curve, tol) {
                return (k, true);
            }
            if e.curve.close_to(&curve.reversed(), tol) {
                return (k, false);
            }
        }
        let start = self.vertex(curve.points[0], tol);
        let end = self.vertex(*curve.points.last().unwrap(), tol);
        self.edges.push(Edge {
            curve,
            start,
            end,
            uses: Vec::new(),
        });
        (self.edges.len() - 1, true)
    }

    /// Makes every edge of a closed shell used once in each direction, flipping faces from the
    /// first one outwards (a face flipped reverses its loop).
    fn orient(&mut self) {
        let n = self.loops.len();
        let mut done = vec![false; n];
        for seed in 0..n {
            if done[seed] {
                continue;
            }
            done[seed] = true;
            let mut stack = vec![seed];
            while let Some(f) = stack.pop() {
                for &(e, dir) in &self.loops[f].clone() {
                    let dir = dir == self.same_sense[f];
                    for &(g, gdir) in &self.edges[e].uses {
                        if g == f || done[g] {
                            continue;
                        }
                        // Same direction on both sides: flip the neighbour.
                        if gdir == dir {
                            self.same_sense[g] = false;
                        }
                        done[g] = true;
                        stack.push(g);
                    }
                }
            }
        }
    }
}

struct Writer {
    out: String,
    next: usize,
}

impl Writer {
    fn add(&mut self, entity: impl AsRef<str>) -> usize {
        let id = self.next;
        self.next += 1;
        let _ = writeln!(self.out, "#{id}={};", entity.as_ref());
        id
    }
    fn point(&mut self, p: &Vec3) -> usize {
        self.add(format!(
            "CARTESIAN_POINT('',({},{},{}))",
            real(p.x),
            real(p.y),
            real(p.z)
        ))
    }
}

/// A B-spline curve (3D, or 2D when `planar`) as `B_SPLINE_CURVE_WITH_KNOTS`, closed.
fn bspline_curve(w: &mut Writer, c: &BCurve, planar: bool) -> usize {
    let pts: Vec<usize> = c
        .points
        .iter()
        .map(|p| {
            if planar {
                w.add(format!("CARTESIAN_POINT('',({},{}))", real(p.x), real(p.y)))
            } else {
                w.point(p)
            }
        })
        .collect();
    let (values, mults) = knot_runs(&c.knots);
    w.add(format!(
        "B_SPLINE_CURVE_WITH_KNOTS('',{},{},.UNSPECIFIED.,.T.,.F.,{},{},.UNSPECIFIED.)",
        c.degree,
        refs(&pts),
        list(mults),
        list(values.into_iter().map(real)),
    ))
}

/// A hole of a face: one closed `EDGE_CURVE` over a `SURFACE_CURVE` (the 3D edge and its
/// `PCURVE` in the face's parameter space) at one vertex, used clockwise in `(u, v)` (the face
/// on its left), as a `FACE_BOUND`.
fn hole_bound(
    w: &mut Writer,
    hole: &super::trimmed::Hole,
    surface: usize,
    ctx2: &mut Option<usize>,
    sense: bool,
) -> usize {
    let c3 = bspline_curve(w, &hole.edge, false);
    let c2 = bspline_curve(w, &hole.pcurve, true);
    let ctx = *ctx2.get_or_insert_with(|| {
        w.add("(GEOMETRIC_REPRESENTATION_CONTEXT(2)PARAMETRIC_REPRESENTATION_CONTEXT()REPRESENTATION_CONTEXT('2D SPACE',''))")
    });
    let rep = w.add(format!("DEFINITIONAL_REPRESENTATION('',(#{c2}),#{ctx})"));
    let pc = w.add(format!("PCURVE('',#{surface},#{rep})"));
    let sc = w.add(format!("SURFACE_CURVE('',#{c3},(#{pc}),.PCURVE_S1.)"));
    let pt = w.point(&hole.edge.points[0]);
    let v = w.add(format!("VERTEX_POINT('',#{pt})"));
    let e = w.add(format!("EDGE_CURVE('',#{v},#{v},#{sc},.T.)"));
    let tf = |b: bool| if b { ".T." } else { ".F." };
    let oe = w.add(format!(
        "ORIENTED_EDGE('',*,*,#{e},{})",
        tf(!hole.counter_clockwise)
    ));
    let lp = w.add(format!("EDGE_LOOP('',(#{oe}))"));
    w.add(format!("FACE_BOUND('',#{lp},{})", tf(sense)))
}

fn refs(ids: &[usize]) -> String {
    list(ids.iter().map(|i| format!("#{i}")))
}

/// The model as a STEP file.
pub fn to_step(model: &CadModel, opts: &StepOptions) -> Result<String> {
    if model.surfaces.is_empty() {
        return Err(Error::no_surface());
    }
    let nets: Vec<&BSplineSurface> = model.surfaces.iter().map(|s| &s.approx.net).collect();
    if nets
        .iter()
        .flat_map(|n| n.control().iter())
        .any(|p| !p.iter().all(|x| x.is_finite()))
    {
        return Err(Error::invalid(
            "a surface has a control point that is not finite",
        ));
    }
    let size = nets
        .iter()
        .flat_map(|n| n.control().iter())
        .fold(1.0f64, |m, p| m.max(p.amax()));
    let mut topo = Topology::build(&nets, 1e-9 * size);
    // A hole's edge bounds one face only: a trimmed shell is open.
    if model.surfaces.iter().any(|s| !s.holes.is_empty()) {
        topo.closed = false;
    }
    let mut w = Writer {
        out: String::new(),
        next: 1,
    };
    let name = model.name.as_str();
    // Product structure.
    let app = w.add("APPLICATION_CONTEXT('automotive design')");
    w.add(format!(
        "APPLICATION_PROTOCOL_DEFINITION('international standard','automotive_design',2000,#{app})"
    ));
    let pctx = w.add(format!("PRODUCT_CONTEXT('',#{app},'mechanical')"));
    let product = w.add(format!(
        "PRODUCT({},{},'',(#{pctx}))",
        string(name),
        string(name)
    ));
    w.add(format!(
        "PRODUCT_RELATED_PRODUCT_CATEGORY('part',$,(#{product}))"
    ));
    let formation = w.add(format!("PRODUCT_DEFINITION_FORMATION('','',#{product})"));
    let dctx = w.add(format!(
        "PRODUCT_DEFINITION_CONTEXT('part definition',#{app},'design')"
    ));
    let pdef = w.add(format!(
        "PRODUCT_DEFINITION('design','',#{formation},#{dctx})"
    ));
    let pds = w.add(format!("PRODUCT_DEFINITION_SHAPE('','',#{pdef})"));
    // Units and context.
    let length = match opts.unit {
        LengthUnit::Millimetre => w.add("(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.))"),
        LengthUnit::Centimetre => w.add("(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.CENTI.,.METRE.))"),
        LengthUnit::Metre => w.add("(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT($,.METRE.))"),
        LengthUnit::Inch => {
            let mm = w.add("(LENGTH_UNIT()NAMED_UNIT(*)SI_UNIT(.MILLI.,.METRE.))");
            let measure = w.add(format!(
                "LENGTH_MEASURE_WITH_UNIT(LENGTH_MEASURE(25.4),#{mm})"
            ));
            let dims = w.add("DIMENSIONAL_EXPONENTS(1.,0.,0.,0.,0.,0.,0.)");
            w.add(format!(
                "(CONVERSION_BASED_UNIT('INCH',#{measure})LENGTH_UNIT()NAMED_UNIT(#{dims}))"
            ))
        }
    };
    let angle = w.add("(NAMED_UNIT(*)PLANE_ANGLE_UNIT()SI_UNIT($,.RADIAN.))");
    let solid = w.add("(NAMED_UNIT(*)SI_UNIT($,.STERADIAN.)SOLID_ANGLE_UNIT())");
    let unc = w.add(format!(
        "UNCERTAINTY_MEASURE_WITH_UNIT(LENGTH_MEASURE({}),#{length},'distance_accuracy_value','maximum model space distance between geometric entities at asserted connectivities')",
        real((1e-7 * size).max(model.tolerance.min(1e-3 * size)))
    ));
    let ctx = w.add(format!(
        "(GEOMETRIC_REPRESENTATION_CONTEXT(3)GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT((#{unc}))GLOBAL_UNIT_ASSIGNED_CONTEXT((#{length},#{angle},#{solid}))REPRESENTATION_CONTEXT('',''))"
    ));
    // Geometry and topology.
    let vertex_ids: Vec<usize> = topo
        .vertices
        .iter()
        .map(|p| {
            let pt = w.point(p);
            w.add(format!("VERTEX_POINT('',#{pt})"))
        })
        .collect();
    let mut edge_ids = Vec::with_capacity(topo.edges.len());
    for e in &topo.edges {
        let c = &e.curve;
        let pts: Vec<usize> = c.points.iter().map(|p| w.point(p)).collect();
        let (values, mults) = knot_runs(&c.knots);
        let closed = e.start == e.end;
        let curve = w.add(format!(
            "B_SPLINE_CURVE_WITH_KNOTS('',{},{},.UNSPECIFIED.,{},.F.,{},{},.UNSPECIFIED.)",
            c.degree,
            refs(&pts),
            if closed { ".T." } else { ".F." },
            list(mults),
            list(values.into_iter().map(real)),
        ));
        edge_ids.push(w.add(format!(
            "EDGE_CURVE('',#{},#{},#{curve},.T.)",
            vertex_ids[e.start], vertex_ids[e.end]
        )));
    }
    let mut faces = Vec::with_capacity(nets.len());
    // The parameter-space context of the pcurves, written with the first one.
    let mut ctx2: Option<usize> = None;
    for (f, (s, net)) in model.surfaces.iter().zip(&nets).enumerate() {
        let [p, q] = net.degree();
        let [nu, nv] = net.counts();
        let c = net.control();
        let grid: Vec<String> = (0..nu)
            .map(|i| {
                let ids: Vec<usize> = (0..nv).map(|j| w.point(&c[i * nv + j])).collect();
                refs(&ids)
            })
            .collect();
        let (ku, mu) = knot_runs(net.knots_u());
        let (kv, mv) = knot_runs(net.knots_v());
        let [cu, cv] = s.approx.closed;
        let tf = |b: bool| if b { ".T." } else { ".F." };
        let surface = w.add(format!(
            "B_SPLINE_SURFACE_WITH_KNOTS({},{p},{q},({}),.UNSPECIFIED.,{},{},.F.,{},{},{},{},.UNSPECIFIED.)",
            string(&s.name),
            grid.join(","),
            tf(cu),
            tf(cv),
            list(mu),
            list(mv),
            list(ku.into_iter().map(real)),
            list(kv.into_iter().map(real)),
        ));
        let oriented: Vec<usize> = topo.loops[f]
            .iter()
            .map(|&(e, dir)| {
                w.add(format!(
                    "ORIENTED_EDGE('',*,*,#{},{})",
                    edge_ids[e],
                    tf(dir)
                ))
            })
            .collect();
        let lp = w.add(format!("EDGE_LOOP('',{})", refs(&oriented)));
        let sense = topo.same_sense[f];
        let mut bounds = vec![w.add(format!("FACE_OUTER_BOUND('',#{lp},{})", tf(sense)))];
        for hole in &s.holes {
            bounds.push(hole_bound(&mut w, hole, surface, &mut ctx2, sense));
        }
        faces.push(w.add(format!(
            "ADVANCED_FACE({},{},#{surface},{})",
            string(&s.name),
            refs(&bounds),
            tf(sense)
        )));
    }
    let origin = w.point(&Vec3::zeros());
    let zdir = w.add("DIRECTION('',(0.,0.,1.))");
    let xdir = w.add("DIRECTION('',(1.,0.,0.))");
    let axis = w.add(format!("AXIS2_PLACEMENT_3D('',#{origin},#{zdir},#{xdir})"));
    let rep = if topo.closed {
        let shell = w.add(format!("CLOSED_SHELL('',{})", refs(&faces)));
        let brep = w.add(format!("MANIFOLD_SOLID_BREP({},#{shell})", string(name)));
        w.add(format!(
            "ADVANCED_BREP_SHAPE_REPRESENTATION({},(#{axis},#{brep}),#{ctx})",
            string(name)
        ))
    } else {
        let shell = w.add(format!("OPEN_SHELL('',{})", refs(&faces)));
        let model_id = w.add(format!(
            "SHELL_BASED_SURFACE_MODEL({},(#{shell}))",
            string(name)
        ));
        w.add(format!(
            "MANIFOLD_SURFACE_SHAPE_REPRESENTATION({},(#{axis},#{model_id}),#{ctx})",
            string(name)
        ))
    };
    w.add(format!("SHAPE_DEFINITION_REPRESENTATION(#{pds},#{rep})"));
    let mut out = String::new();
    out.push_str("ISO-10303-21;\nHEADER;\n");
    let _ = writeln!(
        out,
        "FILE_DESCRIPTION(({}),'2;1');",
        string(&format!("{name}: B-spline surfaces (pdeshape)"))
    );
    let _ = writeln!(
        out,
        "FILE_NAME({},{},(''),(''),'pdeshape {}','pdeshape','');",
        string(&opts.file_name),
        string(&opts.timestamp),
        env!("CARGO_PKG_VERSION")
    );
    out.push_str("FILE_SCHEMA(('AUTOMOTIVE_DESIGN { 1 0 10303 214 1 1 1 1 }'));\nENDSEC;\nDATA;\n");
    out.push_str(&w.out);
    out.push_str("ENDSEC;\nEND-ISO-10303-21;\n");
    Ok(out)
}

/// `YYYY-MM-DDTHH:MM:SS` for seconds since 1970-01-01 UTC.
pub fn step_timestamp(unix_seconds: u64) -> String {
    let t = crate::splinepde::export::iges_timestamp(unix_seconds);
    // YYYYMMDD.HHNNSS
    format!(
        "{}-{}-{}T{}:{}:{}",
        &t[0..4],
        &t[4..6],
        &t[6..8],
        &t[9..11],
        &t[11..13],
        &t[13..15]
    )
}

#[cfg(test)]
mod string_tests {
    #[test]
    fn strings_keep_every_character_in_the_standard_encoding() {
        assert_eq!(super::string("cup (§4.6)"), "'cup (\\X2\\00A7\\X0\\4.6)'");
        assert_eq!(super::string("it's a\\b"), "'it''s a\\\\b'");
        assert_eq!(super::string("Ωμ"), "'\\X2\\03A903BC\\X0\\'");
        // Beyond the basic plane in its own run; a control character is encoded too.
        assert_eq!(
            super::string("𝑥\na"),
            "'\\X4\\0001D465\\X0\\\\X2\\000A\\X0\\a'"
        );
    }
}
