// The `ceres_sesync` command-line program: dispatches to a subcommand.

#include <cstdio>
#include <cstring>
#include <string>

#include "gflags/gflags.h"
#include "glog/logging.h"
#include "tools/commands.h"

DEFINE_string(json, "", "Write a machine-readable JSON summary to this path.");
DEFINE_string(output, "", "Write the resulting poses (g2o) to this path.");
DEFINE_bool(verbose, false, "Log solver progress to stderr.");
DEFINE_string(proof_arithmetic, "automatic",
              "solve, certify: arithmetic of the certificate's proof: "
              "'automatic' (double, then double-double when double cannot "
              "reach the goal bound), 'double' or 'double-double'.");
DEFINE_int32(num_threads, 0,
             "solve, certify: threads for the O(m r) kernels (0: all cores).");

namespace {

struct Command {
  const char* name;
  int (*run)(const ceres_sesync::tools::Args&);
  const char* usage;
};

const Command kCommands[] = {
    {"info", ceres_sesync::tools::RunInfo,
     "info GRAPH.g2o                 dimension, poses, edges, components, "
     "weights"},
    {"solve", ceres_sesync::tools::RunSolve,
     "solve GRAPH.g2o [--output P.g2o] [--tum F] [--json S.json] "
     "[--init chordal|random|vertices]"},
    {"certify", ceres_sesync::tools::RunCertify,
     "certify GRAPH.g2o POSES.g2o [--json C.json]"},
    {"generate", ceres_sesync::tools::RunGenerate,
     "generate cube --side S | city --poses N | landmarks [--dimension 2|3] "
     "--output FILE.g2o [...]"},
};

std::string Usage() {
  std::string s =
      "usage: ceres_sesync <command> [args] [flags]\n"
      "Certifiably correct pose-graph optimization (SE-Sync) for Ceres "
      "users.\n\ncommands:\n";
  for (const Command& c : kCommands) s += std::string("  ") + c.usage + "\n";
  s += "\nexit codes: 0 success/certified, 1 not certified, 2 usage or input "
       "error\nRun 'ceres_sesync --helpfull' for all flags.\n";
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  gflags::SetUsageMessage(Usage());
  gflags::ParseCommandLineFlags(&argc, &argv, /*remove_flags=*/true);
  google::InitGoogleLogging(argv[0]);
  FLAGS_logtostderr = true;
  if (!FLAGS_verbose && FLAGS_minloglevel < google::GLOG_WARNING) {
    FLAGS_minloglevel = google::GLOG_WARNING;
  }
  if (argc < 2) {
    std::fputs(Usage().c_str(), stderr);
    return ceres_sesync::tools::kUsageOrInputError;
  }
  for (const Command& c : kCommands) {
    if (std::strcmp(argv[1], c.name) == 0) {
      return c.run(ceres_sesync::tools::Args(argv + 2, argv + argc));
    }
  }
  std::fprintf(stderr, "ceres_sesync: unknown command '%s'\n\n%s", argv[1],
               Usage().c_str());
  return ceres_sesync::tools::kUsageOrInputError;
}
