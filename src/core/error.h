#pragma once

#include <stdexcept>
#include <string>

namespace ecv {

/// A broken input: a missing or malformed file, a field with a nonsense value. The message names
/// the file, the field and what was expected. The command-line tool maps it to exit code 1.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Throws InputError "<source>: <field>: expected <expected>[, got <got>]".
[[noreturn]] void ThrowInputError(const std::string& source, const std::string& field, const std::string& expected,
                                  const std::string& got = "");

}  // namespace ecv
