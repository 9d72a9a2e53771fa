//! glTF 2.0 binary (`.glb`): from a welded [`TriMesh`] ([`write_glb`]), or straight from a
//! design's grids and the plan of their weld ([`write_glb_grids`]), which writes the same bytes
//! without building the welded mesh.

use super::{
    check_grids, check_mesh, check_u32, join_bytes, le3, parts_of, stream, Format, Frame, MeshInfo,
    Sink, CHUNK, GENERATOR,
};
use crate::mesh::weld::{
    box_union, closed_given, edge_bits, weld, BoundingBox, Plan, PlanPart, WeldOptions, EMPTY_BOX,
};
use crate::mesh::{GridMesh, Part, TriMesh};
use crate::{Error, Result};
use rayon::prelude::*;
use std::io::Write;

const GLB_MAGIC: u32 = 0x4654_6C67; // "glTF"
const GLB_JSON: u32 = 0x4E4F_534A; // "JSON"
const GLB_BIN: u32 = 0x004E_4942; // "BIN\0"
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;

/// The smallest box around positions as designed (before the file's frame).
#[derive(Clone, Copy)]
struct Bounds(BoundingBox);

impl Bounds {
    #[inline(always)]
    fn add(&mut self, q: [f32; 3]) {
        self.0 = box_union(self.0, (q, q));
    }

    /// The smallest box around the positions as written. Each coordinate the frame writes is
    /// a monotone function of one designed coordinate (a scale, a turn by quarter turns), so
    /// the box's corners map to the written box's; a zero of either sign is written `0` (which
    /// of `±0` a minimum keeps depends on the order the points come in).
    fn framed(self, frame: &Frame) -> ([f32; 3], [f32; 3]) {
        let (a, b) = (frame.point(self.0 .0), frame.point(self.0 .1));
        (
            [0, 1, 2].map(|c| a[c].min(b[c]) + 0.0),
            [0, 1, 2].map(|c| a[c].max(b[c]) + 0.0),
        )
    }
}

/// What the JSON chunk says about one part.
struct PartHead {
    name: String,
    vertices: usize,
    triangles: usize,
    bounds: Bounds,
}

/// The JSON chunk (padded with spaces to four bytes) and the length of the binary one's data,
/// for parts written one after the other as positions, normals, texture coordinates (with
/// `with_uv`) and indices. Parts without vertices are left out.
fn document<'a>(
    heads: impl Iterator<Item = &'a PartHead>,
    with_uv: bool,
    closed: bool,
    frame: &Frame,
    info: &MeshInfo,
) -> Result<(Vec<u8>, u128)> {
    use serde_json::{json, Value};
    let mut views: Vec<Value> = Vec::new();
    let mut accessors: Vec<Value> = Vec::new();
    let mut meshes: Vec<Value> = Vec::new();
    let mut nodes: Vec<Value> = Vec::new();
    let mut offset: u128 = 0;
    for (k, head) in heads.enumerate() {
        if head.vertices == 0 {
            continue;
        }
        let indices = 3 * head.triangles as u128;
        check_u32(indices, "triangle indices", "glTF").map_err(|e| e.at(&format!("parts[{k}]")))?;
        let (lo, hi) = head.bounds.framed(frame);
        let n = head.vertices as u128;
        let mut layout: Vec<(u128, Option<u32>, u32)> = vec![
            (n * 12, Some(12), ARRAY_BUFFER),
            (n * 12, Some(12), ARRAY_BUFFER),
        ];
        if with_uv {
            layout.push((n * 8, Some(8), ARRAY_BUFFER));
        }
        layout.push((indices * 4, None, ELEMENT_ARRAY_BUFFER));
        let first = accessors.len();
        for (len, stride, target) in &layout {
            let mut view = json!({
                "buffer": 0,
                "byteOffset": offset as u64,
                "byteLength": *len as u64,
                "target": target,
            });
            if let Some(s) = stride {
                view["byteStride"] = json!(s);
            }
            views.push(view);
            offset += len;
        }
        accessors.push(json!({
            "bufferView": first, "componentType": FLOAT, "count": head.vertices,
            "type": "VEC3", "min": lo, "max": hi,
        }));
        accessors.push(json!({
            "bufferView": first + 1, "componentType": FLOAT, "count": head.vertices,
            "type": "VEC3",
        }));
        let mut attributes = json!({ "POSITION": first, "NORMAL": first + 1 });
        let mut next = first + 2;
        if with_uv {
            accessors.push(json!({
                "bufferView": next, "componentType": FLOAT, "count": head.vertices,
                "type": "VEC2",
            }));
            attributes["TEXCOORD_0"] = json!(next);
            next += 1;
        }
        accessors.push(json!({
            "bufferView": next, "componentType": UNSIGNED_INT, "count": indices as u64,
            "type": "SCALAR",
        }));
        let name = if head.name.is_empty() {
            format!("part{k}")
        } else {
            head.name.clone()
        };
        meshes.push(json!({
            "name": name,
            "primitives": [{ "attributes": attributes, "indices": next, "mode": 4, "material": 0 }],
        }));
        nodes.push(json!({ "name": name, "mesh": meshes.len() - 1 }));
    }
    let bin_len = offset;
    let title = info.title.clone().unwrap_or_else(|| "pdeshape".to_string());
    let children: Vec<usize> = (1..=nodes.len()).collect();
    let mut all_nodes = vec![json!({ "name": title, "children": children })];
    all_nodes.extend(nodes);
    let mut extras = json!({
        "units": "m",
        "design_units": info.units.as_str(),
        "scale": info.scale,
    });
    if let Some(t) = &info.title {
        extras["title"] = json!(t);
    }
    let doc = json!({
        "asset": { "version": "2.0", "generator": GENERATOR, "extras": extras },
        "scene": 0,
        "scenes": [ { "name": title, "nodes": [0] } ],
        "nodes": all_nodes,
        "meshes": meshes,
        "materials": [material(!closed)],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [ { "byteLength": bin_len as u64 } ],
    });
    let mut json_bytes =
        serde_json::to_vec(&doc).map_err(|e| Error::io(format!("writing glTF JSON: {e}")))?;
    while json_bytes.len() % 4 != 0 {
        json_bytes.push(b' ');
    }
    Ok((json_bytes, bin_len))
}

/// The one material of a pdeshape glTF file (meshes and animations): matte light grey,
/// double-sided for an open surface, so both of its sides show.
pub fn material(double_sided: bool) -> serde_json::Value {
    serde_json::json!({
        "name": "pdeshape surface",
        "pbrMetallicRoughness": {
            "baseColorFactor": [0.8, 0.8, 0.82, 1.0],
            "metallicFactor": 0.0,
            "roughnessFactor": 0.6,
        },
        "doubleSided": double_sided,
    })
}

/// The file's header, its JSON chunk and the binary chunk's header, once the total is known to
/// fit; the caller then writes `bin_len` bytes of data and [`pad`]s them.
struct Head {
    json: Vec<u8>,
    bin_len: u128,
    total: u32,
}

impl Head {
    fn new(json: Vec<u8>, bin_len: u128) -> Result<Head> {
        let total = 12 + 8 + json.len() as u128 + 8 + bin_len.next_multiple_of(4);
        let total = check_u32(total, "bytes", "GLB")?;
        Ok(Head {
            json,
            bin_len,
            total,
        })
    }

    fn write(&self, out: &mut Sink) {
        out.u32_le(GLB_MAGIC);
        out.u32_le(2);
        out.u32_le(self.total);
        out.u32_le(self.json.len() as u32);
        out.u32_le(GLB_JSON);
        out.bytes(&self.json);
        out.u32_le(self.bin_len.next_multiple_of(4) as u32);
        out.u32_le(GLB_BIN);
    }

    /// Zeros after the binary data up to four bytes.
    fn pad(&self, out: &mut Sink) {
        for _ in self.bin_len..self.bin_len.next_multiple_of(4) {
            out.bytes(&[0]);
        }
    }
}

/// Twelve bytes of a vector of `f32`.
#[inline(always)]
fn vec3(v: [f32; 3]) -> [u8; 12] {
    le3(v.map(f32::to_bits))
}

/// The vertices one part of a mesh uses, in increasing order, the number of each in that
/// order, the bounds of their positions as written, and the exclusive-or of its triangles'
/// edge bits.
struct GlbPart {
    vertices: Vec<u32>,
    triangles: std::ops::Range<usize>,
    /// `slot[i − base]`: the part's number of vertex `i` (`u32::MAX` where it is not used).
    base: u32,
    slot: Vec<u32>,
    head: PartHead,
    edges: u64,
}

impl GlbPart {
    /// One pass over the part's triangles marking the vertices it uses, one over that range
    /// of vertices numbering them (the table of numbers covers only that range).
    fn new(mesh: &TriMesh, part: &Part) -> GlbPart {
        let tris = &mesh.triangles[part.triangles.clone()];
        let (first, last) = tris
            .par_chunks(1 << 15)
            .map(|ts| {
                let is = ts.as_flattened();
                let lo = is.iter().copied().fold(u32::MAX, u32::min);
                let hi = is.iter().copied().fold(0, u32::max);
                (lo, hi)
            })
            .reduce(|| (u32::MAX, 0), |a, b| (a.0.min(b.0), a.1.max(b.1)));
        let (base, len) = if tris.is_empty() {
            (0, 0)
        } else {
            (first, (last - first) as usize + 1)
        };
        let mut slot = Vec::with_capacity(len);
        crate::mesh::advise_huge_pages(slot.spare_capacity_mut());
        slot.resize(len, u32::MAX);
        let mut edges = 0;
        for &t in tris {
            edges ^= edge_bits(t);
            for i in t {
                slot[(i - base) as usize] = 0;
            }
        }
        let mut vertices = Vec::with_capacity(len);
        crate::mesh::advise_huge_pages(vertices.spare_capacity_mut());
        let mut bounds = Bounds(EMPTY_BOX);
        for (i, s) in slot.iter_mut().enumerate() {
            if *s == 0 {
                *s = vertices.len() as u32;
                let v = base + i as u32;
                vertices.push(v);
                bounds.add(mesh.positions[v as usize]);
            }
        }
        GlbPart {
            head: PartHead {
                name: part.name.clone(),
                vertices: vertices.len(),
                triangles: tris.len(),
                bounds,
            },
            vertices,
            triangles: part.triangles.clone(),
            base,
            slot,
            edges,
        }
    }

    /// The part's number of vertex `i` (one it uses).
    #[inline(always)]
    fn local(&self, i: u32) -> u32 {
        self.slot[(i - self.base) as usize]
    }
}

/// glTF 2.0 binary (`.glb`) in glTF's conventions: `+Y` up (the design's `+Z` turned to `+Y`,
/// `(x, y, z) → (x, z, −y)`) and metres (positions times `scale` and the metres per unit).
///
/// One scene with a root node named after the design's title, with one child node and one mesh
/// per part, both named after the part; each mesh has one triangle primitive (mode 4) with
/// `POSITION` (with min/max), `NORMAL`, `TEXCOORD_0` only when the mesh has texture coordinates,
/// and `u32` indices, using one material: double-sided when the mesh is open (has edges used by
/// one triangle), so both sides of an open surface show. Each part has its own vertices (a
/// vertex on a shared edge is written once per part, at the same position), in the order of
/// the mesh's vertex numbers. `asset` names the generator (with pdeshape's version) and carries
/// the title, units and scale in `extras`.
pub fn write_glb(mesh: &TriMesh, info: &MeshInfo, w: &mut dyn Write) -> Result<()> {
    check_mesh(mesh)?;
    let frame = Frame::new(info, Format::Glb)?;
    let with_uv = !mesh.uv.is_empty();
    // Vertex numbering per part (parts in parallel).
    let glb_parts: Vec<GlbPart> = parts_of(mesh)
        .par_iter()
        .map(|p| GlbPart::new(mesh, p))
        .collect();
    let closed = closed_given(mesh, glb_parts.iter().fold(0, |x, p| x ^ p.edges));
    let heads = glb_parts.iter().map(|p| &p.head);
    let (json, bin_len) = document(heads, with_uv, closed, &frame, info)?;
    let head = Head::new(json, bin_len)?;
    stream(w, "GLB", |out| {
        head.write(out);
        for gp in &glb_parts {
            if gp.vertices.is_empty() {
                continue;
            }
            let vs = &gp.vertices;
            let (positions, normals) = (&mesh.positions, &mesh.normals);
            out.records(vs.len(), |k| vec3(frame.point(positions[vs[k] as usize])))?;
            out.records(vs.len(), |k| vec3(frame.normal(normals[vs[k] as usize])))?;
            if with_uv {
                out.records(vs.len(), |k| {
                    let [u, v] = mesh.uv[vs[k] as usize];
                    join_bytes::<4, 4, 8>(u.to_le_bytes(), v.to_le_bytes())
                })?;
            }
            let ts = &mesh.triangles[gp.triangles.clone()];
            out.records(ts.len(), |k| le3(ts[k].map(|i| gp.local(i))))?;
        }
        head.pad(out);
        Ok(())
    })
}

/// A design's grids welded (as [`crate::mesh::weld`] with `names` and `options`) and written
/// as [`write_glb`] writes the welded mesh, byte for byte, without building it: each part's
/// vertices, normals and triangles are read from its grid row by row as they are written (see
/// the weld's plan). Where the layout does not give the parts (tiny grids, a vertex no
/// triangle uses, patches that cannot be oriented alike), the mesh is welded and written.
pub fn write_glb_grids(
    grids: &[GridMesh],
    names: &[&str],
    options: WeldOptions,
    info: &MeshInfo,
    w: &mut dyn Write,
) -> Result<()> {
    check_grids(grids, true)?;
    let frame = Frame::new(info, Format::Glb)?;
    let plan = Plan::new(grids, names, options);
    let (Some(parts), Some(closed)) = (plan.parts(), plan.closed()) else {
        return write_glb(&weld(grids, names, options), info, w);
    };
    let heads: Vec<PartHead> = parts
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let mut bounds = Bounds(plan.own_bounds(k));
            for &w in &p.foreign {
                bounds.add(plan.position(w));
            }
            PartHead {
                name: p.name.clone(),
                vertices: p.vertices(),
                triangles: p.triangles(),
                bounds,
            }
        })
        .collect();
    let (json, bin_len) = document(heads.iter(), false, closed, &frame, info)?;
    let head = Head::new(json, bin_len)?;
    // The turns (and with them the normals and triangles) are found while the first part's
    // positions are written.
    std::thread::scope(|scope| {
        scope.spawn(|| plan.prepare());
        write_parts(&plan, parts, &head, &frame, w)
    })
}

/// The file [`write_glb_grids`] writes, given its head: every part's positions, normals and
/// indices, read from the grids through the plan.
fn write_parts(
    plan: &Plan,
    parts: &[PlanPart],
    head: &Head,
    frame: &Frame,
    w: &mut dyn Write,
) -> Result<()> {
    let grids = plan.grids();
    stream(w, "GLB", |out| {
        head.write(out);
        for (k, p) in parts.iter().enumerate() {
            let g = &grids[k];
            // Blocks of about half a chunk: rows of vertices, quad rows of triangles.
            let rows = (CHUNK / 2 / (12 * g.nv)).max(1);
            let quad_rows = (CHUNK / 2 / (24 * g.nv)).max(1);
            let foreign = &p.foreign;
            out.records(foreign.len(), |m| {
                vec3(frame.point(plan.position(foreign[m])))
            })?;
            out.blocks(g.nu, rows, |range, text| {
                plan.own_positions(k, range, |run| {
                    text.records(0..run.len(), |m| vec3(frame.point(run[m])))
                })
            })?;
            // The turns are needed from here on: found (or waited for) on this thread, not
            // in the thread pool's blocks.
            plan.prepare();
            out.records(foreign.len(), |m| {
                vec3(frame.normal(plan.candidate_normal(foreign[m])))
            })?;
            out.blocks(g.nu, rows, |range, text| {
                plan.own_normals(k, range, |run| {
                    text.records(0..run.len(), |m| vec3(frame.normal(run[m])))
                })
            })?;
            out.blocks(g.nu - 1, quad_rows, |range, text| {
                plan.local_triangles(k, range, |t| text.bytes(&le3(t)))
            })?;
        }
        head.pad(out);
        Ok(())
    })
}

#[cfg(test)]
mod tests;
