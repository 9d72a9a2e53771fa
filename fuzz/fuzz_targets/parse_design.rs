//! The design-file reader on arbitrary bytes: it must return a design or an error with a
//! non-empty message, never panic; an error's location must be found without panicking.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    match pdeshape::spec::parse_design(text) {
        Ok(spec) => {
            // What is read writes back out and reads in to the same design.
            let again = pdeshape::spec::write_design(&spec);
            if let Ok(out) = again {
                let back = pdeshape::spec::parse_design(&out).expect("a written design reads back");
                assert_eq!(back, spec);
            }
        }
        Err(e) => {
            let line = pdeshape::spec::describe_error("f.toml", text, &e);
            assert!(!line.trim().is_empty());
        }
    }
});
