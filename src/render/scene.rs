//! What to draw (`Scene` of mesh and point layers, and labels) and how
//! (`RenderOptions`).

use crate::error::{Error, Result};
use crate::math::{Point3, Real, Vector3};
use crate::mesh::{PointCloud, PolyMesh};

use super::camera::Projection;
use super::colormap::ColorMap;
use super::picture::Rgb;

/// Default surface colour (a light blue-grey).
pub const SURFACE: Rgb = [190, 198, 214];
/// Default colour of the back side of surfaces (a warm tint, so holes and
/// inconsistently oriented faces stand out).
pub const BACK: Rgb = [222, 160, 120];
/// Default colour of points.
pub const POINTS: Rgb = [90, 135, 205];
/// Default colour of edge overlays.
pub const EDGES: Rgb = [25, 25, 35];
/// Colour of sharp edges (creases) over a cage.
pub const SHARP_EDGES: Rgb = [215, 30, 30];

/// A polygon mesh to draw: its faces (shaded), its edges, or both.
///
/// ```
/// use subdyn::render::{MeshLayer, EDGES};
/// let cube = subdyn::examples::cube();
/// let layer = MeshLayer::new(&cube).with_edges(EDGES);
/// assert!(layer.faces && layer.edges.is_some());
/// ```
#[derive(Clone, Debug)]
pub struct MeshLayer<'a> {
    /// The mesh; polygons are fan-triangulated.
    pub mesh: &'a PolyMesh,
    /// One normal per vertex (for instance exact limit normals); when `None`,
    /// normals come from the faces, smooth across edges flatter than the
    /// crease angle of [`RenderOptions`].
    pub normals: Option<&'a [Vector3]>,
    /// One scalar per vertex, drawn with the colour map (interpolated per pixel).
    pub scalars: Option<&'a [Real]>,
    /// Colour of the front side (without scalars).
    pub color: Rgb,
    /// Colour of the back side (without scalars; with scalars the map colour is darkened).
    pub back_color: Rgb,
    /// Draw the faces.
    pub faces: bool,
    /// Draw the edges on top in this colour.
    pub edges: Option<Rgb>,
    /// Sharp edges `(i, j)` of the mesh, drawn over the edges twice as wide
    /// in [`SHARP_EDGES`] (a control cage's creases).
    pub sharp: &'a [(u32, u32)],
}

impl<'a> MeshLayer<'a> {
    /// Shaded faces in the default colours, no edges.
    pub fn new(mesh: &'a PolyMesh) -> Self {
        MeshLayer {
            mesh,
            normals: None,
            scalars: None,
            color: SURFACE,
            back_color: BACK,
            faces: true,
            edges: None,
            sharp: &[],
        }
    }

    /// Only the edges of `mesh` (a wireframe, e.g. a control cage over its limit surface).
    pub fn wireframe(mesh: &'a PolyMesh, color: Rgb) -> Self {
        MeshLayer {
            faces: false,
            edges: Some(color),
            ..MeshLayer::new(mesh)
        }
    }

    /// With per-vertex normals.
    pub fn with_normals(mut self, normals: &'a [Vector3]) -> Self {
        self.normals = Some(normals);
        self
    }

    /// With per-vertex scalars (colour-mapped).
    pub fn with_scalars(mut self, scalars: &'a [Real]) -> Self {
        self.scalars = Some(scalars);
        self
    }

    /// With edges drawn on top.
    pub fn with_edges(mut self, color: Rgb) -> Self {
        self.edges = Some(color);
        self
    }
}

/// A point cloud to draw as depth-tested disks ("splats").
#[derive(Clone, Debug)]
pub struct CloudLayer<'a> {
    /// The points; with normals they are shaded like a surface, without they are flat.
    pub cloud: &'a PointCloud,
    /// One scalar per point, drawn with the colour map.
    pub scalars: Option<&'a [Real]>,
    /// Colour (without scalars).
    pub color: Rgb,
    /// Disk radius in pixels of the final picture.
    pub radius: Real,
}

impl<'a> CloudLayer<'a> {
    /// Points of radius 1.5 pixels in the default colour.
    pub fn new(cloud: &'a PointCloud) -> Self {
        CloudLayer {
            cloud,
            scalars: None,
            color: POINTS,
            radius: 1.5,
        }
    }
}

/// A short text drawn just right of and above a point, on top of everything
/// (not depth-tested), e.g. a control point's number.
///
/// ```
/// use subdyn::math::Point3;
/// use subdyn::render::{render, Label, MeshLayer, RenderOptions, Scene, EDGES};
/// let cube = subdyn::examples::cube();
/// let labels = vec![Label::new(cube.positions[0], "0")];
/// let scene = Scene { meshes: vec![MeshLayer::wireframe(&cube, EDGES)], labels, ..Scene::default() };
/// let picture = render(&scene, &RenderOptions { width: 64, height: 48, ..Default::default() })?;
/// assert!(picture.count(|c| c == EDGES) > 0);
/// # Ok::<(), subdyn::Error>(())
/// ```
#[derive(Clone, Debug)]
pub struct Label {
    /// The point labelled.
    pub at: Point3,
    /// The text (the bitmap font's characters).
    pub text: String,
    /// Its colour (default [`LABELS`]).
    pub color: Rgb,
}

/// Default colour of labels (a dark red).
pub const LABELS: Rgb = [170, 20, 20];

impl Label {
    /// A label in the default colour.
    pub fn new(at: Point3, text: impl Into<String>) -> Self {
        Label {
            at,
            text: text.into(),
            color: LABELS,
        }
    }
}

/// Everything to draw.
#[derive(Clone, Debug, Default)]
pub struct Scene<'a> {
    /// Meshes (surfaces and/or wireframes).
    pub meshes: Vec<MeshLayer<'a>>,
    /// Point clouds.
    pub clouds: Vec<CloudLayer<'a>>,
    /// Labels, drawn last.
    pub labels: Vec<Label>,
}

/// How to draw a [`Scene`]. Every field has a default (see [`Default`]).
#[derive(Clone, Debug)]
pub struct RenderOptions {
    /// Picture width in pixels, 1 to 8192 (default 640).
    pub width: u32,
    /// Picture height in pixels, 1 to 8192 (default 480).
    pub height: u32,
    /// Degrees about +Y; 0 looks from +Z, 90 from +X (default 30).
    pub azimuth: Real,
    /// Degrees above the XZ plane, −90 to 90 (default 20).
    pub elevation: Real,
    /// Orthographic (default) or perspective.
    pub projection: Projection,
    /// Free border around the geometry, as a fraction of the smaller side (default 0.05).
    pub margin: Real,
    /// Supersampling factor per axis, 1 to 4: the scene is drawn at `k`
    /// times the size and box-filtered down (default 1; `--ssaa` is 2).
    pub supersample: u32,
    /// Background colour (default white).
    pub background: Rgb,
    /// A line of text centred at the top (default none).
    pub title: Option<String>,
    /// Scalar values mapped to the two ends of the colour map (default: the
    /// smallest and largest finite scalar in the scene).
    pub scalar_range: Option<(Real, Real)>,
    /// Text above the legend bar, e.g. the unit (default none).
    pub legend_label: Option<String>,
    /// Draw the legend when some layer has scalars (default true).
    pub legend: bool,
    /// The colour map (default viridis).
    pub colormap: ColorMap,
    /// Eye-dome lighting on points without normals, so that a bare scan
    /// reads as a shape rather than a silhouette (default true).
    pub eye_dome: bool,
    /// Faces meeting at more than this many degrees are shaded with a sharp
    /// edge when normals come from the faces (default 40).
    pub crease_angle: Real,
}

impl Default for RenderOptions {
    fn default() -> Self {
        RenderOptions {
            width: 640,
            height: 480,
            azimuth: 30.0,
            elevation: 20.0,
            projection: Projection::Orthographic,
            margin: 0.05,
            supersample: 1,
            background: [255, 255, 255],
            title: None,
            scalar_range: None,
            legend_label: None,
            legend: true,
            colormap: ColorMap::Viridis,
            eye_dome: true,
            crease_angle: 40.0,
        }
    }
}

/// Largest number of pixels drawn at the working (supersampled) resolution.
pub const MAX_WORK_PIXELS: u64 = 1 << 26;

impl RenderOptions {
    /// Checks sizes, the supersampling factor and the margin.
    pub fn validate(&self) -> Result<()> {
        super::picture::check_size(self.width, self.height)?;
        if !(1..=4).contains(&self.supersample) {
            return Err(Error::out_of_range(format!(
                "supersampling factor {} is out of range: expected 1 to 4",
                self.supersample
            )));
        }
        let k = u64::from(self.supersample);
        let work = u64::from(self.width) * u64::from(self.height) * k * k;
        if work > MAX_WORK_PIXELS {
            return Err(Error::input(format!(
                "{}×{} with {k}× supersampling needs {work} working pixels; at most {MAX_WORK_PIXELS} are allowed",
                self.width, self.height
            )));
        }
        if !(0.0..0.5).contains(&self.margin) {
            return Err(Error::out_of_range(format!(
                "margin {} is out of range: expected 0 to 0.5",
                self.margin
            )));
        }
        if let Some((lo, hi)) = self.scalar_range
            && !(lo.is_finite() && hi.is_finite() && lo <= hi)
        {
            return Err(Error::input(format!(
                "scalar range {lo}..{hi}: expected two finite numbers, the first not above the second"
            )));
        }
        Ok(())
    }
}

/// Checks that per-vertex arrays match their geometry.
pub(crate) fn validate_scene(scene: &Scene) -> Result<()> {
    for (i, m) in scene.meshes.iter().enumerate() {
        let n = m.mesh.num_vertices();
        check_len("mesh", i, "normals", m.normals.map(<[_]>::len), n)?;
        check_len("mesh", i, "scalars", m.scalars.map(<[_]>::len), n)?;
        m.mesh.validate()?;
        if let Some(&(a, b)) = m
            .sharp
            .iter()
            .find(|&&(a, b)| a as usize >= n || b as usize >= n)
        {
            return Err(Error::input(format!(
                "mesh {i}: sharp edge {a} {b} names a vertex beyond its {n}"
            )));
        }
    }
    for (i, c) in scene.clouds.iter().enumerate() {
        check_len(
            "cloud",
            i,
            "scalars",
            c.scalars.map(<[_]>::len),
            c.cloud.len(),
        )?;
        check_len(
            "cloud",
            i,
            "normals",
            c.cloud.normals.as_ref().map(Vec::len),
            c.cloud.len(),
        )?;
        if !(c.radius.is_finite() && (0.0..=100.0).contains(&c.radius)) {
            return Err(Error::out_of_range(format!(
                "point radius {} pixels is out of range: expected 0 to 100",
                c.radius
            )));
        }
    }
    Ok(())
}

/// `Err` when an optional per-vertex array has the wrong length.
fn check_len(kind: &str, i: usize, what: &str, len: Option<usize>, n: usize) -> Result<()> {
    match len {
        Some(len) if len != n => Err(Error::size_mismatch(format!(
            "{kind} layer {i}: {len} {what} for {n} vertices"
        ))),
        _ => Ok(()),
    }
}
