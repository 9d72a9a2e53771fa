//! Reading an animation: a timed design or a morph file, with what locates its errors, and one
//! time of it as a design (`pdeshape surface --time`).

use crate::common::{self, CliError, Loaded};
use pdeshape::anim::Animation;
use pdeshape::spec;
use std::path::Path;

/// An animation read from a file, with what locates its errors.
pub(crate) struct Animated {
    pub anim: Animation,
    /// The file whose paths the design's errors name (the morph's source for a morph).
    pub design: Loaded,
    /// The `[output]` grid of the file.
    pub output: spec::OutputSpec,
    pub title: Option<String>,
}

/// Reads a timed design or a morph file ([`pdeshape::open::open_animation`]).
pub(crate) fn load(path: &Path) -> Result<Animated, CliError> {
    let o = pdeshape::open::open_animation(path).map_err(common::opened)?;
    let anim = o
        .animation
        .expect("open_animation always gives an animation");
    Ok(Animated {
        anim,
        design: Loaded {
            file: o.design.file,
            text: o.design.text,
            spec: o.spec,
        },
        output: o.output,
        title: o.title,
    })
}

/// The design of `path` at time `t` (`pdeshape surface --time`).
pub(crate) fn load_at(path: &Path, t: f64) -> Result<Loaded, CliError> {
    if !t.is_finite() {
        return Err(CliError::input(format!("--time: must be finite (got {t})")));
    }
    let l = load(path)?;
    let mut spec = l.anim.spec_at(t).map_err(|e| l.design.error(&e))?;
    if let Animation::Morph { .. } = l.anim {
        spec.output = l.output.clone();
    }
    Ok(Loaded { spec, ..l.design })
}
