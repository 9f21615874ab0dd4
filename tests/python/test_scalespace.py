"""The Python module against the CLI and its own promises (issue 22). Run by ctest (Python.Pytest)
with PYTHONPATH=build/python and SCALESPACE_CLI=build/scalespace; by hand:
PYTHONPATH=build/python SCALESPACE_CLI=build/scalespace /usr/bin/python3 -m pytest tests/python
"""
import gc
import json
import os
import signal
import subprocess
import threading
import time
import warnings
from pathlib import Path

import numpy as np
import pytest

import scalespace as ss

CLI = os.environ.get("SCALESPACE_CLI", str(Path(__file__).resolve().parents[2] / "build" / "scalespace"))


def cli(*args):
    subprocess.run([CLI, *map(str, args), "-q"], check=True, capture_output=True)


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    d = tmp_path_factory.mktemp("data")
    cli("generate", "sphere", "-n", 3000, "--noise", 0.002, "--seed", 3, "-o", d / "sphere.ply")
    cli("generate", "house", "-n", 12000, "--seed", 1, "-o", d / "house.ply")
    return d


def columns(path):
    """A curvature output's columns by name: its attributes, and nx ny nz (read as normals)."""
    cloud = ss.read(str(path))
    out = dict(cloud.attributes)
    for c, name in enumerate(("nx", "ny", "nz")):
        out[name] = cloud.normals[:, c].astype(np.float32)
    return out


def sphere_points(n=2000, seed=1):
    p = np.random.default_rng(seed).normal(size=(n, 3))
    return p / np.linalg.norm(p, axis=1)[:, None]


# ------------------------------------------------------------------------------- round trips
@pytest.mark.parametrize("name,ascii", [("a.ply", False), ("b.ply", True), ("c.xyz", False),
                                        ("d.txt", False), ("e.csv", False), ("f.pts", False),
                                        ("g.las", False), ("h.pcd", False), ("i.pcd", True)])
def test_round_trip_every_writable_format(tmp_path, name, ascii):
    rng = np.random.default_rng(7)
    # Georeferenced-like coordinates on a millimetre grid: LAS stores scaled integers.
    points = np.round(rng.uniform(-50, 50, size=(500, 3)), 3) + [651234.0, 5432100.0, 120.0]
    normals = sphere_points(500, 2)
    attributes = {"intensity": rng.integers(0, 65535, 500).astype(np.uint16),
                  "curv": rng.normal(size=500).astype(np.float32),
                  "label": rng.integers(-5, 100, 500).astype(np.int32)}
    ss.write(tmp_path / name if False else str(tmp_path / name), points, normals, attributes,
             ascii=ascii)
    cloud = ss.read(str(tmp_path / name))
    assert cloud.points.shape == (500, 3) and cloud.points.dtype == np.float64
    np.testing.assert_allclose(cloud.points, points, rtol=0, atol=1e-3 if name.endswith(".las") else 1e-6)
    assert cloud.normals is not None
    np.testing.assert_allclose(cloud.normals, normals, atol=1e-6)
    for key, values in attributes.items():
        assert key in cloud.attributes, (key, list(cloud.attributes))
        np.testing.assert_allclose(cloud.attributes[key].astype(np.float64),
                                   values.astype(np.float64), rtol=1e-6)
    if name.endswith(".ply") or name.endswith(".pcd"):  # typed formats keep the dtype
        assert cloud.attributes["intensity"].dtype == np.uint16
        assert cloud.attributes["curv"].dtype == np.float32


def test_pwn_holds_positions_and_normals_only(tmp_path):
    # CGAL's points with normals: headerless "x y z nx ny nz"; attributes are not written, and a
    # cloud without normals is refused before any file is made.
    points, normals = sphere_points(50), sphere_points(50, 3)
    path = str(tmp_path / "s.pwn")
    ss.write(path, points, normals, {"label": np.arange(50, dtype=np.int32)})
    first = open(path).readline().split()
    assert len(first) == 6 and abs(float(first[0]) - points[0, 0]) < 1e-12
    back = ss.read(path)
    np.testing.assert_allclose(back.points, points, atol=1e-12)
    np.testing.assert_allclose(back.normals, normals, atol=1e-12)
    assert back.attributes == {}
    with pytest.raises(ss.OptionError, match="normals"):
        ss.write(str(tmp_path / "bare.pwn"), points)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.pwn"]


def test_write_a_cloud_object_and_read_meshes(tmp_path):
    cloud = ss.Cloud(sphere_points(100), None, {"flag": np.ones(100, bool)})
    ss.write(str(tmp_path / "c.ply"), cloud)
    back = ss.read(str(tmp_path / "c.ply"))
    assert back.normals is None and back.attributes["flag"].dtype == np.uint8
    (tmp_path / "m.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 2 4\n")
    assert ss.read(str(tmp_path / "m.obj")).points.shape == (4, 3)
    sampled = ss.read(str(tmp_path / "m.obj"), sample=50)
    assert sampled.points.shape == (50, 3) and sampled.normals is not None


def test_placeholder_normals_read_as_none(tmp_path):
    # A writer without normals that fills the columns with zeros (libcgal-demo's blobby.xyz):
    # read without normals, with a warning; the CLI says so and estimates them.
    points = sphere_points(500)
    path = tmp_path / "zeros.xyz"
    np.savetxt(path, np.hstack([points, np.zeros_like(points)]))
    with pytest.warns(UserWarning, match="zero or NaN/Inf"):
        cloud = ss.read(str(path))
    assert cloud.normals is None and cloud.points.shape == (500, 3)
    run = subprocess.run([CLI, "features", str(path), "-o", str(tmp_path / "f.ply")],
                         capture_output=True, text=True, check=True)
    assert "read without normals" in run.stderr and "input has no normals" in run.stderr


# ------------------------------------------------------------------------- equal to the CLI
def test_curvature_equals_the_cli(data, tmp_path):
    cli("curvature", data / "sphere.ply", "-o", tmp_path / "c.ply", "--scale-k", 20, "--robust")
    expected = columns(tmp_path / "c.ply")
    cloud = ss.read(str(data / "sphere.ply"))
    got = ss.curvature(cloud.points, cloud.normals, scale_k=20, robust=True)
    assert got["fit_valid"].sum() > 2900
    for name, values in got.items():
        # The file holds float32 columns of the same doubles: equal after the same rounding.
        np.testing.assert_array_equal(values.astype(expected[name].dtype), expected[name], name)


def test_curvature_warns_of_a_scale_reaching_the_diagonal():
    points = sphere_points(300)
    normals = points / np.linalg.norm(points, axis=1, keepdims=True)
    with pytest.warns(RuntimeWarning, match="reaches the cloud's diagonal"):  # the CLI's text
        ss.curvature(points, normals, scale=1e6)


def test_curvature_without_normals_equals_the_cli(data, tmp_path):
    points = ss.read(str(data / "house.ply")).points
    ss.write(str(tmp_path / "bare.ply"), points)  # no normals: both estimate and orient them
    cli("curvature", tmp_path / "bare.ply", "-o", tmp_path / "c.ply", "--scale", 0.3)
    expected = columns(tmp_path / "c.ply")
    got = ss.curvature(points, scale=0.3)
    for name in ("curv_mean", "curv_max", "nx", "ny", "nz", "neighbors", "fit_valid"):
        np.testing.assert_array_equal(got[name].astype(expected[name].dtype), expected[name], name)


def test_estimate_normals_equals_the_cli(data, tmp_path):
    points = ss.read(str(data / "house.ply")).points
    ss.write(str(tmp_path / "bare.ply"), points)
    # the across-sheet cost, the default (Hoppe's cost and the rays), Hoppe's cost alone, sheets
    # oriented by their own tree, by the PCA normals', and by whichever the rays prefer; the
    # reflected agreement, alone and as features orients its sheet normals
    for weight, visibility, sheet, sign, reflect in ((1, True, 0, "", False),
                                                     (0, True, 0, "", False),
                                                     (0, False, 0, "", False),
                                                     (0, True, 0.05, "", False),
                                                     (0, True, 0.05, "pca", False),
                                                     (0, True, 0.05, "rays", False),
                                                     (0, False, 0, "", True),
                                                     (0, True, 0.05, "rays", True)):
        flags = ["--visibility" if visibility else "--no-visibility"]
        flags += {"": [], "pca": ["--sign-from-pca"], "rays": ["--sign-by-rays"]}[sign]
        flags += ["--reflect"] if reflect else []
        cli("normals", tmp_path / "bare.ply", "-o", tmp_path / "n.ply", "--across-weight", weight,
            *flags, "--sheet", sheet)
        expected = columns(tmp_path / "n.ply")
        normals, reliable = ss.estimate_normals(points, across_weight=weight,
                                                visibility=visibility, sheet=sheet,
                                                sign_from_pca=sign == "pca",
                                                sign_by_rays=sign == "rays", reflect=reflect)
        for c, name in enumerate(("nx", "ny", "nz")):
            np.testing.assert_array_equal(normals[:, c].astype(np.float32), expected[name], name)
        np.testing.assert_array_equal(reliable, expected["normal_reliable"] != 0)
    with pytest.raises(ValueError, match="acrossWeight"):
        ss.estimate_normals(points, across_weight=-1)
    with pytest.raises(ValueError, match="reflectAcrossBisector"):
        ss.estimate_normals(points, across_weight=1, reflect=True)
    with pytest.raises(ss.OptionError, match="sheet") as e:
        ss.estimate_normals(points, sheet=-1)
    assert "Options::" not in str(e.value)
    with pytest.raises(ss.OptionError, match="sign_from_pca needs sheet normals"):
        ss.estimate_normals(points, sign_from_pca=True)
    with pytest.raises(ss.OptionError, match="sign_by_rays needs sheet normals"):
        ss.estimate_normals(points, sign_by_rays=True)
    with pytest.raises(ss.OptionError, match="one of sign_from_pca and sign_by_rays"):
        ss.estimate_normals(points, sheet=0.05, sign_from_pca=True, sign_by_rays=True)


def test_noisy_normals_take_more_neighbours_as_the_cli_does(tmp_path):
    # A plane with noise 0.8 spacings: the normals of 10 neighbours follow the noise; k doubles
    # (max_k, default 80) until they do not. max_k=k keeps k; the CLI's --max-k is the same.
    rng = np.random.default_rng(11)
    points = np.stack([rng.uniform(0, 1, 40000), rng.uniform(0, 1, 40000),
                       rng.normal(0, 0.004, 40000)], axis=1).astype(np.float32)
    error = lambda n: np.median(np.degrees(np.arccos(np.clip(np.abs(n[:, 2]), 0, 1))))
    adapted, _ = ss.estimate_normals(points)
    fixed, _ = ss.estimate_normals(points, max_k=10)
    assert error(fixed) > 20 and error(adapted) < 15
    ss.write(str(tmp_path / "bare.ply"), points)
    for flags, expected in ((("--max-k", 10), fixed), ((), adapted)):
        cli("normals", tmp_path / "bare.ply", "-o", tmp_path / "n.ply", *flags)
        got = columns(tmp_path / "n.ply")
        for c, name in enumerate(("nx", "ny", "nz")):
            np.testing.assert_array_equal(expected[:, c].astype(np.float32), got[name], name)


def test_a_pcd_viewpoint_orients_the_normals_as_the_cli_does(tmp_path):
    # A ridge scanned from below (z away from the ground): its parts turn to face the PCD's
    # VIEWPOINT (the +z seeds alone orient it away), and the ridge, seen from the scanner, is a
    # concave crease.
    rng = np.random.default_rng(7)
    a, b = rng.uniform(0, 2, 8000), rng.uniform(0, 2, 8000)
    points = np.stack([a, b, 0.6 * (1 - np.abs(a - 1))], axis=1).astype(np.float32)
    header = ("VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 8000\n"
              "HEIGHT 1\nVIEWPOINT 1 1 -1.5 1 0 0 0\nPOINTS 8000\nDATA ascii\n")
    (tmp_path / "t.pcd").write_text(header + "\n".join(" ".join(repr(float(v)) for v in p)
                                                        for p in points) + "\n")
    cloud = ss.read(str(tmp_path / "t.pcd"))
    assert cloud.viewpoint == (1.0, 1.0, -1.5)
    cli("normals", tmp_path / "t.pcd", "-o", tmp_path / "n.ply")
    expected = columns(tmp_path / "n.ply")
    normals, _ = ss.estimate_normals(cloud.points, viewpoint=cloud.viewpoint)
    for c, name in enumerate(("nx", "ny", "nz")):
        np.testing.assert_array_equal(normals[:, c].astype(np.float32), expected[name], name)
    towards = np.asarray(cloud.viewpoint) - cloud.points
    assert (np.sum(normals * towards, axis=1) > 0).mean() > 0.99
    plain, _ = ss.estimate_normals(cloud.points)
    assert (np.sum(plain * towards, axis=1) > 0).mean() < 0.05
    # features, planes and cylinders estimate the normals as the CLI does with viewpoint=.
    cli("features", tmp_path / "t.pcd", "-o", tmp_path / "f.ply")
    features = ss.features(cloud.points, viewpoint=cloud.viewpoint)
    np.testing.assert_array_equal(features["convexity"],
                                  ss.read(str(tmp_path / "f.ply")).attributes["convexity"])
    sheets, _ = ss.estimate_normals(cloud.points, viewpoint=cloud.viewpoint, sheet=0.05,
                                    sign_by_rays=True)
    np.testing.assert_array_equal(features["convexity"],
                                  ss.features(cloud.points, sheets)["convexity"])
    assert (features["convexity"] < 0).sum() > 100 and (features["convexity"] > 0).sum() == 0
    assert (ss.features(cloud.points)["convexity"] > 0).sum() > 100


def test_planes_and_segments_equal_the_cli(data, tmp_path):
    cli("planes", data / "house.ply", "-o", tmp_path / "planes", "--scales", 10)
    cli("segment", tmp_path / "planes", "--min-persistence", 2, "-o", tmp_path / "p.ply")
    cli("segment", tmp_path / "planes", "--scale", 0.5, "-o", tmp_path / "s.ply")
    (tmp_path / "brush.txt").write_text(" ".join(map(str, range(0, 12000, 97))))
    cli("segment", tmp_path / "planes", "--similar", 1, "--within", tmp_path / "brush.txt",
        "-o", tmp_path / "w.ply")
    cloud = ss.read(str(data / "house.ply"))
    planes = ss.planes(cloud.points, cloud.normals, scales=10)
    stored = ss.read_planes(str(tmp_path / "planes"))
    assert len(stored.components["id"]) == len(planes.components["id"]) > 5
    np.testing.assert_array_equal(stored.membership, planes.membership)
    for key in ("birth_level", "death_level", "persistence", "point_count", "planar",
                "noise_limited"):
        np.testing.assert_array_equal(stored.components[key], planes.components[key], key)
    for key in ("normal", "offset", "area", "birth_scale"):
        np.testing.assert_allclose(stored.components[key], planes.components[key], rtol=1e-9,
                                   atol=1e-9, err_msg=key)

    def plane_id(name):
        return ss.read(str(tmp_path / name)).attributes["plane_id"]
    np.testing.assert_array_equal(planes.labels_by_persistence(2), plane_id("p.ply"))
    np.testing.assert_array_equal(planes.labels_at_scale(0.5), plane_id("s.ply"))
    within = np.arange(0, 12000, 97)
    np.testing.assert_array_equal(planes.label_components(planes.find_similar(1, within)),
                                  plane_id("w.ply"))
    ranked = planes.rank_by_brush(within)
    assert ranked["score"][0] == ranked["score"].max() and len(ranked["component"]) > 1


def test_planes_merge_options_are_checked_before_any_work(data):
    cloud = ss.read(str(data / "house.ply"))
    for kwargs, name in [({"merge_rms": -1}, "merge_rms"),
                         ({"merge_deviation": float("nan")}, "merge_deviation"),
                         ({"merge_parallel": 90}, "merge_parallel"),
                         ({"refine_distance": -0.1}, "refine_distance"),
                         ({"fill_max_angle": 0}, "fill_max_angle")]:
        with pytest.raises(ss.OptionError, match=name) as e:
            ss.planes(cloud.points, **kwargs)
        assert "Options::" not in str(e.value)


def test_planes_refine_unlabelled_is_the_cli_flag_and_labels_more(data, tmp_path):
    # Merged unions take the points of no region that their plane describes: on the house, some
    # are labelled with it and none is unlabelled that was labelled without it.
    cloud = ss.read(str(data / "house.ply"))
    with_fill = ss.planes(cloud.points, cloud.normals, scales=20)
    without = ss.planes(cloud.points, cloud.normals, scales=20, refine_unlabelled=False)
    assert (with_fill.membership >= 0).sum() > (without.membership >= 0).sum()
    assert np.all(with_fill.membership[without.membership >= 0] >= 0)
    cli("planes", data / "house.ply", "-o", tmp_path / "p", "--scales", 20,
        "--no-refine-unlabelled")
    np.testing.assert_array_equal(ss.read_planes(str(tmp_path / "p")).membership,
                                  without.membership)


def test_stack_in_memory_equals_the_stack_on_disk_and_the_export(data, tmp_path):
    cloud = ss.read(str(data / "sphere.ply"))
    cli("scales", data / "sphere.ply", "-o", tmp_path / "s.stack", "--scales", 4, "--encoding",
        "float32")
    cli("export", tmp_path / "s.stack", "--scale", 2, "-o", tmp_path / "e.ply")
    exported = ss.read(str(tmp_path / "e.ply"))
    memory = ss.compute_stack(cloud.points, cloud.normals, scales=4)
    disk = ss.open_stack(str(tmp_path / "s.stack"))
    assert memory.scale_count == disk.scale_count == 4 and memory.point_count == 3000
    np.testing.assert_allclose(memory.scales, disk.scales, rtol=1e-12)
    layer = memory.scale(2)
    np.testing.assert_array_equal(layer["curv_mean"], disk.scale(2)["curv_mean"])
    np.testing.assert_array_equal(layer["curv_mean"], exported.attributes["curv_mean"])
    np.testing.assert_allclose(layer["projection"][:, 0], exported.attributes["proj_x"], rtol=0,
                               atol=1e-12)
    series = memory.point(17)
    assert series["normal"].shape == (4, 3)
    np.testing.assert_array_equal(series["curv_mean"], disk.point(17)["curv_mean"])
    # Outputs own their memory: the stack may go, its arrays stay valid.
    del memory
    gc.collect()
    assert np.isfinite(layer["curv_mean"]).all() and layer["normal"].flags.owndata is False


def test_lines_and_features_equal_the_cli(data, tmp_path):
    cli("lines", data / "house.ply", "-o", tmp_path / "l.ply", "--scale", 0.6)
    cli("features", data / "house.ply", "-o", tmp_path / "f.ply")
    cloud = ss.read(str(data / "house.ply"))
    lines = ss.lines(cloud.points, cloud.normals, scale=0.6)
    written = ss.read(str(tmp_path / "l.ply"))  # the vertex element: one row per line vertex
    np.testing.assert_allclose(lines["vertices"], written.points, rtol=0, atol=1e-9)
    for name in ("line_id", "k1", "k_gap"):
        np.testing.assert_array_equal(lines[name].astype(written.attributes[name].dtype),
                                      written.attributes[name], name)
    features = ss.features(cloud.points, cloud.normals)
    labelled = ss.read(str(tmp_path / "f.ply")).attributes
    for name in ("feature_votes", "curve_id", "convexity", "edge_id"):
        np.testing.assert_array_equal(features[name].astype(labelled[name].dtype),
                                      labelled[name], name)
    assert len(features["curves"]) == features["curve_id"].max() + 1
    # Each curve split at its corners: every labelled point in one edge of its own curve.
    assert len(features["edges"]) == features["edge_id"].max() + 1 >= len(features["curves"])
    np.testing.assert_array_equal(features["edge_id"] >= 0, features["curve_id"] >= 0)
    for k, edge in enumerate(features["edges"]):
        assert np.all(features["edge_id"][edge["points"]] == k)
        assert np.all(features["curve_id"][edge["points"]] == edge["curve"])
    cli("features", data / "house.ply", "-o", tmp_path / "g.ply", "--salient-per-scale")
    thesis_k = ss.features(cloud.points, cloud.normals, salient_per_scale=True)
    written = ss.read(str(tmp_path / "g.ply")).attributes["feature_votes"]
    np.testing.assert_array_equal(thesis_k["feature_votes"].astype(written.dtype), written)
    bounds = [s["salient_bound"] for s in thesis_k["scales"]]
    carried = [s["salient_bound"] * s["scale"] for s in features["scales"]]
    np.testing.assert_allclose(carried, carried[0], rtol=1e-12)  # K t of the finest scale
    assert not np.allclose(bounds, features["scales"][0]["salient_bound"])
    cli("features", data / "house.ply", "-o", tmp_path / "w.ply", "--centreline-reach", 0)
    wide = ss.features(cloud.points, cloud.normals, centreline_reach=0)
    written = ss.read(str(tmp_path / "w.ply")).attributes["curve_id"]
    np.testing.assert_array_equal(wide["curve_id"].astype(written.dtype), written)
    # The trimmed band only loses points.
    assert np.all(wide["curve_id"][features["curve_id"] >= 0] >= 0)
    assert (wide["curve_id"] >= 0).sum() > (features["curve_id"] >= 0).sum()
    # The split into edges: off, one edge per curve, as the CLI's flag gives it.
    cli("features", data / "house.ply", "-o", tmp_path / "e.ply", "--edge-reach", 0)
    whole = ss.features(cloud.points, cloud.normals, edge_reach=0)
    written = ss.read(str(tmp_path / "e.ply")).attributes["edge_id"]
    np.testing.assert_array_equal(whole["edge_id"].astype(written.dtype), written)
    assert len(whole["edges"]) == len(whole["curves"]) < len(features["edges"])
    # The salient bound without its cap (the thesis' relative bound): the same votes through
    # both; the bound each scale's vertices passed, capped or not, in the dict.
    cli("features", data / "house.ply", "-o", tmp_path / "c.ply", "--salient-cap", 0)
    relative = ss.features(cloud.points, cloud.normals, salient_cap=0)
    written = ss.read(str(tmp_path / "c.ply")).attributes["feature_votes"]
    np.testing.assert_array_equal(relative["feature_votes"].astype(written.dtype), written)
    for result, cap in ((features, 0.7), (relative, np.inf)):
        for s in result["scales"]:
            assert s["vertex_bound"] * s["scale"] == pytest.approx(
                max(min(0.5 * s["salient_bound"] * s["scale"], cap),
                    result["salient_curvature_floor"]), rel=1e-12)
    for kwargs, name in [({"salient_cap": -1}, "salient_cap"),
                         ({"edge_reach": -1}, "edge_reach"),
                         ({"edge_rejoin_angle": 120}, "edge_rejoin_angle"),
                         ({"centreline_reach": float("nan")}, "centreline_reach")]:
        with pytest.raises(ss.OptionError, match=name) as e:
            ss.features(cloud.points, cloud.normals, **kwargs)
        assert "Options::" not in str(e.value)
    # The seeds' order: the random one of Sec. 3.3 through both, and it changes the lines.
    cli("lines", data / "house.ply", "-o", tmp_path / "r.ply", "--scale", 0.6,
        "--random-seed-order")
    random = ss.lines(cloud.points, cloud.normals, scale=0.6, curved_seeds_first=False)
    written = ss.read(str(tmp_path / "r.ply"))
    np.testing.assert_allclose(random["vertices"], written.points, rtol=0, atol=1e-9)
    assert random["vertices"].shape != lines["vertices"].shape or not np.array_equal(
        random["vertices"], lines["vertices"])
    summary = json.loads((tmp_path / "r.json").read_text())
    assert summary["parameters"]["curved_seeds_first"] is False


@pytest.fixture(scope="module")
def pipes(tmp_path_factory):
    """The pipe rack, and `scalespace cylinders` on it: default labels and those at a scale."""
    d = tmp_path_factory.mktemp("pipes")
    cli("generate", "pipes", "-n", 60000, "-o", d / "pipes.ply")
    cli("cylinders", d / "pipes.ply", "-o", d / "default")
    scales = json.loads((d / "default" / "components.json").read_text())["levels"]
    t = scales[len(scales) // 2]["scale"] * 1.01  # not a computed scale: the nearest is taken
    cli("cylinders", d / "pipes.ply", "-o", d / "at", "--scale", t, "--min-persistence", 1)
    cloud = ss.read(str(d / "pipes.ply"))
    return d, cloud, ss.cylinders(cloud.points, cloud.normals), t


def test_cylinders_equal_the_cli(pipes):
    d, cloud, cylinders, t = pipes
    written = json.loads((d / "default" / "components.json").read_text())
    expected = written["components"]
    got = cylinders.components
    assert len(got) == len(expected) == len(cylinders) > 3
    np.testing.assert_allclose(cylinders.scales, [l["scale"] for l in written["levels"]],
                               rtol=1e-12)
    for g, e in zip(got, expected):
        for key in ("id", "birth_level", "death_level", "gap_levels", "persistence",
                    "representative_level", "point_count", "straight"):
            assert g[key] == e[key], key
        for key in ("face_sectors",):
            assert g[key] == e[key], key
        for key in ("normal_lean",):
            np.testing.assert_allclose(g[key], e[key], rtol=1e-9, atol=1e-12, err_msg=key)
        for key in ("birth_scale", "death_scale", "radius", "rms", "length", "arc_degrees",
                    "sector_fill", "section_shape"):
            np.testing.assert_allclose(g[key], e[key], rtol=1e-9, err_msg=key)
        np.testing.assert_allclose(g["axis"], e["axis"], rtol=1e-9, atol=1e-9)  # absolute
        np.testing.assert_allclose(g["radii"], e["radii"], rtol=1e-9)
        assert g["axis"].shape == (len(g["radii"]), 3)
        if e["straight"]:
            np.testing.assert_allclose(g["direction"], e["direction"], atol=1e-9)
            np.testing.assert_allclose(g["centre"], e["centre"], rtol=1e-9, atol=1e-9)
        else:
            assert g["direction"] is None and g["centre"] is None
    for g, e in zip(cylinders.levels, written["levels"]):
        for key in ("lines", "regular_lines", "regions", "tubes", "rejected"):
            assert g[key] == e[key], key

    default = ss.read(str(d / "default" / "cloud.ply")).attributes
    np.testing.assert_array_equal(cylinders.labels_by_persistence(), default["cylinder_id"])
    at = ss.read(str(d / "at" / "cloud.ply")).attributes
    level = cylinders.nearest_level(t)
    labels = cylinders.labels_at_scale(t, min_persistence=1)
    assert labels.dtype == np.int32 and (labels >= 0).any()
    np.testing.assert_array_equal(labels, at["cylinder_id"])
    np.testing.assert_array_equal(cylinders.labels_at_level(level, 1), labels)
    # The CLI writes the anisotropy at that scale, -1 where none.
    sigma = cylinders.anisotropy(level)
    assert sigma.dtype == np.float32 and np.isnan(sigma).any()
    np.testing.assert_array_equal(np.where(np.isnan(sigma), -1, sigma), at["anisotropy"])
    # A component's points at a level are those labelled with it there.
    everywhere = cylinders.labels_at_level(level)
    for c in np.unique(everywhere[everywhere >= 0]):
        np.testing.assert_array_equal(cylinders.points(int(c), level),
                                      np.flatnonzero(everywhere == c))
    first = got[0]
    assert len(cylinders.points(0, first["representative_level"])) == first["point_count"]
    if first["death_level"] + 1 < len(cylinders.scales):
        assert len(cylinders.points(0, first["death_level"] + 1)) == 0


def test_cylinders_without_normals_equal_the_cli(pipes, tmp_path):
    _, cloud, _, _ = pipes
    ss.write(str(tmp_path / "bare.ply"), cloud.points)  # both estimate and orient the normals
    cli("cylinders", tmp_path / "bare.ply", "-o", tmp_path / "c")
    expected = json.loads((tmp_path / "c" / "components.json").read_text())["components"]
    cylinders = ss.cylinders(cloud.points)
    assert len(cylinders) == len(expected) > 3
    np.testing.assert_allclose([c["radius"] for c in cylinders.components],
                               [c["radius"] for c in expected], rtol=1e-9)
    np.testing.assert_array_equal(cylinders.labels_by_persistence(),
                                  ss.read(str(tmp_path / "c" / "cloud.ply")).attributes["cylinder_id"])


def test_cylinders_one_curvature_sign_equals_the_cli(tmp_path):
    # Two overlapping unit cylinders: one_curvature_sign stops the regions at the groove between
    # them (tests/features, OneCurvatureSignStopsARegionAtAConcaveGroove), as the CLI's flag does.
    rng = np.random.default_rng(4)
    points, normals = [], []
    for y in (-0.8, 0.8):
        theta = rng.uniform(0, 2 * np.pi, 8000)
        n = np.stack([np.zeros_like(theta), np.cos(theta), np.sin(theta)], axis=1)
        p = n + np.stack([rng.uniform(0, 6, 8000), np.full(8000, y), np.zeros(8000)], axis=1)
        keep = np.hypot(p[:, 1] + y, p[:, 2]) >= 1
        points.append(p[keep])
        normals.append(n[keep])
    points, normals = np.concatenate(points), np.concatenate(normals)
    ss.write(str(tmp_path / "twins.ply"), points, normals)
    cli("cylinders", tmp_path / "twins.ply", "-o", tmp_path / "c", "--scales", 1, "--tmin", 0.3,
        "--tmax", 0.31, "--one-curvature-sign")
    expected = json.loads((tmp_path / "c" / "components.json").read_text())["components"]
    split = ss.cylinders(points, normals, scale_count=1, tmin=0.3, tmax=0.31,
                         one_curvature_sign=True)
    assert len(split) == len(expected) == 2
    np.testing.assert_allclose(sorted(c["radius"] for c in split.components),
                               sorted(c["radius"] for c in expected), rtol=1e-9)
    assert len(ss.cylinders(points, normals, scale_count=1, tmin=0.3, tmax=0.31,
                            split_by_axes=False)) < 2


def test_cylinders_trim_junctions_equals_the_cli(tmp_path):
    # A cylinder (r 0.04) standing on a plane, no normals: at one scale the wall's region grows
    # out onto the plane over the rounded foot and its tube, reading r 0.0465, is the reported
    # one; trimmed to the points curving one way (trim_junctions, the default) it is the wall.
    rng = np.random.default_rng(1)
    r, h, d, side = 0.04, 0.1, 0.002, 0.25
    nc = int(2 * np.pi * r * h / d**2)
    theta, z = rng.uniform(0, 2 * np.pi, nc), rng.uniform(0, h, nc)
    wall = np.stack([r * np.cos(theta), r * np.sin(theta), z], axis=1)
    n = int(side * side / d**2)
    plane = np.stack([rng.uniform(-side / 2, side / 2, n), rng.uniform(-side / 2, side / 2, n),
                      np.zeros(n)], axis=1)
    plane = plane[np.hypot(plane[:, 0], plane[:, 1]) > r]
    points = np.concatenate([wall, plane])
    points += rng.normal(0, 0.0005, points.shape)

    def reported_radius(c):
        best = max(c.components, key=lambda k: (k["persistence"], k["point_count"]))
        return best["radius"]

    trimmed = ss.cylinders(points)
    assert abs(reported_radius(trimmed) - r) < 0.01 * r
    assert reported_radius(ss.cylinders(points, trim_junctions=False)) > 1.1 * r
    ss.write(str(tmp_path / "stand.ply"), points)
    cli("cylinders", tmp_path / "stand.ply", "-o", tmp_path / "c", "--no-junction-trim")
    untrimmed = json.loads((tmp_path / "c" / "components.json").read_text())["components"]
    assert max(untrimmed, key=lambda k: (k["persistence"], k["point_count"]))["radius"] > 1.1 * r


def test_cylinders_narrow_tubes_equal_the_cli(tmp_path):
    # A unit tube seen over 100 degrees: under the 135 one scale needs, but found with the same
    # radius at three scales (narrow_tubes, the default), as the CLI finds it.
    rng = np.random.default_rng(2)
    theta = rng.uniform(0, np.radians(100), 6000)
    normals = np.stack([np.zeros_like(theta), np.cos(theta), np.sin(theta)], axis=1)
    points = normals + np.stack([rng.uniform(0, 6, 6000), np.zeros(6000), np.zeros(6000)], axis=1)
    found = ss.cylinders(points, normals, scales=[0.2, 0.3, 0.45])
    assert len(found) == 1
    assert found.components[0]["persistence"] == 2
    assert abs(found.components[0]["radius"] - 1) < 0.02
    assert len(ss.cylinders(points, normals, scales=[0.2, 0.3, 0.45], narrow_tubes=False)) == 0
    # Its normals turn by 100 degrees, and it lives 2 steps.
    for kwargs in ({"narrow_min_arc": 110}, {"narrow_min_persistence": 3}):
        assert len(ss.cylinders(points, normals, scales=[0.2, 0.3, 0.45], **kwargs)) == 0
    ss.write(str(tmp_path / "arc.ply"), points, normals)
    for k, (flags, count) in enumerate((((), 1), (("--no-narrow-tubes",), 0),
                                        (("--narrow-min-arc", 110), 0),
                                        (("--narrow-min-persistence", 3), 0))):
        out = tmp_path / ("c%d" % k)
        cli("cylinders", tmp_path / "arc.ply", "-o", out, "--scales", 3, "--tmin", 0.2, "--tmax",
            0.45, *flags)
        assert len(json.loads((out / "components.json").read_text())["components"]) == count


def test_cylinders_line_filter_equals_the_cli(tmp_path):
    # The thresholds of Eq. 3.5-3.7: lines a thousand scales long, or none turning or varying at
    # all (every line of the sampled tube does a little), leave no regular line and no cylinder,
    # where the defaults find the tube; the CLI's flags do the same.
    rng = np.random.default_rng(3)
    theta = rng.uniform(0, 2 * np.pi, 8000)
    normals = np.stack([np.cos(theta), np.sin(theta), np.zeros_like(theta)], axis=1)
    points = normals + np.stack([np.zeros_like(theta)] * 2 + [rng.uniform(0, 6, 8000)], axis=1)
    assert len(ss.cylinders(points, normals, scales=[0.3])) == 1
    for kwargs in ({"min_line_length": 1000}, {"max_line_curvature": 0}, {"max_line_variation": 0}):
        none = ss.cylinders(points, normals, scales=[0.3], **kwargs)
        assert len(none) == 0 and none.levels[0]["regular_lines"] == 0 < none.levels[0]["lines"]
    ss.write(str(tmp_path / "tube.ply"), points, normals)
    for flags, count in (((), 1), (("--min-line-length", 1000), 0)):
        out = tmp_path / ("c%d" % count)
        cli("cylinders", tmp_path / "tube.ply", "-o", out, "--scales", 1, "--tmin", 0.3, "--tmax",
            0.31, *flags)
        assert len(json.loads((out / "components.json").read_text())["components"]) == count


def test_cylinders_nested_links_equal_the_cli(tmp_path):
    # A unit tube whose two seams along the axis are rough: two half tubes at t = 0.1, the whole
    # at 0.9. A half and the whole fail J > 0.5, but the half lies on the whole's tube
    # (nested_link_tolerance, the default): one component over both scales, as the CLI finds it.
    rng = np.random.default_rng(1)
    theta = rng.uniform(0, 2 * np.pi, 20000)
    normals = np.stack([np.cos(theta), np.sin(theta), np.zeros_like(theta)], axis=1)
    points = normals + np.stack([np.zeros_like(theta)] * 2 + [rng.uniform(0, 6, 20000)], axis=1)
    seam = np.abs(np.sin(theta)) < np.sin(0.2)
    points[seam] += rng.normal(0, 0.1, (seam.sum(), 3))
    found = ss.cylinders(points, normals, scales=[0.1, 0.9])
    assert sorted(c["persistence"] for c in found.components) == [0, 1]
    apart = ss.cylinders(points, normals, scales=[0.1, 0.9], nested_link_tolerance=0)
    assert sorted(c["persistence"] for c in apart.components) == [0, 0, 0]
    ss.write(str(tmp_path / "seams.ply"), points, normals)
    for flags, count in (((), 2), (("--nested-link-tolerance", 0), 3)):
        out = tmp_path / ("c%d" % count)
        cli("cylinders", tmp_path / "seams.ply", "-o", out, "--scales", 2, "--tmin", 0.1, "--tmax",
            0.9, *flags)
        assert len(json.loads((out / "components.json").read_text())["components"]) == count


def test_cylinders_bad_options_and_cancel(pipes):
    _, cloud, cylinders, _ = pipes
    p = cloud.points[::20]
    for kwargs, name in [({"epsilon": 1}, "epsilon"), ({"min_anisotropy": 2}, "min_anisotropy"),
                         ({"scale_count": 0}, "scale_count"), ({"min_arc": 400}, "min_arc"),
                         ({"max_rms": 0}, "max_rms"), ({"tmin": -1}, "tmin"),
                         ({"min_sector_fill": 2}, "min_sector_fill"),
                         ({"max_section_shape": 2}, "max_section_shape"),
                         ({"max_section_shape_rms": -1}, "max_section_shape_rms"),
                         ({"max_face_sectors": -1}, "max_face_sectors"),
                         ({"min_face_lean": float("nan")}, "min_face_lean"),
                         ({"max_gap": -1}, "max_gap"),
                         ({"bridge_radius_tolerance": 1}, "bridge_radius_tolerance"),
                         ({"nested_link_tolerance": 1}, "nested_link_tolerance"),
                         ({"narrow_min_arc": -1}, "narrow_min_arc"),
                         ({"narrow_min_persistence": -1}, "narrow_min_persistence"),
                         ({"narrow_radius_spread": -1}, "narrow_radius_spread"),
                         ({"trim_keep_fraction": 2}, "trim_keep_fraction"),
                         ({"trim_min_radius": -1}, "trim_min_radius"),
                         ({"trim_against_share": 2}, "trim_against_share"),
                         ({"min_line_length": -1}, "min_line_length"),
                         ({"max_line_curvature": float("inf")}, "max_line_curvature"),
                         ({"max_line_variation": -1}, "max_line_variation"),
                         ({"scales": [0.2, 0.1]}, "scales")]:
        with pytest.raises(ss.OptionError, match=name) as e:
            ss.cylinders(p, **kwargs)
        assert "Options::" not in str(e.value)
    with pytest.raises(ss.OptionError, match="has 8 points; the automatic tmin needs more than 10"):
        ss.cylinders(p[:8], cloud.normals[:8])
    with pytest.raises(ss.OptionError, match="level 99"):
        cylinders.anisotropy(99)
    with pytest.raises(ss.OptionError, match="min_persistence"):
        cylinders.labels_by_persistence(-1)
    with pytest.raises(ss.OptionError, match="component"):
        cylinders.points(len(cylinders), 0)
    stages = []

    def stop(fraction, stage):
        stages.append(stage)
        return len(stages) < 3  # the third call cancels
    with pytest.raises(ss.Cancelled):
        ss.cylinders(cloud.points, cloud.normals, progress=stop)
    assert len(stages) == 3


def cube_obj(path, n=12):
    """A unit cube, each face an n x n grid of vertices cut into triangles (faces not welded)."""
    lines, base = [], 1
    g = np.linspace(-1, 1, n)
    for axis in range(3):
        for side in (-1.0, 1.0):
            for u in g:
                for v in g:
                    p = [u, v]
                    p.insert(axis, side)
                    lines.append("v %r %r %r" % tuple(p))
            for i in range(n - 1):
                for j in range(n - 1):
                    a = base + i * n + j
                    lines += ["f %d %d %d" % (a, a + n, a + 1), "f %d %d %d" % (a + 1, a + n, a + n + 1)]
            base += n * n
    path.write_text("\n".join(lines) + "\n")


def test_features_on_a_mesh_equal_the_cli(tmp_path):
    cube_obj(tmp_path / "cube.obj")
    cli("features", tmp_path / "cube.obj", "-o", tmp_path / "f.ply")
    vertices, triangles = ss.read_mesh(str(tmp_path / "cube.obj"))
    assert vertices.shape == (864, 3) and triangles.shape == (6 * 2 * 121, 3)
    with pytest.warns(RuntimeWarning, match="the mesh is coarse"):  # the CLI's warning, too
        features = ss.features(vertices, triangles=triangles)
    labelled = ss.read(str(tmp_path / "f.ply")).attributes
    for name in ("feature_votes", "curve_id", "convexity", "edge_id"):
        np.testing.assert_array_equal(features[name].astype(labelled[name].dtype),
                                      labelled[name], name)
    # The edges the JSON lists are those of the dict, each within one curve.
    edges = json.loads((tmp_path / "f.json").read_text())["edges"]
    assert len(edges) == len(features["edges"]) >= len(features["curves"])
    for written, edge in zip(edges, features["edges"]):
        assert written["curve"] == edge["curve"] and written["points"] == len(edge["points"])
    with pytest.raises(ValueError, match="triangles: row 0 names vertex 864"):
        ss.features(vertices, triangles=np.full((1, 3), 864))


def test_render_lines_features(data):
    cloud = ss.read(str(data / "house.ply"))
    image = ss.render(cloud.points, labels=cloud.attributes["gt_face"], width=80, height=60)
    assert image.shape == (60, 80, 3) and image.dtype == np.uint8 and image.std() > 0
    lines = ss.lines(cloud.points, scale=0.6)
    assert lines["offsets"][-1] == len(lines["vertices"]) > 0
    over = ss.render(cloud.points, labels=cloud.attributes["gt_face"], width=80, height=60,
                     lines=lines, line_color_by="k_gap")
    assert over.shape == image.shape and (over != image).any()
    with pytest.raises(ss.OptionError, match="line_color_by|no_such"):
        ss.render(cloud.points, lines=lines, line_color_by="no_such")
    features = ss.features(cloud.points)
    assert features["curve_id"].shape == (12000,) and len(features["curves"]) > 0
    assert features["salient_curvature_floor"] == max(
        0.6, 8 * features["noise_rms"] / features["spacing"])
    with pytest.raises(ss.OptionError, match="noise_curvature must be finite and >= 0"):
        ss.features(cloud.points, noise_curvature=-1)
    with pytest.raises(ss.OptionError, match="crease_reach must be finite and >= 0"):
        ss.features(cloud.points, crease_reach=-1)
    with pytest.raises(ss.OptionError, match="crease_side_margin must be finite and >= 0"):
        ss.features(cloud.points, crease_side_margin=-1)
    # Without normals, features estimates sheet normals (0.05, the sign the rays prefer) or, with
    # sheet_normals=0, PCA ones, as estimate_normals does, their sign propagated by reflection.
    for sheet, result in ((0.05, features), (0, ss.features(cloud.points, sheet_normals=0))):
        normals, _ = ss.estimate_normals(
            cloud.points, sheet=sheet, sign_by_rays=sheet > 0, reflect=True
        )
        np.testing.assert_array_equal(
            result["curve_id"], ss.features(cloud.points, normals)["curve_id"])
    with pytest.raises(ss.OptionError, match="sheet_normals must be finite and >= 0"):
        ss.features(cloud.points, sheet_normals=-1)


def test_any_layout_gives_the_same_result_and_inputs_stay_untouched():
    p = sphere_points(3000)
    before = p.copy()
    c_order = ss.curvature(p, p, scale_k=20)
    np.testing.assert_array_equal(p, before)
    fortran = ss.curvature(np.asfortranarray(p), np.asfortranarray(p), scale_k=20)
    strided = ss.curvature(np.repeat(p, 2, axis=0)[::2], p.tolist(), scale_k=20)
    for name in c_order:
        np.testing.assert_array_equal(fortran[name], c_order[name], name)
        np.testing.assert_array_equal(strided[name], c_order[name], name)
        assert c_order[name].flags.c_contiguous and c_order[name].shape == (3000,)


# ----------------------------------------------------------------------------- bad inputs
@pytest.mark.parametrize("points,error,message", [
    (np.zeros((10, 2)), ValueError, "points: expected an array of shape (N, 3), got shape (10, 2)"),
    (np.zeros((0, 3)), ValueError, "points: the array holds no points (nothing to analyse)"),
    (np.array([["a", "b", "c"]]), TypeError, "points: expected a float64 array of shape (N, 3) of numbers, got dtype <U1"),
    (np.zeros(3), ValueError, "got shape (3,)"),
])
def test_bad_arrays_raise_with_the_message(points, error, message):
    with pytest.raises(error) as e:
        ss.curvature(points, scale=0.1)
    assert message in str(e.value)


def test_large_arrays_are_checked_and_copied_exactly(tmp_path):
    # 300k georeferenced points: checked and copied in parallel blocks, which must name the first
    # bad row, keep every coordinate bit for bit, and time themselves in the summary.
    rng = np.random.default_rng(3)
    points = np.array([652000.0, 5412000.0, 300.0]) + rng.uniform(0, 100, size=(300_000, 3))
    ss.write(str(tmp_path / "big.ply"), points)
    np.testing.assert_array_equal(ss.read(str(tmp_path / "big.ply")).points, points)
    bad = points.copy()
    bad[290_000, 2] = np.nan
    bad[170_001, 0] = np.inf
    with pytest.raises(ValueError, match=r"points: row 170001: point 170002 has a NaN"):
        ss.curvature(bad, scale_k=10)
    _, summary = ss.curvature(points[:20_000], scale_k=10, summary=True)
    assert 0 <= summary["input_seconds"] < summary["library_seconds"]
    assert 0 <= summary["output_seconds"] < summary["library_seconds"]


def test_bad_values_and_options_raise_with_the_library_message(tmp_path):
    p = sphere_points(500)
    q = p.copy()
    q[5, 1] = np.inf
    with pytest.raises(ValueError, match=r"points: row 5: point 6 has a NaN, infinite or absurdly"):
        ss.curvature(q, scale=0.1)
    with pytest.raises(ss.OptionError, match=r"scale_k must be in \[1, 1000\], got 5000"):
        ss.curvature(p, scale_k=5000)
    with pytest.raises(ss.OptionError, match=r"give exactly one of .*\(scale\) or .*\(scale_k\)"):
        ss.curvature(p, scale=0.1, scale_k=10)
    with pytest.raises(ss.OptionError, match="scale_k 600 must be smaller than the number of points"):
        ss.curvature(p, scale_k=600)
    with pytest.raises(ValueError, match="estimator"):
        ss.curvature(p, scale=0.1, estimator="w9")
    with pytest.raises(ValueError, match="normals: expected 500 rows"):
        ss.curvature(p, p[:10], scale=0.1)
    with pytest.raises(ss.OptionError, match="scales"):
        ss.compute_stack(p, scales=0)
    with pytest.raises(ss.FileError, match="nothing.ply"):
        ss.read(str(tmp_path / "nothing.ply"))
    with pytest.raises(TypeError, match="int64|files hold"):
        ss.write(str(tmp_path / "x.ply"), p, attributes={"a": np.zeros(500, np.int64)})


# ---------------------------------------------------------------- cancel, Ctrl-C, the GIL
def test_progress_callback_cancels_and_leaves_no_stack(tmp_path):
    p = sphere_points(20000)
    stages = []

    def stop(fraction, stage):
        stages.append(stage)
        return False
    with pytest.raises(ss.Cancelled):
        ss.compute_stack(p, p, scales=20, path=str(tmp_path / "s.stack"), progress=stop)
    assert stages and not (tmp_path / "s.stack").exists()

    class Boom(Exception):
        pass

    def boom(fraction, stage):
        raise Boom(stage)
    with pytest.raises(Boom):
        ss.curvature(p, p, scale_k=30, progress=boom)


def test_ctrl_c_cancels_a_long_call_and_leaves_no_output(tmp_path):
    p = sphere_points(200000)
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        # About a minute without the interrupt.
        ss.compute_stack(p, p, scales=200, path=str(tmp_path / "s.stack"))
    assert time.monotonic() - start < 10
    timer.join()
    assert list(tmp_path.iterdir()) == []  # nor any temporary folder


def test_a_call_lets_other_threads_run():
    # The C++ work runs without the GIL: a pure-Python loop in another thread keeps counting
    # while a call runs. With the GIL held it would count only in the interpreter's switch
    # intervals (5 ms) around the call, a twentieth of what it counts in 0.1 s of this thread's
    # sleep; the call lasts about 0.5 s. (Two calls' progress reports interleaving in time was
    # the earlier check: under ctest -j2 one thread could get no core for the whole of the other's
    # call.) Up to three tries, should a busy machine starve the loop.
    p = sphere_points(150000)
    count = [0]
    done = threading.Event()

    def spin():
        while not done.is_set():
            count[0] += 1
    spinner = threading.Thread(target=spin)
    spinner.start()
    try:
        for _ in range(3):
            before = count[0]
            time.sleep(0.1)
            asleep = count[0] - before
            before = count[0]
            ss.curvature(p, p, scale_k=30, threads=1)
            during = count[0] - before
            if during > asleep / 2:
                break
    finally:
        done.set()
        spinner.join()
    assert during > asleep / 2, (during, asleep)


# ------------------------------------------------------- the input buffers kept between calls
def assert_same_columns(got, expected):
    assert got.keys() == expected.keys()
    for name in expected:
        assert got[name].dtype == expected[name].dtype, name
        np.testing.assert_array_equal(got[name], expected[name], name)


def test_input_buffers_are_reused_bit_for_bit_and_released():
    # Georeferenced points (recentred into the reused memory), a smaller and a larger cloud in
    # between, and a call that estimates its normals: every repeat equals a call on fresh memory.
    rng = np.random.default_rng(5)
    geo = np.array([652000.0, 5412000.0, 300.0]) + 50 * sphere_points(6000, 4)
    clouds = {"geo": (geo, sphere_points(6000, 4)), "small": (sphere_points(2000, 6), None),
              "large": (sphere_points(9000, 7), sphere_points(9000, 7))}
    expected = {}
    for name, (points, normals) in clouds.items():
        ss.release_buffers()
        expected[name] = ss.curvature(points, normals, scale_k=15)
    assert expected["geo"]["neighbors"].dtype == np.int32
    assert expected["geo"]["fit_valid"].dtype == np.uint8
    assert expected["geo"]["fit_valid"].sum() > 5900
    for name in ["geo", "small", "geo", "large", "geo", "small"]:
        points, normals = clouds[name]
        assert_same_columns(ss.curvature(points, normals, scale_k=15), expected[name])
    # The last call's buffers: its positions in the 9000 points' buffer, which it reused, and the
    # normals it estimated.
    held = ss.release_buffers()
    assert held >= (9000 + 2000) * 24
    assert ss.release_buffers() == 0
    assert_same_columns(ss.curvature(*clouds["geo"], scale_k=15), expected["geo"])
    assert ss.release_buffers() >= 2 * 6000 * 24
    # Results never share the pool's memory: a later call leaves earlier results as they were.
    first = ss.curvature(*clouds["geo"], scale_k=15)
    ss.curvature(rng.normal(size=(6000, 3)), scale_k=15)
    assert_same_columns(first, expected["geo"])


def test_integer_columns_of_a_large_cloud_equal_the_cli(tmp_path):
    # Enough points for the in-place narrowing's parallel ranges (past 32768 values, then
    # doubling), on a radius that gives every neighbour count from a few to dozens.
    p = sphere_points(150_000, 10)
    ss.write(str(tmp_path / "s.ply"), p, p)
    cli("curvature", tmp_path / "s.ply", "-o", tmp_path / "c.ply", "--scale", 0.02)
    expected = columns(tmp_path / "c.ply")
    got = ss.curvature(p, p, scale=0.02)
    assert got["neighbors"].dtype == np.int32 and got["fit_valid"].dtype == np.uint8
    assert len(np.unique(got["neighbors"])) > 20
    for name in ("neighbors", "fit_valid"):
        np.testing.assert_array_equal(got[name], expected[name], name)


def test_concurrent_calls_take_their_own_buffers():
    clouds = [(sphere_points(20000, 8), sphere_points(20000, 8)),
              (np.array([1e5, -2e5, 10.0]) + sphere_points(15000, 9), None)]
    expected = []
    for points, normals in clouds:
        ss.release_buffers()
        expected.append(ss.curvature(points, normals, scale_k=12))
    start = threading.Barrier(2)
    failures = []

    def run(k):
        start.wait()
        try:
            for _ in range(4):
                assert_same_columns(ss.curvature(*clouds[k], scale_k=12, threads=1), expected[k])
        except AssertionError as e:  # raised in the thread: reported by the test below
            failures.append(e)
    threads = [threading.Thread(target=run, args=(k,)) for k in (0, 1)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not failures
    assert ss.release_buffers() > 0


# -------------------------------------------------------------------------- parametrization
def test_parametrize_equals_the_cli(tmp_path):
    cli("generate", "bumpy-disk", "-n", 4000, "--noise", 0.001, "-o", tmp_path / "d.ply")
    cli("parametrize", tmp_path / "d.ply", "--scales", 15, "-o", tmp_path / "p.ply")
    written = ss.read(str(tmp_path / "p.ply"))
    cloud = ss.read(str(tmp_path / "d.ply"))
    got = ss.parametrize(cloud.points, cloud.normals, scales=15)
    assert got["domain"] == "plane" and got["direction"] is None
    assert got["uv"].shape == (4000, 2)
    np.testing.assert_allclose(got["uv"][:, 0], written.attributes["u"], rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(got["uv"][:, 1], written.attributes["v"], rtol=1e-9, atol=1e-9)
    np.testing.assert_array_equal(got["fold"], written.attributes["fold"])
    assert got["folds"] == 0 and got["overlaps"] == 0 and got["one_to_one"]
    d = ss.distortion(cloud.points, cloud.normals, uv=got["uv"], scales_k=[16, 64])
    cli("distortion", tmp_path / "d.ply", tmp_path / "p.ply", "--scales-k", "16,64",
        "-o", tmp_path / "e.ply")
    summary = json.loads((tmp_path / "e.json").read_text())
    expected = summary["sizes"]
    np.testing.assert_allclose(d["median_stretch"], summary["median_stretch"], rtol=1e-6)
    assert d["stretch"].shape == (4000,) and 1 <= d["median_stretch"] < 1.2
    for g, e in zip(d["sizes"], expected):
        assert g["neighbors"] == e["neighbors"]
        np.testing.assert_allclose(g["median_conformal"], e["median_conformal"], rtol=1e-6)
        np.testing.assert_allclose(g["median_authalic"], e["median_authalic"], rtol=1e-6)
        assert g["conformal"].shape == (4000,) and g["conformal"].dtype == np.float32


def test_parametrize_relaxation_options_equal_the_cli(tmp_path):
    cli("generate", "relief", "-n", 4000, "-o", tmp_path / "r.ply")
    cloud = ss.read(str(tmp_path / "r.ply"))
    runs = {"thesis": (["--relax", 0], dict(relax=0)),
            "conformal": (["--conformal", "--relax-rounds", 2], dict(rigidity=0, sphere_rigidity=0, relax_rounds=2))}
    maps = {}
    for name, (flags, kwargs) in runs.items():
        cli("parametrize", tmp_path / "r.ply", "--scales", 15, *flags, "-o", tmp_path / f"{name}.ply")
        written = ss.read(str(tmp_path / f"{name}.ply"))
        got = ss.parametrize(cloud.points, cloud.normals, scales=15, **kwargs)
        np.testing.assert_allclose(got["uv"][:, 0], written.attributes["u"], rtol=1e-9, atol=1e-9)
        summary = json.loads((tmp_path / f"{name}.json").read_text())["relaxation"]
        assert summary["applied"] == got["relaxed"] == (name != "thesis")
        maps[name] = got["uv"]
    default = ss.parametrize(cloud.points, cloud.normals, scales=15)
    assert default["relaxed"]
    assert not np.allclose(default["uv"], maps["thesis"]) and not np.allclose(default["uv"], maps["conformal"])
    # Large spheres only: a plane domain of 4000 points is relaxed the same either way.
    same = ss.parametrize(cloud.points, cloud.normals, scales=15, relax_large_spheres=True)
    np.testing.assert_array_equal(same["uv"], default["uv"])
    with pytest.raises(ss.OptionError, match="relax_rounds"):
        ss.parametrize(cloud.points, cloud.normals, relax_rounds=0)
    with pytest.raises(ss.OptionError, match="sphere_rigidity must be in"):
        ss.parametrize(cloud.points, cloud.normals, sphere_rigidity=2)
    bad = subprocess.run([CLI, "parametrize", str(tmp_path / "r.ply"), "--relax-rounds", "0", "-o",
                          str(tmp_path / "x.ply"), "-q"], capture_output=True, text=True)
    assert bad.returncode == 2 and "--relax-rounds" in bad.stderr


def test_parametrize_a_sphere_and_bad_arguments():
    p = sphere_points(3000, 4) * 2 + [10, 0, 0]
    got = ss.parametrize(p, (p - [10, 0, 0]) * 3, scales=10, relax=0)  # normals of any length
    assert got["domain"] == "sphere" and got["uv"] is None
    np.testing.assert_allclose(got["radius"], 2, rtol=1e-6)
    np.testing.assert_allclose(got["direction"], (p - [10, 0, 0]) / 2, atol=1e-6)
    relaxed = ss.parametrize(p, (p - [10, 0, 0]) * 3, scales=10)  # an exact sphere stays put
    assert relaxed["relaxed"]
    np.testing.assert_allclose(relaxed["radius"], 2, rtol=1e-3)
    np.testing.assert_allclose(relaxed["direction"], (p - [10, 0, 0]) / 2, atol=1e-3)
    assert got["longitude"].shape == (3000,)
    with pytest.raises(ss.OptionError, match="scales"):
        ss.parametrize(p, scales=1)
    with pytest.raises(ss.OptionError, match="expected auto, plane or sphere"):
        ss.parametrize(p, domain="cone")
    with pytest.raises(ss.OptionError, match="either uv"):
        ss.distortion(p)
    with pytest.raises(ss.OptionError, match="scales_k"):
        ss.distortion(p, direction=p, scales_k=[2])
    with pytest.raises(ValueError):
        ss.distortion(p, uv=np.zeros((10, 2)))
    with pytest.raises(ss.Cancelled):
        ss.parametrize(p, scales=10, progress=lambda f, stage: False)


def test_a_nearly_closed_surface_gets_the_fold_hint(tmp_path):
    # A unit box whose top has a square hole 0.8 wide: the rays leak through it at about 11% of
    # the points, over the 5% of a closed surface and under most open scans. 'auto' looks for
    # folds there (a thin part's rim leaks the same way), finds the hole's rim, which has the box
    # behind it (none of its points sees out on both sides), leaves it out and says that 'on'
    # would take it; with a hole 0.5 wide the rays find it closed and nothing is said; an open
    # sheet reads open at most of its points and nothing is said either.
    def box_with_hole(hole, n=20000, seed=5):
        rng = np.random.default_rng(seed)
        points = rng.uniform(-0.5, 0.5, (n, 3))
        face = rng.integers(0, 3, n)
        side = np.where(rng.random(n) < 0.5, -0.5, 0.5)
        points[np.arange(n), face] = side
        top = (face == 2) & (side > 0)
        return points[~(top & (np.abs(points[:, 0]) < hole / 2) & (np.abs(points[:, 1]) < hole / 2))]

    def hints(points):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            result = ss.features(points)
        return result, [str(w.message) for w in caught if "fold_borders='on'" in str(w.message)]

    result, said = hints(box_with_hole(0.8))
    assert result["fold_borders"] is False and len(said) == 1 and result["fold_points"] == 0
    assert 0 <= result["fold_see_through"] < 0.1 and "edges of an opening" in said[0]
    share = float(said[0].split("open at ")[1].split("%")[0])
    assert 5 < share < 15 and abs(100 * result["rays_open_share"] - share) <= 0.05
    np.savetxt(tmp_path / "holed.xyz", box_with_hole(0.8))
    run = subprocess.run([CLI, "features", str(tmp_path / "holed.xyz"), "-o", str(tmp_path / "holed.ply")],
                         capture_output=True, text=True)
    assert run.returncode == 0 and "--fold-borders on" in run.stderr
    summary = json.loads((tmp_path / "holed.json").read_text())
    assert summary["rays_open_share"] == pytest.approx(result["rays_open_share"])
    assert summary["fold_see_through"] == pytest.approx(result["fold_see_through"])
    assert summary["parameters"]["fold_borders"] is False
    # Given normals, nothing was measured: null, None.
    assert ss.features(box_with_hole(0.8), normals=np.tile([0.0, 0.0, 1.0], (1, 1)).repeat(
        len(box_with_hole(0.8)), 0))["rays_open_share"] is None
    # A box with a thin fin (a bracket's flange, one sheet 0.6 x 1 on a face): nearly closed too
    # (the fin's points see out on both sides), and the fin's free rim does as well, so auto takes
    # it as folds, through the CLI alike, and nothing is said.
    rng = np.random.default_rng(6)
    fin = np.column_stack([0.5 + 0.6 * rng.random(1800), np.zeros(1800), rng.uniform(-0.5, 0.5, 1800)])
    bracket = np.vstack([box_with_hole(0.0, n=18200), fin])
    result, said = hints(bracket)
    assert 0.05 < result["rays_open_share"] < 0.15 and said == []
    assert result["fold_borders"] is True and result["fold_see_through"] > 0.9
    half = 0.5 * result["spacing"]  # the fin's free rim: its far edge and its top and bottom
    on_rim = np.abs(bracket[:, 1]) < 0.01
    on_rim &= (bracket[:, 0] > 1.1 - half) | ((bracket[:, 0] > 0.6) & (np.abs(bracket[:, 2]) > 0.5 - half))
    assert result["fold_points"] > 100 and np.mean(result["convexity"][on_rim] == 1) > 0.8
    np.savetxt(tmp_path / "bracket.xyz", bracket)
    run = subprocess.run([CLI, "features", str(tmp_path / "bracket.xyz"), "-o", str(tmp_path / "bracket.ply")],
                         capture_output=True, text=True)
    assert run.returncode == 0 and "nearly closed and its borders thin" in run.stderr
    summary = json.loads((tmp_path / "bracket.json").read_text())
    assert summary["parameters"]["fold_borders"] is True and summary["fold_points"] == result["fold_points"]
    result, said = hints(box_with_hole(0.5))
    assert result["fold_borders"] is True and said == [] and result["rays_open_share"] <= 0.05
    assert result["fold_see_through"] is None  # closed: every border is a fold, nothing measured
    rng = np.random.default_rng(4)
    sheet = np.column_stack([rng.random(8000), rng.random(8000), rng.normal(0, 0.002, 8000)])
    result, said = hints(sheet)
    assert result["fold_borders"] is False and said == []


def test_fold_borders_follow_the_rays_or_the_keyword(tmp_path):
    # A closed box without normals: the rays find it closed, so 'auto' looks for folds (a box has
    # none: its fits see its creases), as the CLI does; the summary says it applied.
    cli("generate", "box", "-n", 12000, "--seed", 2, "-o", tmp_path / "generated.xyz")
    np.savetxt(tmp_path / "box.xyz", ss.read(str(tmp_path / "generated.xyz")).points)
    box = ss.read(str(tmp_path / "box.xyz"))
    assert box.normals is None
    cli("features", tmp_path / "box.xyz", "-o", tmp_path / "box.ply")
    summary = json.loads((tmp_path / "box.json").read_text())
    result = ss.features(box.points)
    assert result["fold_borders"] is True
    assert summary["parameters"]["fold_borders"] is True
    assert summary["fold_points"] == result["fold_points"]
    written = ss.read(str(tmp_path / "box.ply")).attributes["curve_id"]
    np.testing.assert_array_equal(result["curve_id"].astype(written.dtype), written)
    # An open noisy sheet: 'auto' leaves its border alone (where a scan stops); 'on' makes it a
    # convex curve around the sheet, and nothing inside it.
    rng = np.random.default_rng(4)
    sheet = np.column_stack([rng.random(8000), rng.random(8000), rng.normal(0, 0.002, 8000)])
    auto = ss.features(sheet)
    assert auto["fold_borders"] is False and auto["fold_points"] == 0
    on = ss.features(sheet, fold_borders="on")
    assert on["fold_borders"] is True and on["fold_points"] > 0
    labelled = sheet[on["curve_id"] >= 0]
    to_border = np.minimum.reduce([labelled[:, 0], 1 - labelled[:, 0],
                                   labelled[:, 1], 1 - labelled[:, 1]])
    assert len(labelled) > 0 and to_border.max() < 3 * on["spacing"]
    assert set(on["convexity"][on["curve_id"] >= 0]) == {1}
    off = ss.features(sheet, fold_borders="off")
    assert off["fold_points"] == 0
    with pytest.raises(ss.OptionError, match="fold_borders"):
        ss.features(sheet, fold_borders="yes")
    with pytest.raises(ss.OptionError, match="fold_reach"):
        ss.features(sheet, fold_reach=0)
    with pytest.raises(ss.OptionError, match="fold_share"):
        ss.features(sheet, fold_share=2)


def thin_rim_plate(rng):
    """A unit square plate sloping by 10 degrees to a rim 4 mm thick, with exact normals (the C++
    test TheBandOfAThinRimEndsAtItsOutermostPoints's)."""
    xy = rng.random((16000, 2))
    side = np.where(np.arange(16000) % 2 == 1, 1.0, -1.0)
    to_x, to_y = np.minimum(xy[:, 0], 1 - xy[:, 0]), np.minimum(xy[:, 1], 1 - xy[:, 1])
    slope = np.tan(np.radians(10))
    points = np.column_stack([xy, side * (0.002 + slope * np.minimum(to_x, to_y))])
    out = np.where((to_x < to_y)[:, None],
                   np.column_stack([np.sign(xy[:, 0] - 0.5), np.zeros(16000), np.zeros(16000)]),
                   np.column_stack([np.zeros(16000), np.sign(xy[:, 1] - 0.5), np.zeros(16000)]))
    normals = np.column_stack([np.zeros(16000), np.zeros(16000), side]) + slope * out
    # The rim itself, a strip 4 mm wide around the square.
    t, z = rng.random(400), rng.uniform(-0.002, 0.002, 400)
    k = np.arange(400) % 4
    rim = np.column_stack([np.where(k < 2, t, k - 2), np.where(k < 2, k, t), z])
    rim_normals = np.zeros((400, 3))
    rim_normals[k < 2, 1] = np.where(k[k < 2] == 0, -1.0, 1.0)
    rim_normals[k >= 2, 0] = np.where(k[k >= 2] == 2, -1.0, 1.0)
    normals = normals / np.linalg.norm(normals, axis=1)[:, None]
    return np.vstack([points, rim]), np.vstack([normals, rim_normals])


def test_the_band_of_a_thin_rim_ends_at_its_outermost_points(tmp_path):
    # The faces' planes meet beyond the rim, so no crease line is found there: rim_lines trims the
    # band to the plate within crease_half_width x e of its outermost points (the default), and
    # the CLI's summary says which was used.
    points, normals = thin_rim_plate(np.random.default_rng(3))

    def beyond(result):
        labelled = points[result["curve_id"] >= 0]
        near_x = np.minimum(labelled[:, 0], 1 - labelled[:, 0])
        near_y = np.minimum(labelled[:, 1], 1 - labelled[:, 1])
        away = near_x + near_y >= 4 * result["spacing"]  # not at a corner
        return np.mean(np.minimum(near_x, near_y)[away] > result["spacing"])

    rim = ss.features(points, normals)
    centreline = ss.features(points, normals, rim_lines=False)
    assert beyond(centreline) > 0.04 and beyond(rim) < 0.005
    np.savetxt(tmp_path / "plate.xyz", np.column_stack([points, normals]),
               header="x y z nx ny nz", comments="")
    cli("features", tmp_path / "plate.xyz", "-o", tmp_path / "plate.ply", "--no-rim-lines")
    summary = json.loads((tmp_path / "plate.json").read_text())
    assert summary["parameters"]["rim_lines"] is False
    written = ss.read(str(tmp_path / "plate.ply")).attributes["curve_id"]
    np.testing.assert_array_equal(centreline["curve_id"].astype(written.dtype), written)
