"""Shared fixtures: the CLI binaries of the workspace (built by `cargo build
--release`) and scans made with `data-gen`."""

import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BIN = Path(os.environ.get("SUBDYN_BIN_DIR", ROOT / "target" / "release"))


def binary(name: str) -> Path:
    path = BIN / name
    if not path.exists():
        pytest.fail(f"{path} is missing: run `cargo build --release --workspace --bins` first")
    return path


def run(name: str, *args, cwd=None) -> subprocess.CompletedProcess:
    """Runs a workspace binary; fails the test with its stderr on error."""
    out = subprocess.run([str(binary(name)), *map(str, args)], cwd=cwd,
                         capture_output=True, text=True)
    if out.returncode != 0:
        pytest.fail(f"{name} {' '.join(map(str, args))} failed: {out.stderr}")
    return out


def scan(path: Path, shape: str = "sphere", seed: int = 1, views: int = 8) -> Path:
    run("data-gen", "scan", shape, "-o", path, "--views", views, "--noise", 0.001,
        "--seed", seed)
    return path


@pytest.fixture(scope="session")
def sphere_scan(tmp_path_factory) -> Path:
    """A closed 8-view range scan of a sphere (25k points)."""
    return scan(tmp_path_factory.mktemp("scan") / "sphere.ply")


@pytest.fixture(scope="session")
def sphere_fit(sphere_scan):
    import subdyn

    points, normals = subdyn.read_points(sphere_scan)
    return subdyn.fit(points, normals)
