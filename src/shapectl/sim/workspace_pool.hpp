#pragma once
// Hands out statics workspaces and takes them back when their last owner lets go, so a new
// state reuses a symbolic analysis and buffers instead of redoing them. Memory only: a
// workspace comes back without its factorization, and no result depends on which one a state
// gets (the analysis of a pattern is deterministic; values are overwritten). Thread-safe.
#include <functional>
#include <memory>
#include <mutex>
#include <vector>

#include <shapectl/sim/statics.hpp>

namespace shapectl {

class WorkspacePool : public std::enable_shared_from_this<WorkspacePool> {
 public:
  // `make` builds a new workspace when none is free; at most `keep` free ones are kept.
  static std::shared_ptr<WorkspacePool> create(std::function<StaticsWorkspace()> make,
                                               int keep = 4);
  std::shared_ptr<StaticsWorkspace> acquire();

 private:
  WorkspacePool(std::function<StaticsWorkspace()> make, int keep)
      : make_(std::move(make)), keep_(keep) {}
  void release(StaticsWorkspace* ws);

  std::function<StaticsWorkspace()> make_;
  int keep_;
  std::mutex mutex_;
  std::vector<std::unique_ptr<StaticsWorkspace>> free_;
};

}  // namespace shapectl
