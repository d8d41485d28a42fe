#include "microcobot/devices/device.h"

#include "microcobot/core/error.h"

namespace mc::devices {

std::string_view to_string(Lifecycle state) {
  switch (state) {
    case Lifecycle::kUnconfigured:
      return "unconfigured";
    case Lifecycle::kInactive:
      return "inactive";
    case Lifecycle::kActive:
      return "active";
    case Lifecycle::kFault:
      return "fault";
  }
  return "?";
}

void Device::configure() {
  if (state_ == Lifecycle::kActive) {
    throw InvalidInput("device '" + name_ + "': cannot configure while active (deactivate first)");
  }
  enter_safe_state();
  try {
    on_configure();
  } catch (...) {
    state_ = Lifecycle::kFault;
    throw;
  }
  state_ = Lifecycle::kInactive;
}

void Device::activate() {
  if (state_ != Lifecycle::kInactive) {
    throw InvalidInput("device '" + name_ + "': cannot activate from state " +
                       std::string(to_string(state_)));
  }
  on_activate();
  state_ = Lifecycle::kActive;
}

void Device::deactivate() {
  if (state_ != Lifecycle::kActive) return;
  enter_safe_state();
  on_deactivate();
  state_ = Lifecycle::kInactive;
}

void Device::fault() noexcept {
  enter_safe_state();
  state_ = Lifecycle::kFault;
}

}  // namespace mc::devices
