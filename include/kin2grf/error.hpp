// kin2grf: errors that name what went wrong and where.
//
// Every reader and every pipeline step throws InputError for bad input (never a crash, never a
// silent guess). The message always names the file (or "<memory>"), and, where known, the field,
// byte offset, frame or marker.
#pragma once

#include <stdexcept>
#include <string>

namespace kin2grf {

class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace kin2grf
