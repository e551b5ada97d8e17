//! Hierarchical deformation with multiresolution lattices
//! (multiresolution-lattice FFD paper, §4).
//!
//! A [`LayeredFfd`] is one lattice in use: its rest state parameterizes the
//! rest model (`B = W S_n`, computed once, because a deformed lattice "may
//! not be valid", §3.2 footnote), its current control points `p`, and a
//! per-vertex correction table `δ`, so the model is `v = B p + δ`.
//!
//! **Global → local** (§4.1): after deforming with a coarse lattice `L'`,
//! the finer lattice is its octree subdivision `O(L')`. Its parameters come
//! from the unmodified `O(L)`, and since the octree rules `O` differ from the
//! Catmull-Clark rules `C`, `B_fine O(L') ≠ B L'` in general: the model would
//! jump. The paper corrects the gap with a lookup table; ours is
//! `δ_fine = (B L' + δ) − B_fine O(L')`, stored per vertex. It is zero
//! whenever `L'` is an affine image of `L` (both maps are affine invariant
//! and reproduce the rest model), so it measures exactly the octree/
//! Catmull-Clark difference of the non-affine part of the deformation.
//!
//! **Local → global** (§4.2): a new coarse lattice encloses both the
//! deformed model and the fine lattice's control points and carries both
//! ([`Enclosing`]); after a global edit the fine lattice's moved control
//! points and the moved model start a new [`LayeredFfd`] (its `δ` makes the
//! switch seamless), so local editing can resume.

use crate::error::{Error, Result};
use crate::lattice::{BoxLatticeParams, Lattice, box_lattice, octree_refined};
use crate::math::{Point3, Vector3};

use super::deform::{Ffd, FfdParams};

/// One lattice of a hierarchical deformation: `v = B p + δ`.
#[derive(Clone, Debug)]
pub struct LayeredFfd {
    /// The lattice in its rest state (it parameterizes the rest model).
    pub rest: Lattice,
    /// `B` over the rest model.
    pub ffd: Ffd,
    /// Current control points `p`.
    pub control: Vec<Point3>,
    /// Correction `δ` per model vertex (the lookup table of §4.1).
    pub correction: Vec<Vector3>,
}

impl LayeredFfd {
    /// Starts deforming `model_rest` with `rest`, the model currently at
    /// `model_now` and the lattice at `control`; `δ = model_now − B control`.
    pub fn new(
        rest: Lattice,
        model_rest: &[Point3],
        model_now: &[Point3],
        control: Vec<Point3>,
        params: &FfdParams,
    ) -> Result<LayeredFfd> {
        if model_now.len() != model_rest.len() || control.len() != rest.num_vertices() {
            return Err(Error::size_mismatch(format!(
                "hierarchical FFD: {} current and {} rest model vertices, {} control points for a lattice of {}",
                model_now.len(),
                model_rest.len(),
                control.len(),
                rest.num_vertices()
            )));
        }
        let ffd = Ffd::new(&rest, model_rest, params)?;
        LayeredFfd::with_ffd(rest, ffd, model_now, control)
    }

    /// Like [`LayeredFfd::new`] with the rest model already embedded in `rest` by `ffd`.
    pub fn with_ffd(
        rest: Lattice,
        ffd: Ffd,
        model_now: &[Point3],
        control: Vec<Point3>,
    ) -> Result<LayeredFfd> {
        if model_now.len() != ffd.rest.len() || control.len() != rest.num_vertices() {
            return Err(Error::size_mismatch(format!(
                "hierarchical FFD: {} model vertices for an embedding of {}, {} control points for a lattice of {}",
                model_now.len(),
                ffd.rest.len(),
                control.len(),
                rest.num_vertices()
            )));
        }
        let at = ffd.deform(&control)?;
        let correction = model_now.iter().zip(&at).map(|(a, b)| a - b).collect();
        Ok(LayeredFfd {
            rest,
            ffd,
            control,
            correction,
        })
    }

    /// A first, global lattice over an undeformed model (`δ = 0`).
    pub fn global(rest: Lattice, model: &[Point3], params: &FfdParams) -> Result<LayeredFfd> {
        let control = rest.positions.clone();
        LayeredFfd::new(rest, model, model, control, params)
    }

    /// The model at the current control points: `B p + δ`.
    pub fn model(&self) -> Result<Vec<Point3>> {
        let v = self.ffd.deform(&self.control)?;
        Ok(v.iter().zip(&self.correction).map(|(p, d)| p + d).collect())
    }

    /// Global → local: the octree subdivision of this lattice, at the octree
    /// subdivision of the current control points, parameterized by the
    /// subdivision of the rest lattice, with the correction that keeps the
    /// model where it is.
    pub fn finer(&self, params: &FfdParams) -> Result<LayeredFfd> {
        let (rest, o) = octree_refined(&self.rest)?;
        let control = o.apply(&self.control)?;
        LayeredFfd::new(rest, &self.ffd.rest, &self.model()?, control, params)
    }

    /// Largest correction length (0 right after [`LayeredFfd::global`]).
    pub fn max_correction(&self) -> f64 {
        self.correction.iter().map(|d| d.norm()).fold(0.0, f64::max)
    }
}

/// Local → global: a coarse lattice around the current model and a finer
/// lattice's current control points, embedding both.
#[derive(Clone, Debug)]
pub struct Enclosing {
    /// The enclosing lattice at rest.
    pub lattice: Lattice,
    /// Its FFD over `[model vertices | fine control points]`.
    pub ffd: Ffd,
    /// Number of model vertices (the rest are fine control points).
    pub model_vertices: usize,
}

impl Enclosing {
    /// An automatic box lattice (`box_params`; culling is off, so the box
    /// holds every point) around the current model of `fine` and its
    /// control points.
    pub fn around(
        fine: &LayeredFfd,
        box_params: &BoxLatticeParams,
        params: &FfdParams,
    ) -> Result<Enclosing> {
        let model = fine.model()?;
        let mut points = model.clone();
        points.extend_from_slice(&fine.control);
        let lattice = box_lattice(
            &points,
            &BoxLatticeParams {
                cull: false,
                ..box_params.clone()
            },
        )?;
        let ffd = Ffd::new(&lattice, &points, params)?;
        Ok(Enclosing {
            lattice,
            ffd,
            model_vertices: model.len(),
        })
    }

    /// The model and the fine lattice's control points carried by the
    /// enclosing lattice's control points `p`.
    pub fn carried(&self, p: &[Point3]) -> Result<(Vec<Point3>, Vec<Point3>)> {
        let mut all = self.ffd.deform(p)?;
        let fine = all.split_off(self.model_vertices);
        Ok((all, fine))
    }

    /// Back to local editing after the enclosing lattice moved to `p`: the
    /// fine lattice at its carried control points, with `δ` keeping the
    /// carried model.
    pub fn back_to_local(&self, fine: &LayeredFfd, p: &[Point3]) -> Result<LayeredFfd> {
        let (model, control) = self.carried(p)?;
        LayeredFfd::with_ffd(fine.rest.clone(), fine.ffd.clone(), &model, control)
    }
}
