//! The design layer's validation on every design the reader accepts: an error or a valid design,
//! never a panic (solving is left out: it is bounded by the limits, not by the fuzzer's clock).
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(spec) = pdeshape::spec::parse_design(text) {
        let _ = pdeshape::design::validate_design(&spec);
    }
});
