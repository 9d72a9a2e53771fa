//! Export the bundled cup as STEP with its certified deviation.
//!
//! Every surface of the solved design is approximated by a B-spline surface within a tolerance
//! of 10⁻⁴ of the design's size; for the analytic PDE patches the deviation is a proven bound
//! (from bounds of the patch's derivatives), not a sampled estimate. The model is written as an
//! AP214 STEP file. Prints the largest deviation and the size of the file.
//!
//! `cargo run --release -p pdeshape --example export_step`

use pdeshape::cad::step::{step_timestamp, to_step, StepOptions};
use pdeshape::cad::{approximate_design, design_size};
use pdeshape::design::solve_design;
use pdeshape::spec::parse_design;

fn main() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/cup.toml");
    let solved =
        solve_design(&parse_design(&std::fs::read_to_string(path).unwrap()).unwrap()).unwrap();

    let tolerance = 1e-4 * design_size(&solved);
    let model = approximate_design(&solved, tolerance).unwrap();
    let mut largest = 0.0f64;
    for s in &model.surfaces {
        // `relation` is "≤" for a proven bound and "≈" for a sampled estimate.
        let a = &s.approx;
        println!(
            "  {}: deviation {} {:.3e} ({})",
            s.name,
            a.certificate.relation(),
            a.deviation,
            a.certificate.word()
        );
        largest = largest.max(a.deviation);
    }
    assert!(largest <= tolerance);

    let options = StepOptions {
        unit: solved.units,
        file_name: "cup.step".into(),
        timestamp: step_timestamp(0),
    };
    let text = to_step(&model, &options).unwrap();
    let out = std::env::temp_dir().join(format!("pdeshape-cup-{}.step", std::process::id()));
    std::fs::write(&out, &text).unwrap();
    println!("largest deviation: {largest:.3e} (tolerance {tolerance:.3e})");
    println!("{}: {} bytes", out.display(), text.len());
    std::fs::remove_file(&out).unwrap();
}

#[cfg(test)]
mod tests {
    #[test]
    fn runs() {
        super::main();
    }
}
