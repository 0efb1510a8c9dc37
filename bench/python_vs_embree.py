#!/usr/bin/python3
"""frusta's Python module against Embree 3 called from Python, in one process.

Embree is called as embreex and pyembree call it (rtcIntersect1M /
rtcOccluded1M on ray records packed from numpy arrays, the rays split over
threads; bench/embree_python.c through ctypes, packing in C), and also with
its 16-wide packets; for each workload Embree's best of those and of its two
coherence flags counts, with its high-quality build. frusta runs in its
trace modes (auto, single, hybrid16, raystream) from the same arrays, and
through its multi-frusta calls where they apply; its fastest call counts.
Both return t, triangle, u and v (frusta's calls without normals, as
Embree's hits are read here; its camera call with them fetches each hit
triangle). Workloads per scene:
1024x1024 camera rays (frusta's camera call, and the same rays as arrays, row
by row), shadow segments between their hits and the scene's point light
(frusta's point-light call, and arrays from the light and to it), and 1M
random rays (origins in the scene's box, uniform directions; frusta's arrays
as given and with reorder=True). Best of REPEAT
alternating calls each. Each frusta call's answers are compared with Embree's
on the same rays by the rule of docs/rayfile.md; for shadows, the
disagreements whose segment meets a surface within the rule's tolerance of
its ends are counted apart.

usage: bench/python_vs_embree.py [--repeat 4] [--threads 2] [--rays 1000000] [scenes...]
Writes bench/results/python-vs-embree.txt and prints a markdown table.
"""
import argparse
import ctypes
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "build", "python"))
import frusta  # noqa: E402

# The scenes' cameras and point lights (../shared/scenes/README.md).
VIEWS = {
    "conference": ((1400, 400, -700), (-500, 150, 300), (0, 1, 0), 60, (300, 550, -200)),
    "dragon": ((-0.12, 0.20, 0.33), (-0.0059, 0.125, -0.0046), (0, 1, 0), 40, (0.20, 0.45, 0.35)),
    "kitchen": ((3.75, 2.30, 3.60), (3.4365, 1.8802, 2.7482), (-0.127, 0.907, -0.4005), 40, (2.25, 2.00, 1.00)),
    "sibenik": ((-18, -11, 0), (10, -8, 0), (0, 1, 0), 60, (-5, 0, 0)),
}


def embree_library(tmp):
    so = os.path.join(tmp, "libembree_python.so")
    subprocess.run(["cc", "-O2", "-fPIC", "-shared", "-fopenmp", os.path.join(ROOT, "bench", "embree_python.c"),
                    "-lembree3", "-o", so], check=True)
    lib = ctypes.CDLL(so)
    p, sz, i = ctypes.c_void_p, ctypes.c_size_t, ctypes.c_int
    lib.ebp_scene_new.restype = p
    lib.ebp_scene_new.argtypes = [p, sz, p, sz]
    lib.ebp_scene_free.argtypes = [p]
    lib.ebp_intersect.argtypes = [p, p, p, sz, p, p, p, p, p, p, i, i, i]
    lib.ebp_occluded.argtypes = [p, p, p, sz, p, p, p, i, i, i]
    return lib


class Embree:
    def __init__(self, lib, v, t, threads):
        self.lib, self.threads = lib, threads
        v = np.ascontiguousarray(v, dtype=np.float32)
        t = np.ascontiguousarray(t, dtype=np.uint32)
        self.s = lib.ebp_scene_new(v.ctypes.data, len(v), t.ctypes.data, len(t))

    @staticmethod
    def _ptr(a):
        return None if a is None else a.ctypes.data

    def intersect(self, o, d, coherent, packet16):
        n = len(o)
        t, prim = np.empty(n, np.float32), np.empty(n, np.uint32)
        u, v = np.empty(n, np.float32), np.empty(n, np.float32)
        self.lib.ebp_intersect(self.s, o.ctypes.data, d.ctypes.data, n, None, None, t.ctypes.data, prim.ctypes.data,
                               u.ctypes.data, v.ctypes.data, coherent, packet16, self.threads)
        return t

    def occluded(self, o, d, tnear, tfar, coherent, packet16):
        occ = np.empty(len(o), np.uint8)
        self.lib.ebp_occluded(self.s, o.ctypes.data, d.ctypes.data, len(o), self._ptr(tnear), self._ptr(tfar),
                              occ.ctypes.data, coherent, packet16, self.threads)
        return occ.astype(bool)

    def close(self):
        self.lib.ebp_scene_free(self.s)


def camera(view, w, h):
    eye, look, up, fov, _ = (np.asarray(x, dtype=np.float64) for x in view)
    fwd = look - eye
    fwd /= np.linalg.norm(fwd)
    right = np.cross(fwd, up)
    right /= np.linalg.norm(right)
    upv = np.cross(right, fwd)
    half = np.tan(np.radians(float(fov)) / 2)
    x = ((np.arange(w) + 0.5) / w * 2 - 1) * half * w / h
    y = (1 - (np.arange(h) + 0.5) / h * 2) * half
    d = fwd + x[None, :, None] * right + y[:, None, None] * upv
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    o = np.broadcast_to(eye, d.shape)
    return (np.ascontiguousarray(o.reshape(-1, 3), dtype=np.float32),
            np.ascontiguousarray(d.reshape(-1, 3), dtype=np.float32))


def tile_order(w, h):
    """Pixel indices of a w x h image (multiples of 16) in 16x16 tiles of
    4x4 blocks."""
    i = np.arange(w * h).reshape(h // 16, 4, 4, w // 16, 4, 4)  # tile row, block row, row; tile col, block col, col
    return i.transpose(0, 3, 1, 4, 2, 5).reshape(-1)


def agree_hits(t1, t2):
    """docs/rayfile.md: both miss, or both hit at t within 1e-4 * max(1, |t|)."""
    m1, m2 = np.isinf(t1), np.isinf(t2)
    a, b = np.where(m1 | m2, 0, t1), np.where(m1 | m2, 0, t2)
    return (m1 & m2) | (~m1 & ~m2 & (np.abs(a - b) <= 1e-4 * np.maximum(1, np.abs(a))))


def range_end_hits(fs, o, d, tnear, tfar):
    """Which of these segments' nearest surface lies within 1e-4 * max(1, t)
    of their tnear or tfar: there the rule excuses a different occlusion."""
    tol = lambda t: 1e-4 * np.maximum(1, np.abs(t))  # noqa: E731
    t = fs.intersect(o, d, np.maximum(0, tnear - tol(tnear)).astype(np.float32)).t
    t = np.where(np.isinf(t), 1e30, t)
    return (np.abs(t - tnear) <= tol(t)) | (np.abs(t - tfar) <= tol(t))


def timed(runs, repeat):
    """The best time of each run over repeat rounds, the runs alternating."""
    best = {k: float("inf") for k in runs}
    for _ in range(repeat):
        for k, fn in runs.items():
            t0 = time.perf_counter()
            fn()
            best[k] = min(best[k], time.perf_counter() - t0)
    return best


def results_header(script):
    """A results file's first lines: the commit and the command."""
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    return [f"# commit {commit}", f"# {script} " + " ".join(sys.argv[1:])]


def embree_variants(call):
    """Embree's four ways from Python: rtcIntersect1M / rtcOccluded1M or
    16-wide packets, each with the coherent and the incoherent flag."""
    return {("packet16" if p16 else "1M") + ("/coherent" if c else "/incoherent"):
            (lambda c=c, p16=p16: call(c, p16)) for c in (1, 0) for p16 in (0, 1)}


def in_modes(fs, calls):
    """The arrays calls in frusta's default trace mode (auto) and in the
    others that lead somewhere (single, hybrid16, raystream), as Embree's
    ways and flags are all tried."""
    def in_mode(mode, fn):
        fs.trace_mode = mode
        try:
            return fn()
        finally:
            fs.trace_mode = "auto"

    out = dict(calls)
    for mode in ("single", "hybrid16", "raystream"):
        for k, fn in calls.items():
            out[f"{k} in {mode} mode"] = lambda fn=fn, mode=mode: in_mode(mode, fn)
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=4)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--rays", type=int, default=1 << 20)
    ap.add_argument("--size", type=int, default=1024)
    ap.add_argument("scenes", nargs="*", default=["conference", "dragon"])
    a = ap.parse_args()
    frusta.set_threads(a.threads)
    lines = results_header("bench/python_vs_embree.py")
    table = []
    with tempfile.TemporaryDirectory() as tmp:
        lib = embree_library(tmp)
        for name in a.scenes:
            path = os.path.join(ROOT, "..", "shared", "scenes", name, f"{name}.ply.zst")
            fs = frusta.Scene.load(path)
            em = Embree(lib, fs.vertices, fs.triangles, a.threads)
            view = VIEWS[name]
            eye, at, up, fov, light = view
            # camera rays: frusta's camera call (multi-frusta, rays made on the
            # fly) and the same rays from arrays; Embree from those arrays
            hits, d = fs.intersect_camera(eye, at, up, fov, a.size, a.size, directions=True)
            d = np.ascontiguousarray(d.reshape(-1, 3))
            o = np.ascontiguousarray(np.broadcast_to(np.float32(eye), d.shape))
            t_cam = hits.t.reshape(-1)
            # shadow rays: the camera's hit points and the point light, from
            # the light (frusta's point-light call, and arrays) and from the
            # points (arrays), the same segments; the points in 4x4 blocks of
            # 16x16 tiles, the order a renderer keeps them in, for both
            order = tile_order(a.size, a.size)
            hit = np.isfinite(t_cam[order])
            oo, dd, tt = o[order][hit], d[order][hit], t_cam[order][hit]
            pts = np.ascontiguousarray((oo + tt[:, None] * dd).astype(np.float32))
            lo, hi = fs.bounds
            eps = np.float32(1e-5 * np.linalg.norm(hi - lo))
            L = np.float32(light)
            v = pts - L
            dist = np.linalg.norm(v, axis=1).astype(np.float32)
            from_l = (np.ascontiguousarray(np.broadcast_to(L, pts.shape)), np.ascontiguousarray(v / dist[:, None]),
                      np.ascontiguousarray(1e-4 * dist), np.ascontiguousarray(dist - eps))
            to_l = (pts, np.ascontiguousarray(-v / dist[:, None]), np.full(len(pts), eps, np.float32),
                    np.ascontiguousarray(dist * np.float32(1 - 1e-4)))
            rng = np.random.default_rng(1)
            ro = rng.uniform(lo, hi, (a.rays, 3)).astype(np.float32)
            rd = rng.normal(size=(a.rays, 3)).astype(np.float32)
            work = {
                "camera": ({"camera call": lambda: fs.intersect_camera(eye, at, up, fov, a.size, a.size,
                                                                       normals=False).t.reshape(-1),
                            "camera call with normals": lambda: fs.intersect_camera(eye, at, up, fov, a.size,
                                                                                    a.size).t.reshape(-1),
                            **in_modes(fs, {"arrays": lambda: fs.intersect(o, d, normals=False).t})},
                           embree_variants(lambda c, p16: em.intersect(o, d, c, p16)), len(o), agree_hits),
                "shadow": ({"point-light call": lambda: fs.occluded_point_light(pts, L, eps),
                            **in_modes(fs, {"arrays from the light": lambda: fs.occluded(*from_l),
                                            "arrays to the light": lambda: fs.occluded(*to_l)})},
                           {**{k + " from the light": fn for k, fn in
                               embree_variants(lambda c, p16: em.occluded(*from_l, c, p16)).items()},
                            **{k + " to the light": fn for k, fn in
                               embree_variants(lambda c, p16: em.occluded(*to_l, c, p16)).items()}},
                           len(pts), np.equal),
                "random": (in_modes(fs, {"arrays": lambda: fs.intersect(ro, rd, normals=False).t,
                                         "arrays reordered": lambda: fs.intersect(ro, rd, normals=False,
                                                                                  reorder=True).t}),
                           embree_variants(lambda c, p16: em.intersect(ro, rd, c, p16)), len(ro), agree_hits),
            }
            for wl, (f_runs, e_runs, n, same) in work.items():
                # answers: each frusta call against Embree on the same rays or segments
                ref = e_runs.get("1M/coherent")
                disagree, excused = {}, 0
                for k, fn in f_runs.items():
                    if wl == "shadow":
                        seg = to_l if "to the" in k else from_l
                        e = e_runs["1M/coherent " + ("to the light" if "to the" in k else "from the light")]()
                        bad = np.nonzero(~same(fn(), e))[0]
                        excused += int(range_end_hits(fs, *(np.ascontiguousarray(x[bad]) for x in seg)).sum())
                    else:
                        bad = np.nonzero(~same(fn(), ref()))[0]
                    disagree[k] = len(bad)
                best = timed({**{("frusta", k): fn for k, fn in f_runs.items()},
                              **{("embree", k): fn for k, fn in e_runs.items()}}, a.repeat)
                fk, ft = min(((k[1], t) for k, t in best.items() if k[0] == "frusta"), key=lambda x: x[1])
                ek, et = min(((k[1], t) for k, t in best.items() if k[0] == "embree"), key=lambda x: x[1])
                line = (f"scene={name} workload={wl} rays={n} threads={a.threads} frusta_mrays={n / ft / 1e6:.2f} "
                        f"frusta_call={fk.replace(' ', '_')} embree_mrays={n / et / 1e6:.2f} "
                        f"embree_mode={ek.replace(' ', '_')} ratio={et / ft:.2f} "
                        f"disagree={sum(disagree.values())} excused_at_range_ends={excused} "
                        + " ".join(f"{who}[{k.replace(' ', '_')}]={n / t / 1e6:.2f}" for (who, k), t in best.items()))
                print(line, flush=True)
                lines.append(line)
                table.append((name, wl, n / ft / 1e6, fk, n / et / 1e6, ek, et / ft, sum(disagree.values()),
                              excused, n * len(f_runs)))
            em.close()
            fs.close()
    os.makedirs(os.path.join(ROOT, "bench", "results"), exist_ok=True)
    with open(os.path.join(ROOT, "bench", "results", "python-vs-embree.txt"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n| scene | rays | frusta Mrays/s (fastest call) | Embree Mrays/s (fastest way) | frusta / Embree "
          "| answers that differ (at a range's end) |")
    print("|---|---|---|---|---|---|")
    for name, wl, fm, fk, emr, ek, ratio, dis, exc, n in table:
        ends = f" ({exc})" if wl == "shadow" else ""
        print(f"| {name} | {wl} | {fm:.1f} ({fk}) | {emr:.1f} ({ek}) | **{ratio:.2f}** | {dis}{ends} of {n} |")


if __name__ == "__main__":
    main()
