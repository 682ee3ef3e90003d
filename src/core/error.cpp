#include "core/error.h"

namespace ecv {

void ThrowInputError(const std::string& source, const std::string& field, const std::string& expected,
                     const std::string& got) {
  std::string message = source;
  if (!field.empty()) message += ": " + field;
  message += ": expected " + expected;
  if (!got.empty()) message += ", got " + got;
  throw InputError(message);
}

}  // namespace ecv
