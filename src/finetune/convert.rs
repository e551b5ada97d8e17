//! Conversion of a Doo-Sabin control mesh to a non-uniform Catmull-Clark
//! control mesh (the fine-tuning paper's §4.3 and its Appendix (b), which the
//! excerpt lacks; reconstructed here).
//!
//! **Derivation.** A uniform quadratic B-spline with control points `Pᵢ`
//! is, after degree elevation, a cubic B-spline with every knot doubled
//! (knot intervals `1, 0, 1, 0, …`). Its segment around `Pᵢ` is the
//! quadratic Bézier `(Pᵢ₋₁ + Pᵢ)/2, Pᵢ, (Pᵢ + Pᵢ₊₁)/2`; elevated to cubic, its
//! inner Bézier points `(Pᵢ₋₁ + 5Pᵢ)/6` and `(5Pᵢ + Pᵢ₊₁)/6` are the cubic
//! B-spline control points (at a double knot the B-spline polygon passes
//! through the Bézier junction). So every quadratic control point yields two
//! cubic ones, joined by a leg of interval 1; consecutive pairs are joined by
//! a leg of interval 0. The tensor product gives, for every face corner
//! `(f, v)` of a regular quad mesh, the cubic control point
//! `Q(f, v) = (25 v + 5 (v₋ + v₊) + v_opp) / 36` (`v₋, v₊` the neighbours of
//! `v` in `f`, `v_opp` the opposite vertex).
//!
//! The converted mesh therefore has one vertex per face corner and exactly
//! the topology of one Doo-Sabin step ([`doo_sabin_faces`]): edges of F-faces
//! (inside one original face) get interval `ε` (0 in theory; the paper uses
//! 0.05 "to clarify the effect"), edges of V-faces (around one original
//! vertex) get interval 1, and every converted vertex has valence 4. For an
//! `n`-gon we use the Fourier form of the quad mask that is exact for `n = 4`,
//! `αₖ = (1 + (4/3) cos θₖ + (4/9) cos 2θₖ) / n`, `θₖ = 2πk/n` (it gives
//! `25/36, 5/36, 1/36, 5/36` for a quad and `25/27, 1/27, 1/27` for a
//! triangle; rows sum to 1). On regular quad meshes the conversion is exact
//! (the same limit surface); elsewhere it is an approximation, as the paper says.

use crate::error::{Error, Result};
use crate::math::Real;
use crate::mesh::PolyMesh;
use crate::stencil::StencilTable;
use crate::subdivision::doo_sabin_faces;
use crate::topology::Level;

/// What an edge of the converted mesh came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConvertedEdge {
    /// Inside one original face (an F-face edge): knot interval `ε`.
    Face,
    /// Around one original vertex (a V-face edge): knot interval 1.
    Vertex,
}

/// A Doo-Sabin mesh converted to a non-uniform Catmull-Clark mesh.
#[derive(Clone, Debug)]
pub struct Conversion {
    /// The converted control mesh (vertex `c` is original face corner `c`).
    pub mesh: PolyMesh,
    /// Its connectivity.
    pub level: Level,
    /// One knot interval per edge of `level`.
    pub intervals: Vec<Real>,
    /// Kind of each edge of `level`.
    pub edge_kind: Vec<ConvertedEdge>,
    /// `converted = stencil · original`.
    pub stencil: StencilTable,
    /// Connectivity of the original mesh.
    pub original: Level,
}

/// Conversion weight `αₖ` of the vertex `k` steps along an `n`-gon from the
/// corner: `(1 + (4/3) cos θ + (4/9) cos 2θ) / n`, `θ = 2πk/n` (see the module docs).
pub fn conversion_weight(n: usize, k: usize) -> Real {
    let t = std::f64::consts::TAU * k as Real / n as Real;
    (1.0 + 4.0 / 3.0 * t.cos() + 4.0 / 9.0 * (2.0 * t).cos()) / n as Real
}

/// Converts the Doo-Sabin control mesh `mesh`; F-face edges get interval
/// `epsilon` (≥ 0; the paper uses 0.05), V-face edges 1.
///
/// ```
/// let cube = subdyn::examples::cube();
/// let c = subdyn::finetune::doo_sabin_to_non_uniform(&cube, 0.05).unwrap();
/// assert_eq!(c.mesh.num_vertices(), 24); // one per face corner
/// assert!((0..c.level.num_vertices).all(|v| c.level.valence(v) == 4));
/// ```
pub fn doo_sabin_to_non_uniform(mesh: &PolyMesh, epsilon: Real) -> Result<Conversion> {
    if !epsilon.is_finite() || !(0.0..=1.0).contains(&epsilon) {
        return Err(Error::input(format!(
            "the small knot interval must be in [0, 1], got {epsilon}"
        )));
    }
    let original = Level::from_mesh(mesh)?;
    let nc = original.face_verts.len();
    let mut corner_face = vec![0usize; nc];
    for f in 0..original.num_faces() {
        corner_face[original.face_offsets[f] as usize..original.face_offsets[f + 1] as usize]
            .fill(f);
    }
    let stencil = StencilTable::from_row_fn(nc, original.num_vertices, |c, b| {
        let f = corner_face[c];
        let fv = original.face_vertices(f);
        let n = fv.len();
        let i = c - original.face_offsets[f] as usize;
        for (j, &v) in fv.iter().enumerate() {
            b.add(v, conversion_weight(n, (j + n - i) % n));
        }
    });
    let (faces, nf, _) = doo_sabin_faces(&original);
    let positions = stencil.apply(&mesh.positions)?;
    let converted = PolyMesh::from_faces(positions, &faces)?;
    let level = Level::from_mesh(&converted)?;
    // An edge joining two corners of the same original face is an F-face edge.
    let edge_kind: Vec<ConvertedEdge> = level
        .edge_verts
        .iter()
        .map(|&[a, b]| {
            if corner_face[a as usize] == corner_face[b as usize] {
                ConvertedEdge::Face
            } else {
                ConvertedEdge::Vertex
            }
        })
        .collect();
    debug_assert!(nf == original.num_faces());
    let intervals = edge_kind
        .iter()
        .map(|k| match k {
            ConvertedEdge::Face => epsilon,
            ConvertedEdge::Vertex => 1.0,
        })
        .collect();
    Ok(Conversion {
        mesh: converted,
        level,
        intervals,
        edge_kind,
        stencil,
        original,
    })
}
