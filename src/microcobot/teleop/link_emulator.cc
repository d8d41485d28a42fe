#include "microcobot/teleop/link_emulator.h"

#include <cmath>

#include "microcobot/core/error.h"

namespace mc::teleop {

void LinkParams::validate() const {
  require(std::isfinite(delay_s) && delay_s >= 0.0 && delay_s <= 10.0, "link.delay_s",
          "must be within [0, 10] s", delay_s);
  require(std::isfinite(jitter_s) && jitter_s >= 0.0 && jitter_s <= delay_s, "link.jitter_s",
          "must be within [0, delay_s]", jitter_s);
  require(std::isfinite(loss) && loss >= 0.0 && loss < 1.0, "link.loss", "must be within [0, 1)", loss);
}

void require_period(double period_s) {
  require(std::isfinite(period_s) && period_s > 0.0, "link period", "must be > 0 s", period_s);
}

}  // namespace mc::teleop
