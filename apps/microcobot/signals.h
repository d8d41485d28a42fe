#pragma once
/// @file
/// Whole-command atomicity and signals for the `microcobot` CLI.
///
/// Output sets: every `--out DIR` (and the default directories of `run` and `report`) is
/// redirected to a staging directory beside DIR (`.DIR.tmp-XXXXXX`); the command writes its
/// whole output set there and main() moves the files into DIR only when the command
/// succeeded (commit_outputs). On any failure the staging directory is removed
/// (discard_outputs), so a failed command leaves nothing new behind. Summaries printed by
/// emit() name the final paths.
///
/// Signals: SIGINT and SIGTERM print one line, remove the staging directories and exit with
/// 128 + signal (130, 143). A command that can stop cleanly (`run`) asks for cooperative
/// handling: the signal then only sets a flag the command polls; it finishes its output
/// (marked as interrupted) and throws Interrupted.

#include <filesystem>
#include <string>

#include "microcobot/core/error.h"

namespace mc::cli {

/// Thrown by a command that stopped on a signal after writing what it could; exit 128 + signal.
/// `outputs_complete`: the signal came after the work was done (while its outputs were being
/// written), so the outputs are whole, not marked as interrupted.
class Interrupted : public mc::Error {
 public:
  explicit Interrupted(int signal, bool outputs_complete = false);
  int exit_code() const { return 128 + signal_; }

 private:
  int signal_;
};

void install_signal_handlers();
/// While true, SIGINT/SIGTERM only set the flag read by interrupt_signal() (a second signal
/// still exits at once).
void set_cooperative_interrupts(bool on);
/// The signal received (SIGINT, SIGTERM) or 0.
int interrupt_signal();
/// "SIGINT", "SIGTERM".
std::string signal_name(int signal);

/// Creates the staging directory for the output directory `target` and returns it. Throws
/// InvalidInput naming `target` when it cannot be created there.
std::filesystem::path stage_output(const std::filesystem::path& target);
/// Moves every staged file into its target directory (refusing first, with nothing moved,
/// when a target entry is in the way, e.g. a directory where a file goes). A SIGINT/SIGTERM
/// while the files are moved waits for the last one (a half-moved set would mix new files with
/// old ones); interrupt_signal() then reports it and the caller exits 128 + signal.
void commit_outputs();
/// Removes the staging directories (and the parents stage_output created).
void discard_outputs() noexcept;
/// Prints `text` on stdout now, or after commit_outputs() while outputs are staged (dropped
/// by discard_outputs()).
void print_after_commit(const std::string& text);
/// `text` with each staging directory replaced by its target.
std::string unstaged(std::string text);

}  // namespace mc::cli
