#include "arucoslam/util/files.h"

#include <unistd.h>

#include <fstream>
#include <sstream>
#include <system_error>

#include "arucoslam/util/error.h"

namespace arucoslam {

namespace fs = std::filesystem;

std::string ReadTextFile(const fs::path& path) {
  RequireFile(path, "file");
  std::ifstream stream(path, std::ios::binary);
  if (!stream) throw InputError(path.string(), "cannot open the file for reading");
  std::ostringstream buffer;
  buffer << stream.rdbuf();
  return buffer.str();
}

void WriteTextFileAtomically(const fs::path& path, std::string_view content) {
  const fs::path temporary = path.string() + ".tmp-" + std::to_string(getpid());
  {
    std::ofstream stream(temporary, std::ios::binary | std::ios::trunc);
    if (!stream) throw InputError(path.string(), "cannot create the file (is the folder writable?)");
    stream.write(content.data(), static_cast<std::streamsize>(content.size()));
    if (!stream) {
      std::error_code ignored;
      fs::remove(temporary, ignored);
      throw InputError(path.string(), "write failed (disk full?)");
    }
  }
  std::error_code error;
  fs::rename(temporary, path, error);
  if (error) {
    fs::remove(temporary, error);
    throw InputError(path.string(), "cannot move the finished file into place");
  }
}

void RequireFile(const fs::path& path, std::string_view what) {
  std::error_code error;
  if (!fs::exists(path, error)) {
    throw InputError(path.string(), std::string(what) + " does not exist");
  }
  if (!fs::is_regular_file(path, error)) {
    throw InputError(path.string(), std::string(what) + " is not a regular file");
  }
}

void RequireDirectory(const fs::path& path, std::string_view what) {
  std::error_code error;
  if (!fs::exists(path, error)) {
    throw InputError(path.string(), std::string(what) + " does not exist");
  }
  if (!fs::is_directory(path, error)) {
    throw InputError(path.string(), std::string(what) + " is not a directory");
  }
}

StagedDirectory::StagedDirectory(fs::path target) : target_(std::move(target)) {
  if (target_.has_filename() == false) target_ = target_.parent_path();
  staging_ = target_.string() + ".partial-" + std::to_string(getpid());
  std::error_code error;
  fs::remove_all(staging_, error);
  fs::create_directories(staging_, error);
  if (error) throw InputError(target_.string(), "cannot create the output folder: " + error.message());
}

StagedDirectory::~StagedDirectory() {
  if (committed_) return;
  std::error_code ignored;
  fs::remove_all(staging_, ignored);
}

void StagedDirectory::Commit() {
  std::error_code error;
  if (fs::exists(target_, error)) fs::remove_all(target_, error);
  if (error) throw InputError(target_.string(), "cannot replace the existing output folder");
  fs::rename(staging_, target_, error);
  if (error) throw InputError(target_.string(), "cannot move the output folder into place");
  committed_ = true;
}

}  // namespace arucoslam
