// `scalespace cylinders`: the pipes of the generated rack found with their radii, the folder's
// files readable by other tools, label queries by scale and persistence, clear errors, and a
// user's folder never written into.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "cli/CliTestSupport.hpp"
#include "scalespace/core/PipeScene.hpp"
#include "scalespace/features/CylinderDetection.hpp"
#include "scalespace/io/CloudIO.hpp"
#include "scalespace/io/Polylines.hpp"

using namespace scalespace;

namespace {

using test::Cli;
using test::run;
namespace fs = std::filesystem;

nlohmann::json readJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

}  // namespace

TEST_F(Cli, CylindersFindThePipesOfTheRack) {
  ASSERT_EQ(run("generate pipes -n 150000 -q -o " + path("p.ply")).code, 0);
  auto r = run("cylinders " + path("p.ply") + " -q -o " + path("out"));
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json result = readJson(path("out/components.json"));
  EXPECT_EQ(result["result"], "cylinders");
  EXPECT_EQ(result["levels"].size(), std::size_t(CylinderOptions{}.scaleCount));
  const PointCloud cloud = readCloud(path("out/cloud.ply"));
  ASSERT_EQ(cloud.size(), 150000u);
  const AttributeColumn* id = cloud.findAttribute("cylinder_id");
  const AttributeColumn* gt = cloud.findAttribute("gt_pipe");
  ASSERT_NE(id, nullptr);
  ASSERT_NE(cloud.findAttribute("anisotropy"), nullptr);
  // Each straight pipe is mostly one component with its radius; the floor, wall and box none.
  std::map<int, std::map<int, std::size_t>> votes;  // gt pipe -> component -> points
  std::size_t planeLabelled = 0, planePoints = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const int pipe = int(gt->values[i]), label = int(id->values[i]);
    if (pipe < 0) {
      ++planePoints;
      planeLabelled += label >= 0;
    } else if (label >= 0) {
      ++votes[pipe][label];
    }
  }
  EXPECT_LT(double(planeLabelled), 0.01 * double(planePoints));
  for (const PipeTruth& truth : pipeSceneTruth()) {
    if (truth.kind != PipeKind::Straight) continue;
    SCOPED_TRACE(truth.name);
    ASSERT_FALSE(votes[truth.id].empty());
    auto best = votes[truth.id].begin();
    for (auto it = votes[truth.id].begin(); it != votes[truth.id].end(); ++it)
      if (it->second > best->second) best = it;
    const nlohmann::json& component = result["components"][std::size_t(best->first)];
    EXPECT_EQ(component["id"], best->first);
    EXPECT_TRUE(component["straight"].get<bool>());
    EXPECT_NEAR(component["radius"].get<double>(), truth.radius, 0.02 * truth.radius);
  }
  // The axes: one polyline per component, with the radius profile.
  const PolylineSet axes = readPolylines(path("out/axes.ply"));
  EXPECT_EQ(axes.lineCount(), result["components"].size());
  ASSERT_NE(axes.vertices.findAttribute("radius"), nullptr);
  std::ifstream csv(path("out/components.csv"));
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("id,birth_level,birth_scale,death_level,death_scale,persistence", 0), 0u);
  EXPECT_NE(header.find(",gap_levels"), std::string::npos);
  for (const auto& c : result["components"])
    EXPECT_EQ(
        c["persistence"].get<int>(),
        c["death_level"].get<int>() - c["birth_level"].get<int>() - c["gap_levels"].get<int>());

  // Labels at one scale, and only persistent components: fewer points labelled. The folder is an
  // earlier result, so it is replaced.
  r = run("cylinders " + path("p.ply") + " -q --scale 0.1 --min-persistence 2 -o " + path("out"));
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json again = readJson(path("out/components.json"));
  EXPECT_EQ(again["labels"]["min_persistence"], 2);
  EXPECT_TRUE(again["labels"]["scale"].is_number());
  const PointCloud atScale = readCloud(path("out/cloud.ply"));
  std::size_t before = 0, after = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    before += id->values[i] >= 0;
    after += atScale.findAttribute("cylinder_id")->values[i] >= 0;
  }
  EXPECT_LE(after, before);

  // The same queries from the saved folder, without recomputing: identical labels.
  auto labelsOf = [&](const std::string& file) {
    return readCloud(path(file)).findAttribute("cylinder_id")->values;
  };
  r = run("cylinders-segment " + path("out") + " -q --scale 0.1 --min-persistence 2 -o " +
          path("seg_scale.ply"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(labelsOf("seg_scale.ply"), atScale.findAttribute("cylinder_id")->values);
  r = run("cylinders-segment " + path("out") + " -q -o " + path("seg_default.ply"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(labelsOf("seg_default.ply"), id->values);
  // A folder that is no cylinders result, and a cloud of another size, are refused; `segment`
  // on a cylinders result points to cylinders-segment.
  r = run("cylinders-segment " + path(".") + " -q -o " + path("x.ply"));
  EXPECT_NE(r.code, 0);
  r = run("segment " + path("out") + " --min-persistence 1 -q -o " + path("x.ply"));
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("cylinders-segment"), std::string::npos) << r.err;
  ASSERT_EQ(run("generate cylinder -n 100 -q -o " + path("small.ply")).code, 0);
  r = run("cylinders-segment " + path("out") + " --input " + path("small.ply") + " -q -o " +
          path("x.ply"));
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("points"), std::string::npos) << r.err;
}

TEST_F(Cli, CylindersRejectBadOptionsAndForeignFolders) {
  ASSERT_EQ(run("generate cylinder -n 3000 -q -o " + path("c.ply")).code, 0);
  test::Result r;
  for (const auto& [flag, value] :
       std::vector<std::pair<std::string, std::string>>{{"--epsilon", "1"},
                                                        {"--min-arc", "500"},
                                                        {"--min-sector-fill", "1.5"},
                                                        {"--max-face-sectors", "-1"},
                                                        {"--min-face-lean", "-1"},
                                                        {"--max-gap", "-1"},
                                                        {"--bridge-radius-tolerance", "1"},
                                                        {"--nested-link-tolerance", "1"}}) {
    r = run("cylinders " + path("c.ply") + " " + flag + " " + value + " -q -o " + path("o"));
    EXPECT_EQ(r.code, 2) << flag;
    EXPECT_NE(r.err.find(flag), std::string::npos) << r.err;
  }
  for (const char* flag : {"--narrow-min-arc", "--narrow-min-persistence", "--narrow-radius-spread",
                           "--trim-keep-fraction", "--trim-min-radius", "--trim-against-share",
                           "--min-line-length", "--max-line-curvature", "--max-line-variation"}) {
    r = run("cylinders " + path("c.ply") + " " + flag + " -1 -q -o " + path("o"));
    EXPECT_EQ(r.code, 2) << flag;
    EXPECT_NE(r.err.find(flag), std::string::npos) << r.err;
  }
  r = run("cylinders " + path("c.ply") + " --tmin 1 --tmax 0.5 -q -o " + path("o"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--tmax"), std::string::npos) << r.err;
  for (const char* scale : {"-1", "0"}) {
    r = run("cylinders " + path("c.ply") + " --scale " + scale + " -q -o " + path("o"));
    EXPECT_EQ(r.code, 2) << scale;
    EXPECT_NE(r.err.find("--scale must be finite and > 0"), std::string::npos) << r.err;
  }
  // A folder holding someone's files is never written into.
  fs::create_directories(path("mine"));
  std::ofstream(path("mine/notes.txt")) << "keep";
  r = run("cylinders " + path("c.ply") + " -q -o " + path("mine"));
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("refusing"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(path("mine/notes.txt")));
  EXPECT_FALSE(fs::exists(path("mine/components.json")));
  // Malformed input: one clear line, nothing written.
  std::ofstream(path("bad.ply")) << "ply\nformat ascii 1.0\nelement vertex 2\nend_header\n1 2\n";
  r = run("cylinders " + path("bad.ply") + " -q -o " + path("o2"));
  EXPECT_NE(r.code, 0);
  EXPECT_FALSE(fs::exists(path("o2")));
  // Too few points, or all at one place: a clear error naming the cause.
  {
    std::ofstream five(path("five.xyz"));
    for (int i = 0; i < 5; ++i) five << i << " " << i * i << " 0\n";
    std::ofstream same(path("same.xyz"));
    for (int i = 0; i < 500; ++i) same << "1 2 3\n";
  }
  r = run("cylinders " + path("five.xyz") + " -q -o " + path("o3"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("5 points"), std::string::npos) << r.err;
  r = run("cylinders " + path("same.xyz") + " -q -o " + path("o4"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("coincide"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("o4")));
  // A mesh read as its 8 vertices: the error says how to sample its faces instead.
  std::ofstream(path("cube.off"))
      << "OFF\n8 6 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
         "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n";
  r = run("cylinders " + path("cube.off") + " -q -o " + path("o5"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("8 points"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("read as its 8 vertices: --sample N"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("o5")));
  // --one-sided belongs to the pipes and poles scenes.
  r = run("generate box --one-sided -q -o " + path("x.ply"));
  EXPECT_EQ(r.code, 2);
}

// The thresholds of Eq. 3.5-3.7 are options: recorded in the result, and a minimum length of a
// thousand scales leaves no regular line and so no cylinder, where the defaults find it.
TEST_F(Cli, CylindersTakeTheLineFilterThresholds) {
  ASSERT_EQ(run("generate cylinder -n 20000 -q -o " + path("c.ply")).code, 0);
  auto r = run("cylinders " + path("c.ply") + " --scales 3 -q -o " + path("d"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(readJson(path("d/components.json"))["components"].empty());
  r = run("cylinders " + path("c.ply") +
          " --scales 3 --min-line-length 1000 --max-line-curvature 2 --max-line-variation 0.7 -q "
          "-o " +
          path("f"));
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json result = readJson(path("f/components.json"));
  EXPECT_EQ(result["parameters"]["min_length_factor"], 1000.0);
  EXPECT_EQ(result["parameters"]["max_curvature_factor"], 2.0);
  EXPECT_EQ(result["parameters"]["max_mean_variation"], 0.7);
  ASSERT_EQ(result["levels"].size(), 3u);
  for (const auto& level : result["levels"]) {
    EXPECT_GT(level["lines"].get<int>(), 0);
    EXPECT_EQ(level["regular_lines"], 0);
  }
  EXPECT_TRUE(result["components"].empty());
}

// The poles of `generate poles` from positions alone under noise: each pole one component of its
// radius, and the box standing on the floor, whose edges a coarse scale rounds, no persistent one.
TEST_F(Cli, CylindersFindThePolesWithoutNormalsAndNotTheBox) {
  ASSERT_EQ(run("generate poles -n 120000 --noise 5e-4 --seed 3 -q -o " + path("p.ply")).code, 0);
  PointCloud bare = readCloud(path("p.ply"));
  bare.setNormals({});
  writeCloud(bare, path("bare.ply"));
  auto r = run("cylinders " + path("bare.ply") + " -q -o " + path("out"));
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json result = readJson(path("out/components.json"));
  const PointCloud cloud = readCloud(path("out/cloud.ply"));
  const auto& id = cloud.findAttribute("cylinder_id")->values;
  const auto& gt = cloud.findAttribute("gt_pipe")->values;
  std::map<int, std::map<int, std::size_t>>
      votes;  // component -> gt pole (-1: box, floor) -> points
  for (std::size_t i = 0; i < cloud.size(); ++i)
    if (id[i] >= 0) ++votes[int(id[i])][int(gt[i])];
  std::map<int, int> found;  // gt pole -> component holding most of it
  for (const auto& [component, counts] : votes) {
    const auto holder = std::max_element(counts.begin(), counts.end(),
                                         [](auto& a, auto& b) { return a.second < b.second; });
    const int persistence = result["components"][std::size_t(component)]["persistence"];
    if (holder->first < 0)
      EXPECT_LT(persistence, 2) << "component " << component << " on the box or floor";
    else
      found[holder->first] = component;
  }
  for (const PipeTruth& pole : pipeSceneTruth(PipeLayout::Poles)) {
    SCOPED_TRACE(pole.name);
    ASSERT_EQ(found.count(pole.id), 1u);
    const nlohmann::json& component = result["components"][std::size_t(found[pole.id])];
    EXPECT_NEAR(component["radius"].get<double>(), pole.radius, 0.02 * pole.radius);
    EXPECT_TRUE(component["straight"].get<bool>());
    EXPECT_GE(component["persistence"].get<int>(), 1);
  }
}

// A cloud without normals gets cylinderNormalOptions(): sheet normals with the PCA normals' signs,
// the same as `normals --sheet 0.05 --sign-from-pca` gives.
TEST_F(Cli, CylindersEstimateSheetNormalsSignedByThePcaNormals) {
  ASSERT_EQ(run("generate pipes -n 40000 -q -o " + path("p.ply")).code, 0);
  PointCloud bare = readCloud(path("p.ply"));
  bare.setNormals({});
  writeCloud(bare, path("bare.ply"));
  auto r = run("cylinders " + path("bare.ply") + " --scales 2 --tmin 0.04 --tmax 0.08 -o " +
               path("direct"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("sheet planes"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("MST of the PCA normals"), std::string::npos) << r.err;
  r = run("normals " + path("bare.ply") + " --sheet 0.05 --sign-from-pca -q -o " + path("n.ply"));
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("cylinders " + path("n.ply") + " --scales 2 --tmin 0.04 --tmax 0.08 -q -o " +
          path("given"));
  ASSERT_EQ(r.code, 0) << r.err;
  const PointCloud direct = readCloud(path("direct/cloud.ply"));
  const PointCloud given = readCloud(path("given/cloud.ply"));
  ASSERT_EQ(direct.size(), given.size());
  EXPECT_EQ(direct.findAttribute("cylinder_id")->values,
            given.findAttribute("cylinder_id")->values);
  EXPECT_EQ(direct.normals(), given.normals());
  const auto& labels = direct.findAttribute("cylinder_id")->values;
  EXPECT_GT(std::count_if(labels.begin(), labels.end(), [](double v) { return v >= 0; }), 5000);

  r = run("normals " + path("bare.ply") + " --sign-from-pca -q -o " + path("m.ply"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--sign-from-pca needs sheet normals (--sheet > 0)"), std::string::npos)
      << r.err;
}
