// ReadImageFile: an image file decoded with OpenCV, or one InputError naming the file and what
// is wrong (missing, truncated PNG or JPEG, not an image), without the decoder's own stderr lines.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <string_view>

namespace arucoslam {

// What is wrong with the bytes of a PNG file (signature, a chunk running past the end, no
// IEND chunk); nullopt for a well-formed chunk layout or for bytes that are not a PNG at all.
// Chunk contents and checksums are left to the decoder.
std::optional<std::string> PngLayoutDefect(std::string_view bytes);
// The same for a JPEG file: one cut short has no end-of-image marker (FF D9) in its last
// kilobyte (its decoder would fill the missing rows with grey and only warn).
std::optional<std::string> JpegLayoutDefect(std::string_view bytes);

// The file decoded with `cv_imread_flags` (cv::IMREAD_*). Throws InputError naming `path`: no
// such file, a PNG or JPEG cut short (PngLayoutDefect, JpegLayoutDefect), or bytes OpenCV
// cannot decode.
cv::Mat ReadImageFile(const std::filesystem::path& path, int cv_imread_flags);

}  // namespace arucoslam
