#pragma once
// Reads the scipy reference vectors of tests/data (made by tests/data/gen_reference.py).
#include <complex>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace mc::test {

inline nlohmann::json load_reference(const std::string& name) {
  std::ifstream in(std::string(MC_TEST_DATA_DIR) + "/" + name);
  if (!in) throw std::runtime_error("missing reference file " + name + " (run tests/data/gen_reference.py)");
  return nlohmann::json::parse(in);
}

inline std::vector<std::complex<double>> complex_vector(const nlohmann::json& j) {
  const auto re = j.at("re").get<std::vector<double>>();
  const auto im = j.at("im").get<std::vector<double>>();
  std::vector<std::complex<double>> out(re.size());
  for (std::size_t i = 0; i < re.size(); ++i) out[i] = {re[i], im[i]};
  return out;
}

}  // namespace mc::test
