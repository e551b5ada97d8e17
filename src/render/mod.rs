//! A small software rasteriser for looking at results: z-buffer, Lambert
//! shading with a headlight, point splats, edge overlays, a perceptual colour
//! map with a legend for per-vertex scalars (distances), PNG output.
//!
//! ```
//! use subdyn::render::{render, write_png, MeshLayer, RenderOptions, Scene, EDGES};
//! # let dir = tempfile::tempdir().unwrap();
//! let cube = subdyn::examples::cube();
//! let heights: Vec<f64> = cube.positions.iter().map(|p| p.y).collect();
//! let scene = Scene {
//!     meshes: vec![MeshLayer::new(&cube).with_scalars(&heights).with_edges(EDGES)],
//!     ..Scene::default()
//! };
//! let options = RenderOptions { title: Some("cube".into()), ..RenderOptions::default() };
//! let picture = render(&scene, &options)?;
//! write_png(&dir.path().join("cube.png"), &picture)?;
//! # Ok::<(), subdyn::Error>(())
//! ```
//!
//! Files: `camera` (orbit view, fit), `raster` (triangles, top-left rule,
//! z-buffer), `marks` (lines, disks), `eye_dome`
//! (screen-space shading of bare points), `shading` (normals, Lambert),
//! `colormap` + `viridis` (the table), `font` (5×7 bitmap), `legend`
//! (colour bar, ticks, title), `scene` (layers, options), `draw` (`render`),
//! `picture` (`Picture`, PNG).

mod camera;
mod colormap;
mod draw;
mod eye_dome;
mod font;
mod legend;
mod marks;
mod picture;
mod plot;
mod raster;
mod scene;
mod shading;
mod slices;
mod viridis;

pub use camera::{Camera, Projection, ScreenPoint};
pub use colormap::{ColorMap, DISTANCE_PERCENTILE, NO_VALUE, distance_range};
pub use draw::render;
pub use font::{draw_text, text_width};
pub use legend::{log_tick_labels, log_ticks, nice_ticks, tick_labels};
pub use picture::{MAX_SIDE, Picture, Rgb, check_png_path, write_png};
pub use plot::{HLine, PlotOptions, Series, line_plot, series_color};
pub use scene::{
    BACK, CloudLayer, EDGES, LABELS, Label, MAX_WORK_PIXELS, MeshLayer, POINTS, RenderOptions,
    SHARP_EDGES, SURFACE, Scene,
};
pub use shading::{AMBIENT, corner_normals, face_normals};
pub use slices::slice_overlay;
