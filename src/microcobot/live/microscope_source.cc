#include "microcobot/live/microscope_source.h"

namespace mc::live {

void apply_microscope(platform::Platform& p, const ConsoleCommand& c) noexcept {
  // Every command's microscope part counts (a later command without it changes nothing).
  devices::FocusDrive* focus = p.focus();
  if (focus == nullptr) return;
  if (c.has_focus) focus->command_z_m(c.focus_z_m);
  if (c.objective >= 0) focus->command_objective(c.objective);
  if (c.exposure_s > 0.0) p.camera()->set_exposure_s(c.exposure_s);
  if (c.gain > 0.0) p.camera()->set_gain(c.gain);
}

SourceRequest MicroscopeSource::poll(const SourceTick& t) noexcept {
  ConsoleCommand c;
  while (ring_.pop(c)) apply_microscope(t.platform, c);
  return {};
}

}  // namespace mc::live
