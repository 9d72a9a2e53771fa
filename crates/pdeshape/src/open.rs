//! Opening design files: the one reader of a design file's text (one size limit, one treatment
//! of directories, FIFOs, devices and symlinks) and the one reading of what the file is — a
//! still design, a timed design (`[time]`, formula fields in `t`, a `[rig]`) or a morph file
//! (`[morph]` between two still designs). The CLI, the designer and the Python package all open
//! files through [`open`] (or [`DesignFile::read`] and [`DesignFile::parse_still`]); what a
//! shell adds is its own (the designer confines paths to its start directory through the
//! resolver of [`open_with`]).
//!
//! Errors are one line naming the file: `file: the design file has … bytes; at most …`,
//! `file: cannot read the design file: …`, or a parse error located as `file:line:col: place:
//! message` ([`spec::describe_error`]).

use crate::anim::{Animation, Morph};
use crate::spec::{self, time, DesignSpec, OutputSpec};
use crate::Error;
use std::io::Read;
use std::path::{Path, PathBuf};

/// The largest design file read, in bytes (the parser's own limit,
/// [`spec::limits::MAX_FILE_BYTES`]: 16 MiB).
pub const MAX_FILE_BYTES: u64 = spec::limits::MAX_FILE_BYTES as u64;

/// What went wrong opening a design file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OpenErrorKind {
    /// The file (or a morph's source or target) does not exist or cannot be read.
    Unreadable,
    /// Not a regular file: a directory, a FIFO, a device or a socket.
    NotAFile,
    /// Larger than [`MAX_FILE_BYTES`].
    TooLarge,
    /// Not UTF-8 text, or text that is not a valid design.
    Invalid,
    /// A morph's source or target refused by the caller's resolver (see [`open_with`]).
    Refused,
}

/// A file that could not be opened as a design: one line naming the file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OpenError {
    /// The line for the user: `file: …` or `file:line:col: place: message`.
    pub message: String,
    /// The place in the design the error is about (`morph.source`, `curves.rim.radius`, …),
    /// empty for errors of the file itself.
    pub place: String,
    /// What kind of failure it was.
    pub kind: OpenErrorKind,
}

impl std::fmt::Display for OpenError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for OpenError {}

impl OpenError {
    fn file(kind: OpenErrorKind, message: String) -> Self {
        OpenError {
            message,
            place: String::new(),
            kind,
        }
    }

    /// A design error located in `file`'s `text`.
    pub fn located(file: &str, text: &str, e: &Error) -> Self {
        OpenError {
            message: spec::describe_error(file, text, e),
            place: e.place().to_string(),
            kind: OpenErrorKind::Invalid,
        }
    }
}

/// An I/O error in words, without the "(os error N)" suffix.
pub fn io_words(e: &std::io::Error) -> String {
    use std::io::ErrorKind::*;
    match e.kind() {
        NotFound => "no such file or directory".to_string(),
        PermissionDenied => "permission denied".to_string(),
        _ => {
            let s = e.to_string();
            match s.find(" (os error") {
                Some(i) => s[..i].to_string(),
                None => s,
            }
        }
    }
}

/// Why an input file was not read ([`open_regular`], [`read_regular`], [`read_held`]).
#[derive(Clone, Debug)]
pub enum ReadError {
    /// It does not exist or cannot be opened or read: the system's words.
    Unreadable(String),
    /// It is not a regular file (a directory, a FIFO, a device or a socket).
    NotAFile(std::fs::FileType),
    /// It has (or grew to while it was read) this many bytes, more than the limit.
    TooLarge(u64),
    /// Holding it would not fit in the memory budget: the budget's message.
    OverBudget(String),
}

impl ReadError {
    /// What went wrong, in words, for `file: cannot read …` or `file: …`: the system's words,
    /// "a FIFO (named pipe) is not a regular file", "Is a directory", or the size.
    pub fn words(&self) -> String {
        match self {
            ReadError::Unreadable(w) => format!("cannot read: {w}"),
            ReadError::NotAFile(t) if t.is_dir() => "cannot read: Is a directory".to_string(),
            ReadError::NotAFile(t) => {
                format!("cannot read: {} is not a regular file", kind_words(*t))
            }
            ReadError::TooLarge(n) => format!("the file has {n} bytes, more than can be read"),
            ReadError::OverBudget(m) => m.clone(),
        }
    }

    /// The matching [`OpenErrorKind`].
    pub fn kind(&self) -> OpenErrorKind {
        match self {
            ReadError::Unreadable(_) => OpenErrorKind::Unreadable,
            ReadError::NotAFile(_) => OpenErrorKind::NotAFile,
            ReadError::TooLarge(_) | ReadError::OverBudget(_) => OpenErrorKind::TooLarge,
        }
    }
}

/// Opens `path` for reading if it is a regular file (symlinks followed), with its length. The
/// type is checked before the file is opened, so a FIFO is refused rather than waited on, and
/// again on the open file (opened non-blocking), so a FIFO swapped in between is refused too.
/// Every input file of the CLI, the designer and the Python package is opened here.
pub fn open_regular(path: &Path) -> Result<(std::fs::File, u64), ReadError> {
    let unreadable = |e: std::io::Error| ReadError::Unreadable(io_words(&e));
    let meta = std::fs::metadata(path).map_err(unreadable)?;
    if !meta.is_file() {
        return Err(ReadError::NotAFile(meta.file_type()));
    }
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path).map_err(unreadable)?;
    let meta = file.metadata().map_err(unreadable)?;
    if !meta.is_file() {
        return Err(ReadError::NotAFile(meta.file_type()));
    }
    Ok((file, meta.len()))
}

/// Reads at most `limit` bytes of `file`; more (a file that grew) is refused as
/// [`ReadError::TooLarge`] after reading one byte past the limit, never all of it.
pub fn read_bounded(file: std::fs::File, len: u64, limit: u64) -> Result<Vec<u8>, ReadError> {
    if len > limit {
        return Err(ReadError::TooLarge(len));
    }
    let mut bytes = Vec::with_capacity(len as usize);
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| ReadError::Unreadable(io_words(&e)))?;
    if bytes.len() as u64 > limit {
        return Err(ReadError::TooLarge(bytes.len() as u64));
    }
    Ok(bytes)
}

/// The bytes of the regular file `path`, at most `limit` of them ([`open_regular`],
/// [`read_bounded`]).
pub fn read_regular(path: &Path, limit: u64) -> Result<Vec<u8>, ReadError> {
    let (file, len) = open_regular(path)?;
    read_bounded(file, len, limit)
}

/// The bytes of an input file that is held whole in memory (a mesh, a STEP or IGES file): a
/// regular file whose size the memory budget ([`crate::memory::check`]) admits, read no further
/// than that size.
pub fn read_held(path: &Path) -> Result<Vec<u8>, ReadError> {
    let (file, len) = open_regular(path)?;
    crate::memory::check(
        crate::memory::mesh_read(len, 0),
        &format!("holding the file of {len} bytes"),
        "",
    )
    .map_err(|e| ReadError::OverBudget(e.to_string()))?;
    read_bounded(file, len, len)
}

/// A design file's text with the name its errors are shown under.
#[derive(Clone, Debug)]
pub struct DesignFile {
    /// The name errors are located in (the path as given, or as a shell shows it).
    pub file: String,
    /// The file's text.
    pub text: String,
}

/// What a path that is not a regular file is, in words.
fn kind_words(t: std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_socket() {
            return "a socket";
        }
        if t.is_block_device() || t.is_char_device() {
            return "a device";
        }
    }
    if t.is_dir() {
        "a directory"
    } else {
        "not a regular file"
    }
}

impl DesignFile {
    /// Reads `path` (shown as its own display). See [`DesignFile::read_as`].
    pub fn read(path: &Path) -> Result<DesignFile, OpenError> {
        Self::read_as(path, &path.display().to_string())
    }

    /// Reads the design file `path`, naming it `shown` in errors. Symlinks are followed; what
    /// they lead to is checked like any path. Only a regular file is read: a directory is
    /// refused as "Is a directory" (the system's words), a FIFO, device or socket as "not a
    /// regular file" (without opening it, so a FIFO never blocks). At most [`MAX_FILE_BYTES`]
    /// are read: a larger file is refused with its size, a file growing while it is read is cut
    /// at one byte more and refused the same way.
    pub fn read_as(path: &Path, shown: &str) -> Result<DesignFile, OpenError> {
        let cannot = |words: String| {
            OpenError::file(
                OpenErrorKind::Unreadable,
                format!("{shown}: cannot read the design file: {words}"),
            )
        };
        let not_a_file = |t: std::fs::FileType| {
            let message = if t.is_dir() {
                format!("{shown}: cannot read the design file: Is a directory")
            } else {
                format!(
                    "{shown}: cannot read the design file: {} is not a regular file",
                    kind_words(t)
                )
            };
            OpenError::file(OpenErrorKind::NotAFile, message)
        };
        let too_large = |n: u64| {
            OpenError::file(
                OpenErrorKind::TooLarge,
                format!(
                    "{shown}: the design file has {n} bytes; at most {MAX_FILE_BYTES} (16 MiB) \
                     are read"
                ),
            )
        };
        let bytes = read_regular(path, MAX_FILE_BYTES).map_err(|e| match e {
            ReadError::Unreadable(words) => cannot(words),
            ReadError::NotAFile(t) => not_a_file(t),
            ReadError::TooLarge(n) => too_large(n),
            ReadError::OverBudget(m) => OpenError::file(OpenErrorKind::TooLarge, m),
        })?;
        let text = String::from_utf8(bytes).map_err(|e| {
            let at = e.utf8_error().valid_up_to();
            OpenError::file(
                OpenErrorKind::Invalid,
                format!("{shown}: the design file is not UTF-8 text (invalid byte at offset {at})"),
            )
        })?;
        Ok(DesignFile {
            file: shown.to_string(),
            text,
        })
    }

    /// The design as a still design: the plain reader's, or — for a design whose numbers are
    /// formulas in `t` ([`spec::time`]) or that has a `[rig]` — the design at its start time,
    /// with the timed reader's errors (the plain reader knows no `[rig]`).
    pub fn parse_still(&self) -> Result<DesignSpec, OpenError> {
        let text = &self.text;
        spec::parse_design(text)
            .or_else(|e| match time::parse_timed(text) {
                Ok(d) if d.depends_on_time() => d.at(d.time.start),
                Err(timed) if text.contains("\"=") || text.contains("[rig") => Err(timed),
                _ => Err(e),
            })
            .map_err(|e| self.located(&e))
    }

    /// `file:line:col: place: message` for an error about this file.
    pub fn located(&self, e: &Error) -> OpenError {
        OpenError::located(&self.file, &self.text, e)
    }
}

/// A design file opened: the design (at its start time, if it depends on time) and, for a
/// design whose numbers are formulas in `t` (or that has a `[rig]`) or for a morph file, its
/// animation.
pub struct Opened {
    /// The file whose text locates the design's errors: the file itself, or a morph's source.
    pub design: DesignFile,
    /// The design, at the start time of an animation.
    pub spec: DesignSpec,
    /// The animation of a timed design or a morph file; `None` for a still design.
    pub animation: Option<Animation>,
    /// The file's `[output]` (a morph file's own).
    pub output: OutputSpec,
    /// The file's title (a morph file's own).
    pub title: Option<String>,
}

/// Where a morph file's `source` or `target` is: the path to read and the name to show.
/// `key` is `source` or `target`, `name` the file's own words.
pub type Resolve<'a> = dyn Fn(&str, &str) -> Result<(PathBuf, String), OpenError> + 'a;

/// Opens a design file: a morph file (its source and target beside it, resolved against its
/// directory), a timed design that depends on `t`, or a still design
/// ([`DesignFile::parse_still`]).
pub fn open(path: &Path) -> Result<Opened, OpenError> {
    open_with(path, &path.display().to_string(), &beside(path))
}

/// The resolver of [`open`]: a morph's source and target relative to the morph file's
/// directory, shown as joined.
fn beside(path: &Path) -> impl Fn(&str, &str) -> Result<(PathBuf, String), OpenError> {
    let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
    move |_: &str, name: &str| {
        let p = dir.join(name);
        let shown = p.display().to_string();
        Ok((p, shown))
    }
}

/// [`open`] with the name errors show and the resolver of a morph's source and target (the
/// designer confines both to its start directory).
pub fn open_with(path: &Path, shown: &str, resolve: &Resolve<'_>) -> Result<Opened, OpenError> {
    open_inner(path, shown, resolve, false)
}

/// Opens a design file as an animation (`pdeshape animate`): a morph file, or any other design
/// read as a timed design ([`time::parse_timed`], with its errors) — a design without `t` is
/// an animation solved once. [`Opened::animation`] is always `Some`.
pub fn open_animation(path: &Path) -> Result<Opened, OpenError> {
    open_inner(path, &path.display().to_string(), &beside(path), true)
}

fn open_inner(
    path: &Path,
    shown: &str,
    resolve: &Resolve<'_>,
    animation: bool,
) -> Result<Opened, OpenError> {
    let file = DesignFile::read_as(path, shown)?;
    let morph_file = time::parse_morph_file(&file.text).map_err(|e| file.located(&e))?;
    if let Some(mf) = morph_file {
        let read = |key: &str, name: &str| -> Result<DesignFile, OpenError> {
            let (p, shown) = resolve(key, name)?;
            let f = DesignFile::read_as(&p, &shown)?;
            f.parse_still()?;
            Ok(f)
        };
        let source = read("source", &mf.morph.source)?;
        let target = read("target", &mf.morph.target)?;
        let morph = Morph::new(&source.text, &target.text).map_err(|e| OpenError {
            message: format!("{shown}: morph: {}", source.located(&e).message),
            place: "morph".to_string(),
            kind: OpenErrorKind::Invalid,
        })?;
        let spec = morph.at(0.0).map_err(|e| source.located(&e))?;
        return Ok(Opened {
            design: source,
            spec,
            animation: Some(Animation::Morph {
                morph,
                time: mf.time,
                ease: mf.morph.ease,
            }),
            output: mf.output,
            title: mf.title,
        });
    }
    if animation {
        let timed = time::parse_timed(&file.text).map_err(|e| file.located(&e))?;
        let spec = timed.at(timed.time.start).map_err(|e| file.located(&e))?;
        return Ok(Opened {
            output: spec.output.clone(),
            title: spec.title.clone(),
            spec,
            design: file,
            animation: Some(Animation::Timed(timed)),
        });
    }
    if let Ok(timed) = time::parse_timed(&file.text) {
        if timed.depends_on_time() {
            let spec = timed.at(timed.time.start).map_err(|e| file.located(&e))?;
            return Ok(Opened {
                output: spec.output.clone(),
                title: spec.title.clone(),
                spec,
                design: file,
                animation: Some(Animation::Timed(timed)),
            });
        }
    }
    let spec = file.parse_still()?;
    Ok(Opened {
        output: spec.output.clone(),
        title: spec.title.clone(),
        spec,
        design: file,
        animation: None,
    })
}

#[cfg(test)]
mod tests;
