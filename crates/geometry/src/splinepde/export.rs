//! Exports of a solved net: JSON (degrees, knots, control points, rank and free points) and
//! IGES 5.3 (one rational B-spline surface, entity 128, all weights 1).

use super::engine::SplineNet;
use super::scalar::Scalar;
use crate::{Error, Result};
use serde_json::{json, Value};

/// The net as JSON: `degree`, `counts`, `knots_u`, `knots_v`, `control` (row-major rows of
/// `[x, y, z]`, `control[i][j]` with `i` along u), the operator, and the solve report. In exact
/// mode `control_exact` and `knots_*_exact` repeat the values as fraction strings `"p/q"`.
pub fn to_json<T: Scalar>(net: &SplineNet<T>) -> Value {
    let (nu, nv) = (net.u.count(), net.v.count());
    let f = |x: &T| x.to_f64();
    let control: Vec<Vec<[f64; 3]>> = (0..nu)
        .map(|i| {
            (0..nv)
                .map(|j| {
                    let p = net.control_point(i, j);
                    [f(&p[0]), f(&p[1]), f(&p[2])]
                })
                .collect()
        })
        .collect();
    let r = &net.report;
    let mut out = json!({
        "degree": [net.u.degree, net.v.degree],
        "counts": [nu, nv],
        "knots_u": net.u.knots.iter().map(f).collect::<Vec<_>>(),
        "knots_v": net.v.knots.iter().map(f).collect::<Vec<_>>(),
        "control": control,
        "operator": net.operator.describe(),
        "exact": T::EXACT,
        "report": {
            "equations": r.equations,
            "pde_rank": r.pde_rank,
            "rank": r.rank,
            "unknowns": r.unknowns,
            "freedom": r.freedom,
            "fixed": r.fixed,
            "determined": r.determined,
            "free": r.free,
            "chosen_by": r.chosen_by,
        },
    });
    if T::EXACT {
        let t = |x: &T| x.to_text();
        let exact: Vec<Vec<[String; 3]>> = (0..nu)
            .map(|i| {
                (0..nv)
                    .map(|j| {
                        let p = net.control_point(i, j);
                        [t(&p[0]), t(&p[1]), t(&p[2])]
                    })
                    .collect()
            })
            .collect();
        out["control_exact"] = json!(exact);
        out["knots_u_exact"] = json!(net.u.knots.iter().map(t).collect::<Vec<_>>());
        out["knots_v_exact"] = json!(net.v.knots.iter().map(t).collect::<Vec<_>>());
    }
    out
}

/// An IGES real: shortest round-trip digits, always with a decimal point, exponent `E`.
fn real(x: f64) -> String {
    let s = format!("{x:?}");
    let (mant, exp) = match s.find(['e', 'E']) {
        Some(k) => (&s[..k], Some(&s[k + 1..])),
        None => (s.as_str(), None),
    };
    let mant = if mant.contains('.') {
        mant.to_string()
    } else {
        format!("{mant}.0")
    };
    match exp {
        Some(e) => format!("{mant}E{e}"),
        None => mant,
    }
}

/// A Hollerith string `nHtext`.
fn hollerith(s: &str) -> String {
    format!("{}H{s}", s.len())
}

/// Lays tokens (each ending with its delimiter) out in lines of at most `width` characters
/// without splitting a token.
fn pack(tokens: &[String], width: usize) -> Vec<String> {
    let mut lines = Vec::new();
    let mut cur = String::new();
    for t in tokens {
        if !cur.is_empty() && cur.len() + t.len() > width {
            lines.push(std::mem::take(&mut cur));
        }
        cur.push_str(t);
    }
    if !cur.is_empty() {
        lines.push(cur);
    }
    lines
}

/// Options of the IGES header.
#[derive(Clone, Debug)]
pub struct IgesOptions {
    /// The file name recorded in the Global section.
    pub file_name: String,
    /// Creation time `YYYYMMDD.HHNNSS` (UTC).
    pub timestamp: String,
}

/// `YYYYMMDD.HHNNSS` for seconds since 1970-01-01 UTC.
pub fn iges_timestamp(unix_seconds: u64) -> String {
    let days = (unix_seconds / 86_400) as i64;
    let rem = unix_seconds % 86_400;
    // Civil date from days since the epoch (proleptic Gregorian calendar).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let y = yoe + era * 400;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = if m <= 2 { y + 1 } else { y };
    format!(
        "{y:04}{m:02}{d:02}.{:02}{:02}{:02}",
        rem / 3600,
        (rem / 60) % 60,
        rem % 60
    )
}

/// One tensor B-spline surface for [`iges_surfaces`]: degrees, full knot vectors, control
/// points row-major (`i` along `u`, index `i·n_v + j`), closed flags `[u, v]`, a label of at
/// most eight characters.
#[derive(Clone, Debug)]
pub struct IgesSurface {
    /// Degrees `[p_u, p_v]`.
    pub degree: [usize; 2],
    /// Full knot vector in `u` (control points in `u` plus `p_u + 1` knots).
    pub knots_u: Vec<f64>,
    /// Full knot vector in `v` (control points in `v` plus `p_v + 1` knots).
    pub knots_v: Vec<f64>,
    /// Control points row-major, `i` along `u` (index `i·n_v + j`).
    pub control: Vec<[f64; 3]>,
    /// Closed in `[u, v]` (the entity's PROP1 and PROP2).
    pub closed: [bool; 2],
    /// Entity label, at most eight characters.
    pub label: String,
}

/// The model's length unit in the Global section: IGES unit flag and name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct IgesUnit {
    /// IGES unit flag (Global section parameter 14).
    pub flag: u32,
    /// Unit name (Global section parameter 15).
    pub name: &'static str,
}

impl IgesUnit {
    /// Millimetres: flag 2, `MM`.
    pub const MILLIMETRE: IgesUnit = IgesUnit {
        flag: 2,
        name: "MM",
    };
    /// Centimetres: flag 10, `CM`.
    pub const CENTIMETRE: IgesUnit = IgesUnit {
        flag: 10,
        name: "CM",
    };
    /// Metres: flag 6, `M`.
    pub const METRE: IgesUnit = IgesUnit { flag: 6, name: "M" };
    /// Inches: flag 1, `INCH`.
    pub const INCH: IgesUnit = IgesUnit {
        flag: 1,
        name: "INCH",
    };
}

/// The net as an IGES 5.3 file with one entity 128 (rational B-spline surface, polynomial:
/// all weights 1), in millimetres ([`iges_surfaces`]).
pub fn to_iges<T: Scalar>(net: &SplineNet<T>, opts: &IgesOptions) -> Result<String> {
    to_iges_in(net, opts, IgesUnit::MILLIMETRE)
}

/// [`to_iges`] with the Global section declaring `unit` (flag and name; the coordinates are
/// written as they are, in that unit).
pub fn to_iges_in<T: Scalar>(
    net: &SplineNet<T>,
    opts: &IgesOptions,
    unit: IgesUnit,
) -> Result<String> {
    let net = net.to_f64();
    let (nu, nv) = (net.u.count(), net.v.count());
    let surface = IgesSurface {
        degree: [net.u.degree, net.v.degree],
        knots_u: net.u.knots.clone(),
        knots_v: net.v.knots.clone(),
        control: (0..nu * nv)
            .map(|k| {
                let c = net.control_point(k / nv, k % nv);
                [c[0], c[1], c[2]]
            })
            .collect(),
        closed: [false, false],
        label: "SURFACE".into(),
    };
    iges_surfaces(
        &[surface],
        opts,
        unit,
        "pdeshape: a B-spline solution of a PDE, IGES entity 128",
    )
}

/// One entity of [`iges_entities`]: its type and form numbers, its parameters after the type
/// number (pointers are the directory sequence numbers `2k + 1` of entity `k`), its status
/// number (eight digits: blank, subordinate, use, hierarchy), a label of at most eight
/// characters and the label's subscript.
#[derive(Clone, Debug)]
pub struct IgesEntity {
    /// Entity type number (128 for a B-spline surface).
    pub number: u32,
    /// Form number.
    pub form: u32,
    /// Parameter data after the type number, each formatted.
    pub params: Vec<String>,
    /// Status number, eight digits ([`IGES_INDEPENDENT`], [`IGES_DEPENDENT`], [`IGES_PARAMETRIC`]).
    pub status: &'static str,
    /// Entity label, at most eight characters.
    pub label: String,
    /// Subscript of the label (0 for none).
    pub subscript: usize,
}

/// Status of an independent entity.
pub const IGES_INDEPENDENT: &str = "00000000";
/// Status of an entity physically dependent on another (a trimmed surface's parts).
pub const IGES_DEPENDENT: &str = "00010000";
/// Status of a dependent curve in a surface's parameter space.
pub const IGES_PARAMETRIC: &str = "00010500";

/// An IGES real (for entities built outside this module).
pub fn iges_real(x: f64) -> String {
    real(x)
}

/// The parameters of an entity 128 (after the type number) for a surface: its parameter `s`
/// is our `u` (first control-point index), `t` is `v`; control points are listed with `s`
/// varying fastest; the parameter range is the knot domain.
pub fn iges_surface_params(s: &IgesSurface) -> Vec<String> {
    let [p, q] = s.degree;
    let nu = s.knots_u.len() - p - 1;
    let nv = s.knots_v.len() - q - 1;
    let flag = |b: bool| if b { "1" } else { "0" };
    let mut params: Vec<String> = vec![
        (nu - 1).to_string(),
        (nv - 1).to_string(),
        p.to_string(),
        q.to_string(),
        flag(s.closed[0]).into(), // PROP1: closed in s
        flag(s.closed[1]).into(), // PROP2: closed in t
        "1".into(),               // PROP3: polynomial
        "0".into(),               // PROP4: not periodic in s
        "0".into(),               // PROP5: not periodic in t
    ];
    params.extend(s.knots_u.iter().map(|&x| real(x)));
    params.extend(s.knots_v.iter().map(|&x| real(x)));
    params.extend((0..nu * nv).map(|_| real(1.0)));
    for j in 0..nv {
        for i in 0..nu {
            params.extend(s.control[i * nv + j].iter().map(|&x| real(x)));
        }
    }
    params.extend([
        real(s.knots_u[p]),
        real(s.knots_u[nu]),
        real(s.knots_v[q]),
        real(s.knots_v[nv]),
    ]);
    params
}

/// Checks a surface's sizes and values for entity 128.
pub fn check_iges_surface(s: &IgesSurface) -> Result<()> {
    let [p, q] = s.degree;
    let nu = s.knots_u.len().saturating_sub(p + 1);
    let nv = s.knots_v.len().saturating_sub(q + 1);
    if nu <= p || nv <= q || s.control.len() != nu * nv {
        return Err(Error::invalid(
            "a surface's knots and control points do not fit together",
        ));
    }
    if s.control
        .iter()
        .flatten()
        .chain(&s.knots_u)
        .chain(&s.knots_v)
        .any(|x| !x.is_finite())
    {
        return Err(Error::invalid("the net has a value that is not finite"));
    }
    Ok(())
}

/// Surfaces as an IGES 5.3 file with one entity 128 each (rational B-spline surface,
/// polynomial: all weights 1, [`iges_surface_params`]) through [`iges_entities`].
pub fn iges_surfaces(
    surfaces: &[IgesSurface],
    opts: &IgesOptions,
    unit: IgesUnit,
    start_text: &str,
) -> Result<String> {
    for s in surfaces {
        check_iges_surface(s)?;
    }
    let maxc = surfaces
        .iter()
        .flat_map(|s| s.control.iter().flatten())
        .fold(0.0f64, |m, x| m.max(x.abs()));
    let entities: Vec<IgesEntity> = surfaces
        .iter()
        .enumerate()
        .map(|(e, s)| IgesEntity {
            number: 128,
            form: 0,
            params: iges_surface_params(s),
            status: IGES_INDEPENDENT,
            label: s.label.clone(),
            subscript: if surfaces.len() == 1 { 0 } else { e + 1 },
        })
        .collect();
    iges_entities(&entities, opts, unit, start_text, maxc)
}

/// Entities as an IGES 5.3 file in the fixed 80-column format: Start, Global, Directory Entry,
/// Parameter Data and Terminate sections, ASCII, lines ending in `\n`. `max_coordinate` is the
/// largest coordinate's size, declared in the Global section.
pub fn iges_entities(
    entities: &[IgesEntity],
    opts: &IgesOptions,
    unit: IgesUnit,
    start_text: &str,
    max_coordinate: f64,
) -> Result<String> {
    let bad = |s: &str| s.chars().any(|c| !c.is_ascii() || c.is_ascii_control());
    if bad(&opts.file_name) || bad(&opts.timestamp) {
        return Err(Error::invalid(
            "IGES strings must be printable ASCII (file name or timestamp)",
        ));
    }
    let line = |text: &str, letter: char, seq: usize| format!("{text:<72}{letter}{seq:>7}\n");
    let mut out = String::new();
    // Start section.
    let start = [start_text];
    for (k, s) in start.iter().enumerate() {
        out.push_str(&line(s, 'S', k + 1));
    }
    // Global section.
    let maxc = max_coordinate;
    let g: Vec<String> = vec![
        "1H,".into(),
        "1H;".into(),
        hollerith("pdeshape"),
        hollerith(&opts.file_name),
        hollerith("pdeshape"),
        hollerith(env!("CARGO_PKG_VERSION")),
        "32".into(),
        "38".into(),
        "6".into(),
        "308".into(),
        "15".into(),
        hollerith("pdeshape"),
        real(1.0),
        unit.flag.to_string(),
        hollerith(unit.name),
        "1".into(),
        real(1.0),
        hollerith(&opts.timestamp),
        real(1e-9),
        real(maxc.max(1.0)),
        hollerith("unknown"),
        hollerith("unknown"),
        "11".into(),
        "0".into(),
        hollerith(&opts.timestamp),
    ];
    let n_g = g.len();
    let gtokens: Vec<String> = g
        .into_iter()
        .enumerate()
        .map(|(k, t)| format!("{t}{}", if k + 1 == n_g { ';' } else { ',' }))
        .collect();
    let glines = pack(&gtokens, 72);
    for (k, l) in glines.iter().enumerate() {
        out.push_str(&line(l, 'G', k + 1));
    }
    let mut directory = String::new();
    let mut parameters = String::new();
    let mut p_lines = 0usize;
    for (e, ent) in entities.iter().enumerate() {
        let mut params = vec![ent.number.to_string()];
        params.extend(ent.params.iter().cloned());
        let n_p = params.len();
        let ptokens: Vec<String> = params
            .into_iter()
            .enumerate()
            .map(|(k, t)| format!("{t}{}", if k + 1 == n_p { ';' } else { ',' }))
            .collect();
        let plines = pack(&ptokens, 64);
        // Directory entry: two lines, nine 8-column fields each plus the sequence field.
        let de = 2 * e + 1;
        let d1 = format!(
            "{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}",
            ent.number,
            p_lines + 1,
            0,
            0,
            0,
            0,
            0,
            0,
            ent.status
        );
        let label: String = ent
            .label
            .chars()
            .filter(|c| c.is_ascii_graphic())
            .take(8)
            .collect();
        let d2 = format!(
            "{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}{:>8}",
            ent.number,
            0,
            0,
            plines.len(),
            ent.form,
            "",
            "",
            label,
            ent.subscript
        );
        directory.push_str(&line(&d1, 'D', de));
        directory.push_str(&line(&d2, 'D', de + 1));
        for l in &plines {
            p_lines += 1;
            parameters.push_str(&format!("{l:<64}{de:>8}P{p_lines:>7}\n"));
        }
    }
    out.push_str(&directory);
    out.push_str(&parameters);
    let t = format!(
        "S{:>7}G{:>7}D{:>7}P{:>7}",
        start.len(),
        glines.len(),
        2 * entities.len(),
        p_lines
    );
    out.push_str(&line(&t, 'T', 1));
    Ok(out)
}
