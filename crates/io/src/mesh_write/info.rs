//! `MeshInfo` (title, units, scale, up axis) and what the writers make of it: the `Frame` that
//! scales and turns points and normals, the generator, part names as tokens, the units line.

use super::format::Format;
use super::{Units, Up};
use crate::mesh::{Part, TriMesh};
use crate::{Error, Result};

/// What the writers record beside the triangles: the design's title, its length unit, a scale
/// and the up axis of the file.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshInfo {
    /// The design's title, written where the format has room for it (OBJ and PLY comments, the glTF
    /// root node's name and `asset.extras`).
    pub title: Option<String>,
    /// The unit of the design's coordinates (times `scale`).
    pub units: Units,
    /// A factor applied to every position (finite and positive).
    pub scale: f64,
    /// The up axis of OBJ, STL and PLY files (glTF is always `+Y` up).
    pub up: Up,
}

impl Default for MeshInfo {
    fn default() -> Self {
        MeshInfo {
            title: None,
            units: Units::default(),
            scale: 1.0,
            up: Up::Z,
        }
    }
}

/// The generator named in every file.
pub(super) const GENERATOR: &str = concat!("pdeshape ", env!("CARGO_PKG_VERSION"));

/// A position and normal map `p → k·R p`, `n → R n`.
#[derive(Clone, Copy)]
pub(super) struct Frame {
    k: f64,
    y_up: bool,
}

impl Frame {
    pub(super) fn new(info: &MeshInfo, format: Format) -> Result<Frame> {
        if !(info.scale.is_finite() && info.scale > 0.0) {
            return Err(Error::invalid(format!(
                "must be finite and positive (got {})",
                info.scale
            ))
            .at("scale"));
        }
        Ok(match format {
            // glTF: metres, +Y up.
            Format::Glb => Frame {
                k: info.scale * info.units.metres(),
                y_up: true,
            },
            _ => Frame {
                k: info.scale,
                y_up: info.up == Up::Y,
            },
        })
    }

    #[inline(always)]
    fn turn(&self, p: [f64; 3]) -> [f64; 3] {
        if self.y_up {
            [p[0], p[2], -p[1]]
        } else {
            p
        }
    }

    #[inline(always)]
    pub(super) fn point(&self, p: [f32; 3]) -> [f32; 3] {
        if self.k == 1.0 && !self.y_up {
            return p;
        }
        self.turn(p.map(f64::from)).map(|c| (c * self.k) as f32)
    }

    #[inline(always)]
    pub(super) fn normal(&self, n: [f32; 3]) -> [f32; 3] {
        if self.y_up {
            [n[0], n[2], -n[1]]
        } else {
            n
        }
    }
}

/// A part's name as one token (whitespace and control characters become `_`; empty names
/// `part<k>`).
pub(super) fn token(name: &str, k: usize) -> String {
    let t: String = name
        .chars()
        .map(|c| {
            if c.is_whitespace() || c.is_control() {
                '_'
            } else {
                c
            }
        })
        .collect();
    if t.is_empty() {
        format!("part{k}")
    } else {
        t
    }
}

/// A text on one line (line breaks become spaces).
pub(super) fn one_line(text: &str) -> String {
    text.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}

/// The parts of a mesh: its own, or one unnamed part with every triangle.
pub(super) fn parts_of(mesh: &TriMesh) -> Vec<Part> {
    if mesh.parts.is_empty() {
        vec![Part {
            name: "mesh".to_string(),
            triangles: 0..mesh.triangles.len(),
        }]
    } else {
        mesh.parts.clone()
    }
}

/// The unit line every text header carries.
pub(super) fn units_text(info: &MeshInfo) -> String {
    format!(
        "units: {} (1 unit = {} m); up: {}",
        info.units.as_str(),
        info.units.metres(),
        info.up.label()
    )
}
