#!/usr/bin/env python3
"""Calling overhead of subdyn.fit against the CLI, on the embedded demo scan.

    python python/bench_overhead.py [--runs 5] [--cli target/release/subdyn]

Both sides do the same work: the CLI's `subdyn fit SCAN -o fit.obj
--limit-out surf.ply` (process start, read, fit, tessellate, write), against
`read_points`, `fit`, `write_control` and `write_limit` in Python. Printed:
the median wall time of each, and the median of the fitting time the
library reports itself (`fit.seconds` of the report), which separates the
calling overhead from the machine's noise.
"""

import argparse
import gzip
import json
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import subdyn

ROOT = Path(__file__).resolve().parents[1]


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--cli", type=Path, default=ROOT / "target" / "release" / "subdyn")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        scan = tmp / "spot_scan.ply"
        scan.write_bytes(gzip.decompress((ROOT / "data" / "demo" / "spot_scan.ply.gz").read_bytes()))
        cli_wall, cli_fit, py_wall, py_fit, py_call = [], [], [], [], []
        for _ in range(args.runs):
            t = time.perf_counter()
            subprocess.run([str(args.cli), "fit", str(scan), "-o", str(tmp / "cli.obj"),
                            "--limit-out", str(tmp / "cli.ply"), "--report",
                            str(tmp / "cli.json"), "--quiet"], check=True,
                           stdout=subprocess.DEVNULL)
            cli_wall.append(time.perf_counter() - t)
            cli_fit.append(json.loads((tmp / "cli.json").read_text())["fit"]["seconds"])

            t = time.perf_counter()
            points, normals = subdyn.read_points(scan)
            c = time.perf_counter()
            r = subdyn.fit(points, normals)
            py_call.append(time.perf_counter() - c - r.report["total_s"])
            r.write_control(tmp / "py.obj")
            r.write_limit(tmp / "py.ply")
            py_wall.append(time.perf_counter() - t)
            py_fit.append(r.report["fit"]["seconds"])
        same = (tmp / "cli.obj").read_bytes() == (tmp / "py.obj").read_bytes()
    med = statistics.median
    print(f"demo scan: {len(points)} points, {args.runs} runs each, medians")
    print(f"CLI    wall {med(cli_wall):.3f} s, fit {med(cli_fit):.3f} s")
    print(f"Python wall {med(py_wall):.3f} s, fit {med(py_fit):.3f} s, "
          f"time in fit() outside the library {1000 * med(py_call):.1f} ms")
    print(f"Python / CLI: wall {med(py_wall) / med(cli_wall):.3f}, "
          f"fit {med(py_fit) / med(cli_fit):.3f}; control meshes identical: {same}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
