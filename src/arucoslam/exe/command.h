// The subcommands of the `arucoslam` binary. Each Add*Command registers a CLI11
// subcommand whose callback runs the work and stores the process exit status.
#pragma once

#include <CLI/CLI.hpp>

#include <string>
#include <vector>

namespace arucoslam {

// Exit statuses shared by every subcommand.
inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;    // the work ran but failed (e.g. no pose found)
inline constexpr int kExitBadInput = 2;   // bad user input: one clear line on stderr

// Appends the ids of a list such as "0-9,12,20-22"; throws InputError("--ids", ...).
void ParseIdRangeInto(const std::string& text, std::vector<int>& ids);

}  // namespace arucoslam
