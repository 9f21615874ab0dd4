#include "scalespace/planes/PlaneExport.hpp"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/JsonInteger.hpp"
#include "scalespace/io/AtomicFile.hpp"
#include "scalespace/render/ColorMap.hpp"

namespace scalespace {

namespace {
// Absolute plane offset: n . (x_rel + origin) = offset_rel + n . origin.
double absoluteOffset(const PlaneComponent& c, const Vec3& origin) {
  return c.plane.offset + c.plane.normal.dot(origin);
}
}  // namespace

void writeComponentsJson(const PlaneModel& model, const Vec3& origin, const std::string& input,
                         const std::string& path) {
  nlohmann::json root;
  root["format"] = "scalespace-planes-1";
  root["input"] = input;
  root["point_count"] = model.membership.pointCount;
  root["scales"] = model.scales;
  root["persistence_definition"] = "death_level - birth_level";
  root["planarity_split"] = model.planaritySplit;
  nlohmann::json list = nlohmann::json::array();
  for (const PlaneComponent& c : model.components) {
    nlohmann::json j;
    j["id"] = c.id;
    j["birth_level"] = c.birthLevel;
    j["birth_scale"] = c.birthScale;
    j["death_level"] = c.deathLevel;
    j["death_scale"] = c.deathScale;
    j["persistence"] = c.persistence;
    j["representative_level"] = c.representativeLevel;
    j["point_count"] = c.pointCount;
    j["normal"] = {c.plane.normal.x(), c.plane.normal.y(), c.plane.normal.z()};
    j["offset"] = absoluteOffset(c, origin);
    j["rms"] = c.plane.rms;
    j["representative_scale"] = c.representativeScale;
    j["planar"] = c.planar;
    j["noise_limited"] = c.noiseLimited;
    j["area"] = c.area;
    j["plane_valid"] = c.plane.valid;
    list.push_back(std::move(j));
  }
  root["components"] = std::move(list);
  writeFileAtomically(path, [&](std::ostream& out) { out << root.dump(1) << '\n'; });
}

void writeComponentsCsv(const PlaneModel& model, const Vec3& origin, const std::string& path) {
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "id,birth_level,birth_scale,death_level,death_scale,persistence,nx,ny,nz,offset,rms,"
           "area,point_count,representative_scale,planar,noise_limited\n";
    out << std::setprecision(17);
    for (const PlaneComponent& c : model.components)
      out << c.id << ',' << c.birthLevel << ',' << c.birthScale << ',' << c.deathLevel << ','
          << c.deathScale << ',' << c.persistence << ',' << c.plane.normal.x() << ','
          << c.plane.normal.y() << ',' << c.plane.normal.z() << ',' << absoluteOffset(c, origin)
          << ',' << c.plane.rms << ',' << c.area << ',' << c.pointCount << ','
          << c.representativeScale << ',' << (c.planar ? 1 : 0) << ',' << (c.noiseLimited ? 1 : 0)
          << '\n';
  });
}

void addPlaneLabelColumns(PointCloud& cloud, const std::vector<int>& labels) {
  if (labels.size() != cloud.size())
    throw Error("addPlaneLabelColumns: " + std::to_string(labels.size()) + " labels for " +
                std::to_string(cloud.size()) + " points");
  auto& id = cloud.addAttribute("plane_id", ScalarType::Int32);
  auto& red = cloud.addAttribute("red", ScalarType::UInt8);
  auto& green = cloud.addAttribute("green", ScalarType::UInt8);
  auto& blue = cloud.addAttribute("blue", ScalarType::UInt8);
  const std::vector<Rgb> colors = colorizeLabels(std::vector<double>(labels.begin(), labels.end()));
  for (std::size_t i = 0; i < labels.size(); ++i) {
    id.values[i] = labels[i];
    red.values[i] = colors[i].r;
    green.values[i] = colors[i].g;
    blue.values[i] = colors[i].b;
  }
}

void writeOutlinesObj(const std::vector<PlaneComponent>& components, const Vec3& origin,
                      const std::string& path) {
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "# scalespace plane outlines: one closed polyline per alpha-shape boundary loop\n";
    out << std::setprecision(17);
    std::size_t next = 1;  // OBJ vertex indices start at 1
    for (const PlaneComponent& c : components) {
      if (c.outlines.empty()) continue;
      out << "g component_" << c.id << '\n';
      for (const auto& loop : c.outlines) {
        if (loop.size() < 2) continue;
        for (const Vec3& p : loop) {
          const Vec3 a = p + origin;
          out << "v " << a.x() << ' ' << a.y() << ' ' << a.z() << '\n';
        }
        out << 'l';
        for (std::size_t k = 0; k < loop.size(); ++k) out << ' ' << next + k;
        out << ' ' << next << '\n';  // closed
        next += loop.size();
      }
    }
  });
}

void writeOutlinesPly(const std::vector<PlaneComponent>& components, const Vec3& origin,
                      const std::string& path) {
  std::size_t vertices = 0;
  for (const auto& c : components)
    for (const auto& loop : c.outlines)
      if (loop.size() >= 2) vertices += loop.size();
  writeFileAtomically(path, [&](std::ostream& out) {
    out << "ply\nformat ascii 1.0\ncomment scalespace plane outlines\n";
    out << "element vertex " << vertices << "\nproperty double x\nproperty double y\n"
        << "property double z\nelement edge " << vertices
        << "\nproperty int vertex1\nproperty int vertex2\nproperty int component\nend_header\n";
    out << std::setprecision(17);
    for (const auto& c : components)
      for (const auto& loop : c.outlines)
        if (loop.size() >= 2)
          for (const Vec3& p : loop) {
            const Vec3 a = p + origin;
            out << a.x() << ' ' << a.y() << ' ' << a.z() << '\n';
          }
    std::size_t base = 0;
    for (const auto& c : components)
      for (const auto& loop : c.outlines) {
        if (loop.size() < 2) continue;
        for (std::size_t k = 0; k < loop.size(); ++k)
          out << base + k << ' ' << base + (k + 1) % loop.size() << ' ' << c.id << '\n';
        base += loop.size();
      }
  });
}

void writePersistenceDiagramSvg(const PlaneModel& model, const std::string& path) {
  if (model.scales.empty()) throw OptionError("persistence diagram: the model has no scales");
  const double size = 480, margin = 60, plot = size - 2 * margin;
  // Log axes over [t_0, t_M-1], padded by half a decade step.
  const double lo = std::log10(model.scales.front()), hiRaw = std::log10(model.scales.back());
  const double pad = std::max(0.05, 0.05 * (hiRaw - lo));
  const double a = lo - pad, b = hiRaw + pad;
  auto X = [&](double t) { return margin + (std::log10(t) - a) / (b - a) * plot; };
  auto Y = [&](double t) { return size - margin - (std::log10(t) - a) / (b - a) * plot; };
  int maxPers = 1;
  for (const auto& c : model.components) maxPers = std::max(maxPers, c.persistence);
  std::ostringstream svg;
  svg << std::setprecision(6);
  svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << size << "\" height=\"" << size
      << "\" viewBox=\"0 0 " << size << ' ' << size
      << "\" font-family=\"sans-serif\" font-size=\"12\">\n";
  svg << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  svg << "<rect x=\"" << margin << "\" y=\"" << margin << "\" width=\"" << plot << "\" height=\""
      << plot << "\" fill=\"none\" stroke=\"black\"/>\n";
  // Decade ticks and labels (10^k) on both axes.
  for (int k = int(std::ceil(a)); k <= int(std::floor(b)); ++k) {
    const double t = std::pow(10.0, k);
    svg << "<line x1=\"" << X(t) << "\" y1=\"" << size - margin << "\" x2=\"" << X(t) << "\" y2=\""
        << size - margin + 5 << "\" stroke=\"black\"/>\n";
    svg << "<text x=\"" << X(t) << "\" y=\"" << size - margin + 18 << "\" text-anchor=\"middle\">1e"
        << k << "</text>\n";
    svg << "<line x1=\"" << margin - 5 << "\" y1=\"" << Y(t) << "\" x2=\"" << margin << "\" y2=\""
        << Y(t) << "\" stroke=\"black\"/>\n";
    svg << "<text x=\"" << margin - 8 << "\" y=\"" << Y(t) + 4 << "\" text-anchor=\"end\">1e" << k
        << "</text>\n";
  }
  svg << "<line x1=\"" << X(std::pow(10, a)) << "\" y1=\"" << Y(std::pow(10, a)) << "\" x2=\""
      << X(std::pow(10, b)) << "\" y2=\"" << Y(std::pow(10, b))
      << "\" stroke=\"grey\" stroke-dasharray=\"4 3\"/>\n";
  svg << "<text x=\"" << size / 2 << "\" y=\"" << size - 15
      << "\" text-anchor=\"middle\">birth scale</text>\n";
  svg << "<text x=\"18\" y=\"" << size / 2 << "\" text-anchor=\"middle\" transform=\"rotate(-90 18 "
      << size / 2 << ")\">death scale</text>\n";
  svg << "<text x=\"" << size / 2 << "\" y=\"30\" text-anchor=\"middle\">persistence diagram ("
      << model.components.size() << " components, " << model.scales.size() << " scales)</text>\n";
  for (const auto& c : model.components) {
    const Rgb col = viridis(double(c.persistence) / maxPers);
    svg << "<circle cx=\"" << X(c.birthScale) << "\" cy=\"" << Y(c.deathScale)
        << "\" r=\"3.5\" fill=\"rgb(" << int(col.r) << ',' << int(col.g) << ',' << int(col.b)
        << ")\" fill-opacity=\"0.8\"><title>component " << c.id << ": persistence " << c.persistence
        << "</title></circle>\n";
  }
  svg << "</svg>\n";
  const std::string text = svg.str();
  writeFileAtomically(path, [&](std::ostream& out) { out << text; });
}

void writeMembership(const PointMembership& m, const std::string& path) {
  writeFileAtomically(path, [&](std::ostream& out) {
    const std::uint64_t n = m.pointCount;
    const std::uint32_t levels = std::uint32_t(m.levelCount);
    out.write("SSPM", 4);
    out.write(reinterpret_cast<const char*>(&n), sizeof n);
    out.write(reinterpret_cast<const char*>(&levels), sizeof levels);
    static_assert(sizeof(int) == 4, "membership ids are written as 32-bit integers");
    out.write(reinterpret_cast<const char*>(m.ids.data()), std::streamsize(m.ids.size() * 4));
  });
}

PointMembership readMembership(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FileError(path, "", "cannot open", "run `scalespace planes` first");
  char magic[4] = {};
  std::uint64_t n = 0;
  std::uint32_t levels = 0;
  in.read(magic, 4);
  in.read(reinterpret_cast<char*>(&n), sizeof n);
  in.read(reinterpret_cast<char*>(&levels), sizeof levels);
  if (!in || std::memcmp(magic, "SSPM", 4) != 0)
    throw FileError(path, "byte 0", "not a scalespace membership file");
  PointMembership m;
  m.pointCount = std::size_t(n);
  m.levelCount = int(levels);
  // 16 + 4 n levels bytes, checked by division: the product can wrap (n = 2^62 gives 16 bytes),
  // and without levels there must be no points either (the queries allocate per point).
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  const std::uintmax_t ids = ec || size < 16 ? 0 : (size - 16) / 4;
  const bool consistent =
      !ec && size >= 16 && (size - 16) % 4 == 0 &&
      (levels == 0 ? ids == 0 && n == 0 : ids % levels == 0 && ids / levels == n);
  if (!consistent)
    throw FileError(path, "byte 4",
                    "truncated or corrupt: " + std::to_string(n) + " points and " +
                        std::to_string(levels) + " levels do not match the size (" +
                        std::to_string(size) + " bytes)",
                    "run `scalespace planes` again");
  m.ids.resize(std::size_t(n) * levels);
  in.read(reinterpret_cast<char*>(m.ids.data()), std::streamsize(m.ids.size() * 4));
  if (!in) throw FileError(path, "", "truncated");
  return m;
}

PlaneModel readPlaneModel(const std::string& directory, std::string* input) {
  const std::string jsonPath = (std::filesystem::path(directory) / "components.json").string();
  std::ifstream in(jsonPath);
  if (!in) throw FileError(jsonPath, "", "cannot open", "run `scalespace planes IN -o DIR` first");
  nlohmann::json root;
  try {
    in >> root;
  } catch (const std::exception& e) {
    throw FileError(jsonPath, "", std::string("invalid JSON: ") + e.what());
  }
  PlaneModel model;
  std::string where;  // the component being read, for the message
  try {
    model.scales = root.at("scales").get<std::vector<double>>();
    model.planaritySplit = root.value("planarity_split", false);  // absent before the split
    if (input) *input = root.at("input").get<std::string>();
    for (const auto& j : root.at("components")) {
      where = "component " + std::to_string(model.components.size());
      PlaneComponent c;
      c.id = jsonInteger<int>(j.at("id"));
      c.birthLevel = jsonInteger<int>(j.at("birth_level"));
      c.birthScale = j.at("birth_scale").get<double>();
      c.deathLevel = jsonInteger<int>(j.at("death_level"));
      c.deathScale = j.at("death_scale").get<double>();
      c.persistence = jsonInteger<int>(j.at("persistence"));
      c.representativeLevel = jsonInteger<int>(j.at("representative_level"));
      c.pointCount = jsonInteger<std::size_t>(j.at("point_count"));
      const auto n = j.at("normal").get<std::vector<double>>();
      if (n.size() != 3) throw std::runtime_error("normal must have 3 values");
      c.plane.normal = Vec3(n[0], n[1], n[2]);
      c.plane.offset = j.at("offset").get<double>();  // absolute coordinates
      c.plane.rms = j.at("rms").get<double>();
      c.plane.valid = j.value("plane_valid", true);
      c.area = j.at("area").get<double>();
      c.planar = j.value("planar", true);  // absent from results written before it existed
      c.noiseLimited = c.planar && j.value("noise_limited", false);
      if (c.id != int(model.components.size())) throw std::runtime_error("ids must be 0, 1, ...");
      // The levels index the scales and membership.bin's levels (the queries, `segment`).
      if (c.birthLevel < 0 || c.birthLevel > c.representativeLevel ||
          c.representativeLevel > c.deathLevel || c.deathLevel >= model.scaleCount() ||
          c.persistence != c.deathLevel - c.birthLevel)
        throw std::runtime_error(
            "birth_level " + std::to_string(c.birthLevel) + ", representative_level " +
            std::to_string(c.representativeLevel) + ", death_level " +
            std::to_string(c.deathLevel) + ", persistence " + std::to_string(c.persistence) +
            ": expected 0 <= birth <= representative <= death < " +
            std::to_string(model.scaleCount()) + " (the scales) and persistence = death - birth");
      c.representativeScale = model.scales[std::size_t(c.representativeLevel)];
      model.components.push_back(std::move(c));
    }
  } catch (const std::exception& e) {
    throw FileError(jsonPath, where, std::string("unexpected content: ") + e.what(),
                    "run `scalespace planes` again");
  }
  model.membership = readMembership((std::filesystem::path(directory) / "membership.bin").string());
  if (model.membership.levelCount != model.scaleCount())
    throw FileError(directory, "", "components.json and membership.bin disagree on the scales");
  for (int id : model.membership.ids)
    if (id < -1 || id >= int(model.components.size()))
      throw FileError(directory + "/membership.bin", "", "component id out of range");
  return model;
}

bool isPlaneResult(const std::string& directory) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(directory, ec)) return false;
  std::ifstream in(fs::path(directory) / "membership.bin", std::ios::binary);
  char magic[4] = {};
  return in.read(magic, 4) && std::string(magic, 4) == "SSPM" &&
         fs::is_regular_file(fs::path(directory) / "components.json", ec);
}

void checkPlaneResultDestination(const std::string& directory) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(directory, ec)) return;
  if (!fs::is_directory(directory, ec))
    throw FileError(directory, "", "exists and is not a folder",
                    "choose another output folder for the planes");
  // Our five files replace theirs: only ever in an empty folder or an earlier result.
  if (!fs::is_empty(directory, ec) && !isPlaneResult(directory))
    throw FileError(directory, "",
                    "is a folder that holds other files and no planes result: refusing to write "
                    "into it",
                    "choose a new or empty output folder");
}

void writePlaneModel(const PlaneModel& model, const Vec3& origin, const std::string& input,
                     const std::string& directory) {
  namespace fs = std::filesystem;
  checkPlaneResultDestination(directory);
  std::error_code ec;
  fs::create_directories(directory, ec);
  if (ec) throw FileError(directory, "", "cannot create the directory: " + ec.message());
  const fs::path dir(directory);
  writeMembership(model.membership, (dir / "membership.bin").string());
  writeComponentsCsv(model, origin, (dir / "components.csv").string());
  writeOutlinesObj(model.components, origin, (dir / "outlines.obj").string());
  writePersistenceDiagramSvg(model, (dir / "persistence.svg").string());
  writeComponentsJson(model, origin, input, (dir / "components.json").string());
}

}  // namespace scalespace
