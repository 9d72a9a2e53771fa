//! Time-dependent designs: morph ends, self-morph, the ventricle's periodicity and volume curve.

use pdeshape::anim::{for_each_frame, Animation, Keyframes, Morph};
use pdeshape::design::Export;
use pdeshape::spec::time::{parse_timed, TimeSpec};

use pdeshape_testkit::{example, example_path};

fn frames(anim: &Animation, times: &[f64]) -> Keyframes {
    let mut keys = Keyframes::new(anim.time());
    for_each_frame(anim, times, 16, 32, &Export::default(), |f| {
        keys.push(&f);
        Ok(())
    })
    .unwrap();
    keys
}

fn meshes_of(text: &str) -> Vec<[f32; 3]> {
    let spec = pdeshape::spec::parse_design(text).unwrap();
    let solved = pdeshape::design::solve_design(&spec).unwrap();
    let grids = solved.meshes(16, 32).unwrap();
    solved.weld(&grids, &Export::default()).positions
}

fn morph(source: &str, target: &str) -> Animation {
    Animation::Morph {
        morph: Morph::new(source, target).unwrap(),
        time: TimeSpec {
            end: 1.0,
            frames: Some(5),
            ..TimeSpec::default()
        },
        ease: 1.5,
    }
}

#[test]
fn the_morph_starts_at_the_source_and_ends_at_the_target() {
    let (s, t) = (example("anim/water_glass.toml"), example("wine_glass.toml"));
    let a = morph(&s, &t);
    let keys = frames(&a, &a.times().unwrap());
    assert_eq!(keys.positions[0], meshes_of(&s));
    assert_eq!(keys.positions[4], meshes_of(&t));
    // The middle frames are neither.
    assert_ne!(keys.positions[2], keys.positions[0]);
    assert_ne!(keys.positions[2], keys.positions[4]);
}

#[test]
fn a_morph_between_a_design_and_itself_is_constant() {
    let s = example("wine_glass.toml");
    let a = morph(&s, &s);
    let keys = frames(&a, &a.times().unwrap());
    for k in 1..keys.positions.len() {
        assert_eq!(keys.positions[k], keys.positions[0], "frame {k}");
    }
}

#[test]
fn designs_of_different_structure_are_refused() {
    let e = Morph::new(&example("water_glass.toml"), &example("wine_glass.toml")).unwrap_err();
    assert!(e.to_string().contains("same structure"), "{e}");
}

#[test]
fn the_ventricle_beats_periodically_with_its_extremes_at_the_expected_phases() {
    let d = parse_timed(&example("anim/ventricle.toml")).unwrap();
    let tm = 0.8;
    let a = Animation::Timed(d);
    // One period later the design is the same to rounding (sin²(π) ≈ 1.5e-32).
    let keys = frames(&a, &[0.0, tm]);
    for (p, q) in keys.positions[0].iter().zip(&keys.positions[1]) {
        for c in 0..3 {
            assert!((p[c] - q[c]).abs() < 1e-5, "{p:?} {q:?}");
        }
    }
    // Volumes over the beat: largest at t = 0 (end-diastole), smallest at t_m/2 (end-systole),
    // symmetric about t_m/2 (S(t) = S(t_m − t)).
    let times: Vec<f64> = (0..=16).map(|k| tm * k as f64 / 16.0).collect();
    let mut vols = Vec::new();
    for_each_frame(&a, &times, 16, 32, &Export::default(), |f| {
        vols.push(pdeshape::anim::measure(f.solved)?.1);
        Ok(())
    })
    .unwrap();
    let argmax = (0..vols.len())
        .max_by(|&i, &j| vols[i].total_cmp(&vols[j]))
        .unwrap();
    let argmin = (0..vols.len())
        .min_by(|&i, &j| vols[i].total_cmp(&vols[j]))
        .unwrap();
    assert!(argmax == 0 || argmax == 16, "{vols:?}");
    assert_eq!(argmin, 8, "{vols:?}");
    for k in 0..=8 {
        assert!(
            (vols[k] - vols[16 - k]).abs() < 1e-8 * vols[0],
            "{k}: {vols:?}"
        );
    }
    // Smooth: second differences small against the swing.
    let swing = vols[0] - vols[8];
    for k in 1..16 {
        let d2 = vols[k + 1] - 2.0 * vols[k] + vols[k - 1];
        assert!(d2.abs() < 0.2 * swing, "{k}: {vols:?}");
    }
}

#[test]
fn frames_welded_on_the_first_frames_topology_equal_a_fresh_weld() {
    use pdeshape::mesh::{weld_mapped, WeldOptions, WeldTopology};
    let timed = parse_timed(&example("anim/ventricle.toml")).unwrap();
    let anim = Animation::Timed(timed);
    let times = anim.times().unwrap();
    let options = WeldOptions::default();
    let mut topology: Option<WeldTopology> = None;
    let mut compared = 0;
    let mut first_positions = Vec::new();
    for &t in times.iter().step_by(5) {
        let spec = anim.spec_at(t).unwrap();
        let solved = pdeshape::design::solve_design(&spec).unwrap();
        let grids = solved.meshes(16, 32).unwrap();
        let fresh = weld_mapped(&grids, &solved.names(), options);
        match &topology {
            None => {
                let (w, first) = WeldTopology::new(&grids, &solved.names(), options);
                assert_eq!(first, fresh);
                first_positions = first.mesh.positions.clone();
                topology = Some(w);
            }
            Some(w) => {
                let again = w
                    .weld(&grids)
                    .expect("the ventricle welds alike at every t");
                // Bit for bit, positions, normals, triangles and parts.
                assert_eq!(again, fresh, "t = {t}");
                // The frames do move (the comparison is not of one mesh with itself).
                assert_ne!(again.mesh.positions, first_positions);
                compared += 1;
            }
        }
    }
    assert!(compared >= 8, "{compared}");
    // Grids whose vertices join otherwise are refused: move the apex patch away from the rest.
    let spec = anim.spec_at(0.0).unwrap();
    let solved = pdeshape::design::solve_design(&spec).unwrap();
    let mut grids = solved.meshes(16, 32).unwrap();
    for p in &mut grids[0].positions {
        p[0] += 50.0;
    }
    assert!(topology.unwrap().weld(&grids).is_none());
}

/// The lateral (y) displacement of the body's centre line at grid row `i` in every frame: the
/// mean of the row's vertices (the radial part has no mean over a full turn of v).
fn lateral_by_row(text: &str, nu: usize) -> (Vec<f64>, Vec<f64>, Vec<Vec<f64>>) {
    let anim = Animation::Timed(parse_timed(text).unwrap());
    let times = anim.times().unwrap();
    let mut us = Vec::new();
    let mut rows: Vec<Vec<f64>> = vec![Vec::new(); nu];
    for_each_frame(&anim, &times, nu, 32, &Export::default(), |f| {
        let g = &f.grids[0];
        assert!(g.periodic_v);
        us = g.u.clone();
        for (i, row) in rows.iter_mut().enumerate() {
            let y: f64 = (0..g.nv)
                .map(|j| g.positions[g.index(i, j)][1] as f64)
                .sum::<f64>()
                / g.nv as f64;
            row.push(y);
        }
        Ok(())
    })
    .unwrap();
    (times, us, rows)
}

/// Least-squares `y ≈ a sin θ + b cos θ + c`, `θ = 2π ω t`, over frames that sample whole
/// periods evenly (where the three functions are orthogonal).
fn fit(times: &[f64], ys: &[f64], omega: f64) -> (f64, f64, f64) {
    let n = times.len() as f64;
    let th = |t: f64| 2.0 * std::f64::consts::PI * omega * t;
    let a = 2.0 / n
        * times
            .iter()
            .zip(ys)
            .map(|(&t, y)| th(t).sin() * y)
            .sum::<f64>();
    let b = 2.0 / n
        * times
            .iter()
            .zip(ys)
            .map(|(&t, y)| th(t).cos() * y)
            .sum::<f64>();
    let c = ys.iter().sum::<f64>() / n;
    (a, b, c)
}

fn wrap(x: f64) -> f64 {
    let tau = 2.0 * std::f64::consts::PI;
    (x + std::f64::consts::PI).rem_euclid(tau) - std::f64::consts::PI
}

#[test]
fn the_fishs_travelling_wave_has_phase_difference_alpha_delta_u_between_stations() {
    // fish.toml: Ω(u) = 0.15 + 0.9u², α = 2π, ω = 1, φ = 0, 48 frames over one period.
    let text = example("anim/fish.toml");
    let (times, us, rows) = lateral_by_row(&text, 21);
    let alpha = 2.0 * std::f64::consts::PI;
    let omega_of = |u: f64| 0.15 + 0.9 * u * u;
    // w = Ω sin(αu − θ) = Ω sin(αu) cos θ − Ω cos(αu) sin θ: phase ψ = atan2(b, −a) = αu.
    let phase = |i: usize| {
        let (a, b, c) = fit(&times, &rows[i], 1.0);
        // The straight body has no mean sideways offset; the fit explains every frame.
        assert!(c.abs() < 1e-5, "row {i}: mean {c}");
        let amp = (a * a + b * b).sqrt();
        assert!(
            (amp - omega_of(us[i])).abs() < 1e-5 * (1.0 + amp),
            "row {i}: amplitude {amp} against Ω = {}",
            omega_of(us[i])
        );
        for (k, &t) in times.iter().enumerate() {
            let th = 2.0 * std::f64::consts::PI * t;
            let model = a * th.sin() + b * th.cos() + c;
            assert!((rows[i][k] - model).abs() < 1e-5, "row {i}, frame {k}");
        }
        b.atan2(-a)
    };
    for (i, j) in [(2, 5), (5, 11), (8, 17), (3, 19)] {
        let got = wrap(phase(j) - phase(i));
        let want = wrap(alpha * (us[j] - us[i]));
        assert!(
            (got - want).abs() < 1e-4,
            "stations u = {} and {}: phase difference {got}, α Δu = {want}",
            us[i],
            us[j]
        );
    }
}

#[test]
fn a_standing_wave_keeps_one_phase_along_the_body_with_nodes() {
    // The same body with Eq. 8.9's standing wave Ω(u) cos(αu + φ) sin(2πωt).
    let text = example("anim/fish.toml").replace("kind = \"travelling\"", "kind = \"standing\"");
    let (times, us, rows) = lateral_by_row(&text, 21);
    let alpha = 2.0 * std::f64::consts::PI;
    for (i, &u) in us.iter().enumerate() {
        let (a, b, _) = fit(&times, &rows[i], 1.0);
        // All in sin θ (no cos θ part): every station reaches its extreme at the same time.
        assert!(b.abs() < 1e-5, "row {i}: cos part {b}");
        let want = (0.15 + 0.9 * u * u) * (alpha * u).cos();
        assert!((a - want).abs() < 1e-5, "row {i}: {a} against {want}");
    }
    // u = 1/4 is a node: it does not move.
    let node = us.iter().position(|&u| (u - 0.25).abs() < 1e-12).unwrap();
    assert!(rows[node].iter().all(|y| y.abs() < 1e-5));
}

/// Rotation of `p` by `deg` degrees about the line through `about` along the unit `axis`
/// (Rodrigues), written out independently of the library's transforms.
fn rotate(p: [f64; 3], axis: [f64; 3], deg: f64, about: [f64; 3]) -> [f64; 3] {
    let (s, c) = deg.to_radians().sin_cos();
    let x = [p[0] - about[0], p[1] - about[1], p[2] - about[2]];
    let k = axis;
    let kx = [
        k[1] * x[2] - k[2] * x[1],
        k[2] * x[0] - k[0] * x[2],
        k[0] * x[1] - k[1] * x[0],
    ];
    let kd = k[0] * x[0] + k[1] * x[1] + k[2] * x[2];
    [0, 1, 2].map(|i| about[i] + x[i] * c + kx[i] * s + k[i] * kd * (1.0 - c))
}

#[test]
fn the_rig_moves_attached_curves_rigidly_meets_its_keys_and_closes_the_loop() {
    let text = example("anim/arm.toml");
    let anim = Animation::Timed(parse_timed(&text).unwrap());
    let grids_at = |t: f64| {
        let spec = anim.spec_at(t).unwrap();
        let solved = pdeshape::design::solve_design(&spec).unwrap();
        solved.meshes(12, 24).unwrap()
    };
    // The wrist ring (radius 0.55 at z = 8, attached to the forearm) is the forearm patch's
    // last row. At the key time t = 1 the joints are at upper 35°, forearm 42.5° (its keys
    // 15° at 0.5 and 70° at 1.5 with zero slopes: the cubic's middle), so the ring is the rest
    // ring turned by the forearm's hinge, then the upper arm's.
    let wrist_rest = |v: f64| [0.55 * v.cos(), 0.55 * v.sin(), 8.0];
    let pose = |p: [f64; 3], fore: f64, upper: f64| {
        let p = rotate(p, [0.0, 1.0, 0.0], fore, [0.0, 0.0, 4.0]);
        rotate(p, [0.0, 1.0, 0.0], upper, [0.0, 0.0, 0.0])
    };
    for (t, fore, upper) in [(0.5, 15.0, 17.5), (1.0, 42.5, 35.0), (1.5, 70.0, 17.5)] {
        let g = grids_at(t);
        let fa = &g[1];
        let last = fa.nu - 1;
        for j in 0..fa.nv {
            let want = pose(wrist_rest(fa.v[j]), fore, upper);
            let got = fa.positions[fa.index(last, j)];
            let d = (0..3)
                .map(|c| (got[c] as f64 - want[c]).powi(2))
                .sum::<f64>()
                .sqrt();
            assert!(d < 2e-5, "t = {t}, v = {}: {got:?} vs {want:?}", fa.v[j]);
        }
    }
    // Rigid at every frame: the pairwise distances of the wrist ring's points and of the
    // fingertip patch's first row (the same ring) do not change.
    let rest = grids_at(0.0);
    let ring = |g: &[pdeshape::mesh::GridMesh]| {
        let fa = &g[1];
        (0..fa.nv)
            .map(|j| fa.positions[fa.index(fa.nu - 1, j)].map(f64::from))
            .collect::<Vec<_>>()
    };
    let dist = |a: [f64; 3], b: [f64; 3]| (0..3).map(|c| (a[c] - b[c]).powi(2)).sum::<f64>().sqrt();
    let r0 = ring(&rest);
    let mut moved = 0.0f64;
    for &t in anim.times().unwrap().iter().step_by(7) {
        let r = ring(&grids_at(t));
        for i in 0..r.len() {
            moved = moved.max(dist(r[i], r0[i]));
            for j in 0..i {
                assert!(
                    (dist(r[i], r[j]) - dist(r0[i], r0[j])).abs() < 1e-5,
                    "t = {t}: points {i}, {j}"
                );
            }
        }
    }
    assert!(moved > 1.0, "the wrist moved by {moved}");
    // The loop closes: the design at the end of the cycle is the one at its start.
    assert_eq!(anim.spec_at(2.0).unwrap(), anim.spec_at(0.0).unwrap());
    assert_eq!(grids_at(2.0), rest);
    // A derivative curve cannot be attached (a difference vector does not turn about a point).
    let bad = text.replace(
        "tip_ring = \"hand\"",
        "tip_ring = \"hand\"\ntip_d = \"hand\"",
    );
    let e = parse_timed(&bad).unwrap_err();
    assert_eq!(e.place(), "rig.attach.tip_d", "{e}");
}

/// Every frame of an animation as `for_each_frame` hands it over (grids, welded mesh), with
/// the counts of frames solved and repeated.
type Solved = (
    Vec<Vec<pdeshape::mesh::GridMesh>>,
    Vec<pdeshape::mesh::TriMesh>,
);

fn all_frames(anim: &Animation, times: &[f64]) -> (Solved, pdeshape::anim::Solves) {
    let (mut grids, mut meshes) = (Vec::new(), Vec::new());
    let mut order = Vec::new();
    let solves = for_each_frame(anim, times, 16, 32, &Export::default(), |f| {
        order.push((f.index, f.t));
        grids.push(f.grids.to_vec());
        meshes.push(f.mesh.clone());
        Ok(())
    })
    .unwrap();
    let expected: Vec<(usize, f64)> = times.iter().copied().enumerate().collect();
    assert_eq!(order, expected, "frames in order");
    ((grids, meshes), solves)
}

fn in_pool<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

/// Frames solved in parallel (several workers, each re-solving incrementally from its own
/// previous frame) are those of compiling the design afresh at every time, bit for bit, and
/// do not depend on the number of threads.
#[test]
fn parallel_frames_equal_fresh_compiles_at_every_time_bit_for_bit() {
    let anim = Animation::Timed(parse_timed(&example("anim/ventricle.toml")).unwrap());
    let times: Vec<f64> = anim.times().unwrap().into_iter().step_by(3).collect();
    let ((grids, meshes), solves) = in_pool(3, || all_frames(&anim, &times));
    assert_eq!(solves.solved, times.len());
    let ((grids1, meshes1), _) = in_pool(1, || all_frames(&anim, &times));
    assert_eq!(grids, grids1);
    assert_eq!(meshes, meshes1);
    for (k, &t) in times.iter().enumerate() {
        let spec = anim.spec_at(t).unwrap();
        let solved = pdeshape::design::solve_design(&spec).unwrap();
        let fresh = solved.meshes(16, 32).unwrap();
        assert_eq!(grids[k], fresh, "t = {t}");
        assert_eq!(
            meshes[k],
            solved.weld(&fresh, &Export::default()),
            "t = {t}"
        );
    }
    assert_ne!(meshes[1].positions, meshes[0].positions, "the frames move");
}

/// A design without formula fields in `t` is solved once; a morph between a design and itself
/// too; every frame is that solve.
#[test]
fn animations_that_do_not_change_are_solved_once() {
    let text = example("wine_glass.toml");
    let timed = parse_timed(&format!("{text}\n[time]\nend = 1.0\nframes = 6\n")).unwrap();
    let still = Animation::Timed(timed);
    assert!(!still.depends_on_time());
    let times = still.times().unwrap();
    let ((grids, meshes), solves) = in_pool(2, || all_frames(&still, &times));
    assert_eq!((solves.solved, solves.repeated), (1, 5));
    let solved = pdeshape::design::solve_design(&still.spec_at(0.0).unwrap()).unwrap();
    let fresh = solved.meshes(16, 32).unwrap();
    for k in 0..times.len() {
        assert_eq!(grids[k], fresh, "frame {k}");
        assert_eq!(
            meshes[k],
            solved.weld(&fresh, &Export::default()),
            "frame {k}"
        );
    }
    let same = morph(&text, &text);
    assert!(!same.depends_on_time());
    let (_, solves) = in_pool(2, || all_frames(&same, &same.times().unwrap()));
    assert_eq!((solves.solved, solves.repeated), (1, 4));
    // A hold: the radius starts to grow at t = 1/2, so frames 0, 1, 2 are one design; one
    // worker solves frame 0 and hands it over again for 1 and 2.
    let held = example("water_glass.toml").replacen(
        "radius = 1.0",
        "radius = \"= 1 + (t - 0.5 + abs(t - 0.5))/2\"",
        1,
    );
    let held =
        Animation::Timed(parse_timed(&format!("{held}\n[time]\nend = 1.0\nframes = 6\n")).unwrap());
    let times = held.times().unwrap();
    assert_eq!(times.len(), 6);
    let ((grids, meshes), solves) = in_pool(1, || all_frames(&held, &times));
    assert_eq!((solves.solved, solves.repeated), (4, 2));
    for (k, &t) in times.iter().enumerate() {
        let solved = pdeshape::design::solve_design(&held.spec_at(t).unwrap()).unwrap();
        let fresh = solved.meshes(16, 32).unwrap();
        assert_eq!(grids[k], fresh, "t = {t}");
        assert_eq!(
            meshes[k],
            solved.weld(&fresh, &Export::default()),
            "t = {t}"
        );
    }
    assert_eq!(meshes[2], meshes[0]);
    assert_ne!(meshes[3].positions, meshes[0].positions);
}

/// Every bundled animation (the timed designs and the morph), at its own grid.
fn bundled_animations() -> Vec<(String, Animation, (usize, usize))> {
    let dir = example_path("anim");
    let mut out = Vec::new();
    let mut names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    names.sort();
    for path in names {
        let text = std::fs::read_to_string(&path).unwrap();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        if let Some(m) = pdeshape::spec::time::parse_morph_file(&text).unwrap() {
            let read = |f: &str| std::fs::read_to_string(dir.join(f)).unwrap();
            let morph = Morph::new(&read(&m.morph.source), &read(&m.morph.target)).unwrap();
            let grid = (m.output.nu.unwrap(), m.output.nv.unwrap());
            let anim = Animation::Morph {
                morph,
                time: m.time,
                ease: m.morph.ease,
            };
            out.push((name, anim, grid));
        } else if text.contains("[time]") {
            let timed = parse_timed(&text).unwrap();
            let spec = timed.at(timed.time.start).unwrap();
            let grid = (spec.output.nu.unwrap(), spec.output.nv.unwrap());
            out.push((name, Animation::Timed(timed), grid));
        }
    }
    out
}

/// Bit patterns of a mesh's numbers (so that `-0.0` and `0.0` differ).
fn bits(m: &pdeshape::mesh::TriMesh) -> (Vec<u32>, Vec<u32>) {
    let b = |v: &[[f32; 3]]| v.iter().flatten().map(|x| x.to_bits()).collect();
    (b(&m.positions), b(&m.normals))
}

/// Welding a frame on the first frame's topology (the vertex map checked, not rebuilt; the
/// positions gathered) gives the mesh of welding that frame from scratch, bit for bit, at every
/// frame of every bundled animation.
#[test]
fn frames_welded_by_gather_equal_a_full_weld_at_every_frame_of_every_bundled_animation() {
    use pdeshape::mesh::{weld_mapped, FrameWeld, WeldOptions, WeldTopology};
    let options = WeldOptions::default();
    let all = bundled_animations();
    let names: Vec<&str> = all.iter().map(|a| a.0.as_str()).collect();
    for expected in ["arm", "face", "fish", "glass_morph", "snake", "ventricle"] {
        assert!(names.contains(&&*format!("{expected}.toml")), "{names:?}");
    }
    for (name, anim, (nu, nv)) in &all {
        let times = anim.times().unwrap();
        let mut compiled = pdeshape::design::compile(&anim.spec_at(times[0]).unwrap()).unwrap();
        let mut welder: Option<FrameWeld> = None;
        let mut first = Vec::new();
        for (k, &t) in times.iter().enumerate() {
            compiled.set_spec(anim.spec_at(t).unwrap()).unwrap();
            let labels: Vec<String> = compiled
                .solved()
                .names()
                .iter()
                .map(|s| s.to_string())
                .collect();
            let labels: Vec<&str> = labels.iter().map(String::as_str).collect();
            let grids = compiled.meshes(*nu, *nv).unwrap().to_vec();
            let fresh = weld_mapped(&grids, &labels, options);
            match welder.as_mut() {
                None => {
                    let (topology, w) = WeldTopology::new(&grids, &labels, options);
                    assert_eq!(bits(&w.mesh), bits(&fresh.mesh));
                    first = w.mesh.positions.clone();
                    welder = Some(FrameWeld::new(topology));
                }
                Some(w) => {
                    assert!(w.weld(&grids), "{name}: frame {k} (t = {t})");
                    assert_eq!(w.mesh(), &fresh.mesh, "{name}: frame {k}");
                    assert_eq!(bits(w.mesh()), bits(&fresh.mesh), "{name}: frame {k}");
                    assert_eq!(w.flipped(), fresh.flipped.as_slice(), "{name}: frame {k}");
                    assert_eq!(w.topology().weld(&grids).unwrap(), fresh, "{name}: {k}");
                }
            }
        }
        // The frames move (the comparison is not of one mesh with itself).
        assert_ne!(welder.unwrap().mesh().positions, first, "{name}");
    }
}

/// The check of the vertex map refuses grids whose vertices would join otherwise: two patches
/// that come together, a row that collapses to a point, a shared ring that parts.
#[test]
fn the_gathered_weld_refuses_frames_whose_vertices_join_otherwise() {
    use pdeshape::mesh::{weld_mapped, FrameWeld, WeldOptions, WeldTopology};
    let anim = Animation::Timed(parse_timed(&example("anim/ventricle.toml")).unwrap());
    let solved = pdeshape::design::solve_design(&anim.spec_at(0.0).unwrap()).unwrap();
    let grids = solved.meshes(16, 32).unwrap();
    let options = WeldOptions::default();
    let (topology, _) = WeldTopology::new(&grids, &solved.names(), options);
    let mut welder = FrameWeld::new(topology);
    assert!(welder.weld(&grids));
    let refused = |g: &[pdeshape::mesh::GridMesh], welder: &mut FrameWeld| {
        assert!(!welder.weld(g));
        // The full weld finds another vertex map too.
        let full = weld_mapped(g, &solved.names(), options);
        assert_ne!(
            full.source,
            weld_mapped(&grids, &solved.names(), options).source
        );
    };
    // The base ring of the last patch parts from nothing, but a copy of its first vertex
    // moved onto the apex joins them.
    let mut g = grids.clone();
    let apex = g[0].positions[0];
    let last = g.len() - 1;
    let n = g[last].positions.len();
    g[last].positions[n - 1] = apex;
    refused(&g, &mut welder);
    // An interior row of a patch collapses to one point.
    let mut g = grids.clone();
    let nv = g[1].nv;
    let p = g[1].positions[5 * nv];
    for q in &mut g[1].positions[5 * nv..6 * nv] {
        *q = p;
    }
    refused(&g, &mut welder);
    // The ring shared by the first two patches parts (one copy moved by a grid spacing).
    let mut g = grids.clone();
    let nu = g[1].nu;
    let _ = nu;
    g[1].positions[3][2] += 0.05;
    refused(&g, &mut welder);
    // And the unchanged grids are welded again.
    assert!(welder.weld(&grids));
}
