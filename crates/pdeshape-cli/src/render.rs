//! `pdeshape render DESIGN -o shape.png`: the shaded surface with its position curves and spine.

use crate::common::{self, CliError, Output};
use pdeshape::curve::{Curve, Domain};
use pdeshape::design::BuiltDesign;
use pdeshape::render::{render_png, Polyline, RenderOptions};
use pdeshape::{Vec3, TAU};
use std::path::PathBuf;

#[derive(clap::Args, Debug)]
pub struct Args {
    /// The design file (TOML).
    pub design: PathBuf,
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
    /// Colour the surface by Gaussian (`gauss`) or mean (`mean`, outward normal) curvature:
    /// blue low, grey middle, red high.
    #[arg(long, value_enum)]
    pub color: Option<crate::analyze::ColorBy>,
    /// The curvature range of the colour map, LO,HI (default: symmetric about 0, ± the largest
    /// magnitude on the grid).
    #[arg(long, allow_hyphen_values = true)]
    pub range: Option<String>,
}

/// Largest picture side we agree to render.
const MAX_SIDE: u32 = 8192;
/// Points per drawn curve and along the spine.
const CURVE_POINTS: usize = 256;
const CURVE_COLOR: [u8; 3] = [210, 40, 30];
const SPINE_COLOR: [u8; 3] = [20, 70, 200];

fn parse_size(s: &str) -> Result<(u32, u32), CliError> {
    let bad = || {
        CliError::input(format!(
            "--size: expected WIDTHxHEIGHT such as 800x600 (got '{s}')"
        ))
    };
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let w: u32 = w.trim().parse().map_err(|_| bad())?;
    let h: u32 = h.trim().parse().map_err(|_| bad())?;
    if !(1..=MAX_SIDE).contains(&w) || !(1..=MAX_SIDE).contains(&h) {
        return Err(CliError::input(format!(
            "--size: width and height must be between 1 and {MAX_SIDE} (got {w}x{h})"
        )));
    }
    Ok((w, h))
}

fn parse_view(s: &str) -> Result<Vec3, CliError> {
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

/// `CURVE_POINTS` points of a curve: over [0, 2π) for a periodic curve (drawn closed), over its
/// whole interval otherwise.
pub(crate) fn curve_polyline(curve: &dyn Curve) -> Polyline {
    let (points, closed) = match curve.domain() {
        Domain::Periodic => (
            (0..CURVE_POINTS)
                .map(|k| curve.point(TAU * k as f64 / CURVE_POINTS as f64))
                .collect(),
            true,
        ),
        Domain::Interval(a, b) => (
            (0..CURVE_POINTS)
                .map(|k| curve.point(a + (b - a) * k as f64 / (CURVE_POINTS - 1) as f64))
                .collect(),
            false,
        ),
    };
    Polyline {
        points,
        color: CURVE_COLOR,
        width: 2.0,
        closed,
    }
}

/// The position curves of every patch (each shared curve once) and every patch's spine.
pub fn overlays(built: &BuiltDesign) -> Vec<Polyline> {
    let mut lines = Vec::new();
    let mut drawn: Vec<String> = Vec::new();
    for conds in &built.conditions {
        for c in conds.iter().filter(|c| c.derivative == 0) {
            if let Some(name) = &c.curve_name {
                if drawn.contains(name) {
                    continue;
                }
                drawn.push(name.clone());
            }
            lines.push(curve_polyline(&*c.curve));
        }
    }
    for p in &built.patches {
        let points = (0..CURVE_POINTS)
            .map(|k| p.surface.spine(k as f64 / (CURVE_POINTS - 1) as f64, 0))
            .collect();
        lines.push(Polyline {
            points,
            color: SPINE_COLOR,
            width: 2.0,
            closed: false,
        });
    }
    lines.retain(|l| l.points.iter().all(|p| p.iter().all(|x| x.is_finite())));
    lines
}

/// Refuses picture paths that do not end in `.png`.
pub fn check_png_path(path: &std::path::Path) -> Result<(), CliError> {
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

pub fn run(args: &Args) -> Result<(), CliError> {
    let shown = args.output.display().to_string();
    check_png_path(&args.output)
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
            "--range: needs --color gauss or --color mean",
        ));
    }
    let design = common::load(&args.design)?;
    design.validate()?;
    let (nu, nv) = design.grid(args.nu, args.nv)?;
    let mut out = Output::create(&args.output)?;
    let built = design.build()?;
    let meshes = common::meshes(&built, nu, nv)?;
    let options = RenderOptions {
        width,
        height,
        view,
        ..RenderOptions::default()
    };
    let (png, note) = match args.color {
        None => (
            render_png(&meshes, &overlays(&built), &options),
            String::new(),
        ),
        Some(by) => {
            let (colors, lo, hi) = crate::analyze::curvature_colors(&built, &meshes, by, range)?;
            (
                pdeshape::render::render_png_colored(&meshes, &colors, &overlays(&built), &options),
                format!(
                    ", {} curvature from {lo:.6e} (blue) to {hi:.6e} (red)",
                    by.word()
                ),
            )
        }
    };
    let png = png.map_err(|e| CliError::input(format!("-o {shown}: {e}")))?;
    out.write_all(&png)?;
    out.commit()?;
    crate::common::print_stdout(&format!("wrote {shown}: {width}x{height}{note}\n"));
    Ok(())
}
