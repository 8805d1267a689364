#include "arucoslam/util/scratch_folder.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

TEST(ScratchFolder, IsAnEmptyFolderNamedAfterTheTest) {
  const ScratchFolder scratch("scratch_folder_test");
  EXPECT_TRUE(fs::is_directory(scratch.path()));
  EXPECT_TRUE(fs::is_empty(scratch.path()));
  EXPECT_EQ(scratch.path().parent_path(), fs::temp_directory_path());
  EXPECT_EQ(scratch.path().filename(),
            "arucoslam_scratch_folder_test_ScratchFolder_IsAnEmptyFolderNamedAfterTheTest");
}

TEST(ScratchFolder, DifferentPrefixesGiveDifferentFolders) {
  const ScratchFolder a("scratch_folder_test_a");
  const ScratchFolder b("scratch_folder_test_b");
  EXPECT_NE(a.path(), b.path());
  EXPECT_TRUE(fs::is_directory(a.path()));
  EXPECT_TRUE(fs::is_directory(b.path()));
}

TEST(ScratchFolder, IsRemovedWithWhatItHolds) {
  fs::path path;
  {
    const ScratchFolder scratch("scratch_folder_test");
    path = scratch.path();
    std::ofstream(path / "file.txt") << "content";
    fs::create_directories(path / "sub");
    std::ofstream(path / "sub" / "nested.txt") << "content";
    ASSERT_TRUE(fs::exists(path / "file.txt"));
  }
  EXPECT_FALSE(fs::exists(path));
}

TEST(ScratchFolder, EmptiesAFolderLeftOverByAnEarlierRun) {
  const fs::path path = ScratchFolder("scratch_folder_test").path();  // made and removed
  fs::create_directories(path / "sub");
  std::ofstream(path / "stale.txt") << "stale";
  std::ofstream(path / "sub" / "stale.txt") << "stale";

  const ScratchFolder scratch("scratch_folder_test");
  ASSERT_EQ(scratch.path(), path);
  EXPECT_TRUE(fs::is_directory(scratch.path()));
  EXPECT_TRUE(fs::is_empty(scratch.path()));
}

}  // namespace
}  // namespace arucoslam
