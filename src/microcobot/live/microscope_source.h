#pragma once
/// @file
/// The microscope's commands from the network (net/microscope_link.h: the slave's microscope
/// topic): the focus drive, the turret, the camera's exposure and gain. They move no part of the
/// slave, so this source never asks for the coupling: it applies what arrived at every operator
/// tick, in every role, whoever drives.

#include "microcobot/live/command_source.h"
#include "microcobot/live/console_command.h"
#include "microcobot/runtime/spsc_ring.h"

namespace mc::live {

/// The focus, objective, exposure and gain a console command carries, applied to the platform's
/// microscope (nothing without a camera). Loop thread; real-time safe.
void apply_microscope(platform::Platform& p, const ConsoleCommand& c) noexcept;

class MicroscopeSource final : public CommandSource {
 public:
  /// A command's microscope part (one producer thread). Wait-free; false when the ring is full
  /// (16 waiting: the next one counts).
  bool push(const ConsoleCommand& c) noexcept { return ring_.push(c); }

  std::string_view name() const noexcept override { return "microscope"; }
  SourceRequest poll(const SourceTick& t) noexcept override;
  void drive(const SourceTick&, teleop::ConsoleInput&) noexcept override {}

 private:
  runtime::SpscRing<ConsoleCommand> ring_{16};
};

}  // namespace mc::live
