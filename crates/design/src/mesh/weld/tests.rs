//! The weld's topology and the mesh report against references that count every edge in one
//! map (the construction they replaced, kept here as the definition), on grids with seams,
//! poles, shared edges, near-coincident rows and tiny grids, and on the examples.

use super::*;
use crate::mesh::test_grids::cases;

/// The weld's merge as first written: every vertex visited in order, candidates looked up in
/// the cells around them.
fn merge_reference(
    grids: &[GridMesh],
    options: WeldOptions,
    diag: f64,
) -> (Vec<[f32; 3]>, Vec<Vec<u32>>) {
    let tol = if diag.is_finite() && diag > 0.0 {
        WELD_TOLERANCE * diag
    } else {
        f64::MIN_POSITIVE
    };
    let tol2 = tol * tol;
    let cell = |p: [f32; 3]| p.map(|x| (x as f64 / tol).floor() as i64);
    let mut positions: Vec<[f32; 3]> = Vec::new();
    let mut source: Vec<Vec<u32>> = Vec::new();
    let mut buckets: HashMap<([i64; 3], usize), Vec<u32>> = HashMap::new();
    for (k, g) in grids.iter().enumerate() {
        let group = if options.join_patches { 0 } else { k };
        let (nu, nv) = (g.nu, g.nv);
        let mut cand = vec![false; nu * nv];
        for i in 0..nu {
            let row = &g.positions[i * nv..(i + 1) * nv];
            let collapsed = row.iter().all(|p| p == &row[0]);
            for j in 0..nv {
                let end_col = !g.periodic_v && (j == 0 || j + 1 == nv);
                cand[i * nv + j] = i == 0 || i + 1 == nu || end_col || collapsed;
            }
        }
        let mut map = Vec::new();
        for (idx, &p) in g.positions.iter().enumerate() {
            if !cand[idx] {
                map.push(positions.len() as u32);
                positions.push(p);
                continue;
            }
            let c = cell(p);
            let mut found = None;
            'search: for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        if let Some(list) = buckets.get(&([c[0] + dx, c[1] + dy, c[2] + dz], group))
                        {
                            for &w in list {
                                let q = positions[w as usize];
                                let d2: f64 =
                                    (0..3).map(|a| (p[a] as f64 - q[a] as f64).powi(2)).sum();
                                if d2 <= tol2 {
                                    found = Some(w);
                                    break 'search;
                                }
                            }
                        }
                    }
                }
            }
            let w = found.unwrap_or_else(|| {
                let w = positions.len() as u32;
                positions.push(p);
                buckets.entry((c, group)).or_default().push(w);
                w
            });
            map.push(w);
        }
        source.push(map);
    }
    (positions, source)
}

/// The topology as first built: every edge of every triangle in one map.
fn topology_reference(grids: &[GridMesh], names: &[&str], options: WeldOptions) -> WeldTopology {
    let diag = diagonal(grids);
    let (positions, source) = merge_reference(grids, options, diag);
    let tris: Vec<Vec<[u32; 3]>> = grids
        .iter()
        .zip(&source)
        .map(|(g, map)| {
            g.triangles()
                .map(|t| t.map(|i| map[i as usize]))
                .filter(|[a, b, c]| a != b && b != c && a != c)
                .collect()
        })
        .collect();
    let mut edges: HashMap<(u32, u32), (usize, bool, u32)> = HashMap::new();
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    for (k, ts) in tris.iter().enumerate() {
        for t in ts {
            for e in 0..3 {
                let (a, b) = (t[e], t[(e + 1) % 3]);
                edges.entry(key(a, b)).or_insert((k, a < b, 0)).2 += 1;
            }
        }
    }
    let uses = |a: u32, b: u32| edges.get(&key(a, b)).map_or(0, |e| e.2);
    let mut parity = Parity::new(grids.len());
    for (k, ts) in tris.iter().enumerate() {
        for t in ts {
            for e in 0..3 {
                let (a, b) = (t[e], t[(e + 1) % 3]);
                if let Some(&(first, forward, 2)) = edges.get(&key(a, b)) {
                    if first != k {
                        parity.join(first, k, forward == (a < b));
                    }
                }
            }
        }
    }
    let relative: Vec<(usize, bool)> = (0..grids.len()).map(|k| parity.find(k)).collect();
    let mut groups: Vec<Group> = Vec::new();
    for &(root, _) in &relative {
        if groups.iter().any(|g| g.root == root) || parity.conflict[root] {
            continue;
        }
        let members: Vec<usize> = (0..grids.len())
            .filter(|&k| relative[k].0 == root)
            .collect();
        let closed = members.iter().all(|&k| {
            tris[k]
                .iter()
                .all(|t| (0..3).all(|e| uses(t[e], t[(e + 1) % 3]) == 2))
        });
        let mut rim = Vec::new();
        if !closed {
            for &k in &members {
                for t in &tris[k] {
                    for e in 0..3 {
                        if uses(t[e], t[(e + 1) % 3]) == 1 {
                            rim.push(t[e]);
                        }
                    }
                }
            }
        }
        groups.push(Group {
            root,
            members,
            closed,
            rim,
        });
    }
    WeldTopology {
        options,
        names: (0..grids.len())
            .map(|k| {
                names
                    .get(k)
                    .map(|s| s.to_string())
                    .unwrap_or_else(|| format!("patch{k}"))
            })
            .collect(),
        shapes: grids.iter().map(|g| (g.nu, g.nv)).collect(),
        vertices: positions.len(),
        source,
        tris,
        relative,
        groups,
    }
}

/// The report as first written: every edge in one map.
fn report_reference(mesh: &TriMesh) -> MeshReport {
    let mut uses: HashMap<(u32, u32), (u32, u32)> = HashMap::new();
    let mut degenerate = 0;
    for &t in &mesh.triangles {
        let [a, b, c] = t;
        let f = facet_cross(&mesh.positions, t);
        if a == b || b == c || a == c || f == [0.0; 3] {
            degenerate += 1;
        }
        for e in 0..3 {
            let (a, b) = (t[e], t[(e + 1) % 3]);
            let entry = uses.entry((a.min(b), a.max(b))).or_default();
            if a < b {
                entry.0 += 1;
            } else {
                entry.1 += 1;
            }
        }
    }
    let mut r = MeshReport {
        boundary_edges: 0,
        nonmanifold_edges: 0,
        misoriented_edges: 0,
        degenerate_triangles: degenerate,
        signed_volume: signed_volume_of(&mesh.positions, &mesh.triangles),
    };
    for &(f, b) in uses.values() {
        match f + b {
            1 => r.boundary_edges += 1,
            2 if f != 1 => r.misoriented_edges += 1,
            2 => {}
            _ => r.nonmanifold_edges += 1,
        }
    }
    r
}

fn assert_same_weld(name: &str, grids: &[GridMesh]) {
    for join in [true, false] {
        let options = WeldOptions { join_patches: join };
        let names = ["a", "b"];
        let reference = topology_reference(grids, &names, options);
        let (topology, welded) = WeldTopology::new(grids, &names, options);
        assert_eq!(topology, reference, "{name}, join {join}");
        let expected = reference.finish(
            grids,
            merge_reference(grids, options, diagonal(grids)).0,
            diagonal(grids),
        );
        assert_eq!(welded, expected, "{name}, join {join}");
        assert_eq!(
            merge(grids, options, diagonal(grids)),
            merge_reference(grids, options, diagonal(grids))
        );
        assert_same_report(name, &welded.mesh);
        // The one-shot weld builds the same mesh without keeping a topology, bit for bit.
        let once = weld_mapped(grids, &names, options);
        assert_eq!(once, welded, "{name}, join {join}");
        assert_eq!(bits(&once.mesh), bits(&welded.mesh), "{name}, join {join}");
        // The normals are those of one pass over the copies and one over the triangles.
        let normals = normals_reference(grids, &welded);
        assert_eq!(
            normals
                .iter()
                .map(|n| n.map(f32::to_bits))
                .collect::<Vec<_>>(),
            bits(&welded.mesh).1,
            "{name}, join {join}"
        );
    }
}

/// Positions and normals as bits (a zero's sign counts).
fn bits(m: &TriMesh) -> (Vec<[u32; 3]>, Vec<[u32; 3]>) {
    let b = |v: &[[f32; 3]]| v.iter().map(|p| p.map(f32::to_bits)).collect();
    (b(&m.positions), b(&m.normals))
}

/// The vertex normals by their definition: the copies' normals (turned with their grid) summed
/// in the order of the grids' vertices and normalised; where that vanishes or points against
/// the sum of the facets around the vertex (in the order of the mesh's triangles), that sum
/// normalised.
fn normals_reference(grids: &[GridMesh], w: &Welded) -> Vec<[f32; 3]> {
    let n = w.mesh.positions.len();
    let mut sums = vec![[0.0f64; 3]; n];
    for (k, g) in grids.iter().enumerate() {
        let s = if w.flipped[k] { -1.0 } else { 1.0 };
        for (&v, m) in w.source[k].iter().zip(&g.normals) {
            for c in 0..3 {
                sums[v as usize][c] += s * m[c] as f64;
            }
        }
    }
    let mut facets = vec![[0.0f64; 3]; n];
    for &t in &w.mesh.triangles {
        let f = facet_cross(&w.mesh.positions, t);
        for i in t {
            for c in 0..3 {
                facets[i as usize][c] += f[c];
            }
        }
    }
    sums.iter()
        .zip(&facets)
        .map(|(s, a)| {
            let len = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
            let n = if len > 1e-3 {
                s.map(|c| (c / len) as f32)
            } else {
                [0.0; 3]
            };
            let dot: f64 = (0..3).map(|c| n[c] as f64 * a[c]).sum();
            let len = (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt();
            if dot <= 0.0 && len > 0.0 {
                a.map(|c| (c / len) as f32)
            } else {
                n
            }
        })
        .collect()
}

fn assert_same_report(name: &str, m: &TriMesh) {
    let r = report(m);
    let r0 = report_reference(m);
    assert_eq!(r, r0, "{name}");
    assert_eq!(
        r.signed_volume.to_bits(),
        r0.signed_volume.to_bits(),
        "{name}"
    );
    assert_eq!(
        is_closed(m),
        r0.boundary_edges == 0 && r0.nonmanifold_edges == 0,
        "{name}"
    );
}

#[test]
fn the_topology_is_that_of_counting_every_edge() {
    let mut seen_closed = 0;
    let mut seen_rim = 0;
    let mut seen_conflict = 0;
    for (name, grids) in cases() {
        assert_same_weld(&name, &grids);
        let t = topology_reference(&grids, &[], WeldOptions::default());
        seen_closed += t.groups.iter().filter(|g| g.closed).count();
        seen_rim += t.groups.iter().filter(|g| !g.rim.is_empty()).count();
        seen_conflict += (t.groups.len()
            < t.relative
                .iter()
                .map(|r| r.0)
                .collect::<std::collections::HashSet<_>>()
                .len()) as usize;
    }
    // The cases reach every branch: closed groups, open ones with rims, a conflict.
    assert!(
        seen_closed >= 6 && seen_rim >= 10 && seen_conflict >= 1,
        "{seen_closed} {seen_rim} {seen_conflict}"
    );
}

#[test]
fn the_topology_of_every_example_is_that_of_counting_every_edge() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples");
    let (mut n, mut trimmed) = (0, 0);
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "toml") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        let Ok(spec) = crate::spec::parse_design(&text) else {
            continue;
        };
        let Ok(mut design) = crate::design::compile(&spec) else {
            continue;
        };
        if !design.solved().trims.is_empty() {
            // Trimmed designs are meshed without the weld: their report.
            let m = design.solved().tri_mesh(24, 40).unwrap();
            assert_same_report(&path.display().to_string(), &m);
            trimmed += 1;
        }
        let Ok(grids) = design.meshes(24, 40) else {
            continue;
        };
        assert_same_weld(&path.display().to_string(), grids);
        n += 1;
    }
    assert!(
        n >= 15 && trimmed >= 2,
        "only {n} examples welded, {trimmed} trimmed"
    );
}
