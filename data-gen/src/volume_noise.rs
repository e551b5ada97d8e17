//! The noise models of `data-gen volume`, drawn from data-gen's own seeded
//! generator ([`crate::rng::Rng`]), so that the output is byte-identical for
//! a seed on every platform.

use clap::ValueEnum;
use serde::Serialize;

use crate::rng::Rng;

/// Stream key of `data-gen volume` ([`Rng::for_item`]`(seed, VOLUME_STREAM, …)`).
pub const VOLUME_STREAM: u64 = 0x766F_6C75_6D65; // "volume"
/// Item of the noise stream.
pub const NOISE_ITEM: u64 = 1;
/// Item of the bias-field coefficients.
pub const BIAS_ITEM: u64 = 2;

/// How noise of standard deviation σ is added to a noiseless intensity `v`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum NoiseModel {
    /// `v + σ n`, n ~ N(0, 1): CT-like, unbiased, can go negative.
    Gaussian,
    /// `√((v + σ n₁)² + (σ n₂)²)`: the magnitude of complex Gaussian noise, as
    /// in MRI. Never negative; biased upwards where `v` is small
    /// (mean σ√(π/2) where v = 0).
    Rician,
}

/// Adds noise of standard deviation `sigma` to every voxel, in storage order,
/// from the stream `(seed, VOLUME_STREAM, NOISE_ITEM)`. `sigma = 0` leaves `data` alone.
pub fn add_noise(data: &mut [f32], sigma: f64, model: NoiseModel, seed: u64) {
    if sigma == 0.0 {
        return;
    }
    let mut rng = Rng::for_item(seed, VOLUME_STREAM, NOISE_ITEM);
    for v in data.iter_mut() {
        let x = f64::from(*v);
        *v = match model {
            NoiseModel::Gaussian => x + sigma * rng.gaussian(),
            NoiseModel::Rician => {
                let re = x + sigma * rng.gaussian();
                let im = sigma * rng.gaussian();
                re.hypot(im)
            }
        } as f32;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaussian_noise_has_the_requested_spread_and_repeats_per_seed() {
        let noisy = |seed| {
            let mut data = vec![5.0f32; 100_000];
            add_noise(&mut data, 0.5, NoiseModel::Gaussian, seed);
            data
        };
        let a = noisy(3);
        let n = a.len() as f64;
        let mean = a.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
        let var = a
            .iter()
            .map(|&v| (f64::from(v) - mean).powi(2))
            .sum::<f64>()
            / n;
        assert!(
            (mean - 5.0).abs() < 0.01 && (var.sqrt() - 0.5).abs() < 0.01,
            "{mean} {var}"
        );
        assert_eq!(a, noisy(3));
        assert_ne!(a, noisy(4));
    }

    #[test]
    fn rician_background_mean_is_sigma_sqrt_half_pi() {
        let mut data = vec![0.0f32; 100_000];
        add_noise(&mut data, 2.0, NoiseModel::Rician, 1);
        let mean = data.iter().map(|&v| f64::from(v)).sum::<f64>() / data.len() as f64;
        let expected = 2.0 * (std::f64::consts::PI / 2.0).sqrt();
        assert!((mean - expected).abs() < 0.02, "{mean} vs {expected}");
    }
}
