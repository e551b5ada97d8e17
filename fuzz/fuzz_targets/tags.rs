//! The tag file reader (`i j s` creases, `v i s` vertex sharpness, `h f`
//! holes).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let dir = subdyn_fuzz::scratch(&["fuzz.txt"]);
    let _ = subdyn::io::read_tags(subdyn_fuzz::file(&dir, "fuzz.txt", data));
});
