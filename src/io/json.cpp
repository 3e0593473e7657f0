#include "kin2grf/io/json.hpp"

#include "kin2grf/error.hpp"
#include "kin2grf/io/text.hpp"

namespace kin2grf {

std::string json_text(const nlohmann::json& j) {
  // Labels and paths come from files: invalid UTF-8 is replaced (U+FFFD), not an internal error.
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

nlohmann::json parse_json_text(std::string_view text, const std::string& path) {
  // The parser itself keeps its nesting on the heap, but whatever later walks the document (a
  // dump() in an error message, a copy) recurses once a level: the depth is bounded here, where
  // the file is read, and nowhere later can a file's nesting size the stack.
  const auto depth_limit = [&path](int depth, nlohmann::json::parse_event_t event, const nlohmann::json&) {
    if (depth >= kMaxJsonDepth && (event == nlohmann::json::parse_event_t::object_start ||
                                  event == nlohmann::json::parse_event_t::array_start))
      throw InputError(path + ": JSON nested more than " + std::to_string(kMaxJsonDepth) + " levels deep");
    return true;
  };
  try {
    return nlohmann::json::parse(text, depth_limit);
  } catch (const nlohmann::json::exception& e) {  // parse errors, and numbers out of range (1e400)
    throw InputError(path + ": not valid JSON: " + e.what());
  }
}

nlohmann::json read_json_file(const std::string& path) { return parse_json_text(read_file_text(path), path); }

std::string json_excerpt(const nlohmann::json& j, std::size_t max_chars) {
  std::string s = j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  if (s.size() > max_chars) s = s.substr(0, max_chars) + "...";
  return s;
}

}  // namespace kin2grf
