#!/usr/bin/env python3
"""Fit every scan of a folder as Ray tasks: one control mesh, one limit
surface and one report per scan.

    python ray_batch_fit.py SCANS/ -o FITS/                      # local Ray
    python ray_batch_fit.py SCANS/ -o FITS/ --address auto       # a running cluster
    python ray_batch_fit.py SCANS/ -o FITS/ --cpus-per-task 4 --option tol=0.05

Each scan is one task that asks Ray for ``--cpus-per-task`` CPUs and runs
subdyn's fit in a rayon pool of exactly the CPUs Ray assigned to it, so the
tasks on a node never oversubscribe it. For ``SCANS/bunny.ply`` the task
writes ``FITS/bunny.obj`` (control mesh), ``FITS/bunny.surf.ply`` (limit
surface, triangles) and ``FITS/bunny.json`` (the report of ``subdyn fit
--report``). On a cluster both folders must be on a filesystem every node
sees, and subdyn must be installed on every node (``pip install ./python``).
A scan that fails is reported on one line; the exit status is then 1.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import ray

SCAN_SUFFIXES = (".ply", ".xyz", ".obj", ".off", ".ply.gz", ".xyz.gz", ".obj.gz")


def scan_stem(path: Path) -> str:
    name = path.name
    for suffix in sorted(SCAN_SUFFIXES, key=len, reverse=True):
        if name.endswith(suffix):
            return name[: -len(suffix)]
    return path.stem


@ray.remote
def fit_scan(scan: str, out_dir: str, options: dict, cpus: int) -> dict:
    """One scan: read, fit with as many threads as Ray gave this task, write."""
    import subdyn

    assigned = ray.get_runtime_context().get_assigned_resources().get("CPU", cpus)
    threads = max(1, int(assigned))
    stem = scan_stem(Path(scan))
    out = Path(out_dir)
    started = time.perf_counter()
    try:
        points, normals = subdyn.read_points(scan)
        result = subdyn.fit(points, normals, threads=threads, **options)
        control = out / f"{stem}.obj"
        surface = out / f"{stem}.surf.ply"
        result.write_control(control)
        result.write_limit(surface)
        report = dict(result.report, input=scan, output=str(control),
                      limit_out=str(surface), threads=threads)
        tmp = out / f".{stem}.json.tmp"
        tmp.write_text(json.dumps(report, indent=2) + "\n")
        os.replace(tmp, out / f"{stem}.json")
    except (OSError, ValueError) as e:
        return {"scan": scan, "error": str(e)}
    level = result.report["fit"]["levels"][-1]
    return {"scan": scan, "control": str(control), "threads": threads,
            "control_points": level["control_points"], "p95_pct": level["error"]["p95_pct"],
            "seconds": time.perf_counter() - started}


def parse_option(text: str):
    key, sep, value = text.partition("=")
    if not sep:
        raise argparse.ArgumentTypeError(f"--option {text}: expected NAME=VALUE")
    for cast in (int, float):
        try:
            return key, cast(value)
        except ValueError:
            pass
    return key, {"true": True, "false": False}.get(value.lower(), value)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scans", type=Path, help="folder of scans (.ply, .xyz, .obj, .off)")
    ap.add_argument("-o", "--output", type=Path, required=True, help="folder for the results")
    ap.add_argument("--address", help="Ray cluster address (e.g. auto or ray://head:10001); "
                    "default: start a local Ray")
    ap.add_argument("--num-cpus", type=int, help="CPUs of the local Ray (default: all)")
    ap.add_argument("--cpus-per-task", type=int, default=1, help="CPUs (threads) per scan")
    ap.add_argument("--option", type=parse_option, action="append", default=[],
                    metavar="NAME=VALUE", help="an option of subdyn.fit (e.g. tol=0.05)")
    args = ap.parse_args(argv)
    scans = sorted(p for p in args.scans.iterdir()
                   if p.is_file() and p.name.endswith(SCAN_SUFFIXES)) if args.scans.is_dir() else []
    if not scans:
        print(f"ray_batch_fit: error: {args.scans}: no scans (.ply, .xyz, .obj, .off) found",
              file=sys.stderr)
        return 2
    if args.cpus_per_task < 1:
        print("ray_batch_fit: error: --cpus-per-task must be at least 1", file=sys.stderr)
        return 2
    args.output.mkdir(parents=True, exist_ok=True)
    if args.address:
        ray.init(address=args.address, log_to_driver=False)
    else:
        ray.init(num_cpus=args.num_cpus, log_to_driver=False, include_dashboard=False)
    options = dict(args.option)
    futures = [fit_scan.options(num_cpus=args.cpus_per_task).remote(
        str(s.resolve()), str(args.output.resolve()), options, args.cpus_per_task) for s in scans]
    failed = 0
    for r in ray.get(futures):
        if "error" in r:
            failed += 1
            print(f"ray_batch_fit: {r['scan']}: {r['error']}", file=sys.stderr)
        else:
            print(f"{r['scan']}: {r['control_points']} control points, p95 {r['p95_pct']:.3f} % "
                  f"in {r['seconds']:.2f} s on {r['threads']} threads -> {r['control']}")
    ray.shutdown()
    print(f"{len(scans) - failed} of {len(scans)} scans fitted")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
