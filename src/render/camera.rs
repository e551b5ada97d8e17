//! The camera: an orbit view around the bounding-box centre, orthographic or
//! perspective, fitted to a rectangle of the picture.

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3};

/// How 3-space is flattened onto the picture.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Parallel projection along the view direction (sizes do not shrink with distance).
    Orthographic,
    /// Pinhole projection with the given full vertical field of view in degrees
    /// (the camera stands back far enough to see the whole bounding sphere).
    Perspective {
        /// Field of view in degrees, in `(0, 170]`.
        fov_deg: Real,
    },
}

/// A point projected to the picture: `x` right and `y` down in pixels,
/// `depth` the distance from the eye along the view axis (world units, > 0).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScreenPoint {
    /// Column, in pixels (pixel `i` covers `[i, i + 1)`).
    pub x: Real,
    /// Row, in pixels from the top.
    pub y: Real,
    /// Distance from the eye along the view axis.
    pub depth: Real,
}

/// An orbit camera. Azimuth turns about the +Y axis and elevation lifts the
/// eye above the XZ plane: azimuth 0, elevation 0 looks from +Z towards −Z
/// with +X to the right and +Y up; azimuth 90 looks from +X.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    centre: Point3,
    right: Vector3,
    up: Vector3,
    /// Unit vector from the centre towards the eye.
    back: Vector3,
    /// Distance from the eye to the centre.
    distance: Real,
    /// Focal length in view units (perspective only).
    focal: Option<Real>,
    /// Picture transform: pixel = offset + scale · (view-plane coordinate), y flipped.
    scale: Real,
    offset: [Real; 2],
}

impl Camera {
    /// A camera looking at the centre of the box `lo..hi` from
    /// (`azimuth`, `elevation`) in degrees; elevation must lie in `[-90, 90]`.
    /// Call [`Camera::fit`] before projecting.
    pub fn orbit(
        lo: Point3,
        hi: Point3,
        azimuth: Real,
        elevation: Real,
        projection: Projection,
    ) -> Result<Camera> {
        if !azimuth.is_finite() || !elevation.is_finite() || elevation.abs() > 90.0 {
            return Err(Error::input(format!(
                "view azimuth {azimuth}, elevation {elevation}: the azimuth must be finite and the elevation between -90 and 90 degrees"
            )));
        }
        let (az, el) = (azimuth.to_radians(), elevation.to_radians());
        let back = Vector3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos());
        // d(back)/d(azimuth), normalised: well defined even at the poles.
        let right = Vector3::new(az.cos(), 0.0, -az.sin());
        let up = back.cross(&right);
        let radius = ((hi - lo).norm() / 2.0).max(Real::MIN_POSITIVE.sqrt());
        let (distance, focal) = match projection {
            Projection::Orthographic => (2.0 * radius, None),
            Projection::Perspective { fov_deg } => {
                if !(fov_deg.is_finite() && fov_deg > 0.0 && fov_deg <= 170.0) {
                    return Err(Error::out_of_range(format!(
                        "field of view {fov_deg} degrees is out of range: expected (0, 170]"
                    )));
                }
                let half = (fov_deg / 2.0).to_radians();
                (radius / half.sin(), Some(1.0 / half.tan()))
            }
        };
        Ok(Camera {
            centre: nalgebra::center(&lo, &hi),
            right,
            up,
            back,
            distance,
            focal,
            scale: 1.0,
            offset: [0.0, 0.0],
        })
    }

    /// Unit vector from the scene towards the eye (the headlight direction).
    pub fn towards_eye(&self) -> Vector3 {
        self.back
    }

    /// Unit vectors of the picture's right and up directions in 3-space.
    pub fn right_up(&self) -> (Vector3, Vector3) {
        (self.right, self.up)
    }

    /// Whether the projection is perspective.
    pub fn is_perspective(&self) -> bool {
        self.focal.is_some()
    }

    /// View-plane coordinates (before the picture transform) and depth.
    fn view(&self, p: &Point3) -> (Real, Real, Real) {
        let d = p - self.centre;
        let depth = self.distance - d.dot(&self.back);
        let (x, y) = (d.dot(&self.right), d.dot(&self.up));
        match self.focal {
            None => (x, y, depth),
            Some(f) => (f * x / depth, f * y / depth, depth),
        }
    }

    /// Scales and centres the projection of `points` into the pixel rectangle
    /// `[x0, x0 + w) × [y0, y0 + h)`, leaving `margin` (a fraction of the
    /// rectangle's smaller side) free on every side. Does nothing for no points.
    pub fn fit<'a>(
        &mut self,
        points: impl IntoIterator<Item = &'a Point3>,
        rect: [Real; 4],
        margin: Real,
    ) {
        let mut lo = [Real::INFINITY; 2];
        let mut hi = [Real::NEG_INFINITY; 2];
        for p in points {
            let (x, y, _) = self.view(p);
            lo = [lo[0].min(x), lo[1].min(y)];
            hi = [hi[0].max(x), hi[1].max(y)];
        }
        if lo[0] > hi[0] || lo.iter().chain(&hi).any(|c| c.is_nan()) {
            return;
        }
        let [x0, y0, w, h] = rect;
        let m = margin.clamp(0.0, 0.45) * w.min(h);
        let (ew, eh) = (hi[0] - lo[0], hi[1] - lo[1]);
        let sx = if ew > 0.0 {
            (w - 2.0 * m) / ew
        } else {
            Real::INFINITY
        };
        let sy = if eh > 0.0 {
            (h - 2.0 * m) / eh
        } else {
            Real::INFINITY
        };
        let s = sx.min(sy);
        self.scale = if s.is_finite() && s > 0.0 { s } else { 1.0 };
        let mid = [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0];
        self.offset = [
            x0 + w / 2.0 - self.scale * mid[0],
            y0 + h / 2.0 + self.scale * mid[1],
        ];
    }

    /// Pixels per world unit at the centre's depth (for splat and bias sizes).
    pub fn pixels_per_unit(&self) -> Real {
        match self.focal {
            None => self.scale,
            Some(f) => self.scale * f / self.distance,
        }
    }

    /// Projects a point to the picture.
    pub fn project(&self, p: &Point3) -> ScreenPoint {
        let (x, y, depth) = self.view(p);
        ScreenPoint {
            x: self.offset[0] + self.scale * x,
            y: self.offset[1] - self.scale * y,
            depth,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn azimuth_zero_looks_down_minus_z_with_x_right_and_y_up() {
        let (lo, hi) = (Point3::new(-1.0, -1.0, -1.0), Point3::new(1.0, 1.0, 1.0));
        let mut cam = Camera::orbit(lo, hi, 0.0, 0.0, Projection::Orthographic).unwrap();
        cam.fit(&[lo, hi], [0.0, 0.0, 100.0, 100.0], 0.0);
        let c = cam.project(&Point3::origin());
        let px = cam.project(&Point3::new(1.0, 0.0, 0.0));
        let py = cam.project(&Point3::new(0.0, 1.0, 0.0));
        let pz = cam.project(&Point3::new(0.0, 0.0, 1.0));
        assert!(px.x > c.x && (px.y - c.y).abs() < 1e-9);
        assert!(py.y < c.y && (py.x - c.x).abs() < 1e-9);
        assert!(pz.depth < c.depth);
        assert!(Camera::orbit(lo, hi, 0.0, 91.0, Projection::Orthographic).is_err());
    }

    #[test]
    fn perspective_keeps_every_point_in_front_of_the_eye() {
        let (lo, hi) = (Point3::new(-1.0, -2.0, -3.0), Point3::new(1.0, 2.0, 3.0));
        let p = Projection::Perspective { fov_deg: 30.0 };
        for (az, el) in [(0.0, 0.0), (45.0, 30.0), (200.0, -90.0), (10.0, 90.0)] {
            let cam = Camera::orbit(lo, hi, az, el, p).unwrap();
            for corner in 0..8 {
                let q = Point3::new(
                    if corner & 1 == 0 { lo.x } else { hi.x },
                    if corner & 2 == 0 { lo.y } else { hi.y },
                    if corner & 4 == 0 { lo.z } else { hi.z },
                );
                assert!(cam.project(&q).depth > 0.0);
            }
        }
    }
}
