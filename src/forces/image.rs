//! Image forces for recovering shapes from volumes (Qin et al. 1998, §4.2).
//!
//! The paper pulls the surface with `f = −k ∇P` from the edge potential
//! `P = −‖∇(G_σ * I)‖`, sampled at the quadrature points, and grows it with
//! an inflation (balloon) force. Applied explicitly, `−k ∇P` is a gradient
//! step on `P` whose useful step size depends on the edge's sharpness, so
//! subdyn instead searches `P` along the surface normal at every quadrature
//! point for the nearest minimum (the edge that `−∇P · n` flows to) and
//! attaches a spring to it, which the implicit step treats exactly: the
//! equilibrium is the same (`∇P · n = 0` on the edge) and the step is stable
//! for any stiffness. Where no edge lies within the search range the point
//! is pushed outward by the range when it is inside the object and inward
//! when outside: that is the inflation force, with a pressure that stops by
//! itself at the boundary.
//!
//! With a known iso-value `T` (CT Hounsfield units, a probability map's 0.5)
//! the boundary is instead the nearest crossing of `G_σ * I = T` along the
//! normal, located to sub-voxel accuracy by linear interpolation and two
//! secant steps.

use crate::math::{Point3, Real, Vector3};
use crate::volume::Volume;

/// What marks the boundary in the image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BoundaryModel {
    /// The level set `G_σ * I = value` (intensity units of the volume).
    Iso {
        /// The iso-value.
        value: Real,
    },
    /// The nearest minimum of the edge potential `P` along the normal whose
    /// strength `−P` (relative to the volume's strongest edge) is at least
    /// `min_strength`, with intensity falling outward for bright objects.
    Edge {
        /// Weakest edge accepted, in `[0, 1)` (default 0.1).
        min_strength: Real,
    },
}

/// The images a boundary search reads.
#[derive(Clone, Copy, Debug)]
pub struct ImageField<'a> {
    /// `G_σ * I`.
    pub smoothed: &'a Volume,
    /// The edge potential of `smoothed` (needed for [`BoundaryModel::Edge`]).
    pub potential: Option<&'a Volume>,
    /// The boundary model.
    pub model: BoundaryModel,
    /// Intensity above which (below which, for dark objects) a point is
    /// inside the object: the iso-value, or a threshold such as Otsu's.
    pub inside_level: Real,
    /// The object is brighter than its surroundings.
    pub bright_inside: bool,
    /// Highest minus lowest intensity of `smoothed` (sets the scale below
    /// which a gradient is too weak to follow).
    pub contrast: Real,
}

/// Fraction of the smoothed volume's intensity range per voxel below which
/// the image gradient is too weak to give a direction.
const WEAK_GRADIENT: Real = 1e-3;

impl ImageField<'_> {
    /// The direction a point with no boundary in range moves: out of the
    /// object when `inside`, into it otherwise — down the smoothed image's
    /// gradient for bright objects (up for dark ones) where the gradient is
    /// clear, else along `±n`. Following the image rather than the normal
    /// keeps parts of the surface whose normal has turned from running away.
    pub fn balloon_direction(&self, x: &Point3, n: &Vector3, inside: bool) -> Vector3 {
        let g = self.smoothed.gradient(x);
        let outward = if self.bright_inside { -g } else { g };
        let len = outward.norm();
        let dir = if len * self.smoothed.voxel_size() > WEAK_GRADIENT * self.contrast {
            outward / len
        } else {
            *n
        };
        if inside { dir } else { -dir }
    }
}

/// Where the search along one normal ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Offset {
    /// The boundary lies at `x + t n` (`t` in world units, signed).
    Boundary(Real),
    /// No boundary within range and the point is inside: push outward.
    Inside,
    /// No boundary within range and the point is outside: pull inward.
    Outside,
}

impl ImageField<'_> {
    /// The boundary nearest to `x` along the unit normal `n` within
    /// `±range` (world units), sampled every `step`.
    pub fn boundary_offset(&self, x: &Point3, n: &Vector3, range: Real, step: Real) -> Offset {
        let s = self.smoothed;
        let c0 = s.continuous_index(x);
        let dc = s.index_vector(n);
        let at = |t: Real| [c0[0] + t * dc[0], c0[1] + t * dc[1], c0[2] + t * dc[2]];
        let sign = if self.bright_inside { 1.0 } else { -1.0 };
        // g > 0 inside, g < 0 outside.
        let g = |t: Real| sign * (s.sample_index(at(t)) - self.inside_level);
        let m = (range / step).ceil().max(1.0) as usize;
        let t_of = |k: usize| (k as Real - m as Real) * step;
        // Samples are taken lazily, ring by ring outward from t = 0, and the
        // search stops at the first ring holding a boundary.
        let mut gs = vec![Real::NAN; 2 * m + 1];
        let mut ps = vec![Real::NAN; 2 * m + 1];
        let mut g_at = |k: usize| {
            if gs[k].is_nan() {
                gs[k] = g(t_of(k));
            }
            gs[k]
        };
        let pot = self.potential;
        let mut p_at = |k: usize| match pot {
            Some(v) => {
                if ps[k].is_nan() {
                    ps[k] = v.sample_index(at(t_of(k)));
                }
                ps[k]
            }
            None => 0.0,
        };
        let mut found = None;
        for r in 0..m {
            // Intervals [k, k + 1] at distance r from the centre sample m.
            for k in [m + r, m - r - 1] {
                let hit = match self.model {
                    BoundaryModel::Iso { .. } => {
                        let (ga, gb) = (g_at(k), g_at(k + 1));
                        (ga >= 0.0 && gb < 0.0).then(|| secant(&g, t_of(k), t_of(k + 1), ga, gb))
                    }
                    BoundaryModel::Edge { min_strength } => {
                        // A minimum of P at sample k + 1 (needs k + 2).
                        let c = k + 1;
                        if pot.is_none() || c + 1 > 2 * m {
                            None
                        } else {
                            let (pa, pc, pb) = (p_at(c - 1), p_at(c), p_at(c + 1));
                            if pc <= pa
                                && pc < pb
                                && -pc >= min_strength
                                && g_at(c + 1) < g_at(c - 1)
                            {
                                let curv = pa - 2.0 * pc + pb;
                                let shift = if curv > 0.0 {
                                    (0.5 * (pa - pb) / curv).clamp(-0.5, 0.5)
                                } else {
                                    0.0
                                };
                                Some(t_of(c) + shift * step)
                            } else {
                                None
                            }
                        }
                    }
                };
                if let Some(t) = hit
                    && found.is_none_or(|f: Real| t.abs() < f.abs())
                {
                    found = Some(t);
                }
            }
            if found.is_some() {
                break;
            }
        }
        match found {
            Some(t) => Offset::Boundary(t),
            None if g(0.0) >= 0.0 => Offset::Inside,
            None => Offset::Outside,
        }
    }
}

/// Root of `g` in `[a, b]` (`ga ≥ 0 > gb`): linear interpolation, then two
/// secant (regula falsi) steps that keep the bracket.
fn secant(g: &impl Fn(Real) -> Real, mut a: Real, mut b: Real, mut ga: Real, mut gb: Real) -> Real {
    let mut t = a + (b - a) * ga / (ga - gb);
    for _ in 0..2 {
        let gt = g(t);
        if gt >= 0.0 {
            (a, ga) = (t, gt);
        } else {
            (b, gb) = (t, gt);
        }
        if ga == gb {
            break;
        }
        t = a + (b - a) * ga / (ga - gb);
    }
    t
}
