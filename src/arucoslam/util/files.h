// File helpers that keep output all-or-nothing: a text file is written to a temporary
// name and renamed; a StagedDirectory is filled aside and moved into place on Commit().
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace arucoslam {

// Reads a whole file; throws InputError naming the file when it is missing or unreadable.
std::string ReadTextFile(const std::filesystem::path& path);

// Writes `content` to `path` via a temporary file in the same folder and a rename, so a
// reader never sees half a file. Throws InputError when the folder is not writable.
void WriteTextFileAtomically(const std::filesystem::path& path, std::string_view content);

// Throws InputError naming `path` (and what it is for) when it is not an existing file.
void RequireFile(const std::filesystem::path& path, std::string_view what);
// Same for a directory.
void RequireDirectory(const std::filesystem::path& path, std::string_view what);

// An output directory built aside (`<target>.partial-<pid>`) and renamed to `target` on
// Commit(). Without Commit() (an error was thrown) the partial folder is removed. An
// existing `target` is replaced only on Commit().
class StagedDirectory {
 public:
  explicit StagedDirectory(std::filesystem::path target);
  ~StagedDirectory();
  StagedDirectory(const StagedDirectory&) = delete;
  StagedDirectory& operator=(const StagedDirectory&) = delete;

  // Where to write while staging.
  const std::filesystem::path& path() const { return staging_; }
  const std::filesystem::path& target() const { return target_; }
  void Commit();

 private:
  std::filesystem::path target_;
  std::filesystem::path staging_;
  bool committed_ = false;
};

}  // namespace arucoslam
