//! Doo-Sabin subdivision of polygon meshes of any topology, as stencil tables.
//!
//! Doo and Sabin 1978. Every corner `(f, vᵢ)` of an `n`-gon `f` becomes a new
//! vertex `Σⱼ αᵢⱼ vⱼ` with `αᵢᵢ = (n + 5) / (4n)` and
//! `αᵢⱼ = (3 + 2 cos(2π (i − j) / n)) / (4n)` (`i ≠ j`); for a quad these are
//! the tensor-product Chaikin weights `9/16, 3/16, 1/16`, so on a regular grid
//! the limit is the uniform biquadratic B-spline surface. Child vertex `c` is
//! the parent corner `c` (an index into the parent's `face_verts`).
//!
//! Child faces, in this order: one *F-face* per parent face (its corners, same
//! order), one *E-face* per interior edge (the four corners at its ends),
//! one *V-face* per interior vertex (its corners, counter-clockwise).
//!
//! **Boundary rule** (documented choice): boundary faces are refined by the same
//! corner masks, and boundary edges and boundary vertices get no E- or
//! V-face. The surface is then the biquadratic B-spline "without end
//! conditions": it stays inside the control mesh and does not reach the
//! boundary polygon (each level trims half a face at the rim).

use crate::error::Result;
use crate::math::Real;
use crate::mesh::PolyMesh;
use crate::stencil::StencilTable;
use crate::topology::{Level, NONE};

/// One Doo-Sabin step: the stencil `P_child = S P_parent` and the child faces.
#[derive(Clone, Debug)]
pub struct DooSabinStep {
    /// Rows: one per parent face corner.
    pub stencil: StencilTable,
    /// The child faces as a mesh without positions (`positions` empty).
    pub faces: PolyMesh,
    /// Number of F-faces (the first faces of `faces`), then E-faces, then V-faces.
    pub num_f_faces: usize,
    /// Number of E-faces.
    pub num_e_faces: usize,
}

/// Doo-Sabin weight `α_k` of the vertex `k` steps along an `n`-gon from the
/// corner (Doo and Sabin 1978): `(n + 5) / (4n)` for `k = 0`, else
/// `(3 + 2 cos(2πk / n)) / (4n)`.
pub fn doo_sabin_weight(n: usize, k: usize) -> Real {
    let nf = n as Real;
    if k.is_multiple_of(n) {
        (nf + 5.0) / (4.0 * nf)
    } else {
        (3.0 + 2.0 * (std::f64::consts::TAU * k as Real / nf).cos()) / (4.0 * nf)
    }
}

/// The corner index (into `face_verts`) of vertex `v` in face `f`.
fn corner(level: &Level, f: u32, v: u32) -> u32 {
    let f = f as usize;
    level.face_offsets[f] + level.corner_in_face(f, v).unwrap_or(0) as u32
}

/// The child faces of one Doo-Sabin step (F-, E-, then V-faces); child vertex
/// `c` is parent corner `c`. Returns the faces and the F- and E-face counts.
pub fn doo_sabin_faces(level: &Level) -> (Vec<Vec<u32>>, usize, usize) {
    let mut faces: Vec<Vec<u32>> = (0..level.num_faces())
        .map(|f| (level.face_offsets[f]..level.face_offsets[f + 1]).collect())
        .collect();
    let nf = faces.len();
    for e in 0..level.num_edges() {
        let [f0, f1] = level.edge_faces[e];
        if f1 == NONE {
            continue;
        }
        // The edge runs a -> b in f0 and b -> a in f1.
        let [a, b] = level.edge_verts[e];
        faces.push(vec![
            corner(level, f0, b),
            corner(level, f0, a),
            corner(level, f1, a),
            corner(level, f1, b),
        ]);
    }
    let ne = faces.len() - nf;
    for v in 0..level.num_vertices {
        if level.vertex_faces(v).is_empty() || level.is_boundary_vertex(v) {
            continue;
        }
        let ring = level.vertex_ring(v);
        faces.push(
            ring.faces
                .iter()
                .map(|&f| corner(level, f, v as u32))
                .collect(),
        );
    }
    (faces, nf, ne)
}

/// One Doo-Sabin step of `level`: stencil rows (sum to 1) and child faces.
pub fn doo_sabin_step(level: &Level) -> DooSabinStep {
    let nc = level.face_verts.len();
    let mut corner_face = vec![0usize; nc];
    for f in 0..level.num_faces() {
        corner_face[level.face_offsets[f] as usize..level.face_offsets[f + 1] as usize].fill(f);
    }
    let stencil = StencilTable::from_row_fn(nc, level.num_vertices, |c, b| {
        let f = corner_face[c];
        let fv = level.face_vertices(f);
        let n = fv.len();
        let i = c - level.face_offsets[f] as usize;
        for (j, &v) in fv.iter().enumerate() {
            b.add(v, doo_sabin_weight(n, (j + n - i) % n));
        }
    });
    let (faces, num_f_faces, num_e_faces) = doo_sabin_faces(level);
    let mut mesh = PolyMesh::default();
    mesh.face_offsets.push(0);
    for f in &faces {
        mesh.face_vertices.extend_from_slice(f);
        mesh.face_offsets.push(mesh.face_vertices.len() as u32);
    }
    DooSabinStep {
        stencil,
        faces: mesh,
        num_f_faces,
        num_e_faces,
    }
}

/// Levels `0..=n` of Doo-Sabin refinement with their stencils.
#[derive(Clone, Debug)]
pub struct DooSabinHierarchy {
    /// `meshes[k]`: level `k` with refined positions.
    pub meshes: Vec<PolyMesh>,
    /// `stencils[k]` maps level `k` to level `k + 1`.
    pub stencils: Vec<StencilTable>,
}

impl DooSabinHierarchy {
    /// The finest mesh.
    pub fn finest(&self) -> &PolyMesh {
        self.meshes.last().expect("level 0 is always present")
    }
}

/// Refines `mesh` with Doo-Sabin `levels` times (at most 8); errors on
/// topology the refiner cannot handle (non-manifold, degenerate faces) or a
/// level whose child mesh would have more than 50 million faces.
///
/// ```
/// let cube = subdyn::examples::cube();
/// let h = subdyn::subdivision::doo_sabin_refine(&cube, 1).unwrap();
/// // 6 F-faces, 12 E-faces, 8 V-faces (triangles)
/// assert_eq!(h.finest().num_faces(), 26);
/// assert!(h.stencils[0].row_sums().iter().all(|s| (s - 1.0).abs() < 1e-12));
/// ```
pub fn doo_sabin_refine(mesh: &PolyMesh, levels: usize) -> Result<DooSabinHierarchy> {
    if levels > 8 {
        return Err(crate::Error::input(format!(
            "{levels} Doo-Sabin levels requested; at most 8 are allowed"
        )));
    }
    let mut h = DooSabinHierarchy {
        meshes: vec![mesh.clone()],
        stencils: Vec::with_capacity(levels),
    };
    for _ in 0..levels {
        let parent = h.finest();
        if parent.face_vertices.len() > 50_000_000 {
            return Err(crate::Error::input(format!(
                "a further Doo-Sabin level of a mesh with {} face corners would be too large",
                parent.face_vertices.len()
            )));
        }
        let level = Level::from_mesh(parent)?;
        let step = doo_sabin_step(&level);
        let mut child = step.faces;
        child.positions = step.stencil.apply(&parent.positions)?;
        h.meshes.push(child);
        h.stencils.push(step.stencil);
    }
    Ok(h)
}
