//! The limits on the work a design file may ask for, checked when the file is parsed, before
//! anything is built, solved or allocated beyond the parsed text. Each refusal names the field,
//! the value and the limit (`dynamic.steps: 4294967296 time steps; at most 1000000 allowed`).
//!
//! [`LIMITS`] is the one table of them: `docs/design-file.md` shows it and the JSON schema
//! carries the same numbers as `maximum`/`maxLength`/`maxItems` (tests check both).

use super::{CurveKind, DesignSpec};
use crate::{Error, Result};

/// Largest design file read, in bytes (16 MiB). Parsing a file of this size takes well under
/// 1 GB of memory.
pub const MAX_FILE_BYTES: usize = 16 << 20;
/// Longest string value (a title, a name, a formula), in characters.
pub const MAX_STRING_CHARS: usize = 4096;
/// Deepest nesting of parentheses in a string (a formula).
pub const MAX_FORMULA_DEPTH: usize = 64;
/// Most entries of any one array (control points, samples, knots, points).
pub const MAX_ARRAY_ITEMS: usize = 100_000;
/// Most nested tables and arrays.
pub const MAX_NESTING: usize = 32;
/// Most named curves.
pub const MAX_CURVES: usize = 10_000;
/// Most patches.
pub const MAX_PATCHES: usize = 1024;
/// Most `cos` (or `sin`) terms of a Fourier curve.
pub const MAX_FOURIER_TERMS: usize = 1024;
/// Most time steps of a `[dynamic]` run (`steps`, `max_steps`).
pub const MAX_STEPS: usize = 1_000_000;
/// Most intervals of a `[dynamic]` run.
pub const MAX_INTERVALS: usize = 1_000_000;
/// Most `steps × intervals` of a `[dynamic]` run (about a minute of work).
pub const MAX_STEP_WORK: u64 = 200_000_000;
/// Most annealing evaluations of `[optimize]` (and `pdeshape optimize --evaluations`).
pub const MAX_EVALUATIONS: usize = 1_000_000;
/// Most Nelder–Mead polish evaluations of `[optimize]` (and `--polish`).
pub const MAX_POLISH: usize = 100_000;
/// Most annealing chains of `[optimize]` (and `--chains`).
pub const MAX_CHAINS: usize = 1024;
/// Most worker threads of `pdeshape optimize --threads` (each takes a stack of its own; the
/// chains, at most [`MAX_CHAINS`], are the parallel work).
pub const MAX_THREADS: usize = 1024;
/// Most gradient evaluations of one start of `pdeshape optimize --method gradient`
/// (`--evaluations`).
pub const MAX_GRADIENT_EVALUATIONS: usize = 100_000;
/// Most starts of `pdeshape optimize --method gradient` (`--starts`).
pub const MAX_STARTS: usize = 1000;
/// Most constraints of `[optimize]`.
pub const MAX_CONSTRAINTS: usize = 256;
/// Most parameters of `[optimize]`, and most `[[parameters]]` entries.
pub const MAX_PARAMETERS: usize = 64;
/// Most vertices of an output grid (`nu × nv`, also for `--nu`/`--nv`): 67 million vertices
/// (`mesh::MAX_VERTICES`, checked again where the grid is allocated).
pub const MAX_GRID_VERTICES: usize = 1 << 26;
/// Smallest smoothing parameter `a` of a polyharmonic operator.
pub const MIN_SMOOTHING: f64 = 1e-6;
/// Largest smoothing parameter `a` of a polyharmonic operator.
pub const MAX_SMOOTHING: f64 = 1e6;
/// Smallest magnitude of a non-zero coefficient of a general or sixth-order operator, and the
/// largest ratio between the magnitudes of two of them.
pub const MIN_COEFFICIENT: f64 = 1e-100;
/// Largest magnitude of a coefficient of a general or sixth-order operator.
pub const MAX_COEFFICIENT: f64 = 1e100;

/// One row of the table of limits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Limit {
    /// Where it applies (a field, or a kind of value).
    pub field: &'static str,
    /// The bound as written in the docs (`≤ 1000000`).
    pub bound: &'static str,
    /// Why.
    pub reason: &'static str,
}

/// The table of every limit on work or size a design file is checked against.
pub const LIMITS: &[Limit] = &[
    Limit {
        field: "the file",
        bound: "≤ 16 MiB (16777216 bytes)",
        reason: "memory of parsing",
    },
    Limit {
        field: "any string (title, name, formula)",
        bound: "≤ 4096 characters",
        reason: "formula work, messages",
    },
    Limit {
        field: "parentheses in a string",
        bound: "nested ≤ 64 deep",
        reason: "formula parser stack",
    },
    Limit {
        field: "any array",
        bound: "≤ 100000 entries",
        reason: "memory and solve time",
    },
    Limit {
        field: "tables and arrays",
        bound: "nested ≤ 32 deep",
        reason: "parser stack",
    },
    Limit {
        field: "curves",
        bound: "≤ 10000 curves",
        reason: "build time",
    },
    Limit {
        field: "patches",
        bound: "≤ 1024 patches",
        reason: "solve time",
    },
    Limit {
        field: "operator.a (polyharmonic)",
        bound: "1e-6 ≤ a ≤ 1e6",
        reason: "mode systems stay solvable (a·n neither underflows nor overflows)",
    },
    Limit {
        field: "operator.coefficients, sixth-order a, b, c, d",
        bound: "0 or 1e-100 ≤ abs(c) ≤ 1e100",
        reason: "characteristic roots computable",
    },
    Limit {
        field: "curves.*.cos, curves.*.sin (fourier)",
        bound: "≤ 1024 terms",
        reason: "evaluation time",
    },
    Limit {
        field: "dynamic.steps, dynamic.max_steps",
        bound: "≤ 1000000",
        reason: "run time",
    },
    Limit {
        field: "dynamic.intervals",
        bound: "≤ 1000000",
        reason: "memory",
    },
    Limit {
        field: "dynamic.steps × dynamic.intervals",
        bound: "≤ 200000000",
        reason: "run time (about a minute)",
    },
    Limit {
        field: "optimize.evaluations, --evaluations",
        bound: "≤ 1000000",
        reason: "run time",
    },
    Limit {
        field: "optimize.polish, --polish",
        bound: "≤ 100000",
        reason: "run time",
    },
    Limit {
        field: "optimize.chains, --chains",
        bound: "1 … 1024",
        reason: "threads and memory",
    },
    Limit {
        field: "optimize --threads",
        bound: "1 … 1024",
        reason: "threads and memory",
    },
    Limit {
        field: "optimize --method gradient --evaluations",
        bound: "1 … 100000 gradient evaluations per start",
        reason: "run time",
    },
    Limit {
        field: "optimize --starts",
        bound: "1 … 1000",
        reason: "run time",
    },
    Limit {
        field: "optimize.constraints",
        bound: "≤ 256",
        reason: "evaluation time",
    },
    Limit {
        field: "optimize.parameters",
        bound: "≤ 64",
        reason: "evaluation time",
    },
    Limit {
        field: "output.nu × output.nv, --nu × --nv",
        bound: "≤ 67108864 vertices (nu ≥ 2, nv ≥ 3)",
        reason: "memory",
    },
    Limit {
        field: "spline.spans, spline control points",
        bound: "spans 1 … 1000 each; ≤ 10000 control points",
        reason: "dense linear algebra",
    },
    Limit {
        field: "render --size",
        bound: "each side 1 … 16384 pixels",
        reason: "memory",
    },
    Limit {
        field: "memory of one request (grids: 128 bytes a vertex; pictures: 16 bytes a pixel; \
                spline systems: 6 n² entries for n control points; dynamic runs: 384 bytes a \
                node and component, 24 a node and frame held; meshes read by fit: the file and \
                768 bytes a vertex or face; the search log of optimize: 96 + 8 bytes a \
                parameter per evaluation; a quadrature level: 256 bytes a u node, 16 kB a v \
                node)",
        bound: "≤ the smaller of 4 GiB and half of MemAvailable (and of PDESHAPE_MAX_MEMORY \
                if set)",
        reason: "refused before allocating, never aborted by the allocator",
    },
];

/// The limits of [`LIMITS`] as a markdown table (the one in `docs/design-file.md`).
pub fn limits_markdown() -> String {
    let mut s = String::from("| what | limit | why |\n|---|---|---|\n");
    for l in LIMITS {
        s.push_str(&format!("| {} | {} | {} |\n", l.field, l.bound, l.reason));
    }
    s
}

/// Refuses text longer than [`MAX_FILE_BYTES`].
pub(crate) fn check_text(text: &str) -> Result<()> {
    if text.len() > MAX_FILE_BYTES {
        return Err(Error::invalid(format!(
            "the design file has {} bytes; at most {MAX_FILE_BYTES} (16 MiB) are read",
            text.len()
        )));
    }
    Ok(())
}

fn join(place: &str, key: &str) -> String {
    if place.is_empty() {
        super::key_path(key)
    } else {
        format!("{place}.{}", super::key_path(key))
    }
}

/// Generic limits on a parsed TOML value: string length and parenthesis depth, array length,
/// nesting. `depth` is the nesting of `value`.
pub(crate) fn check_value(value: &toml::Value, place: &str, depth: usize) -> Result<()> {
    if depth > MAX_NESTING {
        return Err(Error::invalid(format!(
            "tables and arrays nest more than {MAX_NESTING} deep"
        ))
        .at(place));
    }
    match value {
        toml::Value::String(s) => check_string(s).map_err(|e| e.at(place)),
        toml::Value::Array(items) => {
            if items.len() > MAX_ARRAY_ITEMS {
                return Err(Error::invalid(format!(
                    "{} entries; at most {MAX_ARRAY_ITEMS} allowed",
                    items.len()
                ))
                .at(place));
            }
            for (i, item) in items.iter().enumerate() {
                check_value(item, &format!("{place}[{i}]"), depth + 1)?;
            }
            Ok(())
        }
        toml::Value::Table(t) => {
            for (k, item) in t {
                check_string(k).map_err(|e| e.at(place))?;
                check_value(item, &join(place, k), depth + 1)?;
            }
            Ok(())
        }
        _ => Ok(()),
    }
}

/// A string's length and its nesting of parentheses.
pub(crate) fn check_string(s: &str) -> Result<()> {
    let n = s.chars().count();
    if n > MAX_STRING_CHARS {
        return Err(Error::invalid(format!(
            "a text of {n} characters; at most {MAX_STRING_CHARS} allowed"
        )));
    }
    let mut depth = 0usize;
    let mut deepest = 0usize;
    for c in s.chars() {
        match c {
            '(' | '[' | '{' => {
                depth += 1;
                deepest = deepest.max(depth);
            }
            ')' | ']' | '}' => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    if deepest > MAX_FORMULA_DEPTH {
        return Err(Error::invalid(format!(
            "parentheses nest {deepest} deep; at most {MAX_FORMULA_DEPTH} allowed"
        )));
    }
    Ok(())
}

fn at_most(value: u64, max: u64, what: &str, place: &str) -> Result<()> {
    if value > max {
        return Err(Error::invalid(format!("{value} {what}; at most {max} allowed")).at(place));
    }
    Ok(())
}

fn coefficient(c: f64, place: &str) -> Result<()> {
    let m = c.abs();
    if c != 0.0 && !(MIN_COEFFICIENT..=MAX_COEFFICIENT).contains(&m) {
        return Err(Error::invalid(format!(
            "must be 0 or of magnitude between 1e-100 and 1e100 (got {})",
            crate::check::num(c)
        ))
        .at(place));
    }
    Ok(())
}

fn operator(op: &super::OperatorSpec, place: &str) -> Result<()> {
    use super::OperatorSpec::*;
    match op {
        Polyharmonic { a, .. } => {
            if a.is_finite() && *a > 0.0 && !(MIN_SMOOTHING..=MAX_SMOOTHING).contains(a) {
                return Err(Error::invalid(format!(
                    "must lie between 1e-6 and 1e6 (got {}): the solver's mode systems are \
                     exact only in that range",
                    crate::check::num(*a)
                ))
                .at(&format!("{place}.a")));
            }
        }
        SixthOrder { a, b, c, d } => {
            for (name, x) in [("a", a), ("b", b), ("c", c), ("d", d)] {
                coefficient(*x, &format!("{place}.{name}"))?;
            }
        }
        General { coefficients } => {
            for (k, x) in coefficients.iter().enumerate() {
                coefficient(*x, &format!("{place}.coefficients[{k}]"))?;
            }
        }
    }
    Ok(())
}

/// Limits of the parsed design's fields (counts and sizes of work), checked before anything is
/// built.
pub fn check_spec(spec: &DesignSpec) -> Result<()> {
    at_most(
        spec.curves.len() as u64,
        MAX_CURVES as u64,
        "curves",
        "curves",
    )?;
    for (name, c) in &spec.curves {
        if let CurveKind::Fourier { cos, sin, .. } = &c.kind {
            let place = format!("curves.{}", super::key_path(name));
            for (key, terms) in [("cos", cos), ("sin", sin)] {
                at_most(
                    terms.len() as u64,
                    MAX_FOURIER_TERMS as u64,
                    "terms",
                    &format!("{place}.{key}"),
                )?;
            }
        }
    }
    at_most(
        spec.parameters.len() as u64,
        MAX_PARAMETERS as u64,
        "parameters",
        "parameters",
    )?;
    if let Some(op) = &spec.operator {
        operator(op, "operator")?;
    }
    if let Some(patches) = &spec.patches {
        at_most(
            patches.len() as u64,
            MAX_PATCHES as u64,
            "patches",
            "patches",
        )?;
        for (i, p) in patches.iter().enumerate() {
            if let Some(op) = &p.operator {
                operator(op, &format!("patches[{i}].operator"))?;
            }
        }
    }
    if let Some(d) = &spec.dynamic {
        if let Some(s) = d.steps {
            at_most(s as u64, MAX_STEPS as u64, "time steps", "dynamic.steps")?;
        }
        if let Some(s) = d.max_steps {
            at_most(
                s as u64,
                MAX_STEPS as u64,
                "time steps",
                "dynamic.max_steps",
            )?;
        }
        if let Some(j) = d.intervals {
            at_most(
                j as u64,
                MAX_INTERVALS as u64,
                "intervals",
                "dynamic.intervals",
            )?;
        }
        if let (Some(s), Some(j)) = (d.steps, d.intervals) {
            let work = s as u64 * j as u64;
            if work > MAX_STEP_WORK {
                return Err(Error::invalid(format!(
                    "{s} steps × {j} intervals = {work}; at most {MAX_STEP_WORK} allowed"
                ))
                .at("dynamic.steps"));
            }
        }
    }
    if let Some(o) = &spec.optimize {
        check_optimize_counts(o.evaluations, o.polish, o.chains).map_err(|e| e.at("optimize"))?;
        at_most(
            o.constraints.len() as u64,
            MAX_CONSTRAINTS as u64,
            "constraints",
            "optimize.constraints",
        )?;
        at_most(
            o.parameters.len() as u64,
            MAX_PARAMETERS as u64,
            "parameters",
            "optimize.parameters",
        )?;
    }
    if let (Some(nu), Some(nv)) = (spec.output.nu, spec.output.nv) {
        if nu.checked_mul(nv).is_none_or(|n| n > MAX_GRID_VERTICES) {
            return Err(Error::invalid(format!(
                "a {nu} × {nv} grid has more than {MAX_GRID_VERTICES} vertices"
            ))
            .at("output.nu"));
        }
    }
    Ok(())
}

/// The limits on an optimisation's evaluations, polish and chains (places `evaluations`,
/// `polish`, `chains`), shared by the file and the command line.
pub fn check_optimize_counts(evaluations: usize, polish: usize, chains: usize) -> Result<()> {
    at_most(
        evaluations as u64,
        MAX_EVALUATIONS as u64,
        "evaluations",
        "evaluations",
    )?;
    at_most(polish as u64, MAX_POLISH as u64, "evaluations", "polish")?;
    if chains == 0 || chains > MAX_CHAINS {
        return Err(
            Error::invalid(format!("must be between 1 and {MAX_CHAINS} (got {chains})"))
                .at("chains"),
        );
    }
    // Every chain starts with one evaluation.
    if evaluations < chains {
        return Err(Error::invalid(format!(
            "must be at least the number of chains, {chains} (got {evaluations})"
        ))
        .at("evaluations"));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::parse_design;

    fn err(text: &str) -> String {
        parse_design(text).unwrap_err().to_string()
    }

    #[test]
    fn work_limits_name_field_value_and_limit() {
        assert_eq!(
            err("[dynamic]\nintervals = 30\nsteps = 4294967296\nt_end = 1.0\n"),
            "dynamic.steps: 4294967296 time steps; at most 1000000 allowed"
        );
        assert_eq!(
            err("[dynamic]\nintervals = 2000000\nsteps = 10\nt_end = 1.0\n"),
            "dynamic.intervals: 2000000 intervals; at most 1000000 allowed"
        );
        assert_eq!(
            err("[dynamic]\nintervals = 1000\nsteps = 1000000\nt_end = 1.0\n"),
            "dynamic.steps: 1000000 steps × 1000 intervals = 1000000000; at most 200000000 allowed"
        );
        let opt = |k: &str| {
            format!(
                "[optimize]\nobjective = \"area\"\n{k}\n[[optimize.parameters]]\nname = \"a\"\nmin = 1.0\nmax = 2.0\n"
            )
        };
        assert_eq!(
            err(&opt("evaluations = 99999999999")),
            "optimize.evaluations: 99999999999 evaluations; at most 1000000 allowed"
        );
        assert_eq!(
            err(&opt("polish = 99999999999")),
            "optimize.polish: 99999999999 evaluations; at most 100000 allowed"
        );
        // Each chain starts with one evaluation; the file's own check says so (not only the
        // optimiser), so `check` and the schema agree.
        assert_eq!(
            err(&opt("evaluations = 0")),
            "optimize.evaluations: must be at least the number of chains, 4 (got 0)"
        );
        assert_eq!(
            err(&opt("evaluations = 2\nchains = 3")),
            "optimize.evaluations: must be at least the number of chains, 3 (got 2)"
        );
    }

    #[test]
    fn fourier_terms_are_capped() {
        let terms = vec!["[0.0, 0.0, 0.0]"; 1025].join(", ");
        let text =
            format!("[curves.c]\ntype = \"fourier\"\na0 = [0.0, 0.0, 0.0]\ncos = [{terms}]\n");
        assert_eq!(err(&text), "curves.c.cos: 1025 terms; at most 1024 allowed");
        let ok = vec!["[0.0, 0.0, 0.0]"; 1024].join(", ");
        let text = format!("[curves.c]\ntype = \"fourier\"\na0 = [0.0, 0.0, 0.0]\ncos = [{ok}]\n");
        assert!(parse_design(&text).is_ok());
    }

    #[test]
    fn smoothing_parameter_range() {
        for (a, ok) in [
            ("1e-320", false),
            ("1e-7", false),
            ("1e-6", true),
            ("1e6", true),
            ("2e6", false),
        ] {
            let text = format!("[operator]\nkind = \"polyharmonic\"\norder = 2\na = {a}\n");
            assert_eq!(parse_design(&text).is_ok(), ok, "a = {a}");
        }
        assert_eq!(
            err("[operator]\nkind = \"polyharmonic\"\norder = 2\na = 1e-320\n"),
            "operator.a: must lie between 1e-6 and 1e6 (got 1e-320): the solver's mode systems \
             are exact only in that range"
        );
        assert!(
            err("[operator]\nkind = \"general\"\ncoefficients = [1.0, 1e-320]\n")
                .starts_with("operator.coefficients[1]: must be 0 or of magnitude")
        );
    }

    #[test]
    fn sizes_of_strings_arrays_and_nesting() {
        let long = "x".repeat(5000);
        assert_eq!(
            err(&format!("title = \"{long}\"\n")),
            "title: a text of 5000 characters; at most 4096 allowed"
        );
        let deep = format!("{}u{}", "(".repeat(65), ")".repeat(65));
        assert_eq!(
            err(&format!(
                "[curves.c]\ntype = \"formula\"\nx = \"{deep}\"\ny = \"0\"\nz = \"0\"\n"
            )),
            "curves.c.x: parentheses nest 65 deep; at most 64 allowed"
        );
        let big = vec!["[0.0, 0.0, 0.0]"; 100_001].join(",");
        assert_eq!(
            err(&format!(
                "[curves.c]\ntype = \"bezier\"\ncontrol = [{big}]\n"
            )),
            "curves.c.control: 100001 entries; at most 100000 allowed"
        );
        let nested = format!("x = {}1{}\n", "[".repeat(40), "]".repeat(40));
        assert!(
            err(&nested).contains("nest more than 32 deep"),
            "{}",
            err(&nested)
        );
    }

    #[test]
    fn the_file_size_is_capped() {
        let text = format!("# {}\n", "x".repeat(super::MAX_FILE_BYTES));
        assert!(err(&text).starts_with("the design file has 16777219 bytes; at most 16777216"));
    }

    #[test]
    fn the_grid_limit_is_the_mesh_limit() {
        assert_eq!(super::MAX_GRID_VERTICES, crate::mesh::MAX_VERTICES);
    }

    #[test]
    fn the_docs_show_the_table() {
        let doc = include_str!("../../../../docs/design-file.md");
        assert!(
            doc.contains(&super::limits_markdown()),
            "docs/design-file.md must contain the table of limits exactly:\n{}",
            super::limits_markdown()
        );
    }
}
