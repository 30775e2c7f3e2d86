// Synthetic candidate histories for the placement tests: no FEM yet, so temperatures are
// mixtures of a few smooth responses to SB-1's duty cycle, with mirror-symmetric weights.
#pragma once

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "core/ids.hpp"
#include "placement/place.hpp"

namespace tt::placement::synthetic {

/// Standard normal draws from a seeded generator (Box-Muller; portable across libraries).
class Normal {
 public:
  explicit Normal(std::uint64_t seed) : gen_(seed) {}
  double operator()() {
    const double u1 = (static_cast<double>(gen_() >> 11) + 0.5) * 0x1.0p-53;
    const double u2 = static_cast<double>(gen_() >> 11) * 0x1.0p-53;
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }
  Eigen::VectorXd vector(Eigen::Index n) {
    Eigen::VectorXd v(n);
    for (Eigen::Index i = 0; i < n; ++i) v(i) = (*this)();
    return v;
  }

 private:
  std::mt19937_64 gen_;
};

/// SB-1's candidate positions C-54 [m], ids 1..54 (top, left, right; z, then transverse).
inline Eigen::MatrixX3d c54_positions() {
  Eigen::MatrixX3d p(54, 3);
  const double zs[6] = {0.04, 0.12, 0.20, 0.28, 0.36, 0.44};
  const double xs[3] = {-0.08, 0.0, 0.08};
  const double ys[3] = {0.08, 0.16, 0.24};
  int i = 0;
  for (double z : zs)
    for (double x : xs) p.row(i++) << x, 0.30, z;
  for (double side : {-0.16, 0.16})
    for (double z : zs)
      for (double y : ys) p.row(i++) << side, y, z;
  return p;
}

/// Heat input of duty cycle P-1: 1 while the spindle runs.
inline double running(double t) {
  return (t < 600.0 || (t >= 900.0 && t < 2100.0) || t >= 2400.0) ? 1.0 : 0.0;
}

/// #times x 3 first-order responses to the duty cycle with time constants 400, 1500, 5000 s.
inline Eigen::MatrixXd responses(const Eigen::VectorXd& t) {
  const double tau[3] = {400.0, 1500.0, 5000.0};
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(t.size(), 3);
  for (Eigen::Index k = 1; k < t.size(); ++k)
    for (int a = 0; a < 3; ++a) {
      const double dt = t(k) - t(k - 1);
      const double decay = std::exp(-dt / tau[a]);
      r(k, a) = r(k - 1, a) * decay + running(t(k - 1)) * (1.0 - decay);
    }
  return r;
}

/// A C-54 problem on SB-1's 2 h: histories mirror-symmetric in x up to noise_K, dy and dz built
/// from the histories of a few candidates (so a good answer exists).
inline PlacementInput c54_input(double noise_K, std::uint64_t seed) {
  PlacementInput in;
  const int n = 54;
  for (int i = 1; i <= n; ++i) in.ids.push_back(static_cast<core::SensorId>(i));
  in.positions_m = c54_positions();
  in.times_s = Eigen::VectorXd::LinSpaced(201, 0.0, 7200.0);
  const Eigen::MatrixXd r = responses(in.times_s);
  Normal normal(seed);
  in.temperatures_K.resize(in.times_s.size(), n);
  for (int i = 0; i < n; ++i) {
    const Eigen::RowVector3d p = in.positions_m.row(i);
    // Weights depend on |x| only, so mirror twins share them.
    const double front = std::exp(-std::pow((p(2) - 0.425) / 0.12, 2));
    const double rear = std::exp(-std::pow((p(2) - 0.065) / 0.12, 2));
    const double lift = 0.5 + p(1) + 0.5 * std::abs(p(0));
    in.temperatures_K.col(i) = 293.15 + (8.0 * front * lift) * r.col(0).array() +
                               (5.0 * rear * lift) * r.col(1).array() +
                               (3.0 + 2.0 * p(2)) * r.col(2).array();
  }
  for (Eigen::Index k = 1; k < in.temperatures_K.rows(); ++k)
    for (int i = 0; i < n; ++i) in.temperatures_K(k, i) += noise_K * normal();
  const Eigen::VectorXd dy = 1e-6 * (2.0 * r.col(0) + 3.0 * r.col(1) - 4.0 * r.col(2));
  const Eigen::VectorXd dz = 1e-6 * (6.0 * r.col(0) + 1.0 * r.col(1) + 9.0 * r.col(2));
  in.targets.push_back({"dy", dy});
  in.targets.push_back({"dz", dz});
  return in;
}

/// The physics observer's view of c54_input's machine, for placement for estimation: the three
/// responses as the filter's states, each a first-order lag of its time constant driven by an
/// unknown heat input (white, variance 1 - a^2 per reading, a = exp(-dt/tau)); a candidate reads
/// its weights on them (as c54_input mixes them) with `sigma_K`; dy and dz are c54_input's rows.
/// One run of `readings` readings every 360 s from a known start.
inline EstimationProblem c54_estimation(const PlacementInput& in, double sigma_K, int readings) {
  EstimationProblem p;
  const double tau[3] = {400.0, 1500.0, 5000.0}, dt = 360.0;
  Eigen::Matrix3d f = Eigen::Matrix3d::Zero(), q = Eigen::Matrix3d::Zero();
  for (int a = 0; a < 3; ++a) {
    f(a, a) = std::exp(-dt / tau[a]);
    q(a, a) = 1.0 - f(a, a) * f(a, a);
  }
  CovarianceTrack track;
  track.initial = Eigen::Matrix3d::Zero();
  track.transitions.assign(static_cast<std::size_t>(readings), f);
  track.process.assign(static_cast<std::size_t>(readings), q);
  p.tracks.push_back(track);
  const auto n = static_cast<Eigen::Index>(in.ids.size());
  p.candidate_rows.resize(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::RowVector3d x = in.positions_m.row(i);
    const double front = std::exp(-std::pow((x(2) - 0.425) / 0.12, 2));
    const double rear = std::exp(-std::pow((x(2) - 0.065) / 0.12, 2));
    const double lift = 0.5 + x(1) + 0.5 * std::abs(x(0));
    p.candidate_rows.row(i) << 8.0 * front * lift, 5.0 * rear * lift, 3.0 + 2.0 * x(2);
  }
  p.candidate_sigma = Eigen::VectorXd::Constant(n, sigma_K);
  p.target_rows.resize(2, 3);
  p.target_rows << 2e-6, 3e-6, -4e-6, 6e-6, 1e-6, 9e-6;
  return p;
}

}  // namespace tt::placement::synthetic
