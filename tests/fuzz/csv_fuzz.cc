// libFuzzer harness: the CSV reader (mc::parse_csv) on arbitrary bytes. Any input must either
// parse into a rectangular table of finite numbers or throw mc::InvalidInput with a one-line
// message of bounded length; nothing else (crash, other exception, NaN) is allowed.

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "microcobot/core/csv.h"
#include "microcobot/core/error.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const mc::CsvTable t = mc::parse_csv(text, "fuzz.csv");
    for (std::size_t c = 0; c < t.cols(); ++c) {
      if (t.column(c).size() != t.rows()) std::abort();
      for (const double v : t.column(c)) {
        if (!std::isfinite(v)) std::abort();
      }
    }
  } catch (const mc::InvalidInput& e) {
    const std::string what = e.what();
    if (what.find('\n') != std::string::npos || what.size() > 400) std::abort();
  }
  return 0;
}
