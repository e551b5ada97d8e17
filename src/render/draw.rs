//! `render`: a scene to a picture — camera, faces, splats, edges,
//! down-sampling, then labels, legend and title at the final resolution.

use std::collections::HashSet;

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3, bbox_diagonal, bounding_box};
use crate::mesh::PolyMesh;

use super::camera::{Camera, ScreenPoint};
use super::colormap::normalise;
use super::eye_dome::eye_dome;
use super::font::draw_text;
use super::legend::{Legend, draw_title, title_height};
use super::marks::{draw_disk, draw_line};
use super::picture::{Picture, Rgb};
use super::raster::{Target, fill_triangle};
use super::scene::{CloudLayer, MeshLayer, RenderOptions, SHARP_EDGES, Scene, validate_scene};
use super::shading::{Headlight, corner_normals, lit};

/// Depth tolerance of edge overlays, as a fraction of the scene's bounding-box
/// diagonal: edges this far behind the nearest surface still show.
const EDGE_BIAS: Real = 0.004;
/// Darkening of colour-mapped back faces.
const BACK_SHADE: f32 = 0.75;

/// Draws `scene` as seen with `options`.
///
/// The camera orbits the centre of the scene's bounding box and is fitted so
/// that all geometry fills the picture (less the margin, the title band and
/// the legend strip). Faces are fan-triangulated and shaded per pixel
/// (Lambert, headlight, two-sided: back sides get [`RenderOptions`]'s back
/// colour), points are depth-tested disks (with eye-dome lighting when they
/// have no normals), edges are drawn last, then the labels on top. When a layer
/// has scalars, a legend bar for the scalar range is drawn at the right.
///
/// ```
/// use subdyn::render::{render, MeshLayer, RenderOptions, Scene};
/// let cube = subdyn::examples::cube();
/// let scene = Scene { meshes: vec![MeshLayer::new(&cube)], ..Scene::default() };
/// let picture = render(&scene, &RenderOptions { width: 64, height: 48, ..Default::default() })?;
/// assert_eq!((picture.width(), picture.height()), (64, 48));
/// assert!(picture.count(|c| c != [255, 255, 255]) > 500);
/// # Ok::<(), subdyn::Error>(())
/// ```
pub fn render(scene: &Scene, options: &RenderOptions) -> Result<Picture> {
    options.validate()?;
    validate_scene(scene)?;
    let points: Vec<Point3> = scene
        .meshes
        .iter()
        .flat_map(|m| m.mesh.positions.iter())
        .chain(scene.clouds.iter().flat_map(|c| c.cloud.positions.iter()))
        .copied()
        .collect();
    let (lo, hi) = bounding_box(&points)
        .ok_or_else(|| Error::input("nothing to draw: the scene has no vertices or points"))?;
    let diag = bbox_diagonal(&points);

    let (w, h) = (options.width, options.height);
    let text_scale = (w.min(h) / 240).clamp(1, 4);
    let range = options.scalar_range.or_else(|| scalar_range(scene));
    let mut legend = match range {
        Some(range) if options.legend => Some(Legend::new(
            range,
            options.legend_label.clone(),
            options.colormap,
            text_scale,
        )),
        _ => None,
    };
    let mut title = options.title.clone().filter(|t| !t.is_empty());
    let mut top = title.as_ref().map_or(0, |_| title_height(text_scale));
    let mut right = legend.as_ref().map_or(0, Legend::width);
    if w < right + 32 || h < top + 32 {
        // Too small for decorations: the geometry gets the whole picture.
        (legend, title, top, right) = (None, None, 0, 0);
    }

    let k = options.supersample;
    let kf = Real::from(k);
    let mut camera = Camera::orbit(
        lo,
        hi,
        options.azimuth,
        options.elevation,
        options.projection,
    )?;
    let rect = [
        0.0,
        Real::from(top) * kf,
        Real::from(w - right) * kf,
        Real::from(h - top) * kf,
    ];
    camera.fit(&points, rect, options.margin);
    let (right_dir, up_dir) = camera.right_up();
    let light = Headlight::new(camera.towards_eye(), right_dir, up_dir);

    let background = options.background.map(|c| f32::from(c) / 255.0);
    let mut target = Target::new((w * k) as usize, (h * k) as usize, background);
    let context = Context {
        camera: &camera,
        light,
        range: range.unwrap_or((0.0, 1.0)),
        options,
    };
    for layer in scene.meshes.iter().filter(|m| m.faces) {
        context.draw_faces(&mut target, layer);
    }
    for layer in &scene.clouds {
        context.draw_points(&mut target, layer, kf);
    }
    if options.eye_dome {
        eye_dome(&mut target, k as usize);
    }
    for layer in &scene.meshes {
        if let Some(color) = layer.edges {
            let all = edge_list(layer.mesh);
            context.draw_edges(
                &mut target,
                layer,
                &all,
                color,
                k as usize,
                EDGE_BIAS * diag,
            );
        }
        context.draw_edges(
            &mut target,
            layer,
            layer.sharp,
            SHARP_EDGES,
            2 * k as usize,
            EDGE_BIAS * diag,
        );
    }

    let mut picture = downsample(&target, k)?;
    let label_scale = text_scale;
    for label in &scene.labels {
        let p = camera.project(&label.at);
        if p.x.is_finite() && p.y.is_finite() && p.x.abs() < 1e6 && p.y.abs() < 1e6 {
            let (x, y) = ((p.x / kf).round() as i64, (p.y / kf).round() as i64);
            let up = i64::from(8 * label_scale);
            let s = i64::from(label_scale);
            draw_text(
                &mut picture,
                x + 2 * s,
                y - up,
                &label.text,
                label_scale,
                label.color,
            );
        }
    }
    if let Some(legend) = legend {
        legend.draw(
            &mut picture,
            i64::from(w - right),
            i64::from(top),
            i64::from(h),
        );
    }
    if let Some(title) = title {
        draw_title(&mut picture, &title, text_scale);
    }
    Ok(picture)
}

/// Smallest and largest finite scalar of all layers; `None` without scalars.
fn scalar_range(scene: &Scene) -> Option<(Real, Real)> {
    let all = scene
        .meshes
        .iter()
        .filter_map(|m| m.scalars)
        .chain(scene.clouds.iter().filter_map(|c| c.scalars));
    let mut range: Option<(Real, Real)> = None;
    let mut any = false;
    for s in all {
        any = true;
        for &v in s.iter().filter(|v| v.is_finite()) {
            range = Some(range.map_or((v, v), |(a, b)| (a.min(v), b.max(v))));
        }
    }
    if any {
        Some(range.unwrap_or((0.0, 1.0)))
    } else {
        None
    }
}

/// What every layer needs while drawing.
struct Context<'a> {
    camera: &'a Camera,
    light: Headlight,
    range: (Real, Real),
    options: &'a RenderOptions,
}

impl Context<'_> {
    /// Colour of a scalar value as sRGB in `[0, 1]`.
    fn map(&self, value: Real) -> [f32; 3] {
        self.options
            .colormap
            .color_f32(normalise(value, self.range))
    }

    /// Shaded, depth-tested faces.
    fn draw_faces(&self, target: &mut Target, layer: &MeshLayer) {
        let mesh = layer.mesh;
        let screen: Vec<ScreenPoint> = mesh
            .positions
            .iter()
            .map(|p| self.camera.project(p))
            .collect();
        let corner: Vec<Vector3> = match layer.normals {
            Some(n) => mesh.face_vertices.iter().map(|&v| n[v as usize]).collect(),
            None => corner_normals(mesh, self.options.crease_angle),
        };
        let front = to_unit(layer.color);
        let back = to_unit(layer.back_color);
        let perspective = self.camera.is_perspective();
        for (f, face) in mesh.faces().enumerate() {
            let off = mesh.face_offsets[f] as usize;
            for i in 1..face.len() - 1 {
                let c = [off, off + i, off + i + 1];
                let v = c.map(|ci| mesh.face_vertices[ci] as usize);
                let s = layer.scalars.map(|s| v.map(|vi| s[vi]));
                fill_triangle(target, v.map(|vi| screen[vi]), perspective, |frag| {
                    let b = frag.bary;
                    let n = corner[c[0]] * b[0] + corner[c[1]] * b[1] + corner[c[2]] * b[2];
                    let base = match s {
                        Some(s) => {
                            let rgb = self.map(s[0] * b[0] + s[1] * b[1] + s[2] * b[2]);
                            if frag.back {
                                rgb.map(|x| x * BACK_SHADE)
                            } else {
                                rgb
                            }
                        }
                        None if frag.back => back,
                        None => front,
                    };
                    lit(base, self.light.brightness(&n))
                });
            }
        }
    }

    /// Depth-tested disks, shaded when the cloud has normals.
    fn draw_points(&self, target: &mut Target, layer: &CloudLayer, k: Real) {
        let flat = to_unit(layer.color);
        for (i, p) in layer.cloud.positions.iter().enumerate() {
            let base = layer.scalars.map_or(flat, |s| self.map(s[i]));
            let (color, flat) = match &layer.cloud.normals {
                Some(n) => (lit(base, self.light.brightness(&n[i])), false),
                None => (base, true),
            };
            draw_disk(
                target,
                self.camera.project(p),
                layer.radius * k,
                color,
                flat,
            );
        }
    }

    /// The `edges` of the layer's mesh, `width` working pixels wide.
    fn draw_edges(
        &self,
        target: &mut Target,
        layer: &MeshLayer,
        edges: &[(u32, u32)],
        color: Rgb,
        width: usize,
        bias: Real,
    ) {
        let project = |v: u32| self.camera.project(&layer.mesh.positions[v as usize]);
        let color = to_unit(color);
        for &(a, b) in edges {
            draw_line(
                target,
                project(a),
                project(b),
                width,
                bias,
                self.camera.is_perspective(),
                color,
            );
        }
    }
}

/// Every edge of `mesh` once, in the order the faces meet them.
fn edge_list(mesh: &PolyMesh) -> Vec<(u32, u32)> {
    let mut seen = HashSet::new();
    mesh.faces()
        .flat_map(|face| (0..face.len()).map(move |i| (face[i], face[(i + 1) % face.len()])))
        .filter(|&(a, b)| seen.insert((a.min(b), a.max(b))))
        .collect()
}

/// An 8-bit colour as sRGB in `[0, 1]`.
fn to_unit(c: Rgb) -> [f32; 3] {
    c.map(|x| f32::from(x) / 255.0)
}

/// Averages `k × k` blocks of the target into a picture.
fn downsample(target: &Target, k: u32) -> Result<Picture> {
    let k = k as usize;
    let (w, h) = (target.width / k, target.height / k);
    let mut pixels = Vec::with_capacity(w * h);
    let norm = 255.0 / (k * k) as f32;
    for y in 0..h {
        for x in 0..w {
            let mut sum = [0.0f32; 3];
            for dy in 0..k {
                let row = (y * k + dy) * target.width;
                for dx in 0..k {
                    let c = target.color[row + x * k + dx];
                    for i in 0..3 {
                        sum[i] += c[i];
                    }
                }
            }
            pixels.push(sum.map(|s| (s * norm).round().clamp(0.0, 255.0) as u8));
        }
    }
    Picture::from_pixels(w as u32, h as u32, pixels)
}
