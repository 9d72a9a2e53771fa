//! Frame generation: the design at every frame's time, compiled incrementally (what did not
//! change is reused), tessellated and welded into one triangle mesh per frame with one topology.

use super::source::Animation;
use crate::design::{compile, CompiledDesign, Export, SolvedDesign};
use crate::mesh::{GridMesh, TriMesh, WeldOptions, WeldTopology};
use crate::spec::time::TimeSpec;
use crate::spec::Units;
use crate::{Error, Result};

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
    match e {
        Error::Invalid { place, message } => Error::Invalid {
            place,
            message: when + &message,
        },
        Error::NotUnique { place, message } => Error::NotUnique {
            place,
            message: when + &message,
        },
        Error::Io { place, message } => Error::Io {
            place,
            message: when + &message,
        },
    }
}

/// Solves the animation at each of `times` on an `nu × nv` grid and calls `f` with every frame
/// in order. The meshes of all frames must share their triangles (the same welding of poles and
/// seams); a frame where they change is refused with its time.
pub fn for_each_frame(
    anim: &Animation,
    times: &[f64],
    nu: usize,
    nv: usize,
    export: &Export,
    mut f: impl FnMut(Frame) -> Result<()>,
) -> Result<()> {
    let mut compiled: Option<CompiledDesign> = None;
    let mut triangles: Option<Vec<[u32; 3]>> = None;
    let mut topology: Option<WeldTopology> = None;
    for (index, &t) in times.iter().enumerate() {
        let spec = anim.spec_at(t).map_err(|e| at_time(e, t))?;
        match compiled.as_mut() {
            None => compiled = Some(compile(&spec).map_err(|e| at_time(e, t))?),
            Some(c) => c.set_spec(spec).map_err(|e| at_time(e, t))?,
        }
        let solved = compiled.as_ref().expect("compiled").solved();
        if solved.surfaces.is_empty() {
            return Err(Error::invalid("the design has no surface to animate"));
        }
        if !solved.trims.is_empty() {
            return Err(Error::invalid(
                "designs with [[trims]] are not animated (their meshes change topology)",
            )
            .at("trims"));
        }
        let grids = solved.meshes(nu, nv).map_err(|e| at_time(e, t))?;
        // The first frame's welding is kept: the later frames are welded on its topology (the
        // same result as welding them afresh, without building the edge maps again).
        let again = topology.as_ref().and_then(|w| w.weld(&grids));
        let mesh = match again {
            Some(w) => w.mesh,
            None => {
                let options = WeldOptions {
                    join_patches: !export.separate_patches,
                };
                let (w, welded) = WeldTopology::new(&grids, &solved.names(), options);
                topology = Some(w);
                welded.mesh
            }
        };
        match &triangles {
            None => triangles = Some(mesh.triangles.clone()),
            Some(first) if *first != mesh.triangles => {
                return Err(Error::invalid(format!(
                    "at t = {}: the mesh's triangles differ from the first frame's (a curve \
                     became a point or two patches met or parted); every frame must weld alike",
                    crate::formula::short(t)
                )))
            }
            _ => {}
        }
        f(Frame {
            index,
            t,
            solved,
            grids: &grids,
            mesh: &mesh,
        })?;
    }
    Ok(())
}

/// The frames of an animation as one triangle topology and the vertex positions and normals of
/// every frame (design coordinates).
#[derive(Clone, Debug, Default)]
pub struct Keyframes {
    /// The design's title and unit.
    pub title: Option<String>,
    pub units: Units,
    /// The times of the frames.
    pub times: Vec<f64>,
    /// The triangles, counter-clockwise seen from the side the normals point to.
    pub triangles: Vec<[u32; 3]>,
    /// Per frame, per vertex.
    pub positions: Vec<Vec<[f32; 3]>>,
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
        if self.positions.is_empty() {
            self.triangles = frame.mesh.triangles.clone();
            self.title = frame.solved.title.clone();
            self.units = frame.solved.units;
            let r = crate::mesh::report(frame.mesh);
            self.closed = r.boundary_edges == 0 && r.nonmanifold_edges == 0;
        }
        self.times.push(frame.t);
        self.positions.push(frame.mesh.positions.clone());
        self.normals.push(frame.mesh.normals.clone());
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
