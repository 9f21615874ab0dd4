#pragma once
// PNG files through libpng: 8-bit RGB, written atomically (temporary file, then rename).
#include <string>

#include "scalespace/render/Image.hpp"

namespace scalespace {

/// Writes `image` as an 8-bit RGB PNG. Throws FileError naming `path` on failure; an existing
/// file is only replaced once the new one is complete.
void writePng(const Image& image, const std::string& path);

/// Reads an 8-bit or 16-bit grey/RGB/RGBA/palette PNG into RGB (alpha dropped). Throws FileError.
Image readPng(const std::string& path);

}  // namespace scalespace
