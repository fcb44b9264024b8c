// Tests of pose_conversions.h: round trips between Pose and Eigen / Ceres
// example types, id matching, and the (kappa, tau) convention of the Ceres
// constraint adapters against the g2o reader. Includes only the umbrella
// header (which this also tests).

#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "ceres_sesync/ceres_sesync.h"
#include "gtest/gtest.h"

namespace ceres_sesync {
namespace {

// User-side types written the way Ceres's examples/slam write them, plus an
// extra member that the adapters must leave alone.
struct Pose2d {
  double x = 0, y = 0, yaw_radians = 0;
  int user_tag = 0;
};
struct Constraint2d {
  int id_begin = 0, id_end = 0;
  double x = 0, y = 0, yaw_radians = 0;
  Eigen::Matrix3d information = Eigen::Matrix3d::Identity();
};
struct Pose3d {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  int user_tag = 0;
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};
struct Constraint3d {
  int id_begin = 0, id_end = 0;
  Pose3d t_be;
  Eigen::Matrix<double, 6, 6> information =
      Eigen::Matrix<double, 6, 6>::Identity();
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};
using MapOfPoses2d = std::map<int, Pose2d>;
using MapOfPoses3d =
    std::map<int, Pose3d, std::less<int>,
             Eigen::aligned_allocator<std::pair<const int, Pose3d>>>;
using VectorOfConstraints3d =
    std::vector<Constraint3d, Eigen::aligned_allocator<Constraint3d>>;

// Rounding-level tolerance for conversions that go through sin/cos, atan2,
// quaternion <-> matrix and an SVD projection of an exact rotation: each step
// is backward stable, so errors are a few ulps of O(1) quantities.
constexpr double kRoundTrip = 1e-12;

Eigen::Matrix3d RandomRotation3(std::mt19937_64* rng) {
  std::normal_distribution<double> normal;
  Eigen::Quaterniond q(normal(*rng), normal(*rng), normal(*rng), normal(*rng));
  return q.normalized().toRotationMatrix();
}

Pose RandomPose(int d, std::mt19937_64* rng) {
  std::normal_distribution<double> normal;
  Pose pose;
  if (d == 2) {
    pose = PoseFromXYYaw(0, 0, 3 * normal(*rng));
  } else {
    pose.R = RandomRotation3(rng);
  }
  pose.t = Eigen::VectorXd::NullaryExpr(d, [&]() { return normal(*rng); });
  return pose;
}

// A random symmetric positive definite k x k matrix (well conditioned).
Eigen::MatrixXd RandomSpd(int k, std::mt19937_64* rng) {
  std::normal_distribution<double> normal;
  Eigen::MatrixXd A =
      Eigen::MatrixXd::NullaryExpr(k, k, [&]() { return normal(*rng); });
  return A * A.transpose() + k * Eigen::MatrixXd::Identity(k, k);
}

double MaxPoseDifference(const Pose& a, const Pose& b) {
  return std::max((a.R - b.R).cwiseAbs().maxCoeff(),
                  (a.t - b.t).cwiseAbs().maxCoeff());
}

std::string G2oNumber(double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.17g", v);
  return buffer;
}

// Reads `text` with the g2o reader; fails the test on error.
PoseGraph ReadG2oText(const std::string& text) {
  std::istringstream in(text);
  PoseGraph graph;
  std::string error;
  EXPECT_TRUE(ReadG2o(in, "text", G2oReadOptions(), &graph, &error)) << error;
  return graph;
}

void ExpectSameMeasurements(const PoseGraph& a, const PoseGraph& b) {
  ASSERT_EQ(a.dimension, b.dimension);
  ASSERT_EQ(a.num_poses, b.num_poses);
  EXPECT_EQ(a.vertex_ids, b.vertex_ids);
  ASSERT_EQ(a.measurements.size(), b.measurements.size());
  for (size_t k = 0; k < a.measurements.size(); ++k) {
    const RelativePoseMeasurement& ma = a.measurements[k];
    const RelativePoseMeasurement& mb = b.measurements[k];
    SCOPED_TRACE("measurement " + std::to_string(k));
    EXPECT_EQ(ma.i, mb.i);
    EXPECT_EQ(ma.j, mb.j);
    EXPECT_LE((ma.R - mb.R).cwiseAbs().maxCoeff(), kRoundTrip);
    EXPECT_LE((ma.t - mb.t).cwiseAbs().maxCoeff(), kRoundTrip);
    // Same formula on the same doubles: equal to rounding.
    EXPECT_NEAR(ma.kappa, mb.kappa, 1e-12 * mb.kappa);
    EXPECT_NEAR(ma.tau, mb.tau, 1e-12 * mb.tau);
  }
}

TEST(PoseConversionsTest, IsometryRoundTrips) {
  std::mt19937_64 rng(1);
  for (int trial = 0; trial < 20; ++trial) {
    for (int d : {2, 3}) {
      const Pose pose = RandomPose(d, &rng);
      Pose back;
      std::string error;
      if (d == 2) {
        Eigen::Isometry2d T;
        ASSERT_TRUE(PoseToIsometry(pose, &T, &error)) << error;
        // The isometry acts on points as R p + t.
        const Eigen::Vector2d p(0.3, -1.7);
        EXPECT_LE((T * p - (pose.R * p + pose.t)).norm(), kRoundTrip);
        back = PoseFromIsometry(T);
      } else {
        Eigen::Isometry3d T;
        ASSERT_TRUE(PoseToIsometry(pose, &T, &error)) << error;
        const Eigen::Vector3d p(0.3, -1.7, 2.2);
        EXPECT_LE((T * p - (pose.R * p + pose.t)).norm(), kRoundTrip);
        back = PoseFromIsometry(T);
      }
      EXPECT_LE(MaxPoseDifference(pose, back), kRoundTrip);
    }
  }
}

TEST(PoseConversionsTest, IsometryVectorsWithAnyAllocator) {
  std::mt19937_64 rng(2);
  Poses poses3, poses2;
  for (int i = 0; i < 7; ++i) {
    poses3.push_back(RandomPose(3, &rng));
    poses2.push_back(RandomPose(2, &rng));
  }
  std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>>
      transforms3;
  std::vector<Eigen::Isometry2d> transforms2;
  std::string error;
  ASSERT_TRUE(PosesToIsometries(poses3, &transforms3, &error)) << error;
  ASSERT_TRUE(PosesToIsometries(poses2, &transforms2, &error)) << error;
  ASSERT_EQ(transforms3.size(), 7u);
  ASSERT_EQ(transforms2.size(), 7u);
  const Poses back3 = PosesFromIsometries(transforms3);
  const Poses back2 = PosesFromIsometries(transforms2);
  for (int i = 0; i < 7; ++i) {
    EXPECT_LE(MaxPoseDifference(poses3[i], back3[i]), kRoundTrip);
    EXPECT_LE(MaxPoseDifference(poses2[i], back2[i]), kRoundTrip);
  }
  // A 2D pose among 3D ones is named in the error, output untouched.
  poses3[4] = poses2[0];
  transforms3.clear();
  EXPECT_FALSE(PosesToIsometries(poses3, &transforms3, &error));
  EXPECT_NE(error.find("pose 4"), std::string::npos) << error;
  EXPECT_TRUE(transforms3.empty());
}

TEST(PoseConversionsTest, IsometryOfProjectedRotation) {
  // A slightly non-orthogonal rotation comes out as the nearest rotation.
  Pose pose = PoseFromXYYaw(1, 2, 0.7);
  pose.R(0, 0) += 1e-4;
  Eigen::Isometry2d T;
  ASSERT_TRUE(PoseToIsometry(pose, &T, nullptr));
  const Eigen::Matrix2d R = T.linear();
  EXPECT_LE((R.transpose() * R - Eigen::Matrix2d::Identity()).norm(), 1e-14);
  EXPECT_NEAR(R.determinant(), 1.0, 1e-14);
  EXPECT_LE((R - pose.R).norm(), 1e-4);  // Within the perturbation.
}

TEST(PoseConversionsTest, QuaternionRoundTripAndSign) {
  std::mt19937_64 rng(3);
  for (int trial = 0; trial < 20; ++trial) {
    const Pose pose = RandomPose(3, &rng);
    Eigen::Quaterniond q;
    Eigen::Vector3d t;
    std::string error;
    ASSERT_TRUE(PoseToQuaternionTranslation(pose, &q, &t, &error)) << error;
    EXPECT_NEAR(q.norm(), 1.0, 1e-15);
    EXPECT_GE(q.w(), 0.0);
    EXPECT_LE((q.toRotationMatrix() - pose.R).cwiseAbs().maxCoeff(),
              kRoundTrip);
    EXPECT_LE((t - pose.t).cwiseAbs().maxCoeff(), 0.0);
    // -q and a scaled q are the same rotation.
    const Pose from_negated =
        PoseFromQuaternionTranslation(Eigen::Quaterniond(-q.coeffs()), t);
    const Pose from_scaled =
        PoseFromQuaternionTranslation(Eigen::Quaterniond(2.5 * q.coeffs()), t);
    EXPECT_LE(MaxPoseDifference(pose, from_negated), kRoundTrip);
    EXPECT_LE(MaxPoseDifference(pose, from_scaled), kRoundTrip);
  }
  // A zero quaternion yields a non-finite rotation (rejected downstream).
  const Pose bad = PoseFromQuaternionTranslation(Eigen::Quaterniond(0, 0, 0, 0),
                                                 Eigen::Vector3d::Zero());
  EXPECT_FALSE(bad.R.allFinite());
  Eigen::Quaterniond q;
  Eigen::Vector3d t;
  std::string error;
  EXPECT_FALSE(PoseToQuaternionTranslation(bad, &q, &t, &error));
  EXPECT_NE(error.find("non-finite"), std::string::npos) << error;
}

TEST(PoseConversionsTest, XYYawRoundTripAndWrap) {
  for (double yaw : {0.0, 0.5, -2.0, 3.0, M_PI, -M_PI + 1e-9, 7.0, -12.0}) {
    const Pose pose = PoseFromXYYaw(1.5, -2.5, yaw);
    EXPECT_NEAR(pose.R.determinant(), 1.0, 1e-15);
    double x, y, back;
    ASSERT_TRUE(PoseToXYYaw(pose, &x, &y, &back, nullptr));
    EXPECT_EQ(x, 1.5);
    EXPECT_EQ(y, -2.5);
    EXPECT_GT(back, -M_PI);
    EXPECT_LE(back, M_PI);
    // Same angle modulo 2 pi.
    EXPECT_NEAR(std::remainder(back - yaw, 2 * M_PI), 0.0, kRoundTrip)
        << "yaw " << yaw;
  }
}

TEST(PoseConversionsTest, WrongDimensionsAndNonFiniteAreErrors) {
  std::mt19937_64 rng(4);
  const Pose pose2 = RandomPose(2, &rng);
  const Pose pose3 = RandomPose(3, &rng);
  std::string error;
  Eigen::Isometry2d T2;
  Eigen::Isometry3d T3;
  EXPECT_FALSE(PoseToIsometry(pose3, &T2, &error));
  EXPECT_NE(error.find("not a 2D pose"), std::string::npos) << error;
  EXPECT_FALSE(PoseToIsometry(pose2, &T3, &error));
  EXPECT_NE(error.find("not a 3D pose"), std::string::npos) << error;
  double x, y, yaw;
  EXPECT_FALSE(PoseToXYYaw(pose3, &x, &y, &yaw, &error));
  EXPECT_FALSE(PoseToXYYaw(Pose(), &x, &y, &yaw, &error));  // Empty pose.
  EXPECT_FALSE(PoseToXYYaw(pose2, nullptr, &y, &yaw, &error));
  Pose nan_pose = pose2;
  nan_pose.t(1) = std::nan("");
  EXPECT_FALSE(PoseToXYYaw(nan_pose, &x, &y, &yaw, &error));
  EXPECT_NE(error.find("non-finite"), std::string::npos) << error;
}

TEST(PoseConversionsTest, ArraysRoundTrip) {
  std::mt19937_64 rng(5);
  for (int d : {2, 3}) {
    Poses poses;
    for (int i = 0; i < 5; ++i) poses.push_back(RandomPose(d, &rng));
    std::vector<double> rotations(d * d * 5), translations(d * 5);
    std::string error;
    ASSERT_TRUE(
        PosesToArrays(d, poses, rotations.data(), translations.data(), &error))
        << error;
    // Column-major layout: entry (r, c) of pose i at d*d*i + c*d + r.
    EXPECT_EQ(rotations[d * d * 3 + 1 * d + 0], poses[3].R(0, 1));
    EXPECT_EQ(translations[d * 4 + 1], poses[4].t(1));
    Poses back;
    ASSERT_TRUE(PosesFromArrays(d, 5, rotations.data(), translations.data(),
                                &back, &error))
        << error;
    ASSERT_EQ(back.size(), 5u);
    for (int i = 0; i < 5; ++i) {
      EXPECT_EQ(MaxPoseDifference(poses[i], back[i]), 0.0);  // Exact copy.
    }
    // Bad input.
    EXPECT_FALSE(PosesToArrays(5 - d, poses, rotations.data(),
                               translations.data(), &error));
    EXPECT_FALSE(
        PosesFromArrays(4, 5, rotations.data(), translations.data(), &back));
    EXPECT_FALSE(PosesFromArrays(d, 5, nullptr, translations.data(), &back));
    EXPECT_FALSE(
        PosesFromArrays(d, -1, rotations.data(), translations.data(), &back));
    translations[d * 2] = std::nan("");
    EXPECT_FALSE(PosesFromArrays(d, 5, rotations.data(), translations.data(),
                                 &back, &error));
    EXPECT_NE(error.find("pose 2"), std::string::npos) << error;
  }
}

// A small 2D graph with sparse, non-sorted ids (first appearance order 7, 3,
// 42, 5).
PoseGraph MakeGraph(int d, std::mt19937_64* rng) {
  PoseGraph graph;
  graph.dimension = d;
  for (int64_t id : {7, 3, 42, 5}) graph.AddVertex(id);
  const int edges[][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 2}};
  for (const auto& e : edges) {
    const Pose rel = RandomPose(d, rng);
    RelativePoseMeasurement m;
    m.i = e[0];
    m.j = e[1];
    m.R = rel.R;
    m.t = rel.t;
    m.kappa = 3.5 + e[0];
    m.tau = 11.0 + e[1];
    graph.measurements.push_back(m);
  }
  return graph;
}

TEST(PoseConversionsTest, Ceres2dMapRoundTripMatchesByVertexId) {
  std::mt19937_64 rng(6);
  const PoseGraph graph = MakeGraph(2, &rng);
  Poses poses;
  for (int i = 0; i < graph.num_poses; ++i)
    poses.push_back(RandomPose(2, &rng));
  MapOfPoses2d map;
  map[42].user_tag = 99;  // An existing entry: its extra member is kept.
  map[1000].x = 123;      // Not a vertex: ignored, left alone.
  std::string error;
  ASSERT_TRUE(PosesToCeres2dMap(graph, poses, &map, &error)) << error;
  EXPECT_EQ(map.size(), 5u);
  EXPECT_EQ(map[42].user_tag, 99);
  EXPECT_EQ(map[1000].x, 123);
  // The value keyed by id graph.vertex_ids[i] is pose i.
  for (int i = 0; i < graph.num_poses; ++i) {
    const Pose2d& value = map.at(static_cast<int>(graph.vertex_ids[i]));
    EXPECT_LE(MaxPoseDifference(
                  PoseFromXYYaw(value.x, value.y, value.yaw_radians), poses[i]),
              kRoundTrip);
  }
  Poses back;
  ASSERT_TRUE(PosesFromCeres2dMap(graph, map, &back, &error)) << error;
  ASSERT_EQ(back.size(), poses.size());
  for (int i = 0; i < graph.num_poses; ++i) {
    EXPECT_LE(MaxPoseDifference(poses[i], back[i]), kRoundTrip);
  }
  // The objective is the same whichever representation the poses went
  // through.
  EXPECT_NEAR(EvaluateObjective(graph, back), EvaluateObjective(graph, poses),
              1e-12 * EvaluateObjective(graph, poses));

  // A missing id is named.
  map.erase(5);
  EXPECT_FALSE(PosesFromCeres2dMap(graph, map, &back, &error));
  EXPECT_NE(error.find("vertex id 5 "), std::string::npos) << error;
  // Wrong number of poses for the graph: the map is untouched.
  const MapOfPoses2d before = map;
  poses.pop_back();
  EXPECT_FALSE(PosesToCeres2dMap(graph, poses, &map, &error));
  EXPECT_NE(error.find("3 poses for a graph of 4"), std::string::npos) << error;
  EXPECT_EQ(map.size(), before.size());
}

TEST(PoseConversionsTest, Ceres3dMapRoundTripAndDimensionMismatch) {
  std::mt19937_64 rng(7);
  const PoseGraph graph = MakeGraph(3, &rng);
  Poses poses;
  for (int i = 0; i < graph.num_poses; ++i)
    poses.push_back(RandomPose(3, &rng));
  MapOfPoses3d map;
  std::string error;
  ASSERT_TRUE(PosesToCeres3dMap(graph, poses, &map, &error)) << error;
  ASSERT_EQ(map.size(), 4u);
  for (const auto& [id, value] : map) {
    EXPECT_NEAR(value.q.norm(), 1.0, 1e-15) << id;
  }
  Poses back;
  ASSERT_TRUE(PosesFromCeres3dMap(graph, map, &back, &error)) << error;
  for (int i = 0; i < graph.num_poses; ++i) {
    EXPECT_LE(MaxPoseDifference(poses[i], back[i]), kRoundTrip);
  }
  // A 3D graph with the 2D adapters, and vice versa.
  MapOfPoses2d map2;
  EXPECT_FALSE(PosesFromCeres2dMap(graph, map2, &back, &error));
  EXPECT_NE(error.find("3D, not 2D"), std::string::npos) << error;
  EXPECT_FALSE(PosesToCeres2dMap(graph, poses, &map2, &error));
  EXPECT_TRUE(map2.empty());
  const PoseGraph graph2 = MakeGraph(2, &rng);
  EXPECT_FALSE(PosesFromCeres3dMap(graph2, map, &back, &error));
  EXPECT_NE(error.find("2D, not 3D"), std::string::npos) << error;
  // 2D poses for the 3D graph.
  Poses poses2(4, RandomPose(2, &rng));
  EXPECT_FALSE(PosesToCeres3dMap(graph, poses2, &map, &error));
  EXPECT_NE(error.find("not a 3D pose"), std::string::npos) << error;
  // A non-finite pose in the map is named.
  map.at(42).p.x() = std::nan("");
  EXPECT_FALSE(PosesFromCeres3dMap(graph, map, &back, &error));
  EXPECT_NE(error.find("vertex id 42"), std::string::npos) << error;
}

TEST(PoseConversionsTest, VertexIdThatDoesNotFitTheKeyType) {
  std::mt19937_64 rng(8);
  PoseGraph graph = MakeGraph(2, &rng);
  graph.vertex_ids[2] = int64_t{1} << 40;  // Does not fit an int key.
  Poses poses(4, RandomPose(2, &rng));
  MapOfPoses2d map;
  std::string error;
  EXPECT_FALSE(PosesToCeres2dMap(graph, poses, &map, &error));
  EXPECT_NE(error.find("does not fit"), std::string::npos) << error;
  EXPECT_TRUE(map.empty());
  // Reading: the id is "missing" (it cannot be a key), not aliased to another.
  // (2^40 truncated to int is 0: an entry with key 0 must not be taken for
  // it.)
  for (int key : {7, 3, 5, 0}) map[key] = Pose2d();
  EXPECT_FALSE(PosesFromCeres2dMap(graph, map, &poses, &error));
  EXPECT_NE(error.find(std::to_string(int64_t{1} << 40)), std::string::npos)
      << error;
}

// The weights of a 2D constraint with a full (correlated) information matrix
// equal those the g2o reader gives for the same edge written as a g2o line.
TEST(PoseConversionsTest, Ceres2dConstraintWeightsMatchG2oReader) {
  std::mt19937_64 rng(9);
  std::vector<Constraint2d> constraints;
  std::string g2o;
  const int ids[][2] = {{10, 4}, {4, 8}, {8, 10}, {10, 8}};  // Parallel edge.
  for (const auto& e : ids) {
    Constraint2d c;
    c.id_begin = e[0];
    c.id_end = e[1];
    std::normal_distribution<double> normal;
    c.x = normal(rng);
    c.y = normal(rng);
    c.yaw_radians = normal(rng);
    c.information = RandomSpd(3, &rng);
    constraints.push_back(c);
    g2o += "EDGE_SE2 " + std::to_string(e[0]) + " " + std::to_string(e[1]);
    for (double v : {c.x, c.y, c.yaw_radians}) g2o += " " + G2oNumber(v);
    for (int r = 0; r < 3; ++r) {
      for (int col = r; col < 3; ++col) {
        g2o += " " + G2oNumber(c.information(r, col));
      }
    }
    g2o += "\n";
  }
  PoseGraph graph;
  std::string error;
  ASSERT_TRUE(PoseGraphFromCeres2dConstraints(constraints, &graph, &error))
      << error;
  const PoseGraph from_g2o = ReadG2oText(g2o);
  ExpectSameMeasurements(graph, from_g2o);
  EXPECT_TRUE(graph.initial_poses.empty());
  EXPECT_EQ(graph.fixed_pose, -1);
  // And the closed form on one edge, independently of both.
  const Eigen::Matrix3d& I = constraints[0].information;
  const Eigen::Matrix2d I_tt = I.topLeftCorner<2, 2>();
  EXPECT_NEAR(graph.measurements[0].tau, 2 / I_tt.inverse().trace(), 1e-12);
  EXPECT_EQ(graph.measurements[0].kappa, I(2, 2));
}

TEST(PoseConversionsTest, Ceres3dConstraintWeightsMatchG2oReader) {
  std::mt19937_64 rng(10);
  VectorOfConstraints3d constraints;
  std::string g2o;
  const int ids[][2] = {{0, 1}, {1, 2}, {2, 0}, {3, 2}};
  for (const auto& e : ids) {
    Constraint3d c;
    c.id_begin = e[0];
    c.id_end = e[1];
    const Pose rel = RandomPose(3, &rng);
    c.t_be.p = rel.t;
    c.t_be.q = Eigen::Quaterniond(Eigen::Matrix3d(rel.R));
    c.information = RandomSpd(6, &rng);
    constraints.push_back(c);
    g2o += "EDGE_SE3:QUAT " + std::to_string(e[0]) + " " + std::to_string(e[1]);
    for (double v : {c.t_be.p.x(), c.t_be.p.y(), c.t_be.p.z(), c.t_be.q.x(),
                     c.t_be.q.y(), c.t_be.q.z(), c.t_be.q.w()}) {
      g2o += " " + G2oNumber(v);
    }
    for (int r = 0; r < 6; ++r) {
      for (int col = r; col < 6; ++col) {
        g2o += " " + G2oNumber(c.information(r, col));
      }
    }
    g2o += "\n";
  }
  PoseGraph graph;
  std::string error;
  ASSERT_TRUE(PoseGraphFromCeres3dConstraints(constraints, &graph, &error))
      << error;
  ExpectSameMeasurements(graph, ReadG2oText(g2o));
  const Eigen::Matrix<double, 6, 6>& I = constraints[1].information;
  const Eigen::Matrix3d I_tt = I.topLeftCorner<3, 3>();
  const Eigen::Matrix3d I_RR = I.bottomRightCorner<3, 3>();
  EXPECT_NEAR(graph.measurements[1].tau, 3 / I_tt.inverse().trace(),
              1e-12 * graph.measurements[1].tau);
  EXPECT_NEAR(graph.measurements[1].kappa, 3 / (2 * I_RR.inverse().trace()),
              1e-12 * graph.measurements[1].kappa);
}

TEST(PoseConversionsTest, PoseGraphFromCeres3dUsesMapOrderAndInitialPoses) {
  std::mt19937_64 rng(11);
  MapOfPoses3d map;
  Poses expected;  // In ascending id order (the std::map's order).
  for (int id : {2, 5, 9}) {
    const Pose pose = RandomPose(3, &rng);
    map[id].p = pose.t;
    map[id].q = Eigen::Quaterniond(Eigen::Matrix3d(pose.R));
    expected.push_back(pose);
  }
  VectorOfConstraints3d constraints(3);
  constraints[0].id_begin = 9, constraints[0].id_end = 5;
  constraints[1].id_begin = 5, constraints[1].id_end = 2;
  constraints[2].id_begin = 2, constraints[2].id_end = 9;
  PoseGraph graph;
  std::string error;
  ASSERT_TRUE(PoseGraphFromCeres3d(map, constraints, &graph, &error)) << error;
  EXPECT_EQ(graph.vertex_ids, (std::vector<int64_t>{2, 5, 9}));
  ASSERT_EQ(graph.initial_poses.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_LE(MaxPoseDifference(graph.initial_poses[i], expected[i]),
              kRoundTrip);
  }
  EXPECT_EQ(graph.measurements[0].i, 2);
  EXPECT_EQ(graph.measurements[0].j, 1);
  // Identity information: tau = 3 / 3 = 1, kappa = 3 / (2 * 3) = 0.5.
  EXPECT_DOUBLE_EQ(graph.measurements[0].tau, 1.0);
  EXPECT_DOUBLE_EQ(graph.measurements[0].kappa, 0.5);
  // A constraint to an id that is not in the map.
  constraints[2].id_end = 77;
  EXPECT_FALSE(PoseGraphFromCeres3d(map, constraints, &graph, &error));
  EXPECT_NE(error.find("constraint 2"), std::string::npos) << error;
  EXPECT_NE(error.find("vertex id 77 is not in the poses map"),
            std::string::npos)
      << error;
}

TEST(PoseConversionsTest, PoseGraphFromCeres2dMapAndGaugeMatchesFirstEntry) {
  std::mt19937_64 rng(12);
  MapOfPoses2d map;
  map[3] = Pose2d{1, 2, 0.5, 0};
  map[1] = Pose2d{-1, 0, 0.1, 0};
  std::vector<Constraint2d> constraints(1);
  constraints[0].id_begin = 3;
  constraints[0].id_end = 1;
  PoseGraph graph;
  std::string error;
  ASSERT_TRUE(PoseGraphFromCeres2d(map, constraints, &graph, &error)) << error;
  EXPECT_EQ(graph.vertex_ids, (std::vector<int64_t>{1, 3}));
  EXPECT_EQ(graph.initial_poses[0].t, Eigen::Vector2d(-1, 0));
  // Identity information: tau = 2 / 2 = 1, kappa = 1.
  EXPECT_DOUBLE_EQ(graph.measurements[0].tau, 1.0);
  EXPECT_DOUBLE_EQ(graph.measurements[0].kappa, 1.0);
}

TEST(PoseConversionsTest, BadConstraintsAreErrors) {
  std::string error;
  PoseGraph graph;
  // Empty.
  std::vector<Constraint2d> constraints;
  EXPECT_FALSE(PoseGraphFromCeres2dConstraints(constraints, &graph, &error));
  EXPECT_NE(error.find("no constraints"), std::string::npos) << error;
  // Self-loop.
  constraints.resize(2);
  constraints[0].id_begin = 0, constraints[0].id_end = 1;
  constraints[1].id_begin = 1, constraints[1].id_end = 1;
  EXPECT_FALSE(PoseGraphFromCeres2dConstraints(constraints, &graph, &error));
  EXPECT_NE(error.find("constraint 1 (1 -> 1): self-loop"), std::string::npos)
      << error;
  // Indefinite translational block.
  constraints[1].id_begin = 1, constraints[1].id_end = 2;
  constraints[1].information(0, 1) = constraints[1].information(1, 0) = 2.0;
  EXPECT_FALSE(PoseGraphFromCeres2dConstraints(constraints, &graph, &error));
  EXPECT_NE(error.find("translational information block"), std::string::npos)
      << error;
  // Non-positive rotational precision.
  constraints[1].information = Eigen::Matrix3d::Identity();
  constraints[1].information(2, 2) = 0;
  EXPECT_FALSE(PoseGraphFromCeres2dConstraints(constraints, &graph, &error));
  EXPECT_NE(error.find("rotational information block"), std::string::npos)
      << error;
  // Non-finite.
  constraints[1].information = Eigen::Matrix3d::Identity();
  constraints[1].yaw_radians = std::nan("");
  EXPECT_FALSE(PoseGraphFromCeres2dConstraints(constraints, &graph, &error));
  EXPECT_NE(error.find("non-finite"), std::string::npos) << error;
  // Disconnected: 0-1 and 2-3.
  constraints[1].yaw_radians = 0;
  constraints[1].id_begin = 2, constraints[1].id_end = 3;
  EXPECT_FALSE(PoseGraphFromCeres2dConstraints(constraints, &graph, &error));
  EXPECT_NE(error.find("do not form a valid pose graph"), std::string::npos)
      << error;
  // Valid again.
  constraints[1].id_begin = 1;
  EXPECT_TRUE(PoseGraphFromCeres2dConstraints(constraints, &graph, &error))
      << error;
  EXPECT_EQ(graph.num_poses, 3);

  // 3D: a quaternion far from unit length.
  VectorOfConstraints3d constraints3(1);
  constraints3[0].id_begin = 0, constraints3[0].id_end = 1;
  constraints3[0].t_be.q = Eigen::Quaterniond(1.1, 0, 0, 0);
  EXPECT_FALSE(PoseGraphFromCeres3dConstraints(constraints3, &graph, &error));
  EXPECT_NE(error.find("quaternion"), std::string::npos) << error;
  // Slightly off unit length: normalized, as the g2o reader does.
  constraints3[0].t_be.q = Eigen::Quaterniond(1.0 + 1e-6, 0, 0, 0);
  ASSERT_TRUE(PoseGraphFromCeres3dConstraints(constraints3, &graph, &error))
      << error;
  EXPECT_LE((graph.measurements[0].R - Eigen::Matrix3d::Identity()).norm(),
            1e-15);
}

// Graph -> Ceres constraints -> graph reproduces every measurement, and the
// isotropic information matrices written are what the g2o writer writes.
TEST(PoseConversionsTest, ConstraintsRoundTripOnCubes) {
  for (int d : {2, 3}) {
    SCOPED_TRACE("d = " + std::to_string(d));
    CubeOptions options;
    options.dimension = d;
    options.side = 4;
    options.loop_closure_probability = 0.3;
    options.seed = 3;
    PoseGraph cube;
    Poses truth;
    std::string error;
    ASSERT_TRUE(GenerateCube(options, &cube, &truth, &error)) << error;
    PoseGraph back;
    if (d == 2) {
      std::vector<Constraint2d> constraints;
      ASSERT_TRUE(PoseGraphToCeres2dConstraints(cube, &constraints, &error))
          << error;
      ASSERT_EQ(constraints.size(), cube.measurements.size());
      EXPECT_EQ(constraints[0].information,
                Eigen::Vector3d(options.tau, options.tau, options.kappa)
                    .asDiagonal()
                    .toDenseMatrix());
      ASSERT_TRUE(PoseGraphFromCeres2dConstraints(constraints, &back, &error))
          << error;
      // And the poses through a map.
      MapOfPoses2d map;
      ASSERT_TRUE(PosesToCeres2dMap(cube, truth, &map, &error)) << error;
      Poses poses;
      ASSERT_TRUE(PosesFromCeres2dMap(back, map, &poses, &error)) << error;
      EXPECT_NEAR(EvaluateObjective(back, poses),
                  EvaluateObjective(cube, truth),
                  1e-10 * EvaluateObjective(cube, truth));
    } else {
      VectorOfConstraints3d constraints;
      ASSERT_TRUE(PoseGraphToCeres3dConstraints(cube, &constraints, &error))
          << error;
      ASSERT_EQ(constraints.size(), cube.measurements.size());
      Eigen::Matrix<double, 6, 1> diagonal;
      diagonal << options.tau, options.tau, options.tau, 2 * options.kappa,
          2 * options.kappa, 2 * options.kappa;
      EXPECT_EQ(constraints[0].information,
                diagonal.asDiagonal().toDenseMatrix());
      ASSERT_TRUE(PoseGraphFromCeres3dConstraints(constraints, &back, &error))
          << error;
      MapOfPoses3d map;
      ASSERT_TRUE(PosesToCeres3dMap(cube, truth, &map, &error)) << error;
      Poses poses;
      ASSERT_TRUE(PosesFromCeres3dMap(back, map, &poses, &error)) << error;
      EXPECT_NEAR(EvaluateObjective(back, poses),
                  EvaluateObjective(cube, truth),
                  1e-10 * EvaluateObjective(cube, truth));
    }
    ExpectSameMeasurements(back, cube);
  }
  // The wrong dimension is an error.
  CubeOptions options;
  options.side = 3;
  PoseGraph cube3;
  ASSERT_TRUE(GenerateCube(options, &cube3, nullptr, nullptr));
  std::vector<Constraint2d> constraints2;
  std::string error;
  EXPECT_FALSE(PoseGraphToCeres2dConstraints(cube3, &constraints2, &error));
  EXPECT_TRUE(constraints2.empty());
}

// The documented gauge: with a poses map, SE-Sync's solution keeps the map's
// first pose (the one Ceres's examples hold constant) at its value, so it can
// be copied back into the map without moving that pose.
TEST(PoseConversionsTest, SolutionKeepsTheFirstMapPoseFixed) {
  CubeOptions options;
  options.side = 4;
  options.seed = 5;
  PoseGraph cube;
  Poses truth;
  std::string error;
  ASSERT_TRUE(GenerateCube(options, &cube, &truth, &error)) << error;
  VectorOfConstraints3d constraints;
  ASSERT_TRUE(PoseGraphToCeres3dConstraints(cube, &constraints, &error));
  // The user's guess: the ground truth moved by a rigid transform, so the
  // first pose is not the identity.
  const Eigen::Isometry3d offset =
      Eigen::Translation3d(1, -2, 3) *
      Eigen::AngleAxisd(0.8, Eigen::Vector3d(1, 2, 2).normalized());
  std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>>
      transforms;
  ASSERT_TRUE(PosesToIsometries(truth, &transforms, &error)) << error;
  for (Eigen::Isometry3d& T : transforms) T = offset * T;
  MapOfPoses3d map;
  ASSERT_TRUE(
      PosesToCeres3dMap(cube, PosesFromIsometries(transforms), &map, &error))
      << error;
  PoseGraph graph;
  ASSERT_TRUE(PoseGraphFromCeres3d(map, constraints, &graph, &error)) << error;
  SolverSummary summary;
  const Poses solution = Solve(graph, SolverOptions(), &summary);
  ASSERT_TRUE(summary.certified()) << summary.FullReport();
  ASSERT_EQ(static_cast<int>(solution.size()), graph.num_poses);
  Poses first_in_map;
  ASSERT_TRUE(PosesFromCeres3dMap(graph, map, &first_in_map, &error));
  // Rounding-level agreement (the gauge is applied exactly by the solver, up
  // to the composition of a few rotations).
  EXPECT_LE(MaxPoseDifference(solution[0], first_in_map[0]), 1e-9);
  // And the optimum is invariant: same objective as in the cube's own frame.
  SolverSummary cube_summary;
  Solve(cube, SolverOptions(), &cube_summary);
  EXPECT_NEAR(summary.objective, cube_summary.objective,
              1e-6 * cube_summary.objective);
}

}  // namespace
}  // namespace ceres_sesync
