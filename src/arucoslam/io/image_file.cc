#include "arucoslam/io/image_file.h"

#include <cstdint>
#include <opencv2/imgcodecs.hpp>

#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

constexpr std::string_view kPngSignature("\x89PNG\r\n\x1a\n", 8);

std::uint32_t BigEndian32(std::string_view bytes, std::size_t offset) {
  std::uint32_t value = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    value = (value << 8) | static_cast<unsigned char>(bytes[offset + i]);
  }
  return value;
}

}  // namespace

std::optional<std::string> PngLayoutDefect(std::string_view bytes) {
  if (!bytes.starts_with(kPngSignature)) return std::nullopt;  // not a PNG: the decoder says
  std::size_t offset = kPngSignature.size();
  while (offset < bytes.size()) {
    if (bytes.size() - offset < 12) return "truncated PNG (ends inside a chunk header)";
    const std::uint64_t length = BigEndian32(bytes, offset);
    const std::string type(bytes.substr(offset + 4, 4));
    if (bytes.size() - offset - 12 < length)
      return "truncated PNG (ends inside its " + type + " chunk)";
    if (type == "IEND") return std::nullopt;
    offset += 12 + length;
  }
  return "truncated PNG (no IEND chunk)";
}

std::optional<std::string> JpegLayoutDefect(std::string_view bytes) {
  if (!bytes.starts_with("\xFF\xD8\xFF")) return std::nullopt;  // not a JPEG
  // Entropy-coded data stuffs every 0xFF (FF 00) or makes it a restart marker (FF D0-D7), so
  // FF D9 near the end is the end-of-image marker; some writers pad a few bytes after it.
  const std::size_t from = bytes.size() > 1024 ? bytes.size() - 1024 : 2;
  for (std::size_t i = bytes.size() - 1; i > from; --i) {
    if (bytes[i] == '\xD9' && bytes[i - 1] == '\xFF') return std::nullopt;
  }
  return "truncated JPEG (no end-of-image marker)";
}

cv::Mat ReadImageFile(const std::filesystem::path& path, int cv_imread_flags) {
  if (!std::filesystem::exists(path)) throw InputError(path.string(), "image not found");
  if (!std::filesystem::is_regular_file(path)) {
    throw InputError(path.string(), "is not a file (an image was expected)");
  }
  const std::string bytes = ReadTextFile(path);  // the whole file, as bytes
  std::optional<std::string> defect = PngLayoutDefect(bytes);
  if (!defect) defect = JpegLayoutDefect(bytes);
  if (defect) throw InputError(path.string(), *defect);
  cv::Mat image;
  if (!bytes.empty()) {
    const cv::Mat encoded(1, static_cast<int>(bytes.size()), CV_8UC1,
                          const_cast<char*>(bytes.data()));
    image = cv::imdecode(encoded, cv_imread_flags);
  }
  if (image.empty()) {
    throw InputError(path.string(), "cannot read the image (not an image or corrupt)");
  }
  return image;
}

}  // namespace arucoslam
