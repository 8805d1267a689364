// For tests only: a fresh empty folder under the system temp directory, named after the running
// gtest test so that tests run in parallel never share one; removed again on destruction.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <string_view>
#include <system_error>

namespace arucoslam {

// `<temp>/arucoslam_<prefix>_<suite>_<test>`, emptied if a run that did not finish left it
// behind. Construct it inside a test (or a fixture): it reads the current test's name.
class ScratchFolder {
 public:
  explicit ScratchFolder(std::string_view prefix) {
    const ::testing::TestInfo* const test = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = "arucoslam_" + std::string(prefix);
    if (test != nullptr) {
      name += std::string("_") + test->test_suite_name() + "_" + test->name();
    }
    // Parameterised tests are named like "Instance/Suite" and "Case/0".
    std::replace(name.begin(), name.end(), '/', '_');
    path_ = std::filesystem::temp_directory_path() / name;
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchFolder() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  ScratchFolder(const ScratchFolder&) = delete;
  ScratchFolder& operator=(const ScratchFolder&) = delete;

  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace arucoslam
