#!/usr/bin/python3
"""What reorder=True buys on random rays, and what the same order buys Embree.

A million random rays per scene (origins in the scene's box, uniform
directions), closest hits without normals, 2 threads, best of REPEAT
alternating calls: frusta's arrays as given and with reorder=True (the
ordering timed with the call), and both tracers on the same rays sorted
beforehand, outside the timing, by the key reorder=True uses (the cell of a
16x16x16 grid over the scene's box along a Morton curve; stable). Embree is
called as in bench/python_vs_embree.py (packet16, incoherent flag: its
fastest way on these rays there).

usage: bench/python_reorder.py [--repeat 5] [scenes...]
Writes bench/results/python-reorder.txt and prints a markdown table.
"""
import argparse
import os
import sys
import tempfile

import numpy as np

import frusta

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import python_vs_embree as pve  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def cell_order(o, lo, hi):
    q = ((o - lo) / (hi - lo) * 16).clip(0, 15).astype(np.int64)

    def spread(x):
        return (x & 1) | (x & 2) << 2 | (x & 4) << 4 | (x & 8) << 6

    return np.argsort(spread(q[:, 0]) | spread(q[:, 1]) << 1 | spread(q[:, 2]) << 2, kind="stable")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("scenes", nargs="*", default=["kitchen", "conference", "sibenik", "dragon", "hairball"])
    a = ap.parse_args()
    frusta.set_threads(a.threads)
    lines = pve.results_header("bench/python_reorder.py")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        lib = pve.embree_library(tmp)
        for name in a.scenes:
            fs = frusta.Scene.load(os.path.join(ROOT, "..", "shared", "scenes", name, f"{name}.ply.zst"))
            em = pve.Embree(lib, fs.vertices, fs.triangles, a.threads)
            lo, hi = fs.bounds
            rng = np.random.default_rng(1)
            o = rng.uniform(lo, hi, (1 << 20, 3)).astype(np.float32)
            d = rng.normal(size=(1 << 20, 3)).astype(np.float32)
            p = cell_order(o, lo, hi)
            so, sd = np.ascontiguousarray(o[p]), np.ascontiguousarray(d[p])
            runs = {"frusta": lambda: fs.intersect(o, d, normals=False),
                    "frusta_reorder": lambda: fs.intersect(o, d, normals=False, reorder=True),
                    "frusta_sorted": lambda: fs.intersect(so, sd, normals=False),
                    "embree": lambda: em.intersect(o, d, False, True),
                    "embree_sorted": lambda: em.intersect(so, sd, False, True)}
            mr = {k: len(o) / t / 1e6 for k, t in pve.timed(runs, a.repeat).items()}
            line = f"scene={name} rays={len(o)} threads={a.threads} " + " ".join(f"{k}={v:.2f}" for k, v in mr.items())
            print(line, flush=True)
            lines.append(line)
            rows.append((name, mr))
            em.close()
            fs.close()
    with open(os.path.join(ROOT, "bench", "results", "python-reorder.txt"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n| scene | frusta as given | reorder=True | speed-up | Embree | frusta reorder / Embree "
          "| sorted beforehand: frusta | Embree | frusta / Embree |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, m in rows:
        print(f"| {name} | {m['frusta']:.1f} | {m['frusta_reorder']:.1f} | {m['frusta_reorder'] / m['frusta']:.2f} "
              f"| {m['embree']:.1f} | {m['frusta_reorder'] / m['embree']:.2f} | {m['frusta_sorted']:.1f} "
              f"| {m['embree_sorted']:.1f} | {m['frusta_sorted'] / m['embree_sorted']:.2f} |")


if __name__ == "__main__":
    main()
