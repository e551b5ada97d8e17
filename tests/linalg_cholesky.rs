//! `linalg`'s sparse Cholesky against an independent one: a weighted grid
//! Laplacian plus a varying diagonal (symmetric positive definite, a few
//! hundred unknowns) solved by the scalar factor (`SparseCholesky`), by
//! the 3 × 3-block factor on `A ⊗ S` (`CholeskyPattern`, serial and split
//! between two threads) and by faer's sparse `Llt` (its own ordering):
//! the solutions agree to `1e-10` relative.

use faer::linalg::solvers::Solve;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Side};

use subdyn::linalg::{CholeskyPattern, SparseCholesky};
use subdyn::math::{Point3, Real};
use subdyn::stencil::StencilTable;

/// A small SPD matrix: `S` of the block system `A ⊗ S`.
const S: [[Real; 3]; 3] = [[4.0, 1.0, 0.5], [1.0, 3.0, 0.2], [0.5, 0.2, 2.0]];

/// `A = Σ_e w_e (e_a − e_b)(e_a − e_b)ᵀ + diag(c)` on a `w × h` grid with
/// its right and upper neighbours and every seventh node's diagonal
/// neighbour, weights `w_e ∈ [0.5, 1.5]`, `c_i ∈ [0.1, 0.6]`: its edges
/// `(a, b, w_e)` and its diagonal.
fn grid_system(w: usize, h: usize) -> (Vec<(usize, usize, Real)>, Vec<Real>) {
    let node = |i: usize, j: usize| i * h + j;
    let mut edges = Vec::new();
    for i in 0..w {
        for j in 0..h {
            let a = node(i, j);
            let mut near = Vec::new();
            if i + 1 < w {
                near.push(node(i + 1, j));
            }
            if j + 1 < h {
                near.push(node(i, j + 1));
            }
            if a % 7 == 0 && i + 1 < w && j + 1 < h {
                near.push(node(i + 1, j + 1));
            }
            for b in near {
                let weight = 1.0 + 0.5 * ((a * 31 + b * 17) as Real).sin();
                edges.push((a, b, weight));
            }
        }
    }
    let mut diagonal: Vec<Real> = (0..w * h)
        .map(|i| 0.35 + 0.25 * (1.7 * i as Real).cos())
        .collect();
    for &(a, b, weight) in &edges {
        diagonal[a] += weight;
        diagonal[b] += weight;
    }
    (edges, diagonal)
}

/// The entries `(row, column, value)` of `A`, both triangles.
fn entries(edges: &[(usize, usize, Real)], diagonal: &[Real]) -> Vec<(usize, usize, Real)> {
    let mut out: Vec<(usize, usize, Real)> = diagonal
        .iter()
        .enumerate()
        .map(|(i, &d)| (i, i, d))
        .collect();
    for &(a, b, weight) in edges {
        out.push((a, b, -weight));
        out.push((b, a, -weight));
    }
    out
}

/// faer's solution of `A X = B` (`B` with `columns` columns, column-major).
fn faer_solution(n: usize, a: &[(usize, usize, Real)], b: &[Real], columns: usize) -> Vec<Real> {
    let triplets: Vec<Triplet<usize, usize, Real>> =
        a.iter().map(|&(r, c, v)| Triplet::new(r, c, v)).collect();
    let matrix = SparseColMat::<usize, Real>::try_new_from_triplets(n, n, &triplets)
        .expect("valid triplets");
    let llt = matrix.as_ref().sp_cholesky(Side::Lower).expect("SPD");
    let rhs = Mat::from_fn(n, columns, |i, j| b[j * n + i]);
    let x = llt.solve(&rhs);
    (0..columns)
        .flat_map(|j| (0..n).map(move |i| (i, j)))
        .map(|(i, j)| x[(i, j)])
        .collect()
}

/// `max |x − y| / max |y|`.
fn relative_gap(x: &[Real], y: &[Real]) -> Real {
    assert_eq!(x.len(), y.len());
    let gap = x
        .iter()
        .zip(y)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, Real::max);
    gap / y.iter().map(|v| v.abs()).fold(0.0, Real::max)
}

fn right_hand_side(n: usize) -> Vec<Real> {
    (0..n).map(|i| (0.37 * i as Real).sin() + 0.1).collect()
}

#[test]
fn scalar_and_block_factors_agree_with_faer_llt() {
    for (w, h) in [(20, 15), (25, 25)] {
        let n = w * h;
        let (edges, diagonal) = grid_system(w, h);
        let a = entries(&edges, &diagonal);

        // Scalar factor, three right-hand sides (x, y, z) at once.
        let mut rows = vec![Vec::new(); n];
        for &(r, c, v) in &a {
            rows[r].push((c as u32, v));
        }
        let table = StencilTable::from_rows(n, &rows);
        let b: Vec<Real> = right_hand_side(3 * n);
        let points: Vec<Point3> = (0..n)
            .map(|i| Point3::new(b[i], b[n + i], b[2 * n + i]))
            .collect();
        let ours = SparseCholesky::new(&table)
            .expect("SPD")
            .solve(&points)
            .expect("n right-hand sides");
        let ours: Vec<Real> = (0..3)
            .flat_map(|k| ours.iter().map(move |p| p[k]))
            .collect();
        let reference = faer_solution(n, &a, &b, 3);
        let gap = relative_gap(&ours, &reference);
        assert!(gap < 1e-10, "{w} × {h} scalar: {gap:e}");

        // Block factor on A ⊗ S: node a holds unknowns 3a, 3a + 1, 3a + 2.
        let m = 3 * n;
        let node_of: Vec<usize> = (0..m).map(|i| i / 3).collect();
        let unknowns = |a: usize| (0..3).map(move |p| 3 * a + p);
        let mut groups: Vec<Vec<usize>> = (0..n).map(|a| unknowns(a).collect()).collect();
        groups.extend(
            edges
                .iter()
                .map(|&(a, b, _)| unknowns(a).chain(unknowns(b)).collect()),
        );
        let refs: Vec<&[usize]> = groups.iter().map(|g| g.as_slice()).collect();
        let (pattern, slots) = CholeskyPattern::new(m, &node_of, &refs);
        let mut values = vec![0.0; pattern.num_values()];
        let mut s = 0;
        // The first n groups carry A_aa S (their pairs p ≤ q); the edge
        // groups only their pairs across the two nodes, −w_e S.
        let coefficients = diagonal.iter().map(|&d| (d, true));
        let coefficients = coefficients.chain(edges.iter().map(|&(_, _, weight)| (-weight, false)));
        for (group, (coefficient, same_node)) in groups.iter().zip(coefficients) {
            for p in 0..group.len() {
                for q in p..group.len() {
                    let (i, j) = (group[p], group[q]);
                    if (i / 3 == j / 3) == same_node {
                        values[slots[s]] += coefficient * S[i % 3][j % 3];
                    }
                    s += 1;
                }
            }
        }
        assert_eq!(s + m, slots.len());
        let b = right_hand_side(m);
        let ours = pattern.factor(&values).expect("SPD").solution(&b);
        let mut kron = Vec::new();
        for &(r, c, v) in &a {
            for (p, row) in S.iter().enumerate() {
                for (q, &sv) in row.iter().enumerate() {
                    kron.push((3 * r + p, 3 * c + q, v * sv));
                }
            }
        }
        let reference = faer_solution(m, &kron, &b, 1);
        let gap = relative_gap(&ours, &reference);
        assert!(gap < 1e-10, "{w} × {h} blocks: {gap:e}");
        // The larger system is split between two threads.
        assert_eq!(pattern.parallel_parts().is_some(), n >= 512, "{w} × {h}");
    }
}
