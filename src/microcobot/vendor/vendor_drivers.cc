#include "microcobot/vendor/vendor_drivers.h"

#include <mutex>

#include "microcobot/platform/driver_registry.h"
#include "microcobot/vendor/anc300_driver.h"
#include "microcobot/vendor/gcs2_driver.h"

namespace mc::vendor {

void register_vendor_drivers() {
  static std::once_flag once;
  std::call_once(once, [] {
    platform::register_devices("pi-gcs2", make_gcs2_devices);
    platform::register_devices("anc300", make_anc300_devices);
  });
}

}  // namespace mc::vendor
