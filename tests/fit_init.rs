//! Integration tests of `subdyn::fit::init`: the initial control mesh built
//! from a point cloud. Synthetic clouds (sphere, torus, two fused tori, a
//! one-sided height field) check the chosen method, closedness, genus and
//! manifoldness; the Stanford range view `bun045.ply` (when `../shared` is
//! present) checks the open-scan detection; bad inputs give `Error::Input`.

use std::f64::consts::TAU;
use std::path::Path;
use std::time::Instant;

use subdyn::Error;
use subdyn::fit::init::{
    InitKind, InitParams, PrincipalFrame, closedness, initial_mesh, signed_volume, surface_topology,
};
use subdyn::math::{Point3, Real, Vector3};
use subdyn::mesh::{PointCloud, PolyMesh};
use subdyn::topology::Level;

/// A small deterministic generator (SplitMix64) so the clouds are reproducible.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> Real {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as Real / (1u64 << 53) as Real
    }

    /// Uniform in `[a, b)`.
    fn range(&mut self, a: Real, b: Real) -> Real {
        a + (b - a) * self.next()
    }

    /// A uniformly distributed unit vector.
    fn unit(&mut self) -> Vector3 {
        let z = self.range(-1.0, 1.0);
        let phi = self.range(0.0, TAU);
        let r = (1.0 - z * z).sqrt();
        Vector3::new(r * phi.cos(), r * phi.sin(), z)
    }
}

/// `n` points uniformly on the sphere of radius `r` about `c`.
fn sphere(n: usize, c: Point3, r: Real, seed: u64) -> Vec<Point3> {
    let mut rng = Rng(seed);
    (0..n).map(|_| c + rng.unit() * r).collect()
}

/// A point uniformly distributed (by area) on the torus of radii `big`, `small`
/// about the z axis, by rejection on the tube angle.
fn torus_point(rng: &mut Rng, big: Real, small: Real) -> Point3 {
    loop {
        let (a, b) = (rng.range(0.0, TAU), rng.range(0.0, TAU));
        if rng.range(0.0, big + small) <= big + small * b.cos() {
            let rho = big + small * b.cos();
            return Point3::new(rho * a.cos(), rho * a.sin(), small * b.sin());
        }
    }
}

/// True when `p` is inside the solid torus of radii `big`, `small` centred at `c`.
fn inside_torus(p: &Point3, c: &Point3, big: Real, small: Real) -> bool {
    let d = p - c;
    let rho = (d.x * d.x + d.y * d.y).sqrt();
    (rho - big).powi(2) + d.z * d.z < small * small
}

/// Rotation by `angle` about the unit axis `axis`.
fn rotate(points: &mut [Point3], axis: Vector3, angle: Real) {
    let r = nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle);
    for p in points {
        *p = r * *p;
    }
}

/// A torus (radii 1 and 0.35), tilted so its axis is no coordinate axis.
fn torus_cloud(n: usize, seed: u64) -> Vec<Point3> {
    let mut rng = Rng(seed);
    let mut pts: Vec<Point3> = (0..n).map(|_| torus_point(&mut rng, 1.0, 0.35)).collect();
    rotate(&mut pts, Vector3::new(1.0, 2.0, 0.5), 0.7);
    pts
}

/// Two tori (radii 1 and 0.35) side by side whose tubes overlap: the surface
/// of their union, a genus-2 solid. Points inside the other torus are dropped.
fn double_torus_cloud(n: usize, seed: u64) -> Vec<Point3> {
    let mut rng = Rng(seed);
    let centres = [Point3::new(-0.9, 0.0, 0.0), Point3::new(0.9, 0.0, 0.0)];
    let mut pts = Vec::with_capacity(n);
    while pts.len() < n {
        let which = pts.len() % 2;
        let p = centres[which] + torus_point(&mut rng, 1.0, 0.35).coords;
        if !inside_torus(&p, &centres[1 - which], 1.0, 0.35) {
            pts.push(p);
        }
    }
    rotate(&mut pts, Vector3::new(0.3, -1.0, 0.2), 0.4);
    pts
}

/// A one-sided height field `z = 0.25 sin(2x) cos(3y)` over `[−1, 1] × [−0.7, 0.7]`,
/// as one range view sees it.
fn height_field(n: usize, seed: u64) -> Vec<Point3> {
    let mut rng = Rng(seed);
    (0..n)
        .map(|_| {
            let (x, y) = (rng.range(-1.0, 1.0), rng.range(-0.7, 0.7));
            Point3::new(x, y, 0.25 * (2.0 * x).sin() * (3.0 * y).cos())
        })
        .collect()
}

fn cloud(points: Vec<Point3>) -> PointCloud {
    PointCloud {
        positions: points,
        normals: None,
    }
}

/// Runs `initial_mesh` with `params`, prints the report and timing, and checks
/// what every cage must satisfy: a manifold quad mesh `Level::from_mesh` accepts.
fn build(
    name: &str,
    points: &[Point3],
    params: &InitParams,
) -> (PolyMesh, subdyn::fit::init::InitReport) {
    let t = Instant::now();
    let (mesh, report) = initial_mesh(&cloud(points.to_vec()), params).expect("initial mesh");
    eprintln!(
        "{name}: {} points, {:?} in {:.1} ms: {} V, {} F, genus {:?} — {}",
        points.len(),
        report.chosen,
        t.elapsed().as_secs_f64() * 1e3,
        report.vertices,
        report.faces,
        report.genus,
        report.reason
    );
    assert_ne!(report.chosen, InitKind::Auto);
    assert!(
        Level::from_mesh(&mesh).is_ok(),
        "{name}: cage is not manifold"
    );
    assert!(mesh.faces().all(|f| f.len() == 4), "{name}: not all quads");
    assert_eq!(
        (report.vertices, report.faces),
        (mesh.num_vertices(), mesh.num_faces())
    );
    (mesh, report)
}

/// Asserts a closed, outward-oriented cage of the given genus without folds.
fn assert_closed(name: &str, mesh: &PolyMesh, genus: i64) {
    assert_closed_topology(name, mesh, genus);
    assert_eq!(folds(mesh), 0, "{name}: folded edges");
}

/// Asserts a closed, outward-oriented cage of the given genus.
fn assert_closed_topology(name: &str, mesh: &PolyMesh, genus: i64) {
    let t = surface_topology(mesh).expect("topology");
    assert_eq!(t.boundary_loops, 0, "{name}: has a boundary");
    assert_eq!(t.components, 1, "{name}: components");
    assert_eq!(t.genus, genus, "{name}: genus");
    assert!(signed_volume(mesh) > 0.0, "{name}: not outward");
}

/// Edges whose two faces' normals (cross products of the quad diagonals)
/// differ by more than 120°: a smoothing or snapping step turned a face over.
fn folds(mesh: &PolyMesh) -> usize {
    let level = Level::from_mesh(mesh).expect("manifold");
    let normal = |f: usize| {
        let v = mesh.face(f);
        let [a, b, c, d] = [v[0], v[1], v[2], v[3]].map(|i| mesh.positions[i as usize]);
        (c - a).cross(&(d - b)).normalize()
    };
    level
        .edge_faces
        .iter()
        .enumerate()
        .filter(|&(e, f)| {
            !level.is_boundary_edge(e) && normal(f[0] as usize).dot(&normal(f[1] as usize)) < -0.5
        })
        .count()
}

#[test]
fn sphere_gives_the_ellipsoid_cage() {
    let (c, r) = (Point3::new(1.0, 2.0, 3.0), 2.0);
    let pts = sphere(3000, c, r, 1);
    let (_, auto) = build("sphere auto", &pts, &InitParams::default());
    assert_eq!((auto.chosen, auto.genus), (InitKind::Occupancy, Some(0)));
    let (mesh, report) = build(
        "sphere",
        &pts,
        &InitParams {
            kind: InitKind::Closed,
            ..Default::default()
        },
    );
    assert_eq!(report.chosen, InitKind::Closed);
    assert_eq!((mesh.num_vertices(), mesh.num_faces()), (26, 24));
    assert_eq!(report.genus, Some(0));
    assert_closed("sphere", &mesh, 0);
    // Control points on the sphere of the data (the extents of a sampled
    // sphere fall short of 2r by a little, and the centre moves by as much).
    for p in &mesh.positions {
        let d = (p - c).norm();
        assert!(
            (d - r).abs() < 0.03 * r,
            "cage vertex at distance {d} from the centre, radius {r}"
        );
    }
}

#[test]
fn closed_cage_follows_the_principal_axes() {
    // An ellipsoid with semi-axes 3, 2, 1, rotated: the cage's vertices lie on it.
    let mut rng = Rng(7);
    let mut pts: Vec<Point3> = (0..4000)
        .map(|_| {
            let u = rng.unit();
            Point3::new(3.0 * u.x, 2.0 * u.y, u.z)
        })
        .collect();
    let axis = Vector3::new(1.0, 1.0, 0.0);
    rotate(&mut pts, axis, 0.9);
    let params = InitParams {
        kind: InitKind::Closed,
        ..Default::default()
    };
    let (mesh, report) = build("ellipsoid", &pts, &params);
    assert_eq!(report.chosen, InitKind::Closed);
    assert_closed("ellipsoid", &mesh, 0);
    let back = nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), -0.9);
    for p in &mesh.positions {
        let q = back * p;
        let level = (q.x / 3.0).powi(2) + (q.y / 2.0).powi(2) + q.z.powi(2);
        assert!(
            (level - 1.0).abs() < 0.05,
            "cage vertex {q} off the ellipsoid: {level}"
        );
    }
    // The same cloud through Auto is closed and genus 0 too.
    let (_, auto) = build("ellipsoid auto", &pts, &InitParams::default());
    assert_eq!((auto.chosen, auto.genus), (InitKind::Occupancy, Some(0)));
}

#[test]
fn torus_gives_a_genus_one_occupancy_cage() {
    let pts = torus_cloud(6000, 2);
    let (mesh, report) = build("torus", &pts, &InitParams::default());
    assert_eq!(report.chosen, InitKind::Occupancy);
    assert_eq!(report.genus, Some(1));
    assert_closed("torus", &mesh, 1);
    // The cage surrounds the tube: every vertex within a voxel or so of the torus surface.
    let frame = PrincipalFrame::from_points(&pts).expect("frame");
    let voxel = frame.extents()[0] / 12.0;
    let back = nalgebra::Rotation3::from_axis_angle(
        &nalgebra::Unit::new_normalize(Vector3::new(1.0, 2.0, 0.5)),
        -0.7,
    );
    for p in &mesh.positions {
        let q = back * p;
        let rho = (q.x * q.x + q.y * q.y).sqrt();
        let dist = ((rho - 1.0).powi(2) + q.z * q.z).sqrt() - 0.35;
        assert!(
            dist.abs() < 1.5 * voxel,
            "cage vertex {dist} from the torus (voxel {voxel})"
        );
    }
}

#[test]
fn fused_tori_give_genus_two() {
    let pts = double_torus_cloud(10000, 3);
    let (mesh, report) = build("two tori", &pts, &InitParams::default());
    assert_eq!(report.chosen, InitKind::Occupancy);
    assert_eq!(report.genus, Some(2));
    assert_closed("two tori", &mesh, 2);
}

#[test]
fn occupancy_of_a_sphere_is_a_closed_genus_zero_cage() {
    let pts = sphere(3000, Point3::origin(), 1.0, 4);
    let params = InitParams {
        kind: InitKind::Occupancy,
        ..Default::default()
    };
    let (mesh, report) = build("sphere occupancy", &pts, &params);
    assert_eq!(report.chosen, InitKind::Occupancy);
    assert_closed("sphere occupancy", &mesh, 0);
    // Smoothed voxel boundary snapped to the points: well within a voxel of
    // the sphere, and every face facing away from the centre.
    let voxel = 2.0 / 12.0;
    for p in &mesh.positions {
        let d = p.coords.norm() - 1.0;
        assert!(
            d.abs() < 0.5 * voxel,
            "occupancy vertex {d} from the sphere"
        );
    }
    for f in mesh.faces() {
        let [a, b, c, d] = [f[0], f[1], f[2], f[3]].map(|v| mesh.positions[v as usize]);
        let normal = (c - a).cross(&(d - b));
        assert!(
            normal.dot(&(a.coords + c.coords)) > 0.0,
            "a face points inwards"
        );
    }
}

#[test]
fn occupancy_closes_holes_in_the_coverage() {
    // A sphere scanned without its polar caps (|z| > 0.8 unseen): the plain
    // flood fill leaks through the two holes; the closing fallback seals them.
    let pts: Vec<Point3> = sphere(6000, Point3::origin(), 1.0, 17)
        .into_iter()
        .filter(|p| p.z.abs() < 0.8)
        .collect();
    let params = InitParams {
        kind: InitKind::Occupancy,
        ..Default::default()
    };
    let (mesh, report) = build("capless sphere", &pts, &params);
    assert!(report.reason.contains("closing 1") || report.reason.contains("closing 2"));
    assert_closed("capless sphere", &mesh, 0);
    let (_, auto) = build("capless sphere auto", &pts, &InitParams::default());
    assert_eq!((auto.chosen, auto.genus), (InitKind::Occupancy, Some(0)));
}

#[test]
fn outliers_do_not_change_the_genus() {
    // 5 % outliers, uniform in the bounding box enlarged by 10 % of its diagonal.
    let mut pts = torus_cloud(8000, 18);
    let (lo, hi) = subdyn::math::bounding_box(&pts).expect("points");
    let pad = 0.1 * (hi - lo).norm();
    let mut rng = Rng(19);
    for _ in 0..pts.len() / 19 {
        pts.push(Point3::new(
            rng.range(lo.x - pad, hi.x + pad),
            rng.range(lo.y - pad, hi.y + pad),
            rng.range(lo.z - pad, hi.z + pad),
        ));
    }
    let (mesh, report) = build("torus + 5 % outliers", &pts, &InitParams::default());
    assert!(report.reason.contains("outliers dropped"));
    assert_eq!(report.chosen, InitKind::Occupancy);
    assert_closed("torus + 5 % outliers", &mesh, 1);
    let mut sphere_pts = sphere(5000, Point3::origin(), 1.0, 20);
    for _ in 0..sphere_pts.len() / 19 {
        sphere_pts.push(Point3::new(
            rng.range(-1.3, 1.3),
            rng.range(-1.3, 1.3),
            rng.range(-1.3, 1.3),
        ));
    }
    let (mesh, report) = build(
        "sphere + 5 % outliers",
        &sphere_pts,
        &InitParams {
            kind: InitKind::Closed,
            ..Default::default()
        },
    );
    assert_eq!(report.chosen, InitKind::Closed);
    for p in &mesh.positions {
        let d = p.coords.norm();
        assert!(
            (d - 1.0).abs() < 0.05,
            "outliers stretched the ellipsoid: vertex at {d}"
        );
    }
}

#[test]
fn height_field_gives_an_open_grid() {
    let pts = height_field(5000, 5);
    let (mesh, report) = build("height field", &pts, &InitParams::default());
    assert_eq!(report.chosen, InitKind::Open);
    let t = surface_topology(&mesh).expect("topology");
    assert_eq!((t.components, t.boundary_loops, t.genus), (1, 1, 0));
    // 12 cells along x (length 2), ceil(1.4 / (2/12)) = 9 along y, all full.
    assert_eq!(mesh.num_faces(), 12 * 9);
    // Grid vertices lie near the height field (median of a 2h window).
    for p in &mesh.positions {
        let z = 0.25 * (2.0 * p.x).sin() * (3.0 * p.y).cos();
        assert!(
            (p.z - z).abs() < 0.08,
            "grid vertex {p} off the surface ({z})"
        );
    }
}

#[test]
fn open_grid_faces_the_bulge() {
    // A spherical cap seen from +z (z > 0.5 on the unit sphere): the scanner
    // is on +z, so face normals must point up.
    let mut rng = Rng(6);
    let pts: Vec<Point3> = std::iter::repeat_with(|| rng.unit())
        .filter(|u| u.z > 0.5)
        .take(3000)
        .map(Point3::from)
        .collect();
    let (mesh, report) = build("cap", &pts, &InitParams::default());
    assert_eq!(report.chosen, InitKind::Open);
    let mut up = 0.0;
    for f in mesh.faces() {
        let [a, b, c] = [f[0], f[1], f[2]].map(|v| mesh.positions[v as usize]);
        up += (b - a).cross(&(c - a)).z;
    }
    assert!(up > 0.0, "open cage faces away from the scanner");
    // Flipping the cloud upside down flips the cage.
    let flipped: Vec<Point3> = pts.iter().map(|p| Point3::new(p.x, -p.y, -p.z)).collect();
    let (mesh, _) = build("cap flipped", &flipped, &InitParams::default());
    let down: Real = mesh
        .faces()
        .map(|f| {
            let [a, b, c] = [f[0], f[1], f[2]].map(|v| mesh.positions[v as usize]);
            (b - a).cross(&(c - a)).z
        })
        .sum();
    assert!(down < 0.0);
}

#[test]
fn layered_fraction_separates_open_from_closed() {
    let cases: Vec<(&str, Vec<Point3>, bool)> = vec![
        ("sphere", sphere(3000, Point3::origin(), 1.0, 8), true),
        ("torus", torus_cloud(6000, 9), true),
        ("two tori", double_torus_cloud(10000, 10), true),
        ("height field", height_field(5000, 11), false),
    ];
    let threshold = InitParams::default().closed_threshold;
    for (name, pts, closed) in cases {
        let frame = PrincipalFrame::from_points(&pts).expect("frame");
        let c = closedness(&pts, &frame, threshold);
        eprintln!(
            "{name}: layered fraction {:.3} ({} columns)",
            c.layered_fraction, c.columns
        );
        assert_eq!(
            c.closed, closed,
            "{name}: layered fraction {}",
            c.layered_fraction
        );
    }
}

#[test]
#[cfg_attr(not(shared_data), ignore = "needs ../shared/data beside the clone")]
fn bunny_range_view_is_open() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data/scans/bun045.ply");
    let cloud = subdyn::io::read_points(&path).expect("read bun045");
    assert_eq!(cloud.len(), 40_097);
    let t = Instant::now();
    let (mesh, report) = initial_mesh(&cloud, &InitParams::default()).expect("bun045 init");
    eprintln!(
        "bun045: {:?} in {:.1} ms, {} V, {} F — {}",
        report.chosen,
        t.elapsed().as_secs_f64() * 1e3,
        report.vertices,
        report.faces,
        report.reason
    );
    assert_eq!(report.chosen, InitKind::Open);
    let frame = PrincipalFrame::from_points(&cloud.positions).expect("frame");
    let c = closedness(&cloud.positions, &frame, 0.3);
    assert!(
        c.layered_fraction < 0.05,
        "bun045 layered fraction {}",
        c.layered_fraction
    );
    // The scanner looks down −z in the range image's own frame: the cage faces +z.
    let up: Real = mesh
        .faces()
        .map(|f| {
            let [a, b, c, d] = [f[0], f[1], f[2], f[3]].map(|v| mesh.positions[v as usize]);
            (c - a).cross(&(d - b)).z
        })
        .sum();
    assert!(up > 0.0, "bun045 cage faces away from the scanner");
    let topo = surface_topology(&mesh).expect("bun045 cage is manifold");
    assert_eq!(topo.components, 1);
    assert!(topo.boundary_loops >= 1);
    assert_eq!(topo.genus, 0);
}

#[test]
fn bad_inputs_are_input_errors() {
    let ok = sphere(100, Point3::origin(), 1.0, 12);
    let expect_input =
        |name: &str, points: Vec<Point3>, params: &InitParams, needle: &str| match initial_mesh(
            &cloud(points),
            params,
        ) {
            Err(Error::Input(msg)) => {
                eprintln!("{name}: {msg}");
                assert!(msg.contains(needle), "{name}: '{msg}' lacks '{needle}'");
            }
            other => panic!("{name}: expected Error::Input, got {other:?}"),
        };
    let d = InitParams::default();
    expect_input("empty", vec![], &d, "empty");
    expect_input("three points", ok[..3].to_vec(), &d, "at least 10");
    expect_input(
        "identical",
        vec![Point3::new(1.0, 2.0, 3.0); 50],
        &d,
        "identical",
    );
    let line: Vec<Point3> = (0..50)
        .map(|i| Point3::new(i as Real, 2.0 * i as Real, -(i as Real)))
        .collect();
    expect_input("collinear", line, &d, "collinear");
    let mut nan = ok.clone();
    nan[17].y = Real::NAN;
    expect_input("one NaN", nan, &d, "point 17");
    expect_input(
        "all NaN",
        vec![Point3::new(Real::NAN, Real::NAN, Real::NAN); 20],
        &d,
        "non-finite",
    );
    let mut inf = ok.clone();
    inf[3].x = Real::INFINITY;
    expect_input("infinite", inf, &d, "non-finite");
    for resolution in [0, 1, 100_000] {
        let p = InitParams {
            resolution,
            ..Default::default()
        };
        expect_input("resolution", ok.clone(), &p, "resolution");
    }
    let p = InitParams {
        closed_threshold: Real::NAN,
        ..Default::default()
    };
    expect_input("threshold", ok.clone(), &p, "threshold");
}

#[test]
fn every_kind_works_on_every_cloud() {
    // Forcing a method on an unusual cloud still gives a valid manifold cage.
    let clouds = [
        ("sphere", sphere(800, Point3::origin(), 1.0, 13)),
        ("torus", torus_cloud(2000, 14)),
        ("height field", height_field(1500, 15)),
    ];
    for (name, pts) in &clouds {
        for kind in [InitKind::Closed, InitKind::Open, InitKind::Occupancy] {
            let p = InitParams {
                kind,
                ..Default::default()
            };
            let (_, report) = build(&format!("{name} as {kind}"), pts, &p);
            assert_eq!(report.chosen, kind);
        }
    }
    // A planar cloud: open by detection, and a flat but valid ellipsoid when forced.
    let mut rng = Rng(16);
    let flat: Vec<Point3> = (0..500)
        .map(|_| Point3::new(rng.range(0.0, 2.0), rng.range(0.0, 1.0), 0.0))
        .collect();
    let (_, r) = build("plane", &flat, &InitParams::default());
    assert_eq!(r.chosen, InitKind::Open);
    let p = InitParams {
        kind: InitKind::Closed,
        ..Default::default()
    };
    let (mesh, _) = build("plane as closed", &flat, &p);
    // A flat cage folds sharply (by design) along its rim: no fold check.
    assert_closed_topology("plane as closed", &mesh, 0);
}

#[test]
fn kind_names_round_trip() {
    for kind in [
        InitKind::Auto,
        InitKind::Closed,
        InitKind::Open,
        InitKind::Occupancy,
    ] {
        assert_eq!(kind.name().parse::<InitKind>().expect("parse"), kind);
    }
    assert!(matches!(
        "mesh.obj".parse::<InitKind>(),
        Err(Error::Input(_))
    ));
}

/// Points on the surface of an arch: two 0.4 × 1 × 1 legs `gap` apart
/// along x under a 1 × 0.4 thick bridge, every face sampled on a jittered
/// grid of pitch `pitch`, points inside another box dropped.
fn arch_cloud(gap: Real, pitch: Real, seed: u64) -> Vec<Point3> {
    let width = 0.8 + gap;
    let boxes = [
        ([0.0, 0.0, 0.0], [0.4, 1.0, 1.0]),
        ([0.4 + gap, 0.0, 0.0], [width, 1.0, 1.0]),
        ([0.0, 1.0, 0.0], [width, 1.4, 1.0]),
    ];
    let inside = |p: &Point3, skip: usize| {
        boxes.iter().enumerate().any(|(i, (lo, hi))| {
            i != skip && (0..3).all(|k| p[k] > lo[k] - 1e-9 && p[k] < hi[k] + 1e-9)
        })
    };
    let mut rng = Rng(seed);
    let mut pts = Vec::new();
    for (b, (lo, hi)) in boxes.iter().enumerate() {
        for axis in 0..3 {
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            let (nu, nv) = (
                ((hi[u] - lo[u]) / pitch).round() as usize,
                ((hi[v] - lo[v]) / pitch).round() as usize,
            );
            for side in [lo[axis], hi[axis]] {
                for i in 0..nu {
                    for j in 0..nv {
                        let mut p = Point3::origin();
                        p[axis] = side;
                        p[u] = lo[u] + (i as Real + rng.range(0.2, 0.8)) * pitch;
                        p[v] = lo[v] + (j as Real + rng.range(0.2, 0.8)) * pitch;
                        if !inside(&p, b) {
                            pts.push(p);
                        }
                    }
                }
            }
        }
    }
    pts
}

#[test]
fn arch_keeps_the_gap_between_its_legs_open() {
    let gap = 0.15;
    let pts = arch_cloud(gap, 0.025, 9);
    // Cage vertices well inside the gap between the legs: a web spans it.
    let in_gap = |mesh: &PolyMesh| {
        mesh.positions
            .iter()
            .filter(|p| p.x > 0.43 && p.x < 0.37 + gap && p.y < 0.9 && p.z > 0.15 && p.z < 0.85)
            .count()
    };
    // 8 voxels along the longest axis: the 0.175 voxel is wider than the gap.
    let occupancy = |max_refinement: Real| InitParams {
        kind: InitKind::Occupancy,
        resolution: 8,
        max_refinement,
        ..Default::default()
    };
    let (mesh, report) = build("arch", &pts, &occupancy(2.0));
    assert!(
        report.reason.contains("narrowest gaps"),
        "{}",
        report.reason
    );
    assert_closed_topology("arch", &mesh, 0);
    assert_eq!(in_gap(&mesh), 0, "a web spans the arch's gap");
    // The check can fail: with voxels wider than the gap the shell fills it.
    let (webbed, _) = build("arch, refinement off", &pts, &occupancy(1.0));
    assert!(in_gap(&webbed) > 0, "expected a web without refinement");
}

/// Points uniformly (by area) on the surface of the union of axis-aligned
/// boxes `(lo, hi)`: each box's faces sampled by area, points inside another
/// box dropped.
fn boxes_cloud(boxes: &[([Real; 3], [Real; 3])], n: usize, seed: u64) -> Vec<Point3> {
    let mut rng = Rng(seed);
    let area = |(lo, hi): &([Real; 3], [Real; 3])| {
        let e = [0, 1, 2].map(|k| hi[k] - lo[k]);
        2.0 * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0])
    };
    let total: Real = boxes.iter().map(area).sum();
    let inside = |p: &[Real; 3], (lo, hi): &([Real; 3], [Real; 3])| {
        (0..3).all(|k| p[k] > lo[k] && p[k] < hi[k])
    };
    let mut pts = Vec::with_capacity(n);
    while pts.len() < n {
        let mut pick = rng.range(0.0, total);
        let b = boxes
            .iter()
            .find(|b| {
                pick -= area(b);
                pick < 0.0
            })
            .unwrap_or(&boxes[0]);
        let (lo, hi) = b;
        let e = [0, 1, 2].map(|k| hi[k] - lo[k]);
        let faces = [e[1] * e[2], e[2] * e[0], e[0] * e[1]];
        let mut f = rng.range(0.0, faces.iter().sum());
        let axis = (0..3)
            .find(|&k| {
                f -= faces[k];
                f < 0.0
            })
            .unwrap_or(2);
        let mut p = [0, 1, 2].map(|k| rng.range(lo[k], hi[k]));
        p[axis] = if rng.next() < 0.5 { lo[axis] } else { hi[axis] };
        if !boxes.iter().any(|o| inside(&p, o)) {
            pts.push(Point3::new(p[0], p[1], p[2]));
        }
    }
    pts
}

#[test]
fn occupancy_keeps_separate_thin_parts_apart() {
    // A stool: a seat 2 × 2 × 0.12 on four legs 0.1 thick and 1.2 long, the
    // legs 1.8 apart. Lines through two legs meet them as two thin sheets
    // with free space between, which the interior probes take for a leak;
    // a closing would web the legs together.
    let mut boxes = vec![([-1.0, -1.0, 0.0], [1.0, 1.0, 0.12])];
    for (x, y) in [(-1.0, -1.0), (0.9, -1.0), (-1.0, 0.9), (0.9, 0.9)] {
        boxes.push(([x, y, -1.2], [x + 0.1, y + 0.1, 0.0]));
    }
    let pts = boxes_cloud(&boxes, 12_000, 5);
    let (mesh, report) = build("stool", &pts, &InitParams::default());
    assert_eq!(report.chosen, InitKind::Occupancy);
    assert!(report.reason.contains("closing 0"), "{}", report.reason);
    assert_closed_topology("stool", &mesh, 0);
}
