//! A directory of PNG slices: the input cut at each `--SLICE--` into up to
//! four files `slice_0.png` … `slice_3.png`.
#![no_main]

use libfuzzer_sys::fuzz_target;
use subdyn::io::{VolumeReadOptions, read_volume};

fuzz_target!(|data: &[u8]| {
    let dir = subdyn_fuzz::scratch(&["slices"]).join("slices");
    std::fs::create_dir_all(&dir).expect("slice directory");
    for (i, part) in subdyn_fuzz::parts(data, b"--SLICE--", 4)
        .into_iter()
        .enumerate()
    {
        subdyn_fuzz::file(&dir, &format!("slice_{i}.png"), part);
    }
    let _ = read_volume(&dir, &VolumeReadOptions::default());
});
