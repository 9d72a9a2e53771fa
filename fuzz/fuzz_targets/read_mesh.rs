//! The mesh readers of `fit` (OBJ, STL, PLY) on arbitrary bytes: a mesh or an error with a
//! non-empty one-line message, never a panic. The first byte picks the format.
#![no_main]
use libfuzzer_sys::fuzz_target;
use pdeshape::fit::{MeshFormat, InputMesh};

fuzz_target!(|data: &[u8]| {
    let Some((&pick, bytes)) = data.split_first() else {
        return;
    };
    let format = match pick % 3 {
        0 => MeshFormat::Obj,
        1 => MeshFormat::Stl,
        _ => MeshFormat::Ply,
    };
    match InputMesh::read(bytes, format) {
        Ok(mesh) => {
            // What is read can be measured and its topology found.
            let _ = mesh.topology();
            let _ = mesh.bounds();
        }
        Err(e) => {
            let m = e.to_string();
            assert!(!m.trim().is_empty());
            assert!(!m.contains('\n'), "{m}");
        }
    }
});
