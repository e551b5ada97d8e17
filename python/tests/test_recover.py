"""subdyn.recover against `subdyn recover` on the same volume."""

import json

import numpy as np
import pytest

import subdyn
from conftest import run


@pytest.fixture(scope="module")
def sphere_volume(tmp_path_factory):
    d = tmp_path_factory.mktemp("volume")
    run("data-gen", "volume", "sphere", "-o", d / "v.raw")
    meta = json.loads((d / "v.json").read_text())
    assert meta["dtype"] == "f32" and meta["layout"] == "x fastest, then y, then z"
    nx, ny, nz = meta["dims"]
    data = np.fromfile(d / "v.raw", dtype="<f4").reshape(nz, ny, nx).transpose(2, 1, 0)
    return d, data, meta


def test_recover_equals_cli(sphere_volume):
    d, volume, meta = sphere_volume
    # The CLI takes the sidecar's iso_value as its boundary; an array carries
    # no sidecar, so the same level is passed to Python.
    run("subdyn", "recover", d / "v.raw", "-o", d / "cli.obj", "--report", d / "cli.json",
        "--quiet", "--max-level", 1)
    r = subdyn.recover(volume, spacing=meta["spacing"], origin=meta["origin"], max_level=1,
                       iso=meta["iso_value"])
    v, f = subdyn.read_mesh(d / "cli.obj")
    extent = np.linalg.norm(np.array(meta["dims"]) * np.array(meta["spacing"]))
    assert r.control_vertices.shape == v.shape
    assert np.abs(r.control_vertices - v).max() <= 1e-9 * extent
    cli = json.loads((d / "cli.json").read_text())
    assert r.report["init"] == cli["init"]
    assert r.report["dims"] == cli["dims"] == meta["dims"]
    assert [lv["control_points"] for lv in r.report["recover"]["levels"]] == \
        [lv["control_points"] for lv in cli["recover"]["levels"]]
    # the limit surface lies on the unit sphere data-gen rasterised
    radius = np.linalg.norm(r.limit_vertices, axis=1)
    assert np.abs(radius - np.median(radius)).max() < 0.05


def test_recover_from_a_seed_and_its_errors(sphere_volume):
    _, volume, meta = sphere_volume
    r = subdyn.recover(volume, meta["spacing"], meta["origin"], seed=(0.0, 0.0, 0.0),
                       max_level=0, iso=0.5)
    assert r.report["init"]["method"] == "seed"
    with pytest.raises(ValueError, match=r"seed \(5, 0, 0\) lies outside the volume"):
        subdyn.recover(volume, meta["spacing"], meta["origin"], seed=(5, 0, 0))
    with pytest.raises(ValueError, match="unknown option 'threshold'"):
        subdyn.recover(volume, meta["spacing"], meta["origin"], threshold=0.5)
    with pytest.raises(ValueError, match="volume must be a 3-D array"):
        subdyn.recover(volume[0], meta["spacing"], meta["origin"])


def test_ct_presets_and_poor_results(sphere_volume):
    _, volume, meta = sphere_volume
    args = (volume, meta["spacing"], meta["origin"])
    with pytest.raises(ValueError, match="iso or preset, not both"):
        subdyn.recover(*args, iso=0.5, preset="skin")
    # -500 HU is outside the [0, 1] intensities of this volume
    with pytest.raises(ValueError, match="-500 lies outside"):
        subdyn.recover(*args, preset="skin")
    # A cube reaching 0.5 past the top of the box (z up to 1.8; the box
    # ends near 1.3): the result leaves the box, an error unless accepted.
    cube = np.array([[x, y, z] for z in (0.2, 1.8) for y in (-0.8, 0.8) for x in (-0.8, 0.8)])
    faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
    with pytest.raises(ValueError, match="poor result: the surface leaves the volume's box"):
        subdyn.recover(*args, init=(cube, faces), iso=0.5, max_level=0)
    r = subdyn.recover(*args, init=(cube, faces), iso=0.5, max_level=0, accept_poor=True)
    assert any("leaves the volume's box" in p for p in r.report["poor_result"])


def boundary_vertices(faces):
    """The vertices on edges used by one face."""
    count = {}
    for f in faces:
        for a, b in zip(f, np.roll(f, -1)):
            e = (min(a, b), max(a, b))
            count[e] = count.get(e, 0) + 1
    return sorted({v for e, c in count.items() if c == 1 for v in e})


def test_open_at_box(sphere_volume):
    _, volume, meta = sphere_volume
    # The sphere cut a quarter of the way down from its top by the box.
    nz = volume.shape[2]
    z_index = [i for i in range(nz) if volume[:, :, i].max() > 0.5]
    k = z_index[-1] - (z_index[-1] - z_index[0]) // 4
    cut = volume[:, :, : k + 1]
    face = meta["origin"][2] + (k + 0.5) * meta["spacing"][2]
    args = (cut, meta["spacing"], meta["origin"])
    closed = subdyn.recover(*args, iso=0.5)
    assert boundary_vertices(closed.control_faces) == []
    opened = subdyn.recover(*args, iso=0.5, open_at_box=True)
    rim = boundary_vertices(opened.limit_faces)
    assert len(rim) > 20
    off = np.abs(opened.limit_vertices[rim, 2] - face) / meta["spacing"][2]
    assert off.max() <= 1e-9, off.max()
    with pytest.raises(ValueError, match="does not reach the volume's box"):
        subdyn.recover(volume, meta["spacing"], meta["origin"], iso=0.5, open_at_box=True)
