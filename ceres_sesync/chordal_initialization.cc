#include "ceres_sesync/chordal_initialization.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <numeric>
#include <vector>

#include "ceres_sesync/internal/chordal.h"
#include "ceres_sesync/internal/extended_cholesky.h"
#include "ceres_sesync/internal/rounding.h"
#include "ceres_sesync/internal/sesync_problem.h"
#include "ceres_sesync/internal/sparse_cholesky_factor.h"
#include "glog/logging.h"

namespace ceres_sesync {

namespace internal {

namespace {

int FindRoot(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

// Block-coordinate Procrustes over the component rotations G_c (see
// ChordalRotations): G_c = Proj(M^T), M = -sum_{c' != c} A_cc' G_c'^T.
std::vector<Eigen::MatrixXd> AlignComponents(const Eigen::MatrixXd& A, int d,
                                             int k) {
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(d, d);
  std::vector<Eigen::MatrixXd> G(k, I);
  for (int sweep = 0; sweep < 50; ++sweep) {
    double change = 0;
    for (int c = 1; c < k; ++c) {
      Eigen::MatrixXd M = Eigen::MatrixXd::Zero(d, d);
      for (int e = 0; e < k; ++e) {
        if (e != c) M -= A.block(d * c, d * e, d, d) * G[e].transpose();
      }
      const Eigen::MatrixXd next = ProjectToRotation(M.transpose());
      change = std::max(change, (next - G[c]).norm());
      G[c] = next;
    }
    if (k == 2 || change < 1e-12) break;  // k = 2: one exact step.
  }
  return G;
}

// For d = 2 the blocks of L(G^rho) are kappa-weighted sums of rotations
// [[c, -s], [s, c]], i.e. the real form of complex numbers c + i s, and the
// chordal problem is the complex Hermitian system of size n_free (Z x = b)
// instead of the real one of size 2 n_free: a quarter of the factor's real
// entries' work (4 real flops per complex one, against 2 x 2 blocks of 4
// entries each), ~2x fewer flops in all. Fills Z and b (the anchors' column
// sums, -sum_a Z_ka) if every block is exactly of that form (entries (0, 0)
// = (1, 1) and (0, 1) = -(1, 0), bitwise; absent entries are 0); else
// returns false (a graph with rotations given as general 2 x 2 matrices) and
// the caller solves the real system, as for d = 3.
bool ComplexChordalSystem(const SparseMatrix& L,
                          const std::vector<int>& free_index, int num_free,
                          ComplexSparseMatrix* Z, Eigen::VectorXcd* b) {
  const int n = static_cast<int>(L.cols()) / 2;
  std::vector<std::array<double, 4>> block(n, {0, 0, 0, 0});
  std::vector<int> touched;
  std::vector<char> seen(n, 0);
  std::vector<Eigen::Triplet<std::complex<double>>> triplets;
  triplets.reserve(L.nonZeros() / 4 + n);
  b->setZero(num_free);
  for (int j = 0; j < n; ++j) {
    // Gather block column j: entry (r % 2) + 2 (c % 2) of block r / 2.
    for (int c = 2 * j; c < 2 * j + 2; ++c) {
      for (SparseMatrix::InnerIterator it(L, c); it; ++it) {
        const int i = static_cast<int>(it.row()) / 2;
        if (!seen[i]) {
          seen[i] = 1;
          touched.push_back(i);
        }
        block[i][it.row() % 2 + 2 * (c % 2)] = it.value();
      }
    }
    for (int i : touched) {
      const std::array<double, 4>& v = block[i];
      if (v[0] != v[3] || v[2] != -v[1]) return false;
      const std::complex<double> z(v[0], v[1]);
      const int fr = free_index[i], fc = free_index[j];
      if (fr >= 0 && fc >= 0 && fr >= fc) triplets.emplace_back(fr, fc, z);
      if (fr >= 0 && fc < 0) (*b)(fr) -= z;
      block[i] = {0, 0, 0, 0};
      seen[i] = 0;
    }
    touched.clear();
  }
  Z->resize(num_free, num_free);
  Z->setFromTriplets(triplets.begin(), triplets.end());
  return true;
}

}  // namespace

bool ChordalRotationsFromLaplacian(const SparseMatrix& L, int d,
                                   Eigen::MatrixXd* R,
                                   std::vector<int>* component,
                                   const std::vector<int>* block_ordering,
                                   int num_threads) {
  const int dn = static_cast<int>(L.rows()), n = dn / d;
  // Components of the block graph: off-diagonal blocks with a nonzero entry.
  std::vector<int> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  for (int k = 0; k < L.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(L, k); it; ++it) {
      const int a = static_cast<int>(it.row()) / d,
                b = static_cast<int>(it.col()) / d;
      if (a != b && it.value() != 0) {
        parent[FindRoot(parent, a)] = FindRoot(parent, b);
      }
    }
  }
  // Anchors: the first block of each component, fixed at I; the others
  // ("free") are numbered in order.
  std::vector<int> label(n, -1), root_label(n, -1), free_index(n, -1);
  int num_components = 0, num_free = 0;
  for (int i = 0; i < n; ++i) {
    const int root = FindRoot(parent, i);
    if (root_label[root] < 0) {
      root_label[root] = num_components++;
    } else {
      free_index[i] = num_free++;
    }
    label[i] = root_label[root];
  }
  if (component) *component = label;
  R->setZero(d, dn);
  for (int i = 0; i < n; ++i) {
    if (free_index[i] < 0) R->middleCols(d * i, d).setIdentity();
  }
  if (num_free == 0) return true;
  // The fill-reducing ordering of the free blocks: empty unless given for
  // all of them.
  std::vector<int> block_order;
  if (block_ordering != nullptr) {
    std::vector<char> seen(n, 0);
    block_order.reserve(num_free);
    for (int block : *block_ordering) {
      if (block < 0 || block >= n || seen[block] || free_index[block] < 0) {
        continue;
      }
      seen[block] = 1;
      block_order.push_back(free_index[block]);
    }
    if (static_cast<int>(block_order.size()) != num_free) block_order.clear();
  }
  // With R = [I .. I (anchors), X]: minimize tr(X L_ff X^T) + 2 tr(L_fa A
  // X^T), i.e. solve L_ff X^T = -L_fa A (L_ff is positive definite when
  // every component is connected through nonzero blocks).
  if (d == 2) {
    ComplexSparseMatrix Z;
    Eigen::VectorXcd b;
    if (ComplexChordalSystem(L, free_index, num_free, &Z, &b)) {
      ComplexCholmodFactor factor;
      ConfigureCholmod(CholmodLayout::kAutomatic, &factor);
      if (!block_order.empty()) {
        factor.AnalyzePatternWithOrdering(Z, block_order);
      } else {
        factor.analyzePattern(Z);
      }
      factor.factorize(Z);
      if (factor.info() != Eigen::Success) return false;
      const Eigen::VectorXcd x = factor.solve(b);
      // The real form of x: block k of X^T is [[Re, -Im], [Im, Re]] x_k.
      Eigen::MatrixXd X(2, 2 * num_free);
      for (int k = 0; k < num_free; ++k) {
        X(0, 2 * k) = X(1, 2 * k + 1) = x(k).real();
        X(0, 2 * k + 1) = x(k).imag();
        X(1, 2 * k) = -x(k).imag();
      }
      X = ProjectBlocksToRotations(X, d);
      for (int i = 0; i < n; ++i) {
        if (free_index[i] >= 0) {
          R->middleCols(2 * i, 2) = X.middleCols(2 * free_index[i], 2);
        }
      }
      return true;
    }
  }
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(L.nonZeros());
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(d * num_free, d);
  for (int k = 0; k < L.outerSize(); ++k) {
    for (SparseMatrix::InnerIterator it(L, k); it; ++it) {
      const int r = static_cast<int>(it.row()), c = static_cast<int>(it.col());
      const int fr = free_index[r / d], fc = free_index[c / d];
      if (fr < 0) continue;
      if (fc >= 0) {
        triplets.emplace_back(d * fr + r % d, d * fc + c % d, it.value());
      } else {
        rhs(d * fr + r % d, c % d) -= it.value();
      }
    }
  }
  SparseMatrix L_ff(d * num_free, d * num_free);
  L_ff.setFromTriplets(triplets.begin(), triplets.end());
  const int size = d * num_free;
  std::vector<int> ordering;
  ordering.reserve(size);
  for (int k : block_order) {
    for (int a = 0; a < d; ++a) ordering.push_back(d * k + a);
  }
  // With the vertices' ordering, each free block's d unknowns are pivots
  // together: the pattern, completed to whole d x d blocks (the diagonal
  // blocks' off-diagonal zeros), is analyzed by blocks.
  std::vector<int> block_start;
  if (ordering.empty()) {  // No ordering, or not of every free block.
    CholmodFactor analysis;
    ConfigureCholmod(CholmodLayout::kSimplicial, &analysis);
    analysis.analyzePattern(L_ff);
    ordering = analysis.Ordering();
  } else {
    for (int k = 0; k <= num_free; ++k) block_start.push_back(d * k);
  }
  // The project's supernodal Cholesky (extended_cholesky.h, in double) with
  // the solves of sparse_cholesky_factor.h, not CHOLMOD: on sphere2500 and
  // torus3D CHOLMOD's simplicial factorization was ~80% of this stage.
  // Scaled by a power of two (exact) so that the pivots stay within the
  // range the factorization accepts for any precisions.
  std::vector<int> position(size);
  for (int k = 0; k < size; ++k) position[ordering[k]] = k;
  PermutedPattern pattern =
      block_start.empty()
          ? PermuteSymmetricPattern(size, L_ff.outerIndexPtr(),
                                    L_ff.innerIndexPtr(), position)
          : PermuteSymmetricBlockPattern(size, L_ff.outerIndexPtr(),
                                         L_ff.innerIndexPtr(), position,
                                         block_start);
  int exponent = 0;
  std::frexp(L_ff.coeffs().cwiseAbs().maxCoeff(), &exponent);
  std::vector<double> values(pattern.row_index.size());
  for (int q = 0; q < L_ff.nonZeros(); ++q) {
    if (pattern.slot[q] >= 0) {
      values[pattern.slot[q]] = std::ldexp(L_ff.valuePtr()[q], -exponent);
    }
  }
  DoubleDoubleCholesky::Options options;
  options.num_threads = num_threads;
  DoubleDoubleCholesky factor(options);
  factor.Analyze(size, std::move(pattern.column_start),
                 std::move(pattern.row_index), block_start);
  if (!factor.Factorize(values)) return false;
  const SparseCholeskyFactor solver(
      std::move(ordering),
      [&factor](const SparseCholeskyFactor::SupernodeVisitor& supernode) {
        factor.ForEachSupernode(supernode);
      });
  // X^T = L_ff^{-1} rhs, i.e. X = rhs^T L_ff^{-1}; the scaling is undone on
  // the right-hand side.
  Eigen::MatrixXd X;
  const Eigen::MatrixXd B = (rhs * std::ldexp(1.0, -exponent)).transpose();
  solver.SolveRows(B, &X, num_threads);
  X = ProjectBlocksToRotations(X, d);
  for (int i = 0; i < n; ++i) {
    if (free_index[i] >= 0) {
      R->middleCols(d * i, d) = X.middleCols(d * free_index[i], d);
    }
  }
  return true;
}

bool ChordalRotations(const SESyncProblem& problem, Eigen::MatrixXd* R) {
  const int d = problem.dimension(), n = problem.num_rotations();
  std::vector<int> component, block_ordering;
  block_ordering.reserve(n);
  for (int vertex : problem.vertex_ordering()) {
    const int block = problem.layout().rotation_of_vertex(vertex);
    if (block >= 0) block_ordering.push_back(block);
  }
  if (!ChordalRotationsFromLaplacian(problem.RotationLaplacian(), d, R,
                                     &component, &block_ordering,
                                     problem.num_threads())) {
    return false;
  }
  const int k = *std::max_element(component.begin(), component.end()) + 1;
  if (k <= 1) return true;
  constexpr int kMaxAlignedComponents = 64;
  if (k > kMaxAlignedComponents) {
    VLOG(1) << "chordal initialization: " << k
            << " rotation components, not aligned";
    return true;
  }
  // C: row block c holds the rotations of component c (zeros elsewhere).
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(d * k, d * n);
  for (int i = 0; i < n; ++i) {
    C.block(d * component[i], d * i, d, d) = R->middleCols(d * i, d);
  }
  Eigen::MatrixXd CQ;
  problem.MultiplyQ(C, &CQ);
  const Eigen::MatrixXd A = CQ * C.transpose();
  const std::vector<Eigen::MatrixXd> G = AlignComponents(A, d, k);
  for (int i = 0; i < n; ++i) {
    R->middleCols(d * i, d) = G[component[i]] * R->middleCols(d * i, d);
  }
  return true;
}

}  // namespace internal

namespace {

// Chordal rotations (d x dn, n rotation blocks) and the optimal translations
// (d x N), in the frame of the world pose with priors, else with R_0 = I and
// t_0 = 0.
bool Chordal(const PoseGraph& graph, Solution* solution, std::string* error) {
  if (!ValidatePoseGraph(graph, error)) return false;
  const internal::SESyncProblem problem(graph);
  Eigen::MatrixXd R;
  if (!problem.ok() || !internal::ChordalRotations(problem, &R)) {
    if (error) *error = "chordal initialization: sparse Cholesky failed";
    return false;
  }
  const Eigen::MatrixXd T = problem.RecoverTranslations(R);
  const internal::ProblemLayout& layout = problem.layout();
  const int d = graph.dimension;
  Eigen::MatrixXd A = Eigen::MatrixXd::Identity(d, d);
  Eigen::VectorXd c = T.col(layout.gauge());
  if (layout.world_rotation) {
    A = R.middleCols(d * layout.world_rotation_block(), d).transpose();
  }
  solution->poses.resize(graph.num_poses);
  for (int i = 0; i < graph.num_poses; ++i) {
    const Eigen::MatrixXd Ri = R.middleCols(d * i, d);
    solution->poses[i] =
        Pose{layout.world_rotation ? internal::ProjectToRotation(A * Ri) : Ri,
             A * (T.col(i) - c)};
  }
  solution->landmarks.resize(graph.num_landmarks);
  for (int l = 0; l < graph.num_landmarks; ++l) {
    solution->landmarks[l] = A * (T.col(layout.landmark_node(l)) - c);
  }
  return true;
}

}  // namespace

bool ChordalRotations(const PoseGraph& graph, Eigen::MatrixXd* R,
                      std::string* error) {
  Solution solution;
  if (!Chordal(graph, &solution, error)) return false;
  const int d = graph.dimension;
  R->resize(d, d * graph.num_poses);
  for (int i = 0; i < graph.num_poses; ++i) {
    R->middleCols(d * i, d) = solution.poses[i].R;
  }
  return true;
}

bool ChordalInitialization(const PoseGraph& graph, Poses* poses,
                           std::string* error) {
  Solution solution;
  if (!Chordal(graph, &solution, error)) return false;
  *poses = std::move(solution.poses);
  return true;
}

bool ChordalInitialization(const PoseGraph& graph, Solution* solution,
                           std::string* error) {
  return Chordal(graph, solution, error);
}

}  // namespace ceres_sesync
