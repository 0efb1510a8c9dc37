"""The Python module against the C library, brute force in double, and bad input.

The C side is called through ctypes on the build's libfrusta.so (FRUSTA_LIB),
so the module's packing, chunking, threading and output are checked against
the library's own answers bit for bit.
"""
import ctypes
import os
import subprocess
import threading
import time

import numpy as np
import pytest

import frusta
from frusta.o3d import RaycastingScene

SHARED = os.environ.get("FRUSTA_SHARED", os.path.join(os.path.dirname(__file__), "../../../shared"))


# ---- the C library through ctypes -------------------------------------------------

class CRay(ctypes.Structure):
    _fields_ = [("org", ctypes.c_float * 3), ("tnear", ctypes.c_float), ("dir", ctypes.c_float * 3),
                ("tfar", ctypes.c_float)]


CHIT = np.dtype([("t", "<f4"), ("u", "<f4"), ("v", "<f4"), ("prim", "<u4"), ("ng", "<f4", 3)])
CRAY = np.dtype([("org", "<f4", 3), ("tnear", "<f4"), ("dir", "<f4", 3), ("tfar", "<f4")])


@pytest.fixture(scope="module")
def clib():
    path = os.environ.get("FRUSTA_LIB")
    if not path or not os.path.exists(path):
        pytest.skip("FRUSTA_LIB names no libfrusta.so")
    lib = ctypes.CDLL(path)
    lib.fr_scene_from_arrays.argtypes = [ctypes.c_void_p, ctypes.c_size_t, ctypes.c_void_p, ctypes.c_size_t,
                                         ctypes.POINTER(ctypes.c_void_p)]
    lib.fr_scene_commit.argtypes = [ctypes.c_void_p]
    lib.fr_scene_release.argtypes = [ctypes.c_void_p]
    lib.fr_scene_set_trace_mode.argtypes = [ctypes.c_void_p, ctypes.c_int]
    lib.fr_intersect_stream.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t]
    lib.fr_occluded_stream.argtypes = [ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_size_t]
    return lib


def c_scene(lib, v, t, mode):
    s = ctypes.c_void_p()
    v = np.ascontiguousarray(v, dtype=np.float32)
    t = np.ascontiguousarray(t, dtype=np.uint32)
    assert lib.fr_scene_from_arrays(v.ctypes.data, len(v), t.ctypes.data, len(t), ctypes.byref(s)) == 0
    assert lib.fr_scene_commit(s) == 0
    assert lib.fr_scene_set_trace_mode(s, mode) == 0
    return s


def c_rays(o, d, tnear=0.0, tfar=np.inf):
    r = np.zeros(len(o), dtype=CRAY)
    r["org"], r["dir"], r["tnear"], r["tfar"] = o, d, tnear, tfar
    return r


# ---- scenes and rays -------------------------------------------------------------

def sphere_mesh(n_lat=24, n_lon=48, radius=1.0, centre=(0.0, 0.0, 0.0), jitter=0.2, seed=1):
    """A closed, consistently wound, star-shaped lat-long sphere."""
    rng = np.random.default_rng(seed)
    verts = [(0.0, radius, 0.0)]
    for i in range(1, n_lat):
        th = np.pi * i / n_lat
        for j in range(n_lon):
            ph = 2 * np.pi * j / n_lon
            r = radius * (1 + jitter * (rng.random() - 0.5))
            verts.append((r * np.sin(th) * np.cos(ph), r * np.cos(th), r * np.sin(th) * np.sin(ph)))
    verts.append((0.0, -radius, 0.0))
    ring = lambda i, j: 1 + (i - 1) * n_lon + j % n_lon  # noqa: E731
    tris = [(0, ring(1, j + 1), ring(1, j)) for j in range(n_lon)]
    for i in range(1, n_lat - 1):
        for j in range(n_lon):
            tris.append((ring(i, j), ring(i, j + 1), ring(i + 1, j + 1)))
            tris.append((ring(i, j), ring(i + 1, j + 1), ring(i + 1, j)))
    last = len(verts) - 1
    tris += [(last, ring(n_lat - 1, j), ring(n_lat - 1, j + 1)) for j in range(n_lon)]
    v = np.array(verts, dtype=np.float64) + np.asarray(centre)
    return v.astype(np.float32), np.array(tris, dtype=np.int64)


def soup(n, seed, size=10.0):
    rng = np.random.default_rng(seed)
    a = rng.uniform(-size, size, (n, 3))
    b = a + rng.uniform(-1, 1, (n, 3))
    c = a + rng.uniform(-1, 1, (n, 3))
    v = np.stack([a, b, c], axis=1).reshape(-1, 3).astype(np.float32)
    return v, np.arange(3 * n, dtype=np.int64).reshape(-1, 3)


def random_rays(n, seed, size=10.0):
    rng = np.random.default_rng(seed)
    o = rng.uniform(-2 * size, 2 * size, (n, 3)).astype(np.float32)
    d = (rng.uniform(-size, size, (n, 3)) - o).astype(np.float32)
    return o, d


def camera_rays(scene, w, h):
    lo, hi = scene.bounds
    centre, extent = (lo + hi) / 2, float(np.linalg.norm(hi - lo))
    eye = centre + np.array([0.3, 0.4, 1.0], dtype=np.float32) * extent
    fwd = centre - eye
    fwd /= np.linalg.norm(fwd)
    right = np.cross(fwd, [0, 1, 0])
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    x = (np.arange(w) + 0.5) / w * 2 - 1
    y = (np.arange(h) + 0.5) / h * 2 - 1
    d = fwd + 0.5 * (x[None, :, None] * right + y[:, None, None] * up)
    o = np.broadcast_to(eye, d.shape)
    return np.ascontiguousarray(o, dtype=np.float32), np.ascontiguousarray(d, dtype=np.float32)


def moller(v, t, o, d):
    """Every (ray, triangle) in double: t and the least barycentric."""
    a, b, c = (v[t[:, k]].astype(np.float64) for k in range(3))
    e1, e2 = b - a, c - a
    o, d = o.astype(np.float64)[:, None, :], d.astype(np.float64)[:, None, :]
    p = np.cross(d, e2)
    det = np.einsum("rtk,tk->rt", p, e1)
    n = np.cross(e1, e2)
    parallel = np.abs(det) <= 1e-6 * np.linalg.norm(n, axis=1) * np.linalg.norm(d, axis=2)
    det = np.where(det == 0, 1e-300, det)
    q = o - a
    b1 = np.einsum("rtk,rtk->rt", q, p) / det
    qv = np.cross(q, e1)
    b2 = np.einsum("rtk,rtk->rt", np.broadcast_to(d, qv.shape), qv) / det
    tt = np.einsum("tk,rtk->rt", e2, qv) / det
    margin = np.minimum(np.minimum(b1, b2), 1 - b1 - b2)
    return tt, np.where(parallel, np.nan, margin)


# ---- answers ---------------------------------------------------------------------

@pytest.mark.parametrize("mode", ["single", "auto", "hybrid16", "raystream"])
def test_intersect_equals_c_api(clib, mode):
    v, t = soup(4000, 3)
    o, d = random_rays(20000, 4)
    modes = {"auto": 0, "single": 1, "packet8": 2, "packet16": 3, "hybrid16": 4, "raystream": 5}
    cs = c_scene(clib, v, t, modes[mode])
    rays = c_rays(o, d)
    hits = np.zeros(len(o), dtype=CHIT)
    clib.fr_intersect_stream(cs, rays.ctypes.data, hits.ctypes.data, len(o))
    occ = np.zeros(len(o), dtype=np.uint8)
    clib.fr_occluded_stream(cs, rays.ctypes.data, occ.ctypes.data, len(o))
    clib.fr_scene_release(cs)
    s = frusta.Scene(v, t)
    s.trace_mode = mode
    assert s.trace_mode == mode
    h = s.intersect(o, d)
    assert (h.prim != frusta.INVALID_ID).sum() > 1000
    np.testing.assert_array_equal(h.t, hits["t"])
    same = h.prim == hits["prim"]
    if mode == "single":
        assert same.all()
    else:  # a packet may report the other triangle of a tie, at the same t
        assert same.mean() > 0.999
    np.testing.assert_array_equal(h.u[same], hits["u"][same])
    np.testing.assert_array_equal(h.normal[same], hits["ng"][same])
    np.testing.assert_array_equal(s.occluded(o, d), occ.astype(bool))
    bare = s.intersect(o, d, normals=False)  # the same answers, without the normal array
    assert bare.normal is None
    for a, b in zip(bare[:4], h[:4]):
        np.testing.assert_array_equal(a, b)


def test_camera_rays_equal_c_api(clib):
    scene = frusta.Scene.builtin()
    o, d = camera_rays(scene, 256, 192)
    cs = c_scene(clib, scene.vertices, scene.triangles, 0)
    hits = np.zeros(o.shape[0] * o.shape[1], dtype=CHIT)
    rays = c_rays(o.reshape(-1, 3), d.reshape(-1, 3))
    clib.fr_intersect_stream(cs, rays.ctypes.data, hits.ctypes.data, len(rays))
    clib.fr_scene_release(cs)
    h = scene.intersect(o, d)
    assert h.t.shape == (192, 256) and h.normal.shape == (192, 256, 3)
    np.testing.assert_array_equal(h.t.reshape(-1), hits["t"])
    assert (h.prim.reshape(-1) == hits["prim"]).mean() > 0.999
    assert np.isfinite(h.t).mean() > 0.1


def test_threads_give_the_same_answers():
    v, t = soup(3000, 7)
    o, d = random_rays(50000, 8)
    s = frusta.Scene(v, t)
    frusta.set_threads(1)
    one = s.intersect(o, d)
    frusta.set_threads(0)
    assert frusta.get_threads() >= 1
    many = s.intersect(o, d)
    np.testing.assert_array_equal(one.t, many.t)
    results = [None] * 4

    def run(i):
        results[i] = s.intersect(o, d).t

    ts = [threading.Thread(target=run, args=(i,)) for i in range(4)]
    for x in ts:
        x.start()
    for x in ts:
        x.join()
    for r in results:
        np.testing.assert_array_equal(r, one.t)


@pytest.mark.parametrize("mode", ["single", "auto"])
def test_reordered_arrays_give_the_same_answers(mode):
    # reorder=True traces large incoherent arrays in the order of their
    # origins' cells. In single mode a ray's answer does not depend on its
    # neighbours, so every bit must be the one of the arrays traced as given,
    # per-ray ranges and normals included, across a round's end (2^20 rays)
    # and on one thread or several; in auto mode, whose packets depend on
    # the neighbours, the answers are a trace mode's: the same t, u and v to
    # rounding, the triangle but at a tie.
    v, t = soup(3000, 11)
    s = frusta.Scene(v, t)
    s.trace_mode = mode
    n = (1 << 20) + 4099
    o, d = random_rays(n, 12)
    rng = np.random.default_rng(13)
    tnear = rng.uniform(0, 0.2, n).astype(np.float32)
    tfar = rng.uniform(0.5, 3, n).astype(np.float32)
    ref, ref_occ = s.intersect(o, d, tnear, tfar), s.occluded(o, d, tnear, tfar)
    assert np.isfinite(ref.t).mean() > 0.05 and ref_occ.mean() > 0.05
    for threads in (1, 0):
        frusta.set_threads(threads)
        got, occ = s.intersect(o, d, tnear, tfar, reorder=True), s.occluded(o, d, tnear, tfar, reorder=True)
        np.testing.assert_array_equal(got.t, ref.t)
        np.testing.assert_array_equal(occ, ref_occ)
        same = got.prim == ref.prim
        if mode == "single":
            assert same.all()
            for name in ("u", "v", "normal"):
                np.testing.assert_array_equal(getattr(got, name), getattr(ref, name))
        else:
            assert same.mean() > 0.9999
            np.testing.assert_allclose(got.u[same], ref.u[same], atol=1e-4)
            np.testing.assert_array_equal(got.normal[same], ref.normal[same])
    frusta.set_threads(0)
    # a bad ray is named as in arrays traced as given: the first
    bad = d.copy()
    bad[70001, 0] = np.nan
    bad[40000, 2] = np.inf
    for call in (s.intersect, s.occluded):
        with pytest.raises(ValueError, match="ray 40000:"):
            call(o, bad, reorder=True)
    # coherent arrays (one origin) and small ones are traced as given
    cam_o = np.zeros_like(d[:50000])
    np.testing.assert_array_equal(s.intersect(cam_o, d[:50000], reorder=True).prim,
                                  s.intersect(cam_o, d[:50000]).prim)


def test_gil_released_while_tracing():
    s = frusta.Scene.builtin()
    o, d = random_rays(1 << 21, 9, size=5.0)
    frusta.set_threads(1)
    ticks = []
    done = threading.Event()

    def tick():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    x = threading.Thread(target=tick)
    x.start()
    time.sleep(0.01)
    start = time.perf_counter()
    s.occluded(o, d)
    s.intersect(o, d)
    end = time.perf_counter()
    done.set()
    x.join()
    frusta.set_threads(0)
    during = [t for t in ticks if start < t < end]
    assert end - start > 0.05
    assert len(during) >= 5, "another Python thread did not run while frusta traced"


def test_ranges():
    v, t = sphere_mesh()
    s = frusta.Scene(v, t)
    o = np.zeros((3, 3), dtype=np.float32)
    d = np.array([[1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float32)
    full = s.intersect(o, d)
    assert np.isfinite(full.t).all()
    short = s.intersect(o, d, tfar=np.array([0.1, 10, 0.1], dtype=np.float32))
    assert np.isinf(short.t[0]) and np.isfinite(short.t[1]) and np.isinf(short.t[2])
    assert not s.occluded(o, d, tnear=2.0).any()
    assert s.occluded(o, d, 0.0, 5.0).all()
    h = s.intersect(o.astype(np.float64), d.astype(np.float64))  # converted once
    np.testing.assert_array_equal(h.t, full.t)


# ---- every hit ---------------------------------------------------------------------

def test_intersect_all_against_double():
    v1, t1 = sphere_mesh(12, 24, seed=2)
    v2, t2 = soup(300, 5, size=3.0)
    v = np.concatenate([v1, v2])
    t = np.concatenate([t1, t2 + len(v1)])
    s = frusta.Scene(v, t)
    o, d = random_rays(400, 6, size=3.0)
    a = s.intersect_all(o, d, max_hits=64)
    assert a.count.shape == (400,) and a.count.sum() == len(a.ray) and len(a.ray) > 400
    tt, margin = moller(v, t, o, d)
    clear = (margin > 1e-4) & (tt > 1e-4 * np.maximum(1, np.abs(tt)))
    start = np.concatenate([[0], np.cumsum(a.count.astype(np.int64))])
    for i in range(400):
        got = a.prim[start[i]:start[i + 1]]
        ts = a.t[start[i]:start[i + 1]]
        assert len(set(got.tolist())) == len(got), "a triangle listed twice"
        assert (np.diff(ts) >= 0).all()
        want = set(np.nonzero(clear[i])[0].tolist())
        assert want <= set(got.tolist()), f"ray {i}: clearly crossed triangles missing"
        for p, x in zip(got, ts):
            assert not (margin[i, p] < -1e-3), f"ray {i}: triangle {p} listed but not crossed"
            assert abs(tt[i, p] - x) <= 1e-4 * max(1.0, abs(x))
    # the first crossing is the closest hit
    h = s.intersect(o, d)
    first = a.t[start[:-1][a.count > 0]]
    np.testing.assert_allclose(first, h.t[a.count > 0], rtol=1e-5)
    # truncation keeps the count whole
    b = s.intersect_all(o, d, max_hits=1)
    np.testing.assert_array_equal(b.count, a.count)
    assert len(b.ray) == (a.count > 0).sum()
    np.testing.assert_array_equal(s.count_intersections(o, d), a.count)


def test_count_through_vertices_is_parity():
    v, t = sphere_mesh(16, 32, seed=3)
    s = frusta.Scene(v, t)
    inside = np.zeros((len(v), 3), dtype=np.float32) + np.float32(0.01)
    d = v - inside  # straight at every vertex
    assert (s.count_intersections(inside, d) == 1).all()
    outside = inside - 5 * d
    assert (s.count_intersections(outside, d) == 2).all()
    pts = np.random.default_rng(4).uniform(-1.5, 1.5, (5000, 3)).astype(np.float32)
    r = np.linalg.norm(pts, axis=1)
    sure = (r < 0.85) | (r > 1.15)
    np.testing.assert_array_equal(s.contains(pts)[sure], (r < 0.85)[sure])


# ---- the Open3D adapter ------------------------------------------------------------

def test_open3d_shapes():
    rc = RaycastingScene()
    tri = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0]], dtype=np.float32)
    g0 = rc.add_triangles(tri, np.array([[0, 1, 2]], dtype=np.uint32))
    v, t = sphere_mesh(8, 16, centre=(5, 0, 0))
    g1 = rc.add_triangles(v, t)
    assert (g0, g1) == (0, 1)
    rays = np.array([[0.2, 0.2, 1, 0, 0, -1], [5, 0, 5, 0, 0, -1], [9, 9, 9, 1, 0, 0]], dtype=np.float32)
    ans = rc.cast_rays(rays)
    assert set(ans) == {"t_hit", "geometry_ids", "primitive_ids", "primitive_uvs", "primitive_normals"}
    np.testing.assert_allclose(ans["t_hit"].numpy()[0], 1.0)
    assert np.isinf(ans["t_hit"].numpy()[2])
    assert list(ans["geometry_ids"].numpy()) == [0, 1, RaycastingScene.INVALID_ID]
    assert ans["primitive_ids"].numpy()[0] == 0 and ans["primitive_ids"].numpy()[1] < len(t)
    assert ans["primitive_uvs"].shape == (3, 2) and ans["primitive_normals"].shape == (3, 3)
    np.testing.assert_allclose(np.linalg.norm(ans["primitive_normals"][:2], axis=1), 1, rtol=1e-6)
    assert list(rc.test_occlusions(rays).numpy()) == [True, True, False]
    assert list(rc.count_intersections(rays).numpy()) == [1, 2, 0]
    li = rc.list_intersections(rays)
    assert list(li["ray_splits"].numpy()) == [0, 1, 3, 3]
    assert list(li["geometry_ids"].numpy()) == [0, 1, 1]


# ---- files -------------------------------------------------------------------------

def test_load_and_errors(tmp_path):
    dragon = os.path.join(SHARED, "scenes/dragon/dragon.ply.zst")
    if os.path.exists(dragon):
        s = frusta.Scene.load(dragon)
        assert s.triangle_count > 100000
    with pytest.raises(OSError):
        frusta.Scene.load(str(tmp_path / "missing.obj"))
    bad = tmp_path / "bad.ply"
    bad.write_bytes(b"ply\nformat ascii 1.0\nelement vertex 99999999999\nend_header\n")
    with pytest.raises(ValueError):
        frusta.Scene.load(str(bad))


def test_scene_reads_contiguous_vertices_in_place():
    """C-contiguous float32 vertices are read in place (the scene holds the
    array itself); other dtypes and layouts are converted once, and the
    triangles are always the scene's own checked copy. Every way gives the
    same answers."""
    import gc
    import sys
    v, t = sphere_mesh(16, 32)
    o, d = random_rays(2000, 9, size=1.0)
    ref = frusta.Scene(v.astype(np.float64), t).intersect(o, d)
    for tt in (t, t.astype(np.int32), t.astype(np.uint32)):
        vv = v.copy()
        before_v, before_t = sys.getrefcount(vv), sys.getrefcount(tt)
        s = frusta.Scene(vv, tt)
        assert sys.getrefcount(vv) == before_v + 1 and sys.getrefcount(tt) == before_t
        tt_copy = tt.copy()
        tt[:] = len(vv) + 5  # the caller's triangles may change: the scene has its own
        h = s.intersect(o, d)
        assert np.array_equal(h.prim, ref.prim) and np.array_equal(h.t, ref.t)
        tt[:] = tt_copy
        s.close()
        assert sys.getrefcount(vv) == before_v
    # a strided or float64 array is copied: the scene holds no reference to it
    wide = np.zeros((len(v), 4), np.float32)
    wide[:, :3] = v
    before = sys.getrefcount(wide)
    s = frusta.Scene(wide[:, :3], t)
    assert sys.getrefcount(wide) == before
    assert np.array_equal(s.intersect(o, d).prim, ref.prim)
    # the vertices outlive the name the caller gave them
    s = frusta.Scene(v.copy(), t)
    gc.collect()
    assert np.array_equal(s.intersect(o, d).prim, ref.prim)


# ---- bad input ---------------------------------------------------------------------

def test_bad_input_raises():
    v, t = sphere_mesh(8, 16)
    s = frusta.Scene(v, t)
    o = np.zeros((4, 3), dtype=np.float32)
    d = np.ones((4, 3), dtype=np.float32)
    with pytest.raises(TypeError, match="float"):
        s.intersect(o.astype(np.int32), d)
    with pytest.raises(TypeError):
        s.intersect(np.array(["a", "b", "c"]), d)
    with pytest.raises(ValueError, match=r"\(\.\.\., 3\)"):
        s.intersect(np.zeros((4, 2), dtype=np.float32), d)
    with pytest.raises(ValueError, match="same shape"):
        s.intersect(o[:3], d)
    nan = d.copy()
    nan[2, 1] = np.nan
    with pytest.raises(ValueError, match="ray 2"):
        s.intersect(o, nan)
    with pytest.raises(ValueError, match="ray 2"):
        s.occluded(o, nan)
    with pytest.raises(ValueError, match="ray 2"):
        s.intersect_all(o, nan)
    with pytest.raises(ValueError, match="tnear is NaN"):
        s.intersect(o, d, tnear=float("nan"))
    with pytest.raises(ValueError, match="one value per ray"):
        s.intersect(o, d, tfar=np.ones(3))
    with pytest.raises(ValueError, match="max_hits"):
        s.intersect_all(o, d, max_hits=-1)
    with pytest.raises(ValueError, match="none of"):
        s.trace_mode = "fastest"
    with pytest.raises(ValueError, match="vertex 9"):
        frusta.Scene(v, np.array([[0, 1, 9999]]))
    with pytest.raises(ValueError, match="not finite"):
        frusta.Scene(np.full((3, 3), np.nan), np.array([[0, 1, 2]]))
    with pytest.raises(ValueError):
        frusta.Scene(v, np.array([[0.5, 1, 2]]))
    strided = np.zeros((4, 6), dtype=np.float32)[:, ::2]  # non-contiguous: read through a copy
    assert s.intersect(strided, d).t.shape == (4,)
    s.close()
    with pytest.raises(ValueError, match="closed"):
        s.intersect(o, d)
    s.close()  # twice is fine
    assert "closed" in repr(s)


def test_close_while_tracing_raises():
    s = frusta.Scene.builtin()
    o, d = random_rays(1 << 22, 10, size=5.0)
    frusta.set_threads(1)
    err = []

    def run():
        try:
            s.intersect(o, d)
        except Exception as e:  # noqa: BLE001
            err.append(e)

    x = threading.Thread(target=run)
    x.start()
    time.sleep(0.05)
    with pytest.raises(RuntimeError, match="being traced"):
        s.close()
    x.join()
    frusta.set_threads(0)
    assert not err
    s.close()


def test_context_manager_and_repr():
    v, t = sphere_mesh(4, 8)
    with frusta.Scene(v, t) as s:
        assert "triangles" in repr(s)
        assert s.vertices.shape == v.shape and s.triangles.shape == t.shape
    with pytest.raises(ValueError):
        s.bounds


# ---- multi-frusta calls -------------------------------------------------------------

def test_intersect_camera_equals_rays():
    s = frusta.Scene.builtin()
    eye, at, up = (0.0, 3.0, 9.0), (0.0, 0.5, 0.0), (0.0, 1.0, 0.0)
    h, d = s.intersect_camera(eye, at, up, 50.0, 203, 117, directions=True)
    assert h.t.shape == (117, 203) and d.shape == (117, 203, 3)
    np.testing.assert_allclose(np.linalg.norm(d, axis=-1), 1, rtol=1e-6)
    o = np.broadcast_to(np.float32(eye), d.shape).copy()
    g = s.intersect(o, d)
    both_miss = np.isinf(g.t) & np.isinf(h.t)
    both_hit = np.isfinite(g.t) & np.isfinite(h.t)
    gt, ht = np.where(both_hit, g.t, 0), np.where(both_hit, h.t, 0)
    close = both_hit & (np.abs(gt - ht) <= 1e-4 * np.maximum(1, np.abs(gt)))
    assert (both_miss | close).mean() > 0.999
    assert np.isfinite(h.t).mean() > 0.3
    same = g.prim == h.prim
    assert same.mean() > 0.999
    np.testing.assert_allclose(h.normal[same], g.normal[same], rtol=1e-5, atol=1e-6)
    bare = s.intersect_camera(eye, at, up, 50.0, 203, 117, normals=False)
    assert bare.normal is None
    np.testing.assert_array_equal(bare.t, h.t)
    np.testing.assert_array_equal(bare.prim, h.prim)
    with pytest.raises(ValueError, match="field of view"):
        s.intersect_camera(eye, at, up, 0.0, 8, 8)
    with pytest.raises(ValueError, match="empty or too large"):
        s.intersect_camera(eye, at, up, 50.0, 0, 8)
    with pytest.raises(ValueError, match="3 finite"):
        s.intersect_camera((0, np.nan, 0), at, up, 50.0, 8, 8)


def camera_hit_points(s, width, height):
    """The points a camera over the built-in scene sees, row by row."""
    eye = (0.0, 3.0, 9.0)
    h, d = s.intersect_camera(eye, (0.0, 0.5, 0.0), (0.0, 1.0, 0.0), 50.0, width, height, directions=True)
    hit = np.isfinite(h.t)
    return (np.float32(eye) + h.t[..., None] * d)[hit].astype(np.float32)


def test_occluded_point_light_equals_rays():
    s = frusta.Scene.builtin()
    p = camera_hit_points(s, 256, 192)
    light = np.float32([2.0, 6.0, 3.0])
    lo, hi = s.bounds
    eps = 1e-5 * float(np.linalg.norm(hi - lo))
    occ = s.occluded_point_light(p, light)
    v = p - light
    dist = np.linalg.norm(v, axis=1)
    o = np.broadcast_to(light, p.shape).copy()
    ref = s.occluded(o, (v / dist[:, None]).astype(np.float32), (1e-4 * dist).astype(np.float32),
                     (dist - eps).astype(np.float32))
    assert 0.05 < occ.mean() < 0.95
    assert (occ != ref).sum() <= len(p) // 1000
    with pytest.raises(ValueError, match="point 1"):
        s.occluded_point_light(np.array([[0, 0, 0], [np.inf, 0, 0]], np.float32), light)
    many = np.zeros((100000, 3), np.float32)  # checked chunk by chunk on the threads: the first bad one counts
    many[90000, 2], many[70001, 1] = np.nan, -np.inf
    for call in (lambda q: s.occluded_point_light(q, light),
                 lambda q: s.visibility_area_light(q, light, (1.0, 0.0, 0.0), (0.0, 0.0, 1.0))):
        with pytest.raises(ValueError, match="point 70001 "):
            call(many)
    with pytest.raises(ValueError, match="eps"):
        s.occluded_point_light(p, light, eps=-1.0)


def test_visibility_area_light():
    s = frusta.Scene.builtin()
    p = camera_hit_points(s, 128, 96)
    corner, e1, e2 = (-2.0, 8.0, -2.0), (4.0, 0.0, 0.0), (0.0, 0.0, 4.0)
    v16 = s.visibility_area_light(p, corner, e1, e2)
    assert v16.shape == (len(p),) and v16.dtype == np.float32
    assert ((v16 * 16) % 1 == 0).all() and 0 < v16.mean() < 1 and ((v16 > 0) & (v16 < 1)).any()
    v64 = s.visibility_area_light(p, corner, e1, e2, samples=64)
    assert np.abs(v64 - v16).mean() < 0.1  # the same light, more samples
    # a point far above everything sees the whole light; one under the floor none
    tops = s.visibility_area_light(np.array([[0, 7.9, 0], [0, -50, 0]], np.float32), corner, e1, e2)
    assert tops[0] == 1.0
    with pytest.raises(ValueError, match="multiple of 16"):
        s.visibility_area_light(p, corner, e1, e2, samples=10)
    with pytest.raises(ValueError, match="point 0"):
        s.visibility_area_light(np.full((2, 3), np.nan, np.float32), corner, e1, e2)


# ---- rendering ---------------------------------------------------------------------

def read_pfm(path):
    with open(path, "rb") as f:
        assert f.readline().strip() == b"PF"
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        v = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4").reshape(h, w, 3)
    return v[::-1]  # rows are stored bottom to top


@pytest.mark.parametrize("shade,spp", [("eyelight", 0), ("normals", 0), ("shadows", 0), ("softshadow", 16),
                                       ("softshadow", 32), ("whitted", 0), ("ao", 32), ("path", 4)])
def test_render_equals_the_command(tmp_path, shade, spp):
    command = os.environ.get("FRUSTA_BIN")
    if not command or not os.path.exists(command):
        pytest.skip("FRUSTA_BIN names no frusta command")
    out = tmp_path / "c.pfm"
    flags = ["--spp", str(spp)] if shade in ("path", "ao") else []
    if shade == "softshadow":
        flags = ["--light-samples", str(spp)]
    subprocess.run([command, "render", "--builtin", "--shade", shade, "--size", "96x64", "--out", str(out)] + flags,
                   check=True, capture_output=True)
    want = read_pfm(out)
    scene = frusta.Scene.builtin()
    got = scene.render(96, 64, shade, spp=spp or 16, display=False)
    assert got.rgb.shape == (64, 96, 3)
    np.testing.assert_array_equal(got.rgb, want)
    assert got.spp == {"eyelight": 1, "normals": 1, "shadows": 1, "whitted": 1}.get(shade, spp)


def test_render_path_options_equal_the_command(tmp_path):
    command = os.environ.get("FRUSTA_BIN")
    if not command or not os.path.exists(command):
        pytest.skip("FRUSTA_BIN names no frusta command")
    out = tmp_path / "p.pfm"
    subprocess.run([command, "render", "--builtin=materials", "--shade", "path", "--size", "64x48", "--spp", "3",
                    "--sampler", "sobol", "--seed", "7", "--max-depth", "5", "--aperture", "0.05", "--focus", "9",
                    "--env-color", "0.5,0.6,0.7", "--env-intensity", "2", "--env-rotate", "30", "--out", str(out)],
                   check=True, capture_output=True)
    got = frusta.Scene.builtin("materials").render(64, 48, "path", spp=3, sampler="sobol", seed=7, max_depth=5,
                                                   aperture=0.05, focus=9.0, env_color=(0.5, 0.6, 0.7),
                                                   env_intensity=2.0, env_rotate=30.0, display=False)
    np.testing.assert_array_equal(got.rgb, read_pfm(out))
    other = frusta.Scene.builtin("materials").render(64, 48, "path", spp=3, sampler="sobol", seed=8, max_depth=5,
                                                     aperture=0.05, focus=9.0, env_color=(0.5, 0.6, 0.7),
                                                     env_intensity=2.0, env_rotate=30.0, display=False)
    assert not np.array_equal(got.rgb, other.rgb)  # the seed is the image's
    with pytest.raises(ValueError, match="sampler"):
        frusta.Scene.builtin().render(8, 8, "path", sampler="halton")
    with pytest.raises(ValueError, match="max_depth"):
        frusta.Scene.builtin().render(8, 8, "path", max_depth=99)


SCENE_OBJ = """mtllib box.mtl
v -4 0 -4
v 4 0 -4
v 4 0 4
v -4 0 4
v 0 0.2 0
v 1 0.2 0
v 0 1.8 0
v 0 0.2 1
usemtl floor
f 1 3 2
f 1 4 3
usemtl statue
f 5 6 7
f 5 7 8
f 5 8 6
f 6 8 7
"""

SCENE_JSON = """{
  "meshes": [{"file": "box.obj"}],
  "materials": {"statue": {"type": "metal", "preset": "gold", "roughness": 0.3}},
  "camera": {"eye": [3, 2.5, 4], "at": [0, 0.6, 0], "fov": 40},
  "environment": {"color": [0.4, 0.5, 0.7], "intensity": 1.5},
  "lights": {"point": {"position": [2, 5, 2], "intensity": [40, 40, 40]}},
  "render": {"shade": "path", "size": [40, 30], "spp": 3, "sampler": "sobol", "seed": 5, "max_depth": 6}
}"""


def test_render_a_scene_file_as_the_command(tmp_path):
    command = os.environ.get("FRUSTA_BIN")
    if not command or not os.path.exists(command):
        pytest.skip("FRUSTA_BIN names no frusta command")
    (tmp_path / "box.obj").write_text(SCENE_OBJ)
    (tmp_path / "box.mtl").write_text("newmtl floor\nKd 0.7 0.7 0.7\nnewmtl statue\nKd 0.2 0.2 0.9\n")
    (tmp_path / "scene.json").write_text(SCENE_JSON)
    out = tmp_path / "c.pfm"
    subprocess.run([command, "render", str(tmp_path / "scene.json"), "--out", str(out)], check=True,
                   capture_output=True)
    scene = frusta.Scene.load(str(tmp_path / "scene.json"))
    got = scene.render(display=False)  # everything from the file: size, shade, camera, lights, materials
    assert got.rgb.shape == (30, 40, 3) and got.spp == 3
    np.testing.assert_array_equal(got.rgb, read_pfm(out))
    plain = tmp_path / "plain.json"  # the same without the gold: the MTL's blue Lambert
    plain.write_text(SCENE_JSON.replace('"materials": {"statue": {"type": "metal", "preset": "gold", "roughness": 0.3}},', ""))
    assert not np.array_equal(frusta.Scene.load(str(plain)).render(display=False).rgb, got.rgb)
    quick = scene.render(spp=1, shade="eyelight")  # arguments win over the file
    assert quick.spp == 1 and quick.rgb.shape == (30, 40, 3)


def test_save_image(tmp_path):
    rgb = np.random.default_rng(3).random((12, 20, 3)).astype(np.float32)
    for ext in ("png", "exr", "pfm"):
        frusta.save_image(str(tmp_path / f"a.{ext}"), rgb)
        assert (tmp_path / f"a.{ext}").stat().st_size > 0
    raw = (tmp_path / "a.pfm").read_bytes()  # a header, then the rows bottom first
    assert np.array_equal(np.frombuffer(raw[-20 * 3 * 4:], "<f4").reshape(20, 3), rgb[0])
    with pytest.raises(ValueError):
        frusta.save_image(str(tmp_path / "a.bmp"), rgb)
    with pytest.raises(ValueError):
        frusta.save_image(str(tmp_path / "b.png"), rgb[:, :, :2])
    with pytest.raises(OSError):
        frusta.save_image(str(tmp_path / "no" / "dir.png"), rgb)
    assert not (tmp_path / "a.bmp").exists()


def test_render_options_and_errors():
    scene = frusta.Scene.builtin()
    a = scene.render(48, 32, "eyelight", eye=(0, 3, 9), at=(0, 0.5, 0), fov=40)
    b = scene.render(48, 32, "eyelight")
    assert not np.array_equal(a.rgb, b.rgb)  # another view
    assert (a.depth < 1e29).mean() > 0.3 and a.normal.shape == (32, 48, 3)
    p = scene.render(48, 32, "path", spp=2, denoise=True)
    assert p.rgb.max() < 1.0 and p.spp == 2  # display values through the filmic curve
    lin = scene.render(48, 32, "path", spp=2, display=False, exposure=3.0)
    assert lin.rgb.max() > 0
    lit = scene.render(48, 32, "shadows", light=(0, 50, 0))
    assert not np.array_equal(lit.rgb, scene.render(48, 32, "shadows").rgb)
    flat = frusta.Scene.builtin(smooth=0).render(48, 32, "eyelight")
    assert not np.array_equal(flat.rgb, b.rgb)  # shading normals, as frusta render --smooth 0
    with pytest.raises(ValueError, match="smooth"):
        frusta.Scene.builtin(smooth=400)
    img8 = frusta.to_srgb8(p.rgb)
    assert img8.dtype == np.uint8 and img8.shape == (32, 48, 3)
    with pytest.raises(ValueError, match="none of"):
        scene.render(8, 8, "raytraced")
    with pytest.raises(ValueError, match="multiples of 16"):
        scene.render(8, 8, "ao", spp=20)
    with pytest.raises(ValueError, match="eye and at"):
        scene.render(8, 8, eye=(0, 0, 1))
    with pytest.raises(ValueError, match="width 0"):
        scene.render(0, 8)
    with pytest.raises(ValueError, match="size"):
        scene.render(shade="eyelight")  # no size: the built-in scene has no scene file to give one
    with pytest.raises(OSError):
        scene.render(8, 8, "path", environment="/nonexistent/sky.hdr")
