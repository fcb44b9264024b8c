// `ceres_sesync certify GRAPH.g2o POSES.g2o`: certify a given solution.

#include <cstdio>
#include <iostream>

#include "ceres_sesync/certification.h"
#include "ceres_sesync/g2o_io.h"
#include "ceres_sesync/internal/json_writer.h"
#include "gflags/gflags.h"
#include "tools/commands.h"
#include "tools/progress.h"

DEFINE_double(max_relative_suboptimality,
              ceres_sesync::CertifyOptions().max_relative_suboptimality,
              "Certified iff the proven relative suboptimality bound "
              "is at most this.");
DEFINE_bool(improve, false,
            "If not certified, run SE-Sync from the candidate and "
            "write the improved poses to --output.");

namespace ceres_sesync::tools {

int RunCertify(const Args& args) {
  if (args.size() != 2) {
    std::fputs(
        "usage: ceres_sesync certify GRAPH.g2o POSES.g2o [flags] (see "
        "'ceres_sesync help certify')\n",
        stderr);
    return kUsageOrInputError;
  }
  PoseGraph graph;
  std::string error;
  if (!ReadG2oFile(args[0], G2oReadOptions(), &graph, &error)) {
    std::fprintf(stderr, "ceres_sesync certify: %s\n", error.c_str());
    return kUsageOrInputError;
  }
  // The poses and (for a graph with landmarks) the landmark positions.
  Solution candidate;
  if (!ReadG2oSolution(args[1], graph, &candidate, &error)) {
    std::fprintf(stderr, "ceres_sesync certify: %s\n", error.c_str());
    return kUsageOrInputError;
  }
  CertifyOptions options;
  options.max_relative_suboptimality = FLAGS_max_relative_suboptimality;
  options.improve_if_not_certified = FLAGS_improve;
  options.num_threads = FLAGS_num_threads;
  if (!ParseProofArithmetic(FLAGS_proof_arithmetic,
                            &options.proof_arithmetic)) {
    std::fprintf(stderr,
                 "ceres_sesync certify: unknown --proof_arithmetic '%s'\n",
                 FLAGS_proof_arithmetic.c_str());
    return kUsageOrInputError;
  }
  options.solver_options.proof_arithmetic = options.proof_arithmetic;
  options.solver_options.num_threads = FLAGS_num_threads;
  options.solver_options.verbose = FLAGS_verbose;
  std::unique_ptr<ProgressPrinter> progress;
  if (FLAGS_improve) progress = ProgressPrinterFromFlags();
  if (progress) options.solver_options.progress = progress->Callback();
  Certificate certificate;
  const bool ok = Certify(graph, candidate, options, &certificate, &error);
  if (progress) progress->Finish();
  if (!ok) {
    std::fprintf(stderr, "ceres_sesync certify: %s: %s\n", args[1].c_str(),
                 error.c_str());
    return kUsageOrInputError;
  }
  std::cout << certificate.FullReport() << std::flush;
  if (certificate.has_improved_poses && !FLAGS_output.empty() &&
      !WriteG2oSolution(
          FLAGS_output, graph,
          Solution{certificate.improved_poses, certificate.improved_landmarks},
          &error)) {
    std::fprintf(stderr, "ceres_sesync certify: %s\n", error.c_str());
    return kUsageOrInputError;
  }
  if (!FLAGS_json.empty()) {
    internal::JsonWriter json;
    json.String("graph", args[0]);
    json.String("poses", args[1]);
    json.Int("num_landmarks", graph.num_landmarks);
    json.Int("num_priors", static_cast<int>(graph.priors.size()));
    json.Number("objective", certificate.objective);
    json.Number("rotation_objective", certificate.rotation_objective);
    json.Number("lambda_min", certificate.lambda_min);
    json.Number("eta", certificate.eta);
    // Every proof accounts for all round-off (the key is kept for scripts).
    json.Bool("strict_round_off", true);
    json.BeginObject("proof");
    json.String("precision", certificate.proof_precision);
    json.Int("factorizations", certificate.factorizations);
    json.Int("extended_factorizations", certificate.extended_factorizations);
    json.Number("extended_time_s", certificate.extended_proof_time_s);
    json.EndObject();
    json.Number("lower_bound", certificate.lower_bound);
    json.Number("suboptimality_bound", certificate.suboptimality_bound);
    json.Number("relative_suboptimality_bound",
                certificate.relative_suboptimality_bound);
    json.Bool("certified", certificate.certified);
    json.Number("negative_curvature", certificate.negative_curvature);
    json.Number("time_s", certificate.time_s);
    if (certificate.has_improved_poses) {
      json.Number("improved_objective",
                  certificate.improvement_summary.objective);
      json.Bool("improved_certified",
                certificate.improvement_summary.certified());
    }
    if (!json.WriteToFile(FLAGS_json, &error)) {
      std::fprintf(stderr, "ceres_sesync certify: %s\n", error.c_str());
      return kUsageOrInputError;
    }
  }
  return certificate.certified ? kSuccess : kNotCertified;
}

}  // namespace ceres_sesync::tools
