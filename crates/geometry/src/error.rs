//! The one error type of the library: what kind of failure, where in the input (a path in the
//! design such as `curves.rim.radius`, or an argument's name), the message, and the I/O error
//! behind it when there is one. Shells print [`Error`]'s `Display` (`place: message`) or its
//! parts ([`Error::place`], [`Error::message`]) without parsing strings.

use std::fmt;
use std::sync::Arc;

/// What kind of failure an [`Error`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum ErrorKind {
    /// Input that is malformed or out of range.
    Invalid,
    /// The conditions do not determine a unique surface (wrong count, repeated conditions, a
    /// singular mode system, …).
    NotUnique,
    /// Writing or reading bytes failed.
    Io,
}

/// The one error of the library. Every message names the offending input.
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct Error {
    kind: ErrorKind,
    place: String,
    message: String,
    source: Option<Arc<std::io::Error>>,
}

/// `Result` with the library's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// Every message's numbers in short form ([`crate::check::short_numbers`]): `1e308`, not
    /// its 309 digits.
    fn new(kind: ErrorKind, message: impl Into<String>) -> Self {
        Error {
            kind,
            place: String::new(),
            message: crate::check::short_numbers(&message.into()),
            source: None,
        }
    }

    /// A design without a surface asked for a surface's output (a mesh, CAD data, samples):
    /// the one message every writer and shell gives.
    pub fn no_surface() -> Self {
        Self::invalid(
            "the design has no surface (only a [dynamic] curve: `pdeshape curve` runs it)",
        )
    }

    /// Malformed or out-of-range input, place unknown yet.
    pub fn invalid(message: impl Into<String>) -> Self {
        Self::new(ErrorKind::Invalid, message)
    }

    /// Conditions that do not determine a unique surface.
    pub fn not_unique(message: impl Into<String>) -> Self {
        Self::new(ErrorKind::NotUnique, message)
    }

    /// An I/O failure described by `message`.
    pub fn io(message: impl Into<String>) -> Self {
        Self::new(ErrorKind::Io, message)
    }

    /// An I/O failure described by `message`, keeping `source` as the error behind it
    /// ([`std::error::Error::source`]).
    pub fn io_from(message: impl Into<String>, source: std::io::Error) -> Self {
        Error {
            source: Some(Arc::new(source)),
            ..Self::io(message)
        }
    }

    /// The same error with another message (kind, place and source kept).
    pub fn with_message(self, message: impl Into<String>) -> Self {
        Error {
            message: crate::check::short_numbers(&message.into()),
            ..self
        }
    }

    /// Prefixes the place of the error with `outer`: `e.at("curves.rim")` turns `radius: …` into
    /// `curves.rim.radius: …`.
    pub fn at(mut self, outer: &str) -> Self {
        self.place = if self.place.is_empty() {
            outer.to_string()
        } else if outer.is_empty() {
            self.place
        } else if self.place.starts_with('[') {
            format!("{outer}{}", self.place)
        } else {
            format!("{outer}.{}", self.place)
        };
        self
    }

    /// What kind of failure this is.
    pub fn kind(&self) -> ErrorKind {
        self.kind
    }

    /// The place (path in the input, or an argument's name) this error refers to; empty if
    /// unknown.
    pub fn place(&self) -> &str {
        &self.place
    }

    /// The message as printed after the place: for [`ErrorKind::NotUnique`] with its
    /// "conditions do not determine a unique surface: " lead.
    pub fn message(&self) -> String {
        match self.kind {
            ErrorKind::NotUnique => format!(
                "conditions do not determine a unique surface: {}",
                self.message
            ),
            _ => self.message.clone(),
        }
    }

    /// The message as it was given, without the place or a kind's lead.
    pub fn detail(&self) -> &str {
        &self.message
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if !self.place.is_empty() {
            write!(f, "{}: ", self.place)?;
        }
        f.write_str(&self.message())
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.source
            .as_deref()
            .map(|e| e as &(dyn std::error::Error + 'static))
    }
}

/// Equal kind, place and message (the I/O source is not compared).
impl PartialEq for Error {
    fn eq(&self, other: &Self) -> bool {
        self.kind == other.kind && self.place == other.place && self.message == other.message
    }
}

impl From<std::io::Error> for Error {
    fn from(e: std::io::Error) -> Self {
        Error::io_from(e.to_string(), e)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn places_nest() {
        let e = Error::invalid("must be positive")
            .at("radius")
            .at("curves.rim");
        assert_eq!(e.to_string(), "curves.rim.radius: must be positive");
        assert_eq!(e.place(), "curves.rim.radius");
        assert_eq!(e.message(), "must be positive");
        let e = Error::invalid("bad").at("[2]").at("conditions");
        assert_eq!(e.to_string(), "conditions[2]: bad");
        let e = Error::not_unique("two positions at u = 0.5");
        assert_eq!(
            e.to_string(),
            "conditions do not determine a unique surface: two positions at u = 0.5"
        );
        assert_eq!(e.kind(), ErrorKind::NotUnique);
        assert_eq!(e.detail(), "two positions at u = 0.5");
    }

    #[test]
    fn io_errors_keep_their_source() {
        use std::error::Error as _;
        let io = std::io::Error::new(std::io::ErrorKind::PermissionDenied, "denied");
        let e = Error::from(io).at("output");
        assert_eq!(e.kind(), ErrorKind::Io);
        assert_eq!(e.to_string(), "output: denied");
        let source = e.source().expect("the I/O error is kept");
        let io = source.downcast_ref::<std::io::Error>().unwrap();
        assert_eq!(io.kind(), std::io::ErrorKind::PermissionDenied);
        assert!(Error::invalid("x").source().is_none());
    }
}
