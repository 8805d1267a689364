// DefaultVocabularyPath: where `run` finds the bag-of-words vocabulary shipped with arucoslam
// when --vocabulary is not given (next to the executable, else the source tree's data/).
#pragma once

#include <filesystem>

namespace arucoslam {

inline constexpr const char* kDefaultVocabularyName = "vocabulary/orb_k10_l5.bin";

// The first existing of <executable dir>/vocabulary/, <executable dir>/../share/arucoslam/
// vocabulary/ and the data/vocabulary/ folder of the sources; throws InputError naming the
// last place looked at when none exists.
std::filesystem::path DefaultVocabularyPath();

}  // namespace arucoslam
