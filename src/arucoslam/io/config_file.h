// The SLAM run's config file: every option of SystemOptions as YAML, one section per nested
// options struct, each key with its comment. `arucoslam run --print-config` writes it and
// `--config FILE` reads it; both go through the layers' VisitOptions (options_visit.h).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

namespace arucoslam {

struct SystemOptions;

// Every option of `options` as commented YAML: keys as the C++ fields, in their order,
// enums by name, an unset optional section as null with its keys commented out below it.
std::string SystemOptionsYaml(const SystemOptions& options);

// Reads config text over `options`: the keys it sets replace their values, the others keep
// theirs; an empty text changes nothing. Throws InputError(source, "<key path> (line N):
// ...") on a YAML syntax error, an unknown section or key, a wrong type or enum name, or a
// value that fails its options' Check(); `options` is then unchanged.
void ParseSystemOptions(std::string_view text, const std::string& source, SystemOptions& options);
// The same from a file (InputError naming it when it is missing or unreadable).
void ReadSystemOptions(const std::filesystem::path& path, SystemOptions& options);

}  // namespace arucoslam
