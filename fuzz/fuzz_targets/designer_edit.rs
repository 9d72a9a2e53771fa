//! The designer's API (`pdeshape serve`): an edit request body is JSON read into the library's
//! `Edit` and applied to a design, which is then validated; arbitrary bytes must give an edit or
//! an error, the edit must apply or fail with a message, and an applied edit must undo to the
//! design it started from. Never a panic (solving is left out, as in `validate_design`).
#![no_main]
use libfuzzer_sys::fuzz_target;
use pdeshape::design::{validate_design, Edit};

const START: &str = include_str!("../../examples/cup.toml");

fuzz_target!(|data: &[u8]| {
    let Ok(edit) = serde_json::from_slice::<Edit>(data) else {
        return;
    };
    let start = pdeshape::spec::parse_design(START).expect("the example reads");
    let mut spec = start.clone();
    match edit.apply(&mut spec) {
        Ok(undo) => {
            let _ = validate_design(&spec);
            undo.apply(&mut spec).expect("the undo edit applies");
            assert_eq!(spec, start, "undo restores the design");
        }
        Err(e) => {
            assert!(!e.to_string().trim().is_empty());
            assert_eq!(spec, start, "a failed edit changes nothing");
        }
    }
});
