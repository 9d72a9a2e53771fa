//! The same surface with more vertices, for a layout that needs corners where the mesh has
//! none: the general mode lays a mesh out on its own vertices, so a CAD part whose flat sides
//! are a few long triangles, or a box of twelve, leaves the layout no vertex inside a side,
//! and its patches span the side from edge to edge, leaning into the planes of the rounds and
//! corners at their ends. Both splits put every new vertex on a triangle's edge at its
//! midpoint: the surface is unchanged, and so is every triangle's plane and orientation.

use super::mesh::InputMesh;
use crate::{Result, Vec3};
use std::cmp::Ordering;
use std::collections::{BinaryHeap, HashMap};

/// `mesh` with every triangle split into four at its edges' midpoints (a midpoint shared by
/// the edge's triangles), as many times as it takes to have at least `vertices` used
/// vertices: the mesh and the number of splits.
pub(super) fn split_until(mesh: &InputMesh, vertices: usize) -> Result<(InputMesh, usize)> {
    let mut m = mesh.clone();
    let mut splits = 0;
    while m.used_vertices().iter().filter(|&&u| u).count() < vertices {
        let mut positions = m.positions.clone();
        let mut middle: HashMap<(u32, u32), u32> = HashMap::new();
        let mut mid = |a: u32, b: u32, positions: &mut Vec<Vec3>| -> u32 {
            *middle.entry((a.min(b), a.max(b))).or_insert_with(|| {
                positions.push((positions[a as usize] + positions[b as usize]) * 0.5);
                positions.len() as u32 - 1
            })
        };
        let mut triangles = Vec::with_capacity(4 * m.triangles.len());
        for &[a, b, c] in &m.triangles {
            let (ab, bc, ca) = (
                mid(a, b, &mut positions),
                mid(b, c, &mut positions),
                mid(c, a, &mut positions),
            );
            triangles.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        m = InputMesh::new(positions, triangles)?;
        splits += 1;
    }
    Ok((m, splits))
}

/// An edge waiting to be bisected, longest first.
struct Long {
    length: f64,
    ends: (u32, u32),
}

impl PartialEq for Long {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Long {}
impl PartialOrd for Long {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Long {
    fn cmp(&self, other: &Self) -> Ordering {
        self.length
            .total_cmp(&other.length)
            .then_with(|| other.ends.cmp(&self.ends))
    }
}

/// `mesh` with its edges longer than `longest` bisected, the longest first, until none is or
/// the mesh has `max_triangles` triangles: the mesh and the number of bisections.
///
/// A bisection splits every triangle on the edge in two at the edge's midpoint, through its
/// opposite corner, so the mesh stays conforming (no T-junction) and each triangle keeps its
/// orientation. Taking the longest edge of the whole mesh first means each bisected edge is
/// the longest of its triangles (any longer one would have gone before), which is Rivara's
/// longest-edge bisection: no angle of the refined mesh falls below half the smallest angle
/// of the triangle it came from (a sliver's pieces keep at least half its sharpest corner).
pub(super) fn split_long(
    mesh: &InputMesh,
    longest: f64,
    max_triangles: usize,
) -> Result<(InputMesh, usize)> {
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    let mut positions = mesh.positions.clone();
    let mut triangles = mesh.triangles.clone();
    // The triangles on each edge (two on a manifold edge, one on the boundary).
    let mut on: HashMap<(u32, u32), Vec<u32>> = HashMap::with_capacity(3 * triangles.len() / 2);
    for (t, tri) in triangles.iter().enumerate() {
        for c in 0..3 {
            on.entry(key(tri[c], tri[(c + 1) % 3]))
                .or_default()
                .push(t as u32);
        }
    }
    let length = |p: &[Vec3], (a, b): (u32, u32)| (p[a as usize] - p[b as usize]).norm();
    let mut queue: BinaryHeap<Long> = on
        .keys()
        .filter_map(|&ends| {
            let length = length(&positions, ends);
            (length > longest).then_some(Long { length, ends })
        })
        .collect();
    let mut bisections = 0;
    while let Some(Long { ends: (a, b), .. }) = queue.pop() {
        let Some(around) = on.remove(&(a, b)) else {
            continue;
        };
        if triangles.len() + around.len() > max_triangles {
            break;
        }
        let m = positions.len() as u32;
        positions.push((positions[a as usize] + positions[b as usize]) * 0.5);
        let mut fresh = vec![key(a, m), key(m, b)];
        for t in around {
            let tri = triangles[t as usize];
            // The triangle turned so that its side from `p` to `q` is the edge; `r` opposite.
            let Some(i) = (0..3).find(|&i| key(tri[i], tri[(i + 1) % 3]) == (a, b)) else {
                continue;
            };
            let (p, q, r) = (tri[i], tri[(i + 1) % 3], tri[(i + 2) % 3]);
            let u = triangles.len() as u32;
            triangles[t as usize] = [p, m, r];
            triangles.push([m, q, r]);
            on.entry(key(p, m)).or_default().push(t);
            on.entry(key(m, q)).or_default().push(u);
            on.entry(key(m, r)).or_default().extend([t, u]);
            if let Some(list) = on.get_mut(&key(q, r)) {
                for x in list.iter_mut().filter(|x| **x == t) {
                    *x = u;
                }
            }
            fresh.push(key(m, r));
        }
        for ends in fresh {
            let length = length(&positions, ends);
            if length > longest {
                queue.push(Long { length, ends });
            }
        }
        bisections += 1;
    }
    Ok((InputMesh::new(positions, triangles)?, bisections))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::features::tests::unit_box;
    use std::collections::HashSet;

    /// Each undirected edge's directed uses: a closed, consistently oriented mesh uses every
    /// edge once each way.
    fn directed(mesh: &InputMesh) -> HashMap<(u32, u32), usize> {
        let mut uses = HashMap::new();
        for t in &mesh.triangles {
            for c in 0..3 {
                *uses.entry((t[c], t[(c + 1) % 3])).or_default() += 1;
            }
        }
        uses
    }

    fn area_vector(mesh: &InputMesh) -> (f64, Vec3) {
        let mut area = 0.0;
        let mut sum = Vec3::zeros();
        for t in 0..mesh.triangles.len() {
            let [a, b, c] = mesh.corners(t);
            let n = (b - a).cross(&(c - a));
            area += 0.5 * n.norm();
            sum += n;
        }
        (area, sum)
    }

    fn smallest_angle(mesh: &InputMesh) -> f64 {
        let mut least = f64::INFINITY;
        for t in 0..mesh.triangles.len() {
            let p = mesh.corners(t);
            for c in 0..3 {
                let (x, y) = (p[(c + 1) % 3] - p[c], p[(c + 2) % 3] - p[c]);
                least = least.min(x.angle(&y));
            }
        }
        least
    }

    /// The unit box split until no edge is longer than 0.3: the same closed, oriented surface
    /// (area 6, volume 1, every directed edge once), every vertex on a side, no edge over the
    /// bound, and no angle below half the box's smallest (45°: Rivara's bound).
    #[test]
    fn long_edges_of_a_box_are_bisected_on_its_sides() {
        let mesh = unit_box();
        let (fine, bisections) = split_long(&mesh, 0.3, usize::MAX).unwrap();
        assert!(bisections > 0);
        assert_eq!(fine.positions.len(), 8 + bisections);
        fine.require_closed().unwrap();
        assert!(directed(&fine).values().all(|&k| k == 1));
        let (area, sum) = area_vector(&fine);
        assert!((area - 6.0).abs() < 1e-13, "{area}");
        assert!(sum.norm() < 1e-13);
        assert!((fine.signed_volume() - 1.0).abs() < 1e-13);
        assert!(fine.positions.iter().all(|q| {
            let on = |c: f64| c.abs() < 1e-15 || (c - 1.0).abs() < 1e-15;
            on(q.x) || on(q.y) || on(q.z)
        }));
        let mut edges = HashSet::new();
        for t in &fine.triangles {
            for c in 0..3 {
                let (a, b) = (t[c], t[(c + 1) % 3]);
                edges.insert((a.min(b), a.max(b)));
            }
        }
        for (a, b) in edges {
            let l = (fine.positions[a as usize] - fine.positions[b as usize]).norm();
            assert!(l <= 0.3, "{l}");
        }
        let least = smallest_angle(&fine).to_degrees();
        assert!(least >= 22.5 - 1e-9, "{least}");
    }

    /// An open sheet of two slivers (1 by 0.02): the boundary stays one loop, every edge is
    /// within the bound, the sheet's area and normal are kept, and the triangle cap stops the
    /// bisections where it says.
    #[test]
    fn a_sliver_sheet_is_cut_across_its_length_and_the_cap_holds() {
        let p = |x: f64, y: f64| Vec3::new(x, y, 0.0);
        let mesh = InputMesh::new(
            vec![p(0.0, 0.0), p(1.0, 0.0), p(1.0, 0.02), p(0.0, 0.02)],
            vec![[0, 1, 2], [0, 2, 3]],
        )
        .unwrap();
        let (fine, _) = split_long(&mesh, 0.1, usize::MAX).unwrap();
        assert_eq!(fine.boundary_loops().unwrap().len(), 1);
        let (area, sum) = area_vector(&fine);
        assert!((area - 0.02).abs() < 1e-15, "{area}");
        assert!((sum - Vec3::new(0.0, 0.0, 0.04)).norm() < 1e-15);
        assert!(directed(&fine).values().all(|&k| k == 1));
        for t in 0..fine.triangles.len() {
            let c = fine.corners(t);
            for k in 0..3 {
                assert!((c[k] - c[(k + 1) % 3]).norm() <= 0.1);
            }
        }
        // At least 1/0.1 pieces along each long side.
        assert!(fine.triangles.len() >= 20, "{}", fine.triangles.len());
        // A bisection adds a triangle per triangle on its edge: the cap of 9 stops them at 8
        // or 9, on the same sheet.
        let (capped, bisections) = split_long(&mesh, 0.1, 9).unwrap();
        assert!(
            (8..=9).contains(&capped.triangles.len()),
            "{}",
            capped.triangles.len()
        );
        assert_eq!(capped.positions.len(), 4 + bisections);
        assert!((area_vector(&capped).0 - 0.02).abs() < 1e-15);
    }
}
