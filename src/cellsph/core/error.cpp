#include "cellsph/core/error.hpp"

namespace cellsph::detail {

void check_failed(const char* expr, const char* file, int line, const std::string& msg) {
  std::ostringstream os;
  os << "internal check failed: " << expr << " at " << file << ":" << line;
  if (!msg.empty()) os << ": " << msg;
  throw std::logic_error(os.str());
}

}  // namespace cellsph::detail
