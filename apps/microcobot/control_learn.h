#pragma once
// `microcobot control learn`: iterative learning control on repeated references of the tuning or
// validation set, one row of per-trial RMS and max per reference.

#include <CLI/CLI.hpp>

namespace mc::cli {
void add_control_learn(CLI::App& control_group);
}
