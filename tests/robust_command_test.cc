// `ceres_sesync generate outliers` and `ceres_sesync solve --robust`: the
// indices written by the generator are exactly the JSON's outlier_edges,
// the CSV edge report has one line per EDGE line, the exit code follows the
// inlier problem's certificate, and bad options fail with exit 2 and no
// output file.

#include <algorithm>
#include <cstdio>  // std::remove
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "gtest/gtest.h"
#include "tests/util/tool_runner.h"

namespace ceres_sesync {
namespace {

using test_util::FileExists;
using test_util::RunTool;

std::string TempPath(const std::string& name) {
  return std::string(CERES_SESYNC_BINARY_DIR) + "/robust_command_test_" + name;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<int> ReadIndices(const std::string& path) {
  std::ifstream in(path);
  std::vector<int> v;
  for (int k; in >> k;) v.push_back(k);
  return v;
}

// The integers of the JSON array after "key": [ (the writer's layout).
std::vector<int> JsonInts(const std::string& json, const std::string& key) {
  std::vector<int> v;
  size_t at = json.find("\"" + key + "\": [");
  if (at == std::string::npos) return {-1};
  at += key.size() + 5;
  const size_t end = json.find(']', at);
  std::stringstream items(json.substr(at, end - at));
  for (std::string item; std::getline(items, item, ',');) {
    if (item.find_first_not_of(" \n") != std::string::npos) {
      v.push_back(std::stoi(item));
    }
  }
  return v;
}

int CountLines(const std::string& text) {
  int lines = 0;
  for (char c : text) lines += c == '\n';
  return lines;
}

TEST(RobustCommand, GeneratedOutliersAreTheRejectedEdges) {
  if (!test_util::ToolBuilt()) GTEST_SKIP() << "the tool is not built";
  const std::string clean = TempPath("clean.g2o");
  const std::string corrupted = TempPath("corrupted.g2o");
  const std::string indices = TempPath("indices.txt");
  const std::string json = TempPath("robust.json");
  const std::string csv = TempPath("edges.csv");
  const std::string poses = TempPath("poses.g2o");
  ASSERT_EQ(RunTool("generate cube --side 4 --kappa 200 --tau 200 --seed 2 "
                    "--loop_closure_probability 0.5 --output " +
                    clean),
            0);
  ASSERT_EQ(RunTool("generate outliers " + clean +
                    " --fraction 0.4 --seed 3 --output " + corrupted +
                    " --outlier_indices " + indices),
            0);
  const std::vector<int> added = ReadIndices(indices);
  ASSERT_GT(added.size(), 5u);
  ASSERT_EQ(RunTool("solve " + corrupted + " --robust --json " + json +
                    " --edge_report " + csv + " --output " + poses),
            0);
  const std::string text = ReadFile(json);
  EXPECT_NE(text.find("\"robust\": true"), std::string::npos) << text;
  EXPECT_NE(text.find("\"certified\": true"), std::string::npos);
  EXPECT_NE(text.find("\"robust_status\": \"CONVERGED\""), std::string::npos);
  EXPECT_EQ(JsonInts(text, "outlier_edges"), added);
  EXPECT_NE(text.find("\"num_outliers\": " + std::to_string(added.size())),
            std::string::npos);
  // Header + one line per EDGE line of the input.
  const std::string report = ReadFile(csv);
  const std::string graph_text = ReadFile(corrupted);
  int edges = 0;
  for (size_t at = 0;
       (at = graph_text.find("\nEDGE_", at)) != std::string::npos; ++at) {
    ++edges;
  }
  EXPECT_EQ(CountLines(report), edges + 1);
  EXPECT_EQ(report.rfind("edge,vertex_i,vertex_j,weight,inlier,", 0), 0u);
  EXPECT_TRUE(FileExists(poses));

  // --max_time limits the whole robust solve: out of time, TIME_LIMIT, not
  // certified (exit 1), the verdicts of where it stopped.
  const std::string limited_json = TempPath("limited.json");
  EXPECT_EQ(RunTool("solve " + corrupted + " --robust --max_time 0.0001 " +
                    "--json " + limited_json),
            1);
  const std::string limited = ReadFile(limited_json);
  EXPECT_NE(limited.find("\"robust_status\": \"TIME_LIMIT\""),
            std::string::npos)
      << limited;
  EXPECT_NE(limited.find("\"certified\": false"), std::string::npos);
  std::remove(limited_json.c_str());

  // The default indices path, and the plain solve is not robust.
  const std::string corrupted2 = TempPath("corrupted2.g2o");
  ASSERT_EQ(RunTool("generate outliers " + clean +
                    " --fraction 0.2 --mode clustered --cluster_size 3 "
                    "--output " +
                    corrupted2),
            0);
  EXPECT_TRUE(FileExists(corrupted2 + ".outliers.txt"));
  const std::string plain_json = TempPath("plain.json");
  RunTool("solve " + corrupted2 + " --json " + plain_json);
  EXPECT_EQ(ReadFile(plain_json).find("\"robust\""), std::string::npos);

  for (const std::string& path :
       {clean, corrupted, indices, json, csv, poses, corrupted2,
        corrupted2 + ".outliers.txt", plain_json}) {
    std::remove(path.c_str());
  }
}

TEST(RobustCommand, BadOptionsFailWithoutOutput) {
  if (!test_util::ToolBuilt()) GTEST_SKIP() << "the tool is not built";
  const std::string clean = TempPath("bad_clean.g2o");
  const std::string out = TempPath("bad_out.g2o");
  ASSERT_EQ(RunTool("generate cube --side 3 --output " + clean), 0);
  for (const std::string& args :
       {std::string("generate outliers ") + clean + " --output " + out,
        "generate outliers " + clean + " --fraction 1.5 --output " + out,
        "generate outliers " + clean + " --fraction 0.3 --mode x --output " +
            out,
        "generate outliers " + clean + " --fraction 0.3 --side 3 --output " +
            out,
        "generate outliers " + clean +
            " --fraction 0.3 --cluster_size 3 "
            "--output " +
            out,
        "generate outliers " + TempPath("missing.g2o") +
            " --fraction 0.3 --output " + out,
        "generate cube --side 3 --fraction 0.3 --output " + out,
        "solve " + clean + " --edge_report " + out,
        "solve " + clean + " --robust --known_inliers some --output " + out,
        "solve " + clean + " --robust --inlier_probability 1 --output " +
            out}) {
    EXPECT_EQ(RunTool(args), 2) << args;
    EXPECT_FALSE(FileExists(out)) << args;
    EXPECT_FALSE(FileExists(out + ".outliers.txt")) << args;
  }
  std::remove(clean.c_str());
}

// A noiseless 3D landmark graph with GPS priors plus wrong associations
// and false fixes, through the tools: the indices file lists them
// ("landmark K", "prior K"), the JSON's outlier_priors are exactly the
// false fixes, as many landmark measurements are rejected as were added
// and all but a few of them are wrong associations (the others are ties: a
// landmark one pose alone observes truly is fit as well by one wrong
// association); the solution file has the landmarks.
TEST(RobustCommand, WrongAssociationsAndFalseFixesThroughTheTools) {
  if (!test_util::ToolBuilt()) GTEST_SKIP() << "the tool is not built";
  const std::string clean = TempPath("lm_clean.g2o");
  const std::string corrupted = TempPath("lm_corrupted.g2o");
  const std::string indices = TempPath("lm_indices.txt");
  const std::string json = TempPath("lm_robust.json");
  const std::string solution = TempPath("lm_solution.g2o");
  ASSERT_EQ(RunTool("generate landmarks --dimension 3 --num_poses 200 "
                    "--num_landmarks 150 --world_size 16 --gps_interval 10 "
                    "--start_prior --landmark_nu 400 --noiseless --seed 2 "
                    "--output " +
                    clean),
            0);
  ASSERT_EQ(RunTool("generate outliers " + clean +
                    " --landmark_fraction 0.3 --prior_fraction 0.3 --seed 5 "
                    "--output " +
                    corrupted + " --outlier_indices " + indices),
            0);
  std::vector<int> landmarks, priors;
  {
    std::ifstream in(indices);
    std::string kind;
    for (int k; in >> kind >> k;) {
      (kind == "landmark" ? landmarks : priors).push_back(k);
      EXPECT_TRUE(kind == "landmark" || kind == "prior") << kind;
    }
  }
  ASSERT_GT(landmarks.size(), 100u);
  ASSERT_GT(priors.size(), 3u);
  ASSERT_EQ(RunTool("solve " + corrupted + " --robust --json " + json +
                    " --output " + solution),
            0);
  const std::string text = ReadFile(json);
  EXPECT_NE(text.find("\"certified\": true"), std::string::npos);
  EXPECT_EQ(JsonInts(text, "outlier_priors"), priors);
  EXPECT_TRUE(JsonInts(text, "outlier_edges").empty());
  const std::vector<int> rejected =
      JsonInts(text, "outlier_landmark_measurements");
  EXPECT_EQ(rejected.size(), landmarks.size());
  int rejected_wrong = 0;
  for (int k : rejected) {
    rejected_wrong += std::count(landmarks.begin(), landmarks.end(), k);
  }
  // At most a few ties (here 3 of the 378).
  EXPECT_GE(rejected_wrong, static_cast<int>(landmarks.size()) - 5);
  const std::string written = ReadFile(solution);
  EXPECT_NE(written.find("VERTEX_TRACKXYZ"), std::string::npos);
}

}  // namespace
}  // namespace ceres_sesync
