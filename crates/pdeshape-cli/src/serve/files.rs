//! Files of the designer, confined to the directory the server was started in: a path is
//! relative, has no `..` (nor `.`, nor a root or drive), names a `.toml` file, and — once
//! symlinks are resolved — still lies inside the start directory. Saves are atomic (a
//! temporary file beside the target, renamed over it).

use super::error::ApiError;
use crate::common::Loaded;
use pdeshape::anim::{Animation, Morph};
use pdeshape::spec::{self, time, DesignSpec};
use std::path::{Component, Path, PathBuf};

/// Largest design file the designer reads.
pub const MAX_FILE_BYTES: u64 = 4 << 20;
/// Design files listed at most, and how deep the listing looks.
const MAX_LISTED: usize = 500;
const MAX_DEPTH: usize = 4;

/// Checks the shape of `rel` (relative, plain components, `.toml`) and joins it to `root`.
fn checked_join(root: &Path, rel: &str) -> Result<PathBuf, ApiError> {
    let bad = |m: &str| ApiError::forbidden(format!("'{rel}': {m}"), "path");
    if rel.is_empty() {
        return Err(ApiError::bad_request("must not be empty", "path"));
    }
    if rel.contains('\0') || rel.contains('\\') {
        return Err(bad("must not contain NUL or backslashes"));
    }
    let path = Path::new(rel);
    if path.is_absolute() || rel.starts_with('/') {
        return Err(bad(
            "must be relative to the directory the server was started in",
        ));
    }
    for c in path.components() {
        match c {
            Component::Normal(_) => {}
            Component::ParentDir => return Err(bad("must not contain '..'")),
            _ => return Err(bad("must be a plain relative path (no '.', root or drive)")),
        }
    }
    let is_toml = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e == "toml");
    if !is_toml {
        return Err(ApiError::bad_request(
            format!("'{rel}': design files end in .toml"),
            "path",
        ));
    }
    Ok(root.join(path))
}

/// `path` with symlinks resolved must stay inside `root` (itself canonical).
fn inside(root: &Path, rel: &str, resolved: &Path) -> Result<(), ApiError> {
    if resolved.starts_with(root) {
        Ok(())
    } else {
        Err(ApiError::forbidden(
            format!("'{rel}': leads outside the directory the server was started in"),
            "path",
        ))
    }
}

/// Resolves `rel` inside `root` to an existing regular file no larger than [`MAX_FILE_BYTES`].
fn existing_file(root: &Path, rel: &str) -> Result<PathBuf, ApiError> {
    let path = checked_join(root, rel)?;
    let resolved = path.canonicalize().map_err(|e| {
        ApiError::not_found(format!("'{rel}': cannot open the design file: {e}"), "path")
    })?;
    inside(root, rel, &resolved)?;
    let meta = std::fs::metadata(&resolved)
        .map_err(|e| ApiError::not_found(format!("'{rel}': {e}"), "path"))?;
    if !meta.is_file() {
        return Err(ApiError::not_found(format!("'{rel}': not a file"), "path"));
    }
    if meta.len() > MAX_FILE_BYTES {
        return Err(ApiError::unprocessable(
            format!("'{rel}': larger than {MAX_FILE_BYTES} bytes"),
            "path",
        ));
    }
    Ok(resolved)
}

/// Reads and parses the design file `rel` inside `root`; returns the path as shown and the
/// loaded design. Parse errors are located as `file:line:col`.
pub fn load_design(root: &Path, rel: &str) -> Result<(String, Loaded), ApiError> {
    let resolved = existing_file(root, rel)?;
    let loaded = crate::common::load(&resolved).map_err(|e| {
        ApiError::unprocessable(e.message.replace(&*resolved.to_string_lossy(), rel), "path")
    })?;
    Ok((rel.to_string(), loaded))
}

/// A design file as the designer opens it: the design (at its start time, if it depends on
/// time) and, for a design whose numbers are formulas in `t` (or that has a `[rig]`) or for a
/// morph file, its animation.
pub struct Opened {
    pub file: String,
    pub spec: DesignSpec,
    pub animation: Option<Animation>,
}

/// Reads the design file `rel` inside `root`, time-dependent or not. A morph's source and
/// target must lie inside `root` too.
pub fn open_design(root: &Path, rel: &str) -> Result<Opened, ApiError> {
    let resolved = existing_file(root, rel)?;
    let text = std::fs::read_to_string(&resolved)
        .map_err(|e| ApiError::unprocessable(format!("'{rel}': cannot read it: {e}"), "path"))?;
    let located = |file: &str, text: &str, e: &pdeshape::Error| {
        ApiError::unprocessable(spec::describe_error(file, text, e), e.place())
    };
    if let Some(mf) = time::parse_morph_file(&text).map_err(|e| located(rel, &text, &e))? {
        let dir = Path::new(rel).parent().unwrap_or(Path::new(""));
        let read = |other: &str, key: &str| -> Result<(String, String), ApiError> {
            let joined = dir.join(other);
            // `..` is allowed here as long as the file stays inside the start directory.
            let full = root.join(&joined).canonicalize().map_err(|e| {
                ApiError::not_found(
                    format!("{rel}: morph.{key}: cannot open '{other}': {e}"),
                    &format!("morph.{key}"),
                )
            })?;
            if !full.starts_with(root) {
                return Err(ApiError::forbidden(
                    format!("{rel}: morph.{key}: '{other}' lies outside the directory the server was started in"),
                    &format!("morph.{key}"),
                ));
            }
            let shown = full
                .strip_prefix(root)
                .map(|p| p.to_string_lossy().into_owned())
                .unwrap_or_else(|_| other.to_string());
            let (_, loaded) = load_design(root, &shown)?;
            Ok((shown, loaded.text))
        };
        let (source_file, source) = read(&mf.morph.source, "source")?;
        let (_, target) = read(&mf.morph.target, "target")?;
        let morph = Morph::new(&source, &target).map_err(|e| {
            ApiError::unprocessable(
                format!(
                    "{rel}: morph: {}",
                    spec::describe_error(&source_file, &source, &e)
                ),
                "morph",
            )
        })?;
        let spec = morph
            .at(0.0)
            .map_err(|e| located(&source_file, &source, &e))?;
        let animation = Animation::Morph {
            morph,
            time: mf.time,
            ease: mf.morph.ease,
        };
        return Ok(Opened {
            file: rel.to_string(),
            spec,
            animation: Some(animation),
        });
    }
    if let Ok(timed) = time::parse_timed(&text) {
        if timed.depends_on_time() {
            let spec = timed
                .at(timed.time.start)
                .map_err(|e| located(rel, &text, &e))?;
            return Ok(Opened {
                file: rel.to_string(),
                spec,
                animation: Some(Animation::Timed(timed)),
            });
        }
    }
    let (file, loaded) = load_design(root, rel)?;
    Ok(Opened {
        file,
        spec: loaded.spec,
        animation: None,
    })
}

/// Writes `text` to `rel` inside `root` atomically; returns `rel`.
pub fn save_text(root: &Path, rel: &str, text: &str) -> Result<String, ApiError> {
    let path = checked_join(root, rel)?;
    let parent = path.parent().unwrap_or(root);
    let parent_resolved = parent
        .canonicalize()
        .map_err(|e| ApiError::not_found(format!("'{rel}': no such directory: {e}"), "path"))?;
    inside(root, rel, &parent_resolved)?;
    let target = parent_resolved.join(path.file_name().unwrap_or_default());
    // An existing target (or a symlink, dangling or not) must resolve inside too.
    if std::fs::symlink_metadata(&target).is_ok() {
        match target.canonicalize() {
            Ok(resolved) => {
                inside(root, rel, &resolved)?;
                if resolved.is_dir() {
                    return Err(ApiError::bad_request(
                        format!("'{rel}': is a directory"),
                        "path",
                    ));
                }
            }
            Err(_) => {
                return Err(ApiError::forbidden(
                    format!("'{rel}': is a symlink to nowhere"),
                    "path",
                ))
            }
        }
    }
    let mut out = crate::common::Output::create(&target)
        .map_err(|e| ApiError::internal(e.message.replace(&*target.to_string_lossy(), rel)))?;
    out.write_all(text.as_bytes())
        .and_then(|()| out.commit())
        .map_err(|e| ApiError::internal(e.message.replace(&*target.to_string_lossy(), rel)))?;
    Ok(rel.to_string())
}

/// The design files (`*.toml`) under `root`, relative, sorted; hidden folders and `target` are
/// skipped and symlinked folders are not followed.
pub fn list(root: &Path) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack = vec![(root.to_path_buf(), 0usize)];
    while let Some((dir, depth)) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for entry in entries.flatten() {
            let name = entry.file_name();
            let name = name.to_string_lossy();
            if name.starts_with('.') || name == "target" || name == "node_modules" {
                continue;
            }
            let Ok(kind) = entry.file_type() else {
                continue;
            };
            let path = entry.path();
            if kind.is_dir() && depth < MAX_DEPTH {
                stack.push((path, depth + 1));
            } else if kind.is_file() && name.ends_with(".toml") && name != "Cargo.toml" {
                if let Ok(rel) = path.strip_prefix(root) {
                    out.push(rel.to_string_lossy().into_owned());
                }
            }
            if out.len() >= MAX_LISTED {
                break;
            }
        }
    }
    out.sort();
    out
}
