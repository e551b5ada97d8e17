//! Bad parameters: a non-zero exit, one line on stderr, nothing written.

mod common;

use common::{data_gen, scratch};

#[test]
fn bad_parameters_give_one_clear_line() {
    let dir = scratch("errors");
    std::fs::write(dir.join("empty.obj"), "v 0 0 0\n").unwrap();
    let cases: &[(&[&str], &str)] = &[
        (
            &["scan", "sphere", "-o", "s.ply", "--views", "0"],
            "--views 0",
        ),
        (
            &["scan", "sphere", "-o", "s.ply", "--noise", "-0.1"],
            "--noise",
        ),
        (
            &["scan", "sphere", "-o", "s.ply", "--noise", "nan"],
            "--noise",
        ),
        (
            &["scan", "sphere", "-o", "s.ply", "--dropout", "1"],
            "--dropout",
        ),
        (
            &["scan", "sphere", "-o", "s.ply", "--outliers", "1.5"],
            "--outliers",
        ),
        (
            &["scan", "sphere", "-o", "s.ply", "--resolution", "0,5"],
            "W,H",
        ),
        (&["scan", "sphere", "-o", "s.ply", "--fov", "180"], "--fov"),
        (
            &["scan", "sphere", "-o", "s.ply", "--distance", "0.2"],
            "--distance",
        ),
        (&["scan", "sphere", "-o", "s.xyz"], ".ply"),
        (
            &["scan", "--mesh", "missing.obj", "-o", "s.ply"],
            "missing.obj",
        ),
        (&["scan", "--mesh", "empty.obj", "-o", "s.ply"], "no faces"),
        (
            &["scan", "sphere", "-o", "s.ply", "--poses", "nope.json"],
            "nope.json",
        ),
        (&["scan", "teapot", "-o", "s.ply"], "teapot"),
        (&["scan", "-o", "s.ply"], "required"),
        (
            &["shape", "torus", "-o", "t.obj", "--minor", "2"],
            "--minor",
        ),
        (
            &["shape", "sphere", "-o", "t.obj", "--radius", "-1"],
            "--radius",
        ),
        (
            &["shape", "sphere", "-o", "t.obj", "--resolution", "0"],
            "--resolution",
        ),
        (&["shape", "sphere", "-o", "t.txt"], "extension"),
        (
            &["shape", "--from", "missing.obj", "-o", "t.obj"],
            "missing.obj",
        ),
        (
            &["demo", "-o", "demo", "--source", "missing.obj"],
            "missing.obj",
        ),
    ];
    for (args, needle) in cases {
        let out = data_gen(&dir, args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?} should fail");
        assert_eq!(
            stderr.lines().count(),
            1,
            "{args:?}: one line, got {stderr:?}"
        );
        assert!(
            stderr.contains(needle),
            "{args:?}: {stderr:?} should mention {needle}"
        );
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
    let mut left: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["empty.obj"], "failed runs write nothing");
}
