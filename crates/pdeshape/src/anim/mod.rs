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
//!                                 └──Measures (measures.rs: time, area, volume; CSV, SVG)
//! ```

mod frames;
mod gltf;
mod measures;
mod morph;
mod source;

pub use frames::{for_each_frame, Frame, Keyframes};
pub use gltf::write_glb;
pub use measures::{measure, Measures, Row};
pub use morph::{ease, Morph};
pub use source::Animation;
