"""The call shapes of Open3D's RaycastingScene, answered by frusta.

    # import open3d as o3d; scene = o3d.t.geometry.RaycastingScene()
    from frusta.o3d import RaycastingScene; scene = RaycastingScene()
    scene.add_triangles(vertices, triangles)
    ans = scene.cast_rays(rays)          # rays: (..., 6) = origin, direction
    ans["t_hit"].numpy(), ans["geometry_ids"].numpy(), ans["primitive_ids"].numpy()

Results are numpy arrays that also answer .numpy(), as Open3D's tensors do.
Meshes are given as arrays, or as objects with Open3D's vertex and triangle
accessors; each add_triangles returns its geometry id (0, 1, ...).
"""
import numpy as np

from . import INVALID_ID, Scene


class _Tensor(np.ndarray):
    """A numpy array with Open3D's Tensor.numpy()."""

    def numpy(self):
        return np.asarray(self)


def _tensor(a):
    return np.asarray(a).view(_Tensor)


def _array(x, dtype):
    if hasattr(x, "numpy") and not isinstance(x, np.ndarray):
        x = x.numpy()
    return np.asarray(x, dtype=dtype)


def _mesh_arrays(mesh):
    if hasattr(mesh, "vertex") and hasattr(mesh, "triangle"):  # open3d.t.geometry.TriangleMesh
        return mesh.vertex.positions, mesh.triangle.indices
    return mesh.vertices, mesh.triangles  # open3d.geometry.TriangleMesh


class RaycastingScene:
    INVALID_ID = INVALID_ID

    def __init__(self, nthreads=0):
        self._vertices, self._triangles, self._first = [], [], [0]
        self._scene = None

    def add_triangles(self, vertex_positions, triangle_indices=None):
        if triangle_indices is None:
            vertex_positions, triangle_indices = _mesh_arrays(vertex_positions)
        v = _array(vertex_positions, np.float32).reshape(-1, 3)
        t = _array(triangle_indices, np.int64).reshape(-1, 3)
        offset = sum(len(x) for x in self._vertices)
        self._vertices.append(v)
        self._triangles.append(t + offset)
        self._first.append(self._first[-1] + len(t))
        self._scene = None
        return len(self._vertices) - 1

    def _committed(self):
        if self._scene is None:
            if not self._vertices:
                raise ValueError("RaycastingScene: no geometry added")
            self._scene = Scene(np.concatenate(self._vertices), np.concatenate(self._triangles))
        return self._scene

    @staticmethod
    def _rays(rays):
        r = _array(rays, np.float32)
        if r.ndim < 1 or r.shape[-1] != 6:
            raise ValueError(f"rays: expected shape (..., 6), got {r.shape}")
        return np.ascontiguousarray(r[..., :3]), np.ascontiguousarray(r[..., 3:])

    def _geometry(self, prim):
        first = np.asarray(self._first[1:], dtype=np.int64)
        hit = prim != INVALID_ID
        geom = np.full(prim.shape, INVALID_ID, dtype=np.uint32)
        local = np.full(prim.shape, INVALID_ID, dtype=np.uint32)
        g = np.searchsorted(first, prim[hit], side="right")
        geom[hit] = g
        local[hit] = prim[hit] - np.asarray(self._first, dtype=np.int64)[g]
        return geom, local

    def cast_rays(self, rays, nthreads=0):
        o, d = self._rays(rays)
        h = self._committed().intersect(o, d)
        geom, local = self._geometry(h.prim)
        n = h.normal.astype(np.float32)
        length = np.linalg.norm(n, axis=-1, keepdims=True)
        n = np.divide(n, length, out=np.zeros_like(n), where=length > 0)
        return {
            "t_hit": _tensor(h.t),
            "geometry_ids": _tensor(geom),
            "primitive_ids": _tensor(local),
            "primitive_uvs": _tensor(np.stack([h.u, h.v], axis=-1)),
            "primitive_normals": _tensor(n),
        }

    def test_occlusions(self, rays, tnear=0.0, tfar=float("inf"), nthreads=0):
        o, d = self._rays(rays)
        return _tensor(self._committed().occluded(o, d, tnear, tfar))

    def count_intersections(self, rays, nthreads=0):
        o, d = self._rays(rays)
        return _tensor(self._committed().count_intersections(o, d).astype(np.int32))

    def list_intersections(self, rays, nthreads=0):
        o, d = self._rays(rays)
        scene = self._committed()
        most = int(scene.count_intersections(o, d).max(initial=0))  # room for every crossing, no more
        a = scene.intersect_all(o, d, max_hits=max(most, 1))
        geom, local = self._geometry(a.prim)
        splits = np.concatenate([[0], np.cumsum(a.count.reshape(-1), dtype=np.int64)]).astype(np.uint32)
        return {
            "ray_splits": _tensor(splits),
            "ray_ids": _tensor(a.ray.astype(np.int32)),
            "geometry_ids": _tensor(geom),
            "primitive_ids": _tensor(local),
            "primitive_uvs": _tensor(np.stack([a.u, a.v], axis=-1)),
            "t_hit": _tensor(a.t),
        }
