// The `arucoslam` binary: parses the command line, dispatches to a subcommand, and turns
// bad input into one clear line on stderr with exit status 2.
#include <glog/logging.h>

#include <cstdio>
#include <exception>
#include <string>

#include "arucoslam/exe/command.h"
#include "arucoslam/util/error.h"
#include "arucoslam/util/logging.h"

int main(int argc, char** argv) {
  using namespace arucoslam;
  google::InitGoogleLogging(argv[0]);
  FLAGS_logtostderr = true;
  CLI::App app{"ArucoSLAM: monocular visual SLAM fused with ArUco fiducial markers"};
  app.set_version_flag("--version", std::string("arucoslam ") + ARUCOSLAM_VERSION);
  app.require_subcommand(1);
  std::string log_level = "info";
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error or off")
      ->capture_default_str();
  app.parse_complete_callback([&log_level] {
    if (!SetLogLevel(log_level)) {
      throw CLI::ValidationError("--log-level", "unknown level '" + log_level + "'");
    }
    // Ceres' solver warnings (glog) show only when debugging.
    const bool debugging = log_level == "debug" || log_level == "trace";
    FLAGS_minloglevel = debugging ? google::GLOG_INFO : google::GLOG_ERROR;
  });

  int exit_status = kExitOk;
  // Subcommands (one file each, *_command.cc).
  AddDemoCommand(app, exit_status);
  AddMarkersCommand(app, exit_status);
  AddWorldCommand(app, exit_status);
  AddEvalCommand(app, exit_status);
  AddSimulateCommand(app, exit_status);
  AddLocateCommand(app, exit_status);
  AddRunCommand(app, exit_status);
  AddVocabCommand(app, exit_status);
  AddExperimentsCommand(app, exit_status);
  (void)exit_status;

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    const int status = app.exit(error);
    return status == 0 ? 0 : kExitBadInput;
  } catch (const InputError& error) {
    std::fprintf(stderr, "arucoslam: %s\n", error.what());
    return kExitBadInput;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "arucoslam: internal error: %s\n", error.what());
    return kExitFailure;
  }
  return exit_status;
}
