//! Small design texts that several tests use.

/// A valid biharmonic design (cup-like: a circle at `u = 0`, an ellipse at `u = 1`, derivative
/// curves towards circles ahead, 16 × 24 output), the base that the CLI's error tests break one
/// thing at a time.
pub const BIHARMONIC: &str = r#"title = "test design"
conditions = [
  { u = 0.0, curve = "base" },
  { u = 0.0, derivative = 1, curve = "base_tangent" },
  { u = 1.0, curve = "rim" },
  { u = 1.0, derivative = 1, curve = "rim_tangent" },
]

[operator]
kind = "polyharmonic"
order = 2
a = 1.5

[curves.base]
type = "circle"
center = [0.0, 0.0, 0.0]
radius = 1.0

[curves.base_ahead]
type = "circle"
center = [0.0, 0.0, 1.0]
radius = 1.2

[curves.base_tangent]
type = "derivative"
position = "base"
direction = "base_ahead"
scale = 1.0

[curves.rim]
type = "ellipse"
center = [0.0, 0.0, 2.0]
rx = 1.5
ry = 1.0

[curves.rim_ahead]
type = "circle"
center = [0.0, 0.0, 3.0]
radius = 1.5

[curves.rim_tangent]
type = "derivative"
position = "rim"
direction = "rim_ahead"
scale = 1.0

[output]
nu = 16
nv = 24
"#;
