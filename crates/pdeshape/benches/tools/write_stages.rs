//! The stages of `pdeshape surface DESIGN -o OUT.ext` in one fresh process, each timed by the
//! wall clock and by the process's CPU time (user and system, all threads) and minor page
//! faults: solve, tessellate, weld, encode into memory, and writing that memory to a file with
//! and without fsync. One line of JSON per run; run it several times (each run is a fresh
//! process, as the CLI is):
//!
//! `cargo bench -p pdeshape --bench write_stages -- ../../examples/cup.toml 1024 1024 glb /tmp`

use pdeshape::design::WriteDesign as _;
use pdeshape::design::{compile, Export};
use pdeshape::mesh::{write_mesh, Format};
use pdeshape::spec::parse_design;
use std::io::Write;
use std::time::Instant;

/// CPU time of the whole process so far: user and system ms, and minor page faults.
fn usage() -> [f64; 3] {
    // SAFETY: getrusage fills the struct it is given.
    let mut r: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut r) };
    let t = |v: libc::timeval| v.tv_sec as f64 * 1e3 + v.tv_usec as f64 * 1e-3;
    [t(r.ru_utime), t(r.ru_stime), r.ru_minflt as f64]
}

struct Stage {
    wall: Instant,
    usage: [f64; 3],
}

impl Stage {
    fn start() -> Stage {
        Stage {
            wall: Instant::now(),
            usage: usage(),
        }
    }
    /// `"name": [wall ms, user ms, system ms, minor faults]`.
    fn end(self, name: &str, out: &mut Vec<String>) {
        let wall = self.wall.elapsed().as_secs_f64() * 1e3;
        let u = usage();
        let d = [0, 1, 2].map(|k| u[k] - self.usage[k]);
        out.push(format!(
            "\"{name}\": [{wall:.2}, {:.2}, {:.2}, {}]",
            d[0], d[1], d[2]
        ));
    }
}

fn main() {
    let args: Vec<String> = std::env::args().filter(|a| a != "--bench").collect();
    let design = args.get(1).map_or(
        concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/cup.toml"),
        |s| s.as_str(),
    );
    let nu: usize = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(1024);
    let nv: usize = args.get(3).and_then(|a| a.parse().ok()).unwrap_or(1024);
    let format = match args.get(4).map_or("glb", |s| s.as_str()) {
        "obj" => Format::Obj,
        "stl" => Format::Stl,
        "ply" => Format::Ply,
        _ => Format::Glb,
    };
    let dir = args
        .get(5)
        .map(std::path::PathBuf::from)
        .unwrap_or_else(std::env::temp_dir);
    let mut out = Vec::new();
    let spec = parse_design(&std::fs::read_to_string(design).unwrap()).unwrap();
    let s = Stage::start();
    let compiled = compile(&spec).unwrap();
    let solved = compiled.solved();
    s.end("solve", &mut out);
    let s = Stage::start();
    let grids = solved.meshes(nu, nv).unwrap();
    s.end("tessellate", &mut out);
    let export = Export::default();
    // The file's bytes straight from the grids (GLB; the others weld first), handed to a sink.
    let s = Stage::start();
    solved
        .write_grids(format, &grids, &export, &mut std::io::sink())
        .unwrap();
    s.end("grids_to_sink", &mut out);
    let s = Stage::start();
    let mesh = solved.weld(&grids, &export);
    s.end("weld", &mut out);
    let info = solved.mesh_info(&export);
    let s = Stage::start();
    let mut bytes = Vec::new();
    write_mesh(format, &mesh, &info, &mut bytes).unwrap();
    s.end("encode", &mut out);
    for sync in [false, true] {
        let path = dir.join(format!("write_stages_{}.bin", std::process::id()));
        let s = Stage::start();
        let mut f = std::fs::File::create(&path).unwrap();
        for c in bytes.chunks(1 << 20) {
            f.write_all(c).unwrap();
        }
        if sync {
            f.sync_all().unwrap();
        }
        drop(f);
        s.end(if sync { "file_fsync" } else { "file" }, &mut out);
        std::fs::remove_file(&path).unwrap();
    }
    // Writing back each 8 MiB as soon as it is written (the kernel starts the disk writes while
    // the next megabytes are produced), then fsync; with a pause of `busy` ms per MiB standing
    // for the encoding.
    for busy in [0.0, 0.3] {
        let path = dir.join(format!("write_stages_{}.bin", std::process::id()));
        let s = Stage::start();
        let mut f = std::fs::File::create(&path).unwrap();
        let mut done = 0usize;
        let mut synced = 0usize;
        for c in bytes.chunks(1 << 20) {
            let t = Instant::now();
            while t.elapsed().as_secs_f64() * 1e3 < busy {
                std::hint::spin_loop();
            }
            f.write_all(c).unwrap();
            done += c.len();
            if done - synced >= 8 << 20 {
                use std::os::fd::AsRawFd;
                // SAFETY: a valid descriptor and range; only starts write-back.
                unsafe {
                    libc::sync_file_range(
                        f.as_raw_fd(),
                        synced as i64,
                        (done - synced) as i64,
                        libc::SYNC_FILE_RANGE_WRITE,
                    )
                };
                synced = done;
            }
        }
        let t = Instant::now();
        f.sync_all().unwrap();
        let tail = t.elapsed().as_secs_f64() * 1e3;
        drop(f);
        s.end(&format!("writeback_busy{busy}"), &mut out);
        out.push(format!("\"writeback_busy{busy}_fsync\": {tail:.2}"));
        std::fs::remove_file(&path).unwrap();
        let path = dir.join(format!("write_stages_{}.bin", std::process::id()));
        let s = Stage::start();
        let mut f = std::fs::File::create(&path).unwrap();
        for c in bytes.chunks(1 << 20) {
            let t = Instant::now();
            while t.elapsed().as_secs_f64() * 1e3 < busy {
                std::hint::spin_loop();
            }
            f.write_all(c).unwrap();
        }
        let t = Instant::now();
        f.sync_all().unwrap();
        let tail = t.elapsed().as_secs_f64() * 1e3;
        drop(f);
        s.end(&format!("plain_busy{busy}"), &mut out);
        out.push(format!("\"plain_busy{busy}_fsync\": {tail:.2}"));
        std::fs::remove_file(&path).unwrap();
    }
    let s = Stage::start();
    let path = dir.join(format!("write_stages_{}.bin", std::process::id()));
    let mut f = std::io::BufWriter::new(std::fs::File::create(&path).unwrap());
    write_mesh(format, &mesh, &info, &mut f).unwrap();
    let f = f.into_inner().unwrap();
    s.end("encode_to_file", &mut out);
    let s = Stage::start();
    f.sync_all().unwrap();
    drop(f);
    s.end("fsync", &mut out);
    std::fs::remove_file(&path).unwrap();
    println!(
        "{{\"bytes\": {}, \"vertices\": {}, {}}}",
        bytes.len(),
        mesh.positions.len(),
        out.join(", ")
    );
}
