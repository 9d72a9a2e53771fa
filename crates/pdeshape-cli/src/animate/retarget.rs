//! What the extra outputs take from the one pass over the frames (`Collector`): the mesh given
//! to `--retarget`, read and anchored on the first frame, followed through every frame, and each
//! frame's overlays for the pictures.

use super::load::Animated;
use super::Args;
use crate::common::CliError;
use pdeshape::anim::{self, Retarget};
use pdeshape::fit::{MeshFormat, MeshRead};
use pdeshape::render::{self as pic, Polyline};
use std::path::Path;

/// The mesh to re-target, in the units the file states (the caller puts it in the design's).
fn read_mesh(path: &Path) -> Result<MeshRead, CliError> {
    let shown = path.display();
    let bytes = crate::fit::read_mesh_bytes(path, &format!("--retarget {shown}"))?;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let format = MeshFormat::from_extension(&ext)
        .ok_or_else(|| CliError::input(MeshFormat::unknown(&format!("--retarget {shown}"))))?;
    crate::fit::read_mesh(path, &format!("--retarget {shown}"), &bytes, format)
}

/// What the extra outputs take from the one pass over the frames: the re-targeted mesh's frames
/// and the overlays (condition curves) of every frame for the pictures. The pictures themselves
/// are drawn after the pass, from the frames' welded meshes, framed by the box around all of
/// them.
pub(super) struct Collector {
    pub(super) retarget: Option<Retarget>,
    overlays: Option<Vec<Vec<Polyline>>>,
}

impl Collector {
    /// Reads the mesh to re-target (anchored on the design at the first time) before any frame
    /// is solved.
    pub(super) fn new(args: &Args, l: &Animated, times: &[f64]) -> Result<Collector, CliError> {
        let located = |e: pdeshape::Error| l.design.error(&e);
        let retarget = match &args.retarget {
            Some(path) => {
                let read = read_mesh(path)?;
                let spec = l.anim.spec_at(times[0]).map_err(located)?;
                let mesh = read.mesh_in(spec.units.unwrap_or_default());
                let compiled = pdeshape::design::compile(&spec).map_err(located)?;
                let r = Retarget::new(
                    compiled.solved(),
                    &mesh.positions,
                    mesh.triangles,
                    l.anim.time(),
                )
                .map_err(|e| CliError::input(format!("--retarget {}: {e}", path.display())))?;
                Some(r)
            }
            None => None,
        };
        let pictures = args.apng.is_some()
            || args.gif.is_some()
            || args.contact_sheet.is_some()
            || args.frames_dir.is_some();
        Ok(Collector {
            retarget,
            overlays: pictures.then(Vec::new),
        })
    }

    /// Takes what it needs of a frame (called for every frame, in order).
    pub(super) fn frame(&mut self, f: &anim::Frame) -> pdeshape::Result<()> {
        if let Some(r) = self.retarget.as_mut() {
            r.push(f.t, f.solved)?;
        }
        if let Some(o) = self.overlays.as_mut() {
            o.push(pic::overlay_lines(&f.solved.overlays()));
        }
        Ok(())
    }

    /// The overlays of frame `k` with the box that frames every picture alike.
    pub(super) fn overlays(&self, k: usize, boxed: &Polyline) -> Vec<Polyline> {
        let mut o = self
            .overlays
            .as_ref()
            .and_then(|o| o.get(k).cloned())
            .unwrap_or_default();
        o.push(boxed.clone());
        o
    }
}
