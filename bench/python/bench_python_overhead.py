#!/usr/bin/env python3
"""The cost of calling scalespace from Python (issue 22): for 1M points, the wall time of
scalespace.curvature() minus the library call's own time (computeCurvatureColumns, as its summary
reports it), i.e. checking and passing the points in, the GIL release and worker thread, and the
18 result columns out as NumPy arrays. Targets: < 5% of the C++ time, < 10 ms in and out. The
first call also allocates the input buffers that the module keeps for the next ones.
The peer: Open3D's o3d.utility.Vector3dVector on the same array (the conversion every Open3D
call on NumPy points starts with), when python3-open3d is importable; skipped and said otherwise.

    PYTHONPATH=build/python /usr/bin/python3 bench/python/bench_python_overhead.py [--points N]
"""
import argparse
import statistics
import time

import numpy as np

import scalespace as ss


def best_of(runs, f):
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        f()
        times.append(time.perf_counter() - start)
    return min(times), statistics.median(times)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=1_000_000)
    parser.add_argument("--retain", action="store_true",
                        help="call scalespace.retain_freed_memory() first (repeated calls reuse "
                             "memory instead of faulting fresh pages in)")
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--scale-k", type=int, default=40)
    args = parser.parse_args()

    rng = np.random.default_rng(1)
    normals = rng.normal(size=(args.points, 3))
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    points = normals * (1 + 0.001 * rng.normal(size=(args.points, 1)))  # a noisy unit sphere
    if args.retain:
        print(f"retain_freed_memory(): {ss.retain_freed_memory()}")
    print(f"{args.points} points, curvature scale_k={args.scale_k}, W3, {args.runs} runs each")

    walls, libs, ins, outs = [], [], [], []
    for _ in range(args.runs):
        start = time.perf_counter()
        columns, summary = ss.curvature(points, normals, scale_k=args.scale_k, summary=True)
        walls.append(time.perf_counter() - start)
        libs.append(summary["library_seconds"])
        ins.append(summary["input_seconds"])
        outs.append(summary["output_seconds"])
        del columns
    overheads = [w - c for w, c in zip(walls, libs)]
    k = overheads.index(statistics.median_low(overheads))
    print(f"curvature(): wall {walls[k]:.3f} s, the library call {libs[k]:.3f} s, "
          f"overhead {1e3 * overheads[k]:.1f} ms = {100 * overheads[k] / libs[k]:.2f}% "
          f"(median run; all overheads ms: {', '.join(f'{1e3 * o:.1f}' for o in overheads)})")
    print(f"  of which: points and normals checked and copied in {1e3 * ins[k]:.1f} ms, "
          f"columns out and the input buffers given back {1e3 * outs[k]:.1f} ms, "
          f"the rest (call, worker thread, summary) {1e3 * (overheads[k] - ins[k] - outs[k]):.1f} ms")

    # Points that are not float64 C-contiguous are converted once: the cost of that copy.
    fortran = np.asfortranarray(points)
    start = time.perf_counter()
    _, s = ss.curvature(fortran, normals, scale_k=args.scale_k, summary=True)
    wall = time.perf_counter() - start
    print(f"curvature() on a Fortran-ordered copy: overhead {1e3 * (wall - s['library_seconds']):.1f} ms")

    try:
        import open3d as o3d
    except ImportError:
        print("peer: open3d is not importable (Debian python3-open3d): skipped")
        return
    into, into_median = best_of(args.runs, lambda: o3d.utility.Vector3dVector(points))
    vec = o3d.utility.Vector3dVector(points)
    back, back_median = best_of(args.runs, lambda: np.array(vec))
    print(f"peer Open3D {o3d.__version__}: Vector3dVector(points) {1e3 * into:.1f} ms "
          f"(median {1e3 * into_median:.1f}), np.array(vector) back {1e3 * back:.1f} ms "
          f"(median {1e3 * back_median:.1f})")


if __name__ == "__main__":
    main()
