"""Bad input gives ValueError, files OSError, each with the library's one line."""

import os

import numpy as np
import pytest

import subdyn


def test_unknown_option_is_named():
    with pytest.raises(ValueError, match="unknown option 'tolerance'.*tol, tol_stat"):
        subdyn.fit(np.random.default_rng(0).normal(size=(100, 3)), tolerance=1)


def test_bad_option_values():
    p = np.random.default_rng(0).normal(size=(100, 3))
    with pytest.raises(ValueError, match="tol_stat='median' is not one of max, p95, rms, mean"):
        subdyn.fit(p, tol_stat="median")
    with pytest.raises(ValueError, match="max_level=-1 is not a non-negative integer"):
        subdyn.fit(p, max_level=-1)
    with pytest.raises(ValueError, match="unknown initial model 'cube'"):
        subdyn.fit(p, init="cube")
    with pytest.raises(ValueError, match="tess 0 is out of range"):
        subdyn.fit(p, tess=0)
    with pytest.raises(ValueError, match="threads must be at least 1"):
        subdyn.fit(p, threads=0)


def test_bad_points():
    with pytest.raises(ValueError, match=r"points must be an \(n, 3\) array, got shape \(5, 2\)"):
        subdyn.fit(np.zeros((5, 2)))
    with pytest.raises(ValueError, match="a fit needs at least 10 points"):
        subdyn.fit(np.zeros((5, 3)))
    p = np.random.default_rng(0).normal(size=(100, 3))
    p[7, 1] = np.nan
    with pytest.raises(ValueError, match="input: "):
        subdyn.fit(p)


def test_bad_meshes():
    v = np.eye(3)
    with pytest.raises(ValueError, match="face 0 refers to vertex 7, but the mesh has only 3 vertices"):
        subdyn.LimitSurface(v, [[0, 1, 7]])
    with pytest.raises(ValueError, match="not a valid index"):
        subdyn.LimitSurface(v, [[0, 1, -1]])
    with pytest.raises(ValueError, match="unknown boundary rule 'soft'"):
        subdyn.subdivide(v, [[0, 1, 2]], 1, boundary="soft")
    with pytest.raises(ValueError, match="9 levels is too many"):
        subdyn.subdivide(v, [[0, 1, 2]], 9)
    s = subdyn.LimitSurface(v, [[0, 1, 2]])
    with pytest.raises(ValueError, match="face 3 out of range"):
        s.evaluate(3, 0.2, 0.2)
    with pytest.raises(ValueError, match="outside"):
        s.evaluate(0, 2.0, 0.2)
    with pytest.raises(ValueError, match="derivative 'dw' is not one of"):
        s.jacobian(0, 0.2, 0.2, derivative="dw")


def test_files(tmp_path):
    with pytest.raises(OSError, match="missing.ply: No such file"):
        subdyn.read_points(tmp_path / "missing.ply")
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 1 zero\n")
    with pytest.raises(ValueError, match="bad.obj:3:"):
        subdyn.read_mesh(bad)
    with pytest.raises(OSError, match="no_dir"):
        subdyn.write_mesh(tmp_path / "no_dir" / "x.obj", np.eye(3), [[0, 1, 2]])
    with pytest.raises(ValueError, match="x.stl"):
        subdyn.write_mesh(tmp_path / "x.stl", np.eye(3), [[0, 1, 2]])
    assert sorted(os.listdir(tmp_path)) == ["bad.obj"], "a failed write leaves nothing"
