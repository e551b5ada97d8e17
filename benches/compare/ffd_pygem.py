#!/usr/bin/env python3
"""Free-form deformation: `subdyn bench ffd` against a NumPy Bernstein box FFD.

PyGeM's `FFD` is the box FFD Python users know: Sederberg & Parry's formula
(1986), a deformed point is sum_ijk B_i^l(s) B_j^m(t) B_k^n(u) P_ijk over a
box lattice of (l+1)(m+1)(n+1) control points, with (s, t, u) the point's
coordinates in the box. This script implements that formula directly in
NumPy (vectorised over all vertices; no PyGeM code, no PyGeM dependency) and
times it on the same 50,052-vertex torus that `subdyn bench ffd` uses, with
the same number of control points: degree 4 per axis (5 x 5 x 5 = 125) against
subdyn's automatic 4 x 4 x 4-cell box lattice (125 control points) refined 3
times.

One command (from anywhere; needs target/release/subdyn):

    python3 benches/compare/ffd_pygem.py

1. creates (or reuses) benches/compare/.venv and installs numpy there (PyPI),
   then re-runs itself inside it;
2. builds the torus (388 x 129 quads, major radius 1, minor 0.35, the same
   vertices as `subdyn::examples::torus`) and the box (its bounding box grown
   by 5 % of the diagonal on every side, as `subdyn lattice`);
3. times, best of --repeat runs: "embed" (box coordinates and the three
   Bernstein bases, the precompute), "deform" (the full tensor product for
   new control points), "one-point update" (moving one control point: a
   rank-one update of every vertex with a nonzero weight), and a PyGeM-style
   call that does both each time;
4. runs `subdyn bench ffd --octree-levels 2 --levels 3 --quiet` and reads the
   JSON line;
5. prints a Markdown table (the FFD section of RESULTS.md is built from it)
   and writes ffd_pygem.json beside this script.

A comparison beside the product, never a dependency of it; not part of CI.
Standard library only outside the venv.
"""

from __future__ import annotations

import argparse
import datetime
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
VENV = HERE / ".venv"
VENV_PY = VENV / "bin" / "python"


def log(msg: str) -> None:
    print(f"[ffd-pygem] {msg}", file=sys.stderr, flush=True)


def ensure_venv() -> None:
    if Path(sys.prefix).resolve() == VENV.resolve():
        return
    if not VENV_PY.exists():
        log(f"creating virtual environment {VENV}")
        subprocess.run([sys.executable, "-m", "venv", str(VENV)], check=True)
    if subprocess.run([str(VENV_PY), "-c", "import numpy"], capture_output=True).returncode:
        log("installing numpy into the venv")
        subprocess.run([str(VENV_PY), "-m", "pip", "install", "-q", "numpy"], check=True)
    os.execv(str(VENV_PY), [str(VENV_PY), str(Path(__file__).resolve())] + sys.argv[1:])


def torus(n: int, m: int, r_major: float, r_minor: float):
    """The vertices of subdyn::examples::torus(n, m, R, r), same order."""
    import numpy as np

    a = 2 * np.pi * np.arange(n) / n
    b = 2 * np.pi * np.arange(m) / m
    A, B = np.meshgrid(a, b, indexing="ij")
    r = r_major + r_minor * np.cos(B)
    return np.stack([r * np.cos(A), r * np.sin(A), r_minor * np.sin(B)], axis=-1).reshape(-1, 3)


def bernstein(degree: int, x):
    """B_i^degree(x) for i = 0..degree, one row per x."""
    import numpy as np
    from math import comb

    i = np.arange(degree + 1)
    c = np.array([comb(degree, k) for k in i], dtype=float)
    return c * x[:, None] ** i * (1.0 - x[:, None]) ** (degree - i)


def best(f, repeat: int):
    t = float("inf")
    out = None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        t = min(t, time.perf_counter() - t0)
    return out, t


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--updates", type=int, default=200)
    ap.add_argument("--subdyn", default=str(ROOT / "target" / "release" / "subdyn"))
    args = ap.parse_args()
    ensure_venv()
    import numpy as np

    pts = torus(388, 129, 1.0, 0.35)
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    pad = 0.05 * np.linalg.norm(hi - lo)
    origin, length = lo - pad, (hi - lo) + 2 * pad
    deg = (4, 4, 4)
    # Rest control points: the box's (l+1)(m+1)(n+1) grid (Bernstein linear precision).
    grids = [np.linspace(0.0, 1.0, d + 1) for d in deg]
    S, T, U = np.meshgrid(*grids, indexing="ij")
    rest = origin + np.stack([S, T, U], axis=-1) * length  # (5, 5, 5, 3)

    def embed():
        stu = (pts - origin) / length
        return [bernstein(d, stu[:, k]) for k, d in enumerate(deg)]

    (bs, bt, bu), embed_s = best(embed, args.repeat)
    rng = np.random.default_rng(1)
    moved = rest + 0.05 * rng.standard_normal(rest.shape)

    def deform(p):
        return np.einsum("ni,nj,nk,ijkd->nd", bs, bt, bu, p, optimize=True)

    identity_err = float(np.abs(deform(rest) - pts).max())
    out, einsum_s = best(lambda: deform(moved), args.repeat)
    # The fastest NumPy form: the dense weight matrix once (N x 125), then
    # each deformation one matrix product (BLAS).
    def dense():
        b0, b1, b2 = embed()
        return (b0[:, :, None, None] * b1[:, None, :, None] * b2[:, None, None, :]).reshape(len(pts), -1)

    W, dense_embed_s = best(dense, args.repeat)
    flat = moved.reshape(-1, 3)
    out2, deform_s = best(lambda: W @ flat, args.repeat)
    assert np.abs(out2 - out).max() < 1e-12
    # One control point (the centre one) moved: v += B_i(s) B_j(t) B_k(u) * delta.
    i, j, k = 2, 2, 2
    w = bs[:, i] * bt[:, j] * bu[:, k]
    nz = np.nonzero(w)[0]
    v = out.copy()
    t0 = time.perf_counter()
    for r in range(args.updates):
        delta = np.array([np.cos(r * 0.37), np.sin(r * 0.37), 0.5]) * 0.01
        v[nz] += w[nz, None] * delta
    update_s = (time.perf_counter() - t0) / args.updates
    _, pygem_call_s = best(lambda: (embed(), deform(moved)), args.repeat)

    log("running subdyn bench ffd")
    line = subprocess.run(
        [args.subdyn, "bench", "ffd", "--octree-levels", "2", "--levels", "3", "--quiet"],
        check=True,
        capture_output=True,
        text=True,
    ).stdout.strip().splitlines()[-1]
    sd = json.loads(line)
    assert sd["vertices"] == len(pts), (sd["vertices"], len(pts))

    res = {
        "vertices": int(len(pts)),
        "numpy": {
            "control_points": int(np.prod([d + 1 for d in deg])),
            "degree": deg,
            "embed_s": embed_s,
            "dense_embed_s": dense_embed_s,
            "einsum_deform_ms": 1e3 * einsum_s,
            "deform_ms": 1e3 * deform_s,
            "one_point_update_ms": 1e3 * update_s,
            "one_point_update_rows": int(len(nz)),
            "pygem_style_call_s": pygem_call_s,
            "identity_max_error": identity_err,
            "numpy_version": np.__version__,
        },
        "subdyn": sd,
        "machine": {
            "cores": os.cpu_count(),
            "processor": platform.processor() or platform.machine(),
            "python": platform.python_version(),
            "load_average": os.getloadavg(),
        },
        "date_utc": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M"),
    }
    (HERE / "ffd_pygem.json").write_text(json.dumps(res, indent=2) + "\n")
    n = res["numpy"]
    print("| | NumPy Bernstein box FFD (degree 4 per axis, 125 control points) | subdyn (4³-cell box lattice, 125 control points, 3 levels) | subdyn / NumPy |")
    print("|---|---:|---:|---:|")
    print(f"| precompute: NumPy dense weights N×125; subdyn refine + embed + B | {n['dense_embed_s']*1e3:.1f} ms | {sd['embedding_total_s']*1e3:.1f} ms | {sd['embedding_total_s']/n['dense_embed_s']:.1f}× |")
    print(f"| full deformation: NumPy W @ P (BLAS); subdyn B p | {n['deform_ms']:.2f} ms | {sd['full_product_ms']:.2f} ms | {sd['full_product_ms']/n['deform_ms']:.2f}× |")
    print(f"| move one control point (rank-one update; column of B) | {n['one_point_update_ms']:.3f} ms ({n['one_point_update_rows']:,} rows) | {sd['local_update_ms']:.3f} ms ({sd['column_vertices']:,} rows) | {sd['local_update_ms']/n['one_point_update_ms']:.3f}× |")
    print(f"| PyGeM-style call (Bernstein bases + einsum every time) | {n['pygem_style_call_s']*1e3:.1f} ms | — | — |")
    print(f"| einsum deformation alone | {n['einsum_deform_ms']:.1f} ms | — | — |")
    print(f"\nidentity error (unmoved lattice): NumPy {identity_err:.1e}, subdyn {sd['max_abs_diff_local_vs_full']:.1e} (local vs full)")


if __name__ == "__main__":
    main()
