//! Writing a solved design in any mesh format: the grids welded into one mesh (GLB straight
//! from the grids through the weld's plan), a trimmed design as its trimmed triangle mesh, CSV
//! samples.

use crate::design::{Export, SolvedDesign};
use crate::mesh::GridMesh;
use crate::mesh_write::{self as mesh, Format, MeshInfo};
use crate::{Error, Result};
use std::io::Write;

/// A solved design written in a mesh format: the writing methods of [`SolvedDesign`].
pub trait WriteDesign {
    /// Tessellates (or samples, for CSV) every surface on an `nu × nv` grid and writes them in
    /// `format` with the default [`Export`] options: patches joined, as designed (`+Z` up, or
    /// `+Y` for glTF), scale 1. Returns the grids when it made them (for a picture of the same
    /// grid).
    fn write(
        &self,
        format: Format,
        nu: usize,
        nv: usize,
        w: &mut dyn Write,
    ) -> Result<Option<Vec<GridMesh>>>;

    /// [`WriteDesign::write`] with export options. A design with `[[trims]]` is written as its
    /// trimmed triangle mesh ([`SolvedDesign::tri_mesh`]); CSV, which stores full grids, is
    /// refused for it.
    fn write_with(
        &self,
        format: Format,
        nu: usize,
        nv: usize,
        export: &Export,
        w: &mut dyn Write,
    ) -> Result<Option<Vec<GridMesh>>>;

    /// The design's grids written in a mesh format as [`SolvedDesign::weld`] welds them (see
    /// [`mesh::write_welded`]: a GLB is written without building the welded mesh).
    fn write_grids(
        &self,
        format: Format,
        grids: &[GridMesh],
        export: &Export,
        w: &mut dyn Write,
    ) -> Result<()>;

    /// What a mesh file records about this design: its title and units, with the export's
    /// scale and up axis.
    fn mesh_info(&self, export: &Export) -> MeshInfo;
}

impl WriteDesign for SolvedDesign {
    fn write(
        &self,
        format: Format,
        nu: usize,
        nv: usize,
        w: &mut dyn Write,
    ) -> Result<Option<Vec<GridMesh>>> {
        self.write_with(format, nu, nv, &Export::default(), w)
    }

    fn write_with(
        &self,
        format: Format,
        nu: usize,
        nv: usize,
        export: &Export,
        w: &mut dyn Write,
    ) -> Result<Option<Vec<GridMesh>>> {
        if !self.trims.is_empty() {
            if format == Format::Csv {
                let t = &self.trims[0];
                return Err(Error::invalid(format!(
                    "csv stores full grids of samples; {}: a trimmed design is written as a \
                     mesh (obj, stl, ply, glb)",
                    self.trim_origin().unwrap_or_default()
                ))
                .at(&t.place));
            }
            mesh::write_mesh(format, &self.tri_mesh(nu, nv)?, &self.mesh_info(export), w)?;
            Ok(None)
        } else if format == Format::Csv {
            mesh::write_csv(&self.samples(nu, nv)?, w)?;
            Ok(None)
        } else {
            let grids = self.meshes(nu, nv)?;
            self.write_grids(format, &grids, export, w)?;
            Ok(Some(grids))
        }
    }

    fn write_grids(
        &self,
        format: Format,
        grids: &[GridMesh],
        export: &Export,
        w: &mut dyn Write,
    ) -> Result<()> {
        let info = self.mesh_info(export);
        mesh::write_welded(
            format,
            grids,
            &self.names(),
            export.weld_options(),
            &info,
            w,
        )
    }

    fn mesh_info(&self, export: &Export) -> MeshInfo {
        MeshInfo {
            title: self.title.clone(),
            units: self.units,
            scale: export.scale,
            up: export.up,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::WriteDesign;

    /// A biharmonic cup: base circle and rim with one derivative curve at both ends.
    const CUP: &str = r#"title = "test"
conditions = [{ u = 0.0, curve = "base" }, { u = 0.0, derivative = 1, curve = "tan" },
  { u = 1.0, curve = "rim" }, { u = 1.0, derivative = 1, curve = "tan" }]
[operator]
kind = "polyharmonic"
order = 2
a = 1.5
[curves.base]
type = "circle"
center = [0, 0, 0]
radius = 1.0
[curves.rim]
type = "circle"
center = [0, 0, 1]
radius = 2
[curves.out]
type = "circle"
center = [0, 0, 2]
radius = 2
[curves.tan]
type = "derivative"
position = "rim"
direction = "out"
scale = 2.0
"#;

    /// `SolvedDesign::write` writes the meshes of every surface in a mesh format, and full-precision
    /// samples for CSV, as the writers do with the design's own meshes and samples.
    #[test]
    fn solved_designs_write_every_format() {
        use crate::design::solve_design;
        use crate::mesh_write::{self as mesh, Format};
        use crate::spec::parse_design;
        let solved = solve_design(&parse_design(CUP).unwrap()).unwrap();
        for format in [
            Format::Obj,
            Format::Stl,
            Format::Ply,
            Format::Glb,
            Format::Csv,
        ] {
            let mut written = Vec::new();
            let meshes = solved.write(format, 5, 12, &mut written).unwrap();
            let mut expected = Vec::new();
            if format == Format::Csv {
                assert!(meshes.is_none());
                mesh::write_csv(&solved.samples(5, 12).unwrap(), &mut expected).unwrap();
            } else {
                let m = solved.meshes(5, 12).unwrap();
                assert_eq!(meshes.as_deref(), Some(&m[..]));
                let export = crate::design::Export::default();
                let welded = solved.weld(&m, &export);
                // One part per surface, named after it.
                let names: Vec<&str> = welded.parts.iter().map(|p| p.name.as_str()).collect();
                assert_eq!(names, solved.names());
                mesh::write_mesh(format, &welded, &solved.mesh_info(&export), &mut expected)
                    .unwrap();
            }
            assert!(!written.is_empty());
            assert_eq!(written, expected, "{format:?}");
        }
        // CSV is not a mesh format.
        let e = mesh::write(Format::Csv, &[], &mut Vec::new()).unwrap_err();
        assert!(e.to_string().contains("write_csv"), "{e}");
    }
}
