#!/usr/bin/env python3
"""`cylinders` from Python on the poles of `scalespace generate poles` (core/PipeScene.hpp):
four vertical poles (radius 0.05, 0.2, 0.5 seen from one side, and 0.12; each with a band the
scanner missed) and a box 1 x 0.6 x 0.8 standing on an 8 x 8 m floor, 216k points, no normals
(estimated as the CLI does), Gaussian noise of 0, 2.5e-4, 5e-4 and 1e-3 of the diagonal. Per run:
each pole's best IoU with a component at its representative level (found at >= 0.8) and its
persistence, and the false tubes (components whose points lie mostly on the box or the floor)
with their persistence. Runs the defaults and the keyword sets given (as `scalespace.cylinders`
takes them). bench_cylinders --scene poles scores the same scene per region, next to RANSAC.

    PYTHONPATH=build/python SCALESPACE_CLI=build/scalespace /usr/bin/python3 \\
        bench/python/bench_cylinders_box_and_poles.py [--seed S] ["dict(max_section_shape=0.2)" ...]
"""
import argparse
import os
import subprocess
import tempfile
import time

import numpy as np

import scalespace as ss

POLE_COUNT = 4


def scene(noise, seed, points=216000):
    """Points and labels (the pole's id; -1 on the box and the floor), from the CLI's generator."""
    cli = os.environ.get("SCALESPACE_CLI", "scalespace")
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "poles.ply")
        subprocess.run([cli, "generate", "poles", "-n", str(points), "--noise", str(noise),
                        "--seed", str(seed), "-q", "-o", path], check=True)
        cloud = ss.read(path)
    return cloud.points, cloud.attributes["gt_pipe"].astype(int)


def score(result, labels):
    poles, false = {}, []
    for comp in result.components:
        at = result.labels_at_level(comp["representative_level"]) == comp["id"]
        counts = np.bincount(labels[at] + 1, minlength=POLE_COUNT + 1)
        holder = int(counts.argmax()) - 1
        if holder < 0:
            false.append((comp["persistence"], round(comp["radius"], 3)))
            continue
        iou = (at & (labels == holder)).sum() / (at | (labels == holder)).sum()
        if iou > poles.get(holder, (0, 0))[0]:
            poles[holder] = (iou, comp["persistence"])
    return poles, false


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=3)
    parser.add_argument("settings", nargs="*", help='keyword sets, e.g. "dict(max_section_shape=0.2)"')
    args = parser.parse_args()
    settings = [{}] + [eval(s, {"dict": dict}) for s in args.settings]
    for noise in [0, 2.5e-4, 5e-4, 1e-3]:
        noisy, labels = scene(noise, args.seed)
        for kwargs in settings:
            start = time.perf_counter()
            result = ss.cylinders(noisy, **kwargs)
            seconds = time.perf_counter() - start
            poles, false = score(result, labels)
            found = sum(1 for iou, _ in poles.values() if iou >= 0.8)
            print(f"noise {noise:g} {kwargs or 'defaults'}: poles found {found}/{POLE_COUNT}, "
                  f"false tubes {len(false)} (persistence >= 2: "
                  f"{sum(1 for p, _ in false if p >= 2)}), {seconds:.1f} s")
            for i in sorted(poles):
                print(f"    pole {i} IoU {poles[i][0]:.3f} persistence {poles[i][1]}")
            for persistence, radius in false:
                print(f"    false on the box or floor: radius {radius}, persistence {persistence}")


if __name__ == "__main__":
    main()
