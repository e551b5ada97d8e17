#!/usr/bin/env python3
"""Check subdyn's point-to-mesh distances against Open3D, by hand (not CI).

    python3 benches/compare/check_open3d_distance.py [--mesh M.obj] [--points N]
        [--timing-points N] [--timing-levels L] [--venv DIR] [--subdyn BIN]

What it does:

1. Sets up a Python virtual environment (`python3 -m venv`, then
   `pip install open3d numpy`) in --venv (default benches/compare/.venv, the
   one run_compare.py uses too) and re-runs itself there. Open3D's wheel needs three Debian libraries:
   libusb-1.0-0, libgl1 and libgomp1 (`apt-get install libusb-1.0-0 libgl1
   libgomp1`); the script checks for them first and says which are missing.
2. Accuracy: reads the mesh (default ../shared/data/meshes/spot.obj), fan-
   triangulates its faces from their first vertex (as subdyn's TriangleBvh
   does), makes N points (default 100,000: half near the surface, half
   uniform in the bounding box grown by 10 %). Open3D computes in float32, so
   vertices and points are rounded to float32 first and both programs get
   exactly those values (written as exact decimals): the difference then
   measures Open3D's float32 arithmetic against subdyn's float64. It runs
   Open3D `RaycastingScene.compute_distance` and
   `subdyn compare POINTS.xyz MESH.obj --distances-out D.txt` (one line
   `x y z d` per point) and prints the largest absolute difference, relative
   to the bounding-box diagonal and to the distance itself; a float64 brute
   force in numpy on 300 of the points says which of the two is off.
3. Timing: the mesh refined by `subdyn subdivide --levels L` (default 2: spot
   becomes 140,544 triangles) against --timing-points points (default
   1,000,000), Open3D (scene build + query) next to subdyn (BVH build + query,
   from the `compare --report` timings), same threads (all cores).

Build subdyn first: `cargo build --release` (--subdyn defaults to
target/release/subdyn).
"""

import argparse
import ctypes.util
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
NEEDED_LIBS = {"usb-1.0": "libusb-1.0-0", "GL": "libgl1", "gomp": "libgomp1"}


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--mesh", default=str(ROOT.parent / "shared/data/meshes/spot.obj"))
    p.add_argument("--points", type=int, default=100_000)
    p.add_argument("--timing-points", type=int, default=1_000_000)
    p.add_argument("--timing-levels", type=int, default=2)
    p.add_argument("--venv", default=str(Path(__file__).resolve().parent / ".venv"))
    p.add_argument("--subdyn", default=str(ROOT / "target/release/subdyn"))
    p.add_argument("--seed", type=int, default=1)
    return p.parse_args()


def ensure_venv(args):
    """Re-executes inside the venv (creating it and installing Open3D first)."""
    missing = [deb for lib, deb in NEEDED_LIBS.items() if ctypes.util.find_library(lib) is None]
    if missing:
        sys.exit(
            "Open3D needs the Debian packages " + ", ".join(missing)
            + ": apt-get install " + " ".join(missing)
        )
    venv = Path(args.venv)
    python = venv / "bin" / "python"
    if Path(sys.prefix).resolve() == venv.resolve():
        return
    if not python.exists():
        print(f"creating {venv} ...", flush=True)
        subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    if subprocess.run([str(python), "-c", "import open3d, numpy"], capture_output=True).returncode:
        print(f"installing open3d and numpy into {venv} (a few minutes) ...", flush=True)
        subprocess.run([str(python), "-m", "pip", "install", "--quiet", "open3d", "numpy"], check=True)
    os.execv(str(python), [str(python), __file__, *sys.argv[1:]])


def read_obj(path):
    """Vertices and fan-triangulated faces of an OBJ file (v / f lines)."""
    import numpy as np

    verts, tris = [], []
    with open(path) as f:
        for line in f:
            if line.startswith("v "):
                verts.append([float(t) for t in line.split()[1:4]])
            elif line.startswith("f "):
                idx = [int(t.split("/")[0]) for t in line.split()[1:]]
                idx = [i - 1 if i > 0 else len(verts) + i for i in idx]
                for k in range(1, len(idx) - 1):
                    tris.append([idx[0], idx[k], idx[k + 1]])
    return np.array(verts), np.array(tris, dtype=np.int64)


def write_obj(path, verts, tris):
    with open(path, "w") as f:
        for v in verts:
            f.write("v %r %r %r\n" % (float(v[0]), float(v[1]), float(v[2])))
        for t in tris:
            f.write("f %d %d %d\n" % (t[0] + 1, t[1] + 1, t[2] + 1))


def write_xyz(path, pts):
    import numpy as np

    # float32 values written as the float64 that equals them: exact.
    np.savetxt(path, pts.astype(np.float64), fmt="%.17g")


def make_points(verts, tris, n, rng):
    """Half near the surface (area samples + 1 % diag noise), half uniform in the grown box."""
    import numpy as np

    a, b, c = verts[tris[:, 0]], verts[tris[:, 1]], verts[tris[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    lo, hi = verts.min(0), verts.max(0)
    diag = np.linalg.norm(hi - lo)
    k = n // 2
    t = rng.choice(len(tris), size=k, p=area / area.sum())
    r1, r2 = np.sqrt(rng.random(k))[:, None], rng.random(k)[:, None]
    near = (1 - r1) * a[t] + r1 * (1 - r2) * b[t] + r1 * r2 * c[t]
    near += rng.normal(0.0, 0.01 * diag, near.shape)
    far = rng.uniform(lo - 0.1 * diag, hi + 0.1 * diag, size=(n - k, 3))
    return np.concatenate([near, far]), diag


def brute_distances(verts, tris, pts):
    """Float64 point-to-mesh distances by brute force (numpy): the plane
    projection when it falls inside a triangle, else the nearest edge."""
    import numpy as np

    a, b, c = verts[tris[:, 0]], verts[tris[:, 1]], verts[tris[:, 2]]
    n = np.cross(b - a, c - a)
    n2 = np.einsum("ij,ij->i", n, n)

    def seg(p, s, t):
        st = t - s
        l2 = np.einsum("ij,ij->i", st, st)
        x = np.clip(np.einsum("ij,ij->i", p - s, st) / np.where(l2 > 0, l2, 1), 0, 1)
        return np.linalg.norm(p - (s + st * x[:, None]), axis=1)

    out = []
    for p in pts:
        proj = p - n * (np.einsum("ij,ij->i", p - a, n) / n2)[:, None]
        wa = np.einsum("ij,ij->i", np.cross(b - proj, c - proj), n) / n2
        wb = np.einsum("ij,ij->i", np.cross(c - proj, a - proj), n) / n2
        inside = (wa >= 0) & (wb >= 0) & (1 - wa - wb >= 0)
        plane = np.linalg.norm(p - proj, axis=1)
        edges = np.minimum(np.minimum(seg(p, a, b), seg(p, b, c)), seg(p, c, a))
        out.append(np.where(inside, plane, edges).min())
    return np.array(out)


def open3d_distances(verts32, tris, pts32):
    import numpy as np
    import open3d as o3d

    t0 = time.perf_counter()
    scene = o3d.t.geometry.RaycastingScene()
    scene.add_triangles(o3d.core.Tensor(verts32), o3d.core.Tensor(tris.astype(np.uint32)))
    # The BVH is built lazily on the first query: time a one-point query with the build.
    scene.compute_distance(o3d.core.Tensor(pts32[:1]))
    t1 = time.perf_counter()
    d = scene.compute_distance(o3d.core.Tensor(pts32)).numpy().astype(np.float64)
    t2 = time.perf_counter()
    return d, t1 - t0, t2 - t1


def subdyn_distances(args, mesh_path, pts_path, work):
    import numpy as np

    report, dists = work / "report.json", work / "distances.txt"
    t0 = time.perf_counter()
    subprocess.run(
        [args.subdyn, "compare", str(pts_path), str(mesh_path), "--report", str(report),
         "--distances-out", str(dists), "--quiet"],
        check=True, stdout=subprocess.DEVNULL,
    )
    wall = time.perf_counter() - t0
    r = json.loads(report.read_text())
    d = np.fromstring(dists.read_text(), sep=" ").reshape(-1, 4)[:, 3]
    return d, r["timings_s"]["build"], r["a_to_b"]["query_s"], wall


def compare_run(args, verts, tris, n, work, label, rng):
    import numpy as np

    verts32 = verts.astype(np.float32)
    pts, diag = make_points(verts32.astype(np.float64), tris, n, rng)
    pts32 = pts.astype(np.float32)
    mesh_path, pts_path = work / f"{label}.obj", work / f"{label}.xyz"
    write_obj(mesh_path, verts32, tris)
    write_xyz(pts_path, pts32)
    d_o3d, o3d_build, o3d_query = open3d_distances(verts32, tris, pts32)
    d_sd, sd_build, sd_query, sd_wall = subdyn_distances(args, mesh_path, pts_path, work)
    diff = np.abs(d_o3d - d_sd)
    k = np.linspace(0, n - 1, 300).astype(int)
    ref = brute_distances(verts32.astype(np.float64), tris, pts32[k].astype(np.float64))
    ref_sd, ref_o3d = np.abs(d_sd[k] - ref).max(), np.abs(d_o3d[k] - ref).max()
    rel = diff / np.maximum(d_sd, 1e-300)
    big = d_sd > 1e-3 * diag
    far = d_sd > 1e-1 * diag
    print(f"\n{label}: {len(tris):,} triangles, {n:,} points, bbox diagonal {diag:.6g}")
    print(f"  float64 brute force on {len(k)} points: max |subdyn - brute| = {ref_sd:.3e}, "
          f"max |open3d - brute| = {ref_o3d:.3e}")
    print(f"  max |open3d - subdyn|            = {diff.max():.3e}  ({diff.max() / diag:.3e} of the diagonal)")
    print(f"  max relative difference |Δ|/d    = {rel.max():.3e} (all points)")
    print(f"  max relative difference, d > 1e-3 diag = {rel[big].max():.3e} ({big.sum():,} points)")
    print(f"  max relative difference, d > 1e-1 diag = {rel[far].max():.3e} ({far.sum():,} points)")
    print("  (Open3D works in float32: expect |Δ| near 1e-7 of the coordinates, whatever d is)")
    print(f"  open3d: build {o3d_build:.3f} s, query {o3d_query:.3f} s")
    print(f"  subdyn: build {sd_build:.3f} s, query {sd_query:.3f} s (whole run with I/O {sd_wall:.2f} s)")
    print(f"  query time ratio open3d / subdyn = {o3d_query / sd_query:.2f}")
    return {
        "label": label, "triangles": int(len(tris)), "points": n, "diagonal": diag,
        "brute_points": int(len(k)), "max_abs_diff_subdyn_vs_brute": float(ref_sd),
        "max_abs_diff_open3d_vs_brute": float(ref_o3d),
        "max_abs_diff": float(diff.max()), "max_abs_diff_over_diag": float(diff.max() / diag),
        "max_rel_diff": float(rel.max()), "max_rel_diff_d_gt_1e-3_diag": float(rel[big].max()),
        "max_rel_diff_d_gt_1e-1_diag": float(rel[far].max()),
        "open3d_build_s": o3d_build, "open3d_query_s": o3d_query,
        "subdyn_build_s": sd_build, "subdyn_query_s": sd_query,
    }


def main():
    args = parse_args()
    ensure_venv(args)
    import numpy as np
    import open3d as o3d

    if not Path(args.subdyn).exists():
        sys.exit(f"{args.subdyn} not found: run `cargo build --release` first")
    print(f"open3d {o3d.__version__}, numpy {np.__version__}, {os.cpu_count()} cores")
    rng = np.random.default_rng(args.seed)
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        verts, tris = read_obj(args.mesh)
        results.append(compare_run(args, verts, tris, args.points, work, "accuracy", rng))
        if args.timing_points > 0:
            fine = work / "fine.obj"
            subprocess.run(
                [args.subdyn, "subdivide", args.mesh, "-o", str(fine),
                 "--levels", str(args.timing_levels), "--quiet"],
                check=True, stdout=subprocess.DEVNULL,
            )
            verts, tris = read_obj(fine)
            results.append(compare_run(args, verts, tris, args.timing_points, work, "timing", rng))
    print(json.dumps(results))


if __name__ == "__main__":
    main()
