"""LimitSurface (evaluation, Jacobians), subdivide and mesh I/O."""

import pickle

import numpy as np
import pytest

import subdyn
from conftest import run

# The unit cube as the CLI embeds it is not needed: build one here.
CUBE_V = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], float)
CUBE_F = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]


def samples(n=50, faces=6, seed=0):
    rng = np.random.default_rng(seed)
    return rng.integers(0, faces, n), rng.uniform(0.05, 0.95, n), rng.uniform(0.05, 0.95, n)


def test_evaluate_is_the_jacobian_times_the_control_points():
    s = subdyn.LimitSurface(CUBE_V, CUBE_F)
    f, u, v = samples()
    e = s.evaluate(f, u, v)
    for name in ("p", "du", "dv", "duu", "duv", "dvv"):
        J = s.jacobian(f, u, v, derivative=name)
        assert J.shape == (len(f), 8)
        assert np.abs(J @ CUBE_V - getattr(e, name)).max() < 1e-13
    # position rows are affine combinations, derivative rows sum to zero
    assert np.allclose(s.jacobian(f, u, v).sum(axis=1), 1.0)
    assert np.allclose(s.jacobian(f, u, v, "du").sum(axis=1), 0.0)


def test_derivatives_agree_with_finite_differences():
    s = subdyn.LimitSurface(CUBE_V, CUBE_F)
    f, u, v = samples(20)
    h = 1e-6
    e = s.evaluate(f, u, v)
    du = (s.evaluate(f, u + h, v).p - s.evaluate(f, u - h, v).p) / (2 * h)
    dvv = (s.evaluate(f, u, v + h).dv - s.evaluate(f, u, v - h).dv) / (2 * h)
    assert np.abs(du - e.du).max() < 1e-6
    assert np.abs(dvv - e.dvv).max() < 1e-5


def test_scalar_evaluation_and_the_known_centre():
    s = subdyn.LimitSurface(CUBE_V, CUBE_F)
    e = s.evaluate(0, 0.5, 0.5)
    assert e.p.shape == (3,)
    # the centre of a cube face lies 0.0802… inside the face (OpenSubdiv agrees)
    assert abs(e.p[2] - 0.080246913580246909) < 1e-12


def test_creases_change_the_surface_and_pickle():
    # three sharp edges at vertex 0 make it a corner
    creases = np.array([[0, 1, 10.0], [0, 2, 10.0], [0, 4, 10.0]])
    smooth = subdyn.LimitSurface(CUBE_V, CUBE_F)
    sharp = subdyn.LimitSurface(CUBE_V, CUBE_F, creases=creases)
    corner = sharp.evaluate(0, 0.0, 0.0).p
    assert np.abs(corner - CUBE_V[0]).max() < 1e-12  # an infinitely sharp corner interpolates
    assert np.abs(smooth.evaluate(0, 0.0, 0.0).p - CUBE_V[0]).max() > 0.1
    back = pickle.loads(pickle.dumps(sharp))
    f, u, v = samples()
    assert np.array_equal(back.evaluate(f, u, v).p, sharp.evaluate(f, u, v).p)
    assert (back.jacobian(f, u, v) != sharp.jacobian(f, u, v)).nnz == 0


def test_tessellation_matches_the_cli(tmp_path):
    subdyn.write_mesh(tmp_path / "cube.obj", CUBE_V, CUBE_F)
    run("subdyn", "limit", tmp_path / "cube.obj", "-o", tmp_path / "surf.obj", "--tess", 5)
    v, f = subdyn.read_mesh(tmp_path / "surf.obj")
    tv, tf, tn = subdyn.LimitSurface(CUBE_V, CUBE_F).tessellate(5)
    assert np.abs(tv - v).max() < 1e-12 and np.array_equal(tf, np.array(f))
    assert np.allclose(np.linalg.norm(tn, axis=1), 1.0)


@pytest.mark.parametrize("limit", [False, True])
def test_subdivide_matches_the_cli(tmp_path, limit):
    subdyn.write_mesh(tmp_path / "cube.ply", CUBE_V, CUBE_F)
    (tmp_path / "creases.txt").write_text("0 1 2.5\n")
    args = ["subdivide", tmp_path / "cube.ply", "-o", tmp_path / "out.ply", "--levels", 3,
            "--creases", tmp_path / "creases.txt", "--boundary", "edge-only"]
    run("subdyn", *(args + (["--limit"] if limit else [])))
    v, f = subdyn.read_mesh(tmp_path / "out.ply")
    sv, sf = subdyn.subdivide(CUBE_V, CUBE_F, 3, creases=[[0, 1, 2.5]], boundary="edge-only",
                              limit=limit)
    assert np.abs(sv - v).max() < 1e-12
    assert len(sf) == len(f) and all(np.array_equal(a, b) for a, b in zip(sf, f))
    assert len(sf) == (2 * 6 * 4 ** 3 if limit else 6 * 4 ** 3)


def test_mesh_io_round_trip(tmp_path):
    faces = [[0, 1, 2, 3], [0, 3, 4], [1, 5, 2]]
    v = np.random.default_rng(3).normal(size=(6, 3))
    n = v / np.linalg.norm(v, axis=1, keepdims=True)
    for fmt in ("ply", "obj", "off"):
        path = tmp_path / f"m.{fmt}"
        subdyn.write_mesh(path, v, faces, normals=n if fmt != "off" else None)
        rv, rf = subdyn.read_mesh(path)
        assert np.abs(rv - v).max() < 1e-12, fmt
        assert [list(x) for x in rf] == faces, fmt
    points, normals = subdyn.read_points(tmp_path / "m.ply")
    assert np.abs(normals - n).max() < 1e-12
