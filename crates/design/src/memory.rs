//! Memory estimated before it is allocated. Every request whose size a design or a flag chooses
//! (output grids, sample grids, pictures, dense spline systems, dynamic runs, meshes read for
//! fitting, the optimiser's search log, quadrature levels) is priced in bytes first and
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

/// Bytes per grid node and component of a `[dynamic]` run: the banded factorisation of the
/// scheme (seven-entry rows, pivots, factors, scratch and right-hand sides), the solution
/// levels, the final curve and its report. Measured: `pdeshape curve` on one component and
/// 10⁶ intervals peaks at 332 MB resident (12 MB of it the process itself), about 320 B a
/// node with the two frames held; 384 B leaves a margin.
pub const BYTES_PER_DYNAMIC_NODE: u64 = 384;

/// Bytes per grid node of one frame of a dynamic curve kept in memory (a point, 3 × `f64`).
pub const BYTES_PER_FRAME_NODE: u64 = 24;

/// Bytes per element (vertex, face or triangle) of a mesh read for fitting, all stages
/// together: the reader's records (a PLY reader keeps a small map of named properties per
/// element), the welded mesh (24 B a vertex, 12 B a triangle) and its edge map. Measured:
/// `pdeshape fit` of an ASCII PLY of 199 502 vertices and 399 000 faces (14 MB) peaks at
/// 292 MB resident, about 470 B an element besides the file; the same mesh as OBJ at 77 MB.
/// 768 B leaves a margin.
pub const BYTES_PER_MESH_ELEMENT: u64 = 768;

/// Bytes per record of the optimiser's search log besides its parameters (8 B each): phase,
/// chain, level, temperature, value, best and the vector's header.
pub const BYTES_PER_LOG_RECORD: u64 = 96;

/// Bytes per node of the `u` rule of one quadrature level (the rule and one row sum).
pub const BYTES_PER_QUADRATURE_ROW: u64 = 256;

/// Bytes per node of the `v` rule of one quadrature level, besides each worker's row of
/// partials: the surface's row tables (a PDE patch keeps `cos nv`, `sin nv` of every mode for
/// each column; 1024 modes of 16 B at most).
pub const BYTES_PER_QUADRATURE_COLUMN: u64 = 16 * 1024;

/// Environment variable that lowers the budget (a number of bytes), for tests and for shared
/// machines.
pub const BUDGET_VARIABLE: &str = "PDESHAPE_MAX_MEMORY";

/// How long a reading of the available memory stands for "now": requests come by the
/// thousand (a sample grid per piece of a fit) and `/proc/meminfo` costs a system call and a
/// parse each time.
const AVAILABLE_FRESH: std::time::Duration = std::time::Duration::from_millis(100);

/// `MemAvailable` of `/proc/meminfo` in bytes, where there is one, as read within the last
/// [`AVAILABLE_FRESH`].
pub fn available() -> Option<u64> {
    use std::sync::Mutex;
    use std::time::Instant;
    static LAST: Mutex<Option<(Instant, Option<u64>)>> = Mutex::new(None);
    if let Ok(last) = LAST.lock() {
        if let Some((at, bytes)) = *last {
            if at.elapsed() < AVAILABLE_FRESH {
                return bytes;
            }
        }
    }
    let bytes = read_available();
    if let Ok(mut last) = LAST.lock() {
        *last = Some((Instant::now(), bytes));
    }
    bytes
}

/// `MemAvailable` of `/proc/meminfo` in bytes, read now.
fn read_available() -> Option<u64> {
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

/// Human-readable bytes (`1.5 GB`, `300 MB`, `12 kB`, `100 bytes`).
pub fn describe(bytes: u64) -> String {
    let b = bytes as f64;
    if b >= 1e9 {
        format!("{:.1} GB", b / 1e9)
    } else if b >= 1e6 {
        format!("{:.0} MB", b / 1e6)
    } else if b >= 1e3 {
        format!("{:.0} kB", b / 1e3)
    } else {
        format!("{bytes} bytes")
    }
}

/// Whether [`BUDGET_VARIABLE`] sets the budget (it is below the other bounds).
fn budget_from_variable(limit: u64) -> bool {
    std::env::var(BUDGET_VARIABLE)
        .ok()
        .and_then(|v| v.trim().parse::<u64>().ok())
        == Some(limit)
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
            let why = if budget_from_variable(limit) {
                format!("set by {BUDGET_VARIABLE}")
            } else {
                format!(
                    "the smaller of {} and half of the memory available now",
                    describe(MAX_REQUEST_BYTES)
                )
            };
            Err(Error::invalid(format!(
                "{what} needs {need}; at most {} may be used ({why})",
                describe(limit)
            ))
            .at(place))
        }
    }
}

/// [`check`] for `count` items of `each` bytes.
pub fn check_items(count: u64, each: u64, what: &str, place: &str) -> Result<()> {
    check(count.checked_mul(each), what, place)
}

/// The memory of a `[dynamic]` run on `intervals` intervals with `components` components,
/// keeping `frames` frames of the curve at once.
pub fn dynamic_run(intervals: u64, components: u64, frames: u64) -> Option<u64> {
    let per_node = components
        .checked_mul(BYTES_PER_DYNAMIC_NODE)?
        .checked_add(frames.checked_mul(BYTES_PER_FRAME_NODE)?)?;
    intervals.checked_add(1)?.checked_mul(per_node)
}

/// The memory of reading a mesh of `elements` elements (vertices and faces together) from a
/// file of `file_bytes` bytes held in memory.
pub fn mesh_read(file_bytes: u64, elements: u64) -> Option<u64> {
    elements
        .checked_mul(BYTES_PER_MESH_ELEMENT)?
        .checked_add(file_bytes)
}

/// The memory of the optimiser's search log: one record per evaluation, each with its
/// `parameters` values.
pub fn search_log(evaluations: u64, parameters: u64) -> Option<u64> {
    let each = parameters
        .checked_mul(8)?
        .checked_add(BYTES_PER_LOG_RECORD)?;
    evaluations.checked_mul(each)
}

/// The memory of one quadrature level of `u_nodes × v_nodes` nodes summed by `workers`
/// threads, each with a row of partials (six points, 144 B a node).
pub fn quadrature_level(u_nodes: u64, v_nodes: u64, workers: u64) -> Option<u64> {
    let per_column = workers
        .checked_mul(144)?
        .checked_add(BYTES_PER_QUADRATURE_COLUMN)?;
    u_nodes
        .checked_mul(BYTES_PER_QUADRATURE_ROW)?
        .checked_add(v_nodes.checked_mul(per_column)?)
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
    fn the_estimates_add_up_their_items_and_saturate_to_none() {
        // 10 intervals → 11 nodes of 2 components and 3 frames: 11·(2·384 + 3·24).
        assert_eq!(dynamic_run(10, 2, 3), Some(11 * (2 * 384 + 3 * 24)));
        assert_eq!(dynamic_run(u64::MAX, 1, 0), None);
        assert_eq!(mesh_read(1000, 10), Some(1000 + 10 * 768));
        assert_eq!(mesh_read(0, u64::MAX), None);
        assert_eq!(search_log(100, 3), Some(100 * (96 + 24)));
        assert_eq!(search_log(u64::MAX, 1), None);
        assert_eq!(
            quadrature_level(10, 20, 2),
            Some(10 * 256 + 20 * (2 * 144 + 16 * 1024))
        );
        assert_eq!(quadrature_level(1, u64::MAX, 1), None);
    }

    #[test]
    fn describe_rounds_to_readable_units() {
        assert_eq!(describe(8_600_000_000), "8.6 GB");
        assert_eq!(describe(300_000_000), "300 MB");
        assert_eq!(describe(12_345), "12 kB");
        assert_eq!(describe(12), "12 bytes");
    }
}
