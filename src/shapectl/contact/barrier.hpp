#pragma once
// IPC's barrier on a gap d (Li et al. 2020): b(d) = −(d − d̂)² ln(d / d̂) for 0 < d < d̂, 0 at
// and beyond d̂ (C² there), +inf for d ≤ 0.
namespace shapectl {

struct BarrierValue {
  double value = 0;   // b(d)
  double first = 0;   // b′(d)
  double second = 0;  // b″(d)
};

// b and its first two derivatives at gap d for the distance d̂ > 0; all +inf for d ≤ 0.
BarrierValue barrier(double d, double dhat);

// Throws std::invalid_argument, naming `term`, unless d̂ > 0 and κ ≥ 0 are finite.
void check_barrier_parameters(const char* term, double distance, double stiffness);

}  // namespace shapectl
