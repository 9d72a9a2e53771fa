//! `pdeshape surface DESIGN -o OUT`: solve, tessellate, write (obj, stl, ply, glb, csv).

use crate::common::{self, CliError, Output};
use pdeshape::mesh::{self, Format};
use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The design file (TOML).
    pub design: PathBuf,
    /// Output file; the extension picks the format: obj, stl, ply, glb or csv. `-` writes to
    /// standard output (with --format).
    #[arg(short, long)]
    pub output: PathBuf,
    /// The format (obj, stl, ply, glb or csv), when -o has no extension or is `-`.
    #[arg(long)]
    pub format: Option<String>,
    /// Grid rows (values of u; default from [output] or 64).
    #[arg(long)]
    pub nu: Option<usize>,
    /// Grid columns (values of v; default from [output] or 128).
    #[arg(long)]
    pub nv: Option<usize>,
    /// Print one JSON line with the solve, tessellate and write times (ms) on stderr.
    #[arg(long)]
    pub timings: bool,
    /// Also draw the surface (with its boundary curves and spine) into this PNG file, as
    /// `pdeshape render` does with its default view and size.
    #[arg(long)]
    pub picture: Option<PathBuf>,
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

pub fn run(args: &Args) -> Result<(), CliError> {
    let shown = args.output.display().to_string();
    let fpath = common::format_path(
        &args.output,
        args.format.as_deref(),
        "obj, stl, ply, glb or csv",
    )?;
    let flag = if args.format.is_some() {
        "--format"
    } else {
        "-o"
    };
    let format = Format::from_path(&fpath).map_err(|e| {
        let shown = args.format.as_deref().unwrap_or(&shown);
        CliError::input(format!("{flag} {shown}: {}", common::message_of(&e)))
    })?;
    let design = common::load(&args.design)?;
    design.validate()?;
    let (nu, nv) = design.grid(args.nu, args.nv)?;
    if let Some(pic) = &args.picture {
        crate::render::check_png_path(pic)?;
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
        return Err(design.error(&pdeshape::Error::invalid(
            "the design has no surface (only a [dynamic] curve: `pdeshape curve` runs it)",
        )));
    }
    // A grid-evaluation error names a condition curve of the design: locate it in the file.
    let located = |e: pdeshape::Error| {
        if e.place().is_empty() {
            CliError::input(format!("-o {shown}: {e}"))
        } else {
            design.error(&e)
        }
    };
    let t = Instant::now();
    let (meshes, samples) = if format == Format::Csv {
        (None, Some(solved.samples(nu, nv).map_err(located)?))
    } else {
        (Some(solved.meshes(nu, nv).map_err(located)?), None)
    };
    let tessellate_ms = ms(t);
    let t = Instant::now();
    let mut w = out.writer();
    match (&meshes, &samples) {
        (_, Some(samples)) => mesh::write_csv(samples, &mut w),
        (Some(meshes), _) => mesh::write(format, meshes, &mut w),
        (None, None) => unreachable!("one of the two was made"),
    }
    .map_err(|e| CliError::input(format!("-o {shown}: {e}")))?;
    w.flush()
        .map_err(|e| CliError::input(format!("-o {shown}: {e}")))?;
    drop(w);
    let write_ms = ms(t);
    // The picture is drawn before anything is committed, so a failure leaves neither file.
    if let Some(pic) = picture_out.as_mut() {
        let meshes = match meshes {
            Some(m) => m,
            None => solved.meshes(nu, nv).map_err(located)?,
        };
        let png = pdeshape::render::render_png(
            &meshes,
            &solved.overlays(),
            &pdeshape::render::RenderOptions::default(),
        )
        .map_err(|e| CliError::input(e.to_string()))?;
        pic.write_all(&png)?;
    }
    let t = Instant::now();
    out.commit()?;
    if let Some(pic) = picture_out {
        pic.commit()?;
    }
    let write_ms = write_ms + ms(t);
    if args.timings {
        eprintln!(
            "{}",
            serde_json::json!({
                "solve_ms": solve_ms,
                "tessellate_ms": tessellate_ms,
                "write_ms": write_ms,
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
    crate::common::report(&format!(
        "wrote {shown}: {n} patch{}, {nu} × {nv} grid{fd}{picture}\n",
        if n == 1 { "" } else { "es" }
    ));
    Ok(())
}
