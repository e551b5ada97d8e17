"""pymeshlab helpers: subdyn results and arrays to and from pymeshlab meshes.
pymeshlab is imported on first use; subdyn itself does not need it."""

from __future__ import annotations

from typing import Any, Tuple

import numpy as np


def to_mesh(result_or_vertices: Any, triangles: Any = None):
    """A ``pymeshlab.Mesh`` from a :class:`subdyn.FitResult` (its limit
    surface) or from vertices and (k, 3) triangles."""
    import pymeshlab

    if triangles is None:
        r = result_or_vertices
        if r.limit_triangles is None:
            raise ValueError("the result's limit surface is quads; fit without quads=True")
        vertices, triangles = r.limit_vertices, r.limit_triangles
    else:
        vertices = result_or_vertices
    return pymeshlab.Mesh(vertex_matrix=np.asarray(vertices, np.float64),
                          face_matrix=np.asarray(triangles, np.int32))


def to_mesh_set(result_or_vertices: Any, triangles: Any = None):
    """A ``pymeshlab.MeshSet`` holding :func:`to_mesh`'s mesh."""
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.add_mesh(to_mesh(result_or_vertices, triangles))
    return ms


def from_mesh(mesh) -> Tuple[np.ndarray, np.ndarray]:
    """``(vertices, triangles)`` of a ``pymeshlab.Mesh``."""
    return (np.asarray(mesh.vertex_matrix(), dtype=np.float64),
            np.asarray(mesh.face_matrix(), dtype=np.int64))
