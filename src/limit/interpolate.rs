//! Control points whose limit points interpolate given targets, by
//! progressive iterative approximation.
//!
//! With `L` the limit-position stencil of a control mesh's vertices
//! ([`limit_stencil`]), the iteration `P ← P + (T − L P)` of Chen, Zhang,
//! Luo and Wang (2008, "Progressive interpolation based on Catmull-Clark
//! subdivision surfaces") drives every vertex's limit point to its target
//! `T`; it converges because the eigenvalues of `L` lie in `(0, 1]` (each
//! limit mask is a convex combination centred on its own vertex). The error
//! left after `k` iterations is `(I − L)ᵏ (T − L P₀)`, so a good start needs
//! few iterations.

use crate::error::{Error, Result};
use crate::math::{Point3, Real};
use crate::mesh::PolyMesh;
use crate::subdivision::{RefineOptions, Refiner};

use super::limit_stencil;

/// Moves the `movable` control points of `mesh` for `iterations` steps of
/// progressive iterative approximation towards limit points `targets` (one
/// per vertex) and returns all of them with the largest remaining distance
/// `|T − L P|` over the movable ones. Keeping the others fixed (the
/// iteration on a principal submatrix of `L`, which converges likewise)
/// stops a local change from rippling over the whole mesh.
pub fn interpolate_limit_points(
    mesh: &PolyMesh,
    options: &RefineOptions,
    targets: &[Point3],
    movable: &[bool],
    iterations: usize,
) -> Result<(Vec<Point3>, Real)> {
    if targets.len() != mesh.num_vertices() || movable.len() != mesh.num_vertices() {
        return Err(Error::size_mismatch(format!(
            "{} limit targets and {} movable flags for {} control points",
            targets.len(),
            movable.len(),
            mesh.num_vertices()
        )));
    }
    // One level more lets `limit_stencil` use masks at vertices of n-gons.
    let h = Refiner::new(mesh, options)?.refine_uniform(1)?;
    let l = limit_stencil(&h, 0)?;
    let mut p = mesh.positions.clone();
    let mut lp = vec![Point3::origin(); p.len()];
    let mut residual = 0.0;
    for k in 0..=iterations {
        l.apply_into(&p, &mut lp);
        residual = targets
            .iter()
            .zip(&lp)
            .zip(movable)
            .filter(|(_, m)| **m)
            .map(|((t, y), _)| (t - y).norm())
            .fold(0.0, Real::max);
        if k == iterations {
            break;
        }
        for (((x, t), y), _) in p
            .iter_mut()
            .zip(targets)
            .zip(&lp)
            .zip(movable)
            .filter(|(_, m)| **m)
        {
            x.coords += t.coords - y.coords;
        }
    }
    Ok((p, residual))
}
