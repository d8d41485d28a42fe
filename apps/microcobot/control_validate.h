#pragma once
// `microcobot control validate`: the tracking controller on a seeded random
// tuning or validation set of references, one row per case, with the goals' verdicts.

#include <CLI/CLI.hpp>

namespace mc::cli {
void add_control_validate(CLI::App& control_group);
}
