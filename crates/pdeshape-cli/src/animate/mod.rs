//! `pdeshape animate DESIGN -o OUT.glb`: a time-dependent design (a `[time]` section with
//! formula fields in `t`, or a morph file with `[morph]`) solved at every frame and written as
//! a glTF animation, with the measures of every frame (CSV, SVG plot) and a PNG per frame.

use crate::common::{self, CliError, Loaded, Output};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use pdeshape::anim::{self, Animation, Keyframes, Measures, Row};
use pdeshape::design::Export;
use pdeshape::mesh::MeshInfo;
use std::io::Write;
use std::path::PathBuf;

mod load;
mod outputs;
mod pictures;
mod retarget;
pub(crate) use load::{load, load_at};

#[derive(clap::Args, Debug)]
pub(crate) struct Args {
    /// The design file (TOML) with a [time] section, or a morph file with [morph].
    pub design: PathBuf,
    /// The animation (glTF binary, .glb): one mesh with a morph target per frame and an
    /// animation of their weights.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Also write the measures of every frame (frame, t, area, volume) to this CSV file.
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Also plot the measures (volume and area against t) into this SVG file.
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Also render every frame into this directory as frame_0000.png, … (created if missing).
    #[arg(long)]
    pub frames_dir: Option<PathBuf>,
    /// Grid rows (values of u; default from [output] or 64).
    #[arg(long)]
    pub nu: Option<usize>,
    /// Grid columns (values of v; default from [output] or 128).
    #[arg(long)]
    pub nv: Option<usize>,
    /// Multiply every position by this factor (finite, positive).
    #[arg(long, default_value_t = 1.0)]
    pub scale: f64,
    /// Re-target the motion onto this triangle mesh (OBJ, STL, PLY, OFF or glTF, in the design's
    /// units; a file that states its units, as glTF does, is converted to them): each vertex
    /// follows its closest point on the design at the first frame.
    #[arg(long)]
    pub retarget: Option<PathBuf>,
    /// Where the re-targeted mesh's animation goes (.glb; required with --retarget).
    #[arg(long)]
    pub retarget_output: Option<PathBuf>,
    /// Also write the frames as an animated PNG (APNG, looping; one frame per frame of [time]).
    #[arg(long)]
    pub apng: Option<PathBuf>,
    /// Also write the frames as an animated GIF (looping; 256 colours per frame, each pixel at
    /// its nearest palette colour; the delay from [time] in hundredths of a second).
    #[arg(long)]
    pub gif: Option<PathBuf>,
    /// Also write a contact sheet: up to 12 frames, evenly spread, in one PNG.
    #[arg(long)]
    pub contact_sheet: Option<PathBuf>,
    /// Size of each picture of --apng, --gif and --contact-sheet, WIDTHxHEIGHT (default:
    /// 480x360).
    #[arg(long)]
    pub picture_size: Option<String>,
    /// Direction from the object towards the eye for --apng, --gif and --contact-sheet, x,y,z
    /// (default: a three-quarter view).
    #[arg(long)]
    pub view: Option<String>,
}

fn progress(total: u64) -> ProgressBar {
    let target = if common::quiet() || total < 8 {
        ProgressDrawTarget::hidden()
    } else {
        ProgressDrawTarget::stderr()
    };
    let pb = ProgressBar::with_draw_target(Some(total), target);
    if let Ok(style) =
        ProgressStyle::with_template("{prefix} [{bar:40}] {pos}/{len} frames {msg} ({elapsed})")
    {
        pb.set_style(style.progress_chars("=> "));
    }
    pb.set_prefix("animate");
    pb
}

pub(crate) fn run(args: &Args) -> Result<(), CliError> {
    common::check_extension(&args.output, "-o", "glb")?;
    if let Some(p) = &args.csv {
        common::check_extension(p, "--csv", "csv")?;
    }
    if let Some(p) = &args.plot {
        common::check_extension(p, "--plot", "svg")?;
    }
    if !(args.scale.is_finite() && args.scale > 0.0) {
        return Err(CliError::input(format!(
            "--scale: must be finite and positive (got {})",
            args.scale
        )));
    }
    outputs::check(args)?;
    let l = load(&args.design)?;
    let mut grid_spec = l.design.spec.clone();
    grid_spec.output = l.output.clone();
    let grid_of = Loaded {
        file: l.design.file.clone(),
        text: l.design.text.clone(),
        spec: grid_spec,
    };
    let (nu, nv) = grid_of.grid(args.nu, args.nv)?;
    let times = l.anim.times().map_err(|e| {
        let shown = args.design.display().to_string();
        match &l.anim {
            Animation::Timed(_) => l.design.error(&e),
            Animation::Morph { .. } => CliError::input(format!("{shown}: {e}")),
        }
    })?;
    let mut out = Output::create(&args.output)?;
    let mut csv_out = args.csv.as_deref().map(Output::create).transpose()?;
    let mut plot_out = args.plot.as_deref().map(Output::create).transpose()?;
    if let Some(dir) = &args.frames_dir {
        std::fs::create_dir_all(dir).map_err(|e| {
            CliError::input(format!(
                "--frames-dir {}: {}",
                dir.display(),
                common::io_words(&e)
            ))
        })?;
    }
    let export = Export::default();
    let mut keys = Keyframes::new(l.anim.time());
    let mut measures = Measures {
        units: l.design.spec.units.unwrap_or_default().as_str().to_string(),
        ..Measures::default()
    };
    let want_measures = csv_out.is_some() || plot_out.is_some();
    let mut collector = retarget::Collector::new(args, &l, &times)?;
    let pb = progress(times.len() as u64);
    let located = |e: pdeshape::Error| l.design.error(&e);
    let shown = args.output.display().to_string();
    // The GLB takes every frame as it comes; the vertices of all frames are kept only for the
    // pictures.
    let pictures = args.frames_dir.is_some()
        || args.apng.is_some()
        || args.gif.is_some()
        || args.contact_sheet.is_some();
    let mut glb: Option<anim::GlbFrames> = None;
    let mut glb_failed = false;
    let solved = anim::for_each_frame(&l.anim, &times, nu, nv, &export, |f| {
        if pictures {
            keys.push(&f);
        } else {
            keys.push_time(&f);
        }
        let (p, n) = (&f.mesh.positions, &f.mesh.normals);
        let step = match glb.as_mut() {
            Some(g) => g.push(p, n),
            None => {
                let info = MeshInfo {
                    units: f.solved.units,
                    scale: args.scale,
                    ..MeshInfo::default()
                };
                anim::GlbFrames::new(&info, &f.mesh.triangles, p, n, times.len())
                    .map(|g| glb = Some(g))
            }
        };
        if step.is_err() {
            glb_failed = true;
        }
        step?;
        collector.frame(&f)?;
        if want_measures {
            let (area, volume) = anim::measure(f.solved)?;
            measures.rows.push(Row {
                t: f.t,
                epsilon: l.anim.epsilon(f.t),
                area,
                volume,
            });
        }
        pb.inc(1);
        Ok(())
    });
    if let Err(e) = solved {
        return Err(if glb_failed {
            CliError::input(format!("-o {shown}: {e}"))
        } else {
            located(e)
        });
    }
    pb.finish_and_clear();
    let title = l.title.clone().or_else(|| keys.title.clone());
    let info = MeshInfo {
        title: title.clone(),
        units: keys.units,
        scale: args.scale,
        ..MeshInfo::default()
    };
    let vertices = glb.as_ref().map_or(0, anim::GlbFrames::vertices);
    {
        let glb = glb.ok_or_else(|| {
            CliError::input(format!(
                "-o {shown}: the animation has no frame with triangles"
            ))
        })?;
        let mut w = out.writer();
        glb.finish(&keys, &info, &mut w)
            .map_err(|e| CliError::input(format!("-o {shown}: {e}")))?;
        w.flush()
            .map_err(|e| CliError::input(format!("-o {shown}: {e}")))?;
    }
    if let Some(o) = csv_out.as_mut() {
        let mut w = o.writer();
        measures
            .write_csv(&mut w)
            .and_then(|_| w.flush())
            .map_err(|e| CliError::input(format!("--csv: {}", common::io_words(&e))))?;
    }
    if let Some(o) = plot_out.as_mut() {
        let name = title.clone().unwrap_or_else(|| "pdeshape animate".into());
        o.write_all(measures.svg(&name).as_bytes())?;
    }
    // Pictures of every frame, from the frames already solved (framed by the box around all).
    let mut pictures = Vec::new();
    if let Some(dir) = &args.frames_dir {
        let pngs = pictures::frame_pictures(&keys, &collector).map_err(located)?;
        for (k, png) in pngs.iter().enumerate() {
            let mut o = Output::create(&dir.join(format!("frame_{k:04}.png")))?;
            o.write_all(png)?;
            pictures.push(o);
        }
    }
    let more = outputs::run(args, &l, &times, &keys, collector)?;
    out.commit()?;
    if let Some(o) = csv_out {
        o.commit()?;
    }
    if let Some(o) = plot_out {
        o.commit()?;
    }
    let n_pictures = pictures.len();
    for p in pictures {
        p.commit()?;
    }
    let mut extra = String::new();
    if let Some(p) = &args.csv {
        extra += &format!("; wrote {}", p.display());
    }
    if let Some(p) = &args.plot {
        extra += &format!("; wrote {}", p.display());
    }
    if let Some(d) = &args.frames_dir {
        extra += &format!("; wrote {n_pictures} pictures in {}", d.display());
    }
    for o in more.outputs {
        o.commit()?;
    }
    extra += &more.report;
    common::report(&format!(
        "wrote {shown}: {} frames, {nu} × {nv} grid, {} vertices{}{extra}\n",
        times.len(),
        vertices,
        if keys.looped { ", looped" } else { "" }
    ));
    Ok(())
}
