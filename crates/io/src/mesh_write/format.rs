//! `Format`: the output formats and their choice by file extension.

use crate::{Error, Result};

/// Output formats, chosen by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Wavefront OBJ (`.obj`).
    Obj,
    /// Binary STL (`.stl`).
    Stl,
    /// Binary little-endian PLY (`.ply`).
    Ply,
    /// glTF 2.0 binary (`.glb`).
    Glb,
    /// Full-precision grid samples as CSV (`.csv`), written by [`super::write_csv`].
    Csv,
}

impl Format {
    /// The format for a path's extension (case-insensitive): obj, stl, ply, glb, csv (the
    /// mesh and sample formats of [`crate::format::OutputFormat::from_path`]).
    pub fn from_path(path: &std::path::Path) -> Result<Format> {
        use crate::format::{extensions_hint, unknown_extension, OutputFormat, MESH_FORMATS};
        let Some(ext) = path.extension() else {
            return Err(Error::invalid(format!(
                "output path '{}' has no extension: {}",
                path.display(),
                extensions_hint(&MESH_FORMATS)
            )));
        };
        let ext = ext.to_string_lossy();
        match OutputFormat::from_name(&ext) {
            Some(f) if !f.is_cad() => f.mesh(),
            _ => Err(unknown_extension(&ext, &MESH_FORMATS)),
        }
    }

    /// The canonical (lower-case) file extension, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Obj => "obj",
            Format::Stl => "stl",
            Format::Ply => "ply",
            Format::Glb => "glb",
            Format::Csv => "csv",
        }
    }

    /// True for the mesh formats (written from a [`TriMesh`]); false for CSV, which is
    /// written from full-precision [`Samples`].
    pub fn is_mesh(self) -> bool {
        self != Format::Csv
    }
}
