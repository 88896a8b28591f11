#pragma once
// The robot link's options, the same for `run` and `serve`: the motion governor and the EGM
// ports (link/make_robot_link.hpp). `--robot` stays with each command: their defaults differ.
#include <CLI/CLI.hpp>

#include <shapectl/link/make_robot_link.hpp>

namespace shapectl::cli {

struct LinkArgs {
  LinkConfig config;
  double watchdog_ms = 100;  // --watchdog-ms; into config.watchdog_timeout by link_config
};

void add_link_options(CLI::App& cmd, LinkArgs& args);
// The settings of `args` for a `kind` link starting at `initial_joints`; InputError naming the
// field that is out of range (validate).
LinkConfig link_config(const LinkArgs& args, LinkKind kind, const Eigen::VectorXd& initial_joints);

}  // namespace shapectl::cli
