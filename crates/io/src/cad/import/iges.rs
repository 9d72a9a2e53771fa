//! The IGES reader of `import`: the faces of a part written as a B-rep (entities 186/514/510/
//! 508/504/502: shells of faces, loops of edges, vertex lists) or as trimmed surfaces (144 with
//! its boundaries 142), their surfaces (128, 108, 190, 192, 194, 196, 198) and the edges' curves
//! (110, 100, 104, 126, 102), every entity through its transformation matrix (124) and the
//! Global section's model scale.
//!
//! A trimmed-surface file gives every edge once per face: the edges are matched by position
//! (end points within a tolerance relative to the part's size, and interior points on the other
//! curve), so that an edge used by one face only is free, as in a B-rep.

use super::Frame;
use super::{build_curve, closest_parameter, combo, n, Analytic, Brep, Edge, Face, FaceSurface};
use crate::cad::iges_read::{self, Entity, IgesFile};
use crate::curve::{Curve, Domain};
use crate::spec::{CurveKind, DomainSpec, NurbsSpec};
use crate::{Result, Vec3};
use std::collections::HashMap;
use std::f64::consts::PI;

/// End points and interior points of edges closer than this fraction of the part's size (the
/// diagonal of the box of all edge ends) are one point. IGES writers print about 15 significant
/// digits, so copies of one point differ by rounding far below it; distinct vertices of a part
/// are far above it.
const REL_TOL: f64 = 1e-7;

/// How deep entities may point at entities that point at entities (composite curves in
/// composite curves, chains of transformation matrices).
const MAX_DEPTH: usize = 16;

/// `x ↦ m x + t`.
#[derive(Clone, Copy, Debug)]
struct Affine {
    m: [[f64; 3]; 3],
    t: Vec3,
}

impl Affine {
    fn scale(s: f64) -> Affine {
        Affine {
            m: [[s, 0.0, 0.0], [0.0, s, 0.0], [0.0, 0.0, s]],
            t: Vec3::zeros(),
        }
    }
    fn vector(&self, d: Vec3) -> Vec3 {
        Vec3::new(
            self.m[0][0] * d.x + self.m[0][1] * d.y + self.m[0][2] * d.z,
            self.m[1][0] * d.x + self.m[1][1] * d.y + self.m[1][2] * d.z,
            self.m[2][0] * d.x + self.m[2][1] * d.y + self.m[2][2] * d.z,
        )
    }
    fn point(&self, p: Vec3) -> Vec3 {
        self.vector(p) + self.t
    }
    /// `self ∘ inner`.
    fn after(&self, inner: &Affine) -> Affine {
        let mut m = [[0.0; 3]; 3];
        for (i, row) in m.iter_mut().enumerate() {
            for (j, x) in row.iter_mut().enumerate() {
                *x = (0..3).map(|k| self.m[i][k] * inner.m[k][j]).sum();
            }
        }
        Affine {
            m,
            t: self.point(inner.t),
        }
    }
    /// The factor `s` when the map is a rotation (or reflection) times `s`.
    fn similarity(&self) -> Option<f64> {
        let col = |j: usize| Vec3::new(self.m[0][j], self.m[1][j], self.m[2][j]);
        let (a, b, c) = (col(0), col(1), col(2));
        let s = a.norm();
        let ok = |x: f64, y: f64| (x - y).abs() <= 1e-9 * s * s;
        (s > 0.0
            && ok(b.norm_squared(), s * s)
            && ok(c.norm_squared(), s * s)
            && ok(a.dot(&b), 0.0)
            && ok(a.dot(&c), 0.0)
            && ok(b.dot(&c), 0.0))
        .then_some(s)
    }
}

/// A piece of an edge: one curve entity's geometry in model space, in its own direction.
struct Piece {
    kind: CurveKind,
    range: Option<[f64; 2]>,
    p0: Vec3,
    p1: Vec3,
    /// A point at the middle of the parameter interval (degenerate pieces, direction of closed
    /// ones).
    mid: Vec3,
}

/// One use of a piece by a face: true when the face runs it in its own direction.
struct Use {
    piece: usize,
    forward: bool,
}

struct RawFace<'a> {
    entity: &'a Entity,
    kind: String,
    surface: FaceSurface,
    uses: Vec<Use>,
}

struct Reader<'a> {
    file: &'a IgesFile,
    /// The Global section's model scale: model units → the file's unit.
    unit: Affine,
    pieces: Vec<Piece>,
}

impl<'a> Reader<'a> {
    fn entity(&self, de: usize) -> &'a Entity {
        // Pointers are checked against the file when read (`Entity::pointer`).
        self.file.get(de).expect("a checked pointer")
    }

    /// Follows parameter `k` of `e` to an entity of one of `kinds`.
    fn follow(&self, e: &Entity, k: usize, what: &str, kinds: &[i64]) -> Result<&'a Entity> {
        let de = e.pointer(self.file, k, what, false)?;
        let t = self.entity(de);
        if !kinds.contains(&t.kind) {
            return Err(e.bad(&format!(
                "parameter {k} ({what}) points at D {de}, an entity {}, not {}",
                t.kind,
                kinds
                    .iter()
                    .map(|k| k.to_string())
                    .collect::<Vec<_>>()
                    .join(" or ")
            )));
        }
        Ok(t)
    }

    /// The map from `e`'s definition space to model space (its chain of 124 entities) after
    /// `outer` (the transformation of the entity that holds it).
    fn placed(&self, e: &Entity, outer: &Affine) -> Result<Affine> {
        let mut chain = Vec::new();
        let mut de = e.transform;
        while de != 0 {
            if chain.len() > MAX_DEPTH {
                return Err(e.bad("its transformation matrices point at each other"));
            }
            let t = self.entity(de);
            let r = |k| t.real(k, "matrix element");
            chain.push(Affine {
                m: [
                    [r(1)?, r(2)?, r(3)?],
                    [r(5)?, r(6)?, r(7)?],
                    [r(9)?, r(10)?, r(11)?],
                ],
                t: Vec3::new(r(4)?, r(8)?, r(12)?),
            });
            de = t.transform;
        }
        // x_model = outer(T_last(…(T_first(x))))
        let mut a = *outer;
        for t in chain.iter().rev() {
            a = a.after(t);
        }
        Ok(a)
    }

    fn xyz(e: &Entity, k: usize, what: &str) -> Result<Vec3> {
        Ok(Vec3::new(
            e.real(k, what)?,
            e.real(k + 1, what)?,
            e.real(k + 2, what)?,
        ))
    }

    /// Entity 116 (a point) in model space.
    fn point_entity(&self, e: &Entity, k: usize, what: &str, outer: &Affine) -> Result<Vec3> {
        let p = self.follow(e, k, what, &[116])?;
        Ok(self.placed(p, outer)?.point(Self::xyz(p, 1, "coordinate")?))
    }

    /// Entity 123 (a direction) in model space, of unit length.
    fn direction_entity(&self, e: &Entity, k: usize, what: &str, outer: &Affine) -> Result<Vec3> {
        let d = self.follow(e, k, what, &[123])?;
        let v = self.placed(d, outer)?.vector(Self::xyz(d, 1, "component")?);
        let l = v.norm();
        if !(l.is_finite() && l > 0.0) {
            return Err(d.bad("a direction of zero length"));
        }
        Ok(v / l)
    }

    /// The surface of a face: its kind for reports and what the design makes of it.
    fn surface(&self, e: &Entity, outer: &Affine) -> Result<(String, FaceSurface)> {
        let a = self.placed(e, outer)?;
        let name = |what: &str| format!("{} ({what})", e.kind);
        let analytic = |what: &str, s: Analytic| Ok((name(what), FaceSurface::Analytic(s, true)));
        let similar = || {
            a.similarity().ok_or_else(|| {
                e.bad("its transformation is not a rotation and uniform scale, so the surface would not stay analytic")
            })
        };
        let positive = |k: usize, what: &str| -> Result<f64> {
            let x = e.real(k, what)?;
            if x > 0.0 {
                Ok(x)
            } else {
                Err(e.bad(&format!("the {what} must be positive, not {x}")))
            }
        };
        let frame = |o: Vec3, z: Vec3, hint: Option<Vec3>| -> Result<Frame> {
            let hint = hint.unwrap_or(if z.x.abs() < 0.9 {
                Vec3::x()
            } else {
                Vec3::y()
            });
            let x = hint - z * hint.dot(&z);
            if x.norm() < 1e-12 {
                return Err(e.bad("the reference direction is parallel to the axis"));
            }
            let x = x.normalize();
            Ok(Frame {
                o,
                x,
                y: z.cross(&x),
                z,
            })
        };
        let opt_dir = |k: usize, what: &str| -> Result<Option<Vec3>> {
            if e.form == 1 {
                Ok(Some(self.direction_entity(e, k, what, &a)?))
            } else {
                Ok(None)
            }
        };
        match e.kind {
            128 => {
                let net = self.nurbs(e, &a)?;
                let what = if net.weights.is_some() {
                    "rational B-spline surface"
                } else {
                    "B-spline surface"
                };
                Ok((name(what), FaceSurface::Nurbs(net)))
            }
            108 => {
                let nrm = Self::xyz(e, 1, "plane coefficient")?;
                let d = e.real(4, "plane coefficient")?;
                let l2 = nrm.norm_squared();
                if !(l2 > 0.0 && l2.is_finite()) {
                    return Err(e.bad("a plane with a zero normal (A, B, C)"));
                }
                let o = a.point(nrm * (d / l2));
                let z = a.vector(nrm);
                similar()?;
                analytic("plane", Analytic::Plane(frame(o, z.normalize(), None)?))
            }
            190 => {
                let o = self.point_entity(e, 1, "location", &a)?;
                let z = self.direction_entity(e, 2, "normal", &a)?;
                let hint = opt_dir(3, "reference direction")?;
                analytic("plane surface", Analytic::Plane(frame(o, z, hint)?))
            }
            192 => {
                let s = similar()?;
                let o = self.point_entity(e, 1, "point on the axis", &a)?;
                let z = self.direction_entity(e, 2, "axis", &a)?;
                let r = positive(3, "radius")? * s;
                let hint = opt_dir(4, "reference direction")?;
                analytic("cylinder", Analytic::Cylinder(frame(o, z, hint)?, r))
            }
            194 => {
                let s = similar()?;
                let o = self.point_entity(e, 1, "point on the axis", &a)?;
                let z = self.direction_entity(e, 2, "axis", &a)?;
                let r = e.real(3, "radius")?;
                let semi = e.real(4, "semi-angle")?;
                if !(r >= 0.0 && semi > 0.0 && semi < 90.0) {
                    return Err(e.bad(&format!(
                        "a cone of radius {r} and semi-angle {semi}° (0 to 90° open)"
                    )));
                }
                let hint = opt_dir(5, "reference direction")?;
                analytic(
                    "cone",
                    Analytic::Cone(frame(o, z, hint)?, r * s, semi.to_radians()),
                )
            }
            196 => {
                let s = similar()?;
                let o = self.point_entity(e, 1, "centre", &a)?;
                let r = positive(2, "radius")? * s;
                let (z, hint) = if e.form == 1 {
                    (
                        self.direction_entity(e, 3, "axis", &a)?,
                        Some(self.direction_entity(e, 4, "reference direction", &a)?),
                    )
                } else {
                    (a.vector(Vec3::z()).normalize(), None)
                };
                analytic("sphere", Analytic::Sphere(frame(o, z, hint)?, r))
            }
            198 => {
                let s = similar()?;
                let o = self.point_entity(e, 1, "centre", &a)?;
                let z = self.direction_entity(e, 2, "axis", &a)?;
                let major = positive(3, "major radius")? * s;
                let minor = positive(4, "minor radius")? * s;
                let hint = opt_dir(5, "reference direction")?;
                analytic("torus", Analytic::Torus(frame(o, z, hint)?, major, minor))
            }
            120 => match self.revolution(e, &a)? {
                Some((what, s)) => analytic(&format!("surface of revolution: {what}"), s),
                None => Ok((name("surface of revolution"), FaceSurface::Skipped)),
            },
            122 => Ok((name("tabulated cylinder"), FaceSurface::Skipped)),
            140 => Ok((name("offset surface"), FaceSurface::Skipped)),
            118 => Ok((name("ruled surface"), FaceSurface::Skipped)),
            k => Ok((format!("{k}"), FaceSurface::Skipped)),
        }
    }

    /// Entity 120 as the analytic surface it is when its generatrix is a line (a cylinder,
    /// cone or plane) or a circular arc (a sphere or torus) in a plane through the axis; `None`
    /// for other generatrices (the face is then skipped).
    fn revolution(&self, e: &Entity, a: &Affine) -> Result<Option<(&'static str, Analytic)>> {
        let axis = self.follow(e, 1, "axis", &[110])?;
        let ax = self.placed(axis, a)?;
        let o = ax.point(Self::xyz(axis, 1, "start point")?);
        let z = ax.point(Self::xyz(axis, 4, "end point")?) - o;
        if z.norm().is_nan() || z.norm() <= 0.0 {
            return Err(axis.bad("an axis of zero length"));
        }
        let z = z.normalize();
        let g = e.pointer(self.file, 2, "generatrix", false)?;
        let g = self.entity(g);
        let ag = self.placed(g, a)?;
        // Axial and radial coordinates of a point, and the frame at axial height `h`.
        let coords = |p: Vec3| {
            let h = (p - o).dot(&z);
            (h, (p - o - z * h).norm())
        };
        let frame = |h: f64| {
            let hint = if z.x.abs() < 0.9 {
                Vec3::x()
            } else {
                Vec3::y()
            };
            let x = (hint - z * hint.dot(&z)).normalize();
            Frame {
                o: o + z * h,
                x,
                y: z.cross(&x),
                z,
            }
        };
        let size = |p: Vec3| 1e-12 * (1.0 + (p - o).norm());
        match g.kind {
            110 => {
                let p = ag.point(Self::xyz(g, 1, "start point")?);
                let q = ag.point(Self::xyz(g, 4, "end point")?);
                // In a plane through the axis.
                if (q - p).cross(&z).dot(&(p - o)).abs() > size(p) * (q - p).norm() {
                    return Ok(None);
                }
                let ((h0, r0), (h1, r1)) = (coords(p), coords(q));
                let tol = size(p).max(size(q));
                Ok(Some(if (h1 - h0).abs() <= tol {
                    ("plane", Analytic::Plane(frame(h0)))
                } else if (r1 - r0).abs() <= tol {
                    ("cylinder", Analytic::Cylinder(frame(h0), r0))
                } else {
                    let semi = ((r1 - r0) / (h1 - h0)).atan();
                    ("cone", Analytic::Cone(frame(h0), r0, semi))
                }))
            }
            100 => {
                let zt = g.real(1, "plane offset")?;
                let c = ag.point(Vec3::new(g.real(2, "centre")?, g.real(3, "centre")?, zt));
                let s = ag.point(Vec3::new(g.real(4, "start")?, g.real(5, "start")?, zt));
                let normal = ag.vector(Vec3::z());
                // The arc's plane holds the axis.
                if normal.dot(&z).abs() > 1e-12 * normal.norm()
                    || normal.dot(&(c - o)).abs() > size(c) * normal.norm()
                {
                    return Ok(None);
                }
                let r = (s - c).norm();
                let (h, major) = coords(c);
                Ok(Some(if major <= size(c) {
                    ("sphere", Analytic::Sphere(frame(h), r))
                } else {
                    ("torus", Analytic::Torus(frame(h), major, r))
                }))
            }
            _ => Ok(None),
        }
    }

    /// Entity 128 as a `[[nurbs]]` table (its name set by the kernel).
    fn nurbs(&self, e: &Entity, a: &Affine) -> Result<NurbsSpec> {
        let k1 = e.int(1, "upper index in u", 1, e.params.len() as i64)? as usize;
        let k2 = e.int(2, "upper index in v", 1, e.params.len() as i64)? as usize;
        let m1 = e.int(3, "degree in u", 1, 30)? as usize;
        let m2 = e.int(4, "degree in v", 1, 30)? as usize;
        let (nu, nv) = (k1 + 1, k2 + 1);
        // Knots, weights and points must all be parameters of the entity (checked before
        // anything is allocated from the counts).
        let needed = (nu + m1 + 1)
            + (nv + m2 + 1)
            + nu.checked_mul(nv)
                .map_or(usize::MAX, |c| c.saturating_mul(4));
        if 9 + needed > e.params.len() {
            return Err(e.bad(&format!(
                "{nu} × {nv} control points of degree {m1} × {m2} need {} parameters, the \
                 entity has {}",
                9 + needed,
                e.params.len()
            )));
        }
        let mut reals = e.reals_from(10);
        let knots_u = reals.take(nu + m1 + 1, "knot in u")?;
        let knots_v = reals.take(nv + m2 + 1, "knot in v")?;
        let w = reals.take(nu * nv, "weight")?;
        let pts = reals.take(3 * nu * nv, "control point")?;
        // The first index (u) varies fastest in the file.
        let control = (0..nu)
            .map(|i| {
                (0..nv)
                    .map(|j| {
                        let k = 3 * (j * nu + i);
                        let p = a.point(Vec3::new(pts[k], pts[k + 1], pts[k + 2]));
                        [p.x, p.y, p.z]
                    })
                    .collect()
            })
            .collect();
        let rational = w.iter().any(|x| *x != w[0]);
        let weights = rational.then(|| {
            (0..nu)
                .map(|i| (0..nv).map(|j| w[j * nu + i]).collect())
                .collect()
        });
        let net = NurbsSpec {
            name: String::new(),
            degree: [m1, m2],
            knots_u,
            knots_v,
            control,
            weights,
        };
        crate::design::NurbsSurface::from_spec(&net, "").map_err(|err| {
            let at = err.place().trim_start_matches('.');
            let at = if at.is_empty() {
                String::new()
            } else {
                format!("{at}: ")
            };
            e.bad(&format!("{at}{}", err.message()))
        })?;
        Ok(net)
    }

    /// The pieces of a curve entity in model space, in its direction (a composite curve gives
    /// its constituents in order); pieces of no length are left out.
    fn curve(&mut self, e: &'a Entity, outer: &Affine, depth: usize) -> Result<Vec<usize>> {
        if depth > MAX_DEPTH {
            return Err(e.bad("composite curves nested too deep (or in a cycle)"));
        }
        let a = self.placed(e, outer)?;
        let piece = match e.kind {
            102 => {
                let count = e.count(1, "number of curves", 1)?;
                let mut out = Vec::new();
                for k in 0..count {
                    let c =
                        self.follow(e, 2 + k, "constituent curve", &[100, 102, 104, 110, 126])?;
                    out.extend(self.curve(c, &a, depth + 1)?);
                }
                return Ok(out);
            }
            110 => {
                let p = a.point(Self::xyz(e, 1, "start point")?);
                let q = a.point(Self::xyz(e, 4, "end point")?);
                let l = (q - p).norm();
                if l == 0.0 {
                    return Ok(Vec::new());
                }
                let d = (q - p) / l;
                let [x, y, z] = combo(p, &[("v", d)]);
                Piece {
                    kind: CurveKind::Formula {
                        x,
                        y,
                        z,
                        domain: DomainSpec::Interval([0.0, l]),
                    },
                    range: None,
                    p0: p,
                    p1: q,
                    mid: (p + q) / 2.0,
                }
            }
            100 => {
                let zt = e.real(1, "plane offset")?;
                let c = Vec3::new(e.real(2, "centre")?, e.real(3, "centre")?, zt);
                let s = Vec3::new(e.real(4, "start")?, e.real(5, "start")?, zt);
                let t = Vec3::new(e.real(6, "end")?, e.real(7, "end")?, zt);
                let r = (s - c).norm();
                if r.is_nan() || r <= 0.0 {
                    return Err(e.bad("a circular arc of zero radius"));
                }
                let angle = |p: Vec3| (p.y - c.y).atan2(p.x - c.x);
                let t0 = angle(s);
                let mut t1 = angle(t);
                while t1 <= t0 + 1e-12 {
                    t1 += 2.0 * PI;
                }
                self.conic(&a, c, r, r, t0, t1)
            }
            104 => {
                let q = |k: usize, what: &str| e.real(k, what);
                let (ca, cb, cc) = (q(1, "A")?, q(2, "B")?, q(3, "C")?);
                let (cd, ce, cf) = (q(4, "D")?, q(5, "E")?, q(6, "F")?);
                let zt = q(7, "plane offset")?;
                let (ra, rb) = ((-cf / ca).sqrt(), (-cf / cc).sqrt());
                if e.form != 1 || cb != 0.0 || cd != 0.0 || ce != 0.0 || !(ra > 0.0 && rb > 0.0) {
                    return Err(e.bad(
                        "a conic other than an ellipse in standard position (form 1, \
                         B = D = E = 0): not read",
                    ));
                }
                let angle = |x: f64, y: f64| (y / rb).atan2(x / ra);
                let t0 = angle(q(8, "start")?, q(9, "start")?);
                let mut t1 = angle(q(10, "end")?, q(11, "end")?);
                while t1 <= t0 + 1e-12 {
                    t1 += 2.0 * PI;
                }
                self.conic(&a, Vec3::new(0.0, 0.0, zt), ra, rb, t0, t1)
            }
            126 => self.bspline_curve(e, &a)?,
            k => {
                return Err(e.bad(&format!(
                    "a curve entity {k}: not read (110, 100, 104, 126 and 102 are)"
                )))
            }
        };
        self.pieces.push(piece);
        Ok(vec![self.pieces.len() - 1])
    }

    /// `c + ra cos t x + rb sin t y` over `[t0, t1]` in definition space, mapped by `a`.
    fn conic(&self, a: &Affine, c: Vec3, ra: f64, rb: f64, t0: f64, t1: f64) -> Piece {
        let o = a.point(c);
        let (x, y) = (a.vector(Vec3::x()), a.vector(Vec3::y()));
        let at = |t: f64| o + x * (ra * t.cos()) + y * (rb * t.sin());
        let [fx, fy, fz] = combo(
            o,
            &[
                (&format!("{}*cos(v)", n(ra)), x),
                (&format!("{}*sin(v)", n(rb)), y),
            ],
        );
        Piece {
            kind: CurveKind::Formula {
                x: fx,
                y: fy,
                z: fz,
                domain: DomainSpec::Interval([t0, t1]),
            },
            range: None,
            p0: at(t0),
            p1: at(t1),
            mid: at((t0 + t1) / 2.0),
        }
    }

    /// Entity 126 as the design's B-spline curve over its parameter range `[V(0), V(1)]`.
    fn bspline_curve(&self, e: &Entity, a: &Affine) -> Result<Piece> {
        let k = e.int(1, "upper index", 1, e.params.len() as i64)? as usize;
        let m = e.int(2, "degree", 1, 30)? as usize;
        let count = k + 1;
        // knots, weights, points, V(0), V(1) after the six leading parameters.
        if 6 + (count + m + 1) + 4 * count + 2 > e.params.len() {
            return Err(e.bad(&format!(
                "{count} control points of degree {m} need {} parameters, the entity has {}",
                6 + (count + m + 1) + 4 * count + 2,
                e.params.len()
            )));
        }
        let mut reals = e.reals_from(7);
        let knots = reals.take(count + m + 1, "knot")?;
        let w = reals.take(count, "weight")?;
        let pts = reals.take(3 * count, "control point")?;
        let v = reals.take(2, "parameter range")?;
        let control = (0..count)
            .map(|i| {
                let p = a.point(Vec3::new(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]));
                [p.x, p.y, p.z]
            })
            .collect();
        let weights = w.iter().any(|x| *x != w[0]).then_some(w);
        let kind = CurveKind::BSpline {
            degree: m,
            control,
            knots: Some(knots.clone()),
            periodic: false,
            weights,
        };
        let curve = build_curve(&kind).map_err(|err| e.bad(&err.to_string()))?;
        let (lo, hi) = (knots[m], knots[knots.len() - m - 1]);
        let (v0, v1) = (v[0].max(lo), v[1].min(hi));
        if v1.is_nan() || v0.is_nan() || v1 <= v0 {
            return Err(e.bad(&format!(
                "the parameter range [{}, {}] is not inside the knots' [{lo}, {hi}]",
                v[0], v[1]
            )));
        }
        Ok(Piece {
            kind,
            range: Some([v0, v1]),
            p0: curve.point(v0),
            p1: curve.point(v1),
            mid: curve.point((v0 + v1) / 2.0),
        })
    }
}

/// The B-rep of an IGES file.
pub(super) fn read(text: &str) -> Result<Brep> {
    let file = iges_read::parse(text)?;
    let mut r = Reader {
        file: &file,
        unit: Affine::scale(1.0 / file.scale),
        pieces: Vec::new(),
    };
    let unit = r.unit;
    let mut faces: Vec<RawFace> = Vec::new();
    let shells: Vec<&Entity> = file.entities.iter().filter(|e| e.kind == 514).collect();
    if shells.is_empty() {
        // Trimmed surfaces: each boundary's model-space curve, in the boundary's direction.
        for e in file.entities.iter().filter(|e| e.kind == 144) {
            let a = r.placed(e, &unit)?;
            let s = r.follow(e, 1, "surface", &SURFACES)?;
            let (kind, surface) = r.surface(s, &a)?;
            let inner = e.count(3, "number of inner boundaries", 1)?;
            let mut boundaries = Vec::new();
            if e.int(2, "outer boundary flag", 0, 1)? == 1 {
                boundaries.push(r.follow(e, 4, "outer boundary", &[142])?);
            }
            for k in 0..inner {
                boundaries.push(r.follow(e, 5 + k, "inner boundary", &[142])?);
            }
            let mut uses = Vec::new();
            for b in boundaries {
                let ab = r.placed(b, &a)?;
                let c = b.pointer(&file, 4, "model-space curve", true)?;
                if c == 0 {
                    return Err(b.bad(
                        "a boundary without its model-space curve (only its curve in the \
                         surface's parameters): not read",
                    ));
                }
                let curve = r.follow(b, 4, "model-space curve", &CURVES)?;
                let pieces = r.curve(curve, &ab, 0)?;
                uses.extend(pieces.into_iter().map(|piece| Use {
                    piece,
                    forward: true,
                }));
            }
            faces.push(RawFace {
                entity: e,
                kind,
                surface,
                uses,
            });
        }
        // Untrimmed B-spline surfaces standing alone: faces without edges.
        for e in file
            .entities
            .iter()
            .filter(|e| e.kind == 128 && e.subordinate == 0)
        {
            let (kind, surface) = r.surface(e, &unit)?;
            faces.push(RawFace {
                entity: e,
                kind,
                surface,
                uses: Vec::new(),
            });
        }
    } else {
        let mut seen = std::collections::HashSet::new();
        for shell in shells {
            let count = shell.count(1, "number of faces", 2)?;
            for k in 0..count {
                let face = r.follow(shell, 2 + 2 * k, "face", &[510])?;
                let same = shell.int(3 + 2 * k, "face orientation", 0, 1)? == 1;
                if seen.insert(face.de) {
                    faces.push(brep_face(&mut r, face, same, &unit)?);
                }
            }
        }
    }
    edges(faces, &r.pieces, file.units)
}

/// Surfaces a face may lie on (those not read are listed as skipped).
const SURFACES: [i64; 13] = [
    108, 114, 118, 120, 122, 128, 140, 143, 190, 192, 194, 196, 198,
];

/// Curves a boundary or an edge may be.
const CURVES: [i64; 5] = [100, 102, 104, 110, 126];

/// A face of a B-rep (entity 510) with its loops (508) of edges (504) and the shell's
/// orientation of it.
fn brep_face<'a>(
    r: &mut Reader<'a>,
    face: &'a Entity,
    same: bool,
    unit: &Affine,
) -> Result<RawFace<'a>> {
    let a = r.placed(face, unit)?;
    let s = r.follow(face, 1, "surface", &SURFACES)?;
    let (kind, mut surface) = r.surface(s, &a)?;
    if let FaceSurface::Analytic(_, sense) = &mut surface {
        *sense = same;
    }
    let loops = face.count(2, "number of loops", 1)?;
    let mut uses = Vec::new();
    for k in 0..loops {
        let lp = r.follow(face, 4 + k, "loop", &[508])?;
        let al = r.placed(lp, &a)?;
        let n_edges = lp.count(1, "number of edges", 5)?;
        let mut at = 2;
        for _ in 0..n_edges {
            let vertex = lp.int(at, "edge type", 0, 1)? == 1;
            let list = r.follow(lp, at + 1, "edge list", &[502, 504])?;
            let index = lp.int(at + 2, "index in the edge list", 1, i64::MAX)? as usize;
            let forward = lp.int(at + 3, "edge orientation", 0, 1)? == 1;
            let pcurves = lp.count(at + 4, "number of parameter-space curves", 2)?;
            at += 5 + 2 * pcurves;
            if vertex {
                continue; // a loop of one vertex (a pole): no edge
            }
            if list.kind != 504 {
                return Err(lp.bad("an edge that points at a vertex list"));
            }
            let count = list.count(1, "number of edges", 5)?;
            if index > count {
                return Err(lp.bad(&format!(
                    "edge {index} of the edge list D {}, which has {count}",
                    list.de
                )));
            }
            let base = 2 + 5 * (index - 1);
            let curve = r.follow(list, base, "curve", &CURVES)?;
            let ae = r.placed(list, &al)?;
            let pieces = r.curve(curve, &ae, 0)?;
            // The edge's direction is its curve's; a loop that runs it backwards runs its
            // pieces in reverse order.
            let mut run: Vec<Use> = pieces
                .into_iter()
                .map(|piece| Use { piece, forward })
                .collect();
            if !forward {
                run.reverse();
            }
            uses.extend(run);
        }
    }
    Ok(RawFace {
        entity: face,
        kind,
        surface,
        uses,
    })
}

/// One vertex per cluster of points closer than `tol` (a grid of cells of size `tol`).
struct Vertices {
    tol: f64,
    cells: HashMap<[i64; 3], Vec<usize>>,
    points: Vec<Vec3>,
}

impl Vertices {
    fn id(&mut self, p: Vec3) -> usize {
        let cell = |p: Vec3| [p.x, p.y, p.z].map(|x| (x / self.tol).floor() as i64);
        let c = cell(p);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let key = [c[0] + dx, c[1] + dy, c[2] + dz];
                    if let Some(ids) = self.cells.get(&key) {
                        for &v in ids {
                            if (self.points[v] - p).norm() <= self.tol {
                                return v;
                            }
                        }
                    }
                }
            }
        }
        self.points.push(p);
        self.cells.entry(c).or_default().push(self.points.len() - 1);
        self.points.len() - 1
    }
}

/// The distance from points inside `a` to the curve of `b` (closest points).
fn off_curve(a: &Piece, b: &Piece) -> Result<f64> {
    let (ca, cb) = (build_curve(&a.kind)?, build_curve(&b.kind)?);
    let span = |p: &Piece, c: &dyn Curve| match (p.range, c.domain()) {
        (Some([lo, hi]), _) => [lo, hi],
        (None, Domain::Interval(lo, hi)) => [lo, hi],
        (None, _) => [0.0, 2.0 * PI],
    };
    let [a0, a1] = span(a, &*ca);
    let [b0, b1] = span(b, &*cb);
    let mut worst: f64 = 0.0;
    for k in 1..4 {
        let p = ca.point(a0 + (a1 - a0) * k as f64 / 4.0);
        let t = closest_parameter(&*cb, b0, b1, p);
        worst = worst.max((cb.point(t) - p).norm());
    }
    Ok(worst)
}

/// The faces' pieces as edges: end points within the tolerance are one vertex, and pieces
/// with the same two vertices whose interior points lie on each other's curves are one edge
/// (used by both faces).
fn edges(faces: Vec<RawFace>, pieces: &[Piece], units: Option<crate::spec::Units>) -> Result<Brep> {
    let (lo, hi) = pieces.iter().flat_map(|p| [p.p0, p.p1]).fold(
        (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)),
        |(lo, hi), p| (lo.inf(&p), hi.sup(&p)),
    );
    let size = if pieces.is_empty() {
        1.0
    } else {
        (hi - lo).norm().max(f64::MIN_POSITIVE)
    };
    let tol = REL_TOL * size;
    let mut vertices = Vertices {
        tol,
        cells: HashMap::new(),
        points: Vec::new(),
    };
    let ends: Vec<[usize; 2]> = pieces
        .iter()
        .map(|p| [vertices.id(p.p0), vertices.id(p.p1)])
        .collect();
    // A piece whose ends and middle are one point has no length (a pole of a face).
    let degenerate: Vec<bool> = pieces
        .iter()
        .zip(&ends)
        .map(|(p, e)| e[0] == e[1] && (p.mid - p.p0).norm() <= tol)
        .collect();
    let mut out: Vec<Edge> = Vec::new();
    let mut of_piece: Vec<usize> = Vec::new(); // edge index → its piece
    let mut by_ends: HashMap<[usize; 2], Vec<usize>> = HashMap::new();
    let mut brep_faces = Vec::new();
    for face in faces {
        let mut face_edges = Vec::new();
        for u in face.uses.iter().filter(|u| !degenerate[u.piece]) {
            let p = &pieces[u.piece];
            let [s, e] = ends[u.piece];
            let key = [s.min(e), s.max(e)];
            let mut found = None;
            for &k in by_ends.get(&key).map_or(&[][..], Vec::as_slice) {
                let q = &pieces[of_piece[k]];
                let off = off_curve(p, q)
                    .and_then(|x| Ok(x.max(off_curve(q, p)?)))
                    .map_err(|err| face.entity.bad(&err.to_string()))?;
                if off <= tol {
                    // The same direction as the edge's curve when the starts agree (for a
                    // closed curve, when the middles do).
                    let same = if s != e {
                        s == out[k].start
                    } else {
                        (p.mid - q.mid).norm() <= tol
                    };
                    found = Some((k, same));
                    break;
                }
            }
            let (k, same) = match found {
                Some(f) => f,
                None => {
                    out.push(Edge {
                        kind: p.kind.clone(),
                        range: p.range,
                        start: s,
                        end: e,
                    });
                    of_piece.push(u.piece);
                    by_ends.entry(key).or_default().push(out.len() - 1);
                    (out.len() - 1, true)
                }
            };
            face_edges.push((k, u.forward == same));
        }
        brep_faces.push(Face {
            kind: face.kind,
            place: format!("D {}", face.entity.de),
            label: format!("P {}: entity {}", face.entity.p, face.entity.kind),
            surface: face.surface,
            edges: face_edges,
        });
    }
    Ok(Brep {
        units,
        edges: out,
        faces: brep_faces,
    })
}
