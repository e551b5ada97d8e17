//! Closest points on the limit surface: the spring-force engine of fitting.
//!
//! Precompute: a [`PatchTable`] at level `L` (default 2); each patch is
//! sampled on a small grid and the samples go into a k-d tree.
//!
//! Query: the nearest samples seed a projected Newton iteration on
//! `½‖P(s, t) − q‖²` inside a level-`L` face, with a Gauss-Newton fallback
//! where the Hessian is indefinite and a backtracking line search; when the
//! iterate leaves its face it crosses the edge into the neighbouring face.
//! The result is reported as a base-face sample `(face, u, v)`.
//!
//! While the surface moves (fitting), [`ClosestPointEngine::set_positions`]
//! only moves the patches; the seed tree is rebuilt when a query next needs
//! it, so descents started from the previous answers alone
//! ([`ClosestPointEngine::closest_points_local`]) skip that cost.

use std::num::NonZero;
use std::sync::OnceLock;

use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3, bbox_diagonal};
use crate::subdivision::Refiner;
use crate::topology::NONE;

use super::Sample;
use super::param::CORNERS;
use super::patch_table::{PatchPoint, PatchTable, QuadtreeCache};

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
    /// A descent stops when a step moves less than this in the patch's
    /// `(s, t)` (default 1e-13). The distance is stationary at the answer, so
    /// its error is of the order of the square of this times the patch size:
    /// fitting can use 1e-7 and still get distances to round-off.
    pub tolerance: Real,
}

impl Default for ClosestPointParams {
    fn default() -> Self {
        ClosestPointParams {
            level: 2,
            seeds_per_side: 3,
            candidates: 3,
            max_iterations: 30,
            tolerance: 1e-13,
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
    /// The patch of the engine's [`PatchTable`] holding the point, and the
    /// point's `(s, t)` in it (for [`PatchTable::stencil`]).
    pub patch: (u32, [Real; 2]),
}

/// At most this many queries are answered without the seed tree when it is
/// not built yet ([`ClosestPointEngine::closest_points`]).
const FEW_QUERIES: usize = 32;

/// Closest-point queries against the limit surface of a fixed control mesh.
pub struct ClosestPointEngine {
    table: PatchTable,
    seeds: Vec<(u32, [Real; 2])>,
    /// The k-d tree of the seeds' current positions, built when first needed.
    tree: OnceLock<ImmutableKdTree<Real, 3>>,
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
        Self::with_quadtrees(refiner, positions, params, QuadtreeCache::default())
    }

    /// [`new`](Self::new) with the patch table's quadtrees shared through
    /// `shapes` ([`PatchTable::with_quadtrees`]).
    pub fn with_quadtrees(
        refiner: &Refiner,
        positions: &[Point3],
        params: &ClosestPointParams,
        shapes: QuadtreeCache,
    ) -> Result<Self> {
        if params.level == 0 || params.level > 6 {
            return Err(Error::input(format!(
                "closest-point level {} must be between 1 and 6",
                params.level
            )));
        }
        if !(params.tolerance > 0.0 && params.tolerance < 1.0) {
            return Err(Error::input(format!(
                "closest-point tolerance {} must be in (0, 1)",
                params.tolerance
            )));
        }
        if params.seeds_per_side == 0 || params.candidates == 0 || params.max_iterations == 0 {
            return Err(Error::input(
                "closest-point seeds, candidates and iterations must be positive",
            ));
        }
        if positions.len() != refiner.level.num_vertices {
            return Err(Error::size_mismatch(format!(
                "{} positions for a mesh of {} vertices",
                positions.len(),
                refiner.level.num_vertices
            )));
        }
        if refiner.level.num_faces() == 0 {
            return Err(Error::input("the control mesh has no faces"));
        }
        let n = params.seeds_per_side;
        let table = PatchTable::with_quadtrees(refiner, positions, params.level, shapes)?;
        let seeds: Vec<(u32, [Real; 2])> = (0..table.num_patches() as u32)
            .flat_map(|f| {
                (0..n * n).map(move |i| {
                    let s = ((i % n) as Real + 0.5) / n as Real;
                    let t = ((i / n) as Real + 0.5) / n as Real;
                    (f, [s, t])
                })
            })
            .collect();
        let scale = bbox_diagonal(table.positions()).max(Real::MIN_POSITIVE);
        let engine = ClosestPointEngine {
            table,
            seeds,
            tree: OnceLock::new(),
            params: params.clone(),
            scale,
        };
        engine.seed_tree()?;
        Ok(engine)
    }

    /// Moves the control points (same topology), keeping everything that
    /// depends on topology alone; cheaper than [`new`](Self::new). The seed
    /// tree is rebuilt by the next query that needs it.
    pub fn set_positions(&mut self, positions: &[Point3]) -> Result<()> {
        self.table.set_positions(positions)?;
        self.tree = OnceLock::new();
        self.scale = bbox_diagonal(self.table.positions()).max(Real::MIN_POSITIVE);
        Ok(())
    }

    /// The k-d tree of the seeds at the current positions (built once per
    /// [`set_positions`](Self::set_positions)).
    fn seed_tree(&self) -> Result<&ImmutableKdTree<Real, 3>> {
        if let Some(tree) = self.tree.get() {
            return Ok(tree);
        }
        let pts: Vec<[Real; 3]> = self
            .seed_positions()?
            .iter()
            .map(|p| [p.x, p.y, p.z])
            .collect();
        Ok(self
            .tree
            .get_or_init(|| ImmutableKdTree::new_from_slice(&pts)))
    }

    /// The seeds' positions on the surface, in parallel.
    fn seed_positions(&self) -> Result<Vec<Point3>> {
        self.seeds
            .par_iter()
            .map(|&(f, st)| self.table.position(f as usize, st))
            .collect()
    }

    /// The closest limit-surface point to `q`.
    pub fn closest_point(&self, q: Point3) -> Result<ClosestPoint> {
        self.closest_point_near(q, None)
    }

    /// The closest point to `q`, also trying a start at `hint` (a patch and
    /// its `(s, t)`, e.g. the previous answer while the surface moves). With
    /// a hint, the descent from it comes first, and the nearest seed of the
    /// k-d tree is descended from too only when that seed is itself closer
    /// to `q` than the hint's answer or the hint's descent was still moving
    /// after its last iteration (a far hint): a descent never ends farther
    /// than it starts, so either way the answer is at least as close as
    /// every seed, as without a hint. A hint whose patch is out of range
    /// counts as none.
    pub fn closest_point_near(
        &self,
        q: Point3,
        hint: Option<(u32, [Real; 2])>,
    ) -> Result<ClosestPoint> {
        check_query(q)?;
        let tree = self.seed_tree()?;
        let at = [q.x, q.y, q.z];
        match hint.filter(|h| (h.0 as usize) < self.table.num_patches()) {
            Some(h) => {
                let (from_hint, settled) = self.best_descent(q, std::iter::once(h))?;
                let seed = tree.nearest_one::<SquaredEuclidean>(&at);
                if !settled || seed.distance.sqrt() < from_hint.distance {
                    let (from_seed, _) =
                        self.best_descent(q, std::iter::once(self.seeds[seed.item as usize]))?;
                    if from_seed.distance < from_hint.distance {
                        return Ok(from_seed);
                    }
                }
                Ok(from_hint)
            }
            None => {
                let k = NonZero::new(self.params.candidates.min(self.seeds.len()))
                    .unwrap_or(NonZero::<usize>::MIN);
                let near = tree.nearest_n::<SquaredEuclidean>(&at, k);
                self.best_descent(q, near.iter().map(|nn| self.seeds[nn.item as usize]))
                    .map(|(c, _)| c)
            }
        }
    }

    /// The closest point to `q` reached by descending from `start` alone (a
    /// previous answer): a local minimum of the distance, the closest point
    /// when the surface has moved little since `start` was found.
    pub fn closest_point_local(&self, q: Point3, start: (u32, [Real; 2])) -> Result<ClosestPoint> {
        check_query(q)?;
        self.best_descent(q, std::iter::once(start)).map(|(c, _)| c)
    }

    /// The nearest of the descents from `starts` (out-of-range patches
    /// skipped), and whether that descent settled within its iterations.
    fn best_descent(
        &self,
        q: Point3,
        starts: impl Iterator<Item = (u32, [Real; 2])>,
    ) -> Result<(ClosestPoint, bool)> {
        let starts = starts.filter(|h| (h.0 as usize) < self.table.num_patches());
        let mut best: Option<(Real, usize, [Real; 2], PatchPoint, bool)> = None;
        for (f, st) in starts {
            let (f, st, e, settled) = self.descend(q, f as usize, st)?;
            let d = (e.p - q).norm();
            if best.as_ref().is_none_or(|b| d < b.0) {
                best = Some((d, f, st, e, settled));
            }
        }
        let (d, f, st, e, settled) = best.ok_or_else(|| Error::input("no seed found"))?;
        // Orientation of (s, t) relative to (u, v) decides the normal's sign.
        let normal = (e.d[0].cross(&e.d[1]) * self.table.orientation(f))
            .try_normalize(0.0)
            .unwrap_or_else(Vector3::zeros);
        let found = ClosestPoint {
            sample: self.table.sample(f, st),
            point: e.p,
            distance: d,
            normal,
            patch: (f as u32, st),
        };
        Ok((found, settled))
    }

    /// The patch table the engine searches.
    pub fn table(&self) -> &PatchTable {
        &self.table
    }

    /// Closest points of many queries, each also started from its hint (see
    /// [`closest_point_near`](Self::closest_point_near)), in parallel. A hint
    /// whose patch is out of range counts as none: a full search.
    pub fn closest_points_near(
        &self,
        queries: &[Point3],
        hints: &[(u32, [Real; 2])],
    ) -> Result<Vec<ClosestPoint>> {
        self.seed_tree()?;
        self.each_with_start(queries, hints, |q, h| self.closest_point_near(q, Some(h)))
    }

    /// [`closest_point_local`](Self::closest_point_local) for many queries,
    /// in parallel: no seed search, so no seed tree either.
    pub fn closest_points_local(
        &self,
        queries: &[Point3],
        starts: &[(u32, [Real; 2])],
    ) -> Result<Vec<ClosestPoint>> {
        self.each_with_start(queries, starts, |q, s| self.closest_point_local(q, s))
    }

    /// `query(q, start)` for every query and its start, in parallel.
    fn each_with_start(
        &self,
        queries: &[Point3],
        starts: &[(u32, [Real; 2])],
        query: impl Fn(Point3, (u32, [Real; 2])) -> Result<ClosestPoint> + Sync,
    ) -> Result<Vec<ClosestPoint>> {
        if starts.len() != queries.len() {
            return Err(Error::size_mismatch(format!(
                "{} starting points for {} queries",
                starts.len(),
                queries.len()
            )));
        }
        // In the order of the starts' patches: queries on one patch read
        // the same control points and quadtree, which then stay in cache
        // (the callers' points come in any order, often shuffled).
        let mut order: Vec<u32> = (0..queries.len() as u32).collect();
        order.par_sort_unstable_by_key(|&i| starts[i as usize].0);
        let found: Vec<ClosestPoint> = order
            .par_iter()
            .map(|&i| query(queries[i as usize], starts[i as usize]))
            .collect::<Result<_>>()?;
        // Back in the queries' order: `rank[i]` is query `i`'s place in `order`.
        let mut rank = vec![0u32; order.len()];
        for (k, &i) in order.iter().enumerate() {
            rank[i as usize] = k as u32;
        }
        Ok(rank.par_iter().map(|&k| found[k as usize]).collect())
    }

    /// Closest points of many queries, in parallel.
    pub fn closest_points(&self, queries: &[Point3]) -> Result<Vec<ClosestPoint>> {
        if self.tree.get().is_none() && queries.len() <= FEW_QUERIES {
            return self.closest_points_by_scan(queries);
        }
        self.seed_tree()?;
        queries.par_iter().map(|&q| self.closest_point(q)).collect()
    }

    /// [`closest_points`](Self::closest_points) for a handful of queries
    /// while the seed tree is not built: each query's nearest seeds by a
    /// scan over the seeds, which costs far less than building the tree
    /// (the same candidates as the tree's but for ties).
    fn closest_points_by_scan(&self, queries: &[Point3]) -> Result<Vec<ClosestPoint>> {
        for &q in queries {
            check_query(q)?;
        }
        let seeds = self.seed_positions()?;
        let k = self.params.candidates.clamp(1, seeds.len().max(1));
        queries
            .iter()
            .map(|&q| {
                // The k nearest seeds, nearest first.
                let mut near: Vec<(Real, usize)> = Vec::with_capacity(k + 1);
                for (i, x) in seeds.iter().enumerate() {
                    let d = (x - q).norm_squared();
                    if near.len() < k || d < near[k - 1].0 {
                        let at = near.partition_point(|e| e.0 <= d);
                        near.insert(at, (d, i));
                        near.truncate(k);
                    }
                }
                self.best_descent(q, near.iter().map(|&(_, i)| self.seeds[i]))
                    .map(|(c, _)| c)
            })
            .collect()
    }

    /// Projected Newton descent from `(f, st)`, crossing into neighbouring
    /// patches; false when it was still moving after the last iteration.
    fn descend(
        &self,
        q: Point3,
        mut f: usize,
        mut st: [Real; 2],
    ) -> Result<(usize, [Real; 2], PatchPoint, bool)> {
        let mut e = self.table.eval(f, st)?;
        let mut crossings = 0;
        let tol = self.params.tolerance;
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
            let Some(mut step) = step else {
                return Ok((f, st, e, true));
            };
            // On a true boundary (no patch across), slide along it: drop the
            // blocked component and take the 1-D Newton step along the edge.
            for i in 0..2 {
                let outward = (st[i] <= 0.0 && step[i] < 0.0) || (st[i] >= 1.0 && step[i] > 0.0);
                let side = match (i, step[i] < 0.0) {
                    (0, true) => 3,
                    (0, false) => 1,
                    (_, true) => 0,
                    (_, false) => 2,
                };
                if outward && self.across(f, side, st).is_none() {
                    let j = 1 - i;
                    let (hn, hg) = if j == 0 {
                        (nh[0], gn[0])
                    } else {
                        (nh[2], gn[2])
                    };
                    let h = if hn > 0.0 { hn } else { hg };
                    step[i] = 0.0;
                    step[j] = if h > 0.0 { -g[j] / h } else { 0.0 };
                }
            }
            if step == [0.0, 0.0] {
                return Ok((f, st, e, true));
            }
            // A step shorter than the tolerance would move the point by
            // less than that (the distance, stationary here, by its square):
            // settled without evaluating there.
            let len = (step[0] * step[0] + step[1] * step[1]).sqrt();
            if len < tol {
                return Ok((f, st, e, true));
            }
            // Limit the step to half a patch.
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
                let ce = self.table.eval(f, cand)?;
                if (ce.p - q).norm_squared() <= d0 {
                    accepted = Some((cand, ce, a));
                    break;
                }
                a *= 0.5;
            }
            let Some((cand, ce, a)) = accepted else {
                return Ok((f, st, e, true));
            };
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
                e = self.table.eval(f, st)?;
                crossings += 1;
                continue;
            }
            if moved < tol {
                return Ok((f, st, e, true));
            }
        }
        Ok((f, st, e, false))
    }

    /// The same surface point seen from the patch across edge `k` of patch `f`.
    fn across(&self, f: usize, k: usize, st: [Real; 2]) -> Option<(usize, [Real; 2])> {
        let l = self.table.level();
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

fn check_query(q: Point3) -> Result<()> {
    if q.coords.iter().all(|c| c.is_finite()) {
        Ok(())
    } else {
        Err(Error::non_finite(format!(
            "query point ({}, {}, {}) is not finite",
            q.x, q.y, q.z
        )))
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
