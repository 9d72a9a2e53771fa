//! The checks every writer makes before it writes: grids and meshes (counts, array lengths,
//! finite values) and counts that must fit a format's 32-bit fields.

use crate::mesh::{Grid, TriMesh};
use crate::{Error, Result};

/// Checks the patches before anything is written: at least one patch; array lengths that agree
/// with `nu × nv`; finite parameter values, positions and normals; and, for the mesh formats
/// (`need_faces`), at least one face per patch.
pub(super) fn check_grids<T: Copy + Into<f64> + Sync>(
    grids: &[Grid<T>],
    need_faces: bool,
) -> Result<()> {
    if grids.is_empty() {
        return Err(Error::invalid(
            "no patches to write: the design produced no surface",
        ));
    }
    for (k, g) in grids.iter().enumerate() {
        check_grid(g, need_faces).map_err(|e| e.at(&format!("patches[{k}]")))?;
    }
    Ok(())
}

fn check_grid<T: Copy + Into<f64> + Sync>(g: &Grid<T>, need_faces: bool) -> Result<()> {
    let Some(n) = g.nu.checked_mul(g.nv) else {
        return Err(Error::invalid(format!(
            "grid size {} × {} overflows",
            g.nu, g.nv
        )));
    };
    if n == 0 {
        return Err(Error::invalid(format!(
            "empty grid ({} × {} vertices)",
            g.nu, g.nv
        )));
    }
    if need_faces {
        let min_nv = if g.periodic_v { 3 } else { 2 };
        if g.nu < 2 || g.nv < min_nv {
            return Err(Error::invalid(format!(
                "a {} × {} grid{} has no faces (need nu ≥ 2 and nv ≥ {min_nv})",
                g.nu,
                g.nv,
                if g.periodic_v { " periodic in v" } else { "" }
            )));
        }
    }
    let lengths = [
        ("u", g.u.len(), g.nu),
        ("v", g.v.len(), g.nv),
        ("positions", g.positions.len(), n),
        ("normals", g.normals.len(), n),
    ];
    for (name, len, want) in lengths {
        if len != want {
            return Err(Error::invalid(format!(
                "{name} has {len} entries, expected {want} for a {} × {} grid",
                g.nu, g.nv
            )));
        }
    }
    if let Some((i, &u)) = g.u.iter().enumerate().find(|(_, u)| !u.is_finite()) {
        return Err(Error::invalid(format!("non-finite parameter u[{i}] = {u}")));
    }
    if let Some((j, &v)) = g.v.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(Error::invalid(format!("non-finite parameter v[{j}] = {v}")));
    }
    for (name, data) in [("position", &g.positions), ("normal", &g.normals)] {
        let bad = crate::mesh::first_bad(data, |p| {
            !p.iter().all(|&c| Into::<f64>::into(c).is_finite())
        });
        if let Some(idx) = bad {
            let p = data[idx].map(Into::<f64>::into);
            return Err(Error::invalid(format!(
                "non-finite {name} [{}, {}, {}] at vertex {idx} (i = {}, j = {})",
                p[0],
                p[1],
                p[2],
                idx / g.nv,
                idx % g.nv
            )));
        }
    }
    Ok(())
}

/// Refuses totals that do not fit a format's 32-bit counts or indices.
pub(super) fn check_u32(total: u128, what: &str, format: &str) -> Result<u32> {
    u32::try_from(total).map_err(|_| {
        Error::invalid(format!(
            "{total} {what} do not fit the 32-bit counts of the {format} format; use coarser grids"
        ))
    })
}

/// Checks a mesh before anything is written: structure ([`TriMesh::check`]), at least one
/// triangle, finite positions, normals and texture coordinates.
pub(super) fn check_mesh(mesh: &TriMesh) -> Result<()> {
    mesh.check().map_err(|e| Error::invalid(e).at("mesh"))?;
    if mesh.triangles.is_empty() {
        return Err(Error::invalid(
            "no triangles to write: the design produced no surface",
        ));
    }
    for (name, data) in [("position", &mesh.positions), ("normal", &mesh.normals)] {
        let bad = crate::mesh::first_bad(data, |p| {
            !(p[0].is_finite() & p[1].is_finite() & p[2].is_finite())
        });
        if let Some(idx) = bad {
            let p = data[idx];
            return Err(Error::invalid(format!(
                "non-finite {name} [{}, {}, {}] at vertex {idx}",
                p[0], p[1], p[2]
            ))
            .at("mesh"));
        }
    }
    if let Some(idx) = mesh
        .uv
        .iter()
        .position(|p| !p.iter().all(|c| c.is_finite()))
    {
        return Err(Error::invalid(format!("non-finite uv at vertex {idx}")).at("mesh"));
    }
    Ok(())
}
