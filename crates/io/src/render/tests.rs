use super::*;
use crate::mesh::Grid;
use std::f64::consts::PI;

/// A grid evaluated from a closed-form surface `f(u, v) -> (X, N)`, `u ∈ [0, 1]`, `v` periodic on
/// `[0, 2π)` or on `[0, 1]`.
fn grid(nu: usize, nv: usize, periodic: bool, f: impl Fn(f64, f64) -> (Vec3, Vec3)) -> GridMesh {
    let u: Vec<f64> = (0..nu).map(|i| i as f64 / (nu - 1) as f64).collect();
    let v: Vec<f64> = if periodic {
        (0..nv).map(|j| crate::TAU * j as f64 / nv as f64).collect()
    } else {
        (0..nv).map(|j| j as f64 / (nv - 1) as f64).collect()
    };
    let mut positions = Vec::new();
    let mut normals = Vec::new();
    for &ui in &u {
        for &vj in &v {
            let (x, n) = f(ui, vj);
            positions.push([x.x as f32, x.y as f32, x.z as f32]);
            normals.push([n.x as f32, n.y as f32, n.z as f32]);
        }
    }
    Grid {
        nu,
        nv,
        periodic_v: periodic,
        u,
        v,
        positions,
        normals,
    }
}

/// Unit sphere from the north pole (u = 0) to the south pole; `X_u × X_v` points outwards.
fn sphere(nu: usize, nv: usize) -> GridMesh {
    grid(nu, nv, true, |u, v| {
        let th = PI * u;
        let x = Vec3::new(th.sin() * v.cos(), th.sin() * v.sin(), th.cos());
        (x, x)
    })
}

/// Torus with radii 1 and 0.35 around the z axis.
fn torus(nu: usize, nv: usize) -> GridMesh {
    grid(nu, nv, true, |u, v| {
        let a = crate::TAU * u;
        let n = Vec3::new(v.cos() * a.cos(), v.cos() * a.sin(), v.sin());
        let x = Vec3::new(a.cos(), a.sin(), 0.0) + 0.35 * n;
        (x, n)
    })
}

/// Open cup: a paraboloid-ish wall from the bottom (u = 0, radius 0.3) to the rim (u = 1, radius
/// 1, height 1); the normals `X_u × X_v` point into the cup.
fn cup(nu: usize, nv: usize) -> GridMesh {
    grid(nu, nv, true, |u, v| {
        let r = 0.3 + 0.7 * u;
        let z = u * u;
        let x = Vec3::new(r * v.cos(), r * v.sin(), z);
        // X_u = (0.7 cos, 0.7 sin, 2u), X_v = r(−sin, cos, 0): X_u × X_v = r(−2u cos, −2u sin, 0.7).
        let n = Vec3::new(-2.0 * u * v.cos(), -2.0 * u * v.sin(), 0.7).normalize();
        (x, n)
    })
}

struct Picture {
    w: usize,
    h: usize,
    rgb: Vec<u8>,
}

impl Picture {
    fn px(&self, x: usize, y: usize) -> [u8; 3] {
        let i = 3 * (y * self.w + x);
        [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
    }
}

fn decode(bytes: &[u8]) -> Picture {
    let decoder = png::Decoder::new(bytes);
    let mut reader = decoder.read_info().expect("PNG header");
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).expect("PNG data");
    assert_eq!(info.color_type, png::ColorType::Rgb);
    assert_eq!(info.bit_depth, png::BitDepth::Eight);
    buf.truncate(info.buffer_size());
    Picture {
        w: info.width as usize,
        h: info.height as usize,
        rgb: buf,
    }
}

fn render(meshes: &[GridMesh], overlays: &[Polyline], opts: &RenderOptions) -> Picture {
    decode(&render_png(meshes, overlays, opts).expect("render"))
}

/// Pixels that differ from the empty background.
fn object_mask(p: &Picture, opts: &RenderOptions) -> Vec<bool> {
    let bg = render(&[], &[], opts);
    (0..p.w * p.h)
        .map(|i| (0..3).any(|k| p.rgb[3 * i + k].abs_diff(bg.rgb[3 * i + k]) > 2))
        .collect()
}

fn bbox(mask: &[bool], w: usize) -> (usize, usize, usize, usize) {
    let (mut x0, mut x1, mut y0, mut y1) = (usize::MAX, 0, usize::MAX, 0);
    for (i, &m) in mask.iter().enumerate() {
        if m {
            let (x, y) = (i % w, i / w);
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
    }
    (x0, x1, y0, y1)
}

fn luma(c: [u8; 3]) -> f64 {
    0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64
}

#[test]
fn sphere_is_centred_and_fills_the_frame() {
    let opts = RenderOptions::default();
    let p = render(&[sphere(64, 96)], &[], &opts);
    assert_eq!((p.w, p.h), (800, 600));
    let mask = object_mask(&p, &opts);
    let (x0, x1, y0, y1) = bbox(&mask, p.w);
    // The margin is 6 % of the height (36 px) on the limiting side; the sphere's outline lies
    // slightly outside the polygon through its vertices' images only by antialiasing.
    assert!(
        x0 > 0 && y0 > 0 && x1 < p.w - 1 && y1 < p.h - 1,
        "{x0} {x1} {y0} {y1}"
    );
    assert!((y0 as i64 - 36).abs() <= 3 && (p.h as i64 - 1 - y1 as i64 - 36).abs() <= 3);
    let cx = 0.5 * (x0 + x1) as f64;
    let cy = 0.5 * (y0 + y1) as f64;
    assert!(
        (cx - 400.0).abs() <= 2.0 && (cy - 300.0).abs() <= 2.0,
        "{cx} {cy}"
    );
    // A disc of diameter 0.88 · 600: π/4 · 528² / (800 · 600) ≈ 0.456 of the picture.
    let frac = mask.iter().filter(|&&m| m).count() as f64 / (p.w * p.h) as f64;
    assert!((frac - 0.456).abs() < 0.01, "{frac}");
}

#[test]
fn key_light_from_the_upper_left() {
    let opts = RenderOptions {
        width: 300,
        height: 300,
        ..RenderOptions::default()
    };
    let p = render(&[sphere(48, 64)], &[], &opts);
    let mask = object_mask(&p, &opts);
    let mean = |keep: &dyn Fn(usize, usize) -> bool| {
        let (mut s, mut n) = (0.0, 0.0);
        for y in 0..p.h {
            for x in 0..p.w {
                if mask[y * p.w + x] && keep(x, y) {
                    s += luma(p.px(x, y));
                    n += 1.0;
                }
            }
        }
        s / n
    };
    let (left, right) = (mean(&|x, _| x < 150), mean(&|x, _| x >= 150));
    let (top, bottom) = (mean(&|_, y| y < 150), mean(&|_, y| y >= 150));
    assert!(left > right + 5.0, "left {left} right {right}");
    assert!(top > bottom + 15.0, "top {top} bottom {bottom}");
    // The brightest point (key light highlight) is in the upper left quadrant, the darkest in the
    // lower half.
    let object = (0..p.w * p.h).filter(|&i| mask[i]);
    let brightest = object
        .clone()
        .max_by(|&i, &j| luma(p.px(i % p.w, i / p.w)).total_cmp(&luma(p.px(j % p.w, j / p.w))))
        .unwrap();
    let darkest = object
        .min_by(|&i, &j| luma(p.px(i % p.w, i / p.w)).total_cmp(&luma(p.px(j % p.w, j / p.w))))
        .unwrap();
    assert!(
        brightest % p.w < 150 && brightest / p.w < 150,
        "{brightest}"
    );
    assert!(darkest / p.w > 150, "{darkest}");
    // Shading varies a lot over the sphere.
    let lumas: Vec<f64> = (0..p.w * p.h)
        .filter(|&i| mask[i])
        .map(|i| luma(p.px(i % p.w, i / p.w)))
        .collect();
    let max = lumas.iter().cloned().fold(0.0, f64::max);
    let min = lumas.iter().cloned().fold(255.0, f64::min);
    assert!(max - min > 100.0, "{min}..{max}");
}

#[test]
fn inside_of_a_cup_is_tinted() {
    let opts = RenderOptions {
        width: 400,
        height: 300,
        ..RenderOptions::default()
    };
    let p = render(&[cup(32, 64)], &[], &opts);
    let mask = object_mask(&p, &opts);
    let warm = (0..p.w * p.h)
        .filter(|&i| mask[i])
        .filter(|&i| {
            let c = p.px(i % p.w, i / p.w);
            c[0] as i32 > c[2] as i32 + 25
        })
        .count();
    let cool = (0..p.w * p.h)
        .filter(|&i| mask[i])
        .filter(|&i| {
            let c = p.px(i % p.w, i / p.w);
            (c[2] as i32) > c[0] as i32 + 5
        })
        .count();
    let total = mask.iter().filter(|&&m| m).count();
    // Seen from above, both the inside (front side, cool) and the outside (back, warm) show.
    assert!(
        warm > total / 5 && cool > total / 5,
        "{warm} {cool} {total}"
    );
    // Flipping the normals swaps the sides.
    let mut flipped = cup(32, 64);
    for n in &mut flipped.normals {
        *n = n.map(|c| -c);
    }
    let q = render(&[flipped], &[], &opts);
    let warm_flipped = (0..q.w * q.h)
        .filter(|&i| mask[i])
        .filter(|&i| {
            let c = q.px(i % q.w, i / q.w);
            c[0] as i32 > c[2] as i32 + 25
        })
        .count();
    assert!(
        (warm_flipped as i64 - cool as i64).abs() < total as i64 / 10,
        "{warm_flipped} {cool}"
    );
}

fn red_line(points: Vec<Vec3>, closed: bool) -> Polyline {
    Polyline {
        points,
        color: [255, 0, 0],
        width: 3.0,
        closed,
    }
}

fn is_pure_red(c: [u8; 3]) -> bool {
    c[0] > 200 && c[1] < 60 && c[2] < 60
}

fn is_reddish(c: [u8; 3]) -> bool {
    c[0] as i32 > c[1] as i32 + 40 && c[0] as i32 > c[2] as i32 + 40
}

#[test]
fn overlays_in_front_and_hidden() {
    let opts = RenderOptions {
        width: 400,
        height: 300,
        ..RenderOptions::default()
    };
    let mesh = sphere(48, 64);
    // The equator, slightly outside the sphere so that its front half is in front.
    let equator: Vec<Vec3> = (0..128)
        .map(|k| {
            let t = crate::TAU * k as f64 / 128.0;
            1.002 * Vec3::new(t.cos(), t.sin(), 0.0)
        })
        .collect();
    let p = render(
        std::slice::from_ref(&mesh),
        &[red_line(equator, true)],
        &opts,
    );
    let red = p
        .rgb
        .chunks(3)
        .filter(|c| is_pure_red([c[0], c[1], c[2]]))
        .count();
    assert!(red > 300, "{red}");

    // A spine along the axis, entirely inside: faded but visible, and never fully red.
    let spine: Vec<Vec3> = (0..=20)
        .map(|k| Vec3::new(0.0, 0.0, -0.8 + 0.08 * k as f64))
        .collect();
    let q = render(
        std::slice::from_ref(&mesh),
        &[red_line(spine.clone(), false)],
        &opts,
    );
    let tinted = q
        .rgb
        .chunks(3)
        .filter(|c| is_reddish([c[0], c[1], c[2]]))
        .count();
    let pure = q
        .rgb
        .chunks(3)
        .filter(|c| is_pure_red([c[0], c[1], c[2]]))
        .count();
    assert!(tinted > 100, "{tinted}");
    assert_eq!(pure, 0);
    // Without the sphere the same spine is drawn fully.
    let r = render(&[], &[red_line(spine, false)], &opts);
    let pure = r
        .rgb
        .chunks(3)
        .filter(|c| is_pure_red([c[0], c[1], c[2]]))
        .count();
    assert!(pure > 300, "{pure}");
}

#[test]
fn deterministic_and_other_views() {
    let opts = RenderOptions {
        width: 320,
        height: 240,
        ..RenderOptions::default()
    };
    let meshes = [torus(64, 32), sphere(16, 24)];
    let a = render_png(&meshes, &[], &opts).unwrap();
    let b = render_png(&meshes, &[], &opts).unwrap();
    assert_eq!(a, b);
    // Looking straight down the up axis: another up vector is picked, the torus is centred.
    for view in [
        Vec3::z(),
        -Vec3::z(),
        Vec3::new(0.0, 0.0, 1e-12) + Vec3::z(),
    ] {
        let opts = RenderOptions {
            view: Some(view),
            ..opts.clone()
        };
        let p = render(&meshes[..1], &[], &opts);
        let (x0, x1, y0, y1) = bbox(&object_mask(&p, &opts), p.w);
        assert!((0.5 * (x0 + x1) as f64 - 160.0).abs() <= 2.0);
        assert!((0.5 * (y0 + y1) as f64 - 120.0).abs() <= 2.0);
        assert!(y0 > 0 && y1 < p.h - 1);
    }
}

#[test]
fn empty_scenes() {
    let opts = RenderOptions {
        width: 64,
        height: 48,
        ..RenderOptions::default()
    };
    let p = render(&[], &[], &opts);
    assert_eq!((p.w, p.h), (64, 48));
    // A vertical gradient, light at the top.
    assert!(luma(p.px(10, 0)) > luma(p.px(10, 47)) + 20.0);
    assert_eq!(p.px(0, 5), p.px(63, 5));
    // Empty meshes, an empty polyline, a single-point polyline, a zero-width line.
    let empty = Grid {
        nu: 0,
        nv: 0,
        periodic_v: false,
        u: vec![],
        v: vec![],
        positions: vec![],
        normals: vec![],
    };
    let dot = Polyline {
        points: vec![Vec3::new(1.0, 2.0, 3.0)],
        color: [255, 0, 0],
        width: 5.0,
        closed: true,
    };
    let nothing = Polyline {
        points: vec![],
        color: [0, 0, 0],
        width: 2.0,
        closed: false,
    };
    let q = render(std::slice::from_ref(&empty), &[dot.clone(), nothing], &opts);
    assert!(is_pure_red(q.px(32, 24)));
    // A degenerate mesh: every vertex at one point.
    let mut flat = sphere(8, 8);
    for p in &mut flat.positions {
        *p = [0.5, 0.5, 0.5];
    }
    let q = render(&[flat, empty], &[], &opts);
    assert_eq!(q.rgb, p.rgb);
    // Missing normals (zero or NaN): the facet normals shade instead.
    let mut facets = sphere(24, 32);
    for (k, n) in facets.normals.iter_mut().enumerate() {
        *n = if k % 2 == 0 { [0.0; 3] } else { [f32::NAN; 3] };
    }
    let q = render(&[facets], &[], &opts);
    let mask = object_mask(&q, &opts);
    let lumas: Vec<f64> = (0..q.w * q.h)
        .filter(|&i| mask[i])
        .map(|i| luma(q.px(i % q.w, i / q.w)))
        .collect();
    assert!(lumas.len() > q.w * q.h / 4);
    let max = lumas.iter().cloned().fold(0.0, f64::max);
    let min = lumas.iter().cloned().fold(255.0, f64::min);
    assert!(max - min > 60.0, "{min}..{max}");
    // Tiny pictures.
    for (w, h) in [(1, 1), (1, 7), (5, 1)] {
        let opts = RenderOptions {
            width: w,
            height: h,
            ..RenderOptions::default()
        };
        let p = render(&[sphere(8, 8)], std::slice::from_ref(&dot), &opts);
        assert_eq!((p.w, p.h), (w as usize, h as usize));
    }
}

#[test]
fn bad_input_is_refused() {
    let ok = RenderOptions::default();
    for (w, h) in [(0, 10), (10, 0), (MAX_SIDE + 1, 10), (10, MAX_SIDE + 1)] {
        let opts = RenderOptions {
            width: w,
            height: h,
            ..ok.clone()
        };
        let e = render_png(&[], &[], &opts).unwrap_err();
        assert_eq!(e.place(), "size", "{e}");
        assert_eq!(e.kind(), crate::ErrorKind::Invalid);
    }
    let mut bad = sphere(8, 8);
    bad.positions[13][1] = f32::NAN;
    let e = render_png(&[sphere(4, 4), bad], &[], &ok).unwrap_err();
    assert_eq!(e.place(), "meshes[1].positions[13]", "{e}");
    let mut bad = sphere(8, 8);
    bad.positions[0][2] = f32::INFINITY;
    assert!(render_png(&[bad], &[], &ok).is_err());
    let mut short = sphere(8, 8);
    short.normals.pop();
    assert_eq!(
        render_png(&[short], &[], &ok).unwrap_err().place(),
        "meshes[0]"
    );
    let line = red_line(vec![Vec3::zeros(), Vec3::new(f64::NAN, 0.0, 0.0)], false);
    let e = render_png(&[], &[line], &ok).unwrap_err();
    assert_eq!(e.place(), "overlays[0].points[1]");
    let mut line = red_line(vec![Vec3::zeros(), Vec3::x()], false);
    line.width = f32::NAN;
    assert_eq!(
        render_png(&[], &[line], &ok).unwrap_err().place(),
        "overlays[0].width"
    );
    let far = red_line(vec![Vec3::repeat(-1e300), Vec3::repeat(1e300)], false);
    assert!(render_png(&[], &[far], &ok).is_err());
    for (view, up, place) in [
        (Some(Vec3::zeros()), Vec3::z(), "view"),
        (Some(Vec3::new(f64::NAN, 1.0, 0.0)), Vec3::z(), "view"),
        (None, Vec3::zeros(), "up"),
        (None, Vec3::new(0.0, f64::INFINITY, 0.0), "up"),
    ] {
        let opts = RenderOptions {
            view,
            up,
            ..ok.clone()
        };
        assert_eq!(
            render_png(&[sphere(4, 4)], &[], &opts).unwrap_err().place(),
            place
        );
    }
}

/// The picture is not mirrored: seen from +z with +y up, +x points right; seen from −y with +z
/// up, +x points right too.
#[test]
fn axes_are_not_mirrored() {
    let axis = |d: Vec3, color: [u8; 3]| Polyline {
        points: vec![Vec3::zeros(), d],
        color,
        width: 4.0,
        closed: false,
    };
    let centroid = |p: &Picture, color: [u8; 3]| {
        let (mut sx, mut sy, mut n) = (0.0, 0.0, 0.0);
        for y in 0..p.h {
            for x in 0..p.w {
                if p.px(x, y) == color {
                    sx += x as f64;
                    sy += y as f64;
                    n += 1.0;
                }
            }
        }
        assert!(n > 10.0);
        (sx / n, sy / n)
    };
    let lines = [
        axis(Vec3::x(), [255, 0, 0]),
        axis(Vec3::y(), [0, 0, 255]),
        axis(Vec3::z(), [0, 255, 0]),
    ];
    let opts = RenderOptions {
        width: 200,
        height: 200,
        view: Some(Vec3::z()),
        up: Vec3::y(),
    };
    let p = render(&[], &lines, &opts);
    let (red, blue) = (centroid(&p, [255, 0, 0]), centroid(&p, [0, 0, 255]));
    assert!(red.0 > blue.0 + 40.0, "{red:?} {blue:?}");
    assert!(blue.1 + 40.0 < red.1, "{red:?} {blue:?}");
    let opts = RenderOptions {
        view: Some(-Vec3::y()),
        up: Vec3::z(),
        ..opts
    };
    let p = render(&[], &lines, &opts);
    let (red, green) = (centroid(&p, [255, 0, 0]), centroid(&p, [0, 255, 0]));
    assert!(red.0 > green.0 + 40.0, "{red:?} {green:?}");
    assert!(green.1 + 40.0 < red.1, "{red:?} {green:?}");
}
