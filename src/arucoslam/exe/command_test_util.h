// For the exe/ tests: runs the built `arucoslam` binary (ARUCOSLAM_BINARY) with arguments
// and returns its exit status and combined stdout/stderr.
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace arucoslam::testing_util {

struct CommandResult {
  int status = -1;     // exit status; -1 when the process did not exit normally
  std::string output;  // stdout and stderr
};

inline CommandResult RunArucoslam(const std::string& arguments) {
  const std::string command = std::string(ARUCOSLAM_BINARY) + " " + arguments + " 2>&1";
  CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 512> buffer{};
  while (fgets(buffer.data(), buffer.size(), pipe) != nullptr) result.output += buffer.data();
  const int status = pclose(pipe);
  result.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

// The same with stdout and stderr kept apart (captured through files in `scratch_dir`).
struct SplitCommandResult {
  int status = -1;
  std::string out;
  std::string err;
};

inline SplitCommandResult RunArucoslamSplit(const std::string& arguments,
                                            const std::filesystem::path& scratch_dir) {
  const std::filesystem::path out = scratch_dir / "stdout.txt";
  const std::filesystem::path err = scratch_dir / "stderr.txt";
  const std::string command = std::string(ARUCOSLAM_BINARY) + " " + arguments + " > " +
                              out.string() + " 2> " + err.string();
  const int raw = std::system(command.c_str());
  const auto read = [](const std::filesystem::path& path) {
    std::ifstream stream(path);
    std::ostringstream text;
    text << stream.rdbuf();
    return text.str();
  };
  SplitCommandResult result;
  result.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  result.out = read(out);
  result.err = read(err);
  return result;
}

}  // namespace arucoslam::testing_util
