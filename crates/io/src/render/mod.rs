//! Pictures: a small software rasteriser that draws grid meshes shaded, with polylines (boundary
//! curves, spine) over them, and encodes a PNG.
//!
//! The camera is a mild perspective one (a 30° cone around the bounding sphere of everything drawn),
//! aimed at the centre of the bounding box; the projected points are then scaled and shifted so
//! that everything fits the picture with a 6 % margin. Surfaces are shaded per sample (Phong
//! interpolation of the vertex normals) with a key light from the upper left, a weaker fill light
//! from the right, a sky/ground ambient term and a small specular highlight. The side the normals
//! point to is drawn in a cool grey-blue, the other side in a warm tan, so the inside of a cup reads
//! at once. Silhouettes and depth steps get a thin dark outline. Every picture is rendered with
//! 2 × 2 supersampling in linear light and averaged down.
//! Polylines are drawn over the surface with analytic coverage; where the surface hides them they
//! are still drawn, faded and dashed.

mod anim_picture;
#[cfg(test)]
mod color_tests;
mod colorbar;
mod raster;
#[cfg(test)]
mod tests;
mod text;

pub use anim_picture::{
    contact_sheet, frame_delay, gif_delay, quantize, Apng, ContactSheet, Gif, Quantized,
};
pub(crate) use colorbar::nice_step;
pub(crate) use colorbar::tick_label;
pub use colorbar::{
    nice_ticks, render_png_colored_with_bar, render_rgb_colored_with_bar, robust_range,
    short_label, write_caption, BarLayout, ColorBar, ROBUST_RANGE_RULE,
};

use crate::design::{Overlay, OverlayKind};
use crate::mesh::{GridMesh, TriMesh};
use crate::{Error, Result, Vec3};

/// A polyline drawn over the shaded surface.
#[derive(Clone, Debug)]
pub struct Polyline {
    /// The vertices, in the design's coordinates.
    pub points: Vec<Vec3>,
    /// Line colour (sRGB).
    pub color: [u8; 3],
    /// Line width in pixels.
    pub width: f32,
    /// Join the last point to the first.
    pub closed: bool,
}

/// The colour of each kind of a design's overlays: position curves red, spines blue, trim
/// curves orange.
pub fn overlay_color(kind: OverlayKind) -> [u8; 3] {
    match kind {
        OverlayKind::Curve => [210, 40, 30],
        OverlayKind::Spine => [20, 70, 200],
        OverlayKind::Trim => [230, 140, 20],
    }
}

impl From<&Overlay> for Polyline {
    fn from(o: &Overlay) -> Self {
        Polyline {
            points: o.points.clone(),
            color: overlay_color(o.kind),
            width: 2.0,
            closed: o.closed,
        }
    }
}

/// A design's overlays ([`crate::design::SolvedDesign::overlays`]) as the lines a picture draws.
pub fn overlay_lines(overlays: &[Overlay]) -> Vec<Polyline> {
    overlays.iter().map(Polyline::from).collect()
}

/// View and picture options.
#[derive(Clone, Debug)]
pub struct RenderOptions {
    /// Picture width in pixels (1 to [`MAX_SIDE`]).
    pub width: u32,
    /// Picture height in pixels (1 to [`MAX_SIDE`]).
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

/// Largest picture side, in pixels.
pub const MAX_SIDE: u32 = 16384;

/// Samples per pixel along each axis.
const SUPERSAMPLE: usize = 2;
/// Full opening angle of the view cone around the bounding sphere (degrees).
const FIELD_OF_VIEW_DEG: f64 = 30.0;
/// Empty border on each side, as a fraction of the picture size.
const MARGIN: f64 = 0.06;

/// The default view direction (from the object towards the eye): a three-quarter view from the
/// front right and above, `(1, −1.4, 0.9)` normalised, meant with +z up.
pub fn default_view() -> Vec3 {
    Vec3::new(1.0, -1.4, 0.9).normalize()
}

/// Renders meshes and overlays into PNG bytes (8-bit RGB, `options.width × options.height`).
///
/// Refuses sizes of 0 or above [`MAX_SIDE`], non-finite positions or overlay points, negative or
/// non-finite line widths, a zero or non-finite `view` or `up`, and meshes whose arrays do not
/// match `nu × nv`. Empty input gives the background alone.
pub fn render_png(
    meshes: &[GridMesh],
    overlays: &[Polyline],
    options: &RenderOptions,
) -> Result<Vec<u8>> {
    let rgb = render_rgb(meshes, overlays, options)?;
    encode_png(options.width, options.height, &rgb)
}

/// Renders meshes and overlays into raw pixels: `3 · width · height` bytes, rows top to bottom,
/// sRGB. Same checks as [`render_png`].
pub fn render_rgb(
    meshes: &[GridMesh],
    overlays: &[Polyline],
    options: &RenderOptions,
) -> Result<Vec<u8>> {
    check_size(options)?;
    validate(meshes, overlays)?;
    let camera = Camera::fit(meshes, overlays, options)?;
    Ok(raster::draw(meshes, overlays, &camera))
}

/// [`render_png`] with every surface vertex coloured: `colors[k][i]` is the sRGB colour of vertex
/// `i` of `meshes[k]` (for instance [`diverging_colors`] of a curvature), interpolated across the
/// triangles and lit like the plain surface; the side the normals point away from is drawn 25 %
/// darker. Refuses colour lists whose lengths do not match the meshes.
pub fn render_png_colored(
    meshes: &[GridMesh],
    colors: &[Vec<[u8; 3]>],
    overlays: &[Polyline],
    options: &RenderOptions,
) -> Result<Vec<u8>> {
    check_colors(meshes, colors)?;
    check_size(options)?;
    validate(meshes, overlays)?;
    let camera = Camera::fit(meshes, overlays, options)?;
    let rgb = raster::draw_colored(meshes, Some(colors), overlays, &camera);
    encode_png(options.width, options.height, &rgb)
}

/// Refuses colour lists whose number or lengths do not match the meshes.
fn check_colors(meshes: &[GridMesh], colors: &[Vec<[u8; 3]>]) -> Result<()> {
    if colors.len() != meshes.len() {
        return Err(Error::invalid(format!(
            "{} colour lists for {} meshes",
            colors.len(),
            meshes.len()
        )));
    }
    for (k, (c, m)) in colors.iter().zip(meshes).enumerate() {
        if c.len() != m.len() {
            return Err(Error::invalid(format!(
                "mesh {k} has {} vertices but {} colours",
                m.len(),
                c.len()
            )));
        }
    }
    Ok(())
}

/// Refuses picture sizes of 0 or above [`MAX_SIDE`].
fn check_size(options: &RenderOptions) -> Result<()> {
    let (w, h) = (options.width, options.height);
    if w == 0 || h == 0 || w > MAX_SIDE || h > MAX_SIDE {
        return Err(Error::invalid(format!(
            "picture size {w} × {h}: each side must be between 1 and {MAX_SIDE} pixels"
        ))
        .at("size"));
    }
    crate::memory::check_items(
        w as u64 * h as u64,
        crate::memory::BYTES_PER_PIXEL,
        &format!("a {w} × {h} picture"),
        "size",
    )?;
    Ok(())
}

/// The cool–warm diverging colour map: `lo` blue `(59, 76, 192)`, the middle of `[lo, hi]` light
/// grey `(221, 221, 221)`, `hi` red `(180, 4, 38)`, linear in between (in sRGB bytes); values
/// outside `[lo, hi]` take the end colours and non-finite values a neutral grey
/// `(128, 128, 128)`. Assumes `lo < hi`.
pub fn diverging_colors(values: &[f64], lo: f64, hi: f64) -> Vec<[u8; 3]> {
    const LOW: [f64; 3] = [59.0, 76.0, 192.0];
    const MID: [f64; 3] = [221.0, 221.0, 221.0];
    const HIGH: [f64; 3] = [180.0, 4.0, 38.0];
    values
        .iter()
        .map(|&x| {
            if !x.is_finite() {
                return [128, 128, 128];
            }
            let t = ((x - lo) / (hi - lo)).clamp(0.0, 1.0);
            let (a, b, s) = if t < 0.5 {
                (LOW, MID, 2.0 * t)
            } else {
                (MID, HIGH, 2.0 * t - 1.0)
            };
            [0, 1, 2].map(|k| (a[k] + (b[k] - a[k]) * s).round() as u8)
        })
        .collect()
}

/// Encodes `3 · width · height` bytes of RGB8 pixels as a PNG.
pub fn encode_png(width: u32, height: u32, rgb: &[u8]) -> Result<Vec<u8>> {
    let expected = 3 * width as usize * height as usize;
    if rgb.len() != expected || width == 0 || height == 0 {
        return Err(Error::invalid(format!(
            "{} bytes of pixels for a {width} × {height} RGB picture (expected {expected})",
            rgb.len()
        ))
        .at("size"));
    }
    let mut bytes = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut bytes, width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::Fast);
        let mut writer = encoder
            .write_header()
            .map_err(|e| Error::io(format!("PNG header: {e}")))?;
        writer
            .write_image_data(rgb)
            .map_err(|e| Error::io(format!("PNG data: {e}")))?;
        writer
            .finish()
            .map_err(|e| Error::io(format!("PNG end: {e}")))?;
    }
    Ok(bytes)
}

/// What the rasteriser draws: vertices with normals, and triangles over them (a grid's or an
/// indexed mesh's).
pub trait Drawable: Sync {
    /// Vertex positions.
    fn positions(&self) -> &[[f32; 3]];
    /// Vertex normals.
    fn normals(&self) -> &[[f32; 3]];
    /// The triangles, counter-clockwise seen from the normals.
    fn triangle_list(&self) -> Vec<[u32; 3]>;
    /// Structural problems (array lengths, indices), if any.
    fn structure(&self) -> std::result::Result<(), String>;
    /// How a message names vertex `i`.
    fn vertex_name(&self, i: usize) -> String {
        i.to_string()
    }
}

impl Drawable for GridMesh {
    fn positions(&self) -> &[[f32; 3]] {
        &self.positions
    }
    fn normals(&self) -> &[[f32; 3]] {
        &self.normals
    }
    fn triangle_list(&self) -> Vec<[u32; 3]> {
        self.triangles().collect()
    }
    fn structure(&self) -> std::result::Result<(), String> {
        let n = self.nu.checked_mul(self.nv);
        if n != Some(self.positions.len()) || self.normals.len() != self.positions.len() {
            return Err(format!(
                "{} positions and {} normals for a {} × {} grid",
                self.positions.len(),
                self.normals.len(),
                self.nu,
                self.nv
            ));
        }
        Ok(())
    }
    fn vertex_name(&self, i: usize) -> String {
        format!("({}, {})", i / self.nv.max(1), i % self.nv.max(1))
    }
}

impl Drawable for TriMesh {
    fn positions(&self) -> &[[f32; 3]] {
        &self.positions
    }
    fn normals(&self) -> &[[f32; 3]] {
        &self.normals
    }
    fn triangle_list(&self) -> Vec<[u32; 3]> {
        self.triangles.clone()
    }
    fn structure(&self) -> std::result::Result<(), String> {
        self.check()
    }
}

/// [`render_rgb`] of an indexed triangle mesh (a welded animation frame): raw sRGB pixels.
pub fn render_rgb_tri(
    mesh: &TriMesh,
    overlays: &[Polyline],
    options: &RenderOptions,
) -> Result<Vec<u8>> {
    check_size(options)?;
    let meshes = std::slice::from_ref(mesh);
    validate(meshes, overlays)?;
    let camera = Camera::fit(meshes, overlays, options)?;
    Ok(raster::draw(meshes, overlays, &camera))
}

/// [`render_png`] of an indexed triangle mesh (a trimmed design).
pub fn render_png_tri(
    mesh: &TriMesh,
    overlays: &[Polyline],
    options: &RenderOptions,
) -> Result<Vec<u8>> {
    let rgb = render_rgb_tri(mesh, overlays, options)?;
    encode_png(options.width, options.height, &rgb)
}

fn validate<M: Drawable>(meshes: &[M], overlays: &[Polyline]) -> Result<()> {
    for (k, m) in meshes.iter().enumerate() {
        let place = format!("meshes[{k}]");
        m.structure().map_err(|e| Error::invalid(e).at(&place))?;
        let n = m.positions().len();
        if n > u32::MAX as usize / 2 {
            return Err(Error::invalid(format!("{n} vertices are too many to draw")).at(&place));
        }
        if let Some(i) = m
            .positions()
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(Error::invalid(format!(
                "non-finite position {:?} at vertex {}",
                m.positions()[i],
                m.vertex_name(i)
            ))
            .at(&format!("{place}.positions[{i}]")));
        }
    }
    let total: usize = meshes.iter().map(|m| m.positions().len()).sum();
    if total > u32::MAX as usize / 2 {
        return Err(Error::invalid(format!("{total} vertices are too many to draw")).at("meshes"));
    }
    for (k, o) in overlays.iter().enumerate() {
        if !o.width.is_finite() || o.width < 0.0 {
            return Err(Error::invalid(format!(
                "line width must be a finite number ≥ 0 (got {})",
                o.width
            ))
            .at(&format!("overlays[{k}].width")));
        }
        if let Some(i) = o
            .points
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            let p = o.points[i];
            return Err(
                Error::invalid(format!("non-finite point ({}, {}, {})", p.x, p.y, p.z))
                    .at(&format!("overlays[{k}].points[{i}]")),
            );
        }
    }
    Ok(())
}

/// A perspective camera fitted to the scene. Screen coordinates are in samples (supersampled
/// pixels), x to the right, y down; depth is kept as `d / w`, `w` being the distance from the eye
/// along the viewing axis and `d` the distance of the eye from the scene centre, so that larger is
/// nearer and values stay near 1 whatever the size of the scene.
#[derive(Clone, Debug)]
pub(crate) struct Camera {
    center: Vec3,
    right: Vec3,
    upward: Vec3,
    toward_eye: Vec3,
    /// Eye distance from the centre.
    dist: f64,
    /// Bounding radius of the scene.
    radius: f64,
    scale: f64,
    ox: f64,
    oy: f64,
    /// Picture size in samples.
    pub(crate) width: usize,
    pub(crate) height: usize,
    pub(crate) supersample: usize,
}

impl Camera {
    fn fit<M: Drawable>(
        meshes: &[M],
        overlays: &[Polyline],
        options: &RenderOptions,
    ) -> Result<Camera> {
        let view = match options.view {
            None => default_view(),
            Some(v) => {
                let n = v.norm();
                if !(n.is_finite() && n > 0.0) {
                    return Err(Error::invalid(format!(
                        "view direction ({}, {}, {}) must be finite and non-zero",
                        v.x, v.y, v.z
                    ))
                    .at("view"));
                }
                v / n
            }
        };
        let up = options.up;
        let un = up.norm();
        if !(un.is_finite() && un > 0.0) {
            return Err(Error::invalid(format!(
                "up direction ({}, {}, {}) must be finite and non-zero",
                up.x, up.y, up.z
            ))
            .at("up"));
        }
        let mut up = up / un;
        if up.cross(&view).norm() < 1e-6 {
            // Looking along the up direction: take the world axis least aligned with the view.
            let axes = [Vec3::z(), Vec3::y(), Vec3::x()];
            up = axes
                .into_iter()
                .min_by(|a, b| a.dot(&view).abs().total_cmp(&b.dot(&view).abs()))
                .unwrap_or(Vec3::z());
        }
        let right = up.cross(&view).normalize();
        let upward = view.cross(&right);

        // Bounding box of everything drawn.
        let mut lo = Vec3::repeat(f64::INFINITY);
        let mut hi = Vec3::repeat(f64::NEG_INFINITY);
        let mut add = |p: Vec3| {
            lo = lo.inf(&p);
            hi = hi.sup(&p);
        };
        for m in meshes {
            let (a, b) = mesh_box(m);
            if a.x <= b.x {
                add(a);
                add(b);
            }
        }
        for o in overlays {
            for &p in &o.points {
                add(p);
            }
        }
        let ss = SUPERSAMPLE;
        let width = options.width as usize * ss;
        let height = options.height as usize * ss;
        let empty = lo.x > hi.x;
        let (center, radius) = if empty {
            (Vec3::zeros(), 1.0)
        } else {
            let c = 0.5 * (lo + hi);
            let r = 0.5 * (hi - lo).norm();
            if !r.is_finite() {
                return Err(Error::invalid(format!(
                    "the scene spans from ({}, {}, {}) to ({}, {}, {}), too far to draw",
                    lo.x, lo.y, lo.z, hi.x, hi.y, hi.z
                )));
            }
            // A single point still gets a view around it.
            let r = if r > 0.0 { r } else { c.norm().max(1.0) * 1e-3 };
            (c, r)
        };
        let dist = radius / (0.5 * FIELD_OF_VIEW_DEG.to_radians()).sin();
        let mut cam = Camera {
            center,
            right,
            upward,
            toward_eye: view,
            dist,
            radius,
            scale: 1.0,
            ox: 0.0,
            oy: 0.0,
            width,
            height,
            supersample: ss,
        };
        // Extent of the projected points, in units of the image plane at distance 1.
        let (mut umin, mut umax, mut vmin, mut vmax) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        let mut extend = |(u, v): (f64, f64)| {
            umin = umin.min(u);
            umax = umax.max(u);
            vmin = vmin.min(v);
            vmax = vmax.max(v);
        };
        for m in meshes {
            for p in m.positions() {
                extend(cam.plane(Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64)));
            }
        }
        for o in overlays {
            for &p in &o.points {
                extend(cam.plane(p));
            }
        }
        let (wf, hf) = (width as f64, height as f64);
        if umin > umax {
            cam.scale = wf.min(hf);
            cam.ox = 0.5 * wf;
            cam.oy = 0.5 * hf;
            return Ok(cam);
        }
        let du = umax - umin;
        let dv = vmax - vmin;
        let tiny = 1e-9 * radius / dist;
        let avail = 1.0 - 2.0 * MARGIN;
        let sx = if du > tiny {
            avail * wf / du
        } else {
            f64::INFINITY
        };
        let sy = if dv > tiny {
            avail * hf / dv
        } else {
            f64::INFINITY
        };
        let mut scale = sx.min(sy);
        if !scale.is_finite() {
            // Everything on one point of the screen: show the bounding sphere.
            scale = avail * wf.min(hf) * dist / (2.0 * radius);
        }
        cam.scale = scale;
        cam.ox = 0.5 * wf - scale * 0.5 * (umin + umax);
        cam.oy = 0.5 * hf + scale * 0.5 * (vmin + vmax);
        Ok(cam)
    }

    /// Perspective image of `p` on the plane at distance 1 from the eye (x right, y up).
    fn plane(&self, p: Vec3) -> (f64, f64) {
        let q = p - self.center;
        let w = self.dist - q.dot(&self.toward_eye);
        (q.dot(&self.right) / w, q.dot(&self.upward) / w)
    }

    /// Screen position (samples, y down) and depth `d / w` of `p`.
    pub(crate) fn project(&self, p: Vec3) -> [f32; 3] {
        let q = p - self.center;
        let w = self.dist - q.dot(&self.toward_eye);
        let x = self.ox + self.scale * q.dot(&self.right) / w;
        let y = self.oy - self.scale * q.dot(&self.upward) / w;
        [x as f32, y as f32, (self.dist / w) as f32]
    }

    /// A world vector in camera coordinates (x right, y up, z towards the eye).
    pub(crate) fn to_camera(&self, v: Vec3) -> [f32; 3] {
        [
            v.dot(&self.right) as f32,
            v.dot(&self.upward) as f32,
            v.dot(&self.toward_eye) as f32,
        ]
    }

    /// Depth tolerance for overlays, in units of `w / d`: a line this close behind the surface
    /// (1 % of the scene radius) still counts as in front.
    pub(crate) fn line_bias(&self) -> f32 {
        (0.01 * self.radius / self.dist) as f32
    }

    /// Depth step between neighbouring samples (3 % of the scene radius, in units of `w / d`)
    /// beyond which the nearer sample is drawn as part of an outline.
    pub(crate) fn edge_threshold(&self) -> f32 {
        (0.03 * self.radius / self.dist) as f32
    }
}

fn mesh_box<M: Drawable>(m: &M) -> (Vec3, Vec3) {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in m.positions() {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (
        Vec3::new(lo[0] as f64, lo[1] as f64, lo[2] as f64),
        Vec3::new(hi[0] as f64, hi[1] as f64, hi[2] as f64),
    )
}
