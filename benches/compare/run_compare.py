#!/usr/bin/env python3
"""Side-by-side comparison of subdyn fit with Open3D and pymeshlab.

One command (from anywhere):

    python3 benches/compare/run_compare.py

1. creates (or reuses) a virtual environment in benches/compare/.venv, installs
   open3d, pymeshlab and numpy there, and re-runs itself inside it;
2. builds subdyn (`cargo build --release`) and generates the scans with ground
   truth with the project's own generator (`data-gen scan ...`);
3. reconstructs each scan with Open3D Poisson (depth 8 and 9), Open3D ball
   pivoting, pymeshlab screened Poisson and `subdyn fit`, timing each;
4. measures every output against the ground truth with the same code for all
   (`subdyn compare OUTPUT TRUTH --report R.json`), counts vertices, checks
   watertightness (`subdyn info --json`: no boundary and no non-manifold edge);
5. writes benches/compare/RESULTS.md and RESULTS.json.

See benches/compare/README.md. Not part of CI. Standard library only outside
the venv.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import shutil
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent  # workspace root (/work/main)
VENV = HERE / ".venv"
VENV_PY = VENV / "bin" / "python"
PACKAGES = ["numpy", "open3d", "pymeshlab"]
DEBIAN_LIBS = ["libusb-1.0-0", "libgl1", "libgomp1"]  # what Open3D's wheel links against

SCAN_ARGS = ["--views", "8", "--noise", "0.001", "--seed", "1"]
# The goal setting: a real closed mesh scanned from 8 views, ~29k points
# (Spot at 200×150 pixels per view gives 28,638 points), 0.1 % noise. The mesh
# lives outside the repository; the row is skipped with a note when it is absent.
SHARED_MESHES = Path(os.environ.get("SUBDYN_SHARED_MESHES", str(ROOT.parent / "shared" / "data" / "meshes")))
# name, data-gen shape (or None for --mesh), genus of the ground truth, extra data-gen arguments
SCANS = [
    ("sphere", "sphere", 0, []),
    ("torus", "torus", 1, []),
    ("genus2", "genus2", 2, []),
    ("spot", None, 0, ["--mesh", SHARED_MESHES / "spot.obj", "--resolution", "200,150"]),
]
# The scan whose subdyn row is checked against the performance goal.
GOAL_SCAN = "spot"
# --scaling: one shape scanned at growing resolution (points ≈ 1.3 × W × H / 1000 × 1000 on the sphere).
SCALING_SHAPE = "sphere"
SCALING_RESOLUTIONS = ["100,75", "174,130", "320,240", "1000,750"]
SCALING_TIMEOUT_S = 180.0  # a size whose fit takes longer is recorded as "did not finish" and larger ones skipped

SUBDYN = ROOT / "target" / "release" / "subdyn"
DATA_GEN = ROOT / "target" / "release" / "data-gen"


def log(msg: str) -> None:
    print(f"[compare] {msg}", flush=True)


def run(cmd, **kw) -> subprocess.CompletedProcess:
    return subprocess.run([str(c) for c in cmd], check=True, **kw)


# --------------------------------------------------------------------------- setup


def in_venv() -> bool:
    return Path(sys.prefix).resolve() == VENV.resolve()


def check_debian_libs() -> None:
    if shutil.which("dpkg") is None:
        return
    missing = []
    for lib in DEBIAN_LIBS:
        r = subprocess.run(["dpkg", "-s", lib], capture_output=True, text=True)
        if r.returncode != 0 or "Status: install ok installed" not in r.stdout:
            missing.append(lib)
    if missing:
        log("Open3D needs Debian packages that are missing: " + " ".join(missing))
        log("install them with:  apt-get update && apt-get install -y " + " ".join(missing))


def ensure_venv(args) -> None:
    """Create the venv, install the packages, re-exec this script inside it."""
    if in_venv():
        return
    check_debian_libs()
    if not VENV_PY.exists():
        log(f"creating virtual environment {VENV}")
        run([sys.executable, "-m", "venv", VENV])
    r = subprocess.run([VENV_PY, "-c", "import open3d, pymeshlab, numpy"], capture_output=True)
    if r.returncode != 0 or args.upgrade:
        log("installing " + " ".join(PACKAGES) + " into the venv (first run: a few minutes)")
        run([VENV_PY, "-m", "pip", "install", "-q", "--upgrade", "pip"])
        run([VENV_PY, "-m", "pip", "install", "-q"] + PACKAGES)
    os.execv(str(VENV_PY), [str(VENV_PY), str(Path(__file__).resolve())] + sys.argv[1:])


def build_rust(args) -> None:
    if args.no_build:
        return
    log("cargo build --release")
    run(["cargo", "build", "--release", "-q"], cwd=ROOT)
    run(["cargo", "build", "--release", "-q", "-p", "data-gen"], cwd=ROOT)


def generate_scans(work: Path, scans, skipped: list[str]) -> list[dict]:
    """Runs `data-gen scan` for every scan; a scan of a mesh file that is absent is skipped with a note."""
    out = []
    for name, shape, genus, extra in scans:
        if "--mesh" in extra:
            mesh = Path(extra[extra.index("--mesh") + 1])
            if not mesh.exists():
                note = f"{name}: skipped, {mesh} is absent (set SUBDYN_SHARED_MESHES to the folder holding it)"
                log(note)
                skipped.append(note)
                continue
        ply = work / f"{name}.ply"
        args = ([shape] if shape else []) + [str(a) for a in extra] + SCAN_ARGS
        cmd = [DATA_GEN, "scan", "-o", ply] + args
        log(" ".join(str(c) for c in cmd))
        run(cmd, cwd=ROOT, capture_output=True)
        truth = work / f"{name}.truth.obj"
        side = json.loads((work / f"{name}.json").read_text())
        shown = " ".join(a if not a.startswith("/") else "…/" + Path(a).name for a in args)
        out.append({"name": name, "shape": shape or Path(extra[extra.index("--mesh") + 1]).name,
                    "genus": genus, "scan": ply, "truth": truth,
                    "points": side.get("counts", {}).get("total"),
                    "command": "data-gen scan -o " + ply.name + " " + shown})
    return out


# --------------------------------------------------------------------------- I/O


def read_points(ply: Path):
    """x, y, z of a binary little-endian PLY vertex element (any other properties skipped)."""
    import numpy as np

    data = ply.read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    assert header[1].startswith("format binary_little_endian"), header[1]
    types = {"double": "<f8", "float": "<f4", "int": "<i4", "uint": "<u4", "uchar": "u1",
             "char": "i1", "short": "<i2", "ushort": "<u2", "float32": "<f4", "float64": "<f8",
             "int32": "<i4", "uint8": "u1"}
    n, fields, in_vertex = 0, [], False
    for line in header:
        w = line.split()
        if w[0] == "element":
            in_vertex = w[1] == "vertex"
            if in_vertex:
                n = int(w[2])
        elif w[0] == "property" and in_vertex:
            fields.append((w[2], types[w[1]]))
    arr = np.frombuffer(data, dtype=np.dtype(fields), count=n, offset=end)
    return np.stack([arr["x"], arr["y"], arr["z"]], axis=1).astype(np.float64)


def write_xyz_ply(path: Path, pts) -> None:
    """Points only (no normals: every method has to estimate its own)."""
    import numpy as np

    head = (f"ply\nformat binary_little_endian 1.0\nelement vertex {len(pts)}\n"
            "property double x\nproperty double y\nproperty double z\nend_header\n")
    path.write_bytes(head.encode("ascii") + np.ascontiguousarray(pts, dtype="<f8").tobytes())


# --------------------------------------------------------------------------- methods
# Each method returns the path of its output mesh; the caller times the call
# (wall clock, reading the points and estimating normals included).


def o3d_cloud_with_normals(xyz_ply: Path):
    import open3d as o3d

    pcd = o3d.io.read_point_cloud(str(xyz_ply))
    pcd.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(knn=30))
    pcd.orient_normals_consistent_tangent_plane(15)
    return pcd


def o3d_poisson(depth: int):
    def method(xyz_ply: Path, out_dir: Path, scan) -> dict:
        import open3d as o3d

        pcd = o3d_cloud_with_normals(xyz_ply)
        mesh, _densities = o3d.geometry.TriangleMesh.create_from_point_cloud_poisson(
            pcd, depth=depth, n_threads=0)
        out = out_dir / f"o3d_poisson_d{depth}.ply"
        o3d.io.write_triangle_mesh(str(out), mesh)
        return {"output": out}
    return method


def o3d_ball_pivoting(xyz_ply: Path, out_dir: Path, scan) -> dict:
    import numpy as np
    import open3d as o3d

    pcd = o3d_cloud_with_normals(xyz_ply)
    spacing = float(np.mean(np.asarray(pcd.compute_nearest_neighbor_distance())))
    radii = [spacing * f for f in (1.0, 2.0, 4.0)]
    mesh = o3d.geometry.TriangleMesh.create_from_point_cloud_ball_pivoting(
        pcd, o3d.utility.DoubleVector(radii))
    out = out_dir / "o3d_ball_pivoting.ply"
    o3d.io.write_triangle_mesh(str(out), mesh)
    return {"output": out, "params": {"radii": radii, "mean_spacing": spacing}}


def pml_screened_poisson(xyz_ply: Path, out_dir: Path, scan) -> dict:
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.load_new_mesh(str(xyz_ply))
    ms.compute_normal_for_point_clouds(k=10, smoothiter=0)
    ms.generate_surface_reconstruction_screened_poisson(depth=8)
    out = out_dir / "pml_screened_poisson.ply"
    ms.save_current_mesh(str(out), binary=True, save_vertex_normal=False)
    return {"output": out}


def subdyn_fit(xyz_ply: Path, out_dir: Path, scan) -> dict:
    fit = out_dir / "subdyn_fit.obj"
    surf = out_dir / "subdyn_limit.ply"
    rep = out_dir / "subdyn_fit_report.json"
    run([SUBDYN, "fit", scan["scan"], "-o", fit, "--limit-out", surf, "--quiet", "--report", rep],
        capture_output=True)
    return {"output": surf, "control_mesh": fit, "fit_report": rep}


METHODS = [
    ("Open3D Poisson depth 8", "o3d_poisson_d8", o3d_poisson(8)),
    ("Open3D Poisson depth 9", "o3d_poisson_d9", o3d_poisson(9)),
    ("Open3D ball pivoting", "o3d_bpa", o3d_ball_pivoting),
    ("pymeshlab screened Poisson depth 8", "pml_spsr", pml_screened_poisson),
    ("subdyn fit", "subdyn_fit", subdyn_fit),
]


# --------------------------------------------------------------------------- measuring


def info(mesh: Path) -> dict:
    r = run([SUBDYN, "info", "--json", mesh], capture_output=True, text=True)
    return json.loads(r.stdout)


def compare(output: Path, truth: Path, report: Path, extra=()) -> dict:
    run([SUBDYN, "compare", output, truth, "--report", report, "--quiet", *extra], capture_output=True)
    return json.loads(report.read_text())


def measure(output: Path, truth: Path, out_dir: Path, tag: str, extra=()) -> dict:
    rep = compare(output, truth, out_dir / f"{tag}_compare.json", extra)
    inf = info(output)
    a2b, b2a = rep["a_to_b"], rep["b_to_a"]
    return {
        "accuracy_mean_pct": a2b["stats_pct"]["mean"],
        "accuracy_p95_pct": a2b["stats_pct"]["p95"],
        "accuracy_max_pct": a2b["max_pct"],
        "completeness_mean_pct": b2a["stats_pct"]["mean"],
        "completeness_p95_pct": b2a["stats_pct"]["p95"],
        "completeness_max_pct": b2a["max_pct"],
        "chamfer_pct": rep["chamfer_pct"],
        "hausdorff_pct": rep["hausdorff_pct"],
        "normal_consistency": rep.get("normal_consistency"),
        "diagonal": rep["diagonal"],
        "vertices": inf["vertices"],
        "faces": inf["faces"],
        "boundary_edges": inf["boundary_edges"],
        "non_manifold_edges": inf["non_manifold_edges"],
        "components": len(inf.get("components", [])),
        "genus": inf.get("genus"),
        "watertight": inf["faces"] > 0 and inf["boundary_edges"] == 0 and inf["non_manifold_edges"] == 0,
    }


# --------------------------------------------------------------------------- report


def machine() -> dict:
    import open3d
    import pymeshlab

    cpu = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    nproc = subprocess.run(["nproc"], capture_output=True, text=True).stdout.strip()
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=ROOT,
                            capture_output=True, text=True).stdout.strip()
    dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=ROOT,
                           capture_output=True, text=True).stdout.strip() != ""
    try:
        import importlib.metadata as md
        pml_version = md.version("pymeshlab")
    except Exception:  # noqa: BLE001
        pml_version = getattr(pymeshlab, "__version__", "unknown")
    return {
        "nproc": nproc, "cpu": cpu, "os": platform.platform(), "python": platform.python_version(),
        "open3d": open3d.__version__, "pymeshlab": pml_version,
        "subdyn_commit": commit + ("-dirty" if dirty else ""),
        "loadavg_at_start": [round(x, 2) for x in os.getloadavg()],
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
    }


def fmt(x, digits=3) -> str:
    if x is None:
        return "—"
    if isinstance(x, float):
        return f"{x:.{digits}f}"
    return str(x)


def write_results(results: dict, md_path: Path, json_path: Path) -> None:
    json_path.write_text(json.dumps(results, indent=2, default=str) + "\n")
    m = results["machine"]
    L = []
    L.append("# subdyn vs Open3D and pymeshlab: reconstruction from simulated scans")
    L.append("")
    L.append("Generated by `python3 benches/compare/run_compare.py` (see README.md in this folder); "
             "every figure below is also in `RESULTS.json`.")
    L.append("")
    L.append(f"**Machine:** {m['nproc']} cores (`nproc`), {m['cpu']}; {m['os']}; Python {m['python']}; "
             f"open3d {m['open3d']}; pymeshlab {m['pymeshlab']}; subdyn commit `{m['subdyn_commit']}`; "
             f"run {m['date']} (load average at start {', '.join(str(x) for x in m['loadavg_at_start'])}).")
    L.append("")
    L.append("**Metric** (the same for every method): `subdyn compare OUTPUT TRUTH --report R.json` — exact "
             "point-to-triangle distances (BVH) between 100,000 area-weighted samples of one surface and the "
             "other surface, plus every vertex for the maxima; all figures in **% of the ground truth's "
             "bounding-box diagonal**. *Accuracy* = mean distance output → truth; *completeness* = mean "
             "distance truth → output; *Chamfer* = ½(accuracy + completeness); *Hausdorff* = max of both "
             "one-sided maxima. *Watertight* = at least one face, no boundary edge and no non-manifold "
             "edge (`subdyn info --json`), i.e. every edge has exactly two faces. *Seconds* = wall clock "
             "of the whole reconstruction, reading the points and normal estimation included.")
    L.append("")
    for sc in results["scans"]:
        L.append(f"## {sc['name']} (genus {sc['genus']}, {sc['points']:,} points)")
        L.append("")
        run_info = sc.get("run") or {}
        when = (f" Run {run_info.get('date')}, subdyn `{run_info.get('subdyn_commit')}`, load average at the start "
                f"of the scan {', '.join(str(x) for x in sc.get('loadavg', []))}.") if run_info else ""
        L.append(f"Scan: `{sc['command']}` (ground truth: `{Path(str(sc['truth'])).name}`, "
                 f"bounding-box diagonal {sc.get('diagonal', float('nan')):.4f}).{when}")
        L.append("")
        L.append("| method | seconds | vertices / control points | accuracy % | completeness % | Chamfer % "
                 "| Hausdorff % | watertight | genus |")
        L.append("|---|---:|---:|---:|---:|---:|---:|---|---:|")
        for r in sc["methods"]:
            if r.get("error"):
                L.append(f"| {r['method']} | — | — | — | — | — | — | failed: {r['error'][:80]} | — |")
                continue
            verts = f"{r['vertices']:,}"
            if r.get("control_points") is not None:
                verts = f"{r['control_points']:,} control points / {r['vertices']:,} limit-mesh vertices"
            wt = "yes" if r["watertight"] else f"no ({r['boundary_edges']:,} boundary, {r['non_manifold_edges']:,} non-manifold edges)"
            L.append(f"| {r['method']} | {r['seconds']:.2f} | {verts} | {fmt(r['accuracy_mean_pct'], 4)} | "
                     f"{fmt(r['completeness_mean_pct'], 4)} | {fmt(r['chamfer_pct'], 4)} | "
                     f"{fmt(r['hausdorff_pct'], 3)} | {wt} | {fmt(r['genus'])} |")
        for line in criteria_lines(sc):
            L.append("")
            L.append(line)
        extra = [r for r in sc["methods"] if r.get("limit_exact")]
        for r in extra:
            le = r["limit_exact"]
            L.append("")
            L.append(f"subdyn's exact limit surface (`subdyn compare fit.obj TRUTH --limit-a`, exact projection "
                     f"instead of the K=4 tessellation): accuracy {le['accuracy_mean_pct']:.4f} %, "
                     f"completeness {le['completeness_mean_pct']:.4f} %, Chamfer {le['chamfer_pct']:.4f} %, "
                     f"Hausdorff {le['hausdorff_pct']:.3f} %.")
        L.append("")
    if results.get("skipped"):
        for note in results["skipped"]:
            L.append(f"*{note}.*")
            L.append("")
    if results.get("scaling"):
        L.extend(scaling_lines(results["scaling"]))
    L.append("## Settings and caveats")
    L.append("")
    for line in results["notes"]:
        L.append(f"- {line}")
    L.append("")
    md_path.write_text("\n".join(L) + kept_sections(md_path))


def kept_sections(md_path: Path) -> str:
    """The level-1 sections other scripts appended to RESULTS.md (everything after this script's own)."""
    try:
        old = md_path.read_text()
    except OSError:
        return ""
    lines = old.splitlines(keepends=True)
    starts = [i for i, line in enumerate(lines) if line.startswith("# ")]
    if len(starts) < 2:
        return ""
    return "\n\n" + "".join(lines[starts[1]:])


def subdyn_row(sc: dict):
    return next((r for r in sc["methods"] if r.get("tag") == "subdyn_fit" and not r.get("error")), None)


def criteria_lines(sc: dict) -> list[str]:
    """The issue's acceptance criteria for subdyn's row, and the goal for GOAL_SCAN, each stated with its numbers."""
    r = subdyn_row(sc)
    if r is None:
        return ["**Issue 4 criteria:** subdyn fit failed on this scan (see the table)."]
    noise = 0.1  # σ of the range noise, % of the diagonal (SCAN_ARGS)
    ok_c, ok_h = r["chamfer_pct"] < noise, r["hausdorff_pct"] < 1.0
    out = [f"**Issue 4 criteria (subdyn):** Chamfer {r['chamfer_pct']:.4f} % < noise σ {noise} % → "
           f"**{'yes' if ok_c else 'no'}**; Hausdorff {r['hausdorff_pct']:.3f} % < 1 % → **{'yes' if ok_h else 'no'}**; "
           f"genus of the limit mesh {fmt(r['genus'])} (truth {sc['genus']}) → "
           f"**{'yes' if r['genus'] == sc['genus'] else 'no'}**."]
    if sc["name"] != GOAL_SCAN:
        return out
    o3d = next((m for m in sc["methods"] if m.get("tag") == "o3d_poisson_d8" and not m.get("error")), None)
    pml = next((m for m in sc["methods"] if m.get("tag") == "pml_spsr" and not m.get("error")), None)
    ref = [m["vertices"] for m in (o3d, pml) if m is not None]
    cp = r.get("control_points")
    fr = r.get("fit_report") or {}
    fit_s = (fr.get("fit") or {}).get("seconds")
    parts = [f"Chamfer {r['chamfer_pct']:.4f} % ≤ 0.03 % → **{'yes' if r['chamfer_pct'] <= 0.03 else 'no'}**"]
    if ref and cp is not None:
        parts.append(f"{cp:,} control points ≤ 1/10 of {min(ref):,} (fewest Open3D/pymeshlab Poisson vertices) = "
                     f"{min(ref) / 10:,.0f} → **{'yes' if cp * 10 <= min(ref) else 'no'}**")
    parts.append(f"Hausdorff {r['hausdorff_pct']:.3f} % < 1 % → **{'yes' if r['hausdorff_pct'] < 1.0 else 'no'}**")
    parts.append(f"watertight → **{'yes' if r['watertight'] else 'no'}**")
    t = f"{r['seconds']:.2f} s wall clock" + (f" ({fit_s:.2f} s fitting by the report)" if fit_s else "")
    parts.append(f"time {t} ≤ 2 s for {sc['points']:,} points → **{'yes' if r['seconds'] <= 2.0 else 'no'}** "
                 f"(load average {', '.join(str(x) for x in sc.get('loadavg', []))} on 2 shared cores)")
    if o3d is not None:
        parts.append(f"against Open3D Poisson depth 8 in this run: {r['seconds'] / o3d['seconds']:.1f}× its time, "
                     f"{r['chamfer_pct'] / o3d['chamfer_pct']:.2f}× its Chamfer")
    out.append("**Issue 4 goal (real closed mesh, 8 views, 0.1 % noise):** " + "; ".join(parts) + ".")
    return out


def scaling_lines(rows: list[dict]) -> list[str]:
    L = ["## Scaling: `subdyn fit` time against the number of points", ""]
    first = rows[0]
    L.append(f"One shape ({SCALING_SHAPE}) scanned at growing resolution: `{first['command']}` with "
             f"`--resolution W,H` below; `subdyn fit SCAN -o fit.obj --limit-out surf.ply --quiet --report R.json` "
             f"(defaults), Chamfer of `surf.ply` against the ground truth as above. Sizes whose fit would exceed "
             f"{SCALING_TIMEOUT_S:.0f} s are stopped and marked. Load average at the start of each fit in the last column.")
    L.append("")
    L.append("| points | resolution | seconds | µs per point | control points | levels | Chamfer % | Hausdorff % | load |")
    L.append("|---:|---|---:|---:|---:|---:|---:|---:|---|")
    for r in rows:
        if r.get("error"):
            L.append(f"| {fmt(r.get('points'))} | {r['resolution']} | — | — | — | — | — | — | {r['error'][:60]} |")
            continue
        L.append(f"| {r['points']:,} | {r['resolution']} | {r['seconds']:.2f} | {1e6 * r['seconds'] / r['points']:.0f} | "
                 f"{r['control_points']:,} | {fmt(r.get('levels'))} | {fmt(r['chamfer_pct'], 4)} | "
                 f"{fmt(r['hausdorff_pct'], 3)} | {', '.join(str(x) for x in r['loadavg'])} |")
    L.append("")
    return L


NOTES = [
    "Scans: `data-gen scan` (8 perspective views on a Fibonacci sphere, 160×120 pixels per view, "
    "Gaussian range noise σ = 0.1 % of the diagonal, seed 1, no dropout, no outliers). The ground truth is the "
    "mesh the scan was taken of (`*.truth.obj`: sphere = quad sphere 24,578 vertices; torus R = 1, r = 0.35, "
    "8,192 vertices; genus2 = two blended tori from `data-gen shape genus2`; spot = Keenan Crane's Spot, "
    "`../shared/data/meshes/spot.obj`, scanned at 200×150 pixels per view to get the issue's ~29k points), so "
    "its own discretisation error (< 0.03 % of the diagonal) is part of every figure.",
    "Open3D and pymeshlab get the points only (a points-only PLY is written first): the scan's ground-truth "
    "normals are withheld, every method estimates its own normals and that time is counted.",
    "Open3D normals: `estimate_normals(KDTreeSearchParamKNN(30))` then "
    "`orient_normals_consistent_tangent_plane(15)`. Poisson: `create_from_point_cloud_poisson(depth=8|9)` with "
    "default scale 1.1 and **no density trimming** (the scans are closed and cover the object, so the raw "
    "Poisson surface is kept; its low-density excess where coverage is thin counts against accuracy).",
    "Open3D Poisson depth 9 is almost the same mesh as depth 8 (torus: 37,204 / 37,216 / 37,206 / 37,206 "
    "vertices at depth 7 / 8 / 9 / 10): Open3D's adaptive octree stops refining where there are too few points "
    "per node (samples_per_node = 1.5 at ~20k points), so a deeper octree only costs time here.",
    "Open3D ball pivoting: same normals, radii = 1, 2, 4 × the mean nearest-neighbour spacing; it "
    "interpolates the noisy points, so its accuracy includes the scan noise and it leaves holes.",
    "pymeshlab: `compute_normal_for_point_clouds(k=10, smoothiter=0)` then "
    "`generate_surface_reconstruction_screened_poisson(depth=8)`, other parameters at their defaults.",
    "subdyn: `subdyn fit SCAN -o fit.obj --limit-out surf.ply --quiet` with default settings (tolerance 0.1 % "
    "of the diagonal on the 95th percentile, up to 3 levels); it reads the scan itself and ignores its normals. "
    "The measured output is the limit tessellation `surf.ply` (4×4 exact limit samples per control quad); the "
    "exact-limit figures below each table measure `fit.obj` with `--limit-a` instead. Vertices column: control "
    "points of `fit.obj` / vertices of `surf.ply`.",
    "OMP_WAIT_POLICY=PASSIVE is set for every method (Open3D and pymeshlab use OpenMP; with libgomp's default "
    "busy-waiting, pymeshlab's screened Poisson took 36 s instead of 6 s on the loaded 2-core machine).",
    "Timings are single runs, wall clock on a shared 2-core machine; Open3D and pymeshlab use their own threading "
    "defaults, subdyn its own (rayon) — read them as orders of magnitude.",
]


# --------------------------------------------------------------------------- scaling


def run_scaling(work: Path, resolutions: list[str]) -> list[dict]:
    """`subdyn fit` on one shape scanned at growing resolution; stops at the first size over the time limit."""
    rows = []
    out_dir = work / "scaling"
    out_dir.mkdir(parents=True, exist_ok=True)
    for res in resolutions:
        name = f"{SCALING_SHAPE}_{res.replace(',', 'x')}"
        ply = out_dir / f"{name}.ply"
        args = [SCALING_SHAPE, "--resolution", res] + SCAN_ARGS
        row = {"resolution": res, "command": "data-gen scan " + SCALING_SHAPE + " -o SCAN.ply " + " ".join(SCAN_ARGS)}
        log(f"scaling: data-gen scan {' '.join(args)}")
        run([DATA_GEN, "scan", "-o", ply] + args, cwd=ROOT, capture_output=True)
        row["points"] = json.loads((out_dir / f"{name}.json").read_text())["counts"]["total"]
        fit, surf, rep = out_dir / f"{name}_fit.obj", out_dir / f"{name}_limit.ply", out_dir / f"{name}_fit.json"
        row["loadavg"] = [round(x, 2) for x in os.getloadavg()]
        log(f"scaling: subdyn fit, {row['points']:,} points")
        t0 = time.perf_counter()
        try:
            run([SUBDYN, "fit", ply, "-o", fit, "--limit-out", surf, "--quiet", "--report", rep],
                capture_output=True, timeout=SCALING_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            row["error"] = f"did not finish in {SCALING_TIMEOUT_S:.0f} s"
            log(f"  {row['error']}; larger sizes skipped")
            rows.append(row)
            break
        row["seconds"] = time.perf_counter() - t0
        fr = json.loads(rep.read_text())["fit"]
        row["fit_seconds"] = fr.get("seconds")
        row["levels"] = len(fr.get("levels", []))
        row["control_points"] = info(fit)["vertices"]
        m = measure(surf, out_dir / f"{name}.truth.obj", out_dir, name)
        row["chamfer_pct"], row["hausdorff_pct"] = m["chamfer_pct"], m["hausdorff_pct"]
        log(f"  {row['seconds']:.2f} s, {row['control_points']} control points, Chamfer {row['chamfer_pct']:.4f} %")
        rows.append(row)
    return rows


# --------------------------------------------------------------------------- main


def keep_previous(results: dict, json_path: Path) -> None:
    """Adds the previous run's scans (and scaling table) that this run did not redo, in SCANS order."""
    try:
        old = json.loads(json_path.read_text())
    except (OSError, ValueError):
        return
    done = {sc["name"] for sc in results["scans"]}
    prev = [sc for sc in old.get("scans", []) if sc["name"] not in done]
    for sc in prev:
        sc.setdefault("run", {"date": old.get("machine", {}).get("date"),
                              "subdyn_commit": old.get("machine", {}).get("subdyn_commit")})
    order = {name: i for i, (name, *_rest) in enumerate(SCANS)}
    results["scans"] = sorted(results["scans"] + prev, key=lambda sc: order.get(sc["name"], len(order)))
    if "scaling" not in results and old.get("scaling"):
        results["scaling"] = old["scaling"]
        results["scaling_run"] = old.get("scaling_run", {k: old.get("machine", {}).get(k)
                                                          for k in ("date", "subdyn_commit")})


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--work", default=str(ROOT / "target" / "compare"), help="scratch directory (scans, outputs, reports)")
    ap.add_argument("--no-build", action="store_true", help="skip cargo build --release")
    ap.add_argument("--upgrade", action="store_true", help="reinstall the venv packages")
    ap.add_argument("--only", nargs="*",
                    help="scan names to run (default: all; `--only` with no name runs none, e.g. with --scaling)")
    ap.add_argument("--out", default=str(HERE), help="where RESULTS.md and RESULTS.json go")
    ap.add_argument("--seed", type=int, default=1,
                    help="noise seed of every scan (default 1, the committed results'); another seed shows how "
                         "much the figures depend on one noise draw (use with --out elsewhere)")
    ap.add_argument("--scaling", action="store_true",
                    help=f"also time subdyn fit on {SCALING_SHAPE} scans of ~10k, 30k, 100k and 1M points")
    ap.add_argument("--scaling-resolutions", nargs="*", default=SCALING_RESOLUTIONS,
                    help="pixels per view W,H of the scaling scans (8 views)")
    ap.add_argument("--keep", action="store_true",
                    help="keep the scans (and the scaling table) of the previous RESULTS.json that this run does not redo")
    ap.add_argument("--corpus", action="store_true",
                    help="the corpus benchmark instead of the four scans: every corpus shape fitted by subdyn, "
                         "Open3D Poisson depth 8 and pymeshlab, one table with the issue-24 criteria (README.md, Corpus)")
    ap.add_argument("--scans-only", action="store_true", help="with --corpus: write the corpus inputs and stop")
    ap.add_argument("--subdyn-only", action="store_true",
                    help="with --corpus: refit subdyn only, reusing each row's Poisson/pymeshlab figures from the "
                         "last run that made them (marked cached)")
    ap.add_argument("--shapes", metavar="A,B,C",
                    help="with --corpus: only these rows (row names like cow-n1 or shape names like cow); "
                         "RESULTS.* stay untouched, the table goes to WORK/corpus/last_table.md")
    ap.add_argument("--split", choices=["choose", "check"],
                    help="with --corpus: only the rows of this set (choose: defaults may be tuned on it; check: held out)")
    ap.add_argument("--baseline", action="store_true",
                    help="with --corpus: write the section 'Corpus baseline (before issue 24 work)' instead of "
                         "'Corpus benchmark'")
    args = ap.parse_args()
    corpus_only = [a for a in ("scans_only", "subdyn_only", "shapes", "split", "baseline") if getattr(args, a)]
    if corpus_only and not args.corpus:
        ap.error("--" + corpus_only[0].replace("_", "-") + " needs --corpus")

    # OpenMP threads that busy-wait (libgomp's default) starve each other and
    # the other processes on a small shared machine: pymeshlab's screened
    # Poisson took 36 s instead of 6 s under load. Passive waiting for all.
    os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
    ensure_venv(args)  # re-execs inside the venv when needed
    build_rust(args)
    for exe in (SUBDYN, DATA_GEN):
        if not exe.exists():
            log(f"missing {exe}; run cargo build --release")
            return 1
    r = subprocess.run([SUBDYN, "compare", "--help"], capture_output=True)
    if r.returncode != 0:
        log("`subdyn compare` is not available in this build; cannot measure")
        return 1

    if args.corpus:
        import corpus

        args.section = "Corpus baseline (before issue 24 work)" if args.baseline else "Corpus benchmark"
        args.section_key = "corpus_baseline" if args.baseline else "corpus"
        return corpus.main(args)
    SCAN_ARGS[SCAN_ARGS.index("--seed") + 1] = str(args.seed)
    work = Path(args.work)
    work.mkdir(parents=True, exist_ok=True)
    scans = [s for s in SCANS if args.only is None or s[0] in args.only]
    t_all = time.perf_counter()
    notes = [n.replace("seed 1,", f"seed {args.seed},") for n in NOTES]
    results = {"machine": machine(), "scans": [], "notes": notes, "skipped": []}
    for sc in generate_scans(work, scans, results["skipped"]):
        sc["loadavg"] = [round(x, 2) for x in os.getloadavg()]
        sc["run"] = {k: results["machine"][k] for k in ("date", "subdyn_commit")}
        out_dir = work / sc["name"]
        out_dir.mkdir(exist_ok=True)
        xyz = out_dir / "points_only.ply"
        write_xyz_ply(xyz, read_points(sc["scan"]))
        rows = []
        for label, tag, fn in METHODS:
            log(f"{sc['name']}: {label}")
            row = {"method": label, "tag": tag}
            try:
                t0 = time.perf_counter()
                res = fn(xyz, out_dir, sc)
                row["seconds"] = time.perf_counter() - t0
                row["output"] = str(res["output"])
                row["params"] = res.get("params")
                row.update(measure(res["output"], sc["truth"], out_dir, tag))
                sc["diagonal"] = row["diagonal"]
                if "control_mesh" in res:
                    ci = info(res["control_mesh"])
                    row["control_points"] = ci["vertices"]
                    row["control_faces"] = ci["faces"]
                    row["control_genus"] = ci.get("genus")
                    row["control_watertight"] = ci["boundary_edges"] == 0 and ci["non_manifold_edges"] == 0
                    try:
                        row["fit_report"] = json.loads(Path(res["fit_report"]).read_text())
                    except (OSError, ValueError):
                        pass
                    le = measure(res["control_mesh"], sc["truth"], out_dir, tag + "_limit_exact", ["--limit-a"])
                    row["limit_exact"] = {k: le[k] for k in ("accuracy_mean_pct", "accuracy_p95_pct",
                                                             "accuracy_max_pct", "completeness_mean_pct",
                                                             "completeness_p95_pct", "completeness_max_pct",
                                                             "chamfer_pct", "hausdorff_pct")}
                log(f"  {row['seconds']:.2f} s, {row['vertices']} vertices, Chamfer {row['chamfer_pct']:.4f} %, "
                    f"Hausdorff {row['hausdorff_pct']:.3f} %, watertight {row['watertight']}")
            except Exception as e:  # noqa: BLE001 — a failing method is a row, not a crash
                msg = str(e)
                if isinstance(e, subprocess.CalledProcessError) and e.stderr:
                    msg = (e.stderr.decode() if isinstance(e.stderr, bytes) else e.stderr).strip().splitlines()[-1]
                row["error"] = msg
                log(f"  FAILED: {msg}")
            rows.append(row)
        sc["methods"] = rows
        sc["scan"], sc["truth"] = str(sc["scan"]), str(sc["truth"])
        results["scans"].append(sc)
    if args.scaling:
        results["scaling"] = run_scaling(work, args.scaling_resolutions)
    results["total_seconds"] = time.perf_counter() - t_all
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    if args.keep:
        keep_previous(results, out / "RESULTS.json")
    write_results(results, out / "RESULTS.md", out / "RESULTS.json")
    log(f"wrote {out / 'RESULTS.md'} and RESULTS.json in {results['total_seconds']:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
