#include <shapectl/sim/workspace_pool.hpp>

namespace shapectl {

std::shared_ptr<WorkspacePool> WorkspacePool::create(int keep) {
  return std::shared_ptr<WorkspacePool>(new WorkspacePool(keep));
}

std::shared_ptr<StaticsWorkspace> WorkspacePool::acquire(const StaticsSolver& solver) {
  Shape shape{3 * solver.node_count(), solver.fixed_dof(), solver.options().backend};
  std::unique_ptr<StaticsWorkspace> ws;
  {
    std::lock_guard lock(mutex_);
    for (auto it = free_.rbegin(); it != free_.rend(); ++it) {
      if (!(it->shape == shape)) continue;
      ws = std::move(it->workspace);
      free_.erase(std::next(it).base());
      break;
    }
  }
  if (!ws) ws = std::make_unique<StaticsWorkspace>(solver.make_workspace());
  std::weak_ptr<WorkspacePool> pool = weak_from_this();
  return std::shared_ptr<StaticsWorkspace>(ws.release(), [pool, shape = std::move(shape)](
                                                             StaticsWorkspace* w) mutable {
    if (auto p = pool.lock()) p->release(std::move(shape), w);
    else delete w;
  });
}

void WorkspacePool::release(Shape shape, StaticsWorkspace* ws) {
  std::unique_ptr<StaticsWorkspace> owned(ws);
  owned->forget_factor();
  std::lock_guard lock(mutex_);
  if (static_cast<int>(free_.size()) >= keep_) free_.erase(free_.begin());
  free_.push_back({std::move(shape), std::move(owned)});
}

}  // namespace shapectl
