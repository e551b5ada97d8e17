//! Volumes: the grid, smoothing, edge potential, thresholds, slice pictures.

use nalgebra::Matrix3;
use subdyn::math::{Point3, Real, Vector3};
use subdyn::volume::{
    Volume, edge_potential, gaussian_smoothed, gaussian_smoothed_owned, otsu_threshold,
};

fn volume_from(dims: [usize; 3], spacing: [Real; 3], f: impl Fn([usize; 3]) -> f32) -> Volume {
    let mut data = Vec::new();
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                data.push(f([i, j, k]));
            }
        }
    }
    Volume::new(dims, data, spacing, Point3::new(-3.0, 2.0, 10.0)).unwrap()
}

#[test]
fn samples_sit_at_voxel_centres_and_a_linear_ramp_is_interpolated_exactly() {
    let ramp = |c: [usize; 3]| 2.0 * c[0] as f32 - c[1] as f32 + 0.5 * c[2] as f32;
    let v = volume_from([5, 6, 7], [0.5, 1.0, 2.0], ramp);
    // World of index (i, j, k) = origin + (0.5 i, j, 2 k).
    let p = v.world([1.0, 2.0, 3.0]);
    assert!((p - Point3::new(-2.5, 4.0, 16.0)).norm() < 1e-12);
    assert_eq!(v.sample(&p), ramp([1, 2, 3]) as Real);
    let c = v.continuous_index(&Point3::new(-2.3, 4.25, 15.0));
    assert!(
        (c[0] - 1.4).abs() < 1e-12 && (c[1] - 2.25).abs() < 1e-12 && (c[2] - 2.5).abs() < 1e-12
    );
    let q = Point3::new(-2.3, 4.25, 15.0);
    assert!((v.sample(&q) - (2.0 * 1.4 - 2.25 + 0.5 * 2.5)).abs() < 1e-6);
    // The gradient in world units: d/dx = 2 / 0.5, d/dy = −1 / 1, d/dz = 0.5 / 2.
    let g = v.gradient(&q);
    assert!((g - Vector3::new(4.0, -1.0, 0.25)).norm() < 1e-5, "{g}");
}

#[test]
fn bad_grids_are_errors_not_panics() {
    assert!(Volume::new([2, 2, 0], vec![], [1.0; 3], Point3::origin()).is_err());
    assert!(Volume::new([2, 2, 2], vec![0.0; 7], [1.0; 3], Point3::origin()).is_err());
    let mut nan = vec![0.0; 8];
    nan[5] = f32::NAN;
    let e = Volume::new([2, 2, 2], nan, [1.0; 3], Point3::origin()).unwrap_err();
    assert!(e.to_string().contains("voxel 5"), "{e}");
    assert!(Volume::new([2, 2, 2], vec![0.0; 8], [1.0, 0.0, 1.0], Point3::origin()).is_err());
    let singular = Matrix3::new(1.0, 2.0, 0.0, 2.0, 4.0, 0.0, 0.0, 0.0, 1.0);
    assert!(Volume::with_affine([2, 2, 2], vec![0.0; 8], singular, Point3::origin()).is_err());
}

#[test]
fn smoothing_keeps_constants_and_spreads_an_impulse_by_sigma_in_world_units() {
    let flat = volume_from([9, 9, 9], [1.0; 3], |_| 3.5);
    let s = gaussian_smoothed(&flat, 1.5).unwrap();
    assert!(s.data().iter().all(|&v| (v - 3.5).abs() < 1e-5));
    // An impulse on anisotropic voxels: the variance along each world axis is σ².
    let dims = [41, 21, 11];
    let spacing = [0.5, 1.0, 2.0];
    let centre = [20, 10, 5];
    let imp = volume_from(dims, spacing, |c| if c == centre { 1.0 } else { 0.0 });
    let sigma = 2.0;
    let s = gaussian_smoothed(&imp, sigma).unwrap();
    let total: f64 = s.data().iter().map(|&v| v as f64).sum();
    assert!((total - 1.0).abs() < 1e-5, "mass {total}");
    for a in 0..3 {
        let mut var = 0.0;
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let c = [i, j, k];
                    let d = (c[a] as f64 - centre[a] as f64) * spacing[a];
                    var += d * d * s.at(i, j, k) as f64;
                }
            }
        }
        // Integer sampling of a Gaussian with σ_a = σ / s_a voxels keeps the
        // variance within a few % for σ_a ≥ 1 (z has σ_a = 1).
        assert!(
            (var.sqrt() - sigma).abs() < 0.06 * sigma,
            "axis {a}: σ {}",
            var.sqrt()
        );
    }
    assert!(gaussian_smoothed(&imp, -1.0).is_err());
    assert!(gaussian_smoothed(&imp, f64::NAN).is_err());
}

#[test]
fn the_edge_potential_is_lowest_on_the_step_and_otsu_splits_two_levels() {
    // A step along x between 10 and 30 at x = 12.5 (between samples 12 and 13).
    let step = volume_from(
        [26, 4, 4],
        [1.0; 3],
        |c| if c[0] <= 12 { 10.0 } else { 30.0 },
    );
    let s = gaussian_smoothed(&step, 1.0).unwrap();
    let p = edge_potential(&s).unwrap();
    let row: Vec<f32> = (0..26).map(|i| p.at(i, 2, 2)).collect();
    let min = row.iter().cloned().fold(f32::INFINITY, f32::min);
    assert!((min + 1.0).abs() < 1e-6, "normalised to −1: {min}");
    assert!(row[12] == min || row[13] == min, "{row:?}");
    assert!(row[2].abs() < 0.01 && row[23].abs() < 0.01);
    let t = otsu_threshold(&step).unwrap();
    assert!(t > 10.0 && t < 30.0, "{t}");
    let flat = volume_from([4, 4, 4], [1.0; 3], |_| 1.0);
    assert!(edge_potential(&flat).is_err());
    assert!(otsu_threshold(&flat).is_err());
}

#[test]
fn slice_pictures_show_the_contour_where_the_surface_cuts_the_plane() {
    use subdyn::render::slice_overlay;
    let v = volume_from([20, 20, 20], [1.0; 3], |c| (c[0] + c[1]) as f32);
    // A cube surface from world (−3+5, 2+5, 10+5) to (+10 each side).
    let mut cube = subdyn::examples::cube();
    for p in &mut cube.positions {
        *p = Point3::new(2.0, 7.0, 15.0) + 10.0 * p.coords;
    }
    let yellow = [255, 220, 0];
    // z index 10 is world z 20, inside the cube's z range [15, 25].
    let z = |k: Real| v.world([0.0, 0.0, k]).z;
    let pic = slice_overlay(&v, 2, z(10.0), 200, &[(&cube, yellow)], "mm").unwrap();
    assert_eq!((pic.width(), pic.height()), (200, 200));
    let drawn = pic.count(|c| c == yellow);
    // The square contour's side is 10 voxels = 100 pixels: about 4 × 100 × 2 pixels.
    assert!(drawn > 600 && drawn < 1200, "{drawn} contour pixels");
    // z index 2 (world 12) misses the cube: no contour, only the label.
    let none = slice_overlay(&v, 2, z(2.0), 200, &[(&cube, yellow)], "").unwrap();
    assert_eq!(none.count(|c| c == yellow), 0);
    assert!(slice_overlay(&v, 3, z(0.0), 200, &[], "").is_err());
    assert!(slice_overlay(&v, 2, z(20.0), 200, &[], "").is_err());
}

/// The in-place passes equal a direct separable convolution (f64, borders
/// repeating the edge sample, taps `exp(−½ (t/σ_a)²)` to `⌈3 σ_a⌉`,
/// normalised) on an anisotropic grid with a pseudo-random image, and the
/// owned variant gives the same samples bit for bit.
#[test]
fn in_place_smoothing_equals_a_direct_separable_convolution() {
    let dims = [9, 7, 11];
    let spacing = [0.7, 1.0, 1.6];
    let sigma = 1.3;
    let value = |c: [usize; 3]| {
        let h = (c[0] * 73_856_093) ^ (c[1] * 19_349_663) ^ (c[2] * 83_492_791);
        (h % 1000) as f32 / 1000.0
    };
    let v = volume_from(dims, spacing, value);
    let s = gaussian_smoothed(&v, sigma).unwrap();
    let owned = gaussian_smoothed_owned(v.clone(), sigma).unwrap();
    assert_eq!(s.data(), owned.data());
    assert_eq!(s.dims(), v.dims());
    assert_eq!(s.linear(), v.linear());
    let taps: Vec<Vec<Real>> = (0..3)
        .map(|a| {
            let sv = sigma / spacing[a];
            let r = (3.0 * sv).ceil() as isize;
            let w: Vec<Real> = (-r..=r)
                .map(|t| (-0.5 * (t as Real / sv).powi(2)).exp())
                .collect();
            let sum: Real = w.iter().sum();
            w.iter().map(|x| x / sum).collect()
        })
        .collect();
    let clamp = |i: isize, n: usize| i.clamp(0, n as isize - 1) as usize;
    let mut worst = 0.0f64;
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let mut sum = 0.0;
                let (rx, ry, rz) = (
                    (taps[0].len() / 2) as isize,
                    (taps[1].len() / 2) as isize,
                    (taps[2].len() / 2) as isize,
                );
                for (tz, wz) in taps[2].iter().enumerate() {
                    for (ty, wy) in taps[1].iter().enumerate() {
                        for (tx, wx) in taps[0].iter().enumerate() {
                            let c = [
                                clamp(i as isize + tx as isize - rx, dims[0]),
                                clamp(j as isize + ty as isize - ry, dims[1]),
                                clamp(k as isize + tz as isize - rz, dims[2]),
                            ];
                            sum += wx * wy * wz * value(c) as Real;
                        }
                    }
                }
                worst = worst.max((s.at(i, j, k) as Real - sum).abs());
            }
        }
    }
    assert!(worst < 1e-5, "in-place smoothing differs by {worst}");
    assert!(gaussian_smoothed_owned(v, -1.0).is_err());
}
