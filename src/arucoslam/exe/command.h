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

// `markers generate | sdf | import` (markers_command.cc).
void AddMarkersCommand(CLI::App& app, int& exit_status);

// `experiments` and `demo` (experiments_command.cc).
void AddExperimentsCommand(CLI::App& app, int& exit_status);
void AddDemoCommand(CLI::App& app, int& exit_status);

// `world factory` (world_command.cc).
void AddWorldCommand(CLI::App& app, int& exit_status);

// `eval` (eval_command.cc).
void AddEvalCommand(CLI::App& app, int& exit_status);

// `simulate` (simulate_command.cc).
void AddSimulateCommand(CLI::App& app, int& exit_status);

// `locate` (locate_command.cc).
void AddLocateCommand(CLI::App& app, int& exit_status);

// `run` (run_command.cc).
void AddRunCommand(CLI::App& app, int& exit_status);

// `vocab train | info` (vocab_command.cc).
void AddVocabCommand(CLI::App& app, int& exit_status);

}  // namespace arucoslam
