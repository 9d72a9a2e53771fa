//! The mesh and its fit side by side, each coloured by its distance to the other.

use super::measure::PointDistances;
use super::mesh::InputMesh;
use crate::mesh::GridMesh;
use crate::render::{
    default_view, diverging_colors, encode_png, render_rgb_colored_with_bar, write_caption,
    BarLayout, ColorBar, RenderOptions,
};
use crate::{Result, Vec3};

/// A PNG picture: the mesh on the left (each vertex coloured by its distance to the fit), the
/// fitted surfaces on the right (each sample coloured by its distance to the mesh), on the
/// cool–warm scale from 0 (blue) through `scale / 2` (grey) to `scale` (the tolerance, in the
/// mesh's units) and beyond (red); captioned "mesh" and "fit", with the scale's colour bar
/// labelled in the mesh's units on the right.
pub fn picture(
    mesh: &InputMesh,
    distances: &PointDistances,
    scale: f64,
    options: &RenderOptions,
) -> Result<Vec<u8>> {
    let view = options.view.unwrap_or_else(default_view).normalize();
    let up = options.up.normalize();
    // Screen right for an eye along `view` looking back at the object.
    let mut right = (-view).cross(&up);
    if right.norm() < 1e-9 {
        right = Vec3::x();
    }
    let right = right.normalize();
    let (lo, hi) = mesh.bounds();
    let width = (hi - lo).iter().cloned().fold(0.0, f64::max);
    let shift = right * (1.2 * width);
    let f = |p: Vec3| [p.x as f32, p.y as f32, p.z as f32];
    let scale = if scale > 0.0 && scale.is_finite() {
        scale
    } else {
        1.0
    };
    let mut meshes = Vec::with_capacity(mesh.triangles.len() + distances.grids.len());
    let mut colors = Vec::with_capacity(meshes.capacity());
    // Each triangle as a 2 × 2 grid with a repeated corner.
    for (t, tri) in mesh.triangles.iter().enumerate() {
        let [a, b, c] = mesh.corners(t);
        let n = (b - a).cross(&(c - a));
        let n = if n.norm() > 0.0 { n.normalize() } else { up };
        meshes.push(GridMesh {
            nu: 2,
            nv: 2,
            periodic_v: false,
            u: vec![0.0, 1.0],
            v: vec![0.0, 1.0],
            positions: vec![f(a), f(b), f(c), f(c)],
            normals: vec![f(n); 4],
        });
        let d: Vec<f64> = [tri[0], tri[1], tri[2], tri[2]]
            .iter()
            .map(|&i| distances.mesh[i as usize])
            .collect();
        colors.push(diverging_colors(&d, 0.0, scale));
    }
    for (g, d) in distances.grids.iter().zip(&distances.fit) {
        meshes.push(GridMesh {
            nu: g.nu,
            nv: g.nv,
            periodic_v: g.periodic_v,
            u: g.u.clone(),
            v: g.v.clone(),
            positions: g
                .positions
                .iter()
                .map(|p| f(Vec3::new(p[0], p[1], p[2]) + shift))
                .collect(),
            normals: g
                .normals
                .iter()
                .map(|n| [n[0] as f32, n[1] as f32, n[2] as f32])
                .collect(),
        });
        colors.push(diverging_colors(d, 0.0, scale));
    }
    let options = RenderOptions {
        view: Some(view),
        ..options.clone()
    };
    let bar = ColorBar {
        title: "distance".into(),
        lo: 0.0,
        hi: scale,
        note: "in the mesh's units; the top is the tolerance".into(),
    };
    let mut rgb = render_rgb_colored_with_bar(&meshes, &colors, &[], &options, &bar)?;
    // The two objects share the picture's left part, the mesh on its left half.
    let layout = BarLayout::new(options.width, options.height);
    let half = layout.panel_x as i64 / 2;
    let top = (4 * layout.scale) as i64;
    for (centre, text) in [(half / 2, "mesh"), (half + half / 2, "fit")] {
        write_caption(&mut rgb, options.width, options.height, centre, top, text);
    }
    encode_png(options.width, options.height, &rgb)
}
