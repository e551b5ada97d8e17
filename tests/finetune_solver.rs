//! The Levenberg-Marquardt solver of fine tuning and its sparse Cholesky:
//! the factorisation solves random sparse SPD systems (mixed node sizes,
//! padding and split nodes) to rounding; it refuses an indefinite matrix;
//! LM lowers a small sum of squares monotonically to its minimum; and on a
//! closed curve LM and argmin's nonlinear CG reach the same curve. The
//! product from the factor's slots and conjugate gradients preconditioned
//! by another matrix's factor are checked against dense algebra.

mod common;

use std::f64::consts::TAU;

use common::Rng;
use nalgebra::{DMatrix, DVector};

use subdyn::finetune::{
    CholeskyPattern, CurveFinetune, CurveFinetuneParams, FinetuneMethod, LeastSquares, LmParams,
    RELATIVE_RESIDUAL, Residuals, alpha_from_values, levenberg_marquardt, preconditioned_solution,
};
use subdyn::math::Point3;
use subdyn::subdivision::{CurveScheme, CurveTopology};

/// Random groups of three unknowns.
fn random_groups(rng: &mut Rng, n: usize) -> Vec<Vec<usize>> {
    (0..2 * n)
        .map(|_| (0..3).map(|_| rng.below(n)).collect())
        .collect()
}

/// Checks the factor of the random sparse SPD matrix `Σ_g v_g v_gᵀ + I`
/// over `groups` against a dense product, and that a negative diagonal is
/// refused (at every `refuse_every`-th unknown). Returns the pattern.
fn random_system(
    rng: &mut Rng,
    n: usize,
    node_of: &[usize],
    groups: &[Vec<usize>],
    refuse_every: usize,
) -> CholeskyPattern {
    let weights: Vec<Vec<f64>> = groups
        .iter()
        .map(|g| g.iter().map(|_| rng.uniform(-1.0, 1.0)).collect())
        .collect();
    let refs: Vec<&[usize]> = groups.iter().map(|g| g.as_slice()).collect();
    let (pattern, slots) = CholeskyPattern::new(n, node_of, &refs);
    let mut dense = DMatrix::<f64>::identity(n, n);
    let mut values = vec![0.0; pattern.num_values()];
    let mut s = 0;
    for (g, w) in groups.iter().zip(&weights) {
        for p in 0..g.len() {
            for q in p..g.len() {
                let twice = if q != p && g[p] == g[q] { 2.0 } else { 1.0 };
                values[slots[s]] += w[p] * w[q] * twice;
                s += 1;
                dense[(g[p], g[q])] += w[p] * w[q];
                if p != q {
                    dense[(g[q], g[p])] += w[p] * w[q];
                }
            }
        }
    }
    for i in 0..n {
        values[slots[s + i]] += 1.0;
    }
    let b: Vec<f64> = (0..n).map(|_| rng.uniform(-1.0, 1.0)).collect();
    // The product from the slots is the dense product.
    let ab = DVector::from_vec(pattern.product(&values, &b));
    let want = &dense * DVector::from_vec(b.clone());
    assert!((&ab - &want).norm() <= 1e-12 * (1.0 + want.norm()));
    // Conjugate gradients preconditioned by the factor of a perturbed matrix
    // (diagonal × 1.3) reach the solution; with one iteration they do not.
    if n > 2 {
        let mut other = values.clone();
        for i in 0..n {
            other[slots[s + i]] = 1.3 * values[slots[s + i]] + 0.2;
        }
        let m = pattern.factor(&other).expect("SPD");
        let (x, its) = preconditioned_solution(&pattern, &values, &m, &b, 0.0, 60);
        let x = x.expect("converges");
        let r = &dense * DVector::from_vec(x) - DVector::from_vec(b.clone());
        assert!(r.norm() <= 2.0 * RELATIVE_RESIDUAL * DVector::from_vec(b.clone()).norm());
        assert!(its > 1, "{its} iterations");
        // A looser forcing term stops earlier, at its own tolerance.
        let (loose, loose_its) = preconditioned_solution(&pattern, &values, &m, &b, 1e-3, 60);
        let r =
            &dense * DVector::from_vec(loose.expect("converges")) - DVector::from_vec(b.clone());
        assert!(r.norm() <= 1e-3 * DVector::from_vec(b.clone()).norm());
        assert!(loose_its <= its, "{loose_its} > {its} iterations");
        assert!(
            preconditioned_solution(&pattern, &values, &m, &b, 0.0, 1)
                .0
                .is_none()
        );
    }
    let x = pattern.factor(&values).expect("SPD").solution(&b);
    let residual = &dense * DVector::from_vec(x) - DVector::from_vec(b.clone());
    assert!(
        residual.norm() < 1e-10 * DVector::from_vec(b).norm(),
        "residual {}",
        residual.norm()
    );
    // The same values with a strongly negative diagonal entry are refused.
    for i in (0..n).step_by(refuse_every) {
        let mut bad = values.clone();
        bad[slots[s + i]] -= 1e6;
        assert!(pattern.factor(&bad).is_none(), "unknown {i}");
    }
    pattern
}

#[test]
fn sparse_cholesky_solves_random_spd_systems() {
    let mut rng = Rng::new(3);
    for n in [1, 2, 7, 40] {
        // One unknown per node, nodes of 2, of 3 and of 5 (split into 3 + 2).
        for size in [1, 2, 3, 5] {
            let node_of: Vec<usize> = (0..n).map(|i| i / size).collect();
            let groups = random_groups(&mut rng, n);
            random_system(&mut rng, n, &node_of, &groups, n);
        }
        // Nodes in scrambled order.
        let node_of: Vec<usize> = (0..n).map(|i| (i * 7) % 5).collect();
        let groups = random_groups(&mut rng, n);
        random_system(&mut rng, n, &node_of, &groups, n);
    }
}

#[test]
fn sparse_cholesky_solves_a_grid_system_ordered_by_nested_dissection() {
    // A 30 × 20 grid of 2-unknown nodes coupled to their right and upper
    // neighbours, plus a ring joining the first column to the last (deep
    // enough for several levels of dissection, with a cycle).
    let (w, h) = (30, 20);
    let node = |i: usize, j: usize| (i % w) * h + j;
    let n = 2 * w * h;
    let node_of: Vec<usize> = (0..n).map(|k| k / 2).collect();
    let mut rng = Rng::new(5);
    let mut groups = Vec::new();
    for i in 0..w {
        for j in 0..h {
            let a = node(i, j);
            let mut near = vec![node(i + 1, j)];
            if j + 1 < h {
                near.push(node(i, j + 1));
            }
            for b in near {
                groups.push(vec![2 * a, 2 * a + 1, 2 * b, 2 * b + 1]);
            }
        }
    }
    // 600 blocks: split between two threads at the first separator, and
    // the failure of a pivot in either part or in the separator is seen.
    let pattern = random_system(&mut rng, n, &node_of, &groups, 7);
    let (a, b) = pattern.parallel_parts().expect("split in two parts");
    assert!(a > 100 && b > 100, "parts of {a} and {b} blocks");
}

/// `r = (z_0 − 1, 10 (z_1 − z_0²), z_2 − z_1)`: Rosenbrock plus a chain, minimum 0 at (1, 1, 1).
struct Rosenbrock;

impl LeastSquares for Rosenbrock {
    fn num_vars(&self) -> usize {
        3
    }
    fn nodes(&self) -> Vec<usize> {
        vec![0, 1, 2]
    }
    fn energy(&self, z: &[f64]) -> f64 {
        let r = [z[0] - 1.0, 10.0 * (z[1] - z[0] * z[0]), z[2] - z[1]];
        r.iter().map(|r| r * r).sum()
    }
    fn residuals(&self, z: &[f64], out: &mut Residuals) {
        out.clear();
        out.push(z[0] - 1.0, [(0, 1.0)]);
        out.push(10.0 * (z[1] - z[0] * z[0]), [(0, -20.0 * z[0]), (1, 10.0)]);
        out.push(z[2] - z[1], [(2, 1.0), (1, -1.0)]);
    }
}

#[test]
fn levenberg_marquardt_lowers_the_energy_to_the_minimum() {
    let params = LmParams {
        gradient_tolerance: 1e-10,
        max_iterations: 200,
        stall_window: 0,
        stall_relative: 0.0,
        refinement_iterations: 0,
    };
    let run = levenberg_marquardt(&Rosenbrock, &[-1.2, 1.0, 3.0], &params);
    assert!(run.converged, "{}", run.termination);
    assert_eq!(run.energies.len() as u64, run.iterations + 1);
    assert!(run.energies.windows(2).all(|w| w[1] < w[0]));
    for (z, want) in run.z.iter().zip([1.0, 1.0, 1.0]) {
        assert!((z - want).abs() < 1e-8, "{:?}", run.z);
    }
}

/// `r = (2 z_0 − 2, z_1 − z_0², z_0 + z_1 − 3)`, with `z_0` named twice in
/// the first and last rows when `split` (half of its derivative each).
struct Repeated {
    split: bool,
}

impl LeastSquares for Repeated {
    fn num_vars(&self) -> usize {
        2
    }
    fn nodes(&self) -> Vec<usize> {
        vec![0, 1]
    }
    fn energy(&self, z: &[f64]) -> f64 {
        let r = [2.0 * z[0] - 2.0, z[1] - z[0] * z[0], z[0] + z[1] - 3.0];
        r.iter().map(|r| r * r).sum()
    }
    fn residuals(&self, z: &[f64], out: &mut Residuals) {
        out.clear();
        if self.split {
            out.push(2.0 * z[0] - 2.0, [(0, 1.0), (0, 1.0)]);
        } else {
            out.push(2.0 * z[0] - 2.0, [(0, 2.0)]);
        }
        out.push(z[1] - z[0] * z[0], [(1, 1.0), (0, -2.0 * z[0])]);
        if self.split {
            out.push(z[0] + z[1] - 3.0, [(0, 0.5), (1, 1.0), (0, 0.5)]);
        } else {
            out.push(z[0] + z[1] - 3.0, [(0, 1.0), (1, 1.0)]);
        }
    }
}

#[test]
fn levenberg_marquardt_adds_up_a_variable_named_twice_in_a_row() {
    let params = LmParams {
        gradient_tolerance: 1e-12,
        max_iterations: 100,
        stall_window: 0,
        stall_relative: 0.0,
        refinement_iterations: 0,
    };
    let whole = levenberg_marquardt(&Repeated { split: false }, &[3.0, -1.0], &params);
    let split = levenberg_marquardt(&Repeated { split: true }, &[3.0, -1.0], &params);
    assert!(whole.iterations > 1, "{} iterations", whole.iterations);
    assert_eq!(whole.iterations, split.iterations);
    for (a, b) in whole.energies.iter().zip(&split.energies) {
        assert!((a - b).abs() <= 1e-12 * (1.0 + a.abs()), "{a} against {b}");
    }
    for (a, b) in whole.z.iter().zip(&split.z) {
        assert!((a - b).abs() < 1e-10, "{:?} against {:?}", whole.z, split.z);
    }
}

#[test]
fn levenberg_marquardt_and_nonlinear_cg_reach_the_same_closed_curve() {
    let n = 12;
    let points: Vec<Point3> = (0..n)
        .map(|i| {
            let a = TAU * i as f64 / n as f64;
            Point3::new(1.5 * a.cos(), a.sin() + 0.1 * (3.0 * a).cos(), 0.0)
        })
        .collect();
    let topo = CurveTopology::new(CurveScheme::Cubic, n, true).unwrap();
    let mut values = vec![1.0; n];
    values[4] = 1.4;
    let alpha = alpha_from_values(&topo, 1, &values).unwrap();
    let solve = |method| {
        let params = CurveFinetuneParams {
            method,
            ..Default::default()
        };
        CurveFinetune::new(&topo, &points, &alpha, &params)
            .unwrap()
            .solve()
            .unwrap()
    };
    let (lm, r_lm) = solve(FinetuneMethod::LevenbergMarquardt);
    let (ncg, r_ncg) = solve(FinetuneMethod::NonlinearCg);
    assert!(r_lm.converged && r_ncg.converged);
    assert!(
        r_lm.iterations * 20 < r_ncg.iterations,
        "LM {} vs NCG {} iterations",
        r_lm.iterations,
        r_ncg.iterations
    );
    let rel = (r_lm.final_energy - r_ncg.final_energy).abs() / r_ncg.final_energy;
    assert!(
        rel < 1e-8,
        "energies {} vs {}",
        r_lm.final_energy,
        r_ncg.final_energy
    );
    let d = lm
        .control_points
        .iter()
        .zip(&ncg.control_points)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(d < 1e-5, "control points differ by {d}");
}
