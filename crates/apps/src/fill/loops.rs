//! The holes of a triangle mesh: its boundary loops (edges used by one triangle), after the
//! checks that make them well defined: every edge in one or two triangles, used in opposite
//! directions by two (consistent orientation), and the triangles around every vertex one fan.

use crate::{Error, Result, Vec3};
use std::collections::HashMap;

/// One boundary loop of a mesh: a hole.
#[derive(Clone, Debug, PartialEq)]
pub struct BoundaryLoop {
    /// The loop's vertices (indices into the mesh's positions), in the direction of the fill:
    /// each step `vertices[k] → vertices[k + 1]` is the reverse of an edge of the mesh's
    /// triangles, so, seen from the side the mesh's normals point to, the hole lies on the left
    /// (counterclockwise). The first vertex is the smallest index of the loop.
    pub vertices: Vec<u32>,
    /// The loop's length (the sum of its edges).
    pub length: f64,
}

/// The boundary loops of a manifold, consistently oriented triangle mesh, ordered by their
/// first (smallest) vertex.
///
/// Refused, with a message naming the first offender (vertices counted from 1, as in OBJ
/// files): a mesh without triangles, a triangle repeating a vertex, an edge in three or more
/// triangles, an edge two triangles use in the same direction (inconsistent orientation), and
/// a vertex whose triangles do not form one fan (the surface pinches there: its boundary is
/// not one loop). Edges are taken in order of their vertex indices.
pub fn boundary_loops(positions: &[Vec3], triangles: &[[u32; 3]]) -> Result<Vec<BoundaryLoop>> {
    if triangles.is_empty() {
        return Err(Error::invalid("the mesh has no triangles"));
    }
    let n = positions.len();
    for (k, t) in triangles.iter().enumerate() {
        if let Some(&v) = t.iter().find(|&&v| v as usize >= n) {
            return Err(Error::invalid(format!(
                "triangle {} refers to vertex {} but the mesh has {n} vertices",
                k + 1,
                v + 1
            )));
        }
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            return Err(Error::invalid(format!(
                "triangle {} repeats a vertex ({}, {}, {})",
                k + 1,
                t[0] + 1,
                t[1] + 1,
                t[2] + 1
            )));
        }
    }
    // Every edge as (low, high, forward?, triangle), sorted.
    let mut edges: Vec<(u32, u32, bool, u32)> = Vec::with_capacity(triangles.len() * 3);
    for (k, t) in triangles.iter().enumerate() {
        for j in 0..3 {
            let (a, b) = (t[j], t[(j + 1) % 3]);
            edges.push((a.min(b), a.max(b), a < b, k as u32));
        }
    }
    edges.sort_unstable();
    // Directed boundary edges of the mesh, tail → head.
    let mut boundary: Vec<(u32, u32)> = Vec::new();
    let mut i = 0;
    while i < edges.len() {
        let (a, b, fwd, t) = edges[i];
        let mut j = i + 1;
        while j < edges.len() && edges[j].0 == a && edges[j].1 == b {
            j += 1;
        }
        match j - i {
            1 => boundary.push(if fwd { (a, b) } else { (b, a) }),
            2 => {
                if edges[i + 1].2 == fwd {
                    return Err(Error::invalid(format!(
                        "the mesh is not consistently oriented: triangles {} and {} run edge \
                         {}–{} in the same direction",
                        t.min(edges[i + 1].3) + 1,
                        t.max(edges[i + 1].3) + 1,
                        a + 1,
                        b + 1
                    )));
                }
            }
            m => {
                return Err(Error::invalid(format!(
                    "the mesh is not manifold: edge {}–{} is used by {m} triangles",
                    a + 1,
                    b + 1
                )))
            }
        }
        i = j;
    }
    check_fans(triangles)?;
    // Each boundary vertex has one outgoing and one incoming boundary edge (one fan); the
    // fill runs the edges backwards: head → tail.
    let next: HashMap<u32, u32> = boundary.iter().map(|&(a, b)| (b, a)).collect();
    let mut starts: Vec<u32> = next.keys().copied().collect();
    starts.sort_unstable();
    let mut seen: HashMap<u32, ()> = HashMap::with_capacity(starts.len());
    let mut loops = Vec::new();
    for s in starts {
        if seen.contains_key(&s) {
            continue;
        }
        let mut vertices = vec![s];
        seen.insert(s, ());
        let mut length = 0.0;
        let mut at = s;
        loop {
            let to = next[&at];
            length += (positions[to as usize] - positions[at as usize]).norm();
            if to == s {
                break;
            }
            seen.insert(to, ());
            vertices.push(to);
            at = to;
        }
        loops.push(BoundaryLoop { vertices, length });
    }
    Ok(loops)
}

/// Refuses a vertex whose triangles form more than one fan. Each triangle `(v, a, b)` adds
/// the link edge `a → b` to `v`; with the edges checked, the link of every vertex is a union
/// of paths and cycles, one of them exactly when the vertex is manifold.
fn check_fans(triangles: &[[u32; 3]]) -> Result<()> {
    let mut corners: Vec<(u32, u32, u32)> = Vec::with_capacity(triangles.len() * 3);
    for t in triangles {
        for j in 0..3 {
            corners.push((t[j], t[(j + 1) % 3], t[(j + 2) % 3]));
        }
    }
    corners.sort_unstable();
    let mut i = 0;
    while i < corners.len() {
        let v = corners[i].0;
        let mut j = i + 1;
        while j < corners.len() && corners[j].0 == v {
            j += 1;
        }
        let link = &corners[i..j];
        let head_of = |a: u32| link.iter().find(|c| c.1 == a).map(|c| c.2);
        // A path starts at a tail that is no head; a cycle has none.
        let starts: Vec<u32> = link
            .iter()
            .filter(|c| !link.iter().any(|d| d.2 == c.1))
            .map(|c| c.1)
            .collect();
        let fans = if starts.len() > 1 {
            starts.len()
        } else {
            let first = starts.first().copied().unwrap_or(link[0].1);
            let mut count = 0;
            let mut at = first;
            while let Some(b) = head_of(at) {
                count += 1;
                at = b;
                if at == first || count > link.len() {
                    break;
                }
            }
            if count == link.len() {
                1
            } else {
                2
            }
        };
        if fans > 1 {
            return Err(Error::invalid(format!(
                "the mesh is not manifold at vertex {}: its triangles form {}separate fans (the \
                 surface pinches there, its boundary is not one loop)",
                v + 1,
                if starts.len() > 1 {
                    format!("{} ", starts.len())
                } else {
                    String::new()
                }
            )));
        }
        i = j;
    }
    Ok(())
}

/// The number of edges used by exactly one triangle (0: the mesh is closed).
pub fn open_edges(triangles: &[[u32; 3]]) -> usize {
    let mut count: HashMap<(u32, u32), u32> = HashMap::with_capacity(triangles.len() * 2);
    for t in triangles {
        for j in 0..3 {
            let (a, b) = (t[j], t[(j + 1) % 3]);
            *count.entry((a.min(b), a.max(b))).or_insert(0) += 1;
        }
    }
    count.values().filter(|&&c| c == 1).count()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A square of two triangles (counterclockwise seen from +z) and a fan with a hole.
    fn square() -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        (p, vec![[0, 1, 2], [0, 2, 3]])
    }

    #[test]
    fn the_loop_runs_against_the_triangles() {
        let (p, t) = square();
        let loops = boundary_loops(&p, &t).unwrap();
        assert_eq!(loops.len(), 1);
        // The mesh runs 0 → 1 → 2 → 3; the fill runs 0 → 3 → 2 → 1.
        assert_eq!(loops[0].vertices, vec![0, 3, 2, 1]);
        assert!((loops[0].length - 4.0).abs() < 1e-15);
        assert_eq!(open_edges(&t), 4);
    }

    #[test]
    fn bad_meshes_are_refused_naming_the_place() {
        let (p, _) = square();
        let e = boundary_loops(&p, &[]).unwrap_err();
        assert!(e.to_string().contains("no triangles"), "{e}");
        let e = boundary_loops(&p, &[[0, 1, 2], [0, 1, 3], [1, 0, 2]]).unwrap_err();
        assert!(e.to_string().contains("edge 1–2 is used by 3"), "{e}");
        let e = boundary_loops(&p, &[[0, 1, 2], [0, 1, 3]]).unwrap_err();
        assert!(e.to_string().contains("same direction"), "{e}");
        // Two triangles touching at vertex 0 only: a bowtie.
        let mut q = p.clone();
        q.push(Vec3::new(-1.0, 0.0, 0.0));
        q.push(Vec3::new(-1.0, -1.0, 0.0));
        let e = boundary_loops(&q, &[[0, 1, 2], [0, 4, 5]]).unwrap_err();
        assert!(e.to_string().contains("vertex 1"), "{e}");
        let e = boundary_loops(&p, &[[0, 1, 1]]).unwrap_err();
        assert!(e.to_string().contains("repeats"), "{e}");
    }
}
