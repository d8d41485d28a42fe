#pragma once
// The index of a telemetry channel by name (the benches read tick_us off the live samples).
#include <cstddef>
#include <string_view>

#include "microcobot/platform/platform.h"

namespace mc::bench {

inline std::size_t telemetry_channel(std::string_view name) {
  return platform::telemetry_channel_index(name);
}

}  // namespace mc::bench
