//! The built-in session of `subdyn sculpt --demo` (McDonnell & Qin, figs.
//! 7–10 in spirit) on the paper's 3×3×3-point cube, and the picture strip of
//! its key frames.

use std::path::Path;

use subdyn::lattice::{Lattice, box_grid};
use subdyn::math::{Point3, bounding_box};
use subdyn::mesh::{PointCloud, PolyMesh};
use subdyn::render::{CloudLayer, MeshLayer, Picture, RenderOptions, Scene, render, write_png};

use super::sculpt::Snapshot;

/// The session: with the underside fixed, drag a corner with a rope and let
/// go (fig. 7), extrude a side face twice (fig. 9), trim a top corner cell
/// (fig. 8), fix the left side too and bend the arm up with a rope
/// (fig. 10), make plastic.
pub const DEMO_SCRIPT: &str = r#"{
  "dt": 0.002,
  "steps": 1000,
  "material": {"damping": 4.0},
  "ops": [
    {"step": 0,   "op": "fix", "box": [[-1, -1, -1], [3, 0.01, 3]]},
    {"step": 0,   "op": "rope", "at": [1, 1, 1], "to": [1.6, 1.8, 1.7], "until": 120, "stiffness": 150},
    {"step": 160, "op": "release"},
    {"step": 400, "op": "extrude", "near": [1, 0.75, 0.75]},
    {"step": 420, "op": "extrude", "near": [1.5, 0.75, 0.75]},
    {"step": 480, "op": "trim", "near": [0.25, 0.75, 0.75]},
    {"step": 560, "op": "fix", "box": [[-1, -1, -1], [0.01, 3, 3]]},
    {"step": 560, "op": "rope", "at": [2, 1, 1], "to": [1.7, 1.9, 1.0], "until": 760, "stiffness": 80},
    {"step": 800, "op": "plastic", "halt": true},
    {"step": 800, "op": "release"}
  ]
}"#;

/// Key frames of the picture: (step, caption).
pub const DEMO_SNAPSHOTS: [(usize, &str); 6] = [
    (0, "cube 3x3x3, level 2"),
    (140, "rope drag"),
    (470, "extrude twice"),
    (550, "trim a cell"),
    (790, "fix sides, pull"),
    (1000, "plastic: at rest"),
];

/// The paper's cube: 3×3×3 control points, 8 cells.
pub fn demo_lattice() -> anyhow::Result<Lattice> {
    Ok(box_grid(
        Point3::new(0.0, 0.0, 0.0),
        Point3::new(1.0, 1.0, 1.0),
        [2, 2, 2],
    )?)
}

/// Renders the snapshots side by side with one camera framing all of them.
pub fn write_strip(snapshots: &[Snapshot], path: &Path) -> anyhow::Result<()> {
    let all: Vec<Point3> = snapshots
        .iter()
        .flat_map(|s| s.surface.positions.iter().chain(&s.lattice.positions))
        .copied()
        .collect();
    let (lo, hi) = bounding_box(&all).ok_or_else(|| anyhow::anyhow!("no frame to draw"))?;
    let corners: Vec<Point3> = (0..8)
        .map(|i| {
            Point3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        })
        .collect();
    let frame_box = PolyMesh::from_faces(corners, &[vec![0, 1, 3, 2], vec![4, 6, 7, 5]])?;
    let (w, h) = (300u32, 280u32);
    let mut frames = Vec::with_capacity(snapshots.len());
    for s in snapshots {
        let caption = super::sculpt_demo::DEMO_SNAPSHOTS
            .iter()
            .find(|d| d.0 == s.step)
            .map_or(String::new(), |d| d.1.to_string());
        let fixed = PointCloud::new(s.fixed.clone(), None)?;
        let mut bounds = MeshLayer::wireframe(&frame_box, [255, 255, 255]);
        bounds.edges = None;
        let scene = Scene {
            meshes: vec![
                MeshLayer::new(&s.surface),
                MeshLayer::wireframe(&s.lattice, [40, 60, 160]),
                bounds,
            ],
            clouds: if s.fixed.is_empty() {
                Vec::new()
            } else {
                vec![CloudLayer {
                    color: [200, 30, 30],
                    radius: 4.0,
                    ..CloudLayer::new(&fixed)
                }]
            },
            labels: Vec::new(),
        };
        let options = RenderOptions {
            width: w,
            height: h,
            azimuth: 35.0,
            elevation: 25.0,
            supersample: 2,
            title: Some(format!("{caption} (step {})", s.step)),
            eye_dome: false,
            margin: 0.02,
            ..RenderOptions::default()
        };
        frames.push(render(&scene, &options)?);
    }
    write_png(path, &Picture::side_by_side(&frames)?)?;
    Ok(())
}
