#pragma once
// What the cell's tests share.

#include "microcobot/platform/platform_config.h"

namespace mc::cell::test {

/// The default platform (named: GCC 12 sees its temporaries' members as maybe uninitialised).
inline const platform::PlatformConfig& default_platform() {
  static const platform::PlatformConfig c;
  return c;
}

}  // namespace mc::cell::test
