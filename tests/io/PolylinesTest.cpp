#include <gtest/gtest.h>

#include <sstream>

#include "IoTestSupport.hpp"
#include "scalespace/core/Error.hpp"
#include "scalespace/io/CloudIO.hpp"
#include "scalespace/io/PlyFormat.hpp"
#include "scalespace/io/Polylines.hpp"

namespace scalespace {
namespace {

using test::ScratchDir;

/// Four lines: open (4 vertices), closed (5), open (2), closed (3); georeferenced positions,
/// normals and columns of several types.
PolylineSet makeLines() {
  const std::vector<std::size_t> sizes = {4, 5, 2, 3};
  PolylineSet lines;
  std::vector<Vec3> positions, normals;
  for (std::size_t l = 0; l < sizes.size(); ++l) {
    for (std::size_t k = 0; k < sizes[l]; ++k) {
      positions.push_back(Vec3(654321.125 + 0.1 * double(k), 5432109.5 + double(l), 0.3 * k));
      normals.push_back(Vec3(0, 0.6, 0.8));
    }
    lines.offsets.push_back(positions.size());
    lines.closed.push_back(l % 2);
  }
  lines.vertices.setAbsolutePositions(positions);
  lines.vertices.setNormals(normals);
  auto& id = lines.vertices.addAttribute("line_id", ScalarType::Int32);
  auto& kappa = lines.vertices.addAttribute("kappa1", ScalarType::Float32);
  auto& nu = lines.vertices.addAttribute("nu", ScalarType::Float64);
  auto& flag = lines.vertices.addAttribute("stop", ScalarType::UInt8);
  auto& step = lines.vertices.addAttribute("step", ScalarType::Int16);
  for (std::size_t l = 0; l < sizes.size(); ++l)
    for (std::size_t i = lines.offsets[l]; i < lines.offsets[l + 1]; ++i) {
      id.values[i] = double(l);
      kappa.values[i] = double(float(0.1 * double(i)));
      nu.values[i] = 1.0 / 3.0 + double(i);
      flag.values[i] = double(i % 7) * 30;
      step.values[i] = -double(i) * 100;
    }
  return lines;
}

void expectSameLines(const PolylineSet& expected, const PolylineSet& actual) {
  test::expectSameCloud(expected.vertices, actual.vertices);
  ASSERT_EQ(expected.offsets, actual.offsets);
  ASSERT_EQ(actual.closed.size(), actual.lineCount());
  for (std::size_t l = 0; l < expected.lineCount(); ++l)
    EXPECT_EQ(expected.isClosed(l), actual.isClosed(l)) << "line " << l;
}

TEST(Polylines, PlyRoundTripBinaryAndAsciiKeepsLinesClosureAndTypedColumns) {
  const PolylineSet lines = makeLines();
  ScratchDir dir;
  for (const bool ascii : {false, true}) {
    const std::string path = dir.file(ascii ? "ascii.ply" : "binary.PLY");
    WriteOptions options;
    options.ascii = ascii;
    writePolylines(lines, path, options);
    const std::string text = test::readText(path);
    EXPECT_NE(text.find(ascii ? "format ascii 1.0" : "format binary_little_endian 1.0"),
              std::string::npos);
    // 3 + 5 + 1 + 3 edges, declared after the vertex properties.
    EXPECT_NE(text.find("property uchar stop\nproperty short step\n"
                        "element edge 12\nproperty int vertex1\nproperty int vertex2\nend_header"),
              std::string::npos)
        << text.substr(0, 600);
    const PolylineSet back = readPolylines(path);
    expectSameLines(lines, back);
    EXPECT_EQ(back.vertices.origin(), lines.vertices.origin());
    // A cloud reader sees the vertices and skips the edges.
    test::expectSameCloud(lines.vertices, readCloud(path));
  }
  // The ascii edges: line 1 (vertices 4..8) ends with its closing edge 8 -> 4; the line of two
  // vertices (9, 10) is one edge.
  WriteOptions ascii;
  ascii.ascii = true;
  writePolylines(lines, dir.file("e.ply"), ascii);
  const std::string text = test::readText(dir.file("e.ply"));
  EXPECT_NE(text.find("\n0 1\n1 2\n2 3\n4 5\n5 6\n6 7\n7 8\n8 4\n9 10\n11 12\n12 13\n13 11\n"),
            std::string::npos)
      << text;
}

TEST(Polylines, ZeroLinesAndAnEmptyOffsetsListRoundTrip) {
  ScratchDir dir;
  PolylineSet empty;
  empty.vertices.addAttribute("kappa1", ScalarType::Float32);
  for (const bool ascii : {false, true}) {
    WriteOptions options;
    options.ascii = ascii;
    writePolylines(empty, dir.file("empty.ply"), options);
    const PolylineSet back = readPolylines(dir.file("empty.ply"));
    EXPECT_EQ(back.lineCount(), 0u);
    EXPECT_EQ(back.vertices.size(), 0u);
    ASSERT_EQ(back.vertices.attributes().size(), 1u);
    EXPECT_EQ(back.vertices.attributes()[0].name, "kappa1");
  }
  PolylineSet noOffsets;
  noOffsets.offsets.clear();
  writePolylines(noOffsets, dir.file("none.obj"));
  EXPECT_EQ(readPolylines(dir.file("empty.ply")).offsets, std::vector<std::size_t>{0});
}

TEST(Polylines, ObjHoldsVerticesAndOneBasedLineRecordsAndSaysWhatItDropped) {
  PolylineSet lines;
  lines.vertices.setAbsolutePositions(
      {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(0.1, 2, 3), Vec3(5, 5, 5)});
  lines.vertices.addAttribute("kappa1", ScalarType::Float32, 0.5);
  lines.offsets = {0, 3, 5};
  lines.closed = {1, 0};
  ScratchDir dir;
  writePolylines(lines, dir.file("l.OBJ"));
  EXPECT_EQ(test::readText(dir.file("l.OBJ")),
            "# written by scalespace " SCALESPACE_VERSION
            "\n"
            "# 5 vertices, 2 polylines (a closed line repeats its first vertex)\n"
            "# OBJ stores positions only; not stored here: kappa1\n"
            "# (write the polylines as .ply to keep them)\n"
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0.1 2 3\nv 5 5 5\n"
            "l 1 2 3 1\nl 4 5\n");
  // The mesh reader ignores `l` records: the vertices read back as a cloud.
  EXPECT_EQ(readCloud(dir.file("l.OBJ")).size(), 5u);
}

TEST(Polylines, EdgesFromElsewhereAreChainedInFileOrder) {
  // Edges out of vertex order, vertices shared by two lines (0, 3), a closed line of two vertices,
  // an unused vertex (5), an extra edge property, and the edge element before the vertices.
  const std::string edges =
      "element edge 7\nproperty uchar red\nproperty int vertex1\nproperty int vertex2\n";
  const std::string vertices =
      "element vertex 6\nproperty float x\nproperty float y\nproperty float z\nproperty int tag\n";
  const std::string edgeRows = "9 4 2\n9 2 0\n9 0 4\n9 1 3\n9 3 1\n9 0 3\n9 3 2\n";
  const std::string vertexRows = "0 0 0 10\n1 0 0 11\n2 0 0 12\n3 0 0 13\n4 0 0 14\n5 0 0 15\n";
  for (const bool edgesFirst : {false, true}) {
    const std::string text = "ply\nformat ascii 1.0\n" +
                             (edgesFirst ? edges + vertices : vertices + edges) + "end_header\n" +
                             (edgesFirst ? edgeRows + vertexRows : vertexRows + edgeRows);
    const PolylineSet lines = readPolylinesPly(text, "foreign.ply");
    EXPECT_EQ(lines.offsets, (std::vector<std::size_t>{0, 3, 5, 8}));
    EXPECT_EQ(lines.closed, (std::vector<std::uint8_t>{1, 1, 0}));
    EXPECT_EQ(lines.vertices.findAttribute("tag")->values,
              (std::vector<double>{14, 12, 10, 11, 13, 10, 13, 12}));
    EXPECT_EQ(lines.vertices.absolutePosition(2), Vec3(0, 0, 0));
    EXPECT_EQ(lines.vertices.findAttribute("red"), nullptr);  // edge properties are not kept
  }
  // No edge element: no lines (the vertices belong to none).
  const PolylineSet none = readPolylinesPly(
      "ply\nformat ascii 1.0\n" + vertices + "end_header\n" + vertexRows, "points.ply");
  EXPECT_EQ(none.lineCount(), 0u);
  EXPECT_EQ(none.vertices.size(), 0u);
  EXPECT_NE(none.vertices.findAttribute("tag"), nullptr);
}

/// The FileError message of reading `text`, or "" when it reads.
std::string readError(const std::string& text, const std::string& file = "bad.ply") {
  try {
    readPolylinesPly(text, file);
  } catch (const FileError& e) {
    EXPECT_EQ(e.file(), file);
    return e.what();
  }
  return "";
}

TEST(Polylines, MalformedEdgesAreFileErrorsNamingThePlace) {
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty double x\nproperty double y\n"
      "property double z\n";
  const std::string points = "0 0 0\n1 0 0\n2 0 0\n";
  const std::string edgeHeader = "element edge 2\nproperty int vertex1\nproperty int vertex2\n";
  EXPECT_EQ(readError(head + edgeHeader + "end_header\n" + points + "0 1\n1 2\n"), "");
  std::string e = readError(head + edgeHeader + "end_header\n" + points + "0 1\n1 3\n");
  EXPECT_NE(e.find("bad.ply: line 15: edge 2: vertex2 = 3 is not the index of a vertex (the file "
                   "has 3)"),
            std::string::npos)
      << e;
  e = readError(head + edgeHeader + "end_header\n" + points + "-1 1\n1 2\n");
  EXPECT_NE(e.find("line 14: edge 1: vertex1 = -1"), std::string::npos) << e;
  e = readError(head + "element edge 1\nproperty float vertex1\nproperty float vertex2\n" +
                "end_header\n" + points + "0.5 1\n");
  EXPECT_NE(e.find("vertex1 = 0.5 is not the index"), std::string::npos) << e;
  e = readError(head + "element edge 1\nproperty int vertex1\nproperty list uchar int vertex2\n" +
                "end_header\n" + points + "0 1 1\n");
  EXPECT_NE(e.find("line 7: the edge element has no scalar properties 'vertex1' and 'vertex2'"),
            std::string::npos)
      << e;
  e = readError(head + edgeHeader + "end_header\n" + points + "0 1\n");
  EXPECT_NE(e.find("unexpected end of file: element 'edge' declares 2 items, found 1"),
            std::string::npos)
      << e;

  // Binary: an index out of range names its byte; a truncated edge list is refused before
  // reading it.
  PolylineSet lines;
  lines.vertices.setAbsolutePositions({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)});
  lines.offsets = {0, 3};
  std::ostringstream out;
  const std::vector<PlyEdge> edges = {{0, 1}, {1, 2}};
  writePly(lines.vertices, out, PlyEncoding::BinaryLittleEndian, &edges);
  std::string binary = out.str();
  EXPECT_EQ(readError(binary), "");
  const std::size_t lastIndex = binary.size() - 4;
  binary[lastIndex] = 7;  // edge 2: 1 -> 7
  e = readError(binary);
  EXPECT_NE(e.find("byte " + std::to_string(binary.size() - 8) +
                   ": edge 2: vertex2 = 7 is not the index of a vertex"),
            std::string::npos)
      << e;
  e = readError(out.str().substr(0, out.str().size() - 3));
  EXPECT_NE(e.find("element 'edge' declares 2 items of at least 8 bytes but only 13 bytes remain"),
            std::string::npos)
      << e;
  // The file reader names the path.
  ScratchDir dir;
  test::writeText(dir.file("cut.ply"), out.str().substr(0, out.str().size() - 3));
  try {
    readPolylines(dir.file("cut.ply"));
    ADD_FAILURE() << "a truncated file was read";
  } catch (const FileError& error) {
    EXPECT_EQ(error.file(), dir.file("cut.ply"));
  }
  // Dropping a vertex drops the edges that use it and renumbers the others.
  ReadOptions drop;
  drop.dropNonFinite = true;
  std::vector<PlyEdge> read;
  const std::string fourPoints = std::string("ply\nformat ascii 1.0\nelement vertex 4\n") +
                                 "property float x\nproperty float y\nproperty float z\n" +
                                 edgeHeader + "end_header\n0 0 0\nnan 0 0\n2 0 0\n3 0 0\n" +
                                 "0 1\n2 3\n";
  ReadReport report;
  const PointCloud kept = readPly(fourPoints, "x.ply", drop, &report, &read);
  EXPECT_EQ(kept.size(), 3u);
  EXPECT_EQ(report.droppedNonFinite, 1u);
  ASSERT_EQ(read.size(), 1u);
  EXPECT_EQ(read[0], (PlyEdge{1, 2}));
  EXPECT_DOUBLE_EQ(kept.absolutePosition(read[0][0]).x(), 2.0);
}

TEST(Polylines, MissingFilesAndOtherExtensionsAreRefused) {
  ScratchDir dir;
  try {
    readPolylines(dir.file("missing.ply"));
    ADD_FAILURE();
  } catch (const FileError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.ply: cannot open the file"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(readPolylines(dir.file("lines.obj")), OptionError);
  EXPECT_THROW(writePolylines(makeLines(), dir.file("lines.xyz")), OptionError);
  EXPECT_EQ(dir.entryCount(), 0u);
}

TEST(Polylines, MalformedSetsAreOptionErrorsNamingTheField) {
  auto message = [](const PolylineSet& lines) {
    try {
      validatePolylineSet(lines, "out.ply");
    } catch (const OptionError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  PolylineSet lines = makeLines();
  EXPECT_EQ(message(lines), "");
  lines.closed.clear();  // all open
  EXPECT_EQ(message(lines), "");
  lines.closed = {1};
  EXPECT_NE(message(lines).find("out.ply: PolylineSet::closed has 1 flags for 4 lines"),
            std::string::npos);
  lines = makeLines();
  lines.offsets.back() = 13;
  EXPECT_NE(message(lines).find("PolylineSet::offsets must start at 0 and end at the vertex "
                                "count 14"),
            std::string::npos)
      << message(lines);
  lines = makeLines();
  lines.offsets = {0, 4, 13, 14};  // a line of one vertex
  EXPECT_NE(message(lines).find("PolylineSet::offsets: line 2 has 1 vertex"), std::string::npos)
      << message(lines);
  lines.offsets = {0, 9, 4, 14};
  EXPECT_NE(message(lines).find("PolylineSet::offsets decrease at line 1"), std::string::npos)
      << message(lines);
  lines.offsets.clear();
  EXPECT_NE(message(lines).find("PolylineSet::offsets is empty but there are 14 vertices"),
            std::string::npos);
}

TEST(Polylines, AFailedWriteLeavesNoFileAndKeepsAnEarlierOne) {
  ScratchDir dir;
  PolylineSet bad = makeLines();
  bad.offsets = {0, 1, 14};
  for (const char* name : {"a.ply", "a.obj"}) {
    EXPECT_THROW(writePolylines(bad, dir.file(name)), OptionError);
  }
  EXPECT_EQ(dir.entryCount(), 0u);
  // An attribute PLY cannot name fails inside the atomic write: the temporary file goes too.
  PolylineSet unnamed = makeLines();
  unnamed.vertices.addAttribute("two words", ScalarType::Float32);
  EXPECT_THROW(writePolylines(unnamed, dir.file("b.ply")), Error);
  EXPECT_EQ(dir.entryCount(), 0u);
  // Over an earlier file, which stays as it was.
  writePolylines(makeLines(), dir.file("b.ply"));
  const std::string before = test::readText(dir.file("b.ply"));
  EXPECT_THROW(writePolylines(unnamed, dir.file("b.ply")), Error);
  EXPECT_EQ(test::readText(dir.file("b.ply")), before);
  EXPECT_EQ(dir.entryCount(), 1u);
}

}  // namespace
}  // namespace scalespace
