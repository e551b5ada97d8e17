#!/usr/bin/env python3
"""Volume recovery: `subdyn recover` against scikit-image's marching cubes.

One command (from anywhere; needs target/release/subdyn and target/release/data-gen):

    python3 benches/compare/recover_vs_marching_cubes.py

1. creates (or reuses) benches/compare/.venv, installs numpy, scipy and
   scikit-image there (PyPI) and re-runs itself inside it;
2. generates three volumes with ground truth into a temporary directory with
   the project's own generator (`data-gen volume SHAPE --format raw ...`):
   sphere (genus 0), torus (genus 1), genus2 (genus 2), each with a Gaussian
   blur of 0.03 mm and Gaussian noise σ = 0.05 (inside 1, outside 0);
3. extracts the sidecar's iso-surface with `skimage.measure.marching_cubes`,
   on the raw volume and on the volume smoothed by a Gaussian of one voxel
   (σ = the smallest spacing in world units, per axis σ/spacing voxels: what
   `subdyn recover` does by default), mapped to world coordinates
   (world = origin + index × spacing);
4. runs `subdyn recover BASE.json --iso ISO -o fit.obj --limit-out surf.ply
   --report r.json --quiet` with default settings;
5. measures every surface against BASE.truth.obj with the same code
   (`subdyn compare SURF TRUTH --report C.json`): Chamfer and Hausdorff in
   voxels (÷ the smallest spacing) and in % of the truth's bounding-box diagonal;
6. prints the Markdown tables (the section "Volume recovery vs marching cubes"
   of RESULTS.md is built from them) and writes every figure to
   recover_vs_marching_cubes.json beside this script.

Options: --repeat N (timed runs per method, median reported; default 3),
--keep DIR (keep volumes, meshes and compare reports there instead of a
temporary directory), --subdyn / --data-gen (binaries), --out DIR.

A comparison beside the product, never a dependency of it; not part of CI.
Standard library only outside the venv.
"""

from __future__ import annotations

import argparse
import datetime
import hashlib
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent  # workspace root
VENV = HERE / ".venv"
VENV_PY = VENV / "bin" / "python"
PACKAGES = ["numpy", "scipy", "scikit-image"]

# (name, genus, data-gen arguments after the shape)
VOLUMES = [
    ("sphere", 0, ["--dims", "96,96,48", "--spacing", "0.025,0.025,0.05"]),
    ("torus", 1, ["--dims", "128,128,32", "--spacing", "0.028,0.028,0.05"]),
    ("genus2", 2, ["--dims", "144,84,24", "--spacing", "0.045,0.045,0.06"]),
]
COMMON_ARGS = ["--blur", "0.03", "--noise", "0.05"]


def log(msg: str) -> None:
    print(f"[recover-vs-mc] {msg}", file=sys.stderr, flush=True)


def run(cmd, **kw) -> subprocess.CompletedProcess:
    return subprocess.run([str(c) for c in cmd], check=True, **kw)


def in_venv() -> bool:
    return Path(sys.prefix).resolve() == VENV.resolve()


def ensure_venv(args) -> None:
    """Create the venv, install the packages, re-exec this script inside it."""
    if in_venv():
        return
    if not VENV_PY.exists():
        log(f"creating virtual environment {VENV}")
        run([sys.executable, "-m", "venv", VENV])
    r = subprocess.run([VENV_PY, "-c", "import numpy, scipy, skimage"], capture_output=True)
    if r.returncode != 0 or args.upgrade:
        log("installing " + " ".join(PACKAGES) + " into the venv")
        run([VENV_PY, "-m", "pip", "install", "-q"] + PACKAGES)
    os.execv(str(VENV_PY), [str(VENV_PY), str(Path(__file__).resolve())] + sys.argv[1:])


# --------------------------------------------------------------------------- I/O


def read_volume(side: dict, base: Path):
    """The raw f32 volume as an array indexed [x, y, z], intensities scaled to physical units."""
    import numpy as np

    nx, ny, nz = side["dims"]
    assert side["dtype"] == "f32" and side["byte_order"] == "little", side
    raw = base.parent / side["files"][0]
    data = np.fromfile(raw, dtype="<f4", offset=int(side.get("header_bytes", 0)))
    assert data.size == nx * ny * nz, (data.size, nx, ny, nz)
    # x fastest, then y, then z: C order (z, y, x); transpose to [x, y, z].
    vol = data.reshape(nz, ny, nx).transpose(2, 1, 0)
    scale = side.get("intensity_scale", {"slope": 1.0, "intercept": 0.0})
    vol = vol.astype(np.float64) * scale["slope"] + scale["intercept"]
    return np.ascontiguousarray(vol)


def write_ply(path: Path, verts, faces) -> None:
    """Binary little-endian PLY: double x y z, triangles as `list uchar int`."""
    import numpy as np

    verts = np.ascontiguousarray(verts, dtype="<f8")
    faces = np.asarray(faces, dtype="<i4")
    rec = np.empty(len(faces), dtype=[("n", "u1"), ("i", "<i4", (3,))])
    rec["n"] = 3
    rec["i"] = faces
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(verts)}\n"
        "property double x\nproperty double y\nproperty double z\n"
        f"element face {len(faces)}\n"
        "property list uchar int vertex_indices\nend_header\n"
    )
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(verts.tobytes())
        f.write(rec.tobytes())


def obj_vertex_count(path: Path) -> int:
    with open(path) as f:
        return sum(1 for line in f if line.startswith("v "))


def read_ply(path: Path):
    """Vertex positions and faces of a binary little-endian PLY (faces of one size only)."""
    import numpy as np

    data = path.read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    assert header[1].startswith("format binary_little_endian"), header[1]
    types = {"double": "<f8", "float": "<f4", "float64": "<f8", "float32": "<f4"}
    nv = nf = 0
    props, elem = [], None
    for line in header:
        w = line.split()
        if w[0] == "element":
            elem = w[1]
            if elem == "vertex":
                nv = int(w[2])
            elif elem == "face":
                nf = int(w[2])
        elif w[0] == "property" and elem == "vertex":
            props.append((w[2], types[w[1]]))
        elif w[0] == "property" and elem == "face":
            assert w[1:4] == ["list", "uchar", "int"], line
    vdt = np.dtype(props)
    v = np.frombuffer(data, dtype=vdt, count=nv, offset=end)
    verts = np.stack([v["x"], v["y"], v["z"]], axis=1).astype(float)
    off = end + nv * vdt.itemsize
    k = data[off]
    fdt = np.dtype([("n", "u1"), ("i", "<i4", (k,))])
    f = np.frombuffer(data, dtype=fdt, count=nf, offset=off)
    assert (f["n"] == k).all(), "mixed face sizes"
    return verts, f["i"].astype(np.int64)


def signed_distance_fn(side: dict):
    """The analytic signed distance (+ outside) of the generator's shape, from the sidecar, or None.

    sphere |p| − r; torus about z √((√(x²+y²) − R)² + z²) − r; genus2 the smooth union of two such
    tori (its sidecar formula, an approximate signed distance: exact away from the blend).
    """
    import numpy as np

    a = side.get("truth", {}).get("analytic", {})
    shape = side.get("shape")
    if shape == "sphere":
        c, r = np.array(a["centre"]), a["radius"]
        return lambda p: np.linalg.norm(p - c, axis=1) - r
    if shape == "torus" and a.get("axis") == [0.0, 0.0, 1.0]:
        R, r = a["major_radius"], a["minor_radius"]
        return lambda p: np.hypot(np.hypot(p[:, 0], p[:, 1]) - R, p[:, 2]) - r
    if shape == "genus2" and "c = 1.1, R = 1, r = 0.4, k = 0.1" in a.get("implicit", ""):
        c, R, r, k = 1.1, 1.0, 0.4, 0.1

        def f(p):
            t1 = np.hypot(np.hypot(p[:, 0] - c, p[:, 1]) - R, p[:, 2]) - r
            t2 = np.hypot(np.hypot(p[:, 0] + c, p[:, 1]) - R, p[:, 2]) - r
            m = np.minimum(t1, t2)
            return m - k * np.log(np.exp(-(t1 - m) / k) + np.exp(-(t2 - m) / k))

        return f
    return None


def mean_signed_offset(path: Path, sdf) -> float:
    """Area-weighted mean of the analytic signed distance over a mesh (vertex areas: ⅓ of the
    incident triangles' areas; polygons fanned into triangles)."""
    import numpy as np

    verts, faces = read_ply(path)
    w = np.zeros(len(verts))
    for j in range(1, faces.shape[1] - 1):
        a, b, c = verts[faces[:, 0]], verts[faces[:, j]], verts[faces[:, j + 1]]
        area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
        for idx in (faces[:, 0], faces[:, j], faces[:, j + 1]):
            np.add.at(w, idx, area / 3.0)
    return float((w * sdf(verts)).sum() / w.sum())


def median_wall(fn, repeat: int):
    """Run fn() repeat times; its first result and the median and all wall times."""
    times, first = [], None
    for i in range(repeat):
        t0 = time.perf_counter()
        res = fn()
        times.append(time.perf_counter() - t0)
        if i == 0:
            first = res
    return first, statistics.median(times), times


# --------------------------------------------------------------------------- methods


def marching_cubes(side: dict, base: Path, out: Path, smooth: bool) -> dict:
    """Read, optionally smooth by one voxel, extract the iso-surface, write it. Timed as a whole."""
    import numpy as np
    from scipy import ndimage
    from skimage import measure

    t0 = time.perf_counter()
    vol = read_volume(side, base)
    spacing = np.array(side["spacing"], dtype=float)
    origin = np.array(side["origin"], dtype=float)
    sigma_world = float(spacing.min())  # one voxel, as subdyn recover's default
    t_smooth = 0.0
    if smooth:
        ts = time.perf_counter()
        vol = ndimage.gaussian_filter(vol, sigma=tuple(sigma_world / spacing), mode="nearest")
        t_smooth = time.perf_counter() - ts
    tm = time.perf_counter()
    verts, faces, _normals, _values = measure.marching_cubes(
        vol, level=float(side["iso_value"]), spacing=tuple(spacing)
    )
    t_mc = time.perf_counter() - tm
    verts = verts + origin  # voxel centres at integer indexes: world = origin + index × spacing
    write_ply(out, verts, faces)
    total = time.perf_counter() - t0
    return {
        "vertices": int(len(verts)),
        "faces": int(len(faces)),
        "seconds": total,
        "marching_cubes_seconds": t_mc,
        "smoothing_seconds": t_smooth,
        "smoothing_sigma_world": sigma_world if smooth else None,
        "smoothing_sigma_voxels": list(sigma_world / spacing) if smooth else None,
    }


def subdyn_recover(subdyn: Path, base: Path, iso: float, work: Path) -> dict:
    fit, surf, rep = work / f"{base.stem}.fit.obj", work / f"{base.stem}.surf.ply", work / f"{base.stem}.recover.json"
    cmd = [subdyn, "recover", base, "--iso", repr(iso), "-o", fit, "--limit-out", surf,
           "--report", rep, "--quiet"]
    t0 = time.perf_counter()
    run(cmd, capture_output=True)
    wall = time.perf_counter() - t0
    report = json.loads(rep.read_text())
    fit_sha = hashlib.sha256(fit.read_bytes()).hexdigest()[:16]
    levels = report["recover"]["levels"]
    return {
        "command": " ".join(str(c) for c in
                            ["subdyn", "recover", base.name, "--iso", repr(iso), "-o", fit.name,
                             "--limit-out", surf.name, "--report", rep.name, "--quiet"]),
        "fit": fit,
        "surf": surf,
        "fit_sha": fit_sha,
        "seconds": wall,
        "control_points": obj_vertex_count(fit),
        "control_points_per_level": [lv["control_points"] for lv in levels],
        "limit_vertices": None,  # filled from the compare report
        "stop_reason": report["recover"].get("stop_reason"),
        "converged": report["recover"].get("converged"),
        "init": report.get("init"),
        "report_total_s": report.get("total_s"),
    }


def compare(subdyn: Path, surf: Path, truth: Path, rep: Path, limit_a: bool = False) -> dict:
    cmd = [subdyn, "compare", surf, truth, "--report", rep, "--quiet"] + (["--limit-a"] if limit_a else [])
    run(cmd, capture_output=True)
    return json.loads(rep.read_text())


# --------------------------------------------------------------------------- main


def fmt_int(n) -> str:
    return f"{n:,}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--subdyn", type=Path, default=ROOT / "target" / "release" / "subdyn")
    ap.add_argument("--data-gen", type=Path, default=ROOT / "target" / "release" / "data-gen")
    ap.add_argument("--out", type=Path, default=HERE, help="where the .json and .md go")
    ap.add_argument("--keep", type=Path, default=None, help="keep volumes and outputs in this directory")
    ap.add_argument("--repeat", type=int, default=3, help="timed runs per method (median reported)")
    ap.add_argument("--upgrade", action="store_true", help="reinstall the venv packages")
    args = ap.parse_args()
    ensure_venv(args)

    import numpy
    import scipy
    import skimage

    for b in (args.subdyn, args.data_gen):
        if not b.exists():
            sys.exit(f"missing {b}: build it first (cargo build --release; cargo build --release -p data-gen)")

    git = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True)
    commit = git.stdout.strip() or "unknown"
    dirty = subprocess.run(["git", "-C", ROOT, "status", "--porcelain", "--untracked-files=no",
                            "--", ".", ":!benches/compare"],
                           capture_output=True, text=True).stdout.strip()
    if dirty:
        commit += "-dirty"
    subdyn_sha = hashlib.sha256(args.subdyn.read_bytes()).hexdigest()[:16]
    subdyn_mtime = datetime.datetime.fromtimestamp(args.subdyn.stat().st_mtime, datetime.timezone.utc)
    version = subprocess.run([args.subdyn, "--version"], capture_output=True, text=True).stdout.strip()
    cpu = "unknown"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    meta = {
        "date_utc": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "nproc": os.cpu_count(),
        "cpu": cpu,
        "loadavg_start": list(os.getloadavg()),
        "platform": platform.platform(),
        "python": platform.python_version(),
        "numpy": numpy.__version__,
        "scipy": scipy.__version__,
        "scikit_image": skimage.__version__,
        "subdyn_commit": commit,
        "subdyn_binary": str(args.subdyn),
        "subdyn_binary_sha256_16": subdyn_sha,
        "subdyn_binary_mtime_utc": subdyn_mtime.strftime("%Y-%m-%d %H:%M:%S UTC"),
        "subdyn_version": version,
    }

    tmp = None
    if args.keep:
        work = args.keep.resolve()
        work.mkdir(parents=True, exist_ok=True)
    else:
        tmp = tempfile.TemporaryDirectory(prefix="recover_vs_mc_")
        work = Path(tmp.name)

    shapes = []
    for name, genus, dims_args in VOLUMES:
        base_raw = work / f"{name}.raw"
        gen_args = ["volume", name, "-o", base_raw, "--format", "raw"] + dims_args + COMMON_ARGS
        gen_cmd = "data-gen " + " ".join(str(a) if not isinstance(a, Path) else a.name for a in gen_args)
        log(gen_cmd)
        run([args.data_gen] + gen_args, capture_output=True)
        base = work / f"{name}.json"
        side = json.loads(base.read_text())
        truth = work / side["truth_mesh"]
        iso = float(side["iso_value"])
        voxel = float(min(side["spacing"]))
        diag = float(side["truth"]["bounding_box"]["diagonal"])
        truth_chord = side["truth"].get("max_face_centroid_distance_to_analytic_surface")

        sdf = signed_distance_fn(side)
        rows = []

        def measured(method, surf, extra, limit_a=False, tag=""):
            rep = compare(args.subdyn, surf, truth, work / f"{name}.{tag}.compare.json", limit_a)
            return dict(
                method=method,
                chamfer=rep["chamfer"],
                hausdorff=rep["hausdorff"],
                chamfer_vox=rep["chamfer"] / voxel,
                hausdorff_vox=rep["hausdorff"] / voxel,
                chamfer_pct=rep["chamfer_pct"],
                hausdorff_pct=rep["hausdorff_pct"],
                measured_vertices=rep["a"]["vertices"],
                mean_signed_offset_vox=(mean_signed_offset(surf, sdf) / voxel
                                        if sdf is not None and surf.suffix == ".ply" else None),
                **extra,
            )

        for smooth in (False, True):
            tag = "mc_smooth" if smooth else "mc"
            out = work / f"{name}.{tag}.ply"
            log(f"{name}: marching cubes{' on the 1-voxel-smoothed volume' if smooth else ''}")
            mc, med, times = median_wall(lambda: marching_cubes(side, base, out, smooth), args.repeat)
            mc["seconds"], mc["seconds_all"] = med, times
            label = "marching cubes, σ = 1 voxel smoothing" if smooth else "marching cubes, raw volume"
            rows.append(measured(label, out, dict(kind=tag, **mc), tag=tag))

        log(f"{name}: subdyn recover")
        runs = [subdyn_recover(args.subdyn, base, iso, work) for _ in range(args.repeat)]
        sd = runs[-1]  # its files are the ones on disk
        sd["seconds_all"] = [r["seconds"] for r in runs]
        sd["seconds"] = statistics.median(sd["seconds_all"])
        sd["fit_obj_sha256_16_per_run"] = [r.pop("fit_sha") for r in runs]
        sd["identical_across_runs"] = len(set(sd["fit_obj_sha256_16_per_run"])) == 1
        fit, surf = sd.pop("fit"), sd.pop("surf")
        row = measured("subdyn recover (limit tessellation, K = 4)", surf, dict(kind="subdyn", **sd), tag="subdyn")
        row["limit_vertices"] = row["measured_vertices"]
        row["vertices"] = sd["control_points"]
        rows.append(row)
        exact = measured("subdyn recover (exact limit surface, --limit-a)", fit,
                         dict(kind="subdyn_exact", vertices=sd["control_points"], seconds=sd["seconds"]),
                         limit_a=True, tag="subdyn_exact")
        rows.append(exact)

        mc_rows = [r for r in rows if r["kind"] in ("mc", "mc_smooth")]
        verdicts = {}
        for r in mc_rows:
            verdicts[r["kind"]] = {
                "chamfer_equal_or_better": row["chamfer"] <= r["chamfer"],
                "vertices_at_most_one_tenth": row["vertices"] * 10 <= r["vertices"],
                "vertex_ratio": r["vertices"] / row["vertices"],
                "chamfer_ratio_subdyn_over_mc": row["chamfer"] / r["chamfer"],
            }
        shapes.append(dict(
            name=name, genus=genus, command=gen_cmd, dims=side["dims"], spacing=side["spacing"],
            origin=side["origin"], iso_value=iso, voxel=voxel, truth_diagonal=diag,
            truth_vertices=side["truth"]["vertices"],
            truth_max_face_centroid_distance_to_analytic=truth_chord,
            rows=rows, verdict=verdicts,
        ))

    if tmp is not None:
        tmp.cleanup()

    # ----------------------------------------------------------------------- output
    result = {"meta": meta, "shapes": shapes,
              "definitions": {
                  "chamfer": "subdyn compare: (mean A->B + mean B->A)/2 over 100,000 area-weighted samples each way",
                  "hausdorff": "subdyn compare: max of both one-sided maxima (samples plus vertices)",
                  "voxels": "distance / smallest spacing of the volume",
                  "pct": "% of the ground truth's bounding-box diagonal",
                  "vertices": "marching cubes: mesh vertices; subdyn: control points of fit.obj",
                  "mean_signed_offset_vox": "area-weighted mean of the shape's analytic signed distance (+ outside) over the measured tessellation, in voxels (genus2: its smooth-union formula, approximate near the blend); not for --limit-a rows",
                  "seconds_mc": "median over --repeat runs of: read raw + (smoothing) + marching_cubes + write PLY, in Python",
                  "seconds_subdyn": "median over --repeat runs of the wall clock of the whole `subdyn recover` process (read, smooth, init, fit, write fit.obj + surf.ply + report)",
              }}
    (args.out / "recover_vs_marching_cubes.json").write_text(json.dumps(result, indent=2) + "\n")

    md = []
    md.append(f"**Machine:** {meta['nproc']} cores ({meta['cpu']}), shared with other builds "
              f"(load average at start {', '.join(f'{x:.2f}' for x in meta['loadavg_start'])}); "
              f"Python {meta['python']}, scikit-image {meta['scikit_image']}, scipy {meta['scipy']}, "
              f"numpy {meta['numpy']}; subdyn commit `{meta['subdyn_commit']}` (binary {meta['subdyn_binary']}, "
              f"built {meta['subdyn_binary_mtime_utc']}, sha256 {meta['subdyn_binary_sha256_16']}…); "
              f"run {meta['date_utc']}.")
    md.append("")
    for s in shapes:
        md.append(f"### {s['name']} (genus {s['genus']}, {s['dims'][0]}×{s['dims'][1]}×{s['dims'][2]} voxels, "
                  f"spacing {', '.join(str(x) for x in s['spacing'])}; 1 voxel = {s['voxel']} = "
                  f"{100 * s['voxel'] / s['truth_diagonal']:.3f} % of the diagonal {s['truth_diagonal']:.4f})")
        md.append("")
        md.append(f"Volume: `{s['command']}`, iso-value {s['iso_value']}.")
        md.append("")
        md.append("| method | vertices / control points | Chamfer (voxels) | Hausdorff (voxels) | Chamfer % diag | Hausdorff % diag | mean signed offset (voxels) | seconds (median of " + str(args.repeat) + ") |")
        md.append("|---|---:|---:|---:|---:|---:|---:|---:|")
        for r in s["rows"]:
            if r["kind"] == "subdyn":
                v = f"{fmt_int(r['vertices'])} control points ({fmt_int(r['limit_vertices'])} limit-mesh vertices)"
            elif r["kind"] == "subdyn_exact":
                v = f"{fmt_int(r['vertices'])} control points"
            else:
                v = fmt_int(r["vertices"])
            so = "—" if r["mean_signed_offset_vox"] is None else f"{r['mean_signed_offset_vox']:+.4f}"
            secs = f"{r['seconds']:.2f}" if r["kind"] != "subdyn_exact" else "(same run)"
            md.append(f"| {r['method']} | {v} | {r['chamfer_vox']:.4f} | {r['hausdorff_vox']:.3f} | "
                      f"{r['chamfer_pct']:.4f} | {r['hausdorff_pct']:.3f} | {so} | {secs} |")
        md.append("")
        parts = []
        for kind, label in (("mc", "raw marching cubes"), ("mc_smooth", "smoothed marching cubes")):
            v = s["verdict"][kind]
            ok = v["chamfer_equal_or_better"] and v["vertices_at_most_one_tenth"]
            parts.append(
                f"against {label}: Chamfer {'equal or better' if v['chamfer_equal_or_better'] else 'WORSE'} "
                f"(subdyn/MC = {v['chamfer_ratio_subdyn_over_mc']:.2f}), MC has {v['vertex_ratio']:.1f}× "
                f"subdyn's control points ({'≥ 10×' if v['vertices_at_most_one_tenth'] else '< 10×'}) → "
                f"**{'yes' if ok else 'no'}**")
        subrow = next(r for r in s["rows"] if r["kind"] == "subdyn")
        if not subrow["identical_across_runs"]:
            md.append(f"Note: the {args.repeat} subdyn runs wrote different fit.obj files; the last run is measured.")
            md.append("")
        md.append("Equal or better Chamfer with at most one tenth of the vertices? " + "; ".join(parts) + ".")
        md.append("")
    text = "\n".join(md)
    print(text)


if __name__ == "__main__":
    main()
