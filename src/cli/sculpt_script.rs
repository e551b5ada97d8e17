//! The script of `subdyn sculpt` (format in `docs/sculpt.md`): parsing, and
//! validation of every operation against the lattice before the first step.

use std::path::Path;

use anyhow::{Context, bail};
use serde::Deserialize;

use subdyn::lattice::Lattice;
use subdyn::math::{Point3, Real};
use subdyn::solid::{
    Solid, SolidParams, Stiffness, check_value, extrude_face, extruded_topology, trim_cell,
};

/// Most steps a script may ask for.
pub const MAX_STEPS: usize = 1_000_000;

/// Optional material overrides.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    /// Mass density.
    pub density: Option<Real>,
    /// Normal spring stiffness per unit length.
    pub normal_stiffness: Option<Real>,
    /// Virtual spring stiffness per unit length.
    pub virtual_stiffness: Option<Real>,
    /// Damping per unit mass.
    pub damping: Option<Real>,
}

/// One operation (the `"op"` field names it).
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "op", rename_all = "snake_case", deny_unknown_fields)]
pub enum Op {
    /// Grab the mass point nearest `at` with a rope whose far end moves from
    /// that point to `to`, arriving at step `until` (default: at once).
    Rope {
        at: [Real; 3],
        to: [Real; 3],
        until: Option<usize>,
        stiffness: Option<Real>,
        rest_length: Option<Real>,
    },
    /// Let go of every rope.
    Release,
    /// Extrude a boundary face of the control lattice, by index or nearest centroid.
    Extrude {
        face: Option<usize>,
        near: Option<[Real; 3]>,
    },
    /// Remove a control cell, by index or nearest centroid.
    Trim {
        cell: Option<usize>,
        near: Option<[Real; 3]>,
    },
    /// Fix control points, by index and/or inside an axis-aligned box `[min, max]`.
    Fix {
        points: Option<Vec<usize>>,
        #[serde(rename = "box")]
        bbox: Option<[[Real; 3]; 2]>,
    },
    /// Free control points (same selection as `fix`).
    Free {
        points: Option<Vec<usize>>,
        #[serde(rename = "box")]
        bbox: Option<[[Real; 3]; 2]>,
    },
    /// New spring stiffnesses (either may be left out).
    Stiffness {
        normal: Option<Real>,
        #[serde(rename = "virtual")]
        virtual_: Option<Real>,
    },
    /// New damping per unit mass.
    Damping { value: Real },
    /// Make plastic; with `halt` (default true) also stop every motion.
    Plastic { halt: Option<bool> },
}

impl Op {
    /// The operation's name.
    pub fn name(&self) -> &'static str {
        match self {
            Op::Rope { .. } => "rope",
            Op::Release => "release",
            Op::Extrude { .. } => "extrude",
            Op::Trim { .. } => "trim",
            Op::Fix { .. } => "fix",
            Op::Free { .. } => "free",
            Op::Stiffness { .. } => "stiffness",
            Op::Damping { .. } => "damping",
            Op::Plastic { .. } => "plastic",
        }
    }
}

/// One operation of a script with the step it runs before.
#[derive(Debug)]
pub struct StepOp {
    /// The step.
    pub step: usize,
    /// Its place in the file's `ops` list (errors name it).
    pub index: usize,
    /// The operation.
    pub op: Op,
}

impl StepOp {
    /// `op 3 (step 550, fix)`: how every error names the operation.
    pub fn label(&self) -> String {
        format!("op {} (step {}, {})", self.index, self.step, self.op.name())
    }
}

/// A parsed and checked script.
#[derive(Debug)]
pub struct Script {
    /// Time step.
    pub dt: Real,
    /// Steps to run.
    pub steps: usize,
    /// Material overrides.
    pub material: Material,
    /// The operations sorted by step (stable: same-step ops keep their order).
    pub ops: Vec<StepOp>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScript {
    dt: Real,
    steps: usize,
    #[serde(default)]
    material: Material,
    #[serde(default)]
    ops: Vec<serde_json::Value>,
}

fn finite(name: &str, v: &[Real]) -> anyhow::Result<()> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        bail!("{name}: {v:?} is not finite")
    }
}

/// Parses a script; `what` names it in errors (a path or "the demo").
pub fn parse_script(text: &str, what: &str) -> anyhow::Result<Script> {
    let raw: RawScript = serde_json::from_str(text).with_context(|| {
        format!("{what}: not a valid sculpt script (plain JSON, no comments; see docs/sculpt.md)")
    })?;
    if !(raw.dt.is_finite() && raw.dt > 0.0 && raw.dt <= 10.0) {
        bail!("{what}: dt = {} (expected 0 < dt ≤ 10 seconds)", raw.dt);
    }
    if raw.steps == 0 || raw.steps > MAX_STEPS {
        bail!("{what}: steps = {} (expected 1 to {MAX_STEPS})", raw.steps);
    }
    let mut ops = Vec::with_capacity(raw.ops.len());
    for (i, mut value) in raw.ops.into_iter().enumerate() {
        let step = value
            .as_object_mut()
            .and_then(|o| o.remove("step"))
            .and_then(|s| s.as_u64())
            .ok_or_else(|| anyhow::anyhow!("{what}: op {i} has no \"step\" (a whole number)"))?
            as usize;
        if step > raw.steps {
            bail!(
                "{what}: op {i} at step {step}, after the last step {}",
                raw.steps
            );
        }
        let op: Op = serde_json::from_value(value)
            .with_context(|| format!("{what}: op {i} (step {step})"))?;
        let op = StepOp { step, index: i, op };
        check_op(&op.op, step, raw.steps).with_context(|| format!("{what}: {}", op.label()))?;
        ops.push(op);
    }
    ops.sort_by_key(|o| o.step);
    Ok(Script {
        dt: raw.dt,
        steps: raw.steps,
        material: raw.material,
        ops,
    })
}

/// The checks that need no lattice: every value in range, `until` within
/// the session, exactly one way to pick a face or cell, a non-empty selection.
fn check_op(op: &Op, step: usize, steps: usize) -> anyhow::Result<()> {
    match op {
        Op::Rope {
            at,
            to,
            until,
            stiffness,
            rest_length,
        } => {
            finite("at", at)?;
            finite("to", to)?;
            if let Some(s) = stiffness {
                check_value("stiffness", *s, true).map_err(plain)?;
            }
            if let Some(r) = rest_length {
                check_value("rest_length", *r, false).map_err(plain)?;
            }
            if let Some(u) = until
                && !(step..=steps).contains(u)
            {
                bail!(
                    "until = {u}: expected a step from the op's step {step} to the last step {steps}"
                );
            }
        }
        Op::Extrude { face, near } => one_of("face", face.is_some(), near)?,
        Op::Trim { cell, near } => one_of("cell", cell.is_some(), near)?,
        Op::Fix { points, bbox } | Op::Free { points, bbox } => {
            if points.is_none() && bbox.is_none() {
                bail!("give \"points\" and/or \"box\"");
            }
            if let Some(b) = bbox {
                finite("box", &[b[0], b[1]].concat())?;
                if (0..3).any(|k| b[0][k] > b[1][k]) {
                    bail!("box {b:?}: expected [min, max] with min ≤ max on every axis");
                }
            }
        }
        Op::Stiffness { normal, virtual_ } => {
            if normal.is_none() && virtual_.is_none() {
                bail!("give \"normal\" and/or \"virtual\"");
            }
            if let Some(k) = normal {
                check_value("normal", *k, false).map_err(plain)?;
            }
            if let Some(k) = virtual_ {
                check_value("virtual", *k, false).map_err(plain)?;
            }
        }
        Op::Damping { value } => check_value("value", *value, false).map_err(plain)?,
        Op::Release | Op::Plastic { .. } => {}
    }
    Ok(())
}

/// Checks a parsed script against the lattice it will sculpt, before the
/// first step: the material, and every operation in order on the lattice as
/// the earlier edits leave it (extrusions and trims applied, no motion), so
/// a face, cell or control-point index must exist then and a box must hold a
/// control point of the unmoved lattice. Errors name the script and the op:
/// `ops.json: op 3 (step 550, fix): …`.
pub fn check_script(
    script: &Script,
    lattice: &Lattice,
    level: usize,
    what: &str,
) -> anyhow::Result<()> {
    solid_params(level, &script.material)
        .check()
        .map_err(plain)
        .with_context(|| format!("{what}: material"))?;
    let mut lat = lattice.clone();
    for op in &script.ops {
        lat = edited(lat, &op.op).with_context(|| format!("{what}: {}", op.label()))?;
    }
    Ok(())
}

/// `lat` after `op` (only extrude and trim change it), or why `op` cannot
/// apply to it.
fn edited(lat: Lattice, op: &Op) -> anyhow::Result<Lattice> {
    Ok(match op {
        Op::Extrude { face, near } => {
            let f = extruded_face(&lat, *face, near)?;
            extrude_face(&lat, f).map_err(plain)?
        }
        Op::Trim { cell, near } => {
            let c = trimmed_cell(&lat, *cell, near)?;
            trim_cell(&lat, c).map_err(plain)?
        }
        Op::Fix { points, bbox } | Op::Free { points, bbox } => {
            let n = lat.num_vertices();
            if let Some(&i) = points.iter().flatten().find(|&&i| i >= n) {
                bail!("control point {i} does not exist (the lattice then has {n} control points)");
            }
            if selection_in(&lat.positions, points, bbox).is_empty() {
                bail!("the selection holds no control point");
            }
            lat
        }
        _ => lat,
    })
}

/// The boundary face an `extrude` op picks: `face`, which must be a boundary
/// face, or the one whose centroid is nearest `near`.
pub fn extruded_face(
    lat: &Lattice,
    face: Option<usize>,
    near: &Option<[Real; 3]>,
) -> anyhow::Result<usize> {
    let t = &lat.topology;
    match (face, near) {
        (Some(f), _) => {
            extruded_topology(t, f).map_err(plain)?;
            Ok(f)
        }
        (None, Some(q)) => nearest_centroid(
            &lat.positions,
            t.boundary_faces()
                .into_iter()
                .map(|f| (f as usize, t.faces.row(f as usize))),
            q,
        )
        .ok_or_else(|| anyhow::anyhow!("the lattice has no boundary face")),
        (None, None) => bail!("extrude needs \"face\" or \"near\""),
    }
}

/// The cell a `trim` op picks: `cell`, which must exist and not be the only
/// one, or the one whose centroid is nearest `near`.
pub fn trimmed_cell(
    lat: &Lattice,
    cell: Option<usize>,
    near: &Option<[Real; 3]>,
) -> anyhow::Result<usize> {
    let t = &lat.topology;
    match (cell, near) {
        (Some(c), _) => Ok(c),
        (None, Some(q)) => nearest_centroid(
            &lat.positions,
            (0..t.num_cells()).map(|c| (c, t.cell_vertices.row(c))),
            q,
        )
        .ok_or_else(|| anyhow::anyhow!("the lattice has no cell")),
        (None, None) => bail!("trim needs \"cell\" or \"near\""),
    }
}

/// A library error in the script's words: an input error's message without
/// its `input:` prefix (the op is already named in front of it).
fn plain(e: subdyn::Error) -> anyhow::Error {
    match e {
        subdyn::Error::Input(message) => anyhow::anyhow!(message),
        e => anyhow::Error::new(e),
    }
}

fn one_of(name: &str, index: bool, near: &Option<[Real; 3]>) -> anyhow::Result<()> {
    match (index, near) {
        (true, Some(_)) | (false, None) => bail!("give exactly one of \"{name}\" and \"near\""),
        (false, Some(n)) => finite("near", n),
        _ => Ok(()),
    }
}

/// Reads a script file.
pub fn read_script(path: &Path) -> anyhow::Result<Script> {
    let text = String::from_utf8(subdyn::io::read_input(path)?)
        .map_err(|_| anyhow::anyhow!("{}: the script is not UTF-8 text", path.display()))?;
    parse_script(&text, &path.display().to_string())
}

/// The solid's parameters with the script's material applied.
pub fn solid_params(level: usize, m: &Material) -> SolidParams {
    let d = SolidParams::default();
    SolidParams {
        level,
        density: m.density.unwrap_or(d.density),
        stiffness: Stiffness {
            edge: m.normal_stiffness.unwrap_or(d.stiffness.edge),
            virtual_: m.virtual_stiffness.unwrap_or(d.stiffness.virtual_),
        },
        damping: m.damping.unwrap_or(d.damping),
        ..d
    }
}

/// Control points of `solid` selected by indices and/or a box.
pub fn selection(
    solid: &Solid,
    points: &Option<Vec<usize>>,
    bbox: &Option<[[Real; 3]; 2]>,
) -> Vec<usize> {
    selection_in(solid.control_points(), points, bbox)
}

/// Indices selected among `positions` by indices and/or a box.
fn selection_in(
    positions: &[Point3],
    points: &Option<Vec<usize>>,
    bbox: &Option<[[Real; 3]; 2]>,
) -> Vec<usize> {
    let mut out = points.clone().unwrap_or_default();
    if let Some([lo, hi]) = bbox {
        out.extend(
            positions
                .iter()
                .enumerate()
                .filter_map(|(i, p)| (0..3).all(|k| p[k] >= lo[k] && p[k] <= hi[k]).then_some(i)),
        );
    }
    out
}

/// Index of the item whose centroid (of the given vertex lists) is nearest `q`.
fn nearest_centroid<'a>(
    positions: &[Point3],
    lists: impl Iterator<Item = (usize, &'a [u32])>,
    q: &[Real; 3],
) -> Option<usize> {
    let q = Point3::new(q[0], q[1], q[2]);
    lists
        .map(|(i, l)| {
            let c = l.iter().fold(Point3::origin().coords, |s, &v| {
                s + positions[v as usize].coords
            }) / l.len() as Real;
            ((c - q.coords).norm(), i)
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|x| x.1)
}
