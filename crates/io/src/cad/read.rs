//! Reading back the B-spline surfaces of the STEP and IGES files pdeshape writes, and the
//! deviation of what was read from the design's own surfaces (the round trip).
//!
//! The STEP reader parses every entity instance of the `DATA` section (ISO 10303-21 syntax:
//! numbers, strings, enumerations, references, lists, typed values; complex instances are
//! skipped) and builds each `B_SPLINE_SURFACE_WITH_KNOTS` from its `CARTESIAN_POINT`s. The IGES
//! reader takes every entity 128 of the parameter data section. Errors name the line.

use crate::spline::BSplineSurface;
use crate::surface::{Surface, VDomain};
use crate::{Error, Result, Vec3, TAU};
use std::collections::HashMap;

/// A surface read from a file: its name (STEP: the surface's name; IGES: `surface k`) and net.
#[derive(Clone, Debug)]
pub struct ReadSurface {
    /// STEP: the surface entity's name; IGES: `surface k`, counted from 1.
    pub name: String,
    /// The B-spline net as the file gives it.
    pub net: BSplineSurface,
}

#[derive(Clone, Debug, PartialEq)]
pub(super) enum Value {
    Num(f64),
    Str(String),
    Ref(usize),
    Enum(String),
    List(Vec<Value>),
    Typed(String, Vec<Value>),
    Unset,
}

pub(super) struct Parser<'a> {
    pub(super) s: &'a [u8],
    pub(super) i: usize,
}

impl Parser<'_> {
    fn ws(&mut self) {
        while self.i < self.s.len() && self.s[self.i].is_ascii_whitespace() {
            self.i += 1;
        }
    }
    fn err(&self, what: &str) -> String {
        format!("{what} at column {}", self.i + 1)
    }
    fn list(&mut self) -> std::result::Result<Vec<Value>, String> {
        self.ws();
        if self.s.get(self.i) != Some(&b'(') {
            return Err(self.err("expected `(`"));
        }
        self.i += 1;
        let mut out = Vec::new();
        loop {
            self.ws();
            if self.s.get(self.i) == Some(&b')') {
                self.i += 1;
                return Ok(out);
            }
            out.push(self.value()?);
            self.ws();
            match self.s.get(self.i) {
                Some(b',') => self.i += 1,
                Some(b')') => {}
                _ => return Err(self.err("expected `,` or `)`")),
            }
        }
    }
    pub(super) fn value(&mut self) -> std::result::Result<Value, String> {
        self.ws();
        let Some(&c) = self.s.get(self.i) else {
            return Err(self.err("unexpected end"));
        };
        match c {
            b'(' => Ok(Value::List(self.list()?)),
            b'$' | b'*' => {
                self.i += 1;
                Ok(Value::Unset)
            }
            b'#' => {
                self.i += 1;
                let start = self.i;
                while self.i < self.s.len() && self.s[self.i].is_ascii_digit() {
                    self.i += 1;
                }
                std::str::from_utf8(&self.s[start..self.i])
                    .ok()
                    .and_then(|t| t.parse().ok())
                    .map(Value::Ref)
                    .ok_or_else(|| self.err("bad reference"))
            }
            b'\'' => {
                self.i += 1;
                let mut out = String::new();
                loop {
                    match self.s.get(self.i) {
                        None => return Err(self.err("unterminated string")),
                        Some(b'\'') if self.s.get(self.i + 1) == Some(&b'\'') => {
                            out.push('\'');
                            self.i += 2;
                        }
                        Some(b'\'') => {
                            self.i += 1;
                            return Ok(Value::Str(out));
                        }
                        Some(&b) => {
                            out.push(b as char);
                            self.i += 1;
                        }
                    }
                }
            }
            b'.' => {
                self.i += 1;
                let start = self.i;
                while self.i < self.s.len() && self.s[self.i] != b'.' {
                    self.i += 1;
                }
                let t = String::from_utf8_lossy(&self.s[start..self.i]).into_owned();
                self.i += 1;
                Ok(Value::Enum(t))
            }
            b'-' | b'+' | b'0'..=b'9' => {
                let start = self.i;
                while self.i < self.s.len()
                    && matches!(
                        self.s[self.i],
                        b'0'..=b'9' | b'.' | b'e' | b'E' | b'-' | b'+'
                    )
                {
                    self.i += 1;
                }
                std::str::from_utf8(&self.s[start..self.i])
                    .ok()
                    .and_then(|t| t.parse().ok())
                    .map(Value::Num)
                    .ok_or_else(|| self.err("bad number"))
            }
            c if c.is_ascii_alphabetic() => {
                let start = self.i;
                while self.i < self.s.len()
                    && (self.s[self.i].is_ascii_alphanumeric() || self.s[self.i] == b'_')
                {
                    self.i += 1;
                }
                let name = String::from_utf8_lossy(&self.s[start..self.i]).into_owned();
                Ok(Value::Typed(name, self.list()?))
            }
            _ => Err(self.err("unexpected character")),
        }
    }
}

/// The id and the body of an instance `#n = body`.
pub(super) fn instance_parts(line: usize, inst: &str) -> Result<(usize, &str)> {
    let at = |m: &str| Error::invalid(format!("line {line}: {m}"));
    let Some(eq) = inst.find('=') else {
        return Err(at("an instance without `=`"));
    };
    let id: usize = inst[..eq]
        .trim()
        .trim_start_matches('#')
        .parse()
        .map_err(|_| at("a bad instance name"))?;
    Ok((id, inst[eq + 1..].trim()))
}

/// Splits the DATA section into `(line, text)` of each instance `#n=...;`.
pub(super) fn instances(text: &str) -> Result<Vec<(usize, String)>> {
    let start = text
        .find("DATA;")
        .ok_or_else(|| Error::invalid("not a STEP file: no DATA section"))?;
    let mut out = Vec::new();
    let mut line = text[..start].matches('\n').count() + 1;
    let mut cur = String::new();
    let mut cur_line = line;
    let mut in_str = false;
    for c in text[start + 5..].chars() {
        if c == '\n' {
            line += 1;
        }
        if cur.trim().is_empty() {
            cur_line = line;
        }
        if c == '\'' {
            in_str = !in_str;
        }
        if c == ';' && !in_str {
            let t = std::mem::take(&mut cur);
            let t = t.trim();
            if t == "ENDSEC" {
                return Ok(out);
            }
            out.push((cur_line, t.to_string()));
            continue;
        }
        cur.push(c);
    }
    Err(Error::invalid("STEP file ends inside the DATA section"))
}

/// Every `B_SPLINE_SURFACE_WITH_KNOTS` of a STEP file, in file order.
pub fn read_step(text: &str) -> Result<Vec<ReadSurface>> {
    let mut points: HashMap<usize, Vec3> = HashMap::new();
    let mut surfaces: Vec<(usize, Vec<Value>)> = Vec::new();
    for (line, inst) in instances(text)? {
        let at = |m: String| Error::invalid(format!("line {line}: {m}"));
        let (id, body) = instance_parts(line, &inst)?;
        if body.starts_with('(') {
            continue; // complex instance (units, contexts)
        }
        let mut p = Parser {
            s: body.as_bytes(),
            i: 0,
        };
        let v = p.value().map_err(at)?;
        let Value::Typed(name, args) = v else {
            return Err(at("expected an entity".into()));
        };
        match name.as_str() {
            "CARTESIAN_POINT" => {
                let coords = match args.get(1) {
                    Some(Value::List(c)) => c
                        .iter()
                        .map(|x| match x {
                            Value::Num(x) => Ok(*x),
                            _ => Err(at("a coordinate that is not a number".into())),
                        })
                        .collect::<Result<Vec<f64>>>()?,
                    _ => return Err(at("CARTESIAN_POINT without coordinates".into())),
                };
                match coords.len() {
                    3 => {
                        points.insert(id, Vec3::new(coords[0], coords[1], coords[2]));
                    }
                    // A point of a curve in a face's parameter space (a hole's pcurve).
                    2 => {}
                    _ => return Err(at("CARTESIAN_POINT is neither 2D nor 3D".into())),
                }
            }
            "B_SPLINE_SURFACE_WITH_KNOTS" => surfaces.push((line, args)),
            _ => {}
        }
    }
    surfaces
        .into_iter()
        .map(|(line, a)| {
            let at =
                |m: &str| Error::invalid(format!("line {line}: B_SPLINE_SURFACE_WITH_KNOTS: {m}"));
            let int = |v: &Value| match v {
                Value::Num(x) if *x >= 0.0 && x.fract() == 0.0 => Ok(*x as usize),
                _ => Err(at("expected a count")),
            };
            let nums = |v: Option<&Value>| -> Result<Vec<f64>> {
                match v {
                    Some(Value::List(l)) => l
                        .iter()
                        .map(|x| match x {
                            Value::Num(x) => Ok(*x),
                            _ => Err(at("expected a number")),
                        })
                        .collect(),
                    _ => Err(at("expected a list of numbers")),
                }
            };
            if a.len() < 13 {
                return Err(at("too few parameters"));
            }
            let name = match &a[0] {
                Value::Str(s) => s.clone(),
                _ => String::new(),
            };
            let (p, q) = (int(&a[1])?, int(&a[2])?);
            let Value::List(rows) = &a[3] else {
                return Err(at("control points are not a list of lists"));
            };
            let mut control = Vec::new();
            let mut nv = None;
            for r in rows {
                let Value::List(r) = r else {
                    return Err(at("a control row is not a list"));
                };
                if *nv.get_or_insert(r.len()) != r.len() {
                    return Err(at("control rows of different lengths"));
                }
                for x in r {
                    match x {
                        Value::Ref(k) => control.push(
                            *points
                                .get(k)
                                .ok_or_else(|| at(&format!("#{k} is not a CARTESIAN_POINT")))?,
                        ),
                        _ => return Err(at("a control point is not a reference")),
                    }
                }
            }
            // The knot vector along a direction of `count` control points and degree `degree`
            // has `count + degree + 1` knots: multiplicities summing to more are refused before
            // the vector is allocated (a multiplicity read from the file sizes it).
            let expand = |mults: Vec<f64>,
                          knots: Vec<f64>,
                          count: usize,
                          degree: usize,
                          dir: &str|
             -> Result<Vec<f64>> {
                if mults.len() != knots.len() {
                    return Err(at("knot multiplicities and knots differ in length"));
                }
                let most = count.saturating_add(degree).saturating_add(1);
                let mut total = 0usize;
                for m in &mults {
                    total = total.saturating_add(int(&Value::Num(*m))?);
                }
                if total > most {
                    return Err(at(&format!(
                        "the {dir} knot multiplicities sum to {total}; {count} control points of \
                         degree {degree} need {most} knots"
                    )));
                }
                let mut out = Vec::with_capacity(total);
                for (m, k) in mults.iter().zip(knots) {
                    out.extend(std::iter::repeat_n(k, int(&Value::Num(*m))?));
                }
                Ok(out)
            };
            let nu = rows.len();
            let nv = nv.unwrap_or(0);
            let ku = expand(nums(a.get(8))?, nums(a.get(10))?, nu, p, "u")?;
            let kv = expand(nums(a.get(9))?, nums(a.get(11))?, nv, q, "v")?;
            let net =
                BSplineSurface::new([p, q], ku, kv, control).map_err(|e| at(&e.to_string()))?;
            Ok(ReadSurface { name, net })
        })
        .collect()
}

/// The deviation of a surface read back from the design's surface: the largest distance on a
/// `k × k` lattice in every knot cell of the net, with the net's parameters taken as the
/// surface's own (as pdeshape writes them).
pub fn read_back_deviation(surface: &dyn Surface, net: &BSplineSurface, k: usize) -> f64 {
    // A trimmed face's net may start its periodic `v` elsewhere (a hole across the seam):
    // compared on the surface's own period.
    if surface.v_domain() == VDomain::Periodic && net.domain()[1][0] != 0.0 {
        if let Ok(back) = super::trimmed::rotate_v(net, 0.0) {
            return super::certify::sampled_deviation(surface, &back, k.max(2));
        }
    }
    super::certify::sampled_deviation(surface, net, k.max(2))
}

/// True if `net`'s parameter domain is the surface's (the pairing is right).
pub fn same_domain(surface: &dyn Surface, net: &BSplineSurface) -> bool {
    let [[u0, u1], [v0, v1]] = net.domain();
    let u = surface.u_range();
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-9 * (1.0 + a.abs().max(b.abs()));
    let v_ok = match surface.v_domain() {
        VDomain::Periodic => close(v1 - v0, TAU),
        VDomain::Interval(a, b) => close(a, v0) && close(b, v1),
    };
    close(u.start, u0) && close(u.end, u1) && v_ok
}

/// Highest degree of an IGES surface read back (pdeshape writes bicubic nets; a degree read from
/// a file sizes the knot vectors).
const MAX_IGES_DEGREE: usize = 64;

/// Every entity 128 of an IGES file written by pdeshape (fixed format), in directory order.
/// Every count read from the file is checked against the parameters the entity has before
/// anything is allocated from it.
pub fn read_iges(text: &str) -> Result<Vec<ReadSurface>> {
    // Parameter data: columns 1–64 text, 65–72 the directory pointer, 73 'P'.
    let mut params: Vec<(usize, usize, String)> = Vec::new(); // (de, first line, text)
    for (k, line) in text.lines().enumerate() {
        let lineno = k + 1;
        if line.len() < 73 {
            continue;
        }
        if line.as_bytes()[72] != b'P' {
            continue;
        }
        let de: usize = line[64..72].trim().parse().map_err(|_| {
            Error::invalid(format!(
                "line {lineno}: a parameter line without its directory pointer"
            ))
        })?;
        match params.last_mut() {
            Some((d, _, t)) if *d == de => t.push_str(&line[..64]),
            _ => params.push((de, lineno, line[..64].to_string())),
        }
    }
    let mut out = Vec::new();
    for (de, lineno, text) in params {
        let at = |m: &str| Error::invalid(format!("line {lineno}: entity at D{de}: {m}"));
        let body = text.trim_end().trim_end_matches(';');
        let fields: Vec<&str> = body.split(',').map(str::trim).collect();
        if fields.first() != Some(&"128") {
            continue;
        }
        let num = |k: usize| -> Result<f64> {
            fields
                .get(k)
                .and_then(|t| t.replace(['D', 'd'], "E").parse::<f64>().ok())
                .ok_or_else(|| at(&format!("parameter {k} is not a number")))
        };
        let int = |k: usize| -> Result<usize> {
            let x = num(k)?;
            if x >= 0.0 && x.fract() == 0.0 {
                Ok(x as usize)
            } else {
                Err(at(&format!("parameter {k} is not a count")))
            }
        };
        let (k1, k2, m1, m2) = (int(1)?, int(2)?, int(3)?, int(4)?);
        // The counts size what is read and allocated below: they must fit in the parameters the
        // entity has (knots, weights and three coordinates per control point after the ten
        // leading ones), checked without overflow before anything is allocated from them.
        let needed = (|| {
            let nu = k1.checked_add(1)?;
            let nv = k2.checked_add(1)?;
            let ku = nu.checked_add(m1)?.checked_add(1)?;
            let kv = nv.checked_add(m2)?.checked_add(1)?;
            let points = nu.checked_mul(nv)?;
            10usize
                .checked_add(ku)?
                .checked_add(kv)?
                .checked_add(points.checked_mul(4)?)
        })();
        match needed {
            Some(n) if n <= fields.len() && m1 <= MAX_IGES_DEGREE && m2 <= MAX_IGES_DEGREE => {}
            _ => {
                return Err(at(&format!(
                    "the counts ({} × {} control points of degree {} × {}) do not fit in the {} parameters of the entity",
                    pdeshape_geometry::check::num(k1 as f64 + 1.0),
                    pdeshape_geometry::check::num(k2 as f64 + 1.0),
                    m1,
                    m2,
                    fields.len()
                )))
            }
        }
        let (nu, nv) = (k1 + 1, k2 + 1);
        let mut pos = 10;
        let mut take = |n: usize| -> Result<Vec<f64>> {
            let v = (pos..pos + n).map(num).collect::<Result<Vec<f64>>>()?;
            pos += n;
            Ok(v)
        };
        let ku = take(nu + m1 + 1)?;
        let kv = take(nv + m2 + 1)?;
        let weights = take(nu * nv)?;
        if weights.iter().any(|w| *w != 1.0) {
            return Err(at("rational surfaces are not read (weights other than 1)"));
        }
        let pts = take(3 * nu * nv)?;
        // s (u) varies fastest in the file; the net is row-major in u.
        let mut control = vec![Vec3::zeros(); nu * nv];
        for j in 0..nv {
            for i in 0..nu {
                let k = 3 * (j * nu + i);
                control[i * nv + j] = Vec3::new(pts[k], pts[k + 1], pts[k + 2]);
            }
        }
        let net = BSplineSurface::new([m1, m2], ku, kv, control).map_err(|e| at(&e.to_string()))?;
        out.push(ReadSurface {
            name: format!("surface {}", out.len() + 1),
            net,
        });
    }
    Ok(out)
}
