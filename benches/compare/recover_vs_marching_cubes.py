#!/usr/bin/env python3
"""Volume recovery: `subdyn recover` against scikit-image's marching cubes.

One command (from anywhere; needs target/release/subdyn and target/release/data-gen):

    python3 benches/compare/recover_vs_marching_cubes.py

1. creates (or reuses) benches/compare/.venv, installs numpy, scipy and
   scikit-image there (PyPI) and re-runs itself inside it;
2. generates the volumes with ground truth into a temporary directory with
   the project's own generator (`data-gen volume SHAPE --format raw ...`, or
   `data-gen volume --mesh FILE ...`), all with Gaussian noise σ = 0.05
   (inside 1, outside 0) and a Gaussian blur of 0.03 mm unless noted:
   - sphere (genus 0), torus (genus 1), genus2 (genus 2): the analytic shapes;
   - spot, cow, rocker-arm (genus 0, 0, 1): the meshes in ../shared/data/meshes
     (or the folder in SUBDYN_SHARED_MESHES), rasterised with --mesh; a missing
     mesh is reported as skipped;
   - chair (genus 5; 0.08 × 0.08 legs, 0.08 × 0.04 slats), bracket (genus 4),
     plate (genus 1), anvil, bulb (genus 0): data-gen's built-in shapes. The
     chair's spacing 0.032, 0.016, 0.032 makes every thin part 2.5 voxels thick
     along its thinnest axis (legs along x, slats along x and y, seat along z),
     and its blur is 0.016 mm (one voxel of its finest axis): at 0.03 mm the
     slats' centre intensity is 0.41, below the iso-value, so the slats are not
     in the volume at all (measured and printed: the chair volume is also
     generated at 0.03 mm for that check). The widths of the legs and slats in
     the volume are measured (the above-iso run along x and along y through
     each part's centre, iso crossings linearly interpolated, mean over the
     four legs or slats and every z slice of their middle) and printed;
   - sphere-cut: the unit sphere in a 40 × 40 × 30 grid of 0.06 whose top face
     (z = 0.57) cuts it, as in data-gen/tests/recover_cut.rs. Its truth is the
     sphere clipped at the box face (meshed by marching cubes on its exact
     signed distance at a 0.01 grid, ⅙ voxel), not data-gen's whole sphere.
     Also measured: the exit code, whether the control mesh is closed
     (`subdyn info --json`: no boundary or non-manifold edge, one component),
     and how far the cap lies from the box face: of the limit tessellation's
     vertices (`--limit-out`) above the face minus 3 voxels and inside the rim
     (and, as in the test, 3 voxels in from the rim), the largest |z − face|
     in voxels;
3. extracts the sidecar's iso-surface with `skimage.measure.marching_cubes`,
   on the raw volume and on the volume smoothed by a Gaussian of one voxel
   (σ = the smallest spacing in world units, per axis σ/spacing voxels;
   subdyn recover's default for edges, it smooths an iso-surface by half a
   voxel), mapped to world coordinates (world = origin + index × spacing);
4. runs `subdyn recover BASE.json --iso ISO -o fit.obj --limit-out surf.ply
   --report r.json --quiet` with default settings, each run in a fresh
   process under `/usr/bin/time -v` (peak RSS; without it
   resource.getrusage(RUSAGE_CHILDREN) in a fresh wrapper process). A failed
   run (non-zero exit, e.g. a poor result refused) is recorded with its exit
   code and stderr line and shown in the tables, never skipped;
5. measures every surface against the truth mesh with the same code
   (`subdyn compare SURF TRUTH --report C.json`): Chamfer and Hausdorff in
   voxels (÷ the smallest spacing) and in % of the truth's bounding-box
   diagonal; `subdyn info --json` gives the fit's genus and closedness;
6. checks, per volume, subdyn's limit tessellation against marching cubes on
   the raw volume at the same iso: Chamfer ≤ MC's, Hausdorff ≤ MC's, control
   points ≤ MC vertices / 10 (pass/fail columns);
7. the MNI152 2009a templates in ../shared/data/volumes (or the folder in
   SUBDYN_SHARED_VOLUMES): on the T1, `subdyn recover T1 --iso ISO` (the
   docs give no whole-brain command; ISO = half the median intensity of the
   voxels 3-5 voxels inside the skull-stripped brain's edge, computed here
   with numpy/scipy, the background being 0) against a fresh Python process
   that reads the NIfTI, smooths by half a voxel (f32; subdyn's cage smoothing, its forces use a quarter) with
   scipy.ndimage.gaussian_filter and runs marching cubes at the same iso,
   interleaved, --repeat times each; both under /usr/bin/time -v: wall time,
   peak RSS ÷ (voxels × 4 bytes), the ratio subdyn ÷ (smoothing + marching
   cubes), and an import-only Python process as the interpreter's baseline.
   The same for the docs' ventricle command (`--auto --seed -6,0,18 --dark
   --iso 120`; marching cubes extracts every 120 level set, so only time and
   memory compare). The grey-matter map at `--iso 128`: exit code, stderr line,
   time and peak RSS;
8. prints the Markdown tables (the section "Volume recovery vs marching cubes"
   of RESULTS.md is built from them) and writes every figure to
   recover_vs_marching_cubes.json beside this script (--out).

Options: --repeat N (timed runs per method, median reported; default 3),
--keep DIR (keep volumes, meshes and compare reports there instead of a
temporary directory), --subdyn / --data-gen (binaries), --out DIR,
--no-mni (skip step 7), --sigma-voxels F (subdyn recover with `--sigma` of F voxels
instead of its default, for experiments).

A comparison beside the product, never a dependency of it; not part of CI.
Standard library only outside the venv.
"""

from __future__ import annotations

import argparse
import datetime
import hashlib
import json
import math
import os
import platform
import shlex
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
SHARED_DATA = ROOT.parent / "shared" / "data"
SHARED_MESHES = Path(os.environ.get("SUBDYN_SHARED_MESHES", str(SHARED_DATA / "meshes")))
SHARED_VOLUMES = Path(os.environ.get("SUBDYN_SHARED_VOLUMES", str(SHARED_DATA / "volumes")))
MNI_T1 = SHARED_VOLUMES / "mni_icbm152_t1_tal_nlin_sym_09a_converted.nii.gz"
MNI_GM = SHARED_VOLUMES / "mni_icbm152_gm_tal_nlin_sym_09a_converted.nii.gz"
GNU_TIME = Path("/usr/bin/time")

BLUR, NOISE = "0.03", "0.05"
COMMON_ARGS = ["--blur", BLUR, "--noise", NOISE]

# The chair's thin parts (data-gen/src/shapes/machined.rs, CHAIR): name, nominal width per axis,
# centres (x, y) of the four parts, z range of the lines measured.
CHAIR_PARTS = [
    ("leg", {"x": 0.08, "y": 0.08}, [(-0.46, -0.46), (0.46, -0.46), (-0.46, 0.46), (0.46, 0.46)], (0.1, 0.8)),
    ("slat", {"x": 0.08, "y": 0.04}, [(-0.27, 0.46), (-0.09, 0.46), (0.09, 0.46), (0.27, 0.46)], (1.05, 1.65)),
]


def volume(name, source, dims_args, genus=None, blur=None, **extra) -> dict:
    """A volume: SOURCE a built-in shape name or a mesh Path; genus None = the truth's (sidecar)."""
    return dict(name=name, source=source, dims_args=dims_args, genus=genus,
                blur=blur, **extra)


VOLUMES = [
    volume("sphere", "sphere", ["--dims", "96,96,48", "--spacing", "0.025,0.025,0.05"], genus=0),
    volume("torus", "torus", ["--dims", "128,128,32", "--spacing", "0.028,0.028,0.05"], genus=1),
    volume("genus2", "genus2", ["--dims", "144,84,24", "--spacing", "0.045,0.045,0.06"], genus=2),
    volume("spot", SHARED_MESHES / "spot.obj", ["--spacing", "0.02,0.02,0.03"]),
    volume("cow", SHARED_MESHES / "cow.obj", ["--spacing", "0.015,0.015,0.0225"]),
    volume("rocker-arm", SHARED_MESHES / "rocker-arm.obj", ["--spacing", "0.01,0.01,0.015"]),
    volume("chair", "chair", ["--spacing", "0.032,0.016,0.032"], blur="0.016",
           parts=CHAIR_PARTS, blur_check=BLUR),
    volume("bracket", "bracket", ["--spacing", "0.025,0.025,0.035"]),
    volume("plate", "plate", ["--spacing", "0.025,0.025,0.025"]),
    volume("anvil", "anvil", ["--spacing", "0.025,0.025,0.035"]),
    volume("bulb", "bulb", ["--spacing", "0.03,0.03,0.045"]),
    volume("sphere-cut", "sphere",
           ["--dims", "40,40,30", "--spacing", "0.06,0.06,0.06", "--origin=-1.17,-1.17,-1.2"],
           genus=0, cut=True),
]


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


NIFTI_DTYPES = {2: "u1", 4: "i2", 8: "i4", 16: "f4", 64: "f8", 256: "i1", 512: "u2", 768: "u4"}


def read_nifti(path: Path):
    """A NIfTI-1 volume (.nii or .nii.gz) as an f32 array indexed [x, y, z] (scl_slope/scl_inter
    applied) and its 4×4 voxel-to-world map (the sform, else the pixdim scaling, with a note)."""
    import gzip
    import struct

    import numpy as np

    raw = (gzip.open if str(path).endswith(".gz") else open)(path, "rb").read()
    bo = "<" if struct.unpack("<i", raw[:4])[0] == 348 else ">"
    assert struct.unpack(bo + "i", raw[:4])[0] == 348, "not a NIfTI-1 file"
    dim = struct.unpack(bo + "8h", raw[40:56])
    datatype = struct.unpack(bo + "h", raw[70:72])[0]
    pixdim = struct.unpack(bo + "8f", raw[76:108])
    vox_offset = int(struct.unpack(bo + "f", raw[108:112])[0])
    slope, inter = struct.unpack(bo + "2f", raw[112:120])
    sform_code = struct.unpack(bo + "h", raw[254:256])[0]
    nx, ny, nz = dim[1:4]
    dt = np.dtype(NIFTI_DTYPES[datatype]).newbyteorder(bo)
    vol = np.frombuffer(raw, dtype=dt, count=nx * ny * nz, offset=vox_offset)
    vol = vol.reshape(nz, ny, nx).transpose(2, 1, 0).astype(np.float32)
    if slope not in (0.0, 1.0) or inter != 0.0:
        vol = vol * np.float32(slope or 1.0) + np.float32(inter)
    affine = np.eye(4)
    if sform_code > 0:
        affine[:3, :] = np.array(struct.unpack(bo + "12f", raw[280:328])).reshape(3, 4)
        note = f"sform (code {sform_code})"
    else:
        affine[:3, :3] = np.diag(pixdim[1:4])
        note = "no sform: pixdim scaling, origin 0"
    return np.ascontiguousarray(vol), affine, note


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


# --------------------------------------------------------------------------- processes

# Used when /usr/bin/time is missing: a fresh wrapper process runs the command and reports the
# peak RSS of its only child.
RUSAGE_WRAPPER = (
    "import resource, subprocess, sys\n"
    "rc = subprocess.run(sys.argv[2:]).returncode\n"
    "kb = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss\n"
    "open(sys.argv[1], 'w').write(f'Maximum resident set size (kbytes): {kb}\\n')\n"
    "sys.exit(rc)\n"
)


def stderr_line(text: str, code: int) -> str:
    """The line that says what happened: the error line of a failed run, else the first line."""
    lines = [ln.strip() for ln in text.splitlines() if ln.strip()]
    if not lines:
        return ""
    if code != 0:
        for ln in lines:
            if "error" in ln.lower():
                return ln
        return lines[-1]
    return lines[0]


def measure_process(cmd, stats: Path) -> dict:
    """Run cmd in a fresh process: exit code, wall seconds, peak RSS (bytes), its stderr line."""
    cmd = [str(c) for c in cmd]
    if GNU_TIME.exists():
        full, how = [str(GNU_TIME), "-v", "-o", str(stats)] + cmd, "/usr/bin/time -v"
    else:
        full = [sys.executable, "-c", RUSAGE_WRAPPER, str(stats)] + cmd
        how = "resource.getrusage(RUSAGE_CHILDREN) in a fresh wrapper process"
    stats.unlink(missing_ok=True)
    t0 = time.perf_counter()
    p = subprocess.run(full, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    rss_kb = None
    try:
        for line in stats.read_text().splitlines():
            if "Maximum resident set size" in line:
                rss_kb = int(line.rsplit(":", 1)[1])
    except (OSError, ValueError):
        pass
    stats.with_suffix(".stderr").write_text(p.stderr)
    return dict(exit_code=p.returncode, wall_s=wall,
                peak_rss_bytes=None if rss_kb is None else rss_kb * 1024, peak_rss_method=how,
                stderr_line=stderr_line(p.stderr, p.returncode), stderr=p.stderr)


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
    sigma_world = float(spacing.min())  # one voxel (subdyn recover's default for edges)
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


def sigma_args(args, voxel: float) -> list:
    """The options added to every subdyn recover: `--sigma` when --sigma-voxels is given (σ in
    voxels × the smallest spacing), then --subdyn-args (nothing by default: subdyn's defaults)."""
    sigma = [] if args.sigma_voxels is None else ["--sigma", repr(args.sigma_voxels * voxel)]
    return sigma + shlex.split(args.subdyn_args)


def subdyn_recover(subdyn: Path, base: Path, iso: float, work: Path, extra=()) -> dict:
    """One `subdyn recover` process (under measure_process). A failed run gives failed=True, its
    exit code and stderr line, and no files (stale ones are removed first)."""
    stem = base.name[: -len(".nii.gz")] if base.name.endswith(".nii.gz") else base.stem
    fit, surf, rep = work / f"{stem}.fit.obj", work / f"{stem}.surf.ply", work / f"{stem}.recover.json"
    for p in (fit, surf, rep):
        p.unlink(missing_ok=True)
    args = ["--iso", repr(iso)] + list(extra)
    cmd = [subdyn, "recover", base] + args + ["-o", fit, "--limit-out", surf, "--report", rep, "--quiet"]
    proc = measure_process(cmd, work / f"{stem}.recover.time")
    res = {
        "command": " ".join(str(c) for c in
                            ["subdyn", "recover", base.name] + args +
                            ["-o", fit.name, "--limit-out", surf.name, "--report", rep.name, "--quiet"]),
        "fit": fit,
        "surf": surf,
        "exit_code": proc["exit_code"],
        "stderr_line": proc["stderr_line"],
        "seconds": proc["wall_s"],
        "peak_rss_bytes": proc["peak_rss_bytes"],
        "peak_rss_method": proc["peak_rss_method"],
        "failed": proc["exit_code"] != 0 or not fit.exists(),
    }
    if res["failed"]:
        return res
    report = json.loads(rep.read_text())
    levels = report["recover"]["levels"]
    res.update({
        "fit_sha": hashlib.sha256(fit.read_bytes()).hexdigest()[:16],
        "control_points": obj_vertex_count(fit),
        "control_points_per_level": [lv["control_points"] for lv in levels],
        "limit_vertices": None,  # filled from the compare report
        "stop_reason": report["recover"].get("stop_reason"),
        "converged": report["recover"].get("converged"),
        "sigma": report["recover"].get("sigma"),
        "init": report.get("init"),
        "report_total_s": report.get("total_s"),
        "report_peak_memory": report.get("peak_memory"),
    })
    return res


def compare(subdyn: Path, surf: Path, truth: Path, rep: Path, limit_a: bool = False) -> dict:
    cmd = [subdyn, "compare", surf, truth, "--report", rep, "--quiet"] + (["--limit-a"] if limit_a else [])
    run(cmd, capture_output=True)
    return json.loads(rep.read_text())


def mesh_info(subdyn: Path, path: Path) -> dict | None:
    """`subdyn info --json`: closed (no boundary or non-manifold edge), components, genus."""
    p = subprocess.run([str(subdyn), "info", "--json", str(path)], capture_output=True, text=True)
    if p.returncode != 0:
        return None
    j = json.loads(p.stdout)
    return dict(closed=j["boundary_edges"] == 0 and j["non_manifold_edges"] == 0,
                boundary_edges=j["boundary_edges"], boundary_loops=j["boundary_loops"],
                non_manifold_edges=j["non_manifold_edges"], components=len(j["components"]),
                genus=j.get("genus"), vertices=j["vertices"], faces=j["faces"])


# --------------------------------------------------------------------------- thin parts, cut box


def part_widths(vol, side: dict, parts) -> list:
    """Widths of thin parts in the volume: along x and along y through each part's centre, the
    run of voxels above the iso-value that holds the centre, its two crossings interpolated
    linearly; for every z slice in the part's z range. In world units and in voxels."""
    import numpy as np

    o, s, iso = np.array(side["origin"]), np.array(side["spacing"]), float(side["iso_value"])

    def idx(w, a):
        return int(round((w - o[a]) / s[a]))

    def width(p, c):
        if p[c] <= iso:
            return 0.0
        i = c
        while i > 0 and p[i - 1] > iso:
            i -= 1
        j = c
        while j < len(p) - 1 and p[j + 1] > iso:
            j += 1
        lo = (i - 1) + (iso - p[i - 1]) / (p[i] - p[i - 1]) if i > 0 else float(i)
        hi = j + (p[j] - iso) / (p[j] - p[j + 1]) if j < len(p) - 1 else float(j)
        return hi - lo

    out = []
    for name, nominal, centres, (z0, z1) in parts:
        ks = range(idx(z0, 2), idx(z1, 2) + 1)
        centre_values = [float(vol[idx(cx, 0), idx(cy, 1), k]) for cx, cy in centres for k in ks]
        for a, axis in ((0, "x"), (1, "y")):
            w = []
            for cx, cy in centres:
                for k in ks:
                    if a == 0:
                        w.append(width(vol[:, idx(cy, 1), k], idx(cx, 0)))
                    else:
                        w.append(width(vol[idx(cx, 0), :, k], idx(cy, 1)))
            w = np.array(w)
            out.append(dict(part=name, axis=axis, lines=int(len(w)), missing=int((w == 0).sum()),
                            nominal_world=nominal[axis], nominal_voxels=nominal[axis] / s[a],
                            mean_voxels=float(w.mean()), min_voxels=float(w.min()),
                            max_voxels=float(w.max()), mean_world=float(w.mean() * s[a]),
                            mean_min_spacing_voxels=float(w.mean() * s[a] / s.min()),
                            centre_intensity_mean=float(np.mean(centre_values))))
    return out


def cut_geometry(side: dict) -> dict:
    """The sphere cut by the grid's top face: centre, radius, face z (the last voxel's far side)
    and the rim's radius."""
    a = side["truth"]["analytic"]
    c, r = [float(x) for x in a["centre"]], float(a["radius"])
    nz, sz, oz = side["dims"][2], float(side["spacing"][2]), float(side["origin"][2])
    face = oz + (nz - 0.5) * sz
    assert c[2] - r < face < c[2] + r, "the grid's top face does not cut the sphere"
    return dict(centre=c, radius=r, face=face, rim=math.sqrt(r * r - (face - c[2]) ** 2),
                voxel=float(min(side["spacing"])))


def clipped_sphere_truth(geo: dict, out: Path, h: float = 0.01) -> dict:
    """The sphere clipped at the face, max(|p - c| - r, z - face) = 0, meshed by marching cubes on
    that exact signed distance at spacing h."""
    import numpy as np
    from skimage import measure

    c, r, face = np.array(geo["centre"]), geo["radius"], geo["face"]
    lo = c - r - 2 * h
    hi = np.array([c[0] + r + 2 * h, c[1] + r + 2 * h, face + 2 * h])
    n = np.ceil((hi - lo) / h).astype(int) + 1
    x, y, z = (lo[i] + h * np.arange(n[i], dtype=np.float32) for i in range(3))
    f = np.empty(tuple(n), dtype=np.float32)
    rxy2 = (x[:, None] - c[0]) ** 2 + (y[None, :] - c[1]) ** 2
    for k, zk in enumerate(z):
        f[:, :, k] = np.maximum(np.sqrt(rxy2 + (zk - c[2]) ** 2) - r, zk - face)
    verts, faces, _n, _v = measure.marching_cubes(f, level=0.0, spacing=(h, h, h),
                                                  gradient_direction="ascent")
    write_ply(out, verts + lo, faces)
    return dict(file=out.name, grid_spacing=h, vertices=int(len(verts)), faces=int(len(faces)),
                how=f"marching cubes on max(|p - c| - r, z - face) at spacing {h}")


def cap_distance(surf: Path, geo: dict) -> dict:
    """How far the cap lies from the box face: limit vertices above face − 3 voxels inside the rim
    (and 3 voxels in from it, as data-gen/tests/recover_cut.rs), max and mean |z − face| / voxel;
    the top's height over the face and the rest's largest distance from the sphere, in voxels."""
    import numpy as np

    v, _ = read_ply(surf)
    c, r, face, rim, vox = np.array(geo["centre"]), geo["radius"], geo["face"], geo["rim"], geo["voxel"]
    rho = np.hypot(v[:, 0] - c[0], v[:, 1] - c[1])
    near = v[:, 2] > face - 3 * vox
    out = {}
    for label, lim in (("inside_rim", rim), ("rim_minus_3_voxels", rim - 3 * vox)):
        sel = near & (rho < lim)
        d = np.abs(v[sel, 2] - face) / vox
        out[label] = dict(points=int(sel.sum()), max_vox=float(d.max()) if sel.any() else None,
                          mean_vox=float(d.mean()) if sel.any() else None)
    out["top_minus_face_vox"] = float((v[:, 2].max() - face) / vox)
    rest = v[:, 2] < face - 3 * vox
    out["sphere_max_vox"] = float(np.abs(np.linalg.norm(v[rest] - c, axis=1) - r).max() / vox)
    return out


# --------------------------------------------------------------------------- the MNI templates


def brain_iso(vol) -> dict:
    """A brain-boundary iso-value for a skull-stripped T1 (background exactly 0): half-way from the
    background to the median tissue intensity 3-5 voxels inside the brain's edge (distance
    transform of the non-zero mask). Without a zero background: Otsu's threshold."""
    import numpy as np
    from scipy import ndimage

    mask = vol > 0
    zero_fraction = float(1.0 - mask.mean())
    if zero_fraction < 0.05:
        from skimage.filters import threshold_otsu
        return dict(iso=float(threshold_otsu(vol)), how="Otsu's threshold (no zero background)",
                    zero_fraction=zero_fraction)
    _lab, n_comp = ndimage.label(mask)
    depth = ndimage.distance_transform_edt(mask)
    shell = (depth >= 2.5) & (depth < 5.5)
    tissue = float(np.median(vol[shell]))
    return dict(iso=0.5 * tissue, tissue_median=tissue, background=0.0, zero_fraction=zero_fraction,
                nonzero_components=int(n_comp), shell_voxels=int(shell.sum()),
                edge_voxel_median=float(np.median(vol[(depth > 0) & (depth < 1.5)])),
                how="half-way from the background (0) to the median intensity of the voxels 3-5 voxels "
                    "inside the edge of the non-zero (skull-stripped brain) mask")


def mc_worker(spec_path: Path) -> None:
    """A fresh process for one measurement: read the NIfTI, smooth (f32), marching cubes, write PLY."""
    t0 = time.perf_counter()
    import numpy as np
    from scipy import ndimage
    from skimage import measure

    t_import = time.perf_counter() - t0
    spec = json.loads(Path(spec_path).read_text())
    tr = time.perf_counter()
    vol, affine, note = read_nifti(Path(spec["input"]))
    t_read = time.perf_counter() - tr
    spacing = np.linalg.norm(affine[:3, :3], axis=0)
    ts = time.perf_counter()
    sm = ndimage.gaussian_filter(vol, sigma=tuple(spec["sigma_world"] / spacing), mode="nearest")
    t_smooth = time.perf_counter() - ts
    del vol
    tm = time.perf_counter()
    verts, faces, _n, _v = measure.marching_cubes(sm, level=float(spec["iso"]))
    t_mc = time.perf_counter() - tm
    tw = time.perf_counter()
    write_ply(Path(spec["out"]), verts @ affine[:3, :3].T + affine[:3, 3], faces)
    t_write = time.perf_counter() - tw
    Path(spec["result"]).write_text(json.dumps(dict(
        vertices=int(len(verts)), faces=int(len(faces)), import_s=t_import, read_s=t_read,
        smoothing_s=t_smooth, marching_cubes_s=t_mc, write_s=t_write,
        in_process_s=time.perf_counter() - t0, sigma_voxels=list(spec["sigma_world"] / spacing),
        dtype=str(sm.dtype), world_map=note)))


def mni_section(args, work: Path) -> dict:
    """The MNI T1 (brain boundary; the docs' ventricle command) against smoothing + marching cubes,
    interleaved, and the grey-matter map at --iso 128."""
    import numpy as np

    out = dict(t1=str(MNI_T1), gm=str(MNI_GM))
    if not MNI_T1.exists():
        out["skipped"] = f"{MNI_T1} is absent (set SUBDYN_SHARED_VOLUMES)"
        return out
    vol, affine, note = read_nifti(MNI_T1)
    spacing = np.linalg.norm(affine[:3, :3], axis=0)
    voxels = int(vol.size)
    out.update(dims=list(vol.shape), spacing=spacing.tolist(), voxels=voxels, f32_bytes=4 * voxels,
               world_map=note)
    bi = brain_iso(vol)
    out["brain_iso"] = bi
    del vol
    iso = round(bi["iso"], 3)
    sigma = 0.5 * float(spacing.min())  # subdyn recover's cage smoothing with --iso (its forces: a quarter voxel)
    base = [VENV_PY, "-c", "import numpy, scipy.ndimage, skimage.measure"]
    out["python_import_baseline"] = {k: v for k, v in measure_process(
        base, work / "mni-python-baseline.time").items() if k != "stderr"}
    cases = [
        ("brain", f"T1, brain boundary --iso {iso} (no brain example in the docs)", iso, []),
        ("ventricle", "T1, the docs' ventricle command (docs/recover.md)", 120.0,
         ["--auto", "--seed", "-6,0,18", "--dark"]),
    ]
    out["cases"] = []
    for key, label, c_iso, extra in cases:
        wd = work / f"mni-{key}"
        wd.mkdir(exist_ok=True)
        sd_runs, mc_runs = [], []
        for i in range(args.repeat):  # interleaved: subdyn, marching cubes, subdyn, ...
            log(f"MNI {key}: subdyn recover (run {i + 1})")
            sd = subdyn_recover(args.subdyn, MNI_T1, c_iso, wd,
                                extra + sigma_args(args, float(spacing.min())))
            sd.pop("fit"), sd.pop("surf")
            sd_runs.append(sd)
            log(f"MNI {key}: Gaussian smoothing + marching cubes (run {i + 1})")
            spec = dict(input=str(MNI_T1), iso=c_iso, sigma_world=sigma, out=str(wd / "mc.ply"),
                        result=str(wd / "mc.result.json"))
            (wd / "mc.spec.json").write_text(json.dumps(spec))
            Path(spec["result"]).unlink(missing_ok=True)
            proc = measure_process([VENV_PY, Path(__file__).resolve(), "--mc-worker", wd / "mc.spec.json"],
                                   wd / "mc.time")
            mc = {k: v for k, v in proc.items() if k != "stderr"}
            if proc["exit_code"] == 0:
                mc.update(json.loads(Path(spec["result"]).read_text()))
            mc_runs.append(mc)
        sd, mc = sd_runs[-1], mc_runs[-1]
        med = lambda rs, k: statistics.median([r[k] for r in rs]) if all(r.get(k) is not None for r in rs) else None
        c = dict(key=key, label=label, iso=c_iso, sigma_world=sigma, subdyn=sd, subdyn_runs=sd_runs,
                 mc=mc, mc_runs=mc_runs,
                 subdyn_wall_s=med(sd_runs, "seconds"), mc_wall_s=med(mc_runs, "wall_s"),
                 mc_smooth_plus_mc_s=(statistics.median([r["smoothing_s"] + r["marching_cubes_s"] for r in mc_runs])
                                      if all("smoothing_s" in r for r in mc_runs) else None),
                 subdyn_peak_rss=max(r["peak_rss_bytes"] or 0 for r in sd_runs) or None,
                 mc_peak_rss=max(r["peak_rss_bytes"] or 0 for r in mc_runs) or None)
        c["subdyn_rss_ratio"] = c["subdyn_peak_rss"] / (4 * voxels) if c["subdyn_peak_rss"] else None
        c["mc_rss_ratio"] = c["mc_peak_rss"] / (4 * voxels) if c["mc_peak_rss"] else None
        c["wall_ratio_subdyn_over_smooth_mc"] = (c["subdyn_wall_s"] / c["mc_smooth_plus_mc_s"]
                                                 if c["mc_smooth_plus_mc_s"] else None)
        c["wall_ratio_subdyn_over_mc_process"] = (c["subdyn_wall_s"] / c["mc_wall_s"]
                                                  if c["mc_wall_s"] else None)
        if sd.get("sigma") is not None and abs(sd["sigma"] - sigma) > 1e-9:
            c["note"] = f"subdyn smoothed by σ = {sd['sigma']}, marching cubes by {sigma}"
        out["cases"].append(c)
    if MNI_GM.exists():
        wd = work / "mni-gm"
        wd.mkdir(exist_ok=True)
        log("MNI grey-matter map: subdyn recover --iso 128")
        gm = subdyn_recover(args.subdyn, MNI_GM, 128.0, wd, sigma_args(args, float(spacing.min())))
        gm.pop("fit"), gm.pop("surf")
        gm["peak_rss_ratio"] = gm["peak_rss_bytes"] / (4 * voxels) if gm["peak_rss_bytes"] else None
        out["gm"] = gm
    else:
        out["gm"] = {"skipped": f"{MNI_GM} is absent"}
    return out


# --------------------------------------------------------------------------- main


def fmt_int(n) -> str:
    return f"{n:,}"


def fmt(x, spec=".4f", none="—") -> str:
    return none if x is None else format(x, spec)


def pf(ok) -> str:
    return "n/a" if ok is None else ("pass" if ok else "**FAIL**")


def gen_volume(args, spec: dict, work: Path, name: str, blur: str) -> tuple:
    """data-gen volume into work/NAME.raw + NAME.json; (command shown, completed process)."""
    src = spec["source"]
    base_raw = work / f"{name}.raw"
    what = ["--mesh", src] if isinstance(src, Path) else [src]
    gen_args = (["volume"] + what + ["-o", base_raw, "--format", "raw"] + spec["dims_args"]
                + ["--blur", blur, "--noise", NOISE])
    gen_cmd = "data-gen " + " ".join(a.name if a == base_raw else str(a) for a in gen_args)
    log(gen_cmd)
    p = subprocess.run([str(a) for a in [args.data_gen] + gen_args], capture_output=True, text=True)
    return gen_cmd, p


def one_volume(args, spec: dict, work: Path) -> dict:
    """Generate, extract with marching cubes, recover with subdyn, measure: one volume's record."""
    name = spec["name"]
    src = spec["source"]
    blur = spec["blur"] or BLUR
    rec = dict(name=name, genus=spec["genus"], blur=blur, noise=NOISE, cut=bool(spec.get("cut")),
               source=str(src))
    if isinstance(src, Path) and not src.exists():
        rec["skipped"] = f"{src} is absent (set SUBDYN_SHARED_MESHES to the folder holding it)"
        log(f"{name}: skipped, {rec['skipped']}")
        return rec
    gen_cmd, p = gen_volume(args, spec, work, name, blur)
    rec["command"] = gen_cmd
    if p.returncode != 0:
        rec["generation_failed"] = dict(exit_code=p.returncode, stderr_line=stderr_line(p.stderr, p.returncode))
        return rec
    base = work / f"{name}.json"
    side = json.loads(base.read_text())
    truth = work / side["truth_mesh"]
    iso = float(side["iso_value"])
    voxel = float(min(side["spacing"]))
    truth_topology = side["truth"].get("topology", {})
    if rec["genus"] is None:
        rec["genus"] = truth_topology.get("genus")
    rec.update(dims=side["dims"], spacing=side["spacing"], origin=side["origin"], iso_value=iso,
               voxel=voxel, voxels=int(math.prod(side["dims"])),
               truth_vertices=side["truth"]["vertices"],
               truth_max_face_centroid_distance_to_analytic=side["truth"].get(
                   "max_face_centroid_distance_to_analytic_surface"),
               generator_warning=next((ln.strip() for ln in p.stderr.splitlines() if "warning" in ln), None))
    sdf = signed_distance_fn(side)
    if spec.get("cut"):
        geo = cut_geometry(side)
        rec["cut_geometry"] = geo
        truth = work / f"{name}.truth_clipped.ply"
        rec["clipped_truth"] = clipped_sphere_truth(geo, truth)
        sphere_sdf = sdf
        sdf = lambda pts: __import__("numpy").maximum(sphere_sdf(pts), pts[:, 2] - geo["face"])
    rec["truth_file"] = truth.name
    if spec.get("parts"):
        rec["part_widths"] = part_widths(read_volume(side, base), side, spec["parts"])
        if spec.get("blur_check"):
            cname = f"{name}.blur{spec['blur_check']}"
            ccmd, cp = gen_volume(args, spec, work, cname, spec["blur_check"])
            if cp.returncode == 0:
                cside = json.loads((work / f"{cname}.json").read_text())
                rec["part_widths_blur_check"] = dict(
                    blur=spec["blur_check"], command=ccmd,
                    widths=part_widths(read_volume(cside, work / f"{cname}.json"), cside, spec["parts"]))
    # The truth's bounding-box diagonal: the compare report's (the clipped truth's for a cut volume).
    rows = []

    def measured(method, surf, extra, limit_a=False, tag=""):
        rep = compare(args.subdyn, surf, truth, work / f"{name}.{tag}.compare.json", limit_a)
        rec["truth_diagonal"] = rep["b"]["bbox"]["diagonal"]
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
        rows.append(measured(label, out, dict(kind=tag, topology=mesh_info(args.subdyn, out), **mc), tag=tag))

    log(f"{name}: subdyn recover")
    runs = [subdyn_recover(args.subdyn, base, iso, work, sigma_args(args, min(side["spacing"])))
            for _ in range(args.repeat)]
    sd = runs[-1]  # its files are the ones on disk
    sd["seconds_all"] = [r["seconds"] for r in runs]
    sd["seconds"] = statistics.median(sd["seconds_all"])
    sd["exit_codes"] = [r["exit_code"] for r in runs]
    fit, surf = sd.pop("fit"), sd.pop("surf")
    if sd["failed"]:
        log(f"{name}: subdyn recover failed (exit {sd['exit_code']}): {sd['stderr_line']}")
        rows.append(dict(method="subdyn recover (limit tessellation, K = 4)", kind="subdyn", **sd))
    else:
        sd["fit_obj_sha256_16_per_run"] = [r.get("fit_sha") for r in runs]
        sd.pop("fit_sha", None)
        sd["identical_across_runs"] = len(set(sd["fit_obj_sha256_16_per_run"])) == 1
        sd["topology"] = mesh_info(args.subdyn, fit)
        sd["limit_topology"] = mesh_info(args.subdyn, surf)
        row = measured("subdyn recover (limit tessellation, K = 4)", surf, dict(kind="subdyn", **sd), tag="subdyn")
        row["limit_vertices"] = row["measured_vertices"]
        row["vertices"] = sd["control_points"]
        rows.append(row)
        exact = measured("subdyn recover (exact limit surface, --limit-a)", fit,
                         dict(kind="subdyn_exact", vertices=sd["control_points"], seconds=sd["seconds"]),
                         limit_a=True, tag="subdyn_exact")
        rows.append(exact)
        if spec.get("cut"):
            rec["cap"] = cap_distance(surf, rec["cut_geometry"])
    rec["rows"] = rows

    row = next(r for r in rows if r["kind"] == "subdyn")
    verdicts = {}
    for r in (r for r in rows if r["kind"] in ("mc", "mc_smooth")):
        if row.get("failed"):
            verdicts[r["kind"]] = dict(chamfer_equal_or_better=False, hausdorff_equal_or_better=False,
                                       vertices_at_most_one_tenth=False, vertex_ratio=None,
                                       chamfer_ratio_subdyn_over_mc=None, hausdorff_ratio_subdyn_over_mc=None,
                                       subdyn_failed=True)
            continue
        verdicts[r["kind"]] = {
            "chamfer_equal_or_better": row["chamfer"] <= r["chamfer"],
            "hausdorff_equal_or_better": row["hausdorff"] <= r["hausdorff"],
            "vertices_at_most_one_tenth": row["vertices"] * 10 <= r["vertices"],
            "vertex_ratio": r["vertices"] / row["vertices"],
            "chamfer_ratio_subdyn_over_mc": row["chamfer"] / r["chamfer"],
            "hausdorff_ratio_subdyn_over_mc": row["hausdorff"] / r["hausdorff"],
        }
    rec["verdict"] = verdicts
    return rec


def summary_table(shapes, md) -> None:
    md.append("### Summary: subdyn recover against marching cubes on the raw volume (same iso)")
    md.append("")
    md.append("Criteria per volume: Chamfer ≤ MC's, Hausdorff ≤ MC's (both of subdyn's limit tessellation "
              "and of raw marching cubes against the truth mesh, in voxels = ÷ the smallest spacing), "
              "control points ≤ MC vertices / 10.")
    md.append("")
    md.append("| volume | genus | voxels | subdyn exit | Chamfer subdyn / MC (vox) | Chamfer ≤ MC | "
              "Hausdorff subdyn / MC (vox) | Hausdorff ≤ MC | control points / MC vertices (MC ÷ CP) | "
              "CP ≤ MC/10 | fit genus, closed | seconds subdyn / MC |")
    md.append("|---|---:|---:|---|---:|---|---:|---|---:|---|---|---:|")
    for s in shapes:
        if "rows" not in s:
            why = s.get("skipped") or (f"data-gen failed: exit {s['generation_failed']['exit_code']}: "
                                       f"{s['generation_failed']['stderr_line']}")
            md.append(f"| {s['name']} | {s.get('genus', '—')} | — | not run: {why} | — | — | — | — | — | — | — | — |")
            continue
        mc = next(r for r in s["rows"] if r["kind"] == "mc")
        sd = next(r for r in s["rows"] if r["kind"] == "subdyn")
        v = s["verdict"]["mc"]
        vox = "×".join(str(d) for d in s["dims"])
        name = s["name"] + (" (cut by the box; truth clipped at the face)" if s["cut"] else "")
        if sd.get("failed"):
            md.append(f"| {name} | {s['genus']} | {vox} | **{sd['exit_code']}**: {sd['stderr_line']} | "
                      f"— / {mc['chamfer_vox']:.4f} | **FAIL** | — / {mc['hausdorff_vox']:.3f} | **FAIL** | "
                      f"— / {fmt_int(mc['vertices'])} | **FAIL** | — | {sd['seconds']:.2f} / {mc['seconds']:.2f} |")
            continue
        t = sd.get("topology") or {}
        topo = f"{t.get('genus')}, {'closed' if t.get('closed') and t.get('components') == 1 else 'NOT closed'}"
        if t.get("genus") != s["genus"]:
            topo += f" (truth {s['genus']})"
        md.append(f"| {name} | {s['genus']} | {vox} | {sd['exit_code']} | {sd['chamfer_vox']:.4f} / "
                  f"{mc['chamfer_vox']:.4f} | {pf(v['chamfer_equal_or_better'])} | {sd['hausdorff_vox']:.3f} / "
                  f"{mc['hausdorff_vox']:.3f} | {pf(v['hausdorff_equal_or_better'])} | "
                  f"{fmt_int(sd['vertices'])} / {fmt_int(mc['vertices'])} ({v['vertex_ratio']:.1f}×) | "
                  f"{pf(v['vertices_at_most_one_tenth'])} | {topo} | {sd['seconds']:.2f} / {mc['seconds']:.2f} |")
    md.append("")


def shape_section(s, md, repeat) -> None:
    if "rows" not in s:
        return
    md.append(f"### {s['name']} (genus {s['genus']}, {s['dims'][0]}×{s['dims'][1]}×{s['dims'][2]} voxels, "
              f"spacing {', '.join(str(x) for x in s['spacing'])}; 1 voxel = {s['voxel']} = "
              f"{100 * s['voxel'] / s['truth_diagonal']:.3f} % of the diagonal {s['truth_diagonal']:.4f})")
    md.append("")
    md.append(f"Volume: `{s['command']}`, iso-value {s['iso_value']}.")
    if s.get("clipped_truth"):
        g, ct = s["cut_geometry"], s["clipped_truth"]
        md.append(f"The grid's top face z = {g['face']:.2f} cuts the sphere in a disc of radius {g['rim']:.3f}; "
                  f"truth: the sphere clipped at the face ({ct['how']}, {fmt_int(ct['vertices'])} vertices).")
    md.append("")
    md.append("| method | vertices / control points | Chamfer (voxels) | Hausdorff (voxels) | Chamfer % diag | Hausdorff % diag | mean signed offset (voxels) | seconds (median of " + str(repeat) + ") |")
    md.append("|---|---:|---:|---:|---:|---:|---:|---:|")
    for r in s["rows"]:
        if r.get("failed"):
            md.append(f"| {r['method']} | **failed: exit {r['exit_code']}**: {r['stderr_line']} | — | — | — | — | — | "
                      f"{r['seconds']:.2f} |")
            continue
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
    sub = next(r for r in s["rows"] if r["kind"] == "subdyn")
    if not sub.get("failed"):
        md.append(f"subdyn: {sub['stop_reason']}; control points per level "
                  f"{', '.join(fmt_int(n) for n in sub['control_points_per_level'])}.")
        md.append("")
        if not sub["identical_across_runs"]:
            md.append(f"Note: the {repeat} subdyn runs wrote different fit.obj files; the last run is measured.")
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
        md.append("Equal or better Chamfer with at most one tenth of the vertices? " + "; ".join(parts) + ".")
        md.append("")
    if s.get("part_widths"):
        md.append(f"Thin parts in this volume (blur {s['blur']} mm): width of the above-iso run along x and y "
                  "through each part's centre, iso crossings interpolated linearly, over the four parts × "
                  "every z slice of their middle; voxels of that axis (nominal = the box's width ÷ spacing):")
        md.append("")
        md.append("| volume | part | axis | nominal (voxels) | measured mean (voxels) | min–max | lines | missing (centre below iso) | mean intensity at the centres |")
        md.append("|---|---|---|---:|---:|---:|---:|---:|---:|")
        sets = [(f"{s['name']} (blur {s['blur']})", s["part_widths"])]
        if s.get("part_widths_blur_check"):
            bc = s["part_widths_blur_check"]
            sets.append((f"check: blur {bc['blur']}", bc["widths"]))
        for label, ws in sets:
            for w in ws:
                md.append(f"| {label} | {w['part']} | {w['axis']} | {w['nominal_voxels']:.2f} | {w['mean_voxels']:.2f} | "
                          f"{w['min_voxels']:.2f}–{w['max_voxels']:.2f} | {w['lines']} | {w['missing']} | "
                          f"{w['centre_intensity_mean']:.3f} |")
        md.append("")


def cut_table(shapes, md) -> None:
    cuts = [s for s in shapes if s.get("cut") and "rows" in s]
    if not cuts:
        return
    md.append("### Objects cut by the box")
    md.append("")
    md.append("Cap: limit-tessellation vertices with z > face − 3 voxels and inside the rim (second figure: "
              "3 voxels in from the rim, as data-gen/tests/recover_cut.rs); max |z − face| ÷ voxel. "
              "Criteria: exit 0, control mesh closed (one component, no boundary or non-manifold edge), "
              "cap within 0.5 voxel of the face.")
    md.append("")
    md.append("| volume | subdyn exit | exit 0 | closed (boundary loops, components, genus) | closed | "
              "cap points | cap max (voxels) inside rim / 3 vox in | cap ≤ 0.5 voxel | top − face (voxels) | "
              "rest: max off the sphere (voxels) | raw MC surface |")
    md.append("|---|---|---|---|---|---:|---:|---|---:|---:|---|")
    for s in cuts:
        sd = next(r for r in s["rows"] if r["kind"] == "subdyn")
        mc = next(r for r in s["rows"] if r["kind"] == "mc")
        mt = mc.get("topology") or {}
        mcs = (f"{'closed' if mt.get('closed') else 'open'} ({fmt_int(mt.get('boundary_edges', 0))} boundary edges, "
               f"{mt.get('boundary_loops')} loops)")
        if sd.get("failed"):
            md.append(f"| {s['name']} | **{sd['exit_code']}**: {sd['stderr_line']} | **FAIL** | — | **FAIL** | — | — | "
                      f"**FAIL** | — | — | {mcs} |")
            continue
        t, cap = sd["topology"], s["cap"]
        closed = t["closed"] and t["components"] == 1
        a, b = cap["inside_rim"], cap["rim_minus_3_voxels"]
        md.append(f"| {s['name']} | {sd['exit_code']} | {pf(sd['exit_code'] == 0)} | {t['boundary_loops']}, "
                  f"{t['components']}, {t['genus']} | {pf(closed)} | {fmt_int(a['points'])} / {fmt_int(b['points'])} | "
                  f"{fmt(a['max_vox'], '.3f')} / {fmt(b['max_vox'], '.3f')} | "
                  f"{pf(a['max_vox'] is not None and a['max_vox'] <= 0.5)} | {cap['top_minus_face_vox']:+.3f} | "
                  f"{cap['sphere_max_vox']:.3f} | {mcs} |")
    md.append("")


def mni_tables(mni, md) -> None:
    md.append("### MNI152 2009a templates")
    md.append("")
    if mni is None:
        md.append("Not run (--no-mni).")
        md.append("")
        return
    if "skipped" in mni:
        md.append(f"Skipped: {mni['skipped']}.")
        md.append("")
        return
    bi = mni["brain_iso"]
    d = mni["dims"]
    md.append(f"T1: {d[0]}×{d[1]}×{d[2]} voxels of {', '.join(f'{x:g}' for x in mni['spacing'])} mm "
              f"({fmt_int(mni['voxels'])} voxels; × 4 bytes = {mni['f32_bytes'] / 1e6:.1f} MB). The docs give no "
              f"whole-brain command (only the ventricle one), so the brain uses `--iso {round(bi['iso'], 3)}`: "
              f"{bi['how']} ({100 * bi.get('zero_fraction', 0):.1f} % of the voxels are 0, the non-zero voxels form "
              f"{bi.get('nonzero_components')} component(s); tissue median {bi.get('tissue_median')}). "
              f"Smoothing for marching cubes: σ = {mni['cases'][0]['sigma_world']} mm, subdyn's cage smoothing with --iso (its forces: a quarter voxel); "
              f"float32. Interleaved runs, each a fresh process under "
              f"{mni['cases'][0]['subdyn']['peak_rss_method']}.")
    md.append("")
    bl = mni["python_import_baseline"]
    md.append("| case | method | exit | wall (s) | in-process stages (s) | peak RSS (MB) | peak RSS ÷ (voxels × 4 B) | output |")
    md.append("|---|---|---|---:|---|---:|---:|---|")
    for c in mni["cases"]:
        sd, mc = c["subdyn"], c["mc"]
        out = (f"{fmt_int(sd['control_points'])} control points; {sd['stop_reason']}" if not sd.get("failed")
               else f"failed: {sd['stderr_line']}")
        md.append(f"| {c['label']} | `{sd['command']}` | {sd['exit_code']} | {c['subdyn_wall_s']:.2f} | "
                  f"report total {fmt(sd.get('report_total_s'), '.2f')} | "
                  f"{fmt(c['subdyn_peak_rss'] and c['subdyn_peak_rss'] / 1e6, '.0f')} | {fmt(c['subdyn_rss_ratio'], '.2f')} | {out} |")
        stages = (f"import {mc['import_s']:.2f}, read {mc['read_s']:.2f}, smoothing {mc['smoothing_s']:.2f}, "
                  f"marching cubes {mc['marching_cubes_s']:.2f}, write {mc['write_s']:.2f}"
                  if "smoothing_s" in mc else "—")
        mout = f"{fmt_int(mc['vertices'])} vertices" if "vertices" in mc else f"failed: {mc['stderr_line']}"
        md.append(f"| {c['label']} | Python: read NIfTI, gaussian_filter σ = {c['sigma_world']}, marching_cubes "
                  f"level {c['iso']} | {mc['exit_code']} | {c['mc_wall_s']:.2f} | {stages} | "
                  f"{fmt(c['mc_peak_rss'] and c['mc_peak_rss'] / 1e6, '.0f')} | {fmt(c['mc_rss_ratio'], '.2f')} | {mout} |")
    gm = mni.get("gm", {})
    if "skipped" in gm:
        md.append(f"| grey-matter map --iso 128 | subdyn | — | — | — | — | — | skipped: {gm['skipped']} |")
    else:
        out = (f"{fmt_int(gm['control_points'])} control points; {gm['stop_reason']}" if not gm.get("failed")
               else f"stderr: `{gm['stderr_line']}`")
        md.append(f"| grey-matter map --iso 128 (same grid) | `{gm['command']}` | {gm['exit_code']} | {gm['seconds']:.2f} | — | "
                  f"{fmt(gm['peak_rss_bytes'] and gm['peak_rss_bytes'] / 1e6, '.0f')} | {fmt(gm['peak_rss_ratio'], '.2f')} | {out} |")
    md.append(f"| (baseline) | Python importing numpy, scipy.ndimage, skimage.measure only | {bl['exit_code']} | "
              f"{bl['wall_s']:.2f} | — | {fmt(bl['peak_rss_bytes'] and bl['peak_rss_bytes'] / 1e6, '.0f')} | "
              f"{fmt(bl['peak_rss_bytes'] and bl['peak_rss_bytes'] / mni['f32_bytes'], '.2f')} | — |")
    md.append("")
    for c in mni["cases"]:
        md.append(f"{c['label']}: wall-time ratio subdyn ÷ (smoothing + marching cubes) = "
                  f"{fmt(c['wall_ratio_subdyn_over_smooth_mc'], '.2f')} "
                  f"(÷ the whole Python process: {fmt(c['wall_ratio_subdyn_over_mc_process'], '.2f')}); "
                  f"peak RSS ÷ (voxels × 4 B): subdyn {fmt(c['subdyn_rss_ratio'], '.2f')}, "
                  f"Python {fmt(c['mc_rss_ratio'], '.2f')}." + (f" Note: {c['note']}." if c.get("note") else ""))
        md.append("")


def main() -> None:
    if len(sys.argv) == 3 and sys.argv[1] == "--mc-worker":
        mc_worker(Path(sys.argv[2]))
        return
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--subdyn", type=Path, default=ROOT / "target" / "release" / "subdyn")
    ap.add_argument("--data-gen", type=Path, default=ROOT / "target" / "release" / "data-gen")
    ap.add_argument("--out", type=Path, default=HERE, help="where the .json goes")
    ap.add_argument("--keep", type=Path, default=None, help="keep volumes and outputs in this directory")
    ap.add_argument("--repeat", type=int, default=3, help="timed runs per method (median reported)")
    ap.add_argument("--no-mni", action="store_true", help="skip the MNI templates")
    ap.add_argument("--sigma-voxels", type=float, default=None,
                    help="pass --sigma (this many voxels of the smallest spacing) to every subdyn recover")
    ap.add_argument("--subdyn-args", default="",
                    help="more options for every subdyn recover, one shell-quoted string "
                         "(e.g. \"--tol 0.25\"), to try a setting on the whole bench")
    ap.add_argument("--upgrade", action="store_true", help="reinstall the venv packages")
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    ensure_venv(args)
    args.subdyn, args.data_gen = args.subdyn.resolve(), args.data_gen.resolve()
    t_start = time.perf_counter()

    import numpy
    import scipy
    import skimage
    from scipy import ndimage  # noqa: F401  (loaded here, before any timed call)
    from skimage import measure  # noqa: F401

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
        "niceness": os.nice(0),
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
        "data_gen_binary": str(args.data_gen),
        "repeat": args.repeat,
        "peak_rss_method": "/usr/bin/time -v" if GNU_TIME.exists() else "resource.getrusage(RUSAGE_CHILDREN)",
    }

    tmp = None
    if args.keep:
        work = args.keep.resolve()
        work.mkdir(parents=True, exist_ok=True)
    else:
        tmp = tempfile.TemporaryDirectory(prefix="recover_vs_mc_")
        work = Path(tmp.name)

    shapes = [one_volume(args, spec, work) for spec in VOLUMES]
    mni = None if args.no_mni else mni_section(args, work)
    meta["loadavg_end"] = list(os.getloadavg())
    meta["wall_s_whole_run"] = time.perf_counter() - t_start

    if tmp is not None:
        tmp.cleanup()

    # ----------------------------------------------------------------------- output
    result = {"meta": meta, "shapes": shapes, "mni": mni,
              "definitions": {
                  "chamfer": "subdyn compare: (mean A->B + mean B->A)/2 over 100,000 area-weighted samples each way",
                  "hausdorff": "subdyn compare: max of both one-sided maxima (samples plus vertices)",
                  "voxels": "distance / smallest spacing of the volume",
                  "pct": "% of the ground truth's bounding-box diagonal",
                  "vertices": "marching cubes: mesh vertices; subdyn: control points of fit.obj",
                  "mean_signed_offset_vox": "area-weighted mean of the shape's analytic signed distance (+ outside) over the measured tessellation, in voxels (genus2: its smooth-union formula, approximate near the blend; sphere-cut: max(sphere, z - face)); not for --limit-a rows",
                  "seconds_mc": "median over --repeat runs of: read raw + (smoothing) + marching_cubes + write PLY, in Python",
                  "seconds_subdyn": "median over --repeat runs of the wall clock of the whole `subdyn recover` process (read, smooth, init, fit, write fit.obj + surf.ply + report), run under /usr/bin/time -v",
                  "criteria": "subdyn's limit tessellation against raw marching cubes at the same iso: chamfer <= MC's, hausdorff <= MC's, control points * 10 <= MC vertices; a failed subdyn run fails all three",
                  "closed": "subdyn info --json: boundary_edges == 0 and non_manifold_edges == 0 (and one component)",
                  "cap": "sphere-cut: limit-tessellation vertices with z > face - 3 voxels and hypot(x, y) < rim (or rim - 3 voxels); max |z - face| / voxel",
                  "part_widths": "chair: width of the above-iso run along x / y through each part's centre, crossings interpolated linearly, per z slice of the part's middle; in voxels of that axis",
                  "peak_rss": "Maximum resident set size of the process (/usr/bin/time -v), bytes; ratio = / (voxels * 4)",
                  "wall_ratio_subdyn_over_smooth_mc": "MNI: subdyn recover process wall / (gaussian_filter + marching_cubes seconds inside the Python process)",
                  "wall_ratio_subdyn_over_mc_process": "MNI: subdyn recover process wall / whole Python process wall (interpreter start, imports, NIfTI read, smoothing, marching cubes, PLY write)",
              }}

    def default(o):
        return str(o) if isinstance(o, Path) else o

    for s in shapes:
        for r in s.get("rows", []):
            r.pop("stderr", None)
    (args.out / "recover_vs_marching_cubes.json").write_text(json.dumps(result, indent=2, default=default) + "\n")

    md = []
    md.append(f"**Machine:** {meta['nproc']} cores ({meta['cpu']}), shared with other builds "
              f"(load average at start {', '.join(f'{x:.2f}' for x in meta['loadavg_start'])}, at the end "
              f"{', '.join(f'{x:.2f}' for x in meta['loadavg_end'])}; niceness {meta['niceness']}); "
              f"Python {meta['python']}, scikit-image {meta['scikit_image']}, scipy {meta['scipy']}, "
              f"numpy {meta['numpy']}; subdyn commit `{meta['subdyn_commit']}` (binary {meta['subdyn_binary']}, "
              f"built {meta['subdyn_binary_mtime_utc']}, sha256 {meta['subdyn_binary_sha256_16']}…); "
              f"run {meta['date_utc']}, --repeat {args.repeat}, whole run {meta['wall_s_whole_run']:.0f} s.")
    md.append("")
    summary_table(shapes, md)
    cut_table(shapes, md)
    mni_tables(mni, md)
    for s in shapes:
        shape_section(s, md, args.repeat)
    text = "\n".join(md)
    print(text)


if __name__ == "__main__":
    main()
