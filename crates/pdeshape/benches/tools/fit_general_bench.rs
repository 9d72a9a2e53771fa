//! Times the general fitting mode (`fit::fit_measured` with the mode forced to general) on the
//! meshes of `pdeshape_testkit::implicit` and prints one markdown row per mesh (BENCHMARKS.md):
//! triangles, faces, Hausdorff and RMS relative to the diagonal, the design's TOML bytes and
//! the fit's wall time (the peer script adds the gzipped sizes). With a directory argument it also writes each mesh
//! (`NAME.obj`) and its fitted design (`NAME.toml`) there, for the decimation peer
//! (`bench/peers/decimate_rate.py`) to compare at equal bytes and equal error.
//!
//! Usage: `cargo bench -p pdeshape --bench fit_general_bench -- [DIR] [--large]` (`--large`
//! adds the smooth meshes finely tessellated: a torus of about 100 000 triangles, a double
//! torus of about 90 000 and a half torus of about 50 000, whose facets lie far closer to the
//! implicit surface than the fits do).

use pdeshape::fit::{fit_measured, InputMesh, ModeChoice, Request};
use pdeshape::spec::write_design;
use pdeshape_testkit::implicit;
use std::time::Instant;

fn obj(mesh: &InputMesh) -> String {
    let mut s = String::new();
    for p in &mesh.positions {
        s += &format!("v {} {} {}\n", p.x, p.y, p.z);
    }
    for t in &mesh.triangles {
        s += &format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
    }
    s
}

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| a != "--bench")
        .collect();
    let dir = args.iter().find(|a| !a.starts_with("--")).cloned();
    let large = args.iter().any(|a| a == "--large");
    let mut cases: Vec<(&str, InputMesh)> = vec![
        ("torus", implicit::torus(32)),
        ("double_torus", implicit::double_torus(44)),
        ("limbs", implicit::limbs(40)),
        ("mug", implicit::mug(40)),
        ("half_torus", implicit::half_torus(32)),
    ];
    if large {
        cases.push(("torus_large", implicit::torus(84)));
        cases.push(("double_torus_large", implicit::double_torus(100)));
        cases.push(("half_torus_large", implicit::half_torus(84)));
    }
    println!(
        "| mesh | triangles | faces | Hausdorff / diag | RMS / diag | TOML bytes | mesh bytes (12V + 12T) | fit |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for (name, mesh) in cases {
        let request = Request {
            mode: ModeChoice::General,
            tolerance: Some(0.01),
            ..Request::default()
        };
        let t = Instant::now();
        let fitted = match fit_measured(&mesh, &request) {
            Ok(f) => f,
            Err(e) => {
                println!(
                    "| {name} | {} | refused: {e} | | | | | |",
                    mesh.triangles.len()
                );
                continue;
            }
        };
        let secs = t.elapsed().as_secs_f64();
        let text = write_design(&fitted.fit.spec).unwrap();
        let m = &fitted.measures;
        println!(
            "| {name} | {} | {} | {:.2} % | {:.3} % | {} | {} | {:.1} s |",
            mesh.triangles.len(),
            fitted.fit.patches,
            100.0 * m.hausdorff_relative,
            100.0 * m.rms_relative,
            text.len(),
            m.mesh_bytes,
            secs
        );
        if let Some(d) = &dir {
            std::fs::create_dir_all(d).unwrap();
            std::fs::write(format!("{d}/{name}.obj"), obj(&mesh)).unwrap();
            std::fs::write(format!("{d}/{name}.toml"), &text).unwrap();
        }
    }
}
