#include "ceres_sesync/g2o_io.h"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "Eigen/Eigenvalues"
#include "Eigen/Geometry"
#include "ceres_sesync/internal/file_util.h"
#include "gtest/gtest.h"

namespace ceres_sesync {
namespace {

namespace fs = std::filesystem;

// Round trips go through text written in the shortest exact form, but the
// reader recomputes tau and kappa as e.g. 2 / (2 / tau) and rotations via
// angles / quaternions, which costs a few ulps: 1e-12 relative is far above
// that and far below any real error.
constexpr double kRoundTripTolerance = 1e-12;

// A fresh path in the test's temporary directory.
std::string TempPath(const std::string& name) {
  return testing::TempDir() + "g2o_io_test_" + std::to_string(getpid()) + "_" +
         name;
}

void WriteText(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  ASSERT_TRUE(out.good()) << path;
}

Eigen::MatrixXd RandomRotation(int d, std::mt19937* rng) {
  std::normal_distribution<double> normal;
  if (d == 2) {
    const double theta = 3 * normal(*rng);
    return Eigen::Rotation2Dd(theta).toRotationMatrix();
  }
  Eigen::Quaterniond q(normal(*rng), normal(*rng), normal(*rng), normal(*rng));
  return q.normalized().toRotationMatrix();
}

Eigen::VectorXd RandomVector(int d, std::mt19937* rng) {
  std::normal_distribution<double> normal(0, 10);
  Eigen::VectorXd v(d);
  for (int k = 0; k < d; ++k) v(k) = normal(*rng);
  return v;
}

// A connected graph on sparse, unordered ids with a parallel edge, random
// measurements, precisions and initial poses, and a fixed pose.
PoseGraph MakeGraph(int d, std::mt19937* rng) {
  PoseGraph graph;
  graph.dimension = d;
  for (int64_t id : std::vector<int64_t>{50, 7, 123456789012LL, 0, 9})
    graph.AddVertex(id);
  std::uniform_real_distribution<double> weight(0.1, 1e4);
  const std::vector<std::pair<int, int>> edges = {
      {0, 1}, {1, 2}, {2, 3}, {3, 4}, {4, 0}, {1, 3}, {1, 3}};
  for (auto [i, j] : edges) {
    RelativePoseMeasurement m;
    m.i = i;
    m.j = j;
    m.R = RandomRotation(d, rng);
    m.t = RandomVector(d, rng);
    m.kappa = weight(*rng);
    m.tau = weight(*rng);
    graph.measurements.push_back(m);
  }
  for (int k = 0; k < graph.num_poses; ++k) {
    graph.initial_poses.push_back(
        {RandomRotation(d, rng), RandomVector(d, rng)});
  }
  graph.fixed_pose = 3;
  return graph;
}

void ExpectNear(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  ASSERT_EQ(a.rows(), b.rows());
  ASSERT_EQ(a.cols(), b.cols());
  EXPECT_LE((a - b).norm(), kRoundTripTolerance * std::max(1.0, b.norm()))
      << a << "\nvs\n"
      << b;
}

void ExpectRelativeNear(double a, double b) {
  EXPECT_LE(std::abs(a - b), kRoundTripTolerance * std::abs(b))
      << a << " vs " << b;
}

// Expects graph `b` to equal `a` up to the dense order, matching poses by id.
void ExpectSameGraph(const PoseGraph& a, const PoseGraph& b) {
  ASSERT_EQ(a.dimension, b.dimension);
  ASSERT_EQ(a.num_poses, b.num_poses);
  ASSERT_EQ(a.measurements.size(), b.measurements.size());
  for (size_t k = 0; k < a.measurements.size(); ++k) {
    const auto& ma = a.measurements[k];
    const auto& mb = b.measurements[k];
    EXPECT_EQ(a.vertex_ids[ma.i], b.vertex_ids[mb.i]);
    EXPECT_EQ(a.vertex_ids[ma.j], b.vertex_ids[mb.j]);
    ExpectNear(mb.R, ma.R);
    ExpectNear(mb.t, ma.t);
    ExpectRelativeNear(mb.kappa, ma.kappa);
    ExpectRelativeNear(mb.tau, ma.tau);
  }
}

class RoundTripTest : public testing::TestWithParam<int> {};

TEST_P(RoundTripTest, WriteThenReadReproducesTheGraph) {
  const int d = GetParam();
  std::mt19937 rng(d);
  const PoseGraph graph = MakeGraph(d, &rng);
  const std::string path = TempPath("round_trip.g2o");
  std::string error;
  ASSERT_TRUE(WriteG2oFile(path, graph, graph.initial_poses, &error)) << error;

  PoseGraph read;
  G2oReadSummary summary;
  ASSERT_TRUE(ReadG2oFile(path, {}, &read, &error, &summary)) << error;
  // With VERTEX lines the dense order is the vertex order: identical.
  EXPECT_EQ(read.vertex_ids, graph.vertex_ids);
  ExpectSameGraph(graph, read);
  for (size_t k = 0; k < graph.measurements.size(); ++k) {
    EXPECT_EQ(read.measurements[k].i, graph.measurements[k].i);
    EXPECT_EQ(read.measurements[k].j, graph.measurements[k].j);
  }
  ASSERT_EQ(read.initial_poses.size(), graph.initial_poses.size());
  for (int k = 0; k < graph.num_poses; ++k) {
    ExpectNear(read.initial_poses[k].R, graph.initial_poses[k].R);
    ExpectNear(read.initial_poses[k].t, graph.initial_poses[k].t);
  }
  EXPECT_EQ(read.fixed_pose, graph.fixed_pose);
  EXPECT_TRUE(summary.has_fix);
  EXPECT_EQ(summary.num_vertices, graph.num_poses);
  EXPECT_EQ(summary.num_edges, 7);
  EXPECT_EQ(summary.num_skipped_lines, 0);
  ExpectRelativeNear(EvaluateObjective(read, read.initial_poses),
                     EvaluateObjective(graph, graph.initial_poses));

  // Without poses: no VERTEX lines, poses in order of first appearance.
  ASSERT_TRUE(WriteG2oFile(path, graph, {}, &error)) << error;
  ASSERT_TRUE(ReadG2oFile(path, {}, &read, &error)) << error;
  EXPECT_TRUE(read.initial_poses.empty());
  ExpectSameGraph(graph, read);
  EXPECT_EQ(read.vertex_ids[read.fixed_pose],
            graph.vertex_ids[graph.fixed_pose]);
  std::remove(path.c_str());
}

INSTANTIATE_TEST_SUITE_P(Dimensions, RoundTripTest, testing::Values(2, 3));

// Reads `text` from a file and returns the graph (asserting success).
PoseGraph ReadText(const std::string& text, G2oReadSummary* summary = nullptr,
                   G2oReadOptions options = {}) {
  const std::string path = TempPath("good.g2o");
  WriteText(path, text);
  PoseGraph graph;
  std::string error;
  EXPECT_TRUE(ReadG2oFile(path, options, &graph, &error, summary)) << error;
  std::remove(path.c_str());
  return graph;
}

TEST(G2oReadTest, NonIsotropicInformation2D) {
  // A positive definite, non-diagonal 3x3 information matrix.
  Eigen::Matrix3d info;
  info << 40, 3, 1.5, 3, 25, -2, 1.5, -2, 700;
  ASSERT_EQ(info.llt().info(), Eigen::Success);
  // tau = 2 / trace(inverse(I_tt)), kappa = I33 (the reference convention).
  const double tau = 2 / info.topLeftCorner<2, 2>().inverse().trace();
  const double kappa = info(2, 2);

  std::ostringstream g2o, toro;
  g2o.precision(17);
  toro.precision(17);
  g2o << "EDGE_SE2 4 2 1.5 -0.5 0.3 " << info(0, 0) << " " << info(0, 1) << " "
      << info(0, 2) << " " << info(1, 1) << " " << info(1, 2) << " "
      << info(2, 2) << "\n";
  // TORO order: I11 I12 I22 I33 I13 I23.
  toro << "EDGE2 4 2 1.5 -0.5 0.3 " << info(0, 0) << " " << info(0, 1) << " "
       << info(1, 1) << " " << info(2, 2) << " " << info(0, 2) << " "
       << info(1, 2) << "\n";
  for (const std::string& text : {g2o.str(), toro.str()}) {
    const PoseGraph graph = ReadText(text);
    ASSERT_EQ(graph.measurements.size(), 1u);
    const auto& m = graph.measurements[0];
    EXPECT_NEAR(m.tau, tau, 1e-12 * tau);
    EXPECT_EQ(m.kappa, kappa);
    EXPECT_EQ(graph.vertex_ids, (std::vector<int64_t>{4, 2}));
    ExpectNear(m.R, Eigen::Rotation2Dd(0.3).toRotationMatrix());
    ExpectNear(m.t, Eigen::Vector2d(1.5, -0.5));
  }
}

TEST(G2oReadTest, NonIsotropicInformation3D) {
  // A random symmetric positive definite 6x6 information matrix.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(-1, 1);
  Eigen::Matrix<double, 6, 6> A;
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) A(r, c) = uniform(rng);
  }
  Eigen::Matrix<double, 6, 6> info =
      A * A.transpose() + 0.5 * Eigen::Matrix<double, 6, 6>::Identity();
  info.topLeftCorner<3, 3>() *= 100;  // Different scales for t and R.
  info.topRightCorner<3, 3>() *= 10;
  info.bottomLeftCorner<3, 3>() *= 10;
  // trace(inverse(M)) as the sum of inverse eigenvalues, independently of the
  // reader's matrix inverse.
  const auto trace_inverse = [](const Eigen::Matrix3d& M) {
    return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(M)
        .eigenvalues()
        .cwiseInverse()
        .sum();
  };
  const double tau = 3 / trace_inverse(info.topLeftCorner<3, 3>());
  const double kappa = 3 / (2 * trace_inverse(info.bottomRightCorner<3, 3>()));

  const Eigen::Quaterniond q(0.92, 0.1, -0.3, 0.2);  // |q| = 0.993.
  std::ostringstream text;
  text.precision(17);
  text << "EDGE_SE3:QUAT 0 1 1 2 3 " << q.x() << " " << q.y() << " " << q.z()
       << " " << q.w();
  for (int r = 0; r < 6; ++r) {
    for (int c = r; c < 6; ++c) text << " " << info(r, c);
  }
  text << "\n";
  // Within the 1e-2 normalization tolerance.
  ASSERT_LT(std::abs(q.norm() - 1), 1e-2);
  G2oReadSummary summary;
  const PoseGraph graph = ReadText(text.str(), &summary);
  ASSERT_EQ(graph.measurements.size(), 1u);
  EXPECT_NEAR(graph.measurements[0].tau, tau, 1e-10 * tau);
  EXPECT_NEAR(graph.measurements[0].kappa, kappa, 1e-10 * kappa);
  ExpectNear(graph.measurements[0].R, q.normalized().toRotationMatrix());
  EXPECT_EQ(summary.num_normalized_quaternions, 1);
}

TEST(G2oReadTest, IndefiniteCrossTermsAreAcceptedAndCounted) {
  // Both diagonal blocks are the identity, but the z / rx cross term 2 makes
  // the full matrix indefinite (as in cubicle.g2o). kappa and tau only use the
  // blocks: tau = 3 / 3 = 1, kappa = 3 / (2 * 3) = 0.5.
  const std::string text =
      "EDGE_SE3:QUAT 0 1 1 0 0 0 0 0 1 1 0 0 0 0 0 1 0 0 0 0 1 2 0 0 1 0 0 1 0 "
      "1\n";
  G2oReadSummary summary;
  const PoseGraph graph = ReadText(text, &summary);
  ASSERT_EQ(graph.measurements.size(), 1u);
  EXPECT_EQ(summary.num_indefinite_information, 1);
  EXPECT_NEAR(graph.measurements[0].tau, 1, 1e-15);
  EXPECT_NEAR(graph.measurements[0].kappa, 0.5, 1e-15);
}

TEST(G2oReadTest, BlankLinesCommentsAndCrlfCarryNoEdges) {
  const std::string text =
      "# a comment\n"
      "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\r\n"
      "\n"
      "   \t \n"
      "EDGE_SE2 1 2 1 0 0 1 0 0 1 0 1\n"
      "\n";
  const PoseGraph graph = ReadText(text);
  EXPECT_EQ(graph.measurements.size(), 2u);
  EXPECT_EQ(graph.num_poses, 3);
  EXPECT_TRUE(graph.initial_poses.empty());
}

TEST(G2oReadTest, VertexLinesDefineThePoseOrderAndFixIsHonoured) {
  const std::string text =
      "EDGE_SE2 10 30 1 0 0 1 0 0 1 0 1\n"
      "EDGE_SE2 30 20 1 0 0 1 0 0 1 0 1\n"
      "VERTEX_SE2 20 1 2 0.5\n"
      "VERTEX_SE2 30 0 0 0\n"
      "VERTEX2 10 0 0 0\n"  // Legacy TORO tag, same layout.
      "FIX 30\n";
  G2oReadSummary summary;
  const PoseGraph graph = ReadText(text, &summary);
  EXPECT_EQ(graph.vertex_ids, (std::vector<int64_t>{20, 30, 10}));
  EXPECT_EQ(graph.fixed_pose, 1);
  EXPECT_TRUE(summary.has_fix);
  ASSERT_EQ(graph.initial_poses.size(), 3u);
  ExpectNear(graph.initial_poses[0].t, Eigen::Vector2d(1, 2));
  ExpectNear(graph.initial_poses[0].R,
             Eigen::Rotation2Dd(0.5).toRotationMatrix());
  EXPECT_EQ(graph.measurements[0].i, 2);
  EXPECT_EQ(graph.measurements[0].j, 1);
}

TEST(G2oReadTest, SkipOptionCountsUnsupportedLines) {
  const std::string text =
      "VERTEX_SE2 0 0 0 0\n"
      "VERTEX_SE2 1 0 0 0\n"
      "EDGE_PRIOR_XY 100 1 2 1 0 1\n"
      "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n"
      "EDGE_BEARING_SE2_XY 0 100 0.5 1\n"
      "EDGE_BEARING_SE2_XY 1 100 0.25 1\n";
  G2oReadOptions options;
  options.skip_unsupported_tags = true;
  G2oReadSummary summary;
  const PoseGraph graph = ReadText(text, &summary, options);
  EXPECT_EQ(graph.num_poses, 2);
  EXPECT_EQ(graph.measurements.size(), 1u);
  EXPECT_EQ(summary.num_skipped_lines, 3);
  EXPECT_EQ(summary.skipped_tags["EDGE_PRIOR_XY"], 1);
  EXPECT_EQ(summary.skipped_tags["EDGE_BEARING_SE2_XY"], 2);
}

TEST(G2oReadTest, ReadsFromAStream) {
  std::istringstream in("EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n");
  PoseGraph graph;
  std::string error;
  ASSERT_TRUE(ReadG2o(in, "memory", {}, &graph, &error)) << error;
  EXPECT_EQ(graph.measurements.size(), 1u);
  std::istringstream bad("EDGE_SE2 0 1 1 0 0 1 0 0 1 0\n");
  EXPECT_FALSE(ReadG2o(bad, "memory", {}, &graph, &error));
  EXPECT_EQ(error.rfind("memory:1: ", 0), 0u) << error;
}

// ---- bad input: each case fails with "PATH:LINE: message" ------------------

struct BadInput {
  const char* name;
  const char* text;
  int line;              // Line the message must name.
  const char* contains;  // Part of the message.
};

const char kEdge[] = "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n";
const char kEdge3D[] =
    "EDGE_SE3:QUAT 0 1 1 0 0 0 0 0 1 1 0 0 0 0 0 1 0 0 0 0 1 0 0 0 1 0 0 1 0 "
    "1\n";

std::vector<BadInput> BadInputs() {
  static const std::string e = kEdge, e3 = kEdge3D;
  static const std::vector<std::string> texts = {
      e + "EDGE_SE2 1 2 1 0 0 1 0 0 1 0\n",        // short
      e + "EDGE_SE2 1 2 1 0 0 1 0 0 1 0 1 7\n",    // trailing
      e + e + "EDGE_SE2 1 2 1 x 0 1 0 0 1 0 1\n",  // non-numeric
      e + "EDGE_SE2 1 2 1 0 nan 1 0 0 1 0 1\n",    // NaN
      e + "EDGE_SE2 1 2 1 0 0 1 0 0 inf 0 1\n",    // Inf
      e + "EDGE_SE2 1 2 1 0 0 1 0 0 1 0 1e999\n",  // overflow
      e + "EDGE_SE2 1 2.5 1 0 0 1 0 0 1 0 1\n",    // id not integer
      e + "EDGE_SE2 -1 2 1 0 0 1 0 0 1 0 1\n",     // negative id
      e + "EDGE_SE2 1 2 1 0 0 1 2 0 1 0 1\n",      // 2D not PD
      e + "EDGE_SE2 1 2 1 0 0 1 0 0 1 0 0\n",      // I33 = 0
      e3 + "EDGE_SE3:QUAT 1 2 1 0 0 0 0 0 1.5 1 0 0 0 0 0 1 0 0 0 0 1 0 0 0 "
           "1 0 0 1 0 1\n",  // |q| = 1.5
      e3 + "EDGE_SE3:QUAT 1 2 1 0 0 0 0 0 0 1 0 0 0 0 0 1 0 0 0 0 1 0 0 0 1 "
           "0 0 1 0 1\n",  // zero quaternion
      e3 + "EDGE_SE3:QUAT 1 2 1 0 0 0 0 0 1 1 0 0 0 0 0 1 0 0 0 0 1 0 0 0 1 "
           "2 0 1 0 1\n",                               // 3D I_RR not PD
      e + e3,                                           // mixed 2D/3D
      e + "EDGE_SE2 2 2 1 0 0 1 0 0 1 0 1\n",           // self-loop
      e + "EDGE_FOO 1 2\n",                             // unknown tag
      e + "EDGE_POINTXYZ_PRIOR 1 0 0 0 1 0 0 1 0 1\n",  // landmark prior
      e3 + "EDGE3 1 2 1 0 0 0 0 0 1 0 0 0 0 0 1 0 0 0 0 1 0 0 0 1 0 0 1 0 1\n",
      "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\n" + e +
          "EDGE_SE2 1 2 1 0 0 1 0 0 1 0 1\n",  // missing vertex
      "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nVERTEX_SE2 0 0 0 0\n" + e,
      "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1\nVERTEX_SE3:QUAT 1 0 0 0 0 0 0 0.5\n" +
          e3,                                  // bad vertex quat
      "",                                      // empty
      "# only a comment\n\n",                  // no edges
      e + "EDGE_SE2 2 3 1 0 0 1 0 0 1 0 1\n",  // two islands
      "VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 0 0 0\nVERTEX_SE2 7 0 0 0\n" + e,
      e + "FIX 5\n",         // FIX unknown
      e + "FIX 0\nFIX 1\n",  // two FIX
  };
  return {
      {"Short", texts[0].c_str(), 2, "needs 11 fields, found 10"},
      {"Trailing", texts[1].c_str(), 2, "unexpected trailing '7'"},
      {"NonNumeric", texts[2].c_str(), 3, "'x' is not a number"},
      {"NaN", texts[3].c_str(), 2, "'nan' is not finite"},
      {"Inf", texts[4].c_str(), 2, "'inf' is not finite"},
      {"Overflow", texts[5].c_str(), 2, "'1e999' is not finite"},
      {"FractionalId", texts[6].c_str(), 2, "'2.5' is not a vertex id"},
      {"NegativeId", texts[7].c_str(), 2, "'-1' is not a vertex id"},
      {"NotPositiveDefinite2D", texts[8].c_str(), 2,
       "translational information block is not positive definite"},
      {"ZeroRotationalInformation", texts[9].c_str(), 2,
       "rotational information block is not positive definite"},
      {"QuaternionNorm", texts[10].c_str(), 2, "has norm"},
      {"ZeroQuaternion", texts[11].c_str(), 2, "has norm 0"},
      {"NotPositiveDefinite3D", texts[12].c_str(), 2,
       "rotational information block is not positive definite"},
      {"Mixed2D3D", texts[13].c_str(), 2, "mixed 2D and 3D"},
      {"SelfLoop", texts[14].c_str(), 2, "self-loop"},
      {"UnknownTag", texts[15].c_str(), 2, "unsupported tag 'EDGE_FOO'"},
      {"LandmarkPriorTag", texts[16].c_str(), 2,
       "unsupported tag 'EDGE_POINTXYZ_PRIOR'"},
      {"LegacyEdge3", texts[17].c_str(), 2, "unsupported legacy tag 'EDGE3'"},
      {"EdgeToMissingVertex", texts[18].c_str(), 4,
       "vertex 2, which has no VERTEX line"},
      {"DuplicateVertex", texts[19].c_str(), 3,
       "duplicate VERTEX id 0 (first defined on line 1)"},
      {"BadVertexQuaternion", texts[20].c_str(), 2, "has norm 0.5"},
      {"Empty", texts[21].c_str(), 1, "no EDGE lines"},
      {"OnlyComments", texts[22].c_str(), 2, "no EDGE lines"},
      {"TwoIslands", texts[23].c_str(), 2,
       "disconnected: 2 components of sizes 2, 2; vertex 2"},
      {"UnconnectedVertex", texts[24].c_str(), 3,
       "disconnected: 2 components of sizes 2, 1; vertex 7"},
      {"FixUnknownVertex", texts[25].c_str(), 2, "FIX refers to vertex 5"},
      {"TwoFixVertices", texts[26].c_str(), 3, "a second FIX vertex"},
  };
}

class BadInputTest : public testing::TestWithParam<BadInput> {};

TEST_P(BadInputTest, FailsNamingFileAndLine) {
  const BadInput& bad = GetParam();
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
  // The skip option does not hide real errors (unsupported tags aside).
  G2oReadOptions skip;
  skip.skip_unsupported_tags = true;
  const bool skippable =
      std::string(bad.contains).rfind("unsupported tag", 0) == 0;
  EXPECT_EQ(ReadG2oFile(path, skip, &graph, &error), skippable) << error;
  std::remove(path.c_str());
}

INSTANTIATE_TEST_SUITE_P(Cases, BadInputTest, testing::ValuesIn(BadInputs()),
                         [](const testing::TestParamInfo<BadInput>& info) {
                           return info.param.name;
                         });

TEST(G2oReadTest, MissingFileFails) {
  PoseGraph graph;
  std::string error;
  const std::string path = TempPath("does_not_exist.g2o");
  EXPECT_FALSE(ReadG2oFile(path, {}, &graph, &error));
  EXPECT_NE(error.find(path), std::string::npos) << error;
}

// ---- poses files
// -------------------------------------------------------------

TEST(G2oPosesTest, WriteThenReadPoses) {
  for (int d : {2, 3}) {
    std::mt19937 rng(10 + d);
    const PoseGraph graph = MakeGraph(d, &rng);
    Poses poses;
    for (int k = 0; k < graph.num_poses; ++k) {
      poses.push_back({RandomRotation(d, &rng), RandomVector(d, &rng)});
    }
    const std::string path = TempPath("poses.g2o");
    std::string error;
    ASSERT_TRUE(WriteG2oPoses(path, graph, poses, &error)) << error;
    Poses read;
    ASSERT_TRUE(ReadG2oPoses(path, graph, &read, &error)) << error;
    ASSERT_EQ(read.size(), poses.size());
    for (size_t k = 0; k < poses.size(); ++k) {
      ExpectNear(read[k].R, poses[k].R);
      ExpectNear(read[k].t, poses[k].t);
    }
    // A whole graph file works as a poses file too (its edges are ignored).
    ASSERT_TRUE(WriteG2oFile(path, graph, poses, &error)) << error;
    ASSERT_TRUE(ReadG2oPoses(path, graph, &read, &error)) << error;
    ExpectNear(read[2].t, poses[2].t);
    std::remove(path.c_str());
  }
}

TEST(G2oPosesTest, BadPosesFilesFailNamingFileAndLine) {
  PoseGraph graph;
  graph.dimension = 2;
  graph.AddVertex(0);
  graph.AddVertex(1);
  const std::string v0 = "VERTEX_SE2 0 0 0 0\n";
  const struct {
    std::string text;
    int line;
    const char* contains;
  } cases[] = {
      {v0 + "VERTEX_SE2 5 0 0 0\n", 2, "vertex 5 is not in the pose graph"},
      {v0 + v0, 2, "duplicate VERTEX id 0"},
      {v0 + "VERTEX_SE3:QUAT 1 0 0 0 0 0 0 1\n", 2, "for a 2D pose graph"},
      {v0 + "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n", 2,
       "no VERTEX line for vertex 1"},
      {v0 + "VERTEX_SE2 1 0 nan 0\n", 2, "not finite"},
      {v0 + "VERTEX_SE2 1 0 0\n", 2, "needs 4 fields"},
  };
  const std::string path = TempPath("bad_poses.g2o");
  for (const auto& c : cases) {
    WriteText(path, c.text);
    Poses poses;
    std::string error;
    EXPECT_FALSE(ReadG2oPoses(path, graph, &poses, &error));
    const std::string where = path + ":" + std::to_string(c.line) + ": ";
    EXPECT_EQ(error.rfind(where, 0), 0u) << error;
    EXPECT_NE(error.find(c.contains), std::string::npos) << error;
  }
  // A bad quaternion in 3D.
  graph.dimension = 3;
  WriteText(
      path,
      "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1\nVERTEX_SE3:QUAT 1 0 0 0 0 0 0 2\n");
  Poses poses;
  std::string error;
  EXPECT_FALSE(ReadG2oPoses(path, graph, &poses, &error));
  EXPECT_EQ(error.rfind(path + ":2: ", 0), 0u) << error;
  std::remove(path.c_str());
}

// ---- TUM
// ---------------------------------------------------------------------

TEST(TumTest, ParsesBackToTheSamePoses) {
  for (int d : {2, 3}) {
    std::mt19937 rng(20 + d);
    const PoseGraph graph = MakeGraph(d, &rng);
    const std::string path = TempPath("trajectory.tum");
    std::string error;
    ASSERT_TRUE(WriteTumFile(path, graph, graph.initial_poses, &error))
        << error;
    std::ifstream in(path);
    std::string line;
    int k = 0;
    while (std::getline(in, line)) {
      ASSERT_LT(k, graph.num_poses);
      std::istringstream fields(line);
      int64_t stamp;
      double x, y, z, qx, qy, qz, qw;
      ASSERT_TRUE(fields >> stamp >> x >> y >> z >> qx >> qy >> qz >> qw)
          << line;
      std::string extra;
      EXPECT_FALSE(fields >> extra) << line;
      EXPECT_EQ(stamp, graph.vertex_ids[k]);
      const Pose& pose = graph.initial_poses[k];
      Eigen::Vector3d t = Eigen::Vector3d::Zero();
      Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
      t.head(d) = pose.t;
      R.topLeftCorner(d, d) = pose.R;
      ExpectNear(Eigen::Vector3d(x, y, z), t);
      const Eigen::Quaterniond q(qw, qx, qy, qz);
      EXPECT_NEAR(q.norm(), 1, 1e-15);
      ExpectNear(q.toRotationMatrix(), R);
      ++k;
    }
    EXPECT_EQ(k, graph.num_poses);
    std::remove(path.c_str());
  }
}

// ---- atomic writes
// -------------------------------------------------------------

// Names in `dir` containing ".tmp.".
int CountTemporaryFiles(const std::string& dir) {
  int count = 0;
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().filename().string().find(".tmp.") != std::string::npos) {
      ++count;
    }
  }
  return count;
}

TEST(AtomicWriteTest, MissingDirectoryLeavesNoFile) {
  std::mt19937 rng(1);
  const PoseGraph graph = MakeGraph(2, &rng);
  const std::string dir = TempPath("no_such_dir");
  const std::string path = dir + "/out.g2o";
  std::string error;
  EXPECT_FALSE(WriteG2oFile(path, graph, graph.initial_poses, &error));
  EXPECT_NE(error.find(path), std::string::npos) << error;
  EXPECT_FALSE(WriteG2oPoses(path, graph, graph.initial_poses, &error));
  EXPECT_FALSE(WriteTumFile(path, graph, graph.initial_poses, &error));
  EXPECT_FALSE(fs::exists(dir));
}

TEST(AtomicWriteTest, ReplacesExistingFilesAndLeavesNoTemporaries) {
  const std::string dir = TempPath("atomic_dir");
  fs::create_directories(dir);
  const std::string path = dir + "/out.txt";
  std::string error;
  ASSERT_TRUE(internal::WriteFileAtomically(path, "first", &error)) << error;
  ASSERT_TRUE(internal::WriteFileAtomically(path, "second", &error)) << error;
  std::string contents;
  ASSERT_TRUE(internal::ReadFileToString(path, &contents, &error)) << error;
  EXPECT_EQ(contents, "second");
  EXPECT_EQ(CountTemporaryFiles(dir), 0);
  // Renaming over a directory fails: the directory stays, no temporary left.
  fs::create_directories(dir + "/a_directory");
  EXPECT_FALSE(
      internal::WriteFileAtomically(dir + "/a_directory", "x", &error));
  EXPECT_TRUE(fs::is_directory(dir + "/a_directory"));
  EXPECT_EQ(CountTemporaryFiles(dir), 0);
  // Invalid poses are refused before anything is written.
  std::mt19937 rng(2);
  const PoseGraph graph = MakeGraph(3, &rng);
  Poses too_few(graph.initial_poses.begin(), graph.initial_poses.end() - 1);
  EXPECT_FALSE(WriteG2oPoses(dir + "/poses.g2o", graph, too_few, &error));
  EXPECT_FALSE(fs::exists(dir + "/poses.g2o"));
  fs::remove_all(dir);
}

// ---- the benchmark datasets
// ------------------------------------------------------

struct Dataset {
  const char* file;
  int dimension;
  int edges;
};

TEST(DatasetsTest, AllLoadWithTheExpectedSizes) {
  const std::string dir = CERES_SESYNC_DATA_DIR;
  if (dir.empty() || !fs::is_directory(dir)) {
    GTEST_SKIP() << "dataset directory '" << dir << "' not found";
  }
  const Dataset datasets[] = {
      {"CSAIL.g2o", 2, 1172},       {"intel.g2o", 2, 2512},
      {"manhattan.g2o", 2, 5453},   {"city10000.g2o", 2, 20687},
      {"ais2klinik.g2o", 2, 16727}, {"kitti_00.g2o", 2, 4677},
      {"tinyGrid3D.g2o", 3, 11},    {"smallGrid3D.g2o", 3, 297},
      {"sphere2500.g2o", 3, 4949},  {"parking-garage.g2o", 3, 6275},
      {"torus3D.g2o", 3, 9048},     {"cubicle.g2o", 3, 16869},
  };
  for (const Dataset& dataset : datasets) {
    SCOPED_TRACE(dataset.file);
    const std::string path = dir + "/" + dataset.file;
    if (!fs::exists(path)) {
      ADD_FAILURE() << "missing dataset " << path;
      continue;
    }
    // Scan the ids independently: distinct ids over VERTEX and EDGE lines.
    std::set<int64_t> ids;
    int vertex_lines = 0;
    {
      std::ifstream in(path);
      std::string line;
      while (std::getline(in, line)) {
        std::istringstream fields(line);
        std::string tag;
        int64_t a, b;
        if (!(fields >> tag)) continue;
        if (tag.rfind("VERTEX", 0) == 0 && fields >> a) {
          ids.insert(a);
          ++vertex_lines;
        } else if (tag.rfind("EDGE", 0) == 0 && fields >> a >> b) {
          ids.insert(a);
          ids.insert(b);
        }
      }
    }
    PoseGraph graph;
    G2oReadSummary summary;
    std::string error;
    const auto start = std::chrono::steady_clock::now();
    ASSERT_TRUE(ReadG2oFile(path, {}, &graph, &error, &summary)) << error;
    const double ms = std::chrono::duration<double, std::milli>(
                          std::chrono::steady_clock::now() - start)
                          .count();
    std::printf(
        "  %-20s d=%d poses=%6d edges=%6d normalized quaternions=%5d "
        "indefinite information=%5d read in %6.2f ms\n",
        dataset.file, graph.dimension, graph.num_poses,
        static_cast<int>(graph.measurements.size()),
        summary.num_normalized_quaternions, summary.num_indefinite_information,
        ms);
    EXPECT_EQ(graph.dimension, dataset.dimension);
    EXPECT_EQ(static_cast<int>(graph.measurements.size()), dataset.edges);
    EXPECT_EQ(graph.num_poses, static_cast<int>(ids.size()));
    EXPECT_EQ(*ids.rbegin() + 1, static_cast<int64_t>(ids.size()))
        << "these datasets use ids 0..n-1";
    EXPECT_EQ(summary.num_edges, dataset.edges);
    EXPECT_FALSE(summary.has_fix);
    EXPECT_EQ(summary.num_skipped_lines, 0);
    if (vertex_lines > 0) {
      ASSERT_EQ(static_cast<int>(graph.initial_poses.size()), graph.num_poses);
      const double f = EvaluateObjective(graph, graph.initial_poses);
      EXPECT_TRUE(std::isfinite(f) && f >= 0) << f;
    } else {
      EXPECT_TRUE(graph.initial_poses.empty());
    }
  }
}

}  // namespace
}  // namespace ceres_sesync
