//! The mesh file's own frame: how its coordinates become the design's, and how a point the
//! fit names in a message is shown in them.
//!
//! A fit works in the design's frame: +Z up, in the design's units. A file that states another
//! frame (glTF is +Y up and in metres by definition; the tool's own OBJ, STL and PLY files may
//! state `up: +Y` and their units) is turned and scaled into it when read. Every point a
//! message names (where a fit misses, where the repairs acted, a component left out, a section
//! that cannot be fitted) is turned back, so the user finds it where the file has it.

use crate::Vec3;

/// How a mesh file's coordinates map to the design's: `design = turn(file) / design_unit`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FileFrame {
    /// The file is +Y up: its `(x, y, z)` is the design's `(x, −z, y)`.
    pub y_up: bool,
    /// One design unit in the file's units (a glTF file, in metres, fitted in millimetres:
    /// 0.001).
    pub design_unit: f64,
}

impl Default for FileFrame {
    /// The design's own frame: a file that states nothing is read as it is.
    fn default() -> Self {
        FileFrame {
            y_up: false,
            design_unit: 1.0,
        }
    }
}

impl FileFrame {
    /// The design's point of the file's `p`.
    pub fn to_design(&self, p: Vec3) -> Vec3 {
        let q = if self.y_up {
            Vec3::new(p.x, -p.z, p.y)
        } else {
            p
        };
        q / self.design_unit
    }

    /// The file's point of the design's `p` (the inverse of [`FileFrame::to_design`]).
    pub fn to_file(&self, p: Vec3) -> Vec3 {
        let q = p * self.design_unit;
        self.direction_to_file(q)
    }

    /// The file's direction of the design's direction `d` (turned, not scaled).
    pub fn direction_to_file(&self, d: Vec3) -> Vec3 {
        if self.y_up {
            Vec3::new(d.x, d.z, -d.y)
        } else {
            d
        }
    }

    /// The design's point `p` as a message shows it: `(x, y, z)` in the file's coordinates,
    /// each to six significant digits without trailing zeros.
    pub fn point(&self, p: Vec3) -> String {
        coordinates(self.to_file(p))
    }

    /// The design's direction `d` as a message shows it, in the file's axes.
    pub fn direction(&self, d: Vec3) -> String {
        coordinates(self.direction_to_file(d))
    }

    /// The plane through the design's point `p` with unit normal `n`, as a message names it:
    /// `through (x, y, z) normal to (a, b, c)`, in the file's coordinates.
    pub fn plane(&self, p: Vec3, n: Vec3) -> String {
        format!("through {} normal to {}", self.point(p), self.direction(n))
    }
}

/// `(x, y, z)`, each coordinate to six significant digits, trailing zeros dropped.
fn coordinates(p: Vec3) -> String {
    let c = |x: f64| {
        let s = crate::number::sig(x, 6);
        let (mantissa, exponent) = s
            .split_once('e')
            .map_or((s.as_str(), None), |(m, e)| (m, Some(e)));
        let mantissa = if mantissa.contains('.') {
            mantissa.trim_end_matches('0').trim_end_matches('.')
        } else {
            mantissa
        };
        match exponent {
            Some(e) => format!("{mantissa}e{e}"),
            None => mantissa.to_string(),
        }
    };
    format!("({}, {}, {})", c(p.x), c(p.y), c(p.z))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_file_point_of_a_design_point_is_where_the_file_has_it() {
        // glTF in millimetre design units: a vertex at (1, 2, 3) m in the file, +Y up, is the
        // design's (1000, −3000, 2000) mm.
        let gltf = FileFrame {
            y_up: true,
            design_unit: 0.001,
        };
        let file = Vec3::new(1.0, 2.0, 3.0);
        let design = gltf.to_design(file);
        assert_eq!(design, Vec3::new(1000.0, -3000.0, 2000.0));
        assert_eq!(gltf.to_file(design), file);
        assert_eq!(gltf.point(design), "(1, 2, 3)");
        // The file's up direction is the design's +Z.
        assert_eq!(gltf.direction(Vec3::new(0.0, 0.0, 1.0)), "(0, 1, 0)");
        let same = FileFrame::default();
        assert_eq!(
            same.point(Vec3::new(-0.5, 1.25e-7, 12345.67)),
            "(-0.5, 1.25e-7, 12345.7)"
        );
    }
}
