//! A curve's `transform` steps as one affine map ([`crate::curve::Affine`]), and control points
//! carried through it both ways (where the designer draws and drags them).

use crate::curve::Affine;
use crate::spec::{CurveKind, CurveSpec, TransformStep, V3};
use crate::{Result, Vec3};

fn v3(p: &V3) -> Vec3 {
    Vec3::new(p[0], p[1], p[2])
}

/// The affine map of `transform` steps applied in order (rotation angles in degrees). An
/// invalid step is refused at `{place}.transform[i].rotate` (`.scale`, `.dilate`).
pub fn transform_map(steps: &[TransformStep], place: &str) -> Result<Affine> {
    transform_map_at(steps, &|| place.to_string())
}

/// [`transform_map`] with the place built only when a step is refused.
pub(crate) fn transform_map_at(
    steps: &[TransformStep],
    place: &dyn Fn() -> String,
) -> Result<Affine> {
    let mut map = Affine::identity();
    for (i, step) in steps.iter().enumerate() {
        let at = |what: &str| format!("{}.transform[{i}].{what}", place());
        let next = match step {
            TransformStep::Translate(d) => Affine::translation(v3(d)),
            TransformStep::Rotate { axis, angle, about } => {
                Affine::rotation(v3(axis), angle.to_radians(), v3(about))
                    .map_err(|e| e.at(&at("rotate")))?
            }
            TransformStep::Scale { factor, about } => {
                Affine::scaling(*factor, v3(about)).map_err(|e| e.at(&at("scale")))?
            }
            TransformStep::Dilate { factors, about } => {
                Affine::dilation(v3(factors), v3(about)).map_err(|e| e.at(&at("dilate")))?
            }
        };
        map = map.then(&next);
    }
    Ok(map)
}

/// The control points of a B-spline, Bézier or samples curve where the curve's transform puts
/// them (`None` for other kinds, or when a step is invalid: compiling reports that).
pub fn world_control_points(cs: &CurveSpec) -> Option<Vec<V3>> {
    let points = match &cs.kind {
        CurveKind::BSpline { control, .. } | CurveKind::Bezier { control } => control,
        CurveKind::Samples { points, .. } => points,
        _ => return None,
    };
    let map = transform_map(&cs.transform, "").ok()?;
    Some(
        points
            .iter()
            .map(|p| {
                let q = map.apply_point(&v3(p));
                [q.x, q.y, q.z]
            })
            .collect(),
    )
}

/// The control point that the curve's transform carries to `world` (the inverse map); `None`
/// when a step is invalid or the map is singular.
pub fn spec_point(cs: &CurveSpec, world: V3) -> Option<V3> {
    let map = transform_map(&cs.transform, "").ok()?;
    let inverse = map.linear.try_inverse()?;
    let p = inverse * (v3(&world) - map.shift);
    p.iter().all(|x| x.is_finite()).then_some([p.x, p.y, p.z])
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Translate, rotate by 90° about z, scale by 2: (1,2,3) → (2,2,3) → (−2,2,3) → (−4,4,6),
    /// and back through the inverse.
    #[test]
    fn control_points_map_through_the_transform_and_back() {
        let cs = CurveSpec {
            kind: CurveKind::Bezier {
                control: vec![[1.0, 2.0, 3.0], [0.0, 0.0, 1.0]],
            },
            transform: vec![
                TransformStep::Translate([1.0, 0.0, 0.0]),
                TransformStep::Rotate {
                    axis: [0.0, 0.0, 1.0],
                    angle: 90.0,
                    about: [0.0, 0.0, 0.0],
                },
                TransformStep::Scale {
                    factor: 2.0,
                    about: [0.0, 0.0, 0.0],
                },
            ],
            v_origin: 0.0,
            arc_length: false,
        };
        let w = world_control_points(&cs).unwrap();
        for (a, b) in w[0].iter().zip([-4.0, 4.0, 6.0]) {
            assert!((a - b).abs() < 1e-12, "{:?}", w[0]);
        }
        let back = spec_point(&cs, w[0]).unwrap();
        for (a, b) in back.iter().zip([1.0, 2.0, 3.0]) {
            assert!((a - b).abs() < 1e-12, "{back:?}");
        }
    }

    /// A scaling by 0 is refused at its place; a singular map has no inverse point.
    #[test]
    fn an_invalid_step_is_refused_with_its_place() {
        let steps = [
            TransformStep::Translate([1.0, 0.0, 0.0]),
            TransformStep::Scale {
                factor: 0.0,
                about: [0.0, 0.0, 0.0],
            },
        ];
        let e = transform_map(&steps, "curves.rim").unwrap_err();
        assert_eq!(e.place(), "curves.rim.transform[1].scale");
    }
}
