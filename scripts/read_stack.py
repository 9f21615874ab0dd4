#!/usr/bin/python3
"""Example reader of a scalespace stack (docs/STACK_FORMAT.md) with plain NumPy.

    /usr/bin/python3 scripts/read_stack.py NAME.stack [--scale J] [--point I]

Every quantity is one .npy file shaped (M, N) or (M, N, 3): memory-map it and index it,
arr[j] is scale j for all points, arr[:, i] is point i at every scale. Nothing is loaded
until it is indexed. Needs Debian's python3-numpy.
"""
import argparse
import json
import os
import sys

import numpy as np


def load_stack(path):
    """Returns (manifest, {name: memory-mapped array}, input positions (N, 3) float64)."""
    with open(os.path.join(path, "manifest.json")) as f:
        manifest = json.load(f)
    if manifest.get("format") != "scalespace-stack":
        raise ValueError(f"{path}: not a scalespace stack")
    arrays = {}
    for name, q in manifest["quantities"].items():
        a = np.load(os.path.join(path, q["file"]), mmap_mode="r")
        if list(a.shape) != q["shape"] or a.dtype != np.dtype(q["dtype"]):
            raise ValueError(f"{path}/{q['file']}: shape/dtype differ from the manifest")
        arrays[name] = a
    xyz = np.load(os.path.join(path, manifest["input_positions"]["file"]), mmap_mode="r")
    return manifest, arrays, xyz


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("stack")
    p.add_argument("--scale", type=int, default=0)
    p.add_argument("--point", type=int, default=0)
    a = p.parse_args()
    manifest, arrays, xyz = load_stack(a.stack)
    m, n = manifest["scale_count"], manifest["point_count"]
    print(f"{a.stack}: {n} points x {m} scales, t = {manifest['scales'][0]:.6g} .. {manifest['scales'][-1]:.6g}")
    j, i = a.scale, a.point
    origin = np.array(manifest["origin"])
    print(f"input position of point {i} = {xyz[i]}")
    print(f"projection[{j}, {i}] (absolute) = {arrays['projection'][j, i] + origin}")
    for name in ("curv_mean", "curv_max", "curv_min", "gls_tau", "gls_kappa", "anisotropy"):
        print(f"{name}[{j}, {i}] = {float(arrays[name][j, i]):.6g}")
    valid = arrays["fit_valid"][j]
    print(f"valid fits at scale {j}: {int(valid.sum())} of {n}")
    print(f"mean curvature of point {i} over the scales: {np.asarray(arrays['curv_mean'][:, i])}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
