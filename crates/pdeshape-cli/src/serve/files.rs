//! Files of the designer, confined to the directory the server was started in: a path is
//! relative, has no `..` (nor `.`, nor a root or drive), names a `.toml` file, and — once
//! symlinks are resolved — still lies inside the start directory. Saves are atomic (a
//! temporary file beside the target, renamed over it).

use super::error::ApiError;
use pdeshape::anim::Animation;
use pdeshape::open::{self, OpenError, OpenErrorKind};
use pdeshape::spec::DesignSpec;
use std::path::{Component, Path, PathBuf};

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

/// Resolves `rel` inside `root` (symlinks resolved) to a path that must stay inside it.
fn existing_file(root: &Path, rel: &str) -> Result<PathBuf, ApiError> {
    let path = checked_join(root, rel)?;
    let resolved = path.canonicalize().map_err(|e| {
        ApiError::not_found(
            format!(
                "'{rel}': cannot open the design file: {}",
                open::io_words(&e)
            ),
            "path",
        )
    })?;
    inside(root, rel, &resolved)?;
    Ok(resolved)
}

/// The library's refusal of a file as the designer answers it: a file that cannot be read (or
/// is not a regular file) is not found, one too large or not a design cannot be processed.
/// The place is the path's (the message locates the error in the file), or a morph's key.
fn refused(e: OpenError) -> ApiError {
    let place = if e.place.starts_with("morph") {
        e.place.as_str()
    } else {
        "path"
    };
    match e.kind {
        OpenErrorKind::Unreadable | OpenErrorKind::NotAFile => {
            ApiError::not_found(e.message, place)
        }
        OpenErrorKind::TooLarge | OpenErrorKind::Invalid => {
            ApiError::unprocessable(e.message, place)
        }
        OpenErrorKind::Refused => ApiError::forbidden(e.message, place),
    }
}

/// A design file as the designer opens it: the design (at its start time, if it depends on
/// time) and, for a design whose numbers are formulas in `t` (or that has a `[rig]`) or for a
/// morph file, its animation.
pub(super) struct Opened {
    pub file: String,
    pub spec: DesignSpec,
    pub animation: Option<Animation>,
}

/// Opens the design file `rel` inside `root` ([`pdeshape::open::open_with`]), time-dependent
/// or not. A morph's source and target must lie inside `root` too (`..` is allowed in them as
/// long as the file stays inside).
pub(super) fn open_design(root: &Path, rel: &str) -> Result<Opened, ApiError> {
    let resolved = existing_file(root, rel)?;
    let dir = Path::new(rel).parent().unwrap_or(Path::new(""));
    let resolve = |key: &str, other: &str| -> Result<(PathBuf, String), OpenError> {
        let refuse = |kind, message: String| OpenError {
            message,
            place: format!("morph.{key}"),
            kind,
        };
        let full = root.join(dir.join(other)).canonicalize().map_err(|e| {
            refuse(
                OpenErrorKind::Unreadable,
                format!("{rel}: morph.{key}: cannot open '{other}': {e}"),
            )
        })?;
        if !full.starts_with(root) {
            return Err(refuse(
                OpenErrorKind::Refused,
                format!(
                    "{rel}: morph.{key}: '{other}' lies outside the directory the server was \
                     started in"
                ),
            ));
        }
        let shown = full
            .strip_prefix(root)
            .map(|p| p.to_string_lossy().into_owned())
            .unwrap_or_else(|_| other.to_string());
        Ok((full, shown))
    };
    let o = open::open_with(&resolved, rel, &resolve).map_err(refused)?;
    Ok(Opened {
        file: rel.to_string(),
        spec: o.spec,
        animation: o.animation,
    })
}

/// Writes `text` to `rel` inside `root` atomically; returns `rel`.
pub(super) fn save_text(root: &Path, rel: &str, text: &str) -> Result<String, ApiError> {
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
    let shown = pdeshape::spec::words::user_text(rel);
    let refuse = |status: fn(String, &str) -> ApiError, why: &str| {
        status(format!("'{shown}': cannot save: {why}"), "path")
    };
    let too_long = Path::new(rel)
        .components()
        .any(|c| c.as_os_str().len() > MAX_NAME);
    if too_long {
        return Err(refuse(
            ApiError::bad_request,
            &format!("a file or folder name is longer than {MAX_NAME} bytes"),
        ));
    }
    // A folder without write permission is refused by its mode, as a read-only file is, also
    // for a server run by a user the permissions do not bind (root).
    let folder_locked = std::fs::metadata(&parent_resolved)
        .map(|m| m.permissions().readonly())
        .unwrap_or(false);
    if folder_locked {
        return Err(refuse(ApiError::forbidden, "its folder is read-only"));
    }
    // The same checks as every output of the CLI, in the designer's words: a save never replaces
    // a read-only file (there is no `--force` here).
    let mut out = crate::common::Output::open(&target, false).map_err(|r| {
        use crate::common::Refusal;
        match r {
            Refusal::NotAFile(what) => refuse(
                ApiError::bad_request,
                &format!("it is {what}, not a regular file"),
            ),
            Refusal::NoDirectory(_) => refuse(ApiError::not_found, "its folder does not exist"),
            Refusal::SameFile => refuse(ApiError::conflict, "another save to it is under way"),
            Refusal::ReadOnly => refuse(ApiError::forbidden, "the file is read-only"),
            Refusal::Create(_, e) => io_refusal(&shown, &e),
        }
    })?;
    out.write_all(text.as_bytes())
        .and_then(|()| out.commit())
        .and_then(|()| crate::common::finish_outputs())
        .map_err(|e| {
            // A failure of the disk itself (full, an I/O error): the message names the file
            // relative to the start directory, whatever the CLI's words said.
            let why = e
                .message
                .split_once(": ")
                .map_or(e.message.as_str(), |(_, w)| w);
            let why = why.replace(&*target.to_string_lossy(), &shown);
            let why = why.replace(&*root.to_string_lossy(), ".");
            ApiError::unavailable(format!("'{shown}': cannot save: {why}"), "path")
        })?;
    Ok(rel.to_string())
}

/// Longest file or folder name a save accepts, in bytes (`NAME_MAX` of Linux and macOS).
const MAX_NAME: usize = 255;

/// An I/O error creating the save's temporary file in its folder, as the designer answers it.
fn io_refusal(shown: &str, e: &std::io::Error) -> ApiError {
    let why = crate::common::io_words(e);
    let message = format!("'{shown}': cannot save: cannot write in its folder: {why}");
    match e.kind() {
        std::io::ErrorKind::PermissionDenied | std::io::ErrorKind::ReadOnlyFilesystem => {
            ApiError::forbidden(message, "path")
        }
        std::io::ErrorKind::InvalidFilename => ApiError::bad_request(message, "path"),
        _ => ApiError::unavailable(message, "path"),
    }
}

/// The design files (`*.toml`) under `root`, relative, sorted; hidden folders and `target` are
/// skipped and symlinked folders are not followed.
pub(super) fn list(root: &Path) -> Vec<String> {
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
