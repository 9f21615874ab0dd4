#!/usr/bin/python3
"""Example reader of a scalespace stack (docs/STACK_FORMAT.md) with plain NumPy.

    /usr/bin/python3 scripts/read_stack.py NAME.stack [--scale J] [--point I]
    /usr/bin/python3 scripts/read_stack.py COMPACT.stack --compare FLOAT32.stack
        (quantisation errors of a compact stack against its float32 twin, same input/options)

Every quantity is one .npy file shaped (M, N), (M, N, 3) or, for bit-packed flags,
(M, ceil(N / 8)): memory-map it and index it, arr[j] is scale j for all points, arr[:, i] is
point i at every scale. Nothing is loaded until it is indexed.

Two encodings (manifest "encoding"; format version 1 is always float32):
  float32  the values as they are (projection.npy, normal.npy, curv_max.npy, ...);
  compact  quantised (projection_offset.npy, frame.npy, curv_max_t.npy, ...): decode_scale()
           and decode_point() below turn them back into the float32 quantities. Format version 3
           (the default, 19.125 bytes per point per scale) stores the offsets with a shared
           exponent and anisotropy / geometric_variation as 8-bit log codes; version 2 (23.125
           bytes) stores them as float16.
Needs Debian's python3-numpy and nothing else.
"""
import argparse
import json
import os
import sys

import numpy as np

OCT_MAX = 1023  # octahedral components: signed-normalised 11 bits, stored as q + 1023
ANGLE_STEPS = 1024  # dir_max angle: theta = q * pi / 1024, 10 bits


def load_stack(path):
    """Returns (manifest, {name: memory-mapped array}, input positions (N, 3) float64)."""
    with open(os.path.join(path, "manifest.json")) as f:
        manifest = json.load(f)
    if manifest.get("format") != "scalespace-stack":
        raise ValueError(f"{path}: not a scalespace stack")
    if manifest["format_version"] not in (1, 2, 3):
        raise ValueError(f"{path}: format version {manifest['format_version']} is not supported")
    arrays = {}
    for name, q in manifest["quantities"].items():
        a = np.load(os.path.join(path, q["file"]), mmap_mode="r")
        if list(a.shape) != q["shape"] or a.dtype != np.dtype(q["dtype"]):
            raise ValueError(f"{path}/{q['file']}: shape/dtype differ from the manifest")
        arrays[name] = a
    xyz = np.load(os.path.join(path, manifest["input_positions"]["file"]), mmap_mode="r")
    if encoding(manifest) == "compact" and manifest["format_version"] >= 3:
        check_codecs(path, manifest)
    return manifest, arrays, xyz


def check_codecs(path, manifest):
    """Version 3: the parameters the decoders read from the manifest must be sane."""
    q = manifest["quantities"]
    off = q["projection_offset"]
    bias = off.get("bias")
    if off.get("codec") != "shared_exponent" or not isinstance(bias, int) or not 0 <= bias <= 64:
        raise ValueError(f"{path}: projection_offset: expected codec shared_exponent, bias 0..64")
    for name, codec in (("anisotropy", "slog8"), ("geometric_variation", "log8")):
        lo, hi = q[name].get("log_min"), q[name].get("log_max")
        if (q[name].get("codec") != codec or not isinstance(lo, (int, float))
                or not isinstance(hi, (int, float)) or not 0 < lo < hi < np.inf):
            raise ValueError(f"{path}: {name}: expected codec {codec}, 0 < log_min < log_max < inf")


def encoding(manifest):
    return manifest.get("encoding", "float32")  # version 1 has no "encoding": float32


def decode_frame(code):
    """uint32 frame codes (any shape) -> normal, dir_max, dir_min (shape + (3,), float64).

    bits 0-10: qx + 1023, bits 11-21: qy + 1023 (octahedral normal), bits 22-31: q, the angle
    theta = q pi / 1024 of dir_max in the tangent basis (b1, b2) of the decoded normal;
    dir_min = normal x dir_max. Integer arithmetic decides the fold and the basis' sign.
    """
    code = np.asarray(code, dtype=np.uint32)
    qx = np.clip((code & 0x7FF).astype(np.int64) - OCT_MAX, -OCT_MAX, OCT_MAX)
    qy = np.clip(((code >> 11) & 0x7FF).astype(np.int64) - OCT_MAX, -OCT_MAX, OCT_MAX)
    z = OCT_MAX - np.abs(qx) - np.abs(qy)
    lower = z < 0  # lower hemisphere: unfold the corner triangles of the octahedral square
    x = np.where(lower, (OCT_MAX - np.abs(qy)) * np.where(qx >= 0, 1, -1), qx)
    y = np.where(lower, (OCT_MAX - np.abs(qx)) * np.where(qy >= 0, 1, -1), qy)
    n = np.stack([x, y, z], axis=-1).astype(np.float64)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    # Tangent basis of Duff et al. 2017, with the sign of the integer z.
    s = np.where(z >= 0, 1.0, -1.0)
    nx, ny, nz = n[..., 0], n[..., 1], n[..., 2]
    a = -1.0 / (s + nz)
    b = nx * ny * a
    b1 = np.stack([1 + s * nx * nx * a, s * b, -s * nx], axis=-1)
    b2 = np.stack([b, s + ny * ny * a, -ny], axis=-1)
    theta = (code >> 22).astype(np.float64) * (np.pi / ANGLE_STEPS)
    dmax = np.cos(theta)[..., None] * b1 + np.sin(theta)[..., None] * b2
    dmin = np.cross(n, dmax)
    return n, dmax, dmin


def decode_offset(code, bias):
    """uint32 shared-exponent codes (any shape) -> offsets in units of t (shape + (3,), float64).

    bits 0-8, 9-17, 18-26: x, y, z, each a sign (bit 8) and a magnitude m (bits 0-7); bits 27-31:
    the exponent e shared by the three; component = (-1)^sign * m * 2^(e - bias), exact in float64
    (integer operations, then ldexp): the same doubles as ScaleStackReader.
    """
    code = np.asarray(code, dtype=np.uint32)
    e = (code >> 27).astype(np.int32) - np.int32(bias)
    comps = []
    for c in range(3):
        field = (code >> (9 * c)) & 0x1FF
        m = (field & 0xFF).astype(np.float64)
        comps.append(np.ldexp(np.where((field & 0x100) != 0, -m, m), e))
    return np.stack(comps, axis=-1)


def decode_log8(code, log_min, log_max):
    """uint8 log codes (any shape) -> float64: code 0 is 0, code k = 1..255 the geometric centre
    log_min * (log_max / log_min) ** ((k - 0.5) / 255) of the k-th of 255 equal-ratio bins."""
    code = np.asarray(code, dtype=np.uint8)
    k = code.astype(np.float64)
    return np.where(code == 0, 0.0, log_min * np.power(log_max / log_min, (k - 0.5) / 255))


def decode_slog8(code, log_min, log_max):
    """Signed uint8 log codes -> float64: bit 7 is the sign, k = bits 0-6 the magnitude's code:
    0 if k = 0, else log_min * (log_max / log_min) ** ((k - 0.5) / 127)."""
    code = np.asarray(code, dtype=np.uint8)
    k = (code & 0x7F).astype(np.float64)
    magnitude = np.where(k == 0, 0.0, log_min * np.power(log_max / log_min, (k - 0.5) / 127))
    return np.where((code & 0x80) != 0, -magnitude, magnitude)


def _decode(manifest, arrays, rel, t, index, valid):
    """Decodes compact arrays at `index` (scale j: (j,); point i: (slice(None), i)).
    rel: input positions relative to the origin, broadcastable to the result; t: the scale
    value(s), broadcastable (shape () or (M,)); valid: the fit flags (0/1) at `index`."""
    def half(name):
        return np.asarray(arrays[name][index], dtype=np.float64)

    v = valid.astype(bool)
    q = manifest["quantities"]
    v3 = manifest["format_version"] >= 3
    if v3:
        offset = decode_offset(arrays["projection_offset"][index], q["projection_offset"]["bias"])
    else:
        offset = half("projection_offset")
    out = {"fit_valid": valid.astype(np.uint8),
           "neighbors": np.asarray(arrays["neighbors"][index]),
           # projection = input + offset * t, relative to the origin (also for invalid fits)
           "projection": rel + offset * t[..., None]}
    n, dmax, dmin = decode_frame(arrays["frame"][index])
    out["normal"], out["dir_max"], out["dir_min"] = (np.where(v[..., None], a, 0.0) for a in (n, dmax, dmin))
    out["curv_max"] = np.where(v, half("curv_max_t") / t, 0.0)
    out["curv_min"] = np.where(v, half("curv_min_t") / t, 0.0)
    out["curv_mean"] = 0.5 * (out["curv_max"] + out["curv_min"])
    out["gls_tau"] = np.where(v, half("gls_tau_t") * t, 0.0)
    out["gls_kappa"] = np.where(v, half("gls_kappa_t") / t, 0.0)
    for name in ("anisotropy", "geometric_variation"):
        if v3:
            decode = decode_slog8 if name == "anisotropy" else decode_log8
            value = decode(arrays[name][index], q[name]["log_min"], q[name]["log_max"])
        else:
            value = half(name)
        out[name] = np.where(v, value, 0.0)
    return out  # gls_fitness is not stored in the compact encoding


def decode_scale(manifest, arrays, xyz, j):
    """Scale j, every point: {name: array (N,) or (N, 3)} with the float32 encoding's names;
    projection relative to manifest["origin"] as in the float32 files."""
    if encoding(manifest) == "float32":
        return {name: np.asarray(a[j]) for name, a in arrays.items()}
    n = manifest["point_count"]
    t = np.float64(manifest["scales"][j])
    rel = np.asarray(xyz, dtype=np.float64) - np.array(manifest["origin"])
    valid = np.unpackbits(arrays["fit_valid_bits"][j], count=n, bitorder="little")
    return _decode(manifest, arrays, rel, t, (j,), valid)


def decode_point(manifest, arrays, xyz, i):
    """Point i, every scale: {name: array (M,) or (M, 3)}."""
    if encoding(manifest) == "float32":
        return {name: np.asarray(a[:, i]) for name, a in arrays.items()}
    t = np.asarray(manifest["scales"], dtype=np.float64)
    rel = np.asarray(xyz[i], dtype=np.float64) - np.array(manifest["origin"])
    valid = (np.asarray(arrays["fit_valid_bits"][:, i // 8]) >> (i % 8)) & 1
    return _decode(manifest, arrays, rel, t, (slice(None), i), valid)


def compare(compact_path, float32_path):
    """Prints the max and 99th percentile of the quantisation errors over every valid fit."""
    mc, ac, xc = load_stack(compact_path)
    mf, af, xf = load_stack(float32_path)
    if encoding(mc) != "compact" or encoding(mf) != "float32":
        raise ValueError("--compare needs a compact stack and its float32 twin")
    if mc["input_checksum"] != mf["input_checksum"] or mc["scales"] != mf["scales"]:
        raise ValueError("the two stacks were not computed from the same input and scales")
    errors = {k: [] for k in ("position / t", "normal angle (deg)", "dir_max angle (deg)",
                              "dir_min angle (deg)", "|d k_max| t", "|d k_min| t",
                              "|d k_max| / |k_max| (|k_max| t > 0.01)",
                              "|d k_min| / |k_min| (|k_min| t > 0.01)",
                              "|d kappa| / |kappa| (|kappa| t > 0.01)")}
    # Log-coded quantities (version 3): relative error inside the code's range, absolute below it
    # (version 2: float16's normal range).
    ranges = {}
    for name, key in (("anisotropy", "aniso"), ("geometric_variation", "nu")):
        qc = mc["quantities"][name]
        ranges[name] = (key, qc.get("log_min", 2.0 ** -14), qc.get("log_max", 65504.0))
        errors[f"|d {key}| / {key} ({key} in [log_min, log_max])"] = []
        errors[f"|d {key}| ({key} < log_min, negative included)"] = []
    negative = {name: 0 for name in ranges}
    flags_differ = 0

    def axis_angle(a, b):
        return np.degrees(np.arctan2(np.linalg.norm(np.cross(a, b), axis=-1), np.abs(np.sum(a * b, axis=-1))))

    for j, t in enumerate(mc["scales"]):
        c = decode_scale(mc, ac, xc, j)
        f = decode_scale(mf, af, xf, j)
        flags_differ += int(np.count_nonzero(c["fit_valid"] != f["fit_valid"]))
        v = (c["fit_valid"] == 1) & (f["fit_valid"] == 1)
        errors["position / t"].append(np.linalg.norm(c["projection"] - f["projection"], axis=-1) / t)
        fn = f["normal"][v] / np.linalg.norm(f["normal"][v], axis=-1, keepdims=True)
        errors["normal angle (deg)"].append(np.degrees(np.arccos(np.clip(np.sum(c["normal"][v] * fn, axis=-1), -1, 1))))
        errors["dir_max angle (deg)"].append(axis_angle(c["dir_max"][v], f["dir_max"][v]))
        errors["dir_min angle (deg)"].append(axis_angle(c["dir_min"][v], f["dir_min"][v]))
        for name, key in (("curv_max", "k_max"), ("curv_min", "k_min"), ("gls_kappa", "kappa")):
            d = np.abs(c[name][v] - f[name][v].astype(np.float64))
            k = np.abs(f[name][v].astype(np.float64))
            if name != "gls_kappa":
                errors[f"|d {key}| t"].append(d * t)
            big = k * t > 0.01
            errors[f"|d {key}| / |{key}| (|{key}| t > 0.01)"].append(d[big] / k[big])
        for name, (key, lo, hi) in ranges.items():
            fv = f[name][v].astype(np.float64)
            d = np.abs(c[name][v] - fv)
            signed = mc["quantities"][name].get("codec") == "slog8"
            mag = np.abs(fv) if signed else fv
            inside = (mag >= lo) & (mag <= hi)
            errors[f"|d {key}| / {key} ({key} in [log_min, log_max])"].append(d[inside] / mag[inside])
            errors[f"|d {key}| ({key} < log_min, negative included)"].append(d[mag < lo])
            negative[name] += int(np.count_nonzero(fv < 0))
    per_file = ", ".join(f"{k} {q['clamped']}" for k, q in mc["quantities"].items() if q.get("clamped"))
    print(f"{compact_path} vs {float32_path}: {mc['point_count']} points x {mc['scale_count']} scales, "
          f"valid flags differing: {flags_differ}, values clamped: {mc.get('clamped_values', 0)}"
          + (f" ({per_file})" if per_file else ""))
    print("negative float32 values (valid fits): " + ", ".join(f"{k} {c}" for k, c in negative.items()))
    print(f"{'error':52s} {'max':>10s} {'99th pct':>10s} {'count':>10s}")
    for name, parts in errors.items():
        e = np.concatenate(parts) if parts else np.zeros(0)
        if e.size:
            print(f"{name:52s} {e.max():10.3g} {np.percentile(e, 99):10.3g} {e.size:10d}")
    return 0


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("stack")
    p.add_argument("--scale", type=int, default=0)
    p.add_argument("--point", type=int, default=0)
    p.add_argument("--compare", metavar="FLOAT32_STACK",
                   help="print the quantisation errors of STACK (compact) against its float32 twin")
    a = p.parse_args()
    if a.compare:
        return compare(a.stack, a.compare)
    manifest, arrays, xyz = load_stack(a.stack)
    m, n = manifest["scale_count"], manifest["point_count"]
    print(f"{a.stack}: {n} points x {m} scales, t = {manifest['scales'][0]:.6g} .. {manifest['scales'][-1]:.6g}, "
          f"encoding {encoding(manifest)}")
    j, i = a.scale, a.point
    origin = np.array(manifest["origin"])
    scale = decode_scale(manifest, arrays, xyz, j)
    print(f"input position of point {i} = {xyz[i]}")
    proj = scale["projection"][i] + origin
    print(f"projection[{j}, {i}] (absolute) = {proj}")
    for k, c in enumerate("xyz"):
        print(f"projection_{c}[{j}, {i}] = {proj[k]:.17g}")
    for name in ("normal", "dir_max", "dir_min"):
        for k, c in enumerate("xyz"):
            print(f"{name}_{c}[{j}, {i}] = {float(scale[name][i][k]):.9g}")
    for name in ("curv_mean", "curv_max", "curv_min", "gls_tau", "gls_kappa", "anisotropy",
                 "geometric_variation"):
        print(f"{name}[{j}, {i}] = {float(scale[name][i]):.6g}")
    valid = scale["fit_valid"]
    print(f"valid fits at scale {j}: {int(valid.sum())} of {n}")
    print(f"mean curvature of point {i} over the scales: {decode_point(manifest, arrays, xyz, i)['curv_mean']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
