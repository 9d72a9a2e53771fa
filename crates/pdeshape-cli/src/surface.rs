//! `pdeshape surface DESIGN -o OUT`: solve, tessellate, write (obj, stl, ply, glb, csv).

use crate::common::{self, CliError, Output};
use pdeshape::design::Export;
use pdeshape::design::WriteDesign as _;
use pdeshape::format::OutputFormat;
use pdeshape::mesh::{Format, Up};
use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args, Debug)]
pub(crate) struct Args {
    /// The design file (TOML).
    pub design: PathBuf,
    /// Set a design parameter (a `[[parameters]]` entry) to a value within its bounds;
    /// repeatable, e.g. `--set theta=0.3 --set s=1.2`.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// Output file; the extension picks the format: obj, stl, ply, glb, csv, or step/stp and
    /// igs/iges (B-spline surfaces with their deviation). `-` writes to standard output (with
    /// --format).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The format (obj, stl, ply, glb or csv), when -o has no extension or is `-`.
    #[arg(long)]
    pub format: Option<String>,
    /// Grid rows (values of u; default from [output] or 64; n-sided patches, networks and
    /// patchworks take a square grid, coarser by default for designs of more than 256 pieces).
    #[arg(long)]
    pub nu: Option<usize>,
    /// Grid columns (values of v; default from [output] or 128).
    #[arg(long)]
    pub nv: Option<usize>,
    /// Print one JSON line of times (ms) on stderr: solve, tessellate, write (= weld + file +
    /// commit: welding the patches, encoding and writing the file, syncing and renaming it) and
    /// the total since the process started. A GLB is written straight from the grids, the weld
    /// planned as part of the file's time (its weld time is 0).
    #[arg(long)]
    pub timings: bool,
    /// Multiply every position by this factor (finite, positive) before writing a mesh.
    #[arg(long, default_value_t = 1.0)]
    pub scale: f64,
    /// The up axis of an OBJ, STL or PLY file: z (as designed) or y (the design's +Z turned to
    /// +Y). glTF is always +Y up.
    #[arg(long, value_enum)]
    pub up: Option<UpAxis>,
    /// Keep the patches apart: each is welded (poles, seams) and oriented on its own instead of
    /// joining patches that share an edge into one mesh.
    #[arg(long)]
    pub separate_patches: bool,
    /// Also draw the surface (with its boundary curves and spine) into this PNG file, as
    /// `pdeshape render` does with its default view and size.
    #[arg(long)]
    pub picture: Option<PathBuf>,
    /// Colour the `--picture` by Gaussian (`gauss`) or mean (`mean`) curvature, with a colour bar
    /// (range as `pdeshape render --color`).
    #[arg(long, value_enum)]
    pub color: Option<crate::analyze::ColorBy>,
    /// STEP/IGES: the largest deviation of the B-splines from the surfaces (design units;
    /// default 10⁻⁴ of the design's size).
    #[arg(long)]
    pub tolerance: Option<f64>,
    /// STEP/IGES: the length unit the file declares (mm, cm, m or in; default: the design's
    /// `units`, else mm).
    #[arg(long)]
    pub units: Option<String>,
    /// Evaluate a time-dependent design (formulas in t, or a morph file) at this time.
    #[arg(long)]
    pub time: Option<f64>,
}

/// The `--up` values.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum UpAxis {
    Z,
    Y,
}

/// The export options of `--scale`, `--up` and `--separate-patches` for `format`, refused with
/// the flag's name.
pub(crate) fn export_options(
    format: Format,
    scale: f64,
    up: Option<UpAxis>,
    separate_patches: bool,
) -> Result<Export, CliError> {
    if !(scale.is_finite() && scale > 0.0) {
        return Err(CliError::input(format!(
            "--scale: must be finite and positive (got {scale})"
        )));
    }
    let up = match (format, up) {
        (Format::Glb, Some(UpAxis::Z)) => {
            return Err(CliError::input(
                "--up z: glTF is +Y up by definition (the design's +Z is turned to +Y); --up applies to obj, stl and ply",
            ))
        }
        (_, Some(UpAxis::Y)) => Up::Y,
        _ => Up::Z,
    };
    Ok(Export {
        separate_patches,
        scale,
        up,
    })
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

pub(crate) fn run(args: &Args) -> Result<(), CliError> {
    let cad = OutputFormat::from_path(&args.output)
        .ok()
        .filter(|f| f.is_cad());
    if let Some(cad) = cad {
        // STEP/IGES carry the exact surfaces, not a grid, in the design's own axes and size.
        let what = "STEP or IGES output (exact B-spline surfaces)";
        common::refuse_grid_flags(args.nu, args.nv, "STEP or IGES output")?;
        common::refuse_flag(args.scale != 1.0, "--scale", what)?;
        common::refuse_flag(args.up.is_some(), "--up", what)?;
        common::refuse_flag(args.separate_patches, "--separate-patches", what)?;
        common::refuse_flag(args.picture.is_some(), "--picture", what)?;
        common::refuse_flag(args.timings, "--timings", what)?;
        common::refuse_flag(args.time.is_some(), "--time", what)?;
        return crate::cad::write(
            &args.design,
            &args.output,
            cad,
            args.tolerance,
            args.units.as_deref(),
        );
    }
    let shown = args.output.display().to_string();
    let format = common::output_format(
        &args.output,
        args.format.as_deref(),
        "obj, stl, ply, glb or csv",
    )?;
    let what = "mesh and sample output (only STEP and IGES)";
    common::refuse_flag(args.tolerance.is_some(), "--tolerance", what)?;
    common::refuse_flag(args.units.is_some(), "--units", what)?;
    if format == Format::Csv {
        // Samples are written as evaluated, at full precision, one grid per patch.
        let what = "csv samples (written as designed, one grid per patch)";
        common::refuse_flag(args.scale != 1.0, "--scale", what)?;
        common::refuse_flag(args.up.is_some(), "--up", what)?;
        common::refuse_flag(args.separate_patches, "--separate-patches", what)?;
    }
    let export = export_options(format, args.scale, args.up, args.separate_patches)?;
    let mut design = match args.time {
        Some(t) => crate::animate::load_at(&args.design, t)?,
        None => common::load(&args.design)?,
    };
    common::apply_sets(&mut design, &args.set)?;
    design.validate()?;
    let (nu, nv) = design.grid(args.nu, args.nv)?;
    if let Some(pic) = &args.picture {
        crate::render::check_png_path(pic)?;
    }
    if args.color.is_some() && args.picture.is_none() {
        return Err(CliError::input(
            "--color: colours the picture; needs --picture",
        ));
    }
    let mut out = Output::create(&args.output)?;
    let mut picture_out = args
        .picture
        .as_ref()
        .map(|p| Output::create(p))
        .transpose()?;

    let t = Instant::now();
    let solved = design.build()?;
    let solve_ms = ms(t);
    if solved.surfaces.is_empty() {
        return Err(design.error(&pdeshape::Error::no_surface()));
    }
    // A grid-evaluation error names a condition curve of the design: locate it in the file.
    let located = |e: pdeshape::Error| {
        if e.place().is_empty() {
            CliError::input(format!("-o {shown}: {e}"))
        } else {
            design.error(&e)
        }
    };
    if !solved.trims.is_empty() {
        if args.color.is_some() {
            return Err(CliError::input(
                "--color: curvature colours are not drawn on trimmed designs yet",
            ));
        }
        if format == Format::Csv {
            let origin = solved.trim_origin().unwrap_or_default();
            return Err(CliError::input(format!(
                "-o {shown}: csv stores full grids of samples; {origin}: a trimmed design is \
                 written as obj, stl, ply or glb"
            )));
        }
    }
    let t = Instant::now();
    let mut w = out.writer();
    let written = solved
        .write_timed(format, nu, nv, &export, &mut w)
        .map_err(located)?;
    w.flush()
        .map_err(|e| CliError::input(format!("-o {shown}: {e}")))?;
    drop(w);
    let tessellate_ms = written.timings.tessellate_ms;
    let weld_ms = written.timings.weld_ms;
    let write_ms = ms(t) - tessellate_ms;
    let file_ms = write_ms - weld_ms;
    // The picture is drawn before anything is committed, so a failure leaves neither file.
    if let Some(pic) = picture_out.as_mut() {
        let options = pdeshape::render::RenderOptions::default();
        let png = match (written.tri_mesh, args.color) {
            (Some(m), _) => pdeshape::render::render_png_tri(
                &m,
                &pdeshape::render::overlay_lines(&solved.overlays()),
                &options,
            ),
            (None, None) => {
                let meshes = match written.grids {
                    Some(m) => m,
                    None => solved.meshes(nu, nv).map_err(located)?,
                };
                pdeshape::render::render_png(
                    &meshes,
                    &pdeshape::render::overlay_lines(&solved.overlays()),
                    &options,
                )
            }
            (None, Some(by)) => {
                let meshes = match written.grids {
                    Some(m) => m,
                    None => solved.meshes(nu, nv).map_err(located)?,
                };
                let (colors, lo, hi) =
                    crate::analyze::curvature_colors(&solved, &meshes, by, None)?;
                let bar = crate::render::curvature_bar(by, lo, hi, false);
                pdeshape::render::render_png_colored_with_bar(
                    &meshes,
                    &colors,
                    &pdeshape::render::overlay_lines(&solved.overlays()),
                    &options,
                    &bar,
                )
            }
        }
        .map_err(|e| CliError::input(e.to_string()))?;
        pic.write_all(&png)?;
    }
    let t = Instant::now();
    out.commit()?;
    if let Some(pic) = picture_out {
        pic.commit()?;
    }
    let commit_ms = ms(t);
    let write_ms = write_ms + commit_ms;
    if args.timings {
        // write_ms = weld_ms + file_ms (encoding and handing the bytes to the file) + commit_ms
        // (the file synced to disk and renamed into place, the picture's too); total_ms runs
        // from the start of the process's main function to here.
        eprintln!(
            "{}",
            serde_json::json!({
                "solve_ms": solve_ms,
                "tessellate_ms": tessellate_ms,
                "write_ms": write_ms,
                "weld_ms": weld_ms,
                "file_ms": file_ms,
                "commit_ms": commit_ms,
                "total_ms": crate::common::since_start_ms(),
            })
        );
    }
    let n = solved.surfaces.len();
    let fd = match solved.fd_grid {
        Some([gu, gv]) => format!(" (finite differences on {gu} × {gv})"),
        None => String::new(),
    };
    let picture = match &args.picture {
        Some(p) => format!("; wrote {}", p.display()),
        None => String::new(),
    };
    let dest = crate::common::destination(&args.output);
    crate::common::report(&format!(
        "wrote {dest}: {n} patch{}, {nu} × {nv} grid{fd}{picture}\n",
        if n == 1 { "" } else { "es" }
    ));
    Ok(())
}
