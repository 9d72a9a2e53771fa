//! Colour scales shown with their values: the range a colour map spans ([`robust_range`]), the
//! ticks of its bar ([`nice_ticks`], [`tick_label`]) and the bar drawn beside a coloured picture
//! ([`render_png_colored_with_bar`]).

use super::text::{text_width, Canvas, GLYPH};
use super::{check_colors, check_size};
use super::{diverging_colors, encode_png, raster, validate, Camera, Polyline, RenderOptions};
use crate::mesh::GridMesh;
use crate::Result;

/// How [`robust_range`] chooses the range, in words (for messages and the bar's note).
pub const ROBUST_RANGE_RULE: &str = "1st to 99th percentile, symmetric about 0 when it spans 0";

/// The lower and upper percentiles [`robust_range`] starts from.
const PERCENTILES: (f64, f64) = (0.01, 0.99);

/// A colour range that shows the data: the 1st and 99th percentiles `p₁ ≤ p₉₉` of the finite
/// values (nearest rank), so that a few extreme vertices (poles, creases) do not flatten the rest
/// into one colour. When `p₁ < 0 < p₉₉` the range is made symmetric, `±max(|p₁|, |p₉₉|)`, so the
/// middle colour means zero (saddle against dome for Gaussian curvature); otherwise it is
/// `[p₁, p₉₉]` itself (a mean curvature of one sign, like a closed vesicle's, spans the whole map
/// instead of half of it). Equal percentiles `p` give `p ± 1 %` of `|p|` (`±1` for `p = 0`).
/// `None` when no value is finite.
pub fn robust_range<'a>(values: impl IntoIterator<Item = &'a f64>) -> Option<(f64, f64)> {
    let mut v: Vec<f64> = values
        .into_iter()
        .copied()
        .filter(|x| x.is_finite())
        .collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let rank = |q: f64| v[((q * (v.len() - 1) as f64).round() as usize).min(v.len() - 1)];
    let (lo, hi) = (rank(PERCENTILES.0), rank(PERCENTILES.1));
    if lo < 0.0 && hi > 0.0 {
        let m = lo.abs().max(hi);
        return Some((-m, m));
    }
    // One-signed data that vary by less than a millionth of their size are constant for a
    // picture (a sphere's curvature to rounding): spreading the colour map over that rounding
    // would paint noise.
    if hi - lo > 1e-6 * lo.abs().max(hi.abs()) {
        return Some((lo, hi));
    }
    let mid = 0.5 * (lo + hi);
    let d = if mid == 0.0 { 1.0 } else { 0.01 * mid.abs() };
    Some((mid - d, mid + d))
}

/// Round tick values inside `[lo, hi]`: the multiples of a step `1`, `2` or `5 × 10ᵏ` chosen so
/// that there are about five of them (between 3 and 11 for any range). Empty unless
/// `lo < hi` are finite.
pub fn nice_ticks(lo: f64, hi: f64) -> Vec<f64> {
    if !(lo.is_finite() && hi.is_finite() && lo < hi) {
        return Vec::new();
    }
    let step = nice_step(lo, hi);
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last).map(|k| k as f64 * step).collect()
}

/// The step of [`nice_ticks`].
pub(crate) fn nice_step(lo: f64, hi: f64) -> f64 {
    let raw = (hi - lo) / 5.0;
    let p = 10f64.powf(raw.log10().floor());
    let m = raw / p;
    let f = if m < 1.5 {
        1.0
    } else if m < 3.5 {
        2.0
    } else if m < 7.5 {
        5.0
    } else {
        10.0
    };
    f * p
}

/// The label of tick `x` among ticks `step` apart: fixed-point with as many decimals as the step
/// needs when `10⁻³ ≤ max(|x|, step) < 10⁵`, otherwise scientific with the digits the step needs
/// (`-2.5e-4`). A minus sign is `-` (the font is ASCII).
pub(crate) fn tick_label(x: f64, step: f64) -> String {
    let x = if x.abs() < 1e-9 * step { 0.0 } else { x };
    let big = x.abs().max(step);
    if (1e-3..1e5).contains(&big) {
        let decimals = (-step.log10().floor()).max(0.0) as usize;
        // 1, 2 or 5 × 10ᵏ: one more decimal only for a step like 0.25 (not produced here).
        format!("{x:.decimals$}")
    } else {
        let e = big.log10().floor();
        let digits = (e - step.log10().floor()).clamp(0.0, 6.0) as usize;
        format!("{x:.digits$e}")
    }
}

/// A label with three significant digits (the exact ends of the range), as
/// [`pdeshape_geometry::number::sig`] writes it.
pub fn short_label(x: f64) -> String {
    pdeshape_geometry::number::sig(x, 3)
}

/// What a colour bar shows: the quantity's name (wrapped into words over the bar), the range of
/// the colour map (`lo` blue at the bottom, `hi` red at the top, as [`diverging_colors`]) and a
/// short note under it (how the range was chosen).
#[derive(Clone, Debug, PartialEq)]
pub struct ColorBar {
    /// The quantity's name, written over the bar (wrapped at spaces).
    pub title: String,
    /// The value at the bottom of the bar (blue); finite and below `hi`.
    pub lo: f64,
    /// The value at the top of the bar (red); finite.
    pub hi: f64,
    /// A short note under the bar (how the range was chosen); may be empty.
    pub note: String,
}

/// Where the parts of a bar land in a picture of `width × height` pixels (for tests and for
/// pictures made elsewhere): the text scale, the panel's left edge, the bar's rectangle
/// `(x, y, w, h)` and the pixel rows of `lo` and `hi`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BarLayout {
    /// Text scale: every font pixel is `scale × scale` pixels (2 in pictures of at least 640 × 480,
    /// else 1).
    pub scale: usize,
    /// Left edge of the bar's panel, in pixels; the surface is drawn in the columns left of it.
    pub panel_x: usize,
    /// The bar's rectangle `(x, y, w, h)` in pixels, `(x, y)` its top-left corner.
    pub bar: (usize, usize, usize, usize),
}

impl BarLayout {
    /// The layout of a bar in a picture of this size (the picture keeps at least half its width
    /// for the surface).
    pub fn new(width: u32, height: u32) -> BarLayout {
        let (w, h) = (width as usize, height as usize);
        let scale = if h >= 480 && w >= 640 { 2 } else { 1 };
        let g = GLYPH * scale;
        // Bar, tick, gap, nine characters of label, margins.
        let panel = (g + 2 * g + g / 2 + g / 2 + 9 * g + g).min(w / 2);
        let panel_x = w - panel;
        let top = 4 * g;
        let bottom = 3 * g;
        let bar_h = h.saturating_sub(top + bottom).max(1);
        BarLayout {
            scale,
            panel_x,
            bar: (panel_x + g, top.min(h.saturating_sub(1)), 2 * g, bar_h),
        }
    }

    /// The pixel row of value `x` on the bar (clamped to it).
    pub fn row_of(&self, x: f64, lo: f64, hi: f64) -> usize {
        let (_, y, _, h) = self.bar;
        let t = ((hi - x) / (hi - lo)).clamp(0.0, 1.0);
        y + (t * (h.saturating_sub(1)) as f64).round() as usize
    }
}

/// [`super::render_png_colored`] with a colour bar on the right: the surface is drawn in the
/// picture's left part, and a white panel on the right shows the bar (the colour map from `lo` at
/// the bottom to `hi` at the top), ticks at [`nice_ticks`] labelled with [`tick_label`], the exact
/// ends labelled with [`short_label`], the title above and the note below. Refuses what
/// [`super::render_png_colored`] refuses and a range that is not finite with `lo < hi`.
pub fn render_png_colored_with_bar(
    meshes: &[GridMesh],
    colors: &[Vec<[u8; 3]>],
    overlays: &[Polyline],
    options: &RenderOptions,
    bar: &ColorBar,
) -> Result<Vec<u8>> {
    let rgb = render_rgb_colored_with_bar(meshes, colors, overlays, options, bar)?;
    encode_png(options.width, options.height, &rgb)
}

/// The pixels of [`render_png_colored_with_bar`] (`3 · width · height` bytes, sRGB).
pub fn render_rgb_colored_with_bar(
    meshes: &[GridMesh],
    colors: &[Vec<[u8; 3]>],
    overlays: &[Polyline],
    options: &RenderOptions,
    bar: &ColorBar,
) -> Result<Vec<u8>> {
    check_colors(meshes, colors)?;
    check_size(options)?;
    if !(bar.lo.is_finite() && bar.hi.is_finite() && bar.lo < bar.hi) {
        return Err(crate::Error::invalid(format!(
            "colour range {} to {}: needs finite ends with the first below the second",
            bar.lo, bar.hi
        ))
        .at("range"));
    }
    validate(meshes, overlays)?;
    let layout = BarLayout::new(options.width, options.height);
    let (w, h) = (options.width as usize, options.height as usize);
    let left = RenderOptions {
        width: layout.panel_x.max(1) as u32,
        ..options.clone()
    };
    let camera = Camera::fit(meshes, overlays, &left)?;
    let part = raster::draw_colored(meshes, Some(colors), overlays, &camera);
    let mut rgb = vec![255u8; 3 * w * h];
    let lw = left.width as usize;
    for y in 0..h {
        rgb[3 * y * w..3 * (y * w + lw)].copy_from_slice(&part[3 * y * lw..3 * (y + 1) * lw]);
    }
    draw_bar(
        &mut Canvas {
            rgb: &mut rgb,
            width: w,
            height: h,
        },
        &layout,
        bar,
    );
    Ok(rgb)
}

/// Writes `text` into a picture of `width × height` pixels (`3 · width · height` bytes, as
/// [`render_rgb_colored_with_bar`] returns), centred on column `centre_x` with its top at row
/// `top`, in the bar's ink and text scale (a caption over a part of the picture). Text beyond
/// the picture is clipped; characters outside ASCII are drawn as `?`.
pub fn write_caption(rgb: &mut [u8], width: u32, height: u32, centre_x: i64, top: i64, text: &str) {
    let (w, h) = (width as usize, height as usize);
    if rgb.len() < 3 * w * h {
        return;
    }
    let s = BarLayout::new(width, height).scale;
    let x = centre_x - text_width(text, s) as i64 / 2;
    Canvas {
        rgb,
        width: w,
        height: h,
    }
    .text(x, top, text, s, INK);
}

const INK: [u8; 3] = [40, 40, 40];

fn draw_bar(c: &mut Canvas<'_>, layout: &BarLayout, bar: &ColorBar) {
    let s = layout.scale;
    let g = (GLYPH * s) as i64;
    let (bx, by, bw, bh) = layout.bar;
    let (bx, by, bw, bh) = (bx as i64, by as i64, bw as i64, bh as i64);
    let (lo, hi) = (bar.lo, bar.hi);
    // The gradient, one colour per row.
    let values: Vec<f64> = (0..bh)
        .map(|r| hi - (hi - lo) * r as f64 / (bh - 1).max(1) as f64)
        .collect();
    for (r, col) in diverging_colors(&values, lo, hi).into_iter().enumerate() {
        c.fill(bx, by + r as i64, bw, 1, col);
    }
    // Frame.
    c.fill(bx - 1, by - 1, bw + 2, 1, INK);
    c.fill(bx - 1, by + bh, bw + 2, 1, INK);
    c.fill(bx - 1, by - 1, 1, bh + 2, INK);
    c.fill(bx + bw, by - 1, 1, bh + 2, INK);
    let tick_x = bx + bw + 1;
    let label_x = tick_x + g / 2 + g / 4;
    let label = |c: &mut Canvas<'_>, x: f64, text: &str, long: bool| {
        let y = layout.row_of(x, lo, hi) as i64;
        c.fill(
            tick_x,
            y - (s as i64 - 1) / 2,
            if long { g / 2 } else { g / 3 },
            s as i64,
            INK,
        );
        c.text(label_x, y - g / 2, text, s, INK);
    };
    // Ends first (exact values), then round ticks not crowding them.
    let y_lo = layout.row_of(lo, lo, hi) as i64;
    let y_hi = layout.row_of(hi, lo, hi) as i64;
    label(c, hi, &short_label(hi), true);
    label(c, lo, &short_label(lo), true);
    let step = nice_step(lo, hi);
    for t in nice_ticks(lo, hi) {
        let y = layout.row_of(t, lo, hi) as i64;
        if (y - y_lo).abs() < g + g / 2 || (y - y_hi).abs() < g + g / 2 {
            continue;
        }
        label(c, t, &tick_label(t, step), false);
    }
    // Title above, word-wrapped to the panel; note below.
    let avail = (c.width as i64 - layout.panel_x as i64 - g).max(g) as usize;
    let mut lines: Vec<String> = Vec::new();
    for word in bar.title.split_whitespace() {
        match lines.last_mut() {
            Some(l) if text_width(&format!("{l} {word}"), s) <= avail => {
                l.push(' ');
                l.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    let first = by - 2 * g - (lines.len() as i64 - 1) * (g + 2);
    for (k, l) in lines.iter().enumerate() {
        c.text(
            layout.panel_x as i64 + g / 2,
            first + k as i64 * (g + 2),
            l,
            s,
            INK,
        );
    }
    if !bar.note.is_empty() {
        let ns = 1;
        let mut y = by + bh + g / 2 + 2;
        let ng = (GLYPH * ns) as i64;
        let mut line = String::new();
        let mut lines = Vec::new();
        for word in bar.note.split_whitespace() {
            if !line.is_empty() && text_width(&format!("{line} {word}"), ns) > avail {
                lines.push(std::mem::take(&mut line));
            }
            if !line.is_empty() {
                line.push(' ');
            }
            line.push_str(word);
        }
        lines.push(line);
        for l in lines {
            c.text(layout.panel_x as i64 + g / 2, y, &l, ns, [90, 90, 90]);
            y += ng + 2;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::color_tests::Disc;
    use super::*;
    use crate::mesh::tessellate;

    #[test]
    fn range_clips_outliers_and_is_symmetric_only_across_zero() {
        // 1000 values in [1, 2] and two wild poles: the poles do not set the range.
        let mut v: Vec<f64> = (0..1000).map(|i| 1.0 + i as f64 / 999.0).collect();
        v.push(500.0);
        v.push(f64::NAN);
        v.push(-400.0);
        let (lo, hi) = robust_range(&v).unwrap();
        // Nearest ranks round(0.01 · 1001) = 10 and round(0.99 · 1001) = 991 of 1002 sorted
        // values: −400 first, then 1 + (k − 1)/999.
        assert_eq!((lo, hi), (1.0 + 9.0 / 999.0, 1.0 + 990.0 / 999.0));
        // Across zero: symmetric about it.
        let w: Vec<f64> = (0..=100).map(|i| -1.0 + 3.0 * i as f64 / 100.0).collect();
        // Ranks 1 and 100 of 101: w[0] = −1 and w[99] ≈ 1.97; the larger magnitude wins.
        assert_eq!(robust_range(&w), Some((-w[99], w[99])));
        assert_eq!(robust_range(&[2.0, 2.0]), Some((1.98, 2.02)));
        assert_eq!(robust_range(&[0.0]), Some((-1.0, 1.0)));
        // Rounding noise on a constant is a constant.
        let k = [0.25 * (1.0 - 1e-13), 0.25, 0.25 * (1.0 + 1e-13)];
        let (lo, hi) = robust_range(&k).unwrap();
        assert!((lo - 0.2475).abs() < 1e-12 && (hi - 0.2525).abs() < 1e-12);
        assert_eq!(robust_range(&[f64::NAN]), None);
    }

    #[test]
    fn one_signed_data_span_the_whole_colour_map() {
        // A vesicle-like mean curvature: all between 0.9 and 1.1. The old symmetric range
        // (±max) maps all of it to one end of the map; the robust one reaches both ends.
        let h: Vec<f64> = (0..2000)
            .map(|i| 1.0 + 0.1 * (i as f64 * 0.01).sin())
            .collect();
        let (lo, hi) = robust_range(&h).unwrap();
        let c = diverging_colors(&h, lo, hi);
        let blue = c.iter().filter(|x| **x == [59, 76, 192]).count();
        let red = c.iter().filter(|x| **x == [180, 4, 38]).count();
        assert!(blue >= 20 && red >= 20, "{blue} {red}");
        let old = diverging_colors(&h, -1.1, 1.1);
        let distinct_old = old.iter().collect::<std::collections::BTreeSet<_>>().len();
        let distinct_new = c.iter().collect::<std::collections::BTreeSet<_>>().len();
        assert!(
            distinct_new > 4 * distinct_old,
            "{distinct_old} {distinct_new}"
        );
    }

    #[test]
    fn ticks_are_round_inside_and_about_five() {
        for (lo, hi) in [
            (0.0, 1.0),
            (-0.37, 0.37),
            (1.0093, 1.9921),
            (-3.2e-5, 7.7e-4),
            (12.0, 13.0),
            (-2.5e7, 1e8),
        ] {
            let t = nice_ticks(lo, hi);
            let step = nice_step(lo, hi);
            assert!((3..=11).contains(&t.len()), "{lo} {hi}: {t:?}");
            let m = step / 10f64.powf(step.log10().floor());
            assert!(
                [1.0, 2.0, 5.0, 10.0].iter().any(|f| (m - f).abs() < 1e-9),
                "{step}"
            );
            for x in &t {
                assert!(*x >= lo && *x <= hi, "{x} outside {lo} {hi}");
                // The label reads back as the tick to within a hundredth of the step.
                let back: f64 = tick_label(*x, step).parse().unwrap();
                assert!(
                    (back - x).abs() <= 0.01 * step,
                    "{x} {}",
                    tick_label(*x, step)
                );
            }
        }
        assert_eq!(
            nice_ticks(0.0, 1.0),
            vec![0.0, 0.2, 0.4, 0.6000000000000001, 0.8, 1.0]
        );
        assert_eq!(tick_label(0.6000000000000001, 0.2), "0.6");
        assert_eq!(tick_label(-2.5e-4, 5e-5), "-2.5e-4");
        assert_eq!(tick_label(-2.5e-4, 1e-5), "-2.5e-4");
        assert_eq!(tick_label(-2.5e-4, 1e-6), "-2.50e-4");
        assert_eq!(short_label(1.23456), "1.23");
        assert_eq!(short_label(-0.000123456), "-1.23e-4");
        assert!(nice_ticks(1.0, 1.0).is_empty());
    }

    fn decode(png: &[u8]) -> (Vec<u8>, usize, usize) {
        let decoder = png::Decoder::new(std::io::Cursor::new(png));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap();
        (buf, info.width as usize, info.height as usize)
    }

    #[test]
    fn the_bar_shows_the_map_its_ends_and_labels() {
        let mesh = tessellate(&Disc, 8, 32).unwrap();
        let options = RenderOptions {
            width: 800,
            height: 600,
            view: Some(crate::Vec3::new(0.0, 0.0, 1.0)),
            up: crate::Vec3::new(0.0, 1.0, 0.0),
        };
        let values: Vec<f64> = (0..mesh.len()).map(|i| i as f64).collect();
        let (lo, hi) = (0.0, (mesh.len() - 1) as f64);
        let colors = vec![diverging_colors(&values, lo, hi)];
        let bar = ColorBar {
            title: "mean curvature".into(),
            lo,
            hi,
            note: "range: all values".into(),
        };
        let png =
            render_png_colored_with_bar(std::slice::from_ref(&mesh), &colors, &[], &options, &bar)
                .unwrap();
        let (px, w, h) = decode(&png);
        assert_eq!((w, h), (800, 600));
        let at = |x: usize, y: usize| {
            [
                px[3 * (y * w + x)],
                px[3 * (y * w + x) + 1],
                px[3 * (y * w + x) + 2],
            ]
        };
        let layout = BarLayout::new(800, 600);
        let (bx, _, bw, _) = layout.bar;
        let mid_x = bx + bw / 2;
        // Top of the bar is hi's colour, bottom lo's, the middle row the middle grey.
        assert_eq!(at(mid_x, layout.row_of(hi, lo, hi)), [180, 4, 38]);
        assert_eq!(at(mid_x, layout.row_of(lo, lo, hi)), [59, 76, 192]);
        let mid = at(mid_x, layout.row_of(0.5 * (lo + hi), lo, hi));
        assert!(mid.iter().all(|&c| (215..=227).contains(&c)), "{mid:?}");
        // Labels: dark ink right of the bar beside the top and bottom rows (the end values).
        let ink = |y: usize| {
            (bx + bw + 4..w)
                .flat_map(|x| (y.saturating_sub(8)..(y + 8).min(h)).map(move |yy| (x, yy)))
                .filter(|&(x, yy)| at(x, yy) == INK)
                .count()
        };
        assert!(ink(layout.row_of(hi, lo, hi)) > 20);
        assert!(ink(layout.row_of(lo, lo, hi)) > 20);
        // The title is above the bar.
        let title_ink = (layout.panel_x..w)
            .flat_map(|x| (0..layout.bar.1).map(move |y| (x, y)))
            .filter(|&(x, y)| at(x, y) == INK)
            .count();
        assert!(title_ink > 50, "{title_ink}");
        // The surface is still drawn, left of the panel, centred there.
        let cx = layout.panel_x / 2;
        let colourful = (0..layout.panel_x)
            .filter(|&x| {
                let p = at(x, 300);
                p.iter().max().unwrap() - p.iter().min().unwrap() > 60
            })
            .count();
        assert!(colourful > 100, "{colourful}");
        assert!(at(cx, 300) != at(layout.panel_x + 2, 300) || colourful > 0);
        // Bad ranges are refused.
        let bad = ColorBar {
            lo: 1.0,
            hi: 1.0,
            ..bar
        };
        assert!(render_png_colored_with_bar(&[mesh], &colors, &[], &options, &bad).is_err());
    }
}
