#include <shapectl/linalg/cholesky_backend.hpp>

#include <shapectl/enum_names.hpp>

namespace shapectl {

namespace {

constexpr auto kCholeskyBackends =
    enum_names<CholeskyBackend>(std::pair{CholeskyBackend::SimplicialLDLT, "ldlt"},
                                std::pair{CholeskyBackend::Band, "band"},
                                std::pair{CholeskyBackend::CholmodSupernodal, "cholmod"});

}  // namespace

const char* to_string(CholeskyBackend backend) { return kCholeskyBackends.name(backend); }
bool parse(std::string_view name, CholeskyBackend* backend) {
  return kCholeskyBackends.parse(name, backend);
}

}  // namespace shapectl
