//! Per-vertex colouring.

use super::*;
use crate::mesh::tessellate;
use crate::surface::{Partials, Surface, VDomain};

#[test]
fn diverging_map_ends_middle_and_nan() {
    let c = diverging_colors(&[-2.0, -1.0, 0.0, 1.0, 5.0, f64::NAN], -1.0, 1.0);
    assert_eq!(c[0], [59, 76, 192]);
    assert_eq!(c[1], [59, 76, 192]);
    assert_eq!(c[2], [221, 221, 221]);
    assert_eq!(c[3], [180, 4, 38]);
    assert_eq!(c[4], [180, 4, 38]);
    assert_eq!(c[5], [128, 128, 128]);
    // A quarter of the way: halfway between blue and grey.
    assert_eq!(diverging_colors(&[0.25], 0.0, 1.0)[0], [140, 149, 207]);
}

pub(super) struct Disc;
impl Surface for Disc {
    fn v_domain(&self) -> VDomain {
        VDomain::Periodic
    }
    fn partials(&self, u: f64, v: f64) -> Partials {
        let r = 0.2 + u;
        Partials {
            x: crate::Vec3::new(r * v.cos(), r * v.sin(), 0.0),
            xu: crate::Vec3::new(v.cos(), v.sin(), 0.0),
            xv: crate::Vec3::new(-r * v.sin(), r * v.cos(), 0.0),
            xuv: crate::Vec3::new(-v.sin(), v.cos(), 0.0),
            xvv: crate::Vec3::new(-r * v.cos(), -r * v.sin(), 0.0),
            ..Default::default()
        }
    }
}

#[test]
fn colored_surfaces_show_their_colour_and_bad_lists_are_refused() {
    let mesh = tessellate(&Disc, 8, 32).unwrap();
    let options = RenderOptions {
        width: 64,
        height: 64,
        view: Some(crate::Vec3::new(0.0, 0.0, 1.0)),
        up: crate::Vec3::new(0.0, 1.0, 0.0),
    };
    let red = vec![[200u8, 0, 0]; mesh.len()];
    let png = render_png_colored(std::slice::from_ref(&mesh), &[red], &[], &options).unwrap();
    let decoder = png::Decoder::new(std::io::Cursor::new(png));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size()];
    reader.next_frame(&mut buf).unwrap();
    // A pixel on the ring (radius 0.7 of 1.2, right of the centre): red dominates.
    let (x, y) = (32 + 13, 32);
    let px = &buf[3 * (y * 64 + x)..3 * (y * 64 + x) + 3];
    assert!(px[0] > 2 * px[1].max(px[2]) && px[0] > 60, "{px:?}");
    let short = vec![[0u8; 3]; 3];
    let e = render_png_colored(std::slice::from_ref(&mesh), &[short], &[], &options).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!("mesh 0 has {} vertices but 3 colours", mesh.len())
    );
    assert!(render_png_colored(&[mesh], &[], &[], &options).is_err());
}
