// microcobot: the command line of the micro-manipulation cobotic platform.
// Exit codes: 0 ok, 2 usage error, 3 invalid input or parameters, 4 computation failed.

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <string_view>

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include "cli.h"
#include "microcobot/core/error.h"
#include "microcobot/core/input_file.h"
#include "signals.h"

namespace {

int fail(mc::ExitCode code, const std::string& message) {
  // One line, whatever the message holds (a file name with a newline, a CLI11 message).
  std::string line;
  for (const char c : mc::cli::unstaged(message)) line += (c == '\n' || c == '\r') ? ' ' : c;
  std::cerr << "microcobot: error: " << line << std::endl;
  return static_cast<int>(code);
}

std::string names_of(const CLI::App& app) {
  std::string out;
  for (const auto* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
    out += (out.empty() ? "" : ", ") + sub->get_name();
  }
  return out;
}

// Every numeric flag refuses NaN and infinities as a usage error (exit 2), whichever command
// it belongs to, before any range check could let them through.
const CLI::Validator kFinite(
    [](std::string& text) -> std::string {
      double v = 0.0;
      if (CLI::detail::lexical_cast(text, v) && !std::isfinite(v)) {
        return "'" + mc::excerpt(text) + "' is not a finite number";
      }
      return {};
    },
    "FINITE", "finite");

// `--out DIR` is redirected to a staging directory beside DIR (signals.h).
const CLI::Validator kStaged(
    [](std::string& text) -> std::string {
      text = mc::cli::stage_output(text).string();
      return {};
    },
    "", "staged");

void harden(CLI::App& app) {
  for (CLI::Option* opt : app.get_options()) {
    if (opt->get_type_name().find("FLOAT") != std::string::npos) opt->check(kFinite);
    // serve's recordings appear in --out while it runs, each file atomic on its own.
    if (opt->check_lname("out") && app.get_name() != "serve") opt->transform(kStaged);
  }
  for (CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) harden(*sub);
}

// The command words of argv (before the first flag): an unknown group or verb is named.
void check_command_words(const CLI::App& app, int argc, char** argv) {
  const CLI::App* level = &app;
  for (int i = 1; i < argc; ++i) {
    const std::string_view word = argv[i];
    if (word.empty() || word[0] == '-') {
      if (level == &app) continue;  // -v before the group
      break;
    }
    const auto subs = level->get_subcommands([](const CLI::App*) { return true; });
    if (subs.empty()) break;
    const CLI::App* next = nullptr;
    for (const auto* s : subs) {
      if (s->get_name() == word) next = s;
    }
    if (next == nullptr) {
      if (level == &app) {
        throw mc::UsageError("unknown command '" + mc::excerpt(word) + "' (commands: " + names_of(app) + ")");
      }
      throw mc::UsageError("microcobot " + level->get_name() + ": unknown verb '" + mc::excerpt(word) +
                           "' (verbs: " + names_of(*level) + ")");
    }
    level = next;
  }
}

int run_cli(CLI::App& app, int argc, char** argv);

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
    if (verbosity >= 2)
      spdlog::set_level(spdlog::level::debug);
    else if (verbosity == 1)
      spdlog::set_level(spdlog::level::info);
  });

  for (const auto& group : mc::cli::groups()) {
    CLI::App* sub = app.add_subcommand(group.name, group.description);
    group.add(*sub);
    if (!sub->get_subcommands([](const CLI::App*) { return true; }).empty()) {
      // A group of verbs without a verb is a usage error that lists the verbs.
      sub->require_subcommand(0, 1);
      sub->parse_complete_callback([sub] {
        if (sub->get_subcommands().empty()) {
          throw mc::UsageError("microcobot " + sub->get_name() +
                               ": a verb is required (verbs: " + names_of(*sub) + ")");
        }
      });
    }
  }
  harden(app);
  mc::cli::install_signal_handlers();

  const int rc = run_cli(app, argc, argv);
  if (rc != EXIT_SUCCESS) mc::cli::discard_outputs();
  return rc;
}

namespace {

int run_cli(CLI::App& app, int argc, char** argv) {
  try {
    check_command_words(app, argc, argv);
    app.parse(argc, argv);
    // A signal the command itself took as its end (serve, link echo: stopped by SIGINT/SIGTERM
    // on purpose, exit 0) is not an interruption of the outputs.
    const int before_commit = mc::cli::interrupt_signal();
    mc::cli::commit_outputs();
    // A signal while the outputs were moved into place waited for the last one (signals.h).
    if (const int sig = mc::cli::interrupt_signal(); sig != 0 && before_commit == 0) {
      const mc::cli::Interrupted e(sig, true);
      return fail(static_cast<mc::ExitCode>(e.exit_code()), e.what());
    }
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::string what = e.what();
    if (what.empty()) what = e.get_name();
    return fail(mc::ExitCode::kUsage, mc::excerpt(what, 300) + " (run with --help for usage)");
  } catch (const mc::cli::Interrupted& e) {
    // The command stopped cleanly and marked its outputs: keep them.
    try {
      mc::cli::commit_outputs();
    } catch (const mc::Error& c) {
      fail(c.exit_code(), c.what());
    }
    return fail(static_cast<mc::ExitCode>(e.exit_code()), e.what());
  } catch (const mc::Error& e) {
    return fail(e.exit_code(), e.what());
  } catch (const std::bad_alloc&) {
    return fail(mc::ExitCode::kComputationFailed, "out of memory");
  } catch (const std::exception& e) {
    return fail(mc::ExitCode::kComputationFailed, std::string("internal error: ") + e.what());
  }
  return EXIT_SUCCESS;
}

}  // namespace
