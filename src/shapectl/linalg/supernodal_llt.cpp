#include <shapectl/linalg/supernodal_llt.hpp>

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <stdexcept>
#include <tbb/parallel_invoke.h>
#include <utility>
#include <vector>

#include <shapectl/hand_off.hpp>
#include <shapectl/linalg/own_kernel_calls.hpp>

namespace shapectl {

namespace {

// Supernode k: columns first … first + columns − 1 of L, stored as a dense column-major block
// of `rows` rows: the diagonal block (rows first … first + columns − 1), then the rows below it.
struct Supernode {
  int first, columns, rows;
  double* values;
  const int* row_index;  // all `rows` of them, ascending
};

// A supernodal pattern with its values (or without, for the structure alone).
class Supernodes {
 public:
  Supernodes(const SupernodalPattern& pattern, double* values)
      : pattern_(pattern), values_(values) {}
  int count() const { return pattern_.count(); }
  int size() const { return pattern_.size(); }
  Supernode operator[](int k) const {
    return {pattern_.first_column[k], pattern_.columns(k), pattern_.rows(k),
            values_ + pattern_.value_starts[k], pattern_.row_index.data() + pattern_.row_starts[k]};
  }
  int most_rows() const { return most(pattern_.row_starts); }
  int most_columns() const { return most(pattern_.first_column); }

 private:
  int most(const std::vector<int>& starts) const {
    int result = 0;
    for (int k = 0; k < count(); ++k) result = std::max(result, starts[k + 1] - starts[k]);
    return result;
  }
  const SupernodalPattern& pattern_;
  double* values_;
};

using Block = Eigen::Map<Eigen::MatrixXd>;
Block block_of(const Supernode& s) { return Block(s.values, s.rows, s.columns); }

constexpr int kAboveBoth = 2;  // a team: factored after both subtrees

// L y = b over the supernodes of team `t` (all where `team` is empty), in order. A supernode's
// rows below its diagonal block touch x only through a scatter of those rows.
template <typename X>
void forward(const Supernodes& supernodes, const std::vector<int>& team, int t, X& x) {
  std::vector<double> work(static_cast<std::size_t>(supernodes.most_rows()) * x.cols());
  for (int k = 0; k < supernodes.count(); ++k) {
    if (!team.empty() && team[k] != t) continue;
    const Supernode s = supernodes[k];
    const Block block = block_of(s);
    auto diagonal = x.middleRows(s.first, s.columns);
    block.topRows(s.columns).template triangularView<Eigen::Lower>().solveInPlace(diagonal);
    const int below = s.rows - s.columns;
    if (below == 0) continue;
    Block update(work.data(), below, x.cols());
    update.noalias() = block.bottomRows(below) * diagonal;
    for (int i = 0; i < below; ++i) x.row(s.row_index[s.columns + i]) -= update.row(i);
  }
}

// Lᵀ x = y over the supernodes of team `t` (all where `team` is empty), in reverse; a gather of
// the rows below each diagonal block.
template <typename X>
void backward(const Supernodes& supernodes, const std::vector<int>& team, int t, X& x) {
  std::vector<double> work(static_cast<std::size_t>(supernodes.most_rows()) * x.cols());
  for (int k = supernodes.count() - 1; k >= 0; --k) {
    if (!team.empty() && team[k] != t) continue;
    const Supernode s = supernodes[k];
    const Block block = block_of(s);
    auto diagonal = x.middleRows(s.first, s.columns);
    const int below = s.rows - s.columns;
    if (below > 0) {
      Block known(work.data(), below, x.cols());
      for (int i = 0; i < below; ++i) known.row(i) = x.row(s.row_index[s.columns + i]);
      diagonal.noalias() -= block.bottomRows(below).transpose() * known;
    }
    block.topRows(s.columns).transpose().template triangularView<Eigen::Upper>().solveInPlace(
        diagonal);
  }
}

// Forward then backward; with two teams (supernodal_teams), their subtrees at once. A subtree
// writes its own rows and those above both, never the other's: forward, team 1 works on a
// copy whose rows above both start at zero and collect its updates, added to x's after both
// teams (the same sums on every run); backward, both read the rows above, already solved.
template <typename X>
void forward_backward(const SupernodalPattern& pattern, const std::vector<int>& team,
                      const double* values, X& x) {
  if (!values) throw std::logic_error("supernodal LLᵀ: solve with a factor's values");
  // Read only: Supernodes hands out writable blocks, which the solve does not write.
  const Supernodes supernodes(pattern, const_cast<double*>(values));
  if (x.rows() != static_cast<Eigen::Index>(pattern.size()))
    throw std::logic_error("supernodal LLᵀ: solve as many rows as the factor has");
  if (!team.empty() && team.size() != static_cast<std::size_t>(supernodes.count()))
    throw std::logic_error("supernodal LLᵀ: a team for each supernode (supernodal_teams)");
  if (std::find(team.begin(), team.end(), 1) == team.end()) {
    forward(supernodes, {}, 0, x);
    backward(supernodes, {}, 0, x);
    return;
  }
  auto rows_of = [&](int k, X& m) {
    return m.middleRows(supernodes[k].first, supernodes[k].columns);
  };
  X other = x;
  for (int k = 0; k < supernodes.count(); ++k)
    if (team[k] == kAboveBoth) rows_of(k, other).setZero();
  HandOff forward_teams;
  tbb::parallel_invoke(forward_teams([&] { forward(supernodes, team, 0, x); }),
                       forward_teams([&] { forward(supernodes, team, 1, other); }));
  forward_teams.joined();
  for (int k = 0; k < supernodes.count(); ++k) {
    if (team[k] == 1) rows_of(k, x) = rows_of(k, other);
    if (team[k] == kAboveBoth) rows_of(k, x) += rows_of(k, other);
  }
  forward(supernodes, team, kAboveBoth, x);
  backward(supernodes, team, kAboveBoth, x);
  HandOff backward_teams;
  tbb::parallel_invoke(backward_teams([&] { backward(supernodes, team, 0, x); }),
                       backward_teams([&] { backward(supernodes, team, 1, x); }));
  backward_teams.joined();
}

// Team 0 or 1 for each supernode in one of two disjoint subtrees, kAboveBoth for the rest: from
// the roots down, the subtree with most of the work is replaced by its children while it has
// more than half of it; the subtrees left are dealt to the lighter team, largest first. All
// team 0 where that would leave a team under a tenth of the work, or the work is too small
// to be worth a second thread.
std::vector<int> split_in_two(const Supernodes& supernodes) {
  const int count = supernodes.count();
  std::vector<int> owner(supernodes.size());
  for (int k = 0; k < count; ++k)
    for (int c = 0; c < supernodes[k].columns; ++c) owner[supernodes[k].first + c] = k;
  std::vector<int> parent(count, -1);
  std::vector<double> subtree(count, 0);
  double all = 0;
  for (int k = 0; k < count; ++k) {
    const Supernode s = supernodes[k];
    subtree[k] += double(s.columns) * s.rows * s.rows;  // ~ its flops
    all += double(s.columns) * s.rows * s.rows;
    if (s.rows > s.columns) {
      parent[k] = owner[s.row_index[s.columns]];
      subtree[parent[k]] += subtree[k];
    }
  }
  std::vector<int> team(count, 0);
  constexpr double kWorthASecondThread = 2e6;  // ~ flops: 0.1-0.2 ms
  if (all < kWorthASecondThread) return team;
  std::vector<std::vector<int>> children(count);
  std::vector<int> frontier;
  for (int k = 0; k < count; ++k) (parent[k] < 0 ? frontier : children[parent[k]]).push_back(k);
  std::vector<char> above(count, 0);
  auto heaviest = [&] {
    return std::max_element(frontier.begin(), frontier.end(),
                            [&](int a, int b) { return subtree[a] < subtree[b]; });
  };
  double frontier_work = all;
  while (!frontier.empty() && 2 * subtree[*heaviest()] > frontier_work) {
    const auto top = heaviest();
    const int k = *top;
    frontier.erase(top);
    above[k] = 1;
    frontier_work -= double(supernodes[k].columns) * supernodes[k].rows * supernodes[k].rows;
    frontier.insert(frontier.end(), children[k].begin(), children[k].end());
  }
  std::sort(frontier.begin(), frontier.end(),
            [&](int a, int b) { return subtree[a] > subtree[b]; });
  std::array<double, 2> load{0, 0};
  std::vector<int> root_team(count, -1);
  for (const int k : frontier) {
    const int t = load[0] <= load[1] ? 0 : 1;
    root_team[k] = t;
    load[t] += subtree[k];
  }
  if (std::min(load[0], load[1]) < 0.1 * all) return team;
  for (int k = count - 1; k >= 0; --k)  // parents before children
    team[k] = above[k] ? kAboveBoth : root_team[k] >= 0 ? root_team[k] : team[parent[k]];
  return team;
}

// The left-looking supernodal factorization: supernode j first takes its columns of A, then
// the updates of every earlier supernode d with rows in j's columns (its descendants), then
// factors itself. A lane's `waiting[j]` lists those d (linked through next_waiting_); once d has
// updated j it waits for the supernode of its next row below j's columns, from next_row_[d] on.
class LeftLooking {
 public:
  struct Lane {
    std::vector<int> waiting;    // supernode → the first descendant waiting for it, or −1
    std::vector<int> local_row;  // row → its place in the supernode being factored
    std::vector<double> work;    // one descendant's update
  };

  LeftLooking(const SparseMatrix& lower, const Supernodes& supernodes)
      : lower_(lower),
        supernodes_(supernodes),
        owner_(lower.rows()),
        next_waiting_(supernodes.count(), -1),
        next_row_(supernodes.count(), 0) {
    for (int k = 0; k < supernodes.count(); ++k)
      for (int c = 0; c < supernodes[k].columns; ++c) owner_[supernodes[k].first + c] = k;
  }
  Lane lane() const {
    return {std::vector<int>(supernodes_.count(), -1), std::vector<int>(lower_.rows()),
            std::vector<double>(static_cast<std::size_t>(supernodes_.most_rows()) *
                                supernodes_.most_columns())};
  }

  // Factors supernode j with the updates waiting in `lane`; false at a pivot that is not > 0.
  bool factor(int j, Lane& lane) {
    const Supernode s = supernodes_[j];
    for (int i = 0; i < s.rows; ++i) lane.local_row[s.row_index[i]] = i;
    Block block = block_of(s);
    block.setZero();
    const int* outer = lower_.outerIndexPtr();
    const int* inner = lower_.innerIndexPtr();
    const double* values = lower_.valuePtr();
    for (int c = 0; c < s.columns; ++c)
      for (int k = outer[s.first + c]; k < outer[s.first + c + 1]; ++k)
        block(lane.local_row[inner[k]], c) = values[k];
    const int end = s.first + s.columns;
    const int first_waiting = std::exchange(lane.waiting[j], -1);
    for (int d = first_waiting; d != -1;) {
      const int next = next_waiting_[d];
      const Supernode from = supernodes_[d];
      // d's rows from `first` on: those up to `last` are j's columns, all are j's rows.
      const int first = next_row_[d];
      int last = first;
      while (last < from.rows && from.row_index[last] < end) ++last;
      const int in_columns = last - first, in_rows = from.rows - first;
      const Block d_block = block_of(from);
      Block update(lane.work.data(), in_rows, in_columns);
      update.noalias() =
          d_block.middleRows(first, in_rows) * d_block.middleRows(first, in_columns).transpose();
      for (int c = 0; c < in_columns; ++c) {
        double* column = &block(0, from.row_index[first + c] - s.first);
        for (int r = c; r < in_rows; ++r)
          column[lane.local_row[from.row_index[first + r]]] -= update(r, c);
      }
      wait_for_next_row(d, last, lane);
      d = next;
    }
    auto diagonal = block.topRows(s.columns);
    const Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>, Eigen::Lower> llt(diagonal);
    // LLT stops at a pivot ≤ 0 only; a NaN pivot passes it, and any non-finite entry of A
    // reaches some later pivot through the updates.
    if (llt.info() != Eigen::Success || !diagonal.diagonal().allFinite()) return false;
    if (s.rows == s.columns) return true;
    auto below = block.bottomRows(s.rows - s.columns);
    diagonal.transpose().triangularView<Eigen::Upper>().solveInPlace<Eigen::OnTheRight>(below);
    wait_for_next_row(j, s.columns, lane);
    return true;
  }

  // Appends `other`'s waiting lists to `into`'s (only supernodes above both subtrees have any
  // left in both).
  void join(Lane& into, const Lane& other) {
    for (int k = 0; k < supernodes_.count(); ++k) {
      if (other.waiting[k] == -1) continue;
      int* tail = &into.waiting[k];
      while (*tail != -1) tail = &next_waiting_[*tail];
      *tail = other.waiting[k];
    }
  }

 private:
  void wait_for_next_row(int d, int position, Lane& lane) {
    const Supernode s = supernodes_[d];
    if (position == s.rows) return;
    next_row_[d] = position;
    const int target = owner_[s.row_index[position]];
    next_waiting_[d] = lane.waiting[target];
    lane.waiting[target] = d;
  }

  const SparseMatrix& lower_;
  const Supernodes& supernodes_;
  std::vector<int> owner_;  // column → its supernode
  std::vector<int> next_waiting_, next_row_;
};

}  // namespace

bool factorize_supernodal(const SparseMatrix& lower, const SupernodalPattern& pattern,
                          const std::vector<int>& team, double* values) {
  count_own_kernel_call();
  const Supernodes supernodes(pattern, values);
  const int n = pattern.size();
  if (lower.rows() != n || lower.cols() != n || !lower.isCompressed())
    throw std::logic_error("supernodal LLᵀ: factorize a compressed matrix of the factor's size");
  if (team.size() != static_cast<std::size_t>(supernodes.count()))
    throw std::logic_error("supernodal LLᵀ: a team for each supernode (supernodal_teams)");
  LeftLooking left_looking(lower, supernodes);
  // Two disjoint subtrees of the elimination tree on two threads, then the supernodes above
  // them on one. Each lane lists its own waiting descendants; those waiting for a supernode
  // above both subtrees join one list when both are done. The split and the lists depend on
  // the pattern only, so every run adds the same updates in the same order.
  std::array<LeftLooking::Lane, 2> lanes{left_looking.lane(), left_looking.lane()};
  std::array<bool, 2> factored{true, true};
  auto factor_team = [&](int t) {
    for (int k = 0; k < supernodes.count() && factored[t]; ++k)
      if (team[k] == t) factored[t] = left_looking.factor(k, lanes[t]);
  };
  if (std::count(team.begin(), team.end(), 1) > 0) {
    HandOff hand_off;
    tbb::parallel_invoke(hand_off([&] { factor_team(0); }), hand_off([&] { factor_team(1); }));
    hand_off.joined();
  } else {
    factor_team(0);
  }
  if (!factored[0] || !factored[1]) return false;
  left_looking.join(lanes[0], lanes[1]);
  for (int k = 0; k < supernodes.count(); ++k)
    if (team[k] == kAboveBoth && !left_looking.factor(k, lanes[0])) return false;
  return true;
}

std::vector<int> supernodal_teams(const SupernodalPattern& pattern) {
  return split_in_two(Supernodes(pattern, nullptr));
}

void solve_supernodal_in_place(const SupernodalPattern& pattern, const double* values,
                               Eigen::VectorXd& x, const std::vector<int>& teams) {
  count_own_kernel_call();
  forward_backward(pattern, teams, values, x);
}

void solve_supernodal_in_place(const SupernodalPattern& pattern, const double* values,
                               Eigen::MatrixXd& x, const std::vector<int>& teams) {
  count_own_kernel_call();
  forward_backward(pattern, teams, values, x);
}

}  // namespace shapectl
