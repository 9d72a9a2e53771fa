//! The animation as glTF 2.0 binary: one mesh whose morph targets are the frames, with animated
//! weights.
//!
//! Why morph targets: Blender imports them as shape keys with an action on their values, and
//! three.js as `morphTargetInfluences` driven by an `AnimationMixer`, so the file plays in both
//! without a plug-in; linear interpolation of one-hot weights between neighbouring keys is the
//! linear interpolation of the two frames' vertices, so playback is smooth between frames. The
//! alternative, one node per frame with animated scale (visibility), plays too but jumps from
//! frame to frame and repeats the triangles in every frame.

use super::frames::Keyframes;
use crate::mesh_write::MeshInfo;
use crate::{Error, Result};
use std::io::Write;

const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const GLB_MAGIC: u32 = 0x4654_6C67;
const GLB_JSON: u32 = 0x4E4F_534A;
const GLB_BIN: u32 = 0x004E_4942;

/// glTF's frame: metres, `+Y` up (`(x, y, z) → (x, z, −y)`), as [`crate::mesh_write::write_glb`].
fn to_gltf(p: [f32; 3], k: f64) -> [f64; 3] {
    let q = p.map(f64::from);
    [q[0] * k, q[2] * k, -q[1] * k]
}

/// Little-endian bytes of the binary chunk, with one buffer view per accessor.
#[derive(Default)]
struct Bin {
    bytes: Vec<u8>,
    views: Vec<serde_json::Value>,
}

impl Bin {
    /// Appends `len` bytes that `fill` writes (a view of its own).
    fn view_with(
        &mut self,
        len: usize,
        target: Option<u32>,
        fill: impl FnOnce(&mut [u8]),
    ) -> usize {
        let start = self.bytes.len();
        self.bytes.resize(start + len, 0);
        fill(&mut self.bytes[start..]);
        let mut v = serde_json::json!({
            "buffer": 0, "byteOffset": start, "byteLength": len,
        });
        if let Some(t) = target {
            v["target"] = t.into();
        }
        self.views.push(v);
        self.views.len() - 1
    }

    fn view(&mut self, data: impl Iterator<Item = [u8; 4]>, target: Option<u32>) -> usize {
        let data: Vec<[u8; 4]> = data.collect();
        self.view_with(4 * data.len(), target, |out| {
            for (o, b) in out.chunks_exact_mut(4).zip(&data) {
                o.copy_from_slice(b);
            }
        })
    }
}

/// A view of `data` as little-endian f32 and its VEC3 accessor (with its bounds when asked).
fn vec3_accessor(
    bin: &mut Bin,
    accessors: &mut Vec<serde_json::Value>,
    data: &[[f32; 3]],
    with_bounds: bool,
) -> usize {
    let view = bin.view_with(12 * data.len(), Some(ARRAY_BUFFER), |out| {
        for (o, x) in out.chunks_exact_mut(4).zip(data.iter().flatten()) {
            o.copy_from_slice(&x.to_le_bytes());
        }
    });
    let mut a = serde_json::json!({
        "bufferView": view, "componentType": FLOAT, "count": data.len(), "type": "VEC3",
    });
    if with_bounds {
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for p in data {
            for c in 0..3 {
                lo[c] = lo[c].min(p[c]);
                hi[c] = hi[c].max(p[c]);
            }
        }
        a["min"] = serde_json::json!(lo);
        a["max"] = serde_json::json!(hi);
    }
    accessors.push(a);
    accessors.len() - 1
}

/// An animation's `.glb` built frame by frame as the frames come (see [`write_glb`] for what
/// it holds): the first frame is the mesh, every later frame's differences from it go straight
/// into the binary chunk, and [`GlbFrames::finish`] writes the file. The glTF JSON, which
/// comes first in the file, holds every morph target's bounds, so nothing can be written
/// before the last frame without changing the file.
pub struct GlbFrames {
    /// Metres per design unit, times the scale.
    k: f64,
    /// The first frame in glTF's frame (positions in metres), in f64.
    base: Vec<[f64; 3]>,
    base_n: Vec<[f64; 3]>,
    bin: Bin,
    accessors: Vec<serde_json::Value>,
    targets: Vec<serde_json::Value>,
    /// The frames expected (for the size of the buffer and the messages) and pushed.
    expected: usize,
    frames: usize,
    /// Buffers of one frame's differences.
    dp: Vec<[f32; 3]>,
    dn: Vec<[f32; 3]>,
}

impl GlbFrames {
    /// Starts the file with the first frame (`positions` and `normals` in design coordinates,
    /// scaled to metres by `info`), for an animation of `expected` frames.
    pub fn new(
        info: &MeshInfo,
        triangles: &[[u32; 3]],
        positions: &[[f32; 3]],
        normals: &[[f32; 3]],
        expected: usize,
    ) -> Result<Self> {
        if triangles.is_empty() {
            return Err(Error::invalid("the animation has no frame with triangles"));
        }
        if !(info.scale.is_finite() && info.scale > 0.0) {
            return Err(Error::invalid("must be finite and positive").at("scale"));
        }
        let k = info.scale * info.units.metres();
        let nv = positions.len();
        let mut bin = Bin::default();
        // Every frame's positions and normals, the indices and the keys' times and weights.
        let frame_bytes = 24 * nv as u64;
        let want = frame_bytes * expected.max(1) as u64
            + 12 * triangles.len() as u64
            + 4 * (expected as u64 + 1) * (expected as u64 + 1);
        if want <= u32::MAX as u64 / 2 {
            // Only a hint: where it fails the buffer grows as it goes.
            let _ = bin.bytes.try_reserve_exact(want as usize);
        }
        let base: Vec<[f64; 3]> = positions.iter().map(|&p| to_gltf(p, k)).collect();
        let base_n: Vec<[f64; 3]> = normals.iter().map(|&m| to_gltf(m, 1.0)).collect();
        let narrow =
            |v: &[[f64; 3]]| -> Vec<[f32; 3]> { v.iter().map(|p| p.map(|c| c as f32)).collect() };
        let mut accessors = Vec::new();
        vec3_accessor(&mut bin, &mut accessors, &narrow(&base), true);
        vec3_accessor(&mut bin, &mut accessors, &narrow(&base_n), false);
        let view = bin.view_with(12 * triangles.len(), Some(ELEMENT_ARRAY_BUFFER), |out| {
            for (o, i) in out.chunks_exact_mut(4).zip(triangles.iter().flatten()) {
                o.copy_from_slice(&i.to_le_bytes());
            }
        });
        accessors.push(serde_json::json!({
            "bufferView": view, "componentType": UNSIGNED_INT,
            "count": 3 * triangles.len(), "type": "SCALAR",
        }));
        Ok(GlbFrames {
            k,
            base,
            base_n,
            bin,
            accessors,
            targets: Vec::with_capacity(expected.saturating_sub(1)),
            expected,
            frames: 1,
            dp: Vec::new(),
            dn: Vec::new(),
        })
    }

    /// Adds the next frame (a morph target: its differences from the first frame).
    pub fn push(&mut self, positions: &[[f32; 3]], normals: &[[f32; 3]]) -> Result<()> {
        if positions.len() != self.base.len() || normals.len() != self.base_n.len() {
            return Err(Error::invalid(format!(
                "frame {} has {} vertices, the first {}",
                self.frames,
                positions.len(),
                self.base.len()
            )));
        }
        let k = self.k;
        self.dp.clear();
        self.dp
            .extend(positions.iter().zip(&self.base).map(|(&p, b)| {
                let a = to_gltf(p, k);
                [
                    (a[0] - b[0]) as f32,
                    (a[1] - b[1]) as f32,
                    (a[2] - b[2]) as f32,
                ]
            }));
        self.dn.clear();
        self.dn
            .extend(normals.iter().zip(&self.base_n).map(|(&p, b)| {
                let a = to_gltf(p, 1.0);
                [
                    (a[0] - b[0]) as f32,
                    (a[1] - b[1]) as f32,
                    (a[2] - b[2]) as f32,
                ]
            }));
        let p = vec3_accessor(&mut self.bin, &mut self.accessors, &self.dp, true);
        let q = vec3_accessor(&mut self.bin, &mut self.accessors, &self.dn, false);
        self.targets
            .push(serde_json::json!({ "POSITION": p, "NORMAL": q }));
        if self.bin.bytes.len() as u64 > u32::MAX as u64 / 2 {
            return Err(Error::invalid(format!(
                "the animation would exceed the 2 GiB a .glb holds (at frame {} of {}); use \
                 fewer frames or a smaller grid (--nu, --nv)",
                self.frames,
                self.expected.max(self.frames + 1)
            )));
        }
        self.frames += 1;
        Ok(())
    }

    /// The vertices of a frame.
    pub fn vertices(&self) -> usize {
        self.base.len()
    }

    /// Writes the file: the frames pushed, played at `keys.times` (`keys` gives the times,
    /// the loop, the title and whether the mesh is closed; its vertices are not read).
    pub fn finish(self, keys: &Keyframes, info: &MeshInfo, w: &mut dyn Write) -> Result<()> {
        use serde_json::json;
        let GlbFrames {
            mut bin,
            mut accessors,
            targets,
            frames: n,
            ..
        } = self;
        if keys.times.len() != n {
            return Err(Error::invalid(format!(
                "{} frames and {} times",
                n,
                keys.times.len()
            )));
        }
        let (pos, nrm, idx) = (0, 1, 2);
        let title = info
            .title
            .clone()
            .or_else(|| keys.title.clone())
            .unwrap_or_else(|| "pdeshape".to_string());
        let mut primitive = json!({
            "attributes": { "POSITION": pos, "NORMAL": nrm },
            "indices": idx, "mode": 4, "material": 0,
        });
        let mut mesh = json!({ "name": title, "primitives": [] });
        let mut animations = Vec::new();
        let m = targets.len();
        if m > 0 {
            primitive["targets"] = json!(targets);
            mesh["weights"] = json!(vec![0.0; m]);
            let t0 = keys.times[0];
            let mut times: Vec<f32> = keys.times.iter().map(|t| (t - t0) as f32).collect();
            let mut frame_of_key: Vec<usize> = (0..n).collect();
            if keys.looped {
                times.push(keys.period as f32);
                frame_of_key.push(0);
            }
            let input_view = bin.view(times.iter().map(|t| t.to_le_bytes()), None);
            accessors.push(json!({
                "bufferView": input_view, "componentType": FLOAT, "count": times.len(),
                "type": "SCALAR", "min": [times[0]], "max": [times[times.len() - 1]],
            }));
            let input = accessors.len() - 1;
            let weights = frame_of_key.iter().flat_map(|&f| {
                (1..=m).map(move |j| if j == f { 1f32 } else { 0f32 }.to_le_bytes())
            });
            let output_view = bin.view(weights, None);
            accessors.push(json!({
                "bufferView": output_view, "componentType": FLOAT,
                "count": times.len() * m, "type": "SCALAR",
            }));
            let output = accessors.len() - 1;
            animations.push(json!({
                "name": "frames",
                "samplers": [ { "input": input, "output": output, "interpolation": "LINEAR" } ],
                "channels": [ { "sampler": 0, "target": { "node": 1, "path": "weights" } } ],
            }));
        }
        mesh["primitives"] = json!([primitive]);
        let mut extras = json!({
            "units": "m",
            "design_units": info.units.as_str(),
            "scale": info.scale,
            "frames": n,
            "times": keys.times,
            "loop": keys.looped,
        });
        if let Some(t) = &info.title {
            extras["title"] = json!(t);
        }
        let mut doc = json!({
            "asset": {
                "version": "2.0",
                "generator": concat!("pdeshape ", env!("CARGO_PKG_VERSION")),
                "extras": extras,
            },
            "scene": 0,
            "scenes": [ { "name": title, "nodes": [0] } ],
            "nodes": [ { "name": title, "children": [1] }, { "name": "surface", "mesh": 0 } ],
            "meshes": [mesh],
            "materials": [crate::mesh_write::glb_material(!keys.closed)],
            "accessors": accessors,
            "bufferViews": bin.views,
            "buffers": [ { "byteLength": bin.bytes.len() } ],
        });
        if !animations.is_empty() {
            doc["animations"] = json!(animations);
        }
        let mut json_bytes =
            serde_json::to_vec(&doc).map_err(|e| Error::io(format!("writing glTF JSON: {e}")))?;
        while json_bytes.len() % 4 != 0 {
            json_bytes.push(b' ');
        }
        let mut data = bin.bytes;
        while data.len() % 4 != 0 {
            data.push(0);
        }
        let total = 12 + 8 + json_bytes.len() + 8 + data.len();
        let total = u32::try_from(total)
            .map_err(|_| Error::invalid("the animation exceeds the 4 GiB a .glb holds"))?;
        let io = |e: std::io::Error| Error::io_from(format!("writing GLB: {e}"), e);
        w.write_all(&GLB_MAGIC.to_le_bytes()).map_err(io)?;
        w.write_all(&2u32.to_le_bytes()).map_err(io)?;
        w.write_all(&total.to_le_bytes()).map_err(io)?;
        w.write_all(&(json_bytes.len() as u32).to_le_bytes())
            .map_err(io)?;
        w.write_all(&GLB_JSON.to_le_bytes()).map_err(io)?;
        w.write_all(&json_bytes).map_err(io)?;
        w.write_all(&(data.len() as u32).to_le_bytes())
            .map_err(io)?;
        w.write_all(&GLB_BIN.to_le_bytes()).map_err(io)?;
        w.write_all(&data).map_err(io)?;
        Ok(())
    }
}

/// Writes the keyframes as a `.glb`: frame 0 is the mesh, frame `k ≥ 1` is morph target `k − 1`
/// (position and normal differences from frame 0), and one animation sets the weights at the
/// frames' times (seconds from the first frame) to frame `k`'s one-hot vector, interpolated
/// linearly. A looped animation has one more key, at the period, back at frame 0, so it repeats
/// without a jump. Positions are scaled to metres (`info.units`, `info.scale`). The same file as
/// pushing the frames through [`GlbFrames`].
pub fn write_glb(keys: &Keyframes, info: &MeshInfo, w: &mut dyn Write) -> Result<()> {
    let n = keys.positions.len();
    if n == 0 || keys.triangles.is_empty() {
        return Err(Error::invalid("the animation has no frame with triangles"));
    }
    let mut glb = GlbFrames::new(
        info,
        &keys.triangles,
        &keys.positions[0],
        &keys.normals[0],
        n,
    )?;
    for f in 1..n {
        glb.push(&keys.positions[f], &keys.normals[f])?;
    }
    glb.finish(keys, info, w)
}
