#include "scalespace/scales/ScaleStackIO.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "scalespace/core/Error.hpp"
#include "scalespace/core/JsonInteger.hpp"
#include "scalespace/core/SpatialOrder.hpp"
#include "scalespace/scales/StackQuantization.hpp"

#ifndef SCALESPACE_VERSION
#define SCALESPACE_VERSION "unknown"
#endif

namespace fs = std::filesystem;

namespace scalespace {
namespace {

// One .npy file per quantity. dtype strings are NumPy's ('<f4' little-endian float32, ...).
struct Quantity {
  const char* name;
  const char* dtype;
  std::size_t itemSize;
  int components;  // 1: shape (M, N); 3: shape (M, N, 3); 0: bit-packed, shape (M, ceil(N / 8))
  const char* description;
  std::vector<float> ScaleLayer::*floats;  // float32 encoding; nullptr for integers and compact
  const char* scaling;                     // compact: how the stored value relates to t_j
  const char* codec;                       // compact version 3: how the number is stored
};

// The float32 encoding (format version 1): the ScaleLayer fields as they are.
const Quantity kFloat32Quantities[] = {
    {"projection", "<f4", 4, 3, "projected position relative to manifest origin",
     &ScaleLayer::projection, "none", nullptr},
    {"normal", "<f4", 4, 3, "unit normal", &ScaleLayer::normal, "none", nullptr},
    {"dir_max", "<f4", 4, 3, "principal direction of k_max", &ScaleLayer::dirMax, "none", nullptr},
    {"dir_min", "<f4", 4, 3, "principal direction of k_min", &ScaleLayer::dirMin, "none", nullptr},
    {"curv_mean", "<f4", 4, 1, "mean curvature H", &ScaleLayer::meanCurvature, "none", nullptr},
    {"curv_max", "<f4", 4, 1, "principal curvature k_max", &ScaleLayer::kMax, "none", nullptr},
    {"curv_min", "<f4", 4, 1, "principal curvature k_min", &ScaleLayer::kMin, "none", nullptr},
    {"gls_tau", "<f4", 4, 1, "GLS tau", &ScaleLayer::tau, "none", nullptr},
    {"gls_kappa", "<f4", 4, 1, "GLS kappa", &ScaleLayer::kappa, "none", nullptr},
    {"gls_fitness", "<f4", 4, 1, "GLS fitness (Pratt norm)", &ScaleLayer::fitness, "none", nullptr},
    {"anisotropy", "<f4", 4, 1, "1 - |u_l| (Eq. 1.20)", &ScaleLayer::anisotropy, "none", nullptr},
    {"geometric_variation", "<f4", 4, 1, "GLS geometric variation nu",
     &ScaleLayer::geometricVariation, "none", nullptr},
    {"neighbors", "<u2", 2, 1, "samples in the last fit (saturated at 65535)", nullptr, "none",
     nullptr},
    {"fit_valid", "|u1", 1, 1, "1 if the fit is valid", nullptr, "none", nullptr},
};

// The compact encodings (docs/STACK_FORMAT.md): format version 3 (written, 19.125 bytes per point
// and scale) and version 2 (read, and written only on request: 23.125 bytes). Both have the same
// files in the same order, the order of the buffers of encodeCompact / decodeCompact; version 3
// stores the offset with a shared exponent and the anisotropy and nu as 8-bit log codes.
enum CompactFile {
  kOffset,
  kFrame,
  kCurvMax,
  kCurvMin,
  kTau,
  kKappa,
  kAnisotropy,
  kVariation,
  kNeighbors,
  kValidBits,
  kCompactFiles
};
const Quantity kCompactV2Quantities[] = {
    {"projection_offset", "<f2", 2, 3, "(projection - input position) / t_j", nullptr, "over_t",
     nullptr},
    {"frame", "<u4", 4, 1,
     "bits 0-10, 11-21: octahedral normal (excess 1023); bits 22-31: dir_max angle q pi/1024",
     nullptr, "none", nullptr},
    {"curv_max_t", "<f2", 2, 1, "k_max * t_j", nullptr, "times_t", nullptr},
    {"curv_min_t", "<f2", 2, 1, "k_min * t_j", nullptr, "times_t", nullptr},
    {"gls_tau_t", "<f2", 2, 1, "GLS tau / t_j", nullptr, "over_t", nullptr},
    {"gls_kappa_t", "<f2", 2, 1, "GLS kappa * t_j", nullptr, "times_t", nullptr},
    {"anisotropy", "<f2", 2, 1, "1 - |u_l| (Eq. 1.20)", nullptr, "none", nullptr},
    {"geometric_variation", "<f2", 2, 1, "GLS geometric variation nu", nullptr, "none", nullptr},
    {"neighbors", "|u1", 1, 1, "samples in the last fit (saturated at 255)", nullptr, "none",
     nullptr},
    {"fit_valid_bits", "|u1", 1, 0, "1 if the fit is valid, bit-packed (bitorder little)", nullptr,
     "none", nullptr},
};
const Quantity kCompactV3Quantities[] = {
    {"projection_offset", "<u4", 4, 1,
     "(projection - input position) / t_j, shared exponent: bits 0-8, 9-17, 18-26: x, y, z (bit 8 "
     "sign, bits 0-7 magnitude m); bits 27-31: e; component = +-m 2^(e - bias)",
     nullptr, "over_t", "shared_exponent"},
    {"frame", "<u4", 4, 1,
     "bits 0-10, 11-21: octahedral normal (excess 1023); bits 22-31: dir_max angle q pi/1024",
     nullptr, "none", "octahedral_frame"},
    {"curv_max_t", "<f2", 2, 1, "k_max * t_j", nullptr, "times_t", "float16"},
    {"curv_min_t", "<f2", 2, 1, "k_min * t_j", nullptr, "times_t", "float16"},
    {"gls_tau_t", "<f2", 2, 1, "GLS tau / t_j", nullptr, "over_t", "float16"},
    {"gls_kappa_t", "<f2", 2, 1, "GLS kappa * t_j", nullptr, "times_t", "float16"},
    {"anisotropy", "|u1", 1, 1,
     "1 - |u_l| (Eq. 1.20); bit 7: sign, k = bits 0-6: 0 if k = 0, else "
     "log_min (log_max / log_min)^((k - 0.5) / 127)",
     nullptr, "none", "slog8"},
    {"geometric_variation", "|u1", 1, 1,
     "GLS geometric variation nu; code 0: 0, code k: log_min (log_max / log_min)^((k - 0.5) / 255)",
     nullptr, "none", "log8"},
    {"neighbors", "|u1", 1, 1, "samples in the last fit (saturated at 255)", nullptr, "none",
     "uint8"},
    {"fit_valid_bits", "|u1", 1, 0, "1 if the fit is valid, bit-packed (bitorder little)", nullptr,
     "none", "packbits_little"},
};
static_assert(sizeof kCompactV2Quantities / sizeof kCompactV2Quantities[0] == kCompactFiles);
static_assert(sizeof kCompactV3Quantities / sizeof kCompactV3Quantities[0] == kCompactFiles);

struct QuantityTable {
  const Quantity* begin_;
  const Quantity* end_;
  const Quantity* begin() const { return begin_; }
  const Quantity* end() const { return end_; }
};
// The files of an encoding; compact stacks by format version (2 or 3).
QuantityTable quantities(StackEncoding e, int compactVersion) {
  if (e == StackEncoding::Float32)
    return {std::begin(kFloat32Quantities), std::end(kFloat32Quantities)};
  if (compactVersion == 2)
    return {std::begin(kCompactV2Quantities), std::end(kCompactV2Quantities)};
  return {std::begin(kCompactV3Quantities), std::end(kCompactV3Quantities)};
}

// Bytes of one scale of a quantity, and of one point of it (bit-packed: the byte holding it).
std::size_t sliceBytes(const Quantity& q, std::size_t n) {
  return q.components == 0 ? quant::packedBytes(n) : n * std::size_t(q.components) * q.itemSize;
}
std::size_t pointBytes(const Quantity& q) {
  return q.components == 0 ? 1 : std::size_t(q.components) * q.itemSize;
}
std::uint64_t pointOffset(const Quantity& q, std::size_t n, std::size_t j, std::size_t i) {
  if (q.components == 0) return std::uint64_t(j) * quant::packedBytes(n) + i / 8;
  return (std::uint64_t(j) * n + i) * pointBytes(q);
}

constexpr const char* kManifest = "manifest.json";

const unsigned char* layerBytes(const Quantity& q, const ScaleLayer& layer) {
  if (q.floats) return reinterpret_cast<const unsigned char*>((layer.*q.floats).data());
  if (std::strcmp(q.name, "neighbors") == 0)
    return reinterpret_cast<const unsigned char*>(layer.neighbors.data());
  return layer.valid.data();
}
unsigned char* layerBytes(const Quantity& q, ScaleLayer& layer) {
  return const_cast<unsigned char*>(layerBytes(q, static_cast<const ScaleLayer&>(layer)));
}

// float -> float16 with a count of the clamped (or non-finite) values per file.
struct HalfWriter {
  std::size_t* clamped;
  void operator()(double v, unsigned char* out) const {
    bool c = false;
    const std::uint16_t h = quant::floatToHalf(float(v), c);
    if (c) ++*clamped;
    std::memcpy(out, &h, 2);
  }
};

float readHalf(const unsigned char* p) {
  std::uint16_t h;
  std::memcpy(&h, p, 2);
  return quant::halfToFloat(h);
}

// The codecs of a compact stack: its format version and, for version 3, the offset exponent bias
// and the ranges of the log codes (the writer's constants; the reader's come from the manifest).
struct CompactCodecs {
  int version = kStackFormatVersion;
  int offsetBias = quant::kOffsetBias;
  quant::Log8Code anisotropy{quant::kAnisotropyLogMin, quant::kAnisotropyLogMax, true};
  quant::Log8Code variation{quant::kVariationLogMin, quant::kVariationLogMax};
};

// Encodes one scale (t: its scale value; rel: the input positions relative to the origin, 3 N, in
// the layer's order) into buf in input order. A layer in processing order (L.inputIndex) is read
// in its own order and each point's codes are stored at its input index: reordering the ~19
// encoded bytes of a point costs less than putting its ~80 bytes of floats in input order first
// (compare both in a profile of bench/fig_1_10 --mode timing).
void encodeCompact(const ScaleLayer& L, double t, const std::vector<double>& rel,
                   const CompactCodecs& codecs, std::vector<std::vector<unsigned char>>& buf,
                   std::vector<std::size_t>& clamped, std::vector<std::uint8_t>& validScratch) {
  const std::size_t n = L.size();
  const Index* inputIndex = L.inputIndex.empty() ? nullptr : L.inputIndex.data();
  const bool version3 = codecs.version >= 3;
  const Quantity* table = quantities(StackEncoding::Compact, codecs.version).begin();
  for (int k = 0; k < kCompactFiles; ++k) buf[k].assign(sliceBytes(table[k], n), 0);
  if (inputIndex) validScratch.assign(n, 0);
  // Points are independent: encoded in parallel blocks (a tenth of a 1M x 50 stack's time when
  // sequential), each block counting its clamped values; the sums do not depend on the blocks.
  std::mutex countLock;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 8192), [&](const auto& range) {
    std::vector<std::size_t> local(clamped.size(), 0);
    auto half = [&](int k) { return HalfWriter{&local[std::size_t(k)]}; };
    auto log8 = [&](int k, const quant::Log8Code& code, float v, std::size_t i) {
      bool c = false;
      buf[std::size_t(k)][i] = code.encode(double(v), c);
      if (c) ++local[std::size_t(k)];
    };
    for (std::size_t e = range.begin(); e != range.end(); ++e) {
      const std::size_t i = inputIndex ? inputIndex[e] : e;  // where entry e's codes go
      // The projection is meaningful for invalid fits too (the last valid one): always stored.
      Vec3 offset;
      for (int c = 0; c < 3; ++c)
        offset[c] = (double(L.projection[3 * e + c]) - rel[3 * e + c]) / t;
      if (version3) {
        bool c = false;
        const std::uint32_t code = quant::encodeSharedExponent(offset, c);
        if (c) ++local[kOffset];
        std::memcpy(&buf[kOffset][4 * i], &code, 4);
      } else {
        for (int c = 0; c < 3; ++c) half(kOffset)(offset[c], &buf[kOffset][6 * i + 2 * c]);
      }
      buf[kNeighbors][i] = std::uint8_t(std::min<unsigned>(L.neighbors[e], 255u));
      if (inputIndex) validScratch[i] = L.valid[e];
      if (!L.valid[e]) continue;  // zeros: decoded as zeros
      const auto v3 = [&](const std::vector<float>& a) {
        return Vec3(a[3 * e], a[3 * e + 1], a[3 * e + 2]);
      };
      const std::uint32_t frame = quant::encodeFrame(v3(L.normal), v3(L.dirMax));
      std::memcpy(&buf[kFrame][4 * i], &frame, 4);
      half(kCurvMax)(double(L.kMax[e]) * t, &buf[kCurvMax][2 * i]);
      half(kCurvMin)(double(L.kMin[e]) * t, &buf[kCurvMin][2 * i]);
      half(kTau)(double(L.tau[e]) / t, &buf[kTau][2 * i]);
      half(kKappa)(double(L.kappa[e]) * t, &buf[kKappa][2 * i]);
      if (version3) {
        log8(kAnisotropy, codecs.anisotropy, L.anisotropy[e], i);
        log8(kVariation, codecs.variation, L.geometricVariation[e], i);
      } else {
        half(kAnisotropy)(double(L.anisotropy[e]), &buf[kAnisotropy][2 * i]);
        half(kVariation)(double(L.geometricVariation[e]), &buf[kVariation][2 * i]);
      }
    }
    const std::lock_guard<std::mutex> hold(countLock);
    for (std::size_t k = 0; k < clamped.size(); ++k) clamped[k] += local[k];
  });
  quant::packBits(inputIndex ? validScratch.data() : L.valid.data(), n, buf[kValidBits].data());
}

// Decodes `count` consecutive points of one scale: data[k] points at the first point's bytes of
// file k (for the bit-packed flags: the byte holding it, whose bit is firstBit); rel are the
// points' input positions relative to the origin. Point p goes to entry out0 + p of `out`.
void decodeCompact(const CompactCodecs& codecs, const std::vector<const unsigned char*>& data,
                   std::size_t firstBit, std::size_t count, double t, const double* rel,
                   ScaleLayer& out, std::size_t out0) {
  const bool version3 = codecs.version >= 3;
  for (std::size_t p = 0; p < count; ++p) {
    const std::size_t o = out0 + p;
    Vec3 offset;
    if (version3) {
      std::uint32_t code;
      std::memcpy(&code, data[kOffset] + 4 * p, 4);
      offset = quant::decodeSharedExponent(code, codecs.offsetBias);
    } else {
      for (int c = 0; c < 3; ++c) offset[c] = double(readHalf(data[kOffset] + 6 * p + 2 * c));
    }
    // In double, then rounded once: what read_stack.py computes in float64.
    for (int c = 0; c < 3; ++c) out.projection[3 * o + c] = float(rel[3 * p + c] + offset[c] * t);
    out.neighbors[o] = data[kNeighbors][p];
    const std::uint8_t valid = quant::unpackBit(data[kValidBits], firstBit + p);
    out.valid[o] = valid;
    if (!valid) continue;  // out was zero-initialised
    std::uint32_t frame;
    std::memcpy(&frame, data[kFrame] + 4 * p, 4);
    Vec3 nrm, dmax, dmin;
    quant::decodeFrame(frame, nrm, dmax, dmin);
    for (int c = 0; c < 3; ++c) {
      out.normal[3 * o + c] = float(nrm[c]);
      out.dirMax[3 * o + c] = float(dmax[c]);
      out.dirMin[3 * o + c] = float(dmin[c]);
    }
    const double kMax = double(readHalf(data[kCurvMax] + 2 * p)) / t;
    const double kMin = double(readHalf(data[kCurvMin] + 2 * p)) / t;
    out.kMax[o] = float(kMax);
    out.kMin[o] = float(kMin);
    out.meanCurvature[o] = float(0.5 * (kMax + kMin));
    out.tau[o] = float(double(readHalf(data[kTau] + 2 * p)) * t);
    out.kappa[o] = float(double(readHalf(data[kKappa] + 2 * p)) / t);
    out.fitness[o] = 0;  // not stored in the compact encoding
    if (version3) {
      out.anisotropy[o] = float(codecs.anisotropy.decode(data[kAnisotropy][p]));
      out.geometricVariation[o] = float(codecs.variation.decode(data[kVariation][p]));
    } else {
      out.anisotropy[o] = readHalf(data[kAnisotropy] + 2 * p);
      out.geometricVariation[o] = readHalf(data[kVariation] + 2 * p);
    }
  }
}

// 64-bit FNV-1a-style hash over 8-byte little-endian words of the whole data stream (a final
// partial word is zero-padded): one multiply per 8 bytes, fast enough to run while writing
// gigabytes. Streaming: add() may be called with any split of the data.
struct Checksum {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  unsigned char carry[8] = {};
  std::size_t carried = 0;
  void word(const unsigned char* p) {
    std::uint64_t w;
    std::memcpy(&w, p, 8);
    h = (h ^ w) * 0x100000001b3ULL;
  }
  void add(const unsigned char* p, std::size_t n) {
    while (carried > 0 && carried < 8 && n > 0) {
      carry[carried++] = *p++;
      --n;
    }
    if (carried == 8) {
      word(carry);
      carried = 0;
    }
    for (; n >= 8; n -= 8, p += 8) word(p);
    for (; n > 0; --n) carry[carried++] = *p++;
  }
  std::uint64_t value() const {
    if (carried == 0) return h;
    unsigned char last[8] = {};
    std::memcpy(last, carry, carried);
    std::uint64_t w;
    std::memcpy(&w, last, 8);
    return (h ^ w) * 0x100000001b3ULL;
  }
};

std::string hex64(std::uint64_t v) {
  char b[17];
  std::snprintf(b, sizeof b, "%016llx", static_cast<unsigned long long>(v));
  return b;
}

std::string shapeText(const std::vector<std::size_t>& shape) {
  std::string s = "(";
  for (std::size_t k = 0; k < shape.size(); ++k)
    s += std::to_string(shape[k]) + (shape.size() == 1 ? "," : k + 1 < shape.size() ? ", " : "");
  return s + ")";
}

// NumPy format 1.0: magic, version, uint16 header length, dict padded with spaces and '\n' so
// that the data starts at a multiple of 64 bytes.
std::string npyHeader(const std::string& dtype, const std::vector<std::size_t>& shape) {
  std::string dict =
      "{'descr': '" + dtype + "', 'fortran_order': False, 'shape': " + shapeText(shape) + ", }";
  std::size_t total = 10 + dict.size() + 1;
  const std::size_t padded = (total + 63) / 64 * 64;
  dict.append(padded - total, ' ');
  dict.push_back('\n');
  std::string h = "\x93NUMPY";
  h.push_back(char(1));
  h.push_back(char(0));
  h.push_back(char(dict.size() & 0xff));
  h.push_back(char(dict.size() >> 8));
  return h + dict;
}

std::vector<std::size_t> quantityShape(const Quantity& q, std::size_t m, std::size_t n) {
  if (q.components == 0) return {m, quant::packedBytes(n)};
  if (q.components == 1) return {m, n};
  return {m, n, std::size_t(q.components)};
}

void writeAll(int fd, const void* data, std::size_t size, const std::string& file) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t w = ::write(fd, p, size);
    if (w < 0) {
      if (errno == EINTR) continue;
      throw FileError(file, "", std::string("cannot write: ") + std::strerror(errno),
                      "check free disk space and permissions");
    }
    p += w;
    size -= std::size_t(w);
  }
}

void syncPath(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
}

void preadAll(int fd, void* data, std::size_t size, std::uint64_t offset, const std::string& file) {
  char* p = static_cast<char*>(data);
  while (size > 0) {
    const ssize_t r = ::pread(fd, p, size, off_t(offset));
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0)
      throw FileError(file, "byte " + std::to_string(offset),
                      "unexpected end of file or read error",
                      "the stack is damaged: recompute it with 'scalespace scales'");
    p += r;
    size -= std::size_t(r);
    offset += std::uint64_t(r);
  }
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
          {"robust", o.robust},
          {"robust_iterations", o.robustIterations},
          {"mls_steps", o.mlsSteps},
          {"mls_tolerance", o.mlsTolerance},
          {"min_neighbors", o.minNeighbors},
          {"estimator", estimatorName(o.estimator)},
          {"seed", o.seed}};
}

}  // namespace

const char* stackEncodingName(StackEncoding encoding) {
  return encoding == StackEncoding::Compact ? "compact" : "float32";
}

StackEncoding parseStackEncoding(const std::string& name) {
  if (name == "compact") return StackEncoding::Compact;
  if (name == "float32") return StackEncoding::Float32;
  throw OptionError("StackWriteOptions::encoding must be compact or float32, not '" + name + "'");
}

// ---------------------------------------------------------------------------------------- writer

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
  // finish() replaces what is at `path`: only ever a stack this program wrote.
  if (fs::exists(d.finalPath, ec) && !isScaleStack(d.finalPath.string()))
    throw FileError(d.finalPath.string(), "",
                    "exists and is not a scale stack (no scalespace manifest.json): refusing to "
                    "replace it",
                    "choose another output path for the stack, e.g. NAME.stack");
  fs::remove_all(d.tmpPath, ec);
  if (!fs::create_directories(d.tmpPath, ec) || ec)
    throw FileError(d.tmpPath.string(), "",
                    "cannot create the temporary stack directory: " + ec.message(),
                    "check that the parent directory exists and is writable");
  try {
    for (const Quantity& q : quantities(d.encoding, d.codecs.version)) {
      const std::string file = (d.tmpPath / (std::string(q.name) + ".npy")).string();
      const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      if (fd < 0)
        throw FileError(file, "", std::string("cannot create: ") + std::strerror(errno),
                        "check permissions and free space");
      d.fds.push_back(fd);
      d.sums.emplace_back();
      const std::string h = npyHeader(q.dtype, quantityShape(q, d.m, d.n));
      writeAll(fd, h.data(), h.size(), file);
    }
    // Input positions (absolute, float64): exports put them beside the per-scale values.
    const std::string file = (d.tmpPath / "input_positions.npy").string();
    const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0) throw FileError(file, "", std::string("cannot create: ") + std::strerror(errno));
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
  manifest["format"] = "scalespace-stack";
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
    const int fd = ::open(manifestPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd < 0)
      throw FileError(manifestPath, "", std::string("cannot create: ") + std::strerror(errno));
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

ScaleSpaceSummary computeScaleStack(const PointCloud& cloud, const ScaleSpaceOptions& options,
                                    const std::string& path, const ProgressCallback& progress,
                                    const StackWriteOptions& write) {
  std::unique_ptr<ScaleStackWriter> writer;
  ScaleSpaceOptions all = options;
  all.layerContents = LayerContents::All;  // the stack stores every quantity
  // The writer puts the encoded bytes in input order (encodeCompact).
  all.layerOrder =
      write.encoding == StackEncoding::Compact ? LayerOrder::Processing : LayerOrder::Input;
  ScaleSpaceSummary summary = runScaleSpace(
      cloud, all,
      [&](std::size_t j, const ScaleLayer& layer, const ScaleStats& stats) {
        // The series is known only once runScaleSpace resolved t_min; M is the option count.
        if (!writer)
          writer = std::make_unique<ScaleStackWriter>(path, cloud, options,
                                                      std::size_t(options.series.count), write);
        writer->writeScale(j, layer, stats.t);
      },
      progress);
  if (!writer) throw Error("computeScaleStack: no scale was computed");
  writer->finish(summary);
  return summary;
}

void writeScaleStack(const std::string& path, const PointCloud& cloud,
                     const ScaleSpaceOptions& options, const ScaleStack& stack,
                     const StackWriteOptions& write) {
  ScaleStackWriter writer(path, cloud, options, stack.layers.size(), write);
  for (std::size_t j = 0; j < stack.layers.size(); ++j)
    writer.writeScale(j, stack.layers[j], stack.summary.series.scales.at(j));
  writer.finish(stack.summary);
}

// ---------------------------------------------------------------------------------------- reader

namespace {

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
      preadAll(positionsFd, rel.data(), rel.size() * 8, positionsOffset, positionsFile);
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
    unsigned char pre[10];
    struct stat st {};
    ::fstat(fd, &st);
    if (st.st_size < 10) throw FileError(file, "byte 0", "not a NumPy .npy file (too short)", fix);
    preadAll(fd, pre, 10, 0, file);
    if (std::memcmp(pre, "\x93NUMPY", 6) != 0 || pre[6] != 1)
      throw FileError(file, "byte 0", "not a NumPy format 1.0 .npy file", fix);
    const std::size_t headerLen = std::size_t(pre[8]) | (std::size_t(pre[9]) << 8);
    if (std::uint64_t(st.st_size) < 10 + headerLen)
      throw FileError(file, "byte 10", "truncated .npy header", fix);
    std::string header(headerLen, '\0');
    preadAll(fd, header.data(), headerLen, 10, file);
    std::vector<std::size_t> wantShape = shape;
    const std::string want = npyHeader(dtype, wantShape).substr(10);
    if (header != want)
      throw FileError(file, "byte 10",
                      "header '" + header.substr(0, header.find('}') + 1) +
                          "' differs from the manifest (expected dtype " + dtype + ", shape " +
                          shapeText(shape) + ")",
                      fix);
    std::uint64_t count = itemSize;
    for (std::size_t s : shape) count *= s;
    const std::uint64_t expected = 10 + headerLen + count;
    if (std::uint64_t(st.st_size) != expected)
      throw FileError(file, "",
                      "size is " + std::to_string(st.st_size) + " bytes, expected " +
                          std::to_string(expected) + " from the manifest's shape",
                      fix);
    return 10 + headerLen;
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
    if (manifest.at("format").get<std::string>() != "scalespace-stack")
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
    preadAll(d.fds[k], out, bytes, d.dataOffset[k] + std::uint64_t(j) * bytes, d.files[k]);
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
    preadAll(d.positionsFd, rel, 24, d.positionsOffset + std::uint64_t(i) * 24, d.positionsFile);
    for (int c = 0; c < 3; ++c) rel[c] -= info().origin[c];
    unsigned char item[kCompactFiles][8];
    std::vector<const unsigned char*> ptrs(kCompactFiles);
    for (std::size_t j = 0; j < m; ++j) {
      std::size_t k = 0;
      for (const Quantity& q : d.table) {
        preadAll(d.fds[k], item[k], pointBytes(q), d.dataOffset[k] + pointOffset(q, n, j, i),
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
      preadAll(d.fds[k], out + j * item, item, d.dataOffset[k] + pointOffset(q, n, j, i),
               d.files[k]);
    ++k;
  }
  return series;
}

std::vector<Vec3> ScaleStackReader::inputPositions() const {
  const Impl& d = *impl_;
  std::vector<double> xyz(3 * pointCount());
  preadAll(d.positionsFd, xyz.data(), xyz.size() * 8, d.positionsOffset, d.positionsFile);
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
      preadAll(fd, buf.data(), chunk, offset + done, file);
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
  return format != manifest.end() && *format == "scalespace-stack";
}

}  // namespace scalespace
