//! The measures of every frame (time, area, enclosed volume), as CSV and as an SVG plot.

use crate::analysis::{integrate_design, Quadrature};
use crate::design::SolvedDesign;
use crate::Result;
use std::fmt::Write as _;
use std::io::Write;

/// One frame's measures (design units).
#[derive(Clone, Debug, PartialEq)]
pub struct Row {
    /// The frame's time.
    pub t: f64,
    /// The morph parameter, for a morph.
    pub epsilon: Option<f64>,
    /// The total area of the design's surfaces (the caps of `volume` not included).
    pub area: f64,
    /// The enclosed volume; an open design is closed by caps over its open boundaries, as
    /// `pdeshape analyze` does ([`crate::analysis::Cap`]).
    pub volume: f64,
}

/// Most quadrature nodes per patch and frame: a 64th of `analyze`'s budget, since the
/// measures are taken for every frame (smooth frames converge within 128 × 256 nodes). A
/// surface that does not converge within it (a folded or degenerate frame) gets the last
/// level's estimate instead of 4 million nodes a frame.
pub(super) const MAX_NODES_PER_FRAME: usize = 1 << 16;

/// The area and enclosed volume of a solved design (adaptive quadrature to `10⁻⁹` relative
/// within [`MAX_NODES_PER_FRAME`], caps over open boundaries as in `analyze`).
pub fn measure(solved: &SolvedDesign) -> Result<(f64, f64)> {
    let q = Quadrature {
        tolerance: 1e-9,
        max_nodes: MAX_NODES_PER_FRAME,
        ..Quadrature::default()
    };
    let d = integrate_design(solved, &q)?;
    Ok((d.total.area, d.total.volume))
}

/// The measures of all frames.
#[derive(Clone, Debug, Default)]
pub struct Measures {
    /// One row per frame, in order.
    pub rows: Vec<Row>,
    /// The design's unit (`mm`, …), for the headers.
    pub units: String,
}

impl Measures {
    /// `frame,t[,epsilon],area,volume` with the unit in the header (`area_mm2`, `volume_mm3`),
    /// numbers in their shortest round-trip form.
    pub fn write_csv(&self, w: &mut dyn Write) -> std::io::Result<()> {
        let morph = self.rows.iter().any(|r| r.epsilon.is_some());
        let u = &self.units;
        if morph {
            writeln!(w, "frame,t,epsilon,area_{u}2,volume_{u}3")?;
        } else {
            writeln!(w, "frame,t,area_{u}2,volume_{u}3")?;
        }
        for (k, r) in self.rows.iter().enumerate() {
            match r.epsilon {
                Some(e) if morph => writeln!(w, "{k},{:?},{e:?},{:?},{:?}", r.t, r.area, r.volume)?,
                _ => writeln!(w, "{k},{:?},{:?},{:?}", r.t, r.area, r.volume)?,
            }
        }
        Ok(())
    }

    /// The extremes of the volume: `(frame of the largest, frame of the smallest)`.
    pub fn volume_extremes(&self) -> Option<(usize, usize)> {
        let by = |a: &(usize, &Row), b: &(usize, &Row)| a.1.volume.total_cmp(&b.1.volume);
        let max = self.rows.iter().enumerate().max_by(by)?.0;
        let min = self.rows.iter().enumerate().min_by(by)?.0;
        Some((max, min))
    }

    /// A plot of volume and area against time: two panels with axes, ticks and labels.
    pub fn svg(&self, title: &str) -> String {
        let (w, h) = (720.0, 520.0);
        let mut s = String::new();
        let _ = writeln!(
            s,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="12">"#
        );
        let _ = writeln!(s, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
        let _ = writeln!(
            s,
            r#"<text x="{}" y="22" text-anchor="middle" font-size="15">{}</text>"#,
            w / 2.0,
            pdeshape_io::svg::escape(title)
        );
        let u = &self.units;
        let t: Vec<f64> = self.rows.iter().map(|r| r.t).collect();
        let vol: Vec<f64> = self.rows.iter().map(|r| r.volume).collect();
        let area: Vec<f64> = self.rows.iter().map(|r| r.area).collect();
        panel(&mut s, 40.0, &t, &vol, &format!("volume ({u}³)"), "#c0392b");
        panel(&mut s, 280.0, &t, &area, &format!("area ({u}²)"), "#2c6fbb");
        s.push_str("</svg>\n");
        s
    }
}

/// Round tick values covering `[lo, hi]`.
fn ticks(lo: f64, hi: f64) -> Vec<f64> {
    let span = (hi - lo).max(1e-300);
    let raw = span / 5.0;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|&s| s >= raw)
        .unwrap_or(10.0 * mag);
    let mut v = (lo / step).ceil() * step;
    let mut out = Vec::new();
    while v <= hi + 1e-9 * span && out.len() < 20 {
        out.push(v);
        v += step;
    }
    out
}

fn panel(s: &mut String, top: f64, x: &[f64], y: &[f64], label: &str, color: &str) {
    let (left, width, height) = (90.0, 600.0, 190.0);
    if x.is_empty() {
        return;
    }
    let (x0, x1) = (x[0], x[x.len() - 1].max(x[0] + 1e-12));
    let (mut y0, mut y1) = y
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let pad = ((y1 - y0) * 0.08).max(1e-9 * y1.abs().max(1e-300));
    y0 -= pad;
    y1 += pad;
    let px = |v: f64| left + (v - x0) / (x1 - x0) * width;
    let py = |v: f64| top + height - (v - y0) / (y1 - y0) * height;
    let _ = writeln!(
        s,
        r##"<rect x="{left}" y="{top}" width="{width}" height="{height}" fill="none" stroke="#444"/>"##
    );
    for v in ticks(y0, y1) {
        let yy = py(v);
        let _ = writeln!(
            s,
            r##"<line x1="{left}" y1="{yy:.1}" x2="{:.1}" y2="{yy:.1}" stroke="#ddd"/><text x="{:.1}" y="{:.1}" text-anchor="end">{}</text>"##,
            left + width,
            left - 6.0,
            yy + 4.0,
            crate::formula::short(v)
        );
    }
    for v in ticks(x0, x1) {
        let xx = px(v);
        let _ = writeln!(
            s,
            r##"<line x1="{xx:.1}" y1="{top}" x2="{xx:.1}" y2="{:.1}" stroke="#eee"/><text x="{xx:.1}" y="{:.1}" text-anchor="middle">{}</text>"##,
            top + height,
            top + height + 16.0,
            crate::formula::short(v)
        );
    }
    let _ = writeln!(
        s,
        r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">t (s)</text>"#,
        left + width / 2.0,
        top + height + 32.0
    );
    let _ = writeln!(
        s,
        r#"<text transform="translate(18 {:.1}) rotate(-90)" text-anchor="middle">{}</text>"#,
        top + height / 2.0,
        pdeshape_io::svg::escape(label)
    );
    let pts: Vec<String> = x
        .iter()
        .zip(y)
        .map(|(&a, &b)| format!("{:.2},{:.2}", px(a), py(b)))
        .collect();
    let _ = writeln!(
        s,
        r#"<polyline points="{}" fill="none" stroke="{color}" stroke-width="2"/>"#,
        pts.join(" ")
    );
}
