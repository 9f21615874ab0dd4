#include "scalespace/render/ColorMap.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>

namespace scalespace {

namespace {
// Viridis sampled at 9 evenly spaced positions (0, 1/8, ..., 1); linear interpolation between
// them stays within a couple of units of the full table.
constexpr std::array<std::array<double, 3>, 9> kViridis{{{68, 1, 84},
                                                         {71, 44, 122},
                                                         {59, 81, 139},
                                                         {44, 113, 142},
                                                         {33, 144, 141},
                                                         {39, 173, 129},
                                                         {92, 200, 99},
                                                         {170, 220, 50},
                                                         {253, 231, 37}}};

std::uint8_t toByte(double v) { return std::uint8_t(std::clamp(std::lround(v), 0L, 255L)); }
}  // namespace

Rgb viridis(double t) {
  if (!std::isfinite(t)) return kUnlabelledGrey;
  t = std::clamp(t, 0.0, 1.0) * double(kViridis.size() - 1);
  const std::size_t i = std::min(std::size_t(t), kViridis.size() - 2);
  const double f = t - double(i);
  const auto& a = kViridis[i];
  const auto& b = kViridis[i + 1];
  return {toByte(a[0] + f * (b[0] - a[0])), toByte(a[1] + f * (b[1] - a[1])),
          toByte(a[2] + f * (b[2] - a[2]))};
}

ScalarRange robustRange(const std::vector<double>& values, double lowQuantile,
                        double highQuantile) {
  std::vector<double> finite;
  finite.reserve(values.size());
  for (double v : values)
    if (std::isfinite(v)) finite.push_back(v);
  if (finite.empty()) return {};
  auto quantile = [&](double q) {
    const std::size_t k = std::size_t(std::clamp(q, 0.0, 1.0) * double(finite.size() - 1) + 0.5);
    std::nth_element(finite.begin(), finite.begin() + std::ptrdiff_t(k), finite.end());
    return finite[k];
  };
  return {quantile(lowQuantile), quantile(highQuantile)};
}

std::vector<Rgb> colorizeScalars(const std::vector<double>& values, const ScalarRange& range) {
  std::vector<Rgb> colors(values.size());
  const double span = range.hi - range.lo;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      colors[i] = kUnlabelledGrey;
      continue;
    }
    // A constant attribute maps to the middle of the map rather than dividing by zero.
    colors[i] = viridis(span > 0 ? (values[i] - range.lo) / span : 0.5);
  }
  return colors;
}

Rgb labelColor(long long label) {
  if (label < 0) return kUnlabelledGrey;
  // Golden-ratio hue spacing: the fractional parts of k * 0.618... are well spread for any k.
  const double goldenConjugate = 0.6180339887498949;
  double h = std::fmod(0.13 + double(label) * goldenConjugate, 1.0) * 6.0;
  const double s = 0.7, v = 0.95;
  const int sector = int(h) % 6;
  const double f = h - std::floor(h);
  const double p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  double r = 0, g = 0, b = 0;
  switch (sector) {
    case 0:
      r = v, g = t, b = p;
      break;
    case 1:
      r = q, g = v, b = p;
      break;
    case 2:
      r = p, g = v, b = t;
      break;
    case 3:
      r = p, g = q, b = v;
      break;
    case 4:
      r = t, g = p, b = v;
      break;
    default:
      r = v, g = p, b = q;
      break;
  }
  return {toByte(255 * r), toByte(255 * g), toByte(255 * b)};
}

std::vector<Rgb> colorizeLabels(const std::vector<double>& labels) {
  std::map<long long, std::size_t> counts;
  for (double v : labels)
    if (std::isfinite(v) && v >= 0) ++counts[std::llround(v)];
  std::vector<std::pair<long long, std::size_t>> byCount(counts.begin(), counts.end());
  std::sort(byCount.begin(), byCount.end(), [](const auto& a, const auto& b) {
    return a.second != b.second ? a.second > b.second : a.first < b.first;
  });
  std::map<long long, Rgb> colorOf;
  for (std::size_t k = 0; k < byCount.size(); ++k)
    colorOf[byCount[k].first] = labelColor((long long)k);
  std::vector<Rgb> colors(labels.size(), kUnlabelledGrey);
  for (std::size_t i = 0; i < labels.size(); ++i)
    if (std::isfinite(labels[i]) && labels[i] >= 0) colors[i] = colorOf[std::llround(labels[i])];
  return colors;
}

}  // namespace scalespace
