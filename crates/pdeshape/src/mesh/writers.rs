//! Writers. Each takes the patches of a design (one grid each) and writes them one after another.
//!
//! Every writer first checks all of its input (at least one patch, consistent array lengths, finite
//! positions, normals and parameter values, index ranges that fit the format) and only then writes,
//! so a refused input never leaves a truncated or broken file behind. The bytes are assembled in a
//! chunk buffer of about a megabyte that is handed to the destination with `write_all`, so the
//! destination needs no buffering of its own.
//!
//! Texture coordinates are `(s, t)` with `s = u_i` and `t = v_j/2π` for a periodic `v` (the seam
//! column gets `t = 1` where a format duplicates it), or `t = (v_j − v_0)/(v_{nv−1} − v_0)` for an
//! interval.

use super::{Grid, GridMesh, Samples};
use crate::{Error, Result, TAU};
use std::io::Write;

/// Output formats, chosen by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Obj,
    Stl,
    Ply,
    Glb,
    Csv,
}

const EXTENSIONS_HINT: &str = "use .obj, .stl, .ply, .glb or .csv";

impl Format {
    /// The format for a path's extension (case-insensitive): obj, stl, ply, glb, csv.
    pub fn from_path(path: &std::path::Path) -> Result<Format> {
        let Some(ext) = path.extension() else {
            return Err(Error::invalid(format!(
                "output path '{}' has no extension: {EXTENSIONS_HINT}",
                path.display()
            )));
        };
        let ext = ext.to_string_lossy();
        match ext.to_ascii_lowercase().as_str() {
            "obj" => Ok(Format::Obj),
            "stl" => Ok(Format::Stl),
            "ply" => Ok(Format::Ply),
            "glb" => Ok(Format::Glb),
            "csv" => Ok(Format::Csv),
            _ => Err(Error::invalid(format!(
                "unknown output extension '.{ext}': {EXTENSIONS_HINT}"
            ))),
        }
    }

    /// The canonical (lower-case) file extension, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Obj => "obj",
            Format::Stl => "stl",
            Format::Ply => "ply",
            Format::Glb => "glb",
            Format::Csv => "csv",
        }
    }

    /// True for the mesh formats (written from f32 [`GridMesh`]es); false for CSV, which is
    /// written from full-precision [`Samples`].
    pub fn is_mesh(self) -> bool {
        self != Format::Csv
    }
}

/// Writes meshes in a mesh format (obj, stl, ply, glb); CSV, which stores full-precision
/// samples, is written by [`write_csv`].
pub fn write(format: Format, meshes: &[GridMesh], w: &mut dyn Write) -> Result<()> {
    match format {
        Format::Obj => write_obj(meshes, w),
        Format::Stl => write_stl(meshes, w),
        Format::Ply => write_ply(meshes, w),
        Format::Glb => write_glb(meshes, w),
        Format::Csv => Err(Error::invalid(
            "csv stores full-precision samples: write them with write_csv",
        )),
    }
}

// ---------------------------------------------------------------------------------------------
// Input checks
// ---------------------------------------------------------------------------------------------

/// Checks the patches before anything is written: at least one patch; array lengths that agree
/// with `nu × nv`; finite parameter values, positions and normals; and, for the mesh formats
/// (`need_faces`), at least one face per patch.
fn check_grids<T: Copy + Into<f64>>(grids: &[Grid<T>], need_faces: bool) -> Result<()> {
    if grids.is_empty() {
        return Err(Error::invalid(
            "no patches to write: the design produced no surface",
        ));
    }
    for (k, g) in grids.iter().enumerate() {
        check_grid(g, need_faces).map_err(|e| e.at(&format!("patches[{k}]")))?;
    }
    Ok(())
}

fn check_grid<T: Copy + Into<f64>>(g: &Grid<T>, need_faces: bool) -> Result<()> {
    let Some(n) = g.nu.checked_mul(g.nv) else {
        return Err(Error::invalid(format!(
            "grid size {} × {} overflows",
            g.nu, g.nv
        )));
    };
    if n == 0 {
        return Err(Error::invalid(format!(
            "empty grid ({} × {} vertices)",
            g.nu, g.nv
        )));
    }
    if need_faces {
        let min_nv = if g.periodic_v { 3 } else { 2 };
        if g.nu < 2 || g.nv < min_nv {
            return Err(Error::invalid(format!(
                "a {} × {} grid{} has no faces (need nu ≥ 2 and nv ≥ {min_nv})",
                g.nu,
                g.nv,
                if g.periodic_v { " periodic in v" } else { "" }
            )));
        }
    }
    let lengths = [
        ("u", g.u.len(), g.nu),
        ("v", g.v.len(), g.nv),
        ("positions", g.positions.len(), n),
        ("normals", g.normals.len(), n),
    ];
    for (name, len, want) in lengths {
        if len != want {
            return Err(Error::invalid(format!(
                "{name} has {len} entries, expected {want} for a {} × {} grid",
                g.nu, g.nv
            )));
        }
    }
    if let Some((i, &u)) = g.u.iter().enumerate().find(|(_, u)| !u.is_finite()) {
        return Err(Error::invalid(format!("non-finite parameter u[{i}] = {u}")));
    }
    if let Some((j, &v)) = g.v.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(Error::invalid(format!("non-finite parameter v[{j}] = {v}")));
    }
    for (name, data) in [("position", &g.positions), ("normal", &g.normals)] {
        let bad = data
            .iter()
            .position(|p| !p.iter().all(|&c| Into::<f64>::into(c).is_finite()));
        if let Some(idx) = bad {
            let p = data[idx].map(Into::<f64>::into);
            return Err(Error::invalid(format!(
                "non-finite {name} [{}, {}, {}] at vertex {idx} (i = {}, j = {})",
                p[0],
                p[1],
                p[2],
                idx / g.nv,
                idx % g.nv
            )));
        }
    }
    Ok(())
}

/// Refuses totals that do not fit a format's 32-bit counts or indices.
fn check_u32(total: u128, what: &str, format: &str) -> Result<u32> {
    u32::try_from(total).map_err(|_| {
        Error::invalid(format!(
            "{total} {what} do not fit the 32-bit counts of the {format} format; use coarser grids"
        ))
    })
}

// ---------------------------------------------------------------------------------------------
// Output helpers
// ---------------------------------------------------------------------------------------------

const CHUNK: usize = 1 << 20;

/// A byte buffer that is passed to the destination with `write_all` whenever it holds about
/// [`CHUNK`] bytes.
struct Sink<'a> {
    buf: Vec<u8>,
    w: &'a mut dyn Write,
    what: &'static str,
    float: ryu::Buffer,
}

impl<'a> Sink<'a> {
    fn new(w: &'a mut dyn Write, what: &'static str) -> Self {
        Sink {
            buf: Vec::with_capacity(CHUNK + 4096),
            w,
            what,
            float: ryu::Buffer::new(),
        }
    }

    /// Passes the buffer on once it is full; call between records.
    #[inline]
    fn tick(&mut self) -> Result<()> {
        if self.buf.len() >= CHUNK {
            self.drain()?;
        }
        Ok(())
    }

    fn drain(&mut self) -> Result<()> {
        let what = self.what;
        self.w
            .write_all(&self.buf)
            .map_err(|e| Error::io(format!("writing {what}: {e}")))?;
        self.buf.clear();
        Ok(())
    }

    fn finish(mut self) -> Result<()> {
        self.drain()?;
        let what = self.what;
        self.w
            .flush()
            .map_err(|e| Error::io(format!("writing {what}: {e}")))
    }

    #[inline]
    fn bytes(&mut self, b: &[u8]) {
        self.buf.extend_from_slice(b);
    }

    /// Shortest decimal text that parses back to the same `f32` (the value is finite: checked).
    #[inline]
    fn f32_text(&mut self, x: f32) {
        let s = self.float.format_finite(x);
        self.buf.extend_from_slice(s.as_bytes());
    }

    /// Shortest decimal text that parses back to the same `f64` (the value is finite: checked).
    #[inline]
    fn f64_text(&mut self, x: f64) {
        let s = self.float.format_finite(x);
        self.buf.extend_from_slice(s.as_bytes());
    }

    #[inline]
    fn uint_text(&mut self, mut x: u64) {
        let mut tmp = [0u8; 20];
        let mut k = tmp.len();
        loop {
            k -= 1;
            tmp[k] = b'0' + (x % 10) as u8;
            x /= 10;
            if x == 0 {
                break;
            }
        }
        self.buf.extend_from_slice(&tmp[k..]);
    }

    #[inline]
    fn f32_le(&mut self, x: f32) {
        self.buf.extend_from_slice(&x.to_le_bytes());
    }

    #[inline]
    fn u32_le(&mut self, x: u32) {
        self.buf.extend_from_slice(&x.to_le_bytes());
    }
}

/// Texture coordinate `t` of column `j` (`j == nv` is the duplicated seam of a periodic grid).
fn tex_t<T>(g: &Grid<T>, j: usize) -> f32 {
    if g.periodic_v {
        if j >= g.nv {
            1.0
        } else {
            (g.v[j] / TAU) as f32
        }
    } else {
        let (v0, v1) = (g.v[0], g.v[g.nv - 1]);
        let span = v1 - v0;
        if span != 0.0 && span.is_finite() {
            ((g.v[j] - v0) / span) as f32
        } else {
            0.0
        }
    }
}

/// Columns of a grid with the seam duplicated when `v` is periodic.
fn seam_columns<T>(g: &Grid<T>) -> usize {
    g.nv + usize::from(g.periodic_v)
}

// ---------------------------------------------------------------------------------------------
// OBJ
// ---------------------------------------------------------------------------------------------

/// One OBJ record `prefix x y z`.
fn obj_vec3(out: &mut Sink, prefix: &[u8], v: &[f32; 3]) -> Result<()> {
    out.bytes(prefix);
    out.f32_text(v[0]);
    out.bytes(b" ");
    out.f32_text(v[1]);
    out.bytes(b" ");
    out.f32_text(v[2]);
    out.bytes(b"\n");
    out.tick()
}

/// Wavefront OBJ with `v`, `vt`, `vn` and quad faces `f v/vt/vn`.
///
/// Each patch `k` is an object `o patch<k>` with its `nu·nv` positions and normals (vertex
/// `(i, j)` is number `i·nv + j + 1` after the previous patches) and texture coordinates
/// `(u_i, t_j)`. A periodic patch gets one extra texture column `t = 1` so that the faces across
/// the seam (column `nv−1` to column 0) use it while sharing the seam's positions and normals.
/// Faces are the quads of [`Grid::quads`], counter-clockwise seen from the normals. Numbers are
/// the shortest text that reads back to the identical `f32`.
pub fn write_obj(meshes: &[GridMesh], w: &mut dyn Write) -> Result<()> {
    check_grids(meshes, true)?;
    let mut out = Sink::new(w, "OBJ");
    out.bytes(b"# pdeshape OBJ: ");
    out.uint_text(meshes.len() as u64);
    out.bytes(b" patch(es), quads, v/vt/vn\n");
    let mut pos_base: u64 = 1;
    let mut tex_base: u64 = 1;
    for (k, g) in meshes.iter().enumerate() {
        let (nu, nv) = (g.nu, g.nv);
        let tw = seam_columns(g);
        out.bytes(b"o patch");
        out.uint_text(k as u64);
        out.bytes(b"\n");
        for p in &g.positions {
            obj_vec3(&mut out, b"v ", p)?;
        }
        let ts: Vec<f32> = (0..tw).map(|j| tex_t(g, j)).collect();
        for &u in &g.u {
            let s = u as f32;
            for &t in &ts {
                out.bytes(b"vt ");
                out.f32_text(s);
                out.bytes(b" ");
                out.f32_text(t);
                out.bytes(b"\n");
                out.tick()?;
            }
        }
        for n in &g.normals {
            obj_vec3(&mut out, b"vn ", n)?;
        }
        let cols = if g.periodic_v { nv } else { nv - 1 };
        for i in 0..nu - 1 {
            for j in 0..cols {
                let j1 = (j + 1) % nv;
                // Corners (i,j), (i+1,j), (i+1,j+1), (i,j+1) as in `Grid::quads`; the texture
                // column of the last corner pair is j+1 without wrapping.
                let corners = [
                    (i * nv + j, i * tw + j),
                    ((i + 1) * nv + j, (i + 1) * tw + j),
                    ((i + 1) * nv + j1, (i + 1) * tw + j + 1),
                    (i * nv + j1, i * tw + j + 1),
                ];
                out.bytes(b"f");
                for (p, t) in corners {
                    let p = pos_base + p as u64;
                    out.bytes(b" ");
                    out.uint_text(p);
                    out.bytes(b"/");
                    out.uint_text(tex_base + t as u64);
                    out.bytes(b"/");
                    out.uint_text(p);
                }
                out.bytes(b"\n");
                out.tick()?;
            }
        }
        pos_base += (nu * nv) as u64;
        tex_base += (nu * tw) as u64;
    }
    out.finish()
}

// ---------------------------------------------------------------------------------------------
// STL
// ---------------------------------------------------------------------------------------------

/// True when two corners of the triangle are the same point (as at a pole, where a whole grid row
/// collapses): such a triangle has no area and no facet direction.
fn degenerate(p: &[[f32; 3]], t: [u32; 3]) -> bool {
    let [a, b, c] = t.map(|i| p[i as usize]);
    a == b || b == c || a == c
}

/// Facet normal: the normalised mean of the three vertex normals, or the normalised geometric
/// normal `(b−a)×(c−a)` if that mean (nearly) vanishes, or zero if both vanish.
fn facet_normal(g: &GridMesh, t: [u32; 3]) -> [f32; 3] {
    let f = |a: [f32; 3]| a.map(f64::from);
    let [na, nb, nc] = t.map(|i| f(g.normals[i as usize]));
    let s = [
        na[0] + nb[0] + nc[0],
        na[1] + nb[1] + nc[1],
        na[2] + nb[2] + nc[2],
    ];
    let len = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    if len > 1e-6 {
        return s.map(|c| (c / len) as f32);
    }
    let [a, b, c] = t.map(|i| f(g.positions[i as usize]));
    let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
    let x = [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ];
    let len = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
    if len > 0.0 {
        x.map(|c| (c / len) as f32)
    } else {
        [0.0; 3]
    }
}

/// Binary STL (triangles, facet normals from the vertex normals).
///
/// An 80-byte header, the triangle count, then per triangle the facet normal (see below), the
/// three corners (counter-clockwise seen from the normal) and a zero attribute word. The triangles
/// are those of [`Grid::triangles`] for each patch in turn, except that triangles with two
/// coincident corners (bit-equal positions, as at a pole) are left out; the count in the header
/// is the number actually written. The facet normal is the normalised mean of the three vertex
/// normals, falling back to the normalised geometric normal if the mean vanishes.
pub fn write_stl(meshes: &[GridMesh], w: &mut dyn Write) -> Result<()> {
    check_grids(meshes, true)?;
    let mut count: u128 = 0;
    for g in meshes {
        count += g
            .triangles()
            .filter(|&t| !degenerate(&g.positions, t))
            .count() as u128;
    }
    let count = check_u32(count, "triangles", "STL")?;
    let mut out = Sink::new(w, "STL");
    let mut header = [b' '; 80];
    let text = b"pdeshape binary STL";
    header[..text.len()].copy_from_slice(text);
    out.bytes(&header);
    out.u32_le(count);
    for g in meshes {
        for t in g.triangles() {
            if degenerate(&g.positions, t) {
                continue;
            }
            for c in facet_normal(g, t) {
                out.f32_le(c);
            }
            for i in t {
                for c in g.positions[i as usize] {
                    out.f32_le(c);
                }
            }
            out.bytes(&[0, 0]);
            out.tick()?;
        }
    }
    out.finish()
}

// ---------------------------------------------------------------------------------------------
// PLY
// ---------------------------------------------------------------------------------------------

/// Binary little-endian PLY with positions, normals, uv and faces.
///
/// Element `vertex` holds `x y z nx ny nz u v` as floats for the `nu·nv` vertices of each patch in
/// turn (texture coordinates `(u_i, t_j)`, no seam duplication: a periodic patch's last column has
/// `t = v_{nv−1}/2π < 1`); element `face` holds the quads of [`Grid::quads`] as
/// `list uchar uint vertex_indices`, offset by the vertices of the previous patches.
pub fn write_ply(meshes: &[GridMesh], w: &mut dyn Write) -> Result<()> {
    check_grids(meshes, true)?;
    let vertices: u128 = meshes.iter().map(|g| g.len() as u128).sum();
    let faces: u128 = meshes.iter().map(|g| quad_count(g) as u128).sum();
    let vertices = check_u32(vertices, "vertices", "PLY")?;
    let faces = check_u32(faces, "faces", "PLY")?;
    let mut out = Sink::new(w, "PLY");
    out.bytes(b"ply\nformat binary_little_endian 1.0\ncomment pdeshape: ");
    out.uint_text(meshes.len() as u64);
    out.bytes(b" patch(es)\nelement vertex ");
    out.uint_text(vertices.into());
    out.bytes(
        b"\nproperty float x\nproperty float y\nproperty float z\n\
          property float nx\nproperty float ny\nproperty float nz\n\
          property float u\nproperty float v\nelement face ",
    );
    out.uint_text(faces.into());
    out.bytes(b"\nproperty list uchar uint vertex_indices\nend_header\n");
    for g in meshes {
        let ts: Vec<f32> = (0..g.nv).map(|j| tex_t(g, j)).collect();
        for i in 0..g.nu {
            let s = g.u[i] as f32;
            for (j, &t) in ts.iter().enumerate() {
                let idx = i * g.nv + j;
                for c in g.positions[idx] {
                    out.f32_le(c);
                }
                for c in g.normals[idx] {
                    out.f32_le(c);
                }
                out.f32_le(s);
                out.f32_le(t);
                out.tick()?;
            }
        }
    }
    let mut base: u32 = 0;
    for g in meshes {
        for q in g.quads() {
            out.bytes(&[4]);
            for i in q {
                out.u32_le(base + i);
            }
            out.tick()?;
        }
        // Fits: the total vertex count was checked above.
        base += g.len() as u32;
    }
    out.finish()
}

/// Number of quads (half the number of triangles) of a grid, as [`Grid::quads`] yields them.
fn quad_count<T>(g: &Grid<T>) -> usize {
    let cols = if g.periodic_v {
        g.nv
    } else {
        g.nv.saturating_sub(1)
    };
    g.nu.saturating_sub(1) * cols
}

// ---------------------------------------------------------------------------------------------
// GLB
// ---------------------------------------------------------------------------------------------

const GLB_MAGIC: u32 = 0x4654_6C67; // "glTF"
const GLB_JSON: u32 = 0x4E4F_534A; // "JSON"
const GLB_BIN: u32 = 0x004E_4942; // "BIN\0"
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;
const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;

/// Byte sizes of one patch's data in the binary chunk (every one a multiple of 4).
struct GlbPatch {
    vertices: usize,
    triangles: usize,
}

impl GlbPatch {
    fn of(g: &GridMesh) -> Self {
        let w = seam_columns(g);
        GlbPatch {
            vertices: g.nu * w,
            triangles: 2 * (g.nu - 1) * (w - 1),
        }
    }
    fn bytes(&self) -> u128 {
        // positions 12, normals 12, uv 8 bytes per vertex; 12 bytes per triangle.
        self.vertices as u128 * 32 + self.triangles as u128 * 12
    }
}

/// glTF 2.0 binary (`.glb`), one mesh primitive per patch.
///
/// One scene with one node and one mesh; the mesh has one triangle primitive (mode 4) per patch
/// with attributes `POSITION` (with its min/max), `NORMAL` and `TEXCOORD_0` and `u32` indices. A
/// periodic patch repeats its seam column as column `nv` (same position and normal, `t = 1`), so
/// it has `nu·(nv+1)` vertices and continuous texture coordinates; vertex `(i, j)` is
/// `i·W + j` with `W = nv` or `nv+1`, and the triangles are those of [`Grid::triangles`] in the
/// same order. All data sit in one buffer (the BIN chunk), one buffer view per attribute and patch,
/// every offset a multiple of 4.
pub fn write_glb(meshes: &[GridMesh], w: &mut dyn Write) -> Result<()> {
    use serde_json::{json, Value};
    check_grids(meshes, true)?;
    let patches: Vec<GlbPatch> = meshes.iter().map(GlbPatch::of).collect();
    for (k, p) in patches.iter().enumerate() {
        check_u32(3 * p.triangles as u128, "triangle indices", "glTF")
            .map_err(|e| e.at(&format!("patches[{k}]")))?;
    }
    let bin_len: u128 = patches.iter().map(GlbPatch::bytes).sum();

    let mut views: Vec<Value> = Vec::new();
    let mut accessors: Vec<Value> = Vec::new();
    let mut primitives: Vec<Value> = Vec::new();
    let mut offset: u128 = 0;
    for (g, p) in meshes.iter().zip(&patches) {
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for q in &g.positions {
            for c in 0..3 {
                lo[c] = lo[c].min(q[c]);
                hi[c] = hi[c].max(q[c]);
            }
        }
        let n = p.vertices as u128;
        let parts: [(u128, Option<u32>, u32); 4] = [
            (n * 12, Some(12), ARRAY_BUFFER),
            (n * 12, Some(12), ARRAY_BUFFER),
            (n * 8, Some(8), ARRAY_BUFFER),
            (p.triangles as u128 * 12, None, ELEMENT_ARRAY_BUFFER),
        ];
        let first = accessors.len();
        for (len, stride, target) in parts {
            let mut view = json!({
                "buffer": 0,
                "byteOffset": offset as u64,
                "byteLength": len as u64,
                "target": target,
            });
            if let Some(s) = stride {
                view["byteStride"] = json!(s);
            }
            views.push(view);
            offset += len;
        }
        accessors.push(json!({
            "bufferView": first, "componentType": FLOAT, "count": p.vertices, "type": "VEC3",
            "min": lo, "max": hi,
        }));
        accessors.push(json!({
            "bufferView": first + 1, "componentType": FLOAT, "count": p.vertices, "type": "VEC3",
        }));
        accessors.push(json!({
            "bufferView": first + 2, "componentType": FLOAT, "count": p.vertices, "type": "VEC2",
        }));
        accessors.push(json!({
            "bufferView": first + 3, "componentType": UNSIGNED_INT, "count": 3 * p.triangles,
            "type": "SCALAR",
        }));
        primitives.push(json!({
            "attributes": { "POSITION": first, "NORMAL": first + 1, "TEXCOORD_0": first + 2 },
            "indices": first + 3,
            "mode": 4,
        }));
    }
    debug_assert_eq!(offset, bin_len);
    let doc = json!({
        "asset": { "version": "2.0", "generator": "pdeshape" },
        "scene": 0,
        "scenes": [ { "nodes": [0] } ],
        "nodes": [ { "mesh": 0, "name": "pdeshape" } ],
        "meshes": [ { "name": "pdeshape", "primitives": primitives } ],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [ { "byteLength": bin_len as u64 } ],
    });
    let mut json_bytes =
        serde_json::to_vec(&doc).map_err(|e| Error::io(format!("writing glTF JSON: {e}")))?;
    while json_bytes.len() % 4 != 0 {
        json_bytes.push(b' ');
    }
    let bin_padded = bin_len.next_multiple_of(4);
    let total = 12 + 8 + json_bytes.len() as u128 + 8 + bin_padded;
    let total = check_u32(total, "bytes", "GLB")?;

    let mut out = Sink::new(w, "GLB");
    out.u32_le(GLB_MAGIC);
    out.u32_le(2);
    out.u32_le(total);
    out.u32_le(json_bytes.len() as u32);
    out.u32_le(GLB_JSON);
    out.bytes(&json_bytes);
    out.u32_le(bin_padded as u32);
    out.u32_le(GLB_BIN);
    for (g, p) in meshes.iter().zip(&patches) {
        let (nu, nv) = (g.nu, g.nv);
        let width = seam_columns(g);
        // Vertex (i, j) of the written patch is grid vertex (i, j mod nv).
        let source = |i: usize, j: usize| i * nv + j % nv;
        for i in 0..nu {
            for j in 0..width {
                for c in g.positions[source(i, j)] {
                    out.f32_le(c);
                }
            }
            out.tick()?;
        }
        for i in 0..nu {
            for j in 0..width {
                for c in g.normals[source(i, j)] {
                    out.f32_le(c);
                }
            }
            out.tick()?;
        }
        let ts: Vec<f32> = (0..width).map(|j| tex_t(g, j)).collect();
        for i in 0..nu {
            let s = g.u[i] as f32;
            for &t in &ts {
                out.f32_le(s);
                out.f32_le(t);
            }
            out.tick()?;
        }
        let mut written = 0usize;
        for i in 0..nu - 1 {
            for j in 0..width - 1 {
                let a = (i * width + j) as u32;
                let b = ((i + 1) * width + j) as u32;
                let c = b + 1;
                let d = a + 1;
                for x in [a, b, c, a, c, d] {
                    out.u32_le(x);
                }
                written += 2;
            }
            out.tick()?;
        }
        debug_assert_eq!(written, p.triangles);
    }
    // The binary parts are all multiples of 4 bytes; pad anyway should that ever change.
    for _ in bin_len..bin_padded {
        out.bytes(&[0]);
    }
    out.finish()
}

// ---------------------------------------------------------------------------------------------
// CSV
// ---------------------------------------------------------------------------------------------

/// CSV samples `u,v,x,y,z,nx,ny,nz` (plus `patch` when there are several), rows u-major.
///
/// One row per grid vertex `(i, j)`, `i` outer and `j` inner, with the grid's parameter values
/// `u_i`, `v_j`, the position and the unit normal; with several patches a ninth column holds the
/// 0-based patch number and the patches follow one another. Every number is the shortest decimal
/// text that reads back to the identical `f64`.
pub fn write_csv(samples: &[Samples], w: &mut dyn Write) -> Result<()> {
    check_grids(samples, false)?;
    let several = samples.len() > 1;
    let mut out = Sink::new(w, "CSV");
    out.bytes(if several {
        b"u,v,x,y,z,nx,ny,nz,patch\n"
    } else {
        b"u,v,x,y,z,nx,ny,nz\n"
    });
    for (k, g) in samples.iter().enumerate() {
        for i in 0..g.nu {
            let u = g.u[i];
            for j in 0..g.nv {
                let idx = i * g.nv + j;
                out.f64_text(u);
                out.bytes(b",");
                out.f64_text(g.v[j]);
                for c in g.positions[idx].into_iter().chain(g.normals[idx]) {
                    out.bytes(b",");
                    out.f64_text(c);
                }
                if several {
                    out.bytes(b",");
                    out.uint_text(k as u64);
                }
                out.bytes(b"\n");
                out.tick()?;
            }
        }
    }
    out.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integer_and_float_text() {
        let mut dest = Vec::new();
        let mut out = Sink::new(&mut dest, "test");
        for x in [0, 7, 10, 99, 100, 4_294_967_295, u64::MAX] {
            out.uint_text(x);
            out.bytes(b" ");
        }
        out.f32_text(0.1);
        out.bytes(b" ");
        out.f32_text(-0.0);
        out.bytes(b" ");
        out.f64_text(0.1 + 0.2);
        out.finish().unwrap();
        assert_eq!(
            String::from_utf8(dest).unwrap(),
            "0 7 10 99 100 4294967295 18446744073709551615 0.1 -0.0 0.30000000000000004"
        );
    }
}
