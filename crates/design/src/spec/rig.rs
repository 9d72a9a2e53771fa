//! The `[rig]` of a timed design (book §8.1.3.1): a skeleton of hinged bones with keyframed
//! joint angles over the cycle `[time.start, time.end]`; a curve attached to a bone moves
//! rigidly with it, and the PDE patches between the curves skin the rig in every frame.
//!
//! ```toml
//! [[rig.bones]]
//! name = "upper"
//! head = [0.0, 0.0, 0.0]          # the joint, in the rest pose
//! axis = [0.0, 1.0, 0.0]          # the hinge axis (right-handed, degrees)
//! keys = [[0.0, 0.0], [0.5, 60.0]] # (t, angle) over one cycle
//! [[rig.bones]]
//! name = "fore"
//! parent = "upper"
//! head = [0.0, 0.0, 4.0]
//! axis = [0.0, 1.0, 0.0]
//! keys = [[0.0, 0.0], [0.25, 45.0], [0.5, 90.0]]
//! [rig.attach]
//! wrist = "fore"
//! ```
//!
//! At time `t` the pose is forward kinematics in rest coordinates: a point of bone `k` with the
//! chain `root, …, parent, k` goes to `R_root(… R_parent(R_k(x)))`, `R_j` the rotation by the
//! joint angle `θ_j(t)` about the line through bone `j`'s rest `head` along its rest `axis`. The
//! angles interpolate the keys with a periodic cubic Hermite spline whose slopes are the
//! centred differences of the neighbouring keys (Catmull–Rom on non-uniform times, wrapping
//! over the cycle), so the motion is C¹, meets every key, and the frame at `end` is the frame at
//! `start`: the loop closes. [`apply`] writes the pose into the design as `rotate` steps
//! appended to the `transform` of every attached curve and removes `[rig]`, so a design at one
//! time is an ordinary design.

use super::locate;
use crate::formula::short;
use crate::{Error, Result};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The most bones of a rig.
pub const MAX_BONES: usize = 64;
/// The most keys of a bone.
pub const MAX_KEYS: usize = 1024;

/// `[rig]`: the bones and which curve moves with which bone.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RigSpec {
    /// The bones; a parent comes before its children.
    pub bones: Vec<BoneSpec>,
    /// Curve name → bone name.
    #[serde(default)]
    pub attach: BTreeMap<String, String>,
}

/// One hinged bone.
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BoneSpec {
    /// The bone's name (for `parent` and `[rig.attach]`).
    pub name: String,
    /// The bone it hangs from (earlier in the list); none for a root.
    #[serde(default)]
    pub parent: Option<String>,
    /// The joint (rest pose).
    pub head: [f64; 3],
    /// The hinge axis (rest pose; normalised; right-handed).
    pub axis: [f64; 3],
    /// `[t, angle in degrees]` pairs, times increasing within `[start, end)`.
    pub keys: Vec<[f64; 2]>,
}

/// A checked rig.
#[derive(Clone, Debug)]
pub struct Rig {
    bones: Vec<Bone>,
    attach: Vec<(String, usize)>,
    start: f64,
    period: f64,
}

#[derive(Clone, Debug)]
struct Bone {
    parent: Option<usize>,
    head: [f64; 3],
    axis: [f64; 3],
    keys: Vec<[f64; 2]>,
}

impl Rig {
    /// Reads and checks `[rig]` for the cycle `[start, end]` (errors placed in `rig`).
    pub fn new(value: &toml::Value, start: f64, end: f64) -> Result<Rig> {
        let spec = super::deserialize_at::<RigSpec>(value.clone(), "rig")?;
        if spec.bones.is_empty() || spec.bones.len() > MAX_BONES {
            return Err(Error::invalid(format!(
                "give 1 to {MAX_BONES} bones (got {})",
                spec.bones.len()
            ))
            .at("rig.bones"));
        }
        let period = end - start;
        let mut bones: Vec<Bone> = Vec::new();
        for (i, b) in spec.bones.iter().enumerate() {
            let place = format!("rig.bones[{i}]");
            if spec.bones[..i].iter().any(|o| o.name == b.name) {
                return Err(Error::invalid(format!("a second bone named '{}'", b.name))
                    .at(&format!("{place}.name")));
            }
            let parent = match &b.parent {
                None => None,
                Some(p) => Some(
                    spec.bones[..i]
                        .iter()
                        .position(|o| &o.name == p)
                        .ok_or_else(|| {
                            Error::invalid(format!(
                            "no bone '{p}' before this one (a parent comes before its children)"
                        ))
                            .at(&format!("{place}.parent"))
                        })?,
                ),
            };
            // Finite and not all zero (a huge axis such as 1e300 is a direction like any other).
            if !(b.axis.iter().all(|x| x.is_finite()) && b.axis.iter().any(|&x| x != 0.0)) {
                return Err(
                    Error::invalid("must be a non-zero vector").at(&format!("{place}.axis"))
                );
            }
            if b.keys.is_empty() || b.keys.len() > MAX_KEYS {
                return Err(Error::invalid(format!(
                    "give 1 to {MAX_KEYS} keys [t, degrees] (got {})",
                    b.keys.len()
                ))
                .at(&format!("{place}.keys")));
            }
            for (k, key) in b.keys.iter().enumerate() {
                let ok_t = key[0] >= start && key[0] < end && (k == 0 || key[0] > b.keys[k - 1][0]);
                if !ok_t {
                    return Err(Error::invalid(format!(
                        "key times must increase within [time.start, time.end) = [{}, {}) (got \
                         {})",
                        short(start),
                        short(end),
                        short(key[0])
                    ))
                    .at(&format!("{place}.keys[{k}]")));
                }
            }
            bones.push(Bone {
                parent,
                head: b.head,
                axis: {
                    let big = b.axis.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                    let scaled = b.axis.map(|x| x / big);
                    let len = scaled.iter().map(|x| x * x).sum::<f64>().sqrt();
                    scaled.map(|x| x / len)
                },
                keys: b.keys.clone(),
            });
        }
        let mut attach = Vec::new();
        for (curve, bone) in &spec.attach {
            let place = format!("rig.attach.{}", locate::key_path(curve));
            let k = spec
                .bones
                .iter()
                .position(|b| &b.name == bone)
                .ok_or_else(|| Error::invalid(format!("no bone named '{bone}'")).at(&place))?;
            attach.push((curve.clone(), k));
        }
        Ok(Rig {
            bones,
            attach,
            start,
            period,
        })
    }

    /// The joint angle of bone `k` at time `t`, in degrees (periodic over the cycle).
    pub fn angle(&self, k: usize, t: f64) -> f64 {
        let keys = &self.bones[k].keys;
        let n = keys.len();
        if n == 1 {
            return keys[0][1];
        }
        let p = self.period;
        let s = self.start + (t - self.start).rem_euclid(p);
        // The key at or before s (wrapping to the last key of the previous cycle).
        let i = keys.iter().rposition(|k| k[0] <= s);
        // Key `j` of the periodic sequence, as (time, value), for any integer j.
        let key = |j: isize| -> (f64, f64) {
            let m = j.rem_euclid(n as isize) as usize;
            let shift = j.div_euclid(n as isize) as f64 * p;
            (keys[m][0] + shift, keys[m][1])
        };
        let i = match i {
            Some(i) => i as isize,
            None => -1,
        };
        let (t0, y0) = key(i);
        let (t1, y1) = key(i + 1);
        let slope = |j: isize| {
            let (ta, ya) = key(j - 1);
            let (tb, yb) = key(j + 1);
            (yb - ya) / (tb - ta)
        };
        let (m0, m1) = (slope(i), slope(i + 1));
        let h = t1 - t0;
        let x = (s - t0) / h;
        let (x2, x3) = (x * x, x * x * x);
        (2.0 * x3 - 3.0 * x2 + 1.0) * y0
            + (x3 - 2.0 * x2 + x) * h * m0
            + (-2.0 * x3 + 3.0 * x2) * y1
            + (x3 - x2) * h * m1
    }

    /// The rotations that pose a curve of bone `k` at time `t`, in the order they apply:
    /// `(axis, degrees, about)` from bone `k` up to the root.
    pub fn chain(&self, k: usize, t: f64) -> Vec<([f64; 3], f64, [f64; 3])> {
        let mut out = Vec::new();
        let mut b = Some(k);
        while let Some(j) = b {
            out.push((self.bones[j].axis, self.angle(j, t), self.bones[j].head));
            b = self.bones[j].parent;
        }
        out
    }

    /// The names of the attached curves and their bones.
    pub fn attached(&self) -> &[(String, usize)] {
        &self.attach
    }
}

/// Poses the design tree `doc` (numbers already evaluated at `t`) with its `[rig]`, if any:
/// appends the rotations of every attached curve's bone chain to the curve's `transform` and
/// removes `[rig]`. A curve that is missing, or a `derivative` curve (a difference of two
/// curves: attach those), is refused at `rig.attach.<curve>`.
pub fn apply(doc: &mut toml::Value, t: f64, start: f64, end: f64) -> Result<()> {
    let Some(table) = doc.as_table_mut() else {
        return Ok(());
    };
    let Some(rig) = table.remove("rig") else {
        return Ok(());
    };
    let rig = Rig::new(&rig, start, end)?;
    for (curve, bone) in rig.attached() {
        let place = format!("rig.attach.{}", locate::key_path(curve));
        let c = table
            .get_mut("curves")
            .and_then(|c| c.get_mut(curve.as_str()))
            .and_then(|c| c.as_table_mut())
            .ok_or_else(|| Error::invalid(format!("no curve named '{curve}'")).at(&place))?;
        if c.get("type").and_then(|v| v.as_str()) == Some("derivative") {
            return Err(Error::invalid(
                "a derivative curve is a difference of two curves: attach its position and \
                 direction curves instead",
            )
            .at(&place));
        }
        let steps = c
            .entry("transform")
            .or_insert_with(|| toml::Value::Array(Vec::new()));
        let Some(steps) = steps.as_array_mut() else {
            return Err(Error::invalid("transform must be an array of steps")
                .at(&format!("curves.{}.transform", locate::key_path(curve))));
        };
        for (axis, angle, about) in rig.chain(*bone, t) {
            let v3 = |p: [f64; 3]| toml::Value::Array(p.map(toml::Value::Float).to_vec());
            let mut rotate = toml::Table::new();
            rotate.insert("axis".into(), v3(axis));
            rotate.insert("angle".into(), toml::Value::Float(angle));
            rotate.insert("about".into(), v3(about));
            let mut step = toml::Table::new();
            step.insert("rotate".into(), toml::Value::Table(rotate));
            steps.push(toml::Value::Table(step));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rig(keys: &str) -> Rig {
        let text = format!(
            "[[bones]]\nname = \"a\"\nhead = [0, 0, 0]\naxis = [0, 2, 0]\nkeys = {keys}\n\
             [[bones]]\nname = \"b\"\nparent = \"a\"\nhead = [0, 0, 3]\naxis = [1, 0, 0]\n\
             keys = [[0.0, 10.0]]\n[attach]\nc = \"b\"\n"
        );
        let v = toml::Value::Table(toml::from_str(&text).unwrap());
        Rig::new(&v, 0.0, 2.0).unwrap()
    }

    #[test]
    fn angles_meet_the_keys_and_close_the_loop() {
        let r = rig("[[0.0, 0.0], [0.5, 40.0], [1.2, -30.0]]");
        for (t, want) in [(0.0, 0.0), (0.5, 40.0), (1.2, -30.0)] {
            assert_eq!(r.angle(0, t), want, "t = {t}");
        }
        // Periodic: the end of the cycle is its start, and slopes agree across it.
        assert_eq!(r.angle(0, 2.0), r.angle(0, 0.0));
        let h = 1e-6;
        let before = (r.angle(0, 2.0 - h) - r.angle(0, 2.0 - 2.0 * h)) / h;
        let after = (r.angle(0, h) - r.angle(0, 0.0)) / h;
        assert!(
            (before - after).abs() < 1e-3 * (1.0 + after.abs()),
            "{before} {after}"
        );
        // Continuous slope at an inner key.
        let l = (r.angle(0, 0.5) - r.angle(0, 0.5 - h)) / h;
        let rr = (r.angle(0, 0.5 + h) - r.angle(0, 0.5)) / h;
        assert!((l - rr).abs() < 1e-3 * (1.0 + l.abs()), "{l} {rr}");
        // One key: constant.
        assert_eq!(r.angle(1, 0.7), 10.0);
        // The chain of b: its own hinge first, then a's.
        let c = r.chain(1, 0.5);
        assert_eq!(c.len(), 2);
        assert_eq!(c[0], ([1.0, 0.0, 0.0], 10.0, [0.0, 0.0, 3.0]));
        assert_eq!(c[1], ([0.0, 1.0, 0.0], 40.0, [0.0, 0.0, 0.0]));
    }

    /// A huge axis is a direction like any other: scaled before it is normalised.
    #[test]
    fn huge_axes_are_normalised_without_overflow() {
        let text = "[[bones]]\nname = \"a\"\nhead = [0, 0, 0]\naxis = [0, 1e300, 1e300]\n\
                    keys = [[0.0, 5.0]]\n[attach]\nc = \"a\"\n";
        let v = toml::Value::Table(toml::from_str(text).unwrap());
        let r = Rig::new(&v, 0.0, 2.0).unwrap();
        let h = 0.5f64.sqrt();
        let axis = r.chain(0, 0.0)[0].0;
        assert!(
            (axis[1] - h).abs() < 1e-15 && (axis[2] - h).abs() < 1e-15 && axis[0] == 0.0,
            "{axis:?}"
        );
    }

    #[test]
    fn bad_rigs_are_refused_with_their_place() {
        let bad = |text: &str| {
            let v = toml::Value::Table(toml::from_str(text).unwrap());
            Rig::new(&v, 0.0, 1.0).unwrap_err().place().to_string()
        };
        let bone = "name = \"a\"\nhead = [0, 0, 0]\naxis = [0, 1, 0]\n";
        assert_eq!(
            bad(&format!(
                "[[bones]]\n{bone}keys = [[0.5, 1.0], [0.2, 2.0]]\n"
            )),
            "rig.bones[0].keys[1]"
        );
        assert_eq!(
            bad(&format!("[[bones]]\n{bone}keys = [[1.0, 1.0]]\n")),
            "rig.bones[0].keys[0]"
        );
        assert_eq!(
            bad("[[bones]]\nname = \"a\"\nhead = [0, 0, 0]\naxis = [0, 0, 0]\nkeys = [[0, 1]]\n"),
            "rig.bones[0].axis"
        );
        assert_eq!(
            bad(&format!(
                "[[bones]]\n{bone}parent = \"z\"\nkeys = [[0, 1]]\n"
            )),
            "rig.bones[0].parent"
        );
        assert_eq!(
            bad(&format!(
                "[[bones]]\n{bone}keys = [[0, 1]]\n[attach]\nc = \"z\"\n"
            )),
            "rig.attach.c"
        );
    }
}
