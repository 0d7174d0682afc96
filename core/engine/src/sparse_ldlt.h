#pragma once
// Sparse LDLᵀ factorisation of a symmetric matrix with a fixed pattern: the up-looking algorithm
// of T. A. Davis's LDL (ACM TOMS 31(4), 2005), with its symbolic analysis done once and every
// work array sized then, so that numeric factorisations and solves allocate nothing (Eigen's
// SimplicialLDLT allocates in each factorize). The caller orders the unknowns (fill-reducing
// ordering, see ImplicitSolver) and hands over the upper triangle in compressed columns.

#include <cstdint>
#include <span>
#include <vector>

namespace liversim::detail {

class SparseLdlt {
 public:
  // Symbolic analysis of the pattern: column k holds rows ≤ k, the diagonal included.
  void analyse(std::span<const int> column_begin, std::span<const int> row_index);

  // Numeric factorisation of values in the analysed pattern. False on a zero pivot (a singular
  // matrix), with failed_column() naming it. Allocates nothing.
  bool factorise(std::span<const int> column_begin, std::span<const int> row_index,
                 std::span<const double> values);
  int failed_column() const { return failed_column_; }

  // Solves A·x = b in place (b in, x out). Allocates nothing.
  void solve(std::span<double> rhs) const;

 private:
  int size_ = 0;
  std::vector<int> parent_, nonzeros_in_column_, column_start_, flag_, pattern_, l_row_;
  std::vector<double> l_value_, diagonal_, work_;
  int failed_column_ = -1;
};

}  // namespace liversim::detail
