//! The patch map of a [`PatchTable`]: which patch and which `(s, t)` hold a
//! base sample `(face, u, v)`, and each patch's place in its base face.

use super::PatchTable;
use crate::math::Real;

use crate::limit::Sample;
use crate::limit::param::{child_frame, quadrant};

impl PatchTable {
    /// The affine map of patch `f`'s `(s, t)` into its base face's `(u, v)`:
    /// `(u, v) = origin + axes · (s, t)`.
    pub fn patch_frame(&self, f: usize) -> ([Real; 2], [[Real; 2]; 2]) {
        (self.patches[f].origin, self.patches[f].axes)
    }

    /// The cells on which patch `f` is one polynomial piece: `(J, c)` with
    /// cell coordinates `J (s, t) + c ∈ [0, 1]²` — the whole patch for a
    /// regular face, the quadtree leaves (and the innermost cells) otherwise.
    /// Quadrature on each cell is exact for polynomial integrands.
    pub fn cells(&self, f: usize) -> Vec<([[Real; 2]; 2], [Real; 2])> {
        let patch = &self.patches[f];
        if patch.regular {
            return vec![([[1.0, 0.0], [0.0, 1.0]], [0.0, 0.0])];
        }
        let tree = patch.tree.get_or_init(|| self.tree(f));
        tree.shape.leaves.iter().map(|l| (l.jac, l.off)).collect()
    }

    /// The base-face sample of patch `f` at `(s, t)`.
    pub fn sample(&self, f: usize, st: [Real; 2]) -> Sample {
        let p = &self.patches[f];
        let a = p.axes;
        Sample {
            face: p.base,
            u: p.origin[0] + a[0][0] * st[0] + a[0][1] * st[1],
            v: p.origin[1] + a[1][0] * st[0] + a[1][1] * st[1],
        }
    }

    /// Sign of the orientation of patch `f`'s `(s, t)` relative to its base
    /// face's `(u, v)` (rotations keep it at +1).
    pub fn orientation(&self, f: usize) -> Real {
        let a = self.patches[f].axes;
        (a[0][0] * a[1][1] - a[0][1] * a[1][0]).signum()
    }

    /// The patch and `(s, t)` holding base sample `(face, u, v)`; ties go to
    /// the upper half as in the evaluator.
    pub fn locate(&self, face: usize, u: Real, v: Real) -> (usize, [Real; 2]) {
        let mut f = face;
        let mut st = [u, v];
        for (k, offs) in self.offsets.iter().enumerate() {
            let n = (offs[f + 1] - offs[f]) as usize;
            let i = if k == 0 && n != 4 {
                let (i, sub) = crate::limit::param::subface(n, u, v);
                st = sub;
                i
            } else {
                let q = quadrant(st);
                st = child_frame(q, st).0;
                q
            };
            f = offs[f] as usize + i;
        }
        (f, st)
    }
}
