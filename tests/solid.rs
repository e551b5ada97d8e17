//! Dynamic subdivision solids: rest, momentum, energy decay, make plastic,
//! stability of the implicit integrator against the explicit one, fixed
//! points, extrude/trim round trips and bad input.

use subdyn::lattice::{Lattice, box_grid};
use subdyn::math::{Point3, Real, Vector3};
use subdyn::solid::{Solid, SolidParams, Stiffness, extrude_face, trim_cell};

fn cube() -> Lattice {
    box_grid(
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(1.0, 1.0, 1.0),
        [2, 2, 2],
    )
    .unwrap()
}

fn solid(level: usize, damping: Real) -> Solid {
    let params = SolidParams {
        level,
        damping,
        ..SolidParams::default()
    };
    Solid::new(&cube(), params).unwrap()
}

/// A deterministic deformation of the cube's control points (a shear and a
/// bulge) with a small velocity field, so that springs are stretched and
/// the solid moves.
fn perturb(s: &mut Solid, amount: Real) {
    let p: Vec<Point3> = s
        .control_points()
        .iter()
        .map(|q| {
            Point3::new(
                q.x + amount * q.z * q.y,
                q.y - amount * 0.5 * q.x,
                q.z + amount * (q.x - 0.5) * (q.y - 0.5),
            )
        })
        .collect();
    let v: Vec<Vector3> = s
        .control_points()
        .iter()
        .map(|q| Vector3::new(q.y - 0.5, 0.3 * q.z, -(q.x - 0.5)) * amount)
        .collect();
    s.set_state(&p, &v).unwrap();
}

fn max_move(a: &[Point3], b: &[Point3]) -> Real {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).norm())
        .fold(0.0, Real::max)
}

#[test]
fn without_forces_the_solid_stays_at_rest() {
    let mut s = solid(2, 2.0);
    let d0 = s.mass_points().to_vec();
    assert_eq!(d0.len(), 729);
    assert!(s.spring_energy() < 1e-20);
    for _ in 0..50 {
        s.step_explicit(1e-3).unwrap();
    }
    for _ in 0..10 {
        s.step_implicit(1e-2).unwrap();
    }
    assert!(max_move(&d0, s.mass_points()) < 1e-13);
    assert!(s.kinetic_energy() < 1e-24);
}

#[test]
fn momentum_is_conserved_without_damping_and_fixed_points() {
    let mut s = solid(2, 0.0);
    perturb(&mut s, 0.2);
    let m0 = s.momentum();
    assert!(m0.norm() > 1e-2, "the test needs a moving solid");
    assert!(s.spring_energy() > 1e-2);
    for _ in 0..200 {
        s.step_explicit(2e-3).unwrap();
    }
    assert!(
        (s.momentum() - m0).norm() < 1e-10 * m0.norm(),
        "{:?} vs {m0:?}",
        s.momentum()
    );
    for _ in 0..20 {
        s.step_implicit(1e-2).unwrap();
    }
    // CG stops at a relative residual of 1e-8.
    assert!(
        (s.momentum() - m0).norm() < 1e-6 * m0.norm(),
        "{:?} vs {m0:?}",
        s.momentum()
    );
    // A rope is an external force: momentum changes.
    let far = s.nearest_mass_point(&Point3::new(1.0, 1.0, 1.0));
    s.add_rope(far, Point3::new(3.0, 1.0, 1.0), 50.0, 0.0)
        .unwrap();
    s.step_explicit(2e-3).unwrap();
    assert!((s.momentum() - m0).norm() > 1e-3 * m0.norm());
}

#[test]
fn energy_decays_with_damping() {
    for implicit in [false, true] {
        let mut s = solid(2, 4.0);
        perturb(&mut s, 0.2);
        let e0 = s.energy();
        let mut worst: Real = 0.0;
        for _ in 0..150 {
            if implicit {
                s.step_implicit(1e-2).unwrap();
            } else {
                for _ in 0..5 {
                    s.step_explicit(2e-3).unwrap();
                }
            }
            worst = worst.max(s.energy());
        }
        let e1 = s.energy();
        assert!(
            worst <= e0 * (1.0 + 1e-9),
            "implicit {implicit}: energy rose from {e0} to {worst}"
        );
        assert!(
            e1 < 0.05 * e0,
            "implicit {implicit}: energy {e1} after 1.5 s (start {e0})"
        );
    }
}

#[test]
fn after_make_plastic_the_deformed_shape_is_at_rest() {
    let mut s = solid(2, 2.0);
    let d0 = s.mass_points().to_vec();
    let corner = s.nearest_mass_point(&Point3::new(1.0, 1.0, 1.0));
    s.add_rope(corner, Point3::new(1.6, 1.4, 1.5), 80.0, 0.0)
        .unwrap();
    for _ in 0..100 {
        s.step_implicit(1e-2).unwrap();
    }
    s.release_ropes();
    let deformed = s.mass_points().to_vec();
    assert!(
        max_move(&d0, &deformed) > 0.05,
        "the rope did not deform the cube"
    );
    s.make_plastic().unwrap();
    s.halt();
    assert!(s.spring_energy() < 1e-24);
    for _ in 0..50 {
        s.step_explicit(2e-3).unwrap();
        s.step_implicit(1e-2).unwrap();
    }
    assert!(max_move(&deformed, s.mass_points()) < 1e-13);
    // Without make plastic the same deformation springs back.
    let mut t = solid(2, 2.0);
    t.add_rope(corner, Point3::new(1.6, 1.4, 1.5), 80.0, 0.0)
        .unwrap();
    for _ in 0..100 {
        t.step_implicit(1e-2).unwrap();
    }
    t.release_ropes();
    t.halt();
    let before = t.mass_points().to_vec();
    for _ in 0..10 {
        t.step_implicit(1e-2).unwrap();
    }
    assert!(max_move(&before, t.mass_points()) > 1e-3);
}

/// Largest spring energy over `steps` explicit steps from a perturbed,
/// undamped cube, relative to the start (infinite when it blew up).
fn explicit_growth(h: Real, steps: usize) -> Real {
    let mut s = solid(2, 0.0);
    perturb(&mut s, 0.05);
    let e0 = s.energy();
    let mut worst: Real = 1.0;
    for _ in 0..steps {
        if s.step_explicit(h).is_err() {
            return Real::INFINITY;
        }
        let e = s.energy();
        if !e.is_finite() {
            return Real::INFINITY;
        }
        worst = worst.max(e / e0);
    }
    worst
}

#[test]
fn implicit_is_stable_at_ten_times_the_largest_stable_explicit_step() {
    // Bisection (in log scale) for the largest explicit step whose energy
    // stays within twice its start over 300 undamped steps.
    let stable = |h: Real| explicit_growth(h, 300) < 2.0;
    let (mut lo, mut hi) = (1e-4, 1.0);
    assert!(stable(lo) && !stable(hi));
    for _ in 0..14 {
        let mid = (lo * hi).sqrt();
        if stable(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let h_max = lo;
    eprintln!("largest stable explicit step on the level-2 cube: {h_max:.4e} s");
    assert!(hi / lo < 1.01);
    // Both sides: a bit above the threshold the explicit integrator blows up.
    assert!(explicit_growth(1.3 * h_max, 300) > 10.0);
    assert!(explicit_growth(0.7 * h_max, 600) < 1.5);
    // The implicit integrator at 10× (and 100×) that step: energy never grows.
    for factor in [10.0, 100.0] {
        let mut s = solid(2, 0.0);
        perturb(&mut s, 0.05);
        let e0 = s.energy();
        for _ in 0..100 {
            s.step_implicit(factor * h_max).unwrap();
            assert!(
                s.energy() <= e0 * (1.0 + 1e-9),
                "implicit at {factor}×{h_max:.2e} gained energy"
            );
        }
    }
}

#[test]
fn fixed_control_points_do_not_move() {
    let mut s = solid(1, 2.0);
    let left: Vec<usize> = (0..s.control_points().len())
        .filter(|&i| s.control_points()[i].x < 0.1)
        .collect();
    assert_eq!(left.len(), 9);
    s.set_fixed(&left, true).unwrap();
    let p0 = s.control_points().to_vec();
    let corner = s.nearest_mass_point(&Point3::new(1.0, 1.0, 1.0));
    s.add_rope(corner, Point3::new(1.5, 1.5, 1.0), 50.0, 0.0)
        .unwrap();
    for _ in 0..40 {
        s.step_implicit(1e-2).unwrap();
        s.step_explicit(1e-3).unwrap();
    }
    for &i in &left {
        assert_eq!(s.control_points()[i], p0[i]);
    }
    assert!(max_move(&p0, s.control_points()) > 0.05);
    s.set_fixed(&left, false).unwrap();
    s.step_implicit(1e-2).unwrap();
    assert!(left.iter().any(|&i| s.control_points()[i] != p0[i]));
}

#[test]
fn extrude_then_trim_gives_back_the_topology() {
    let lat = cube();
    let top = (0..lat.topology.num_faces())
        .find(|&f| {
            lat.topology.is_boundary_face(f)
                && lat
                    .topology
                    .faces
                    .row(f)
                    .iter()
                    .all(|&v| lat.positions[v as usize].z > 0.99)
        })
        .unwrap();
    let ext = extrude_face(&lat, top).unwrap();
    assert_eq!(ext.topology.num_cells(), 9);
    assert_eq!(ext.num_vertices(), 31);
    // The new cell sits on top, as tall as the cell under it.
    let zmax = ext.positions.iter().map(|p| p.z).fold(0.0, Real::max);
    assert!((zmax - 1.5).abs() < 1e-12);
    let back = trim_cell(&ext, 8).unwrap();
    assert_eq!(back.topology, lat.topology);
    assert_eq!(back.positions, lat.positions);
    assert_eq!(back.tags, lat.tags);

    // The same on a solid: counts change and come back.
    let mut s = solid(1, 2.0);
    let n_mass = s.mass_points().len();
    s.extrude(top).unwrap();
    assert_eq!(s.control_points().len(), 31);
    assert!(s.mass_points().len() > n_mass);
    assert!(s.spring_energy() < 1e-20, "an extruded cell starts at rest");
    s.trim(8).unwrap();
    assert_eq!(s.control_lattice().topology, lat.topology);
    assert_eq!(s.mass_points().len(), n_mass);
    // Trimming a corner cell of the cube keeps a connected lattice.
    s.trim(0).unwrap();
    assert_eq!(s.control_lattice().topology.num_cells(), 7);
    assert_eq!(s.control_points().len(), 26);
}

#[test]
fn bad_input_is_an_error() {
    let mut s = solid(1, 2.0);
    assert!(s.step_explicit(Real::NAN).is_err());
    assert!(s.step_implicit(-1.0).is_err());
    assert!(s.add_rope(1_000_000, Point3::origin(), 1.0, 0.0).is_err());
    assert!(
        s.add_rope(0, Point3::new(Real::NAN, 0.0, 0.0), 1.0, 0.0)
            .is_err()
    );
    assert!(s.set_fixed(&[27], true).is_err());
    assert!(s.set_damping(-1.0).is_err());
    assert!(
        s.set_stiffness(Stiffness {
            edge: Real::INFINITY,
            virtual_: 1.0
        })
        .is_err()
    );
    let interior = (0..36)
        .find(|&f| !s.control_lattice().topology.is_boundary_face(f))
        .unwrap();
    assert!(s.extrude(interior).is_err());
    assert!(s.trim(8).is_err());
    let params = SolidParams {
        level: 9,
        ..SolidParams::default()
    };
    assert!(Solid::new(&cube(), params).is_err());
    let one = box_grid(Point3::origin(), Point3::new(1.0, 1.0, 1.0), [1, 1, 1]).unwrap();
    let mut t = Solid::new(&one, SolidParams::default()).unwrap();
    assert!(t.trim(0).is_err());
    // An explicit step far too large blows up and is then reported, not hidden.
    let mut u = solid(1, 0.0);
    perturb(&mut u, 0.1);
    let mut failed = false;
    for _ in 0..2000 {
        if u.step_explicit(1.0).is_err() {
            failed = true;
            break;
        }
    }
    assert!(failed);
}
