// Uses the installed library as a third-party program would: a sampled unit sphere, its W3
// curvatures (H = 1 with outward normals), a PLY written and read back. Exit 0 when all hold.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "scalespace/core/AnalyticSurface.hpp"
#include "scalespace/fit/CurvatureEstimation.hpp"
#include "scalespace/io/CloudIO.hpp"

int main() {
  using namespace scalespace;
  SurfaceSampleOptions sphere;
  sphere.count = 5000;
  PointCloud cloud = sampleSurface(sphere);
  CurvatureOptions options;
  options.scale = 0.3;
  const CurvatureSummary summary = computeCurvatureColumns(cloud, options);
  const AttributeColumn* h = cloud.findAttribute("curv_mean");
  double worst = 0;
  for (double v : h->values) worst = std::max(worst, std::abs(v - 1));
  const std::string path =
      (std::filesystem::temp_directory_path() / ("consumer_" + std::to_string(::getpid()) + ".ply"))
          .string();
  cloud.setNormals({});  // the fitted normal is the nx ny nz columns now
  writeCloud(cloud, path);
  const PointCloud back = readCloud(path);
  std::filesystem::remove(path);
  const bool ok = summary.invalid == 0 && worst < 1e-3 && back.size() == cloud.size() &&
                  back.findAttribute("curv_mean") != nullptr;
  std::printf("consumer: %zu points, max |H - 1| = %.3g, %s\n", cloud.size(), worst,
              ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
}
