#pragma once
// An 8-bit RGB raster, row-major from the top-left pixel: what the renderer produces and the PNG
// writer stores.
#include <cstdint>
#include <vector>

namespace scalespace {

struct Rgb {
  std::uint8_t r = 0, g = 0, b = 0;
  bool operator==(const Rgb& o) const { return r == o.r && g == o.g && b == o.b; }
  bool operator!=(const Rgb& o) const { return !(*this == o); }
};

struct Image {
  int width = 0;
  int height = 0;
  std::vector<Rgb> pixels;  // width * height

  Image() = default;
  Image(int w, int h, Rgb fill = {}) : width(w), height(h), pixels(std::size_t(w) * h, fill) {}
  Rgb& at(int x, int y) { return pixels[std::size_t(y) * width + x]; }
  const Rgb& at(int x, int y) const { return pixels[std::size_t(y) * width + x]; }
};

}  // namespace scalespace
