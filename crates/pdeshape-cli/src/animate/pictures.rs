//! The pictures of the frames: their size (`--picture-size`), the box that frames them all
//! alike, the frames on the contact sheet and the PNG of every frame for `--frames-dir`.

use super::retarget::Collector;
use super::Args;
use crate::common::CliError;
use pdeshape::anim::Keyframes;
use pdeshape::render::{self as pic, Polyline, RenderOptions};
use pdeshape::Vec3;
use rayon::prelude::*;

/// The eight corners of a box as an invisible polyline, so that every frame's picture has the
/// same framing (the renderer fits everything it draws).
pub(crate) fn frame_box(lo: [f64; 3], hi: [f64; 3]) -> Polyline {
    let mut points = Vec::new();
    for k in 0..8 {
        let c = |i: usize| if k >> i & 1 == 0 { lo[i] } else { hi[i] };
        points.push(Vec3::new(c(0), c(1), c(2)));
    }
    Polyline {
        points,
        color: [255, 255, 255],
        width: 0.0,
        closed: false,
    }
}

/// Frames on the contact sheet (at most; evenly spread, the first and the last included).
const SHEET_FRAMES: usize = 12;
/// Tiles per row of the contact sheet.
pub(super) const SHEET_COLUMNS: u32 = 4;

/// `--picture-size WIDTHxHEIGHT` ([`pdeshape::format::parse_size`]), each side 16 to 4096 (a
/// frame of an animated picture is kept for every frame).
pub(super) fn parse_size(s: &str) -> Result<(u32, u32), CliError> {
    let (w, h) = pdeshape::format::parse_size(s).map_err(|e| {
        CliError::input(format!("--picture-size: {}", crate::common::message_of(&e)))
    })?;
    if w < 16 || h < 16 || w > 4096 || h > 4096 {
        return Err(CliError::input(format!(
            "--picture-size: width and height must be between 16 and 4096 (got {w}x{h})"
        )));
    }
    Ok((w, h))
}

/// `--picture-size`, or its default.
pub(super) fn picture_size(args: &Args) -> &str {
    args.picture_size.as_deref().unwrap_or("480x360")
}

/// The frames on the contact sheet: up to [`SHEET_FRAMES`], evenly spread.
pub(super) fn sheet_frames(n: usize) -> Vec<usize> {
    if n <= SHEET_FRAMES {
        return (0..n).collect();
    }
    (0..SHEET_FRAMES)
        .map(|k| (k * (n - 1) + (SHEET_FRAMES - 1) / 2) / (SHEET_FRAMES - 1))
        .collect()
}

/// The PNG pictures of every frame for `--frames-dir` (drawn like `pdeshape render`'s default),
/// in parallel.
pub(super) fn frame_pictures(keys: &Keyframes, c: &Collector) -> pdeshape::Result<Vec<Vec<u8>>> {
    let (lo, hi) = keys.bounds();
    let boxed = frame_box(lo, hi);
    (0..keys.positions.len())
        .into_par_iter()
        .map(|k| {
            pic::render_png_tri(
                &keys.mesh(k),
                &c.overlays(k, &boxed),
                &RenderOptions::default(),
            )
        })
        .collect()
}
