//! Time-dependent designs (§6.4.1, §8.1): a design sampled at the frames of its `[time]`
//! section, or a morph between two designs of the same structure, re-solved per frame and
//! written as a glTF animation with the measures of every frame.
//!
//! ```text
//! TimedDesign (spec::time) ─┐
//!                           ├─ Animation::spec_at(t) ─▶ DesignSpec ─▶ CompiledDesign::set_spec
//! Morph (morph.rs) ─────────┘                                             │ meshes, weld
//!                                                                         ▼
//!                              Keyframes (frames.rs: one topology, positions per frame)
//!                                 ├──write_glb (gltf.rs: morph targets, animated weights)
//!                                 ├──Measures (measures.rs: time, area, volume; CSV, SVG)
//!                                 └──pictures (render/anim_picture.rs: APNG, contact sheet)
//! a separate triangle mesh ──Correspondence (retarget.rs: closest points on the first frame)
//!                            └─ moved with every frame ─▶ Keyframes ─▶ write_glb
//! ```

mod frames;
mod gltf;
mod measures;
mod morph;
mod retarget;
mod source;

pub use frames::{for_each_frame, Frame, Keyframes, Solves};
pub use gltf::{write_glb, GlbFrames};
pub use measures::{measure, Measures, Row};
pub use morph::{ease, Morph};
pub use retarget::{vertex_normals, Anchor, Correspondence, Retarget};
pub use source::Animation;
