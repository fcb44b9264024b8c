// The `ceres_sesync` command-line program: dispatches to a subcommand.
//
// Every subcommand lists its own flags below (kCommands); `ceres_sesync help
// COMMAND` and `ceres_sesync COMMAND --help` print them with their defaults,
// and a flag of the program that the command does not take is a usage error.
// The logging library's flags (--v, --logtostderr, ...) are accepted
// everywhere and listed by --helpfull only.

#include <sys/ioctl.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <set>
#include <string>
#include <vector>

#include "ceres_sesync/process_memory.h"
#include "gflags/gflags.h"
#include "glog/logging.h"
#include "tools/commands.h"

DEFINE_string(json, "", "Write a machine-readable JSON summary to this path.");
DEFINE_string(output, "", "Write the resulting poses (g2o) to this path.");
DEFINE_bool(verbose, false, "Log solver progress to stderr (glog INFO).");
DEFINE_string(proof_arithmetic, "automatic",
              "Arithmetic of the certificate's proof: 'automatic' (double, "
              "then double-double when double cannot reach the goal bound), "
              "'double' or 'double-double'.");
DEFINE_int32(num_threads, 0, "Threads for the O(m r) kernels (0: all cores).");

namespace {

using ceres_sesync::tools::Args;
using ceres_sesync::tools::kSuccess;
using ceres_sesync::tools::kUsageOrInputError;

// A flag of a command, with an optional command-specific description that
// replaces the flag's own.
struct FlagHelp {
  const char* name;
  const char* help = nullptr;
};

struct Command {
  const char* name;
  int (*run)(const Args&);
  const char* synopsis;  // The positional arguments.
  const char* summary;   // One line for the command list.
  const char* description;
  std::vector<FlagHelp> flags;
};

const std::vector<Command>& Commands() {
  static const std::vector<Command> commands = {
      {"info",
       ceres_sesync::tools::RunInfo,
       "GRAPH.g2o",
       "describe a pose graph (sizes, components)",
       "Reads a pose graph and describes it: dimension, poses, edges, "
       "connected components, the range of the precisions kappa and tau, "
       "initial guess, FIX vertex, skipped lines.",
       {{"json"}, {"skip_unsupported_tags"}}},
      {"solve",
       ceres_sesync::tools::RunSolve,
       "GRAPH.g2o",
       "solve with SE-Sync and certify the result",
       "Solves the pose graph with SE-Sync (Riemannian staircase, rounding) "
       "and proves the result globally optimal when the relaxation is exact. "
       "Landmarks and priors are part of the problem; with priors the "
       "solution is in their world frame. Exit code 0 when certified, 1 when "
       "not.",
       {{"output",
         "Write the solution (VERTEX lines: poses, then landmark positions, "
         "original ids) to this g2o file."},
        {"tum"},
        {"json"},
        {"components"},
        {"init"},
        {"seed", "Seed of --init random."},
        {"initial_rank"},
        {"max_rank"},
        {"preconditioner"},
        {"local_solver"},
        {"gradient_tolerance"},
        {"test_certificate_after_escape"},
        {"test_certificate_near_convergence"},
        {"newton_at_rank_d"},
        {"max_time"},
        {"num_threads"},
        {"proof_arithmetic"},
        {"progress"},
        {"robust"},
        {"inlier_threshold"},
        {"inlier_probability"},
        {"known_inliers"},
        {"edge_report"},
        {"verbose"}}},
      {"certify",
       ceres_sesync::tools::RunCertify,
       "GRAPH.g2o POSES.g2o",
       "certify a given solution (e.g. from Ceres)",
       "Proves the poses of POSES.g2o (VERTEX lines, matched by id; landmark "
       "VERTEX_XY / VERTEX_TRACKXYZ lines too when the graph has landmarks) "
       "globally optimal for GRAPH.g2o, or gives a proven lower bound on the "
       "optimum and a suboptimality bound. Exit code 0 when certified, 1 "
       "when not.",
       {{"json"},
        {"max_relative_suboptimality"},
        {"improve"},
        {"output",
         "With --improve: write the improved solution (poses and landmarks) "
         "to this g2o file."},
        {"num_threads"},
        {"proof_arithmetic"},
        {"progress", "With --improve: show the solve's progress (see solve)."},
        {"verbose"}}},
      {"generate",
       ceres_sesync::tools::RunGenerate,
       "cube|city|landmarks|outliers",
       "write a synthetic pose graph (cube, city, landmarks, outliers)",
       "'generate cube' writes the synthetic cube benchmark of SE-Sync's "
       "Section 6.1: a boustrophedon path through an s x s x s lattice (s x s "
       "in 2D) with odometry, random loop closures and noise of the paper's "
       "model. 'generate city' writes a large Manhattan-style random walk "
       "(--poses N) for scaling studies, with loop closures at revisited "
       "places. 'generate landmarks' writes a Manhattan walk observing random "
       "point landmarks within a sensor range, with optional GPS-like "
       "position priors and a start prior (--preset victoria: many landmarks "
       "per pose). 'generate outliers GRAPH.g2o' writes a copy of a graph "
       "with wrong loop closures appended (--fraction of all its loop "
       "closures; random, or clustered: groups of mutually consistent wrong "
       "closures), wrong landmark associations (--landmark_fraction) and "
       "false position fixes (--prior_fraction), and the indices of what it "
       "added.",
       {{"output", "Write the generated graph to this g2o file (required)."},
        {"side"},
        {"poses"},
        {"dimension"},
        {"loop_closure_probability"},
        {"loop_closure_radius"},
        {"kappa"},
        {"tau"},
        {"seed",
         "Random seed (the output is a deterministic function of "
         "the flags)."},
        {"ground_truth"},
        {"vertices"},
        {"preset"},
        {"num_poses"},
        {"num_landmarks"},
        {"sensor_range"},
        {"world_size"},
        {"block_length"},
        {"step_length"},
        {"turn_probability"},
        {"detection_probability"},
        {"max_observations"},
        {"landmark_nu"},
        {"gps_interval"},
        {"gps_tau"},
        {"start_prior"},
        {"start_prior_kappa"},
        {"start_prior_tau"},
        {"noiseless"},
        {"fraction"},
        {"mode"},
        {"cluster_size"},
        {"landmark_fraction"},
        {"prior_fraction"},
        {"outlier_indices"}}},
  };
  return commands;
}

const Command* FindCommand(const std::string& name) {
  for (const Command& c : Commands()) {
    if (name == c.name) return &c;
  }
  return nullptr;
}

int TerminalWidth() {
  winsize size{};
  if (isatty(fileno(stdout)) && ioctl(fileno(stdout), TIOCGWINSZ, &size) == 0 &&
      size.ws_col >= 40) {
    return size.ws_col;
  }
  return 80;
}

// `text` word-wrapped to `width` columns, each line indented by `indent`.
std::string Wrap(const std::string& text, int indent, int width) {
  std::string out, line;
  size_t k = 0;
  while (k < text.size()) {
    while (k < text.size() && text[k] == ' ') ++k;
    const size_t end = std::min(text.find(' ', k), text.size());
    if (k == end) break;
    const std::string word = text.substr(k, end - k);
    if (!line.empty() &&
        indent + line.size() + 1 + word.size() > static_cast<size_t>(width)) {
      out += std::string(indent, ' ') + line + "\n";
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
    k = end;
  }
  if (!line.empty()) out += std::string(indent, ' ') + line + "\n";
  return out;
}

// The shortest "%g" form of `x` that reads back as `x` (0.1, not gflags'
// 0.10000000000000001).
std::string ShortestDouble(double x) {
  char buf[64];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof(buf), "%.*g", digits, x);
    if (std::strtod(buf, nullptr) == x) break;
  }
  return buf;
}

std::string GeneralHelp() {
  std::string s =
      "usage: ceres_sesync COMMAND ARGS [flags]\n"
      "Certifiably correct pose-graph optimization (SE-Sync) for Ceres "
      "users.\n\ncommands:\n";
  char buf[256];
  for (const Command& c : Commands()) {
    const std::string call = std::string(c.name) + " " + c.synopsis;
    std::snprintf(buf, sizeof(buf), "  %-30s %s\n", call.c_str(), c.summary);
    s += buf;
  }
  std::snprintf(buf, sizeof(buf), "  %-30s %s\n", "help [COMMAND]",
                "this text, or the flags of a command");
  s += buf;
  s += "\n" +
       Wrap(
           "'ceres_sesync help COMMAND' (or 'ceres_sesync COMMAND --help') "
           "lists the flags of a command with their defaults.",
           0, 80) +
       "exit codes: 0 success/certified, 1 not certified, 2 usage or input "
       "error\n";
  return s;
}

std::string CommandHelp(const Command& c) {
  const int width = TerminalWidth();
  std::string s = std::string("usage: ceres_sesync ") + c.name + " " +
                  c.synopsis + " [flags]\n\n" + Wrap(c.description, 0, width) +
                  "\nflags (shown with their defaults):\n";
  for (const FlagHelp& f : c.flags) {
    gflags::CommandLineFlagInfo info;
    if (!gflags::GetCommandLineFlagInfo(f.name, &info)) {
      // A programming error: the table names a flag nobody defines.
      LOG(FATAL) << "command " << c.name << " lists an undefined flag --"
                 << f.name;
    }
    std::string value = info.default_value;
    if (info.type == "string") {
      value = "\"" + value + "\"";
    } else if (info.type == "double") {
      value = ShortestDouble(std::strtod(value.c_str(), nullptr));
    }
    s += "  --" + info.name + "=" + value + "\n" +
         Wrap(f.help ? f.help : info.description, 6, width);
  }
  return s;
}

// Every flag some command lists: the program's own flags.
std::set<std::string> ProgramFlags() {
  std::set<std::string> names;
  for (const Command& c : Commands()) {
    for (const FlagHelp& f : c.flags) names.insert(f.name);
  }
  return names;
}

// Flags are checked before gflags parses them, so that an unknown flag is a
// usage error (exit 2; gflags would exit 1, the "not certified" code).
bool CheckFlagNames(int argc, char** argv) {
  for (int k = 1; k < argc; ++k) {
    const std::string arg = argv[k];
    if (arg == "--") break;
    if (arg.size() < 2 || arg[0] != '-') continue;
    const size_t begin = arg[1] == '-' ? 2 : 1;
    const size_t eq = arg.find('=');
    const std::string name = arg.substr(begin, eq - begin);
    gflags::CommandLineFlagInfo info;
    if (gflags::GetCommandLineFlagInfo(name.c_str(), &info)) {
      // "--flag value": skip the value.
      if (info.type != "bool" && eq == std::string::npos) ++k;
      continue;
    }
    if (name.rfind("no", 0) == 0 &&
        gflags::GetCommandLineFlagInfo(name.substr(2).c_str(), &info) &&
        info.type == "bool") {
      continue;
    }
    std::fprintf(stderr,
                 "ceres_sesync: unknown flag '%s' (see 'ceres_sesync help')\n",
                 arg.c_str());
    return false;
  }
  return true;
}

// False (with a message) if a program flag was set that `command` does not
// take.
bool CheckCommandFlags(const Command& command) {
  std::set<std::string> taken;
  for (const FlagHelp& f : command.flags) taken.insert(f.name);
  const std::set<std::string> program = ProgramFlags();
  std::vector<gflags::CommandLineFlagInfo> all;
  gflags::GetAllFlags(&all);
  for (const gflags::CommandLineFlagInfo& info : all) {
    if (info.is_default || !program.count(info.name) ||
        taken.count(info.name)) {
      continue;
    }
    std::fprintf(stderr,
                 "ceres_sesync %s: --%s is not a flag of this command (see "
                 "'ceres_sesync help %s')\n",
                 command.name, info.name.c_str(), command.name);
    return false;
  }
  return true;
}

bool FlagIsSet(const char* name) {
  std::string value;
  return gflags::GetCommandLineOption(name, &value) && value == "true";
}

}  // namespace

namespace {

// glibc's malloc backs its heap with transparent huge pages (madvise) when
// its tunable glibc.malloc.hugetlb is 1: one page fault per 2 MiB instead of
// per 4 KiB. With KeepFreedMemory() every block comes from the heap, so that
// covers the solver's allocations. Tunables are read when the process
// starts, so the tool starts itself once more with the tunable added, unless
// GLIBC_TUNABLES already names it (a user's choice, e.g. =0, is kept: the
// way to run the tool without the restart, e.g. under valgrind, which does
// not follow an exec by default). Where the exec fails the tool goes on as
// it is. Measured (CLI solve, one run, the 2-core VM of bench/ where a fault
// costs ~7-12 us; THP "madvise"): kitti_00 99 -> 48 ms (5,610 -> 1,260
// faults), manhattan 0.10 -> 0.06 s, city10000 0.29 -> 0.19 s, sphere2500
// 0.16 -> 0.12 s; peak RSS +2-10%.
void RestartWithHugePageHeap(char** argv) {
#ifdef __GLIBC__
  constexpr char kTunable[] = "glibc.malloc.hugetlb";
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  std::string value = tunables != nullptr ? tunables : "";
  if (value.find(kTunable) != std::string::npos) return;
  const std::string previous = value;
  value += (value.empty() ? "" : ":") + std::string(kTunable) + "=1";
  if (setenv("GLIBC_TUNABLES", value.c_str(), 1) != 0) return;
  execv("/proc/self/exe", argv);
  // Still here: the exec failed; go on with the environment as it was.
  if (tunables != nullptr) {
    setenv("GLIBC_TUNABLES", previous.c_str(), 1);
  } else {
    unsetenv("GLIBC_TUNABLES");
  }
#else
  (void)argv;
#endif
}

}  // namespace

int main(int argc, char** argv) {
  RestartWithHugePageHeap(argv);
  // Freed memory stays for the next factorization (process_memory.h).
  ceres_sesync::KeepFreedMemory();
  gflags::SetUsageMessage(GeneralHelp());
  gflags::SetVersionString(CERES_SESYNC_VERSION);
  if (!CheckFlagNames(argc, argv)) return kUsageOrInputError;
  gflags::ParseCommandLineNonHelpFlags(&argc, &argv, /*remove_flags=*/true);
  const std::string name = argc >= 2 ? argv[1] : "";
  // --help / --helpshort, `help` and `help COMMAND`: our own help text.
  if (name == "help" || FlagIsSet("help") || FlagIsSet("helpshort")) {
    const std::string topic =
        name == "help" ? (argc >= 3 ? argv[2] : "") : name;
    if (topic.empty()) {
      std::fputs(GeneralHelp().c_str(), stdout);
      return kSuccess;
    }
    const Command* command = FindCommand(topic);
    if (command == nullptr) {
      std::fprintf(stderr, "ceres_sesync: unknown command '%s'\n\n%s",
                   topic.c_str(), GeneralHelp().c_str());
      return kUsageOrInputError;
    }
    std::fputs(CommandHelp(*command).c_str(), stdout);
    return kSuccess;
  }
  // --helpfull, --helpxml, --version, ...: gflags' own (all flags).
  gflags::HandleCommandLineHelpFlags();

  google::InitGoogleLogging(argv[0]);
  FLAGS_logtostderr = true;
  if (!FLAGS_verbose && FLAGS_minloglevel < google::GLOG_WARNING) {
    FLAGS_minloglevel = google::GLOG_WARNING;
  }
  const char* tunables = std::getenv("GLIBC_TUNABLES");
  VLOG(1) << "GLIBC_TUNABLES=" << (tunables != nullptr ? tunables : "");
  if (name.empty()) {
    std::fputs(GeneralHelp().c_str(), stderr);
    return kUsageOrInputError;
  }
  const Command* command = FindCommand(name);
  if (command == nullptr) {
    std::fprintf(stderr, "ceres_sesync: unknown command '%s'\n\n%s",
                 name.c_str(), GeneralHelp().c_str());
    return kUsageOrInputError;
  }
  if (!CheckCommandFlags(*command)) return kUsageOrInputError;
  return command->run(Args(argv + 2, argv + argc));
}
