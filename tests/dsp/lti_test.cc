#include "microcobot/dsp/lti.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "microcobot/core/error.h"
#include "reference.h"

namespace mc::dsp {
namespace {

Eigen::MatrixXd matrix(const nlohmann::json& j) {
  Eigen::MatrixXd m(static_cast<Eigen::Index>(j.size()), static_cast<Eigen::Index>(j.at(0).size()));
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    for (Eigen::Index k = 0; k < m.cols(); ++k)
      m(i, k) = j.at(static_cast<std::size_t>(i)).at(static_cast<std::size_t>(k));
  }
  return m;
}

void expect_matrix_near(const Eigen::MatrixXd& got, const Eigen::MatrixXd& want, double rel,
                        const std::string& what) {
  ASSERT_EQ(got.rows(), want.rows()) << what;
  ASSERT_EQ(got.cols(), want.cols()) << what;
  for (Eigen::Index i = 0; i < got.rows(); ++i) {
    for (Eigen::Index k = 0; k < got.cols(); ++k) {
      // Relative to the entry, or to its row's largest entry for entries that cancel to ~0.
      const double scale = std::max(std::abs(want(i, k)), 1e-6 * want.row(i).cwiseAbs().maxCoeff());
      EXPECT_NEAR(got(i, k), want(i, k), rel * scale) << what << " (" << i << "," << k << ")";
    }
  }
}

void expect_vector_near(const std::vector<double>& got, const std::vector<double>& want, double tol,
                        const std::string& what) {
  ASSERT_EQ(got.size(), want.size());
  double scale = 0;
  for (double v : want) scale = std::max(scale, std::abs(v));
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_NEAR(got[i], want[i], tol * scale) << what << " " << i;
}

const TransferFunction kEq36({250.0, 6.406e5}, {1.0, 2135.0, 4.559e6});  // thesis eq. 3.6

TEST(Lti, C2dMatchesScipy) {
  const auto ref = mc::test::load_reference("dsp_lti.json");
  const StateSpace ss{matrix(ref.at("A")), matrix(ref.at("B")), matrix(ref.at("C")), matrix(ref.at("D")),
                      0.0};
  for (const auto& c : ref.at("c2d")) {
    const double dt = c.at("dt");
    const auto d = c.at("method") == "zoh" ? c2d_zoh(ss, dt) : c2d_tustin(ss, dt);
    const std::string what = c.at("method").get<std::string>() + " dt " + std::to_string(dt);
    expect_matrix_near(d.A, matrix(c.at("Ad")), 1e-10, what + " A");
    expect_matrix_near(d.B, matrix(c.at("Bd")), 1e-10, what + " B");
    expect_matrix_near(d.C, matrix(c.at("Cd")), 1e-10, what + " C");
    expect_matrix_near(d.D, matrix(c.at("Dd")), 1e-10, what + " D");
    EXPECT_EQ(d.dt, dt);
  }
}

TEST(Lti, LsimStepImpulseMatchScipy) {
  const auto ref = mc::test::load_reference("dsp_lti.json");
  const TransferFunction tf(ref.at("num").get<std::vector<double>>(),
                            ref.at("den").get<std::vector<double>>());
  const auto t = ref.at("t").get<std::vector<double>>();
  const auto u = ref.at("u").get<std::vector<double>>();
  expect_vector_near(lsim(tf, u, t, true), ref.at("y_interp").get<std::vector<double>>(), 1e-8, "interp");
  expect_vector_near(lsim(tf, u, t, false), ref.at("y_hold").get<std::vector<double>>(), 1e-8, "hold");
  expect_vector_near(step(tf, t), ref.at("y_step").get<std::vector<double>>(), 1e-8, "step");
  expect_vector_near(impulse(tf, t), ref.at("y_impulse").get<std::vector<double>>(), 1e-8, "impulse");
  const auto ss = tf2ss(tf);
  const auto& r = ref.at("tf2ss");
  expect_matrix_near(ss.A, matrix(r.at("A")), 1e-14, "tf2ss A");
  expect_matrix_near(ss.C, matrix(r.at("C")), 1e-14, "tf2ss C");
  const auto w = ref.at("w").get<std::vector<double>>();
  const auto h = freqresp(tf, w);
  const auto want = mc::test::complex_vector(ref.at("h"));
  for (std::size_t i = 0; i < w.size(); ++i) EXPECT_LT(std::abs(h[i] - want[i]), 1e-12 * std::abs(want[i]));
}

TEST(Lti, PolesZerosDcGainStability) {
  const auto p = kEq36.poles();
  ASSERT_EQ(p.size(), 2u);
  for (const auto& s : p) EXPECT_LT(std::abs(s * s + 2135.0 * s + 4.559e6), 1e-6 * 4.559e6);
  ASSERT_EQ(kEq36.zeros().size(), 1u);
  EXPECT_NEAR(kEq36.zeros()[0].real(), -6.406e5 / 250.0, 1e-9);
  EXPECT_NEAR(kEq36.dc_gain(), 6.406e5 / 4.559e6, 1e-15);
  EXPECT_TRUE(kEq36.is_stable());
  EXPECT_FALSE(TransferFunction({1.0}, {1.0, -1.0, 4.0}).is_stable());
  EXPECT_TRUE(std::isinf(TransferFunction({1.0}, {1.0, 0.0}).dc_gain()));
  EXPECT_THROW(TransferFunction({1.0, 0.0, 0.0}, {1.0, 1.0}), InvalidParams);
  EXPECT_THROW(TransferFunction({1.0}, {0.0}), InvalidParams);
}

TEST(Lti, SsTfRoundTripAndResponsesAgree) {
  const auto ss = tf2ss(kEq36);
  const auto back = ss2tf(ss);
  ASSERT_EQ(back.num().size(), 2u);  // the s^2 term cancels exactly and is stripped
  EXPECT_NEAR(back.num()[0], 250.0, 1e-9 * 250.0);
  EXPECT_NEAR(back.num()[1], 6.406e5, 1e-9 * 6.406e5);
  EXPECT_NEAR(back.den()[1], 2135.0, 1e-9 * 2135.0);
  EXPECT_NEAR(back.den()[2], 4.559e6, 1e-9 * 4.559e6);
  for (double w : {1.0, 100.0, 2135.0, 1e4, 1e6}) {
    EXPECT_LT(std::abs(ss.response(w) - kEq36.response(w)), 1e-12 * std::abs(kEq36.response(w)));
  }
}

TEST(Lti, DiscretisationsPreserveWhatTheyPromise) {
  const double dt = 1e-4;
  // ZOH: poles map exactly by exp(s dt), DC gain preserved; d2c inverts it.
  const auto zoh = c2d(kEq36, dt, Discretization::kZoh);
  EXPECT_NEAR(zoh.dc_gain(), kEq36.dc_gain(), 1e-12);
  for (const auto& s : kEq36.poles()) {
    double best = 1e9;
    for (const auto& z : zoh.poles()) best = std::min(best, std::abs(z - std::exp(s * dt)));
    EXPECT_LT(best, 1e-12);
  }
  const auto back = ss2tf(d2c_zoh(c2d_zoh(tf2ss(kEq36), dt))).normalized();
  EXPECT_NEAR(back.den()[1], 2135.0, 1e-7 * 2135.0);
  EXPECT_NEAR(back.den()[2], 4.559e6, 1e-7 * 4.559e6);
  EXPECT_NEAR(back.num().back(), 6.406e5, 1e-7 * 6.406e5);
  // Tustin with prewarp: exact at the prewarp frequency.
  const double w0 = 2 * std::numbers::pi * 1500.0;
  const auto tus = c2d(kEq36, dt, Discretization::kTustin, w0);
  EXPECT_LT(std::abs(tus.response(w0) - kEq36.response(w0)), 1e-12 * std::abs(kEq36.response(w0)));
  const auto plain = c2d(kEq36, dt, Discretization::kTustin);
  EXPECT_GT(std::abs(plain.response(w0) - kEq36.response(w0)), 1e-4 * std::abs(kEq36.response(w0)));
  // Matched: poles and finite zeros by exp(s dt), DC gain equal.
  const auto mat = c2d(kEq36, dt, Discretization::kMatched);
  EXPECT_NEAR(mat.dc_gain(), kEq36.dc_gain(), 1e-12);
  const auto zz = mat.zeros();
  ASSERT_EQ(zz.size(), 2u);
  bool has_minus_one = false, has_mapped = false;
  for (const auto& z : zz) {
    has_minus_one = has_minus_one || std::abs(z + 1.0) < 1e-9;
    has_mapped = has_mapped || std::abs(z - std::exp(-6.406e5 / 250.0 * dt)) < 1e-9;
  }
  EXPECT_TRUE(has_minus_one && has_mapped);
  // An integrator: the gain is matched at 0.01 Nyquist instead.
  const TransferFunction integ({10.0}, {1.0, 0.0});
  const auto mi = c2d_matched(integ, dt);
  const double wm = 0.01 * std::numbers::pi / dt;
  EXPECT_NEAR(std::abs(mi.response(wm)), std::abs(integ.response(wm)), 1e-9 * std::abs(integ.response(wm)));
}

TEST(Lti, DiscreteLsimAndDivergenceIsReported) {
  // y[k+1] = 0.5 y[k] + u[k]: step response 2 (1 - 0.5^k).
  const TransferFunction d({1.0}, {1.0, -0.5}, 0.1);
  std::vector<double> t(20), u(20, 1.0);
  for (std::size_t k = 0; k < t.size(); ++k) t[k] = 0.1 * static_cast<double>(k);
  const auto y = lsim(d, u, t);
  for (std::size_t k = 0; k < y.size(); ++k)
    EXPECT_NEAR(y[k], 2.0 * (1.0 - std::pow(0.5, static_cast<double>(k))), 1e-12);
  const TransferFunction unstable({1.0}, {1.0, -1e200}, 0.1);
  EXPECT_THROW(lsim(unstable, u, t), ComputationFailed);
  std::vector<double> bad_t{0.0, 0.1, 0.3};
  std::vector<double> u3(3, 1.0);
  EXPECT_THROW(lsim(kEq36, u3, bad_t), InvalidParams);
}

}  // namespace
}  // namespace mc::dsp
