//! `data-gen volume`: determinism, the partial-volume sum against the exact
//! sphere volume, every format read back with an independent reader (image,
//! tiff, exr crates; raw and NIfTI by hand), anisotropic spacing, and one-line
//! errors for bad input.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use serde_json::Value;

/// A fresh empty directory for one test under Cargo's per-target temp dir.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("volume-tests")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn data_gen(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_data-gen"))
        .arg("volume")
        .args(args)
        .output()
        .unwrap()
}

/// Runs `data-gen volume ARGS -o OUT`, asserting success.
fn volume(out: &Path, args: &[&str]) {
    let mut all: Vec<&str> = args.to_vec();
    let out = out.to_str().unwrap();
    all.extend(["-o", out]);
    let o = data_gen(&all);
    assert!(
        o.status.success(),
        "data-gen volume {all:?} failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

fn json(path: &Path) -> Value {
    serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap()
}

fn triple(v: &Value) -> [f64; 3] {
    std::array::from_fn(|k| v[k].as_f64().unwrap())
}

fn dims(v: &Value) -> [usize; 3] {
    std::array::from_fn(|k| v["dims"][k].as_u64().unwrap() as usize)
}

/// Little-endian f32 voxels.
fn f32s(bytes: &[u8]) -> Vec<f32> {
    bytes
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

/// Reads `BASE.raw` and its sidecar `BASE.json` by hand.
fn read_raw(raw: &Path) -> (Vec<f32>, Value) {
    let header = json(&raw.with_extension("json"));
    assert_eq!(header["dtype"], "f32");
    assert_eq!(header["byte_order"], "little");
    let data = f32s(&std::fs::read(raw).unwrap());
    let [nx, ny, nz] = dims(&header);
    assert_eq!(data.len(), nx * ny * nz);
    (data, header)
}

/// Parsed NIfTI-1 header fields (by hand, nifti1.h offsets) and the voxels.
struct Nifti {
    dim: [i16; 8],
    datatype: i16,
    bitpix: i16,
    pixdim: [f32; 8],
    vox_offset: f32,
    qform_code: i16,
    sform_code: i16,
    qoffset: [f32; 3],
    srow: [[f32; 4]; 3],
    data: Vec<f32>,
}

fn read_nifti(path: &Path) -> Nifti {
    let mut bytes = std::fs::read(path).unwrap();
    if path.to_string_lossy().ends_with(".gz") {
        let mut plain = Vec::new();
        flate2::read::GzDecoder::new(&bytes[..])
            .read_to_end(&mut plain)
            .unwrap();
        bytes = plain;
    }
    let h = &bytes;
    let i16_at = |at: usize| i16::from_le_bytes([h[at], h[at + 1]]);
    let f32_at = |at: usize| f32::from_le_bytes([h[at], h[at + 1], h[at + 2], h[at + 3]]);
    assert_eq!(
        i32::from_le_bytes([h[0], h[1], h[2], h[3]]),
        348,
        "sizeof_hdr"
    );
    assert_eq!(&h[344..348], b"n+1\0", "magic");
    let vox_offset = f32_at(108);
    Nifti {
        dim: std::array::from_fn(|n| i16_at(40 + 2 * n)),
        datatype: i16_at(70),
        bitpix: i16_at(72),
        pixdim: std::array::from_fn(|n| f32_at(76 + 4 * n)),
        vox_offset,
        qform_code: i16_at(252),
        sform_code: i16_at(254),
        qoffset: [f32_at(268), f32_at(272), f32_at(276)],
        srow: std::array::from_fn(|r| std::array::from_fn(|c| f32_at(280 + 16 * r + 4 * c))),
        data: f32s(&h[vox_offset as usize..]),
    }
}

/// Largest |a − b|.
fn max_diff(a: &[f32], b: &[f32]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (f64::from(*x) - f64::from(*y)).abs())
        .fold(0.0, f64::max)
}

/// Stored → physical with the sidecar's `intensity_scale`.
fn physical(stored: impl Iterator<Item = f64>, sidecar: &Value) -> Vec<f32> {
    let slope = sidecar["intensity_scale"]["slope"].as_f64().unwrap();
    let intercept = sidecar["intensity_scale"]["intercept"].as_f64().unwrap();
    stored.map(|s| (slope * s + intercept) as f32).collect()
}

/// Blurred, noisy, biased, anisotropic: what every format must carry.
const FULL: &[&str] = &[
    "sphere",
    "--spacing",
    "0.06,0.05,0.09",
    "--blur",
    "0.07",
    "--noise",
    "0.05",
    "--inhomogeneity",
    "0.2",
    "--seed",
    "7",
    "--inside",
    "120",
    "--outside",
    "30",
];

#[test]
fn same_seed_same_bytes_other_seed_other_bytes() {
    let dir = scratch("determinism");
    let args = [
        "torus",
        "--dims",
        "24,24,12",
        "--blur",
        "0.05",
        "--noise",
        "3",
        "--noise-model",
        "rician",
        "--inhomogeneity",
        "0.3",
        "--inside",
        "100",
        "--outside",
        "10",
    ];
    for (run, seed) in [("a", "5"), ("b", "5"), ("c", "6")] {
        std::fs::create_dir(dir.join(run)).unwrap();
        volume(
            &dir.join(run).join("v.nii.gz"),
            &[&args[..], &["--seed", seed]].concat(),
        );
        volume(
            &dir.join(run).join("stack"),
            &[&args[..], &["--seed", seed, "--format", "png16"]].concat(),
        );
    }
    let read = |run: &str, p: &str| std::fs::read(dir.join(run).join(p)).unwrap();
    let mut files = vec![
        "v.nii.gz".to_string(),
        "v.json".into(),
        "v.truth.obj".into(),
        "stack/volume.json".into(),
    ];
    files.extend((0..12).map(|k| format!("stack/slice_{k}.png")));
    for f in &files {
        assert!(
            read("a", f) == read("b", f),
            "{f} differs between two runs with the same seed"
        );
    }
    assert!(
        read("a", "v.nii.gz") != read("c", "v.nii.gz"),
        "another seed gave the same volume"
    );
    assert!(read("a", "stack/slice_6.png") != read("c", "stack/slice_6.png"));
}

#[test]
fn sphere_partial_volume_sums_to_the_sphere_volume() {
    let dir = scratch("sphere-volume");
    let r: f64 = 1.3;
    let exact = 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
    // Isotropic coarse grid, then an anisotropic one whose voxels do not line up
    // with the centre.
    for (name, grid) in [
        ("iso.raw", vec!["--dims", "24,24,24"]),
        (
            "aniso.raw",
            vec!["--spacing", "0.11,0.07,0.17", "--origin", "-1.61,-1.5,-1.7"],
        ),
    ] {
        let out = dir.join(name);
        volume(&out, &[&["sphere", "--radius", "1.3"][..], &grid].concat());
        let (f, header) = read_raw(&out);
        let spacing = triple(&header["spacing"]);
        let voxel = spacing.iter().product::<f64>();
        let sum = f.iter().map(|&v| f64::from(v)).sum::<f64>() * voxel;
        let mesh = header["truth_mesh_volume"].as_f64().unwrap();
        eprintln!(
            "{name}: dims {:?}, Σf·V = {sum:.6}, exact 4/3πr³ = {exact:.6} ({:+.4} %), mesh {mesh:.6} ({:+.4} %)",
            dims(&header),
            100.0 * (sum / exact - 1.0),
            100.0 * (sum / mesh - 1.0)
        );
        assert!((sum / exact - 1.0).abs() < 5e-3, "{name}: {sum} vs {exact}");
        assert!(
            (sum / mesh - 1.0).abs() < 1e-3,
            "{name}: {sum} vs mesh {mesh}"
        );
        assert!(f.iter().all(|&v| (0.0..=1.0 + 1e-6).contains(&v)));
        assert_eq!(header["rasterisation"]["unresolved_lines"], 0);
        assert!((header["fraction_volume"].as_f64().unwrap() - sum).abs() < 1e-6 * sum);
    }
}

#[test]
fn every_format_reads_back_as_the_raw_data() {
    let dir = scratch("formats");
    let raw = dir.join("ref.raw");
    volume(&raw, FULL);
    let (reference, header) = read_raw(&raw);
    let [nx, ny, nz] = dims(&header);
    assert!(nz >= 12, "the stack needs two-digit slice numbers: {nz}");
    let spacing = triple(&header["spacing"]);
    let origin = triple(&header["origin"]);
    let slice_len = nx * ny;

    // NIfTI, plain and gzip: f32 exact, header fields.
    for name in ["v.nii", "v.nii.gz"] {
        volume(&dir.join(name), FULL);
        let n = read_nifti(&dir.join(name));
        assert_eq!(n.dim, [3, nx as i16, ny as i16, nz as i16, 1, 1, 1, 1]);
        assert_eq!((n.datatype, n.bitpix), (16, 32));
        assert_eq!(n.vox_offset, 352.0);
        assert_eq!(n.pixdim[0], 1.0, "qfac");
        for k in 0..3 {
            assert_eq!(n.pixdim[k + 1], spacing[k] as f32);
            assert_eq!(n.qoffset[k], origin[k] as f32);
            for c in 0..3 {
                let expected = if c == k { spacing[k] as f32 } else { 0.0 };
                assert_eq!(n.srow[k][c], expected);
            }
            assert_eq!(n.srow[k][3], origin[k] as f32);
        }
        assert_eq!((n.qform_code, n.sform_code), (1, 1));
        assert_eq!(n.data, reference, "{name}");
        let sidecar = json(&dir.join("v.json"));
        assert_eq!(sidecar["header_bytes"], 352);
        assert_eq!(sidecar["truth_mesh"], "v.truth.obj");
        assert!(dir.join("v.truth.obj").exists());
    }

    // PNG stacks: numbered without padding, quantised with the sidecar's scale.
    for (format, bits) in [("png8", 8), ("png16", 16)] {
        let out = dir.join(format);
        volume(&out, &[FULL, &["--format", format]].concat());
        let sidecar = json(&out.join("volume.json"));
        assert_eq!(sidecar["files"][10], "slice_10.png");
        assert!(out.join(format!("slice_{}.png", nz - 1)).exists());
        assert!(!out.join("slice_01.png").exists());
        let mut stored = Vec::with_capacity(reference.len());
        for k in 0..nz {
            let img = image::open(out.join(format!("slice_{k}.png"))).unwrap();
            assert_eq!((img.width() as usize, img.height() as usize), (nx, ny));
            if bits == 8 {
                let g = img.as_luma8().expect("8-bit grey");
                stored.extend(g.as_raw().iter().map(|&v| f64::from(v)));
            } else {
                let g = img.as_luma16().expect("16-bit grey");
                stored.extend(g.as_raw().iter().map(|&v| f64::from(v)));
            }
        }
        let back = physical(stored.into_iter(), &sidecar);
        let slope = sidecar["intensity_scale"]["slope"].as_f64().unwrap();
        let err = max_diff(&back, &reference);
        assert!(
            err <= 0.5 * slope * 1.001 + 1e-4,
            "{format}: error {err}, step {slope}"
        );
        // The iso-value in stored units maps back to (inside + outside) / 2.
        let iso = sidecar["iso_value"].as_f64().unwrap();
        assert!(
            (slope * iso + sidecar["intensity_scale"]["intercept"].as_f64().unwrap() - 75.0).abs()
                < 1e-9
        );
    }

    // Multi-page TIFF: 16-bit and f32, one page per z.
    for (name, format) in [("v16.tif", "tiff"), ("v32.tif", "tiff-f32")] {
        let out = dir.join(name);
        volume(&out, &[FULL, &["--format", format]].concat());
        let sidecar = json(&out.with_extension("json"));
        let mut dec = tiff::decoder::Decoder::new(std::fs::File::open(&out).unwrap()).unwrap();
        let mut stored: Vec<f64> = Vec::new();
        let mut pages = 0;
        loop {
            assert_eq!(dec.dimensions().unwrap(), (nx as u32, ny as u32));
            match dec.read_image().unwrap() {
                tiff::decoder::DecodingResult::U16(v) => {
                    stored.extend(v.iter().map(|&x| f64::from(x)))
                }
                tiff::decoder::DecodingResult::F32(v) => {
                    stored.extend(v.iter().map(|&x| f64::from(x)))
                }
                _ => panic!("{name}: unexpected sample type"),
            }
            pages += 1;
            if !dec.more_images() {
                break;
            }
            dec.next_image().unwrap();
        }
        assert_eq!(pages, nz);
        let back = physical(stored.into_iter(), &sidecar);
        let slope = sidecar["intensity_scale"]["slope"].as_f64().unwrap();
        if format == "tiff-f32" {
            assert_eq!(back, reference);
        } else {
            assert!(max_diff(&back, &reference) <= 0.5 * slope * 1.001 + 1e-6);
        }
    }

    // EXR stack: one single-channel f32 file per slice.
    let out = dir.join("exr");
    volume(&out, &[FULL, &["--format", "exr"]].concat());
    let mut back = Vec::with_capacity(reference.len());
    for k in 0..nz {
        use exr::prelude::*;
        let img = read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .from_file(out.join(format!("slice_{k}.exr")))
            .unwrap();
        let layer = &img.layer_data;
        assert_eq!((layer.size.0, layer.size.1), (nx, ny));
        assert_eq!(layer.channel_data.list.len(), 1);
        assert_eq!(layer.channel_data.list[0].name, Text::from("Y"));
        match &layer.channel_data.list[0].sample_data {
            FlatSamples::F32(v) => back.extend_from_slice(v),
            _ => panic!("EXR slice {k} is not f32"),
        }
    }
    assert_eq!(back.len(), slice_len * nz);
    assert_eq!(back, reference);
}

#[test]
fn slice_images_put_x_in_columns_and_y_in_rows() {
    // A box longer in x than in y, in a grid with dims (40, 20, 6): the picture
    // is 40 wide, 20 high, and its bright region is wide.
    let dir = scratch("orientation");
    let mesh = dir.join("box.obj");
    std::fs::write(
        &mesh,
        "v 0 0 0\nv 3 0 0\nv 3 1 0\nv 0 1 0\nv 0 0 1\nv 3 0 1\nv 3 1 1\nv 0 1 1\n\
         f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n",
    )
    .unwrap();
    let out = dir.join("stack");
    // x from -0.5 to 3.5 mm (voxel centres at origin + i·0.1), y from 0 to 2.
    volume(
        &out,
        &[
            "--mesh",
            mesh.to_str().unwrap(),
            "--dims",
            "40,20,6",
            "--spacing",
            "0.1,0.1,0.4",
            "--origin",
            "-0.45,0.05,-0.5",
            "--format",
            "png8",
        ],
    );
    let img = image::open(out.join("slice_2.png")).unwrap().to_luma8();
    assert_eq!(img.dimensions(), (40, 20));
    // Column i = x index, row j = y index: x ∈ [0, 3] is columns 5..35, y ∈ [0, 1] rows 0..10.
    assert_eq!(img.get_pixel(20, 4)[0], 255); // inside
    assert_eq!(img.get_pixel(2, 4)[0], 0); // x < 0
    assert_eq!(img.get_pixel(20, 15)[0], 0); // y > 1
    let raw = dir.join("box.raw");
    volume(
        &raw,
        &[
            "--mesh",
            mesh.to_str().unwrap(),
            "--dims",
            "40,20,6",
            "--spacing",
            "0.1,0.1,0.4",
            "--origin",
            "-0.45,0.05,-0.5",
        ],
    );
    let (f, _) = read_raw(&raw);
    let sum: f64 = f.iter().map(|&v| f64::from(v)).sum::<f64>() * 0.1 * 0.1 * 0.4;
    assert!((sum - 3.0).abs() < 1e-6, "box volume {sum}");
}

#[test]
fn anisotropic_spacing_is_honoured() {
    let dir = scratch("anisotropic");
    let out = dir.join("e.nii");
    volume(&out, &["ellipsoid", "--spacing", "0.1,0.05,0.2"]);
    let sidecar = json(&dir.join("e.json"));
    let d = dims(&sidecar);
    // Radii 1.5, 1, 0.6 plus a 0.15 × 3 margin on each side.
    let extent: [f64; 3] = [3.0 + 0.9, 2.0 + 0.9, 1.2 + 0.9];
    let spacing = [0.1, 0.05, 0.2];
    for k in 0..3 {
        assert_eq!(
            d[k],
            (extent[k] / spacing[k] - 1e-9).ceil() as usize,
            "axis {k}"
        );
    }
    let n = read_nifti(&out);
    assert_eq!(&n.dim[1..4], &[d[0] as i16, d[1] as i16, d[2] as i16]);
    assert_eq!(&n.pixdim[1..4], &[0.1f32, 0.05, 0.2]);
    assert_eq!(
        [n.srow[0][0], n.srow[1][1], n.srow[2][2]],
        [0.1f32, 0.05, 0.2]
    );
    // The grid is centred on the ellipsoid: world of the middle index is 0.
    for k in 0..3 {
        let o = f64::from(n.srow[k][3]);
        assert!((o + 0.5 * (d[k] as f64 - 1.0) * spacing[k]).abs() < 1e-6);
    }
    let voxel = 0.1 * 0.05 * 0.2;
    let sum: f64 = n.data.iter().map(|&v| f64::from(v)).sum::<f64>() * voxel;
    let exact = 4.0 / 3.0 * std::f64::consts::PI * 1.5 * 1.0 * 0.6;
    assert!((sum / exact - 1.0).abs() < 5e-3, "{sum} vs {exact}");
}

/// Runs a failing command and returns its one-line message.
fn fails(args: &[&str]) -> String {
    let o = data_gen(args);
    assert!(!o.status.success(), "{args:?} should fail");
    let stderr = String::from_utf8_lossy(&o.stderr).into_owned();
    let lines: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    assert_eq!(lines.len(), 1, "{args:?}: not one line: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    lines[0].to_string()
}

#[test]
fn bad_input_is_one_clear_line() {
    let dir = scratch("errors");
    let out = dir.join("v.nii");
    let o = out.to_str().unwrap();
    assert!(fails(&["sphere", "--dims", "0,10,10", "-o", o]).contains("--dims"));
    assert!(fails(&["sphere", "--dims", "600,600,600", "-o", o]).contains("512"));
    assert!(fails(&["sphere", "--spacing", "-1,1,1", "-o", o]).contains("--spacing"));
    assert!(fails(&["sphere", "--spacing", "0.0001,0.0001,0.0001", "-o", o]).contains("512"));
    assert!(fails(&["sphere", "--format", "jpeg", "-o", o]).contains("jpeg"));
    assert!(fails(&["sphere", "--format", "tiff", "-o", o]).contains("--format"));
    assert!(fails(&["sphere", "--inhomogeneity", "1.5", "-o", o]).contains("--inhomogeneity"));
    assert!(fails(&["sphere", "--inside", "1", "--outside", "1", "-o", o]).contains("constant"));
    assert!(
        fails(&["sphere", "--dims", "10,10,10", "--origin", "5,5,5", "-o", o])
            .contains("outside the grid")
    );
    let missing = dir.join("missing.obj");
    assert!(fails(&["--mesh", missing.to_str().unwrap(), "-o", o]).contains("missing.obj"));
    // A cube without its top face.
    let open = dir.join("open.obj");
    std::fs::write(
        &open,
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n\
         f 1 4 3 2\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n",
    )
    .unwrap();
    let message = fails(&["--mesh", open.to_str().unwrap(), "-o", o]);
    assert!(
        message.contains("not closed") && message.contains("open.obj"),
        "{message}"
    );
    // Nothing was written by the failed runs.
    assert!(!out.exists());
    // A directory that is not a previous stack is not replaced.
    let taken = dir.join("taken");
    std::fs::create_dir(&taken).unwrap();
    std::fs::write(taken.join("notes.txt"), "keep me").unwrap();
    assert!(
        fails(&["sphere", "--dims", "8,8,8", "-o", taken.to_str().unwrap()])
            .contains("not a data-gen volume stack")
    );
    assert!(taken.join("notes.txt").exists());
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().starts_with('.'))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
}
