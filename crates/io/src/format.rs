//! The output formats of a design, by name and by file extension: the mesh formats (OBJ, STL,
//! PLY, glTF binary), the samples (CSV) and the CAD formats (STEP, IGES). One type for the CLI,
//! the designer and the Python package: [`OutputFormat::from_path`] for a file's extension,
//! [`str::parse`] for a name (`--format obj`), [`std::fmt::Display`] for the canonical name.
//! The mesh writers take the [`mesh::Format`] of a mesh or sample format
//! ([`OutputFormat::mesh`]).

use crate::mesh_write as mesh;
use crate::{Error, Result};
use std::path::Path;

/// An output format of a design.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum OutputFormat {
    /// Wavefront OBJ (`.obj`).
    Obj,
    /// Binary STL (`.stl`).
    Stl,
    /// Binary little-endian PLY (`.ply`).
    Ply,
    /// glTF 2.0 binary (`.glb`).
    Glb,
    /// Full-precision grid samples as CSV (`.csv`).
    Csv,
    /// STEP (ISO 10303-21; `.step` or `.stp`).
    Step,
    /// IGES (`.igs` or `.iges`).
    Iges,
}

impl OutputFormat {
    /// Every format, mesh formats first.
    pub const ALL: [OutputFormat; 7] = [
        OutputFormat::Obj,
        OutputFormat::Stl,
        OutputFormat::Ply,
        OutputFormat::Glb,
        OutputFormat::Csv,
        OutputFormat::Step,
        OutputFormat::Iges,
    ];

    /// The extensions (and names) of the format, the canonical one first: `obj`, `stl`, `ply`,
    /// `glb`, `csv`, `step` and `stp`, `igs` and `iges`.
    pub fn extensions(self) -> &'static [&'static str] {
        match self {
            OutputFormat::Obj => &["obj"],
            OutputFormat::Stl => &["stl"],
            OutputFormat::Ply => &["ply"],
            OutputFormat::Glb => &["glb"],
            OutputFormat::Csv => &["csv"],
            OutputFormat::Step => &["step", "stp"],
            OutputFormat::Iges => &["igs", "iges"],
        }
    }

    /// The canonical (lower-case) name, which is also the extension written: `obj`, `stl`,
    /// `ply`, `glb`, `csv`, `step`, `igs`.
    pub fn name(self) -> &'static str {
        self.extensions()[0]
    }

    /// The format of a name or extension ([`OutputFormat::extensions`]), any case, with or
    /// without a leading dot.
    pub fn from_name(name: &str) -> Option<OutputFormat> {
        let name = name.strip_prefix('.').unwrap_or(name);
        Self::ALL
            .into_iter()
            .find(|f| f.extensions().iter().any(|e| e.eq_ignore_ascii_case(name)))
    }

    /// The format of a path's extension (any case); refused, naming the path or the extension,
    /// when it has none or an unknown one (with every accepted extension, and the nearest one
    /// when the extension looks like a typo of it).
    pub fn from_path(path: &Path) -> Result<OutputFormat> {
        let Some(ext) = path.extension() else {
            return Err(Error::invalid(format!(
                "output path '{}' has no extension: {}",
                path.display(),
                extensions_hint(&Self::ALL)
            )));
        };
        let ext = ext.to_string_lossy();
        Self::from_name(&ext).ok_or_else(|| unknown(&ext, &Self::ALL))
    }

    /// Whether this is STEP or IGES (exact B-spline surfaces, no grid).
    pub fn is_cad(self) -> bool {
        matches!(self, OutputFormat::Step | OutputFormat::Iges)
    }

    /// The mesh writers' format of a mesh or sample format; a CAD format is refused as the
    /// mesh writers refuse an unknown extension.
    pub fn mesh(self) -> Result<mesh::Format> {
        match self {
            OutputFormat::Obj => Ok(mesh::Format::Obj),
            OutputFormat::Stl => Ok(mesh::Format::Stl),
            OutputFormat::Ply => Ok(mesh::Format::Ply),
            OutputFormat::Glb => Ok(mesh::Format::Glb),
            OutputFormat::Csv => Ok(mesh::Format::Csv),
            OutputFormat::Step | OutputFormat::Iges => Err(unknown(self.name(), &MESH_FORMATS)),
        }
    }
}

/// The mesh and sample formats (those [`OutputFormat::mesh`] turns into a mesh writer's format).
pub const MESH_FORMATS: [OutputFormat; 5] = [
    OutputFormat::Obj,
    OutputFormat::Stl,
    OutputFormat::Ply,
    OutputFormat::Glb,
    OutputFormat::Csv,
];

/// What a refusal of an extension suggests: "use .obj, .stl, … or .iges", every extension of
/// `formats` ([`OutputFormat::extensions`]).
pub fn extensions_hint(formats: &[OutputFormat]) -> String {
    let all: Vec<String> = formats
        .iter()
        .flat_map(|f| f.extensions())
        .map(|e| format!(".{e}"))
        .collect();
    match all.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("use {} or {last}", rest.join(", ")),
        Some((last, _)) => format!("use {last}"),
        None => String::new(),
    }
}

/// The refusal of an unknown extension `ext` (without its dot) among `formats`: every accepted
/// extension, and the nearest one when `ext` looks like a typo of it.
pub fn unknown_extension(ext: &str, formats: &[OutputFormat]) -> Error {
    unknown(ext, formats)
}

fn unknown(ext: &str, formats: &[OutputFormat]) -> Error {
    // A format this output does not take (a CAD extension for a mesh) is no typo.
    let candidates = formats.iter().flat_map(|f| f.extensions().iter().copied());
    let guess = match OutputFormat::from_name(ext) {
        Some(_) => None,
        None => crate::spec::suggest::nearest(ext, candidates),
    }
    .map(|g| format!(" (did you mean .{g}?)"))
    .unwrap_or_default();
    Error::invalid(format!(
        "unknown output extension '.{ext}'{guess}: {}",
        extensions_hint(formats)
    ))
}

impl From<mesh::Format> for OutputFormat {
    fn from(f: mesh::Format) -> Self {
        match f {
            mesh::Format::Obj => OutputFormat::Obj,
            mesh::Format::Stl => OutputFormat::Stl,
            mesh::Format::Ply => OutputFormat::Ply,
            mesh::Format::Glb => OutputFormat::Glb,
            mesh::Format::Csv => OutputFormat::Csv,
        }
    }
}

impl std::str::FromStr for OutputFormat {
    type Err = Error;

    /// A format by name ([`OutputFormat::from_name`]); an unknown name is refused with the
    /// message of an unknown extension.
    fn from_str(s: &str) -> Result<Self> {
        Self::from_name(s).ok_or_else(|| unknown(s.strip_prefix('.').unwrap_or(s), &Self::ALL))
    }
}

impl std::fmt::Display for OutputFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A CAD model as the text of a STEP or IGES file declaring `unit`, `file_name` and the date
/// `unix_seconds` in its header (see [`export_timestamp`]); other formats are refused.
pub fn write_cad(
    model: &crate::cad::CadModel,
    format: OutputFormat,
    unit: crate::spec::Units,
    file_name: &str,
    unix_seconds: u64,
) -> Result<String> {
    use crate::cad::{self, step};
    match format {
        OutputFormat::Step => step::to_step(
            model,
            &step::StepOptions {
                unit,
                file_name: file_name.to_string(),
                timestamp: step::step_timestamp(unix_seconds),
            },
        ),
        OutputFormat::Iges => cad::to_iges(model, unit, file_name, unix_seconds),
        other => Err(Error::invalid(format!(
            "{other} is not a CAD format (step or igs)"
        ))),
    }
}

/// A `[spline]` design's net as IGES 5.3 (one B-spline surface, entity 128) declaring `unit`,
/// `file_name` (every character but printable ASCII as `_`) and the date `unix_seconds` (see
/// [`export_timestamp`]): what `pdeshape spline -o net.igs` writes.
pub fn write_spline_iges(
    net: &crate::splinepde::SplineNet<f64>,
    unit: crate::spec::Units,
    file_name: &str,
    unix_seconds: u64,
) -> Result<String> {
    use crate::splinepde::export::{iges_timestamp, to_iges_in, IgesOptions, IgesUnit};
    let file_name = file_name
        .chars()
        .map(|c| if c.is_ascii_graphic() { c } else { '_' })
        .collect();
    to_iges_in(
        net,
        &IgesOptions {
            file_name,
            timestamp: iges_timestamp(unix_seconds),
        },
        IgesUnit::from(unit),
    )
}

/// Whether `path` ends in `.ext` (any case).
pub fn has_extension(path: &Path, ext: &str) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case(ext))
}

/// A picture size `WIDTHxHEIGHT` (`x` or `X`, spaces around the numbers allowed), each side
/// between 1 and [`crate::render::MAX_SIDE`] pixels (the pictures' own limits; their memory is
/// priced when they are drawn).
pub fn parse_size(s: &str) -> Result<(u32, u32)> {
    let max = crate::render::MAX_SIDE;
    let bad = || Error::invalid(format!("expected WIDTHxHEIGHT such as 800x600 (got '{s}')"));
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
    if !(1..=max).contains(&w) || !(1..=max).contains(&h) {
        return Err(Error::invalid(format!(
            "width and height must be between 1 and {max} (got {w}x{h})"
        )));
    }
    Ok((w, h))
}

/// A picture size, `WIDTHxHEIGHT` as [`parse_size`] reads it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PictureSize {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
}

impl std::str::FromStr for PictureSize {
    type Err = Error;

    fn from_str(s: &str) -> Result<Self> {
        parse_size(s).map(|(width, height)| PictureSize { width, height })
    }
}

/// The Unix time (seconds) a written file records as its date (the STEP and IGES headers):
/// `SOURCE_DATE_EPOCH` when it is set to a whole number of seconds (reproducible builds),
/// else the current time.
pub fn export_timestamp() -> u64 {
    timestamp_from(std::env::var("SOURCE_DATE_EPOCH").ok().as_deref())
}

/// [`export_timestamp`] for a given value of `SOURCE_DATE_EPOCH`.
pub fn timestamp_from(source_date_epoch: Option<&str>) -> u64 {
    source_date_epoch
        .and_then(|s| s.trim().parse::<u64>().ok())
        .unwrap_or_else(|| {
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map(|d| d.as_secs())
                .unwrap_or(0)
        })
}

#[cfg(test)]
mod tests;
