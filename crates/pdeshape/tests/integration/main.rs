//! The integration tests of the library, one test binary (every module links the library
//! once); `shell_common` holds the surfaces the shell tests share, the rest of what tests,
//! benches and examples share is in `pdeshape-testkit`.

mod anim;
mod campaign;
mod fill;
mod fit;
mod fit_general;
mod import_iges;
mod import_step;
mod shell_ccx;
mod shell_common;
mod shell_mesh;
mod weld;
mod write_design;
mod writers;
