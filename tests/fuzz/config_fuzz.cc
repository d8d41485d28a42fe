// libFuzzer harness: the platform configuration parser (the keys `run --config` accepts), from
// text; the referenced stick-slip file is not followed (a fuzzer should not open paths).

#include <cstdint>
#include <cstdlib>
#include <string>

#include "microcobot/core/params.h"
#include "microcobot/platform/platform_config.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const auto c = mc::params_from_yaml_text<mc::platform::PlatformConfig>(text);
    c.validate();
  } catch (const mc::Error& e) {
    const std::string what = e.what();
    if (what.find('\n') != std::string::npos || what.size() > 600) std::abort();
  }
  return 0;
}
