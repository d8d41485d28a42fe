#pragma once
/// @file
/// The live console (web/console.html and the scripts and styles it names, embedded at build
/// time) as one self-contained page with uPlot inlined: it opens offline, from the binary alone.

#include <string>

namespace mc::live {

/// The console's HTML page, scripts and styles inlined.
std::string console_page();

}  // namespace mc::live
