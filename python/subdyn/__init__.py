"""subdyn: Catmull-Clark subdivision surfaces fitted to point clouds and
volumes, with numpy arrays in and out.

The work is done in Rust (``subdyn._subdyn``) with the GIL released; this
module turns arrays into the flat face lists the extension takes and its
results into plain classes that pickle.

    import numpy as np, subdyn
    result = subdyn.fit(points)                  # (n, 3) array
    mesh = subdyn.open3d.to_triangle_mesh(result)  # an open3d TriangleMesh
"""

from __future__ import annotations

import importlib
import json
from dataclasses import dataclass, field
from typing import Any, Dict, List, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np

from . import _subdyn

__version__ = _subdyn.__version__

__all__ = [
    "FitResult",
    "LimitSample",
    "LimitSurface",
    "fit",
    "read_mesh",
    "read_points",
    "recover",
    "subdivide",
    "write_mesh",
]

Faces = Union[np.ndarray, Sequence[Sequence[int]]]


def _points(array: Any, what: str) -> np.ndarray:
    a = np.ascontiguousarray(array, dtype=np.float64)
    if a.ndim != 2 or a.shape[1] != 3:
        raise ValueError(f"{what} must be an (n, 3) array, got shape {a.shape}")
    return a


def _flat_faces(faces: Faces) -> Tuple[np.ndarray, np.ndarray]:
    """Faces (a (k, n) int array or a list of index sequences) as the flat
    vertex list and the offsets where each face starts."""
    if isinstance(faces, np.ndarray) and faces.ndim == 2:
        k, n = faces.shape
        flat = np.ascontiguousarray(faces, dtype=np.int64).ravel()
        return flat, np.arange(0, k * n + 1, n, dtype=np.int64) if n else np.zeros(1, np.int64)
    rows = [np.asarray(f, dtype=np.int64).ravel() for f in faces]
    sizes = np.array([len(r) for r in rows], dtype=np.int64)
    offsets = np.zeros(len(rows) + 1, dtype=np.int64)
    np.cumsum(sizes, out=offsets[1:])
    flat = np.concatenate(rows) if rows else np.zeros(0, dtype=np.int64)
    return flat, offsets


def _face_list(flat: np.ndarray, offsets: np.ndarray) -> List[np.ndarray]:
    return [flat[offsets[i]:offsets[i + 1]].copy() for i in range(len(offsets) - 1)]


def _face_array(flat: np.ndarray, offsets: np.ndarray, n: int) -> np.ndarray:
    """Faces that all have `n` vertices as a (k, n) int64 array."""
    return flat.reshape(-1, n) if len(flat) else np.zeros((0, n), dtype=np.int64)


def _mesh_args(vertices: Any, faces: Faces) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    flat, offsets = _flat_faces(faces)
    return _points(vertices, "vertices"), flat, offsets


@dataclass
class FitResult:
    """What :func:`fit` and :func:`recover` return: plain arrays and a dict,
    so it pickles.

    ``control_faces`` is a list of int64 arrays (any polygon size);
    ``control_creases`` is (m, 3) float64, rows ``(i, j, sharpness)``: the
    control edges tagged as sharp creases (``fit``'s ``crease_angle``; the
    limit surface is the control mesh's with them, as
    ``LimitSurface(control_vertices, control_faces, creases=control_creases)``);
    ``limit_triangles`` is (k, 3) int64 (``limit_quads`` (k, 4) instead when
    the call had ``quads=True``); ``report`` equals the JSON of the CLI's
    ``--report`` (with ``input`` naming the array and no output paths).
    """

    control_vertices: np.ndarray
    control_faces: List[np.ndarray]
    limit_vertices: np.ndarray
    limit_triangles: Optional[np.ndarray]
    limit_normals: np.ndarray
    report: Dict[str, Any]
    init_vertices: np.ndarray
    init_faces: List[np.ndarray]
    limit_quads: Optional[np.ndarray] = field(default=None)
    control_creases: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))

    @property
    def limit_faces(self) -> np.ndarray:
        """The limit surface's faces: triangles, or quads with ``quads=True``."""
        return self.limit_triangles if self.limit_triangles is not None else self.limit_quads

    def write_control(self, path: str) -> None:
        """Writes the control mesh (format from the extension) with its
        creases: ``t crease`` lines in an OBJ file, else ``PATH.creases``
        beside it (when there are any)."""
        write_mesh(path, self.control_vertices, self.control_faces,
                   creases=self.control_creases if len(self.control_creases) else None)

    def write_limit(self, path: str, normals: bool = True) -> None:
        """Writes the limit surface (with its unit normals unless ``normals=False``)."""
        write_mesh(path, self.limit_vertices, self.limit_faces,
                   self.limit_normals if normals else None)


def _result(raw: Dict[str, Any], quads: bool) -> FitResult:
    cv, cfv, cfo = raw["control"]
    iv, ifv, ifo = raw["init"]
    lv, lfv, lfo = raw["limit"]
    lf = _face_array(lfv, lfo, 4 if quads else 3)
    return FitResult(
        control_vertices=cv,
        control_faces=_face_list(cfv, cfo),
        limit_vertices=lv,
        limit_triangles=None if quads else lf,
        limit_quads=lf if quads else None,
        limit_normals=raw["limit_normals"],
        report=json.loads(raw["report"]),
        init_vertices=iv,
        init_faces=_face_list(ifv, ifo),
        control_creases=raw["creases"],
    )


def fit(points: Any, normals: Any = None, **options: Any) -> FitResult:
    """Fits a dynamic Catmull-Clark surface to ``points`` ((n, 3)), as
    ``subdyn fit`` does: same control mesh, same report.

    Options are the CLI's flags in snake_case: ``tol`` (0.1, % of the
    diagonal), ``tol_stat`` ("p95"; "max", "rms", "mean"), ``max_level`` (3),
    ``refine`` ("adaptive" or "uniform"), ``refine_significance``,
    ``refine_off_data``, ``tension``, ``bending``, ``fairness``,
    ``untangle_rounds``, ``final_untangle_rounds``, ``mass``,
    ``crease_angle`` (50 degrees; 0 turns sharp creases off),
    ``init`` ("auto", "closed", "open", "occupancy", or a ``(vertices,
    faces)`` control mesh), ``init_resolution``, ``tess`` (4, the limit
    surface's samples per quad edge), ``quads`` (False), and ``threads``
    (run in a pool of that many threads; default all cores). An unknown
    option is a ValueError.
    """
    pts = _points(points, "points")
    nrm = None if normals is None else _points(normals, "normals")
    init = options.pop("init", None)
    init_mesh = None
    if init is not None and not isinstance(init, str):
        try:
            vertices, faces = init
        except (TypeError, ValueError):
            raise ValueError("init must be a method name or a (vertices, faces) mesh") from None
        init_mesh = _mesh_args(vertices, faces)
    elif init is not None:
        options["init"] = init
    raw = _subdyn.fit(pts, nrm, init_mesh, options)
    return _result(raw, bool(options.get("quads", False)))


def recover(volume: Any, spacing: Sequence[float] = (1.0, 1.0, 1.0),
            origin: Sequence[float] = (0.0, 0.0, 0.0), points: Any = None,
            init: Any = None, **options: Any) -> FitResult:
    """Recovers a closed shape from a volume, as ``subdyn recover`` does.

    ``volume[i, j, k]`` is the sample at world point ``origin + (i sx, j sy,
    k sz)``. ``points`` are user-placed boundary points ((m, 3)); ``init`` a
    ``(vertices, faces)`` starting mesh. Options as the CLI's flags: ``iso``
    (negative values too; an array has no sidecar, so where the CLI would
    take a sidecar's ``iso_value`` pass it here), ``preset`` ("skin" -500 HU or "bone" +300 HU, for
    CT in Hounsfield units), ``edge_strength``, ``dark``, ``sigma``, ``tol`` (voxels), ``max_level``,
    ``auto``, ``seed`` ((x, y, z)), ``seed_radius``, ``resolution``,
    ``points_weight``, ``two_sided_weight``, ``two_sided_distance``
    (voxels), ``max_unmatched``, ``refine`` ("adaptive" or "uniform"),
    ``max_level_growth``, ``max_control_share``, ``bending``, ``tess``, ``quads``, ``threads``, ``accept_poor``, ``open_at_box`` (an object cut by the volume's box is
    left open there, its rim on the box face; by default it closes on the
    face). A poor result (the surface leaves the volume's box, much
    of it found no boundary, or a level got worse) raises ``ValueError``
    naming why, unless ``accept_poor=True``; ``report["poor_result"]`` lists
    the reasons of an accepted one.
    """
    v = np.asarray(volume, dtype=np.float32)
    if v.ndim != 3:
        raise ValueError(f"volume must be a 3-D array, got {v.ndim} dimensions")
    data = np.ascontiguousarray(v.transpose(2, 1, 0)).ravel()
    spacing = tuple(float(s) for s in spacing)
    origin = tuple(float(o) for o in origin)
    if len(spacing) != 3 or len(origin) != 3:
        raise ValueError("spacing and origin must have three numbers each")
    pts = None if points is None else _points(points, "points")
    init_mesh = None if init is None else _mesh_args(*init)
    raw = _subdyn.recover(data, list(v.shape), spacing, origin, pts, init_mesh, options)
    return _result(raw, bool(options.get("quads", False)))


def subdivide(vertices: Any, faces: Faces, levels: int, creases: Any = None,
              boundary: str = "edge-and-corner", limit: bool = False,
              quads: bool = False) -> Tuple[np.ndarray, List[np.ndarray]]:
    """Uniform Catmull-Clark refinement to ``levels`` (0 to 8), as ``subdyn
    subdivide``. ``creases`` is an (m, 3) array of rows ``(i, j, sharpness)``
    (sharpness >= 10 is infinitely sharp); ``boundary`` "edge-and-corner",
    "edge-only" or "none" (the faces at untagged boundary vertices become
    holes and are left out). Vertex sharpness, hole faces, the Chaikin crease
    method and smooth triangles are on the command line only for now. With ``limit`` the vertices lie on the limit surface and the
    faces are triangles unless ``quads``. Returns ``(vertices, faces)``."""
    cr = None if creases is None else np.ascontiguousarray(creases, dtype=np.float64)
    v, fv, fo = _subdyn.subdivide(*_mesh_args(vertices, faces), int(levels), cr, boundary,
                                  bool(limit), bool(quads))
    return v, _face_list(fv, fo)


class LimitSample(NamedTuple):
    """Limit positions and derivatives, each (n, 3) (or (3,) for one sample)."""

    p: np.ndarray
    du: np.ndarray
    dv: np.ndarray
    duu: np.ndarray
    duv: np.ndarray
    dvv: np.ndarray


class LimitSurface:
    """The exact Catmull-Clark limit surface of a control mesh.

    A quad's ``u`` runs from its first vertex to its second, ``v`` from the
    first to the fourth (both in [0, 1]); an n-gon's quad sub-face ``i``
    covers ``[tu, tu + 1/2] x [tv, tv + 1/2]``, ``(tu, tv) = (i mod d, i div
    d)``, ``d = ceil(sqrt(n))`` (OpenSubdiv Bfr's parameterisation).
    """

    def __init__(self, vertices: Any, faces: Faces, creases: Any = None,
                 boundary: str = "edge-and-corner") -> None:
        self._args = (_points(vertices, "vertices"), faces, creases, boundary)
        cr = None if creases is None else np.ascontiguousarray(creases, dtype=np.float64)
        self._surface = _subdyn.LimitSurface(*_mesh_args(vertices, faces), cr, boundary)

    def __reduce__(self):
        return (LimitSurface, self._args)

    @property
    def num_control_points(self) -> int:
        return self._surface.num_control_points

    @property
    def num_faces(self) -> int:
        return self._surface.num_faces

    @staticmethod
    def _samples(face, u, v):
        f = np.atleast_1d(np.asarray(face, dtype=np.int64))
        uu = np.atleast_1d(np.asarray(u, dtype=np.float64))
        vv = np.atleast_1d(np.asarray(v, dtype=np.float64))
        f, uu, vv = np.broadcast_arrays(f, uu, vv)
        return (np.ascontiguousarray(f.ravel()), np.ascontiguousarray(uu.ravel()),
                np.ascontiguousarray(vv.ravel()))

    def evaluate(self, face, u, v) -> LimitSample:
        """Positions and first and second derivatives at ``(face, u, v)``
        (scalars or arrays, broadcast together)."""
        scalar = np.ndim(face) == 0 and np.ndim(u) == 0 and np.ndim(v) == 0
        out = self._surface.evaluate(*self._samples(face, u, v))
        return LimitSample(*(q[0] if scalar else q for q in out))

    def jacobian(self, face, u, v, derivative: str = "p"):
        """The limit stencils at the samples as a ``scipy.sparse.csr_matrix``
        of shape (samples, control points): ``J @ control_vertices`` is
        ``evaluate(face, u, v).p`` (or the derivative named ``du``, ``dv``,
        ``duu``, ``duv``, ``dvv``), and J is the derivative of the samples
        with respect to the control points."""
        from scipy.sparse import csr_matrix

        data, indices, indptr, shape = self._surface.jacobian(*self._samples(face, u, v),
                                                              derivative)
        return csr_matrix((data, indices, indptr), shape=shape)

    def tessellate(self, k: int = 4, quads: bool = False):
        """The limit surface sampled k x k per quad: ``(vertices, faces,
        normals)`` with faces (m, 3) triangles, or (m, 4) with ``quads``."""
        v, fv, fo, n = self._surface.tessellate(int(k), bool(quads))
        return v, _face_array(fv, fo, 4 if quads else 3), n


def read_mesh(path: str) -> Tuple[np.ndarray, List[np.ndarray]]:
    """Reads a mesh (.obj, .ply, .off; .gz too): ``(vertices, faces)``."""
    v, fv, fo = _subdyn.read_mesh(str(path))
    return v, _face_list(fv, fo)


def read_points(path: str) -> Tuple[np.ndarray, Optional[np.ndarray]]:
    """Reads the points of a point or mesh file: ``(points, normals or None)``."""
    return _subdyn.read_points(str(path))


def write_mesh(path: str, vertices: Any, faces: Faces, normals: Any = None,
               creases: Any = None) -> None:
    """Writes a mesh, format from the extension (.obj, .ply, .off), through a
    temporary file so a failure leaves nothing behind. A control mesh's
    ``creases`` ((m, 3) rows ``(i, j, sharpness)``) go into an OBJ file as
    OpenSubdiv ``t crease`` lines, beside other formats as ``PATH.creases``."""
    nrm = None if normals is None else _points(normals, "normals")
    cr = None if creases is None else np.ascontiguousarray(creases, dtype=np.float64)
    _subdyn.write_mesh(str(path), *_mesh_args(vertices, faces), nrm, cr)


def __getattr__(name: str):
    # `subdyn.open3d` and `subdyn.pymeshlab` load on first use, so neither
    # library is needed to import subdyn.
    if name in ("open3d", "pymeshlab"):
        return importlib.import_module(f".{name}", __name__)
    raise AttributeError(f"module 'subdyn' has no attribute '{name}'")
