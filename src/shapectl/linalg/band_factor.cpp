#include <shapectl/linalg/band_factor.hpp>

#include <tbb/task_group.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include <shapectl/hand_off.hpp>
#include <shapectl/linalg/own_kernel_calls.hpp>

extern "C" {  // LAPACK and BLAS (OpenBLAS)
void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info);
void dtrsm_(const char* side, const char* uplo, const char* trans, const char* diag, const int* m,
            const int* n, const double* alpha, const double* a, const int* lda, double* b,
            const int* ldb);
void dsyrk_(const char* uplo, const char* trans, const int* n, const int* k, const double* alpha,
            const double* a, const int* lda, const double* beta, double* c, const int* ldc);
void dgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k,
            const double* alpha, const double* a, const int* lda, const double* b, const int* ldb,
            const double* beta, double* c, const int* ldc);
}

namespace shapectl {

namespace {
const double kOne = 1, kMinusOne = -1;

// LAPACK lower band storage (ldab = kd + 1) seen as a dense column-major matrix: A(r, c) sits
// at ab[r + c·kd], leading dimension kd, wherever the band covers it (c ≤ r ≤ c + kd).
struct BandView {
  double* ab;
  int n, kd;
  double* at(int row, int col) const { return ab + row + static_cast<std::size_t>(col) * kd; }
  int ld() const { return std::max(kd, 1); }
};

// One block column: `size` columns from `first`, and its panel, the `rows` rows below the
// diagonal block that the band reaches (≤ kd). The panel's first `rectangle` rows lie in the
// band; the corner below them (rows first + kd ..) only on and above its diagonal, its other
// entries being zero in A and in L.
struct BlockColumn {
  int first = 0, size = 0, rows = 0, rectangle = 0;
  BlockColumn(const BandView& band, int first_column, int block)
      : first(first_column), size(std::min(block, band.n - first_column)) {
    rows = std::max(0, std::min(band.kd, band.n - first - size));
    rectangle = std::min(band.kd - size, rows);
  }
};

// Factors the block column's diagonal block (dpotrf) and its panel, L21 = A21 L11⁻ᵀ (dtrsm),
// which is left both in the band and in `panel` (rows × size, column-major, with the corner's
// zeros) for the trailing update. False if the diagonal block is not positive definite.
bool factor_block_column(const BandView& band, const BlockColumn& b, std::vector<double>& panel) {
  const int ld = band.ld();
  int info = 0;
  dpotrf_("L", &b.size, band.at(b.first, b.first), &ld, &info);
  if (info != 0) return false;
  if (b.rows == 0) return true;
  const int corner = b.rows - b.rectangle;
  panel.resize(static_cast<std::size_t>(b.rows) * b.size);
  for (int c = 0; c < b.size; ++c) {
    double* to = panel.data() + static_cast<std::size_t>(c) * b.rows;
    const double* from = band.at(b.first + b.size, b.first + c);
    std::copy(from, from + b.rectangle, to);
    for (int i = 0; i < corner; ++i) to[b.rectangle + i] = i <= c ? from[b.rectangle + i] : 0;
  }
  dtrsm_("R", "L", "T", "N", &b.rows, &b.size, &kOne, band.at(b.first, b.first), &ld, panel.data(),
         &b.rows);
  for (int c = 0; c < b.size; ++c) {
    const double* from = panel.data() + static_cast<std::size_t>(c) * b.rows;
    std::copy(from, from + b.rectangle + std::min(c + 1, corner),
              band.at(b.first + b.size, b.first + c));
  }
  return true;
}

// The trailing update A22 −= L21 L21ᵀ of the block column's rows × rows lower triangle
// (rows and columns first + size .., all in the band: r − c ≤ kd − 1), restricted to its
// columns [from, to): a dsyrk for their diagonal part, a dgemm for the rows below it.
void update_trailing_columns(const BandView& band, const BlockColumn& b,
                             const std::vector<double>& panel, int from, int to) {
  const int count = to - from;
  if (count <= 0) return;
  const int ld = band.ld();
  double* diagonal = band.at(b.first + b.size + from, b.first + b.size + from);
  const double* l = panel.data() + from;
  dsyrk_("L", "N", &count, &b.size, &kMinusOne, l, &b.rows, &kOne, diagonal, &ld);
  const int below = b.rows - to;
  if (below > 0)
    dgemm_("N", "T", &below, &count, &b.size, &kMinusOne, l + count, &b.rows, l, &b.rows, &kOne,
           diagonal + count, &ld);
}

// Where to split a trailing update between the two threads: the first one takes columns
// [0, split) and then factors the next block column (dpotrf and dtrsm, `next_flops`), the
// other the rest. Columns [0, s) of a rows × rows triangle hold rows·s − s²/2 of its entries,
// each costing 2·size flops; equal shares when s = rows − √(rows²/2 + next_flops/(2·size)).
// At least the next block column's width, which the first thread must own.
int lookahead_split(const BlockColumn& b, const BlockColumn& next) {
  const double next_flops =
      next.size * next.size * (next.size / 3.0 + next.rows);  // dpotrf + dtrsm
  const double s = b.rows - std::sqrt(0.5 * b.rows * b.rows + next_flops / (2.0 * b.size));
  return std::clamp(static_cast<int>(std::lround(s)), std::min(next.size, b.rows), b.rows);
}

// The column c_p of a rows × rows triangle such that columns [from, c_p) hold p/pieces of the
// entries of columns [from, rows): (rows − c_p)² = (rows − from)² (1 − p/pieces).
int equal_flops_column(int rows, int from, int p, int pieces) {
  if (p >= pieces) return rows;
  const double c = rows - (rows - from) * std::sqrt(1.0 - static_cast<double>(p) / pieces);
  return std::clamp(static_cast<int>(std::lround(c)), from, rows);
}
}  // namespace

// Right-looking like LAPACK's dpbtrf, with a look-ahead of one block column: the trailing
// update of block column k is split by columns; the calling thread updates the part holding
// block column k + 1 and then factors that block column while another thread updates the
// rest. One synchronisation per block column. With one thread, the whole update in one go.
bool factor_band(double* ab, int n, int kd, int block, bool two_threads) {
  count_own_kernel_call();
  const BandView band{ab, n, kd};
  const int nb = std::clamp(block, 1, std::max(kd, 1));
  if (n == 0) return true;
  std::vector<double> panel, next_panel;
  BlockColumn b(band, 0, nb);
  if (!factor_block_column(band, b, panel)) return false;
  while (b.first + b.size < n) {
    const BlockColumn next(band, b.first + b.size, nb);
    const int split = lookahead_split(b, next);
    bool next_ok = true;
    if (two_threads) {
      // The rest in a few pieces of equal flops: a piece another thread took and then could not
      // run (preempted on a busy machine) holds this thread up for less; pieces nobody took,
      // this thread runs itself in wait().
      constexpr int kPieces = 4;
      HandOff hand_off;
      tbb::task_group rest;
      for (int p = 0; p < kPieces; ++p) {
        const int from = equal_flops_column(b.rows, split, p, kPieces);
        const int to = equal_flops_column(b.rows, split, p + 1, kPieces);
        rest.run(hand_off([&, from, to] { update_trailing_columns(band, b, panel, from, to); }));
      }
      update_trailing_columns(band, b, panel, 0, split);
      next_ok = factor_block_column(band, next, next_panel);
      rest.wait();
      hand_off.joined();
    } else {
      update_trailing_columns(band, b, panel, 0, b.rows);
      next_ok = factor_block_column(band, next, next_panel);
    }
    if (!next_ok) return false;
    b = next;
    std::swap(panel, next_panel);
  }
  return true;
}

}  // namespace shapectl
