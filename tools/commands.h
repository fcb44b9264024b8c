// Subcommands of the `ceres_sesync` program. Each takes the positional
// arguments after the subcommand name (flags are parsed once by gflags in
// ceres_sesync_main.cc) and returns the process exit code:
//   0 = success (for solve/certify: a certified global optimum),
//   1 = ran but not certified,
//   2 = usage or input error (message on stderr naming the file and line).
// Output files are written atomically (temporary file + rename).

#ifndef CERES_SESYNC_TOOLS_COMMANDS_H_
#define CERES_SESYNC_TOOLS_COMMANDS_H_

#include <string>
#include <vector>

#include "ceres_sesync/sesync_solver.h"
#include "gflags/gflags.h"

DECLARE_string(json);
DECLARE_string(output);
DECLARE_bool(verbose);
DECLARE_int32(num_threads);
DECLARE_string(proof_arithmetic);

namespace ceres_sesync::tools {

enum ExitCode { kSuccess = 0, kNotCertified = 1, kUsageOrInputError = 2 };

using Args = std::vector<std::string>;

int RunInfo(const Args& args);
int RunSolve(const Args& args);
int RunCertify(const Args& args);
int RunGenerate(const Args& args);

// --proof_arithmetic: "automatic", "double" or "double-double"; false for
// anything else.
bool ParseProofArithmetic(const std::string& name,
                          SolverOptions::ProofArithmetic* arithmetic);

}  // namespace ceres_sesync::tools

#endif  // CERES_SESYNC_TOOLS_COMMANDS_H_
