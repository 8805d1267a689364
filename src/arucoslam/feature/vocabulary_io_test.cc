#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <random>

#include "arucoslam/feature/vocabulary.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/scratch_folder.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

// A small vocabulary trained on random descriptors (k 4, L 3).
Vocabulary SmallVocabulary() {
  std::mt19937_64 rng(17);
  std::vector<cv::Mat> images;
  for (int i = 0; i < 20; ++i) {
    cv::Mat image(60, kOrbDescriptorBytes, CV_8U);
    for (int r = 0; r < image.rows; ++r) {
      for (int c = 0; c < image.cols; ++c) image.at<std::uint8_t>(r, c) = rng() & 0xff;
    }
    images.push_back(image);
  }
  VocabularyOptions options;
  options.branching = 4;
  options.levels = 3;
  return Vocabulary::Train(images, options);
}

// The message of the InputError that loading `bytes` throws ("" when it loads).
std::string LoadError(const std::string& bytes) {
  try {
    Vocabulary::FromBytes(bytes, "vocab.bin");
  } catch (const InputError& error) {
    EXPECT_EQ(error.source(), "vocab.bin");
    return error.message();
  }
  return "";
}

void PutU32(std::string& bytes, std::size_t offset, std::uint32_t value) {
  std::memcpy(bytes.data() + offset, &value, 4);
}

class VocabularyIoTest : public ::testing::Test {
 protected:
  ScratchFolder scratch_{"vocabulary_io_test"};
  const fs::path& dir_ = scratch_.path();
};

TEST_F(VocabularyIoTest, FileRoundTripIsExact) {
  const Vocabulary vocabulary = SmallVocabulary();
  ASSERT_GT(vocabulary.num_words(), 40u);
  const fs::path path = dir_ / "vocab.bin";
  vocabulary.Save(path);
  const Vocabulary loaded = Vocabulary::Load(path);
  EXPECT_EQ(loaded, vocabulary);  // every node: parent, centre, weight (bit-exact doubles)
  EXPECT_EQ(fs::file_size(path), 28u + (vocabulary.num_nodes() - 1) * 44u + 8u);
  EXPECT_EQ(loaded.ToBytes(), vocabulary.ToBytes());
  cv::Mat query(100, kOrbDescriptorBytes, CV_8U);
  cv::randu(query, 0, 256);
  EXPECT_EQ(loaded.Transform(query).entries, vocabulary.Transform(query).entries);
}

TEST_F(VocabularyIoTest, RejectsWrongMagicVersionTruncationAndCorruption) {
  const std::string good = SmallVocabulary().ToBytes();
  EXPECT_EQ(LoadError(good), "");

  std::string bytes = good;
  bytes[0] = 'X';
  EXPECT_NE(LoadError(bytes).find("wrong magic"), std::string::npos);
  EXPECT_NE(LoadError("").find("wrong magic"), std::string::npos);

  bytes = good;
  PutU32(bytes, 8, 2);
  EXPECT_EQ(LoadError(bytes), "vocabulary file version 2, this build reads version 1");

  for (std::size_t size : {std::size_t{12}, std::size_t{28}, good.size() / 2, good.size() - 1}) {
    EXPECT_NE(LoadError(good.substr(0, size)).find("truncated"), std::string::npos) << size;
  }
  EXPECT_NE(LoadError(good + "x").find("oversized"), std::string::npos);

  bytes = good;
  bytes[good.size() / 2] ^= 0x10;  // one bit inside a node
  EXPECT_NE(LoadError(bytes).find("checksum"), std::string::npos);

  bytes = good;
  PutU32(bytes, 12, 1);  // k = 1 is not a tree
  EXPECT_NE(LoadError(bytes).find("bad vocabulary header"), std::string::npos);
}

TEST_F(VocabularyIoTest, MissingFileNamesIt) {
  try {
    Vocabulary::Load(dir_ / "absent.bin");
    FAIL() << "no error";
  } catch (const InputError& error) {
    EXPECT_NE(error.source().find("absent.bin"), std::string::npos);
  }
}

}  // namespace
}  // namespace arucoslam
