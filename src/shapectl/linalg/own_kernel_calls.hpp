#pragma once
// A count of the calls into our own factorization and solve kernels (supernodal_llt.hpp,
// band_cholesky.hpp, band_factor.hpp, permuted_cholmod.hpp), for tests that show a back-end
// (the "cholmod-library" one) runs none of them.
#include <cstdint>

namespace shapectl {

// The calls so far, in all threads.
std::uint64_t own_kernel_calls();
// Called on entry by each of our kernels.
void count_own_kernel_call();

}  // namespace shapectl
