// End-to-end checks of the `scalespace` program: exit codes, one-line errors, the curvature
// output's layout (one row per input point, in order, named columns) and its values on a sphere.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "cli/CliTestSupport.hpp"
#include "scalespace/fit/CurvatureEstimation.hpp"
#include "scalespace/io/CloudIO.hpp"

namespace fs = std::filesystem;
using namespace scalespace;

namespace {

using test::Cli;
using test::Result;
using test::run;

TEST_F(Cli, HelpAndVersionSucceed) {
  EXPECT_EQ(run("--help").code, 0);
  EXPECT_EQ(run("curvature --help").code, 0);
  EXPECT_EQ(run("--version").code, 0);
}

TEST_F(Cli, WrongOptionsGiveOneLineAndNonZeroExit) {
  for (const std::string args :
       {"curvature", "curvature nope.ply -o x.ply --scale 1", "frobnicate", "curvature --bogus"}) {
    const Result r = run(args);
    EXPECT_NE(r.code, 0) << args;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
  }
}

TEST_F(Cli, GenerateNamesEveryShapeAndBoundsThePointCount) {
  Result r = run("generate blah -q -o " + path("g.ply"));
  EXPECT_EQ(r.code, 2) << r.err;
  // Every shape the command takes, not only the five analytic surfaces.
  for (const char* shape : {"sphere", "pipes", "house", "ring"})
    EXPECT_NE(r.err.find(shape), std::string::npos) << shape << ": " << r.err;
  // A count no machine holds: a clear bound, not "std::bad_alloc".
  r = run("generate sphere -n 4000000000 -q -o " + path("g.ply"));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("--points must be in [1, 100000000], got 4000000000"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(path("g.ply")));
}

TEST_F(Cli, OrientTakesTheViewpointQuotedAsTheHelpShowsIt) {
  ASSERT_EQ(run("generate sphere -n 500 -q -o " + path("s.ply")).code, 0);
  for (const std::string orient : {"viewpoint 0 0 10", "'viewpoint 0 0 10'", "'mst'"}) {
    const Result r =
        run("normals " + path("s.ply") + " --orient " + orient + " -q -o " + path("n.ply"));
    EXPECT_EQ(r.code, 0) << orient << ": " << r.err;
  }
  const Result r =
      run("normals " + path("s.ply") + " --orient 'viewpoint 0 0' -q -o " + path("m.ply"));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("--orient takes"), std::string::npos) << r.err;
}

TEST_F(Cli, StackInfoOfADamagedManifestSaysWhatIsWrong) {
  ASSERT_EQ(run("generate sphere -n 300 -q -o " + path("s.ply")).code, 0);
  ASSERT_EQ(run("scales " + path("s.ply") + " -o " + path("s.stack") + " --scales 2 -q").code, 0);
  std::ofstream(path("s.stack/manifest.json")) << "{\n";
  const Result r = run("stack-info " + path("s.stack"));
  EXPECT_EQ(r.code, 1) << r.err;
  // Not "no manifest.json": it is there, and unreadable.
  EXPECT_EQ(r.err.find("no manifest.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("manifest.json"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("invalid JSON"), std::string::npos) << r.err;
}

TEST_F(Cli, CurvatureOfASphereKeepsRowsAndNamesColumns) {
  ASSERT_EQ(run("generate sphere -n 20000 --seed 3 -q -o " + path("s.ply")).code, 0);
  const PointCloud input = readCloud(path("s.ply"));
  const Result r = run("curvature " + path("s.ply") + " -o " + path("c.ply") + " --scale 0.2");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("done in"), std::string::npos);  // final line with the time taken
  ASSERT_TRUE(fs::exists(path("c.json")));

  const PointCloud out = readCloud(path("c.ply"));
  ASSERT_EQ(out.size(), input.size());
  for (std::size_t i = 0; i < input.size(); i += 997)
    EXPECT_EQ(out.absolutePosition(i), input.absolutePosition(i));  // input order kept
  // The input's columns come first, then in_n*, then the documented curvature columns.
  const auto& attrs = out.attributes();
  ASSERT_GE(attrs.size(), input.attributes().size() + 3);
  for (std::size_t c = 0; c < input.attributes().size(); ++c)
    EXPECT_EQ(attrs[c].name, input.attributes()[c].name);
  std::vector<std::string> tail;
  for (std::size_t c = input.attributes().size() + 3; c < attrs.size(); ++c)
    tail.push_back(attrs[c].name);
  std::vector<std::string> expected;
  for (const std::string& n : curvatureColumnNames())
    if (n != "nx" && n != "ny" && n != "nz") expected.push_back(n);  // read back as normals
  EXPECT_EQ(tail, expected);
  ASSERT_TRUE(out.hasNormals());

  // Unit sphere with outward normals: H = k1 = k2 = +1 (docs/THESIS_NOTES.md, sign convention).
  const auto* h = out.findAttribute("curv_mean");
  const auto* valid = out.findAttribute("fit_valid");
  for (std::size_t i = 0; i < out.size(); i += 101) {
    ASSERT_EQ(valid->values[i], 1.0);
    EXPECT_NEAR(h->values[i], 1.0, 0.05);
    EXPECT_GT(out.normals()[i].dot(input.normals()[i]), 0.999);
  }
}

TEST_F(Cli, ScalesWritesCompactByDefaultAndFloat32OnRequest) {
  ASSERT_EQ(run("generate sphere -n 2000 --seed 3 -q -o " + path("s.ply")).code, 0);
  auto info = [&](const std::string& stack) {
    const std::string out = path("info.txt");
    const std::string cmd =
        std::string(SCALESPACE_CLI_PATH) + " stack-info " + stack + " >" + out + " 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0);
    std::ifstream in(out);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  };
  Result r = run("scales " + path("s.ply") + " -o " + path("c.stack") + " --scales 2 -q");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(info(path("c.stack")).find("encoding: compact, 19.125 bytes per point per scale"),
            std::string::npos)
      << info(path("c.stack"));
  r = run("scales " + path("s.ply") + " -o " + path("f.stack") +
          " --scales 2 -q --encoding float32");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(info(path("f.stack")).find("encoding: float32, 83.000 bytes per point per scale"),
            std::string::npos)
      << info(path("f.stack"));
  r = run("export " + path("c.stack") + " --scale 1 -o " + path("c1.ply"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(readCloud(path("c1.ply")).size(), 2000u);
  // Without -q: a per-scale table at the end (one line per scale after its header).
  r = run("scales " + path("s.ply") + " -o " + path("t.stack") + " --scales 3");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto header = r.err.find("  scale        t  samples  mean_nbrs");
  ASSERT_NE(header, std::string::npos) << r.err;
  const auto summary = r.err.find("2000 points x 3 scales");
  ASSERT_NE(summary, std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin() + std::ptrdiff_t(header),
                       r.err.begin() + std::ptrdiff_t(summary), '\n'),
            4);
  r = run("scales " + path("s.ply") + " -o " + path("x.stack") + " --encoding float8");
  EXPECT_NE(r.code, 0);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

TEST_F(Cli, ExportCarriesTheInputAttributesOfTheStacksCloud) {
  // A Stairs scene has a ground-truth attribute (gt_face); export --input carries it, in order.
  ASSERT_EQ(run("generate stairs -n 3000 --seed 2 -q -o " + path("st.ply")).code, 0);
  ASSERT_EQ(run("generate stairs -n 3000 --seed 3 -q -o " + path("other.ply")).code, 0);
  Result r = run("scales " + path("st.ply") + " -o " + path("st.stack") + " --scales 2 -q");
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("export " + path("st.stack") + " --scale 1 -o " + path("e.ply") + " --input " +
          path("st.ply"));
  ASSERT_EQ(r.code, 0) << r.err;
  const PointCloud in = readCloud(path("st.ply")), out = readCloud(path("e.ply"));
  ASSERT_EQ(out.size(), in.size());
  const auto* face = out.findAttribute("gt_face");
  ASSERT_NE(face, nullptr);
  EXPECT_EQ(face->values, in.findAttribute("gt_face")->values);
  // The input's attributes come first, then the scale's quantities.
  EXPECT_EQ(out.attributes().front().name, "gt_face");
  EXPECT_NE(out.findAttribute("curv_mean"), nullptr);
  // Another cloud of the same size is refused, naming it; --input needs --scale.
  r = run("export " + path("st.stack") + " --scale 1 -o " + path("x.ply") + " --input " +
          path("other.ply"));
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("other.ply"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("x.ply")));
  r = run("export " + path("st.stack") + " --point 1 --input " + path("st.ply"));
  EXPECT_EQ(r.code, 2) << r.err;
  r = run("export " + path("st.stack") + " --scale 1 -o " + path("x.ply") + " --drop-invalid");
  EXPECT_EQ(r.code, 2) << r.err;
}

TEST_F(Cli, CurvatureWarnsOfAScaleReachingTheDiagonalOnceAndBeforeTheWork) {
  ASSERT_EQ(run("generate sphere -n 800 --seed 3 -q -o " + path("s.ply")).code, 0);
  const Result r = run("curvature " + path("s.ply") + " -o " + path("c.ply") + " --scale 1e6");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::size_t warning = r.err.find("warning: the scale 1e+06 reaches the cloud's diagonal");
  ASSERT_NE(warning, std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("reaches the cloud's diagonal", r.err.find('\n', warning)),
            std::string::npos)
      << r.err;
  EXPECT_LT(warning, r.err.find("done in"));
  std::ifstream json(path("c.json"));
  const std::string text((std::istreambuf_iterator<char>(json)), {});
  EXPECT_NE(text.find("reaches the cloud's diagonal"), std::string::npos);
  const Result fine = run("curvature " + path("s.ply") + " -o " + path("d.ply") + " --scale 0.3");
  ASSERT_EQ(fine.code, 0) << fine.err;
  EXPECT_EQ(fine.err.find("warning"), std::string::npos) << fine.err;
}

TEST_F(Cli, CurvatureEstimatesNormalsWhenMissingAndNeverOverwritesItsInput) {
  {
    std::ofstream xyz(path("plane.xyz"));
    for (int i = 0; i < 60; ++i)
      for (int j = 0; j < 60; ++j) xyz << i * 0.1 << ' ' << j * 0.1 << ' ' << 0.0 << '\n';
  }
  const auto before = fs::file_size(path("plane.xyz"));
  Result r = run("curvature " + path("plane.xyz") + " -o " + path("plane.xyz") + " --scale 0.5");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(fs::file_size(path("plane.xyz")), before);

  r = run("curvature " + path("plane.xyz") + " -o " + path("plane.ply") + " --scale-k 20");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("no normals"), std::string::npos);
  const PointCloud out = readCloud(path("plane.ply"));
  const auto* kmax = out.findAttribute("curv_max");
  for (std::size_t i = 0; i < out.size(); ++i) {
    EXPECT_NEAR(std::abs(out.normals()[i].z()), 1.0, 1e-6);
    EXPECT_NEAR(kmax->values[i], 0.0, 1e-6);
  }
}

TEST_F(Cli, BadFilesGiveAClearErrorNamingTheFile) {
  {
    std::ofstream bad(path("bad.ply"));
    bad << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n";
  }
  const Result r = run("curvature " + path("bad.ply") + " -o " + path("o.ply") + " --scale 1");
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("bad.ply"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("o.ply")));
}

TEST_F(Cli, ThreadCountDoesNotChangeTheResult) {
  ASSERT_EQ(run("generate saddle -n 5000 -q -o " + path("s.ply")).code, 0);
  ASSERT_EQ(
      run("curvature -q " + path("s.ply") + " -o " + path("a.ply") + " --scale 0.3 --threads 1")
          .code,
      0);
  ASSERT_EQ(
      run("curvature -q " + path("s.ply") + " -o " + path("b.ply") + " --scale 0.3 --threads 2")
          .code,
      0);
  std::ifstream a(path("a.ply"), std::ios::binary), b(path("b.ply"), std::ios::binary);
  std::stringstream sa, sb;
  sa << a.rdbuf();
  sb << b.rdbuf();
  EXPECT_EQ(sa.str(), sb.str());
}

}  // namespace

TEST_F(Cli, PlanesEstimateNormalsWhenMissingAndFindTheBoxFaces) {
  // A 2 x 1.5 x 1 box surface without normals, as a scanner's XYZ file would be.
  {
    std::ofstream xyz(path("box.xyz"));
    const double size[3] = {2.0, 1.5, 1.0}, step = 0.05;
    for (int axis = 0; axis < 3; ++axis)
      for (int side = 0; side < 2; ++side) {
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        for (double a = 0; a <= size[u] + 1e-9; a += step)
          for (double b = 0; b <= size[v] + 1e-9; b += step) {
            double p[3];
            p[axis] = side * size[axis], p[u] = a, p[v] = b;
            xyz << p[0] << ' ' << p[1] << ' ' << p[2] << '\n';
          }
      }
  }
  const Result r = run("planes " + path("box.xyz") + " -o " + path("planes") + " --scales 8");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("no normals"), std::string::npos);
  std::ifstream json(path("planes/components.json"));
  std::stringstream ss;
  ss << json.rdbuf();
  const auto doc = nlohmann::json::parse(ss.str());
  // Every face of the box is a component: at least six planes, with normals along the axes.
  ASSERT_TRUE(doc.contains("components"));
  int axisAligned = 0;
  for (const auto& c : doc["components"]) {
    const auto& n = c["normal"];
    const double m = std::max(
        {std::abs(n[0].get<double>()), std::abs(n[1].get<double>()), std::abs(n[2].get<double>())});
    if (m > 0.999) ++axisAligned;
  }
  EXPECT_GE(axisAligned, 6);
}

TEST_F(Cli, APcdViewpointIsShownAndTheEstimatedNormalsFaceIt) {
  // A ground seen from below (a scan in its sensor's frame): `info` shows the PCD's VIEWPOINT,
  // `normals` turns the tree's parts to face it (the +z seeds alone would point them up), and a
  // PCD output keeps it.
  std::vector<Vec3> ground;
  for (int a = 0; a < 60; ++a)
    for (int b = 0; b < 60; ++b)
      ground.emplace_back(0.02 * a, 0.02 * b, 0.05 * std::sin(0.1 * a) * std::cos(0.15 * b));
  PointCloud cloud;
  cloud.setAbsolutePositions(ground);
  cloud.setViewpoint(Vec3(0.6, 0.6, -1));
  writeCloud(cloud, path("g.pcd"));
  Result r = run("info " + path("g.pcd"));
  EXPECT_NE(r.out.find("viewpoint   0.6 0.6 -1 (estimated normals face it)"), std::string::npos)
      << r.out;
  r = run("normals " + path("g.pcd") + " -o " + path("n.pcd"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("the tree's parts face the file's VIEWPOINT"), std::string::npos) << r.err;
  const PointCloud out = readCloud(path("n.pcd"));
  ASSERT_TRUE(out.viewpoint());
  EXPECT_EQ(*out.viewpoint(), *cloud.viewpoint());
  std::size_t down = 0;
  for (std::size_t i = 0; i < out.size(); ++i) down += out.normals()[i].z() < 0 ? 1 : 0;
  EXPECT_EQ(down, out.size());
}

TEST_F(Cli, PwnIsWrittenWhereNormalsAreTheResultAndRefusedWhereColumnsAre) {
  // CGAL's points with normals: `normals` writes one that reads back with the same normals;
  // `curvature`, whose result is columns a .pwn cannot hold, is refused before any work.
  ASSERT_EQ(run("generate sphere -n 500 -q -o " + path("s.ply")).code, 0);
  Result r = run("normals " + path("s.ply") + " -q -o " + path("s.pwn"));
  ASSERT_EQ(r.code, 0) << r.err;
  const PointCloud pwn = readCloud(path("s.pwn")), ply = readCloud(path("s.ply"));
  ASSERT_EQ(pwn.size(), ply.size());
  ASSERT_TRUE(pwn.hasNormals());
  EXPECT_TRUE(pwn.attributes().empty());
  std::size_t outward = 0;
  for (std::size_t i = 0; i < pwn.size(); ++i)
    outward += pwn.normals()[i].dot(pwn.absolutePosition(i)) > 0 ? 1 : 0;
  EXPECT_EQ(outward, pwn.size());
  r = run("curvature " + path("s.pwn") + " --scale 0.3 -q -o " + path("c.pwn"));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("a .pwn holds positions and normals only"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(path("c.pwn")));
}
