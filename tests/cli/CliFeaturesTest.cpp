// `scalespace lines` and `scalespace features`: outputs other tools open, mesh vertices labelled,
// clear errors on bad options and inputs.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli/CliTestSupport.hpp"
#include "features/CubeMesh.hpp"
#include "scalespace/io/CloudIO.hpp"
#include "scalespace/io/Polylines.hpp"

using namespace scalespace;

namespace {

using test::Cli;
using test::run;

nlohmann::json readJson(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

/// A unit cube as an OFF mesh whose faces are n x n grids of squares (two triangles each),
/// outward: the mesh protocol of Sec. 3.4.1 needs vertices spread along the edges.
void writeCube(const std::string& path, int n, const Vec3& offset = Vec3::Zero()) {
  std::vector<Vec3> vertices;
  std::vector<std::array<Index, 3>> triangles;
  test::cubeMesh(n, vertices, triangles);
  for (Vec3& v : vertices) v += offset;
  std::ofstream out(path);
  out.precision(17);
  out << "OFF\n" << vertices.size() << " " << triangles.size() << " 0\n";
  for (const Vec3& p : vertices) out << p.x() << " " << p.y() << " " << p.z() << "\n";
  for (const auto& t : triangles) out << "3 " << t[0] << " " << t[1] << " " << t[2] << "\n";
}

}  // namespace

TEST_F(Cli, LinesWritePlyWithEdgesAndObj) {
  ASSERT_EQ(run("generate cylinder -n 20000 -q -o " + path("c.ply")).code, 0);
  auto r = run("lines " + path("c.ply") + " --scale 0.1 -q -o " + path("l.ply"));
  ASSERT_EQ(r.code, 0) << r.err;
  const PolylineSet lines = readPolylines(path("l.ply"));
  ASSERT_GT(lines.lineCount(), 5u);
  for (const char* column : {"line_id", "scale", "k1", "k2", "k_gap", "nu", "tx", "ty", "tz"})
    EXPECT_NE(lines.vertices.findAttribute(column), nullptr) << column;
  const nlohmann::json summary = readJson(path("l.json"));
  EXPECT_EQ(summary["scales"][0]["lines"].get<std::size_t>(), lines.lineCount());
  // Several scales into one OBJ: `l` records.
  r = run("lines " + path("c.ply") + " --scales 2 --tmin 0.08 --tmax 0.2 -q -o " + path("l.obj"));
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream obj(path("l.obj"));
  std::string text((std::istreambuf_iterator<char>(obj)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\nl "), std::string::npos);
  EXPECT_EQ(readJson(path("l.json"))["scales"].size(), 2u);
}

TEST_F(Cli, FeaturesLabelPointsAndMeshVertices) {
  ASSERT_EQ(run("generate box -n 40000 -q -o " + path("b.ply")).code, 0);
  auto r = run("features " + path("b.ply") + " -q -o " + path("f.ply"));
  ASSERT_EQ(r.code, 0) << r.err;
  const PointCloud labelled = readCloud(path("f.ply"));
  for (const char* column : {"feature_votes", "curve_id", "convexity"})
    ASSERT_NE(labelled.findAttribute(column), nullptr) << column;
  const nlohmann::json summary = readJson(path("f.json"));
  ASSERT_GE(summary["curves"].size(), 1u);
  EXPECT_EQ(summary["curves"][0]["convexity"], "convex");
  EXPECT_EQ(summary["scales"].size(), 5u);

  // A mesh: the vertices on its edges are labelled convex, those of the faces' middles none.
  writeCube(path("cube.off"), 10);
  r = run("features " + path("cube.off") + " -q -o " + path("m.ply") + " --lines " +
          path("m_lines.ply"));
  ASSERT_EQ(r.code, 0) << r.err;
  // The vertices on its edges are labelled convex, those of the faces' middles none.
  auto checkCube = [](const PointCloud& vertices, const Vec3& offset) {
    ASSERT_EQ(vertices.size(), 602u);
    const AttributeColumn* convexity = vertices.findAttribute("convexity");
    ASSERT_NE(convexity, nullptr);
    std::size_t edgeVertices = 0, edgeConvex = 0, middleLabelled = 0;
    for (std::size_t i = 0; i < vertices.size(); ++i) {
      const Vec3 p = vertices.absolutePosition(i) - offset;
      int onBorder = 0;  // coordinates at 0 or 1: 2 on an edge, 1 inside a face
      for (int c = 0; c < 3; ++c) onBorder += std::abs(p[c]) < 1e-6 || std::abs(p[c] - 1) < 1e-6;
      double inside = 1;
      for (int c = 0; c < 3; ++c) inside = std::min({inside, std::abs(p[c]), std::abs(1 - p[c])});
      if (onBorder >= 2) {
        ++edgeVertices;
        edgeConvex += convexity->values[i] == 1;
      }
      if (onBorder == 1 && inside >= 0.35) middleLabelled += convexity->values[i] != 0;
    }
    EXPECT_GE(edgeConvex, std::size_t(0.9 * double(edgeVertices))) << edgeVertices;
    EXPECT_EQ(middleLabelled, 0u);
  };
  checkCube(readCloud(path("m.ply")), Vec3::Zero());
  EXPECT_EQ(readJson(path("m.json"))["labelled"], "mesh vertices");
  // Per edge: the cube's 12, each one curve's part (edge_id in the cloud, "edges" in the JSON).
  EXPECT_EQ(readJson(path("m.json"))["edges"].size(), 12u);
  ASSERT_NE(readCloud(path("m.ply")).findAttribute("edge_id"), nullptr);
  EXPECT_GT(readPolylines(path("m_lines.ply")).lineCount(), 0u);

  // The same cube far from the origin (georeferenced coordinates: the samples are stored relative
  // to an origin of their own) labels its edges as well.
  writeCube(path("far.off"), 10, Vec3(5e5, -3e5, 1e4));
  r = run("features " + path("far.off") + " -q -o " + path("far.ply"));
  ASSERT_EQ(r.code, 0) << r.err;
  checkCube(readCloud(path("far.ply")), Vec3(5e5, -3e5, 1e4));
}

TEST_F(Cli, FeatureCommandsRefuseBadOptionsAndInputs) {
  ASSERT_EQ(run("generate cylinder -n 3000 -q -o " + path("c.ply")).code, 0);
  auto refused = [&](const std::string& args, const std::string& says, int code = 2) {
    const auto r = run(args);
    EXPECT_EQ(r.code, code) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << args << "\n" << r.err;
    EXPECT_FALSE(std::filesystem::exists(path("out.ply"))) << args;
  };
  const std::string c = path("c.ply");
  refused("lines " + c + " -o " + path("out.ply"), "--scale");
  refused("lines " + c + " --scale 0.1 -o " + path("out.xyz"), ".ply or .obj");
  refused("lines " + c + " --scale -1 -o " + path("out.ply"), "scale");
  refused("lines " + c + " --scale 0.1 --gamma 0 -o " + path("out.ply"), "--gamma");
  refused("lines " + c + " --scale 0.1 --alpha 0.9 -o " + path("out.ply"), "--alpha");
  refused("lines " + c + " --scale 0.1 -o " + c, "never overwritten");
  // features' two outputs on one file: the lines replaced the labelled cloud (exit 0).
  refused("features " + c + " -o " + path("out.ply") + " --lines " + path("out.ply"),
          "--lines " + path("out.ply") + " is the output");
  // --scales with bounds the wrong way round: both reported as given, not one clamped onto the
  // other ("tmin=0.01 tmax=0.01").
  refused("lines " + c + " --scales 3 --tmin 0.01 --tmax 0.001 -o " + path("out.ply"),
          "--tmin = 0.010000 is not below --tmax = 0.001000");
  refused("features " + c + " --salient 2 -o " + path("out.ply"), "--salient");
  refused("features " + c + " --scales 0 -o " + path("out.ply"), "--scales");
  refused("features " + c + " --min-scales 9 -o " + path("out.ply"), "--min-scales");
  refused("features " + c + " -o " + path("out.off"), "OFF, OBJ and STL are meshes");
  refused("features " + c + " --mesh-samples 0 -o " + path("out.ply"), "--mesh-samples");
  refused("features " + c + " --sheet-normals -1 -o " + path("out.ply"), "--sheet-normals");
  refused("features " + c + " --edge-rejoin-angle 95 -o " + path("out.ply"), "--edge-rejoin-angle");
  refused("features " + c + " --crease-reach -1 -o " + path("out.ply"), "--crease-reach");
  refused("features " + c + " --crease-half-width 0 -o " + path("out.ply"), "--crease-half-width");
  refused("features " + c + " --crease-side-margin -1 -o " + path("out.ply"),
          "--crease-side-margin");
  refused("features " + c + " --fold-borders yes -o " + path("out.ply"), "--fold-borders");
  refused("features " + c + " --fold-reach 0 -o " + path("out.ply"), "--fold-reach");
  refused("features " + c + " --fold-share 1.5 -o " + path("out.ply"), "--fold-share");
  std::ofstream(path("bad.off")) << "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n";
  refused("features " + path("bad.off") + " -o " + path("out.ply"), "vertex 2", 1);
  std::ofstream(path("bad.stl")) << "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n";
  refused("features " + path("bad.stl") + " -o " + path("out.ply"), "inside a facet", 1);
  // An OFF of vertices only (as CGAL's point sets) is a point cloud: its points are labelled.
  ASSERT_EQ(run("generate sphere -n 500 -q -o " + path("flat.ply")).code, 0);
  const PointCloud sphere = readCloud(path("flat.ply"));
  std::ofstream off(path("points.off"));
  off << "OFF\n" << sphere.size() << " 0 0\n";
  for (std::size_t i = 0; i < sphere.size(); ++i)
    off << sphere.absolutePosition(i).transpose() << "\n";
  off.close();
  const auto r = run("features " + path("points.off") + " -q -o " + path("points.ply"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(readCloud(path("points.ply")).size(), sphere.size());
  EXPECT_EQ(readJson(path("points.json"))["labelled"], "points");
}

TEST_F(Cli, LinesSayWhenTheDefaultScalesCollapse) {
  // 20 points on a sphere: the mean distance to the 16th neighbour is far above 10% of the
  // diagonal, so the default bounds cross. The error names them as defaults, with their rules.
  ASSERT_EQ(run("generate sphere -n 20 -q -o " + path("s.ply")).code, 0);
  const auto r = run("lines " + path("s.ply") + " --scales 3 -q -o " + path("l.ply"));
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("the default --tmin (the mean distance to the 16th neighbour)"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("the default --tmax (10% of the bounding-box diagonal)"), std::string::npos)
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(path("l.ply")));
}
