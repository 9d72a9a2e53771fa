//! The CSV of full-precision grid samples.

use super::blocks::{stream, LINES};
use super::check::check_grids;
use crate::mesh::Samples;
use crate::Result;
use std::io::Write;

/// CSV samples `u,v,x,y,z,nx,ny,nz` (plus `patch` when there are several), rows u-major.
///
/// One row per grid vertex `(i, j)`, `i` outer and `j` inner, with the grid's parameter values
/// `u_i`, `v_j`, the position and the unit normal; with several patches a ninth column holds the
/// 0-based patch number and the patches follow one another. Every number is the shortest decimal
/// text that reads back to the identical `f64`.
pub fn write_csv(samples: &[Samples], w: &mut dyn Write) -> Result<()> {
    check_grids(samples, false)?;
    let several = samples.len() > 1;
    stream(w, "CSV", |out| {
        out.bytes(if several {
            b"u,v,x,y,z,nx,ny,nz,patch\n"
        } else {
            b"u,v,x,y,z,nx,ny,nz\n"
        });
        for (k, g) in samples.iter().enumerate() {
            out.blocks(g.nu * g.nv, LINES / 4, |range, text| {
                for idx in range {
                    let (i, j) = (idx / g.nv, idx % g.nv);
                    text.f64_text(g.u[i]);
                    text.bytes(b",");
                    text.f64_text(g.v[j]);
                    for c in g.positions[idx].into_iter().chain(g.normals[idx]) {
                        text.bytes(b",");
                        text.f64_text(c);
                    }
                    if several {
                        text.bytes(b",");
                        text.uint_text(k as u64);
                    }
                    text.bytes(b"\n");
                }
            })?;
        }
        Ok(())
    })
}
