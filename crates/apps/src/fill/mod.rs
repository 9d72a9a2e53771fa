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
//! A hole one patch cannot span (long, L- or U-shaped) is split along bridging chords between
//! its boundary vertices (`split.rs`): the pieces on either side share the chord's points and
//! its normal field, so they meet G1 along it, and each is filled like a hole (or split again,
//! at most [`MAX_DEPTH`] times deep). A hole whose shortest chord is short against the loop it
//! cuts off is split before one patch is tried.
//!
//! A piece's fill is kept when no triangle comes out with its normal against the patch's, no
//! point of the patch has its normal against the loop's normals carried inside (a harmonic
//! patch of them: a fold of the disk's map, which turns the patch's normal with it), and the
//! normal jump at the loop stays below [`MAX_JUMP`], for one of the ribbons tried
//! ([`RibbonChoice`]).
//!
//! What is refused, with one line naming the place: a mesh that is empty, non-manifold (an edge
//! in three or more triangles, a vertex whose triangles are not one fan: its boundary is not
//! one loop) or inconsistently oriented; a selection of holes that selects none; and a hole
//! that cannot be filled sensibly: a loop through one point twice, a fill that would need more
//! than [`MAX_POINTS`] points, or a piece that no ribbon fills as above when no chord inside it
//! (in the plane square to its mean normal) splits it further, as for a hole that is most of a
//! closed surface. A loop that is most of the mesh's boundary is filled like any other.

mod curvature;
mod hole;
mod loops;
mod measure;
mod split;
mod tessellate;

pub use hole::RibbonChoice;
pub use loops::{boundary_loops, open_edges, BoundaryLoop};
pub use measure::{normal_jump, vertex_normals};
pub use tessellate::MAX_POINTS;

use crate::fit::InputMesh;
use crate::mesh::{Part, TriMesh};
use crate::spec::{DesignSpec, DiskSpec};
use crate::{Error, Result, Vec3};
use curvature::{form, Form};
use std::collections::HashMap;
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
    /// The ribbon the fill kept ([`RibbonChoice`]; `conformal` for G0, which has none;
    /// `mixed` when the pieces of a split hole kept different ones).
    pub ribbon: &'static str,
    /// The patches the hole was filled with: 1, or more when it was split along chords.
    pub pieces: usize,
    /// The largest angle (radians) between the normals of the two patches that meet along a
    /// chord, at the chord's points (0 for a hole in one piece).
    pub chord_g1_angle: f64,
    /// The largest and RMS normal jump (radians) across the chords: the angle between the
    /// area-weighted normals of the two sides' triangles at the chord's points.
    pub chord_jump: (f64, f64),
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
    /// The patches, one per filled hole or piece of a split hole, in the order of `holes`.
    pub patches: Vec<FillPatch>,
}

/// One patch of a fill: the disk patch and the data it was solved from, as a design file's
/// `[[disk]]` table holds them.
#[derive(Clone, Debug, PartialEq)]
pub struct FillPatch {
    /// `hole<k>` (from 1, in the order of the reports), `hole<k>.<j>` for the pieces of a
    /// split hole.
    pub name: String,
    /// The solved patch.
    pub patch: pdeshape_geometry::disk::DiskPatch,
    /// The loop's points (the hole's vertices and chord points).
    pub points: Vec<Vec3>,
    /// The ribbon at the points (G1, G2).
    pub derivatives: Option<Vec<Vec3>>,
    /// `∂²X/∂r²` at the points (G2).
    pub second: Option<Vec<Vec3>>,
    /// Samples per edge of the polyline through the points.
    pub samples_per_edge: usize,
}

impl FillPatch {
    /// The patch as a `[[disk]]` table.
    pub fn disk_spec(&self) -> DiskSpec {
        let list = |v: &[Vec3]| v.iter().map(|p| [p.x, p.y, p.z]).collect::<Vec<_>>();
        DiskSpec {
            name: self.name.clone(),
            order: self.patch.order(),
            points: list(&self.points),
            derivatives: self.derivatives.as_deref().map(list),
            second: self.second.as_deref().map(list),
            samples_per_edge: self.samples_per_edge,
        }
    }
}

impl Filled {
    /// The fill's patches as a design file (one `[[disk]]` table each), titled `title`.
    pub fn design(&self, title: &str) -> DesignSpec {
        DesignSpec {
            title: Some(title.to_string()),
            disk: self.patches.iter().map(FillPatch::disk_spec).collect(),
            ..DesignSpec::default()
        }
    }

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
    let mut work = Work {
        mesh,
        positions: mesh.positions.clone(),
        normals,
        chord_forms: HashMap::new(),
        triangles: mesh.triangles.clone(),
    };
    let mut reports = Vec::with_capacity(chosen.len());
    let mut patches = Vec::new();
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
        let (v0, t0) = (work.positions.len(), work.triangles.len());
        let form_at = |work: &Work, v: u32| -> Option<Form> {
            if (v as usize) < work.mesh.positions.len() {
                let table = neighbours();
                let rings = |w: u32| table.of(w).to_vec();
                form(&work.mesh.positions, &rings, v, work.normals[v as usize])
            } else {
                work.chord_forms.get(&v).copied()
            }
        };
        // The pieces still to fill (the hole, or the two sides of a chord) with their depth.
        let mut stack = vec![(lp.vertices.clone(), 0usize)];
        let mut leaves: Vec<Leaf> = Vec::new();
        let mut chord_points: Vec<u32> = Vec::new();
        while let Some((piece, depth)) = stack.pop() {
            let p: Vec<Vec3> = piece.iter().map(|&v| work.positions[v as usize]).collect();
            let n: Vec<Vec3> = piece.iter().map(|&v| work.normals[v as usize]).collect();
            let chord = if depth < MAX_DEPTH {
                split::best_chord(&p, &n)
            } else {
                None
            };
            // A long piece is split at once; any other is tried in one patch first.
            let split_now = chord.as_ref().is_some_and(|c| c.score < split::SPLIT_BELOW);
            if !split_now {
                let refusal =
                    match fill_piece(&mut work, &form_at, &piece, depth > 0, options, median)
                        .map_err(place)?
                    {
                        Ok(leaf) => {
                            leaves.push(leaf);
                            continue;
                        }
                        Err(refusal) => refusal,
                    };
                if chord.is_none() {
                    let why = if depth >= MAX_DEPTH {
                        format!(" (even split into {} pieces)", 1 << depth)
                    } else if depth > 0 {
                        format!(
                            " (a piece of {} vertices after {depth} splits, and no chord \
                             inside it splits it further)",
                            piece.len()
                        )
                    } else {
                        ", and no chord inside it splits it".into()
                    };
                    return Err(place(Error::invalid(format!("{refusal}{why}"))));
                }
            }
            let Some(chord) = chord else {
                continue;
            };
            // The chord's points, their normals and (G2) forms.
            let first = u32::try_from(work.positions.len())
                .map_err(|_| Error::invalid("the mesh has too many vertices"))?;
            let ends = [piece[chord.a], piece[chord.b]];
            if options.continuity == Continuity::G2 {
                let fa = form_at(&work, ends[0]);
                let fb = form_at(&work, ends[1]);
                if let (Some(fa), Some(fb)) = (fa, fb) {
                    for (i, (&t, &nv)) in chord.params.iter().zip(&chord.normals).enumerate() {
                        work.chord_forms
                            .insert(first + i as u32, split::interpolate_form(&fa, &fb, t, nv));
                    }
                }
            }
            work.positions.extend_from_slice(&chord.points);
            work.normals.extend_from_slice(&chord.normals);
            let inner: Vec<u32> = (0..chord.points.len() as u32).map(|i| first + i).collect();
            chord_points.extend_from_slice(&inner);
            // Piece one: a … b along the loop, then the chord back from b to a; piece two:
            // b … a along the loop, then the chord from a to b.
            let s = piece.len();
            let mut one: Vec<u32> = (chord.a..=chord.b).map(|i| piece[i]).collect();
            one.extend(inner.iter().rev());
            let mut two: Vec<u32> = (chord.b..chord.a + s + 1).map(|i| piece[i % s]).collect();
            two.extend(inner.iter());
            stack.push((two, depth + 1));
            stack.push((one, depth + 1));
        }
        // Along the chords: the two patches' normals at each chord point, and the two sides'
        // triangles' normals.
        let (chord_g1_angle, chord_jump) = chord_measures(&work, &leaves, &chord_points);
        let jump = normal_jump(
            &work.positions,
            &work.triangles[t0..],
            &mesh.triangles,
            &lp.vertices,
        );
        let ribbon = if leaves.iter().all(|l| l.ribbon == leaves[0].ribbon) {
            leaves[0].ribbon.name()
        } else {
            "mixed"
        };
        let number = reports.len() + 1;
        let many = leaves.len() > 1;
        for (j, leaf) in leaves.iter().enumerate() {
            patches.push(FillPatch {
                name: if many {
                    format!("hole{number}.{}", j + 1)
                } else {
                    format!("hole{number}")
                },
                patch: leaf.patch.clone(),
                points: leaf.data.points.clone(),
                derivatives: leaf.data.derivatives.clone(),
                second: leaf.data.second.clone(),
                samples_per_edge: hole::OVERSAMPLE,
            });
        }
        reports.push(HoleReport {
            first_vertex: lp.vertices[0],
            boundary_vertices: lp.vertices.len(),
            length: lp.length,
            vertices_added: work.positions.len() - v0,
            triangles_added: work.triangles.len() - t0,
            g1_angle: leaves.iter().map(|l| l.g1_angle).fold(0.0, f64::max),
            ribbon,
            normal_jump: jump,
            pieces: leaves.len(),
            chord_g1_angle,
            chord_jump,
            seconds: start.elapsed().as_secs_f64(),
        });
    }
    let Work {
        positions,
        triangles,
        ..
    } = work;
    let open = open_edges(&triangles);
    Ok(Filled {
        positions,
        mesh_triangles: mesh.triangles.len(),
        triangles,
        holes: reports,
        holes_found: loops.len(),
        open_edges: open,
        patches,
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

/// The deepest a hole is split: at most `2^MAX_DEPTH` pieces.
pub const MAX_DEPTH: usize = 5;

/// The state of a fill: the mesh, then every fill's points (chord points among them) and
/// triangles so far.
struct Work<'a> {
    mesh: &'a InputMesh,
    positions: Vec<Vec3>,
    /// A normal per point of `positions`: the mesh's vertex normals, a chord's normal field at
    /// its points, zero at a patch's interior points.
    normals: Vec<Vec3>,
    /// The second fundamental form at chord points (G2).
    chord_forms: HashMap<u32, Form>,
    triangles: Vec<[u32; 3]>,
}

/// One filled piece of a hole.
struct Leaf {
    /// The patch and its data.
    patch: pdeshape_geometry::disk::DiskPatch,
    data: hole::VertexData,
    /// The piece's loop and the patch's unit normal at each of its vertices.
    vertices: Vec<u32>,
    patch_normals: Vec<Vec3>,
    /// Its triangles in the work's list.
    triangles: std::ops::Range<usize>,
    ribbon: RibbonChoice,
    g1_angle: f64,
}

/// Fills one piece (a hole's loop or a part of it) with one disk patch: the ribbons in turn
/// (one for G0; [`RibbonChoice::PIECES`]' order for the pieces of a split hole) until a tessellation neither folds nor meets the mesh at a crease; the piece
/// is added to `work`. `Ok(Err(why))` when no ribbon gives such a fill; `Err` for a loop that
/// cannot be filled at all.
fn fill_piece(
    work: &mut Work,
    form_at: &dyn Fn(&Work, u32) -> Option<Form>,
    piece: &[u32],
    split: bool,
    options: &FillOptions,
    median: f64,
) -> Result<std::result::Result<Leaf, String>> {
    let base = u32::try_from(work.positions.len())
        .map_err(|_| Error::invalid("the mesh has too many vertices"))?;
    let choices: &[RibbonChoice] = if options.continuity == Continuity::G0 {
        &RibbonChoice::ALL[..1]
    } else if split {
        &RibbonChoice::PIECES
    } else {
        &RibbonChoice::ALL
    };
    let mut fewest: Option<(usize, usize)> = None;
    let mut crease = f64::INFINITY;
    for &ribbon in choices {
        let hole = hole::build(
            &work.positions,
            &work.normals,
            &|v| form_at(work, v),
            piece,
            options.continuity,
            ribbon,
        )?;
        let t = tessellate::tessellate(&hole, &work.positions, base, options.grading, median)?;
        if t.folded > 0 {
            if fewest.is_none_or(|(f, _)| t.folded < f) {
                fewest = Some((t.folded, t.triangles.len()));
            }
            continue;
        }
        // A fill that bends over the mesh (a hole that is not convex enough) meets it at a
        // crease.
        let n0 = work.positions.len();
        work.positions.extend_from_slice(&t.positions);
        let jump = normal_jump(&work.positions, &t.triangles, &work.mesh.triangles, piece);
        if jump.0 > MAX_JUMP {
            work.positions.truncate(n0);
            crease = crease.min(jump.0);
            continue;
        }
        work.normals.resize(work.positions.len(), Vec3::zeros());
        let first = work.triangles.len();
        work.triangles.extend_from_slice(&t.triangles);
        return Ok(Ok(Leaf {
            patch: hole.patch.clone(),
            data: hole.data.clone(),
            vertices: piece.to_vec(),
            patch_normals: hole
                .boundary
                .iter()
                .map(|b| b.xr.cross(&b.xt).normalize())
                .collect(),
            triangles: first..work.triangles.len(),
            ribbon,
            g1_angle: hole.g1_angle,
        }));
    }
    Ok(Err(match fewest {
        Some((folded, of)) if crease.is_infinite() => format!(
            "the hole is too long or too winding for one disk patch: its map folds (at best \
             {folded} of the fill's {of} triangles face against the patch)"
        ),
        _ => format!(
            "the hole is too long or too winding for one disk patch: its map folds or meets \
             the mesh at a crease (at best {:.0}°, more than {:.0}°)",
            crease.to_degrees(),
            MAX_JUMP.to_degrees()
        ),
    }))
}

/// The G1 of a split hole along its chords: the largest angle between the two patches'
/// normals at the chord points, and the largest and RMS angle between the area-weighted
/// normals of the two sides' triangles there. Zeros for a hole in one piece.
fn chord_measures(work: &Work, leaves: &[Leaf], chord_points: &[u32]) -> (f64, (f64, f64)) {
    if chord_points.is_empty() {
        return (0.0, (0.0, 0.0));
    }
    let slot: HashMap<u32, usize> = chord_points
        .iter()
        .enumerate()
        .map(|(k, &v)| (v, k))
        .collect();
    // Per chord point, per side (in the order the leaves reach it): patch normal, triangles.
    let mut sides: Vec<Vec<(usize, Vec3, Vec3)>> = vec![Vec::new(); chord_points.len()];
    for (l, leaf) in leaves.iter().enumerate() {
        for (&v, &n) in leaf.vertices.iter().zip(&leaf.patch_normals) {
            if let Some(&k) = slot.get(&v) {
                sides[k].push((l, n, Vec3::zeros()));
            }
        }
        for t in &work.triangles[leaf.triangles.clone()] {
            let p = t.map(|i| work.positions[i as usize]);
            let area = (p[1] - p[0]).cross(&(p[2] - p[0]));
            for v in t {
                if let Some(&k) = slot.get(v) {
                    if let Some(side) = sides[k].iter_mut().find(|s| s.0 == l) {
                        side.2 += area;
                    }
                }
            }
        }
    }
    let angle = |a: &Vec3, b: &Vec3| a.cross(b).norm().atan2(a.dot(b));
    let (mut g1, mut worst, mut sq, mut count) = (0.0f64, 0.0f64, 0.0, 0usize);
    for side in &sides {
        if let [a, b] = side.as_slice() {
            g1 = g1.max(angle(&a.1, &b.1));
            if a.2.norm() > 0.0 && b.2.norm() > 0.0 {
                let j = angle(&a.2, &b.2);
                worst = worst.max(j);
                sq += j * j;
                count += 1;
            }
        }
    }
    let rms = if count > 0 {
        (sq / count as f64).sqrt()
    } else {
        0.0
    };
    (g1, (worst, rms))
}
