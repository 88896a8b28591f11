#include <shapectl/linalg/cholesky_backend.hpp>

#include <shapectl/enum_names.hpp>

namespace shapectl {

namespace {

constexpr auto kCholeskyBackends =
    enum_names<CholeskyBackend>(std::pair{CholeskyBackend::SimplicialLDLT, "ldlt"},
                                std::pair{CholeskyBackend::Band, "band"},
                                std::pair{CholeskyBackend::CholmodSupernodal, "cholmod"},
                                std::pair{CholeskyBackend::CholmodLibrary, "cholmod-library"});

}  // namespace

const char* to_string(CholeskyBackend backend) { return kCholeskyBackends.name(backend); }
bool parse(std::string_view name, CholeskyBackend* backend) {
  return kCholeskyBackends.parse(name, backend);
}

std::string linear_solver_choices() {
  std::string choices = "\"auto\"";
  const std::vector<std::string> names = kCholeskyBackends.names();
  for (std::size_t k = 0; k < names.size(); ++k)
    choices += (k + 1 < names.size() ? ", \"" : " or \"") + names[k] + "\"";
  return choices;
}

}  // namespace shapectl
