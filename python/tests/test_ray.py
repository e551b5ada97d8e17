"""Four scans fitted as Ray tasks on a local Ray (the batch example)."""

import json
import subprocess
import sys

import numpy as np
import pytest

import subdyn
from conftest import ROOT, scan

pytest.importorskip("ray")
EXAMPLE = ROOT / "examples" / "python" / "ray_batch_fit.py"


def test_four_scans_as_ray_tasks(tmp_path):
    scans, made = tmp_path / "scans", tmp_path / "made"
    scans.mkdir()
    made.mkdir()
    for seed, shape in enumerate(["sphere", "ellipsoid", "torus", "sphere"], start=1):
        # data-gen also writes the ground truth beside the scan: keep the scan only
        scan(made / f"{shape}{seed}.ply", shape=shape, seed=seed, views=6).rename(
            scans / f"{shape}{seed}.ply")
    (scans / "notes.txt").write_text("not a scan\n")
    out = tmp_path / "fits"
    run = subprocess.run(
        [sys.executable, str(EXAMPLE), str(scans), "-o", str(out), "--num-cpus", "2",
         "--cpus-per-task", "1", "--option", "max_level=1"],
        capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr
    assert "4 of 4 scans fitted" in run.stdout
    stems = sorted(p.name[:-4] for p in scans.glob("*.ply"))
    assert sorted(p.stem for p in out.glob("*.obj")) == stems
    assert sorted(p.name[:-9] for p in out.glob("*.surf.ply")) == stems
    for stem in stems:
        report = json.loads((out / f"{stem}.json").read_text())
        assert report["threads"] == 1
        assert report["command"] == "fit" and report["output"].endswith(f"{stem}.obj")
    # a task's result is the in-process fit's
    points, normals = subdyn.read_points(scans / "torus3.ply")
    direct = subdyn.fit(points, normals, max_level=1, threads=1)
    v, _ = subdyn.read_mesh(out / "torus3.obj")
    diagonal = np.linalg.norm(points.max(0) - points.min(0))
    assert np.abs(v - direct.control_vertices).max() <= 1e-9 * diagonal


def test_a_bad_scan_fails_the_run_with_one_line(tmp_path):
    scans = tmp_path / "scans"
    scans.mkdir()
    (scans / "broken.xyz").write_text("1 2 3\n4 5\n")
    run = subprocess.run(
        [sys.executable, str(EXAMPLE), str(scans), "-o", str(tmp_path / "fits"), "--num-cpus",
         "1"], capture_output=True, text=True, timeout=600)
    assert run.returncode == 1
    assert "broken.xyz:2:" in run.stderr
    assert "0 of 1 scans fitted" in run.stdout
    assert not list((tmp_path / "fits").iterdir()), "a failed scan leaves no file"
