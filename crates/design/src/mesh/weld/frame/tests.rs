//! Frames finished by the streaming pass (`weld_frame_pass.rs`) against the full weld, bit for
//! bit, on the weld's test grids (poles, seams, shared edges, collapsed rows, sheets, cups,
//! conflicting orientations, tiny grids) moved, turned inside out and flattened.

use super::*;
use crate::mesh::test_grids::{cases, grid};
use crate::mesh::{weld_mapped, WeldOptions};

/// Everything of a weld, numbers as bit patterns (so that `-0.0` and `0.0` differ).
type Bits = (Vec<u32>, Vec<u32>, Vec<[u32; 3]>, Vec<Part>, Vec<bool>);

fn bits(mesh: &TriMesh, flipped: &[bool]) -> Bits {
    let b = |v: &[[f32; 3]]| v.iter().flatten().map(|x| x.to_bits()).collect();
    (
        b(&mesh.positions),
        b(&mesh.normals),
        mesh.triangles.clone(),
        mesh.parts.clone(),
        flipped.to_vec(),
    )
}

/// The grids with every point moved by `f` (coincident points stay coincident), the normals
/// kept.
fn moved(grids: &[GridMesh], f: impl Fn([f64; 3]) -> [f64; 3]) -> Vec<GridMesh> {
    grids
        .iter()
        .map(|g| {
            let mut g = g.clone();
            for p in &mut g.positions {
                *p = f(p.map(|x| x as f64)).map(|x| x as f32);
            }
            g
        })
        .collect()
}

/// The grids with some normals turned against the surface and some zero (where the weld takes
/// the facets' mean, whose summation order then shows in the bits).
fn odd_normals(grids: &[GridMesh]) -> Vec<GridMesh> {
    grids
        .iter()
        .map(|g| {
            let mut g = g.clone();
            for (i, n) in g.normals.iter_mut().enumerate() {
                if i % 3 == 0 {
                    *n = n.map(|x| -x);
                } else if i % 7 == 0 {
                    *n = [0.0; 3];
                }
            }
            g
        })
        .collect()
}

/// Welds `frames` one after the other on the first's topology and compares each with the full
/// weld. Returns how many the pass finished and how many turns it left to the reference.
fn weld_frames(name: &str, frames: &[Vec<GridMesh>], options: WeldOptions) -> (usize, usize) {
    let names = ["a", "b", "c"];
    let (topology, _) = WeldTopology::new(&frames[0], &names, options);
    let mut welder = FrameWeld::new(topology);
    for (k, grids) in frames.iter().enumerate() {
        let full = weld_mapped(grids, &names, options);
        if !welder.weld(grids) {
            // The vertices join otherwise: not a frame of this topology.
            assert_ne!(full.source, welder.topology().source, "{name}: frame {k}");
            continue;
        }
        assert_eq!(
            bits(welder.mesh(), welder.flipped()),
            bits(&full.mesh, &full.flipped),
            "{name}, join {}: frame {k}",
            options.join_patches
        );
    }
    let undecided = welder.plan.pass.as_ref().map_or(0, |p| p.undecided);
    (welder.plan.by_pass, undecided)
}

#[test]
fn frames_finished_by_the_pass_equal_the_full_weld() {
    let (mut frames_by_pass, mut cases_seen) = (0, 0);
    for (name, grids) in cases() {
        // Moved (stretched, sheared, bent), turned inside out (mirrored), moved again, the
        // first again.
        let bent = |p: [f64; 3]| {
            [
                1.05 * p[0] + 0.1 * p[1].sin(),
                0.97 * p[1] + 0.02 * p[2],
                p[2] + 0.05 * p[0] * p[1],
            ]
        };
        let frames = vec![
            grids.clone(),
            moved(&grids, bent),
            moved(&grids, |p| [-p[0], p[1], p[2]]),
            moved(&grids, bent),
            moved(&grids, |p| [p[0] + 0.25, p[1] - 0.5, 2.0 * p[2]]),
            odd_normals(&moved(&grids, bent)),
            grids.clone(),
        ];
        for join in [true, false] {
            let (by_pass, _) = weld_frames(&name, &frames, WeldOptions { join_patches: join });
            frames_by_pass += by_pass;
        }
        cases_seen += 1;
    }
    // Most frames after the first are the pass's (a frame after a mirror is not: its groups
    // turned).
    assert!(
        cases_seen >= 30 && frames_by_pass >= 3 * cases_seen,
        "{frames_by_pass} frames by the pass in {cases_seen} cases"
    );
}

#[test]
fn a_group_of_next_to_no_volume_is_decided_by_the_reference_sum() {
    // The unit sphere covered twice, the second time with a negative radius on the way back
    // up: a closed group whose volume (∝ ∫ r²·(−z′) du = ∫ sin³ 2πu du) is zero up to
    // rounding, so the pass cannot tell its sign.
    let lobes = grid(17, 16, true, |u, v| {
        let (s, c) = (crate::TAU * u).sin_cos();
        [s * v.cos(), s * v.sin(), c]
    });
    let frames = vec![
        vec![lobes.clone()],
        vec![lobes.clone()],
        moved(&[lobes], |p| [1.5 * p[0], 1.5 * p[1], 0.5 * p[2]]),
    ];
    let (by_pass, undecided) = weld_frames("lobes", &frames, WeldOptions::default());
    assert!(by_pass >= 1 && undecided >= 1, "{by_pass} {undecided}");
}

#[test]
fn a_frame_with_a_number_that_is_not_finite_is_finished_by_the_reference() {
    let (_, grids) = cases()
        .into_iter()
        .find(|(n, _)| n == "hemispheres 17x32")
        .expect("the case");
    let mut bad = grids.clone();
    bad[0].positions[5 * 32 + 3] = [f32::NAN, 0.0, 1.0];
    let mut bad_normal = grids.clone();
    bad_normal[1].normals[4 * 32 + 7] = [f32::INFINITY, 0.0, 0.0];
    let frames = vec![grids.clone(), grids.clone(), bad, bad_normal, grids];
    let (by_pass, _) = weld_frames("not finite", &frames, WeldOptions::default());
    // The second and last frames only.
    assert_eq!(by_pass, 2);
}
