//! Sharp features of a mesh, for the general mode's layout: the edges where two triangles meet
//! at more than [`FEATURE_ANGLE`] (a box's edges, a drilled hole's rim) split the triangles
//! about each vertex into smooth *sectors*, each with its own normal. A layout edge between
//! two faces that lie in different sectors at one of its ends runs along a feature: it is a
//! crease (G0), its tangent at that end along the feature (the line both sectors' planes hold).
//! A layout edge whose faces lie in one sector at a sharp vertex takes that sector's normal at
//! that end (`end_normals` of the `[[patchwork]]` edge), so the faces of a flat side of a box
//! stay flat up to its edges and corners instead of leaning into the average of the planes
//! that meet there. Vertices with one sector (all of a smooth mesh's) keep the mesh's
//! area-weighted normal, as before.

use super::mesh::InputMesh;
use crate::Vec3;
use std::collections::HashMap;

/// The dihedral angle (degrees) between two triangles' normals across their shared edge above
/// which the edge is a sharp feature. Smooth meshes tessellated as coarsely as the low-polygon
/// models in the tests (a teapot's 6° to 30° between neighbouring facets) stay smooth; a box's
/// 90°, a chamfer's 45° and the fandisk's creases are features.
pub(super) const FEATURE_ANGLE: f64 = 40.0;

/// The fewest sharp edges joined end to end that make a feature (a box's twelve edges are one
/// run, a drilled hole's rim of 16 segments another).
const MIN_FEATURE_EDGES: usize = 6;

/// The largest angle (degrees) between a feature's direction (where the planes of the sectors on
/// either side of a layout edge meet) and the chord of a layout edge that follows it, at which
/// the edge's end tangent is laid along the feature (an arc of a circle leaves its chord at
/// half its angle). Beyond it the edge keeps its fitted tangent, and the design creases the
/// corner's edges if they leave its planes.
const FEATURE_FOLLOW_ANGLE: f64 = 80.0;

/// An edge of two triangles: its ends (the smaller first), the two triangles' corners at each
/// end, and whether it is sharp.
type EdgePair = ((u32, u32), [u32; 2], [u32; 2], bool);

/// The mesh's smooth sectors about its vertices.
pub(super) struct Sectors {
    /// Per triangle corner (`3 t + c`) its sector.
    sector: Vec<u32>,
    /// Per sector its unit normal.
    normal: Vec<Vec3>,
    /// Per vertex whether it has more than one sector.
    sharp: Vec<bool>,
    /// Per vertex the start of its triangles in `around` (`offsets[v]..offsets[v + 1]`).
    offsets: Vec<u32>,
    /// The triangle corners (`3 t + c`) at each vertex.
    around: Vec<u32>,
    /// The sharp edges from each vertex on one (by the vertex): the other end, and the two
    /// triangles' corners at this vertex.
    feature: HashMap<u32, Vec<(u32, [u32; 2])>>,
}

fn find(parent: &mut [u32], mut x: u32) -> u32 {
    while parent[x as usize] != x {
        let p = parent[x as usize];
        parent[x as usize] = parent[p as usize];
        x = p;
    }
    x
}

fn union(parent: &mut [u32], a: u32, b: u32) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        parent[ra.max(rb) as usize] = ra.min(rb);
    }
}

/// The triangle's unit normal, or zero when it has no area.
fn face_normal(c: &[Vec3; 3]) -> Vec3 {
    let n = (c[1] - c[0]).cross(&(c[2] - c[0]));
    let l = n.norm();
    if l > 0.0 && l.is_finite() {
        n / l
    } else {
        Vec3::zeros()
    }
}

impl Sectors {
    /// No sectors but the vertices' own (no sharp feature): every corner takes its vertex's
    /// normal of `normals`.
    pub(super) fn smooth(mesh: &InputMesh, normals: &[Vec3]) -> Sectors {
        let nv = mesh.positions.len();
        Sectors {
            sector: mesh.triangles.iter().flatten().copied().collect(),
            normal: normals.to_vec(),
            sharp: vec![false; nv],
            offsets: vec![0; nv + 1],
            around: Vec::new(),
            feature: HashMap::new(),
        }
    }

    /// The sectors of `mesh`, whose area-weighted vertex normals are `normals` (kept at the
    /// vertices of one sector).
    pub(super) fn new(mesh: &InputMesh, normals: &[Vec3]) -> Sectors {
        let nt = mesh.triangles.len();
        let face: Vec<Vec3> = (0..nt).map(|t| face_normal(&mesh.corners(t))).collect();
        let cos_feature = FEATURE_ANGLE.to_radians().cos();
        // Each edge of two triangles: its ends, and the two triangles' corners at each end.
        let mut first: HashMap<(u32, u32), (u32, u32)> = HashMap::with_capacity(3 * nt / 2);
        let mut pairs: Vec<EdgePair> = Vec::new();
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for c in 0..3 {
                let (a, b) = (tri[c], tri[(c + 1) % 3]);
                let (ca, cb) = (3 * t as u32 + c as u32, 3 * t as u32 + (c as u32 + 1) % 3);
                let key = (a.min(b), a.max(b));
                let here = if a < b { (ca, cb) } else { (cb, ca) };
                match first.get(&key) {
                    None => {
                        first.insert(key, here);
                    }
                    Some(&(oa, ob)) => {
                        let (n0, n1) = (face[oa as usize / 3], face[t]);
                        // A triangle without area takes no side.
                        let sharp =
                            n0 != Vec3::zeros() && n1 != Vec3::zeros() && n0.dot(&n1) < cos_feature;
                        pairs.push((key, [oa, here.0], [ob, here.1], sharp));
                    }
                }
            }
        }
        drop(first);
        // Sharp edges in runs of fewer than `MIN_FEATURE_EDGES` (a scan's noise, a stray fold)
        // are no feature.
        let mut run: Vec<u32> = (0..mesh.positions.len() as u32).collect();
        for &((a, b), _, _, sharp) in &pairs {
            if sharp {
                union(&mut run, a, b);
            }
        }
        let mut run_edges: HashMap<u32, usize> = HashMap::new();
        for &((a, _), _, _, sharp) in &pairs {
            if sharp {
                *run_edges.entry(find(&mut run, a)).or_default() += 1;
            }
        }
        let mut parent: Vec<u32> = (0..3 * nt as u32).collect();
        let mut feature: HashMap<u32, Vec<(u32, [u32; 2])>> = HashMap::new();
        for &((lo, hi), at_lo, at_hi, sharp) in &pairs {
            if sharp && run_edges[&find(&mut run, lo)] >= MIN_FEATURE_EDGES {
                feature.entry(lo).or_default().push((hi, at_lo));
                feature.entry(hi).or_default().push((lo, at_hi));
            } else {
                union(&mut parent, at_lo[0], at_lo[1]);
                union(&mut parent, at_hi[0], at_hi[1]);
            }
        }
        // Vertices' corners (a CSR table), sectors numbered, their normals weighted by angle.
        let nv = mesh.positions.len();
        let mut offsets = vec![0u32; nv + 1];
        for tri in &mesh.triangles {
            for &v in tri {
                offsets[v as usize + 1] += 1;
            }
        }
        for v in 0..nv {
            offsets[v + 1] += offsets[v];
        }
        let mut fill = offsets.clone();
        let mut around = vec![0u32; 3 * nt];
        for (t, tri) in mesh.triangles.iter().enumerate() {
            for (c, &v) in tri.iter().enumerate() {
                around[fill[v as usize] as usize] = 3 * t as u32 + c as u32;
                fill[v as usize] += 1;
            }
        }
        let mut id: HashMap<u32, u32> = HashMap::new();
        let mut sector = vec![0u32; 3 * nt];
        let mut sum: Vec<Vec3> = Vec::new();
        let mut vertex_of: Vec<u32> = Vec::new();
        for corner in 0..3 * nt as u32 {
            let root = find(&mut parent, corner);
            let next = id.len() as u32;
            let s = *id.entry(root).or_insert(next);
            if s as usize == sum.len() {
                sum.push(Vec3::zeros());
                let (t, c) = (corner as usize / 3, corner as usize % 3);
                vertex_of.push(mesh.triangles[t][c]);
            }
            sector[corner as usize] = s;
            let (t, c) = (corner as usize / 3, corner as usize % 3);
            let p = mesh.corners(t);
            let (x, y) = (p[(c + 1) % 3] - p[c], p[(c + 2) % 3] - p[c]);
            let angle = x.cross(&y).norm().atan2(x.dot(&y));
            sum[s as usize] += face[t] * angle;
        }
        let mut sharp = vec![false; nv];
        for v in 0..nv {
            let (lo, hi) = (offsets[v] as usize, offsets[v + 1] as usize);
            if let Some(&c0) = around[lo..hi].first() {
                let s0 = sector[c0 as usize];
                sharp[v] = around[lo..hi].iter().any(|&c| sector[c as usize] != s0);
            }
        }
        let normal = sum
            .iter()
            .zip(&vertex_of)
            .map(|(s, &v)| {
                let l = s.norm();
                if !sharp[v as usize] || l.is_nan() || l <= 0.0 {
                    normals[v as usize]
                } else {
                    s / l
                }
            })
            .collect();
        Sectors {
            sector,
            normal,
            sharp,
            offsets,
            around,
            feature,
        }
    }

    /// The normal at corner `c` of triangle `t`: its sector's.
    pub(super) fn corner_normal(&self, t: usize, c: usize) -> Vec3 {
        self.normal[self.sector[3 * t + c] as usize]
    }

    /// Whether vertex `v` has more than one sector (it lies on a sharp feature).
    pub(super) fn is_sharp(&self, v: usize) -> bool {
        self.sharp[v]
    }

    /// The unit normal of sector `s`.
    pub(super) fn normal(&self, s: u32) -> Vec3 {
        self.normal[s as usize]
    }

    /// The sector at vertex `v` that the direction `dir` leaves it into: that of the triangle at
    /// `v` whose centroid is seen from `v` most nearly along `dir` (`None` where `v` has no
    /// triangle).
    pub(super) fn sector_towards(&self, mesh: &InputMesh, v: usize, dir: Vec3) -> Option<u32> {
        let (lo, hi) = (self.offsets[v] as usize, self.offsets[v + 1] as usize);
        let p = mesh.positions[v];
        let mut best: Option<(f64, u32)> = None;
        for &corner in &self.around[lo..hi] {
            let t = corner as usize / 3;
            let c = mesh.corners(t);
            let m = (c[0] + c[1] + c[2]) / 3.0 - p;
            let l = m.norm();
            if l.is_nan() || l <= 0.0 {
                continue;
            }
            let cos = m.dot(&dir) / l;
            if best.is_none_or(|b| cos > b.0) {
                best = Some((cos, self.sector[corner as usize]));
            }
        }
        best.map(|b| b.1)
    }

    /// Whether a feature runs on through vertex `x`: it has two sharp edges, turning by less
    /// than [`FEATURE_TURN`] (else it is a feature's corner or end, or where features meet).
    fn runs_through(&self, mesh: &InputMesh, x: u32) -> bool {
        let Some(f) = self.feature.get(&x) else {
            return false;
        };
        if f.len() != 2 {
            return false;
        }
        let p = mesh.positions[x as usize];
        let (a, b) = (
            p - mesh.positions[f[0].0 as usize],
            mesh.positions[f[1].0 as usize] - p,
        );
        a.angle(&b) < FEATURE_TURN.to_radians()
    }

    /// A path of sharp edges from vertex `u` to `v` that stays within [`FEATURE_REACH`] chords
    /// of the segment between them and runs through no feature's corner or end
    /// ([`Sectors::runs_through`]) and no vertex of `stops` (the layout's other vertices): the
    /// sectors on either side of its first edge at `u`.
    fn feature_path(&self, mesh: &InputMesh, stops: &[bool], u: u32, v: u32) -> Option<[u32; 2]> {
        let (pu, pv) = (mesh.positions[u as usize], mesh.positions[v as usize]);
        let chord = pv - pu;
        let len2 = chord.norm_squared();
        if len2.is_nan() || len2 <= 0.0 {
            return None;
        }
        let reach2 = FEATURE_REACH * FEATURE_REACH * len2;
        let near = |x: u32| {
            let d = mesh.positions[x as usize] - pu;
            let t = (d.dot(&chord) / len2).clamp(0.0, 1.0);
            (d - chord * t).norm_squared() <= reach2
        };
        // Breadth first from `u`; each vertex reached keeps the sectors of the first edge of
        // the path that reached it.
        let mut seen: HashMap<u32, [u32; 2]> = HashMap::new();
        let mut queue = std::collections::VecDeque::new();
        for &(w, [c0, c1]) in self.feature.get(&u)? {
            let sides = [self.sector[c0 as usize], self.sector[c1 as usize]];
            if w == v {
                return Some(sides);
            }
            if near(w) && !stops[w as usize] && self.runs_through(mesh, w) && !seen.contains_key(&w)
            {
                seen.insert(w, sides);
                queue.push_back(w);
            }
        }
        while let Some(x) = queue.pop_front() {
            if seen.len() > FEATURE_SEARCH {
                return None;
            }
            let sides = seen[&x];
            for &(w, _) in self.feature.get(&x).map_or(&[][..], |f| f.as_slice()) {
                if w == v {
                    return Some(sides);
                }
                if w != u
                    && near(w)
                    && !stops[w as usize]
                    && self.runs_through(mesh, w)
                    && !seen.contains_key(&w)
                {
                    seen.insert(w, sides);
                    queue.push_back(w);
                }
            }
        }
        None
    }
}

/// How far (in chords) a path of sharp edges may stray from a layout edge's chord and still be
/// the feature the edge follows (an arc of a circle up to about 200° keeps within 0.6 chords
/// of its chord).
const FEATURE_REACH: f64 = 0.6;

/// The largest turn (degrees) between a feature's two sharp edges at a vertex through which it
/// runs on (a polygon of 8 sides turns by 45°).
const FEATURE_TURN: f64 = 50.0;

/// The most vertices a search for a feature path visits.
const FEATURE_SEARCH: usize = 4096;

/// What a layout edge takes at one of its ends from the sectors there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct EndPlan {
    /// The normal of the tangent plane the edge takes at this end (for a crease, that of the
    /// sector on one side).
    pub(super) normal: Vec3,
    /// Whether `normal` is a sector's own (the end is a sharp vertex), to be written as the
    /// edge's `end_normals`.
    pub(super) own: bool,
    /// Along a feature: the feature's unit direction leaving the end (where the planes of the
    /// sectors on either side meet), which the edge's end tangent takes.
    pub(super) along: Option<Vec3>,
}

/// Per layout edge (`ends`: indices into `vertices`, the layout's mesh vertices) whether it is a
/// crease and its plan at each end. An edge joined to its other end by a path of the mesh's
/// sharp edges near its chord follows a feature: a crease, its end tangents along the feature
/// where the edge leaves within [`FEATURE_FOLLOW_ANGLE`] of it. An edge whose faces (`faces`,
/// loops of indices into `vertices`) lie in different sectors at one of its ends crosses a
/// feature there and is a crease too. Any other edge at a sharp vertex takes the normal of its
/// faces' sector there. `corner[i]` is the normal the layout gives vertex `i` where it is not
/// sharp.
pub(super) fn plan_edges(
    mesh: &InputMesh,
    sectors: &Sectors,
    vertices: &[usize],
    faces: &[Vec<usize>],
    corner: &[Vec3],
    ends: &[[usize; 2]],
) -> Vec<(bool, [EndPlan; 2])> {
    let pos = |i: usize| mesh.positions[vertices[i]];
    let unit = |x: Vec3| x / x.norm().max(1e-300);
    let mut stops = vec![false; mesh.positions.len()];
    for &v in vertices {
        stops[v] = true;
    }
    // The sectors of the faces' corners at sharp vertices, by (vertex, other end of a side).
    let mut beside: HashMap<(usize, usize), Vec<u32>> = HashMap::new();
    for face in faces {
        let m = face.len();
        for k in 0..m {
            let i = face[k];
            if !sectors.is_sharp(vertices[i]) {
                continue;
            }
            let (next, prev) = (face[(k + 1) % m], face[(k + m - 1) % m]);
            let dir = unit(pos(next) - pos(i)) + unit(pos(prev) - pos(i));
            if let Some(s) = sectors.sector_towards(mesh, vertices[i], dir) {
                for j in [next, prev] {
                    beside.entry((i, j)).or_default().push(s);
                }
            }
        }
    }
    let follow = FEATURE_FOLLOW_ANGLE.to_radians().cos();
    ends.iter()
        .map(|&[a, b]| {
            let sharp = [a, b].map(|i| sectors.is_sharp(vertices[i]));
            let smooth = |i: usize| EndPlan {
                normal: corner[i],
                own: false,
                along: None,
            };
            if !sharp[0] && !sharp[1] {
                return (false, [smooth(a), smooth(b)]);
            }
            let path = [(a, b), (b, a)].map(|(i, j)| {
                sectors.feature_path(mesh, &stops, vertices[i] as u32, vertices[j] as u32)
            });
            let follows = sharp[0] && sharp[1] && path[0].is_some() && path[1].is_some();
            let sides =
                [(a, b), (b, a)].map(|(i, j)| beside.get(&(i, j)).cloned().unwrap_or_default());
            let crosses = sides.iter().any(|s| s.iter().any(|&x| x != s[0]));
            let plan = [(a, b, path[0], &sides[0]), (b, a, path[1], &sides[1])].map(
                |(i, j, path, side)| {
                    if !sectors.is_sharp(vertices[i]) {
                        return smooth(i);
                    }
                    let chord = unit(pos(j) - pos(i));
                    let own = |s: u32, along: Option<Vec3>| EndPlan {
                        normal: sectors.normal(s),
                        own: true,
                        along,
                    };
                    if let (true, Some([s0, s1])) = (follows, path) {
                        let l = sectors.normal(s0).cross(&sectors.normal(s1));
                        let len = l.norm();
                        let along = (len > 0.1)
                            .then(|| {
                                if l.dot(&chord) < 0.0 {
                                    -l / len
                                } else {
                                    l / len
                                }
                            })
                            .filter(|l| l.dot(&chord) >= follow);
                        return own(s0, along);
                    }
                    let same = side.first().filter(|&&s| side.iter().all(|&x| x == s));
                    match same
                        .copied()
                        .or_else(|| sectors.sector_towards(mesh, vertices[i], chord))
                    {
                        Some(s) => own(s, None),
                        None => smooth(i),
                    }
                },
            );
            (follows || crosses, plan)
        })
        .collect()
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// The unit box as 12 triangles, counterclockwise seen from outside.
    pub(in crate::fit) fn unit_box() -> InputMesh {
        let p = |x: f64, y: f64, z: f64| Vec3::new(x, y, z);
        let positions = vec![
            p(0.0, 0.0, 0.0),
            p(1.0, 0.0, 0.0),
            p(1.0, 1.0, 0.0),
            p(0.0, 1.0, 0.0),
            p(0.0, 0.0, 1.0),
            p(1.0, 0.0, 1.0),
            p(1.0, 1.0, 1.0),
            p(0.0, 1.0, 1.0),
        ];
        let quads = [
            [0, 3, 2, 1],
            [4, 5, 6, 7],
            [0, 1, 5, 4],
            [1, 2, 6, 5],
            [2, 3, 7, 6],
            [3, 0, 4, 7],
        ];
        let triangles = quads
            .iter()
            .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
            .collect();
        InputMesh::new(positions, triangles).unwrap()
    }

    /// A sphere of `n × 2n` quads split in two (poles as fans): neighbouring facets turn by
    /// π/n.
    fn sphere(n: usize) -> InputMesh {
        let mut positions = vec![Vec3::new(0.0, 0.0, 1.0)];
        for i in 1..n {
            let th = std::f64::consts::PI * i as f64 / n as f64;
            for j in 0..2 * n {
                let ph = std::f64::consts::PI * j as f64 / n as f64;
                positions.push(Vec3::new(
                    th.sin() * ph.cos(),
                    th.sin() * ph.sin(),
                    th.cos(),
                ));
            }
        }
        positions.push(Vec3::new(0.0, 0.0, -1.0));
        let m = 2 * n as u32;
        let at = |i: usize, j: u32| 1 + (i as u32 - 1) * m + j % m;
        let south = positions.len() as u32 - 1;
        let mut triangles = Vec::new();
        for j in 0..m {
            triangles.push([0, at(1, j), at(1, j + 1)]);
            triangles.push([south, at(n - 1, j + 1), at(n - 1, j)]);
        }
        for i in 1..n - 1 {
            for j in 0..m {
                let (a, b, c, d) = (at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j));
                triangles.push([a, d, c]);
                triangles.push([a, c, b]);
            }
        }
        InputMesh::new(positions, triangles).unwrap()
    }

    #[test]
    fn a_box_has_a_sector_per_side_at_every_corner_and_a_sphere_none() {
        let mesh = unit_box();
        let normals = crate::fit::vertex_normals(&mesh);
        let s = Sectors::new(&mesh, &normals);
        for v in 0..8 {
            assert!(s.is_sharp(v), "corner {v}");
        }
        // Every corner of a triangle takes its side's normal exactly.
        for t in 0..12 {
            let c = mesh.corners(t);
            let n = (c[1] - c[0]).cross(&(c[2] - c[0])).normalize();
            for k in 0..3 {
                assert!((s.corner_normal(t, k) - n).norm() < 1e-15, "triangle {t}");
            }
        }
        // The box's edge from corner 0 to 1 is a feature; the side's diagonal 0 to 2 is not
        // (the only sharp path bends at corner 1, where three features meet).
        let stops = vec![false; 8];
        assert!(s.feature_path(&mesh, &stops, 0, 1).is_some());
        assert!(s.feature_path(&mesh, &stops, 0, 2).is_none());
        // A sphere whose facets turn by 11.25° has no feature.
        let ball = sphere(16);
        let normals = crate::fit::vertex_normals(&ball);
        let s = Sectors::new(&ball, &normals);
        assert!((0..ball.positions.len()).all(|v| !s.is_sharp(v)));
    }

    #[test]
    fn a_box_layouts_edges_are_creases_along_its_edges_and_planes_across_its_sides() {
        let mesh = unit_box();
        let normals = crate::fit::vertex_normals(&mesh);
        let s = Sectors::new(&mesh, &normals);
        let vertices: Vec<usize> = (0..8).collect();
        let faces: Vec<Vec<usize>> = mesh
            .triangles
            .iter()
            .map(|t| t.iter().map(|&v| v as usize).collect())
            .collect();
        let mut ends: Vec<[usize; 2]> = Vec::new();
        for f in &faces {
            for k in 0..3 {
                let (a, b) = (f[k].min(f[(k + 1) % 3]), f[k].max(f[(k + 1) % 3]));
                if !ends.contains(&[a, b]) {
                    ends.push([a, b]);
                }
            }
        }
        let plans = plan_edges(&mesh, &s, &vertices, &faces, &normals, &ends);
        for (&[a, b], (crease, plan)) in ends.iter().zip(&plans) {
            let chord = mesh.positions[b] - mesh.positions[a];
            // The box's edges are the chords of length 1; the sides' diagonals √2.
            let along_edge = (chord.norm() - 1.0).abs() < 1e-12;
            assert_eq!(*crease, along_edge, "{a}-{b}");
            for (k, end) in plan.iter().enumerate() {
                assert!(end.own);
                let out = if k == 0 { chord } else { -chord };
                if along_edge {
                    // Along the feature: the line both sides' planes hold.
                    let l = end.along.expect("along");
                    assert!((l - out).norm() < 1e-12, "{a}-{b}: {l:?}");
                } else {
                    // Across a side: that side's normal, square to the diagonal.
                    assert!(end.along.is_none());
                    assert!(end.normal.dot(&chord).abs() < 1e-12);
                    assert!((end.normal.abs().sum() - 1.0).abs() < 1e-12);
                }
            }
        }
    }
}
