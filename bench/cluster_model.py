#!/usr/bin/env python3
"""Frame time of a cluster frame, modelled from this machine's measurements.

Reads bench/results/cluster_scaling.txt (bench/cluster_scaling.sh): the
tiles' render times on one core (kitchen, 1024x1024), the bytes a rank
sends rank 0 per pixel, and rank 0's post-processing time. Prints, for 4 to
256 nodes, the modelled frame time of 1080p soft shadows and of a 4K
path-traced frame at 1024 samples per pixel, on 10 and 100 Gbit/s links:

  T(N) = max(render / N + imbalance, gather) + last transfer + post

  render     tiles x mean tile time / cores per node
  imbalance  the last tile a thread takes (the tiles' 99th percentile):
             dealing is dynamic, so no rank waits longer than that
  gather     the pixels of the other N-1 ranks through rank 0's one link
             (it overlaps rendering: tiles come back as they finish)
  last       the last ranges' pixels, after the last tile
  post       rank 0's work after the gather (soft shadows: the filter
             and shading, parallel over its cores); 0 for path tracing

usage: bench/cluster_model.py [RESULTS]
"""
import re
import sys

CORES = 32  # a node: 32 cores, each as fast as one of this machine's
LINKS = {"10 Gbit/s": 10e9 / 8, "100 Gbit/s": 100e9 / 8}  # bytes per second
NODES = [4, 8, 16, 32, 64, 128, 256]
MEASURED_SPP = 4  # the path tiles were timed at this many samples


def read(path):
    text = open(path).read()
    tiles = {}
    for m in re.finditer(r"^## kitchen tiles, 1 thread\n((?:(?!##).*\n)*)", text, re.M):
        for line in m.group(1).splitlines():
            if line.startswith("tiles "):
                kv = dict(t.split("=", 1) for t in line.split()[1:])
                tiles[kv["workload"]] = {k: float(kv[k]) for k in ("count", "mean_ms", "p99_ms", "max_ms")}
    per_px = {}
    for shade in ("softshadow", "path"):
        # the 2-rank render: bytes sent over the pixels rank 1 rendered
        blocks = re.findall(r"^## kitchen render %s 2x1\n((?:(?!##).*\n)*)" % shade, text, re.M)
        line = [l for l in blocks[-1].splitlines() if l.startswith("cluster ")][0]
        kv = dict(t.split("=", 1) for t in line.split()[1:])
        worker_tiles = int(kv["rank_tiles"].split(",")[1])
        per_px[shade] = int(kv["bytes_sent"]) / (worker_tiles * 256.0)
    # rank 0's soft-shadow post-processing on one thread: a one-thread
    # render's time less a one-thread bench frame of the same rays
    r11 = float(re.search(r"^## kitchen render softshadow 1x1\n(?:(?!##).*\n)*?.* seconds=([0-9.]+)", text, re.M).group(1))
    b11 = re.search(r"^## kitchen tiles, 1 thread\n((?:(?!##).*\n)*)", text, re.M).group(1)
    frame = float(re.search(r"workload=soft16 .* seconds=([0-9.]+)", b11).group(1))
    post = r11 - frame
    return tiles, per_px, post  # core-seconds per 1024x1024 frame


def frame_time(n, tiles_count, tile_mean, tile_p99, px, bytes_px, link, post_core_s):
    render = tiles_count * tile_mean / (n * CORES)
    imbalance = tile_p99
    gather = px * bytes_px * (n - 1) / n / link
    last = CORES * 256 * bytes_px / link  # a range of one tile per core
    post = post_core_s / CORES
    t = max(render + imbalance, gather) + last + post
    bound = "gather" if gather > render + imbalance else "imbalance" if imbalance > render else "render"
    return t, render, gather, bound


def main():
    path = sys.argv[1] if len(sys.argv) > 1 else "bench/results/cluster_scaling.txt"
    tiles, per_px, post_core_s = read(path)
    soft, pt = tiles["soft16"], tiles["path"]
    print("Inputs (kitchen, one core of this machine): soft16 tile %.4f ms mean, %.4f ms p99; path tile %.3f ms mean, "
          "%.3f ms p99 at %d spp; bytes to rank 0 per pixel: softshadow %.1f, path %.1f; soft-shadow post-processing "
          "%.1f core-ms per megapixel; a node: %d cores."
          % (soft["mean_ms"], soft["p99_ms"], pt["mean_ms"], pt["p99_ms"], MEASURED_SPP, per_px["softshadow"],
             per_px["path"], post_core_s * 1e3 * 1e6 / (1024 * 1024), CORES))
    print()
    px = 1920 * 1080
    ntiles = (1920 // 16) * ((1080 + 15) // 16)
    post = post_core_s * px / (1024 * 1024)
    soft_args = (ntiles, soft["mean_ms"] * 1e-3, soft["p99_ms"] * 1e-3, px)
    one = ntiles * soft["mean_ms"] * 1e-3 / CORES + post / CORES
    print("1080p soft shadows (16 shadow rays per pixel, filtered; one node: %.1f ms), frame time in ms (frames/s); "
          "the last column if the workers filtered and shaded their tiles and sent 8-bit RGB (3 bytes per pixel):"
          % (one * 1e3))
    print()
    print("| nodes | " + " | ".join(LINKS) + " | 10 Gbit/s, 3 bytes per pixel | bound by |")
    print("|---|" + "---|" * len(LINKS) + "---|---|")
    for n in NODES:
        cells, bounds = [], []
        for name, link in LINKS.items():
            t, _, _, b = frame_time(n, *soft_args, per_px["softshadow"], link, post)
            cells.append("%.1f (%.0f)" % (t * 1e3, 1 / t))
            bounds.append(b)
        t, _, _, b = frame_time(n, *soft_args, 3.0, LINKS["10 Gbit/s"], 0.0)
        cells.append("%.1f (%.0f)" % (t * 1e3, 1 / t))
        bounds.append(b)
        print("| %d | %s | %s |" % (n, " | ".join(cells), " / ".join(bounds)))
    print()
    px = 3840 * 2160
    scale = 1024 / MEASURED_SPP
    print("4K path tracing at 1024 spp, frame time in s (parallel efficiency); the last column with tiles of 8x8 "
          "pixels (a quarter of the time each):")
    print()
    print("| nodes | " + " | ".join(LINKS) + " | 10 Gbit/s, 8x8 tiles | bound by |")
    print("|---|" + "---|" * len(LINKS) + "---|---|")
    for n in NODES:
        cells, bounds = [], []
        for side, links in ((16, LINKS), (8, {"10 Gbit/s": LINKS["10 Gbit/s"]})):
            ntiles = (3840 // side) * (2160 // side)
            k = scale * (side * side) / 256.0
            ideal = ntiles * pt["mean_ms"] * 1e-3 * k / CORES
            for name, link in links.items():
                t, _, _, b = frame_time(n, ntiles, pt["mean_ms"] * 1e-3 * k, pt["p99_ms"] * 1e-3 * k, px, per_px["path"],
                                        link, 0.0)
                cells.append("%.2f (%.0f%%)" % (t, 100 * ideal / n / t))
                bounds.append(b)
        print("| %d | %s | %s |" % (n, " | ".join(cells), " / ".join(bounds)))


if __name__ == "__main__":
    main()
