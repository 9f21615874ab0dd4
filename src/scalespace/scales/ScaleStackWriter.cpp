#include "scalespace/scales/ScaleStackWriter.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/FileSync.hpp"
#include "scalespace/core/SpatialOrder.hpp"
#include "scalespace/scales/NpyFormat.hpp"
#include "scalespace/scales/ScaleStackReader.hpp"
#include "scalespace/scales/StackChecksum.hpp"
#include "scalespace/scales/StackCodecs.hpp"
#include "scalespace/scales/StackLayout.hpp"

#ifndef SCALESPACE_VERSION
#define SCALESPACE_VERSION "unknown"
#endif

namespace fs = std::filesystem;

namespace scalespace {

// The store's internal pieces (StackLayout.hpp, StackCodecs.hpp, StackChecksum.hpp, NpyFormat.hpp).
using namespace store;

namespace {

// Creates (or truncates) a file of the temporary stack directory; FileError naming it otherwise.
int createFile(const std::string& file, const std::string& fix = {}) {
  const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) throw FileError(file, "", std::string("cannot create: ") + std::strerror(errno), fix);
  return fd;
}

nlohmann::json statsJson(const ScaleStats& s) {
  return {{"t", s.t},
          {"samples", s.samples},
          {"mean_neighbors", s.meanNeighbors},
          {"mean_mls_steps", s.meanMlsSteps},
          {"valid_points", s.validPoints},
          {"sampling_seconds", s.samplingSeconds},
          {"index_seconds", s.indexSeconds},
          {"projection_seconds", s.projectionSeconds}};
}

nlohmann::json optionsJson(const ScaleSpaceOptions& o) {
  return {{"scales", o.series.count},
          {"spacing", scaleSpacingName(o.series.spacing)},
          {"tmin_option", o.series.tMin},
          {"tmax_option", o.series.tMax},
          {"K", o.series.K},
          {"alpha", o.alpha},
          {"robust", o.fit.robust},
          {"robust_iterations", o.fit.robustIterations},
          {"mls_steps", o.fit.mlsMaxSteps},
          {"mls_tolerance", o.fit.mlsTolerance},
          {"min_neighbors", o.fit.minNeighbors},
          {"estimator", estimatorName(o.fit.estimator)},
          {"seed", o.seed}};
}

}  // namespace

struct ScaleStackWriter::Impl {
  fs::path finalPath, tmpPath;
  std::size_t n = 0, m = 0, written = 0;
  StackEncoding encoding = StackEncoding::Compact;
  std::vector<int> fds;
  std::vector<Checksum> sums;
  std::uint64_t positionsSum = 0;
  Vec3 origin;
  std::vector<double> scales;                    // t_j given to writeScale
  std::vector<double> inputRel;                  // compact: input positions - origin, 3 N
  std::vector<Index> layerIndex;                 // the inputIndex of the last layer (checked)...
  std::vector<double> layerRel;                  // ... and, compact, inputRel in its order
  std::vector<std::uint8_t> validScratch;        // compact: the validity flags in input order
  std::vector<std::vector<unsigned char>> bufs;  // compact: one scale, encoded
  std::vector<std::size_t> clamped;              // compact: clamped values per file
  CompactCodecs codecs;                          // compact: format version and codecs
  nlohmann::json parameters;
  bool finished = false;

  void closeAll() {
    for (int& fd : fds)
      if (fd >= 0) {
        ::close(fd);
        fd = -1;
      }
  }
};

void checkStackDestination(const std::string& path) {
  std::error_code ec;
  if (fs::exists(path, ec) && !isScaleStack(path))
    throw FileError(path, "",
                    "exists and is not a scale stack (no scalespace manifest.json): refusing to "
                    "replace it",
                    "choose another output path for the stack, e.g. NAME.stack");
}

ScaleStackWriter::ScaleStackWriter(const std::string& path, const PointCloud& cloud,
                                   const ScaleSpaceOptions& options, std::size_t scaleCount,
                                   const StackWriteOptions& write)
    : impl_(std::make_unique<Impl>()) {
  Impl& d = *impl_;
  std::string clean = path;
  while (clean.size() > 1 && clean.back() == '/') clean.pop_back();
  d.finalPath = clean;
  d.tmpPath = clean + ".tmp-" + std::to_string(::getpid());
  d.n = cloud.size();
  d.m = scaleCount;
  d.origin = cloud.origin();
  d.parameters = optionsJson(options);
  d.encoding = write.encoding;
  if (write.compactVersion != 2 && write.compactVersion != 3)
    throw OptionError("StackWriteOptions::compactVersion must be 2 or 3, not " +
                      std::to_string(write.compactVersion));
  d.codecs.version = write.compactVersion;
  d.clamped.assign(kCompactFiles, 0);
  d.bufs.resize(kCompactFiles);
  std::error_code ec;
  checkStackDestination(d.finalPath.string());  // finish() replaces what is there
  fs::remove_all(d.tmpPath, ec);
  if (!fs::create_directories(d.tmpPath, ec) || ec)
    throw FileError(d.tmpPath.string(), "",
                    "cannot create the temporary stack directory: " + ec.message(),
                    "check that the parent directory exists and is writable");
  try {
    for (const Quantity& q : quantities(d.encoding, d.codecs.version)) {
      const std::string file = (d.tmpPath / (std::string(q.name) + ".npy")).string();
      d.fds.push_back(createFile(file, "check permissions and free space"));
      const int fd = d.fds.back();
      d.sums.emplace_back();
      const std::string h = npyHeader(q.dtype, quantityShape(q, d.m, d.n));
      writeAll(fd, h.data(), h.size(), file);
    }
    // Input positions (absolute, float64): exports put them beside the per-scale values.
    const std::string file = (d.tmpPath / "input_positions.npy").string();
    const int fd = createFile(file);
    const std::string h = npyHeader("<f8", {d.n, 3});
    writeAll(fd, h.data(), h.size(), file);
    std::vector<double> xyz(3 * d.n);
    for (std::size_t i = 0; i < d.n; ++i) {
      const Vec3 p = cloud.absolutePosition(i);
      xyz[3 * i] = p.x(), xyz[3 * i + 1] = p.y(), xyz[3 * i + 2] = p.z();
    }
    writeAll(fd, xyz.data(), xyz.size() * 8, file);
    if (d.encoding == StackEncoding::Compact) {
      // Exactly what the reader computes: input - origin, from the stored doubles.
      d.inputRel.resize(3 * d.n);
      for (std::size_t k = 0; k < 3 * d.n; ++k) d.inputRel[k] = xyz[k] - d.origin[int(k % 3)];
    }
    Checksum c;
    c.add(reinterpret_cast<const unsigned char*>(xyz.data()), xyz.size() * 8);
    d.positionsSum = c.value();
    ::fsync(fd);
    ::close(fd);
  } catch (...) {
    d.closeAll();
    fs::remove_all(d.tmpPath, ec);
    throw;
  }
}

ScaleStackWriter::~ScaleStackWriter() {
  if (!impl_) return;
  impl_->closeAll();
  if (!impl_->finished) {
    std::error_code ec;
    fs::remove_all(impl_->tmpPath, ec);
  }
}

void ScaleStackWriter::writeScale(std::size_t j, const ScaleLayer& layer, double t) {
  Impl& d = *impl_;
  if (j != d.written || j >= d.m)
    throw Error("ScaleStackWriter: scale " + std::to_string(j) +
                " written out of order (expected " + std::to_string(d.written) + " of " +
                std::to_string(d.m) + ")");
  if (layer.size() != d.n)
    throw Error("ScaleStackWriter: layer has " + std::to_string(layer.size()) +
                " points, expected " + std::to_string(d.n));
  if (!layer.complete())
    throw Error("ScaleStackWriter: the layer lacks arrays (computed with LayerContents::All?)");
  if (!(t > 0) || !std::isfinite(t))
    throw Error("ScaleStackWriter: scale " + std::to_string(j) + " has t = " + std::to_string(t));
  const bool compact = d.encoding == StackEncoding::Compact;
  // A layer in processing order: the same order at every scale of a stack, so it is checked (the
  // encoder writes at these indices) and the positions are put in its order once.
  if (!layer.inputIndex.empty() && layer.inputIndex != d.layerIndex) {
    try {
      invertPermutation(layer.inputIndex);
    } catch (const OptionError& e) {
      throw Error(std::string("ScaleStackWriter: the layer's input indices: ") + e.what());
    }
    d.layerIndex = layer.inputIndex;
    if (compact) {
      d.layerRel.resize(3 * d.n);
      for (std::size_t e = 0; e < d.n; ++e)
        for (std::size_t c = 0; c < 3; ++c)
          d.layerRel[3 * e + c] = d.inputRel[3 * std::size_t(d.layerIndex[e]) + c];
    }
  }
  if (compact)
    encodeCompact(layer, t, layer.inputIndex.empty() ? d.inputRel : d.layerRel, d.codecs, d.bufs,
                  d.clamped, d.validScratch);
  // Float32 stores the arrays as they are: in input order.
  std::optional<ScaleLayer> reordered;
  if (!compact && !layer.inputIndex.empty()) reordered = inInputOrder(layer);
  const ScaleLayer& raw = reordered ? *reordered : layer;
  std::size_t k = 0;
  for (const Quantity& q : quantities(d.encoding, d.codecs.version)) {
    const std::size_t bytes = sliceBytes(q, d.n);
    const unsigned char* p = compact ? d.bufs[k].data() : layerBytes(q, raw);
    writeAll(d.fds[k], p, bytes, (d.tmpPath / q.name).string() + ".npy");
    d.sums[k].add(p, bytes);
    // Start writing this scale to disk now (asynchronous): the fsync of finish() then waits for
    // the last scale only, instead of flushing the whole stack at the end.
    ::sync_file_range(d.fds[k], 0, 0, SYNC_FILE_RANGE_WRITE);
    ++k;
  }
  d.scales.push_back(t);
  ++d.written;
}

std::size_t ScaleStackWriter::clampedValues() const {
  std::size_t total = 0;
  for (std::size_t c : impl_->clamped) total += c;
  return total;
}

void ScaleStackWriter::finish(const ScaleSpaceSummary& summary) {
  Impl& d = *impl_;
  if (d.written != d.m)
    throw Error("ScaleStackWriter: " + std::to_string(d.written) + " of " + std::to_string(d.m) +
                " scales written before finish()");
  if (summary.series.scales.size() != d.m)
    throw Error("ScaleStackWriter: the summary has " +
                std::to_string(summary.series.scales.size()) + " scales, expected " +
                std::to_string(d.m));
  for (std::size_t j = 0; j < d.m; ++j)
    if (std::abs(summary.series.scales[j] - d.scales[j]) > 1e-12 * d.scales[j])
      throw Error("ScaleStackWriter: scale " + std::to_string(j) +
                  " was written with t = " + std::to_string(d.scales[j]) +
                  " but the summary says " + std::to_string(summary.series.scales[j]));
  for (int fd : d.fds) ::fsync(fd);
  d.closeAll();
  nlohmann::json manifest;
  manifest["format"] = kFormatTag;
  const bool compact = d.encoding == StackEncoding::Compact;
  // Float32 stacks stay version 1 (readable by older programs); compact stacks are version 3
  // (version 2 on request).
  manifest["format_version"] = compact ? d.codecs.version : 1;
  manifest["encoding"] = stackEncodingName(d.encoding);
  manifest["program"] = "scalespace";
  manifest["program_version"] = SCALESPACE_VERSION;
  manifest["point_count"] = d.n;
  manifest["scale_count"] = d.m;
  manifest["scales"] = summary.series.scales;
  manifest["t_min"] = summary.series.tMin;
  manifest["t_max"] = summary.series.tMax;
  manifest["origin"] = {d.origin.x(), d.origin.y(), d.origin.z()};
  manifest["input_checksum"] = hex64(summary.inputChecksum);
  manifest["checksum_algorithm"] = "fnv1a64-words";
  manifest["quantisation"] = compact ? "compact" : "none";
  manifest["parameters"] = d.parameters;
  nlohmann::json stats = nlohmann::json::array();
  for (const ScaleStats& s : summary.stats) stats.push_back(statsJson(s));
  manifest["stats"] = stats;
  manifest["total_seconds"] = summary.totalSeconds;
  nlohmann::json entries = nlohmann::json::object();
  std::size_t k = 0;
  std::size_t clampedTotal = 0;
  for (const Quantity& q : quantities(d.encoding, d.codecs.version)) {
    entries[q.name] = {
        {"file", std::string(q.name) + ".npy"}, {"dtype", q.dtype},
        {"shape", quantityShape(q, d.m, d.n)},  {"scale_factor", 1.0},
        {"description", q.description},         {"checksum", hex64(d.sums[k].value())}};
    if (compact) {
      entries[q.name]["scaling"] = q.scaling;
      entries[q.name]["clamped"] = d.clamped[k];
      clampedTotal += d.clamped[k];
    }
    // Version 3: how each file is stored, with the parameters a decoder needs (numpy included).
    if (q.codec) entries[q.name]["codec"] = q.codec;
    if (q.codec && std::strcmp(q.codec, "shared_exponent") == 0)
      entries[q.name]["bias"] = d.codecs.offsetBias;
    if (q.codec && (std::strcmp(q.codec, "log8") == 0 || std::strcmp(q.codec, "slog8") == 0)) {
      const quant::Log8Code& code = k == kAnisotropy ? d.codecs.anisotropy : d.codecs.variation;
      entries[q.name]["log_min"] = code.lo();
      entries[q.name]["log_max"] = code.hi();
    }
    ++k;
  }
  manifest["quantities"] = entries;
  if (compact) manifest["clamped_values"] = clampedTotal;
  manifest["input_positions"] = {{"file", "input_positions.npy"},
                                 {"dtype", "<f8"},
                                 {"shape", {d.n, 3}},
                                 {"checksum", hex64(d.positionsSum)}};
  // The manifest is written last: a directory without it is never a valid stack.
  const std::string manifestPath = (d.tmpPath / kManifest).string();
  {
    const std::string text = manifest.dump(1) + "\n";
    const int fd = createFile(manifestPath);
    writeAll(fd, text.data(), text.size(), manifestPath);
    ::fsync(fd);
    ::close(fd);
  }
  syncPath(d.tmpPath.string());
  // Replace an older stack only now that the new one is complete.
  std::error_code ec;
  fs::path old;
  if (fs::exists(d.finalPath, ec)) {
    old = d.finalPath.string() + ".old-" + std::to_string(::getpid());
    fs::remove_all(old, ec);
    fs::rename(d.finalPath, old, ec);
    if (ec)
      throw FileError(d.finalPath.string(), "",
                      "cannot replace the existing stack: " + ec.message(),
                      "remove it or choose another -o");
  }
  fs::rename(d.tmpPath, d.finalPath, ec);
  if (ec)
    throw FileError(d.finalPath.string(), "",
                    "cannot move the finished stack into place: " + ec.message(),
                    "check permissions of the parent directory");
  d.finished = true;
  if (!old.empty()) fs::remove_all(old, ec);
  const fs::path parent = d.finalPath.parent_path();
  syncPath(parent.empty() ? "." : parent.string());
}

void writeScaleStack(const std::string& path, const PointCloud& cloud,
                     const ScaleSpaceOptions& options, const ScaleStack& stack,
                     const StackWriteOptions& write) {
  ScaleStackWriter writer(path, cloud, options, stack.layers.size(), write);
  for (std::size_t j = 0; j < stack.layers.size(); ++j)
    writer.writeScale(j, stack.layers[j], stack.summary.series.scales.at(j));
  writer.finish(stack.summary);
}

}  // namespace scalespace
