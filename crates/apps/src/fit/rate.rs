//! Rate and distortion: a mesh fitted at a range of tolerances, each fit's bytes (TOML, gzipped
//! TOML, plain `f64`, packed) beside its distances, and the same mesh decimated to a range of
//! sizes beside it, as a CSV table and an SVG plot, so a user sees where PDE patches beat
//! decimation and where they do not.
//!
//! The decimation is this crate's own half-edge collapse with quadric costs (the one the
//! general mode's layout starts from, without the sliver clean-up): vertices stay on the mesh,
//! as with a vertex-subset decimation; a decimator that moves vertices to their quadrics'
//! optima (such as `fast-simplification`) is somewhat more accurate at the same size
//! (BENCHMARKS.md has both). Its packed size follows [`super::pack`]: positions to a step of
//! 1/64 of its own Hausdorff distance, each coordinate axis in as many bits as its own range
//! needs (a fit's corners share one width for all three: this favours the decimation by at
//! most a bit or two a vertex), indices in `⌈log₂ V⌉` bits. Its distances are
//! two-sided like a fit's: every vertex of the mesh to the decimated mesh, and 10 points of
//! each decimated triangle (the cubic barycentric lattice) to the mesh.

use super::auto::{fit_measured, measure_like, ModeChoice, Request};
use super::frame::FileFrame;
use super::layout::{vertex_normals, Decimation};
use super::measure::{Distances, MeshDistance};
use super::mesh::InputMesh;
use super::pack::{bits_for, pack, STEP_FRACTION};
use crate::number::sig;
use crate::spec::write_design;
use crate::{Error, Result, Vec3};
use rayon::prelude::*;
use std::io::Write;
use std::time::Instant;

/// Most tolerances of one sweep.
pub const MAX_TOLERANCES: usize = 16;

/// Levels of the decimation curve.
const DECIMATION_LEVELS: usize = 12;

/// One fit of the sweep.
#[derive(Clone, Debug, serde::Serialize)]
pub struct RatePoint {
    /// The tolerance asked for (a fraction of the diagonal).
    pub tolerance: f64,
    /// The mode that fitted it.
    pub mode: String,
    /// Patches (faces of the general mode).
    pub patches: usize,
    /// Two-sided Hausdorff distance over the diagonal.
    pub hausdorff: f64,
    /// RMS distance over the diagonal.
    pub rms: f64,
    /// Whether the fit misses the tolerance.
    pub missed: bool,
    /// Bytes of the design file.
    pub toml_bytes: usize,
    /// Bytes of the design file gzipped (level 9).
    pub toml_gz_bytes: usize,
    /// Eight bytes per number of the design.
    pub f64_bytes: usize,
    /// Bytes of the packed numbers ([`super::pack`]).
    pub packed_bytes: usize,
    /// Hausdorff distance of the packed design (its numbers quantised) over the diagonal.
    pub packed_hausdorff: f64,
    /// RMS distance of the packed design over the diagonal.
    pub packed_rms: f64,
    /// Seconds the fit took.
    pub seconds: f64,
}

/// A tolerance the modes refused, with why.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Refusal {
    /// The tolerance.
    pub tolerance: f64,
    /// The mode's message.
    pub reason: String,
}

/// One level of the decimation curve.
#[derive(Clone, Debug, serde::Serialize)]
pub struct DecimatedPoint {
    /// Vertices kept.
    pub vertices: usize,
    /// Triangles left.
    pub triangles: usize,
    /// Two-sided Hausdorff distance over the diagonal.
    pub hausdorff: f64,
    /// RMS distance over the diagonal.
    pub rms: f64,
    /// `12 V + 12 T` (`f32` positions, `u32` indices).
    pub raw_bytes: usize,
    /// Bytes of the packed positions and indices (module documentation).
    pub packed_bytes: usize,
}

/// A sweep (module documentation).
#[derive(Clone, Debug, serde::Serialize)]
pub struct RateDistortion {
    /// The mesh's bounding-box diagonal.
    pub diagonal: f64,
    /// Triangles of the mesh.
    pub mesh_triangles: usize,
    /// `12 V + 12 T` of the mesh.
    pub mesh_bytes: usize,
    /// The fits, in the order of the tolerances.
    pub fits: Vec<RatePoint>,
    /// Tolerances no mode could fit.
    pub refused: Vec<Refusal>,
    /// The decimation curve, from the largest to the smallest.
    pub decimated: Vec<DecimatedPoint>,
}

/// Gzip (level 9) of `bytes`, its length.
fn gz_len(bytes: &[u8]) -> Result<usize> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
    e.write_all(bytes)
        .and_then(|_| e.finish())
        .map(|v| v.len())
        .map_err(|e| Error::invalid(format!("gzip: {e}")))
}

/// Fits `mesh` at each of `tolerances` in `mode` and decimates it (module documentation).
/// Errors: no tolerance, more than [`MAX_TOLERANCES`], one outside `(0, 1)`, each placed at
/// `tolerances[i]`; a tolerance the modes refuse is a [`Refusal`], not an error. Points the
/// refusals name are in the coordinates of the frame `file` (the mesh's file's).
pub fn rate_distortion(
    mesh: &InputMesh,
    tolerances: &[f64],
    mode: ModeChoice,
    file: FileFrame,
) -> Result<RateDistortion> {
    if tolerances.is_empty() || tolerances.len() > MAX_TOLERANCES {
        return Err(Error::invalid(format!(
            "{} tolerances: give 1 to {MAX_TOLERANCES}",
            tolerances.len()
        ))
        .at("tolerances"));
    }
    for (i, &t) in tolerances.iter().enumerate() {
        if !(t > 0.0 && t < 1.0) {
            return Err(Error::invalid(format!(
                "{t}: must be a number between 0 and 1 (a fraction of the diagonal)"
            ))
            .at(&format!("tolerances[{i}]")));
        }
    }
    let diagonal = mesh.diagonal();
    let mut fits = Vec::new();
    let mut refused = Vec::new();
    for &tolerance in tolerances {
        let t = Instant::now();
        let request = Request {
            mode,
            tolerance: Some(tolerance),
            file,
            ..Request::default()
        };
        let fitted = match fit_measured(mesh, &request) {
            Ok(f) => f,
            Err(e) => {
                refused.push(Refusal {
                    tolerance,
                    reason: e.message(),
                });
                continue;
            }
        };
        let seconds = t.elapsed().as_secs_f64();
        let text = write_design(&fitted.fit.spec)?;
        let packed = pack(&fitted.fit.spec, diagonal, tolerance)?;
        let (pm, _) = measure_like(mesh, &fitted, &packed.spec)?;
        let m = &fitted.measures;
        fits.push(RatePoint {
            tolerance,
            mode: fitted.fit.mode.name().to_string(),
            patches: fitted.fit.patches,
            hausdorff: m.hausdorff_relative,
            rms: m.rms_relative,
            missed: fitted.missed(),
            toml_bytes: text.len(),
            toml_gz_bytes: gz_len(text.as_bytes())?,
            f64_bytes: m.design_bytes,
            packed_bytes: packed.bytes,
            packed_hausdorff: pm.hausdorff_relative,
            packed_rms: pm.rms_relative,
            seconds,
        });
    }
    Ok(RateDistortion {
        diagonal,
        mesh_triangles: mesh.triangles.len(),
        mesh_bytes: mesh.binary_size(),
        fits,
        refused,
        decimated: decimation_curve(mesh)?,
    })
}

/// The decimation curve: one run of collapses, measured at [`DECIMATION_LEVELS`] vertex counts
/// spread geometrically from half the mesh's vertices down to 1/1000 of them (at least 8).
fn decimation_curve(mesh: &InputMesh) -> Result<Vec<DecimatedPoint>> {
    let normals = vertex_normals(mesh);
    let weight = vec![1.0; mesh.positions.len()];
    let mut d = Decimation::new(mesh, &normals, &weight);
    let start = d.remaining();
    let (hi, lo) = (start as f64 / 2.0, (start as f64 / 1000.0).max(8.0));
    if hi <= lo {
        return Ok(Vec::new());
    }
    let original = MeshDistance::new(mesh);
    let diagonal = mesh.diagonal();
    let mut out: Vec<DecimatedPoint> = Vec::new();
    for k in 0..DECIMATION_LEVELS {
        let f = k as f64 / (DECIMATION_LEVELS - 1) as f64;
        let target = (hi * (lo / hi).powf(f)).round() as usize;
        d.collapse_to(target);
        if out.last().is_some_and(|p| p.vertices == d.remaining()) {
            break;
        }
        let layout = d.layout();
        let positions: Vec<Vec3> = layout.vertices.iter().map(|&i| mesh.positions[i]).collect();
        let triangles: Vec<[u32; 3]> = layout
            .faces
            .iter()
            .filter(|f| f.len() == 3)
            .map(|f| [f[0] as u32, f[1] as u32, f[2] as u32])
            .collect();
        let coarse = InputMesh::new(positions, triangles)?;
        out.push(measure_decimated(mesh, &original, &coarse, diagonal));
    }
    Ok(out)
}

/// Two-sided distances of a decimated mesh and its packed size (module documentation).
fn measure_decimated(
    mesh: &InputMesh,
    original: &MeshDistance,
    coarse: &InputMesh,
    diagonal: f64,
) -> DecimatedPoint {
    let index = MeshDistance::new(coarse);
    let to_coarse: Vec<f64> = mesh
        .positions
        .par_iter()
        .filter_map(|&p| index.closest(p).map(|c| c.0))
        .collect();
    let to_mesh: Vec<f64> = (0..coarse.triangles.len())
        .into_par_iter()
        .flat_map_iter(|t| {
            let [a, b, c] = coarse.corners(t);
            let mut d = Vec::with_capacity(10);
            for i in 0..=3 {
                for j in 0..=3 - i {
                    let (x, y) = (i as f64 / 3.0, j as f64 / 3.0);
                    let p = a + (b - a) * x + (c - a) * y;
                    d.push(original.closest(p).map_or(f64::NAN, |c| c.0));
                }
            }
            d
        })
        .collect();
    let (a, b) = (Distances::of(&to_coarse), Distances::of(&to_mesh));
    let (h1, r1, h2, r2) = (a.max, a.rms, b.max, b.rms);
    let hausdorff = h1.max(h2);
    let (v, t) = (coarse.positions.len(), coarse.triangles.len());
    let step = (hausdorff * STEP_FRACTION).max(diagonal * 1e-9);
    let coordinate_bits = (0..3)
        .map(|axis| {
            let q: Vec<i64> = coarse
                .positions
                .iter()
                .map(|p| (p[axis] / step).round() as i64)
                .collect();
            let span = q.iter().max().unwrap_or(&0) - q.iter().min().unwrap_or(&0);
            bits_for(span as u64) as usize
        })
        .sum::<usize>();
    let index_bits = bits_for(v.saturating_sub(1) as u64).max(1) as usize;
    let bits = v * coordinate_bits + 3 * t * index_bits;
    DecimatedPoint {
        vertices: v,
        triangles: t,
        hausdorff: hausdorff / diagonal,
        rms: (0.5 * (r1 * r1 + r2 * r2)).sqrt() / diagonal,
        raw_bytes: 12 * v + 12 * t,
        // Three minima (8 bytes each), the widths and the counts.
        packed_bytes: bits.div_ceil(8) + 3 * 8 + 3 + 2 * 4,
    }
}

/// `10^e` bytes in words: `100`, `1 k`, `10 k`, `1 M`, …
fn bytes_label(e: i32) -> String {
    let (unit, p) = match e {
        e if e >= 9 => (" G", e - 9),
        e if e >= 6 => (" M", e - 6),
        e if e >= 3 => (" k", e - 3),
        _ => ("", e),
    };
    format!("{}{unit}", 10u64.pow(p.max(0) as u32))
}

impl RateDistortion {
    /// The sweep as CSV: one row per fit (`kind = fit`) and per decimation level
    /// (`kind = decimation`), distances as percentages of the diagonal.
    pub fn csv(&self) -> String {
        let mut s = String::from(
            "kind,tolerance_percent,mode,patches_or_triangles,hausdorff_percent,rms_percent,\
             missed,toml_bytes,toml_gz_bytes,f64_bytes,packed_bytes,packed_hausdorff_percent,\
             packed_rms_percent,seconds\n",
        );
        for p in &self.fits {
            s += &format!(
                "fit,{},{},{},{},{},{},{},{},{},{},{},{},{:.3}\n",
                100.0 * p.tolerance,
                p.mode,
                p.patches,
                100.0 * p.hausdorff,
                100.0 * p.rms,
                p.missed,
                p.toml_bytes,
                p.toml_gz_bytes,
                p.f64_bytes,
                p.packed_bytes,
                100.0 * p.packed_hausdorff,
                100.0 * p.packed_rms,
                p.seconds
            );
        }
        for p in &self.decimated {
            s += &format!(
                "decimation,,,{},{},{},,,,{},{},,,\n",
                p.triangles,
                100.0 * p.hausdorff,
                100.0 * p.rms,
                p.raw_bytes,
                p.packed_bytes
            );
        }
        s
    }

    /// The sweep as an SVG plot, two panels above each other: the Hausdorff distance and the
    /// RMS distance (percent of the diagonal, log scale) against bytes (log scale, the same
    /// range in both); the fits packed and as gzipped TOML, the decimation raw and packed;
    /// `title` above them.
    pub fn svg(&self, title: &str) -> String {
        let (w, panel) = (760.0, 430.0);
        let h = 30.0 + 2.0 * panel;
        let all = [Distance::Hausdorff, Distance::Rms].map(|d| self.series(d));
        // One byte range for both panels, the mesh's own size included.
        let mesh = (self.mesh_bytes.max(1) as f64).log10();
        let (mut x0, mut x1) = (mesh, mesh);
        for (_, _, _, pts) in all.iter().flatten() {
            for &(b, d) in pts {
                if b > 0.0 && b.is_finite() && d > 0.0 && d.is_finite() {
                    (x0, x1) = (x0.min(b.log10()), x1.max(b.log10()));
                }
            }
        }
        let bytes = (x0.floor(), x1.ceil().max(x0.floor() + 1.0));
        let mut s = format!(
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" \
             viewBox=\"0 0 {w} {h}\" font-family=\"sans-serif\" font-size=\"12\">\n\
             <rect width=\"{w}\" height=\"{h}\" fill=\"white\"/>\n\
             <text x=\"80\" y=\"22\" font-size=\"14\">{}</text>\n",
            pdeshape_io::svg::escape(title)
        );
        for (k, (distance, series)) in [Distance::Hausdorff, Distance::Rms]
            .into_iter()
            .zip(&all)
            .enumerate()
        {
            s += &self.panel(distance, series, bytes, 30.0 + k as f64 * panel, w, panel);
        }
        s += "</svg>\n";
        s
    }

    /// The four curves of one distance: `(name, colour, dashed, (bytes, percent))`.
    fn series(&self, distance: Distance) -> Vec<Series> {
        let rms = distance == Distance::Rms;
        let fit = |p: &RatePoint, packed: bool| {
            100.0
                * match (rms, packed) {
                    (false, false) => p.hausdorff,
                    (false, true) => p.packed_hausdorff,
                    (true, false) => p.rms,
                    (true, true) => p.packed_rms,
                }
        };
        let dec = |p: &DecimatedPoint| 100.0 * if rms { p.rms } else { p.hausdorff };
        vec![
            (
                "PDE patches, packed",
                "#c0392b",
                false,
                self.fits
                    .iter()
                    .map(|p| (p.packed_bytes as f64, fit(p, true)))
                    .collect(),
            ),
            (
                "PDE patches, gzipped TOML",
                "#c0392b",
                true,
                self.fits
                    .iter()
                    .map(|p| (p.toml_gz_bytes as f64, fit(p, false)))
                    .collect(),
            ),
            (
                "decimation, packed",
                "#2471a3",
                false,
                self.decimated
                    .iter()
                    .map(|p| (p.packed_bytes as f64, dec(p)))
                    .collect(),
            ),
            (
                "decimation, f32 + u32",
                "#2471a3",
                true,
                self.decimated
                    .iter()
                    .map(|p| (p.raw_bytes as f64, dec(p)))
                    .collect(),
            ),
        ]
    }

    /// One panel of [`Self::svg`], `height` tall from `y_top`, bytes over the decades
    /// `(x0, x1)`.
    fn panel(
        &self,
        distance: Distance,
        series: &[Series],
        (x0, x1): (f64, f64),
        y_top: f64,
        w: f64,
        height: f64,
    ) -> String {
        let finite = |&(x, y): &(f64, f64)| x > 0.0 && y > 0.0 && x.is_finite() && y.is_finite();
        let (mut y0, mut y1) = (f64::MAX, f64::MIN);
        for &(_, y) in series.iter().flat_map(|s| s.3.iter()).filter(|p| finite(p)) {
            (y0, y1) = (y0.min(y.log10()), y1.max(y.log10()));
        }
        if y0 > y1 {
            (y0, y1) = (-2.0, 1.0);
        }
        let (y0, y1) = (y0.floor(), y1.ceil().max(y0.floor() + 1.0));
        let (left, right, top, bottom) = (80.0, 230.0, y_top + 10.0, y_top + height - 46.0);
        let px = |x: f64| left + (x.log10() - x0) / (x1 - x0) * (w - left - right);
        let py = |y: f64| bottom - (y.log10() - y0) / (y1 - y0) * (bottom - top);
        let mut s = String::new();
        // Decades and their labels.
        for e in x0 as i32..=x1 as i32 {
            let x = px(10f64.powi(e));
            s += &format!(
                "<line x1=\"{x:.1}\" y1=\"{top}\" x2=\"{x:.1}\" y2=\"{bottom:.1}\" \
                 stroke=\"#ddd\"/>\n\
                 <text x=\"{x:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{}</text>\n",
                bottom + 16.0,
                bytes_label(e)
            );
        }
        for e in y0 as i32..=y1 as i32 {
            let y = py(10f64.powi(e));
            s += &format!(
                "<line x1=\"{left}\" y1=\"{y:.1}\" x2=\"{:.1}\" y2=\"{y:.1}\" stroke=\"#ddd\"/>\n\
                 <text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\">{}%</text>\n",
                w - right,
                left - 6.0,
                y + 4.0,
                sig(10f64.powi(e), 1)
            );
        }
        s += &format!(
            "<rect x=\"{left}\" y=\"{top}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"none\" \
             stroke=\"#444\"/>\n\
             <text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">bytes</text>\n\
             <text transform=\"translate(18 {:.1}) rotate(-90)\" text-anchor=\"middle\">\
             {} distance, % of the diagonal</text>\n",
            w - left - right,
            bottom - top,
            (left + w - right) / 2.0,
            bottom + 34.0,
            (top + bottom) / 2.0,
            distance.name()
        );
        let mx = px(self.mesh_bytes as f64);
        s += &format!(
            "<line x1=\"{mx:.1}\" y1=\"{top}\" x2=\"{mx:.1}\" y2=\"{bottom:.1}\" \
             stroke=\"#777\" stroke-dasharray=\"2 3\"/>\n\
             <text x=\"{:.1}\" y=\"{:.1}\" fill=\"#555\" text-anchor=\"end\">the mesh</text>\n",
            mx - 4.0,
            top + 14.0
        );
        for (k, (name, colour, dashed, pts)) in series.iter().enumerate() {
            let dash = if *dashed {
                " stroke-dasharray=\"5 4\""
            } else {
                ""
            };
            let mut pts: Vec<(f64, f64)> = pts.iter().copied().filter(finite).collect();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            if !pts.is_empty() {
                let path: Vec<String> = pts
                    .iter()
                    .map(|&(x, y)| format!("{:.1},{:.1}", px(x), py(y)))
                    .collect();
                s += &format!(
                    "<polyline points=\"{}\" fill=\"none\" stroke=\"{colour}\" \
                     stroke-width=\"2\"{dash}/>\n",
                    path.join(" ")
                );
                for &(x, y) in &pts {
                    s += &format!(
                        "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"3\" fill=\"{colour}\"/>\n",
                        px(x),
                        py(y)
                    );
                }
            }
            let ly = top + 10.0 + 20.0 * k as f64;
            let lx = w - right + 14.0;
            s += &format!(
                "<line x1=\"{lx:.1}\" y1=\"{ly:.1}\" x2=\"{:.1}\" y2=\"{ly:.1}\" \
                 stroke=\"{colour}\" stroke-width=\"2\"{dash}/>\n\
                 <text x=\"{:.1}\" y=\"{:.1}\">{}</text>\n",
                lx + 24.0,
                lx + 30.0,
                ly + 4.0,
                pdeshape_io::svg::escape(name)
            );
        }
        s
    }
}

/// The distance a panel of the plot shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Distance {
    Hausdorff,
    Rms,
}

impl Distance {
    fn name(self) -> &'static str {
        match self {
            Distance::Hausdorff => "Hausdorff",
            Distance::Rms => "RMS",
        }
    }
}

/// A curve of the plot: name, colour, dashed, `(bytes, distance in percent)`.
type Series = (&'static str, &'static str, bool, Vec<(f64, f64)>);

#[cfg(test)]
mod tests {
    use super::*;

    /// A flat `n × n` grid of squares, each cut into two triangles, in the plane `z = 0`.
    fn flat(n: usize) -> InputMesh {
        let mut positions = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                positions.push(Vec3::new(i as f64, j as f64 * 1.3, 0.0));
            }
        }
        let k = |i: usize, j: usize| (j * (n + 1) + i) as u32;
        let mut triangles = Vec::new();
        for j in 0..n {
            for i in 0..n {
                triangles.push([k(i, j), k(i + 1, j), k(i + 1, j + 1)]);
                triangles.push([k(i, j), k(i + 1, j + 1), k(i, j + 1)]);
            }
        }
        InputMesh::new(positions, triangles).unwrap()
    }

    #[test]
    fn a_decimated_plane_stays_on_the_plane_and_its_levels_shrink() {
        // Every decimation of a flat mesh that keeps its outline lies on it: the two-sided
        // distances are rounding only; a bug in either direction's measure would show.
        let mesh = flat(40);
        let curve = decimation_curve(&mesh).unwrap();
        assert!(curve.len() >= 3, "{curve:?}");
        for w in curve.windows(2) {
            assert!(w[1].vertices < w[0].vertices, "{curve:?}");
            assert!(w[1].packed_bytes < w[0].packed_bytes, "{curve:?}");
        }
        for p in &curve {
            assert!(p.hausdorff < 1e-12 && p.rms < 1e-12, "{p:?}");
            assert_eq!(p.raw_bytes, 12 * p.vertices + 12 * p.triangles);
        }
    }

    #[test]
    fn a_bent_sheet_decimated_moves_away_from_itself() {
        // The same grid on a cylinder: coarser levels cut the chords deeper, so the coarsest
        // level is farther from the mesh than the finest, and no farther than the sagitta of
        // the longest chord across the whole sheet (the radius: a half cylinder).
        let mut mesh = flat(40);
        let r = 40.0 / std::f64::consts::PI;
        for p in mesh.positions.iter_mut() {
            let t = p.x / r;
            *p = Vec3::new(r * t.cos(), p.y, r * t.sin());
        }
        let curve = decimation_curve(&mesh).unwrap();
        let (first, last) = (&curve[0], curve.last().unwrap());
        assert!(first.hausdorff < last.hausdorff, "{curve:?}");
        let diagonal = mesh.diagonal();
        assert!(last.hausdorff * diagonal <= r, "{curve:?}");
        assert!(first.hausdorff > 0.0, "{curve:?}");
    }

    #[test]
    fn bad_tolerances_are_refused_at_their_place() {
        let mesh = flat(4);
        let e = rate_distortion(&mesh, &[0.01, 1.5], ModeChoice::Auto, FileFrame::default())
            .unwrap_err();
        assert_eq!(e.place(), "tolerances[1]");
        let e = rate_distortion(&mesh, &[], ModeChoice::Auto, FileFrame::default()).unwrap_err();
        assert_eq!(e.place(), "tolerances");
    }
}
