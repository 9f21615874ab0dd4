#include "scalespace/render/PngWriter.hpp"

#include <png.h>

#include <csetjmp>
#include <cstdio>
#include <ostream>
#include <vector>

#include "scalespace/core/Error.hpp"
#include "scalespace/io/AtomicFile.hpp"

namespace scalespace {

namespace {

void writeToStream(png_structp png, png_bytep data, png_size_t length) {
  auto* out = static_cast<std::ostream*>(png_get_io_ptr(png));
  out->write(reinterpret_cast<const char*>(data), std::streamsize(length));
}
void flushStream(png_structp png) { static_cast<std::ostream*>(png_get_io_ptr(png))->flush(); }

// libpng reports errors by longjmp to the setjmp below; this function owns no C++ object with a
// destructor after setjmp, so the jump skips nothing. Returns false on a libpng error.
bool encode(const Image& image, png_bytep* rows, std::ostream& out) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, info ? &info : nullptr);
    return false;
  }
  png_set_write_fn(png, &out, writeToStream, flushStream);
  png_set_IHDR(png, info, png_uint_32(image.width), png_uint_32(image.height), 8,
               PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  png_write_image(png, rows);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

bool decode(std::FILE* file, png_uint_32& width, png_uint_32& height, std::vector<png_byte>& data,
            std::vector<png_bytep>& rows) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  if (!png) return false;
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, info ? &info : nullptr, nullptr);
    return false;
  }
  png_init_io(png, file);
  png_read_info(png, info);
  // Normalise every PNG flavour to 8-bit RGB.
  png_set_expand(png);
  png_set_strip_16(png);
  png_set_strip_alpha(png);
  png_set_gray_to_rgb(png);
  png_read_update_info(png, info);
  width = png_get_image_width(png, info);
  height = png_get_image_height(png, info);
  const png_size_t rowBytes = png_get_rowbytes(png, info);
  if (rowBytes != png_size_t(width) * 3) {
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  data.resize(rowBytes * height);
  rows.resize(height);
  for (png_uint_32 y = 0; y < height; ++y) rows[y] = data.data() + y * rowBytes;
  png_read_image(png, rows.data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

}  // namespace

void writePng(const Image& image, const std::string& path) {
  if (image.width <= 0 || image.height <= 0 ||
      image.pixels.size() != std::size_t(image.width) * std::size_t(image.height))
    throw Error(path + ": cannot write an empty or inconsistent image (" +
                std::to_string(image.width) + "x" + std::to_string(image.height) + ")");
  static_assert(sizeof(Rgb) == 3, "Rgb must be packed for libpng rows");
  std::vector<png_bytep> rows(std::size_t(image.height));
  for (int y = 0; y < image.height; ++y)
    rows[std::size_t(y)] =
        const_cast<png_bytep>(reinterpret_cast<const png_byte*>(&image.at(0, y)));
  writeFileAtomically(path, [&](std::ostream& out) {
    if (!encode(image, rows.data(), out))
      throw FileError(path, "", "libpng failed to encode the image", "check the disk space");
  });
}

Image readPng(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (!file) throw FileError(path, "", "cannot open for reading", "check the path");
  png_byte signature[8] = {};
  const bool isPng = std::fread(signature, 1, 8, file) == 8 && png_sig_cmp(signature, 0, 8) == 0;
  std::rewind(file);
  png_uint_32 width = 0, height = 0;
  std::vector<png_byte> data;
  std::vector<png_bytep> rows;
  const bool ok = isPng && decode(file, width, height, data, rows);
  std::fclose(file);
  if (!isPng) throw FileError(path, "byte 0", "not a PNG file (bad signature)");
  if (!ok) throw FileError(path, "", "corrupt or unsupported PNG data");
  Image image(static_cast<int>(width), static_cast<int>(height));
  for (std::size_t i = 0; i < image.pixels.size(); ++i)
    image.pixels[i] = {data[3 * i], data[3 * i + 1], data[3 * i + 2]};
  return image;
}

}  // namespace scalespace
