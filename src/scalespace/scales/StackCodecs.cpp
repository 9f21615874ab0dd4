#include "scalespace/scales/StackCodecs.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstring>
#include <iterator>
#include <mutex>

namespace scalespace::store {
namespace {

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

// The compact encodings, version 2 and 3 (StackCodecs.hpp, CompactFile: the files' order).
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

}  // namespace

QuantityTable quantities(StackEncoding e, int compactVersion) {
  if (e == StackEncoding::Float32)
    return {std::begin(kFloat32Quantities), std::end(kFloat32Quantities)};
  if (compactVersion == 2)
    return {std::begin(kCompactV2Quantities), std::end(kCompactV2Quantities)};
  return {std::begin(kCompactV3Quantities), std::end(kCompactV3Quantities)};
}

const unsigned char* layerBytes(const Quantity& q, const ScaleLayer& layer) {
  if (q.floats) return reinterpret_cast<const unsigned char*>((layer.*q.floats).data());
  if (std::strcmp(q.name, "neighbors") == 0)
    return reinterpret_cast<const unsigned char*>(layer.neighbors.data());
  return layer.valid.data();
}
unsigned char* layerBytes(const Quantity& q, ScaleLayer& layer) {
  return const_cast<unsigned char*>(layerBytes(q, static_cast<const ScaleLayer&>(layer)));
}

// Reordering the ~19 encoded bytes of a point costs less than putting its ~80 bytes of floats in
// input order first (compare both in a profile of bench/fig_1_10 --mode timing).
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

}  // namespace scalespace::store
