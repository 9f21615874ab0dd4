// invalidFitWarnings: the cause a user can act on, and no advice that contradicts it.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "scalespace/fit/FitDiagnosis.hpp"

using namespace scalespace;

namespace {

PointCloud cloudOf(const std::vector<Vec3>& positions) {
  PointCloud cloud;
  cloud.setAbsolutePositions(positions);
  return cloud;
}

std::string joined(const std::vector<std::string>& warnings) {
  std::string all;
  for (const std::string& w : warnings) all += w + "\n";
  return all;
}

TEST(FitDiagnosis, CoincidentPointsAreNamedNotALargerScale) {
  const PointCloud cloud = cloudOf(std::vector<Vec3>(50, Vec3(1, 1, 1)));
  FitCounts counts;
  counts.total = counts.invalid = 50;
  counts.meanNeighbors = 0;
  const std::string all = joined(invalidFitWarnings(cloud, counts));
  EXPECT_NE(all.find("all 50 points are at one position"), std::string::npos) << all;
  EXPECT_EQ(all.find("larger"), std::string::npos) << all;
}

TEST(FitDiagnosis, AScaleBeyondTheCloudIsNotToldToGrow) {
  std::vector<Vec3> p;
  for (int i = 0; i < 10; ++i)
    for (int j = 0; j < 10; ++j) p.emplace_back(0.1 * i, 0.1 * j, 0);
  const PointCloud cloud = cloudOf(p);
  FitCounts counts;
  counts.total = counts.invalid = 100;
  counts.largestScale = 20;  // the diagonal is ~1.27
  counts.meanNeighbors = 1;  // a sparse Poisson-disk level at that scale
  const std::string all = joined(invalidFitWarnings(cloud, counts));
  EXPECT_NE(all.find("choose t below the diagonal"), std::string::npos) << all;
  EXPECT_EQ(all.find("choose a larger scale"), std::string::npos) << all;
  // Within the cloud, too few neighbours still asks for a larger scale.
  counts.largestScale = 0.01;
  EXPECT_NE(joined(invalidFitWarnings(cloud, counts)).find("choose a larger scale"),
            std::string::npos);
}

}  // namespace
