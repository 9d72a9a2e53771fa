//! `pdeshape shell DESIGN [--thickness T] [--elements N] [--json] [-o result.vtu|csv]`: the
//! thin-shell strength analysis of a design with CalculiX (its `[shell]` section, or the book's
//! set-up of §7.5.1): largest shear stress and where, ratio to yield, mass, mesh size, solver
//! time; the stress field as VTU (ParaView) or CSV.
//!
//! The solver is the program named by the environment variable `PDESHAPE_CCX`, else `ccx` on
//! the `PATH`.

use crate::common::{self, CliError, Output};
use pdeshape::shell::{self, ShellSetup};
use std::path::PathBuf;
use std::time::Instant;

#[derive(clap::Args, Debug)]
pub(crate) struct Args {
    /// The design file (TOML); its [shell] section, if any, sets up the analysis.
    pub design: PathBuf,
    /// Wall thickness in metres (overrides shell.thickness; default 0.0005).
    #[arg(long)]
    pub thickness: Option<f64>,
    /// Element grid: N cells along u and 4N around v per patch (overrides shell.elements).
    #[arg(long)]
    pub elements: Option<usize>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    /// Write the stress field: .vtu (VTK unstructured grid, for ParaView) or .csv
    /// (patch,u,v,x,y,z,max_shear per node).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

/// What the solver stage failed on: status 1 (not bad input).
fn solver_error(e: &pdeshape::Error) -> CliError {
    CliError {
        message: common::message_of(e),
        status: 1,
    }
}

pub(crate) fn run(args: &Args) -> Result<(), CliError> {
    let kind = match &args.output {
        None => None,
        Some(p) => match p.extension().and_then(|e| e.to_str()) {
            Some("vtu") => Some("vtu"),
            Some("csv") => Some("csv"),
            _ => {
                return Err(CliError::input(format!(
                    "-o {}: the stress field is written as .vtu or .csv",
                    p.display()
                )))
            }
        },
    };
    if let Some(t) = args.thickness {
        if !(t > 0.0 && t <= 0.1 && t.is_finite()) {
            return Err(CliError::input(format!(
                "--thickness: must be positive and at most 0.1 m (got {t})"
            )));
        }
    }
    if let Some(n) = args.elements {
        let most = shell::MAX_ELEMENTS.0.min(shell::MAX_ELEMENTS.1 / 4);
        if !(1..=most).contains(&n) {
            return Err(CliError::input(format!(
                "--elements: must be between 1 and {most} (got {n})"
            )));
        }
    }
    let design = common::load(&args.design)?;
    design.validate()?;
    let built = design.build()?;
    let names = built.names();
    let mut setup = ShellSetup::new(&design.spec, &names).map_err(|e| design.error(&e))?;
    if let Some(t) = args.thickness {
        setup.thickness = t;
    }
    if let Some(n) = args.elements {
        setup.elements = (n, 4 * n);
        setup
            .check_size(names.len(), "--elements")
            .map_err(|e| CliError::input(format!("--elements: {}", common::message_of(&e))))?;
    }
    let mut out = match &args.output {
        Some(p) => {
            if p == &args.design {
                return Err(CliError::input(format!(
                    "-o {}: would overwrite the design file",
                    p.display()
                )));
            }
            Some(Output::create(p)?)
        }
        None => None,
    };
    let t0 = Instant::now();
    let model = setup.model(&built).map_err(|e| design.error(&e))?;
    let mesh_seconds = t0.elapsed().as_secs_f64();
    let report = shell::analyse(&model, &setup.run_options()).map_err(|e| solver_error(&e))?;
    let mass = setup.mass(&built).map_err(|e| design.error(&e))?;
    if let (Some(o), Some(kind)) = (&mut out, kind) {
        let text = if kind == "vtu" {
            shell::vtu(&model, &report, &names)
        } else {
            shell::csv(&model, &report, &names)
        };
        o.write_all(text.as_bytes())?;
    }
    let summary = Summary {
        title: built.title.clone(),
        names: &names,
        setup: &setup,
        model: &model,
        report: &report,
        mass,
        mesh_seconds,
    };
    let text = if args.json {
        summary.json()
    } else {
        summary.text()
    };
    if let Some(o) = out {
        o.commit()?;
        if let Some(p) = &args.output {
            let line = format!("wrote {}\n", common::destination(p));
            // With --json, stdout holds the JSON document only.
            if args.json {
                if !common::quiet() {
                    eprint!("{line}");
                }
            } else {
                common::report(&line);
            }
        }
    }
    common::print_stdout(&text);
    Ok(())
}

struct Summary<'a> {
    title: Option<String>,
    names: &'a [&'a str],
    setup: &'a ShellSetup,
    model: &'a shell::ShellModel,
    report: &'a shell::ShellReport,
    mass: f64,
    mesh_seconds: f64,
}

impl Summary<'_> {
    fn counts(&self) -> (usize, usize) {
        let quads = self
            .model
            .mesh
            .elements
            .iter()
            .filter(|e| e.corners() == 4)
            .count();
        (quads, self.model.mesh.elements.len() - quads)
    }

    fn peak_place(&self) -> (&str, f64, f64, [f64; 3]) {
        let k = self.report.peak.node;
        let (patch, u, v) = self.model.mesh.params[k];
        (
            self.names.get(patch).copied().unwrap_or("?"),
            u,
            v,
            self.model.mesh.nodes[k],
        )
    }

    fn ratio(&self) -> f64 {
        self.report.peak.value / self.setup.material.yield_stress
    }

    fn text(&self) -> String {
        let (quads, tris) = self.counts();
        let (patch, u, v, x) = self.peak_place();
        let m = &self.setup.material;
        let mut s = String::new();
        if let Some(t) = &self.title {
            s.push_str(&format!("design: {t}\n"));
        }
        s.push_str(&format!(
            "mesh: {} nodes, {} elements ({quads} S8R, {tris} S6), {} × {} cells per patch\n",
            self.model.mesh.nodes.len(),
            self.model.mesh.elements.len(),
            self.setup.elements.0,
            self.setup.elements.1
        ));
        s.push_str(&format!(
            "wall: {} mm of {} (E = {} GPa, ν = {}, ρ = {} kg/m³, yield {} MPa)\n",
            self.setup.thickness * 1e3,
            m.name,
            m.youngs_modulus / 1e9,
            m.poisson_ratio,
            m.density,
            m.yield_stress / 1e6
        ));
        s.push_str(&format!(
            "largest shear stress: {:.6e} Pa at '{patch}' u = {u:.4}, v = {v:.4} \
             (x, y, z = {:.6e}, {:.6e}, {:.6e} m)\n",
            self.report.peak.value, x[0], x[1], x[2]
        ));
        s.push_str(&format!(
            "ratio to yield: {:.4} (largest shear / yield stress)\n",
            self.ratio()
        ));
        s.push_str(&format!("mass: {:.6e} kg\n", self.mass));
        s.push_str(&format!(
            "time: meshing {:.3} s, deck {:.3} s, solver {:.3} s, read-back {:.3} s\n",
            self.mesh_seconds,
            self.report.deck_seconds,
            self.report.solver_seconds,
            self.report.read_seconds
        ));
        s
    }

    fn json(&self) -> String {
        let (quads, tris) = self.counts();
        let (patch, u, v, x) = self.peak_place();
        let m = &self.setup.material;
        let v = serde_json::json!({
            "title": self.title,
            "max_shear": self.report.peak.value,
            "at": { "patch": patch, "u": u, "v": v, "x": x[0], "y": x[1], "z": x[2] },
            "ratio_to_yield": self.ratio(),
            "mass": self.mass,
            "thickness": self.setup.thickness,
            "material": {
                "name": m.name, "youngs_modulus": m.youngs_modulus,
                "poisson_ratio": m.poisson_ratio, "density": m.density,
                "yield_stress": m.yield_stress,
            },
            "nodes": self.model.mesh.nodes.len(),
            "elements": { "S8R": quads, "S6": tris },
            "cells_per_patch": [self.setup.elements.0, self.setup.elements.1],
            "seconds": {
                "meshing": self.mesh_seconds, "deck": self.report.deck_seconds,
                "solver": self.report.solver_seconds, "read_back": self.report.read_seconds,
            },
        });
        let mut s = serde_json::to_string_pretty(&v).unwrap_or_default();
        s.push('\n');
        s
    }
}
