#include <array>
#include <cmath>
#include <optional>
#include <vector>

#include "scalespace/core/Error.hpp"
#include "scalespace/io/ByteReader.hpp"
#include "scalespace/io/CloudBuilder.hpp"
#include "scalespace/io/PlyFormat.hpp"
#include "scalespace/io/TextParsing.hpp"

namespace scalespace {

namespace {

using namespace io_detail;

struct PlyProperty {
  std::string name;
  ScalarType type = ScalarType::Float32;  // the item type for a list
  bool isList = false;
  ScalarType countType = ScalarType::UInt8;
};

struct PlyElement {
  std::string name;
  std::size_t count = 0;
  std::size_t line = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  PlyEncoding encoding = PlyEncoding::Ascii;
  std::vector<PlyElement> elements;
  std::size_t dataOffset = 0;  // first byte after end_header
  std::size_t dataLine = 0;    // line number of end_header
};

std::optional<ScalarType> plyType(std::string_view name) {
  static const std::array<std::pair<const char*, ScalarType>, 16> types = {{
      {"char", ScalarType::Int8},
      {"int8", ScalarType::Int8},
      {"uchar", ScalarType::UInt8},
      {"uint8", ScalarType::UInt8},
      {"short", ScalarType::Int16},
      {"int16", ScalarType::Int16},
      {"ushort", ScalarType::UInt16},
      {"uint16", ScalarType::UInt16},
      {"int", ScalarType::Int32},
      {"int32", ScalarType::Int32},
      {"uint", ScalarType::UInt32},
      {"uint32", ScalarType::UInt32},
      {"float", ScalarType::Float32},
      {"float32", ScalarType::Float32},
      {"double", ScalarType::Float64},
      {"float64", ScalarType::Float64},
  }};
  for (const auto& [n, t] : types)
    if (name == n) return t;
  return std::nullopt;
}

const char* encodingName(PlyEncoding e) {
  switch (e) {
    case PlyEncoding::Ascii:
      return "ascii";
    case PlyEncoding::BinaryLittleEndian:
      return "binary_little_endian";
    case PlyEncoding::BinaryBigEndian:
      return "binary_big_endian";
  }
  return "";
}

PlyHeader parseHeader(std::string_view data, const std::string& file) {
  LineScanner lines(data);
  std::string_view line;
  if (!lines.next(line) || trim(line) != "ply")
    throw FileError(file, "line 1", "expected the PLY magic line 'ply'",
                    "this is not a PLY file: check the file extension");
  PlyHeader header;
  bool haveFormat = false;
  std::vector<std::string_view> tokens;
  while (true) {
    if (!lines.next(line))
      throw FileError(file, lineWhere(lines.lineNumber()), "the header has no end_header line",
                      "the file is truncated or not a PLY file");
    const std::string where = lineWhere(lines.lineNumber());
    splitWhitespace(line, tokens);
    if (tokens.empty()) continue;
    const std::string_view keyword = tokens[0];
    if (keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "end_header") break;
    if (keyword == "format") {
      if (tokens.size() != 3 || tokens[2] != "1.0")
        throw FileError(file, where, "expected 'format <encoding> 1.0'");
      if (tokens[1] == "ascii")
        header.encoding = PlyEncoding::Ascii;
      else if (tokens[1] == "binary_little_endian")
        header.encoding = PlyEncoding::BinaryLittleEndian;
      else if (tokens[1] == "binary_big_endian")
        header.encoding = PlyEncoding::BinaryBigEndian;
      else
        throw FileError(file, where, "unknown PLY encoding " + quoted(tokens[1]),
                        "expected ascii, binary_little_endian or binary_big_endian");
      haveFormat = true;
    } else if (keyword == "element") {
      const auto count = tokens.size() == 3 ? parseUnsigned(tokens[2]) : std::nullopt;
      if (!count) throw FileError(file, where, "expected 'element <name> <count>'");
      for (const auto& e : header.elements)
        if (e.name == tokens[1])
          throw FileError(file, where, "element '" + e.name + "' is declared twice");
      header.elements.push_back(
          PlyElement{std::string(tokens[1]), std::size_t(*count), lines.lineNumber(), {}});
    } else if (keyword == "property") {
      if (header.elements.empty())
        throw FileError(file, where, "property declared before any element");
      PlyProperty property;
      if (tokens.size() == 5 && tokens[1] == "list") {
        const auto countType = plyType(tokens[2]);
        const auto itemType = plyType(tokens[3]);
        if (!countType || !itemType || !isIntegerType(*countType))
          throw FileError(file, where, "bad list property types",
                          "expected 'property list <integer type> <type> <name>'");
        property = PlyProperty{std::string(tokens[4]), *itemType, true, *countType};
      } else if (tokens.size() == 3) {
        const auto type = plyType(tokens[1]);
        if (!type)
          throw FileError(file, where, "unknown property type " + quoted(tokens[1]),
                          "expected char, uchar, short, ushort, int, uint, float, double or "
                          "int8 ... float64");
        property = PlyProperty{std::string(tokens[2]), *type, false, ScalarType::UInt8};
      } else {
        throw FileError(file, where, "expected 'property <type> <name>'");
      }
      for (const auto& p : header.elements.back().properties)
        if (p.name == property.name)
          throw FileError(file, where, "property '" + p.name + "' is declared twice");
      header.elements.back().properties.push_back(property);
    } else {
      throw FileError(file, where, "unknown header keyword " + quoted(keyword),
                      "expected format, element, property, comment, obj_info or end_header");
    }
  }
  if (!haveFormat) throw FileError(file, "", "the header has no 'format' line");
  header.dataOffset = lines.offset();
  header.dataLine = lines.lineNumber();
  return header;
}

/// How each vertex property is used.
struct VertexLayout {
  std::array<int, 3> position{-1, -1, -1};
  std::array<int, 3> normal{-1, -1, -1};
  std::vector<int> column;  // per property: attribute column index or -1
};

VertexLayout planVertex(const PlyElement& vertex, const std::string& file, CloudBuilder& builder) {
  VertexLayout layout;
  layout.column.assign(vertex.properties.size(), -1);
  static const char* positionNames[3] = {"x", "y", "z"};
  static const char* normalNames[3] = {"nx", "ny", "nz"};
  for (std::size_t i = 0; i < vertex.properties.size(); ++i) {
    if (vertex.properties[i].isList) continue;
    for (int k = 0; k < 3; ++k) {
      if (vertex.properties[i].name == positionNames[k]) layout.position[k] = int(i);
      if (vertex.properties[i].name == normalNames[k]) layout.normal[k] = int(i);
    }
  }
  for (int k = 0; k < 3; ++k)
    if (layout.position[k] < 0)
      throw FileError(
          file, lineWhere(vertex.line),
          std::string("the vertex element has no scalar property '") + positionNames[k] + "'",
          "a point cloud needs x, y and z");
  const bool normals = layout.normal[0] >= 0 && layout.normal[1] >= 0 && layout.normal[2] >= 0;
  if (normals)
    builder.enableNormals();
  else
    layout.normal = {-1, -1, -1};  // a partial normal is kept as plain attributes
  for (std::size_t i = 0; i < vertex.properties.size(); ++i) {
    const PlyProperty& p = vertex.properties[i];
    const bool used = int(i) == layout.position[0] || int(i) == layout.position[1] ||
                      int(i) == layout.position[2] || int(i) == layout.normal[0] ||
                      int(i) == layout.normal[1] || int(i) == layout.normal[2];
    if (!p.isList && !used) layout.column[i] = int(builder.addColumn(p.name, p.type));
  }
  return layout;
}

/// What a sink does with list properties: nothing (they are skipped) unless it says otherwise.
struct SkipsLists {
  static constexpr bool kKeepsLists = false;
  void setList(std::size_t, const std::vector<double>&) {}
};

/// Stores property `i`'s value into the point being assembled; `finish` adds the point.
struct VertexAssembler : SkipsLists {
  const VertexLayout& layout;
  CloudBuilder& builder;
  Vec3 position = Vec3::Zero();
  Vec3 normal = Vec3::Zero();
  std::vector<double> values;

  VertexAssembler(const VertexLayout& l, CloudBuilder& b)
      : layout(l), builder(b), values(b.columnCount(), 0.0) {}
  void set(std::size_t i, double value) {
    for (int k = 0; k < 3; ++k) {
      if (layout.position[k] == int(i)) position[k] = value;
      if (layout.normal[k] == int(i)) normal[k] = value;
    }
    if (layout.column[i] >= 0) values[std::size_t(layout.column[i])] = value;
  }
  template <class Where>
  void finish(Where&& where) {
    builder.addPoint(position, normal, values.data(), where);
  }
};

/// Which properties of the `edge` element hold its two vertex indices.
struct EdgeLayout {
  int vertex1 = -1, vertex2 = -1;
};

EdgeLayout planEdge(const PlyElement& edge, const std::string& file) {
  EdgeLayout layout;
  for (std::size_t i = 0; i < edge.properties.size(); ++i) {
    if (edge.properties[i].isList) continue;
    if (edge.properties[i].name == "vertex1") layout.vertex1 = int(i);
    if (edge.properties[i].name == "vertex2") layout.vertex2 = int(i);
  }
  if (layout.vertex1 < 0 || layout.vertex2 < 0)
    throw FileError(file, lineWhere(edge.line),
                    "the edge element has no scalar properties 'vertex1' and 'vertex2'",
                    "an edge is declared as 'property int vertex1' and 'property int vertex2'");
  return layout;
}

/// Collects the `edge` element's vertex index pairs, each checked against the vertex count as it
/// is read, so that the error names the place of the bad edge.
struct EdgeAssembler : SkipsLists {
  const EdgeLayout& layout;
  std::size_t vertexCount;
  const std::string& file;
  std::vector<PlyEdge>& edges;
  double ends[2] = {0, 0};

  void set(std::size_t i, double value) {
    if (int(i) == layout.vertex1) ends[0] = value;
    if (int(i) == layout.vertex2) ends[1] = value;
  }
  template <class Where>
  void finish(Where&& where) {
    for (int k = 0; k < 2; ++k)
      if (!(ends[k] >= 0 && ends[k] < double(vertexCount) && ends[k] == std::floor(ends[k])))
        throw FileError(file, where(),
                        "edge " + std::to_string(edges.size() + 1) + ": vertex" +
                            std::to_string(k + 1) + " = " + formatNumber(ends[k]) +
                            " is not the index of a vertex (the file has " +
                            std::to_string(vertexCount) + ")",
                        "vertex indices start at 0 and stay below the vertex count");
    edges.push_back({Index(ends[0]), Index(ends[1])});
  }
};

/// The `face` element's vertex index list: `vertex_indices` (the usual name) or `vertex_index`.
int planFace(const PlyElement& face, const std::string& file) {
  for (std::size_t i = 0; i < face.properties.size(); ++i)
    if (face.properties[i].isList &&
        (face.properties[i].name == "vertex_indices" || face.properties[i].name == "vertex_index"))
      return int(i);
  throw FileError(file, lineWhere(face.line),
                  "the face element has no list property 'vertex_indices'",
                  "a face is declared as 'property list uchar int vertex_indices'");
}

/// Collects the faces as triangles (polygons as fans, as OFF and OBJ), each index checked against
/// the vertex count as it is read; a face of fewer than 3 vertices is an error, as in OFF.
struct FaceAssembler {
  static constexpr bool kKeepsLists = true;
  int listIndex;
  std::size_t vertexCount;
  const std::string& file;
  std::vector<std::array<Index, 3>>& triangles;
  std::vector<double> polygon;
  std::size_t faces = 0;

  void set(std::size_t, double) {}
  void setList(std::size_t i, const std::vector<double>& values) {
    if (int(i) == listIndex) polygon = values;
  }
  template <class Where>
  void finish(Where&& where) {
    ++faces;
    if (polygon.size() < 3)
      throw FileError(
          file, where(),
          "face " + std::to_string(faces) + " has " + std::to_string(polygon.size()) + " vertices",
          "a face needs at least 3");
    for (const double v : polygon)
      if (!(v >= 0 && v < double(vertexCount) && v == std::floor(v)))
        throw FileError(file, where(),
                        "face " + std::to_string(faces) + ": vertex index " + formatNumber(v) +
                            " is not in [0, " + std::to_string(vertexCount) + ")",
                        "vertex indices start at 0 and stay below the vertex count");
    for (std::size_t k = 1; k + 1 < polygon.size(); ++k)
      triangles.push_back({Index(polygon[0]), Index(polygon[k]), Index(polygon[k + 1])});
    polygon.clear();
  }
};

/// For elements nobody reads: ascii values are still parsed (and so checked).
struct IgnoredItems : SkipsLists {
  void set(std::size_t, double) {}
  template <class Where>
  void finish(Where&&) {}
};

void skipBinaryList(ByteReader& in, const PlyProperty& p, bool big, const std::string& file) {
  const double count = in.readScalar(p.countType, big, "a list count");
  if (count < 0)
    throw FileError(file, byteWhere(in.offset()), "negative list length in '" + p.name + "'");
  std::size_t bytes = 0;
  if (!multiplyChecked(std::size_t(count), scalarTypeSize(p.type), bytes))
    throw FileError(file, byteWhere(in.offset()), "list too long");
  in.skip(bytes, "list items");
}

/// Decodes every item of `element` into `sink` (lists are skipped unless the sink keeps them).
template <class Sink>
void readBinaryItems(ByteReader& in, const PlyElement& element, bool big, const std::string& file,
                     Sink& sink) {
  std::vector<double> list;
  for (std::size_t n = 0; n < element.count; ++n) {
    const std::size_t start = in.offset();
    for (std::size_t i = 0; i < element.properties.size(); ++i) {
      const PlyProperty& p = element.properties[i];
      if (p.isList && Sink::kKeepsLists) {
        const double count = in.readScalar(p.countType, big, "a list count");
        if (count < 0 || count * double(scalarTypeSize(p.type)) > double(in.remaining()))
          throw FileError(file, byteWhere(in.offset()),
                          "list '" + p.name + "' declares " + formatNumber(count) +
                              " items but the file has fewer bytes left",
                          "the file is truncated or corrupt");
        list.resize(std::size_t(count));
        for (double& v : list) v = in.readScalar(p.type, big, "a list item");
        sink.setList(i, list);
      } else if (p.isList)
        skipBinaryList(in, p, big, file);
      else
        sink.set(i, in.readScalar(p.type, big, "a property value"));
    }
    sink.finish([&] { return byteWhere(start); });
  }
}

/// The elements a reader wants: the vertices always, the edges when `edges` is given, the faces
/// when `triangles` is.
struct ElementPlan {
  std::size_t vertexIndex = 0;
  const VertexLayout* vertex = nullptr;
  std::size_t edgeIndex = std::size_t(-1);  // none
  const EdgeLayout* edge = nullptr;
  std::size_t vertexCount = 0;
  std::vector<PlyEdge>* edges = nullptr;
  std::size_t faceIndex = std::size_t(-1);  // none
  int faceList = -1;
  std::vector<std::array<Index, 3>>* triangles = nullptr;
};

void readBinary(const PlyHeader& header, std::string_view data, const std::string& file,
                CloudBuilder& builder, const ElementPlan& plan) {
  const bool big = header.encoding == PlyEncoding::BinaryBigEndian;
  ByteReader in(data, file);
  in.seek(header.dataOffset, "the end of the header");
  for (std::size_t e = 0; e < header.elements.size(); ++e) {
    const PlyElement& element = header.elements[e];
    if (element.properties.empty()) continue;  // nothing stored, whatever the count
    // Each instance takes at least `minimum` bytes: check the declared count against what the
    // file holds before looping or allocating.
    std::size_t minimum = 0;
    bool fixed = true;
    for (const auto& p : element.properties) {
      minimum += scalarTypeSize(p.isList ? p.countType : p.type);
      fixed = fixed && !p.isList;
    }
    std::size_t needed = 0;
    if (!multiplyChecked(element.count, minimum, needed) || needed > in.remaining())
      throw FileError(file, byteWhere(in.offset()),
                      "element '" + element.name + "' declares " + std::to_string(element.count) +
                          " items of at least " + std::to_string(minimum) + " bytes but only " +
                          std::to_string(in.remaining()) + " bytes remain",
                      "the file is truncated or its header count is wrong");
    if (e == plan.vertexIndex) {
      builder.reserve(element.count);
      VertexAssembler vertex(*plan.vertex, builder);
      readBinaryItems(in, element, big, file, vertex);
    } else if (e == plan.edgeIndex) {
      plan.edges->reserve(element.count);
      EdgeAssembler edge{{}, *plan.edge, plan.vertexCount, file, *plan.edges};
      readBinaryItems(in, element, big, file, edge);
    } else if (e == plan.faceIndex) {
      plan.triangles->reserve(element.count);
      FaceAssembler face{plan.faceList, plan.vertexCount, file, *plan.triangles, {}, 0};
      readBinaryItems(in, element, big, file, face);
    } else if (fixed) {
      in.skip(needed, element.name.c_str());
    } else {
      for (std::size_t n = 0; n < element.count; ++n)
        for (const auto& p : element.properties) {
          if (p.isList)
            skipBinaryList(in, p, big, file);
          else
            in.skip(scalarTypeSize(p.type), "a property");
        }
    }
  }
}

/// Parses the lines of every item of `element` into `sink`.
template <class Sink>
void readAsciiItems(LineScanner& lines, std::size_t lineBase, const PlyElement& element,
                    const std::string& file, Sink& sink) {
  std::vector<std::string_view> tokens;
  std::vector<double> list;
  std::string_view line;
  for (std::size_t n = 0; n < element.count; ++n) {
    do {
      if (!lines.next(line))
        throw FileError(file, lineWhere(lineBase + lines.lineNumber() + 1),
                        "unexpected end of file: element '" + element.name + "' declares " +
                            std::to_string(element.count) + " items, found " + std::to_string(n),
                        "the file is truncated or its header count is wrong");
      splitWhitespace(line, tokens);
    } while (tokens.empty());
    const std::size_t lineNumber = lineBase + lines.lineNumber();
    std::size_t t = 0;
    auto nextNumber = [&](ScalarType type, const std::string& name) {
      if (t >= tokens.size())
        throw FileError(file, lineWhere(lineNumber),
                        "too few values: property '" + name + "' is missing");
      const auto value = parseNumber(tokens[t]);
      if (!value || !fitsScalarType(*value, type))
        throw FileError(file, lineWhere(lineNumber),
                        quoted(tokens[t]) + " is not a valid " + scalarTypeName(type) +
                            " for property '" + name + "'");
      ++t;
      return toStoredValue(*value, type);  // a float property holds a float
    };
    for (std::size_t i = 0; i < element.properties.size(); ++i) {
      const PlyProperty& p = element.properties[i];
      if (p.isList) {
        const double count = nextNumber(p.countType, p.name);
        if (count < 0 || count > double(tokens.size() - t))
          throw FileError(file, lineWhere(lineNumber),
                          "list '" + p.name + "' declares " + formatNumber(count) +
                              " items but the line has fewer values");
        list.resize(std::size_t(count));
        for (double& v : list) v = nextNumber(p.type, p.name);
        if (Sink::kKeepsLists) sink.setList(i, list);
      } else {
        sink.set(i, nextNumber(p.type, p.name));
      }
    }
    if (t != tokens.size())
      throw FileError(
          file, lineWhere(lineNumber),
          "expected " + std::to_string(t) + " values, found " + std::to_string(tokens.size()),
          "each " + element.name + " must be on its own line");
    sink.finish([&] { return lineWhere(lineNumber); });
  }
}

void readAscii(const PlyHeader& header, std::string_view data, const std::string& file,
               CloudBuilder& builder, const ElementPlan& plan) {
  LineScanner lines(data.substr(header.dataOffset));
  const std::size_t lineBase = header.dataLine;
  for (std::size_t e = 0; e < header.elements.size(); ++e) {
    const PlyElement& element = header.elements[e];
    if (element.properties.empty()) continue;
    // Every item is a line of at least one character plus its newline.
    if (element.count > lines.remainingBytes() / 2 + 1)
      throw FileError(file, lineWhere(lineBase + lines.lineNumber() + 1),
                      "element '" + element.name + "' declares " + std::to_string(element.count) +
                          " items but the file has only " + std::to_string(lines.remainingBytes()) +
                          " bytes left",
                      "the file is truncated or its header count is wrong");
    if (e == plan.vertexIndex) {
      builder.reserve(element.count);
      VertexAssembler vertex(*plan.vertex, builder);
      readAsciiItems(lines, lineBase, element, file, vertex);
    } else if (e == plan.edgeIndex) {
      plan.edges->reserve(element.count);
      EdgeAssembler edge{{}, *plan.edge, plan.vertexCount, file, *plan.edges};
      readAsciiItems(lines, lineBase, element, file, edge);
    } else if (e == plan.faceIndex) {
      plan.triangles->reserve(element.count);
      FaceAssembler face{plan.faceList, plan.vertexCount, file, *plan.triangles, {}, 0};
      readAsciiItems(lines, lineBase, element, file, face);
    } else {
      IgnoredItems ignored;
      readAsciiItems(lines, lineBase, element, file, ignored);
    }
  }
}

constexpr Index kDroppedVertex = Index(-1);

/// Each file vertex's index among the kept ones, kDroppedVertex for a skipped one.
std::vector<Index> renumberAfterDrops(std::size_t vertexCount,
                                      const std::vector<std::size_t>& dropped) {
  std::vector<Index> renumbered(vertexCount, 0);
  for (std::size_t d : dropped) renumbered[d] = kDroppedVertex;
  Index next = 0;
  for (Index& r : renumbered)
    if (r != kDroppedVertex) r = next++;
  return renumbered;
}

/// Drops the items (edges, triangles) that use a skipped vertex and renumbers the others.
template <std::size_t N>
void dropAndRenumber(std::vector<std::array<Index, N>>& items,
                     const std::vector<Index>& renumbered) {
  std::size_t kept = 0;
  for (const std::array<Index, N>& item : items) {
    std::array<Index, N> mapped;
    bool usable = true;
    for (std::size_t k = 0; k < N; ++k) {
      mapped[k] = renumbered[std::size_t(item[k])];
      usable = usable && mapped[k] != kDroppedVertex;
    }
    if (usable) items[kept++] = mapped;
  }
  items.resize(kept);
}

}  // namespace

PointCloud readPly(std::string_view data, const std::string& file, const ReadOptions& options,
                   ReadReport* report, std::vector<PlyEdge>* edges,
                   std::vector<std::array<Index, 3>>* triangles) {
  const PlyHeader header = parseHeader(data, file);
  ElementPlan plan;
  plan.vertexIndex = header.elements.size();
  for (std::size_t e = 0; e < header.elements.size(); ++e) {
    if (header.elements[e].name == "vertex") plan.vertexIndex = e;
    if (header.elements[e].name == "edge" && edges) plan.edgeIndex = e;
    if (header.elements[e].name == "face" && triangles) plan.faceIndex = e;
  }
  if (plan.vertexIndex == header.elements.size())
    throw FileError(file, lineWhere(header.dataLine), "the header declares no 'vertex' element",
                    "a point cloud PLY needs 'element vertex <count>' with x, y, z properties");
  if (edges) edges->clear();
  if (triangles) triangles->clear();
  CloudBuilder builder(file, options);
  const VertexLayout vertex = planVertex(header.elements[plan.vertexIndex], file, builder);
  plan.vertex = &vertex;
  EdgeLayout edge;
  if (plan.edgeIndex < header.elements.size() &&
      !header.elements[plan.edgeIndex].properties.empty()) {
    edge = planEdge(header.elements[plan.edgeIndex], file);
    plan.edge = &edge;
    plan.edges = edges;
  } else {
    plan.edgeIndex = std::size_t(-1);  // no edge stored
  }
  plan.vertexCount = header.elements[plan.vertexIndex].count;
  if (plan.faceIndex < header.elements.size() &&
      !header.elements[plan.faceIndex].properties.empty()) {
    plan.faceList = planFace(header.elements[plan.faceIndex], file);
    plan.triangles = triangles;
  } else {
    plan.faceIndex = std::size_t(-1);  // no face stored
  }
  if (edges || triangles) builder.recordDroppedOrdinals();
  if (header.encoding == PlyEncoding::Ascii)
    readAscii(header, data, file, builder, plan);
  else
    readBinary(header, data, file, builder, plan);
  if ((edges || triangles) && !builder.droppedOrdinals().empty()) {
    const std::vector<Index> renumbered =
        renumberAfterDrops(plan.vertexCount, builder.droppedOrdinals());
    if (edges) dropAndRenumber(*edges, renumbered);
    if (triangles) dropAndRenumber(*triangles, renumbered);
  }
  return builder.finish(report, std::string("ply (") + encodingName(header.encoding) + ")");
}

bool plyDeclaresFaces(std::string_view data, const std::string& file) {
  for (const PlyElement& element : parseHeader(data, file).elements)
    if (element.name == "face" && element.count > 0 && !element.properties.empty()) return true;
  return false;
}

}  // namespace scalespace
