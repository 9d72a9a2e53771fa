//! More outputs of `pdeshape animate`: the motion re-targeted onto a separate triangle mesh
//! (`--retarget MESH --retarget-output OUT.glb`), an animated PNG or GIF of the frames
//! (`--apng`, `--gif`), a contact sheet of frames (`--contact-sheet`) and a picture per frame
//! (`--frames-dir`). They take what they need from the one pass over the frames (no frame is
//! solved twice), are drawn in parallel, and are written atomically with the other outputs.

use super::load::Animated;
use super::pictures::{frame_box, parse_size, picture_size, sheet_frames, SHEET_COLUMNS};
use super::retarget::Collector;
use super::Args;
use crate::common::{CliError, Output};
use pdeshape::anim::{self, Keyframes};
use pdeshape::fit::MeshFormat;
use pdeshape::mesh::MeshInfo;
use pdeshape::render::{self as pic, RenderOptions};
use rayon::prelude::*;
use std::io::Write;
use std::path::Path;

fn extension_is(path: &Path, ext: &str) -> bool {
    pdeshape::format::has_extension(path, ext)
}

/// Checks the flags before any work: extensions, the pairing of `--retarget` with
/// `--retarget-output`, the size and the view.
pub(super) fn check(args: &Args) -> Result<(), CliError> {
    match (&args.retarget, &args.retarget_output) {
        (Some(m), Some(o)) => {
            let ext = m.extension().and_then(|e| e.to_str()).unwrap_or("");
            if MeshFormat::from_extension(&ext.to_ascii_lowercase()).is_none() {
                return Err(CliError::input(MeshFormat::unknown(&format!(
                    "--retarget {}",
                    m.display()
                ))));
            }
            if !extension_is(o, "glb") {
                return Err(CliError::input(format!(
                    "--retarget-output {}: must end in .glb",
                    o.display()
                )));
            }
        }
        (Some(_), None) => {
            return Err(CliError::input(
                "--retarget: give --retarget-output OUT.glb for the re-targeted mesh",
            ))
        }
        (None, Some(_)) => {
            return Err(CliError::input(
                "--retarget-output: give --retarget MESH, the mesh to re-target",
            ))
        }
        (None, None) => {}
    }
    for (p, flag, ext) in [
        (&args.apng, "--apng", "png"),
        (&args.contact_sheet, "--contact-sheet", "png"),
        (&args.gif, "--gif", "gif"),
    ] {
        if let Some(p) = p {
            if !extension_is(p, ext) {
                return Err(CliError::input(format!(
                    "{flag} {}: must end in .{ext}",
                    p.display()
                )));
            }
        }
    }
    parse_size(picture_size(args))?;
    if let Some(v) = &args.view {
        crate::render::parse_view(v)?;
    }
    // Only the pictures of --apng, --gif and --contact-sheet take a size and a view (those of
    // --frames-dir are drawn like `pdeshape render`'s default).
    if args.apng.is_none() && args.gif.is_none() && args.contact_sheet.is_none() {
        for (given, flag) in [
            (args.picture_size.is_some(), "--picture-size"),
            (args.view.is_some(), "--view"),
        ] {
            if given {
                return Err(CliError::input(format!(
                    "{flag}: applies only to the pictures of --apng, --gif and \
                     --contact-sheet, and none is given"
                )));
            }
        }
    }
    Ok(())
}

/// Outputs made and not yet committed, with the words of the report.
#[derive(Default)]
pub(super) struct Pending {
    pub outputs: Vec<Output>,
    pub report: String,
}

/// Makes the outputs these flags ask for from the frames of the one pass (`keys`, and what
/// `c` took of every frame); nothing when none is asked for.
pub(super) fn run(
    args: &Args,
    l: &Animated,
    times: &[f64],
    keys: &Keyframes,
    c: Collector,
) -> Result<Pending, CliError> {
    let mut pending = Pending::default();
    let (width, height) = parse_size(picture_size(args))?;
    let options = RenderOptions {
        width,
        height,
        view: args
            .view
            .as_deref()
            .map(crate::render::parse_view)
            .transpose()?,
        ..RenderOptions::default()
    };
    let dt = if times.len() > 1 {
        times[1] - times[0]
    } else {
        l.anim.time().end - l.anim.time().start
    };
    let (lo, hi) = keys.bounds();
    let boxed = frame_box(lo, hi);
    let on_sheet = sheet_frames(times.len());
    let every = args.apng.is_some() || args.gif.is_some();
    let drawn: Vec<usize> = if every {
        (0..times.len()).collect()
    } else if args.contact_sheet.is_some() {
        on_sheet.clone()
    } else {
        Vec::new()
    };
    let located = |e: pdeshape::Error| l.design.error(&e);
    let pictures: Vec<Vec<u8>> = drawn
        .par_iter()
        .map(|&k| pic::render_rgb_tri(&keys.mesh(k), &c.overlays(k, &boxed), &options))
        .collect::<pdeshape::Result<_>>()
        .map_err(located)?;
    let picture = |k: usize| {
        &pictures[if every {
            k
        } else {
            drawn.binary_search(&k).unwrap_or(0)
        }]
    };
    if let Some(p) = &args.apng {
        let mut o = Output::create(p)?;
        let mut bytes = Vec::new();
        let delay = pic::frame_delay(dt).map_err(|e| CliError::input(format!("--apng: {e}")))?;
        let mut apng = pic::Apng::new(&mut bytes, width, height, times.len() as u32, delay)
            .map_err(|e| CliError::input(format!("--apng: {e}")))?;
        for k in 0..times.len() {
            apng.push(picture(k))
                .map_err(|e| CliError::input(format!("--apng: {e}")))?;
        }
        apng.finish()
            .map_err(|e| CliError::input(format!("--apng: {e}")))?;
        o.write_all(&bytes)?;
        pending.outputs.push(o);
        pending.report += &format!("; wrote {}", p.display());
    }
    if let Some(p) = &args.gif {
        let mut o = Output::create(p)?;
        let delay = pic::gif_delay(dt).map_err(|e| CliError::input(format!("--gif: {e}")))?;
        let quantized: Vec<pic::Quantized> =
            pictures.par_iter().map(|rgb| pic::quantize(rgb)).collect();
        let mut gif = pic::Gif::new(Vec::new(), width, height, times.len() as u32, delay)
            .map_err(|e| CliError::input(format!("--gif: {e}")))?;
        for q in &quantized {
            gif.push_quantized(q)
                .map_err(|e| CliError::input(format!("--gif: {e}")))?;
        }
        let bytes = gif
            .finish()
            .map_err(|e| CliError::input(format!("--gif: {e}")))?;
        o.write_all(&bytes)?;
        pending.outputs.push(o);
        pending.report += &format!("; wrote {}", p.display());
    }
    if let Some(p) = &args.contact_sheet {
        let tiles = on_sheet
            .iter()
            .map(|&k| {
                (
                    picture(k).clone(),
                    format!("t = {}", pic::short_label(times[k])),
                )
            })
            .collect();
        let sheet = pic::ContactSheet {
            tile_width: width,
            tile_height: height,
            columns: SHEET_COLUMNS,
            tiles,
        };
        let (w, h, rgb) = pic::contact_sheet(&sheet)
            .map_err(|e| CliError::input(format!("--contact-sheet: {e}")))?;
        let png = pic::encode_png(w, h, &rgb)
            .map_err(|e| CliError::input(format!("--contact-sheet: {e}")))?;
        let mut o = Output::create(p)?;
        o.write_all(&png)?;
        pending.outputs.push(o);
        pending.report += &format!("; wrote {}", p.display());
    }
    if let (Some(r), Some(p)) = (c.retarget, &args.retarget_output) {
        let shown = p.display().to_string();
        let mut o = Output::create(p)?;
        let info = MeshInfo {
            title: Some(format!(
                "{} (re-targeted)",
                l.title.clone().unwrap_or_else(|| "pdeshape".into())
            )),
            units: r.keys.units,
            scale: args.scale,
            ..MeshInfo::default()
        };
        {
            let mut w = o.writer();
            anim::write_glb(&r.keys, &info, &mut w)
                .map_err(|e| CliError::input(format!("--retarget-output {shown}: {e}")))?;
            w.flush()
                .map_err(|e| CliError::input(format!("--retarget-output {shown}: {e}")))?;
        }
        pending.outputs.push(o);
        pending.report += &format!(
            "; wrote {shown}: {} vertices re-targeted, offsets up to {}",
            r.correspondence.points.len(),
            pic::short_label(r.correspondence.max_distance())
        );
    }
    Ok(pending)
}
