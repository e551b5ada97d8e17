//! `M`, `D` and `K` assembled patch by patch from dense element matrices.
//!
//! Same integrals as [`super::mass_matrix`] and [`super::stiffness_matrix`]
//! (Qin, Mandal, Vemuri 1998, eqs. 10–12, in the parameter measure
//! `dA = du dv`), organised as the finite-element method does: every
//! level-`L` patch gets its own small dense matrix `K_e = ∫∫ Σ_q c_q J_qᵀ J_q`
//! over the level-`L` vertices it depends on, the patches are scattered into
//! `K_L`, and `K = Sᵀ K_L S` carries that to the control points.
//!
//! A regular patch is a bicubic B-spline over 16 grid points, and in the
//! parameter measure its matrix over those points depends only on the
//! patch's frame in its base face — one `16 × 16` matrix per frame, exact
//! with a 4 × 4 Gauss-Legendre rule, shared by all the patches with that
//! frame (every level-1 patch of a quad mesh has one of eight). Patches at
//! irregular vertices use the same rule on the patch as a whole through the
//! exact local stencils ([`super::patch_samples`]'s points), which is not
//! exact there but is what the point-cloud fit and the volume recovery
//! sample their forces with. On a regular mesh the result equals
//! [`super::stiffness_matrix`] of [`super::quadrature`] to round-off
//! (`tests/dynamics.rs`).

use std::collections::HashMap;

use rayon::prelude::*;

use super::gauss_legendre;
use super::quadrature::{invert, rows_to_base, square_rule};
use crate::error::{Error, Result};
use crate::limit::{PatchTable, SampleStencil, patch_weights};
use crate::math::Real;
use crate::stencil::{Elements, StencilTable};

use super::MaterialParams;

/// `K` (thin plate under tension) over the control points of `table`'s
/// base mesh, patch by patch with an `order × order` rule (module docs).
pub fn patch_stiffness_matrix(
    table: &PatchTable,
    order: usize,
    params: &MaterialParams,
) -> Result<StencilTable> {
    params.check()?;
    let [k] = assembled(table, order, [stiffness_weights(params)])?;
    Ok(k)
}

/// `[M, D, K]` with a material per base face: the paper's densities and
/// elasticities `μ(u, v)`, `γ(u, v)`, `α_ii(u, v)`, `β_ij(u, v)` (eqs.
/// 10–12) taken constant on each face of the control mesh. `materials` holds
/// one material for the whole surface or one per base face. Every patch's
/// element is `Σ_q c_q E_q` over the six Jacobian terms `q` with its face's
/// weights `c`, so the faces' parameters may differ freely; with one
/// material it equals [`patch_damping_matrix`] and [`patch_stiffness_matrix`].
pub fn patch_matrices(
    table: &PatchTable,
    order: usize,
    materials: &[MaterialParams],
) -> Result<[StencilTable; 3]> {
    let faces = table.num_base_faces();
    if materials.len() != 1 && materials.len() != faces {
        return Err(Error::size_mismatch(format!(
            "{} materials for a control mesh of {faces} faces: give one, or one per face",
            materials.len()
        )));
    }
    let uniform = materials.len() == 1;
    for (f, m) in materials.iter().enumerate() {
        m.check().map_err(|e| match e {
            Error::Input(what) if !uniform => {
                Error::with_kind(what.kind(), format!("face {f}'s {what}"))
            }
            e => e,
        })?;
    }
    let unit: [[Real; 6]; 6] = std::array::from_fn(|q| std::array::from_fn(|r| Real::from(q == r)));
    let terms = elements(table, order, unit)?;
    let s = table.to_level();
    let weights: [fn(&MaterialParams) -> [Real; 6]; 3] = [
        |m| damping_weights(m.mu),
        |m| damping_weights(m.gamma),
        stiffness_weights,
    ];
    let mut out = Vec::with_capacity(3);
    for weight in weights {
        let mut elements = Elements::new();
        let mut sum = Vec::new();
        for f in 0..terms.len() {
            let c = weight(&materials[if uniform { 0 } else { table.base_face(f) }]);
            let (cols, e) = terms.get(f);
            sum.clear();
            sum.resize(e[0].len(), 0.0);
            for (c, e) in c.iter().zip(e) {
                if *c != 0.0 {
                    for (x, y) in sum.iter_mut().zip(e) {
                        *x += c * y;
                    }
                }
            }
            elements.push(cols, &sum)?;
        }
        out.push(StencilTable::from_elements(s.num_rows(), &elements)?.pulled_back(s)?);
    }
    Ok(out
        .try_into()
        .unwrap_or_else(|_| unreachable!("three matrices")))
}

/// `K` of [`patch_stiffness_matrix`] and `D` of [`patch_damping_matrix`]
/// together, in one pass over the patches (their stencils are shared).
pub fn patch_stiffness_and_damping(
    table: &PatchTable,
    order: usize,
    params: &MaterialParams,
    gamma: Real,
) -> Result<[StencilTable; 2]> {
    let elements = stiffness_and_damping_elements(table, order, params, gamma)?;
    scattered(table, &elements)
}

/// The elements of [`patch_stiffness_and_damping`] before they are carried
/// to the control points: for every patch, its level-`L` columns and the
/// row-major `K_e` and `D_e` over them ([`PatchElements::get`]).
pub fn stiffness_and_damping_elements(
    table: &PatchTable,
    order: usize,
    params: &MaterialParams,
    gamma: Real,
) -> Result<PatchElements<2>> {
    params.check()?;
    damping_params(gamma).check()?;
    elements(
        table,
        order,
        [stiffness_weights(params), damping_weights(gamma)],
    )
}

/// Every patch's element: its level-`L` columns (distinct, in no
/// particular order) and one row-major matrix over them per weight set.
/// Patches with equal matrices share one copy: the interior regular patches
/// of one frame (their columns are their 16 grid vertices in grid order),
/// and the irregular patches of one local structure and frame (their
/// columns in quadtree order).
#[derive(Clone, Debug)]
pub struct PatchElements<const N: usize> {
    col_offsets: Vec<usize>,
    cols: Vec<u32>,
    /// Each patch's entry in `matrices`.
    which: Vec<u32>,
    matrices: Vec<Matrices<N>>,
}

impl<const N: usize> PatchElements<N> {
    /// Patch `f`'s columns and matrices.
    pub fn get(&self, f: usize) -> (&[u32], [&[Real]; N]) {
        let m = &self.matrices[self.which[f] as usize];
        (
            &self.cols[self.col_offsets[f]..self.col_offsets[f + 1]],
            std::array::from_fn(|i| &m[i][..]),
        )
    }

    /// Number of patches.
    pub fn len(&self) -> usize {
        self.which.len()
    }

    /// True when there are no patches.
    pub fn is_empty(&self) -> bool {
        self.which.is_empty()
    }
}

/// The weights of `[J, J_u, J_v, J_uu, J_uv, J_vv]` in `K` (eq. 12).
fn stiffness_weights(params: &MaterialParams) -> [Real; 6] {
    [
        0.0,
        params.alpha11,
        params.alpha22,
        params.beta11,
        params.beta12,
        params.beta22,
    ]
}

/// The weights of `[J, …]` in `D = ∫∫ γ JᵀJ`.
fn damping_weights(gamma: Real) -> [Real; 6] {
    [gamma, 0.0, 0.0, 0.0, 0.0, 0.0]
}

fn damping_params(gamma: Real) -> MaterialParams {
    MaterialParams {
        gamma,
        ..Default::default()
    }
}

/// `D = ∫∫ γ JᵀJ du dv` (or `M` with `γ = μ`) over the control points,
/// patch by patch (module docs).
pub fn patch_damping_matrix(table: &PatchTable, order: usize, gamma: Real) -> Result<StencilTable> {
    damping_params(gamma).check()?;
    let [d] = assembled(table, order, [damping_weights(gamma)])?;
    Ok(d)
}

/// The area of the parameter domain (`∫∫ du dv` over the base faces, quad
/// sub-face tiles for n-gons): the weights of any quadrature sum to it.
pub fn parameter_area(table: &PatchTable) -> Real {
    (0..table.num_patches())
        .map(|f| inverse(table.patch_frame(f).1).1.recip())
        .sum()
}

/// `Sᵀ (Σ_e K_e) S` for each set of weights `c` of `[J, J_u, J_v, J_uu,
/// J_uv, J_vv]`.
fn assembled<const N: usize>(
    table: &PatchTable,
    order: usize,
    c: [[Real; 6]; N],
) -> Result<[StencilTable; N]> {
    scattered(table, &elements(table, order, c)?)
}

/// Every patch's element for each set of weights `c`. Irregular patches
/// with the same local structure and frame share one computation: their
/// keys are found first, one patch of each distinct key is integrated, and
/// every such patch then refers to its key's matrices over its own columns.
/// Regular patches share their frame's grid matrix where their grid rows
/// select 16 distinct vertices (the interior); the others carry it.
fn elements<const N: usize>(
    table: &PatchTable,
    order: usize,
    c: [[Real; 6]; N],
) -> Result<PatchElements<N>> {
    if order == 0 || order > 16 {
        return Err(Error::input(format!(
            "quadrature order {order} must be between 1 and 16"
        )));
    }
    let gl = gauss_legendre(order);
    let shapes: Vec<Option<(&[u32], ShapeKey)>> = (0..table.num_patches())
        .into_par_iter()
        .map(|f| {
            table
                .irregular_shape(f)
                .map(|(local, key)| (local, (key, frame_bits(frame(table, f).0))))
        })
        .collect();
    let mut first: HashMap<&ShapeKey, usize> = HashMap::new();
    for (f, shape) in shapes.iter().enumerate() {
        if let Some((_, key)) = shape {
            first.entry(key).or_insert(f);
        }
    }
    let first: Vec<(&ShapeKey, usize)> = first.into_iter().collect();
    // A structure's matrices over its quadtree columns, or `None` when its
    // stencils leave those columns (then every such patch is integrated on
    // its own).
    let shared: Vec<Option<Matrices<N>>> = first
        .par_iter()
        .map(|&(_, f)| {
            let local = shapes[f].map(|(local, _)| local);
            let (_, matrices, on_local) = irregular_element(table, f, &gl, c, local);
            on_local.then_some(matrices)
        })
        .collect();
    let mut matrices: Vec<Matrices<N>> = Vec::new();
    let mut entry: HashMap<&ShapeKey, u32> = HashMap::new();
    for ((key, _), m) in first.iter().zip(shared) {
        if let Some(m) = m {
            entry.insert(key, matrices.len() as u32);
            matrices.push(m);
        }
    }
    // The regular frames' grid matrices, numbered in the order met.
    let mut frames: Vec<[[Real; 2]; 2]> = Vec::new();
    let frame_of: Vec<Option<u32>> = (0..table.num_patches())
        .map(|f| {
            table.grid_rows(f).map(|_| {
                let axes = table.patch_frame(f).1;
                let k = frames.iter().position(|a| *a == axes).unwrap_or_else(|| {
                    frames.push(axes);
                    frames.len() - 1
                });
                (matrices.len() + k) as u32
            })
        })
        .collect();
    matrices.extend(frames.iter().map(|&axes| grid_matrices(axes, &gl, c)));
    // Each patch: its columns, and either a shared entry or its own matrices.
    let own: Vec<(Vec<u32>, Entry<N>)> = (0..table.num_patches())
        .into_par_iter()
        .map(|f| match (table.grid_rows(f), &shapes[f]) {
            (Some(grid), _) => {
                let shared = frame_of[f].expect("regular patches have a frame");
                match selected(&grid) {
                    Some(cols) => (cols, Entry::Shared(shared)),
                    None => {
                        let (cols, g) = grid_matrix(&grid);
                        let e = &matrices[shared as usize];
                        let m = cols.len();
                        (
                            cols,
                            Entry::Own(std::array::from_fn(|i| carried(&e[i], &g, m))),
                        )
                    }
                }
            }
            (None, Some((local, key))) if entry.contains_key(key) => {
                (local.to_vec(), Entry::Shared(entry[key]))
            }
            _ => {
                let (cols, matrices, _) = irregular_element(table, f, &gl, c, None);
                (cols, Entry::Own(matrices))
            }
        })
        .collect();
    let mut out = PatchElements {
        col_offsets: vec![0],
        cols: Vec::new(),
        which: Vec::with_capacity(own.len()),
        matrices,
    };
    for (cols, m) in own {
        out.cols.extend(cols);
        out.col_offsets.push(out.cols.len());
        out.which.push(match m {
            Entry::Shared(k) => k,
            Entry::Own(m) => {
                out.matrices.push(m);
                (out.matrices.len() - 1) as u32
            }
        });
    }
    Ok(out)
}

/// `Sᵀ (Σ_e K_e) S` of each weight set's elements.
fn scattered<const N: usize>(
    table: &PatchTable,
    per_patch: &PatchElements<N>,
) -> Result<[StencilTable; N]> {
    let s = table.to_level();
    let mut out = Vec::with_capacity(N);
    for i in 0..N {
        let mut elements = Elements::new();
        for f in 0..per_patch.len() {
            let (cols, matrices) = per_patch.get(f);
            elements.push(cols, matrices[i])?;
        }
        out.push(StencilTable::from_elements(s.num_rows(), &elements)?.pulled_back(s)?);
    }
    Ok(out
        .try_into()
        .unwrap_or_else(|_| unreachable!("one matrix per weight set")))
}

/// A patch's matrices: a shared entry of [`PatchElements`] or its own.
enum Entry<const N: usize> {
    Shared(u32),
    Own(Matrices<N>),
}

/// One row-major matrix per weight set.
type Matrices<const N: usize> = [Vec<Real>; N];

/// An irregular patch's local structure (its number in the table's
/// quadtree cache) and the bits of its frame.
type ShapeKey = (usize, [u64; 4]);

/// Patch `f`'s inverse frame (base `(u, v)` to its `(s, t)`) and the
/// frame's |determinant|.
fn frame(table: &PatchTable, f: usize) -> ([[Real; 2]; 2], Real) {
    inverse(table.patch_frame(f).1)
}

fn frame_bits(inv: [[Real; 2]; 2]) -> [u64; 4] {
    [inv[0][0], inv[0][1], inv[1][0], inv[1][1]].map(Real::to_bits)
}

/// Inverse of a 2 × 2 matrix and its |determinant|.
fn inverse(m: [[Real; 2]; 2]) -> ([[Real; 2]; 2], Real) {
    (invert(m), (m[0][0] * m[1][1] - m[0][1] * m[1][0]).abs())
}

/// Adds `w · Σ_q c_q j_q j_qᵀ` to each dense `m × m` matrix `out[i]` with
/// its own `c[i]`, the rows `j_q` given by `row(q)`.
fn add_outer<'a, const N: usize>(
    out: &mut [Vec<Real>; N],
    m: usize,
    c: [[Real; 6]; N],
    w: Real,
    row: impl Fn(usize) -> &'a [Real],
) {
    for (out, c) in out.iter_mut().zip(c) {
        add_outer_one(out, m, c, w, &row);
    }
}

fn add_outer_one<'a>(
    out: &mut [Real],
    m: usize,
    c: [Real; 6],
    w: Real,
    row: impl Fn(usize) -> &'a [Real],
) {
    for (q, &cq) in c.iter().enumerate() {
        if cq == 0.0 {
            continue;
        }
        let j = row(q);
        for a in 0..m {
            let ja = cq * w * j[a];
            if ja != 0.0 {
                for (o, &jb) in out[a * m..(a + 1) * m].iter_mut().zip(j) {
                    *o += ja * jb;
                }
            }
        }
    }
}

/// The `16 × 16` matrices over the 16 grid points of a regular patch with
/// frame `axes` (exact with a 4 × 4 or finer Gauss-Legendre rule).
fn grid_matrices<const N: usize>(
    axes: [[Real; 2]; 2],
    gl: &[(Real, Real)],
    c: [[Real; 6]; N],
) -> Matrices<N> {
    let (inv, det) = inverse(axes);
    let mut e = [(); N].map(|_| vec![0.0; 256]);
    for &(a, wa) in gl {
        for &(b, wb) in gl {
            let mut rows = patch_weights(a, b);
            rows_to_base(&mut rows, inv);
            add_outer(&mut e, 16, c, wa * wb * det, |q| &rows[q]);
        }
    }
    e
}

/// The 16 grid vertices in grid order when every grid row is one distinct
/// vertex with weight 1 (an interior regular patch): its element is then
/// the grid matrix itself over them.
fn selected(grid: &[(&[u32], &[Real]); 16]) -> Option<Vec<u32>> {
    let cols: Vec<u32> = grid
        .iter()
        .map(|(c, w)| (c.len() == 1 && w[0] == 1.0).then(|| c[0]))
        .collect::<Option<_>>()?;
    let mut sorted = cols.clone();
    sorted.sort_unstable();
    sorted.windows(2).all(|w| w[0] != w[1]).then_some(cols)
}

/// The sorted columns of grid rows `grid` and the rows as a dense `16 × m`
/// matrix `G` over them (a patch's element is then `Gᵀ E G`).
fn grid_matrix(grid: &[(&[u32], &[Real]); 16]) -> (Vec<u32>, Vec<Real>) {
    let mut cols: Vec<u32> = grid.iter().flat_map(|(c, _)| c.iter().copied()).collect();
    cols.sort_unstable();
    cols.dedup();
    let m = cols.len();
    let mut g = vec![0.0; 16 * m];
    for (k, (gc, gw)) in grid.iter().enumerate() {
        for (&col, &x) in gc.iter().zip(gw.iter()) {
            g[k * m + cols.binary_search(&col).unwrap_or(0)] += x;
        }
    }
    (cols, g)
}

/// The element of irregular patch `f`: the exact stencils at the Gauss
/// points of the whole patch, over its quadtree columns `local` when every
/// stencil lies on them (the third value says so; patches with the same
/// local structure and frame then have the same matrices up to the column
/// order), else over the sorted union of the stencils' columns.
fn irregular_element<const N: usize>(
    table: &PatchTable,
    f: usize,
    gl: &[(Real, Real)],
    c: [[Real; 6]; N],
    local: Option<&[u32]>,
) -> (Vec<u32>, Matrices<N>, bool) {
    let (inv, det) = frame(table, f);
    let (sts, ws): (Vec<[Real; 2]>, Vec<Real>) = square_rule(gl).into_iter().unzip();
    let samples: Vec<(SampleStencil, Real)> = table
        .stencils(f, &sts)
        .into_iter()
        .zip(ws)
        .map(|(mut s, w)| {
            rows_to_base(&mut s.weights, inv);
            (s, w * det)
        })
        .collect();
    // The quadtree's columns when every stencil lies on them (exact
    // evaluations in the innermost cells do too), else their sorted union.
    let local = local.filter(|local| {
        samples
            .iter()
            .all(|(s, _)| s.cols.iter().all(|c| local.contains(c)))
    });
    let cols: Vec<u32> = match local {
        Some(local) => local.to_vec(),
        None => {
            let mut cols: Vec<u32> = samples.iter().flat_map(|(s, _)| s.cols.clone()).collect();
            cols.sort_unstable();
            cols.dedup();
            cols
        }
    };
    let mut position: Vec<(u32, usize)> = cols.iter().copied().zip(0..).collect();
    position.sort_unstable();
    let at = |col: u32| {
        position
            .binary_search_by_key(&col, |p| p.0)
            .map_or(0, |i| position[i].1)
    };
    let m = cols.len();
    let mut matrix = [(); N].map(|_| vec![0.0; m * m]);
    let mut dense = [(); 6].map(|_| vec![0.0; m]);
    for (s, w) in &samples {
        for (q, d) in dense.iter_mut().enumerate() {
            d.iter_mut().for_each(|x| *x = 0.0);
            for (&col, &x) in s.cols.iter().zip(&s.weights[q]) {
                d[at(col)] += x;
            }
        }
        add_outer(&mut matrix, m, c, *w, |q| &dense[q]);
    }
    (cols, matrix, local.is_some())
}

/// `Gᵀ E G` for the `16 × 16` grid matrix `E` and the `16 × m` grid rows `G`.
fn carried(e: &[Real], g: &[Real], m: usize) -> Vec<Real> {
    // E G (16 × m), then Gᵀ (E G).
    let mut eg = vec![0.0; 16 * m];
    for a in 0..16 {
        for k in 0..16 {
            let x = e[a * 16 + k];
            if x != 0.0 {
                for (o, &y) in eg[a * m..(a + 1) * m]
                    .iter_mut()
                    .zip(&g[k * m..(k + 1) * m])
                {
                    *o += x * y;
                }
            }
        }
    }
    let mut matrix = vec![0.0; m * m];
    for k in 0..16 {
        for i in 0..m {
            let x = g[k * m + i];
            if x != 0.0 {
                for (o, &y) in matrix[i * m..(i + 1) * m]
                    .iter_mut()
                    .zip(&eg[k * m..(k + 1) * m])
                {
                    *o += x * y;
                }
            }
        }
    }
    matrix
}
