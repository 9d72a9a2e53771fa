/// The one error type of the library. Every message names the offending input.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// Input that is malformed or out of range. `place` is a path such as `conditions[2].curve`
    /// (empty when the caller has not said where the value came from).
    #[error("{}{message}", place_prefix(place))]
    Invalid { place: String, message: String },
    /// The conditions do not determine a unique surface (wrong count, repeated conditions, a
    /// singular mode system, …).
    #[error(
        "{}conditions do not determine a unique surface: {message}",
        place_prefix(place)
    )]
    NotUnique { place: String, message: String },
    /// Writing or reading bytes failed.
    #[error("{}{message}", place_prefix(place))]
    Io { place: String, message: String },
}

fn place_prefix(place: &str) -> String {
    if place.is_empty() {
        String::new()
    } else {
        format!("{place}: ")
    }
}

/// `Result` with the library's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// Malformed or out-of-range input, place unknown yet.
    pub fn invalid(message: impl Into<String>) -> Self {
        Error::Invalid {
            place: String::new(),
            message: message.into(),
        }
    }

    /// Conditions that do not determine a unique surface.
    pub fn not_unique(message: impl Into<String>) -> Self {
        Error::NotUnique {
            place: String::new(),
            message: message.into(),
        }
    }

    /// An I/O failure.
    pub fn io(message: impl Into<String>) -> Self {
        Error::Io {
            place: String::new(),
            message: message.into(),
        }
    }

    /// Prefixes the place of the error with `outer`: `e.at("curves.rim")` turns `radius: …` into
    /// `curves.rim.radius: …`.
    pub fn at(self, outer: &str) -> Self {
        let join = |place: String| {
            if place.is_empty() {
                outer.to_string()
            } else if outer.is_empty() {
                place
            } else if place.starts_with('[') {
                format!("{outer}{place}")
            } else {
                format!("{outer}.{place}")
            }
        };
        match self {
            Error::Invalid { place, message } => Error::Invalid {
                place: join(place),
                message,
            },
            Error::NotUnique { place, message } => Error::NotUnique {
                place: join(place),
                message,
            },
            Error::Io { place, message } => Error::Io {
                place: join(place),
                message,
            },
        }
    }

    /// The place (path in the input) this error refers to; empty if unknown.
    pub fn place(&self) -> &str {
        match self {
            Error::Invalid { place, .. }
            | Error::NotUnique { place, .. }
            | Error::Io { place, .. } => place,
        }
    }
}

impl From<std::io::Error> for Error {
    fn from(e: std::io::Error) -> Self {
        Error::io(e.to_string())
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
        let e = Error::invalid("bad").at("[2]").at("conditions");
        assert_eq!(e.to_string(), "conditions[2]: bad");
        let e = Error::not_unique("two positions at u = 0.5");
        assert_eq!(
            e.to_string(),
            "conditions do not determine a unique surface: two positions at u = 0.5"
        );
    }
}
