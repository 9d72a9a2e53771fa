//! `pdeshape fit MESH -o DESIGN.toml`: fit PDE patches to a triangle mesh (obj, stl, ply, off,
//! glb or gltf; in the units and up axis the file states, which the design then carries): a
//! closed one by the tube mode, an open one by the sheet mode, any other manifold mesh by the
//! general mode (a layout of n-sided patches, G1 across its edges), or any as a template says;
//! write the design, print the two-sided distances and the compression ratio. A fit that misses
//! the tolerance is not written (exit status 1) unless `--best-effort` is given.

use crate::common::{CliError, Output};
use pdeshape::fit::{self, InputMesh, MeshFormat, MeshRead};
use pdeshape::spec;
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args, Debug)]
pub(crate) struct Args {
    /// The mesh: an OBJ, STL (binary or ASCII), PLY, OFF or glTF (.glb, .gltf) file of one
    /// surface: closed (fitted along its main axis, poles at both ends) or open (a sheet, fitted
    /// by profiles across it). glTF is read in metres and turned from +Y up to +Z up (in the
    /// design units its pdeshape extras name); the tool's own OBJ, STL and PLY are read in the
    /// units and up axis they state; the design carries the units a file states.
    pub mesh: PathBuf,
    /// The fitted design file (TOML).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Largest two-sided Hausdorff distance between the mesh and the fit, relative to the
    /// mesh's bounding-box diagonal (default 0.02; the tube and sheet modes then refine their
    /// sections to 0.002): a fit that misses it is not written and the exit status is 1 (see
    /// --best-effort).
    #[arg(long)]
    pub tolerance: Option<f64>,
    /// The mode: auto (tube for a closed mesh, sheet for an open one, the general mode when
    /// that mode refuses the mesh or misses the tolerance), tube, sheet or general.
    #[arg(long, default_value = "auto", value_parser = ["auto", "tube", "sheet", "general"], conflicts_with = "template")]
    pub mode: String,
    /// Write the fit even when it misses the tolerance (the miss is still reported).
    #[arg(long)]
    pub best_effort: bool,
    /// A fixed number of patches, evenly spread along the axis, instead of the adaptive choice.
    #[arg(long, conflicts_with = "template")]
    pub sections: Option<usize>,
    /// A template (TOML) naming the sectioning planes and the mode of each part, for shapes the
    /// automatic modes cannot split.
    #[arg(long)]
    pub template: Option<PathBuf>,
    /// Write the measures (distances, sizes, ratio, timings) as JSON to this file.
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Draw the mesh and the fit side by side, coloured by distance, into this PNG file.
    #[arg(long)]
    pub picture: Option<PathBuf>,
    /// Fit at each of these tolerances (fractions of the diagonal, comma-separated) and
    /// decimate the mesh beside them: -o is then a CSV table of bytes against distances
    /// (rate and distortion), and --plot draws it.
    #[arg(long, value_delimiter = ',', num_args = 1.., conflicts_with_all = ["template", "tolerance", "best_effort", "picture", "json", "sections"])]
    pub sweep: Option<Vec<f64>>,
    /// With --sweep: the plot of bytes against the Hausdorff distance, as an SVG file.
    #[arg(long, requires = "sweep")]
    pub plot: Option<PathBuf>,
}

pub(crate) fn run(args: &Args) -> Result<(), CliError> {
    let shown = args.mesh.display().to_string();
    if let Some(t) = args.tolerance {
        if !(t > 0.0 && t.is_finite() && t < 1.0) {
            return Err(CliError::input(format!(
                "--tolerance {t}: must be a number between 0 and 1 (a fraction of the diagonal)"
            )));
        }
    }
    let mode = fit::ModeChoice::parse(&args.mode)
        .map_err(|e| CliError::input(format!("--mode {}: {}", args.mode, e.message())))?;
    let format = input_format(&args.mesh, &shown)?;
    let ext = |p: &PathBuf, want: &str, flag: &str| -> Result<(), CliError> {
        match p.extension().and_then(|e| e.to_str()) {
            Some(e) if e.eq_ignore_ascii_case(want) => Ok(()),
            _ => Err(CliError::input(format!(
                "{flag} {}: the file name must end in .{want}",
                p.display()
            ))),
        }
    };
    if let Some(tolerances) = &args.sweep {
        return sweep(args, tolerances, mode, format, &shown, ext);
    }
    ext(&args.output, "toml", "-o")?;
    if let Some(p) = &args.json {
        ext(p, "json", "--json")?;
    }
    if let Some(p) = &args.picture {
        ext(p, "png", "--picture")?;
    }
    // The template first: a bad one is reported before the mesh is read.
    let template = args
        .template
        .as_ref()
        .map(|p| read_template(p))
        .transpose()?;
    let bytes = read_mesh_bytes(&args.mesh, &shown)?;
    let mut out = Output::create(&args.output)?;
    let mut json_out = args.json.as_ref().map(|p| Output::create(p)).transpose()?;
    let mut picture_out = args
        .picture
        .as_ref()
        .map(|p| Output::create(p))
        .transpose()?;

    let t = Instant::now();
    let read = read_mesh(&args.mesh, &shown, &bytes, format)?;
    // What the reader and the repairs did (an OBJ's objects welded into one mesh, T-junctions
    // split, fins dropped …): a note after a fit, the reason's context after a refusal, so a
    // refusal stays one line.
    let (mesh, notes) = read
        .repaired()
        .map_err(|e| CliError::input(format!("{shown}: {e}")))?;
    let note = (!notes.is_empty()).then(|| notes.join("; "));
    let with_note = |e: CliError| match &note {
        Some(n) => CliError::input(format!("{} ({n})", e.message)),
        None => e,
    };
    let read_ms = t.elapsed().as_secs_f64() * 1e3;
    let t = Instant::now();
    let request = fit::Request {
        mode,
        template: template.as_ref().map(|(_, _, t)| t),
        tolerance: args.tolerance,
        patches: args.sections,
        units: read.units,
        file: read.file,
    };
    let mut fitted = fit::fit_measured(&mesh, &request)
        .map_err(|e| match &template {
            Some((file, text, _)) if e.place().starts_with("parts") => CliError::input(format!(
                "{} (fitting {shown})",
                spec::describe_error(file, text, &e)
            )),
            _ => fit_error(e, &shown),
        })
        .map_err(with_note)?;
    let elapsed_ms = t.elapsed().as_secs_f64() * 1e3;
    let name = args
        .mesh
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    let text = fitted
        .design_file(&name)
        .map_err(|e| CliError::input(format!("-o: {e}")))?;
    let miss_words = fitted.miss();
    let worst_shown = fitted.worst_shown();
    let mut report = fitted.report(&shown, &notes);
    let fit::Fitted {
        fit: fitted,
        measures: m,
        distances,
        tolerance,
        fallback,
        declined,
        ..
    } = fitted;
    let missed = miss_words.is_some();
    if let (Some(words), false) = (&miss_words, args.best_effort) {
        let reasons: Vec<String> = declined
            .iter()
            .map(|d| format!("the {} mode's fit is kept: {d}", fitted.mode.name()))
            .chain(fitted.notes.iter().cloned())
            .collect();
        let why = if reasons.is_empty() {
            String::new()
        } else {
            format!(" ({})", reasons.join("; "))
        };
        return Err(CliError {
            message: format!(
                "{shown}: {words}; nothing written (a larger --tolerance, or --best-effort to \
                 write it anyway){why}"
            ),
            status: 1,
        });
    }
    if let Some(why) = &declined {
        crate::common::note(&format!(
            "{shown}: the {} mode's fit misses the tolerance and {why}: that fit is kept",
            fitted.mode.name()
        ));
    } else if let Some(why) = &fallback {
        crate::common::note(&format!("{shown}: {why}; fitted by the general mode"));
    }
    if let Some(n) = &note {
        crate::common::note(&format!("{shown}: {n}"));
    }
    for n in &fitted.notes {
        crate::common::note(&format!("{shown}: {n}"));
    }
    out.write_all(text.as_bytes())?;
    if let Some(j) = json_out.as_mut() {
        // The measures are taken inside the fit (the general mode measures every round).
        report["timings_ms"] = serde_json::json!({ "read": read_ms, "fit": elapsed_ms });
        let s = serde_json::to_string_pretty(&report)
            .map_err(|e| CliError::input(format!("--json: {e}")))?;
        j.write_all(s.as_bytes())?;
    }
    if let Some(p) = picture_out.as_mut() {
        let png = fit::picture(
            &mesh,
            &distances,
            &fit::layout_edges(&fitted.spec, &distances),
            tolerance * m.diagonal,
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
    crate::common::report(&format!(
        "{shown}: {} in {:.0} ms; wrote {}\n",
        m.summary(&fitted, tolerance),
        elapsed_ms,
        crate::common::destination(&args.output)
    ));
    if m.toml_bytes > m.mesh_bytes {
        crate::common::note(&format!(
            "{shown}: the design file ({} bytes) is larger than the mesh ({} bytes as 12·V + \
             12·T): ratio {:.3}",
            m.toml_bytes, m.mesh_bytes, m.toml_ratio
        ));
    }
    if missed {
        crate::common::note(&format!(
            "{shown}: written anyway (--best-effort): the fit misses the tolerance {}% of the \
             diagonal by {} at {}",
            pct(tolerance),
            num(m.hausdorff - tolerance * m.diagonal),
            worst_shown
        ));
    }
    Ok(())
}

/// `fit --sweep`: the rate–distortion table and its plot.
fn sweep(
    args: &Args,
    tolerances: &[f64],
    mode: fit::ModeChoice,
    format: MeshFormat,
    shown: &str,
    ext: impl Fn(&PathBuf, &str, &str) -> Result<(), CliError>,
) -> Result<(), CliError> {
    ext(&args.output, "csv", "-o (with --sweep)")?;
    if let Some(p) = &args.plot {
        ext(p, "svg", "--plot")?;
    }
    let bytes = read_mesh_bytes(&args.mesh, shown)?;
    let mut out = Output::create(&args.output)?;
    let mut plot = args.plot.as_ref().map(|p| Output::create(p)).transpose()?;
    let read = read_mesh(&args.mesh, shown, &bytes, format)?;
    let (mesh, _) = read
        .repaired()
        .map_err(|e| CliError::input(format!("{shown}: {e}")))?;
    let t = Instant::now();
    let rd = fit::rate_distortion(&mesh, tolerances, mode, read.file).map_err(|e| {
        if e.place().starts_with("tolerances") {
            CliError::input(format!("--sweep {}", e.message()))
        } else {
            CliError::input(format!("{shown}: {}", e.message()))
        }
    })?;
    out.write_all(rd.csv().as_bytes())?;
    if let Some(p) = plot.as_mut() {
        let name = args
            .mesh
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_default();
        p.write_all(
            rd.svg(&format!("{name}: {} triangles", rd.mesh_triangles))
                .as_bytes(),
        )?;
    }
    out.commit()?;
    if let Some(p) = plot {
        p.commit()?;
    }
    for r in &rd.refused {
        crate::common::note(&format!(
            "{shown}: at the tolerance {}%: {}",
            pct(r.tolerance),
            r.reason
        ));
    }
    crate::common::report(&format!(
        "{shown}: {} fits, {} levels of decimation in {:.1} s; wrote {}\n",
        rd.fits.len(),
        rd.decimated.len(),
        t.elapsed().as_secs_f64(),
        crate::common::destination(&args.output)
    ));
    Ok(())
}

fn num(x: f64) -> String {
    pdeshape::number::sig(x, 6)
}

fn pct(x: f64) -> String {
    pdeshape::number::sig(100.0 * x, 4)
}

fn fit_error(e: pdeshape::Error, shown: &str) -> CliError {
    match e.place() {
        "tolerance" | "sections" => CliError::input(format!("--{e}")),
        _ => CliError::input(format!("{shown}: {e}")),
    }
}

/// Most bytes of a template file.
const MAX_TEMPLATE_BYTES: u64 = 1 << 20;

/// Reads and parses a template; errors as `file:line:col: place: message`.
fn read_template(path: &std::path::Path) -> Result<(String, String, fit::Template), CliError> {
    let file = path.display().to_string();
    let bytes = pdeshape::open::read_regular(path, MAX_TEMPLATE_BYTES).map_err(|e| match e {
        pdeshape::open::ReadError::TooLarge(n) => CliError::input(format!(
            "--template {file}: the template has {n} bytes; at most {MAX_TEMPLATE_BYTES} are read"
        )),
        e => CliError::input(format!("--template {file}: {}", e.words())),
    })?;
    let text = String::from_utf8(bytes).map_err(|e| {
        CliError::input(format!(
            "{file}: the template is not UTF-8 text (invalid byte at offset {})",
            e.utf8_error().valid_up_to()
        ))
    })?;
    let t = fit::parse_template(&text)
        .map_err(|e| CliError::input(spec::describe_error(&file, &text, &e)))?;
    Ok((file, text, t))
}

/// The bytes of a mesh file: a regular file, refused from its size before it is read when
/// holding it would not fit in the memory budget ([`pdeshape::open::read_held`]).
/// The format of an input mesh, from its extension.
pub(crate) fn input_format(path: &std::path::Path, shown: &str) -> Result<MeshFormat, CliError> {
    path.extension()
        .and_then(|e| e.to_str())
        .and_then(MeshFormat::from_extension)
        .ok_or_else(|| CliError::input(MeshFormat::unknown(shown)))
}

pub(crate) fn read_mesh_bytes(path: &std::path::Path, shown: &str) -> Result<Vec<u8>, CliError> {
    pdeshape::open::read_held(path).map_err(|e| CliError::input(format!("{shown}: {}", e.words())))
}

/// Reads the bytes of the mesh file `path` as `format`; the files a `.gltf` file names (its
/// buffers) are read beside it as the file itself is ([`pdeshape::open::read_held`]). Errors
/// are `{shown}: …`.
pub(crate) fn read_mesh(
    path: &std::path::Path,
    shown: &str,
    bytes: &[u8],
    format: MeshFormat,
) -> Result<MeshRead, CliError> {
    let dir = path.parent().unwrap_or(std::path::Path::new(""));
    let external = |name: &str| pdeshape::open::read_held(&dir.join(name)).map_err(|e| e.words());
    InputMesh::read_report_with(bytes, format, &external)
        .map_err(|e| CliError::input(format!("{shown}: {e}")))
}
