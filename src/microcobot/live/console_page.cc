#include "microcobot/live/console_page.h"

#include <string_view>

#include "microcobot/report/assets.h"

namespace mc::live {
namespace assets {
extern const unsigned char kConsoleHtml[];
extern const unsigned char kConsoleJs[];
extern const unsigned char kConsoleCss[];
}  // namespace assets

namespace {
std::string_view text(const unsigned char* bytes) { return reinterpret_cast<const char*>(bytes); }

void replace(std::string& page, std::string_view marker, std::string_view with) {
  const auto at = page.find(marker);
  if (at != std::string::npos) page.replace(at, marker.size(), with);
}
}  // namespace

std::string console_page() {
  std::string page(text(assets::kConsoleHtml));
  // Inlined scripts must not close their own <script> element early.
  replace(page, "/*UPLOT_CSS*/", text(report::assets::kUplotCss));
  replace(page, "/*CONSOLE_CSS*/", text(assets::kConsoleCss));
  replace(page, "/*UPLOT_JS*/", text(report::assets::kUplotJs));
  replace(page, "/*CONSOLE_JS*/", text(assets::kConsoleJs));
  return page;
}

}  // namespace mc::live
