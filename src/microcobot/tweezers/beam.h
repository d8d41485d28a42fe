#pragma once
/// @file
/// The natural frequencies of a uniform square beam clamped at both ends as the thesis writes
/// them (eq. 3.2, Table 3.1): the physical limit of passing vibrations through a deported handle.

#include <optional>
#include <string>
#include <vector>

namespace mc::tweezers {

/// A material of Table 3.1 (Young's modulus and density from the Cambridge Materials Data Book).
struct Material {
  std::string name;
  double young_Pa;
  double density_kg_m3;
};

/// The four materials of Table 3.1.
const std::vector<Material>& beam_materials();
/// Looks a material up by name (case-insensitive; spaces, '-' and '_' ignored), e.g.
/// "stainless-steel", "carbon_fiber". Returns nullopt when unknown.
std::optional<Material> find_material(const std::string& name);

/// Eq. 3.2: omega_n = (n pi / L)^2 sqrt(E I / (rho A)) for a square section of side s
/// (I = s^4 / 12, A = s^2); returns f_n = omega_n / 2 pi in Hz. The thesis's 20 cm, 5 x 5 mm^2
/// beam gives Table 3.1 (276, 286, 288, 611 Hz).
double beam_natural_frequency(double young_Pa, double density_kg_m3, double length_m, double side_m,
                              int mode = 1);

}  // namespace mc::tweezers
