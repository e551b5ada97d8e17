"""subdyn.fit against the CLI, pickling, threads, watertightness."""

import json
import pickle

import numpy as np
import pytest

import subdyn
from conftest import run

TIMING_KEYS = ("seconds", "elapsed", "_s")


def without_timings(value):
    """The report with every timing field left out (they differ run to run)."""
    if isinstance(value, dict):
        return {k: without_timings(v) for k, v in value.items()
                if not any(t in k for t in TIMING_KEYS)}
    if isinstance(value, list):
        return [without_timings(v) for v in value]
    return value


def test_fit_equals_cli(tmp_path, sphere_scan, sphere_fit):
    run("subdyn", "fit", sphere_scan, "-o", tmp_path / "cli.obj", "--report",
        tmp_path / "cli.json", "--quiet")
    vertices, faces = subdyn.read_mesh(tmp_path / "cli.obj")
    r = sphere_fit
    points, _ = subdyn.read_points(sphere_scan)
    diagonal = np.linalg.norm(points.max(0) - points.min(0))
    assert r.control_vertices.shape == vertices.shape
    assert np.abs(r.control_vertices - vertices).max() <= 1e-9 * diagonal
    assert len(r.control_faces) == len(faces)
    assert all(np.array_equal(a, b) for a, b in zip(r.control_faces, faces))
    cli = json.load(open(tmp_path / "cli.json"))
    assert sorted(cli) == sorted(r.report)
    assert r.report["input"] == f"an array of {len(points)} points"
    paths = ("input", "output", "limit_out", "crease_file")
    cli = {k: v for k, v in cli.items() if k not in paths}
    ours = {k: v for k, v in r.report.items() if k not in paths}
    assert without_timings(ours) == without_timings(cli)
    assert r.report["fit"]["levels"], "the report lists the levels"


def test_options_reach_the_fit(sphere_scan):
    points, _ = subdyn.read_points(sphere_scan)
    coarse = subdyn.fit(points, max_level=0, init="closed", tess=2)
    assert len(coarse.report["fit"]["levels"]) == 1
    assert coarse.report["init"]["method"] == "closed"
    # tess=2 gives 2×2 quads per control quad, 8 triangles each
    quads = sum(1 if len(f) == 4 else len(f) for f in coarse.control_faces)
    assert coarse.limit_triangles.shape == (8 * quads, 3)
    q = subdyn.fit(points, max_level=0, init="closed", tess=2, quads=True)
    assert q.limit_triangles is None and q.limit_quads.shape == (4 * quads, 4)


def test_fit_from_a_given_mesh(sphere_scan, sphere_fit):
    points, _ = subdyn.read_points(sphere_scan)
    r = subdyn.fit(points, init=(sphere_fit.init_vertices, sphere_fit.init_faces), max_level=0)
    assert r.report["init"]["method"] == "mesh"
    assert r.control_vertices.shape == sphere_fit.init_vertices.shape


def test_result_pickles(sphere_fit):
    r = pickle.loads(pickle.dumps(sphere_fit))
    assert isinstance(r, subdyn.FitResult)
    assert np.array_equal(r.control_vertices, sphere_fit.control_vertices)
    assert np.array_equal(r.limit_triangles, sphere_fit.limit_triangles)
    assert all(np.array_equal(a, b) for a, b in zip(r.control_faces, sphere_fit.control_faces))
    assert r.report == sphere_fit.report


def test_threads_option_runs_in_its_own_pool(sphere_scan):
    # The library's patch assembly splits its sums by rayon's thread count,
    # so one and two threads agree to rounding (about 1e-13), not to the bit;
    # the CLI with RAYON_NUM_THREADS=1 and 2 differs the same way.
    points, normals = subdyn.read_points(sphere_scan)
    one = subdyn.fit(points, normals, threads=1, max_level=1)
    two = subdyn.fit(points, normals, threads=2, max_level=1)
    again = subdyn.fit(points, normals, threads=2, max_level=1)
    diagonal = np.linalg.norm(points.max(0) - points.min(0))
    assert np.abs(one.control_vertices - two.control_vertices).max() <= 1e-9 * diagonal
    assert two.control_vertices.tobytes() == again.control_vertices.tobytes()


def test_limit_surface_of_a_closed_scan_is_watertight(sphere_fit):
    o3d = pytest.importorskip("open3d")
    mesh = subdyn.open3d.to_triangle_mesh(sphere_fit)
    assert len(mesh.triangles) == len(sphere_fit.limit_triangles)
    assert mesh.is_watertight()
    assert mesh.is_orientable()
    assert isinstance(mesh, o3d.geometry.TriangleMesh)


def test_sharp_creases_come_back_with_the_fit(tmp_path):
    """A machined plate's sharp edges: the Python fit's ``control_creases``
    are the CLI's ``t crease`` lines, they round-trip through OBJ and a tag
    file beside a PLY, and the limit surface is the one with them."""
    path = tmp_path / "plate.ply"
    run("data-gen", "scan", "plate", "-o", path, "--noise", 0.001, "--views", 8,
        "--resolution", "128,96", "--seed", 1)
    points, _ = subdyn.read_points(path)
    r = subdyn.fit(points)
    assert r.control_creases.shape[1] == 3 and len(r.control_creases) >= 12
    assert r.report["creases"] == len(r.control_creases)
    assert (r.control_creases[:, 2] == 10).all()
    run("subdyn", "fit", path, "-o", tmp_path / "cli.obj", "--quiet")
    tags = [line.split()[3:] for line in open(tmp_path / "cli.obj") if line.startswith("t crease")]
    assert np.array_equal(np.array(tags, dtype=float), r.control_creases)
    smooth = subdyn.fit(points, crease_angle=0)
    assert smooth.control_creases.shape == (0, 3)

    r.write_control(tmp_path / "ours.obj")
    assert open(tmp_path / "ours.obj").read() == open(tmp_path / "cli.obj").read()
    r.write_control(tmp_path / "ours.ply")
    beside = [line.split() for line in open(tmp_path / "ours.ply.creases")
              if not line.startswith("#")]
    assert np.array_equal(np.array(beside, dtype=float), r.control_creases)

    # The centres of the quads are vertices of the limit tessellation (tess 4)
    # with the creases, not without them.
    from scipy.spatial import cKDTree
    quads = np.array([f for f, face in enumerate(r.control_faces) if len(face) == 4])
    half = np.full(len(quads), 0.5)
    tree = cKDTree(r.limit_vertices)
    diagonal = np.linalg.norm(points.max(0) - points.min(0))
    gaps = []
    for creases in (r.control_creases, None):
        surface = subdyn.LimitSurface(r.control_vertices, r.control_faces, creases=creases)
        gaps.append(tree.query(surface.evaluate(quads, half, half).p)[0].max())
    assert gaps[0] <= 1e-9 * diagonal < 1e-4 * diagonal < gaps[1]
    with pytest.raises(ValueError, match="without normals"):
        subdyn.write_mesh(tmp_path / "n.obj", r.control_vertices, r.control_faces,
                          normals=r.control_vertices, creases=r.control_creases)
