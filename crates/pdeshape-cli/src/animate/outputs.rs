//! More outputs of `pdeshape animate`: the motion re-targeted onto a separate triangle mesh
//! (`--retarget MESH --retarget-output OUT.glb`), an animated PNG or GIF of the frames
//! (`--apng`, `--gif`), a contact sheet of frames (`--contact-sheet`) and a picture per frame
//! (`--frames-dir`). They take what they need from the one pass over the frames (no frame is
//! solved twice), are drawn in parallel, and are written atomically with the other outputs.

use crate::animate::{frame_box, Animated, Args};
use crate::common::{CliError, Output};
use pdeshape::anim::{self, Keyframes, Retarget};
use pdeshape::fit::{MeshFormat, TriMesh};
use pdeshape::mesh::MeshInfo;
use pdeshape::render::{self as pic, Polyline, RenderOptions};
use rayon::prelude::*;
use std::io::Write;
use std::path::Path;

/// Frames on the contact sheet (at most; evenly spread, the first and the last included).
const SHEET_FRAMES: usize = 12;
/// Tiles per row of the contact sheet.
const SHEET_COLUMNS: u32 = 4;

fn extension_is(path: &Path, ext: &str) -> bool {
    pdeshape::format::has_extension(path, ext)
}

/// `--picture-size WIDTHxHEIGHT` ([`pdeshape::format::parse_size`]), each side 16 to 4096 (a
/// frame of an animated picture is kept for every frame).
fn parse_size(s: &str) -> Result<(u32, u32), CliError> {
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

/// Checks the flags before any work: extensions, the pairing of `--retarget` with
/// `--retarget-output`, the size and the view.
pub fn check(args: &Args) -> Result<(), CliError> {
    match (&args.retarget, &args.retarget_output) {
        (Some(m), Some(o)) => {
            let ext = m.extension().and_then(|e| e.to_str()).unwrap_or("");
            if MeshFormat::from_extension(&ext.to_ascii_lowercase()).is_none() {
                return Err(CliError::input(format!(
                    "--retarget {}: must end in .obj, .stl or .ply",
                    m.display()
                )));
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

/// `--picture-size`, or its default.
fn picture_size(args: &Args) -> &str {
    args.picture_size.as_deref().unwrap_or("480x360")
}

/// Outputs made and not yet committed, with the words of the report.
#[derive(Default)]
pub struct Pending {
    pub outputs: Vec<Output>,
    pub report: String,
}

fn read_mesh(path: &Path) -> Result<TriMesh, CliError> {
    let shown = path.display();
    let bytes = crate::fit::read_mesh_bytes(path, &format!("--retarget {shown}"))?;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let format = MeshFormat::from_extension(&ext)
        .ok_or_else(|| CliError::input(format!("--retarget {shown}: unknown mesh format")))?;
    TriMesh::read(&bytes, format).map_err(|e| CliError::input(format!("--retarget {shown}: {e}")))
}

/// The frames on the contact sheet: up to [`SHEET_FRAMES`], evenly spread.
fn sheet_frames(n: usize) -> Vec<usize> {
    if n <= SHEET_FRAMES {
        return (0..n).collect();
    }
    (0..SHEET_FRAMES)
        .map(|k| (k * (n - 1) + (SHEET_FRAMES - 1) / 2) / (SHEET_FRAMES - 1))
        .collect()
}

/// What the extra outputs take from the one pass over the frames: the re-targeted mesh's frames
/// and the overlays (condition curves) of every frame for the pictures. The pictures themselves
/// are drawn after the pass, from the frames' welded meshes, framed by the box around all of
/// them.
pub struct Collector {
    retarget: Option<Retarget>,
    overlays: Option<Vec<Vec<Polyline>>>,
}

impl Collector {
    /// Reads the mesh to re-target (anchored on the design at the first time) before any frame
    /// is solved.
    pub fn new(args: &Args, l: &Animated, times: &[f64]) -> Result<Collector, CliError> {
        let located = |e: pdeshape::Error| l.design.error(&e);
        let retarget = match &args.retarget {
            Some(path) => {
                let mesh = read_mesh(path)?;
                let spec = l.anim.spec_at(times[0]).map_err(located)?;
                let compiled = pdeshape::design::compile(&spec).map_err(located)?;
                let r = Retarget::new(
                    compiled.solved(),
                    &mesh.positions,
                    mesh.triangles,
                    l.anim.time(),
                )
                .map_err(|e| CliError::input(format!("--retarget {}: {e}", path.display())))?;
                Some(r)
            }
            None => None,
        };
        let pictures = args.apng.is_some()
            || args.gif.is_some()
            || args.contact_sheet.is_some()
            || args.frames_dir.is_some();
        Ok(Collector {
            retarget,
            overlays: pictures.then(Vec::new),
        })
    }

    /// Takes what it needs of a frame (called for every frame, in order).
    pub fn frame(&mut self, f: &anim::Frame) -> pdeshape::Result<()> {
        if let Some(r) = self.retarget.as_mut() {
            r.push(f.t, f.solved)?;
        }
        if let Some(o) = self.overlays.as_mut() {
            o.push(pic::overlay_lines(&f.solved.overlays()));
        }
        Ok(())
    }

    /// The overlays of frame `k` with the box that frames every picture alike.
    fn overlays(&self, k: usize, boxed: &Polyline) -> Vec<Polyline> {
        let mut o = self
            .overlays
            .as_ref()
            .and_then(|o| o.get(k).cloned())
            .unwrap_or_default();
        o.push(boxed.clone());
        o
    }
}

/// The PNG pictures of every frame for `--frames-dir` (drawn like `pdeshape render`'s default),
/// in parallel.
pub fn frame_pictures(keys: &Keyframes, c: &Collector) -> pdeshape::Result<Vec<Vec<u8>>> {
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

/// Makes the outputs these flags ask for from the frames of the one pass (`keys`, and what
/// `c` took of every frame); nothing when none is asked for.
pub fn run(
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
