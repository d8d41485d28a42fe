// libFuzzer harness: the YAML parameter parser (mc::params_from_yaml_text) with the stick-slip
// axis's parameters, the largest parameter set. Any input gives valid parameters or an
// mc::Error (InvalidInput for the file, InvalidParams for a value) with a one-line message.

#include <cstdint>
#include <cstdlib>
#include <string>

#include "microcobot/core/params.h"
#include "microcobot/stickslip/stickslip_params.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const auto p = mc::params_from_yaml_text<mc::stickslip::StickSlipParams>(text);
    p.validate();  // must hold for whatever was accepted
  } catch (const mc::Error& e) {
    const std::string what = e.what();
    if (what.find('\n') != std::string::npos || what.size() > 600) std::abort();
  }
  return 0;
}
