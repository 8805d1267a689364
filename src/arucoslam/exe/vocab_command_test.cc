#include <gtest/gtest.h>

#include "arucoslam/exe/command_test_util.h"
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

#include "arucoslam/feature/vocabulary.h"
#include "arucoslam/util/scratch_folder.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

using testing_util::RunArucoslam;

int CountLines(const std::string& text) {
  return static_cast<int>(std::count(text.begin(), text.end(), '\n'));
}

class VocabCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    fs::create_directories(dir_ / "images" / "sub");
    // Textured images (blurred noise with shapes), some in a subfolder.
    cv::RNG rng(5);
    for (int i = 0; i < 6; ++i) {
      cv::Mat image(240, 320, CV_8U);
      rng.fill(image, cv::RNG::UNIFORM, 0, 255);
      cv::GaussianBlur(image, image, cv::Size(5, 5), 1.5);
      for (int k = 0; k < 20; ++k) {
        cv::rectangle(image, cv::Rect(rng.uniform(0, 300), rng.uniform(0, 220), 20, 15),
                      cv::Scalar(rng.uniform(0, 255)), cv::FILLED);
      }
      const fs::path folder = i < 4 ? dir_ / "images" : dir_ / "images" / "sub";
      cv::imwrite((folder / ("frame_" + std::to_string(i) + ".png")).string(), image);
    }
    std::ofstream(dir_ / "images" / "notes.txt") << "not an image\n";
  }
  ScratchFolder scratch_{"vocab_command_test"};
  const fs::path& dir_ = scratch_.path();
};

TEST_F(VocabCommandTest, TrainsFromAFolderAndInfoDescribesIt) {
  const fs::path out = dir_ / "vocab.bin";
  const auto result = RunArucoslam("vocab train --quiet --images " + (dir_ / "images").string() +
                                     " --out " + out.string() +
                                     " --k 5 --levels 3 --max-features-per-image 300");
  ASSERT_EQ(result.status, 0) << result.output;
  EXPECT_NE(result.output.find("k 5, L 3"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("from 6 images"), std::string::npos) << result.output;
  const Vocabulary vocabulary = Vocabulary::Load(out);
  EXPECT_EQ(vocabulary.branching(), 5);
  EXPECT_EQ(vocabulary.levels(), 3);
  EXPECT_EQ(vocabulary.num_training_images(), 6u);
  EXPECT_GT(vocabulary.num_words(), 60u);  // ~1800 features fill most of the 125 leaves
  EXPECT_LE(vocabulary.num_words(), 125u);

  const auto info = RunArucoslam("vocab info --vocab " + out.string());
  ASSERT_EQ(info.status, 0) << info.output;
  EXPECT_NE(info.output.find(std::to_string(vocabulary.num_words()) + " words"),
            std::string::npos)
      << info.output;
}

TEST_F(VocabCommandTest, ListFileStrideAndMaxImages) {
  std::ofstream(dir_ / "list.txt") << "# training set\nimages/sub\n\nimages/frame_0.png\n";
  const fs::path out = dir_ / "from_list.bin";
  auto result = RunArucoslam("vocab train --quiet --images " + (dir_ / "list.txt").string() +
                               " --out " + out.string() + " --k 4 --levels 2");
  ASSERT_EQ(result.status, 0) << result.output;
  EXPECT_EQ(Vocabulary::Load(out).num_training_images(), 3u);
  result = RunArucoslam("vocab train --quiet --images " + (dir_ / "images").string() + " --out " +
                        out.string() + " --k 4 --levels 2 --stride 2 --max-images 2");
  ASSERT_EQ(result.status, 0) << result.output;
  EXPECT_EQ(Vocabulary::Load(out).num_training_images(), 2u);
}

TEST_F(VocabCommandTest, BadInputIsOneLineAndWritesNothing) {
  const fs::path out = dir_ / "never.bin";
  const std::string images = " --images " + (dir_ / "images").string();
  for (const std::string& arguments :
       {"vocab train --images " + (dir_ / "absent").string() + " --out " + out.string(),
        "vocab train" + images + " --out " + out.string() + " --k 1",
        "vocab train" + images + " --out " + out.string() + " --levels 9",
        "vocab train" + images + " --out " + out.string() + " --max-features-per-image 5",
        "vocab train --images " + (dir_ / "images" / "notes.txt").string() + " --out " +
            out.string()}) {
    const auto result = RunArucoslam(arguments);
    EXPECT_EQ(result.status, 2) << arguments << "\n" << result.output;
    EXPECT_EQ(CountLines(result.output), 1) << result.output;
    EXPECT_FALSE(fs::exists(out)) << arguments;
  }
  // A truncated vocabulary file.
  std::ofstream(dir_ / "short.bin", std::ios::binary) << "ASLAMBOW\x01\x00";
  const auto info = RunArucoslam("vocab info --vocab " + (dir_ / "short.bin").string());
  EXPECT_EQ(info.status, 2);
  EXPECT_NE(info.output.find("truncated"), std::string::npos) << info.output;
}

}  // namespace
}  // namespace arucoslam
