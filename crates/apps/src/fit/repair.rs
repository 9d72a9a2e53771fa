//! Repairs of meshes as files deliver them, before a fit: what the modelling tool or the scanner
//! left that is not a surface, removed or mended, each kind counted so the command can say what
//! it did (and where: a point in the mesh's own coordinates).
//!
//! In order:
//! 1. **Degenerate triangles** (a repeated corner, or no area at all) are dropped.
//! 2. **Duplicate triangles** (the same three corners, in any order) keep the first.
//! 3. **Cracks**: boundary vertices closer than the crack tolerance to another boundary vertex
//!    are welded to it. The tolerance is [`CRACK_FRACTION`] of the bounding-box diagonal, and at
//!    most a quarter of the shortest boundary edge at either vertex, so that no edge of the
//!    surface collapses.
//! 4. **T-junctions**: a boundary vertex lying on a boundary edge of another triangle (within the
//!    same tolerance, and away from the edge's ends) splits that triangle there, so both sides
//!    of the seam share the vertex. Repeated until no such vertex is left (at most
//!    [`MAX_PASSES`] times).
//! 5. **Non-manifold edges** (three or more triangles): where the triangles fall in pieces of
//!    two each (parts of an assembly touching along an edge), the parts are split apart there,
//!    every part but the largest taking its own copies of the edge's vertices, and keep all
//!    their triangles. Elsewhere the two triangles of the largest manifold pieces stay (pieces
//!    joined across edges of exactly two triangles), the others are dropped: a fin or a stray
//!    triangle glued to the surface goes, the surface stays. A file whose repair would drop
//!    more than [`MAX_NONMANIFOLD_SHARE`] of its triangles is refused (a volume mesh's cells,
//!    not a surface).
//! 6. **Pinched vertices**: a vertex whose triangles make several fans (pieces of the surface
//!    that touch at the vertex only: a scan's tiny pocket hanging from one point, a fin of a
//!    few triangles, two sheets of a surface touching) is cut, one vertex per fan at the same
//!    place, for the next step to see its pieces apart.
//! 7. **Stray pieces**: connected components smaller than [`STRAY_SHARE`] of the largest in
//!    triangles and than [`STRAY_EXTENT`] of it across are dropped (specks of a scan), and so
//!    are pieces cut off at a pinched vertex that are smaller than [`STRAY_SHARE`] of the
//!    largest in triangles, whatever their extent (a pocket hanging from a point is a defect,
//!    not a part: a scan's tetrahedral bubble, which no collapse can remove without flattening
//!    it into two triangles back to back, blocked the Stanford dragon's layouts). Components
//!    of comparable size or extent stay: the fit decides what to do with several bodies. The
//!    cut vertices of the pieces that stay are joined again (a pinch between two large sheets
//!    is left as the file has it).
//! 8. **Orientation**: across every edge of two triangles, the two must run the edge opposite
//!    ways. Walking each piece (joined across such edges) from its first triangle, a triangle
//!    that disagrees with the one it was reached from is flipped; a piece most of whose
//!    triangles were flipped is flipped back whole, so the file's own majority orientation
//!    stays. A piece that cannot be oriented (a crude decimation's folded triangles: an edge
//!    still run the same way by its two triangles after the walk) loses the later-reached
//!    triangle at each such edge when those are at most [`FOLD_SHARE`] of it, and the rest
//!    is oriented by the walk's flips (every other edge agrees with them). A piece that would
//!    lose more (a Möbius band of a few quads, a Klein bottle) is left as it is, and the
//!    general mode refuses it with a point. (When dropping was not bounded so, a Klein bottle
//!    became a surface whose layouts kept failing round after round for minutes; the general
//!    mode's rounds are now bounded by their work as well.)
//!
//! Nothing is moved: vertices keep their positions (a welded vertex takes the position of the
//! one it joins), so the repaired mesh is the file's surface with its defects removed.

use super::frame::FileFrame;
use super::mesh::{InputMesh, MeshRead};
use crate::{Error, Result, Vec3};
use std::collections::HashMap;

/// Boundary vertices closer than this fraction of the bounding-box diagonal are one vertex, and
/// a boundary vertex this close to a boundary edge lies on it.
pub const CRACK_FRACTION: f64 = 1e-4;

/// Components with fewer triangles than this share of the largest one, and smaller across
/// than [`STRAY_EXTENT`] of it, are stray.
pub const STRAY_SHARE: f64 = 0.01;

/// Components whose bounding box's diagonal is at least this share of the largest
/// component's stay, however few their triangles: a part of a high-resolution scan (a pair of
/// glasses beside a bust) is not a speck, and the fit would miss it by its distance from the
/// rest.
pub const STRAY_EXTENT: f64 = 0.01;

/// The largest share of a piece's triangles that may be dropped to make it orientable (a
/// piece that needs more, a Möbius band of a few quads, is left as it is).
pub const FOLD_SHARE: f64 = 0.01;

/// The largest share of the triangles the non-manifold edges' repair may drop: beyond it the
/// file is not a surface with a few fins and strays but something else (the faces of a volume
/// mesh's cells, every inner face shared by two cells and each edge by four or more: a grid
/// of 20³ cubes loses 70 % of its triangles), and what the repair would leave is not the
/// object. (A building of three boxes stacked face to face loses the 31 % between them, and
/// what is left is its outside.)
pub const MAX_NONMANIFOLD_SHARE: f64 = 0.5;

/// Passes of the T-junction split at most (each splits every edge it can).
pub const MAX_PASSES: usize = 8;

/// What [`repair`] did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Repairs {
    /// Triangles dropped for a repeated corner or no area.
    pub degenerate: usize,
    /// Triangles dropped as copies of another.
    pub duplicates: usize,
    /// Boundary vertices welded across cracks.
    pub cracks: usize,
    /// Boundary vertices that split a triangle's edge (T-junctions).
    pub t_junctions: usize,
    /// Edges where parts touched (each with its two triangles there), split apart.
    pub touching: usize,
    /// Edges that had three or more triangles.
    pub nonmanifold_edges: usize,
    /// Triangles dropped at those edges.
    pub nonmanifold_dropped: usize,
    /// Pieces hanging from the surface by one vertex (a pinch), dropped.
    pub pinched: usize,
    /// Triangles of those pieces.
    pub pinched_triangles: usize,
    /// Components dropped as stray, and their triangles.
    pub stray_components: usize,
    /// Triangles of the stray components.
    pub stray_triangles: usize,
    /// Triangles flipped to run their edges opposite to their neighbours.
    pub flipped: usize,
    /// Triangles dropped where they fold against their neighbours so that no flipping orients
    /// their piece (a crude decimation's folds), at most [`FOLD_SHARE`] of the piece.
    pub folded: usize,
    /// A point of the first repair, in the mesh's (design) coordinates.
    pub first: Option<Vec3>,
    /// The frame of the file the mesh was read from: the note names `first` in its
    /// coordinates.
    pub file: FileFrame,
}

impl Repairs {
    /// True when nothing was repaired.
    pub fn is_empty(&self) -> bool {
        self.first.is_none()
    }

    /// One line for the user, `None` when nothing was repaired.
    pub fn note(&self) -> Option<String> {
        let p = self.first?;
        let mut parts = Vec::new();
        let plural =
            |n: usize, one: &str, many: &str| format!("{n} {}", if n == 1 { one } else { many });
        if self.degenerate > 0 {
            parts.push(format!(
                "{} dropped",
                plural(
                    self.degenerate,
                    "degenerate triangle",
                    "degenerate triangles"
                )
            ));
        }
        if self.duplicates > 0 {
            parts.push(format!(
                "{} dropped",
                plural(self.duplicates, "duplicate triangle", "duplicate triangles")
            ));
        }
        if self.cracks > 0 {
            parts.push(format!(
                "{} welded across cracks",
                plural(self.cracks, "vertex", "vertices")
            ));
        }
        if self.t_junctions > 0 {
            parts.push(plural(
                self.t_junctions,
                "T-junction split",
                "T-junctions split",
            ));
        }
        if self.touching > 0 {
            parts.push(format!(
                "{} where parts touch split apart",
                plural(self.touching, "edge", "edges")
            ));
        }
        if self.nonmanifold_edges > 0 {
            parts.push(format!(
                "{} made manifold by dropping {}",
                plural(self.nonmanifold_edges, "edge", "edges"),
                plural(self.nonmanifold_dropped, "triangle", "triangles")
            ));
        }
        if self.pinched > 0 {
            parts.push(format!(
                "{} by a single vertex ({}) dropped",
                plural(self.pinched, "piece hanging", "pieces hanging"),
                plural(self.pinched_triangles, "triangle", "triangles")
            ));
        }
        if self.stray_components > 0 {
            parts.push(format!(
                "{} of {} dropped",
                plural(self.stray_components, "stray piece", "stray pieces"),
                plural(self.stray_triangles, "triangle", "triangles")
            ));
        }
        if self.folded > 0 {
            parts.push(format!(
                "{} dropped at folds that no flipping orients",
                plural(self.folded, "triangle", "triangles")
            ));
        }
        if self.flipped > 0 {
            parts.push(format!(
                "{} flipped to agree with their neighbours",
                plural(self.flipped, "triangle", "triangles")
            ));
        }
        Some(format!(
            "repaired: {} (the first near {})",
            parts.join(", "),
            self.file.point(p)
        ))
    }
}

impl MeshRead {
    /// The mesh [`repair`]ed, with one phrase for each of what the reader
    /// ([`MeshRead::note`]) and the repairs ([`Repairs::note`]) did: what a fit reports of its
    /// input.
    pub fn repaired(&self) -> Result<(InputMesh, Vec<String>)> {
        let (mesh, repairs) = repair_in(&self.mesh, self.file)?;
        let notes = self.note().into_iter().chain(repairs.note()).collect();
        Ok((mesh, notes))
    }
}

/// The mesh with the defects of the module documentation removed, and what was done (a mesh
/// read from a file: [`MeshRead::repaired`], whose messages name points in the file's frame).
pub fn repair(mesh: &InputMesh) -> Result<(InputMesh, Repairs)> {
    repair_in(mesh, FileFrame::default())
}

/// [`repair`], its messages naming points in the coordinates of the file `file` describes.
fn repair_in(mesh: &InputMesh, file: FileFrame) -> Result<(InputMesh, Repairs)> {
    let mut r = Repairs {
        file,
        ..Repairs::default()
    };
    let mut positions = mesh.positions.clone();
    let diag = mesh.diagonal();

    // 1–2. Degenerate and duplicate triangles (duplicates found by sorting, not hashing: a
    // mesh of a million triangles is repaired in a fraction of a second).
    let tiny = (1e-12 * diag).powi(2);
    let mut keyed: Vec<([u32; 3], usize)> = Vec::with_capacity(mesh.triangles.len());
    for (i, t) in mesh.triangles.iter().enumerate() {
        let [a, b, c] = t.map(|i| positions[i as usize]);
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || (b - a).cross(&(c - a)).norm() <= tiny {
            r.degenerate += 1;
            note_at(&mut r, centroid(&positions, t));
            continue;
        }
        let mut key = *t;
        key.sort_unstable();
        keyed.push((key, i));
    }
    keyed.sort_unstable();
    let mut keep = vec![false; mesh.triangles.len()];
    for (k, &(key, i)) in keyed.iter().enumerate() {
        if k > 0 && keyed[k - 1].0 == key {
            r.duplicates += 1;
            note_at(&mut r, centroid(&positions, &mesh.triangles[i]));
        } else {
            keep[i] = true;
        }
    }
    let mut triangles: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .zip(&keep)
        .filter(|(_, &k)| k)
        .map(|(t, _)| *t)
        .collect();

    // 3. Cracks: boundary vertices welded to a close boundary vertex.
    let tol = CRACK_FRACTION * diag;
    let (boundary, nonmanifold) = edge_kinds(&triangles);
    let mut shortest: HashMap<u32, f64> = HashMap::new();
    for &(a, b) in &boundary {
        let l = (positions[a as usize] - positions[b as usize]).norm();
        for v in [a, b] {
            let e = shortest.entry(v).or_insert(f64::INFINITY);
            *e = e.min(l);
        }
    }
    let mut verts: Vec<u32> = shortest.keys().copied().collect();
    verts.sort_unstable();
    let grid = Grid::new(tol.max(f64::MIN_POSITIVE));
    let mut cells: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    let mut map: HashMap<u32, u32> = HashMap::new();
    for &v in &verts {
        let p = positions[v as usize];
        let reach = tol.min(0.25 * shortest[&v]);
        let found = grid.around(&p).into_iter().find_map(|c| {
            cells.get(&c)?.iter().copied().find(|&w| {
                let d = (positions[w as usize] - p).norm();
                d <= reach && d <= 0.25 * shortest[&w]
            })
        });
        match found {
            Some(w) => {
                map.insert(v, w);
                r.cracks += 1;
                note_at(&mut r, p);
            }
            None => cells.entry(grid.cell(&p)).or_default().push(v),
        }
    }
    if !map.is_empty() {
        let mut kept = Vec::with_capacity(triangles.len());
        for t in &triangles {
            let t = t.map(|i| *map.get(&i).unwrap_or(&i));
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                r.degenerate += 1;
                continue;
            }
            kept.push(t);
        }
        triangles = kept;
    }

    // 4. T-junctions.
    for _ in 0..if boundary.is_empty() { 0 } else { MAX_PASSES } {
        let split = split_t_junctions(&positions, &mut triangles, tol);
        if split.is_empty() {
            break;
        }
        r.t_junctions += split.len();
        note_at(&mut r, positions[split[0] as usize]);
    }

    // 5. Non-manifold edges (looked for again only if the steps before changed the edges):
    // parts touching along an edge split apart there, then the rest resolved.
    let changed = r.cracks > 0 || r.t_junctions > 0;
    let pieces = (nonmanifold > 0 || changed)
        .then(|| EdgePieces::new(&triangles))
        .flatten();
    if let Some(mut pieces) = pieces {
        let (split, first) = unzip_touching(&mut pieces, &mut positions, &mut triangles);
        if let Some(p) = first {
            r.touching = split;
            note_at(&mut r, p);
        }
        // The split edges have two triangles each now: what is left, looked at again.
        let rest = if split > 0 {
            EdgePieces::new(&triangles)
        } else {
            Some(pieces)
        };
        if let Some(rest) = rest {
            let (kept, edges, dropped) = resolve_nonmanifold(&triangles, rest);
            let at = centroid(&positions, &triangles[dropped[0]]);
            if dropped.len() as f64 > MAX_NONMANIFOLD_SHARE * triangles.len() as f64 {
                return Err(Error::invalid(format!(
                    "the mesh is not one surface: {edges} of its edges are shared by three or \
                     more triangles (the first near {}), and making it manifold would drop {} of \
                     its {} triangles (a volume mesh's cells, or surfaces overlapping face to \
                     face): export the object's outer surface alone",
                    file.point(at),
                    dropped.len(),
                    triangles.len()
                )));
            }
            r.nonmanifold_edges = edges;
            r.nonmanifold_dropped = dropped.len();
            note_at(&mut r, at);
            triangles = kept;
        }
    }

    // 6. Pinched vertices cut (their copies from `copies` on, each of `origin`).
    let copies = positions.len();
    let origin = split_pinches(&mut positions, &mut triangles);

    // 7. Stray pieces, and pieces hanging by a vertex; the cuts of the rest joined again.
    let (kept, dropped) = drop_stray(&triangles, &positions, copies);
    for d in &dropped {
        if d.cut {
            r.pinched += 1;
            r.pinched_triangles += d.triangles;
        } else {
            r.stray_components += 1;
            r.stray_triangles += d.triangles;
        }
        note_at(&mut r, centroid(&positions, &triangles[d.first]));
    }
    if !dropped.is_empty() {
        triangles = kept;
    }
    for t in &mut triangles {
        for c in t.iter_mut() {
            if *c as usize >= copies {
                *c = origin[*c as usize - copies];
            }
        }
    }
    positions.truncate(copies);

    // 8. Orientation.
    let (flipped, folded) = orient(&positions, &mut triangles);
    if let Some(&first) = folded.first() {
        r.folded = folded.len();
        note_at(&mut r, centroid(&positions, &triangles[first]));
    }
    if let Some(&first) = flipped.first() {
        r.flipped = flipped.len();
        note_at(&mut r, centroid(&positions, &triangles[first]));
    }
    if !folded.is_empty() {
        let mut keep = vec![true; triangles.len()];
        for &t in &folded {
            keep[t] = false;
        }
        let mut k = 0;
        triangles.retain(|_| {
            k += 1;
            keep[k - 1]
        });
    }
    if triangles.is_empty() {
        // Every triangle dropped (all without area, say): the repairs say what they dropped.
        let what = r.note().unwrap_or_default();
        let what = what.strip_prefix("repaired: ").unwrap_or(&what);
        return Err(Error::invalid(format!(
            "no triangle of the mesh's {} is left once repaired ({what})",
            mesh.triangles.len()
        )));
    }
    Ok((InputMesh::new(positions, triangles)?, r))
}

/// Flips triangles so that every edge of two triangles is run both ways (module
/// documentation, step 7). Returns the indices of the flipped triangles and of those to drop:
/// in a piece that no flipping orients, where at most [`FOLD_SHARE`] of its triangles are
/// at edges the walk leaves run the same way, the later-reached triangle of each such edge
/// (every other edge of the piece then agrees with the walk's flips, so the rest is oriented).
///
/// The walk crosses the flattest edges first (Prim's order on the fold across each edge, the
/// two triangles' normals as the walk would orient them): where no orientation exists, the
/// edges it leaves run the same way are then where the surface folds, not along a seam wherever
/// a depth-first walk happened to close its loops (the Stanford dragon's crude decimation,
/// `dragon_vrip_res4`, loses 4 of its 10 267 triangles so; the depth-first walk left more than
/// 1 % of them at such edges, and the dragon was refused).
fn orient(positions: &[Vec3], triangles: &mut [[u32; 3]]) -> (Vec<usize>, Vec<usize>) {
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    let normal: Vec<Vec3> = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            let n = (b - a).cross(&(c - a));
            let l = n.norm();
            if l > 0.0 {
                n / l
            } else {
                Vec3::zeros()
            }
        })
        .collect();
    let next = across_edges(triangles);
    let mut flip: Vec<Option<bool>> = vec![None; triangles.len()];
    let mut out = Vec::new();
    let mut drop: Vec<usize> = Vec::new();
    // The order in which the walk reached each triangle.
    let mut order = vec![usize::MAX; triangles.len()];
    for seed in 0..triangles.len() {
        if flip[seed].is_some() {
            continue;
        }
        flip[seed] = Some(false);
        let mut piece = vec![seed];
        order[seed] = 0;
        // (fold, triangle, its flip): the fold `1 − n·n'` in [0, 2] orders as its bits.
        let mut heap: BinaryHeap<Reverse<(u64, usize, bool)>> = BinaryHeap::new();
        let sign = |f: bool| if f { -1.0 } else { 1.0 };
        let mut t = seed;
        loop {
            let f = flip[t] == Some(true);
            for &(o, same) in &next[t] {
                if flip[o].is_none() {
                    let g = f ^ same;
                    let fold = 1.0 - (normal[t] * sign(f)).dot(&(normal[o] * sign(g)));
                    heap.push(Reverse((fold.clamp(0.0, 2.0).to_bits(), o, g)));
                }
            }
            let Some(o) =
                std::iter::from_fn(|| heap.pop()).find(|Reverse((_, o, _))| flip[*o].is_none())
            else {
                break;
            };
            let Reverse((_, o, g)) = o;
            flip[o] = Some(g);
            order[o] = piece.len();
            piece.push(o);
            t = o;
        }
        let flipped = piece.iter().filter(|&&t| flip[t] == Some(true)).count();
        let back = 2 * flipped > piece.len();
        // The edges still run the same way after the walk, by their later-reached triangle.
        let mut later: Vec<usize> = Vec::new();
        for &t in &piece {
            for &(o, same) in &next[t] {
                if (flip[t] == flip[o]) == same && order[t] > order[o] {
                    later.push(t);
                }
            }
        }
        later.sort_unstable();
        later.dedup();
        // A piece that would lose more than its share to become orientable (a Möbius band of
        // a few quads) is left as it is.
        if later.len() as f64 > FOLD_SHARE * piece.len() as f64 {
            continue;
        }
        for &t in &piece {
            if later.binary_search(&t).is_err() && (flip[t] == Some(true)) != back {
                triangles[t].swap(1, 2);
                out.push(t);
            }
        }
        drop.extend(later);
    }
    out.sort_unstable();
    drop.sort_unstable();
    (out, drop)
}

/// Each triangle's neighbours across its edges of exactly two triangles, with whether the two
/// run that edge the same way (so that one of them must be flipped for the pair to agree).
fn across_edges(triangles: &[[u32; 3]]) -> Vec<Vec<(usize, bool)>> {
    // Each edge's triangles, and whether each runs it from its smaller end.
    let mut sides: Vec<((u32, u32), usize, bool)> = Vec::with_capacity(3 * triangles.len());
    for (i, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            sides.push(((a.min(b), a.max(b)), i, a < b));
        }
    }
    sides.sort_unstable();
    let mut next: Vec<Vec<(usize, bool)>> = vec![Vec::new(); triangles.len()];
    let mut k = 0;
    while k < sides.len() {
        let mut j = k + 1;
        while j < sides.len() && sides[j].0 == sides[k].0 {
            j += 1;
        }
        if j - k == 2 {
            let (s, t) = (sides[k], sides[k + 1]);
            if s.1 != t.1 {
                next[s.1].push((t.1, s.2 == t.2));
                next[t.1].push((s.1, s.2 == t.2));
            }
        }
        k = j;
    }
    next
}

/// Whether the triangles reached from triangle `seed` across edges of exactly two triangles
/// can all be flipped to run every such edge both ways (what [`orient`] does where it can): a
/// walk gives each triangle the flip its neighbour asks, and the piece is orientable when no
/// edge asks a reached triangle for the other one.
pub(super) fn orientable_from(mesh: &InputMesh, seed: usize) -> bool {
    let across = across_edges(&mesh.triangles);
    let mut flip: Vec<Option<bool>> = vec![None; mesh.triangles.len()];
    flip[seed] = Some(false);
    let mut stack = vec![seed];
    while let Some(t) = stack.pop() {
        let f = flip[t] == Some(true);
        for &(o, same) in &across[t] {
            // Two triangles running their edge the same way need opposite flips.
            let want = f ^ same;
            match flip[o] {
                None => {
                    flip[o] = Some(want);
                    stack.push(o);
                }
                Some(g) if g != want => return false,
                Some(_) => {}
            }
        }
    }
    true
}

/// The centroid of triangle `t`.
fn centroid(positions: &[Vec3], t: &[u32; 3]) -> Vec3 {
    (positions[t[0] as usize] + positions[t[1] as usize] + positions[t[2] as usize]) / 3.0
}

fn note_at(r: &mut Repairs, p: Vec3) {
    if r.first.is_none() {
        r.first = Some(p);
    }
}

/// The edges of exactly one triangle (as in [`boundary_edges`]) and the number of edges of three
/// or more, in one pass.
fn edge_kinds(triangles: &[[u32; 3]]) -> (Vec<(u32, u32)>, usize) {
    // Each edge as its sorted ends in one key, with the directed edge it was, sorted: equal
    // keys are the triangles of one edge.
    let mut edges: Vec<(u64, (u32, u32))> = Vec::with_capacity(3 * triangles.len());
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges.push((((a.min(b) as u64) << 32) | a.max(b) as u64, (a, b)));
        }
    }
    edges.sort_unstable_by_key(|e| e.0);
    let (mut boundary, mut nonmanifold) = (Vec::new(), 0);
    let mut k = 0;
    while k < edges.len() {
        let mut j = k + 1;
        while j < edges.len() && edges[j].0 == edges[k].0 {
            j += 1;
        }
        match j - k {
            1 => boundary.push(edges[k].1),
            2 => {}
            _ => nonmanifold += 1,
        }
        k = j;
    }
    boundary.sort_unstable();
    (boundary, nonmanifold)
}

/// Edges of exactly one triangle, as `(a, b)` in that triangle's order.
fn boundary_edges(triangles: &[[u32; 3]]) -> Vec<(u32, u32)> {
    edge_kinds(triangles).0
}

/// A uniform grid of cubes for neighbour searches.
struct Grid {
    size: f64,
}

impl Grid {
    fn new(size: f64) -> Self {
        Grid { size }
    }

    fn cell(&self, p: &Vec3) -> [i64; 3] {
        [0, 1, 2].map(|c| (p[c] / self.size).floor() as i64)
    }

    /// The 27 cells around `p`'s.
    fn around(&self, p: &Vec3) -> Vec<[i64; 3]> {
        let c = self.cell(p);
        let mut out = Vec::with_capacity(27);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    out.push([c[0] + dx, c[1] + dy, c[2] + dz]);
                }
            }
        }
        out
    }
}

/// Vertices on an edge, each with its parameter along the edge.
type OnEdge = Vec<(f64, u32)>;

/// One pass of the T-junction split: every boundary edge with boundary vertices on it (within
/// `tol`, and farther than `tol` from its ends) has its triangle cut into a fan through them.
/// Returns the vertices that split an edge.
fn split_t_junctions(positions: &[Vec3], triangles: &mut Vec<[u32; 3]>, tol: f64) -> Vec<u32> {
    let boundary = boundary_edges(triangles);
    if boundary.is_empty() {
        return Vec::new();
    }
    // Boundary vertices in cells of the mean boundary edge's length.
    let mean = boundary
        .iter()
        .map(|&(a, b)| (positions[a as usize] - positions[b as usize]).norm())
        .sum::<f64>()
        / boundary.len() as f64;
    let grid = Grid::new(mean.max(tol).max(f64::MIN_POSITIVE));
    let mut cells: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    let mut on_boundary: Vec<u32> = boundary.iter().flat_map(|&(a, b)| [a, b]).collect();
    on_boundary.sort_unstable();
    on_boundary.dedup();
    for &v in &on_boundary {
        cells
            .entry(grid.cell(&positions[v as usize]))
            .or_default()
            .push(v);
    }
    let mut found: HashMap<(u32, u32), OnEdge> = HashMap::new();
    for &(a, b) in &boundary {
        let (pa, pb) = (positions[a as usize], positions[b as usize]);
        let d = pb - pa;
        let len = d.norm();
        if len <= 2.0 * tol {
            continue;
        }
        let (lo, hi) = (pa.inf(&pb), pa.sup(&pb));
        let (c0, c1) = (
            grid.cell(&(lo - Vec3::repeat(tol))),
            grid.cell(&(hi + Vec3::repeat(tol))),
        );
        let mut on = Vec::new();
        for x in c0[0]..=c1[0] {
            for y in c0[1]..=c1[1] {
                for z in c0[2]..=c1[2] {
                    for &v in cells.get(&[x, y, z]).map_or(&[][..], |l| &l[..]) {
                        if v == a || v == b {
                            continue;
                        }
                        let p = positions[v as usize];
                        let s = (p - pa).dot(&d) / (len * len);
                        if s * len <= tol || (1.0 - s) * len <= tol {
                            continue;
                        }
                        if (pa + d * s - p).norm() <= tol {
                            on.push((s, v));
                        }
                    }
                }
            }
        }
        if !on.is_empty() {
            found.insert((a, b), on);
        }
    }
    if found.is_empty() {
        return Vec::new();
    }
    // The triangle of each edge found; one edge of a triangle per pass, its other edges wait
    // for the next.
    let mut cuts: HashMap<usize, ((u32, u32), OnEdge)> = HashMap::new();
    for (i, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            let e = (t[k], t[(k + 1) % 3]);
            if let Some(on) = found.remove(&e) {
                cuts.entry(i).or_insert((e, on));
            }
        }
    }
    let mut split = Vec::new();
    let mut order: Vec<usize> = cuts.keys().copied().collect();
    order.sort_unstable();
    for t in order {
        let ((a, b), mut on) = cuts.remove(&t).unwrap_or_default();
        on.sort_by(|x, y| x.0.total_cmp(&y.0));
        on.dedup_by_key(|x| x.1);
        let tri = triangles[t];
        let c = tri
            .iter()
            .copied()
            .find(|&v| v != a && v != b)
            .unwrap_or(tri[0]);
        // The fan a, v₁, …, b around c keeps the triangle's orientation (a → b → c).
        let mut chain = vec![a];
        chain.extend(on.iter().map(|x| x.1));
        chain.push(b);
        triangles[t] = [chain[0], chain[1], c];
        for w in chain.windows(2).skip(1) {
            triangles.push([w[0], w[1], c]);
        }
        split.extend(on.iter().map(|x| x.1));
    }
    split
}

/// The edges of more than two triangles and the manifold pieces around them (what step 5's
/// two parts share).
struct EdgePieces {
    /// Each edge's triangles (its ends sorted).
    by_edge: HashMap<(u32, u32), Vec<usize>>,
    /// The edges of more than two triangles, sorted.
    bad: Vec<(u32, u32)>,
    /// Union-find over the triangles: pieces joined across edges of exactly two triangles.
    parent: Vec<usize>,
    /// Each piece's triangles, by its root.
    size: HashMap<usize, usize>,
}

impl EdgePieces {
    /// `None` when every edge has at most two triangles.
    fn new(triangles: &[[u32; 3]]) -> Option<EdgePieces> {
        let mut by_edge: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
        for (i, t) in triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                by_edge.entry((a.min(b), a.max(b))).or_default().push(i);
            }
        }
        let mut bad: Vec<(u32, u32)> = by_edge
            .iter()
            .filter(|(_, l)| l.len() > 2)
            .map(|(e, _)| *e)
            .collect();
        if bad.is_empty() {
            return None;
        }
        bad.sort_unstable();
        let mut parent: Vec<usize> = (0..triangles.len()).collect();
        for l in by_edge.values() {
            if l.len() == 2 {
                union(&mut parent, l[0], l[1]);
            }
        }
        let mut size: HashMap<usize, usize> = HashMap::new();
        for i in 0..triangles.len() {
            *size.entry(find(&mut parent, i)).or_insert(0) += 1;
        }
        Some(EdgePieces {
            by_edge,
            bad,
            parent,
            size,
        })
    }
}

/// Parts that touch along edges (two closed bodies of a CAD assembly sharing an edge, each
/// with its two triangles there): at an edge of more than two triangles, the pieces (joined
/// across edges of exactly two triangles) with exactly two triangles there running the edge
/// opposite ways are parts; when there are several, every part but the largest (the first of
/// the largest) takes its own copies of the edge's two vertices, at the same places, in all
/// its triangles (other triangles there, a fin, stay with the largest part). Each part then keeps
/// all its triangles (dropping two of the four left holes in a part that the fit then did not
/// cover). Returns the number of edges so split and the middle of the first.
fn unzip_touching(
    pieces: &mut EdgePieces,
    positions: &mut Vec<Vec3>,
    triangles: &mut [[u32; 3]],
) -> (usize, Option<Vec3>) {
    let EdgePieces {
        by_edge,
        bad,
        parent,
        size,
    } = pieces;
    let mut first = None;
    // Whether triangle `t` runs the edge from `a` to `b`.
    let forward = |t: &[u32; 3], a: u32, b: u32| (0..3).any(|k| t[k] == a && t[(k + 1) % 3] == b);
    // The (vertex, piece) pairs that take a copy.
    let mut copy: HashMap<(u32, usize), u32> = HashMap::new();
    let mut split = 0;
    for &(a, b) in bad.iter() {
        let mut groups: Vec<(usize, Vec<usize>)> = Vec::new();
        for &t in &by_edge[&(a, b)] {
            let r = find(parent, t);
            match groups.iter_mut().find(|g| g.0 == r) {
                Some(g) => g.1.push(t),
                None => groups.push((r, vec![t])),
            }
        }
        // The parts: pieces with two triangles here that run the edge opposite ways (a fin,
        // one triangle, stays with the largest, for the next step to drop).
        groups.retain(|(_, l)| {
            l.len() == 2 && forward(&triangles[l[0]], a, b) != forward(&triangles[l[1]], a, b)
        });
        if groups.len() < 2 {
            continue;
        }
        groups.sort_by_key(|g| (std::cmp::Reverse(size[&g.0]), g.0));
        for (r, _) in &groups[1..] {
            for v in [a, b] {
                copy.entry((v, *r)).or_insert_with(|| {
                    positions.push(positions[v as usize]);
                    (positions.len() - 1) as u32
                });
            }
        }
        split += 1;
        first.get_or_insert((positions[a as usize] + positions[b as usize]) / 2.0);
    }
    if copy.is_empty() {
        return (0, None);
    }
    for (i, t) in triangles.iter_mut().enumerate() {
        let r = find(parent, i);
        for c in t.iter_mut() {
            if let Some(&w) = copy.get(&(*c, r)) {
                *c = w;
            }
        }
    }
    (split, first)
}

/// Keeps at most two triangles per edge: those of the largest manifold pieces (`pieces`, of
/// `triangles`). Returns the kept triangles, the number of non-manifold edges and the indices
/// of the dropped triangles (at least one).
fn resolve_nonmanifold(
    triangles: &[[u32; 3]],
    pieces: EdgePieces,
) -> (Vec<[u32; 3]>, usize, Vec<usize>) {
    let EdgePieces {
        by_edge,
        bad,
        mut parent,
        size,
    } = pieces;
    let mut dropped = vec![false; triangles.len()];
    for e in &bad {
        let mut l: Vec<usize> = by_edge[e]
            .iter()
            .copied()
            .filter(|&i| !dropped[i])
            .collect();
        if l.len() <= 2 {
            continue;
        }
        l.sort_by_key(|&i| (std::cmp::Reverse(size[&find(&mut parent, i)]), i));
        for &i in &l[2..] {
            dropped[i] = true;
        }
    }
    let gone: Vec<usize> = (0..triangles.len()).filter(|&i| dropped[i]).collect();
    let kept = triangles
        .iter()
        .zip(&dropped)
        .filter(|(_, &d)| !d)
        .map(|(t, _)| *t)
        .collect();
    (kept, bad.len(), gone)
}

/// Splits every vertex whose triangles make several fans (module documentation, step 6):
/// triangles of a vertex are one fan when a walk across its edges of two triangles joins them
/// (every edge has at most two after step 5). The largest fan (the first of the largest)
/// keeps the vertex; each other gets a new vertex at the same place, appended to `positions`.
/// Returns the vertex each new one was cut from, in their order.
fn split_pinches(positions: &mut Vec<Vec3>, triangles: &mut [[u32; 3]]) -> Vec<u32> {
    let n = positions.len();
    // Each vertex's triangles, in the triangles' order.
    let mut start = vec![0usize; n + 1];
    for t in triangles.iter() {
        for &i in t {
            start[i as usize + 1] += 1;
        }
    }
    for i in 0..n {
        start[i + 1] += start[i];
    }
    let mut fill = start.clone();
    let mut star = vec![0u32; start[n]];
    for (k, t) in triangles.iter().enumerate() {
        for &i in t {
            star[fill[i as usize]] = k as u32;
            fill[i as usize] += 1;
        }
    }
    let mut origin = Vec::new();
    let mut by_corner: Vec<(u32, usize)> = Vec::new();
    let mut parent: Vec<usize> = Vec::new();
    for v in 0..n as u32 {
        let around = &star[start[v as usize]..start[v as usize + 1]];
        if around.len() < 2 {
            continue;
        }
        // Two triangles of `v` that share another corner share the edge to it.
        by_corner.clear();
        for (j, &t) in around.iter().enumerate() {
            by_corner.extend(
                triangles[t as usize]
                    .iter()
                    .filter(|&&w| w != v)
                    .map(|&w| (w, j)),
            );
        }
        by_corner.sort_unstable();
        parent.clear();
        parent.extend(0..around.len());
        for pair in by_corner.windows(2) {
            if pair[0].0 == pair[1].0 {
                union(&mut parent, pair[0].1, pair[1].1);
            }
        }
        let roots: Vec<usize> = (0..around.len()).map(|j| find(&mut parent, j)).collect();
        // One fan (nearly every vertex): nothing to cut.
        if roots.iter().all(|&r| r == roots[0]) {
            continue;
        }
        let mut size: HashMap<usize, usize> = HashMap::new();
        for &r in &roots {
            *size.entry(r).or_default() += 1;
        }
        let keep = roots
            .iter()
            .copied()
            .max_by_key(|r| (size[r], std::cmp::Reverse(*r)))
            .unwrap_or(0);
        let mut copy: HashMap<usize, u32> = HashMap::new();
        for (j, &t) in around.iter().enumerate() {
            if roots[j] == keep {
                continue;
            }
            let w = *copy.entry(roots[j]).or_insert_with(|| {
                positions.push(positions[v as usize]);
                origin.push(v);
                (positions.len() - 1) as u32
            });
            for c in triangles[t as usize].iter_mut() {
                if *c == v {
                    *c = w;
                }
            }
        }
    }
    origin
}

/// A component [`drop_stray`] dropped.
struct Dropped {
    /// Its first triangle.
    first: usize,
    /// Its triangles.
    triangles: usize,
    /// Whether it was dropped for hanging by a pinched vertex only (not small across).
    cut: bool,
}

/// Drops the components (through shared vertices) smaller than [`STRAY_SHARE`] of the largest
/// in triangles and than [`STRAY_EXTENT`] of its bounding box's diagonal across, and those
/// smaller in triangles only that hold a vertex from `copies` on (a piece cut off at a pinched
/// vertex). Returns the kept triangles and the dropped components.
fn drop_stray(
    triangles: &[[u32; 3]],
    positions: &[Vec3],
    copies: usize,
) -> (Vec<[u32; 3]>, Vec<Dropped>) {
    let vertices = positions.len();
    let mut parent: Vec<usize> = (0..vertices).collect();
    for t in triangles {
        union(&mut parent, t[0] as usize, t[1] as usize);
        union(&mut parent, t[1] as usize, t[2] as usize);
    }
    let roots: Vec<usize> = triangles
        .iter()
        .map(|t| find(&mut parent, t[0] as usize))
        .collect();
    let mut size = vec![0usize; vertices];
    let mut cut = vec![false; vertices];
    let mut lo = vec![Vec3::repeat(f64::INFINITY); vertices];
    let mut hi = vec![Vec3::repeat(f64::NEG_INFINITY); vertices];
    for (t, &r) in triangles.iter().zip(&roots) {
        size[r] += 1;
        for &i in t {
            cut[r] |= i as usize >= copies;
            lo[r] = lo[r].inf(&positions[i as usize]);
            hi[r] = hi[r].sup(&positions[i as usize]);
        }
    }
    let across = |r: usize| (hi[r] - lo[r]).norm();
    // The largest component (the first of the most triangles).
    let Some(&main) = roots
        .iter()
        .max_by_key(|&&r| (size[r], std::cmp::Reverse(r)))
    else {
        return (Vec::new(), Vec::new());
    };
    let (largest, extent) = (size[main], across(main));
    let stray = |r: &usize| {
        (size[*r] as f64) < STRAY_SHARE * largest as f64
            && (cut[*r] || across(*r) < STRAY_EXTENT * extent)
    };
    let mut dropped = Vec::new();
    let mut seen = std::collections::HashSet::new();
    for (i, r) in roots.iter().enumerate() {
        if stray(r) && seen.insert(*r) {
            dropped.push(Dropped {
                first: i,
                triangles: size[*r],
                // A speck by its extent is a speck, cut off or not: dropped although not
                // small across, it was cut off.
                cut: across(*r) >= STRAY_EXTENT * extent,
            });
        }
    }
    let kept = triangles
        .iter()
        .zip(&roots)
        .filter(|(_, r)| !stray(r))
        .map(|(t, _)| *t)
        .collect();
    (kept, dropped)
}

fn find(parent: &mut [usize], mut a: usize) -> usize {
    while parent[a] != a {
        let g = parent[parent[a]];
        parent[a] = g;
        a = g;
    }
    a
}

fn union(parent: &mut [usize], a: usize, b: usize) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        parent[ra.max(rb)] = ra.min(rb);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit cube `[0, 2]³` with its top face (z = 2) cut `n × n` and the other faces
    /// in two triangles each, outward; the top's vertices on its border are T-junctions of the
    /// side faces when `n > 1`.
    fn cube_with_fine_top(n: usize) -> InputMesh {
        let mut p: Vec<Vec3> = Vec::new();
        let mut t: Vec<[u32; 3]> = Vec::new();
        let v = |p: &mut Vec<Vec3>, x: f64, y: f64, z: f64| {
            if let Some(i) = p
                .iter()
                .position(|q| (q - Vec3::new(x, y, z)).norm() < 1e-12)
            {
                return i as u32;
            }
            p.push(Vec3::new(x, y, z));
            (p.len() - 1) as u32
        };
        let h = 2.0 / n as f64;
        for i in 0..n {
            for j in 0..n {
                let (x0, y0) = (i as f64 * h, j as f64 * h);
                let a = v(&mut p, x0, y0, 2.0);
                let b = v(&mut p, x0 + h, y0, 2.0);
                let c = v(&mut p, x0 + h, y0 + h, 2.0);
                let d = v(&mut p, x0, y0 + h, 2.0);
                t.push([a, b, c]);
                t.push([a, c, d]);
            }
        }
        // Corners of the cube.
        let c: Vec<u32> = (0..8)
            .map(|k| {
                v(
                    &mut p,
                    2.0 * (k & 1) as f64,
                    2.0 * ((k >> 1) & 1) as f64,
                    2.0 * ((k >> 2) & 1) as f64,
                )
            })
            .collect();
        // Bottom, and the four sides, outward.
        let quads = [
            [c[0], c[2], c[3], c[1]],
            [c[0], c[1], c[5], c[4]],
            [c[1], c[3], c[7], c[5]],
            [c[3], c[2], c[6], c[7]],
            [c[2], c[0], c[4], c[6]],
        ];
        for q in quads {
            t.push([q[0], q[1], q[2]]);
            t.push([q[0], q[2], q[3]]);
        }
        InputMesh::new(p, t).unwrap()
    }

    fn closed_and_manifold(m: &InputMesh) {
        let topo = m.topology();
        assert_eq!(topo.boundary_edges, 0, "{topo:?}");
        assert_eq!(topo.nonmanifold_edges, 0, "{topo:?}");
        assert_eq!(topo.components, 1, "{topo:?}");
    }

    #[test]
    fn t_junctions_are_split_and_the_cube_closes_with_its_volume() {
        let m = cube_with_fine_top(4);
        // Three vertices of the top's border inside each of its four edges.
        assert_eq!(m.topology().boundary_edges, 4 + 16);
        let (fixed, r) = repair(&m).unwrap();
        assert_eq!(r.t_junctions, 12, "{r:?}");
        assert_eq!(
            (r.degenerate, r.duplicates, r.cracks, r.nonmanifold_edges),
            (0, 0, 0, 0)
        );
        closed_and_manifold(&fixed);
        assert!(
            (fixed.signed_volume() - 8.0).abs() < 1e-12,
            "{}",
            fixed.signed_volume()
        );
        assert_eq!(fixed.positions, m.positions);
        assert!(r.note().unwrap().contains("12 T-junctions split"));
        // A whole mesh is left as it is.
        let (same, r) = repair(&cube_with_fine_top(1)).unwrap();
        assert!(r.is_empty() && r.note().is_none());
        assert_eq!(same, cube_with_fine_top(1));
    }

    #[test]
    fn cracks_are_welded_and_nothing_else_moves() {
        // The top as a separate sheet of its own vertices, 1e-6 above the sides' top edges.
        let m = cube_with_fine_top(1);
        let mut p = m.positions.clone();
        let mut t = m.triangles.clone();
        let top: Vec<u32> = (0..4).collect();
        let shift: Vec<u32> = top
            .iter()
            .map(|&i| {
                p.push(m.positions[i as usize] + Vec3::new(0.0, 0.0, 1e-6));
                (p.len() - 1) as u32
            })
            .collect();
        for tri in t.iter_mut().take(2) {
            *tri = tri.map(|i| shift[i as usize]);
        }
        let cracked = InputMesh::new(p, t).unwrap();
        assert_eq!(cracked.topology().boundary_edges, 8);
        let (fixed, r) = repair(&cracked).unwrap();
        assert_eq!(r.cracks, 4, "{r:?}");
        closed_and_manifold(&fixed);
        // A crack wider than the tolerance (1e-4 of the diagonal, 3.5e-4) stays open.
        let mut p = cracked.positions.clone();
        for q in p.iter_mut().skip(8) {
            q.z += 1e-3;
        }
        let (open, r) = repair(&InputMesh::new(p, cracked.triangles.clone()).unwrap()).unwrap();
        assert_eq!(r.cracks, 0);
        assert_eq!(open.topology().boundary_edges, 8);
    }

    /// A closed tetrahedron with corner `at` (an existing vertex) and three new corners
    /// `at + size·(e_x, e_y, e_z)` (outward for `size > 0` about that corner's octant), appended.
    fn tetrahedron_at(p: &mut Vec<Vec3>, t: &mut Vec<[u32; 3]>, at: u32, size: f64) {
        let c = p[at as usize];
        let s = p.len() as u32;
        p.extend([
            c + Vec3::new(size, 0.0, 0.0),
            c + Vec3::new(0.0, size, 0.0),
            c + Vec3::new(0.0, 0.0, size),
        ]);
        let (x, y, z) = (s, s + 1, s + 2);
        t.extend([[at, y, x], [at, x, z], [at, z, y], [x, y, z]]);
    }

    #[test]
    fn pieces_hanging_by_a_vertex_are_dropped_and_pinches_between_large_pieces_kept() {
        let (base, _) = repair(&cube_with_fine_top(15)).unwrap();
        // 460 triangles: a tetrahedron's 4 are under `STRAY_SHARE` of them.
        assert!(4.0 < STRAY_SHARE * base.triangles.len() as f64);
        let corner = |p: &[Vec3], q: Vec3| p.iter().position(|x| (x - q).norm() == 0.0).unwrap();
        let mut p = base.positions.clone();
        let mut t = base.triangles.clone();
        // A tetrahedron a quarter of the cube across hanging from the corner (2, 2, 2), and
        // a speck of one from (0, 0, 0).
        let far = corner(&p, Vec3::new(2.0, 2.0, 2.0)) as u32;
        tetrahedron_at(&mut p, &mut t, far, 0.5);
        let near = corner(&p, Vec3::zeros()) as u32;
        tetrahedron_at(&mut p, &mut t, near, -1e-3);
        let dirty = InputMesh::new(p, t).unwrap();
        assert_eq!(dirty.topology().components, 1);
        let (fixed, r) = repair(&dirty).unwrap();
        assert_eq!(
            (
                r.pinched,
                r.pinched_triangles,
                r.stray_components,
                r.stray_triangles
            ),
            (1, 4, 1, 4),
            "{r:?}"
        );
        assert!(r
            .note()
            .unwrap()
            .contains("1 piece hanging by a single vertex (4 triangles)"));
        assert_eq!(fixed.triangles, base.triangles);
        assert_eq!(fixed.positions.len(), dirty.positions.len());
        closed_and_manifold(&fixed);

        // Two cubes meeting at a corner: neither hangs from the other, and the corner they
        // share stays one vertex.
        let mut p = base.positions.clone();
        let mut t = base.triangles.clone();
        let shift = p.len() as u32;
        p.extend(base.positions.iter().map(|q| q + Vec3::repeat(2.0)));
        t.extend(base.triangles.iter().map(|x| x.map(|i| i + shift)));
        let origin = shift + corner(&base.positions, Vec3::zeros()) as u32;
        for x in t.iter_mut() {
            for i in x.iter_mut() {
                if *i == origin {
                    *i = far;
                }
            }
        }
        let touching = InputMesh::new(p, t).unwrap();
        let (fixed, r) = repair(&touching).unwrap();
        assert!(r.is_empty(), "{r:?}");
        assert_eq!(fixed.triangles, touching.triangles);
        assert_eq!(fixed.topology().components, 1);
    }

    #[test]
    fn fins_degenerate_and_duplicate_triangles_and_specks_are_dropped() {
        let m = cube_with_fine_top(8);
        let (base, _) = repair(&m).unwrap();
        let mut p = base.positions.clone();
        let mut t = base.triangles.clone();
        // A fin on the edge from (0, 0, 0) to (2, 0, 0), standing out of the cube.
        let (a, b) = (
            p.iter().position(|q| q.norm() == 0.0).unwrap() as u32,
            p.iter()
                .position(|q| (q - Vec3::new(2.0, 0.0, 0.0)).norm() == 0.0)
                .unwrap() as u32,
        );
        p.push(Vec3::new(1.0, -1.0, -1.0));
        t.push([a, b, (p.len() - 1) as u32]);
        // A duplicate, a degenerate triangle and a speck far away.
        t.push(t[0]);
        t.push([a, a, b]);
        let s = p.len() as u32;
        p.extend([
            Vec3::new(9.0, 9.0, 9.0),
            Vec3::new(9.01, 9.0, 9.0),
            Vec3::new(9.0, 9.01, 9.0),
        ]);
        t.push([s, s + 1, s + 2]);
        let dirty = InputMesh::new(p, t).unwrap();
        let (fixed, r) = repair(&dirty).unwrap();
        assert_eq!(
            (
                r.degenerate,
                r.duplicates,
                r.nonmanifold_edges,
                r.nonmanifold_dropped,
                r.stray_components,
                r.stray_triangles
            ),
            (1, 1, 1, 1, 1, 1),
            "{r:?}"
        );
        closed_and_manifold(&fixed);
        assert_eq!(fixed.triangles, base.triangles);
        let note = r.note().unwrap();
        assert!(
            note.contains("1 edge made manifold by dropping 1 triangle"),
            "{note}"
        );
        // Two bodies of comparable size both stay.
        let mut p = base.positions.clone();
        let mut t = base.triangles.clone();
        let n = p.len() as u32;
        p.extend(base.positions.iter().map(|q| q + Vec3::new(5.0, 0.0, 0.0)));
        t.extend(base.triangles.iter().map(|tri| tri.map(|i| i + n)));
        let (two, r) = repair(&InputMesh::new(p, t).unwrap()).unwrap();
        assert!(r.is_empty(), "{r:?}");
        assert_eq!(two.topology().components, 2);
        // So does a piece of two triangles (under 1 % of the cube's 394) a third of the
        // cube's diagonal across, beside it; a speck 1 % of it across goes.
        let mut p = base.positions.clone();
        let mut t = base.triangles.clone();
        let n = p.len() as u32;
        let strip = [
            [3.0, 0.0, 0.0],
            [3.0, 1.15, 0.0],
            [3.1, 0.0, 0.0],
            [3.1, 1.15, 0.0],
        ];
        p.extend(strip.map(|[x, y, z]| Vec3::new(x, y, z)));
        t.extend([[n, n + 2, n + 1], [n + 1, n + 2, n + 3]]);
        let across = 0.0099 * 12f64.sqrt();
        p.extend(
            [
                [3.0, 1.0, 1.0],
                [3.0, 1.0 + across, 1.0],
                [3.0, 1.0, 1.0 + 1e-3],
            ]
            .map(|[x, y, z]| Vec3::new(x, y, z)),
        );
        t.push([n + 4, n + 5, n + 6]);
        let m = InputMesh::new(p, t).unwrap();
        let (kept, r) = repair(&m).unwrap();
        assert_eq!((r.stray_components, r.stray_triangles), (1, 1), "{r:?}");
        assert_eq!(kept.triangles.len(), base.triangles.len() + 2);
        assert_eq!(kept.topology().components, 2);
    }

    /// Two closed cubes of an assembly touching along an edge (the first's edge at x = y = 2
    /// is the second's at its corner x = y = 0): the edge has four triangles, two of each
    /// cube. The cubes are split apart there and keep all their triangles, each closed (the
    /// repair dropped two of the four before, leaving a hole in one cube); a fin beside them
    /// (one triangle on an edge) is still dropped.
    #[test]
    fn parts_touching_along_an_edge_are_split_apart_not_cut_open() {
        let a = cube_with_fine_top(1);
        let mut p = a.positions.clone();
        let mut t = a.triangles.clone();
        let shift = Vec3::new(2.0, 2.0, 0.0);
        let index: Vec<u32> = a
            .positions
            .iter()
            .map(|q| {
                let q = q + shift;
                match p.iter().position(|x| (x - q).norm() < 1e-12) {
                    Some(i) => i as u32,
                    None => {
                        p.push(q);
                        (p.len() - 1) as u32
                    }
                }
            })
            .collect();
        t.extend(a.triangles.iter().map(|tri| tri.map(|i| index[i as usize])));
        let m = InputMesh::new(p.clone(), t.clone()).unwrap();
        assert_eq!(m.topology().nonmanifold_edges, 1);
        let (fixed, r) = repair(&m).unwrap();
        assert_eq!(
            (r.touching, r.nonmanifold_edges, r.nonmanifold_dropped),
            (1, 0, 0),
            "{r:?}"
        );
        assert_eq!(fixed.triangles.len(), m.triangles.len());
        let topo = fixed.topology();
        assert_eq!(
            (topo.boundary_edges, topo.nonmanifold_edges, topo.components),
            (0, 0, 2),
            "{topo:?}"
        );
        assert!((fixed.signed_volume() - 16.0).abs() < 1e-12);
        // Nothing moved: every vertex of the repaired mesh is one of the file's.
        assert!(fixed.positions.iter().all(|q| p.contains(q)));
        let note = r.note().unwrap();
        assert!(
            note.contains("1 edge where parts touch split apart"),
            "{note}"
        );
        // A fin on the touching edge: five triangles there, the fin's piece of one.
        let mut p2 = p.clone();
        p2.push(Vec3::new(3.0, 1.0, 1.0));
        let mut t2 = t.clone();
        let at = |q: Vec3| p.iter().position(|x| *x == q).unwrap() as u32;
        let (e0, e1) = (at(Vec3::new(2.0, 2.0, 0.0)), at(Vec3::new(2.0, 2.0, 2.0)));
        t2.push([e0, e1, (p2.len() - 1) as u32]);
        let (fixed, r) = repair(&InputMesh::new(p2, t2).unwrap()).unwrap();
        assert_eq!((r.touching, r.nonmanifold_dropped), (1, 1), "{r:?}");
        assert_eq!(fixed.triangles.len(), m.triangles.len());
    }

    /// The faces of every cell of an `n`³ grid of cubes (a volume mesh written as a surface
    /// file): each inner face shared by two cells, each inner edge by four faces.
    fn cell_faces(n: u32) -> InputMesh {
        let v = |i: u32, j: u32, k: u32| i + (n + 1) * (j + (n + 1) * k);
        let mut p = Vec::new();
        for k in 0..=n {
            for j in 0..=n {
                for i in 0..=n {
                    p.push(Vec3::new(i as f64, j as f64, k as f64));
                }
            }
        }
        let mut t = Vec::new();
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    // The cell's six faces, each cell writing all of its own, split along the
                    // diagonal its parity picks (a face between two cells is two different
                    // pairs of triangles, not a duplicate).
                    let odd = (i + j + k) % 2 == 1;
                    let mut quad = |q: [u32; 4]| {
                        let q = if odd { [q[1], q[2], q[3], q[0]] } else { q };
                        t.push([q[0], q[1], q[2]]);
                        t.push([q[0], q[2], q[3]]);
                    };
                    let c = |a: u32, b: u32, d: u32| v(i + a, j + b, k + d);
                    quad([c(0, 0, 0), c(0, 1, 0), c(1, 1, 0), c(1, 0, 0)]);
                    quad([c(0, 0, 1), c(1, 0, 1), c(1, 1, 1), c(0, 1, 1)]);
                    quad([c(0, 0, 0), c(1, 0, 0), c(1, 0, 1), c(0, 0, 1)]);
                    quad([c(0, 1, 0), c(0, 1, 1), c(1, 1, 1), c(1, 1, 0)]);
                    quad([c(0, 0, 0), c(0, 0, 1), c(0, 1, 1), c(0, 1, 0)]);
                    quad([c(1, 0, 0), c(1, 1, 0), c(1, 1, 1), c(1, 0, 1)]);
                }
            }
        }
        InputMesh::new(p, t).unwrap()
    }

    /// A volume mesh's cell faces are not a surface with a few fins: the repair that would
    /// drop most of them refuses the file instead, naming a point; one cell (a closed cube)
    /// and two cells sharing a face (one inner face, dropped with its fins) are repaired.
    #[test]
    fn a_volume_mesh_is_refused_not_repaired_away() {
        let e = repair(&cell_faces(3)).unwrap_err();
        let m = e.message();
        assert!(
            m.starts_with("the mesh is not one surface: ") && m.contains("near ("),
            "{m}"
        );
        assert!(m.contains("export the object's outer surface alone"), "{m}");
        let (cube, r) = repair(&cell_faces(1)).unwrap();
        assert!(r.is_empty(), "{r:?}");
        closed_and_manifold(&cube);
    }

    #[test]
    fn a_flipped_triangle_is_flipped_back_and_the_cube_keeps_its_volume() {
        let mut m = cube_with_fine_top(3);
        m.triangles[4].swap(0, 1);
        assert!(crate::fit::require_oriented(&m, crate::fit::FileFrame::default()).is_err());
        let (r, rep) = repair(&m).unwrap();
        assert_eq!(rep.flipped, 1, "{rep:?}");
        assert!(
            rep.note().unwrap().contains("1 triangle flipped"),
            "{:?}",
            rep.note()
        );
        crate::fit::require_oriented(&r, crate::fit::FileFrame::default()).unwrap();
        closed_and_manifold(&r);
        assert!(
            (r.signed_volume() - 8.0).abs() < 1e-12,
            "{}",
            r.signed_volume()
        );
    }

    #[test]
    fn the_majority_orientation_stays_when_most_triangles_are_flipped() {
        let mut m = cube_with_fine_top(3);
        let n = m.triangles.len();
        for t in &mut m.triangles[1..] {
            t.swap(1, 2);
        }
        let (r, rep) = repair(&m).unwrap();
        assert_eq!(rep.flipped, 1, "{rep:?}");
        assert!(n > 2);
        crate::fit::require_oriented(&r, crate::fit::FileFrame::default()).unwrap();
        assert!(
            (r.signed_volume() + 8.0).abs() < 1e-12,
            "{}",
            r.signed_volume()
        );
    }

    /// A Möbius band of `n` quads (`2n` triangles), the last joining the first with its rows
    /// swapped.
    fn mobius(n: usize) -> InputMesh {
        let point = |i: usize, w: f64| {
            let t = std::f64::consts::TAU * i as f64 / n as f64;
            let r = 1.0 + 0.5 * w * (t / 2.0).cos();
            Vec3::new(r * t.cos(), r * t.sin(), 0.5 * w * (t / 2.0).sin())
        };
        let mut p = Vec::new();
        for i in 0..n {
            p.push(point(i, 1.0));
            p.push(point(i, -1.0));
        }
        let (top, bottom) = (|i: usize| (2 * i) as u32, |i: usize| (2 * i + 1) as u32);
        let mut t = Vec::new();
        for i in 0..n {
            // The last quad joins the first with its rows swapped: the half twist.
            let (nt, nb) = if i + 1 < n {
                (top(i + 1), bottom(i + 1))
            } else {
                (bottom(0), top(0))
            };
            t.push([top(i), bottom(i), nb]);
            t.push([top(i), nb, nt]);
        }
        InputMesh::new(p, t).unwrap()
    }

    /// A Möbius band of 12 quads: no orientation exists, and one triangle in 24 is more than
    /// the share a repair may drop, so it is left as it is (and refused by the general mode),
    /// one triangle turned or not.
    #[test]
    fn a_mobius_band_is_left_as_it_is() {
        let mut m = mobius(12);
        for turned in [false, true] {
            if turned {
                m.triangles[3].swap(1, 2);
            }
            let (r, rep) = repair(&m).unwrap();
            assert_eq!(rep.flipped, 0, "{rep:?}");
            assert_eq!(rep.folded, 0, "{rep:?}");
            assert_eq!(r.triangles, m.triangles);
            // Refused as what it is: no flipping would orient it.
            let e = crate::fit::require_oriented(&r, crate::fit::FileFrame::default())
                .unwrap_err()
                .to_string();
            assert!(e.contains("the surface is not orientable"), "{e}");
            assert!(!e.contains("flip one of them"), "{e}");
        }
    }

    /// A long band with one half twist (200 quads, 400 triangles) stands for a crude
    /// decimation's fold: the walk leaves one edge run the same way, within the share a repair
    /// may drop, so the later-reached triangle there is dropped, said, and the rest comes out
    /// oriented (flipped where the walk said), every other triangle kept.
    #[test]
    fn a_fold_within_the_share_is_dropped_and_the_rest_oriented() {
        let m = mobius(200);
        let (r, rep) = repair(&m).unwrap();
        assert_eq!(rep.folded, 1, "{rep:?}");
        assert_eq!(r.triangles.len(), m.triangles.len() - 1);
        crate::fit::require_oriented(&r, crate::fit::FileFrame::default()).unwrap();
        let note = rep.note().unwrap();
        assert!(
            note.contains("1 triangle dropped at folds that no flipping orients"),
            "{note}"
        );
        // Every kept triangle is one of the band's, as it was or flipped.
        for t in &r.triangles {
            let mut s = *t;
            s.sort_unstable();
            assert!(
                m.triangles.iter().any(|u| {
                    let mut u = *u;
                    u.sort_unstable();
                    u == s
                }),
                "{t:?}"
            );
        }
    }

    /// A mesh whose every triangle has no area is refused by the repairs in words that say so
    /// and where, not as a mesh without triangles.
    #[test]
    fn a_mesh_of_triangles_without_area_is_refused_by_what_was_dropped() {
        let p = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
        ];
        let mesh = InputMesh::new(p, vec![[0, 1, 2], [0, 2, 1]]).unwrap();
        let e = repair(&mesh).unwrap_err().to_string();
        assert!(
            e.contains("no triangle of the mesh's 2 is left once repaired")
                && e.contains("2 degenerate triangles dropped")
                && e.contains("the first near (1"),
            "{e}"
        );
    }
}
