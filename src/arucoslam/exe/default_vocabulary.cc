#include "arucoslam/exe/default_vocabulary.h"

#include <system_error>
#include <vector>

#include "arucoslam/util/error.h"

namespace arucoslam {

std::filesystem::path DefaultVocabularyPath() {
  namespace fs = std::filesystem;
  std::vector<fs::path> places;
  std::error_code error;
  const fs::path executable = fs::read_symlink("/proc/self/exe", error);
  if (!error) {
    places.push_back(executable.parent_path() / kDefaultVocabularyName);
    places.push_back(executable.parent_path() / ".." / "share" / "arucoslam" /
                     kDefaultVocabularyName);
  }
  places.push_back(fs::path(ARUCOSLAM_DATA_DIR) / kDefaultVocabularyName);
  for (const fs::path& place : places) {
    if (fs::is_regular_file(place)) return place;
  }
  throw InputError(places.back().string(),
                   "default vocabulary not found (give one with --vocabulary FILE)");
}

}  // namespace arucoslam
