//! Volume input: NIfTI-1 (every scalar datatype, both byte orders, gzip,
//! sform / rotated qform / pixdim maps, scaling), raw + JSON, slice
//! directories, multi-page TIFF and EXR, written byte by byte (or with the
//! image crates) here, read back with `subdyn::io::read_volume`; one clear
//! error for each kind of bad input; and the MNI152 template when
//! `../shared` is present. (Round trips through data-gen's own writers are in
//! `data-gen/tests/subdyn_reads.rs`.)

use std::io::Write;
use std::path::{Path, PathBuf};

use nalgebra::{Matrix3, Vector3};
use subdyn::io::{VolumeReadOptions, read_volume};
use subdyn::math::Point3;

/// A fresh empty directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("volume-io")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn read(path: &Path) -> subdyn::io::VolumeFile {
    read_volume(path, &VolumeReadOptions::default())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn read_err(path: &Path) -> String {
    match read_volume(path, &VolumeReadOptions::default()) {
        Ok(_) => panic!("{} should not load", path.display()),
        Err(e) => e.to_string(),
    }
}

// ---------------------------------------------------------------------------
// NIfTI-1 written by hand (nifti1.h offsets).

/// The NIfTI-1 header fields a test sets.
#[derive(Clone)]
struct Nifti {
    dims: Vec<i16>,
    datatype: i16,
    bitpix: i16,
    big: bool,
    pixdim: [f32; 4],
    vox_offset: f32,
    scl: (f32, f32),
    qform: i16,
    quatern: [f32; 6],
    sform: i16,
    srow: [[f32; 4]; 3],
    sizeof_hdr: i32,
    magic: [u8; 4],
}

impl Nifti {
    fn new(dims: [i16; 3], datatype: i16, bitpix: i16) -> Self {
        Nifti {
            dims: dims.to_vec(),
            datatype,
            bitpix,
            big: false,
            pixdim: [1.0; 4],
            vox_offset: 352.0,
            scl: (0.0, 0.0),
            qform: 0,
            quatern: [0.0; 6],
            sform: 0,
            srow: [[0.0; 4]; 3],
            sizeof_hdr: 348,
            magic: *b"n+1\0",
        }
    }

    fn header(&self) -> Vec<u8> {
        let mut h = vec![0u8; 352];
        let big = self.big;
        let i16b = |v: i16| {
            if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            }
        };
        let i32b = |v: i32| {
            if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            }
        };
        let f32b = |v: f32| {
            if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            }
        };
        h[0..4].copy_from_slice(&i32b(self.sizeof_hdr));
        h[40..42].copy_from_slice(&i16b(self.dims.len() as i16));
        for (n, d) in self.dims.iter().enumerate() {
            h[42 + 2 * n..44 + 2 * n].copy_from_slice(&i16b(*d));
        }
        h[70..72].copy_from_slice(&i16b(self.datatype));
        h[72..74].copy_from_slice(&i16b(self.bitpix));
        for (n, p) in self.pixdim.iter().enumerate() {
            h[76 + 4 * n..80 + 4 * n].copy_from_slice(&f32b(*p));
        }
        h[108..112].copy_from_slice(&f32b(self.vox_offset));
        h[112..116].copy_from_slice(&f32b(self.scl.0));
        h[116..120].copy_from_slice(&f32b(self.scl.1));
        h[123] = 2; // mm
        h[252..254].copy_from_slice(&i16b(self.qform));
        h[254..256].copy_from_slice(&i16b(self.sform));
        for (n, q) in self.quatern.iter().enumerate() {
            h[256 + 4 * n..260 + 4 * n].copy_from_slice(&f32b(*q));
        }
        for (r, row) in self.srow.iter().enumerate() {
            for (c, v) in row.iter().enumerate() {
                let at = 280 + 16 * r + 4 * c;
                h[at..at + 4].copy_from_slice(&f32b(*v));
            }
        }
        h[344..348].copy_from_slice(&self.magic);
        h
    }

    /// Header, padding up to vox_offset, then `voxels` (already encoded).
    fn file(&self, voxels: &[u8]) -> Vec<u8> {
        let mut out = self.header();
        out.resize((self.vox_offset as usize).max(352), 0);
        out.extend_from_slice(voxels);
        out
    }
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    gz.write_all(bytes).unwrap();
    gz.finish().unwrap()
}

/// Values 0..n with a sign flip and an offset, so that order, sign and byte
/// order errors all show.
fn pattern(n: usize, signed: bool) -> Vec<f64> {
    (0..n)
        .map(|i| {
            let v = (i * 7 % 23) as f64 + 1.0;
            if signed && i % 3 == 0 { -v } else { v }
        })
        .collect()
}

#[test]
fn nifti_every_datatype_in_both_byte_orders() {
    let dir = scratch("nifti-types");
    let dims = [3i16, 4, 5];
    let n = 60;
    type Enc = fn(f64, bool) -> Vec<u8>;
    let types: [(i16, i16, bool, Enc); 6] = [
        (2, 8, false, |v, _| vec![v as u8]),
        (4, 16, true, |v, b| {
            let x = v as i16;
            (if b { x.to_be_bytes() } else { x.to_le_bytes() }).to_vec()
        }),
        (8, 32, true, |v, b| {
            let x = v as i32 * 1000;
            (if b { x.to_be_bytes() } else { x.to_le_bytes() }).to_vec()
        }),
        (16, 32, true, |v, b| {
            let x = v as f32 * 0.25;
            (if b { x.to_be_bytes() } else { x.to_le_bytes() }).to_vec()
        }),
        (64, 64, true, |v, b| {
            let x = v * 0.125;
            (if b { x.to_be_bytes() } else { x.to_le_bytes() }).to_vec()
        }),
        (512, 16, false, |v, b| {
            let x = v as u16 * 1000;
            (if b { x.to_be_bytes() } else { x.to_le_bytes() }).to_vec()
        }),
    ];
    for (code, bitpix, signed, enc) in types {
        let values = pattern(n, signed);
        let factor = match code {
            8 | 512 => 1000.0,
            16 => 0.25,
            64 => 0.125,
            _ => 1.0,
        };
        for big in [false, true] {
            let mut h = Nifti::new(dims, code, bitpix);
            h.big = big;
            let voxels: Vec<u8> = values.iter().flat_map(|&v| enc(v, big)).collect();
            let path = dir.join(format!("t{code}_{big}.nii"));
            std::fs::write(&path, h.file(&voxels)).unwrap();
            let vf = read(&path);
            assert_eq!(vf.volume.dims(), [3, 4, 5]);
            let got: Vec<f64> = vf.volume.data().iter().map(|&v| f64::from(v)).collect();
            let want: Vec<f64> = values.iter().map(|v| v * factor).collect();
            assert_eq!(got, want, "datatype {code}, big-endian {big}");
            assert!(vf.source.contains(if big { "big" } else { "little" }));
        }
    }
}

#[test]
fn nifti_gz_sform_anisotropic_with_origin_and_scaling() {
    let dir = scratch("nifti-sform");
    let mut h = Nifti::new([4, 3, 2], 4, 16);
    h.sform = 1;
    h.srow = [
        [0.5, 0.0, 0.0, -10.0],
        [0.0, 0.75, 0.0, 20.0],
        [0.0, 0.0, 2.5, 3.5],
    ];
    // A qform that disagrees: the sform must win.
    h.qform = 1;
    h.pixdim = [1.0, 9.0, 9.0, 9.0];
    h.scl = (2.0, -1.0);
    let values: Vec<i16> = (0..24).map(|i| i as i16 - 5).collect();
    let voxels: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
    let path = dir.join("v.nii.gz");
    std::fs::write(&path, gzip(&h.file(&voxels))).unwrap();
    let vf = read(&path);
    let v = &vf.volume;
    assert_eq!(v.dims(), [4, 3, 2]);
    assert_eq!(v.spacing(), [0.5, 0.75, 2.5]);
    assert_eq!(v.origin(), Point3::new(-10.0, 20.0, 3.5));
    let w = v.world([3.0, 2.0, 1.0]);
    assert!((w - Point3::new(-8.5, 21.5, 6.0)).norm() < 1e-6, "{w}");
    for (i, &s) in v.data().iter().enumerate() {
        assert_eq!(s, 2.0 * f32::from(values[i]) - 1.0);
    }
    assert!(vf.notes.iter().any(|n| n.contains("scl_slope")));
    assert!(vf.notes.iter().any(|n| n.contains("sform")));
    assert!(vf.source.contains("gzip"));
}

#[test]
fn nifti_rotated_qform_with_qfac() {
    let dir = scratch("nifti-qform");
    // 90° about z: (b, c, d) = (0, 0, sin 45°); qfac = −1 flips the k axis.
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let mut h = Nifti::new([2, 3, 4], 2, 8);
    h.qform = 1;
    h.pixdim = [-1.0, 0.5, 2.0, 3.0];
    h.quatern = [0.0, 0.0, s, 7.0, -8.0, 9.0];
    let path = dir.join("q.nii");
    std::fs::write(&path, h.file(&[1u8; 24])).unwrap();
    let v = read(&path).volume;
    let o = Point3::new(7.0, -8.0, 9.0);
    assert!((v.origin() - o).norm() < 1e-6);
    // Index axes: i → +y (0.5), j → −x (2), k → −z (3, qfac).
    let expect = [
        Vector3::new(0.0, 0.5, 0.0),
        Vector3::new(-2.0, 0.0, 0.0),
        Vector3::new(0.0, 0.0, -3.0),
    ];
    for (a, e) in expect.iter().enumerate() {
        let mut idx = [0.0; 3];
        idx[a] = 1.0;
        let step = v.world(idx) - o;
        assert!((step - e).norm() < 1e-6, "axis {a}: {step} vs {e}");
    }
    // The round trip through the inverse.
    let p = v.world([1.0, 2.0, 3.0]);
    let c = v.continuous_index(&p);
    assert!((c[0] - 1.0).abs() + (c[1] - 2.0).abs() + (c[2] - 3.0).abs() < 1e-9);
}

#[test]
fn nifti_pixdim_only_and_overrides() {
    let dir = scratch("nifti-pixdim");
    let mut h = Nifti::new([2, 2, 2], 2, 8);
    h.pixdim = [1.0, 1.5, 2.0, 4.0];
    let path = dir.join("p.nii");
    std::fs::write(&path, h.file(&[3u8; 8])).unwrap();
    let vf = read(&path);
    assert_eq!(vf.volume.spacing(), [1.5, 2.0, 4.0]);
    assert_eq!(vf.volume.origin(), Point3::origin());
    let opts = VolumeReadOptions {
        spacing: Some([0.1, 0.2, 0.3]),
        origin: Some([1.0, 2.0, 3.0]),
    };
    let vf = read_volume(&path, &opts).unwrap();
    assert_eq!(
        *vf.volume.linear(),
        Matrix3::from_diagonal(&Vector3::new(0.1, 0.2, 0.3))
    );
    assert_eq!(vf.volume.origin(), Point3::new(1.0, 2.0, 3.0));
    assert!(vf.notes.iter().any(|n| n.contains("--spacing")));
    for bad in [[0.0, 1.0, 1.0], [1.0, f64::NAN, 1.0], [-1.0, 1.0, 1.0]] {
        let opts = VolumeReadOptions {
            spacing: Some(bad),
            origin: None,
        };
        let e = read_volume(&path, &opts).unwrap_err().to_string();
        assert!(e.contains("--spacing"), "{e}");
    }
}

#[test]
fn nifti_bad_headers_give_one_clear_error() {
    let dir = scratch("nifti-bad");
    let good = Nifti::new([2, 2, 2], 2, 8);
    let voxels = [0u8; 8];
    let mut cases: Vec<(&str, Vec<u8>, &str)> = Vec::new();
    let mut h = good.clone();
    h.sizeof_hdr = 540;
    cases.push(("nifti2.nii", h.file(&voxels), "NIfTI-2"));
    let mut h = good.clone();
    h.sizeof_hdr = 400;
    cases.push(("sizeof.nii", h.file(&voxels), "sizeof_hdr"));
    let mut h = good.clone();
    h.dims[1] = 0;
    cases.push(("dim0.nii", h.file(&voxels), "dim[2] = 0"));
    let mut h = good.clone();
    h.dims[2] = -3;
    cases.push(("dimneg.nii", h.file(&voxels), "dim[3] = -3"));
    let mut h = good.clone();
    h.vox_offset = 4000.0;
    cases.push(("offset.nii", h.header(), "beyond the end"));
    cases.push(("trunc.nii", good.file(&voxels[..5]), "truncated"));
    cases.push(("trunc.nii.gz", gzip(&good.file(&voxels[..5])), "truncated"));
    // Whole voxels but a damaged gzip trailer: a wrong CRC-32, or none.
    let gz = gzip(&good.file(&voxels));
    let mut bad_crc = gz.clone();
    let crc_at = bad_crc.len() - 8;
    bad_crc[crc_at] ^= 0x55;
    cases.push(("crc.nii.gz", bad_crc, "checksum"));
    cases.push(("notrailer.nii.gz", gz[..gz.len() - 8].to_vec(), "gzip"));
    let mut h = good.clone();
    h.datatype = 32;
    cases.push(("complex.nii", h.file(&voxels), "datatype 32"));
    let mut h = good.clone();
    h.magic = *b"ni1\0";
    cases.push(("pair.nii", h.file(&voxels), "two-file"));
    cases.push(("short.nii", vec![0x5c, 1, 0, 0, 9], "too short"));
    cases.push(("empty.nii", Vec::new(), "too short"));
    let mut h = good.clone();
    h.pixdim = [1.0, 0.0, 1.0, 1.0];
    cases.push(("pixdim.nii", h.file(&voxels), "pixdim[1]"));
    let mut h = Nifti::new([2, 1, 1], 16, 32);
    h.pixdim = [1.0; 4];
    let nan: Vec<u8> = [1.0f32, f32::NAN]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    cases.push(("nan.nii", h.file(&nan), "finite"));
    for (name, bytes, expect) in cases {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let e = read_err(&path);
        assert!(e.contains(expect), "{name}: '{e}' lacks '{expect}'");
        assert!(e.contains(name), "{name}: '{e}' does not name the file");
        assert!(!e.contains('\n'), "{name}: '{e}' is not one line");
    }
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data beside the clone")]
fn mni152_template_loads_with_its_header_geometry() {
    // Expected values from nibabel 5 (img.shape, img.affine, img.get_fdata()).
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../shared/data/volumes/mni_icbm152_t1_tal_nlin_sym_09a_converted.nii.gz");
    let vf = read(&path);
    let v = &vf.volume;
    assert_eq!(v.dims(), [197, 233, 189]);
    assert_eq!(v.spacing(), [1.0, 1.0, 1.0]);
    assert_eq!(*v.linear(), Matrix3::identity());
    assert_eq!(v.origin(), Point3::new(-98.0, -134.0, -72.0));
    assert_eq!(v.range(), (0.0, 255.0));
    assert_eq!(v.at(98, 116, 94), 198.0);
    assert_eq!(v.at(120, 130, 100), 223.0);
    assert_eq!(v.at(10, 20, 30), 0.0);
    let mean = v.data().iter().map(|&x| f64::from(x)).sum::<f64>() / v.data().len() as f64;
    assert!((mean - 38.438930276559084).abs() < 1e-6, "mean {mean}");
    assert!(vf.source.contains("u8"));
    assert!(vf.notes.iter().any(|n| n.contains("sform_code 2")));
}

// ---------------------------------------------------------------------------
// Raw + JSON.

#[test]
fn raw_with_json_header_big_endian_and_header_bytes() {
    let dir = scratch("raw");
    let values: Vec<i16> = (0..30).map(|i| 100 - 7 * i as i16).collect();
    let mut bytes = vec![0xAB; 16];
    bytes.extend(values.iter().flat_map(|v| v.to_be_bytes()));
    std::fs::write(dir.join("v.raw"), &bytes).unwrap();
    std::fs::write(
        dir.join("v.json"),
        r#"{"dims": [5, 3, 2], "spacing": [0.5, 1.0, 3.0], "origin": [1, -2, 4.5],
            "dtype": "int16", "byte_order": "big", "header_bytes": 16,
            "intensity_scale": {"slope": 0.5, "intercept": 10}, "iso_value": 40}"#,
    )
    .unwrap();
    for given in ["v.raw", "v.json"] {
        let vf = read(&dir.join(given));
        let v = &vf.volume;
        assert_eq!(v.dims(), [5, 3, 2]);
        assert_eq!(v.spacing(), [0.5, 1.0, 3.0]);
        assert_eq!(v.origin(), Point3::new(1.0, -2.0, 4.5));
        for (s, x) in v.data().iter().zip(&values) {
            assert_eq!(*s, 0.5 * f32::from(*x) + 10.0);
        }
        assert_eq!(vf.iso_value, Some(30.0));
    }
    // Wrong size, unknown dtype, missing header.
    std::fs::write(dir.join("short.raw"), &bytes[..50]).unwrap();
    std::fs::write(
        dir.join("short.json"),
        r#"{"dims": [5, 3, 2], "dtype": "i16"}"#,
    )
    .unwrap();
    let e = read_err(&dir.join("short.raw"));
    assert!(e.contains("short.raw") && e.contains("60"), "{e}");
    std::fs::write(dir.join("odd.raw"), &bytes[..60]).unwrap();
    std::fs::write(
        dir.join("odd.json"),
        r#"{"dims": [5, 3, 2], "dtype": "rgb"}"#,
    )
    .unwrap();
    let e = read_err(&dir.join("odd.raw"));
    assert!(e.contains("odd.json") && e.contains("dtype"), "{e}");
    std::fs::write(dir.join("alone.raw"), &bytes[..60]).unwrap();
    let e = read_err(&dir.join("alone.raw"));
    assert!(e.contains("alone.raw") && e.contains("JSON header"), "{e}");
    std::fs::write(dir.join("dims.raw"), &bytes[..60]).unwrap();
    std::fs::write(dir.join("dims.json"), r#"{"dims": [5, 0, 2]}"#).unwrap();
    let e = read_err(&dir.join("dims.raw"));
    assert!(e.contains("dims.json") && e.contains("dims"), "{e}");
}

#[test]
fn unknown_and_missing_paths_are_clear_errors() {
    let dir = scratch("unknown");
    std::fs::write(dir.join("v.xyz"), "1 2 3\n").unwrap();
    let e = read_err(&dir.join("v.xyz"));
    assert!(e.contains("v.xyz") && e.contains(".nii"), "{e}");
    let e = read_err(&dir.join("missing.nii"));
    assert!(e.contains("missing.nii"), "{e}");
}

// ---------------------------------------------------------------------------
// Slice directories, multi-page TIFF, EXR.

/// The test pattern: distinct in x, y and z, so transposed or reordered
/// slices show.
fn voxel(i: usize, j: usize, k: usize) -> u16 {
    (i + 10 * j + 100 * k) as u16
}

fn write_png(path: &Path, w: u32, h: u32, k: usize, sixteen: bool) {
    if sixteen {
        let px: Vec<u16> = (0..h as usize)
            .flat_map(|j| (0..w as usize).map(move |i| voxel(i, j, k) * 50))
            .collect();
        image::ImageBuffer::<image::Luma<u16>, _>::from_raw(w, h, px)
            .unwrap()
            .save(path)
            .unwrap();
    } else {
        let px: Vec<u8> = (0..h as usize)
            .flat_map(|j| (0..w as usize).map(move |i| (voxel(i, j, k) % 256) as u8))
            .collect();
        image::GrayImage::from_raw(w, h, px)
            .unwrap()
            .save(path)
            .unwrap();
    }
}

#[test]
fn png_slice_directories_sort_by_number_and_keep_x_in_columns() {
    let dir = scratch("png");
    let (nx, ny, nz) = (5usize, 3usize, 12usize);
    for sixteen in [false, true] {
        let stack = dir.join(if sixteen { "p16" } else { "p8" });
        std::fs::create_dir_all(&stack).unwrap();
        for k in 0..nz {
            write_png(
                &stack.join(format!("slice_{k}.png")),
                nx as u32,
                ny as u32,
                k,
                sixteen,
            );
        }
        std::fs::write(stack.join("notes.txt"), "not a slice").unwrap();
        let opts = VolumeReadOptions {
            spacing: Some([0.5, 0.8, 2.0]),
            origin: Some([-1.0, 2.0, 30.0]),
        };
        let vf = read_volume(&stack, &opts).unwrap();
        let v = &vf.volume;
        assert_eq!(v.dims(), [nx, ny, nz]);
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let want = if sixteen {
                        f32::from(voxel(i, j, k) * 50)
                    } else {
                        f32::from((voxel(i, j, k) % 256) as u8)
                    };
                    assert_eq!(v.at(i, j, k), want, "({i},{j},{k}) 16-bit {sixteen}");
                }
            }
        }
        assert_eq!(v.spacing(), [0.5, 0.8, 2.0]);
        assert_eq!(v.world([1.0, 1.0, 1.0]), Point3::new(-0.5, 2.8, 32.0));
        assert!(vf.source.contains(if sixteen { "16-bit" } else { "8-bit" }));
        // Without options: unit spacing and a note asking for --spacing.
        let vf = read(&stack);
        assert_eq!(vf.volume.spacing(), [1.0; 3]);
        assert!(
            vf.notes.iter().any(|n| n.contains("--spacing")),
            "{:?}",
            vf.notes
        );
    }
}

#[test]
fn png_sidecar_gives_geometry_scale_and_iso() {
    let dir = scratch("png-sidecar");
    for k in 0..3 {
        write_png(&dir.join(format!("s{k}.png")), 4, 2, k, false);
    }
    std::fs::write(
        dir.join("volume.json"),
        r#"{"dims": [4, 2, 3], "spacing": [0.25, 0.5, 1.5], "origin": [3, 2, 1],
            "intensity_scale": {"slope": 0.01, "intercept": -1}, "iso_value": 128}"#,
    )
    .unwrap();
    let vf = read(&dir);
    assert_eq!(vf.volume.spacing(), [0.25, 0.5, 1.5]);
    assert_eq!(vf.volume.origin(), Point3::new(3.0, 2.0, 1.0));
    assert!(
        (f64::from(vf.volume.at(3, 1, 2)) - (0.01 * f64::from(voxel(3, 1, 2)) - 1.0)).abs() < 1e-6
    );
    assert!((vf.iso_value.unwrap() - 0.28).abs() < 1e-12);
    // --spacing wins over the sidecar.
    let opts = VolumeReadOptions {
        spacing: Some([2.0, 2.0, 2.0]),
        origin: None,
    };
    let vf = read_volume(&dir, &opts).unwrap();
    assert_eq!(vf.volume.spacing(), [2.0; 3]);
    assert_eq!(vf.volume.origin(), Point3::new(3.0, 2.0, 1.0));
    // A sidecar whose dims disagree is an error naming it.
    std::fs::write(dir.join("volume.json"), r#"{"dims": [4, 2, 4]}"#).unwrap();
    let e = read_err(&dir);
    assert!(e.contains("volume.json") && e.contains("dims"), "{e}");
}

#[test]
fn bad_slice_directories_name_the_file() {
    let dir = scratch("png-bad");
    let case = |name: &str| {
        let d = dir.join(name);
        std::fs::create_dir_all(&d).unwrap();
        d
    };
    let d = case("sizes");
    write_png(&d.join("slice_0.png"), 4, 3, 0, false);
    write_png(&d.join("slice_1.png"), 4, 3, 1, false);
    write_png(&d.join("slice_2.png"), 3, 4, 2, false);
    let e = read_err(&d);
    assert!(e.contains("slice_2.png") && e.contains("same size"), "{e}");
    let d = case("depths");
    write_png(&d.join("slice_0.png"), 4, 3, 0, false);
    write_png(&d.join("slice_1.png"), 4, 3, 1, true);
    let e = read_err(&d);
    assert!(
        e.contains("slice_1.png") && e.contains("mixed bit depths"),
        "{e}"
    );
    let d = case("nonumber");
    write_png(&d.join("slice_0.png"), 4, 3, 0, false);
    write_png(&d.join("extra.png"), 4, 3, 1, false);
    let e = read_err(&d);
    assert!(e.contains("extra.png") && e.contains("number"), "{e}");
    let d = case("empty");
    std::fs::write(d.join("readme.txt"), "x").unwrap();
    let e = read_err(&d);
    assert!(e.contains("no slice images"), "{e}");
    let d = case("corrupt");
    write_png(&d.join("slice_0.png"), 4, 3, 0, false);
    std::fs::write(d.join("slice_1.png"), b"\x89PNG\r\n\x1a\nnot really").unwrap();
    let e = read_err(&d);
    assert!(e.contains("slice_1.png") && e.contains("PNG"), "{e}");
    let d = case("mixed");
    write_png(&d.join("slice_0.png"), 4, 3, 0, false);
    write_exr(&d.join("slice_1.exr"), 4, 3, &[0.0; 12]);
    let e = read_err(&d);
    assert!(e.contains("several kinds"), "{e}");
    // Colour slices become luma; grey written as RGB stays exact.
    let d = case("rgb");
    for k in 0..2 {
        let px: Vec<u8> = (0..12).flat_map(|i| [i as u8 * 10 + k; 3]).collect();
        image::RgbImage::from_raw(4, 3, px)
            .unwrap()
            .save(d.join(format!("c{k}.png")))
            .unwrap();
    }
    let vf = read(&d);
    assert_eq!(vf.volume.at(2, 1, 1), 61.0);
    assert!(
        vf.notes.iter().any(|n| n.contains("luma")),
        "{:?}",
        vf.notes
    );
}

fn write_exr(path: &Path, w: usize, h: usize, samples: &[f32]) {
    use exr::prelude::*;
    let channels = AnyChannels::sort(SmallVec::from_vec(vec![AnyChannel::new(
        "Y",
        FlatSamples::F32(samples.to_vec()),
    )]));
    let layer = Layer::new(
        (w, h),
        LayerAttributes::default(),
        Encoding::SMALL_LOSSLESS,
        channels,
    );
    Image::from_layer(layer).write().to_file(path).unwrap();
}

#[test]
fn exr_slices_and_a_single_exr() {
    let dir = scratch("exr");
    let (nx, ny, nz) = (6, 4, 3);
    let value =
        |i: usize, j: usize, k: usize| (i as f32) * 0.5 - (j as f32) * 1.25 + (k as f32) * 10.0;
    for k in 0..nz {
        let s: Vec<f32> = (0..ny)
            .flat_map(|j| (0..nx).map(move |i| value(i, j, k)))
            .collect();
        write_exr(&dir.join(format!("slice_{k}.exr")), nx, ny, &s);
    }
    let v = read(&dir).volume;
    assert_eq!(v.dims(), [nx, ny, nz]);
    for (n, &s) in v.data().iter().enumerate() {
        let (i, j, k) = (n % nx, (n / nx) % ny, n / (nx * ny));
        assert_eq!(s, value(i, j, k));
    }
    let one = read(&dir.join("slice_2.exr")).volume;
    assert_eq!(one.dims(), [nx, ny, 1]);
    assert_eq!(one.at(5, 3, 0), value(5, 3, 2));
}

#[test]
fn multipage_tiff_u16_and_f32_with_imagej_spacing() {
    use tiff::encoder::{Rational, TiffEncoder, colortype};
    use tiff::tags::{ResolutionUnit, Tag};
    let dir = scratch("tiff");
    let (nx, ny, nz) = (5usize, 4usize, 3usize);
    for float in [false, true] {
        let path = dir.join(if float { "f.tif" } else { "u.tiff" });
        let mut enc = TiffEncoder::new(std::fs::File::create(&path).unwrap()).unwrap();
        for k in 0..nz {
            let px: Vec<u16> = (0..ny)
                .flat_map(|j| (0..nx).map(move |i| voxel(i, j, k)))
                .collect();
            macro_rules! page {
                ($c:ty, $data:expr) => {{
                    let mut page = enc.new_image::<$c>(nx as u32, ny as u32).unwrap();
                    page.resolution_unit(ResolutionUnit::None);
                    page.x_resolution(Rational { n: 4, d: 1 });
                    page.y_resolution(Rational { n: 2, d: 1 });
                    if k == 0 {
                        page.encoder()
                            .write_tag(
                                Tag::ImageDescription,
                                "ImageJ=1.54f\nunit=micron\nspacing=1500\n",
                            )
                            .unwrap();
                    }
                    page.write_data($data).unwrap();
                }};
            }
            if float {
                let f: Vec<f32> = px.iter().map(|&v| f32::from(v) * 0.5).collect();
                page!(colortype::Gray32Float, &f);
            } else {
                page!(colortype::Gray16, &px);
            }
        }
        drop(enc); // closes the file
        let vf = read(&path);
        let v = &vf.volume;
        assert_eq!(v.dims(), [nx, ny, nz]);
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let want = f32::from(voxel(i, j, k)) * if float { 0.5 } else { 1.0 };
                    assert_eq!(v.at(i, j, k), want);
                }
            }
        }
        let s = v.spacing();
        let want = [0.25e-3, 0.5e-3, 1.5];
        assert!((0..3).all(|a| (s[a] - want[a]).abs() < 1e-12), "{s:?}");
        assert!(
            vf.notes.iter().any(|n| n.contains("ImageJ")),
            "{:?}",
            vf.notes
        );
    }
    std::fs::write(dir.join("bad.tif"), b"II*\0garbage").unwrap();
    let e = read_err(&dir.join("bad.tif"));
    assert!(e.contains("bad.tif") && e.contains("TIFF"), "{e}");
}

// ---------------------------------------------------------------------------
// `subdyn info VOLUME`.

#[test]
fn info_prints_the_grid_of_a_volume_and_one_line_for_a_bad_one() {
    let dir = scratch("info");
    let mut h = Nifti::new([3, 2, 2], 2, 8);
    h.sform = 1;
    h.srow = [
        [0.5, 0.0, 0.0, -4.0],
        [0.0, 2.0, 0.0, 5.0],
        [0.0, 0.0, 1.5, 6.0],
    ];
    let voxels: Vec<u8> = (0..12).map(|i| 10 + i).collect();
    std::fs::write(dir.join("v.nii"), h.file(&voxels)).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_subdyn"))
        .args(["info", "v.nii", "--json"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["kind"], "volume");
    assert_eq!(v["dims"], serde_json::json!([3, 2, 2]));
    assert_eq!(v["spacing"], serde_json::json!([0.5, 2.0, 1.5]));
    assert_eq!(v["origin"], serde_json::json!([-4.0, 5.0, 6.0]));
    assert_eq!(v["range"], serde_json::json!([10.0, 21.0]));
    assert_eq!(v["world_box"]["max"], serde_json::json!([-3.0, 7.0, 7.5]));

    let mut bad = h.clone();
    bad.dims[0] = -1;
    std::fs::write(dir.join("bad.nii"), bad.file(&voxels)).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_subdyn"))
        .args(["info", "bad.nii"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(
        err.contains("bad.nii") && err.contains("dim[1] = -1"),
        "{err}"
    );
}

#[test]
fn tiff_slice_directory_and_4d_nifti() {
    use tiff::encoder::{TiffEncoder, colortype};
    let dir = scratch("tiff-dir");
    let (nx, ny, nz) = (4usize, 3usize, 11usize);
    for k in 0..nz {
        let px: Vec<u16> = (0..ny)
            .flat_map(|j| (0..nx).map(move |i| voxel(i, j, k)))
            .collect();
        let file = std::fs::File::create(dir.join(format!("img{k}.tif"))).unwrap();
        TiffEncoder::new(file)
            .unwrap()
            .write_image::<colortype::Gray16>(nx as u32, ny as u32, &px)
            .unwrap();
    }
    let vf = read(&dir);
    assert_eq!(vf.volume.dims(), [nx, ny, nz]);
    // img10 sorts after img9 by number.
    assert_eq!(vf.volume.at(3, 2, 10), f32::from(voxel(3, 2, 10)));
    assert_eq!(vf.volume.at(1, 0, 9), f32::from(voxel(1, 0, 9)));

    // A 4D NIfTI: the first of three volumes, with a note.
    let h = Nifti::new([2, 2, 2], 2, 8);
    let mut h4 = h.clone();
    h4.dims.push(3);
    let voxels: Vec<u8> = (0..24).collect();
    std::fs::write(dir.join("t.nii"), h4.file(&voxels)).unwrap();
    let vf = read(&dir.join("t.nii"));
    assert_eq!(vf.volume.dims(), [2, 2, 2]);
    assert_eq!(vf.volume.data(), &[0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0]);
    assert!(
        vf.notes.iter().any(|n| n.contains("3 volumes")),
        "{:?}",
        vf.notes
    );
}
