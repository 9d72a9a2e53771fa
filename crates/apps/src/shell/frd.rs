//! Reading nodal results from a CalculiX `.frd` file (ASCII).

use crate::{Error, Result};

/// Nodal displacements and stresses of the last increment, by node number.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FrdResults {
    /// Node number → coordinates (the nodes the file lists, expanded shell nodes included).
    pub nodes: std::collections::BTreeMap<u32, [f64; 3]>,
    /// Node number → displacement `[u_x, u_y, u_z]`.
    pub displacements: std::collections::BTreeMap<u32, [f64; 3]>,
    /// `[sxx, syy, szz, sxy, syz, szx]`.
    pub stresses: std::collections::BTreeMap<u32, [f64; 6]>,
}

/// Fixed-width fields of a `-1` record: node number (columns 4–13), then values of 12 columns.
fn record(line: &str, values: usize, lineno: usize) -> Result<(u32, Vec<f64>)> {
    let bad = || Error::invalid(format!("line {lineno}: malformed result record"));
    let id: u32 = line
        .get(3..13)
        .ok_or_else(bad)?
        .trim()
        .parse()
        .map_err(|_| bad())?;
    let mut v = Vec::with_capacity(values);
    for k in 0..values {
        let f = line.get(13 + 12 * k..25 + 12 * k).ok_or_else(bad)?;
        v.push(f.trim().parse().map_err(|_| bad())?);
    }
    Ok((id, v))
}

/// Parses the node block (`2C`) and the `DISP` and `STRESS` result blocks of an `.frd` text.
/// Later blocks of the same kind replace earlier ones (the last increment wins).
pub fn read_frd(text: &str) -> Result<FrdResults> {
    let mut out = FrdResults::default();
    #[derive(PartialEq)]
    enum Block {
        None,
        Nodes,
        Disp,
        Stress,
        Other,
    }
    let mut block = Block::None;
    for (k, line) in text.lines().enumerate() {
        let lineno = k + 1;
        let t = line.trim_start();
        if t.starts_with("2C") {
            block = Block::Nodes;
            out.nodes.clear();
        } else if let Some(rest) = t.strip_prefix("-4") {
            let name = rest.split_whitespace().next().unwrap_or("");
            block = match name {
                "DISP" => {
                    out.displacements.clear();
                    Block::Disp
                }
                "STRESS" => {
                    out.stresses.clear();
                    Block::Stress
                }
                _ => Block::Other,
            };
        } else if t.starts_with("-3") {
            block = Block::None;
        } else if line.starts_with(" -1") {
            match block {
                Block::Nodes => {
                    let (id, v) = record(line, 3, lineno)?;
                    out.nodes.insert(id, [v[0], v[1], v[2]]);
                }
                Block::Disp => {
                    let (id, v) = record(line, 3, lineno)?;
                    out.displacements.insert(id, [v[0], v[1], v[2]]);
                }
                Block::Stress => {
                    let (id, v) = record(line, 6, lineno)?;
                    out.stresses
                        .insert(id, [v[0], v[1], v[2], v[3], v[4], v[5]]);
                }
                _ => {}
            }
        }
    }
    if out.stresses.is_empty() {
        return Err(Error::invalid("the result file holds no nodal stresses"));
    }
    Ok(out)
}
