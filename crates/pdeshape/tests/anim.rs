//! Time-dependent designs: morph ends, self-morph, the ventricle's periodicity and volume curve.

use pdeshape::anim::{for_each_frame, Animation, Keyframes, Morph};
use pdeshape::design::Export;
use pdeshape::spec::time::{parse_timed, TimeSpec};
use std::path::Path;

fn example(name: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(name);
    std::fs::read_to_string(p).unwrap()
}

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
