// g2o I/O of point landmarks and pose priors (g2o_io.h): round trips, the
// conversion of g2o's own measurement conventions (checked against g2o's
// error definitions evaluated here from first principles), and every bad
// landmark / prior / parameter line failing with "PATH:LINE: message".

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "Eigen/Eigenvalues"
#include "Eigen/Geometry"
#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/pose_graph.h"
#include "gtest/gtest.h"
#include "tests/util/test_graphs.h"

namespace ceres_sesync {
namespace {

// Round trips reproduce every double up to the few ulps of recomputing the
// precisions (e.g. 2 / (2 / nu)) and rotations via angles / quaternions.
constexpr double kRoundTripTolerance = 1e-12;

std::string TempPath(const std::string& name) {
  return testing::TempDir() + "g2o_io_landmarks_test_" +
         std::to_string(getpid()) + "_" + name;
}

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  ASSERT_TRUE(out.good()) << path;
}

bool ReadText(const std::string& text, PoseGraph* graph, std::string* error,
              G2oReadSummary* summary = nullptr) {
  std::istringstream in(text);
  return ReadG2o(in, "mem.g2o", {}, graph, error, summary);
}

double RelativeError(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  if (a.rows() != b.rows() || a.cols() != b.cols()) return INFINITY;
  return (a - b).norm() / std::max(1.0, b.norm());
}

// A noisy random graph with landmarks and all three kinds of priors, sparse
// interleaved ids (landmark ids between pose ids) and initial values.
PoseGraph MakeGraph(int d, Solution* initial) {
  test_util::RandomLandmarkGraphOptions options;
  options.poses.dimension = d;
  options.poses.num_poses = 6;
  options.poses.num_loop_closures = 3;
  options.poses.seed = 10 + d;
  options.num_landmarks = 5;
  options.observations_per_landmark = 3;
  options.num_position_priors = 2;
  options.num_rotation_priors = 1;
  options.num_pose_priors = 2;
  Solution truth;
  PoseGraph g = test_util::RandomLandmarkGraph(options, &truth);
  // Re-id: poses 0, 10, 20, ..., landmarks 5, 15, 25, ...
  PoseGraph h = g;
  h.vertex_ids.clear();
  h.index_of_vertex_id.clear();
  h.num_poses = 0;
  for (int i = 0; i < g.num_poses; ++i) h.AddVertex(10 * i);
  h.landmark_ids.clear();
  h.index_of_landmark_id.clear();
  h.num_landmarks = 0;
  for (int l = 0; l < g.num_landmarks; ++l) h.AddLandmark(10 * l + 5);
  // Distinct, non-isotropic-looking precisions.
  for (size_t k = 0; k < h.landmark_measurements.size(); ++k) {
    h.landmark_measurements[k].nu = 3.5 + k;
  }
  *initial = truth;
  return h;
}

void ExpectSameLandmarksAndPriors(const PoseGraph& a, const PoseGraph& b) {
  ASSERT_EQ(a.num_landmarks, b.num_landmarks);
  ASSERT_EQ(a.landmark_measurements.size(), b.landmark_measurements.size());
  for (size_t k = 0; k < a.landmark_measurements.size(); ++k) {
    const auto& p = a.landmark_measurements[k];
    const auto& q = b.landmark_measurements[k];
    EXPECT_EQ(a.vertex_ids[p.i], b.vertex_ids[q.i]);
    EXPECT_EQ(a.landmark_ids[p.l], b.landmark_ids[q.l]);
    EXPECT_LE(RelativeError(q.z, p.z), kRoundTripTolerance);
    EXPECT_NEAR(q.nu, p.nu, kRoundTripTolerance * p.nu);
  }
  ASSERT_EQ(a.priors.size(), b.priors.size());
  for (size_t k = 0; k < a.priors.size(); ++k) {
    const auto& p = a.priors[k];
    const auto& q = b.priors[k];
    EXPECT_EQ(a.vertex_ids[p.i], b.vertex_ids[q.i]);
    EXPECT_EQ(p.has_rotation(), q.has_rotation());
    EXPECT_EQ(p.has_position(), q.has_position());
    EXPECT_NEAR(q.kappa, p.kappa, kRoundTripTolerance * p.kappa);
    EXPECT_NEAR(q.tau, p.tau, kRoundTripTolerance * p.tau);
    if (p.has_rotation()) {
      EXPECT_LE(RelativeError(q.R, p.R), 1e-12);
    }
    if (p.has_position()) {
      EXPECT_LE(RelativeError(q.t, p.t), 1e-12);
    }
  }
}

class LandmarkRoundTripTest : public testing::TestWithParam<int> {};

TEST_P(LandmarkRoundTripTest, WriteThenReadReproducesTheGraph) {
  const int d = GetParam();
  Solution x;
  const PoseGraph graph = MakeGraph(d, &x);
  std::string error;
  ASSERT_TRUE(ValidatePoseGraph(graph, {true}, &error)) << error;
  const std::string path = TempPath("round_trip.g2o");
  ASSERT_TRUE(WriteG2oFile(path, graph, x.poses, x.landmarks, &error)) << error;

  PoseGraph read;
  G2oReadSummary summary;
  ASSERT_TRUE(ReadG2oFile(path, {}, &read, &error, &summary)) << error;
  EXPECT_EQ(read.vertex_ids, graph.vertex_ids);
  EXPECT_EQ(read.landmark_ids, graph.landmark_ids);
  ExpectSameLandmarksAndPriors(graph, read);
  EXPECT_EQ(summary.num_landmarks, graph.num_landmarks);
  EXPECT_EQ(summary.num_landmark_edges,
            static_cast<int>(graph.landmark_measurements.size()));
  EXPECT_EQ(summary.num_priors, static_cast<int>(graph.priors.size()));
  EXPECT_EQ(summary.num_offset_parameters, d == 3 ? 1 : 0);
  ASSERT_EQ(read.initial_landmarks.size(), x.landmarks.size());
  for (size_t l = 0; l < x.landmarks.size(); ++l) {
    EXPECT_EQ(read.initial_landmarks[l], x.landmarks[l]);  // Exact digits.
  }
  const double f = EvaluateObjective(graph, x);
  ASSERT_GT(f, 0);
  EXPECT_NEAR(
      EvaluateObjective(read, read.initial_poses, read.initial_landmarks), f,
      1e-10 * f);

  // Without VERTEX lines: poses and landmarks in order of first appearance;
  // the same graph up to that order.
  ASSERT_TRUE(WriteG2oFile(path, graph, {}, &error)) << error;
  ASSERT_TRUE(ReadG2oFile(path, {}, &read, &error)) << error;
  EXPECT_TRUE(read.initial_landmarks.empty());
  ExpectSameLandmarksAndPriors(graph, read);

  // Solution files: poses and landmarks by id.
  const std::string solution_path = TempPath("solution.g2o");
  ASSERT_TRUE(WriteG2oSolution(solution_path, graph, x, &error)) << error;
  Solution back;
  ASSERT_TRUE(ReadG2oSolution(solution_path, read, &back, &error)) << error;
  EXPECT_NEAR(EvaluateObjective(read, back), f, 1e-10 * f);
  // ReadG2oPoses ignores the landmark lines.
  Poses poses;
  ASSERT_TRUE(ReadG2oPoses(solution_path, read, &poses, &error)) << error;
  EXPECT_EQ(poses.size(), x.poses.size());
  std::remove(path.c_str());
  std::remove(solution_path.c_str());
}

INSTANTIATE_TEST_SUITE_P(Dimensions, LandmarkRoundTripTest,
                         testing::Values(2, 3));

// ---- g2o's conventions -----------------------------------------------------

// tr(M^-1) from the eigenvalues, independently of the reader's formula.
double TraceInverse(const Eigen::MatrixXd& M) {
  return Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(M)
      .eigenvalues()
      .cwiseInverse()
      .sum();
}

std::string Upper(const Eigen::MatrixXd& M) {
  std::ostringstream s;
  s.precision(17);
  for (int r = 0; r < M.rows(); ++r) {
    for (int c = r; c < M.cols(); ++c) s << " " << M(r, c);
  }
  return s.str();
}

std::string Numbers(std::initializer_list<double> values) {
  std::ostringstream s;
  s.precision(17);
  for (double v : values) s << " " << v;
  return s.str();
}

Eigen::Isometry3d MakeIsometry(const Eigen::Quaterniond& q,
                               const Eigen::Vector3d& t) {
  Eigen::Isometry3d x = Eigen::Isometry3d::Identity();
  x.linear() = q.normalized().toRotationMatrix();
  x.translation() = t;
  return x;
}

TEST(G2oLandmarkConventionsTest, Se2PointXyMeasurementIsInThePoseFrame) {
  // g2o: error = x_pose^-1 * p - z. Build z from a known pose and landmark.
  const double theta = 0.7;
  const Eigen::Vector2d t(1, -2), p(4, 3);
  const Eigen::Rotation2Dd R(theta);
  const Eigen::Vector2d z = R.inverse() * (p - t);
  Eigen::Matrix2d info;
  info << 40, 3, 3, 9;
  std::ostringstream text;
  text.precision(17);
  text << "VERTEX_SE2 1" << Numbers({t(0), t(1), theta}) << "\n"
       << "VERTEX_XY 2" << Numbers({p(0), p(1)}) << "\n"
       << "EDGE_SE2_XY 1 2" << Numbers({z(0), z(1)}) << Upper(info) << "\n";
  PoseGraph g;
  std::string error;
  ASSERT_TRUE(ReadText(text.str(), &g, &error)) << error;
  ASSERT_EQ(g.landmark_measurements.size(), 1u);
  const LandmarkMeasurement& m = g.landmark_measurements[0];
  EXPECT_NEAR(m.nu, 2 / TraceInverse(info), 1e-13 * m.nu);
  // The model's residual p - t - R z vanishes at the vertices.
  EXPECT_LT(EvaluateObjective(g, g.initial_poses, g.initial_landmarks), 1e-24);
  EXPECT_EQ(g.landmark_ids, std::vector<int64_t>{2});
  EXPECT_EQ(g.vertex_ids, std::vector<int64_t>{1});
}

TEST(G2oLandmarkConventionsTest, Se3TrackXyzAppliesTheSensorOffset) {
  // g2o: error = (x_pose * offset)^-1 * p - z.
  const Eigen::Isometry3d x = MakeIsometry(
      Eigen::Quaterniond(0.9, 0.2, -0.3, 0.1), Eigen::Vector3d(1, 2, 3));
  const Eigen::Isometry3d offset = MakeIsometry(
      Eigen::Quaterniond(0.5, -0.5, 0.5, 0.5), Eigen::Vector3d(0.1, 0, 0.3));
  const Eigen::Vector3d p(-2, 5, 1);
  const Eigen::Vector3d z = (x * offset).inverse() * p;
  Eigen::Matrix3d info;
  info << 30, 2, 1, 2, 20, -3, 1, -3, 10;
  const Eigen::Quaterniond qx(x.linear()), qo(offset.linear());
  std::ostringstream text;
  text.precision(17);
  text << "PARAMS_SE3OFFSET 4"
       << Numbers({offset.translation()(0), offset.translation()(1),
                   offset.translation()(2), qo.x(), qo.y(), qo.z(), qo.w()})
       << "\nVERTEX_SE3:QUAT 0"
       << Numbers({x.translation()(0), x.translation()(1), x.translation()(2),
                   qx.x(), qx.y(), qx.z(), qx.w()})
       << "\nVERTEX_TRACKXYZ 1" << Numbers({p(0), p(1), p(2)})
       << "\nEDGE_SE3_TRACKXYZ 0 1 4" << Numbers({z(0), z(1), z(2)})
       << Upper(info) << "\n";
  PoseGraph g;
  std::string error;
  G2oReadSummary summary;
  ASSERT_TRUE(ReadText(text.str(), &g, &error, &summary)) << error;
  EXPECT_EQ(summary.num_offset_parameters, 1);
  ASSERT_EQ(g.landmark_measurements.size(), 1u);
  EXPECT_NEAR(g.landmark_measurements[0].nu, 3 / TraceInverse(info), 1e-12);
  EXPECT_LT(EvaluateObjective(g, g.initial_poses, g.initial_landmarks), 1e-22);
  // The same line read with the identity offset does not fit the vertices:
  // the offset matters and is applied.
  std::string identity = text.str();
  identity.replace(identity.find("PARAMS_SE3OFFSET 4"), 18,
                   "PARAMS_SE3OFFSET 5 0 0 0 0 0 0 1\nPARAMS_SE3OFFSET 4");
  identity.replace(identity.find("EDGE_SE3_TRACKXYZ 0 1 4"), 23,
                   "EDGE_SE3_TRACKXYZ 0 1 5");
  ASSERT_TRUE(ReadText(identity, &g, &error)) << error;
  EXPECT_GT(EvaluateObjective(g, g.initial_poses, g.initial_landmarks), 0.1);
}

TEST(G2oLandmarkConventionsTest, PosePriorsSplitLikeEdges) {
  // EDGE_PRIOR_SE2: error = Z^-1 x; tau = 2 / tr(I_tt^-1), kappa = I33.
  Eigen::Matrix3d info;
  info << 40, 3, 1.5, 3, 25, -2, 1.5, -2, 700;
  std::ostringstream text;
  text.precision(17);
  text << "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n"
       << "EDGE_PRIOR_SE2 0 1.5 -2 0.3" << Upper(info) << "\n"
       << "EDGE_PRIOR_SE2 1 7 7 -0.5 0 0 0 0 0 12\n"  // Rotation only.
       << "EDGE_PRIOR_SE2_XY 1 3 4 5 1 6\n";          // Position only.
  PoseGraph g;
  std::string error;
  ASSERT_TRUE(ReadText(text.str(), &g, &error)) << error;
  ASSERT_EQ(g.priors.size(), 3u);
  const PosePrior& full = g.priors[0];
  EXPECT_EQ(full.i, 0);
  EXPECT_NEAR(full.tau, 2 / TraceInverse(info.topLeftCorner(2, 2)), 1e-12);
  EXPECT_EQ(full.kappa, 700);
  EXPECT_LE(RelativeError(full.R, Eigen::Rotation2Dd(0.3).toRotationMatrix()),
            1e-15);
  EXPECT_LE(RelativeError(full.t, Eigen::Vector2d(1.5, -2)), 1e-15);
  const PosePrior& rotation = g.priors[1];
  EXPECT_EQ(rotation.i, 1);
  EXPECT_EQ(rotation.tau, 0);
  EXPECT_EQ(rotation.kappa, 12);
  const PosePrior& position = g.priors[2];
  EXPECT_EQ(position.kappa, 0);
  Eigen::Matrix2d I;
  I << 5, 1, 1, 6;
  EXPECT_NEAR(position.tau, 2 / TraceInverse(I), 1e-13);
  EXPECT_LE(RelativeError(position.t, Eigen::Vector2d(3, 4)), 1e-15);
}

TEST(G2oLandmarkConventionsTest, Se3PriorAppliesARotationOffset) {
  // g2o: error = Z^-1 (x * offset); with offset = (R_off, 0) the prior is
  // R_x ~ R_Z R_off^T, t_x ~ t_Z.
  const Eigen::Isometry3d x = MakeIsometry(
      Eigen::Quaterniond(0.3, 0.2, -0.6, 0.1), Eigen::Vector3d(4, -1, 2));
  const Eigen::Isometry3d offset = MakeIsometry(
      Eigen::Quaterniond(0.8, 0.1, 0.4, -0.2), Eigen::Vector3d::Zero());
  const Eigen::Isometry3d Z = x * offset;  // An exact prior.
  const Eigen::Quaterniond qz(Z.linear()), qo(offset.linear()), qx(x.linear());
  Eigen::Matrix<double, 6, 6> info = Eigen::Matrix<double, 6, 6>::Identity();
  info.topLeftCorner<3, 3>() << 9, 1, 0, 1, 8, 2, 0, 2, 7;
  info.bottomRightCorner<3, 3>() *= 40;
  std::ostringstream text;
  text.precision(17);
  text << "PARAMS_SE3OFFSET 2"
       << Numbers({0, 0, 0, qo.x(), qo.y(), qo.z(), qo.w()})
       << "\nVERTEX_SE3:QUAT 0"
       << Numbers({x.translation()(0), x.translation()(1), x.translation()(2),
                   qx.x(), qx.y(), qx.z(), qx.w()})
       << "\nEDGE_SE3_PRIOR 0 2"
       << Numbers({Z.translation()(0), Z.translation()(1), Z.translation()(2),
                   qz.x(), qz.y(), qz.z(), qz.w()})
       << Upper(info) << "\nEDGE_SE3_XYZ_PRIOR 0 2 4 -1 2 5 0 0 5 0 5\n";
  PoseGraph g;
  std::string error;
  ASSERT_TRUE(ReadText(text.str(), &g, &error)) << error;
  ASSERT_EQ(g.priors.size(), 2u);
  EXPECT_NEAR(g.priors[0].tau, 3 / TraceInverse(info.topLeftCorner(3, 3)),
              1e-12);
  EXPECT_NEAR(g.priors[0].kappa, 3 / (2 * 3 / 40.0), 1e-12);
  // The XYZ prior ignores its offset (as g2o's computeError does).
  EXPECT_NEAR(g.priors[1].tau, 5, 1e-14);
  EXPECT_EQ(g.priors[1].kappa, 0);
  EXPECT_LT(EvaluateObjective(g, g.initial_poses), 1e-22);
}

TEST(G2oLandmarkReadTest, LandmarksAndPriorsConnectTheGraph) {
  std::string error;
  PoseGraph g;
  // Two pose islands sharing a landmark: connected.
  ASSERT_TRUE(
      ReadText("EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n"
               "EDGE_SE2 2 3 1 0 0 1 0 0 1 0 1\n"
               "EDGE_SE2_XY 1 9 1 0 1 0 1\n"
               "EDGE_SE2_XY 2 9 -1 0 1 0 1\n",
               &g, &error))
      << error;
  EXPECT_EQ(g.num_poses, 4);
  EXPECT_EQ(g.num_landmarks, 1);
  // Two islands, each with a prior: connected through the world frame.
  ASSERT_TRUE(
      ReadText("EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n"
               "EDGE_SE2 2 3 1 0 0 1 0 0 1 0 1\n"
               "EDGE_PRIOR_SE2_XY 0 0 0 1 0 1\n"
               "EDGE_PRIOR_SE2 3 5 0 0 1 0 0 1 0 1\n",
               &g, &error))
      << error;
  EXPECT_EQ(g.priors.size(), 2u);
  // A landmark seen by one pose, and a prior-only single pose.
  ASSERT_TRUE(ReadText("EDGE_SE2_XY 0 9 1 0 1 0 1\n", &g, &error)) << error;
  ASSERT_TRUE(ReadText("EDGE_PRIOR_SE2_XY 0 0 0 1 0 1\n", &g, &error)) << error;
  EXPECT_EQ(g.num_poses, 1);
}

// ---- bad input
// ---------------------------------------------------------------

struct BadLine {
  const char* name;
  std::string text;
  int line;
  const char* contains;
};

const std::string kEdge = "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n";
const std::string kEdge3 =
    "EDGE_SE3:QUAT 0 1 1 0 0 0 0 0 1 1 0 0 0 0 0 1 0 0 0 0 1 0 0 0 1 0 0 1 0 "
    "1\n";
const std::string kParams = "PARAMS_SE3OFFSET 0 0 0 0 0 0 0 1\n";
const std::string kI6 = " 1 0 0 0 0 0 1 0 0 0 0 1 0 0 0 1 0 0 1 0 1";

std::vector<BadLine> BadLines() {
  return {
      {"LandmarkEdgeShort", kEdge + "EDGE_SE2_XY 0 5 1 2 1 0\n", 2,
       "EDGE_SE2_XY needs 7 fields, found 6"},
      {"LandmarkEdgeTrailing", kEdge + "EDGE_SE2_XY 0 5 1 2 1 0 1 4\n", 2,
       "unexpected trailing '4'"},
      {"LandmarkEdgeNaN", kEdge + "EDGE_SE2_XY 0 5 nan 2 1 0 1\n", 2,
       "'nan' is not finite"},
      {"LandmarkEdgeBadId", kEdge + "EDGE_SE2_XY 0 x5 1 2 1 0 1\n", 2,
       "'x5' is not a vertex id"},
      {"LandmarkEdgeNotPositiveDefinite", kEdge + "EDGE_SE2_XY 0 5 1 2 1 2 1\n",
       2, "translational information matrix is not positive definite"},
      {"LandmarkEdgeSelfLoop", kEdge + "EDGE_SE2_XY 1 1 1 2 1 0 1\n", 2,
       "self-loop"},
      {"LandmarkVertexShort", kEdge + "VERTEX_XY 5 1\n", 2,
       "VERTEX_XY needs 3 fields, found 2"},
      {"LandmarkVertexInf", kEdge + "VERTEX_XY 5 1 inf\n", 2, "not finite"},
      {"LandmarkVertexDuplicatesPose",
       "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nVERTEX_XY 1 2 3\n" + kEdge, 3,
       "duplicate VERTEX id 1 (first defined on line 2)"},
      {"PoseVertexDuplicatesLandmark",
       "VERTEX_XY 1 2 3\nVERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\n" + kEdge, 3,
       "duplicate VERTEX id 1 (first defined on line 1)"},
      {"DuplicateLandmarkVertex",
       kEdge + "VERTEX_XY 5 2 3\nVERTEX_XY 5 2 3\nEDGE_SE2_XY 0 5 1 2 1 0 1\n",
       3, "duplicate VERTEX id 5 (first defined on line 2)"},
      {"UnobservedLandmark", kEdge + "VERTEX_XY 5 2 3\n", 2,
       "landmark 5 is not observed by any EDGE_SE2_XY line"},
      {"PoseUsedAsLandmark", kEdge + "EDGE_SE2_XY 0 1 1 2 1 0 1\n", 2,
       "vertex 1 is a pose (line 1), but this edge uses it as a landmark"},
      {"LandmarkUsedAsPose",
       "VERTEX_XY 1 0 0\n" + kEdge + "EDGE_SE2_XY 0 1 1 2 1 0 1\n", 2,
       "vertex 1 is a landmark (line 1), but this edge uses it as a pose"},
      {"EdgeToLandmarkWithoutVertex",
       kEdge + "VERTEX_XY 5 2 3\nEDGE_SE2_XY 0 5 1 2 1 0 1\n"
               "EDGE_SE2_XY 0 6 1 2 1 0 1\n",
       4, "edge refers to landmark 6, which has no VERTEX_XY line"},
      {"PriorToPoseWithoutVertex",
       "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\n" + kEdge +
           "EDGE_PRIOR_SE2_XY 7 0 0 1 0 1\n",
       4, "edge refers to vertex 7, which has no VERTEX line"},
      {"DisconnectedLandmarkIsland",
       kEdge + "EDGE_SE2_XY 0 5 1 2 1 0 1\nEDGE_SE2_XY 7 8 1 2 1 0 1\n", 3,
       "disconnected: 2 components of sizes 3, 2; vertex 7"},
      {"LandmarkInA3DFile", kEdge3 + "VERTEX_XY 5 1 2\n", 2,
       "mixed 2D and 3D tags"},
      {"TiedOnlyByARotationPrior",
       kEdge + "EDGE_SE2 2 3 1 0 0 1 0 0 1 0 1\n"
               "EDGE_PRIOR_SE2_XY 0 0 0 1 0 1\n"
               "EDGE_PRIOR_SE2 3 0 0 0 0 0 0 0 0 1\n",
       2,
       "translational terms are disconnected: 2 components; vertex 2 (first "
       "seen here) is tied to vertex 0 only through rotation priors"},
      {"PriorNoInformation", kEdge + "EDGE_PRIOR_SE2 0 0 0 0 0 0 0 0 0 0\n", 2,
       "the prior carries no information"},
      {"PriorRotationBlockNegative",
       kEdge + "EDGE_PRIOR_SE2 0 0 0 0 1 0 0 1 0 -1\n", 2,
       "rotational information block is neither positive definite nor zero"},
      {"PriorTranslationBlockIndefinite",
       kEdge + "EDGE_PRIOR_SE2 0 0 0 0 1 2 0 1 0 1\n", 2,
       "translational information block is neither positive definite nor "
       "zero"},
      {"PositionPriorNotPositiveDefinite",
       kEdge + "EDGE_PRIOR_SE2_XY 0 0 0 1 0 0\n", 2,
       "translational information matrix is not positive definite"},
      {"PositionPriorShort", kEdge + "EDGE_PRIOR_SE2_XY 0 0 0 1 0\n", 2,
       "EDGE_PRIOR_SE2_XY needs 6 fields, found 5"},
      {"FixWithPriors", kEdge + "EDGE_PRIOR_SE2_XY 0 0 0 1 0 1\nFIX 0\n", 3,
       "FIX together with priors (first prior on line 2)"},
      {"FixOfALandmark", kEdge + "EDGE_SE2_XY 0 5 1 2 1 0 1\nFIX 5\n", 3,
       "FIX refers to landmark 5"},
      {"TrackXyzUndefinedParameter",
       kEdge3 + "EDGE_SE3_TRACKXYZ 0 5 3 1 2 3 1 0 0 1 0 1\n", 2,
       "parameter 3 is not defined"},
      {"TrackXyzParameterAfterUse",
       kEdge3 + "EDGE_SE3_TRACKXYZ 0 5 0 1 2 3 1 0 0 1 0 1\n" + kParams, 2,
       "parameter 0 is not defined"},
      {"TrackXyzBadParameterId",
       kParams + kEdge3 + "EDGE_SE3_TRACKXYZ 0 5 -1 1 2 3 1 0 0 1 0 1\n", 3,
       "'-1' is not a parameter id"},
      {"TrackXyzShort", kParams + kEdge3 + "EDGE_SE3_TRACKXYZ 0 5 0 1 2 3\n", 3,
       "EDGE_SE3_TRACKXYZ needs 12 fields, found 6"},
      {"DuplicateParameter", kParams + kParams + kEdge3, 2,
       "duplicate PARAMS_SE3OFFSET id 0 (first defined on line 1)"},
      {"ParameterBadQuaternion", "PARAMS_SE3OFFSET 0 0 0 0 0 0 0 2\n" + kEdge3,
       1, "has norm 2"},
      {"Se3PriorTranslationalOffset",
       "PARAMS_SE3OFFSET 1 0 0.5 0 0 0 0 1\n" + kEdge3 +
           "EDGE_SE3_PRIOR 0 1 0 0 0 0 0 0 1" + kI6 + "\n",
       3, "only offsets without translation are supported"},
      {"Se3PriorBadQuaternion",
       kParams + kEdge3 + "EDGE_SE3_PRIOR 0 0 0 0 0 0 0 0 0.5" + kI6 + "\n", 3,
       "has norm 0.5"},
      {"Se3PriorUndefinedParameter",
       kEdge3 + "EDGE_SE3_PRIOR 0 0 0 0 0 0 0 0 1" + kI6 + "\n", 2,
       "parameter 0 is not defined"},
      {"Se3XyzPriorNotPositiveDefinite",
       kParams + kEdge3 + "EDGE_SE3_XYZ_PRIOR 0 0 1 2 3 1 0 0 -1 0 1\n", 3,
       "translational information matrix is not positive definite"},
      {"UnsupportedLandmarkPrior", kEdge + "EDGE_PRIOR_XY 5 0 0 1 0 1\n", 2,
       "unsupported tag 'EDGE_PRIOR_XY'"},
      {"UnsupportedBearing", kEdge + "EDGE_BEARING_SE2_XY 0 5 0.3 1\n", 2,
       "unsupported tag 'EDGE_BEARING_SE2_XY'"},
  };
}

class BadLandmarkLineTest : public testing::TestWithParam<BadLine> {};

TEST_P(BadLandmarkLineTest, FailsNamingFileAndLine) {
  const BadLine& bad = GetParam();
  const std::string path = TempPath(std::string("bad_") + bad.name + ".g2o");
  WriteText(path, bad.text);
  PoseGraph graph;
  std::string error;
  EXPECT_FALSE(ReadG2oFile(path, {}, &graph, &error));
  const std::string where = path + ":" + std::to_string(bad.line) + ": ";
  EXPECT_EQ(error.rfind(where, 0), 0u)
      << "expected prefix '" << where << "' in: " << error;
  EXPECT_NE(error.find(bad.contains), std::string::npos)
      << "expected '" << bad.contains << "' in: " << error;
  std::remove(path.c_str());
}

INSTANTIATE_TEST_SUITE_P(Cases, BadLandmarkLineTest,
                         testing::ValuesIn(BadLines()),
                         [](const testing::TestParamInfo<BadLine>& info) {
                           return info.param.name;
                         });

TEST(G2oSolutionTest, BadSolutionFilesFailNamingFileAndLine) {
  PoseGraph graph;
  std::string error;
  ASSERT_TRUE(ReadText(kEdge + "EDGE_SE2_XY 0 5 1 2 1 0 1\n"
                               "EDGE_SE2_XY 1 6 1 2 1 0 1\n",
                       &graph, &error))
      << error;
  const std::string poses = "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0\n";
  const struct {
    std::string text;
    int line;
    const char* contains;
  } cases[] = {
      {poses + "VERTEX_XY 5 1 2\n", 3, "no VERTEX line for landmark 6"},
      {poses + "VERTEX_XY 5 1 2\nVERTEX_XY 5 1 2\n", 4,
       "duplicate VERTEX id 5 (first defined on line 3)"},
      {poses + "VERTEX_XY 7 1 2\n", 3, "vertex 7 is not a landmark"},
      {poses + "VERTEX_XY 5 1\n", 3, "VERTEX_XY needs 3 fields"},
      {poses + "VERTEX_TRACKXYZ 5 1 2 3\n", 3, "for a 2D pose graph"},
  };
  const std::string path = TempPath("bad_solution.g2o");
  for (const auto& c : cases) {
    WriteText(path, c.text);
    Solution solution;
    EXPECT_FALSE(ReadG2oSolution(path, graph, &solution, &error));
    const std::string where = path + ":" + std::to_string(c.line) + ": ";
    EXPECT_EQ(error.rfind(where, 0), 0u) << error;
    EXPECT_NE(error.find(c.contains), std::string::npos) << error;
  }
  // Writers refuse a wrong number of landmark positions, writing nothing.
  Solution wrong{IdentityPoses(2, 2), {Eigen::Vector2d(1, 2)}};
  EXPECT_FALSE(WriteG2oSolution(path + ".out", graph, wrong, &error));
  EXPECT_NE(error.find("expected 2 landmark positions"), std::string::npos)
      << error;
  EXPECT_FALSE(
      WriteG2oFile(path + ".out", graph, wrong.poses, wrong.landmarks, &error));
  std::ifstream out(path + ".out");
  EXPECT_FALSE(out.good());
  std::remove(path.c_str());
}

}  // namespace
}  // namespace ceres_sesync
