// `scalespace render --lines`: polylines drawn over the cloud.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "cli/CliTestSupport.hpp"
#include "scalespace/io/CloudIO.hpp"
#include "scalespace/io/Polylines.hpp"
#include "scalespace/render/PngWriter.hpp"

namespace fs = std::filesystem;
using namespace scalespace;

namespace {

using test::Cli;
using test::Result;
using test::run;

int countColor(const Image& image, const Rgb& color) {
  int n = 0;
  for (const Rgb& p : image.pixels) n += p == color;
  return n;
}

TEST_F(Cli, RenderDrawsLinesAndRefusesAMissingLinesFile) {
  ASSERT_EQ(run("generate sphere -n 3000 -q -o " + path("s.ply")).code, 0);
  const PointCloud sphere = readCloud(path("s.ply"));
  Vec3 lo, hi;
  sphere.bounds(lo, hi);
  const Vec3 centre = sphere.origin() + 0.5 * (lo + hi);
  const double radius = 0.5 * (hi.x() - lo.x());
  // The equator, closed, with a column to colour it by.
  PolylineSet equator;
  std::vector<Vec3> ring;
  for (int k = 0; k < 64; ++k) {
    const double a = 2 * M_PI * k / 64;
    ring.push_back(centre + radius * Vec3(std::cos(a), std::sin(a), 0));
  }
  equator.vertices.setAbsolutePositions(ring);
  auto& angle = equator.vertices.addAttribute("angle", ScalarType::Float32);
  for (int k = 0; k < 64; ++k) angle.values[std::size_t(k)] = k;
  equator.offsets = {0, 64};
  equator.closed = {1};
  writePolylines(equator, path("equator.ply"));

  const std::string render =
      "render " + path("s.ply") + " --view front --size 200x200 --no-shading -q ";
  Result r = run(render + "-o " + path("plain.png"));
  ASSERT_EQ(r.code, 0) << r.err;
  r = run(render + "-o " + path("lines.png") + " --lines " + path("equator.ply"));
  ASSERT_EQ(r.code, 0) << r.err;
  const Rgb lineRed{230, 25, 25};
  EXPECT_EQ(countColor(readPng(path("plain.png")), lineRed), 0);
  // The front half of the ring shows across the sphere (about 180 pixels wide, 3 high).
  EXPECT_GT(countColor(readPng(path("lines.png")), lineRed), 300);
  r = run(render + "-o " + path("angle.png") + " --lines " + path("equator.ply") +
          " --line-color-by angle");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(countColor(readPng(path("angle.png")), lineRed), 0);
  EXPECT_NE(readPng(path("angle.png")).pixels, readPng(path("plain.png")).pixels);

  // A missing lines file: one line naming it, exit 1, no image.
  r = run(render + "-o " + path("missing.png") + " --lines " + path("nope.ply"));
  EXPECT_EQ(r.code, 1);
  EXPECT_EQ(r.err, "scalespace: error: " + path("nope.ply") +
                       ": cannot open the file (check that it exists and is readable)\n");
  EXPECT_FALSE(fs::exists(path("missing.png")));
  // An attribute the lines lack is named with its flag; --line-color-by needs --lines.
  r = run(render + "-o " + path("x.png") + " --lines " + path("equator.ply") +
          " --line-color-by kappa1");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--line-color-by 'kappa1' is not a vertex attribute of the lines (they "
                       "have: angle"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(run(render + "-o " + path("x.png") + " --line-color-by angle").code, 2);
  EXPECT_FALSE(fs::exists(path("x.png")));
}

}  // namespace
