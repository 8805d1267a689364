#include "arucoslam/io/image_file.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <opencv2/imgcodecs.hpp>

#include "arucoslam/util/error.h"

namespace arucoslam {
namespace {

constexpr std::array<unsigned char, 8> kPngSignature = {0x89, 'P',  'N',  'G',
                                                        '\r', '\n', 0x1a, '\n'};

std::uint32_t BigEndian32(const unsigned char* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) |
         std::uint32_t{p[3]};
}

}  // namespace

std::optional<std::string> PngLayoutDefect(const std::vector<unsigned char>& bytes) {
  if (bytes.size() < kPngSignature.size() ||
      !std::equal(kPngSignature.begin(), kPngSignature.end(), bytes.begin())) {
    return std::nullopt;  // not a PNG: the decoder says what it is
  }
  std::size_t offset = kPngSignature.size();
  while (offset < bytes.size()) {
    if (bytes.size() - offset < 12) return "truncated PNG (ends inside a chunk header)";
    const std::uint64_t length = BigEndian32(&bytes[offset]);
    const std::string type(reinterpret_cast<const char*>(&bytes[offset + 4]), 4);
    if (bytes.size() - offset - 12 < length)
      return "truncated PNG (ends inside its " + type + " chunk)";
    if (type == "IEND") return std::nullopt;
    offset += 12 + length;
  }
  return "truncated PNG (no IEND chunk)";
}

std::optional<std::string> JpegLayoutDefect(const std::vector<unsigned char>& bytes) {
  if (bytes.size() < 3 || bytes[0] != 0xFF || bytes[1] != 0xD8 || bytes[2] != 0xFF) {
    return std::nullopt;  // not a JPEG
  }
  // Entropy-coded data stuffs every 0xFF (FF 00) or makes it a restart marker (FF D0-D7), so
  // FF D9 near the end is the end-of-image marker; some writers pad a few bytes after it.
  const std::size_t from = bytes.size() > 1024 ? bytes.size() - 1024 : 2;
  for (std::size_t i = bytes.size() - 1; i > from; --i) {
    if (bytes[i] == 0xD9 && bytes[i - 1] == 0xFF) return std::nullopt;
  }
  return "truncated JPEG (no end-of-image marker)";
}

cv::Mat ReadImageFile(const std::filesystem::path& path, int cv_imread_flags) {
  std::ifstream file(path, std::ios::binary);
  if (!file) {
    throw InputError(path.string(),
                     std::filesystem::exists(path) ? "cannot open the image" : "image not found");
  }
  const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(file)),
                                         std::istreambuf_iterator<char>());
  for (const auto& defect : {PngLayoutDefect(bytes), JpegLayoutDefect(bytes)}) {
    if (defect) throw InputError(path.string(), *defect);
  }
  cv::Mat image = bytes.empty() ? cv::Mat() : cv::imdecode(bytes, cv_imread_flags);
  if (image.empty())
    throw InputError(path.string(), "cannot read the image (not an image or corrupt)");
  return image;
}

}  // namespace arucoslam
