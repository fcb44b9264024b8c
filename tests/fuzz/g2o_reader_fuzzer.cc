// libFuzzer target for the g2o reader (ceres_sesync/g2o_io.h).
//
// Build: cmake -DCERES_SESYNC_BUILD_FUZZERS=ON with clang (see
// scripts/fuzz.sh). Every input is read with ReadG2o from a std::istringstream
// with skip_unsupported_tags = false and = true. Besides "no crash, no
// sanitizer report", the fuzzer checks what the reader promises (g2o_io.h):
//
//  - a successful read yields a graph that passes ValidatePoseGraph (with
//    landmarks and priors allowed), whose bookkeeping (vertex_ids,
//    index_of_vertex_id, initial_poses, fixed_pose, and the same for the
//    landmarks) is consistent, and whose G2oReadSummary matches the graph;
//  - a failed read fills a non-empty message that starts with "NAME:";
//  - reading is deterministic (a second read gives the same graph);
//  - skipping unsupported tags only adds lines to skip: if the strict read
//    succeeds, the lenient read succeeds with the identical graph and no
//    skipped lines; if the lenient read skipped nothing, both reads agree on
//    success and on the graph.
//
// There is no in-memory writer (WriteG2oFile writes files), so no write/read
// round trip is fuzzed here; g2o_io_test covers the writers.
//
// A violated invariant prints what went wrong and aborts, which libFuzzer
// reports as a crash and saves the input.

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/pose_graph.h"
#include "glog/logging.h"

namespace {

using ceres_sesync::G2oReadOptions;
using ceres_sesync::G2oReadSummary;
using ceres_sesync::PoseGraph;

const char kName[] = "fuzz.g2o";

[[noreturn]] void Violated(const char* what, const std::string& detail) {
  std::fprintf(stderr, "g2o_reader_fuzzer: invariant violated: %s %s\n", what,
               detail.c_str());
  std::abort();
}

#define FUZZ_CHECK(condition, detail)                 \
  do {                                                \
    if (!(condition)) Violated(#condition, (detail)); \
  } while (0)

struct ReadResult {
  bool ok = false;
  PoseGraph graph;
  G2oReadSummary summary;
  std::string error;
};

ReadResult Read(const std::string& text, bool skip_unsupported_tags) {
  ReadResult result;
  std::istringstream in(text);
  G2oReadOptions options;
  options.skip_unsupported_tags = skip_unsupported_tags;
  result.ok = ceres_sesync::ReadG2o(in, kName, options, &result.graph,
                                    &result.error, &result.summary);
  return result;
}

// Bitwise equality of two graphs (the reader is deterministic, so equal
// inputs must give equal doubles, not merely close ones).
bool SameGraph(const PoseGraph& a, const PoseGraph& b) {
  if (a.dimension != b.dimension || a.num_poses != b.num_poses ||
      a.vertex_ids != b.vertex_ids || a.fixed_pose != b.fixed_pose ||
      a.measurements.size() != b.measurements.size() ||
      a.initial_poses.size() != b.initial_poses.size() ||
      a.landmark_ids != b.landmark_ids ||
      a.initial_landmarks != b.initial_landmarks ||
      a.landmark_measurements.size() != b.landmark_measurements.size() ||
      a.priors.size() != b.priors.size()) {
    return false;
  }
  for (size_t k = 0; k < a.landmark_measurements.size(); ++k) {
    const auto& p = a.landmark_measurements[k];
    const auto& q = b.landmark_measurements[k];
    if (p.i != q.i || p.l != q.l || p.z != q.z || p.nu != q.nu) return false;
  }
  for (size_t k = 0; k < a.priors.size(); ++k) {
    const auto& p = a.priors[k];
    const auto& q = b.priors[k];
    if (p.i != q.i || p.R != q.R || p.t != q.t || p.kappa != q.kappa ||
        p.tau != q.tau) {
      return false;
    }
  }
  for (size_t k = 0; k < a.measurements.size(); ++k) {
    const auto& p = a.measurements[k];
    const auto& q = b.measurements[k];
    if (p.i != q.i || p.j != q.j || p.R != q.R || p.t != q.t ||
        p.kappa != q.kappa || p.tau != q.tau) {
      return false;
    }
  }
  for (size_t k = 0; k < a.initial_poses.size(); ++k) {
    if (a.initial_poses[k].R != b.initial_poses[k].R ||
        a.initial_poses[k].t != b.initial_poses[k].t) {
      return false;
    }
  }
  return true;
}

void CheckResult(const ReadResult& r) {
  if (!r.ok) {
    FUZZ_CHECK(!r.error.empty(), "failed read without a message");
    FUZZ_CHECK(r.error.rfind(std::string(kName) + ":", 0) == 0, r.error);
    return;
  }
  const PoseGraph& g = r.graph;
  std::string error;
  FUZZ_CHECK(ceres_sesync::ValidatePoseGraph(g, &error), error);
  FUZZ_CHECK(!g.measurements.empty() || !g.landmark_measurements.empty() ||
                 !g.priors.empty(),
             "");
  FUZZ_CHECK(static_cast<int>(g.landmark_ids.size()) == g.num_landmarks, "");
  FUZZ_CHECK(static_cast<int>(g.index_of_landmark_id.size()) == g.num_landmarks,
             "");
  for (int l = 0; l < g.num_landmarks; ++l) {
    FUZZ_CHECK(g.landmark_ids[l] >= 0, "negative landmark id");
    FUZZ_CHECK(g.FindLandmark(g.landmark_ids[l]) == l, "landmark map");
    FUZZ_CHECK(g.FindVertex(g.landmark_ids[l]) < 0, "landmark id is a pose");
  }
  FUZZ_CHECK(
      g.initial_landmarks.empty() ||
          static_cast<int>(g.initial_landmarks.size()) == g.num_landmarks,
      "");
  FUZZ_CHECK(r.summary.num_landmarks == g.num_landmarks, "");
  FUZZ_CHECK(r.summary.num_landmark_edges ==
                 static_cast<int>(g.landmark_measurements.size()),
             "");
  FUZZ_CHECK(r.summary.num_priors == static_cast<int>(g.priors.size()), "");
  FUZZ_CHECK(static_cast<int>(g.vertex_ids.size()) == g.num_poses, "");
  FUZZ_CHECK(static_cast<int>(g.index_of_vertex_id.size()) == g.num_poses, "");
  for (int k = 0; k < g.num_poses; ++k) {
    FUZZ_CHECK(g.vertex_ids[k] >= 0, "negative vertex id");
    FUZZ_CHECK(g.FindVertex(g.vertex_ids[k]) == k, "id map inconsistent");
  }
  FUZZ_CHECK(g.initial_poses.empty() ||
                 static_cast<int>(g.initial_poses.size()) == g.num_poses,
             "");
  FUZZ_CHECK(g.fixed_pose >= -1 && g.fixed_pose < g.num_poses, "");
  FUZZ_CHECK(r.summary.num_vertices == g.num_poses, "");
  FUZZ_CHECK(r.summary.num_edges == static_cast<int>(g.measurements.size()),
             "");
  FUZZ_CHECK(r.summary.has_fix == (g.fixed_pose >= 0), "");
  FUZZ_CHECK(r.summary.num_skipped_lines >= 0, "");
  int skipped = 0;
  for (const auto& [tag, count] : r.summary.skipped_tags) {
    FUZZ_CHECK(count > 0 && !tag.empty(), tag);
    skipped += count;
  }
  FUZZ_CHECK(skipped == r.summary.num_skipped_lines, "");
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int* /*argc*/, char*** /*argv*/) {
  // The reader logs a glog warning per skipped tag; keep the fuzzer quiet.
  FLAGS_minloglevel = google::GLOG_ERROR;
  FLAGS_logtostderr = true;
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);

  const ReadResult strict = Read(text, false);
  CheckResult(strict);
  const ReadResult lenient = Read(text, true);
  CheckResult(lenient);

  // Determinism.
  const ReadResult again = Read(text, false);
  FUZZ_CHECK(again.ok == strict.ok, "");
  if (strict.ok) FUZZ_CHECK(SameGraph(again.graph, strict.graph), "");
  if (!strict.ok) FUZZ_CHECK(again.error == strict.error, again.error);

  // Skipping unsupported tags never loses a graph the strict reader accepts.
  if (strict.ok) {
    FUZZ_CHECK(lenient.ok, lenient.error);
    FUZZ_CHECK(lenient.summary.num_skipped_lines == 0, "");
    FUZZ_CHECK(SameGraph(lenient.graph, strict.graph), "");
  }
  if (lenient.ok && lenient.summary.num_skipped_lines == 0) {
    FUZZ_CHECK(strict.ok, strict.error);
    FUZZ_CHECK(SameGraph(lenient.graph, strict.graph), "");
  }
  return 0;
}
