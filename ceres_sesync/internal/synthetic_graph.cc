#include "ceres_sesync/internal/synthetic_graph.h"

#include <cmath>
#include <utility>

#include "Eigen/Geometry"
#include "ceres_sesync/langevin.h"

namespace ceres_sesync::internal {

Eigen::MatrixXd HeadingRotation(int d, const Eigen::Vector3d& forward) {
  if (d == 2) {
    Eigen::MatrixXd R(2, 2);
    R << forward.x(), -forward.y(), forward.y(), forward.x();
    return R;
  }
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d left = std::abs(forward.z()) > 0.5
                                   ? Eigen::Vector3d::UnitY().eval()
                                   : up.cross(forward).eval();
  Eigen::MatrixXd R(3, 3);
  R.col(0) = forward;
  R.col(1) = left;
  R.col(2) = forward.cross(left);
  return R;
}

bool CheckNoiseOptions(double loop_closure_probability, double kappa,
                       double tau, double spacing, std::string* error) {
  auto fail = [&](const char* message) {
    if (error) *error = message;
    return false;
  };
  if (!(loop_closure_probability >= 0 && loop_closure_probability <= 1)) {
    return fail("loop closure probability must be in [0, 1]");
  }
  if (!(kappa > 0 && std::isfinite(kappa))) {
    return fail("kappa must be finite and positive");
  }
  if (!(tau > 0 && std::isfinite(tau))) {
    return fail("tau must be finite and positive");
  }
  if (!(spacing > 0 && std::isfinite(spacing))) {
    return fail("spacing must be finite and positive");
  }
  return true;
}

void AddNoisyMeasurement(const Poses& truth, int i, int j, double kappa,
                         double tau, std::mt19937_64* rng, PoseGraph* graph) {
  const int d = graph->dimension;
  RelativePoseMeasurement e;
  e.i = i;
  e.j = j;
  e.kappa = kappa;
  e.tau = tau;
  e.R = truth[i].R.transpose() * truth[j].R *
        SampleIsotropicLangevin(d, kappa, rng);
  e.t = truth[i].R.transpose() * (truth[j].t - truth[i].t);
  const double sigma = 1 / std::sqrt(tau);
  for (int k = 0; k < d; ++k) e.t[k] += sigma * SampleStandardNormal(rng);
  graph->measurements.push_back(std::move(e));
}

}  // namespace ceres_sesync::internal
