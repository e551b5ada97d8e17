//! Implicit time integration of dynamic surfaces (`SurfaceDynamics`) and the
//! sparse Cholesky solver of steps that reuse their matrix.

mod common;

use common::{default_refiner, mixed_mesh, refined_cube};
use subdyn::dynamics::{
    LinearSolver, MaterialParams, PcgParams, SparseCholesky, SurfaceDynamics, patch_damping_matrix,
    patch_stiffness_matrix, pcg,
};
use subdyn::forces::drag_spring;
use subdyn::limit::{ClosestPoint, ClosestPointEngine, ClosestPointParams};
use subdyn::math::{Point3, Real, Vector3};
use subdyn::mesh::PolyMesh;
use subdyn::stencil::StencilTable;

fn engine(mesh: &PolyMesh) -> ClosestPointEngine {
    ClosestPointEngine::new(
        &default_refiner(mesh),
        &mesh.positions,
        &ClosestPointParams::default(),
    )
    .unwrap()
}

fn material(mu: Real) -> MaterialParams {
    MaterialParams {
        mu,
        gamma: 1.0,
        ..MaterialParams::thin_plate(1e-2, 1e-3, 1.0)
    }
}

/// `M/Δt² + D/Δt + K` of `mesh` plus a drag spring at the closest point to
/// `pick`: a step's matrix.
fn step_matrix(mesh: &PolyMesh, pick: Point3) -> StencilTable {
    let e = engine(mesh);
    let (table, m) = (e.table(), material(0.5));
    let mass = patch_damping_matrix(table, 4, m.mu).unwrap();
    let damping = patch_damping_matrix(table, 4, m.gamma).unwrap();
    let k = patch_stiffness_matrix(table, 4, &m).unwrap();
    let at = e.closest_points(&[pick]).unwrap()[0];
    let spring = drag_spring(&e, &at, pick, 10.0).unwrap().matrix;
    let dt = 0.1;
    k.linear_combination(1.0, &damping, 1.0 / dt)
        .unwrap()
        .linear_combination(1.0, &mass, 1.0 / (dt * dt))
        .unwrap()
        .linear_combination(1.0, &spring, 1.0)
        .unwrap()
}

fn right_hand_sides(n: usize) -> Vec<Point3> {
    (0..n)
        .map(|i| {
            let t = i as Real;
            Point3::new((0.37 * t).sin(), (1.3 * t).cos(), 1.0 - 0.01 * t)
        })
        .collect()
}

fn worst(a: &[Point3], b: &[Point3]) -> Real {
    a.iter()
        .zip(b)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, Real::max)
}

/// The factor solves the system to round-off and agrees with conjugate
/// gradients, on a closed mesh with extraordinary vertices and on a mesh of
/// triangles, quads and a pentagon with a boundary.
#[test]
fn cholesky_solves_step_systems() {
    for (name, mesh) in [("cube", refined_cube(2)), ("mixed", mixed_mesh())] {
        let a = step_matrix(&mesh, Point3::new(0.9, 0.2, 0.1));
        let n = a.num_rows();
        let b = right_hand_sides(n);
        let factor = SparseCholesky::new(&a).unwrap();
        assert!(factor.factor_entries() >= a.weights.len().div_ceil(2));
        let x = factor.solve(&b).unwrap();
        let residual = worst(&a.apply(&x).unwrap(), &b);
        let scale = b.iter().map(|b| b.coords.norm()).fold(0.0, Real::max);
        assert!(residual < 1e-11 * scale, "{name}: residual {residual:e}");
        let mut y = vec![Point3::origin(); n];
        let report = pcg(
            &a,
            &b,
            &mut y,
            &PcgParams {
                tolerance: 1e-13,
                ..Default::default()
            },
        )
        .unwrap();
        assert!(report.converged);
        let norm = x.iter().map(|x| x.coords.norm()).fold(0.0, Real::max);
        assert!(worst(&x, &y) < 1e-9 * norm, "{name}: {:e}", worst(&x, &y));
    }
}

/// Refactoring keeps the ordering for the same pattern and orders again for
/// another; an indefinite matrix is an error and keeps the previous factor.
#[test]
fn cholesky_refactors_and_rejects_indefinite_matrices() {
    let mesh = refined_cube(2);
    let a = step_matrix(&mesh, Point3::new(0.9, 0.2, 0.1));
    let b = right_hand_sides(a.num_rows());
    let mut factor = SparseCholesky::new(&a).unwrap();
    let x = factor.solve(&b).unwrap();
    let mut doubled = a.clone();
    doubled.weights.iter_mut().for_each(|w| *w *= 2.0);
    factor.refactor(&doubled).unwrap();
    let half: Vec<Point3> = x.iter().map(|x| Point3::from(x.coords / 2.0)).collect();
    assert!(worst(&factor.solve(&b).unwrap(), &half) < 1e-12);
    // Another pattern: another mesh.
    let other = step_matrix(&mixed_mesh(), Point3::new(0.3, 0.4, 0.4));
    let b = right_hand_sides(other.num_rows());
    factor.refactor(&other).unwrap();
    let z = factor.solve(&b).unwrap();
    assert!(worst(&other.apply(&z).unwrap(), &b) < 1e-10);
    let mut negated = other.clone();
    negated.weights.iter_mut().for_each(|w| *w = -*w);
    let err = factor.refactor(&negated).unwrap_err().to_string();
    assert!(err.contains("not positive definite"), "{err}");
    assert!(SparseCholesky::new(&negated).is_err());
    assert!(worst(&factor.solve(&b).unwrap(), &z) == 0.0);
    let short = factor.solve(&b[1..]).unwrap_err().to_string();
    assert!(short.contains("right-hand sides"), "{short}");
}

/// A drag: the surface point closest to `pick` pulled by a spring towards a
/// target that moves with the step.
struct Drag {
    engine: ClosestPointEngine,
    at: ClosestPoint,
    start: Point3,
}

impl Drag {
    fn new(mesh: &PolyMesh, pick: Point3) -> Drag {
        let engine = engine(mesh);
        let at = engine.closest_points(&[pick]).unwrap()[0];
        let start = at.point;
        Drag { engine, at, start }
    }

    /// The spring's stiffness and load with the target at `start + offset`.
    fn spring(&self, offset: Vector3) -> (StencilTable, Vec<Point3>) {
        let s = drag_spring(&self.engine, &self.at, self.start + offset, 5.0).unwrap();
        (s.matrix, s.rhs)
    }
}

fn dynamics(mesh: &PolyMesh, drag: &Drag, mu: Real, solver: LinearSolver) -> SurfaceDynamics {
    SurfaceDynamics::on_patches(
        drag.engine.table(),
        mesh.positions.clone(),
        &[material(mu)],
        4,
        0.05,
        solver,
    )
    .unwrap()
}

const PCG: LinearSolver = LinearSolver::Pcg(PcgParams {
    tolerance: 1e-13,
    max_iterations: 0,
});

/// Massless (first-order) steps: the energy never rises, Cholesky and
/// conjugate gradients take the same steps, and the factor is made once per
/// spring attachment, not once per step.
#[test]
fn massless_steps_dissipate_and_reuse_the_factor() {
    let mesh = refined_cube(2);
    let drag = Drag::new(&mesh, Point3::new(0.9, 0.3, 0.2));
    let mut chol = dynamics(&mesh, &drag, 0.0, LinearSolver::Cholesky);
    let mut cg = dynamics(&mesh, &drag, 0.0, PCG);
    let (s, f) = drag.spring(Vector3::new(0.4, 0.1, 0.0));
    let mut before = chol.energy(Some(&s), &f).unwrap();
    for step in 0..25 {
        let r = chol.step(Some(&s), &f).unwrap();
        let q = cg.step(Some(&s), &f).unwrap();
        assert_eq!(r.factored, step == 0);
        assert!(q.cg_iterations > 0 && r.cg_iterations == 0);
        assert!(
            r.energy <= before + 1e-12 * before.abs(),
            "step {step}: energy rose from {before} to {}",
            r.energy
        );
        assert!(worst(chol.positions(), cg.positions()) < 1e-9);
        before = r.energy;
    }
    assert_eq!(chol.factorizations(), 1);
    // The target moves: the same matrix, another load.
    let (s2, f2) = drag.spring(Vector3::new(0.5, 0.3, 0.1));
    assert_eq!(s2.weights, s.weights);
    for _ in 0..5 {
        chol.step(Some(&s2), &f2).unwrap();
        cg.step(Some(&s2), &f2).unwrap();
    }
    assert_eq!(chol.factorizations(), 1);
    assert!(worst(chol.positions(), cg.positions()) < 1e-9);
    // Let go: another matrix.
    let zero = vec![Point3::origin(); mesh.num_vertices()];
    chol.step(None, &zero).unwrap();
    assert_eq!(chol.factorizations(), 2);
    // Near equilibrium the relative change falls below any tolerance.
    let mut last = 1.0;
    for _ in 0..200 {
        last = chol.step(Some(&s2), &f2).unwrap().relative_change;
    }
    assert!(last < 1e-5, "not settled: {last:e}");
    let dragged = drag
        .engine
        .table()
        .to_level()
        .apply(chol.positions())
        .unwrap();
    assert!(
        dragged
            .iter()
            .any(|x| x.x > mesh.positions.iter().map(|p| p.x).fold(0.0, Real::max))
    );
}

/// With a mass (the paper's second-order dynamics) the kinetic plus
/// potential energy never rises either, and the surface overshoots its
/// equilibrium by more than half the way there before it settles; the
/// massless surface by less than a tenth.
#[test]
fn second_order_steps_dissipate_and_overshoot() {
    let mesh = refined_cube(2);
    let drag = Drag::new(&mesh, Point3::new(0.9, 0.3, 0.2));
    let (s, f) = drag.spring(Vector3::new(0.3, 0.0, 0.0));
    let probe = |d: &SurfaceDynamics| {
        let x = drag.engine.table().to_level().apply(d.positions()).unwrap();
        x.iter().map(|p| p.x).fold(Real::MIN, Real::max)
    };
    // The farthest point of the surface along the drag, at rest and after
    // a long massless run (the equilibrium).
    let mut rest = dynamics(&mesh, &drag, 0.0, LinearSolver::Cholesky);
    let start = probe(&rest);
    for _ in 0..400 {
        rest.step(Some(&s), &f).unwrap();
    }
    let equilibrium = probe(&rest);
    let mut heavy = dynamics(&mesh, &drag, 50.0, LinearSolver::Cholesky);
    let mut cg = dynamics(&mesh, &drag, 50.0, PCG);
    let mut before = heavy.energy(Some(&s), &f).unwrap();
    let mut peak = Real::MIN;
    for step in 0..200 {
        let r = heavy.step(Some(&s), &f).unwrap();
        cg.step(Some(&s), &f).unwrap();
        assert!(
            r.energy <= before + 1e-12 * before.abs(),
            "step {step}: energy rose from {before} to {}",
            r.energy
        );
        before = r.energy;
        peak = peak.max(probe(&heavy));
    }
    assert_eq!(heavy.factorizations(), 1);
    let gap = worst(heavy.positions(), cg.positions());
    assert!(gap < 1e-6, "Cholesky and CG {gap:e} apart");
    let reach = equilibrium - start;
    assert!(reach > 0.1, "the drag moved the surface by {reach}");
    assert!(
        peak > equilibrium + 0.5 * reach,
        "no overshoot: peak {peak}, equilibrium {equilibrium}, start {start}"
    );
    let mut light = dynamics(&mesh, &drag, 0.0, LinearSolver::Cholesky);
    let mut light_peak = Real::MIN;
    for _ in 0..200 {
        light.step(Some(&s), &f).unwrap();
        light_peak = light_peak.max(probe(&light));
    }
    assert!(
        light_peak < equilibrium + 0.1 * reach,
        "massless peak {light_peak}, equilibrium {equilibrium}, start {start}"
    );
}

#[test]
fn bad_dynamics_input_is_an_error() {
    let mesh = refined_cube(2);
    let drag = Drag::new(&mesh, Point3::new(0.9, 0.3, 0.2));
    let e = drag.engine.table();
    let m = material(0.0);
    let d = patch_damping_matrix(e, 4, 1.0).unwrap();
    let k = patch_stiffness_matrix(e, 4, &m).unwrap();
    let p = mesh.positions.clone();
    let err = |r: Result<SurfaceDynamics, subdyn::error::Error>| r.unwrap_err().to_string();
    let new = |dt: Real, p: Vec<Point3>| {
        SurfaceDynamics::new(None, d.clone(), k.clone(), p, dt, LinearSolver::Cholesky)
    };
    assert!(err(new(0.0, p.clone())).contains("time step"));
    assert!(err(new(Real::NAN, p.clone())).contains("time step"));
    assert!(err(new(0.1, p[1..].to_vec())).contains("98 × 98 for 97"));
    let mut nan = p.clone();
    nan[3].y = Real::NAN;
    assert!(err(new(0.1, nan)).contains("control point 3"));
    let mut ok = new(0.1, p.clone()).unwrap();
    let mut load = vec![Point3::origin(); p.len()];
    assert!(
        ok.step(None, &load[1..])
            .unwrap_err()
            .to_string()
            .contains("a load of 97")
    );
    load[5].z = Real::INFINITY;
    assert!(
        ok.step(None, &load)
            .unwrap_err()
            .to_string()
            .contains("control point 5")
    );
    assert_eq!(ok.positions(), &p[..]);
}
