//! Triangle meshes read from OBJ, STL, PLY, OFF and glTF files (through `tobj`, `stl_io` and
//! `ply-rs`; OFF, a few lines of text, by [`read_off`]; glTF by `super::gltf_read`), and
//! the checks the fitting needs: finite coordinates, valid indices, a size limit, edge
//! manifoldness, closedness and connectedness. An OBJ file of several objects or groups (the
//! tool's own OBJ has one object per patch, Blender writes one per object), or a glTF file of
//! several triangle primitives, is read as one mesh welded by position, and [`MeshRead::note`]
//! says so.
//!
//! Units and the up axis are taken as the file states them: glTF is in metres and +Y up by its
//! specification (turned to the design's +Z up; pdeshape's GLB records the design's units in
//! its extras, and the mesh is read in those); the tool's own OBJ, STL and PLY state
//! `units: mm (1 unit = 0.001 m); up: +Y` in a comment or header (`stated_frame`), and a
//! `+Y` up file is turned back the same way. A file that states nothing is read as its numbers
//! are, without units.

use super::frame::FileFrame;
use crate::spec::Units;
use crate::{Error, Result, Vec3};
use smallvec::SmallVec;
use std::collections::HashMap;
use std::io::Cursor;

/// Largest number of triangles read: a mesh beyond it is refused before its triangles are stored
/// (a fit keeps a few arrays of the mesh's size: the fit of `igea1m.ply`, a million triangles,
/// peaked at 642 MiB; above about two million the first decimation's price refuses a mesh
/// anyway, BENCHMARKS.md).
pub const MAX_TRIANGLES: usize = 4_000_000;

/// The largest coordinate a fit reads: lengths up to about `1e60` square and multiply (areas of
/// areas, quadrics' constant terms) without overflow.
pub const MAX_COORDINATE: f64 = 1e60;

/// The smallest extent (bounding box's longest side) of a mesh a fit reads: its triangles'
/// squared areas, `1e-240` at this size, stay clear of underflow.
pub const MIN_SPAN: f64 = 1e-60;

/// An indexed triangle mesh read for fitting (OBJ, STL, PLY, OFF, glTF), with its topology checks; the
/// design layer's [`crate::mesh::TriMesh`] is the mesh a design is written as.
#[derive(Clone, Debug, PartialEq)]
pub struct InputMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
}

/// What [`InputMesh::topology`] finds.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Topology {
    /// Edges used by exactly one triangle.
    pub boundary_edges: usize,
    /// Edges used by three or more triangles.
    pub nonmanifold_edges: usize,
    /// Connected components (through shared vertices) of the triangles.
    pub components: usize,
    /// Triangles with a repeated vertex index.
    pub degenerate: usize,
}

/// Mesh file formats, by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshFormat {
    /// Wavefront OBJ (`.obj`).
    Obj,
    /// STL (`.stl`).
    Stl,
    /// PLY (`.ply`).
    Ply,
    /// Object File Format (`.off`), as text.
    Off,
    /// glTF 2.0: binary (`.glb`) or JSON (`.gltf`, its buffers embedded as data URIs or in
    /// files beside it, read through [`InputMesh::read_report_with`]); told apart by content.
    Gltf,
}

/// Reads a file that a mesh file names beside it (a `.gltf` file's buffers): given the
/// reference as the file writes it (percent-decoded, a relative path), its bytes, or why they
/// cannot be read in a few words.
pub type External<'a> = dyn Fn(&str) -> std::result::Result<Vec<u8>, String> + 'a;

/// The reader of external files for bytes read without their directory: none is read.
fn no_external(_: &str) -> std::result::Result<Vec<u8>, String> {
    Err(
        "the glTF file's buffers in other files are read only beside the file (give a .glb, or \
         a .gltf whose buffers are data URIs)"
            .to_string(),
    )
}

impl MeshFormat {
    /// The extensions [`MeshFormat::from_extension`] knows, in words for messages.
    pub const EXTENSIONS: &'static str = "obj, stl, ply, off, glb or gltf";

    /// The format named by a file extension (`obj`, `stl`, `ply`, `off`, `glb`, `gltf`, any
    /// case).
    pub fn from_extension(ext: &str) -> Option<Self> {
        match ext.to_ascii_lowercase().as_str() {
            "obj" => Some(MeshFormat::Obj),
            "stl" => Some(MeshFormat::Stl),
            "ply" => Some(MeshFormat::Ply),
            "off" => Some(MeshFormat::Off),
            "glb" | "gltf" => Some(MeshFormat::Gltf),
            _ => None,
        }
    }

    /// The message for a file whose extension names no mesh format: `{shown}: unknown mesh
    /// format (…)`.
    pub fn unknown(shown: &str) -> String {
        format!(
            "{shown}: unknown mesh format (the extension must be {})",
            Self::EXTENSIONS
        )
    }
}

/// A mesh read from a file, with what the reader did to it beyond parsing.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshRead {
    /// The mesh, in the design's frame (+Z up) and in `units` when the file states them.
    pub mesh: InputMesh,
    /// Set when an OBJ file's several objects or groups, or a glTF file's several triangle
    /// primitives, were joined into one mesh.
    pub joined: Option<Joined>,
    /// The format read.
    pub format: MeshFormat,
    /// The length unit of the mesh's coordinates when the file states it (glTF: metres, or
    /// the design units its extras name; the tool's own OBJ, STL and PLY: their units line);
    /// a design fitted to the mesh carries it.
    pub units: Option<Units>,
    /// What the reader converted or left out (a turn to +Z up, glTF primitives of points or
    /// lines), each a phrase for [`MeshRead::note`].
    pub converted: Vec<String>,
    /// How the file's own coordinates became `mesh`'s: messages name points in the file's.
    pub file: FileFrame,
}

/// How a file's objects, groups or primitives were joined into one mesh
/// ([`InputMesh::read_report`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Joined {
    /// Objects, groups or material runs of an OBJ file (each a model to the OBJ parser), or
    /// triangle primitives of a glTF file (each placed by its node).
    pub parts: usize,
    /// Vertices merged into another one at the same position (within [`WELD_FRACTION`] of the
    /// bounding-box diagonal).
    pub welded: usize,
    /// Triangles dropped because welding left two of their corners equal.
    pub dropped: usize,
}

/// Vertices of different OBJ objects closer than this fraction of the mesh's bounding-box
/// diagonal are one vertex (the design layer's weld uses the same fraction).
pub const WELD_FRACTION: f64 = 1e-6;

impl MeshRead {
    /// One line for the user when the reader converted the file's frame, left primitives out
    /// or joined parts of the file, `None` otherwise.
    pub fn note(&self) -> Option<String> {
        let mut parts = self.converted.clone();
        if let Some(j) = self.joined {
            let mut text = match self.format {
                MeshFormat::Gltf => format!(
                    "the glTF file has {} triangle primitives, read as one mesh: {} vertices \
                     welded by position",
                    j.parts, j.welded
                ),
                _ => format!(
                    "the OBJ file has {} objects or groups, read as one mesh: {} vertices welded \
                     by position",
                    j.parts, j.welded
                ),
            };
            if j.dropped > 0 {
                text += &format!(
                    ", {} triangles left with two equal corners dropped",
                    j.dropped
                );
            }
            parts.push(text);
        }
        (!parts.is_empty()).then(|| parts.join("; "))
    }

    /// The mesh with its coordinates in `units`: scaled from the units the file states, as it
    /// is when the file states none (a mesh given to a design in those units).
    pub fn mesh_in(&self, units: Units) -> InputMesh {
        let mut mesh = self.mesh.clone();
        if let Some(from) = self.units {
            if from != units {
                let k = from.metres() / units.metres();
                for p in &mut mesh.positions {
                    *p *= k;
                }
            }
        }
        mesh
    }
}

impl InputMesh {
    /// A mesh from positions and triangles, checked: at least one triangle, finite coordinates
    /// (the error names the vertex), indices in range (naming the triangle), at most
    /// [`MAX_TRIANGLES`].
    pub fn new(positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<Self> {
        if triangles.is_empty() {
            return Err(Error::invalid(if positions.len() >= 3 {
                format!(
                    "the mesh has {} vertices and no triangles (a point cloud?): reconstruct a \
                     surface from the points first (a Poisson or ball-pivoting reconstruction)",
                    positions.len()
                )
            } else {
                "the mesh has no triangles".to_string()
            }));
        }
        check_count(triangles.len())?;
        if let Some(k) = positions
            .iter()
            .position(|p| !p.iter().all(|c| c.is_finite()))
        {
            return Err(Error::invalid(
                vertex_problem(k + 1, positions[k]).unwrap_or_default(),
            ));
        }
        let n = positions.len();
        if let Some(k) = triangles
            .iter()
            .position(|t| t.iter().any(|&i| i as usize >= n))
        {
            return Err(Error::invalid(format!(
                "triangle {} refers to vertex {} but the mesh has {n} vertices",
                k + 1,
                triangles[k].iter().max().map_or(0, |&i| i as usize + 1)
            )));
        }
        let mesh = InputMesh {
            positions,
            triangles,
        };
        mesh.check_scale()?;
        Ok(mesh)
    }

    /// Reads a mesh from the bytes of a file in `format`. Polygons of an OBJ, PLY or OFF file
    /// are split into triangles in their own planes (convex ones into fans); coincident STL
    /// corners are merged into one vertex.
    /// An OBJ file of several objects or groups is one mesh, welded by position
    /// ([`InputMesh::read_report`] says when).
    pub fn read(bytes: &[u8], format: MeshFormat) -> Result<Self> {
        Ok(InputMesh::read_report(bytes, format)?.mesh)
    }

    /// [`InputMesh::read`], with what the reader did: whether an OBJ file's objects or groups
    /// (a glTF file's primitives) were joined, and how many vertices were welded; the units
    /// and up axis the file states, and what was converted. A `.gltf` file whose buffers are
    /// in other files is refused: [`InputMesh::read_report_with`] reads those.
    pub fn read_report(bytes: &[u8], format: MeshFormat) -> Result<MeshRead> {
        InputMesh::read_report_with(bytes, format, &no_external)
    }

    /// [`InputMesh::read_report`], the files a `.gltf` file names beside it (its buffers) read
    /// by `external`.
    pub fn read_report_with(
        bytes: &[u8],
        format: MeshFormat,
        external: &External<'_>,
    ) -> Result<MeshRead> {
        let mut units = None;
        let mut converted = Vec::new();
        let mut file = FileFrame::default();
        let (positions, triangles, parts) = match format {
            MeshFormat::Obj => read_obj(bytes)?,
            MeshFormat::Stl => {
                let (p, t) = read_stl(bytes)?;
                (p, t, 1)
            }
            MeshFormat::Ply => {
                let (p, t) = read_ply(bytes)?;
                (p, t, 1)
            }
            MeshFormat::Off => {
                let (p, t) = read_off(bytes)?;
                (p, t, 1)
            }
            MeshFormat::Gltf => {
                let g = super::gltf_read::read_gltf(bytes, external)?;
                units = Some(g.units);
                converted = g.notes;
                file = g.frame;
                (g.positions, g.triangles, g.parts)
            }
        };
        if let Some((stated, y_up)) = stated_frame(bytes, format) {
            units = Some(stated);
            if y_up {
                // The writers' turn (x, y, z) → (x, z, −y), undone.
                file.y_up = true;
                converted.push(format!(
                    "the file states +Y up (units: {}): turned to +Z up",
                    stated.as_str()
                ));
            }
        }
        // Checked in the file's frame, so a bad value or index is named as the file has it
        // (and before welding).
        let mut mesh = InputMesh::new(positions, triangles)?;
        if file != FileFrame::default() {
            for p in &mut mesh.positions {
                *p = file.to_design(*p);
            }
            mesh.check_scale()?;
        }
        if parts < 2 {
            return Ok(MeshRead {
                mesh,
                joined: None,
                format,
                units,
                converted,
                file,
            });
        }
        let (mesh, welded, dropped) = weld_by_position(mesh)?;
        Ok(MeshRead {
            mesh,
            joined: Some(Joined {
                parts,
                welded,
                dropped,
            }),
            format,
            units,
            converted,
            file,
        })
    }

    /// The corners of triangle `t`.
    pub fn corners(&self, t: usize) -> [Vec3; 3] {
        self.triangles[t].map(|i| self.positions[i as usize])
    }

    /// The signed volume enclosed by the triangles (positive for a closed mesh whose
    /// triangles turn counter-clockwise seen from outside): the sum of the tetrahedra from the
    /// origin to each triangle.
    pub fn signed_volume(&self) -> f64 {
        (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.corners(t);
                a.dot(&b.cross(&c)) / 6.0
            })
            .sum()
    }

    /// Refuses coordinates beyond [`MAX_COORDINATE`] and a mesh whose used vertices span less
    /// than [`MIN_SPAN`]: the fit squares lengths and multiplies areas, which overflow or
    /// vanish there (a mesh of kilometres in micrometres is `1e9`, far inside).
    fn check_scale(&self) -> Result<()> {
        if let Some(k) = self
            .positions
            .iter()
            .position(|p| p.amax() > MAX_COORDINATE)
        {
            return Err(Error::invalid(
                vertex_problem(k + 1, self.positions[k]).unwrap_or_default(),
            ));
        }
        // The box's longest side, not its diagonal: the diagonal's squares vanish first.
        let (lo, hi) = self.bounds();
        let span = (hi - lo).amax();
        if span > 0.0 && span < MIN_SPAN {
            return Err(Error::invalid(format!(
                "the mesh spans only {span:e} (its bounding box's longest side, from ({:e}, \
                 {:e}, {:e})), less than the {MIN_SPAN:e} a mesh is computed in (its triangles' \
                 areas would vanish): scale the mesh up",
                lo.x, lo.y, lo.z
            )));
        }
        Ok(())
    }

    /// The surface's area: the sum of its triangles' areas.
    pub fn area(&self) -> f64 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.positions[i as usize]);
                0.5 * (b - a).cross(&(c - a)).norm()
            })
            .sum()
    }

    /// The length of the bounding box's diagonal.
    pub fn diagonal(&self) -> f64 {
        let (lo, hi) = self.bounds();
        (hi - lo).norm()
    }

    /// The corners of the bounding box of the vertices used by triangles.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::repeat(f64::INFINITY);
        let mut hi = Vec3::repeat(f64::NEG_INFINITY);
        for t in &self.triangles {
            for &i in t {
                let p = self.positions[i as usize];
                lo = lo.inf(&p);
                hi = hi.sup(&p);
            }
        }
        (lo, hi)
    }

    /// The size of the mesh in binary: `f32` coordinates and `u32` triangle indices, `12·V + 12·T`
    /// bytes.
    pub fn binary_size(&self) -> usize {
        12 * self.positions.len() + 12 * self.triangles.len()
    }

    /// Boundary and non-manifold edges, connected components and degenerate triangles.
    pub fn topology(&self) -> Topology {
        let mut edges: HashMap<(u32, u32), u32> = HashMap::with_capacity(self.triangles.len() * 2);
        let mut degenerate = 0;
        let mut parent: Vec<u32> = (0..self.positions.len() as u32).collect();
        for t in &self.triangles {
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                degenerate += 1;
            }
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
                union(&mut parent, a, b);
            }
        }
        let boundary_edges = edges.values().filter(|&&c| c == 1).count();
        let nonmanifold_edges = edges.values().filter(|&&c| c > 2).count();
        let mut roots: Vec<u32> = self
            .triangles
            .iter()
            .map(|t| find(&mut parent, t[0]))
            .collect();
        roots.sort_unstable();
        roots.dedup();
        Topology {
            boundary_edges,
            nonmanifold_edges,
            components: roots.len(),
            degenerate,
        }
    }

    /// The connected components (through shared vertices), each a mesh of its own triangles
    /// and the vertices they use, in the order of their first triangle.
    pub fn components(&self) -> Vec<InputMesh> {
        self.components_indexed()
            .into_iter()
            .map(|(m, _)| m)
            .collect()
    }

    /// [`InputMesh::components`], each with the index in this mesh of each of its vertices.
    pub fn components_indexed(&self) -> Vec<(InputMesh, Vec<u32>)> {
        let mut parent: Vec<u32> = (0..self.positions.len() as u32).collect();
        for t in &self.triangles {
            union(&mut parent, t[0], t[1]);
            union(&mut parent, t[1], t[2]);
        }
        let mut part_of: HashMap<u32, usize> = HashMap::new();
        let mut parts: Vec<(InputMesh, Vec<u32>)> = Vec::new();
        // Each vertex's index in its part.
        let mut index: HashMap<u32, u32> = HashMap::new();
        for t in &self.triangles {
            let root = find(&mut parent, t[0]);
            let k = *part_of.entry(root).or_insert_with(|| {
                parts.push((
                    InputMesh {
                        positions: Vec::new(),
                        triangles: Vec::new(),
                    },
                    Vec::new(),
                ));
                parts.len() - 1
            });
            let (part, whole) = &mut parts[k];
            let tri = t.map(|i| {
                *index.entry(i).or_insert_with(|| {
                    part.positions.push(self.positions[i as usize]);
                    whole.push(i);
                    (part.positions.len() - 1) as u32
                })
            });
            part.triangles.push(tri);
        }
        parts
    }

    /// Per vertex, whether a triangle uses it.
    pub fn used_vertices(&self) -> Vec<bool> {
        let mut used = vec![false; self.positions.len()];
        for t in &self.triangles {
            for &i in t {
                used[i as usize] = true;
            }
        }
        used
    }

    /// The closed loops of boundary edges (edges of one triangle), each as its vertices in
    /// order. Fails, naming the vertex, where the boundary passes a vertex twice.
    pub fn boundary_loops(&self) -> Result<Vec<Vec<u32>>> {
        let mut edges: HashMap<(u32, u32), u32> = HashMap::with_capacity(self.triangles.len() * 2);
        for t in &self.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_insert(0) += 1;
            }
        }
        let mut next: HashMap<u32, Vec<u32>> = HashMap::new();
        for (&(a, b), &c) in &edges {
            if c == 1 {
                next.entry(a).or_default().push(b);
                next.entry(b).or_default().push(a);
            }
        }
        let mut starts: Vec<u32> = next.keys().copied().collect();
        starts.sort_unstable();
        if let Some(v) = starts.iter().find(|v| next[v].len() != 2) {
            return Err(Error::invalid(format!(
                "the boundary of the mesh passes vertex {} more than once",
                v + 1
            )));
        }
        let mut seen: HashMap<u32, bool> = HashMap::new();
        let mut loops = Vec::new();
        for &s in &starts {
            if seen.contains_key(&s) {
                continue;
            }
            let mut ring = vec![s];
            seen.insert(s, true);
            let (mut prev, mut at) = (s, next[&s][0]);
            while at != s {
                seen.insert(at, true);
                ring.push(at);
                let n = &next[&at];
                let step = if n[0] == prev { n[1] } else { n[0] };
                prev = at;
                at = step;
            }
            loops.push(ring);
        }
        Ok(loops)
    }

    /// Refuses a mesh that is not one edge-manifold surface (open or closed), with a message
    /// that says what was found.
    pub fn require_single(&self) -> Result<Topology> {
        let t = self.topology();
        if t.nonmanifold_edges > 0 {
            return Err(Error::invalid(format!(
                "the mesh is not manifold: {} edges are shared by three or more triangles",
                t.nonmanifold_edges
            )));
        }
        if t.components > 1 {
            return Err(Error::invalid(format!(
                "the mesh has {} separate components; fit each on its own",
                t.components
            )));
        }
        Ok(t)
    }

    /// Refuses a mesh that is not one closed, edge-manifold surface, with a message that says
    /// what was found.
    pub fn require_closed(&self) -> Result<Topology> {
        let t = self.require_single()?;
        if t.boundary_edges > 0 {
            return Err(Error::invalid(format!(
                "the mesh is open ({} boundary edges): the tube mode fits closed bodies",
                t.boundary_edges
            )));
        }
        Ok(t)
    }

    /// Refuses a mesh that is not one open, edge-manifold surface.
    pub fn require_open(&self) -> Result<Topology> {
        let t = self.require_single()?;
        if t.boundary_edges == 0 {
            return Err(Error::invalid(
                "the mesh is closed: the sheet mode fits open surfaces",
            ));
        }
        Ok(t)
    }
}

/// Merges vertices closer than [`WELD_FRACTION`] of the bounding-box diagonal into the first of
/// them (cells of that size, each vertex compared with the kept vertices of the 27 cells around
/// it), renumbers the triangles and drops those left with two equal corners; returns the mesh,
/// the number of merged vertices and of dropped triangles.
fn weld_by_position(mesh: InputMesh) -> Result<(InputMesh, usize, usize)> {
    let eps = WELD_FRACTION * mesh.diagonal();
    let (lo, _) = mesh.bounds();
    let cell = |p: &Vec3| -> [i64; 3] {
        if eps > 0.0 {
            [0, 1, 2].map(|c| ((p[c] - lo[c]) / eps).floor() as i64)
        } else {
            [0; 3]
        }
    };
    let mut cells: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    let mut positions: Vec<Vec3> = Vec::new();
    let mut map = vec![u32::MAX; mesh.positions.len()];
    let used = mesh.used_vertices();
    let mut welded = 0;
    for (k, p) in mesh.positions.iter().enumerate() {
        if !used[k] {
            continue;
        }
        let c = cell(p);
        let mut found = None;
        'search: for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(list) = cells.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) {
                        if let Some(&j) = list
                            .iter()
                            .find(|&&j| (positions[j as usize] - p).norm() <= eps)
                        {
                            found = Some(j);
                            break 'search;
                        }
                    }
                }
            }
        }
        map[k] = match found {
            Some(j) => {
                welded += 1;
                j
            }
            None => {
                let j = positions.len() as u32;
                positions.push(*p);
                cells.entry(c).or_default().push(j);
                j
            }
        };
    }
    let before = mesh.triangles.len();
    let triangles: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .map(|t| t.map(|i| map[i as usize]))
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
        .collect();
    let dropped = before - triangles.len();
    Ok((InputMesh::new(positions, triangles)?, welded, dropped))
}

fn find(parent: &mut [u32], mut a: u32) -> u32 {
    while parent[a as usize] != a {
        let g = parent[parent[a as usize] as usize];
        parent[a as usize] = g;
        a = g;
    }
    a
}

fn union(parent: &mut [u32], a: u32, b: u32) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        parent[ra.max(rb) as usize] = ra.min(rb);
    }
}

/// Refuses a mesh whose reading ([`crate::memory::mesh_read`]: the file's bytes and
/// `elements` vertices and faces, counted from the header or the lines before anything is
/// stored) would not fit in the memory budget.
pub(super) fn check_memory(bytes: &[u8], elements: usize) -> Result<()> {
    crate::memory::check(
        crate::memory::mesh_read(bytes.len() as u64, elements as u64),
        &format!("reading a mesh of {elements} vertices and faces"),
        "",
    )
}

pub(super) fn check_count(triangles: usize) -> Result<()> {
    if triangles > MAX_TRIANGLES {
        return Err(Error::invalid(format!(
            "the mesh has {triangles} triangles, more than the {MAX_TRIANGLES} a fit reads; \
             decimate it first"
        )));
    }
    Ok(())
}

/// The units and up axis (whether `+Y`) an OBJ, STL or PLY file states in the line the tool's
/// writers put in its comments or header: `units: mm (1 unit = 0.001 m); up: +Y` (OBJ comments
/// before the first element, PLY `comment` lines of the header) or `units mm; up +Y` (the
/// binary STL's 80-byte header). `None` for a file that states no units.
pub(crate) fn stated_frame(bytes: &[u8], format: MeshFormat) -> Option<(Units, bool)> {
    let lines = || {
        bytes
            .split(|&b| b == b'\n')
            .map(|l| String::from_utf8_lossy(l).trim().to_string())
    };
    match format {
        MeshFormat::Obj => lines()
            .take_while(|l| l.is_empty() || l.starts_with('#'))
            .find_map(|l| stated_line(l.trim_start_matches('#'))),
        MeshFormat::Ply => lines()
            .take_while(|l| l != "end_header")
            .filter_map(|l| l.strip_prefix("comment ").map(str::to_string))
            .find_map(|l| stated_line(&l)),
        MeshFormat::Stl if bytes.len() >= 84 && !bytes.starts_with(b"solid") => {
            let head = &bytes[..80];
            let end = head.iter().position(|&b| b == 0).unwrap_or(80);
            stated_line(&String::from_utf8_lossy(&head[..end]))
        }
        _ => None,
    }
}

/// The units and up axis of one line: `;`-separated pieces, one `units[:] U` (mm, cm, m or
/// in, then anything), optionally one `up[:] +Y` or `+Z`; other pieces are not read.
fn stated_line(line: &str) -> Option<(Units, bool)> {
    let mut units = None;
    let mut y_up = false;
    let value = |piece: &str, key: &str| -> Option<String> {
        let rest = piece.strip_prefix(key)?;
        rest.starts_with([':', ' '])
            .then(|| rest.trim_start_matches(':').trim().to_string())
    };
    for piece in line.split(';').map(str::trim) {
        if let Some(v) = value(piece, "units") {
            units = Some(Units::parse(v.split_whitespace().next()?).ok()?);
        } else if let Some(v) = value(piece, "up") {
            y_up = match v.to_ascii_lowercase().as_str() {
                "+y" | "y" => true,
                "+z" | "z" => false,
                _ => return None,
            };
        }
    }
    units.map(|u| (u, y_up))
}

/// What is wrong with the mesh's vertex number `k` (counted from 1) at `p`: a coordinate that
/// is not finite, or one beyond [`MAX_COORDINATE`]; `None` for a vertex a mesh can be
/// computed with.
fn vertex_problem(k: usize, p: Vec3) -> Option<String> {
    if !p.iter().all(|c| c.is_finite()) {
        Some(format!(
            "vertex {k} is not finite: ({}, {}, {})",
            p.x, p.y, p.z
        ))
    } else if p.amax() > MAX_COORDINATE {
        Some(format!(
            "vertex {k} lies at ({:e}, {:e}, {:e}), beyond the ±{MAX_COORDINATE:e} a mesh is \
             computed in (its squared distances would overflow): scale the mesh down",
            p.x, p.y, p.z
        ))
    } else {
        None
    }
}

/// The first `v` line of an OBJ file whose vertex a mesh cannot be computed with
/// ([`vertex_problem`]), as `line L: vertex k …` with `k` the file's own number of the vertex
/// (the parser numbers vertices in the order faces first use them). Looked for only once the
/// parsed mesh has such a vertex.
fn obj_vertex_problem(bytes: &[u8]) -> Option<String> {
    let mut k = 0;
    for (line, l) in bytes.split(|&b| b == b'\n').enumerate() {
        let Some(rest) = l.strip_prefix(b"v ").or_else(|| l.strip_prefix(b"v\t")) else {
            continue;
        };
        k += 1;
        let c: Vec<f64> = String::from_utf8_lossy(rest)
            .split_whitespace()
            .take(3)
            .filter_map(|x| x.parse().ok())
            .collect();
        if let [x, y, z] = c[..] {
            if let Some(what) = vertex_problem(k, Vec3::new(x, y, z)) {
                return Some(format!("line {}: {what}", line + 1));
            }
        }
    }
    None
}

/// Splits a polygon of `n ≥ 3` corners into a fan.
fn fan(out: &mut Vec<[u32; 3]>, corners: &[u32]) {
    for k in 1..corners.len().saturating_sub(1) {
        out.push([corners[0], corners[k], corners[k + 1]]);
    }
}

/// Splits a face of `n ≥ 3` corners into `n − 2` triangles of its orientation: a convex face
/// (every corner turning the same way about its Newell normal) into a fan, a non-convex one
/// (a CAD export's L-shaped or notched face) by a constrained Delaunay triangulation of its
/// corners in its own plane, the triangles inside its outline kept (a fan of a non-convex
/// face folds triangles back over each other). A face that has no plane, touches or crosses
/// itself, or refers to vertices not yet read is fanned, as the file has it.
fn polygon(out: &mut Vec<[u32; 3]>, positions: &[Vec3], corners: &[u32]) {
    let n = corners.len();
    if n <= 3 || corners.iter().any(|&c| c as usize >= positions.len()) {
        return fan(out, corners);
    }
    let p: Vec<Vec3> = corners.iter().map(|&c| positions[c as usize]).collect();
    let origin = p[0];
    let mut normal = Vec3::zeros();
    for k in 0..n {
        normal += (p[k] - origin).cross(&(p[(k + 1) % n] - origin));
    }
    let len = normal.norm();
    if !(len.is_finite() && len > 0.0) {
        return fan(out, corners);
    }
    let normal = normal / len;
    let e1 = {
        let t = if normal.x.abs() < 0.9 {
            Vec3::x()
        } else {
            Vec3::y()
        };
        (t - normal * normal.dot(&t)).normalize()
    };
    let e2 = normal.cross(&e1);
    let q: Vec<[f64; 2]> = p
        .iter()
        .map(|x| [(x - origin).dot(&e1), (x - origin).dot(&e2)])
        .collect();
    let turn = |k: usize| {
        let (a, b, c) = (q[k], q[(k + 1) % n], q[(k + 2) % n]);
        (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0])
    };
    if (0..n).all(|k| turn(k) >= 0.0) {
        return fan(out, corners);
    }
    match triangulate_outline(&q) {
        Some(tris) => out.extend(tris.iter().map(|t| t.map(|k| corners[k]))),
        None => fan(out, corners),
    }
}

/// The triangles (corner indices, counterclockwise) of the simple counterclockwise polygon
/// `q`, from a constrained Delaunay triangulation of its corners and sides: `None` when its
/// sides touch or cross, two corners coincide, or the triangles inside are not `n − 2`.
fn triangulate_outline(q: &[[f64; 2]]) -> Option<Vec<[usize; 3]>> {
    use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};
    let n = q.len();
    let mut cdt = ConstrainedDelaunayTriangulation::<Point2<f64>>::new();
    let mut handles = Vec::with_capacity(n);
    for c in q {
        handles.push(cdt.insert(Point2::new(c[0], c[1])).ok()?);
    }
    if cdt.num_vertices() != n {
        return None;
    }
    let corner: HashMap<usize, usize> = handles
        .iter()
        .enumerate()
        .map(|(k, h)| (h.index(), k))
        .collect();
    for k in 0..n {
        let (a, b) = (handles[k], handles[(k + 1) % n]);
        if !cdt.can_add_constraint(a, b) {
            return None;
        }
        cdt.add_constraint(a, b);
    }
    // Inside the outline: the centroid's winding number about it.
    let inside = |x: f64, y: f64| {
        let mut wind = 0i32;
        for k in 0..n {
            let (a, b) = (q[k], q[(k + 1) % n]);
            let side = (b[0] - a[0]) * (y - a[1]) - (x - a[0]) * (b[1] - a[1]);
            if a[1] <= y && b[1] > y && side > 0.0 {
                wind += 1;
            } else if a[1] > y && b[1] <= y && side < 0.0 {
                wind -= 1;
            }
        }
        wind != 0
    };
    let mut tris = Vec::with_capacity(n - 2);
    for f in cdt.inner_faces() {
        let v = f.vertices();
        let (x, y) = v.iter().fold((0.0, 0.0), |(x, y), h| {
            (x + h.position().x / 3.0, y + h.position().y / 3.0)
        });
        if inside(x, y) {
            tris.push([
                *corner.get(&v[0].fix().index())?,
                *corner.get(&v[1].fix().index())?,
                *corner.get(&v[2].fix().index())?,
            ]);
        }
    }
    (tris.len() == n - 2).then_some(tris)
}

/// The positions and triangles of an OBJ file, and how many models (objects, groups, material
/// runs) the parser found.
fn read_obj(bytes: &[u8]) -> Result<(Vec<Vec3>, Vec<[u32; 3]>, usize)> {
    // Count faces before parsing, so a huge file is refused before it is stored.
    let (mut faces, mut vertices) = (0, 0);
    for l in bytes.split(|&b| b == b'\n') {
        if l.starts_with(b"f ") || l.starts_with(b"f\t") {
            faces += 1;
        } else if l.starts_with(b"v ") || l.starts_with(b"v\t") {
            vertices += 1;
        }
    }
    check_count(faces)?;
    check_memory(bytes, faces + vertices)?;
    let opts = tobj::LoadOptions {
        single_index: false,
        triangulate: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let prepared = obj_for_parser(bytes);
    let bytes = prepared.as_deref().unwrap_or(bytes);
    let (models, _) =
        tobj::load_obj_buf(&mut Cursor::new(bytes), &opts, |_| Ok(Default::default())).map_err(
            |e| Error::invalid(reader_message(&format!("not a readable OBJ file: {e}"))),
        )?;
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for model in &models {
        let m = &model.mesh;
        if m.positions.len() % 3 != 0 {
            return Err(Error::invalid(
                "OBJ vertex with fewer than three coordinates",
            ));
        }
        let base = positions.len() as u32;
        positions.extend(
            m.positions
                .chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2])),
        );
        let mut at = 0;
        let arities: Vec<u32> = if m.face_arities.is_empty() {
            vec![3; m.indices.len() / 3]
        } else {
            m.face_arities.clone()
        };
        for a in arities {
            let a = a as usize;
            if at + a > m.indices.len() {
                return Err(Error::invalid("OBJ face list ends early"));
            }
            let corners: Vec<u32> = m.indices[at..at + a].iter().map(|&i| i + base).collect();
            if a >= 3 {
                polygon(&mut triangles, &positions, &corners);
            }
            at += a;
        }
    }
    if positions.iter().any(|p| vertex_problem(0, *p).is_some()) {
        if let Some(what) = obj_vertex_problem(bytes) {
            return Err(Error::invalid(what));
        }
    }
    Ok((positions, triangles, models.len()))
}

/// An OBJ file's text as the parser takes it, when it differs from the file: a line ending in
/// `\` is continued on the next (the format's line continuation, as Rhino writes long faces),
/// and a `usemtl` that names no material is blanked (materials are not read; the parser
/// refuses it). Lines joined or blanked are kept as empty lines, so the text has the file's
/// line count.
fn obj_for_parser(bytes: &[u8]) -> Option<Vec<u8>> {
    let unnamed = |l: &[u8]| l.trim_ascii() == b"usemtl";
    let continued = |l: &[u8]| l.trim_ascii_end().ends_with(b"\\");
    if !bytes
        .split(|&b| b == b'\n')
        .any(|l| unnamed(l) || continued(l))
    {
        return None;
    }
    let mut out = Vec::with_capacity(bytes.len());
    let mut pending = 0;
    for l in bytes.split(|&b| b == b'\n') {
        if continued(l) {
            let l = l.trim_ascii_end();
            out.extend_from_slice(&l[..l.len() - 1]);
            out.push(b' ');
            pending += 1;
            continue;
        }
        if !unnamed(l) {
            out.extend_from_slice(l);
        }
        out.push(b'\n');
        out.extend(std::iter::repeat_n(b'\n', pending));
        pending = 0;
    }
    Some(out)
}

fn read_stl(bytes: &[u8]) -> Result<(Vec<Vec3>, Vec<[u32; 3]>)> {
    // A binary STL states its triangle count at byte 80; refuse a huge one before reading it.
    let ascii = bytes.starts_with(b"solid") && bytes.len() >= 84 && {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        84 + 50 * n != bytes.len()
    };
    if !ascii && bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        // The file's own length first: a count past its end is a truncated file (or not an
        // STL), whatever the count.
        if 84 + 50 * n > bytes.len() {
            return Err(Error::invalid(format!(
                "the STL file is truncated: it announces {n} triangles ({} bytes) but has {} bytes",
                84 + 50 * n,
                bytes.len()
            )));
        }
        check_count(n)?;
        check_memory(bytes, 4 * n)?;
    }
    if ascii || bytes.len() < 84 {
        let corners = bytes
            .split(|&b| b == b'\n')
            .filter(|l| l.trim_ascii_start().starts_with(b"vertex"))
            .count();
        check_memory(bytes, corners)?;
    }
    let mut cursor = Cursor::new(bytes);
    let reader = stl_io::create_stl_reader(&mut cursor)
        .map_err(|e| Error::invalid(reader_message(&format!("not a readable STL file: {e}"))))?;
    let mut index: HashMap<[u32; 3], u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for (k, tri) in reader.enumerate() {
        let tri = tri
            .map_err(|e| Error::invalid(reader_message(&format!("STL triangle {}: {e}", k + 1))))?;
        if triangles.len() >= MAX_TRIANGLES {
            check_count(triangles.len() + 1)?;
        }
        let mut t = [0u32; 3];
        for (c, v) in tri.vertices.iter().enumerate() {
            let p = [v[0], v[1], v[2]];
            if !p.iter().all(|x| x.is_finite()) {
                return Err(Error::invalid(format!(
                    "STL triangle {}: corner {} is not finite: ({}, {}, {})",
                    k + 1,
                    c + 1,
                    p[0],
                    p[1],
                    p[2]
                )));
            }
            // +0 and −0 are the same point.
            let key = p.map(|x| (x + 0.0).to_bits());
            let next = positions.len() as u32;
            let i = *index.entry(key).or_insert_with(|| {
                positions.push(Vec3::new(p[0] as f64, p[1] as f64, p[2] as f64));
                next
            });
            t[c] = i;
        }
        triangles.push(t);
    }
    Ok((positions, triangles))
}

fn read_ply(bytes: &[u8]) -> Result<(Vec<Vec3>, Vec<[u32; 3]>)> {
    // The reader counts the lines of an element's data from 0; the file's line numbers count
    // the header's and the earlier elements' too.
    let header_lines = bytes
        .split(|&b| b == b'\n')
        .position(|l| l.trim_ascii() == b"end_header")
        .map_or(0, |i| i + 1);
    let bad = |e: std::io::Error| Error::invalid(ply_message(&e.to_string(), 0));
    let mut cursor = Cursor::new(bytes);
    let header = ply_rs::parser::Parser::<PlySkip>::new()
        .read_header(&mut cursor)
        .map_err(bad)?;
    check_count(header.elements.get("face").map_or(0, |e| e.count))?;
    let elements = header
        .elements
        .values()
        .fold(0usize, |n, e| n.saturating_add(e.count));
    check_memory(bytes, elements)?;
    // Every element takes at least one byte of the file: a count the file cannot hold is
    // refused before the reader sizes anything from it.
    for (name, e) in &header.elements {
        if e.count > bytes.len() {
            return Err(Error::invalid(format!(
                "not a readable PLY file: the header announces {} {} elements, more than its {} bytes can hold",
                e.count,
                crate::spec::words::user_text(name),
                bytes.len()
            )));
        }
    }
    // Each element read into what the fit keeps of it (coordinates, index lists), in the
    // header's order; the others are read and dropped. (The reader's own element, a map of
    // named properties per vertex and face, took some 190 bytes each: 309 MB of a
    // million-triangle scan.) Its line numbers count from each element's first line.
    let mut verts: Vec<PlyVertex> = Vec::new();
    let mut faces: Vec<PlyIndices> = Vec::new();
    let mut strip_lists: Vec<PlyIndices> = Vec::new();
    let mut before = 0usize;
    for (name, e) in &header.elements {
        let at = |err: std::io::Error| {
            Error::invalid(ply_message(&err.to_string(), header_lines + 1 + before))
        };
        match name.as_str() {
            "vertex" => {
                verts = ply_rs::parser::Parser::<PlyVertex>::new()
                    .read_payload_for_element(&mut cursor, e, &header)
                    .map_err(at)?
            }
            "face" | "tristrips" => {
                let read = ply_rs::parser::Parser::<PlyIndices>::new()
                    .read_payload_for_element(&mut cursor, e, &header)
                    .map_err(at)?;
                if name == "face" {
                    faces = read;
                } else {
                    strip_lists = read;
                }
            }
            _ => {
                ply_rs::parser::Parser::<PlySkip>::new()
                    .read_payload_for_element(&mut cursor, e, &header)
                    .map_err(at)?;
            }
        }
        before = before.saturating_add(e.count);
    }
    let mut positions = Vec::with_capacity(verts.len());
    for (k, v) in verts.iter().enumerate() {
        let mut p = [0.0; 3];
        for (c, key) in ["x", "y", "z"].iter().enumerate() {
            p[c] = v.0[c].ok_or_else(|| {
                Error::invalid(format!("PLY vertex {}: no numeric '{key}'", k + 1))
            })?;
        }
        positions.push(Vec3::new(p[0], p[1], p[2]));
    }
    let mut triangles = Vec::new();
    for (k, f) in faces.into_iter().enumerate() {
        let corners = f.list().ok_or_else(|| {
            Error::invalid(format!(
                "PLY face {}: no integer list 'vertex_indices'",
                k + 1
            ))
        })?;
        if corners.iter().any(|&i| i < 0 || i > u32::MAX as i64) {
            return Err(Error::invalid(format!(
                "PLY face {}: a negative or too large vertex index",
                k + 1
            )));
        }
        let corners: Vec<u32> = corners.iter().map(|&i| i as u32).collect();
        polygon(&mut triangles, &positions, &corners);
    }
    for (k, s) in strip_lists.into_iter().enumerate() {
        let list = s.list().ok_or_else(|| {
            Error::invalid(format!(
                "PLY tristrips {}: no integer list 'vertex_indices'",
                k + 1
            ))
        })?;
        strips(&mut triangles, &list).map_err(|at| {
            Error::invalid(format!(
                "PLY tristrips {}: index {} ({}) is neither a vertex nor -1, the end of a strip",
                k + 1,
                at + 1,
                list[at]
            ))
        })?;
        check_count(triangles.len())?;
    }
    Ok((positions, triangles))
}

/// A number of any PLY scalar type (`None` for a list).
fn ply_scalar(p: &ply_rs::ply::Property) -> Option<f64> {
    use ply_rs::ply::Property;
    Some(match *p {
        Property::Float(x) => x as f64,
        Property::Double(x) => x,
        Property::Char(x) => x as f64,
        Property::UChar(x) => x as f64,
        Property::Short(x) => x as f64,
        Property::UShort(x) => x as f64,
        Property::Int(x) => x as f64,
        Property::UInt(x) => x as f64,
        _ => return None,
    })
}

/// A PLY vertex as a fit reads it: `x`, `y`, `z` (`None` where absent or not a number).
struct PlyVertex([Option<f64>; 3]);

impl ply_rs::ply::PropertyAccess for PlyVertex {
    fn new() -> Self {
        PlyVertex([None; 3])
    }
    fn set_property(&mut self, name: String, property: ply_rs::ply::Property) {
        let c = match name.as_str() {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => return,
        };
        self.0[c] = ply_scalar(&property);
    }
}

/// A PLY face or strip as a fit reads it: its list of vertex indices, `vertex_indices` (or
/// `vertex_index`, as some writers name it, when there is no `vertex_indices`), of any integer
/// type; `Some(None)` when that property is not an integer list.
#[derive(Default)]
struct PlyIndices {
    list: Option<Option<SmallVec<[i64; 4]>>>,
    /// The list is `vertex_indices`' (which a `vertex_index` does not replace).
    named: bool,
}

impl PlyIndices {
    fn list(self) -> Option<SmallVec<[i64; 4]>> {
        self.list.flatten()
    }
}

impl ply_rs::ply::PropertyAccess for PlyIndices {
    fn new() -> Self {
        PlyIndices::default()
    }
    fn set_property(&mut self, name: String, property: ply_rs::ply::Property) {
        use ply_rs::ply::Property;
        let named = match name.as_str() {
            "vertex_indices" => true,
            "vertex_index" if !self.named => false,
            _ => return,
        };
        let list = match property {
            Property::ListChar(x) => Some(x.iter().map(|&i| i as i64).collect()),
            Property::ListUChar(x) => Some(x.iter().map(|&i| i as i64).collect()),
            Property::ListShort(x) => Some(x.iter().map(|&i| i as i64).collect()),
            Property::ListUShort(x) => Some(x.iter().map(|&i| i as i64).collect()),
            Property::ListInt(x) => Some(x.iter().map(|&i| i as i64).collect()),
            Property::ListUInt(x) => Some(x.iter().map(|&i| i as i64).collect()),
            _ => None,
        };
        self.list = Some(list);
        self.named = named;
    }
}

/// A PLY element a fit does not use: read, as the format asks, and dropped.
struct PlySkip;

impl ply_rs::ply::PropertyAccess for PlySkip {
    fn new() -> Self {
        PlySkip
    }
}

/// The triangles of a PLY `tristrips` list (the Stanford and Georgia Tech scans' layout):
/// strips of vertex indices separated by `−1`, each strip `s₀ s₁ s₂ …` the triangles
/// `(s_{k}, s_{k+1}, s_{k+2})` for even `k` and `(s_{k+1}, s_{k}, s_{k+2})` for odd `k`, so that
/// every triangle keeps the first one's orientation. A triangle with a repeated corner (how a
/// strip turns or jumps) is no triangle and left out. `Err(position)` names an index that is
/// neither a vertex index nor `−1`.
fn strips(out: &mut Vec<[u32; 3]>, list: &[i64]) -> std::result::Result<(), usize> {
    if let Some(at) = list.iter().position(|&i| i < -1 || i > u32::MAX as i64) {
        return Err(at);
    }
    for strip in list.split(|&i| i == -1) {
        for (k, w) in strip.windows(3).enumerate() {
            let [a, b, c] = [w[0] as u32, w[1] as u32, w[2] as u32];
            if a == b || b == c || a == c {
                continue;
            }
            out.push(if k % 2 == 0 { [a, b, c] } else { [b, a, c] });
        }
    }
    Ok(())
}

/// The positions and triangles of an OFF file as text: a header line whose keyword (in any
/// case) ends in `OFF` (`OFF`, or `COFF`, `NOFF`, `STOFF`, … whose vertices carry colours,
/// normals or texture coordinates after their three coordinates, which are not read), the
/// counts of vertices, faces and (optionally) edges on the same line or the next, one vertex
/// per line, then one face per line: its corner count `n`, `n` indices from 0, and anything
/// after them (a colour) not read. `#` starts a comment; blank lines are skipped. Faces of more than three corners
/// are split into fans, faces of fewer skipped (points and segments, as OBJ's are). Binary OFF
/// and the `4OFF` and `nOFF` variants (points of other dimensions) are refused. Errors name the
/// file's line.
fn read_off(bytes: &[u8]) -> Result<(Vec<Vec3>, Vec<[u32; 3]>)> {
    let bad = |line: usize, what: String| {
        Error::invalid(format!("not a readable OFF file: line {line}: {what}"))
    };
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let line = 1 + bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        bad(
            line,
            "not text (binary OFF is not read: write it as text)".into(),
        )
    })?;
    let mut lines = text
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.split('#').next().unwrap_or("").trim()))
        .filter(|(_, l)| !l.is_empty());
    let (at, header) = lines
        .next()
        .ok_or_else(|| Error::invalid("not a readable OFF file: the file is empty"))?;
    let mut words = header.split_whitespace();
    let raw = words.next().unwrap_or("");
    // A count glued to the keyword (`OFF8 6 12`, as some writers leave it) is the first count.
    let (raw, glued) = match raw.to_ascii_uppercase().find("OFF") {
        Some(i) if i + 3 < raw.len() && raw[i + 3..].bytes().all(|b| b.is_ascii_digit()) => {
            (&raw[..i + 3], Some(&raw[i + 3..]))
        }
        _ => (raw, None),
    };
    // `4OFF` and `nOFF` (a lower-case n) are points of other dimensions; otherwise the
    // keyword is read in any case (`off` is seen too).
    if raw.contains('4') || raw.ends_with("nOFF") {
        return Err(bad(
            at,
            format!(
                "{}: points of other than three coordinates are not read",
                crate::spec::words::user_text(raw)
            ),
        ));
    }
    let keyword = raw.to_ascii_uppercase();
    let known = keyword
        .strip_suffix("OFF")
        .is_some_and(|prefix| prefix.chars().all(|c| matches!(c, 'S' | 'T' | 'C' | 'N')));
    if !known {
        return Err(bad(
            at,
            format!(
                "the file starts with '{}', not an OFF keyword (OFF, COFF, NOFF, STOFF, …)",
                crate::spec::words::user_text(raw)
            ),
        ));
    }
    let mut rest: Vec<&str> = glued.into_iter().chain(words).collect();
    if rest
        .first()
        .is_some_and(|w| w.eq_ignore_ascii_case("BINARY"))
    {
        return Err(bad(at, "binary OFF is not read: write it as text".into()));
    }
    let mut counts_at = at;
    if rest.is_empty() {
        let (l, c) = lines
            .next()
            .ok_or_else(|| bad(at, "no counts of vertices and faces follow".into()))?;
        counts_at = l;
        rest = c.split_whitespace().collect();
    }
    let count = |k: usize, what: &str| -> Result<usize> {
        let w = rest
            .get(k)
            .ok_or_else(|| bad(counts_at, format!("no count of {what}")))?;
        let n: usize = w.parse().map_err(|_| {
            bad(
                counts_at,
                format!(
                    "the count of {what} '{}' is not a whole number",
                    crate::spec::words::user_text(w)
                ),
            )
        })?;
        // Every vertex and face takes a line of at least two bytes.
        if n > bytes.len() / 2 {
            return Err(bad(
                counts_at,
                format!(
                    "{n} {what} announced, more than its {} bytes can hold",
                    bytes.len()
                ),
            ));
        }
        Ok(n)
    };
    let (nv, nf) = (count(0, "vertices")?, count(1, "faces")?);
    check_count(nf)?;
    check_memory(bytes, nv + nf)?;
    let number = |line: usize, w: &str, what: &str| -> Result<f64> {
        w.parse::<f64>().map_err(|_| {
            bad(
                line,
                format!(
                    "{what}: '{}' is not a number",
                    crate::spec::words::user_text(w)
                ),
            )
        })
    };
    let mut positions = Vec::with_capacity(nv);
    for k in 0..nv {
        let (l, v) = lines
            .next()
            .ok_or_else(|| bad(at, format!("the file ends after {k} of its {nv} vertices")))?;
        let w: Vec<&str> = v.split_whitespace().take(3).collect();
        if w.len() < 3 {
            return Err(bad(
                l,
                format!("vertex {k} has fewer than three coordinates"),
            ));
        }
        let what = format!("vertex {k}");
        positions.push(Vec3::new(
            number(l, w[0], &what)?,
            number(l, w[1], &what)?,
            number(l, w[2], &what)?,
        ));
    }
    let mut triangles = Vec::with_capacity(nf);
    let mut corners = Vec::new();
    for k in 0..nf {
        let (l, f) = lines
            .next()
            .ok_or_else(|| bad(at, format!("the file ends after {k} of its {nf} faces")))?;
        let mut w = f.split_whitespace();
        let n: usize = w
            .next()
            .and_then(|x| x.parse().ok())
            .ok_or_else(|| bad(l, format!("face {k} does not start with its corner count")))?;
        corners.clear();
        for _ in 0..n {
            let x = w
                .next()
                .ok_or_else(|| bad(l, format!("face {k} has fewer than its {n} corner indices")))?;
            let i: u32 = x.parse().map_err(|_| {
                bad(
                    l,
                    format!(
                        "face {k}: '{}' is not a vertex index",
                        crate::spec::words::user_text(x)
                    ),
                )
            })?;
            if i as usize >= nv {
                return Err(bad(
                    l,
                    format!("face {k} refers to vertex {i} but the file has {nv} vertices (counted from 0)"),
                ));
            }
            corners.push(i);
        }
        polygon(&mut triangles, &positions, &corners);
    }
    Ok((positions, triangles))
}

/// A mesh reader's message on one line in plain words: its first line, the Rust number types
/// it names (`vertex f32 f32 f32`) called numbers, long quoted values shortened.
fn reader_message(raw: &str) -> String {
    let mut first = raw.lines().next().unwrap_or("").trim();
    // `stl_io` refuses values that do not fit a 32-bit float (`1e308` reads as infinity) with
    // "expected finite f32, got inf which is Infinite".
    let range = "a number is not finite or lies beyond ±3.4e38 (STL stores single precision)";
    let joined;
    if let Some(at) = first.find("expected finite f32") {
        joined = format!("{}{range}", &first[..at]);
        first = &joined;
    }
    let mut out = first
        .replace("f32 f32 f32", "three numbers")
        .replace("f64 f64 f64", "three numbers");
    for (t, w) in [
        ("f32", "a number"),
        ("f64", "a number"),
        ("u32", "a whole number"),
        ("usize", "a whole number"),
        ("u8", "a whole number"),
        ("i32", "a whole number"),
    ] {
        out = out
            .split(' ')
            .map(|word| if word == t { w } else { word })
            .collect::<Vec<_>>()
            .join(" ");
    }
    crate::spec::words::shorten_quoted(&out)
}

/// The PLY reader's message in plain words on one line: its own (`Line 7: Couln't read element
/// line.` followed by the reader's internal error values) becomes `line 7: the element line
/// `3 1 2 x` does not match the header …`; anything else keeps its first line.
fn ply_message(raw: &str, offset: usize) -> String {
    let first = raw.lines().next().unwrap_or("").trim();
    let line = first
        .strip_prefix("Line ")
        .and_then(|r| r.split(':').next())
        .and_then(|n| n.trim().parse::<usize>().ok())
        .map(|n| n + offset);
    let quoted = raw
        .lines()
        .find_map(|l| l.trim().strip_prefix("String: '"))
        .map(|s| {
            s.trim_end_matches('\'')
                .trim_end_matches("\\n")
                .trim()
                .to_string()
        });
    let text = match (line, quoted) {
        (Some(n), Some(q)) => format!(
            "line {n}: the element line `{q}` does not match the header (a value that is not a \
             number of the declared type, or a wrong count)"
        ),
        (Some(n), None) => format!(
            "line {n}: {}",
            first.split_once(':').map_or(first, |(_, r)| r).trim()
        ),
        _ if first.is_empty() => "the header or the data is damaged".to_string(),
        _ => first.to_string(),
    };
    crate::spec::words::shorten_quoted(&format!("not a readable PLY file: {text}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A damaged PLY element line is reported by its line and text, without the reader's
    /// internal error values.
    #[test]
    fn ply_read_errors_are_one_plain_line() {
        let ply = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                   property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
                   end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 1e-7\n";
        let e = InputMesh::read(ply.as_bytes(), MeshFormat::Ply)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("line 13: the element line `3 0 1 1e-7` does not match the header"),
            "{e}"
        );
        for word in [
            "ParseIntError",
            "Custom",
            "kind",
            "String:",
            "\n",
            "Couln't",
        ] {
            assert!(!e.contains(word), "{word} in {e}");
        }
    }

    /// The elements a fit does not use are read and dropped in the header's order (an element
    /// between the vertices and the faces, extra properties), `vertex_index` stands for a
    /// missing `vertex_indices`, a damaged line after a skipped element is still named by the
    /// file's own line number, and an index list that is not of integers is refused.
    #[test]
    fn ply_elements_are_read_in_the_header_order() {
        let ply = |faces: &str, list: &str| {
            format!(
                "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
                 property float z\nproperty uchar red\nelement material 2\nproperty float shine\n\
                 element face 4\nproperty list uchar {list}\nproperty float quality\n\
                 end_header\n0 0 0 9\n1 0 0 9\n0 1 0 9\n0 0 1 9\n0.5\n0.25\n{faces}"
            )
        };
        let faces = "3 0 2 1 1\n3 0 1 3 1\n3 1 2 3 1\n3 0 3 2 1\n";
        for name in ["int vertex_indices", "int vertex_index"] {
            let m = InputMesh::read(ply(faces, name).as_bytes(), MeshFormat::Ply).unwrap();
            assert_eq!(m.triangles, tetra().triangles, "{name}");
            assert_eq!(m.positions, tetra().positions, "{name}");
        }
        // The header's 13 lines, 4 vertices and 2 materials: the third face is line 22.
        let broken = "3 0 2 1 1\n3 0 1 3 1\n3 1 x 3 1\n3 0 3 2 1\n";
        let e = InputMesh::read(
            ply(broken, "int vertex_indices").as_bytes(),
            MeshFormat::Ply,
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("line 22: the element line `3 1 x 3 1`"), "{e}");
        let e = InputMesh::read(
            ply(faces, "float vertex_indices").as_bytes(),
            MeshFormat::Ply,
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("PLY face 1: no integer list 'vertex_indices'"),
            "{e}"
        );
    }

    /// A PLY of triangle strips (`element tristrips`, as the Stanford and Georgia Tech scans
    /// are written) reads as its triangles: a tetrahedron as one strip, and as three strips
    /// with `-1` between them and a repeated corner, is closed and every edge is used once in
    /// each direction (the strips' alternate triangles turned to the first one's orientation),
    /// facing out (volume 1/6 by the divergence theorem). An index below -1 is refused by its
    /// strip and place.
    #[test]
    fn triangle_strips_read_as_their_triangles() {
        let ply = |list: &str| {
            let n = list.split_whitespace().count();
            format!(
                "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
                 property float z\nelement tristrips 1\nproperty list int int vertex_indices\n\
                 end_header\n0 0 0\n1 0 0\n0 1 0\n0 0 -1\n{n} {list}\n"
            )
        };
        for list in ["0 1 2 3 0 1", "0 1 2 3 3 -1 2 3 0 -1 0 3 1"] {
            let m = InputMesh::read(ply(list).as_bytes(), MeshFormat::Ply).unwrap();
            assert_eq!(m.triangles.len(), 4, "{list}");
            let mut directed = std::collections::HashSet::new();
            let volume = m.signed_volume();
            for t in &m.triangles {
                for k in 0..3 {
                    assert!(directed.insert((t[k], t[(k + 1) % 3])), "{list}: {t:?}");
                }
            }
            for &(a, b) in &directed {
                assert!(directed.contains(&(b, a)), "{list}: edge {a}-{b} once");
            }
            assert!(
                (volume - 1.0 / 6.0).abs() < 1e-15,
                "{list}: volume {volume}"
            );
        }
        let e = InputMesh::read(ply("0 1 2 -2").as_bytes(), MeshFormat::Ply)
            .unwrap_err()
            .to_string();
        assert!(e.contains("PLY tristrips 1: index 4 (-2)"), "{e}");
    }

    /// An ASCII STL vertex line that is not three numbers is reported without Rust type names.
    #[test]
    fn stl_read_errors_name_no_rust_types() {
        let stl = "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvetex 1 0 0\n\
                   vertex 0 1 0\nendloop\nendfacet\nendsolid s\n";
        let e = InputMesh::read(stl.as_bytes(), MeshFormat::Stl)
            .unwrap_err()
            .to_string();
        assert!(e.contains("STL triangle 1"), "{e}");
        assert!(!e.contains("f32"), "{e}");
    }

    /// A value beyond single precision (`1e308` reads as infinity) is named in plain words.
    #[test]
    fn stl_values_beyond_single_precision_are_plain() {
        let stl = "solid s\nfacet normal 0 1e308 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n\
                   vertex 0 1 0\nendloop\nendfacet\nendsolid s\n";
        let e = InputMesh::read(stl.as_bytes(), MeshFormat::Stl)
            .unwrap_err()
            .to_string();
        assert!(e.contains("STL triangle 1: a number is not finite"), "{e}");
        for word in ["f32", "Infinite", "expected"] {
            assert!(!e.contains(word), "{word} in {e}");
        }
    }

    /// An OFF file as CGAL's and Princeton's data write them: a `COFF` header, counts on the
    /// next line, colours after the coordinates and after a face's indices, comments and blank
    /// lines; a quadrilateral is split into a fan. The tetrahedron is read as [`tetra`] is.
    #[test]
    fn off_files_are_read_with_their_colours_and_comments_ignored() {
        let off = "COFF # a tetrahedron\n\n4 5 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n\
                   0 1 0 0 0 255 255\n  0 0 1 9 9 9 255\n# faces\n3 0 2 1 200 200 200\n\
                   3 0 1 3\n3 1 2 3\n3 0 3 2\n2 0 1\n";
        let m = InputMesh::read(off.as_bytes(), MeshFormat::Off).unwrap();
        assert_eq!(m, tetra());
        let quad = "off 4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
        let m = InputMesh::read(quad.as_bytes(), MeshFormat::Off).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(MeshFormat::from_extension("OFF"), Some(MeshFormat::Off));
        // A count glued to the keyword, after leading blanks, is the vertex count.
        let glued = "\t  OFF4 1 0 # glued\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n";
        assert_eq!(
            InputMesh::read(glued.as_bytes(), MeshFormat::Off).unwrap(),
            m
        );
    }

    /// An OBJ as Rhino writes it, a `usemtl` naming no material, a missing material library
    /// and faces continued on the next line by a `\`, reads as its faces: materials are not
    /// read.
    #[test]
    fn obj_unnamed_materials_and_continued_lines_are_read() {
        let obj = "mtllib missing.mtl\nusemtl \nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n\
                   f 1 3 \\\n 2\nusemtl\r\nf 1 \\\r\n2 \\\n4\nf 2 3 4\nf 1 4 3\n";
        // The same triangles by their corners' positions (the parser numbers vertices in
        // the order the faces use them), each turned to start at its smallest corner.
        let corners = |m: &InputMesh| {
            let mut t: Vec<[[u64; 3]; 3]> = m
                .triangles
                .iter()
                .map(|t| {
                    let mut c = t.map(|i| m.positions[i as usize].map(f64::to_bits).into());
                    let first = (0..3).min_by_key(|&k| c[k]).unwrap();
                    c.rotate_left(first);
                    c
                })
                .collect();
            t.sort();
            t
        };
        let m = InputMesh::read(obj.as_bytes(), MeshFormat::Obj).unwrap();
        assert_eq!(corners(&m), corners(&tetra()));
        // A bad face after a blanked `usemtl` is still the parser's refusal, not read past.
        let bad = "usemtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n";
        let e = InputMesh::read(bad.as_bytes(), MeshFormat::Obj)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("not a readable OBJ file: face parse error"),
            "{e}"
        );
    }

    /// Damaged OFF files: one line naming the file's line and what is wrong there.
    #[test]
    fn off_read_errors_name_the_line() {
        let cases = [
            ("", "the file is empty"),
            (
                "PLY\n",
                "line 1: the file starts with 'PLY', not an OFF keyword",
            ),
            (
                "4OFF\n1 0 0\n",
                "line 1: 4OFF: points of other than three coordinates",
            ),
            (
                "nOFF\n4\n1 0 0\n",
                "line 1: nOFF: points of other than three coordinates",
            ),
            ("off binary\n", "line 1: binary OFF is not read"),
            ("OFF BINARY\n", "line 1: binary OFF is not read"),
            ("OFF\n3\n", "line 2: no count of faces"),
            (
                "OFF\n3 x 0\n",
                "line 2: the count of faces 'x' is not a whole number",
            ),
            (
                "OFF\n99999 1 0\n",
                "line 2: 99999 vertices announced, more than its",
            ),
            (
                "OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n",
                "line 4: vertex 1 has fewer than three coordinates",
            ),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 zero\n0 1 0\n3 0 1 2\n",
                "line 4: vertex 1: 'zero' is not a number",
            ),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
                "line 6: face 0 refers to vertex 3 but the file has 3 vertices",
            ),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n",
                "line 6: face 0: '-1' is not a vertex index",
            ),
            (
                "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                "the file ends after 1 of its 2 faces",
            ),
            (
                "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n",
                "line 6: face 0 has fewer than its 3 corner indices",
            ),
        ];
        for (text, want) in cases {
            let e = InputMesh::read(text.as_bytes(), MeshFormat::Off)
                .unwrap_err()
                .to_string();
            assert!(e.starts_with("not a readable OFF file: "), "{e}");
            assert!(e.contains(want), "{text:?}: {e}");
            assert!(!e.contains('\n'), "{e}");
        }
        let e = InputMesh::read(b"OFF\n\xff\xfe", MeshFormat::Off)
            .unwrap_err()
            .to_string();
        assert!(e.contains("line 2: not text"), "{e}");
    }

    /// OBJ coordinates are read in double precision: a scan in world coordinates (millions of
    /// units from the origin, millimetre detail) keeps its detail (single precision would
    /// round 10 000 000.123 to 10 000 000).
    #[test]
    fn obj_coordinates_keep_double_precision() {
        let obj = "v 10000000.123 -30000000.5 5000000.25\nv 10000000.124 -30000000.5 5000000.25\n\
                   v 10000000.123 -30000000.499 5000000.25\nf 1 2 3\n";
        let m = InputMesh::read(obj.as_bytes(), MeshFormat::Obj).unwrap();
        assert_eq!(
            m.positions[0],
            Vec3::new(10000000.123, -30000000.5, 5000000.25)
        );
        assert_eq!(m.positions[1].x, 10000000.124);
        assert_eq!(m.positions[2].y, -30000000.499);
    }

    fn tetra() -> InputMesh {
        InputMesh::new(
            vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(0.0, 0.0, 1.0),
            ],
            vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
        )
        .unwrap()
    }

    #[test]
    fn closed_tetrahedron_passes_and_its_parts_are_refused() {
        let t = tetra();
        assert_eq!(t.require_closed().unwrap().components, 1);
        let mut open = t.clone();
        open.triangles.pop();
        let e = open.require_closed().unwrap_err().to_string();
        assert!(e.contains("open (3 boundary edges)"), "{e}");
        let mut two = t.clone();
        let n = two.positions.len() as u32;
        two.positions
            .extend(t.positions.iter().map(|p| p + Vec3::x() * 5.0));
        two.triangles
            .extend(t.triangles.iter().map(|tr| tr.map(|i| i + n)));
        let e = two.require_closed().unwrap_err().to_string();
        assert!(e.contains("2 separate components"), "{e}");
        let mut fin = t.clone();
        fin.positions.push(Vec3::new(1.0, 1.0, 1.0));
        fin.triangles.push([0, 1, 4]);
        let e = fin.require_closed().unwrap_err().to_string();
        assert!(e.contains("not manifold: 1 edges"), "{e}");
    }

    /// An OBJ of two objects, each with its own copies of the shared vertices (as an exporter
    /// writes one object per part), is one closed mesh once welded; a single object is read as
    /// it is, without a note.
    #[test]
    fn obj_objects_are_welded_into_one_mesh() {
        let t = tetra();
        // The second object's copies are moved by `shift` along x.
        let obj = |shift: f64| {
            let mut obj = String::new();
            let mut next = 1;
            for (name, tris) in [("a", &t.triangles[..2]), ("b", &t.triangles[2..])] {
                obj += &format!("o {name}\n");
                for tr in tris {
                    for &i in tr {
                        let p = t.positions[i as usize];
                        let d = if name == "b" { shift } else { 0.0 };
                        obj += &format!("v {} {} {}\n", p.x + d, p.y, p.z);
                    }
                    obj += &format!("f {} {} {}\n", next, next + 1, next + 2);
                    next += 3;
                }
            }
            obj
        };
        // Copies that differ by far less than the weld's distance are one vertex.
        let obj_close = obj(1e-9);
        let read = InputMesh::read_report(obj_close.as_bytes(), MeshFormat::Obj).unwrap();
        assert_eq!(read.mesh.positions.len(), 4);
        assert_eq!(read.mesh.triangles.len(), 4);
        assert_eq!(read.mesh.require_closed().unwrap().components, 1);
        let j = read.joined.unwrap();
        assert_eq!((j.parts, j.welded, j.dropped), (2, 8, 0));
        let note = read.note().unwrap();
        assert!(note.contains("2 objects or groups"), "{note}");
        assert!(note.contains("8 vertices welded"), "{note}");
        // The same faces as groups weld alike.
        let groups = obj_close.replace("o a", "g a").replace("o b", "g b");
        let read = InputMesh::read_report(groups.as_bytes(), MeshFormat::Obj).unwrap();
        assert_eq!(read.mesh.require_closed().unwrap().components, 1);
        // Objects apart stay apart, and the fit's check says so.
        let apart = obj(5.0);
        let read = InputMesh::read_report(apart.as_bytes(), MeshFormat::Obj).unwrap();
        let e = read.mesh.require_single().unwrap_err().to_string();
        assert!(e.contains("2 separate components"), "{e}");
        // One object: no weld, no note.
        let single = obj_close.replace("o b\n", "");
        let read = InputMesh::read_report(single.as_bytes(), MeshFormat::Obj).unwrap();
        assert_eq!(read.joined, None);
        assert_eq!(read.note(), None);
        assert_eq!(read.mesh.positions.len(), 12);
    }

    #[test]
    fn bad_values_are_refused_with_their_place() {
        let e = InputMesh::new(vec![], vec![]).unwrap_err().to_string();
        assert!(e.contains("no triangles"), "{e}");
        let mut p = tetra().positions;
        p[2].y = f64::NAN;
        let e = InputMesh::new(p, tetra().triangles)
            .unwrap_err()
            .to_string();
        assert!(e.contains("vertex 3 is not finite"), "{e}");
        let e = InputMesh::new(tetra().positions, vec![[0, 1, 7]])
            .unwrap_err()
            .to_string();
        assert!(e.contains("triangle 1 refers to vertex 8"), "{e}");
    }

    /// Coordinates whose squares overflow, or a mesh so small its areas vanish, are refused
    /// with the vertex or the extent; any size between (and far from the origin) is read.
    #[test]
    fn scales_a_fit_cannot_compute_in_are_refused() {
        let scaled = |k: f64, shift: f64| {
            let t = tetra();
            let p = t.positions.iter().map(|p| p * k + Vec3::repeat(shift));
            InputMesh::new(p.collect(), t.triangles)
        };
        let e = scaled(1e200, 0.0).unwrap_err().to_string();
        assert!(e.contains("vertex 2 lies at (1e200, 0e0, 0e0)"), "{e}");
        assert!(e.contains("scale the mesh down"), "{e}");
        let e = scaled(1e-200, 0.0).unwrap_err().to_string();
        assert!(e.contains("spans only 1e-200"), "{e}");
        assert!(e.contains("scale the mesh up"), "{e}");
        // An unused vertex far away counts as well (its coordinates are the file's).
        let mut t = tetra();
        t.positions.push(Vec3::new(0.0, -2e61, 0.0));
        let e = InputMesh::new(t.positions, t.triangles)
            .unwrap_err()
            .to_string();
        assert!(e.contains("vertex 5 lies at"), "{e}");
        // Read at any scale between: the diagonal √3 k, up to the rounding of the shifted
        // coordinates (a few units in the last place of the shift).
        for (k, shift) in [(1e59, 0.0), (1e-59, 0.0), (1.0, 1e9), (1e-50, 1e-40)] {
            let d = scaled(k, shift).unwrap().diagonal();
            let bound = 1e-15 * k + 4.0 * f64::EPSILON * shift;
            assert!((d - 3f64.sqrt() * k).abs() <= bound, "{k} {shift}: {d}");
        }
    }

    /// An L-shaped prism whose two ends are single hexagons, each listed from a corner that
    /// does not see the whole face (a fan from it folds a triangle back over the face), and
    /// whose six sides are quads: every format splits the ends in their planes, so every
    /// triangle faces out, the surface is closed, and its area is the prism's.
    #[test]
    fn non_convex_faces_are_split_in_their_planes_in_every_format() {
        let outline = [
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
            (0.0, 0.0),
        ];
        let h = 0.5;
        let mut v = String::new();
        for z in [0.0, h] {
            for (x, y) in outline {
                v += &format!("{x} {y} {z}\n");
            }
        }
        // Zero-based corners: the bottom reversed (seen from below), the top, the sides.
        let mut faces: Vec<Vec<usize>> = vec![(0..6).rev().collect(), (6..12).collect()];
        for k in 0..6 {
            let j = (k + 1) % 6;
            faces.push(vec![k, j, j + 6, k + 6]);
        }
        let line = |f: &Vec<usize>, base: usize| {
            f.iter()
                .map(|i| (i + base).to_string())
                .collect::<Vec<_>>()
                .join(" ")
        };
        let obj: String = v.lines().map(|l| format!("v {l}\n")).collect::<String>()
            + &faces
                .iter()
                .map(|f| format!("f {}\n", line(f, 1)))
                .collect::<String>();
        let off = format!("OFF\n12 8 0\n{v}")
            + &faces
                .iter()
                .map(|f| format!("{} {}\n", f.len(), line(f, 0)))
                .collect::<String>();
        let ply = "ply\nformat ascii 1.0\nelement vertex 12\nproperty double x\n\
                   property double y\nproperty double z\nelement face 8\n\
                   property list uchar int vertex_indices\nend_header\n"
            .to_string()
            + &v
            + &faces
                .iter()
                .map(|f| format!("{} {}\n", f.len(), line(f, 0)))
                .collect::<String>();
        let area = 2.0 * 3.0 + h * 8.0;
        for (name, bytes, format) in [
            ("OBJ", obj, MeshFormat::Obj),
            ("OFF", off, MeshFormat::Off),
            ("PLY", ply, MeshFormat::Ply),
        ] {
            let m = InputMesh::read(bytes.as_bytes(), format).unwrap();
            assert_eq!(m.triangles.len(), 2 * 4 + 6 * 2, "{name}");
            m.require_closed().unwrap();
            let mut total = 0.0;
            for k in 0..m.triangles.len() {
                let [a, b, c] = m.corners(k);
                let n = (b - a).cross(&(c - a));
                total += 0.5 * n.norm();
                let centre = (a + b + c) / 3.0;
                // Outward: the ends along ∓z, the sides away from the outline's inside.
                let out = if centre.z.abs() < 1e-12 {
                    -Vec3::z()
                } else if (centre.z - h).abs() < 1e-12 {
                    Vec3::z()
                } else {
                    let inner = Vec3::new(0.75, 0.75, centre.z);
                    let d = centre - inner;
                    Vec3::new(d.x, d.y, 0.0)
                };
                assert!(
                    n.dot(&out) > 0.0,
                    "{name}: triangle {k} faces in: {a} {b} {c}"
                );
            }
            assert!(
                (total - area).abs() < 1e-12,
                "{name}: area {total} against {area}"
            );
        }
    }

    /// Faces the plane split cannot take keep the fan, without a panic: one that crosses
    /// itself (a bow tie), one with two corners at one point, one without area.
    #[test]
    fn faces_without_a_simple_outline_are_fanned() {
        let p = |x: f64, y: f64| Vec3::new(x, y, 0.0);
        let positions = vec![
            p(0.0, 0.0),
            p(1.0, 1.0),
            p(1.0, 0.0),
            p(0.0, 1.0),
            p(0.5, 0.2),
        ];
        for corners in [
            vec![0, 1, 2, 3],
            vec![0, 2, 4, 1, 4, 3],
            vec![0, 4, 4, 1],
            vec![0, 0, 0, 0],
        ] {
            let mut fanned = Vec::new();
            fan(&mut fanned, &corners);
            let mut out = Vec::new();
            polygon(&mut out, &positions, &corners);
            assert_eq!(out, fanned, "{corners:?}");
        }
        // Convex faces are fanned as before, whatever their size.
        let hexagon: Vec<u32> = (0..6).collect();
        let ring: Vec<Vec3> = (0..6)
            .map(|k| {
                let t = k as f64 * std::f64::consts::PI / 3.0;
                Vec3::new(t.cos(), t.sin(), 0.3)
            })
            .collect();
        let (mut out, mut fanned) = (Vec::new(), Vec::new());
        polygon(&mut out, &ring, &hexagon);
        fan(&mut fanned, &hexagon);
        assert_eq!(out, fanned);
    }

    #[test]
    fn the_three_formats_read_the_same_tetrahedron() {
        let t = tetra();
        let mut obj = String::new();
        for p in &t.positions {
            obj += &format!("v {} {} {}\n", p.x, p.y, p.z);
        }
        for tr in &t.triangles {
            obj += &format!("f {} {} {}\n", tr[0] + 1, tr[1] + 1, tr[2] + 1);
        }
        // The OBJ and STL readers number vertices in the order the faces first use them: the
        // same mesh, triangle by triangle, up to that renumbering.
        let same = |m: &InputMesh| {
            assert_eq!(m.positions.len(), t.positions.len());
            assert_eq!(m.triangles.len(), t.triangles.len());
            for k in 0..t.triangles.len() {
                assert_eq!(m.corners(k), t.corners(k), "triangle {k}");
            }
        };
        same(&InputMesh::read(obj.as_bytes(), MeshFormat::Obj).unwrap());
        let mut ply = String::from(
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
             property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
        );
        for p in &t.positions {
            ply += &format!("{} {} {}\n", p.x, p.y, p.z);
        }
        for tr in &t.triangles {
            ply += &format!("3 {} {} {}\n", tr[0], tr[1], tr[2]);
        }
        assert_eq!(InputMesh::read(ply.as_bytes(), MeshFormat::Ply).unwrap(), t);
        let tris: Vec<stl_io::Triangle> = (0..4)
            .map(|k| stl_io::Triangle {
                normal: stl_io::Normal::new([0.0; 3]),
                vertices: t
                    .corners(k)
                    .map(|p| stl_io::Vertex::new([p.x as f32, p.y as f32, p.z as f32])),
            })
            .collect();
        let mut stl = Vec::new();
        stl_io::write_stl(&mut stl, tris.iter()).unwrap();
        same(&InputMesh::read(&stl, MeshFormat::Stl).unwrap());
        // Truncated: the announced count does not fit.
        let e = InputMesh::read(&stl[..stl.len() - 7], MeshFormat::Stl)
            .unwrap_err()
            .to_string();
        assert!(e.contains("truncated"), "{e}");
        // A count beyond the limit is refused before anything is read.
        let mut huge = stl[..84].to_vec();
        huge[80..84].copy_from_slice(&10_000_000u32.to_le_bytes());
        let e = InputMesh::read(&huge, MeshFormat::Stl)
            .unwrap_err()
            .to_string();
        assert!(e.contains("10000000 triangles"), "{e}");
        let e = InputMesh::read(
            b"ply\nformat ascii 1.0\nelement vertex 4\n",
            MeshFormat::Ply,
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("PLY"), "{e}");
        let e = InputMesh::read(b"v 0 0 0\nv 1 0 0\nf 1 2 3\n", MeshFormat::Obj)
            .unwrap_err()
            .to_string();
        assert!(!e.is_empty());
    }
}
