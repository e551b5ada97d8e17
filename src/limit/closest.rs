//! Closest points on the limit surface: the spring-force engine of fitting.
//!
//! Precompute: the control mesh is refined uniformly to level `L` (default 2);
//! every level-`L` face whose corners are regular becomes a bicubic B-spline
//! patch with 16 control points (exactly the limit surface over that face).
//! A face that touches an irregular vertex is, on first use, subdivided
//! locally into a quadtree of regular bicubic leaves, [`TREE_DEPTH`] levels
//! deep; only the innermost cell at the irregular vertex is evaluated through
//! [`LimitEvaluator`]. Each face is sampled on a small grid and the samples go
//! into a k-d tree.
//!
//! Query: the nearest samples seed a projected Newton iteration on
//! `½‖P(s, t) − q‖²` inside a level-`L` face, with a Gauss-Newton fallback
//! where the Hessian is indefinite and a backtracking line search; when the
//! iterate leaves its face it crosses the edge into the neighbouring face.
//! The result is reported as a base-face sample `(face, u, v)`.

use std::num::NonZero;
use std::sync::OnceLock;

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3, bbox_diagonal};
use crate::subdivision::{Hierarchy, Refiner};
use crate::topology::{Level, NONE};

use super::bspline::patch_weights;
use super::patch::{CORNERS, LocalPatch, patch_grid};
use super::vertex_masks::{CornerKind, corner_kind};
use super::{LimitEvaluator, Sample};

/// Options of [`ClosestPointEngine::new`].
#[derive(Clone, Debug)]
pub struct ClosestPointParams {
    /// Uniform refinement level whose faces are the search patches (default 2).
    pub level: usize,
    /// Seed samples per patch side (default 3: a 3 × 3 grid inside each patch).
    pub seeds_per_side: usize,
    /// Seeds tried per query (default 3).
    pub candidates: usize,
    /// Newton iterations per seed (default 30).
    pub max_iterations: usize,
}

impl Default for ClosestPointParams {
    fn default() -> Self {
        ClosestPointParams {
            level: 2,
            seeds_per_side: 3,
            candidates: 3,
            max_iterations: 30,
        }
    }
}

/// Result of a closest-point query.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosestPoint {
    /// Parameter location on the control mesh.
    pub sample: Sample,
    /// The closest limit-surface point.
    pub point: Point3,
    /// Distance from the query.
    pub distance: Real,
    /// Unit normal of the surface there (zero where undefined).
    pub normal: Vector3,
}

/// Levels of local subdivision below `L` for faces at irregular vertices.
pub const TREE_DEPTH: usize = 8;

/// A level-`L` face: its limit patch and its place in its base face.
struct Patch {
    /// Control points of the bicubic patch, or `None` near an irregular vertex.
    grid: Option<[Point3; 16]>,
    /// Regular leaves of the local subdivision of an irregular face (lazy).
    tree: OnceLock<Vec<Leaf>>,
    base: u32,
    /// Base `(u, v) = origin + axes · (s, t)`.
    origin: [Real; 2],
    axes: [[Real; 2]; 2],
}

/// A cell of an irregular face's quadtree: leaf `(s', t') = J (s, t) + c`
/// in the face's `(s, t)`, with its bicubic control points (`None` for the
/// innermost cell at an irregular vertex, evaluated exactly).
struct Leaf {
    jac: [[Real; 2]; 2],
    off: [Real; 2],
    grid: Option<[Point3; 16]>,
}

/// Position and first/second derivatives in a patch's own `(s, t)`.
struct Eval {
    p: Point3,
    d: [Vector3; 5],
}

/// Closest-point queries against the limit surface of a fixed control mesh.
pub struct ClosestPointEngine {
    evaluator: LimitEvaluator,
    positions: Vec<Point3>,
    level: Level,
    sharp: crate::topology::Sharpness,
    level_positions: Vec<Point3>,
    patches: Vec<Patch>,
    seeds: Vec<(u32, [Real; 2])>,
    tree: ImmutableKdTree<Real, 3>,
    params: ClosestPointParams,
    scale: Real,
}

impl ClosestPointEngine {
    /// Precomputes patches and the seed tree for control points `positions`.
    pub fn new(
        refiner: &Refiner,
        positions: &[Point3],
        params: &ClosestPointParams,
    ) -> Result<Self> {
        if params.level == 0 || params.level > 6 {
            return Err(Error::Input(format!(
                "closest-point level {} must be between 1 and 6",
                params.level
            )));
        }
        if params.seeds_per_side == 0 || params.candidates == 0 || params.max_iterations == 0 {
            return Err(Error::Input(
                "closest-point seeds, candidates and iterations must be positive".into(),
            ));
        }
        if positions.len() != refiner.level.num_vertices {
            return Err(Error::Input(format!(
                "{} positions for a mesh of {} vertices",
                positions.len(),
                refiner.level.num_vertices
            )));
        }
        if refiner.level.num_faces() == 0 {
            return Err(Error::Input("the control mesh has no faces".into()));
        }
        let h = refiner.refine_uniform(params.level)?;
        let evaluator = LimitEvaluator::new(refiner);
        let pl = h.refine_positions(positions)?;
        let lp = &pl[params.level];
        let fine = h.finest();
        let sharp = h.sharpness.last().expect("levels exist");
        let maps = param_maps(&h);
        let patches: Vec<Patch> = (0..fine.num_faces())
            .into_par_iter()
            .map(|f| {
                let regular = fine.face_vertices(f).iter().all(|&c| {
                    corner_kind(fine, sharp, c as usize, f as u32) != CornerKind::Irregular
                });
                let grid = regular.then(|| {
                    patch_grid(fine, sharp, f).map(|b| {
                        Point3::from(
                            b.entries()
                                .map(|(c, w)| w * lp[c as usize].coords)
                                .sum::<Vector3>(),
                        )
                    })
                });
                let (base, origin, axes) = maps[f];
                Patch {
                    grid,
                    tree: OnceLock::new(),
                    base,
                    origin,
                    axes,
                }
            })
            .collect();
        let mut engine = ClosestPointEngine {
            evaluator,
            positions: positions.to_vec(),
            level: fine.clone(),
            sharp: sharp.clone(),
            level_positions: lp.clone(),
            patches,
            seeds: Vec::new(),
            tree: ImmutableKdTree::new_from_slice(&[[0.0; 3]]),
            params: params.clone(),
            scale: bbox_diagonal(positions).max(Real::MIN_POSITIVE),
        };
        let n = params.seeds_per_side;
        let seeds: Vec<(u32, [Real; 2])> = (0..engine.patches.len() as u32)
            .flat_map(|f| {
                (0..n * n).map(move |i| {
                    let s = ((i % n) as Real + 0.5) / n as Real;
                    let t = ((i / n) as Real + 0.5) / n as Real;
                    (f, [s, t])
                })
            })
            .collect();
        let pts: Vec<[Real; 3]> = seeds
            .par_iter()
            .map(|&(f, st)| engine.eval(f as usize, st).map(|e| [e.p.x, e.p.y, e.p.z]))
            .collect::<Result<_>>()?;
        engine.tree = ImmutableKdTree::new_from_slice(&pts);
        engine.seeds = seeds;
        Ok(engine)
    }

    /// Evaluates patch `f` at `(s, t)`: position and `∂s, ∂t, ∂ss, ∂st, ∂tt`.
    fn eval(&self, f: usize, st: [Real; 2]) -> Result<Eval> {
        let patch = &self.patches[f];
        if let Some(grid) = &patch.grid {
            let w = patch_weights(st[0], st[1]);
            let q: [Vector3; 6] =
                std::array::from_fn(|k| (0..16).map(|i| w[k][i] * grid[i].coords).sum());
            return Ok(Eval {
                p: Point3::from(q[0]),
                d: [q[1], q[2], q[3], q[4], q[5]],
            });
        }
        let leaves = patch.tree.get_or_init(|| self.leaves(f));
        let inside = |l: &&Leaf| {
            let x = l.jac[0][0] * st[0] + l.jac[0][1] * st[1] + l.off[0];
            let y = l.jac[1][0] * st[0] + l.jac[1][1] * st[1] + l.off[1];
            (-1e-12..=1.0 + 1e-12).contains(&x) && (-1e-12..=1.0 + 1e-12).contains(&y)
        };
        if let Some(leaf) = leaves.iter().filter(|l| l.grid.is_some()).find(inside) {
            let j = leaf.jac;
            let x = [
                (j[0][0] * st[0] + j[0][1] * st[1] + leaf.off[0]).clamp(0.0, 1.0),
                (j[1][0] * st[0] + j[1][1] * st[1] + leaf.off[1]).clamp(0.0, 1.0),
            ];
            let grid = leaf.grid.as_ref().expect("filtered");
            let w = patch_weights(x[0], x[1]);
            let q: [Vector3; 6] =
                std::array::from_fn(|k| (0..16).map(|i| w[k][i] * grid[i].coords).sum());
            // (s', t') = J (s, t) + c: first and second derivatives by the chain rule.
            let (su, sv, tu, tv) = (j[0][0], j[0][1], j[1][0], j[1][1]);
            return Ok(Eval {
                p: Point3::from(q[0]),
                d: [
                    q[1] * su + q[2] * tu,
                    q[1] * sv + q[2] * tv,
                    q[3] * su * su + q[4] * (2.0 * su * tu) + q[5] * tu * tu,
                    q[3] * su * sv + q[4] * (su * tv + sv * tu) + q[5] * tu * tv,
                    q[3] * sv * sv + q[4] * (2.0 * sv * tv) + q[5] * tv * tv,
                ],
            });
        }
        let a = patch.axes;
        let u = patch.origin[0] + a[0][0] * st[0] + a[0][1] * st[1];
        let v = patch.origin[1] + a[1][0] * st[0] + a[1][1] * st[1];
        let e = self
            .evaluator
            .evaluate(patch.base as usize, u, v, &self.positions)?;
        // (u, v) = o + A (s, t): chain rule.
        let (us, ut, vs, vt) = (a[0][0], a[0][1], a[1][0], a[1][1]);
        Ok(Eval {
            p: e.p,
            d: [
                e.du * us + e.dv * vs,
                e.du * ut + e.dv * vt,
                e.duu * us * us + e.duv * (2.0 * us * vs) + e.dvv * vs * vs,
                e.duu * us * ut + e.duv * (us * vt + ut * vs) + e.dvv * vs * vt,
                e.duu * ut * ut + e.duv * (2.0 * ut * vt) + e.dvv * vt * vt,
            ],
        })
    }

    /// The closest limit-surface point to `q`.
    pub fn closest_point(&self, q: Point3) -> Result<ClosestPoint> {
        if !q.coords.iter().all(|c| c.is_finite()) {
            return Err(Error::Input(format!(
                "query point ({}, {}, {}) is not finite",
                q.x, q.y, q.z
            )));
        }
        let k = NonZero::new(self.params.candidates.min(self.seeds.len()))
            .unwrap_or(NonZero::<usize>::MIN);
        let near = self.tree.nearest_n::<SquaredEuclidean>(&[q.x, q.y, q.z], k);
        let mut best: Option<(Real, usize, [Real; 2], Eval)> = None;
        for nn in near {
            let (f, st) = self.seeds[nn.item as usize];
            let (f, st, e) = self.descend(q, f as usize, st)?;
            let d = (e.p - q).norm();
            if best.as_ref().is_none_or(|b| d < b.0) {
                best = Some((d, f, st, e));
            }
        }
        let (d, f, st, e) = best.ok_or_else(|| Error::Input("no seed found".into()))?;
        let p = &self.patches[f];
        let a = p.axes;
        let n = e.d[0].cross(&e.d[1]);
        // Orientation of (s, t) relative to (u, v) decides the normal's sign.
        let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
        let normal = (n * det.signum())
            .try_normalize(0.0)
            .unwrap_or_else(Vector3::zeros);
        Ok(ClosestPoint {
            sample: Sample {
                face: p.base,
                u: p.origin[0] + a[0][0] * st[0] + a[0][1] * st[1],
                v: p.origin[1] + a[1][0] * st[0] + a[1][1] * st[1],
            },
            point: e.p,
            distance: d,
            normal,
        })
    }

    /// Quadtree leaves of irregular level-`L` face `f` (see module docs).
    fn leaves(&self, f: usize) -> Vec<Leaf> {
        let positions = |rows: [Vec<Real>; 16], cols: &[u32]| -> [Point3; 16] {
            rows.map(|r| {
                Point3::from(
                    r.iter()
                        .zip(cols)
                        .map(|(&w, &c)| w * self.level_positions[c as usize].coords)
                        .sum::<Vector3>(),
                )
            })
        };
        let mut leaves = Vec::new();
        let mut stack = vec![(
            LocalPatch::around(&self.level, &self.sharp, f),
            [[1.0, 0.0], [0.0, 1.0]],
            [0.0, 0.0],
            0,
        )];
        while let Some((patch, jac, off, depth)) = stack.pop() {
            if depth == TREE_DEPTH {
                leaves.push(Leaf {
                    jac,
                    off,
                    grid: None,
                });
                continue;
            }
            let refined = patch.refined();
            for k in 0..4 {
                // Child k: corner 0 at corner k, s' towards corner k+1, t' towards k−1.
                let o = CORNERS[k];
                let a = [
                    CORNERS[(k + 1) % 4][0] - o[0],
                    CORNERS[(k + 1) % 4][1] - o[1],
                ];
                let b = [
                    CORNERS[(k + 3) % 4][0] - o[0],
                    CORNERS[(k + 3) % 4][1] - o[1],
                ];
                let m = [[2.0 * a[0], 2.0 * a[1]], [2.0 * b[0], 2.0 * b[1]]];
                let cj = [
                    [
                        m[0][0] * jac[0][0] + m[0][1] * jac[1][0],
                        m[0][0] * jac[0][1] + m[0][1] * jac[1][1],
                    ],
                    [
                        m[1][0] * jac[0][0] + m[1][1] * jac[1][0],
                        m[1][0] * jac[0][1] + m[1][1] * jac[1][1],
                    ],
                ];
                let d = [off[0] - o[0], off[1] - o[1]];
                let co = [
                    m[0][0] * d[0] + m[0][1] * d[1],
                    m[1][0] * d[0] + m[1][1] * d[1],
                ];
                let cf = patch.child_face(k);
                if refined.is_regular(cf) {
                    let grid = positions(refined.grid_rows(cf), &refined.cols);
                    leaves.push(Leaf {
                        jac: cj,
                        off: co,
                        grid: Some(grid),
                    });
                } else {
                    stack.push((refined.extract(cf), cj, co, depth + 1));
                }
            }
        }
        leaves
    }

    /// Closest points of many queries, in parallel.
    pub fn closest_points(&self, queries: &[Point3]) -> Result<Vec<ClosestPoint>> {
        queries.par_iter().map(|&q| self.closest_point(q)).collect()
    }

    /// Projected Newton descent from `(f, st)`, crossing into neighbouring patches.
    fn descend(
        &self,
        q: Point3,
        mut f: usize,
        mut st: [Real; 2],
    ) -> Result<(usize, [Real; 2], Eval)> {
        let mut e = self.eval(f, st)?;
        let mut crossings = 0;
        let tol = 1e-13;
        for _ in 0..self.params.max_iterations {
            let r = e.p - q;
            let (ps, pt) = (e.d[0], e.d[1]);
            let g = [ps.dot(&r), pt.dot(&r)];
            // Newton Hessian, Gauss-Newton if not positive definite.
            let gn = [ps.dot(&ps), ps.dot(&pt), pt.dot(&pt)];
            let nh = [
                gn[0] + e.d[2].dot(&r),
                gn[1] + e.d[3].dot(&r),
                gn[2] + e.d[4].dot(&r),
            ];
            let step = solve_spd(nh, g).or_else(|| solve_spd(gn, g));
            let Some(mut step) = step else { break };
            // Limit the step to half a patch.
            let len = (step[0] * step[0] + step[1] * step[1]).sqrt();
            if len > 0.5 {
                step = [step[0] * 0.5 / len, step[1] * 0.5 / len];
            }
            // Clip to the patch; remember which side we hit.
            let mut alpha: Real = 1.0;
            let mut side = None;
            for i in 0..2 {
                let x = st[i] + step[i];
                if x < 0.0 && step[i] < 0.0 {
                    let a = -st[i] / step[i];
                    if a < alpha {
                        alpha = a;
                        side = Some(if i == 0 { 3 } else { 0 });
                    }
                } else if x > 1.0 && step[i] > 0.0 {
                    let a = (1.0 - st[i]) / step[i];
                    if a < alpha {
                        alpha = a;
                        side = Some(if i == 0 { 1 } else { 2 });
                    }
                }
            }
            // Backtracking on the distance.
            let d0 = r.norm_squared();
            let mut accepted = None;
            let mut a = alpha;
            for _ in 0..20 {
                let cand = [
                    (st[0] + a * step[0]).clamp(0.0, 1.0),
                    (st[1] + a * step[1]).clamp(0.0, 1.0),
                ];
                let ce = self.eval(f, cand)?;
                if (ce.p - q).norm_squared() <= d0 {
                    accepted = Some((cand, ce, a));
                    break;
                }
                a *= 0.5;
            }
            let Some((cand, ce, a)) = accepted else { break };
            let moved = ((cand[0] - st[0]).powi(2) + (cand[1] - st[1]).powi(2)).sqrt();
            st = cand;
            e = ce;
            if a == alpha
                && alpha < 1.0
                && crossings < 16
                && let Some((g, gst)) = side.and_then(|k| self.across(f, k, st))
            {
                f = g;
                st = gst;
                e = self.eval(f, st)?;
                crossings += 1;
                continue;
            }
            if moved < tol {
                break;
            }
        }
        Ok((f, st, e))
    }

    /// The same surface point seen from the patch across edge `k` of patch `f`.
    fn across(&self, f: usize, k: usize, st: [Real; 2]) -> Option<(usize, [Real; 2])> {
        let l = &self.level;
        let e = l.face_edge_list(f)[k] as usize;
        let [f0, f1] = l.edge_faces[e];
        let g = if f0 as usize == f { f1 } else { f0 };
        if g == NONE {
            return None;
        }
        let g = g as usize;
        let j = l.face_edge_list(g).iter().position(|&x| x as usize == e)?;
        // Fraction along edge k of f, from corner k to corner k+1.
        let (c0, c1) = (CORNERS[k], CORNERS[(k + 1) % 4]);
        let tau = if c0[0] != c1[0] {
            (st[0] - c0[0]) / (c1[0] - c0[0])
        } else {
            (st[1] - c0[1]) / (c1[1] - c0[1])
        };
        // In g the edge runs the other way.
        let sigma = 1.0 - tau;
        let (d0, d1) = (CORNERS[j], CORNERS[(j + 1) % 4]);
        Some((
            g,
            [
                d0[0] + sigma * (d1[0] - d0[0]),
                d0[1] + sigma * (d1[1] - d0[1]),
            ],
        ))
    }

    /// Bounding-box diagonal of the control points (the scale of distances).
    pub fn scale(&self) -> Real {
        self.scale
    }
}

/// Solves the 2×2 SPD system `[a b; b c] x = −g`; `None` if not positive definite.
fn solve_spd(h: [Real; 3], g: [Real; 2]) -> Option<[Real; 2]> {
    let det = h[0] * h[2] - h[1] * h[1];
    if !(h[0] > 0.0 && det > 1e-300 * (h[0] * h[2]).abs().max(1e-300)) {
        return None;
    }
    Some([
        (-g[0] * h[2] + g[1] * h[1]) / det,
        (g[0] * h[1] - g[1] * h[0]) / det,
    ])
}

/// For every face of the finest level: its base face and the affine map from
/// its `(s, t)` to the base face's `(u, v)`.
fn param_maps(h: &Hierarchy) -> Vec<(u32, [Real; 2], [[Real; 2]; 2])> {
    let l0 = h.level(0);
    let mut maps: Vec<(u32, [Real; 2], [[Real; 2]; 2])> = (0..l0.num_faces() as u32)
        .map(|f| (f, [0.0, 0.0], [[1.0, 0.0], [0.0, 1.0]]))
        .collect();
    for k in 0..h.num_levels() {
        let parent = h.level(k);
        let mut next = Vec::with_capacity(parent.face_verts.len());
        for (f, &(base, o, a)) in maps.iter().enumerate() {
            let n = parent.face_vertices(f).len();
            for i in 0..n {
                if n != 4 {
                    // n-gon sub-face i: its tile, at half scale (only at level 0).
                    let d = (n as Real).sqrt().ceil() as usize;
                    next.push((
                        base,
                        [(i % d) as Real, (i / d) as Real],
                        [[0.5, 0.0], [0.0, 0.5]],
                    ));
                    continue;
                }
                // Child i: corner 0 at parent corner i, s towards i+1, t towards i−1.
                let c = CORNERS[i];
                let ax = [
                    CORNERS[(i + 1) % 4][0] - c[0],
                    CORNERS[(i + 1) % 4][1] - c[1],
                ];
                let bx = [
                    CORNERS[(i + 3) % 4][0] - c[0],
                    CORNERS[(i + 3) % 4][1] - c[1],
                ];
                // parent (s, t) = c + ½ (ax s' + bx t'); base = o + a · parent.
                let po = [
                    o[0] + a[0][0] * c[0] + a[0][1] * c[1],
                    o[1] + a[1][0] * c[0] + a[1][1] * c[1],
                ];
                let col = |v: [Real; 2]| {
                    [
                        0.5 * (a[0][0] * v[0] + a[0][1] * v[1]),
                        0.5 * (a[1][0] * v[0] + a[1][1] * v[1]),
                    ]
                };
                let (cs, ct) = (col(ax), col(bx));
                next.push((base, po, [[cs[0], ct[0]], [cs[1], ct[1]]]));
            }
        }
        maps = next;
    }
    maps
}
