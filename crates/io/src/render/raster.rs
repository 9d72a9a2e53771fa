//! The rasteriser proper: projection, triangle set-up and binning into horizontal bands, then per
//! band (in parallel) depth-buffered triangle filling, shading, overlay lines and the downsampling
//! to sRGB bytes. Screen coordinates are snapped to 1/16 of a sample and edge functions are exact
//! integers, so neighbouring triangles never leave cracks.

use super::Drawable;
use super::{Camera, Polyline};
use crate::Vec3;
use rayon::prelude::*;

/// Output rows per band of work.
const BAND: usize = 8;
/// Sub-sample precision of vertex positions (fixed point, 4 bits).
const SUB: i64 = 16;
const HALF: i64 = SUB / 2;

/// Colours, as sRGB bytes.
const FRONT: [u8; 3] = [178, 190, 206];
const BACK: [u8; 3] = [226, 182, 134];
const SKY: [u8; 3] = [251, 252, 253];
const FLOOR: [u8; 3] = [206, 213, 224];

/// Brightness factor of outline samples (silhouettes and depth steps).
const OUTLINE: f32 = 0.35;

/// Dashes of hidden lines, in output pixels.
const DASH_PERIOD: f32 = 10.0;
const DASH_ON: f32 = 6.0;
/// Opacity of hidden lines on and between dashes.
const HIDDEN_ON: f32 = 0.6;
const HIDDEN_OFF: f32 = 0.15;

/// A projected vertex: fixed-point screen position, depth `d/w`, camera-space normal.
#[derive(Clone, Copy)]
struct Vert {
    x: i64,
    y: i64,
    z: f32,
    n: [f32; 3],
    /// Linear base colour (per-vertex colouring only).
    c: [f32; 3],
}

/// A triangle ready to fill: counter-clockwise on screen (y down), which side faces the eye, a
/// normal to use where the vertex normals cancel, and its sample rows and columns.
#[derive(Clone, Copy)]
struct Tri {
    v: [u32; 3],
    back: bool,
    flat: [f32; 3],
    y0: u32,
    y1: u32,
    x0: u32,
    x1: u32,
}

/// A projected polyline point: screen position (samples), depth, arc length (output pixels).
#[derive(Clone, Copy)]
struct LinePoint {
    x: f32,
    y: f32,
    z: f32,
    s: f32,
}

struct Line {
    points: Vec<LinePoint>,
    closed: bool,
    color: [f32; 3],
    /// Half width in samples.
    half: f32,
}

fn srgb_to_linear(c: u8) -> f32 {
    let c = c as f32 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn linear3(c: [u8; 3]) -> [f32; 3] {
    c.map(srgb_to_linear)
}

const LUT_SIZE: usize = 4096;

fn srgb_lut() -> Vec<u8> {
    (0..LUT_SIZE)
        .map(|i| {
            let l = i as f64 / (LUT_SIZE - 1) as f64;
            let c = if l <= 0.0031308 {
                12.92 * l
            } else {
                1.055 * l.powf(1.0 / 2.4) - 0.055
            };
            (c * 255.0).round().clamp(0.0, 255.0) as u8
        })
        .collect()
}

fn normalize3(v: [f32; 3]) -> [f32; 3] {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if n > 0.0 && n.is_finite() {
        [v[0] / n, v[1] / n, v[2] / n]
    } else {
        [0.0, 0.0, 1.0]
    }
}

fn dot3(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Light set-up in camera coordinates (x right, y up, z towards the eye).
struct Lights {
    key: [f32; 3],
    fill: [f32; 3],
    half: [f32; 3],
    front: [f32; 3],
    back: [f32; 3],
}

impl Lights {
    fn new() -> Lights {
        let key = normalize3([-0.55, 0.6, 0.58]);
        let fill = normalize3([0.8, -0.15, 0.45]);
        let half = normalize3([key[0], key[1], key[2] + 1.0]);
        Lights {
            key,
            fill,
            half,
            front: linear3(FRONT),
            back: linear3(BACK),
        }
    }

    /// Linear colour of a surface sample with normal `n` (towards the visible side).
    fn shade(&self, n: [f32; 3], back: bool) -> [f32; 3] {
        self.shade_base(n, if back { self.back } else { self.front })
    }

    /// Linear colour of a surface sample of base colour `base` with normal `n`.
    fn shade_base(&self, n: [f32; 3], base: [f32; 3]) -> [f32; 3] {
        let n = normalize3(n);
        let kd = dot3(n, self.key).max(0.0);
        let fd = dot3(n, self.fill).max(0.0);
        let ambient = 0.17 + 0.07 * n[1];
        let light = ambient + 0.8 * kd + 0.2 * fd;
        let spec = if kd > 0.0 {
            0.2 * dot3(n, self.half).max(0.0).powi(40)
        } else {
            0.0
        };
        [
            base[0] * light + spec,
            base[1] * light + spec,
            base[2] * light + spec,
        ]
    }
}

/// Draws everything into sRGB bytes of `camera.width/ss × camera.height/ss` pixels.
pub(crate) fn draw<M: Drawable>(meshes: &[M], overlays: &[Polyline], camera: &Camera) -> Vec<u8> {
    draw_colored(meshes, None, overlays, camera)
}

/// [`draw`] with per-vertex sRGB colours (`colors[k][i]` for vertex `i` of mesh `k`) instead of
/// the two side colours; the back side is drawn 25 % darker.
pub(crate) fn draw_colored<M: Drawable>(
    meshes: &[M],
    colors: Option<&[Vec<[u8; 3]>]>,
    overlays: &[Polyline],
    camera: &Camera,
) -> Vec<u8> {
    let ss = camera.supersample;
    let (sw, sh) = (camera.width, camera.height);
    let (ow, oh) = (sw / ss, sh / ss);

    // Vertices of all meshes, projected.
    let mut verts: Vec<Vert> = Vec::with_capacity(meshes.iter().map(|m| m.positions().len()).sum());
    for (k, m) in meshes.iter().enumerate() {
        let start = verts.len();
        verts.resize(
            start + m.positions().len(),
            Vert {
                x: 0,
                y: 0,
                z: 0.0,
                n: [0.0; 3],
                c: [0.0; 3],
            },
        );
        let mesh_colors = colors
            .and_then(|c| c.get(k))
            .filter(|c| c.len() == m.positions().len());
        verts[start..]
            .par_iter_mut()
            .zip(m.positions().par_iter().zip(m.normals().par_iter()))
            .enumerate()
            .for_each(|(i, (v, (p, n)))| {
                let [x, y, z] = camera.project(Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64));
                let nc = if n.iter().all(|c| c.is_finite()) {
                    camera.to_camera(Vec3::new(n[0] as f64, n[1] as f64, n[2] as f64))
                } else {
                    [0.0; 3]
                };
                *v = Vert {
                    x: (x as f64 * SUB as f64).round() as i64,
                    y: (y as f64 * SUB as f64).round() as i64,
                    z,
                    n: nc,
                    c: mesh_colors.map_or([0.0; 3], |c| linear3(c[i])),
                };
            });
    }

    // Triangles, set up in parallel.
    let mut tris: Vec<Tri> = Vec::new();
    let mut offset = 0u32;
    for m in meshes {
        let idx: Vec<[u32; 3]> = m.triangle_list();
        let verts = &verts;
        let pos = m.positions();
        let base = offset;
        tris.par_extend(
            idx.into_par_iter()
                .filter_map(move |t| setup(t, base, verts, pos, camera, sw, sh)),
        );
        offset += m.positions().len() as u32;
    }

    // Bins of triangles per band.
    let band_samples = BAND * ss;
    let nbands = oh.div_ceil(BAND);
    let mut bins: Vec<Vec<u32>> = vec![Vec::new(); nbands];
    for (k, t) in tris.iter().enumerate() {
        // A band also rasterises one sample row above and below it (for outlines).
        let first = (t.y0 as usize).saturating_sub(1) / band_samples;
        let last = ((t.y1 as usize + 1) / band_samples).min(nbands - 1);
        for bin in &mut bins[first..=last] {
            bin.push(k as u32);
        }
    }

    let lines = project_lines(overlays, camera);
    let lights = Lights::new();
    let lut = srgb_lut();
    let sky = linear3(SKY);
    let floor = linear3(FLOOR);
    let bias = camera.line_bias();
    let edge = camera.edge_threshold();

    let mut out = vec![0u8; 3 * ow * oh];
    out.par_chunks_mut(3 * ow * BAND).enumerate().for_each_init(
        || Scratch::new(sw * (band_samples + 2)),
        |scratch, (band, chunk)| {
            let rows = chunk.len() / (3 * ow) * ss;
            let y0 = band * band_samples;
            scratch.clear(sw * (rows + 2));
            let (lo, hi) = (y0.saturating_sub(1), (y0 + rows + 1).min(sh));
            let rows_of_band = BandRows { y0, lo, hi, sw };
            for &k in &bins[band] {
                fill(
                    &tris[k as usize],
                    &verts,
                    scratch,
                    &rows_of_band,
                    colors.is_some(),
                );
            }
            // Shading and background.
            for r in 0..rows {
                let t = (y0 + r) as f32 / sh.max(1) as f32;
                let bg = [
                    sky[0] + (floor[0] - sky[0]) * t,
                    sky[1] + (floor[1] - sky[1]) * t,
                    sky[2] + (floor[2] - sky[2]) * t,
                ];
                let y = y0 + r;
                let row = (r + 1) * sw;
                for x in 0..sw {
                    let i = row + x;
                    let d = scratch.depth[i];
                    scratch.color[i] = if d > 0.0 {
                        let c = if colors.is_some() {
                            let k = if scratch.back[i] { 0.75 } else { 1.0 };
                            lights.shade_base(scratch.normal[i], scratch.base[i].map(|x| x * k))
                        } else {
                            lights.shade(scratch.normal[i], scratch.back[i])
                        };
                        // Outline: a neighbour sample shows the background or a surface
                        // much farther away.
                        // 1/e > 1/d + edge, for depths e ≥ 0 (0 being the background).
                        let limit = d / (1.0 + edge * d);
                        let far = |j: usize| scratch.depth[j] < limit;
                        let outline = (x > 0 && far(i - 1))
                            || (x + 1 < sw && far(i + 1))
                            || (y > 0 && far(i - sw))
                            || (y + 1 < sh && far(i + sw));
                        if outline {
                            c.map(|v| v * OUTLINE)
                        } else {
                            c
                        }
                    } else {
                        bg
                    };
                }
            }
            for line in &lines {
                draw_line(line, scratch, y0, rows, sw, ss, bias);
            }
            // Average the samples of each pixel, then encode.
            let norm = 1.0 / (ss * ss) as f32;
            for (r, row) in chunk.chunks_mut(3 * ow).enumerate() {
                for (c, px) in row.chunks_mut(3).enumerate() {
                    let mut acc = [0.0f32; 3];
                    for dy in 0..ss {
                        let base = (r * ss + dy + 1) * sw + c * ss;
                        for s in &scratch.color[base..base + ss] {
                            acc[0] += s[0];
                            acc[1] += s[1];
                            acc[2] += s[2];
                        }
                    }
                    for k in 0..3 {
                        let l = (acc[k] * norm).clamp(0.0, 1.0);
                        px[k] = lut[(l * (LUT_SIZE - 1) as f32 + 0.5) as usize];
                    }
                }
            }
        },
    );
    out
}

/// Per-band buffers of samples.
struct Scratch {
    depth: Vec<f32>,
    normal: Vec<[f32; 3]>,
    back: Vec<bool>,
    color: Vec<[f32; 3]>,
    cover: Vec<f32>,
    /// Interpolated base colours (per-vertex colouring only).
    base: Vec<[f32; 3]>,
}

impl Scratch {
    fn new(n: usize) -> Scratch {
        Scratch {
            depth: vec![0.0; n],
            normal: vec![[0.0; 3]; n],
            back: vec![false; n],
            color: vec![[0.0; 3]; n],
            cover: vec![0.0; n],
            base: vec![[0.0; 3]; n],
        }
    }

    fn clear(&mut self, n: usize) {
        self.depth[..n].fill(0.0);
        self.cover[..n].fill(0.0);
    }
}

/// Sample index range `[lo, hi]` whose centres `i + ½` lie within fixed-point `[a, b]`.
fn sample_range(a: i64, b: i64, limit: usize) -> Option<(u32, u32)> {
    // Centre of sample i is SUB·i + HALF.
    let lo = (a - HALF + SUB - 1).div_euclid(SUB).max(0);
    let hi = (b - HALF).div_euclid(SUB).min(limit as i64 - 1);
    (lo <= hi).then_some((lo as u32, hi as u32))
}

fn setup(
    t: [u32; 3],
    base: u32,
    verts: &[Vert],
    pos: &[[f32; 3]],
    camera: &Camera,
    sw: usize,
    sh: usize,
) -> Option<Tri> {
    let [a, b, c] = t.map(|i| verts[(base + i) as usize]);
    let area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    if area == 0 {
        return None;
    }
    let (x0, x1) = sample_range(a.x.min(b.x).min(c.x), a.x.max(b.x).max(c.x), sw)?;
    let (y0, y1) = sample_range(a.y.min(b.y).min(c.y), a.y.max(b.y).max(c.y), sh)?;
    // Which side of the surface faces the eye: the geometric normal (b − a) × (c − a) of the
    // counter-clockwise quad order points to the eye when the screen winding (y down) is
    // clockwise; the normals' side is "front" unless the stored normals disagree with the winding.
    let p = |i: u32| {
        let q = pos[i as usize];
        Vec3::new(q[0] as f64, q[1] as f64, q[2] as f64)
    };
    let g = (p(t[1]) - p(t[0])).cross(&(p(t[2]) - p(t[0])));
    let gc = camera.to_camera(g);
    let ns = [0, 1, 2].map(|k| a.n[k] + b.n[k] + c.n[k]);
    let agree = dot3(gc, ns) >= 0.0;
    let winding_visible = area < 0;
    let back = winding_visible != agree;
    let mut flat = normalize3(gc);
    if flat[2] < 0.0 {
        flat = flat.map(|x| -x);
    }
    let v = if area > 0 {
        [base + t[0], base + t[1], base + t[2]]
    } else {
        [base + t[0], base + t[2], base + t[1]]
    };
    Some(Tri {
        v,
        back,
        flat,
        y0,
        y1,
        x0,
        x1,
    })
}

/// The sample rows a band's triangles are filled into: the band starts at sample row `y0` (row
/// `y` of the picture is row `y + 1 − y0` of the band's buffers), triangles are drawn into rows
/// `[lo, hi)`, and a row has `sw` samples.
struct BandRows {
    y0: usize,
    lo: usize,
    hi: usize,
    sw: usize,
}

/// Fills one triangle into the band's sample rows `band`.
fn fill(t: &Tri, verts: &[Vert], s: &mut Scratch, band: &BandRows, colored: bool) {
    let BandRows { y0, lo, hi, sw } = *band;
    let ylo = (t.y0 as usize).max(lo);
    let yhi = (t.y1 as usize).min(hi - 1);
    if ylo > yhi {
        return;
    }
    let [a, b, c] = t.v.map(|i| verts[i as usize]);
    let area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    let inv = 1.0 / area as f32;
    let sign = if t.back { -1.0f32 } else { 1.0 };
    let px0 = t.x0 as i64 * SUB + HALF;
    for y in ylo..=yhi {
        let py = y as i64 * SUB + HALF;
        let mut e0 = (c.x - b.x) * (py - b.y) - (c.y - b.y) * (px0 - b.x);
        let mut e1 = (a.x - c.x) * (py - c.y) - (a.y - c.y) * (px0 - c.x);
        let mut e2 = (b.x - a.x) * (py - a.y) - (b.y - a.y) * (px0 - a.x);
        let d0 = -(c.y - b.y) * SUB;
        let d1 = -(a.y - c.y) * SUB;
        let d2 = -(b.y - a.y) * SUB;
        let row = (y + 1 - y0) * sw;
        for x in t.x0 as usize..=t.x1 as usize {
            if e0 >= 0 && e1 >= 0 && e2 >= 0 {
                let (wa, wb, wc) = (e0 as f32 * inv, e1 as f32 * inv, e2 as f32 * inv);
                let z = wa * a.z + wb * b.z + wc * c.z;
                let i = row + x;
                if z > s.depth[i] {
                    s.depth[i] = z;
                    let mut n = [0, 1, 2].map(|k| sign * (wa * a.n[k] + wb * b.n[k] + wc * c.n[k]));
                    if dot3(n, n) < 1e-8 {
                        n = t.flat;
                    }
                    s.normal[i] = n;
                    s.back[i] = t.back;
                    if colored {
                        s.base[i] = [0, 1, 2].map(|k| wa * a.c[k] + wb * b.c[k] + wc * c.c[k]);
                    }
                }
            }
            e0 += d0;
            e1 += d1;
            e2 += d2;
        }
    }
}

fn project_lines(overlays: &[Polyline], camera: &Camera) -> Vec<Line> {
    let ss = camera.supersample as f32;
    let max_width = (camera.width.max(camera.height)) as f32 / ss;
    overlays
        .iter()
        .filter(|o| o.width > 0.0 && !o.points.is_empty())
        .map(|o| {
            let mut s = 0.0f32;
            let mut prev: Option<LinePoint> = None;
            let points = o
                .points
                .iter()
                .map(|&p| {
                    let [x, y, z] = camera.project(p);
                    if let Some(q) = prev {
                        s += ((x - q.x).powi(2) + (y - q.y).powi(2)).sqrt() / ss;
                    }
                    let lp = LinePoint { x, y, z, s };
                    prev = Some(lp);
                    lp
                })
                .collect();
            Line {
                points,
                closed: o.closed,
                color: linear3(o.color),
                half: 0.5 * o.width.min(max_width) * ss,
            }
        })
        .collect()
}

/// Draws a polyline into the band: coverage from the distance of each sample centre to the nearest
/// segment, full opacity where the line is in front of the surface, faded dashes where hidden.
fn draw_line(
    line: &Line,
    s: &mut Scratch,
    y0: usize,
    rows: usize,
    sw: usize,
    ss: usize,
    bias: f32,
) {
    let pts = &line.points;
    let n = pts.len();
    let nseg = if n == 1 {
        1
    } else if line.closed && n > 2 {
        n
    } else {
        n - 1
    };
    let reach = line.half + 1.0;
    let (mut bx0, mut bx1, mut by0, mut by1) = (usize::MAX, 0usize, usize::MAX, 0usize);
    for k in 0..nseg {
        let p = pts[k];
        let mut q = pts[(k + 1) % n];
        if line.closed && k + 1 == n {
            // The closing segment continues the arc length.
            let len = ((q.x - p.x).powi(2) + (q.y - p.y).powi(2)).sqrt() / ss as f32;
            q.s = p.s + len;
        }
        let ylo = (p.y.min(q.y) - reach).floor().max(y0 as f32);
        let yhi = (p.y.max(q.y) + reach).ceil().min((y0 + rows) as f32 - 1.0);
        if ylo > yhi {
            continue;
        }
        let xlo = (p.x.min(q.x) - reach).floor().max(0.0);
        let xhi = (p.x.max(q.x) + reach).ceil().min(sw as f32 - 1.0);
        if xlo > xhi {
            continue;
        }
        let (ylo, yhi, xlo, xhi) = (ylo as usize, yhi as usize, xlo as usize, xhi as usize);
        bx0 = bx0.min(xlo);
        bx1 = bx1.max(xhi);
        by0 = by0.min(ylo);
        by1 = by1.max(yhi);
        let (dx, dy) = (q.x - p.x, q.y - p.y);
        let len2 = dx * dx + dy * dy;
        for y in ylo..=yhi {
            let cy = y as f32 + 0.5;
            let row = (y + 1 - y0) * sw;
            for x in xlo..=xhi {
                let cx = x as f32 + 0.5;
                let t = if len2 > 0.0 {
                    (((cx - p.x) * dx + (cy - p.y) * dy) / len2).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let (ex, ey) = (cx - p.x - t * dx, cy - p.y - t * dy);
                let dist = (ex * ex + ey * ey).sqrt();
                let cover = (line.half + 0.5 - dist).clamp(0.0, 1.0);
                if cover <= 0.0 {
                    continue;
                }
                let i = row + x;
                let zl = p.z + t * (q.z - p.z);
                let zs = s.depth[i];
                let hidden = zs > 0.0 && 1.0 / zl > 1.0 / zs + bias;
                let alpha = if hidden {
                    let arc = p.s + t * (q.s - p.s);
                    if arc.rem_euclid(DASH_PERIOD) < DASH_ON {
                        HIDDEN_ON
                    } else {
                        HIDDEN_OFF
                    }
                } else {
                    1.0
                };
                let a = cover * alpha;
                if a > s.cover[i] {
                    s.cover[i] = a;
                }
            }
        }
    }
    if bx0 > bx1 {
        return;
    }
    for y in by0..=by1 {
        let row = (y + 1 - y0) * sw;
        for i in row + bx0..=row + bx1 {
            let a = s.cover[i];
            if a > 0.0 {
                let c = &mut s.color[i];
                for (ck, lk) in c.iter_mut().zip(line.color) {
                    *ck += a * (lk - *ck);
                }
                s.cover[i] = 0.0;
            }
        }
    }
}
