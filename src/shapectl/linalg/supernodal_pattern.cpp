#include <shapectl/linalg/supernodal_pattern.hpp>

#include <stdexcept>

namespace shapectl {

double SupernodalPattern::flops() const {
  double f = 0;
  for (int k = 0; k < count(); ++k)
    for (int c = 0; c < columns(k); ++c) f += double(rows(k) - c) * (rows(k) - c);
  return f;
}

SupernodalPattern supernodal_pattern(const cholmod_factor& factor) {
  if (!factor.is_super || factor.itype != CHOLMOD_INT)
    throw std::logic_error("supernodal pattern: a supernodal CHOLMOD factor");
  const int count = static_cast<int>(factor.nsuper);
  const int* super = static_cast<const int*>(factor.super);
  const int* pi = static_cast<const int*>(factor.pi);
  const int* px = static_cast<const int*>(factor.px);
  const int* s = static_cast<const int*>(factor.s);
  SupernodalPattern p;
  p.first_column.assign(super, super + count + 1);
  p.row_starts.assign(pi, pi + count + 1);
  p.value_starts.assign(px, px + count + 1);
  p.row_index.assign(s, s + pi[count]);
  return p;
}

SupernodalPattern expand_blocks(const SupernodalPattern& blocks, int block) {
  SupernodalPattern p;
  const int count = blocks.count();
  p.first_column.resize(count + 1);
  p.row_starts.resize(count + 1);
  p.value_starts.resize(count + 1);
  p.row_index.resize(blocks.row_index.size() * block);
  for (int k = 0; k <= count; ++k) {
    p.first_column[k] = block * blocks.first_column[k];
    p.row_starts[k] = block * blocks.row_starts[k];
  }
  for (std::size_t r = 0; r < blocks.row_index.size(); ++r)
    for (int c = 0; c < block; ++c) p.row_index[block * r + c] = block * blocks.row_index[r] + c;
  for (int k = 0; k < count; ++k)
    p.value_starts[k + 1] = p.value_starts[k] + p.rows(k) * p.columns(k);
  return p;
}

}  // namespace shapectl
