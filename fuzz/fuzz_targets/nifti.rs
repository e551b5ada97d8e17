//! The NIfTI-1 reader: the input as `.nii`, and as `.nii.gz` when it is a
//! gzip stream.
#![no_main]

use libfuzzer_sys::fuzz_target;
use subdyn::io::{VolumeReadOptions, read_volume};

fuzz_target!(|data: &[u8]| {
    let name = if data.starts_with(&[0x1f, 0x8b]) {
        "fuzz.nii.gz"
    } else {
        "fuzz.nii"
    };
    let dir = subdyn_fuzz::scratch(&["fuzz.nii", "fuzz.nii.gz"]);
    let _ = read_volume(
        subdyn_fuzz::file(&dir, name, data),
        &VolumeReadOptions::default(),
    );
});
