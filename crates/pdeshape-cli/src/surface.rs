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
    /// Output file; the extension picks the format: obj, stl, ply, glb or csv.
    #[arg(short, long)]
    pub output: PathBuf,
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
    let format = Format::from_path(&args.output)
        .map_err(|e| CliError::input(format!("-o {shown}: {}", common::message_of(&e))))?;
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

    if design.spec.solver.method == pdeshape::spec::SolverMethod::Fd {
        return run_fd(args, &design, format, nu, nv, out, picture_out);
    }
    let t = Instant::now();
    let built = design.build()?;
    let solve_ms = ms(t);

    let io_err = |e: pdeshape::Error| CliError::input(format!("-o {shown}: {e}"));
    let (tessellate_ms, write_ms);
    let mut meshes = None;
    if format == Format::Csv {
        let t = Instant::now();
        let samples = common::samples(&built, nu, nv)?;
        tessellate_ms = ms(t);
        let t = Instant::now();
        let mut w = out.writer();
        mesh::write_csv(&samples, &mut w).map_err(io_err)?;
        w.flush()
            .map_err(|e| CliError::input(format!("-o {shown}: {e}")))?;
        drop(w);
        write_ms = ms(t);
    } else {
        let t = Instant::now();
        let m = common::meshes(&built, nu, nv)?;
        tessellate_ms = ms(t);
        let t = Instant::now();
        let mut w = out.writer();
        match format {
            Format::Obj => mesh::write_obj(&m, &mut w),
            Format::Stl => mesh::write_stl(&m, &mut w),
            Format::Ply => mesh::write_ply(&m, &mut w),
            Format::Glb => mesh::write_glb(&m, &mut w),
            Format::Csv => unreachable!("handled above"),
        }
        .map_err(io_err)?;
        meshes = Some(m);
        w.flush()
            .map_err(|e| CliError::input(format!("-o {shown}: {e}")))?;
        drop(w);
        write_ms = ms(t);
    }
    // The picture is drawn before anything is committed, so a failure leaves neither file.
    if let Some(pic) = picture_out.as_mut() {
        let meshes = match meshes {
            Some(m) => m,
            None => common::meshes(&built, nu, nv)?,
        };
        let png = pdeshape::render::render_png(
            &meshes,
            &crate::render::overlays(&built),
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
    crate::common::print_stdout(&format!(
        "wrote {shown}: {} patch{}, {nu} × {nv} grid\n",
        built.patches.len(),
        if built.patches.len() == 1 { "" } else { "es" }
    ));
    Ok(())
}

/// `surface` with `solver = "fd"`: every patch solved by finite differences
/// ([`pdeshape::design::build_fd_design`]), then tessellated, written and drawn like the analytic
/// patches (the picture shows the position curves; finite-difference patches have no spine).
fn run_fd(
    args: &Args,
    design: &common::Loaded,
    format: Format,
    nu: usize,
    nv: usize,
    mut out: Output,
    mut picture_out: Option<Output>,
) -> Result<(), CliError> {
    let shown = args.output.display().to_string();
    let t = Instant::now();
    let built = pdeshape::design::build_fd_design(&design.spec).map_err(|e| design.error(&e))?;
    let solve_ms = ms(t);
    let bad = |name: &str| {
        CliError::input(format!(
            "the finite-difference surface '{name}' is not finite somewhere"
        ))
    };
    let io_err = |e: pdeshape::Error| CliError::input(format!("-o {shown}: {e}"));
    let t = Instant::now();
    let mut meshes = Vec::new();
    let mut samples = Vec::new();
    for p in &built.patches {
        if format == Format::Csv {
            let g = mesh::sample(&p.surface, nu, nv).map_err(|e| CliError::input(e.to_string()))?;
            if !g
                .positions
                .iter()
                .chain(&g.normals)
                .flatten()
                .all(|x| x.is_finite())
            {
                return Err(bad(&p.name));
            }
            samples.push(g);
        }
        if format != Format::Csv || picture_out.is_some() {
            let g =
                mesh::tessellate(&p.surface, nu, nv).map_err(|e| CliError::input(e.to_string()))?;
            if !g
                .positions
                .iter()
                .chain(&g.normals)
                .flatten()
                .all(|x| x.is_finite())
            {
                return Err(bad(&p.name));
            }
            meshes.push(g);
        }
    }
    let tessellate_ms = ms(t);
    let t = Instant::now();
    let mut w = out.writer();
    match format {
        Format::Obj => mesh::write_obj(&meshes, &mut w),
        Format::Stl => mesh::write_stl(&meshes, &mut w),
        Format::Ply => mesh::write_ply(&meshes, &mut w),
        Format::Glb => mesh::write_glb(&meshes, &mut w),
        Format::Csv => mesh::write_csv(&samples, &mut w),
    }
    .map_err(io_err)?;
    w.flush()
        .map_err(|e| CliError::input(format!("-o {shown}: {e}")))?;
    drop(w);
    if let Some(pic) = picture_out.as_mut() {
        let mut lines: Vec<pdeshape::render::Polyline> = built
            .conditions
            .iter()
            .flatten()
            .filter(|c| c.derivative == 0)
            .map(|c| crate::render::curve_polyline(&*c.curve))
            .collect();
        lines.retain(|l| l.points.iter().all(|p| p.iter().all(|x| x.is_finite())));
        let png = pdeshape::render::render_png(
            &meshes,
            &lines,
            &pdeshape::render::RenderOptions::default(),
        )
        .map_err(|e| CliError::input(e.to_string()))?;
        pic.write_all(&png)?;
    }
    out.commit()?;
    if let Some(pic) = picture_out {
        pic.commit()?;
    }
    let write_ms = ms(t);
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
    let [gu, gv] = built.grid;
    crate::common::print_stdout(&format!(
        "wrote {shown}: {} patch{}, {nu} × {nv} grid (finite differences on {gu} × {gv})\n",
        built.patches.len(),
        if built.patches.len() == 1 { "" } else { "es" }
    ));
    Ok(())
}
