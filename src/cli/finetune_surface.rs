//! `subdyn finetune surface MESH --edge-values V.json -o OUT.obj`.
//!
//! Edge-values JSON: `{"default": 1.0, "edges": [[i, j, a], …]}` — the edge
//! between vertices `i` and `j` (0-based, as in MESH) gets control value
//! `a > 0`; every other edge gets `default` (1 when absent).

use std::path::{Path, PathBuf};

use clap::{Args, ValueEnum};
use serde_json::{Value, json};

use subdyn::finetune::{FinetuneMethod, SurfaceFineTune, SurfaceFineTuneParams, SurfaceScheme};
use subdyn::io::{atomic_write, write_mesh};
use subdyn::math::Real;
use subdyn::subdivision::NonUniformHierarchy;
use subdyn::topology::Level;

use super::common::{Written, about_file, check_mesh_output, check_output_dir, write_report};
use super::options::read_polygon_mesh;

/// The scheme of the input mesh.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum InputScheme {
    /// Doo-Sabin control mesh (converted to non-uniform Catmull-Clark).
    #[default]
    DooSabin,
    /// Catmull-Clark control mesh (legs scaled directly; approximate).
    CatmullClark,
}

/// Arguments of `subdyn finetune surface`.
#[derive(Debug, Args)]
pub struct SurfaceArgs {
    /// Control mesh (.obj, .ply, .off).
    #[arg(value_name = "MESH")]
    pub input: PathBuf,
    /// Scheme of MESH.
    #[arg(long, value_enum, default_value_t = InputScheme::DooSabin)]
    pub scheme: InputScheme,
    /// Control values per edge: {"default": 1.0, "edges": [[i, j, a], ...]}.
    #[arg(long, value_name = "V.json")]
    pub edge_values: PathBuf,
    /// Vertices of MESH that stay put, comma-separated (e.g. 0,4,7).
    #[arg(long, value_name = "IDS", value_delimiter = ',')]
    pub fix: Vec<u32>,
    /// Spring coefficients k_l,k_a,k_b of energy (14).
    #[arg(long, value_name = "KL,KA,KB", value_delimiter = ',', default_values_t = [1.0, 1.0, 1.0])]
    pub k: Vec<Real>,
    /// Knot interval in place of 0 on converted face edges (Doo-Sabin input).
    #[arg(long, default_value_t = 0.05)]
    pub epsilon: Real,
    /// Most iterations of the minimiser.
    #[arg(long, default_value_t = 2000)]
    pub max_iters: u64,
    /// Minimiser of energy (14): lm (Levenberg-Marquardt) or ncg (argmin's nonlinear CG).
    #[arg(long, value_name = "lm|ncg", default_value = "lm")]
    pub method: FinetuneMethod,
    /// Output: the fine-tuned (non-uniform Catmull-Clark) control mesh.
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Also write its knot intervals, lines `i j d` (for `subdivide --scheme non-uniform --knots`).
    #[arg(long, value_name = "FILE")]
    pub knots_out: Option<PathBuf>,
    /// Also write the fine-tuned surface refined `--levels` times.
    #[arg(long, value_name = "FILE")]
    pub refined: Option<PathBuf>,
    /// Levels for `--refined` (0 to 6).
    #[arg(long, default_value_t = 3)]
    pub levels: usize,
    /// Write a JSON report (energies per iteration, counts, timings).
    #[arg(long, value_name = "FILE")]
    pub report: Option<PathBuf>,
    /// No warnings.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Reads the edge-values JSON into `(i, j, a)` triples for every edge of `level`.
pub fn read_edge_values(path: &Path, level: &Level) -> anyhow::Result<Vec<(u32, u32, Real)>> {
    let text = String::from_utf8(subdyn::io::read_input(path)?)
        .map_err(|_| anyhow::anyhow!("{}: not UTF-8 text", path.display()))?;
    let bad = |msg: String| anyhow::anyhow!("{}: {msg}", path.display());
    let v: Value = serde_json::from_str(&text).map_err(|e| bad(format!("not valid JSON: {e}")))?;
    let obj = v
        .as_object()
        .ok_or_else(|| bad("expected an object {\"default\": …, \"edges\": […]}".into()))?;
    if let Some(k) = obj.keys().find(|k| *k != "default" && *k != "edges") {
        return Err(bad(format!(
            "unknown key \"{k}\" (expected \"default\" and \"edges\")"
        )));
    }
    let default = match obj.get("default") {
        None => 1.0,
        Some(d) => d
            .as_f64()
            .ok_or_else(|| bad("\"default\" must be a number".into()))?,
    };
    let mut out: Vec<(u32, u32, Real)> = level
        .edge_verts
        .iter()
        .map(|&[a, b]| (a, b, default))
        .collect();
    let edges = match obj.get("edges") {
        None => Vec::new(),
        Some(e) => e
            .as_array()
            .cloned()
            .ok_or_else(|| bad("\"edges\" must be an array".into()))?,
    };
    for (k, item) in edges.iter().enumerate() {
        let triple = item
            .as_array()
            .filter(|a| a.len() == 3)
            .and_then(|a| Some((a[0].as_u64()?, a[1].as_u64()?, a[2].as_f64()?)))
            .ok_or_else(|| {
                bad(format!(
                    "edges[{k}] must be [i, j, value] with vertex indices i, j"
                ))
            })?;
        let (i, j, a) = triple;
        if i > u32::MAX as u64 || j > u32::MAX as u64 {
            return Err(bad(format!("edges[{k}]: vertex index out of range")));
        }
        out.push((i as u32, j as u32, a));
    }
    Ok(out)
}

/// Runs `subdyn finetune surface`.
pub fn run(args: &SurfaceArgs) -> anyhow::Result<()> {
    check_mesh_output(&args.output)?;
    if let Some(r) = &args.refined {
        check_mesh_output(r)?;
    }
    if let Some(p) = &args.knots_out {
        check_output_dir(p)?;
    }
    if let Some(p) = &args.report {
        check_output_dir(p)?;
    }
    if args.levels > 6 {
        anyhow::bail!(
            "--levels {} is too many for --refined (at most 6)",
            args.levels
        );
    }
    let [k_l, k_a, k_b] = args.k[..] else {
        anyhow::bail!("--k needs three values k_l,k_a,k_b, got {}", args.k.len());
    };
    let mesh = read_polygon_mesh(&args.input, args.quiet)?;
    let name = args.input.display().to_string();
    let level = Level::from_mesh(&mesh).map_err(|e| about_file(e, &args.input))?;
    let values = read_edge_values(&args.edge_values, &level)?;
    let params = SurfaceFineTuneParams {
        k: [k_l, k_a, k_b],
        epsilon: args.epsilon,
        max_iters: args.max_iters,
        method: args.method,
        ..Default::default()
    };
    let scheme = match args.scheme {
        InputScheme::DooSabin => SurfaceScheme::DooSabin,
        InputScheme::CatmullClark => SurfaceScheme::CatmullClark,
    };
    let problem =
        SurfaceFineTune::new(&mesh, scheme, &values, &args.fix, &params).map_err(|e| match e {
            subdyn::Error::Input(msg)
                if msg.contains("control value") || msg.contains("joined") =>
            {
                anyhow::anyhow!("{}: {msg}", args.edge_values.display())
            }
            e => anyhow::Error::new(e).context(name.clone()),
        })?;
    let (out, report) = problem.solve()?;
    write_mesh(&args.output, &out, None).map_err(|e| about_file(e, &args.output))?;
    let mut written = Written::new();
    written.add(&args.output, "control mesh");
    if let Some(path) = &args.knots_out {
        atomic_write(path, |w| {
            writeln!(w, "# i j knot-interval (subdyn finetune surface)")?;
            for (e, &[a, b]) in problem.level.edge_verts.iter().enumerate() {
                writeln!(w, "{a} {b} {}", problem.intervals[e])?;
            }
            Ok(())
        })
        .map_err(|e| about_file(e, path))?;
        written.add(path, "knot intervals");
    }
    if let Some(path) = &args.refined {
        let h = NonUniformHierarchy::new(
            problem.level.clone(),
            problem.intervals.clone(),
            args.levels,
        )?;
        let fine = subdyn::mesh::PolyMesh {
            positions: h.stencil_to_level(args.levels)?.apply(&out.positions)?,
            face_offsets: h.levels[args.levels].face_offsets.clone(),
            face_vertices: h.levels[args.levels].face_verts.clone(),
        };
        fine.validate()?;
        write_mesh(path, &fine, None).map_err(|e| about_file(e, path))?;
        written.add(path, format!("refined mesh, level {}", args.levels));
    }
    let (e0, e1) = (
        report.energies.first().copied().unwrap_or(0.0),
        report.energies.last().copied().unwrap_or(0.0),
    );
    if let Some(path) = &args.report {
        write_report(
            path,
            &json!({
                "command": "finetune surface",
                "input": name,
                "output": args.output.display().to_string(),
                "scheme": format!("{:?}", args.scheme),
                "k": args.k,
                "fixed": args.fix,
                "report": report,
            }),
        )?;
        written.add(path, "report");
    }
    written.print_after(&format!(
        "fine-tuned {name}: energy {e0:.3e} -> {e1:.3e} in {} iterations ({}), largest move {:.4}\n",
        report.iterations,
        report.termination,
        report.max_displacement,
    ))
}
