#include "kin2grf/io/json.hpp"

#include "kin2grf/error.hpp"
#include "kin2grf/io/text.hpp"

namespace kin2grf {

std::string json_text(const nlohmann::json& j) {
  // Labels and paths come from files: invalid UTF-8 is replaced (U+FFFD), not an internal error.
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

nlohmann::json read_json_file(const std::string& path) {
  try {
    return nlohmann::json::parse(read_file_text(path));
  } catch (const nlohmann::json::exception& e) {  // parse errors, and numbers out of range (1e400)
    throw InputError(path + ": not valid JSON: " + e.what());
  }
}

}  // namespace kin2grf
