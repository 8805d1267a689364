#include "arucoslam/util/files.h"

#include <gtest/gtest.h>

#include <fstream>

#include "arucoslam/util/error.h"
#include "arucoslam/util/scratch_folder.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

TEST(Files, AtomicWriteThenRead) {
  const ScratchFolder scratch("files_test");
  const fs::path& dir = scratch.path();
  WriteTextFileAtomically(dir / "a.txt", "hello\n");
  EXPECT_EQ(ReadTextFile(dir / "a.txt"), "hello\n");
  int entries = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 1);  // no temporary left behind
}

TEST(Files, MissingFileNamesThePath) {
  try {
    ReadTextFile("/nonexistent/x.json");
    FAIL() << "expected InputError";
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), "/nonexistent/x.json");
    EXPECT_NE(std::string(error.what()).find("does not exist"), std::string::npos);
  }
}

TEST(Files, StagedDirectoryIsRemovedWithoutCommit) {
  const ScratchFolder scratch("files_test");
  const fs::path& dir = scratch.path();
  const fs::path target = dir / "out";
  {
    StagedDirectory staged(target);
    std::ofstream(staged.path() / "x.txt") << "partial";
  }
  EXPECT_FALSE(fs::exists(target));
  int entries = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir)) ++entries;
  EXPECT_EQ(entries, 0);
}

TEST(Files, StagedDirectoryCommitReplacesTarget) {
  const ScratchFolder scratch("files_test");
  const fs::path& dir = scratch.path();
  const fs::path target = dir / "out";
  fs::create_directories(target);
  std::ofstream(target / "old.txt") << "old";
  {
    StagedDirectory staged(target);
    std::ofstream(staged.path() / "new.txt") << "new";
    staged.Commit();
  }
  EXPECT_TRUE(fs::exists(target / "new.txt"));
  EXPECT_FALSE(fs::exists(target / "old.txt"));
}

}  // namespace
}  // namespace arucoslam
