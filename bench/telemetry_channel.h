#pragma once
// The index of a telemetry channel by name (the benches read tick_us off the live samples).
#include <cstddef>
#include <string_view>

#include "microcobot/platform/platform.h"

namespace mc::bench {

inline std::size_t telemetry_channel(std::string_view name) {
  for (std::size_t i = 0; i < platform::kTelemetryChannels.size(); ++i)
    if (std::string_view(platform::kTelemetryChannels[i]) == name) return i;
  return 0;
}

}  // namespace mc::bench
