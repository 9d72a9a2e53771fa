//! Frame generation: the design at every frame's time, compiled incrementally (what did not
//! change is reused), tessellated and welded into one triangle mesh per frame with one topology.

use super::source::Animation;
use crate::design::{compile, CompiledDesign, Export, SolvedDesign, SurfaceKind};
use crate::mesh::{FrameWeld, GridMesh, TriMesh, WeldOptions, WeldTopology};
use crate::spec::time::TimeSpec;
use crate::spec::{DesignSpec, Units};
use crate::{Error, Result};
use rayon::prelude::*;

/// One frame, as [`for_each_frame`] hands it over.
pub struct Frame<'a> {
    /// The frame's number (from 0).
    pub index: usize,
    /// Its time.
    pub t: f64,
    /// The design solved at `t`.
    pub solved: &'a SolvedDesign,
    /// Its grids (one per surface).
    pub grids: &'a [GridMesh],
    /// The grids welded into one mesh (its triangles are those of every other frame).
    pub mesh: &'a TriMesh,
}

/// Says at which time an error of the design happened, keeping its place in the file.
pub(crate) fn at_time(e: Error, t: f64) -> Error {
    let when = format!("at t = {}: ", crate::formula::short(t));
    let message = when + e.detail();
    e.with_message(message)
}

/// What one worker of [`for_each_frame`] keeps from frame to frame: its compiled design (so the
/// next frame re-solves only what changed), the grids with the surfaces they were made from,
/// the weld topology of its first frame with the buffers of its welded mesh, and the design of
/// its last frame.
#[derive(Default)]
struct Worker {
    compiled: Option<CompiledDesign>,
    grids: Vec<GridMesh>,
    sources: Vec<SurfaceKind>,
    weld: Option<FrameWeld>,
    /// The last frame's mesh when `weld` did not make it (the first frame, or a frame whose
    /// vertices the full weld had to join).
    own: Option<TriMesh>,
    /// The last frame's mesh is there (nothing failed since).
    ready: bool,
    last: Option<DesignSpec>,
    /// The design [`Worker::prepare`] solved and tessellated (not yet welded).
    prepared: Option<DesignSpec>,
    /// Frames this worker solved and frames it found equal to its previous one.
    solved: usize,
    repeated: usize,
}

impl Worker {
    /// The mesh of the last frame.
    fn mesh(&self) -> Option<&TriMesh> {
        if !self.ready {
            return None;
        }
        self.own
            .as_ref()
            .or_else(|| self.weld.as_ref().map(FrameWeld::mesh))
    }

    /// Solves, tessellates and welds the design at `t` (nothing when it equals the design of
    /// this worker's previous frame: that frame's result is the answer, bit for bit; only the
    /// weld when [`Worker::prepare`] solved it). Returns true when the mesh was welded afresh
    /// (its triangles are to be compared with the first frame's).
    fn frame(
        &mut self,
        anim: &Animation,
        t: f64,
        nu: usize,
        nv: usize,
        export: &Export,
    ) -> Result<bool> {
        let spec = anim.spec_at(t).map_err(|e| at_time(e, t))?;
        if self.ready && self.last.as_ref() == Some(&spec) {
            self.repeated += 1;
            return Ok(false);
        }
        if self.prepared.as_ref() != Some(&spec) {
            self.solve(spec.clone(), t, nu, nv)?;
        }
        self.prepared = None;
        let solved = self.compiled.as_ref().expect("compiled").solved();
        // The first frame's welding is kept: the later frames are welded on its topology (the
        // same result as welding them afresh, without building the edge maps again), into the
        // buffers of the last frame.
        let mut fresh_weld = false;
        let gathered = self.weld.as_mut().is_some_and(|w| w.weld(&self.grids));
        if gathered {
            self.own = None;
        } else if let Some(w) = self
            .weld
            .as_ref()
            .and_then(|w| w.topology().weld(&self.grids))
        {
            self.own = Some(w.mesh);
        } else {
            let options = WeldOptions {
                join_patches: !export.separate_patches,
            };
            let (w, welded) = WeldTopology::new(&self.grids, &solved.names(), options);
            self.weld = Some(FrameWeld::after(w, &welded, &self.grids));
            self.own = Some(welded.mesh);
            fresh_weld = true;
        }
        self.ready = true;
        self.last = Some(spec);
        self.solved += 1;
        Ok(fresh_weld)
    }

    /// Solves and tessellates the design `spec` at `t`: everything of a frame but the weld.
    fn solve(&mut self, spec: DesignSpec, t: f64, nu: usize, nv: usize) -> Result<()> {
        // Forget the last design first: on an error below nothing stale is taken for it.
        self.last = None;
        self.ready = false;
        self.prepared = None;
        match self.compiled.as_mut() {
            None => self.compiled = Some(compile(&spec).map_err(|e| at_time(e, t))?),
            Some(c) => c.set_spec(spec).map_err(|e| at_time(e, t))?,
        }
        let solved = self.compiled.as_ref().expect("compiled").solved();
        if solved.surfaces.is_empty() {
            return Err(Error::invalid("the design has no surface to animate"));
        }
        if !solved.trims.is_empty() {
            return Err(Error::invalid(
                "designs with [[trims]] are not animated (their meshes change topology)",
            )
            .at("trims"));
        }
        // Only the surfaces that were solved again are tessellated again (a reused surface is
        // the very object whose grid this worker already has).
        let sources = &self.sources;
        let fresh = |k: usize| {
            sources
                .get(k)
                .is_none_or(|s| s.id() != solved.surfaces[k].kind.id())
        };
        if let Err(e) = solved.meshes_into(nu, nv, &mut self.grids, fresh) {
            self.grids.clear();
            self.sources.clear();
            return Err(at_time(e, t));
        }
        self.sources.clear();
        self.sources
            .extend(solved.surfaces.iter().map(|s| s.kind.clone()));
        Ok(())
    }

    /// Solves and tessellates this worker's first frame ahead (while the animation's first
    /// frame is being welded); [`Worker::frame`] at `t` then only welds it. An error is left for
    /// `frame` to meet again and report in its place.
    fn prepare(&mut self, anim: &Animation, t: f64, nu: usize, nv: usize) {
        if let Ok(spec) = anim.spec_at(t) {
            if self.solve(spec.clone(), t, nu, nv).is_ok() {
                self.prepared = Some(spec);
            }
        }
    }
}

/// How many frames [`for_each_frame`] solved and how many it found equal to the frame its
/// worker had solved before (handed over again without solving, tessellating or welding).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Solves {
    /// Frames solved.
    pub solved: usize,
    /// Frames equal to the one their worker had solved before, handed over again.
    pub repeated: usize,
}

/// Solves the animation at each of `times` on an `nu × nv` grid and calls `f` with every frame
/// in order. The meshes of all frames must share their triangles (the same welding of poles and
/// seams); a frame where they change is refused with its time.
///
/// Frames are solved in parallel, one per thread of the current rayon pool: after the first
/// frame (solved alone; its weld topology is given to every worker), worker `w` solves frames
/// `1 + w, 1 + w + W, …` with a compiled design of its own (re-solving only what changed
/// since its previous frame, and nothing when its design did not change), and `f` sees them in
/// order. Every solve is deterministic and a reused part is exactly what a fresh compile would
/// make, so the frames are those of compiling the design afresh at every time, bit for bit,
/// whatever the number of threads. An animation that does not depend on time (no formula in
/// `t`, no rig, a morph between equal designs) is solved once.
pub fn for_each_frame(
    anim: &Animation,
    times: &[f64],
    nu: usize,
    nv: usize,
    export: &Export,
    mut f: impl FnMut(Frame) -> Result<()>,
) -> Result<Solves> {
    let workers = if anim.depends_on_time() {
        rayon::current_num_threads().max(1)
    } else {
        1
    };
    let mut pool: Vec<Worker> = (0..workers.min(times.len().max(1)))
        .map(|_| Worker::default())
        .collect();
    let mut triangles: Option<Vec<[u32; 3]>> = None;
    // The first frame alone, so that every worker welds on its topology (building one costs
    // several frames); then one frame per worker at a time.
    let batches = times
        .get(..1)
        .into_iter()
        .chain(times.get(1..).unwrap_or_default().chunks(pool.len()));
    let mut first_index = 0;
    for chunk in batches {
        if first_index == 1 {
            let weld = pool[0].weld.clone();
            for w in &mut pool[1..] {
                w.weld = weld.clone();
            }
        }
        let results: Vec<Result<bool>> = if first_index == 0 {
            // While the first frame is solved and its topology built, the other workers solve
            // and tessellate their first frames (`1 + w`).
            let (first, rest) = pool.split_at_mut(1);
            let (result, ()) = rayon::join(
                || first[0].frame(anim, chunk[0], nu, nv, export),
                || {
                    rest.par_iter_mut().enumerate().for_each(|(w, worker)| {
                        if let Some(&t) = times.get(2 + w) {
                            worker.prepare(anim, t, nu, nv);
                        }
                    })
                },
            );
            vec![result]
        } else {
            pool[..chunk.len()]
                .par_iter_mut()
                .zip(chunk.par_iter())
                .map(|(w, &t)| w.frame(anim, t, nu, nv, export))
                .collect()
        };
        for (k, (result, w)) in results.into_iter().zip(&pool).enumerate() {
            let (index, t) = (first_index + k, chunk[k]);
            let fresh_weld = result?;
            let mesh = w.mesh().expect("a solved frame");
            match &triangles {
                None => triangles = Some(mesh.triangles.clone()),
                Some(first) if fresh_weld && *first != mesh.triangles => {
                    return Err(Error::invalid(format!(
                        "at t = {}: the mesh's triangles differ from the first frame's (a \
                         curve became a point or two patches met or parted); every frame must \
                         weld alike",
                        crate::formula::short(t)
                    )))
                }
                _ => {}
            }
            f(Frame {
                index,
                t,
                solved: w.compiled.as_ref().expect("compiled").solved(),
                grids: &w.grids,
                mesh,
            })?;
        }
        first_index += chunk.len();
    }
    Ok(Solves {
        solved: pool.iter().map(|w| w.solved).sum(),
        repeated: pool.iter().map(|w| w.repeated).sum(),
    })
}

/// The frames of an animation as one triangle topology and the vertex positions and normals of
/// every frame (design coordinates).
#[derive(Clone, Debug, Default)]
pub struct Keyframes {
    /// The design's title.
    pub title: Option<String>,
    /// The design's length unit.
    pub units: Units,
    /// The times of the frames.
    pub times: Vec<f64>,
    /// The triangles, counter-clockwise seen from the side the normals point to.
    pub triangles: Vec<[u32; 3]>,
    /// Vertex positions, `positions[frame][vertex]`.
    pub positions: Vec<Vec<[f32; 3]>>,
    /// Unit vertex normals, `normals[frame][vertex]`.
    pub normals: Vec<Vec<[f32; 3]>>,
    /// Every edge is used by two triangles (in the first frame).
    pub closed: bool,
    /// The motion is periodic: after the last frame comes the first, one step later.
    pub looped: bool,
    /// The period of a looped animation (`end − start`).
    pub period: f64,
}

impl Keyframes {
    /// Empty keyframes for an animation with these times.
    pub fn new(time: &TimeSpec) -> Keyframes {
        Keyframes {
            looped: time.looped,
            period: time.end - time.start,
            ..Keyframes::default()
        }
    }

    /// Appends a frame (the first fixes the triangles, title and unit).
    pub fn push(&mut self, frame: &Frame) {
        self.push_time(frame);
        self.positions.push(frame.mesh.positions.clone());
        self.normals.push(frame.mesh.normals.clone());
    }

    /// [`Keyframes::push`] without the frame's vertices (for a writer that takes them as they
    /// come, [`super::GlbFrames`]): its time, and the triangles, title, unit and closedness of
    /// the first frame.
    pub fn push_time(&mut self, frame: &Frame) {
        if self.times.is_empty() {
            self.triangles = frame.mesh.triangles.clone();
            self.title = frame.solved.title.clone();
            self.units = frame.solved.units;
            let r = crate::mesh::report(frame.mesh);
            self.closed = r.boundary_edges == 0 && r.nonmanifold_edges == 0;
        }
        self.times.push(frame.t);
    }

    /// Frame `k` as a triangle mesh.
    pub fn mesh(&self, k: usize) -> TriMesh {
        TriMesh {
            positions: self.positions[k].clone(),
            normals: self.normals[k].clone(),
            uv: Vec::new(),
            triangles: self.triangles.clone(),
            parts: Vec::new(),
        }
    }

    /// The box `(min, max)` around every frame.
    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in self.positions.iter().flatten() {
            for c in 0..3 {
                lo[c] = lo[c].min(p[c] as f64);
                hi[c] = hi[c].max(p[c] as f64);
            }
        }
        (lo, hi)
    }
}
