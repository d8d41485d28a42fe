#include "microcobot/tweezers/beam.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>

#include "microcobot/core/error.h"

namespace mc::tweezers {

const std::vector<Material>& beam_materials() {
  static const std::vector<Material> kMaterials = {
      {"cast iron", 170e9, 7150.0},
      {"stainless steel", 200e9, 7850.0},
      {"aluminum 7075-T6", 70e9, 2700.0},
      {"carbon fiber", 200e9, 1720.0},
  };
  return kMaterials;
}

namespace {
std::string key(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (std::isalnum(static_cast<unsigned char>(c)))
      out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return out;
}
}  // namespace

std::optional<Material> find_material(const std::string& name) {
  const std::string k = key(name);
  for (const auto& m : beam_materials()) {
    const std::string mk = key(m.name);
    // Accept the full name or its first word(s) ("aluminum" for "aluminum 7075-T6").
    if (mk == k || (!k.empty() && mk.rfind(k, 0) == 0)) return m;
  }
  return std::nullopt;
}

double beam_natural_frequency(double young_Pa, double density_kg_m3, double length_m, double side_m,
                              int mode) {
  require_positive(young_Pa, "young_Pa");
  require_positive(density_kg_m3, "density_kg_m3");
  require_positive(length_m, "length_m");
  require_positive(side_m, "side_m");
  require(mode >= 1, "mode", "must be >= 1", mode);
  const double i_over_a = side_m * side_m / 12.0;  // (s^4/12) / s^2
  const double k = mode * std::numbers::pi / length_m;
  const double omega = k * k * std::sqrt(young_Pa * i_over_a / density_kg_m3);
  return omega / (2.0 * std::numbers::pi);
}

}  // namespace mc::tweezers
