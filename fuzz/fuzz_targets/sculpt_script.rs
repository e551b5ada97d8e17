//! The `subdyn sculpt` script parser and its validation (the CLI's own
//! module, compiled in here).
#![no_main]

use libfuzzer_sys::fuzz_target;

#[allow(dead_code)]
#[path = "../../src/cli/sculpt_script.rs"]
mod sculpt_script;

fuzz_target!(|data: &[u8]| {
    subdyn_fuzz::init();
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = sculpt_script::parse_script(text, "fuzz.json");
    }
});
