#include "microcobot/dsp/zpk.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "microcobot/core/error.h"

namespace mc::dsp {

using C = std::complex<double>;

namespace {

using CVec = std::vector<C>;

bool is_real(const C& c) { return c.imag() == 0.0; }

// scipy's _cplxreal: one of each conjugate pair (positive imaginary part, averaged with the
// conjugate of its partner) followed by the real roots, both sorted by real part.
CVec cplxreal(CVec z) {
  if (z.empty()) return z;
  const double tol = 100 * std::numeric_limits<double>::epsilon();
  std::stable_sort(z.begin(), z.end(), [](const C& a, const C& b) {
    if (a.real() != b.real()) return a.real() < b.real();
    return std::abs(a.imag()) < std::abs(b.imag());
  });
  CVec reals, zp, zn;
  for (const C& c : z) {
    if (std::abs(c.imag()) <= tol * std::abs(c)) {
      reals.emplace_back(c.real(), 0.0);
    } else if (c.imag() > 0) {
      zp.push_back(c);
    } else {
      zn.push_back(c);
    }
  }
  if (zp.size() != zn.size()) throw InvalidParams("zpk", "complex root without its conjugate");
  // Runs of equal real part are sorted by |imag| (scipy does the same).
  auto sort_runs = [&](CVec& v) {
    std::size_t start = 0;
    while (start < v.size()) {
      std::size_t stop = start + 1;
      while (stop < v.size() && v[stop].real() - v[stop - 1].real() <= tol * std::abs(v[stop - 1])) ++stop;
      std::stable_sort(v.begin() + static_cast<std::ptrdiff_t>(start),
                       v.begin() + static_cast<std::ptrdiff_t>(stop),
                       [](const C& a, const C& b) { return std::abs(a.imag()) < std::abs(b.imag()); });
      start = stop;
    }
  };
  sort_runs(zp);
  sort_runs(zn);
  CVec out;
  for (std::size_t i = 0; i < zp.size(); ++i) {
    if (std::abs(zp[i] - std::conj(zn[i])) > tol * std::abs(zn[i])) {
      throw InvalidParams("zpk", "complex root without its conjugate");
    }
    out.push_back((zp[i] + std::conj(zn[i])) / 2.0);
  }
  out.insert(out.end(), reals.begin(), reals.end());
  return out;
}

std::size_t idx_worst(const CVec& p) {
  std::size_t best = 0;
  double best_v = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double v = std::abs(1.0 - std::abs(p[i]));
    if (v < best_v) {
      best_v = v;
      best = i;
    }
  }
  return best;
}

enum class Which { kReal, kComplex, kAny };

// scipy's _nearest_real_complex_idx: the nearest element of the wanted kind (stable argsort).
std::size_t nearest_idx(const CVec& from, const C& to, Which which) {
  std::vector<std::size_t> order(from.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return std::abs(from[a] - to) < std::abs(from[b] - to);
  });
  for (std::size_t i : order) {
    if (which == Which::kAny || (which == Which::kReal) == is_real(from[i])) return i;
  }
  throw InvalidParams("zpk", "cannot pair roots into sections");
}

C take(CVec& v, std::size_t i) {
  const C c = v[i];
  v.erase(v.begin() + static_cast<std::ptrdiff_t>(i));
  return c;
}

Biquad single_section(const CVec& z, const CVec& p) {
  // Coefficients right-aligned in the 3-wide rows as scipy's _single_zpksos.
  const auto b = poly_from_roots(z);
  const auto a = poly_from_roots(p);
  std::array<double, 6> row{0, 0, 0, 0, 0, 0};
  for (std::size_t i = 0; i < b.size(); ++i) row[3 - b.size() + i] = b[i];
  for (std::size_t i = 0; i < a.size(); ++i) row[6 - a.size() + i] = a[i];
  return Biquad::from_row(row);
}

}  // namespace

std::vector<double> poly_from_roots(const std::vector<std::complex<double>>& roots) {
  CVec c{C(1.0, 0.0)};
  for (const C& r : roots) {
    CVec next(c.size() + 1, C(0.0, 0.0));
    for (std::size_t i = 0; i < c.size(); ++i) {
      next[i] += c[i];
      next[i + 1] -= c[i] * r;
    }
    c = std::move(next);
  }
  std::vector<double> out(c.size());
  for (std::size_t i = 0; i < c.size(); ++i) out[i] = c[i].real();
  return out;
}

Zpk bilinear_zpk(const Zpk& analog, double fs) {
  require_positive(fs, "fs_Hz");
  const double fs2 = 2.0 * fs;
  Zpk d;
  C num(1.0, 0.0), den(1.0, 0.0);
  for (const C& z : analog.z) {
    d.z.push_back((fs2 + z) / (fs2 - z));
    num *= fs2 - z;
  }
  for (const C& p : analog.p) {
    d.p.push_back((fs2 + p) / (fs2 - p));
    den *= fs2 - p;
  }
  for (std::size_t i = analog.z.size(); i < analog.p.size(); ++i) d.z.emplace_back(-1.0, 0.0);
  d.k = analog.k * (num / den).real();
  return d;
}

Sos zpk2sos(const Zpk& zpk) {
  CVec z = zpk.z, p = zpk.p;
  if (z.empty() && p.empty()) return {Biquad{zpk.k, 0, 0, 0, 0}};
  while (p.size() < z.size()) p.emplace_back(0.0, 0.0);
  while (z.size() < p.size()) z.emplace_back(0.0, 0.0);
  const std::size_t n_sections = (p.size() + 1) / 2;
  if (p.size() % 2 == 1) {
    p.emplace_back(0.0, 0.0);
    z.emplace_back(0.0, 0.0);
  }
  z = cplxreal(z);
  p = cplxreal(p);
  auto count_real = [](const CVec& v) {
    return static_cast<std::size_t>(std::count_if(v.begin(), v.end(), is_real));
  };
  Sos sos(n_sections);
  for (std::size_t si = n_sections; si-- > 0;) {
    const C p1 = take(p, idx_worst(p));
    if (is_real(p1) && count_real(p) == 0) {
      // Last remaining real pole: pair with the nearest real zero.
      const C z1 = take(z, nearest_idx(z, p1, Which::kReal));
      sos[si] = single_section({z1, C(0, 0)}, {p1, C(0, 0)});
    } else if (p.size() + 1 == z.size() && !is_real(p1) && count_real(p) == 1 && count_real(z) == 1) {
      // One real pole and one real zero left: pair this complex pole with a complex zero.
      const C z1 = take(z, nearest_idx(z, p1, Which::kComplex));
      sos[si] = single_section({z1, std::conj(z1)}, {p1, std::conj(p1)});
    } else {
      C p2;
      if (is_real(p1)) {
        CVec reals;
        std::vector<std::size_t> where;
        for (std::size_t i = 0; i < p.size(); ++i) {
          if (is_real(p[i])) {
            reals.push_back(p[i]);
            where.push_back(i);
          }
        }
        p2 = take(p, where[idx_worst(reals)]);
      } else {
        p2 = std::conj(p1);
      }
      if (!z.empty()) {
        const C z1 = take(z, nearest_idx(z, p1, Which::kAny));
        if (!is_real(z1)) {
          sos[si] = single_section({z1, std::conj(z1)}, {p1, p2});
        } else if (!z.empty()) {
          const C z2 = take(z, nearest_idx(z, p1, Which::kReal));
          sos[si] = single_section({z1, z2}, {p1, p2});
        } else {
          sos[si] = single_section({z1}, {p1, p2});
        }
      } else {
        sos[si] = single_section({}, {p1, p2});
      }
    }
  }
  sos[0].b0 *= zpk.k;
  sos[0].b1 *= zpk.k;
  sos[0].b2 *= zpk.k;
  return sos;
}

}  // namespace mc::dsp
