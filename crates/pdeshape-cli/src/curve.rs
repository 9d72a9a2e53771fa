//! `pdeshape curve DESIGN -o curve.csv [--frames frames.csv] [--picture curve.svg]`: run the
//! `[dynamic]` section of a design (a general run of the scheme or an interpolation) and write the
//! final curve, the frames of its evolution and a picture.

use crate::common::{self, CliError, Output};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use pdeshape::design::{self, DynamicPlan};
use pdeshape::dynamic::CurveFrame;
use pdeshape::dynamic_output as output;
use pdeshape::dynamic_run::OutcomeKind;
use pdeshape::Vec3;
use std::io::Write;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub(crate) struct Args {
    /// The design file (TOML) with a [dynamic] section.
    pub design: PathBuf,
    /// The final curve as CSV (`u,x[,y[,z]]`, one row per grid node, full precision).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Also write the frames of the evolution as CSV (`step,t,u,x[,y[,z]]`), every
    /// `frames_every`-th level of the run.
    #[arg(long)]
    pub frames: Option<PathBuf>,
    /// Also draw the initial, some intermediate and the final curve with the data points as an
    /// SVG picture.
    #[arg(long)]
    pub picture: Option<PathBuf>,
}

/// Frames kept for the picture: at most this many (thinned by halves beyond).
const PICTURE_FRAMES: usize = 64;
/// Intermediate curves drawn.
const PICTURE_INTERMEDIATE: usize = 4;
const PICTURE_SIZE: (u32, u32) = (900, 600);

/// Keeps at most `PICTURE_FRAMES` frames, evenly thinned, always with the first.
fn keep_for_picture(kept: &mut Vec<CurveFrame>, frame: CurveFrame) {
    kept.push(frame);
    if kept.len() > PICTURE_FRAMES {
        let mut i = 0;
        kept.retain(|_| {
            i += 1;
            (i - 1) % 2 == 0
        });
    }
}

fn progress(total: u64, what: &str) -> ProgressBar {
    let target = if common::quiet() {
        ProgressDrawTarget::hidden()
    } else {
        ProgressDrawTarget::stderr()
    };
    let pb = ProgressBar::with_draw_target(Some(total), target);
    if let Ok(style) =
        ProgressStyle::with_template("{prefix} [{bar:40}] {pos}/{len} steps {msg} ({elapsed})")
    {
        pb.set_style(style.progress_chars("=> "));
    }
    pb.set_prefix(what.to_string());
    pb
}

pub(crate) fn run(args: &Args) -> Result<(), CliError> {
    common::check_extension(&args.output, "-o", "csv")?;
    if let Some(f) = &args.frames {
        common::check_extension(f, "--frames", "csv")?;
    }
    if let Some(p) = &args.picture {
        common::check_extension(p, "--picture", "svg")?;
    }
    let design = common::load(&args.design)?;
    let Some(section) = design.spec.dynamic.as_ref() else {
        return Err(CliError::input(format!(
            "{}: the design has no [dynamic] section: `pdeshape curve` runs dynamic curves \
             (for the surface of this design use `pdeshape surface`)",
            design.file
        )));
    };
    let built = design::build_dynamic(section).map_err(|e| design.error(&e))?;

    let mut out = Output::create(&args.output)?;
    let mut frames_out = args.frames.as_deref().map(Output::create).transpose()?;
    let mut picture_out = args.picture.as_deref().map(Output::create).transpose()?;

    let dim = pdeshape::dynamic_run::dimension(&built);
    // The run's storage and the frames held at once (the picture keeps up to
    // `PICTURE_FRAMES + 1`; the last frame and the one being observed), before any of it is
    // allocated.
    let (held, held_for) = if args.picture.is_some() {
        (PICTURE_FRAMES + 3, Some("--picture"))
    } else {
        (2, None)
    };
    pdeshape::dynamic_run::check_memory(&built, held, held_for).map_err(|e| design.error(&e))?;
    let frames_shown = args
        .frames
        .as_ref()
        .map(|p| p.display().to_string())
        .unwrap_or_default();
    let frames_err = |e: pdeshape::Error| CliError::input(format!("--frames {frames_shown}: {e}"));
    let mut frames_writer = frames_out.as_mut().map(|o| o.writer());
    if let Some(w) = frames_writer.as_mut() {
        output::write_frames_header(dim, w).map_err(frames_err)?;
    }
    let mut write_error: Option<pdeshape::Error> = None;
    let mut kept: Vec<CurveFrame> = Vec::new();
    let mut last_frame: Option<CurveFrame> = None;
    let want_picture = picture_out.is_some();
    let (total, label) = match &built.plan {
        DynamicPlan::Run(r) => (r.grid.steps as u64, "curve"),
        DynamicPlan::Interpolate { problem, .. } => (problem.max_steps as u64, "interpolate"),
    };
    let pb = progress(total, label);
    let mut observer = |n: usize, t: f64, nodes: Option<&[Vec3]>| {
        if n.is_multiple_of(256) {
            pb.set_position(n as u64);
        }
        if let Some(nodes) = nodes {
            let frame = CurveFrame {
                step: n,
                time: t,
                nodes: nodes.to_vec(),
            };
            if let (Some(w), None) = (frames_writer.as_mut(), &write_error) {
                if let Err(e) = output::write_frame_rows(&frame, dim, w) {
                    write_error = Some(e);
                }
            }
            if want_picture {
                keep_for_picture(&mut kept, frame.clone());
            }
            last_frame = Some(frame);
        }
    };

    let outcome =
        pdeshape::dynamic_run::run(&built, &mut observer).map_err(|e| design.error(&e))?;
    let mut report = outcome.report();
    let (data_points, end_points) = match &outcome.kind {
        OutcomeKind::Interpolate(r) => (r.points.clone(), r.ends.to_vec()),
        OutcomeKind::Run(_) => (Vec::new(), Vec::new()),
    };
    let nodes = outcome.nodes;
    pb.finish_and_clear();
    if let Some(e) = write_error {
        return Err(frames_err(e));
    }
    if let Some(w) = frames_writer.as_mut() {
        w.flush()
            .map_err(|e| CliError::input(format!("--frames {frames_shown}: {e}")))?;
    }
    drop(frames_writer);
    let shown = args.output.display().to_string();
    {
        let mut w = out.writer();
        output::write_curve_csv(&nodes, dim, &mut w)
            .map_err(|e| CliError::input(format!("-o {shown}: {e}")))?;
        w.flush()
            .map_err(|e| CliError::input(format!("-o {shown}: {e}")))?;
    }
    if let Some(pic) = picture_out.as_mut() {
        if let Some(last) = last_frame {
            if kept.last().map(|f| f.step) != Some(last.step) {
                kept.push(last);
            }
        }
        let picked = output::pick_frames(&kept, PICTURE_INTERMEDIATE);
        let svg = output::svg_picture(
            &picked,
            &data_points,
            &end_points,
            dim,
            PICTURE_SIZE.0,
            PICTURE_SIZE.1,
        )
        .map_err(|e| CliError::input(format!("--picture: {e}")))?;
        pic.write_all(svg.as_bytes())?;
    }
    out.commit()?;
    if let Some(f) = frames_out {
        f.commit()?;
    }
    if let Some(p) = picture_out {
        p.commit()?;
    }
    report.push_str(&format!(
        "wrote {}: {} nodes\n",
        crate::common::destination(&args.output),
        nodes.len()
    ));
    if let Some(f) = &args.frames {
        report.push_str(&format!("wrote {}: frames\n", f.display()));
    }
    if let Some(p) = &args.picture {
        report.push_str(&format!("wrote {}: picture\n", p.display()));
    }
    common::report(&report);
    Ok(())
}
