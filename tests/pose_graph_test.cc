#include "ceres_sesync/pose_graph.h"

#include "gtest/gtest.h"

namespace ceres_sesync {
namespace {

TEST(PoseGraphTest, ConnectedComponentsCountsIslands) {
  PoseGraph g;
  g.dimension = 2;
  for (int v : {10, 20, 30, 40}) g.AddVertex(v);
  RelativePoseMeasurement e;
  e.R = Eigen::MatrixXd::Identity(2, 2);
  e.t = Eigen::VectorXd::Zero(2);
  e.kappa = e.tau = 1;
  e.i = 0, e.j = 1;
  g.measurements.push_back(e);
  e.i = 2, e.j = 3;
  g.measurements.push_back(e);
  std::vector<int> label;
  EXPECT_EQ(ConnectedComponents(g, &label), 2);
  EXPECT_EQ(label[0], label[1]);
  EXPECT_NE(label[1], label[2]);
  std::string error;
  EXPECT_FALSE(ValidatePoseGraph(g, &error));
  EXPECT_NE(error.find("disconnected"), std::string::npos);
  EXPECT_EQ(g.FindVertex(30), 2);
  EXPECT_EQ(g.FindVertex(31), -1);
}

}  // namespace
}  // namespace ceres_sesync
