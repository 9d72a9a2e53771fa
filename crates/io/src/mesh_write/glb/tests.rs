//! The GLB written straight from the grids through the weld's plan against the welded mesh
//! written, on the weld's cases, the plan's edge cases and every example.

use crate::mesh::test_grids::{cases, grid};
use crate::mesh::weld::Plan;
use crate::mesh::{weld, GridMesh, WeldOptions};
use crate::mesh_write::{write_glb, write_glb_grids, MeshInfo, Units, Up};

/// The weld cases and grids at the edges of what the plan takes: an end column collapsed to
/// one point (a fan), the same at both ends, a four-column sheet (the fewest columns the plan
/// takes without a periodic `v`), and grids written in several blocks.
fn plan_cases() -> Vec<(String, Vec<GridMesh>)> {
    let mut out = cases();
    out.push((
        "fan column".into(),
        vec![grid(7, 9, false, |u, v| [v * (1.0 + u), v * u, 0.2 * v])],
    ));
    out.push((
        "two fans".into(),
        vec![grid(6, 8, false, |u, v| {
            let w = v * (crate::TAU - v);
            [w * (1.0 + u), w * u, v]
        })],
    ));
    out.push((
        "four columns".into(),
        vec![grid(5, 4, false, |u, v| [u, v, (u * v).sin()])],
    ));
    // Grids written in several blocks each, on the thread pool: a cup whose wall meets the
    // base's rim, and a sheet with end columns.
    out.push((
        "large cup".into(),
        vec![
            grid(300, 400, true, |u, v| [u * v.cos(), u * v.sin(), 0.0]),
            grid(260, 400, true, |u, v| [v.cos(), v.sin(), u]),
        ],
    ));
    out.push((
        "large sheet".into(),
        vec![grid(400, 300, false, |u, v| {
            [u, v, 0.1 * (3.0 * u * v).sin()]
        })],
    ));
    out
}

/// The GLB written straight from the grids through the weld's plan is, byte for byte, the
/// welded mesh written, for both weld options and two file frames.
fn assert_same_glb(name: &str, grids: &[GridMesh]) -> bool {
    let infos = [
        MeshInfo::default(),
        MeshInfo {
            title: Some("a title".into()),
            scale: 2.5,
            up: Up::Y,
            units: Units::Centimetre,
        },
    ];
    let names = ["a", "b"];
    let mut planned = true;
    for join in [true, false] {
        let options = WeldOptions { join_patches: join };
        let plan = Plan::new(grids, &names, options);
        planned &= plan.parts().is_some() && plan.closed().is_some();
        for info in &infos {
            let mut direct = Vec::new();
            let mut welded = Vec::new();
            let a = write_glb_grids(grids, &names, options, info, &mut direct);
            let b = write_glb(&weld(grids, &names, options), info, &mut welded);
            // (The grids are checked first: an empty design is refused in other words.)
            assert_eq!(a.is_ok(), b.is_ok(), "{name}, join {join}: {a:?} {b:?}");
            assert!(
                direct == welded,
                "{name}, join {join}, scale {}",
                info.scale
            );
        }
    }
    planned
}

#[test]
fn glb_from_the_plan_is_the_welded_mesh_written() {
    let mut planned = Vec::new();
    let mut left = Vec::new();
    for (name, grids) in plan_cases() {
        if assert_same_glb(&name, &grids) {
            planned.push(name);
        } else {
            left.push(name);
        }
    }
    // The plan stands wherever the layout gives the parts, and not where it does not.
    for name in [
        "sphere 17x32",
        "hemispheres 9x16",
        "cup",
        "cup reversed wall",
        "pinched",
        "noisy pole",
        "sheet 4x5",
        "seam column 9x16",
        "fan column",
        "two fans",
        "four columns",
    ] {
        assert!(
            planned.iter().any(|p| p == name),
            "{name} planned: {planned:?}"
        );
    }
    for name in ["sphere 2x3", "sheet 3x3", "strip", "moebius"] {
        assert!(
            left.iter().any(|p| p == name),
            "{name} left to the mesh: {left:?}"
        );
    }
}

#[test]
fn glb_of_every_example_is_the_welded_mesh_written() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples");
    let mut n = 0;
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
        let Ok(grids) = design.meshes(24, 40) else {
            continue;
        };
        assert_same_glb(&path.display().to_string(), grids);
        n += 1;
    }
    assert!(n >= 15, "only {n} examples written");
}
