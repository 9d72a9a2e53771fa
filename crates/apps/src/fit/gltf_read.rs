//! glTF 2.0 meshes (`.glb`, and `.gltf` JSON whose buffers are data URIs or files beside it)
//! read for fitting: every triangle primitive of every node of the default scene (the first
//! scene when none is the default, every mesh untransformed when the file has no scene), each
//! with its node's world transform, as one part of the mesh ([`super::InputMesh::read_report`]
//! welds the parts by position). The `gltf` crate parses and checks the JSON; the GLB container
//! and the accessors' bytes are read here, every range checked, so a damaged file is refused
//! with the place it names (`meshes[2].primitives[0]`, `accessors[5]`, `buffers[0]`).
//!
//! glTF is +Y up and in metres: positions are read in the scene's frame, and their
//! [`FileFrame`] turns them to +Z up by the inverse of the GLB writer's turn (`(x, y, z)` of the
//! file is `(x, −z, y)` of the design), in metres unless the file's `asset.extras` name the
//! design's units (`design_units`, as pdeshape's GLB writer records them): the mesh is then in
//! those units.

use super::frame::FileFrame;
use super::mesh::{check_count, check_memory, External};
use crate::spec::Units;
use crate::{Error, Result, Vec3};
use gltf::accessor::{DataType, Dimensions};
use gltf::mesh::Mode;
use nalgebra::{Matrix3, Matrix4, Quaternion, UnitQuaternion, Vector3};
use std::borrow::Cow;
use std::collections::HashMap;

/// What a glTF file gave: the positions and triangles of all its parts, in the design's frame.
pub(super) struct GltfMesh {
    /// Positions in the file's frame: the scene's, once each node's transform is applied
    /// (metres, +Y up).
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
    /// Triangle primitives read (each a part).
    pub parts: usize,
    /// The design's unit: metres, or the units the file's extras state.
    pub units: Units,
    /// How the positions become the design's.
    pub frame: FileFrame,
    /// What was converted or skipped, for the read's note.
    pub notes: Vec<String>,
}

fn bad(what: impl std::fmt::Display) -> Error {
    Error::invalid(format!("not a readable glTF file: {what}"))
}

const GLB_JSON: u32 = 0x4E4F_534A;
const GLB_BIN: u32 = 0x004E_4942;

/// The JSON and (if any) the binary chunk of a GLB file.
fn split_glb(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>)> {
    let word = |at: usize| -> Option<u32> {
        let b = bytes.get(at..at + 4)?;
        Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    let (Some(version), Some(length)) = (word(4), word(8)) else {
        return Err(bad(format!(
            "the GLB file is truncated: {} bytes, fewer than its 12-byte header",
            bytes.len()
        )));
    };
    if version != 2 {
        return Err(bad(format!(
            "GLB version {version}: only version 2 is read"
        )));
    }
    let length = length as usize;
    if length > bytes.len() {
        return Err(bad(format!(
            "the GLB file is truncated: its header announces {length} bytes, the file has {}",
            bytes.len()
        )));
    }
    if length < 20 {
        return Err(bad(format!(
            "the GLB header announces {length} bytes, too few for a JSON chunk"
        )));
    }
    let bytes = &bytes[..length];
    let mut at = 12;
    let mut json = None;
    let mut bin = None;
    while at < length {
        let (Some(len), Some(kind)) = (word(at), word(at + 4)) else {
            return Err(bad(format!(
                "the GLB file is truncated: a chunk header at byte {at} runs past its {length} bytes"
            )));
        };
        let start = at + 8;
        let end = start
            .checked_add(len as usize)
            .filter(|&e| e <= length)
            .ok_or_else(|| {
                bad(format!(
                    "the GLB file is truncated: the chunk at byte {at} announces {len} bytes, \
                     past the end of the file ({length} bytes)"
                ))
            })?;
        let data = &bytes[start..end];
        match (kind, json.is_none()) {
            (GLB_JSON, true) => json = Some(data),
            (_, true) => {
                return Err(bad(
                    "the GLB file's first chunk is not its JSON (type `JSON`)",
                ))
            }
            (GLB_BIN, false) if bin.is_none() => bin = Some(data),
            // Chunks of other types are skipped, as the specification says.
            _ => {}
        }
        at = end;
    }
    let json = json.ok_or_else(|| bad("the GLB file has no JSON chunk"))?;
    Ok((json, bin))
}

/// The gltf crate's validation error in words.
fn validation_words(e: &gltf::json::validation::Error) -> &'static str {
    use gltf::json::validation::Error as V;
    match e {
        V::IndexOutOfBounds => "refers to an item the file does not have",
        V::Invalid => "is not a valid value",
        V::Missing => "is missing",
        V::Oversize => "is too large",
        V::Unsupported => "names an extension that is not read",
    }
}

/// The parsed and checked document.
fn document(json: &[u8]) -> Result<gltf::Document> {
    let root = gltf::json::Root::from_slice(json).map_err(|e| {
        bad(crate::spec::words::shorten_quoted(&format!(
            "the JSON: {e}"
        )))
    })?;
    // The crate's check of a primitive's POSITION looks its accessor up before the index is
    // checked: an index past the accessors is refused here.
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            let key = gltf::json::validation::Checked::Valid(gltf::Semantic::Positions);
            if let Some(i) = prim.attributes.get(&key) {
                if i.value() >= root.accessors.len() {
                    return Err(bad(format!(
                        "meshes[{m}].primitives[{p}]: POSITION refers to accessors[{}], but the \
                         file has {} accessors",
                        i.value(),
                        root.accessors.len()
                    )));
                }
            }
        }
    }
    gltf::Document::from_json(root).map_err(|e| match e {
        gltf::Error::Validation(list) => {
            let more = match list.len() {
                0 | 1 => String::new(),
                n => format!(" (and {} more problems)", n - 1),
            };
            match list.first() {
                Some((path, err)) => bad(format!("{path}: {}{more}", validation_words(err))),
                None => bad("the document does not pass the glTF checks"),
            }
        }
        other => bad(other),
    })
}

/// `asset.extras.design_units` (pdeshape's GLB writer records the design's units there).
fn design_units(json: &[u8]) -> Option<Units> {
    #[derive(serde::Deserialize)]
    struct Head {
        asset: Asset,
    }
    #[derive(serde::Deserialize)]
    struct Asset {
        #[serde(default)]
        extras: Option<serde_json::Value>,
    }
    let head: Head = serde_json::from_slice(json).ok()?;
    let units = head
        .asset
        .extras?
        .get("design_units")?
        .as_str()?
        .to_string();
    Units::parse(&units).ok()
}

/// A `data:` URI's bytes (base64 only).
fn data_uri(uri: &str) -> Option<std::result::Result<Vec<u8>, String>> {
    let rest = uri.strip_prefix("data:")?;
    Some(match rest.split_once(',') {
        Some((head, body)) if head.ends_with(";base64") => {
            base64(body).ok_or_else(|| "the data URI is not valid base64".to_string())
        }
        _ => Err("the data URI is not base64 (`data:…;base64,…`)".to_string()),
    })
}

/// Standard or URL-safe base64, padding optional (the `base64` crate).
fn base64(text: &str) -> Option<Vec<u8>> {
    use base64::engine::general_purpose::{GeneralPurpose, GeneralPurposeConfig};
    use base64::engine::DecodePaddingMode;
    use base64::{alphabet, Engine};
    let config = GeneralPurposeConfig::new()
        .with_decode_padding_mode(DecodePaddingMode::Indifferent)
        .with_decode_allow_trailing_bits(true);
    [alphabet::STANDARD, alphabet::URL_SAFE]
        .iter()
        .find_map(|a| GeneralPurpose::new(a, config).decode(text).ok())
}

/// A relative URI's path, percent-decoded; `None` for a URI with a scheme or an absolute path.
fn relative_path(uri: &str) -> Option<String> {
    let scheme_end = uri.find(':');
    let first_sep = uri.find(['/', '?', '#']);
    if let Some(c) = scheme_end {
        if first_sep.is_none_or(|s| c < s) {
            return None;
        }
    }
    if uri.starts_with('/') || uri.starts_with('\\') {
        return None;
    }
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut k = 0;
    while k < bytes.len() {
        if bytes[k] == b'%' {
            let hex = std::str::from_utf8(bytes.get(k + 1..k + 3)?).ok()?;
            out.push(u8::from_str_radix(hex, 16).ok()?);
            k += 3;
        } else {
            out.push(bytes[k]);
            k += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// The data of every buffer the mesh's accessors use (`None` for the others).
fn load_buffers<'b>(
    doc: &gltf::Document,
    blob: Option<&'b [u8]>,
    used: &[bool],
    external: &External<'_>,
) -> Result<Vec<Option<Cow<'b, [u8]>>>> {
    let mut out = Vec::new();
    for buffer in doc.buffers() {
        let k = buffer.index();
        if !used.get(k).copied().unwrap_or(false) {
            out.push(None);
            continue;
        }
        let data: Cow<'b, [u8]> = match buffer.source() {
            gltf::buffer::Source::Bin => Cow::Borrowed(blob.ok_or_else(|| {
                bad(format!(
                    "buffers[{k}]: refers to the GLB binary chunk, but the file has none"
                ))
            })?),
            gltf::buffer::Source::Uri(uri) => match data_uri(uri) {
                Some(decoded) => {
                    Cow::Owned(decoded.map_err(|e| bad(format!("buffers[{k}]: {e}")))?)
                }
                None => {
                    let shown = crate::spec::words::user_text(uri);
                    let path = relative_path(uri).ok_or_else(|| {
                        bad(format!(
                            "buffers[{k}]: '{shown}' is not a file beside the glTF file (only \
                             relative paths and data URIs are read)"
                        ))
                    })?;
                    Cow::Owned(
                        external(&path).map_err(|e| bad(format!("buffers[{k}]: {shown}: {e}")))?,
                    )
                }
            },
        };
        if data.len() < buffer.length() {
            return Err(bad(format!(
                "buffers[{k}]: declares {} bytes, its data has {}",
                buffer.length(),
                data.len()
            )));
        }
        out.push(Some(data));
    }
    Ok(out)
}

/// The elements of an accessor, their bytes checked to lie in its buffer.
struct Elements<'b> {
    data: &'b [u8],
    stride: usize,
    count: usize,
    ty: DataType,
    normalized: bool,
}

impl Elements<'_> {
    /// Component `c` of element `k` (in range: checked when the accessor was opened).
    fn get(&self, k: usize, c: usize) -> f64 {
        let size = self.ty.size();
        let at = k * self.stride + c * size;
        let b = &self.data[at..at + size];
        let n = self.normalized;
        match self.ty {
            DataType::F32 => f32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            DataType::U32 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as f64,
            DataType::I8 => {
                let v = b[0] as i8 as f64;
                if n {
                    (v / 127.0).max(-1.0)
                } else {
                    v
                }
            }
            DataType::U8 => {
                let v = b[0] as f64;
                if n {
                    v / 255.0
                } else {
                    v
                }
            }
            DataType::I16 => {
                let v = i16::from_le_bytes([b[0], b[1]]) as f64;
                if n {
                    (v / 32767.0).max(-1.0)
                } else {
                    v
                }
            }
            DataType::U16 => {
                let v = u16::from_le_bytes([b[0], b[1]]) as f64;
                if n {
                    v / 65535.0
                } else {
                    v
                }
            }
        }
    }

    fn index(&self, k: usize) -> u64 {
        self.get(k, 0) as u64
    }
}

/// Opens accessor `a` as `want` elements, every byte it reads checked to lie in its view and
/// the view in its buffer.
fn elements<'b>(
    a: &gltf::Accessor,
    want: Dimensions,
    buffers: &'b [Option<Cow<'_, [u8]>>],
) -> Result<Elements<'b>> {
    let k = a.index();
    let here = |what: String| bad(format!("accessors[{k}]: {what}"));
    if a.sparse().is_some() {
        return Err(here("sparse accessors are not read".into()));
    }
    if a.dimensions() != want {
        return Err(here(format!(
            "its type is {:?}, not {want:?}",
            a.dimensions()
        )));
    }
    let view = a.view().ok_or_else(|| here("has no bufferView".into()))?;
    let v = view.index();
    let comps = want.multiplicity();
    let size = comps * a.data_type().size();
    let stride = view.stride().unwrap_or(size);
    if stride < size {
        return Err(bad(format!(
            "bufferViews[{v}]: its byteStride {stride} is less than the {size} bytes of an \
             element of accessors[{k}]"
        )));
    }
    let b = view.buffer().index();
    let data: &[u8] = buffers
        .get(b)
        .and_then(|d| d.as_deref())
        .ok_or_else(|| bad(format!("buffers[{b}]: its data was not read")))?;
    let view_end = view
        .offset()
        .checked_add(view.length())
        .filter(|&e| e <= data.len())
        .ok_or_else(|| {
            bad(format!(
                "bufferViews[{v}]: bytes {} to {} lie past the end of buffers[{b}] ({} bytes)",
                view.offset(),
                view.offset() as u128 + view.length() as u128,
                data.len()
            ))
        })?;
    let count = a.count();
    let span = if count == 0 {
        Some(0)
    } else {
        (count - 1)
            .checked_mul(stride)
            .and_then(|x| x.checked_add(size))
    };
    let start = view.offset() + a.offset();
    let end = span
        .and_then(|s| start.checked_add(s))
        .filter(|&e| e <= view_end)
        .ok_or_else(|| {
            here(format!(
                "{count} elements from byte {} of bufferViews[{v}] run past its {} bytes",
                a.offset(),
                view.length()
            ))
        })?;
    Ok(Elements {
        data: &data[start..end],
        stride,
        count,
        ty: a.data_type(),
        normalized: a.normalized(),
    })
}

/// A node's local transform in double precision.
fn local(node: &gltf::Node) -> Result<Matrix4<f64>> {
    let m = match node.transform() {
        gltf::scene::Transform::Matrix { matrix } => Matrix4::from_fn(|r, c| matrix[c][r] as f64),
        gltf::scene::Transform::Decomposed {
            translation: t,
            rotation: q,
            scale: s,
        } => {
            let q = Quaternion::new(q[3] as f64, q[0] as f64, q[1] as f64, q[2] as f64);
            let norm = q.norm();
            if !(norm.is_finite() && norm > 1e-6) {
                return Err(bad(format!(
                    "nodes[{}]: its rotation is not a unit quaternion",
                    node.index()
                )));
            }
            let r = UnitQuaternion::from_quaternion(q).to_homogeneous();
            let s = Matrix4::new_nonuniform_scaling(&Vector3::new(
                s[0] as f64,
                s[1] as f64,
                s[2] as f64,
            ));
            let t = Matrix4::new_translation(&Vector3::new(t[0] as f64, t[1] as f64, t[2] as f64));
            t * r * s
        }
    };
    if !m.iter().all(|x| x.is_finite()) {
        return Err(bad(format!(
            "nodes[{}]: its transform has a number that is not finite",
            node.index()
        )));
    }
    Ok(m)
}

/// One mesh placed in the scene: by a node (its world transform) or, in a file without a
/// scene, as it is.
struct Placed {
    node: Option<usize>,
    mesh: usize,
    world: Matrix4<f64>,
}

/// The meshes of the scene, each with its node's world transform, in the order of a
/// depth-first walk of the scene's nodes.
fn placed(doc: &gltf::Document) -> Result<(Vec<Placed>, String)> {
    let scene = doc.default_scene().or_else(|| doc.scenes().next());
    let Some(scene) = scene else {
        let all = doc
            .meshes()
            .map(|m| Placed {
                node: None,
                mesh: m.index(),
                world: Matrix4::identity(),
            })
            .collect();
        return Ok((all, "every mesh (the file has no scene)".to_string()));
    };
    let mut seen = vec![false; doc.nodes().len()];
    let mut out = Vec::new();
    let mut stack: Vec<(gltf::Node, Matrix4<f64>)> =
        scene.nodes().map(|n| (n, Matrix4::identity())).collect();
    stack.reverse();
    while let Some((node, parent)) = stack.pop() {
        let k = node.index();
        match seen.get_mut(k) {
            Some(s) if !*s => *s = true,
            _ => {
                return Err(bad(format!(
                    "nodes[{k}]: reached twice from scenes[{}] (a node has one parent and the \
                     hierarchy no cycle)",
                    scene.index()
                )))
            }
        }
        let world = parent * local(&node)?;
        if let Some(m) = node.mesh() {
            out.push(Placed {
                node: Some(k),
                mesh: m.index(),
                world,
            });
        }
        let children: Vec<gltf::Node> = node.children().collect();
        for c in children.into_iter().rev() {
            stack.push((c, world));
        }
    }
    Ok((out, format!("scenes[{}]", scene.index())))
}

/// A triangle primitive to read.
struct Plan<'d> {
    place: String,
    node: Option<usize>,
    world: Matrix4<f64>,
    positions: gltf::Accessor<'d>,
    indices: Option<gltf::Accessor<'d>>,
    mode: Mode,
}

impl Plan<'_> {
    /// The number of corners the primitive's mode turns into triangles.
    fn corners(&self) -> usize {
        self.indices
            .as_ref()
            .map_or(self.positions.count(), |i| i.count())
    }

    fn triangle_count(&self) -> usize {
        let n = self.corners();
        match self.mode {
            Mode::Triangles => n / 3,
            _ => n.saturating_sub(2),
        }
    }
}

fn mode_words(mode: Mode) -> &'static str {
    match mode {
        Mode::Points => "points",
        Mode::Lines => "lines",
        Mode::LineLoop => "a line loop",
        Mode::LineStrip => "a line strip",
        Mode::Triangles => "triangles",
        Mode::TriangleStrip => "a triangle strip",
        Mode::TriangleFan => "a triangle fan",
    }
}

/// Reads a glTF file: `.glb` bytes, or `.gltf` JSON whose external buffers `external` reads.
pub(super) fn read_gltf(bytes: &[u8], external: &External<'_>) -> Result<GltfMesh> {
    let (json, blob) = if bytes.starts_with(b"glTF") {
        split_glb(bytes)?
    } else if bytes.trim_ascii_start().starts_with(b"{") {
        (bytes, None)
    } else {
        let head: String = bytes
            .iter()
            .take(4)
            .map(|&b| if b.is_ascii_graphic() { b as char } else { '.' })
            .collect();
        return Err(bad(format!(
            "the file starts with '{head}': neither a GLB (magic 'glTF') nor glTF JSON ('{{')"
        )));
    };
    let doc = document(json)?;
    let units = design_units(json);
    let (placed, from) = placed(&doc)?;
    let mut plans = Vec::new();
    let mut skipped = Vec::new();
    let meshes: Vec<gltf::Mesh> = doc.meshes().collect();
    for p in &placed {
        let Some(mesh) = meshes.get(p.mesh) else {
            continue;
        };
        for prim in mesh.primitives() {
            let place = format!("meshes[{}].primitives[{}]", p.mesh, prim.index());
            match prim.mode() {
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan => {}
                other => {
                    skipped.push(format!("{place} ({})", mode_words(other)));
                    continue;
                }
            }
            let positions = prim
                .get(&gltf::Semantic::Positions)
                .ok_or_else(|| bad(format!("{place}: has no POSITION")))?;
            plans.push(Plan {
                place,
                node: p.node,
                world: p.world,
                positions,
                indices: prim.indices(),
                mode: prim.mode(),
            });
        }
    }
    if plans.is_empty() {
        return Err(bad(if skipped.is_empty() {
            format!("{from} has no mesh")
        } else {
            format!(
                "no primitive of triangles in {from}: {}",
                shortened(&skipped)
            )
        }));
    }
    for plan in &plans {
        if plan.mode == Mode::Triangles && plan.corners() % 3 != 0 {
            return Err(bad(format!(
                "{}: {} {}, not a multiple of 3 for triangles",
                plan.place,
                plan.corners(),
                if plan.indices.is_some() {
                    "indices"
                } else {
                    "vertices"
                }
            )));
        }
    }
    // Sizes before anything is stored.
    let total = plans
        .iter()
        .fold(0usize, |n, p| n.saturating_add(p.triangle_count()));
    check_count(total)?;
    let vertices = plans
        .iter()
        .fold(0usize, |n, p| n.saturating_add(p.positions.count()));
    check_memory(bytes, total.saturating_add(vertices))?;
    let mut used = vec![false; doc.buffers().len()];
    for plan in &plans {
        for a in std::iter::once(&plan.positions).chain(&plan.indices) {
            if let Some(v) = a.view() {
                if let Some(u) = used.get_mut(v.buffer().index()) {
                    *u = true;
                }
            }
        }
    }
    let buffers = load_buffers(&doc, blob, &used, external)?;
    let metres = units.unwrap_or(Units::Metre).metres();
    let mut positions: Vec<Vec3> = Vec::with_capacity(vertices);
    let mut triangles: Vec<[u32; 3]> = Vec::with_capacity(total);
    for plan in &plans {
        let pos = elements(&plan.positions, Dimensions::Vec3, &buffers)?;
        let a = plan.positions.index();
        let linear: Matrix3<f64> = plan.world.fixed_view::<3, 3>(0, 0).into_owned();
        let shift: Vector3<f64> = plan.world.fixed_view::<3, 1>(0, 3).into_owned();
        let flip = linear.determinant() < 0.0;
        // Corners of a primitive without indices are merged where bit-equal, as STL's are.
        let mut merged: HashMap<[u64; 3], u32> = HashMap::new();
        let mut local_index: Vec<u32> = Vec::with_capacity(pos.count);
        let base = positions.len();
        for k in 0..pos.count {
            let p = Vector3::new(pos.get(k, 0), pos.get(k, 1), pos.get(k, 2));
            if !p.iter().all(|c| c.is_finite()) {
                return Err(bad(format!(
                    "accessors[{a}]: element {k} is not finite: ({}, {}, {})",
                    p.x, p.y, p.z
                )));
            }
            if plan.indices.is_none() {
                let key = [p.x, p.y, p.z].map(|c| (c + 0.0).to_bits());
                if let Some(&j) = merged.get(&key) {
                    local_index.push(j);
                    continue;
                }
                merged.insert(key, (positions.len() - base) as u32);
            }
            let w = linear * p + shift;
            let d = Vec3::new(w.x, w.y, w.z);
            if !d.iter().all(|c| c.is_finite()) {
                let node = plan
                    .node
                    .map_or(String::new(), |n| format!(" placed by nodes[{n}]"));
                return Err(bad(format!(
                    "{}{node}: vertex {k} is not finite once transformed",
                    plan.place
                )));
            }
            local_index.push((positions.len() - base) as u32);
            positions.push(d);
        }
        let n_vertices = pos.count;
        let index_elements = match &plan.indices {
            Some(ia) => {
                let e = elements(ia, Dimensions::Scalar, &buffers)?;
                if !matches!(e.ty, DataType::U8 | DataType::U16 | DataType::U32) {
                    return Err(bad(format!(
                        "accessors[{}]: indices of {:?}, not unsigned integers",
                        ia.index(),
                        e.ty
                    )));
                }
                Some((ia.index(), e))
            }
            None => None,
        };
        let count = plan.corners();
        let mut corners: Vec<u32> = Vec::with_capacity(count);
        for k in 0..count {
            let v = match &index_elements {
                Some((ia, e)) => {
                    let i = e.index(k);
                    if i >= n_vertices as u64 {
                        return Err(bad(format!(
                            "{}: index {i} (accessors[{ia}] element {k}) is past its {n_vertices} \
                             vertices",
                            plan.place
                        )));
                    }
                    i as usize
                }
                None => k,
            };
            let local = local_index
                .get(v)
                .copied()
                .ok_or_else(|| bad(format!("{}: vertex {v} was not read", plan.place)))?;
            corners.push(base as u32 + local);
        }
        let mut push = |t: [u32; 3]| {
            triangles.push(if flip { [t[0], t[2], t[1]] } else { t });
        };
        match plan.mode {
            Mode::TriangleStrip => {
                for i in 0..count.saturating_sub(2) {
                    let t = if i % 2 == 0 {
                        [corners[i], corners[i + 1], corners[i + 2]]
                    } else {
                        [corners[i], corners[i + 2], corners[i + 1]]
                    };
                    // Repeated corners join strips: they are no triangle.
                    if t[0] != t[1] && t[1] != t[2] && t[0] != t[2] {
                        push(t);
                    }
                }
            }
            Mode::TriangleFan => {
                for i in 0..count.saturating_sub(2) {
                    push([corners[i + 1], corners[i + 2], corners[0]]);
                }
            }
            _ => {
                for t in corners.chunks_exact(3) {
                    push([t[0], t[1], t[2]]);
                }
            }
        }
    }
    let mut notes = Vec::new();
    notes.push(match units {
        Some(u) => format!(
            "read as glTF: metres, +Y up, turned to +Z up in {} (the design units the file's \
             extras state)",
            u.as_str()
        ),
        None => "read as glTF: metres, +Y up, turned to +Z up (units = \"m\")".to_string(),
    });
    if !skipped.is_empty() {
        notes.push(format!(
            "{} primitives of points or lines skipped: {}",
            skipped.len(),
            shortened(&skipped)
        ));
    }
    Ok(GltfMesh {
        positions,
        triangles,
        parts: plans.len(),
        units: units.unwrap_or(Units::Metre),
        // glTF (x, y, z), +Y up, is the design's (x, −z, y).
        frame: FileFrame {
            y_up: true,
            design_unit: metres,
        },
        notes,
    })
}

/// The first few places of a list, and how many more.
fn shortened(list: &[String]) -> String {
    let shown: Vec<&str> = list.iter().take(3).map(String::as_str).collect();
    let mut text = shown.join(", ");
    if list.len() > 3 {
        text += &format!(" and {} more", list.len() - 3);
    }
    text
}

#[cfg(test)]
mod tests {
    use super::super::mesh::{InputMesh, MeshFormat, MeshRead};
    use crate::spec::Units;
    use crate::Vec3;
    use serde_json::{json, Value};

    /// A GLB file of `doc` and the binary chunk `bin`, padded as the specification asks.
    fn glb(doc: &Value, bin: &[u8]) -> Vec<u8> {
        let mut j = serde_json::to_vec(doc).unwrap();
        while !j.len().is_multiple_of(4) {
            j.push(b' ');
        }
        let mut b = bin.to_vec();
        while !b.len().is_multiple_of(4) {
            b.push(0);
        }
        let total = 12 + 8 + j.len() + if b.is_empty() { 0 } else { 8 + b.len() };
        let mut out = Vec::new();
        out.extend(b"glTF");
        out.extend(2u32.to_le_bytes());
        out.extend((total as u32).to_le_bytes());
        out.extend((j.len() as u32).to_le_bytes());
        out.extend(b"JSON");
        out.extend(j);
        if !b.is_empty() {
            out.extend((b.len() as u32).to_le_bytes());
            out.extend(b"BIN\0");
            out.extend(b);
        }
        out
    }

    /// Accessors and views over one binary buffer, assembled as a test writes them.
    #[derive(Default)]
    struct Bin {
        bytes: Vec<u8>,
        views: Vec<Value>,
        accessors: Vec<Value>,
    }

    impl Bin {
        fn view(&mut self, data: &[u8]) -> usize {
            while !self.bytes.len().is_multiple_of(4) {
                self.bytes.push(0);
            }
            self.views.push(json!({
                "buffer": 0, "byteOffset": self.bytes.len(), "byteLength": data.len()
            }));
            self.bytes.extend(data);
            self.views.len() - 1
        }

        fn positions(&mut self, p: &[[f32; 3]]) -> usize {
            let data: Vec<u8> = p.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
            let v = self.view(&data);
            let lo = [0, 1, 2].map(|c| p.iter().map(|q| q[c]).fold(f32::INFINITY, f32::min));
            let hi = [0, 1, 2].map(|c| p.iter().map(|q| q[c]).fold(f32::NEG_INFINITY, f32::max));
            self.accessors.push(json!({
                "bufferView": v, "componentType": 5126, "count": p.len(), "type": "VEC3",
                "min": lo, "max": hi
            }));
            self.accessors.len() - 1
        }

        fn indices(&mut self, i: &[u16]) -> usize {
            let data: Vec<u8> = i.iter().flat_map(|x| x.to_le_bytes()).collect();
            let v = self.view(&data);
            self.accessors.push(json!({
                "bufferView": v, "componentType": 5123, "count": i.len(), "type": "SCALAR"
            }));
            self.accessors.len() - 1
        }

        /// A document of these accessors, `meshes` and `nodes`, the scene of the `roots`.
        fn doc(&self, meshes: Value, nodes: Value, roots: &[usize]) -> Value {
            json!({
                "asset": { "version": "2.0" },
                "scene": 0,
                "scenes": [ { "nodes": roots } ],
                "nodes": nodes,
                "meshes": meshes,
                "accessors": self.accessors,
                "bufferViews": self.views,
                "buffers": [ { "byteLength": self.bytes.len() } ],
            })
        }

        fn glb(&self, meshes: Value, nodes: Value, roots: &[usize]) -> Vec<u8> {
            glb(&self.doc(meshes, nodes, roots), &self.bytes)
        }
    }

    /// The unit cube, vertex `x + 2y + 4z`, its triangles counter-clockwise seen from outside.
    fn cube() -> (Vec<[f32; 3]>, Vec<u16>) {
        let p = (0..8)
            .map(|k| [(k & 1) as f32, ((k >> 1) & 1) as f32, ((k >> 2) & 1) as f32])
            .collect();
        let t = vec![
            0, 2, 3, 0, 3, 1, 4, 5, 7, 4, 7, 6, 0, 1, 5, 0, 5, 4, 2, 6, 7, 2, 7, 3, 0, 4, 6, 0, 6,
            2, 1, 3, 7, 1, 7, 5,
        ];
        (p, t)
    }

    fn read(bytes: &[u8]) -> MeshRead {
        InputMesh::read_report(bytes, MeshFormat::Gltf).unwrap()
    }

    fn error(bytes: &[u8]) -> String {
        InputMesh::read_report(bytes, MeshFormat::Gltf)
            .unwrap_err()
            .to_string()
    }

    /// `v` turned by the quaternion `(x, y, z, w)`, normalised: `q v q*` written out.
    fn turn(q: [f64; 4], v: [f64; 3]) -> [f64; 3] {
        let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
        let (x, y, z, w) = (q[0] / n, q[1] / n, q[2] / n, q[3] / n);
        // t = 2 (u × v), v' = v + w t + u × t.
        let t = [
            2.0 * (y * v[2] - z * v[1]),
            2.0 * (z * v[0] - x * v[2]),
            2.0 * (x * v[1] - y * v[0]),
        ];
        [
            v[0] + w * t[0] + (y * t[2] - z * t[1]),
            v[1] + w * t[1] + (z * t[0] - x * t[2]),
            v[2] + w * t[2] + (x * t[1] - y * t[0]),
        ]
    }

    /// glTF `(x, y, z)` (metres, +Y up) in the design's frame.
    fn design(p: [f64; 3]) -> Vec3 {
        Vec3::new(p[0], -p[2], p[1])
    }

    fn close(a: Vec3, b: Vec3, tol: f64) -> bool {
        (a - b).amax() <= tol
    }

    /// A cube placed by translation, rotation and scale: each position is the transformed
    /// input, computed here on its own, in the design's frame; the triangles still face out
    /// (the volume is the scales' product, positive).
    #[test]
    fn a_node_transform_is_applied_and_turned_to_z_up() {
        let (p, t) = cube();
        let mut bin = Bin::default();
        let a = bin.positions(&p);
        let i = bin.indices(&t);
        let q = [0.2f32, -0.4, 0.4, 0.8];
        let (tr, sc) = ([1.0f32, 2.0, 3.0], [2.0f32, 0.5, 1.5]);
        let file = bin.glb(
            json!([{ "primitives": [{ "attributes": { "POSITION": a }, "indices": i }] }]),
            json!([{ "mesh": 0, "translation": tr, "rotation": q, "scale": sc }]),
            &[0],
        );
        let r = read(&file);
        assert_eq!(r.units, Some(Units::Metre));
        assert_eq!(r.joined, None);
        let note = r.note().unwrap();
        assert!(note.contains("metres, +Y up, turned to +Z up"), "{note}");
        assert_eq!(r.mesh.positions.len(), 8);
        let qd = q.map(f64::from);
        for (k, v) in p.iter().enumerate() {
            let s = [0, 1, 2].map(|c| v[c] as f64 * sc[c] as f64);
            let w = turn(qd, s);
            let want = design([0, 1, 2].map(|c| w[c] + tr[c] as f64));
            assert!(close(r.mesh.positions[k], want, 1e-12), "{k}");
        }
        let want = 2.0 * 0.5 * 1.5;
        assert!(
            (r.mesh.signed_volume() - want).abs() < 1e-12,
            "{}",
            r.mesh.signed_volume()
        );
        r.mesh.require_closed().unwrap();
    }

    /// What the repairs say of a glTF file names its points in the file's frame (+Y up,
    /// metres, placed by its node), not the design's: a cube raised 5 along the file's +Y with
    /// its first triangle given twice.
    #[test]
    fn repairs_name_points_where_the_file_has_them() {
        let (p, mut t) = cube();
        t.extend_from_within(..3);
        let mut bin = Bin::default();
        let a = bin.positions(&p);
        let i = bin.indices(&t);
        let file = bin.glb(
            json!([{ "primitives": [{ "attributes": { "POSITION": a }, "indices": i }] }]),
            json!([{ "mesh": 0, "translation": [0.0, 5.0, 0.0] }]),
            &[0],
        );
        let r = read(&file);
        let (mesh, notes) = r.repaired().unwrap();
        assert_eq!(mesh.triangles.len(), 12);
        // The repeated triangle (0, 2, 3): corners (0, 0, 0), (0, 1, 0), (1, 1, 0) of the
        // file, raised 5 along y; its centroid in the design's frame is (1/3, 0, 5 + 2/3).
        let note = notes.join("; ");
        assert!(
            note.contains("1 duplicate triangle dropped (the first near (0.333333, 5.66667, 0))"),
            "{note}"
        );
        assert!(close(
            r.file.to_design(Vec3::new(1.0 / 3.0, 5.0 + 2.0 / 3.0, 0.0)),
            Vec3::new(1.0 / 3.0, 0.0, 5.0 + 2.0 / 3.0),
            1e-15
        ));
    }

    /// A mirrored node (negative determinant) keeps the triangles facing out: their corners
    /// are reversed, as glTF asks.
    #[test]
    fn a_mirrored_node_reverses_its_triangles() {
        let (p, t) = cube();
        let mut bin = Bin::default();
        let a = bin.positions(&p);
        let i = bin.indices(&t);
        let mesh = json!([{ "primitives": [{ "attributes": { "POSITION": a }, "indices": i }] }]);
        for (scale, matrix) in [([-1.0f32, 1.0, 1.0], false), ([1.0, 1.0, -2.0], true)] {
            let node = if matrix {
                let m = [
                    scale[0], 0.0, 0.0, 0.0, 0.0, scale[1], 0.0, 0.0, 0.0, 0.0, scale[2], 0.0, 0.0,
                    0.0, 0.0, 1.0,
                ];
                json!([{ "mesh": 0, "matrix": m }])
            } else {
                json!([{ "mesh": 0, "scale": scale }])
            };
            let r = read(&bin.glb(mesh.clone(), node, &[0]));
            let want = (scale[0] * scale[1] * scale[2]).abs() as f64;
            assert!((r.mesh.signed_volume() - want).abs() < 1e-12, "{scale:?}");
            for (k, v) in p.iter().enumerate() {
                let w = [0, 1, 2].map(|c| v[c] as f64 * scale[c] as f64);
                assert_eq!(r.mesh.positions[k], design(w));
            }
        }
    }

    /// Transforms compose down the hierarchy: parent · child · grandchild, a matrix among them.
    #[test]
    fn node_transforms_compose_down_the_hierarchy() {
        let (p, t) = cube();
        let mut bin = Bin::default();
        let a = bin.positions(&p);
        let i = bin.indices(&t);
        // Column-major: scale 3 along x, translation (0, 1, 0).
        let m = [
            3.0f32, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 1.0,
        ];
        let s = std::f32::consts::FRAC_1_SQRT_2;
        let file = bin.glb(
            json!([{ "primitives": [{ "attributes": { "POSITION": a }, "indices": i }] }]),
            json!([
                { "children": [1], "translation": [0.0, 0.0, 5.0] },
                { "children": [2], "rotation": [0.0, s, 0.0, s] },
                { "mesh": 0, "matrix": m },
            ]),
            &[0],
        );
        let r = read(&file);
        for (k, v) in p.iter().enumerate() {
            let v = v.map(f64::from);
            let inner = [3.0 * v[0], v[1] + 1.0, v[2]];
            let mid = turn([0.0, s as f64, 0.0, s as f64], inner);
            let world = [mid[0], mid[1], mid[2] + 5.0];
            assert!(close(r.mesh.positions[k], design(world), 1e-12), "{k}");
        }
        assert!((r.mesh.signed_volume() - 3.0).abs() < 1e-12);
    }

    /// Strips and fans become triangles of one orientation (glTF's order of their corners);
    /// a strip's repeated corners make no triangle.
    #[test]
    fn strips_and_fans_become_consistently_oriented_triangles() {
        let square: Vec<[f32; 3]> = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 1.0, 0.0],
        ];
        let mut bin = Bin::default();
        let a = bin.positions(&square);
        let strip = bin.indices(&[0, 1, 2, 3, 3, 1, 3, 4, 5]);
        let fan = bin.indices(&[1, 4, 5, 3]);
        let node = json!([{ "mesh": 0 }]);
        let r = read(&bin.glb(
            json!([{ "primitives": [{ "attributes": { "POSITION": a }, "indices": strip, "mode": 5 }] }]),
            node.clone(),
            &[0],
        ));
        // Strip triangles: (0 1 2), (1 3 2), [(2 3 3), (3 3 1) repeated], (3 1 3)… as read.
        let normals: Vec<Vec3> = (0..r.mesh.triangles.len())
            .map(|k| {
                let [a, b, c] = r.mesh.corners(k);
                (b - a).cross(&(c - a))
            })
            .collect();
        assert_eq!(r.mesh.triangles[..2], [[0, 1, 2], [1, 3, 2]]);
        assert!(!normals.is_empty());
        for n in &normals {
            // glTF +Z is the design's −Y.
            assert!(n.y < 0.0 && n.x == 0.0 && n.z == 0.0, "{n:?}");
        }
        for t in &r.mesh.triangles {
            assert!(t[0] != t[1] && t[1] != t[2] && t[0] != t[2], "{t:?}");
        }
        let r = read(&bin.glb(
            json!([{ "primitives": [{ "attributes": { "POSITION": a }, "indices": fan, "mode": 6 }] }]),
            node,
            &[0],
        ));
        assert_eq!(r.mesh.triangles, vec![[4, 5, 1], [5, 3, 1]]);
    }

    /// A primitive without indices is read as a triangle per three vertices, its equal
    /// corners merged: a closed tetrahedron. A second primitive is a second part, welded.
    #[test]
    fn unindexed_primitives_and_several_parts_are_one_mesh() {
        let v = [
            [0.0f32, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        let tris = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
        let soup: Vec<[f32; 3]> = tris.iter().flatten().map(|&k| v[k]).collect();
        let mut bin = Bin::default();
        let a = bin.positions(&soup);
        let node = json!([{ "mesh": 0 }]);
        let r = read(&bin.glb(
            json!([{ "primitives": [{ "attributes": { "POSITION": a } }] }]),
            node.clone(),
            &[0],
        ));
        assert_eq!(r.mesh.positions.len(), 4);
        assert_eq!(r.mesh.triangles.len(), 4);
        r.mesh.require_closed().unwrap();
        assert!((r.mesh.signed_volume() - 1.0 / 6.0).abs() < 1e-15);
        // Two halves of the same soup as two primitives, with a points primitive skipped.
        let mut bin = Bin::default();
        let h1 = bin.positions(&soup[..6]);
        let h2 = bin.positions(&soup[6..]);
        let r = read(&bin.glb(
            json!([{ "primitives": [
                { "attributes": { "POSITION": h1 } },
                { "attributes": { "POSITION": h2 }, "mode": 0 },
                { "attributes": { "POSITION": h2 } },
            ] }]),
            node,
            &[0],
        ));
        let j = r.joined.unwrap();
        assert_eq!((j.parts, j.welded, j.dropped), (2, 4, 0));
        r.mesh.require_closed().unwrap();
        let note = r.note().unwrap();
        assert!(note.contains("2 triangle primitives"), "{note}");
        assert!(
            note.contains(
                "1 primitives of points or lines skipped: meshes[0].primitives[1] (points)"
            ),
            "{note}"
        );
    }

    /// pdeshape's extras name the design's units: the mesh is read in them. A `.gltf` JSON
    /// file reads its buffer from a data URI or, through the caller, from a file beside it.
    #[test]
    fn extras_units_data_uris_and_external_buffers() {
        let (p, t) = cube();
        let mut bin = Bin::default();
        let a = bin.positions(&p);
        let i = bin.indices(&t);
        let mesh = json!([{ "primitives": [{ "attributes": { "POSITION": a }, "indices": i }] }]);
        let mut doc = bin.doc(mesh, json!([{ "mesh": 0 }]), &[0]);
        doc["asset"]["extras"] = json!({ "units": "m", "design_units": "cm", "scale": 1.0 });
        let r = read(&glb(&doc, &bin.bytes));
        assert_eq!(r.units, Some(Units::Centimetre));
        assert_eq!(r.mesh.positions[7], Vec3::new(100.0, -100.0, 100.0));
        assert!(r.note().unwrap().contains("in cm"));
        // The same as JSON, the buffer a data URI.
        doc["buffers"][0]["uri"] = json!(format!(
            "data:application/octet-stream;base64,{}",
            base64(&bin.bytes)
        ));
        let text = serde_json::to_vec(&doc).unwrap();
        assert_eq!(read(&text).mesh, r.mesh);
        // In a file beside it, its name percent-encoded.
        doc["buffers"][0]["uri"] = json!("cube%20data.bin");
        let text = serde_json::to_vec(&doc).unwrap();
        let beside = |name: &str| {
            if name == "cube data.bin" {
                Ok(bin.bytes.clone())
            } else {
                Err(format!("no file {name}"))
            }
        };
        let m = InputMesh::read_report_with(&text, MeshFormat::Gltf, &beside).unwrap();
        assert_eq!(m.mesh, r.mesh);
        // Read without a directory, the external buffer is refused with its name.
        let e = error(&text);
        assert!(e.contains("buffers[0]: cube%20data.bin: "), "{e}");
        assert_eq!(MeshFormat::from_extension("GLB"), Some(MeshFormat::Gltf));
        assert_eq!(MeshFormat::from_extension("gltf"), Some(MeshFormat::Gltf));
    }

    fn base64(bytes: &[u8]) -> String {
        use base64::Engine;
        base64::engine::general_purpose::STANDARD.encode(bytes)
    }

    /// pdeshape's own writers read back in the design's frame and units: the GLB (metres,
    /// +Y up, f32: each coordinate within 2⁻²⁴ of its size, relative, after the scale to metres
    /// and back) and an OBJ written +Y up in cm (exactly: the turn only moves and negates).
    #[test]
    fn the_tools_own_glb_and_turned_obj_read_back_as_designed() {
        use crate::mesh::TriMesh;
        use crate::mesh_write::{write_glb, write_obj, MeshInfo, Up};
        let positions: Vec<[f32; 3]> = vec![
            [0.1, 0.2, 0.3],
            [12.5, -0.7, 0.25],
            [-3.3, 4.1, 0.0],
            [0.9, 0.8, 7.77],
        ];
        let triangles = vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
        let m = TriMesh {
            normals: vec![[0.0, 0.0, 1.0]; 4],
            positions: positions.clone(),
            uv: Vec::new(),
            triangles,
            parts: Vec::new(),
        };
        let info = MeshInfo {
            units: Units::Centimetre,
            ..MeshInfo::default()
        };
        let mut bytes = Vec::new();
        write_glb(&m, &info, &mut bytes).unwrap();
        let r = read(&bytes);
        assert_eq!(r.units, Some(Units::Centimetre));
        for (k, p) in positions.iter().enumerate() {
            for (c, &x) in p.iter().enumerate() {
                let (got, want) = (r.mesh.positions[k][c], x as f64);
                assert!(
                    (got - want).abs() <= want.abs() * 2f64.powi(-24) * 1.000001,
                    "{k} {c}: {got} {want}"
                );
            }
        }
        let mut obj = Vec::new();
        write_obj(
            &m,
            &MeshInfo {
                up: Up::Y,
                ..info.clone()
            },
            &mut obj,
        )
        .unwrap();
        assert!(String::from_utf8_lossy(&obj).contains("up: +Y"));
        let r = InputMesh::read_report(&obj, MeshFormat::Obj).unwrap();
        assert_eq!(r.units, Some(Units::Centimetre));
        assert!(r.note().unwrap().contains("turned to +Z up"));
        let want: Vec<Vec3> = positions
            .iter()
            .map(|p| {
                // The OBJ's shortest text of each f32, read in double precision.
                let s = |x: f32| format!("{x}").parse::<f64>().unwrap();
                Vec3::new(s(p[0]), s(p[1]), s(p[2]))
            })
            .collect();
        // The OBJ reader numbers vertices in the order the faces use them: the same triangles.
        assert_eq!(r.mesh.triangles.len(), m.triangles.len());
        for (k, t) in m.triangles.iter().enumerate() {
            assert_eq!(r.mesh.corners(k), t.map(|i| want[i as usize]), "{k}");
        }
        // The STL header states its units and up axis too.
        let mut stl = Vec::new();
        crate::mesh_write::write_stl(
            &m,
            &MeshInfo {
                up: Up::Y,
                ..info.clone()
            },
            &mut stl,
        )
        .unwrap();
        let r = InputMesh::read_report(&stl, MeshFormat::Stl).unwrap();
        assert_eq!(r.units, Some(Units::Centimetre));
        assert_eq!(
            r.mesh.positions[0],
            Vec3::new(0.1f32 as f64, 0.2f32 as f64, 0.3f32 as f64)
        );
        // A file stating nothing: no units, as it is.
        let r = InputMesh::read_report(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", MeshFormat::Obj)
            .unwrap();
        assert_eq!((r.units, r.note()), (None, None));
    }

    /// Damaged files: one line naming the place, never a panic.
    #[test]
    fn damaged_files_are_refused_with_their_place() {
        let (p, t) = cube();
        let mut bin = Bin::default();
        let a = bin.positions(&p);
        let i = bin.indices(&t);
        let mesh = json!([{ "primitives": [{ "attributes": { "POSITION": a }, "indices": i }] }]);
        let good_doc = bin.doc(mesh.clone(), json!([{ "mesh": 0 }]), &[0]);
        let good = glb(&good_doc, &bin.bytes);
        read(&good);
        let with = |edit: &dyn Fn(&mut Value)| {
            let mut d = good_doc.clone();
            edit(&mut d);
            glb(&d, &bin.bytes)
        };
        let mut bad_magic = good.clone();
        bad_magic[..4].copy_from_slice(b"glTX");
        let mut version = good.clone();
        version[4] = 1;
        let mut nan = bin.bytes.clone();
        nan[12..16].copy_from_slice(&f32::NAN.to_le_bytes());
        let mut past = bin.bytes.clone();
        // Index 4 (triangle 2's second corner) is 9, past the 8 vertices.
        past[96 + 2 * 4..96 + 2 * 4 + 2].copy_from_slice(&9u16.to_le_bytes());
        let json_text = serde_json::to_string(&good_doc).unwrap();
        let cases: Vec<(Vec<u8>, &str)> = vec![
            (
                good[..good.len() - 10].to_vec(),
                "the GLB file is truncated: its header announces",
            ),
            (good[..7].to_vec(), "the GLB file is truncated: 7 bytes"),
            (bad_magic, "the file starts with 'glTX': neither a GLB"),
            (version, "GLB version 1"),
            (
                b"{\"asset\": {\"version\": \"2.0\"".to_vec(),
                "the JSON: EOF while parsing",
            ),
            (
                json_text
                    .replace("\"POSITION\":0", "\"POSITION\":7")
                    .into_bytes(),
                "meshes[0].primitives[0]: POSITION refers to accessors[7]",
            ),
            (
                with(&|d| d["accessors"][1]["bufferView"] = json!(5)),
                "accessors[1].bufferView: refers to an item the file does not have",
            ),
            (
                with(&|d| d["accessors"][1]["count"] = json!(60)),
                "accessors[1]: 60 elements from byte 0 of bufferViews[1] run past its 72 bytes",
            ),
            (
                with(&|d| d["bufferViews"][0]["byteLength"] = json!(400)),
                "bufferViews[0]: bytes 0 to 400 lie past the end of buffers[0]",
            ),
            (
                glb(&good_doc, &past),
                "meshes[0].primitives[0]: index 9 (accessors[1] element 4) is past its 8 vertices",
            ),
            (
                glb(&good_doc, &nan),
                "accessors[0]: element 1 is not finite: (NaN",
            ),
            (
                glb(&good_doc, &[]),
                "buffers[0]: refers to the GLB binary chunk, but the file has none",
            ),
            (
                with(&|d| d["nodes"] = json!([{ "mesh": 0, "children": [0] }])),
                "nodes[0]: reached twice from scenes[0]",
            ),
            (
                with(&|d| d["accessors"][1]["count"] = json!(35)),
                "meshes[0].primitives[0]: 35 indices, not a multiple of 3",
            ),
            (
                with(&|d| d["meshes"][0]["primitives"][0]["mode"] = json!(1)),
                "no primitive of triangles in scenes[0]: meshes[0].primitives[0] (lines)",
            ),
            (
                with(&|d| d["nodes"][0]["rotation"] = json!([0.0, 0.0, 0.0, 0.0])),
                "nodes[0]: its rotation is not a unit quaternion",
            ),
            (
                with(&|d| {
                    d["buffers"][0]["uri"] = json!("data:application/octet-stream;base64,@@")
                }),
                "buffers[0]: the data URI is not valid base64",
            ),
            (
                with(&|d| d["buffers"][0]["uri"] = json!("https://example.org/cube.bin")),
                "buffers[0]: 'https://example.org/cube.bin' is not a file beside the glTF file",
            ),
            (
                with(&|d| {
                    d["accessors"][0]["sparse"] = json!({
                        "count": 1,
                        "indices": { "bufferView": 1, "componentType": 5123 },
                        "values": { "bufferView": 0 }
                    })
                }),
                "accessors[0]: sparse accessors are not read",
            ),
        ];
        for (bytes, want) in &cases {
            let e = error(bytes);
            assert!(e.starts_with("not a readable glTF file: "), "{e}");
            assert!(e.contains(want), "want '{want}' in: {e}");
            assert!(!e.contains('\n'), "{e}");
        }
        // A missing file beside it names the file.
        let mut d = good_doc.clone();
        d["buffers"][0]["uri"] = json!("cube.bin");
        let text = serde_json::to_vec(&d).unwrap();
        let e = InputMesh::read_report_with(&text, MeshFormat::Gltf, &|_: &str| {
            Err("cannot read: no such file or directory".to_string())
        })
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("buffers[0]: cube.bin: cannot read: no such file or directory"),
            "{e}"
        );
        // Every prefix of a good file is refused without a panic.
        for n in 0..good.len() {
            assert!(
                InputMesh::read_report(&good[..n], MeshFormat::Gltf).is_err(),
                "{n}"
            );
        }
    }
}
