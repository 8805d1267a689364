// `arucoslam vocab train | info`: trains the bag-of-words vocabulary on the ORB features of a
// set of images (folders, image files or list files) and describes a vocabulary file.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "arucoslam/exe/command.h"
#include "arucoslam/feature/orb_extractor.h"
#include "arucoslam/feature/vocabulary.h"
#include "arucoslam/io/image_file.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/files.h"

namespace arucoslam {
namespace {

namespace fs = std::filesystem;

struct VocabTrainArgs {
  std::vector<std::string> images;
  std::string out;
  VocabularyOptions vocabulary;
  int max_features_per_image = 500;
  int stride = 1;      // every stride-th image of the sorted list
  int max_images = 0;  // 0: no limit (after the stride)
  bool quiet = false;
};

bool IsImageFile(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".pgm" || ext == ".ppm" ||
         ext == ".bmp" || ext == ".tif" || ext == ".tiff";
}

// Adds the images that `source` names: a folder (searched recursively, sorted), an image
// file, or a text file listing one folder or image per line (relative to the list's folder;
// blank lines and lines starting with # skipped).
void CollectImages(const fs::path& source, int list_depth, std::vector<fs::path>& images) {
  if (fs::is_directory(source)) {
    std::vector<fs::path> found;
    for (const auto& entry : fs::recursive_directory_iterator(source)) {
      if (entry.is_regular_file() && IsImageFile(entry.path())) found.push_back(entry.path());
    }
    std::sort(found.begin(), found.end());
    images.insert(images.end(), found.begin(), found.end());
  } else if (fs::is_regular_file(source) && IsImageFile(source)) {
    images.push_back(source);
  } else if (fs::is_regular_file(source)) {
    if (list_depth > 0) throw InputError(source.string(), "a list file may not name another list");
    std::ifstream list(source);
    std::string line;
    int number = 0;
    while (std::getline(list, line)) {
      ++number;
      line.erase(line.find_last_not_of(" \t\r") + 1);
      if (line.empty() || line[0] == '#') continue;
      fs::path entry(line);
      if (entry.is_relative()) entry = source.parent_path() / entry;
      if (!fs::exists(entry)) {
        throw InputError(source.string(), "line " + std::to_string(number) + ": '" + line +
                                              "' does not exist");
      }
      CollectImages(entry, list_depth + 1, images);
    }
  } else {
    throw InputError("--images", "'" + source.string() + "' does not exist");
  }
}

void CheckArgs(const VocabTrainArgs& args) {
  if (args.vocabulary.branching < 2 || args.vocabulary.branching > 255) {
    throw InputError("--k", "expected a branching factor of 2 to 255");
  }
  if (args.vocabulary.levels < 1 || args.vocabulary.levels > 8) {
    throw InputError("--levels", "expected 1 to 8 levels");
  }
  if (args.vocabulary.max_iterations < 1) throw InputError("--iterations", "expected >= 1");
  if (args.max_features_per_image < 10 || args.max_features_per_image > 10000) {
    throw InputError("--max-features-per-image", "expected 10 to 10000");
  }
  if (args.stride < 1) throw InputError("--stride", "expected >= 1");
  if (args.max_images < 0) throw InputError("--max-images", "expected >= 0 (0: all)");
}

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void RunVocabTrain(const VocabTrainArgs& args) {
  CheckArgs(args);
  std::vector<fs::path> all;
  for (const std::string& source : args.images) CollectImages(source, 0, all);
  std::vector<fs::path> images;
  for (std::size_t i = 0; i < all.size(); i += args.stride) {
    if (args.max_images > 0 && static_cast<int>(images.size()) >= args.max_images) break;
    images.push_back(all[i]);
  }
  if (images.empty()) throw InputError("--images", "no image files found");

  const auto start = std::chrono::steady_clock::now();
  OrbExtractorOptions orb;
  orb.num_features = args.max_features_per_image;
  const OrbExtractor extractor(orb);
  std::vector<cv::Mat> descriptors;
  std::size_t num_features = 0;
  for (std::size_t i = 0; i < images.size(); ++i) {
    const cv::Mat image = ReadImageFile(images[i], cv::IMREAD_GRAYSCALE);
    descriptors.push_back(extractor.Extract(image).descriptors);
    num_features += descriptors.back().rows;
    if (!args.quiet && ((i + 1) % 100 == 0 || i + 1 == images.size())) {
      std::fprintf(stderr, "\rextracting ORB: %zu/%zu images, %zu features", i + 1,
                   images.size(), num_features);
      std::fflush(stderr);
    }
  }
  if (!args.quiet) std::fprintf(stderr, "\nclustering (k %d, L %d)...\n",
                                args.vocabulary.branching, args.vocabulary.levels);
  if (num_features < 2) throw InputError("--images", "fewer than 2 ORB features in the images");
  const Vocabulary vocabulary = Vocabulary::Train(descriptors, args.vocabulary);
  vocabulary.Save(args.out);
  std::printf("wrote %s: k %d, L %d, %zu words (%zu nodes) from %zu images, %zu features, "
              "in %.1f s\n",
              args.out.c_str(), vocabulary.branching(), vocabulary.levels(),
              vocabulary.num_words(), vocabulary.num_nodes(), images.size(), num_features,
              SecondsSince(start));
}

void RunVocabInfo(const std::string& path) {
  const auto start = std::chrono::steady_clock::now();
  const Vocabulary vocabulary = Vocabulary::Load(path);
  const double load_s = SecondsSince(start);
  std::size_t zero_weight = 0;
  for (WordId w = 0; w < vocabulary.num_words(); ++w) zero_weight += vocabulary.WordWeight(w) == 0;
  std::printf("%s: k %d, L %d, %zu words (%zu nodes, %zu of zero weight), trained on %u images; "
              "loaded in %.3f s\n",
              path.c_str(), vocabulary.branching(), vocabulary.levels(), vocabulary.num_words(),
              vocabulary.num_nodes(), zero_weight, vocabulary.num_training_images(), load_s);
}

}  // namespace

void AddVocabCommand(CLI::App& app, int& exit_status) {
  CLI::App* vocab = app.add_subcommand("vocab", "Bag-of-words vocabulary: train, info");
  vocab->require_subcommand(1);

  auto args = std::make_shared<VocabTrainArgs>();
  CLI::App* train = vocab->add_subcommand(
      "train", "Train a vocabulary (hierarchical k-majority on ORB descriptors, TF-IDF weights)");
  train->add_option("--images", args->images,
                    "image folders (recursive), image files or list files (one path a line)")
      ->required();
  train->add_option("--out", args->out, "output vocabulary file (binary)")->required();
  train->add_option("--k", args->vocabulary.branching, "branching factor")->capture_default_str();
  train->add_option("--levels", args->vocabulary.levels, "depth L of the tree (words <= k^L)")
      ->capture_default_str();
  train->add_option("--max-features-per-image", args->max_features_per_image,
                    "ORB features extracted per image")
      ->capture_default_str();
  train->add_option("--iterations", args->vocabulary.max_iterations,
                    "k-majority rounds per node")
      ->capture_default_str();
  train->add_option("--seed", args->vocabulary.seed, "seed of the k-means++ seeding")
      ->capture_default_str();
  train->add_option("--stride", args->stride, "use every n-th image of the sorted list")
      ->capture_default_str();
  train->add_option("--max-images", args->max_images, "at most this many images (0: all)")
      ->capture_default_str();
  train->add_flag("--quiet", args->quiet, "no progress lines");
  train->callback([args, &exit_status] {
    RunVocabTrain(*args);
    exit_status = kExitOk;
  });

  auto path = std::make_shared<std::string>();
  CLI::App* info = vocab->add_subcommand("info", "Describe a vocabulary file");
  info->add_option("--vocab", *path, "vocabulary file")->required();
  info->callback([path, &exit_status] {
    RunVocabInfo(*path);
    exit_status = kExitOk;
  });
}

}  // namespace arucoslam
