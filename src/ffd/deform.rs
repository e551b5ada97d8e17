//! `Ffd`: free-form deformation with a lattice of arbitrary topology as one
//! sparse map `v = B p`, `B = W S_n` (MacCracken & Joy 1996, §5): `S_n`
//! refines the lattice `n` times, `W` holds each model vertex's weights in
//! its cell of level `n`. Deforming is one product; moving a few control
//! points updates only the rows in their columns of `B` (found through `Bᵀ`).

use std::time::Instant;

use crate::error::{Error, Result};
use crate::lattice::{
    Lattice, LatticeHierarchy, MAX_LATTICE_LEVELS, refined_cells, refinement_stencil,
};
use crate::math::{Point3, Real};
use crate::stencil::StencilTable;

use super::embed::embedding_in_cells;

/// Parameters of [`Ffd::new`].
#[derive(Clone, Debug)]
pub struct FfdParams {
    /// Refinement levels `n` of the lattice (default 3; 1 to 6).
    pub levels: usize,
    /// Largest parameter-bound violation accepted for a point that lies in
    /// no cell exactly (default `0.05`): the gaps between a hexahedron's
    /// bilinear face and its triangulated neighbour are this thin.
    pub slack: Real,
}

impl Default for FfdParams {
    fn default() -> Self {
        FfdParams {
            levels: 3,
            slack: 0.05,
        }
    }
}

/// What embedding found.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct FfdReport {
    /// Model vertices.
    pub points: usize,
    /// Vertices inside the lattice's region.
    pub embedded: usize,
    /// Vertices outside it (they do not move).
    pub outside: usize,
    /// Vertices taken into the nearest cell although slightly outside every cell.
    pub snapped: usize,
    /// Vertices in type-n (non-hexahedral) cells.
    pub in_type_n_cells: usize,
    /// Largest Newton iteration count of a trilinear inversion.
    pub max_newton_iterations: usize,
    /// Refinement levels.
    pub levels: usize,
    /// Cells of the refined level.
    pub level_cells: usize,
    /// Weights stored in `B`.
    pub b_entries: usize,
    /// Seconds to refine the lattice (topology and `S_n`).
    pub refine_s: f64,
    /// Seconds to embed the vertices and form `B`.
    pub embed_s: f64,
}

/// A frozen lattice deformation over a set of model vertices.
#[derive(Clone, Debug)]
pub struct Ffd {
    /// `B = W S_n`: model vertices from level-0 control points (empty rows outside).
    pub b: StencilTable,
    /// `Bᵀ`, for local updates.
    pub bt: StencilTable,
    /// The model vertices as embedded.
    pub rest: Vec<Point3>,
    /// Indices of vertices outside the lattice.
    pub outside: Vec<u32>,
    /// Current control points.
    pub control: Vec<Point3>,
    /// Current deformed vertices.
    pub deformed: Vec<Point3>,
    /// What embedding found.
    pub report: FfdReport,
}

impl Ffd {
    /// Refines the lattice, embeds the points and forms `B` (the precompute step).
    pub fn new(lattice: &Lattice, points: &[Point3], params: &FfdParams) -> Result<Ffd> {
        if params.levels == 0 {
            return Err(Error::input(
                "FFD needs at least one refinement level (level-0 cells are arbitrary polyhedra)",
            ));
        }
        if params.levels > MAX_LATTICE_LEVELS {
            return Err(Error::input(format!(
                "{} lattice levels requested; at most {MAX_LATTICE_LEVELS} are allowed (cells grow eightfold per level)",
                params.levels
            )));
        }
        if !(params.slack.is_finite() && params.slack >= 0.0) {
            return Err(Error::input(format!(
                "slack {} must be a finite number ≥ 0",
                params.slack
            )));
        }
        if let Some(i) = points
            .iter()
            .position(|p| !p.coords.iter().all(|x| x.is_finite()))
        {
            return Err(Error::input(format!(
                "model vertex {i}: coordinate is not a finite number"
            )));
        }
        let t0 = Instant::now();
        // Levels 0..n-1 in full; level n only as type-n cells and boundary
        // quads (all the embedding needs; its full incidence structure would
        // be most of the memory).
        let h = LatticeHierarchy::new(lattice, params.levels - 1)?;
        let last = h.level(params.levels - 1);
        let s = refinement_stencil(&last.topology, &last.tags)
            .compose(&h.stencil_to_level(params.levels - 1)?)?;
        let (cells, boundary) = refined_cells(&last.topology)?;
        let level_cells = cells.len();
        let xn = s.apply(&lattice.positions)?;
        let refine_s = t0.elapsed().as_secs_f64();
        let t1 = Instant::now();
        let emb = embedding_in_cells(&cells, &boundary, &xn, points, params.slack);
        let b = emb.weights.compose(&s)?;
        let bt = b.transpose();
        let embed_s = t1.elapsed().as_secs_f64();
        let report = FfdReport {
            points: points.len(),
            embedded: points.len() - emb.outside.len(),
            outside: emb.outside.len(),
            snapped: emb.snapped,
            in_type_n_cells: emb.in_type_n_cells,
            max_newton_iterations: emb.max_newton_iterations,
            levels: params.levels,
            level_cells,
            b_entries: b.num_entries(),
            refine_s,
            embed_s,
        };
        let mut ffd = Ffd {
            b,
            bt,
            rest: points.to_vec(),
            outside: emb.outside,
            control: lattice.positions.clone(),
            deformed: Vec::new(),
            report,
        };
        ffd.deformed = ffd.deform(&lattice.positions)?;
        Ok(ffd)
    }

    /// The model deformed by control points `p`: `B p`, outside vertices unmoved.
    pub fn deform(&self, p: &[Point3]) -> Result<Vec<Point3>> {
        check_finite(p)?;
        let mut out = self.b.apply(p)?;
        for &i in &self.outside {
            out[i as usize] = self.rest[i as usize];
        }
        Ok(out)
    }

    /// Sets the control points and recomputes every vertex (one product into
    /// the existing buffer).
    pub fn set_control(&mut self, p: &[Point3]) -> Result<()> {
        check_finite(p)?;
        if p.len() != self.control.len() {
            return Err(Error::input(format!(
                "{} control points given, the lattice has {}",
                p.len(),
                self.control.len()
            )));
        }
        self.control.copy_from_slice(p);
        self.b.apply_into(&self.control, &mut self.deformed);
        for &i in &self.outside {
            self.deformed[i as usize] = self.rest[i as usize];
        }
        Ok(())
    }

    /// Moves control points `(index, new position)` and updates only the
    /// vertices in their columns of `B`: `v_r += B_rc (p_c' − p_c)` for the
    /// rows `r` of column `c` of `Bᵀ`. Returns the number of row updates.
    pub fn move_control(&mut self, moves: &[(usize, Point3)]) -> Result<usize> {
        let mut touched = 0;
        for &(c, q) in moves {
            if c >= self.control.len() {
                return Err(Error::out_of_range(format!(
                    "control point {c} does not exist (the lattice has {})",
                    self.control.len()
                )));
            }
            if !q.coords.iter().all(|x| x.is_finite()) {
                return Err(Error::non_finite(format!(
                    "control point {c}: new position is not finite"
                )));
            }
        }
        for &(c, q) in moves {
            let d = q - self.control[c];
            self.control[c] = q;
            let (rows, w) = self.bt.row(c);
            for (&r, &w) in rows.iter().zip(w) {
                self.deformed[r as usize] += w * d;
            }
            touched += rows.len();
        }
        Ok(touched)
    }
}

fn check_finite(p: &[Point3]) -> Result<()> {
    match p
        .iter()
        .position(|q| !q.coords.iter().all(|x| x.is_finite()))
    {
        Some(i) => Err(Error::input(format!(
            "control point {i}: coordinate is not a finite number"
        ))),
        None => Ok(()),
    }
}
