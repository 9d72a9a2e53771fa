//! `pdeshape fit MESH -o DESIGN.toml`: fit PDE patches to a closed triangle mesh (obj, stl,
//! ply), write the design, print the two-sided distances and the compression ratio.

use crate::common::{CliError, Output};
use pdeshape::fit::{self, MeshFormat, TriMesh, TubeOptions};
use pdeshape::spec::write_design;
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The mesh: an OBJ, STL (binary or ASCII) or PLY file of one closed surface.
    pub mesh: PathBuf,
    /// The fitted design file (TOML).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Largest distance between the mesh's sections and the fit, relative to the mesh's
    /// bounding-box diagonal; patches are split until it holds and merged while it does.
    #[arg(long, default_value_t = 2e-3)]
    pub tolerance: f64,
    /// A fixed number of patches, evenly spread along the axis, instead of the adaptive choice.
    #[arg(long)]
    pub sections: Option<usize>,
    /// Sectioning planes given by the user (not available yet: only the automatic mode).
    #[arg(long)]
    pub template: Option<PathBuf>,
    /// Write the measures (distances, sizes, ratio, timings) as JSON to this file.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Draw the mesh and the fit side by side, coloured by distance, into this PNG file.
    #[arg(long)]
    pub picture: Option<PathBuf>,
}

pub fn run(args: &Args) -> Result<(), CliError> {
    let shown = args.mesh.display().to_string();
    if args.template.is_some() {
        return Err(CliError::input(
            "--template: template mode is not available yet; the automatic mode fits closed \
             tube-like and star-shaped meshes",
        ));
    }
    if !(args.tolerance > 0.0 && args.tolerance.is_finite() && args.tolerance < 1.0) {
        return Err(CliError::input(format!(
            "--tolerance {}: must be a number between 0 and 1 (a fraction of the diagonal)",
            args.tolerance
        )));
    }
    let format = args
        .mesh
        .extension()
        .and_then(|e| e.to_str())
        .and_then(MeshFormat::from_extension)
        .ok_or_else(|| {
            CliError::input(format!(
                "{shown}: unknown mesh format (the extension must be obj, stl or ply)"
            ))
        })?;
    let ext = |p: &PathBuf, want: &str, flag: &str| -> Result<(), CliError> {
        match p.extension().and_then(|e| e.to_str()) {
            Some(e) if e.eq_ignore_ascii_case(want) => Ok(()),
            _ => Err(CliError::input(format!(
                "{flag} {}: the file name must end in .{want}",
                p.display()
            ))),
        }
    };
    ext(&args.output, "toml", "-o")?;
    if let Some(p) = &args.json {
        ext(p, "json", "--json")?;
    }
    if let Some(p) = &args.picture {
        ext(p, "png", "--picture")?;
    }
    let bytes = read_mesh_bytes(&args.mesh, &shown)?;
    let mut out = Output::create(&args.output)?;
    let mut json_out = args.json.as_ref().map(|p| Output::create(p)).transpose()?;
    let mut picture_out = args
        .picture
        .as_ref()
        .map(|p| Output::create(p))
        .transpose()?;

    let t = Instant::now();
    let mesh =
        TriMesh::read(&bytes, format).map_err(|e| CliError::input(format!("{shown}: {e}")))?;
    let read_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    let fitted = fit::fit_tube(
        &mesh,
        &TubeOptions {
            target: args.tolerance,
            patches: args.sections,
            ..TubeOptions::default()
        },
    )
    .map_err(|e| {
        let place = e.place();
        if place == "tolerance" || place == "sections" {
            CliError::input(format!("--{e}"))
        } else {
            CliError::input(format!("{shown}: {e}"))
        }
    })?;
    let fit_ms = t.elapsed().as_secs_f64() * 1e3;
    let mut spec = fitted.spec.clone();
    let name = args
        .mesh
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    spec.title = Some(format!("fitted to {name}"));
    let text = write_design(&spec).map_err(|e| CliError::input(format!("-o: {e}")))?;
    let t = Instant::now();
    let solved = pdeshape::design::solve_design(&spec)
        .map_err(|e| CliError::input(format!("{shown}: the fitted design does not solve: {e}")))?;
    let (m, distances) = fit::measure(&mesh, &spec, &solved, 48, 96)
        .map_err(|e| CliError::input(format!("{shown}: {e}")))?;
    let measure_ms = t.elapsed().as_secs_f64() * 1e3;
    out.write_all(text.as_bytes())?;
    if let Some(j) = json_out.as_mut() {
        let report = serde_json::json!({
            "mesh": shown,
            "patches": fitted.patches,
            "modes": fitted.modes,
            "sections": fitted.sections,
            "sections_dropped": fitted.dropped,
            "sample_error_relative": fitted.sample_error,
            "tolerance": args.tolerance,
            "measures": m,
            "timings_ms": { "read": read_ms, "fit": fit_ms, "measure": measure_ms },
        });
        let s = serde_json::to_string_pretty(&report)
            .map_err(|e| CliError::input(format!("--json: {e}")))?;
        j.write_all(s.as_bytes())?;
    }
    if let Some(p) = picture_out.as_mut() {
        let png = fit::picture(
            &mesh,
            &distances,
            args.tolerance * m.diagonal,
            &pdeshape::render::RenderOptions {
                width: 1200,
                height: 600,
                ..Default::default()
            },
        )
        .map_err(|e| CliError::input(format!("--picture: {e}")))?;
        p.write_all(&png)?;
    }
    out.commit()?;
    if let Some(j) = json_out {
        j.commit()?;
    }
    if let Some(p) = picture_out {
        p.commit()?;
    }
    println!(
        "{}: {} triangles → {} patches ({} modes) in {:.0} ms; Hausdorff {:.3e}, RMS {:.3e} \
         of the diagonal; {} bytes → {} bytes of coefficients (ratio {:.0}), {} bytes of TOML \
         (ratio {:.1}); wrote {}",
        shown,
        m.mesh_triangles,
        fitted.patches,
        fitted.modes,
        fit_ms,
        m.hausdorff_relative,
        m.rms_relative,
        m.mesh_bytes,
        m.design_bytes,
        m.ratio,
        m.toml_bytes,
        m.toml_ratio,
        args.output.display()
    );
    Ok(())
}

/// The bytes of a mesh file, refused from its size before it is read when holding it
/// ([`pdeshape::memory::mesh_read`]) would not fit in the memory budget.
pub(crate) fn read_mesh_bytes(path: &std::path::Path, shown: &str) -> Result<Vec<u8>, CliError> {
    if let Ok(m) = std::fs::metadata(path) {
        pdeshape::memory::check(
            pdeshape::memory::mesh_read(m.len(), 0),
            &format!("holding the mesh file of {} bytes", m.len()),
            "",
        )
        .map_err(|e| CliError::input(format!("{shown}: {e}")))?;
    }
    std::fs::read(path).map_err(|e| {
        CliError::input(format!(
            "{shown}: cannot read: {}",
            crate::common::io_words(&e)
        ))
    })
}
