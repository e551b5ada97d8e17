//! `subdyn render IN -o OUT.png`: draw a mesh (or its limit surface) and
//! point clouds with the software rasteriser of `subdyn::render`; a lattice
//! JSON file is drawn as a cage by [`super::render_lattice`].

use std::path::{Path, PathBuf};
use std::str::FromStr;

use clap::Args;

use subdyn::io::{read_mesh, read_points};
use subdyn::limit::tessellate;
use subdyn::math::{Real, bbox_diagonal};
use subdyn::mesh::{PointCloud, PolyMesh};
use subdyn::metrics::{TriangleBvh, distances};
use subdyn::render::{
    CloudLayer, DISTANCE_PERCENTILE, EDGES, Label, MAX_SIDE, MeshLayer, Projection, RenderOptions,
    Scene, check_png_path, distance_range, render, write_png,
};

use super::common::{Written, about_file, thousands};
use super::options::RefineArgs;
use super::progress::Progress;

/// Largest `--limit` accepted.
pub const MAX_LIMIT: usize = 64;
/// Most vertices `--label-vertices` numbers (more would cover the picture).
pub const MAX_LABELS: usize = 2_000;
/// Largest number of limit faces `--limit` may produce.
const MAX_LIMIT_FACES: f64 = 20_000_000.0;

/// Arguments of `subdyn render`.
#[derive(Debug, Args)]
#[command(
    after_help = "The view orbits the centre of the bounding box: azimuth 0, elevation 0 \
    looks from +Z with +Y up; azimuth 90 looks from +X. Front faces are blue-grey, back faces \
    orange. With --color-by-distance-to, the legend is in % of REF's bounding-box diagonal, \
    clipped at the 99th percentile unless --range is given."
)]
pub struct RenderArgs {
    /// Mesh or point file (.obj, .ply, .off, .xyz); a file without faces is
    /// drawn as points; a lattice (.json, as `subdyn lattice` writes it) as
    /// the edges of its cells with its control points as dots.
    #[arg(value_name = "IN")]
    pub input: PathBuf,
    /// Output picture (.png).
    #[arg(short, long, value_name = "OUT.png")]
    pub output: PathBuf,
    /// Also draw this point file as splats.
    #[arg(long, value_name = "CLOUD")]
    pub points: Option<PathBuf>,
    /// Colour IN's vertices (or points) by their distance to the surface of
    /// REF, in % of REF's bounding-box diagonal, with a legend; the colours
    /// span 0 to the 99th percentile of the distances (the legend then
    /// reads "dist % p99", larger ones take the top colour) unless --range
    /// is given.
    #[arg(long, value_name = "REF")]
    pub color_by_distance_to: Option<PathBuf>,
    /// View direction in degrees: azimuth about +Y, elevation above the XZ plane (−90 to 90).
    #[arg(
        long,
        value_name = "AZ,EL",
        default_value = "30,20",
        allow_hyphen_values = true
    )]
    pub view: String,
    /// Picture size in pixels (each side 1 to 8192).
    #[arg(
        long,
        value_name = "W,H",
        default_value = "640,480",
        allow_hyphen_values = true
    )]
    pub size: String,
    /// Draw the limit surface of IN instead of IN itself, each quad as a K×K grid of limit samples.
    #[arg(long, value_name = "K")]
    pub limit: Option<usize>,
    /// Overlay IN's edges (the control cage when --limit is given), its
    /// sharp edges (an OBJ's `t crease` tags, --creases) in red and twice
    /// as wide.
    #[arg(long)]
    pub cage: bool,
    /// Number IN's vertices in the picture (a lattice's control points: the
    /// numbers `subdyn ffd --moves` takes); at most 2,000 vertices.
    #[arg(long)]
    pub label_vertices: bool,
    /// Radius of point splats in pixels.
    #[arg(long, value_name = "R", default_value_t = 1.5)]
    pub point_size: Real,
    /// Perspective projection (30° field of view) instead of orthographic.
    #[arg(long)]
    pub perspective: bool,
    /// Anti-aliasing: draw at twice the size and average 2×2 blocks.
    #[arg(long)]
    pub ssaa: bool,
    /// A title line at the top of the picture.
    #[arg(long, value_name = "TEXT")]
    pub title: Option<String>,
    /// Values at the two ends of the colour map (default: smallest and
    /// largest; with --color-by-distance-to, 0 and the 99th percentile).
    #[arg(long, value_name = "MIN,MAX", allow_hyphen_values = true)]
    pub range: Option<String>,
    #[command(flatten)]
    pub refine: RefineArgs,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Runs `subdyn render`.
pub fn run(args: &RenderArgs) -> anyhow::Result<()> {
    check_png_path(&args.output)?;
    let options = options(args)?;
    if let Some(k) = args.limit
        && !(1..=MAX_LIMIT).contains(&k)
    {
        anyhow::bail!("--limit {k} is out of range: expected 1 to {MAX_LIMIT}");
    }
    if subdyn::io::is_lattice_file(&args.input) {
        return super::render_lattice::run(args, options);
    }
    if is_json(&args.input) {
        anyhow::bail!(
            "{}: not lattice JSON (an object with a \"vertices\" list); render draws .obj, .ply, .off and .xyz files and lattices",
            args.input.display()
        );
    }
    let progress = Progress::new(args.quiet);
    let name = args.input.display().to_string();

    progress.stage(format!("reading {name}"));
    let mesh = read_mesh(&args.input).map_err(|e| about_file(e, &args.input))?;
    let as_points = mesh.num_faces() == 0;
    if as_points && (args.limit.is_some() || args.cage) {
        anyhow::bail!(
            "{name}: the file has {} points but no faces; --limit and --cage need a polygon mesh",
            thousands(mesh.num_vertices())
        );
    }
    let cloud = if as_points {
        Some(read_points(&args.input).map_err(|e| about_file(e, &args.input))?)
    } else {
        None
    };
    let limit = match args.limit {
        Some(k) => {
            progress.stage(format!("tessellating the limit surface ({k}×{k} per quad)"));
            Some(limit_surface(args, &mesh, k, &name)?)
        }
        None => None,
    };
    let extra = match &args.points {
        Some(path) => {
            progress.stage(format!("reading {}", path.display()));
            Some(read_points(path).map_err(|e| about_file(e, path))?)
        }
        None => None,
    };

    // The drawn surface (or points) of IN: what gets coloured by distance.
    let (surface, normals) = match &limit {
        Some((m, n)) => (Some(m), Some(n.as_slice())),
        None if as_points => (None, None),
        None => (Some(&mesh), None),
    };
    let distance = match &args.color_by_distance_to {
        Some(reference) => {
            progress.stage(format!("distances to {}", reference.display()));
            let queries = match (surface, &cloud) {
                (Some(m), _) => &m.positions,
                (None, Some(c)) => &c.positions,
                (None, None) => &mesh.positions,
            };
            Some(distance_pct(queries, reference)?)
        }
        None => None,
    };

    let mut options = options;
    // Without --range, 0 to the 99th percentile: a hot spot takes the top
    // colour instead of squeezing everything else into the bottom one.
    let mut clip_note = String::new();
    if let Some(d) = &distance
        && options.scalar_range.is_none()
        && let Some((lo, hi)) = distance_range(d, DISTANCE_PERCENTILE)
    {
        options.scalar_range = Some((lo, hi));
        let max = d
            .iter()
            .copied()
            .filter(|x| x.is_finite())
            .fold(0.0, Real::max);
        if max > hi {
            let above = d.iter().filter(|&&x| x > hi).count();
            options.legend_label = Some("dist % p99".into());
            clip_note = format!(
                "colours 0 to {hi:.4} %, the 99th percentile of the distances; {} above it in the top colour, up to {max:.4} % (--range 0,{max:.4} shows all)\n",
                thousands(above)
            );
        }
    }
    // The cage's sharp edges (OBJ `t crease` tags, --creases), in red.
    let sharp: Vec<(u32, u32)> = if args.cage && !as_points {
        args.refine
            .options(&args.input)?
            .creases
            .iter()
            .filter(|c| c.2 > 0.0)
            .map(|c| (c.0, c.1))
            .collect()
    } else {
        Vec::new()
    };
    let mut scene = Scene::default();
    if let Some(m) = surface {
        let mut layer = MeshLayer::new(m);
        layer.normals = normals;
        layer.scalars = distance.as_deref();
        if args.cage && limit.is_none() {
            layer.edges = Some(EDGES);
            layer.sharp = &sharp;
        }
        scene.meshes.push(layer);
    }
    if args.cage && limit.is_some() {
        scene.meshes.push(MeshLayer {
            sharp: &sharp,
            ..MeshLayer::wireframe(&mesh, EDGES)
        });
    }
    for (c, scalars) in [(&cloud, distance.as_deref()), (&extra, None)] {
        if let Some(c) = c {
            let mut layer = CloudLayer::new(c);
            layer.radius = args.point_size;
            layer.scalars = if surface.is_none() { scalars } else { None };
            scene.clouds.push(layer);
        }
    }

    if args.label_vertices {
        scene.labels = vertex_labels(&mesh.positions, &name)?;
    }
    progress.stage("drawing");
    let picture = render(&scene, &options)?;
    progress.stage(format!("writing {}", args.output.display()));
    write_png(&args.output, &picture).map_err(|e| about_file(e, &args.output))?;
    drop(progress);
    let mut written = Written::new();
    written.add(
        &args.output,
        format!("picture, {}×{}", picture.width(), picture.height()),
    );
    written.print_after(&format!(
        "rendered {name} ({})\n{clip_note}",
        describe(surface, cloud.as_ref(), extra.as_ref()),
    ))
}

/// Whether `path` ends in `.json`.
pub fn is_json(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("json"))
}

/// Labels with the vertex numbers of `positions` (at most [`MAX_LABELS`]);
/// `name` names the file in the error.
pub fn vertex_labels(positions: &[subdyn::math::Point3], name: &str) -> anyhow::Result<Vec<Label>> {
    if positions.len() > MAX_LABELS {
        anyhow::bail!(
            "{name}: --label-vertices numbers at most {} vertices, the file has {}",
            thousands(MAX_LABELS),
            thousands(positions.len())
        );
    }
    Ok(positions
        .iter()
        .enumerate()
        .map(|(i, p)| Label::new(*p, i.to_string()))
        .collect())
}

/// Checks and gathers the picture options.
fn options(args: &RenderArgs) -> anyhow::Result<RenderOptions> {
    let (width, height): (u32, u32) = pair(
        &args.size,
        "--size",
        &format!("W,H with each side 1 to {MAX_SIDE} pixels, e.g. 640,480"),
    )?;
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
        anyhow::bail!(
            "--size {width},{height} is out of range: each side must be 1 to {MAX_SIDE} pixels"
        );
    }
    let (azimuth, elevation): (Real, Real) =
        pair(&args.view, "--view", "AZ,EL in degrees, e.g. 30,20")?;
    if !azimuth.is_finite() || !(-90.0..=90.0).contains(&elevation) {
        anyhow::bail!(
            "--view {}: the azimuth must be finite and the elevation between -90 and 90 degrees",
            args.view
        );
    }
    let scalar_range = match &args.range {
        Some(r) => {
            let (lo, hi): (Real, Real) = pair(r, "--range", "MIN,MAX, e.g. 0,0.5")?;
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                anyhow::bail!("--range {r}: expected two finite numbers, MIN below MAX");
            }
            Some((lo, hi))
        }
        None => None,
    };
    if !(args.point_size.is_finite() && (0.0..=100.0).contains(&args.point_size)) {
        anyhow::bail!(
            "--point-size {} is out of range: expected 0 to 100 pixels",
            args.point_size
        );
    }
    Ok(RenderOptions {
        width,
        height,
        azimuth,
        elevation,
        projection: if args.perspective {
            Projection::Perspective { fov_deg: 30.0 }
        } else {
            Projection::Orthographic
        },
        supersample: if args.ssaa { 2 } else { 1 },
        title: args.title.clone(),
        scalar_range,
        legend_label: args
            .color_by_distance_to
            .as_ref()
            .map(|_| "dist %".to_string()),
        ..RenderOptions::default()
    })
}

/// Parses `"a,b"` into two values; the error names the option and the expected form.
fn pair<T: FromStr>(text: &str, option: &str, expected: &str) -> anyhow::Result<(T, T)> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    match parts.as_slice() {
        [a, b] => match (a.parse::<T>(), b.parse::<T>()) {
            (Ok(a), Ok(b)) => Ok((a, b)),
            _ => anyhow::bail!("{option} {text:?}: expected {expected}"),
        },
        _ => anyhow::bail!("{option} {text:?}: expected {expected}"),
    }
}

/// The limit surface of `mesh` as a K×K-per-quad tessellation with exact normals.
fn limit_surface(
    args: &RenderArgs,
    mesh: &PolyMesh,
    k: usize,
    name: &str,
) -> anyhow::Result<(PolyMesh, Vec<subdyn::math::Vector3>)> {
    let quads: usize = mesh
        .faces()
        .map(|f| if f.len() == 4 { 1 } else { f.len() })
        .sum();
    let faces = quads as f64 * (k * k) as f64;
    if faces > MAX_LIMIT_FACES {
        anyhow::bail!(
            "{name}: --limit {k} would make about {} faces (at most {} allowed); use a smaller K",
            thousands(faces as usize),
            thousands(MAX_LIMIT_FACES as usize)
        );
    }
    let refiner = args.refine.refiner(mesh, Path::new(name))?;
    tessellate(&refiner, &mesh.positions, k).map_err(|e| about_file(e, Path::new(name)))
}

/// Distance of every query to the surface of the mesh in `reference`, in %
/// of the reference's bounding-box diagonal.
fn distance_pct(queries: &[subdyn::math::Point3], reference: &Path) -> anyhow::Result<Vec<Real>> {
    let mesh = read_mesh(reference).map_err(|e| about_file(e, reference))?;
    let bvh = TriangleBvh::from_mesh(&mesh).map_err(|e| about_file(e, reference))?;
    let diag = bbox_diagonal(&mesh.positions);
    if diag.is_nan() || diag <= 0.0 {
        anyhow::bail!(
            "{}: the mesh has no extent (all vertices coincide)",
            reference.display()
        );
    }
    let found = distances(&bvh, queries)?;
    Ok(found.iter().map(|n| 100.0 * n.distance / diag).collect())
}

/// "5,856 faces" / "40,097 points" / "… + 1,000 points".
fn describe(
    surface: Option<&PolyMesh>,
    cloud: Option<&PointCloud>,
    extra: Option<&PointCloud>,
) -> String {
    let mut parts = Vec::new();
    if let Some(m) = surface {
        parts.push(format!("{} faces", thousands(m.num_faces())));
    }
    for c in [cloud, extra].into_iter().flatten() {
        parts.push(format!("{} points", thousands(c.len())));
    }
    parts.join(" + ")
}
