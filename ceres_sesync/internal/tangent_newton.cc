#include "ceres_sesync/internal/tangent_newton.h"

#include <algorithm>
#include <cmath>

#include "glog/logging.h"

namespace ceres_sesync::internal {

TangentNewton::TangentNewton(const SESyncProblem& problem)
    : problem_(problem),
      d_(problem.dimension()),
      p_(problem.dimension() * (problem.dimension() - 1) / 2),
      n_(problem.num_rotations()),
      t0_(problem.num_translations() - 1) {
  const ProblemLayout& layout = problem.layout();
  const int d = d_, p = p_, b = 1 + d;
  const int vertices = layout.num_vertices();
  // Unknowns: d per translation (of the reduced nodes), then p per rotation.
  rotation_offset_ = d * t0_;
  num_unknowns_ = rotation_offset_ + p * n_;
  translation_of_vertex_.resize(vertices);
  rotation_of_vertex_.resize(vertices);
  for (int v = 0; v < vertices; ++v) {
    const int node = layout.translation_of_vertex(v);
    translation_of_vertex_[v] = node >= 0 ? layout.reduced(node) : -1;
    rotation_of_vertex_[v] = layout.rotation_of_vertex(v);
  }
  // f(v, lv, w, lw, value) for every stored entry of K_0 without Lambda,
  // (vertex, local index) of its row and of its column: local index 0 the
  // translation, 1 + c the rotation's column c. Each is one entry of Lbar,
  // Vbar (twice: K_0 holds -Vbar and -Vbar^T) or D. Translation node k is
  // vertex k.
  const SparseMatrix& L = problem.Lbar();
  const SparseMatrix& V = problem.Vbar();
  const SparseMatrix& D = problem.D();
  auto for_each_entry_of_k0 = [&](auto&& f) {
    for (int k = 0; k < L.outerSize(); ++k) {
      for (SparseMatrix::InnerIterator it(L, k); it; ++it) {
        f(layout.unreduced(it.row()), 0, layout.unreduced(k), 0, it.value());
      }
    }
    for (int k = 0; k < V.outerSize(); ++k) {
      for (SparseMatrix::InnerIterator it(V, k); it; ++it) {
        const int vt = layout.unreduced(it.row());
        const int vr = layout.vertex_of_rotation(k / d);
        f(vt, 0, vr, 1 + k % d, -it.value());
        f(vr, 1 + k % d, vt, 0, -it.value());
      }
    }
    for (int k = 0; k < D.outerSize(); ++k) {
      for (SparseMatrix::InnerIterator it(D, k); it; ++it) {
        f(layout.vertex_of_rotation(it.row() / d), 1 + it.row() % d,
          layout.vertex_of_rotation(k / d), 1 + k % d, it.value());
      }
    }
  };
  // K_0's entries, each as (v, w) with v >= w (swapped where needed),
  // bucketed by w: a counting pass, then a fill.
  struct Entry {
    int v, local;  // local: lw (1 + d) + lv in the pair's block.
    double value;
  };
  std::vector<int> bucket_start(vertices + 1, 0);
  for_each_entry_of_k0([&](int v, int, int w, int, double) {
    ++bucket_start[std::min(v, w) + 1];
  });
  for (int v = 0; v < vertices; ++v) bucket_start[v + 1] += bucket_start[v];
  std::vector<Entry> entries(bucket_start.back());
  {
    std::vector<int> next(bucket_start.begin(), bucket_start.end() - 1);
    for_each_entry_of_k0([&](int v, int lv, int w, int lw, double value) {
      if (v < w) {
        std::swap(v, w);
        std::swap(lv, lw);
      }
      entries[next[w]++] = {v, lw * b + lv, value};
    });
  }
  // The vertex pairs (v >= w): by w, its diagonal pair first, then those of
  // its entries in their order; K_0's (1 + d) x (1 + d) block of each
  // (column-major) in base_. pair_of[v] is v's pair in the current w's
  // bucket if it is at least that bucket's first pair.
  std::vector<int> pair_of(vertices, -1);
  // About the number of pairs (a full block has b^2 entries, and each
  // vertex's diagonal block is counted besides).
  const size_t expected_pairs = vertices + entries.size() / (b * b);
  pair_first_.reserve(expected_pairs);
  pair_second_.reserve(expected_pairs);
  base_.reserve(expected_pairs * b * b);
  for (int w = 0; w < vertices; ++w) {
    const int first_pair = static_cast<int>(pair_first_.size());
    auto pair_index = [&](int v) {
      if (pair_of[v] < first_pair) {
        pair_of[v] = static_cast<int>(pair_first_.size());
        pair_first_.push_back(v);
        pair_second_.push_back(w);
        base_.resize(base_.size() + b * b, 0.0);
      }
      return pair_of[v];
    };
    pair_index(w);
    for (int q = bucket_start[w]; q < bucket_start[w + 1]; ++q) {
      const Entry& e = entries[q];
      base_[static_cast<size_t>(pair_index(e.v)) * b * b + e.local] = e.value;
    }
  }
  const size_t num_pairs = pair_first_.size();
  // The unknowns of each vertex, and the elimination order: the vertices'
  // (problem.vertex_ordering()), each vertex's unknowns together.
  unknown_start_.assign(vertices + 1, 0);
  for (int v = 0; v < vertices; ++v) {
    unknown_start_[v + 1] = unknown_start_[v] +
                            (translation_of_vertex_[v] >= 0 ? d : 0) +
                            (rotation_of_vertex_[v] >= 0 ? p : 0);
  }
  unknowns_.resize(unknown_start_[vertices]);
  for (int v = 0; v < vertices; ++v) {
    int at = unknown_start_[v];
    if (translation_of_vertex_[v] >= 0) {
      for (int a = 0; a < d; ++a) {
        unknowns_[at++] = d * translation_of_vertex_[v] + a;
      }
    }
    if (rotation_of_vertex_[v] >= 0) {
      for (int k = 0; k < p; ++k) {
        unknowns_[at++] = rotation_offset_ + p * rotation_of_vertex_[v] + k;
      }
    }
  }
  CHECK_EQ(static_cast<int>(unknowns_.size()), num_unknowns_);
  std::vector<int> block_start(1, 0);  // Each vertex's unknowns, pivots.
  for (int v : problem.vertex_ordering()) {
    for (int t = unknown_start_[v]; t < unknown_start_[v + 1]; ++t) {
      ordering_.push_back(unknowns_[t]);
    }
    if (static_cast<int>(ordering_.size()) > block_start.back()) {
      block_start.push_back(static_cast<int>(ordering_.size()));
    }
  }
  CHECK_EQ(static_cast<int>(ordering_.size()), num_unknowns_);
  std::vector<int> position(num_unknowns_);
  for (int k = 0; k < num_unknowns_; ++k) position[ordering_[k]] = k;
  // The permuted upper pattern of H, each unordered pair of unknowns once:
  // block (v, w) for v > w whole, for v = w its lower triangle; slot_ in
  // that order (pair, column j of the block, row i).
  std::vector<int> column_start(num_unknowns_ + 1, 0);
  auto for_each_entry = [&](auto&& f) {
    for (size_t k = 0; k < num_pairs; ++k) {
      const int v = pair_first_[k], w = pair_second_[k];
      for (int j = unknown_start_[w]; j < unknown_start_[w + 1]; ++j) {
        for (int i = v == w ? j : unknown_start_[v]; i < unknown_start_[v + 1];
             ++i) {
          const int pi = position[unknowns_[i]], pj = position[unknowns_[j]];
          f(std::max(pi, pj), std::min(pi, pj));
        }
      }
    }
  };
  for_each_entry([&](int column, int) { ++column_start[column + 1]; });
  for (int k = 0; k < num_unknowns_; ++k) {
    column_start[k + 1] += column_start[k];
  }
  std::vector<int> next(column_start.begin(), column_start.end() - 1);
  std::vector<int> row_index(column_start.back());
  slot_.reserve(column_start.back());
  for_each_entry([&](int column, int row) {
    const int slot = next[column]++;
    row_index[slot] = row;
    slot_.push_back(slot);
  });
  DoubleDoubleCholesky::Options options;
  options.num_threads = problem.num_threads();
  cholesky_ = std::make_unique<DoubleDoubleCholesky>(options);
  // Whole blocks per vertex pair: analyzed by blocks.
  cholesky_->Analyze(num_unknowns_, std::move(column_start),
                     std::move(row_index), block_start);
  values_.resize(slot_.size());
}

template <int D>
void TangentNewton::Assemble(const Eigen::MatrixXd& Y,
                             const Eigen::MatrixXd& Lambda, double eps) {
  constexpr int P = D * (D - 1) / 2, B = D + 1, U = D + P;
  using MatB = Eigen::Matrix<double, B, B>;
  using MatE = Eigen::Matrix<double, B, U>;
  using MatH = Eigen::Matrix<double, U, U>;
  const int vertices = static_cast<int>(translation_of_vertex_.size());
  // E_a of every vertex: B x U (column-major), row a of the tangent
  // vector's entries at the vertex's K_0 rows (0: translation, 1 + c:
  // rotation column c) as functions of its unknowns (0 .. D-1: translation
  // coordinates, D + k: rotation coordinate k), zero where the vertex has
  // no such unknown, from the tangent basis Y_i E_k (SetBasis).
  SetBasis(Y);
  embedding_.assign(static_cast<size_t>(vertices) * D * B * U, 0.0);
  for (int v = 0; v < vertices; ++v) {
    const int blk = rotation_of_vertex_[v];
    for (int a = 0; a < D; ++a) {
      Eigen::Map<MatE> E(embedding_.data() +
                         (static_cast<size_t>(v) * D + a) * B * U);
      if (translation_of_vertex_[v] >= 0) E(0, a) = 1;
      if (blk >= 0) {
        for (int k = 0; k < P; ++k) {
          for (int c = 0; c < D; ++c) {
            E(1 + c, D + k) = rotated_(a, D * (P * blk + k) + c);
          }
        }
      }
    }
  }
  // The full-size local index of each of a vertex's unknowns.
  auto local = [&](int v, int t) {
    return translation_of_vertex_[v] >= 0 ? t : D + t;
  };
  size_t at = 0;
  for (size_t pair = 0; pair < pair_first_.size(); ++pair) {
    const int v = pair_first_[pair], w = pair_second_[pair];
    MatB K = Eigen::Map<const MatB>(base_.data() + pair * B * B);
    const int blk = rotation_of_vertex_[v];
    if (v == w && blk >= 0) {
      K.template bottomRightCorner<D, D>() -=
          Lambda.template middleCols<D>(D * blk);
    }
    MatH H = MatH::Zero();
    for (int a = 0; a < D; ++a) {
      Eigen::Map<const MatE> Ev(embedding_.data() +
                                (static_cast<size_t>(v) * D + a) * B * U);
      Eigen::Map<const MatE> Ew(embedding_.data() +
                                (static_cast<size_t>(w) * D + a) * B * U);
      H.noalias() += Ev.transpose() * (K * Ew);
    }
    const int uv = unknown_start_[v + 1] - unknown_start_[v];
    const int uw = unknown_start_[w + 1] - unknown_start_[w];
    for (int j = 0; j < uw; ++j) {
      for (int i = v == w ? j : 0; i < uv; ++i) {
        double value = 2 * H(local(v, i), local(w, j));
        if (v == w && i == j && local(v, i) >= D) value += eps;
        values_[slot_[at++]] = value;
      }
    }
  }
}

bool TangentNewton::Factorize(const Eigen::MatrixXd& Y,
                              const Eigen::MatrixXd& Lambda, double eps) {
  if (d_ == 2) {
    Assemble<2>(Y, Lambda, eps);
  } else {
    CHECK_EQ(d_, 3);
    Assemble<3>(Y, Lambda, eps);
  }
  Y_.resize(0, 0);
  if (!cholesky_->Factorize(values_)) return false;
  auto supernodes = [this](const SparseCholeskyFactor::SupernodeVisitor& f) {
    cholesky_->ForEachSupernode(f);
  };
  if (solver_ == nullptr) {
    solver_ = std::make_unique<SparseCholeskyFactor>(ordering_, supernodes);
  } else {
    solver_->RefreshValues(supernodes);
  }
  Y_ = Y;
  ++factorizations_;
  return true;
}

void TangentNewton::SetBasis(const Eigen::MatrixXd& Y) {
  // Y_i E_k for the orthonormal skew basis E_k (E_k(j, i) = -E_k(i, j) =
  // 1 / sqrt(2), i < j): its column i is Y_i's column j / sqrt(2), its
  // column j minus Y_i's column i / sqrt(2).
  const int D = d_, P = p_;
  const double s = 1 / std::sqrt(2.0);
  rotated_.resize(D, D * P * n_);
  for (int blk = 0; blk < n_; ++blk) {
    int k = 0;
    for (int i = 0; i < D; ++i) {
      for (int j = i + 1; j < D; ++j, ++k) {
        auto W = rotated_.middleCols(D * (P * blk + k), D);
        W.setZero();
        W.col(i) = s * Y.col(D * blk + j);
        W.col(j) = -s * Y.col(D * blk + i);
      }
    }
  }
}

void TangentNewton::Rebase(const Eigen::MatrixXd& Y) {
  SetBasis(Y);
  Y_ = Y;
}

void TangentNewton::Apply(const Eigen::MatrixXd& V, Eigen::MatrixXd* PV) const {
  const int d = d_, p = p_;
  Eigen::MatrixXd g(1, p * n_);
  for (int blk = 0; blk < n_; ++blk) {
    for (int k = 0; k < p; ++k) {
      g(0, p * blk + k) =
          V.middleCols(d * blk, d)
              .cwiseProduct(rotated_.middleCols(d * (p * blk + k), d))
              .sum();
    }
  }
  Eigen::MatrixXd z;
  solver_->SolveRowsTail(g, rotation_offset_, &z, problem_.num_threads());
  PV->setZero(V.rows(), V.cols());
  for (int blk = 0; blk < n_; ++blk) {
    for (int k = 0; k < p; ++k) {
      PV->middleCols(d * blk, d) +=
          z(0, p * blk + k) * rotated_.middleCols(d * (p * blk + k), d);
    }
  }
}

}  // namespace ceres_sesync::internal
