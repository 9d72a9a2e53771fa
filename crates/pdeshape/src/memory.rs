//! Memory estimated before it is allocated. Every request whose size a design or a flag chooses
//! (output grids, sample grids, pictures, dense spline systems) is priced in bytes first and
//! refused above [`budget`] with a message naming the field or flag, the value and the bound,
//! so that the allocator never aborts the process.

use crate::{Error, Result};

/// The fixed cap on one request: 4 GiB.
pub const MAX_REQUEST_BYTES: u64 = 4 << 30;

/// Bytes per vertex of an output grid, all buffers together: positions and normals in `f32`
/// (24 B), the same in `f64` for full-precision samples (48 B), and the writers' index and text
/// buffers; a generous round figure.
pub const BYTES_PER_GRID_VERTEX: u64 = 128;

/// Bytes per output pixel of a picture: the RGB image (3 B), its PNG encoding (at most about as
/// large) and the per-band sample buffers; a generous round figure.
pub const BYTES_PER_PIXEL: u64 = 16;

/// Environment variable that lowers the budget (a number of bytes), for tests and for shared
/// machines.
pub const BUDGET_VARIABLE: &str = "PDESHAPE_MAX_MEMORY";

/// `MemAvailable` of `/proc/meminfo` in bytes, where there is one.
pub fn available() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kb.checked_mul(1024)
}

/// The most one request may take: the smallest of [`MAX_REQUEST_BYTES`], half of the memory
/// available now ([`available`]) and the value of [`BUDGET_VARIABLE`] if it is set.
pub fn budget() -> u64 {
    let mut b = MAX_REQUEST_BYTES;
    if let Some(a) = available() {
        b = b.min(a / 2);
    }
    if let Some(v) = std::env::var(BUDGET_VARIABLE)
        .ok()
        .and_then(|v| v.trim().parse::<u64>().ok())
    {
        b = b.min(v);
    }
    b
}

/// Human-readable bytes (`1.5 GB`, `300 MB`).
pub fn describe(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= 1e9 {
        format!("{:.1} GB", b / 1e9)
    } else if b >= 1e6 {
        format!("{:.0} MB", b / 1e6)
    } else {
        format!("{:.0} kB", (b / 1e3).max(1.0))
    }
}

/// Refuses `bytes` (saturated: `None` means more than can be counted) above [`budget`]:
/// `"<what> needs about 8.6 GB of memory; at most 4.3 GB may be used …"` at `place`.
pub fn check(bytes: Option<u64>, what: &str, place: &str) -> Result<()> {
    let limit = budget();
    match bytes {
        Some(b) if b <= limit => Ok(()),
        _ => {
            let need = bytes.map_or("more memory than can be counted".to_string(), |b| {
                format!("about {} of memory", describe(b))
            });
            Err(Error::invalid(format!(
                "{what} needs {need}; at most {} may be used (the smaller of {} and half of \
                 the memory available now)",
                describe(limit),
                describe(MAX_REQUEST_BYTES)
            ))
            .at(place))
        }
    }
}

/// [`check`] for `count` items of `each` bytes.
pub fn check_items(count: u64, each: u64, what: &str, place: &str) -> Result<()> {
    check(count.checked_mul(each), what, place)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_budget_is_at_most_the_cap_and_half_of_what_is_available() {
        let b = budget();
        assert!(b <= MAX_REQUEST_BYTES);
        if let Some(a) = available() {
            assert!(b <= a / 2);
            assert!(a > 0);
        }
    }

    #[test]
    fn requests_above_the_budget_are_refused_with_their_place() {
        assert!(check(Some(1 << 20), "a small grid", "nu").is_ok());
        let e = check(Some(MAX_REQUEST_BYTES + 1), "a 9000 × 9000 grid", "--nu")
            .unwrap_err()
            .to_string();
        assert!(e.contains("--nu"), "{e}");
        assert!(e.contains("a 9000 × 9000 grid needs about 4.3 GB"), "{e}");
        let e = check_items(u64::MAX, 2, "a grid", "nu")
            .unwrap_err()
            .to_string();
        assert!(e.contains("more memory than can be counted"), "{e}");
    }

    #[test]
    fn describe_rounds_to_readable_units() {
        assert_eq!(describe(8_600_000_000), "8.6 GB");
        assert_eq!(describe(300_000_000), "300 MB");
        assert_eq!(describe(12), "1 kB");
    }
}
