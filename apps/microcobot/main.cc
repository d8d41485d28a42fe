// microcobot: the command line of the micro-manipulation cobotic platform.
// Exit codes: 0 ok, 2 usage error, 3 invalid input or parameters, 4 computation failed.

#include <cstdlib>
#include <iostream>

#include <CLI/CLI.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include "cli.h"
#include "microcobot/core/error.h"

namespace {

int fail(mc::ExitCode code, const std::string& message) {
  std::cerr << "microcobot: error: " << message << std::endl;
  return static_cast<int>(code);
}

}  // namespace

int main(int argc, char** argv) {
  auto logger = spdlog::stderr_color_mt("microcobot");
  logger->set_pattern("[%l] %v");
  spdlog::set_default_logger(logger);
  spdlog::set_level(spdlog::level::warn);

  CLI::App app{"microcobot - desktop micro-manipulation cobotic platform (simulated devices by default)",
               "microcobot"};
  app.set_version_flag("--version", std::string("microcobot ") + MC_VERSION);
  app.require_subcommand(1);
  app.fallthrough();  // -v may follow the subcommand
  int verbosity = 0;
  app.add_flag("-v,--verbose", verbosity, "Log to stderr (-v info, -vv debug)");
  app.parse_complete_callback([&] {
    if (verbosity >= 2) spdlog::set_level(spdlog::level::debug);
    else if (verbosity == 1) spdlog::set_level(spdlog::level::info);
  });

  for (const auto& group : mc::cli::groups()) {
    CLI::App* sub = app.add_subcommand(group.name, group.description);
    group.add(*sub);
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::string what = e.what();
    if (what.empty()) what = e.get_name();
    return fail(mc::ExitCode::kUsage, what + " (run with --help for usage)");
  } catch (const mc::Error& e) {
    return fail(e.exit_code(), e.what());
  } catch (const std::bad_alloc&) {
    return fail(mc::ExitCode::kComputationFailed, "out of memory");
  } catch (const std::exception& e) {
    return fail(mc::ExitCode::kComputationFailed, std::string("internal error: ") + e.what());
  }
  return EXIT_SUCCESS;
}
