//! `subdyn recover VOLUME [--seed x,y,z | --auto] [--iso T] -o SHAPE.obj`:
//! recover a closed shape from a volume (MRI, CT, slice stack) with a
//! dynamic Catmull-Clark surface pulled by image forces.

use std::path::{Path, PathBuf};
use std::time::Instant;

use clap::Args;

use super::fit::RefineMode;
use serde_json::json;

use subdyn::fit::Refinement;
use subdyn::fit::recover::{
    BONE_HU, PreparedVolume, RecoverParams, RecoverReport, RecoverStart, SKIN_HU, opened_at_box,
    poor_result, prepare_volume_owned, recover_shape,
};
use subdyn::forces::BoundaryModel;
use subdyn::io::{VolumeFile, VolumeReadOptions, read_points, read_volume, write_mesh};
use subdyn::limit::tessellate;
use subdyn::math::{Point3, Real};
use subdyn::mesh::PolyMesh;
use subdyn::subdivision::{RefineOptions, Refiner};

use super::common::{
    Written, about_file, check_mesh_output, check_output_dir, print_stdout, seconds, thousands,
    write_report,
};
use super::memory::{StagePeaks, peak_rss, stage_peak};
use super::options::{LimitOutArgs, read_polygon_mesh};
use super::progress::Progress;

/// Arguments of `subdyn recover`.
#[derive(Debug, Args)]
pub struct RecoverArgs {
    /// The volume: a NIfTI-1 file (.nii, .nii.gz), a multi-page TIFF, a
    /// directory of PNG/TIFF/EXR slices (sorted by the number in the name),
    /// or a raw file with its JSON header.
    #[arg(value_name = "VOLUME")]
    pub input: PathBuf,
    /// Output control mesh; the format follows the extension.
    #[arg(short, long, value_name = "SHAPE", default_value = "shape.obj")]
    pub output: PathBuf,
    /// Grow the model from a small sphere at this world point (x,y,z), which
    /// must lie inside the object (genus 0 only); with --auto, start from the
    /// connected component holding this point alone.
    #[arg(long, value_name = "x,y,z", value_parser = parse_triple, allow_hyphen_values = true, conflicts_with = "init")]
    pub seed: Option<[f64; 3]>,
    /// Start from the boundary of the object above the inside level (the
    /// iso-value, or Otsu's threshold): its largest connected component and
    /// every other of at least 1 % of its voxels, each a closed cage; any
    /// genus. The default.
    #[arg(long)]
    pub auto: bool,
    /// Start from this closed control mesh instead (world coordinates).
    #[arg(long, value_name = "MESH", conflicts_with = "auto")]
    pub init: Option<PathBuf>,
    /// The boundary is the level set at this intensity (e.g. CT Hounsfield
    /// units, negative ones too: --iso -300; 0.5 of a probability map).
    /// Without it (or --preset) the boundary is the level the volume's JSON
    /// sidecar names (`iso_value`, as data-gen writes), else the strongest
    /// nearby edge of the smoothed image.
    #[arg(long, value_name = "T", allow_negative_numbers = true)]
    pub iso: Option<f64>,
    /// A CT iso-value in Hounsfield units (NIfTI scl_slope / scl_inter are
    /// applied on reading): skin = -500 HU (half-way from air, -1000, to soft
    /// tissue, 0), bone = +300 HU (above soft tissue, below cortical bone).
    #[arg(long, value_enum, conflicts_with = "iso")]
    pub preset: Option<CtPreset>,
    /// The boundary is the strongest nearby edge (not a sidecar's
    /// `iso_value`); edges weaker than this fraction of the volume's
    /// strongest are ignored (default 0.1).
    #[arg(long, value_name = "F", conflicts_with_all = ["iso", "preset"])]
    pub edge_strength: Option<f64>,
    /// The object is darker than its surroundings (ventricles in T1 MRI, air).
    #[arg(long)]
    pub dark: bool,
    /// Gaussian smoothing σ in world units (default: a quarter of a voxel with --iso, one voxel for edges; the --auto cage is taken at half a voxel or more).
    #[arg(long, value_name = "S")]
    pub sigma: Option<f64>,
    /// Voxel spacing for formats without it (world = origin + index × spacing).
    #[arg(long, value_name = "sx,sy,sz", value_parser = parse_triple)]
    pub spacing: Option<[f64; 3]>,
    /// World position of voxel (0,0,0) for formats without it.
    #[arg(long, value_name = "ox,oy,oz", value_parser = parse_triple, allow_hyphen_values = true)]
    pub origin: Option<[f64; 3]>,
    /// Stop when the 95th percentile of the surface-to-boundary offsets is below this many voxels.
    #[arg(long, value_name = "VOXELS", default_value_t = 0.5)]
    pub tol: f64,
    /// Subdivision levels allowed above the initial cage.
    #[arg(long, value_name = "L", default_value_t = 3)]
    pub max_level: usize,
    /// Cells along the object's longest side for --auto's cage.
    #[arg(long, value_name = "N", default_value_t = 24)]
    pub resolution: usize,
    /// Radius of the --seed sphere in voxels.
    #[arg(long, value_name = "VOXELS", default_value_t = 3.0)]
    pub seed_radius: f64,
    /// User-placed boundary points (any point file: .xyz, .ply, .obj, .off),
    /// each pulling its closest point of the surface with a spring: for
    /// boundaries the image does not show (the paper's caudate nucleus).
    #[arg(long, value_name = "FILE")]
    pub points: Option<PathBuf>,
    /// Total stiffness of the --points springs relative to the image springs.
    #[arg(long, value_name = "W", default_value_t = RecoverParams::default().points_weight)]
    pub points_weight: f64,
    /// Total stiffness of the two-sided forces relative to the image springs
    /// (0: off). With --auto, the object's iso-surface points farther than
    /// --two-sided-distance from the surface pull it, so a part the surface
    /// misses (a horn tip, a leg the cage lost) is pulled out.
    #[arg(long, value_name = "W", default_value_t = RecoverParams::default().two_sided_weight)]
    pub two_sided_weight: f64,
    /// How far (voxels) an iso-surface point must be from the surface to pull it.
    #[arg(long, value_name = "VOXELS", default_value_t = RecoverParams::default().two_sided_voxels)]
    pub two_sided_distance: f64,
    /// Largest share of iso-surface points farther than --two-sided-distance
    /// from the surface for the tolerance to count as met.
    #[arg(long, value_name = "F", default_value_t = RecoverParams::default().max_unmatched)]
    pub max_unmatched: f64,
    /// How a level above the tolerance is refined: the faces off the
    /// boundary (adaptive) or every face (uniform).
    #[arg(long, value_enum, default_value_t = RefineMode::Adaptive)]
    pub refine: RefineMode,
    /// An adaptive level has at most this many times its parent's control points.
    #[arg(long, value_name = "F", default_value_t = RecoverParams::default().max_level_growth)]
    pub max_level_growth: f64,
    /// Adaptive levels stop adding control points at this share of the
    /// object's iso-surface points (marching cubes' vertex count).
    #[arg(long, value_name = "F", default_value_t = RecoverParams::default().max_control_share)]
    pub max_control_share: f64,
    /// Bending weight λ_b of the thin plate.
    #[arg(long, value_name = "λ", default_value_t = RecoverParams::default().bending)]
    pub bending: f64,
    #[command(flatten)]
    pub limit: LimitOutArgs,
    /// Write a JSON report (stage times, per level: control points, steps, offsets).
    #[arg(long, value_name = "FILE")]
    pub report: Option<PathBuf>,
    /// Write slices with the recovered contour (yellow) and the initial one
    /// (blue) over the image to this directory: three axial slices, one
    /// coronal, one sagittal, in the radiological convention (right on the
    /// left, anterior or superior up), labelled with their world position.
    #[arg(long, value_name = "DIR")]
    pub slices_png: Option<PathBuf>,
    /// Write the result even when it is poor: its surface leaves the
    /// volume's box, too much of it found no boundary ("unresolved"), or a
    /// finer level followed the image worse than its parent. Without it such
    /// a result is an error and nothing is written.
    #[arg(long)]
    pub accept_poor: bool,
    /// Leave an object cut by the volume's box open there: the cap on the
    /// box face is removed and the rim moved onto the face (by default the
    /// surface closes on the box faces, as marching cubes on a padded
    /// volume does).
    #[arg(long)]
    pub open_at_box: bool,
    /// No progress display.
    #[arg(short, long)]
    pub quiet: bool,
}

/// CT presets of `--preset`: iso-values in Hounsfield units.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum CtPreset {
    /// The skin: -500 HU ([`SKIN_HU`]).
    Skin,
    /// Bone: +300 HU ([`BONE_HU`]).
    Bone,
}

impl CtPreset {
    /// The iso-value in Hounsfield units.
    fn hounsfield(self) -> f64 {
        match self {
            CtPreset::Skin => SKIN_HU,
            CtPreset::Bone => BONE_HU,
        }
    }
}

fn parse_triple(s: &str) -> Result<[f64; 3], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("'{s}': {e}; expected three numbers x,y,z"))?;
    match v.as_slice() {
        [a, b, c] if v.iter().all(|x| x.is_finite()) => Ok([*a, *b, *c]),
        _ => Err(format!("'{s}': expected three finite numbers x,y,z")),
    }
}

/// Runs `subdyn recover`.
pub fn run(args: &RecoverArgs) -> anyhow::Result<()> {
    let start = Instant::now();
    check_mesh_output(&args.output)?;
    args.limit.check()?;
    if let Some(p) = &args.report {
        check_output_dir(p)?;
    }
    if let Some(dir) = &args.slices_png {
        subdyn::io::check_output_dir_path(dir)?;
    }
    // The boundary the command line chose, if it chose one.
    let chosen = match (
        args.iso.or(args.preset.map(CtPreset::hounsfield)),
        args.edge_strength,
    ) {
        (Some(value), _) => Some(BoundaryModel::Iso { value }),
        (None, Some(min_strength)) => Some(BoundaryModel::Edge { min_strength }),
        (None, None) => None,
    };
    let mut params = RecoverParams {
        boundary: chosen.unwrap_or(RecoverParams::default().boundary),
        sigma: args.sigma,
        bright_inside: !args.dark,
        tolerance_voxels: args.tol,
        max_level: args.max_level,
        bending: args.bending,
        points_weight: args.points_weight,
        two_sided_weight: args.two_sided_weight,
        two_sided_voxels: args.two_sided_distance,
        max_unmatched: args.max_unmatched,
        refinement: match args.refine {
            RefineMode::Adaptive => Refinement::Adaptive,
            RefineMode::Uniform => Refinement::Uniform,
        },
        max_level_growth: args.max_level_growth,
        max_control_share: args.max_control_share,
        ..Default::default()
    };
    params.check()?;
    let points = match &args.points {
        Some(path) => {
            read_points(path)
                .map_err(|e| about_file(e, path))?
                .positions
        }
        None => Vec::new(),
    };
    let progress = Progress::new(args.quiet);
    progress.stage(format!("reading {}", args.input.display()));
    let t = Instant::now();
    let read_options = VolumeReadOptions {
        spacing: args.spacing,
        origin: args.origin,
    };
    let VolumeFile {
        volume: input,
        source,
        mut notes,
        iso_value,
    } = read_volume(&args.input, &read_options).map_err(|e| about_file(e, &args.input))?;
    // A sidecar that names the surface's level is taken at its word unless
    // the command line chose the boundary.
    if let Some(value) = iso_value
        && chosen.is_none()
    {
        params.boundary = BoundaryModel::Iso { value };
        params.check()?;
        notes.push(format!(
            "iso-value {value} from the sidecar's iso_value (--iso T for another level, --edge-strength F for the edge model)"
        ));
    }
    let read_s = seconds(t);
    let read_peak = peak_rss();
    // The input is smoothed in its own memory and given up; the smoothed
    // volume has the same grid, and --slices-png reads the input again.
    let volume_bytes = 4 * input.data().len() as u64;
    progress.stage("smoothing and edge detection");
    let (prepared, prepare_peak) = stage_peak(|| prepare_volume_owned(input, &params));
    let prepared = prepared.map_err(|e| {
        anyhow::Error::new(e).context(format!("preparing {}", args.input.display()))
    })?;
    progress.stage("building the initial model");
    let t = Instant::now();
    let (init, init_peak) = stage_peak(|| initial_model(args, &prepared));
    let subdyn::fit::recover::InitialModel {
        mesh: init,
        boundary,
        report: init_json,
    } = init?;
    let init_s = seconds(t);
    let levels = params.max_level as u64 + 1;
    let mut on_step = |level: usize, step: usize, energy: f64| {
        progress.counted(
            level as u64,
            levels,
            format!("levels (at most) · level {level}, step {step}: energy {energy:.4e}"),
        );
    };
    let (result, evolution_peak) =
        stage_peak(|| recover_shape(&prepared, &init, &points, &boundary, &params, &mut on_step));
    let result = result.map_err(|e| {
        anyhow::Error::new(e).context(format!("recovering from {}", args.input.display()))
    })?;
    let problems = poor_result(&result.report, &params);
    if !problems.is_empty() && !args.accept_poor {
        drop(progress);
        print_stdout(&summary(args, &notes, read_s, init_s, &result.report))?;
        anyhow::bail!(
            "poor result from {}, nothing written: {}; --accept-poor writes it anyway",
            args.input.display(),
            problems.join("; ")
        );
    }
    let memory = StagePeaks {
        volume_bytes,
        stages: vec![
            ("read", read_peak),
            ("smoothing", prepare_peak),
            ("initial model", init_peak),
            ("evolution", evolution_peak),
        ],
    };
    let opened;
    let control = if args.open_at_box {
        opened = opened_at_box(&result.control, &prepared.smoothed)?;
        &opened
    } else {
        &result.control
    };
    progress.stage(format!("writing {}", args.output.display()));
    write_mesh(&args.output, control, None).map_err(|e| about_file(e, &args.output))?;
    let mut written = Written::new();
    written.add(&args.output, "control mesh");
    let surface = |mesh: &PolyMesh| -> anyhow::Result<(PolyMesh, Vec<subdyn::math::Vector3>)> {
        let refiner = Refiner::new(mesh, &RefineOptions::default())?;
        Ok(tessellate(&refiner, &mesh.positions, args.limit.tess)?)
    };
    let (surf, normals) = surface(control)?;
    if let Some(path) = &args.limit.limit_out {
        write_mesh(path, &args.limit.faces.mesh(&surf), Some(&normals))
            .map_err(|e| about_file(e, path))?;
        written.add(path, "limit surface");
    }
    let mut slice_files = Vec::new();
    if let Some(dir) = &args.slices_png {
        progress.stage("drawing slices");
        let (init_surf, _) = surface(&init)?;
        let image = read_volume(&args.input, &read_options)
            .map_err(|e| about_file(e, &args.input))?
            .volume;
        slice_files = write_slices(dir, &args.input, &image, &surf, &init_surf)?;
        for file in &slice_files {
            written.add(Path::new(file), "slice picture");
        }
    }
    drop(progress);
    if let Some(path) = &args.report {
        let (dims, origin) = prepared.input_grid();
        let value = json!({
            "command": "recover",
            "input": args.input.display().to_string(),
            "format": source,
            "notes": notes,
            "dims": dims,
            "spacing": prepared.smoothed.spacing(),
            "origin": [origin.x, origin.y, origin.z],
            "padding": PreparedVolume::PADDING,
            "poor_result": problems,
            "output": args.output.display().to_string(),
            "limit_out": args.limit.limit_out.as_ref().map(|p| p.display().to_string()),
            "init": init_json,
            "stages_s": {
                "read": read_s,
                "smoothing": prepared.smoothing_seconds,
                "potential": prepared.potential_seconds,
                "init": init_s,
                "evolution": result.report.levels.iter().map(|l| l.seconds).sum::<f64>(),
            },
            "recover": serde_json::to_value(&result.report)?,
            "peak_memory": memory.json(),
            "slices": slice_files,
            "total_s": seconds(start),
        });
        write_report(path, &value)?;
        written.add(path, "report");
    }
    let mut text = summary(args, &notes, read_s, init_s, &result.report);
    for p in &problems {
        text.push_str(&format!("poor result accepted (--accept-poor): {p}\n"));
    }
    text.push_str(&memory.line());
    written.print_after(&text)
}

/// The initial control mesh from --seed, --init or --auto.
fn initial_model(
    args: &RecoverArgs,
    prepared: &PreparedVolume,
) -> anyhow::Result<subdyn::fit::recover::InitialModel> {
    let seed = args.seed.map(|s| Point3::new(s[0], s[1], s[2]));
    let start = match (&args.init, seed) {
        (Some(path), _) => RecoverStart::Mesh(read_polygon_mesh(path, args.quiet)?),
        (None, Some(point)) if !args.auto => RecoverStart::Seed {
            point,
            radius_voxels: args.seed_radius,
        },
        _ => RecoverStart::Auto {
            seed,
            resolution: args.resolution,
        },
    };
    let mut model =
        subdyn::fit::recover::initial_model(prepared, &start, !args.dark).map_err(|e| {
            match cli_wording(&e.to_string()) {
                Some(line) => anyhow::anyhow!(line),
                None => anyhow::Error::new(e),
            }
        })?;
    if let Some(path) = &args.init {
        model.report["method"] = json!("file");
        model.report["path"] = json!(path.display().to_string());
    }
    Ok(model)
}

/// The library's message about the seed or the resolution in the words of
/// the command line (`--seed …`, `--seed-radius …`, `--resolution …`).
fn cli_wording(message: &str) -> Option<String> {
    let message = message.strip_prefix("input: ")?;
    ["seed radius ", "seed ", "resolution "]
        .iter()
        .find_map(|name| {
            message
                .strip_prefix(name)
                .map(|rest| format!("--{} {rest}", name.trim().replace(' ', "-")))
        })
}

/// Three axial slices through the object (at a quarter, half and three
/// quarters of its world z extent), and the coronal and sagittal slices
/// through its middle, in the radiological convention
/// ([`slice_overlay`](subdyn::render::slice_overlay)); positions in mm for
/// NIfTI input (RAS+ mm), in world units otherwise.
fn write_slices(
    dir: &Path,
    input: &Path,
    volume: &subdyn::volume::Volume,
    surface: &PolyMesh,
    initial: &PolyMesh,
) -> anyhow::Result<Vec<String>> {
    use subdyn::render::{slice_overlay, write_png};
    subdyn::io::create_output_dir(dir)?;
    let name = input.to_string_lossy().to_ascii_lowercase();
    let unit = if name.ends_with(".nii") || name.ends_with(".nii.gz") {
        "mm"
    } else {
        ""
    };
    let at = |a: usize, f: Real| {
        let (lo, hi) = surface
            .positions
            .iter()
            .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), p| {
                (lo.min(p[a]), hi.max(p[a]))
            });
        lo + f * (hi - lo)
    };
    let views = [
        (2, at(2, 0.25)),
        (2, at(2, 0.5)),
        (2, at(2, 0.75)),
        (1, at(1, 0.5)),
        (0, at(0, 0.5)),
    ];
    let mut files = Vec::new();
    for (axis, position) in views {
        let pic = slice_overlay(
            volume,
            axis,
            position,
            512,
            &[(initial, [60, 140, 255]), (surface, [255, 220, 0])],
            unit,
        )?;
        let path = dir.join(format!(
            "{}_{}{:.1}.png",
            ["sagittal", "coronal", "axial"][axis],
            ["x", "y", "z"][axis],
            (10.0 * position).round() / 10.0 + 0.0
        ));
        write_png(&path, &pic).map_err(|e| about_file(e, &path))?;
        files.push(path.display().to_string());
    }
    Ok(files)
}

fn summary(
    args: &RecoverArgs,
    notes: &[String],
    read_s: f64,
    init_s: f64,
    r: &RecoverReport,
) -> String {
    let mut s = format!(
        "recovered {} in {:.2} s: {}\n",
        args.input.display(),
        r.seconds + read_s + init_s,
        r.stop_reason
    );
    for n in notes {
        s.push_str(&format!("note: {n}\n"));
    }
    s.push_str(&format!(
        "stages: read {read_s:.2} s, smoothing {:.2} s, edges {:.2} s, initial model {init_s:.2} s; voxel {:.4}, σ {:.4}, inside level {:.4}\n",
        r.smoothing_seconds, r.potential_seconds, r.voxel, r.sigma, r.inside_level
    ));
    s.push_str(
        "level  control points  samples  steps  seconds  p95 vox  RMS vox  max vox  unresolved\n",
    );
    for l in &r.levels {
        s.push_str(&format!(
            "{:>5}  {:>14}  {:>7}  {:>5}  {:>7.2}  {:>7.3}  {:>7.3}  {:>7.3}  {:>9.1}%\n",
            l.level,
            thousands(l.control_points),
            thousands(l.samples),
            l.steps,
            l.seconds,
            l.offsets.p95,
            l.offsets.rms,
            l.offsets.max,
            100.0 * l.unresolved
        ));
    }
    s.push_str(
        "(offsets: surface to the boundary found along its normal; unresolved: share of the surface that found no boundary within the search range along its normal (± a third of the median control edge, 2 to 12 voxels), so the thin plate, not the image, placed it)\n",
    );
    s
}
