//! Writers. Mesh formats (OBJ, STL, PLY, GLB) are written from one indexed [`TriMesh`] (see
//! [`crate::mesh::weld`] for how a design's grids become one) with a [`MeshInfo`]: the title, the
//! length unit, a scale and the up axis; CSV is written from full-precision grids.
//!
//! Every writer first checks all of its input (at least one triangle or patch, consistent array
//! lengths, finite values, index ranges that fit the format) and only then writes, so a refused
//! input never leaves a truncated or broken file behind. The bytes are assembled in chunk
//! buffers of about a megabyte on a second thread while the calling thread hands the previous
//! one to the destination with `write_all`, in one pass, so the destination needs no buffering
//! of its own.

use crate::mesh::weld::{weld, WeldOptions};
pub use crate::mesh::Up;
use crate::mesh::{Grid, GridMesh, Part, Samples, TriMesh};
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
    /// The format for a path's extension (case-insensitive): obj, stl, ply, glb, csv (the
    /// mesh and sample formats of [`crate::format::OutputFormat::from_path`]).
    pub fn from_path(path: &std::path::Path) -> Result<Format> {
        match crate::format::OutputFormat::from_path(path)? {
            f if f.is_cad() => {
                let ext = path.extension().unwrap_or_default().to_string_lossy();
                Err(Error::invalid(format!(
                    "unknown output extension '.{ext}': {EXTENSIONS_HINT}"
                )))
            }
            f => f.mesh(),
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

/// Writes grids (patches `patch0`, `patch1`, …) in a mesh format, welded and oriented by
/// [`weld`] with the default options ([`write_welded`] with the default [`MeshInfo`]).
pub fn write(format: Format, meshes: &[GridMesh], w: &mut dyn Write) -> Result<()> {
    write_welded(
        format,
        meshes,
        &[],
        WeldOptions::default(),
        &MeshInfo::default(),
        w,
    )
}

/// Writes a design's grids in a mesh format as [`write_mesh`] writes `weld(grids, names,
/// options)`, byte for byte: checked first; GLB straight from the grids
/// ([`write_glb_grids`]), the other formats from the welded mesh.
pub fn write_welded(
    format: Format,
    grids: &[GridMesh],
    names: &[&str],
    options: WeldOptions,
    info: &MeshInfo,
    w: &mut dyn Write,
) -> Result<()> {
    match format {
        Format::Csv => write_mesh(format, &TriMesh::default(), info, w),
        Format::Glb => write_glb_grids(grids, names, options, info, w),
        _ => {
            check_grids(grids, true)?;
            write_mesh(format, &weld(grids, names, options), info, w)
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Input checks
// ---------------------------------------------------------------------------------------------

/// Checks the patches before anything is written: at least one patch; array lengths that agree
/// with `nu × nv`; finite parameter values, positions and normals; and, for the mesh formats
/// (`need_faces`), at least one face per patch.
fn check_grids<T: Copy + Into<f64> + Sync>(grids: &[Grid<T>], need_faces: bool) -> Result<()> {
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

fn check_grid<T: Copy + Into<f64> + Sync>(g: &Grid<T>, need_faces: bool) -> Result<()> {
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
        let bad = crate::mesh::first_bad(data, |p| {
            !p.iter().all(|&c| Into::<f64>::into(c).is_finite())
        });
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

/// Full buffers that may wait for the writing thread: enough for the encoders to run a batch of
/// blocks ahead of it.
const QUEUED: usize = 6;

/// Bytes being assembled, with the number formatting of the text formats.
struct Text {
    buf: Vec<u8>,
    float: ryu::Buffer,
}

impl Text {
    fn new(buf: Vec<u8>) -> Text {
        Text {
            buf,
            float: ryu::Buffer::new(),
        }
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
    fn u32_le(&mut self, x: u32) {
        self.buf.extend_from_slice(&x.to_le_bytes());
    }

    /// One record of `N` bytes for each `k` of `range`, `record(k)`, straight into the buffer.
    #[inline(always)]
    fn records<const N: usize>(
        &mut self,
        range: std::ops::Range<usize>,
        record: impl Fn(usize) -> [u8; N],
    ) {
        let n = range.len();
        let start = self.buf.len();
        self.buf.reserve(n * N);
        let dst = self.buf.spare_capacity_mut()[..n * N]
            .as_mut_ptr()
            .cast::<u8>();
        for (r, k) in range.enumerate() {
            let bytes = record(k);
            // SAFETY: `dst` points to `n·N` reserved bytes; record `r` fills its own `N`.
            unsafe { std::ptr::copy_nonoverlapping(bytes.as_ptr(), dst.add(r * N), N) };
        }
        // SAFETY: the loop wrote all `n·N` bytes after `start`.
        unsafe { self.buf.set_len(start + n * N) };
    }
}

/// A byte buffer that is passed on to the destination whenever it holds about [`CHUNK`]
/// bytes, and blocks of records encoded on the thread pool ([`Sink::blocks`]).
struct Sink {
    text: Text,
    /// To the thread that writes the full buffers ([`stream`]).
    full: std::sync::mpsc::SyncSender<Vec<u8>>,
    /// The emptied buffers it hands back.
    empty: std::sync::mpsc::Receiver<Vec<u8>>,
    what: &'static str,
}

impl std::ops::Deref for Sink {
    type Target = Text;
    fn deref(&self) -> &Text {
        &self.text
    }
}

impl std::ops::DerefMut for Sink {
    fn deref_mut(&mut self) -> &mut Text {
        &mut self.text
    }
}

/// Runs `body` on a second thread while this one writes the chunks it fills to `w`, in order:
/// encoding the next megabytes (on the thread pool, for [`Sink::blocks`]) overlaps handing the
/// last ones to the operating system (for a file, copying them into the page cache). Emptied
/// buffers come back to be filled again. A write error stops the encoding and is the error
/// reported; then `w` is flushed.
fn stream<F>(w: &mut dyn Write, what: &'static str, body: F) -> Result<()>
where
    F: FnOnce(&mut Sink) -> Result<()> + Send,
{
    use std::sync::mpsc::{channel, sync_channel};
    let (full_tx, full_rx) = sync_channel::<Vec<u8>>(QUEUED);
    let (empty_tx, empty_rx) = channel::<Vec<u8>>();
    let io = |e: std::io::Error| Error::io_from(format!("writing {what}: {e}"), e);
    std::thread::scope(|scope| {
        let producer = scope.spawn(move || {
            let mut sink = Sink {
                text: Text::new(Vec::with_capacity(CHUNK + 4096)),
                full: full_tx,
                empty: empty_rx,
                what,
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
        // Unblocks a producer still sending after a write error.
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
        if self.text.buf.len() >= CHUNK {
            self.drain()?;
        }
        Ok(())
    }

    /// An emptied buffer handed back by the writing thread, or a new one.
    fn spare(&mut self) -> Vec<u8> {
        let mut buf = self
            .empty
            .try_recv()
            .unwrap_or_else(|_| Vec::with_capacity(CHUNK + 4096));
        buf.clear();
        buf
    }

    /// Hands a buffer to the writing thread.
    fn send(&mut self, buf: Vec<u8>) -> Result<()> {
        let what = self.what;
        // A closed channel means the writing side stopped on an error, which it reports.
        self.full
            .send(buf)
            .map_err(|_| Error::io(format!("writing {what}: stopped")))
    }

    /// Passes the buffer on (when it holds anything).
    fn drain(&mut self) -> Result<()> {
        if self.text.buf.is_empty() {
            return Ok(());
        }
        let next = self.spare();
        let buf = std::mem::replace(&mut self.text.buf, next);
        self.send(buf)
    }

    /// Encodes the items `0..count` in blocks of `per` (about a chunk of bytes each), several
    /// blocks at once on the thread pool, each by `encode(block, text)` into a buffer of its
    /// own, and passes the blocks on in order after what the buffer already holds.
    fn blocks(
        &mut self,
        count: usize,
        per: usize,
        encode: impl Fn(std::ops::Range<usize>, &mut Text) + Sync,
    ) -> Result<()> {
        let per = per.max(1);
        let blocks = count.div_ceil(per);
        if blocks <= 1 {
            encode(0..count, &mut self.text);
            return self.tick();
        }
        self.drain()?;
        let batch = 2 * rayon::current_num_threads().max(1);
        let mut first = 0;
        while first < blocks {
            let end = (first + batch).min(blocks);
            let mut texts: Vec<Text> = (first..end).map(|_| Text::new(self.spare())).collect();
            texts.par_iter_mut().enumerate().for_each(|(b, text)| {
                let start = (first + b) * per;
                encode(start..(start + per).min(count), text);
            });
            for text in texts {
                self.send(text.buf)?;
            }
            first = end;
        }
        Ok(())
    }

    /// One record of `N` bytes for each of `0..count`, `record(k)` ([`Sink::blocks`]).
    fn records<const N: usize>(
        &mut self,
        count: usize,
        record: impl Fn(usize) -> [u8; N] + Sync,
    ) -> Result<()> {
        self.blocks(count, CHUNK / 2 / N, |range, text| {
            text.records(range, &record)
        })
    }
}

/// Three 32-bit words, little-endian.
#[inline(always)]
fn le3(v: [u32; 3]) -> [u8; 12] {
    let mut b = [0u8; 12];
    for (dst, x) in b.chunks_exact_mut(4).zip(v) {
        dst.copy_from_slice(&x.to_le_bytes());
    }
    b
}

/// Two arrays of bytes as one.
#[inline(always)]
fn join_bytes<const A: usize, const B: usize, const N: usize>(a: [u8; A], b: [u8; B]) -> [u8; N] {
    let mut out = [0u8; N];
    out[..A].copy_from_slice(&a);
    out[A..].copy_from_slice(&b);
    out
}

// ---------------------------------------------------------------------------------------------
// What a file says about its mesh
// ---------------------------------------------------------------------------------------------

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
        let bad = crate::mesh::first_bad(data, |p| {
            !(p[0].is_finite() & p[1].is_finite() & p[2].is_finite())
        });
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
    let x = crate::mesh::weld::facet_cross(&[a, b, c], [0, 1, 2]);
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

/// Lines of text per block encoded at once ([`Sink::blocks`]): well under a chunk.
const LINES: usize = 1 << 13;

/// One OBJ record `prefix x y z`.
fn obj_vec3(out: &mut Text, prefix: &[u8], v: &[f32; 3]) {
    out.bytes(prefix);
    out.f32_text(v[0]);
    out.bytes(b" ");
    out.f32_text(v[1]);
    out.bytes(b" ");
    out.f32_text(v[2]);
    out.bytes(b"\n");
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
        let (positions, normals) = (&mesh.positions, &mesh.normals);
        out.blocks(positions.len(), LINES, |range, text| {
            for k in range {
                obj_vec3(text, b"v ", &frame.point(positions[k]));
            }
        })?;
        out.blocks(normals.len(), LINES, |range, text| {
            for k in range {
                obj_vec3(text, b"vn ", &frame.normal(normals[k]));
            }
        })?;
        let with_uv = !mesh.uv.is_empty();
        out.blocks(mesh.uv.len(), LINES, |range, text| {
            for t in &mesh.uv[range] {
                text.bytes(b"vt ");
                text.f32_text(t[0]);
                text.bytes(b" ");
                text.f32_text(t[1]);
                text.bytes(b"\n");
            }
        })?;
        for (part, name) in parts.iter().zip(&names) {
            out.bytes(b"o ");
            out.bytes(name.as_bytes());
            out.bytes(b"\n");
            let ts = &mesh.triangles[part.triangles.clone()];
            out.blocks(ts.len(), LINES, |range, text| {
                for t in &ts[range] {
                    text.bytes(b"f");
                    for &i in t {
                        let i = u64::from(i) + 1;
                        text.bytes(b" ");
                        text.uint_text(i);
                        text.bytes(if with_uv { b"/" } else { b"//" });
                        if with_uv {
                            text.uint_text(i);
                            text.bytes(b"/");
                        }
                        text.uint_text(i);
                    }
                    text.bytes(b"\n");
                }
            })?;
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
        out.records(mesh.triangles.len(), |k| {
            let [a, b, c] = mesh.triangles[k].map(|i| frame.point(mesh.positions[i as usize]));
            // One record: facet normal, three corners, a zero attribute word.
            let mut record = [0u8; 50];
            for (k, v) in [facet_normal(a, b, c), a, b, c].into_iter().enumerate() {
                record[12 * k..12 * k + 12].copy_from_slice(&le3(v.map(f32::to_bits)));
            }
            record
        })
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
        let (positions, normals) = (&mesh.positions, &mesh.normals);
        let vertex = |k: usize| -> [u8; 24] {
            join_bytes(
                le3(frame.point(positions[k]).map(f32::to_bits)),
                le3(frame.normal(normals[k]).map(f32::to_bits)),
            )
        };
        if with_uv {
            out.records(positions.len(), |k| {
                let [u, v] = mesh.uv[k];
                join_bytes::<24, 8, 32>(
                    vertex(k),
                    join_bytes::<4, 4, 8>(u.to_le_bytes(), v.to_le_bytes()),
                )
            })?;
        } else {
            out.records(positions.len(), vertex)?;
        }
        // One record per face: the count 3, then the three indices.
        out.records(mesh.triangles.len(), |k| {
            join_bytes::<1, 12, 13>([3], le3(mesh.triangles[k]))
        })
    })
}

// ---------------------------------------------------------------------------------------------
// GLB
// ---------------------------------------------------------------------------------------------

mod glb;
pub use glb::material as glb_material;
pub use glb::{write_glb, write_glb_grids};

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
            out.blocks(g.nu * g.nv, LINES / 4, |range, text| {
                for idx in range {
                    let (i, j) = (idx / g.nv, idx % g.nv);
                    text.f64_text(g.u[i]);
                    text.bytes(b",");
                    text.f64_text(g.v[j]);
                    for c in g.positions[idx].into_iter().chain(g.normals[idx]) {
                        text.bytes(b",");
                        text.f64_text(c);
                    }
                    if several {
                        text.bytes(b",");
                        text.uint_text(k as u64);
                    }
                    text.bytes(b"\n");
                }
            })?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;
    use std::collections::HashMap;

    /// A grid of `nu × nv` vertices with awkward numbers (tiny, huge, negative zero, many
    /// digits) in its positions and normals that are not all unit.
    fn odd_grid(nu: usize, nv: usize, shift: f64) -> GridMesh {
        let odd = [
            1e-8,
            1e-40,
            -0.0,
            0.1,
            1.0 / 3.0,
            1.0000001,
            -2.5e-12,
            2.9999998,
        ];
        let mut positions = Vec::with_capacity(nu * nv);
        let mut normals = Vec::with_capacity(nu * nv);
        for i in 0..nu {
            for j in 0..nv {
                let (u, v) = (i as f64 / nu as f64, j as f64 / nv as f64);
                let x = u + shift;
                let mut p = [x, v * 1.7, (x * 7.0 + v * 3.0).sin()];
                if (i * 31 + j * 17) % 97 == 0 {
                    p[(i + j) % 3] = odd[(i * 7 + j) % odd.len()];
                }
                positions.push(p.map(|x| x as f32));
                normals.push([(u * 5.0).cos(), (v * 3.0).sin(), 0.3 + u].map(|x| x as f32));
            }
        }
        Grid {
            nu,
            nv,
            periodic_v: false,
            u: (0..nu).map(|i| i as f64 / (nu - 1) as f64).collect(),
            v: (0..nv).map(|j| 0.25 + j as f64 / (nv - 1) as f64).collect(),
            positions,
            normals,
        }
    }

    /// Meshes large enough that every array is encoded in many blocks, several batches of
    /// them: two grids side by side welded (the second part shares the first's vertices along
    /// the seam), the same grids appended with texture coordinates, one part, and a mesh
    /// without parts.
    fn large_meshes() -> Vec<(&'static str, TriMesh)> {
        let a = odd_grid(420, 260, 0.0);
        let b = odd_grid(300, 260, 1.0 - 1.0 / 420.0);
        let welded = weld(
            &[a.clone(), b.clone()],
            &["left part", ""],
            WeldOptions::default(),
        );
        let mut grids = TriMesh::from_grid(&a, "a");
        grids.append(&TriMesh::from_grid(&b, "b b"));
        let mut single = TriMesh::from_grid(&a, "single");
        single.uv.clear();
        let mut unnamed = single.clone();
        unnamed.parts.clear();
        vec![
            ("welded", welded),
            ("grids with uv", grids),
            ("single", single),
            ("unnamed", unnamed),
        ]
    }

    fn infos() -> Vec<MeshInfo> {
        vec![
            MeshInfo {
                title: Some("A title".to_string()),
                ..MeshInfo::default()
            },
            MeshInfo {
                scale: 2.5,
                up: Up::Y,
                units: Units::Centimetre,
                ..MeshInfo::default()
            },
        ]
    }

    /// What follows the header of a text file: everything from the first line starting with
    /// `v `.
    fn text_body(bytes: &[u8]) -> &[u8] {
        let at = bytes
            .windows(3)
            .position(|w| w == b"\nv ")
            .expect("a vertex line");
        &bytes[at + 1..]
    }

    /// The OBJ records, one at a time in file order, as a single serial pass writes them.
    fn obj_reference(mesh: &TriMesh, info: &MeshInfo) -> Vec<u8> {
        let frame = Frame::new(info, Format::Obj).unwrap();
        let mut t = Text::new(Vec::new());
        let vec3 = |t: &mut Text, prefix: &[u8], v: [f32; 3]| {
            t.bytes(prefix);
            for (c, x) in v.into_iter().enumerate() {
                if c > 0 {
                    t.bytes(b" ");
                }
                t.f32_text(x);
            }
            t.bytes(b"\n");
        };
        for &p in &mesh.positions {
            vec3(&mut t, b"v ", frame.point(p));
        }
        for &n in &mesh.normals {
            vec3(&mut t, b"vn ", frame.normal(n));
        }
        for uv in &mesh.uv {
            t.bytes(b"vt ");
            t.f32_text(uv[0]);
            t.bytes(b" ");
            t.f32_text(uv[1]);
            t.bytes(b"\n");
        }
        for (k, part) in parts_of(mesh).iter().enumerate() {
            t.bytes(format!("o {}\n", token(&part.name, k)).as_bytes());
            for tri in &mesh.triangles[part.triangles.clone()] {
                t.bytes(b"f");
                for &i in tri {
                    let i = i + 1;
                    if mesh.uv.is_empty() {
                        t.bytes(format!(" {i}//{i}").as_bytes());
                    } else {
                        t.bytes(format!(" {i}/{i}/{i}").as_bytes());
                    }
                }
                t.bytes(b"\n");
            }
        }
        t.buf
    }

    fn f32s(out: &mut Vec<u8>, v: &[f32]) {
        for x in v {
            out.extend_from_slice(&x.to_le_bytes());
        }
    }

    /// The STL triangle records.
    fn stl_reference(mesh: &TriMesh, info: &MeshInfo) -> Vec<u8> {
        let frame = Frame::new(info, Format::Stl).unwrap();
        let mut out = Vec::new();
        for t in &mesh.triangles {
            let [a, b, c] = t.map(|i| frame.point(mesh.positions[i as usize]));
            for v in [facet_normal(a, b, c), a, b, c] {
                f32s(&mut out, &v);
            }
            out.extend_from_slice(&[0, 0]);
        }
        out
    }

    /// The PLY vertex and face records.
    fn ply_reference(mesh: &TriMesh, info: &MeshInfo) -> Vec<u8> {
        let frame = Frame::new(info, Format::Ply).unwrap();
        let mut out = Vec::new();
        for (k, (&p, &n)) in mesh.positions.iter().zip(&mesh.normals).enumerate() {
            f32s(&mut out, &frame.point(p));
            f32s(&mut out, &frame.normal(n));
            if !mesh.uv.is_empty() {
                f32s(&mut out, &mesh.uv[k]);
            }
        }
        for t in &mesh.triangles {
            out.push(3);
            for i in t {
                out.extend_from_slice(&i.to_le_bytes());
            }
        }
        out
    }

    /// The GLB binary chunk (each part's vertices in the order its triangles first use them:
    /// positions, normals, texture coordinates, then its triangles in that numbering), and each
    /// part's vertex count, triangle count and position bounds.
    #[allow(clippy::type_complexity)]
    fn glb_reference(
        mesh: &TriMesh,
        info: &MeshInfo,
    ) -> (Vec<u8>, Vec<(usize, usize, [f32; 3], [f32; 3])>) {
        let frame = Frame::new(info, Format::Glb).unwrap();
        let mut out = Vec::new();
        let mut parts = Vec::new();
        for part in parts_of(mesh) {
            // The vertices the part uses, in increasing order.
            let tris = &mesh.triangles[part.triangles.clone()];
            let mut order: Vec<u32> = tris.iter().flatten().copied().collect();
            order.sort_unstable();
            order.dedup();
            let number: HashMap<u32, u32> = order
                .iter()
                .enumerate()
                .map(|(k, &i)| (i, k as u32))
                .collect();
            let local: Vec<u32> = tris.iter().flatten().map(|i| number[i]).collect();
            if order.is_empty() {
                continue;
            }
            let mut lo = [f32::INFINITY; 3];
            let mut hi = [f32::NEG_INFINITY; 3];
            for &i in &order {
                let q = frame.point(mesh.positions[i as usize]);
                f32s(&mut out, &q);
                for c in 0..3 {
                    lo[c] = lo[c].min(q[c]);
                    hi[c] = hi[c].max(q[c]);
                }
            }
            // A zero bound is written `0`, whichever sign the minimum kept.
            let (lo, hi) = (lo.map(|x| x + 0.0), hi.map(|x| x + 0.0));
            for &i in &order {
                f32s(&mut out, &frame.normal(mesh.normals[i as usize]));
            }
            if !mesh.uv.is_empty() {
                for &i in &order {
                    f32s(&mut out, &mesh.uv[i as usize]);
                }
            }
            for k in local {
                out.extend_from_slice(&k.to_le_bytes());
            }
            parts.push((order.len(), part.triangles.len(), lo, hi));
        }
        while out.len() % 4 != 0 {
            out.push(0);
        }
        (out, parts)
    }

    /// Every edge used by exactly two triangles, counted.
    fn closed_reference(mesh: &TriMesh) -> bool {
        let mut uses: HashMap<(u32, u32), usize> = HashMap::new();
        for t in &mesh.triangles {
            for e in 0..3 {
                let (a, b) = (t[e], t[(e + 1) % 3]);
                *uses.entry((a.min(b), a.max(b))).or_default() += 1;
            }
        }
        uses.values().all(|&n| n == 2)
    }

    fn u32_at(bytes: &[u8], at: usize) -> usize {
        u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize
    }

    #[test]
    fn large_meshes_are_written_as_one_serial_pass_writes_them() {
        for (name, mesh) in large_meshes() {
            for info in infos() {
                let case = format!("{name}, scale {}, up {}", info.scale, info.up.label());
                let mut obj = Vec::new();
                write_obj(&mesh, &info, &mut obj).unwrap();
                assert!(text_body(&obj) == obj_reference(&mesh, &info), "OBJ {case}");

                let mut stl = Vec::new();
                write_stl(&mesh, &info, &mut stl).unwrap();
                assert_eq!(u32_at(&stl, 80), mesh.triangles.len(), "STL {case}");
                assert!(stl[84..] == stl_reference(&mesh, &info), "STL {case}");

                let mut ply = Vec::new();
                write_ply(&mesh, &info, &mut ply).unwrap();
                let end = b"end_header\n";
                let at = ply.windows(end.len()).position(|w| w == end).unwrap() + end.len();
                assert!(ply[at..] == ply_reference(&mesh, &info), "PLY {case}");

                let mut glb = Vec::new();
                write_glb(&mesh, &info, &mut glb).unwrap();
                assert_eq!(u32_at(&glb, 8), glb.len(), "GLB {case}");
                let json_len = u32_at(&glb, 12);
                let doc: serde_json::Value =
                    serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
                let bin = &glb[20 + json_len + 8..];
                assert_eq!(u32_at(&glb, 20 + json_len), bin.len(), "GLB {case}");
                let (expected, parts) = glb_reference(&mesh, &info);
                assert!(bin == expected, "GLB binary chunk, {case}");
                assert_eq!(
                    doc["materials"][0]["doubleSided"],
                    json!(!closed_reference(&mesh)),
                    "{case}"
                );
                let meshes = doc["meshes"].as_array().unwrap();
                assert_eq!(meshes.len(), parts.len(), "{case}");
                for (m, (vertices, triangles, lo, hi)) in meshes.iter().zip(parts) {
                    let prim = &m["primitives"][0];
                    let position = &doc["accessors"]
                        [prim["attributes"]["POSITION"].as_u64().unwrap() as usize];
                    assert_eq!(position["count"], json!(vertices), "{case}");
                    assert_eq!(position["min"], json!(lo), "{case}");
                    assert_eq!(position["max"], json!(hi), "{case}");
                    let indices = &doc["accessors"][prim["indices"].as_u64().unwrap() as usize];
                    assert_eq!(indices["count"], json!(3 * triangles), "{case}");
                }
            }
        }
    }

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
