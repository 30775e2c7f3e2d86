#include "solvers/tall_products.hpp"

#include <algorithm>
#include <string>

#include "core/errors.hpp"
#include "core/parallel.hpp"

namespace tt::solvers {
namespace {

/// Rows per chunk: at most eight chunks and at least 2048 rows each, fixed by the row count.
std::ptrdiff_t chunk_rows(Eigen::Index rows) {
  constexpr Eigen::Index kChunks = 8, kMinRows = 2048;
  return static_cast<std::ptrdiff_t>(std::max(kMinRows, (rows + kChunks - 1) / kChunks));
}

void check_rows(Eigen::Index a, Eigen::Index b, const char* what) {
  if (a != b)
    throw core::SolverError(std::string("tall product ") + what + ": " + std::to_string(a) +
                            " rows against " + std::to_string(b));
}

}  // namespace

Eigen::MatrixXd tall_transposed_product(const Eigen::Ref<const Eigen::MatrixXd>& a,
                                        const Eigen::Ref<const Eigen::MatrixXd>& b) {
  check_rows(a.rows(), b.rows(), "a^T b");
  const auto parts = core::parallel_chunks<Eigen::MatrixXd>(
      a.rows(), chunk_rows(a.rows()),
      [&](std::ptrdiff_t begin, std::ptrdiff_t end, std::ptrdiff_t) {
        Eigen::MatrixXd part(a.cols(), b.cols());
        part.noalias() =
            a.middleRows(begin, end - begin).transpose() * b.middleRows(begin, end - begin);
        return part;
      });
  Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(a.cols(), b.cols());
  for (const auto& p : parts) sum += p;
  return sum;
}

void subtract_tall_product(Eigen::Ref<Eigen::MatrixXd> x,
                           const Eigen::Ref<const Eigen::MatrixXd>& a,
                           const Eigen::Ref<const Eigen::MatrixXd>& c) {
  check_rows(x.rows(), a.rows(), "x -= a c");
  if (a.cols() != c.rows() || x.cols() != c.cols())
    throw core::SolverError("tall product x -= a c: a has " + std::to_string(a.cols()) +
                            " columns, c is " + std::to_string(c.rows()) + " x " +
                            std::to_string(c.cols()) + ", x has " + std::to_string(x.cols()) +
                            " columns");
  const std::ptrdiff_t size = chunk_rows(x.rows());
  const std::ptrdiff_t chunks = (x.rows() + size - 1) / size;
  core::parallel_for(chunks, [&](std::ptrdiff_t k) {
    const Eigen::Index begin = k * size, count = std::min<Eigen::Index>(size, x.rows() - begin);
    x.middleRows(begin, count).noalias() -= a.middleRows(begin, count) * c;
  });
}

Eigen::MatrixXd symmetric_tall_product(const Eigen::Ref<const Eigen::MatrixXd>& v,
                                       const Eigen::Ref<const Eigen::MatrixXd>& w) {
  check_rows(v.rows(), w.rows(), "v^T w");
  constexpr Eigen::Index kBlock = 256;
  const Eigen::Index r = v.cols();
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(r, r);
  for (Eigen::Index j = 0; j < r; j += kBlock) {
    const Eigen::Index width = std::min(kBlock, r - j);
    out.block(j, j, r - j, width) =
        tall_transposed_product(v.rightCols(r - j), w.middleCols(j, width));
  }
  const Eigen::MatrixXd lower = out.triangularView<Eigen::Lower>();
  out = lower + lower.transpose();
  out.diagonal() *= 0.5;
  return out;
}

}  // namespace tt::solvers
