#pragma once

#include <string>

#include <gtest/gtest.h>

#include "core/error.h"

namespace ecv::test {

/// The message of the InputError that `action` throws, or a test failure (and "") if it throws none.
template <typename Action>
std::string InputErrorMessage(Action action) {
  try {
    action();
  } catch (const InputError& error) {
    return error.what();
  }
  ADD_FAILURE() << "expected an InputError";
  return "";
}

}  // namespace ecv::test
