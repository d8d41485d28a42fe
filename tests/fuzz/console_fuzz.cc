// libFuzzer harness: the console's messages as the live server receives them from any client:
// a command or an action is either accepted and within the platform's limits, or
// refused with one line.

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "microcobot/core/error.h"
#include "microcobot/live/console_command.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const mc::live::ConsoleLimits limits;
  try {
    const auto c = mc::live::parse_console_command(text, limits);
    const double speed = std::hypot(c.velocity_m_s[0], c.velocity_m_s[1], c.velocity_m_s[2]);
    if (!(speed <= limits.max_speed_m_s * (1 + 1e-12))) std::abort();
    for (std::size_t i = 0; i < 3; ++i)
      if (!(c.goal_m[i] >= limits.min_m[i] && c.goal_m[i] <= limits.max_m[i])) std::abort();
    if (!(c.gripper_opening_m >= 0 && c.gripper_opening_m <= limits.max_opening_m)) std::abort();
    if (!(c.goal_speed_m_s > 0 && c.goal_speed_m_s <= limits.max_speed_m_s)) std::abort();
  } catch (const mc::Error& e) {
    const std::string what = e.what();
    if (what.find('\n') != std::string::npos || what.size() > 600) std::abort();
  }
  try {
    (void)mc::live::parse_console_action(text);
  } catch (const mc::Error& e) {
    if (std::string(e.what()).find('\n') != std::string::npos) std::abort();
  }
  return 0;
}
