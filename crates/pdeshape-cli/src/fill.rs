//! `pdeshape fill MESH -o OUT`: fill the holes of a triangle mesh (obj, stl, ply, off, glb,
//! gltf) with PDE patches G1 to the mesh, welded in; write the mesh (obj, stl, ply or glb by
//! extension), print one line per hole and whether the result is watertight.

use crate::common::{self, CliError, Output};
use pdeshape::fill::{self, Continuity, FillOptions, HoleSelection};
use pdeshape::mesh::{self, Format};
use std::fmt::Write as _;
use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args, Debug)]
pub(crate) struct Args {
    /// The mesh: an OBJ, STL (binary or ASCII), PLY, OFF or glTF (.glb, .gltf) file of one
    /// manifold, consistently oriented surface with holes (in the units and up axis the file
    /// states, which the filled mesh and the design then carry).
    pub mesh: PathBuf,
    /// The filled mesh (obj, stl, ply or glb, by extension).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Which holes: `all` (default); see also --largest and --max-boundary.
    #[arg(long, value_parser = ["all"], conflicts_with_all = ["largest", "max_boundary"])]
    pub holes: Option<String>,
    /// Fill only the K longest holes.
    #[arg(long, value_name = "K", conflicts_with = "max_boundary")]
    pub largest: Option<usize>,
    /// Fill only the holes with at most N boundary vertices.
    #[arg(long, value_name = "N")]
    pub max_boundary: Option<usize>,
    /// How the fill meets the mesh: g1 (tangent planes, default), g2 (tangent planes and
    /// normal curvatures) or g0 (positions only).
    #[arg(long, value_parser = ["g0", "g1", "g2"], default_value = "g1")]
    pub continuity: String,
    /// How fast the fill's edges grow from the hole's spacing towards its centre, per ring of
    /// triangles: 0 to 1 (0: the hole's spacing throughout).
    #[arg(long, default_value_t = 0.1)]
    pub grading: f64,
    /// Also write the fill's patches as a design file, one `[[disk]]` table per patch, that
    /// check, surface and render read.
    #[arg(long, value_name = "D.toml")]
    pub design: Option<PathBuf>,
}

const FORMATS: &str = "obj, stl, ply or glb";

pub(crate) fn run(args: &Args) -> Result<(), CliError> {
    let shown = args.mesh.display().to_string();
    let format = common::output_format(&args.output, None, FORMATS)?;
    if format == Format::Csv {
        return Err(CliError::input(format!(
            "-o {}: fill writes a mesh: {FORMATS}",
            args.output.display()
        )));
    }
    let input = crate::fit::input_format(&args.mesh, &shown)?;
    let holes = match (args.largest, args.max_boundary) {
        (Some(k), _) => HoleSelection::Largest(k),
        (None, Some(n)) => HoleSelection::MaxBoundary(n),
        (None, None) => HoleSelection::All,
    };
    let options = FillOptions {
        holes,
        continuity: match args.continuity.as_str() {
            "g0" => Continuity::G0,
            "g2" => Continuity::G2,
            _ => Continuity::G1,
        },
        grading: args.grading,
    };
    if args.design.as_ref() == Some(&args.output) {
        return Err(CliError::input(format!(
            "--design {}: the same file as -o",
            args.output.display()
        )));
    }
    let bytes = crate::fit::read_mesh_bytes(&args.mesh, &shown)?;
    let mut out = Output::create(&args.output)?;
    let mut design_out = args.design.as_deref().map(Output::create).transpose()?;
    let read = crate::fit::read_mesh(&args.mesh, &shown, &bytes, input)?;
    let note = read.note();
    let units = read.units;
    let mesh = read.mesh;
    let t = Instant::now();
    let filled = fill::fill_holes(&mesh, &options).map_err(|e| match (e.place(), &note) {
        ("largest" | "max-boundary" | "grading", _) => CliError::input(format!("--{e}")),
        (_, Some(n)) => CliError::input(format!("{shown}: {e} ({n})")),
        (_, None) => CliError::input(format!("{shown}: {e}")),
    })?;
    if let Some(n) = &note {
        crate::common::note(&format!("{shown}: {n}"));
    }
    let fill_s = t.elapsed().as_secs_f64();
    let written = filled.to_trimesh();
    let name = args
        .mesh
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    let info = mesh::MeshInfo {
        title: Some(format!("{name}, holes filled")),
        units: units.unwrap_or_default(),
        ..mesh::MeshInfo::default()
    };
    {
        let mut w = out.writer();
        mesh::write_mesh(format, &written, &info, &mut w)
            .map_err(|e| CliError::input(format!("-o {}: {e}", args.output.display())))?;
        w.flush()
            .map_err(|e| CliError::input(format!("-o {}: {e}", args.output.display())))?;
    }
    if let Some(d) = design_out.as_mut() {
        let mut spec = filled.design(&format!("{name}, hole fill"));
        spec.units = units;
        let text = pdeshape::spec::write_design(&spec)
            .map_err(|e| CliError::input(format!("--design: {e}")))?;
        d.write_all(text.as_bytes())?;
    }
    out.commit()?;
    if let Some(d) = design_out {
        d.commit()?;
    }
    let mut text = String::new();
    for (k, h) in filled.holes.iter().enumerate() {
        let split = if h.pieces > 1 {
            format!(
                "; {} pieces along chords (G1 angle {:.3}°, normal jump max {:.3}°, rms {:.3}° \
                 across them)",
                h.pieces,
                h.chord_g1_angle.to_degrees(),
                h.chord_jump.0.to_degrees(),
                h.chord_jump.1.to_degrees()
            )
        } else {
            String::new()
        };
        let _ = writeln!(
            text,
            "hole {} (at vertex {}): {} boundary vertices, {} triangles added ({} ribbon); G1 \
             angle {:.3}° (normal jump max {:.3}°, rms {:.3}°){split}; {:.0} ms",
            k + 1,
            h.first_vertex + 1,
            h.boundary_vertices,
            h.triangles_added,
            h.ribbon,
            h.g1_angle.to_degrees(),
            h.normal_jump.0.to_degrees(),
            h.normal_jump.1.to_degrees(),
            h.seconds * 1e3
        );
    }
    let state = if filled.open_edges == 0 {
        "watertight".to_string()
    } else {
        format!("{} boundary edges remain", filled.open_edges)
    };
    let _ = writeln!(
        text,
        "{shown}: filled {} of {} holes in {:.0} ms: {} triangles, {state}",
        filled.holes.len(),
        filled.holes_found,
        fill_s * 1e3,
        filled.triangles.len()
    );
    common::print_stdout(&text);
    common::report(&format!("wrote {}\n", common::destination(&args.output)));
    if let Some(d) = &args.design {
        common::report(&format!("wrote {}\n", common::destination(d)));
    }
    Ok(())
}
