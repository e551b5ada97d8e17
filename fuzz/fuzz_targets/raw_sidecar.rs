//! Headerless samples with a JSON sidecar: the input cut at its first NUL
//! byte into the sidecar `v.json` and the samples `v.raw` (a sidecar names
//! them as `"files": ["v.raw"]`).
#![no_main]

use libfuzzer_sys::fuzz_target;
use subdyn::io::{VolumeReadOptions, read_volume};

fuzz_target!(|data: &[u8]| {
    let dir = subdyn_fuzz::scratch(&["v.json", "v.raw"]);
    let parts = subdyn_fuzz::parts(data, b"\0", 2);
    let sidecar = subdyn_fuzz::file(&dir, "v.json", parts[0]);
    subdyn_fuzz::file(&dir, "v.raw", parts.get(1).copied().unwrap_or_default());
    let _ = read_volume(sidecar, &VolumeReadOptions::default());
});
