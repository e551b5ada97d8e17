#!/usr/bin/env python3
"""Check volumes for `subdyn recover`, beside the bench in recover_vs_marching_cubes.py.

Defaults chosen on that bench are checked here, on twelve data-gen volumes at
other sizes, blurs, noise levels and seeds (real meshes from ../shared/data/meshes
and data-gen's shapes). Each VARIANT (`TAG=BINARY [OPTIONS...]`) recovers every
volume at its true iso-value 0.5; raw marching cubes (scikit-image, on the volume
padded with its minimum so that it closes at the box) is the anchor. Printed per
volume: Chamfer / Hausdorff to the truth mesh in voxels (`subdyn compare`), levels
and control points; MC's vertex count ÷ 10 is the control-point budget of issue 25.

    benches/compare/.venv/bin/python benches/compare/recover_check_volumes.py \\
        "old=/tmp/subdyn-old" "new=target/release/subdyn --max-level 3"

Needs numpy and scikit-image (the bench's venv has them), target/release/data-gen
and target/release/subdyn. Volumes and outputs go to --work (default
target/recover-check); existing volumes are reused.
"""
import argparse
import json
import os
import subprocess
from pathlib import Path

import numpy as np
from skimage.measure import marching_cubes

ROOT = Path(__file__).resolve().parents[2]
MESHES = Path(os.environ.get("SUBDYN_SHARED_MESHES", str(ROOT.parent / "shared" / "data" / "meshes")))
VOLUMES = [  # name, shape or mesh, dims, blur, noise, seed
    ("fandisk64", f"{MESHES}/fandisk.obj", "64,64,64", "0.02", "0.05", "3"),
    ("cow48", f"{MESHES}/cow.obj", "48,48,48", "0.03", "0.08", "3"),
    ("spot64", f"{MESHES}/spot.obj", "64,64,64", "0.03", "0.1", "3"),
    ("chair64", "chair", "64,64,64", "0.03", "0.05", "3"),
    ("bracket48", "bracket", "48,48,48", "0.03", "0.05", "3"),
    ("anvil80", "anvil", "80,48,40", "0.03", "0.1", "3"),
    ("rocker64", f"{MESHES}/rocker-arm.obj", "64,64,64", "0.02", "0.05", "3"),
    ("torus64", "torus", "64,64,32", "0.03", "0.1", "3"),
    ("cow96", f"{MESHES}/cow.obj", "96,96,96", "0.02", "0.05", "5"),
    ("spot96", f"{MESHES}/spot.obj", "96,96,96", "0.015", "0.05", "5"),
    ("plate64", "plate", "64,48,24", "0.03", "0.05", "5"),
    ("genus2s", "genus2", "96,56,20", "0.04", "0.08", "5"),
]


def run(*args):
    return subprocess.run([str(a) for a in args], capture_output=True, text=True)


def distances(subdyn, mesh, truth, voxel):
    """Chamfer and Hausdorff of `mesh` to `truth` in voxels."""
    report = f"{mesh}.compare.json"
    run(subdyn, "compare", mesh, truth, "--report", report, "--quiet")
    j = json.load(open(report))
    chamfer = 0.5 * (j["a_to_b"]["stats"]["mean"] + j["b_to_a"]["stats"]["mean"]) / voxel
    return chamfer, max(j["a_to_b"]["max"], j["b_to_a"]["max"]) / voxel


def marching_cubes_obj(work, name):
    """Raw marching cubes at 0.5, closed at the box; returns its vertex count."""
    side = json.load(open(work / f"{name}.json"))
    d, sp, o = side["dims"], side["spacing"], side["origin"]
    v = np.fromfile(work / f"{name}.raw", dtype="<f4").reshape(d[2], d[1], d[0])
    verts, faces, _, _ = marching_cubes(np.pad(v, 1, constant_values=v.min()), 0.5)
    verts -= 1
    xyz = np.stack([o[0] + verts[:, 2] * sp[0], o[1] + verts[:, 1] * sp[1], o[2] + verts[:, 0] * sp[2]], 1)
    with open(work / f"{name}.mc.obj", "w") as f:
        f.writelines(f"v {a} {b} {c}\n" for a, b, c in xyz)
        f.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in faces)
    return len(xyz)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("variants", nargs="+", help="TAG=BINARY [OPTIONS...]")
    ap.add_argument("--work", type=Path, default=ROOT / "target" / "recover-check")
    ap.add_argument("--data-gen", type=Path, default=ROOT / "target" / "release" / "data-gen")
    ap.add_argument("--subdyn", type=Path, default=ROOT / "target" / "release" / "subdyn",
                    help="the binary that measures (subdyn compare)")
    args = ap.parse_args()
    args.work.mkdir(parents=True, exist_ok=True)
    variants = [v.split("=", 1) for v in args.variants]
    for name, what, dims, blur, noise, seed in VOLUMES:
        raw = args.work / f"{name}.raw"
        if not raw.exists():
            source = ["--mesh", what] if what.endswith(".obj") else [what]
            r = run(args.data_gen, "volume", *source, "-o", raw, "--format", "raw", "--dims", dims,
                    "--blur", blur, "--noise", noise, "--seed", seed)
            if r.returncode != 0:
                print(f"{name}: data-gen failed: {r.stderr.strip()}")
                continue
        voxel = min(json.load(open(args.work / f"{name}.json"))["spacing"])
        truth = args.work / f"{name}.truth.obj"
        n = marching_cubes_obj(args.work, name)
        ch, h = distances(args.subdyn, args.work / f"{name}.mc.obj", truth, voxel)
        row = f"{name:10s} MC {ch:.3f}/{h:.2f} ({n // 10} cp budget)"
        for tag, spec in variants:
            binary, *options = spec.split()
            out = args.work / f"{name}.{tag}"
            r = run(binary, "recover", raw, "--iso", "0.5", "-o", f"{out}.obj", "--limit-out", f"{out}.ply",
                    "--report", f"{out}.json", "--quiet", *options)
            if r.returncode != 0:
                row += f" | {tag}: exit {r.returncode}"
                continue
            levels = json.load(open(f"{out}.json"))["recover"]["levels"]
            ch, h = distances(args.subdyn, f"{out}.ply", truth, voxel)
            row += f" | {tag} {ch:.3f}/{h:.2f} {len(levels)}L {levels[-1]['control_points']}cp"
        print(row, flush=True)


if __name__ == "__main__":
    main()
