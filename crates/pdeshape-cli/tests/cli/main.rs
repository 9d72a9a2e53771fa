//! The end-to-end tests of the `pdeshape` binary, one test binary (every module links the
//! library once): one module per subcommand or theme, `common` for the helpers they share.

mod analysis;
mod animate;
mod animate_gif;
mod animate_more;
mod blend;
mod cad;
mod campaign;
mod cli;
mod common;
mod design_ops;
mod dynamic;
mod edges;
mod fd;
mod fill;
mod fit;
mod flags;
mod kinds;
mod optimize;
mod params;
mod readme;
mod robust;
mod schema;
mod serve;
mod shell;
mod spline;
