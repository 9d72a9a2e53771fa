//! What the subcommands share: loading a design with located errors, choosing the grid, and
//! writing an output file atomically.

use pdeshape::design::{self, BuiltDesign, DEFAULT_NU, DEFAULT_NV};
use pdeshape::spec::{self, DesignSpec};
use pdeshape::Error;
use std::io::Write;
use std::path::{Path, PathBuf};

/// A failure: one line for stderr and the exit status.
#[derive(Debug)]
pub struct CliError {
    pub message: String,
    pub status: u8,
}

impl CliError {
    /// Bad input (design, arguments, output path): exit status 2.
    pub fn input(message: impl Into<String>) -> Self {
        CliError {
            message: message.into(),
            status: 2,
        }
    }
}

/// A design file read and parsed.
pub struct Loaded {
    pub file: String,
    pub text: String,
    pub spec: DesignSpec,
}

impl Loaded {
    /// `file:line:col: place: message` for an error about this file.
    pub fn error(&self, e: &Error) -> CliError {
        CliError::input(spec::describe_error(&self.file, &self.text, e))
    }

    /// Validates, builds and solves the design.
    pub fn build(&self) -> Result<BuiltDesign, CliError> {
        design::build_design(&self.spec).map_err(|e| self.error(&e))
    }

    /// Validates the design without solving it.
    pub fn validate(&self) -> Result<(), CliError> {
        design::validate_design(&self.spec).map_err(|e| self.error(&e))
    }

    /// The grid: the command line's `--nu`/`--nv`, else `[output]`, else 64 × 128; refused
    /// (before anything is solved or allocated) beyond the library's grid limits.
    pub fn grid(&self, nu: Option<usize>, nv: Option<usize>) -> Result<(usize, usize), CliError> {
        let (nu_file, nv_file) = (self.spec.output.nu, self.spec.output.nv);
        let nu_v = nu.or(nu_file).unwrap_or(DEFAULT_NU);
        let nv_v = nv.or(nv_file).unwrap_or(DEFAULT_NV);
        // The vertex limit holds for the whole design: every patch gets its own grid.
        let patches = match (&self.spec.patches, &self.spec.conditions) {
            (Some(p), _) => p.len(),
            (None, Some(_)) => 1,
            (None, None) => 0,
        } + self.spec.parametric.len();
        let patches = patches.max(1);
        let checked = design::check_grid(nu_v, nv_v).and_then(|()| {
            match nu_v.checked_mul(nv_v).and_then(|n| n.checked_mul(patches)) {
                Some(n) if n <= pdeshape::mesh::MAX_VERTICES => Ok(()),
                _ => Err(pdeshape::Error::invalid(format!(
                    "{patches} patches of {nu_v} × {nv_v} vertices exceed {} vertices in all; refusing to allocate them",
                    pdeshape::mesh::MAX_VERTICES
                ))
                .at("nu × nv")),
            }
        });
        match checked {
            Ok(()) => Ok((nu_v, nv_v)),
            Err(e) => {
                let from_cli = match e.place() {
                    "nu" => nu.is_some(),
                    "nv" => nv.is_some(),
                    _ => nu.is_some() || nv.is_some(),
                };
                if from_cli {
                    let place = match e.place() {
                        "nu" => "--nu".to_string(),
                        "nv" => "--nv".to_string(),
                        _ => "--nu × --nv".to_string(),
                    };
                    Err(CliError::input(format!("{place}: {}", message_of(&e))))
                } else {
                    Err(self.error(&e.at("output")))
                }
            }
        }
    }
}

/// The message of an error without its place.
pub fn message_of(e: &Error) -> String {
    match e {
        Error::Invalid { message, .. } | Error::Io { message, .. } => message.clone(),
        Error::NotUnique { .. } => {
            let s = e.to_string();
            let p = e.place();
            s.strip_prefix(&format!("{p}: ")).unwrap_or(&s).to_string()
        }
    }
}

/// Reads and parses a design file.
pub fn load(path: &Path) -> Result<Loaded, CliError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path)
        .map_err(|e| CliError::input(format!("{file}: cannot read the design file: {e}")))?;
    let spec = spec::parse_design(&text)
        .map_err(|e| CliError::input(spec::describe_error(&file, &text, &e)))?;
    Ok(Loaded { file, text, spec })
}

/// An output file being written: a temporary file next to the target, renamed over it only when
/// everything succeeded. Dropped without [`Output::commit`], it leaves nothing behind.
pub struct Output {
    path: PathBuf,
    temp: tempfile::NamedTempFile,
}

impl Output {
    /// Creates the temporary file in the target's directory (so the final rename is atomic).
    pub fn create(path: &Path) -> Result<Self, CliError> {
        let shown = path.display();
        if path.is_dir() {
            return Err(CliError::input(format!("-o {shown}: is a directory")));
        }
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let temp = tempfile::Builder::new()
            .prefix(".pdeshape-")
            .suffix(".tmp")
            .tempfile_in(&dir)
            .map_err(|e| {
                CliError::input(format!(
                    "-o {shown}: cannot create a file in '{}': {e}",
                    dir.display()
                ))
            })?;
        Ok(Output {
            path: path.to_path_buf(),
            temp,
        })
    }

    /// A buffered writer on the temporary file.
    pub fn writer(&mut self) -> std::io::BufWriter<&mut std::fs::File> {
        std::io::BufWriter::new(self.temp.as_file_mut())
    }

    /// Writes `bytes` to the temporary file.
    pub fn write_all(&mut self, bytes: &[u8]) -> Result<(), CliError> {
        let shown = self.path.display().to_string();
        self.temp
            .as_file_mut()
            .write_all(bytes)
            .map_err(|e| CliError::input(format!("-o {shown}: {e}")))
    }

    /// Flushes and renames the temporary file onto the target.
    pub fn commit(self) -> Result<(), CliError> {
        let shown = self.path.display().to_string();
        // Temporary files are private (0600); the result gets the usual permissions of a new
        // file (rw-r--r--).
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            self.temp
                .as_file()
                .set_permissions(std::fs::Permissions::from_mode(0o644))
                .map_err(|e| CliError::input(format!("-o {shown}: {e}")))?;
        }
        self.temp
            .as_file()
            .sync_all()
            .map_err(|e| CliError::input(format!("-o {shown}: {e}")))?;
        self.temp
            .persist(&self.path)
            .map_err(|e| CliError::input(format!("-o {shown}: {}", e.error)))?;
        Ok(())
    }
}

/// Writes to stdout, ignoring a closed pipe (`pdeshape schema | head` is fine).
pub fn print_stdout(text: &str) {
    let mut out = std::io::stdout().lock();
    let _ = out.write_all(text.as_bytes());
    let _ = out.flush();
}

/// Tessellates every patch of a design (f32 meshes, as every mesh format and picture stores).
pub fn meshes(
    built: &pdeshape::design::BuiltDesign,
    nu: usize,
    nv: usize,
) -> Result<Vec<pdeshape::mesh::GridMesh>, CliError> {
    grids(built, nu, nv, pdeshape::mesh::tessellate)
}

/// Full-precision samples of every patch (CSV).
pub fn samples(
    built: &pdeshape::design::BuiltDesign,
    nu: usize,
    nv: usize,
) -> Result<Vec<pdeshape::mesh::Samples>, CliError> {
    grids(built, nu, nv, pdeshape::mesh::sample)
}

/// Evaluates every patch on the grid and refuses a surface that is not finite somewhere, naming
/// the condition curve that is not finite there (formula curves are checked at sample points
/// only when they are read, so a NaN between them shows up here).
fn grids<T: Copy + Into<f64>>(
    built: &pdeshape::design::BuiltDesign,
    nu: usize,
    nv: usize,
    eval: impl Fn(
        &dyn pdeshape::surface::Surface,
        usize,
        usize,
    ) -> pdeshape::Result<pdeshape::mesh::Grid<T>>,
) -> Result<Vec<pdeshape::mesh::Grid<T>>, CliError> {
    let mut out = Vec::with_capacity(built.patches.len());
    for (k, p) in built.patches.iter().enumerate() {
        let g = eval(&p.surface, nu, nv).map_err(|e| CliError::input(e.to_string()))?;
        let bad = g
            .positions
            .iter()
            .zip(&g.normals)
            .position(|(a, b)| a.iter().chain(b).any(|x| !(*x).into().is_finite()));
        if let Some(at) = bad {
            let (i, j) = (at / g.nv, at % g.nv);
            let (u, v) = (g.u[i], g.v[j]);
            let culprit = built.conditions[k].iter().enumerate().find(|(_, c)| {
                !(0..3).all(|d| c.curve.derivative(v, d).iter().all(|x| x.is_finite()))
            });
            let place = if built.multi_patch {
                format!("patches[{k}].")
            } else {
                String::new()
            };
            return Err(CliError::input(match culprit {
                Some((ci, c)) => format!(
                    "{place}conditions[{ci}].curve{}: not finite at v = {v} (or its derivatives are not)",
                    c.curve_name.as_deref().map(|n| format!(" ('{n}')")).unwrap_or_default()
                ),
                None => format!(
                    "{place}the surface '{}' is not finite at u = {u}, v = {v}",
                    p.name
                ),
            }));
        }
        out.push(g);
    }
    for p in &built.parametric {
        let g = eval(&p.surface, nu, nv).map_err(|e| CliError::input(e.to_string()))?;
        out.push(g);
    }
    Ok(out)
}
