#!/usr/bin/env python3
"""`planes` on a point set that carries a planar segmentation of its own (issue 18's real-data
check): CGAL's building.ply (libcgal-demo's data.tar.gz, data/points_3/building.ply: 100k points
with normals and `segment_index`, 19 planes, -1 elsewhere). Per labelled segment, the best IoU
with a region of some scale, with a persistent component (>= 5 levels) at its representative
level, and with the labels of `segment --min-persistence 5`; a segment is found at IoU >= 0.8.
Runs the defaults and the thesis' method (max_step=0, max_rms=0, merge_rms=0), or the keyword sets given.

    PYTHONPATH=build/python /usr/bin/python3 bench/python/bench_planes_labelled_scan.py \\
        path/to/building.ply [--label segment_index] ["dict(angle=10)" ...]
"""
import argparse
import time

import numpy as np

import scalespace as ss


def best_iou(sets, gt, segments):
    best = {s: 0.0 for s in segments}
    sizes = {s: int((gt == s).sum()) for s in segments}
    for pts in sets:
        labels, counts = np.unique(gt[pts], return_counts=True)
        for s, k in zip(labels, counts):
            if s >= 0:
                best[s] = max(best[s], k / (len(pts) + sizes[s] - k))
    return best


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("cloud")
    parser.add_argument("--label", default="segment_index")
    parser.add_argument("runs", nargs="*", help="keyword sets for scalespace.planes, as Python")
    args = parser.parse_args()
    cloud = ss.read(args.cloud)
    gt = cloud.attributes[args.label].astype(int)
    segments = [int(s) for s in np.unique(gt) if s >= 0]
    runs = [(r, eval(r)) for r in args.runs] or [
        ("defaults", {}), ("thesis", dict(max_step=0, max_rms=0, merge_rms=0))]
    for name, kw in runs:
        start = time.time()
        planes = ss.planes(cloud.points, cloud.normals, **kw)
        seconds = time.time() - start
        m = planes.membership
        regions = [np.nonzero(m[j] == c)[0] for j in range(m.shape[0])
                   for c in np.unique(m[j][m[j] >= 0])]
        comp = planes.components
        persistent = [np.nonzero(m[comp["representative_level"][i]] == c)[0]
                      for i, c in enumerate(comp["id"]) if comp["persistence"][i] >= 5]
        labels = planes.labels_by_persistence(5)
        seg = [np.nonzero(labels == v)[0] for v in np.unique(labels[labels >= 0])]
        found = [sum(v >= 0.8 for v in best_iou(sets, gt, segments).values())
                 for sets in (regions, persistent, seg)]
        per_region = best_iou(regions, gt, segments)
        covered = {s: float(np.mean((m[:, gt == s] >= 0).any(axis=0))) for s in segments}
        print(f"{name}: {len(segments)} segments found as region {found[0]}, as component "
              f"{found[1]}, in labels {found[2]}; {len(comp['id'])} components "
              f"({int((comp['planar'] == 0).sum())} flagged); {seconds:.1f} s")
        print("  segment: points, best region IoU, share of its points in a region at some scale: "
              + ", ".join(f"{s}: {int((gt == s).sum())} {per_region[s]:.2f} {covered[s]:.2f}"
                          for s in segments))


if __name__ == "__main__":
    main()
