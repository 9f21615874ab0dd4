#pragma once
// INTERNAL to the stack store (ScaleStackWriter, ScaleStackReader): the NumPy .npy format 1.0
// header of the stack's files (docs/STACK_FORMAT.md), so that numpy.load(f, mmap_mode='r') opens
// every file of a stack without our code. The writer writes exactly npyHeader(dtype, shape); the
// reader accepts only that same text (a stack is only ever read back by what wrote it, or checked
// against its manifest), which keeps the reader free of a Python-dict parser.
#include <cstddef>
#include <string>
#include <vector>

namespace scalespace::store {

/// Bytes before the header's dict: magic "\x93NUMPY", version (major, minor), uint16 little-endian
/// length of the dict.
constexpr std::size_t kNpyPreludeBytes = 10;

/// A shape as NumPy prints it in the header: "(3,)", "(2, 5)", "(2, 5, 3)".
std::string npyShapeText(const std::vector<std::size_t>& shape);

/// NumPy format 1.0: magic, version, uint16 header length, dict padded with spaces and '\n' so
/// that the data starts at a multiple of 64 bytes. Little-endian C order ('fortran_order': False).
std::string npyHeader(const std::string& dtype, const std::vector<std::size_t>& shape);

/// True when the kNpyPreludeBytes at `prelude` are the magic of a format 1.x file.
bool isNpyVersion1(const unsigned char* prelude);
/// The length of the dict that follows the prelude (the data starts kNpyPreludeBytes after it).
std::size_t npyDictLength(const unsigned char* prelude);

}  // namespace scalespace::store
