//! Automatic thresholds.

use super::Volume;
use crate::error::{Error, Result};

/// Otsu's threshold (Otsu 1979): the level that maximises the between-class
/// variance of a 256-bin histogram of the samples. Errors for a constant volume.
pub fn otsu_threshold(volume: &Volume) -> Result<f32> {
    let (lo, hi) = volume.range();
    if hi.partial_cmp(&lo) != Some(std::cmp::Ordering::Greater) {
        return Err(Error::input(format!(
            "the volume is constant ({lo}): no threshold separates an object"
        )));
    }
    const BINS: usize = 256;
    let scale = (BINS as f32 - 1.0) / (hi - lo);
    let mut hist = [0u64; BINS];
    for &v in volume.data() {
        hist[((v - lo) * scale) as usize] += 1;
    }
    let total: f64 = hist.iter().sum::<u64>() as f64;
    let sum_all: f64 = hist
        .iter()
        .enumerate()
        .map(|(i, &h)| i as f64 * h as f64)
        .sum();
    let (mut w0, mut sum0, mut best, mut best_t) = (0.0, 0.0, -1.0, 0);
    for (t, &h) in hist.iter().enumerate().take(BINS - 1) {
        w0 += h as f64;
        sum0 += t as f64 * h as f64;
        let w1 = total - w0;
        if w0 == 0.0 || w1 == 0.0 {
            continue;
        }
        let m0 = sum0 / w0;
        let m1 = (sum_all - sum0) / w1;
        let between = w0 * w1 * (m0 - m1) * (m0 - m1);
        if between > best {
            best = between;
            best_t = t;
        }
    }
    Ok(lo + (best_t as f32 + 0.5) / scale)
}
