//! Round trips: every `data-gen volume` format read back by
//! `subdyn::io::read_volume` agrees with the f32 NIfTI reference — same
//! grid (anisotropic spacing, non-zero origin), same samples (exactly for
//! f32 formats, within half a quantisation step for PNG / 16-bit TIFF, whose
//! sidecar scale the reader applies) and the physical iso-value.

mod common;

use common::{json, ok, scratch};
use subdyn::io::{VolumeReadOptions, read_volume};

const ARGS: &[&str] = &[
    "volume",
    "torus",
    "--dims",
    "22,18,9",
    "--spacing",
    "0.12,0.1,0.25",
    "--blur",
    "0.08",
    "--noise",
    "0.5",
    "--inside",
    "100",
    "--outside",
    "20",
    "--seed",
    "3",
];

#[test]
fn every_format_reads_back_onto_the_same_grid_and_samples() {
    let dir = scratch("subdyn-reads");
    let generate = |out: &str, format: &str| {
        ok(&dir, &[ARGS, &["--format", format, "-o", out]].concat());
    };
    generate("ref.nii", "nifti");
    let opts = VolumeReadOptions::default();
    let reference = read_volume(dir.join("ref.nii"), &opts).expect("reference NIfTI");
    let side = json(&dir.join("ref.json"));
    let triple =
        |key: &str| -> [f64; 3] { std::array::from_fn(|k| side[key][k].as_f64().expect("number")) };
    let (spacing, origin) = (triple("spacing"), triple("origin"));
    let iso = side["iso_value_physical"].as_f64().expect("iso");
    assert_eq!(iso, 60.0);
    assert!(origin.iter().all(|&o| o != 0.0), "origin {origin:?}");
    let rv = &reference.volume;
    assert_eq!(rv.dims(), [22, 18, 9]);
    for a in 0..3 {
        assert!((rv.spacing()[a] - spacing[a]).abs() < 1e-6);
        assert!((rv.origin()[a] - origin[a]).abs() < 1e-5);
    }
    assert_eq!(reference.iso_value, Some(iso));

    // (output, format, its sidecar)
    let cases: [(&str, &str, &str); 7] = [
        ("v.nii.gz", "nifti-gz", "v.json"),
        ("v.raw", "raw", "v.json"),
        ("f.tif", "tiff-f32", "f.json"),
        ("exr", "exr", "exr/volume.json"),
        ("u.tif", "tiff", "u.json"),
        ("p16", "png16", "p16/volume.json"),
        ("p8", "png8", "p8/volume.json"),
    ];
    for (out, format, sidecar) in cases {
        generate(out, format);
        let vf = read_volume(dir.join(out), &opts).unwrap_or_else(|e| panic!("{format}: {e}"));
        let v = &vf.volume;
        assert_eq!(v.dims(), rv.dims(), "{format}");
        for a in 0..3 {
            assert!(
                (v.spacing()[a] - spacing[a]).abs() < 1e-6,
                "{format} spacing"
            );
            assert!((v.origin()[a] - origin[a]).abs() < 1e-5, "{format} origin");
        }
        // Quantised formats: half a step of the sidecar's slope.
        let sidecar = json(&dir.join(sidecar));
        let slope = sidecar["intensity_scale"]["slope"].as_f64().expect("slope");
        let tol = if slope == 1.0 {
            0.0
        } else {
            0.5 * slope * 1.001
        };
        let worst = v
            .data()
            .iter()
            .zip(rv.data())
            .map(|(a, b)| (f64::from(*a) - f64::from(*b)).abs())
            .fold(0.0, f64::max);
        assert!(worst <= tol, "{format}: worst sample error {worst} > {tol}");
        let got_iso = vf.iso_value.expect("iso from the sidecar");
        assert!(
            (got_iso - iso).abs() < 1e-9 * iso,
            "{format}: iso {got_iso}"
        );
    }
    // The .json of a raw volume reads the same as the .raw.
    let via_json = read_volume(dir.join("v.json"), &opts).expect("raw via json");
    assert_eq!(via_json.volume.data(), rv.data());
}
