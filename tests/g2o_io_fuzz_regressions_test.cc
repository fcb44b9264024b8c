// Regression inputs for the g2o reader: inputs found by (or written for) the
// libFuzzer target tests/fuzz/g2o_reader_fuzzer.cc, embedded as strings. Each
// is read with ReadG2o (both skip_unsupported_tags values) and must give the
// recorded outcome (success, or failure with the recorded message fragment)
// and satisfy the fuzzer's invariants: a successful read passes
// ValidatePoseGraph and its summary matches the graph; a failure has a
// "NAME:LINE:" message; the lenient read agrees with the strict one when
// nothing was skipped.
//
// To add a fuzzer finding: paste the crashing input (escaped; the artifact is
// in build-fuzz/fuzz-artifacts/) as a new row with the outcome the reader's
// documentation (g2o_io.h) prescribes.

#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/pose_graph.h"
#include "gmock/gmock.h"
#include "gtest/gtest.h"

namespace ceres_sesync {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

struct Input {
  const char* name;
  std::string text;
  bool skip_unsupported_tags;
  bool ok;
  const char* message;  // Expected fragment of the error (if !ok).
};

const std::string kInfo3 =
    " 1 0 0 0 0 0 1 0 0 0 0 1 0 0 0 1 0 0 1 0 1";  // 6x6 identity.

std::vector<Input> Inputs() {
  using namespace std::string_literals;
  return {
      // Embedded NUL bytes inside a number and as a whole token.
      {"nul_in_number", "EDGE_SE2 0 1 1\0 0 0 1 0 0 1 0 1\n"s, false, false,
       "is not a number"},
      {"nul_token", "\0\n"s, true, false, "no EDGE lines"},
      // A token longer than the reader's small buffer (64 bytes).
      {"long_number",
       "EDGE_SE2 0 1 1.0000000000000000000000000000000000000000000000000000"
       "00000000000000000000001 0 0 1 0 0 1 0 1\n",
       false, true, ""},
      // Hexadecimal floats are numbers to strtod; infinities are not finite.
      {"hex_float", "EDGE_SE2 0 1 0x1p-2 0 0 1 0 0 1 0 1\n", false, true, ""},
      {"infinity", "EDGE_SE2 0 1 infinity 0 0 1 0 0 1 0 1\n", false, false,
       "is not finite"},
      // Overflow of the precisions: det(I_tt) = 1e600.
      {"tau_overflow", "EDGE_SE2 0 1 1 0 0 1e300 0 0 1e300 0 1\n", false, false,
       "non-finite or non-positive"},
      // Underflow of the precisions: det(I_tt) = 1e-600.
      {"tau_underflow", "EDGE_SE2 0 1 1 0 0 1e-300 0 0 1e-300 0 1\n", false,
       false, "non-finite or non-positive"},
      // Ids: the largest int64, out of range, negative zero, a plus sign.
      {"max_id", "EDGE_SE2 9223372036854775807 0 1 0 0 1 0 0 1 0 1\n", false,
       true, ""},
      {"id_overflow", "EDGE_SE2 9223372036854775808 0 1 0 0 1 0 0 1 0 1\n",
       false, false, "is not a vertex id"},
      {"minus_zero_self_loop", "EDGE_SE2 -0 0 1 0 0 1 0 0 1 0 1\n", false,
       false, "self-loop"},
      {"plus_id_self_loop", "EDGE_SE2 +7 7 1 0 0 1 0 0 1 0 1\n", false, false,
       "self-loop"},
      // CR LF line ends and no final newline.
      {"crlf",
       "VERTEX_SE2 0 0 0 0\r\nVERTEX_SE2 1 1 0 0\r\n"
       "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1",
       false, true, ""},
      // A lone CR is a blank, not a line break: one over-long line.
      {"cr_only",
       "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\rEDGE_SE2 1 2 1 0 0 1 0 0 1 0 1", false,
       false, "unexpected trailing 'EDGE_SE2'"},
      // Quaternion at the edge of the normalization tolerance and beyond.
      {"quaternion_tolerance",
       "EDGE_SE3:QUAT 0 1 1 0 0 0 0 0 1.0099" + kInfo3 + "\n", false, true, ""},
      {"quaternion_too_long",
       "EDGE_SE3:QUAT 0 1 1 0 0 0 0 0 1.0101" + kInfo3 + "\n", false, false,
       "has norm"},
      // Skipped tags around an otherwise valid file; without skipping, an
      // error naming the tag.
      {"skipped", "EDGE_PRIOR_XY 3 1 2 1 0 1\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n",
       true, true, ""},
      {"not_skipped",
       "EDGE_PRIOR_XY 3 1 2 1 0 1\nEDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\n", false,
       false, "unsupported tag 'EDGE_PRIOR_XY'"},
      // A skipped line never hides a legacy 3D tag.
      {"legacy_3d", "EDGE3 0 1 0 0 0 0 0 0\n", true, false, "legacy"},
      // FIX of a vertex that is not in the graph.
      {"fix_unknown", "EDGE_SE2 0 1 1 0 0 1 0 0 1 0 1\nFIX 5\n", false, false,
       "FIX refers to vertex 5"},
  };
}

bool ReadText(const std::string& text, bool skip, PoseGraph* g,
              std::string* error, G2oReadSummary* summary) {
  std::istringstream in(text);
  G2oReadOptions options;
  options.skip_unsupported_tags = skip;
  return ReadG2o(in, "regression.g2o", options, g, error, summary);
}

TEST(G2oFuzzRegressions, RecordedOutcomesAndInvariants) {
  for (const Input& input : Inputs()) {
    SCOPED_TRACE(input.name);
    PoseGraph g;
    std::string error;
    G2oReadSummary summary;
    const bool ok =
        ReadText(input.text, input.skip_unsupported_tags, &g, &error, &summary);
    ASSERT_EQ(ok, input.ok) << error;
    if (!ok) {
      EXPECT_THAT(error, StartsWith("regression.g2o:"));
      EXPECT_THAT(error, HasSubstr(input.message));
      continue;
    }
    std::string invalid;
    EXPECT_TRUE(ValidatePoseGraph(g, &invalid)) << invalid;
    EXPECT_EQ(summary.num_vertices, g.num_poses);
    EXPECT_EQ(summary.num_landmarks, g.num_landmarks);
    EXPECT_EQ(summary.num_landmark_edges,
              static_cast<int>(g.landmark_measurements.size()));
    EXPECT_EQ(summary.num_priors, static_cast<int>(g.priors.size()));
    EXPECT_EQ(summary.num_edges, static_cast<int>(g.measurements.size()));
    EXPECT_EQ(summary.has_fix, g.fixed_pose >= 0);
    if (summary.num_skipped_lines == 0) {
      // Nothing skipped: the other option value gives the same graph.
      PoseGraph h;
      ASSERT_TRUE(ReadText(input.text, !input.skip_unsupported_tags, &h, &error,
                           nullptr))
          << error;
      EXPECT_EQ(h.vertex_ids, g.vertex_ids);
      ASSERT_EQ(h.measurements.size(), g.measurements.size());
      for (size_t k = 0; k < g.measurements.size(); ++k) {
        EXPECT_EQ(h.measurements[k].R, g.measurements[k].R);
        EXPECT_EQ(h.measurements[k].t, g.measurements[k].t);
        EXPECT_EQ(h.measurements[k].kappa, g.measurements[k].kappa);
        EXPECT_EQ(h.measurements[k].tau, g.measurements[k].tau);
      }
    }
  }
}

TEST(G2oFuzzRegressions, ParsedValuesOfTrickyNumbers) {
  PoseGraph g;
  std::string error;
  // 0x1p-2 = 0.25 exactly.
  ASSERT_TRUE(ReadText("EDGE_SE2 0 1 0x1p-2 0 0 1 0 0 1 0 1\n", false, &g,
                       &error, nullptr))
      << error;
  EXPECT_EQ(g.measurements[0].t(0), 0.25);
  // The largest int64 id survives.
  ASSERT_TRUE(ReadText("EDGE_SE2 9223372036854775807 0 1 0 0 1 0 0 1 0 1\n",
                       false, &g, &error, nullptr))
      << error;
  EXPECT_EQ(g.vertex_ids[0], INT64_C(9223372036854775807));
}

}  // namespace
}  // namespace ceres_sesync
