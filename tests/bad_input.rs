//! The bad-input corpus of issue 28 as a test: each case must end with exit
//! code 1, one `subdyn: error: …` line naming the problem, no file left in
//! the run's directory (outputs, temporary files, directories made for
//! outputs) and within a few seconds. Every input is written by the test.

mod common;

use std::io::Write;
use std::path::Path;
use std::time::{Duration, Instant};

use common::{assert_clean_failure, files, run_subdyn};

/// The slowest a refused case may be (the issue allows 10 s; these take
/// milliseconds, so a case near this bound has started to allocate).
const FAST: Duration = Duration::from_secs(5);

/// Runs `args` in `dir` and asserts a clean, fast failure whose message has
/// every `needle`, leaving only `inputs` in `dir`.
fn refused(dir: &Path, args: &[&str], needles: &[&str], inputs: &[&str]) {
    let start = Instant::now();
    let out = run_subdyn(dir, args);
    let took = start.elapsed();
    assert_clean_failure(dir, &out, needles, inputs);
    assert!(took < FAST, "{args:?} took {took:?}");
}

fn cube(dir: &Path) {
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/opensubdiv/cube.obj"),
        dir.join("cube.obj"),
    )
    .unwrap();
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    gz.write_all(bytes).unwrap();
    gz.finish().unwrap()
}

/// A 16³ u8 ball volume `ball.raw` with its sidecar `ball.json`.
fn ball(dir: &Path) {
    let n = 16usize;
    let mut voxels = vec![0u8; n * n * n];
    for (i, v) in voxels.iter_mut().enumerate() {
        let c = [i % n, (i / n) % n, i / (n * n)].map(|c| c as f64 - 7.5);
        if (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt() < 5.0 {
            *v = 200;
        }
    }
    std::fs::write(dir.join("ball.raw"), voxels).unwrap();
    std::fs::write(
        dir.join("ball.json"),
        r#"{"dims": [16, 16, 16], "dtype": "u8", "files": ["ball.raw"]}"#,
    )
    .unwrap();
}

#[test]
fn a_failed_run_leaves_none_of_its_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    cube(d);
    std::fs::create_dir(d.join("sub")).unwrap();
    std::fs::create_dir(d.join("dir.obj")).unwrap();
    let inputs = ["cube.obj", "dir.obj", "sub"];
    // Every output path is checked before any work.
    for args in [
        &[
            "subdivide",
            "cube.obj",
            "-o",
            "o.obj",
            "--report",
            "missing/r.json",
        ][..],
        &[
            "limit",
            "cube.obj",
            "-o",
            "o.obj",
            "--report",
            "missing/r.json",
        ],
        &[
            "lattice",
            "cube.obj",
            "-o",
            "l.json",
            "--report",
            "missing/r.json",
        ],
        &["lattice", "cube.obj", "-o", "missing/l.json"],
        &[
            "compare",
            "cube.obj",
            "cube.obj",
            "--report",
            "missing/r.json",
        ],
        &["fit", "-o", "f.obj", "--plot", "missing/p.png", "--quiet"],
        &["render", "cube.obj", "-o", "missing/p.png"],
    ] {
        refused(d, args, &["missing"], &inputs);
    }
    for args in [
        &["subdivide", "cube.obj", "-o", "o.obj", "--report", "sub"][..],
        &["subdivide", "cube.obj", "-o", "dir.obj"],
    ] {
        refused(d, args, &["is a directory"], &inputs);
    }
}

#[test]
fn an_output_directory_that_is_a_file_is_refused_before_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ball(d);
    std::fs::write(d.join("taken"), b"not a directory").unwrap();
    refused(
        d,
        &[
            "recover",
            "ball.raw",
            "--iso",
            "100",
            "-o",
            "b.obj",
            "--slices-png",
            "taken",
            "--quiet",
        ],
        &["taken", "not a directory"],
        &["ball.json", "ball.raw", "taken"],
    );
}

#[test]
fn an_unstable_sculpt_leaves_no_frames_and_no_directory() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    cube(d);
    assert!(
        run_subdyn(d, &["lattice", "cube.obj", "-o", "lat.json"])
            .status
            .success()
    );
    std::fs::write(
        d.join("ops.json"),
        r#"{"dt": 1, "steps": 40, "ops": [
            {"step": 0, "op": "rope", "at": [0.5, 0.5, 0.5], "to": [3, 3, 3], "until": 40}]}"#,
    )
    .unwrap();
    refused(
        d,
        &[
            "sculpt",
            "lat.json",
            "--script",
            "ops.json",
            "--out-dir",
            "frames",
            "--every",
            "5",
            "--integrator",
            "explicit",
            "--level",
            "1",
        ],
        &["unstable"],
        &["cube.obj", "lat.json", "ops.json"],
    );
}

#[test]
fn fifos_and_devices_are_not_read() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let made = std::process::Command::new("mkfifo")
        .arg(d.join("pipe.obj"))
        .status()
        .unwrap();
    assert!(made.success());
    std::os::unix::fs::symlink("/dev/zero", d.join("zero.ply")).unwrap();
    let inputs = ["pipe.obj", "zero.ply"];
    refused(d, &["info", "pipe.obj"], &["pipe.obj", "FIFO"], &inputs);
    refused(
        d,
        &["subdivide", "pipe.obj", "-o", "o.obj"],
        &["pipe.obj", "FIFO"],
        &inputs,
    );
    refused(d, &["info", "zero.ply"], &["zero.ply", "device"], &inputs);
    refused(
        d,
        &["compare", "zero.ply", "pipe.obj"],
        &["zero.ply", "not a regular file"],
        &inputs,
    );
}

#[test]
fn sidecar_files_must_be_names_beside_the_sidecar() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ball(d);
    for bad in ["../ball.raw", "/etc/passwd", "sub/ball.raw", ".."] {
        std::fs::write(
            d.join("ball.json"),
            format!(r#"{{"dims": [16, 16, 16], "dtype": "u8", "files": ["{bad}"]}}"#),
        )
        .unwrap();
        refused(
            d,
            &["info", "ball.json"],
            &["ball.json", "not a file name in the sidecar's directory"],
            &["ball.json", "ball.raw"],
        );
    }
}

#[test]
fn gzip_streams_are_capped_and_checked() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // 64 MB of spaces in 64 kB: over a 16 MB budget once inflated.
    std::fs::write(d.join("bomb.ply.gz"), gzip(&vec![b' '; 64 << 20])).unwrap();
    let good = gzip(b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    let mut bad_crc = good.clone();
    let at = bad_crc.len() - 8;
    bad_crc[at] ^= 0x55;
    std::fs::write(d.join("crc.obj.gz"), bad_crc).unwrap();
    std::fs::write(d.join("cut.obj.gz"), &good[..good.len() - 8]).unwrap();
    let inputs = ["bomb.ply.gz", "crc.obj.gz", "cut.obj.gz"];
    refused(
        d,
        &["--max-memory", "16M", "info", "bomb.ply.gz"],
        &["bomb.ply.gz", "memory budget", "--max-memory"],
        &inputs,
    );
    refused(
        d,
        &["info", "crc.obj.gz"],
        &["crc.obj.gz", "checksum"],
        &inputs,
    );
    refused(d, &["info", "cut.obj.gz"], &["cut.obj.gz", "gzip"], &inputs);
}

/// A little-endian TIFF of `pages` pages of `side`² 8-bit pixels that all
/// point at one shared deflate strip (a few kB that decode to gigabytes).
fn tiff_bomb(pages: u32, side: u32) -> Vec<u8> {
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::best());
    z.write_all(&vec![0u8; (side * side) as usize]).unwrap();
    let strip = z.finish().unwrap();
    let mut out = b"II".to_vec();
    out.extend(42u16.to_le_bytes());
    let first_ifd = 8 + strip.len() as u32;
    let first_ifd = first_ifd + first_ifd % 2;
    out.extend(first_ifd.to_le_bytes());
    out.extend(&strip);
    out.resize(first_ifd as usize, 0);
    let ifd_bytes = 2 + 8 * 12 + 4;
    for p in 0..pages {
        let entries: [(u16, u16, u32); 8] = [
            (256, 4, side),
            (257, 4, side),
            (258, 3, 8),
            (259, 3, 8),
            (262, 3, 1),
            (273, 4, 8),
            (278, 4, side),
            (279, 4, strip.len() as u32),
        ];
        out.extend(8u16.to_le_bytes());
        for (tag, ty, value) in entries {
            out.extend(tag.to_le_bytes());
            out.extend(ty.to_le_bytes());
            out.extend(1u32.to_le_bytes());
            out.extend(value.to_le_bytes());
        }
        let next = if p + 1 < pages {
            first_ifd + (p + 1) * ifd_bytes
        } else {
            0
        };
        out.extend(next.to_le_bytes());
    }
    out
}

#[test]
fn volume_bombs_are_refused_before_decoding() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // Issue 28's case: 200 pages of 8192² (13.4 G samples) in about 90 kB.
    std::fs::write(d.join("bomb.tif"), tiff_bomb(200, 8192)).unwrap();
    // Three 1024² PNG slices: 25 MB decoded, over a 10 MB budget.
    std::fs::create_dir(d.join("slices")).unwrap();
    for k in 0..3 {
        image::GrayImage::new(1024, 1024)
            .save(d.join(format!("slices/s{k}.png")))
            .unwrap();
    }
    let inputs = ["bomb.tif", "slices"];
    refused(
        d,
        &["--max-memory", "4G", "info", "bomb.tif"],
        &["bomb.tif", "memory budget", "--max-memory"],
        &inputs,
    );
    refused(
        d,
        &["--max-memory", "10M", "info", "slices"],
        &["slices", "memory budget", "--max-memory"],
        &inputs,
    );
    // The same stack within the default budget is read.
    assert!(run_subdyn(d, &["info", "slices"]).status.success());
}

#[test]
fn work_over_the_memory_budget_is_refused_with_the_estimate() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    cube(d);
    ball(d);
    let inputs = ["ball.json", "ball.raw", "cube.obj"];
    refused(
        d,
        &[
            "--max-memory",
            "100M",
            "subdivide",
            "cube.obj",
            "-l",
            "8",
            "-o",
            "o.obj",
        ],
        &["cube.obj", "8 levels", "needs about", "--max-memory"],
        &inputs,
    );
    refused(
        d,
        &[
            "--max-memory",
            "1G",
            "compare",
            "cube.obj",
            "cube.obj",
            "--samples",
            "100000000",
        ],
        &["--samples", "needs about", "--max-memory"],
        &inputs,
    );
    refused(
        d,
        &["bench", "subdivide", "--grid", "4294967296", "--quiet"],
        &["--grid 4294967296"],
        &inputs,
    );
    refused(
        d,
        &[
            "recover", "ball.raw", "--sigma", "1e9", "-o", "b.obj", "--quiet",
        ],
        &["sigma", "far beyond the volume"],
        &inputs,
    );
    // A fit's and a recovery's levels are estimated before they are built
    // (about 100 kB per control face; these take 500–1,000 faces).
    refused(
        d,
        &[
            "--max-memory",
            "1M",
            "recover",
            "ball.raw",
            "-o",
            "b.obj",
            "--report",
            "b.json",
        ],
        &["ball.raw", "level 0 of", "control faces", "--max-memory"],
        &inputs,
    );
    let points: String = (0..2000)
        .map(|i| {
            // A Fibonacci sphere: 2,000 points, evenly spread.
            let z = 1.0 - (2 * i + 1) as f64 / 2000.0;
            let (r, t) = ((1.0 - z * z).sqrt(), i as f64 * 2.399_963_229_728_653);
            format!("{} {} {z}\n", r * t.cos(), r * t.sin())
        })
        .collect();
    std::fs::write(d.join("sphere.xyz"), points).unwrap();
    refused(
        d,
        &[
            "--max-memory",
            "1M",
            "fit",
            "sphere.xyz",
            "-o",
            "s.obj",
            "--limit-out",
            "s.ply",
        ],
        &["sphere.xyz", "level 0 of", "control faces", "--max-memory"],
        &["ball.json", "ball.raw", "cube.obj", "sphere.xyz"],
    );
}

#[test]
fn flag_values_are_checked_on_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    cube(d);
    refused(
        d,
        &["--threads", "100000", "info", "cube.obj"],
        &["--threads 100000", "threads"],
        &["cube.obj"],
    );
    refused(
        d,
        &["info", "cube.obj", "--threads", "0"],
        &["--threads 0"],
        &["cube.obj"],
    );
    // A negative value reaches the verb's range check (not clap's
    // "unexpected argument" text).
    refused(
        d,
        &["fit", "--tol", "-1", "-o", "f.obj", "--quiet"],
        &["tol", "-1"],
        &["cube.obj"],
    );
}

#[test]
fn sigterm_during_a_write_leaves_no_temporary_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    cube(d);
    // 393,216 faces through gzip: seconds of writing.
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_subdyn"))
        .args([
            "subdivide",
            "cube.obj",
            "-l",
            "8",
            "-o",
            "big.obj.gz",
            "--quiet",
        ])
        .current_dir(d)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let seen = loop {
        // A temporary file being filled (the empty probe of the output
        // check at the start does not count).
        let writing = files(d).iter().any(|f| {
            f.contains(".tmp.") && std::fs::metadata(d.join(f)).is_ok_and(|m| m.len() > 0)
        });
        if writing {
            break true;
        }
        if start.elapsed() > Duration::from_secs(60) || child.try_wait().unwrap().is_some() {
            break false;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    if !seen {
        let out = child.wait_with_output().unwrap();
        panic!(
            "no temporary file appeared while writing: {:?} {}",
            out.status,
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let killed = std::process::Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(128 + 15), "exit code of a SIGTERM");
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("SIGTERM"), "{err}");
    assert_eq!(files(d), ["cube.obj"], "files left behind");
}

/// A fan of `n` quads around one vertex (valence `n`) and a single `n`-gon.
fn fan_and_polygon(dir: &Path, n: usize) {
    use std::f64::consts::TAU;
    let mut fan = String::from("v 0 0 0.3\n");
    for i in 0..n {
        let (a, b) = (TAU * i as f64 / n as f64, TAU * (i as f64 + 0.5) / n as f64);
        fan += &format!(
            "v {} {} 0\nv {} {} 0\n",
            a.cos(),
            a.sin(),
            1.5 * b.cos(),
            1.5 * b.sin()
        );
    }
    for i in 0..n {
        fan += &format!(
            "f 1 {} {} {}\n",
            2 + 2 * i,
            3 + 2 * i,
            2 + 2 * ((i + 1) % n)
        );
    }
    std::fs::write(dir.join("fan.obj"), fan).unwrap();
    let mut gon: String = (0..n)
        .map(|i| {
            let a = TAU * i as f64 / n as f64;
            format!("v {} {} 0\n", a.cos(), a.sin())
        })
        .collect();
    gon += "f";
    for i in 1..=n {
        gon += &format!(" {i}");
    }
    gon += "\n";
    std::fs::write(dir.join("gon.obj"), gon).unwrap();
}

#[test]
fn exact_limit_evaluation_refuses_huge_valences_and_polygons() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let n = subdyn::limit::MAX_EXACT_RING + 1;
    fan_and_polygon(d, n);
    let inputs = ["fan.obj", "gon.obj"];
    let valence = format!("valence {n}");
    let size = format!("{n} vertices");
    refused(
        d,
        &["limit", "fan.obj", "-o", "o.obj"],
        &["fan.obj", &valence, "at most 256"],
        &inputs,
    );
    refused(
        d,
        &["limit", "gon.obj", "-o", "o.obj"],
        &["gon.obj", &size, "at most 256"],
        &inputs,
    );
    refused(
        d,
        &["render", "gon.obj", "--limit", "2", "-o", "o.png"],
        &["gon.obj", &size],
        &inputs,
    );
    refused(
        d,
        &["compare", "fan.obj", "gon.obj", "--limit-a"],
        &["fan.obj", &valence],
        &inputs,
    );
    // The same meshes subdivide to their limit positions (limit masks).
    let out = run_subdyn(
        d,
        &["subdivide", "gon.obj", "-l", "1", "--limit", "-o", "s.obj"],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// An allocation the system refuses, past an estimate (the budget set far
/// above an address-space limit of 400 MB): one line and exit 1, not Rust's
/// two-line abort, and nothing left in the directory.
#[test]
fn a_refused_allocation_ends_the_run_with_one_line() {
    use std::os::unix::process::CommandExt;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    cube(d);
    assert!(
        run_subdyn(
            d,
            &[
                "subdivide",
                "cube.obj",
                "-l",
                "4",
                "-o",
                "c4.obj",
                "--quiet"
            ]
        )
        .status
        .success()
    );
    std::fs::remove_file(d.join("cube.obj")).unwrap();
    let mut command = std::process::Command::new(env!("CARGO_BIN_EXE_subdyn"));
    command
        .args([
            "--max-memory",
            "100G",
            "subdivide",
            "c4.obj",
            "-l",
            "7",
            "-o",
            "big.obj",
        ])
        .current_dir(d);
    // SAFETY: setrlimit(2) only, between fork and exec.
    unsafe {
        command.pre_exec(|| {
            let limit = libc::rlimit {
                rlim_cur: 400 << 20,
                rlim_max: 400 << 20,
            };
            if libc::setrlimit(libc::RLIMIT_AS, &limit) == 0 {
                Ok(())
            } else {
                Err(std::io::Error::last_os_error())
            }
        });
    }
    let start = Instant::now();
    let out = command.output().unwrap();
    assert!(start.elapsed() < FAST);
    assert_clean_failure(
        d,
        &out,
        &["out of memory", "nothing was written"],
        &["c4.obj"],
    );
}
