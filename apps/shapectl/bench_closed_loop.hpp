#pragma once
// The closed loop's benchmark row of `shapectl bench`.
#include <nlohmann/json.hpp>

#include <shapectl/sim/scene.hpp>

namespace shapectl::cli {

// The loop of `run --robot sim --world`, on the wall clock, against a world 1.5× stiffer,
// 0.8× as dense and held 4 mm / 3° off at each grip; targets the model's own arch (both first
// joints turned 0.03 rad in). Prints the time until the world's true error is below 1 mm,
// with feedback only and with feedback and online calibration, median over `trials`; the
// figures also go to `record` (bench_json.hpp).
void bench_closed_loop(const Scene& scene, int trials, unsigned seed, nlohmann::json& record);

}  // namespace shapectl::cli
