//! The script of `subdyn sculpt` (format in [`super::sculpt`]'s docs):
//! parsing, validation, and applying one operation to a solid.

use std::path::Path;

use anyhow::{Context, bail};
use serde::Deserialize;

use subdyn::math::{Point3, Real};
use subdyn::solid::{Solid, SolidParams, Stiffness};

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

/// A parsed and checked script.
#[derive(Debug)]
pub struct Script {
    /// Time step.
    pub dt: Real,
    /// Steps to run.
    pub steps: usize,
    /// Material overrides.
    pub material: Material,
    /// `(step, op)` sorted by step (stable: same-step ops keep their order).
    pub ops: Vec<(usize, Op)>,
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
    let raw: RawScript =
        serde_json::from_str(text).with_context(|| format!("{what}: not a valid sculpt script"))?;
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
        check_op(&op).with_context(|| format!("{what}: op {i} (step {step}, {})", op.name()))?;
        ops.push((step, op));
    }
    ops.sort_by_key(|(s, _)| *s);
    Ok(Script {
        dt: raw.dt,
        steps: raw.steps,
        material: raw.material,
        ops,
    })
}

fn check_op(op: &Op) -> anyhow::Result<()> {
    match op {
        Op::Rope {
            at,
            to,
            stiffness,
            rest_length,
            ..
        } => {
            finite("at", at)?;
            finite("to", to)?;
            finite(
                "stiffness",
                &[stiffness.unwrap_or(1.0), rest_length.unwrap_or(0.0)],
            )?;
        }
        Op::Extrude { face, near } => one_of("face", face.is_some(), near)?,
        Op::Trim { cell, near } => one_of("cell", cell.is_some(), near)?,
        Op::Fix { points, bbox } | Op::Free { points, bbox } => {
            if points.is_none() && bbox.is_none() {
                bail!("give \"points\" and/or \"box\"");
            }
            if let Some(b) = bbox {
                finite("box", &[b[0], b[1]].concat())?;
            }
        }
        _ => {}
    }
    Ok(())
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

/// Control points selected by indices and/or a box.
pub fn selection(
    solid: &Solid,
    points: &Option<Vec<usize>>,
    bbox: &Option<[[Real; 3]; 2]>,
) -> Vec<usize> {
    let mut out = points.clone().unwrap_or_default();
    if let Some([lo, hi]) = bbox {
        out.extend(
            solid
                .control_points()
                .iter()
                .enumerate()
                .filter_map(|(i, p)| (0..3).all(|k| p[k] >= lo[k] && p[k] <= hi[k]).then_some(i)),
        );
    }
    out
}

/// Index of the item whose centroid (of the given vertex lists) is nearest `q`.
pub fn nearest_centroid<'a>(
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
