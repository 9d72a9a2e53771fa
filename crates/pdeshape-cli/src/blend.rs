//! `pdeshape blend DESIGN -o OUT`: solve the `[blend]` section (a smoothing PDE spline on BFS
//! elements joining two primary surfaces), write it (obj, stl, ply, glb, csv or the .json control
//! net) and report the G0/G1 mismatch along both joins and the distance to every data point.

use crate::common::{self, CliError, Loaded, Output};
use pdeshape::bfs::Blend;
use pdeshape::design::SurfaceKind;
use pdeshape::format::OutputFormat;
use pdeshape::mesh::{self, Format};
use std::fmt::Write as _;
use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args, Debug)]
pub(crate) struct Args {
    /// The design file (TOML) with a [blend] section.
    pub design: PathBuf,
    /// Output file; the extension picks the format: obj, stl, ply, glb, csv, or json (the Bézier
    /// and B-spline control nets).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The format (obj, stl, ply, glb, csv or json), when -o has no extension or is `-`
    /// (standard output).
    #[arg(long)]
    pub format: Option<String>,
    /// Grid rows (values of x, along the joins; default from [output] or 64).
    #[arg(long)]
    pub nu: Option<usize>,
    /// Grid columns (values of y, across; default from [output] or 128).
    #[arg(long)]
    pub nv: Option<usize>,
    /// Multiply every position by this factor (finite, positive) before writing a mesh.
    #[arg(long, default_value_t = 1.0)]
    pub scale: f64,
    /// The up axis of an OBJ, STL or PLY file: z (as designed) or y. glTF is always +Y up.
    #[arg(long, value_enum)]
    pub up: Option<crate::surface::UpAxis>,
    /// Print one JSON line of times (ms) on stderr, as `pdeshape surface --timings`: solve,
    /// tessellate, write (= weld + file + commit) and the total since the process started.
    #[arg(long)]
    pub timings: bool,
}

/// Solves the design's blend (errors located in the file); its primary surfaces may be
/// surfaces of the design.
pub(crate) fn solve(design: &Loaded) -> Result<std::sync::Arc<Blend>, CliError> {
    if design.spec.blend.is_none() {
        return Err(design.error(&pdeshape::Error::invalid(
            "the design has no [blend] section (pdeshape blend solves blends; use `pdeshape \
             surface` for conditions and patches)",
        )));
    }
    let solved = design.build()?;
    solved
        .surfaces
        .iter()
        .find_map(|s| match &s.kind {
            SurfaceKind::Blend(b) => Some(b.clone()),
            _ => None,
        })
        .ok_or_else(|| CliError::input("the design's blend was not solved"))
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

pub(crate) fn run(args: &Args) -> Result<(), CliError> {
    let shown = args.output.display().to_string();
    let request = common::format_request(
        &args.output,
        args.format.as_deref(),
        "obj, stl, ply, glb, csv or json",
    )?;
    let format = if request.names("json") {
        None
    } else {
        let format = request
            .output_format()
            .and_then(OutputFormat::mesh)
            .map_err(|e| {
                CliError::input(format!(
                    "{} {}: {} (or json for the control net)",
                    request.flag,
                    request.shown,
                    common::message_of(&e)
                ))
            })?;
        Some(format)
    };
    let export = match format {
        Some(f) => Some(crate::surface::export_options(
            f, args.scale, args.up, false,
        )?),
        None => None,
    };
    if format.is_none() {
        common::refuse_grid_flags(args.nu, args.nv, "a .json control net")?;
    }
    if matches!(format, None | Some(Format::Csv)) {
        // The control net and the samples are written as designed.
        let what = "a .json control net or csv samples (written as designed)";
        common::refuse_flag(args.scale != 1.0, "--scale", what)?;
        common::refuse_flag(args.up.is_some(), "--up", what)?;
    }
    let design = common::load(&args.design)?;
    let (nu, nv) = if format.is_some() {
        design.grid(args.nu, args.nv)?
    } else {
        (0, 0)
    };
    let t = Instant::now();
    let blend = solve(&design)?;
    let solve_ms = ms(t);
    let mut out = Output::create(&args.output)?;
    let io_err = |e: pdeshape::Error| CliError::input(format!("-o {shown}: {e}"));
    let (mut tessellate_ms, mut weld_ms) = (0.0, 0.0);
    let t = Instant::now();
    match format {
        None => out.write_all(blend.surface.control_net_json().as_bytes())?,
        Some(Format::Csv) => {
            let samples = mesh::sample(&blend.surface, nu, nv).map_err(io_err)?;
            tessellate_ms = ms(t);
            let mut w = out.writer();
            mesh::write_csv(&[samples], &mut w).map_err(io_err)?;
            w.flush()
                .map_err(|e| CliError::input(format!("-o {shown}: {e}")))?;
        }
        Some(f) => {
            // The blend alone, welded (a periodic blend's seam columns become one), named
            // `blend`, with the design's title and units.
            let m = [mesh::tessellate(&blend.surface, nu, nv).map_err(io_err)?];
            tessellate_ms = ms(t);
            let export = export.unwrap_or_default();
            let info = mesh::MeshInfo {
                title: design.spec.title.clone(),
                units: design.spec.units.unwrap_or_default(),
                scale: export.scale,
                up: export.up,
            };
            let options = mesh::WeldOptions::default();
            let mut w = out.writer();
            if f == Format::Glb {
                // Straight from the grid: the weld is planned while the file is written.
                mesh::write_welded(f, &m, &["blend"], options, &info, &mut w).map_err(io_err)?;
            } else {
                let welded = mesh::weld(&m, &["blend"], options);
                weld_ms = ms(t) - tessellate_ms;
                mesh::write_mesh(f, &welded, &info, &mut w).map_err(io_err)?;
            }
            w.flush()
                .map_err(|e| CliError::input(format!("-o {shown}: {e}")))?;
        }
    }
    let file_ms = ms(t) - tessellate_ms - weld_ms;
    let t = Instant::now();
    out.commit()?;
    let commit_ms = ms(t);
    if args.timings {
        // As `surface --timings`: write_ms = weld_ms + file_ms + commit_ms.
        eprintln!(
            "{}",
            serde_json::json!({
                "solve_ms": solve_ms,
                "tessellate_ms": tessellate_ms,
                "write_ms": weld_ms + file_ms + commit_ms,
                "weld_ms": weld_ms,
                "file_ms": file_ms,
                "commit_ms": commit_ms,
                "total_ms": crate::common::since_start_ms(),
            })
        );
    }
    let mut text = pdeshape::diagnostics::blend_report(&design.spec, &blend);
    let what = if format.is_some() {
        format!("{nu} × {nv} grid")
    } else {
        "Bézier and B-spline control nets".to_string()
    };
    let dest = common::destination(&args.output);
    let _ = writeln!(text, "wrote {dest}: {what}");
    common::report(&text);
    Ok(())
}
