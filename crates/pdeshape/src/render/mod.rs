//! Pictures: a small software rasteriser that draws grid meshes shaded, with polylines (boundary
//! curves, spine) over them, and encodes a PNG.

use crate::mesh::GridMesh;
use crate::{Result, Vec3};

/// A polyline drawn over the shaded surface.
#[derive(Clone, Debug)]
pub struct Polyline {
    pub points: Vec<Vec3>,
    pub color: [u8; 3],
    /// Line width in pixels.
    pub width: f32,
    /// Join the last point to the first.
    pub closed: bool,
}

/// View and picture options.
#[derive(Clone, Debug)]
pub struct RenderOptions {
    pub width: u32,
    pub height: u32,
    /// Direction from the object towards the eye; `None` picks a default three-quarter view.
    pub view: Option<Vec3>,
    /// Up direction on screen (default +z).
    pub up: Vec3,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 800,
            height: 600,
            view: None,
            up: Vec3::new(0.0, 0.0, 1.0),
        }
    }
}

/// Renders meshes and overlays into PNG bytes.
pub fn render_png(
    meshes: &[GridMesh],
    overlays: &[Polyline],
    options: &RenderOptions,
) -> Result<Vec<u8>> {
    let _ = (meshes, overlays, options);
    todo!("render")
}
