// The vendor driver sets (pi-gcs2, anc300, smaract-mcs2) registered before any command reads a
// configuration (`devices: {driver: pi-gcs2, connection: ...}`; docs/hardware.md, "Drivers").

#include "microcobot/drivers/register_drivers.h"

namespace {

[[maybe_unused]] const bool kVendorDrivers = (mc::drivers::register_vendor_drivers(), true);

}  // namespace
