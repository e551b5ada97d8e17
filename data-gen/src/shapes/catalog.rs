//! `build_shape`: the named shapes with their parameters, default
//! resolutions and analytic ground truth.

use serde_json::{Value, json};
use subdyn::error::{Error, Result};
use subdyn::math::{Point3, Real};
use subdyn::mesh::PolyMesh;

use super::sdf::Field;
use super::{anvil, bulb, genus2, machined, quad_sphere};
use crate::measure::orient_outward;
use crate::topology::mesh_topology;

/// The built-in shapes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ShapeKind {
    /// Quad sphere (cube mapped onto the sphere), genus 0.
    Sphere,
    /// Quad sphere scaled to radii `a, b, c`, genus 0.
    Ellipsoid,
    /// Quad torus around z with radii `R` (major) and `r` (minor), genus 1.
    Torus,
    /// Two tori blended by a smooth union (marching tetrahedra, relaxed), genus 2.
    Genus2,
    /// Surface of revolution: a sphere blended into a cylindrical neck, genus 0.
    Bulb,
    /// Rounded boxes with a conical horn, blended (marching tetrahedra), genus 0.
    Anvil,
    /// A thin plate with a through slot, sharp edges (exact box mesh), genus 1.
    Plate,
    /// An L-bracket with two holes and a slot in its base and a hole in its flange, sharp edges, genus 4.
    Bracket,
    /// A chair with thin square legs and a slatted back (narrow gaps), sharp edges, genus 5.
    Chair,
}

impl ShapeKind {
    /// The name used on the command line and in sidecars.
    pub fn name(self) -> &'static str {
        match self {
            ShapeKind::Sphere => "sphere",
            ShapeKind::Ellipsoid => "ellipsoid",
            ShapeKind::Torus => "torus",
            ShapeKind::Genus2 => "genus2",
            ShapeKind::Bulb => "bulb",
            ShapeKind::Anvil => "anvil",
            ShapeKind::Plate => "plate",
            ShapeKind::Bracket => "bracket",
            ShapeKind::Chair => "chair",
        }
    }

    /// The resolution used when none is given, and the allowed range.
    pub fn resolution_range(self) -> (usize, usize, usize) {
        // (default, min, max)
        match self {
            ShapeKind::Sphere | ShapeKind::Ellipsoid => (64, 1, 1024),
            ShapeKind::Torus => (128, 3, 4096),
            ShapeKind::Bulb => (128, 3, 4096),
            ShapeKind::Genus2 => (110, 16, 1000),
            ShapeKind::Anvil => (110, 16, 1000),
            ShapeKind::Plate | ShapeKind::Chair => (100, 10, 1000),
            ShapeKind::Bracket => (90, 10, 1000),
        }
    }

    /// The expected genus.
    pub fn genus(self) -> i64 {
        match self {
            ShapeKind::Torus | ShapeKind::Plate => 1,
            ShapeKind::Genus2 => 2,
            ShapeKind::Bracket => 4,
            ShapeKind::Chair => 5,
            _ => 0,
        }
    }
}

/// Shape parameters; fields a shape does not use are ignored.
#[derive(Clone, Debug, PartialEq)]
pub struct ShapeParams {
    /// Resolution (meaning per shape, see `data-gen shape --help`); `None` for the default.
    pub resolution: Option<usize>,
    /// Sphere radius (default 1).
    pub radius: Real,
    /// Ellipsoid radii along x, y, z (default 1.5, 1, 0.6).
    pub radii: [Real; 3],
    /// Torus major radius `R` (default 1).
    pub major: Real,
    /// Torus minor radius `r` (default 0.35).
    pub minor: Real,
}

impl Default for ShapeParams {
    fn default() -> Self {
        ShapeParams {
            resolution: None,
            radius: 1.0,
            radii: [1.5, 1.0, 0.6],
            major: 1.0,
            minor: 0.35,
        }
    }
}

/// A generated shape: the reference mesh, an implicit function for it when
/// there is one (negative inside), and analytic facts for the sidecar.
pub struct Shape {
    /// The ground-truth mesh, outward oriented.
    pub mesh: PolyMesh,
    /// The smooth surface the mesh samples, as the zero set of a field.
    pub field: Box<Field>,
    /// Parameters and formulas for the sidecar.
    pub analytic: Value,
}

/// Builds shape `kind` with `params`, checking every parameter.
pub fn build_shape(kind: ShapeKind, params: &ShapeParams) -> Result<Shape> {
    let (default, min, max) = kind.resolution_range();
    let n = params.resolution.unwrap_or(default);
    if !(min..=max).contains(&n) {
        return Err(Error::out_of_range(format!(
            "--resolution {n} is out of range for {}: {min}..={max}",
            kind.name()
        )));
    }
    let positive = |name: &str, x: Real| {
        if x.is_finite() && x > 0.0 {
            Ok(x)
        } else {
            Err(Error::input(format!(
                "{name} must be a positive number, got {x}"
            )))
        }
    };
    use std::f64::consts::PI;
    let (mut mesh, field, analytic): (PolyMesh, Box<Field>, Value) = match kind {
        ShapeKind::Sphere => {
            let r = positive("--radius", params.radius)?;
            let mut mesh = quad_sphere::quad_sphere(n)?;
            for p in &mut mesh.positions {
                *p *= r;
            }
            let field = Box::new(move |p: &Point3| p.coords.norm() - r);
            let analytic = json!({
                "resolution": n,
                "resolution_meaning": "quads per cube-face side (6 n^2 quads)",
                "radius": r, "centre": [0.0, 0.0, 0.0],
                "implicit": "|p| - r",
                "area": 4.0 * PI * r * r,
                "volume": 4.0 / 3.0 * PI * r * r * r,
            });
            (mesh, field, analytic)
        }
        ShapeKind::Ellipsoid => {
            let [a, b, c] = params.radii;
            for (name, x) in [("--radii a", a), ("--radii b", b), ("--radii c", c)] {
                positive(name, x)?;
            }
            let mut mesh = quad_sphere::quad_sphere(n)?;
            for p in &mut mesh.positions {
                *p = Point3::new(p.x * a, p.y * b, p.z * c);
            }
            // Normalised so that |∇f| ≈ 1 near the surface: f = (|p/r| - 1) · min(r).
            let s = a.min(b).min(c);
            let field = Box::new(move |p: &Point3| {
                ((p.x / a).powi(2) + (p.y / b).powi(2) + (p.z / c).powi(2)).sqrt() * s - s
            });
            let analytic = json!({
                "resolution": n,
                "resolution_meaning": "quads per cube-face side (6 n^2 quads)",
                "radii": [a, b, c], "centre": [0.0, 0.0, 0.0],
                "implicit": "(x/a)^2 + (y/b)^2 + (z/c)^2 - 1",
                "volume": 4.0 / 3.0 * PI * a * b * c,
            });
            (mesh, field, analytic)
        }
        ShapeKind::Torus => {
            let (big, small) = (
                positive("--major", params.major)?,
                positive("--minor", params.minor)?,
            );
            if small >= big {
                return Err(Error::input(format!(
                    "--minor {small} must be smaller than --major {big} (a ring torus)"
                )));
            }
            let m = n.div_ceil(2).max(3);
            let mesh = subdyn::examples::torus(n, m, big, small);
            let o = Point3::origin();
            let field = Box::new(move |p: &Point3| super::sdf::torus(p, &o, big, small));
            let analytic = json!({
                "resolution": n,
                "resolution_meaning": "segments around the axis; ceil(n/2) around the tube",
                "major_radius": big, "minor_radius": small, "axis": [0.0, 0.0, 1.0],
                "implicit": "(sqrt(x^2 + y^2) - R)^2 + z^2 - r^2",
                "area": 4.0 * PI * PI * big * small,
                "volume": 2.0 * PI * PI * big * small * small,
            });
            (mesh, field, analytic)
        }
        ShapeKind::Genus2 => (
            genus2::genus2(n)?,
            Box::new(genus2::genus2_field) as Box<Field>,
            json!({
                "resolution": n,
                "resolution_meaning": "marching-tetrahedra cells along x",
                "implicit": genus2::FORMULA,
            }),
        ),
        ShapeKind::Bulb => (
            bulb::bulb(n)?,
            Box::new(bulb::bulb_field) as Box<Field>,
            json!({
                "resolution": n,
                "resolution_meaning": "profile steps (equal arc length) and segments around z",
                "implicit": bulb::FORMULA,
            }),
        ),
        ShapeKind::Anvil => (
            anvil::anvil(n)?,
            Box::new(anvil::anvil_field) as Box<Field>,
            json!({
                "resolution": n,
                "resolution_meaning": "marching-tetrahedra cells along x",
                "implicit": anvil::FORMULA,
            }),
        ),
        ShapeKind::Plate | ShapeKind::Bracket | ShapeKind::Chair => {
            let (solid, mesh) = match kind {
                ShapeKind::Plate => (&machined::PLATE, machined::plate(n)?),
                ShapeKind::Bracket => (&machined::BRACKET, machined::bracket(n)?),
                _ => (&machined::CHAIR, machined::chair(n)?),
            };
            (
                mesh,
                Box::new(|p: &Point3| solid.field(p)) as Box<Field>,
                json!({
                    "resolution": n,
                    "resolution_meaning": "grid steps along the longest side (box corners are grid lines)",
                    "implicit": machined::formula(solid),
                    "sharp_edges": true,
                }),
            )
        }
    };
    orient_outward(&mut mesh);
    let topology = mesh_topology(&mesh);
    if topology.genus != Some(kind.genus()) {
        return Err(Error::Topology(format!(
            "the {} mesh came out as {topology:?}, not a closed manifold of genus {}; try another --resolution",
            kind.name(),
            kind.genus()
        )));
    }
    Ok(Shape {
        mesh,
        field,
        analytic,
    })
}

/// How far the mesh is from the smooth surface it samples: the largest
/// first-order distance `|f| / |∇f|` over vertices and over face centroids.
pub fn surface_deviation(mesh: &PolyMesh, field: &Field) -> (Real, Real) {
    let scale = subdyn::math::bbox_diagonal(&mesh.positions).max(1e-300);
    let distance = |p: &Point3| {
        let g = super::sdf::gradient(field, p, 1e-7 * scale).norm();
        if g > 0.0 {
            field(p).abs() / g
        } else {
            field(p).abs()
        }
    };
    let vertices = mesh.positions.iter().map(distance).fold(0.0, Real::max);
    let centroids = mesh
        .faces()
        .map(|f| {
            let c = f.iter().fold(Point3::origin().coords, |s, &v| {
                s + mesh.positions[v as usize].coords
            }) / f.len() as Real;
            distance(&Point3::from(c))
        })
        .fold(0.0, Real::max);
    (vertices, centroids)
}
