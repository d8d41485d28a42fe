#pragma once
/// @file
/// Registers the vendor driver sets in the driver registry (platform/driver_registry.h):
/// `pi-gcs2` (drivers/gcs2_driver.h), `anc300` (drivers/anc300_driver.h) and `smaract-mcs2`
/// (drivers/mcs2_driver.h), so that
///
///     devices: {driver: pi-gcs2, connection: "127.0.0.1:50000"}
///
/// selects them; and the parallel positioner's `pi-hexapod` (drivers/pi_hexapod.h), selected by
/// `parallel_positioner: {driver: pi-hexapod, connection: "HOST:PORT"}`. Idempotent and thread-safe; the
/// `microcobot` program calls it at start-up (apps/microcobot/vendor_drivers.cc), a test or another program
/// calls it before building a platform.

namespace mc::drivers {

void register_vendor_drivers();

}  // namespace mc::drivers
