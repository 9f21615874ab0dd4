#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <vector>

#include "scalespace/core/Error.hpp"
#include "scalespace/render/ColorMap.hpp"
#include "scalespace/render/PngWriter.hpp"
#include "scalespace/render/PointRenderer.hpp"

using namespace scalespace;

namespace {
PointCloud cloudOf(const std::vector<Vec3>& points) {
  PointCloud cloud;
  cloud.setAbsolutePositions(points);
  return cloud;
}
std::string tempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("scalespace_render_" + name)).string();
}
}  // namespace

TEST(ColorMap, ViridisEndsAndRobustRange) {
  EXPECT_EQ(viridis(0.0), (Rgb{68, 1, 84}));
  EXPECT_EQ(viridis(1.0), (Rgb{253, 231, 37}));
  EXPECT_EQ(viridis(-3.0), viridis(0.0));
  EXPECT_EQ(viridis(0.5), (Rgb{33, 144, 141}));
  // Perceptual map: luminance increases monotonically.
  double previous = -1;
  for (int k = 0; k <= 100; ++k) {
    const Rgb c = viridis(k / 100.0);
    const double luminance = 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
    EXPECT_GE(luminance, previous - 0.5);
    previous = luminance;
  }
  std::vector<double> values;
  for (int i = 0; i <= 100; ++i) values.push_back(i);
  values.push_back(1e9);  // outlier
  values.push_back(std::nan(""));
  const ScalarRange r = robustRange(values);
  EXPECT_NEAR(r.lo, 2, 1.01);
  EXPECT_NEAR(r.hi, 98, 1.01);
  const auto colors = colorizeScalars(values, r);
  EXPECT_EQ(colors.back(), kUnlabelledGrey);
  EXPECT_EQ(colors[101], viridis(1.0));
}

TEST(ColorMap, LabelColoursAreDistinct) {
  EXPECT_EQ(labelColor(-1), kUnlabelledGrey);
  for (int a = 0; a < 20; ++a)
    for (int b = a + 1; b < 20; ++b) {
      const Rgb x = labelColor(a), y = labelColor(b);
      const int d = std::abs(x.r - y.r) + std::abs(x.g - y.g) + std::abs(x.b - y.b);
      EXPECT_GT(d, 20) << a << " vs " << b;
    }
}

TEST(ColorMap, LabelsAreColouredByRankOfSize) {
  // Ids 1525 and 2190 land on nearly the same golden-ratio hue; ranked by size they get the
  // colours of ranks 0 and 1, which differ strongly.
  std::vector<double> labels = {2190, 1525, 2190, -1, 2190, 1525, 7};
  const std::vector<Rgb> c = colorizeLabels(labels);
  auto same = [](Rgb a, Rgb b) { return a.r == b.r && a.g == b.g && a.b == b.b; };
  EXPECT_TRUE(same(c[0], labelColor(0)));  // 3 points: rank 0
  EXPECT_TRUE(same(c[1], labelColor(1)));  // 2 points: rank 1
  EXPECT_TRUE(same(c[6], labelColor(2)));  // 1 point: rank 2
  EXPECT_TRUE(same(c[3], kUnlabelledGrey));
  EXPECT_TRUE(same(c[2], c[4]));
  EXPECT_TRUE(same(c[1], c[5]));
}

TEST(PointRenderer, SingleRedPointAtTheCentre) {
  PointCloud cloud = cloudOf({Vec3(3, 4, 5)});
  cloud.addAttribute("red", ScalarType::UInt8, 255);
  cloud.addAttribute("green", ScalarType::UInt8, 0);
  cloud.addAttribute("blue", ScalarType::UInt8, 0);
  RenderOptions opt;
  opt.width = 64;
  opt.height = 48;
  opt.pointRadius = 0;
  opt.view = "front";
  const Image image = renderPoints(cloud, opt);
  int red = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      if (image.at(x, y) == Rgb{255, 0, 0}) {
        ++red;
        EXPECT_EQ(x, 32);
        EXPECT_EQ(y, 24);
      } else {
        EXPECT_EQ(image.at(x, y), opt.background);
      }
  EXPECT_EQ(red, 1);
}

TEST(PointRenderer, DepthTestNearPointHidesFarPoint) {
  // Two points on the same line of sight (front view looks along +y): y = -1 is nearer.
  // A third point frames the picture so both land on the same pixel.
  for (bool nearFirst : {true, false}) {
    std::vector<Vec3> pts = nearFirst ? std::vector<Vec3>{Vec3(0, -1, 0), Vec3(0, 1, 0)}
                                      : std::vector<Vec3>{Vec3(0, 1, 0), Vec3(0, -1, 0)};
    pts.push_back(Vec3(2, 0, 2));
    PointCloud cloud = cloudOf(pts);
    RenderOptions opt;
    opt.width = opt.height = 21;
    opt.margin = 0;
    opt.pointRadius = 2;
    opt.view = "front";
    const Vec3 nearPoint(0, -1, 0);
    opt.colors.resize(3);
    for (int i = 0; i < 3; ++i)
      opt.colors[std::size_t(i)] =
          pts[std::size_t(i)] == nearPoint ? Rgb{0, 0, 255} : Rgb{0, 255, 0};
    const Image image = renderPoints(cloud, opt);
    // The pair projects to the bottom-left corner area; its splat must be blue, never green.
    int blue = 0;
    for (int y = 15; y < 21; ++y)
      for (int x = 0; x < 6; ++x) {
        EXPECT_NE(image.at(x, y), (Rgb{0, 255, 0})) << x << "," << y;
        blue += image.at(x, y) == Rgb{0, 0, 255};
      }
    EXPECT_GT(blue, 0);
  }
}

TEST(PointRenderer, ViewsAndLabels) {
  EXPECT_NEAR((viewDirection("top") - Vec3(0, 0, -1)).norm(), 0, 1e-15);
  EXPECT_NEAR((viewDirection("2,0,0") - Vec3(1, 0, 0)).norm(), 0, 1e-15);
  EXPECT_THROW(viewDirection("side"), OptionError);
  EXPECT_THROW(viewDirection("1,2"), OptionError);
  EXPECT_THROW(viewDirection("0,0,0"), OptionError);
  PointCloud cloud = cloudOf({Vec3(0, 0, 0), Vec3(1, 0, 1)});
  cloud.addAttribute("plane_id", ScalarType::Int32).values = {-1, 3};
  RenderOptions opt;
  opt.labelAttribute = "plane_id";
  const auto colors = pointColors(cloud, opt);
  EXPECT_EQ(colors[0], kUnlabelledGrey);
  EXPECT_EQ(colors[1], labelColor(0));  // the only (hence largest) label: rank 0
  opt.labelAttribute = "missing";
  EXPECT_THROW(renderPoints(cloud, opt), OptionError);
  opt.labelAttribute.clear();
  opt.width = 0;
  EXPECT_THROW(renderPoints(cloud, opt), OptionError);
}

TEST(PointRenderer, UpAxisTurnsTheNamedViews) {
  // The frames are right-handed and the default (z) keeps the views as they were.
  for (const char* up : {"x", "y", "z", "-x", "-y", "-z"}) {
    const UpFrame f = upFrame(up);
    EXPECT_NEAR((f.side.cross(f.ahead) - f.up).norm(), 0, 1e-15) << up;
  }
  EXPECT_NEAR((viewDirection("front", "z") - Vec3(0, 1, 0)).norm(), 0, 1e-15);
  EXPECT_NEAR((viewDirection("top", "y") - Vec3(0, -1, 0)).norm(), 0, 1e-15);
  EXPECT_NEAR((viewDirection("top", "-y") - Vec3(0, 1, 0)).norm(), 0, 1e-15);
  EXPECT_NEAR((viewDirection("front", "y") - Vec3(1, 0, 0)).norm(), 0, 1e-15);
  EXPECT_NEAR((viewDirection("1,0,0", "y") - Vec3(1, 0, 0)).norm(), 0, 1e-15);
  EXPECT_THROW(upFrame("w"), OptionError);
  EXPECT_THROW(upFrame("--z"), OptionError);
  EXPECT_THROW(upFrame(""), OptionError);
  // A floor in the xz plane of a y-up scan: seen from the top it fills the frame, seen from the
  // top of a z-up world (edge-on) it is a line; with up = y the image's up is the scene's -z.
  std::vector<Vec3> floor;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j) floor.emplace_back(i / 39.0, 0.0, j / 39.0);
  PointCloud cloud = cloudOf(floor);
  RenderOptions opt;
  opt.width = opt.height = 64;
  opt.view = "top";
  auto covered = [&](const Image& im) {
    int count = 0;
    for (int y = 0; y < im.height; ++y)
      for (int x = 0; x < im.width; ++x) count += im.at(x, y) != opt.background ? 1 : 0;
    return count;
  };
  opt.up = "y";
  const int fromAbove = covered(renderPoints(cloud, opt));
  opt.up = "z";
  const int edgeOn = covered(renderPoints(cloud, opt));
  EXPECT_GT(fromAbove, 64 * 64 / 2);
  EXPECT_LT(edgeOn, 64 * 64 / 8);
}

TEST(PngWriter, RoundTripIsExact) {
  Image image(7, 5);
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 7; ++x) image.at(x, y) = {std::uint8_t(x * 30), std::uint8_t(y * 50), 17};
  const std::string path = tempPath("roundtrip.png");
  writePng(image, path);
  const Image back = readPng(path);
  ASSERT_EQ(back.width, 7);
  ASSERT_EQ(back.height, 5);
  EXPECT_TRUE(back.pixels == image.pixels);
  // Not a PNG: a clear error naming the file.
  { std::ofstream(path) << "hello"; }
  try {
    readPng(path);
    FAIL() << "expected FileError";
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos);
  }
  EXPECT_THROW(writePng(image, path + "/out.png"), FileError);  // a file where a folder must be
  std::remove(path.c_str());
  EXPECT_THROW(writePng(Image(), path), Error);
}
