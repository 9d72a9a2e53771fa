//! Where an animation frame's time goes: the design at `t` read from its formulas (`spec_at`),
//! re-solved incrementally (`set_spec`), tessellated into the last frame's grids (`meshes`) and
//! welded on the first frame's topology into the last frame's mesh (`FrameWeld`), each timed over
//! every frame of the animation, on the calling thread. First, what the first frame costs once:
//! the fresh compile, its grids, the weld topology and the first two frame welds (the second
//! makes the layout of the streaming pass).
//!
//! `cargo bench -p pdeshape --bench anim_stages -- ../../examples/anim/ventricle.toml [NU NV]`

use pdeshape::anim::Animation;
use pdeshape::design::{compile, SurfaceKind};
use pdeshape::mesh::{FrameWeld, WeldOptions, WeldTopology};
use pdeshape::spec::time::parse_timed;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().filter(|a| a != "--bench").collect();
    let path = args.get(1).expect("a design file with [time]");
    let nu: usize = args.get(2).map_or(64, |s| s.parse().expect("NU"));
    let nv: usize = args.get(3).map_or(128, |s| s.parse().expect("NV"));
    let text = std::fs::read_to_string(path).expect("readable");
    let anim = Animation::Timed(parse_timed(&text).expect("a timed design"));
    let times = anim.times().expect("times");
    let t0 = Instant::now();
    let mut c = compile(&anim.spec_at(times[0]).expect("design")).expect("solves");
    let compiled = t0.elapsed();
    for s in &c.solved().surfaces {
        if let SurfaceKind::Pde(p) = &s.kind {
            println!(
                "{}: {} modes, remainder {}",
                s.name,
                p.modes(),
                p.has_remainder()
            );
        }
    }
    let t0 = Instant::now();
    let grids = c.solved().meshes(nu, nv).expect("grids");
    let meshed = t0.elapsed();
    let names = c
        .solved()
        .names()
        .iter()
        .map(|s| s.to_string())
        .collect::<Vec<_>>();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let t0 = Instant::now();
    let (topology, _) = WeldTopology::new(&grids, &names, WeldOptions::default());
    let topo = t0.elapsed();
    let mut welder = FrameWeld::new(topology);
    let t0 = Instant::now();
    assert!(welder.weld(&grids));
    let first = t0.elapsed();
    let t0 = Instant::now();
    assert!(welder.weld(&grids));
    let second = t0.elapsed();
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3;
    println!(
        "first frame, ms: compile {:.3}, meshes {:.3}, WeldTopology::new {:.3}, first FrameWeld \
         {:.3}, second {:.3}",
        ms(compiled),
        ms(meshed),
        ms(topo),
        ms(first),
        ms(second)
    );
    let mut ms = [0.0f64; 4];
    let reps = 3;
    for _ in 0..reps {
        for &t in &times {
            let t0 = Instant::now();
            let spec = anim.spec_at(t).expect("design");
            let t1 = Instant::now();
            c.set_spec(spec).expect("solves");
            let t2 = Instant::now();
            let grids = c.meshes(nu, nv).expect("grids");
            let t3 = Instant::now();
            assert!(welder.weld(grids), "welds alike");
            let t4 = Instant::now();
            std::hint::black_box(welder.mesh());
            for (m, (a, b)) in ms.iter_mut().zip([(t0, t1), (t1, t2), (t2, t3), (t3, t4)]) {
                *m += (b - a).as_secs_f64() * 1e3;
            }
        }
    }
    let n = (reps * times.len()) as f64;
    let total = ms.iter().sum::<f64>() / n;
    println!(
        "ms per frame ({} frames, {nu} × {nv}): spec_at {:.3}, set_spec {:.3}, meshes {:.3}, \
         weld {:.3}; total {total:.3} ({:.0} frames/s on one thread)",
        times.len(),
        ms[0] / n,
        ms[1] / n,
        ms[2] / n,
        ms[3] / n,
        1e3 / total
    );
}
