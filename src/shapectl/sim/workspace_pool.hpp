#pragma once
// Hands out statics workspaces and takes them back when their last owner lets go, so a new
// state reuses a symbolic analysis and buffers instead of redoing them. State side, not model:
// whoever runs many solves owns one (a ReducedObjective, a calibration, a SimulatedWorld) and
// hands it to the states it makes; it outlives the models, so the trials of a calibration (a
// new GrippedObject each) share their workspaces. A free workspace is reused only for a
// solver of its shape (unknowns, fixed dofs, back-end); its assembler then relearns the
// pattern only if the elements differ. Memory only: a workspace comes back without its
// factorization, and no result depends on which one a state gets (the analysis of a pattern is
// deterministic; values are overwritten). Thread-safe.
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include <shapectl/sim/statics.hpp>

namespace shapectl {

class WorkspacePool : public std::enable_shared_from_this<WorkspacePool> {
 public:
  // At most `keep` free workspaces are kept.
  static std::shared_ptr<WorkspacePool> create(int keep = 4);
  // A free workspace of `solver`'s shape, or a new one (StaticsSolver::make_workspace).
  std::shared_ptr<StaticsWorkspace> acquire(const StaticsSolver& solver);

 private:
  // What a workspace is made for: two solvers with equal shapes make interchangeable ones.
  struct Shape {
    int dof_count = 0;
    std::vector<char> fixed_dof;
    std::optional<SparseCholesky::Backend> backend;
    bool operator==(const Shape& o) const {
      return dof_count == o.dof_count && fixed_dof == o.fixed_dof && backend == o.backend;
    }
  };
  struct Free {
    Shape shape;
    std::unique_ptr<StaticsWorkspace> workspace;
  };
  explicit WorkspacePool(int keep) : keep_(keep) {}
  void release(Shape shape, StaticsWorkspace* ws);

  int keep_;
  std::mutex mutex_;
  std::vector<Free> free_;  // oldest first
};

}  // namespace shapectl
