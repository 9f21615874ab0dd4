#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <vector>

#include "scalespace/core/Error.hpp"
#include "scalespace/render/ColorMap.hpp"
#include "scalespace/render/LineRenderer.hpp"

using namespace scalespace;

namespace {

const Rgb kRed{255, 0, 0};

/// Front view (looking along +y: x to the right, z up, depth = y) of a cloud whose bounding box
/// is x, z in [0, 10]: 10 pixels per unit, x -> column 10 x, z -> row 100 - 10 z.
RenderOptions frontView(int pointRadius) {
  RenderOptions options;
  options.width = options.height = 100;
  options.margin = 0;
  options.view = "front";
  options.pointRadius = pointRadius;
  options.shading = false;
  return options;
}

/// The wall y = 0, x and z in [0, 10], sampled every 0.25 (splats of radius 3 close it).
PointCloud wall() {
  std::vector<Vec3> points;
  for (int i = 0; i <= 40; ++i)
    for (int k = 0; k <= 40; ++k) points.push_back(Vec3(0.25 * i, 0, 0.25 * k));
  PointCloud cloud;
  cloud.setAbsolutePositions(points);
  return cloud;
}

/// Pixels of `color` in row `y`, and in the whole image.
int countInRow(const Image& image, int y, const Rgb& color) {
  int n = 0;
  for (int x = 0; x < image.width; ++x) n += image.at(x, y) == color;
  return n;
}
int countAll(const Image& image, const Rgb& color) {
  int n = 0;
  for (const Rgb& p : image.pixels) n += p == color;
  return n;
}

LineRenderOptions thin() {
  LineRenderOptions options;
  options.color = kRed;
  options.lineRadius = 0;
  return options;
}

}  // namespace

TEST(LineRenderer, PixelsAlongAKnownSegmentAreColoured) {
  // Two points frame the picture and fall just outside it (radius 0).
  PointCloud cloud;
  cloud.setAbsolutePositions({Vec3(0, 0, 0), Vec3(10, 0, 10)});
  Rendering r = renderPointsWithDepth(cloud, frontView(0));
  ASSERT_EQ(countAll(r.image, Rgb{255, 255, 255}), 100 * 100);
  // z = 5.05 -> row 49.5; x from 2.05 to 8.05 -> columns 20.5 to 80.5.
  drawSegments(r, {{Vec3(2.05, 0, 5.05), Vec3(8.05, 0, 5.05), kRed, kRed}}, thin());
  for (int x = 20; x <= 80; ++x) EXPECT_EQ(r.image.at(x, 49), kRed) << "column " << x;
  EXPECT_EQ(countInRow(r.image, 49, kRed), 61);
  EXPECT_EQ(countAll(r.image, kRed), 61);
  // A diagonal is connected: one pixel per column from (20.5, 79.5) to (80.5, 19.5).
  Rendering d = renderPointsWithDepth(cloud, frontView(0));
  drawSegments(d, {{Vec3(2.05, 0, 2.05), Vec3(8.05, 0, 8.05), kRed, kRed}}, thin());
  for (int x = 20; x <= 80; ++x) EXPECT_EQ(d.image.at(x, 99 - x), kRed) << "column " << x;
  // A wider line covers the rows beside.
  LineRenderOptions wide = thin();
  wide.lineRadius = 1;
  drawSegments(r, {{Vec3(2.05, 0, 5.05), Vec3(8.05, 0, 5.05), kRed, kRed}}, wide);
  EXPECT_EQ(countInRow(r.image, 48, kRed), 61);
  EXPECT_EQ(countInRow(r.image, 50, kRed), 61);
}

TEST(LineRenderer, ThePlaneHidesASegmentBehindItButNotOneOnItOrInFront) {
  const PointCloud cloud = wall();
  for (const double y : {1.0, 0.05, -1.0}) {
    Rendering r = renderPointsWithDepth(cloud, frontView(3));
    ASSERT_EQ(countAll(r.image, kRed), 0);
    drawSegments(r, {{Vec3(2.05, y, 5.05), Vec3(8.05, y, 5.05), kRed, kRed}}, thin());
    // Behind by 1 (10 pixels' worth, beyond the tolerance 2 * 3 + 2): hidden. On the surface (a
    // traced line sits among the splats) or in front: drawn.
    EXPECT_EQ(countInRow(r.image, 49, kRed), y > 0.5 ? 0 : 61) << "y = " << y;
  }
  // A segment crossing the wall: only its part in front shows.
  Rendering r = renderPointsWithDepth(cloud, frontView(3));
  drawSegments(r, {{Vec3(2.05, -1, 5.05), Vec3(8.05, 1, 5.05), kRed, kRed}}, thin());
  const int shown = countInRow(r.image, 49, kRed);
  // Drawn while at most the tolerance (0.8) behind the wall: the first 90% of the segment.
  EXPECT_GE(shown, 53);
  EXPECT_LE(shown, 57);
  EXPECT_EQ(r.image.at(20, 49), kRed);
  EXPECT_NE(r.image.at(80, 49), kRed);
}

TEST(LineRenderer, PolylinesAreColouredByAVertexAttributeAndClosedLinesClosed) {
  PointCloud cloud;
  cloud.setAbsolutePositions({Vec3(0, 0, 0), Vec3(10, 0, 10)});
  PolylineSet lines;
  lines.vertices.setAbsolutePositions(
      {Vec3(2.05, 0, 2.05), Vec3(8.05, 0, 2.05), Vec3(8.05, 0, 8.05)});
  auto& kappa = lines.vertices.addAttribute("kappa1", ScalarType::Float32);
  kappa.values = {0, 1, 0};
  lines.offsets = {0, 3};
  lines.closed = {1};
  Rendering r = renderPointsWithDepth(cloud, frontView(0));
  drawPolylines(r, lines, thin());
  EXPECT_EQ(r.image.at(50, 49), kRed);  // the closing segment, (8, 8) -> (2, 2)
  EXPECT_EQ(r.image.at(50, 79), kRed);
  EXPECT_EQ(r.image.at(80, 50), kRed);
  LineRenderOptions byKappa = thin();
  byKappa.colorAttribute = "kappa1";
  Rendering c = renderPointsWithDepth(cloud, frontView(0));
  drawPolylines(c, lines, byKappa);
  EXPECT_EQ(c.image.at(20, 79), viridis(0));
  EXPECT_EQ(c.image.at(80, 79), viridis(1));
  byKappa.colorAttribute = "kappa2";
  try {
    drawPolylines(c, lines, byKappa);
    ADD_FAILURE() << "an unknown attribute was accepted";
  } catch (const OptionError& e) {
    EXPECT_NE(std::string(e.what()).find("LineRenderOptions::colorAttribute 'kappa2' is not a "
                                         "vertex attribute of the lines (they have: kappa1"),
              std::string::npos)
        << e.what();
  }
  LineRenderOptions bad = thin();
  bad.lineRadius = kMaxPointRadius + 1;
  EXPECT_THROW(drawPolylines(c, lines, bad), OptionError);
}

TEST(LineRenderer, HugeSegmentsAreClippedAndNonFiniteOnesSkipped) {
  PointCloud cloud;
  cloud.setAbsolutePositions({Vec3(0, 0, 0), Vec3(10, 0, 10)});
  Rendering r = renderPointsWithDepth(cloud, frontView(0));
  const double inf = std::numeric_limits<double>::infinity();
  drawSegments(r,
               {{Vec3(-1e12, 0, 5.05), Vec3(1e12, 0, 5.05), kRed, kRed},
                {Vec3(inf, 0, 1), Vec3(2, 0, 1), kRed, kRed},
                {Vec3(-5, 0, 50), Vec3(50, 0, 50), kRed, kRed}},  // above the image
               thin());
  EXPECT_EQ(countInRow(r.image, 49, kRed), 100);
  EXPECT_EQ(countAll(r.image, kRed), 100);
}
