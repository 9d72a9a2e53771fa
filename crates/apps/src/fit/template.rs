//! The template mode: the user names the sectioning planes of each part of a shape the
//! automatic modes cannot split (a U-shaped tube, a body with a bend, one sheet of several),
//! and the mode of each part. Book §8.2 extracts the curves of a mesh "utilising a template
//! which consists of a low resolution approximation closely matching the object"; here the
//! template is the skeleton of that approximation: its planes.
//!
//! A template is a small TOML file:
//!
//! ```toml
//! # a = 0.5                 # optional: the smoothing parameter of every part (else chosen)
//!
//! [[parts]]
//! name = "left"             # letters, digits, '_' and '-'
//! mode = "tube"             # "tube" (closed loops; default) or "sheet" (open profiles)
//! axis = [0, 0, 1]          # planes normal to an axis …
//! origin = [-1, 0, 0]       # … through origin + h·axis (origin defaults to [0, 0, 0])
//! positions = [0.0, 2.0]    # … for these h, increasing (at least two)
//! start = "pole"            # "open" (default), "pole" (tube), "edge" (sheet)
//! sections = 32             # fine sections of the part (default 48)
//!
//! [[parts]]
//! name = "bend"
//! planes = [                # or planes given one by one (at least two)
//!   { point = [-1, 0, 2], normal = [0, 0, 1] },
//!   { point = [0, 0, 3], normal = [1, 0, 0] },
//!   { point = [1, 0, 2], normal = [0, 0, -1] },
//! ]
//! ```
//!
//! - **Sections.** Between consecutive planes of a part, planes are interpolated (points
//!   linearly, normals normalised linearly) so the part has about `sections` of them, spread by
//!   the distance between the given points. Each cuts the mesh; where a plane cuts it in
//!   several loops (or pieces), the one whose centroid is nearest to the plane's point is taken.
//!   The planes run along their normals: a part goes the way its normals point.
//! - **Frames.** `v = 0` and the sense of `v` are carried from plane to plane by projecting the
//!   previous plane's `e₁` on the next (parallel transport): no twist along a bend.
//! - **Ends.** `open`: the part ends at its plane's section. `pole` (tube parts): the part
//!   closes at the mesh's extreme vertex beyond the plane, found by walking the mesh from that
//!   section's loop across the plane; sections parallel to the plane between the two are added.
//!   `edge` (sheet parts): the part ends at the arc of the mesh's boundary beyond the plane
//!   (as in the sheet mode).
//! - **Joined parts.** A part whose first plane is the previous part's last one (same point and
//!   normal) continues it: both are one chain of patches, the shared section is a node of both,
//!   and the derivative curve there is shared too (G1 for tubes, G0 for sheets). Other parts
//!   are chains of their own.
//!
//! Errors name the place in the template (`parts[1].planes[2].normal: …`), so the command line
//! can point at its line and column ([`crate::spec::describe_error`]).

use super::chain::{Chain, Joint, Station};
use super::mesh::InputMesh;
use super::options::{Fit, FitMode, FitOptions};
use super::section::{AxisFrame, Piece, Section, Slicer};
use super::sheet::{end_arc, SHEET_AM};
use super::tube::{principal_frame, MODES_SHARE, QUANTUM, SAMPLE_SHARE, TRIM_SHARE, TUBE_A};
use crate::spec::{DesignSpec, SolverSpec};
use crate::work::{self, Work};
use crate::{Error, Result, Vec3};

/// Most parts in a template.
pub(super) const MAX_PARTS: usize = 256;
/// Most planes given for one part.
pub(super) const MAX_PLANES: usize = 1024;

/// The JSON schema of a template file (draft 7), for editors: the keys [`parse_template`]
/// reads, their types and limits. `parse_template` remains the reference (it also checks what a
/// schema cannot say: unit normals, increasing positions, the ends each mode allows).
pub fn template_schema() -> serde_json::Value {
    let v3 = |what: &str| {
        serde_json::json!({
            "description": what,
            "type": "array", "items": { "type": "number" }, "minItems": 3, "maxItems": 3
        })
    };
    let end = |which: &str| {
        serde_json::json!({
            "description": format!(
                "How the part ends {which}: open (at its plane's section; default), pole (a \
                 tube closed at the mesh's extreme vertex beyond the plane) or edge (a sheet \
                 ending at the arc of the mesh's boundary beyond the plane)."
            ),
            "type": "string", "enum": ["open", "pole", "edge"]
        })
    };
    serde_json::json!({
        "$schema": "http://json-schema.org/draft-07/schema#",
        "title": "pdeshape fit template: the sectioning planes and the mode of each part",
        "type": "object",
        "additionalProperties": false,
        "required": ["parts"],
        "properties": {
            "a": {
                "description": "The smoothing parameter of every part (> 0); without it, chosen per chain.",
                "type": "number", "exclusiveMinimum": 0
            },
            "parts": {
                "description": "The parts, in order ([[parts]]).",
                "type": "array", "minItems": 1, "maxItems": MAX_PARTS,
                "items": {
                    "type": "object",
                    "additionalProperties": false,
                    "required": ["name"],
                    "properties": {
                        "name": {
                            "description": "The part's name: letters, digits, '_' and '-'.",
                            "type": "string", "pattern": "^[A-Za-z0-9_-]+$"
                        },
                        "mode": {
                            "description": "tube (closed loops, G1 Hermite patches; default) or sheet (open profiles, four-position patches).",
                            "type": "string", "enum": ["tube", "sheet"]
                        },
                        "axis": v3("Planes normal to this axis (with positions)."),
                        "origin": v3("The planes pass through origin + h·axis (default [0, 0, 0])."),
                        "positions": {
                            "description": "The values h of the planes along the axis, increasing (at least two).",
                            "type": "array", "items": { "type": "number" },
                            "minItems": 2, "maxItems": MAX_PLANES
                        },
                        "planes": {
                            "description": "The planes one by one (at least two; instead of axis and positions).",
                            "type": "array", "minItems": 2, "maxItems": MAX_PLANES,
                            "items": {
                                "type": "object",
                                "additionalProperties": false,
                                "required": ["point", "normal"],
                                "properties": {
                                    "point": v3("A point of the plane."),
                                    "normal": v3("The plane's normal: the part runs the way the normals point.")
                                }
                            }
                        },
                        "start": end("before its first plane"),
                        "end": end("after its last plane"),
                        "sections": {
                            "description": "Fine sections of the part, 4 to 4096 (default 48).",
                            "type": "integer", "minimum": 4, "maximum": 4096
                        }
                    }
                }
            }
        }
    })
}

/// A parsed template.
#[derive(Clone, Debug, PartialEq)]
pub struct Template {
    /// The smoothing parameter of every part; `None` chooses per chain.
    pub a: Option<f64>,
    /// The parts, in the template's order.
    pub parts: Vec<Part>,
}

/// One part of a template.
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    /// The part's name (letters, digits, `_` and `-`).
    pub name: String,
    /// Closed loops or open profiles.
    pub mode: PartMode,
    /// The planes given (at least two), in order along the part.
    pub planes: Vec<Plane>,
    /// How the part ends before its first plane.
    pub start: End,
    /// How the part ends after its last plane.
    pub end: End,
    /// Fine sections of the part.
    pub sections: usize,
    /// Where the planes are in the template: `parts[i].positions` or `parts[i].planes`.
    pub planes_place: String,
}

/// A part's kind of sections.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PartMode {
    /// Closed loops, Hermite patches (G1).
    Tube,
    /// Open profiles, four-position patches (G0).
    Sheet,
}

/// How a part ends.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum End {
    /// The part ends at its plane's section.
    Open,
    /// The part closes at the mesh's extreme vertex beyond the plane (tube parts).
    Pole,
    /// The part ends at the arc of the mesh's boundary beyond the plane (sheet parts).
    Edge,
}

/// A plane through `point` with unit `normal`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// A point of the plane.
    pub point: Vec3,
    /// Unit normal of the plane: a part runs the way its planes' normals point.
    pub normal: Vec3,
}

/// Reads a template (module documentation); errors name their place.
pub fn parse_template(text: &str) -> Result<Template> {
    let table: toml::Table = text.parse().map_err(|e: toml::de::Error| {
        let m: Vec<&str> = e.message().lines().map(str::trim).collect();
        Error::invalid(m.join("; "))
    })?;
    known_keys(&table, &["a", "parts"], "")?;
    let a = match table.get("a") {
        None => None,
        Some(v) => {
            let a = number(v, "a")?;
            if a <= 0.0 {
                return Err(Error::invalid(format!("must be positive (got {a})")).at("a"));
            }
            Some(a)
        }
    };
    let parts = match table.get("parts") {
        Some(toml::Value::Array(items)) => items,
        Some(_) => return Err(Error::invalid("must be an array of tables ([[parts]])").at("parts")),
        None => {
            return Err(Error::invalid(
                "the template has no parts: give at least one [[parts]] table",
            ))
        }
    };
    if parts.is_empty() || parts.len() > MAX_PARTS {
        return Err(Error::invalid(format!(
            "between 1 and {MAX_PARTS} parts (got {})",
            parts.len()
        ))
        .at("parts"));
    }
    let mut out: Vec<Part> = Vec::with_capacity(parts.len());
    for (i, item) in parts.iter().enumerate() {
        let place = format!("parts[{i}]");
        let toml::Value::Table(t) = item else {
            return Err(Error::invalid("must be a table").at(&place));
        };
        let part = parse_part(t, &place)?;
        if let Some(k) = out.iter().position(|p| p.name == part.name) {
            return Err(
                Error::invalid(format!("the name '{}' is taken by parts[{k}]", part.name))
                    .at(&format!("{place}.name")),
            );
        }
        out.push(part);
    }
    Ok(Template { a, parts: out })
}

fn parse_part(t: &toml::Table, place: &str) -> Result<Part> {
    known_keys(
        t,
        &[
            "name",
            "mode",
            "axis",
            "origin",
            "positions",
            "planes",
            "start",
            "end",
            "sections",
        ],
        place,
    )?;
    let at = |k: &str| format!("{place}.{k}");
    let name = match t.get("name") {
        Some(toml::Value::String(s)) => s.clone(),
        Some(_) => return Err(Error::invalid("must be a string").at(&at("name"))),
        None => return Err(Error::invalid("a part needs a name").at(place)),
    };
    if name.is_empty()
        || name.len() > 64
        || !name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
    {
        return Err(
            Error::invalid(format!("'{name}': 1 to 64 letters, digits, '_' or '-'"))
                .at(&at("name")),
        );
    }
    let mode = match word(t, "mode", place)?.as_deref() {
        None | Some("tube") => PartMode::Tube,
        Some("sheet") => PartMode::Sheet,
        Some(w) => {
            return Err(
                Error::invalid(format!("'{w}': must be \"tube\" or \"sheet\"")).at(&at("mode")),
            )
        }
    };
    let end = |key: &str| -> Result<End> {
        let e = match word(t, key, place)?.as_deref() {
            None | Some("open") => End::Open,
            Some("pole") => End::Pole,
            Some("edge") => End::Edge,
            Some(w) => {
                return Err(Error::invalid(format!(
                    "'{w}': must be \"open\", \"pole\" or \"edge\""
                ))
                .at(&at(key)))
            }
        };
        match (mode, e) {
            (PartMode::Tube, End::Edge) => Err(Error::invalid(
                "\"edge\" ends a sheet part; a tube part ends \"open\" or at a \"pole\"",
            )
            .at(&at(key))),
            (PartMode::Sheet, End::Pole) => Err(Error::invalid(
                "\"pole\" ends a tube part; a sheet part ends \"open\" or at the \"edge\"",
            )
            .at(&at(key))),
            _ => Ok(e),
        }
    };
    let (start, finish) = (end("start")?, end("end")?);
    let sections = match t.get("sections") {
        None => 48,
        Some(toml::Value::Integer(n)) if (4..=4096).contains(n) => *n as usize,
        Some(_) => {
            return Err(
                Error::invalid("must be a whole number between 4 and 4096").at(&at("sections"))
            )
        }
    };
    let (planes, planes_place) = match (t.get("planes"), t.get("positions")) {
        (Some(_), Some(_)) => {
            return Err(
                Error::invalid("give either planes or axis and positions, not both")
                    .at(&at("positions")),
            )
        }
        (Some(v), None) => {
            for k in ["axis", "origin"] {
                if t.contains_key(k) {
                    return Err(Error::invalid("goes with positions, not with planes").at(&at(k)));
                }
            }
            let toml::Value::Array(items) = v else {
                return Err(
                    Error::invalid("must be an array of { point, normal } tables")
                        .at(&at("planes")),
                );
            };
            let mut planes = Vec::with_capacity(items.len());
            for (k, item) in items.iter().enumerate() {
                let p = format!("{place}.planes[{k}]");
                let toml::Value::Table(pt) = item else {
                    return Err(Error::invalid("must be a table { point, normal }").at(&p));
                };
                known_keys(pt, &["point", "normal"], &p)?;
                let point = vector(pt.get("point"), &format!("{p}.point"))?;
                let normal = direction(pt.get("normal"), &format!("{p}.normal"))?;
                planes.push(Plane { point, normal });
            }
            (planes, at("planes"))
        }
        (None, Some(v)) => {
            let axis = direction(t.get("axis"), &at("axis"))?;
            let origin = match t.get("origin") {
                None => Vec3::zeros(),
                Some(o) => vector(Some(o), &at("origin"))?,
            };
            let toml::Value::Array(items) = v else {
                return Err(Error::invalid("must be an array of numbers").at(&at("positions")));
            };
            let mut planes = Vec::with_capacity(items.len());
            for (k, item) in items.iter().enumerate() {
                let h = number(item, &format!("{place}.positions[{k}]"))?;
                if let Some(prev) = planes.last() {
                    let prev: &Plane = prev;
                    if h <= (prev.point - origin).dot(&axis) {
                        return Err(Error::invalid(format!("{h}: positions must increase"))
                            .at(&format!("{place}.positions[{k}]")));
                    }
                }
                planes.push(Plane {
                    point: origin + axis * h,
                    normal: axis,
                });
            }
            (planes, at("positions"))
        }
        (None, None) => {
            return Err(Error::invalid("a part needs planes, or axis and positions").at(place))
        }
    };
    if planes.len() < 2 || planes.len() > MAX_PLANES {
        return Err(Error::invalid(format!(
            "between 2 and {MAX_PLANES} planes (got {})",
            planes.len()
        ))
        .at(&planes_place));
    }
    for k in 1..planes.len() {
        let (a, b) = (planes[k - 1], planes[k]);
        if a.normal.dot(&b.normal) <= -0.99 {
            return Err(Error::invalid(format!(
                "plane {} faces the opposite way of plane {}: planes of a part follow one \
                 direction",
                k + 1,
                k
            ))
            .at(&format!("{planes_place}[{k}]")));
        }
        if (b.point - a.point).dot(&(a.normal + b.normal)) <= 0.0 {
            return Err(Error::invalid(format!(
                "plane {} is not ahead of plane {} along their normals",
                k + 1,
                k
            ))
            .at(&format!("{planes_place}[{k}]")));
        }
    }
    Ok(Part {
        name,
        mode,
        planes,
        start,
        end: finish,
        sections,
        planes_place,
    })
}

fn known_keys(t: &toml::Table, keys: &[&str], place: &str) -> Result<()> {
    for k in t.keys() {
        if !keys.contains(&k.as_str()) {
            let p = if place.is_empty() {
                crate::spec::key_path(k)
            } else {
                format!("{place}.{}", crate::spec::key_path(k))
            };
            return Err(Error::invalid(format!(
                "unknown key (expected one of: {})",
                keys.join(", ")
            ))
            .at(&p));
        }
    }
    Ok(())
}

fn number(v: &toml::Value, place: &str) -> Result<f64> {
    let x = match v {
        toml::Value::Float(x) => *x,
        toml::Value::Integer(i) => *i as f64,
        _ => return Err(Error::invalid("must be a number").at(place)),
    };
    if !x.is_finite() {
        return Err(Error::invalid(format!("must be finite (got {x})")).at(place));
    }
    Ok(x)
}

fn word(t: &toml::Table, key: &str, place: &str) -> Result<Option<String>> {
    match t.get(key) {
        None => Ok(None),
        Some(toml::Value::String(s)) => Ok(Some(s.clone())),
        Some(_) => Err(Error::invalid("must be a string").at(&format!("{place}.{key}"))),
    }
}

fn vector(v: Option<&toml::Value>, place: &str) -> Result<Vec3> {
    match v {
        Some(toml::Value::Array(a)) if a.len() == 3 => Ok(Vec3::new(
            number(&a[0], &format!("{place}[0]"))?,
            number(&a[1], &format!("{place}[1]"))?,
            number(&a[2], &format!("{place}[2]"))?,
        )),
        Some(_) => Err(Error::invalid("must be three numbers [x, y, z]").at(place)),
        None => Err(Error::invalid("missing: three numbers [x, y, z]").at(place)),
    }
}

fn direction(v: Option<&toml::Value>, place: &str) -> Result<Vec3> {
    let d = vector(v, place)?;
    let n = d.norm();
    if !(n > 0.0 && n.is_finite()) {
        return Err(Error::invalid("must not be the zero vector").at(place));
    }
    Ok(d / n)
}

/// One fine plane of a part: its frame (origin on the plane, axis its normal) and the place
/// of the plane given at or after it.
struct FinePlane {
    frame: AxisFrame,
    place: String,
}

/// The fine planes of a part (module documentation), with `e₁` carried from `e1`.
/// The planes interpolated between each pair of a part's given planes (module documentation),
/// counting the first of the pair.
fn plane_steps(part: &Part) -> Vec<usize> {
    let lengths: Vec<f64> = part
        .planes
        .windows(2)
        .map(|w| (w[1].point - w[0].point).norm())
        .collect();
    let total: f64 = lengths.iter().sum::<f64>().max(1e-300);
    lengths
        .iter()
        .map(|l| ((part.sections as f64 * l / total).round() as usize).max(2))
        .collect()
}

/// The sections a part cuts: its fine planes, and those of its caps.
fn section_count(part: &Part) -> usize {
    let caps = [part.start, part.end]
        .iter()
        .map(|e| match e {
            End::Pole => cap_count(part),
            End::Edge => 1,
            End::Open => 0,
        })
        .sum::<usize>();
    plane_steps(part).iter().sum::<usize>() + 1 + caps
}

/// Triangles visited a second by the sections (a plane looks at every triangle of the mesh:
/// 512 sections of a 998 000-triangle ellipsoid took about 5 s).
const VISITS_PER_SECOND: f64 = 1e8;

/// The node choice solves a chain once per candidate node, each solve linear in its sections:
/// a chain of `S` sections costs about `S²` over this many seconds (4096 sections in 20 s,
/// 2048 in 5 s).
const CHAIN_SQUARES_PER_SECOND: f64 = 8e5;

/// Refuses a template whose sections would take more than [`work::MAX_SECONDS`] to cut and fit,
/// before the first is cut, naming the part with the most.
fn price(mesh: &InputMesh, template: &Template, chains: &[Vec<usize>]) -> Result<()> {
    let (mut slices, mut squares, mut largest) = (0usize, 0.0, (0usize, 0usize));
    for chain in chains {
        let mut s = 0;
        for &i in chain {
            let n = section_count(&template.parts[i]);
            s += n;
            if n > largest.1 {
                largest = (i, n);
            }
        }
        slices += s;
        squares += (s as f64).powi(2);
    }
    work::check(
        &[
            Work {
                units: slices as f64 * mesh.triangles.len() as f64,
                per_second: VISITS_PER_SECOND,
            },
            Work {
                units: squares,
                per_second: CHAIN_SQUARES_PER_SECOND,
            },
        ],
        &format!(
            "a template of {slices} sections over {} triangles",
            mesh.triangles.len()
        ),
        "give the parts fewer sections (48 by default), or decimate the mesh",
        &format!("parts[{}].sections", largest.0),
    )
}

fn fine_planes(part: &Part, mut e1: Vec3) -> Vec<FinePlane> {
    let p = &part.planes;
    let steps = plane_steps(part);
    let mut out = Vec::new();
    let mut push = |point: Vec3, normal: Vec3, place: String, e1: &mut Vec3| {
        let mut e = *e1 - normal * e1.dot(&normal);
        if e.norm() < 1e-6 {
            e = normal.cross(&Vec3::x());
            if e.norm() < 1e-3 {
                e = normal.cross(&Vec3::y());
            }
        }
        let e = e.normalize();
        *e1 = e;
        out.push(FinePlane {
            frame: AxisFrame {
                origin: point,
                e1: e,
                e2: normal.cross(&e),
                axis: normal,
            },
            place,
        });
    };
    for k in 0..p.len() - 1 {
        for i in 0..steps[k] {
            let t = i as f64 / steps[k] as f64;
            let point = p[k].point * (1.0 - t) + p[k + 1].point * t;
            let normal = (p[k].normal * (1.0 - t) + p[k + 1].normal * t).normalize();
            // A plane between two given ones is reported at the one it leads to.
            let place = format!("{}[{}]", part.planes_place, k + (i > 0) as usize);
            push(point, normal, place, &mut e1);
        }
    }
    let k = p.len() - 1;
    push(
        p[k].point,
        p[k].normal,
        format!("{}[{k}]", part.planes_place),
        &mut e1,
    );
    out
}

/// Fits `mesh` as `template` says (module documentation).
pub fn fit_template(mesh: &InputMesh, template: &Template, opts: &FitOptions) -> Result<Fit> {
    opts.check()?;
    mesh.require_single()?;
    let diag = mesh.diagonal();
    if !(diag.is_finite() && diag > 0.0) {
        return Err(Error::invalid("the mesh has no extent"));
    }
    let tol = opts.target * diag;
    let reference = principal_frame(mesh);
    let outlines = if template
        .parts
        .iter()
        .any(|p| p.start == End::Edge || p.end == End::Edge)
    {
        mesh.boundary_loops()?
    } else {
        Vec::new()
    };
    let neighbours = if template
        .parts
        .iter()
        .any(|p| p.start == End::Pole || p.end == End::Pole)
    {
        vertex_neighbours(mesh)
    } else {
        Vec::new()
    };
    // Chains of joined parts.
    let mut chains: Vec<Vec<usize>> = Vec::new();
    for (i, part) in template.parts.iter().enumerate() {
        let joins = i > 0 && {
            let prev = &template.parts[i - 1];
            let (a, b) = (prev.planes[prev.planes.len() - 1], part.planes[0]);
            (a.point - b.point).norm() <= 1e-9 * diag && a.normal.dot(&b.normal) >= 1.0 - 1e-12
        };
        if joins {
            let prev = &template.parts[i - 1];
            if prev.mode != part.mode {
                return Err(Error::invalid(format!(
                    "continues part '{}' (its first plane is that part's last) but is of the \
                     other mode",
                    prev.name
                ))
                .at(&format!("parts[{i}].mode")));
            }
            if prev.end != End::Open || part.start != End::Open {
                return Err(Error::invalid(format!(
                    "continues part '{}': the two must meet \"open\" (end of the one, start of \
                     the other)",
                    prev.name
                ))
                .at(&format!("parts[{i}].start")));
            }
            if let Some(c) = chains.last_mut() {
                c.push(i);
            }
        } else {
            chains.push(vec![i]);
        }
    }
    price(mesh, template, &chains)?;
    let mut spec = DesignSpec {
        solver: SolverSpec {
            modes: 1,
            ..SolverSpec::default()
        },
        ..DesignSpec::default()
    };
    let (mut sections, mut dropped, mut modes, mut patches) = (0, 0, 0, 0);
    let mut sample_error: f64 = 0.0;
    let mut first: Option<(AxisFrame, f64)> = None;
    for chain_parts in &chains {
        let mut stations: Vec<Station> = Vec::new();
        let mut forced = Vec::new();
        let mut e1 = reference.e1;
        for (pos, &i) in chain_parts.iter().enumerate() {
            let part = &template.parts[i];
            let place = format!("parts[{i}]");
            let fine = fine_planes(part, e1);
            e1 = fine[fine.len() - 1].frame.e1;
            let mut cut: Vec<(Station, Piece, AxisFrame)> = Vec::with_capacity(fine.len());
            for (k, fp) in fine.iter().enumerate() {
                if pos > 0 && k == 0 {
                    // The junction: the previous part's last section.
                    continue;
                }
                let slicer = Slicer::new(mesh, fp.frame, opts.file);
                let near = Some(fp.frame.origin);
                let at =
                    |e: Error| Error::invalid(format!("{e} (part '{}')", part.name)).at(&fp.place);
                let (piece, section) =
                    cut_at(&slicer, part.mode, 0.0, near, opts.samples).map_err(at)?;
                cut.push((station_of(section, part), piece, fp.frame));
            }
            if pos > 0 {
                forced.push(stations.len() - 1);
            }
            // A pole or an edge before the first section.
            let (_, first_piece, first_frame) = &cut[0];
            let mut head: Vec<Station> = Vec::new();
            match part.start {
                End::Pole => {
                    let (cap, d) = cap_stations(
                        mesh,
                        &neighbours,
                        first_piece,
                        first_frame,
                        -1.0,
                        part,
                        opts,
                    )
                    .map_err(|e| e.at(&format!("{place}.start")))?;
                    dropped += d;
                    head = cap;
                }
                End::Edge => {
                    let line = edge_line(mesh, &outlines, first_piece, first_frame, true)
                        .map_err(|e| e.at(&format!("{place}.start")))?;
                    head.push(station_of(
                        super::profile::from_edge_arc(
                            &line,
                            first_frame,
                            0.0,
                            opts.samples,
                            opts.file,
                        )?,
                        part,
                    ));
                }
                End::Open => {}
            }
            let (_, last_piece, last_frame) = &cut[cut.len() - 1];
            let mut tail: Vec<Station> = Vec::new();
            match part.end {
                End::Pole => {
                    let (mut cap, d) =
                        cap_stations(mesh, &neighbours, last_piece, last_frame, 1.0, part, opts)
                            .map_err(|e| e.at(&format!("{place}.end")))?;
                    dropped += d;
                    cap.reverse();
                    tail = cap;
                }
                End::Edge => {
                    let line = edge_line(mesh, &outlines, last_piece, last_frame, false)
                        .map_err(|e| e.at(&format!("{place}.end")))?;
                    tail.push(station_of(
                        super::profile::from_edge_arc(
                            &line,
                            last_frame,
                            0.0,
                            opts.samples,
                            opts.file,
                        )?,
                        part,
                    ));
                }
                End::Open => {}
            }
            stations.extend(head);
            stations.extend(cut.into_iter().map(|c| c.0));
            stations.extend(tail);
        }
        let lead = &template.parts[chain_parts[0]];
        sections += stations.iter().filter(|s| !s.pole).count();
        if stations.len() < 4 {
            return Err(Error::invalid(format!(
                "part '{}' has fewer than four sections: give it more (sections = …)",
                lead.name
            ))
            .at(&format!("parts[{}]", chain_parts[0])));
        }
        let joint = match lead.mode {
            PartMode::Tube => Joint::Hermite,
            PartMode::Sheet => Joint::FourPoints,
        };
        let chain = Chain::new(stations, &forced, joint, opts.max_modes, MODES_SHARE * tol);
        let candidates: Vec<f64> = match (template.a.or(opts.a), joint) {
            (Some(a), _) => vec![a],
            (None, Joint::Hermite) => TUBE_A.to_vec(),
            (None, Joint::FourPoints) => SHEET_AM
                .iter()
                .map(|am| super::chain::significant(am / chain.modes() as f64, 3))
                .collect(),
        };
        let (nodes, solved) = chain
            .fit(&candidates, SAMPLE_SHARE * tol, None)
            .ok_or_else(|| {
                Error::invalid("no patches fit").at(&format!("parts[{}]", chain_parts[0]))
            })?;
        chain.design_into(
            &nodes,
            &solved,
            &format!("{}_", lead.name),
            QUANTUM * diag,
            TRIM_SHARE * tol,
            &mut spec,
        );
        modes = modes.max(chain.modes());
        patches += nodes.len() - 1;
        sample_error = sample_error.max(solved.errors.iter().cloned().fold(0.0, f64::max) / diag);
        if first.is_none() {
            let f = fine_planes(lead, reference.e1)[0].frame;
            first = Some((f, solved.a));
        }
    }
    let (frame, a) = first.unwrap_or((reference, 1.0));
    Ok(Fit {
        spec,
        mode: FitMode::Template,
        frame,
        sections,
        dropped,
        modes,
        patches,
        a,
        sample_error,
        notes: Vec::new(),
    })
}

fn station_of(section: Section, part: &Part) -> Station {
    Station {
        points: section.points,
        pole: false,
        part: part.name.clone(),
    }
}

/// The section of `slicer` at height `h`: a loop (tube) or an open piece (sheet), nearest to
/// `near`.
fn cut_at(
    slicer: &Slicer,
    mode: PartMode,
    h: f64,
    near: Option<Vec3>,
    samples: usize,
) -> Result<(Piece, Section)> {
    match mode {
        PartMode::Tube => {
            let piece = slicer.loop_near(h, near)?;
            let s = Section::from_loop(&piece.points, slicer.frame(), h, samples, slicer.file())?;
            Ok((piece, s))
        }
        PartMode::Sheet => {
            let piece = slicer.open_piece(h, near)?;
            let s = super::profile::from_polyline(
                &piece.points,
                slicer.frame(),
                h,
                samples,
                slicer.file(),
            )?;
            Ok((piece, s))
        }
    }
}

/// The arc of the mesh's boundary beyond `piece` (below its plane if `below`).
fn edge_line(
    mesh: &InputMesh,
    outlines: &[Vec<u32>],
    piece: &Piece,
    frame: &AxisFrame,
    below: bool,
) -> Result<Vec<Vec3>> {
    let key = piece.keys.first().copied();
    let outline = outlines
        .iter()
        .find(|o| {
            key.is_some_and(|(a, b)| {
                o.iter()
                    .zip(o.iter().cycle().skip(1))
                    .any(|(&x, &y)| (x.min(y), x.max(y)) == (a, b))
            })
        })
        .ok_or_else(|| Error::invalid("the section does not end on the mesh's boundary"))?;
    end_arc(mesh, outline, piece, frame, below)
}

/// Each vertex's neighbours through triangle edges.
fn vertex_neighbours(mesh: &InputMesh) -> Vec<Vec<u32>> {
    let mut n: Vec<Vec<u32>> = vec![Vec::new(); mesh.positions.len()];
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            n[a as usize].push(b);
            n[b as usize].push(a);
        }
    }
    n
}

/// The sections of a cap between a part's end plane and its pole.
fn cap_count(part: &Part) -> usize {
    (part.sections / 4).max(6)
}

/// The stations from the pole beyond `piece` (on the side `side` = −1 below its plane, +1
/// above) towards it: the pole, then sections parallel to the plane, denser towards the pole
/// (not including `piece`'s own plane). Also the number of sections left out next to the pole.
fn cap_stations(
    mesh: &InputMesh,
    neighbours: &[Vec<u32>],
    piece: &Piece,
    frame: &AxisFrame,
    side: f64,
    part: &Part,
    opts: &FitOptions,
) -> Result<(Vec<Station>, usize)> {
    let samples = opts.samples;
    let beyond = |i: u32| side * frame.height(&mesh.positions[i as usize]) > 0.0;
    let mut seen = vec![false; mesh.positions.len()];
    let mut stack: Vec<u32> = Vec::new();
    for &(a, b) in &piece.keys {
        for v in [a, b] {
            if beyond(v) && !seen[v as usize] {
                seen[v as usize] = true;
                stack.push(v);
            }
        }
    }
    let mut pole: Option<(u32, f64)> = None;
    while let Some(v) = stack.pop() {
        let h = side * frame.height(&mesh.positions[v as usize]);
        if pole.is_none_or(|(_, best)| h > best) {
            pole = Some((v, h));
        }
        for &w in &neighbours[v as usize] {
            if !seen[w as usize] && beyond(w) {
                seen[w as usize] = true;
                stack.push(w);
            }
        }
    }
    let Some((pv, depth)) = pole else {
        return Err(Error::invalid(
            "the mesh does not go on beyond this plane: no pole to close the part",
        ));
    };
    let pole_point = mesh.positions[pv as usize];
    let slicer = Slicer::new(mesh, *frame, opts.file);
    let count = cap_count(part);
    let centre = piece.centre();
    let mut out = vec![Station::at_pole(pole_point, samples, &part.name)];
    let mut dropped = 0;
    const EDGE: usize = 3;
    for j in 1..=count {
        // From the pole (t = 0) to the plane (t = 1), denser at the pole.
        let t = j as f64 / (count + 1) as f64;
        let h = side * depth * (std::f64::consts::FRAC_PI_2 * t).cos();
        let near = centre + frame.axis * h;
        match slicer
            .loop_near(h, Some(near))
            .and_then(|p| Section::from_loop(&p.points, frame, h, samples, opts.file))
        {
            Ok(s) => out.push(station_of(s, part)),
            Err(_) if j <= EDGE => dropped += 1,
            Err(e) => return Err(e),
        }
    }
    Ok((out, dropped))
}
