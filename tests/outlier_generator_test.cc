// The outlier generator (outlier_generator.h): counts, layout, precisions,
// the consistency of clustered outliers, determinism and errors.

#include "ceres_sesync/outlier_generator.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "ceres_sesync/landmark_generator.h"
#include "ceres_sesync/robust_solver.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/util/test_graphs.h"

namespace ceres_sesync {
namespace {

PoseGraph Graph(int d, bool noiseless, Poses* truth) {
  test_util::RandomGraphOptions o;
  o.dimension = d;
  o.num_poses = 60;
  o.num_loop_closures = 25;
  o.chain = true;
  o.noiseless = noiseless;
  o.seed = 17;
  PoseGraph graph = test_util::RandomPoseGraph(o, truth);
  // Distinct precisions so that the medians mean something.
  for (size_t k = 0; k < graph.measurements.size(); ++k) {
    graph.measurements[k].kappa = 10 + k;
    graph.measurements[k].tau = 100 + 2 * k;
  }
  return graph;
}

int LoopClosures(const PoseGraph& graph) {
  int count = 0;
  for (const RelativePoseMeasurement& e : graph.measurements) {
    count += !IsOdometry(e);
  }
  return count;
}

TEST(OutlierGenerator, CountsLayoutAndPrecisions) {
  for (int d : {2, 3}) {
    const PoseGraph graph = Graph(d, false, nullptr);
    const int m = static_cast<int>(graph.measurements.size());
    const int loops = LoopClosures(graph);
    std::vector<double> kappas, taus;
    double rho = 0;
    for (const RelativePoseMeasurement& e : graph.measurements) {
      if (IsOdometry(e)) continue;
      kappas.push_back(e.kappa);
      taus.push_back(e.tau);
      rho = std::max(rho, e.t.norm());
    }
    auto median = [](std::vector<double> v) {
      std::sort(v.begin(), v.end());
      const size_t h = v.size() / 2;
      return v.size() % 2 ? v[h] : 0.5 * (v[h - 1] + v[h]);
    };
    const double kappa = median(kappas), tau = median(taus);
    for (auto mode :
         {OutlierOptions::Mode::kRandom, OutlierOptions::Mode::kClustered}) {
      for (double fraction : {0.0, 0.1, 0.5, 0.9}) {
        OutlierOptions o;
        o.mode = mode;
        o.fraction = fraction;
        o.cluster_size = 4;
        PoseGraph out;
        std::vector<int> added;
        std::string error;
        ASSERT_TRUE(AddOutliers(graph, o, &out, &added, &error)) << error;
        const int k =
            static_cast<int>(std::lround(fraction * loops / (1 - fraction)));
        ASSERT_EQ(static_cast<int>(added.size()), k);
        ASSERT_EQ(static_cast<int>(out.measurements.size()), m + k);
        // The output's loop closures are the fraction F wrong.
        EXPECT_NEAR(static_cast<double>(k) / (k + loops), fraction,
                    0.5 / (k + loops) + 1e-12);
        for (int q = 0; q < k; ++q) EXPECT_EQ(added[q], m + q);
        for (int q = 0; q < m; ++q) {
          const RelativePoseMeasurement& a = graph.measurements[q];
          const RelativePoseMeasurement& b = out.measurements[q];
          EXPECT_TRUE(a.i == b.i && a.j == b.j && a.R == b.R && a.t == b.t &&
                      a.kappa == b.kappa && a.tau == b.tau);
        }
        for (int index : added) {
          const RelativePoseMeasurement& e = out.measurements[index];
          EXPECT_FALSE(IsOdometry(e));
          EXPECT_NE(e.i, e.j);
          EXPECT_EQ(e.kappa, kappa);
          EXPECT_EQ(e.tau, tau);
          if (mode == OutlierOptions::Mode::kRandom) {
            EXPECT_LE(e.t.norm(), rho * (1 + 1e-12));
          }
        }
        EXPECT_TRUE(ValidatePoseGraph(out, &error)) << error;
        EXPECT_EQ(out.num_poses, graph.num_poses);
        EXPECT_EQ(out.vertex_ids, graph.vertex_ids);
      }
    }
  }
}

// Each group of clustered outliers agrees on one wrong placement G of the
// segment around b: z_(a+s, b+s) = X_(a+s)^-1 G X_(b+s) for every s, with X
// the reference trajectory (here the exact initial poses), and G is not the
// truth's (the identity).
TEST(OutlierGenerator, ClustersAreMutuallyConsistentAndWrong) {
  for (int d : {2, 3}) {
    Poses truth;
    PoseGraph graph = Graph(d, true, &truth);
    graph.initial_poses = truth;
    OutlierOptions o;
    o.mode = OutlierOptions::Mode::kClustered;
    o.fraction = 0.6;
    o.cluster_size = 5;
    PoseGraph out;
    std::vector<int> added;
    ASSERT_TRUE(AddOutliers(graph, o, &out, &added, nullptr));
    ASSERT_GE(added.size(), 10u);
    auto placement = [&](int index, Eigen::MatrixXd* R, Eigen::VectorXd* t) {
      const RelativePoseMeasurement& e = out.measurements[index];
      const Pose& p = truth[e.i];
      const Pose& q = truth[e.j];
      // G = X_p z X_q^-1.
      *R = p.R * e.R * q.R.transpose();
      *t = p.R * e.t + p.t - *R * q.t;
    };
    for (size_t start = 0; start < added.size(); start += o.cluster_size) {
      Eigen::MatrixXd R0, R;
      Eigen::VectorXd t0, t;
      placement(added[start], &R0, &t0);
      EXPECT_GT((R0 - Eigen::MatrixXd::Identity(d, d)).norm() + t0.norm(),
                1e-3);
      const RelativePoseMeasurement& first = out.measurements[added[start]];
      for (size_t s = 1;
           s < static_cast<size_t>(o.cluster_size) && start + s < added.size();
           ++s) {
        const RelativePoseMeasurement& e = out.measurements[added[start + s]];
        EXPECT_EQ(e.i, first.i + static_cast<int>(s));
        EXPECT_EQ(e.j, first.j + static_cast<int>(s));
        placement(added[start + s], &R, &t);
        EXPECT_LT((R - R0).norm(), 1e-9);
        EXPECT_LT((t - t0).norm(), 1e-9 * (1 + t0.norm()));
      }
    }
  }
}

TEST(OutlierGenerator, DeterministicForASeed) {
  const PoseGraph graph = Graph(3, false, nullptr);
  OutlierOptions o;
  o.fraction = 0.5;
  o.seed = 4;
  PoseGraph a, b, c;
  ASSERT_TRUE(AddOutliers(graph, o, &a, nullptr, nullptr));
  ASSERT_TRUE(AddOutliers(graph, o, &b, nullptr, nullptr));
  o.seed = 5;
  ASSERT_TRUE(AddOutliers(graph, o, &c, nullptr, nullptr));
  bool all_equal = true, any_differs = false;
  for (size_t k = graph.measurements.size(); k < a.measurements.size(); ++k) {
    const auto &x = a.measurements[k], &y = b.measurements[k],
               &z = c.measurements[k];
    all_equal =
        all_equal && x.i == y.i && x.j == y.j && x.R == y.R && x.t == y.t;
    any_differs = any_differs || x.i != z.i || x.j != z.j || x.R != z.R;
  }
  EXPECT_TRUE(all_equal);
  EXPECT_TRUE(any_differs);
}

TEST(OutlierGenerator, InvalidRequestsAreRejected) {
  PoseGraph graph = Graph(2, false, nullptr);
  OutlierOptions o;
  PoseGraph out;
  std::string error;
  o.fraction = 1;
  EXPECT_FALSE(AddOutliers(graph, o, &out, nullptr, &error));
  EXPECT_THAT(error, ::testing::HasSubstr("[0, 1)"));
  o.fraction = -0.1;
  EXPECT_FALSE(AddOutliers(graph, o, &out, nullptr, &error));
  o.fraction = 0.3;
  o.mode = OutlierOptions::Mode::kClustered;
  o.cluster_size = 0;
  EXPECT_FALSE(AddOutliers(graph, o, &out, nullptr, &error));
  o.cluster_size = 70;  // More than the poses.
  EXPECT_FALSE(AddOutliers(graph, o, &out, nullptr, &error));
  EXPECT_THAT(error, ::testing::HasSubstr("too few poses"));
  // No loop closures: the fraction has no reference.
  PoseGraph chain = graph;
  chain.measurements.erase(
      std::remove_if(
          chain.measurements.begin(), chain.measurements.end(),
          [](const RelativePoseMeasurement& e) { return !IsOdometry(e); }),
      chain.measurements.end());
  o.cluster_size = 5;
  EXPECT_FALSE(AddOutliers(chain, o, &out, nullptr, &error));
  EXPECT_THAT(error, ::testing::HasSubstr("no loop closures"));
  // Clustered, no initial poses and a broken odometry chain.
  PoseGraph broken = graph;
  broken.initial_poses.clear();
  broken.measurements.erase(
      std::find_if(broken.measurements.begin(), broken.measurements.end(),
                   [](const RelativePoseMeasurement& e) {
                     return std::min(e.i, e.j) == 30 && IsOdometry(e);
                   }));
  ASSERT_TRUE(ValidatePoseGraph(broken, nullptr));
  EXPECT_FALSE(AddOutliers(broken, o, &out, nullptr, &error));
  EXPECT_THAT(error, ::testing::HasSubstr("reference trajectory"));
  o.mode = OutlierOptions::Mode::kRandom;  // Needs none.
  EXPECT_TRUE(AddOutliers(broken, o, &out, nullptr, &error)) << error;
}

// Wrong associations and false fixes: counts, the input first and
// unchanged, each wrong association a copy of a true observation moved to
// another landmark with no pair (l, l') twice, each false fix a position
// prior 10..40 sigma from the truth (the noiseless graph's dead reckoning is
// the truth) with the median position tau; deterministic; errors.
TEST(OutlierGenerator, WrongAssociationsAndFalseFixes) {
  for (int d : {2, 3}) {
    LandmarkGraphOptions o;
    o.dimension = d;
    o.num_poses = 60;
    o.num_landmarks = 80;
    o.world_size = 16;
    o.gps_interval = 3;
    o.start_prior = true;
    o.noiseless = true;
    PoseGraph graph, out;
    Solution truth;
    std::string error;
    ASSERT_TRUE(GenerateLandmarkGraph(o, &graph, &truth, &error)) << error;
    for (size_t q = 0; q < graph.priors.size(); ++q) {
      graph.priors[q].tau = 1 + 2.0 * q;  // Median of the position ones.
    }
    std::vector<double> taus;
    for (const PosePrior& p : graph.priors) {
      if (p.has_position()) taus.push_back(p.tau);
    }
    std::sort(taus.begin(), taus.end());
    const size_t h = taus.size() / 2;
    const double median =
        taus.size() % 2 ? taus[h] : 0.5 * (taus[h - 1] + taus[h]);
    LandmarkOutlierOptions options;
    options.landmark_fraction = 0.3;
    options.prior_fraction = 0.5;
    options.seed = 4;
    std::vector<int> added_l, added_p;
    ASSERT_TRUE(
        AddLandmarkOutliers(graph, options, &out, &added_l, &added_p, &error))
        << error;
    const size_t M = graph.landmark_measurements.size();
    const size_t P = taus.size();
    ASSERT_EQ(added_l.size(), static_cast<size_t>(std::lround(0.3 * M / 0.7)));
    ASSERT_EQ(added_p.size(), P);  // 0.5 / (1 - 0.5) = 1 per position prior.
    ASSERT_EQ(out.measurements.size(), graph.measurements.size());
    ASSERT_EQ(out.landmark_measurements.size(), M + added_l.size());
    ASSERT_EQ(out.priors.size(), graph.priors.size() + added_p.size());
    std::set<std::pair<int, int>> pairs;
    for (size_t k = 0; k < added_l.size(); ++k) {
      EXPECT_EQ(added_l[k], static_cast<int>(M + k));
      const LandmarkMeasurement& w = out.landmark_measurements[added_l[k]];
      // The same (i, z, nu) as a true observation of another landmark.
      int source = -1;
      for (size_t q = 0; q < M; ++q) {
        const LandmarkMeasurement& t = graph.landmark_measurements[q];
        if (t.i == w.i && t.z == w.z && t.nu == w.nu && t.l != w.l) {
          source = t.l;
        }
      }
      ASSERT_GE(source, 0) << k;
      EXPECT_TRUE(pairs.insert({source, w.l}).second) << k;
      // Wrong: the truth puts landmark w.l elsewhere.
      const Pose& x = truth.poses[w.i];
      EXPECT_GT((truth.landmarks[w.l] - x.t - x.R * w.z).norm(), 1e-6);
    }
    for (size_t k = 0; k < added_p.size(); ++k) {
      EXPECT_EQ(added_p[k], static_cast<int>(graph.priors.size() + k));
      const PosePrior& p = out.priors[added_p[k]];
      EXPECT_FALSE(p.has_rotation());
      EXPECT_EQ(p.tau, median);
      const double jump = (p.t - truth.poses[p.i].t).norm() * std::sqrt(median);
      EXPECT_GE(jump, 10 - 1e-9);
      EXPECT_LE(jump, 40 + 1e-9);
    }
    // The input's terms first, unchanged.
    for (size_t q = 0; q < M; ++q) {
      EXPECT_EQ(out.landmark_measurements[q].l,
                graph.landmark_measurements[q].l);
      EXPECT_EQ(out.landmark_measurements[q].z,
                graph.landmark_measurements[q].z);
    }
    EXPECT_TRUE(ValidatePoseGraph(out, &error)) << error;
    PoseGraph again;
    std::vector<int> again_l, again_p;
    ASSERT_TRUE(AddLandmarkOutliers(graph, options, &again, &again_l, &again_p,
                                    &error));
    for (size_t q = 0; q < out.landmark_measurements.size(); ++q) {
      EXPECT_EQ(again.landmark_measurements[q].l,
                out.landmark_measurements[q].l);
    }
    for (size_t q = 0; q < out.priors.size(); ++q) {
      EXPECT_EQ(again.priors[q].t, out.priors[q].t);
    }

    LandmarkOutlierOptions bad = options;
    bad.landmark_fraction = 1;
    EXPECT_FALSE(
        AddLandmarkOutliers(graph, bad, &again, nullptr, nullptr, &error));
    EXPECT_THAT(error, ::testing::HasSubstr("[0, 1)"));
    PoseGraph no_priors = graph;
    no_priors.priors.clear();
    EXPECT_FALSE(AddLandmarkOutliers(no_priors, options, &again, nullptr,
                                     nullptr, &error));
    EXPECT_THAT(error, ::testing::HasSubstr("position priors"));
  }
}

}  // namespace
}  // namespace ceres_sesync
