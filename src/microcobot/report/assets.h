#pragma once
/// @file
/// Files embedded into the binary at build time (cmake/embed_assets.cmake): uPlot (pinned by
/// package-lock.json) and the report page's own script and style (web/). NUL-terminated.

namespace mc::report::assets {
extern const unsigned char kUplotJs[];
extern const unsigned char kUplotCss[];
extern const unsigned char kReportJs[];
extern const unsigned char kReportCss[];
}  // namespace mc::report::assets
