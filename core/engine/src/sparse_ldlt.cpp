#include "sparse_ldlt.h"

namespace liversim::detail {

void SparseLdlt::analyse(std::span<const int> column_begin, std::span<const int> row_index) {
  size_ = static_cast<int>(column_begin.size()) - 1;
  const int n = size_;
  parent_.assign(n, -1);
  nonzeros_in_column_.assign(n, 0);
  flag_.assign(n, 0);
  // Elimination tree and the nonzero count of each column of L: each entry of column k walks up
  // the tree until a node already visited for this row.
  for (int k = 0; k < n; ++k) {
    flag_[k] = k;
    for (int p = column_begin[k]; p < column_begin[k + 1]; ++p) {
      for (int i = row_index[p]; i < k && flag_[i] != k; i = parent_[i]) {
        if (parent_[i] == -1) parent_[i] = k;
        ++nonzeros_in_column_[i];
        flag_[i] = k;
      }
    }
  }
  column_start_.assign(n + 1, 0);
  for (int k = 0; k < n; ++k) column_start_[k + 1] = column_start_[k] + nonzeros_in_column_[k];
  l_row_.assign(column_start_[n], 0);
  l_value_.assign(column_start_[n], 0.0);
  diagonal_.assign(n, 0.0);
  work_.assign(n, 0.0);
  pattern_.assign(n, 0);
}

bool SparseLdlt::factorise(std::span<const int> column_begin, std::span<const int> row_index,
                           std::span<const double> values) {
  failed_column_ = -1;
  const int n = size_;
  for (int k = 0; k < n; ++k) {
    // Scatter column k of A into work_ and find the pattern of row k of L (paths up the tree
    // from each entry), topologically ordered at the end of pattern_.
    work_[k] = 0.0;
    int top = n;
    flag_[k] = k;
    nonzeros_in_column_[k] = 0;
    for (int p = column_begin[k]; p < column_begin[k + 1]; ++p) {
      int i = row_index[p];
      if (i > k) continue;
      work_[i] += values[p];
      int length = 0;
      for (; flag_[i] != k; i = parent_[i]) {
        pattern_[length++] = i;
        flag_[i] = k;
      }
      while (length > 0) pattern_[--top] = pattern_[--length];
    }
    // Sparse triangular solve for row k of L, and the pivot D(k).
    double pivot = work_[k];
    work_[k] = 0.0;
    for (; top < n; ++top) {
      const int i = pattern_[top];
      const double yi = work_[i];
      work_[i] = 0.0;
      const int end = column_start_[i] + nonzeros_in_column_[i];
      for (int p = column_start_[i]; p < end; ++p) work_[l_row_[p]] -= l_value_[p] * yi;
      const double l_ki = yi / diagonal_[i];
      pivot -= l_ki * yi;
      l_row_[end] = k;
      l_value_[end] = l_ki;
      ++nonzeros_in_column_[i];
    }
    if (pivot == 0.0 || pivot != pivot) {  // singular, or NaN in the matrix
      failed_column_ = k;
      return false;
    }
    diagonal_[k] = pivot;
  }
  return true;
}

void SparseLdlt::solve(std::span<double> x) const {
  const int n = size_;
  for (int j = 0; j < n; ++j)
    for (int p = column_start_[j]; p < column_start_[j + 1]; ++p)
      x[l_row_[p]] -= l_value_[p] * x[j];
  for (int j = 0; j < n; ++j) x[j] /= diagonal_[j];
  for (int j = n - 1; j >= 0; --j)
    for (int p = column_start_[j]; p < column_start_[j + 1]; ++p)
      x[j] -= l_value_[p] * x[l_row_[p]];
}

}  // namespace liversim::detail
