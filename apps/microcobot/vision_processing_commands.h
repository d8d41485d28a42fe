#pragma once
// `microcobot vision calibrate|track|autofocus`, added to the `vision` group.

#include <CLI/CLI.hpp>

namespace mc::cli {
void add_vision_processing(CLI::App& group);
/// `vision autofocus` (vision_autofocus_command.cc; add_vision_processing adds it).
void add_vision_autofocus(CLI::App& group);
/// `vision force` and `vision servo` (vision_force_servo_commands.cc).
void add_vision_force(CLI::App& group);
void add_vision_servo(CLI::App& group);
/// `vision pick-place` (vision_pick_place_commands.cc).
void add_vision_pick_place(CLI::App& group);
}  // namespace mc::cli
