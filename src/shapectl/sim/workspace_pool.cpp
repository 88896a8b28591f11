#include <shapectl/sim/workspace_pool.hpp>

namespace shapectl {

std::shared_ptr<WorkspacePool> WorkspacePool::create(std::function<StaticsWorkspace()> make,
                                                     int keep) {
  return std::shared_ptr<WorkspacePool>(new WorkspacePool(std::move(make), keep));
}

std::shared_ptr<StaticsWorkspace> WorkspacePool::acquire() {
  std::unique_ptr<StaticsWorkspace> ws;
  {
    std::lock_guard lock(mutex_);
    if (!free_.empty()) {
      ws = std::move(free_.back());
      free_.pop_back();
    }
  }
  if (!ws) ws = std::make_unique<StaticsWorkspace>(make_());
  std::weak_ptr<WorkspacePool> pool = weak_from_this();
  return std::shared_ptr<StaticsWorkspace>(ws.release(), [pool](StaticsWorkspace* w) {
    if (auto p = pool.lock()) p->release(w);
    else delete w;
  });
}

void WorkspacePool::release(StaticsWorkspace* ws) {
  std::unique_ptr<StaticsWorkspace> owned(ws);
  owned->forget_factor();
  std::lock_guard lock(mutex_);
  if (static_cast<int>(free_.size()) < keep_) free_.push_back(std::move(owned));
}

}  // namespace shapectl
