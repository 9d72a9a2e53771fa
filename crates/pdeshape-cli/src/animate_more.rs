//! More outputs of `pdeshape animate`: the motion re-targeted onto a separate triangle mesh
//! (`--retarget MESH --retarget-output OUT.glb`), an animated PNG of the frames (`--apng`) and a
//! contact sheet of frames (`--contact-sheet`). They are made in one more pass over the frames
//! and written atomically with the other outputs.

use crate::animate::{frame_box, Animated, Args};
use crate::common::{CliError, Output};
use pdeshape::anim::{self, Keyframes, Retarget};
use pdeshape::design::Export;
use pdeshape::fit::{MeshFormat, TriMesh};
use pdeshape::mesh::MeshInfo;
use pdeshape::render::{self as pic, RenderOptions};
use std::io::Write;
use std::path::Path;

/// Frames on the contact sheet (at most; evenly spread, the first and the last included).
const SHEET_FRAMES: usize = 12;
/// Tiles per row of the contact sheet.
const SHEET_COLUMNS: u32 = 4;

fn extension_is(path: &Path, ext: &str) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case(ext))
}

fn parse_size(s: &str) -> Result<(u32, u32), CliError> {
    let bad = || {
        CliError::input(format!(
            "--picture-size: expected WIDTHxHEIGHT such as 480x360 (got '{s}')"
        ))
    };
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
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
    for (p, flag) in [
        (&args.apng, "--apng"),
        (&args.contact_sheet, "--contact-sheet"),
    ] {
        if let Some(p) = p {
            if !extension_is(p, "png") {
                return Err(CliError::input(format!(
                    "{flag} {}: must end in .png",
                    p.display()
                )));
            }
        }
    }
    parse_size(picture_size(args))?;
    if let Some(v) = &args.view {
        crate::render::parse_view(v)?;
    }
    // Only the pictures of --apng and --contact-sheet take a size and a view (those of
    // --frames-dir are drawn like `pdeshape render`'s default).
    if args.apng.is_none() && args.contact_sheet.is_none() {
        for (given, flag) in [
            (args.picture_size.is_some(), "--picture-size"),
            (args.view.is_some(), "--view"),
        ] {
            if given {
                return Err(CliError::input(format!(
                    "{flag}: applies only to the pictures of --apng and --contact-sheet, and \
                     neither is given"
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

/// Makes the outputs these flags ask for, in one more pass over the frames (nothing when none
/// is asked for). `keys` are the design's frames (their bounds frame every picture alike).
pub fn run(
    args: &Args,
    l: &Animated,
    times: &[f64],
    nu: usize,
    nv: usize,
    keys: &Keyframes,
) -> Result<Pending, CliError> {
    let mut pending = Pending::default();
    let want_pictures = args.apng.is_some() || args.contact_sheet.is_some();
    if args.retarget.is_none() && !want_pictures {
        return Ok(pending);
    }
    let located = |e: pdeshape::Error| l.design.error(&e);
    let mut retarget = match &args.retarget {
        Some(path) => {
            let mesh = read_mesh(path)?;
            let t0 = times[0];
            let spec = l.anim.spec_at(t0).map_err(located)?;
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
    let (lo, hi) = keys.bounds();
    let boxed = frame_box(lo, hi);
    let apng_out = args.apng.as_deref().map(Output::create).transpose()?;
    let mut apng_bytes = Vec::new();
    let mut apng = match apng_out {
        Some(_) => {
            let dt = if times.len() > 1 {
                times[1] - times[0]
            } else {
                l.anim.time().end - l.anim.time().start
            };
            let delay =
                pic::frame_delay(dt).map_err(|e| CliError::input(format!("--apng: {e}")))?;
            Some(
                pic::Apng::new(&mut apng_bytes, width, height, times.len() as u32, delay)
                    .map_err(|e| CliError::input(format!("--apng: {e}")))?,
            )
        }
        None => None,
    };
    let on_sheet = sheet_frames(times.len());
    let mut tiles = Vec::new();
    anim::for_each_frame(&l.anim, times, nu, nv, &Export::default(), |f| {
        if let Some(r) = retarget.as_mut() {
            r.push(f.t, f.solved)?;
        }
        let on = on_sheet.contains(&f.index);
        if apng.is_some() || (args.contact_sheet.is_some() && on) {
            let mut overlays = f.solved.overlays();
            overlays.push(boxed.clone());
            let rgb = pic::render_rgb(f.grids, &overlays, &options)?;
            if let Some(a) = apng.as_mut() {
                a.push(&rgb)?;
            }
            if args.contact_sheet.is_some() && on {
                tiles.push((rgb, format!("t = {}", pic::short_label(f.t))));
            }
        }
        Ok(())
    })
    .map_err(located)?;
    apng.map(pic::Apng::finish)
        .transpose()
        .map_err(|e| CliError::input(format!("--apng: {e}")))?;
    if let (Some(mut o), Some(p)) = (apng_out, &args.apng) {
        o.write_all(&apng_bytes)?;
        pending.outputs.push(o);
        pending.report += &format!("; wrote {}", p.display());
    }
    if let Some(p) = &args.contact_sheet {
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
    if let (Some(r), Some(p)) = (retarget, &args.retarget_output) {
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
