//! Writers. Mesh formats (OBJ, STL, PLY, GLB) are written from one indexed [`TriMesh`] (see
//! [`crate::mesh::weld`] for how a design's grids become one) with a [`MeshInfo`]: the title, the
//! length unit, a scale and the up axis; CSV is written from full-precision grids.
//!
//! Every writer first checks all of its input (at least one triangle or patch, consistent array
//! lengths, finite values, index ranges that fit the format) and only then writes, so a refused
//! input never leaves a truncated or broken file behind. The bytes are assembled in chunk
//! buffers of about a megabyte on a second thread while the calling thread hands the previous
//! one to the destination with `write_all`, in one pass, so the destination needs no buffering
//! of its own.

use crate::mesh::weld::{weld, WeldOptions};
pub use crate::mesh::Up;
use crate::mesh::{GridMesh, TriMesh};
pub use crate::spec::Units;
use crate::{Error, Result};
use std::io::Write;

mod blocks;
mod check;
mod csv;
mod format;
mod glb;
mod info;
mod obj;
mod ply;
mod stl;
use blocks::{join_bytes, le3, stream, Sink, CHUNK};
use check::{check_grids, check_mesh, check_u32};
pub use csv::write_csv;
pub use format::Format;
pub use glb::material as glb_material;
pub use glb::{write_glb, write_glb_grids};
pub use info::MeshInfo;
use info::{parts_of, Frame, GENERATOR};
pub use obj::write_obj;
pub use ply::write_ply;
pub use stl::write_stl;

/// Writes a mesh in a mesh format (obj, stl, ply, glb); CSV, which stores full-precision
/// samples, is written by [`write_csv`].
pub fn write_mesh(
    format: Format,
    mesh: &TriMesh,
    info: &MeshInfo,
    w: &mut dyn Write,
) -> Result<()> {
    match format {
        Format::Obj => write_obj(mesh, info, w),
        Format::Stl => write_stl(mesh, info, w),
        Format::Ply => write_ply(mesh, info, w),
        Format::Glb => write_glb(mesh, info, w),
        Format::Csv => Err(Error::invalid(
            "csv stores full-precision samples: write them with write_csv",
        )),
    }
}

/// Writes grids (patches `patch0`, `patch1`, …) in a mesh format, welded and oriented by
/// [`weld`] with the default options ([`write_welded`] with the default [`MeshInfo`]).
pub fn write(format: Format, meshes: &[GridMesh], w: &mut dyn Write) -> Result<()> {
    write_welded(
        format,
        meshes,
        &[],
        WeldOptions::default(),
        &MeshInfo::default(),
        w,
    )
}

/// Writes a design's grids in a mesh format as [`write_mesh`] writes `weld(grids, names,
/// options)`, byte for byte: checked first; GLB straight from the grids
/// ([`write_glb_grids`]), the other formats from the welded mesh.
pub fn write_welded(
    format: Format,
    grids: &[GridMesh],
    names: &[&str],
    options: WeldOptions,
    info: &MeshInfo,
    w: &mut dyn Write,
) -> Result<()> {
    match format {
        Format::Csv => write_mesh(format, &TriMesh::default(), info, w),
        Format::Glb => write_glb_grids(grids, names, options, info, w),
        _ => {
            check_grids(grids, true)?;
            write_mesh(format, &weld(grids, names, options), info, w)
        }
    }
}

#[cfg(test)]
use {crate::mesh::Grid, blocks::Text, info::token, stl::facet_normal};

#[cfg(test)]
mod tests;
