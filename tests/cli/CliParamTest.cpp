// `scalespace parametrize` and `distortion`: the columns and summaries they write, the torus
// flagged, a peer's parametrization read back, clear errors, inputs never overwritten.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli/CliTestSupport.hpp"
#include "scalespace/io/CloudIO.hpp"

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

TEST_F(Cli, ParametrizeWritesTheDomainAndDistortionReadsItBack) {
  ASSERT_EQ(run("generate bumpy-disk -n 6000 --noise 0.001 -q -o " + path("d.ply")).code, 0);
  const auto before = fs::last_write_time(path("d.ply"));
  auto r = run("parametrize " + path("d.ply") + " --scales 20 -q -o " + path("p.ply") +
               " --flattened " + path("flat.ply"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(fs::last_write_time(path("d.ply")), before);
  const PointCloud p = readCloud(path("p.ply"));
  ASSERT_EQ(p.size(), 6000u);
  for (const char* column : {"u", "v", "param_valid", "fold", "overlap", "local_scale"})
    EXPECT_NE(p.findAttribute(column), nullptr) << column;
  EXPECT_EQ(p.findAttribute("s_x"), nullptr);
  const nlohmann::json summary = readJson(path("p.json"));
  EXPECT_EQ(summary["domain"]["kind"], "plane");
  EXPECT_EQ(summary["folds"], 0);
  EXPECT_EQ(summary["overlaps"], 0);
  EXPECT_TRUE(summary["one_to_one"].get<bool>());
  EXPECT_EQ(summary["flattening"]["steps"].size(), 20u);
  EXPECT_EQ(readCloud(path("flat.ply")).size(), 6000u);

  // distortion on the input and the parametrization, then on the parametrization alone.
  r = run("distortion " + path("d.ply") + " " + path("p.ply") + " --scales-k 16,64 -q -o " +
          path("e.ply"));
  ASSERT_EQ(r.code, 0) << r.err;
  const PointCloud e = readCloud(path("e.ply"));
  for (const char* column : {"eps_conf_k16", "eps_auth_k16", "eps_conf_k64", "eps_auth_k64"})
    EXPECT_NE(e.findAttribute(column), nullptr) << column;
  const nlohmann::json d = readJson(path("e.json"));
  ASSERT_EQ(d["sizes"].size(), 2u);
  EXPECT_GE(d["sizes"][0]["median_conformal"].get<double>(), 1.0);
  EXPECT_LT(d["sizes"][0]["median_conformal"].get<double>(), 1.1);
  // The picture of the map: u through viridis, a checkerboard over (u, v).
  r = run("render " + path("p.ply") + " --color u --checker u,v -q -o " + path("map.png"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_GT(fs::file_size(path("map.png")), 1000u);
  r = run("render " + path("p.ply") + " --checker u -q -o " + path("bad.png"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("is not two attribute names"), std::string::npos) << r.err;
  r = run("render " + path("p.ply") + " --checker u,w -q -o " + path("bad.png"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("no attribute 'w'"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("bad.png")));
  r = run("distortion " + path("p.ply") + " -q -o " + path("e2.ply"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(readJson(path("e2.json"))["sizes"].size(), 3u);
}

TEST_F(Cli, ParametrizeWarnsOnATorusAndGivesSphereCoordinates) {
  ASSERT_EQ(run("generate ring -n 6000 -q -o " + path("t.ply")).code, 0);
  auto r = run("parametrize " + path("t.ply") + " --scales 20 -q -o " + path("p.ply"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("warning: the map is not one-to-one"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("genus 0"), std::string::npos);
  const nlohmann::json summary = readJson(path("p.json"));
  EXPECT_FALSE(summary["one_to_one"].get<bool>());
  EXPECT_EQ(summary["domain"]["kind"], "sphere");
  const PointCloud p = readCloud(path("p.ply"));
  for (const char* column : {"s_x", "s_y", "s_z", "longitude", "latitude"})
    EXPECT_NE(p.findAttribute(column), nullptr) << column;
}

TEST_F(Cli, ParametrizeAndDistortionRejectBadInput) {
  ASSERT_EQ(run("generate hemisphere -n 2000 -q -o " + path("h.ply")).code, 0);
  auto r = run("parametrize " + path("h.ply") + " --domain cone -o " + path("p.ply"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("expected auto, plane or sphere"), std::string::npos) << r.err;
  r = run("parametrize " + path("h.ply") + " --scales 1 -o " + path("p.ply"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--scales must be in [2,"), std::string::npos) << r.err;
  r = run("parametrize " + path("h.ply") + " --k 5000 -o " + path("p.ply"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--k must be in [1, 1000]"), std::string::npos) << r.err;
  r = run("parametrize " + path("h.ply") + " -o " + path("h.ply"));
  EXPECT_NE(r.code, 0);
  r = run("parametrize " + path("h.ply") + " -o " + path("p.ply") + " --flattened " +
          path("p.ply"));
  EXPECT_EQ(r.code, 2);
  EXPECT_FALSE(fs::exists(path("p.ply")));
  // The same file spelled another way: still one output replacing the other.
  r = run("parametrize " + path("h.ply") + " -o " + path("p.ply") + " --flattened " +
          (dir_ / "." / "p.ply").string());
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("--flattened"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("p.ply")));
  // distortion needs parametrization columns, the same point count, sizes that are integers.
  r = run("distortion " + path("h.ply") + " -o " + path("e.ply"));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("no parametrization columns"), std::string::npos) << r.err;
  ASSERT_EQ(run("generate hemisphere -n 1000 -q -o " + path("small.ply")).code, 0);
  ASSERT_EQ(run("parametrize " + path("small.ply") + " --scales 5 -q -o " + path("sp.ply")).code,
            0);
  r = run("distortion " + path("h.ply") + " " + path("sp.ply") + " -o " + path("e.ply"));
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("has 1000 points, the input 2000"), std::string::npos) << r.err;
  r = run("distortion " + path("sp.ply") + " --scales-k 16,x -o " + path("e.ply"));
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--scales-k: 'x' is not an integer"), std::string::npos) << r.err;
  r = run("distortion " + path("sp.ply") + " --scales-k 2 -o " + path("e.ply"));
  EXPECT_EQ(r.code, 2);
  EXPECT_FALSE(fs::exists(path("e.ply")));
}
