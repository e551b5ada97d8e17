//! Criterion bench of NIfTI input: reading a 256³ f32 volume with
//! `subdyn::io::read_volume` from `.nii.gz` and `.nii`, against the baseline
//! of only gunzipping the same `.nii.gz` into memory (flate2, the same
//! decoder). The ratio read / gunzip says how much of the read is inflation.
//!
//! Inputs: a synthetic 256³ f32 volume written to a temporary directory (a
//! smooth blob plus deterministic noise, so it compresses about as badly as
//! an MRI). Outputs: criterion's timings.
//!
//! Run with `cargo bench --bench volume_read`.

use std::io::{Read, Write};

use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;

use subdyn::io::{VolumeReadOptions, read_volume};

const N: usize = 256;

/// A NIfTI-1 FLOAT32 file of `data` on an `N³` grid, 1 mm, sform = identity.
fn nifti_bytes(data: &[f32]) -> Vec<u8> {
    let mut h = vec![0u8; 352];
    h[0..4].copy_from_slice(&348i32.to_le_bytes());
    for (n, d) in [3i16, N as i16, N as i16, N as i16, 1, 1, 1, 1]
        .iter()
        .enumerate()
    {
        h[40 + 2 * n..42 + 2 * n].copy_from_slice(&d.to_le_bytes());
    }
    h[70..72].copy_from_slice(&16i16.to_le_bytes());
    h[72..74].copy_from_slice(&32i16.to_le_bytes());
    for n in 0..4 {
        h[76 + 4 * n..80 + 4 * n].copy_from_slice(&1f32.to_le_bytes());
    }
    h[108..112].copy_from_slice(&352f32.to_le_bytes());
    h[123] = 2;
    h[254..256].copy_from_slice(&1i16.to_le_bytes());
    for r in 0..3 {
        let at = 280 + 16 * r + 4 * r;
        h[at..at + 4].copy_from_slice(&1f32.to_le_bytes());
    }
    h[344..348].copy_from_slice(b"n+1\0");
    h.reserve(data.len() * 4);
    for v in data {
        h.extend_from_slice(&v.to_le_bytes());
    }
    h
}

fn volume_read(c: &mut Criterion) {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let data: Vec<f32> = (0..N * N * N)
        .map(|i| {
            let (x, y, z) = (i % N, (i / N) % N, i / (N * N));
            let r = [x, y, z]
                .map(|a| (a as f32 - 128.0) / 80.0)
                .iter()
                .map(|d| d * d)
                .sum::<f32>();
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let noise = (state >> 40) as f32 / (1u64 << 24) as f32 - 0.5;
            100.0 / (1.0 + (8.0 * (r - 1.0)).exp()) + 20.0 + 4.0 * noise
        })
        .collect();
    let dir = tempfile::tempdir().expect("temporary directory");
    let plain = nifti_bytes(&data);
    let nii = dir.path().join("v.nii");
    let gz = dir.path().join("v.nii.gz");
    std::fs::write(&nii, &plain).expect("write .nii");
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    enc.write_all(&plain).expect("gzip");
    std::fs::write(&gz, enc.finish().expect("gzip")).expect("write .nii.gz");
    drop(plain);
    let opts = VolumeReadOptions::default();

    let mut group = c.benchmark_group("nifti_256");
    group.sample_size(10);
    group.bench_function("gunzip_only", |b| {
        b.iter(|| {
            let bytes = std::fs::read(&gz).expect("read");
            let mut out = Vec::with_capacity(N * N * N * 4 + 352);
            flate2::read::MultiGzDecoder::new(&bytes[..])
                .read_to_end(&mut out)
                .expect("gunzip");
            black_box(out.len())
        })
    });
    group.bench_function("read_volume_nii_gz", |b| {
        b.iter(|| black_box(read_volume(&gz, &opts).expect("read").volume.dims()))
    });
    group.bench_function("read_volume_nii", |b| {
        b.iter(|| black_box(read_volume(&nii, &opts).expect("read").volume.dims()))
    });
    group.finish();
}

criterion_group!(benches, volume_read);
criterion_main!(benches);
