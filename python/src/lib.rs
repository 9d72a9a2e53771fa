//! `pdeshape._pdeshape`: the Python extension, a thin shell over the library's public API
//! (`spec::parse_design`, `design::solve_design`, `SolvedDesign`, `analysis`, `optimize`,
//! `mesh`). The Python package `pdeshape` re-exports it with docstrings and type stubs.
//!
//! Every error is a `pdeshape.DesignError` (a `ValueError`) carrying the message the CLI prints:
//! `file:line:col: place: message` for errors in a design, `<argument>: message` for bad
//! arguments. Solves, tessellations and integrals run with the Python thread detached (the GIL
//! released), so threads and Dask workers run them in parallel.

use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{IntoPyArray, PyReadonlyArray1};
use pdeshape::analysis::{self, integrate_design, Integrals, Quadrature};
use pdeshape::cad;
use pdeshape::design::WriteDesign as _;
use pdeshape::design::{self, Export, SolvedDesign};
use pdeshape::diagnostics;
use pdeshape::dynamic::CurveFrame;
use pdeshape::dynamic_run::{self, DynamicOutcome, OutcomeKind};
use pdeshape::fit;
use pdeshape::format::{export_timestamp, OutputFormat};
use pdeshape::mesh::{self, Format, Up};
use pdeshape::optimize::{Parameters, Problem};
use pdeshape::spec::{self, DesignSpec, Units};
use pdeshape::{Error, Vec3};
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;

create_exception!(
    _pdeshape,
    DesignError,
    PyValueError,
    "A design that cannot be read, solved or written; the message is the CLI's (file:line:col: \
     place: message)."
);

fn err(message: impl Into<String>) -> PyErr {
    DesignError::new_err(message.into())
}

/// A design read from TOML text, with its solution once solved.
#[pyclass(module = "pdeshape._pdeshape", name = "Design")]
struct Design {
    /// The name errors are located in (the path, `<string>` or `<dict>`).
    file: String,
    text: String,
    spec: DesignSpec,
    /// Parameter values applied by `set_params` (in the order they were set).
    params: Vec<(String, f64)>,
    solved: Option<Arc<SolvedDesign>>,
}

impl Design {
    /// `file:line:col: place: message` for an error about this design.
    fn located(&self, e: &Error) -> PyErr {
        err(spec::describe_error(&self.file, &self.text, e))
    }

    fn parse(file: String, text: String) -> PyResult<Design> {
        let f = pdeshape::open::DesignFile { file, text };
        let spec = f.parse_still().map_err(|e| err(e.message))?;
        let pdeshape::open::DesignFile { file, text } = f;
        Ok(Design {
            file,
            text,
            spec,
            params: Vec::new(),
            solved: None,
        })
    }

    /// The solved design, solving it (with the GIL released) on first use.
    fn solved(&mut self, py: Python<'_>) -> PyResult<Arc<SolvedDesign>> {
        if let Some(s) = &self.solved {
            return Ok(s.clone());
        }
        let spec = &self.spec;
        let solved = py
            .detach(|| design::solve_design(spec))
            .map_err(|e| self.located(&e))?;
        let solved = Arc::new(solved);
        self.solved = Some(solved.clone());
        Ok(solved)
    }

    /// The grid as the CLI chooses it: the arguments, else `[output]`, else 64 × 128.
    fn grid(&self, nu: Option<usize>, nv: Option<usize>) -> PyResult<(usize, usize)> {
        design::grid(&self.spec, nu, nv).map_err(|e| {
            if e.place().starts_with("output") {
                self.located(&e)
            } else {
                err(format!("{}: {}", e.place(), message_of(&e)))
            }
        })
    }

    /// The index of a patch given by number or name.
    fn patch_index(solved: &SolvedDesign, patch: &Bound<'_, PyAny>) -> PyResult<usize> {
        if let Ok(k) = patch.extract::<usize>() {
            if k < solved.surfaces.len() {
                return Ok(k);
            }
            return Err(err(format!(
                "patch: {k} is out of range (the design has {} surfaces)",
                solved.surfaces.len()
            )));
        }
        let name: String = patch
            .extract()
            .map_err(|_| err("patch: must be a surface's index or name"))?;
        solved
            .surfaces
            .iter()
            .position(|s| s.name == name)
            .ok_or_else(|| {
                err(format!(
                    "patch: no surface is called '{name}' (the surfaces are {})",
                    solved.names().join(", ")
                ))
            })
    }

    fn refuse_trims(&self, solved: &SolvedDesign, what: &str) -> PyResult<()> {
        if solved.trims.is_empty() {
            Ok(())
        } else {
            Err(err(format!(
                "{what}: the design has [[trims]]; its full grids are not the surface: use mesh() \
                 (the trimmed triangle mesh)"
            )))
        }
    }
}

/// The samples of every surface as the flat arrays of `Design.tessellate`.
struct Flat {
    vertices: Vec<f64>,
    normals: Vec<f64>,
    uv: Vec<f64>,
    patch: Vec<u32>,
    faces: Vec<u32>,
    shape: Vec<u64>,
}

impl Flat {
    /// Takes the grids' buffers: the first surface's positions and normals become the
    /// concatenated arrays (grown in place), so only the later surfaces are copied; the (u, v)
    /// pairs, surface numbers and faces are written into buffers of their exact final size, on
    /// the other thread while the positions are being joined.
    fn of(mut samples: Vec<mesh::Samples>) -> Flat {
        let positions: Vec<_> = samples
            .iter_mut()
            .map(|g| std::mem::take(&mut g.positions))
            .collect();
        let normals: Vec<_> = samples
            .iter_mut()
            .map(|g| std::mem::take(&mut g.normals))
            .collect();
        let ((vertices, normals), (uv, patch, faces)) = rayon::join(
            || (concat3(positions), concat3(normals)),
            || (uv_pairs(&samples), patch_numbers(&samples), faces(&samples)),
        );
        let shape = samples
            .iter()
            .flat_map(|g| [g.nu as u64, g.nv as u64])
            .collect();
        Flat {
            vertices,
            normals,
            uv,
            patch,
            faces,
            shape,
        }
    }
}

/// The rows of several grids as one flat array, reusing the first grid's buffer.
fn concat3(parts: Vec<Vec<[f64; 3]>>) -> Vec<f64> {
    let total: usize = parts.iter().map(Vec::len).sum();
    let mut parts = parts.into_iter();
    let mut out = parts.next().unwrap_or_default();
    out.reserve_exact(total - out.len());
    for p in parts {
        out.extend_from_slice(&p);
    }
    out.into_flattened()
}

/// `(u_i, v_j)` of every sample, in the order of the samples.
fn uv_pairs(samples: &[mesh::Samples]) -> Vec<f64> {
    let n: usize = samples.iter().map(|g| g.len()).sum();
    let mut uv = Vec::with_capacity(2 * n);
    for g in samples {
        for &u in &g.u {
            for &v in &g.v {
                uv.push(u);
                uv.push(v);
            }
        }
    }
    uv
}

fn patch_numbers(samples: &[mesh::Samples]) -> Vec<u32> {
    let n: usize = samples.iter().map(|g| g.len()).sum();
    let mut patch = Vec::with_capacity(n);
    for (k, g) in samples.iter().enumerate() {
        patch.resize(patch.len() + g.len(), k as u32);
    }
    patch
}

/// The columns of quads of a grid: `nv` when `v` is periodic (the last wraps to the first).
fn quad_columns(g: &mesh::Samples) -> usize {
    if g.periodic_v {
        g.nv
    } else {
        g.nv.saturating_sub(1)
    }
}

/// `Grid::triangles` of every grid, written out with indices into the concatenated vertices:
/// quads (i,j), (i+1,j), (i+1,j+1), (i,j+1) split along the diagonal from (i,j) to
/// (i+1,j+1), columns wrapping when `v` is periodic.
fn faces(samples: &[mesh::Samples]) -> Vec<u32> {
    let m: usize = samples
        .iter()
        .map(|g| 6 * g.nu.saturating_sub(1) * quad_columns(g))
        .sum();
    let mut f = Vec::with_capacity(m);
    let mut base = 0u32;
    for g in samples {
        let (nu, nv) = (g.nu as u32, g.nv as u32);
        let cols = quad_columns(g) as u32;
        for i in 0..nu.saturating_sub(1) {
            let row = base + i * nv;
            for j in 0..cols {
                let j1 = if j + 1 == nv { 0 } else { j + 1 };
                let (a, b, c, d) = (row + j, row + nv + j, row + nv + j1, row + j1);
                f.extend_from_slice(&[a, b, c, a, c, d]);
            }
        }
        base += (g.nu * g.nv) as u32;
    }
    f
}

/// The message of an error without its place.
fn message_of(e: &Error) -> String {
    e.message()
}

fn vec3s(py: Python<'_>, rows: impl ExactSizeIterator<Item = [f64; 3]>) -> Py<PyAny> {
    let n = rows.len();
    let flat: Vec<f64> = rows.flatten().collect();
    Array2::from_shape_vec((n, 3), flat)
        .expect("n rows of 3")
        .into_pyarray(py)
        .into_any()
        .unbind()
}

fn array2<T: numpy::Element>(py: Python<'_>, flat: Vec<T>, cols: usize) -> Py<PyAny> {
    let n = flat.len() / cols;
    Array2::from_shape_vec((n, cols), flat)
        .expect("whole rows")
        .into_pyarray(py)
        .into_any()
        .unbind()
}

fn array1<T: numpy::Element>(py: Python<'_>, v: Vec<T>) -> Py<PyAny> {
    Array1::from_vec(v).into_pyarray(py).into_any().unbind()
}

fn integrals_dict<'py>(py: Python<'py>, i: &Integrals) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (k, v) in [
        ("area", i.area),
        ("volume", i.volume),
        ("mean_integral", i.mean),
        ("mean_sq_integral", i.mean_sq),
        ("gauss_integral", i.gauss),
        ("bending_energy", i.bending_energy()),
        ("willmore", i.willmore()),
    ] {
        d.set_item(k, v)?;
    }
    Ok(d)
}

fn parse_format(name: &str, place: &str) -> PyResult<Format> {
    name.parse::<OutputFormat>()
        .and_then(OutputFormat::mesh)
        .map_err(|e| err(format!("{place} {name}: {}", message_of(&e))))
}

/// Writes `bytes` to `path` through a temporary file beside it, so a failure leaves no broken
/// file and an existing file is replaced whole.
fn write_atomically(path: &Path, bytes: &[u8]) -> PyResult<()> {
    let shown = path.display();
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let io = |e: std::io::Error| err(format!("path {shown}: {e}"));
    let mut tmp = tempfile::Builder::new()
        .prefix(".pdeshape-")
        .suffix(".tmp")
        .tempfile_in(&dir)
        .map_err(io)?;
    tmp.write_all(bytes).map_err(io)?;
    tmp.flush().map_err(io)?;
    tmp.persist(path).map_err(|e| io(e.error))?;
    Ok(())
}

#[pymethods]
impl Design {
    /// Reads a design file (TOML).
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Design> {
        let f = pdeshape::open::DesignFile::read(&path).map_err(|e| err(e.message))?;
        Design::parse(f.file, f.text)
    }

    /// A design from TOML text; errors are located in `name`.
    #[staticmethod]
    #[pyo3(signature = (text, name = "<string>"))]
    fn from_toml(text: String, name: &str) -> PyResult<Design> {
        Design::parse(name.to_string(), text)
    }

    /// A design from JSON text (what `from_dict` sends): written as TOML, then read as a file.
    #[staticmethod]
    #[pyo3(signature = (text, name = "<dict>"))]
    fn from_json(text: &str, name: &str) -> PyResult<Design> {
        let value: toml::Value = serde_json::from_str(text)
            .map_err(|e| err(format!("{name}: not a table of design keys: {e}")))?;
        let toml_text = toml::to_string(&value)
            .map_err(|e| err(format!("{name}: cannot be written as TOML: {e}")))?;
        Design::parse(name.to_string(), toml_text)
    }

    /// A design from a dict with the keys of a design file (as `tomllib.load` returns);
    /// errors are located in `name` (in the TOML text the dict is written as).
    #[staticmethod]
    #[pyo3(signature = (d, name = "<dict>"))]
    fn from_dict(py: Python<'_>, d: &Bound<'_, PyAny>, name: &str) -> PyResult<Design> {
        let kwargs = PyDict::new(py);
        kwargs.set_item("allow_nan", false)?;
        let text: String = py
            .import("json")?
            .call_method("dumps", (d,), Some(&kwargs))
            .map_err(|e| err(format!("{name}: not a table of design keys: {e}")))?
            .extract()?;
        Design::from_json(&text, name)
    }

    /// The mesh of [`Design::mesh`] as a `trimesh.Trimesh` (needs the trimesh package).
    /// Each triangle's surface is the face attribute `patch` (an index into the metadata's
    /// `patches`); the metadata has the design's `title`, `units`, `file`, `patches` and
    /// `parameters`; `welded=False` gives each surface's grid as sampled, with every vertex's
    /// `uv` (a welded vertex has several, so the welded mesh has none).
    #[pyo3(signature = (nu = None, nv = None, separate_patches = false, welded = true))]
    fn to_trimesh<'py>(
        slf: &Bound<'py, Self>,
        nu: Option<usize>,
        nv: Option<usize>,
        separate_patches: bool,
        welded: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        slf.py()
            .import("pdeshape._convert")?
            .call_method1("to_trimesh", (slf, nu, nv, separate_patches, welded))
    }

    /// The mesh of [`Design::mesh`] as a `pyvista.PolyData` (needs the pyvista package).
    /// Each triangle's surface is the face attribute `patch` (an index into the metadata's
    /// `patches`); the metadata has the design's `title`, `units`, `file`, `patches` and
    /// `parameters`; `welded=False` gives each surface's grid as sampled, with every vertex's
    /// `uv` (a welded vertex has several, so the welded mesh has none).
    #[pyo3(signature = (nu = None, nv = None, separate_patches = false, welded = true))]
    fn to_pyvista<'py>(
        slf: &Bound<'py, Self>,
        nu: Option<usize>,
        nv: Option<usize>,
        separate_patches: bool,
        welded: bool,
    ) -> PyResult<Bound<'py, PyAny>> {
        slf.py()
            .import("pdeshape._convert")?
            .call_method1("to_pyvista", (slf, nu, nv, separate_patches, welded))
    }

    /// The TOML text the design was read from.
    #[getter]
    fn text(&self) -> &str {
        &self.text
    }

    /// Where errors are located (the path, `<string>` or `<dict>`).
    #[getter]
    fn file(&self) -> &str {
        &self.file
    }

    /// The design's title, if it has one.
    #[getter]
    fn title(&self) -> Option<String> {
        self.spec.title.clone()
    }

    /// The design's length unit (`units`: `mm`, `cm`, `m` or `in`), if it declares one.
    #[getter]
    fn units(&self) -> Option<&'static str> {
        self.spec.units.map(|u| u.as_str())
    }

    /// The names of the curves of `[curves]`, sorted.
    #[getter]
    fn curves(&self) -> Vec<String> {
        self.spec.curves.keys().cloned().collect()
    }

    /// The names of the surfaces of the solved design, in design order (solves if needed).
    #[getter]
    fn patches(&mut self, py: Python<'_>) -> PyResult<Vec<String>> {
        let s = self.solved(py)?;
        Ok(s.names().iter().map(|n| n.to_string()).collect())
    }

    /// The design's declared parameters with their bounds and values, as dicts: each
    /// `[[parameters]]` entry (`source` "parameters": `name`, `kind`, `curve`, `with`, `min`,
    /// `max`, `value` — the one set by `with_params`, else the file's, else the neutral one —
    /// `neutral` and `drives`, what it moves in words), then each parameter of `[optimize]`
    /// (`source` "optimize": `name`, `min`, `max`, `initial`, `value`). Empty when the design
    /// declares none; [`Design::parameter_names`] lists every other name `with_params` takes.
    fn parameters<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let out = PyList::empty(py);
        if !self.spec.parameters.is_empty() {
            let solved = self.solved(py)?;
            let d = diagnostics::diagnose(&self.spec, &solved);
            for p in &d.parameters {
                let e = PyDict::new(py);
                e.set_item("source", "parameters")?;
                e.set_item("name", &p.name)?;
                e.set_item("kind", p.kind)?;
                e.set_item("curve", &p.curve)?;
                e.set_item("with", &p.with)?;
                e.set_item("min", p.min)?;
                e.set_item("max", p.max)?;
                e.set_item("value", p.value)?;
                e.set_item("neutral", p.neutral)?;
                e.set_item("drives", &p.drives)?;
                out.append(e)?;
            }
        }
        if let Some(opt) = &self.spec.optimize {
            let ps = Parameters::new(&self.spec, opt).map_err(|e| self.located(&e))?;
            for p in &ps.list {
                let d = PyDict::new(py);
                d.set_item("source", "optimize")?;
                d.set_item("name", &p.name)?;
                d.set_item("min", p.min)?;
                d.set_item("max", p.max)?;
                d.set_item("initial", p.initial)?;
                let set = self
                    .params
                    .iter()
                    .find(|(n, _)| n == &p.name)
                    .map(|(_, v)| *v);
                d.set_item("value", set.unwrap_or(p.initial))?;
                out.append(d)?;
            }
        }
        Ok(out)
    }

    /// Every name `with_params` takes: the declared parameters' ([`Design::parameters`]), then
    /// the book's notation for this design (`a`, and per curve `<curve>T<x|y|z>`,
    /// `<curve>R<x|y|z>`, `<curve>D<x|y|z>`, `<curve>cT` for a B-spline), which have no bounds.
    fn parameter_names(&self) -> Vec<String> {
        let mut out: Vec<String> = self
            .spec
            .parameters
            .iter()
            .map(|p| p.name.clone())
            .collect();
        if let Some(opt) = &self.spec.optimize {
            out.extend(opt.parameters.iter().map(|p| p.name.clone()));
        }
        for n in design::book_names(&self.spec) {
            if !out.contains(&n) {
                out.push(n);
            }
        }
        out
    }

    /// The parameter values set so far by `set_params`, as a dict.
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in &self.params {
            d.set_item(k, v)?;
        }
        Ok(d)
    }

    /// A copy of this design that has the parameter values `values` (`{name: value}` in the
    /// book's notation: `bellyDx`, `rimTz`, `a`, …) applied to the design as read, each checked
    /// by the library against the design's own declarations: a `[[parameters]]` entry within
    /// its `min`/`max`, an `[optimize]` parameter within its bounds; other names in the book's
    /// notation have no bounds (a dilation must not be 0, `a` must stay positive).
    fn with_params(&self, values: &Bound<'_, PyDict>) -> PyResult<Design> {
        let mut params = self.params.clone();
        for (k, v) in values.iter() {
            let name: String = k
                .extract()
                .map_err(|_| err("params: the keys must be parameter names (str)"))?;
            let value: f64 = v
                .extract()
                .map_err(|_| err(format!("params['{name}']: must be a number")))?;
            if !value.is_finite() {
                return Err(err(format!(
                    "params['{name}']: must be finite (got {value})"
                )));
            }
            params.retain(|(n, _)| n != &name);
            params.push((name, value));
        }
        let spec = apply_params(&self.spec, &params)?;
        Ok(Design {
            file: self.file.clone(),
            text: self.text.clone(),
            spec: spec.unwrap_or_else(|| self.spec.clone()),
            params,
            solved: None,
        })
    }

    /// Solves the design (with the GIL released); later calls reuse the solution.
    fn solve(&mut self, py: Python<'_>) -> PyResult<()> {
        self.solved(py).map(|_| ())
    }

    /// Whether the design has been solved.
    #[getter]
    fn is_solved(&self) -> bool {
        self.solved.is_some()
    }

    /// The grid `(nu, nv)` the CLI would use for these arguments.
    #[pyo3(signature = (nu = None, nv = None))]
    fn grid_size(&self, nu: Option<usize>, nv: Option<usize>) -> PyResult<(usize, usize)> {
        self.grid(nu, nv)
    }

    /// Full-precision samples of every surface on an `nu × nv` grid: the rows of the CLI's CSV.
    /// Returns a dict of `vertices (n, 3) f64`, `normals (n, 3) f64`, `uv (n, 2) f64`,
    /// `patch (n,) u32`, `faces (m, 3) u32` (two triangles per grid quad, indices into the
    /// concatenated vertices), `shape (k, 2)` (each surface's `nu, nv`).
    #[pyo3(signature = (nu = None, nv = None))]
    fn tessellate<'py>(
        &mut self,
        py: Python<'py>,
        nu: Option<usize>,
        nv: Option<usize>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (nu, nv) = self.grid(nu, nv)?;
        let solved = self.solved(py)?;
        self.refuse_trims(&solved, "tessellate")?;
        let flat = py
            .detach(|| solved.samples(nu, nv).map(Flat::of))
            .map_err(|e| self.located(&e))?;
        let Flat {
            vertices,
            normals,
            uv,
            patch,
            faces,
            shape,
        } = flat;
        let d = PyDict::new(py);
        d.set_item("vertices", array2(py, vertices, 3))?;
        d.set_item("normals", array2(py, normals, 3))?;
        d.set_item("uv", array2(py, uv, 2))?;
        d.set_item("patch", array1(py, patch))?;
        d.set_item("faces", array2(py, faces, 3))?;
        d.set_item("shape", array2(py, shape, 2))?;
        Ok(d)
    }

    /// The mesh that the CLI writes (OBJ, STL, PLY, glTF): the grids in f32, welded at poles,
    /// seams and shared edges (`separate_patches`: each surface on its own), trimmed designs
    /// re-meshed around their holes. A dict of `vertices (n, 3) f32`, `normals (n, 3) f32`,
    /// `uv (n, 2) f32` (empty when absent), `faces (m, 3) u32`, `parts` (list of
    /// `(name, first_face, end_face)`).
    #[pyo3(signature = (nu = None, nv = None, separate_patches = false))]
    fn mesh<'py>(
        &mut self,
        py: Python<'py>,
        nu: Option<usize>,
        nv: Option<usize>,
        separate_patches: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (nu, nv) = self.grid(nu, nv)?;
        let solved = self.solved(py)?;
        let export = Export {
            separate_patches,
            ..Export::default()
        };
        let m = py
            .detach(|| {
                if solved.trims.is_empty() {
                    solved.meshes(nu, nv).map(|g| solved.weld(&g, &export))
                } else {
                    solved.tri_mesh(nu, nv)
                }
            })
            .map_err(|e| self.located(&e))?;
        let d = PyDict::new(py);
        d.set_item("vertices", array2(py, m.positions.concat(), 3))?;
        d.set_item("normals", array2(py, m.normals.concat(), 3))?;
        d.set_item("uv", array2(py, m.uv.concat(), 2))?;
        d.set_item("faces", array2(py, m.triangles.concat(), 3))?;
        let parts: Vec<(String, usize, usize)> = m
            .parts
            .iter()
            .map(|p| (p.name.clone(), p.triangles.start, p.triangles.end))
            .collect();
        d.set_item("parts", parts)?;
        Ok(d)
    }

    /// `X` and its partial derivatives at the points `(u, v)` of one surface: a dict of `x, xu,
    /// xv, xuu, xuv, xvv`, each shaped like `u` and `v` broadcast together (NumPy's rules:
    /// scalars, lists, arrays of any shape) with a trailing 3. `patch` (index or name) is
    /// required when the design has several surfaces. A parameter outside the surface's domain
    /// raises, unless `clamp=True` moves it to the nearest end; a periodic one is wrapped.
    #[pyo3(signature = (u, v, patch = None, clamp = false))]
    fn evaluate<'py>(
        &mut self,
        py: Python<'py>,
        u: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        patch: Option<&Bound<'py, PyAny>>,
        clamp: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (solved, k) = self.surface_of(py, patch)?;
        let s = solved.surfaces[k].surface();
        let grid = Broadcast::new(py, u, v)?;
        let (u, v) = grid.in_domain(s, &solved.surfaces[k].name, clamp)?;
        let ps: Vec<_> = py.detach(|| u.iter().zip(&v).map(|(&a, &b)| s.partials(a, b)).collect());
        let d = PyDict::new(py);
        let pick = |f: fn(&pdeshape::surface::Partials) -> pdeshape::Vec3| {
            grid.shaped3(
                py,
                ps.iter().map(|p| {
                    let x = f(p);
                    [x.x, x.y, x.z]
                }),
            )
        };
        d.set_item("x", pick(|p| p.x)?)?;
        d.set_item("xu", pick(|p| p.xu)?)?;
        d.set_item("xv", pick(|p| p.xv)?)?;
        d.set_item("xuu", pick(|p| p.xuu)?)?;
        d.set_item("xuv", pick(|p| p.xuv)?)?;
        d.set_item("xvv", pick(|p| p.xvv)?)?;
        Ok(d)
    }

    /// Curvatures at the points `(u, v)` of one surface (with respect to its normal `X_u ×
    /// X_v`): a dict of `gauss, mean, k1, k2` (each shaped like `u` and `v` broadcast together,
    /// NaN where the parametrisation is degenerate) and `normal` (that shape with a trailing
    /// 3). `patch` and `clamp` as in [`Design::evaluate`].
    #[pyo3(signature = (u, v, patch = None, clamp = false))]
    fn curvature<'py>(
        &mut self,
        py: Python<'py>,
        u: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
        patch: Option<&Bound<'py, PyAny>>,
        clamp: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (solved, k) = self.surface_of(py, patch)?;
        let s = solved.surfaces[k].surface();
        let grid = Broadcast::new(py, u, v)?;
        let (u, v) = grid.in_domain(s, &solved.surfaces[k].name, clamp)?;
        let cs: Vec<_> = py.detach(|| {
            u.iter()
                .zip(&v)
                .map(|(&a, &b)| analysis::curvature(&s.partials(a, b)))
                .collect()
        });
        let field = |f: fn(&analysis::Curvature) -> f64| {
            grid.shaped(
                py,
                cs.iter().map(|c| c.as_ref().map_or(f64::NAN, f)).collect(),
            )
        };
        let d = PyDict::new(py);
        d.set_item("gauss", field(|c| c.gauss)?)?;
        d.set_item("mean", field(|c| c.mean)?)?;
        d.set_item("k1", field(|c| c.k1)?)?;
        d.set_item("k2", field(|c| c.k2)?)?;
        d.set_item(
            "normal",
            grid.shaped3(
                py,
                cs.iter().map(|c| {
                    c.as_ref()
                        .map_or([f64::NAN; 3], |c| [c.normal.x, c.normal.y, c.normal.z])
                }),
            )?,
        )?;
        Ok(d)
    }

    /// The spine `A₀(u)` (or its `order`-th u-derivative) of a PDE patch at the values `u` (a
    /// number, a list or an array of any shape): that shape with a trailing 3. `patch` and
    /// `clamp` as in [`Design::evaluate`].
    #[pyo3(signature = (u, patch = None, order = 0, clamp = false))]
    fn spine<'py>(
        &mut self,
        py: Python<'py>,
        u: &Bound<'py, PyAny>,
        patch: Option<&Bound<'py, PyAny>>,
        order: usize,
        clamp: bool,
    ) -> PyResult<Py<PyAny>> {
        let (solved, k) = self.surface_of(py, patch)?;
        let s = &solved.surfaces[k];
        let spine = s.surface().as_spine().ok_or_else(|| {
            err(format!(
                "patch: the surface '{}' ({}) has no spine",
                s.name,
                s.kind.word()
            ))
        })?;
        let zero = 0.0f64.into_pyobject(py)?;
        let grid = Broadcast::new(py, u, zero.as_any())?;
        let (u, _) = grid.in_domain(s.surface(), &s.name, clamp)?;
        grid.shaped3(
            py,
            u.iter().map(|&t| {
                let p = spine.spine(t, order);
                [p.x, p.y, p.z]
            }),
        )
    }

    /// What `pdeshape check --json` reports, from the library's diagnostics: `ok`, `design`,
    /// `title`, `surfaces` (kind, operator, modes, condition errors), shared `edges` (G0, G1),
    /// `attachments`, `parameters`, `warnings`, the text `report`, and `verdict` (`"ok"`, or
    /// `"attention"` when there is a warning or a shared edge is not G0 or not G1).
    fn check<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let solved = self.solved(py)?;
        let spec = &self.spec;
        let file = self.file.clone();
        let v = py.detach(|| {
            let d = diagnostics::diagnose(spec, &solved);
            diagnostics::check_json(&file, spec, &solved, &d)
        });
        py.import("json")?.call_method1("loads", (v.to_string(),))
    }

    /// Area, enclosed volume, curvature integrals and energies, per patch and in total: the
    /// dict of `pdeshape analyze --json` (same keys, same numbers). `tolerance`: the adaptive
    /// quadrature's relative tolerance (default 1e-11, as the CLI's). `quadrature = (qu, qv)`:
    /// instead one fixed level of `qu` Gauss nodes in `u` (a multiple of 8) and `qv` nodes in `v`
    /// per patch, as the optimiser measures designs (much cheaper; for sweeps).
    #[pyo3(signature = (tolerance = None, quadrature = None))]
    fn analysis<'py>(
        &mut self,
        py: Python<'py>,
        tolerance: Option<f64>,
        quadrature: Option<(usize, usize)>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let q = match (tolerance, quadrature) {
            (Some(_), Some(_)) => {
                return Err(err(
                    "tolerance, quadrature: give one of them (adaptive or fixed quadrature)",
                ))
            }
            (None, Some((qu, qv))) if (1..=4096).contains(&qu) && (1..=4096).contains(&qv) => {
                Quadrature::fixed(qu, qv)
            }
            (None, Some((qu, qv))) => {
                return Err(err(format!(
                    "quadrature: both node counts must lie in 1..=4096 (got ({qu}, {qv}))"
                )))
            }
            (None, None) => Quadrature::default(),
            (Some(t), None) if t > 0.0 && t.is_finite() && t < 1.0 => Quadrature {
                tolerance: t,
                ..Quadrature::default()
            },
            (Some(t), None) => {
                return Err(err(format!(
                    "tolerance: must be positive and below 1 (got {t})"
                )))
            }
        };
        let solved = self.solved(py)?;
        let di = py
            .detach(|| integrate_design(&solved, &q))
            .map_err(|e| err(e.to_string()))?;
        let patches = PyList::empty(py);
        for (k, i) in di.patches.iter().enumerate() {
            let a = &di.analyses[k];
            let m = integrals_dict(py, i)?;
            m.set_item("name", &di.names[k])?;
            m.set_item("orientation", di.orientation[k])?;
            let s = di.orientation[k];
            let (h0, h1) = (a.mean_range.0 * s, a.mean_range.1 * s);
            m.set_item("gauss_min", a.gauss_range.0)?;
            m.set_item("gauss_max", a.gauss_range.1)?;
            m.set_item("mean_min", h0.min(h1))?;
            m.set_item("mean_max", h0.max(h1))?;
            m.set_item("quadrature_error", a.error)?;
            m.set_item("converged", a.converged)?;
            m.set_item("nodes", vec![a.u_nodes, a.v_nodes])?;
            patches.append(m)?;
        }
        let total = integrals_dict(py, &di.total)?;
        total.set_item("reduced_volume", di.total.reduced_volume())?;
        total.set_item("equivalent_radius", di.total.equivalent_radius())?;
        let caps = PyList::empty(py);
        for c in &di.caps {
            let m = PyDict::new(py);
            m.set_item("patch", &di.names[c.patch])?;
            m.set_item("u", c.u)?;
            m.set_item("volume", c.volume)?;
            m.set_item("area", c.area)?;
            m.set_item("planarity", c.planarity)?;
            caps.append(m)?;
        }
        let d = PyDict::new(py);
        d.set_item("title", &solved.title)?;
        d.set_item("closed", di.closed)?;
        d.set_item("patches", patches)?;
        d.set_item("total", total)?;
        d.set_item("caps", caps)?;
        d.set_item("quadrature_error", di.error)?;
        Ok(d)
    }

    /// Writes the design as the CLI's `surface` does: `format` (obj, stl, ply, glb, csv, or
    /// step/stp and igs/iges; by default the path's extension). Meshes and samples take the
    /// grid, `scale`, `up` ("z" or "y"), `separate_patches`; STEP and IGES (every surface as a
    /// B-spline) take `tolerance` (default 1e-4 of the design's size), `units` (default the
    /// design's) and `timestamp` (Unix seconds of the header's date, default `SOURCE_DATE_EPOCH`, else now). The file is
    /// written whole or not at all.
    #[pyo3(signature = (path, nu = None, nv = None, format = None, scale = 1.0, up = None,
                        separate_patches = false, tolerance = None, units = None,
                        timestamp = None))]
    // One Rust argument per Python keyword argument: the keywords are the Python API.
    #[allow(clippy::too_many_arguments)]
    fn write(
        &mut self,
        py: Python<'_>,
        path: PathBuf,
        nu: Option<usize>,
        nv: Option<usize>,
        format: Option<&str>,
        scale: f64,
        up: Option<&str>,
        separate_patches: bool,
        tolerance: Option<f64>,
        units: Option<&str>,
        timestamp: Option<u64>,
    ) -> PyResult<()> {
        let cad_format = match format {
            Some(f) => OutputFormat::from_name(f),
            None => OutputFormat::from_path(&path).ok(),
        }
        .filter(|f| f.is_cad());
        if let Some(cad_format) = cad_format {
            let what = "STEP or IGES output (exact B-spline surfaces)";
            for (given, name) in [
                (nu.is_some(), "nu"),
                (nv.is_some(), "nv"),
                (scale != 1.0, "scale"),
                (up.is_some(), "up"),
                (separate_patches, "separate_patches"),
            ] {
                if given {
                    return Err(err(format!("{name}: does not apply to {what}")));
                }
            }
            return self.write_cad(py, &path, cad_format, tolerance, units, timestamp);
        }
        let what = "mesh and sample output (only STEP and IGES)";
        for (given, name) in [
            (tolerance.is_some(), "tolerance"),
            (units.is_some(), "units"),
            (timestamp.is_some(), "timestamp"),
        ] {
            if given {
                return Err(err(format!("{name}: does not apply to {what}")));
            }
        }
        let format = match format {
            Some(f) => parse_format(f, "format")?,
            None => Format::from_path(&path)
                .map_err(|e| err(format!("path {}: {}", path.display(), message_of(&e))))?,
        };
        if !(scale.is_finite() && scale > 0.0) {
            return Err(err(format!(
                "scale: must be finite and positive (got {scale})"
            )));
        }
        let up = match (format, up) {
            (Format::Glb, Some("z")) => {
                return Err(err(
                    "up z: glTF is +Y up by definition (the design's +Z is turned to +Y); up \
                     applies to obj, stl and ply",
                ))
            }
            (_, None | Some("z")) => Up::Z,
            (_, Some("y")) => Up::Y,
            (_, Some(other)) => {
                return Err(err(format!("up: must be \"z\" or \"y\" (got {other:?})")))
            }
        };
        let export = Export {
            separate_patches,
            scale,
            up,
        };
        let (nu, nv) = self.grid(nu, nv)?;
        let solved = self.solved(py)?;
        if solved.surfaces.is_empty() {
            return Err(self.located(&Error::no_surface()));
        }
        let mut bytes = Vec::new();
        py.detach(|| solved.write_with(format, nu, nv, &export, &mut bytes))
            .map_err(|e| {
                if e.place().is_empty() {
                    err(format!("path {}: {e}", path.display()))
                } else {
                    self.located(&e)
                }
            })?;
        write_atomically(&path, &bytes)
    }

    /// Whether the design has a `[dynamic]` section (a curve run by `dynamic()`).
    #[getter]
    fn has_dynamic(&self) -> bool {
        self.spec.dynamic.is_some()
    }

    /// Runs the design's `[dynamic]` section as `pdeshape curve` does (with the GIL released) and
    /// returns a dict: `kind` ("run" or "interpolate"), `dim` (1 to 3 coordinates), `u (J+1,)`
    /// and `nodes (J+1, dim)` (the final curve: the rows of `curve -o`), `frames` (a dict of
    /// `step (F,) u64`, `t (F,) f64`, `nodes (F, J+1, dim)`: the rows of `curve --frames`, every
    /// `frames_every`-th level; empty with `frames=False`), `bending_energy`, and for a run
    /// `t_end`, `steps`; for an interpolation `points (P, dim)`, `params (P,)` (the nodes'
    /// `u` of the points), `distances (P,)`, `steps`, `updates`.
    #[pyo3(signature = (frames = true))]
    fn dynamic<'py>(&self, py: Python<'py>, frames: bool) -> PyResult<Bound<'py, PyDict>> {
        let Some(section) = self.spec.dynamic.as_ref() else {
            return Err(err(format!(
                "{}: the design has no [dynamic] section: dynamic() runs dynamic curves (for the \
                 surface of this design use tessellate() or write())",
                self.file
            )));
        };
        let (out, frames) = py
            .detach(|| run_dynamic(section, frames))
            .map_err(|e| self.located(&e))?;
        let dim = out.dim;
        let jn1 = out.nodes.len();
        let d = PyDict::new(py);
        d.set_item("dim", dim)?;
        d.set_item("u", array1(py, node_parameters(jn1)))?;
        d.set_item("nodes", points_array(py, &out.nodes, dim))?;
        let fd = PyDict::new(py);
        fd.set_item(
            "step",
            array1(py, frames.iter().map(|f| f.step as u64).collect()),
        )?;
        fd.set_item("t", array1(py, frames.iter().map(|f| f.time).collect()))?;
        let width = frames.first().map_or(jn1, |f| f.nodes.len());
        let flat: Vec<f64> = frames
            .iter()
            .flat_map(|f| f.nodes.iter().flat_map(|p| (0..dim).map(|c| p[c])))
            .collect();
        let nodes3 = Array3::from_shape_vec((frames.len(), width, dim), flat)
            .map_err(|e| err(format!("dynamic: frames of unequal length: {e}")))?;
        fd.set_item("nodes", nodes3.into_pyarray(py))?;
        d.set_item("frames", fd)?;
        match &out.kind {
            OutcomeKind::Run(r) => {
                d.set_item("kind", "run")?;
                d.set_item("t_end", r.t_end)?;
                d.set_item("steps", r.steps)?;
            }
            OutcomeKind::Interpolate(r) => {
                d.set_item("kind", "interpolate")?;
                d.set_item("points", points_array(py, &r.points, dim))?;
                d.set_item("params", array1(py, r.params.clone()))?;
                d.set_item("distances", array1(py, r.distances.clone()))?;
                d.set_item("steps", r.steps)?;
                d.set_item("updates", r.updates)?;
            }
        }
        d.set_item("bending_energy", out.bending_energy())?;
        Ok(d)
    }

    /// Searches the design's `[optimize]` parameters as `pdeshape optimize` does, through the
    /// same library call (`Problem::plan`, `Problem::run_search`): `method` "anneal"
    /// (simulated annealing and a Nelder–Mead polish; `evaluations` all chains together,
    /// `chains`, `polish`) or "gradient" (SLSQP on the exact sensitivities; `evaluations` per
    /// start, `starts`) or "hybrid" (annealing, then SLSQP from each chain's best point, the
    /// better result; the annealing options); options not given keep the file's (annealing) or the library's
    /// defaults; `seed` seeds both. Returns a dict of `x` (the best parameter values by name),
    /// `value` (objective + penalty), `objective`, `penalty`, `feasible`, `method`,
    /// `evaluations`, `solves`, `tangent_solves`, `start_value`, `measures` (the shell ones only where the problem
    /// has them), and `gradient` (None for annealing;
    /// else `evaluations`, `solves`, `converged`, `best_start`, `starts` — per start `x`,
    /// `best`, `status`, `converged`, `evaluations` — and `kkt`: `stationarity`,
    /// `dual_infeasibility`, `primal_infeasibility`, `active_constraints`, `active_bounds`).
    #[pyo3(signature = (seed = None, evaluations = None, chains = None, polish = None, method = "anneal", starts = None))]
    #[allow(clippy::too_many_arguments)]
    fn optimize<'py>(
        &self,
        py: Python<'py>,
        seed: Option<i128>,
        evaluations: Option<i64>,
        chains: Option<i64>,
        polish: Option<i64>,
        method: &str,
        starts: Option<i64>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let count = |name: &str, v: Option<i64>| -> PyResult<Option<usize>> {
            v.map(|n| {
                usize::try_from(n)
                    .map_err(|_| err(format!("{name}: must be a non-negative integer (got {n})")))
            })
            .transpose()
        };
        let seed = seed
            .map(|s| {
                u64::try_from(s)
                    .map_err(|_| err(format!("seed: must be an integer in 0..=2**64-1 (got {s})")))
            })
            .transpose()?;
        let argument = |e: &Error| err(format!("{}: {}", e.place(), message_of(e)));
        let method = pdeshape::optimize::SearchMethod::parse(method).map_err(|e| argument(&e))?;
        let request = pdeshape::optimize::SearchRequest {
            method,
            seed,
            evaluations: count("evaluations", evaluations)?,
            chains: count("chains", chains)?,
            polish: count("polish", polish)?,
            starts: count("starts", starts)?,
        };
        if self.spec.optimize.is_none() {
            return Err(self
                .located(&Error::invalid("the design has no [optimize] section").at("optimize")));
        }
        let mut problem = Problem::new(&self.spec).map_err(|e| self.located(&e))?;
        let plan = problem.plan(&request).map_err(|e| {
            if e.place() == "optimize" {
                self.located(&e)
            } else {
                argument(&e)
            }
        })?;
        let outcome = py
            .detach(|| problem.run_search(&plan, &|_, _| {}))
            .map_err(|e| self.located(&e))?;
        let (x, ev) = &outcome.best;
        let xs = PyDict::new(py);
        for (p, v) in problem.parameters.list.iter().zip(x) {
            xs.set_item(&p.name, v)?;
        }
        // The shell measures only where they have values (NaN is not equal to itself, and
        // results are compared as dicts).
        let measures = PyDict::new(py);
        for (j, (name, value)) in pdeshape::optimize::VARIABLES
            .iter()
            .zip(&ev.variables)
            .enumerate()
        {
            if j < 11 || !value.is_nan() {
                measures.set_item(name, value)?;
            }
        }
        let names: Vec<&str> = problem.parameters.names();
        let by_name = |x: &[f64]| -> PyResult<Bound<'py, PyDict>> {
            let d = PyDict::new(py);
            for (n, v) in names.iter().zip(x) {
                d.set_item(n, v)?;
            }
            Ok(d)
        };
        let d = PyDict::new(py);
        d.set_item("x", xs)?;
        d.set_item("value", ev.total())?;
        d.set_item("objective", ev.objective)?;
        d.set_item("penalty", ev.penalty)?;
        d.set_item("feasible", ev.feasible)?;
        d.set_item("method", plan.method.name())?;
        d.set_item("evaluations", outcome.search.evaluations)?;
        d.set_item("solves", outcome.solves)?;
        d.set_item("tangent_solves", outcome.tangent_solves)?;
        d.set_item(
            "start_value",
            outcome.start.1.as_ref().map_or(f64::NAN, |e| e.total()),
        )?;
        d.set_item("measures", measures)?;
        match &outcome.gradient {
            None => d.set_item("gradient", py.None())?,
            Some(g) => {
                let gd = PyDict::new(py);
                gd.set_item("evaluations", g.evaluations)?;
                gd.set_item("solves", g.solves)?;
                gd.set_item("converged", g.converged)?;
                gd.set_item("best_start", g.best_start)?;
                let starts = PyList::empty(py);
                for s in &g.starts {
                    let sd = PyDict::new(py);
                    sd.set_item("x", by_name(&s.x)?)?;
                    sd.set_item("best", s.best)?;
                    sd.set_item("status", s.status)?;
                    sd.set_item("converged", s.converged)?;
                    sd.set_item("evaluations", s.evaluations)?;
                    starts.append(sd)?;
                }
                gd.set_item("starts", starts)?;
                let k = PyDict::new(py);
                k.set_item("stationarity", g.kkt.stationarity)?;
                k.set_item("dual_infeasibility", g.kkt.dual_infeasibility)?;
                k.set_item("primal_infeasibility", g.kkt.primal_infeasibility)?;
                k.set_item("active_constraints", g.kkt.active_constraints)?;
                k.set_item("active_bounds", g.kkt.active_bounds)?;
                gd.set_item("kkt", k)?;
                d.set_item("gradient", gd)?;
            }
        }
        Ok(d)
    }

    /// The design's `[optimize]` problem evaluated at one point, as the optimiser evaluates it
    /// (one solve, the integrals at the problem's fixed quadrature, the objective and penalty
    /// formulas): the point is `values` (`{name: value}` of `[optimize]` parameters, each
    /// within its bounds), else the values `with_params` set, else the initial values. The
    /// design is the one as read with the other values `with_params` set. Returns a dict:
    /// `x` (every parameter's value), `value` (objective + penalty, what the search minimises),
    /// `objective`, `penalty`, `feasible`, `measures` (the formulas' variables by name: `area`,
    /// `volume`, `mean`, …; NaN for shell measures no formula uses) and `constraints` (per
    /// constraint: `expr`, `value` of its formula, `equal`/`min`/`max`, `weight`).
    #[pyo3(signature = (values = None))]
    fn evaluate_problem<'py>(
        &self,
        py: Python<'py>,
        values: Option<&Bound<'py, PyDict>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let (problem, x) = self.problem_at(values)?;
        let ev = py
            .detach(|| problem.evaluate(&x))
            .map_err(|e| self.located(&e))?;
        let v = &ev.variables;
        let totals = Integrals {
            area: v[0],
            volume: v[1],
            mean: v[2],
            mean_sq: v[3],
            gauss: v[4],
        };
        let shell = problem.shell_setup().map(|_| [v[11], v[12], v[13]]);
        let constraints = PyList::empty(py);
        let opt = problem.base.optimize.as_ref();
        for c in opt.map(|o| &o.constraints[..]).unwrap_or(&[]) {
            // The constraint's formula as the objective of a problem of its own, evaluated on
            // the same measures (no second solve).
            let mut spec = problem.base.clone();
            if let Some(o) = spec.optimize.as_mut() {
                o.objective = c.expr.clone();
                o.constraints.clear();
            }
            let one = py
                .detach(|| Problem::new(&spec))
                .map_err(|e| self.located(&e))?;
            let d = PyDict::new(py);
            d.set_item("expr", &c.expr)?;
            d.set_item("value", one.evaluate_with(&totals, shell).objective)?;
            d.set_item("equal", c.equal)?;
            d.set_item("min", c.min)?;
            d.set_item("max", c.max)?;
            d.set_item("weight", c.weight)?;
            constraints.append(d)?;
        }
        let xs = PyDict::new(py);
        for (p, value) in problem.parameters.list.iter().zip(&x) {
            xs.set_item(&p.name, value)?;
        }
        let measures = PyDict::new(py);
        for (name, value) in pdeshape::optimize::VARIABLES.iter().zip(v) {
            measures.set_item(name, value)?;
        }
        let d = PyDict::new(py);
        d.set_item("x", xs)?;
        d.set_item("value", ev.total())?;
        d.set_item("objective", ev.objective)?;
        d.set_item("penalty", ev.penalty)?;
        d.set_item("feasible", ev.feasible)?;
        d.set_item("measures", measures)?;
        d.set_item("constraints", constraints)?;
        Ok(d)
    }

    /// The measures of the design and their derivatives with respect to parameters, from the
    /// library's sensitivities (`optimize::sensitivities`, `Problem::gradient`). `names`: the
    /// parameters (`[[parameters]]` entries or names in the book's notation, a book name taken
    /// from its neutral value on the design as it is); by default the `[optimize]` parameters at
    /// the point `evaluate_problem` uses (then the objective and the constraints are
    /// differentiated too), else the `[[parameters]]` entries. `quadrature = (qu, qv)`: the
    /// fixed rule of the integrals (default the `[optimize]` one, else 24 × 48). Returns a dict:
    /// `names`, `x` (the parameters' values), `measures` (the formulas' variables by name),
    /// `d_measures` (`{measure: array (k,)}`, ∂measure/∂parameter), `errors` (the same shape:
    /// the library's estimate of each derivative's absolute error), `methods` (per parameter,
    /// `linear`, `rotation`, `exact` (the smoothing parameter `a`) — exact up to rounding — or
    /// `richardson`, extrapolated differences),
    /// `exact` (per parameter), `solves`; and for the `[optimize]` problem `objective`,
    /// `d_objective`, `penalty`, `d_penalty`, `value`, `d_value` (objective + penalty) and
    /// `constraints` (per constraint: `expr`, `value`, `gradient`, `equal`, `min`, `max`).
    #[pyo3(signature = (names = None, quadrature = None))]
    fn gradient<'py>(
        &self,
        py: Python<'py>,
        names: Option<Vec<String>>,
        quadrature: Option<(usize, usize)>,
    ) -> PyResult<Bound<'py, PyDict>> {
        // The limits of `[optimize]`'s quadrature_u and quadrature_v.
        if let Some((qu, qv)) = quadrature {
            if !((2..=4096).contains(&qu) && (3..=4096).contains(&qv)) {
                return Err(err(format!(
                    "quadrature: qu must lie in 2..=4096 and qv in 3..=4096 (got ({qu}, {qv}))"
                )));
            }
        }
        let d = PyDict::new(py);
        let s = match (&names, &self.spec.optimize) {
            (None, Some(_)) => {
                let (mut problem, x) = self.problem_at(None)?;
                if let Some(q) = quadrature {
                    problem.quadrature = q;
                }
                let g = py
                    .detach(|| problem.gradient(&x))
                    .map_err(|e| self.located(&e))?;
                let value: Vec<f64> = g
                    .d_objective
                    .iter()
                    .zip(&g.d_penalty)
                    .map(|(a, b)| a + b)
                    .collect();
                d.set_item("objective", g.objective)?;
                d.set_item("d_objective", array1(py, g.d_objective.clone()))?;
                d.set_item("penalty", g.penalty)?;
                d.set_item("d_penalty", array1(py, g.d_penalty.clone()))?;
                d.set_item("value", g.objective + g.penalty)?;
                d.set_item("d_value", array1(py, value))?;
                let constraints = PyList::empty(py);
                for c in &g.constraints {
                    let e = PyDict::new(py);
                    e.set_item("expr", &c.text)?;
                    e.set_item("value", c.value)?;
                    e.set_item("gradient", array1(py, c.gradient.clone()))?;
                    e.set_item("equal", c.equal)?;
                    e.set_item("min", c.min)?;
                    e.set_item("max", c.max)?;
                    constraints.append(e)?;
                }
                d.set_item("constraints", constraints)?;
                g.sensitivities
            }
            _ => {
                let names = match names {
                    Some(n) => n,
                    None if !self.spec.parameters.is_empty() => self
                        .spec
                        .parameters
                        .iter()
                        .map(|p| p.name.clone())
                        .collect(),
                    None => {
                        return Err(err(
                            "names: the design declares no parameters ([[parameters]] or \
                             [optimize]); name them, e.g. ['a', '<curve>Tx']",
                        ))
                    }
                };
                let (qu, qv) = quadrature.unwrap_or((24, 48));
                let spec = &self.spec;
                py.detach(|| pdeshape::optimize::sensitivities(spec, &names, qu, qv))
                    .map_err(|e| {
                        if e.place().starts_with("names") {
                            err(format!("{}: {}", e.place(), message_of(&e)))
                        } else {
                            self.located(&e)
                        }
                    })?
            }
        };
        let vars = pdeshape::optimize::VARIABLES;
        let measures = PyDict::new(py);
        let d_measures = PyDict::new(py);
        let errors = PyDict::new(py);
        for (j, name) in vars.iter().enumerate() {
            measures.set_item(name, s.values[j])?;
            d_measures.set_item(name, array1(py, s.d_values.iter().map(|r| r[j]).collect()))?;
            errors.set_item(name, array1(py, s.errors.iter().map(|r| r[j]).collect()))?;
        }
        let x = PyDict::new(py);
        for (n, v) in s.names.iter().zip(&s.parameters) {
            x.set_item(n, v)?;
        }
        d.set_item("names", &s.names)?;
        d.set_item("x", x)?;
        d.set_item("measures", measures)?;
        d.set_item("d_measures", d_measures)?;
        d.set_item("errors", errors)?;
        let methods: Vec<&str> = s.methods.iter().map(|m| m.label()).collect();
        let exact: Vec<bool> = s.methods.iter().map(|m| m.is_exact()).collect();
        d.set_item("methods", methods)?;
        d.set_item("exact", exact)?;
        d.set_item("solves", s.solves)?;
        d.set_item("tangent_solves", s.tangent_solves)?;
        d.set_item("batch", s.batch)?;
        Ok(d)
    }

    /// For the benchmark of the Python call's overhead: the seconds of each of `repeats` calls
    /// of the library's `SolvedDesign::samples(nu, nv)` alone (`flat = False`) or with the flat
    /// arrays `tessellate` returns assembled (`flat = True`), timed in Rust: `tessellate`
    /// minus these is the cost of the Python call and the NumPy arrays.
    #[pyo3(signature = (nu, nv, repeats, flat = false))]
    fn _rust_samples_seconds(
        &mut self,
        py: Python<'_>,
        nu: usize,
        nv: usize,
        repeats: usize,
        flat: bool,
    ) -> PyResult<Vec<f64>> {
        let (nu, nv) = self.grid(Some(nu), Some(nv))?;
        let solved = self.solved(py)?;
        let mut out = Vec::with_capacity(repeats);
        for _ in 0..repeats {
            let t = std::time::Instant::now();
            let s = py.detach(|| {
                solved.samples(nu, nv).map(|s| {
                    if flat {
                        (Some(Flat::of(s)), None)
                    } else {
                        (None, Some(s))
                    }
                })
            });
            let s = s.map_err(|e| self.located(&e))?;
            out.push(t.elapsed().as_secs_f64());
            drop(s);
        }
        Ok(out)
    }

    fn __repr__(&self) -> String {
        format!(
            "Design({:?}{}{})",
            self.file,
            self.spec
                .title
                .as_deref()
                .map(|t| format!(", title={t:?}"))
                .unwrap_or_default(),
            if self.params.is_empty() {
                String::new()
            } else {
                format!(", params={:?}", self.params)
            }
        )
    }
}

impl Design {
    /// The `[optimize]` problem of the design as read with the values `with_params` set for
    /// names other than its parameters, and the point of [`Design::evaluate_problem`].
    fn problem_at(&self, values: Option<&Bound<'_, PyDict>>) -> PyResult<(Problem, Vec<f64>)> {
        let Some(opt) = self.spec.optimize.as_ref() else {
            return Err(self
                .located(&Error::invalid("the design has no [optimize] section").at("optimize")));
        };
        let names: Vec<&str> = opt.parameters.iter().map(|p| p.name.as_str()).collect();
        let original = Design::parse(self.file.clone(), self.text.clone())?.spec;
        let others: Vec<(String, f64)> = self
            .params
            .iter()
            .filter(|(n, _)| !names.contains(&n.as_str()))
            .cloned()
            .collect();
        let base = apply_params(&original, &others)?.unwrap_or(original);
        let problem = Problem::new(&base).map_err(|e| self.located(&e))?;
        let list = &problem.parameters.list;
        let mut x = problem.parameters.initial();
        for (k, p) in list.iter().enumerate() {
            if let Some((_, v)) = self.params.iter().find(|(n, _)| n == &p.name) {
                x[k] = *v;
            }
        }
        for (key, value) in values.into_iter().flat_map(|v| v.iter()) {
            let name: String = key
                .extract()
                .map_err(|_| err("values: the keys must be parameter names (str)"))?;
            let value: f64 = value
                .extract()
                .map_err(|_| err(format!("values['{name}']: must be a number")))?;
            let Some(k) = list.iter().position(|p| p.name == name) else {
                return Err(err(format!(
                    "values['{name}']: not a parameter of [optimize] (they are {})",
                    names.join(", ")
                )));
            };
            let p = &list[k];
            if !(p.min..=p.max).contains(&value) {
                return Err(err(format!(
                    "values['{name}']: {value} lies outside the bounds [{}, {}] of [optimize]",
                    p.min, p.max
                )));
            }
            x[k] = value;
        }
        Ok((problem, x))
    }

    fn surface_of(
        &mut self,
        py: Python<'_>,
        patch: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<(Arc<SolvedDesign>, usize)> {
        let solved = self.solved(py)?;
        let k = match patch {
            None if solved.surfaces.is_empty() => {
                return Err(err(format!("patch: {}", Error::no_surface())))
            }
            None if solved.surfaces.len() > 1 => {
                return Err(err(format!(
                "patch: the design has {} surfaces ({}); name one (patch=\"{}\") or give its index",
                solved.surfaces.len(),
                solved.names().join(", "),
                solved.surfaces[0].name
            )))
            }
            None => 0,
            Some(p) => Design::patch_index(&solved, p)?,
        };
        Ok((solved, k))
    }
}

/// Parameters `u` and `v` broadcast together as NumPy does (scalars, lists, arrays of any
/// shape): their values in C order and the common shape, which the results take.
struct Broadcast {
    u: Vec<f64>,
    v: Vec<f64>,
    shape: Vec<usize>,
}

impl Broadcast {
    fn new<'py>(
        py: Python<'py>,
        u: &Bound<'py, PyAny>,
        v: &Bound<'py, PyAny>,
    ) -> PyResult<Broadcast> {
        let np = py.import("numpy")?;
        let as_floats = |x: &Bound<'py, PyAny>, name: &str| -> PyResult<Bound<'py, PyAny>> {
            np.call_method1("asarray", (x,))
                .and_then(|a| a.call_method1("astype", ("float64",)))
                .map_err(|_| {
                    err(format!(
                        "{name}: must be numbers (a number, a list or an array)"
                    ))
                })
        };
        let (ua, va) = (as_floats(u, "u")?, as_floats(v, "v")?);
        let shape_of =
            |a: &Bound<'_, PyAny>| -> PyResult<Vec<usize>> { a.getattr("shape")?.extract() };
        let pair = np
            .call_method1("broadcast_arrays", (&ua, &va))
            .map_err(|_| {
                err(format!(
                    "u and v: shapes {:?} and {:?} do not broadcast together",
                    shape_of(&ua).unwrap_or_default(),
                    shape_of(&va).unwrap_or_default()
                ))
            })?;
        let (bu, bv) = (pair.get_item(0)?, pair.get_item(1)?);
        let shape = shape_of(&bu)?;
        let flat = |a: &Bound<'_, PyAny>| -> PyResult<Vec<f64>> {
            let c = np.call_method1("ascontiguousarray", (np.call_method1("ravel", (a,))?,))?;
            let c: PyReadonlyArray1<'_, f64> = c.extract()?;
            Ok(c.as_slice()?.to_vec())
        };
        Ok(Broadcast {
            u: flat(&bu)?,
            v: flat(&bv)?,
            shape,
        })
    }

    /// The parameters in the surface's domain: a periodic one wrapped, a bounded one refused
    /// outside its range (beyond rounding), or moved to its nearest end with `clamp`.
    fn in_domain(
        &self,
        s: &dyn pdeshape::Surface,
        name: &str,
        clamp: bool,
    ) -> PyResult<(Vec<f64>, Vec<f64>)> {
        let d = s.parameter_domain();
        let fit = |values: &[f64],
                   which: &str,
                   range: pdeshape::surface::Interval,
                   periodic: bool| {
            let slack = 1e-12 * range.length().max(1.0);
            values
                .iter()
                .map(|&t| {
                    if !t.is_finite() {
                        return Err(err(format!("{which}: {t} is not a number the surface takes")));
                    }
                    if periodic {
                        return Ok(range.wrap(t));
                    }
                    if t >= range.start - slack && t <= range.end + slack {
                        return Ok(range.clamp(t));
                    }
                    if clamp {
                        return Ok(range.clamp(t));
                    }
                    Err(err(format!(
                        "{which}: {t} is outside the domain [{}, {}] of '{name}' (pass clamp=True to move such values to the nearest end)",
                        range.start, range.end
                    )))
                })
                .collect::<PyResult<Vec<f64>>>()
        };
        Ok((
            fit(&self.u, "u", d.u, d.u_periodic)?,
            fit(&self.v, "v", d.v.interval(), d.v.is_periodic())?,
        ))
    }

    /// Values, one per point, as an array of the common shape.
    fn shaped(&self, py: Python<'_>, values: Vec<f64>) -> PyResult<Py<PyAny>> {
        let a = array1(py, values);
        Ok(a.bind(py)
            .call_method1("reshape", (self.shape.clone(),))?
            .unbind())
    }

    /// Vectors, one per point, as an array of the common shape with a trailing 3.
    fn shaped3(
        &self,
        py: Python<'_>,
        rows: impl ExactSizeIterator<Item = [f64; 3]>,
    ) -> PyResult<Py<PyAny>> {
        let a = vec3s(py, rows);
        let mut shape = self.shape.clone();
        shape.push(3);
        Ok(a.bind(py).call_method1("reshape", (shape,))?.unbind())
    }
}

/// The spec with the parameter values applied (`None` when there are none), checked by the
/// library against the design's own declarations ([`pdeshape::optimize::apply_values`]).
fn apply_params(base: &DesignSpec, params: &[(String, f64)]) -> PyResult<Option<DesignSpec>> {
    if params.is_empty() {
        return Ok(None);
    }
    pdeshape::optimize::apply_values(base, params)
        .map(Some)
        .map_err(|e| {
            err(format!(
                "params['{}']: {}",
                params[e.index].0,
                message_of(&e.error)
            ))
        })
}

/// Fits PDE patches to a triangle mesh as `pdeshape fit MESH -o design.toml --json r.json
/// [--tolerance T] [--sections N] [--mode M] [--best-effort]` does: `data` are the bytes of an
/// OBJ, STL, PLY, OFF or glTF file (a `.glb`, or a `.gltf` whose buffers are data URIs), `name`
/// its file name (the extension gives the format; errors name it). The units a file states
/// (glTF: metres, or the design units of pdeshape's extras) are the design's `units`.
/// The mode and its fallback, the tolerance and the measures are the library's
/// ([`fit::fit_measured`]). Returns the fitted design (its text is the `-o` file) and the
/// report of `--json` as a dict (without `timings_ms`); a fit that misses the tolerance raises
/// unless `best_effort`.
#[pyfunction]
#[pyo3(signature = (data, name, tolerance = None, sections = None, mode = "auto", best_effort = false))]
fn fit_mesh<'py>(
    py: Python<'py>,
    data: Vec<u8>,
    name: &str,
    tolerance: Option<f64>,
    sections: Option<usize>,
    mode: &str,
    best_effort: bool,
) -> PyResult<(Design, Bound<'py, PyAny>)> {
    if let Some(t) = tolerance {
        if !(t > 0.0 && t.is_finite() && t < 1.0) {
            return Err(err(format!(
                "tolerance {t}: must be a number between 0 and 1 (a fraction of the diagonal)"
            )));
        }
    }
    let mode = fit::ModeChoice::parse(mode)
        .map_err(|e| err(format!("mode '{mode}': {}", message_of(&e))))?;
    let format = Path::new(name)
        .extension()
        .and_then(|e| e.to_str())
        .and_then(fit::MeshFormat::from_extension)
        .ok_or_else(|| err(fit::MeshFormat::unknown(name)))?;
    let file_name = Path::new(name)
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    let (text, report) = py
        .detach(|| -> Result<(String, String), String> {
            let read =
                fit::InputMesh::read_report(&data, format).map_err(|e| format!("{name}: {e}"))?;
            let (mesh, notes) = read.repaired().map_err(|e| format!("{name}: {e}"))?;
            let request = fit::Request {
                mode,
                template: None,
                tolerance,
                patches: sections,
                units: read.units,
                file: read.file,
            };
            let mut fitted = fit::fit_measured(&mesh, &request).map_err(|e| match e.place() {
                "tolerance" | "sections" => e.to_string(),
                _ => format!("{name}: {e}"),
            })?;
            if let (Some(words), false) = (fitted.miss(), best_effort) {
                return Err(format!(
                    "{name}: {words} (a larger tolerance, or best_effort=True to have it anyway)"
                ));
            }
            let text = fitted
                .design_file(&file_name)
                .map_err(|e| format!("{name}: {e}"))?;
            let report = fitted.report(name, &notes);
            Ok((text, report.to_string()))
        })
        .map_err(err)?;
    let design = Design::parse(format!("<fit of {file_name}>"), text)?;
    let report = py.import("json")?.call_method1("loads", (report,))?;
    Ok((design, report))
}

/// Fills the holes of a triangle mesh with PDE patches as `pdeshape fill MESH -o OUT --design
/// D.toml` does. The mesh is `data` (the bytes of an OBJ, STL, PLY, OFF or glTF file, `name`
/// its file name, read in the units and up axis the file states, which the design carries) or
/// `positions` (n × 3) and `triangles` (m × 3, from 0). Returns a dict: `vertices` and `faces`
/// (numpy arrays: the mesh's, then the fill's), `mesh_faces` (how many faces are the mesh's),
/// `open_edges`, `holes_found`, `holes` (one dict per filled hole) and `design`
/// (the patches' design text, one `[[disk]]` table each).
#[pyfunction]
#[pyo3(signature = (data = None, name = "<mesh>", positions = None, triangles = None, continuity = "g1", largest = None, max_boundary = None, grading = 0.1))]
#[allow(clippy::too_many_arguments)]
fn fill_mesh<'py>(
    py: Python<'py>,
    data: Option<Vec<u8>>,
    name: &str,
    positions: Option<Vec<[f64; 3]>>,
    triangles: Option<Vec<[i64; 3]>>,
    continuity: &str,
    largest: Option<usize>,
    max_boundary: Option<usize>,
    grading: f64,
) -> PyResult<Bound<'py, PyDict>> {
    use pdeshape::fill::{self, Continuity, FillOptions, HoleSelection};
    let continuity = match continuity {
        "g0" => Continuity::G0,
        "g1" => Continuity::G1,
        "g2" => Continuity::G2,
        other => {
            return Err(err(format!(
                "continuity '{other}': must be 'g0', 'g1' or 'g2'"
            )))
        }
    };
    let holes = match (largest, max_boundary) {
        (Some(_), Some(_)) => {
            return Err(err("largest, max_boundary: give one of them, not both"));
        }
        (Some(k), None) => HoleSelection::Largest(k),
        (None, Some(n)) => HoleSelection::MaxBoundary(n),
        (None, None) => HoleSelection::All,
    };
    let mut units = None;
    let mesh = match (data, positions, triangles) {
        (Some(data), None, None) => {
            let format = Path::new(name)
                .extension()
                .and_then(|e| e.to_str())
                .and_then(fit::MeshFormat::from_extension)
                .ok_or_else(|| err(fit::MeshFormat::unknown(name)))?;
            let read = fit::InputMesh::read_report(&data, format)
                .map_err(|e| err(format!("{name}: {e}")))?;
            units = read.units;
            read.mesh
        }
        (None, Some(p), Some(t)) => {
            let n = p.len();
            if let Some(k) = p.iter().position(|v| !v.iter().all(|c| c.is_finite())) {
                return Err(err(format!("positions[{k}]: is not finite")));
            }
            let mut tris = Vec::with_capacity(t.len());
            for (k, tri) in t.iter().enumerate() {
                if tri.iter().any(|&v| v < 0 || v as usize >= n) {
                    return Err(err(format!(
                        "triangles[{k}]: refers to a vertex outside 0 … {}",
                        n.saturating_sub(1)
                    )));
                }
                tris.push(tri.map(|v| v as u32));
            }
            fit::InputMesh {
                positions: p.iter().map(|v| Vec3::new(v[0], v[1], v[2])).collect(),
                triangles: tris,
            }
        }
        _ => {
            return Err(err(
                "mesh: give data (a file's bytes) or positions and triangles",
            ))
        }
    };
    let options = FillOptions {
        holes,
        continuity,
        grading,
    };
    let filled = py
        .detach(|| fill::fill_holes(&mesh, &options))
        .map_err(|e| match e.place() {
            "largest" | "max-boundary" | "grading" => err(e.to_string().replace('-', "_")),
            _ => err(format!("{name}: {e}")),
        })?;
    let file_name = Path::new(name)
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_default();
    let mut fill_spec = filled.design(&format!("{file_name}, hole fill"));
    fill_spec.units = units;
    let text = spec::write_design(&fill_spec).map_err(|e| err(format!("{name}: {e}")))?;
    let d = PyDict::new(py);
    d.set_item(
        "vertices",
        array2(
            py,
            filled
                .positions
                .iter()
                .flat_map(|p| [p.x, p.y, p.z])
                .collect(),
            3,
        ),
    )?;
    d.set_item(
        "faces",
        array2(
            py,
            filled
                .triangles
                .iter()
                .flat_map(|t| t.map(i64::from))
                .collect(),
            3,
        ),
    )?;
    d.set_item("mesh_faces", filled.mesh_triangles)?;
    d.set_item("open_edges", filled.open_edges)?;
    d.set_item("holes_found", filled.holes_found)?;
    let holes = PyList::empty(py);
    for h in &filled.holes {
        let hd = PyDict::new(py);
        hd.set_item("first_vertex", h.first_vertex)?;
        hd.set_item("boundary_vertices", h.boundary_vertices)?;
        hd.set_item("length", h.length)?;
        hd.set_item("vertices_added", h.vertices_added)?;
        hd.set_item("triangles_added", h.triangles_added)?;
        hd.set_item("g1_angle", h.g1_angle)?;
        hd.set_item("normal_jump", h.normal_jump)?;
        hd.set_item("ribbon", h.ribbon)?;
        hd.set_item("pieces", h.pieces)?;
        hd.set_item("chord_g1_angle", h.chord_g1_angle)?;
        hd.set_item("chord_jump", h.chord_jump)?;
        holes.append(hd)?;
    }
    d.set_item("holes", holes)?;
    d.set_item("design", text)?;
    Ok(d)
}

/// The library's version.
#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

#[pymodule]
fn _pdeshape(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Design>()?;
    m.add("DesignError", m.py().get_type::<DesignError>())?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    m.add_function(wrap_pyfunction!(fit_mesh, m)?)?;
    m.add_function(wrap_pyfunction!(fill_mesh, m)?)?;
    m.add("EQUALITY_TOLERANCE", pdeshape::optimize::EQUALITY_TOLERANCE)?;
    Ok(())
}

impl Design {
    /// STEP or IGES as `pdeshape surface -o x.step|x.igs [--tolerance T] [--units U]` writes
    /// them (the header's date from `timestamp`).
    fn write_cad(
        &mut self,
        py: Python<'_>,
        path: &Path,
        format: OutputFormat,
        tolerance: Option<f64>,
        units: Option<&str>,
        timestamp: Option<u64>,
    ) -> PyResult<()> {
        let unit = units
            .map(|u| {
                u.parse::<Units>()
                    .map_err(|e| err(format!("units: {}", message_of(&e))))
            })
            .transpose()?;
        if let Some(t) = tolerance {
            if !(t.is_finite() && t > 0.0) {
                return Err(err(format!(
                    "tolerance: must be a positive number (got {t})"
                )));
            }
        }
        let solved = self.solved(py)?;
        let file_name = path
            .file_name()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        let seconds = timestamp.unwrap_or_else(export_timestamp);
        let export = py
            .detach(|| cad::export_design(&solved, format, tolerance, unit, &file_name, seconds))
            .map_err(|e| match e {
                cad::CadExportError::Design(e) => self.located(&e),
                cad::CadExportError::Tolerance(e) => err(format!("tolerance: {}", message_of(&e))),
                cad::CadExportError::Write(e) => err(format!("path {}: {e}", path.display())),
            })?;
        write_atomically(path, export.text.as_bytes())
    }
}

/// Runs a `[dynamic]` section as `pdeshape curve` does (the library's
/// [`pdeshape::dynamic_run::run`]), keeping every frame it writes.
fn run_dynamic(
    section: &spec::DynamicSpec,
    keep_frames: bool,
) -> pdeshape::Result<(DynamicOutcome, Vec<CurveFrame>)> {
    let built = design::build_dynamic(section)?;
    // Every frame kept, or the one observed and the last.
    if keep_frames {
        dynamic_run::check_memory(
            &built,
            dynamic_run::frame_count(&built) + 1,
            Some("frames=True"),
        )?;
    } else {
        dynamic_run::check_memory(&built, 2, None)?;
    }
    let mut frames = Vec::new();
    let outcome = {
        let mut observer = |n: usize, t: f64, nodes: Option<&[Vec3]>| {
            if let (true, Some(nodes)) = (keep_frames, nodes) {
                frames.push(CurveFrame {
                    step: n,
                    time: t,
                    nodes: nodes.to_vec(),
                });
            }
        };
        dynamic_run::run(&built, &mut observer)?
    };
    Ok((outcome, frames))
}

/// The first `dim` coordinates of points as an `(n, dim)` array.
fn points_array(py: Python<'_>, points: &[Vec3], dim: usize) -> Py<PyAny> {
    let flat: Vec<f64> = points.iter().flat_map(|p| (0..dim).map(|c| p[c])).collect();
    array2(py, flat, dim)
}

/// `u_j = j/J` of `n = J + 1` nodes, as the CLI's CSV writes them.
fn node_parameters(n: usize) -> Vec<f64> {
    let jn = (n.max(2) - 1) as f64;
    (0..n).map(|j| j as f64 / jn).collect()
}
