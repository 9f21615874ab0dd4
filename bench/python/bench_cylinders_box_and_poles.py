#!/usr/bin/env python3
"""`cylinders` on a scene the pipe rack does not hold: four vertical poles (radius 0.05, 0.12,
0.2, and 0.5 seen from one side; the 0.05 and 0.2 ones with a gap band) and a box 1 x 0.6 x 0.8
standing on an 8 x 8 m floor, ~216k points, no normals (estimated as the CLI does), Gaussian
noise of 0, 2.5e-4, 5e-4 and 1e-3 of the diagonal. Per run: each pole's best IoU with a
component at its representative level (found at >= 0.8) and its persistence, and the false
tubes (components whose points lie mostly on the box or the floor) with their persistence.
Runs the defaults and the keyword sets given (as `scalespace.cylinders` takes them).

    PYTHONPATH=build/python /usr/bin/python3 bench/python/bench_cylinders_box_and_poles.py \\
        [--seed S] ["dict(max_section_shape=0.2)" ...]
"""
import argparse
import time

import numpy as np

import scalespace as ss

POLES = [(-2.0, -2.0, 0.05, 2.0), (0.0, 1.5, 0.2, 3.0), (2.0, -1.0, 0.5, 2.5), (-2.5, 2.5, 0.12, 1.5)]
BOX, FLOOR = -2, -1
NAMES = {BOX: "box", FLOOR: "floor", 0: "pole r 0.05", 1: "pole r 0.2", 2: "half pole r 0.5",
         3: "pole r 0.12"}


def scene(rng, density=2500):
    """Points and labels (pole index, BOX, FLOOR)."""
    floor = np.c_[rng.uniform(-4, 4, (density * 64, 2)), np.zeros(density * 64)]
    outside = np.ones(len(floor), bool)
    for x, y, r, _ in POLES:
        outside &= np.hypot(floor[:, 0] - x, floor[:, 1] - y) > r
    parts, labels = [floor[outside]], [np.full(outside.sum(), FLOOR)]
    for i, (x, y, r, h) in enumerate(POLES):
        n = int(2 * np.pi * r * h * density)
        theta, z = rng.uniform(0, 2 * np.pi, n), rng.uniform(0, h, n)
        keep = ~((z > 0.8) & (z < 1.0) & (theta < 2.0))  # a band the scanner missed
        if r == 0.5:
            keep &= theta <= 4.0  # seen from one side
        p = np.c_[x + r * np.cos(theta), y + r * np.sin(theta), z][keep]
        parts.append(p)
        labels.append(np.full(len(p), i))
    n = 40000
    box = rng.uniform(-0.5, 0.5, (n, 3))
    face = rng.integers(0, 3, n)
    box[np.arange(n), face] = np.sign(box[np.arange(n), face]) * 0.5
    box = box * [1, 0.6, 0.8] + [1.5, 2.5, 0.4]
    box = box[box[:, 2] > 1e-3]  # no bottom face: it stands on the floor
    parts.append(box)
    labels.append(np.full(len(box), BOX))
    return np.vstack(parts), np.concatenate(labels)


def score(result, labels):
    poles, false = {}, []
    for comp in result.components:
        at = result.labels_at_level(comp["representative_level"]) == comp["id"]
        counts = np.bincount(labels[at] + 2, minlength=len(POLES) + 2)
        holder = int(counts.argmax()) - 2
        if holder < 0:
            false.append((NAMES[holder], comp["persistence"], round(comp["radius"], 3)))
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
    rng = np.random.default_rng(args.seed)
    points, labels = scene(rng)
    diagonal = np.linalg.norm(points.max(0) - points.min(0))
    settings = [{}] + [eval(s, {"dict": dict}) for s in args.settings]
    print(f"{len(points)} points, diagonal {diagonal:.2f} m")
    for noise in [0, 2.5e-4, 5e-4, 1e-3]:
        noisy = points + rng.normal(size=points.shape) * noise * diagonal
        for kwargs in settings:
            start = time.perf_counter()
            result = ss.cylinders(noisy, **kwargs)
            seconds = time.perf_counter() - start
            poles, false = score(result, labels)
            found = sum(1 for iou, _ in poles.values() if iou >= 0.8)
            print(f"noise {noise:g} {kwargs or 'defaults'}: poles found {found}/{len(POLES)}, "
                  f"false tubes {len(false)} (persistence >= 2: "
                  f"{sum(1 for _, p, _ in false if p >= 2)}), {seconds:.1f} s")
            for i in sorted(poles):
                print(f"    {NAMES[i]:16s} IoU {poles[i][0]:.3f} persistence {poles[i][1]}")
            for name, persistence, radius in false:
                print(f"    false on the {name}: radius {radius}, persistence {persistence}")


if __name__ == "__main__":
    main()
