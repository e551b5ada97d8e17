"""Open3D helpers: subdyn results and arrays to and from Open3D geometry.
Open3D is imported on first use; subdyn itself does not need it."""

from __future__ import annotations

from typing import Any, Optional, Tuple

import numpy as np


def _o3d():
    import open3d

    return open3d


def to_point_cloud(points: Any, normals: Any = None):
    """An ``open3d.geometry.PointCloud`` from (n, 3) points (and normals)."""
    o3d = _o3d()
    pcd = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(np.asarray(points, np.float64)))
    if normals is not None:
        pcd.normals = o3d.utility.Vector3dVector(np.asarray(normals, np.float64))
    return pcd


def to_triangle_mesh(result_or_vertices: Any, triangles: Any = None, normals: Any = None):
    """An ``open3d.geometry.TriangleMesh`` from a :class:`subdyn.FitResult`
    (its limit surface with normals) or from vertices and (k, 3) triangles."""
    o3d = _o3d()
    if triangles is None:
        r = result_or_vertices
        if r.limit_triangles is None:
            raise ValueError("the result's limit surface is quads; fit without quads=True")
        vertices, triangles, normals = r.limit_vertices, r.limit_triangles, r.limit_normals
    else:
        vertices = result_or_vertices
    mesh = o3d.geometry.TriangleMesh(
        o3d.utility.Vector3dVector(np.asarray(vertices, np.float64)),
        o3d.utility.Vector3iVector(np.asarray(triangles, np.int32)),
    )
    if normals is not None:
        mesh.vertex_normals = o3d.utility.Vector3dVector(np.asarray(normals, np.float64))
    return mesh


def from_point_cloud(pcd) -> Tuple[np.ndarray, Optional[np.ndarray]]:
    """``(points, normals or None)`` of an Open3D point cloud."""
    points = np.asarray(pcd.points, dtype=np.float64)
    normals = np.asarray(pcd.normals, dtype=np.float64) if pcd.has_normals() else None
    return points, normals


def from_triangle_mesh(mesh) -> Tuple[np.ndarray, np.ndarray]:
    """``(vertices, triangles)`` of an Open3D triangle mesh."""
    return (np.asarray(mesh.vertices, dtype=np.float64),
            np.asarray(mesh.triangles, dtype=np.int64))
