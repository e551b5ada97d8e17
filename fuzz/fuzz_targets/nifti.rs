//! The NIfTI-1 reader: the input as `.nii`, and as `.nii.gz` when it is a
//! gzip stream.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let name = if data.starts_with(&[0x1f, 0x8b]) {
        "fuzz.nii.gz"
    } else {
        "fuzz.nii"
    };
    subdyn_fuzz::read_volume_file(name, data);
});
