//! Filling the holes of a triangle mesh with PDE patches, G1 (tangent-plane continuous) to the
//! mesh, tessellated and welded in: a mesh whose only defects are holes comes out watertight.
//!
//! Per hole ([`boundary_loops`]): the loop's vertices are the boundary samples of a
//! polyharmonic patch on the unit disk (`pdeshape_geometry::disk`: biharmonic for G1, with the
//! ribbon in the mesh's tangent planes; harmonic for G0), which passes through every one of
//! them exactly (`hole.rs`); the patch is tessellated in concentric rings whose outer ring is
//! the loop itself (the mesh's indices, not copies), at the loop's spacing (`tessellate.rs`),
//! and its triangles are appended with the mesh's orientation.
//!
//! What is refused, with one line naming the place: a mesh that is empty, non-manifold (an edge
//! in three or more triangles, a vertex whose triangles are not one fan: its boundary is not
//! one loop) or inconsistently oriented; a selection of holes that selects none; and a hole
//! one patch cannot span sensibly: a loop through one point twice, a fill that would need more
//! than [`MAX_POINTS`] points, or, for every ribbon tried ([`RibbonChoice`]), a triangle of the
//! fill that comes out with its normal against the patch's or a normal jump above [`MAX_JUMP`]
//! at the loop (the disk's map folds or bends over the mesh, as for a loop that is long and
//! thin, winds, or is far from convex in its surface). A loop that is most of the mesh's boundary is filled like any other.

mod curvature;
mod hole;
mod loops;
mod measure;
mod tessellate;

pub use hole::RibbonChoice;
pub use loops::{boundary_loops, open_edges, BoundaryLoop};
pub use measure::{normal_jump, vertex_normals};
pub use tessellate::MAX_POINTS;

use crate::fit::InputMesh;
use crate::mesh::{Part, TriMesh};
use crate::{Error, Result, Vec3};
use std::time::Instant;

/// The largest normal jump (radians) a fill may have at its loop's vertices: a larger one is a
/// crease, where the patch has bent over the mesh beside a concave stretch of the loop.
pub const MAX_JUMP: f64 = 45.0 * std::f64::consts::PI / 180.0;

/// Which holes to fill.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum HoleSelection {
    /// Every hole.
    #[default]
    All,
    /// The `K` longest loops (by length).
    Largest(usize),
    /// The holes with at most this many boundary vertices.
    MaxBoundary(usize),
}

/// How the fill meets the mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Continuity {
    /// Position only: the PDE's natural condition across the loop.
    G0,
    /// Tangent planes: the mesh's normals along the loop (default).
    #[default]
    G1,
    /// Tangent planes and normal curvatures: the mesh's normals and its second fundamental form
    /// (fitted over two rings of neighbours) along the loop.
    G2,
}

/// Options of [`fill_holes`].
#[derive(Clone, Debug, PartialEq)]
pub struct FillOptions {
    /// Which holes.
    pub holes: HoleSelection,
    /// G0, G1 or G2 to the mesh.
    pub continuity: Continuity,
    /// How fast the fill's edges grow from the loop's spacing towards its centre, per ring of
    /// triangles (0: the loop's spacing throughout; 0.1 by default); they never exceed the
    /// mesh's median edge.
    pub grading: f64,
}

impl Default for FillOptions {
    fn default() -> Self {
        FillOptions {
            holes: HoleSelection::All,
            continuity: Continuity::G1,
            grading: 0.1,
        }
    }
}

/// What one hole's fill did.
#[derive(Clone, Debug, PartialEq)]
pub struct HoleReport {
    /// The loop's first (smallest) vertex, counted from 0.
    pub first_vertex: u32,
    /// The loop's vertices.
    pub boundary_vertices: usize,
    /// The loop's length.
    pub length: f64,
    /// Vertices added (the patch's interior points).
    pub vertices_added: usize,
    /// Triangles added.
    pub triangles_added: usize,
    /// The largest angle (radians) between the patch's normal and the mesh's vertex normal at
    /// the loop's vertices; G0 fills measure it too.
    pub g1_angle: f64,
    /// The largest and RMS normal jump (radians) at the loop's vertices: the angle between the
    /// area-weighted normals of the fill's and the mesh's triangles there ([`normal_jump`]).
    pub normal_jump: (f64, f64),
    /// The ribbon the fill kept ([`RibbonChoice`]; `conformal` for G0, which has none).
    pub ribbon: &'static str,
    /// Wall time of the hole (patch, tessellation, measures), seconds.
    pub seconds: f64,
}

/// A mesh with its holes filled.
#[derive(Clone, Debug, PartialEq)]
pub struct Filled {
    /// The mesh's vertices, then each fill's new vertices.
    pub positions: Vec<Vec3>,
    /// The mesh's triangles, then each fill's.
    pub triangles: Vec<[u32; 3]>,
    /// How many of `triangles` are the mesh's own.
    pub mesh_triangles: usize,
    /// One report per filled hole, in the order of [`boundary_loops`].
    pub holes: Vec<HoleReport>,
    /// The holes the mesh had.
    pub holes_found: usize,
    /// Edges used by one triangle after the fill (0: watertight).
    pub open_edges: usize,
}

impl Filled {
    /// The result as a mesh to write: positions in mesh precision, angle-weighted vertex
    /// normals, parts `mesh` and `fill`.
    pub fn to_trimesh(&self) -> TriMesh {
        let normals = vertex_normals(&self.positions, &self.triangles);
        let mut parts = vec![Part {
            name: "mesh".into(),
            triangles: 0..self.mesh_triangles,
        }];
        if self.triangles.len() > self.mesh_triangles {
            parts.push(Part {
                name: "fill".into(),
                triangles: self.mesh_triangles..self.triangles.len(),
            });
        }
        TriMesh {
            positions: self
                .positions
                .iter()
                .map(|p| [p.x as f32, p.y as f32, p.z as f32])
                .collect(),
            normals: normals
                .iter()
                .map(|n| [n.x as f32, n.y as f32, n.z as f32])
                .collect(),
            uv: Vec::new(),
            triangles: self.triangles.clone(),
            parts,
        }
    }
}

/// Fills the holes of `mesh` that `options` selects (module documentation).
pub fn fill_holes(mesh: &InputMesh, options: &FillOptions) -> Result<Filled> {
    if !(options.grading.is_finite() && (0.0..=1.0).contains(&options.grading)) {
        return Err(Error::invalid(format!("is 0 to 1, not {}", options.grading)).at("grading"));
    }
    let loops = boundary_loops(&mesh.positions, &mesh.triangles)?;
    if loops.is_empty() {
        return Err(Error::invalid("the mesh has no holes: it is closed"));
    }
    let mut chosen: Vec<usize> = (0..loops.len()).collect();
    match options.holes {
        HoleSelection::All => {}
        HoleSelection::Largest(k) => {
            if k == 0 {
                return Err(Error::invalid("must be at least 1").at("largest"));
            }
            chosen.sort_by(|&a, &b| loops[b].length.total_cmp(&loops[a].length));
            chosen.truncate(k);
            chosen.sort_unstable();
        }
        HoleSelection::MaxBoundary(max) => {
            chosen.retain(|&k| loops[k].vertices.len() <= max);
            if chosen.is_empty() {
                let smallest = loops.iter().map(|l| l.vertices.len()).min().unwrap_or(0);
                return Err(Error::invalid(format!(
                    "no hole has at most {max} boundary vertices (the smallest of the {} has \
                     {smallest})",
                    loops.len()
                ))
                .at("max-boundary"));
            }
        }
    }
    let normals = vertex_normals(&mesh.positions, &mesh.triangles);
    // The neighbour table only G2's curvature fits read, built once when first asked for.
    let table = std::sync::OnceLock::new();
    let neighbours =
        || table.get_or_init(|| Neighbours::new(mesh.positions.len(), &mesh.triangles));
    let median = median_edge(&mesh.positions, &mesh.triangles);
    let mut positions = mesh.positions.clone();
    let mut triangles = mesh.triangles.clone();
    let mut reports = Vec::with_capacity(chosen.len());
    for &k in &chosen {
        let lp = &loops[k];
        let start = Instant::now();
        let place = |e: Error| {
            Error::invalid(format!(
                "hole {} (at vertex {}, {} boundary vertices): {}",
                k + 1,
                lp.vertices[0] + 1,
                lp.vertices.len(),
                e
            ))
        };
        let base = u32::try_from(positions.len())
            .map_err(|_| Error::invalid("the mesh has too many vertices"))?;
        // The ribbons in turn (one for G0), until a tessellation does not fold.
        let choices: &[RibbonChoice] = if options.continuity == Continuity::G0 {
            &RibbonChoice::ALL[..1]
        } else {
            &RibbonChoice::ALL
        };
        let mut fewest: Option<(usize, usize)> = None;
        let mut crease = f64::INFINITY;
        let mut found = None;
        for &ribbon in choices {
            let hole = hole::build(
                &mesh.positions,
                &normals,
                &neighbours,
                &lp.vertices,
                options.continuity,
                ribbon,
            )
            .map_err(place)?;
            let t = tessellate::tessellate(&hole, &mesh.positions, base, options.grading, median)
                .map_err(place)?;
            if t.folded > 0 {
                if fewest.is_none_or(|(f, _)| t.folded < f) {
                    fewest = Some((t.folded, t.triangles.len()));
                }
                continue;
            }
            // A fill that bends over the mesh (a hole that is not convex enough) meets it at a
            // crease.
            let n0 = positions.len();
            positions.extend_from_slice(&t.positions);
            let jump = normal_jump(&positions, &t.triangles, &mesh.triangles, &lp.vertices);
            positions.truncate(n0);
            if jump.0 > MAX_JUMP {
                crease = crease.min(jump.0);
                continue;
            }
            found = Some((hole, t, ribbon, jump));
            break;
        }
        let Some((hole, t, ribbon, jump)) = found else {
            return Err(place(Error::invalid(match fewest {
                Some((folded, of)) if crease.is_infinite() => format!(
                    "the hole is too long or too winding for one disk patch: its map folds (at \
                     best {folded} of the fill's {of} triangles face against the patch)"
                ),
                _ => format!(
                    "the hole is too long or too winding for one disk patch: its map folds or \
                     meets the mesh at a crease (at best {:.0}°, more than {:.0}°)",
                    crease.to_degrees(),
                    MAX_JUMP.to_degrees()
                ),
            })));
        };
        positions.extend_from_slice(&t.positions);
        triangles.extend_from_slice(&t.triangles);
        reports.push(HoleReport {
            first_vertex: lp.vertices[0],
            boundary_vertices: lp.vertices.len(),
            length: lp.length,
            vertices_added: t.positions.len(),
            triangles_added: t.triangles.len(),
            g1_angle: hole.g1_angle,
            ribbon: ribbon.name(),
            normal_jump: jump,
            seconds: start.elapsed().as_secs_f64(),
        });
    }
    let open = open_edges(&triangles);
    Ok(Filled {
        positions,
        mesh_triangles: mesh.triangles.len(),
        triangles,
        holes: reports,
        holes_found: loops.len(),
        open_edges: open,
    })
}

/// The median length of the mesh's edges (each triangle's three, shared ones twice).
fn median_edge(positions: &[Vec3], triangles: &[[u32; 3]]) -> f64 {
    let mut lengths: Vec<f64> = triangles
        .iter()
        .flat_map(|t| {
            (0..3).map(move |j| {
                (positions[t[(j + 1) % 3] as usize] - positions[t[j] as usize]).norm()
            })
        })
        .collect();
    let mid = lengths.len() / 2;
    lengths.select_nth_unstable_by(mid, f64::total_cmp);
    lengths[mid]
}

/// Each vertex's neighbours (the other vertices of its triangles), in one flat table.
pub(crate) struct Neighbours {
    start: Vec<usize>,
    list: Vec<u32>,
}

impl Neighbours {
    fn new(vertices: usize, triangles: &[[u32; 3]]) -> Self {
        let mut pairs: Vec<(u32, u32)> = Vec::with_capacity(triangles.len() * 6);
        for t in triangles {
            for j in 0..3 {
                pairs.push((t[j], t[(j + 1) % 3]));
                pairs.push((t[(j + 1) % 3], t[j]));
            }
        }
        pairs.sort_unstable();
        pairs.dedup();
        let mut start = vec![0; vertices + 1];
        for &(a, _) in &pairs {
            start[a as usize + 1] += 1;
        }
        for k in 0..vertices {
            start[k + 1] += start[k];
        }
        Neighbours {
            start,
            list: pairs.into_iter().map(|p| p.1).collect(),
        }
    }

    /// The neighbours of `v`.
    pub(crate) fn of(&self, v: u32) -> &[u32] {
        &self.list[self.start[v as usize]..self.start[v as usize + 1]]
    }
}
