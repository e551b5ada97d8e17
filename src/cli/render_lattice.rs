//! `subdyn render LAT.json -o OUT.png [--label-vertices]`: a lattice (the
//! file `subdyn lattice` writes) drawn as a cage: every cell edge, the
//! control points as dots, optionally numbered, so a user can see which
//! points to move with `subdyn ffd --moves`.

use subdyn::io::{read_lattice, read_points};
use subdyn::mesh::PointCloud;
use subdyn::render::{CloudLayer, EDGES, MeshLayer, RenderOptions, Scene, render, write_png};

use super::common::{Written, about_file, thousands};
use super::render::{RenderArgs, vertex_labels};

/// Colour of the control-point dots.
const CONTROL_POINTS: [u8; 3] = [200, 40, 40];

/// Draws the lattice in `args.input` with `options`.
pub fn run(args: &RenderArgs, options: RenderOptions) -> anyhow::Result<()> {
    let name = args.input.display().to_string();
    for (given, flag) in [
        (args.limit.is_some(), "--limit"),
        (args.cage, "--cage"),
        (
            args.color_by_distance_to.is_some(),
            "--color-by-distance-to",
        ),
    ] {
        if given {
            anyhow::bail!(
                "{name}: {flag} is for meshes; a lattice is always drawn as the edges of its cells"
            );
        }
    }
    let lattice = read_lattice(&args.input).map_err(|e| about_file(e, &args.input))?;
    let cage = lattice
        .all_faces_mesh()
        .map_err(|e| about_file(e, &args.input))?;
    let dots = PointCloud::new(lattice.positions.clone(), None)?;
    let extra = match &args.points {
        Some(path) => Some(read_points(path).map_err(|e| about_file(e, path))?),
        None => None,
    };
    let mut scene = Scene::default();
    scene.meshes.push(MeshLayer::wireframe(&cage, EDGES));
    scene.clouds.push(CloudLayer {
        color: CONTROL_POINTS,
        radius: 2.0 * args.point_size,
        ..CloudLayer::new(&dots)
    });
    if let Some(c) = &extra {
        scene.clouds.push(CloudLayer {
            radius: args.point_size,
            ..CloudLayer::new(c)
        });
    }
    if args.label_vertices {
        scene.labels = vertex_labels(&lattice.positions, &name)?;
    }
    let picture = render(&scene, &options)?;
    write_png(&args.output, &picture).map_err(|e| about_file(e, &args.output))?;
    let mut written = Written::new();
    written.add(
        &args.output,
        format!("picture, {}×{}", picture.width(), picture.height()),
    );
    written.print_after(&format!(
        "rendered the lattice {name} ({} control points{}, {} cells){}\n",
        thousands(lattice.num_vertices()),
        if args.label_vertices {
            ", numbered"
        } else {
            ""
        },
        thousands(lattice.topology.num_cells()),
        extra.as_ref().map_or(String::new(), |c| format!(
            " + {} points",
            thousands(c.len())
        ))
    ))
}
