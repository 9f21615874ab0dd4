#include "scalespace/scales/ScaleStackReader.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/FileSync.hpp"
#include "scalespace/core/JsonInteger.hpp"
#include "scalespace/scales/NpyFormat.hpp"
#include "scalespace/scales/StackChecksum.hpp"
#include "scalespace/scales/StackCodecs.hpp"
#include "scalespace/scales/StackLayout.hpp"

namespace fs = std::filesystem;

namespace scalespace {

// The store's internal pieces (StackLayout.hpp, StackCodecs.hpp, StackChecksum.hpp, NpyFormat.hpp).
using namespace store;

namespace {

// Reads stack data; a short read means a damaged (truncated) stack, whose only fix is recomputing.
void readStackBytes(int fd, void* data, std::size_t size, std::uint64_t offset,
                    const std::string& file) {
  preadAll(fd, data, size, offset, file,
           "the stack is damaged: recompute it with 'scalespace scales'");
}

// Checks the codec of a version-3 compact quantity in the manifest and reads its parameters into
// `codecs` (the decoders use the manifest's values, so that numpy and we decode alike).
void readCodec(const std::string& manifestPath, const Quantity& q, const nlohmann::json& entry,
               CompactCodecs& codecs) {
  const std::string fix = "recompute the stack with 'scalespace scales'";
  const std::string what = std::string("quantity '") + q.name + "': ";
  const std::string codec = entry.at("codec").get<std::string>();
  if (codec != q.codec || entry.at("scaling").get<std::string>() != q.scaling)
    throw FileError(manifestPath, "",
                    what + "codec '" + codec + "', scaling '" +
                        entry.at("scaling").get<std::string>() + "' (expected '" + q.codec +
                        "', '" + q.scaling + "')",
                    fix);
  if (std::strcmp(q.codec, "shared_exponent") == 0) {
    // Any bias decodes exactly; beyond 0..64 the values would be absurd (2^-64 t and finer).
    const int bias = jsonInteger<int>(entry.at("bias"));
    if (bias < 0 || bias > 64)
      throw FileError(manifestPath, "", what + "bias " + std::to_string(bias) + " is not in 0..64",
                      fix);
    codecs.offsetBias = bias;
  } else if (codec == "log8" || codec == "slog8") {
    const double lo = entry.at("log_min").get<double>(), hi = entry.at("log_max").get<double>();
    if (!(lo > 0) || !(hi > lo) || !std::isfinite(hi))
      throw FileError(manifestPath, "",
                      what + "log_min " + std::to_string(lo) + " and log_max " +
                          std::to_string(hi) + " must satisfy 0 < log_min < log_max < inf",
                      fix);
    (std::strcmp(q.name, "anisotropy") == 0 ? codecs.anisotropy : codecs.variation) =
        quant::Log8Code(lo, hi, codec == "slog8");
  }
}

}  // namespace

struct ScaleStackReader::Impl {
  fs::path dir;
  StackInfo info;
  std::vector<int> fds;  // one per quantity of the encoding
  QuantityTable table = quantities(StackEncoding::Float32, 1);
  CompactCodecs codecs;  // compact: the manifest's version, bias and log ranges
  std::vector<std::uint64_t> dataOffset;
  std::vector<std::string> files;
  std::vector<std::string> sums;
  int positionsFd = -1;
  std::uint64_t positionsOffset = 0;
  std::string positionsFile, positionsSum;
  // Compact: input positions relative to the origin (3 N), read on the first readScale.
  std::once_flag relOnce;
  std::vector<double> rel;

  const std::vector<double>& inputRel() {
    std::call_once(relOnce, [&] {
      rel.resize(3 * info.pointCount);
      readStackBytes(positionsFd, rel.data(), rel.size() * 8, positionsOffset, positionsFile);
      for (std::size_t k = 0; k < rel.size(); ++k) rel[k] -= info.origin[int(k % 3)];
    });
    return rel;
  }

  ~Impl() {
    for (int fd : fds)
      if (fd >= 0) ::close(fd);
    if (positionsFd >= 0) ::close(positionsFd);
  }

  // Opens an .npy file and checks magic, dtype, order, shape and size; returns the data offset.
  std::uint64_t openNpy(const std::string& file, const std::string& dtype,
                        const std::vector<std::size_t>& shape, std::size_t itemSize, int& fdOut) {
    const std::string fix =
        "the stack is damaged or was modified: recompute it with 'scalespace scales'";
    const int fd = ::open(file.c_str(), O_RDONLY);
    if (fd < 0) throw FileError(file, "", std::string("cannot open: ") + std::strerror(errno), fix);
    fdOut = fd;
    unsigned char pre[kNpyPreludeBytes];
    struct stat st {};
    ::fstat(fd, &st);
    if (st.st_size < off_t(kNpyPreludeBytes))
      throw FileError(file, "byte 0", "not a NumPy .npy file (too short)", fix);
    readStackBytes(fd, pre, kNpyPreludeBytes, 0, file);
    if (!isNpyVersion1(pre))
      throw FileError(file, "byte 0", "not a NumPy format 1.0 .npy file", fix);
    const std::size_t headerLen = npyDictLength(pre);
    if (std::uint64_t(st.st_size) < kNpyPreludeBytes + headerLen)
      throw FileError(file, "byte 10", "truncated .npy header", fix);
    std::string header(headerLen, '\0');
    readStackBytes(fd, header.data(), headerLen, kNpyPreludeBytes, file);
    // Only the header our writer writes is accepted (NpyFormat.hpp).
    const std::string want = npyHeader(dtype, shape).substr(kNpyPreludeBytes);
    if (header != want)
      throw FileError(file, "byte 10",
                      "header '" + header.substr(0, header.find('}') + 1) +
                          "' differs from the manifest (expected dtype " + dtype + ", shape " +
                          npyShapeText(shape) + ")",
                      fix);
    std::uint64_t count = itemSize;
    for (std::size_t s : shape) count *= s;
    const std::uint64_t expected = kNpyPreludeBytes + headerLen + count;
    if (std::uint64_t(st.st_size) != expected)
      throw FileError(file, "",
                      "size is " + std::to_string(st.st_size) + " bytes, expected " +
                          std::to_string(expected) + " from the manifest's shape",
                      fix);
    return kNpyPreludeBytes + headerLen;
  }
};

ScaleStackReader::ScaleStackReader(const std::string& path) : impl_(std::make_unique<Impl>()) {
  Impl& d = *impl_;
  d.dir = path;
  const std::string manifestPath = (d.dir / kManifest).string();
  std::error_code ec;
  if (!fs::is_directory(d.dir, ec))
    throw FileError(path, "", "not a scale stack directory",
                    "give the NAME.stack directory written by 'scalespace scales'");
  if (!fs::exists(manifestPath, ec))
    throw FileError(path, "", "no manifest.json: an incomplete stack (its writer was interrupted)",
                    "recompute it with 'scalespace scales'");
  nlohmann::json manifest;
  // A manifest nests 4 levels deep. Deeper JSON is refused while parsing: dump() (parametersJson,
  // manifestJson) recurses once per level and overflowed the stack at 100000 levels.
  constexpr int kMaxDepth = 32;
  const auto depthLimit = [&](int depth, nlohmann::json::parse_event_t, nlohmann::json&) {
    if (depth > kMaxDepth)
      throw FileError(
          manifestPath, "",
          "JSON nested deeper than " + std::to_string(kMaxDepth) + " levels: not a stack manifest",
          "recompute the stack with 'scalespace scales'");
    return true;
  };
  try {
    std::ifstream in(manifestPath);
    manifest = nlohmann::json::parse(in, depthLimit);
  } catch (const FileError&) {
    throw;
  } catch (const std::exception& e) {
    throw FileError(manifestPath, "", std::string("invalid JSON: ") + e.what(),
                    "recompute the stack with 'scalespace scales'");
  }
  const std::string fix = "recompute the stack with 'scalespace scales'";
  try {
    if (manifest.at("format").get<std::string>() != kFormatTag)
      throw FileError(manifestPath, "", "not a scalespace stack manifest", fix);
    StackInfo& info = d.info;
    info.formatVersion = jsonInteger<int>(manifest.at("format_version"));
    if (info.formatVersion < 1 || info.formatVersion > kStackFormatVersion)
      throw FileError(manifestPath, "",
                      "format version " + std::to_string(info.formatVersion) +
                          " is not supported (this program reads versions 1 to " +
                          std::to_string(kStackFormatVersion) + ")",
                      "recompute the stack with this version of scalespace");
    info.programVersion = manifest.at("program_version").get<std::string>();
    info.pointCount = jsonInteger<std::size_t>(manifest.at("point_count"));
    info.scales = manifest.at("scales").get<std::vector<double>>();
    if (info.scales.empty()) throw FileError(manifestPath, "", "the stack has no scales", fix);
    if (jsonInteger<std::size_t>(manifest.at("scale_count")) != info.scales.size())
      throw FileError(manifestPath, "", "scale_count differs from the number of scale values", fix);
    const auto origin = manifest.at("origin").get<std::vector<double>>();
    if (origin.size() != 3)
      throw FileError(manifestPath, "", "origin must have 3 coordinates", fix);
    info.origin = Vec3(origin[0], origin[1], origin[2]);
    info.inputChecksum = std::stoull(manifest.at("input_checksum").get<std::string>(), nullptr, 16);
    for (const auto& s : manifest.at("stats")) {
      ScaleStats st;
      st.t = s.at("t").get<double>();
      st.samples = jsonInteger<std::size_t>(s.at("samples"));
      st.meanNeighbors = s.at("mean_neighbors").get<double>();
      st.meanMlsSteps = s.value("mean_mls_steps", 0.0);  // absent from stacks of version <= 0.1
      st.validPoints = jsonInteger<std::size_t>(s.at("valid_points"));
      st.samplingSeconds = s.at("sampling_seconds").get<double>();
      st.indexSeconds = s.at("index_seconds").get<double>();
      st.projectionSeconds = s.at("projection_seconds").get<double>();
      info.stats.push_back(st);
    }
    if (info.stats.size() != info.scales.size())
      throw FileError(manifestPath, "",
                      "stats has " + std::to_string(info.stats.size()) + " entries for " +
                          std::to_string(info.scales.size()) + " scales",
                      fix);
    // Version 1 is float32 only; version 2 names its encoding.
    const std::string encoding =
        info.formatVersion == 1 ? "float32" : manifest.at("encoding").get<std::string>();
    if (encoding == "compact") {
      info.encoding = StackEncoding::Compact;
    } else if (encoding == "float32") {
      info.encoding = StackEncoding::Float32;
    } else {
      throw FileError(manifestPath, "", "unknown encoding '" + encoding + "'", fix);
    }
    const std::string quantisation = manifest.at("quantisation").get<std::string>();
    if (quantisation != (info.encoding == StackEncoding::Compact ? "compact" : "none"))
      throw FileError(manifestPath, "", "unknown quantisation '" + quantisation + "'", fix);
    info.clampedValues = manifest.contains("clamped_values")
                             ? jsonInteger<std::size_t>(manifest.at("clamped_values"))
                             : 0;
    d.codecs.version = info.formatVersion;
    d.table = quantities(info.encoding, info.formatVersion);
    for (std::size_t j = 0; j < info.scales.size(); ++j)
      if (!(info.scales[j] > 0) || !std::isfinite(info.scales[j]))
        throw FileError(manifestPath, "", "scale " + std::to_string(j) + " is not positive", fix);
    info.parametersJson = manifest.at("parameters").dump();
    info.manifestJson = manifest.dump(1);
    const std::size_t m = info.scales.size(), n = info.pointCount;
    std::size_t perScale = 0;
    for (const Quantity& q : d.table) {
      perScale += sliceBytes(q, n);
      const auto& entry = manifest.at("quantities").at(q.name);
      if (entry.at("dtype").get<std::string>() != q.dtype ||
          jsonIntegers<std::size_t>(entry.at("shape")) != quantityShape(q, m, n))
        throw FileError(manifestPath, "",
                        std::string("quantity '") + q.name + "' has an unexpected dtype or shape",
                        fix);
      if (q.codec) readCodec(manifestPath, q, entry, d.codecs);
      const std::string file = (d.dir / entry.at("file").get<std::string>()).string();
      d.fds.push_back(-1);
      d.dataOffset.push_back(
          d.openNpy(file, q.dtype, quantityShape(q, m, n), q.itemSize, d.fds.back()));
      d.files.push_back(file);
      d.sums.push_back(entry.at("checksum").get<std::string>());
    }
    info.bytesPerPointPerScale = n ? double(perScale) / double(n) : 0.0;
    const auto& pos = manifest.at("input_positions");
    d.positionsFile = (d.dir / pos.at("file").get<std::string>()).string();
    d.positionsSum = pos.at("checksum").get<std::string>();
    d.positionsOffset = d.openNpy(d.positionsFile, "<f8", {n, 3}, 8, d.positionsFd);
  } catch (const nlohmann::json::exception& e) {
    throw FileError(manifestPath, "", std::string("missing or malformed entry: ") + e.what(), fix);
  } catch (const std::invalid_argument&) {
    throw FileError(manifestPath, "", "input_checksum is not hexadecimal", fix);
  } catch (const std::out_of_range&) {
    throw FileError(manifestPath, "", "input_checksum is out of range", fix);
  }
}

ScaleStackReader::~ScaleStackReader() = default;

const StackInfo& ScaleStackReader::info() const { return impl_->info; }

ScaleLayer ScaleStackReader::readScale(std::size_t j) const {
  Impl& d = *impl_;
  if (j >= scaleCount())
    throw OptionError("scale " + std::to_string(j) + " is out of range: the stack has " +
                      std::to_string(scaleCount()) + " scales (0.." +
                      std::to_string(scaleCount() - 1) + ")");
  const std::size_t n = pointCount();
  ScaleLayer layer;
  layer.resize(n);
  const bool compact = info().encoding == StackEncoding::Compact;
  std::vector<std::vector<unsigned char>> bufs(compact ? kCompactFiles : 0);
  std::vector<const unsigned char*> rows;
  std::size_t k = 0;
  for (const Quantity& q : d.table) {
    const std::size_t bytes = sliceBytes(q, n);
    unsigned char* out = layerBytes(q, layer);
    if (compact) {
      bufs[k].resize(bytes);
      out = bufs[k].data();
      rows.push_back(out);
    }
    readStackBytes(d.fds[k], out, bytes, d.dataOffset[k] + std::uint64_t(j) * bytes, d.files[k]);
    ++k;
  }
  if (compact) decodeCompact(d.codecs, rows, 0, n, info().scales[j], d.inputRel().data(), layer, 0);
  return layer;
}

ScaleLayer ScaleStackReader::readPointSeries(std::size_t i) const {
  Impl& d = *impl_;
  if (i >= pointCount())
    throw OptionError("point " + std::to_string(i) + " is out of range: the stack has " +
                      std::to_string(pointCount()) + " points");
  const std::size_t m = scaleCount(), n = pointCount();
  ScaleLayer series;
  series.resize(m);
  if (info().encoding == StackEncoding::Compact) {
    double rel[3];
    readStackBytes(d.positionsFd, rel, 24, d.positionsOffset + std::uint64_t(i) * 24,
                   d.positionsFile);
    for (int c = 0; c < 3; ++c) rel[c] -= info().origin[c];
    unsigned char item[kCompactFiles][8];
    std::vector<const unsigned char*> ptrs(kCompactFiles);
    for (std::size_t j = 0; j < m; ++j) {
      std::size_t k = 0;
      for (const Quantity& q : d.table) {
        readStackBytes(d.fds[k], item[k], pointBytes(q), d.dataOffset[k] + pointOffset(q, n, j, i),
                       d.files[k]);
        ptrs[k] = item[k];
        ++k;
      }
      decodeCompact(d.codecs, ptrs, i % 8, 1, info().scales[j], rel, series, j);
    }
    return series;
  }
  std::size_t k = 0;
  for (const Quantity& q : d.table) {
    const std::size_t item = pointBytes(q);
    unsigned char* out = layerBytes(q, series);
    for (std::size_t j = 0; j < m; ++j)
      readStackBytes(d.fds[k], out + j * item, item, d.dataOffset[k] + pointOffset(q, n, j, i),
                     d.files[k]);
    ++k;
  }
  return series;
}

std::vector<Vec3> ScaleStackReader::inputPositions() const {
  const Impl& d = *impl_;
  std::vector<double> xyz(3 * pointCount());
  readStackBytes(d.positionsFd, xyz.data(), xyz.size() * 8, d.positionsOffset, d.positionsFile);
  std::vector<Vec3> out(pointCount());
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = Vec3(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
  return out;
}

void ScaleStackReader::verifyChecksums() const {
  const Impl& d = *impl_;
  auto check = [&](int fd, std::uint64_t offset, std::uint64_t bytes, const std::string& file,
                   const std::string& expected) {
    Checksum c;
    std::vector<unsigned char> buf(std::size_t(1) << 22);
    for (std::uint64_t done = 0; done < bytes;) {
      const std::size_t chunk = std::size_t(std::min<std::uint64_t>(buf.size(), bytes - done));
      readStackBytes(fd, buf.data(), chunk, offset + done, file);
      c.add(buf.data(), chunk);
      done += chunk;
    }
    if (hex64(c.value()) != expected)
      throw FileError(
          file, "", "checksum " + hex64(c.value()) + " differs from the manifest's " + expected,
          "the file was modified or damaged: recompute the stack with 'scalespace scales'");
  };
  const std::uint64_t m = scaleCount(), n = pointCount();
  std::size_t k = 0;
  for (const Quantity& q : d.table) {
    check(d.fds[k], d.dataOffset[k], m * std::uint64_t(sliceBytes(q, std::size_t(n))), d.files[k],
          d.sums[k]);
    ++k;
  }
  check(d.positionsFd, d.positionsOffset, n * 24, d.positionsFile, d.positionsSum);
}

void ScaleStackReader::checkInput(const PointCloud& cloud, const std::string& cloudName) const {
  const std::uint64_t sum = cloudChecksum(cloud);
  if (sum != info().inputChecksum)
    throw FileError(impl_->dir.string(), "",
                    "was computed from another cloud than " + cloudName + " (input checksum " +
                        hex64(info().inputChecksum) + ", this cloud " + hex64(sum) + ")",
                    "recompute the stack from this cloud");
}

bool isScaleStack(const std::string& path) {
  std::error_code ec;
  if (!fs::is_directory(path, ec)) return false;
  // Recognised by its manifest's format tag, not by the name: a folder is only ever replaced when
  // this program wrote it (a user's folder that happens to hold a manifest.json is not a stack).
  std::ifstream in(fs::path(path) / kManifest);
  if (!in) return false;
  const nlohmann::json manifest = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (!manifest.is_object()) return false;
  const auto format = manifest.find("format");
  return format != manifest.end() && *format == kFormatTag;
}

}  // namespace scalespace
