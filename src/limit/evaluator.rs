//! `LimitEvaluator`: exact limit samples and limit stencils at `(face, u, v)`.

use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3};
use crate::stencil::StencilTable;
use crate::subdivision::Refiner;
use crate::topology::{Level, Sharpness};

use super::local_eval::evaluate_face;
use super::patch::SampleStencil;

/// A parameter location on the control mesh: face `face` at `(u, v)`.
///
/// For a quad, `u` runs from its first vertex to its second and `v` from its
/// first to its fourth. An `n`-gon is parameterised by its quad sub-faces
/// (see [`LimitEvaluator::stencil`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sample {
    /// Base face index.
    pub face: u32,
    /// First parameter.
    pub u: Real,
    /// Second parameter.
    pub v: Real,
}

/// Limit position and derivatives at one sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LimitPoint {
    /// Position on the limit surface.
    pub p: Point3,
    /// `∂P/∂u`.
    pub du: Vector3,
    /// `∂P/∂v`.
    pub dv: Vector3,
    /// `∂²P/∂u²`.
    pub duu: Vector3,
    /// `∂²P/∂u∂v`.
    pub duv: Vector3,
    /// `∂²P/∂v²`.
    pub dvv: Vector3,
}

impl LimitPoint {
    /// Unit normal `Pu × Pv / |Pu × Pv|` (zero if the derivatives are parallel).
    pub fn normal(&self) -> Vector3 {
        self.du
            .cross(&self.dv)
            .try_normalize(0.0)
            .unwrap_or_else(Vector3::zeros)
    }
}

/// Limit stencils of many samples: one table per quantity, rows = samples,
/// columns = control points. These are the Jacobians `J, J_u, J_v, J_uu,
/// J_uv, J_vv` of the dynamics (Qin et al. 1998 write `x(u, v) = J p`).
#[derive(Clone, Debug, Default)]
pub struct LimitStencils {
    /// Positions.
    pub p: StencilTable,
    /// First derivative in `u`.
    pub du: StencilTable,
    /// First derivative in `v`.
    pub dv: StencilTable,
    /// Second derivative in `u`.
    pub duu: StencilTable,
    /// Mixed second derivative.
    pub duv: StencilTable,
    /// Second derivative in `v`.
    pub dvv: StencilTable,
}

/// The largest vertex valence and polygon size that exact limit evaluation
/// accepts. Its local patches are dense in the ring around a face, so the
/// time grows about as the fourth power of the valence (a valence-400
/// vertex takes 7 s, 800 over two minutes); a valence or face this large
/// is refused with an error naming it. `subdivide --limit` (limit masks)
/// has no such limit.
pub const MAX_EXACT_RING: usize = 256;

/// Fails when face `face` has more than [`MAX_EXACT_RING`] vertices or one
/// of its vertices more than [`MAX_EXACT_RING`] edges.
fn check_face_rings(level: &Level, face: usize) -> Result<()> {
    let fv = level.face_vertices(face);
    if fv.len() > MAX_EXACT_RING {
        return Err(Error::input(format!(
            "face {face} has {} vertices; exact limit evaluation takes faces of at most {MAX_EXACT_RING} (subdivide it first, or use subdivide --limit)",
            fv.len()
        )));
    }
    match fv
        .iter()
        .find(|&&v| level.valence(v as usize) > MAX_EXACT_RING)
    {
        Some(&v) => Err(Error::input(format!(
            "vertex {v} has valence {}; exact limit evaluation takes vertices of valence at most {MAX_EXACT_RING} (use subdivide --limit)",
            level.valence(v as usize)
        ))),
        None => Ok(()),
    }
}

/// [`check_face_rings`] for every face of `level`, before work on the whole mesh.
pub(crate) fn check_ring_sizes(level: &Level) -> Result<()> {
    (0..level.num_faces()).try_for_each(|f| check_face_rings(level, f))
}

/// Evaluates the Catmull-Clark limit surface of a control mesh exactly.
///
/// ```
/// use subdyn::limit::LimitEvaluator;
/// use subdyn::subdivision::{Refiner, RefineOptions};
/// let cube = subdyn::examples::cube();
/// let eval = LimitEvaluator::new(&Refiner::new(&cube, &RefineOptions::default()).unwrap());
/// let s = eval.evaluate(0, 0.5, 0.5, &cube.positions).unwrap();
/// // the centre of a cube face lies 0.0802… inside the face (OpenSubdiv agrees)
/// assert!((s.p.x - 0.080246913580246909).abs() < 1e-12);
/// ```
#[derive(Clone, Debug)]
pub struct LimitEvaluator {
    level: Level,
    sharp: Sharpness,
}

impl LimitEvaluator {
    /// Prepares evaluation of the refiner's level-0 mesh.
    pub fn new(refiner: &Refiner) -> LimitEvaluator {
        LimitEvaluator {
            level: refiner.level.clone(),
            sharp: refiner.sharpness.clone(),
        }
    }

    /// Number of control points.
    pub fn num_control_points(&self) -> usize {
        self.level.num_vertices
    }

    /// Number of base faces.
    pub fn num_faces(&self) -> usize {
        self.level.num_faces()
    }

    /// The control mesh connectivity.
    pub fn level(&self) -> &Level {
        &self.level
    }

    /// Weights of the limit position and derivatives at `(face, u, v)` over the
    /// control points. `u, v ∈ [0, 1]`. An `n`-gon's sub-face `i` (corner `i`,
    /// the midpoint of edge `i`, the centroid, the midpoint of edge `i − 1`)
    /// covers `[tu, tu + ½] × [tv, tv + ½]` with `(tu, tv) = (i mod d, i div d)`
    /// and `d = ⌈√n⌉`, as in OpenSubdiv's `Bfr`.
    pub fn stencil(&self, face: usize, u: Real, v: Real) -> Result<SampleStencil> {
        if face >= self.num_faces() {
            return Err(Error::out_of_range(format!(
                "face {face} out of range: the mesh has {} faces",
                self.num_faces()
            )));
        }
        let n = self.level.face_vertices(face).len();
        let umax = if n == 4 {
            1.0
        } else {
            (n as Real).sqrt().ceil() - 0.5
        };
        if !(u.is_finite()
            && v.is_finite()
            && (0.0..=umax).contains(&u)
            && (0.0..=umax).contains(&v))
        {
            return Err(Error::input(format!(
                "parameter ({u}, {v}) of face {face} outside [0, {umax}]²"
            )));
        }
        check_face_rings(&self.level, face)?;
        Ok(evaluate_face(&self.level, &self.sharp, face, u, v))
    }

    /// Position and derivatives at `(face, u, v)` for control points `positions`.
    pub fn evaluate(
        &self,
        face: usize,
        u: Real,
        v: Real,
        positions: &[Point3],
    ) -> Result<LimitPoint> {
        if positions.len() != self.num_control_points() {
            return Err(Error::size_mismatch(format!(
                "{} control points given for a mesh of {}",
                positions.len(),
                self.num_control_points()
            )));
        }
        let s = self.stencil(face, u, v)?;
        let q: [Vector3; 6] = std::array::from_fn(|k| {
            s.cols
                .iter()
                .zip(&s.weights[k])
                .map(|(&c, &w)| w * positions[c as usize].coords)
                .sum()
        });
        Ok(LimitPoint {
            p: Point3::from(q[0]),
            du: q[1],
            dv: q[2],
            duu: q[3],
            duv: q[4],
            dvv: q[5],
        })
    }

    /// Limit stencils of many samples (computed in parallel).
    pub fn stencils(&self, samples: &[Sample]) -> Result<LimitStencils> {
        let rows: Vec<SampleStencil> = samples
            .par_iter()
            .map(|s| self.stencil(s.face as usize, s.u, s.v))
            .collect::<Result<_>>()?;
        let table = |k: usize| {
            let mut t = StencilTable::with_capacity(self.num_control_points(), rows.len(), 0);
            for r in &rows {
                t.push_row(
                    r.cols
                        .iter()
                        .zip(&r.weights[k])
                        .filter(|(_, w)| **w != 0.0)
                        .map(|(&c, &w)| (c, w)),
                );
            }
            t
        };
        Ok(LimitStencils {
            p: table(0),
            du: table(1),
            dv: table(2),
            duu: table(3),
            duv: table(4),
            dvv: table(5),
        })
    }
}
