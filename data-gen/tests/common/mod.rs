//! Shared helpers: run the built `data-gen`, scratch directories, a reader
//! for the scan PLY's `view` property.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Output;
use std::sync::atomic::{AtomicUsize, Ordering};

/// Runs `data-gen ARGS…` in `dir`.
pub fn data_gen(dir: &Path, args: &[&str]) -> Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_data-gen"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the data-gen binary runs")
}

/// Runs `data-gen ARGS…` in `dir` and insists on success.
pub fn ok(dir: &Path, args: &[&str]) -> String {
    let out = data_gen(dir, args);
    assert!(
        out.status.success(),
        "data-gen {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

static NEXT: AtomicUsize = AtomicUsize::new(0);

/// A fresh, empty scratch directory under cargo's per-target temporary directory.
pub fn scratch(name: &str) -> PathBuf {
    let n = NEXT.fetch_add(1, Ordering::Relaxed);
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("data-gen-tests")
        .join(format!("{name}-{}-{n}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch directory");
    dir
}

/// Reads a JSON file.
pub fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).expect("sidecar exists"))
        .expect("valid JSON")
}

/// The `view` property of every vertex of a binary little-endian scan PLY
/// (float/double coordinates and normals, then `int view`), by a reader
/// independent of subdyn's.
pub fn ply_views(path: &Path) -> Vec<i32> {
    let bytes = std::fs::read(path).expect("PLY exists");
    let end = bytes
        .windows(11)
        .position(|w| w == b"end_header\n")
        .expect("end_header")
        + 11;
    let header = std::str::from_utf8(&bytes[..end]).expect("ASCII header");
    assert!(header.contains("format binary_little_endian 1.0"));
    let mut count = 0usize;
    let mut sizes = Vec::new();
    for line in header.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.as_slice() {
            ["element", "vertex", n] => count = n.parse().expect("count"),
            ["property", t, name] => sizes.push((
                match *t {
                    "float" | "int" => 4,
                    "double" => 8,
                    other => panic!("unexpected type {other}"),
                },
                *name,
            )),
            _ => {}
        }
    }
    assert_eq!(
        sizes.last().map(|s| s.1),
        Some("view"),
        "view is the last property"
    );
    let stride: usize = sizes.iter().map(|s| s.0).sum();
    assert_eq!(bytes.len() - end, count * stride, "body size");
    (0..count)
        .map(|i| {
            let at = end + i * stride + stride - 4;
            i32::from_le_bytes(bytes[at..at + 4].try_into().expect("4 bytes"))
        })
        .collect()
}
