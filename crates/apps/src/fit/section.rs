//! Plane sections of a closed triangle mesh, and their periodic curves.
//!
//! A plane `{x : (x − o)·a = h}` cuts every triangle whose corners lie on both sides into a
//! segment between two crossed edges. Corners exactly on the plane count as above it (a
//! symbolic perturbation of `h`), so every crossed edge is crossed once and, on a closed
//! edge-manifold mesh, belongs to exactly two crossed triangles: chaining segments through
//! shared edges gives closed loops.
//!
//! A loop is turned into a curve `C(v)` by angle about its area centroid `c`: `C(v)` is the
//! farthest point of the loop on the ray from `c` in direction `cos v e₁ + sin v e₂`, where
//! `(e₁, e₂, a)` is one right-handed frame for every section. So `v = 0` lies on the same side
//! in every section and `v` turns the same way (counter-clockwise about `a`): consecutive
//! sections are joined without twist. A loop that is not star-shaped about its centroid (rays
//! that meet it more than once over more than a small share of the turn) is refused.

use super::frame::FileFrame;
use crate::fit::mesh::InputMesh;
use crate::{Error, Result, Vec3, TAU};
use std::collections::HashMap;

/// One right-handed frame `(e₁, e₂, axis)` for the sections.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AxisFrame {
    /// A point on the axis: heights are measured from it.
    pub origin: Vec3,
    /// Unit vector in the section planes: the direction of angle 0 about a section's centroid.
    pub e1: Vec3,
    /// Unit vector in the section planes, `axis × e₁`: the direction of angle π/2.
    pub e2: Vec3,
    /// Unit normal of the section planes; heights are measured along it.
    pub axis: Vec3,
}

impl AxisFrame {
    /// The height of `p` along the axis.
    pub fn height(&self, p: &Vec3) -> f64 {
        (p - self.origin).dot(&self.axis)
    }

    /// The section plane at height `h` as messages name it: through its point on the axis,
    /// normal to the axis, in the coordinates of the frame `file`.
    pub fn plane(&self, h: f64, file: FileFrame) -> String {
        file.plane(self.origin + self.axis * h, self.axis)
    }
}

/// Triangles sorted for repeated sectioning along one axis: each triangle's height range.
pub struct Slicer<'m> {
    mesh: &'m InputMesh,
    frame: AxisFrame,
    file: FileFrame,
    heights: Vec<f64>,
}

impl<'m> Slicer<'m> {
    /// Heights of every vertex along `frame.axis`; messages name planes in the coordinates
    /// of the frame `file` (the mesh's file's).
    pub fn new(mesh: &'m InputMesh, frame: AxisFrame, file: FileFrame) -> Self {
        let heights = mesh.positions.iter().map(|p| frame.height(p)).collect();
        Slicer {
            mesh,
            frame,
            file,
            heights,
        }
    }

    /// The frame messages name points in.
    pub fn file(&self) -> FileFrame {
        self.file
    }

    /// The plane at height `h`, as messages name it ([`AxisFrame::plane`]).
    fn plane(&self, h: f64) -> String {
        self.frame.plane(h, self.file)
    }

    /// The frame of the sections.
    pub fn frame(&self) -> &AxisFrame {
        &self.frame
    }

    /// The pieces of the section at height `h`: closed loops and open polylines (which end on
    /// the mesh's boundary), each a list of points in order. Fails if a crossed edge is shared
    /// by three or more crossed triangles (a non-manifold mesh).
    pub fn pieces(&self, h: f64) -> Result<Vec<Piece>> {
        let above = |i: u32| self.heights[i as usize] >= h;
        // For every crossed edge: its point and the (up to two) segments through it.
        let mut edge_index: HashMap<(u32, u32), usize> = HashMap::new();
        let mut points: Vec<Vec3> = Vec::new();
        let mut links: Vec<[usize; 2]> = Vec::new();
        let mut fill: Vec<u8> = Vec::new();
        let mut keys: Vec<(u32, u32)> = Vec::new();
        for t in &self.mesh.triangles {
            let s = t.map(above);
            if s[0] == s[1] && s[1] == s[2] {
                continue;
            }
            let mut ends = [0usize; 2];
            let mut n = 0;
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                if above(a) == above(b) || n == 2 {
                    continue;
                }
                let key = (a.min(b), a.max(b));
                let id = *edge_index.entry(key).or_insert_with(|| {
                    let (pa, pb) = (
                        self.mesh.positions[key.0 as usize],
                        self.mesh.positions[key.1 as usize],
                    );
                    let (ha, hb) = (self.heights[key.0 as usize], self.heights[key.1 as usize]);
                    let w = ((h - ha) / (hb - ha)).clamp(0.0, 1.0);
                    points.push(pa + (pb - pa) * w);
                    links.push([usize::MAX; 2]);
                    fill.push(0);
                    keys.push(key);
                    points.len() - 1
                });
                ends[n] = id;
                n += 1;
            }
            for (x, y) in [(ends[0], ends[1]), (ends[1], ends[0])] {
                if fill[x] >= 2 {
                    return Err(Error::invalid(format!(
                        "the section {} crosses an edge of three or more triangles: the mesh \
                         is not manifold",
                        self.plane(h)
                    )));
                }
                links[x][fill[x] as usize] = y;
                fill[x] += 1;
            }
        }
        let mut seen = vec![false; points.len()];
        let mut pieces = Vec::new();
        // Open polylines first, each from one of its two ends; then the closed loops.
        let starts: Vec<usize> = (0..points.len())
            .filter(|&k| fill[k] == 1)
            .chain((0..points.len()).filter(|&k| fill[k] == 2))
            .collect();
        for start in starts {
            if seen[start] {
                continue;
            }
            let mut ring = vec![points[start]];
            let mut ring_keys = vec![keys[start]];
            seen[start] = true;
            let (mut prev, mut at) = (start, links[start][0]);
            let mut closed = true;
            while at != start {
                seen[at] = true;
                ring.push(points[at]);
                ring_keys.push(keys[at]);
                if fill[at] == 1 {
                    closed = false;
                    break;
                }
                let next = if links[at][0] == prev {
                    links[at][1]
                } else {
                    links[at][0]
                };
                prev = at;
                at = next;
            }
            pieces.push(Piece {
                points: ring,
                closed,
                keys: ring_keys,
            });
        }
        Ok(pieces)
    }

    /// The closed loops of the section at height `h`. Fails if the section has an open piece
    /// (the mesh is open) or crosses a non-manifold edge.
    pub fn loops(&self, h: f64) -> Result<Vec<Piece>> {
        let pieces = self.pieces(h)?;
        if let Some(p) = pieces.iter().find(|p| !p.closed) {
            let q = p.points[0];
            return Err(Error::invalid(format!(
                "the section {} ends at {}: the mesh is open",
                self.plane(h),
                self.file.point(q)
            )));
        }
        Ok(pieces)
    }

    /// The loop of the section at height `h`: without `near`, the section must be a single
    /// loop; with it, the loop whose centroid is nearest to `near` is taken.
    pub fn loop_near(&self, h: f64, near: Option<Vec3>) -> Result<Piece> {
        let loops = self.loops(h)?;
        let k = match (loops.len(), near) {
            (0, _) => {
                return Err(Error::invalid(format!(
                    "the plane {} misses the mesh",
                    self.plane(h)
                )))
            }
            (1, _) => 0,
            (_, Some(p)) => nearest(&loops, p),
            (k, None) => {
                return Err(Error::invalid(format!(
                    "the section {} has {k} separate loops: the automatic mode fits bodies \
                     whose sections along the main axis are single loops (a template names the \
                     planes of each part)",
                    self.plane(h)
                )))
            }
        };
        Ok(loops.into_iter().nth(k).expect("an index of the list"))
    }

    /// The loop of the section at height `h` ([`Slicer::loop_near`]) as a periodic curve
    /// sampled at `samples` equally spaced angles (see the module documentation). Fails, saying
    /// why, if the plane meets the mesh in no loop (or in several without `near`), or if the
    /// loop is not star-shaped.
    pub fn section(&self, h: f64, samples: usize, near: Option<Vec3>) -> Result<Section> {
        let ring = self.loop_near(h, near)?;
        Section::from_loop(&ring.points, &self.frame, h, samples, self.file)
    }

    /// The open profile of the section at height `h` (an open mesh), sampled as an even
    /// periodic curve ([`super::profile`]). Without `near`, the section must be a single open
    /// piece; with it, the piece whose centroid is nearest to `near` is taken.
    pub fn profile(&self, h: f64, samples: usize, near: Option<Vec3>) -> Result<Section> {
        let line = self.open_piece(h, near)?;
        super::profile::from_polyline(&line.points, &self.frame, h, samples, self.file)
    }

    /// The open piece of the section at height `h` (see [`Slicer::profile`]).
    pub fn open_piece(&self, h: f64, near: Option<Vec3>) -> Result<Piece> {
        let pieces = self.pieces(h)?;
        let loops = pieces.iter().filter(|p| p.closed).count();
        let open: Vec<Piece> = pieces.into_iter().filter(|p| !p.closed).collect();
        let line = match (open.len(), near) {
            (0, _) if loops > 0 => {
                return Err(Error::invalid(format!(
                    "the section {} is a closed loop: the mesh is open, but not a sheet whose \
                     sections across its main axis are open profiles (a closed body with a \
                     hole?)",
                    self.plane(h)
                )))
            }
            (0, _) => {
                return Err(Error::invalid(format!(
                    "the plane {} misses the mesh",
                    self.plane(h)
                )))
            }
            (1, _) => 0,
            (_, Some(p)) => nearest(&open, p),
            (k, None) => {
                return Err(Error::invalid(format!(
                    "the section {} has {k} separate pieces: the sheet mode fits sheets whose \
                     sections across the main axis are single profiles (a template names the \
                     planes of each part)",
                    self.plane(h)
                )))
            }
        };
        Ok(open.into_iter().nth(line).expect("an index of the list"))
    }
}

/// The index of the piece whose vertex mean is nearest to `p`.
fn nearest(pieces: &[Piece], p: Vec3) -> usize {
    (0..pieces.len())
        .min_by(|&a, &b| {
            (pieces[a].centre() - p)
                .norm()
                .total_cmp(&(pieces[b].centre() - p).norm())
        })
        .unwrap_or(0)
}

/// A piece of a plane section: a closed loop, or an open polyline between two boundary edges.
#[derive(Clone, Debug, PartialEq)]
pub struct Piece {
    /// The points in order, each on a mesh edge.
    pub points: Vec<Vec3>,
    /// True for a closed loop, false for an open polyline.
    pub closed: bool,
    /// The mesh edge (its vertices, smaller first) of each point: for an open piece, the first
    /// and the last are the boundary edges it ends on.
    pub keys: Vec<(u32, u32)>,
}

impl Piece {
    /// The mean of the points.
    pub fn centre(&self) -> Vec3 {
        self.points.iter().sum::<Vec3>() / self.points.len().max(1) as f64
    }
}

/// A section: its plane's height, centroid, and the curve sampled at equally spaced angles.
#[derive(Clone, Debug, PartialEq)]
pub struct Section {
    /// Height of the section's plane along the frame's axis.
    pub height: f64,
    /// The area centroid of the section's loop, about which the angles are measured.
    pub centroid: Vec3,
    /// `C(2πk/S)`, `k = 0 … S − 1`.
    pub points: Vec<Vec3>,
}

/// Share of the turn over which a ray may meet a loop more than once before the loop counts as
/// not star-shaped (noise makes a few short back-steps).
const BACKTRACK_SHARE: f64 = 0.02;

impl Section {
    /// Samples a closed loop lying in the plane at height `h` (see the module documentation).
    /// Messages name the plane in the coordinates of the frame `file`.
    pub fn from_loop(
        ring: &[Vec3],
        frame: &AxisFrame,
        h: f64,
        samples: usize,
        file: FileFrame,
    ) -> Result<Self> {
        let plane = || frame.plane(h, file);
        let n = ring.len();
        if n < 3 {
            return Err(Error::invalid(format!(
                "the section {} is a degenerate loop of {n} points",
                plane()
            )));
        }
        // 2-D coordinates and the area centroid of the polygon, from the loop's first point:
        // the shoelace sums of coordinates far from the origin (a scan in world coordinates)
        // would cancel catastrophically.
        let o = ring[0];
        let xy: Vec<[f64; 2]> = ring
            .iter()
            .map(|p| [(p - o).dot(&frame.e1), (p - o).dot(&frame.e2)])
            .collect();
        let (mut area, mut cx, mut cy) = (0.0, 0.0, 0.0);
        for k in 0..n {
            let (a, b) = (xy[k], xy[(k + 1) % n]);
            let cross = a[0] * b[1] - b[0] * a[1];
            area += cross;
            cx += (a[0] + b[0]) * cross;
            cy += (a[1] + b[1]) * cross;
        }
        if area.abs() < 1e-300 {
            return Err(Error::invalid(format!(
                "the section {} encloses no area",
                plane()
            )));
        }
        let c = [cx / (3.0 * area), cy / (3.0 * area)];
        // Points of the plane from their 2-D coordinates.
        let lift = frame.axis * (h + frame.origin.dot(&frame.axis));
        let (ox, oy) = (o.dot(&frame.e1), o.dot(&frame.e2));
        let to3 = |x: f64, y: f64| frame.e1 * (x + ox) + frame.e2 * (y + oy) + lift;
        let centroid = to3(c[0], c[1]);
        let step = TAU / samples as f64;
        let mut radius = vec![f64::NAN; samples];
        let mut backtrack = 0.0;
        let angle = |p: [f64; 2]| (p[1] - c[1]).atan2(p[0] - c[0]);
        let mut winding = 0.0;
        for k in 0..n {
            let (a, b) = (xy[k], xy[(k + 1) % n]);
            let (ta, tb) = (angle(a), angle(b));
            let mut d = tb - ta;
            if d > std::f64::consts::PI {
                d -= TAU;
            } else if d <= -std::f64::consts::PI {
                d += TAU;
            }
            winding += d;
        }
        let turn = winding / TAU;
        if (turn.abs() - 1.0).abs() > 1e-6 {
            return Err(Error::invalid(format!(
                "the section {} does not wind once around its centroid (winding number \
                 {turn:.3}): it is not star-shaped",
                plane()
            )));
        }
        let sign = turn.signum();
        for k in 0..n {
            let (a, b) = (xy[k], xy[(k + 1) % n]);
            let ta = angle(a);
            let mut d = angle(b) - ta;
            if d > std::f64::consts::PI {
                d -= TAU;
            } else if d <= -std::f64::consts::PI {
                d += TAU;
            }
            if d * sign < 0.0 {
                backtrack += d.abs();
            }
            let (lo, hi) = if d >= 0.0 { (ta, ta + d) } else { (ta + d, ta) };
            let first = (lo / step).ceil() as i64;
            let last = (hi / step).floor() as i64;
            for j in first..=last {
                let t = j as f64 * step;
                let dir = [t.cos(), t.sin()];
                // Point of segment a→b on the ray from c along dir.
                let ea = [a[0] - c[0], a[1] - c[1]];
                let eb = [b[0] - c[0], b[1] - c[1]];
                let ca = ea[0] * dir[1] - ea[1] * dir[0];
                let cb = eb[0] * dir[1] - eb[1] * dir[0];
                let w = if (ca - cb).abs() > 0.0 {
                    (ca / (ca - cb)).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                let r =
                    (ea[0] + (eb[0] - ea[0]) * w) * dir[0] + (ea[1] + (eb[1] - ea[1]) * w) * dir[1];
                let slot = j.rem_euclid(samples as i64) as usize;
                if radius[slot].is_nan() || r > radius[slot] {
                    radius[slot] = r;
                }
            }
        }
        if backtrack > BACKTRACK_SHARE * TAU {
            return Err(Error::invalid(format!(
                "the section {} is not star-shaped about its centroid (rays from it meet the \
                 loop more than once over {:.0}% of the turn)",
                plane(),
                100.0 * backtrack / TAU
            )));
        }
        if radius.iter().any(|r| !r.is_finite() || *r < 0.0) {
            return Err(Error::invalid(format!(
                "the section {} is not star-shaped about its centroid",
                plane()
            )));
        }
        let points = radius
            .iter()
            .enumerate()
            .map(|(k, &r)| {
                let t = k as f64 * step;
                to3(c[0] + r * t.cos(), c[1] + r * t.sin())
            })
            .collect();
        Ok(Section {
            height: h,
            centroid,
            points,
        })
    }
}

/// Real Fourier coefficients of equally spaced samples of a periodic curve, up to `modes`:
/// `(a₀, [aₙ], [bₙ])` with `C(v) ≈ a₀ + Σ aₙ cos nv + bₙ sin nv` (trapezoidal rule, exact for
/// series below `S/2`).
pub fn fourier(points: &[Vec3], modes: usize) -> (Vec3, Vec<Vec3>, Vec<Vec3>) {
    let s = points.len();
    let mut planner = realfft::RealFftPlanner::<f64>::new();
    let r2c = planner.plan_fft_forward(s);
    let mut input = r2c.make_input_vec();
    let mut spectrum = r2c.make_output_vec();
    let mut a0 = Vec3::zeros();
    let mut cos = vec![Vec3::zeros(); modes];
    let mut sin = vec![Vec3::zeros(); modes];
    for c in 0..3 {
        for (x, p) in input.iter_mut().zip(points) {
            *x = p[c];
        }
        // Lengths always match the plan.
        if r2c.process(&mut input, &mut spectrum).is_err() {
            continue;
        }
        a0[c] = spectrum[0].re / s as f64;
        for n in 1..=modes.min(s / 2) {
            let g = spectrum[n];
            // The Nyquist mode (n = S/2) of the samples counts once.
            let scale = if 2 * n == s { 1.0 } else { 2.0 } / s as f64;
            cos[n - 1][c] = scale * g.re;
            sin[n - 1][c] = -scale * g.im;
        }
    }
    (a0, cos, sin)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed, irregularly triangulated ellipsoid-like body of revolution around z.
    fn body(rings: usize, around: usize) -> InputMesh {
        let mut positions = vec![Vec3::new(0.0, 0.0, -1.0)];
        for i in 1..rings {
            let t = std::f64::consts::PI * i as f64 / rings as f64;
            for j in 0..around {
                // Sheared columns: an irregular triangulation.
                let v = TAU * (j as f64 + 0.37 * (i % 3) as f64) / around as f64;
                let r = 2.0 * t.sin();
                positions.push(Vec3::new(r * v.cos(), r * v.sin(), -t.cos()));
            }
        }
        positions.push(Vec3::new(0.0, 0.0, 1.0));
        let top = positions.len() as u32 - 1;
        let at = |i: usize, j: usize| (1 + (i - 1) * around + j % around) as u32;
        let mut triangles = Vec::new();
        for j in 0..around {
            triangles.push([0, at(1, j + 1), at(1, j)]);
            triangles.push([top, at(rings - 1, j), at(rings - 1, j + 1)]);
        }
        for i in 1..rings - 1 {
            for j in 0..around {
                triangles.push([at(i, j), at(i, j + 1), at(i + 1, j + 1)]);
                triangles.push([at(i, j), at(i + 1, j + 1), at(i + 1, j)]);
            }
        }
        InputMesh::new(positions, triangles).unwrap()
    }

    fn z_frame() -> AxisFrame {
        AxisFrame {
            origin: Vec3::zeros(),
            e1: Vec3::x(),
            e2: Vec3::y(),
            axis: Vec3::z(),
        }
    }

    #[test]
    fn sections_of_a_body_of_revolution_are_its_polygons() {
        let mesh = body(40, 64);
        mesh.require_closed().unwrap();
        let slicer = Slicer::new(&mesh, z_frame(), FileFrame::default());
        for h in [-0.9, -0.3, 0.0, 0.45, 0.97] {
            let loops = slicer.loops(h).unwrap();
            assert_eq!(loops.len(), 1);
            // Every point lies in the plane.
            for p in &loops[0].points {
                assert!((p.z - h).abs() < 1e-12);
            }
            let s = slicer.section(h, 128, None).unwrap();
            // The exact circle has radius 2 sin t with cos t = −h; the polygon's chords lie
            // within r (1 − cos(π/64)) of it, plus the ring's spacing in z.
            let r = 2.0 * (1.0 - h * h).sqrt();
            for (k, p) in s.points.iter().enumerate() {
                let v = TAU * k as f64 / 128.0;
                let rho = (p.x * p.x + p.y * p.y).sqrt();
                assert!(rho <= r + 1e-9, "{h} {k}");
                assert!(rho > r * (1.0 - 0.03), "{h} {k}: {rho} vs {r}");
                // v = 0 is along +x, v turns counter-clockwise about +z.
                assert!((p.y.atan2(p.x).rem_euclid(TAU) - v).abs() < 1e-9 || k == 0);
            }
        }
        assert_eq!(slicer.loops(1.5).unwrap().len(), 0);
    }

    /// A section is the same, moved, when its loop lies 10⁷ units from the origin (a scan in
    /// world coordinates): its centroid and samples move with the loop, to rounding of the
    /// coordinates' size.
    #[test]
    fn sections_far_from_the_origin_are_the_same_moved() {
        let ring: Vec<Vec3> = (0..50)
            .map(|k| {
                let t = TAU * k as f64 / 50.0;
                Vec3::new((1.0 + 0.2 * (3.0 * t).cos()) * t.cos(), 0.7 * t.sin(), 0.25)
            })
            .collect();
        let shift = Vec3::new(1e7, -3e7, 0.0);
        let far: Vec<Vec3> = ring.iter().map(|p| p + shift).collect();
        let a = Section::from_loop(&ring, &z_frame(), 0.25, 64, FileFrame::default()).unwrap();
        let b = Section::from_loop(&far, &z_frame(), 0.25, 64, FileFrame::default()).unwrap();
        // Rounding of coordinates of 3·10⁷: about 4·10⁻⁹ each.
        assert!((b.centroid - shift - a.centroid).norm() < 1e-7);
        for (p, q) in a.points.iter().zip(&b.points) {
            assert!((q - shift - p).norm() < 1e-7, "{p:?} {q:?}");
        }
    }

    #[test]
    fn several_loops_are_refused() {
        let a = body(12, 16);
        let mut two = a.clone();
        let n = two.positions.len() as u32;
        two.positions
            .extend(a.positions.iter().map(|p| p + Vec3::new(5.0, 0.0, 0.0)));
        two.triangles
            .extend(a.triangles.iter().map(|t| t.map(|i| i + n)));
        // Read from a +Y-up file: the plane is named where the file has it, not by its height
        // along the design's axis.
        let file = FileFrame {
            y_up: true,
            design_unit: 1.0,
        };
        let slicer = Slicer::new(&two, z_frame(), file);
        let e = slicer.section(0.1, 64, None).unwrap_err().to_string();
        assert!(
            e.contains("the section through (0, 0.1, 0) normal to (0, 1, 0) has 2 separate loops"),
            "{e}"
        );
    }

    #[test]
    fn fourier_recovers_a_finite_series() {
        let pts: Vec<Vec3> = (0..64)
            .map(|k| {
                let v = TAU * k as f64 / 64.0;
                Vec3::new(
                    1.0 + 2.0 * v.cos(),
                    0.5 * (3.0 * v).sin(),
                    -0.25 * (2.0 * v).cos(),
                )
            })
            .collect();
        let (a0, c, s) = fourier(&pts, 4);
        assert!((a0 - Vec3::new(1.0, 0.0, 0.0)).norm() < 1e-14);
        assert!((c[0] - Vec3::new(2.0, 0.0, 0.0)).norm() < 1e-14);
        assert!((s[2] - Vec3::new(0.0, 0.5, 0.0)).norm() < 1e-14);
        assert!((c[1] - Vec3::new(0.0, 0.0, -0.25)).norm() < 1e-14);
        assert!(c[3].norm() < 1e-14 && s[3].norm() < 1e-14);
    }
}
