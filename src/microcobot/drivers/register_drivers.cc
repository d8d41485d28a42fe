#include "microcobot/drivers/register_drivers.h"

#include <mutex>

#include "microcobot/drivers/anc300_driver.h"
#include "microcobot/drivers/gcs2_driver.h"
#include "microcobot/drivers/mcs2_driver.h"
#include "microcobot/drivers/pi_hexapod.h"
#include "microcobot/platform/driver_registry.h"

namespace mc::drivers {

void register_vendor_drivers() {
  static std::once_flag once;
  std::call_once(once, [] {
    platform::register_devices("pi-gcs2", make_gcs2_devices);
    platform::register_devices("anc300", make_anc300_devices);
    platform::register_devices("smaract-mcs2", make_mcs2_devices);
    platform::register_positioner("pi-hexapod", make_pi_hexapod);
  });
}

}  // namespace mc::drivers
