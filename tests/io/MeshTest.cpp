#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <string>
#include <utility>

#include "IoTestSupport.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/io/CloudIO.hpp"
#include "scalespace/io/MeshFormat.hpp"

namespace scalespace {
namespace {

// Triangle A (area 1) in the plane z = 0, triangle B (area 3) in the plane x = 5; a quad C split
// in two by the fan, far away, added only where needed.
const char* const kTwoTriangles =
    "OFF\n"
    "# two triangles\n"
    "6 2 0\n"
    "0 0 0\n2 0 0\n0 1 0\n"
    "5 0 0\n5 3 0\n5 0 2\n"
    "3 0 1 2\n"
    "3 3 4 5   0.5 0.5 0.5\n";

/// Barycentric coordinates of p in triangle (a, b, c) (assumes p in its plane).
Vec3 barycentric(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 n = (b - a).cross(c - a);
  const double area = n.squaredNorm();
  return Vec3((c - b).cross(p - b).dot(n) / area, (a - c).cross(p - c).dot(n) / area,
              (b - a).cross(p - a).dot(n) / area);
}

TEST(Off, VerticesAndPolygonFan) {
  const TriangleMesh mesh =
      parseOff("OFF 5 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n9 9 9\n4 0 1 2 3\n", "quad.off");
  ASSERT_EQ(mesh.vertices.size(), 5u);
  ASSERT_EQ(mesh.triangles.size(), 2u);
  EXPECT_EQ(mesh.triangles[0], (std::array<Index, 3>{0, 1, 2}));
  EXPECT_EQ(mesh.triangles[1], (std::array<Index, 3>{0, 2, 3}));
  const PointCloud cloud = readOff(kTwoTriangles, "t.off");
  EXPECT_EQ(cloud.size(), 6u);
  EXPECT_FALSE(cloud.hasNormals());
  const PointCloud withNormals = readOff("NOFF\n1 0 0\n1 2 3 0 0 1\n", "n.off");
  ASSERT_TRUE(withNormals.hasNormals());
  EXPECT_EQ(withNormals.normals()[0], Vec3(0, 0, 1));
}

TEST(Off, SamplingIsUniformByAreaAndOnTheTriangles) {
  ReadOptions options;
  options.meshSamples = 20000;
  options.seed = 7;
  ReadReport report;
  const PointCloud cloud = readOff(kTwoTriangles, "t.off", options, &report);
  ASSERT_EQ(cloud.size(), 20000u);
  ASSERT_TRUE(cloud.hasNormals());
  std::size_t onB = 0;
  Vec3 centroidA = Vec3::Zero();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec3 p = cloud.absolutePosition(i);
    const Vec3& n = cloud.normals()[i];
    if (p.x() > 2.5) {
      ++onB;
      ASSERT_NEAR(p.x(), 5.0, 1e-14);
      const Vec3 w = barycentric(p, Vec3(5, 0, 0), Vec3(5, 3, 0), Vec3(5, 0, 2));
      ASSERT_GE(w.minCoeff(), -1e-12);
      ASSERT_NEAR((n - Vec3(1, 0, 0)).norm(), 0.0, 1e-12);
    } else {
      ASSERT_EQ(p.z(), 0.0) << p.transpose();
      const Vec3 w = barycentric(p, Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(0, 1, 0));
      ASSERT_GE(w.minCoeff(), -1e-12);
      ASSERT_NEAR((n - Vec3(0, 0, 1)).norm(), 0.0, 1e-12);
      centroidA += p;
    }
  }
  // Areas 1 and 3: three quarters of the samples on B (binomial sd ~ 0.003).
  EXPECT_NEAR(double(onB) / 20000.0, 0.75, 0.015);
  centroidA /= double(20000 - onB);
  EXPECT_NEAR((centroidA - Vec3(2.0 / 3, 1.0 / 3, 0)).norm(), 0.0, 0.02);  // uniform inside A
  EXPECT_EQ(report.format, "off, 20000 area samples");
}

TEST(Off, SamplingIsDeterministicForASeed) {
  ReadOptions options;
  options.meshSamples = 100;
  const PointCloud a = readOff(kTwoTriangles, "t.off", options);
  const PointCloud b = readOff(kTwoTriangles, "t.off", options);
  test::expectSameCloud(a, b);
  options.seed = 2;
  const PointCloud c = readOff(kTwoTriangles, "t.off", options);
  EXPECT_NE(a.absolutePosition(0), c.absolutePosition(0));
}

TEST(Off, SampledNormalsInterpolateVertexNormals) {
  // One triangle with three different unit vertex normals (NOFF).
  const Vec3 n0(0, 0, 1), n1 = Vec3(1, 0, 1).normalized(), n2 = Vec3(0, 1, 1).normalized();
  std::ostringstream text;
  text.precision(17);
  text << "NOFF\n3 1 0\n0 0 0 " << n0.transpose() << "\n1 0 0 " << n1.transpose() << "\n0 1 0 "
       << n2.transpose() << "\n3 0 1 2\n";
  ReadOptions options;
  options.meshSamples = 500;
  const PointCloud cloud = readOff(text.str(), "n.off", options);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec3 w =
        barycentric(cloud.absolutePosition(i), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0));
    const Vec3 expected = (w[0] * n0 + w[1] * n1 + w[2] * n2).normalized();
    ASSERT_NEAR((cloud.normals()[i] - expected).norm(), 0.0, 1e-9);
    ASSERT_NEAR(cloud.normals()[i].norm(), 1.0, 1e-12);
  }
}

// Without normals in the file, a CAD mesh's averaged vertex normals lean across its edges (54.7
// degrees at a cube's corners): the samples take their face's normal instead (the file's own
// normals, above, are interpolated as given).
TEST(Off, SampledNormalsOfACadMeshAreItsFaceNormals) {
  const std::string cube =
      "OFF\n8 6 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n1 0 1\n1 1 1\n0 1 1\n"
      "4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 1 2 6 5\n4 2 3 7 6\n4 3 0 4 7\n";
  ReadOptions options;
  options.meshSamples = 600;
  const PointCloud cloud = readOff(cube, "cube.off", options);
  ASSERT_EQ(cloud.size(), 600u);
  for (std::size_t i = 0; i < cloud.size(); ++i)
    ASSERT_NEAR(cloud.normals()[i].cwiseAbs().maxCoeff(), 1.0, 1e-12) << cloud.normals()[i];
}

TEST(Mesh, AreaWeightedVertexNormals) {
  // Two faces sharing the edge (0, 1): the shared vertices' normal weights the bigger face more.
  TriangleMesh mesh;
  mesh.vertices = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, -3)};
  mesh.triangles = {{0, 1, 2}, {0, 1, 3}};  // normals +z (area 0.5) and +y (area 1.5)
  const std::vector<Vec3> normals = areaWeightedVertexNormals(mesh);
  EXPECT_NEAR((normals[0] - Vec3(0, 3, 1).normalized()).norm(), 0, 1e-12);
  EXPECT_NEAR((normals[2] - Vec3(0, 0, 1)).norm(), 0, 1e-12);
  EXPECT_NEAR((normals[3] - Vec3(0, 1, 0)).norm(), 0, 1e-12);
}

TEST(Obj, VerticesFacesAndNormalRules) {
  // Faces give each vertex one vn: normals used.
  const PointCloud a = readObj(
      "# cube corner\nmtllib x.mtl\no thing\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n"
      "vn 0 0 -1\ns off\nf 1//1 2//1 3/1/1\n",
      "a.obj");
  ASSERT_EQ(a.size(), 3u);
  ASSERT_TRUE(a.hasNormals());
  EXPECT_EQ(a.normals()[2], Vec3(0, 0, 1));
  // Vertex 1 gets two different normals: ignored.
  const PointCloud b = readObj(
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\nvn 0 0 -1\nf 1//1 2//1 3//1\n"
      "f -3//2 -2//2 -1//2\n",
      "b.obj");
  EXPECT_FALSE(b.hasNormals());
  // No face references, as many vn as v: matched by index.
  const PointCloud c = readObj("v 0 0 0\nv 1 0 0\nvn 1 0 0\nvn 0 1 0\n", "c.obj");
  ASSERT_TRUE(c.hasNormals());
  EXPECT_EQ(c.normals()[1], Vec3(0, 1, 0));
  // Negative indices and quads, then sampling with face normals.
  ReadOptions options;
  options.meshSamples = 50;
  const PointCloud d =
      readObj("v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nf -4 -3 -2 -1\n", "d.obj", options);
  ASSERT_EQ(d.size(), 50u);
  for (std::size_t i = 0; i < d.size(); ++i) {
    EXPECT_NEAR(d.absolutePosition(i).z(), 1.0, 1e-15);
    EXPECT_EQ(d.normals()[i], Vec3(0, 0, 1));
  }
}

TEST(Mesh, ErrorsNameFileAndLine) {
  auto expectError = [](auto reader, const std::string& text, const std::string& needle,
                        std::size_t samples = 0) {
    ReadOptions options;
    options.meshSamples = samples;
    try {
      reader(text, "m.mesh", options);
      FAIL() << "expected FileError for " << text;
    } catch (const FileError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  auto off = [](const std::string& t, const std::string& f, const ReadOptions& o) {
    return readOff(t, f, o);
  };
  auto obj = [](const std::string& t, const std::string& f, const ReadOptions& o) {
    return readObj(t, f, o);
  };
  expectError(off, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "m.mesh: line 6");
  expectError(off, "OFF\n3 1 0\n0 0 0\n1 0 0\n", "unexpected end of file");
  expectError(off, "OFF\n99999999 1 0\n0 0 0\n", "declares 99999999 vertices");
  expectError(off, "PLY\n", "expected the header OFF");
  expectError(off, "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n", "no faces to sample", 10);
  expectError(off, "OFF\n3 1 0\n0 0 0\n1 0 0\n0 2 0\n3 0 1 1\n", "no triangle of positive area",
              10);
  expectError(off, "OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n", "m.mesh: line 4", 10);
  expectError(obj, "v 0 0 0\nf 1 2 3\n", "m.mesh: line 2");
  expectError(obj, "v 0 0\n", "m.mesh: line 1");
  expectError(obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1//4 2 3\n", "normal reference");
}

TEST(Mesh, NonFiniteVerticesAreDroppedWithTheirFaces) {
  ReadOptions options;
  options.meshSamples = 30;
  options.dropNonFinite = true;
  ReadReport report;
  const PointCloud cloud = readOff("OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n0 0 inf\n3 0 1 2\n3 0 1 3\n",
                                   "d.off", options, &report);
  EXPECT_EQ(cloud.size(), 30u);
  EXPECT_EQ(report.droppedNonFinite, 1u);
  for (std::size_t i = 0; i < cloud.size(); ++i) EXPECT_EQ(cloud.absolutePosition(i).z(), 0.0);

  // The same mesh as a PLY: the vertex goes with its face, the other face's indices are kept
  // (renumbered past the dropped vertex: read unshifted, face 1 2 3 would take the far vertex
  // (5, 5) in place of (0, 1)).
  test::ScratchDir dir;
  test::writeText(dir.file("d.ply"),
                  "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float "
                  "y\nproperty float z\nelement face 2\nproperty list uchar int "
                  "vertex_indices\nend_header\n0 0 inf\n0 0 0\n2 0 0\n0 1 0\n5 5 0\n3 1 2 3\n"
                  "3 0 1 2\n");
  ReadReport plyReport;
  const PointCloud fromPly = readCloud(dir.file("d.ply"), options, &plyReport);
  EXPECT_EQ(fromPly.size(), 30u);
  EXPECT_EQ(plyReport.droppedNonFinite, 1u);
  for (std::size_t i = 0; i < fromPly.size(); ++i) {
    const Vec3 p = fromPly.absolutePosition(i);
    EXPECT_EQ(p.z(), 0.0);
    EXPECT_TRUE(p.x() >= -1e-6 && p.y() >= -1e-6 && p.x() / 2 + p.y() <= 1 + 1e-6)
        << p.transpose();  // in the triangle (0, 0), (2, 0), (0, 1)
  }
  options.dropNonFinite = false;
  EXPECT_THROW(readCloud(dir.file("d.ply"), options), FileError);
}

TEST(Mesh, ReadCloudDispatchesMeshFiles) {
  test::ScratchDir dir;
  test::writeText(dir.file("m.OFF"), kTwoTriangles);
  EXPECT_EQ(readCloud(dir.file("m.OFF")).size(), 6u);
  test::writeText(dir.file("m.obj"), "v 1 2 3\n");
  EXPECT_EQ(readCloud(dir.file("m.obj")).absolutePosition(0), Vec3(1, 2, 3));
}

// The unit cube as STL: 12 triangles, each with its own 3 corners (36), welded into 8 vertices.
std::string cubeStlAscii() {
  std::string text = "solid cube\n";
  const int faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  auto corner = [](int v) {
    return std::to_string(v & 1) + " " + std::to_string((v >> 1) & 1) + " " +
           std::to_string((v >> 2) & 1);
  };
  for (const auto& q : faces)
    for (const auto& t :
         {std::array<int, 3>{q[0], q[1], q[2]}, std::array<int, 3>{q[0], q[2], q[3]}}) {
      text += "  facet normal 0 0 0\n    outer loop\n";
      for (const int v : t) text += "      vertex " + corner(v) + "\n";
      text += "    endloop\n  endfacet\n";
    }
  return text + "endsolid cube\n";
}

/// The same triangles as binary STL (with a header that starts with "solid", as some exporters
/// write it).
std::string toBinaryStl(const TriangleMesh& mesh) {
  std::string data = "solid but binary";
  data.resize(80, ' ');
  const auto count = std::uint32_t(mesh.triangles.size());
  data.append(reinterpret_cast<const char*>(&count), 4);
  for (const auto& t : mesh.triangles) {
    const float normal[3] = {0, 0, 0};
    data.append(reinterpret_cast<const char*>(normal), 12);
    for (const Index v : t)
      for (int c = 0; c < 3; ++c) {
        const auto x = float(mesh.vertices[v][c]);
        data.append(reinterpret_cast<const char*>(&x), 4);
      }
    data.append(2, '\0');
  }
  return data;
}

TEST(Stl, AsciiAndBinaryWeldTheirCorners) {
  const TriangleMesh ascii = parseStl(cubeStlAscii(), "cube.stl");
  EXPECT_EQ(ascii.vertices.size(), 8u);
  ASSERT_EQ(ascii.triangles.size(), 12u);
  // Welded: every edge of the closed cube is shared by exactly two triangles, in opposite order.
  std::map<std::pair<Index, Index>, int> edges;
  for (const auto& t : ascii.triangles)
    for (int k = 0; k < 3; ++k) ++edges[{t[std::size_t(k)], t[std::size_t((k + 1) % 3)]}];
  EXPECT_EQ(edges.size(), 36u);
  for (const auto& [edge, count] : edges) {
    EXPECT_EQ(count, 1);
    EXPECT_EQ(edges.count({edge.second, edge.first}), 1u);
  }
  const TriangleMesh binary = parseStl(toBinaryStl(ascii), "cube.stl");
  EXPECT_EQ(binary.vertices, ascii.vertices);
  EXPECT_EQ(binary.triangles, ascii.triangles);
  EXPECT_TRUE(binary.vertexBytes);
  EXPECT_EQ(binary.vertexWhere(0), "byte 96");  // 80 + 4 + 12: the first corner
  // As a cloud: the 8 vertices, or samples on the faces with the faces' normals.
  EXPECT_EQ(readStl(cubeStlAscii(), "cube.stl").size(), 8u);
  ReadOptions options;
  options.meshSamples = 600;
  const PointCloud samples = readStl(toBinaryStl(ascii), "cube.stl", options);
  ASSERT_EQ(samples.size(), 600u);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const Vec3 p = samples.absolutePosition(i);
    EXPECT_NEAR((p - Vec3::Constant(0.5)).cwiseAbs().maxCoeff(), 0.5, 1e-6);
  }
}

TEST(Stl, MalformedFilesNameTheirPlace) {
  auto expectError = [](const std::string& data, const std::string& needle) {
    try {
      parseStl(data, "s.stl");
      ADD_FAILURE() << data;
    } catch (const FileError& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  std::string text = cubeStlAscii();
  expectError(text.substr(0, text.size() / 2), "s.stl: line");
  std::string fourth = text;
  fourth.insert(fourth.find("    endloop"), "      vertex 1 1 1\n");
  expectError(fourth, "line 7: a facet has more than 3 vertices");
  std::string word = text;
  word.replace(word.find("outer loop"), 10, "outer hoop");
  expectError(word, "line 3: unexpected");
  std::string binary = toBinaryStl(parseStl(text, "s.stl"));
  expectError(binary.substr(0, binary.size() - 1),
              "a binary STL declaring 12 triangles has 684 bytes");
  expectError("", "too short");
}

TEST(Mesh, FacesAreFoundInEveryFormatThatHasThem) {
  test::ScratchDir dir;
  test::writeText(dir.file("cube.stl"), cubeStlAscii());
  test::writeText(dir.file("points.off"), "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n");
  test::writeText(dir.file("quad.ply"),
                  "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                  "property float z\nelement face 1\nproperty list uchar int vertex_indices\n"
                  "end_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n");
  test::writeText(dir.file("points.ply"),
                  "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                  "property float z\nend_header\n0 0 0\n");
  EXPECT_EQ(readFacesIfAny(dir.file("cube.stl"))->triangles.size(), 12u);
  EXPECT_EQ(readFacesIfAny(dir.file("quad.ply"))->triangles.size(), 2u);
  EXPECT_FALSE(readFacesIfAny(dir.file("points.off")));  // CGAL's point sets are such files
  EXPECT_FALSE(readFacesIfAny(dir.file("points.ply")));
  EXPECT_THROW(readTriangleMesh(dir.file("points.ply")), FileError);
  EXPECT_TRUE(isMeshPath(dir.file("cube.STL")));
  EXPECT_EQ(readCloud(dir.file("cube.stl")).size(), 8u);
  EXPECT_THROW(writeCloud(readCloud(dir.file("cube.stl")), dir.file("out.stl")), OptionError);
}

}  // namespace
}  // namespace scalespace
