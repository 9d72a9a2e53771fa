//! Writers. Mesh formats (OBJ, STL, PLY, GLB) are written from one indexed [`TriMesh`] (see
//! [`super::weld`] for how a design's grids become one) with a [`MeshInfo`]: the title, the
//! length unit, a scale and the up axis; CSV is written from full-precision grids.
//!
//! Every writer first checks all of its input (at least one triangle or patch, consistent array
//! lengths, finite values, index ranges that fit the format) and only then writes, so a refused
//! input never leaves a truncated or broken file behind. The bytes are assembled in chunk
//! buffers of about a megabyte on a second thread while the calling thread hands the previous
//! one to the destination with `write_all`, in one pass, so the destination needs no buffering
//! of its own.

use super::weld::{weld, WeldOptions};
use super::{Grid, GridMesh, Part, Samples, TriMesh};
pub use crate::spec::Units;
use crate::{Error, Result};
use rayon::prelude::*;
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

    /// True for the mesh formats (written from a [`TriMesh`]); false for CSV, which is
    /// written from full-precision [`Samples`].
    pub fn is_mesh(self) -> bool {
        self != Format::Csv
    }
}

/// Writes a mesh in a mesh format (obj, stl, ply, glb); CSV, which stores full-precision
/// samples, is written by [`write_csv`].
pub fn write_mesh(
    format: Format,
    mesh: &TriMesh,
    info: &MeshInfo,
    w: &mut dyn Write,
) -> Result<()> {
    match format {
        Format::Obj => write_obj(mesh, info, w),
        Format::Stl => write_stl(mesh, info, w),
        Format::Ply => write_ply(mesh, info, w),
        Format::Glb => write_glb(mesh, info, w),
        Format::Csv => Err(Error::invalid(
            "csv stores full-precision samples: write them with write_csv",
        )),
    }
}

/// Writes grids (patches `patch0`, `patch1`, …) in a mesh format: checked, then welded and
/// oriented by [`weld`] with the default options, then [`write_mesh`] with the default
/// [`MeshInfo`].
pub fn write(format: Format, meshes: &[GridMesh], w: &mut dyn Write) -> Result<()> {
    if format == Format::Csv {
        return write_mesh(format, &TriMesh::default(), &MeshInfo::default(), w);
    }
    check_grids(meshes, true)?;
    let mesh = weld(meshes, &[], WeldOptions::default());
    write_mesh(format, &mesh, &MeshInfo::default(), w)
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

/// A byte buffer that is passed on to the destination whenever it holds about [`CHUNK`]
/// bytes.
struct Sink {
    buf: Vec<u8>,
    /// To the thread that writes the full buffers ([`stream`]).
    full: std::sync::mpsc::SyncSender<Vec<u8>>,
    /// The emptied buffers it hands back.
    empty: std::sync::mpsc::Receiver<Vec<u8>>,
    what: &'static str,
    float: ryu::Buffer,
}

/// Runs `body` on a second thread while this one writes the chunks it fills to `w`, in order:
/// encoding the next megabyte overlaps handing the last one to the operating system (for a
/// file, copying it into the page cache). Three buffers circulate; nothing else is allocated.
/// A write error stops the encoding and is the error reported; then `w` is flushed.
fn stream<F>(w: &mut dyn Write, what: &'static str, body: F) -> Result<()>
where
    F: FnOnce(&mut Sink) -> Result<()> + Send,
{
    use std::sync::mpsc::{channel, sync_channel};
    let (full_tx, full_rx) = sync_channel::<Vec<u8>>(2);
    let (empty_tx, empty_rx) = channel::<Vec<u8>>();
    for _ in 0..2 {
        empty_tx
            .send(Vec::with_capacity(CHUNK + 4096))
            .expect("the receiver is alive");
    }
    let io = |e: std::io::Error| Error::io(format!("writing {what}: {e}"));
    std::thread::scope(|scope| {
        let producer = scope.spawn(move || {
            let mut sink = Sink {
                buf: Vec::with_capacity(CHUNK + 4096),
                full: full_tx,
                empty: empty_rx,
                what,
                float: ryu::Buffer::new(),
            };
            body(&mut sink)?;
            sink.drain()
        });
        let mut written = Ok(());
        for chunk in full_rx.iter() {
            if let Err(e) = w.write_all(&chunk) {
                written = Err(io(e));
                break;
            }
            // The producer may have finished: then the buffer is not needed.
            let _ = empty_tx.send(chunk);
        }
        // Unblocks a producer still sending, or waiting for a buffer, after a write error.
        drop(full_rx);
        drop(empty_tx);
        let produced = match producer.join() {
            Ok(r) => r,
            Err(panic) => std::panic::resume_unwind(panic),
        };
        written?;
        produced?;
        w.flush().map_err(io)
    })
}

impl Sink {
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
        // A closed channel means the writing side stopped on an error, which it reports.
        let stopped = || Error::io(format!("writing {what}: stopped"));
        let next = self.empty.recv().map_err(|_| stopped())?;
        let buf = std::mem::replace(&mut self.buf, next);
        self.full.send(buf).map_err(|_| stopped())?;
        self.buf.clear();
        Ok(())
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

    /// Three floats, little-endian, in one copy.
    #[inline]
    fn f32x3_le(&mut self, v: [f32; 3]) {
        let mut b = [0u8; 12];
        for (dst, x) in b.chunks_exact_mut(4).zip(v) {
            dst.copy_from_slice(&x.to_le_bytes());
        }
        self.buf.extend_from_slice(&b);
    }

    /// Many integers, little-endian, passing the buffer on as it fills.
    fn u32s_le(&mut self, xs: &[u32]) -> Result<()> {
        for chunk in xs.chunks(CHUNK / 4) {
            #[cfg(target_endian = "little")]
            {
                // SAFETY: a `u32` slice viewed as its bytes (alignment 1, same length in bytes);
                // on a little-endian machine those are the little-endian encodings.
                let bytes = unsafe {
                    std::slice::from_raw_parts(chunk.as_ptr().cast::<u8>(), 4 * chunk.len())
                };
                self.buf.extend_from_slice(bytes);
            }
            #[cfg(not(target_endian = "little"))]
            for &x in chunk {
                self.u32_le(x);
            }
            self.tick()?;
        }
        Ok(())
    }
}

// ---------------------------------------------------------------------------------------------
// What a file says about its mesh
// ---------------------------------------------------------------------------------------------

/// The axis that points up in a written file. Designs are modelled `+Z` up.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Up {
    /// As designed (the default for OBJ, STL and PLY).
    #[default]
    Z,
    /// Turned so that the design's `+Z` becomes `+Y`: `(x, y, z) → (x, z, −y)` (a rotation, so
    /// orientation and volume are kept). glTF is always written this way.
    Y,
}

impl Up {
    /// `+Z` or `+Y`.
    pub fn label(self) -> &'static str {
        match self {
            Up::Z => "+Z",
            Up::Y => "+Y",
        }
    }
}

/// What the writers record beside the triangles: the design's title, its length unit, a scale
/// and the up axis of the file.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshInfo {
    pub title: Option<String>,
    /// The unit of the design's coordinates (times `scale`).
    pub units: Units,
    /// A factor applied to every position (finite and positive).
    pub scale: f64,
    /// The up axis of OBJ, STL and PLY files (glTF is always `+Y` up).
    pub up: Up,
}

impl Default for MeshInfo {
    fn default() -> Self {
        MeshInfo {
            title: None,
            units: Units::default(),
            scale: 1.0,
            up: Up::Z,
        }
    }
}

/// The generator named in every file.
const GENERATOR: &str = concat!("pdeshape ", env!("CARGO_PKG_VERSION"));

/// A position and normal map `p → k·R p`, `n → R n`.
#[derive(Clone, Copy)]
struct Frame {
    k: f64,
    y_up: bool,
}

impl Frame {
    fn new(info: &MeshInfo, format: Format) -> Result<Frame> {
        if !(info.scale.is_finite() && info.scale > 0.0) {
            return Err(Error::invalid(format!(
                "must be finite and positive (got {})",
                info.scale
            ))
            .at("scale"));
        }
        Ok(match format {
            // glTF: metres, +Y up.
            Format::Glb => Frame {
                k: info.scale * info.units.metres(),
                y_up: true,
            },
            _ => Frame {
                k: info.scale,
                y_up: info.up == Up::Y,
            },
        })
    }

    #[inline(always)]
    fn turn(&self, p: [f64; 3]) -> [f64; 3] {
        if self.y_up {
            [p[0], p[2], -p[1]]
        } else {
            p
        }
    }

    #[inline(always)]
    fn point(&self, p: [f32; 3]) -> [f32; 3] {
        if self.k == 1.0 && !self.y_up {
            return p;
        }
        self.turn(p.map(f64::from)).map(|c| (c * self.k) as f32)
    }

    #[inline(always)]
    fn normal(&self, n: [f32; 3]) -> [f32; 3] {
        if self.y_up {
            [n[0], n[2], -n[1]]
        } else {
            n
        }
    }
}

/// A part's name as one token (whitespace and control characters become `_`; empty names
/// `part<k>`).
fn token(name: &str, k: usize) -> String {
    let t: String = name
        .chars()
        .map(|c| {
            if c.is_whitespace() || c.is_control() {
                '_'
            } else {
                c
            }
        })
        .collect();
    if t.is_empty() {
        format!("part{k}")
    } else {
        t
    }
}

/// A text on one line (line breaks become spaces).
fn one_line(text: &str) -> String {
    text.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}

/// The parts of a mesh: its own, or one unnamed part with every triangle.
fn parts_of(mesh: &TriMesh) -> Vec<Part> {
    if mesh.parts.is_empty() {
        vec![Part {
            name: "mesh".to_string(),
            triangles: 0..mesh.triangles.len(),
        }]
    } else {
        mesh.parts.clone()
    }
}

/// Checks a mesh before anything is written: structure ([`TriMesh::check`]), at least one
/// triangle, finite positions, normals and texture coordinates.
fn check_mesh(mesh: &TriMesh) -> Result<()> {
    mesh.check().map_err(|e| Error::invalid(e).at("mesh"))?;
    if mesh.triangles.is_empty() {
        return Err(Error::invalid(
            "no triangles to write: the design produced no surface",
        ));
    }
    for (name, data) in [("position", &mesh.positions), ("normal", &mesh.normals)] {
        let bad = data
            .par_iter()
            .with_min_len(1 << 14)
            .position_first(|p| !p.iter().all(|c| c.is_finite()));
        if let Some(idx) = bad {
            let p = data[idx];
            return Err(Error::invalid(format!(
                "non-finite {name} [{}, {}, {}] at vertex {idx}",
                p[0], p[1], p[2]
            ))
            .at("mesh"));
        }
    }
    if let Some(idx) = mesh
        .uv
        .iter()
        .position(|p| !p.iter().all(|c| c.is_finite()))
    {
        return Err(Error::invalid(format!("non-finite uv at vertex {idx}")).at("mesh"));
    }
    Ok(())
}

/// The unit line every text header carries.
fn units_text(info: &MeshInfo) -> String {
    format!(
        "units: {} (1 unit = {} m); up: {}",
        info.units.as_str(),
        info.units.metres(),
        info.up.label()
    )
}

/// `(b − a) × (c − a)` normalised, or zero for a triangle without area.
fn facet_normal(a: [f32; 3], b: [f32; 3], c: [f32; 3]) -> [f32; 3] {
    let x = super::weld::facet_cross(&[a, b, c], [0, 1, 2]);
    let len = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
    if len > 0.0 && len.is_finite() {
        x.map(|c| (c / len) as f32)
    } else {
        [0.0; 3]
    }
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

/// Wavefront OBJ: comments with the generator, title, units and up axis; every vertex `v` and
/// normal `vn` (and `vt` when the mesh has texture coordinates), numbered alike; then each part
/// as an object `o <name>` with its triangles `f a//a b//b c//c` (or `a/a/a`), counter-clockwise
/// seen from the normals. Numbers are the shortest text that reads back to the identical `f32`.
pub fn write_obj(mesh: &TriMesh, info: &MeshInfo, w: &mut dyn Write) -> Result<()> {
    check_mesh(mesh)?;
    let frame = Frame::new(info, Format::Obj)?;
    let parts = parts_of(mesh);
    stream(w, "OBJ", |out| {
        out.bytes(format!("# {GENERATOR} OBJ\n").as_bytes());
        if let Some(t) = &info.title {
            out.bytes(format!("# title: {}\n", one_line(t)).as_bytes());
        }
        out.bytes(format!("# {}\n", units_text(info)).as_bytes());
        let names: Vec<String> = parts
            .iter()
            .enumerate()
            .map(|(k, p)| token(&p.name, k))
            .collect();
        out.bytes(format!("# parts: {}\n", names.join(" ")).as_bytes());
        for p in &mesh.positions {
            obj_vec3(out, b"v ", &frame.point(*p))?;
        }
        for n in &mesh.normals {
            obj_vec3(out, b"vn ", &frame.normal(*n))?;
        }
        let with_uv = !mesh.uv.is_empty();
        for t in &mesh.uv {
            out.bytes(b"vt ");
            out.f32_text(t[0]);
            out.bytes(b" ");
            out.f32_text(t[1]);
            out.bytes(b"\n");
            out.tick()?;
        }
        for (part, name) in parts.iter().zip(&names) {
            out.bytes(b"o ");
            out.bytes(name.as_bytes());
            out.bytes(b"\n");
            for t in &mesh.triangles[part.triangles.clone()] {
                out.bytes(b"f");
                for &i in t {
                    let i = u64::from(i) + 1;
                    out.bytes(b" ");
                    out.uint_text(i);
                    out.bytes(if with_uv { b"/" } else { b"//" });
                    if with_uv {
                        out.uint_text(i);
                        out.bytes(b"/");
                    }
                    out.uint_text(i);
                }
                out.bytes(b"\n");
                out.tick()?;
            }
        }
        Ok(())
    })
}

// ---------------------------------------------------------------------------------------------
// STL
// ---------------------------------------------------------------------------------------------

/// Binary STL. The 80-byte header names the generator, units, up axis and parts (cut at 80
/// bytes; it never begins with `solid`); then the triangle count and per triangle the facet
/// normal computed from the facet, `(b − a) × (c − a)` normalised (zero for a triangle without
/// area), the three corners counter-clockwise seen from it, and a zero attribute word.
pub fn write_stl(mesh: &TriMesh, info: &MeshInfo, w: &mut dyn Write) -> Result<()> {
    check_mesh(mesh)?;
    let frame = Frame::new(info, Format::Stl)?;
    let count = check_u32(mesh.triangles.len() as u128, "triangles", "STL")?;
    let parts = parts_of(mesh);
    let names: Vec<String> = parts
        .iter()
        .enumerate()
        .map(|(k, p)| token(&p.name, k))
        .collect();
    let text = format!(
        "{GENERATOR} binary STL; units {}; up {}; parts {}",
        info.units.as_str(),
        info.up.label(),
        names.join(",")
    );
    let mut header = [b' '; 80];
    let n = text.len().min(80);
    header[..n].copy_from_slice(&text.as_bytes()[..n]);
    stream(w, "STL", |out| {
        out.bytes(&header);
        out.u32_le(count);
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|i| frame.point(mesh.positions[i as usize]));
            // One record: facet normal, three corners, a zero attribute word.
            let mut record = [0u8; 50];
            for (k, v) in [facet_normal(a, b, c), a, b, c].into_iter().enumerate() {
                for (q, x) in v.into_iter().enumerate() {
                    let at = 12 * k + 4 * q;
                    record[at..at + 4].copy_from_slice(&x.to_le_bytes());
                }
            }
            out.bytes(&record);
            out.tick()?;
        }
        Ok(())
    })
}

// ---------------------------------------------------------------------------------------------
// PLY
// ---------------------------------------------------------------------------------------------

/// Binary little-endian PLY. Comments name the generator, title, units, up axis and each part
/// with its range of faces (`comment part <name> faces <first> <count>`); element `vertex` holds
/// `x y z nx ny nz` as floats (and `u v` when the mesh has texture coordinates); element `face`
/// holds the triangles as `list uchar uint vertex_indices`, parts one after another.
pub fn write_ply(mesh: &TriMesh, info: &MeshInfo, w: &mut dyn Write) -> Result<()> {
    check_mesh(mesh)?;
    let frame = Frame::new(info, Format::Ply)?;
    let vertices = check_u32(mesh.positions.len() as u128, "vertices", "PLY")?;
    let faces = check_u32(mesh.triangles.len() as u128, "faces", "PLY")?;
    let with_uv = !mesh.uv.is_empty();
    let mut head = String::from("ply\nformat binary_little_endian 1.0\n");
    head += &format!("comment {GENERATOR}\n");
    if let Some(t) = &info.title {
        head += &format!("comment title {}\n", one_line(t));
    }
    head += &format!("comment {}\n", units_text(info));
    for (k, p) in parts_of(mesh).iter().enumerate() {
        head += &format!(
            "comment part {} faces {} {}\n",
            token(&p.name, k),
            p.triangles.start,
            p.triangles.len()
        );
    }
    head += &format!("element vertex {vertices}\n");
    head += "property float x\nproperty float y\nproperty float z\n\
             property float nx\nproperty float ny\nproperty float nz\n";
    if with_uv {
        head += "property float u\nproperty float v\n";
    }
    head += &format!("element face {faces}\nproperty list uchar uint vertex_indices\nend_header\n");
    stream(w, "PLY", |out| {
        out.bytes(head.as_bytes());
        for (k, (p, n)) in mesh.positions.iter().zip(&mesh.normals).enumerate() {
            out.f32x3_le(frame.point(*p));
            out.f32x3_le(frame.normal(*n));
            if with_uv {
                out.f32_le(mesh.uv[k][0]);
                out.f32_le(mesh.uv[k][1]);
            }
            out.tick()?;
        }
        for t in &mesh.triangles {
            let mut record = [3u8; 13];
            for (k, &i) in t.iter().enumerate() {
                record[1 + 4 * k..5 + 4 * k].copy_from_slice(&i.to_le_bytes());
            }
            out.bytes(&record);
            out.tick()?;
        }
        Ok(())
    })
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

/// The vertices one part uses, in first-use order, and its triangles in that numbering.
struct GlbPart {
    vertices: Vec<u32>,
    triangles: std::ops::Range<usize>,
    local: Vec<u32>,
}

use super::weld::is_closed;

/// glTF 2.0 binary (`.glb`) in glTF's conventions: `+Y` up (the design's `+Z` turned to `+Y`,
/// `(x, y, z) → (x, z, −y)`) and metres (positions times `scale` and the metres per unit).
///
/// One scene with a root node named after the design's title, with one child node and one mesh
/// per part, both named after the part; each mesh has one triangle primitive (mode 4) with
/// `POSITION` (with min/max), `NORMAL`, `TEXCOORD_0` only when the mesh has texture coordinates,
/// and `u32` indices, using one material: double-sided when the mesh is open (has edges used by
/// one triangle), so both sides of an open surface show. Each part has its own vertices (a
/// vertex on a shared edge is written once per part, at the same position). `asset` names the
/// generator (with pdeshape's version) and carries the title, units and scale in `extras`.
pub fn write_glb(mesh: &TriMesh, info: &MeshInfo, w: &mut dyn Write) -> Result<()> {
    use serde_json::{json, Value};
    check_mesh(mesh)?;
    let frame = Frame::new(info, Format::Glb)?;
    let with_uv = !mesh.uv.is_empty();
    let all = parts_of(mesh);
    // Vertex numbering per part (parts in parallel, each thread with its own slot table,
    // restored to empty after every part).
    let glb_parts: Vec<GlbPart> = all
        .par_iter()
        .map_init(
            || vec![u32::MAX; mesh.positions.len()],
            |slot, p| {
                let mut vertices = Vec::new();
                let mut local = Vec::with_capacity(3 * p.triangles.len());
                for t in &mesh.triangles[p.triangles.clone()] {
                    for &i in t {
                        let s = &mut slot[i as usize];
                        if *s == u32::MAX {
                            *s = vertices.len() as u32;
                            vertices.push(i);
                        }
                        local.push(*s);
                    }
                }
                for &i in &vertices {
                    slot[i as usize] = u32::MAX;
                }
                GlbPart {
                    vertices,
                    triangles: p.triangles.clone(),
                    local,
                }
            },
        )
        .collect();
    let vertex_bytes: u128 = if with_uv { 32 } else { 24 };
    let mut views: Vec<Value> = Vec::new();
    let mut accessors: Vec<Value> = Vec::new();
    let mut meshes: Vec<Value> = Vec::new();
    let mut nodes: Vec<Value> = Vec::new();
    let mut offset: u128 = 0;
    for (k, (p, gp)) in all.iter().zip(&glb_parts).enumerate() {
        if gp.vertices.is_empty() {
            continue;
        }
        check_u32(gp.local.len() as u128, "triangle indices", "glTF")
            .map_err(|e| e.at(&format!("parts[{k}]")))?;
        let mut lo = [f32::INFINITY; 3];
        let mut hi = [f32::NEG_INFINITY; 3];
        for &i in &gp.vertices {
            let q = frame.point(mesh.positions[i as usize]);
            for c in 0..3 {
                lo[c] = lo[c].min(q[c]);
                hi[c] = hi[c].max(q[c]);
            }
        }
        let n = gp.vertices.len() as u128;
        let mut layout: Vec<(u128, Option<u32>, u32)> = vec![
            (n * 12, Some(12), ARRAY_BUFFER),
            (n * 12, Some(12), ARRAY_BUFFER),
        ];
        if with_uv {
            layout.push((n * 8, Some(8), ARRAY_BUFFER));
        }
        layout.push((gp.local.len() as u128 * 4, None, ELEMENT_ARRAY_BUFFER));
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
            "bufferView": first, "componentType": FLOAT, "count": gp.vertices.len(),
            "type": "VEC3", "min": lo, "max": hi,
        }));
        accessors.push(json!({
            "bufferView": first + 1, "componentType": FLOAT, "count": gp.vertices.len(),
            "type": "VEC3",
        }));
        let mut attributes = json!({ "POSITION": first, "NORMAL": first + 1 });
        let mut next = first + 2;
        if with_uv {
            accessors.push(json!({
                "bufferView": next, "componentType": FLOAT, "count": gp.vertices.len(),
                "type": "VEC2",
            }));
            attributes["TEXCOORD_0"] = json!(next);
            next += 1;
        }
        accessors.push(json!({
            "bufferView": next, "componentType": UNSIGNED_INT, "count": gp.local.len(),
            "type": "SCALAR",
        }));
        let name = if p.name.is_empty() {
            format!("part{k}")
        } else {
            p.name.clone()
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
        "materials": [ {
            "name": "pdeshape surface",
            "pbrMetallicRoughness": {
                "baseColorFactor": [0.8, 0.8, 0.82, 1.0],
                "metallicFactor": 0.0,
                "roughnessFactor": 0.6,
            },
            "doubleSided": !is_closed(mesh),
        } ],
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
    let _ = vertex_bytes;

    stream(w, "GLB", |out| {
        out.u32_le(GLB_MAGIC);
        out.u32_le(2);
        out.u32_le(total);
        out.u32_le(json_bytes.len() as u32);
        out.u32_le(GLB_JSON);
        out.bytes(&json_bytes);
        out.u32_le(bin_padded as u32);
        out.u32_le(GLB_BIN);
        for gp in &glb_parts {
            if gp.vertices.is_empty() {
                continue;
            }
            for chunk in gp.vertices.chunks(4096) {
                for &i in chunk {
                    out.f32x3_le(frame.point(mesh.positions[i as usize]));
                }
                out.tick()?;
            }
            for chunk in gp.vertices.chunks(4096) {
                for &i in chunk {
                    out.f32x3_le(frame.normal(mesh.normals[i as usize]));
                }
                out.tick()?;
            }
            if with_uv {
                for chunk in gp.vertices.chunks(4096) {
                    for &i in chunk {
                        out.f32_le(mesh.uv[i as usize][0]);
                        out.f32_le(mesh.uv[i as usize][1]);
                    }
                    out.tick()?;
                }
            }
            debug_assert_eq!(gp.local.len(), 3 * gp.triangles.len());
            out.u32s_le(&gp.local)?;
        }
        for _ in bin_len..bin_padded {
            out.bytes(&[0]);
        }
        Ok(())
    })
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
    stream(w, "CSV", |out| {
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
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integer_and_float_text() {
        let mut dest = Vec::new();
        stream(&mut dest, "test", |out| {
            for x in [0, 7, 10, 99, 100, 4_294_967_295, u64::MAX] {
                out.uint_text(x);
                out.bytes(b" ");
            }
            out.f32_text(0.1);
            out.bytes(b" ");
            out.f32_text(-0.0);
            out.bytes(b" ");
            out.f64_text(0.1 + 0.2);
            Ok(())
        })
        .unwrap();
        assert_eq!(
            String::from_utf8(dest).unwrap(),
            "0 7 10 99 100 4294967295 18446744073709551615 0.1 -0.0 0.30000000000000004"
        );
    }
}
