// Tests of the JSON writer and of the `ceres_sesync info` command (run as a
// separate process, as a user would).

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>

#include "ceres_sesync/internal/json_writer.h"
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
using test_util::RunToolWithOutput;
using test_util::TempPath;
using test_util::ValueAfter;
using test_util::WriteText;

TEST(JsonValidatorTest, RejectsInvalidDocuments) {
  // The validator must be able to say no, or the tests below prove nothing.
  EXPECT_TRUE(IsValidJson("{\"a\": [1, -2.5e+3, true, null, \"x\\n\"]}"));
  for (const char* bad :
       {"{", "{\"a\" 1}", "{\"a\": 1,}", "[01]", "[1.]", "{\"a\": nan}",
        "\"tab\there\"", "[1] 2", "{\"a\": \"\\x\"}"}) {
    EXPECT_FALSE(IsValidJson(bad)) << bad;
  }
}

// ---- JsonWriter -------------------------------------------------------------

TEST(JsonWriterTest, WritesValidNestedDocuments) {
  internal::JsonWriter json;
  json.String("name", "plain");
  json.Int("count", -42);
  json.Bool("flag", true);
  json.Null("nothing");
  json.BeginObject("empty");
  json.EndObject();
  json.BeginArray("list");
  json.Number(1.5);
  json.Int(7);
  json.String("s");
  json.Bool(false);
  json.Null();
  json.BeginObject();
  json.Number("x", 2);
  json.EndObject();
  json.BeginArray();
  json.EndArray();
  json.EndArray();
  const std::string text = json.ToString();
  EXPECT_TRUE(IsValidJson(text)) << text;
  EXPECT_NE(text.find("\"count\": -42"), std::string::npos) << text;
  EXPECT_NE(text.find("\"empty\": {}"), std::string::npos) << text;
  EXPECT_NE(text.find("[1.5, 7, \"s\", false, null, {"), std::string::npos)
      << text;
}

TEST(JsonWriterTest, EscapesStrings) {
  const std::string nasty = std::string("q\"b\\s/\n\t\r\b\f") + '\x01' +
                            '\x1f' + "\xc3\xa9" + "\xe2\x82\xac" + '\xff' +
                            "\xc3";  // é, €, an invalid byte, a cut é.
  internal::JsonWriter json;
  json.String(nasty, nasty);
  const std::string text = json.ToString();
  EXPECT_TRUE(IsValidJson(text)) << text;
  const std::string expected =
      "\"q\\\"b\\\\s/\\n\\t\\r\\b\\f\\u0001\\u001f\xc3\xa9\xe2\x82\xac\\ufffd"
      "\\ufffd\"";
  EXPECT_NE(text.find(expected + ": " + expected), std::string::npos) << text;
}

TEST(JsonWriterTest, NumbersRoundTripAndNonFiniteIsNull) {
  const double values[] = {0.1, 1.0 / 3, -2.5e-300, 1.7976931348623157e308,
                           123456789012345678.0};
  for (double v : values) {
    std::string text;
    internal::JsonWriter::AppendNumber(v, &text);
    EXPECT_EQ(std::strtod(text.c_str(), nullptr), v) << text;
    EXPECT_TRUE(IsValidJson(text)) << text;
  }
  for (double v : {std::numeric_limits<double>::quiet_NaN(),
                   std::numeric_limits<double>::infinity(),
                   -std::numeric_limits<double>::infinity()}) {
    std::string text;
    internal::JsonWriter::AppendNumber(v, &text);
    EXPECT_EQ(text, "null");
  }
}

// ---- the `info` command
// -------------------------------------------------------

class InfoCommandTest : public testing::Test {
 protected:
  void SetUp() override {
    if (std::string(CERES_SESYNC_TOOL).empty()) {
      GTEST_SKIP() << "the ceres_sesync program is not built";
    }
  }
};

// Three poses (ids 3, 7, 9), three edges with kappa 10, 30, 20 and isotropic
// translational information 5 I (tau = 2 / trace(I/5) = 5), FIX 7.
const char kGoodGraph[] =
    "# a small graph\n"
    "VERTEX_SE2 3 0 0 0\n"
    "VERTEX_SE2 7 1 0 0\n"
    "VERTEX_SE2 9 1 1 1.5\n"
    "EDGE_SE2 3 7 1 0 0 5 0 0 5 0 10\n"
    "EDGE_SE2 7 9 0 1 1.5 5 0 0 5 0 30\n"
    "\n"
    "EDGE_SE2 9 3 -1 1 -1.5 5 0 0 5 0 20\n"
    "FIX 7\n";

TEST_F(InfoCommandTest, DescribesAGoodFile) {
  const std::string graph = TempPath("good.g2o");
  const std::string json_path = TempPath("good.json");
  WriteText(graph, kGoodGraph);
  const RunResult run =
      RunToolWithOutput("info " + graph + " --json " + json_path);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(ValueAfter(run.output, "dimension:"), "2") << run.output;
  EXPECT_EQ(ValueAfter(run.output, "poses:"), "3") << run.output;
  EXPECT_EQ(ValueAfter(run.output, "edges:"), "3") << run.output;
  EXPECT_EQ(ValueAfter(run.output, "connected components:"), "1");
  EXPECT_EQ(ValueAfter(run.output, "kappa min / median / max:"),
            "10 / 20 / 30");
  EXPECT_EQ(ValueAfter(run.output, "tau min / median / max:"), "5 / 5 / 5");
  EXPECT_EQ(ValueAfter(run.output, "initial guess:"), "yes (VERTEX lines)");
  EXPECT_EQ(ValueAfter(run.output, "fixed vertex (FIX):"), "7");
  EXPECT_EQ(ValueAfter(run.output, "skipped lines:"), "0");

  ASSERT_TRUE(fs::exists(json_path));
  const std::string json = ReadText(json_path);
  EXPECT_TRUE(IsValidJson(json)) << json;
  for (const char* field :
       {"\"command\": \"info\"", "\"dimension\": 2", "\"num_poses\": 3",
        "\"num_edges\": 3", "\"num_components\": 1",
        "\"has_initial_guess\": true", "\"has_fix\": true",
        "\"fixed_vertex_id\": 7", "\"num_skipped_lines\": 0"}) {
    EXPECT_NE(json.find(field), std::string::npos) << field << " in " << json;
  }
  EXPECT_NE(json.find("\"file\": \"" + graph + "\""), std::string::npos)
      << json;
  EXPECT_EQ(JsonNumber(json, "\"kappa\"", "min"), 10);
  EXPECT_EQ(JsonNumber(json, "\"kappa\"", "median"), 20);
  EXPECT_EQ(JsonNumber(json, "\"kappa\"", "max"), 30);
  // 2 / (2 / 5) may differ from 5 in the last bit.
  EXPECT_NEAR(JsonNumber(json, "\"tau\"", "median"), 5, 1e-14);
  fs::remove(graph);
  fs::remove(json_path);
}

TEST_F(InfoCommandTest, BadFileExitsWithTwoNamingTheLineAndWritesNoJson) {
  const std::string graph = TempPath("bad.g2o");
  const std::string json_path = TempPath("bad.json");
  WriteText(graph,
            "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n"
            "\n"
            "EDGE_SE2 1 2 1 0 0 1 0 0 1 0 oops\n");
  const RunResult run =
      RunToolWithOutput("info " + graph + " --json " + json_path);
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_NE(run.output.find(graph + ":3: "), std::string::npos) << run.output;
  EXPECT_FALSE(fs::exists(json_path));
  fs::remove(graph);
}

TEST_F(InfoCommandTest, SkipUnsupportedTagsFlag) {
  const std::string graph = TempPath("bearing.g2o");
  const std::string json_path = TempPath("bearing.json");
  WriteText(graph,
            "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n"
            "EDGE_BEARING_SE2_XY 0 5 0.5 1\n");
  RunResult run = RunToolWithOutput("info " + graph);
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_NE(
      run.output.find(graph + ":2: unsupported tag 'EDGE_BEARING_SE2_XY'"),
      std::string::npos)
      << run.output;

  run = RunToolWithOutput("info " + graph + " --skip_unsupported_tags --json " +
                          json_path);
  EXPECT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(ValueAfter(run.output, "skipped lines:"), "1") << run.output;
  const std::string json = ReadText(json_path);
  EXPECT_TRUE(IsValidJson(json)) << json;
  EXPECT_NE(json.find("\"num_skipped_lines\": 1"), std::string::npos) << json;
  EXPECT_NE(json.find("\"EDGE_BEARING_SE2_XY\": 1"), std::string::npos) << json;
  fs::remove(graph);
  fs::remove(json_path);
}

TEST_F(InfoCommandTest, CountsLandmarksAndPriors) {
  const std::string graph = TempPath("landmarks.g2o");
  const std::string json_path = TempPath("landmarks.json");
  // Two landmarks (4 I and 2 I: nu 4 and 2), three measurements, one prior
  // of each kind.
  WriteText(graph,
            "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n"
            "EDGE_SE2_XY 0 10 1 2 4 0 4\n"
            "EDGE_SE2_XY 1 10 0 2 4 0 4\n"
            "EDGE_SE2_XY 1 11 0 2 2 0 2\n"
            "EDGE_PRIOR_SE2_XY 0 0 0 9 0 9\n"
            "EDGE_PRIOR_SE2 1 1 0 0 0 0 0 0 0 3\n"
            "EDGE_PRIOR_SE2 0 0 0 0 1 0 0 1 0 3\n");
  const RunResult run =
      RunToolWithOutput("info " + graph + " --json " + json_path);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(ValueAfter(run.output, "landmarks:"), "2") << run.output;
  EXPECT_EQ(ValueAfter(run.output, "landmark measurements:"), "3");
  EXPECT_EQ(ValueAfter(run.output, "nu min / median / max:"), "2 / 4 / 4");
  EXPECT_EQ(ValueAfter(run.output, "priors:"),
            "3 (position 1, rotation 1, pose 1)");
  const std::string json = ReadText(json_path);
  EXPECT_TRUE(IsValidJson(json)) << json;
  for (const char* field :
       {"\"num_landmarks\": 2", "\"num_landmark_measurements\": 3",
        "\"num_priors\": 3", "\"position\": 1", "\"rotation\": 1",
        "\"pose\": 1", "\"has_initial_landmarks\": false"}) {
    EXPECT_NE(json.find(field), std::string::npos) << field << " in " << json;
  }
  EXPECT_NEAR(JsonNumber(json, "\"nu\"", "min"), 2, 1e-14);
  fs::remove(graph);
  fs::remove(json_path);
}

TEST_F(InfoCommandTest, UsageErrorsExitWithTwo) {
  EXPECT_EQ(RunToolWithOutput("info").exit_code, 2);
  const std::string missing = TempPath("missing.g2o");
  const RunResult run = RunToolWithOutput("info " + missing);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.output.find(missing), std::string::npos) << run.output;
  // An unwritable --json path is an error too.
  const std::string graph = TempPath("good2.g2o");
  WriteText(graph, kGoodGraph);
  EXPECT_EQ(RunToolWithOutput("info " + graph + " --json " +
                              TempPath("no_dir/x.json"))
                .exit_code,
            2);
  fs::remove(graph);
}

TEST_F(InfoCommandTest, DescribesABenchmarkDataset) {
  const std::string path = std::string(CERES_SESYNC_DATA_DIR) + "/CSAIL.g2o";
  if (!fs::exists(path)) GTEST_SKIP() << path << " not found";
  const RunResult run = RunToolWithOutput("info " + path);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  EXPECT_EQ(ValueAfter(run.output, "edges:"), "1172") << run.output;
  EXPECT_EQ(ValueAfter(run.output, "poses:"), "1045") << run.output;
  EXPECT_EQ(ValueAfter(run.output, "initial guess:"), "no") << run.output;
}

}  // namespace
}  // namespace ceres_sesync
