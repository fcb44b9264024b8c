// Tests of the `ceres_sesync` program's command line (run as a separate
// process, as a user would): help, flag checking, progress output,
// `solve --components`, and landmarks and priors through solve and certify.

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/pose_graph.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"
#include "tests/util/json_validator.h"
#include "tests/util/tool_runner.h"

namespace ceres_sesync {
namespace {

namespace fs = std::filesystem;
using test_util::IsValidJson;
using test_util::JsonNumber;
using test_util::ReadText;
using test_util::RunResult;
using test_util::RunTool;
using test_util::RunToolWithOutput;
using test_util::TempPath;
using test_util::ValueAfter;
using test_util::WriteText;
using testing::HasSubstr;
using testing::Not;

class CliTest : public testing::Test {
 protected:
  void SetUp() override {
    if (std::string(CERES_SESYNC_TOOL).empty()) {
      GTEST_SKIP() << "the ceres_sesync program is not built";
    }
  }
};

const char* const kCommands[] = {"info", "solve", "certify", "generate"};

TEST_F(CliTest, HelpListsTheCommandsOwnFlagsWithTheirDefaults) {
  for (const char* args :
       {"help generate", "generate --help", "generate cube --help"}) {
    SCOPED_TRACE(args);
    const RunResult run = RunToolWithOutput(args);
    EXPECT_EQ(run.exit_code, 0) << run.output;
    EXPECT_THAT(run.out, HasSubstr("usage: ceres_sesync generate cube"));
    for (const char* flag :
         {"--side=10\n", "--dimension=3\n", "--loop_closure_probability=0.1\n",
          "--kappa=16.67\n", "--tau=75\n", "--seed=0\n", "--output=\"\"\n",
          "--vertices=\"odometry\"\n"}) {
      EXPECT_THAT(run.out, HasSubstr(flag));
    }
    // Not the logging library's flags, nor other commands' flags.
    for (const char* other :
         {"logtostderr", "minloglevel", "--v=", "--tum", "--components"}) {
      EXPECT_THAT(run.out, Not(HasSubstr(other)));
    }
  }
  const RunResult solve = RunToolWithOutput("solve --help");
  EXPECT_EQ(solve.exit_code, 0);
  for (const char* flag :
       {"--components=false\n", "--progress=false\n", "--max_rank=10\n",
        "--init=\"chordal\"\n", "--gradient_tolerance=1e-06\n"}) {
    EXPECT_THAT(solve.out, HasSubstr(flag));
  }
  EXPECT_THAT(solve.out, Not(HasSubstr("--side")));
  EXPECT_THAT(solve.out, Not(HasSubstr("logtostderr")));

  const RunResult general = RunToolWithOutput("help");
  EXPECT_EQ(general.exit_code, 0);
  for (const char* command : kCommands) {
    EXPECT_THAT(general.out, HasSubstr(std::string("\n  ") + command + " "));
  }
  EXPECT_EQ(RunToolWithOutput("help nosuchcommand").exit_code, 2);
}

TEST_F(CliTest, EveryFlagOfTheProgramIsListedByACommand) {
  // gflags' XML lists every flag with the file that defines it.
  const RunResult xml = RunToolWithOutput("--helpxml");
  const std::regex flag("<flag><file>([^<]*)</file><name>([^<]*)</name>");
  std::set<std::string> program_flags;
  for (auto it = std::sregex_iterator(xml.out.begin(), xml.out.end(), flag);
       it != std::sregex_iterator(); ++it) {
    const std::string file = (*it)[1];
    if (file.find("tools/") != std::string::npos) {
      program_flags.insert((*it)[2]);
    }
  }
  ASSERT_GE(program_flags.size(), 25u) << xml.out.substr(0, 2000);
  std::string all_help;
  for (const char* command : kCommands) {
    all_help += RunToolWithOutput(std::string("help ") + command).out;
  }
  for (const std::string& name : program_flags) {
    EXPECT_THAT(all_help, HasSubstr("\n  --" + name + "=")) << name;
  }
}

TEST_F(CliTest, UnknownAndForeignFlagsAreUsageErrors) {
  const std::string output = TempPath("flags.g2o");
  RunResult run =
      RunToolWithOutput("generate cube --bogus 1 --output " + output);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("unknown flag '--bogus'"));
  run = RunToolWithOutput("generate cube --tum x.tum --output " + output);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr("--tum is not a flag of this command"));
  EXPECT_FALSE(fs::exists(output));
  // Negated booleans and "--flag value" are flags too; glog's are accepted.
  run = RunToolWithOutput("generate cube --side 3 --noverbose --v=0 --output " +
                          output);
  EXPECT_EQ(run.exit_code, 2) << run.output;  // --verbose is not generate's.
  run = RunToolWithOutput("generate cube --side 3 --v=0 --output " + output);
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_TRUE(fs::exists(output));
  fs::remove(output);
}

#ifdef __GLIBC__
// The tool starts itself once more with glibc's huge-page heap tunable
// added to GLIBC_TUNABLES (tools/ceres_sesync_main.cc); a setting of the
// user's is kept, other tunables too.
TEST_F(CliTest, RestartsWithTheHugePageHeapTunable) {
  const std::string graph = TempPath("tunable.g2o");
  ASSERT_EQ(RunTool("generate cube --side 2 --output " + graph), 0);
  const char* saved = std::getenv("GLIBC_TUNABLES");
  const std::string previous = saved != nullptr ? saved : "";
  auto tunables_seen = [&]() {
    const RunResult run =
        RunToolWithOutput("solve " + graph + " --verbose --v=1");
    EXPECT_EQ(run.exit_code, 0) << run.output;
    return ValueAfter(run.err, "GLIBC_TUNABLES=");
  };
  unsetenv("GLIBC_TUNABLES");
  EXPECT_EQ(tunables_seen(), "glibc.malloc.hugetlb=1");
  setenv("GLIBC_TUNABLES", "glibc.malloc.hugetlb=0", 1);
  EXPECT_EQ(tunables_seen(), "glibc.malloc.hugetlb=0");
  setenv("GLIBC_TUNABLES", "glibc.malloc.check=0", 1);
  EXPECT_EQ(tunables_seen(), "glibc.malloc.check=0:glibc.malloc.hugetlb=1");
  if (saved != nullptr) {
    setenv("GLIBC_TUNABLES", previous.c_str(), 1);
  } else {
    unsetenv("GLIBC_TUNABLES");
  }
  fs::remove(graph);
}
#endif

// Two triangles (vertices 0-2 and 5-7): a disconnected graph.
const char kTwoComponents[] =
    "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n"
    "EDGE_SE2 1 2 1 0 0.1 1 0 0 1 0 1\n"
    "EDGE_SE2 2 0 -2 0.1 0 1 0 0 1 0 1\n"
    "EDGE_SE2 5 6 1 0 0.5 1 0 0 1 0 1\n"
    "EDGE_SE2 6 7 1 0 0 1 0 0 1 0 1\n"
    "EDGE_SE2 7 5 1 1 0 1 0 0 1 0 1\n";

TEST_F(CliTest, SolveComponents) {
  const std::string graph = TempPath("two.g2o");
  const std::string json_path = TempPath("two.json");
  const std::string poses = TempPath("two_poses.g2o");
  WriteText(graph, kTwoComponents);
  RunResult run = RunToolWithOutput("solve " + graph + " --json " + json_path +
                                    " --output " + poses);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err,
              HasSubstr(graph + ":4: measurement graph is disconnected"));
  EXPECT_THAT(run.err, HasSubstr("--components"));
  EXPECT_FALSE(fs::exists(json_path));
  EXPECT_FALSE(fs::exists(poses));

  run = RunToolWithOutput("solve " + graph + " --components --json " +
                          json_path + " --output " + poses);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_THAT(run.out, HasSubstr("Connected components"));
  const std::string json = ReadText(json_path);
  ASSERT_TRUE(IsValidJson(json)) << json;
  EXPECT_THAT(json, HasSubstr("\"num_components\": 2"));
  EXPECT_THAT(json, HasSubstr("\"vertex_ids\": [0, 1, 2]"));
  EXPECT_THAT(json, HasSubstr("\"vertex_ids\": [5, 6, 7]"));
  EXPECT_THAT(json, HasSubstr("\"gauge_vertex_id\": 5"));
  EXPECT_THAT(json, HasSubstr("\"status\": \"CERTIFIED_OPTIMUM\""));
  // The total is the sum of the components.
  const double total = JsonNumber(json, "\"graph\"", "objective");
  const double first = JsonNumber(json, "\"gauge_vertex_id\": 0", "objective");
  const double second = JsonNumber(json, "\"gauge_vertex_id\": 5", "objective");
  EXPECT_GT(first, 0);
  EXPECT_GT(second, 0);
  EXPECT_DOUBLE_EQ(total, first + second);
  // All six poses; each component's first pose is its gauge (identity).
  const std::string written = ReadText(poses);
  EXPECT_THAT(written, HasSubstr("VERTEX_SE2 0 0 0 0\n"));
  EXPECT_THAT(written, HasSubstr("VERTEX_SE2 5 0 0 0\n"));
  for (const char* id : {"1 ", "2 ", "6 ", "7 "}) {
    EXPECT_THAT(written, HasSubstr(std::string("VERTEX_SE2 ") + id));
  }
  for (const std::string& path : {graph, json_path, poses}) fs::remove(path);
}

// Three 2D poses (ids 10, 20, 30 at (0, 0, 0), (1, 0, pi/2), (1, 1, pi)),
// landmarks with ids out of order and below the pose ids (100 at (2, 0.5),
// 7 at (0.5, 1.5), 55 at (-0.5, 0.5)), exact measurements, and a full pose
// prior on vertex 10 at the identity: the optimum is exactly that map, in
// the world frame of the prior.
const char kLandmarks2d[] =
    "VERTEX_XY 100 0 0\n"
    "VERTEX_XY 7 0 0\n"
    "VERTEX_XY 55 0 0\n"
    "EDGE_SE2 10 20 1 0 1.5707963267948966 1 0 0 1 0 1\n"
    "EDGE_SE2 20 30 1 0 1.5707963267948966 1 0 0 1 0 1\n"
    "EDGE_SE2_XY 10 100 2 0.5 4 0 4\n"
    "EDGE_SE2_XY 10 55 -0.5 0.5 4 0 4\n"
    "EDGE_SE2_XY 20 100 0.5 -1 4 0 4\n"
    "EDGE_SE2_XY 20 7 1.5 0.5 4 0 4\n"
    "EDGE_SE2_XY 30 7 0.5 -0.5 4 0 4\n"
    "EDGE_SE2_XY 30 55 1.5 0.5 4 0 4\n"
    "EDGE_PRIOR_SE2 10 0 0 0 10 0 0 10 0 10\n";

TEST_F(CliTest, LandmarksAndPriorsThroughSolveAndCertify) {
  const std::string graph_path = TempPath("landmarks.g2o");
  const std::string solved = TempPath("landmarks_solved.g2o");
  const std::string json_path = TempPath("landmarks.json");
  const std::string certify_json = TempPath("landmarks_certify.json");
  WriteText(graph_path, kLandmarks2d);
  RunResult run = RunToolWithOutput("solve " + graph_path + " --output " +
                                    solved + " --json " + json_path);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_THAT(run.out, HasSubstr("Landmarks                          3"));
  EXPECT_THAT(run.out, HasSubstr("Priors                             1"));
  const std::string json = ReadText(json_path);
  ASSERT_TRUE(IsValidJson(json)) << json;
  EXPECT_THAT(json, HasSubstr("\"num_landmarks\": 3"));
  EXPECT_THAT(json, HasSubstr("\"num_landmark_measurements\": 6"));
  EXPECT_THAT(json, HasSubstr("\"num_priors\": 1"));
  EXPECT_THAT(json, HasSubstr("\"certified\": true"));
  // The written solution: every pose and landmark with its original id, at
  // the exact map in the world frame.
  PoseGraph graph;
  std::string error;
  ASSERT_TRUE(ReadG2oFile(graph_path, {}, &graph, &error)) << error;
  Solution x;
  ASSERT_TRUE(ReadG2oSolution(solved, graph, &x, &error)) << error;
  const std::string written = ReadText(solved);
  for (const char* line : {"VERTEX_SE2 10 ", "VERTEX_SE2 20 ", "VERTEX_SE2 30 ",
                           "VERTEX_XY 100 ", "VERTEX_XY 7 ", "VERTEX_XY 55 "}) {
    EXPECT_THAT(written, HasSubstr(line));
  }
  auto landmark = [&](int64_t id) {
    return x.landmarks[graph.FindLandmark(id)];
  };
  EXPECT_LT((landmark(100) - Eigen::Vector2d(2, 0.5)).norm(), 1e-9);
  EXPECT_LT((landmark(7) - Eigen::Vector2d(0.5, 1.5)).norm(), 1e-9);
  EXPECT_LT((landmark(55) - Eigen::Vector2d(-0.5, 0.5)).norm(), 1e-9);
  const Pose& p30 = x.poses[graph.FindVertex(30)];
  EXPECT_LT((p30.t - Eigen::Vector2d(1, 1)).norm(), 1e-9);
  EXPECT_LT((p30.R + Eigen::Matrix2d::Identity()).norm(), 1e-9);
  EXPECT_NEAR(JsonNumber(json, "\"graph\"", "objective"),
              EvaluateObjective(graph, x), 1e-12);

  // certify reads the landmarks back: certified, the same objective.
  run = RunToolWithOutput("certify " + graph_path + " " + solved + " --json " +
                          certify_json);
  EXPECT_EQ(run.exit_code, 0) << run.output;
  const std::string cjson = ReadText(certify_json);
  EXPECT_THAT(cjson, HasSubstr("\"certified\": true"));
  EXPECT_THAT(cjson, HasSubstr("\"num_landmarks\": 3"));
  EXPECT_NEAR(JsonNumber(cjson, "\"graph\"", "objective"),
              EvaluateObjective(graph, x), 1e-12);
  fs::remove(certify_json);

  // A candidate without one landmark's line: an input error naming it.
  std::string partial;
  for (size_t at = 0; at < written.size();) {
    const size_t end = written.find('\n', at);
    const std::string line = written.substr(at, end - at + 1);
    if (line.rfind("VERTEX_XY 55 ", 0) != 0) partial += line;
    at = end + 1;
  }
  const std::string partial_path = TempPath("landmarks_partial.g2o");
  WriteText(partial_path, partial);
  run = RunToolWithOutput("certify " + graph_path + " " + partial_path +
                          " --json " + certify_json);
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_THAT(run.err, HasSubstr("55"));
  EXPECT_FALSE(fs::exists(certify_json));

  // --components with a triangle and an edge beside the map: the map is one
  // component with its landmarks and prior, solved in the world frame (the
  // same exact map), the others each in its own gauge.
  fs::remove(solved);
  const std::string three_path = TempPath("landmarks_three.g2o");
  WriteText(three_path, std::string(kLandmarks2d) +
                            "EDGE_SE2 200 201 1 0 0 1 0 0 1 0 1\n"
                            "EDGE_SE2 201 202 1 0 0.1 1 0 0 1 0 1\n"
                            "EDGE_SE2 202 200 -2 0.1 0 1 0 0 1 0 1\n"
                            "EDGE_SE2 300 301 1 0 0.5 1 0 0 1 0 1\n");
  run = RunToolWithOutput("solve " + three_path + " --components --output " +
                          solved + " --json " + json_path);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_THAT(run.out, HasSubstr("Landmark measurements              6"));
  EXPECT_THAT(run.out, HasSubstr("world"));
  const std::string cjson3 = ReadText(json_path);
  ASSERT_TRUE(IsValidJson(cjson3)) << cjson3;
  EXPECT_THAT(cjson3, HasSubstr("\"num_components\": 3"));
  EXPECT_THAT(cjson3, HasSubstr("\"landmark_ids\": [100, 7, 55]"));
  EXPECT_THAT(cjson3, HasSubstr("\"gauge_vertex_id\": -1"));
  PoseGraph three;
  G2oReadOptions disconnected;
  disconnected.allow_disconnected = true;
  ASSERT_TRUE(ReadG2oFile(three_path, disconnected, &three, &error)) << error;
  Solution y;
  ASSERT_TRUE(ReadG2oSolution(solved, three, &y, &error)) << error;
  EXPECT_LT(
      (y.landmarks[three.FindLandmark(100)] - Eigen::Vector2d(2, 0.5)).norm(),
      1e-9);
  EXPECT_LT((y.poses[three.FindVertex(30)].t - Eigen::Vector2d(1, 1)).norm(),
            1e-9);
  EXPECT_NEAR(JsonNumber(cjson3, "\"graph\"", "objective"),
              EvaluateObjective(three, y), 1e-12);
  fs::remove(three_path);
  fs::remove(solved);

  // A bad landmark line: the file and line, exit 2, nothing written.
  WriteText(graph_path,
            std::string(kLandmarks2d) + "EDGE_SE2_XY 30 100 nan 0.5 4 0 4\n");
  run = RunToolWithOutput("solve " + graph_path + " --output " + solved);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.err, HasSubstr(graph_path + ":13:"));
  EXPECT_FALSE(fs::exists(solved));
  for (const std::string& path : {graph_path, json_path, partial_path}) {
    fs::remove(path);
  }
}

TEST_F(CliTest, ProgressOnlyWhenAskedForOnAPipe) {
  const std::string graph = TempPath("cube.g2o");
  ASSERT_EQ(
      RunToolWithOutput("generate cube --side 4 --output " + graph).exit_code,
      0);
  RunResult run = RunToolWithOutput("solve " + graph);
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(run.err, "");  // stderr is not a terminal.
  run = RunToolWithOutput("solve " + graph + " --noprogress");
  EXPECT_EQ(run.err, "");
  run = RunToolWithOutput("solve " + graph + " --progress");
  EXPECT_EQ(run.exit_code, 0) << run.output;
  // One line per stage, in order.
  size_t at = 0;
  for (const char* stage : {"] data", "] initialize", "] optimize    rank 5",
                            "] verify      rank 5", "] round", "] done"}) {
    const size_t next = run.err.find(stage, at);
    ASSERT_NE(next, std::string::npos) << stage << " in\n" << run.err;
    at = next;
  }
  EXPECT_THAT(run.err, Not(HasSubstr("\r")));  // Plain lines on a pipe.
  EXPECT_THAT(run.err, HasSubstr("F(x) "));
  fs::remove(graph);
}

}  // namespace
}  // namespace ceres_sesync
