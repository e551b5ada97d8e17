//! Scanner poses and rays: views on a Fibonacci sphere or read from a file,
//! orthographic or perspective pixel grids.

use std::path::Path;

use anyhow::{Context, Result, bail};
use serde::{Deserialize, Serialize};
use subdyn::math::{Point3, Real, Vector3};

/// Where a sensor sits and what it looks at (the JSON form of a view in
/// `--poses` files and in scan sidecars).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// Sensor position.
    pub eye: [Real; 3],
    /// The point on the optical axis the sensor looks at.
    pub target: [Real; 3],
    /// Up hint (default +z, or +y when looking along z).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<[Real; 3]>,
}

/// The projection of the pixel grid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Parallel rays along the view direction through a window of the given
    /// height (width = height · W / H), centred on the optical axis.
    Orthographic {
        /// Window height (model units).
        height: Real,
    },
    /// Rays from the eye through the pixel centres; vertical field of view in degrees.
    Perspective {
        /// Vertical field of view, degrees.
        fov_deg: Real,
    },
}

/// `n` poses with eyes on a Fibonacci sphere of radius `distance` around
/// `centre`, all looking at `centre`: eye `i` at height `z = 1 − (2i + 1)/n`
/// and azimuth `i · π (3 − √5)` (the golden angle).
pub fn fibonacci_poses(n: usize, centre: &Point3, distance: Real) -> Vec<Pose> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - (2.0 * i as Real + 1.0) / n as Real;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let a = golden * i as Real;
            let dir = Vector3::new(r * a.cos(), r * a.sin(), z);
            let eye = centre + dir * distance;
            Pose {
                eye: [eye.x, eye.y, eye.z],
                target: [centre.x, centre.y, centre.z],
                up: None,
            }
        })
        .collect()
}

/// Reads poses from JSON: an array of `{"eye": [x,y,z], "target": [x,y,z],
/// "up": [x,y,z]}` (`target` defaults to `default_target`, `up` is optional),
/// or an object with such an array under `"views"` (a scan sidecar).
pub fn read_poses(path: &Path, default_target: &Point3) -> Result<Vec<Pose>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}", path.display()))?;
    let value: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{}: not JSON", path.display()))?;
    let list = match &value {
        serde_json::Value::Array(a) => a.clone(),
        serde_json::Value::Object(o) => match o.get("views") {
            Some(serde_json::Value::Array(a)) => a.clone(),
            _ => bail!(
                "{}: expected an array of poses or an object with a `views` array",
                path.display()
            ),
        },
        _ => bail!("{}: expected an array of poses", path.display()),
    };
    if list.is_empty() {
        bail!("{}: no poses", path.display());
    }
    let target = [default_target.x, default_target.y, default_target.z];
    list.iter()
        .enumerate()
        .map(|(i, v)| {
            let mut v = v.clone();
            if let Some(o) = v.as_object_mut() {
                o.entry("target").or_insert(serde_json::json!(target));
            }
            let pose: Pose = serde_json::from_value(v)
                .with_context(|| format!("{}: pose {i}: expected {{\"eye\": [x, y, z], \"target\": [x, y, z], \"up\": [x, y, z]}}", path.display()))?;
            let finite = pose.eye.iter().chain(&pose.target).chain(pose.up.iter().flatten()).all(|c| c.is_finite());
            if !finite || pose.eye == pose.target {
                bail!("{}: pose {i}: eye and target must be finite and distinct", path.display());
            }
            Ok(pose)
        })
        .collect()
}

/// A pose turned into an orthonormal frame with a pixel grid.
#[derive(Clone, Debug)]
pub struct Camera {
    /// Sensor position.
    pub eye: Point3,
    /// Unit viewing direction.
    pub forward: Vector3,
    /// Unit right vector (image x).
    pub right: Vector3,
    /// Unit up vector (image y).
    pub up: Vector3,
    /// Pixels across and down.
    pub size: (usize, usize),
    /// Projection.
    pub projection: Projection,
}

impl Camera {
    /// The frame of `pose`: `forward = (target − eye)/|…|`, `right = forward × up_hint`, `up = right × forward`.
    pub fn new(pose: &Pose, size: (usize, usize), projection: Projection) -> Camera {
        let eye = Point3::from(pose.eye);
        let forward = (Point3::from(pose.target) - eye).normalize();
        let hint = pose.up.map(Vector3::from).unwrap_or_else(Vector3::z);
        let right = forward
            .cross(&hint)
            .try_normalize(1e-9)
            .or_else(|| forward.cross(&Vector3::y()).try_normalize(1e-9))
            .unwrap_or_else(Vector3::x);
        let up = right.cross(&forward);
        Camera {
            eye,
            forward,
            right,
            up,
            size,
            projection,
        }
    }

    /// Origin and unit direction of the ray through the centre of pixel
    /// `(i, j)` (column `i` from the left, row `j` from the top).
    pub fn ray(&self, i: usize, j: usize) -> (Point3, Vector3) {
        let (w, h) = (self.size.0 as Real, self.size.1 as Real);
        let sx = (i as Real + 0.5) / w - 0.5;
        let sy = 0.5 - (j as Real + 0.5) / h;
        match self.projection {
            Projection::Orthographic { height } => {
                let origin =
                    self.eye + self.right * (sx * height * w / h) + self.up * (sy * height);
                (origin, self.forward)
            }
            Projection::Perspective { fov_deg } => {
                let half = (0.5 * fov_deg.to_radians()).tan();
                let d = self.forward
                    + self.right * (2.0 * sx * half * w / h)
                    + self.up * (2.0 * sy * half);
                (self.eye, d.normalize())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fibonacci_eyes_are_at_the_distance_and_spread() {
        let c = Point3::new(1.0, 2.0, 3.0);
        let poses = fibonacci_poses(8, &c, 5.0);
        let mean = poses
            .iter()
            .fold(Vector3::zeros(), |s, p| s + (Point3::from(p.eye) - c))
            / 8.0;
        for p in &poses {
            assert!(((Point3::from(p.eye) - c).norm() - 5.0).abs() < 1e-12);
        }
        assert!(
            mean.norm() < 1.0,
            "views should surround the centre: {mean}"
        );
    }

    #[test]
    fn central_rays_hit_the_target() {
        let pose = Pose {
            eye: [0.0, -3.0, 0.0],
            target: [0.0; 3],
            up: None,
        };
        for projection in [
            Projection::Perspective { fov_deg: 40.0 },
            Projection::Orthographic { height: 2.0 },
        ] {
            let cam = Camera::new(&pose, (3, 3), projection);
            let (o, d) = cam.ray(1, 1);
            assert!((o + d * (Point3::origin() - o).norm() - Point3::origin()).norm() < 1e-12);
            // Pixel (0, 0) is up and to the left: up is +z, right is +x looking along +y.
            let (o, d) = cam.ray(0, 0);
            let p = o + d * 3.0;
            assert!(p.x < 0.0 && p.z > 0.0, "{p}");
        }
    }
}
