// Keeps CHOLMOD's OpenMP teams from costing more than they save.
//
// CHOLMOD 3 (SuiteSparse 5, as in Debian 12) scatters the entries of A and
// the updates from earlier supernodes into each large supernode in an OpenMP
// team of a fixed size (4), whatever the machine and the caller's thread
// count. Each team does little work, and waking it on every supernode costs
// more than the work when cores are few or busy. Measured on the 2-core
// machine, one supernodal factorization of the certificate matrix of a
// 10^5-pose 2D city (1.0e10 flops): 4.6 s with the teams, 3.2 s with teams of
// 2, 2.3 s with teams of one; Ceres's SPARSE_NORMAL_CHOLESKY runs the same
// kernel.
//
// ScopedSerialOpenMpTeams makes every OpenMP team that the calling thread
// opens while it lives a team of one: it sets the thread's dyn-var (the
// runtime may give a team fewer threads than its num_threads clause asks)
// and its nthreads-var to 1 (libgomp bounds a dynamic team by it, whatever
// the load). Both are ICVs of the calling thread's data environment, so other
// threads of the process keep theirs, and the previous values are restored
// on destruction. The scatters write each entry from one thread, so factors
// do not depend on the team size (tests/openmp_teams_test.cc).
//
// The runtime is the one CHOLMOD was linked with (libgomp), found among the
// loaded libraries at first use; without it this does nothing.
#ifndef CERES_SESYNC_INTERNAL_OPENMP_TEAMS_H_
#define CERES_SESYNC_INTERNAL_OPENMP_TEAMS_H_

namespace ceres_sesync::internal {

class ScopedSerialOpenMpTeams {
 public:
  ScopedSerialOpenMpTeams();
  ~ScopedSerialOpenMpTeams();
  ScopedSerialOpenMpTeams(const ScopedSerialOpenMpTeams&) = delete;
  ScopedSerialOpenMpTeams& operator=(const ScopedSerialOpenMpTeams&) = delete;

  // Whether an OpenMP runtime is loaded (else the guard does nothing).
  static bool RuntimeLoaded();
  // The calling thread's dyn-var (false without a runtime) and
  // nthreads-var (0 without a runtime).
  static bool Dynamic();
  static int MaxThreads();

 private:
  bool dynamic_ = false;
  int max_threads_ = 0;
};

}  // namespace ceres_sesync::internal

#endif  // CERES_SESYNC_INTERNAL_OPENMP_TEAMS_H_
