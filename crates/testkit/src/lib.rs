//! What the integration tests, benches and usage examples of pdeshape share: the bundled
//! example designs (`examples/` at the repository's root), small design texts, curve builders
//! and test meshes.
//!
//! A dev-dependency of `pdeshape` and `pdeshape-cli` only; the layer crates' unit tests keep
//! their own helpers (a dev-dependency on this crate would give them two copies of their types).

#![warn(missing_docs)]

pub mod curves;
pub mod designs;
pub mod fit_meshes;
pub mod hole_meshes;
pub mod implicit;
pub mod mutate;

use pdeshape::spec::{parse_design, DesignSpec};
use std::path::PathBuf;

/// The repository's root directory.
pub fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// The directory of the bundled examples (`examples/` at the repository's root).
pub fn examples_dir() -> PathBuf {
    repo_root().join("examples")
}

/// The path of a bundled example, `name` relative to the examples directory
/// (`"cup.toml"`, `"anim/ventricle.toml"`).
pub fn example_path(name: &str) -> PathBuf {
    examples_dir().join(name)
}

/// The text of a bundled example.
pub fn example(name: &str) -> String {
    let path = example_path(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A bundled example, parsed.
pub fn example_spec(name: &str) -> DesignSpec {
    parse_design(&example(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Every design of `examples/` and `examples/spline/`, sorted by directory then file name, as
/// `(file name, text)`.
pub fn example_designs() -> Vec<(String, String)> {
    let mut out = designs_in("examples", "");
    out.extend(designs_in("examples/spline", ""));
    out
}

/// The `.toml` files of `dir` (relative to the repository), sorted, as `(prefix + file name,
/// text)`.
pub fn designs_in(dir: &str, prefix: &str) -> Vec<(String, String)> {
    let mut names: Vec<_> = std::fs::read_dir(repo_root().join(dir))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    names.sort();
    names
        .into_iter()
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().to_string();
            (
                format!("{prefix}{name}"),
                std::fs::read_to_string(&p).unwrap(),
            )
        })
        .collect()
}
