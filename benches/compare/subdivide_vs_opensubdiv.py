#!/usr/bin/env python3
"""Same-run timing of subdyn's uniform refinement against OpenSubdiv 3.6 Far.

Runs `subdyn bench subdivide --grid N --levels L --threads 1` and the Far
timing program of benches/opensubdiv (far_timing.cpp, built with
benches/opensubdiv/build.sh) interleaved, --rounds times each, on one thread
(RAYON_NUM_THREADS=1, OMP_NUM_THREADS=1), parses the last stdout line (JSON)
of every run and prints a markdown table of the medians per stage with the
subdyn / OpenSubdiv ratios, the stencil and entry counts of both, and the
machine (nproc, CPU model, load average before and after) and date.

Far is run twice per round: with its default float stencil weights
(Far::StencilTableFactory) and with double weights
(Far::StencilTableFactoryReal<double>); subdyn's weights are f64. Both apply
the stencils to double xyz positions.

Standard library only. Example:

    python3 benches/compare/subdivide_vs_opensubdiv.py \\
        --subdyn target/release/subdyn --far /work/osd/far_timing --rounds 5
"""

import argparse
import datetime
import json
import os
import shlex
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

# Stage name -> (subdyn key, Far key).
STAGES = [
    ("topology", "topology_s", "topology_s"),
    ("refinement", "refine_s", "refinement_s"),
    ("stencil build", "stencil_build_s", "stencil_build_s"),
    ("setup (sum of the three)", "setup_s", "setup_s"),
    ("stencil apply (best of repeat)", "stencil_apply_s", "apply_s"),
]


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--subdyn", default=str(ROOT / "target/release/subdyn"),
                   help="subdyn binary (default: target/release/subdyn)")
    p.add_argument("--far", required=True,
                   help="far_timing binary built by benches/opensubdiv/build.sh")
    p.add_argument("--grid", type=int, default=316)
    p.add_argument("--levels", type=int, default=2)
    p.add_argument("--rounds", type=int, default=5, help="runs of each program")
    p.add_argument("--repeat", type=int, default=5,
                   help="stencil applications per run, the best is kept (both programs)")
    p.add_argument("--no-double", action="store_true",
                   help="skip the Far run with double stencil weights")
    p.add_argument("--out", help="also write every run and the medians to this JSON file")
    a = p.parse_args()
    if a.rounds < 1:
        p.error("--rounds must be at least 1")
    for name in ("subdyn", "far"):
        path = getattr(a, name)
        if not os.access(path, os.X_OK):
            p.error(f"--{name} {path}: not an executable file")
    return a


def loadavg():
    with open("/proc/loadavg") as f:
        return " ".join(f.read().split()[:3])


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return "unknown"


def nproc():
    try:
        return subprocess.run(["nproc"], capture_output=True, text=True,
                              check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return str(os.cpu_count())


def run_json(cmd, env):
    r = subprocess.run(cmd, capture_output=True, text=True, env=env)
    if r.returncode != 0:
        sys.exit(f"failed ({r.returncode}): {shlex.join(cmd)}\n{r.stderr}")
    lines = [l for l in r.stdout.splitlines() if l.strip()]
    if not lines:
        sys.exit(f"no output from {shlex.join(cmd)}")
    try:
        return json.loads(lines[-1])
    except json.JSONDecodeError as e:
        sys.exit(f"last line of {shlex.join(cmd)} is not JSON ({e}): {lines[-1]!r}")


def fmt(x):
    return f"{x:.4f}"


def main():
    a = parse_args()
    env = dict(os.environ, RAYON_NUM_THREADS="1", OMP_NUM_THREADS="1")
    common = ["--grid", str(a.grid), "--levels", str(a.levels), "--repeat", str(a.repeat)]
    cmds = {
        "subdyn": [a.subdyn, "bench", "subdivide", *common, "--threads", "1", "--quiet"],
        "far_float": [a.far, *common, "--real", "float"],
    }
    if not a.no_double:
        cmds["far_double"] = [a.far, *common, "--real", "double"]
    subdyn_version = subprocess.run([a.subdyn, "--version"], capture_output=True,
                                    text=True).stdout.strip()

    date = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    load_before = loadavg()
    runs = {k: [] for k in cmds}
    for r in range(a.rounds):
        for k, cmd in cmds.items():
            runs[k].append(run_json(cmd, env))
        print(f"round {r + 1}/{a.rounds} done", file=sys.stderr)
    load_after = loadavg()

    for j in runs["subdyn"]:
        if j.get("threads") != 1:
            sys.exit(f"subdyn ran on {j.get('threads')} threads, expected 1")

    def med(k, key):
        return statistics.median(j[key] for j in runs[k])

    def spread(k, key):
        v = [j[key] for j in runs[k]]
        return min(v), max(v)

    far_keys = [k for k in ("far_float", "far_double") if k in runs]
    label = {"far_float": "Far, float weights", "far_double": "Far, double weights"}

    # Sizes (the same in every round of a program).
    s0 = runs["subdyn"][0]
    counts = {"subdyn": (s0["vertices"], s0["stencil_entries"])}
    for k in far_keys:
        counts[k] = (runs[k][0]["stencils"], runs[k][0]["entries"])
    for k, js in runs.items():
        for j in js:
            c = (j["vertices"], j["stencil_entries"]) if k == "subdyn" else (j["stencils"], j["entries"])
            if c != counts[k]:
                sys.exit(f"{k}: counts changed between rounds: {c} vs {counts[k]}")
    osd = runs[far_keys[0]][0].get("opensubdiv", "?")

    out = []
    out.append(f"Uniform Catmull-Clark, {a.grid}×{a.grid} quad torus, {a.levels} levels, "
               f"one thread each; medians of {a.rounds} interleaved runs per program, "
               f"stencil apply = best of {a.repeat} in each run; double xyz positions.")
    out.append("")
    head = ["stage", "subdyn (s)"]
    for k in far_keys:
        head += [f"{label[k]} (s)", f"subdyn / {label[k]}"]
    out.append("| " + " | ".join(head) + " |")
    out.append("|" + "|".join(["---"] + ["---:"] * (len(head) - 1)) + "|")
    medians = {}
    for name, skey, fkey in STAGES:
        s = med("subdyn", skey)
        row = [name, fmt(s)]
        medians[name] = {"subdyn": s}
        for k in far_keys:
            f = med(k, fkey)
            medians[name][k] = f
            row += [fmt(f), f"{s / f:.2f}" if f > 0 else "n/a"]
        out.append("| " + " | ".join(row) + " |")
    out.append("")
    out.append(f"- Stencils / entries: subdyn {counts['subdyn'][0]:,} rows, "
               f"{counts['subdyn'][1]:,} entries (f64 weights)"
               + "".join(f"; {label[k]} {counts[k][0]:,} stencils, {counts[k][1]:,} entries"
                         for k in far_keys)
               + (" — the same." if all(counts[k] == counts["subdyn"] for k in far_keys)
                  else " — **they differ**."))
    for name, skey, fkey in (STAGES[3], STAGES[4]):
        lo, hi = spread("subdyn", skey)
        parts = [f"subdyn {fmt(lo)}–{fmt(hi)}"]
        for k in far_keys:
            flo, fhi = spread(k, fkey)
            parts.append(f"{label[k]} {fmt(flo)}–{fmt(fhi)}")
        out.append(f"- Range (min–max over the runs), {name}: " + ", ".join(parts) + ".")
    out.append("- Refinement: subdyn builds the full topology of every level; Far is run "
               "with `fullTopologyInLastLevel = true` to match. With Far's default "
               "(`false`, all that stencils need) its refinement median is "
               + ", ".join(f"{fmt(med(k, 'refinement_minimal_s'))} s ({label[k]} runs)"
                           for k in far_keys) + ".")
    out.append(f"- subdyn applying its per-level tables one after the other (not timed on "
               f"the Far side): median {fmt(med('subdyn', 'apply_levelwise_s'))} s.")
    out.append(f"- Machine: nproc {nproc()}, CPU `{cpu_model()}`; load average "
               f"{load_before} before, {load_after} after; {date}.")
    out.append(f"- Versions: {subdyn_version}; OpenSubdiv {osd} (Far, static libosdCPU, "
               f"no OpenMP/TBB).")
    out.append("- Commands (each with RAYON_NUM_THREADS=1 OMP_NUM_THREADS=1), run in this "
               "order every round:")
    for cmd in cmds.values():
        out.append(f"  - `{shlex.join(cmd)}`")
    text = "\n".join(out)
    print(text)

    if a.out:
        report = {
            "date": date,
            "grid": a.grid, "levels": a.levels, "rounds": a.rounds, "repeat": a.repeat,
            "machine": {"nproc": nproc(), "cpu": cpu_model(),
                        "loadavg_before": load_before, "loadavg_after": load_after},
            "versions": {"subdyn": subdyn_version, "opensubdiv": osd},
            "commands": {k: shlex.join(c) for k, c in cmds.items()},
            "medians": medians,
            "counts": {k: {"stencils": c[0], "entries": c[1]} for k, c in counts.items()},
            "runs": runs,
            "markdown": text,
        }
        Path(a.out).write_text(json.dumps(report, indent=2) + "\n")
        print(f"wrote {a.out}", file=sys.stderr)


if __name__ == "__main__":
    main()
