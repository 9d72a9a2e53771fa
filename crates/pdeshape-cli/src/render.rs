//! `pdeshape render DESIGN -o shape.png`: the shaded surface with its position curves and spine.

use crate::common::{self, CliError, Output};
use pdeshape::render::{render_png, RenderOptions};
use pdeshape::Vec3;
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub(crate) struct Args {
    /// The design file (TOML).
    pub design: PathBuf,
    /// Set a design parameter (a `[[parameters]]` entry) to a value within its bounds;
    /// repeatable, e.g. `--set theta=0.3 --set s=1.2`.
    #[arg(long = "set", value_name = "NAME=VALUE")]
    pub set: Vec<String>,
    /// Output picture (.png).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Picture size in pixels, WIDTHxHEIGHT.
    #[arg(long, default_value = "800x600")]
    pub size: String,
    /// Direction from the object towards the eye, x,y,z (default: a three-quarter view).
    #[arg(long, allow_hyphen_values = true)]
    pub view: Option<String>,
    /// Grid rows (values of u; default from [output] or 64).
    #[arg(long)]
    pub nu: Option<usize>,
    /// Grid columns (values of v; default from [output] or 128).
    #[arg(long)]
    pub nv: Option<usize>,
    /// Colour the surface by Gaussian (`gauss`) or mean (`mean`, outward normal) curvature, or
    /// by the largest shear stress of a CalculiX shell analysis (`shear`, as `pdeshape shell`
    /// runs it): blue low, grey middle, red high.
    #[arg(long, value_enum)]
    pub color: Option<Coloring>,
    /// The range of the colour map, LO,HI (curvature; MPa for `shear`) (default: the 1st to
    /// 99th percentile of the curvature on the grid, made symmetric about 0 when it spans 0; 0
    /// to the largest shear stress). A colour bar with the values is drawn on the right.
    #[arg(long, allow_hyphen_values = true)]
    pub range: Option<String>,
}

/// What `pdeshape render --color` colours by.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub(crate) enum Coloring {
    /// Gaussian curvature K.
    Gauss,
    /// Mean curvature H (outward normal).
    Mean,
    /// The largest shear stress (σ₁ − σ₃)/2 of a shell analysis with CalculiX, in MPa.
    Shear,
}

/// The largest shear stress (MPa) of the shell analysis of `built` ([shell] or the book's
/// set-up), mapped onto the render grids: the nodal values interpolated with the elements' shape
/// functions at each grid point `(u, v)`. Returns the colours, the range and the peak.
fn shear_colors(
    design: &common::Loaded,
    built: &pdeshape::design::SolvedDesign,
    meshes: &[pdeshape::mesh::GridMesh],
    range: Option<(f64, f64)>,
) -> Result<(crate::analyze::MeshColors, f64, f64, f64), CliError> {
    use pdeshape::shell::{self, ShellSetup};
    let names = built.names();
    let setup = ShellSetup::new(&design.spec, &names).map_err(|e| design.error(&e))?;
    let model = setup.model(built).map_err(|e| design.error(&e))?;
    let report = shell::analyse(&model, &setup.run_options()).map_err(|e| CliError {
        message: format!("--color shear: {}", common::message_of(&e)),
        status: 1,
    })?;
    let (mesh, shear) = (&model.mesh, &report.max_shear);
    let values: Vec<Vec<f64>> = meshes
        .iter()
        .enumerate()
        .map(|(k, m)| {
            let mut row = Vec::with_capacity(m.u.len() * m.v.len());
            for &u in &m.u {
                for &v in &m.v {
                    row.push(mesh.interpolate(shear, k, u, v) / 1e6);
                }
            }
            row
        })
        .collect();
    let peak = report.peak.value / 1e6;
    let (lo, hi) = range.unwrap_or((0.0, peak));
    let colors = values
        .iter()
        .map(|v| pdeshape::render::diverging_colors(v, lo, hi))
        .collect();
    Ok((colors, lo, hi, peak))
}

/// `--size WIDTHxHEIGHT` ([`pdeshape::format::parse_size`]).
fn parse_size(s: &str) -> Result<(u32, u32), CliError> {
    pdeshape::format::parse_size(s)
        .map_err(|e| CliError::input(format!("--size: {}", crate::common::message_of(&e))))
}

pub(crate) fn parse_view(s: &str) -> Result<Vec3, CliError> {
    let bad = || CliError::input(format!("--view: expected three numbers x,y,z (got '{s}')"));
    let parts: Vec<f64> = s
        .split(',')
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad())?;
    if parts.len() != 3 || parts.iter().any(|x| !x.is_finite()) {
        return Err(bad());
    }
    // Only the direction matters: scale by the largest component so neither 1e308 nor 1e-320
    // overflows or underflows.
    let v = Vec3::new(parts[0], parts[1], parts[2]);
    let m = v.amax();
    if m == 0.0 {
        return Err(CliError::input("--view: must not be the zero vector"));
    }
    Ok(v / m)
}

/// Refuses picture paths that do not end in `.png`.
pub(crate) fn check_png_path(path: &std::path::Path) -> Result<(), CliError> {
    let is_png = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if is_png {
        Ok(())
    } else {
        Err(CliError::input(format!(
            "{}: the picture must be a .png file",
            path.display()
        )))
    }
}

pub(crate) fn run(args: &Args) -> Result<(), CliError> {
    let shown = args.output.display().to_string();
    if !Output::is_stdout(&args.output) {
        check_png_path(&args.output)
    } else {
        Ok(())
    }
    .map_err(|_| CliError::input(format!("-o {shown}: the picture must be a .png file")))?;
    let (width, height) = parse_size(&args.size)?;
    let view = args.view.as_deref().map(parse_view).transpose()?;
    let range = args
        .range
        .as_deref()
        .map(crate::analyze::parse_range)
        .transpose()?;
    if range.is_some() && args.color.is_none() {
        return Err(CliError::input(
            "--range: needs --color gauss, mean or shear",
        ));
    }
    let mut design = common::load(&args.design)?;
    common::apply_sets(&mut design, &args.set)?;
    design.validate()?;
    let (nu, nv) = design.grid(args.nu, args.nv)?;
    let mut out = Output::create(&args.output)?;
    let built = design.build()?;
    if !built.trims.is_empty() {
        if args.color.is_some() {
            return Err(CliError::input(
                "--color: colours are not drawn on trimmed designs yet",
            ));
        }
        let m = built.tri_mesh(nu, nv).map_err(|e| design.error(&e))?;
        let options = RenderOptions {
            width,
            height,
            view,
            ..RenderOptions::default()
        };
        let png = pdeshape::render::render_png_tri(
            &m,
            &pdeshape::render::overlay_lines(&built.overlays()),
            &options,
        )
        .map_err(|e| CliError::input(format!("-o {shown}: {e}")))?;
        out.write_all(&png)?;
        out.commit()?;
        let dest = crate::common::destination(&args.output);
        crate::common::report(&format!(
            "wrote {dest}: {width}x{height}, {} triangles (trimmed)\n",
            m.triangles.len()
        ));
        return Ok(());
    }
    let meshes = built.meshes(nu, nv).map_err(|e| design.error(&e))?;
    let options = RenderOptions {
        width,
        height,
        view,
        ..RenderOptions::default()
    };
    // The colours, their bar and the report's words; then one render.
    let coloured = match args.color {
        None => None,
        Some(Coloring::Shear) => {
            let (colors, lo, hi, peak) = shear_colors(&design, &built, &meshes, range)?;
            let bar = pdeshape::render::ColorBar {
                title: "largest shear stress (MPa)".into(),
                lo,
                hi,
                note: if range.is_some() {
                    "range: --range".into()
                } else {
                    "range: 0 to the largest".into()
                },
            };
            let q = |x: f64| pdeshape::number::quantity(x, "MPa");
            let note = format!(
                ", largest shear stress from {} (blue) to {} (red), peak {}, {}",
                q(lo),
                q(hi),
                q(peak),
                bar.note
            );
            Some((colors, bar, note))
        }
        Some(c) => {
            // Gauss or mean (shear is the arm above).
            let by = if c == Coloring::Mean {
                crate::analyze::ColorBy::Mean
            } else {
                crate::analyze::ColorBy::Gauss
            };
            let (colors, lo, hi) = crate::analyze::curvature_colors(&built, &meshes, by, range)?;
            let bar = curvature_bar(by, lo, hi, range.is_some());
            // K is per length², H per length, in the design's units when it has them.
            let power = if c == Coloring::Mean { -1 } else { -2 };
            let unit = pdeshape::number::length_power(design.spec.units.map(|u| u.as_str()), power);
            let q = |x: f64| pdeshape::number::quantity(x, &unit);
            let note = format!(
                ", {} curvature from {} (blue) to {} (red), {}",
                by.word(),
                q(lo),
                q(hi),
                bar.note
            );
            Some((colors, bar, note))
        }
    };
    let (png, note) = match coloured {
        None => (
            render_png(
                &meshes,
                &pdeshape::render::overlay_lines(&built.overlays()),
                &options,
            ),
            String::new(),
        ),
        Some((colors, bar, note)) => (
            pdeshape::render::render_png_colored_with_bar(
                &meshes,
                &colors,
                &pdeshape::render::overlay_lines(&built.overlays()),
                &options,
                &bar,
            ),
            note,
        ),
    };
    let png = png.map_err(|e| CliError::input(format!("-o {shown}: {e}")))?;
    out.write_all(&png)?;
    out.commit()?;
    let dest = crate::common::destination(&args.output);
    crate::common::report(&format!("wrote {dest}: {width}x{height}{note}\n"));
    Ok(())
}

/// The colour bar of a curvature picture, with a note saying where its range came from.
pub(crate) fn curvature_bar(
    by: crate::analyze::ColorBy,
    lo: f64,
    hi: f64,
    given: bool,
) -> pdeshape::render::ColorBar {
    let note = if given {
        "range: --range".to_string()
    } else if lo == -hi {
        "range: 1st-99th percentile, symmetric about 0".to_string()
    } else {
        "range: 1st-99th percentile".to_string()
    };
    pdeshape::render::ColorBar {
        title: match by {
            crate::analyze::ColorBy::Gauss => "Gaussian curvature K".into(),
            crate::analyze::ColorBy::Mean => "mean curvature H".into(),
        },
        lo,
        hi,
        note,
    }
}
