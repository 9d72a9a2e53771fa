//! Compile a design file, edit it, re-solve incrementally and write a mesh.
//!
//! The bundled cup (`examples/cup.toml`: a base and a bowl, two biharmonic patches) is compiled
//! once; an edit that lifts its rim re-solves only the bowl (the base is reused, bit for bit
//! what a fresh compile gives), and the edited design is written as an OBJ through
//! `WriteDesign`. Prints the rim's height before and after and the size of the file.
//!
//! `cargo run --release -p pdeshape --example compile_and_edit`

use pdeshape::design::WriteDesign as _;
use pdeshape::design::{compile, Edit};
use pdeshape::mesh::Format;
use pdeshape::spec::{parse_design, TransformStep};
use std::io::{BufWriter, Write};

/// The highest point of the design's surfaces on a coarse sample.
fn top(design: &mut pdeshape::design::CompiledDesign) -> f32 {
    let meshes = design.meshes(16, 32).unwrap();
    let z = meshes.iter().flat_map(|m| m.positions.iter().map(|p| p[2]));
    z.fold(f32::MIN, f32::max)
}

fn main() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/cup.toml");
    let spec = parse_design(&std::fs::read_to_string(path).unwrap()).unwrap();
    let mut design = compile(&spec).unwrap();
    let before = top(&mut design);

    // An edit is a value: here one more affine step on the curve `rim`. `apply` re-solves what
    // depends on it and returns the edit that undoes it.
    let undo = design
        .apply(&Edit::Transform {
            name: "rim".into(),
            step: TransformStep::Translate([0.0, 0.0, 0.5]),
        })
        .unwrap();
    let after = top(&mut design);
    println!("rim height: {before:.3} -> {after:.3}");

    // Write the edited design: every surface on a 32 × 64 grid, joined into one OBJ.
    let out = std::env::temp_dir().join(format!("pdeshape-cup-edited-{}.obj", std::process::id()));
    let mut file = BufWriter::new(std::fs::File::create(&out).unwrap());
    design
        .solved()
        .write(Format::Obj, 32, 64, &mut file)
        .unwrap();
    file.flush().unwrap();
    drop(file);
    println!(
        "{}: {} bytes",
        out.display(),
        std::fs::metadata(&out).unwrap().len()
    );
    std::fs::remove_file(&out).unwrap();

    // Undo restores the design as it was read.
    design.apply(&undo).unwrap();
    assert_eq!(design.spec(), &spec);
}

#[cfg(test)]
mod tests {
    #[test]
    fn runs() {
        super::main();
    }
}
